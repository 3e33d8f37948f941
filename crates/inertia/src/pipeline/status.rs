//! One status rule for every answer the pipeline hands out (streaming and batch, so the
//! report, the JSON, the history, Python and C say the same).
//!
//! "Determined" is a promise: the truth within 3σ in at least 90 % of cases. So an
//! answer is determined only when the estimator's own tests passed **and** it has a σ
//! **and** the model checks below pass:
//!
//! * **A σ.** An answer without a standard deviation (an estimator with no uncertainty
//!   model, a batch form without one, or σ switched off) makes no claim about how close it
//!   is: [`Observability::NoSigma`] (code `unchecked`).
//! * **A physical inertia.** The principal moments `J1 ≤ J2 ≤ J3` of a real body satisfy
//!   `J1 > 0` and `J1 + J2 ≥ J3` (the triangle inequality of the second moments, paper
//!   eq. 9). A constraint set that does not enforce it (`paper` on the diagonal only,
//!   `positive-definite`) can return an answer that breaks it; when it breaks it by more
//!   than `PHYSICAL_Z` of its stated σ (`σ(J1 + J2 − J3)` from the principal moments' σ,
//!   taken as independent), a model check failed: the truth is physical, so an answer
//!   that far outside the physical set is not within 3σ of it, and the row model or the
//!   data's conventions do not hold. The answer is not determined
//!   ([`Observability::ModelCheckFailed`] with [`Unobservable::Unphysical`]), but it and
//!   its σ stay visible: the project refuses only for rank or conditioning, a convention
//!   error the gyro proves, or a user's limit, and an unphysical answer is none of them
//!   (the paper's own J breaks `J1 + J2 ≥ J3` by 4.9e-5 kg m², so an estimator that is
//!   right to its σ can be here when its σ is smaller than that). Within `PHYSICAL_Z` σ
//!   the answer is consistent with a physical inertia at its accuracy and stays
//!   determined (the report says so, `PhysicalMargin`).
//! * **What the user said.** A relative uncertainty of the rotor momentum's scale
//!   ([`super::PipelineSettings::rotor_scale_sigma`], the wheels' spin inertia known to
//!   ±r) is a consider parameter: σ is widened by `r |ĵ|` per element
//!   (`crate::estimator::uncertainty::Uncertainty::with_rotor_scale`) before the rules
//!   above are applied, and a determined answer whose widened relative σ
//!   (`σ_F/‖Ĵ‖_F`) exceeds the observability threshold `max_relative_sigma` is not
//!   determined ([`Unobservable::Uncertain`]): the data cannot give J's scale better than
//!   the wheels'. A spacecraft file's per-rotor spin inertia ± σ is the same kind of
//!   term, per rotor (`crate::estimator::rotor_inertia`); so is the wheel-speed time
//!   tag's σ ([`crate::estimator::wheel_delay`]).

use super::config::PipelineConfig;
use crate::constraints::Consistency;
use crate::estimator::observability::{Observability, Unobservable};
use crate::estimator::uncertainty::Uncertainty;
use crate::estimator::Estimate;
use crate::tensor::{matrix_from_j, InertiaVector};

/// How many σ of `J1 + J2 − J3` (or of `J1`) an answer may lie beyond the physical set
/// and still be determined.
pub(crate) const PHYSICAL_Z: f64 = 3.0;

/// A violation smaller than this fraction of `J3` is round-off, not a violation.
pub(crate) const PHYSICAL_ROUND_OFF: f64 = 1e-6;

/// How far an answer lies outside the physical set.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct PhysicalMargin {
    /// Smallest principal moment `J1`, kg m².
    pub min_moment_kg_m2: f64,
    /// `J1 + J2 − J3`, kg m² (negative: the triangle inequality is broken).
    pub triangle_kg_m2: f64,
    /// σ of `J1 + J2 − J3` from the principal moments' σ taken as independent (`None`
    /// without a σ).
    pub triangle_sigma_kg_m2: Option<f64>,
    /// The larger of the two violations in units of its σ (`None` without a σ).
    pub z: Option<f64>,
}

impl PhysicalMargin {
    /// Whether the violation exceeds [`PHYSICAL_Z`] σ (or there is no σ to judge it).
    #[must_use]
    pub(crate) fn significant(&self) -> bool {
        self.z.is_none_or(|z| z > PHYSICAL_Z)
    }
}

