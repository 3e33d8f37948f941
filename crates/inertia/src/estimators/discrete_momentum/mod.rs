//! The discrete momentum estimator ([`crate::estimator::discrete_momentum`]: the paper's
//! rows, eqs. 46–54, telescoped into a discrete conservation of angular momentum) in the
//! pipeline, with the row model chosen from the data.
//!
//! The wheel momentum between samples is estimated with `j` by default
//! ([`crate::estimator::momentum_rows::Stencil::Adaptive`]). Where the settings leave a
//! choice open (the rotation source when the telemetry has gyro rates, and the chain
//! length: `--chain`, a quarter and 4× as long, and the whole record as one chain, whose
//! σ comes from its chained siblings' jackknife: [`chained_siblings`]), every candidate
//! row model folds every sample (the candidates that differ only in the chain length from
//! one shared row source), and each solve uses the candidate [`pick`] picks: first by fit
//! ([`select::choose`]: of those whose residual variance `ρ²/(rows − unknowns)` the data
//! cannot tell from the smallest, the one with the longest chains; a noisier rotation
//! source, or chains long enough for an attitude drift to show, leave larger residuals),
//! then by steadiness ([`select::steadier`]: the same rows in longer chains whose
//! jackknife σ is clearly smaller). The σ of the answer is the chosen candidate's noise σ
//! ([`crate::estimator::jackknife`]) and three bias terms: the discretisation bias from a
//! half-rate shadow of the first candidate, the spread of indistinguishable candidates,
//! and the cross-check of the rotation sources ([`cross_check::reconcile`]). A candidate
//! that has fitted markedly worse than the best for long is ruled out and no longer
//! folded ([`standing`]).
//!
//! One job per file:
//!
//! * here: the registry entry [`DISCRETE_MOMENTUM`], the estimator's state and its push,
//!   sample by sample: fold ([`DiscreteMomentum::fold`]), count the row block, pick,
//!   solve;
//! * [`candidates`](mod@candidates): the candidate row models, their settings and shared row sources;
//! * [`select`]: which candidate answers;
//! * [`sigma`]: the parts of σ;
//! * [`cross_check`]: the candidates' answers against each other;
//! * [`finish`](mod@finish): σ and status of an answer, one sequence for the recursive path and
//!   [`batch`] (the whole record at once);
//! * [`replay`]: the attitude drift weighting's refold and its unweighted twin;
//! * [`standing`] and [`twins`]: which candidates stop being folded;
//! * `tests`: the unit tests.

mod batch;
mod candidates;
mod cross_check;
mod finish;
mod replay;
mod select;
mod sigma;
mod standing;
#[cfg(test)]
mod tests;
pub(crate) mod twins;

use crate::estimator::attitude_drift::AttitudeDrift;
use crate::estimator::consistency::{self, ResidualSegments};
use crate::estimator::discrete_momentum::{DiscreteMomentumEstimator, MomentumEstimatorSettings};
use crate::estimator::excitation::diagnose;
use crate::estimator::external_torque::OutsideEstimates;
use crate::estimator::momentum_rows::{MomentumRowSettings, RotationSource};
use crate::estimator::qr::RecursiveQr;
use crate::estimator::rate_noise::RateNoise;
use crate::estimator::{Estimate, EstimatorError};
use crate::pipeline::config::EstimatorEntry;
use crate::pipeline::config::{InertialTorque, PipelineConfig, SHORT_RECORD_S};
use crate::pipeline::diagnostics::Diagnostics;
use crate::pipeline::error::PipelineError;
use crate::pipeline::interface::{Capabilities, Estimator};
use crate::sample::Sample;
use crate::tensor::InertiaVector;
use candidates::{candidates, chained_siblings, settings, shared_sources, Candidate, SharedSource};
use cross_check::CrossCheck;
use finish::{finish, Evidence, Finished};
use select::in_running;
use sigma::{
    candidate_noise_sigma, discretisation_bias, double_step, model_spread, outside_spread,
    own_answer,
};
use standing::{Standing, RULE_OUT_AFTER};
use std::boxed::Box;
use std::vec::Vec;
use twins::Twins;

