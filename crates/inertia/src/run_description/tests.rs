//! Run descriptions from TOML and JSON: every key, the defaults, errors with file, line
//! and key, and one description over another.

use super::*;
use std::string::ToString;

const ALL: &str = r#"
estimator = "variational"
solver = "native"
batch = false
constraints = "paper"
bounds = ["J33=2.7:3.3", "J12=:0.05"]
diagonal = false
products = "cad"
rotor_scale_sigma = "2%"
every = 3
memory = 120.5
resample = 0.1
gyro_noise = 1e-5
attitude_drift = 0.01
uncertainty = false
rotation_source = "gyro"
rho_model = "held"
glitches = "keep"
torque_bias = false
inertial_torque = "auto"
wheel_delay = 0.05
chain = 0
scalar_first = true
gyro_unit = "deg/s"
negate_rho = true
unit_tolerance = 0.002
period_tolerance = 0.1
columns = { t = "time" }
"#;

fn plain(k: &str) -> String {
    k.to_string()
}

fn no_file(_: &Path, _: Option<ProductConvention>) -> Result<ReadInertia, String> {
    Err("no file here".into())
}

#[test]
fn every_key_reaches_the_settings() {
    let d = RunDescription::parse(ALL, "all.toml", false).unwrap();
    let s = d.pipeline_settings(&plain, &mut no_file).unwrap();
    assert_eq!(s.estimator, "variational");
    assert_eq!(s.constraints.consistency, Consistency::PaperTriangle);
    // A CAD product bound is the tensor entry's negated range.
    assert_eq!(s.constraints.upper_kg_m2[2], Some(3.3));
    assert_eq!(s.constraints.lower_kg_m2[3], Some(-0.05));
    assert_eq!(s.rotor_scale_sigma, Some(0.02));
    assert_eq!(
        (s.solve_every, s.memory_s, s.resample_s),
        (3, Some(120.5), Some(0.1))
    );
    assert_eq!(
        (s.gyro_noise_deg_s_rthz, s.attitude_drift_deg_rth),
        (Some(1e-5), Some(0.01))
    );
    assert!(!s.uncertainty && !s.torque_bias);
    assert_eq!(s.rotation_source, Some(RotationSource::Gyro));
    assert_eq!(s.rho_model, RhoModel::Held);
    assert_eq!(s.glitches, GlitchPolicy::Keep);
    assert_eq!(s.inertial_torque, InertialTorque::Auto);
    assert_eq!(s.wheel_delay, WheelDelay::KnownS(0.05));
    assert_eq!(s.max_chain_s, None);
    let c = d.csv_options(&plain).unwrap();
    assert_eq!(c.quaternion, QuaternionFormat::HamiltonScalarFirst);
    assert_eq!(c.gyro_unit, GyroUnit::DegPerS);
    assert!(c.negate_rho);
    assert_eq!((c.unit_tolerance, c.period_tolerance), (0.002, Some(0.1)));
    assert_eq!(d.given().len(), 27);
}

#[test]
fn an_empty_description_is_the_default_settings() {
    let d = RunDescription::parse("", "empty.toml", false).unwrap();
    assert_eq!(d, RunDescription::default());
    assert!(d.given().is_empty());
    assert_eq!(
        d.pipeline_settings(&plain, &mut no_file).unwrap(),
        PipelineSettings::default()
    );
    assert_eq!(RunDescription::parse("{}", "empty.json", true).unwrap(), d);
}

#[test]
fn errors_name_the_file_the_line_and_the_key() {
    let e = RunDescription::parse("memory = 30\n\nmemroy = 3\n", "run.toml", false).unwrap_err();
    assert_eq!((e.line, e.key.as_deref()), (Some(3), Some("memroy")), "{e}");
    assert_eq!(
        e.to_string(),
        "run.toml:3: `memroy`: unknown key `memroy` (the keys are `inertia estimate`'s long options in snake case)"
    );
    let e =
        RunDescription::parse("every = 2\nrho_model = \"cubic\"\n", "run.toml", false).unwrap_err();
    assert_eq!(
        (e.line, e.key.as_deref()),
        (Some(2), Some("rho_model")),
        "{e}"
    );
    assert!(e.message.contains("auto, smooth, held, plain"), "{e}");
    let e = RunDescription::parse("memory = \"long\"\n", "run.toml", false).unwrap_err();
    assert_eq!((e.line, e.key.as_deref()), (Some(1), Some("memory")), "{e}");
    assert!(e.message.ends_with("expected a number"), "{e}");
    let e = RunDescription::parse("{\n  \"every\": 2,\n  \"chian\": 3\n}", "run.json", true)
        .unwrap_err();
    assert_eq!((e.line, e.key.as_deref()), (Some(3), Some("chian")), "{e}");
    // User text is escaped: the message is one line.
    let e =
        RunDescription::parse("rho_model = \"\\u001b]0;x\\u0007\"\n", "r.toml", false).unwrap_err();
    assert!(!e.to_string().chars().any(char::is_control), "{e:?}");
}

#[test]
fn one_description_over_another() {
    let file = RunDescription::parse("memory = 30\nevery = 2\n", "f.toml", false).unwrap();
    let options = RunDescription {
        every: Some(5),
        ..RunDescription::default()
    };
    let d = file.overridden_by(options);
    assert_eq!((d.memory, d.every), (Some(30.0), Some(5)));
}

#[test]
fn constraint_inputs_need_their_partners() {
    let d = RunDescription::parse("nominal = \"j.json\"\n", "f.toml", false).unwrap();
    let e = d.pipeline_settings(&plain, &mut no_file).unwrap_err();
    assert_eq!(e.to_string(), "nominal: needs tolerance (e.g. 10%)");
    let d = RunDescription::parse(
        "prior = [[1, 0, 0], [0, 2, 0], [0, 0, 3]]\n",
        "f.toml",
        false,
    )
    .unwrap();
    let e = d
        .pipeline_settings(&|k| std::format!("--{}", k.replace('_', "-")), &mut no_file)
        .unwrap_err();
    assert!(e.message.contains("--prior-sigma"), "{e}");
    let e = RunDescription::parse("bounds = \"J44=1:2\"\n", "f.toml", false).unwrap_err();
    assert!(
        e.message.contains("bounds \"J44=1:2\": unknown element"),
        "{e}"
    );
}
