//! Arguments validated into configurations.

use crate::args::{ConstraintArg, EstimateArgs, GlitchArg, InputArgs, RhoModelArg, RotationArg};
use crate::error::{input, read_failed, CliError};
use inertia::constraints::ConstraintSet;
use inertia::estimator::momentum_rows::{RhoModel, RotationSource};
use inertia::pipeline::{PipelineError, PipelineSettings};
use inertia::telemetry::csv::{ColumnNames, CsvOptions, QuaternionFormat};
use inertia::telemetry::glitch::GlitchPolicy;
use inertia::tensor::{j_from_matrix, Component};
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// An inertia tensor file (`FILE.truth.json`, `--nominal`, `--truth`).
#[derive(Debug, Serialize, Deserialize)]
pub struct InertiaFile {
    /// J, kg m², rows of the 3×3 matrix.
    pub inertia_kg_m2: [[f64; 3]; 3],
    /// `[J11, J22, J33, J12, J13, J23]`, kg m² (written for convenience; ignored on input).
    #[serde(default, skip_deserializing)]
    pub j: Option<[f64; 6]>,
}

impl InertiaFile {
    /// From a matrix.
    pub fn new(j: &Matrix3<f64>) -> Self {
        let v = j_from_matrix(j);
        Self {
            inertia_kg_m2: [0, 1, 2].map(|r| [0, 1, 2].map(|c| j[(r, c)])),
            j: Some([0, 1, 2, 3, 4, 5].map(|k| v[k])),
        }
    }

    /// Read and check a file.
    pub fn read(path: &Path) -> Result<Matrix3<f64>, CliError> {
        use std::io::Read;
        // A small JSON file: read at most 1 MiB of it.
        const LIMIT: u64 = 1 << 20;
        let mut text = String::new();
        std::fs::File::open(path)
            .and_then(|f| f.take(LIMIT + 1).read_to_string(&mut text))
            .map_err(|e| read_failed(path, e))?;
        if text.len() as u64 > LIMIT {
            return Err(input(format!(
                "{}: longer than {LIMIT} bytes: not an inertia file",
                path.display()
            )));
        }
        let f: InertiaFile = serde_json::from_str(&text).map_err(|e| {
            input(format!(
                "{}:{}:{}: {e} (expected {{\"inertia_kg_m2\": [[..],[..],[..]]}})",
                path.display(),
                e.line(),
                e.column()
            ))
        })?;
        let m = Matrix3::from_fn(|r, c| f.inertia_kg_m2[r][c]);
        if !m.iter().all(|v| v.is_finite()) {
            return Err(input(format!(
                "{}: inertia_kg_m2 has non-finite entries",
                path.display()
            )));
        }
        if (m - m.transpose()).norm() > 1e-9 * m.norm() {
            return Err(input(format!(
                "{}: inertia_kg_m2 is not symmetric",
                path.display()
            )));
        }
        Ok(m)
    }
}

/// Parse `Jij=LO:HI` into `(component, lower, upper)`. `LO = HI` is an equality.
pub fn parse_bound(s: &str) -> Result<(Component, Option<f64>, Option<f64>), CliError> {
    let bad = |why: &str| {
        input(format!(
            "--bound {s:?}: {why} (expected e.g. J33=2.7:3.3, J12=:0.05)"
        ))
    };
    let (name, range) = s.split_once('=').ok_or_else(|| bad("missing `=`"))?;
    let k = Component::from_name(name.trim()).ok_or_else(|| bad("unknown element"))?;
    let (lo, hi) = range.split_once(':').ok_or_else(|| bad("missing `:`"))?;
    let num = |t: &str| -> Result<Option<f64>, CliError> {
        let t = t.trim();
        if t.is_empty() {
            return Ok(None);
        }
        let v: f64 = t.parse().map_err(|_| bad("not a number"))?;
        if v.is_finite() {
            Ok(Some(v))
        } else {
            Err(bad("not finite"))
        }
    };
    let (l, h) = (num(lo)?, num(hi)?);
    if l.is_none() && h.is_none() {
        return Err(bad("no bound given"));
    }
    Ok((k, l, h))
}

/// Parse `10%` or `0.1`.
pub fn parse_fraction(s: &str) -> Result<f64, CliError> {
    let t = s.trim();
    let v = match t.strip_suffix('%') {
        Some(p) => p.trim().parse::<f64>().map(|v| v / 100.0),
        None => t.parse::<f64>(),
    }
    .map_err(|_| input(format!("--tolerance {s:?}: expected e.g. 10% or 0.1")))?;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(input(format!("--tolerance {s:?}: must be finite and >= 0")))
    }
}

