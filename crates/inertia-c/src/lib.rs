//! C API of the `inertia` estimator, for flight software.
//!
//! The header `include/inertia.h` is generated from this file by cbindgen
//! (`tests/header.rs` regenerates it and fails when the checked-in copy differs).
//!
//! # Two ways to hold an estimator
//!
//! * **On the heap**: [`inertia_estimator_new`] / [`inertia_estimator_free`]. Every
//!   estimator of the library, through [`inertia::pipeline::Pipeline`] (the default,
//!   `discrete-momentum`, among them). Creation and the first pushes allocate (the
//!   discrete momentum estimator builds its candidates from the first samples);
//!   `tests/no_alloc.rs` requires that no push after the first 100 samples of a slew
//!   does, a measurement rather than a guarantee for every input.
//! * **In caller storage**: [`inertia_estimator_size`], [`inertia_estimator_align`],
//!   [`inertia_estimator_init`]. The `variational` and `finite-difference` estimators
//!   with the native solver, in fixed-size state. Neither `init`, nor a push, nor reading
//!   the estimate, nor `reset` allocates: `tests/no_alloc.rs` counts every allocation over
//!   whole simulated runs and requires zero.
//!
//! # Errors
//!
//! Every function returns an [`InertiaStatus`]; none panics across the boundary (each
//! entry point runs under `catch_unwind`; a caught panic is [`InertiaStatus::Panic`]) and
//! none aborts. Null pointers and non-finite numbers are refused with their own codes. The
//! message of the last error on the calling thread is copied out by
//! [`inertia_last_error_message`] (a fixed thread-local buffer: recording it does not
//! allocate).

#![allow(clippy::missing_safety_doc)] // each `unsafe extern fn` documents its contract

mod engine;
mod message;

use core::ffi::{c_char, c_void};
use core::fmt::Write as _;
use core::mem::{align_of, size_of};
use core::panic::AssertUnwindSafe;
use engine::{Engine, FixedConfig};
use inertia::constraints::ConstraintSet;
use inertia::estimator::momentum_rows::{RhoModel, RotationSource};
use inertia::estimator::observability::{Observability, ObservabilitySettings, Unobservable};
use inertia::estimator::recursive::RecursiveSettings;
use inertia::estimator::{Estimate, EstimatorError};
use inertia::fix::{Fix, Fixes};
use inertia::pipeline::{check_first_step, Pipeline, PipelineError, PipelineSettings};
use inertia::sample::{check_range, Sample};
use inertia::telemetry::glitch::GlitchPolicy;
use inertia::tensor::{matrix_from_j, Component};
use message::record;
use nalgebra::Vector3;

/// What a function did: `INERTIA_STATUS_OK`, or why not.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaStatus {
    /// Success.
    Ok = 0,
    /// A required pointer was null.
    NullPointer = 1,
    /// A number given was NaN or infinite.
    NotFinite = 2,
    /// A sample value is outside the supported range (README "Supported range"),
    /// including a quaternion whose norm differs from 1 by more than 1e-3.
    OutOfRange = 3,
    /// A setting is invalid, or does not apply to the chosen estimator.
    InvalidSetting = 4,
    /// The storage given to `inertia_estimator_init` is too small or misaligned.
    BadStorage = 5,
    /// The chosen estimator or setting cannot run in caller storage: use
    /// `inertia_estimator_new`.
    NeedsHeap = 6,
    /// The data were refused: time not increasing, a step too large, an attitude glitch,
    /// a quaternion convention that disagrees with the gyro, missing gyro rates. After this
    /// code from `inertia_estimator_push` (except for a time that does not increase, which
    /// changes nothing) the estimator is stopped until `inertia_estimator_reset`.
    Data = 7,
    /// The solver failed on the data; the estimator is stopped until reset.
    Solver = 8,
    /// The estimator stopped on an earlier error: reset it.
    Stopped = 9,
    /// An internal error (a bug) was caught; the estimator is stopped until reset.
    Panic = 10,
}

/// The estimators (`InertiaSettings::estimator`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaEstimatorKind {
    /// The discrete momentum estimator (the CLI's default; heap only).
    DiscreteMomentum = 0,
    /// The paper's discrete variational estimator (heap or caller storage).
    Variational = 1,
    /// The paper's finite-difference baseline; needs gyro rates (heap or caller storage).
    FiniteDifference = 2,
    /// The momentum recursive least-squares baseline, unconstrained (heap only).
    Momentum = 3,
}

/// The feasible set of J (`InertiaSettings::constraints`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaConstraintKind {
    /// J ⪰ εI and Σ = ½tr(J)I − J ⪰ 0 (default).
    Physical = 0,
    /// The paper's set: J ⪰ εI and the diagonal triangle inequalities.
    Paper = 1,
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
    /// One of `InertiaEstimatorKind`. Default discrete momentum.
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
    /// (default) for none.
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
}

