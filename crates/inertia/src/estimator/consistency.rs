//! Are the residuals consistent with one noise level throughout the record? A scale-free
//! residual test (beyond the paper), for the status: "determined" promises that the model
//! held, and a model that fails for part of the record (a change of J, a glitch in the
//! attitude, a wheel that misbehaves for a while) leaves residuals there far larger than
//! elsewhere, whatever the noise level is.
//!
//! **Recursive residuals.** Folding one row `(a, y)` into a full-rank least-squares state
//! by Givens rotations adds `e²/(1 + aᵀ(RᵀR)⁻¹a)` to the residual sum of squares, with
//! `e = y − aᵀx̂` the prediction error of the state before the row. Under the model, with
//! white Gaussian row errors of variance `s²`, these increments are independent `s²χ²₁`
//! (Brown, Durbin & Evans, 1975), so the increment of `ρ²` over a span of the record
//! with `d` residual degrees of freedom is `s²χ²_d`, independent of the rest, whatever
//! `s` is: the ratio of its mean square to the rest's is `F(d, D − d)`-distributed, and
//! no noise level has to be known.
//!
//! **Segments.** The record is cut into consecutive segments of at least
//! [`FIRST_SEGMENT_DOF`] residual degrees of freedom; when [`MAX_SEGMENTS`] are complete,
//! neighbours are merged pairwise and the segment length doubles, so that memory is fixed
//! and any record has between `MAX_SEGMENTS/2` and `MAX_SEGMENTS` segments. The
//! statistic is the largest ratio of a segment's residual variance to that of all the
//! other segments, [`Worst::ratio`].
//!
//! **Threshold.** Row errors are not white in practice: an unmodelled disturbance torque
//! integrates into a random walk of the momentum along each chain, a propagated attitude
//! drifts, and at a slow telemetry rate the discretisation remainder grows with the
//! angular rate, so honest residual variances vary from segment to segment by more than
//! `F` allows. The threshold [`INCONSISTENT_RATIO`] is set from the honest cells of the
//! Monte Carlo matrix (README), far above their largest ratio; what it catches is a model
//! that fails outright for part of the record (tests: a 20 % change of J mid-run, one
//! 90° attitude glitch). Under exponential forgetting the increments are reweighted and
//! the test is not made.

use super::compensation::NOISE_GRAM_DIAGONAL;
use super::observability::{Observability, Unobservable};
use super::qr::RecursiveQr;
use super::Estimate;
use crate::tensor::InertiaVector;

/// Largest number of complete segments kept.
pub const MAX_SEGMENTS: usize = 32;

/// Fewest complete segments for the test.
pub const MIN_SEGMENTS: usize = 8;

/// Residual degrees of freedom of a segment before the first merge.
pub const FIRST_SEGMENT_DOF: f64 = 60.0;

/// Ratio of one segment's residual variance to the rest's beyond which the residuals are
/// inconsistent with one model and noise level.
pub const INCONSISTENT_RATIO: f64 = 300.0;

/// A span of the record: its share of `ρ²` and of the residual degrees of freedom.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Segment {
    rss: f64,
    dof: f64,
    t_start_s: f64,
    t_end_s: f64,
}

impl Segment {
    fn merge(&self, next: &Segment) -> Segment {
        Segment {
            rss: self.rss + next.rss,
            dof: self.dof + next.dof,
            t_start_s: self.t_start_s,
            t_end_s: next.t_end_s,
        }
    }
}

/// The segment whose residuals stand out most from the rest.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Worst {
    /// Its residual variance over that of all the other segments.
    pub ratio: f64,
    /// Its first sample's time, s.
    pub t_start_s: f64,
    /// Its last sample's time, s.
    pub t_end_s: f64,
}

/// The residual record of one least-squares state, in segments ([module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualSegments {
    done: [Segment; MAX_SEGMENTS],
    len: usize,
    target_dof: f64,
    open: Segment,
    last_rss: f64,
    last_dof: f64,
}

impl Default for ResidualSegments {
    fn default() -> Self {
        Self::new()
    }
}

impl ResidualSegments {
    /// No residuals yet.
    #[must_use]
    pub fn new() -> Self {
        Self {
            done: [Segment::default(); MAX_SEGMENTS],
            len: 0,
            target_dof: FIRST_SEGMENT_DOF,
            open: Segment {
                t_start_s: f64::NAN,
                ..Segment::default()
            },
            last_rss: 0.0,
            last_dof: 0.0,
        }
    }

