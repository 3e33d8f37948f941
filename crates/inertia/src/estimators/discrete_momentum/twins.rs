//! Rotation sources that are one measurement: where the telemetered attitude is the
//! gyro's own integral (a gyro-propagated attitude solution, as in the paper's simulator),
//! the rows with `φ` from the attitude and those with `φ` from the gyro's delta angles
//! ([`crate::estimator::momentum_rows`], "Rotation source") carry the same noise, and
//! their answers differ only by the two integrations' rounding and coning terms. Folding
//! both then doubles the work for nothing, and their cross-check
//! ([`super`]) cannot fail: it is not a check.
//!
//! The test is made on the answers, in the units that matter: every
//! [`TWIN_CHECK_EVERY`] row blocks from [`TWIN_FROM`] on, each pair of candidates that
//! differ only in the rotation source is solved (unconstrained) and compared, element by
//! element, in their least-squares σ: `|ĵ_g − ĵ_a| / √(σ_g² + σ_a²)`. Independent
//! sources (a star tracker, an MEKF, a truth attitude beside a noisy gyro) differ by
//! their noise, 2–434 in that ratio on the README's cases; a gyro-propagated attitude by
//! at most 0.004 (the paper's, FOG and MEMS gyros on the slew). If every pair stays within [`TWIN_Z`] at every check up to
//! [`super::standing::RULE_OUT_AFTER`] row blocks, the attitude's candidates are ruled
//! out for good (the gyro's rows, coning-compensated, are kept); one check beyond it, or
//! one that cannot be made (an attitude candidate whose gyro twin is no longer folded, an
//! answer missing or not finite), and both stay for the whole run.
//! The unconstrained answers then differ by at most [`TWIN_Z`] of their combined σ
//! (about 0.07 of either's); the chosen, constrained answer moved by at most 0.0013 of
//! its σ on the paper's slew (test). The verdict is for good: an attitude that is the
//! gyro's integral for the first [`super::standing::RULE_OUT_AFTER`] row blocks and
//! corrected by a star tracker later is not tested again.

use crate::estimator::momentum_rows::{MomentumRowSettings, RotationSource};
use crate::estimator::qr::RecursiveQr;
use crate::tensor::InertiaVector;

/// Largest `|ĵ_g − ĵ_a| / √(σ_g² + σ_a²)` (least-squares σ) of two candidates that differ
/// only in the rotation source for them to count as one measurement.
pub(crate) const TWIN_Z: f64 = 0.05;

/// Row blocks between the checks.
pub(crate) const TWIN_CHECK_EVERY: usize = 100;

/// Row blocks before the first check (the first answers are too uncertain to compare).
pub(crate) const TWIN_FROM: usize = 1000;

/// What the checks have found so far.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum Twins {
    /// Every check so far within [`TWIN_Z`] (or none made yet).
    #[default]
    Undecided,
    /// A check beyond [`TWIN_Z`], or one that could not be made: both sources stay.
    Independent,
    /// Every check within [`TWIN_Z`] through the ruling-out horizon: the
    /// attitude's candidates are ruled out.
    Same,
    /// No pair to compare (one rotation source, or the other's candidates ruled out by
    /// their fit): no test.
    NoPairs,
}

impl Twins {
    /// Whether a check is due after `blocks` row blocks.
    pub(crate) fn due(self, blocks: usize) -> bool {
        self == Twins::Undecided && blocks >= TWIN_FROM && blocks.is_multiple_of(TWIN_CHECK_EVERY)
    }

    /// The verdict after a check at `blocks` row blocks whose largest ratio over the pairs
    /// is `worst` (`None`: some pair could not be compared), deciding at `horizon` row
    /// blocks ([`super::standing::RULE_OUT_AFTER`]; `usize::MAX`: never, as for [`super::standing`]).
    #[must_use]
    pub(crate) fn after(self, worst: Option<f64>, blocks: usize, horizon: usize) -> Self {
        match worst {
            Some(z) if z <= TWIN_Z => {
                if blocks >= horizon {
                    Twins::Same
                } else {
                    self
                }
            }
            _ => Twins::Independent,
        }
    }
}

