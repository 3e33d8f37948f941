//! The two engines behind one C handle, in safe Rust.
//!
//! * [`Engine::Pipeline`]: [`inertia::pipeline::Pipeline`], every estimator of the
//!   library (the default `discrete-momentum` among them). Built on the heap.
//! * [`Engine::Fixed`]: the constrained least-squares estimators (`variational`,
//!   `finite-difference`) with the native solver, in fixed-size state: the same steps the
//!   pipeline's adapter takes (`pipeline/sdp.rs`: the half-rate shadow for σ, the status
//!   audit, the residual test, the glitch and convention checks), on concrete types with
//!   no box. It can live in caller storage, and neither its construction nor a push
//!   allocates (`tests/no_alloc.rs` counts). `tests/engines.rs` checks that it gives the
//!   pipeline's estimates bit for bit.

use inertia::attitude::Quaternion;
use inertia::constraints::Constraints;
use inertia::estimator::audit::audit;
use inertia::estimator::consistency::{self, ResidualSegments};
use inertia::estimator::observability::ObservabilitySettings;
use inertia::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
use inertia::estimator::rows::{FiniteDifferenceRows, RowSource, VariationalRows};
use inertia::estimator::uncertainty::combine;
use inertia::estimator::Estimate;
use inertia::pipeline::{Pipeline, PipelineError, PipelineSettings};
use inertia::sample::Sample;
use inertia::solver::native::NativeSolver;
use inertia::telemetry::convention::{ConventionCheck, Verdict, STEPS_NEEDED};
use inertia::telemetry::glitch::{GlitchCheck, GlitchPolicy};

/// What a fixed engine is built from (kept for `reset`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct FixedConfig {
    pub constraints: Constraints,
    pub recursive: RecursiveSettings,
    pub uncertainty: bool,
    pub residual_test: bool,
    pub glitches: GlitchPolicy,
    pub observability: ObservabilitySettings,
}

type Recursive<S> = RecursiveEstimator<S, NativeSolver>;

/// The pipeline's constrained least-squares adapter on concrete, fixed-size types.
#[derive(Debug, Clone)]
pub(crate) struct Fixed<S: RowSource> {
    config: FixedConfig,
    main: Recursive<S>,
    shadow: Option<Recursive<S>>,
    samples: usize,
    residuals: Option<ResidualSegments>,
    convention: ConventionCheck,
    glitch: GlitchCheck,
}

impl<S: RowSource + Default> Fixed<S> {
    pub(crate) fn new(config: FixedConfig) -> Result<Self, PipelineError> {
        let err = |source| PipelineError::Estimator {
            sample: None,
            source,
        };
        let main = RecursiveEstimator::new(
            S::default(),
            config.constraints,
            NativeSolver::default(),
            config.recursive,
        )
        .map_err(err)?;
        // As `pipeline/sdp.rs`: the shadow sees every other sample and solves every 8th
        // of them.
        let shadow = if config.uncertainty {
            let s = RecursiveSettings {
                solve_every: config.recursive.solve_every.div_ceil(2).max(8),
                ..config.recursive
            };
            Some(
                RecursiveEstimator::new(
                    S::default(),
                    config.constraints,
                    NativeSolver::default(),
                    s,
                )
                .map_err(err)?,
            )
        } else {
            None
        };
        Ok(Self {
            config,
            main,
            shadow,
            samples: 0,
            residuals: config.residual_test.then(ResidualSegments::new),
            convention: ConventionCheck::default(),
            glitch: GlitchCheck::default(),
        })
    }

    /// One input sample, as `Pipeline::push` takes it (range checked by the caller).
    fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, PipelineError> {
        let index = self.samples;
        if let Some(glitch) = self.glitch.push(s) {
            if self.config.glitches == GlitchPolicy::Stop {
                return Err(PipelineError::AttitudeGlitch {
                    sample: index,
                    glitch,
                });
            }
        }
        self.samples += 1;
        if self.convention.steps() < STEPS_NEEDED {
            self.convention.push(s);
            if let Verdict::Wrong {
                reading,
                as_read,
                fixed,
            } = self.convention.verdict()
            {
                return Err(PipelineError::AttitudeConvention {
                    fix: reading.fix(),
                    as_read,
                    fixed,
                    steps: self.convention.steps(),
                });
            }
        }
        let err = |source| PipelineError::Estimator {
            sample: Some(index),
            source,
        };
        if let Some(half) = self.shadow.as_mut() {
            if index.is_multiple_of(2) {
                half.push(s).map_err(err)?;
            }
        }
        let pushed = self.main.push(s).map_err(err)?;
        if let Some(r) = self.residuals.as_mut() {
            let qr = self.main.qr();
            r.record(qr.rss, qr.residual_dof(), s.t_s);
        }
        let Some(mut e) = pushed else {
            return Ok(None);
        };
        if let (Some(half), Some(j), Some(noise)) = (&self.shadow, e.j(), self.main.noise_sigma()) {
            let j_half = half.last().and_then(|h| h.j());
            e.uncertainty = Some(combine(&noise, &j, j_half.as_ref()));
        }
        audit(
            &mut e,
            self.main.solved(),
            self.config.constraints.set().epsilon_kg_m2,
            self.config.observability.max_relative_sigma,
        );
        if let (Some(r), Some(j), Some(sigma)) = (self.residuals.as_mut(), e.j(), e.sigma_kg_m2()) {
            r.note(&j, &sigma);
        }
        consistency::check(&mut e, self.residuals.as_ref(), None);
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

/// A quaternion as the CSV reader takes it: renormalised when its norm is not exactly 1
/// (the range check has bounded the deviation).
pub(crate) fn unit(c: [f64; 4]) -> Quaternion {
    let raw = Quaternion::from_xyzw(c);
    if raw.norm() != 1.0 {
        if let Some(n) = raw.normalize() {
            return n;
        }
    }
    raw
}
