//! The constrained least-squares estimators (paper Algorithm 1 and eq. 57) in the
//! pipeline: one adapter for any row model, with the uncertainty model's half-rate
//! shadow ([`crate::estimator::uncertainty`]) where the row model has one.

use crate::estimator::audit::audit;
use crate::estimator::compensation::as_solved;
use crate::estimator::consistency::{self, ResidualSegments, Worst};
use crate::estimator::excitation::diagnose;
use crate::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
use crate::estimator::rows::{FiniteDifferenceRows, RowSource, VariationalRows};
use crate::estimator::uncertainty::combine;
use crate::estimator::{batch, Estimate, EstimatorError};
use crate::pipeline::config::EstimatorEntry;
use crate::pipeline::config::PipelineConfig;
use crate::pipeline::diagnostics::Diagnostics;
use crate::pipeline::error::PipelineError;
use crate::pipeline::interface::{BatchOutput, Capabilities, Estimator};
use crate::sample::Sample;
use crate::solver::Backend;
use std::boxed::Box;

/// The paper's discrete variational estimator.
pub(crate) const VARIATIONAL: EstimatorEntry = EstimatorEntry {
    name: "variational",
    summary: "discrete variational rows (paper eqs. 53-54), constrained least squares (the paper's Algorithm 1)",
    capabilities: Capabilities {
        needs_gyro: false,
        constraints: true,
        compensation: true,
        uncertainty: true,
        row_model: false,
        filter: false,
    },
    build: build::<VariationalRows>,
    batch: Some(run_batch::<VariationalRows>),
};

/// The paper's finite-difference SDP baseline.
pub(crate) const FINITE_DIFFERENCE: EstimatorEntry = EstimatorEntry {
    name: "finite-difference",
    summary: "the paper's finite-difference SDP baseline (eq. 26, differenced gyro rates)",
    capabilities: Capabilities {
        needs_gyro: true,
        constraints: true,
        compensation: false,
        uncertainty: false,
        row_model: false,
        filter: false,
    },
    build: build::<FiniteDifferenceRows>,
    batch: Some(run_batch::<FiniteDifferenceRows>),
};

/// The fewest samples a shadow takes between its solves ([`Constrained::new`]).
const SHADOW_SOLVE_BLOCKS: usize = 8;

/// The recursive constrained least-squares estimator as the pipeline runs it: the
/// estimator, its half-rate shadow for the uncertainty model, the status audit and the
/// residual test, after every solve. Generic over the backend so that a fixed-size build
/// (the C API's caller storage, with [`crate::solver::native::NativeSolver`]) takes the
/// same steps as the pipeline (which boxes its backend).
#[derive(Debug, Clone)]
pub struct Constrained<S: RowSource, B: Backend> {
    main: RecursiveEstimator<S, B>,
    /// The shadows on every other and every fourth sample (steps 2h and 4h), for the
    /// step-size bias ([`crate::estimator::uncertainty`]).
    shadow: Option<RecursiveEstimator<S, B>>,
    quarter: Option<RecursiveEstimator<S, B>>,
    samples: usize,
    /// The main estimator's residual record (none under forgetting).
    residuals: Option<ResidualSegments>,
    observability: crate::estimator::observability::ObservabilitySettings,
    epsilon_kg_m2: f64,
    /// The rotor momentum's stated relative σ ([`PipelineConfig::stated_relative_sigma`]).
    stated_relative_sigma: f64,
    /// The gyro's rate-noise density the solves compensate for, rad/s/√Hz.
    gyro_noise_rad_s_rthz: Option<f64>,
}

