//! Singular values of the 6×6 factor `R`, tracked from sample to sample.
//!
//! One-sided (Hestenes) Jacobi: rotate the columns of `B = R V` until they are mutually
//! orthogonal; then `σ_k = ‖b_k‖` and `V` holds the right singular vectors. The method
//! converges to full accuracy from any orthogonal `V`, but from the previous sample's `V`
//! (`R` changes by one row block per sample) it needs one or two sweeps instead of six,
//! which makes the observability test cheap enough to run at every sample. `V` is
//! re-orthonormalised every 256 updates against round-off drift. Fixed size, no
//! allocation.
//!
//! Cost. A warm update is latency-bound: each rotation waits for the dot product of its
//! two columns, and a cyclic-by-row sweep chains all fifteen through column 0. Here a
//! sweep is five rounds of three disjoint pairs (a round-robin ordering, as convergent as
//! the cyclic one), so the three rotations of a round overlap. Near convergence a
//! rotation's angle is tiny, and its tangent, cosine and sine come from short series (one
//! division, no square root), exact to rounding. On the slew telemetry a warm update is
//! one sweep that rotates every pair and one that finds nothing left to rotate. The convergence test compares squares
//! (no square root), on `B` scaled by a power of two (exact) so that squares neither
//! overflow nor underflow. The singular values and `V` are those of the plain algorithm
//! to rounding: the tolerance `TOL` on the columns' orthogonality is unchanged.

use crate::math::{abs, sqrt};
use nalgebra::{Matrix6, Vector6};

/// Sweeps at most per update.
const MAX_SWEEPS: u32 = 30;
/// Columns count as orthogonal when `|b_iᵀb_j| ≤ TOL ‖b_i‖ ‖b_j‖`; the singular values
/// are then accurate to about `TOL²` relative (second order).
const TOL: f64 = 1e-13;
/// `TOL²`, for the test on squares.
const TOL2: f64 = TOL * TOL;
/// Below this `|γ/(β − α)|` the rotation uses the series (relative error `< 10⁻¹⁷`).
const SMALL_ANGLE: f64 = 1e-3;

/// A sweep: every pair once, as five rounds of three disjoint pairs.
const ROUNDS: [[(usize, usize); 3]; 5] = [
    [(0, 1), (2, 3), (4, 5)],
    [(0, 2), (1, 4), (3, 5)],
    [(0, 3), (1, 5), (2, 4)],
    [(0, 4), (1, 3), (2, 5)],
    [(0, 5), (1, 2), (3, 4)],
];

type Columns = [[f64; 6]; 6];

/// The tracked right singular vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SvdTracker {
    v: Matrix6<f64>,
    updates: u32,
}

impl Default for SvdTracker {
    fn default() -> Self {
        Self::new()
    }
}

impl SvdTracker {
    /// Start from `V = I`.
    #[must_use]
    pub fn new() -> Self {
        Self {
            v: Matrix6::identity(),
            updates: 0,
        }
    }

    /// The tracked right singular vectors (columns, in the order of the last
    /// [`Self::singular_values`]).
    #[must_use]
    pub(crate) fn v(&self) -> &Matrix6<f64> {
        &self.v
    }

