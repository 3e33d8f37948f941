//! A gyro at its range limit: a rate gyro saturates at its full-scale rate `R` and then
//! reads `±R` on that axis however fast the body turns. The clipped readings understate
//! the rate, and every estimator that uses the gyro (the rotation from the gyro, the
//! momentum RLS, the equation-error baseline, errors-in-variables compensation) then sees
//! a wrong motion. The run says so and names the axis and the limit.
//!
//! The test, per body axis `i`, over the samples with gyro rates: let `R_i` be the
//! largest `|w_i|` read so far. A sample **reads the limit** when `|w_i| = R_i` exactly
//! (a clipped reading repeats the converter's last code; noise makes an unclipped maximum
//! unique). It is **clipped** when, over the interval that starts at it, the attitude
//! turned faster about that axis than the gyro can read: `|ω_q,i| > (1 + `[`MARGIN`]`) R_i`
//! with `ω_q = log(q_k† q_{k+1}) / h_k` (body axes; the telemetry's own attitude). The
//! axis is flagged when at least [`MIN_CLIPPED`] samples are clipped at its final `R_i`.
//! A quantised gyro whose largest code repeats does not pass (the attitude agrees with
//! it), nor does an attitude integrated from the gyro itself (it cannot disagree).

use crate::attitude::Quaternion;
use crate::sample::Sample;
use nalgebra::Vector3;

/// How much faster than the limit the attitude must turn for a reading at the limit to
/// count as clipped.
pub(crate) const MARGIN: f64 = 0.02;
/// Fewest clipped samples for a verdict on an axis.
pub(crate) const MIN_CLIPPED: u32 = 3;

/// An axis whose gyro readings stop at a limit the attitude exceeds.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ClippedAxis {
    /// Body axis, 0 = x, 1 = y, 2 = z.
    pub axis: usize,
    /// The largest `|w|` read on it, rad/s: the gyro's range limit.
    pub limit_rad_s: f64,
    /// Samples at that limit while the attitude turned faster.
    pub samples: u32,
    /// The fastest rate about that axis the attitude showed while the gyro read the
    /// limit, rad/s.
    pub attitude_rate_rad_s: f64,
}

/// Per axis: the largest `|w_i|`, and the clipped samples at it with the fastest attitude
/// rate among them.
#[derive(Debug, Clone, Copy, Default)]
struct Axis {
    max: f64,
    clipped: u32,
    fastest: f64,
}

/// The test of the [module docs](self), fed sample by sample.
#[derive(Debug, Clone, Default)]
pub(crate) struct GyroRange {
    axes: [Axis; 3],
    /// The previous sample's time, attitude and gyro rates.
    previous: Option<(f64, Quaternion, Vector3<f64>)>,
}

impl GyroRange {
    /// Count the next sample (samples without gyro rates are skipped).
    pub(crate) fn push(&mut self, s: &Sample) {
        let Some(w) = s.omega_rad_s else {
            self.previous = None;
            return;
        };
        if let Some((t0, q0, w0)) = self.previous {
            let h = s.t_s - t0;
            if h > 0.0 && h.is_finite() {
                // The rate over the interval that starts at the previous sample, whose
                // gyro reading covers it (the telemetry's convention).
                let omega = q0.conjugate().mul(&s.q).log() / h;
                for (i, a) in self.axes.iter_mut().enumerate() {
                    let r = w0[i].abs();
                    if !r.is_finite() {
                        continue;
                    }
                    if r > a.max {
                        *a = Axis {
                            max: r,
                            ..Axis::default()
                        };
                    }
                    let turned = omega[i].abs();
                    if r == a.max && r > 0.0 && turned > (1.0 + MARGIN) * r {
                        a.clipped += 1;
                        a.fastest = a.fastest.max(turned);
                    }
                }
            }
        }
        self.previous = Some((s.t_s, s.q, w));
    }

    /// The axes at their range limit ([module docs](self)), in axis order.
    pub(crate) fn clipped(&self) -> impl Iterator<Item = ClippedAxis> + '_ {
        self.axes
            .iter()
            .enumerate()
            .filter(|(_, a)| a.clipped >= MIN_CLIPPED)
            .map(|(axis, a)| ClippedAxis {
                axis,
                limit_rad_s: a.max,
                samples: a.clipped,
                attitude_rate_rad_s: a.fastest,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A steady spin about z at `rate` rad/s sampled at 100 Hz, the gyro reading
    /// `read(rate)`.
    fn spin(rate: f64, read: impl Fn(f64) -> f64) -> GyroRange {
        let mut g = GyroRange::default();
        for k in 0..200 {
            let t = 0.01 * k as f64;
            g.push(&Sample {
                t_s: t,
                q: Quaternion::exp(&Vector3::new(0.0, 0.0, rate * t)),
                rho_nms: Vector3::zeros(),
                tau_nm: Vector3::zeros(),
                omega_rad_s: Some(Vector3::new(0.0, 0.0, read(rate))),
                external: Default::default(),
            });
        }
        g
    }

    #[test]
    fn a_clipped_axis_is_flagged_with_its_limit() {
        let g = spin(5.0, |r| r.min(4.0));
        let c: Vec<_> = g.clipped().collect();
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].axis, 2);
        assert_eq!(c[0].limit_rad_s, 4.0);
        assert!((c[0].attitude_rate_rad_s - 5.0).abs() < 1e-9);
    }

    #[test]
    fn a_gyro_that_agrees_with_the_attitude_is_not() {
        // The same steady reading, repeated exactly, but true.
        assert_eq!(spin(4.0, |r| r).clipped().count(), 0);
        // Within the margin.
        assert_eq!(spin(4.05, |_| 4.0).clipped().count(), 0);
    }
}
