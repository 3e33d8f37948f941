//! The damping block (`PipelineSettings::damping`, `estimator/unknowns.rs`): a torque
//! `−D ω` with `D` one more shared unknown of the discrete momentum rows.
//!
//! * Physics: on throws whose only unmodelled effect is air drag, estimating `D` recovers
//!   it (within 3 of its σ) and J better than without; on a slew with no drag, `D̂` is
//!   zero within its σ and J is unchanged within its σ.
//! * Independent paths: the streaming and the batch runs give the same J and `D`.
//! * The model check: where `D` stands in for a torque fixed in the inertial frame it comes
//!   out negative, which a drag cannot be, and the answer is not determined.

use inertia::estimator::observability::{Observability, Unobservable};
use inertia::fix::Fix;
use inertia::pipeline::{Pipeline, PipelineConfig, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::presets::{LabEffect, Preset, THROW};
use inertia::sim::scenario::{Common, Scenario};
use inertia::tensor::relative_frobenius_error;

fn config(damping: bool) -> PipelineConfig {
    PipelineSettings {
        damping,
        solve_every: 400,
        ..PipelineSettings::default()
    }
    .validate()
    .expect("valid settings")
}

fn streaming(samples: &[Sample], config: PipelineConfig) -> Pipeline {
    let mut p = Pipeline::from_config(config).expect("pipeline");
    for s in samples {
        p.push(s).expect("push");
    }
    p
}

/// The throw with only air drag (and the gyro's noise) besides the ideal gyrostat.
fn drag_only(seed: u64) -> inertia::sim::SimOutput {
    let mut p = Preset::throw_with(&[LabEffect::Drag]);
    p.common.seed = seed;
    p.simulate().expect("valid settings")
}

#[test]
fn damping_recovers_the_drag_and_removes_its_bias() {
    let (mut better, mut within) = (0, 0);
    for seed in 1..=6 {
        let out = drag_only(seed);
        let off = streaming(&out.samples, config(false));
        let on = streaming(&out.samples, config(true));
        let error = |p: &Pipeline| {
            let j = p.last().and_then(|e| e.inertia()).expect("an answer");
            relative_frobenius_error(&j, &out.inertia_kg_m2)
        };
        let (d, sigma) = on.diagnostics().damping_nms.expect("estimated");
        let sigma = sigma.expect("a σ");
        let z = (d - THROW.damping_nms) / sigma;
        eprintln!(
            "seed {seed}: error {:.2e} → {:.2e}, D = {d:.3e} ± {sigma:.1e} (truth {:.1e}, z = {z:.2})",
            error(&off),
            error(&on),
            THROW.damping_nms
        );
        assert!(off.diagnostics().damping_nms.is_none());
        assert!(matches!(
            on.last().expect("answer").observability,
            Observability::Determined { .. }
        ));
        better += usize::from(error(&on) < 0.5 * error(&off));
        within += usize::from(z.abs() <= 3.0);
    }
    // Without D the drag biases J by ~3e-3; with it the error is the noise's.
    assert!(better >= 5, "J at least 2× better in {better} of 6 throws");
    assert!(
        within >= 5,
        "D within 3σ of the truth in {within} of 6 throws"
    );
}

#[test]
fn damping_without_drag_is_zero_within_its_sigma() {
    let mut within = 0;
    for seed in 1..=5 {
        let run = Scenario::slew()
            .simulate(&Common {
                seed,
                duration_s: Some(120.0),
                ..Common::paper()
            })
            .expect("simulation");
        let off = streaming(&run.samples, config(false));
        let on = streaming(&run.samples, config(true));
        let (d, sigma) = on.diagnostics().damping_nms.expect("estimated");
        let sigma = sigma.expect("a σ");
        let (eo, en) = (off.last().expect("answer"), on.last().expect("answer"));
        let (jo, jn) = (eo.j().expect("J"), en.j().expect("J"));
        let s = en.sigma_kg_m2().expect("σ");
        eprintln!("seed {seed}: D = {d:.2e} ± {sigma:.1e}");
        within += usize::from(d.abs() <= 3.0 * sigma);
        for k in 0..6 {
            assert!(
                (jo[k] - jn[k]).abs() <= s[k],
                "seed {seed}, element {k}: {} vs {} (σ {})",
                jo[k],
                jn[k],
                s[k]
            );
        }
    }
    assert!(within >= 4, "D̂ within 3σ of zero in {within} of 5 slews");
}

#[test]
fn a_negative_damping_fails_the_model_check() {
    // An inertial-frame torque and no drag: with the inertial torque not estimated the
    // damping column takes it up, with the wrong sign for a drag.
    let mut p = Preset::throw_with(&[LabEffect::InertialTorque]);
    p.common.seed = 1;
    let out = p.simulate().expect("valid settings");
    let off = PipelineSettings {
        damping: true,
        inertial_torque: inertia::pipeline::InertialTorque::Off,
        solve_every: 400,
        ..PipelineSettings::default()
    }
    .validate()
    .expect("valid settings");
    let on = streaming(&out.samples, off);
    let e = on.last().expect("answer");
    let (d, sigma) = on.diagnostics().damping_nms.expect("estimated");
    eprintln!("D = {d:.3e} ± {:.1e}", sigma.unwrap_or(f64::NAN));
    match e.observability {
        Observability::ModelCheckFailed(r @ Unobservable::NegativeDamping { .. }) => {
            assert_eq!(r.fixes(), &[Fix::InertialTorqueOn]);
        }
        other => panic!("expected a failed model check, got {other}"),
    }
    // The same data with the inertial torque estimated: no such failure.
    let c = PipelineSettings {
        damping: true,
        inertial_torque: inertia::pipeline::InertialTorque::On,
        solve_every: 400,
        ..PipelineSettings::default()
    }
    .validate()
    .expect("valid settings");
    let both = streaming(&out.samples, c);
    assert!(!matches!(
        both.last().expect("answer").observability,
        Observability::ModelCheckFailed(Unobservable::NegativeDamping { .. })
    ));
}

#[test]
fn damping_is_refused_by_estimators_without_a_row_model() {
    let e = PipelineSettings {
        estimator: "variational".into(),
        damping: true,
        ..PipelineSettings::default()
    }
    .validate()
    .expect_err("not applicable");
    assert!(e.to_string().contains("damping"), "{e}");
}

/// The final answer of a run with `--damping` (streaming, or batch) as the lab cells run
/// it (`examples/matrix.rs`, `DAMPING=1`).
fn damped_run(samples: &[Sample], batch: bool) -> inertia::estimator::Estimate {
    let config = PipelineSettings {
        damping: true,
        solve_every: 50,
        ..PipelineSettings::default()
    }
    .validate()
    .expect("valid settings");
    let mut run = inertia::pipeline::Run::new(config, batch).expect("run");
    let mut last = None;
    for s in samples {
        run.push(s, |e| last = Some(*e)).expect("push");
    }
    run.finish(|e| last = Some(*e)).expect("finish");
    last.expect("an estimate")
}

/// Problem: throws whose gyro vibrates at the rotor's frequency, with no drag, run with
/// `--damping`, streaming and batch, seeds 1–20 (the lab cell "only vibration").
/// Reference: the simulated J. `D` takes up part of the vibration; the data cannot tell
/// the model with it from the one with `D` held at zero (residual variances within
/// `1 + 3√(2/ν)`), so σ carries the move of J between the two
/// (`RecursiveQr::holding_at_zero`, the model spread). Before it did, the streaming
/// answers of seeds 3, 17 and 19 were determined with J13 3–4σ off; now every answer is
/// determined and holds the truth within 3σ in every element.
#[test]
fn the_model_without_the_drag_widens_sigma_where_the_data_cannot_rule_it_out() {
    for seed in 1..=20 {
        let mut p = Preset::throw_with(&[LabEffect::Vibration]);
        p.common.seed = seed;
        let out = p.simulate().expect("valid settings");
        for batch in [false, true] {
            let e = damped_run(&out.samples, batch);
            let what = format!("seed {seed}, batch {batch}");
            assert!(
                matches!(e.observability, Observability::Determined { .. }),
                "{what}: {}",
                e.observability
            );
            assert_eq!(
                e.within_3sigma(&out.inertia_kg_m2),
                Some(true),
                "{what}: {:?} ± {:?}",
                e.j(),
                e.sigma_kg_m2()
            );
        }
    }
}

/// The answer of [`damped_run`] on the lab throw with every effect and a drawn tumble
/// (`seed`), after checking that it holds the simulated J within 3σ in every element.
fn drawn_throw_within_3sigma(seed: u64, batch: bool) -> inertia::estimator::Estimate {
    let mut p = Preset::throw().with_drawn_tumble(seed);
    p.common.seed = seed;
    let out = p.simulate().expect("simulation");
    let e = damped_run(&out.samples, batch);
    assert_eq!(
        e.within_3sigma(&out.inertia_kg_m2),
        Some(true),
        "seed {seed}, batch {batch}: {:?} ± {:?}",
        e.j(),
        e.sigma_kg_m2()
    );
    e
}

/// Problem: lab throws with every effect, each tumbling its own way, their wheel speeds
/// held between updates and no time tag asked for, run with `--damping` in batch.
/// Reference: the simulated J. Without a time tag σ carries the move of J that the held
/// speeds' mean lag makes; the plain profile fit that measures it has no `D`, which takes
/// up part of the lag's signature, so with `--damping` the estimator's own move (its
/// batch solve with the speeds read that much later, pinned to its row model) counts as
/// well. Before it did, seeds 5001, 5003 and 5006 were determined with a diagonal element
/// 4.5–6.2σ off (`examples/throw_sigma.rs`, `DAMPING=1`: 40 of 62 batch answers
/// determined beyond 3σ over seeds 5000–5199, 0 of 38 after).
/// Now each holds the truth within 3σ in every element: 5003 determined, 5001 and 5006
/// withheld with most of σ from the time tag (the reason says which part: give the
/// time tag).
#[test]
fn with_damping_the_held_speeds_lag_term_is_the_estimators_own_move() {
    let mut determined = 0;
    for seed in [5001, 5003, 5006] {
        let e = drawn_throw_within_3sigma(seed, true);
        match e.observability {
            Observability::Determined { .. } => determined += 1,
            Observability::NotObservable(Unobservable::Uncertain { dominant, .. }) => {
                assert_eq!(
                    dominant,
                    inertia::estimator::uncertainty::SigmaPart::TimeTag,
                    "seed {seed}"
                );
            }
            other => panic!("seed {seed}: {other}"),
        }
    }
    assert!(determined >= 1, "{determined} of 3 determined");
}

/// Problem: the same lab throws, streaming: the seeds whose streaming answer was
/// determined beyond 3σ when the held speeds' lag term was the batch solve's move
/// (`examples/throw_sigma.rs`, `DAMPING=1`, seeds 10000–10199: 6 of 23 determined
/// answers; their `D` hundreds of its σ from the drag, taking up the lag with the
/// inertial torque, and the batch solve, pinned to the same row model, moved less).
/// Reference: the simulated J. The streaming run's own move counts as well (its pipeline
/// run again over the samples it keeps, with the speeds read one mean lag later): every
/// answer holds the truth within 3σ in every element (measured: 0 of 22 determined
/// answers beyond 3σ on 10000–10199, and 0 of 22 on 5000–5199), and most are still
/// determined.
#[test]
fn streaming_with_damping_the_held_speeds_lag_term_is_its_own_move() {
    let mut determined = 0;
    let seeds = [10013, 10027, 10085, 10139, 10149, 10175];
    for seed in seeds {
        let e = drawn_throw_within_3sigma(seed, false);
        determined += usize::from(matches!(e.observability, Observability::Determined { .. }));
    }
    assert!(
        determined >= 4,
        "{determined} of {} determined",
        seeds.len()
    );
}