/// The physical margin of `e`'s answer when it breaks `J1 > 0` or `J1 + J2 ≥ J3` by more
/// than round-off; `None` for a physical answer or none.
#[must_use]
pub(crate) fn physical_margin(e: &Estimate) -> Option<PhysicalMargin> {
    let j = e.j()?;
    let (mut m, _) = crate::eigen3::symmetric_eigen3(&matrix_from_j(&j));
    m.as_mut_slice().sort_unstable_by(f64::total_cmp);
    let triangle = m[0] + m[1] - m[2];
    let tol = PHYSICAL_ROUND_OFF * m[2].abs();
    if m[0] > 0.0 && triangle >= -tol {
        return None;
    }
    let triangle_sigma = e.uncertainty.map(|u| {
        let s = u.principal_sigma_kg_m2;
        crate::math::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2])
    });
    let z = e.uncertainty.zip(triangle_sigma).map(|(u, st)| {
        let s = u.principal_sigma_kg_m2;
        let zt = if triangle < -tol { -triangle / st } else { 0.0 };
        let z1 = if m[0] <= 0.0 { -m[0] / s[0] } else { 0.0 };
        let z = zt.max(z1);
        if z.is_nan() {
            f64::INFINITY
        } else {
            z
        }
    });
    Some(PhysicalMargin {
        min_moment_kg_m2: m[0],
        triangle_kg_m2: triangle,
        triangle_sigma_kg_m2: triangle_sigma,
        z,
    })
}

/// Apply every rule ([module docs](self)) to `e`, an answer of a run with `config`: the
/// wheel-speed time tag's consider term where one was applied
/// ([`crate::estimator::wheel_delay`]), the rotors' spin-inertia term of a spacecraft file
/// ([`crate::estimator::rotor_inertia`]), the known torque's scale term where a run has
/// computed one (`Run::torque_scale_term`), the rotor scale's where one is given
/// ([`widen_for_rotor_scale`]), then [`settle`].
pub(crate) fn apply(e: &mut Estimate, config: &PipelineConfig) {
    let threshold = config.observability.max_relative_sigma;
    if let Some(c) = config.wheel_delay_consider {
        widen(e, threshold, |u, j| u.with_time_tag(j, &c));
    }
    if let Some(c) = config.rotor_inertia_consider {
        widen(e, threshold, |u, j| u.with_rotor_inertia(j, &c));
    }
    if let Some(c) = config.torque_scale_consider {
        widen(e, threshold, |u, j| u.with_torque_scale(j, &c));
    }
    if let Some(r) = config.rotor_scale_sigma {
        widen_for_rotor_scale(e, r, threshold);
    }
    settle(e, config.constraints().set().consistency);
}

/// Widen `e`'s σ by the rotor momentum's scale uncertainty `r` (relative) and take
/// "determined" back where the widened relative σ `σ_F/‖Ĵ‖_F` exceeds `threshold`
/// (module docs, "What the user said"); the answer is kept.
pub(crate) fn widen_for_rotor_scale(e: &mut Estimate, r: f64, threshold: f64) {
    widen(e, threshold, |u, j| u.with_rotor_scale(j, r));
}

/// Widen `e`'s σ by a consider term (`widened`) and take "determined" back where the
/// widened relative σ `σ_F/‖Ĵ‖_F` exceeds `threshold`; the answer is kept.
fn widen(
    e: &mut Estimate,
    threshold: f64,
    widened: impl Fn(&Uncertainty, &InertiaVector) -> Uncertainty,
) {
    let (Some(u), Some(j)) = (e.uncertainty, e.j()) else {
        return;
    };
    let u = widened(&u, &j);
    e.uncertainty = Some(u);
    let relative_sigma = u.frobenius_sigma_kg_m2() / matrix_from_j(&j).norm();
    if matches!(e.observability, Observability::Determined { .. }) && !(relative_sigma <= threshold)
    {
        e.observability = Observability::NotObservable(Unobservable::Uncertain {
            relative_sigma,
            threshold,
            dominant: u.dominant_part(),
        });
    }
}

/// Apply the status rules ([module docs](self)) to `e`, an answer under the consistency
/// condition `consistency` (under [`Consistency::Physical`] the answer is physical by
/// construction, to the solver's tolerance, and only the σ rule applies).
pub fn settle(e: &mut Estimate, consistency: Consistency) {
    let judged = consistency != Consistency::Physical
        && matches!(
            e.observability,
            Observability::Determined { .. } | Observability::FromPrior(_)
        );
    if judged && e.uncertainty.is_some() {
        if let Some(p) = physical_margin(e).filter(PhysicalMargin::significant) {
            e.observability = Observability::ModelCheckFailed(Unobservable::Unphysical {
                min_moment_kg_m2: p.min_moment_kg_m2,
                triangle_kg_m2: p.triangle_kg_m2,
                triangle_sigma_kg_m2: p.triangle_sigma_kg_m2.unwrap_or(f64::INFINITY),
                z: p.z.unwrap_or(f64::INFINITY),
            });
            return;
        }
    }
    if let (Observability::Determined { condition }, None) = (e.observability, e.uncertainty) {
        e.observability = Observability::NoSigma { condition };
    }
}
