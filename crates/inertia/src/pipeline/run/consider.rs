//! The final answer's consider terms computed over the samples a run keeps: the held
//! wheel speeds' lag and the known torque's scale (book, "Status and uncertainty").

use super::{Mode, Run};
use crate::estimator::wheel_delay;
use crate::estimator::Estimate;
use crate::pipeline::BatchOutput;
use crate::sample::Sample;

impl Run {
    /// The held speeds' lag term over `samples` (`wheel_delay::held_lag_move` at their
    /// mean lag), where the speeds look held and no time tag was asked for.
    ///
    /// With the damping estimated, the largest, element by element, of that and the
    /// estimator's own moves: its batch solve of the samples and of the speeds read
    /// `lag_s` later, pinned to the row model the first chose ([`Self::pinned_pair`]),
    /// and in a streaming run its pipeline run again over both ([`Self::streamed_pair`]).
    /// The profile's plain rows have no `D`, which takes up part of the lag's signature,
    /// and their move understated the answer's (drawn lab throws with `--damping`, seeds
    /// 5000–5199: 20 of 35 streaming and 40 of 62 batch answers determined beyond 3σ);
    /// a streaming answer's `D` can take up more of it than the batch solve's (seeds
    /// 10000–10199: 6 of 23 streaming answers determined beyond 3σ with the batch
    /// solve's move, 0 of 22 with the pipeline's own).
    pub(super) fn held_lag_term(&self, samples: &[Sample]) -> Option<[f64; 6]> {
        let every = self.held_speeds_period_samples()?;
        let lag_s = crate::telemetry::held_speeds::mean_lag_s(every, self.input_step_s());
        let profile = wheel_delay::held_lag_move(samples, &self.config.outside, lag_s);
        if !self.config.damping {
            return profile;
        }
        let moved = |j: Option<([f64; 6], [f64; 6])>| {
            let (j0, j1) = j?;
            let out: [f64; 6] = core::array::from_fn(|k| (j1[k] - j0[k]).abs());
            out.iter().all(|x| x.is_finite()).then_some(out)
        };
        let own = moved(
            self.pinned_pair(samples, |late| wheel_delay::shift_rho(late, lag_s), true)
                .and_then(|(a, b)| Some((a.estimate.j()?.into(), b.estimate.j()?.into()))),
        );
        let streamed =
            moved(self.streamed_pair(samples, |late| wheel_delay::shift_rho(late, lag_s)));
        [profile, own, streamed]
            .into_iter()
            .flatten()
            .reduce(|a, b| core::array::from_fn(|k| a[k].max(b[k])))
    }

    /// A streaming run's own answer over `samples` as given and as `change` leaves them:
    /// its pipeline run again over each, pinned to the row model of its last answer.
    /// `None` in batch, or where either run gives no J.
    fn streamed_pair(
        &self,
        samples: &[Sample],
        change: impl FnOnce(&mut [Sample]),
    ) -> Option<([f64; 6], [f64; 6])> {
        let Mode::Streaming(p) = &self.mode else {
            return None;
        };
        let d = p.diagnostics();
        let config = self
            .config
            .with_delay_applied()
            .pinned_to(d.row_model, d.torque_test);
        let solve = |s: &[Sample]| -> Option<[f64; 6]> {
            let mut q = crate::pipeline::Pipeline::from_config(config).ok()?;
            for x in s {
                q.push_each(x, |_| {}).ok()?;
            }
            q.flush(|_| {}).ok()?;
            Some(q.last()?.j()?.into())
        };
        let mut changed = samples.to_vec();
        change(&mut changed);
        Some((solve(samples)?, solve(&changed)?))
    }

    /// The run's batch solve of `samples` as given, and again of the samples as `change`
    /// leaves them, pinned to the row model the first chose (as the rotors' consider term
    /// is, `rotor_inertia`), so that the difference measures the answer's sensitivity
    /// rather than a switch of model. With `streaming_model`, a streaming run pins both
    /// to the row model of its own last answer instead: the sensitivity of the model
    /// answered with (a batch solve of a throw may choose another, or none). Without a
    /// time tag or the rotors' calibration. `None` where either solve fails.
    fn pinned_pair(
        &self,
        samples: &[Sample],
        change: impl FnOnce(&mut [Sample]),
        streaming_model: bool,
    ) -> Option<(BatchOutput, BatchOutput)> {
        let mut config = self.config.with_delay_applied();
        config.calibrate_rotors = false;
        let starts = &self.records.starts;
        let own = match &self.mode {
            Mode::Streaming(p) if streaming_model => {
                let d = p.diagnostics();
                Some(config.pinned_to(d.row_model, d.torque_test))
            }
            _ => None,
        };
        let first =
            crate::pipeline::batch_of_records(samples, own.as_ref().unwrap_or(&config), starts)
                .ok()?;
        let pinned = own.unwrap_or_else(|| {
            config.pinned_to(first.diagnostics.row_model, first.diagnostics.torque_test)
        });
        let mut changed = samples.to_vec();
        change(&mut changed);
        let second = crate::pipeline::batch_of_records(&changed, &pinned, starts).ok()?;
        Some((first, second))
    }