/// For each attitude candidate still folded (`folded(i)`; indices into `rows`), the
/// candidate whose row settings differ only in the rotation source, if it is still folded
/// too: `(Some(gyro), attitude)`, or `(None, attitude)` for one without a twin to compare
/// (which makes the check fail: [`worst`]). An iterator, not a list: the recursive test
/// runs after warm-up, where nothing may allocate (`inertia-c`'s `no_alloc` test).
pub(crate) fn pairs<'a>(
    rows: &'a [MomentumRowSettings],
    folded: impl Fn(usize) -> bool + Clone + 'a,
) -> impl Iterator<Item = (Option<usize>, usize)> + Clone + 'a {
    rows.iter().enumerate().filter_map(move |(a, ra)| {
        if ra.rotation != RotationSource::Attitude || !folded(a) {
            return None;
        }
        let twin = rows.iter().position(|r| {
            r.rotation == RotationSource::Gyro
                && MomentumRowSettings {
                    rotation: RotationSource::Attitude,
                    ..*r
                } == *ra
        });
        Some((twin.filter(|&g| folded(g)), a))
    })
}

/// The largest `|ĵ_g − ĵ_a| / √(σ_g² + σ_a²)` over `pairs`, from each candidate's
/// `(unconstrained ĵ, least-squares σ)`; `None` when a pair cannot be compared (an
/// attitude candidate without a twin, an answer or σ missing or not finite) or there is
/// none.
pub(crate) fn worst(
    pairs: impl Iterator<Item = (Option<usize>, usize)>,
    answer: impl Fn(usize) -> Option<(InertiaVector, [f64; 6])>,
) -> Option<f64> {
    let mut out: Option<f64> = None;
    for (g, a) in pairs {
        let z = match (answer(g?), answer(a)) {
            (Some((jg, sg)), Some((ja, sa))) => ratio(&jg, &sg, &ja, &sa)?,
            _ => return None,
        };
        out = Some(out.unwrap_or(0.0).max(z));
    }
    out
}

/// The least-squares σ per element of a reduced state's unconstrained solution,
/// `√(ρ²/ν · ((RᵀR)⁻¹)_kk)`; `None` without residual degrees of freedom or with a
/// singular `R`.
pub(crate) fn least_squares_sigma(qr: &RecursiveQr) -> Option<[f64; 6]> {
    let dof = qr.residual_dof();
    if !(dof > 0.0) {
        return None;
    }
    let inv =
        qr.r.solve_upper_triangular(&nalgebra::Matrix6::identity())?;
    let s2 = qr.rss / dof;
    let out: [f64; 6] = core::array::from_fn(|k| (s2 * inv.row(k).norm_squared()).sqrt());
    out.iter().all(|s| s.is_finite()).then_some(out)
}

/// `max_k |a_k − b_k| / √(σa_k² + σb_k²)`; `None` where a variance is zero or not finite,
/// or a difference is not finite (a NaN would otherwise pass as agreement).
pub(crate) fn ratio(
    a: &InertiaVector,
    sa: &[f64; 6],
    b: &InertiaVector,
    sb: &[f64; 6],
) -> Option<f64> {
    let mut worst: f64 = 0.0;
    for k in 0..6 {
        let v = sa[k] * sa[k] + sb[k] * sb[k];
        if !(v > 0.0 && v.is_finite()) {
            return None;
        }
        let z = (a[k] - b[k]).abs() / v.sqrt();
        if !z.is_finite() {
            return None;
        }
        worst = worst.max(z);
    }
    worst.is_finite().then_some(worst)
}

#[cfg(test)]
mod tests {
    use super::super::standing::RULE_OUT_AFTER;
    use super::*;
    use nalgebra::{Matrix6, Vector6};

    #[test]
    fn checks_are_due_every_hundred_blocks_from_the_thousandth_until_decided() {
        let t = Twins::Undecided;
        assert!(!t.due(TWIN_FROM - TWIN_CHECK_EVERY));
        assert!(t.due(TWIN_FROM) && t.due(TWIN_FROM + TWIN_CHECK_EVERY));
        assert!(!t.due(TWIN_FROM + 1));
        assert!(!Twins::Independent.due(TWIN_FROM) && !Twins::Same.due(TWIN_FROM));
    }

    #[test]
    fn one_check_beyond_or_missing_keeps_both_sources_for_good() {
        let t = Twins::Undecided.after(Some(0.01), TWIN_FROM, RULE_OUT_AFTER);
        assert_eq!(t, Twins::Undecided);
        assert_eq!(
            t.after(Some(TWIN_Z * 1.01), TWIN_FROM + 100, RULE_OUT_AFTER),
            Twins::Independent
        );
        assert_eq!(
            t.after(None, TWIN_FROM + 100, RULE_OUT_AFTER),
            Twins::Independent
        );
        assert_eq!(
            t.after(Some(f64::NAN), TWIN_FROM + 100, RULE_OUT_AFTER),
            Twins::Independent
        );
        // Within throughout: the same measurement once the ruling-out horizon is reached.
        assert_eq!(
            t.after(Some(TWIN_Z), RULE_OUT_AFTER - 1, RULE_OUT_AFTER),
            Twins::Undecided
        );
        assert_eq!(
            t.after(Some(TWIN_Z), RULE_OUT_AFTER, RULE_OUT_AFTER),
            Twins::Same
        );
        assert_eq!(t.after(Some(0.0), 1 << 40, usize::MAX), Twins::Undecided);
    }

