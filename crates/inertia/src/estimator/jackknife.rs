//! A standard deviation that survives correlated row errors: the delete-a-group
//! jackknife over the chains of the discrete momentum rows (beyond the paper).
//!
//! The least-squares σ of [`super::uncertainty`] assumes independent rows. The momentum
//! rows of one chain share its initial momentum, and two error sources make them
//! correlated along the chain: an unmodelled white disturbance torque integrates into a
//! random walk of the inertial momentum, and a gyro-propagated attitude's random walk
//! rotates the momentum. Measured on the paper's scenarios (truth attitude, 8 seeds), the
//! errors were 10–16 least-squares σ with the attitude's rotation; a gyro-propagated spin,
//! up to 6.
//!
//! Chains are independent of one another to first order: each has its own initial
//! momentum, so a random walk's value at the chain's start is absorbed and only its
//! increments within the chain, independent between chains, remain. Chain `c` (counted
//! from 0, chains without rows skipped) goes to group `c mod` [`GROUPS`]; the estimate
//! without group `g`, `θ₍g₎`, is the unconstrained least-squares `j` of the other groups'
//! rows, and with `G` non-empty groups
//!
//! ```text
//! σ²_jack = (G − 1)/G · Σ_g (θ₍g₎ − θ̄)²,   θ̄ = (1/G) Σ_g θ₍g₎      (per element)
//! ```
//!
//! (Efron & Stein; the grouped form is consistent under correlation within groups). It is
//! computed from completed chains only and scaled by `√(w_done / w_all)` (row weights) to
//! the data that includes the chain in progress; with fewer than [`MIN_GROUPS`] non-empty
//! groups there is none. The noise σ reported is the larger of this and the
//! least-squares σ, element by element. What it cannot see is a bias common to every
//! chain (a wrong model of the wheels between samples, say). With exponential forgetting
//! the groups' weights differ by orders of magnitude and the equal-weight formula does
//! not hold, so the estimator keeps no groups then and the noise σ is the least-squares
//! one.

use super::normal_equations::NormalEquations;
use super::shared_qr::SharedQr;
use crate::constraints::Constraints;
use crate::solver::unconstrained_minimiser;
use crate::tensor::InertiaVector;

/// Number of jackknife groups.
pub const GROUPS: usize = 8;
/// Fewest non-empty groups for a jackknife σ.
pub const MIN_GROUPS: usize = 4;

/// `√((G − 1)/G · Σ (θ₍g₎ − θ̄)²)` per element from the delete-one-group estimates; `None`
/// with fewer than [`MIN_GROUPS`] of them.
#[must_use]
pub fn jackknife_sigma(estimates: &[InertiaVector]) -> Option<[f64; 6]> {
    let g = estimates.len();
    if g < MIN_GROUPS {
        return None;
    }
    let n = g as f64;
    let mean: InertiaVector = estimates.iter().sum::<InertiaVector>() / n;
    Some(core::array::from_fn(|k| {
        let ss: f64 = estimates
            .iter()
            .map(|e| (e[k] - mean[k]) * (e[k] - mean[k]))
            .sum();
        crate::math::sqrt((n - 1.0) / n * ss)
    }))
}

/// The noise σ reported: element by element the larger of the least-squares σ and the
/// jackknife σ (when there is one), kg m².
#[must_use]
pub fn robust_sigma(least_squares: &[f64; 6], jackknife: Option<&[f64; 6]>) -> [f64; 6] {
    // An element the least squares fix exactly (an equality, σ 0) stays fixed.
    core::array::from_fn(|k| match jackknife {
        Some(jk) if least_squares[k] > 0.0 => least_squares[k].max(jk[k]),
        _ => least_squares[k],
    })
}

/// The rows of the chain in progress and of the completed chains, by group: enough to
/// compute the jackknife σ at any time without holding the rows. The chain in progress
/// is kept as normal equations ([`super::normal_equations`]) and factored when it ends.
#[derive(Debug, Clone)]
pub struct ChainGroups {
    chain: NormalEquations,
    groups: [SharedQr; GROUPS],
    chains: usize,
    /// `(chains, σ)` at the last computation.
    cached: Option<(usize, Option<[f64; 6]>)>,
}

impl Default for ChainGroups {
    fn default() -> Self {
        Self {
            chain: NormalEquations::default(),
            groups: [SharedQr::new(0); GROUPS],
            chains: 0,
            cached: None,
        }
    }
}

impl ChainGroups {
    /// The state of the chain in progress, to add its row blocks to along with the
    /// estimator's ([`super::augmented_qr::AugmentedQr::add`]): it holds the rows of the
    /// shared unknowns only, the initial momenta being minimised out already.
    pub fn chain_mut(&mut self) -> &mut NormalEquations {
        &mut self.chain
    }

