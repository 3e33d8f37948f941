//! Environmental torques: gravity gradient on a circular orbit, a constant body-frame
//! disturbance, a constant inertial-frame torque and linear air drag, all unknown; the
//! magnetic field with the spacecraft's dipoles, and thrusters off the centre of mass,
//! partly known (below). None of the first four is written to `tau_nm` (the known
//! torque); the orbit
//! is returned with the run ([`super::SimOutput::orbit`]) so that a user can compute the
//! gravity-gradient torque.
//!
//! **Orbit.** The simulator's inertial frame is taken as an Earth-centred inertial frame.
//! A circular orbit of radius `r = R_E + altitude_m` ([`EARTH_RADIUS_M`]) and mean motion
//! `n = √(μ/r³)` ([`EARTH_MU_M3_S2`]), inclination `i`, right ascension of the ascending
//! node `Ω` and argument of latitude `u₀` at `t = 0 s` has the position
//!
//! ```text
//! r_I(t) = r (cos u P̂ + sin u Q̂),   u = u₀ + n t,
//! P̂ = (cos Ω, sin Ω, 0),   Q̂ = (−sin Ω cos i, cos Ω cos i, sin i)
//! ```
//!
//! The initial attitude relative to the orbit follows: with the scenarios' `q(t0) = 1`
//! and the defaults (i = Ω = u₀ = 0, `t0 = 0`), the body x axis points to the zenith
//! (along `r̂`), y along the velocity and z along the orbit normal: the body starts
//! aligned with the orbit frame (x radial, y along-track, z orbit normal).
//!
//! **Gravity-gradient torque** (body axes, N m), with `r̂_B = C(q)ᵀ r̂_I`:
//! `τ_gg = 3 μ/r³ r̂_B × (J r̂_B)` ([`gravity_gradient_torque_nm`]).
//!
//! **Constant disturbance:** [`Environment::constant_torque_nm`], N m in body axes.
//!
//! **Aerodynamic torque off the centre of mass** ([`Environment::inertial_torque_nm`]): a
//! torque fixed in the inertial frame, `τ_B = C(q)ᵀ τ_I`. An aerodynamic force through a
//! point off the centre of mass of a body flying through still air along a nearly
//! straight path (a throw) points along the velocity, so its moment is approximately
//! fixed in the inertial frame over a short record.
//!
//! **Air drag** ([`Environment::damping_nms`]): a torque opposing the body rate,
//! `τ_B = −D ω` (D in N m s per rad, the linear term of the drag of a tumbling body at
//! low rates).
//!
//! **Magnetic torques** ([`Environment::magnetic`], [`super::magnetic`]): the residual
//! dipole's `m_res × B_B` is unknown; the magnetorquers' `m_cmd × B` is reported in
//! `tau_nm` with the measured field.
//!
//! **Thrusters** ([`Environment::thrusters`], [`super::thrusters`]): their torque about the
//! origin `Σ r_i × F_i` is reported in `tau_nm`; the rest of their torque about the
//! centre of mass, `−c × F`, is unknown.
//!
//! [`Environment::torque_nm`] is the unknown torque; [`Environment::actuator_torque_nm`]
//! the actuators' torque that telemetry reports (with the true field), and
//! [`Environment::total_torque_nm`] their sum, what acts on the body besides the
//! scenario's known torque and the white disturbance.

use super::magnetic::Magnetic;
use super::thrusters::Thrusters;
use super::SimError;
use crate::attitude::Quaternion;
use crate::sim::sensors::DEG;
use nalgebra::{Matrix3, Vector3};

/// Earth's gravitational parameter, m³/s² (WGS 84 / EGM96 value).
pub const EARTH_MU_M3_S2: f64 = 3.986_004_418e14;
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

/// The environment: unknown torques, the magnetic field and the thrusters. `Default`:
/// none.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Environment {
    /// The orbit; gravity gradient acts when set.
    pub orbit: Option<Orbit>,
    /// Constant disturbance torque, N m, body axes.
    pub constant_torque_nm: Vector3<f64>,
    /// Constant torque in the inertial frame, N m (module docs).
    pub inertial_torque_nm: Vector3<f64>,
    /// Linear drag coefficient D of the torque `−D ω`, N m s (≥ 0; 0 = none).
    pub damping_nms: f64,
    /// The magnetic field, the dipoles and the magnetometer (`None`: no field, no
    /// `external.field_t`).
    pub magnetic: Option<Magnetic>,
    /// Thrusters and the centre of mass (`None`: none, no `external.force_n`).
    pub thrusters: Option<Thrusters>,
}

