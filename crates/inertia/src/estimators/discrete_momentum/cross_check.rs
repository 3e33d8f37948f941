//! The cross-check of the candidates' own answers: where another candidate's answer (another
//! rotation source, another chain length) differs from the chosen one's by more than
//! [`DISAGREE_Z`] noise σ, the data are inconsistent, the difference joins the bias part
//! of σ, and an answer whose σ is then too large is withdrawn ([`reconcile`]).

use super::select::in_running;
use super::sigma::{candidate_noise_sigma, Eigen};
use super::DiscreteMomentum;
use crate::estimator::observability::{Observability, Unobservable};
use crate::estimator::uncertainty::{with_bias_at, Uncertainty};
use crate::estimator::Estimate;
use crate::estimator::EstimatorError;
use crate::tensor::{matrix_from_j, InertiaVector};

/// A candidate's own answer, for the cross-check: `(ĵ, noise σ)` when it was determined
/// at the last refresh, `age` row blocks ago.
#[derive(Clone, Copy)]
pub(super) struct CrossCheck {
    pub(super) answer: Option<(InertiaVector, [f64; 6])>,
    pub(super) age: usize,
    /// The answer was beyond the check's threshold when it was solved: a disagreement
    /// found with a fresh answer.
    pub(super) beyond: bool,
}

/// Row blocks between refreshes of a candidate's own answer for the cross-check, at
/// least; later in a record, a [`CROSS_CHECK_SHARE`]th of the blocks so far (not under
/// forgetting, [`cross_check_every`]).
pub(super) const CROSS_CHECK_EVERY: usize = 50;

/// The cross-check's answers are refreshed once the blocks since the last refresh are
/// this share of the record so far (or [`CROSS_CHECK_EVERY`], whichever is more). An
/// answer from `n` blocks moves by about `σ √(Δn/n)` over `Δn` more (a random walk of
/// the estimate, `σ ∝ 1/√n`), so an answer refreshed every `n/20` blocks is at most about
/// `0.2 σ` old, against the [`DISAGREE_Z`] `= 5 σ` the check looks for; and the refreshes
/// of a record of `N` blocks are `O(log N)`, not `N/50`, each a full solve of a candidate
/// whose warm starts are that old.
pub(super) const CROSS_CHECK_SHARE: usize = 20;

/// Row blocks between refreshes of a determined answer for the cross-check after
/// `blocks` row blocks ([`CROSS_CHECK_SHARE`]): [`CROSS_CHECK_EVERY`] where its age
/// matters, that is where it is `near` the check (it differs from the present answer by
/// more than half the threshold, so that its verdict may flip, and once beyond, its
/// difference joins σ) and under forgetting (the answers rest on the last memory's blocks
/// however long the record). So an answer older than [`CROSS_CHECK_EVERY`] blocks is only
/// used while it is within half the threshold, where it changes neither σ nor the
/// verdict; one that comes near is refreshed at once if it is that old. Nor does an
/// answer that has aged past the threshold tell a disagreement: it is solved again first,
/// and kept while beyond only if it was beyond when solved. (An answer not determined is
/// solved again at every block, so that it joins the check as soon as it is.)
pub(super) fn cross_check_every(blocks: usize, forgetting: bool, near: bool) -> usize {
    if forgetting || near {
        CROSS_CHECK_EVERY
    } else {
        CROSS_CHECK_EVERY.max(blocks / CROSS_CHECK_SHARE)
    }
}

/// `|ĵ_a − ĵ_b| / √(σ_a² + σ_b²)` (noise σ, without the model spread) beyond which two
/// candidates disagree: far in the tail of any honest σ, so that only an inconsistency
/// of the data trips it ([`reconcile`]).
pub(super) const DISAGREE_Z: f64 = 5.0;

/// Reconcile a determined answer with the other candidates' own answers `(ĵ, noise σ)`.
/// Where one differs by more than [`DISAGREE_Z`] noise σ, the data are inconsistent and
/// either answer may be the right one: the difference joins the bias part of σ, so that
/// the stated σ covers both. If σ then exceeds `max_relative_sigma · ‖Ĵ‖_F`, the answer
/// is withdrawn ([`Unobservable::SourcesDisagree`]).
/// `eig` are the eigenpairs of `e`'s `J` ([`crate::eigen3::symmetric_eigen3`]); `slack`, a
/// difference the answers may have for a known reason, joins the answer's noise σ in the
/// comparison (an estimated gyro density compensates the gyro's rows only).
pub(super) fn reconcile(
    e: &mut Estimate,
    eig: &Eigen,
    others: &[(InertiaVector, [f64; 6])],
    max_relative_sigma: f64,
    slack: Option<&[f64; 6]>,
) {
    let (Some(j), Some(u)) = (e.j(), e.uncertainty) else {
        return;
    };
    let (mut bias, mut spread) = (u.bias_kg_m2, u.model_spread_kg_m2);
    let mut worst: f64 = 0.0;
    // The answer's noise σ for the comparison, with a difference the answers may have for
    // a known reason (`slack`) in quadrature.
    let noise: [f64; 6] = match slack {
        Some(s) => core::array::from_fn(|k| libm::hypot(u.noise_kg_m2[k], s[k])),
        None => u.noise_kg_m2,
    };
    for (jb, sigma) in others {
        let Some(z) = disagreement_beyond(&j, &noise, jb, sigma, DISAGREE_Z) else {
            continue;
        };
        worst = worst.max(z);
        for (k, (x, y)) in j.iter().zip(jb.iter()).enumerate() {
            bias[k] = bias[k].max((x - y).abs());
            spread[k] = spread[k].max((x - y).abs());
        }
    }
    if worst == 0.0 {
        return;
    }
    let u = Uncertainty {
        model_spread_kg_m2: spread,
        ..with_bias_at(&u.noise_kg_m2, &bias, eig)
    };
    let relative = u.frobenius_sigma_kg_m2() / matrix_from_j(&j).norm();
    if relative <= max_relative_sigma {
        e.uncertainty = Some(u);
    } else {
        e.observability = Observability::NotObservable(Unobservable::SourcesDisagree { z: worst });
        e.solution = None;
        e.uncertainty = None;
    }
}

