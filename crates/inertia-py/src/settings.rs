//! Keyword arguments → the library's settings, named as the command line names its
//! options (`--memory` is `memory=`, `--no-torque-bias` is `torque_bias=False`, …).
//! Bad values raise `ValueError` (or `TypeError` for a wrong type) naming the argument.

use crate::errors::{type_error, value_error};
use inertia::constraints::{ConstraintSet, ProductConvention};
use inertia::estimator::momentum_rows::{RhoModel, RotationSource};
use inertia::pipeline::{InertialTorque, PipelineError, PipelineSettings, DEFAULT_MAX_CHAIN_S};
use inertia::telemetry::csv::{GyroUnit, QuaternionFormat, DEFAULT_UNIT_TOLERANCE};
use inertia::telemetry::glitch::GlitchPolicy;
use inertia::tensor::Component;
use inertia::text::Num;
use nalgebra::Matrix3;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

/// The estimator `inertia estimate` runs by default.
pub const DEFAULT_ESTIMATOR: &str = "discrete-momentum";

/// How the quaternion columns are to be read, and the reader's tolerances
/// (`--scalar-first`, `--jpl`, `--conjugate`, `--gyro-unit`, `--unit-tolerance`,
/// `--period-tolerance`).
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

/// Keyword arguments, taken out one by one; what is left over is an error.
pub struct Kwargs<'py> {
    dict: Bound<'py, PyDict>,
    function: &'static str,
}

impl<'py> Kwargs<'py> {
    pub fn new(
        dict: Option<&Bound<'py, PyDict>>,
        py: Python<'py>,
        function: &'static str,
    ) -> PyResult<Self> {
        let dict = match dict {
            Some(d) => d.copy()?,
            None => PyDict::new(py),
        };
        Ok(Self { dict, function })
    }

    /// The value of `name`, `None` when absent or `None`.
    pub fn take(&self, name: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        let v = self.dict.get_item(name)?;
        if v.is_some() {
            self.dict.del_item(name)?;
        }
        Ok(v.filter(|v| !v.is_none()))
    }

    pub fn f64(&self, name: &str) -> PyResult<Option<f64>> {
        self.take(name)?
            .map(|v| {
                if v.is_instance_of::<PyString>() {
                    return Err(type_error(format!(
                        "{name}: expected a number, got a string {v}"
                    )));
                }
                v.extract::<f64>().map_err(|_| {
                    type_error(format!("{name}: expected a number, got {}", type_name(&v)))
                })
            })
            .transpose()
    }

    pub fn finite(&self, name: &str) -> PyResult<Option<f64>> {
        match self.f64(name)? {
            Some(v) if !v.is_finite() => {
                Err(value_error(format!("{name}={}: must be finite", Num(v))))
            }
            v => Ok(v),
        }
    }

    pub fn bool(&self, name: &str, default: bool) -> PyResult<bool> {
        self.take(name)?
            .map(|v| {
                v.extract::<bool>().map_err(|_| {
                    type_error(format!(
                        "{name}: expected True or False, got {}",
                        type_name(&v)
                    ))
                })
            })
            .transpose()
            .map(|v| v.unwrap_or(default))
    }

    /// A value given as a string or a number, as text (a number's shortest repr).
    pub fn text_or_number(&self, name: &str) -> PyResult<Option<String>> {
        self.take(name)?
            .map(|v| {
                if v.is_instance_of::<PyString>() {
                    return v.extract::<String>();
                }
                v.extract::<f64>().map(|x| format!("{x:?}")).map_err(|_| {
                    type_error(format!(
                        "{name}: expected a string or a number, got {}",
                        type_name(&v)
                    ))
                })
            })
            .transpose()
    }

    pub fn string(&self, name: &str) -> PyResult<Option<String>> {
        self.take(name)?
            .map(|v| {
                v.extract::<String>().map_err(|_| {
                    type_error(format!("{name}: expected a string, got {}", type_name(&v)))
                })
            })
            .transpose()
    }

