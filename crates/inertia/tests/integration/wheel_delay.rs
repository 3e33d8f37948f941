//! The wheel-speed telemetry's time tag through the run every front end shares
//! (`PipelineSettings::wheel_delay`, `estimator::wheel_delay`): speeds held at 100 Hz on
//! the 4 kHz lab throw lag by 4.9 ms on average, and wheel speeds time-tagged 50 ms late
//! on the 10 Hz slew; given or estimated, the time tag takes the answer back to the
//! truth, and the truth stays within 3σ.

use inertia::estimator::wheel_delay::WheelDelay;
use inertia::estimator::Estimate;
use inertia::pipeline::{PipelineError, PipelineSettings, Run};
use inertia::sample::Sample;
use inertia::sim::presets::{LabEffect, Preset};
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{Realism, WheelTelemetry};
use inertia::tensor::relative_frobenius_error;
use nalgebra::Matrix3;

/// The final estimate of a run of the default estimator with `delay`, streaming or batch.
/// A run of the default estimator with `delay`, streaming or batch.
fn new_run(delay: WheelDelay, batch: bool) -> Run {
    let config = PipelineSettings {
        wheel_delay: delay,
        ..PipelineSettings::default()
    }
    .validate()
    .expect("settings");
    Run::new(config, batch).expect("run")
}

fn run(samples: &[Sample], delay: WheelDelay, batch: bool) -> (Estimate, Run) {
    let mut r = new_run(delay, batch);
    let mut last = None;
    for s in samples {
        r.push(s, |e| last = Some(*e)).expect("push");
    }
    r.finish(|e| last = Some(*e)).expect("finish");
    (last.expect("an estimate"), r)
}

/// The throw with only its speed telemetry's hold (and quantisation), seed `seed`.
fn held_throw(seed: u64) -> inertia::sim::SimOutput {
    let mut p = Preset::throw_without(&[
        LabEffect::Vibration,
        LabEffect::InertialTorque,
        LabEffect::Drag,
    ]);
    p.common.seed = seed;
    p.simulate().expect("sim")
}

fn determined(e: &Estimate) -> bool {
    matches!(
        e.observability,
        inertia::estimator::observability::Observability::Determined { .. }
    )
}

/// `e` holds `truth` within 3σ in every element (`what` names the run).
fn assert_holds_truth(e: &Estimate, truth: &Matrix3<f64>, what: &str) {
    assert_eq!(
        e.within_3sigma(truth),
        Some(true),
        "{what}: {:?} ± {:?}",
        e.j(),
        e.sigma_kg_m2()
    );
}

fn error(e: &Estimate, truth: &Matrix3<f64>) -> f64 {
    relative_frobenius_error(&e.inertia().expect("answer"), truth)
}

/// Problem: the throw with only its speed telemetry's hold (and quantisation), seeds 1–3.
/// Reference: the simulated J. Without the time tag the default is 3 % off (measured
/// 3.0–3.2e-2); with it estimated, 20× closer (7e-4–1.5e-3), the tag within 0.2 ms of the
/// mean lag 4.875 ms, and the truth within 3σ of every element.
#[test]
fn an_estimated_time_tag_undoes_the_lag_of_held_speed_telemetry() {
    for seed in 1..=3 {
        let out = held_throw(seed);
        let truth = out.inertia_kg_m2;
        let (off, _) = run(&out.samples, WheelDelay::Off, false);
        let (on, r) = run(&out.samples, WheelDelay::Estimate, false);
        let fit = r.wheel_delay().expect("applied").expect("estimated");
        assert!((fit.delay_s - 4.875e-3).abs() < 2e-4, "{fit:?}");
        assert!(error(&off, &truth) > 2e-2, "{}", error(&off, &truth));
        assert!(error(&on, &truth) < 2e-3, "{}", error(&on, &truth));
        assert_eq!(on.within_3sigma(&truth), Some(true), "seed {seed}");
        let widened = on.uncertainty.expect("σ").time_tag_kg_m2;
        assert!(widened.iter().all(|&c| c > 0.0), "{widened:?}");
    }
}

