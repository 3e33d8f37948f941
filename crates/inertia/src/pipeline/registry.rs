//! The estimators and solver backends the pipeline can run, by name.
//!
//! Adding a row model, an estimator or a backend is its own file plus one line in
//! [`ESTIMATORS`] or [`BACKENDS`].

use super::diagnostics::Diagnostics;
use super::settings::PipelineConfig;
use super::PipelineError;
use crate::estimator::{Estimate, EstimatorError};
use crate::sample::Sample;
use crate::solver::Backend;
use std::boxed::Box;

/// A streaming estimator as the pipeline drives it: what every estimator has.
pub(crate) trait Estimator: Send {
    /// Feed one sample; an estimate when one is due.
    fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError>;
    /// What the estimator can say about its run at its latest estimate.
    fn diagnostics(&self) -> Diagnostics;
}

/// The answer of a batch run.
#[derive(Debug, Clone)]
pub struct BatchOutput {
    /// The estimate from all samples.
    pub estimate: Estimate,
    /// What the estimator can say about the run.
    pub diagnostics: Diagnostics,
}

/// What an estimator uses and needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Capabilities {
    /// It needs gyro rates in the telemetry.
    pub needs_gyro: bool,
    /// It keeps J in the constraint set.
    pub constraints: bool,
    /// It compensates errors-in-variables given the gyro noise density.
    pub compensation: bool,
    /// It has an uncertainty model.
    pub uncertainty: bool,
    /// It takes the row-model settings (rotation source, model of ρ, torque bias).
    pub row_model: bool,
    /// It differentiates low-pass-filtered signals (takes `filter_cutoff_hz`).
    pub filter: bool,
}

impl Capabilities {
    /// The fewest input samples for one estimate: two for an estimator of gyro rates alone
    /// (one momentum difference), else [`crate::estimator::MIN_SAMPLES`] (two 3-row blocks
    /// over three nodes).
    #[must_use]
    pub const fn min_samples(&self) -> usize {
        if self.needs_gyro && !self.constraints {
            2
        } else {
            crate::estimator::MIN_SAMPLES
        }
    }
}

/// Build a streaming estimator from a validated configuration.
pub(crate) type BuildFn = fn(&PipelineConfig) -> Result<Box<dyn Estimator>, PipelineError>;
/// Estimate from all samples at once.
pub(crate) type BatchFn = fn(&[Sample], &PipelineConfig) -> Result<BatchOutput, PipelineError>;

/// A registered estimator.
#[derive(Debug)]
pub struct EstimatorEntry {
    /// Name, as given in settings and on the command line.
    pub name: &'static str,
    /// One line for help texts.
    pub summary: &'static str,
    /// What it uses and needs.
    pub capabilities: Capabilities,
    pub(crate) build: BuildFn,
    pub(crate) batch: Option<BatchFn>,
}

impl EstimatorEntry {
    /// Whether it can estimate from all samples at once.
    #[must_use]
    pub fn has_batch(&self) -> bool {
        self.batch.is_some()
    }
}

/// A registered solver backend.
#[derive(Debug)]
pub struct BackendEntry {
    /// Name, as given in settings and on the command line.
    pub name: &'static str,
    /// One line for help texts.
    pub summary: &'static str,
    /// Why this build cannot run it, when it cannot.
    pub unavailable: Option<&'static str>,
    pub(crate) build: fn() -> Box<dyn Backend + Send>,
}

/// Every estimator, the default first.
pub static ESTIMATORS: &[EstimatorEntry] = &[
    crate::estimators::constrained::VARIATIONAL,
    crate::estimators::discrete_momentum::DISCRETE_MOMENTUM,
    crate::estimators::constrained::FINITE_DIFFERENCE,
    crate::estimators::momentum_rls::MOMENTUM,
    crate::estimators::equation_error::EQUATION_ERROR,
];

/// Every solver backend, the default first.
pub static BACKENDS: &[BackendEntry] = &[NATIVE, CLARABEL];

const NATIVE: BackendEntry = BackendEntry {
    name: "native",
    summary: "pure-Rust active-set, LMI-face Newton and barrier paths (default)",
    unavailable: None,
    build: || Box::new(crate::solver::native::NativeSolver::default()),
};

const CLARABEL: BackendEntry = BackendEntry {
    name: "clarabel",
    summary: "Clarabel interior-point conic solver (builds with the `clarabel` feature)",
    unavailable: if cfg!(feature = "clarabel") {
        None
    } else {
        Some("this build has no Clarabel backend (rebuild with the `clarabel` feature, which needs system OpenBLAS)")
    },
    build: || {
        #[cfg(feature = "clarabel")]
        {
            Box::new(crate::solver::clarabel_backend::ClarabelSolver::default())
        }
        #[cfg(not(feature = "clarabel"))]
        {
            unreachable!("validation refuses an unavailable backend")
        }
    },
};

fn names<T>(entries: &[T], name: impl Fn(&T) -> &'static str) -> std::string::String {
    entries
        .iter()
        .map(name)
        .collect::<std::vec::Vec<_>>()
        .join(", ")
}

/// Names of the registered estimators, comma-separated.
#[must_use]
pub(crate) fn estimator_names() -> std::string::String {
    names(ESTIMATORS, |e| e.name)
}

/// Names of the registered backends, comma-separated.
#[must_use]
pub(crate) fn backend_names() -> std::string::String {
    names(BACKENDS, |e| e.name)
}

/// The estimator called `name`.
pub(crate) fn estimator(name: &str) -> Result<&'static EstimatorEntry, PipelineError> {
    ESTIMATORS
        .iter()
        .find(|e| e.name == name)
        .ok_or_else(|| PipelineError::UnknownEstimator { name: name.into() })
}

/// The backend called `name`, if this build can run it.
pub(crate) fn backend(name: &str) -> Result<&'static BackendEntry, PipelineError> {
    let entry = BACKENDS
        .iter()
        .find(|e| e.name == name)
        .ok_or_else(|| PipelineError::UnknownSolver { name: name.into() })?;
    match entry.unavailable {
        Some(why) => Err(PipelineError::SolverUnavailable {
            name: entry.name,
            why,
        }),
        None => Ok(entry),
    }
}

/// A fresh backend for a validated entry.
pub(crate) fn build_backend(entry: &BackendEntry) -> Box<dyn Backend + Send> {
    (entry.build)()
}
