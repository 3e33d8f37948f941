//! Settings from C: plain integers and numbers (no heap, no strings) read into a
//! [`Plan`] and checked by the library's `PipelineSettings::check` (the checks the CLI and
//! Python get), from which the heap engine's library settings or the fixed-size engine
//! are built. `0` means "none" for the optional numbers.
//!
//! The estimator and the solver backend are selected by id: `k ≥ 1` is entry `k − 1` of
//! the library's registry ([`ESTIMATORS`], [`BACKENDS`]), 0 the library's default. The
//! header's `INERTIA_ESTIMATOR_*` and `INERTIA_SOLVER_*` constants are generated from the
//! same registry (`tests/header.rs`): this crate keeps no list of its own. The other
//! choices index the library's [`Choice::ALL`] (`tests/c_api/api.rs` checks that each
//! named constant is the value of the same name).

use crate::engine::{self, Engine, FixedConfig};
use crate::status::{fail, pipeline_fail, InertiaStatus};
use inertia::choice::Choice;
use inertia::constraints::Consistency;
use inertia::constraints::ConstraintSet;
use inertia::estimator::momentum_rows::{RhoModel, RotationSource};
use inertia::estimator::observability::ObservabilitySettings;
use inertia::estimator::recursive::RecursiveSettings;
use inertia::pipeline::registry::{BackendEntry, EstimatorEntry, BACKENDS, ESTIMATORS};
use inertia::pipeline::{InertialTorque, PipelineError, PipelineSettings};
use inertia::telemetry::glitch::GlitchPolicy;
use inertia::tensor::Component;

/// The feasible set of J (`InertiaSettings::constraints`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaConstraintKind {
    /// J ⪰ εI and Σ = ½tr(J)I − J ⪰ 0 (default).
    Physical = 0,
    /// The paper's set: J ⪰ εI and the diagonal triangle inequalities.
    Paper = 1,
    /// J ⪰ εI only.
    PositiveDefinite = 2,
}

/// Where the discrete momentum estimator takes the rotation from
/// (`InertiaSettings::rotation_source`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaRotationSource {
    /// Both when the samples have gyro rates; the better fit is used (default).
    Auto = 0,
    /// The attitude quaternions.
    Attitude = 1,
    /// The gyro rates.
    Gyro = 2,
}

/// What the wheel momentum does between samples (`InertiaSettings::rho_model`,
/// discrete momentum estimator).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaRhoModel {
    /// Decided from the data (default).
    Auto = 0,
    /// Smooth.
    Smooth = 1,
    /// Commands held over each step.
    Held = 2,
    /// The plain trapezoid.
    Plain = 3,
}

/// Whether to estimate a torque constant in the inertial frame, per chain
/// (`InertiaSettings::inertial_torque`, discrete momentum; the CLI's `--inertial-torque`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaInertialTorque {
    /// Not estimated (default).
    Off = 0,
    /// Always estimated.
    On = 1,
    /// Estimated where a nested χ² test says the data need it.
    Auto = 2,
    /// `Auto` on a record shorter than 30 s, `Off` on a longer one (the library's and the
    /// command line's default; heap engine).
    Short = 3,
}

/// What to do when the attitude jumps against the gyro (`InertiaSettings::glitches`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaGlitchPolicy {
    /// Stop with `INERTIA_STATUS_DATA` (default).
    Stop = 0,
    /// Estimate anyway.
    Keep = 1,
}