    /// Singular values of `r` (unordered), updating the tracked `V`.
    pub fn singular_values(&mut self, r: &Matrix6<f64>) -> Vector6<f64> {
        self.updates = self.updates.wrapping_add(1);
        if self.updates.is_multiple_of(256) {
            reorthonormalise(&mut self.v);
        }
        let mut v: Columns = core::array::from_fn(|k| core::array::from_fn(|i| self.v[(i, k)]));
        // B = R V · 2^-e with 2^e near the largest |r_ik|: exact, and keeps the squares
        // below in range.
        // (A plain fold: nalgebra's `amax` costs as much as a rotation round here.)
        let amax = r
            .iter()
            .fold(0.0, |m, &x| if abs(x) > m { abs(x) } else { m });
        let (scale, unscale) = power_of_two_scale(amax);
        let rs: Columns = core::array::from_fn(|k| core::array::from_fn(|i| r[(i, k)] * scale));
        let mut b: Columns = [[0.0; 6]; 6];
        // Column m of an upper-triangular R is zero below row m: those terms add an exact
        // zero to a sum that starts at +0 (and so is never −0), and are skipped, with the
        // same sums in the same order (for any other R, every term).
        let triangular = (1..6).all(|i| (0..i).all(|m| r[(i, m)] == 0.0));
        for (bk, vk) in b.iter_mut().zip(&v) {
            for (m, (rm, &vmk)) in rs.iter().zip(vk).enumerate() {
                let rows = if triangular { m + 1 } else { 6 };
                for (x, &y) in bk[..rows].iter_mut().zip(&rm[..rows]) {
                    *x += y * vmk;
                }
            }
        }
        let mut norms: [f64; 6] = core::array::from_fn(|k| dot(&b[k], &b[k]));
        for _ in 0..MAX_SWEEPS {
            let mut rotated = false;
            for round in &ROUNDS {
                for &(i, k) in round {
                    let (alpha, beta) = (norms[i], norms[k]);
                    let gamma = dot(&b[i], &b[k]);
                    // Also false for NaN: nothing to rotate towards.
                    if !(gamma * gamma > TOL2 * alpha * beta) {
                        continue;
                    }
                    rotated = true;
                    let (c, s, t) = rotation(alpha, beta, gamma);
                    rotate(&mut b, i, k, c, s);
                    rotate(&mut v, i, k, c, s);
                    // Hestenes: the rotation moves t·γ between the two column norms.
                    norms[i] = alpha - t * gamma;
                    norms[k] = beta + t * gamma;
                }
            }
            if !rotated {
                break;
            }
        }
        self.v = Matrix6::from_fn(|i, k| v[k][i]);
        Vector6::from_fn(|k, _| sqrt(dot(&b[k], &b[k])) * unscale)
    }
}

/// `(2^-e, 2^e)` with `2^e` within a factor two of `m` (`(1, 1)` for zero, subnormal or
/// non-finite `m`).
fn power_of_two_scale(m: f64) -> (f64, f64) {
    if !(m.is_normal()) {
        return (1.0, 1.0);
    }
    // The exponent of m, clamped so that both factors stay normal.
    let e = (((m.to_bits() >> 52) & 0x7ff) as i32 - 1023).clamp(-1000, 1000);
    let pow2 = |e: i32| f64::from_bits(((e + 1023) as u64) << 52);
    (pow2(-e), pow2(e))
}

#[inline]
fn dot(x: &[f64; 6], y: &[f64; 6]) -> f64 {
    // Two partial sums: a shorter dependency chain than a left fold.
    (x[0] * y[0] + x[2] * y[2] + x[4] * y[4]) + (x[1] * y[1] + x[3] * y[3] + x[5] * y[5])
}

/// Cosine, sine and tangent of the Jacobi rotation that makes columns with squared norms
/// `α`, `β` and inner product `γ ≠ 0` orthogonal.
#[inline]
fn rotation(alpha: f64, beta: f64, gamma: f64) -> (f64, f64, f64) {
    let u = gamma / (beta - alpha);
    if u.abs() < SMALL_ANGLE {
        // tan 2θ = 2u: t = tan θ = u − u³ + 2u⁵, c = 1 − u²/2 + 11u⁴/8, s = c t =
        // u − 3u³/2 + 31u⁵/8, each to O(u⁷) (relative error < 10⁻¹⁷), and each straight
        // from u so that the three evaluate side by side.
        let u2 = u * u;
        let t = u * (1.0 - u2 * (1.0 - 2.0 * u2));
        let c = 1.0 - u2 * (0.5 - 1.375 * u2);
        let s = u * (1.0 - u2 * (1.5 - 3.875 * u2));
        (c, s, t)
    } else {
        let zeta = (beta - alpha) / (2.0 * gamma);
        let t = zeta.signum() / (zeta.abs() + sqrt(1.0 + zeta * zeta));
        let c = 1.0 / sqrt(1.0 + t * t);
        (c, c * t, t)
    }
}

#[inline]
fn rotate(m: &mut Columns, i: usize, k: usize, c: f64, s: f64) {
    let (x, y) = (m[i], m[k]);
    for row in 0..6 {
        m[i][row] = c * x[row] - s * y[row];
        m[k][row] = s * x[row] + c * y[row];
    }
}

