//! Per-sample cost of the discrete momentum estimator beside the paper's variational
//! estimator, on the same `slew` telemetry: one `push` (rows, 16-unknown QR update,
//! observability on the reduced 6×6 problem, constrained solve), for the plain and the
//! Richardson rows.
//!
//! Run: `cargo bench -p inertia --bench discrete_momentum`.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use inertia::constraints::ConstraintSet;
use inertia::estimator::discrete_momentum::{DiscreteMomentumEstimator, MomentumEstimatorSettings};
use inertia::estimator::momentum_rows::{MomentumRowSettings, Stencil};
use inertia::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
use inertia::estimator::rows::VariationalRows;
use inertia::sim::scenario::{Common, Scenario};
use inertia::solver::native::NativeSolver;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let run = Scenario::slew().simulate(&Common::paper()).unwrap();
    let samples = &run.samples;
    // Start 200 s in: the estimate is determined and the state is steady.
    let start = 2000;
    let set = || ConstraintSet::positive_definite().validate().unwrap();
    let mut g = c.benchmark_group("per_sample_slew");
    for stencil in [Stencil::Plain, Stencil::Smooth, Stencil::Adaptive] {
        let mut e = DiscreteMomentumEstimator::new(
            MomentumEstimatorSettings {
                rows: MomentumRowSettings {
                    stencil,
                    ..Default::default()
                },
                ..Default::default()
            },
            set(),
            NativeSolver::default(),
        )
        .unwrap();
        let mut snaps = Vec::new();
        for (k, s) in samples.iter().enumerate().take(start + 500) {
            if k >= start {
                snaps.push((e.clone(), *s));
            }
            e.push(s).unwrap();
        }
        let mut k = 0;
        let name = match stencil {
            Stencil::Plain => "discrete_momentum_plain",
            Stencil::Smooth | Stencil::Held => "discrete_momentum_richardson",
            Stencil::Adaptive => "discrete_momentum_adaptive",
        };
        g.bench_function(name, |b| {
            b.iter_batched_ref(
                || {
                    k = (k + 1) % snaps.len();
                    snaps[k].clone()
                },
                |(e, s)| black_box(e.push(s).unwrap()),
                BatchSize::SmallInput,
            )
        });
    }
    let mut v = RecursiveEstimator::new(
        VariationalRows::default(),
        set(),
        NativeSolver::default(),
        RecursiveSettings::default(),
    )
    .unwrap();
    let mut snaps = Vec::new();
    for (k, s) in samples.iter().enumerate().take(start + 500) {
        if k >= start {
            snaps.push((v.clone(), *s));
        }
        v.push(s).unwrap();
    }
    let mut k = 0;
    g.bench_function("variational", |b| {
        b.iter_batched_ref(
            || {
                k = (k + 1) % snaps.len();
                snaps[k].clone()
            },
            |(v, s)| black_box(v.push(s).unwrap()),
            BatchSize::SmallInput,
        )
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
