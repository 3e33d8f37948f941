//! Which candidate answers: the best fit ([`choose`]), unless the same rows in longer chains
//! are clearly steadier ([`steadier`]); [`pick`] combines the two, and the chains still in
//! the running are the alternatives for the model spread and the cross-check
//! ([`in_running`], [`alternatives_from_s`]).

use super::sigma::frobenius;
use crate::estimator::momentum_rows::MomentumRowSettings;

/// How many times smaller a longer chain's jackknife σ must be than that of the chain
/// [`choose`] picked for it to take its place ([`steadier`]): the
/// jackknife σ of 8 groups has a relative standard error of about 0.27, so this is about
/// two of them.
pub(super) const STEADIER: f64 = 1.5;

/// The candidate to solve, from `(residual variance, residual degrees of freedom, chain
/// length)` per candidate: of those whose residual variance is within `1 + 3√(2/ν)` of
/// the smallest (`ν` its degrees of freedom: the data cannot tell them apart), the one
/// with the longest chains (more of the momentum's history ties `j` down), then the
/// smallest variance. Chains that a drifting attitude or a varying torque would spoil
/// fit worse, and lose. `0` when no variance is finite.
pub(super) fn choose(
    candidates: impl Iterator<Item = (f64, f64, Option<f64>)> + Clone,
    from_s: f64,
) -> usize {
    let length = |c: Option<f64>| c.unwrap_or(f64::INFINITY);
    let candidates = candidates.map(|(v, d, c)| {
        if length(c) >= from_s {
            (v, d, c)
        } else {
            (f64::INFINITY, d, c)
        }
    });
    let (mut v_min, mut dof) = (f64::INFINITY, 0.0);
    for (v, d, _) in candidates.clone() {
        if v < v_min {
            (v_min, dof) = (v, d);
        }
    }
    if !v_min.is_finite() || !(dof > 0.0) {
        return 0;
    }
    let limit = v_min * (1.0 + 3.0 * (2.0 / dof).sqrt());
    let mut out: Option<(usize, f64, f64)> = None;
    for (i, (v, _, chain)) in candidates.enumerate() {
        if !(v <= limit) {
            continue;
        }
        let better = match out {
            None => true,
            Some((_, l, vb)) => length(chain) > l || (length(chain) == l && v < vb),
        };
        if better {
            out = Some((i, length(chain), v));
        }
    }
    out.map_or(0, |o| o.0)
}

/// The candidate to use and the shortest chain still in the running: [`choose`]'s pick
/// by fit, unless [`steadier`] finds the same rows in longer chains clearly steadier;
/// then [`choose`]'s pick among the chains at least that long (where the data cannot
/// tell a longer chain, or the whole record, from it, the longer one), and the shorter
/// chains are out of the running (not alternatives for the model spread or the
/// cross-check either). `fits` as for [`choose`]; `jackknife(i)`, candidate `i`'s
/// jackknife σ (`None`: none, or ruled out).
pub(super) fn pick(
    fits: &[(f64, f64, Option<f64>)],
    rows: &[MomentumRowSettings],
    mut jackknife: impl FnMut(usize) -> Option<[f64; 6]>,
) -> (usize, f64) {
    let fitted = choose(fits.iter().copied(), 0.0);
    let steady = steadier(fitted, rows, &mut jackknife);
    if steady == fitted {
        return (fitted, 0.0);
    }
    let from_s = rows
        .get(steady)
        .and_then(|r| r.max_chain_s)
        .unwrap_or(f64::INFINITY);
    (choose(fits.iter().copied(), from_s), from_s)
}

/// Whether a candidate with these rows is still in the running ([`pick`]).
pub(super) fn in_running(rows: &MomentumRowSettings, from_s: f64) -> bool {
    rows.max_chain_s.unwrap_or(f64::INFINITY) >= from_s
}

/// The shortest chain that is an alternative to the chosen candidate for the model spread
/// and the cross-check: in the running ([`pick`]), and no shorter than `--chain` (`chain_s`)
/// unless the chosen one is. The shortest chains (`--chain`/[`super::candidates::SHORT_CHAIN_DIVISOR`]) are
/// there for drifts that only they remove; where they are not chosen, the scatter of their
/// answers, with four times the initial momenta, is their noise, not a model
/// uncertainty of the chosen answer.
pub(super) fn alternatives_from_s(
    chosen: &MomentumRowSettings,
    from_s: f64,
    chain_s: Option<f64>,
) -> f64 {
    let length = chosen.max_chain_s.unwrap_or(f64::INFINITY);
    from_s.max(length.min(chain_s.unwrap_or(0.0)))
}

/// The candidate to use instead of `fitted`: one with the same rows in longer chains
/// whose jackknife σ is [`STEADIER`] times smaller, the smallest such. Shorter chains fit
/// better wherever the rows' errors drift (the fit test sees the drift), but each chain's
/// initial momenta cost information: where the scatter of the answer across chains,
/// which includes the drift's effect on it, is clearly smaller for longer chains, the
/// drift costs less than the extra unknowns. `fitted` itself when it is the whole record
/// or has no jackknife σ.
pub(super) fn steadier(
    fitted: usize,
    rows: &[MomentumRowSettings],
    jackknife: &mut impl FnMut(usize) -> Option<[f64; 6]>,
) -> usize {
    let Some(r0) = rows.get(fitted) else {
        return fitted;
    };
    let Some(length) = r0.max_chain_s else {
        return fitted;
    };
    let Some(s0) = jackknife(fitted) else {
        return fitted;
    };
    let mut best = (fitted, frobenius(&s0) / STEADIER);
    for (i, r) in rows.iter().enumerate() {
        let longer = r.max_chain_s.is_some_and(|l| l > length);
        if !longer || r.rows_only() != r0.rows_only() {
            continue;
        }
        if let Some(s) = jackknife(i) {
            let s = frobenius(&s);
            if s < best.1 {
                best = (i, s);
            }
        }
    }
    best.0
}

