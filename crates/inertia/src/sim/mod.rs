//! Gyrostat simulator with sensor models (paper §III eq. 26 and §VI).
//!
//! Integrates eq. 26 with quaternion kinematics by RK4 on `substeps` equal substeps of
//! each sample period (see `crate::dynamics::rk4_step`), with
//!
//! * the rotor momentum rate `ρ̇` from a [`InputLaw`] of time and true state (a controller);
//! * a known external torque `τ` from another [`InputLaw`] (reported in telemetry);
//! * an **unknown** white disturbance torque of one-sided spectral density
//!   `disturbance_nm_rthz` (N m/√Hz) per axis, held constant over each substep Δ with
//!   variance `σ²/Δ`, so the momentum it imparts over a time T has standard deviation
//!   `σ √T` per axis. It is not reported in telemetry.
//!
//! Sensors ([`gyro`]): an integrating gyro with white rate noise (deg/s/√Hz); the
//! measured attitude is propagated from the noisy increments, so `φ_k` carries the gyro
//! noise. Rotor momentum is sampled at the nodes without noise. Everything is seeded and
//! reproducible: ChaCha8 streams, one for the disturbance and one for the gyro.
//!
//! Beyond the paper ([`Realism`], default off, so the default output is unchanged bit for
//! bit): attitude from the truth, a star tracker ([`star_tracker`]) or a multiplicative EKF
//! (`mekf`); gyro bias and bias instability ([`gyro`]); wheel commands held at a
//! controller rate (`commands`); wheel telemetry skew, scale error, misalignment, noise
//! and quantisation, wheel speeds held at their own rate (`wheels`); gyro vibration at
//! the rotor frequency (`vibration`); gravity-gradient, constant body-frame and
//! inertial-frame unknown torques and air drag ([`environment`]); Earth's magnetic field
//! with a residual and a commanded dipole and a magnetometer ([`magnetic`]); thrusters
//! off the centre of mass ([`thrusters`]); telemetry decimation;
//! spacecraft presets, among them a hand-thrown lab device ([`presets`]). The loop is in
//! `run`.
//!
//! Noise streams (ChaCha8 seeded with [`SimConfig::seed`]), one per source so that
//! turning one effect on leaves the others' noise unchanged: 0 disturbance torque,
//! 1 gyro angle random walk, 2 star tracker, 3 wheel telemetry noise, 4 gyro bias
//! instability, 5 magnetometer, 6 force sensor.

pub(crate) mod commands;
pub mod control;
pub mod environment;
pub mod gyro;
pub mod magnetic;
pub(crate) mod mekf;
mod orbit;
pub mod presets;
pub mod realism;
pub mod rotors;
pub(crate) mod run;
pub mod scenario;
pub mod sensors;
pub mod star_tracker;
pub mod thrusters;
pub(crate) mod vibration;
pub(crate) mod wheels;

pub use commands::CommandHold;
pub use environment::{Environment, Orbit};
pub use gyro::GyroErrors;
pub use magnetic::{FieldModel, Magnetic, Magnetometer, Magnetorquer};
pub use mekf::MekfSettings;
pub use realism::{AttitudeSource, Realism};
pub use run::simulate;
pub use star_tracker::StarTracker;
pub use thrusters::{Firing, Thruster, Thrusters};
pub use vibration::RotorVibration;
pub use wheels::WheelTelemetry;

use crate::dynamics::GyrostatState;
use crate::sample::Sample;
use nalgebra::{Matrix3, Vector3};

/// A vector-valued input (ρ̇ or τ, N m) as a function of time and true state.
pub trait InputLaw: Sync {
    /// Value at `t_s` in state `x`.
    fn eval(&self, t_s: f64, x: &GyrostatState) -> Vector3<f64>;
}

impl<F: Fn(f64, &GyrostatState) -> Vector3<f64> + Sync> InputLaw for F {
    fn eval(&self, t_s: f64, x: &GyrostatState) -> Vector3<f64> {
        self(t_s, x)
    }
}

/// No input.
#[derive(Debug, Clone, Copy, Default)]
pub struct Zero;

impl InputLaw for Zero {
    fn eval(&self, _t_s: f64, _x: &GyrostatState) -> Vector3<f64> {
        Vector3::zeros()
    }
}

