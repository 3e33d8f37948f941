//! `simulate` refuses options it cannot honour, naming the option the user typed: a value
//! out of range names its option (with the simulator's setting beside it), an orbit below
//! the surface is refused, and an orbit inclination without an orbit is not silently
//! dropped.

use super::{inertia, stderr, stdout};
use std::path::Path;

/// Problem: one bad value per option kind. Reference: the option's name in the message,
/// a failed exit and no file written.
#[test]
fn bad_simulate_options_name_the_option() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("x.csv");
    let out = out.to_str().expect("utf-8");
    for (args, names) in [
        (&["--gyro-arw-deg-rthr=-1"][..], "--gyro-arw-deg-rthr"),
        (&["--wheel-skew-s=nan"][..], "--wheel-skew-s"),
        (&["--star-tracker-hz=-1"][..], "--star-tracker-hz"),
        (&["--drag-nms=-1"][..], "--drag-nms"),
        (
            &["--gravity-gradient-altitude-km=-100"][..],
            "--gravity-gradient-altitude-km",
        ),
        (
            &["--orbit-inclination-deg=30"][..],
            "--gravity-gradient-altitude-km",
        ),
        (&["--duration=-5"][..], "--duration"),
        (&["--momentum-bias=0:0"][..], "--momentum-bias"),
    ] {
        let mut all = vec!["simulate", "--scenario", "slew", "--output", out];
        all.extend_from_slice(args);
        let o = inertia(&all);
        assert!(!o.status.success(), "{args:?} was accepted");
        assert!(stderr(&o).contains(names), "{args:?}: {}", stderr(&o));
        assert!(!std::path::Path::new(out).exists(), "{args:?} wrote a file");
    }
}

/// Problem: a momentum bias on the spin (which starts with its own momentum), and a
/// spacecraft file with thrusters but no rotors (whose speeds `simulate --spacecraft`
/// writes). Reference: each refused by the option's name and what to do instead, and no
/// file written.
#[test]
fn a_bias_on_the_spin_and_a_file_without_rotors_are_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("x.csv");
    let out = out.to_str().expect("utf-8");
    let sc = dir.path().join("thrusters.toml");
    std::fs::write(
        &sc,
        "[[thruster]]\nname = \"t1\"\nposition_m = [0.3, 0.0, 0.0]\ndirection = [0.0, 1.0, 0.0]\nthrust_n = 0.02\ncolumn = \"t1_throttle\"\n",
    )
    .expect("write");
    let sc = sc.to_str().expect("utf-8");
    for (args, says) in [
        (
            ["spin", "--momentum-bias", "0:0:0.1"],
            &["--momentum-bias: the spin"][..],
        ),
        (
            ["slew", "--spacecraft", sc],
            &["thrusters.toml: the file lists no rotors", "--thrusters"][..],
        ),
    ] {
        let mut all = vec!["simulate", "-o", out, "--scenario"];
        all.extend_from_slice(&args);
        let o = inertia(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let e = stderr(&o);
        assert!(says.iter().all(|s| e.contains(s)), "{args:?}: {e}");
        assert!(!std::path::Path::new(out).exists(), "{args:?} wrote a file");
    }
}