/// The constraint set of the arguments (validated with the rest of the settings).
pub fn constraint_set(
    kind: ConstraintArg,
    bounds: &[String],
    nominal: Option<(&Matrix3<f64>, f64)>,
) -> Result<ConstraintSet, CliError> {
    let mut set = match kind {
        ConstraintArg::Physical => ConstraintSet::physical(),
        ConstraintArg::Paper => ConstraintSet::paper(),
        ConstraintArg::PositiveDefinite => ConstraintSet::positive_definite(),
    };
    if let Some((n, p)) = nominal {
        set = set.with_nominal_inertia(n, p);
    }
    for b in bounds {
        let (k, l, h) = parse_bound(b)?;
        set = set.with_bounds(k, l, h);
    }
    Ok(set)
}

/// The pipeline settings of `inertia estimate`.
pub fn pipeline_settings(a: &EstimateArgs) -> Result<PipelineSettings, CliError> {
    let nominal = match (&a.nominal, &a.tolerance) {
        (Some(p), Some(t)) => Some((InertiaFile::read(p)?, parse_fraction(t)?)),
        _ => None,
    };
    Ok(PipelineSettings {
        estimator: a.estimator.clone(),
        solver: a.solver.clone(),
        constraints: constraint_set(
            a.constraints,
            &a.bounds,
            nominal.as_ref().map(|(m, p)| (m, *p)),
        )?,
        solve_every: a.every,
        memory_s: a.memory,
        resample_s: a.resample,
        gyro_noise_deg_s_rthz: a.gyro_noise,
        rotation_source: a.rotation_source.map(|r| match r {
            RotationArg::Attitude => RotationSource::Attitude,
            RotationArg::Gyro => RotationSource::Gyro,
        }),
        rho_model: match a.rho_model {
            RhoModelArg::Auto => RhoModel::Auto,
            RhoModelArg::Smooth => RhoModel::Smooth,
            RhoModelArg::Held => RhoModel::Held,
            RhoModelArg::Plain => RhoModel::Plain,
        },
        torque_bias: !a.no_torque_bias,
        max_chain_s: (a.chain != 0.0).then_some(a.chain),
        glitches: match a.glitches {
            GlitchArg::Stop => GlitchPolicy::Stop,
            GlitchArg::Keep => GlitchPolicy::Keep,
        },
        ..PipelineSettings::default()
    })
}

/// The command-line option behind a pipeline setting.
fn option_of(field: &str) -> &str {
    match field {
        "solve_every" => "--every",
        "memory_s" => "--memory",
        "resample_s" => "--resample",
        "gyro_noise_deg_s_rthz" => "--gyro-noise",
        "constraints" => "--constraints/--bound/--nominal",
        "rotation_source" => "--rotation-source",
        "rho_model" => "--rho-model",
        "torque_bias" => "--no-torque-bias",
        "max_chain_s" => "--chain",
        other => other,
    }
}

/// A settings error in the command line's words.
pub fn settings_error(e: PipelineError) -> CliError {
    match e {
        PipelineError::InvalidSetting {
            field,
            value,
            expected,
        } => input(format!(
            "{} {}: expected {expected}",
            option_of(field),
            inertia::text::Num(value)
        )),
        PipelineError::NotApplicable { setting, estimator } => input(format!(
            "{} does not apply to the {estimator} estimator",
            option_of(setting)
        )),
        other => input(other),
    }
}

/// CSV options from the input arguments.
pub fn csv_options(a: &InputArgs) -> Result<CsvOptions, CliError> {
    let mut columns = ColumnNames::default();
    for c in &a.columns {
        let (k, v) = c.split_once('=').ok_or_else(|| {
            input(format!(
                "--column {c:?}: expected DEFAULT=NAME, e.g. t=time"
            ))
        })?;
        if !columns.rename(k.trim(), v.trim()) {
            return Err(input(format!(
                "--column {c:?}: unknown column {k:?} (known: t, q_x, q_y, q_z, q_w, rho_*, tau_*, w_*)"
            )));
        }
    }
    for (name, v) in [
        ("--unit-tolerance", Some(a.unit_tolerance)),
        ("--period-tolerance", a.period_tolerance),
    ] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0) {
                return Err(input(format!("{name} {v}: must be finite and > 0")));
            }
        }
    }
    Ok(CsvOptions {
        quaternion: if a.scalar_first {
            QuaternionFormat::HamiltonScalarFirst
        } else if a.jpl {
            QuaternionFormat::Jpl
        } else {
            QuaternionFormat::HamiltonScalarLast
        },
        columns,
        unit_tolerance: a.unit_tolerance,
        period_tolerance: a.period_tolerance,
        delimiter: b',',
    })
}
