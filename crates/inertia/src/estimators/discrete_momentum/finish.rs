//! The σ and the status of an answer: one sequence for the streaming path
//! ([`super::DiscreteMomentum`]) and the batch path ([`super::batch`]), each of which
//! hands it what its candidates know ([`Evidence`]).
//!
//! 1. σ: the chosen candidate's noise σ with the bias terms in quadrature, the model
//!    spread and the discretisation bias ([`super::sigma`]);
//! 2. an answer on the floor whose negation would be determined (a reversed ρ: the
//!    pipeline stops there) is told as that, before the cross-check, which would withdraw
//!    it as the rotation sources' disagreement;
//! 3. the cross-check with the other candidates' own answers ([`reconcile`]);
//! 4. the audit of the answer against its own rows ([`crate::estimator::audit`]), and an
//!    answer whose scale only a prior could give withdrawn ([`scale_from_prior`]);
//! 5. the residuals against the stated gyro density and, recursive only, against their
//!    own spans ([`crate::estimator::consistency`]).

use super::cross_check::reconcile;
use super::sigma::{quadrature, scale_from_prior, NO_EIGEN};
use crate::eigen3::symmetric_eigen3;
use crate::estimator::audit::{audit_at, reversed_at_floor};
use crate::estimator::consistency::{self, ResidualSegments};
use crate::estimator::observability::{Observability, Unobservable, NEGATIVE_DAMPING_Z};
use crate::estimator::qr::RecursiveQr;
use crate::estimator::uncertainty::{with_bias_at, Uncertainty};
use crate::estimator::Estimate;
use crate::pipeline::config::PipelineConfig;
use crate::tensor::{matrix_from_j, InertiaVector};

/// What the σ and the status of an answer need from the candidates behind it.
pub(super) trait Evidence {
    /// A failed solve of another candidate for the cross-check.
    type Error;
    /// The run's settings.
    fn config(&self) -> &PipelineConfig;
    /// The chosen candidate's rows as solved (torque-tested, with the prior's): what the
    /// audit judges.
    fn solved(&self) -> &RecursiveQr;
    /// The chosen candidate's rows, torque-tested, without the prior's
    /// ([`scale_from_prior`]).
    fn data(&self) -> &RecursiveQr;
    /// The model-uncertainty part of σ ([`super::sigma::model_spread`]).
    fn model_spread(&self) -> [f64; 6];
    /// The discretisation-bias part of σ ([`super::sigma::discretisation_bias`]); zero
    /// where it cannot be told.
    fn discretisation_bias(&self) -> [f64; 6];
    /// The other candidates' own answers `(ĵ, noise σ)` to cross-check `e` with, asked
    /// for a determined `e` only.
    fn cross_check(&mut self, e: &Estimate) -> Result<&[(InertiaVector, [f64; 6])], Self::Error>;
    /// The residuals' ratio to the stated gyro density at `j`
    /// ([`consistency::gyro_density_ratio`]; `None`: no test).
    fn density_ratio(&self, j: &InertiaVector, gyro_noise_rad_s_rthz: f64) -> Option<f64>;
    /// The chosen candidate's residual record to test `e` against, once `e` has been noted
    /// as the reference of the spans that start after it (`None`: no record).
    fn residuals(&mut self, e: &Estimate) -> Option<&ResidualSegments>;
    /// The damping `D` (N m s) that fits best at `j`, with its σ (the larger of the
    /// least-squares and the jackknife σ), where the chosen rows estimate one.
    fn damping(&self, j: &InertiaVector) -> Option<(f64, Option<f64>)>;
}

/// How [`finish`] ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Finished {
    /// The answer was told as a reversed ρ ([`reversed_at_floor`]): nothing after it ran.
    Reversed,
    /// Every step ran; the residuals' ratio to the stated gyro density
    /// ([`Evidence::density_ratio`]) and the damping with its σ ([`damping`]).
    Checked {
        /// `None`: no test.
        density_ratio: Option<f64>,
        /// `(D, σ_D)`, N m s; `None` where not estimated.
        damping: Option<(f64, Option<f64>)>,
    },
}

