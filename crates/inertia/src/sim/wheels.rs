//! Wheel-momentum telemetry: time-tag skew, scale error, misalignment, noise and
//! quantisation.
//!
//! The wheels are modelled as three orthogonal-wheel equivalents: ρ is the body-frame
//! total rotor momentum (N m s). The telemetered value at node `t_k` is
//!
//! ```text
//! ρ̃_k = Q( C_m diag(1 + ε) ρ(t_k + skew_s) + n_k ),     n_k ~ N(0, σ² I)
//! ```
//!
//! * `skew_s` ([`WheelTelemetry::skew_s`]): the wheel speeds are sampled `skew_s` after
//!   (or, negative, before) the attitude's time tag. ρ between integration substeps is
//!   the cubic Hermite interpolant of the substep ends (exact when ρ̇ is held, since ρ is
//!   then linear over each substep). Before `t0_s` ρ is taken as `ρ(t0_s)`.
//!   `|skew_s|` must not exceed the telemetry period.
//! * `ε` ([`WheelTelemetry::scale_error`]): spin-inertia scale error per body axis,
//!   dimensionless.
//! * `C_m = exp([θ_m×])` ([`WheelTelemetry::misalignment_deg`]): a fixed small rotation,
//!   rotation vector in degrees, body axes, between the true wheel momentum and the
//!   telemetered one.
//! * `σ` ([`WheelTelemetry::noise_nms`]): white noise, N m s, per axis, before
//!   quantisation; noise stream: ChaCha8 seeded with the run's seed, stream 3.
//! * `Q` ([`WheelTelemetry::quantization_nms`]): rounding to the nearest multiple of the
//!   LSB q (N m s), error within ±q/2 per axis.
//! * Hold ([`WheelTelemetry::hold_hz`]): the wheel speeds are telemetered at their own
//!   rate, a whole fraction 1/m of the telemetry rate, and held in between (zero-order
//!   hold): sample i carries the value measured at sample `m ⌊i/m⌋`, so ρ̃ is a staircase
//!   with steps every m samples starting at the first.

use super::sensors::{normal, DEG};
use super::SimError;
use crate::attitude::Quaternion;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::collections::VecDeque;

/// Wheel telemetry errors. `Default`: none (ρ telemetered exactly at the node).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelTelemetry {
    /// Quantisation step (LSB) of the telemetered ρ, N m s (≥ 0; 0 = none).
    pub quantization_nms: f64,
    /// White noise 1σ per axis, N m s (≥ 0).
    pub noise_nms: f64,
    /// Time-tag skew, s: ρ telemetered at node `t_k` is the true ρ at `t_k + skew_s`.
    pub skew_s: f64,
    /// Spin-inertia scale error ε per body axis (telemetered = (1 + ε) true); each > −1.
    pub scale_error: Vector3<f64>,
    /// Misalignment between the true and the telemetered wheel momentum: a rotation
    /// vector, deg, body axes.
    pub misalignment_deg: Vector3<f64>,
    /// Rate of the wheel-speed telemetry, Hz, held between its updates (`None`: every
    /// telemetry sample); the telemetry period times this rate must be 1/m, m whole.
    pub hold_hz: Option<f64>,
}

impl Default for WheelTelemetry {
    fn default() -> Self {
        Self {
            quantization_nms: 0.0,
            noise_nms: 0.0,
            skew_s: 0.0,
            scale_error: Vector3::zeros(),
            misalignment_deg: Vector3::zeros(),
            hold_hz: None,
        }
    }
}

impl WheelTelemetry {
    /// The fixed map `C_m diag(1 + ε)` from true to telemetered ρ.
    #[must_use]
    pub(crate) fn map(&self) -> Matrix3<f64> {
        Quaternion::exp(&(self.misalignment_deg * DEG)).to_matrix()
            * Matrix3::from_diagonal(&self.scale_error.add_scalar(1.0))
    }

    /// Whether the telemetered ρ differs from the true node value in any way.
    #[must_use]
    pub(crate) fn is_active(&self) -> bool {
        *self != Self::default()
    }

    /// The number m of telemetry samples per wheel-speed update (1 without a hold).
    pub(crate) fn hold_every(&self, telemetry_dt_s: f64) -> Result<usize, SimError> {
        let Some(rate) = self.hold_hz else {
            return Ok(1);
        };
        let m = 1.0 / (rate * telemetry_dt_s);
        let r = m.round();
        if !(rate.is_finite() && rate > 0.0 && r >= 1.0 && (m - r).abs() <= 1e-6 * r) {
            return Err(SimError::InvalidSetting {
                field: "wheels.hold_hz",
                value: rate,
                why: "1/(hold_hz * telemetry period) must be a whole number >= 1",
            });
        }
        Ok(r as usize)
    }

