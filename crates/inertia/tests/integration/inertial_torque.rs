//! A disturbance torque constant in the inertial frame (estimator::momentum_rows,
//! "Inertial torque"; estimator::trend_slot): recovery of a known J and of the torque
//! when it is hidden from the telemetry, the bias without it, and the recursive state
//! against the independent dense batch reduction.

use inertia::dynamics::GyrostatState;
use inertia::estimator::momentum_rows::{MomentumRowSettings, Stencil};
use inertia::pipeline::{self, InertialTorque, Pipeline, PipelineSettings};
use inertia::sim::scenario::Common;
use inertia::tensor::relative_frobenius_error;
use nalgebra::Vector3;

use crate::discrete_momentum::{final_error, slew_with_hidden_torque};

/// The paper's slew with `common`'s noise and a constant torque fixed in the inertial
/// frame (`C τ_body = τ_I`) acting and left out of the telemetry.
fn slew_with_inertial_torque(
    tau_inertial_nm: Vector3<f64>,
    common: &Common,
) -> inertia::sim::SimOutput {
    slew_with_hidden_torque(common, move |_t: f64, x: &GyrostatState| {
        x.q.conjugate().rotate(&tau_inertial_nm)
    })
}

/// Problem: the slew with a hidden inertial torque of 2–3e-5 N m (about the body-frame
/// torque of `an_unknown_constant_torque_is_estimated_and_does_not_bias_j`). Reference:
/// the simulated J. With the inertial torque unknown the error is at the noise-free
/// floor of the Richardson rows (< 1e-8; measured 3e-10); with only a body-frame torque unknown, which
/// cannot express it, at least 100 times larger (measured 3.6e-3).
#[test]
fn an_unknown_inertial_torque_is_estimated_and_does_not_bias_j() {
    let run = slew_with_inertial_torque(Vector3::new(2e-5, -3e-5, 2.5e-5), &Common::noise_free());
    let rows = |inertial_torque| MomentumRowSettings {
        stencil: Stencil::Smooth,
        inertial_torque,
        ..Default::default()
    };
    let with = final_error(&run.samples, rows(true), &run.inertia_kg_m2);
    let without = final_error(&run.samples, rows(false), &run.inertia_kg_m2);
    assert!(with < 1e-8, "with the inertial torque unknown: {with:e}");
    assert!(
        without > 100.0 * with,
        "body torque only: {without:e} vs {with:e}"
    );
}

/// The pipeline's answer (recursive, and batch) with the inertial torque `mode`: its
/// relative error and whether the chosen rows have the torque.
fn answer(run: &inertia::sim::SimOutput, mode: InertialTorque) -> [(f64, bool); 2] {
    let settings = PipelineSettings {
        inertial_torque: mode,
        ..PipelineSettings::default()
    };
    let mut p = Pipeline::new(&settings).expect("settings");
    for s in &run.samples {
        p.push(s).expect("push");
    }
    let error = |j: &nalgebra::Matrix3<f64>| relative_frobenius_error(j, &run.inertia_kg_m2);
    let last = p.last().and_then(|e| e.inertia()).expect("answer");
    let recursive = (
        error(&last),
        p.diagnostics().row_model.expect("rows").inertial_torque,
    );
    let config = settings.validate().expect("settings");
    let b = pipeline::batch(&run.samples, &config).expect("batch");
    let j = b.estimate.inertia().expect("batch answer");
    let batch = (
        error(&j),
        b.diagnostics.row_model.expect("rows").inertial_torque,
    );
    [recursive, batch]
}

