//! The spacecraft file: problem/reference pairs and every refusal.

use super::*;

const GOOD: &str = r#"
rotor_errors = "independent"

[[rotor]]
name = "rw1"
axis = [1.0, 0.0, 0.0]
spin_inertia_kg_m2 = 1.0e-3
spin_inertia_sigma_kg_m2 = 2.0e-5
speed_column = "rw1_speed"
speed_unit = "rpm"

[[rotor]]
name = "rw2"
axis = [0.0, 0.6, 0.8]
spin_inertia_kg_m2 = 2.0e-3
speed_column = "rw2_speed"
"#;

#[test]
fn a_good_file_is_read_with_its_units_and_defaults() {
    let s = Spacecraft::parse(GOOD, "sc.toml").unwrap();
    assert_eq!(s.rotor_errors, RotorErrors::Independent);
    assert_eq!(s.rotors.len(), 2);
    assert_eq!(s.rotors[0].speed_unit, SpeedUnit::Rpm);
    assert_eq!(s.rotors[1].speed_unit, SpeedUnit::RadPerS);
    assert_eq!(s.rotors[1].spin_inertia_sigma_kg_m2, 0.0);
    assert!((s.rotors[0].relative_sigma() - 0.02).abs() < 1e-15);
    assert!(s.has_inertia_sigma());
    // 60 rpm = 2π rad/s on rw1; 10 rad/s on rw2.
    let rho = s.momentum_nms(&[60.0, 10.0]);
    let expected = Vector3::new(
        1e-3 * 2.0 * core::f64::consts::PI,
        2e-3 * 10.0 * 0.6,
        2e-3 * 10.0 * 0.8,
    );
    assert!((rho - expected).norm() < 1e-15, "{rho} vs {expected}");
    assert_eq!(s.speed_columns(), ["rw1_speed", "rw2_speed"]);
    assert_eq!(s.rotors[0].time_tag_sigma_s, 0.0);
    // A time tag's σ alone is an uncertainty of the rotors.
    let tagged = GOOD
        .replace("spin_inertia_sigma_kg_m2 = 2.0e-5\n", "")
        .replace(
            "speed_unit = \"rpm\"",
            "speed_unit = \"rpm\"\ntime_tag_sigma_s = 0.02",
        );
    let t = Spacecraft::parse(&tagged, "sc.toml").unwrap();
    assert_eq!(t.rotors[0].time_tag_sigma_s, 0.02);
    assert!(t.has_inertia_sigma());
}

#[test]
fn an_axis_within_tolerance_is_normalised() {
    let text = GOOD.replace("[0.0, 0.6, 0.8]", "[0.0, 0.6, 0.8005]");
    let s = Spacecraft::parse(&text, "sc.toml").unwrap();
    assert!((Vector3::from(s.rotors[1].axis).norm() - 1.0).abs() < 1e-15);
    assert_eq!(
        Spacecraft::parse(&text, "sc.toml").unwrap().rotor_errors,
        RotorErrors::Independent
    );
    let shared = GOOD.replace("rotor_errors = \"independent\"\n", "");
    assert_eq!(
        Spacecraft::parse(&shared, "sc.toml").unwrap().rotor_errors,
        RotorErrors::Shared
    );
}

