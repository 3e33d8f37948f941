//! An exact primal active-set method for the *linear* part of the constraint set.
//!
//! ```text
//! minimise ‖R j − z‖²  subject to  a_lᵀ j ≥ b_l      (triangle inequalities, bounds)
//! ```
//!
//! The LMIs are dropped (a relaxation). If the relaxed optimum satisfies every LMI
//! strictly, it is optimal for the full problem: it is feasible, and nothing feasible
//! does better than the relaxation's optimum. This is the common case for the paper's
//! constraint set and for bounded estimates, and the answer is exact to round-off (a KKT
//! point with the active constraints met to machine precision), with no barrier
//! iterations. Otherwise (an LMI active, `R` too ill-conditioned, or no convergence) it
//! returns `None` and the barrier method runs.
//!
//! Working-set solves use `R⁻¹` by triangular solves: for working set W,
//! `j = j_u + R⁻¹ R⁻ᵀ A_Wᵀ μ` with `j_u = R⁻¹ z` and `(M Mᵀ) μ = b_W − A_W j_u`,
//! `M = A_W R⁻¹`; the multipliers of `‖Rj − z‖² − Σ λ (aᵀj − b)` are `λ = 2μ`.
//! Starting point: the constraint set's interior point (all slacks positive), W = ∅
//! (Nocedal & Wright, Algorithm 16.3). Fixed sizes, no allocation.

use crate::constraints::description::{Lin, MAX_LIN};
use crate::constraints::Constraints;
use nalgebra::{Matrix6, Vector6};

/// Largest number of working-set changes before giving up.
const MAX_ITERATIONS: u32 = 40;

/// The relaxed optimum and its multipliers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ActiveSetSolution {
    /// Optimal `j` of the relaxation.
    pub(crate) j: Vector6<f64>,
    /// Working-set changes made.
    pub(crate) iterations: u32,
    /// Stationarity residual `‖2Rᵀ(Rj − z) − Σ λ_l a_l‖∞`, relative to `max(1, ‖2Rᵀ(Rj − z)‖∞)`.
    pub(crate) dual_residual: f64,
    /// Complementarity `Σ λ_l (a_lᵀ j − b_l)` over the working set (≈ 0).
    pub(crate) gap: f64,
}

/// Solve `Rᵀ w = a` (forward substitution).
fn solve_rt(r: &Matrix6<f64>, a: &Vector6<f64>) -> Vector6<f64> {
    let mut w = Vector6::zeros();
    for i in 0..6 {
        let mut s = a[i];
        for k in 0..i {
            s -= r[(k, i)] * w[k];
        }
        w[i] = s / r[(i, i)];
    }
    w
}

/// Solve `R x = w` (back substitution).
fn solve_r(r: &Matrix6<f64>, w: &Vector6<f64>) -> Vector6<f64> {
    let mut x = Vector6::zeros();
    for i in (0..6).rev() {
        let mut s = w[i];
        for k in i + 1..6 {
            s -= r[(i, k)] * x[k];
        }
        x[i] = s / r[(i, i)];
    }
    x
}

/// Minimiser of `‖Rj − z‖²` with the constraints in `w` (indices into `lins`) as
/// equalities; also returns the multipliers λ (in working-set order).
fn equality_qp(
    r: &Matrix6<f64>,
    j_u: &Vector6<f64>,
    lins: &[Lin<6>],
    w: &[usize],
) -> Option<(Vector6<f64>, [f64; 6])> {
    let n = w.len();
    if n == 0 {
        return Some((*j_u, [0.0; 6]));
    }
    // Rows of M = A_W R⁻¹ as columns m_i = R⁻ᵀ a_i.
    let mut m = [Vector6::zeros(); 6];
    for (i, &l) in w.iter().enumerate() {
        m[i] = solve_rt(r, &lins[l].a);
    }
    let mut s = Matrix6::identity();
    let mut rhs = Vector6::zeros();
    for i in 0..n {
        for k in 0..n {
            s[(i, k)] = m[i].dot(&m[k]);
        }
        rhs[i] = lins[w[i]].b - lins[w[i]].a.dot(j_u);
    }
    let mu = s.cholesky()?.solve(&rhs);
    let mut comb = Vector6::zeros();
    for i in 0..n {
        comb += m[i] * mu[i];
    }
    let j = j_u + solve_r(r, &comb);
    let mut lambda = [0.0; 6];
    for i in 0..n {
        lambda[i] = 2.0 * mu[i];
    }
    j.iter().all(|v| v.is_finite()).then_some((j, lambda))
}

/// The relaxed problem's optimum, or `None` (see the module docs).
#[must_use]
pub(crate) fn solve_linear(
    r: &Matrix6<f64>,
    z: &Vector6<f64>,
    constraints: &Constraints,
) -> Option<ActiveSetSolution> {
    let lins = constraints.lins();
    if lins.is_empty() || lins.len() > MAX_LIN {
        return None;
    }
    let j_u = solve_r(r, z);
    if !j_u.iter().all(|v| v.is_finite()) {
        return None;
    }
    let scale = constraints.interior().amax().max(1.0);
    let tol = 1e-12 * scale;
    let mut j = *constraints.interior();
    let mut work = [0usize; 6];
    let mut n = 0usize;
    for it in 0..MAX_ITERATIONS {
        let (target, lambda) = equality_qp(r, &j_u, lins, &work[..n])?;
        let p = target - j;
        if p.amax() <= tol {
            // At the working-set optimum: drop the most negative multiplier, or stop.
            let (imin, lmin) =
                lambda[..n]
                    .iter()
                    .enumerate()
                    .fold(
                        (usize::MAX, 0.0f64),
                        |acc, (i, &l)| if l < acc.1 { (i, l) } else { acc },
                    );
            if imin == usize::MAX {
                return finish(r, z, lins, &work[..n], &lambda, target, it);
            }
            let _ = lmin;
            work.copy_within(imin + 1..n, imin);
            n -= 1;
            continue;
        }
        // Longest step along p that keeps every inactive constraint satisfied.
        let mut alpha = 1.0f64;
        let mut blocking = None;
        for (l, lin) in lins.iter().enumerate() {
            if work[..n].contains(&l) {
                continue;
            }
            let ap = lin.a.dot(&p);
            if ap < 0.0 {
                let step = (lin.b - lin.a.dot(&j)) / ap;
                if step < alpha {
                    alpha = step.max(0.0);
                    blocking = Some(l);
                }
            }
        }
        j += p * alpha;
        if let Some(l) = blocking {
            if n == 6 {
                return None;
            }
            work[n] = l;
            n += 1;
        }
    }
    None
}

fn finish(
    r: &Matrix6<f64>,
    z: &Vector6<f64>,
    lins: &[Lin<6>],
    work: &[usize],
    lambda: &[f64; 6],
    j: Vector6<f64>,
    iterations: u32,
) -> Option<ActiveSetSolution> {
    // Primal feasibility of every linear constraint (round-off tolerance).
    let scale = j.amax().max(1.0);
    if lins.iter().any(|l| l.eval(&j) < -1e-12 * scale) {
        return None;
    }
    let grad = r.transpose() * (r * j - z) * 2.0;
    let mut stat = grad;
    let mut gap = 0.0;
    for (i, &l) in work.iter().enumerate() {
        stat -= lins[l].a * lambda[i];
        gap += lambda[i] * lins[l].eval(&j);
    }
    Some(ActiveSetSolution {
        j,
        iterations: iterations + 1,
        dual_residual: stat.amax() / grad.amax().max(1.0),
        gap: gap.abs(),
    })
}