/// A change of the inertia during a run (fuel use, a deployment, docking), modelled as an
/// internal mass redistribution: total angular momentum is conserved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InertiaChange {
    /// At `at_s` the inertia jumps to `to_kg_m2`; the body rate jumps so that `Jω`
    /// is unchanged.
    Step {
        /// Time of the step, s.
        at_s: f64,
        /// Inertia after it, kg m².
        to_kg_m2: Matrix3<f64>,
    },
    /// Linear change from the initial inertia at `start_s` to `to_kg_m2` at `end_s`; the
    /// term `−J̇ω` enters eq. 26.
    Ramp {
        /// Start, s.
        start_s: f64,
        /// End, s.
        end_s: f64,
        /// Inertia at the end, kg m².
        to_kg_m2: Matrix3<f64>,
    },
}

impl InertiaChange {
    /// The inertia at `t_s`, given the initial one.
    #[must_use]
    pub(crate) fn inertia_at(&self, initial: &Matrix3<f64>, t_s: f64) -> Matrix3<f64> {
        match *self {
            InertiaChange::Step { at_s, to_kg_m2 } => {
                if t_s >= at_s {
                    to_kg_m2
                } else {
                    *initial
                }
            }
            InertiaChange::Ramp {
                start_s,
                end_s,
                to_kg_m2,
            } => {
                let u = ((t_s - start_s) / (end_s - start_s)).clamp(0.0, 1.0);
                initial + (to_kg_m2 - initial) * u
            }
        }
    }

    /// `J̇` at `t_s` (zero for a step).
    #[must_use]
    pub(crate) fn rate_at(&self, initial: &Matrix3<f64>, t_s: f64) -> Matrix3<f64> {
        match *self {
            InertiaChange::Ramp {
                start_s,
                end_s,
                to_kg_m2,
            } if t_s >= start_s && t_s < end_s => (to_kg_m2 - initial) / (end_s - start_s),
            _ => Matrix3::zeros(),
        }
    }
}

/// Simulation settings. Every field is public and overridable.
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// True inertia, kg m².
    pub inertia_kg_m2: Matrix3<f64>,
    /// State at `t0_s`.
    pub initial: GyrostatState,
    /// Start time, s.
    pub t0_s: f64,
    /// Integration node period h, s: the telemetry period when
    /// [`Realism::telemetry_every`] is 1 (the default), else `telemetry_every · dt_s` is.
    pub dt_s: f64,
    /// Number of telemetry nodes (samples).
    pub samples: usize,
    /// RK4 substeps per integration node period (more where command ticks split it:
    /// no substep is longer than `dt_s/substeps`).
    pub substeps: usize,
    /// Unknown disturbance torque spectral density, N m/√Hz per axis.
    pub disturbance_nm_rthz: f64,
    /// Gyro rate noise spectral density, deg/s/√Hz per axis.
    pub gyro_noise_deg_s_rthz: f64,
    /// Seed of the noise streams.
    pub seed: u64,
    /// A change of inertia during the run (none by default).
    pub inertia_change: Option<InertiaChange>,
    /// Sensors, actuators, environment and telemetry beyond the paper's model
    /// (`Default`: the paper's model, bit for bit).
    pub realism: Realism,
}

/// The most telemetry samples one run produces: the run is held in memory (samples,
/// truth and filter states, about 0.25 kB per sample).
pub const MAX_SAMPLES: usize = 10_000_000;

impl SimConfig {
    /// Number of nodes for a duration: `round(duration/dt) + 1`, saturating (a NaN or
    /// negative ratio gives 1; a simulation refuses more than [`MAX_SAMPLES`]).
    #[must_use]
    pub fn samples_for(duration_s: f64, dt_s: f64) -> usize {
        ((duration_s / dt_s).round() as usize).saturating_add(1)
    }
}

/// The true state at a node (for tests and error figures).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthSample {
    /// Time, s.
    pub t_s: f64,
    /// True state.
    pub state: GyrostatState,
    /// True gyro bias over the integration interval starting at this node, rad/s, body
    /// axes (zero unless [`GyroErrors`] are set).
    pub gyro_bias_rad_s: Vector3<f64>,
}

