//! Keyword arguments → the library's run description ([`RunDescription`]), generically:
//! each keyword is turned into a serde value tree and deserialised by the description
//! itself, so the keywords, their kinds of value, the names of the choices and the
//! defaults are the library's (the command line's options, in snake case). A bad value
//! raises `ValueError` (or `TypeError` for a wrong type) naming the keyword; an unknown
//! keyword is a `TypeError`, as Python raises it.

use crate::errors::{type_error, value_error};
use crate::kwargs::{type_name, Kwargs};
use inertia::pipeline::{PipelineError, PipelineSettings};
use inertia::run_description::RunDescription;
use inertia::telemetry::csv::{GyroUnit, QuaternionFormat, DEFAULT_UNIT_TOLERANCE};
use inertia::text::Num;
use nalgebra::Matrix3;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde::Deserialize;
use serde_value::{DeserializerError, Value};
use std::collections::BTreeMap;

/// How the quaternion columns are to be read, and the reader's tolerances
/// (`scalar_first`, `jpl`, `conjugate`, `gyro_unit`, `unit_tolerance`,
/// `period_tolerance`, `negate_rho`).
#[derive(Debug, Clone, Copy)]
pub struct Convention {
    pub format: QuaternionFormat,
    pub unit_tolerance: f64,
    pub period_tolerance: Option<f64>,
    /// The rho columns hold the rotor momentum with the opposite sign: negate them.
    pub negate_rho: bool,
    /// The unit of the gyro rates (`--gyro-unit`).
    pub gyro_unit: GyroUnit,
    /// No quaternions: the attitude is integrated from the gyro rates
    /// (`GateOptions::attitude_from_gyro`).
    pub attitude_from_gyro: bool,
}

impl Convention {
    /// This convention for arrays without quaternions (`q=None`): the attitude is
    /// integrated from the gyro rates; a quaternion convention given with them is an
    /// argument error, not silently ignored.
    pub fn without_quaternions(mut self) -> PyResult<Self> {
        if self.format != QuaternionFormat::HamiltonScalarLast {
            return Err(value_error(
                "q=None: without quaternions the attitude is integrated from the gyro rates w; scalar_first, jpl and conjugate describe quaternions that were not given",
            ));
        }
        self.attitude_from_gyro = true;
        Ok(self)
    }
}

impl Default for Convention {
    fn default() -> Self {
        Self {
            format: QuaternionFormat::HamiltonScalarLast,
            unit_tolerance: DEFAULT_UNIT_TOLERANCE,
            period_tolerance: None,
            negate_rho: false,
            gyro_unit: GyroUnit::RadPerS,
            attitude_from_gyro: false,
        }
    }
}

/// Everything an estimation run takes besides the data.
#[derive(Debug, Clone)]
pub struct RunSettings {
    pub pipeline: PipelineSettings,
    pub batch: bool,
    pub history: bool,
    pub truth: Option<Matrix3<f64>>,
}

/// A keyword's value as a serde value tree: `None` is absent, a NumPy array or scalar
/// is its `tolist()`, a path its `os.fspath`; anything else unsupported is a unit, which
/// the description refuses as the wrong type.
fn tree(v: &Bound<'_, PyAny>) -> PyResult<Value> {
    Ok(if v.is_none() {
        Value::Option(None)
    } else if v.is_instance_of::<PyBool>() {
        Value::Bool(v.extract()?)
    } else if v.is_instance_of::<PyInt>() {
        match v.extract::<i64>() {
            Ok(i) => Value::I64(i),
            Err(_) => Value::F64(v.extract()?),
        }
    } else if v.is_instance_of::<PyFloat>() {
        Value::F64(v.extract()?)
    } else if v.is_instance_of::<PyString>() {
        Value::String(v.extract()?)
    } else if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        Value::Seq(v.try_iter()?.map(|x| tree(&x?)).collect::<PyResult<_>>()?)
    } else if let Ok(d) = v.downcast::<PyDict>() {
        let mut m = BTreeMap::new();
        for (k, x) in d.iter() {
            m.insert(tree(&k)?, tree(&x)?);
        }
        Value::Map(m)
    } else if v.hasattr("tolist")? {
        tree(&v.call_method0("tolist")?)?
    } else if v.hasattr("__fspath__")? {
        tree(&v.call_method0("__fspath__")?)?
    } else {
        Value::Unit
    })
}

