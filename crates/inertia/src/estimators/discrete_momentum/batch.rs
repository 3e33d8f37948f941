//! The discrete momentum estimator over a whole record at once (`--batch`): every
//! candidate reduced in one pass, chosen as the recursive path chooses ([`pick`]), its σ
//! and status given by the same sequence ([`finish`]).

use super::candidates::{candidates, chained_siblings};
use super::cross_check::COMPARABLE_FIT;
use super::finish::{finish, Evidence, Finished};
use super::select::{
    alternatives_from_s, in_running, pick, rejected_inertial_twin, test_inertial_torque,
};
use super::sigma::{
    discretisation_bias, double_step, model_spread, own_answer, sibling_jackknife,
    with_torque_model_shift,
};
use super::standing::RULE_OUT_AFTER;
use super::twins;
use super::DISCRETE_MOMENTUM;
use crate::estimator::consistency::{self, ResidualSegments};
use crate::estimator::discrete_momentum::{reduce_batch, torque_tested, BatchReduction};
use crate::estimator::excitation::diagnose;
use crate::estimator::external_torque::{Estimated3, OutsideEstimates};
use crate::estimator::jackknife::robust_sigma;
use crate::estimator::momentum_rows::{MomentumRowSettings, RotationSource};
use crate::estimator::observability::{Observability, Unobservable};
use crate::estimator::prior;
use crate::estimator::qr::RecursiveQr;
use crate::estimator::rate_noise::RateNoise;
use crate::estimator::uncertainty::noise_sigma;
use crate::estimator::{batch, Estimate, EstimatorError};
use crate::pipeline::config::{InertialTorque, PipelineConfig, SHORT_RECORD_S};
use crate::pipeline::diagnostics::Diagnostics;
use crate::pipeline::error::PipelineError;
use crate::pipeline::interface::{BatchInputs, BatchOutput};
use crate::sample::Sample;
use crate::solver::Backend;
use crate::tensor::InertiaVector;
use std::boxed::Box;
use std::vec::Vec;

/// A failed row or solve, with the sample it concerns where there is one.
fn wrap(source: EstimatorError) -> PipelineError {
    PipelineError::Estimator {
        sample: match source {
            EstimatorError::Row { sample, .. } => Some(sample),
            _ => None,
        },
        source,
    }
}

