//! Can the data determine J? (paper §IV, last paragraph; docs/conventions.md §5)
//!
//! `J` is determined only if `φ_k` changes in time (else `H_k = 0`) and some rotor momentum
//! or known torque excites the rows (else `y ≡ 0` and J is fixed only up to scale). The
//! test here looks at the singular values `σ_1 ≥ … ≥ σ_6` of `R` and at `Σ‖y_k‖²`:
//!
//! * `y ≡ 0` → [`Unobservable::NoExcitation`];
//! * `σ_6` below `crate::solver::SINGULAR_RATIO` of `σ_1`, or fewer than six rows →
//!   [`Unobservable::RankDeficient`];
//! * `σ_1/σ_6` above the threshold (`DEFAULT_CONDITION_THRESHOLD`) →
//!   [`Unobservable::IllConditioned`];
//! * the least-squares standard deviation of `j`, `‖σ_j‖/‖ĵ‖` with
//!   `Cov(ĵ) = s² (RᵀR)⁻¹`, `s² = ρ²/(rows − 6)`, above [`DEFAULT_MAX_RELATIVE_SIGMA`] →
//!   [`Unobservable::Uncertain`]. This catches rows made of sensor noise only (a
//!   spacecraft at rest): random rows are well conditioned, but explain nothing, and
//!   `R⁻¹ z` is then noise of arbitrary size.
//!
//! When the data fall short by at most one direction (one small singular value, or only
//! the scale missing because `y ≡ 0`) and the constraint set has a-priori element
//! bounds, the bounds can pin that direction: the estimate is reported as
//! [`Observability::FromPrior`], an answer that leans on the prior. Otherwise the estimate
//! is [`Observability::NotObservable`] and no answer is given.

use super::qr::RecursiveQr;
use crate::fix::Fix;

/// Default largest acceptable condition number `σ_1/σ_6` of `R`. Past it, noise in the
/// weakest direction is amplified a million-fold relative to the strongest.
pub(crate) const DEFAULT_CONDITION_THRESHOLD: f64 = 1e6;

/// Default largest acceptable relative standard deviation `‖σ_j‖/‖ĵ‖` of the
/// unconstrained estimate.
pub const DEFAULT_MAX_RELATIVE_SIGMA: f64 = 0.1;

/// Residual degrees of freedom needed before a variance estimate is trusted: with fewer,
/// `s²` (and so every σ) is itself too uncertain to gate on.
pub(crate) const MIN_RESIDUAL_DOF: usize = 6;

/// How many least-squares σ below zero an estimated damping may lie before the model
/// check fails ([`Unobservable::NegativeDamping`]).
pub(crate) const NEGATIVE_DAMPING_Z: f64 = 3.0;

/// Thresholds of the observability test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObservabilitySettings {
    /// Largest acceptable `σ_1/σ_6` (default `DEFAULT_CONDITION_THRESHOLD`).
    pub condition_threshold: f64,
    /// Largest acceptable `‖σ_j‖/‖ĵ‖` (default [`DEFAULT_MAX_RELATIVE_SIGMA`]).
    pub max_relative_sigma: f64,
}

impl Default for ObservabilitySettings {
    fn default() -> Self {
        Self {
            condition_threshold: DEFAULT_CONDITION_THRESHOLD,
            max_relative_sigma: DEFAULT_MAX_RELATIVE_SIGMA,
        }
    }
}

