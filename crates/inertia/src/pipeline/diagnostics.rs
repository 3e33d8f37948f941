//! What an estimator can say about its run beside the [`Estimate`](crate::estimator::Estimate):
//! one struct for every estimator, the same for a streaming run
//! ([`super::Pipeline::diagnostics`]) and a batch run ([`super::BatchOutput`]).
//!
//! Every field but `gaps` is optional: an estimator fills what its model has, and a new
//! diagnostic is one field here, the estimator that fills it, and the report's line.

use crate::estimator::consistency::Worst;
use crate::estimator::discrete_momentum::TorqueTest;
use crate::estimator::excitation::Excitation;
use crate::estimator::external_torque::OutsideEstimates;
use crate::estimator::momentum_rows::MomentumRowSettings;
use nalgebra::Vector3;

/// An estimator's diagnostics at its latest estimate.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct Diagnostics {
    /// Gaps in the time stamps seen (no row spans a gap).
    pub gaps: usize,
    /// How well the data excite each direction of `j` ([`crate::estimator::excitation`]),
    /// for estimators with a least-squares state.
    pub excitation: Option<Excitation>,
    /// The row model in use, for estimators that choose one from the data.
    pub row_model: Option<MomentumRowSettings>,
    /// The estimated constant body-frame disturbance torque, N m, where estimated.
    pub torque_bias_nm: Option<Vector3<f64>>,
    /// The estimated damping coefficient `D` of a torque `−D ω`, N m s, and its
    /// least-squares σ, where estimated ([`super::PipelineSettings::damping`]).
    pub damping_nms: Option<(f64, Option<f64>)>,
    /// The torques of outside measurements: whether the gravity gradient was modelled,
    /// the residual dipole and the centre of mass with their σ, where the rows model any
    /// ([`crate::estimator::external_torque`]).
    pub outside: Option<OutsideEstimates>,
    /// The rotor parameters estimated with J, where a batch run estimates them
    /// ([`crate::estimator::rotor_calibration`]; whitened: the spacecraft file's σ is 1).
    #[cfg(feature = "std")]
    pub rotor_calibration: Option<crate::estimator::rotor_calibration::RotorFit>,
    /// The test for a constant disturbance torque at the last solve, where made: whether
    /// the torque was held at zero for want of evidence
    /// (`crate::estimator::discrete_momentum::torque_tested`).
    pub torque_test: Option<TorqueTest>,
    /// The span of the record whose residuals stand out most from the rest, with their
    /// variance ratio ([`crate::estimator::consistency`]; estimators that test their
    /// residuals recursively, without forgetting).
    pub residual_consistency: Option<Worst>,
    /// At the last solve with a stated gyro density, the residual variance over the part
    /// that density alone implies (below
    /// [`crate::estimator::consistency::DENSITY_OVERSTATED_RATIO`] the density is
    /// overstated).
    pub gyro_density_ratio: Option<f64>,
    /// Where no gyro density was stated: the one estimated from the telemetered rates,
    /// rad/s/√Hz, that the errors-in-variables compensation used at the last solve
    /// (`crate::estimator::rate_noise`; `None` where the rates' differences show the
    /// motion more than the noise, or without rates).
    pub gyro_noise_estimated_rad_s_rthz: Option<f64>,
    /// With an attitude drift stated ([`super::PipelineSettings::attitude_drift_deg_rth`]):
    /// whether the last answer came from the rows weighted for it (`false`: from the
    /// unweighted rows, whose bias σ exceeded their noise σ, or no answer yet to weight
    /// with). `None` without a drift stated.
    pub drift_weighted: Option<bool>,
    /// With both rotation sources in play (gyro rates in the telemetry, no
    /// `rotation_source` set): whether the attitude was found to be the gyro's own
    /// integral, whose rows are then not folded twice; `None` until decided.
    pub attitude_is_gyro_integral: Option<bool>,
}
