//! Arguments into the library's run description ([`RunDescription`]: a run file's, the
//! options given over it), and from it the library's settings, the options' names in
//! messages.

use crate::args::EstimateArgs;
use crate::error::{input, read_failed, CliError};
use inertia::constraints::ProductConvention;
use inertia::pipeline::{PipelineError, PipelineSettings};
use inertia::run_description::{Bounds, ElementBound, InertiaInput, RunDescription};
use inertia::telemetry::csv::CsvOptions;
use inertia::tensor::j_from_matrix;
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
        Ok(Self::read_known(path, Some(ProductConvention::Tensor), "--truth")?.inertia_kg_m2)
    }

    /// Read and check a prior-knowledge file, converting its products to tensor entries:
    /// `option` is the `--products` given on the command line (it must agree with the
    /// file's `products_of_inertia` when both are given).
    pub fn read_known(
        path: &Path,
        option: Option<ProductConvention>,
        what: &str,
    ) -> Result<KnownInertia, CliError> {
        let f = Self::parse(path)?;
        let from_file = match f.products_of_inertia.as_deref() {
            None => None,
            Some("tensor") => Some(ProductConvention::Tensor),
            Some("cad") => Some(ProductConvention::Cad),
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
                    inertia::choice::Choice::choice_name(b)
                )))
            }
            (Some(a), _) => a,
            (None, Some(b)) => b,
            (None, None) => ProductConvention::Tensor,
        };
        let m = convention.matrix_to_tensor(&Matrix3::from_fn(|r, k| f.inertia_kg_m2[r][k]));
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

/// `Jij=LO:HI` given to `--bound` ([`inertia::constraints::parse_bound`]).
fn parse_bound(s: &str) -> Result<ElementBound, CliError> {
    inertia::constraints::parse_bound(s).map_err(|why| {
        input(format!(
            "--bound {s:?}: {why} (expected e.g. J33=2.7:3.3, J12=:0.05)"
        ))
    })
}

/// An option's text parsed as the library's value (`10%`, `5%`).
fn parsed<T: std::str::FromStr<Err = &'static str>>(
    option: &str,
    s: Option<&str>,
) -> Result<Option<T>, CliError> {
    s.map(|s| {
        s.parse()
            .map_err(|why| input(format!("{option} {s:?}: {why}")))
    })
    .transpose()
}

/// The run described: the `--settings` file's, the options given on the command line
/// over it.
pub fn description(a: &EstimateArgs) -> Result<RunDescription, CliError> {
    let file = a
        .settings
        .as_deref()
        .map(|p| RunDescription::load(p).map_err(|e| input(e.to_string())))
        .transpose()?
        .unwrap_or_default();
    let i = &a.input;
    let mut options = RunDescription::default();
    options.estimator = a.estimator.clone();
    options.solver = a.solver.clone();
    options.batch = a.batch.then_some(true);
    options.constraints = a.constraints;
    options.bounds = (!a.bounds.is_empty())
        .then(|| a.bounds.iter().map(|b| parse_bound(b)).collect())
        .transpose()?
        .map(Bounds);
    options.nominal = a.nominal.clone().map(InertiaInput::File);
    options.tolerance = parsed("--tolerance", a.tolerance.as_deref())?;
    options.diagonal = a.diagonal.then_some(true);
    options.prior = a.prior.clone().map(InertiaInput::File);
    options.prior_sigma = parsed("--prior-sigma", a.prior_sigma.as_deref())?;
    options.products = a.products;
    options.rotor_scale_sigma = parsed("--rotor-scale-sigma", a.rotor_scale_sigma.as_deref())?;
    options.torque_scale_sigma = parsed("--torque-scale-sigma", a.torque_scale_sigma.as_deref())?;
    options.filter_cutoff_hz = a.filter_cutoff_hz;
    options.every = a.every;
    options.memory = a.memory;
    options.resample = a.resample;
    options.gyro_noise = a.gyro_noise;
    options.attitude_drift = a.attitude_drift;
    options.rotation_source = a.rotation_source;
    options.rho_model = a.rho_model;
    options.glitches = a.glitches;
    options.torque_bias = a.no_torque_bias.then_some(false);
    options.inertial_torque = a.inertial_torque;
    options.damping = a.damping.then_some(true);
    options.calibrate_rotors = a.calibrate_rotors.then_some(true);
    options.outside = (a.no_gravity_gradient
        || a.gravity_mu.is_some()
        || a.no_residual_dipole
        || a.no_centre_of_mass)
        .then(|| {
            let d = inertia::estimator::momentum_rows::OutsideTorques::default();
            inertia::estimator::momentum_rows::OutsideTorques {
                gravity_gradient: !a.no_gravity_gradient,
                gravity_mu_m3_s2: a.gravity_mu.unwrap_or(d.gravity_mu_m3_s2),
                residual_dipole: !a.no_residual_dipole,
                centre_of_mass: !a.no_centre_of_mass,
            }
        });
    options.wheel_delay = a
        .wheel_delay
        .as_deref()
        .map(inertia::pipeline::parse_wheel_delay)
        .transpose()
        .map_err(settings_error)?;
    options.chain = a.chain;
    options.scalar_first = i.scalar_first.then_some(true);
    options.jpl = i.jpl.then_some(true);
    options.conjugate = i.conjugate.then_some(true);
    options.gyro_unit = i.gyro_unit;
    options.negate_rho = i.negate_rho.then_some(true);
    options.unit_tolerance = i.unit_tolerance;
    options.period_tolerance = i.period_tolerance;
    options.spacecraft = i.spacecraft.clone();
    options.columns = (!i.columns.is_empty())
        .then(|| {
            i.columns
                .iter()
                .map(|c| {
                    c.split_once('=')
                        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
                        .ok_or_else(|| {
                            input(format!(
                                "--column {c:?}: expected DEFAULT=NAME, e.g. t=time"
                            ))
                        })
                })
                .collect()
        })
        .transpose()?;
    Ok(file.overridden_by(options))
}