    /// Record the state after the rows of the sample at `t_s`: its cumulative residual
    /// sum of squares and residual degrees of freedom. Increments before the state has
    /// any residual degree of freedom (the rows that fix the unknowns) are not counted.
    pub fn record(&mut self, rss: f64, dof: f64, t_s: f64) {
        let (d_rss, d_dof) = (rss - self.last_rss, dof - self.last_dof);
        (self.last_rss, self.last_dof) = (rss, dof);
        if !(dof > 0.0) || !d_rss.is_finite() {
            return;
        }
        if self.open.t_start_s.is_nan() {
            self.open.t_start_s = t_s;
        }
        self.open.rss += d_rss.max(0.0);
        self.open.dof += d_dof;
        self.open.t_end_s = t_s;
        if self.open.dof < self.target_dof {
            return;
        }
        if self.len == MAX_SEGMENTS {
            for i in 0..MAX_SEGMENTS / 2 {
                self.done[i] = self.done[2 * i].merge(&self.done[2 * i + 1]);
            }
            self.len = MAX_SEGMENTS / 2;
            self.target_dof *= 2.0;
        }
        self.done[self.len] = self.open;
        self.len += 1;
        self.open = Segment {
            t_start_s: f64::NAN,
            ..Segment::default()
        };
    }

    /// Complete segments so far.
    #[must_use]
    pub fn segments(&self) -> usize {
        self.len
    }

    /// The span that stands out most, with at least [`MIN_SEGMENTS`] complete segments:
    /// one segment against all the others (a glitch), or the record after a segment
    /// boundary against the record before it, and the reverse (a change that persists).
    #[must_use]
    pub fn worst(&self) -> Option<Worst> {
        if self.len < MIN_SEGMENTS {
            return None;
        }
        let done = &self.done[..self.len];
        let total = done.iter().fold(Segment::default(), |a, s| Segment {
            rss: a.rss + s.rss,
            dof: a.dof + s.dof,
            ..a
        });
        let mut out: Option<Worst> = None;
        let mut consider = |span: Segment, rest_rss: f64, rest_dof: f64| {
            let ratio = (span.rss / span.dof) / (rest_rss / rest_dof);
            if ratio.is_finite() && out.is_none_or(|w| ratio > w.ratio) {
                out = Some(Worst {
                    ratio,
                    t_start_s: span.t_start_s,
                    t_end_s: span.t_end_s,
                });
            }
        };
        let mut before = Segment {
            t_start_s: done[0].t_start_s,
            ..Segment::default()
        };
        for (i, s) in done.iter().enumerate() {
            consider(*s, total.rss - s.rss, total.dof - s.dof);
            before = Segment {
                rss: before.rss + s.rss,
                dof: before.dof + s.dof,
                t_end_s: s.t_end_s,
                ..before
            };
            let after = Segment {
                rss: total.rss - before.rss,
                dof: total.dof - before.dof,
                t_start_s: done.get(i + 1).map_or(f64::NAN, |n| n.t_start_s),
                t_end_s: done[self.len - 1].t_end_s,
            };
            // Each side at least two segments long.
            if (2..=self.len - 2).contains(&(i + 1)) {
                consider(before, after.rss, after.dof);
                consider(after, before.rss, before.dof);
            }
        }
        out
    }

    /// [`Self::worst`] when its ratio exceeds [`INCONSISTENT_RATIO`].
    #[must_use]
    pub fn inconsistent(&self) -> Option<Worst> {
        self.worst().filter(|w| w.ratio > INCONSISTENT_RATIO)
    }
}

/// Below this ratio of the residual variance to the part the stated gyro density alone
/// implies ([`gyro_density_ratio`]), the density is overstated.
pub const DENSITY_OVERSTATED_RATIO: f64 = 0.5;