/// The relative change of the estimated gyro density below which the streaming
/// estimator keeps the one it has (`DiscreteMomentum::refresh_gyro_noise`).
const DENSITY_REFRESH: f64 = 0.01;

/// Registry entry.
pub(crate) const DISCRETE_MOMENTUM: EstimatorEntry = EstimatorEntry {
    name: "discrete-momentum",
    summary: "discrete conservation of angular momentum (telescoped paper rows), unknown constant torque, Richardson O(h^4) rows, constrained (default)",
    capabilities: Capabilities {
        needs_gyro: false,
        constraints: true,
        compensation: true,
        uncertainty: true,
        row_model: true,
        filter: false,
    },
    build,
    batch: Some(batch::run_batch),
};

struct DiscreteMomentum {
    config: PipelineConfig,
    candidates: Vec<Candidate>,
    /// The row sources: candidates that differ only in the longest chain share one
    /// ([`DiscreteMomentumEstimator::fold_shared`]), so each row is formed once.
    sources: Vec<SharedSource>,
    /// The candidates' row settings.
    rows: Vec<MomentumRowSettings>,
    /// The candidates' fits at the last solve ([`select::choose`]), kept so that a push does not
    /// allocate.
    fits: Vec<(f64, f64, Option<f64>)>,
    /// The shortest chain of an alternative at the last solve ([`alternatives_from_s`]).
    from_s: f64,
    /// Which candidates the data have not ruled out.
    standing: Standing,
    /// Row blocks beyond the limit that rule a candidate out ([`standing`]).
    rule_out_after: usize,
    /// Whether the attitude is the gyro's integral ([`twins`]).
    twins: Twins,
    chosen: usize,
    since_solve: usize,
    /// The time of the last completed row block ([`Estimator::flush`]).
    last_block_t_s: Option<f64>,
    /// Per candidate: its last own estimate and noise σ, and the row blocks since.
    checks: Vec<Option<CrossCheck>>,
    /// The first candidate's rows on every other sample, for the discretisation bias.
    shadow: Option<Box<Candidate>>,
    /// Per candidate, its residual record (none under forgetting).
    residuals: Vec<ResidualSegments>,
    /// The residuals' ratio to the stated gyro density at the last solve.
    density_ratio: Option<f64>,
    /// Where no gyro density is stated: its estimate from the rates
    /// ([`crate::estimator::rate_noise`]), which sets the compensation's density
    /// (`config.gyro_noise_rad_s_rthz`) at each solve.
    rate_noise: Option<Box<RateNoise>>,
    /// The damping at the last answer with its widened σ ([`finish`]).
    damping: Option<(f64, Option<f64>)>,
    /// The outside torques at the last answer, with its σ carried.
    outside: Option<OutsideEstimates>,
    /// Input samples so far.
    samples: usize,
    /// Samples that completed a row block (the cross-check's clock).
    blocks: usize,
    /// The first sample's time, s, while the record may still be short
    /// ([`InertialTorque::Short`]); `None` once it is not (or before the first sample).
    first_t_s: Option<f64>,
    /// The even sample waiting for its successor (the shadow's next sample).
    held: Option<Sample>,
    /// The other candidates' answers for [`cross_check::reconcile`], kept between solves so that a
    /// push does not allocate.
    others: Vec<(InertiaVector, [f64; 6])>,
    /// The attitude drift the candidates' rows are weighted for
    /// ([`crate::estimator::attitude_drift`]), from the latest answer.
    drift: Option<AttitudeDrift>,
    /// With a drift to weight for and no answer yet: the samples so far, refolded with
    /// the weights once the first answer gives `Ĵ` ([`DiscreteMomentum::replayed`]);
    /// `None` otherwise, and past [`replay::REPLAY_CAP`] samples.
    replay: Option<Vec<Sample>>,
    /// Once the rows are weighted for a drift: the same run unweighted, kept beside it
    /// (weighting a drift that the rows' discretisation bias outweighs costs accuracy),
    /// and whether its answer was the one given at the last solve
    /// ([`replay::unweighted_is_better`]).
    unweighted: Option<(Box<DiscreteMomentum>, bool)>,
}

