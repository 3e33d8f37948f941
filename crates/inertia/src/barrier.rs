//! A log-barrier interior-point method for small problems with 3×3 LMIs.
//!
//! ```text
//! minimise   ‖A x − b‖² + cᵀ x
//! subject to F_i(x) = F_i0 + Σ_k x_k F_ik ⪰ 0     (3×3, i = 1..n_lmi)
//!            a_lᵀ x − b_l ≥ 0                     (l = 1..n_lin)
//! ```
//!
//! For a sequence `t → ∞` it minimises the self-concordant function
//! `φ_t(x) = t (‖Ax − b‖² + cᵀx) − Σ_i log det F_i(x) − Σ_l log(a_lᵀx − b_l)` by Newton
//! steps. Far from the centre (Newton decrement λ ≥ ¼) a backtracking line search on `φ_t`
//! tries longer steps, but never shorter than the damped step `1/(1+λ)`, which provably
//! stays strictly feasible and decreases `φ_t`; so round-off in comparing `φ_t` values
//! (large at large `t`) can cost speed but never convergence. Near the centre, full steps. At a central point, `Z_i = F_i⁻¹/t` and `λ_l = 1/(t s_l)` are dual
//! feasible and the duality gap is exactly `m/t` with `m = 3 n_lmi + n_lin` (Boyd &
//! Vandenberghe §11.6). Sizes are fixed at compile time; nothing allocates.
//!
//! The Newton matrix is never formed: its triangular factor is accumulated by Givens
//! rotations from rows whose Gram matrix it is (see `grad_factor`), so an `R` with
//! condition number 1e8 costs 8 digits, not 16.
//!
//! Why a barrier method rather than a primal-dual one: the problems here have six
//! unknowns and at most ~20 constraint rows, so each Newton step is a few 3×3
//! factorisations and ~30 Givens row folds. A strictly interior start is always available (found
//! once per constraint set, see `constraints`), which removes the main weakness of
//! barrier methods, and the central-path dual point gives honest optimality residuals.

use crate::constraints::description::{Lin, Lmi};
use crate::givens::{fold_row, solve_normal};
use crate::math::{ln, sqrt};
use nalgebra::{Matrix3, SMatrix, SVector};

/// A problem instance (borrowed constraint arrays): objective `‖A x − b‖² + cᵀx`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Problem<'a, const N: usize> {
    /// Least-squares matrix (e.g. the upper-triangular `R`).
    pub(crate) a: SMatrix<f64, N, N>,
    /// Least-squares right-hand side.
    pub(crate) b: SVector<f64, N>,
    /// Linear term.
    pub(crate) c: SVector<f64, N>,
    /// LMIs.
    pub(crate) lmis: &'a [Lmi<N>],
    /// Linear inequalities.
    pub(crate) lins: &'a [Lin<N>],
}

impl<const N: usize> Problem<'_, N> {
    /// The objective `‖A x − b‖² + cᵀx`.
    #[must_use]
    pub(crate) fn objective(&self, x: &SVector<f64, N>) -> f64 {
        (self.a * x - self.b).norm_squared() + self.c.dot(x)
    }
}

/// Settings of the barrier method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarrierSettings {
    /// Stop when the duality gap `m/t` is below this (objective units; the native backend's
    /// objective is scaled so that `f(0) = 1`). Default 1e-12.
    pub gap_tolerance: f64,
    /// … or below this times `|objective|`. Default 0 (off).
    pub gap_rel_tolerance: f64,
    /// When round-off stops progress (a centering stalls: central points within ~1e-12 of
    /// the boundary are at the round-off level of evaluating the LMIs), a last central
    /// point with a gap below this still counts as converged. Default 1e-9. The achieved
    /// gap is always reported.
    pub acceptable_gap: f64,
    /// Initial barrier parameter `t`. Default `None`: `m / f(x0)`, which balances the
    /// objective against the barrier at the start (`f ≥ 0` for least squares).
    pub t0: Option<f64>,
    /// Factor by which `t` grows per outer iteration. Default 10.
    pub mu: f64,
    /// Centering stops when `λ²/2` is below this. Default 1e-10.
    pub newton_tolerance: f64,
    /// Cap on Newton steps per centering. Default 50.
    pub max_centering_steps: u32,
    /// Cap on Newton steps in total. Default 400.
    pub max_newton_steps: u32,
}

impl Default for BarrierSettings {
    fn default() -> Self {
        Self {
            gap_tolerance: 1e-12,
            gap_rel_tolerance: 0.0,
            acceptable_gap: 1e-9,
            t0: None,
            mu: 10.0,
            newton_tolerance: 1e-10,
            max_centering_steps: 50,
            max_newton_steps: 400,
        }
    }
}

