//! Arguments validated into configurations.

use crate::args::{
    ConstraintArg, EstimateArgs, GlitchArg, InputArgs, ProductsArg, RhoModelArg, RotationArg,
};
use crate::error::{input, read_failed, CliError};
use inertia::constraints::{ConstraintSet, ProductConvention};
use inertia::estimator::momentum_rows::{RhoModel, RotationSource};
use inertia::pipeline::{PipelineError, PipelineSettings};
use inertia::telemetry::csv::{ColumnNames, CsvOptions, QuaternionFormat};
use inertia::telemetry::glitch::GlitchPolicy;
use inertia::tensor::{j_from_matrix, Component};
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// An inertia tensor file (`FILE.truth.json`, `--nominal`, `--truth`, `--prior`).
#[derive(Debug, Serialize, Deserialize)]
pub struct InertiaFile {
    /// J, kg m², rows of the 3×3 matrix.
    pub inertia_kg_m2: [[f64; 3]; 3],
    /// `[J11, J22, J33, J12, J13, J23]`, kg m² (written for convenience; ignored on input).
    #[serde(default, skip_deserializing)]
    pub j: Option<[f64; 6]>,
    /// Standard deviation of each element, kg m², as a symmetric 3×3 matrix (`--prior`
    /// only; optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_kg_m2: Option<[[f64; 3]; 3]>,
    /// How the off-diagonal entries are written: `"tensor"` (J12 = −Σ m x y, the
    /// default) or `"cad"` (+Σ m x y).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub products_of_inertia: Option<String>,
}

/// A prior-knowledge file as read: J (and σ) in tensor entries.
#[derive(Debug, Clone, Copy)]
pub struct KnownInertia {
    /// J, kg m², tensor entries.
    pub inertia_kg_m2: Matrix3<f64>,
    /// σ per element, kg m², when the file gives it.
    pub sigma_kg_m2: Option<[f64; 6]>,
}

impl InertiaFile {
    /// From a matrix.
    pub fn new(j: &Matrix3<f64>) -> Self {
        let v = j_from_matrix(j);
        Self {
            inertia_kg_m2: [0, 1, 2].map(|r| [0, 1, 2].map(|c| j[(r, c)])),
            j: Some([0, 1, 2, 3, 4, 5].map(|k| v[k])),
            sigma_kg_m2: None,
            products_of_inertia: None,
        }
    }

    /// Read and check a file of J in tensor entries (a `products_of_inertia` other than
    /// `"tensor"` is an error: simulation truth and `--truth` are always tensors).
    pub fn read(path: &Path) -> Result<Matrix3<f64>, CliError> {
        Ok(Self::read_known(path, Some(ProductsArg::Tensor), "--truth")?.inertia_kg_m2)
    }

    /// Read and check a prior-knowledge file, converting its products to tensor entries:
    /// `option` is the `--products` given on the command line (it must agree with the
    /// file's `products_of_inertia` when both are given).
    pub fn read_known(
        path: &Path,
        option: Option<ProductsArg>,
        what: &str,
    ) -> Result<KnownInertia, CliError> {
        let f = Self::parse(path)?;
        let from_file = match f.products_of_inertia.as_deref() {
            None => None,
            Some("tensor") => Some(ProductsArg::Tensor),
            Some("cad") => Some(ProductsArg::Cad),
            Some(other) => {
                return Err(input(format!(
                    "{}: products_of_inertia {other:?}: expected \"tensor\" (J12 = −Σ m x y) or \"cad\" (+Σ m x y)",
                    path.display()
                )))
            }
        };
        let convention = match (from_file, option) {
            (Some(a), Some(b)) if a != b => {
                return Err(input(format!(
                    "{}: products_of_inertia is {:?} but {what} asks for {}",
                    path.display(),
                    f.products_of_inertia.as_deref().unwrap_or_default(),
                    match b {
                        ProductsArg::Tensor => "tensor",
                        ProductsArg::Cad => "cad",
                    }
                )))
            }
            (Some(a), _) => a,
            (None, Some(b)) => b,
            (None, None) => ProductsArg::Tensor,
        };
        let m = product_convention(Some(convention))
            .matrix_to_tensor(&Matrix3::from_fn(|r, k| f.inertia_kg_m2[r][k]));
        check_matrix(path, "inertia_kg_m2", &m)?;
        let sigma_kg_m2 = match f.sigma_kg_m2 {
            Some(s) => {
                // σ is a magnitude: its sign does not depend on the convention.
                let s = Matrix3::from_fn(|r, k| s[r][k]);
                check_matrix(path, "sigma_kg_m2", &s)?;
                let v = j_from_matrix(&s);
                Some([0, 1, 2, 3, 4, 5].map(|k| v[k]))
            }
            None => None,
        };
        Ok(KnownInertia {
            inertia_kg_m2: m,
            sigma_kg_m2,
        })
    }

