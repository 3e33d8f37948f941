//! `--spacecraft`: `simulate` writes the wheels' speed columns, `estimate` reads them back
//! into the momentum, the wheels' σ reach the report, and a bad spacecraft file or a
//! telemetry file that gives the momentum twice is refused with file, line and key.

use super::{inertia, json, stderr};

const FILE: &str = r#"
rotor_errors = "independent"
[[rotor]]
name = "rw1"
axis = [0.816497, 0.0, 0.577350]
spin_inertia_kg_m2 = 1.5e-3
spin_inertia_sigma_kg_m2 = 3.0e-5
speed_column = "rw1_rpm"
speed_unit = "rpm"
[[rotor]]
name = "rw2"
axis = [0.0, 0.816497, 0.577350]
spin_inertia_kg_m2 = 1.5e-3
speed_column = "rw2_rpm"
speed_unit = "rpm"
[[rotor]]
name = "rw3"
axis = [-0.816497, 0.0, 0.577350]
spin_inertia_kg_m2 = 1.5e-3
speed_column = "rw3_rpm"
speed_unit = "rpm"
[[rotor]]
name = "rw4"
axis = [0.0, -0.816497, 0.577350]
spin_inertia_kg_m2 = 1.5e-3
speed_column = "rw4_rpm"
speed_unit = "rpm"
"#;

/// Problem: the slew through a four-wheel pyramid file, estimated with the same file.
/// Reference: the same slew written as `rho`. The same answer (within 5 % of σ), the
/// speed columns in place of `rho_*`, and the one wheel with a σ its one error source.
#[test]
fn wheel_speeds_round_trip_and_their_sigma_is_reported() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sc = dir.path().join("sc.toml");
    std::fs::write(&sc, FILE).expect("write");
    let (sc, d) = (sc.to_str().expect("utf-8"), dir.path());
    let speeds = d.join("speeds.csv");
    let o = inertia(&[
        "simulate",
        "--scenario",
        "slew",
        "--duration",
        "100",
        "--spacecraft",
        sc,
        "-o",
        speeds.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let header = std::fs::read_to_string(&speeds).expect("read");
    let header = header.lines().next().expect("header");
    assert!(
        header.ends_with("rw1_rpm,rw2_rpm,rw3_rpm,rw4_rpm") && !header.contains("rho_x"),
        "{header}"
    );
    let plain = super::simulate(d, "plain", "slew", "100");
    let a = json(&inertia(&[
        "estimate",
        plain.to_str().expect("utf-8"),
        "--json",
    ]));
    let b = json(&inertia(&[
        "estimate",
        speeds.to_str().expect("utf-8"),
        "--spacecraft",
        sc,
        "--json",
    ]));
    for k in 0..6 {
        let (x, y) = (
            a["j"][k].as_f64().expect("j"),
            b["j"][k].as_f64().expect("j"),
        );
        assert!(
            (x - y).abs() < 0.05 * b["sigma"][k].as_f64().expect("σ"),
            "J[{k}]: {x} vs {y}"
        );
    }
    assert_eq!(b["rotor_inertia"]["rotors"][0], "rw1");
    assert_eq!(b["rotor_inertia"]["errors"], "independent");
    // Only rw1 has a σ: one error source, its spin inertia.
    assert_eq!(
        b["rotor_inertia"]["sources"],
        serde_json::json!(["rw1 spin inertia"])
    );
    let moves = b["rotor_inertia"]["moves_kg_m2"][0]
        .as_array()
        .expect("rw1");
    assert!(moves.iter().any(|v| v.as_f64() != Some(0.0)));
}

/// Problem: a spacecraft file with a bad key, and a telemetry file with both `rho_*` and
/// the speed columns. Reference: the message names the file, the line and the key or
/// column; exit code 2.
#[test]
fn a_bad_spacecraft_file_and_a_momentum_given_twice_are_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let plain = super::simulate(d, "plain", "slew", "20");
    let bad = d.join("bad.toml");
    std::fs::write(
        &bad,
        FILE.replace("[0.0, 0.816497, 0.577350]", "[0.0, 0.9, 0.577350]"),
    )
    .expect("write");
    let o = inertia(&[
        "estimate",
        plain.to_str().expect("utf-8"),
        "--spacecraft",
        bad.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("bad.toml:12: `rotor[1].axis`: not a unit vector"),
        "{e}"
    );
    let sc = d.join("sc.toml");
    std::fs::write(&sc, FILE).expect("write");
    let text = std::fs::read_to_string(&plain).expect("read");
    let both: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                format!("{l},rw1_rpm,rw2_rpm,rw3_rpm,rw4_rpm\n")
            } else {
                format!("{l},0,0,0,0\n")
            }
        })
        .collect();
    let both_path = d.join("both.csv");
    std::fs::write(&both_path, both).expect("write");
    let o = inertia(&[
        "estimate",
        both_path.to_str().expect("utf-8"),
        "--spacecraft",
        sc.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("both.csv:1: column `rho_x` holds the rotor momentum"),
        "{e}"
    );
    // Neither: the speed columns are required.
    let neither = d.join("neither.csv");
    std::fs::write(&neither, text.replacen("rho_", "h_", 3)).expect("write");
    let o = inertia(&[
        "estimate",
        neither.to_str().expect("utf-8"),
        "--spacecraft",
        sc.to_str().expect("utf-8"),
    ]);
    assert!(
        stderr(&o).contains("neither.csv:1: missing column `rw1_rpm`"),
        "{}",
        stderr(&o)
    );
}