    pub fn usize(&self, name: &str, default: usize) -> PyResult<usize> {
        self.take(name)?
            .map(|v| {
                v.extract::<i64>()
                    .map_err(|_| {
                        type_error(format!(
                            "{name}: expected an integer, got {}",
                            type_name(&v)
                        ))
                    })
                    .and_then(|n| {
                        usize::try_from(n)
                            .map_err(|_| value_error(format!("{name}={n}: must be >= 0")))
                    })
            })
            .transpose()
            .map(|v| v.unwrap_or(default))
    }

    /// One of `choices` (`-` and `_` alike).
    pub fn choice(&self, name: &str, choices: &[&'static str]) -> PyResult<Option<&'static str>> {
        let Some(s) = self.string(name)? else {
            return Ok(None);
        };
        let norm = s.replace('_', "-");
        choices
            .iter()
            .find(|c| **c == norm)
            .copied()
            .map(Some)
            .ok_or_else(|| {
                value_error(format!(
                    "{name}={s:?}: expected one of {}",
                    choices.join(", ")
                ))
            })
    }

    /// Three numbers.
    pub fn vector(&self, name: &str) -> PyResult<Option<[f64; 3]>> {
        self.numbers::<3>(name)
    }

    pub fn numbers<const N: usize>(&self, name: &str) -> PyResult<Option<[f64; N]>> {
        self.take(name)?
            .map(|v| {
                let xs: Vec<f64> = v.extract().map_err(|_| {
                    type_error(format!(
                        "{name}: expected {N} numbers, got {}",
                        type_name(&v)
                    ))
                })?;
                let arr: [f64; N] = xs.clone().try_into().map_err(|_| {
                    value_error(format!("{name}: expected {N} numbers, got {}", xs.len()))
                })?;
                if arr.iter().all(|x| x.is_finite()) {
                    Ok(arr)
                } else {
                    Err(value_error(format!("{name}: expected {N} finite numbers")))
                }
            })
            .transpose()
    }

    /// A 3×3 symmetric, finite matrix, kg m².
    pub fn matrix(&self, name: &str) -> PyResult<Option<Matrix3<f64>>> {
        self.take(name)?.map(|v| matrix_value(name, &v)).transpose()
    }

    /// No keyword left: an unknown one is a `TypeError`, as Python raises it.
    pub fn finish(self) -> PyResult<()> {
        if let Some((k, _)) = self.dict.iter().next() {
            return Err(type_error(format!(
                "{}() got an unexpected keyword argument {}",
                self.function,
                k.repr()?
            )));
        }
        Ok(())
    }
}

/// A 3×3 symmetric, finite matrix.
fn matrix_value(name: &str, v: &Bound<'_, PyAny>) -> PyResult<Matrix3<f64>> {
    let rows: Vec<Vec<f64>> = v.extract().map_err(|_| {
        type_error(format!(
            "{name}: expected a 3×3 matrix of numbers, got {}",
            type_name(v)
        ))
    })?;
    if rows.len() != 3 || rows.iter().any(|r| r.len() != 3) {
        return Err(value_error(format!("{name}: expected a 3×3 matrix")));
    }
    let m = Matrix3::from_fn(|r, c| rows[r][c]);
    if !m.iter().all(|x| x.is_finite()) {
        return Err(value_error(format!("{name}: has non-finite entries")));
    }
    if (m - m.transpose()).norm() > 1e-9 * m.norm() {
        return Err(value_error(format!("{name}: is not symmetric")));
    }
    Ok(m)
}

/// `prior_sigma`: `"5%"` (relative), a number (kg m², every element) or a 3×3 matrix
/// (kg m² per element).
enum PriorSigma {
    Relative(f64),
    Elements([f64; 6]),
}

fn prior_sigma(v: &Bound<'_, PyAny>) -> PyResult<PriorSigma> {
    let bad = |x: f64| value_error(format!("prior_sigma={}: must be finite and > 0", Num(x)));
    if let Ok(s) = v.extract::<String>() {
        // As the CLI's --prior-sigma: "5%" relative, "0.02" kg m² for every element.
        let t = s.trim();
        let parse = |x: &str| {
            x.trim().parse::<f64>().map_err(|_| {
                value_error(format!(
                    "prior_sigma={s:?}: expected a relative σ such as \"5%\", a number (kg m²) or a 3×3 matrix"
                ))
            })
        };
        let (x, out): (f64, fn(f64) -> PriorSigma) = match t.strip_suffix('%') {
            Some(p) => (parse(p)? / 100.0, PriorSigma::Relative),
            None => (parse(t)?, |x| PriorSigma::Elements([x; 6])),
        };
        return if x.is_finite() && x > 0.0 {
            Ok(out(x))
        } else {
            Err(bad(x))
        };
    }
    if let Ok(x) = v.extract::<f64>() {
        return if x.is_finite() && x > 0.0 {
            Ok(PriorSigma::Elements([x; 6]))
        } else {
            Err(bad(x))
        };
    }
    let m = matrix_value("prior_sigma", v)?;
    let j = inertia::tensor::j_from_matrix(&m);
    Ok(PriorSigma::Elements(core::array::from_fn(|k| j[k])))
}

pub fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type()
        .name()
        .map_or_else(|_| "an object".into(), |n| n.to_string())
}

/// `--scalar-first`, `--jpl`, `--conjugate`, `--gyro-unit`, `--unit-tolerance`,
/// `--period-tolerance`.
pub fn convention(kw: &Kwargs<'_>) -> PyResult<Convention> {
    let scalar_first = kw.bool("scalar_first", false)?;
    let jpl = kw.bool("jpl", false)?;
    let conjugate = kw.bool("conjugate", false)?;
    if usize::from(scalar_first) + usize::from(jpl) + usize::from(conjugate) > 1 {
        return Err(value_error(
            "scalar_first, jpl and conjugate: choose one (jpl and conjugate are scalar last; jpl has this library's numbers, conjugate maps inertial → body)",
        ));
    }
    let gyro_unit = match kw.string("gyro_unit")?.as_deref() {
        None | Some("rad/s") => GyroUnit::RadPerS,
        Some("deg/s") => GyroUnit::DegPerS,
        Some(other) => {
            return Err(value_error(format!(
                "gyro_unit={other:?}: expected \"rad/s\" or \"deg/s\""
            )))
        }
    };
    let mut c = Convention {
        format: if scalar_first {
            QuaternionFormat::HamiltonScalarFirst
        } else if jpl {
            QuaternionFormat::Jpl
        } else if conjugate {
            QuaternionFormat::Conjugate
        } else {
            QuaternionFormat::HamiltonScalarLast
        },
        gyro_unit,
        negate_rho: kw.bool("negate_rho", false)?,
        ..Convention::default()
    };
    for (name, slot) in [("unit_tolerance", 0), ("period_tolerance", 1)] {
        if let Some(v) = kw.f64(name)? {
            if !(v.is_finite() && v > 0.0) {
                return Err(value_error(format!(
                    "{name}={}: must be finite and > 0",
                    Num(v)
                )));
            }
            if slot == 0 {
                c.unit_tolerance = v;
            } else {
                c.period_tolerance = Some(v);
            }
        }
    }
    Ok(c)
}

/// An element bound: the element, its lower and upper bound (kg m²).
type ElementBound = (Component, Option<f64>, Option<f64>);

/// `Jij=LO:HI` (the command line's `--bound`; [`inertia::constraints::parse_bound`]).
fn parse_bound(s: &str) -> PyResult<ElementBound> {
    inertia::constraints::parse_bound(s).map_err(|why| {
        value_error(format!(
            "bounds {s:?}: {why} (expected e.g. J33=2.7:3.3, J12=:0.05)"
        ))
    })
}

/// `bounds`: a mapping `{"J33": (2.7, 3.3), "J12": (None, 0.05)}`, or strings in the
/// command line's form (`"J33=2.7:3.3"`, one or a sequence).
fn bounds(v: &Bound<'_, PyAny>) -> PyResult<Vec<ElementBound>> {
    if let Ok(s) = v.extract::<String>() {
        return Ok(vec![parse_bound(&s)?]);
    }
    if let Ok(d) = v.downcast::<PyDict>() {
        let mut out = Vec::new();
        for (k, range) in d.iter() {
            let name: String = k.extract().map_err(|_| {
                type_error(format!(
                    "bounds: keys must be element names (J11 … J23), got {}",
                    type_name(&k)
                ))
            })?;
            let c = Component::from_name(name.trim()).ok_or_else(|| {
                value_error(format!(
                    "bounds[{name:?}]: unknown element (J11, J22, J33, J12, J13, J23)"
                ))
            })?;
            let (lo, hi): (Option<f64>, Option<f64>) = range.extract().map_err(|_| {
                type_error(format!(
                    "bounds[{name:?}]: expected (low, high), kg m², either may be None"
                ))
            })?;
            for x in [lo, hi].into_iter().flatten() {
                if !x.is_finite() {
                    return Err(value_error(format!(
                        "bounds[{name:?}]: {} is not finite",
                        Num(x)
                    )));
                }
            }
            if lo.is_none() && hi.is_none() {
                return Err(value_error(format!("bounds[{name:?}]: no bound given")));
            }
            out.push((c, lo, hi));
        }
        return Ok(out);
    }
    let items: Vec<String> = v.extract().map_err(|_| {
        type_error(format!(
            "bounds: expected a dict {{\"J33\": (2.7, 3.3)}} or strings like \"J33=2.7:3.3\", got {}",
            type_name(v)
        ))
    })?;
    items.iter().map(|s| parse_bound(s)).collect()
}

/// `--tolerance`: `0.1` or `"10%"`.
fn fraction(v: &Bound<'_, PyAny>) -> PyResult<f64> {
    let x = if let Ok(s) = v.extract::<String>() {
        let t = s.trim();
        match t.strip_suffix('%') {
            Some(p) => p.trim().parse::<f64>().map(|v| v / 100.0),
            None => t.parse::<f64>(),
        }
        .map_err(|_| value_error(format!("tolerance={s:?}: expected e.g. \"10%\" or 0.1")))?
    } else {
        v.extract::<f64>().map_err(|_| {
            type_error(format!(
                "tolerance: expected a number or \"10%\", got {}",
                type_name(v)
            ))
        })?
    };
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        Err(value_error(format!(
            "tolerance={}: must be finite and >= 0",
            Num(x)
        )))
    }
}

