//! `--torque-scale-sigma`: the known torque's stated scale σ in the final answer's σ
//! (`Run::torque_scale_term`: the batch re-solved with the known torque scaled). A
//! thruster whose thrust is off by 5 %: without wheels J scales with it exactly, no
//! residual sees it, and only the stated σ covers it; with wheels the term is the small
//! part of J the torque sets, and the move such an error makes.

use super::{inertia, json, stderr};
use std::path::Path;

/// A file's known torque and force columns scaled by `k` (the thrust stated `k` times
/// the flown one).
fn scaled(src: &Path, dst: &Path, k: f64) {
    let text = std::fs::read_to_string(src).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let cols: Vec<usize> = (0..header.len())
        .filter(|&i| header[i].starts_with("tau_") || header[i].starts_with("f_"))
        .collect();
    let mut out = header.join(",") + "\n";
    for line in lines {
        let mut v: Vec<String> = line.split(',').map(str::to_string).collect();
        for &i in &cols {
            v[i] = format!("{:e}", v[i].parse::<f64>().unwrap() * k);
        }
        out += &(v.join(",") + "\n");
    }
    std::fs::write(dst, out).unwrap();
}

fn within_3_sigma(e: &serde_json::Value, truth: &[f64; 6]) -> bool {
    (0..6).all(|k| {
        let (j, s) = (e["j"][k].as_f64().unwrap(), e["sigma"][k].as_f64().unwrap());
        (j - truth[k]).abs() <= 3.0 * s
    })
}

fn truth(path: &Path) -> [f64; 6] {
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let m = &t["inertia_kg_m2"];
    let at = |i: usize, j: usize| m[i][j].as_f64().unwrap();
    [at(0, 0), at(1, 1), at(2, 2), at(0, 1), at(0, 2), at(1, 2)]
}