impl<S: RowSource + Default, B: Backend> Constrained<S, B> {
    /// The estimator with `settings` under `constraints`, each solve by a backend from
    /// `backend`. With `uncertainty`, shadows on every other and every fourth sample
    /// measure the bias that changes with the step (twice and four times the step, the
    /// same memory in seconds). They solve with the main estimator, on the same span of
    /// the record, but at most every `SHADOW_SOLVE_BLOCKS` of their own samples (they
    /// measure only a slowly varying bias: at a solve on every sample and h = 0.1 s, a bias
    /// estimate at most 1.6 s and 3.2 s old), and at the end of the input always, so
    /// that the final σ does not depend on how often the main estimator solved.
    /// With `residual_test`, the residuals are recorded for
    /// [`crate::estimator::consistency`] (not under forgetting).
    pub fn new(
        constraints: crate::constraints::Constraints,
        settings: RecursiveSettings,
        uncertainty: bool,
        residual_test: bool,
        mut backend: impl FnMut() -> B,
    ) -> Result<Self, EstimatorError> {
        let main = RecursiveEstimator::new(S::default(), constraints, backend(), settings)?;
        let mut shadow = || -> Result<_, EstimatorError> {
            if !uncertainty {
                return Ok(None);
            }
            // Solved by `Self::push` and `Self::flush`, never by their own pushes.
            let s = RecursiveSettings {
                solve_every: usize::MAX,
                ..settings
            };
            Ok(Some(RecursiveEstimator::new(
                S::default(),
                constraints,
                backend(),
                s,
            )?))
        };
        let (half, quarter) = (shadow()?, shadow()?);
        Ok(Self {
            main,
            shadow: half,
            quarter,
            samples: 0,
            residuals: residual_test.then(ResidualSegments::new),
            observability: settings.observability,
            epsilon_kg_m2: constraints.set().epsilon_kg_m2,
            stated_relative_sigma: 0.0,
            gyro_noise_rad_s_rthz: settings.gyro_noise_rad_s_rthz,
        })
    }
}

impl<S: RowSource, B: Backend> Constrained<S, B> {
    /// Feed one sample; the estimate when a solve was due.
    pub fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        if let Some(half) = self.shadow.as_mut() {
            if self.samples.is_multiple_of(2) {
                half.push(s)?;
            }
        }
        if let Some(quarter) = self.quarter.as_mut() {
            if self.samples.is_multiple_of(4) {
                quarter.push(s)?;
            }
        }
        self.samples += 1;
        let pushed = self.main.push(s)?;
        if let Some(r) = self.residuals.as_mut() {
            let qr = self.main.qr();
            r.record(qr.rss, qr.residual_dof(), s.t_s);
        }
        let Some(e) = pushed else {
            return Ok(None);
        };
        self.solve_shadows(SHADOW_SOLVE_BLOCKS)?;
        Ok(Some(self.finish(e)))
    }

    /// At the end of the input, the answer to the rows since the last solve
    /// ([`RecursiveEstimator::flush`]).
    fn flush(&mut self) -> Result<Option<Estimate>, EstimatorError> {
        let Some(e) = self.main.flush()? else {
            return Ok(None);
        };
        // The shadows on the same rows as the main estimator's final answer.
        self.solve_shadows(1)?;
        Ok(Some(self.finish(e)))
    }

    /// Solve each shadow that has taken at least `blocks` samples since its last solve
    /// (or has never answered).
    fn solve_shadows(&mut self, blocks: usize) -> Result<(), EstimatorError> {
        for shadow in [self.shadow.as_mut(), self.quarter.as_mut()]
            .into_iter()
            .flatten()
        {
            if shadow.unsolved_blocks() >= blocks || shadow.last().is_none() {
                shadow.flush()?;
            }
        }
        Ok(())
    }

    /// A solve's estimate with its σ, audit and consistency test.
    fn finish(&mut self, mut e: Estimate) -> Estimate {
        if let (Some(half), Some(j), Some(noise)) = (&self.shadow, e.j(), self.main.noise_sigma()) {
            let j_half = half.last().and_then(|h| h.j());
            let j_quarter = self.quarter.as_ref().and_then(|q| q.last()?.j());
            e.uncertainty = Some(combine(&noise, &j, j_half.as_ref(), j_quarter.as_ref()));
        }
        audit(
            &mut e,
            &as_solved(self.main.solved(), self.gyro_noise_rad_s_rthz),
            self.epsilon_kg_m2,
            self.observability.max_relative_sigma,
            self.stated_relative_sigma,
        );
        // The density test is the discrete momentum estimator's: the paper's rows share
        // their noise between neighbours, and their residual variance came out at 0.46 of
        // `gyro_density_ratio`'s prediction with the right density (a MEMS slew).
        // The answer as the data gave it is the reference of the spans after it.
        if let (Some(r), Some(j), Some(sigma)) = (self.residuals.as_mut(), e.j(), e.sigma_kg_m2()) {
            r.note(&j, &sigma);
        }
        consistency::check(
            &mut e,
            self.residuals.as_ref(),
            None,
            self.stated_relative_sigma,
        );
        e
    }

    /// The span whose residuals stand out most.
    #[must_use]
    pub(crate) fn residual_consistency(&self) -> Option<Worst> {
        self.residuals.as_ref()?.worst()
    }
}