/// The pipeline settings of the keyword arguments (the command line's defaults).
pub fn pipeline(kw: &Kwargs<'_>) -> PyResult<PipelineSettings> {
    let estimator = kw
        .string("estimator")?
        .unwrap_or_else(|| DEFAULT_ESTIMATOR.into());
    let solver = kw.string("solver")?.unwrap_or_else(|| "native".into());
    let mut constraints = match kw
        .choice("constraints", &["physical", "paper", "positive-definite"])?
        .unwrap_or("physical")
    {
        "paper" => ConstraintSet::paper(),
        "positive-definite" => ConstraintSet::positive_definite(),
        _ => ConstraintSet::physical(),
    };
    let products = match kw.choice("products", &["tensor", "cad"])? {
        Some("cad") => ProductConvention::Cad,
        _ => ProductConvention::Tensor,
    };
    let nominal = kw.matrix("nominal")?.map(|m| products.matrix_to_tensor(&m));
    let tolerance = kw.take("tolerance")?.map(|v| fraction(&v)).transpose()?;
    match (nominal, tolerance) {
        (Some(n), Some(p)) => constraints = constraints.with_nominal_inertia(&n, p),
        (None, None) => {}
        (Some(_), None) => {
            return Err(value_error(
                "nominal: needs tolerance (e.g. tolerance=\"10%\")",
            ))
        }
        (None, Some(_)) => {
            return Err(value_error(
                "tolerance: needs nominal (a 3×3 inertia, kg m²)",
            ))
        }
    }
    if let Some(b) = kw.take("bounds")? {
        for (k, l, h) in bounds(&b)? {
            let (l, h) = products.bound_to_tensor(k, l, h);
            constraints = constraints.with_bounds(k, l, h);
        }
    }
    if kw.bool("diagonal", false)? {
        constraints = constraints.diagonal();
    }
    let sigma = kw
        .take("prior_sigma")?
        .map(|v| prior_sigma(&v))
        .transpose()?;
    match (
        kw.matrix("prior")?.map(|m| products.matrix_to_tensor(&m)),
        sigma,
    ) {
        (Some(m), Some(PriorSigma::Relative(f))) => {
            constraints = constraints.with_relative_prior(&m, f);
        }
        (Some(m), Some(PriorSigma::Elements(s))) => constraints = constraints.with_prior(&m, s),
        (None, None) => {}
        (Some(_), None) => {
            return Err(value_error(
                "prior: needs prior_sigma (e.g. prior_sigma=\"5%\")",
            ))
        }
        (None, Some(_)) => {
            return Err(value_error(
                "prior_sigma: needs prior (a 3×3 inertia, kg m²)",
            ))
        }
    }
    let every = kw.usize("every", 1)?;
    let chain = kw.f64("chain")?.unwrap_or(DEFAULT_MAX_CHAIN_S);
    Ok(PipelineSettings {
        estimator,
        solver,
        constraints,
        solve_every: every,
        memory_s: kw.f64("memory")?,
        resample_s: kw.f64("resample")?,
        gyro_noise_deg_s_rthz: kw.f64("gyro_noise")?,
        attitude_drift_deg_rth: kw.f64("attitude_drift")?,
        uncertainty: kw.bool("uncertainty", true)?,
        rotation_source: kw
            .choice("rotation_source", &["attitude", "gyro"])?
            .map(|r| {
                if r == "gyro" {
                    RotationSource::Gyro
                } else {
                    RotationSource::Attitude
                }
            }),
        rho_model: match kw.choice("rho_model", &["auto", "smooth", "held", "plain"])? {
            Some("smooth") => RhoModel::Smooth,
            Some("held") => RhoModel::Held,
            Some("plain") => RhoModel::Plain,
            _ => RhoModel::Auto,
        },
        torque_bias: kw.bool("torque_bias", true)?,
        rotor_scale_sigma: kw.f64("rotor_scale_sigma")?,
        filter_cutoff_hz: kw.f64("filter_cutoff_hz")?,
        inertial_torque: match kw.choice("inertial_torque", <InertialTorque as inertia::choice::Choice>::NAMES)? {
            Some(name) => name
                .parse()
                .map_err(|e: PipelineError| value_error(e.to_string()))?,
            None => InertialTorque::default(),
        },
        wheel_delay: match kw.text_or_number("wheel_delay")? {
            Some(t) => inertia::pipeline::parse_wheel_delay(&t)
                .map_err(|e: PipelineError| value_error(e.to_string()))?,
            None => Default::default(),
        },
        max_chain_s: (chain != 0.0).then_some(chain),
        glitches: match kw.choice("glitches", &["stop", "keep"])? {
            Some("keep") => GlitchPolicy::Keep,
            _ => GlitchPolicy::Stop,
        },
        ..PipelineSettings::default()
    })
}

