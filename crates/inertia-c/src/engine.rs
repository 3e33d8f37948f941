//! The two engines behind one C handle, in safe Rust.
//!
//! * [`Engine::Pipeline`]: [`inertia::pipeline::Pipeline`], every estimator of the
//!   library (the default `discrete-momentum` among them). Built on the heap.
//! * [`Engine::Fixed`]: the constrained least-squares estimators (`variational`,
//!   `finite-difference`) with the native solver, in fixed-size state: the same steps the
//!   pipeline's adapter takes (`estimators/constrained.rs`: the σ shadows at 2h and 4h, the status
//!   audit, the residual test, the status rule (`inertia::pipeline::status`), the glitch, convention and reversed-momentum checks), on concrete types with
//!   no box. It can live in caller storage, and neither its construction nor a push
//!   allocates (`tests/no_alloc.rs` counts). `tests/c_api/engines.rs` checks that it gives the
//!   pipeline's estimates bit for bit.

use inertia::constraints::Constraints;
use inertia::estimator::recursive::RecursiveSettings;
use inertia::estimator::rows::{FiniteDifferenceRows, RowSource, VariationalRows};
use inertia::estimator::Estimate;
use inertia::pipeline::{AttitudeChecks, Constrained, Pipeline, PipelineError, PipelineSettings};
use inertia::sample::Sample;
use inertia::solver::native::NativeSolver;
use inertia::telemetry::glitch::GlitchPolicy;

/// What a fixed engine is built from (kept for `reset`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct FixedConfig {
    pub constraints: Constraints,
    pub recursive: RecursiveSettings,
    pub uncertainty: bool,
    pub residual_test: bool,
    pub glitches: GlitchPolicy,
}

/// The pipeline's constrained least-squares adapter ([`Constrained`]) and its attitude
/// checks ([`AttitudeChecks`]) on concrete, fixed-size types.
#[derive(Debug, Clone)]
pub(crate) struct Fixed<S: RowSource> {
    config: FixedConfig,
    adapter: Constrained<S, NativeSolver>,
    samples: usize,
    checks: AttitudeChecks,
}

impl<S: RowSource + Default> Fixed<S> {
    pub(crate) fn new(config: FixedConfig) -> Result<Self, PipelineError> {
        let adapter = Constrained::new(
            config.constraints,
            config.recursive,
            config.uncertainty,
            config.residual_test,
            NativeSolver::default,
        )
        .map_err(|source| PipelineError::Estimator {
            sample: None,
            source,
        })?;
        Ok(Self {
            config,
            adapter,
            samples: 0,
            checks: AttitudeChecks::default(),
        })
    }

    /// One input sample, as `Pipeline::push` takes it (range checked by the caller).
    fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, PipelineError> {
        let index = self.samples;
        self.checks.push(index, s, self.config.glitches)?;
        self.samples += 1;
        let e = self
            .adapter
            .push(s)
            .map_err(|source| PipelineError::Estimator {
                sample: Some(index),
                source,
            })?;
        let Some(mut e) = e else { return Ok(None) };
        // The one status rule, as the pipeline applies it (no allocation).
        inertia::pipeline::status::settle(&mut e, self.config.constraints.set().consistency);
        self.checks.estimate(index, &e)?;
        Ok(Some(e))
    }
}

/// An estimator behind the C handle.
#[allow(clippy::large_enum_variant)] // the fixed engines are meant to be inline
pub(crate) enum Engine {
    /// The library's pipeline (heap).
    Pipeline {
        pipeline: Pipeline,
        settings: PipelineSettings,
    },
    /// The variational estimator, fixed size.
    Variational(Fixed<VariationalRows>),
    /// The finite-difference SDP baseline, fixed size.
    FiniteDifference(Fixed<FiniteDifferenceRows>),
}

impl Engine {
    pub(crate) fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, PipelineError> {
        match self {
            Engine::Pipeline { pipeline, .. } => pipeline.push(s),
            Engine::Variational(f) => f.push(s),
            Engine::FiniteDifference(f) => f.push(s),
        }
    }

    /// Start again from no data, with the same settings.
    pub(crate) fn reset(&mut self) -> Result<(), PipelineError> {
        match self {
            Engine::Pipeline { pipeline, settings } => *pipeline = Pipeline::new(settings)?,
            Engine::Variational(f) => *f = Fixed::new(f.config)?,
            Engine::FiniteDifference(f) => *f = Fixed::new(f.config)?,
        }
        Ok(())
    }

    /// The outside torques at the last estimate (the pipeline's discrete momentum
    /// estimator only).
    pub(crate) fn outside(&self) -> Option<inertia::estimator::external_torque::OutsideEstimates> {
        match self {
            Engine::Pipeline { pipeline, .. } => pipeline.diagnostics().outside,
            Engine::Variational(_) | Engine::FiniteDifference(_) => None,
        }
    }

    pub(crate) fn needs_gyro(&self) -> bool {
        match self {
            Engine::Pipeline { pipeline, .. } => {
                pipeline.config().estimator().capabilities.needs_gyro
            }
            Engine::Variational(_) => false,
            Engine::FiniteDifference(_) => true,
        }
    }
}
