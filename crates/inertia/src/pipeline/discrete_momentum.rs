//! The discrete momentum estimator ([`crate::estimator::discrete_momentum`]) in the
//! pipeline, with the row model chosen from the data.
//!
//! The wheel momentum between samples is estimated with `j` by default
//! ([`Stencil::Adaptive`]). Where a setting leaves a choice open (the rotation source when
//! the telemetry has gyro rates, or a stencil the user names), every candidate row model
//! folds every sample, and each solve uses the candidate whose residual variance
//! `ρ²/(rows − unknowns)` is smallest: the model that explains the data best (a noisier
//! rotation source leaves larger residuals). Only the chosen candidate is solved.

use super::registry::{self, BatchOutput, Capabilities, Estimator, EstimatorEntry};
use super::settings::PipelineConfig;
use super::PipelineError;
use crate::estimator::audit::audit;
use crate::estimator::discrete_momentum::{
    reduce_batch, BatchReduction, DiscreteMomentumEstimator, MomentumEstimatorSettings,
};
use crate::estimator::excitation::{diagnose, Excitation};
use crate::estimator::jackknife::robust_sigma;
use crate::estimator::momentum_rows::{MomentumRowSettings, RhoModel, RotationSource, Stencil};
use crate::estimator::qr::RecursiveQr;
use crate::estimator::recursive::RecursiveSettings;
use crate::estimator::uncertainty::{noise_sigma, with_bias};
use crate::estimator::{batch, Estimate, EstimatorError};
use crate::sample::Sample;
use crate::solver::{unconstrained_minimiser, Backend};
use nalgebra::Vector3;
use std::boxed::Box;
use std::vec::Vec;

/// Registry entry.
pub(crate) const DISCRETE_MOMENTUM: EstimatorEntry = EstimatorEntry {
    name: "discrete-momentum",
    summary: "discrete conservation of angular momentum (telescoped paper rows), unknown constant torque, Richardson O(h^4) rows, constrained",
    capabilities: Capabilities {
        needs_gyro: false,
        constraints: true,
        compensation: false,
        uncertainty: true,
        row_model: true,
    },
    build,
    batch: Some(run_batch),
};

type Candidate = DiscreteMomentumEstimator<Box<dyn Backend + Send>>;

/// The candidate row settings for a configuration, given whether the telemetry has gyro
/// rates.
fn candidates(c: &PipelineConfig, has_gyro: bool) -> Vec<MomentumRowSettings> {
    let rotations: &[RotationSource] = match c.rotation_source {
        Some(RotationSource::Attitude) => &[RotationSource::Attitude],
        Some(RotationSource::Gyro) => &[RotationSource::Gyro],
        None if has_gyro => &[RotationSource::Gyro, RotationSource::Attitude],
        None => &[RotationSource::Attitude],
    };
    let stencils: &[Stencil] = match c.rho_model {
        RhoModel::Plain => &[Stencil::Plain],
        RhoModel::Held => &[Stencil::Held],
        RhoModel::Smooth => &[Stencil::Smooth],
        RhoModel::Auto => &[Stencil::Adaptive],
    };
    rotations
        .iter()
        .flat_map(|&rotation| {
            stencils.iter().map(move |&stencil| MomentumRowSettings {
                rotation,
                stencil,
                torque_bias: c.torque_bias,
                max_chain_s: c.max_chain_s,
            })
        })
        .collect()
}

fn settings(c: &PipelineConfig, rows: MomentumRowSettings) -> MomentumEstimatorSettings {
    MomentumEstimatorSettings {
        rows,
        recursive: RecursiveSettings {
            solve_every: 1,
            observability: c.observability,
            memory_s: c.memory_s,
            gyro_noise_rad_s_rthz: None,
        },
    }
}

/// Residual variance of a reduced state, `∞` without residual degrees of freedom.
fn variance(qr: &RecursiveQr) -> f64 {
    let dof = qr.residual_dof();
    if dof > 0.0 {
        qr.rss / dof
    } else {
        f64::INFINITY
    }
}

/// The model-uncertainty part of σ: per element, the largest difference between the
/// chosen candidate's unconstrained `ĵ` and that of any candidate the data cannot tell
/// apart from it: a residual variance within `1 + 3√(2/ν)` of the chosen one's, with `ν`
/// the chosen one's residual degrees of freedom (three standard deviations of the ratio
/// of two variance estimates with ν degrees of freedom each). When two models of the
/// wheels, or two rotation sources, fit the data equally well, neither is known to be
/// right, and the answer is uncertain by at least their difference. Zero when the chosen
/// model fits significantly best.
fn model_spread(states: &[RecursiveQr], chosen: usize) -> [f64; 6] {
    let mut out = [0.0; 6];
    let Some(best) = states.get(chosen) else {
        return out;
    };
    let v_best = variance(best);
    let dof = best.residual_dof();
    if !(dof > 0.0) {
        return out;
    }
    let ratio = 1.0 + 3.0 * libm::sqrt(2.0 / dof);
    let Some(j_best) = unconstrained_minimiser(&best.r, &best.z) else {
        return out;
    };
    for (i, qr) in states.iter().enumerate() {
        if i == chosen || !(variance(qr) <= ratio * v_best) {
            continue;
        }
        if let Some(j) = unconstrained_minimiser(&qr.r, &qr.z) {
            for (o, (a, b)) in out.iter_mut().zip(j.iter().zip(j_best.iter())) {
                *o = o.max((a - b).abs());
            }
        }
    }
    out
}

