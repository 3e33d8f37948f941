//! Rows and options the reader refuses: each error names the file, the line and the field, and the baselines' required columns.

use super::*;

#[test]
fn bad_number() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "num", 5, &|l| field(l, 2, "abc"));
    assert_bad(&p, &[], &["num.csv:5", "`q_y`", "\"abc\""]);
}

#[test]
fn nan_value() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "nan", 7, &|l| field(l, 6, "NaN"));
    assert_bad(&p, &[], &["nan.csv:7", "`rho_y`", "not finite"]);
}

#[test]
fn missing_column() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "miss", 1, &|l| l.replace("rho_z", "rho_q"));
    assert_bad(&p, &[], &["miss.csv:1", "missing column `rho_z`"]);
}

#[test]
fn non_unit_quaternion() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "unit", 9, &|l| field(l, 4, "0.9"));
    assert_bad(&p, &[], &["unit.csv:9", "q_x,q_y,q_z,q_w", "norm"]);
}

#[test]
fn non_increasing_time() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "time", 6, &|l| field(l, 0, "0.1"));
    assert_bad(&p, &[], &["time.csv:6", "`t`", "does not increase"]);
}

#[test]
fn non_uniform_period() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "period", 6, &|l| field(l, 0, "0.43"));
    // Irregular steps are accepted by default; strict mode rejects them.
    assert_bad(
        &p,
        &["--period-tolerance", "1e-3"],
        &["period.csv:6", "`t`", "sample period"],
    );
    let o = inertia(&["estimate", p.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn step_too_large() {
    let d = tempfile::tempdir().unwrap();
    // 180° about x relative to its neighbours.
    let p = bad_file(d.path(), "step", 8, &|l| {
        let l = field(l, 1, "1");
        let l = field(&l, 2, "0");
        let l = field(&l, 3, "0");
        field(&l, 4, "0")
    });
    assert_bad(&p, &[], &["step.csv:8", "q_x,q_y,q_z,q_w", "too long"]);
    // The line is the one that ends the step, also when resampling reads ahead, and the
    // step's times print without float noise.
    for e in ["variational", "discrete-momentum"] {
        assert_bad(
            &p,
            &["--resample", "0.1", "--estimator", e],
            &["step.csv:8", "s to t = 0.6 s gives"],
        );
    }
}

#[test]
fn malformed_row() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "mal", 4, &|l| format!("{l},1,2"));
    assert_bad(&p, &[], &["mal.csv:4", "malformed"]);
}

#[test]
fn missing_file_and_bad_options() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("nope.csv");
    assert_io_error(
        &["estimate", p.to_str().unwrap()],
        &["cannot read", "nope.csv"],
    );
    let ok = simulate(d.path(), "ok", "slew", "2");
    assert_bad(&ok, &["--bound", "J33=3.3:2.7"], &["J33", "contradict"]);
    assert_bad(
        &ok,
        &["--bound", "J44=1:2"],
        &["--bound", "unknown element"],
    );
    assert_bad(
        &ok,
        &[
            "--bound", "J11=:1", "--bound", "J22=:1", "--bound", "J33=3:",
        ],
        &["no inertia satisfies"],
    );
    // Usage errors come from clap, also with exit code 2.
    let o = inertia(&["estimate", ok.to_str().unwrap(), "--estimator", "magic"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn gyro_columns_required_by_the_baselines() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "nogyro", 1, &|l| {
        l.replace("w_x", "a")
            .replace("w_y", "b")
            .replace("w_z", "c")
    });
    assert_bad(
        &p,
        &["--estimator", "momentum"],
        &["nogyro.csv:1", "w_x,w_y,w_z"],
    );
    // The variational estimator does not need them.
    let o = inertia(&["estimate", p.to_str().unwrap()]);
    assert_ne!(o.status.code(), Some(1), "{}", stderr(&o));
}

#[test]
fn unobservable_data_are_reported_not_estimated() {
    let d = tempfile::tempdir().unwrap();
    // The spin case before its wheel pulse, without the J33 bound: y ≡ 0.
    let csv = simulate(d.path(), "spin", "spin", "20");
    let o = inertia(&["estimate", csv.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["status"], "not_observable");
    assert!(v["j"].is_null());
    assert!(v["reason"].as_str().unwrap().contains("up to scale"));
    let advice = v["excitation"]["advice"].as_array().unwrap();
    assert!(advice[0]
        .as_str()
        .unwrap()
        .contains("reaction-wheel momentum change"));
    assert_eq!(
        v["excitation"]["singular_values"].as_array().unwrap().len(),
        6
    );
    let o = inertia(&["estimate", csv.to_str().unwrap()]);
    assert!(stdout(&o).contains("NOT OBSERVABLE"));
}