fn build(c: &PipelineConfig) -> Result<Box<dyn Estimator>, PipelineError> {
    Ok(Box::new(DiscreteMomentum::new(c)?))
}

impl DiscreteMomentum {
    fn new(c: &PipelineConfig) -> Result<Self, PipelineError> {
        // Validate the estimator settings now; candidates are built at the first sample.
        MomentumEstimatorSettings::validate(&settings(c, MomentumRowSettings::default())).map_err(
            |source| PipelineError::Estimator {
                sample: None,
                source,
            },
        )?;
        Ok(Self::empty(c))
    }

    /// The estimator before its first sample, for validated settings.
    fn empty(c: &PipelineConfig) -> Self {
        DiscreteMomentum {
            config: *c,
            candidates: Vec::new(),
            sources: Vec::new(),
            rows: Vec::new(),
            fits: Vec::new(),
            from_s: 0.0,
            standing: Standing::default(),
            rule_out_after: RULE_OUT_AFTER,
            twins: Twins::default(),
            chosen: 0,
            since_solve: 0,
            last_block_t_s: None,
            checks: Vec::new(),
            shadow: None,
            residuals: Vec::new(),
            density_ratio: None,
            // (Not on resampled rates, whose interpolation damps the noise.)
            rate_noise: (c.gyro_noise_rad_s_rthz.is_none() && c.resample_s.is_none())
                .then(Box::default),
            damping: None,
            outside: None,
            samples: 0,
            blocks: 0,
            first_t_s: None,
            held: None,
            others: Vec::new(),
            drift: None,
            replay: c.attitude_drift_deg_rth.map(|_| Vec::new()),
            unweighted: None,
        }
    }

    fn start(&mut self, first: &Sample) -> Result<(), EstimatorError> {
        for rows in candidates(&self.config, first.omega_rad_s.is_some()) {
            let backend = self.config.backend.build();
            self.candidates.push(DiscreteMomentumEstimator::new(
                settings(&self.config, rows),
                self.config.constraints,
                backend,
            )?);
        }
        // A whole-record candidate's σ comes from its chained siblings' jackknife: its own
        // chain groups would hold one chain.
        let rows: Vec<MomentumRowSettings> =
            self.candidates.iter().map(|c| *c.row_settings()).collect();
        self.sources = shared_sources(&rows);
        self.fits.reserve(rows.len());
        for (c, r) in self.candidates.iter_mut().zip(&rows) {
            if chained_siblings(r, rows.iter(), 0.0).next().is_some() {
                c.jackknife_for_torque_only();
            }
        }
        self.rows = rows;
        if self.config.uncertainty {
            if let Some(first) = self.candidates.first() {
                let mut shadow = DiscreteMomentumEstimator::new(
                    settings(&self.config, *first.row_settings()),
                    self.config.constraints,
                    self.config.backend.build(),
                )?;
                // Only its least-squares state is used ([`discretisation_bias`]).
                shadow.stop_jackknife();
                self.shadow = Some(Box::new(shadow));
            }
        }
        self.standing = Standing::new(self.candidates.len(), self.rule_out_after);
        self.set_drift(self.drift);
        Ok(())
    }

