//! Continuous gyrostat dynamics, paper eq. 26, and quaternion kinematics (eq. 24).
//!
//! ```text
//! J ω̇ + ω × (J ω + ρ) + ρ̇ = τ        (eq. 26, body axes)
//! q̇ = ½ q ω̂                          (eq. 24)
//! ```
//!
//! `J` is the total gyrostat inertia about the centre of mass (kg m², eq. 39), `ω` the
//! body rate (rad/s), `ρ` the total rotor angular momentum (N m s), `ρ̇` its rate (N m)
//! and `τ` the external torque (N m), all in body axes.
//!
//! `rk4_step` advances `(q, ω, ρ)` by one classical Runge–Kutta step and, alongside,
//! the body-frame integral `∫ω dt` that an integrating (delta-angle) gyro measures. The
//! quaternion is renormalised after every step.

use crate::attitude::Quaternion;
use nalgebra::{Matrix3, Vector3};

/// The true mechanical state of the gyrostat.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GyrostatState {
    /// Attitude, body → inertial.
    pub q: Quaternion,
    /// Body angular velocity, rad/s, body axes.
    pub omega_rad_s: Vector3<f64>,
    /// Total rotor angular momentum, N m s, body axes.
    pub rho_nms: Vector3<f64>,
}

impl GyrostatState {
    /// Kinetic energy of the carrier plus rotors relative to the body, `½ ωᵀ J ω`, J.
    /// (With constant ρ, `½ ωᵀJω` is conserved in torque-free motion.)
    #[must_use]
    pub fn rotational_energy(&self, j: &Matrix3<f64>) -> f64 {
        0.5 * self.omega_rad_s.dot(&(j * self.omega_rad_s))
    }

    /// Total angular momentum `J ω + ρ` in inertial axes, N m s.
    #[must_use]
    pub fn inertial_momentum(&self, j: &Matrix3<f64>) -> Vector3<f64> {
        self.q.rotate(&(j * self.omega_rad_s + self.rho_nms))
    }
}

/// `ω̇` from eq. 26: `J⁻¹ (τ − ω × (J ω + ρ) − ρ̇)`.
#[must_use]
#[inline]
#[cfg_attr(not(feature = "std"), allow(dead_code))]
pub(crate) fn omega_dot(
    j: &Matrix3<f64>,
    j_inv: &Matrix3<f64>,
    omega: &Vector3<f64>,
    rho: &Vector3<f64>,
    rho_dot: &Vector3<f64>,
    tau: &Vector3<f64>,
) -> Vector3<f64> {
    j_inv * (tau - omega.cross(&(j * omega + rho)) - rho_dot)
}

/// `q̇ = ½ q ω̂` (eq. 24).
#[must_use]
#[inline]
#[cfg_attr(not(feature = "std"), allow(dead_code))]
pub(crate) fn quaternion_rate(q: &Quaternion, omega: &Vector3<f64>) -> Quaternion {
    let d = q.mul(&Quaternion::pure(omega));
    Quaternion::new(0.5 * d.v, 0.5 * d.s)
}

/// Inputs evaluated at a time and state: returns `(ρ̇, τ)` in N m.
pub(crate) trait Inputs {
    /// `(ρ̇, τ)` at time `t_s` in state `x`.
    fn eval(&self, t_s: f64, x: &GyrostatState) -> (Vector3<f64>, Vector3<f64>);
}

impl<F: Fn(f64, &GyrostatState) -> (Vector3<f64>, Vector3<f64>)> Inputs for F {
    fn eval(&self, t_s: f64, x: &GyrostatState) -> (Vector3<f64>, Vector3<f64>) {
        self(t_s, x)
    }
}

#[derive(Clone, Copy)]
#[cfg_attr(not(feature = "std"), allow(dead_code))]
struct Deriv {
    q: Quaternion,
    omega: Vector3<f64>,
    rho: Vector3<f64>,
}

#[cfg_attr(not(feature = "std"), allow(dead_code))]
fn derivative(
    j: &Matrix3<f64>,
    j_inv: &Matrix3<f64>,
    t: f64,
    x: &GyrostatState,
    inputs: &impl Inputs,
) -> Deriv {
    let (rho_dot, tau) = inputs.eval(t, x);
    Deriv {
        q: quaternion_rate(&x.q, &x.omega_rad_s),
        omega: omega_dot(j, j_inv, &x.omega_rad_s, &x.rho_nms, &rho_dot, &tau),
        rho: rho_dot,
    }
}

#[cfg_attr(not(feature = "std"), allow(dead_code))]
fn advance(x: &GyrostatState, d: &Deriv, dt: f64) -> GyrostatState {
    GyrostatState {
        q: Quaternion::new(x.q.v + d.q.v * dt, x.q.s + d.q.s * dt),
        omega_rad_s: x.omega_rad_s + d.omega * dt,
        rho_nms: x.rho_nms + d.rho * dt,
    }
}

/// One classical RK4 step of eq. 26 and eq. 24 from `t_s` to `t_s + dt_s`.
///
/// Returns the new state (quaternion renormalised) and the RK4 quadrature of `∫ω dt`
/// over the step (rad, body axes), consistent to the same order as the state.
#[must_use]
pub(crate) fn rk4_step(
    j: &Matrix3<f64>,
    j_inv: &Matrix3<f64>,
    t_s: f64,
    dt_s: f64,
    x: &GyrostatState,
    inputs: &impl Inputs,
) -> (GyrostatState, Vector3<f64>) {
    let h = dt_s;
    let k1 = derivative(j, j_inv, t_s, x, inputs);
    let x2 = advance(x, &k1, 0.5 * h);
    let k2 = derivative(j, j_inv, t_s + 0.5 * h, &x2, inputs);
    let x3 = advance(x, &k2, 0.5 * h);
    let k3 = derivative(j, j_inv, t_s + 0.5 * h, &x3, inputs);
    let x4 = advance(x, &k3, h);
    let k4 = derivative(j, j_inv, t_s + h, &x4, inputs);
    let w = h / 6.0;
    let q = Quaternion::new(
        x.q.v + (k1.q.v + 2.0 * k2.q.v + 2.0 * k3.q.v + k4.q.v) * w,
        x.q.s + (k1.q.s + 2.0 * k2.q.s + 2.0 * k3.q.s + k4.q.s) * w,
    );
    let next = GyrostatState {
        q: q.normalize().unwrap_or(x.q),
        omega_rad_s: x.omega_rad_s + (k1.omega + 2.0 * k2.omega + 2.0 * k3.omega + k4.omega) * w,
        rho_nms: x.rho_nms + (k1.rho + 2.0 * k2.rho + 2.0 * k3.rho + k4.rho) * w,
    };
    let angle = (x.omega_rad_s + 2.0 * x2.omega_rad_s + 2.0 * x3.omega_rad_s + x4.omega_rad_s) * w;
    (next, angle)
}