/// A run description's key as the command line names it: its option.
pub fn option(key: &str) -> String {
    match key {
        "bounds" => "--bound".into(),
        "columns" => "--column".into(),
        "torque_bias" => "--no-torque-bias".into(),
        "constraints" => "--constraints/--bound/--nominal/--diagonal/--prior".into(),
        // A run file's key without an option of its own.
        "uncertainty" => "uncertainty".into(),
        k => format!("--{}", k.replace('_', "-")),
    }
}

/// The pipeline settings of the run described (the `--nominal`/`--prior` files read
/// here, in the `--products` convention).
pub fn pipeline_settings(d: &RunDescription) -> Result<PipelineSettings, CliError> {
    let mut read = |path: &Path, products: Option<ProductConvention>| {
        InertiaFile::read_known(path, products, "--products")
            .map(|k| (k.inertia_kg_m2, k.sigma_kg_m2))
            .map_err(|e| e.to_string())
    };
    d.pipeline_settings(&option, &mut read)
        .map_err(|e| input(e.message))
}

/// A settings error in the command line's words.
pub fn settings_error(e: PipelineError) -> CliError {
    let name = |field: &str| option(RunDescription::key_of(field));
    match e {
        PipelineError::InvalidSetting {
            field,
            value,
            expected,
        } => input(format!(
            "{} {}: expected {expected}",
            name(field),
            inertia::text::Num(value)
        )),
        PipelineError::NotApplicable { setting, estimator } => input(format!(
            "{} does not apply to the {estimator} estimator",
            name(setting)
        )),
        PipelineError::NeedsSetting {
            setting,
            needs,
            requirement,
            why,
        } => input(format!(
            "{} needs {} {requirement}: {why}",
            name(setting),
            name(needs)
        )),
        other => input(other),
    }
}

/// The spacecraft file of the run described, if any.
pub fn spacecraft(d: &RunDescription) -> Result<Option<inertia::spacecraft::Spacecraft>, CliError> {
    d.spacecraft
        .as_deref()
        .map(|p| inertia::spacecraft::Spacecraft::load(p).map_err(|e| input(e.to_string())))
        .transpose()
}

/// CSV options of the run described (and the speed columns of its spacecraft file).
pub fn csv_options(
    d: &RunDescription,
    spacecraft: Option<&inertia::spacecraft::Spacecraft>,
) -> Result<CsvOptions, CliError> {
    let mut o = d.csv_options(&option).map_err(|e| input(e.message))?;
    o.speed_columns = spacecraft.map_or_else(Vec::new, |s| s.speed_columns());
    o.thruster_columns = spacecraft.map_or_else(Vec::new, |s| s.thruster_columns());
    Ok(o)
}
