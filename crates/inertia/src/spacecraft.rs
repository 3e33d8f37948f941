//! The spacecraft file: what the telemetry alone cannot say about
//! the vehicle. Today its rotors: each wheel's spin axis, spin inertia ± σ, and the
//! telemetry column that holds its speed, so that the rotor momentum is computed from
//! the wheel speeds the attitude system telemeters instead of being pre-summed by hand,
//! and the wheels' inertia uncertainty widens σ (a consider parameter, issue #30).
//!
//! # Format (TOML; reading it needs the feature `spacecraft`)
//!
//! ```toml
//! # How the rotors' spin-inertia errors are related: "shared" (default: the same
//! # relative error for every rotor, as for wheels of one model whose catalogue value
//! # is off) or "independent" (each rotor calibrated on its own).
//! rotor_errors = "shared"
//!
//! [[rotor]]
//! name = "rw1"
//! axis = [1.0, 0.0, 0.0]              # spin axis, body axes, unit (to 1e-3)
//! spin_inertia_kg_m2 = 1.2e-3         # about the spin axis
//! spin_inertia_sigma_kg_m2 = 2.4e-5   # its 1σ uncertainty (default 0: exact)
//! spin_axis_sigma_deg = 0.5           # 1σ tilt of the axis, each way (default 0)
//! speed_column = "rw1_speed"          # the telemetry column of its speed
//! speed_unit = "rpm"                  # rad/s (default), rpm or deg/s
//! max_torque_nm = 0.01                # motor torque limit (optional; `plan` needs it)
//! max_momentum_nms = 0.046            # momentum limit: speed limit × spin inertia (same)
//! ```
//!
//! Thrusters (optional; a file needs at least one rotor or one thruster) give the known
//! torque about the origin and the force from their throttle columns, so that the centre
//! of mass is estimated ([`thrusters`]):
//!
//! ```toml
//! [[thruster]]
//! name = "t1"
//! position_m = [0.0, 0.3, 0.0]        # from the body frame's origin, body axes
//! direction = [0.0, 0.0, 1.0]         # of the force on the body, unit
//! thrust_n = 0.02                     # at a throttle of 1
//! column = "t1_throttle"              # the telemetry column of its throttle (0–1)
//! ```
//!
//! `inertia plan` ([`crate::plan`]) needs three more tables, optional otherwise:
//!
//! ```toml
//! [prior]                             # what is known of J before the manoeuvre
//! inertia_kg_m2 = [[0.28, 0.005, -0.005], [0.005, 0.245, 0.005], [-0.005, 0.005, 0.168]]
//! relative_sigma = 0.1                # 1σ of every element, relative to the largest
//!                                     # moment (or sigma_kg_m2 = [six values, order J11,
//!                                     # J22, J33, J12, J13, J23])
//! [sensors]
//! gyro_noise_deg_s_rthz = 0.0057      # gyro rate noise density
//! wheel_noise_nms = 0.0               # wheel momentum telemetry noise per sample (default 0)
//! telemetry_hz = 10.0                 # telemetry rate
//! controller_hz = 1.0                 # wheel command rate (a whole fraction of it)
//! [limits]
//! max_rate_deg_s = 5.0                # body rate limit (optional)
//! max_angle_deg = 20.0                # largest rotation from the start (optional)
//! ```
//!
//! # Convention
//!
//! A rotor's speed `ω_i` is its spin rate relative to the body about `+axis`; its
//! angular momentum is `J_i ω_i a_i` (the rotor's momentum about its own axis, eq. 3's
//! `ρ`), and the rotor momentum of the sample is their sum, body axes:
//!
//! ```text
//! ρ = Σ_i J_i u_i ω̃_i a_i        (u_i: the speed unit's factor to rad/s)
//! ```
//!
//! # The consider term
//!
//! Each rotor's spin inertia ± σ (errors shared by every rotor, or independent) and its
//! axis's tilt ± σ (two small angles, independent per rotor) are consider parameters:
//! the answer's move for each 1σ error source is measured by re-running the estimator,
//! and σ widens by their root sum square (`crate::estimator::rotor_inertia`).
//!
//! # Validation
//!
//! Unknown keys, a missing key, a non-unit axis, a spin inertia that is not positive, a
//! σ not in `[0, J_i)`, an unknown speed unit, two rotors with one name or one column,
//! more than `MAX_ROTORS` rotors or none: each refused with the file, the line and the
//! key ([`SpacecraftError`]).