/// The MEKF's state at a telemetry node ([`AttitudeSource::Mekf`] only).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterSample {
    /// Time, s.
    pub t_s: f64,
    /// Gyro bias estimate, rad/s, body axes.
    pub bias_rad_s: Vector3<f64>,
    /// 1σ of the attitude error about each body axis (√diag P), rad.
    pub attitude_sigma_rad: Vector3<f64>,
    /// 1σ of the bias estimate per body axis, rad/s.
    pub bias_sigma_rad_s: Vector3<f64>,
}

/// A simulated run: telemetry as the estimator sees it and the truth beside it.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOutput {
    /// Measured telemetry, one per node.
    pub samples: Vec<Sample>,
    /// True state, one per node.
    pub truth: Vec<TruthSample>,
    /// True inertia at the start, kg m².
    pub inertia_kg_m2: Matrix3<f64>,
    /// The inertia change, if any (see [`SimOutput::inertia_at`]).
    pub inertia_change: Option<InertiaChange>,
    /// The orbit when gravity gradient acts: [`Orbit::position_m`] gives the inertial
    /// position at each sample's time, from which (with q and J) the unknown
    /// gravity-gradient torque follows ([`environment::gravity_gradient_torque_nm`]).
    pub orbit: Option<Orbit>,
    /// The MEKF's bias estimate and σ at each telemetry node (empty unless the attitude
    /// source is [`AttitudeSource::Mekf`]).
    pub filter: Vec<FilterSample>,
}

impl SimOutput {
    /// The true inertia at `t_s`, kg m².
    #[must_use]
    pub fn inertia_at(&self, t_s: f64) -> Matrix3<f64> {
        self.inertia_change.map_or(self.inertia_kg_m2, |c| {
            c.inertia_at(&self.inertia_kg_m2, t_s)
        })
    }
}

/// Why a simulation could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A setting is out of its range.
    #[error("simulation setting `{field}` = {} is invalid: {why}", crate::text::Num(*.value))]
    InvalidSetting {
        /// The field name.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        why: &'static str,
    },
}

impl SimConfig {
    /// Check every setting.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        let bad = |field, value, why| Err(SimError::InvalidSetting { field, value, why });
        if !(self.dt_s.is_finite() && self.dt_s > 0.0) {
            return bad("dt_s", self.dt_s, "must be finite and > 0");
        }
        if self.samples < 3 {
            return bad("samples", self.samples as f64, "must be at least 3");
        }
        if self.samples > MAX_SAMPLES {
            return bad(
                "samples",
                self.samples as f64,
                "must be at most 10^7 (the run is held in memory, about 0.25 kB per sample)",
            );
        }
        if self.substeps == 0 {
            return bad("substeps", 0.0, "must be at least 1");
        }
        if !(self.disturbance_nm_rthz.is_finite() && self.disturbance_nm_rthz >= 0.0) {
            return bad(
                "disturbance_nm_rthz",
                self.disturbance_nm_rthz,
                "must be finite and >= 0",
            );
        }
        if !(self.gyro_noise_deg_s_rthz.is_finite() && self.gyro_noise_deg_s_rthz >= 0.0) {
            return bad(
                "gyro_noise_deg_s_rthz",
                self.gyro_noise_deg_s_rthz,
                "must be finite and >= 0",
            );
        }
        if !self.t0_s.is_finite() {
            return bad("t0_s", self.t0_s, "must be finite");
        }
        let j = &self.inertia_kg_m2;
        let asym = (j - j.transpose()).norm();
        if !j.iter().all(|v| v.is_finite()) || asym > 1e-12 * j.norm() {
            return bad("inertia_kg_m2", asym, "must be finite and symmetric");
        }
        let min_eig = j.symmetric_eigenvalues().min();
        if min_eig <= 0.0 {
            return bad("inertia_kg_m2", min_eig, "must be positive definite");
        }
        if self.initial.q.normalize().is_none()
            || !self.initial.omega_rad_s.iter().all(|v| v.is_finite())
            || !self.initial.rho_nms.iter().all(|v| v.is_finite())
        {
            return bad(
                "initial",
                f64::NAN,
                "must be finite with a non-zero quaternion",
            );
        }
        self.realism.validate(self.dt_s)
    }
}
