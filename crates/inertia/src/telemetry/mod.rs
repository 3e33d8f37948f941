//! Telemetry samples: what the attitude system produces at each node `t_k`.
//!
//! One [`Sample`] per node. Attitude, rotor momentum and known torque are node values;
//! the gyro rate is the **average over the following interval** `[t_k, t_{k+1}]`, as an
//! integrating (delta-angle) gyro reports it. Units SI, body axes, quaternion per
//! [`crate::attitude`] (scalar last, Hamilton, body → inertial).
//!
//! With the `csv` feature, [`csv::TelemetryReader`] streams samples from a CSV file with
//! validation that names the file, line and column of every problem.

use crate::attitude::Quaternion;
use nalgebra::Vector3;

/// One telemetry record at node `t_k`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t_s: f64,
    /// Attitude, body → inertial (unit).
    pub q: Quaternion,
    /// Total rotor angular momentum, N m s, body axes.
    pub rho_nms: Vector3<f64>,
    /// Known external torque, N m, body axes (zero when none is known).
    pub tau_nm: Vector3<f64>,
    /// Gyro rate averaged over `[t_k, t_{k+1}]`, rad/s, body axes.
    pub omega_rad_s: Vector3<f64>,
}

#[cfg(feature = "csv")]
pub mod csv;
