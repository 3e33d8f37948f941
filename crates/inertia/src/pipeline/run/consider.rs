//! The final answer's consider terms computed over the samples a run keeps: the held
//! wheel speeds' lag and the known torque's scale (book, "Status and uncertainty").

use super::Run;
use crate::estimator::{torque_scale, wheel_delay};
use crate::sample::Sample;

impl Run {
    /// The held speeds' lag term over `samples` (`wheel_delay::held_lag_move` at their
    /// mean lag), where the speeds look held and no time tag was asked for.
    pub(super) fn held_lag_term(&self, samples: &[Sample]) -> Option<[f64; 6]> {
        let every = self.held_speeds_period_samples()?;
        let lag_s = crate::telemetry::held_speeds::mean_lag_s(every, self.input_step_s());
        wheel_delay::held_lag_move(samples, &self.config.outside, lag_s)
    }

    /// The known torque's scale term over `samples`
    /// (`torque_scale::torque_scale_move`), where its σ is given and the samples carry a
    /// known torque.
    pub(super) fn torque_scale_term(&self, samples: &[Sample]) -> Option<[f64; 6]> {
        let r = self.config.torque_scale_sigma?;
        torque_scale::torque_scale_move(samples, &self.config.outside, r)
    }
}
