//! Newton's method on the KKT system of one active LMI face (a smooth, exact step).
//!
//! When the optimum lies where exactly one eigenvalue of one LMI `F(j)` is zero and every
//! other constraint is inactive, the problem is locally
//!
//! ```text
//! minimise ‖R j − z‖²  subject to  g(j) = λ_min(F(j)) = 0,
//! ```
//!
//! with `g` smooth while `λ_min` is simple. With eigenpairs `(λ_i, v_i)` of `F`, `λ_0` the
//! smallest and `w_i[k] = v_iᵀ F_k v_0`:
//!
//! ```text
//! ∇g = w_0,    ∇²g = Σ_{i=1,2} 2 w_i w_iᵀ / (λ_0 − λ_i)   (negative semidefinite)
//! ```
//!
//! Newton on `∇f − μ∇g = 0, g = 0` uses the Lagrangian Hessian `2RᵀR − μ∇²g`, which is
//! accumulated as a triangular factor from the rows `√2 R` and `√(2μ/(λ_i − λ_0)) w_i`
//! (never squared), and a Schur complement for `Δμ`. `λ_min(F(j))` is concave, so the
//! feasible set is convex and a KKT point with `μ ≥ 0` that satisfies every other
//! constraint strictly is the global optimum. Every answer is checked for exactly that;
//! anything else returns `None`. Started from the previous sample's answer (recursive
//! estimation) or from a barrier answer (which it polishes to round-off accuracy), it
//! converges in a few steps. Fixed sizes, no allocation.

use crate::constraints::description::Lmi;
use crate::constraints::Constraints;
use crate::givens::{fold_row, solve_normal};
use crate::math::sqrt;
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// Most Newton steps.
const MAX_STEPS: u32 = 12;

/// An exact answer on one LMI face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FaceSolution {
    /// The optimum.
    pub(crate) j: Vector6<f64>,
    /// Multiplier of the active eigenvalue constraint (≥ 0).
    pub(crate) mu: f64,
    /// Newton steps.
    pub(crate) steps: u32,
    /// `‖∇f − μ∇g‖∞ / max(1, ‖∇f‖∞)`.
    pub(crate) dual_residual: f64,
    /// The active eigenvalue `λ_min(F(j))` (≈ 0; negative values are the violation).
    pub(crate) eigenvalue: f64,
    /// `μ ‖∇g‖∞ / max(1, ‖∇f‖∞)`: how clearly the objective presses on the face, in the
    /// units of the dual tolerance (`1e-12`, on `dual_residual`). Near the tolerance the
    /// face cannot be told from the interior ([`crate::solver::Backend::solve_on_last_face`]).
    pub(crate) multiplier_margin: f64,
}

/// Sorted eigenpairs of a symmetric 3×3 matrix, ascending.
type Eigen = (Vector3<f64>, [Vector3<f64>; 3]);

/// The last matrix whose eigenpairs [`solve`] took, with them. A recursive run starts
/// each solve at the previous answer, where the previous solve's last step (its
/// convergence test) took the eigenpairs of the same `F(j)`: they are reused, not
/// recomputed (one of the two eigendecompositions of a typical solve). Only a matrix
/// equal bit for bit hits (`+0` and `−0` differ), so the answer is the same bit for bit.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct EigenMemo(Option<(Matrix3<f64>, Eigen)>);

impl EigenMemo {
    fn eigen(&mut self, f: &Matrix3<f64>) -> Eigen {
        match self.0 {
            Some((g, e)) if crate::math::same_bits(g.as_slice(), f.as_slice()) => e,
            _ => {
                let e = crate::eigen3::symmetric_eigen3(f);
                self.0 = Some((*f, e));
                e
            }
        }
    }
}

/// `w[k] = aᵀ F_k b` for the LMI's coefficient matrices.
fn bilinear(lmi: &Lmi<6>, a: &Vector3<f64>, b: &Vector3<f64>) -> Vector6<f64> {
    Vector6::from_fn(|k, _| a.dot(&(lmi.fk[k] * b)))
}

