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
    /// Memory time constant, s: before each row block the state is weighed by
    /// `exp(−Δt/memory)`, with `Δt` the time since the previous block from the samples'
    /// own time stamps (so jitter, gaps and resampling are weighed by the time that
    /// passed). `None` (default): no forgetting.
    pub memory_s: Option<f64>,
    /// Gyro rate-noise density, rad/s/√Hz, for errors-in-variables bias compensation
    /// (`super::compensation`); `None` (default): no compensation.
    pub gyro_noise_rad_s_rthz: Option<f64>,
}

impl Default for RecursiveSettings {
    fn default() -> Self {
        Self {
            solve_every: 1,
            observability: ObservabilitySettings::default(),
            memory_s: None,
            gyro_noise_rad_s_rthz: None,
        }
    }
}

impl RecursiveSettings {
    /// Check the settings.
    pub(crate) fn validate(&self) -> Result<(), EstimatorError> {
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
        if let Some(g) = self.gyro_noise_rad_s_rthz {
            if !(g.is_finite() && g >= 0.0) {
                return Err(EstimatorError::InvalidSetting {
                    field: "gyro_noise_rad_s_rthz",
                    why: "must be finite and >= 0",
                });
            }
        }
        if let Some(m) = self.memory_s {
            if !(m.is_finite() && m > 0.0) {
                return Err(EstimatorError::InvalidSetting {
                    field: "memory_s",
                    why: "must be finite and > 0 s",
                });
            }
        }
        Ok(())
    }
}

/// The recursive estimator over any row source and backend.
#[derive(Debug, Clone)]
pub struct RecursiveEstimator<S: RowSource, B: Backend> {
    source: S,
    qr: RecursiveQr,
    /// `qr` with the prior knowledge stacked on, at the last solve.
    solved: RecursiveQr,
    svd: SvdTracker,
    sv: nalgebra::Vector6<f64>,
    constraints: Constraints,
    backend: B,
    settings: RecursiveSettings,
    samples: usize,
    since_solve: usize,
    last_block_t_s: Option<f64>,
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
            solved: RecursiveQr::new(),
            svd: SvdTracker::new(),
            sv: nalgebra::Vector6::zeros(),
            constraints,
            backend,
            settings,
            samples: 0,
            since_solve: 0,
            last_block_t_s: None,
            last: None,
        })
    }

    /// Feed one sample. Returns an estimate when this sample completed a block and a solve
    /// was due.
    pub fn push(&mut self, s: &crate::sample::Sample) -> Result<Option<Estimate>, EstimatorError> {
        let index = self.samples;
        self.samples += 1;
        let Some(row) = self.source.push(s) else {
            return Ok(None);
        };
        let row = row.map_err(|source| EstimatorError::Row {
            sample: index,
            source,
        })?;
        if let (Some(m), Some(t0)) = (self.settings.memory_s, self.last_block_t_s) {
            self.qr.scale(libm::exp(-(s.t_s - t0) / m));
        }
        self.last_block_t_s = Some(s.t_s);
        self.qr.add(&row);
        self.since_solve += 1;
        if self.since_solve < self.settings.solve_every || self.qr.rows < 6 {
            return Ok(None);
        }
        self.solve_now(s.t_s).map(Some)
    }

    /// At the end of the input: the estimate of the blocks since the last solve, stamped
    /// with the last block's time (none where every block was solved or there are fewer
    /// than 6 rows), so that `solve_every` never leaves rows unanswered.
    pub(crate) fn flush(&mut self) -> Result<Option<Estimate>, EstimatorError> {
        match self.last_block_t_s {
            Some(t_s) if self.since_solve > 0 && self.qr.rows >= 6 => self.solve_now(t_s).map(Some),
            _ => Ok(None),
        }
    }

    /// Blocks folded since the last solve.
    #[must_use]
    pub(crate) fn unsolved_blocks(&self) -> usize {
        self.since_solve
    }

    /// Solve with the data so far, stamped `t_s`.
    pub(crate) fn solve_now(&mut self, t_s: f64) -> Result<Estimate, EstimatorError> {
        self.since_solve = 0;
        let (solved, fit) = super::prior::augment(&self.qr, &self.constraints);
        self.solved = solved;
        self.sv = self.svd.singular_values(&self.solved.r);
        let e = estimate_from(
            &mut self.backend,
            &self.qr,
            &self.solved,
            fit,
            &self.sv,
            &self.constraints,
            &self.settings,
            self.last.and_then(|e| e.j()).as_ref(),
            t_s,
        )?;
        self.last = Some(e);
        Ok(e)
    }

    /// Least-squares standard deviation per element at the last solve (from the tracked
    /// SVD; see [`super::uncertainty`]).
    #[must_use]
    #[cfg_attr(not(feature = "std"), allow(dead_code))]
    pub(crate) fn noise_sigma(&self) -> Option<[f64; 6]> {
        super::uncertainty::noise_sigma(&self.solved, &self.sv, self.svd.v())
            .map(|s| super::prior::zero_fixed(s, &self.constraints))
    }

    /// The least-squares state with the prior knowledge stacked on, at the last solve
    /// ([`super::prior::augment`]).
    #[must_use]
    #[cfg_attr(not(feature = "std"), allow(dead_code))]
    pub(crate) fn solved(&self) -> &RecursiveQr {
        &self.solved
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
    pub(crate) fn gaps(&self) -> usize {
        self.source.gaps()
    }
}

