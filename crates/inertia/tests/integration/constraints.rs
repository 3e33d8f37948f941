//! Constraint sets (paper eqs. 9, 55, 57; docs/conventions.md §4) and the solver front end.

use inertia::constraints::{ConstraintError, ConstraintSet};
use inertia::solver::native::NativeSolver;
use inertia::solver::{solve, SolveStatus};
use inertia::tensor::{
    diagonal_triangle_slacks, j_from_matrix, matrix_from_j, principal, second_moment, Component,
};
use nalgebra::{Matrix3, Matrix6, Vector6};

/// docs/conventions.md §4: positive definite, passes eq. 9 on the diagonal, principal moments (1, 1, 2.5)
/// violate the triangle inequality.
fn errata_counterexample() -> Matrix3<f64> {
    Matrix3::new(1.75, 0.0, 0.75, 0.0, 1.0, 0.0, 0.75, 0.0, 1.75)
}

#[test]
fn counterexample_is_what_the_errata_says() {
    let j = errata_counterexample();
    let (pm, _) = principal(&j);
    assert!((pm - nalgebra::Vector3::new(1.0, 1.0, 2.5)).norm() < 1e-12);
    assert!(diagonal_triangle_slacks(&j).iter().all(|&s| s > 0.0));
    assert!(second_moment(&j).symmetric_eigenvalues().min() < -0.2);
}

#[test]
fn default_set_is_physical_and_has_an_interior_point() {
    for set in [
        ConstraintSet::default(),
        ConstraintSet::paper(),
        ConstraintSet::positive_definite(),
        ConstraintSet::physical().with_nominal(Component::J33, 3.0, 0.1),
        ConstraintSet::paper().with_nominal(Component::J33, 3.0, 0.1),
        ConstraintSet::physical()
            .with_bounds(Component::J11, Some(0.9), Some(1.1))
            .with_bounds(Component::J12, Some(0.03), Some(0.04))
            .with_bounds(Component::J23, None, Some(-0.07)),
    ] {
        let c = set.validate().unwrap();
        assert!(c.strictly_feasible(c.interior()), "{set:?}");
        assert!(
            c.margin(c.interior()) > 1e-3,
            "{set:?}: {}",
            c.margin(c.interior())
        );
    }
}

#[test]
fn crossed_and_contradictory_bounds_are_errors_before_any_data() {
    let crossed = ConstraintSet::physical().with_bounds(Component::J22, Some(2.0), Some(1.0));
    assert!(matches!(
        crossed.validate(),
        Err(ConstraintError::CrossedBounds {
            component: "J22",
            ..
        })
    ));
    // Diagonal bounds that violate the triangle inequality: J11, J22 ≤ 1 and J33 ≥ 3.
    for set in [ConstraintSet::physical(), ConstraintSet::paper()] {
        let bad = set
            .with_bounds(Component::J11, None, Some(1.0))
            .with_bounds(Component::J22, None, Some(1.0))
            .with_bounds(Component::J33, Some(3.0), None);
        let err = bad.validate().unwrap_err();
        assert!(matches!(err, ConstraintError::Infeasible { .. }), "{err}");
        assert!(err.to_string().contains("no inertia satisfies"));
    }
    // A negative upper bound on a moment contradicts J ⪰ εI.
    let neg = ConstraintSet::positive_definite().with_bounds(Component::J11, None, Some(-0.1));
    assert!(matches!(
        neg.validate(),
        Err(ConstraintError::Infeasible { .. })
    ));
    let nan = ConstraintSet::physical().with_bounds(Component::J13, Some(f64::NAN), None);
    assert!(matches!(
        nan.validate(),
        Err(ConstraintError::NonFinite { .. })
    ));
    let eps = ConstraintSet {
        epsilon_kg_m2: 0.0,
        ..ConstraintSet::physical()
    };
    assert!(matches!(
        eps.validate(),
        Err(ConstraintError::NonPositiveEpsilon(_))
    ));
}

#[test]
fn component_names() {
    assert_eq!(Component::from_name("J33"), Some(Component::J33));
    assert_eq!(Component::from_name("j12"), Some(Component::J12));
    assert_eq!(Component::from_name("J21"), Some(Component::J12));
    assert_eq!(Component::from_name("J32"), Some(Component::J23));
    assert_eq!(Component::from_name("J44"), None);
    assert_eq!(Component::from_name("J123"), None);
    for (k, c) in Component::ALL.into_iter().enumerate() {
        assert_eq!(c.index(), k);
        assert_eq!(Component::from_name(c.name()), Some(c));
    }
}

/// When the unconstrained minimiser is the counterexample of docs/conventions.md §4, the default set returns
/// a physically consistent J and the paper's set returns the unphysical one.
#[test]
fn errata_counterexample_default_constraints_fix_it_paper_ones_do_not() {
    let r = Matrix6::identity();
    let z = j_from_matrix(&errata_counterexample());
    let mut native = NativeSolver::default();

    let paper = ConstraintSet::paper().validate().unwrap();
    let sol = solve(&mut native, &r, &z, &paper, None).unwrap();
    assert_eq!(sol.status, SolveStatus::Unconstrained);
    assert_eq!(sol.j, z);
    let (pm, _) = principal(&matrix_from_j(&sol.j));
    assert!(
        pm[0] + pm[1] < pm[2] - 0.4,
        "paper set keeps the unphysical J: {pm}"
    );

    let physical = ConstraintSet::physical().validate().unwrap();
    let sol = solve(&mut native, &r, &z, &physical, None).unwrap();
    assert_eq!(sol.status, SolveStatus::Optimal);
    let j = matrix_from_j(&sol.j);
    let (pm, _) = principal(&j);
    assert!(pm[0] + pm[1] >= pm[2] - 1e-8, "principal moments {pm}");
    assert!(second_moment(&j).symmetric_eigenvalues().min() > -1e-8);
    // It is the nearest physical J: moving it towards z only leaves the set.
    assert!(physical.margin(&sol.j).abs() < 1e-6);
    assert!(
        sol.residuals.gap < 1e-9 && sol.residuals.dual < 1e-6,
        "{:?}",
        sol.residuals
    );
}