/// Solve on the face of LMI `index`, starting from `start`.
#[must_use]
pub(crate) fn solve(
    r: &Matrix6<f64>,
    z: &Vector6<f64>,
    constraints: &Constraints,
    index: usize,
    start: &Vector6<f64>,
    memo: &mut EigenMemo,
) -> Option<FaceSolution> {
    let lmi = constraints.lmis().get(index)?;
    let scale = start.amax().max(1.0);
    let mut j = *start;
    let rt = r.transpose();
    let mut mu = f64::NAN;
    for step in 1..=MAX_STEPS {
        let (lam, v) = memo.eigen(&lmi.eval(&j));
        if !(lam[1] - lam[0] > 1e-9 * scale) {
            return None; // not a simple eigenvalue: the face is not smooth here
        }
        let grad_g = bilinear(lmi, &v[0], &v[0]);
        let grad_f = rt * (r * j - z) * 2.0;
        if step == 1 {
            // Initial multiplier: least-squares fit of ∇f = μ∇g.
            let gg = grad_g.norm_squared();
            if !(gg > 0.0) {
                return None;
            }
            mu = grad_f.dot(&grad_g) / gg;
        }
        let rd = grad_f - grad_g * mu;
        let g = lam[0];
        let done = g.abs() <= 1e-14 * scale && rd.amax() <= 1e-12 * grad_f.amax().max(1.0);
        if done {
            return accept(
                constraints,
                index,
                j,
                mu,
                g,
                step - 1,
                &rd,
                &grad_f,
                &grad_g,
            );
        }
        // Factor of the Lagrangian Hessian 2RᵀR − μ∇²g.
        let mut u = hessian_factor(r);
        if mu > 0.0 {
            for i in 1..3 {
                let c = 2.0 * mu / (lam[i] - lam[0]);
                let w = bilinear(lmi, &v[i], &v[0]);
                fold_row(&mut u, &(w * sqrt(c)), None);
            }
        }
        // Δj = H⁻¹(−rd + ∇g Δμ), ∇gᵀΔj = −g.
        let h_rd = solve_normal(&u, &rd)?;
        let h_g = solve_normal(&u, &grad_g)?;
        let denom = grad_g.dot(&h_g);
        if !(denom > 0.0) {
            return None;
        }
        let dmu = (grad_g.dot(&h_rd) - g) / denom;
        let dj = -h_rd + h_g * dmu;
        j += dj;
        mu += dmu;
        if !j.iter().all(|x| x.is_finite()) || !mu.is_finite() {
            return None;
        }
        // Converged to round-off: the step no longer changes j.
        if dj.amax() <= 1e-15 * scale && g.abs() <= 1e-13 * scale {
            return accept(constraints, index, j, mu, g, step, &rd, &grad_f, &grad_g);
        }
    }
    None
}

/// The factor of `2RᵀR`: the rows `√2 R` folded into an empty factor. For an upper
/// triangular `R` with a positive diagonal that fold copies each row as it comes (its
/// rotation at the pivot has `c = 0`, `s = 1`, exactly), so `√2 R` is the factor itself,
/// bit for bit, without the folds.
fn hessian_factor(r: &Matrix6<f64>) -> Matrix6<f64> {
    let s2 = core::f64::consts::SQRT_2;
    let triangular = (0..6).all(|i| r[(i, i)] > 0.0 && (0..i).all(|k| r[(i, k)] == 0.0));
    if triangular {
        return r * s2;
    }
    folded_rows(r, s2)
}

/// The rows `s R` folded one by one into an empty factor.
fn folded_rows(r: &Matrix6<f64>, s: f64) -> Matrix6<f64> {
    let mut u = Matrix6::zeros();
    for i in 0..6 {
        fold_row(&mut u, &(r.row(i).transpose() * s), None);
    }
    u
}