fn settings(c: &PipelineConfig) -> RecursiveSettings {
    RecursiveSettings {
        solve_every: c.solve_every,
        observability: c.observability,
        memory_s: c.memory_s,
        gyro_noise_rad_s_rthz: c.gyro_noise_rad_s_rthz,
    }
}

fn build<S: RowSource + Default + Send + 'static>(
    c: &PipelineConfig,
) -> Result<Box<dyn Estimator>, PipelineError> {
    let mut adapter = Constrained::<S, Box<dyn Backend + Send>>::new(
        c.constraints,
        settings(c),
        c.uncertainty,
        c.memory_s.is_none(),
        || c.backend.build(),
    )
    .map_err(|source| PipelineError::Estimator {
        sample: None,
        source,
    })?;
    adapter.stated_relative_sigma = c.stated_relative_sigma();
    Ok(Box::new(adapter))
}

impl<S: RowSource + Send, B: Backend + Send> Estimator for Constrained<S, B> {
    fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        Constrained::push(self, s)
    }

    fn flush(&mut self) -> Result<Option<Estimate>, EstimatorError> {
        Constrained::flush(self)
    }

    fn diagnostics(&self) -> Diagnostics {
        Diagnostics {
            gaps: self.main.gaps(),
            excitation: (self.main.qr().rows > 0)
                .then(|| diagnose(self.main.qr(), &self.observability)),
            residual_consistency: Constrained::residual_consistency(self),
            ..Diagnostics::default()
        }
    }
}

fn run_batch<S: RowSource + Default>(
    samples: &[Sample],
    c: &PipelineConfig,
    rotors: &crate::pipeline::interface::BatchInputs,
) -> Result<BatchOutput, PipelineError> {
    if !rotors.is_empty() {
        return Err(PipelineError::NotApplicable {
            setting: "calibrate_rotors",
            estimator: c.estimator.name,
        });
    }
    let mut source = S::default();
    let wrap = |source| PipelineError::Estimator {
        sample: match source {
            EstimatorError::Row { sample, .. } => Some(sample),
            _ => None,
        },
        source,
    };
    let qr = batch::reduce(samples, &mut source).map_err(wrap)?;
    let mut backend = c.backend.build();
    let t_s = samples.last().map_or(0.0, |s| s.t_s);
    let mut solve = |qr: &crate::estimator::qr::RecursiveQr| {
        batch::solve_reduced(
            qr,
            t_s,
            &c.constraints,
            &mut *backend,
            &c.observability,
            c.gyro_noise_rad_s_rthz,
        )
    };
    let mut estimate = solve(&qr).map_err(wrap)?;
    let solved = crate::estimator::prior::augment(&qr, &c.constraints).0;
    // σ as the recursive run has it: the least-squares σ and the step-size bias from the
    // same record at twice and four times the step (`crate::estimator::uncertainty`).
    if c.uncertainty && c.estimator.capabilities.uncertainty {
        let mut at_step = |every: usize| -> Option<crate::tensor::InertiaVector> {
            let thinned: std::vec::Vec<Sample> = samples.iter().step_by(every).copied().collect();
            let qr = batch::reduce(&thinned, &mut S::default()).ok()?;
            solve(&qr).ok()?.j()
        };
        let (half, quarter) = (at_step(2), at_step(4));
        let noise = diagnose(&solved, &c.observability).element_sigma;
        if let (Some(j), Some(noise)) = (estimate.j(), noise) {
            estimate.uncertainty = Some(combine(&noise, &j, half.as_ref(), quarter.as_ref()));
        }
    }
    audit(
        &mut estimate,
        &as_solved(&solved, c.gyro_noise_rad_s_rthz),
        c.constraints.set().epsilon_kg_m2,
        c.observability.max_relative_sigma,
        c.stated_relative_sigma(),
    );
    Ok(BatchOutput {
        estimate,
        diagnostics: Diagnostics {
            gaps: source.gaps(),
            excitation: Some(diagnose(&qr, &c.observability)),
            ..Diagnostics::default()
        },
    })
}
