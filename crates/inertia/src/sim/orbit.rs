//! A circular Earth orbit and the gravity-gradient torque on it (the geometry:
//! [`super::environment`], "Orbit").

use super::SimError;
use crate::attitude::Quaternion;
use crate::sim::sensors::DEG;
use nalgebra::{Matrix3, Vector3};

pub use crate::estimator::external_torque::EARTH_MU_M3_S2;
/// Earth's equatorial radius, m (WGS 84).
pub const EARTH_RADIUS_M: f64 = 6_378_137.0;

/// A circular Earth orbit (module docs for the geometry).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Orbit {
    /// Altitude above [`EARTH_RADIUS_M`], m (finite, > −R_E + 1 m).
    pub altitude_m: f64,
    /// Inclination, deg.
    pub inclination_deg: f64,
    /// Right ascension of the ascending node, deg.
    pub raan_deg: f64,
    /// Argument of latitude at t = 0 s, deg.
    pub arg_latitude_deg: f64,
}

impl Orbit {
    /// An equatorial orbit (i = Ω = u₀ = 0) at `altitude_m`.
    #[must_use]
    pub fn circular(altitude_m: f64) -> Self {
        Self {
            altitude_m,
            inclination_deg: 0.0,
            raan_deg: 0.0,
            arg_latitude_deg: 0.0,
        }
    }

    /// An equatorial orbit with mean motion `n_rad_s`: `r = (μ/n²)^{1/3}`.
    #[must_use]
    pub fn with_mean_motion(n_rad_s: f64) -> Self {
        Self::circular((EARTH_MU_M3_S2 / (n_rad_s * n_rad_s)).cbrt() - EARTH_RADIUS_M)
    }

    /// Orbit radius, m.
    #[must_use]
    pub fn radius_m(&self) -> f64 {
        EARTH_RADIUS_M + self.altitude_m
    }

    /// Mean motion `√(μ/r³)`, rad/s.
    #[must_use]
    pub fn mean_motion_rad_s(&self) -> f64 {
        (EARTH_MU_M3_S2 / self.radius_m().powi(3)).sqrt()
    }

    /// Position in the inertial frame at `t_s`, m.
    #[must_use]
    pub fn position_m(&self, t_s: f64) -> Vector3<f64> {
        let (si, ci) = (self.inclination_deg * DEG).sin_cos();
        let (so, co) = (self.raan_deg * DEG).sin_cos();
        let u = self.arg_latitude_deg * DEG + self.mean_motion_rad_s() * t_s;
        let (su, cu) = u.sin_cos();
        let p = Vector3::new(co, so, 0.0);
        let q = Vector3::new(-so * ci, co * ci, si);
        (p * cu + q * su) * self.radius_m()
    }

    /// The gravity-gradient torque at `t_s` on a body of inertia `j` (kg m²) at attitude
    /// `q` (body → inertial), N m, body axes.
    #[must_use]
    pub fn gravity_gradient_nm(&self, t_s: f64, q: &Quaternion, j: &Matrix3<f64>) -> Vector3<f64> {
        gravity_gradient_torque_nm(&self.position_m(t_s), q, j)
    }

    /// Check every field.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        let bad = |field, value| {
            Err(SimError::InvalidSetting {
                field,
                value,
                why: "must be finite",
            })
        };
        if !(self.altitude_m.is_finite() && self.radius_m() >= 1.0) {
            return Err(SimError::InvalidSetting {
                field: "environment.orbit.altitude_m",
                value: self.altitude_m,
                why: "must be finite with a radius R_E + altitude_m >= 1 m",
            });
        }
        if !self.inclination_deg.is_finite() {
            return bad("environment.orbit.inclination_deg", self.inclination_deg);
        }
        if !self.raan_deg.is_finite() {
            return bad("environment.orbit.raan_deg", self.raan_deg);
        }
        if !self.arg_latitude_deg.is_finite() {
            return bad("environment.orbit.arg_latitude_deg", self.arg_latitude_deg);
        }
        Ok(())
    }
}

/// Gravity-gradient torque `3 μ/r³ r̂_B × (J r̂_B)`, N m, body axes, for the inertial
/// position `r_inertial_m` (m), attitude `q` (body → inertial) and inertia `j` (kg m²).
/// Zero at the centre of the Earth.
#[must_use]
pub fn gravity_gradient_torque_nm(
    r_inertial_m: &Vector3<f64>,
    q: &Quaternion,
    j: &Matrix3<f64>,
) -> Vector3<f64> {
    let r = r_inertial_m.norm();
    if !(r > 0.0) {
        return Vector3::zeros();
    }
    let rb = q.conjugate().rotate(&(r_inertial_m / r));
    rb.cross(&(j * rb)) * (3.0 * EARTH_MU_M3_S2 / (r * r * r))
}
