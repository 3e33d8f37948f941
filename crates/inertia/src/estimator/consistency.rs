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
//! no noise level has to be known. That is the idea; the rows here are not white (the
//! Richardson rows average neighbouring steps, the paper's rows difference them, and the
//! momentum's random walk correlates a chain), so the thresholds below are empirical.
//!
//! **Spans.** The record is cut into consecutive segments of at least
//! `FIRST_SEGMENT_DOF` (60) residual degrees of freedom; when `MAX_SEGMENTS` (32) are complete,
//! neighbours are merged pairwise and the segment length doubles, so that memory is fixed
//! and a long record has between `MAX_SEGMENTS/2` and `MAX_SEGMENTS` complete segments
//! (the test starts at `MIN_SEGMENTS` (8); the open segment, the newest data, is not
//! tested until it completes). A span is
//! one segment (against all the others: a glitch), or the record after a segment
//! boundary (against the record before it: a change that persists), or before it
//! (against after). Its statistic is the ratio of its residual variance to the rest's.
//!
//! **Threshold, and what a span must have done.** Row errors are not white in practice:
//! an unmodelled disturbance torque integrates into a random walk of the momentum along
//! each chain, a propagated attitude drifts, and the discretisation remainder grows with
//! the angular rate (at 1 Hz, at a wheel pulse, or on noise-free data, where it is all
//! there is), so honest residual variances differ between spans by far more than `F`
//! allows: ratios up to 92 in the Monte Carlo matrix (README), 970 on a noise-free spin.
//! Such a span is harmless when the answer does not depend on it. So a span is
//! inconsistent when its ratio exceeds [`INCONSISTENT_RATIO`] *and* the answer moved, with
//! or without it, beyond `SHIFT_Z` (20) of its own stated σ: the estimate now is compared
//! with the last answer before the span (its σ), or, for a span at the start of the
//! record, with the first one after it. A change of J moves the answer by many σ,
//! a glitch that the rows feel does too; a noisier stretch of honest data does not.
//! Without a stated σ (an estimator with no uncertainty model, such as the
//! finite-difference baseline) no span is inconsistent: the worst one is still reported.
//! Under exponential forgetting the increments are reweighted and the test is not made.

// The crate-internal helpers here serve the std front ends (pipeline, estimators).
#![cfg_attr(not(feature = "std"), allow(dead_code))]

use super::compensation::NOISE_GRAM_DIAGONAL;
use super::observability::{Observability, Unobservable};
use super::qr::RecursiveQr;
use super::Estimate;
use crate::tensor::InertiaVector;

/// Largest number of complete segments kept.
pub(crate) const MAX_SEGMENTS: usize = 32;

/// Fewest complete segments for the test.
pub(crate) const MIN_SEGMENTS: usize = 8;

/// Residual degrees of freedom of a segment before the first merge.
pub(crate) const FIRST_SEGMENT_DOF: f64 = 60.0;

/// Ratio of a span's residual variance to the rest's beyond which it may be inconsistent
/// with one model and noise level.
pub const INCONSISTENT_RATIO: f64 = 300.0;

/// Shift of the answer, in its own stated σ (largest over the elements), that makes a
/// span beyond [`INCONSISTENT_RATIO`] inconsistent. On a noise-free spin, whose spans
/// reach ratios of 970 from the discretisation remainder alone, the answers moved by up
/// to 10.1 of their early σ (which, without noise, is too small); in the broken runs of
/// `tests/integration/consistency.rs`, by at least 52.
pub(crate) const SHIFT_Z: f64 = 20.0;

/// An answer and its stated σ per element.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Snapshot {
    j: InertiaVector,
    sigma: [f64; 6],
}

/// A span of the record: its share of `ρ²` and of the residual degrees of freedom, and
/// the last answer before it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Segment {
    rss: f64,
    dof: f64,
    t_start_s: f64,
    t_end_s: f64,
    before: Option<Snapshot>,
}

impl Segment {
    fn merge(&self, next: &Segment) -> Segment {
        Segment {
            rss: self.rss + next.rss,
            dof: self.dof + next.dof,
            t_start_s: self.t_start_s,
            t_end_s: next.t_end_s,
            before: self.before,
        }
    }

    fn open() -> Segment {
        Segment {
            t_start_s: f64::NAN,
            ..Segment::default()
        }
    }
}

/// The span whose residuals stand out most from the rest.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Worst {
    /// Its residual variance over that of the rest of the record.
    pub ratio: f64,
    /// Its first sample's time, s.
    pub t_start_s: f64,
    /// Its last sample's time, s.
    pub t_end_s: f64,
}

/// A span, its ratio, and the answer to compare the present one with.
struct Span {
    worst: Worst,
    reference: Option<Snapshot>,
}

/// The residual record of one least-squares state, in segments ([module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ResidualSegments {
    done: [Segment; MAX_SEGMENTS],
    len: usize,
    target_dof: f64,
    open: Segment,
    last_rss: f64,
    last_dof: f64,
    latest: Option<Snapshot>,
    /// [`Self::worst`] of the complete segments, kept up to date as they change (the
    /// spans change only when a segment completes, while the test runs at every solve).
    worst: Option<Worst>,
}