    fn parse(path: &Path) -> Result<Self, CliError> {
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
        serde_json::from_str(&text).map_err(|e| {
            input(format!(
                "{}:{}:{}: {e} (expected {{\"inertia_kg_m2\": [[..],[..],[..]]}})",
                path.display(),
                e.line(),
                e.column()
            ))
        })
    }
}

fn check_matrix(path: &Path, field: &str, m: &Matrix3<f64>) -> Result<(), CliError> {
    if !m.iter().all(|v| v.is_finite()) {
        return Err(input(format!(
            "{}: {field} has non-finite entries",
            path.display()
        )));
    }
    if (m - m.transpose()).norm() > 1e-9 * m.norm() {
        return Err(input(format!(
            "{}: {field} is not symmetric",
            path.display()
        )));
    }
    Ok(())
}

/// The library's convention of a `--products` option (`None`: tensor entries).
pub fn product_convention(a: Option<ProductsArg>) -> ProductConvention {
    match a {
        Some(ProductsArg::Cad) => ProductConvention::Cad,
        Some(ProductsArg::Tensor) | None => ProductConvention::Tensor,
    }
}

/// Parse `Jij=LO:HI` into `(component, lower, upper)` ([`inertia::constraints::parse_bound`]).
pub fn parse_bound(s: &str) -> Result<(Component, Option<f64>, Option<f64>), CliError> {
    inertia::constraints::parse_bound(s).map_err(|why| {
        input(format!(
            "--bound {s:?}: {why} (expected e.g. J33=2.7:3.3, J12=:0.05)"
        ))
    })
}

/// Parse `10%` or `0.1` given to `option`.
pub fn parse_fraction(option: &str, s: &str) -> Result<f64, CliError> {
    let t = s.trim();
    let v = match t.strip_suffix('%') {
        Some(p) => p.trim().parse::<f64>().map(|v| v / 100.0),
        None => t.parse::<f64>(),
    }
    .map_err(|_| input(format!("{option} {s:?}: expected e.g. 10% or 0.1")))?;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(input(format!("{option} {s:?}: must be finite and >= 0")))
    }
}

/// The constraint set of the arguments (validated with the rest of the settings).
pub fn constraint_set(
    kind: ConstraintArg,
    bounds: &[String],
    nominal: Option<(&Matrix3<f64>, f64)>,
    products: ProductConvention,
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
        let (l, h) = products.bound_to_tensor(k, l, h);
        set = set.with_bounds(k, l, h);
    }
    Ok(set)
}

/// Parse `--prior-sigma`: `5%` (relative) or `0.02` (kg m², every element).
pub fn parse_prior_sigma(s: &str) -> Result<PriorSigma, CliError> {
    let t = s.trim();
    let bad = || {
        input(format!(
            "--prior-sigma {s:?}: expected a relative σ such as 5% or an absolute one in kg m² such as 0.02, finite and > 0"
        ))
    };
    let out = match t.strip_suffix('%') {
        Some(p) => PriorSigma::Relative(p.trim().parse::<f64>().map_err(|_| bad())? / 100.0),
        None => PriorSigma::Absolute(t.parse::<f64>().map_err(|_| bad())?),
    };
    match out {
        PriorSigma::Relative(v) | PriorSigma::Absolute(v) if v.is_finite() && v > 0.0 => Ok(out),
        _ => Err(bad()),
    }
}

/// A `--prior-sigma`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PriorSigma {
    /// A fraction (moments of |J_ii|, products of √(J_ii J_jj)).
    Relative(f64),
    /// kg m², every element.
    Absolute(f64),
}