/// Problem: the 10 Hz slew (120 s) with the wheel speeds time-tagged 50 ms late.
/// Reference: the same data without the late tag (1.1e-6). Measured: late and
/// uncorrected 10× and more above it; the known tag within 2× of it; the estimated one
/// (streaming and batch) within 5× (4.3e-6): the profile's plain rows find the tag
/// 50 µs short at 10 Hz (their O(h²) bias, also −50 µs on on-time data), within its 3σ.
#[test]
fn a_given_or_estimated_time_tag_matches_on_time_telemetry() {
    let sim = |late_s: f64| {
        Scenario::slew()
            .simulate(&Common {
                duration_s: Some(120.0),
                realism: Realism {
                    wheels: WheelTelemetry {
                        skew_s: -late_s,
                        ..WheelTelemetry::default()
                    },
                    ..Realism::default()
                },
                ..Common::physical()
            })
            .expect("sim")
    };
    let (late, on_time) = (sim(0.05), sim(0.0));
    let truth = on_time.inertia_kg_m2;
    let reference = error(&run(&on_time.samples, WheelDelay::Off, false).0, &truth);
    let uncorrected = error(&run(&late.samples, WheelDelay::Off, false).0, &truth);
    let given = error(
        &run(&late.samples, WheelDelay::KnownS(0.05), false).0,
        &truth,
    );
    let (estimated, r) = run(&late.samples, WheelDelay::Estimate, false);
    let (batch, _) = run(&late.samples, WheelDelay::Estimate, true);
    let fit = r.wheel_delay().expect("applied").expect("estimated");
    assert!(
        (fit.delay_s - 0.05).abs() < 3.0 * fit.sigma_s + 1e-4,
        "{fit:?}"
    );
    assert!(
        uncorrected > 10.0 * reference,
        "{uncorrected} vs {reference}"
    );
    assert!(given < 2.0 * reference, "given: {given} vs {reference}");
    for (what, e) in [
        ("estimated", error(&estimated, &truth)),
        ("batch", error(&batch, &truth)),
    ] {
        assert!(e < 5.0 * reference, "{what}: {e} vs {reference}");
    }
    assert_eq!(estimated.within_3sigma(&truth), Some(true));
}

/// API misuse: a time tag that is not finite or beyond the search's 0.25 s is refused by
/// name; one that cannot be estimated leaves the speeds as tagged and says why.
#[test]
fn refuses_a_wild_time_tag_and_reports_one_it_cannot_estimate() {
    for d in [f64::NAN, 1.0, -0.3] {
        let e = PipelineSettings {
            wheel_delay: WheelDelay::KnownS(d),
            ..PipelineSettings::default()
        }
        .validate()
        .expect_err("refused");
        assert!(
            matches!(
                e,
                PipelineError::InvalidSetting {
                    field: "wheel_delay",
                    ..
                }
            ),
            "{e:?}"
        );
    }
    let mut s = Scenario::spin()
        .simulate(&Common {
            duration_s: Some(60.0),
            ..Common::physical()
        })
        .expect("sim")
        .samples;
    for x in &mut s {
        x.rho_nms = nalgebra::Vector3::new(0.2, 0.0, 0.1);
    }
    let (_, r) = run(&s, WheelDelay::Estimate, false);
    assert!(r.wheel_delay().expect("asked").is_err());
}

/// Problem: speeds held at 100 Hz on the 4 kHz throw, and the 10 Hz slew's speeds as
/// telemetered at every sample. Reference: the simulator's update period (40 samples).
/// A run without a time tag names the held speeds' period (the report's
/// `held_wheel_speeds` warning), not the slew's; a run given a time tag says nothing.
#[test]
fn held_speeds_are_named_where_no_time_tag_is_given() {
    let throw = held_throw(1).samples;
    let slew = Scenario::slew()
        .simulate(&Common::physical())
        .expect("sim")
        .samples;
    assert_eq!(
        run(&throw, WheelDelay::Off, false)
            .1
            .held_speeds_period_samples(),
        Some(40)
    );
    assert_eq!(
        run(&throw, WheelDelay::Estimate, false)
            .1
            .held_speeds_period_samples(),
        None
    );
    assert_eq!(
        run(&slew, WheelDelay::Off, false)
            .1
            .held_speeds_period_samples(),
        None
    );
}