impl Default for ResidualSegments {
    fn default() -> Self {
        Self::new()
    }
}

impl ResidualSegments {
    /// No residuals yet.
    #[must_use]
    pub(crate) fn new() -> Self {
        Self {
            done: [Segment::default(); MAX_SEGMENTS],
            len: 0,
            target_dof: FIRST_SEGMENT_DOF,
            open: Segment::open(),
            last_rss: 0.0,
            last_dof: 0.0,
            latest: None,
            worst: None,
        }
    }

    /// Record the state after the rows of the sample at `t_s`: its cumulative residual
    /// sum of squares and residual degrees of freedom. Increments before the state has
    /// any residual degree of freedom (the rows that fix the unknowns) are not counted.
    pub(crate) fn record(&mut self, rss: f64, dof: f64, t_s: f64) {
        if !rss.is_finite() || !dof.is_finite() {
            return;
        }
        let (d_rss, d_dof) = (rss - self.last_rss, dof - self.last_dof);
        (self.last_rss, self.last_dof) = (rss, dof);
        if !(dof > 0.0) {
            return;
        }
        if self.open.t_start_s.is_nan() {
            self.open.t_start_s = t_s;
            self.open.before = self.latest;
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
        self.open = Segment::open();
        self.worst = self
            .spans()
            .map(|s| s.worst)
            .max_by(|a, b| a.ratio.total_cmp(&b.ratio));
    }

    /// Note an answer (determined, or leaning on the prior) and its stated σ per element
    /// (kg m²), for the spans that start after it.
    pub(crate) fn note(&mut self, j: &InertiaVector, sigma_kg_m2: &[f64; 6]) {
        if j.iter().chain(sigma_kg_m2).all(|v| v.is_finite()) {
            self.latest = Some(Snapshot {
                j: *j,
                sigma: *sigma_kg_m2,
            });
        }
    }

    /// Complete segments so far.
    #[cfg(test)]
    #[must_use]
    pub(crate) fn segments(&self) -> usize {
        self.len
    }

    /// Every span with at least [`MIN_SEGMENTS`] complete segments (none before).
    fn spans(&self) -> impl Iterator<Item = Span> + '_ {
        let n = if self.len < MIN_SEGMENTS { 0 } else { self.len };
        let done = &self.done[..n];
        let total = sum(done);
        // The first answer after segment `i`.
        let after = move |i: usize| done.get(i + 1).and_then(|s| s.before);
        let mut prefix = (0.0, 0.0);
        (0..n).flat_map(move |i| {
            let s = &done[i];
            prefix = (prefix.0 + s.rss, prefix.1 + s.dof);
            let span = |(rss, dof): (f64, f64), t_start_s, t_end_s, reference| {
                let rest = (total.0 - rss) / (total.1 - dof);
                // Residuals where the rest has none (exact data): infinitely distinct.
                let ratio = if rest == 0.0 && rss > 0.0 {
                    f64::INFINITY
                } else {
                    (rss / dof) / rest
                };
                (!ratio.is_nan()).then_some(Span {
                    worst: Worst {
                        ratio,
                        t_start_s,
                        t_end_s,
                    },
                    reference,
                })
            };
            let one = span(
                (s.rss, s.dof),
                s.t_start_s,
                s.t_end_s,
                s.before.or(after(i)),
            );
            // Each side of a boundary at least two segments long.
            let split = (2..=n - 2).contains(&(i + 1));
            let before = split
                .then(|| span(prefix, done[0].t_start_s, s.t_end_s, after(i)))
                .flatten();
            let rest = (total.0 - prefix.0, total.1 - prefix.1);
            let later = split
                .then(|| span(rest, done[i + 1].t_start_s, done[n - 1].t_end_s, after(i)))
                .flatten();
            [one, before, later].into_iter().flatten()
        })
    }

    /// The span that stands out most, with at least [`MIN_SEGMENTS`] complete segments.
    #[must_use]
    pub(crate) fn worst(&self) -> Option<Worst> {
        self.worst
    }

    /// The most distinct span beyond [`INCONSISTENT_RATIO`] that moved the answer `j` by
    /// more than [`SHIFT_Z`] of its reference's σ. A span with no answer noted before or
    /// after it is never inconsistent: the ratio alone does not tell a failed model from
    /// honest residuals of unequal size (module docs).
    #[must_use]
    ///
    /// `stated` is the rotor momentum's relative σ the user stated (the wheels' spin
    /// inertia): a wheel whose inertia is off by that much leaves residuals where it
    /// spins and moves the answer by up to about `stated ‖Ĵ‖_F`, which σ then covers
    /// ([`crate::estimator::rotor_inertia`]), so each element's reference σ is widened by
    /// it here: a span is inconsistent only if it moved the answer beyond what the
    /// stated uncertainties allow.
    pub(crate) fn inconsistent(&self, j: &InertiaVector, stated: f64) -> Option<Worst> {
        // No span beyond the ratio: nothing to compare (the common case, without a pass
        // over the spans at every solve).
        if !self.worst.is_some_and(|w| w.ratio > INCONSISTENT_RATIO) {
            return None;
        }
        self.spans()
            .filter(|s| s.worst.ratio > INCONSISTENT_RATIO)
            .filter(|s| {
                s.reference
                    .is_some_and(|r| shift_z(j, &r, stated) > SHIFT_Z)
            })
            .map(|s| s.worst)
            .max_by(|a, b| a.ratio.total_cmp(&b.ratio))
    }
}

