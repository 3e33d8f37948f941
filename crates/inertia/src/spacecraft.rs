//! The spacecraft file: what the telemetry alone cannot say about
//! the vehicle. Today its rotors: each wheel's spin axis, spin inertia ± σ, and the
//! telemetry column that holds its speed, so that the rotor momentum is computed from
//! the wheel speeds the attitude system telemeters instead of being pre-summed by hand,
//! and the wheels' inertia uncertainty widens σ (a consider parameter, issue #30).
//!
//! # Format (TOML; reading it needs the feature `spacecraft`)
//!
//! ```toml
//! # How the rotors' spin-inertia errors are related: "shared" (default: the same
//! # relative error for every rotor, as for wheels of one model whose catalogue value
//! # is off) or "independent" (each rotor calibrated on its own).
//! rotor_errors = "shared"
//!
//! [[rotor]]
//! name = "rw1"
//! axis = [1.0, 0.0, 0.0]              # spin axis, body axes, unit (to 1e-3)
//! spin_inertia_kg_m2 = 1.2e-3         # about the spin axis
//! spin_inertia_sigma_kg_m2 = 2.4e-5   # its 1σ uncertainty (default 0: exact)
//! spin_axis_sigma_deg = 0.5           # 1σ tilt of the axis, each way (default 0)
//! time_tag_sigma_s = 0.05             # 1σ of its speed's own time tag (default 0)
//! speed_column = "rw1_speed"          # the telemetry column of its speed
//! speed_unit = "rpm"                  # rad/s (default), rpm or deg/s
//! max_torque_nm = 0.01                # motor torque limit (optional; `plan` needs it)
//! max_momentum_nms = 0.046            # momentum limit: speed limit × spin inertia (same)
//! ```
//!
//! Thrusters (optional; a file needs at least one rotor or one thruster) give the known
//! torque about the origin and the force from their throttle columns, so that the centre
//! of mass is estimated ([`thrusters`]):
//!
//! ```toml
//! [[thruster]]
//! name = "t1"
//! position_m = [0.0, 0.3, 0.0]        # from the body frame's origin, body axes
//! direction = [0.0, 0.0, 1.0]         # of the force on the body, unit
//! thrust_n = 0.02                     # at a throttle of 1
//! column = "t1_throttle"              # the telemetry column of its throttle (0–1)
//! ```
//!
//! `inertia plan` ([`crate::plan`]) needs three more tables, optional otherwise:
//!
//! ```toml
//! [prior]                             # what is known of J before the manoeuvre
//! inertia_kg_m2 = [[0.28, 0.005, -0.005], [0.005, 0.245, 0.005], [-0.005, 0.005, 0.168]]
//! relative_sigma = 0.1                # 1σ of every element, relative to the largest
//!                                     # moment (or sigma_kg_m2 = [six values, order J11,
//!                                     # J22, J33, J12, J13, J23])
//! [sensors]
//! gyro_noise_deg_s_rthz = 0.0057      # gyro rate noise density
//! wheel_noise_nms = 0.0               # wheel momentum telemetry noise per sample (default 0)
//! telemetry_hz = 10.0                 # telemetry rate
//! controller_hz = 1.0                 # wheel command rate (a whole fraction of it)
//! [limits]
//! max_rate_deg_s = 5.0                # body rate limit (optional)
//! max_angle_deg = 20.0                # largest rotation from the start (optional)
//! ```
//!
//! # Convention
//!
//! A rotor's speed `ω_i` is its spin rate relative to the body about `+axis`; its
//! angular momentum is `J_i ω_i a_i` (the rotor's momentum about its own axis, eq. 3's
//! `ρ`), and the rotor momentum of the sample is their sum, body axes:
//!
//! ```text
//! ρ = Σ_i J_i u_i ω̃_i a_i        (u_i: the speed unit's factor to rad/s)
//! ```
//!
//! # The consider term
//!
//! Each rotor's spin inertia ± σ (errors shared by every rotor, or independent) and its
//! axis's tilt ± σ (two small angles, independent per rotor) and its speed's own time
//! tag ± σ (`time_tag_sigma_s`: the wheel's speed read that much later than the run's
//! wheel-speed time tag says, independent per rotor) are consider parameters:
//! the answer's move for each 1σ error source is measured by re-running the estimator,
//! and σ widens by their root sum square (`crate::estimator::rotor_inertia`); in a batch
//! run with `calibrate_rotors` they are estimated with J instead
//! (`crate::estimator::rotor_calibration`).
//!
//! # Validation
//!
//! Unknown keys, a missing key, a non-unit axis, a spin inertia that is not positive, a
//! σ not in `[0, J_i)`, a tilt σ over 10°, a time-tag σ over `MAX_TIME_TAG_SIGMA_S`,
//! an unknown speed unit, two rotors with one name or one column,
//! more than `MAX_ROTORS` rotors or none: each refused with the file, the line and the
//! key ([`SpacecraftError`]).

