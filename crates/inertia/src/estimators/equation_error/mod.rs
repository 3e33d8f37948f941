//! The filtered equation-error least-squares baseline: Euler's equation of the gyrostat
//! (paper eq. 26, docs/conventions.md §1), in body axes,
//!
//! ```text
//! J ω̇ + ω × (J ω + ρ) + ρ̇ = τ
//! ⇒ [G(ω̇) + S(ω) G(ω)] j (− τ_b) = τ − ρ̇ − ω × ρ        (G of eq. 47: J x = G(x) j)
//! ```
//!
//! with ω, ω̇, ρ, ρ̇ and τ at each node from one zero-phase low-pass filter and
//! differentiator ([`filter`], Savitzky–Golay of order 4) applied to the gyro's integrated
//! angle `θ(t_k) = Σ_{i<k} h ω̄_i` (its first and second derivatives are ω and ω̇; a
//! delta-angle gyro's rates are interval means, so θ is exact at the nodes), to ρ and to τ.
//! This is what experimenters use on lab records (a "filtered equation error" fit); it is
//! the baseline the lab cells of the Monte Carlo matrix compare with. The attitude is not
//! used.
//!
//! One 3-row block per node with a full window (the first and last m nodes have none),
//! stacked in normal equations and solved once per estimate by least squares, with
//! optionally a constant body-frame torque `τ_b` as three more unknowns
//! ([`EquationErrorSettings::body_torque`]). Its σ is the least-squares one,
//! `σ² = RSS/(3n − p)` times the diagonal of `(AᵀA)⁻¹`: it takes the rows as independent,
//! which the filter's overlapping windows make them not, so it is optimistic by about the
//! square root of the number of rows per independent window.
//!
//! It streams: a row needs the m samples after its node, so the state is the last `2m + 1`
//! samples and the normal equations; the estimate after the last sample is the batch
//! least-squares answer (the pipeline's batch form is not registered: it has no
//! excitation report).
//! The time step must be uniform (within 0.1 %); no constraints and no observability test
//! ([`Observability::Unchecked`]), except that a singular system is refused
//! ([`Unobservable::RankDeficient`]) and a J that is not physical is not an answer
//! ([`crate::estimator::momentum::not_physical`]).

pub(crate) mod filter;
#[cfg(test)]
mod tests;

use crate::attitude::skew;
use crate::discrete::g_matrix;
use crate::estimator::momentum::gyro_sample;
use crate::estimator::observability::{Observability, Unobservable};
use crate::estimator::{Estimate, EstimatorError};
use crate::pipeline::config::EstimatorEntry;
use crate::pipeline::config::PipelineConfig;
use crate::pipeline::diagnostics::Diagnostics;
use crate::pipeline::error::PipelineError;
use crate::pipeline::interface::{Capabilities, Estimator};
use crate::sample::Sample;
use crate::solver::{Residuals, Solution, SolveStatus};
use crate::tensor::InertiaVector;
use filter::SavitzkyGolay;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use std::boxed::Box;
use std::collections::VecDeque;
use std::vec::Vec;

/// Registry entry.
pub(crate) const EQUATION_ERROR: EstimatorEntry = EstimatorEntry {
    name: "equation-error",
    summary: "filtered equation-error least squares (Savitzky-Golay ω̇, ρ̇; Euler's equation), unconstrained, needs gyro rates",
    capabilities: Capabilities {
        needs_gyro: true,
        constraints: false,
        compensation: false,
        uncertainty: true,
        row_model: false,
        filter: true,
    },
    build,
    batch: None,
};

/// The default cutoff as a fraction of the sample rate: 200 Hz at 4 kHz, 0.5 Hz at 10 Hz
/// (a window of 33 samples; 63 samples leave a 4e-4 filter bias on the paper's slew).
pub(crate) const DEFAULT_CUTOFF_FRACTION: f64 = 1.0 / 20.0;

/// Relative tolerance on the time step.
const STEP_TOLERANCE: f64 = 1e-3;

/// Settings of the baseline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct EquationErrorSettings {
    /// The filter's −3 dB cutoff, Hz (`None`: [`DEFAULT_CUTOFF_FRACTION`] of the sample
    /// rate).
    pub(crate) cutoff_hz: Option<f64>,
    /// Estimate a constant body-frame torque beside j.
    pub(crate) body_torque: bool,
    /// Estimate every this many samples.
    pub(crate) solve_every: usize,
}

impl Default for EquationErrorSettings {
    fn default() -> Self {
        Self {
            cutoff_hz: None,
            body_torque: false,
            solve_every: 1,
        }
    }
}