/// Failure of the barrier method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum BarrierError {
    /// The start point is not strictly feasible.
    NotInterior,
    /// Newton's system could not be solved (non-finite data or a singular Hessian).
    Numerical,
}

/// The result: point, barrier parameter and work done.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BarrierOutput<const N: usize> {
    /// The (approximately central) point.
    pub(crate) x: SVector<f64, N>,
    /// Final barrier parameter.
    pub(crate) t: f64,
    /// Newton steps taken.
    pub(crate) newton_steps: u32,
    /// Duality gap bound `m/t`.
    pub(crate) gap: f64,
    /// Relative dual residual `‖∇f(x) − Σ_i 𝒜_i*(Z_i) − Σ_l λ_l a_l‖∞ / max(1, ‖∇f(x)‖∞)`
    /// for the dual point corrected by the last Newton step `d` (`Z_i = (F_i⁻¹ −
    /// F_i⁻¹ ΔF_i F_i⁻¹)/t`, `λ_l = (1 − a_lᵀd/s_l)/(t s_l)`, dual feasible while the
    /// Newton decrement is below 1). By the Newton equation this residual is exactly
    /// `‖∇²f d‖∞ = ‖2AᵀA d‖∞`.
    pub(crate) dual_residual: f64,
    /// `false` when the step cap was hit before the gap tolerance.
    pub(crate) converged: bool,
}

/// `true` when every constraint holds strictly at `x`.
#[must_use]
pub(crate) fn strictly_feasible<const N: usize>(
    problem: &Problem<'_, N>,
    x: &SVector<f64, N>,
) -> bool {
    problem.lmis.iter().all(|l| l.eval(x).cholesky().is_some())
        && problem.lins.iter().all(|l| l.eval(x) > 0.0)
}

/// `φ_t(x)`, or `None` outside the domain.
fn barrier_value<const N: usize>(
    problem: &Problem<'_, N>,
    x: &SVector<f64, N>,
    t: f64,
) -> Option<f64> {
    let mut v = t * problem.objective(x);
    for l in problem.lmis {
        let ch = l.eval(x).cholesky()?;
        let d = ch.l_dirty().diagonal();
        v -= 2.0 * (ln(d[0]) + ln(d[1]) + ln(d[2]));
    }
    for l in problem.lins {
        let s = l.eval(x);
        if s <= 0.0 {
            return None;
        }
        v -= ln(s);
    }
    Some(v)
}

/// Gradient of `φ_t` and an upper-triangular factor `U` of its Hessian (`∇²φ_t = UᵀU`),
/// built by Givens rotations from rows whose Gram matrix is the Hessian:
/// `√(2t) A` for the objective, `a_l/s_l` per linear inequality, and for each LMI with
/// Cholesky factor `F = LLᵀ` the entries of `W_k = L⁻¹ F_k L⁻ᵀ` (weight √2 off the
/// diagonal), since `tr(F⁻¹F_k F⁻¹F_l) = ⟨W_k, W_l⟩`. Nothing is squared, so the factor
/// is as well conditioned as the data.
fn grad_factor<const N: usize>(
    problem: &Problem<'_, N>,
    x: &SVector<f64, N>,
    t: f64,
) -> Option<(SVector<f64, N>, SMatrix<f64, N, N>)> {
    let res = problem.a * x - problem.b;
    let mut g = (problem.a.transpose() * res * 2.0 + problem.c) * t;
    let mut u = SMatrix::<f64, N, N>::zeros();
    let st = sqrt(2.0 * t);
    for i in 0..N {
        let row = problem.a.row(i).transpose() * st;
        fold_row(&mut u, &row, None);
    }
    let r2 = core::f64::consts::SQRT_2;
    for l in problem.lmis {
        let ch = l.eval(x).cholesky()?;
        let linv = ch.l().try_inverse()?;
        let mut w = [Matrix3::zeros(); N];
        for k in 0..N {
            w[k] = linv * l.fk[k] * linv.transpose();
            g[k] -= w[k].trace();
        }
        for (p, q, weight) in [
            (0, 0, 1.0),
            (1, 1, 1.0),
            (2, 2, 1.0),
            (0, 1, r2),
            (0, 2, r2),
            (1, 2, r2),
        ] {
            let row = SVector::<f64, N>::from_fn(|k, _| w[k][(p, q)] * weight);
            fold_row(&mut u, &row, None);
        }
    }
    for l in problem.lins {
        let s = l.eval(x);
        if s <= 0.0 {
            return None;
        }
        g -= l.a / s;
        fold_row(&mut u, &(l.a / s), None);
    }
    Some((g, u))
}

