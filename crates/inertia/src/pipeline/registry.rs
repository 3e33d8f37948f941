//! The estimators and solver backends the pipeline can run, by name.
//!
//! Adding a row model, an estimator or a backend is its own file plus one line in
//! [`ESTIMATORS`] or [`BACKENDS`].

pub use super::config::{BackendEntry, EstimatorEntry};
use super::error::PipelineError;

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
        .ok_or_else(|| PipelineError::UnknownEstimator {
            name: name.into(),
            known: estimator_names(),
        })
}

/// The backend called `name`, if this build can run it.
pub(crate) fn backend(name: &str) -> Result<&'static BackendEntry, PipelineError> {
    let entry =
        BACKENDS
            .iter()
            .find(|e| e.name == name)
            .ok_or_else(|| PipelineError::UnknownSolver {
                name: name.into(),
                known: backend_names(),
            })?;
    match entry.unavailable {
        Some(why) => Err(PipelineError::SolverUnavailable {
            name: entry.name,
            why,
        }),
        None => Ok(entry),
    }
}
