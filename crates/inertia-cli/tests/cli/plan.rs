//! `inertia plan` and `simulate --commands`: the plan keeps every limit of the spacecraft
//! file, flies through the simulator, and the estimate of the flight is within the
//! predicted σ.

use super::{inertia, json, stderr, stdout};
use std::path::Path;

/// A 12U-class spacecraft with a four-wheel pyramid (so the allocation is not the
/// identity) and a rate limit tight enough to bind.
const SC: &str = r#"
[[rotor]]
name = "rw1"
axis = [0.816497, 0.0, 0.577350]
spin_inertia_kg_m2 = 1.0e-4
speed_column = "rw1_rpm"
max_torque_nm = 0.004
max_momentum_nms = 0.02
[[rotor]]
name = "rw2"
axis = [0.0, 0.816497, 0.577350]
spin_inertia_kg_m2 = 1.0e-4
speed_column = "rw2_rpm"
max_torque_nm = 0.004
max_momentum_nms = 0.02
[[rotor]]
name = "rw3"
axis = [-0.816497, 0.0, 0.577350]
spin_inertia_kg_m2 = 1.0e-4
speed_column = "rw3_rpm"
max_torque_nm = 0.004
max_momentum_nms = 0.02
[[rotor]]
name = "rw4"
axis = [0.0, -0.816497, 0.577350]
spin_inertia_kg_m2 = 1.0e-4
speed_column = "rw4_rpm"
max_torque_nm = 0.004
max_momentum_nms = 0.02

[prior]
inertia_kg_m2 = [[0.30, -0.005, 0.004], [-0.005, 0.28, 0.002], [0.004, 0.002, 0.19]]
relative_sigma = 0.05

[sensors]
gyro_noise_deg_s_rthz = 0.0025
telemetry_hz = 10.0
controller_hz = 2.0

[limits]
max_rate_deg_s = 2.0
"#;

/// A plan CSV read back: per row its time, each wheel's torque and momentum, and the
/// body-axis momentum from the running sum of the commands.
struct PlanRows {
    t: Vec<f64>,
    tau: Vec<[f64; 4]>,
    h: Vec<[f64; 4]>,
    rho: Vec<[f64; 3]>,
}

fn read_plan(path: &Path) -> PlanRows {
    let text = std::fs::read_to_string(path).expect("plan");
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |n: &str| {
        header
            .iter()
            .position(|c| *c == n)
            .unwrap_or_else(|| panic!("{n}"))
    };
    let (mut t, mut tau, mut h, mut rho) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut sum = [0.0; 3];
    for l in lines {
        let f: Vec<f64> = l.split(',').map(|x| x.parse().expect("number")).collect();
        t.push(f[col("t_s")]);
        tau.push(std::array::from_fn(|i| {
            f[col(&format!("rw{}_torque_nm", i + 1))]
        }));
        h.push(std::array::from_fn(|i| {
            f[col(&format!("rw{}_momentum_nms", i + 1))]
        }));
        rho.push(sum);
        // Commands held over the controller period, 0.5 s.
        for (i, c) in ["rho_dot_x_nm", "rho_dot_y_nm", "rho_dot_z_nm"]
            .iter()
            .enumerate()
        {
            sum[i] += f[col(c)] * 0.5;
        }
    }
    PlanRows { t, tau, h, rho }
}

