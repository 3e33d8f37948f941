//! Several records of one spacecraft in one batch run (`Run::next_record`): the paper's
//! slew flown four times, each record with its own time axis (every one starts at 0), its
//! own momentum bias and its own constant body torque. References: the simulated J, each
//! record alone, and the same records in another order.

use inertia::estimator::observability::Observability;
use inertia::estimator::Estimate;
use inertia::pipeline::{PipelineSettings, Run, RunErrorKind};
use inertia::sample::Sample;
use inertia::sim::environment::Environment;
use inertia::sim::scenario::{Common, Scenario, SlewPlan};
use inertia::sim::Realism;
use inertia::tensor::relative_frobenius_error;
use nalgebra::{Matrix3, Vector3};

/// Record `k` of seed `seed`: a 60 s slew with a momentum bias and a body torque of its
/// own (`torque_nm` along a direction that turns with `k`), its times from 0.
fn record(seed: u64, k: usize, torque_nm: f64) -> (Vec<Sample>, Matrix3<f64>) {
    let turn = k as f64 * 1.9;
    let out = Scenario::Slew(SlewPlan {
        momentum_bias_nms: Vector3::new(turn.cos(), turn.sin(), 0.5) * 0.05 * k as f64,
        ..SlewPlan::default()
    })
    .simulate(&Common {
        duration_s: Some(60.0),
        seed: 1000 * seed + k as u64,
        realism: Realism {
            environment: Environment {
                constant_torque_nm: Vector3::new(turn.sin(), -0.5, turn.cos()) * torque_nm,
                ..Environment::default()
            },
            ..Realism::default()
        },
        ..Common::physical()
    })
    .expect("sim");
    assert_eq!(out.samples[0].t_s, 0.0, "every record's time starts at 0");
    (out.samples, out.inertia_kg_m2)
}

/// The batch answer over `records` (one run, a record boundary between each two).
fn pooled(records: &[&[Sample]]) -> Estimate {
    let config = PipelineSettings::default().validate().expect("settings");
    let mut run = Run::new(config, true).expect("run");
    for (k, r) in records.iter().enumerate() {
        if k > 0 {
            run.next_record().expect("next record");
        }
        for s in *r {
            run.push(s, |_| {}).expect("push");
        }
    }
    assert_eq!(run.records(), records.len());
    let mut last = None;
    run.finish(|e| last = Some(*e)).expect("finish");
    last.expect("an estimate")
}

/// Each element's |error|/σ.
fn z(e: &Estimate, truth: &Matrix3<f64>) -> [f64; 6] {
    let j = e.j().expect("J");
    let t = inertia::tensor::j_from_matrix(truth);
    let s = e.uncertainty.expect("σ").sigma_kg_m2;
    core::array::from_fn(|k| (j[k] - t[k]).abs() / s[k])
}

#[test]
fn four_records_pool_to_a_covered_answer_tighter_than_a_typical_one() {
    for seed in 0..3 {
        let recs: Vec<(Vec<Sample>, Matrix3<f64>)> =
            (0..4).map(|k| record(seed, k, 2e-6)).collect();
        let truth = recs[0].1;
        let slices: Vec<&[Sample]> = recs.iter().map(|r| &r.0[..]).collect();
        let all = pooled(&slices);
        assert!(
            matches!(all.observability, Observability::Determined { .. }),
            "{:?}",
            all.observability
        );
        let zs = z(&all, &truth);
        assert!(zs.iter().all(|&v| v <= 3.0), "seed {seed}: z {zs:?}");
        let sigma = all.uncertainty.expect("σ").sigma_kg_m2;
        let error = relative_frobenius_error(&all.inertia().expect("J"), &truth);
        let mut alone: Vec<[f64; 6]> = Vec::new();
        for (k, r) in slices.iter().enumerate() {
            let one = pooled(&[r]);
            alone.push(one.uncertainty.expect("σ").sigma_kg_m2);
            let e1 = relative_frobenius_error(&one.inertia().expect("J"), &truth);
            eprintln!("seed {seed} record {k}: error {e1:.3e}, pooled {error:.3e}");
        }
        // On the diagonal, σ of the four records is at most 0.8 of the median record's (it
        // may exceed the best record's: the records' own jackknife keeps what differs
        // between them).
        for i in 0..3 {
            let mut s: Vec<f64> = alone.iter().map(|a| a[i]).collect();
            s.sort_by(f64::total_cmp);
            let median = 0.5 * (s[1] + s[2]);
            assert!(
                sigma[i] <= 0.8 * median,
                "seed {seed} J{i}{i}: σ {} of four records, alone {s:?}",
                sigma[i]
            );
        }
    }
}