use crate::text::Clipped;
use nalgebra::Vector3;
use std::string::String;
use std::vec::Vec;

/// What is known of J before a manoeuvre (`[prior]`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Prior {
    /// Prior inertia, kg m², symmetric positive definite.
    pub inertia_kg_m2: [[f64; 3]; 3],
    /// 1σ per element, kg m² (order of eq. 48).
    pub sigma_kg_m2: [f64; 6],
}

/// Sensor noise and rates (`[sensors]`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Sensors {
    /// Gyro rate noise density, deg/s/√Hz.
    pub gyro_noise_deg_s_rthz: f64,
    /// Wheel-momentum telemetry noise per sample, N m s.
    pub wheel_noise_nms: f64,
    /// Telemetry rate, Hz.
    pub telemetry_hz: f64,
    /// Wheel command rate, Hz.
    pub controller_hz: f64,
}

/// The most rotors a spacecraft file may list.
pub(crate) const MAX_ROTORS: usize = 16;

/// How far an axis's norm may differ from 1 (it is then normalised).
pub(crate) const AXIS_NORM_TOLERANCE: f64 = 1e-3;

/// The largest 1σ a rotor's own time tag may have, s: the wheel-speed time tag's search
/// range (`crate::estimator::wheel_delay`); a rotor's offset is modelled by its first
/// order about the run's time tag, re-linearised once.
pub(crate) const MAX_TIME_TAG_SIGMA_S: f64 = 0.25;

/// The unit of a rotor's speed column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum SpeedUnit {
    /// rad/s (the default).
    #[default]
    #[cfg_attr(feature = "serde", serde(rename = "rad/s"))]
    RadPerS,
    /// Revolutions per minute.
    #[cfg_attr(feature = "serde", serde(rename = "rpm"))]
    Rpm,
    /// deg/s.
    #[cfg_attr(feature = "serde", serde(rename = "deg/s"))]
    DegPerS,
}

impl SpeedUnit {
    /// Every unit's name, as a spacecraft file spells it.
    pub(crate) const NAMES: [&'static str; 3] = ["rad/s", "rpm", "deg/s"];

    /// The factor that turns a speed in this unit into rad/s.
    #[must_use]
    pub(crate) fn to_rad_s(self) -> f64 {
        match self {
            SpeedUnit::RadPerS => 1.0,
            SpeedUnit::Rpm => core::f64::consts::PI / 30.0,
            SpeedUnit::DegPerS => core::f64::consts::PI / 180.0,
        }
    }
}

impl core::str::FromStr for SpeedUnit {
    type Err = ();

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "rad/s" => Ok(SpeedUnit::RadPerS),
            "rpm" => Ok(SpeedUnit::Rpm),
            "deg/s" => Ok(SpeedUnit::DegPerS),
            _ => Err(()),
        }
    }
}

/// How the rotors' spin-inertia errors are related ([module docs](self), "The consider
/// term").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum RotorErrors {
    /// One relative error for every rotor, each by its own σ (the default: the
    /// conservative reading of one catalogue value for wheels of one model).
    #[default]
    Shared,
    /// Each rotor's error on its own.
    Independent,
}

/// One rotor (reaction wheel, momentum wheel, flywheel).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Rotor {
    /// Its name (for messages and the report).
    pub name: String,
    /// Spin axis, body axes, unit.
    pub axis: [f64; 3],
    /// Spin inertia about the axis, kg m².
    pub spin_inertia_kg_m2: f64,
    /// Its 1σ uncertainty, kg m² (0: exact).
    pub spin_inertia_sigma_kg_m2: f64,
    /// The 1σ tilt of its axis about each of two perpendicular directions, deg (0: exact).
    pub spin_axis_sigma_deg: f64,
    /// The 1σ of its speed's own time tag about the run's wheel-speed time tag, s (0: on
    /// time): each wheel's telemetry may be read at its own instant. A positive value of
    /// it lags (the speed read at `t` is the one of `t − δ_i`), as `--wheel-delay`'s.
    pub time_tag_sigma_s: f64,
    /// The telemetry column that holds its speed.
    pub speed_column: String,
    /// The unit of that column.
    pub speed_unit: SpeedUnit,
    /// Motor torque limit, N m (`None`: not given).
    pub max_torque_nm: Option<f64>,
    /// Momentum limit, N m s (`None`: not given).
    pub max_momentum_nms: Option<f64>,
}

impl Rotor {
    /// The momentum per stored speed unit, N m s per unit, body axes: `J_i u_i a_i`.
    #[must_use]
    pub(crate) fn momentum_per_unit(&self) -> Vector3<f64> {
        Vector3::from(self.axis) * (self.spin_inertia_kg_m2 * self.speed_unit.to_rad_s())
    }

