//! Wheel control laws for the scenarios of paper §VI.
//!
//! * [`SlewController`]: rest-to-rest slews about body axes, tracked by a PD law with
//!   feed-forward on a quintic (zero rate and acceleration at both ends) reference,
//!   using a **nominal** inertia, not the true one. The commanded body torque `u` is
//!   produced by the wheels as `ρ̇ = −u` (eq. 26):
//!   `u = J_n (α_ref − 2 k_p e − k_d δω) + ω × (J_n ω + ρ)`,
//!   with `e = vec(q_ref† q)` (scalar ≥ 0), `δω = ω − ω_ref`, `k_p = ω_n²`, `k_d = 2ζω_n`.
//! * [`WheelPulse`]: a single wheel spun up by a raised-cosine torque pulse.

use super::InputLaw;
use super::SimError;
use crate::attitude::Quaternion;
use crate::dynamics::GyrostatState;
use nalgebra::{Matrix3, Vector3};

/// One rest-to-rest slew about a body-fixed axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slew {
    /// Rotation axis in body axes (normalised on use).
    pub axis: Vector3<f64>,
    /// Rotation angle, rad.
    pub angle_rad: f64,
    /// Start time, s.
    pub start_s: f64,
    /// Duration, s.
    pub duration_s: f64,
}

/// Quintic rest-to-rest profile: `(s, ṡ, s̈)` for normalised time `u ∈ [0, 1]`, duration T.
fn quintic(u: f64, t: f64) -> (f64, f64, f64) {
    if u <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    if u >= 1.0 {
        return (1.0, 0.0, 0.0);
    }
    let s = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
    let sd = 30.0 * u * u * (1.0 - u) * (1.0 - u) / t;
    let sdd = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u) / (t * t);
    (s, sd, sdd)
}

/// PD + feed-forward slew controller on reaction wheels.
#[derive(Debug, Clone, PartialEq)]
pub struct SlewController {
    nominal_inertia_kg_m2: Matrix3<f64>,
    q0: Quaternion,
    slews: Vec<Slew>,
    natural_freq_rad_s: f64,
    damping: f64,
    /// Reference attitude at each slew's start, derived from `q0` and `slews`.
    starts: Vec<Quaternion>,
}

impl SlewController {
    /// Build the controller: the inertia it believes (kg m²), the attitude at t = 0, the
    /// slews (in time order, not overlapping, each with a positive duration), the
    /// closed-loop natural frequency (rad/s, > 0) and damping ratio (≥ 0). Reference
    /// attitudes at each slew start are precomputed.
    pub fn new(
        nominal_inertia_kg_m2: Matrix3<f64>,
        q0: Quaternion,
        slews: Vec<Slew>,
        natural_freq_rad_s: f64,
        damping: f64,
    ) -> Result<Self, SimError> {
        let bad = |field, value, why| Err(SimError::InvalidSetting { field, value, why });
        if !nominal_inertia_kg_m2.iter().all(|v| v.is_finite()) {
            return bad("nominal_inertia_kg_m2", f64::NAN, "must be finite");
        }
        if !(natural_freq_rad_s.is_finite() && natural_freq_rad_s > 0.0) {
            return bad(
                "natural_freq_rad_s",
                natural_freq_rad_s,
                "must be finite and > 0",
            );
        }
        if !(damping.is_finite() && damping >= 0.0) {
            return bad("damping", damping, "must be finite and >= 0");
        }
        let mut end = f64::NEG_INFINITY;
        for s in &slews {
            if !(s.duration_s.is_finite() && s.duration_s > 0.0) {
                return bad("slew duration_s", s.duration_s, "must be finite and > 0");
            }
            if !(s.start_s.is_finite() && s.start_s >= end) {
                return bad(
                    "slew start_s",
                    s.start_s,
                    "slews must be in time order and must not overlap",
                );
            }
            let n = s.axis.norm();
            if !(n.is_finite() && n > 0.0) {
                return bad("slew axis", n, "must be a finite, non-zero vector");
            }
            if !s.angle_rad.is_finite() {
                return bad("slew angle_rad", s.angle_rad, "must be finite");
            }
            end = s.start_s + s.duration_s;
        }
        let mut starts = Vec::with_capacity(slews.len());
        let mut q = q0;
        for s in &slews {
            starts.push(q);
            q = q.mul(&Quaternion::exp(&(axis(s) * s.angle_rad)));
        }
        Ok(Self {
            nominal_inertia_kg_m2,
            q0,
            slews,
            natural_freq_rad_s,
            damping,
            starts,
        })
    }

    /// Reference attitude, body rate and acceleration (reference axes) at `t_s`.
    #[must_use]
    pub(crate) fn reference(&self, t_s: f64) -> (Quaternion, Vector3<f64>, Vector3<f64>) {
        let mut out = (self.q0, Vector3::zeros(), Vector3::zeros());
        for (s, q_start) in self.slews.iter().zip(&self.starts) {
            if t_s < s.start_s {
                break;
            }
            let (p, pd, pdd) = quintic((t_s - s.start_s) / s.duration_s, s.duration_s);
            let a = axis(s);
            out = (
                q_start.mul(&Quaternion::exp(&(a * (s.angle_rad * p)))),
                a * (s.angle_rad * pd),
                a * (s.angle_rad * pdd),
            );
        }
        out
    }
}

fn axis(s: &Slew) -> Vector3<f64> {
    s.axis.try_normalize(0.0).unwrap_or_else(Vector3::z)
}

impl InputLaw for SlewController {
    fn eval(&self, t_s: f64, x: &GyrostatState) -> Vector3<f64> {
        let (q_ref, w_ref, a_ref) = self.reference(t_s);
        let q_e = q_ref.conjugate().mul(&x.q).positive_scalar();
        // Reference rate and acceleration expressed in body axes.
        let c_be = q_e.to_matrix().transpose();
        let w = x.omega_rad_s;
        let dw = w - c_be * w_ref;
        let kp = self.natural_freq_rad_s * self.natural_freq_rad_s;
        let kd = 2.0 * self.damping * self.natural_freq_rad_s;
        let jn = &self.nominal_inertia_kg_m2;
        let u = jn * (c_be * a_ref - 2.0 * kp * q_e.v - kd * dw) + w.cross(&(jn * w + x.rho_nms));
        -u
    }
}

/// A raised-cosine torque pulse on one wheel: `ρ̇ = (Δρ/T)(1 − cos(2π(t − t0)/T)) a` for
/// `t ∈ [t0, t0 + T]`, which changes the wheel momentum by `Δρ` along unit axis `a`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelPulse {
    /// Wheel spin axis, body axes (normalised on use).
    pub axis: Vector3<f64>,
    /// Momentum change, N m s.
    pub delta_rho_nms: f64,
    /// Start, s.
    pub start_s: f64,
    /// Duration, s.
    pub duration_s: f64,
}

impl InputLaw for WheelPulse {
    fn eval(&self, t_s: f64, _x: &GyrostatState) -> Vector3<f64> {
        let u = (t_s - self.start_s) / self.duration_s;
        if !(0.0..=1.0).contains(&u) {
            return Vector3::zeros();
        }
        let a = self.axis.try_normalize(0.0).unwrap_or_else(Vector3::x);
        a * (self.delta_rho_nms / self.duration_s * (1.0 - (2.0 * core::f64::consts::PI * u).cos()))
    }
}
