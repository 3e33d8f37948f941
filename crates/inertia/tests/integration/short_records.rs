//! Records shorter than four chains (estimator::jackknife, "Records of few chains"): the
//! delete-a-group jackknife over time blocks of the rows, recursive (the chain's
//! whitened innovations) against batch (raw rows, each chain's initial momenta fitted
//! again), and the coverage it gives on the simulated hand-thrown device.

use inertia::estimator::momentum_rows::{MomentumRowSettings, RotationSource, Stencil};
use inertia::sim::presets::{LabEffect, Preset};
use inertia::tensor::j_from_matrix;

use crate::discrete_momentum::estimator;

/// The default row model on a gyro record, one chain (the record is far shorter than
/// `--chain`).
fn rows() -> MomentumRowSettings {
    MomentumRowSettings {
        rotation: RotationSource::Gyro,
        stencil: Stencil::Adaptive,
        ..Default::default()
    }
}

/// The throw with only the lab effects `on`, seed `seed`.
fn throw(on: &[LabEffect], seed: u64) -> inertia::sim::SimOutput {
    let mut p = Preset::throw_with(on);
    p.common.seed = seed;
    p.simulate().expect("sim")
}

/// Problem: 20 throws (seeds 1–20) with the air drag, the effect the rows do not model
/// that leaves the answer least biased, and 20 without any effect. Reference: the
/// simulated J. The noise σ with the time-block jackknife (the larger of it and the
/// least-squares σ, and the torque test's shift where it held the torque at zero) covers
/// the truth within 3σ in at least 70 % of throws for every element (measured: worst
/// element 19/20 with the drag, 17/20 without any effect); with the drag the
/// least-squares σ alone covers at most 65 % for the worst element (measured 0/20: it
/// ignores the rows' correlated errors), so the jackknife is what makes the difference.
/// (Without any effect the torque test now holds the spurious torque at zero, and the
/// least-squares σ of that better answer covers 14/20, 8/20 before.) The pipeline's σ
/// adds the model spread and the discretisation bias.
#[test]
fn time_blocks_give_short_records_a_sigma_that_covers() {
    for on in [&[LabEffect::Drag][..], &[]] {
        let (mut robust, mut ls) = ([0usize; 6], [0usize; 6]);
        let seeds = 20;
        for seed in 1..=seeds {
            let run = throw(on, seed);
            let mut e = estimator(rows());
            for s in &run.samples {
                e.push(s).expect("push");
            }
            let j = e.last().and_then(|x| x.j()).expect("answer");
            let truth = j_from_matrix(&run.inertia_kg_m2);
            let sigma_ls = e.noise_sigma().expect("σ");
            let noise = e.robust_noise_sigma().expect("σ");
            let shift = e.torque_model_shift().unwrap_or([0.0; 6]);
            let sigma: [f64; 6] = core::array::from_fn(|k| noise[k].hypot(shift[k]));
            for k in 0..6 {
                let err = (j[k] - truth[k]).abs();
                robust[k] += usize::from(err <= 3.0 * sigma[k]);
                ls[k] += usize::from(err <= 3.0 * sigma_ls[k]);
            }
        }
        let worst = |c: [usize; 6]| *c.iter().min().expect("six") as f64 / seeds as f64;
        assert!(
            worst(robust) >= 0.7,
            "{on:?}: coverage with the jackknife {robust:?} of {seeds}"
        );
        if !on.is_empty() {
            assert!(
                worst(ls) <= 0.65,
                "{on:?}: least-squares coverage {ls:?} of {seeds}"
            );
        }
    }
}

/// Problem: throws without any lab effect (seeds 1–6), whose correlated row errors
/// inflate the constant-torque χ² (62 on seed 1) far past its threshold. Reference: the
/// simulated J, and the same rows with the torque not estimated (`torque_bias` off).
/// The default pipeline's torque test holds the spurious torque at zero, in at least 3
/// of the 6 because holding it moves the answer by at most TORQUE_SHIFT_Z (5) of its jackknife σ
/// (`shift_z`) while the χ² alone would keep it, and its error is
/// then within 1.5× of the torque-free rows' (measured: before, with the torque kept,
/// 2.0–4.9e-3 against 2.2–6.6e-4); the truth stays within 3σ of every element in at
/// least 5 of the 6.
#[test]
fn a_spurious_torque_on_a_short_record_is_held_at_zero() {
    use inertia::pipeline::{Pipeline, PipelineSettings};
    let last = |samples: &[inertia::sample::Sample], torque_bias: bool| {
        let mut p = Pipeline::new(&PipelineSettings {
            torque_bias,
            ..PipelineSettings::default()
        })
        .expect("settings");
        for s in samples {
            p.push(s).expect("push");
        }
        (*p.last().expect("answer"), p.diagnostics().torque_test)
    };
    let (mut covered, mut by_shift, mut held) = (0, 0, 0);
    let mut errors = Vec::new();
    for seed in 1..=6 {
        let run = throw(&[], seed);
        let (e, test) = last(&run.samples, true);
        let (free, _) = last(&run.samples, false);
        let truth = run.inertia_kg_m2;
        let err = |e: &inertia::estimator::Estimate| {
            inertia::tensor::relative_frobenius_error(&e.inertia().expect("J"), &truth)
        };
        let test = test.expect("tested");
        held += usize::from(test.held_at_zero);
        errors.push((err(&e), err(&free)));
        by_shift += usize::from(
            test.chi2 > inertia::estimator::discrete_momentum::TORQUE_CHI2
                && test
                    .shift_z
                    .is_some_and(|z| z <= inertia::estimator::discrete_momentum::TORQUE_SHIFT_Z),
        );
        covered += usize::from(e.within_3sigma(&truth) == Some(true));
    }
    let median = |k: usize| {
        let mut v: Vec<f64> = errors
            .iter()
            .map(|e| if k == 0 { e.0 } else { e.1 })
            .collect();
        v.sort_by(f64::total_cmp);
        0.5 * (v[2] + v[3])
    };
    assert!(median(0) <= 1.5 * median(1), "{errors:?}");
    assert!(covered >= 5, "{covered} of 6");
    assert!(
        held >= 4 && by_shift >= 3,
        "held {held}, by the shift {by_shift} of 6"
    );
}