/// Newton direction `d = −(UᵀU)⁻¹ g`, regularising a rank-deficient factor slightly.
fn newton_direction<const N: usize>(
    g: &SVector<f64, N>,
    u: &SMatrix<f64, N, N>,
) -> Option<SVector<f64, N>> {
    let dmax = u.diagonal().amax();
    if !(dmax > 0.0 && dmax.is_finite()) {
        return None;
    }
    let mut u = *u;
    if u.diagonal().iter().any(|&d| d <= 1e-15 * dmax) {
        for i in 0..N {
            let row = SVector::<f64, N>::from_fn(|k, _| if k == i { 1e-12 * dmax } else { 0.0 });
            fold_row(&mut u, &row, None);
        }
    }
    solve_normal(&u, g).map(|d| -d)
}

/// Result of one centering.
enum Centering {
    Done,
    /// Hit a cap or a numerical wall: keep the previous central point.
    Stalled,
}

/// Damped Newton on `φ_t` from `x` (updated in place).
fn center<const N: usize>(
    problem: &Problem<'_, N>,
    x: &mut SVector<f64, N>,
    t: f64,
    settings: &BarrierSettings,
    steps: &mut u32,
) -> Centering {
    let mut best_lambda = f64::INFINITY;
    let mut since_progress = 0;
    for _ in 0..settings.max_centering_steps {
        if *steps >= settings.max_newton_steps {
            return Centering::Stalled;
        }
        let Some((g, u)) = grad_factor(problem, x, t) else {
            return Centering::Stalled;
        };
        let Some(d) = newton_direction(&g, &u) else {
            return Centering::Stalled;
        };
        let dec2 = -g.dot(&d);
        if !dec2.is_finite() {
            return Centering::Stalled;
        }
        if dec2 * 0.5 <= settings.newton_tolerance {
            return Centering::Done;
        }
        let lambda = sqrt(dec2.max(0.0));
        // In the quadratic region λ should square each step. When three steps in a row
        // fail to halve the best λ seen, round-off dominates the Newton step and the point
        // is as central as f64 allows.
        if lambda < 0.5 * best_lambda {
            best_lambda = lambda;
            since_progress = 0;
        } else {
            since_progress += 1;
            if lambda < 0.1 && since_progress >= 3 {
                return Centering::Done;
            }
        }
        *steps += 1;
        let damped = 1.0 / (1.0 + lambda);
        let mut alpha = if lambda >= 0.25 {
            // Backtracking from a full step, floored at the damped step.
            let phi0 = barrier_value(problem, x, t);
            let mut a = 1.0;
            loop {
                if a <= damped {
                    break damped;
                }
                if let (Some(p0), Some(p1)) = (phi0, barrier_value(problem, &(*x + d * a), t)) {
                    if p1 <= p0 - 0.25 * a * dec2 {
                        break a;
                    }
                }
                a *= 0.5;
            }
        } else {
            1.0
        };
        // The damped step is feasible in exact arithmetic; guard against round-off.
        let mut xn = *x + d * alpha;
        let mut tries = 0;
        while !strictly_feasible(problem, &xn) {
            alpha *= 0.5;
            xn = *x + d * alpha;
            tries += 1;
            if tries > 30 {
                return Centering::Stalled;
            }
        }
        *x = xn;
    }
    Centering::Stalled
}

/// Most rounds of the outer (path-following) loop.
const MAX_OUTER_ROUNDS: u32 = 2_000;