/// Everything `estimate` takes besides the data.
pub fn run(kw: &Kwargs<'_>) -> PyResult<RunSettings> {
    Ok(RunSettings {
        pipeline: pipeline(kw)?,
        batch: kw.bool("batch", false)?,
        history: kw.bool("history", false)?,
        truth: kw.matrix("truth")?,
    })
}

/// The keyword argument behind a pipeline setting.
fn argument_of(field: &str) -> &str {
    match field {
        "solve_every" => "every",
        "memory_s" => "memory",
        "resample_s" => "resample",
        "gyro_noise_deg_s_rthz" => "gyro_noise",
        "attitude_drift_deg_rth" => "attitude_drift",
        "constraints" => "constraints/bounds/nominal",
        "max_chain_s" => "chain",
        other => other,
    }
}

/// A settings error in the keyword arguments' words (`ValueError`).
pub fn settings_error(e: PipelineError) -> PyErr {
    match e {
        PipelineError::InvalidSetting {
            field,
            value,
            expected,
        } => value_error(format!(
            "{}={}: expected {expected}",
            argument_of(field),
            Num(value)
        )),
        PipelineError::NotApplicable { setting, estimator } => value_error(format!(
            "{} does not apply to the {estimator} estimator",
            argument_of(setting)
        )),
        PipelineError::NeedsSetting {
            setting,
            needs,
            requirement,
            why,
        } => value_error(format!(
            "{} needs {} {requirement}: {why}",
            argument_of(setting),
            argument_of(needs)
        )),
        PipelineError::UnknownEstimator { .. } => value_error(format!("estimator: {e}")),
        PipelineError::UnknownSolver { .. } | PipelineError::SolverUnavailable { .. } => {
            value_error(format!("solver: {e}"))
        }
        other => value_error(other.to_string()),
    }
}