/// Settings of an estimator. Start from `inertia_settings_default()` and change fields.
/// The enum-valued fields are plain integers holding one of the named constants (an
/// unknown value is `INERTIA_STATUS_INVALID_SETTING`, never undefined behaviour); flags
/// are 0 or non-zero. Units SI.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaSettings {
    /// An `INERTIA_ESTIMATOR_*` id (the library's registry, in order, from 1); 0
    /// (default): the library's default, discrete momentum.
    pub estimator: u32,
    /// One of `InertiaConstraintKind`. Default physical.
    pub constraints: u32,
    /// Lower bound per element `[J11, J22, J33, J12, J13, J23]`, kg m²; `-INFINITY`
    /// (default) for none. Products are tensor entries (`J12 = −Σ m x y`).
    pub bound_lower_kg_m2: [f64; 6],
    /// Upper bound per element, kg m²; `INFINITY` (default) for none. A lower bound
    /// equal to the upper one is an equality: the solver eliminates that element.
    pub bound_upper_kg_m2: [f64; 6],
    /// Gaussian prior mean per element, kg m² (tensor entries; negate a CAD tool's
    /// products of inertia). Used when `prior_sigma_kg_m2` is set.
    pub prior_mean_kg_m2: [f64; 6],
    /// Gaussian prior standard deviation per element, kg m², each finite and > 0; all
    /// zero (default) for no prior.
    pub prior_sigma_kg_m2: [f64; 6],
    /// Solve every this many samples (default 1).
    pub solve_every: u32,
    /// Memory time constant, s; 0 (default) for none.
    pub memory_s: f64,
    /// Resample onto a uniform grid of this period, s; 0 (default) for none. Heap only.
    pub resample_s: f64,
    /// Gyro rate-noise density, deg/s/√Hz, for errors-in-variables compensation; 0
    /// (default): none stated (see `gyro_noise_estimate`).
    pub gyro_noise_deg_s_rthz: f64,
    /// Non-zero (default): attach σ to each estimate.
    pub uncertainty: u8,
    /// Non-zero (default): estimate an unknown constant torque (discrete momentum).
    pub torque_bias: u8,
    /// One of `InertiaRotationSource` (discrete momentum). Default auto.
    pub rotation_source: u32,
    /// One of `InertiaRhoModel` (discrete momentum). Default auto.
    pub rho_model: u32,
    /// Short momentum chain, s (discrete momentum); default 30; 0: chains end only at gaps.
    pub max_chain_s: f64,
    /// One of `InertiaGlitchPolicy`. Default stop.
    pub glitches: u32,
    /// Angle random walk of the attitude solution, deg/√h (discrete momentum, with
    /// `gyro_noise_deg_s_rthz`): for an attitude propagated from a gyro, its ARW; the rows
    /// are weighted for the drift (needs `uncertainty`). 0 (default) for none (a star
    /// tracker or an MEKF).
    pub attitude_drift_deg_rth: f64,
    /// One of `InertiaInertialTorque` (discrete momentum). Default off.
    pub inertial_torque: u32,
    /// Relative σ of the wheel momentum's scale (their spin inertia known to ±this), a
    /// consider parameter that widens σ; 0 (default) for none. Heap only.
    pub rotor_scale_sigma: f64,
    /// An `INERTIA_SOLVER_*` id (the library's registry, in order, from 1); 0 (default):
    /// the library's default, native. Caller storage runs the native solver only.
    pub solver: u32,
    /// Non-zero (default): with no density stated (`gyro_noise_deg_s_rthz` 0), the
    /// discrete momentum estimator estimates it from the rates where their differences are
    /// noise and compensates with it; 0: no compensation without a stated density.
    pub gyro_noise_estimate: u8,
}

/// What the C settings ask for, without the heap (no estimator name string).
pub(crate) struct Plan {
    estimator: &'static EstimatorEntry,
    backend: &'static BackendEntry,
    constraints: ConstraintSet,
    solve_every: usize,
    pub(crate) memory_s: Option<f64>,
    pub(crate) resample_s: Option<f64>,
    attitude_drift: Option<f64>,
    gyro_noise: Option<f64>,
    uncertainty: bool,
    torque_bias: bool,
    rotation_source: Option<RotationSource>,
    rho_model: RhoModel,
    inertial_torque: InertialTorque,
    rotor_scale_sigma: Option<f64>,
    max_chain_s: Option<f64>,
    glitches: GlitchPolicy,
}

/// `0` means none; anything else is the value, which the library checks
/// ([`PipelineSettings::check`]).
fn optional(v: f64) -> Option<f64> {
    (v != 0.0).then_some(v)
}