/// Index of the smallest residual variance (the first on ties; `0` when none is finite).
fn best(variances: impl Iterator<Item = f64>) -> usize {
    let mut out = (0, f64::INFINITY);
    for (i, v) in variances.enumerate() {
        if v < out.1 {
            out = (i, v);
        }
    }
    out.0
}

struct DiscreteMomentum {
    config: PipelineConfig,
    candidates: Vec<Candidate>,
    chosen: usize,
    since_solve: usize,
}

fn build(c: &PipelineConfig) -> Result<Box<dyn Estimator>, PipelineError> {
    // Validate the estimator settings now; candidates are built at the first sample.
    MomentumEstimatorSettings::validate(&settings(c, MomentumRowSettings::default())).map_err(
        |source| PipelineError::Estimator {
            sample: None,
            source,
        },
    )?;
    Ok(Box::new(DiscreteMomentum {
        config: *c,
        candidates: Vec::new(),
        chosen: 0,
        since_solve: 0,
    }))
}

impl DiscreteMomentum {
    fn start(&mut self, first: &Sample) -> Result<(), EstimatorError> {
        for rows in candidates(&self.config, first.omega_rad_s.is_some()) {
            let backend = registry::build_backend(self.config.backend);
            self.candidates.push(DiscreteMomentumEstimator::new(
                settings(&self.config, rows),
                self.config.constraints,
                backend,
            )?);
        }
        Ok(())
    }
}

impl Estimator for DiscreteMomentum {
    fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        if self.candidates.is_empty() {
            self.start(s)?;
        }
        let mut folded = false;
        for c in &mut self.candidates {
            folded |= c.fold(s)?;
        }
        if !folded {
            return Ok(None);
        }
        self.since_solve += 1;
        if self.since_solve < self.config.solve_every {
            return Ok(None);
        }
        self.chosen = best(self.candidates.iter().map(|c| c.qr().residual_variance()));
        let Some(c) = self.candidates.get_mut(self.chosen) else {
            return Ok(None);
        };
        if c.qr().rows() < 6 {
            return Ok(None);
        }
        self.since_solve = 0;
        let mut e = c.solve_now(s.t_s)?;
        let noise = c.robust_noise_sigma();
        if self.config.uncertainty {
            if let (Some(j), Some(noise)) = (e.j(), noise) {
                let states: Vec<RecursiveQr> =
                    self.candidates.iter().map(|c| c.qr().reduced()).collect();
                let bias = model_spread(&states, self.chosen);
                e.uncertainty = Some(with_bias(&noise, &bias, &j));
            }
        }
        let Some(c) = self.candidates.get(self.chosen) else {
            return Ok(Some(e));
        };
        audit(
            &mut e,
            c.reduced(),
            self.config.constraints.set().epsilon_kg_m2,
            self.config.observability.max_relative_sigma,
        );
        Ok(Some(e))
    }

    fn gaps(&self) -> usize {
        self.candidates.first().map_or(0, |c| c.gaps())
    }

    fn excitation(&self) -> Option<Excitation> {
        let c = self.candidates.get(self.chosen)?;
        (c.reduced().rows > 0).then(|| diagnose(c.reduced(), &self.config.observability))
    }

    fn row_model(&self) -> Option<MomentumRowSettings> {
        self.candidates.get(self.chosen).map(|c| *c.row_settings())
    }

    fn torque_bias_nm(&self) -> Option<Vector3<f64>> {
        self.candidates.get(self.chosen)?.torque_bias_nm()
    }
}

fn run_batch(samples: &[Sample], c: &PipelineConfig) -> Result<BatchOutput, PipelineError> {
    let wrap = |source| PipelineError::Estimator {
        sample: match source {
            EstimatorError::Row { sample, .. } => Some(sample),
            _ => None,
        },
        source,
    };
    let has_gyro = samples.first().is_some_and(|s| s.omega_rad_s.is_some());
    let mut reduced: Vec<(MomentumRowSettings, BatchReduction)> = Vec::new();
    for rows in candidates(c, has_gyro) {
        reduced.push((rows, reduce_batch(samples, &rows).map_err(wrap)?));
    }
    let chosen = best(reduced.iter().map(|(_, b)| variance(&b.qr)));
    let Some((rows, batch)) = reduced.get(chosen) else {
        return Err(PipelineError::NoBatch {
            estimator: DISCRETE_MOMENTUM.name,
        });
    };
    let qr = &batch.qr;
    let mut backend = registry::build_backend(c.backend);
    let mut estimate = batch::solve_reduced(
        qr,
        samples.last().map_or(0.0, |s| s.t_s),
        &c.constraints,
        &mut *backend,
        &c.observability,
        None,
    )
    .map_err(wrap)?;
    if c.uncertainty {
        let svd = qr.r.svd(false, true);
        if let (Some(j), Some(v_t)) = (estimate.j(), svd.v_t) {
            let sv = svd.singular_values;
            if let Some(ls) = noise_sigma(qr, &sv, &v_t.transpose()) {
                let noise = robust_sigma(&ls, batch.jackknife_sigma_kg_m2.as_ref());
                let states: Vec<RecursiveQr> = reduced.iter().map(|(_, b)| b.qr).collect();
                let bias = model_spread(&states, chosen);
                estimate.uncertainty = Some(with_bias(&noise, &bias, &j));
            }
        }
    }
    audit(
        &mut estimate,
        qr,
        c.constraints.set().epsilon_kg_m2,
        c.observability.max_relative_sigma,
    );
    Ok(BatchOutput {
        estimate,
        excitation: Some(diagnose(qr, &c.observability)),
        gaps: batch.gaps,
        row_model: Some(*rows),
    })
}