#[test]
fn the_records_order_does_not_change_the_answer() {
    let recs: Vec<(Vec<Sample>, Matrix3<f64>)> = (0..3).map(|k| record(7, k, 2e-6)).collect();
    let a = pooled(&[&recs[0].0, &recs[1].0, &recs[2].0]);
    let b = pooled(&[&recs[2].0, &recs[0].0, &recs[1].0]);
    let (ja, jb) = (a.j().expect("J"), b.j().expect("J"));
    let d = (ja - jb).norm() / ja.norm();
    assert!(d < 1e-9, "relative difference {d:e}");
}

#[test]
fn each_record_has_its_own_body_torque() {
    // Opposite torques on two records: one shared torque would fit neither. With a torque
    // of its own each, the answer is as good as with no torque at all.
    let with: Vec<(Vec<Sample>, Matrix3<f64>)> = (0..4)
        .map(|k| record(3, k, if k % 2 == 0 { 2e-5 } else { -2e-5 }))
        .collect();
    let without: Vec<(Vec<Sample>, Matrix3<f64>)> = (0..4).map(|k| record(3, k, 0.0)).collect();
    let truth = with[0].1;
    let e = |recs: &[(Vec<Sample>, Matrix3<f64>)]| {
        let slices: Vec<&[Sample]> = recs.iter().map(|r| &r.0[..]).collect();
        let est = pooled(&slices);
        (
            relative_frobenius_error(&est.inertia().expect("J"), &truth),
            z(&est, &truth),
        )
    };
    let (e_with, z_with) = e(&with);
    let (e_without, _) = e(&without);
    assert!(z_with.iter().all(|&v| v <= 3.0), "z {z_with:?}");
    assert!(
        e_with <= 3.0 * e_without.max(1e-6),
        "error {e_with:e} with the torques, {e_without:e} without"
    );
}

#[test]
fn records_are_refused_where_they_cannot_be_estimated_together() {
    let config = || PipelineSettings::default().validate().expect("settings");
    let (s, _) = record(0, 0, 0.0);
    // Streaming.
    let mut run = Run::new(config(), false).expect("run");
    run.push(&s[0], |_| {}).expect("push");
    let e = run.next_record().expect_err("streaming");
    assert_eq!(e.kind, RunErrorKind::RecordsNeedBatch);
    // A record without samples: the first, or one just begun.
    let mut run = Run::new(config(), true).expect("run");
    let e = run.next_record().expect_err("empty first record");
    assert_eq!(e.kind, RunErrorKind::EmptyRecord { record: 1 });
    run.push(&s[0], |_| {}).expect("push");
    run.next_record().expect("second record");
    let e = run.next_record().expect_err("empty second record");
    assert_eq!(e.kind, RunErrorKind::EmptyRecord { record: 2 });
    // An estimator without the momentum rows.
    let config = PipelineSettings {
        estimator: "variational".into(),
        ..PipelineSettings::default()
    }
    .validate()
    .expect("settings");
    let mut run = Run::new(config, true).expect("run");
    run.push(&s[0], |_| {}).expect("push");
    let e = run.next_record().expect_err("variational");
    assert!(
        matches!(e.kind, RunErrorKind::RecordsNeedRows { .. }),
        "{e:?}"
    );
    // Time going back within a record is still refused.
    let mut run = Run::new(config_default(), true).expect("run");
    run.push(&s[0], |_| {}).expect("push");
    run.push(&s[1], |_| {}).expect("push");
    run.next_record().expect("next record");
    run.push(&s[5], |_| {})
        .expect("a record may start at any time");
    let e = run.push(&s[4], |_| {}).expect_err("time going back");
    assert_eq!(e.sample, Some(3));
}

fn config_default() -> inertia::pipeline::PipelineConfig {
    PipelineSettings::default().validate().expect("settings")
}

#[test]
fn a_one_sample_record_adds_nothing_and_an_empty_last_one_is_refused() {
    let (a, _) = record(5, 0, 2e-6);
    let (b, _) = record(5, 1, 2e-6);
    let two = pooled(&[&a, &b]);
    // A record of one sample has no rows: no row may join it to its neighbours.
    let three = pooled(&[&a, &b[..1], &b]);
    let (j2, j3) = (two.j().expect("J"), three.j().expect("J"));
    assert!((j2 - j3).norm() <= 1e-12 * j2.norm(), "{j2} against {j3}");
    // The answer's time is the last record's own.
    assert_eq!(three.t_s, b.last().expect("samples").t_s);
    // A record begun and never given a sample.
    let mut run = Run::new(config_default(), true).expect("run");
    for s in &a {
        run.push(s, |_| {}).expect("push");
    }
    run.next_record().expect("next record");
    let e = run.finish(|_| {}).expect_err("an empty last record");
    assert_eq!(e.kind, RunErrorKind::EmptyRecord { record: 2 });
}