pub(super) fn run_batch(
    samples: &[Sample],
    c: &PipelineConfig,
    rotors: &BatchInputs,
) -> Result<BatchOutput, PipelineError> {
    // The drift weighting needs an estimate of J before each row is folded: recursive
    // runs only.
    if c.attitude_drift_deg_rth.is_some() {
        return Err(PipelineError::NotApplicable {
            setting: "attitude_drift_deg_rth",
            estimator: "discrete-momentum batch",
        });
    }
    // Without a stated gyro density, the compensation's from the rates, as the recursive
    // path has it at its last solve.
    // (Not on resampled rates, whose interpolation damps the noise.)
    let estimated = (c.gyro_noise_rad_s_rthz.is_none() && c.resample_s.is_none())
        .then(|| RateNoise::of_record(samples))
        .flatten();
    let config = PipelineConfig {
        gyro_noise_rad_s_rthz: c.gyro_noise_rad_s_rthz.or(estimated),
        gyro_noise_estimated: estimated.is_some(),
        ..*c
    };
    let c = &config;
    let has_gyro = samples.first().is_some_and(|s| s.omega_rad_s.is_some());
    let mut reduced: Vec<(MomentumRowSettings, BatchReduction)> = Vec::new();
    // A record longer than [`SHORT_RECORD_S`] is no longer short: without the torque the
    // default adds to short ones ([`InertialTorque::Short`]), as the streaming run rules it
    // out past that span. Of several records, the longest.
    let span = record_ranges(samples.len(), &rotors.records)
        .into_iter()
        .filter_map(|r| Some(samples.get(r.end.checked_sub(1)?)?.t_s - samples.get(r.start)?.t_s))
        .fold(0.0, f64::max);
    let long = c.inertial_torque == InertialTorque::Short && span > SHORT_RECORD_S;
    for rows in candidates(c, has_gyro) {
        if long && rows.inertial_torque {
            continue;
        }
        reduced.push((rows, reduce_batch(samples, &rows, rotors).map_err(wrap)?));
    }
    let attitude_is_gyro_integral = drop_batch_twins(&mut reduced, c);
    let mut fits: Vec<(f64, f64, Option<f64>)> = reduced
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
    test_inertial_torque(&mut fits, &rows);
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
    let (tested, torque_test) = torque_tested(
        batch.qr,
        batch.without_torque,
        batch.jackknife_sigma_kg_m2,
        &c.constraints,
    );
    let mut run = BatchRun {
        samples,
        rotors,
        config: c,
        reduced: &reduced,
        fits: &fits,
        chosen,
        from_s,
        tested,
        without_damping: batch.without_damping.as_ref().and_then(|w| {
            w.for_torque(torque_test.is_some_and(|t| t.held_at_zero))
                .copied()
        }),
        // The chosen rows with the prior's: what the audit judges.
        augmented: prior::augment(&tested, &c.constraints).0,
        backend: c.backend.build(),
        t_s: samples.last().map_or(0.0, |s| s.t_s),
        others: Vec::new(),
    };
    let (mut estimate, noise) = run.own(chosen)?;
    // (The span test needs the recursive residuals, which a batch reduction does not
    // form.)
    let (gyro_density_ratio, damping_nms) = match finish(&mut estimate, noise, &mut run)? {
        Finished::Checked {
            density_ratio,
            damping,
        } => (density_ratio, damping),
        Finished::Reversed => (None, None),
    };
    let outside = batch_outside(samples, rows, &reduced[chosen].1, &estimate);
    let rotor_calibration = reduced[chosen]
        .1
        .shared
        .as_ref()
        .zip(estimate.j())
        .and_then(|(f, j)| f.rotors_at(&j));
    Ok(BatchOutput {
        estimate,
        diagnostics: Diagnostics {
            gaps: batch.gaps,
            excitation: Some(diagnose(&tested, &c.observability)),
            row_model: Some(*rows),
            torque_test,
            gyro_density_ratio,
            gyro_noise_estimated_rad_s_rthz: estimated,
            damping_nms,
            outside,
            rotor_calibration,
            attitude_is_gyro_integral,
            ..Diagnostics::default()
        },
    })
}

/// The index ranges of the records that start at `starts` (after the first, at 0) in
/// `n` samples.
fn record_ranges(n: usize, starts: &[usize]) -> Vec<core::ops::Range<usize>> {
    let mut bounds: Vec<usize> = core::iter::once(0)
        .chain(starts.iter().copied().filter(|&s| s > 0 && s < n))
        .collect();
    bounds.push(n);
    bounds.windows(2).map(|w| w[0]..w[1]).collect()
}

/// The outside torques of a batch run at its answer `e`, from the chosen reduction:
/// whether the gravity gradient was modelled, the residual dipole and the centre of mass
/// with their least-squares σ and, in quadrature, `e`'s σ beyond its noise carried
/// through `∂x/∂j` (as the streaming run's).
fn batch_outside(
    samples: &[Sample],
    rows: &MomentumRowSettings,
    b: &BatchReduction,
    e: &Estimate,
) -> Option<OutsideEstimates> {
    let gravity_gradient =
        rows.outside.gravity_gradient && samples.iter().any(|s| s.external.position_m.is_some());
    let j = e.j()?;
    let values = b.shared.as_ref().map(|o| {
        let at = o.at(&j);
        let beyond = e.uncertainty.map_or([0.0; 6], |u| u.beyond_noise_kg_m2());
        let moved: [_; 6] = core::array::from_fn(|k| {
            let mut jk = j;
            jk[k] += 1.0;
            o.at(&jk)
        });
        core::array::from_fn::<_, 2, _>(|blk| {
            at[blk].map(|(value, sigma)| {
                let sigma = core::array::from_fn(|i| {
                    let carried: f64 = (0..6)
                        .filter_map(|k| moved[k][blk].map(|m| (m.0[i] - value[i]) * beyond[k]))
                        .map(|v| v * v)
                        .sum();
                    sigma[i].map(|s| libm::sqrt(s * s + carried))
                });
                Estimated3 {
                    value,
                    sigma,
                    undetermined_direction: None,
                }
            })
        })
    });
    let [dipole, centre] = values.unwrap_or([None, None]);
    let o = OutsideEstimates {
        gravity_gradient,
        residual_dipole_am2: dipole,
        centre_of_mass_m: centre,
    };
    o.any().then_some(o)
}

