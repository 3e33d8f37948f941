//! Prior knowledge inside the least squares: equalities eliminated, and a Gaussian prior
//! on `j` as rows (issue 13; the paper's prior is the J33 interval of §VI).
//!
//! ```text
//! data:        ‖R j − z‖² / s²                  s² = ρ²/(rows − (6 − m)) from the data
//! equalities:  j_k = v_k (k ∈ F, m of them)      eliminated: solver::eliminate_fixed
//! prior:       Σ_k (j_k − μ_k)² / σ_k²           rows (s/σ_k) j_k = (s/σ_k) μ_k
//! ```
//!
//! The prior rows are weighed against the data by the data's own residual scale `s`, so
//! the stacked factor `R'` gives the posterior covariance `P = s² (R'ᵀR')⁻¹ =
//! (RᵀR/s² + Σ_p⁻¹)⁻¹` through the same formulas as the data alone
//! (`super::uncertainty::noise_sigma`, [`super::observability`]): the prior counts
//! toward observability, and σ combines data and prior. The rows are added at each solve
//! to the data's factor, never folded into it: they cost nothing per sample and are not
//! forgotten under `memory_s`.
//!
//! What the augmented state reports:
//! * the fraction of the information on each element that comes from the data,
//!   `1 − P_kk/σ_k²` (0: the prior alone; → 1: the data);
//! * the prior-data disagreement `χ² = Δρ²/s²`, `Δρ²` the misfit the prior rows add: for
//!   a prior that is right within its σ, a χ² with as many degrees of freedom as the data
//!   determine (at most `p`, the prior's rows), were the rows' errors independent. Above
//!   `RESIDUAL_VARIANCE_ALLOWANCE` (4) times the 99.9 % point of `χ²_p` the answer is
//!   withdrawn as [`super::observability::Unobservable::PriorConflict`].
//!
//! Without excitation (`y ≡ 0`) the data fix only the direction of `j`: `s² = σ_6²
//! ‖μ‖²/(rows − 5)`, the misfit of that direction at the prior's size, and the scale
//! is the prior's alone (the data's information along it is removed).
//!
//! With noise-free data (`ρ² = 0`), or data that leave a direction open (`σ_6(R)` below
//! `SCALE_FLOOR · c`), `s` is floored at `SCALE_FLOOR · c · min σ_k` (`SCALE_FLOOR` =
//! 1e-4, `c` the root-mean-square column norm of `R`), so that the prior still fixes the directions the
//! data leave open, with its own σ there, in a problem the solvers resolve. Data that
//! determine every direction keep their own `s`: a prior never makes σ larger than the
//! data's alone.

use super::qr::RecursiveQr;
use crate::constraints::Constraints;
use crate::solver::eliminate_fixed;
use nalgebra::Vector6;

/// 99.9 % points of `χ²_k`, `k = 1 … 6`.
pub(crate) const CHI2_999: [f64; 6] = [10.828, 13.816, 16.266, 18.467, 20.515, 22.458];

/// Floor of the residual scale `s`, relative to `c · min σ_k` (`c` the root-mean-square
/// column norm of `R`): data that fit (nearly) exactly still leave the prior a weight
/// within `10⁻⁸` of theirs in the normal equations, which the solvers resolve.
pub(crate) const SCALE_FLOOR: f64 = 1e-4;

/// How much the residual scale `s` may understate the noise of `ĵ`: the conflict test
/// flags `χ² > RESIDUAL_VARIANCE_ALLOWANCE · χ²_{p, 0.999}`. The rows' errors are
/// correlated (the reason the discrete momentum estimator states a jackknife σ), so the
/// residuals understate the variance of `ĵ`: on the under-excited test data
/// (`tests/integration/prior.rs`) the median χ² of a right prior is 9.5 against χ²₃'s 2.4, a factor
/// of 4.
pub(crate) const RESIDUAL_VARIANCE_ALLOWANCE: f64 = 4.0;

/// How the prior sits with the data at one solve.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PriorFit {
    /// Prior-data disagreement `Δρ²/s²` (module docs).
    pub chi2: f64,
    /// Rows of the prior (its degrees of freedom at most).
    pub rows: usize,
    /// Fraction of the information on each element from the data, `1 − P_kk/σ_k²`;
    /// `None` for an element fixed by an equality.
    pub data_share: [Option<f64>; 6],
}

impl PriorFit {
    /// `true` when the prior and the data disagree past `Self::threshold`.
    #[must_use]
    pub fn conflicts(&self) -> bool {
        self.rows > 0 && self.chi2 > self.threshold()
    }

    /// The χ² above which the prior and the data conflict.
    #[must_use]
    pub(crate) fn threshold(&self) -> f64 {
        RESIDUAL_VARIANCE_ALLOWANCE * CHI2_999[self.rows.clamp(1, 6) - 1]
    }
}

/// The equalities' disagreement with the data, `χ² = Δρ²/s²`: the misfit the fixed
/// values add over the data's least squares, in units of the data's residual variance
/// (before the equalities). `None` without equalities or residual degrees of freedom.
/// Above [`super::audit::CONFLICT_CHI2`] the data contradict the equalities, as they
/// contradicted an active bound before equalities were eliminated.
#[must_use]
pub(crate) fn equality_chi2(qr: &RecursiveQr, constraints: &Constraints) -> Option<f64> {
    let fixed = constraints.fixed();
    if fixed.iter().all(Option::is_none) || !(qr.residual_dof() > 0.0 && qr.rss > 0.0) {
        return None;
    }
    let e = eliminate_fixed(&qr.r, &qr.z, fixed);
    Some(e.extra_rss / (qr.rss / qr.residual_dof()))
}