/// One node of the window.
#[derive(Debug, Clone, Copy)]
struct Node {
    t_s: f64,
    /// The integrated gyro angle at the node, rad.
    theta_rad: Vector3<f64>,
    rho_nms: Vector3<f64>,
    tau_nm: Vector3<f64>,
}

/// The estimator's state.
#[derive(Debug, Clone)]
pub(crate) struct EquationError {
    settings: EquationErrorSettings,
    filter: Option<SavitzkyGolay>,
    step_s: Option<f64>,
    window: VecDeque<Node>,
    last_rate: Option<Vector3<f64>>,
    /// Normal equations `AᵀA`, `Aᵀb`, `bᵀb` over p unknowns.
    ata: DMatrix<f64>,
    atb: DVector<f64>,
    btb: f64,
    blocks: usize,
    samples: usize,
    /// The time of the last sample that `solve_every` left unanswered, for
    /// [`EquationError::flush`].
    unanswered_t_s: Option<f64>,
}

impl EquationError {
    /// A new estimator.
    #[must_use]
    pub(crate) fn new(settings: EquationErrorSettings) -> Self {
        let p = Self::unknowns(settings.body_torque);
        Self {
            settings,
            filter: None,
            step_s: None,
            window: VecDeque::new(),
            last_rate: None,
            ata: DMatrix::zeros(p, p),
            atb: DVector::zeros(p),
            btb: 0.0,
            blocks: 0,
            samples: 0,
            unanswered_t_s: None,
        }
    }

    fn unknowns(body_torque: bool) -> usize {
        if body_torque {
            9
        } else {
            6
        }
    }