use crate::text::Clipped;
use nalgebra::Vector3;
#[cfg(feature = "spacecraft")]
use serde::Deserialize;
use std::string::String;
#[cfg(feature = "spacecraft")]
use std::string::ToString;
use std::vec::Vec;

/// What is known of J before a manoeuvre (`[prior]`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Prior {
    /// Prior inertia, kg m², symmetric positive definite.
    pub inertia_kg_m2: [[f64; 3]; 3],
    /// 1σ per element, kg m² (order of eq. 48).
    pub sigma_kg_m2: [f64; 6],
}

/// Sensor noise and rates (`[sensors]`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Sensors {
    /// Gyro rate noise density, deg/s/√Hz.
    pub gyro_noise_deg_s_rthz: f64,
    /// Wheel-momentum telemetry noise per sample, N m s.
    pub wheel_noise_nms: f64,
    /// Telemetry rate, Hz.
    pub telemetry_hz: f64,
    /// Wheel command rate, Hz.
    pub controller_hz: f64,
}

/// The most rotors a spacecraft file may list.
pub(crate) const MAX_ROTORS: usize = 16;

/// How far an axis's norm may differ from 1 (it is then normalised).
pub(crate) const AXIS_NORM_TOLERANCE: f64 = 1e-3;

/// The unit of a rotor's speed column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum SpeedUnit {
    /// rad/s (the default).
    #[default]
    #[cfg_attr(feature = "serde", serde(rename = "rad/s"))]
    RadPerS,
    /// Revolutions per minute.
    #[cfg_attr(feature = "serde", serde(rename = "rpm"))]
    Rpm,
    /// deg/s.
    #[cfg_attr(feature = "serde", serde(rename = "deg/s"))]
    DegPerS,
}

impl SpeedUnit {
    /// Every unit's name, as a spacecraft file spells it.
    pub(crate) const NAMES: [&'static str; 3] = ["rad/s", "rpm", "deg/s"];

    /// The factor that turns a speed in this unit into rad/s.
    #[must_use]
    pub(crate) fn to_rad_s(self) -> f64 {
        match self {
            SpeedUnit::RadPerS => 1.0,
            SpeedUnit::Rpm => core::f64::consts::PI / 30.0,
            SpeedUnit::DegPerS => core::f64::consts::PI / 180.0,
        }
    }
}

impl core::str::FromStr for SpeedUnit {
    type Err = ();

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "rad/s" => Ok(SpeedUnit::RadPerS),
            "rpm" => Ok(SpeedUnit::Rpm),
            "deg/s" => Ok(SpeedUnit::DegPerS),
            _ => Err(()),
        }
    }
}

/// How the rotors' spin-inertia errors are related ([module docs](self), "The consider
/// term").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum RotorErrors {
    /// One relative error for every rotor, each by its own σ (the default: the
    /// conservative reading of one catalogue value for wheels of one model).
    #[default]
    Shared,
    /// Each rotor's error on its own.
    Independent,
}