/// `sigma` with 0 for the elements fixed by equalities (their pinning rows give them a
/// least-squares σ that stands for nothing).
#[must_use]
pub(crate) fn zero_fixed(mut sigma: [f64; 6], constraints: &Constraints) -> [f64; 6] {
    for (s, v) in sigma.iter_mut().zip(constraints.fixed()) {
        if v.is_some() {
            *s = 0.0;
        }
    }
    sigma
}

/// `true` when `constraints` carry an equality or a prior (else [`augment`] is the
/// identity).
#[must_use]
pub(crate) fn applies(constraints: &Constraints) -> bool {
    constraints.set().prior.is_some() || constraints.fixed().iter().any(Option::is_some)
}

fn reduce(qr: &RecursiveQr, fixed: &[Option<f64>; 6]) -> (RecursiveQr, f64) {
    let mut out = *qr;
    if fixed.iter().all(Option::is_none) {
        let norm2: f64 = (0..6).map(|k| qr.r.column(k).norm_squared()).sum();
        let scale = crate::math::sqrt(norm2 / 6.0);
        return (out, if scale > 0.0 { scale } else { 1.0 });
    }
    let e = eliminate_fixed(&qr.r, &qr.z, fixed);
    out.r = e.r;
    out.z = e.z;
    out.rss += e.extra_rss;
    out.rows += e.fixed;
    out.weight += e.fixed as f64;
    out.y_energy += fixed
        .iter()
        .flatten()
        .map(|v| e.scale * e.scale * v * v)
        .sum::<f64>();
    (out, e.scale)
}

/// The data's state with the prior knowledge of `constraints` stacked on: the fixed
/// elements eliminated (the reduced problem embedded in six unknowns, each fixed element
/// pinned by one exact row), then the prior rows. Returns the state unchanged
/// (and no fit) when there is no equality and no prior. The state's `rss` and `weight`
/// stay the data's, so its residual variance is `s²`.
#[must_use]
pub(crate) fn augment(
    qr: &RecursiveQr,
    constraints: &Constraints,
) -> (RecursiveQr, Option<PriorFit>) {
    if !applies(constraints) {
        return (*qr, None);
    }
    let fixed = constraints.fixed();
    let (mut out, scale) = reduce(qr, fixed);
    let Some(p) = constraints.set().prior else {
        return (out, None);
    };
    let sigma_min = p.sigma_kg_m2.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    let floor = SCALE_FLOOR * scale * sigma_min;
    let dof = out.residual_dof();
    // Without rotor momentum or known torque (`y ≡ 0`, and no equality giving a scale)
    // the data fix only the direction `v_6` of `j`: their least-squares `j` is 0 and fits
    // exactly. The misfit of that direction, `σ_6² ‖j‖²/(rows − 5)` at the prior's
    // `‖j‖`, measures the noise (as [`super::observability::direction_relative_sigma`]
    // does), and the data's information along `v_6` is removed: the scale is the
    // prior's alone.
    let mut scale_free = 0.0;
    if out.y_energy == 0.0 && dof > 0.0 {
        let svd = out.r.svd(false, true);
        if let Some(v_t) = svd.v_t {
            let (i, smin) = svd.singular_values.argmin();
            let v = v_t.row(i).transpose();
            let norm2: f64 = p.mean_kg_m2.iter().map(|m| m * m).sum();
            scale_free = smin * smin * norm2 / (dof + 1.0);
            let projected = out.r - out.r * v * v.transpose();
            out.r = projected.qr().r();
        }
    }
    // The floor is for data that leave a direction open (ill-conditioned `R`) and fit
    // (nearly) exactly: there the prior's rows must keep a weight the solvers resolve.
    // Data that determine every direction need no floor, and one would make the data's
    // residual scale, and so σ, grow with the prior's σ (issue 30).
    let open = out.r.singular_values().min() < SCALE_FLOOR * scale;
    let own = if dof > 0.0 {
        crate::math::sqrt((out.rss / dof).max(scale_free))
    } else {
        0.0
    };
    let s = if open || !(own > 0.0) {
        own.max(floor)
    } else {
        own
    };
    if dof > 0.0 {
        // Noise-free data: the floor stands for s in every formula downstream.
        out.rss = out.rss.max(s * s * dof);
    }
    let mut misfit = 0.0;
    let mut rows = 0;
    for k in (0..6).filter(|&k| fixed[k].is_none()) {
        let w = s / p.sigma_kg_m2[k];
        let y = w * p.mean_kg_m2[k];
        let left = crate::givens::fold_row(&mut out.r, &Vector6::ith(k, w), Some((&mut out.z, y)));
        misfit += left * left;
        out.y_energy += y * y;
        rows += 1;
    }
    // P_kk = s² Σ_i (R'⁻¹)_{ki}²: columns of R'⁻ᵀ by back substitution.
    let rinv = out.r.try_inverse();
    let data_share = core::array::from_fn(|k| {
        if fixed[k].is_some() {
            return None;
        }
        let pkk = match &rinv {
            Some(ri) => s * s * ri.row(k).norm_squared(),
            None => f64::INFINITY,
        };
        let sk = p.sigma_kg_m2[k];
        Some((1.0 - pkk / (sk * sk)).clamp(0.0, 1.0))
    });
    let fit = PriorFit {
        chi2: if s > 0.0 { misfit / (s * s) } else { 0.0 },
        rows,
        data_share,
    };
    (out, Some(fit))
}

#[cfg(all(test, feature = "sim"))]
mod tests;
