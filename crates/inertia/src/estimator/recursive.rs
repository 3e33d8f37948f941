//! Algorithm 1 of the paper: the recursive estimator.
//!
//! ```text
//! for each sample:   block (H_k, y_k) from the row source        (eqs. 53–54)
//!                    [R; H_k] → R,  [z; y_k] → z  by Givens        (eqs. 60–61)
//!                    every `solve_every` blocks: minimise ‖R j − z‖², j ∈ C   (eq. 59)
//! ```
//!
//! The state is fixed-size (`R` 6×6, `z`, residual sum of squares); the per-sample update
//! does not allocate. The previous answer warm-starts the next solve.

use super::observability::{assess, assess_with, Observability, ObservabilitySettings};
use super::qr::RecursiveQr;
use super::rows::RowSource;
use super::svd_tracker::SvdTracker;
use super::{Estimate, EstimatorError};
use crate::constraints::Constraints;
use crate::solver::{solve, Backend};

/// Settings of the recursive estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecursiveSettings {
    /// Solve every this many row blocks (default 1: every sample).
    pub solve_every: usize,
    /// Thresholds of the observability test.
    pub observability: ObservabilitySettings,
    /// Exponential forgetting factor per block, `0 < λ ≤ 1` (default 1: no forgetting).
    pub forgetting: f64,
}

impl Default for RecursiveSettings {
    fn default() -> Self {
        Self {
            solve_every: 1,
            observability: ObservabilitySettings::default(),
            forgetting: 1.0,
        }
    }
}

impl RecursiveSettings {
    /// Check the settings.
    pub fn validate(&self) -> Result<(), EstimatorError> {
        if self.solve_every == 0 {
            return Err(EstimatorError::InvalidSetting {
                field: "solve_every",
                why: "must be at least 1",
            });
        }
        let o = &self.observability;
        if !(o.condition_threshold.is_finite() && o.condition_threshold > 1.0) {
            return Err(EstimatorError::InvalidSetting {
                field: "condition_threshold",
                why: "must be finite and > 1",
            });
        }
        if !(o.max_relative_sigma > 0.0) {
            return Err(EstimatorError::InvalidSetting {
                field: "max_relative_sigma",
                why: "must be > 0",
            });
        }
        if !(self.forgetting > 0.0 && self.forgetting <= 1.0) {
            return Err(EstimatorError::InvalidSetting {
                field: "forgetting",
                why: "must be in (0, 1]",
            });
        }
        Ok(())
    }
}

/// The recursive estimator over any row source and backend.
#[derive(Debug, Clone)]
pub struct RecursiveEstimator<S: RowSource, B: Backend> {
    source: S,
    qr: RecursiveQr,
    svd: SvdTracker,
    constraints: Constraints,
    backend: B,
    settings: RecursiveSettings,
    samples: usize,
    since_solve: usize,
    last: Option<Estimate>,
}

impl<S: RowSource, B: Backend> RecursiveEstimator<S, B> {
    /// A new estimator.
    pub fn new(
        source: S,
        constraints: Constraints,
        backend: B,
        settings: RecursiveSettings,
    ) -> Result<Self, EstimatorError> {
        settings.validate()?;
        Ok(Self {
            source,
            qr: RecursiveQr::new(),
            svd: SvdTracker::new(),
            constraints,
            backend,
            settings,
            samples: 0,
            since_solve: 0,
            last: None,
        })
    }

    /// Feed one sample. Returns an estimate when this sample completed a block and a solve
    /// was due.
    pub fn push(
        &mut self,
        s: &crate::telemetry::Sample,
    ) -> Result<Option<Estimate>, EstimatorError> {
        let index = self.samples;
        self.samples += 1;
        let Some(row) = self.source.push(s) else {
            return Ok(None);
        };
        let row = row.map_err(|source| EstimatorError::Row {
            sample: index,
            source,
        })?;
        if self.settings.forgetting < 1.0 {
            self.qr.scale(self.settings.forgetting);
        }
        self.qr.add_block(&row.h, &row.y);
        self.since_solve += 1;
        if self.since_solve < self.settings.solve_every || self.qr.rows < 6 {
            return Ok(None);
        }
        self.solve_now(s.t_s).map(Some)
    }

    /// Solve with the data so far, stamped `t_s`.
    pub fn solve_now(&mut self, t_s: f64) -> Result<Estimate, EstimatorError> {
        self.since_solve = 0;
        let sv = self.svd.singular_values(&self.qr.r);
        let observability = assess_with(
            &self.qr,
            &sv,
            self.constraints.set().has_bounds(),
            &self.settings.observability,
        );
        let solution = if observability.has_answer() {
            let warm = self.last.and_then(|e| e.j());
            Some(solve(
                &mut self.backend,
                &self.qr.r,
                &self.qr.z,
                &self.constraints,
                warm.as_ref(),
            )?)
        } else {
            None
        };
        let e = Estimate {
            t_s,
            rows: self.qr.rows,
            observability,
            solution,
        };
        self.last = Some(e);
        Ok(e)
    }

    /// The least-squares state.
    #[must_use]
    pub fn qr(&self) -> &RecursiveQr {
        &self.qr
    }

    /// The latest estimate.
    #[must_use]
    pub fn last(&self) -> Option<&Estimate> {
        self.last.as_ref()
    }

    /// Gaps in the time stamps so far (no row spans a gap).
    #[must_use]
    pub fn gaps(&self) -> usize {
        self.source.gaps()
    }

    /// Samples fed so far.
    #[must_use]
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Whether the data so far determine J (without solving).
    #[must_use]
    pub fn observability(&self) -> Observability {
        assess(
            &self.qr,
            self.constraints.set().has_bounds(),
            &self.settings.observability,
        )
    }
}