/// The pipeline settings of `inertia estimate`.
pub fn pipeline_settings(a: &EstimateArgs) -> Result<PipelineSettings, CliError> {
    let nominal = match (&a.nominal, &a.tolerance) {
        (Some(p), Some(t)) => Some((
            InertiaFile::read_known(p, a.products, "--products")?.inertia_kg_m2,
            parse_fraction("--tolerance", t)?,
        )),
        _ => None,
    };
    let mut constraints = constraint_set(
        a.constraints,
        &a.bounds,
        nominal.as_ref().map(|(m, p)| (m, *p)),
        product_convention(a.products),
    )?;
    if a.diagonal {
        constraints = constraints.diagonal();
    }
    if let Some(path) = &a.prior {
        let known = InertiaFile::read_known(path, a.products, "--products")?;
        let sigma = a
            .prior_sigma
            .as_deref()
            .map(parse_prior_sigma)
            .transpose()?;
        constraints = match (sigma, known.sigma_kg_m2) {
            (Some(PriorSigma::Relative(f)), _) => {
                constraints.with_relative_prior(&known.inertia_kg_m2, f)
            }
            (Some(PriorSigma::Absolute(v)), _) => {
                constraints.with_prior(&known.inertia_kg_m2, [v; 6])
            }
            (None, Some(s)) => constraints.with_prior(&known.inertia_kg_m2, s),
            (None, None) => {
                return Err(input(format!(
                    "{}: the prior needs a standard deviation: --prior-sigma (e.g. 5%) or sigma_kg_m2 in the file",
                    path.display()
                )))
            }
        };
    }
    Ok(PipelineSettings {
        estimator: a.estimator.clone(),
        solver: a.solver.clone(),
        constraints,
        solve_every: a.every,
        memory_s: a.memory,
        resample_s: a.resample,
        gyro_noise_deg_s_rthz: a.gyro_noise,
        attitude_drift_deg_rth: a.attitude_drift,
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
        inertial_torque: a.inertial_torque.parse().map_err(settings_error)?,
        damping: a.damping,
        wheel_delay: inertia::pipeline::parse_wheel_delay(&a.wheel_delay)
            .map_err(settings_error)?,
        rotor_scale_sigma: a
            .rotor_scale_sigma
            .as_deref()
            .map(|s| parse_fraction("--rotor-scale-sigma", s))
            .transpose()?,
        filter_cutoff_hz: a.filter_cutoff_hz,
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
        "constraints" => "--constraints/--bound/--nominal/--diagonal/--prior",
        "rotation_source" => "--rotation-source",
        "rho_model" => "--rho-model",
        "torque_bias" => "--no-torque-bias",
        "inertial_torque" => "--inertial-torque",
        "damping" => "--damping",
        "wheel_delay" => "--wheel-delay",
        "rotor_scale_sigma" => "--rotor-scale-sigma",
        "filter_cutoff_hz" => "--filter-cutoff-hz",
        "max_chain_s" => "--chain",
        "attitude_drift_deg_rth" => "--attitude-drift",
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
        PipelineError::NeedsSetting {
            setting,
            needs,
            requirement,
            why,
        } => input(format!(
            "{} needs {} {requirement}: {why}",
            option_of(setting),
            option_of(needs)
        )),
        other => input(other),
    }
}

/// The spacecraft file of the input arguments, if any.
pub fn spacecraft(a: &InputArgs) -> Result<Option<inertia::spacecraft::Spacecraft>, CliError> {
    a.spacecraft
        .as_deref()
        .map(|p| inertia::spacecraft::Spacecraft::load(p).map_err(|e| input(e.to_string())))
        .transpose()
}

/// CSV options from the input arguments (and the speed columns of their spacecraft
/// file).
pub fn csv_options(
    a: &InputArgs,
    spacecraft: Option<&inertia::spacecraft::Spacecraft>,
) -> Result<CsvOptions, CliError> {
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
        } else if a.conjugate {
            QuaternionFormat::Conjugate
        } else {
            QuaternionFormat::HamiltonScalarLast
        },
        columns,
        unit_tolerance: a.unit_tolerance,
        period_tolerance: a.period_tolerance,
        delimiter: b',',
        negate_rho: a.negate_rho,
        gyro_unit: if a.gyro_unit == "deg/s" {
            inertia::telemetry::csv::GyroUnit::DegPerS
        } else {
            inertia::telemetry::csv::GyroUnit::RadPerS
        },
        speed_columns: spacecraft.map_or_else(Vec::new, |s| s.speed_columns()),
    })
}
