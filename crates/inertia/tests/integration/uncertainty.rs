//! The estimate's standard deviations are calibrated: over 200 seeds per case, the error
//! of each element lies within ±3σ in 90–100 % of runs, at the paper's noise and at 100×
//! its gyro noise, in both scenarios (estimator::uncertainty).

use inertia::constraints::ConstraintSet;
use inertia::estimator::batch;
use inertia::estimator::excitation::diagnose;
use inertia::estimator::observability::ObservabilitySettings;
use inertia::estimator::observability::{Observability, Unobservable};
use inertia::estimator::rows::VariationalRows;
use inertia::estimator::uncertainty::{combine, SigmaPart};
use inertia::pipeline::{Pipeline, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::scenario::{Common, Scenario};
use inertia::solver::native::NativeSolver;
use inertia::tensor::j_from_matrix;
use inertia::tensor::Component;

const RUNS: u64 = 200;

/// (error / σ) per element for one seed.
fn one_run(sc: &Scenario, gyro_deg: f64, seed: u64) -> [f64; 6] {
    let out = sc
        .simulate(&Common {
            gyro_noise_deg_s_rthz: gyro_deg,
            seed,
            ..Common::paper()
        })
        .unwrap();
    let set = if sc.name() == "spin" {
        ConstraintSet::paper().with_nominal(Component::J33, 3.0, 0.1)
    } else {
        ConstraintSet::paper()
    };
    let c = set.validate().unwrap();
    let g = Some(gyro_deg.to_radians());
    let estimate = |s: &[Sample]| {
        batch::estimate(
            s,
            VariationalRows::default(),
            &c,
            &mut NativeSolver::default(),
            &ObservabilitySettings::default(),
            g,
        )
        .unwrap()
        .j()
        .unwrap()
    };
    let full = estimate(&out.samples);
    let thinned =
        |every: usize| -> Vec<Sample> { out.samples.iter().step_by(every).copied().collect() };
    let (j_half, j_quarter) = (estimate(&thinned(2)), estimate(&thinned(4)));
    let noise = diagnose(
        &batch::reduce(&out.samples, VariationalRows::default()).unwrap(),
        &ObservabilitySettings::default(),
    )
    .element_sigma
    .unwrap();
    let u = combine(&noise, &full, Some(&j_half), Some(&j_quarter));
    let truth = j_from_matrix(&out.inertia_kg_m2);
    core::array::from_fn(|k| (full[k] - truth[k]).abs() / u.sigma_kg_m2[k])
}

fn coverage(sc: &Scenario, gyro_deg: f64) -> ([f64; 6], [f64; 6]) {
    let ratios: Vec<[f64; 6]> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..2u64)
            .map(|part| {
                s.spawn(move || {
                    (0..RUNS)
                        .filter(|i| i % 2 == part)
                        .map(|i| one_run(sc, gyro_deg, 1000 + i))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    });
    let n = ratios.len() as f64;
    let inside = core::array::from_fn(|k| ratios.iter().filter(|r| r[k] <= 3.0).count() as f64 / n);
    let mean = core::array::from_fn(|k| ratios.iter().map(|r| r[k]).sum::<f64>() / n);
    (inside, mean)
}

#[test]
fn three_sigma_coverage_is_between_90_and_100_percent() {
    for (sc, gyro) in [
        (Scenario::slew(), 1e-5),
        (Scenario::spin(), 1e-5),
        (Scenario::slew(), 1e-3),
        (Scenario::spin(), 1e-3),
    ] {
        let (inside, mean) = coverage(&sc, gyro);
        eprintln!(
            "{} gyro {gyro:e}: fraction within ±3σ {:?}, mean |error|/σ {:?}",
            sc.name(),
            inside.map(|x| (x * 1000.0).round() / 1000.0),
            mean.map(|x| (x * 100.0).round() / 100.0)
        );
        for (k, f) in inside.iter().enumerate() {
            assert!(
                (0.9..=1.0).contains(f),
                "{} {gyro}: element {k}: {f}",
                sc.name()
            );
        }
    }
}

/// The paper's estimator's last answer through the pipeline on `samples` (a solve at
/// every sample).
fn variational_last(samples: &[Sample]) -> inertia::estimator::Estimate {
    let settings = PipelineSettings {
        estimator: "variational".into(),
        ..PipelineSettings::default()
    };
    let mut p = Pipeline::new(&settings).unwrap();
    for s in samples {
        p.push(s).unwrap();
    }
    p.last().copied().unwrap()
}

/// The paper's estimator through the pipeline on `samples` (a solve at every sample): its final answer, whether it
/// is "determined" and whether the truth lies within 3σ of it.
fn variational_final(samples: &[Sample], truth: &nalgebra::Matrix3<f64>) -> (bool, bool) {
    let e = variational_last(samples);
    (
        matches!(e.observability, Observability::Determined { .. }),
        e.within_3sigma(truth) == Some(true),
    )
}

/// Attitude noise shrinks the paper's estimate by an amount that falls with the step
/// (errors in variables): a 60 s slew with the paper's gyro came out 3.2σ low on J33
/// (5 %) and a spin with a FOG-propagated attitude 1 % low, both "determined", when σ
/// took the bias for a discretisation remainder of order 2. With the order the steps h,
/// 2h and 4h show, every determined answer holds the truth within 3σ (and most answers
/// are determined: σ is widened, not the data refused).
#[test]
fn the_step_size_bias_covers_the_errors_in_variables_shrinkage() {
    let cases = [
        (Scenario::slew(), 1e-5, Some(60.0)),
        (Scenario::spin(), 0.02 / 60.0, None),
    ];
    for (sc, gyro, duration_s) in cases {
        let mut determined = 0;
        for seed in 31..=36 {
            let out = sc
                .simulate(&Common {
                    gyro_noise_deg_s_rthz: gyro,
                    duration_s,
                    seed,
                    ..Common::physical()
                })
                .unwrap();
            let (d, within) = variational_final(&out.samples, &out.inertia_kg_m2);
            assert!(
                !d || within,
                "{} seed {seed}: determined beyond 3σ",
                sc.name()
            );
            determined += usize::from(d);
        }
        assert!(
            determined >= 4,
            "{}: {determined} of 6 determined",
            sc.name()
        );
    }
}

/// Problem: the 60 s slew with the paper's gyro, seeds 31–36, the paper's estimator
/// given the gyro's density (`--gyro-noise`, errors-in-variables compensation), streaming
/// and batch. Reference: the simulated J. The compensation removes the shrinkage
/// (J33 5 % low without it); the audit's χ² of the constraints' move compares the answer
/// with the least-squares minimiser of the compensated problem it solved. Against the
/// uncompensated one it counted the compensation's move as a conflict, and every answer
/// "leaned on the constraint set" with no bound active. Now each is determined and holds
/// the truth within 3σ.
#[test]
fn the_compensated_answer_is_not_taken_for_a_conflict_with_the_constraints() {
    for seed in 31..=36 {
        let out = Scenario::slew()
            .simulate(&Common {
                gyro_noise_deg_s_rthz: 1e-5,
                duration_s: Some(60.0),
                seed,
                ..Common::physical()
            })
            .unwrap();
        for batch in [false, true] {
            let config = PipelineSettings {
                estimator: "variational".into(),
                gyro_noise_deg_s_rthz: Some(1e-5),
                ..PipelineSettings::default()
            }
            .validate()
            .unwrap();
            let mut run = inertia::pipeline::Run::new(config, batch).unwrap();
            let mut last = None;
            for s in &out.samples {
                run.push(s, |e| last = Some(*e)).unwrap();
            }
            run.finish(|e| last = Some(*e)).unwrap();
            let e = last.unwrap();
            assert!(
                matches!(e.observability, Observability::Determined { .. })
                    && e.within_3sigma(&out.inertia_kg_m2) == Some(true),
                "seed {seed}, batch {batch}: {}, {:?} ± {:?}",
                e.observability,
                e.j(),
                e.sigma_kg_m2()
            );
        }
    }
}

/// The paper's 30 s slew (`reproduce`'s short record) with the paper's estimator: the
/// answer moves with the sample step far beyond its noise (attitude noise shrinks it,
/// less at 2h and 4h), and where that withholds the answer the status says so, not that
/// the data barely excite the dynamics.
#[test]
fn a_withheld_answer_names_the_part_of_sigma_that_withheld_it() {
    let mut withheld = 0;
    for seed in 1..=3 {
        let out = Scenario::slew()
            .simulate(&Common {
                duration_s: Some(30.0),
                seed,
                ..Common::physical()
            })
            .unwrap();
        let e = variational_last(&out.samples);
        if let Observability::NotObservable(Unobservable::Uncertain { dominant, .. }) =
            e.observability
        {
            withheld += 1;
            assert_eq!(dominant, SigmaPart::StepBias, "seed {seed}");
            assert!(
                e.observability.to_string().contains("step-size bias"),
                "seed {seed}: {}",
                e.observability
            );
        }
    }
    assert!(withheld >= 2, "{withheld} of 3 withheld");
}