    /// Feed a sample; an estimate when one is due (every
    /// [`EquationErrorSettings::solve_every`] samples once there are rows).
    pub(crate) fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        let index = self.samples;
        self.samples += 1;
        let rate = gyro_sample(s, index)?;
        let theta = match (self.window.back().copied(), self.last_rate) {
            (Some(prev), Some(prev_rate)) => {
                let step = s.t_s - prev.t_s;
                self.check_step(step)?;
                prev.theta_rad + prev_rate * step
            }
            _ => Vector3::zeros(),
        };
        self.window.push_back(Node {
            t_s: s.t_s,
            theta_rad: theta,
            rho_nms: s.rho_nms,
            tau_nm: s.tau_nm,
        });
        self.last_rate = Some(rate);
        let Some(f) = &self.filter else {
            return Ok(None);
        };
        if self.window.len() > f.window_len() {
            self.window.pop_front();
        }
        if self.window.len() == f.window_len() {
            self.add_row();
        }
        let due = self
            .samples
            .is_multiple_of(self.settings.solve_every.max(1));
        let ready = 3 * self.blocks > self.ata.nrows();
        self.unanswered_t_s = (ready && !due).then_some(s.t_s);
        Ok((due && ready).then(|| self.estimate(s.t_s)))
    }

    /// At the end of the input: the estimate at the last sample where `solve_every` left
    /// it unanswered.
    pub(crate) fn flush(&mut self) -> Option<Estimate> {
        self.unanswered_t_s.take().map(|t_s| self.estimate(t_s))
    }

    /// The first step fixes the filter; every later one must equal it.
    fn check_step(&mut self, step: f64) -> Result<(), EstimatorError> {
        match self.step_s {
            None => {
                if !(step > 0.0) {
                    return Err(EstimatorError::InvalidSetting {
                        field: "t",
                        why: "the equation-error baseline needs increasing time stamps",
                    });
                }
                let rate = 1.0 / step;
                let cutoff = self
                    .settings
                    .cutoff_hz
                    .unwrap_or(rate * DEFAULT_CUTOFF_FRACTION);
                self.step_s = Some(step);
                self.filter = Some(SavitzkyGolay::for_cutoff(cutoff, rate));
                Ok(())
            }
            Some(h) if (step - h).abs() <= STEP_TOLERANCE * h => Ok(()),
            Some(_) => Err(EstimatorError::InvalidSetting {
                field: "t",
                why: "the equation-error baseline needs a uniform time step (resample the telemetry onto a uniform grid)",
            }),
        }
    }

    /// The 3-row block of the window's centre node, added to the normal equations.
    fn add_row(&mut self) {
        let (Some(f), Some(h)) = (&self.filter, self.step_s) else {
            return;
        };
        let m = f.half_width;
        let centre = self.window[m].theta_rad;
        let rel: Vec<Vector3<f64>> = self.window.iter().map(|n| n.theta_rad - centre).collect();
        let omega = filter::apply(&f.d1, rel.iter()) / h;
        let omega_dot = filter::apply(&f.d2, rel.iter()) / (h * h);
        let rho = filter::apply(&f.smooth, self.window.iter().map(|n| &n.rho_nms));
        let rho_dot = filter::apply(&f.d1, self.window.iter().map(|n| &n.rho_nms)) / h;
        let tau = filter::apply(&f.smooth, self.window.iter().map(|n| &n.tau_nm));
        let a_j = g_matrix(&omega_dot) + skew(&omega) * g_matrix(&omega);
        let b = tau - rho_dot - omega.cross(&rho);
        let p = self.ata.nrows();
        let mut a = DMatrix::<f64>::zeros(3, p);
        a.view_mut((0, 0), (3, 6)).copy_from(&a_j);
        if p == 9 {
            a.view_mut((0, 6), (3, 3))
                .copy_from(&(-Matrix3::identity()));
        }
        let bv = DVector::from_column_slice(b.as_slice());
        self.ata += a.transpose() * &a;
        self.atb += a.transpose() * &bv;
        self.btb += b.norm_squared();
        self.blocks += 1;
    }

    /// The least-squares answer of the rows so far.
    #[must_use]
    pub(crate) fn estimate(&self, t_s: f64) -> Estimate {
        let p = self.ata.nrows();
        let rows = 3 * self.blocks;
        let not = |reason| Estimate {
            t_s,
            rows,
            observability: Observability::NotObservable(reason),
            solution: None,
            uncertainty: None,
            prior: None,
        };
        // Equilibrate the columns, then solve by Cholesky.
        let d = DVector::from_fn(p, |i, _| {
            let v = self.ata[(i, i)];
            if v > 0.0 {
                1.0 / v.sqrt()
            } else {
                0.0
            }
        });
        let scaled = DMatrix::from_fn(p, p, |i, k| self.ata[(i, k)] * d[i] * d[k]);
        let eig = scaled.clone().symmetric_eigenvalues();
        let max = eig.max();
        let rank = eig.iter().filter(|v| **v > 1e-12 * max).count();
        let inverse = (rank == p)
            .then(|| scaled.cholesky())
            .flatten()
            .map(|c| c.inverse());
        let Some(inv_scaled) = inverse else {
            return not(Unobservable::RankDeficient { rank: rank.min(6) });
        };
        let inv = DMatrix::from_fn(p, p, |i, k| inv_scaled[(i, k)] * d[i] * d[k]);
        let x = &inv * &self.atb;
        let j = InertiaVector::from_fn(|i, _| x[i]);
        if !j.iter().all(|v| v.is_finite()) {
            return not(Unobservable::Diverged);
        }
        if let Some(reason) = crate::estimator::momentum::not_physical(&j) {
            return not(reason);
        }
        let rss = (self.btb - x.dot(&self.atb)).max(0.0);
        let dof = rows.saturating_sub(p).max(1) as f64;
        let s2 = rss / dof;
        let noise: [f64; 6] = core::array::from_fn(|k| (s2 * inv[(k, k)]).max(0.0).sqrt());
        Estimate {
            t_s,
            rows,
            observability: Observability::Unchecked,
            solution: Some(Solution {
                j,
                objective: rss,
                status: SolveStatus::Unconstrained,
                iterations: 0,
                residuals: Residuals::default(),
            }),
            uncertainty: Some(crate::estimator::uncertainty::with_bias(
                &noise, &[0.0; 6], &j,
            )),
            prior: None,
        }
    }

    /// The estimated constant body-frame torque, N m, when estimated and solvable.
    #[must_use]
    pub(crate) fn body_torque_nm(&self) -> Option<Vector3<f64>> {
        if self.ata.nrows() != 9 {
            return None;
        }
        let x = self.ata.clone().cholesky()?.solve(&self.atb);
        Some(Vector3::new(x[6], x[7], x[8]))
    }
}

struct Streaming(EquationError);

impl Estimator for Streaming {
    fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        self.0.push(s)
    }

    fn flush(&mut self) -> Result<Option<Estimate>, EstimatorError> {
        Ok(self.0.flush())
    }

    fn diagnostics(&self) -> Diagnostics {
        Diagnostics {
            torque_bias_nm: self.0.body_torque_nm(),
            ..Diagnostics::default()
        }
    }
}

fn settings(c: &PipelineConfig) -> Result<EquationErrorSettings, PipelineError> {
    if let Some(m) = c.memory_s {
        return Err(PipelineError::InvalidSetting {
            field: "memory_s",
            value: m,
            expected: "none: the equation-error baseline weighs every row alike",
        });
    }
    Ok(EquationErrorSettings {
        solve_every: c.solve_every,
        cutoff_hz: c.filter_cutoff_hz,
        ..EquationErrorSettings::default()
    })
}

fn build(c: &PipelineConfig) -> Result<Box<dyn Estimator>, PipelineError> {
    Ok(Box::new(Streaming(EquationError::new(settings(c)?))))
}
