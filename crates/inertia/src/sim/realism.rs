//! Flight-realistic sensor, actuator, environment and telemetry settings of a run.
//!
//! [`Realism::default`] reproduces the paper's simulator bit for bit: gyro-propagated
//! attitude, a gyro with angle random walk only, continuous wheel commands, ρ telemetered
//! exactly at the nodes, no environmental torque, every integration node written.

use super::commands::CommandHold;
use super::environment::Environment;
use super::gyro::GyroErrors;
use super::mekf::MekfSettings;
use super::star_tracker::StarTracker;
use super::vibration::RotorVibration;
use super::wheels::WheelTelemetry;
use super::SimError;

/// Where the telemetered attitude `q` comes from. In every case the `omega_rad_s` column
/// is the gyro's measured delta angle over the telemetry step divided by the step
/// (bias-corrected by the filter's estimate for [`AttitudeSource::Mekf`] when
/// [`MekfSettings::bias_corrected_rates`] is set, the default).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AttitudeSource {
    /// The true attitude.
    Truth,
    /// Propagated from the gyro's delta angles from the true initial attitude (the
    /// paper's model; default): carries the gyro's random walk and bias.
    #[default]
    GyroPropagated,
    /// A star-tracker measurement at every telemetry node ([`StarTracker`]).
    StarTracker,
    /// The estimate of a multiplicative EKF fusing gyro and star tracker
    /// (`super::mekf`).
    Mekf,
}

/// Everything beyond the paper's simulator. Every field defaults to the paper's model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Realism {
    /// Source of the telemetered attitude.
    pub attitude: AttitudeSource,
    /// Gyro bias and bias instability (the angle random walk is
    /// [`super::SimConfig::gyro_noise_deg_s_rthz`]).
    pub gyro: GyroErrors,
    /// The star tracker (used by [`AttitudeSource::StarTracker`] and
    /// [`AttitudeSource::Mekf`]).
    pub star_tracker: StarTracker,
    /// MEKF tuning (used by [`AttitudeSource::Mekf`]).
    pub mekf: MekfSettings,
    /// Wheel-momentum telemetry errors.
    pub wheels: WheelTelemetry,
    /// Zero-order hold of the wheel torque commands (`None`: continuous control law).
    pub commands: Option<CommandHold>,
    /// Unknown environmental torques.
    pub environment: Environment,
    /// Telemetry decimation: write every n-th integration node (n ≥ 1), so the telemetry
    /// period is `n · dt_s`. The gyro's delta angle covers the whole telemetry step.
    pub telemetry_every: usize,
    /// Gyro vibration at the rotor frequency (`super::vibration`).
    pub vibration: RotorVibration,
}

impl Default for Realism {
    fn default() -> Self {
        Self {
            attitude: AttitudeSource::GyroPropagated,
            gyro: GyroErrors::default(),
            star_tracker: StarTracker::default(),
            mekf: MekfSettings::default(),
            wheels: WheelTelemetry::default(),
            commands: None,
            environment: Environment::default(),
            telemetry_every: 1,
            vibration: RotorVibration::default(),
        }
    }
}

impl Realism {
    /// The number of integration intervals between star-tracker updates of the MEKF,
    /// for integration step `dt_s`.
    pub(crate) fn tracker_every(&self, dt_s: f64) -> Result<usize, SimError> {
        let Some(rate) = self.star_tracker.rate_hz else {
            return Ok(self.telemetry_every);
        };
        let m = 1.0 / (rate * dt_s);
        let r = m.round();
        if !(r >= 1.0 && (m - r).abs() <= 1e-6 * r) {
            return Err(SimError::InvalidSetting {
                field: "star_tracker.rate_hz",
                value: rate,
                why: "1/(rate_hz * dt_s) must be a whole number >= 1",
            });
        }
        Ok(r as usize)
    }

    /// Check every setting; `dt_s` is the integration step.
    pub(crate) fn validate(&self, dt_s: f64) -> Result<(), SimError> {
        if self.telemetry_every == 0 {
            return Err(SimError::InvalidSetting {
                field: "telemetry_every",
                value: 0.0,
                why: "must be at least 1",
            });
        }
        self.gyro.validate()?;
        self.star_tracker.validate()?;
        self.mekf.validate()?;
        self.wheels.validate(dt_s * self.telemetry_every as f64)?;
        if let Some(c) = &self.commands {
            c.validate(dt_s)?;
        }
        self.environment.validate()?;
        self.vibration.validate()?;
        if self.attitude == AttitudeSource::Mekf {
            if !self.star_tracker.noise_arcsec.iter().all(|v| *v > 0.0) {
                return Err(SimError::InvalidSetting {
                    field: "star_tracker.noise_arcsec",
                    value: self.star_tracker.noise_arcsec.min(),
                    why: "must be > 0 on every axis for the MEKF",
                });
            }
            self.tracker_every(dt_s)?;
        }
        Ok(())
    }
}
