//! Does the attitude agree with the gyro? A check of the quaternion convention
//! (docs/conventions.md §3) on telemetry that has both.
//!
//! Over each step the attitude implies a body rate `ω_q = 2 vec(q_k† q_{k+1})/h` (to
//! O(h²)), which must match the gyro's average rate `w_k` over the same step. Read with the
//! wrong convention, it does not: a conjugated quaternion (JPL / inertial → body) gives
//! `ω_q ≈ −C ω` in the wrong frame; scalar-first columns read as scalar-last scramble the
//! components. The check (`ConventionCheck`, run by the pipeline's `AttitudeChecks`)
//! gathers steps in which the body turns clearly faster than the gyro noise, and its
//! [`Verdict`] compares the median relative mismatch
//! `|ω_q − w|/|w|` as read against each alternative reading; the one that fits names the
//! option that fixes the file. Fixed size, no allocation.

// The crate-internal helpers here serve the std front ends (pipeline, CSV reader).
#![cfg_attr(not(feature = "std"), allow(dead_code))]

use crate::attitude::Quaternion;
use crate::fix::Fix;
use crate::sample::Sample;
use nalgebra::Vector3;

/// Steps needed before a verdict.
pub(crate) const STEPS_NEEDED: usize = 64;
/// Smallest gyro rate counted, rad/s (a step slower than this says little about frames).
pub(crate) const MIN_RATE_RAD_S: f64 = 2e-3;
/// Smallest `|cos|` of the angle between the gyro's rate and the attitude's for a step to
/// count in the gyro-unit check (a random direction passes with probability 5 %).
pub(crate) const SCALE_MIN_COS: f64 = 0.9;
/// A reading fits when its median relative mismatch is below this.
pub(crate) const FIT: f64 = 0.25;

/// Readings of the quaternion columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reading {
    /// As given.
    AsRead,
    /// Conjugated: inertial → body (JPL / Shuster), [`Fix::Jpl`].
    Conjugated,
    /// The columns are scalar first ([`Fix::ScalarFirst`]).
    ScalarFirst,
    /// Both ([`Fix::ScalarFirst`], [`Fix::Jpl`]).
    ScalarFirstConjugated,
    /// The columns are scalar last but were read as scalar first (a scalar-first reading
    /// asked for a scalar-last file: [`Fix::ScalarLast`]).
    ScalarLast,
    /// The same, conjugated ([`Fix::ScalarLast`], [`Fix::Jpl`]).
    ScalarLastConjugated,
    /// The gyro rates have the opposite sign.
    GyroNegated,
    /// The gyro rates are 180/π times the attitude's: deg/s read as rad/s
    /// ([`Fix::GyroDegrees`]).
    GyroDegrees,
    /// The gyro rates are π/180 times the attitude's: rad/s read as deg/s
    /// ([`Fix::GyroRadians`]).
    GyroRadians,
}

impl Reading {
    const ALL: [Reading; 7] = [
        Reading::AsRead,
        Reading::Conjugated,
        Reading::ScalarFirst,
        Reading::ScalarFirstConjugated,
        Reading::ScalarLast,
        Reading::ScalarLastConjugated,
        Reading::GyroNegated,
    ];