    #[test]
    fn least_squares_sigma_is_that_of_the_normal_equations() {
        // A triangular R with a positive diagonal: σ² = s² diag((RᵀR)⁻¹).
        let mut qr = RecursiveQr::new();
        qr.r = Matrix6::from_fn(|i, j| {
            if j < i {
                0.0
            } else if i == j {
                2.0 + i as f64
            } else {
                0.3 * (i + 2 * j) as f64
            }
        });
        qr.rss = 8.0;
        qr.weight = 10.0;
        let s = least_squares_sigma(&qr).expect("regular");
        let cov = (qr.r.transpose() * qr.r).try_inverse().expect("regular") * (8.0 / 4.0);
        for k in 0..6 {
            assert!((s[k] - cov[(k, k)].sqrt()).abs() <= 1e-12 * s[k], "{k}");
        }
        // Singular, or no degrees of freedom: no σ.
        let mut singular = qr;
        singular.r[(3, 3)] = 0.0;
        assert!(least_squares_sigma(&singular).is_none());
        qr.weight = 6.0;
        assert!(least_squares_sigma(&qr).is_none());
    }

    #[test]
    fn pairs_differ_only_in_the_rotation_source_and_are_both_folded() {
        let rows = crate::testing::rows;
        let (g, a) = (RotationSource::Gyro, RotationSource::Attitude);
        let all = [
            rows(g, Some(7.5)),
            rows(a, Some(7.5)),
            rows(g, Some(30.0)),
            rows(a, Some(30.0)),
            rows(a, None),
        ];
        let list = |p: &dyn Fn(usize) -> bool| -> std::vec::Vec<(Option<usize>, usize)> {
            pairs(&all, p).collect()
        };
        // The whole-record attitude candidate has no gyro twin.
        assert_eq!(
            list(&|_| true),
            std::vec![(Some(0), 1), (Some(2), 3), (None, 4)]
        );
        // An attitude candidate whose twin is no longer folded has none; one no longer
        // folded itself is not listed.
        assert_eq!(
            list(&|i| i != 2 && i != 4),
            std::vec![(Some(0), 1), (None, 3)]
        );
        let answer = |i: usize| {
            let j = InertiaVector::repeat(1.0 + 0.01 * (i % 2) as f64);
            Some((j, [1.0; 6]))
        };
        let z = worst(pairs(&all, |i| i != 4), answer).expect("comparable");
        assert!((z - 0.01 / 2f64.sqrt()).abs() < 1e-12, "{z}");
        // A candidate without a twin, no pairs, an answer missing or not finite: no
        // verdict.
        assert_eq!(worst(pairs(&all, |_| true), answer), None);
        assert_eq!(worst(core::iter::empty(), answer), None);
        let one_sided = |i: usize| (i == 0).then(|| answer(0)).flatten();
        assert_eq!(worst([(Some(0), 1)].into_iter(), one_sided), None);
        let nan = |i: usize| Some((InertiaVector::repeat(f64::NAN * i as f64), [1.0; 6]));
        assert_eq!(worst([(Some(0), 1)].into_iter(), nan), None);
    }

    #[test]
    fn ratio_is_the_largest_element_in_the_combined_sigma() {
        let a = Vector6::new(1.0, 2.0, 3.0, 0.0, 0.0, 0.0);
        let b = Vector6::new(1.3, 2.0, 3.0, 0.0, 0.0, 0.4);
        let s = [0.3, 1.0, 1.0, 1.0, 1.0, 0.5];
        let z = ratio(&a, &s, &b, &s).expect("finite");
        // Element 0: 0.3/(0.3√2); element 5: 0.4/(0.5√2), smaller.
        assert!((z - 0.5f64.sqrt()).abs() < 1e-12, "{z}");
        let mut zero = s;
        zero[2] = 0.0;
        assert!(ratio(&a, &zero, &b, &zero).is_none());
        // A NaN or infinite answer is no agreement.
        let mut c = b;
        c[4] = f64::NAN;
        assert!(ratio(&a, &s, &c, &s).is_none());
        c[4] = f64::INFINITY;
        assert!(ratio(&c, &s, &c, &s).is_none());
    }
}