/// One telemetry sample at time `t_s` (README "Estimating your own telemetry").
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaSample {
    /// Time, s; increasing from sample to sample.
    pub t_s: f64,
    /// Attitude `[x, y, z, w]`, scalar last, Hamilton, body → inertial; renormalised when
    /// its norm is within 1e-3 of 1 (as the CSV reader does), refused beyond.
    pub q: [f64; 4],
    /// Total rotor angular momentum, N m s, body axes.
    pub rho_nms: [f64; 3],
    /// Known external torque, N m, body axes (zeros when none is known).
    pub tau_nm: [f64; 3],
    /// Gyro rate averaged over `[t_k, t_{k+1}]`, rad/s, body axes; read only when
    /// `has_w` is non-zero.
    pub w_rad_s: [f64; 3],
    /// Non-zero when `w_rad_s` holds a gyro rate. Use the same for every sample.
    pub has_w: u8,
}

/// How an estimate stands.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaEstimateStatus {
    /// No estimate yet (too few samples).
    None = 0,
    /// The data determine J.
    Determined = 1,
    /// The data leave a direction open that the bounds pin: an answer, leaning on them.
    FromPrior = 2,
    /// The data do not determine J: no answer (see the reason).
    NotObservable = 3,
    /// An answer with no observability test (the momentum baseline).
    Unchecked = 4,
}

/// Why an estimate is not `DETERMINED` (the library's `Unobservable`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaReason {
    /// No reason: determined, unchecked, or no estimate yet.
    None = 0,
    /// No rotor momentum or known torque has excited the motion.
    NoExcitation = 1,
    /// Fewer than six independent rows.
    RankDeficient = 2,
    /// The rows explain too little (relative σ of J over the threshold).
    Uncertain = 3,
    /// The gyro noise outweighs the excitation (compensated information not definite).
    NoiseDominated = 4,
    /// The estimate is not finite.
    Diverged = 5,
    /// The answer rests on the J ⪰ εI floor.
    AtFloor = 6,
    /// The constraints moved the answer further than the noise allows.
    ConflictsWithConstraints = 7,
    /// The rotation from the attitude and from the gyro give different answers.
    SourcesDisagree = 8,
    /// A span of the record has residuals far larger than the rest.
    Inconsistent = 9,
    /// The residuals are smaller than the stated gyro density implies.
    DensityOverstated = 10,
    /// The rows are ill-conditioned.
    IllConditioned = 11,
    /// A reason this version of the header does not name.
    Other = 12,
    /// The data contradict the Gaussian prior (`prior_chi2` above its threshold).
    PriorConflict = 13,
    /// The momentum baseline's unconstrained J is not a physical inertia.
    NotPhysical = 14,
}

/// The current estimate.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaEstimate {
    /// Status of the estimate.
    pub status: InertiaEstimateStatus,
    /// Why it is not determined (`INERTIA_REASON_NONE` when it is).
    pub reason: InertiaReason,
    /// Non-zero when `j` and `inertia` hold an answer (otherwise NaN).
    pub has_answer: u8,
    /// Non-zero when `sigma` holds standard deviations (otherwise NaN).
    pub has_sigma: u8,
    /// Time of the newest sample used, s (NaN before the first estimate).
    pub t_s: f64,
    /// `[J11, J22, J33, J12, J13, J23]`, kg m².
    pub j: [f64; 6],
    /// J as a row-major 3×3 matrix, kg m².
    pub inertia: [[f64; 3]; 3],
    /// Standard deviation per element of `j`, kg m².
    pub sigma: [f64; 6],
    /// σ₁/σ₆ of the least-squares state when determined (otherwise NaN).
    pub condition: f64,
    /// Scalar rows used.
    pub rows: u64,
    /// Samples pushed since creation or the last reset.
    pub samples: u64,
    /// With a Gaussian prior: the fraction of the information on each element from the
    /// data (the rest from the prior); NaN without a prior or for a fixed element.
    pub prior_data_share: [f64; 6],
    /// With a Gaussian prior: the prior-data disagreement χ² (NaN without a prior).
    pub prior_chi2: f64,
}

/// An estimator (opaque).
pub struct InertiaEstimator {
    engine: Engine,
    /// Built by `inertia_estimator_new` (freed with a deallocation) rather than in caller
    /// storage.
    heap: bool,
    stopped: bool,
    has_w: Option<bool>,
    last_t_s: Option<f64>,
    samples: u64,
    last: Option<Estimate>,
    /// The memory and resampling settings, for the library's check of the first step
    /// (`inertia::pipeline::check_first_step`).
    memory_s: Option<f64>,
    resample_s: Option<f64>,
}

