//! The telemetry record and the rules every consumer of a sample stream shares.
//!
//! One [`Sample`] per node `t_k`. Attitude, rotor momentum and known torque are node
//! values; the gyro rate, when the telemetry has one, is the **average over the following
//! interval** `[t_k, t_{k+1}]`, as an integrating (delta-angle) gyro reports it. Units SI,
//! body axes, quaternion per [`crate::attitude`] (scalar last, Hamilton, body → inertial).
//!
//! The gap rule (`is_gap`) lives here so that the row sources and the resampler apply
//! the same one.

use crate::attitude::Quaternion;
use nalgebra::Vector3;

/// One telemetry record at node `t_k`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Sample {
    /// Time, s.
    pub t_s: f64,
    /// Attitude, body → inertial (unit).
    pub q: Quaternion,
    /// Total rotor angular momentum, N m s, body axes.
    pub rho_nms: Vector3<f64>,
    /// Known external torque, N m, body axes (zero when none is known).
    pub tau_nm: Vector3<f64>,
    /// Gyro rate averaged over `[t_k, t_{k+1}]`, rad/s, body axes; `None` when the
    /// telemetry has no gyro rates.
    pub omega_rad_s: Option<Vector3<f64>>,
}

/// A step longer than this many times the previous one is a gap (missing samples, a
/// pause): no row spans it, and the resampler restarts its grid after it.
pub(crate) const GAP_RATIO: f64 = 3.0;

/// Whether a step of `step_s` after one of `previous_step_s` is a gap ([`GAP_RATIO`]).
#[must_use]
#[inline]
pub(crate) fn is_gap(previous_step_s: f64, step_s: f64) -> bool {
    step_s > GAP_RATIO * previous_step_s
}

/// The supported range of telemetry values: generous bounds that no spacecraft
/// reaches, inside which every estimator is numerically sound (finite answers and σ, or
/// a typed error, or a not-observable status). Values outside are refused by the CSV
/// reader (naming file, line and column) and by the pipeline ([`check_range`]).
pub mod range {
    /// Largest |t|, s (about 317 years: Unix time fits).
    pub(crate) const TIME_S: f64 = 1e10;
    /// Largest |ρ| component, N m s (the ISS's four CMGs hold about 2e4 together).
    pub const RHO_NMS: f64 = 1e6;
    /// Largest |τ| component, N m.
    pub const TAU_NM: f64 = 1e4;
    /// Largest |ω| component, rad/s (about 950 rpm).
    pub const RATE_RAD_S: f64 = 100.0;
    /// Largest deviation of the quaternion's norm from 1 (the CSV reader renormalises
    /// within [`crate::telemetry::csv::DEFAULT_UNIT_TOLERANCE`] by default).
    pub(crate) const QUATERNION_NORM: f64 = 1e-3;
}

/// Which value of a sample is outside the [`range`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Time.
    Time,
    /// The quaternion's norm.
    Quaternion,
    /// Rotor momentum, axis 0–2.
    Rho(usize),
    /// Known torque, axis 0–2.
    Tau(usize),
    /// Gyro rate, axis 0–2.
    Rate(usize),
}

impl Quantity {
    /// The largest magnitude allowed and its unit.
    #[must_use]
    pub fn limit(self) -> (f64, &'static str) {
        match self {
            Quantity::Time => (range::TIME_S, "s"),
            Quantity::Quaternion => (range::QUATERNION_NORM, "(| |q| - 1 |)"),
            Quantity::Rho(_) => (range::RHO_NMS, "N m s"),
            Quantity::Tau(_) => (range::TAU_NM, "N m"),
            Quantity::Rate(_) => (range::RATE_RAD_S, "rad/s"),
        }
    }

    /// The default CSV column name (`rho_x`, …; `q` for the quaternion).
    #[must_use]
    pub fn column(self) -> &'static str {
        const AXES: [[&str; 3]; 3] = [
            ["rho_x", "rho_y", "rho_z"],
            ["tau_x", "tau_y", "tau_z"],
            ["w_x", "w_y", "w_z"],
        ];
        match self {
            Quantity::Time => "t",
            Quantity::Quaternion => "q",
            Quantity::Rho(i) => AXES[0][i.min(2)],
            Quantity::Tau(i) => AXES[1][i.min(2)],
            Quantity::Rate(i) => AXES[2][i.min(2)],
        }
    }
}

/// A value outside the supported [`range`] (or not finite).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("`{}` = {} is outside the supported range (magnitude at most {} {})", .quantity.column(), crate::text::Num(*.value), crate::text::Num(.quantity.limit().0), .quantity.limit().1)]
pub struct OutOfRange {
    /// Which value.
    pub quantity: Quantity,
    /// The value (for the quaternion, its norm minus 1).
    pub value: f64,
}

/// `Ok` when `value` is within the range of `quantity` (NaN never is).
pub(crate) fn check_value(quantity: Quantity, value: f64) -> Result<(), OutOfRange> {
    if crate::math::abs(value) <= quantity.limit().0 {
        Ok(())
    } else {
        Err(OutOfRange { quantity, value })
    }
}

/// Check every value of `s` against the supported [`range`].
pub fn check_range(s: &Sample) -> Result<(), OutOfRange> {
    check_value(Quantity::Time, s.t_s)?;
    check_value(Quantity::Quaternion, s.q.norm() - 1.0)?;
    for i in 0..3 {
        check_value(Quantity::Rho(i), s.rho_nms[i])?;
        check_value(Quantity::Tau(i), s.tau_nm[i])?;
        if let Some(w) = s.omega_rad_s {
            check_value(Quantity::Rate(i), w[i])?;
        }
    }
    Ok(())
}