/// Give the solved answer `e` of the chosen candidate, whose noise σ is `noise`, its σ and
/// its status (module docs).
pub(super) fn finish<V: Evidence>(
    e: &mut Estimate,
    noise: Option<[f64; 6]>,
    evidence: &mut V,
) -> Result<Finished, V::Error> {
    // The eigenpairs of Ĵ, once for σ's principal moments, the cross-check and the
    // audit (a withdrawn answer has none, and none of them runs).
    let eig = e
        .j()
        .map_or(NO_EIGEN, |j| symmetric_eigen3(&matrix_from_j(&j)));
    let (uncertainty, gyro, epsilon, max_relative_sigma, stated) = {
        let c = evidence.config();
        (
            c.uncertainty,
            c.gyro_noise_rad_s_rthz,
            c.constraints.set().epsilon_kg_m2,
            c.observability.max_relative_sigma,
            c.stated_relative_sigma(),
        )
    };
    if uncertainty {
        if let (Some(_), Some(noise)) = (e.j(), noise) {
            let spread = evidence.model_spread();
            let discretisation = evidence.discretisation_bias();
            let bias = quadrature(&spread, &discretisation);
            e.uncertainty = Some(Uncertainty {
                model_spread_kg_m2: spread,
                ..with_bias_at(&noise, &bias, &eig)
            });
        }
    }
    if reversed_at_floor(e, evidence.solved(), epsilon, max_relative_sigma, &eig.0) {
        audit_at(
            e,
            evidence.solved(),
            epsilon,
            max_relative_sigma,
            stated,
            Some(&eig.0),
        );
        return Ok(Finished::Reversed);
    }
    // Without σ there is nothing to cross-check with (the answers' σ are not stated).
    if uncertainty && matches!(e.observability, Observability::Determined { .. }) {
        // With an estimated density the gyro's rows are compensated and the attitude's
        // are not: their answers may differ by the compensation's move, which is no
        // disagreement of the measurements.
        let slack = gyro
            .filter(|_| evidence.config().gyro_noise_estimated)
            .and_then(|g| compensation_move(evidence.data(), g, &evidence.config().constraints));
        let others = evidence.cross_check(e)?;
        reconcile(e, &eig, others, max_relative_sigma, slack.as_ref());
    }
    audit_at(
        e,
        evidence.solved(),
        epsilon,
        max_relative_sigma,
        stated,
        Some(&eig.0),
    );
    scale_from_prior(e, evidence.data(), &evidence.config().constraints);
    let density_ratio = match (gyro, e.j()) {
        (Some(g), Some(j)) => evidence.density_ratio(&j, g),
        _ => None,
    };
    // An estimated density is not the user's statement to refute: reported, not tested.
    let tested = density_ratio.filter(|_| !evidence.config().gyro_noise_estimated);
    consistency::check(e, evidence.residuals(e), tested, stated);
    let damping = damping(e, evidence);
    Ok(Finished::Checked {
        density_ratio,
        damping,
    })
}

/// The damping `D` at the answer with its σ ([`Evidence::damping`]: the larger of the
/// least-squares and the jackknife σ, as `j`'s noise σ), and the model check on its sign:
/// a `D` negative beyond [`NEGATIVE_DAMPING_Z`] of its σ fails it, since a drag cannot
/// feed energy in, so the damping's column stands in for another effect. It names that
/// effect, so it replaces a failed constraint check (whose answer the same stand-in
/// bends).
fn damping<V: Evidence>(e: &mut Estimate, evidence: &V) -> Option<(f64, Option<f64>)> {
    let (d, sigma) = evidence.damping(&e.j()?)?;
    if let (
        Some(s),
        Observability::Determined { .. }
        | Observability::FromPrior(Unobservable::ConflictsWithConstraints { .. }),
    ) = (sigma, e.observability)
    {
        if d < -NEGATIVE_DAMPING_Z * s {
            e.observability = Observability::ModelCheckFailed(Unobservable::NegativeDamping {
                damping_nms: d,
                sigma_nms: s,
            });
        }
    }
    Some((d, sigma))
}

/// `|ĵ(g) − ĵ|` per element: the move of the unconstrained answer of `data` when it is
/// compensated for a gyro density `g` ([`super::sigma::own_solution`]).
fn compensation_move(
    data: &crate::estimator::qr::RecursiveQr,
    g: f64,
    constraints: &crate::constraints::Constraints,
) -> Option<[f64; 6]> {
    let with = super::sigma::own_solution(data, Some(g), constraints)?;
    let without = super::sigma::own_solution(data, None, constraints)?;
    Some(core::array::from_fn(|k| (with[k] - without[k]).abs()))
}