#[allow(clippy::too_many_arguments)]
fn accept(
    constraints: &Constraints,
    index: usize,
    j: Vector6<f64>,
    mu: f64,
    g: f64,
    steps: u32,
    rd: &Vector6<f64>,
    grad_f: &Vector6<f64>,
    grad_g: &Vector6<f64>,
) -> Option<FaceSolution> {
    if mu < 0.0 {
        return None; // the constraint would not be active: not this face
    }
    // Every other constraint strictly satisfied.
    for (i, l) in constraints.lmis().iter().enumerate() {
        if i != index && l.eval(&j).cholesky().is_none() {
            return None;
        }
    }
    if constraints.lins().iter().any(|l| l.eval(&j) <= 0.0) {
        return None;
    }
    Some(FaceSolution {
        j,
        mu,
        steps,
        dual_residual: rd.amax() / grad_f.amax().max(1.0),
        eigenvalue: g,
        multiplier_margin: mu * grad_g.amax() / grad_f.amax().max(1.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Problem: 300 slowly changing least-squares problems whose unconstrained answer
    /// first violates the triangle inequality (`J = diag(1, 1.1, J33)`, `J33` from 2.3
    /// down to 1.9 plus noise: the physical set's `Σ ⪰ 0` face is active until `J33`
    /// passes 2.1, then the answer is interior), each solved from the previous answer by
    /// one solver that keeps its memo and its last face, as a recursive run does.
    /// Reference: a fresh solver for each (empty memo, no last face, so the whole way:
    /// the fast path first). Tolerance: none, bit for bit. And after every answer on the
    /// face the solver holds that answer and its `F(j)`, so that the next solve starts on
    /// the face with a hit; off the face it holds no face.
    #[test]
    fn the_last_face_and_its_eigenpairs_kept_change_no_answer() {
        use crate::constraints::ConstraintSet;
        use crate::solver::native::NativeSolver;
        use crate::solver::SolveStatus;
        let constraints = ConstraintSet::physical().validate().expect("valid set");
        let mut rnd = crate::testing::uniform(0x2545_f491_4f6c_dd1d);
        let mut r = Matrix6::from_fn(|i, k| {
            if k < i {
                0.0
            } else if k == i {
                2.0 + rnd()
            } else {
                0.3 * rnd()
            }
        });
        let mut kept = NativeSolver::default();
        let mut warm: Option<Vector6<f64>> = None;
        let (mut faces, mut interior) = (0, 0);
        for step in 0..300 {
            for k in 0..6 {
                r[(k, k)] += 0.01 * rnd().abs();
            }
            let j33 = 2.3 - 0.4 * f64::from(step) / 299.0;
            let truth = Vector6::new(1.0, 1.1, j33, 0.01, -0.02, 0.015);
            let z = r * truth + Vector6::from_fn(|_, _| 1e-3 * rnd());
            let with_memo = crate::solver::solve(&mut kept, &r, &z, &constraints, warm.as_ref())
                .expect("solve");
            let fresh = crate::solver::solve(
                &mut NativeSolver::default(),
                &r,
                &z,
                &constraints,
                warm.as_ref(),
            )
            .expect("solve");
            assert_eq!(with_memo, fresh, "step {step}");
            match with_memo.status {
                SolveStatus::Optimal => {
                    faces += 1;
                    assert_eq!(kept.last_face(), Some(with_memo.j), "step {step}");
                    let held = kept.memo().0.map(|(f, _)| f);
                    let at_answer = constraints.lmis().iter().map(|l| l.eval(&with_memo.j));
                    assert!(
                        at_answer.clone().any(|f| Some(f) == held),
                        "step {step}: the memo does not hold F at the answer"
                    );
                }
                SolveStatus::Unconstrained => interior += 1,
                other => panic!("step {step}: {other:?}"),
            }
            warm = Some(with_memo.j);
        }
        assert!(
            faces > 100 && interior > 100,
            "{faces} on the face, {interior} inside"
        );
    }

    /// Problem: random upper triangular `R` with positive diagonals, spanning 12 orders of
    /// magnitude. Reference: the rows `√2 R` folded one by one. Tolerance: none, bit for
    /// bit; and a matrix that is not triangular (or has a zero pivot) takes the folds.
    #[test]
    fn the_hessian_factor_of_a_triangular_r_is_its_folded_rows() {
        let mut rnd = crate::testing::uniform(0x51_7cc1_b727_220a);
        let folded = |r: &Matrix6<f64>| folded_rows(r, core::f64::consts::SQRT_2);
        for case in 0..200 {
            let scale = 10f64.powi(case % 13 - 6);
            let mut r = Matrix6::from_fn(|i, k| {
                if k < i {
                    0.0
                } else if k == i {
                    scale * (0.1 + rnd().abs())
                } else {
                    scale * rnd()
                }
            });
            assert_eq!(hessian_factor(&r), folded(&r), "case {case}");
            assert_eq!(hessian_factor(&r), r * core::f64::consts::SQRT_2);
            // Off the fast path: a sub-diagonal entry, or a zero pivot.
            if case % 2 == 0 {
                r[(3, 1)] = scale * rnd();
            } else {
                r[(2, 2)] = 0.0;
            }
            assert_eq!(hessian_factor(&r), folded(&r), "case {case}");
        }
    }
}