/// Problem: the paper's slew with its sensor noise, with and without a hidden inertial
/// torque of 2–3e-5 N m. Reference: the simulated J and the torque's presence. `auto`
/// takes the torque exactly where it acts (recursive and batch alike); where it acts,
/// its answer is at least 10 times closer than `off`'s, and where it does not, within
/// 1.5 times of `off`'s.
#[test]
fn auto_estimates_the_inertial_torque_where_the_data_need_it() {
    let common = Common::paper();
    for (tau, present) in [
        (Vector3::new(2e-5, -3e-5, 2.5e-5), true),
        (Vector3::zeros(), false),
    ] {
        let run = slew_with_inertial_torque(tau, &common);
        let off = answer(&run, InertialTorque::Off);
        let auto = answer(&run, InertialTorque::Auto);
        for ((e_off, with_off), (e_auto, with_auto)) in off.into_iter().zip(auto) {
            assert!(!with_off);
            assert_eq!(
                with_auto, present,
                "torque {tau:?}: {e_auto:e} vs {e_off:e}"
            );
            if present {
                assert!(e_auto * 10.0 < e_off, "{e_auto:e} vs off {e_off:e}");
            } else {
                assert!(e_auto < 1.5 * e_off, "{e_auto:e} vs off {e_off:e}");
            }
        }
    }
}

/// `auto` compares unweighted fits: with a memory it is refused, naming both settings;
/// `on` with a memory is accepted.
#[test]
fn auto_with_a_memory_is_refused() {
    let with = |mode| PipelineSettings {
        inertial_torque: mode,
        memory_s: Some(60.0),
        ..PipelineSettings::default()
    };
    let e = with(InertialTorque::Auto).validate().map(drop).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("inertial_torque") && text.contains("memory_s"),
        "{text}"
    );
    assert!(with(InertialTorque::On).validate().is_ok());
}

/// The default (`InertialTorque::Short`): on a record shorter than 30 s it tests for a
/// torque fixed in the inertial frame as `auto` does, and on a longer one its answer is
/// `off`'s, J and σ bit for bit, once the record passes 30 s.
#[test]
fn the_default_tests_for_the_torque_on_short_records_only() {
    use inertia::sim::presets::{LabEffect, Preset};
    use inertia::sim::scenario::Scenario;
    let run = |samples: &[inertia::sample::Sample], mode: Option<InertialTorque>| {
        let settings = PipelineSettings {
            inertial_torque: mode.unwrap_or_default(),
            solve_every: 50,
            ..PipelineSettings::default()
        };
        let mut p = Pipeline::new(&settings).expect("settings");
        let mut answers = Vec::new();
        for s in samples {
            if let Some(e) = p.push(s).expect("push") {
                answers.push((s.t_s, e));
            }
        }
        (answers, p.diagnostics().row_model.expect("rows"))
    };
    // A throw with the inertial torque alone: the default answers as `auto`.
    let mut throw = Preset::throw_with(&[LabEffect::InertialTorque]);
    throw.common.seed = 2;
    let out = throw.simulate().expect("simulation");
    let (default, rows) = run(&out.samples, None);
    let (auto, _) = run(&out.samples, Some(InertialTorque::Auto));
    let (off, _) = run(&out.samples, Some(InertialTorque::Off));
    assert!(rows.inertial_torque, "the torque is taken on the throw");
    let last = |a: &[(f64, inertia::estimator::Estimate)]| a.last().expect("answers").1;
    assert_eq!(last(&default), last(&auto));
    let truth = &out.inertia_kg_m2;
    assert_eq!(last(&default).within_3sigma(truth), Some(true));
    let error =
        |e: inertia::estimator::Estimate| relative_frobenius_error(&e.inertia().expect("J"), truth);
    assert!(
        error(last(&default)) < 0.5 * error(last(&off)),
        "{} vs {}",
        error(last(&default)),
        error(last(&off))
    );
    // A 120 s slew: past 30 s every answer is `off`'s.
    let slew = Scenario::slew()
        .simulate(&Common {
            duration_s: Some(120.0),
            ..Common::paper()
        })
        .expect("simulation");
    let (default, rows) = run(&slew.samples, None);
    let (off, _) = run(&slew.samples, Some(InertialTorque::Off));
    assert!(!rows.inertial_torque);
    let mut compared = 0;
    for ((t, a), (_, b)) in default.iter().zip(&off) {
        if *t > 31.0 {
            assert_eq!(a.j(), b.j(), "t = {t}");
            assert_eq!(a.sigma_kg_m2(), b.sigma_kg_m2(), "t = {t}");
            assert_eq!(a.observability.code(), b.observability.code(), "t = {t}");
            compared += 1;
        }
    }
    assert!(compared > 10, "{compared}");
}