/// Run the barrier method from a strictly feasible `x0`.
///
/// A centering that stalls (step cap, or round-off at a point within ~1e-12 of the
/// boundary) ends the method at the last completed central point, whose gap `m/t` is
/// reported; `converged` says whether that gap met the tolerance.
pub(crate) fn solve<const N: usize>(
    problem: &Problem<'_, N>,
    x0: &SVector<f64, N>,
    settings: &BarrierSettings,
) -> Result<BarrierOutput<N>, BarrierError> {
    if !strictly_feasible(problem, x0) {
        return Err(BarrierError::NotInterior);
    }
    if !problem
        .a
        .iter()
        .chain(problem.b.iter())
        .chain(problem.c.iter())
        .all(|v| v.is_finite())
    {
        return Err(BarrierError::Numerical);
    }
    let m = (3 * problem.lmis.len() + problem.lins.len()) as f64;
    let mut x = *x0;
    let f0 = problem.objective(&x);
    let mut t = match settings.t0 {
        Some(t0) => t0,
        None if f0 > 0.0 && m > 0.0 => m / f0,
        None => 1.0,
    }
    .max(f64::MIN_POSITIVE);
    let mut steps = 0u32;
    let mut last: Option<(SVector<f64, N>, f64)> = None;
    let converged;
    // t grows by μ > 1 per round, so m/t falls below any tolerance within a few hundred
    // rounds; the bound makes that explicit (a round that does not get there is a
    // numerical failure, reported as not converged).
    let mut rounds = 0u32;
    loop {
        rounds += 1;
        if rounds > MAX_OUTER_ROUNDS {
            converged = false;
            break;
        }
        let mut trial = x;
        match center(problem, &mut trial, t, settings, &mut steps) {
            Centering::Done => {
                x = trial;
                last = Some((x, t));
            }
            Centering::Stalled => {
                converged = last.is_some_and(|(_, tl)| m / tl <= settings.acceptable_gap);
                break;
            }
        }
        let f = problem.objective(&x);
        let tol = settings
            .gap_tolerance
            .max(settings.gap_rel_tolerance * crate::math::abs(f));
        if m == 0.0 || m / t < tol {
            converged = true;
            break;
        }
        t *= settings.mu;
    }
    let (x, t) = last.ok_or(BarrierError::Numerical)?;
    let (g, u) = grad_factor(problem, &x, t).ok_or(BarrierError::Numerical)?;
    let d = newton_direction(&g, &u).ok_or(BarrierError::Numerical)?;
    let at = problem.a.transpose();
    let grad_f = at * (problem.a * x - problem.b) * 2.0 + problem.c;
    let stationarity = at * (problem.a * d) * 2.0;
    Ok(BarrierOutput {
        x,
        t,
        newton_steps: steps,
        gap: if m == 0.0 { 0.0 } else { m / t },
        dual_residual: stationarity.amax() / grad_f.amax().max(1.0),
        converged,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, SMatrix, SVector};

    fn problem_data() -> (
        [Lmi<3>; 1],
        [Lin<3>; 1],
        SMatrix<f64, 3, 3>,
        SVector<f64, 3>,
    ) {
        let mut lmi = Lmi::<3>::zero();
        lmi.f0 = Matrix3::new(2.0, 0.3, 0.1, 0.3, 1.5, -0.2, 0.1, -0.2, 1.0);
        lmi.fk[0] = Matrix3::new(1.0, 0.2, 0.0, 0.2, 0.0, 0.1, 0.0, 0.1, -0.5);
        lmi.fk[1] = Matrix3::new(0.0, 1.0, 0.3, 1.0, 0.5, 0.0, 0.3, 0.0, 0.2);
        lmi.fk[2] = Matrix3::new(-0.3, 0.0, 0.0, 0.0, 1.0, 0.4, 0.0, 0.4, 1.0);
        let lin = Lin {
            a: SVector::<f64, 3>::new(0.5, -1.0, 0.25),
            b: -2.0,
        };
        let a = SMatrix::<f64, 3, 3>::new(2.0, 0.5, -0.3, 0.0, 1.0, 0.7, 0.0, 0.0, 0.3);
        let b = SVector::<f64, 3>::new(0.4, -0.2, 1.0);
        ([lmi], [lin], a, b)
    }

    /// The factored Hessian and the gradient match finite differences of φ_t.
    #[test]
    fn gradient_and_hessian_factor_match_finite_differences() {
        let (lmis, lins, a, b) = problem_data();
        let p = Problem {
            a,
            b,
            c: SVector::<f64, 3>::new(0.1, 0.0, -0.2),
            lmis: &lmis,
            lins: &lins,
        };
        let x = SVector::<f64, 3>::new(0.1, -0.1, 0.05);
        let t = 3.0;
        assert!(strictly_feasible(&p, &x));
        let (g, u) = grad_factor(&p, &x, t).unwrap();
        let h = u.transpose() * u;
        let e = 1e-5;
        for k in 0..3 {
            let dx = SVector::<f64, 3>::from_fn(|i, _| if i == k { e } else { 0.0 });
            let fp = barrier_value(&p, &(x + dx), t).unwrap();
            let fm = barrier_value(&p, &(x - dx), t).unwrap();
            let gk = (fp - fm) / (2.0 * e);
            assert!(
                (gk - g[k]).abs() < 1e-6 * (1.0 + g[k].abs()),
                "g[{k}] {gk} vs {}",
                g[k]
            );
            let (gp, _) = grad_factor(&p, &(x + dx), t).unwrap();
            let (gm, _) = grad_factor(&p, &(x - dx), t).unwrap();
            let hk = (gp - gm) / (2.0 * e);
            for m in 0..3 {
                assert!(
                    (hk[m] - h[(m, k)]).abs() < 1e-5 * (1.0 + h[(m, k)].abs()),
                    "H[{m},{k}] {} vs {}",
                    hk[m],
                    h[(m, k)]
                );
            }
        }
    }
}