/// Why the data alone cannot determine J.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Unobservable {
    /// No rotor momentum and no known torque: `y ≡ 0`, J fixed only up to scale.
    NoExcitation,
    /// Fewer than six independent rows (e.g. no motion, or a pure spin about a principal
    /// axis).
    RankDeficient {
        /// Numerical rank of `R`.
        rank: usize,
    },
    /// The answer's relative σ exceeds the threshold: the rows explain too little, or a
    /// part of σ beyond their noise is too large.
    Uncertain {
        /// `‖σ_j‖_F/‖Ĵ‖_F`.
        relative_sigma: f64,
        /// The threshold it exceeds.
        threshold: f64,
        /// The part of σ that dominates ([`Uncertainty::dominant_part`]).
        ///
        /// [`Uncertainty::dominant_part`]: super::uncertainty::Uncertainty::dominant_part
        dominant: super::uncertainty::SigmaPart,
    },
    /// With errors-in-variables compensation, the gyro noise outweighs the excitation
    /// (the compensated information matrix is not positive definite).
    NoiseDominated,
    /// The estimate is not finite: the estimator diverged on these data.
    Diverged,
    /// The constrained answer rests on the `J ⪰ εI` floor: the data do not support a
    /// positive-definite J.
    AtFloor {
        /// Smallest principal moment of the answer, kg m².
        min_moment_kg_m2: f64,
        /// Whether the unconstrained least-squares J is negative definite: the signature
        /// of a reversed sign of ρ or τ, or of a wrong quaternion convention.
        unconstrained_negative: bool,
        /// Whether its negation `−J_ls` would pass as determined: positive definite above
        /// the floor, with the stated σ within the relative-σ threshold of it. With no
        /// known torque, negating ρ negates the least-squares answer and nothing else
        /// (the rows are linear in `j` and ρ), so this is what telemetry whose ρ has the
        /// opposite sign of this library's convention gives ([`crate::pipeline`] stops
        /// there, naming the fix).
        mirror_determined: bool,
    },
    /// The constraints moved the answer further than the data's noise allows: the data
    /// contradict the constraint set, and the answer is the constraint set's.
    ConflictsWithConstraints {
        /// `(‖R ĵ − z‖² − ‖R j_ls − z‖²)/s²`, a χ² with 6 degrees of freedom if the truth
        /// satisfies the constraints.
        chi2: f64,
    },
    /// Two row models that should agree (the rotation from the attitude and from the
    /// gyro) give answers further apart than their stated σ allow.
    SourcesDisagree {
        /// Largest `|ĵ_a − ĵ_b| / √(σ_a² + σ_b²)` over the elements.
        z: f64,
    },
    /// One span of the record has residuals far larger than the rest: the model did not
    /// hold there ([`super::consistency`]).
    Inconsistent {
        /// That span's residual variance over the rest's.
        ratio: f64,
        /// Its first sample's time, s.
        t_start_s: f64,
        /// Its last sample's time, s.
        t_end_s: f64,
    },
    /// The residuals are smaller than the stated gyro noise density alone implies: the
    /// density is overstated, and the errors-in-variables compensation built on it
    /// over-corrects (`super::consistency::gyro_density_ratio`).
    DensityOverstated {
        /// Residual variance over the part the stated density implies.
        ratio: f64,
    },
    /// The data contradict the Gaussian prior beyond both their noises
    /// (`super::prior::PriorFit::conflicts`).
    PriorConflict {
        /// Prior-data disagreement, a χ² with at most `rows` degrees of freedom.
        chi2: f64,
        /// Rows of the prior.
        rows: usize,
    },
    /// The unconstrained answer (the momentum RLS baseline) is not a physical inertia.
    NotPhysical {
        /// Smallest principal moment, kg m².
        min_moment_kg_m2: f64,
        /// Smallest eigenvalue of `½ tr(J) I − J` (the second-moment matrix), kg m².
        min_second_moment_kg_m2: f64,
    },
    /// A constrained answer breaks `J1 > 0` or `J1 + J2 ≥ J3` (principal moments
    /// `J1 ≤ J2 ≤ J3`) by more than `crate::pipeline::status::PHYSICAL_Z` of its stated
    /// σ: a real body's J is physical, so a model check failed
    /// ([`Observability::ModelCheckFailed`]; the answer and its σ stay visible).
    Unphysical {
        /// Smallest principal moment `J1`, kg m².
        min_moment_kg_m2: f64,
        /// `J1 + J2 − J3`, kg m² (negative: the triangle inequality is broken).
        triangle_kg_m2: f64,
        /// σ of `J1 + J2 − J3` (the principal moments' σ taken as independent), kg m².
        triangle_sigma_kg_m2: f64,
        /// The larger of the two violations in units of its σ.
        z: f64,
    },
    /// The estimated damping `D` of a torque `−D ω` is negative by more than
    /// `NEGATIVE_DAMPING_Z` of its least-squares σ: a drag cannot feed energy in, so the
    /// damping stands in for another effect and the row model does not hold
    /// ([`Observability::ModelCheckFailed`]; the answer and its σ stay visible).
    NegativeDamping {
        /// `D`, N m s.
        damping_nms: f64,
        /// Its least-squares σ, N m s.
        sigma_nms: f64,
    },
    /// The weakest direction of `j` is too poorly determined.
    IllConditioned {
        /// `σ_1/σ_6`.
        condition: f64,
        /// The threshold it exceeds.
        threshold: f64,
    },
}