    /// The chain in progress ended: file its rows in its group. Nothing happens for a
    /// chain without rows.
    pub fn end_chain(&mut self) {
        if self.chain.counts().rows() == 0 {
            return;
        }
        if let Some(g) = self.groups.get_mut(self.chains % GROUPS) {
            g.merge(&self.chain.factor());
        }
        self.chain = NormalEquations::default();
        self.chains += 1;
    }

    /// The jackknife σ per element, kg m², scaled to include the chain in progress
    /// (module docs); `None` with fewer than [`MIN_GROUPS`] groups or a delete-one-group
    /// problem without a unique solution.
    /// Each delete-one-group problem carries the prior knowledge of `constraints`
    /// ([`super::prior::augment`]), as the estimate does.
    pub fn sigma(&mut self, constraints: &Constraints) -> Option<[f64; 6]> {
        if let Some((chains, sigma)) = self.cached {
            if chains == self.chains {
                return sigma.map(|s| self.scaled(s));
            }
        }
        let sigma = self.compute(constraints);
        self.cached = Some((self.chains, sigma));
        sigma.map(|s| self.scaled(s))
    }

    fn scaled(&self, s: [f64; 6]) -> [f64; 6] {
        let done: f64 = self.groups.iter().map(SharedQr::weight).sum();
        let all = done + self.chain.counts().weight();
        let f = if all > 0.0 {
            crate::math::sqrt(done / all)
        } else {
            1.0
        };
        s.map(|v| v * f)
    }

    fn compute(&self, constraints: &Constraints) -> Option<[f64; 6]> {
        let used = self.chains.min(GROUPS);
        let groups = &self.groups[..used];
        // The groups before `g` and after it, merged once each way: each delete-one
        // state is then one merge, not `used − 2`.
        let mut before = [SharedQr::new(0); GROUPS];
        let mut after = [SharedQr::new(0); GROUPS];
        for g in 1..used {
            before[g] = before[g - 1];
            before[g].merge(&groups[g - 1]);
        }
        for g in (0..used.saturating_sub(1)).rev() {
            after[g] = after[g + 1];
            after[g].merge(&groups[g + 1]);
        }
        let mut estimates = [InertiaVector::zeros(); GROUPS];
        for (g, out) in estimates.iter_mut().enumerate().take(used) {
            let mut rest = before[g];
            rest.merge(&after[g]);
            let reduced = super::prior::augment(&rest.reduced(), constraints).0;
            *out = unconstrained_minimiser(&reduced.r, &reduced.z)?;
        }
        estimates.get(..used).and_then(jackknife_sigma)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimator::shared_qr::SHARED;
    use nalgebra::SVector;

    /// The delete-one states from prefix and suffix merges give the σ of merging every
    /// other group directly (the previous way), to 1e-9 relative, for 4 to 11 chains of
    /// random rows in the shared unknowns.
    #[test]
    fn prefix_and_suffix_merges_give_the_direct_jackknife() {
        let mut rnd = crate::testing::uniform(0x2545_f491_4f6c_dd1d);
        let constraints = crate::constraints::ConstraintSet::physical()
            .validate()
            .unwrap();
        let mut groups = ChainGroups::default();
        let mut estimator = SharedQr::new(0);
        for chain in 0..11 {
            for _ in 0..12 {
                let a: [SVector<f64, SHARED>; 3] =
                    core::array::from_fn(|_| SVector::from_fn(|_, _| rnd()));
                let y: [f64; 3] = core::array::from_fn(|_| rnd());
                groups.chain_mut().add(&(a, y), &y, 0.0);
                estimator.add((a, y), &y, 0.0);
            }
            groups.end_chain();
            let used = groups.chains.min(GROUPS);
            let direct: Option<std::vec::Vec<InertiaVector>> = (0..used)
                .map(|g| {
                    let mut rest = SharedQr::new(0);
                    for (h, group) in groups.groups.iter().enumerate().take(used) {
                        if h != g {
                            rest.merge(group);
                        }
                    }
                    let reduced = rest.reduced();
                    unconstrained_minimiser(&reduced.r, &reduced.z)
                })
                .collect();
            let want = direct.as_deref().and_then(jackknife_sigma);
            let got = groups.compute(&constraints);
            assert_eq!(want.is_some(), got.is_some(), "chain {chain}");
            assert_eq!(got.is_some(), chain + 1 >= MIN_GROUPS, "chain {chain}");
            if let (Some(want), Some(got)) = (want, got) {
                for k in 0..6 {
                    assert!(
                        (got[k] - want[k]).abs() <= 1e-9 * want[k],
                        "chain {chain}, element {k}: {} against {}",
                        got[k],
                        want[k]
                    );
                }
            }
        }
    }
}
