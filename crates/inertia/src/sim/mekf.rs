//! A multiplicative extended Kalman filter (MEKF) fusing the gyro and the star tracker,
//! as flight software runs it; the simulator telemeters its attitude estimate.
//!
//! The standard six-state filter (Lefferts, Markley & Shuster 1982; Markley & Crassidis,
//! *Fundamentals of Spacecraft Attitude Determination and Control*, 2014, §6.2):
//!
//! * **State:** the attitude estimate `q̂` (body → inertial) and the gyro bias estimate
//!   `b̂` (rad/s, body axes). **Error state** `δx = [δθ; δb]` with `q = q̂ exp(δθ)`
//!   (δθ in body axes, rad) and `δb = b − b̂`; covariance `P` (6×6).
//! * **Propagation** over an interval Δt with the gyro's measured delta angle `Δθ̃`:
//!   `θ̂ = Δθ̃ − b̂ Δt`, `q̂ ← q̂ exp(θ̂)`, `P ← Φ P Φᵀ + Q` with
//!   `Φ = [[R, −½Δt (I + R)], [0, I]]`, `R = exp(−[θ̂×])`, and
//!   `Q = [[(σ_v² Δt + σ_u² Δt³/3) I, −½σ_u² Δt² I], [−½σ_u² Δt² I, σ_u² Δt I]]`, where
//!   `σ_v` is the gyro's angle random walk (rad/√s) and `σ_u` the bias random walk
//!   (rad/s/√s; the truth's Gauss–Markov instability enters through
//!   `GyroErrors::rate_random_walk_rad_s_rts`).
//! * **Update** with a star-tracker attitude `q̃`: residual `z = log(q̂† q̃)` (≈ δθ + v),
//!   `H = [I 0]`, noise covariance `StarTracker::covariance_rad2`; gain
//!   `K = P Hᵀ (H P Hᵀ + R_st)⁻¹`, Joseph-form covariance update, then the reset
//!   `q̂ ← q̂ exp(δθ̂)`, `b̂ ← b̂ + δb̂`.
//! * **Initialisation:** `q̂` = the first star-tracker measurement, `b̂ = 0`,
//!   `P = diag(R_st, σ_b0² I)` with σ_b0 = [`MekfSettings::initial_bias_sigma_deg_h`].

use super::gyro::deg_h_to_rad_s;
use super::SimError;
use crate::attitude::Quaternion;
use nalgebra::{Matrix3, Matrix6, Matrix6x3, Vector3, Vector6};

/// MEKF tuning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MekfSettings {
    /// Initial 1σ of the bias estimate, deg/h (finite, > 0). Default 10 deg/h.
    pub initial_bias_sigma_deg_h: f64,
    /// Whether the telemetered rates `omega_rad_s` are bias-corrected (`Δθ̃/h − b̂`, the
    /// increments the filter propagated with) or the raw gyro rates. Default `true`
    /// (bias-corrected, as flight software reports its rate estimate).
    pub bias_corrected_rates: bool,
}

impl Default for MekfSettings {
    fn default() -> Self {
        Self {
            initial_bias_sigma_deg_h: 10.0,
            bias_corrected_rates: true,
        }
    }
}

impl MekfSettings {
    /// Check every field.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        if !(self.initial_bias_sigma_deg_h.is_finite() && self.initial_bias_sigma_deg_h > 0.0) {
            return Err(SimError::InvalidSetting {
                field: "mekf.initial_bias_sigma_deg_h",
                value: self.initial_bias_sigma_deg_h,
                why: "must be finite and > 0",
            });
        }
        Ok(())
    }
}

/// The filter.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Mekf {
    q: Quaternion,
    bias_rad_s: Vector3<f64>,
    p: Matrix6<f64>,
    arw_var: f64,
    rrw_var: f64,
    r_st: Matrix3<f64>,
}