/// Problem: the slew read with a given time tag by the run, against the same samples
/// shifted first (`shift_rho`) and read without one. Reference: the latter. The answers
/// agree to rounding and every estimate arrives (at the end); an error the run meets
/// while it replays the held samples names the same sample as a run that streams them.
#[test]
fn a_given_time_tag_is_the_shift_and_errors_name_the_same_sample() {
    let mut samples = Scenario::slew()
        .simulate(&Common {
            duration_s: Some(60.0),
            ..Common::physical()
        })
        .expect("sim")
        .samples;
    let mut shifted = samples.clone();
    inertia::estimator::wheel_delay::shift_rho(&mut shifted, 0.03);
    let (given, _) = run(&samples, WheelDelay::KnownS(0.03), false);
    let (reference, _) = run(&shifted, WheelDelay::Off, false);
    let (a, b) = (given.j().expect("J"), reference.j().expect("J"));
    assert!((a - b).norm() <= 1e-12 * b.norm(), "{a} vs {b}");
    let count = |delay| {
        let mut r = new_run(delay, false);
        let mut n = 0;
        for s in &shifted {
            r.push(s, |_| n += 1).expect("push");
        }
        r.finish(|_| n += 1).expect("finish");
        n
    };
    assert_eq!(count(WheelDelay::KnownS(0.0)), count(WheelDelay::Off));
    // A half-turn of the attitude between two samples: a step too large for the rows.
    let bad = 300;
    let flip = nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::x_axis(), 3.0);
    for s in &mut samples[bad..] {
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            s.q.to_wxyz()[0],
            s.q.to_wxyz()[1],
            s.q.to_wxyz()[2],
            s.q.to_wxyz()[3],
        ));
        let r = q * flip;
        s.q = inertia::attitude::Quaternion::from_wxyz([r.w, r.i, r.j, r.k]);
    }
    let error_at = |delay| {
        let mut r = new_run(delay, false);
        for s in &samples {
            if let Err(e) = r.push(s, |_| {}) {
                return e.sample;
            }
        }
        r.finish(|_| {}).err().and_then(|e| e.sample)
    };
    let streamed = error_at(WheelDelay::Off);
    assert_eq!(streamed, Some(bad), "the sample that ends the step");
    assert_eq!(error_at(WheelDelay::KnownS(0.03)), streamed);
}

