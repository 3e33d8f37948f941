//! The estimation pipeline: everything an estimate needs, behind one type. The command
//! line tool, and the Python and C bindings, call only this.
//!
//! ```text
//! PipelineSettings ──validate──▶ PipelineConfig ──▶ Pipeline
//!   estimator (by name)            registry entries      samples ─▶ [resample] ─▶ estimator ─▶ Estimate
//!   solver backend (by name)       validated constraints                                       (J, status, σ,
//!   constraints, memory_s, …       gyro noise in rad/s/√Hz                                     solver diagnostics)
//! ```
//!
//! * The estimator and the solver backend are chosen at run time by name from
//!   [`registry::ESTIMATORS`] and [`registry::BACKENDS`].
//! * Memory is a time constant in seconds; each row block is weighed by the time that
//!   actually passed ([`crate::estimator::recursive::RecursiveSettings::memory_s`]), so
//!   jitter, gaps and resampling need no conversion.
//! * Every estimator returns the same [`Estimate`]: J, status with its reason, σ where the
//!   estimator has an uncertainty model, and the solver's diagnostics.
//!
//! ```
//! use inertia::constraints::ConstraintSet;
//! use inertia::pipeline::{Pipeline, PipelineSettings};
//! use inertia::sim::scenario::{Common, Scenario};
//! use inertia::tensor::Component;
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let run = Scenario::slew().simulate(&Common { duration_s: Some(120.0), ..Common::paper() })?;
//! let mut pipeline = Pipeline::new(&PipelineSettings {
//!     estimator: "discrete-momentum".into(),            // the default; or "variational" (the paper's), "finite-difference", "momentum"
//!     solver: "native".into(),                          // or "clarabel" (feature)
//!     constraints: ConstraintSet::positive_definite()   // J ⪰ εI (the default, physical(), adds Σ ⪰ 0,
//!         .with_nominal(Component::J33, 3.0, 0.10),     // which the paper's J breaks by 2.5e-5); J33 within 10 % of 3 kg m²
//!     memory_s: Some(600.0),                            // forget with a 600 s time constant
//!     gyro_noise_deg_s_rthz: Some(1e-5),                // errors-in-variables compensation
//!     ..PipelineSettings::default()
//! })?;                                                  // bad settings fail here, typed
//! for sample in &run.samples {
//!     if let Some(e) = pipeline.push(sample)? {
//!         // e.observability: determined, from the prior, or not (with the reason);
//!         // e.inertia() is None without an answer; e.uncertainty holds σ per element.
//!     }
//! }
//! let e = pipeline.last().unwrap();
//! assert_eq!(e.within_3sigma(&run.inertia_kg_m2), Some(true));
//! # Ok(())
//! # }
//! ```

mod checks;
mod diagnostics;
pub mod registry;
mod run;
mod settings;
pub mod status;

#[cfg(feature = "csv")]
pub mod history;
#[cfg(feature = "serde")]
pub mod report;

pub use crate::estimators::constrained::Constrained;
pub use checks::AttitudeChecks;
pub use diagnostics::Diagnostics;
pub(crate) use registry::Estimator;
pub use registry::{BatchOutput, Capabilities};
pub use run::{check_first_step, Run, RunError, RunErrorKind, RECENT};
pub use settings::{
    parse_wheel_delay, InertialTorque, PipelineConfig, PipelineSettings, DEFAULT_MAX_CHAIN_S,
};

use crate::constraints::ConstraintError;
use crate::estimator::resample::Resampler;
use crate::estimator::{Estimate, EstimatorError, InvalidArgument};
use crate::fix::Fix;
use crate::sample::{check_range, OutOfRange, Sample};
use crate::telemetry::convention::{ConventionCheck, Verdict};
use crate::telemetry::glitch::{Glitch, GlitchCheck, GlitchPolicy};
use std::boxed::Box;
use std::string::String;