/// One rotor (reaction wheel, momentum wheel, flywheel).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Rotor {
    /// Its name (for messages and the report).
    pub name: String,
    /// Spin axis, body axes, unit.
    pub axis: [f64; 3],
    /// Spin inertia about the axis, kg m².
    pub spin_inertia_kg_m2: f64,
    /// Its 1σ uncertainty, kg m² (0: exact).
    pub spin_inertia_sigma_kg_m2: f64,
    /// The 1σ tilt of its axis about each of two perpendicular directions, deg (0: exact).
    pub spin_axis_sigma_deg: f64,
    /// The telemetry column that holds its speed.
    pub speed_column: String,
    /// The unit of that column.
    pub speed_unit: SpeedUnit,
    /// Motor torque limit, N m (`None`: not given).
    pub max_torque_nm: Option<f64>,
    /// Momentum limit, N m s (`None`: not given).
    pub max_momentum_nms: Option<f64>,
}

impl Rotor {
    /// The momentum per stored speed unit, N m s per unit, body axes: `J_i u_i a_i`.
    #[must_use]
    pub(crate) fn momentum_per_unit(&self) -> Vector3<f64> {
        Vector3::from(self.axis) * (self.spin_inertia_kg_m2 * self.speed_unit.to_rad_s())
    }

    /// The relative σ of its spin inertia, `σ_i/J_i`.
    #[must_use]
    pub(crate) fn relative_sigma(&self) -> f64 {
        self.spin_inertia_sigma_kg_m2 / self.spin_inertia_kg_m2
    }

    /// Two unit vectors perpendicular to its axis and to each other (the directions its
    /// axis tilts towards): the axis crossed with the body axis it is least aligned
    /// with, then the axis crossed with that.
    #[must_use]
    pub fn tilt_directions(&self) -> [Vector3<f64>; 2] {
        let a = Vector3::from(self.axis);
        let k = a.iamin();
        let e1 = a.cross(&Vector3::ith(k, 1.0)).normalize();
        [e1, a.cross(&e1)]
    }
}

/// A spacecraft file's contents, validated.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Spacecraft {
    /// The rotors, in the file's order.
    pub rotors: Vec<Rotor>,
    /// How their spin-inertia errors are related.
    pub rotor_errors: RotorErrors,
    /// The prior J (`[prior]`), if given.
    pub prior: Option<Prior>,
    /// Sensor noise and rates (`[sensors]`), if given.
    pub sensors: Option<Sensors>,
    /// Body rate limit, deg/s (`[limits] max_rate_deg_s`), if given.
    pub max_rate_deg_s: Option<f64>,
    /// Largest rotation of the body from its attitude at the start of a plan, deg
    /// (`[limits] max_angle_deg`, at most 180), if given.
    pub max_angle_deg: Option<f64>,
    /// The thrusters (`[[thruster]]`, [`thrusters`]), in the file's order.
    pub thrusters: Vec<Thruster>,
}

/// A spacecraft file that cannot be used: the file, the line (where the problem has
/// one), the key, and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{}{}{message}", .line.map_or_else(String::new, |l| format!("{l}:")), .key.as_ref().map_or_else(String::new, |k| format!(" `{}`:", Clipped::new(k))))]
pub struct SpacecraftError {
    /// The file (as the caller named it).
    pub file: String,
    /// 1-based line, where the problem has one.
    pub line: Option<usize>,
    /// The key at fault (`rotor[2].axis`), where there is one.
    pub key: Option<String>,
    /// What is wrong (one line, control characters escaped).
    pub message: String,
}

#[cfg(feature = "spacecraft")]
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    #[serde(default)]
    rotor_errors: Option<toml::Spanned<String>>,
    #[serde(default, rename = "rotor")]
    rotors: Vec<toml::Spanned<RawRotor>>,
    #[serde(default)]
    prior: Option<toml::Spanned<RawPrior>>,
    #[serde(default)]
    sensors: Option<toml::Spanned<RawSensors>>,
    #[serde(default)]
    limits: Option<toml::Spanned<RawLimits>>,
    #[serde(default, rename = "thruster")]
    thrusters: Vec<toml::Spanned<thrusters::RawThruster>>,
}

#[cfg(feature = "spacecraft")]
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPrior {
    inertia_kg_m2: toml::Spanned<[[f64; 3]; 3]>,
    #[serde(default)]
    sigma_kg_m2: Option<toml::Spanned<[f64; 6]>>,
    #[serde(default)]
    relative_sigma: Option<toml::Spanned<f64>>,
}