/// The 1 − 10⁻³ quantile of χ² with `k` degrees of freedom (Wilson–Hilferty: 1.8 % above
/// the exact quantile at `k = 3`, 1.0 % at `k = 6`, less beyond).
pub(crate) fn chi2_quantile_999(k: f64) -> f64 {
    const Z: f64 = 3.090_232;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + Z * a.sqrt()).powi(3)
}

/// Whether the data need the inertial torque, from the fits `(residual sum of squares,
/// residual degrees of freedom)` of the same rows without and with it: the nested test
/// `Δρ²/s² > max(χ²_k(1 − 10⁻³), k ln n)`, `s²` the variance with it, `k` its unknowns
/// (the difference of the degrees of freedom) and `n` the rows (the residual degrees of
/// freedom with it plus `k`): a significant gain that also pays the Bayesian information
/// criterion's price per unknown. On long records an unmodelled random disturbance makes
/// the inertial momentum a random walk whose trend the χ² quantile alone finds
/// significant (the matrix: `auto` worse than `off` in 25 of 58 cells with the quantile
/// alone, 16 with both). Errors correlated along the rows make `s²` too small and the
/// statistic too large, which errs toward the torque (a wider σ, not a bias). No test
/// (not a finite statistic, or no unknowns between them): not needed.
pub(super) fn needs_inertial_torque(without: (f64, f64), with: (f64, f64)) -> bool {
    let k = without.1 - with.1;
    let s2 = with.0 / with.1;
    let chi2 = (without.0 - with.0) / s2;
    if !(k >= 1.0 && s2.is_finite() && s2 > 0.0 && chi2.is_finite()) {
        return false;
    }
    chi2 > chi2_quantile_999(k).max(k * libm::log(with.1 + k))
}

/// Of each pair of candidates in `fits` (as for [`choose`]) that differ only in the
/// inertial torque and are both standing, the one [`needs_inertial_torque`] rejects is out
/// of this choice (its variance infinite).
pub(super) fn test_inertial_torque(
    fits: &mut [(f64, f64, Option<f64>)],
    rows: &[MomentumRowSettings],
) {
    for (w, rw) in rows.iter().enumerate().filter(|(_, r)| r.inertial_torque) {
        let twin = MomentumRowSettings {
            inertial_torque: false,
            ..*rw
        };
        let Some(o) = rows.iter().position(|r| *r == twin) else {
            continue;
        };
        let ((vo, dof_o, _), (vw, dof_w, _)) = (fits[o], fits[w]);
        if !(vo.is_finite() && vw.is_finite()) {
            continue;
        }
        let loser = if needs_inertial_torque((vo * dof_o, dof_o), (vw * dof_w, dof_w)) {
            o
        } else {
            w
        };
        fits[loser].0 = f64::INFINITY;
    }
}

/// Whether candidate `i`'s rows are the `chosen` one's twin with the inertial torque, which
/// [`test_inertial_torque`] rejected: an alternative for the model spread all the same
/// ([`super::sigma::model_spread`]). The test holds the torque at zero unless the data
/// need it beyond `max(χ²_k(1 − 10⁻³), k ln n)`; below that line a real torque is not
/// ruled out, only not confirmed, and the answer is uncertain by the move of `ĵ` it
/// makes (on throws each tumbling its own way with the wheel speeds' time tag
/// estimated, 4 of 59 determined answers beyond 3σ with the move left out, 0 with the
/// torque always estimated).
pub(super) fn rejected_inertial_twin(
    chosen: &MomentumRowSettings,
    i: &MomentumRowSettings,
) -> bool {
    !chosen.inertial_torque
        && i.inertial_torque
        && MomentumRowSettings {
            inertial_torque: false,
            ..*i
        } == *chosen
}

impl super::DiscreteMomentum {
    /// Choose the candidate to solve ([`pick`]) and the alternatives to it
    /// ([`alternatives_from_s`]).
    pub(super) fn pick_candidate(&mut self) {
        self.fits.clear();
        for (i, c) in self.candidates.iter().enumerate() {
            self.fits.push(self.fit(i, c));
        }
        test_inertial_torque(&mut self.fits, &self.rows);
        let (candidates, standing) = (&mut self.candidates, &self.standing);
        let (chosen, from_s) = pick(&self.fits, &self.rows, |i| {
            candidates
                .get_mut(i)
                .filter(|_| standing.live(i))
                .and_then(|c| c.jackknife_sigma())
        });
        self.chosen = chosen;
        self.from_s = self.rows.get(chosen).map_or(from_s, |r| {
            alternatives_from_s(r, from_s, self.config.max_chain_s)
        });
    }

    /// Per candidate `(residual variance, residual degrees of freedom, chain length)` for
    /// [`choose`], a ruled-out one's variance infinite.
    pub(super) fn fit(
        &self,
        i: usize,
        c: &super::candidates::Candidate,
    ) -> (f64, f64, Option<f64>) {
        let v = if self.standing.live(i) {
            c.qr().residual_variance()
        } else {
            f64::INFINITY
        };
        (v, c.qr().residual_dof(), c.row_settings().max_chain_s)
    }
}