    /// One sample through every candidate, and the chosen answer when a solve is due.
    fn push_sample(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        if self.candidates.is_empty() {
            self.start(s)?;
            self.first_t_s = Some(s.t_s);
        }
        self.end_short_record(s.t_s);
        if let Some(r) = self.rate_noise.as_deref_mut() {
            r.push(s.t_s, s.omega_rad_s);
        }
        let folded = self.fold(s)?;
        self.feed_shadow(s);
        self.samples += 1;
        if !folded {
            return Ok(None);
        }
        self.last_block_t_s = Some(s.t_s);
        if !self.count_block() {
            return Ok(None);
        }
        self.pick_candidate();
        self.solve(s.t_s)
    }

    /// The answer at the last completed row block, where blocks came after the last
    /// solve ([`Estimator::flush`]).
    fn flush_own(&mut self) -> Result<Option<Estimate>, EstimatorError> {
        match self.last_block_t_s {
            Some(t_s) if self.since_solve > 0 => {
                self.pick_candidate();
                self.solve(t_s)
            }
            _ => Ok(None),
        }
    }

    /// Past [`SHORT_RECORD_S`] from the first sample, a record is no longer short: the
    /// candidates with a torque fixed in the inertial frame that
    /// [`InertialTorque::Short`] added are ruled out ([`standing`]), and the run goes on
    /// as with the torque off.
    fn end_short_record(&mut self, t_s: f64) {
        let Some(t0) = self.first_t_s else { return };
        if self.config.inertial_torque != InertialTorque::Short || t_s - t0 <= SHORT_RECORD_S {
            return;
        }
        self.first_t_s = None;
        for (i, c) in self.candidates.iter().enumerate() {
            if c.row_settings().inertial_torque {
                self.standing.rule_out(i);
            }
        }
    }

    /// Sample `s` through the row sources still wanted (a source whose candidates are all
    /// ruled out is no longer fed; the first candidate always is, for the discretisation
    /// bias), each new row folded into their candidates and, without forgetting, into
    /// their residual records. Whether a row block was completed.
    fn fold(&mut self, s: &Sample) -> Result<bool, EstimatorError> {
        let mut folded = false;
        let record = self.config.memory_s.is_none();
        self.residuals
            .resize_with(self.candidates.len(), ResidualSegments::new);
        for src in &mut self.sources {
            let standing = &self.standing;
            let wanted = |i: &usize| *i == 0 || standing.live(*i);
            if !src.members.iter().any(wanted) {
                continue;
            }
            let row = src.rows.push(s).map_err(|source| EstimatorError::Row {
                sample: self.samples,
                source,
            })?;
            let Some(row) = row else {
                continue;
            };
            folded = true;
            // In pairs, their folds interleaved (`fold_shared_pair`), the odd one alone.
            let mut waiting: Option<usize> = None;
            for &i in src.members.iter().filter(|i| wanted(i)) {
                match waiting.take() {
                    None => waiting = Some(i),
                    Some(h) => {
                        // Members are in increasing order ([`shared_sources`]).
                        let (low, high) = self.candidates.split_at_mut(i);
                        match (low.get_mut(h), high.first_mut()) {
                            (Some(a), Some(b)) => {
                                Candidate::fold_shared_pair(a, b, &row, &src.rows, s.t_s);
                            }
                            _ => unreachable!("members of a source in increasing order"),
                        }
                    }
                }
            }
            if let Some(h) = waiting {
                if let Some(c) = self.candidates.get_mut(h) {
                    c.fold_shared(&row, &src.rows, s.t_s);
                }
            }
            if record {
                for &i in src.members.iter().filter(|i| wanted(i)) {
                    let c = &self.candidates[i];
                    self.residuals[i].record(c.qr().rss(), c.qr().residual_dof(), s.t_s);
                }
            }
        }
        Ok(folded)
    }

    /// Sample `s` to the first candidate's half-rate shadow ([`sigma::discretisation_bias`]).
    fn feed_shadow(&mut self, s: &Sample) {
        if let Some(shadow) = self.shadow.as_mut() {
            // Every other sample, its gyro rate averaged over the double step: fed one
            // sample late, when the second rate is known.
            if self.samples.is_multiple_of(2) {
                self.held = Some(*s);
            } else if let Some(a) = self.held.take() {
                // The shadow's double step can turn too far for a row where the data's
                // single steps do not: it is dropped, and with it the bias term, rather
                // than stopping the run.
                if shadow.fold(&double_step(&a, s)).is_err() {
                    self.shadow = None;
                }
            }
        }
    }

