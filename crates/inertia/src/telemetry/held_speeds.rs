//! Wheel speeds held between telemetry updates: a speed telemetered at a lower rate than
//! the attitude and repeated until the next update is late by up to one update period,
//! by about half of it on average, and the momentum rows then credit each change of
//! wheel momentum to a later attitude (3 % of J on the simulated lab throw, speeds held
//! at 100 Hz on a 4 kHz record). The run says so and names the setting that corrects it
//! ([`crate::estimator::wheel_delay`]).
//!
//! The test: the rotor momentum `ρ` changes (as a vector, exactly) at most every other
//! sample, and the numbers of samples between its changes are one period `P ≥ 2` (or
//! `P ± 1`, for an update rate that is not a whole fraction of the sample rate) in at
//! least `REGULAR` of at least `MIN_CHANGES` changes. Speeds quantised but sampled
//! at every sample change at irregular intervals, and constant speeds do not change at
//! all: neither passes.

use nalgebra::Vector3;

/// Longest update period counted, in samples.
#[cfg_attr(not(feature = "std"), allow(dead_code))]
pub(crate) const MAX_PERIOD: usize = 256;
/// Fewest changes of `ρ` for a verdict.
#[cfg_attr(not(feature = "std"), allow(dead_code))]
pub(crate) const MIN_CHANGES: u32 = 10;
/// Fraction of the intervals between changes that must be one period (±1 sample).
#[cfg_attr(not(feature = "std"), allow(dead_code))]
pub(crate) const REGULAR: f64 = 0.8;

/// Counts of the intervals between changes of `ρ`, in samples ([module docs](self)).
#[derive(Debug, Clone)]
pub(crate) struct HeldSpeeds {
    last: Option<Vector3<f64>>,
    since: usize,
    changes: u32,
    /// `intervals[n]`: changes `n` samples after the previous change (`n ≤ MAX_PERIOD`;
    /// longer ones in the last slot).
    intervals: [u32; MAX_PERIOD + 1],
}

impl Default for HeldSpeeds {
    fn default() -> Self {
        Self {
            last: None,
            since: 0,
            changes: 0,
            intervals: [0; MAX_PERIOD + 1],
        }
    }
}

#[cfg_attr(not(feature = "std"), allow(dead_code))]
impl HeldSpeeds {
    /// Count the next sample's `ρ`.
    pub(crate) fn push(&mut self, rho_nms: &Vector3<f64>) {
        self.since += 1;
        match self.last {
            Some(l) if l == *rho_nms => {}
            Some(_) => {
                if self.changes > 0 {
                    self.intervals[self.since.min(MAX_PERIOD)] += 1;
                }
                self.changes += 1;
                self.since = 0;
                self.last = Some(*rho_nms);
            }
            None => {
                self.since = 0;
                self.last = Some(*rho_nms);
            }
        }
    }

    /// The update period in samples when the speeds are held ([module docs](self)),
    /// else `None`.
    #[must_use]
    pub(crate) fn period_samples(&self) -> Option<usize> {
        if self.changes < MIN_CHANGES {
            return None;
        }
        let total: u32 = self.intervals.iter().sum();
        let (p, _) = self
            .intervals
            .iter()
            .enumerate()
            .take(MAX_PERIOD)
            .max_by_key(|&(_, &c)| c)?;
        let near: u32 = self.intervals[p.saturating_sub(1)..=(p + 1).min(MAX_PERIOD - 1)]
            .iter()
            .sum();
        (p >= 2 && f64::from(near) >= REGULAR * f64::from(total)).then_some(p)
    }
}

/// The mean lag, s, of speeds held for `every` samples of `step_s` each and read at the
/// samples' time stamps: `(every − 1)/2` steps (the value updated at one sample is read
/// 0, 1, …, `every − 1` steps late).
#[cfg_attr(not(feature = "std"), allow(dead_code))]
pub(crate) fn mean_lag_s(every: usize, step_s: f64) -> f64 {
    0.5 * step_s * every.saturating_sub(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn count(rho: impl Iterator<Item = f64>) -> Option<usize> {
        let mut h = HeldSpeeds::default();
        for x in rho {
            h.push(&Vector3::new(x, 0.5 * x, 0.0));
        }
        h.period_samples()
    }

    #[test]
    fn a_staircase_is_held_and_a_ramp_or_a_constant_is_not() {
        // Updated every 40 samples: 40 (a ramp held in steps).
        assert_eq!(count((0..4000).map(|k| (k / 40) as f64)), Some(40));
        // Every 2.5 samples on average (100 Hz held on a 250 Hz record): 2 or 3.
        let p = count((0..4000).map(|k| ((k as f64) / 2.5).floor()));
        assert!(matches!(p, Some(2 | 3)), "{p:?}");
        // A new value at every sample, a constant, too few changes.
        assert_eq!(count((0..4000).map(|k| k as f64)), None);
        assert_eq!(count((0..4000).map(|_| 1.0)), None);
        assert_eq!(count((0..300).map(|k| (k / 40) as f64)), None);
    }

    #[test]
    fn quantised_speeds_changing_at_irregular_times_are_not_held() {
        // A slowly varying speed rounded to a step: changes at irregular intervals.
        let q = (0..6000).map(|k| {
            let t = k as f64 * 0.1;
            (50.0 * (t / 40.0).sin() + 3.0 * (t / 7.0).sin()).round()
        });
        assert_eq!(count(q), None);
    }
}
