//! The discrete momentum estimator over a whole record at once (`--batch`): every
//! candidate reduced in one pass, chosen as the recursive path chooses, with the same σ and
//! status checks.

use super::candidates::{candidates, chained_siblings};
use super::cross_check::{reconcile, COMPARABLE_FIT};
use super::select::{alternatives_from_s, in_running, pick};
use super::sigma::{
    discretisation_bias, double_step, model_spread, own_answer, quadrature, scale_from_prior,
    sibling_jackknife,
};
use super::standing::RULE_OUT_AFTER;
use super::twins;
use super::DISCRETE_MOMENTUM;
use crate::eigen3::symmetric_eigen3;
use crate::estimator::audit::{audit, reversed_at_floor};
use crate::estimator::consistency;
use crate::estimator::discrete_momentum::{reduce_batch, torque_tested, BatchReduction};
use crate::estimator::excitation::diagnose;
use crate::estimator::jackknife::robust_sigma;
use crate::estimator::momentum_rows::{MomentumRowSettings, RotationSource};
use crate::estimator::observability::Observability;
use crate::estimator::prior;
use crate::estimator::uncertainty::{noise_sigma, with_bias};
use crate::estimator::{batch, Estimate, EstimatorError};
use crate::pipeline::registry::{self, BatchOutput};
use crate::pipeline::{PipelineConfig, PipelineError};
use crate::sample::Sample;
use crate::tensor::matrix_from_j;
use std::vec::Vec;