/// What the C settings ask for, without the heap (no estimator name string).
struct Plan {
    kind: InertiaEstimatorKind,
    constraints: ConstraintSet,
    solve_every: usize,
    memory_s: Option<f64>,
    resample_s: Option<f64>,
    attitude_drift: Option<f64>,
    gyro_noise: Option<f64>,
    uncertainty: bool,
    torque_bias: bool,
    rotation_source: Option<RotationSource>,
    rho_model: RhoModel,
    max_chain_s: Option<f64>,
    glitches: GlitchPolicy,
}

/// An error: the status and its message, recorded for `inertia_last_error_message`.
fn fail(status: InertiaStatus, msg: core::fmt::Arguments<'_>) -> InertiaStatus {
    record(msg);
    status
}

fn status_of(e: &PipelineError) -> InertiaStatus {
    match e {
        PipelineError::Estimator {
            source: EstimatorError::Solve(_),
            ..
        } => InertiaStatus::Solver,
        PipelineError::Estimator {
            source: EstimatorError::InvalidSetting { .. },
            ..
        }
        | PipelineError::UnknownEstimator { .. }
        | PipelineError::UnknownSolver { .. }
        | PipelineError::SolverUnavailable { .. }
        | PipelineError::InvalidSetting { .. }
        | PipelineError::NotApplicable { .. }
        | PipelineError::NeedsSetting { .. }
        | PipelineError::NoBatch { .. }
        | PipelineError::Constraints(_) => InertiaStatus::InvalidSetting,
        PipelineError::OutOfRange { .. } => InertiaStatus::OutOfRange,
        _ => InertiaStatus::Data,
    }
}

/// Record a library error. `Estimator` errors are written here rather than by their
/// `Display`, which formats the sample index into a `String`.
fn pipeline_fail(e: &PipelineError) -> InertiaStatus {
    match e {
        PipelineError::Estimator {
            sample: Some(s),
            source,
        } => fail(status_of(e), format_args!("input sample {s}: {source}")),
        PipelineError::Estimator {
            sample: None,
            source,
        } => fail(status_of(e), format_args!("{source}")),
        other => fail(
            status_of(e),
            format_args!("{other}{}", fixes(other.fixes())),
        ),
    }
}

/// How a C caller applies a fix ([`inertia::fix`]): what to change before pushing, or
/// the `InertiaSettings` field.
fn c_names(fix: Fix) -> Option<&'static str> {
    Some(match fix {
        Fix::Jpl => "conjugate q before pushing (JPL to Hamilton)",
        Fix::ScalarFirst => "q is [w, x, y, z]: push [x, y, z, w]",
        Fix::ScalarLast => "q is already [x, y, z, w]: push it unchanged",
        Fix::NegateRho => "negate rho_nms (and tau_nm) before pushing",
        Fix::KeepGlitches => "glitches = 1 (keep)",
        Fix::Memory => "memory_s",
        Fix::Resample => "resample_s",
        Fix::GyroNoise => "gyro_noise_deg_s_rthz",
        Fix::GyroDegrees => "multiply w_rad_s by pi/180 before pushing (the rates are in deg/s)",
        Fix::GyroRadians => "the rates are already rad/s: do not convert them",
        Fix::Conjugate => "conjugate q before pushing (inertial to body)",
        _ => return None,
    })
}

/// The fixes after a message, as a C caller applies them.
fn fixes(fixes: &'static [Fix]) -> Fixes<'static> {
    Fixes {
        fixes,
        names: c_names,
        label: "in C",
    }
}

fn finite(name: &str, v: f64) -> Result<(), InertiaStatus> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(fail(
            InertiaStatus::NotFinite,
            format_args!("setting `{name}` is {v}: expected a finite number"),
        ))
    }
}