impl Environment {
    /// Whether any torque acts.
    #[must_use]
    pub(crate) fn is_active(&self) -> bool {
        self.orbit.is_some()
            || self.constant_torque_nm != Vector3::zeros()
            || self.inertial_torque_nm != Vector3::zeros()
            || self.damping_nms != 0.0
            || self.magnetic.is_some()
            || self.thrusters.is_some()
    }

    /// The unknown torque at `t_s` on a body of inertia `j` at attitude `q` (body →
    /// inertial) turning at `omega_rad_s` (body axes), N m, body axes: gravity gradient,
    /// the constant, inertial and drag torques, the residual dipole's `m_res × B_B` and
    /// the thrusters' `−c × F`.
    #[must_use]
    pub fn torque_nm(
        &self,
        t_s: f64,
        q: &Quaternion,
        omega_rad_s: &Vector3<f64>,
        j: &Matrix3<f64>,
    ) -> Vector3<f64> {
        let mut tau = self.classic_torque_nm(t_s, q, omega_rad_s, j);
        if let Some(m) = &self.magnetic {
            let b = m.field_body_t(self.orbit.as_ref(), t_s, q);
            tau += m.residual_dipole_am2.cross(&b);
        }
        if let Some(th) = &self.thrusters {
            tau -= th.centre_of_mass_m.cross(&th.force_n(t_s));
        }
        tau
    }

    /// The actuators' torque that telemetry reports, at `t_s` and attitude `q`, N m, body
    /// axes: the magnetorquers' `m_cmd × B_B` with the **true** field (the telemetry uses
    /// the measured one) and the thrusters' `Σ r_i × F_i` about the origin.
    #[must_use]
    pub fn actuator_torque_nm(&self, t_s: f64, q: &Quaternion) -> Vector3<f64> {
        let mut tau = Vector3::zeros();
        if let Some(m) = &self.magnetic {
            let b = m.field_body_t(self.orbit.as_ref(), t_s, q);
            tau += m.commanded_dipole_am2(t_s).cross(&b);
        }
        if let Some(th) = &self.thrusters {
            tau += th.force_and_torque(t_s).1;
        }
        tau
    }

    /// Everything this environment applies to the body, N m, body axes:
    /// [`Self::torque_nm`] + [`Self::actuator_torque_nm`] (the magnetic torque
    /// `(m_res + m_cmd) × B_B`, the thrusters' torque about the centre of mass).
    #[must_use]
    pub fn total_torque_nm(
        &self,
        t_s: f64,
        q: &Quaternion,
        omega_rad_s: &Vector3<f64>,
        j: &Matrix3<f64>,
    ) -> Vector3<f64> {
        let mut tau = self.classic_torque_nm(t_s, q, omega_rad_s, j);
        if let Some(m) = &self.magnetic {
            let b = m.field_body_t(self.orbit.as_ref(), t_s, q);
            tau += (m.residual_dipole_am2 + m.commanded_dipole_am2(t_s)).cross(&b);
        }
        if let Some(th) = &self.thrusters {
            tau += th.torque_about_com_nm(t_s);
        }
        tau
    }

    /// Gravity gradient, the constant and inertial torques and drag.
    #[must_use]
    fn classic_torque_nm(
        &self,
        t_s: f64,
        q: &Quaternion,
        omega_rad_s: &Vector3<f64>,
        j: &Matrix3<f64>,
    ) -> Vector3<f64> {
        let gg = self
            .orbit
            .map_or_else(Vector3::zeros, |o| o.gravity_gradient_nm(t_s, q, j));
        let inertial = if self.inertial_torque_nm == Vector3::zeros() {
            Vector3::zeros()
        } else {
            q.conjugate().rotate(&self.inertial_torque_nm)
        };
        gg + self.constant_torque_nm + inertial - omega_rad_s * self.damping_nms
    }

    /// Check every field.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        if let Some(o) = &self.orbit {
            o.validate()?;
        }
        if !self.constant_torque_nm.iter().all(|v| v.is_finite()) {
            return Err(SimError::InvalidSetting {
                field: "environment.constant_torque_nm",
                value: self.constant_torque_nm.norm(),
                why: "must be finite",
            });
        }
        if !self.inertial_torque_nm.iter().all(|v| v.is_finite()) {
            return Err(SimError::InvalidSetting {
                field: "environment.inertial_torque_nm",
                value: self.inertial_torque_nm.norm(),
                why: "must be finite",
            });
        }
        if !(self.damping_nms.is_finite() && self.damping_nms >= 0.0) {
            return Err(SimError::InvalidSetting {
                field: "environment.damping_nms",
                value: self.damping_nms,
                why: "must be finite and >= 0",
            });
        }
        if let Some(m) = &self.magnetic {
            m.validate(self.orbit.as_ref())?;
        }
        if let Some(t) = &self.thrusters {
            t.validate()?;
        }
        Ok(())
    }
}