    /// Count a completed row block: rule candidates out ([`standing`], [`twins`]), age the
    /// cross-check's answers. Whether a solve is due (`solve_every`).
    fn count_block(&mut self) -> bool {
        self.refresh_gyro_noise();
        self.rule_out();
        self.blocks += 1;
        if self.twins.due(self.blocks) {
            self.check_twins();
        }
        for k in self.checks.iter_mut().flatten() {
            k.age += 1;
        }
        self.since_solve += 1;
        self.since_solve >= self.config.solve_every
    }

    /// Solve the chosen candidate at `t_s`, once it has rows for all six unknowns, and give
    /// the answer its σ and status ([`finish()`]).
    fn solve(&mut self, t_s: f64) -> Result<Option<Estimate>, EstimatorError> {
        let record = self.config.memory_s.is_none();
        let Some(c) = self.candidates.get_mut(self.chosen) else {
            return Ok(None);
        };
        if c.qr().rows() < 6 {
            return Ok(None);
        }
        self.since_solve = 0;
        let mut e = c.solve_now(t_s)?;
        let noise =
            candidate_noise_sigma(&mut self.candidates, self.chosen, self.config.max_chain_s);
        let mut evidence = Streaming {
            run: self,
            t_s,
            record,
        };
        if let Finished::Checked {
            density_ratio,
            damping,
        } = finish(&mut e, noise, &mut evidence)?
        {
            self.density_ratio = density_ratio;
            self.damping = damping;
        }
        self.outside = self.candidates[self.chosen]
            .outside_at(&e)
            .map(|o| self.widened_by_model_spread(o));
        Ok(Some(e))
    }

    /// Whether candidate `i` is an alternative to the chosen one for the model spread:
    /// standing, in the running, and not rejected by the inertial torque's test unless
    /// as the chosen one's twin ([`select::rejected_inertial_twin`]).
    fn spread_alternative(&self, i: usize, c: &Candidate) -> bool {
        i != self.chosen
            && self.standing.live(i)
            && in_running(c.row_settings(), self.from_s)
            && (self.fits.get(i).is_some_and(|f| f.0.is_finite())
                || select::rejected_inertial_twin(
                    self.candidates[self.chosen].row_settings(),
                    c.row_settings(),
                ))
    }

    /// The outside torques' σ with their model spread in quadrature ([`outside_spread`]),
    /// over the candidates [`Evidence::model_spread`] takes for `j`.
    fn widened_by_model_spread(&self, o: OutsideEstimates) -> OutsideEstimates {
        let others = self
            .candidates
            .iter()
            .enumerate()
            .filter(|&(i, c)| self.spread_alternative(i, c))
            .map(|(_, c)| c);
        let (config, constraints) = (&self.config, &self.config.constraints);
        let mut spread = outside_spread(
            &self.candidates[self.chosen],
            others,
            (config, constraints),
            true,
        );
        // The discretisation bias, as j's: the first candidate's against its half-rate
        // shadow, |x(h) − x(2h)|/3.
        if let (Some(first), Some(shadow)) = (self.candidates.first(), self.shadow.as_deref()) {
            let half = outside_spread(
                first,
                core::iter::once(shadow),
                (config, constraints),
                false,
            );
            for (s, h) in spread.iter_mut().zip(half) {
                for (s, h) in s.iter_mut().zip(h) {
                    *s = libm::sqrt(*s * *s + h * h / 9.0);
                }
            }
        }
        o.widened(&spread)
    }