    /// The known torque's scale term over `samples`, where its σ `r` is given and the
    /// samples carry a known torque: `|ĵ((1 + r) τ, (1 + r) F) − ĵ(τ, F)|` per element,
    /// the run's batch solve of the samples as given and again with the known torque and
    /// the force scaled, pinned to the row model the first chose (as the rotors' consider
    /// term is, `rotor_inertia`), so that it measures the answer's sensitivity rather
    /// than a switch of model. `None` where either solve gives no J. With it, the same
    /// solves' move of the residual dipole and the centre of mass, where estimated
    /// (`OutsideEstimates::moves_to`; zero where neither solve has them).
    pub(super) fn torque_scale_term(
        &self,
        samples: &[Sample],
    ) -> Option<([f64; 6], [[f64; 3]; 2])> {
        let r = self.config.torque_scale_sigma?;
        if !(r > 0.0) || !samples.iter().any(|s| s.tau_nm.iter().any(|&x| x != 0.0)) {
            return None;
        }
        let (first, second) = self.pinned_pair(
            samples,
            |scaled| {
                for x in scaled {
                    x.tau_nm *= 1.0 + r;
                    x.external.force_n = x.external.force_n.map(|f| f * (1.0 + r));
                }
            },
            false,
        )?;
        let (j0, j1) = (first.estimate.j()?, second.estimate.j()?);
        let out: [f64; 6] = core::array::from_fn(|k| (j1[k] - j0[k]).abs());
        let outside = match (&first.diagnostics.outside, &second.diagnostics.outside) {
            (Some(a), Some(b)) => a.moves_to(b),
            _ => [[0.0; 3]; 2],
        };
        out.iter().all(|x| x.is_finite()).then_some((out, outside))
    }

    /// Where a streaming run could not keep its samples (a memory, or more than it keeps)
    /// but saw a known torque: the term taken as `r |ĵ|` of its last answer, the whole
    /// answer's scale (the known torque's share of it where no wheel moves, more than it
    /// otherwise), never none.
    pub(super) fn torque_scale_fallback(
        &self,
        j: &crate::tensor::InertiaVector,
    ) -> Option<[f64; 6]> {
        let r = self.config.torque_scale_sigma.filter(|&r| r > 0.0)?;
        self.known_torque
            .then(|| core::array::from_fn(|k| (r * j[k]).abs()))
    }

    /// Streaming: the last answer, widened by the final consider terms, given once more.
    pub(super) fn widen_streaming_last(&mut self, on_estimate: &mut impl FnMut(&Estimate)) {
        // Streaming: the last answer, widened by the held speeds' lag term (speeds held, no
        // time tag) and the known torque's scale term over the samples kept (without them,
        // its fallback on the last answer), is given once more.
        let streaming = matches!(self.mode, Mode::Streaming(_));
        let kept = self.kept.take();
        let (lag, scale) = match (&kept, &self.mode) {
            (Some(kept), _) => {
                let scale = self.torque_scale_term(kept);
                self.outside_scale_move = scale.map(|s| s.1);
                (self.held_lag_term(kept), scale.map(|s| s.0))
            }
            (None, Mode::Streaming(p)) => (
                None,
                p.last()
                    .and_then(|e| e.j())
                    .and_then(|j| self.torque_scale_fallback(&j)),
            ),
            _ => (None, None),
        };
        if streaming && (lag.is_some() || scale.is_some()) {
            if let Mode::Streaming(p) = &mut self.mode {
                if let Some(e) = p.widen_last(lag, scale) {
                    if lag.is_some() {
                        self.config.wheel_delay_consider = lag;
                    }
                    self.config.torque_scale_consider = scale;
                    on_estimate(&e);
                }
            }
        }
    }
}