    /// The fix, in words (no front end's option: [`Self::fixes`] carries it typed).
    #[must_use]
    pub(crate) fn fix(&self) -> &'static str {
        match self {
            Reading::AsRead => "none needed",
            Reading::Conjugated => {
                "the quaternions look conjugated (a Hamilton quaternion mapping inertial → body): read them conjugated"
            }
            Reading::ScalarFirst => {
                "the quaternion columns look scalar first ([w, x, y, z]): read them scalar first"
            }
            Reading::ScalarFirstConjugated => {
                "the quaternions look scalar first and conjugated: read them scalar first and as JPL"
            }
            Reading::ScalarLast => {
                "the quaternion columns look scalar last ([x, y, z, w]) but were read as scalar first: read them scalar last"
            }
            Reading::ScalarLastConjugated => {
                "the quaternions look scalar last and conjugated: read them scalar last and as JPL"
            }
            Reading::GyroNegated => {
                "the gyro rates look negated relative to the attitude: check the sign of w_x, w_y, w_z"
            }
            Reading::GyroDegrees => {
                "the gyro rates are 180/π = 57.3 times the attitude's rates: they are in deg/s, not rad/s; read them as deg/s"
            }
            Reading::GyroRadians => {
                "the gyro rates are π/180 times the attitude's rates: they are in rad/s, not deg/s; read them as rad/s"
            }
        }
    }

    /// The settings that read the columns this way.
    #[must_use]
    pub(crate) fn fixes(&self) -> &'static [Fix] {
        match self {
            Reading::AsRead | Reading::GyroNegated => &[],
            Reading::GyroDegrees => &[Fix::GyroDegrees],
            Reading::GyroRadians => &[Fix::GyroRadians],
            Reading::Conjugated => &[Fix::Conjugate],
            Reading::ScalarFirst => &[Fix::ScalarFirst],
            Reading::ScalarFirstConjugated => &[Fix::ScalarFirst, Fix::Conjugate],
            Reading::ScalarLast => &[Fix::ScalarLast],
            Reading::ScalarLastConjugated => &[Fix::ScalarLast, Fix::Conjugate],
        }
    }

    fn apply(&self, q: &Quaternion) -> Quaternion {
        // Scalar-first columns read as scalar last: the true (w, x, y, z) is the read
        // (x, y, z, w). Scalar-last columns read as scalar first: the read (x, y, z, w) is
        // the true (y, z, w, x), so the true (w, x, y, z) is the read (z, w, x, y).
        let sf = |q: &Quaternion| {
            let [x, y, z, w] = q.to_xyzw();
            Quaternion::from_wxyz([x, y, z, w])
        };
        let sl = |q: &Quaternion| {
            let [x, y, z, w] = q.to_xyzw();
            Quaternion::from_wxyz([z, w, x, y])
        };
        match self {
            Reading::AsRead
            | Reading::GyroNegated
            | Reading::GyroDegrees
            | Reading::GyroRadians => *q,
            Reading::Conjugated => q.conjugate(),
            Reading::ScalarFirst => sf(q),
            Reading::ScalarFirstConjugated => sf(q).conjugate(),
            Reading::ScalarLast => sl(q),
            Reading::ScalarLastConjugated => sl(q).conjugate(),
        }
    }
}

/// The outcome of the check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Verdict {
    /// Not enough turning steps with gyro rates yet.
    Undecided,
    /// The attitude agrees with the gyro as read (median relative mismatch given).
    Consistent(f64),
    /// Another reading fits: the fix, and the mismatch as read and as fixed.
    Wrong {
        /// The reading that fits.
        reading: Reading,
        /// Median relative mismatch as read.
        as_read: f64,
        /// Median relative mismatch with the fix.
        fixed: f64,
    },
    /// No reading fits (frames, time tags or units differ): the mismatch as read.
    Disagree(f64),
}

/// Mismatches of the steps gathered so far, per reading.
#[derive(Debug, Clone)]
pub(crate) struct ConventionCheck {
    prev: Option<Sample>,
    mismatch: [[f64; STEPS_NEEDED]; 7],
    steps: usize,
    /// `|w|/|ω_q|` of steps where the attitude turns clearly (whatever the gyro's unit).
    scale: [f64; STEPS_NEEDED],
    scale_steps: usize,
}

impl Default for ConventionCheck {
    fn default() -> Self {
        Self {
            prev: None,
            mismatch: [[0.0; STEPS_NEEDED]; 7],
            steps: 0,
            scale: [0.0; STEPS_NEEDED],
            scale_steps: 0,
        }
    }
}

impl ConventionCheck {
    /// Feed the next sample (no effect once decided, or without gyro rates).
    pub(crate) fn push(&mut self, s: &Sample) {
        if self.decided() {
            return;
        }
        let prev = self.prev.replace(*s);
        let Some(a) = prev else { return };
        let (Some(w), h) = (a.omega_rad_s, s.t_s - a.t_s) else {
            return;
        };
        let wn = w.norm();
        self.push_scale(&a, s, &w, h);
        if self.steps >= STEPS_NEEDED {
            return;
        }
        if !(h > 0.0 && h.is_finite() && wn >= MIN_RATE_RAD_S && wn.is_finite()) {
            return;
        }
        // Only short steps: 2 vec(·)/h must be a good rate estimate (|w h| < 0.2 rad).
        if wn * h > 0.2 {
            return;
        }
        for (k, reading) in Reading::ALL.iter().enumerate() {
            let (qa, qb) = (reading.apply(&a.q), reading.apply(&s.q));
            let wq: Vector3<f64> = qa.conjugate().mul(&qb).positive_scalar().v * (2.0 / h);
            let wg = if *reading == Reading::GyroNegated {
                -w
            } else {
                w
            };
            self.mismatch[k][self.steps] = (wq - wg).norm() / wn;
        }
        self.steps += 1;
    }

