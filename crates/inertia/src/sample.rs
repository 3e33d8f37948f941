//! The telemetry record and the rules every consumer of a sample stream shares.
//!
//! One [`Sample`] per node `t_k`. Attitude, rotor momentum and known torque are node
//! values; the gyro rate, when the telemetry has one, is the **average over the following
//! interval** `[t_k, t_{k+1}]`, as an integrating (delta-angle) gyro reports it. Units SI,
//! body axes, quaternion per [`crate::attitude`] (scalar last, Hamilton, body → inertial).
//!
//! The gap rule ([`is_gap`]) lives here so that the row sources and the resampler apply
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
pub const GAP_RATIO: f64 = 3.0;

/// Whether a step of `step_s` after one of `previous_step_s` is a gap ([`GAP_RATIO`]).
#[must_use]
#[inline]
pub fn is_gap(previous_step_s: f64, step_s: f64) -> bool {
    step_s > GAP_RATIO * previous_step_s
}