/// Problem: the throw with only its speed telemetry's hold (seeds 1–3), read without a
/// time tag, and the 10 Hz slew, whose speeds are not held. Reference: the simulated J.
/// The final answer's σ carries the move of J for the held speeds' mean lag
/// (`Uncertainty::time_tag_kg_m2`, the report's warning says so), batch and streaming:
/// on the throw it is of the size of the lag's bias (measured: the answer's error over
/// the term's Frobenius norm 1.01–1.05 batch) and the truth is within 3σ. A streaming
/// run gives its last answer once more, widened, at the end of the input (earlier
/// answers carry no term). The slew carries none.
#[test]
fn the_final_answer_carries_the_held_speeds_lag_in_sigma() {
    let frobenius = |c: [f64; 6]| {
        (c[..3].iter().map(|x| x * x).sum::<f64>()
            + 2.0 * c[3..].iter().map(|x| x * x).sum::<f64>())
        .sqrt()
    };
    for seed in 1..=3 {
        let out = held_throw(seed);
        let truth = out.inertia_kg_m2;
        let (batch, r) = run(&out.samples, WheelDelay::Off, true);
        let u = batch.uncertainty.expect("σ");
        let term = frobenius(u.time_tag_kg_m2);
        let ratio = (batch.inertia().expect("answer") - truth).norm() / term;
        assert!(
            (0.5..2.0).contains(&ratio),
            "seed {seed}: error / term {ratio}"
        );
        assert_eq!(batch.within_3sigma(&truth), Some(true), "seed {seed}");
        let report = r.report("throw.csv", &Default::default()).expect("report");
        let w = report
            .warnings
            .iter()
            .find(|w| w.kind == "held_wheel_speeds")
            .expect("warning");
        assert!(w.message.contains("σ carries"), "{}", w.message);
        let mut r = new_run(WheelDelay::Off, false);
        let mut answers = Vec::new();
        for s in &out.samples {
            r.push(s, |e| answers.push(*e)).expect("push");
        }
        let before = answers.len();
        r.finish(|e| answers.push(*e)).expect("finish");
        assert_eq!(answers.len(), before + 1, "seed {seed}");
        let (previous, last) = (answers[before - 1], answers[before]);
        assert_eq!(previous.uncertainty.expect("σ").time_tag_kg_m2, [0.0; 6]);
        assert_eq!((last.t_s, last.j()), (previous.t_s, previous.j()));
        let term = frobenius(last.uncertainty.expect("σ").time_tag_kg_m2);
        let ratio = (last.inertia().expect("answer") - truth).norm() / term;
        assert!(
            (0.5..2.0).contains(&ratio),
            "seed {seed}: streaming {ratio}"
        );
        assert_eq!(last.within_3sigma(&truth), Some(true), "seed {seed}");
        assert_eq!(r.last(), Some(&last));
    }
    let slew = Scenario::slew()
        .simulate(&Common::physical())
        .expect("sim")
        .samples;
    for batch in [true, false] {
        let (e, _) = run(&slew, WheelDelay::Off, batch);
        assert_eq!(e.uncertainty.expect("σ").time_tag_kg_m2, [0.0; 6]);
    }
}

/// The throw with only its speed hold (seed 1), streaming: the final answer's held-lag
/// term. Reference: the same run without resampling and without a spacecraft file.
/// Resampled to 1 kHz, the lag is still counted in input samples (4.875 ms, not four
/// times that): the term agrees within 20 %. With the flywheel given in a spacecraft
/// file with a spin-inertia σ (the run then holds every sample for the rotors' term),
/// the term is still given, within 1 % of the reference's (the σ is the rotor's, not the
/// lag's). With a memory the answer forgets what the term would count: none.
#[test]
fn the_held_lag_term_counts_input_samples_and_survives_a_spacecraft_file() {
    let samples = held_throw(1).samples;
    let finish = |mut r: Run, speeds: Option<&[f64]>| {
        let mut last = None;
        for (k, s) in samples.iter().enumerate() {
            match speeds {
                Some(w) => r.push_with_speeds(s, &w[k..=k], |e| last = Some(*e)),
                None => r.push(s, |e| last = Some(*e)),
            }
            .expect("push");
        }
        r.finish(|e| last = Some(*e)).expect("finish");
        last.expect("answer").uncertainty.expect("σ").time_tag_kg_m2
    };
    let settings = |f: fn(&mut PipelineSettings)| {
        let mut s = PipelineSettings::default();
        f(&mut s);
        Run::new(s.validate().expect("settings"), false).expect("run")
    };
    let reference = finish(settings(|_| {}), None);
    assert!(reference.iter().all(|&c| c > 0.0), "{reference:?}");
    let close = |a: &[f64; 6], tol: f64| {
        (0..6).all(|k| (a[k] - reference[k]).abs() <= tol * reference[k].max(1e-3 * reference[0]))
    };
    let resampled = finish(settings(|s| s.resample_s = Some(1e-3)), None);
    assert!(close(&resampled, 0.2), "{resampled:?} vs {reference:?}");
    let spin = 1e-5;
    let sc = inertia::spacecraft::Spacecraft::parse(
        &format!(
            "[[rotor]]\nname = \"fly\"\naxis = [0.0, 0.0, 1.0]\nspin_inertia_kg_m2 = {spin}\nspin_inertia_sigma_kg_m2 = 1e-7\nspeed_column = \"fly\"\n"
        ),
        "fly.toml",
    )
    .expect("spacecraft");
    let speeds: Vec<f64> = samples.iter().map(|s| s.rho_nms.z / spin).collect();
    let with_file = finish(settings(|_| {}).with_spacecraft(sc), Some(&speeds));
    assert!(close(&with_file, 0.01), "{with_file:?} vs {reference:?}");
    let memory = finish(settings(|s| s.memory_s = Some(10.0)), None);
    assert_eq!(memory, [0.0; 6]);
}

