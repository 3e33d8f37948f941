//! Reading a spacecraft file: the TOML text into [`Spacecraft`], every problem refused
//! with the file, the line and the key (module docs of [`crate::spacecraft`]).

use super::{
    thrusters, Prior, Rotor, RotorErrors, Sensors, Spacecraft, SpacecraftError, SpeedUnit,
};
use super::{AXIS_NORM_TOLERANCE, MAX_ROTORS, MAX_TIME_TAG_SIGMA_S};
use crate::text::Clipped;
use nalgebra::Vector3;
use serde::Deserialize;
use std::string::{String, ToString};
use std::vec::Vec;

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

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPrior {
    inertia_kg_m2: toml::Spanned<[[f64; 3]; 3]>,
    #[serde(default)]
    sigma_kg_m2: Option<toml::Spanned<[f64; 6]>>,
    #[serde(default)]
    relative_sigma: Option<toml::Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSensors {
    gyro_noise_deg_s_rthz: toml::Spanned<f64>,
    #[serde(default)]
    wheel_noise_nms: Option<toml::Spanned<f64>>,
    telemetry_hz: toml::Spanned<f64>,
    controller_hz: toml::Spanned<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLimits {
    #[serde(default)]
    max_rate_deg_s: Option<toml::Spanned<f64>>,
    #[serde(default)]
    max_angle_deg: Option<toml::Spanned<f64>>,
}

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
    #[serde(default)]
    time_tag_sigma_s: Option<toml::Spanned<f64>>,
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
            // A σ from 0 to `max` (default 0), in `unit`, for `what`.
            let small =
                |v: &Option<toml::Spanned<f64>>, k: &str, max: f64, unit: &str, what: &str| {
                    let x = v.as_ref().map_or(0.0, |s| *s.get_ref());
                    if x.is_finite() && (0.0..=max).contains(&x) {
                        return Ok(x);
                    }
                    Err(err(
                        v.as_ref().map(toml::Spanned::span),
                        key(k),
                        format!(
                            "{} must be at least 0 and at most {} {unit} ({what})",
                            crate::text::Num(x),
                            crate::text::Num(max)
                        ),
                    ))
                };
            let tilt = small(
                &r.spin_axis_sigma_deg,
                "spin_axis_sigma_deg",
                10.0,
                "deg",
                "a small tilt",
            )?;
            let time_tag = small(
                &r.time_tag_sigma_s,
                "time_tag_sigma_s",
                MAX_TIME_TAG_SIGMA_S,
                "s",
                "a small offset",
            )?;
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
                time_tag_sigma_s: time_tag,
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
}