    /// Check every field; `telemetry_dt_s` bounds the skew.
    pub(crate) fn validate(&self, telemetry_dt_s: f64) -> Result<(), SimError> {
        let bad = |field, value, why| Err(SimError::InvalidSetting { field, value, why });
        if !(self.quantization_nms.is_finite() && self.quantization_nms >= 0.0) {
            return bad(
                "wheels.quantization_nms",
                self.quantization_nms,
                "must be finite and >= 0",
            );
        }
        if !(self.noise_nms.is_finite() && self.noise_nms >= 0.0) {
            return bad(
                "wheels.noise_nms",
                self.noise_nms,
                "must be finite and >= 0",
            );
        }
        if !(self.skew_s.is_finite() && self.skew_s.abs() <= telemetry_dt_s * (1.0 + 1e-12)) {
            return bad(
                "wheels.skew_s",
                self.skew_s,
                "must be finite with |skew_s| <= the telemetry period",
            );
        }
        if !self.scale_error.iter().all(|e| e.is_finite() && *e > -1.0) {
            return bad(
                "wheels.scale_error",
                self.scale_error.min(),
                "each must be finite and > -1",
            );
        }
        if !self.misalignment_deg.iter().all(|v| v.is_finite()) {
            return bad(
                "wheels.misalignment_deg",
                self.misalignment_deg.norm(),
                "must be finite",
            );
        }
        self.hold_every(telemetry_dt_s)?;
        Ok(())
    }
}

/// The wheel telemetry during a run: applies the map, the noise and the quantisation.
#[derive(Debug, Clone)]
pub(crate) struct WheelSensor {
    map: Matrix3<f64>,
    rng: ChaCha8Rng,
    noise: Normal<f64>,
    noisy: bool,
    lsb: f64,
}

impl WheelSensor {
    pub(crate) fn new(w: &WheelTelemetry, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(3);
        Self {
            map: w.map(),
            rng,
            noise: normal(w.noise_nms),
            noisy: w.noise_nms > 0.0,
            lsb: w.quantization_nms,
        }
    }

    /// The telemetered value of the true ρ (after any skew).
    pub(crate) fn measure(&mut self, rho_true: &Vector3<f64>) -> Vector3<f64> {
        let mut r = self.map * rho_true;
        if self.noisy {
            r += Vector3::from_fn(|_, _| self.noise.sample(&mut self.rng));
        }
        if self.lsb > 0.0 {
            r = r.map(|v| (v / self.lsb).round() * self.lsb);
        }
        r
    }
}

/// One integration substep's ends: times, ρ and ρ̇ (the ρ̇ used inside the substep).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RhoSpan {
    pub(crate) t0: f64,
    pub(crate) t1: f64,
    pub(crate) rho0: Vector3<f64>,
    pub(crate) rho1: Vector3<f64>,
    pub(crate) rd0: Vector3<f64>,
    pub(crate) rd1: Vector3<f64>,
}

impl RhoSpan {
    /// Cubic Hermite interpolation at `t` (clamped to the span).
    fn at(&self, t: f64) -> Vector3<f64> {
        let dt = self.t1 - self.t0;
        if !(dt > 0.0) {
            return self.rho1;
        }
        let u = ((t - self.t0) / dt).clamp(0.0, 1.0);
        let u2 = u * u;
        let u3 = u2 * u;
        let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
        let h10 = u3 - 2.0 * u2 + u;
        let h01 = -2.0 * u3 + 3.0 * u2;
        let h11 = u3 - u2;
        self.rho0 * h00 + self.rd0 * (h10 * dt) + self.rho1 * h01 + self.rd1 * (h11 * dt)
    }
}

/// Recent substeps, for ρ at skewed times.
#[derive(Debug, Clone, Default)]
pub(crate) struct RhoHistory {
    spans: VecDeque<RhoSpan>,
}

impl RhoHistory {
    pub(crate) fn push(&mut self, s: RhoSpan) {
        self.spans.push_back(s);
    }

    /// Forget spans that end before `t`.
    pub(crate) fn prune_before(&mut self, t: f64) {
        while self.spans.len() > 1 && self.spans.front().is_some_and(|s| s.t1 < t) {
            self.spans.pop_front();
        }
    }

    /// ρ at `t`, if `t` is within the stored spans.
    pub(crate) fn at(&self, t: f64) -> Option<Vector3<f64>> {
        let first = self.spans.front()?;
        let last = self.spans.back()?;
        if t < first.t0 || t > last.t1 {
            return None;
        }
        // The last span starting at or before t.
        let i = self.spans.partition_point(|s| s.t0 <= t).saturating_sub(1);
        self.spans.get(i).map(|s| s.at(t))
    }

    /// The latest ρ stored.
    pub(crate) fn latest(&self) -> Option<Vector3<f64>> {
        self.spans.back().map(|s| s.rho1)
    }
}