/// Problem: the throw with its gyro vibration and held wheel speeds (no inertial torque,
/// no drag), the time tag estimated, seeds 11–18, streaming and batch. Reference: the
/// simulated J. The vibration beating with the held speeds raises the torque test's χ²₃
/// to about 80 with no torque; where holding that spurious torque would move the answer
/// by more than 5 of its jackknife σ it is kept, and before its move joined σ, J12 was
/// 5–6σ off in 4 of seeds 1–8. The residual variances with and without the torque do not
/// tell the two models apart (`models_told_apart`), so the kept answer's σ carries the
/// move: every determined answer holds the truth within 3σ, and the rule is exercised
/// (the torque kept with its move in σ in at least one seed; measured: 2 of 8).
#[test]
fn a_kept_torque_the_residuals_cannot_tell_from_none_carries_its_move_in_sigma() {
    let mut kept_in_sigma = 0;
    for seed in 11..=18 {
        let mut p = Preset::throw_without(&[LabEffect::InertialTorque, LabEffect::Drag]);
        p.common.seed = seed;
        let out = p.simulate().expect("sim");
        for batch in [false, true] {
            let (e, r) = run(&out.samples, WheelDelay::Estimate, batch);
            if determined(&e) {
                assert_holds_truth(
                    &e,
                    &out.inertia_kg_m2,
                    &format!("seed {seed}, batch {batch}"),
                );
            }
            let test = r.pipeline().and_then(|p| p.diagnostics().torque_test);
            if let Some(t) = test.filter(|t| !t.held_at_zero && t.shift_in_sigma) {
                let chi2_limit = 3.0 + 3.0 * (2.0 * 3.0 * out.samples.len() as f64).sqrt();
                assert!(t.chi2 > 16.27 && t.chi2 < chi2_limit, "{t:?}");
                kept_in_sigma += 1;
            }
        }
    }
    assert!(kept_in_sigma >= 1, "the rule was not exercised");
}

/// Problem: the lab throw with every effect, each throw tumbling its own way
/// (`Preset::with_drawn_tumble`), the wheel speeds' time tag estimated, seeds 6, 39 and
/// 53, streaming and batch. Reference: the simulated J. The aerodynamic torque fixed in
/// space acts, but the inertial torque's test (`Δρ²/s² > max(χ²_k(1 − 10⁻³), k ln n)`)
/// leaves it out of the chosen rows; before the answer's σ carried the move of J that the
/// torque makes (`select::rejected_inertial_twin`), every one of these answers was
/// determined with J12, J13 or J23 4–7σ off (`examples/throw_sigma.rs`: 4 of 59 such
/// throws among seeds 0–59, 1 after). Now each is determined and holds the truth within
/// 3σ, with the torque still left out of the streaming run's rows.
#[test]
fn a_torque_the_test_leaves_out_still_widens_sigma_by_its_move() {
    for seed in [6, 39, 53] {
        let mut p = Preset::throw().with_drawn_tumble(seed);
        p.common.seed = seed;
        let out = p.simulate().expect("simulation");
        for batch in [false, true] {
            let (e, r) = run(&out.samples, WheelDelay::Estimate, batch);
            let what = format!("seed {seed}, batch {batch}");
            assert!(determined(&e), "{what}: {:?}", e.observability);
            assert_holds_truth(&e, &out.inertia_kg_m2, &what);
            if let Some(p) = r.pipeline() {
                let rows = p.diagnostics().row_model.expect("rows");
                assert!(!rows.inertial_torque, "{what}: the torque was taken");
            }
        }
    }
}