fn reorthonormalise(v: &mut Matrix6<f64>) {
    for k in 0..6 {
        for i in 0..k {
            let d = v.column(i).dot(&v.column(k));
            let ci = v.column(i).into_owned();
            let mut ck = v.column_mut(k);
            ck -= ci * d;
        }
        let n = v.column(k).norm();
        if n > 0.0 {
            v.column_mut(k).unscale_mut(n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series rotation agrees with the closed form where both apply.
    #[test]
    fn small_angle_series_matches_closed_form() {
        for &(alpha, beta, gamma) in &[
            (1.0, 2.0, 1e-9),
            (2.0, 1.0, -3e-7),
            (1.0, 1.5, 4.9e-4),
            (5.0, 1.0, -3.99e-3),
        ] {
            let (c, s, t) = rotation(alpha, beta, gamma);
            let zeta: f64 = (beta - alpha) / (2.0 * gamma);
            let t0 = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
            let c0 = 1.0 / (1.0 + t0 * t0).sqrt();
            assert!((t - t0).abs() <= 4.0 * f64::EPSILON * t0.abs(), "{t} {t0}");
            assert!((c - c0).abs() <= 2.0 * f64::EPSILON, "{c} {c0}");
            assert!((s - c0 * t0).abs() <= 4.0 * f64::EPSILON * (c0 * t0).abs());
        }
    }

    /// A seeded generator in [-0.5, 0.5).
    fn lcg(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// Sorted singular values of the tracker and of nalgebra's SVD agree to `1e-12 σ_1`
    /// (nalgebra's own accuracy is about `ε σ_1`), `V` stays orthonormal to `1e-13`, and
    /// the columns of `R V` are orthogonal to `1e-12` relative (plus the rounding of
    /// forming `R V`). Seeded random factors grown row by row
    /// (as the estimators grow them), with column scales over eight decades, occasional
    /// forgetting, an exactly rank-deficient case and cold restarts.
    #[test]
    fn tracks_nalgebra_svd_on_random_factors() {
        use crate::estimator::qr::RecursiveQr;
        let mut rnd = lcg(7);
        let mut worst = 0.0f64;
        for case in 0..40 {
            let scales: [f64; 6] = core::array::from_fn(|_| 10f64.powf(8.0 * (rnd() + 0.5)));
            let mut qr = RecursiveQr::new();
            let mut tracker = SvdTracker::new();
            for step in 0..400 {
                let mut h = Vector6::from_fn(|k, _| rnd() * scales[k]);
                if case % 10 == 9 {
                    h[5] = h[4]; // rank 5: two equal columns
                }
                qr.add_row(&h, rnd());
                if step % 97 == 96 {
                    qr.scale(0.5);
                }
                if step % 150 == 149 {
                    tracker = SvdTracker::new();
                }
                let got = tracker.singular_values(&qr.r);
                let mut a: [f64; 6] = core::array::from_fn(|k| got[k]);
                let mut b: [f64; 6] = core::array::from_fn(|k| qr.r.singular_values()[k]);
                a.sort_by(f64::total_cmp);
                b.sort_by(f64::total_cmp);
                for (x, y) in a.iter().zip(&b) {
                    let e = (x - y).abs() / b[5];
                    worst = worst.max(e);
                    assert!(e <= 1e-12, "case {case} step {step}: {a:?} vs {b:?}");
                }
                let v = tracker.v();
                let ortho = (v.transpose() * v - Matrix6::identity()).amax();
                assert!(
                    ortho <= 1e-13,
                    "case {case} step {step}: ‖VᵀV − I‖ {ortho:e}"
                );
                // Recomputing R V adds rounding of about ε σ_1 to every column.
                let bm = qr.r * v;
                for i in 0..6 {
                    for k in i + 1..6 {
                        let (bi, bk) = (bm.column(i), bm.column(k));
                        let (ni, nk) = (bi.norm(), bk.norm());
                        assert!(
                            bi.dot(&bk).abs() <= 1e-12 * ni * nk + 1e-14 * b[5] * ni.max(nk),
                            "case {case} step {step}: columns {i}, {k}"
                        );
                    }
                }
            }
        }
        assert!(worst > 0.0);
    }

    /// Singular values of matrices that are not factors of rows (full, negative entries,
    /// huge and tiny scales) from a cold start.
    #[test]
    fn cold_start_on_general_matrices() {
        let mut rnd = lcg(11);
        for case in 0..500 {
            let scale = 10f64.powi(case % 13 * 50 - 300);
            let r = Matrix6::from_fn(|_, _| rnd() * scale);
            let got = SvdTracker::new().singular_values(&r);
            let mut a: [f64; 6] = core::array::from_fn(|k| got[k]);
            let mut b: [f64; 6] = core::array::from_fn(|k| r.singular_values()[k]);
            a.sort_by(f64::total_cmp);
            b.sort_by(f64::total_cmp);
            for (x, y) in a.iter().zip(&b) {
                assert!((x - y).abs() <= 1e-12 * b[5], "case {case}: {a:?} vs {b:?}");
            }
        }
        assert_eq!(
            SvdTracker::new().singular_values(&Matrix6::zeros()),
            Vector6::zeros()
        );
    }

    /// The observability verdict from the tracked singular values is the verdict from
    /// nalgebra's SVD at every solve of the paper's slew and spin runs, for the
    /// variational and the discrete momentum estimators (whose reduced `R` the tracker
    /// follows), with and without a-priori bounds.
    #[cfg(feature = "sim")]
    #[test]
    fn observability_verdicts_match_reference_svd() {
        use crate::constraints::ConstraintSet;
        use crate::estimator::discrete_momentum::{
            DiscreteMomentumEstimator, MomentumEstimatorSettings,
        };
        use crate::estimator::observability::{assess, assess_with, ObservabilitySettings};
        use crate::estimator::qr::RecursiveQr;
        use crate::estimator::rows::{RowSource, VariationalRows};
        use crate::sim::scenario::{Common, Scenario};
        use crate::solver::native::NativeSolver;
        use core::mem::discriminant;
        let settings = ObservabilitySettings::default();
        let same = |qr: &RecursiveQr, sv: &Vector6<f64>, has_bounds: bool| {
            let (a, b) = (
                assess_with(qr, sv, has_bounds, &settings),
                assess(qr, has_bounds, &settings),
            );
            assert_eq!(discriminant(&a), discriminant(&b), "{a} vs {b}");
            assert_eq!(
                a.reason().map(|r| discriminant(&r)),
                b.reason().map(|r| discriminant(&r)),
                "{a} vs {b}"
            );
            if let (Some(x), Some(y)) = (a.condition(), b.condition()) {
                assert!((x - y).abs() <= 1e-9 * y, "{x} vs {y}");
            }
        };
        let mut verdicts = 0;
        for scenario in [Scenario::slew(), Scenario::spin()] {
            let run = scenario.simulate(&Common::paper()).unwrap();
            let mut rows = VariationalRows::default();
            let mut qr = RecursiveQr::new();
            let mut tracker = SvdTracker::new();
            for s in &run.samples {
                if let Some(row) = rows.push(s) {
                    qr.add(&row.unwrap());
                    let sv = tracker.singular_values(&qr.r);
                    same(&qr, &sv, false);
                    same(&qr, &sv, true);
                    verdicts += 2;
                }
            }
            let mut dm = DiscreteMomentumEstimator::new(
                MomentumEstimatorSettings::default(),
                ConstraintSet::positive_definite().validate().unwrap(),
                NativeSolver::default(),
            )
            .unwrap();
            for s in &run.samples {
                if let Some(e) = dm.push(s).unwrap() {
                    let b = assess(dm.reduced(), false, &settings);
                    assert_eq!(
                        e.observability.code(),
                        b.code(),
                        "{} vs {b}",
                        e.observability
                    );
                    verdicts += 1;
                }
            }
        }
        assert!(verdicts > 10_000, "{verdicts}");
    }

    #[test]
    fn power_of_two_scale_is_exact() {
        for m in [1.0, 3.0, 0.7, 1e-200, 1e200, 8.6e-4] {
            let (s, u) = power_of_two_scale(m);
            assert_eq!(s * u, 1.0);
            assert!((0.5..2.0).contains(&(m * s)), "{m}");
        }
        assert_eq!(power_of_two_scale(0.0), (1.0, 1.0));
        assert_eq!(power_of_two_scale(f64::NAN), (1.0, 1.0));
    }
}