    /// Rule out the candidates the data have ruled out ([`standing`]). The first
    /// keeps folding without its jackknife: the discretisation bias compares it with the
    /// shadow whichever candidate is chosen.
    fn rule_out(&mut self) {
        self.standing.update(
            self.candidates
                .iter()
                .map(|c| (c.qr().residual_variance(), c.qr().residual_dof())),
        );
        for (i, c) in self.candidates.iter_mut().enumerate() {
            if !self.standing.live(i) {
                c.stop_jackknife();
            }
        }
    }

    /// Compare the candidates that differ only in the rotation source ([`twins`]);
    /// once they are found to be one measurement, rule out the attitude's.
    fn check_twins(&mut self) {
        let (gyro, constraints) = (self.config.twin_gyro_noise(), &self.config.constraints);
        let answer = |c: &Candidate| own_answer(&c.qr().reduced(), gyro, constraints);
        let standing = &self.standing;
        let pairs = twins::pairs(&self.rows, |i| i == 0 || standing.live(i));
        if pairs.clone().next().is_none() {
            self.twins = Twins::NoPairs;
            return;
        }
        let candidates = &self.candidates;
        let worst = twins::worst(pairs.clone(), |i| answer(&candidates[i]));
        // The chosen candidate's twin, should the chosen one be ruled out.
        let chosen_twin = pairs
            .filter(|&(_, a)| a == self.chosen)
            .find_map(|(g, _)| g);
        self.twins = self.twins.after(worst, self.blocks, self.rule_out_after);
        if self.twins == Twins::Same {
            // Every attitude candidate still folded was compared with its twin (one
            // without keeps the verdict from `Same`): all of them go.
            let attitude = self.candidates.iter_mut().zip(&self.rows).enumerate();
            for (a, (c, _)) in attitude.filter(|(_, (_, r))| r.rotation == RotationSource::Attitude)
            {
                self.standing.rule_out(a);
                c.stop_jackknife();
            }
            // Until the next solve picks again (`solve_every` > 1), the report describes
            // the twin's rows, whose answer is the same within the test's margin.
            if let Some(g) = chosen_twin {
                self.chosen = g;
            }
        }
    }
}

impl Estimator for DiscreteMomentum {
    fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        self.keep_for_replay(s);
        let e = self.push_sample(s)?;
        let twin = match self.unweighted.as_mut() {
            Some((t, _)) => t.push_sample(s)?,
            None => None,
        };
        Ok(self.weigh_for_drift(e, twin))
    }

    fn flush(&mut self) -> Result<Option<Estimate>, EstimatorError> {
        let e = self.flush_own()?;
        let twin = match self.unweighted.as_mut() {
            Some((t, _)) => t.flush_own()?,
            None => None,
        };
        Ok(self.weigh_for_drift(e, twin))
    }

    fn diagnostics(&self) -> Diagnostics {
        let g = self.given();
        let chosen = g.candidates.get(g.chosen);
        Diagnostics {
            gaps: self.sources.first().map_or(0, |g| g.rows.gaps()),
            excitation: chosen
                .filter(|c| c.reduced().rows > 0)
                .map(|c| diagnose(c.reduced(), &g.config.observability)),
            row_model: chosen.map(|c| *c.row_settings()),
            torque_bias_nm: chosen.and_then(|c| c.torque_bias_nm()),
            damping_nms: g.damping,
            outside: g
                .outside
                .map(|o| OutsideEstimates {
                    // The rows' sources, which the candidates may share, saw the positions.
                    gravity_gradient: self.sources.iter().any(|s| s.rows.gravity_gradient()),
                    ..o
                })
                .filter(OutsideEstimates::any),
            torque_test: chosen.and_then(|c| c.torque_test()),
            residual_consistency: g.residuals.get(g.chosen).and_then(|r| r.worst()),
            gyro_density_ratio: g.density_ratio,
            gyro_noise_estimated_rad_s_rthz: g
                .rate_noise
                .as_ref()
                .and(g.config.gyro_noise_rad_s_rthz),
            drift_weighted: self
                .config
                .attitude_drift_deg_rth
                .map(|_| matches!(self.unweighted, Some((_, false)))),
            attitude_is_gyro_integral: match g.twins {
                Twins::Undecided | Twins::NoPairs => None,
                Twins::Same => Some(true),
                Twins::Independent => Some(false),
            },
            rotor_calibration: None,
        }
    }
}

