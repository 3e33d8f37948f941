//! The observability test's parts on the `slew` telemetry, 200 s in: one warm update of
//! the tracked SVD of `R` (as the recursive estimator makes it at each solve) beside
//! nalgebra's SVD of the same `R`, and the closed-form 3×3 eigensolver (through
//! `uncertainty::combine`, which is one eigen-decomposition and a few square roots).
//!
//! Run: `cargo bench -p inertia --bench observability -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use inertia::constraints::ConstraintSet;
use inertia::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
use inertia::estimator::rows::VariationalRows;
use inertia::estimator::svd_tracker::SvdTracker;
use inertia::estimator::uncertainty::combine;
use inertia::sim::scenario::{Common, Scenario};
use inertia::solver::native::NativeSolver;
use nalgebra::Matrix6;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let run = Scenario::slew().simulate(&Common::paper()).unwrap();
    let start = 2000;
    let mut e = RecursiveEstimator::new(
        VariationalRows::default(),
        ConstraintSet::positive_definite().validate().unwrap(),
        NativeSolver::default(),
        RecursiveSettings::default(),
    )
    .unwrap();
    // The tracker as the estimator holds it before each solve, and the R it then sees.
    let mut tracker = SvdTracker::new();
    let mut snaps: Vec<(SvdTracker, Matrix6<f64>)> = Vec::new();
    let mut estimates = Vec::new();
    for (k, s) in run.samples.iter().enumerate().take(start + 500) {
        if let Some(est) = e.push(s).unwrap() {
            let r = e.qr().r;
            if k >= start {
                snaps.push((tracker, r));
                if let Some(j) = est.j() {
                    estimates.push(j);
                }
            }
            tracker.singular_values(&r);
        }
    }
    let mut g = c.benchmark_group("observability_slew");
    let mut k = 0;
    g.bench_function("svd_tracker_warm", |b| {
        b.iter_batched_ref(
            || {
                k = (k + 1) % snaps.len();
                snaps[k]
            },
            |(t, r)| black_box(t.singular_values(r)),
            BatchSize::SmallInput,
        )
    });
    let mut k = 0;
    g.bench_function("svd_nalgebra", |b| {
        b.iter(|| {
            k = (k + 1) % snaps.len();
            black_box(black_box(&snaps[k].1).singular_values())
        })
    });
    let noise = [1e-4; 6];
    let mut k = 0;
    g.bench_function("eigen3_via_combine", |b| {
        b.iter(|| {
            k = (k + 1) % estimates.len();
            black_box(combine(&noise, black_box(&estimates[k]), None, None))
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