#[test]
fn a_plan_keeps_every_limit_and_its_flight_is_within_the_predicted_sigma() {
    let d = tempfile::tempdir().unwrap();
    let sc = d.path().join("sc.toml");
    std::fs::write(&sc, SC).unwrap();
    let plan = d.path().join("plan.csv");
    let o = inertia(&[
        "plan",
        "--spacecraft",
        sc.to_str().unwrap(),
        "--rehearsals",
        "0",
        "-o",
        plan.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("information matrix"), "{out}");
    // Without rehearsals `--chain auto` (the default) is the estimator's default chain.
    assert!(
        out.contains("estimator chain: 30 s; estimate with --chain 30"),
        "{out}"
    );
    for f in ["plan.prediction.csv", "plan.png", "plan.svg"] {
        assert!(d.path().join(f).exists(), "{f}");
    }
    let PlanRows { t, tau, h, rho } = read_plan(&plan);
    assert!(
        t.len() > 10 && (t[1] - t[0] - 0.5).abs() < 1e-12,
        "{:?}",
        &t[..2]
    );
    // Every wheel within its torque and momentum limits; the body rate ω = −J⁻¹ρ of the
    // prior within the rate limit; each used to at most the margin 1/(1 + 3 · 0.05 ·
    // 0.30/0.19) of the limit (the prior's σ relative to its smallest moment).
    let margin = 1.0 / (1.0 + 3.0 * 0.05 * 0.30 / 0.19);
    let worst_tau = tau
        .iter()
        .flatten()
        .map(|x| x.abs() / 0.004)
        .fold(0.0, f64::max);
    let worst_h = h
        .iter()
        .flatten()
        .map(|x| x.abs() / 0.02)
        .fold(0.0, f64::max);
    assert!(
        worst_tau <= margin + 1e-9 && worst_h <= margin + 1e-9,
        "{worst_tau} {worst_h}"
    );
    assert!(
        worst_tau > 0.5 * margin,
        "the plan uses its torque: {worst_tau}"
    );
    let j = nalgebra::Matrix3::new(0.30, -0.005, 0.004, -0.005, 0.28, 0.002, 0.004, 0.002, 0.19);
    let j_inv = j.try_inverse().unwrap();
    let worst_rate = rho
        .iter()
        .map(|r| (j_inv * nalgebra::Vector3::from(*r)).norm() / 2f64.to_radians())
        .fold(0.0, f64::max);
    assert!(worst_rate <= margin + 1e-9, "{worst_rate}");
    // The wheels' momenta are the commands' running sum through the allocation: the
    // last row's momentum is what the body-axis commands add up to.
    let n = h.len() - 1;
    let back: f64 = (0..4)
        .map(|i| h[n][i] * [0.816497, 0.0, -0.816497, 0.0][i])
        .sum();
    assert!((back - rho[n][0]).abs() < 1e-6, "{back} vs {}", rho[n][0]);

    // Fly it on a true J off the prior, and estimate.
    let flight = d.path().join("flight.csv");
    let o = inertia(&[
        "simulate",
        "--commands",
        plan.to_str().unwrap(),
        "--inertia",
        "0.31:0.27:0.18:-0.006:0.004:0.002",
        "--gyro-noise",
        "0.0025",
        "--controller-hz",
        "2",
        "--seed",
        "3",
        "-o",
        flight.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("commands"), "{}", stderr(&o));
    let rows = std::fs::read_to_string(&flight).unwrap().lines().count();
    let expect = ((t[t.len() - 1] - t[0]) * 10.0).round() as usize + 2;
    assert_eq!(rows, expect, "header + one row per 0.1 s over the plan");
    let e = json(&inertia(&["estimate", flight.to_str().unwrap(), "--json"]));
    let truth = [0.31, 0.27, 0.18, -0.006, 0.004, 0.002];
    let pred = std::fs::read_to_string(d.path().join("plan.prediction.csv")).unwrap();
    let last: Vec<f64> = pred
        .lines()
        .last()
        .unwrap()
        .split(',')
        .skip(1)
        .take(6)
        .map(|x| x.parse().unwrap())
        .collect();
    for k in 0..6 {
        let err = (e["j"][k].as_f64().expect("j") - truth[k]).abs();
        assert!(
            err <= 4.0 * last[k],
            "J[{k}]: error {err} vs predicted σ {}",
            last[k]
        );
    }
}

#[test]
fn a_file_without_limits_or_sensors_is_refused_by_key() {
    let d = tempfile::tempdir().unwrap();
    for (from, to, key) in [
        ("max_torque_nm = 0.004\n", "", "rotor[0].max_torque_nm"),
        ("[sensors]", "[sensorz]", "sensorz"),
        ("relative_sigma = 0.05\n", "", "prior"),
    ] {
        let sc = d.path().join("sc.toml");
        std::fs::write(&sc, SC.replacen(from, to, 1)).unwrap();
        let o = inertia(&[
            "plan",
            "--spacecraft",
            sc.to_str().unwrap(),
            "-o",
            d.path().join("p.csv").to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(key), "{key}: {}", stderr(&o));
        assert!(!d.path().join("p.csv").exists());
    }
    // A chain that is neither a length nor `auto` is refused, naming the option.
    let sc = d.path().join("sc.toml");
    std::fs::write(&sc, SC).unwrap();
    for bad in ["fast", "-5", "inf"] {
        let o = inertia(&[
            "plan",
            "--spacecraft",
            sc.to_str().unwrap(),
            "--chain",
            bad,
            "-o",
            d.path().join("p.csv").to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!("--chain \"{bad}\"")),
            "{}",
            stderr(&o)
        );
    }
}

#[test]
fn a_bad_command_file_is_refused_with_its_line() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("c.csv");
    std::fs::write(
        &p,
        "t_s,rho_dot_x_nm,rho_dot_y_nm,rho_dot_z_nm\n0,1e-3,0,0\n1,x,0,0\n",
    )
    .unwrap();
    let o = inertia(&[
        "simulate",
        "--commands",
        p.to_str().unwrap(),
        "-o",
        d.path().join("f.csv").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("c.csv:3:"), "{}", stderr(&o));
}

/// The largest rotation from the first attitude of a telemetry file's quaternions, deg.
fn max_angle_deg(csv: &Path) -> f64 {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (x, y, z, w) = (col("q_x"), col("q_y"), col("q_z"), col("q_w"));
    let q: Vec<nalgebra::UnitQuaternion<f64>> = lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|s| s.parse().unwrap()).collect();
            nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                v[w], v[x], v[y], v[z],
            ))
        })
        .collect();
    q.iter()
        .map(|qk| (q[0].inverse() * qk).angle().to_degrees())
        .fold(0.0, f64::max)
}