/// serde's name of what it expected, in Python's words.
fn expected(what: &str) -> &str {
    match what {
        "f64" | "f32" => "a number",
        "usize" | "u64" | "u32" | "i64" => "an integer",
        "a boolean" => "True or False",
        // A table (`outside`).
        s if s.starts_with("struct ") => "a dict",
        other => other,
    }
}

/// A value as a message shows it (`"cubic"`, `1.5`).
fn shown(v: &Bound<'_, PyAny>) -> String {
    if let Ok(s) = v.extract::<String>() {
        return format!("{s:?}");
    }
    if let Ok(x) = v.extract::<f64>() {
        if !v.is_instance_of::<PyBool>() {
            return Num(x).to_string();
        }
    }
    v.repr().map_or_else(|_| "?".into(), |r| r.to_string())
}

/// Whether `key` is a keyword of the run description (not a key nested in one's table).
fn is_keyword(key: &str) -> bool {
    RunDescription::SETTINGS_KEYS.contains(&key) || RunDescription::INPUT_KEYS.contains(&key)
}

/// The error of keyword `key` given `v`, in Python's words.
fn keyword_error(function: &str, key: &str, v: &Bound<'_, PyAny>, e: DeserializerError) -> PyErr {
    match e {
        // A key of a table's dict (`outside={"gravity": …}`).
        DeserializerError::UnknownField(field, known) if is_keyword(key) => value_error(format!(
            "{key}: unknown key {field:?} (known: {})",
            known.join(", ")
        )),
        DeserializerError::UnknownField(..) => type_error(format!(
            "{function}() got an unexpected keyword argument '{key}'"
        )),
        DeserializerError::InvalidType(_, what) => type_error(format!(
            "{key}: expected {}, got {}",
            expected(&what),
            type_name(v)
        )),
        DeserializerError::InvalidValue(_, what) => {
            let what = if what == "usize" {
                "an integer >= 0"
            } else {
                expected(&what)
            };
            value_error(format!("{key}={}: expected {what}", shown(v)))
        }
        DeserializerError::Custom(m) if m.starts_with(key) => value_error(m),
        other => value_error(format!("{key}: {other}")),
    }
}

/// The error of the entry of a table keyword's dict (`outside={"residual_dipole": "no"}`)
/// at fault, named `outside["residual_dipole"]`; `None` where the fault is not one
/// entry's (an unknown key, a message of the table's own, an entry that needs others).
fn entry_error(
    function: &str,
    key: &str,
    d: &Bound<'_, PyDict>,
    e: &DeserializerError,
    one: &dyn Fn(Value) -> Value,
) -> PyResult<Option<PyErr>> {
    if matches!(
        e,
        DeserializerError::UnknownField(..) | DeserializerError::Custom(_)
    ) {
        return Ok(None);
    }
    for (k, x) in d.iter() {
        let entry = Value::Map(BTreeMap::from([(tree(&k)?, tree(&x)?)]));
        match RunDescription::deserialize(one(entry)) {
            Err(DeserializerError::MissingField(_)) | Ok(_) => {}
            Err(e) => {
                let name = match k.extract::<String>() {
                    Ok(s) => format!("{key}[{s:?}]"),
                    Err(_) => format!("{key}[{}]", k.repr()?),
                };
                return Ok(Some(keyword_error(function, &name, &x, e)));
            }
        }
    }
    Ok(None)
}