/// Only candidates whose residual variance is within this factor of the chosen one's are
/// cross-checked: one that fits much worse (a star tracker's differenced noise against a
/// gyro) is the worse model, not evidence against the chosen one.
pub(super) const COMPARABLE_FIT: f64 = 2.0;

/// Largest `|a − b| / √(σ_a² + σ_b²)` over the elements.
pub(super) fn disagreement(
    a: &InertiaVector,
    sa: &[f64; 6],
    b: &InertiaVector,
    sb: &[f64; 6],
) -> f64 {
    (0..6)
        .map(|k| (a[k] - b[k]).abs() / (sa[k] * sa[k] + sb[k] * sb[k]).sqrt())
        .fold(0.0, f64::max)
}

/// [`disagreement`] where it exceeds `z`, `None` otherwise: the same verdict, but the
/// usual case, every element well inside `z` (at every solve, for each candidate), is
/// told by squares, without a `√` and a division per element. The squares' test lets
/// through everything within a relative `1e-9` of `z`, whose exact value then decides.
pub(super) fn disagreement_beyond(
    a: &InertiaVector,
    sa: &[f64; 6],
    b: &InertiaVector,
    sb: &[f64; 6],
    z: f64,
) -> Option<f64> {
    let near = z * z * (1.0 - 1e-9);
    let candidate = (0..6).any(|k| {
        let d = a[k] - b[k];
        let s2 = sa[k] * sa[k] + sb[k] * sb[k];
        // Squares decide only where neither they nor `near · s2` can underflow or
        // overflow to a wrong verdict (a `|d|` whose square underflows is then within
        // 1e-8 σ); elsewhere, a zero, infinite or NaN variance or difference included,
        // the exact value does.
        !((1e-290..=1e290).contains(&s2) && d * d <= near * s2)
    });
    if !candidate {
        return None;
    }
    Some(disagreement(a, sa, b, sb)).filter(|d| *d > z)
}

impl DiscreteMomentum {
    /// The other candidates' own answers `(ĵ, noise σ)` that a determined answer `e` is
    /// [`reconcile`]d with ([`DISAGREE_Z`]): those still in the running that fit
    /// comparably ([`COMPARABLE_FIT`]); none for an answer without σ or a single
    /// candidate. The answers are refreshed every [`CROSS_CHECK_EVERY`] row blocks, or
    /// every [`CROSS_CHECK_SHARE`]th of the record so far if that is more and there is no
    /// forgetting ([`cross_check_every`]).
    pub(super) fn cross_check(
        &mut self,
        e: &Estimate,
        t_s: f64,
    ) -> Result<&[(InertiaVector, [f64; 6])], EstimatorError> {
        if self.candidates.len() < 2 || !matches!(e.observability, Observability::Determined { .. })
        {
            return Ok(&[]);
        }
        let (Some(j), Some(u)) = (e.j(), e.uncertainty) else {
            return Ok(&[]);
        };
        self.checks.resize(self.candidates.len(), None);
        let best_variance = self
            .candidates
            .get(self.chosen)
            .map_or(f64::INFINITY, |c| c.qr().residual_variance());
        self.others.clear();
        for i in 0..self.candidates.len() {
            let c = &self.candidates[i];
            if i == self.chosen
                || !self.standing.live(i)
                // A model the inertial torque's test rejected (`select::test_inertial_torque`).
                || !self.fits.get(i).is_some_and(|f| f.0.is_finite())
                || !in_running(c.row_settings(), self.from_s)
                || c.qr().rows() < 6
                || !(c.qr().residual_variance() <= COMPARABLE_FIT * best_variance)
            {
                continue;
            }
            // How far the kept answer is from the present one: within reach of the
            // check (`cross_check_every`), or beyond it.
            let z = self.checks[i].and_then(|k| k.answer).and_then(|(jb, sb)| {
                disagreement_beyond(&j, &u.noise_kg_m2, &jb, &sb, DISAGREE_Z / 2.0)
            });
            let beyond = z.is_some_and(|z| z > DISAGREE_Z);
            let forgetting = self.config.memory_s.is_some();
            let stale = self.checks[i].is_none_or(|k| {
                k.answer.is_none()
                    || k.age >= cross_check_every(self.blocks, forgetting, z.is_some())
                    // A disagreement is never told by an answer older than this solve
                    // unless that answer disagreed when it was fresh.
                    || (beyond && !k.beyond && k.age > 0)
            });
            if stale {
                let own = self.candidates[i].solve_now(t_s)?;
                // An answer that is not determined is not compared, and is solved again
                // at the next block.
                let answer = match (
                    own.observability,
                    own.j(),
                    candidate_noise_sigma(&mut self.candidates, i, self.config.max_chain_s),
                ) {
                    (Observability::Determined { .. }, Some(j), Some(sigma)) => Some((j, sigma)),
                    _ => None,
                };
                let beyond = answer.is_some_and(|(jb, sb)| {
                    disagreement_beyond(&j, &u.noise_kg_m2, &jb, &sb, DISAGREE_Z).is_some()
                });
                self.checks[i] = Some(CrossCheck {
                    answer,
                    age: 0,
                    beyond,
                });
            }
            if let Some(answer) = self.checks[i].and_then(|k| k.answer) {
                self.others.push(answer);
            }
        }
        Ok(&self.others)
    }
}