    /// The relative σ of its spin inertia, `σ_i/J_i`.
    #[must_use]
    pub(crate) fn relative_sigma(&self) -> f64 {
        self.spin_inertia_sigma_kg_m2 / self.spin_inertia_kg_m2
    }

    /// Two unit vectors perpendicular to its axis and to each other (the directions its
    /// axis tilts towards): the axis crossed with the body axis it is least aligned
    /// with, then the axis crossed with that.
    #[must_use]
    pub fn tilt_directions(&self) -> [Vector3<f64>; 2] {
        let a = Vector3::from(self.axis);
        let k = a.iamin();
        let e1 = a.cross(&Vector3::ith(k, 1.0)).normalize();
        [e1, a.cross(&e1)]
    }
}

/// A spacecraft file's contents, validated.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Spacecraft {
    /// The rotors, in the file's order.
    pub rotors: Vec<Rotor>,
    /// How their spin-inertia errors are related.
    pub rotor_errors: RotorErrors,
    /// The prior J (`[prior]`), if given.
    pub prior: Option<Prior>,
    /// Sensor noise and rates (`[sensors]`), if given.
    pub sensors: Option<Sensors>,
    /// Body rate limit, deg/s (`[limits] max_rate_deg_s`), if given.
    pub max_rate_deg_s: Option<f64>,
    /// Largest rotation of the body from its attitude at the start of a plan, deg
    /// (`[limits] max_angle_deg`, at most 180), if given.
    pub max_angle_deg: Option<f64>,
    /// The thrusters (`[[thruster]]`, [`thrusters`]), in the file's order.
    pub thrusters: Vec<Thruster>,
}

/// A spacecraft file that cannot be used: the file, the line (where the problem has
/// one), the key, and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{}{}{message}", .line.map_or_else(String::new, |l| format!("{l}:")), .key.as_ref().map_or_else(String::new, |k| format!(" `{}`:", Clipped::new(k))))]
pub struct SpacecraftError {
    /// The file (as the caller named it).
    pub file: String,
    /// 1-based line, where the problem has one.
    pub line: Option<usize>,
    /// The key at fault (`rotor[2].axis`), where there is one.
    pub key: Option<String>,
    /// What is wrong (one line, control characters escaped).
    pub message: String,
}

impl Spacecraft {
    /// The rotor momentum of one sample from its rotors' stored speeds (in the file's
    /// order and units), N m s, body axes: `Σ_i J_i u_i ω̃_i a_i`.
    #[must_use]
    pub fn momentum_nms(&self, speeds: &[f64]) -> Vector3<f64> {
        self.rotors
            .iter()
            .zip(speeds)
            .map(|(r, &w)| r.momentum_per_unit() * w)
            .sum()
    }

    /// The speed columns, in the file's order.
    #[must_use]
    pub fn speed_columns(&self) -> Vec<String> {
        self.rotors.iter().map(|r| r.speed_column.clone()).collect()
    }

    /// The thrusters' throttle columns, in the file's order.
    #[must_use]
    pub fn thruster_columns(&self) -> Vec<String> {
        self.thrusters.iter().map(|t| t.column.clone()).collect()
    }

    /// Whether any rotor's spin inertia, axis or time tag carries an uncertainty (a
    /// consider term applies).
    #[must_use]
    pub(crate) fn has_inertia_sigma(&self) -> bool {
        self.rotors.iter().any(|r| {
            r.spin_inertia_sigma_kg_m2 > 0.0
                || r.spin_axis_sigma_deg > 0.0
                || r.time_tag_sigma_s > 0.0
        })
    }

    /// The relative σ of the rotor momentum the file states, for the checks that compare
    /// moves of the answer with its σ: `√(S + Σ_i 2 θ_i²)`, `θ_i` the axis tilt's σ, rad,
    /// and `S` the spin inertias' part, `max_i s_i²` where their errors are shared (one
    /// error) and `Σ_i s_i²` where independent (`s_i` the relative σ of each).
    #[must_use]
    pub(crate) fn stated_relative_sigma(&self) -> f64 {
        let s2 = self
            .rotors
            .iter()
            .map(|r| r.relative_sigma() * r.relative_sigma());
        let inertia = match self.rotor_errors {
            RotorErrors::Shared => s2.fold(0.0, f64::max),
            RotorErrors::Independent => s2.sum(),
        };
        let tilts: f64 = self
            .rotors
            .iter()
            .map(|r| 2.0 * r.spin_axis_sigma_deg.to_radians().powi(2))
            .sum();
        (inertia + tilts).sqrt()
    }
}

#[cfg(feature = "spacecraft")]
mod file;
pub mod thrusters;
pub use thrusters::Thruster;

#[cfg(all(test, feature = "spacecraft"))]
mod tests;