pub(super) fn run_batch(
    samples: &[Sample],
    c: &PipelineConfig,
) -> Result<BatchOutput, PipelineError> {
    let wrap = |source| PipelineError::Estimator {
        sample: match source {
            EstimatorError::Row { sample, .. } => Some(sample),
            _ => None,
        },
        source,
    };
    // The drift weighting needs an estimate of J before each row is folded: recursive
    // runs only.
    if c.attitude_drift_deg_rth.is_some() {
        return Err(PipelineError::NotApplicable {
            setting: "attitude_drift_deg_rth",
            estimator: "discrete-momentum batch",
        });
    }
    let has_gyro = samples.first().is_some_and(|s| s.omega_rad_s.is_some());
    let mut reduced: Vec<(MomentumRowSettings, BatchReduction)> = Vec::new();
    for rows in candidates(c, has_gyro) {
        reduced.push((rows, reduce_batch(samples, &rows).map_err(wrap)?));
    }
    let attitude_is_gyro_integral = drop_batch_twins(&mut reduced, c);
    let fits: Vec<(f64, f64, Option<f64>)> = reduced
        .iter()
        .map(|(rows, b)| {
            (
                b.qr.residual_variance(),
                b.qr.residual_dof(),
                rows.max_chain_s,
            )
        })
        .collect();
    let rows: Vec<MomentumRowSettings> = reduced.iter().map(|(r, _)| *r).collect();
    let (chosen, from_s) = pick(&fits, &rows, |i| {
        reduced.get(i).and_then(|(_, b)| b.jackknife_sigma_kg_m2)
    });
    let from_s = rows
        .get(chosen)
        .map_or(from_s, |r| alternatives_from_s(r, from_s, c.max_chain_s));
    let Some((rows, batch)) = reduced.get(chosen) else {
        return Err(PipelineError::NoBatch {
            estimator: DISCRETE_MOMENTUM.name,
        });
    };
    let qr = &batch.qr;
    let (tested, torque_test) = torque_tested(batch.qr, batch.without_torque);
    let mut backend = registry::build_backend(c.backend);
    let t_s = samples.last().map_or(0.0, |s| s.t_s);
    // One candidate's own answer and noise σ (for the whole record as one chain, at
    // least its chained siblings' jackknife σ: [`chained_siblings`]).
    let mut own = |i: usize| -> Result<(Estimate, Option<[f64; 6]>), PipelineError> {
        let (rows, b) = &reduced[i];
        let sibling = sibling_jackknife(
            chained_siblings(
                rows,
                reduced.iter().map(|(r, _)| r),
                c.max_chain_s.unwrap_or(0.0),
            )
            .map(|k| reduced[k].1.jackknife_sigma_kg_m2),
        );
        // As the recursive solve does: the torque held at zero where the data give no
        // evidence of one.
        let (tested, _) = torque_tested(b.qr, b.without_torque);
        let e = batch::solve_reduced(
            &tested,
            t_s,
            &c.constraints,
            &mut *backend,
            &c.observability,
            c.gyro_noise_rad_s_rthz,
        )
        .map_err(wrap)?;
        // With prior knowledge, σ is the least-squares one of the data and the prior
        // together, or the data's own jackknife σ where that is larger (the batch
        // jackknife's delete-one solves carry no prior: conservative).
        let (solved, _) = prior::augment(&tested, &c.constraints);
        let jackknife = sibling_jackknife([b.jackknife_sigma_kg_m2, sibling].into_iter());
        let svd = nalgebra::SVD::try_new(
            solved.r,
            false,
            true,
            f64::EPSILON,
            crate::math::MAX_DECOMPOSITION_ITERATIONS,
        );
        let noise = svd.and_then(|svd| {
            let v_t = svd.v_t?;
            noise_sigma(&solved, &svd.singular_values, &v_t.transpose())
                .map(|ls| robust_sigma(&prior::zero_fixed(ls, &c.constraints), jackknife.as_ref()))
        });
        Ok((e, noise))
    };
    let (mut estimate, noise) = own(chosen)?;
    // The chosen rows with the prior's: what the audit judges.
    let augmented = prior::augment(&tested, &c.constraints).0;
    if c.uncertainty {
        if let (Some(j), Some(noise)) = (estimate.j(), noise) {
            let others = reduced
                .iter()
                .enumerate()
                .filter(|&(i, (r, _))| i != chosen && in_running(r, from_s))
                .map(|(_, (_, b))| b.qr);
            let spread = model_spread(&tested, others, c.gyro_noise_rad_s_rthz, &c.constraints);
            // As in the recursive path: the first candidate on every other sample.
            let half: Vec<Sample> = samples
                .chunks_exact(2)
                .map(|p| double_step(&p[0], &p[1]))
                .collect();
            let discretisation = match (reduced.first(), c.gyro_noise_rad_s_rthz) {
                (Some((first, full)), gyro) => match reduce_batch(&half, first) {
                    Ok(h) => discretisation_bias(&full.qr, &h.qr, gyro, &c.constraints),
                    Err(_) => [0.0; 6],
                },
                _ => [0.0; 6],
            };
            let bias = quadrature(&spread, &discretisation);
            estimate.uncertainty = Some(with_bias(&noise, &bias, &j));
        }
        // As in the recursive path: a reversed ρ is told before the cross-check.
        let reversed = estimate.j().is_some_and(|j| {
            reversed_at_floor(
                &estimate,
                &augmented,
                c.constraints.set().epsilon_kg_m2,
                c.observability.max_relative_sigma,
                &symmetric_eigen3(&matrix_from_j(&j)).0,
            )
        });
        if !reversed && matches!(estimate.observability, Observability::Determined { .. }) {
            let mut others = Vec::new();
            for (i, (r, b)) in reduced.iter().enumerate() {
                if i == chosen
                    || !in_running(r, from_s)
                    || !(b.qr.residual_variance() <= COMPARABLE_FIT * qr.residual_variance())
                {
                    continue;
                }
                if let (e, Some(sigma)) = own(i)? {
                    if let (Observability::Determined { .. }, Some(jb)) = (e.observability, e.j()) {
                        others.push((jb, sigma));
                    }
                }
            }
            if let Some(j) = estimate.j() {
                let eig = symmetric_eigen3(&matrix_from_j(&j));
                reconcile(
                    &mut estimate,
                    &eig,
                    &others,
                    c.observability.max_relative_sigma,
                );
            }
        }
    }
    audit(
        &mut estimate,
        &augmented,
        c.constraints.set().epsilon_kg_m2,
        c.observability.max_relative_sigma,
    );
    scale_from_prior(&mut estimate, &tested, &c.constraints);
    // The residuals against the stated gyro density, as in the recursive path: the gyro
    // rotation's rows are the ones the density describes. (The span test needs the
    // recursive residuals, which a batch reduction does not form.)
    let gyro_density_ratio = match (c.gyro_noise_rad_s_rthz, estimate.j()) {
        (Some(g), Some(j)) => reduced
            .iter()
            .find(|(rows, _)| rows.rotation == RotationSource::Gyro)
            .and_then(|(_, b)| consistency::gyro_density_ratio(&b.qr, &j, g)),
        _ => None,
    };
    consistency::check(&mut estimate, None, gyro_density_ratio);
    Ok(BatchOutput {
        gyro_density_ratio,
        estimate,
        excitation: Some(diagnose(&tested, &c.observability)),
        gaps: batch.gaps,
        row_model: Some(*rows),
        torque_test,
        attitude_is_gyro_integral,
    })
}

/// The batch form of the test for an attitude that is the gyro's own integral
/// ([`twins`]): over a record of at least [`RULE_OUT_AFTER`] row blocks (the
/// recursive test's horizon), the pairs of candidates that differ only in the rotation
/// source are compared once, on the whole record; within [`twins::TWIN_Z`], the
/// attitude's candidates are left out. `Some(verdict)` where the test was made, `None`
/// for a shorter record or without both sources.
pub(super) fn drop_batch_twins(
    reduced: &mut Vec<(MomentumRowSettings, BatchReduction)>,
    c: &PipelineConfig,
) -> Option<bool> {
    let rows: Vec<MomentumRowSettings> = reduced.iter().map(|(r, _)| *r).collect();
    let pairs = twins::pairs(&rows, |_| true);
    let blocks = reduced.first().map_or(0, |(_, b)| b.qr.rows / 3);
    if pairs.clone().next().is_none() || blocks < RULE_OUT_AFTER {
        return None;
    }
    let worst = twins::worst(pairs, |i| {
        own_answer(&reduced[i].1.qr, c.gyro_noise_rad_s_rthz, &c.constraints)
    });
    // Every attitude candidate has a twin where the verdict is `Same` ([`twins::worst`]).
    let same = worst.is_some_and(|z| z <= twins::TWIN_Z);
    if same {
        reduced.retain(|(r, _)| r.rotation != RotationSource::Attitude);
    }
    Some(same)
}