#[cfg(feature = "spacecraft")]
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSensors {
    gyro_noise_deg_s_rthz: toml::Spanned<f64>,
    #[serde(default)]
    wheel_noise_nms: Option<toml::Spanned<f64>>,
    telemetry_hz: toml::Spanned<f64>,
    controller_hz: toml::Spanned<f64>,
}

#[cfg(feature = "spacecraft")]
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLimits {
    #[serde(default)]
    max_rate_deg_s: Option<toml::Spanned<f64>>,
    #[serde(default)]
    max_angle_deg: Option<toml::Spanned<f64>>,
}

#[cfg(feature = "spacecraft")]
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRotor {
    name: toml::Spanned<String>,
    axis: toml::Spanned<[f64; 3]>,
    spin_inertia_kg_m2: toml::Spanned<f64>,
    #[serde(default)]
    spin_inertia_sigma_kg_m2: Option<toml::Spanned<f64>>,
    #[serde(default)]
    spin_axis_sigma_deg: Option<toml::Spanned<f64>>,
    speed_column: toml::Spanned<String>,
    #[serde(default)]
    speed_unit: Option<toml::Spanned<String>>,
    #[serde(default)]
    max_torque_nm: Option<toml::Spanned<f64>>,
    #[serde(default)]
    max_momentum_nms: Option<toml::Spanned<f64>>,
}