/// The streaming run at a solve, as the σ and the status of its answer see it
/// ([`finish()`]).
struct Streaming<'a> {
    run: &'a mut DiscreteMomentum,
    /// The solve's time stamp (the cross-check's own solves).
    t_s: f64,
    /// Whether the residuals are recorded (no forgetting).
    record: bool,
}

impl Streaming<'_> {
    fn chosen(&self) -> &Candidate {
        &self.run.candidates[self.run.chosen]
    }
}

impl Evidence for Streaming<'_> {
    type Error = EstimatorError;

    fn config(&self) -> &PipelineConfig {
        &self.run.config
    }

    fn solved(&self) -> &RecursiveQr {
        self.chosen().solved()
    }

    fn data(&self) -> &RecursiveQr {
        self.chosen().reduced()
    }

    fn model_spread(&self) -> [f64; 6] {
        let run = &*self.run;
        let others = run
            .candidates
            .iter()
            .enumerate()
            .filter(|&(i, c)| run.spread_alternative(i, c))
            .map(|(_, c)| {
                let gyro = run.config.gyro_noise_for(c.row_settings().rotation);
                (c.qr().reduced(), gyro)
            });
        let chosen = run.candidates[run.chosen].row_settings().rotation;
        let gyro = run.config.gyro_noise_for(chosen);
        // The model without the drag, where the rows estimate it.
        let without_damping = self.chosen().reduced_without_damping();
        model_spread(
            (self.chosen().reduced(), gyro),
            others.chain(without_damping.map(|qr| (qr, gyro))),
            &run.config.constraints,
        )
    }

    fn discretisation_bias(&self) -> [f64; 6] {
        let run = &*self.run;
        match (run.candidates.first(), run.shadow.as_deref()) {
            (Some(first), Some(shadow)) => discretisation_bias(
                &first.qr().reduced(),
                &shadow.qr().reduced(),
                run.config.gyro_noise_for(first.row_settings().rotation),
                &run.config.constraints,
            ),
            _ => [0.0; 6],
        }
    }

    fn cross_check(
        &mut self,
        e: &Estimate,
    ) -> Result<&[(InertiaVector, [f64; 6])], EstimatorError> {
        self.run.cross_check(e, self.t_s)
    }

    fn density_ratio(&self, j: &InertiaVector, g: f64) -> Option<f64> {
        // The density describes the gyro: its rows are the ones to compare with it (with
        // an attitude better than the gyro, the attitude's rows are quieter).
        // Under forgetting the counts are discounted and the test is not made.
        let run = &*self.run;
        let described = run
            .candidates
            .iter()
            .enumerate()
            .find(|&(i, c)| {
                (i == 0 || run.standing.live(i))
                    && c.row_settings().rotation == RotationSource::Gyro
            })
            .map(|(_, c)| c);
        match described {
            Some(d) if self.record => consistency::gyro_density_ratio(&d.qr().reduced(), j, g),
            _ => None,
        }
    }

    fn damping(&self, j: &InertiaVector) -> Option<(f64, Option<f64>)> {
        self.chosen().damping_at(j)
    }

    fn residuals(&mut self, e: &Estimate) -> Option<&ResidualSegments> {
        // The answer as the data gave it, withdrawn or not, is the reference of the spans
        // that start after it.
        if let (Some(j), Some(sigma)) = (e.j(), e.sigma_kg_m2()) {
            for r in &mut self.run.residuals {
                r.note(&j, &sigma);
            }
        }
        self.run
            .residuals
            .get(self.run.chosen)
            .filter(|_| self.record)
    }
}