fn choice<T: Copy>(name: &str, v: u32, options: &[T]) -> Result<T, InertiaStatus> {
    options.get(v as usize).copied().ok_or_else(|| {
        fail(
            InertiaStatus::InvalidSetting,
            format_args!(
                "setting `{name}` = {v} is invalid: expected 0 to {}",
                options.len() - 1
            ),
        )
    })
}

/// Id `v` of a registry (`entries`): 0 is the entry called `default`, `k ≥ 1` entry
/// `k − 1`.
fn registered<T>(
    name: &str,
    v: u32,
    entries: &'static [T],
    entry_name: fn(&T) -> &'static str,
    default: &str,
) -> Result<&'static T, InertiaStatus> {
    let found = match v {
        0 => entries.iter().find(|e| entry_name(e) == default),
        k => entries.get(k as usize - 1),
    };
    found.ok_or_else(|| {
        fail(
            InertiaStatus::InvalidSetting,
            format_args!(
                "setting `{name}` = {v} is invalid: expected 0 (default) to {}",
                entries.len()
            ),
        )
    })
}

/// A value of the library's choice `T` by its index in [`Choice::ALL`].
fn library_choice<T: Choice>(name: &str, v: u32) -> Result<T, InertiaStatus> {
    choice(name, v, T::ALL)
}

impl Plan {
    pub(crate) fn from_c(s: &InertiaSettings) -> Result<Self, InertiaStatus> {
        let estimator = registered(
            "estimator",
            s.estimator,
            ESTIMATORS,
            |e| e.name,
            PipelineSettings::DEFAULT_ESTIMATOR,
        )?;
        let backend = registered(
            "solver",
            s.solver,
            BACKENDS,
            |e| e.name,
            PipelineSettings::DEFAULT_SOLVER,
        )?;
        if let Some(why) = backend.unavailable {
            return Err(pipeline_fail(&PipelineError::SolverUnavailable {
                name: backend.name,
                why,
            }));
        }
        let mut constraints = ConstraintSet {
            consistency: library_choice::<Consistency>("constraints", s.constraints)?,
            ..ConstraintSet::physical()
        };
        for (k, c) in Component::ALL.iter().enumerate() {
            let (l, u) = (s.bound_lower_kg_m2[k], s.bound_upper_kg_m2[k]);
            if l.is_nan() || u.is_nan() || l == f64::INFINITY || u == f64::NEG_INFINITY {
                return Err(fail(
                    InertiaStatus::NotFinite,
                    format_args!(
                        "bound on {}: [{l}, {u}] (NaN, or infinite on the wrong side)",
                        inertia::tensor::COMPONENT_NAMES[k]
                    ),
                ));
            }
            let (l, u) = (l.is_finite().then_some(l), u.is_finite().then_some(u));
            if l.is_some() || u.is_some() {
                constraints = constraints.with_bounds(*c, l, u);
            }
        }
        // A prior is given when any σ is; the library checks each value (finite, > 0).
        if s.prior_sigma_kg_m2.iter().any(|&v| v != 0.0) {
            constraints.prior = Some(inertia::constraints::GaussianPrior {
                mean_kg_m2: s.prior_mean_kg_m2,
                sigma_kg_m2: s.prior_sigma_kg_m2,
            });
        }
        let plan = Plan {
            estimator,
            backend,
            constraints,
            solve_every: s.solve_every as usize,
            memory_s: optional(s.memory_s),
            resample_s: optional(s.resample_s),
            attitude_drift: optional(s.attitude_drift_deg_rth),
            // None stated: estimated (unset), or none (a stated 0).
            gyro_noise: match optional(s.gyro_noise_deg_s_rthz) {
                None if s.gyro_noise_estimate == 0 => Some(0.0),
                g => g,
            },
            uncertainty: s.uncertainty != 0,
            torque_bias: s.torque_bias != 0,
            // 0: chosen from the data; k ≥ 1: the library's value k − 1.
            rotation_source: match s.rotation_source {
                0 => None,
                k => Some(*RotationSource::ALL.get(k as usize - 1).ok_or_else(|| {
                    fail(
                        InertiaStatus::InvalidSetting,
                        format_args!(
                            "setting `rotation_source` = {k} is invalid: expected 0 to {}",
                            RotationSource::ALL.len()
                        ),
                    )
                })?),
            },
            rho_model: library_choice("rho_model", s.rho_model)?,
            inertial_torque: library_choice("inertial_torque", s.inertial_torque)?,
            rotor_scale_sigma: optional(s.rotor_scale_sigma),
            max_chain_s: optional(s.max_chain_s),
            glitches: library_choice("glitches", s.glitches)?,
        };
        // Every value is the library's to check, as for the CLI and Python (no heap).
        plan.settings(std::string::String::new(), std::string::String::new())
            .check(plan.estimator)
            .map_err(|e| pipeline_fail(&e))?;
        Ok(plan)
    }