impl Unobservable {
    /// The settings its message recommends changing ([`crate::fix`]), in its order.
    #[must_use]
    pub fn fixes(&self) -> &'static [Fix] {
        match self {
            Unobservable::AtFloor {
                mirror_determined: true,
                ..
            } => &[Fix::NegateRho],
            Unobservable::Inconsistent { .. } => &[Fix::Memory],
            Unobservable::DensityOverstated { .. } => &[Fix::GyroNoise],
            Unobservable::PriorConflict { .. } => &[Fix::PriorSigma, Fix::Products],
            Unobservable::NegativeDamping { .. } => &[Fix::InertialTorqueOn],
            _ => &[],
        }
    }
}

impl core::fmt::Display for Unobservable {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Unobservable::NoExcitation => write!(
                f,
                "no rotor momentum or known torque has excited the motion (y = 0): the data fix J only up to scale"
            ),
            Unobservable::RankDeficient { rank } => write!(
                f,
                "the rows have rank {rank} < 6: the attitude motion does not excite every inertia component"
            ),
            Unobservable::Uncertain {
                relative_sigma,
                threshold,
                dominant,
            } => {
                if relative_sigma.is_finite() {
                    write!(
                        f,
                        "relative standard deviation of J {relative_sigma:.2e} > {threshold}, most of it from {dominant}"
                    )
                } else {
                    write!(
                        f,
                        "too few rows yet to judge the estimate's accuracy (fewer than {MIN_RESIDUAL_DOF} residual degrees of freedom)"
                    )
                }
            }
            Unobservable::NoiseDominated => write!(
                f,
                "the gyro noise outweighs the excitation: the noise-compensated information matrix is not positive definite"
            ),
            Unobservable::Diverged => write!(
                f,
                "the estimate is not finite: the estimator diverged on these data"
            ),
            Unobservable::AtFloor {
                min_moment_kg_m2,
                unconstrained_negative,
                mirror_determined,
            } => {
                write!(
                    f,
                    "the answer rests on the J ⪰ εI floor (smallest principal moment {min_moment_kg_m2:.2e} kg m²): the data do not support a positive-definite J"
                )?;
                if *mirror_determined {
                    f.write_str("; its negation would be determined: rho (or tau) has the opposite sign of this library's convention (negate it), or the quaternions are conjugated (docs/conventions.md §1, §3)")?;
                } else if *unconstrained_negative {
                    f.write_str("; the unconstrained J is negative definite, the signature of a reversed sign of rho or tau or of a wrong quaternion convention (docs/conventions.md §1, §3)")?;
                }
                Ok(())
            }
            Unobservable::ConflictsWithConstraints { chi2 } => write!(
                f,
                "the constraints moved the answer {chi2:.1e} noise variances away from the data's least-squares J: the data contradict the constraint set"
            ),
            Unobservable::SourcesDisagree { z } => write!(
                f,
                "the answers with the rotation from the attitude and from the gyro differ by {z:.1} standard deviations: the attitude and the gyro disagree beyond their noise (a gyro scale factor or misalignment, a time-tag skew, or a wrong frame)"
            ),
            Unobservable::Inconsistent {
                ratio,
                t_start_s,
                t_end_s,
            } => write!(
                f,
                "the residuals between t = {t_start_s:.1} s and {t_end_s:.1} s are {} the rest's variance: the model did not hold there (a glitch in the attitude or the wheel telemetry, a change of J, an unmodelled torque); remove that span, or forget old data with a memory for a J that changes",
                crate::text::Times(*ratio)
            ),
            Unobservable::DensityOverstated { ratio } => write!(
                f,
                "the residuals are {} the variance the stated gyro noise density alone implies: the density is overstated and the compensation built on it over-corrects (the gyro noise density is the rate-noise density in deg/s/√Hz, the angle random walk in deg/√h divided by 60)",
                crate::text::Times(*ratio)
            ),
            Unobservable::PriorConflict { chi2, rows } => write!(
                f,
                "the data contradict the prior: disagreement χ² = {} on {rows} prior elements (threshold {}); the prior is wrong by more than its σ (check the prior's σ and its products-of-inertia convention)",
                crate::text::Num(*chi2),
                super::prior::RESIDUAL_VARIANCE_ALLOWANCE
                    * super::prior::CHI2_999[(*rows).clamp(1, 6) - 1]
            ),
            Unobservable::NotPhysical {
                min_moment_kg_m2,
                min_second_moment_kg_m2,
            } => write!(
                f,
                "the unconstrained least-squares J is not a physical inertia (smallest principal moment {}, smallest eigenvalue of ½ tr(J) I − J {} kg m²): the data do not determine J; a constrained estimator reports what they do determine",
                crate::text::Num(*min_moment_kg_m2),
                crate::text::Num(*min_second_moment_kg_m2)
            ),
            Unobservable::Unphysical {
                min_moment_kg_m2,
                triangle_kg_m2,
                triangle_sigma_kg_m2,
                z,
            } => write!(
                f,
                "not a physical inertia (J1 + J2 − J3 = {triangle_kg_m2:.2e} ± {triangle_sigma_kg_m2:.1e} kg m², J1 = {min_moment_kg_m2:.4e} kg m²; {z:.1} σ outside J1 > 0, J1 + J2 ≥ J3): a real body's J is physical, so the row model or the data's conventions do not hold here; the answer and its σ are shown, not promised (the physical constraint set keeps the answer physical)"
            ),
            Unobservable::NegativeDamping {
                damping_nms,
                sigma_nms,
            } => write!(
                f,
                "the damping came out negative (D = {} ± {} N m s, beyond {NEGATIVE_DAMPING_Z} σ): a drag cannot feed energy in, so the damping stands in for another effect (a torque fixed in the inertial frame?) and the answer may be biased; it and its σ are shown, not promised",
                crate::text::Num(*damping_nms),
                crate::text::Num(*sigma_nms)
            ),
            Unobservable::IllConditioned {
                condition,
                threshold,
            } => write!(
                f,
                "the rows are ill-conditioned (condition number {condition:.2e} > {threshold:.0e})"
            ),
        }
    }
}