/// `0` means none; anything else must be finite and > 0.
fn optional_positive(name: &str, v: f64) -> Result<Option<f64>, InertiaStatus> {
    finite(name, v)?;
    if v == 0.0 {
        Ok(None)
    } else if v > 0.0 {
        Ok(Some(v))
    } else {
        Err(fail(
            InertiaStatus::InvalidSetting,
            format_args!("setting `{name}` = {v} is invalid: expected 0 (none) or > 0"),
        ))
    }
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

impl Plan {
    fn from_c(s: &InertiaSettings) -> Result<Self, InertiaStatus> {
        use InertiaEstimatorKind as K;
        let kind = choice(
            "estimator",
            s.estimator,
            &[
                K::DiscreteMomentum,
                K::Variational,
                K::FiniteDifference,
                K::Momentum,
            ],
        )?;
        let mut constraints = choice(
            "constraints",
            s.constraints,
            &[ConstraintSet::physical(), ConstraintSet::paper()],
        )?;
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
        if s.solve_every == 0 {
            return Err(fail(
                InertiaStatus::InvalidSetting,
                format_args!("setting `solve_every` = 0 is invalid: expected at least 1"),
            ));
        }
        let gyro_noise = {
            let g = s.gyro_noise_deg_s_rthz;
            finite("gyro_noise_deg_s_rthz", g)?;
            if g < 0.0 {
                return Err(fail(
                    InertiaStatus::InvalidSetting,
                    format_args!("setting `gyro_noise_deg_s_rthz` = {g} is invalid: expected >= 0"),
                ));
            }
            (g > 0.0).then_some(g)
        };
        Ok(Plan {
            kind,
            constraints,
            solve_every: s.solve_every as usize,
            memory_s: optional_positive("memory_s", s.memory_s)?,
            resample_s: optional_positive("resample_s", s.resample_s)?,
            attitude_drift: optional_positive("attitude_drift_deg_rth", s.attitude_drift_deg_rth)?,
            gyro_noise,
            uncertainty: s.uncertainty != 0,
            torque_bias: s.torque_bias != 0,
            rotation_source: choice(
                "rotation_source",
                s.rotation_source,
                &[
                    None,
                    Some(RotationSource::Attitude),
                    Some(RotationSource::Gyro),
                ],
            )?,
            rho_model: choice(
                "rho_model",
                s.rho_model,
                &[
                    RhoModel::Auto,
                    RhoModel::Smooth,
                    RhoModel::Held,
                    RhoModel::Plain,
                ],
            )?,
            max_chain_s: optional_positive("max_chain_s", s.max_chain_s)?,
            glitches: choice(
                "glitches",
                s.glitches,
                &[GlitchPolicy::Stop, GlitchPolicy::Keep],
            )?,
        })
    }

    fn name(&self) -> &'static str {
        match self.kind {
            InertiaEstimatorKind::DiscreteMomentum => "discrete-momentum",
            InertiaEstimatorKind::Variational => "variational",
            InertiaEstimatorKind::FiniteDifference => "finite-difference",
            InertiaEstimatorKind::Momentum => "momentum",
        }
    }

    /// The library's settings (allocates: the estimator's name is a `String`).
    fn pipeline_settings(&self) -> PipelineSettings {
        PipelineSettings {
            estimator: self.name().into(),
            solver: "native".into(),
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
            max_chain_s: self.max_chain_s,
            attitude_drift_deg_rth: self.attitude_drift,
            glitches: self.glitches,
        }
    }

    /// The fixed-size engine, validated as `PipelineSettings::validate` would, without
    /// the heap.
    fn fixed_engine(&self) -> Result<Engine, InertiaStatus> {
        let fd = match self.kind {
            InertiaEstimatorKind::Variational => false,
            InertiaEstimatorKind::FiniteDifference => true,
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
        if self.resample_s.is_some() {
            return Err(fail(
                InertiaStatus::NeedsHeap,
                format_args!("resampling cannot run in caller storage: use inertia_estimator_new"),
            ));
        }
        // The row-model settings at `PipelineSettings::default()`'s values (not built here:
        // it holds `String`s). `tests/c_api/engines.rs` checks the two agree.
        for (setting, changed) in [
            ("rotation_source", self.rotation_source.is_some()),
            ("rho_model", self.rho_model != RhoModel::Auto),
            ("torque_bias", !self.torque_bias),
            (
                "max_chain_s",
                self.max_chain_s != Some(inertia::pipeline::DEFAULT_MAX_CHAIN_S),
            ),
            ("gyro_noise_deg_s_rthz", fd && self.gyro_noise.is_some()),
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

impl InertiaEstimator {
    fn new(engine: Engine, heap: bool, plan: &Plan) -> Self {
        Self {
            engine,
            heap,
            stopped: false,
            has_w: None,
            last_t_s: None,
            samples: 0,
            last: None,
            memory_s: plan.memory_s,
            resample_s: plan.resample_s,
        }
    }

    fn push(&mut self, s: &InertiaSample) -> InertiaStatus {
        if self.stopped {
            return fail(
                InertiaStatus::Stopped,
                format_args!("the estimator stopped on an earlier error: reset it"),
            );
        }
        let t = [s.t_s];
        let values = t
            .iter()
            .chain(&s.q)
            .chain(&s.rho_nms)
            .chain(&s.tau_nm)
            .chain(if s.has_w != 0 { &s.w_rad_s[..] } else { &[] });
        if let Some(v) = values.copied().find(|v| !v.is_finite()) {
            return fail(
                InertiaStatus::NotFinite,
                format_args!(
                    "sample {}: a value is {v}: every value must be finite",
                    self.samples
                ),
            );
        }
        let has_w = s.has_w != 0;
        if self.has_w.is_some_and(|h| h != has_w) {
            return fail(
                InertiaStatus::Data,
                format_args!(
                    "sample {}: has_w = {} where the earlier samples had {}: gyro rates must be given for every sample or none",
                    self.samples,
                    u8::from(has_w),
                    u8::from(!has_w)
                ),
            );
        }
        if !has_w && self.engine.needs_gyro() {
            return fail(
                InertiaStatus::Data,
                format_args!("this estimator needs gyro rates (has_w) in every sample"),
            );
        }
        if let (Some(t0), 1) = (self.last_t_s, self.samples) {
            if let Err(e) = check_first_step(self.memory_s, self.resample_s, s.t_s - t0) {
                return fail(
                    InertiaStatus::InvalidSetting,
                    format_args!("sample 1: {e}{}", fixes(&[Fix::Memory])),
                );
            }
        }
        if let Some(t0) = self.last_t_s {
            if !(s.t_s > t0) {
                return fail(
                    InertiaStatus::Data,
                    format_args!(
                        "sample {}: time {} s does not increase (previous {} s)",
                        self.samples,
                        inertia::text::Num(s.t_s),
                        inertia::text::Num(t0)
                    ),
                );
            }
        }
        let mut sample = Sample {
            t_s: s.t_s,
            q: inertia::attitude::Quaternion::from_xyzw(s.q),
            rho_nms: Vector3::from(s.rho_nms),
            tau_nm: Vector3::from(s.tau_nm),
            omega_rad_s: has_w.then(|| Vector3::from(s.w_rad_s)),
        };
        if let Err(e) = check_range(&sample) {
            return fail(
                InertiaStatus::OutOfRange,
                format_args!("sample {}: {e}", self.samples),
            );
        }
        sample.q = engine::unit(s.q);
        self.has_w = Some(has_w);
        self.last_t_s = Some(s.t_s);
        self.samples += 1;
        match self.engine.push(&sample) {
            Ok(Some(e)) => {
                self.last = Some(e);
                InertiaStatus::Ok
            }
            Ok(None) => InertiaStatus::Ok,
            Err(e) => {
                self.stopped = true;
                pipeline_fail(&e)
            }
        }
    }

    fn reset(&mut self) -> InertiaStatus {
        // Stopped until the reset succeeds.
        self.stopped = true;
        if let Err(e) = self.engine.reset() {
            return pipeline_fail(&e);
        }
        self.stopped = false;
        self.has_w = None;
        self.last_t_s = None;
        self.samples = 0;
        self.last = None;
        InertiaStatus::Ok
    }

    fn estimate(&self) -> InertiaEstimate {
        let nan = f64::NAN;
        let mut out = InertiaEstimate {
            status: InertiaEstimateStatus::None,
            reason: InertiaReason::None,
            has_answer: 0,
            has_sigma: 0,
            t_s: nan,
            j: [nan; 6],
            inertia: [[nan; 3]; 3],
            sigma: [nan; 6],
            condition: nan,
            rows: 0,
            samples: self.samples,
            prior_data_share: [nan; 6],
            prior_chi2: nan,
        };
        let Some(e) = self.last else { return out };
        out.t_s = e.t_s;
        out.rows = e.rows as u64;
        out.status = match e.observability {
            Observability::Determined { .. } => InertiaEstimateStatus::Determined,
            Observability::FromPrior(_) => InertiaEstimateStatus::FromPrior,
            Observability::NotObservable(_) => InertiaEstimateStatus::NotObservable,
            _ => InertiaEstimateStatus::Unchecked,
        };
        out.reason = e.observability.reason().map_or(InertiaReason::None, reason);
        if let Some(c) = e.observability.condition() {
            out.condition = c;
        }
        if let Some(j) = e.j() {
            out.has_answer = 1;
            out.j = core::array::from_fn(|k| j[k]);
            let m = matrix_from_j(&j);
            out.inertia = core::array::from_fn(|r| core::array::from_fn(|c| m[(r, c)]));
        }
        if let Some(s) = e.sigma_kg_m2() {
            out.has_sigma = 1;
            out.sigma = s;
        }
        if let Some(p) = e.prior {
            out.prior_chi2 = p.chi2;
            out.prior_data_share = p.data_share.map(|d| d.unwrap_or(f64::NAN));
        }
        out
    }
}

fn reason(r: Unobservable) -> InertiaReason {
    match r {
        Unobservable::NoExcitation => InertiaReason::NoExcitation,
        Unobservable::RankDeficient { .. } => InertiaReason::RankDeficient,
        Unobservable::Uncertain { .. } => InertiaReason::Uncertain,
        Unobservable::NoiseDominated => InertiaReason::NoiseDominated,
        Unobservable::Diverged => InertiaReason::Diverged,
        Unobservable::AtFloor { .. } => InertiaReason::AtFloor,
        Unobservable::ConflictsWithConstraints { .. } => InertiaReason::ConflictsWithConstraints,
        Unobservable::SourcesDisagree { .. } => InertiaReason::SourcesDisagree,
        Unobservable::Inconsistent { .. } => InertiaReason::Inconsistent,
        Unobservable::DensityOverstated { .. } => InertiaReason::DensityOverstated,
        Unobservable::IllConditioned { .. } => InertiaReason::IllConditioned,
        Unobservable::PriorConflict { .. } => InertiaReason::PriorConflict,
        Unobservable::NotPhysical { .. } => InertiaReason::NotPhysical,
        _ => InertiaReason::Other,
    }
}

/// Run `f` with panics caught: a panic becomes `INERTIA_STATUS_PANIC` with its message.
fn guard(f: impl FnOnce() -> InertiaStatus) -> InertiaStatus {
    guard_or(InertiaStatus::Panic, f)
}

/// Run `f` with panics caught: a panic records its message and gives `on_panic`.
fn guard_or<T>(on_panic: T, f: impl FnOnce() -> T) -> T {
    match std::panic::catch_unwind(AssertUnwindSafe(f)) {
        Ok(s) => s,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .copied()
                .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
                .unwrap_or("(no message)");
            record(format_args!("internal error (a bug in inertia): {what}"));
            on_panic
        }
    }
}

/// The default settings: the discrete momentum estimator, the physical constraint set,
/// no bounds, no memory, no resampling, no gyro-noise compensation, σ on, torque bias on,
/// chains of 30 s, glitches stop the run (the CLI's `estimate` defaults). For caller
/// storage set `estimator = INERTIA_ESTIMATOR_KIND_VARIATIONAL`.
#[no_mangle]
pub extern "C" fn inertia_settings_default() -> InertiaSettings {
    InertiaSettings {
        estimator: InertiaEstimatorKind::DiscreteMomentum as u32,
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
    }
}

/// Create an estimator on the heap (any estimator). On success `*out` holds it; free it
/// with `inertia_estimator_free`. On failure `*out` is set to NULL (when `out` is not
/// NULL).
///
/// # Safety
/// `settings` is NULL or points to an `InertiaSettings`; `out` is NULL or points to
/// writable storage for a pointer.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_new(
    settings: *const InertiaSettings,
    out: *mut *mut InertiaEstimator,
) -> InertiaStatus {
    guard(|| {
        if out.is_null() || settings.is_null() {
            return null("inertia_estimator_new: `settings` and `out` must not be NULL");
        }
        // SAFETY: `out` is non-null and, by the contract, points to a writable pointer.
        unsafe { out.write(core::ptr::null_mut()) };
        // SAFETY: `settings` is non-null and, by the contract, points to an
        // `InertiaSettings`; every field type accepts any bit pattern (no enums, no bool).
        let s = unsafe { settings.read() };
        let plan = match Plan::from_c(&s) {
            Ok(p) => p,
            Err(status) => return status,
        };
        let settings = plan.pipeline_settings();
        let pipeline = match Pipeline::new(&settings) {
            Ok(p) => p,
            Err(e) => return pipeline_fail(&e),
        };
        let est = Box::new(InertiaEstimator::new(
            Engine::Pipeline { pipeline, settings },
            true,
            &plan,
        ));
        // SAFETY: as above, `out` is valid for writes.
        unsafe { out.write(Box::into_raw(est)) };
        InertiaStatus::Ok
    })
}

/// Bytes of storage `inertia_estimator_init` needs.
#[no_mangle]
pub extern "C" fn inertia_estimator_size() -> usize {
    size_of::<InertiaEstimator>()
}

/// Alignment, bytes, of the storage `inertia_estimator_init` needs.
#[no_mangle]
pub extern "C" fn inertia_estimator_align() -> usize {
    align_of::<InertiaEstimator>()
}

/// Build an estimator in caller storage, with no heap allocation then or later: the
/// `variational` or `finite-difference` estimator (any other is
/// `INERTIA_STATUS_NEEDS_HEAP`). `storage` must hold `inertia_estimator_size()` bytes
/// aligned to `inertia_estimator_align()`. On success `*out` is the estimator (it
/// points into `storage`); end it with `inertia_estimator_free` (which frees nothing,
/// and drops nothing that holds memory) before reusing the storage.
///
/// # Safety
/// `storage` is NULL or valid for writes of `len` bytes, not used by anything else while
/// the estimator lives; `settings` is NULL or points to an `InertiaSettings`; `out` is
/// NULL or points to writable storage for a pointer.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_init(
    storage: *mut c_void,
    len: usize,
    settings: *const InertiaSettings,
    out: *mut *mut InertiaEstimator,
) -> InertiaStatus {
    guard(|| {
        if storage.is_null() || settings.is_null() || out.is_null() {
            return null(
                "inertia_estimator_init: `storage`, `settings` and `out` must not be NULL",
            );
        }
        // SAFETY: `out` is non-null and points to a writable pointer (contract).
        unsafe { out.write(core::ptr::null_mut()) };
        if len < inertia_estimator_size() || !storage.cast::<InertiaEstimator>().is_aligned() {
            return fail(
                InertiaStatus::BadStorage,
                format_args!(
                    "inertia_estimator_init: storage of {len} bytes at an address aligned to {}: needs {} bytes aligned to {}",
                    1usize << (storage as usize).trailing_zeros().min(63),
                    inertia_estimator_size(),
                    inertia_estimator_align()
                ),
            );
        }
        // SAFETY: non-null, points to an `InertiaSettings` (contract); all field types
        // accept any bit pattern.
        let s = unsafe { settings.read() };
        let (plan, engine) = match Plan::from_c(&s).and_then(|p| Ok((p.fixed_engine()?, p))) {
            Ok((e, p)) => (p, e),
            Err(status) => return status,
        };
        let est = storage.cast::<InertiaEstimator>();
        // SAFETY: `storage` is non-null, aligned and at least `size_of::<InertiaEstimator>()`
        // bytes long (checked above) and valid for writes (contract); `write` does not
        // read or drop what was there.
        unsafe { est.write(InertiaEstimator::new(engine, false, &plan)) };
        // SAFETY: `out` is valid for writes (contract).
        unsafe { out.write(est) };
        InertiaStatus::Ok
    })
}

fn null(what: &str) -> InertiaStatus {
    fail(InertiaStatus::NullPointer, format_args!("{what}"))
}

/// Push one sample. An estimate is formed when the sample completes a row block and a
/// solve is due; read it with `inertia_estimator_get`. Refused samples (NULL, NaN,
/// outside the supported range, time not increasing, `has_w` changing) leave the
/// estimator as it was. Other data errors (`INERTIA_STATUS_DATA`, `_SOLVER`) stop it
/// until `inertia_estimator_reset`.
///
/// # Safety
/// `est` is NULL or an estimator from `inertia_estimator_new`/`_init` not yet freed, not
/// used concurrently; `sample` is NULL or points to an `InertiaSample`.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_push(
    est: *mut InertiaEstimator,
    sample: *const InertiaSample,
) -> InertiaStatus {
    // SAFETY: by the contract a non-null `est` is a live estimator used by no one else.
    let Some(e) = (unsafe { est.as_mut() }) else {
        return null("inertia_estimator_push: `est` must not be NULL");
    };
    if sample.is_null() {
        return null("inertia_estimator_push: `sample` must not be NULL");
    }
    // SAFETY: non-null, points to an `InertiaSample` (contract); its fields accept any
    // bit pattern.
    let s = unsafe { sample.read() };
    let status = guard(|| e.push(&s));
    if status == InertiaStatus::Panic {
        // A panic may have left the state half-updated: stopped until reset.
        e.stopped = true;
    }
    status
}

