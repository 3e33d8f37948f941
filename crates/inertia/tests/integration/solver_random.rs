//! The native solver on seeded random problems, judged by its own optimality conditions
//! (runs in the default build; `tests/solver_agreement.rs` compares with Clarabel).

use crate::common;

use inertia::solver::native::NativeSolver;
use inertia::solver::{solve, SolveStatus};

#[test]
fn native_answers_are_feasible_and_optimal_on_random_problems() {
    let n = 10_000;
    let mut active = 0;
    let mut worst_dual = 0.0f64;
    let mut worst_gap = 0.0f64;
    for (i, p) in common::problems(11, n).iter().enumerate() {
        let c = p.set.validate().unwrap();
        let s = solve(&mut NativeSolver::default(), &p.r, &p.z, &c, None)
            .unwrap_or_else(|e| panic!("{i} {}: {e}", p.label));
        assert!(
            c.margin(&s.j) > -1e-9,
            "{i}: infeasible, margin {}",
            c.margin(&s.j)
        );
        match s.status {
            SolveStatus::Unconstrained => assert_eq!(s.iterations, 0),
            SolveStatus::Optimal => {
                active += 1;
                // Scaled units (objective 1 at j = 0): gap and stationarity.
                assert!(s.residuals.gap <= 1e-9, "{i}: gap {:e}", s.residuals.gap);
                worst_dual = worst_dual.max(s.residuals.dual);
                worst_gap = worst_gap.max(s.residuals.gap);
                assert!(
                    s.residuals.dual <= 1e-6,
                    "{i}: dual residual {:e}",
                    s.residuals.dual
                );
                // Optimality against feasible competitors: the interior point and
                // points on the segment towards it are no better.
                for w in [0.001, 0.01, 0.1, 1.0] {
                    let q = s.j * (1.0 - w) + c.interior() * w;
                    let f = (p.r * q - p.z).norm_squared();
                    assert!(
                        f >= s.objective * (1.0 - 1e-9) - 1e-12 * p.z.norm_squared(),
                        "{i}: w={w}"
                    );
                }
            }
            // Inaccurate, or a status no solver reports (RecursiveLeastSquares).
            other => panic!("{i}: {other:?} {s:?}"),
        }
    }
    eprintln!("{active} constrained solves, worst relative dual residual {worst_dual:e}, worst gap {worst_gap:e}");
    assert!(active > n / 2, "{active}");
}
