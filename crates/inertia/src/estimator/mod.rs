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

#[cfg(feature = "std")]
pub mod batch;
pub mod compensation;
#[cfg(feature = "std")]
pub mod excitation;
pub mod momentum;
pub mod observability;
pub mod qr;
pub mod recursive;
pub mod resample;
pub mod rows;
pub mod svd_tracker;
pub mod uncertainty;

use crate::discrete::RowError;
use crate::solver::{Solution, SolveError};
use crate::tensor::{matrix_from_j, InertiaVector};
use nalgebra::Matrix3;
use observability::Observability;

/// One estimate at a time stamp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Time of the newest sample used, s.
    pub t_s: f64,
    /// Scalar rows used.
    pub rows: usize,
    /// Whether the data determine J.
    pub observability: Observability,
    /// The constrained least-squares answer (`None` when not observable).
    pub solution: Option<Solution>,
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
}

/// Why an estimator stopped.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
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
pub const MIN_SAMPLES: usize = 4;