impl Spacecraft {
    /// Read and validate a spacecraft file.
    #[cfg(feature = "spacecraft")]
    pub fn load(path: &std::path::Path) -> Result<Self, SpacecraftError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SpacecraftError {
            file: file.clone(),
            line: None,
            key: None,
            message: format!(" {}", Clipped::new(&e.to_string())),
        })?;
        Self::parse(&text, &file)
    }

    /// Validate a spacecraft file's text; `file` names it in messages.
    #[cfg(feature = "spacecraft")]
    pub fn parse(text: &str, file: &str) -> Result<Self, SpacecraftError> {
        let line_of = |offset: usize| 1 + text[..offset.min(text.len())].matches('\n').count();
        let err = |span: Option<core::ops::Range<usize>>, key: Option<String>, message: String| {
            SpacecraftError {
                file: file.to_string(),
                line: span.map(|s| line_of(s.start)),
                key,
                message: format!(" {}", Clipped::with_limit(&message, 300)),
            }
        };
        let raw: RawFile = toml::from_str(text).map_err(|e| {
            // toml's message spans several lines (it quotes the file); keep its first, and
            // name the key of the line it points at.
            let m = e.message().lines().next().unwrap_or("").to_string();
            let key = e.span().and_then(|s| {
                let start = text[..s.start.min(text.len())]
                    .rfind('\n')
                    .map_or(0, |i| i + 1);
                let line = text[start..].lines().next()?;
                let (k, _) = line.split_once('=')?;
                let k = k.trim();
                (!k.is_empty() && !k.starts_with('#')).then(|| k.to_string())
            });
            err(e.span(), key, m)
        })?;
        let rotor_errors = match &raw.rotor_errors {
            None => RotorErrors::Shared,
            Some(s) => match s.get_ref().as_str() {
                "shared" => RotorErrors::Shared,
                "independent" => RotorErrors::Independent,
                other => {
                    return Err(err(
                        Some(s.span()),
                        Some("rotor_errors".into()),
                        format!("{other:?} is not one of \"shared\", \"independent\""),
                    ))
                }
            },
        };
        if raw.rotors.is_empty() && raw.thrusters.is_empty() {
            return Err(err(
                None,
                None,
                "no rotor and no thruster: list each wheel as a [[rotor]] table, each thruster as a [[thruster]] table".into(),
            ));
        }
        if raw.rotors.len() > MAX_ROTORS {
            return Err(err(
                Some(raw.rotors[MAX_ROTORS].span()),
                None,
                format!(
                    "{} rotors; at most {MAX_ROTORS} are supported",
                    raw.rotors.len()
                ),
            ));
        }
        let mut rotors: Vec<Rotor> = Vec::with_capacity(raw.rotors.len());
        for (i, r) in raw.rotors.iter().enumerate() {
            let r = r.get_ref();
            let key = |k: &str| Some(format!("rotor[{i}].{k}"));
            let name = r.name.get_ref().trim().to_string();
            if name.is_empty() {
                return Err(err(Some(r.name.span()), key("name"), "empty name".into()));
            }
            let axis = *r.axis.get_ref();
            let norm = Vector3::from(axis).norm();
            if !(axis.iter().all(|x| x.is_finite()) && (norm - 1.0).abs() <= AXIS_NORM_TOLERANCE) {
                return Err(err(
                    Some(r.axis.span()),
                    key("axis"),
                    format!(
                        "not a unit vector (norm {}; within {AXIS_NORM_TOLERANCE} of 1 it is normalised)",
                        crate::text::Num(norm)
                    ),
                ));
            }
            let j = *r.spin_inertia_kg_m2.get_ref();
            if !(j.is_finite() && j > 0.0 && j <= 1e4) {
                return Err(err(
                    Some(r.spin_inertia_kg_m2.span()),
                    key("spin_inertia_kg_m2"),
                    format!(
                        "{} is not a spin inertia (positive, at most 1e4 kg m²)",
                        crate::text::Num(j)
                    ),
                ));
            }
            let sigma = r
                .spin_inertia_sigma_kg_m2
                .as_ref()
                .map_or(0.0, |s| *s.get_ref());
            if !(sigma.is_finite() && (0.0..j).contains(&sigma)) {
                return Err(err(
                    r.spin_inertia_sigma_kg_m2.as_ref().map(toml::Spanned::span),
                    key("spin_inertia_sigma_kg_m2"),
                    format!(
                        "{} must be at least 0 and less than the spin inertia {}",
                        crate::text::Num(sigma),
                        crate::text::Num(j)
                    ),
                ));
            }
            let tilt = r.spin_axis_sigma_deg.as_ref().map_or(0.0, |s| *s.get_ref());
            if !(tilt.is_finite() && (0.0..=10.0).contains(&tilt)) {
                return Err(err(
                    r.spin_axis_sigma_deg.as_ref().map(toml::Spanned::span),
                    key("spin_axis_sigma_deg"),
                    format!(
                        "{} must be at least 0 and at most 10 deg (a small tilt)",
                        crate::text::Num(tilt)
                    ),
                ));
            }
            let speed_column = r.speed_column.get_ref().trim().to_string();
            if speed_column.is_empty() {
                return Err(err(
                    Some(r.speed_column.span()),
                    key("speed_column"),
                    "empty column name".into(),
                ));
            }
            let speed_unit = match &r.speed_unit {
                None => SpeedUnit::RadPerS,
                Some(u) => u.get_ref().parse().map_err(|()| {
                    err(
                        Some(u.span()),
                        key("speed_unit"),
                        format!(
                            "{:?} is not one of {}",
                            u.get_ref(),
                            SpeedUnit::NAMES.join(", ")
                        ),
                    )
                })?,
            };
            if let Some(other) = rotors.iter().position(|o| o.name == name) {
                return Err(err(
                    Some(r.name.span()),
                    key("name"),
                    format!("rotor[{other}] has the same name"),
                ));
            }
            if let Some(other) = rotors.iter().position(|o| o.speed_column == speed_column) {
                return Err(err(
                    Some(r.speed_column.span()),
                    key("speed_column"),
                    format!("rotor[{other}] reads the same column"),
                ));
            }
            let positive = |v: &Option<toml::Spanned<f64>>, k: &str| match v {
                None => Ok(None),
                Some(x) if x.get_ref().is_finite() && *x.get_ref() > 0.0 => Ok(Some(*x.get_ref())),
                Some(x) => Err(err(
                    Some(x.span()),
                    key(k),
                    format!("{} must be finite and > 0", crate::text::Num(*x.get_ref())),
                )),
            };
            let max_torque_nm = positive(&r.max_torque_nm, "max_torque_nm")?;
            let max_momentum_nms = positive(&r.max_momentum_nms, "max_momentum_nms")?;
            rotors.push(Rotor {
                name,
                axis: (Vector3::from(axis) / norm).into(),
                spin_inertia_kg_m2: j,
                spin_inertia_sigma_kg_m2: sigma,
                spin_axis_sigma_deg: tilt,
                speed_column,
                speed_unit,
                max_torque_nm,
                max_momentum_nms,
            });
        }
        let positive = |v: &toml::Spanned<f64>, k: &str, zero_ok: bool| {
            let x = *v.get_ref();
            if x.is_finite() && (x > 0.0 || (zero_ok && x == 0.0)) {
                Ok(x)
            } else {
                Err(err(
                    Some(v.span()),
                    Some(k.into()),
                    format!(
                        "{} must be finite and {}",
                        crate::text::Num(x),
                        if zero_ok { ">= 0" } else { "> 0" }
                    ),
                ))
            }
        };
        let prior = match &raw.prior {
            None => None,
            Some(p) => {
                let p = p.get_ref();
                let m = *p.inertia_kg_m2.get_ref();
                let mat = nalgebra::Matrix3::from_fn(|r, c| m[r][c]);
                let asym = (mat - mat.transpose()).norm();
                if !mat.iter().all(|x| x.is_finite())
                    || asym > 1e-9 * mat.norm()
                    || mat.cholesky().is_none()
                {
                    return Err(err(
                        Some(p.inertia_kg_m2.span()),
                        Some("prior.inertia_kg_m2".into()),
                        "must be a symmetric positive definite 3 × 3 matrix, kg m²".into(),
                    ));
                }
                let sigma = match (&p.sigma_kg_m2, &p.relative_sigma) {
                    (Some(_), Some(r)) => {
                        return Err(err(
                            Some(r.span()),
                            Some("prior.relative_sigma".into()),
                            "give sigma_kg_m2 or relative_sigma, not both".into(),
                        ))
                    }
                    (Some(v), None) => {
                        let a = *v.get_ref();
                        if !a.iter().all(|x| x.is_finite() && *x > 0.0) {
                            return Err(err(
                                Some(v.span()),
                                Some("prior.sigma_kg_m2".into()),
                                "six finite values > 0, kg m² (J11, J22, J33, J12, J13, J23)"
                                    .into(),
                            ));
                        }
                        a
                    }
                    (None, Some(r)) => {
                        let x = positive(r, "prior.relative_sigma", false)?;
                        [x * mat.diagonal().max(); 6]
                    }
                    (None, None) => {
                        return Err(err(
                            Some(p.inertia_kg_m2.span()),
                            Some("prior".into()),
                            "needs its σ: sigma_kg_m2 or relative_sigma".into(),
                        ))
                    }
                };
                Some(Prior {
                    inertia_kg_m2: m,
                    sigma_kg_m2: sigma,
                })
            }
        };
        let sensors = match &raw.sensors {
            None => None,
            Some(v) => {
                let v = v.get_ref();
                let telemetry_hz = positive(&v.telemetry_hz, "sensors.telemetry_hz", false)?;
                let controller_hz = positive(&v.controller_hz, "sensors.controller_hz", false)?;
                let ratio = telemetry_hz / controller_hz;
                if (ratio - ratio.round()).abs() > 1e-9 * ratio || ratio.round() < 1.0 {
                    return Err(err(
                        Some(v.controller_hz.span()),
                        Some("sensors.controller_hz".into()),
                        "must divide telemetry_hz a whole number of times".into(),
                    ));
                }
                Some(Sensors {
                    gyro_noise_deg_s_rthz: positive(
                        &v.gyro_noise_deg_s_rthz,
                        "sensors.gyro_noise_deg_s_rthz",
                        true,
                    )?,
                    wheel_noise_nms: match &v.wheel_noise_nms {
                        None => 0.0,
                        Some(w) => positive(w, "sensors.wheel_noise_nms", true)?,
                    },
                    telemetry_hz,
                    controller_hz,
                })
            }
        };
        let max_rate_deg_s = match raw
            .limits
            .as_ref()
            .and_then(|l| l.get_ref().max_rate_deg_s.as_ref())
        {
            None => None,
            Some(r) => Some(positive(r, "limits.max_rate_deg_s", false)?),
        };
        let max_angle_deg = match raw
            .limits
            .as_ref()
            .and_then(|l| l.get_ref().max_angle_deg.as_ref())
        {
            None => None,
            Some(a) => {
                let x = positive(a, "limits.max_angle_deg", false)?;
                if x > 180.0 {
                    return Err(err(
                        Some(a.span()),
                        Some("limits.max_angle_deg".into()),
                        format!("{} is more than 180°", crate::text::Num(x)),
                    ));
                }
                Some(x)
            }
        };
        let columns: Vec<String> = rotors.iter().map(|r| r.speed_column.clone()).collect();
        let thrusters = thrusters::parse(&raw.thrusters, &columns, &err)?;
        Ok(Spacecraft {
            rotors,
            rotor_errors,
            prior,
            sensors,
            max_rate_deg_s,
            max_angle_deg,
            thrusters,
        })
    }

    /// The rotor momentum of one sample from its rotors' stored speeds (in the file's
    /// order and units), N m s, body axes: `Σ_i J_i u_i ω̃_i a_i`.
    #[must_use]
    pub fn momentum_nms(&self, speeds: &[f64]) -> Vector3<f64> {
        self.rotors
            .iter()
            .zip(speeds)
            .map(|(r, &w)| r.momentum_per_unit() * w)
            .sum()
    }

    /// The speed columns, in the file's order.
    #[must_use]
    pub fn speed_columns(&self) -> Vec<String> {
        self.rotors.iter().map(|r| r.speed_column.clone()).collect()
    }

    /// The thrusters' throttle columns, in the file's order.
    #[must_use]
    pub fn thruster_columns(&self) -> Vec<String> {
        self.thrusters.iter().map(|t| t.column.clone()).collect()
    }

    /// Whether any rotor's spin inertia or axis carries an uncertainty (a consider term
    /// applies).
    #[must_use]
    pub(crate) fn has_inertia_sigma(&self) -> bool {
        self.rotors
            .iter()
            .any(|r| r.spin_inertia_sigma_kg_m2 > 0.0 || r.spin_axis_sigma_deg > 0.0)
    }

    /// The relative σ of the rotor momentum the file states, for the checks that compare
    /// moves of the answer with its σ: `√(S + Σ_i 2 θ_i²)`, `θ_i` the axis tilt's σ, rad,
    /// and `S` the spin inertias' part, `max_i s_i²` where their errors are shared (one
    /// error) and `Σ_i s_i²` where independent (`s_i` the relative σ of each).
    #[must_use]
    pub(crate) fn stated_relative_sigma(&self) -> f64 {
        let s2 = self
            .rotors
            .iter()
            .map(|r| r.relative_sigma() * r.relative_sigma());
        let inertia = match self.rotor_errors {
            RotorErrors::Shared => s2.fold(0.0, f64::max),
            RotorErrors::Independent => s2.sum(),
        };
        let tilts: f64 = self
            .rotors
            .iter()
            .map(|r| 2.0 * r.spin_axis_sigma_deg.to_radians().powi(2))
            .sum();
        (inertia + tilts).sqrt()
    }
}

pub mod thrusters;
pub use thrusters::Thruster;

#[cfg(all(test, feature = "spacecraft"))]
mod tests;