/// Why a pipeline cannot be built or cannot go on.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PipelineError {
    /// No estimator of that name.
    #[error("unknown estimator `{name}` (known: {})", registry::estimator_names())]
    UnknownEstimator {
        /// The name given.
        name: String,
    },
    /// No solver backend of that name.
    #[error("unknown solver `{name}` (known: {})", registry::backend_names())]
    UnknownSolver {
        /// The name given.
        name: String,
    },
    /// The backend exists but not in this build.
    #[error("solver `{name}`: {why}")]
    SolverUnavailable {
        /// Backend name.
        name: &'static str,
        /// Why.
        why: &'static str,
    },
    /// A setting is out of range.
    #[error("setting `{field}` = {} is invalid: expected {expected}", crate::text::Num(*.value))]
    InvalidSetting {
        /// The setting.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A setting named a value it does not have.
    #[error("setting `{setting}`: unknown value `{}` (known: {expected})", crate::text::Clipped::new(.value))]
    UnknownChoice {
        /// The setting.
        setting: &'static str,
        /// The value given.
        value: String,
        /// The values it has.
        expected: &'static str,
    },
    /// A setting that needs another one.
    #[error("setting `{setting}` needs `{needs}` {requirement}: {why}")]
    NeedsSetting {
        /// The setting.
        setting: &'static str,
        /// The setting it needs.
        needs: &'static str,
        /// What that one must be (`"> 0"`, `"on"`).
        requirement: &'static str,
        /// Why.
        why: &'static str,
    },
    /// A setting the chosen estimator does not use (rather than ignore it silently).
    #[error("setting `{setting}` does not apply to the {estimator} estimator")]
    NotApplicable {
        /// The setting.
        setting: &'static str,
        /// The estimator.
        estimator: &'static str,
    },
    /// The estimator has no batch form.
    #[error("the {estimator} estimator has no batch form")]
    NoBatch {
        /// The estimator.
        estimator: &'static str,
    },
    /// The attitude disagrees with the gyro rates, and another reading of the quaternion
    /// columns agrees ([`crate::telemetry::convention`]).
    #[error("the attitude quaternions disagree with the gyro rates (median relative mismatch {as_read:.2} over {steps} steps; {fixed:.2e} when read differently): {fix}")]
    AttitudeConvention {
        /// The fix, in words.
        fix: &'static str,
        /// The fix, typed ([`Self::fixes`]).
        fixes: &'static [Fix],
        /// Median relative mismatch as read.
        as_read: f64,
        /// Median relative mismatch with the fix.
        fixed: f64,
        /// Steps compared.
        steps: usize,
    },
    /// The data fit a negative-definite J whose negation would be determined
    /// ([`Unobservable::AtFloor`] with `mirror_determined`): the wheel momentum ρ has the
    /// opposite sign of this library's convention (the rotors' own momentum, body axes,
    /// docs/conventions.md §1), or so has the known torque τ; until gyro rates have
    /// confirmed the quaternion convention, a conjugated quaternion cannot be ruled out.
    ///
    /// [`Unobservable::AtFloor`]: crate::estimator::observability::Unobservable::AtFloor
    #[error("{}", checks::ReversedMessage { sample, tau_given, quaternions })]
    ReversedMomentum {
        /// 0-based index of the input sample whose estimate showed it (`None`: a batch
        /// answer, from the whole record).
        sample: Option<usize>,
        /// Whether the telemetry had a non-zero known torque.
        tau_given: bool,
        /// The quaternion convention check's verdict: [`Verdict::Consistent`] where the
        /// gyro rates confirmed it (then only the sign of ρ or τ is left).
        quaternions: Verdict,
    },
    /// One step of the attitude jumps against the gyro ([`crate::telemetry::glitch`]),
    /// and the policy is [`GlitchPolicy::Stop`].
    #[error("{glitch} (the step ends at this line; keep glitches to estimate anyway)")]
    AttitudeGlitch {
        /// 0-based index of the input sample that ends the step.
        sample: usize,
        /// The step.
        glitch: Glitch,
    },
    /// A sample holds a value outside the supported range ([`crate::sample::range`]).
    #[error("input sample {sample}: {source}")]
    OutOfRange {
        /// 0-based index of the input sample.
        sample: usize,
        /// Which value, and how far out.
        source: OutOfRange,
    },
    /// Resampling would put more than [`MAX_RESAMPLE_FACTOR`] samples in one input step.
    #[error("input sample {sample}: resampling to {} s would make {} samples of the step of {} s (at most {})", crate::text::Num(*.period_s), crate::text::Num((*.step_s / *.period_s).round()), crate::text::Num(*.step_s), crate::text::Num(MAX_RESAMPLE_FACTOR))]
    ResampleTooFine {
        /// 0-based index of the input sample that ends the step.
        sample: usize,
        /// The step, s.
        step_s: f64,
        /// The resampling period, s.
        period_s: f64,
    },
    /// The constraint set is unusable.
    #[error("constraints: {0}")]
    Constraints(#[from] ConstraintError),
    /// The estimator stopped on the data.
    #[error("{}{source}", sample.map(|s| std::format!("input sample {s}: ")).unwrap_or_default())]
    Estimator {
        /// 0-based index of the input sample that stopped it, when one did.
        sample: Option<usize>,
        /// What went wrong.
        source: EstimatorError,
    },
}

impl PipelineError {
    /// The settings its message recommends changing ([`crate::fix`]), in its order.
    #[must_use]
    pub fn fixes(&self) -> &'static [Fix] {
        match self {
            PipelineError::AttitudeConvention { fixes, .. } => fixes,
            PipelineError::ReversedMomentum { quaternions, .. } => match quaternions {
                Verdict::Consistent(_) => &[Fix::NegateRho],
                _ => &[Fix::NegateRho, Fix::Conjugate],
            },
            PipelineError::AttitudeGlitch { .. } => &[Fix::KeepGlitches],
            PipelineError::ResampleTooFine { .. } => &[Fix::Resample],
            _ => &[],
        }
    }

    /// Its kind, as every front end reports it.
    #[must_use]
    pub fn error_kind(&self) -> crate::error_kind::ErrorKind {
        use crate::error_kind::ErrorKind as K;
        match self {
            PipelineError::AttitudeConvention { .. } => K::AttitudeConvention,
            PipelineError::ReversedMomentum { .. } => K::ReversedMomentum,
            PipelineError::AttitudeGlitch { .. } => K::AttitudeGlitch,
            PipelineError::OutOfRange { .. } => K::OutOfRange,
            PipelineError::Estimator { source, .. } => match source {
                EstimatorError::Solve(_) => K::Solver,
                EstimatorError::TooFewSamples { .. } => K::TooFewSamples,
                EstimatorError::Row { .. } => K::Row,
                _ => K::InvalidSetting,
            },
            _ => K::InvalidSetting,
        }
    }

    pub(crate) fn from_argument(a: InvalidArgument) -> Self {
        PipelineError::InvalidSetting {
            field: a.name,
            value: a.value,
            expected: a.expected,
        }
    }
}

