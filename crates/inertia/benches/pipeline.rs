//! Per-sample cost of whole pipelines on the `slew` telemetry of
//! `benches/discrete_momentum.rs`: the discrete momentum estimator's automatic path (the
//! `Pipeline` with estimator `discrete-momentum` and default settings, which folds every
//! candidate row model per sample: gyro and attitude rotations × four chain lengths,
//! eight in all, and solves the best) beside the variational pipeline with the same
//! defaults (physical constraint set, uncertainty, audit). A third measurement takes the
//! same slew for 600 s and times the samples after 400 s: by then (3000 row blocks) the
//! gyro-propagated attitude has been found to be the gyro's own integral and only the
//! four gyro candidates are folded (`estimators/discrete_momentum/twins.rs`).
//!
//! A fourth runs the variational estimator through `Run` (the policy every front end
//! shares: the sample gate, the held-speeds and gyro-range checks, and the samples a
//! streaming run keeps for the held speeds' lag term), beside the bare `Pipeline` above.
//!
//! A `Pipeline` cannot be cloned, so each measurement builds one, feeds it the first
//! 200 s (400 s) untimed, and times the samples after that (the estimate is determined
//! and the state steady there), building a new one when they run out.
//!
//! Run: `cargo bench -p inertia --bench pipeline -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, Criterion};
use inertia::pipeline::{Pipeline, PipelineSettings, Run};
use inertia::sim::scenario::{Common, Scenario};
use std::hint::black_box;
use std::time::{Duration, Instant};

fn bench(c: &mut Criterion) {
    let run = Scenario::slew().simulate(&Common::paper()).unwrap();
    let long = Scenario::slew()
        .simulate(&Common {
            duration_s: Some(600.0),
            ..Common::paper()
        })
        .unwrap();
    let mut g = c.benchmark_group("pipeline_per_sample_slew");
    for (name, estimator, samples, start) in [
        ("variational", "variational", &run.samples, 2000),
        (
            "discrete_momentum_auto",
            "discrete-momentum",
            &run.samples,
            2000,
        ),
        (
            "discrete_momentum_auto_after_400s",
            "discrete-momentum",
            &long.samples,
            4000,
        ),
    ] {
        let settings = PipelineSettings {
            estimator: estimator.into(),
            ..PipelineSettings::default()
        };
        g.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                let mut done = 0u64;
                while done < iters {
                    let mut p = Pipeline::new(&settings).unwrap();
                    for s in &samples[..start] {
                        p.push(s).unwrap();
                    }
                    let n = (iters - done).min((samples.len() - start) as u64) as usize;
                    let t0 = Instant::now();
                    for s in &samples[start..start + n] {
                        black_box(p.push(black_box(s)).unwrap());
                    }
                    total += t0.elapsed();
                    done += n as u64;
                }
                total
            })
        });
    }
    let config = PipelineSettings {
        estimator: "variational".into(),
        ..PipelineSettings::default()
    }
    .validate()
    .unwrap();
    g.bench_function("variational_through_run", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut done = 0u64;
            while done < iters {
                let mut r = Run::new(config, false).unwrap();
                for s in &run.samples[..2000] {
                    r.push(s, |_| {}).unwrap();
                }
                let n = (iters - done).min((run.samples.len() - 2000) as u64) as usize;
                let t0 = Instant::now();
                for s in &run.samples[2000..2000 + n] {
                    r.push(black_box(s), |e| {
                        black_box(e);
                    })
                    .unwrap();
                }
                total += t0.elapsed();
                done += n as u64;
            }
            total
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
