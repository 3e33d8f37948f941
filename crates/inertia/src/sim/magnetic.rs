//! The magnetic field, the spacecraft's magnetic dipoles and a magnetometer.
//!
//! # Conventions (read these)
//!
//! * **Frames.** The field model gives the field `B_I` in the simulator's **inertial**
//!   frame (the frame of the attitude and of the orbit, [`super::environment`]). Everything
//!   on the spacecraft is in **body** axes: `B_B = C(q)ᵀ B_I` with the **true** attitude
//!   `q` (body → inertial), the dipoles, the torques and the magnetometer's reading.
//! * **Units.** Field in tesla (T), dipoles in A m², torques in N m.
//! * **Torque of a dipole** `m` in the field: `τ = m × B_B` (body axes).
//!
//! # Field models ([`FieldModel`])
//!
//! * [`FieldModel::Dipole`]: Earth's field as a **centred dipole aligned with the inertial
//!   z axis** (the Earth's rotation and the dipole's 10° tilt are neglected), with the
//!   equatorial surface strength `B0` = [`EARTH_DIPOLE_T`] (3.12e-5 T) at
//!   `R_E` = [`EARTH_RADIUS_M`]:
//!
//!   ```text
//!   B_I(r) = −B0 (R_E/|r|)³ [3 (ẑ·r̂) r̂ − ẑ]
//!   ```
//!
//!   So `|B| = B0 (R_E/r)³` over the equator (pointing along +ẑ, north) and twice that
//!   over the poles (pointing along −r̂ over the north pole, into the Earth). It needs the
//!   orbit ([`super::Environment::orbit`], which also turns gravity gradient on): the
//!   position is `r_I(t)` of [`super::Orbit::position_m`]. ([`dipole_field_t`])
//! * [`FieldModel::Constant`]: a constant field fixed in the **inertial** frame, T (a
//!   lab's field, or a short record without an orbit: "a 3e-5 T field").
//!
//! # Dipoles
//!
//! * **Residual dipole** [`Magnetic::residual_dipole_am2`] `m_res`, fixed in the body: an
//!   **unknown** torque `m_res × B_B` (not in `tau_nm`).
//! * **Commanded dipole** ([`Magnetorquer`], optional): per body axis a sine wave
//!   `m_cmd,i(t) = A_i sin(2π t/P_i + φ_i)` of the simulator's time `t` (s). Its torque
//!   `m_cmd × B_B` (true field) acts on the body, and the telemetry's known torque
//!   `tau_nm` gets `m_cmd(t_k) × B̃_k` computed with the **measured** field `B̃_k` at the
//!   node, as the CSV reader folds `dipole_*` columns: a magnetometer error shows up as an
//!   unknown torque `m_cmd × (B_B − B̃)`, honestly.
//!
//! # Magnetometer ([`Magnetometer`])
//!
//! At every telemetry node the sample's `external.field_t` is `B̃ = B_B + b + n`, with the
//! constant bias `b` (T, body axes) and white Gaussian noise `n ~ N(0, σ² I)` (σ T per
//! axis, per sample, independent between samples). Noise stream: ChaCha8 seeded with the
//! run's seed, stream 5 (so turning the magnetometer on leaves every other noise
//! unchanged).

use super::orbit::{Orbit, EARTH_RADIUS_M};
use super::SimError;
use crate::attitude::Quaternion;
use crate::sample::range;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Earth's dipole field strength at the equator on the surface, `B0`, T (the classical
/// value of the attitude-control textbooks; IGRF's degree-1 terms give about 3.0e-5 T
/// today).
pub const EARTH_DIPOLE_T: f64 = 3.12e-5;

/// The noise stream of the magnetometer.
const STREAM: u64 = 5;

/// Earth's centred dipole field along the inertial z axis at the inertial position
/// `r_inertial_m` (m): `−B0 (R_E/|r|)³ [3 (ẑ·r̂) r̂ − ẑ]`, T, inertial axes (module docs).
/// Zero at the centre of the Earth.
#[must_use]
pub fn dipole_field_t(r_inertial_m: &Vector3<f64>) -> Vector3<f64> {
    let r = r_inertial_m.norm();
    if !(r > 0.0) {
        return Vector3::zeros();
    }
    let rhat = r_inertial_m / r;
    let ratio = EARTH_RADIUS_M / r;
    (rhat * (3.0 * rhat.z) - Vector3::z()) * (-EARTH_DIPOLE_T * ratio * ratio * ratio)
}

/// Where the field comes from (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum FieldModel {
    /// Earth's centred dipole along the inertial z axis ([`dipole_field_t`]) at the
    /// orbit's position; needs [`super::Environment::orbit`].
    Dipole,
    /// A constant field fixed in the inertial frame, T (each component finite, at most
    /// `range::FIELD_T` in size).
    Constant {
        /// The field, T, inertial axes.
        field_t: Vector3<f64>,
    },
}

