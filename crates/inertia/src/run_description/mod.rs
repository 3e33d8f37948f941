//! A run described in its users' words: the settings of an estimation run and the input
//! conventions of its telemetry, by the names of the command line's long options and
//! Python's keywords (`memory`, `every`, `chain`, `rho_model`, `scalar_first`, …), each
//! optional.
//!
//! A [`RunDescription`] deserialises (serde, unknown keys refused) from a run file, TOML
//! or JSON ([`RunDescription::load`], errors naming the file, the line and the key), and
//! from Python's keyword arguments; the command line builds one from the options given.
//! [`RunDescription::overridden_by`] lays one over another (explicit options over a
//! file), and [`RunDescription::pipeline_settings`] and [`RunDescription::csv_options`]
//! turn it into the library's [`PipelineSettings`] and [`crate::telemetry::csv::CsvOptions`] with their
//! documented defaults for what it leaves out. Validation stays with
//! [`PipelineSettings::validate`]: a description only feeds the same settings.
//!
//! ```toml
//! estimator = "discrete-momentum"
//! memory = 120.0          # s
//! rho_model = "held"
//! bounds = ["J33=2.7:3.3"]
//! gyro_unit = "deg/s"
//! ```

mod file;
pub use file::RunFileError;
mod values;

pub use values::{Bounds, ElementBound, Fraction, InertiaInput, PriorSigma};

use crate::constraints::{Consistency, ConstraintSet, ProductConvention};
use crate::estimator::momentum_rows::{OutsideTorques, RhoModel, RotationSource};
use crate::estimator::wheel_delay::WheelDelay;
use crate::pipeline::{InertialTorque, PipelineSettings, DEFAULT_MAX_CHAIN_S};
use crate::telemetry::gate::{GyroUnit, QuaternionFormat};
use crate::telemetry::glitch::GlitchPolicy;
use nalgebra::Matrix3;
use std::collections::BTreeMap;
use std::format;
use std::path::{Path, PathBuf};
use std::string::String;
use std::vec::Vec;

