//! Gyro vibration at the rotor frequency: a spinning rotor's imbalance shakes the IMU.
//!
//! With one rotor of spin inertia `I_w` (kg m²) carrying all of ρ, the rotor speed is
//! `Ω = ‖ρ‖ / I_w` (rad/s) and its angle `θ(t) = ∫ Ω dt` (from 0 at `t0_s`). The gyro
//! senses, on top of the body rate, the rate
//!
//! ```text
//! v_i(t) = A_i sin(θ(t) + φ_i),   i = x, y, z (body axes)
//! ```
//!
//! with amplitude `A` ([`RotorVibration::amplitude_rad_s`]) and phase `φ`
//! ([`RotorVibration::phase_rad`]). Within each RK4 substep of length Δ the rotor turns at
//! the speed of the substep's mean ρ, so the vibration's delta angle over it is exactly
//! `A_i (cos(θ₀ + φ_i) − cos(θ₁ + φ_i)) / Ω`. The gyro reports delta angles over the sample
//! period h, so at a constant rotor speed the reported rate carries the sinusoid at the
//! rotor frequency `Ω/2π` with amplitude `A_i sinc(Ω h/2)` (`sinc x = sin x / x`). The
//! vibration is a sensor error: it enters the reported rates and the gyro-propagated
//! attitude, not the body's motion.

use super::SimError;
use nalgebra::Vector3;

/// Rotor-frequency vibration seen by the gyro. `Default`: none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotorVibration {
    /// Amplitude per body axis, rad/s (0 = none).
    pub amplitude_rad_s: Vector3<f64>,
    /// Phase per body axis, rad.
    pub phase_rad: Vector3<f64>,
    /// Spin inertia of the one rotor that carries ρ, kg m² (finite, > 0).
    pub rotor_spin_inertia_kg_m2: f64,
}

impl Default for RotorVibration {
    fn default() -> Self {
        Self {
            amplitude_rad_s: Vector3::zeros(),
            phase_rad: Vector3::zeros(),
            rotor_spin_inertia_kg_m2: 1.0,
        }
    }
}

impl RotorVibration {
    /// Whether the gyro vibrates.
    #[must_use]
    pub(crate) fn is_active(&self) -> bool {
        self.amplitude_rad_s != Vector3::zeros()
    }

    /// The rotor speed for rotor momentum `rho_nms`, rad/s.
    #[must_use]
    pub(crate) fn rotor_speed_rad_s(&self, rho_nms: &Vector3<f64>) -> f64 {
        rho_nms.norm() / self.rotor_spin_inertia_kg_m2
    }

    /// Check every field.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        if !self.amplitude_rad_s.iter().all(|v| v.is_finite()) {
            return Err(SimError::InvalidSetting {
                field: "vibration.amplitude_rad_s",
                value: self.amplitude_rad_s.norm(),
                why: "must be finite",
            });
        }
        if !self.phase_rad.iter().all(|v| v.is_finite()) {
            return Err(SimError::InvalidSetting {
                field: "vibration.phase_rad",
                value: self.phase_rad.norm(),
                why: "must be finite",
            });
        }
        let i = self.rotor_spin_inertia_kg_m2;
        if !(i.is_finite() && i > 0.0) {
            return Err(SimError::InvalidSetting {
                field: "vibration.rotor_spin_inertia_kg_m2",
                value: i,
                why: "must be finite and > 0",
            });
        }
        Ok(())
    }
}

/// The rotor's angle during a run.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct RotorAngle {
    theta_rad: f64,
}

impl RotorAngle {
    /// The vibration's delta angle over one substep of `dt_s` in which ρ goes from
    /// `rho0` to `rho1`, rad, body axes; advances the rotor angle.
    pub(crate) fn substep(
        &mut self,
        v: &RotorVibration,
        rho0: &Vector3<f64>,
        rho1: &Vector3<f64>,
        dt_s: f64,
    ) -> Vector3<f64> {
        let speed = v.rotor_speed_rad_s(&((rho0 + rho1) * 0.5));
        let t0 = self.theta_rad;
        let t1 = t0 + speed * dt_s;
        // Keep the angle small: the phase is all that matters.
        self.theta_rad = t1 % core::f64::consts::TAU;
        Vector3::from_fn(|i, _| {
            let (a, p) = (v.amplitude_rad_s[i], v.phase_rad[i]);
            if speed * dt_s > 1e-9 {
                a * ((t0 + p).cos() - (t1 + p).cos()) / speed
            } else {
                a * (t0 + p).sin() * dt_s
            }
        })
    }
}