/// Assess and solve the state `solved` (the data's state `data` with the prior knowledge
/// of `constraints` stacked on, [`super::prior::augment`], giving `fit`), whose `R` has
/// singular values `sv`: the estimate stamped `t_s`. Shared by the recursive estimators.
#[allow(clippy::too_many_arguments)]
pub(crate) fn estimate_from<B: Backend + ?Sized>(
    backend: &mut B,
    data: &RecursiveQr,
    solved: &RecursiveQr,
    fit: Option<super::prior::PriorFit>,
    sv: &nalgebra::Vector6<f64>,
    constraints: &Constraints,
    settings: &RecursiveSettings,
    warm: Option<&crate::tensor::InertiaVector>,
    t_s: f64,
) -> Result<Estimate, EstimatorError> {
    let has_bounds = constraints.set().has_bounds();
    let observability = with_prior(
        assess_with(
            solved,
            sv,
            has_bounds,
            &combined_settings(&settings.observability, fit.as_ref()),
        ),
        data,
        fit.as_ref(),
        constraints,
        &settings.observability,
    );
    let (solution, observability) = solve_with(
        backend,
        solved,
        constraints,
        observability,
        settings.gyro_noise_rad_s_rthz,
        warm,
    )?;
    Ok(Estimate {
        t_s,
        rows: data.rows,
        observability,
        solution,
        uncertainty: None,
        prior: fit,
    })
}

/// The observability thresholds of the problem with a Gaussian prior: no condition-number
/// test (the prior's rows are weighed against data that may fix other directions far
/// more sharply; the posterior σ, which the relative-σ test checks, is what counts).
pub(crate) fn combined_settings(
    settings: &ObservabilitySettings,
    fit: Option<&super::prior::PriorFit>,
) -> ObservabilitySettings {
    match fit {
        Some(_) => ObservabilitySettings {
            condition_threshold: f64::INFINITY,
            ..*settings
        },
        None => *settings,
    }
}

/// The status of an answer with prior knowledge: leaning on the constraint set when the
/// data contradict its equalities ([`super::prior::equality_chi2`]); withdrawn when a
/// Gaussian prior and the data disagree ([`super::prior::PriorFit::conflicts`]);
/// "determined with the prior knowledge" when the data alone (without equalities or
/// prior) would not determine J.
pub(crate) fn with_prior(
    observability: Observability,
    data: &RecursiveQr,
    fit: Option<&super::prior::PriorFit>,
    constraints: &Constraints,
    settings: &ObservabilitySettings,
) -> Observability {
    // Without excitation only a bound away from zero or a prior gives J its scale
    // (equalities at zero do not: the answer would be the floor's).
    let set = constraints.set();
    let observability = match observability {
        Observability::FromPrior(r @ super::observability::Unobservable::NoExcitation)
            if set.prior.is_none() && !set.has_scale_bound() =>
        {
            Observability::NotObservable(r)
        }
        o => o,
    };
    // Equalities the data contradict: the answer leans on them (as on a bound).
    if let (Observability::Determined { .. }, Some(chi2)) = (
        observability,
        super::prior::equality_chi2(data, constraints),
    ) {
        if chi2 > super::audit::CONFLICT_CHI2 {
            return Observability::FromPrior(
                super::observability::Unobservable::ConflictsWithConstraints { chi2 },
            );
        }
    }
    if !super::prior::applies(constraints) || !observability.has_answer() {
        return observability;
    }
    if let Some(fit) = fit.filter(|f| f.conflicts()) {
        return Observability::NotObservable(super::observability::Unobservable::PriorConflict {
            chi2: fit.chi2,
            rows: fit.rows,
        });
    }
    // "Determined by the data" only if the data alone, without the equalities and the
    // prior, would be.
    if let Observability::Determined { .. } = observability {
        let alone = assess(data, constraints.set().has_bounds(), settings);
        if let Some(reason) = alone.reason() {
            return Observability::FromPrior(reason);
        }
    }
    observability
}

/// Solve (with errors-in-variables compensation when a gyro noise is given) when the
/// observability allows an answer. Shared by the recursive and batch estimators.
pub(crate) fn solve_with<B: Backend + ?Sized>(
    backend: &mut B,
    qr: &RecursiveQr,
    constraints: &Constraints,
    observability: Observability,
    gyro_noise_rad_s_rthz: Option<f64>,
    warm: Option<&crate::tensor::InertiaVector>,
) -> Result<(Option<crate::solver::Solution>, Observability), EstimatorError> {
    if !observability.has_answer() {
        return Ok((None, observability));
    }
    let (r, z) = match gyro_noise_rad_s_rthz {
        Some(g) if g > 0.0 && qr.noise_s > 0.0 => {
            match super::compensation::compensate(qr, g) {
                Some(rz) => rz,
                // The open direction is the prior's to fix: solve uncompensated.
                None if matches!(observability, Observability::FromPrior(_)) => (qr.r, qr.z),
                None => {
                    return Ok((
                        None,
                        Observability::NotObservable(
                            super::observability::Unobservable::NoiseDominated,
                        ),
                    ))
                }
            }
        }
        _ => (qr.r, qr.z),
    };
    let sol = solve(&mut &mut *backend, &r, &z, constraints, warm)?;
    Ok((Some(sol), observability))
}
