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
pub(crate) mod config;
pub(crate) mod diagnostics;
pub(crate) mod error;
pub(crate) mod interface;
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
pub use config::{InertialTorque, PipelineConfig};
pub use diagnostics::Diagnostics;
pub use error::{PipelineError, MAX_RESAMPLE_FACTOR};
pub(crate) use interface::Estimator;
pub use interface::{BatchOutput, Capabilities};
pub use run::{check_first_step, Run, RunError, RunErrorKind, MIN_MOMENTUM_SIGNIFICANCE, RECENT};
pub use settings::{parse_wheel_delay, PipelineSettings, DEFAULT_MAX_CHAIN_S};

use crate::estimator::resample::Resampler;
use crate::estimator::Estimate;
use crate::sample::{check_range, Sample};
use crate::telemetry::convention::{ConventionCheck, Verdict};
use crate::telemetry::glitch::{GlitchCheck, GlitchPolicy};
use std::boxed::Box;

/// An estimator fed sample by sample, with optional resampling in front.
pub struct Pipeline {
    config: PipelineConfig,
    resampler: Option<Resampler>,
    estimator: Box<dyn Estimator>,
    input_samples: usize,
    estimator_samples: usize,
    last: Option<Estimate>,
    /// The newest estimate before the status rules ([`status::apply`]).
    last_unsettled: Option<Estimate>,
    checks: AttitudeChecks,
    /// The previous input sample's time and the step that ended at it.
    previous: Option<(f64, Option<f64>)>,
}

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
        config.check_no_calibration()?;
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
            last_unsettled: None,
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
            last_unsettled,
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
                *last_unsettled = Some(e);
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

    /// End of input: the estimator's answer at its last completed row block, where rows
    /// came after its last solve (`solve_every` > 1; [`interface::Estimator::flush`]),
    /// given to `on_estimate` as a pushed sample's would be.
    pub(crate) fn flush(
        &mut self,
        mut on_estimate: impl FnMut(&Estimate),
    ) -> Result<(), PipelineError> {
        let e = self
            .estimator
            .flush()
            .map_err(|source| PipelineError::Estimator {
                sample: None,
                source,
            })?;
        if let Some(mut e) = e {
            self.last_unsettled = Some(e);
            status::apply(&mut e, &self.config);
            self.checks
                .estimate(self.input_samples.saturating_sub(1), &e)?;
            self.last = Some(e);
            on_estimate(&e);
        }
        Ok(())
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
    pub(crate) fn attitude_check(&self) -> Verdict {
        self.checks.verdict()
    }

    /// The newest estimate.
    #[must_use]
    pub fn last(&self) -> Option<&Estimate> {
        self.last.as_ref()
    }

    /// The newest estimate with the status rules applied again with the final answer's
    /// consider terms, the held wheel speeds' lag `time_tag` and the known torque's scale
    /// `torque_scale` ([`status::apply`], as a batch run applies them), which it becomes;
    /// `None` without an estimate with σ.
    pub(crate) fn widen_last(
        &mut self,
        time_tag: Option<[f64; 6]>,
        torque_scale: Option<[f64; 6]>,
    ) -> Option<Estimate> {
        let mut e = self.last_unsettled.filter(|e| e.uncertainty.is_some())?;
        let config = PipelineConfig {
            wheel_delay_consider: time_tag.or(self.config.wheel_delay_consider),
            torque_scale_consider: torque_scale,
            ..self.config
        };
        status::apply(&mut e, &config);
        self.last = Some(e);
        Some(e)
    }

    /// What the estimator can say about the run at its latest estimate: gaps, excitation,
    /// row model, torque and residual tests (`Diagnostics`).
    #[must_use]
    pub fn diagnostics(&self) -> Diagnostics {
        self.estimator.diagnostics()
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
    batch_of_records(samples, config, &[])
}

/// [`batch`] over several records laid end to end ([`Run::next_record`]): `starts` is the
/// index of each later record's first sample.
pub(crate) fn batch_of_records(
    samples: &[Sample],
    config: &PipelineConfig,
    starts: &[usize],
) -> Result<BatchOutput, PipelineError> {
    config.check_no_calibration()?;
    batch_with(
        samples,
        config,
        &interface::BatchInputs {
            records: starts.to_vec(),
            ..interface::BatchInputs::NONE
        },
    )
}

/// [`batch`] estimating the rotor parameters of `sources` with J
/// ([`crate::estimator::rotor_calibration`]; an estimator that takes the row-model
/// settings).
pub(crate) fn batch_with(
    samples: &[Sample],
    config: &PipelineConfig,
    sources: &interface::BatchInputs,
) -> Result<BatchOutput, PipelineError> {
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
    let mut out = run(samples, config, sources)?;
    // The rotors' overall scale the rows could not fix: the answer at the scale the
    // estimated parameters imply, and the rest of it a consider term.
    let mut config = *config;
    if let Some(f) = &out.diagnostics.rotor_calibration {
        config.rotor_inertia_consider = f.apply(&mut out.estimate, config.rotor_inertia_consider);
    }
    status::apply(&mut out.estimate, &config);
    checks::reversed_momentum(&out.estimate, None, tau_given, || check.verdict())?;
    Ok(out)
}

/// The configured estimator's batch form, where the settings allow one: it must have one,
/// and memory and resampling do not apply.
pub(crate) fn batch_applies(config: &PipelineConfig) -> Result<config::BatchFn, PipelineError> {
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