/// Each bad file's message names the file, the line and the key.
#[test]
fn bad_files_are_refused_with_file_line_and_key() {
    let cases: &[(&str, &str, &str)] = &[
        ("[0.0, 0.6, 0.8]", "[0.0, 0.6, 0.9]", "sc.toml:14: `rotor[1].axis`: not a unit vector"),
        ("spin_inertia_kg_m2 = 2.0e-3", "spin_inertia_kg_m2 = -2.0e-3", "sc.toml:15: `rotor[1].spin_inertia_kg_m2`: -0.002 is not a spin inertia"),
        ("spin_inertia_sigma_kg_m2 = 2.0e-5", "spin_inertia_sigma_kg_m2 = 2.0e-3", "sc.toml:8: `rotor[0].spin_inertia_sigma_kg_m2`: 0.002 must be at least 0 and less than"),
        ("speed_unit = \"rpm\"", "speed_unit = \"RPM\"", "sc.toml:10: `rotor[0].speed_unit`: \"RPM\" is not one of rad/s, rpm, deg/s"),
        ("rotor_errors = \"independent\"", "rotor_errors = \"both\"", "sc.toml:2: `rotor_errors`: \"both\" is not one of"),
        ("rw2_speed", "rw1_speed", "sc.toml:16: `rotor[1].speed_column`: rotor[0] reads the same column"),
        ("name = \"rw2\"", "name = \"rw1\"", "sc.toml:13: `rotor[1].name`: rotor[0] has the same name"),
        ("speed_unit = \"rpm\"", "speed_units = \"rpm\"", "sc.toml:10: `speed_units`: unknown field"),
        ("speed_column = \"rw2_speed\"", "", "missing field `speed_column`"),
        ("spin_inertia_kg_m2 = 1.0e-3", "spin_inertia_kg_m2 = \"heavy\"", "sc.toml:7: `spin_inertia_kg_m2`:"),
        ("speed_unit = \"rpm\"", "speed_unit = \"rpm\"\ntime_tag_sigma_s = 0.5", "sc.toml:11: `rotor[0].time_tag_sigma_s`: 0.5 must be at least 0 and at most 0.25 s"),
        ("speed_unit = \"rpm\"", "speed_unit = \"rpm\"\ntime_tag_sigma_s = -0.01", "sc.toml:11: `rotor[0].time_tag_sigma_s`: -0.01 must be at least 0"),
    ];
    for (from, to, expected) in cases {
        let text = GOOD.replace(from, to);
        assert_ne!(text, GOOD, "{from}");
        let e = Spacecraft::parse(&text, "sc.toml").unwrap_err().to_string();
        assert!(
            e.starts_with("sc.toml:") && e.contains(expected),
            "{to}: {e}"
        );
        assert!(!e.contains('\n'), "one line: {e:?}");
    }
    let e = Spacecraft::parse("rotor_errors = \"shared\"\n", "sc.toml").unwrap_err();
    assert!(e.to_string().contains("no rotor"), "{e}");
    let many: String = (0..=MAX_ROTORS)
        .map(|i| format!("[[rotor]]\nname = \"r{i}\"\naxis = [1.0, 0.0, 0.0]\nspin_inertia_kg_m2 = 1.0\nspeed_column = \"c{i}\"\n"))
        .collect();
    let e = Spacecraft::parse(&many, "sc.toml").unwrap_err();
    assert!(e.to_string().contains("at most 16"), "{e}");
}

#[test]
fn control_characters_in_a_file_are_escaped() {
    let text = GOOD.replace(
        "speed_unit = \"rpm\"",
        "speed_unit = \"\u{1b}]0;pwned\u{7}\"",
    );
    let e = Spacecraft::parse(&text, "sc.toml").unwrap_err().to_string();
    assert!(!e.contains('\u{1b}') && !e.contains('\u{7}'), "{e:?}");
}

#[test]
fn a_missing_file_is_named() {
    let e = Spacecraft::load(std::path::Path::new("/nonexistent/sc.toml")).unwrap_err();
    assert!(e.to_string().starts_with("/nonexistent/sc.toml:"), "{e}");
}

const PLANNABLE: &str = r#"
[[rotor]]
name = "rw1"
axis = [1.0, 0.0, 0.0]
spin_inertia_kg_m2 = 1.0e-4
speed_column = "rw1_speed"
max_torque_nm = 0.01
max_momentum_nms = 0.046

[prior]
inertia_kg_m2 = [[0.28, 0.005, 0.0], [0.005, 0.245, 0.0], [0.0, 0.0, 0.17]]
relative_sigma = 0.1

[sensors]
gyro_noise_deg_s_rthz = 0.0057
telemetry_hz = 10.0
controller_hz = 1.0

[limits]
max_rate_deg_s = 5.0
max_angle_deg = 20.0
"#;

#[test]
fn the_plan_keys_are_read() {
    let s = Spacecraft::parse(PLANNABLE, "sc.toml").unwrap();
    assert_eq!(s.rotors[0].max_torque_nm, Some(0.01));
    assert_eq!(s.rotors[0].max_momentum_nms, Some(0.046));
    let p = s.prior.unwrap();
    assert_eq!(p.inertia_kg_m2[0][1], 0.005);
    // Relative σ of the largest moment, for every element.
    assert!((p.sigma_kg_m2[4] - 0.028).abs() < 1e-15);
    let v = s.sensors.unwrap();
    assert_eq!(
        (v.telemetry_hz, v.controller_hz, v.wheel_noise_nms),
        (10.0, 1.0, 0.0)
    );
    assert_eq!(s.max_rate_deg_s, Some(5.0));
    assert_eq!(s.max_angle_deg, Some(20.0));
    // The files without them read as before.
    let g = Spacecraft::parse(GOOD, "sc.toml").unwrap();
    assert!(g.prior.is_none() && g.sensors.is_none() && g.max_rate_deg_s.is_none());
    assert_eq!(g.rotors[0].max_torque_nm, None);
}