    fn name(&self) -> &'static str {
        self.estimator.name
    }

    /// The library's settings (allocates: the estimator's name is a `String`).
    pub(crate) fn pipeline_settings(&self) -> PipelineSettings {
        self.settings(self.estimator.name.into(), self.backend.name.into())
    }

    /// The library's settings with these names (empty names: no heap).
    fn settings(
        &self,
        estimator: std::string::String,
        solver: std::string::String,
    ) -> PipelineSettings {
        PipelineSettings {
            estimator,
            solver,
            constraints: self.constraints,
            solve_every: self.solve_every,
            memory_s: self.memory_s,
            resample_s: self.resample_s,
            gyro_noise_deg_s_rthz: self.gyro_noise,
            uncertainty: self.uncertainty,
            observability: ObservabilitySettings::default(),
            rotation_source: self.rotation_source,
            rho_model: self.rho_model,
            torque_bias: self.torque_bias,
            inertial_torque: self.inertial_torque,
            // Air drag: a laboratory effect, not in the C API.
            damping: false,
            // A batch calibration with a spacecraft file: not in the C API, which has
            // neither.
            calibrate_rotors: false,
            // Every outside torque the samples' `InertiaExternal` gives is modelled.
            outside: Default::default(),
            rotor_scale_sigma: self.rotor_scale_sigma,
            // The known torque's scale term needs the samples a `Run` keeps: not in the C
            // API, which streams without them.
            torque_scale_sigma: None,
            // The filter's cutoff is the estimator's own default (`InertiaSettings` has
            // none to give).
            filter_cutoff_hz: None,
            max_chain_s: self.max_chain_s,
            attitude_drift_deg_rth: self.attitude_drift,
            glitches: self.glitches,
            // The wheel-speed time tag needs the whole record before the first estimate:
            // not in the C API, which estimates as samples arrive.
            wheel_delay: inertia::estimator::wheel_delay::WheelDelay::Off,
        }
    }

    /// The fixed-size engine (the settings' values were checked by the library's
    /// `PipelineSettings::check` in [`Self::from_c`]): what it cannot run is refused.
    pub(crate) fn fixed_engine(&self) -> Result<Engine, InertiaStatus> {
        // The two estimators this crate implements in fixed-size state.
        let fd = match self.estimator.name {
            "variational" => false,
            "finite-difference" => true,
            _ => {
                return Err(fail(
                    InertiaStatus::NeedsHeap,
                    format_args!(
                        "the {} estimator cannot run in caller storage (only variational and finite-difference can): use inertia_estimator_new",
                        self.name()
                    ),
                ))
            }
        };
        if self.backend.name != PipelineSettings::DEFAULT_SOLVER {
            return Err(fail(
                InertiaStatus::NeedsHeap,
                format_args!(
                    "the {} solver cannot run in caller storage (only {} can): use inertia_estimator_new",
                    self.backend.name,
                    PipelineSettings::DEFAULT_SOLVER
                ),
            ));
        }
        if self.resample_s.is_some() {
            return Err(fail(
                InertiaStatus::NeedsHeap,
                format_args!("resampling cannot run in caller storage: use inertia_estimator_new"),
            ));
        }
        if self.rotor_scale_sigma.is_some() {
            return Err(fail(
                InertiaStatus::NeedsHeap,
                format_args!(
                    "rotor_scale_sigma cannot run in caller storage: use inertia_estimator_new"
                ),
            ));
        }
        // The row-model settings at `PipelineSettings::default()`'s values (not built here:
        // it holds `String`s). `tests/c_api/engines.rs` checks the two agree.
        for (setting, changed) in [
            ("rotation_source", self.rotation_source.is_some()),
            ("rho_model", self.rho_model != RhoModel::Auto),
            ("torque_bias", !self.torque_bias),
            (
                "inertial_torque",
                self.inertial_torque != InertialTorque::Off,
            ),
            (
                "max_chain_s",
                self.max_chain_s != Some(inertia::pipeline::DEFAULT_MAX_CHAIN_S),
            ),
            (
                "gyro_noise_deg_s_rthz",
                fd && self.gyro_noise.is_some_and(|g| g > 0.0),
            ),
            ("attitude_drift_deg_rth", self.attitude_drift.is_some()),
        ] {
            if changed {
                return Err(fail(
                    InertiaStatus::InvalidSetting,
                    format_args!(
                        "setting `{setting}` does not apply to the {} estimator",
                        self.name()
                    ),
                ));
            }
        }
        let constraints = self
            .constraints
            .validate()
            .map_err(|e| pipeline_fail(&PipelineError::Constraints(e)))?;
        let config = FixedConfig {
            constraints,
            recursive: RecursiveSettings {
                solve_every: self.solve_every,
                observability: ObservabilitySettings::default(),
                memory_s: self.memory_s,
                gyro_noise_rad_s_rthz: self.gyro_noise.map(f64::to_radians),
            },
            // The finite-difference baseline has no uncertainty model.
            uncertainty: self.uncertainty && !fd,
            residual_test: self.memory_s.is_none(),
            glitches: self.glitches,
        };
        let engine = if fd {
            engine::Fixed::new(config).map(Engine::FiniteDifference)
        } else {
            engine::Fixed::new(config).map(Engine::Variational)
        };
        engine.map_err(|e| pipeline_fail(&e))
    }
}

