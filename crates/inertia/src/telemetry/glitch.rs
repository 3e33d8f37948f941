//! Does one step of the attitude jump against the gyro? A per-step outlier test on
//! telemetry that has both (beyond the paper): a single wild quaternion (a star-tracker
//! misidentification, a bit flip, a filter reset) must not silently rule the answer.
//!
//! Over each step the attitude implies a body rate `ω_q = 2 vec(q_k† q_{k+1})/h`, which
//! must match the gyro's average rate `w_k` over the same step to within the sensors'
//! noise and an O(h²) remainder (as in [`super::convention`]). A step is a glitch when its
//! mismatch `m = |ω_q − w|` is both far outside the recent steps' — `m² >`
//! `GLITCH_RATIO² · E[m²]` (`GLITCH_RATIO` = 20), with `E[m²]` an exponential mean over the recent
//! unflagged steps (`MEMORY_STEPS` = 100) — and large in absolute terms,
//! `m > RELATIVE_FLOOR · |w| + ABSOLUTE_FLOOR_RAD_S` (0.1 and 1e-3 rad/s; so that a gyro-propagated
//! attitude, whose mismatch is round-off, or the O(h²) remainder at 1 Hz never trip it).
//! A 1° jump at 10 Hz is a 0.17 rad/s mismatch; a star tracker's 40″ roll noise about
//! 3e-3 rad/s. Steps across a gap (`crate::sample::is_gap`) are not tested. Fixed size,
//! no allocation.

// The crate-internal helpers here serve the std front ends (pipeline, CSV reader).
#![cfg_attr(not(feature = "std"), allow(dead_code))]

use crate::sample::Sample;

/// Mismatch, in RMS of the recent steps' mismatch, beyond which a step may be a glitch.
pub(crate) const GLITCH_RATIO: f64 = 20.0;
/// Mismatch, as a fraction of the gyro rate, below which a step is never a glitch.
pub(crate) const RELATIVE_FLOOR: f64 = 0.1;
/// Mismatch, rad/s, below which a step is never a glitch (with [`RELATIVE_FLOOR`]).
pub(crate) const ABSOLUTE_FLOOR_RAD_S: f64 = 1e-3;
/// Time constant of the recent steps' mean square mismatch, in steps.
pub(crate) const MEMORY_STEPS: f64 = 100.0;
/// Steps before any verdict (the mean must have something to stand on).
pub(crate) const WARM_UP_STEPS: usize = 20;

/// A step the test flags.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Glitch {
    /// 0-based index of the sample that ends the step.
    pub sample: usize,
    /// Time of the step's first sample, s.
    pub t_s: f64,
    /// The attitude's turn over the step, rad.
    pub attitude_turn_rad: f64,
    /// The gyro's turn over the step, rad.
    pub gyro_turn_rad: f64,
    /// `|ω_q − w|` in RMS of the recent steps'.
    pub ratio: f64,
}

impl core::fmt::Display for Glitch {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "the attitude turns {:.3}° over the step from t = {} s where the gyro turns {:.3}° ({:.1e} times the recent steps' RMS mismatch): a glitch in the quaternions or the rates",
            self.attitude_turn_rad.to_degrees(),
            crate::text::Num(self.t_s),
            self.gyro_turn_rad.to_degrees(),
            self.ratio
        )
    }
}

/// What to do with a step the test flags.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GlitchPolicy {
    /// Stop with an error naming the step (default): fix the file, or ask for
    /// [`GlitchPolicy::Keep`].
    #[default]
    Stop,
    /// Estimate anyway; the steps are counted and listed in the report. (A sample is not
    /// dropped: both of its steps, and the rows over them, would change.)
    Keep,
}

/// Glitches listed in full; beyond, only counted.
pub(crate) const LISTED: usize = 16;

/// The running test ([module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlitchCheck {
    prev: Option<Sample>,
    prev_step_s: f64,
    samples: usize,
    steps: usize,
    mean_square: f64,
    count: usize,
    listed: [Option<Glitch>; LISTED],
}

impl Default for GlitchCheck {
    fn default() -> Self {
        Self {
            prev: None,
            prev_step_s: f64::INFINITY,
            samples: 0,
            steps: 0,
            mean_square: 0.0,
            count: 0,
            listed: [None; LISTED],
        }
    }
}

impl GlitchCheck {
    /// Test the step that ends at `s`; the glitch, when it is one (also counted and,
    /// among the first [`LISTED`], listed).
    pub(crate) fn push(&mut self, s: &Sample) -> Option<Glitch> {
        let index = self.samples;
        self.samples += 1;
        let a = self.prev.replace(*s)?;
        let w = a.omega_rad_s?;
        let h = s.t_s - a.t_s;
        // A gap is no step: no row spans it, and the gyro's rate is not its average.
        let gap = crate::sample::is_gap(self.prev_step_s, h);
        self.prev_step_s = h;
        if gap || !(h > 0.0 && h.is_finite() && w.iter().all(|v| v.is_finite())) {
            return None;
        }
        let turn = a.q.conjugate().mul(&s.q).positive_scalar().v;
        let m = (turn * (2.0 / h) - w).norm();
        if !m.is_finite() {
            return None;
        }
        let glitch = self.steps >= WARM_UP_STEPS
            && m * m > GLITCH_RATIO * GLITCH_RATIO * self.mean_square
            && m > RELATIVE_FLOOR * w.norm() + ABSOLUTE_FLOOR_RAD_S;
        if glitch {
            let g = Glitch {
                sample: index,
                t_s: a.t_s,
                attitude_turn_rad: 2.0 * libm::asin(turn.norm().min(1.0)),
                gyro_turn_rad: w.norm() * h,
                ratio: m / crate::math::sqrt(self.mean_square),
            };
            if let Some(slot) = self.listed.get_mut(self.count) {
                *slot = Some(g);
            }
            self.count += 1;
            return Some(g);
        }
        // The mean follows the unflagged steps only, from a plain mean while warming up.
        let weight = 1.0 / (self.steps as f64 + 1.0).min(MEMORY_STEPS);
        self.mean_square += weight * (m * m - self.mean_square);
        self.steps += 1;
        None
    }

    /// Steps flagged so far.
    #[must_use]
    pub fn count(&self) -> usize {
        self.count
    }

    /// The first [`LISTED`] steps flagged.
    #[cfg_attr(not(feature = "serde"), allow(dead_code))] // used by the report
    pub(crate) fn listed(&self) -> impl Iterator<Item = &Glitch> {
        self.listed.iter().flatten()
    }
}
