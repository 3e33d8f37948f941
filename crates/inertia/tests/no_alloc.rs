//! The per-sample update (rows, QR update, observability test, native constrained solve)
//! does not allocate. Counted with a counting global allocator over whole runs that
//! include both fast-path and constrained (interior-point) solves.

use inertia::constraints::ConstraintSet;
use inertia::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
use inertia::estimator::rows::{FiniteDifferenceRows, VariationalRows};
use inertia::sim::scenario::{Common, Scenario};
use inertia::solver::native::NativeSolver;
use inertia::tensor::Component;

#[test]
fn recursive_update_and_native_solve_do_not_allocate() {
    for (sc, set) in [
        (
            Scenario::spin(),
            ConstraintSet::paper().with_nominal(Component::J33, 3.0, 0.1),
        ),
        (Scenario::slew(), ConstraintSet::physical()),
    ] {
        let out = sc.simulate(&Common::paper()).unwrap();
        let c = set.validate().unwrap();
        let mut var = RecursiveEstimator::new(
            VariationalRows::default(),
            c,
            NativeSolver::default(),
            RecursiveSettings::default(),
        )
        .unwrap();
        let mut fd = RecursiveEstimator::new(
            FiniteDifferenceRows::default(),
            c,
            NativeSolver::default(),
            RecursiveSettings::default(),
        )
        .unwrap();
        let (mut solves, mut constrained, mut answers) = (0u32, 0u32, 0u32);
        let info = allocation_counter::measure(|| {
            for s in &out.samples {
                if let Some(e) = var.push(s).unwrap() {
                    if let Some(sol) = e.solution {
                        solves += 1;
                        answers += 1;
                        if sol.iterations > 0 {
                            constrained += 1;
                        }
                    }
                }
                let _ = fd.push(s).unwrap();
            }
        });
        assert_eq!(
            info.count_total,
            0,
            "{}: {} allocations",
            sc.name(),
            info.count_total
        );
        assert!(
            solves > 1000 && constrained > 100,
            "{}: {solves} solves, {constrained} constrained",
            sc.name()
        );
        assert!(answers > 0);
    }
}

/// Control: the counter sees allocations (so the test above can fail).
#[test]
fn the_counter_counts() {
    let info = allocation_counter::measure(|| {
        let v: Vec<f64> = Vec::with_capacity(std::hint::black_box(16));
        std::hint::black_box(v);
    });
    assert_eq!(info.count_total, 1);
}