/// Copy the current estimate into `*out` (status `INERTIA_ESTIMATE_STATUS_NONE` before
/// the first).
///
/// # Safety
/// `est` is NULL or a live estimator; `out` is NULL or points to writable storage for an
/// `InertiaEstimate`.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_get(
    est: *const InertiaEstimator,
    out: *mut InertiaEstimate,
) -> InertiaStatus {
    // SAFETY: a non-null `est` is a live estimator (contract).
    let Some(e) = (unsafe { est.as_ref() }) else {
        return null("inertia_estimator_get: `est` must not be NULL");
    };
    if out.is_null() {
        return null("inertia_estimator_get: `out` must not be NULL");
    }
    guard(|| {
        let estimate = e.estimate();
        // SAFETY: `out` is non-null and valid for writes (contract).
        unsafe { out.write(estimate) };
        InertiaStatus::Ok
    })
}

/// Copy the reason of the current estimate in words (empty when there is none) into
/// `buf` (`len` bytes, always NUL-terminated when `len > 0`, cut at a character
/// boundary). Returns the length of the whole message without the NUL, like
/// `snprintf`.
///
/// # Safety
/// `est` is NULL or a live estimator; `buf` is NULL or valid for writes of `len` bytes.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_reason(
    est: *const InertiaEstimator,
    buf: *mut c_char,
    len: usize,
) -> usize {
    // SAFETY: a non-null `est` is a live estimator (contract).
    let Some(e) = (unsafe { est.as_ref() }) else {
        return 0;
    };
    guard_or(0, || {
        let mut m = message::Buffer::new();
        if let Some(r) = e.last.and_then(|l| l.observability.reason()) {
            let _ = write!(m, "{r}");
        }
        // SAFETY: `buf` is NULL or valid for `len` bytes (contract).
        unsafe { m.copy_to(buf, len) }
    })
}

