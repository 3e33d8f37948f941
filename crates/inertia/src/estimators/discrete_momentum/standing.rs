//! Which candidate row models of the discrete momentum pipeline
//! ([`super`]) the data have ruled out, so that they stop costing a
//! fold per sample.
//!
//! A candidate whose residual variance is beyond `v_min · max(COMPARABLE_FIT, 1 +
//! 3√(2/ν))` (`v_min` the smallest of the candidates still standing, `ν` its residual
//! degrees of freedom) takes no part in an answer: it is not chosen (the choice's limit is
//! `v_min (1 + 3√(2/ν))`), it adds nothing to the model spread (the same limit) and it is
//! not cross-checked (only within `COMPARABLE_FIT · v_min` of the chosen one, whose
//! variance is at least `v_min`). One that has stayed beyond that for [`RULE_OUT_AFTER`]
//! consecutive row blocks is ruled out for good: it is no longer folded, chosen, spread or
//! cross-checked. Answers are then exactly those of the run without it for as long as it
//! would have stayed beyond the limit; a model that fitted markedly worse over that long
//! is taken not to come back.

use super::cross_check::COMPARABLE_FIT;
use std::vec::Vec;

/// Consecutive row blocks beyond the limit after which a candidate is ruled out.
pub(crate) const RULE_OUT_AFTER: usize = 3000;

/// Per candidate: consecutive row blocks beyond the limit, `None` once ruled out.
#[derive(Debug, Clone, Default)]
pub(crate) struct Standing {
    beyond: Vec<Option<usize>>,
    /// Row blocks beyond the limit that rule a candidate out ([`RULE_OUT_AFTER`];
    /// `usize::MAX`: never, to test that ruling out changes nothing).
    after: usize,
}

impl Standing {
    /// `n` candidates, all standing, ruled out after `after` row blocks beyond the limit.
    pub(crate) fn new(n: usize, after: usize) -> Self {
        Self {
            beyond: std::vec![Some(0); n],
            after,
        }
    }

    /// Whether candidate `i` is still standing.
    pub(crate) fn live(&self, i: usize) -> bool {
        self.beyond.get(i).is_some_and(Option::is_some)
    }

    /// Rule candidate `i` out for good, whatever its fit ([`super::twins`]).
    pub(crate) fn rule_out(&mut self, i: usize) {
        if let Some(b) = self.beyond.get_mut(i) {
            *b = None;
        }
    }

    /// Count a row block, given each candidate's `(residual variance, residual degrees of
    /// freedom)` (those of ruled-out ones are ignored).
    pub(crate) fn update(&mut self, fits: impl Iterator<Item = (f64, f64)> + Clone) {
        let (mut v_min, mut dof) = (f64::INFINITY, 0.0);
        for (i, (v, d)) in fits.clone().enumerate() {
            if self.live(i) && v < v_min {
                (v_min, dof) = (v, d);
            }
        }
        if !v_min.is_finite() || !(dof > 0.0) {
            return;
        }
        let limit = v_min * COMPARABLE_FIT.max(1.0 + 3.0 * (2.0 / dof).sqrt());
        for (b, (v, _)) in self.beyond.iter_mut().zip(fits) {
            let Some(n) = b else { continue };
            *n = if v > limit { *n + 1 } else { 0 };
            if *n >= self.after {
                *b = None;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_candidate_beyond_the_limit_throughout_is_ruled_out() {
        let mut s = Standing::new(3, RULE_OUT_AFTER);
        for k in 0..RULE_OUT_AFTER {
            // Candidate 1 dips back within the limit once, half way.
            let v1 = if k == RULE_OUT_AFTER / 2 { 1.5 } else { 3.0 };
            s.update([(1.0, 1e4), (v1, 1e4), (2.5, 1e4)].into_iter());
            assert_eq!(s.live(2), k + 1 < RULE_OUT_AFTER);
        }
        assert!(s.live(0) && s.live(1));
        // A ruled-out candidate stays out, however well it fits; the best one is never
        // beyond its own limit.
        for _ in 0..RULE_OUT_AFTER {
            s.update([(1.0, 1e4), (3.0, 1e4), (0.1, 1e4)].into_iter());
        }
        assert!(s.live(0) && !s.live(1) && !s.live(2));
    }
}