macro_rules! description {
    (
        settings { $( $(#[$sm:meta])* $s:ident : $st:ty, )* }
        input { $( $(#[$im:meta])* $i:ident : $it:ty, )* }
    ) => {
        /// A run in its users' words ([module docs](self)): every field optional, `None`
        /// for the default.
        #[derive(Debug, Clone, Default, PartialEq, serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        #[non_exhaustive]
        pub struct RunDescription {
            $( $(#[$sm])* pub $s: Option<$st>, )*
            $( $(#[$im])* pub $i: Option<$it>, )*
        }

        impl RunDescription {
            /// The keys of the run's settings.
            pub const SETTINGS_KEYS: &'static [&'static str] = &[$(stringify!($s)),*];
            /// The keys of the telemetry's input conventions.
            pub const INPUT_KEYS: &'static [&'static str] = &[$(stringify!($i)),*];

            /// This description with `over`'s values where `over` gives one (command-line
            /// options over a run file).
            #[must_use]
            pub fn overridden_by(self, over: Self) -> Self {
                Self {
                    $( $s: over.$s.or(self.$s), )*
                    $( $i: over.$i.or(self.$i), )*
                }
            }

            /// The keys given a value, in the order of [`Self::SETTINGS_KEYS`] then
            /// [`Self::INPUT_KEYS`].
            #[must_use]
            pub fn given(&self) -> Vec<&'static str> {
                let mut out = Vec::new();
                $( if self.$s.is_some() { out.push(stringify!($s)); } )*
                $( if self.$i.is_some() { out.push(stringify!($i)); } )*
                out
            }
        }
    };
}

description! {
    settings {
        /// Estimator, by its registered name (`--estimator`).
        estimator: String,
        /// Solver backend, by its registered name (`--solver`).
        solver: String,
        /// One batch solve over all samples (`--batch`).
        batch: bool,
        /// The constraint set (`--constraints`).
        constraints: Consistency,
        /// Element bounds (`--bound`).
        bounds: Bounds,
        /// A nominal inertia bounding every element (`--nominal`, with `tolerance`).
        nominal: InertiaInput,
        /// The nominal's tolerance (`--tolerance`).
        tolerance: Fraction,
        /// Every product of inertia fixed at zero (`--diagonal`).
        diagonal: bool,
        /// A Gaussian prior's mean (`--prior`, with `prior_sigma` or a file's σ).
        prior: InertiaInput,
        /// The prior's σ (`--prior-sigma`).
        prior_sigma: PriorSigma,
        /// How products of inertia are written in `nominal`, `prior` and `bounds`
        /// (`--products`).
        products: ProductConvention,
        /// Relative σ of the rotor momentum's scale (`--rotor-scale-sigma`).
        rotor_scale_sigma: Fraction,
        /// Relative σ of the known torque's scale (`--torque-scale-sigma`).
        torque_scale_sigma: Fraction,
        /// The equation-error baseline's cutoff, Hz (`--filter-cutoff-hz`).
        filter_cutoff_hz: f64,
        /// Solve every this many samples (`--every`).
        every: usize,
        /// Memory time constant, s (`--memory`).
        memory: f64,
        /// Resampling period, s (`--resample`).
        resample: f64,
        /// Gyro rate-noise density, deg/s/√Hz (`--gyro-noise`).
        gyro_noise: f64,
        /// Angle random walk of the attitude, deg/√h (`--attitude-drift`).
        attitude_drift: f64,
        /// σ attached to each estimate (default true).
        uncertainty: bool,
        /// Source of the incremental rotations (`--rotation-source`).
        rotation_source: RotationSource,
        /// Model of the rotor momentum between samples (`--rho-model`).
        rho_model: RhoModel,
        /// Attitude glitches: stop or keep (`--glitches`).
        glitches: GlitchPolicy,
        /// Estimate a constant body torque (default true; `--no-torque-bias`).
        torque_bias: bool,
        /// An inertial-frame torque per chain (`--inertial-torque`).
        inertial_torque: InertialTorque,
        /// A linear damping torque −D ω as an unknown (`--damping`).
        damping: bool,
        /// The rotors' spin-inertia scale and axis tilts estimated with J, their priors
        /// from the spacecraft file (batch runs; `--calibrate-rotors`).
        calibrate_rotors: bool,
        /// The torques of outside measurements modelled (a table: `gravity_gradient`,
        /// `gravity_mu_m3_s2`, `residual_dipole`, `centre_of_mass`; `--no-gravity-gradient`,
        /// `--gravity-mu`, `--no-residual-dipole`, `--no-centre-of-mass`).
        outside: OutsideTorques,
        /// The wheel-speed time tag (`--wheel-delay`).
        #[serde(default, deserialize_with = "values::wheel_delay")]
        wheel_delay: WheelDelay,
        /// Short momentum chain, s; 0 for chains that end only at gaps (`--chain`).
        chain: f64,
    }
    input {
        /// Quaternion columns scalar first (`--scalar-first`).
        scalar_first: bool,
        /// JPL/Shuster quaternions (`--jpl`).
        jpl: bool,
        /// Hamilton quaternions inertial → body (`--conjugate`).
        conjugate: bool,
        /// The unit of the gyro columns (`--gyro-unit`).
        gyro_unit: GyroUnit,
        /// The rho columns hold the momentum with the opposite sign (`--negate-rho`).
        negate_rho: bool,
        /// Largest `| |q| − 1 |` renormalised (`--unit-tolerance`).
        unit_tolerance: f64,
        /// Strict sampling: the relative tolerance on the period (`--period-tolerance`).
        period_tolerance: f64,
        /// A spacecraft file (`--spacecraft`).
        spacecraft: PathBuf,
        /// Column renames, default name → name in the file (`--column`).
        columns: BTreeMap<String, String>,
    }
}

/// A description that does not make settings: the key at fault and the message, in the
/// words of the front end that named the keys.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct SettingError {
    /// The key at fault.
    pub key: &'static str,
    /// What is wrong, the keys named by the front end.
    pub message: String,
}

/// An inertia: J in tensor entries, kg m², and the σ per element its file gives, if any.
type ReadInertia = (Matrix3<f64>, Option<[f64; 6]>);

/// How a front end reads an inertia file given as `nominal` or `prior`, in the `products`
/// convention asked for (a file may carry its own): J in tensor entries, kg m², and the
/// σ per element the file gives, if any; or why not.
pub(crate) type ReadInertiaFile<'a> = dyn FnMut(&Path, Option<ProductConvention>) -> Result<(Matrix3<f64>, Option<[f64; 6]>), String>
    + 'a;

fn error(key: &'static str, message: String) -> SettingError {
    SettingError { key, message }
}

impl RunDescription {
    /// The key that sets a [`PipelineSettings`] field, as a
    /// [`crate::pipeline::PipelineError`] names it (`memory_s` is `memory`, `max_chain_s`
    /// is `chain`); any other name as it is.
    #[must_use]
    pub fn key_of(field: &str) -> &str {
        match field {
            "solve_every" => "every",
            "memory_s" => "memory",
            "resample_s" => "resample",
            "gyro_noise_deg_s_rthz" => "gyro_noise",
            "attitude_drift_deg_rth" => "attitude_drift",
            "max_chain_s" => "chain",
            other => other,
        }
    }

    /// The pipeline settings described, [`PipelineSettings::default`] for what is not.
    /// `name` writes a key in the front end's words (`--prior-sigma`, `prior_sigma`);
    /// `read` reads an inertia file given as `nominal` or `prior`, with the `products`
    /// convention asked for (a file may carry its own).
    pub fn pipeline_settings(
        &self,
        name: &dyn Fn(&str) -> String,
        read: &mut ReadInertiaFile<'_>,
    ) -> Result<PipelineSettings, SettingError> {
        let d = PipelineSettings::default();
        let chain = self.chain.unwrap_or(DEFAULT_MAX_CHAIN_S);
        Ok(PipelineSettings {
            estimator: self.estimator.clone().unwrap_or(d.estimator),
            solver: self.solver.clone().unwrap_or(d.solver),
            constraints: self.constraint_set(name, read)?,
            solve_every: self.every.unwrap_or(d.solve_every),
            memory_s: self.memory,
            resample_s: self.resample,
            gyro_noise_deg_s_rthz: self.gyro_noise,
            uncertainty: self.uncertainty.unwrap_or(d.uncertainty),
            rotor_scale_sigma: self.rotor_scale_sigma.map(|f| f.0),
            torque_scale_sigma: self.torque_scale_sigma.map(|f| f.0),
            filter_cutoff_hz: self.filter_cutoff_hz,
            observability: d.observability,
            rotation_source: self.rotation_source,
            rho_model: self.rho_model.unwrap_or(d.rho_model),
            torque_bias: self.torque_bias.unwrap_or(d.torque_bias),
            inertial_torque: self.inertial_torque.unwrap_or(d.inertial_torque),
            damping: self.damping.unwrap_or(d.damping),
            calibrate_rotors: self.calibrate_rotors.unwrap_or(d.calibrate_rotors),
            outside: self.outside.unwrap_or(d.outside),
            max_chain_s: (chain != 0.0).then_some(chain),
            attitude_drift_deg_rth: self.attitude_drift,
            glitches: self.glitches.unwrap_or(d.glitches),
            wheel_delay: self.wheel_delay.unwrap_or(d.wheel_delay),
        })
    }

    /// An inertia given as a matrix (its products in the `products` convention) or a
    /// file, in tensor entries.
    fn inertia(
        &self,
        key: &'static str,
        input: &InertiaInput,
        name: &dyn Fn(&str) -> String,
        read: &mut ReadInertiaFile<'_>,
    ) -> Result<ReadInertia, SettingError> {
        match input {
            InertiaInput::File(p) => read(p, self.products).map_err(|m| error(key, m)),
            InertiaInput::Matrix(rows) => {
                let m = checked_matrix(key, rows, name)?;
                Ok((self.products.unwrap_or_default().matrix_to_tensor(&m), None))
            }
        }
    }

    fn constraint_set(
        &self,
        name: &dyn Fn(&str) -> String,
        read: &mut ReadInertiaFile<'_>,
    ) -> Result<ConstraintSet, SettingError> {
        let mut set = ConstraintSet {
            consistency: self.constraints.unwrap_or_default(),
            ..ConstraintSet::physical()
        };
        match (&self.nominal, self.tolerance) {
            (Some(n), Some(p)) => {
                let (m, _) = self.inertia("nominal", n, name, read)?;
                set = set.with_nominal_inertia(&m, p.0);
            }
            (None, None) => {}
            (Some(_), None) => {
                return Err(error(
                    "nominal",
                    format!(
                        "{}: needs {} (e.g. 10%)",
                        name("nominal"),
                        name("tolerance")
                    ),
                ))
            }
            (None, Some(_)) => {
                return Err(error(
                    "tolerance",
                    format!(
                        "{}: needs {} (a 3×3 inertia, kg m²)",
                        name("tolerance"),
                        name("nominal")
                    ),
                ))
            }
        }
        let products = self.products.unwrap_or_default();
        for &(k, l, h) in self.bounds.iter().flat_map(|b| &b.0) {
            let (l, h) = products.bound_to_tensor(k, l, h);
            set = set.with_bounds(k, l, h);
        }
        if self.diagonal == Some(true) {
            set = set.diagonal();
        }
        match (&self.prior, self.prior_sigma) {
            (Some(p), sigma) => {
                let (m, file_sigma) = self.inertia("prior", p, name, read)?;
                set = match (sigma, file_sigma) {
                    (Some(PriorSigma::Relative(f)), _) => set.with_relative_prior(&m, f),
                    (Some(PriorSigma::Absolute(v)), _) => set.with_prior(&m, [v; 6]),
                    (Some(PriorSigma::Matrix(rows)), _) => {
                        let s = crate::tensor::j_from_matrix(&checked_matrix(
                            "prior_sigma",
                            &rows,
                            name,
                        )?);
                        set.with_prior(&m, core::array::from_fn(|k| s[k]))
                    }
                    (None, Some(s)) => set.with_prior(&m, s),
                    (None, None) => {
                        return Err(error(
                            "prior",
                            format!(
                                "{}: the prior needs a standard deviation: {} (e.g. 5%){}",
                                name("prior"),
                                name("prior_sigma"),
                                if matches!(p, InertiaInput::File(_)) {
                                    " or sigma_kg_m2 in its file"
                                } else {
                                    ""
                                }
                            ),
                        ))
                    }
                };
            }
            (None, Some(_)) => {
                return Err(error(
                    "prior_sigma",
                    format!(
                        "{}: needs {} (a 3×3 inertia, kg m²)",
                        name("prior_sigma"),
                        name("prior")
                    ),
                ))
            }
            (None, None) => {}
        }
        Ok(set)
    }

    /// The quaternion format of `scalar_first`, `jpl` and `conjugate` (at most one).
    pub(crate) fn quaternion_format(
        &self,
        name: &dyn Fn(&str) -> String,
    ) -> Result<QuaternionFormat, SettingError> {
        let flags = [
            (self.scalar_first, QuaternionFormat::HamiltonScalarFirst),
            (self.jpl, QuaternionFormat::Jpl),
            (self.conjugate, QuaternionFormat::Conjugate),
        ];
        let mut on = flags.iter().filter(|(f, _)| *f == Some(true));
        let format = on
            .next()
            .map_or(QuaternionFormat::HamiltonScalarLast, |f| f.1);
        if on.next().is_some() {
            return Err(error(
                "scalar_first",
                format!(
                    "{}, {} and {}: choose one (jpl and conjugate are scalar last; jpl has this library's numbers, conjugate maps inertial → body)",
                    name("scalar_first"),
                    name("jpl"),
                    name("conjugate")
                ),
            ));
        }
        Ok(format)
    }

    /// The CSV reader's options described (their defaults for what is not; no speed
    /// columns: the caller adds its spacecraft file's).
    #[cfg(feature = "csv")]
    pub fn csv_options(
        &self,
        name: &dyn Fn(&str) -> String,
    ) -> Result<crate::telemetry::csv::CsvOptions, SettingError> {
        use crate::telemetry::csv::{ColumnNames, CsvOptions};
        let d = CsvOptions::default();
        let mut columns = ColumnNames::default();
        for (k, v) in self.columns.iter().flatten() {
            if !columns.rename(k.trim(), v.trim()) {
                return Err(error(
                    "columns",
                    format!(
                        "{}: unknown column {k:?} (known: t, q_x, q_y, q_z, q_w, rho_*, tau_*, w_*)",
                        name("columns")
                    ),
                ));
            }
        }
        for (key, v) in [
            ("unit_tolerance", self.unit_tolerance),
            ("period_tolerance", self.period_tolerance),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && v > 0.0) {
                    return Err(error(
                        key,
                        format!(
                            "{}={}: must be finite and > 0",
                            name(key),
                            crate::text::Num(v)
                        ),
                    ));
                }
            }
        }
        Ok(CsvOptions {
            quaternion: self.quaternion_format(name)?,
            columns,
            unit_tolerance: self.unit_tolerance.unwrap_or(d.unit_tolerance),
            period_tolerance: self.period_tolerance,
            negate_rho: self.negate_rho.unwrap_or(d.negate_rho),
            gyro_unit: self.gyro_unit.unwrap_or(d.gyro_unit),
            ..d
        })
    }
}

/// A finite, symmetric 3×3 matrix.
fn checked_matrix(
    key: &'static str,
    rows: &[[f64; 3]; 3],
    name: &dyn Fn(&str) -> String,
) -> Result<Matrix3<f64>, SettingError> {
    let m = Matrix3::from_fn(|r, c| rows[r][c]);
    if !m.iter().all(|x| x.is_finite()) {
        return Err(error(key, format!("{}: has non-finite entries", name(key))));
    }
    if (m - m.transpose()).norm() > 1e-9 * m.norm() {
        return Err(error(key, format!("{}: is not symmetric", name(key))));
    }
    Ok(m)
}

#[cfg(test)]
mod tests;
