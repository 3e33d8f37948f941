//! The final answer's consider terms computed over the samples a run keeps: the held
//! wheel speeds' lag and the known torque's scale (book, "Status and uncertainty").

use super::{Mode, Run};
use crate::estimator::wheel_delay;
use crate::estimator::Estimate;
use crate::sample::Sample;
use std::vec::Vec;

impl Run {
    /// The held speeds' lag term over `samples` (`wheel_delay::held_lag_move` at their
    /// mean lag), where the speeds look held and no time tag was asked for.
    pub(super) fn held_lag_term(&self, samples: &[Sample]) -> Option<[f64; 6]> {
        let every = self.held_speeds_period_samples()?;
        let lag_s = crate::telemetry::held_speeds::mean_lag_s(every, self.input_step_s());
        wheel_delay::held_lag_move(samples, &self.config.outside, lag_s)
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
        let mut config = self.config.with_delay_applied();
        config.calibrate_rotors = false;
        let starts = self.records.starts.clone();
        let first = crate::pipeline::batch_of_records(samples, &config, &starts).ok()?;
        let j0 = first.estimate.j()?;
        let pinned = config.pinned_to(first.diagnostics.row_model, first.diagnostics.torque_test);
        let scaled: Vec<Sample> = samples
            .iter()
            .map(|s| {
                let mut x = *s;
                x.tau_nm *= 1.0 + r;
                x.external.force_n = s.external.force_n.map(|f| f * (1.0 + r));
                x
            })
            .collect();
        let second = crate::pipeline::batch_of_records(&scaled, &pinned, &starts).ok()?;
        let j1 = second.estimate.j()?;
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