impl PipelineError {
    /// For a step too large for the rows (`|φ| ≥ 1`), the time its end sample has, s,
    /// and otherwise `None`: how a caller that holds the samples' lines finds the line to
    /// name ([`Self::ends_step`]); the estimator may be behind the reader (resampling
    /// reads ahead, the half-rate shadow's step ends at a later sample).
    #[must_use]
    pub(crate) fn step_end_s(&self) -> Option<f64> {
        match self {
            PipelineError::Estimator {
                source:
                    EstimatorError::Row {
                        source: crate::discrete::RowError::StepTooLarge { t1_s, .. },
                        ..
                    },
                ..
            } => Some(*t1_s),
            _ => None,
        }
    }

    /// Whether a sample at `t_s` is at or after the step end `step_end_s` (to 1e-9 of its
    /// size): the first such sample ends the step.
    #[must_use]
    pub(crate) fn ends_step(t_s: f64, step_end_s: f64) -> bool {
        t_s >= step_end_s - 1e-9 * (1.0 + step_end_s.abs())
    }
}

/// An estimator fed sample by sample, with optional resampling in front.
pub struct Pipeline {
    config: PipelineConfig,
    resampler: Option<Resampler>,
    estimator: Box<dyn Estimator>,
    input_samples: usize,
    estimator_samples: usize,
    last: Option<Estimate>,
    checks: AttitudeChecks,
    /// The previous input sample's time and the step that ended at it.
    previous: Option<(f64, Option<f64>)>,
}

/// Most resampled samples per input step (`resample_s`): a finer grid is refused
/// ([`PipelineError::ResampleTooFine`]) rather than left to produce billions of samples.
pub const MAX_RESAMPLE_FACTOR: f64 = 100.0;

impl core::fmt::Debug for Pipeline {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Pipeline")
            .field("config", &self.config)
            .field("input_samples", &self.input_samples)
            .field("last", &self.last)
            .finish_non_exhaustive()
    }
}

impl Pipeline {
    /// Validate `settings` and build the pipeline.
    pub fn new(settings: &PipelineSettings) -> Result<Self, PipelineError> {
        Self::from_config(settings.validate()?)
    }

    /// Build from an already validated configuration.
    pub fn from_config(config: PipelineConfig) -> Result<Self, PipelineError> {
        config.check_no_wheel_delay()?;
        let resampler = config
            .resample_s
            .map(Resampler::new)
            .transpose()
            .map_err(PipelineError::from_argument)?;
        Ok(Self {
            estimator: (config.estimator.build)(&config)?,
            config,
            resampler,
            input_samples: 0,
            estimator_samples: 0,
            last: None,
            checks: AttitudeChecks::default(),
            previous: None,
        })
    }

    /// Feed one input sample. Returns the newest estimate it produced (resampling can
    /// produce several, or none; [`Self::push_each`] sees every one).
    pub fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, PipelineError> {
        let mut newest = None;
        self.push_each(s, |e| newest = Some(*e))?;
        Ok(newest)
    }

