//! Can the status be trusted? Checks of an answer against its own data, run after every
//! solve (beyond the paper). "Determined" is a promise that the answer is right within its
//! stated σ; it is withdrawn when:
//!
//! * the answer rests on the `J ⪰ εI` floor (smallest principal moment below 2ε): the
//!   data do not support a positive-definite J, which is what a reversed sign of ρ or τ or
//!   a conjugated quaternion produce → [`Unobservable::AtFloor`], no answer; where the
//!   negated least-squares answer would pass as determined (what a reversed sign of ρ
//!   gives: the rows are linear in `j` and ρ) the pipeline stops
//!   ([`crate::pipeline::PipelineError::ReversedMomentum`]);
//! * the stated σ is comparable to J (`σ_F > max_relative_sigma · ‖Ĵ‖_F`) →
//!   [`Unobservable::Uncertain`], no answer;
//! * the constraints moved the answer further than the noise allows:
//!   `χ² = (‖R ĵ − z‖² − ‖R j_ls − z‖²)/s²`, which is χ²-distributed with at most six
//!   degrees of freedom when the truth satisfies the constraints, exceeds
//!   [`CONFLICT_CHI2`] → [`Unobservable::ConflictsWithConstraints`], reported as an answer
//!   that leans on the constraint set ([`Observability::FromPrior`]), not on the data.
//!   Where the user stated a relative σ `r` of the rotor momentum (the wheels' spin
//!   inertia: [`crate::pipeline::PipelineSettings::rotor_scale_sigma`], a spacecraft
//!   file's rotors), the unconstrained answer is itself uncertain by about `r ‖Ĵ‖_F` per
//!   element beyond the noise, and the move is measured against both:
//!   `χ² = Δᵀ (s²(RᵀR)⁻¹ + (r ‖Ĵ‖_F)² I)⁻¹ Δ`, `Δ = ĵ − j_ls`.

// The crate-internal helpers here serve the std front ends (pipeline, estimators).
#![cfg_attr(not(feature = "std"), allow(dead_code))]

use super::observability::{Observability, Unobservable};
use super::qr::RecursiveQr;
use super::Estimate;
use crate::tensor::matrix_from_j;

/// χ² threshold of the constraint-conflict test: the 1 − 10⁻⁴ quantile of χ²₆.
pub(crate) const CONFLICT_CHI2: f64 = 27.86;

/// Withdraw or qualify the status of `e` (solved from `qr` under a `J ⪰ εI` floor of
/// `epsilon_kg_m2`) where its own data contradict it.
pub(crate) fn audit(
    e: &mut Estimate,
    qr: &RecursiveQr,
    epsilon_kg_m2: f64,
    max_relative_sigma: f64,
    stated_relative_sigma: f64,
) {
    let moments = e
        .j()
        .map(|j| crate::eigen3::symmetric_eigen3(&matrix_from_j(&j)).0);
    audit_at(
        e,
        qr,
        epsilon_kg_m2,
        max_relative_sigma,
        stated_relative_sigma,
        moments.as_ref(),
    );
}

/// [`audit`] given the principal moments of `e`'s `J` (any order), for a caller that has
/// them already.
pub(crate) fn audit_at(
    e: &mut Estimate,
    qr: &RecursiveQr,
    epsilon_kg_m2: f64,
    max_relative_sigma: f64,
    stated_relative_sigma: f64,
    moments: Option<&nalgebra::Vector3<f64>>,
) {
    if !matches!(
        e.observability,
        Observability::Determined { .. } | Observability::FromPrior(_)
    ) {
        return;
    }
    let (Some(j), Some(moments)) = (e.j(), moments) else {
        return;
    };
    if let Some(floor) = at_floor(e, qr, epsilon_kg_m2, max_relative_sigma, moments) {
        e.observability = Observability::NotObservable(floor);
        e.solution = None;
        e.uncertainty = None;
        return;
    }
    let m = matrix_from_j(&j);
    let unconstrained = crate::solver::unconstrained_minimiser(&qr.r, &qr.z);
    if let Some(u) = &e.uncertainty {
        let relative_sigma = u.frobenius_sigma_kg_m2() / m.norm();
        if !(relative_sigma <= max_relative_sigma) {
            e.observability = Observability::NotObservable(Unobservable::Uncertain {
                relative_sigma,
                threshold: max_relative_sigma,
                dominant: u.dominant_part(),
            });
            e.solution = None;
            e.uncertainty = None;
            return;
        }
    }
    let dof = qr.residual_dof();
    if let (Some(u), true, Observability::Determined { .. }) =
        (unconstrained, dof > 0.0 && qr.rss > 0.0, e.observability)
    {
        let s2 = qr.rss / dof;
        let gain = (qr.r * j - qr.z).norm_squared() - (qr.r * u - qr.z).norm_squared();
        let chi2 = if stated_relative_sigma > 0.0 {
            // Δᵀ (s²(RᵀR)⁻¹ + c² I)⁻¹ Δ; the noise-only χ² where that cannot be formed.
            let c = stated_relative_sigma * m.norm();
            (qr.r.transpose() * qr.r)
                .try_inverse()
                .map(|p| p * s2 + nalgebra::Matrix6::identity() * (c * c))
                .and_then(nalgebra::Matrix6::try_inverse)
                .map_or(gain / s2, |w| {
                    let d = j - u;
                    (d.transpose() * w * d)[(0, 0)]
                })
        } else {
            gain / s2
        };
        if chi2 > CONFLICT_CHI2 {
            e.observability =
                Observability::FromPrior(Unobservable::ConflictsWithConstraints { chi2 });
        }
    }
}