/// Withdraw the answer of `e` when its residuals contradict the model or the noise: a
/// span of the record inconsistent with the rest ([`ResidualSegments::inconsistent`],
/// [`Unobservable::Inconsistent`]), or residuals smaller than the stated gyro density
/// implies ([`DENSITY_OVERSTATED_RATIO`], [`Unobservable::DensityOverstated`]). A model
/// that failed for part of the record leaves an answer that is no mixture's truth, and an
/// overstated density an over-compensated one; σ knows neither.
pub fn check(e: &mut Estimate, segments: Option<&ResidualSegments>, density_ratio: Option<f64>) {
    if !matches!(
        e.observability,
        Observability::Determined { .. } | Observability::FromPrior(_)
    ) {
        return;
    }
    let why = if let Some(w) = segments.and_then(ResidualSegments::inconsistent) {
        Unobservable::Inconsistent {
            ratio: w.ratio,
            t_start_s: w.t_start_s,
            t_end_s: w.t_end_s,
        }
    } else if let Some(ratio) = density_ratio.filter(|r| *r < DENSITY_OVERSTATED_RATIO) {
        Unobservable::DensityOverstated { ratio }
    } else {
        return;
    };
    e.observability = Observability::NotObservable(why);
    e.solution = None;
    e.uncertainty = None;
}

/// The residual variance per degree of freedom of `qr` over the part a gyro of rate-noise
/// density `gyro_noise_rad_s_rthz` alone would put into its rows at `j`:
/// `σ² c jᵀDj / rows`, with `c = Σ noise_s` and `D` of [`super::compensation`] (the
/// expected energy of `δH j`, white from row to row). Every other error source (the
/// wheels, the disturbance torque, the star tracker, the model) only adds to the
/// residuals, so a ratio well below one says that the stated density is too large, and
/// the errors-in-variables compensation built on it removes information the rows do not
/// lack. `None` without residual degrees of freedom or modelled noise.
#[must_use]
pub fn gyro_density_ratio(
    qr: &RecursiveQr,
    j: &InertiaVector,
    gyro_noise_rad_s_rthz: f64,
) -> Option<f64> {
    let d: f64 = (0..6).map(|k| NOISE_GRAM_DIAGONAL[k] * j[k] * j[k]).sum();
    let predicted = gyro_noise_rad_s_rthz * gyro_noise_rad_s_rthz * qr.noise_s * d / qr.rows as f64;
    let ratio = qr.residual_variance() / predicted;
    (predicted > 0.0 && ratio.is_finite()).then_some(ratio)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// White residuals of one variance: increments `s² χ²₁` (from a fixed pseudo-random
    /// sequence), recorded as cumulative sums.
    fn white(n: usize, s2: f64, spike: Option<(usize, f64)>) -> ResidualSegments {
        let mut r = ResidualSegments::new();
        let (mut rss, mut x) = (0.0, 0x2545_f491_4f6c_dd1d_u64);
        for k in 0..n {
            // Box-Muller on an xorshift generator.
            let mut u = || {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x >> 11) as f64 / (1u64 << 53) as f64
            };
            let (a, b) = (u().max(1e-300), u());
            let e = (-2.0 * a.ln()).sqrt() * (2.0 * core::f64::consts::PI * b).cos();
            rss += s2 * e * e;
            if let Some((at, size)) = spike {
                if k == at {
                    rss += size;
                }
            }
            r.record(rss, k as f64 + 1.0, k as f64 * 0.1);
        }
        r
    }

    #[test]
    fn white_residuals_are_consistent_at_any_scale() {
        for s2 in [1e-20, 1.0, 1e12] {
            let r = white(50_000, s2, None);
            let w = r.worst().unwrap();
            assert!(r.segments() >= MAX_SEGMENTS / 2 && r.segments() <= MAX_SEGMENTS);
            assert!(w.ratio < 1.5, "ratio {}", w.ratio);
            assert!(r.inconsistent().is_none());
        }
    }

    #[test]
    fn one_wild_residual_names_its_segment() {
        // One residual of 1e7 s² at row 20,000 (t = 1999.9 s).
        let r = white(50_000, 1.0, Some((20_000, 1e7)));
        let w = r.inconsistent().expect("flagged");
        assert!(w.t_start_s <= 1999.9 && 1999.9 <= w.t_end_s, "{w:?}");
        assert!(w.ratio > 3.0 * INCONSISTENT_RATIO);
    }

    #[test]
    fn too_few_segments_give_no_verdict() {
        let r = white(300, 1.0, Some((100, 1e6)));
        assert!(r.segments() < MIN_SEGMENTS);
        assert!(r.worst().is_none());
    }
}