/// Start again from no data with the same settings (also clears a stop). Allocates for a
/// heap estimator (the pipeline is rebuilt); not in caller storage.
///
/// # Safety
/// `est` is NULL or a live estimator not used concurrently.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_reset(est: *mut InertiaEstimator) -> InertiaStatus {
    // SAFETY: a non-null `est` is a live estimator used by no one else (contract).
    let Some(e) = (unsafe { est.as_mut() }) else {
        return null("inertia_estimator_reset: `est` must not be NULL");
    };
    guard(|| e.reset())
}

/// End an estimator: free it when `inertia_estimator_new` made it; for one in caller
/// storage, end it in place (the storage is the caller's again). NULL is ignored.
///
/// # Safety
/// `est` is NULL or a live estimator, not used again afterwards.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_free(est: *mut InertiaEstimator) {
    if est.is_null() {
        return;
    }
    let _ = guard(|| {
        // SAFETY: `est` is a live estimator (contract); reading `heap` is a plain read.
        let heap = unsafe { (*est).heap };
        if heap {
            // SAFETY: `heap` means `est` came from `Box::into_raw` in
            // `inertia_estimator_new`, and it is not used again (contract).
            drop(unsafe { Box::from_raw(est) });
        } else {
            // SAFETY: `est` was written in place by `inertia_estimator_init` and is not
            // used again (contract): drop it where it is, without deallocating.
            unsafe { core::ptr::drop_in_place(est) };
        }
        InertiaStatus::Ok
    });
}