    /// Feed one input sample; `on_estimate` receives every estimate it produced, in time
    /// order.
    pub fn push_each(
        &mut self,
        s: &Sample,
        mut on_estimate: impl FnMut(&Estimate),
    ) -> Result<(), PipelineError> {
        let index = self.input_samples;
        check_range(s).map_err(|source| PipelineError::OutOfRange {
            sample: index,
            source,
        })?;
        if let (Some(h), Some((t0, before))) = (self.config.resample_s, self.previous) {
            let step = s.t_s - t0;
            // A gap restarts the grid: nothing is interpolated across it.
            let gap = before.is_some_and(|b| crate::sample::is_gap(b, step));
            if !gap && step / h > MAX_RESAMPLE_FACTOR {
                return Err(PipelineError::ResampleTooFine {
                    sample: index,
                    step_s: step,
                    period_s: h,
                });
            }
        }
        // As the resampler sees it: the step after a gap (or the first) has no previous
        // step to be a gap against.
        self.previous = Some((
            s.t_s,
            self.previous.and_then(|(t0, before)| {
                let step = s.t_s - t0;
                (!before.is_some_and(|b| crate::sample::is_gap(b, step))).then_some(step)
            }),
        ));
        self.checks.push(index, s, self.config.glitches)?;
        self.input_samples += 1;
        let Self {
            resampler,
            estimator,
            estimator_samples,
            last,
            checks,
            config,
            ..
        } = self;
        let mut feed = |u: &Sample| -> Result<(), PipelineError> {
            *estimator_samples += 1;
            let e = estimator
                .push(u)
                .map_err(|source| PipelineError::Estimator {
                    sample: Some(index),
                    source,
                })?;
            if let Some(mut e) = e {
                status::apply(&mut e, config);
                checks.estimate(index, &e)?;
                *last = Some(e);
                on_estimate(&e);
            }
            Ok(())
        };
        match resampler {
            None => feed(s),
            Some(r) => {
                let mut result = Ok(());
                r.push(s, |u| {
                    if result.is_ok() {
                        result = feed(&u);
                    }
                });
                result
            }
        }
    }

    /// The steps where the attitude jumped against the gyro, kept under
    /// [`GlitchPolicy::Keep`] ([`crate::telemetry::glitch`]).
    #[must_use]
    pub fn glitches(&self) -> &GlitchCheck {
        self.checks.glitches()
    }

    /// How the attitude compares with the gyro rates so far
    /// ([`crate::telemetry::convention`]).
    #[must_use]
    pub fn attitude_check(&self) -> Verdict {
        self.checks.verdict()
    }

    /// The newest estimate.
    #[must_use]
    pub fn last(&self) -> Option<&Estimate> {
        self.last.as_ref()
    }

    /// What the estimator can say about the run at its latest estimate: gaps, excitation,
    /// row model, torque and residual tests ([`Diagnostics`]).
    #[must_use]
    pub fn diagnostics(&self) -> Diagnostics {
        self.estimator.diagnostics()
    }

    /// Input samples fed.
    #[must_use]
    pub fn input_samples(&self) -> usize {
        self.input_samples
    }

    /// Samples the estimator saw (after resampling).
    #[must_use]
    pub(crate) fn estimator_samples(&self) -> usize {
        self.estimator_samples
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &PipelineConfig {
        &self.config
    }
}

/// Estimate from all samples at once (eq. 57) with the configured estimator, which must
/// have a batch form. Memory and resampling do not apply.
pub fn batch(samples: &[Sample], config: &PipelineConfig) -> Result<BatchOutput, PipelineError> {
    config.check_no_wheel_delay()?;
    let run = batch_applies(config)?;
    let mut check = ConventionCheck::default();
    let mut glitches = GlitchCheck::default();
    let mut tau_given = false;
    for (sample, s) in samples.iter().enumerate() {
        check_range(s).map_err(|source| PipelineError::OutOfRange { sample, source })?;
        check.push(s);
        tau_given |= s.tau_nm != nalgebra::Vector3::zeros();
        if let Some(glitch) = glitches.push(s) {
            if config.glitches == GlitchPolicy::Stop {
                return Err(PipelineError::AttitudeGlitch { sample, glitch });
            }
        }
    }
    checks::convention_error(&check)?;
    let mut out = run(samples, config)?;
    status::apply(&mut out.estimate, config);
    checks::reversed_momentum(&out.estimate, None, tau_given, || check.verdict())?;
    Ok(out)
}

/// The configured estimator's batch form, where the settings allow one: it must have one,
/// and memory and resampling do not apply.
pub(crate) fn batch_applies(config: &PipelineConfig) -> Result<registry::BatchFn, PipelineError> {
    let entry = config.estimator;
    for (setting, set) in [
        ("memory_s", config.memory_s.is_some()),
        ("resample_s", config.resample_s.is_some()),
    ] {
        if set {
            return Err(PipelineError::NotApplicable {
                setting,
                estimator: "batch",
            });
        }
    }
    entry.batch.ok_or(PipelineError::NoBatch {
        estimator: entry.name,
    })
}