/// Whether and how an estimate is determined.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(tag = "status", rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Observability {
    /// The data determine J.
    Determined {
        /// `σ_1/σ_6` of `R`.
        condition: f64,
    },
    /// The data alone fall short (the reason), and the prior knowledge determines the
    /// answer with them: the a-priori bounds pin one open direction, or a Gaussian prior
    /// supplies the missing information (its σ is in the answer's).
    FromPrior(Unobservable),
    /// Nothing determines J: no answer.
    NotObservable(Unobservable),
    /// The estimator makes no observability test (the momentum RLS baseline): an answer,
    /// with no claim about how well the data determine it.
    Unchecked,
    /// The rows pass the rank and conditioning tests, but the answer has no standard
    /// deviation (an estimator or batch form without an uncertainty model, or σ switched
    /// off): without a σ there is no promise to keep, so it is not
    /// [`Observability::Determined`] (code `unchecked`; [`crate::pipeline::status`]).
    NoSigma {
        /// `σ_1/σ_6` of `R`.
        condition: f64,
    },
    /// An answer with its σ that a model check refutes (the reason, e.g.
    /// [`Unobservable::Unphysical`]): it is reported with its σ, but not determined,
    /// since the promise rests on a model the data contradict (code
    /// `model_check_failed`; [`crate::pipeline::status`]).
    ModelCheckFailed(Unobservable),
}