impl Mekf {
    /// A filter started at the star-tracker attitude `q0` with tracker covariance `r_st`
    /// (rad², body axes), gyro angle random walk `arw_rad_rts` (rad/√s), bias random walk
    /// `rrw_rad_s_rts` (rad/s/√s) and `settings`.
    #[must_use]
    pub(crate) fn new(
        q0: Quaternion,
        r_st: Matrix3<f64>,
        arw_rad_rts: f64,
        rrw_rad_s_rts: f64,
        settings: &MekfSettings,
    ) -> Self {
        let sb = deg_h_to_rad_s(settings.initial_bias_sigma_deg_h);
        let mut p = Matrix6::zeros();
        p.fixed_view_mut::<3, 3>(0, 0).copy_from(&r_st);
        p.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(Matrix3::identity() * (sb * sb)));
        Self {
            q: q0,
            bias_rad_s: Vector3::zeros(),
            p,
            arw_var: arw_rad_rts * arw_rad_rts,
            rrw_var: rrw_rad_s_rts * rrw_rad_s_rts,
            r_st,
        }
    }

    /// The attitude estimate (body → inertial).
    #[must_use]
    pub(crate) fn attitude(&self) -> Quaternion {
        self.q
    }

    /// The bias estimate, rad/s.
    #[must_use]
    pub(crate) fn bias_rad_s(&self) -> Vector3<f64> {
        self.bias_rad_s
    }

    /// The error covariance `P` (δθ in rad, δb in rad/s).
    #[must_use]
    pub(crate) fn covariance(&self) -> Matrix6<f64> {
        self.p
    }

    /// Propagate over `dt_s` with the measured delta angle (rad). Returns the
    /// bias-corrected increment `Δθ̃ − b̂ Δt` it propagated with.
    pub(crate) fn propagate(&mut self, measured_angle: &Vector3<f64>, dt_s: f64) -> Vector3<f64> {
        let theta = measured_angle - self.bias_rad_s * dt_s;
        let inc = Quaternion::exp(&theta);
        self.q = self.q.mul(&inc).normalize().unwrap_or(self.q);
        let r = inc.to_matrix().transpose();
        let mut phi = Matrix6::identity();
        phi.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
        phi.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&((Matrix3::identity() + r) * (-0.5 * dt_s)));
        let i3 = Matrix3::identity();
        let mut q = Matrix6::zeros();
        let (v, u) = (self.arw_var, self.rrw_var);
        q.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(i3 * (v * dt_s + u * dt_s.powi(3) / 3.0)));
        q.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(i3 * (-0.5 * u * dt_s * dt_s)));
        q.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(i3 * (-0.5 * u * dt_s * dt_s)));
        q.fixed_view_mut::<3, 3>(3, 3).copy_from(&(i3 * (u * dt_s)));
        self.p = phi * self.p * phi.transpose() + q;
        self.symmetrise();
        theta
    }

    /// Update with a star-tracker attitude. A singular innovation covariance (not
    /// reachable with validated settings) leaves the filter unchanged.
    pub(crate) fn update(&mut self, measured: &Quaternion) {
        let z = self.q.conjugate().mul(measured).log();
        let s = self.p.fixed_view::<3, 3>(0, 0) + self.r_st;
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        let k: Matrix6x3<f64> = self.p.fixed_view::<6, 3>(0, 0) * s_inv;
        let dx: Vector6<f64> = k * z;
        let mut ikh = Matrix6::identity();
        {
            let mut left = ikh.fixed_view_mut::<6, 3>(0, 0);
            left -= k;
        }
        self.p = ikh * self.p * ikh.transpose() + k * self.r_st * k.transpose();
        self.symmetrise();
        let dtheta = Vector3::new(dx[0], dx[1], dx[2]);
        self.q = self
            .q
            .mul(&Quaternion::exp(&dtheta))
            .normalize()
            .unwrap_or(self.q);
        self.bias_rad_s += Vector3::new(dx[3], dx[4], dx[5]);
    }

    fn symmetrise(&mut self) {
        self.p = (self.p + self.p.transpose()) * 0.5;
    }
}
