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
//! [`Environment::torque_nm`] is the unknown torque; `Environment::total_torque_nm` adds
//! the actuators' torque that telemetry reports (with the true field): what acts on the
//! body besides the scenario's known torque and the white disturbance.

use super::magnetic::Magnetic;
pub use super::orbit::{gravity_gradient_torque_nm, Orbit, EARTH_MU_M3_S2, EARTH_RADIUS_M};
use super::thrusters::Thrusters;
use super::SimError;
use crate::attitude::Quaternion;
use nalgebra::{Matrix3, Vector3};

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

    /// Everything this environment applies to the body, N m, body axes:
    /// [`Self::torque_nm`] + the actuators' torque (the magnetic torque
    /// `(m_res + m_cmd) × B_B`, the thrusters' torque about the centre of mass).
    #[must_use]
    pub(crate) fn total_torque_nm(
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
