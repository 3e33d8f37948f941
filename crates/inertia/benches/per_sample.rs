//! Per-sample cost of the recursive estimator (paper Algorithm 1): the QR update alone,
//! and the full update (rows, QR, observability, constrained solve) on the `slew` and
//! `spin` telemetry, split into samples where the unconstrained minimiser is feasible
//! (fast path) and where constraints are active. Native and, with the `clarabel`
//! feature, Clarabel side by side on the same samples.
//!
//! Run: `cargo bench -p inertia --bench per_sample` (add `--features clarabel` and
//! `OPENBLAS_NUM_THREADS=1` for the reference).

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use inertia::constraints::ConstraintSet;
use inertia::estimator::qr::RecursiveQr;
use inertia::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
use inertia::estimator::rows::{RowSource, VariationalRows};
use inertia::sample::Sample;
use inertia::sim::scenario::{Common, Scenario};
use inertia::solver::native::NativeSolver;
use inertia::solver::Backend;
use inertia::tensor::Component;
use std::hint::black_box;

type Est<B> = RecursiveEstimator<VariationalRows, B>;

/// Snapshots of the estimator before each sample, and the sample indices (past the first
/// 10 s) whose solve took the fast path and whose solve iterated.
fn snapshots<B: Backend + Clone>(
    samples: &[Sample],
    set: ConstraintSet,
    backend: B,
) -> (Vec<Est<B>>, Vec<usize>, Vec<usize>) {
    let c = set.validate().unwrap();
    let mut e = RecursiveEstimator::new(
        VariationalRows::default(),
        c,
        backend,
        RecursiveSettings::default(),
    )
    .unwrap();
    let mut snaps = Vec::with_capacity(samples.len());
    let (mut fast, mut active) = (Vec::new(), Vec::new());
    for (k, s) in samples.iter().enumerate() {
        snaps.push(e.clone());
        if let Some(est) = e.push(s).unwrap() {
            if let Some(sol) = est.solution {
                if s.t_s > 10.0 {
                    if sol.iterations == 0 {
                        fast.push(k);
                    } else {
                        active.push(k);
                    }
                }
            }
        }
    }
    (snaps, fast, active)
}

/// Time one `push` at samples cycling through `which`.
fn bench_push<B: Backend + Clone>(
    c: &mut Criterion,
    name: &str,
    samples: &[Sample],
    snaps: &[Est<B>],
    which: &[usize],
) {
    if which.is_empty() {
        return;
    }
    let mut i = 0usize;
    c.bench_function(name, |b| {
        b.iter_batched(
            || {
                i = (i + 1) % which.len();
                let k = which[i];
                (snaps[k].clone(), k)
            },
            |(mut e, k)| black_box(e.push(&samples[k]).unwrap()),
            BatchSize::SmallInput,
        )
    });
}

/// The telemetry and constraint set of a benchmark case: the paper's set (plus the J33
/// bound for the spin case), or the exact physical set, whose Σ ⪰ 0 LMI is active at the
/// end of the slew (the paper's J_true lies just outside it) and so exercises the
/// interior-point path.
fn scenario_data(sc: &Scenario, physical: bool) -> (Vec<Sample>, ConstraintSet) {
    let out = sc.simulate(&Common::paper()).unwrap();
    let base = if physical {
        ConstraintSet::physical()
    } else {
        ConstraintSet::paper()
    };
    let set = if sc.name() == "spin" {
        base.with_nominal(Component::J33, 3.0, 0.1)
    } else {
        base
    };
    (out.samples, set)
}

fn qr_update(c: &mut Criterion) {
    let (samples, _) = scenario_data(&Scenario::slew(), false);
    let mut rows = VariationalRows::default();
    let blocks: Vec<_> = samples
        .iter()
        .filter_map(|s| rows.push(s))
        .map(Result::unwrap)
        .collect();
    let mut i = 0usize;
    let mut qr = RecursiveQr::new();
    c.bench_function("qr_update_3_rows", |b| {
        b.iter(|| {
            i = (i + 1) % blocks.len();
            qr.add_block(black_box(&blocks[i].h), black_box(&blocks[i].y));
        })
    });
    black_box(qr);
    let settings = inertia::estimator::observability::ObservabilitySettings::default();
    c.bench_function("observability_assess", |b| {
        b.iter(|| inertia::estimator::observability::assess(black_box(&qr), false, &settings))
    });
    c.bench_function("svd_6x6", |b| b.iter(|| black_box(&qr).r.singular_values()));
}

fn per_sample(c: &mut Criterion) {
    for (sc, physical) in [
        (Scenario::slew(), false),
        (Scenario::spin(), false),
        (Scenario::slew(), true),
    ] {
        let (samples, set) = scenario_data(&sc, physical);
        let name = if physical {
            format!("{}_physical", sc.name())
        } else {
            sc.name().to_string()
        };
        let (snaps, fast, active) = snapshots(&samples, set, NativeSolver::default());
        eprintln!(
            "{name}: {} fast-path samples, {} constrained samples",
            fast.len(),
            active.len()
        );
        bench_push(
            c,
            &format!("{name}/native/fast_path"),
            &samples,
            &snaps,
            &fast,
        );
        bench_push(
            c,
            &format!("{name}/native/constrained"),
            &samples,
            &snaps,
            &active,
        );
        let all: Vec<usize> = fast.iter().chain(&active).copied().collect();
        bench_push(c, &format!("{name}/native/all"), &samples, &snaps, &all);
        #[cfg(feature = "clarabel")]
        {
            use inertia::solver::clarabel_backend::ClarabelSolver;
            let (snaps, fast_c, active_c) = snapshots(&samples, set, ClarabelSolver::single_pass());
            // The same samples as the native figures where the classification agrees.
            let _ = (fast_c, active_c);
            bench_push(
                c,
                &format!("{name}/clarabel/fast_path"),
                &samples,
                &snaps,
                &fast,
            );
            bench_push(
                c,
                &format!("{name}/clarabel/constrained"),
                &samples,
                &snaps,
                &active,
            );
            bench_push(c, &format!("{name}/clarabel/all"), &samples, &snaps, &all);
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(2));
    targets = qr_update, per_sample
}
criterion_main!(benches);
