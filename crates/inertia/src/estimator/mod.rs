//! Estimators of the inertia components (paper §§IV–VI).
//!
//! * [`recursive::RecursiveEstimator`] — Algorithm 1: a fixed-size QR state updated with
//!   each 3-row block and a constrained solve every `solve_every` blocks. With
//!   [`rows::VariationalRows`] it is the paper's variational estimator; with
//!   [`rows::FiniteDifferenceRows`] the finite-difference SDP baseline.
//! * [`batch::estimate`] — eq. 57: every row stacked, reduced by one Householder QR,
//!   solved once. Independent of the recursive code path; they must agree.
//! * [`momentum::MomentumRls`] — the momentum-based recursive least-squares baseline of
//!   Norman, Peck & O'Shaughnessy (inertia part), with no constraints.
//!
//! Every estimate says whether the data determine J ([`observability`]).

pub(crate) mod attitude_drift;
pub(crate) mod audit;
pub(crate) mod augmented_qr;
#[cfg(feature = "std")]
pub mod batch;
pub(crate) mod chain_clock;
pub(crate) mod compensation;
pub mod consistency;
pub mod discrete_momentum;
#[cfg(feature = "std")]
pub mod excitation;
pub mod external_torque;
pub(crate) mod jackknife;
pub mod momentum;
pub mod momentum_rows;
pub(crate) mod normal_equations;
pub mod observability;
#[cfg(feature = "std")]
pub(crate) mod plain_fit;
pub mod prior;
pub mod qr;
pub(crate) mod rate_noise;
pub mod recursive;
pub mod resample;
#[cfg(feature = "std")]
pub mod rotor_calibration;
#[cfg(feature = "std")]
pub mod rotor_inertia;
pub mod rows;
pub(crate) mod shared_qr;
pub mod svd_tracker;
pub(crate) mod trend_slot;
pub mod uncertainty;
pub(crate) mod unknowns;
#[cfg(feature = "std")]
pub mod wheel_delay;

use crate::discrete::RowError;
use crate::solver::{Solution, SolveError};
use crate::tensor::{matrix_from_j, InertiaVector};
use nalgebra::Matrix3;
use observability::Observability;

/// One estimate at a time stamp: the same type for every estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Estimate {
    /// Time of the newest sample used, s.
    pub t_s: f64,
    /// Scalar rows used.
    pub rows: usize,
    /// Whether the data determine J, and if not, why.
    pub observability: Observability,
    /// The answer with its solver diagnostics (`None` when there is no answer).
    pub solution: Option<Solution>,
    /// Standard deviations per element and principal moment, when the estimator has an
    /// uncertainty model ([`uncertainty`]).
    pub uncertainty: Option<uncertainty::Uncertainty>,
    /// How a Gaussian prior sat with the data at this solve (`prior`), when one was
    /// given.
    pub prior: Option<prior::PriorFit>,
}

impl Estimate {
    /// `j` when an answer exists.
    #[must_use]
    pub fn j(&self) -> Option<InertiaVector> {
        self.solution.map(|s| s.j)
    }

    /// `J` (kg m²) when an answer exists.
    #[must_use]
    pub fn inertia(&self) -> Option<Matrix3<f64>> {
        self.j().map(|j| matrix_from_j(&j))
    }

    /// Standard deviation per element, kg m², when known.
    #[must_use]
    pub fn sigma_kg_m2(&self) -> Option<[f64; 6]> {
        self.uncertainty.map(|u| u.sigma_kg_m2)
    }

    /// Whether `truth` lies within ±3σ of the estimate in every element (`None` without
    /// an answer or a σ).
    #[must_use]
    pub fn within_3sigma(&self, truth: &Matrix3<f64>) -> Option<bool> {
        let (j, sigma) = (self.j()?, self.sigma_kg_m2()?);
        let t = crate::tensor::j_from_matrix(truth);
        Some((0..6).all(|k| crate::math::abs(j[k] - t[k]) <= 3.0 * sigma[k]))
    }
}

/// Why an estimator stopped.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EstimatorError {
    /// Not enough samples for even two row blocks.
    #[error("too few samples: need at least {need}, got {got}")]
    TooFewSamples {
        /// Minimum.
        need: usize,
        /// Given.
        got: usize,
    },
    /// A row could not be formed from the samples ending at `sample` (0-based).
    #[error("sample {sample}: {source}")]
    Row {
        /// Index of the newest sample of the row.
        sample: usize,
        /// The row error.
        source: RowError,
    },
    /// The solver failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// A setting is out of range.
    #[error("estimator setting `{field}` is invalid: {why}")]
    InvalidSetting {
        /// Field.
        field: &'static str,
        /// What it must be.
        why: &'static str,
    },
}

/// Minimum number of samples for one estimate from 3-row blocks over three nodes (two
/// blocks, six scalar rows).
pub(crate) const MIN_SAMPLES: usize = 4;

/// A constructor argument out of its documented range.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("argument `{name}` = {value} is invalid: expected {expected}")]
pub struct InvalidArgument {
    /// The argument's name.
    pub name: &'static str,
    /// The value given.
    pub value: f64,
    /// What it must be.
    pub expected: &'static str,
}