/// `(Σ ρ², Σ dof)` of segments.
fn sum(segments: &[Segment]) -> (f64, f64) {
    segments
        .iter()
        .fold((0.0, 0.0), |(r, d), s| (r + s.rss, d + s.dof))
}

/// `max_k |j_k − r.j_k| / σ_k`, `σ_k = √(r.σ_k² + (stated ‖r.J‖_F)²)`.
fn shift_z(j: &InertiaVector, r: &Snapshot, stated: f64) -> f64 {
    let scale = stated * crate::tensor::matrix_from_j(&r.j).norm();
    (0..6)
        .map(|k| (j[k] - r.j[k]).abs() / crate::math::sqrt(r.sigma[k] * r.sigma[k] + scale * scale))
        .filter(|z| !z.is_nan())
        .fold(0.0, f64::max)
}

/// Below this ratio of the residual variance to the part the stated gyro density alone
/// implies (`gyro_density_ratio`), the density is overstated.
pub const DENSITY_OVERSTATED_RATIO: f64 = 0.5;

/// Withdraw the answer of `e` when its residuals contradict the model or the noise: a
/// span of the record inconsistent with the rest ([`ResidualSegments::inconsistent`],
/// [`Unobservable::Inconsistent`]), or residuals smaller than the stated gyro density
/// implies ([`DENSITY_OVERSTATED_RATIO`], [`Unobservable::DensityOverstated`]). A model
/// that failed for part of the record leaves an answer that is no mixture's truth, and an
/// overstated density an over-compensated one; σ knows neither.
pub(crate) fn check(
    e: &mut Estimate,
    segments: Option<&ResidualSegments>,
    density_ratio: Option<f64>,
    stated: f64,
) {
    if !matches!(
        e.observability,
        Observability::Determined { .. } | Observability::FromPrior(_)
    ) {
        return;
    }
    let Some(j) = e.j() else { return };
    let why = if let Some(w) = segments.and_then(|r| r.inconsistent(&j, stated)) {
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
pub(crate) fn gyro_density_ratio(
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
        // The answer is zero ± 0.01 throughout.
        r.note(&InertiaVector::zeros(), &[0.01; 6]);
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
            let far = InertiaVector::repeat(1e9);
            let w = r.worst().unwrap();
            assert!(r.segments() >= MAX_SEGMENTS / 2 && r.segments() <= MAX_SEGMENTS);
            assert!(w.ratio < 1.5, "ratio {}", w.ratio);
            assert!(r.inconsistent(&far, 0.0).is_none());
        }
    }

    #[test]
    fn one_wild_residual_names_its_segment() {
        // One residual of 1e7 s² at row 20,000 (t = 1999.9 s).
        let r = white(50_000, 1.0, Some((20_000, 1e7)));
        // Flagged when the answer moved beyond SHIFT_Z of its σ, not when it did not.
        assert!(r.inconsistent(&InertiaVector::zeros(), 0.0).is_none());
        let w = r
            .inconsistent(&InertiaVector::repeat(1.0), 0.0)
            .expect("flagged");
        assert!(w.t_start_s <= 1999.9 && 1999.9 <= w.t_end_s, "{w:?}");
        assert!(w.ratio > 3.0 * INCONSISTENT_RATIO);
    }

    #[test]
    fn a_residual_in_exact_data_is_infinitely_distinct() {
        let mut r = ResidualSegments::new();
        r.note(&InertiaVector::zeros(), &[0.01; 6]);
        for k in 0..2000 {
            let rss = if k >= 1000 { 1e-30 } else { 0.0 };
            r.record(rss, k as f64 + 1.0, k as f64);
        }
        let w = r
            .inconsistent(&InertiaVector::repeat(1.0), 0.0)
            .expect("flagged");
        assert!(
            w.ratio.is_infinite() && w.t_start_s <= 1000.0 && 1000.0 <= w.t_end_s,
            "{w:?}"
        );
    }

    #[test]
    fn too_few_segments_give_no_verdict() {
        let r = white(300, 1.0, Some((100, 1e6)));
        assert!(r.segments() < MIN_SEGMENTS);
        assert!(r.worst().is_none());
    }

    #[test]
    fn the_kept_worst_span_is_the_worst_of_all_spans() {
        // Through merges (50,000 rows is beyond 32 segments of 60 dof) and a spike.
        for spike in [None, Some((20_000, 1e7))] {
            for n in [400, 3_000, 20_500, 50_000] {
                let r = white(n, 1.0, spike);
                let fresh = r
                    .spans()
                    .map(|s| s.worst)
                    .max_by(|a, b| a.ratio.total_cmp(&b.ratio));
                assert_eq!(r.worst(), fresh, "n {n}, spike {spike:?}");
            }
        }
    }
}