    /// The scale of the gyro against the attitude over one step: `|w|/|ω_q|` with the
    /// attitude's rate `ω_q = 2 vec(q_a† q_b)/h`, from steps that turn clearly
    /// (`|ω_q| ≥` [`MIN_RATE_RAD_S`]), slowly enough for it to be a rate, and **along
    /// the gyro's axis** (`|cos ∠(w, ω_q)| ≥` [`SCALE_MIN_COS`]; a unit scales `w`, not its
    /// direction). The last condition keeps out steps whose attitude turns by its noise
    /// alone (a star tracker's 40″ at 10 Hz is ~3e-3 rad/s), whose `ω_q` points anywhere
    /// and whose ratio is noise: once their median fell within 10 % of π/180 on honest
    /// rad/s data, and they hid a real deg/s (the unit tests in telemetry/convention/tests.rs).
    fn push_scale(&mut self, a: &Sample, b: &Sample, w: &Vector3<f64>, h: f64) {
        let wn = w.norm();
        if self.scale_steps >= STEPS_NEEDED || !(h > 0.0 && h.is_finite() && wn.is_finite()) {
            return;
        }
        let wq: Vector3<f64> = a.q.conjugate().mul(&b.q).positive_scalar().v * (2.0 / h);
        let rate = wq.norm();
        let aligned = wn > 0.0 && rate > 0.0 && w.dot(&wq).abs() >= SCALE_MIN_COS * wn * rate;
        if rate >= MIN_RATE_RAD_S && rate * h <= 0.2 && aligned {
            self.scale[self.scale_steps] = wn / rate;
            self.scale_steps += 1;
        }
    }

    /// Whether both the frame check and the scale check have their steps.
    #[must_use]
    pub(crate) fn decided(&self) -> bool {
        self.steps >= STEPS_NEEDED && self.scale_steps >= STEPS_NEEDED
            || self.unit_verdict().is_some()
    }

    /// A gyro unit of deg/s (or rad/s) against the attitude: the median `|w|/|ω_q|`
    /// within 10 % of 180/π (or π/180).
    fn unit_verdict(&self) -> Option<Verdict> {
        if self.scale_steps < STEPS_NEEDED {
            return None;
        }
        let mut m = self.scale;
        m.sort_unstable_by(f64::total_cmp);
        let ratio = m[STEPS_NEEDED / 2];
        let deg = 180.0 / core::f64::consts::PI;
        for (reading, factor) in [
            (Reading::GyroDegrees, deg),
            (Reading::GyroRadians, 1.0 / deg),
        ] {
            if (ratio / factor - 1.0).abs() < 0.1 {
                return Some(Verdict::Wrong {
                    reading,
                    as_read: (ratio - 1.0).abs(),
                    fixed: (ratio / factor - 1.0).abs(),
                });
            }
        }
        None
    }

    /// Steps gathered.
    #[must_use]
    pub(crate) fn steps(&self) -> usize {
        self.steps.max(if self.unit_verdict().is_some() {
            self.scale_steps
        } else {
            0
        })
    }

    /// The verdict on the steps so far.
    #[must_use]
    pub(crate) fn verdict(&self) -> Verdict {
        if let Some(v) = self.unit_verdict() {
            return v;
        }
        if self.steps < STEPS_NEEDED {
            return Verdict::Undecided;
        }
        let medians: [f64; 7] = core::array::from_fn(|k| {
            let mut m = self.mismatch[k];
            m.sort_unstable_by(f64::total_cmp);
            m[STEPS_NEEDED / 2]
        });
        let as_read = medians[0];
        if as_read < FIT {
            return Verdict::Consistent(as_read);
        }
        let (best, fixed) =
            medians
                .iter()
                .enumerate()
                .skip(1)
                .fold(
                    (0, f64::INFINITY),
                    |b, (k, &m)| if m < b.1 { (k, m) } else { b },
                );
        if fixed < FIT && fixed < 0.5 * as_read {
            Verdict::Wrong {
                reading: Reading::ALL[best],
                as_read,
                fixed,
            }
        } else {
            Verdict::Disagree(as_read)
        }
    }
}

#[cfg(all(test, feature = "sim"))]
mod tests;
