//! The spacecraft file's thrusters (`[[thruster]]`): where each is, which way it pushes,
//! its thrust, and the telemetry column of its throttle, so that the run computes the
//! known torque about the body frame's origin and the force from the firings, and the
//! estimator finds the centre of mass ([`crate::estimator::external_torque`]).
//!
//! ```toml
//! [[thruster]]
//! name = "t1"
//! position_m = [0.0, 0.3, 0.0]   # from the body frame's origin, body axes
//! direction = [0.0, 0.0, 1.0]    # of the force on the body, unit (to 1e-3)
//! thrust_n = 0.02                # the force at a throttle of 1
//! column = "t1_throttle"         # its throttle in the telemetry: 0 off, 1 full thrust
//! ```
//!
//! At a sample with throttles `u_i`, the force on the body is `F = Σ_i u_i T_i d_i` and
//! its torque about the origin `τ = Σ_i r_i × u_i T_i d_i`; the run adds `τ` to the
//! sample's known torque and gives `F` as its force. A throttle is the force's value at
//! the sample (for pulses shorter than the telemetry step, the step's duty cycle is the
//! closest a node value can come).

#[cfg(feature = "spacecraft")]
use super::SpacecraftError;
use nalgebra::Vector3;
#[cfg(feature = "spacecraft")]
use serde::Deserialize;
use std::string::String;
#[cfg(feature = "spacecraft")]
use std::string::ToString;
#[cfg(feature = "spacecraft")]
use std::vec::Vec;

/// The most thrusters a spacecraft file may list.
pub(crate) const MAX_THRUSTERS: usize = 32;

/// The largest throttle accepted (a throttle is a fraction of full thrust; a little
/// over 1 allows for rounding in the telemetry).
pub(crate) const MAX_THROTTLE: f64 = 1.5;

/// One thruster.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Thruster {
    /// Its name (for messages).
    pub name: String,
    /// Where it acts, m, body axes, from the origin the known torque is taken about.
    pub position_m: [f64; 3],
    /// The direction of its force on the body, unit, body axes.
    pub direction: [f64; 3],
    /// Its force at a throttle of 1, N.
    pub thrust_n: f64,
    /// The telemetry column of its throttle.
    pub column: String,
}

/// The force (N) and its torque about the origin (N m), body axes, of `thrusters` at the
/// throttles `throttles` (in the file's order).
#[must_use]
pub fn force_and_torque(thrusters: &[Thruster], throttles: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
    let mut force = Vector3::zeros();
    let mut torque = Vector3::zeros();
    for (t, &u) in thrusters.iter().zip(throttles) {
        let f = Vector3::from(t.direction) * (t.thrust_n * u);
        force += f;
        torque += Vector3::from(t.position_m).cross(&f);
    }
    (force, torque)
}

#[cfg(feature = "spacecraft")]
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawThruster {
    name: toml::Spanned<String>,
    position_m: toml::Spanned<[f64; 3]>,
    direction: toml::Spanned<[f64; 3]>,
    thrust_n: toml::Spanned<f64>,
    column: toml::Spanned<String>,
}

/// What a parse error is made of: the span, the key, the message.
#[cfg(feature = "spacecraft")]
pub(super) type ErrorAt<'a> =
    &'a dyn Fn(Option<core::ops::Range<usize>>, Option<String>, String) -> SpacecraftError;

/// The `[[thruster]]` tables, validated; `taken` are the rotors' columns (a thruster may
/// not read one).
#[cfg(feature = "spacecraft")]
pub(super) fn parse(
    raw: &[toml::Spanned<RawThruster>],
    taken: &[String],
    err: ErrorAt<'_>,
) -> Result<Vec<Thruster>, SpacecraftError> {
    if raw.len() > MAX_THRUSTERS {
        return Err(err(
            Some(raw[MAX_THRUSTERS].span()),
            None,
            std::format!(
                "{} thrusters; at most {MAX_THRUSTERS} are supported",
                raw.len()
            ),
        ));
    }
    let mut out: Vec<Thruster> = Vec::with_capacity(raw.len());
    for (i, t) in raw.iter().enumerate() {
        let t = t.get_ref();
        let key = |k: &str| Some(std::format!("thruster[{i}].{k}"));
        let name = t.name.get_ref().trim().to_string();
        if name.is_empty() {
            return Err(err(Some(t.name.span()), key("name"), "empty name".into()));
        }
        if let Some(other) = out.iter().position(|o| o.name == name) {
            return Err(err(
                Some(t.name.span()),
                key("name"),
                std::format!("thruster[{other}] has the same name"),
            ));
        }
        let position = *t.position_m.get_ref();
        if !position.iter().all(|x| x.is_finite() && x.abs() <= 1e3) {
            return Err(err(
                Some(t.position_m.span()),
                key("position_m"),
                "three finite values within 1e3 m".into(),
            ));
        }
        let direction = *t.direction.get_ref();
        let norm = Vector3::from(direction).norm();
        if !(direction.iter().all(|x| x.is_finite()) && (norm - 1.0).abs() <= 1e-3) {
            return Err(err(
                Some(t.direction.span()),
                key("direction"),
                std::format!(
                    "not a unit vector (norm {}; within 1e-3 of 1 it is normalised)",
                    crate::text::Num(norm)
                ),
            ));
        }
        let thrust = *t.thrust_n.get_ref();
        if !(thrust.is_finite() && thrust > 0.0 && thrust <= 1e5) {
            return Err(err(
                Some(t.thrust_n.span()),
                key("thrust_n"),
                std::format!(
                    "{} is not a thrust (positive, at most 1e5 N)",
                    crate::text::Num(thrust)
                ),
            ));
        }
        let column = t.column.get_ref().trim().to_string();
        if column.is_empty() {
            return Err(err(
                Some(t.column.span()),
                key("column"),
                "empty column name".into(),
            ));
        }
        if let Some(other) = out.iter().position(|o| o.column == column) {
            return Err(err(
                Some(t.column.span()),
                key("column"),
                std::format!("thruster[{other}] reads the same column"),
            ));
        }
        if taken.contains(&column) {
            return Err(err(
                Some(t.column.span()),
                key("column"),
                "a rotor reads the same column".into(),
            ));
        }
        out.push(Thruster {
            name,
            position_m: position,
            direction: (Vector3::from(direction) / norm).into(),
            thrust_n: thrust,
            column,
        });
    }
    Ok(out)
}