#[test]
fn an_attitude_limit_is_kept_in_flight() {
    // Without the limit the plan turns the body by more than 1°; with `max_angle_deg =
    // 1` its flight on the prior J (the simulator's true attitude) stays within the
    // margin of 1° of the start, and the plan reports that use.
    let d = tempfile::tempdir().unwrap();
    let fly = |sc_text: &str, name: &str| -> f64 {
        let sc = d.path().join(format!("{name}.toml"));
        std::fs::write(&sc, sc_text).unwrap();
        let plan = d.path().join(format!("{name}.csv"));
        let o = inertia(&[
            "plan",
            "--spacecraft",
            sc.to_str().unwrap(),
            "--rehearsals",
            "0",
            "-o",
            plan.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let flight = d.path().join(format!("{name}_flight.csv"));
        let o = inertia(&[
            "simulate",
            "--commands",
            plan.to_str().unwrap(),
            "--inertia",
            "0.30:0.28:0.19:-0.005:0.004:0.002",
            "--attitude",
            "truth",
            "--controller-hz",
            "2",
            "-o",
            flight.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        max_angle_deg(&flight)
    };
    let free = fly(SC, "free");
    assert!(free > 1.0, "the unconstrained plan turns {free}°");
    let limited = SC.replace(
        "max_rate_deg_s = 2.0",
        "max_rate_deg_s = 2.0\nmax_angle_deg = 1.0",
    );
    let sc = d.path().join("limited.toml");
    std::fs::write(&sc, &limited).unwrap();
    let o = inertia(&[
        "plan",
        "--spacecraft",
        sc.to_str().unwrap(),
        "--rehearsals",
        "0",
        "-o",
        d.path().join("limited_plan.csv").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let margin = 1.0 / (1.0 + 3.0 * 0.05 * 0.30 / 0.19);
    let used: f64 = stdout(&o)
        .split("angle ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .expect("the angle's use is reported")
        .parse()
        .unwrap();
    assert!(used <= margin + 0.005, "{}", stdout(&o));
    let angle = fly(&limited, "limited");
    assert!(
        angle <= margin * 1.01,
        "flown {angle}° against 1° × margin {margin}"
    );
    // A limit beyond 180° is refused by key.
    let bad = SC.replace(
        "max_rate_deg_s = 2.0",
        "max_rate_deg_s = 2.0\nmax_angle_deg = 200.0",
    );
    std::fs::write(&sc, bad).unwrap();
    let o = inertia(&[
        "plan",
        "--spacecraft",
        sc.to_str().unwrap(),
        "-o",
        d.path().join("bad.csv").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("limits.max_angle_deg"),
        "{}",
        stderr(&o)
    );
}