/// Copy the message of the last error on this thread into `buf` (`len` bytes, always
/// NUL-terminated when `len > 0`, cut at a character boundary). Returns the length of the
/// whole message without the NUL (0 when there was no error), like `snprintf`: a return
/// value `>= len` means it was cut.
///
/// # Safety
/// `buf` is NULL or valid for writes of `len` bytes.
#[no_mangle]
pub unsafe extern "C" fn inertia_last_error_message(buf: *mut c_char, len: usize) -> usize {
    // SAFETY: forwarded contract.
    guard_or(0, || unsafe { message::last_to(buf, len) })
}

/// The name of a status code (a static string, e.g. `"INERTIA_STATUS_DATA"`;
/// `"INERTIA_STATUS_UNKNOWN"` for a value that is none).
#[no_mangle]
pub extern "C" fn inertia_status_name(status: i32) -> *const c_char {
    use InertiaStatus as S;
    let all = [
        S::Ok,
        S::NullPointer,
        S::NotFinite,
        S::OutOfRange,
        S::InvalidSetting,
        S::BadStorage,
        S::NeedsHeap,
        S::Data,
        S::Solver,
        S::Stopped,
        S::Panic,
    ];
    let Some(status) = all.into_iter().find(|s| *s as i32 == status) else {
        return c"INERTIA_STATUS_UNKNOWN".as_ptr();
    };
    let s: &'static core::ffi::CStr = match status {
        InertiaStatus::Ok => c"INERTIA_STATUS_OK",
        InertiaStatus::NullPointer => c"INERTIA_STATUS_NULL_POINTER",
        InertiaStatus::NotFinite => c"INERTIA_STATUS_NOT_FINITE",
        InertiaStatus::OutOfRange => c"INERTIA_STATUS_OUT_OF_RANGE",
        InertiaStatus::InvalidSetting => c"INERTIA_STATUS_INVALID_SETTING",
        InertiaStatus::BadStorage => c"INERTIA_STATUS_BAD_STORAGE",
        InertiaStatus::NeedsHeap => c"INERTIA_STATUS_NEEDS_HEAP",
        InertiaStatus::Data => c"INERTIA_STATUS_DATA",
        InertiaStatus::Solver => c"INERTIA_STATUS_SOLVER",
        InertiaStatus::Stopped => c"INERTIA_STATUS_STOPPED",
        InertiaStatus::Panic => c"INERTIA_STATUS_PANIC",
    };
    s.as_ptr()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_a_status_and_a_message() {
        let status = guard(|| panic!("boom {}", 42));
        assert_eq!(status, InertiaStatus::Panic);
        let mut buf = [0u8; 128];
        // SAFETY: `buf` is writable for its length.
        let n = unsafe { inertia_last_error_message(buf.as_mut_ptr().cast(), buf.len()) };
        let text = core::str::from_utf8(&buf[..n]).unwrap();
        assert_eq!(text, "internal error (a bug in inertia): boom 42");
        assert_eq!(guard_or(7usize, || panic!("again")), 7);
    }

    #[test]
    fn messages_are_cut_at_character_boundaries() {
        let mut m = message::Buffer::new();
        let long = "é".repeat(message::CAPACITY); // 2 bytes each
        write!(m, "{long}").unwrap();
        let mut out = [0xFFu8; 6];
        // SAFETY: `out` is writable for its length.
        let n = unsafe { m.copy_to(out.as_mut_ptr().cast(), out.len()) };
        assert_eq!(n, 2 * message::CAPACITY);
        // 5 bytes of room: two whole "é" and the NUL.
        assert_eq!(&out[..5], "éé\0".as_bytes());
        let mut empty = [0xFFu8; 1];
        // SAFETY: as above.
        unsafe { m.copy_to(empty.as_mut_ptr().cast(), 1) };
        assert_eq!(empty[0], 0);
    }
}