/// The default settings: the discrete momentum estimator, the physical constraint set,
/// no bounds, no memory, no resampling, the gyro's noise density estimated from the rates
/// (discrete momentum) and compensated, σ on, torque bias on,
/// chains of 30 s, glitches stop the run (the CLI's `estimate` defaults). For caller
/// storage set `estimator = INERTIA_ESTIMATOR_VARIATIONAL`.
#[no_mangle]
pub extern "C" fn inertia_settings_default() -> InertiaSettings {
    InertiaSettings {
        estimator: 0,
        constraints: InertiaConstraintKind::Physical as u32,
        bound_lower_kg_m2: [f64::NEG_INFINITY; 6],
        bound_upper_kg_m2: [f64::INFINITY; 6],
        prior_mean_kg_m2: [0.0; 6],
        prior_sigma_kg_m2: [0.0; 6],
        solve_every: 1,
        memory_s: 0.0,
        resample_s: 0.0,
        gyro_noise_deg_s_rthz: 0.0,
        uncertainty: 1,
        torque_bias: 1,
        rotation_source: InertiaRotationSource::Auto as u32,
        rho_model: InertiaRhoModel::Auto as u32,
        max_chain_s: inertia::pipeline::DEFAULT_MAX_CHAIN_S,
        glitches: InertiaGlitchPolicy::Stop as u32,
        attitude_drift_deg_rth: 0.0,
        inertial_torque: InertiaInertialTorque::Off as u32,
        rotor_scale_sigma: 0.0,
        solver: 0,
        gyro_noise_estimate: 1,
    }
}