/// Magnetorquers driven by a sine wave per body axis:
/// `m_i(t) = A_i sin(2π t/P_i + φ_i)`, A m² (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Magnetorquer {
    /// Amplitude `A` per body axis, A m² (finite, |A| ≤ `range::DIPOLE_AM2`).
    pub amplitude_am2: Vector3<f64>,
    /// Period `P` per body axis, s (finite, > 0).
    pub period_s: Vector3<f64>,
    /// Phase `φ` per body axis, rad (finite).
    pub phase_rad: Vector3<f64>,
}

impl Magnetorquer {
    /// Amplitude `amplitude_am2` on every axis with the periods 50 s, 70 s and 90 s and
    /// zero phases: the commanded dipole turns through every direction over a few
    /// minutes.
    #[must_use]
    pub fn sine(amplitude_am2: f64) -> Self {
        Self {
            amplitude_am2: Vector3::repeat(amplitude_am2),
            period_s: Vector3::new(50.0, 70.0, 90.0),
            phase_rad: Vector3::zeros(),
        }
    }

    /// The commanded dipole at `t_s`, A m², body axes.
    #[must_use]
    pub fn dipole_am2(&self, t_s: f64) -> Vector3<f64> {
        Vector3::from_fn(|i, _| {
            let w = core::f64::consts::TAU / self.period_s[i];
            self.amplitude_am2[i] * (w * t_s + self.phase_rad[i]).sin()
        })
    }

    fn validate(&self) -> Result<(), SimError> {
        let a = self.amplitude_am2;
        if !a
            .iter()
            .all(|v| v.is_finite() && v.abs() <= range::DIPOLE_AM2)
        {
            return Err(SimError::InvalidSetting {
                field: "environment.magnetic.magnetorquer.amplitude_am2",
                value: a.amax(),
                why: "must be finite with every component at most 1e5 A m² in size",
            });
        }
        let p = self.period_s;
        if !p.iter().all(|v| v.is_finite() && *v > 0.0) {
            return Err(SimError::InvalidSetting {
                field: "environment.magnetic.magnetorquer.period_s",
                value: p.min(),
                why: "must be finite and > 0 on every axis",
            });
        }
        if !self.phase_rad.iter().all(|v| v.is_finite()) {
            return Err(SimError::InvalidSetting {
                field: "environment.magnetic.magnetorquer.phase_rad",
                value: self.phase_rad.norm(),
                why: "must be finite",
            });
        }
        Ok(())
    }
}

/// A three-axis magnetometer in body axes (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Magnetometer {
    /// 1σ white noise per axis and sample, T (finite, ≥ 0). Default 1e-7 T (100 nT, a
    /// small spacecraft's magnetoresistive sensor).
    pub noise_t: f64,
    /// Constant bias, T, body axes (finite, each at most `range::FIELD_T`). Default 0.
    pub bias_t: Vector3<f64>,
}

impl Default for Magnetometer {
    fn default() -> Self {
        Self {
            noise_t: 1e-7,
            bias_t: Vector3::zeros(),
        }
    }
}

/// The magnetic environment and the spacecraft's dipoles (module docs). `Default`:
/// Earth's dipole field, no dipole, no magnetorquer, the default magnetometer.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Magnetic {
    /// The field model.
    pub field: FieldModel,
    /// Residual dipole `m_res`, A m², body axes (finite, each at most
    /// `range::DIPOLE_AM2`): its torque `m_res × B_B` is unknown.
    pub residual_dipole_am2: Vector3<f64>,
    /// Commanded dipole (`None`: no magnetorquers).
    pub magnetorquer: Option<Magnetorquer>,
    /// The magnetometer whose reading goes to the samples' `external.field_t`.
    pub magnetometer: Magnetometer,
}

impl Default for Magnetic {
    fn default() -> Self {
        Self::dipole()
    }
}

impl Magnetic {
    /// Earth's dipole field (needs the orbit), no dipole, the default magnetometer.
    #[must_use]
    pub fn dipole() -> Self {
        Self {
            field: FieldModel::Dipole,
            residual_dipole_am2: Vector3::zeros(),
            magnetorquer: None,
            magnetometer: Magnetometer::default(),
        }
    }

    /// A constant inertial field `field_t` (T), no dipole, the default magnetometer.
    #[must_use]
    pub fn constant(field_t: Vector3<f64>) -> Self {
        Self {
            field: FieldModel::Constant { field_t },
            ..Self::dipole()
        }
    }

    /// The field at `t_s` in the inertial frame, T (zero for the dipole model without an
    /// orbit, which [`super::SimConfig`]'s validation refuses).
    #[must_use]
    pub fn field_inertial_t(&self, orbit: Option<&Orbit>, t_s: f64) -> Vector3<f64> {
        match self.field {
            FieldModel::Dipole => {
                orbit.map_or_else(Vector3::zeros, |o| dipole_field_t(&o.position_m(t_s)))
            }
            FieldModel::Constant { field_t } => field_t,
        }
    }