#[test]
fn simulate_realism_options() {
    let dir = tempfile::tempdir().unwrap();
    let read = |p: &Path| std::fs::read_to_string(p).unwrap();
    // A preset, decimated to 1 Hz telemetry with its 10 Hz controller.
    let small = dir.path().join("small.csv");
    let o = inertia(&[
        "simulate",
        "--preset",
        "small-sat",
        "--duration",
        "30",
        "--telemetry-dt",
        "1",
        "-o",
        small.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = read(&small);
    assert!(text.starts_with("t,q_x,q_y,q_z,q_w,rho_x,rho_y,rho_z,tau_x,tau_y,tau_z,w_x,w_y,w_z\n"));
    assert_eq!(text.lines().count(), 32, "header + 31 samples at 1 Hz");
    let truth: serde_json::Value =
        serde_json::from_str(&read(&dir.path().join("small.truth.json"))).unwrap();
    assert_eq!(truth["inertia_kg_m2"][0][0], 0.31);

    // The paper's slew with every effect on; gravity gradient adds r_x,r_y,r_z.
    let all = dir.path().join("all.csv");
    let o = inertia(&[
        "simulate",
        "--scenario",
        "slew",
        "--duration",
        "20",
        "--attitude",
        "star-tracker",
        "--star-tracker-arcsec",
        "5:5:40",
        "--gyro-arw-deg-rthr",
        "0.02",
        "--gyro-bias-deg-h",
        "1:-1:0.5",
        "--controller-hz",
        "10",
        "--command-phase",
        "0.05",
        "--wheel-quantization-nms",
        "1e-4",
        "--wheel-skew-s",
        "-0.05",
        "--gravity-gradient-altitude-km",
        "500",
        "--constant-torque-nm",
        "1e-5:0:-1e-5",
        "-o",
        all.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = read(&all);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(&header[14..], ["r_x", "r_y", "r_z"]);
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 201);
    for row in &rows {
        let r = (row[14] * row[14] + row[15] * row[15] + row[16] * row[16]).sqrt();
        assert!((r - 6_878_137.0).abs() < 1e-3, "orbit radius {r}");
        for rho in &row[5..8] {
            let steps = rho / 1e-4;
            assert!(
                (steps - steps.round()).abs() < 1e-6,
                "ρ {rho} not quantised"
            );
        }
        // The unknown torques are not telemetered.
        assert_eq!(&row[8..11], [0.0, 0.0, 0.0]);
    }
    // `estimate` reads it (extra columns ignored).
    let o = inertia(&["estimate", all.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));

    // Invalid settings name the option or the field.
    let bad = |extra: &[&str], needle: &str| {
        let out = dir.path().join("bad.csv");
        let mut args = vec!["simulate", "--scenario", "slew", "--duration", "5"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", out.to_str().unwrap()]);
        let o = inertia(&args);
        assert!(!o.status.success(), "{extra:?} accepted");
        assert!(stderr(&o).contains(needle), "{extra:?}: {}", stderr(&o));
    };
    bad(&["--telemetry-dt", "0.15"], "--telemetry-dt");
    bad(
        &["--controller-hz", "10", "--command-phase", "0.2"],
        "commands.phase_s",
    );
    bad(&["--command-phase", "0.05"], "--controller-hz");
    bad(&["--star-tracker-arcsec", "1:2"], "--star-tracker-arcsec");
    bad(&["--wheel-skew-s", "0.5"], "wheels.skew_s");
    bad(
        &["--attitude", "mekf", "--star-tracker-hz", "3"],
        "star_tracker.rate_hz",
    );
    bad(&["--preset", "microsat"], "cannot be used with");
    // --help documents the options.
    let help = stdout(&inertia(&["simulate", "--help"]));
    for opt in [
        "--preset",
        "--attitude",
        "--controller-hz",
        "--command-phase",
        "--telemetry-dt",
        "--star-tracker-arcsec",
        "--gyro-arw-deg-rthr",
        "--gyro-bias-deg-h",
        "--wheel-quantization-nms",
        "--wheel-skew-s",
        "--gravity-gradient-altitude-km",
        "--constant-torque-nm",
    ] {
        assert!(help.contains(opt), "{opt} missing from --help");
    }
}

/// Each `simulate` option changes what it names and nothing else, by its specification:
/// the same 20 s of the slew with one option at a time against the same run without it.
#[test]
fn simulate_options_change_what_they_name() {
    let dir = tempfile::tempdir().unwrap();
    let sim = |name: &str, extra: &[&str]| -> Vec<Vec<f64>> {
        let out = dir.path().join(format!("{name}.csv"));
        let mut args = vec!["simulate", "--scenario", "slew", "--duration", "20"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", out.to_str().unwrap()]);
        let o = inertia(&args);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        std::fs::read_to_string(&out)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect()
    };
    let cols = |rows: &[Vec<f64>], c: std::ops::Range<usize>| -> Vec<Vec<f64>> {
        rows.iter().map(|r| r[c.clone()].to_vec()).collect()
    };
    let (q, rho, w) = (1..5, 5..8, 11..14);
    let base = sim("base", &["--attitude", "truth"]);
    assert_eq!(base.len(), 201);

    // The attitude source changes the quaternions only.
    let gyro = sim("gyro", &["--attitude", "gyro"]);
    assert_ne!(cols(&gyro, q.clone()), cols(&base, q.clone()));
    assert_eq!(cols(&gyro, rho.clone()), cols(&base, rho.clone()));
    assert_eq!(cols(&gyro, w.clone()), cols(&base, w.clone()));
    assert_eq!(cols(&gyro, 8..11), cols(&base, 8..11), "τ");

    // Wheel white noise: ρ only, with the stated 1σ.
    let noisy = sim(
        "noise",
        &["--attitude", "truth", "--wheel-noise-nms", "1e-4"],
    );
    assert_eq!(cols(&noisy, q.clone()), cols(&base, q.clone()));
    assert_eq!(cols(&noisy, w.clone()), cols(&base, w.clone()));
    for axis in 0..3 {
        let d: Vec<f64> = noisy
            .iter()
            .zip(&base)
            .map(|(a, b)| a[5 + axis] - b[5 + axis])
            .collect();
        let sd = (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
        assert!((sd / 1e-4 - 1.0).abs() < 0.2, "axis {axis}: σ {sd:e}");
    }

    // Spin-inertia scale error per axis: telemetered = (1 + ε) true.
    let scaled = sim(
        "scale",
        &["--attitude", "truth", "--wheel-scale-error", "0.01:0:-0.01"],
    );
    assert_eq!(cols(&scaled, w.clone()), cols(&base, w.clone()));
    for (a, b) in scaled.iter().zip(&base) {
        for (axis, f) in [1.01, 1.0, 0.99].into_iter().enumerate() {
            let (x, y) = (a[5 + axis], f * b[5 + axis]);
            assert!((x - y).abs() <= 1e-12 * (1e-9 + y.abs()), "{x} vs {y}");
        }
    }

    // Misalignment: ρ turned by 1° about body z.
    let turned = sim(
        "misaligned",
        &["--attitude", "truth", "--wheel-misalignment-deg", "0:0:1"],
    );
    assert_eq!(cols(&turned, w.clone()), cols(&base, w.clone()));
    let (s, c) = 1f64.to_radians().sin_cos();
    for (a, b) in turned.iter().zip(&base) {
        let expect = [c * b[5] - s * b[6], s * b[5] + c * b[6], b[7]];
        for k in 0..3 {
            assert!((a[5 + k] - expect[k]).abs() <= 1e-12 + 1e-9 * expect[k].abs());
        }
    }

    // Gyro bias instability: the rates change, the true attitude does not.
    let drifting = sim(
        "instability",
        &[
            "--attitude",
            "truth",
            "--gyro-bias-instability-deg-h",
            "50",
            "--gyro-bias-correlation-s",
            "10",
        ],
    );
    assert_eq!(cols(&drifting, q.clone()), cols(&base, q.clone()));
    assert_eq!(cols(&drifting, rho.clone()), cols(&base, rho.clone()));
    assert_ne!(cols(&drifting, w.clone()), cols(&base, w.clone()));

    // The star tracker's roll noise (40″) is about the boresight given, 5″ across it.
    let tracker = sim(
        "tracker",
        &[
            "--attitude",
            "star-tracker",
            "--star-tracker-boresight",
            "1:0:0",
        ],
    );
    let mut sum = [0.0f64; 3];
    for (a, b) in tracker.iter().zip(&base) {
        // Body-frame error: q_true⁻¹ ⊗ q_tracker, small angle 2 vec(·).
        let (qt, qm) = (&b[1..5], &a[1..5]);
        let (x1, y1, z1, w1) = (-qt[0], -qt[1], -qt[2], qt[3]);
        let (x2, y2, z2, w2) = (qm[0], qm[1], qm[2], qm[3]);
        let v = [
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ];
        let sign = (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2).signum();
        for k in 0..3 {
            let arcsec = 2.0 * sign * v[k] * 180.0 / core::f64::consts::PI * 3600.0;
            sum[k] += arcsec * arcsec;
        }
    }
    let sd: Vec<f64> = sum.iter().map(|s| (s / base.len() as f64).sqrt()).collect();
    assert!((sd[0] / 40.0 - 1.0).abs() < 0.2, "roll about x: {sd:?}");
    assert!(
        (sd[1] / 5.0 - 1.0).abs() < 0.2 && (sd[2] / 5.0 - 1.0).abs() < 0.2,
        "{sd:?}"
    );

    // The MEKF's raw rates: the same attitude, the rates without its bias estimate.
    let mekf = sim(
        "mekf",
        &["--attitude", "mekf", "--gyro-bias-deg-h", "5:-5:5"],
    );
    let raw = sim(
        "raw",
        &[
            "--attitude",
            "mekf",
            "--gyro-bias-deg-h",
            "5:-5:5",
            "--mekf-raw-rates",
        ],
    );
    assert_eq!(cols(&raw, q.clone()), cols(&mekf, q.clone()));
    assert_eq!(cols(&raw, rho.clone()), cols(&mekf, rho.clone()));
    assert_ne!(cols(&raw, w.clone()), cols(&mekf, w.clone()));

    // The orbit's inclination: out of the equatorial plane (r_z) only when inclined.
    let orbit = |i: &str| {
        let rows = sim(
            &format!("orbit{i}"),
            &[
                "--attitude",
                "truth",
                "--gravity-gradient-altitude-km",
                "500",
                "--orbit-inclination-deg",
                i,
            ],
        );
        rows.iter().map(|r| r[16].abs()).fold(0.0, f64::max)
    };
    assert!(orbit("0") < 1e-6);
    assert!(orbit("60") > 1e3);

    // The microsatellite preset.
    let micro = dir.path().join("micro.csv");
    let o = inertia(&[
        "simulate",
        "--preset",
        "microsat",
        "--duration",
        "10",
        "-o",
        micro.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let truth: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("micro.truth.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(truth["inertia_kg_m2"][0][0], 4.6);
}

/// The simulator's options also go by names that carry their units (SI, or the density's
/// unit): the same file either way.
#[test]
fn simulate_options_with_units_in_their_names_are_the_same_options() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, options: &[&str]| -> String {
        let out = dir.path().join(format!("{name}.csv"));
        let mut args = vec!["simulate", "--scenario", "slew", "--controller-hz", "10"];
        args.extend_from_slice(options);
        args.extend_from_slice(&["-o", out.to_str().unwrap()]);
        let o = inertia(&args);
        assert!(o.status.success(), "{options:?}: {}", stderr(&o));
        std::fs::read_to_string(out).unwrap()
    };
    let short = run(
        "short",
        &[
            "--duration",
            "6",
            "--dt",
            "0.05",
            "--telemetry-dt",
            "0.1",
            "--gyro-noise",
            "1e-4",
            "--disturbance",
            "1e-7",
            "--command-phase",
            "0.05",
        ],
    );
    let long = run(
        "long",
        &[
            "--duration-s",
            "6",
            "--dt-s",
            "0.05",
            "--telemetry-dt-s",
            "0.1",
            "--gyro-noise-deg-s-rthz",
            "1e-4",
            "--disturbance-nm-rthz",
            "1e-7",
            "--command-phase-s",
            "0.05",
        ],
    );
    assert_eq!(short, long);
    assert_eq!(short.lines().count(), 62);
    let help = stdout(&inertia(&["simulate", "--help"]));
    assert!(help.contains("duration-s") && help.contains("disturbance-nm-rthz"));
}