impl Observability {
    /// `true` when an answer may be reported.
    #[must_use]
    pub fn has_answer(&self) -> bool {
        !matches!(self, Observability::NotObservable(_))
    }

    /// Short code for files: `determined`, `from_prior`, `not_observable`, `unchecked`,
    /// `model_check_failed`.
    #[must_use]
    pub fn code(&self) -> &'static str {
        match self {
            Observability::Determined { .. } => "determined",
            Observability::FromPrior(_) => "from_prior",
            Observability::NotObservable(_) => "not_observable",
            Observability::Unchecked | Observability::NoSigma { .. } => "unchecked",
            Observability::ModelCheckFailed(_) => "model_check_failed",
        }
    }

    /// Why the data fall short, when they do.
    #[must_use]
    pub fn reason(&self) -> Option<Unobservable> {
        match self {
            Observability::FromPrior(r)
            | Observability::NotObservable(r)
            | Observability::ModelCheckFailed(r) => Some(*r),
            _ => None,
        }
    }

    /// `σ_1/σ_6` of `R` when the data determine J.
    #[must_use]
    pub fn condition(&self) -> Option<f64> {
        match self {
            Observability::Determined { condition } | Observability::NoSigma { condition } => {
                Some(*condition)
            }
            _ => None,
        }
    }
}

impl core::fmt::Display for Observability {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Observability::Determined { condition } => {
                write!(
                    f,
                    "determined by the data (condition number {condition:.3e})"
                )
            }
            Observability::FromPrior(r @ Unobservable::ConflictsWithConstraints { .. }) => {
                write!(f, "answer leans on the constraint set: {r}")
            }
            Observability::FromPrior(r) => {
                write!(
                    f,
                    "determined with the prior knowledge; the data alone fall short: {r}"
                )
            }
            Observability::NotObservable(r) => write!(f, "NOT OBSERVABLE: {r}"),
            Observability::Unchecked => {
                f.write_str("recursive least squares (no observability test, unconstrained)")
            }
            Observability::NoSigma { condition } => write!(
                f,
                "unchecked: an answer without a standard deviation (this estimator states none here), so nothing says how close it is; the rows pass the rank and conditioning tests (condition number {condition:.3e})"
            ),
            Observability::ModelCheckFailed(r) => write!(f, "model check failed: {r}"),
        }
    }
}

/// `‖σ_j‖/‖ĵ‖` of the unconstrained least-squares estimate, `∞` when it cannot be
/// formed (fewer than [`MIN_RESIDUAL_DOF`] residual degrees of freedom or a singular `R`).
/// `sv` are the singular values of `R`: `tr((RᵀR)⁻¹) = Σ σ_k⁻²`.
#[must_use]
pub(crate) fn relative_sigma(qr: &RecursiveQr, sv: &nalgebra::Vector6<f64>) -> f64 {
    if qr.residual_dof() < MIN_RESIDUAL_DOF as f64 || sv.min() <= 0.0 {
        return f64::INFINITY;
    }
    let Some(j) = crate::solver::unconstrained_minimiser(&qr.r, &qr.z) else {
        return f64::INFINITY;
    };
    let s2 = qr.rss / qr.residual_dof();
    let var: f64 = sv.iter().map(|s| 1.0 / (s * s)).sum::<f64>() * s2;
    let jn = j.norm();
    if jn > 0.0 && var.is_finite() {
        crate::math::sqrt(var) / jn
    } else {
        f64::INFINITY
    }
}