    /// The true field at `t_s` in body axes, `C(q)ᵀ B_I`, T, for the attitude `q` (body →
    /// inertial).
    #[must_use]
    pub(crate) fn field_body_t(
        &self,
        orbit: Option<&Orbit>,
        t_s: f64,
        q: &Quaternion,
    ) -> Vector3<f64> {
        q.conjugate().rotate(&self.field_inertial_t(orbit, t_s))
    }

    /// The commanded dipole at `t_s`, A m², body axes (zero without magnetorquers).
    #[must_use]
    pub(crate) fn commanded_dipole_am2(&self, t_s: f64) -> Vector3<f64> {
        self.magnetorquer
            .map_or_else(Vector3::zeros, |m| m.dipole_am2(t_s))
    }

    /// Check every field; `orbit` is the environment's.
    pub(crate) fn validate(&self, orbit: Option<&Orbit>) -> Result<(), SimError> {
        match self.field {
            FieldModel::Dipole if orbit.is_none() => {
                return Err(SimError::InvalidSetting {
                    field: "environment.magnetic.field",
                    value: f64::NAN,
                    why: "the dipole field model needs the orbit (environment.orbit)",
                })
            }
            FieldModel::Constant { field_t }
                if !field_t
                    .iter()
                    .all(|v| v.is_finite() && v.abs() <= range::FIELD_T) =>
            {
                return Err(SimError::InvalidSetting {
                    field: "environment.magnetic.field",
                    value: field_t.amax(),
                    why: "must be finite with every component at most 1e-2 T in size",
                });
            }
            _ => {}
        }
        let m = self.residual_dipole_am2;
        if !m
            .iter()
            .all(|v| v.is_finite() && v.abs() <= range::DIPOLE_AM2)
        {
            return Err(SimError::InvalidSetting {
                field: "environment.magnetic.residual_dipole_am2",
                value: m.amax(),
                why: "must be finite with every component at most 1e5 A m² in size",
            });
        }
        if let Some(t) = &self.magnetorquer {
            t.validate()?;
        }
        let s = self.magnetometer.noise_t;
        if !(s.is_finite() && (0.0..=range::FIELD_T).contains(&s)) {
            return Err(SimError::InvalidSetting {
                field: "environment.magnetic.magnetometer.noise_t",
                value: s,
                why: "must be finite, >= 0 and at most 1e-2 T",
            });
        }
        let b = self.magnetometer.bias_t;
        if !b.iter().all(|v| v.is_finite() && v.abs() <= range::FIELD_T) {
            return Err(SimError::InvalidSetting {
                field: "environment.magnetic.magnetometer.bias_t",
                value: b.amax(),
                why: "must be finite with every component at most 1e-2 T in size",
            });
        }
        Ok(())
    }
}

/// The magnetometer's error stream (stream 5).
pub(crate) struct MagnetometerNoise {
    rng: ChaCha8Rng,
    noise: Normal<f64>,
    bias_t: Vector3<f64>,
}

impl MagnetometerNoise {
    pub(crate) fn new(m: &Magnetometer, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(STREAM);
        Self {
            rng,
            noise: super::sensors::normal(m.noise_t),
            bias_t: m.bias_t,
        }
    }

    /// The reading for the true body-frame field `b_t`: `b_t + bias + noise`.
    pub(crate) fn measure(&mut self, b_t: &Vector3<f64>) -> Vector3<f64> {
        let n = Vector3::from_fn(|_, _| self.noise.sample(&mut self.rng));
        b_t + self.bias_t + n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Equator and poles against the formula, and the direction (north over the
    /// equator, into the Earth over the north pole).
    #[test]
    fn dipole_at_the_equator_and_the_poles() {
        let r = 7.0e6;
        let k = EARTH_DIPOLE_T * (EARTH_RADIUS_M / r).powi(3);
        let eq = dipole_field_t(&Vector3::new(r * 0.6, r * 0.8, 0.0));
        assert!((eq - Vector3::z() * k).norm() <= 1e-12 * k, "{eq}");
        let north = dipole_field_t(&Vector3::new(0.0, 0.0, r));
        assert!(
            (north + Vector3::z() * 2.0 * k).norm() <= 1e-12 * k,
            "{north}"
        );
        let south = dipole_field_t(&Vector3::new(0.0, 0.0, -r));
        assert!(
            (south + Vector3::z() * 2.0 * k).norm() <= 1e-12 * k,
            "{south}"
        );
        assert_eq!(dipole_field_t(&Vector3::zeros()), Vector3::zeros());
    }

    #[test]
    fn magnetorquer_sines() {
        let m = Magnetorquer::sine(0.2);
        assert_eq!(m.dipole_am2(0.0), Vector3::zeros());
        let d = m.dipole_am2(12.5);
        assert!((d.x - 0.2).abs() < 1e-15, "quarter period of 50 s: {d}");
        assert!(Magnetic::constant(Vector3::x()).commanded_dipole_am2(3.0) == Vector3::zeros());
    }
}