#[test]
fn a_stated_thrust_sigma_covers_a_thrust_scale_error() {
    let d = tempfile::tempdir().unwrap();
    let p = |name: &str| d.path().join(name).to_str().unwrap().to_string();
    // No wheel moves: the thrusters alone excite the spacecraft.
    std::fs::write(
        p("zero.csv"),
        "t_s,rho_dot_x_nm,rho_dot_y_nm,rho_dot_z_nm\n0,0,0,0\n300,0,0,0\n",
    )
    .unwrap();
    let o = inertia(&[
        "simulate",
        "--commands",
        &p("zero.csv"),
        "--thrusters",
        "0.02",
        "-o",
        &p("flown.csv"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    scaled(
        &d.path().join("flown.csv"),
        &d.path().join("stated.csv"),
        1.05,
    );
    let truth = truth(&d.path().join("flown.truth.json"));

    // Taken as exact, the 5 % is J's 5 %, and the answer is called determined far
    // beyond its σ: no residual can see a scale common to every row.
    let exact = json(&inertia(&["estimate", &p("stated.csv"), "--json"]));
    assert_eq!(exact["status"], "determined");
    assert!(!within_3_sigma(&exact, &truth), "{exact}");
    assert!(exact["torque_scale_sigma_kg_m2"].is_null());
    let j11 = exact["j"][0].as_f64().unwrap();
    assert!(
        (j11 / truth[0] - 1.05).abs() < 1e-3,
        "{j11} vs {}",
        truth[0]
    );

    // Stated, the term is 5 % of J (all of J is the torque's), streaming and batch alike,
    // and with a memory (no samples kept: the whole answer's scale), and the truth is
    // within 3σ.
    for mode in ["streaming", "--batch", "--memory"] {
        let mut args = vec!["estimate", "--json", "--torque-scale-sigma", "5%"];
        match mode {
            "--batch" => args.push("--batch"),
            "--memory" => args.extend(["--memory", "400"]),
            _ => {}
        }
        let batch = mode;
        let path = p("stated.csv");
        args.push(&path);
        let e = json(&inertia(&args));
        assert!(within_3_sigma(&e, &truth), "batch {batch}: {e}");
        for k in 0..6 {
            let term = e["torque_scale_sigma_kg_m2"][k].as_f64().unwrap();
            let j = e["j"][k].as_f64().unwrap();
            assert!(
                (term - 0.05 * j.abs()).abs() <= 0.02 * 0.05 * j.abs() + 1e-9,
                "batch {batch}, element {k}: term {term}, J {j}"
            );
        }
    }
}

#[test]
fn with_wheels_the_term_is_the_part_of_j_the_torque_sets() {
    let d = tempfile::tempdir().unwrap();
    let p = |name: &str| d.path().join(name).to_str().unwrap().to_string();
    let o = inertia(&[
        "simulate",
        "--scenario",
        "slew",
        "--thrusters",
        "0.02",
        "-o",
        &p("slew.csv"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = json(&inertia(&[
        "estimate",
        &p("slew.csv"),
        "--json",
        "--torque-scale-sigma",
        "5%",
    ]));
    let truth = truth(&d.path().join("slew.truth.json"));
    assert!(within_3_sigma(&e, &truth), "{e}");
    // The wheels set most of J here: the term is well below 5 % of J, but not zero.
    for k in 0..3 {
        let term = e["torque_scale_sigma_kg_m2"][k].as_f64().unwrap();
        let j = e["j"][k].as_f64().unwrap();
        assert!(
            term > 0.0 && term < 0.02 * j,
            "element {k}: term {term}, J {j}"
        );
    }
    // The thrust stated 5 % high: the term of the stated file is the move the error
    // made (the answer's own row model, re-solved), within a factor of 2 per moment.
    scaled(
        &d.path().join("slew.csv"),
        &d.path().join("slew5.csv"),
        1.05,
    );
    let off = json(&inertia(&[
        "estimate",
        &p("slew5.csv"),
        "--json",
        "--torque-scale-sigma",
        "5%",
    ]));
    assert!(within_3_sigma(&off, &truth), "{off}");
    for k in 0..3 {
        let term = off["torque_scale_sigma_kg_m2"][k].as_f64().unwrap();
        let moved = (off["j"][k].as_f64().unwrap() - e["j"][k].as_f64().unwrap()).abs();
        assert!(
            (0.5..=2.0).contains(&(term / moved)),
            "element {k}: term {term}, the error's move {moved}"
        );
    }
    // The centre of mass (the thrusters' torque `(r_i − c) × F_i`, true c = 0) carries the
    // same solves' move: taken as exact its σ is micrometres, with the stated 5 % it is
    // millimetres, at least a third of the move the 5 % error makes (the error also
    // switches the row model, as for J), and the stated file's holds the truth within 3σ.
    let centre = |e: &serde_json::Value, k: usize, what: &str| {
        e["outside"]["centre_of_mass_m"][what][k].as_f64().unwrap()
    };
    let exact = json(&inertia(&["estimate", &p("slew.csv"), "--json"]));
    for k in 0..3 {
        let (plain, stated) = (centre(&exact, k, "sigma"), centre(&e, k, "sigma"));
        let moved = (centre(&off, k, "value") - centre(&e, k, "value")).abs();
        assert!(plain < 1e-5 && stated > 100.0 * plain, "{plain} {stated}");
        assert!(
            moved <= 3.0 * stated,
            "axis {k}: σ {stated}, the error's move {moved}"
        );
        assert!(centre(&off, k, "value").abs() <= 3.0 * centre(&off, k, "sigma"));
    }
    // Without a known torque there is nothing to scale: no term.
    let plain = d.path().join("plain.csv");
    let o = inertia(&[
        "simulate",
        "--scenario",
        "slew",
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = json(&inertia(&[
        "estimate",
        plain.to_str().unwrap(),
        "--json",
        "--torque-scale-sigma",
        "5%",
    ]));
    assert!(e["torque_scale_sigma_kg_m2"].is_null(), "{e}");
}
