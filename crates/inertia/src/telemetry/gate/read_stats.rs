//! What a reader counted: samples, renormalised quaternions, sign flips, the shortest and
//! longest step ([`super::Gate`]).

use crate::attitude::Quaternion;

/// Counts of what was read.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReadStats {
    /// Samples accepted.
    pub rows: usize,
    /// Quaternions renormalised (within the tolerance).
    pub renormalised: usize,
    /// Quaternions whose sign was opposite to the previous one's (same attitude).
    pub sign_flips: usize,
    /// Samples rejected (a reader stops at the first; this is 0 or 1).
    pub rejected: usize,
    /// Shortest step, s (0 before two samples).
    pub min_step_s: f64,
    /// Longest step, s.
    pub max_step_s: f64,
    /// Whether the attitude was integrated from the gyro rates (no quaternions given,
    /// [`super::GateOptions::attitude_from_gyro`]).
    pub attitude_from_gyro: bool,
}

impl ReadStats {
    /// The counts of two inputs read one after the other (several records).
    #[must_use]
    pub fn merged(&self, other: &ReadStats) -> ReadStats {
        let steps = |s: &ReadStats| s.rows > 1;
        ReadStats {
            rows: self.rows + other.rows,
            renormalised: self.renormalised + other.renormalised,
            sign_flips: self.sign_flips + other.sign_flips,
            rejected: self.rejected + other.rejected,
            min_step_s: match (steps(self), steps(other)) {
                (true, true) => self.min_step_s.min(other.min_step_s),
                (false, true) => other.min_step_s,
                _ => self.min_step_s,
            },
            max_step_s: self.max_step_s.max(other.max_step_s),
            attitude_from_gyro: self.attitude_from_gyro || other.attitude_from_gyro,
        }
    }

    /// Count the step of `dt` s into the next sample, whose quaternion `q` follows `prev`
    /// (before that sample is counted in `rows`): the shortest and longest step, and a sign
    /// opposite to the previous quaternion's.
    pub(crate) fn step(&mut self, dt: f64, prev: &Quaternion, q: &Quaternion) {
        self.min_step_s = if self.rows > 1 {
            self.min_step_s.min(dt)
        } else {
            dt
        };
        self.max_step_s = self.max_step_s.max(dt);
        if prev.v.dot(&q.v) + prev.s * q.s < 0.0 {
            self.sign_flips += 1;
        }
    }
}