/// The batch run's candidates once one is chosen, as the σ and the status of its answer
/// see them ([`finish`]).
struct BatchRun<'a> {
    samples: &'a [Sample],
    /// The rotor parameters' sources, where the run estimates them.
    rotors: &'a BatchInputs,
    config: &'a PipelineConfig,
    /// Every candidate's rows and their reduction.
    reduced: &'a [(MomentumRowSettings, BatchReduction)],
    /// Their fits as the choice saw them: a model the inertial torque's test rejected
    /// has an infinite variance ([`test_inertial_torque`]) and is no alternative, except
    /// for the model spread as the chosen one's twin ([`rejected_inertial_twin`]).
    fits: &'a [(f64, f64, Option<f64>)],
    chosen: usize,
    /// The shortest chain of an alternative ([`alternatives_from_s`]).
    from_s: f64,
    /// The chosen candidate's rows, torque-tested ([`torque_tested`]).
    tested: RecursiveQr,
    /// The same with the damping held at zero, where the rows estimate it: the model
    /// without the drag, an alternative for the model spread.
    without_damping: Option<RecursiveQr>,
    /// The same with the prior's rows.
    augmented: RecursiveQr,
    backend: Box<dyn Backend + Send>,
    /// The answers' time stamp: the last sample's.
    t_s: f64,
    /// The other candidates' answers for the cross-check.
    others: Vec<(InertiaVector, [f64; 6])>,
}

impl BatchRun<'_> {
    /// Candidate `i`'s own answer and noise σ (for the whole record as one chain, at least
    /// its chained siblings' jackknife σ: [`chained_siblings`]).
    fn own(&mut self, i: usize) -> Result<(Estimate, Option<[f64; 6]>), PipelineError> {
        let (reduced, c) = (self.reduced, self.config);
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
        let (tested, test) = torque_tested(
            b.qr,
            b.without_torque,
            b.jackknife_sigma_kg_m2,
            &c.constraints,
        );
        let mut solve = |gyro: Option<f64>| {
            batch::solve_reduced(
                &tested,
                self.t_s,
                &c.constraints,
                &mut *self.backend,
                &c.observability,
                gyro,
            )
            .map_err(wrap)
        };
        let mut e = solve(c.gyro_noise_for(rows.rotation))?;
        // As the recursive estimator: an estimated density that outweighs the excitation
        // leaves the uncompensated answer.
        if c.gyro_noise_estimated
            && e.observability == Observability::NotObservable(Unobservable::NoiseDominated)
        {
            e = solve(None)?;
        }
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
        // As the recursive estimator's: a torque held at zero for moving the answer too
        // little leaves that move in σ.
        let noise =
            noise.map(|s| with_torque_model_shift(s, test.and_then(|t| t.model_shift_kg_m2)));
        Ok((e, noise))
    }
}