/// The fast path returns the unconstrained least-squares answer exactly.
#[test]
fn fast_path_is_exact_least_squares() {
    let r = Matrix6::from_fn(|i, k| {
        if k >= i {
            1.0 + (i * 7 + k * 3) as f64 * 0.1
        } else {
            0.0
        }
    });
    // A physical J (the paper's J_true is not: see `paper_j_true_is_slightly_unphysical`).
    let j_true = Vector6::new(1.0, 2.0, 2.5, 0.03, -0.06, -0.07);
    let z = r * j_true;
    let c = ConstraintSet::physical().validate().unwrap();
    let sol = solve(&mut NativeSolver::default(), &r, &z, &c, None).unwrap();
    assert_eq!(sol.status, SolveStatus::Unconstrained);
    assert!((sol.j - j_true).norm() < 1e-12);
    assert_eq!(sol.iterations, 0);
}

/// The paper's J_true has principal moments with λ1 + λ2 < λ3 by 4.9e-5 kg m²: it is
/// slightly flatter than a flat plate, so Σ = ½ tr(J) I − J has a negative eigenvalue of
/// −2.5e-5 kg m². The physical constraint set cannot return it exactly; the nearest
/// physical J is ~1e-5 away in relative Frobenius norm, far below every error figure.
#[test]
fn paper_j_true_is_slightly_unphysical() {
    let j = inertia::tensor::paper_j_true();
    let (pm, _) = principal(&j);
    let excess = pm[2] - pm[0] - pm[1];
    assert!((excess - 4.93e-5).abs() < 1e-6, "λ3 − λ1 − λ2 = {excess:e}");
    let min_sigma = second_moment(&j).symmetric_eigenvalues().min();
    assert!((min_sigma + 2.46e-5).abs() < 1e-6, "{min_sigma:e}");
    let c = ConstraintSet::physical().validate().unwrap();
    let z = j_from_matrix(&j);
    let sol = solve(
        &mut NativeSolver::default(),
        &Matrix6::identity(),
        &z,
        &c,
        None,
    )
    .unwrap();
    let rel = (matrix_from_j(&sol.j) - j).norm() / j.norm();
    assert!(rel > 1e-6 && rel < 2e-5, "{rel:e}");
    // The diagonal test of eq. 9 passes, so the paper's set accepts it.
    let paper = ConstraintSet::paper().validate().unwrap();
    assert!(paper.strictly_feasible(&z));
}

/// The tracked Jacobi SVD agrees with nalgebra's SVD, from a cold start and when tracking
/// a slowly changing factor.
#[test]
fn svd_tracker_matches_reference_svd() {
    use inertia::estimator::svd_tracker::SvdTracker;
    let mut tracker = SvdTracker::new();
    let mut r = Matrix6::from_fn(|i, k| {
        if k >= i {
            1.0 + ((i * 5 + k * 3) % 7) as f64 * 0.3
        } else {
            0.0
        }
    });
    for step in 0..2000 {
        r[(step % 6, 5)] += 1e-3 * ((step as f64) * 0.7).sin();
        r[(0, 0)] *= 1.0 + 1e-4;
        let mut a: Vec<f64> = tracker.singular_values(&r).iter().copied().collect();
        let mut b: Vec<f64> = r.singular_values().iter().copied().collect();
        a.sort_by(f64::total_cmp);
        b.sort_by(f64::total_cmp);
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-12 * b[5], "step {step}: {a:?} vs {b:?}");
        }
    }
}

/// The products-of-inertia convention (issue 13): a CAD product `+Σ m x y` is the tensor
/// entry negated, for matrices (moments untouched, twice is the identity) and for
/// bounds (`lo ≤ P ≤ hi` is `−hi ≤ J_ik ≤ −lo`; a moment's bound is unchanged).
#[test]
fn cad_products_convert_to_tensor_entries() {
    use inertia::constraints::ProductConvention;
    use inertia::tensor::Component;
    let m = nalgebra::Matrix3::new(1.0, 0.02, -0.03, 0.02, 2.0, 0.04, -0.03, 0.04, 3.0);
    let t = ProductConvention::Cad.matrix_to_tensor(&m);
    assert_eq!(t.diagonal(), m.diagonal());
    assert_eq!(t[(0, 1)], -0.02);
    assert_eq!(t[(2, 0)], 0.03);
    assert_eq!(ProductConvention::Cad.matrix_to_tensor(&t), m);
    assert_eq!(ProductConvention::Tensor.matrix_to_tensor(&m), m);
    let cad = ProductConvention::Cad;
    assert_eq!(
        cad.bound_to_tensor(Component::J12, Some(0.01), Some(0.03)),
        (Some(-0.03), Some(-0.01))
    );
    assert_eq!(
        cad.bound_to_tensor(Component::J13, None, Some(0.05)),
        (Some(-0.05), None)
    );
    assert_eq!(
        cad.bound_to_tensor(Component::J33, Some(2.7), Some(3.3)),
        (Some(2.7), Some(3.3))
    );
}
