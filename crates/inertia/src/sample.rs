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
    /// What acts on the body from outside, as measured at the node ([`External`]; all
    /// `None` by default).
    #[cfg_attr(feature = "serde", serde(default))]
    pub external: External,
}

/// Measurements of what acts on the body from outside, at one node. Each is optional;
/// given, it lets the momentum rows model one more torque:
///
/// * the **position** gives the gravity-gradient torque `3μ/r³ r̂_B × (J r̂_B)`, linear
///   in `J` (rows, no new unknown; needs the attitude relative to the inertial frame of
///   the position);
/// * the **magnetic field** lets a residual magnetic dipole `m` (body axes, A m²) be
///   estimated from its torque `m × B`;
/// * the **force** lets the centre of mass `c` (body axes, m, from the point the known
///   torque is taken about) be estimated from the force's torque about it, `−c × F`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct External {
    /// Position of the centre of mass in the inertial frame of the attitude, m (the orbit
    /// position; origin at the centre of the attracting body).
    #[cfg_attr(feature = "serde", serde(default))]
    pub position_m: Option<Vector3<f64>>,
    /// Magnetic field, T, body axes (a magnetometer's reading).
    #[cfg_attr(feature = "serde", serde(default))]
    pub field_t: Option<Vector3<f64>>,
    /// Total external force (thrusters), N, body axes.
    #[cfg_attr(feature = "serde", serde(default))]
    pub force_n: Option<Vector3<f64>>,
}

impl External {
    /// Nothing measured.
    pub(crate) const NONE: External = External {
        position_m: None,
        field_t: None,
        force_n: None,
    };
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
    /// Largest |r| component of the position, m (beyond the Moon's orbit).
    pub(crate) const POSITION_M: f64 = 1e10;
    /// Largest |B| component, T (a hundred times Earth's surface field).
    pub(crate) const FIELD_T: f64 = 1e-2;
    /// Largest |F| component, N.
    pub(crate) const FORCE_N: f64 = 1e6;
    /// Largest commanded magnetic dipole component, A m².
    pub(crate) const DIPOLE_AM2: f64 = 1e5;
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
    /// Position, axis 0–2.
    Position(usize),
    /// Magnetic field, axis 0–2.
    Field(usize),
    /// Force, axis 0–2.
    Force(usize),
    /// Commanded magnetic dipole, axis 0–2.
    Dipole(usize),
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
            Quantity::Position(_) => (range::POSITION_M, "m"),
            Quantity::Field(_) => (range::FIELD_T, "T"),
            Quantity::Force(_) => (range::FORCE_N, "N"),
            Quantity::Dipole(_) => (range::DIPOLE_AM2, "A m^2"),
        }
    }

    /// The default CSV column name (`rho_x`, …; `q` for the quaternion).
    #[must_use]
    pub fn column(self) -> &'static str {
        const AXES: [[&str; 3]; 7] = [
            ["rho_x", "rho_y", "rho_z"],
            ["tau_x", "tau_y", "tau_z"],
            ["w_x", "w_y", "w_z"],
            ["r_x", "r_y", "r_z"],
            ["b_x", "b_y", "b_z"],
            ["f_x", "f_y", "f_z"],
            ["dipole_x", "dipole_y", "dipole_z"],
        ];
        match self {
            Quantity::Time => "t",
            Quantity::Quaternion => "q",
            Quantity::Rho(i) => AXES[0][i.min(2)],
            Quantity::Tau(i) => AXES[1][i.min(2)],
            Quantity::Rate(i) => AXES[2][i.min(2)],
            Quantity::Position(i) => AXES[3][i.min(2)],
            Quantity::Field(i) => AXES[4][i.min(2)],
            Quantity::Force(i) => AXES[5][i.min(2)],
            Quantity::Dipole(i) => AXES[6][i.min(2)],
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
        let e = &s.external;
        if let Some(r) = e.position_m {
            check_value(Quantity::Position(i), r[i])?;
        }
        if let Some(b) = e.field_t {
            check_value(Quantity::Field(i), b[i])?;
        }
        if let Some(f) = e.force_n {
            check_value(Quantity::Force(i), f[i])?;
        }
    }
    Ok(())
}