/// The run description of the keyword arguments left in `kw` (all of them taken: what
/// is not the description's is an unexpected keyword of `function`).
pub fn describe(kw: &Kwargs<'_>, function: &str) -> PyResult<RunDescription> {
    let mut all = BTreeMap::new();
    for (k, v) in kw.dict().iter() {
        let key: String = k.extract()?;
        let value = tree(&v)?;
        if matches!(value, Value::Option(None)) {
            continue;
        }
        // One keyword at a time, so that an error names it; in a table's dict
        // (`outside={…}`), one key at a time, so that it names that key too.
        let one = |value: Value| Value::Map(BTreeMap::from([(Value::String(key.clone()), value)]));
        if let Err(e) = RunDescription::deserialize(one(value.clone())) {
            if let Ok(d) = v.downcast::<PyDict>() {
                if let Some(err) = entry_error(function, &key, d, &e, &one)? {
                    return Err(err);
                }
            }
            return Err(keyword_error(function, &key, &v, e));
        }
        all.insert(Value::String(key), value);
    }
    kw.dict().clear();
    RunDescription::deserialize(Value::Map(all)).map_err(|e| value_error(e.to_string()))
}

/// A keyword named as itself.
fn keyword(key: &str) -> String {
    key.to_string()
}

/// The reading convention described.
pub fn convention(d: &RunDescription) -> PyResult<Convention> {
    let o = d
        .csv_options(&keyword)
        .map_err(|e| value_error(e.message))?;
    Ok(Convention {
        format: o.quaternion,
        unit_tolerance: o.unit_tolerance,
        period_tolerance: o.period_tolerance,
        negate_rho: o.negate_rho,
        gyro_unit: o.gyro_unit,
        attitude_from_gyro: false,
    })
}

/// The pipeline settings described (the command line's defaults). `nominal` and `prior`
/// are 3×3 matrices here, not files.
pub fn pipeline(d: &RunDescription) -> PyResult<PipelineSettings> {
    let mut no_files = |_: &std::path::Path, _| {
        Err("expected a 3×3 matrix of numbers (kg m²), not a file name".to_string())
    };
    d.pipeline_settings(&keyword, &mut no_files).map_err(|e| {
        if e.message.starts_with("expected") {
            type_error(format!("{}: {}", e.key, e.message))
        } else {
            value_error(e.message)
        }
    })
}

/// Everything `estimate` takes besides the data: the description of the keywords, and
/// `history` and `truth`, which are Python's own.
pub fn run(kw: &Kwargs<'_>, function: &str) -> PyResult<(RunSettings, RunDescription)> {
    let history = kw.bool("history", false)?;
    let truth = kw.matrix("truth")?;
    let d = describe(kw, function)?;
    Ok((
        RunSettings {
            pipeline: pipeline(&d)?,
            batch: d.batch.unwrap_or(false),
            history,
            truth,
        },
        d,
    ))
}

/// A settings error in the keyword arguments' words.
pub fn settings_message(e: PipelineError) -> String {
    let name = |field: &'static str| -> String {
        match RunDescription::key_of(field) {
            "constraints" => "constraints/bounds/nominal".into(),
            // A key of a table (`outside.gravity_mu_m3_s2`), as the dict gives it.
            k => match k.split_once('.') {
                Some((table, entry)) => format!("{table}[{entry:?}]"),
                None => k.into(),
            },
        }
    };
    match e {
        PipelineError::InvalidSetting {
            field,
            value,
            expected,
        } => format!("{}={}: expected {expected}", name(field), Num(value)),
        PipelineError::NotApplicable { setting, estimator } => format!(
            "{} does not apply to the {estimator} estimator",
            name(setting)
        ),
        PipelineError::NeedsSetting {
            setting,
            needs,
            requirement,
            why,
        } => format!(
            "{} needs {} {requirement}: {why}",
            name(setting),
            name(needs)
        ),
        PipelineError::UnknownEstimator { .. } => format!("estimator: {e}"),
        PipelineError::UnknownSolver { .. } | PipelineError::SolverUnavailable { .. } => {
            format!("solver: {e}")
        }
        other => other.to_string(),
    }
}

/// A settings error as a `ValueError` ([`settings_message`]).
pub fn settings_error(e: PipelineError) -> PyErr {
    value_error(settings_message(e))
}