/// The least-squares σ of `‖Ĵ − J‖_F`, kg m², from `qr` (`s² (RᵀR)⁻¹`, each product of
/// inertia counted twice); `None` without residual degrees of freedom or with a singular
/// `R`.
fn least_squares_frobenius_sigma(qr: &RecursiveQr) -> Option<f64> {
    let dof = qr.residual_dof();
    if !(dof > 0.0) {
        return None;
    }
    let inverse = qr.r.try_inverse()?;
    let weights = [1.0, 1.0, 1.0, 2.0, 2.0, 2.0];
    let v: f64 = (0..6)
        .map(|i| weights[i] * inverse.row(i).norm_squared())
        .sum();
    let sigma = crate::math::sqrt(qr.rss / dof * v);
    sigma.is_finite().then_some(sigma)
}

/// [`Unobservable::AtFloor`] where `e`'s answer (principal moments `moments`) rests on the
/// `J ⪰ εI` floor, with what the unconstrained answer `J_ls` of `qr` says: whether it is
/// negative definite, and whether `−J_ls` would pass as determined (above the floor, σ —
/// the stated one, else the least-squares one — within `max_relative_sigma · ‖J_ls‖`).
/// `None` off the floor.
#[must_use]
pub(crate) fn at_floor(
    e: &Estimate,
    qr: &RecursiveQr,
    epsilon_kg_m2: f64,
    max_relative_sigma: f64,
    moments: &nalgebra::Vector3<f64>,
) -> Option<Unobservable> {
    let min_moment_kg_m2 = moments.min();
    if !(min_moment_kg_m2 < 2.0 * epsilon_kg_m2) {
        return None;
    }
    let unconstrained = crate::solver::unconstrained_minimiser(&qr.r, &qr.z);
    let largest =
        unconstrained.map(|u| crate::eigen3::symmetric_eigen3(&matrix_from_j(&u)).0.max());
    let sigma = e
        .uncertainty
        .as_ref()
        .map(super::uncertainty::Uncertainty::frobenius_sigma_kg_m2)
        .or_else(|| least_squares_frobenius_sigma(qr));
    let mirror_determined = match (unconstrained, largest, sigma) {
        (Some(u), Some(m), Some(s)) => {
            -m >= 2.0 * epsilon_kg_m2 && s <= max_relative_sigma * matrix_from_j(&u).norm()
        }
        _ => false,
    };
    Some(Unobservable::AtFloor {
        min_moment_kg_m2,
        unconstrained_negative: largest.is_some_and(|m| m < 0.0),
        mirror_determined,
    })
}

/// Whether `e`, solved (determined or from the prior) with principal moments `moments`,
/// rests on the floor where `−J_ls` would be determined ([`at_floor`]): what a reversed
/// sign of ρ gives. Checked before a cross-check that would withdraw the answer for
/// another reason.
#[must_use]
pub(crate) fn reversed_at_floor(
    e: &Estimate,
    qr: &RecursiveQr,
    epsilon_kg_m2: f64,
    max_relative_sigma: f64,
    moments: &nalgebra::Vector3<f64>,
) -> bool {
    matches!(
        e.observability,
        Observability::Determined { .. } | Observability::FromPrior(_)
    ) && e.j().is_some()
        && matches!(
            at_floor(e, qr, epsilon_kg_m2, max_relative_sigma, moments),
            Some(Unobservable::AtFloor {
                mirror_determined: true,
                ..
            })
        )
}