impl Evidence for BatchRun<'_> {
    type Error = PipelineError;

    fn config(&self) -> &PipelineConfig {
        self.config
    }

    fn solved(&self) -> &RecursiveQr {
        &self.augmented
    }

    fn data(&self) -> &RecursiveQr {
        &self.tested
    }

    fn model_spread(&self) -> [f64; 6] {
        let others = self
            .reduced
            .iter()
            .enumerate()
            .filter(|&(i, (r, _))| {
                i != self.chosen
                    && in_running(r, self.from_s)
                    && (self.fits[i].0.is_finite()
                        || rejected_inertial_twin(&self.reduced[self.chosen].0, r))
            })
            .map(|(_, (r, b))| (b.qr, self.config.gyro_noise_for(r.rotation)));
        let chosen = self.reduced[self.chosen].0.rotation;
        let gyro = self.config.gyro_noise_for(chosen);
        model_spread(
            (&self.tested, gyro),
            others.chain(self.without_damping.map(|qr| (qr, gyro))),
            &self.config.constraints,
        )
    }

    fn discretisation_bias(&self) -> [f64; 6] {
        // The first candidate on every other sample of each record, as the recursive
        // path's shadow; a double step keeps its first sample's rotor momentum.
        let records = record_ranges(self.samples.len(), &self.rotors.records);
        let halve = |v: &[Sample]| -> Vec<Sample> {
            records
                .iter()
                .flat_map(|r| {
                    v[r.clone()]
                        .chunks_exact(2)
                        .map(|p| double_step(&p[0], &p[1]))
                })
                .collect()
        };
        let half = halve(self.samples);
        let mut starts = Vec::new();
        let mut n = 0;
        for (k, r) in records.iter().enumerate() {
            if k > 0 {
                starts.push(n);
            }
            n += r.len() / 2;
        }
        let half_rotors = BatchInputs {
            momenta: self
                .rotors
                .momenta
                .iter()
                .map(|d| {
                    records
                        .iter()
                        .flat_map(|r| d[r.clone()].chunks_exact(2).map(|p| p[0]))
                        .collect()
                })
                .collect(),
            prior_mean: self.rotors.prior_mean.clone(),
            records: starts,
        };
        match self.reduced.first() {
            Some((first, full)) => match reduce_batch(&half, first, &half_rotors) {
                Ok(h) => discretisation_bias(
                    &full.qr,
                    &h.qr,
                    self.config.gyro_noise_for(first.rotation),
                    &self.config.constraints,
                ),
                Err(_) => [0.0; 6],
            },
            _ => [0.0; 6],
        }
    }

    fn cross_check(&mut self, _: &Estimate) -> Result<&[(InertiaVector, [f64; 6])], PipelineError> {
        let reduced = self.reduced;
        let best_variance = reduced[self.chosen].1.qr.residual_variance();
        self.others.clear();
        for (i, (r, b)) in reduced.iter().enumerate() {
            if i == self.chosen
                || !in_running(r, self.from_s)
                || !self.fits[i].0.is_finite()
                || !(b.qr.residual_variance() <= COMPARABLE_FIT * best_variance)
            {
                continue;
            }
            if let (e, Some(sigma)) = self.own(i)? {
                if let (Observability::Determined { .. }, Some(jb)) = (e.observability, e.j()) {
                    self.others.push((jb, sigma));
                }
            }
        }
        Ok(&self.others)
    }

    fn density_ratio(&self, j: &InertiaVector, g: f64) -> Option<f64> {
        // The gyro rotation's rows are the ones the density describes.
        self.reduced
            .iter()
            .find(|(rows, _)| rows.rotation == RotationSource::Gyro)
            .and_then(|(_, b)| consistency::gyro_density_ratio(&b.qr, j, g))
    }

    fn residuals(&mut self, _: &Estimate) -> Option<&ResidualSegments> {
        None
    }

    fn damping(&self, j: &InertiaVector) -> Option<(f64, Option<f64>)> {
        Some(self.reduced.get(self.chosen)?.1.damping?.at(j))
    }
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
        own_answer(&reduced[i].1.qr, c.twin_gyro_noise(), &c.constraints)
    });
    // Every attitude candidate has a twin where the verdict is `Same` ([`twins::worst`]).
    let same = worst.is_some_and(|z| z <= twins::TWIN_Z);
    if same {
        reduced.retain(|(r, _)| r.rotation != RotationSource::Attitude);
    }
    Some(same)
}