/// Problem: a momentum-biased slew (`simulate --momentum-bias`) whose second wheel's axis
/// is tilted by 0.3° from the file's, estimated with `--batch --calibrate-rotors` and the
/// file stating 0.5° of tilt σ. Reference: the tilt simulated. The report gives each of
/// the 8 tilts with its σ, the data fixing all 8, the tilted wheel's tilt within 3σ of
/// 0.3° and the others within 3σ of 0; without `--batch` the option is refused, naming
/// `--batch`.
#[test]
fn a_calibration_finds_a_tilted_wheel() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let stated = FILE
        .replace("spin_inertia_sigma_kg_m2 = 3.0e-5\n", "")
        .replace(
            "speed_unit = \"rpm\"",
            "speed_unit = \"rpm\"\nspin_axis_sigma_deg = 0.5",
        );
    let nominal = d.join("nominal.toml");
    std::fs::write(&nominal, &stated).expect("write");
    // rw2's axis (0, cos e, sin e) turned by 0.3° about body x.
    let e = 0.577350f64.atan2(0.816497);
    let (sin, cos) = (e + 0.3f64.to_radians()).sin_cos();
    let tilted = FILE.replace(
        "[0.0, 0.816497, 0.577350]",
        &format!("[0.0, {cos:.9}, {sin:.9}]"),
    );
    let truth = d.join("truth.toml");
    std::fs::write(&truth, tilted).expect("write");
    let csv = d.join("biased.csv");
    let o = inertia(&[
        "simulate",
        "--scenario",
        "slew",
        "--duration",
        "120",
        "--momentum-bias",
        "0.03:-0.02:0.1",
        "--spacecraft",
        truth.to_str().expect("utf-8"),
        "-o",
        csv.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (csv, nominal) = (
        csv.to_str().expect("utf-8"),
        nominal.to_str().expect("utf-8"),
    );
    let r = json(&inertia(&[
        "estimate",
        csv,
        "--spacecraft",
        nominal,
        "--batch",
        "--calibrate-rotors",
        "--json",
    ]));
    let c = &r["rotor_calibration"];
    assert_eq!(c["data_fixed"], 8, "{c}");
    let sources: Vec<&str> = c["sources"]
        .as_array()
        .expect("sources")
        .iter()
        .map(|s| s.as_str().expect("name"))
        .collect();
    assert_eq!(sources.len(), 8);
    // rw2's tilt directions: the 0.3° turn is the tilt whose direction has a body-z part.
    let tilt = |k: usize| {
        (
            c["value"][k].as_f64().unwrap(),
            c["sigma"][k].as_f64().unwrap(),
        )
    };
    let (a, b) = (tilt(2), tilt(3));
    let turned = a.0.hypot(b.0);
    assert!(
        (turned - 0.3).abs() <= 3.0 * a.1.max(b.1),
        "rw2 tilts {a:?} {b:?}"
    );
    for k in [0, 1, 4, 5, 6, 7] {
        let (v, s) = tilt(k);
        assert!(v.abs() <= 3.0 * s, "{}: {v} ± {s}", sources[k]);
    }
    let o = inertia(&[
        "estimate",
        csv,
        "--spacecraft",
        nominal,
        "--calibrate-rotors",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--calibrate-rotors needs --batch"),
        "{}",
        stderr(&o)
    );
}