/// With `y ≡ 0` the data fix only the direction of `j`: the right singular vector `v_6`
/// of `R`. Its relative standard deviation is `s √(Σ_{i≤5} σ_i⁻²)` with the per-row
/// misfit `s² = σ_6²/(rows − 5)`.
#[must_use]
pub(crate) fn direction_relative_sigma(sv: &nalgebra::Vector6<f64>, rows: f64) -> f64 {
    if rows < (5 + MIN_RESIDUAL_DOF) as f64 {
        return f64::INFINITY;
    }
    let mut s = *sv;
    s.as_mut_slice().sort_unstable_by(|a, b| b.total_cmp(a));
    let inv: f64 = (0..5).map(|i| 1.0 / (s[i] * s[i])).sum();
    let r = s[5] * crate::math::sqrt(inv / (rows - 5.0));
    if r.is_finite() {
        r
    } else {
        f64::INFINITY
    }
}

/// Assess `qr` (computes an SVD of `R`).
#[must_use]
pub fn assess(
    qr: &RecursiveQr,
    has_bounds: bool,
    settings: &ObservabilitySettings,
) -> Observability {
    assess_with(qr, &qr.r.singular_values(), has_bounds, settings)
}

/// Assess `qr` given the singular values `sv` of `R` (any order), e.g. from a
/// [`super::svd_tracker::SvdTracker`].
#[must_use]
pub(crate) fn assess_with(
    qr: &RecursiveQr,
    sv: &nalgebra::Vector6<f64>,
    has_bounds: bool,
    settings: &ObservabilitySettings,
) -> Observability {
    let threshold = settings.condition_threshold;
    let sv = *sv;
    let smax = sv.max();
    let tiny = smax * crate::solver::SINGULAR_RATIO;
    let rank = if qr.rows == 0 || !(smax > 0.0) {
        0
    } else {
        sv.iter().filter(|&&s| s > tiny).count().min(qr.rows)
    };
    let smin = sv.min();
    let condition = if smin > 0.0 {
        smax / smin
    } else {
        f64::INFINITY
    };
    let weak = sv.iter().filter(|&&s| s * threshold < smax).count();
    let (reason, open_directions) = if qr.y_energy == 0.0 {
        let rel = direction_relative_sigma(&sv, qr.weight - qr.nuisance);
        if rel > settings.max_relative_sigma {
            return Observability::NotObservable(Unobservable::Uncertain {
                relative_sigma: rel,
                threshold: settings.max_relative_sigma,
                dominant: super::uncertainty::SigmaPart::Noise,
            });
        }
        (Unobservable::NoExcitation, weak.max(1))
    } else if rank < 6 {
        (Unobservable::RankDeficient { rank }, 6 - rank)
    } else if condition > threshold {
        (
            Unobservable::IllConditioned {
                condition,
                threshold,
            },
            weak,
        )
    } else {
        let rel = relative_sigma(qr, &sv);
        if rel > settings.max_relative_sigma {
            return Observability::NotObservable(Unobservable::Uncertain {
                relative_sigma: rel,
                threshold: settings.max_relative_sigma,
                dominant: super::uncertainty::SigmaPart::Noise,
            });
        }
        return Observability::Determined { condition };
    };
    if has_bounds && open_directions <= 1 && rank >= 5 {
        Observability::FromPrior(reason)
    } else {
        Observability::NotObservable(reason)
    }
}