#[test]
fn bad_plan_keys_are_refused_with_line_and_key() {
    let cases = [
        (
            "max_torque_nm = 0.01",
            "max_torque_nm = -1",
            7,
            "rotor[0].max_torque_nm",
        ),
        (
            "[[0.28, 0.005, 0.0], [0.005, 0.245, 0.0], [0.0, 0.0, 0.17]]",
            "[[0.28, 0.5, 0.0], [0.005, 0.245, 0.0], [0.0, 0.0, 0.17]]",
            11,
            "prior.inertia_kg_m2",
        ),
        (
            "controller_hz = 1.0",
            "controller_hz = 3.0",
            17,
            "sensors.controller_hz",
        ),
        (
            "telemetry_hz = 10.0",
            "telemetry_hz = 0",
            16,
            "sensors.telemetry_hz",
        ),
        (
            "max_rate_deg_s = 5.0",
            "max_rate_deg_s = nan",
            20,
            "limits.max_rate_deg_s",
        ),
        (
            "max_angle_deg = 20.0",
            "max_angle_deg = 181.0",
            21,
            "limits.max_angle_deg",
        ),
        (
            "max_angle_deg = 20.0",
            "max_angle_deg = -1.0",
            21,
            "limits.max_angle_deg",
        ),
        ("relative_sigma = 0.1", "", 11, "prior"),
    ];
    for (from, to, line, key) in cases {
        let text = PLANNABLE.replace(from, to);
        let e = Spacecraft::parse(&text, "sc.toml").unwrap_err();
        assert_eq!(e.line, Some(line), "{key}: {e}");
        assert_eq!(e.key.as_deref(), Some(key), "{e}");
    }
    let e = Spacecraft::parse(&PLANNABLE.replace("[limits]", "[limitz]"), "sc.toml").unwrap_err();
    assert!(e.to_string().contains("limitz"), "{e}");
}

const THRUSTERS: &str = r#"
[[thruster]]
name = "t1"
position_m = [0.0, 0.3, 0.0]
direction = [0.0, 0.0, 1.0]
thrust_n = 0.02
column = "t1_throttle"

[[thruster]]
name = "t2"
position_m = [0.3, 0.0, 0.0]
direction = [0.0, 1.0, 0.0]
thrust_n = 0.5
column = "t2_throttle"
"#;

#[test]
fn thrusters_alone_are_a_spacecraft_and_give_force_and_torque_about_the_origin() {
    let s = Spacecraft::parse(THRUSTERS, "sc.toml").unwrap();
    assert!(s.rotors.is_empty());
    assert_eq!(s.thruster_columns(), ["t1_throttle", "t2_throttle"]);
    let (f, tau) = thrusters::force_and_torque(&s.thrusters, &[0.5, 1.0]);
    // t1: 0.01 N along z at 0.3 y → torque 0.003 about x; t2: 0.5 N along y at 0.3 x →
    // 0.15 about z.
    assert!((f - Vector3::new(0.0, 0.5, 0.01)).norm() < 1e-15, "{f}");
    assert!(
        (tau - Vector3::new(0.003, 0.0, 0.15)).norm() < 1e-15,
        "{tau}"
    );
}

#[test]
fn a_bad_thruster_is_refused_with_its_line_and_key() {
    let bad = THRUSTERS.replace("direction = [0.0, 1.0, 0.0]", "direction = [0.0, 2.0, 0.0]");
    let e = Spacecraft::parse(&bad, "sc.toml").unwrap_err().to_string();
    assert!(
        e.starts_with("sc.toml:12: `thruster[1].direction`: not a unit vector"),
        "{e}"
    );
    let twice = THRUSTERS.replace("t2_throttle", "t1_throttle");
    let e = Spacecraft::parse(&twice, "sc.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`thruster[1].column`: thruster[0] reads the same column"),
        "{e}"
    );
    let e = Spacecraft::parse("rotor_errors = \"shared\"\n", "sc.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("no rotor and no thruster"), "{e}");
}
