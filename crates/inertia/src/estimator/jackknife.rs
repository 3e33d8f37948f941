//! A standard deviation that survives correlated row errors: the delete-a-group
//! jackknife over the chains of the discrete momentum rows, or over time blocks of them
//! in a record of few chains (beyond the paper).
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
//! chain (a wrong model of the wheels between samples, say).
//!
//! **A chain that holds a direction alone.** The delete-one answer's deviation is
//! `θ₍g₎ − θ̂ = −A₍g₎⁻¹ s_g` (`s_g` the group's score at `θ̂`, `A₍g₎` the other groups'
//! information): where one group holds nearly all the information along some direction
//! (a single chain that excites it, as in the small satellite's first minutes), `A₍g₎`
//! is nearly singular there and the deviation is the other groups' noise amplified
//! without bound: on the first 300 s of the small satellite (four chains) the grouped
//! jackknife put σ at 28 % of J where the batch run's is 0.3 % and the error 0.05 %.
//! With chains as groups each deviation is therefore capped ([`cap_leverage`]): with
//! `M_g = A^{-1/2} A₍g₎ A^{-1/2}` (eigenvalues `μ_i` in `(0, 1]`, `1 − μ_i` the group's
//! share of the information along `v_i`), the deviation's component along each `v_i`
//! with `μ_i < 1 − ` [`MAX_LEVERAGE`] is scaled by `μ_i/(1 − MAX_LEVERAGE)`: the
//! deviation the same score would make if the other groups held 3 % of the information
//! there (an amplification of 33 at most). A group below that share everywhere is left
//! exactly as it was. The cap is set high on purpose: a cap at 50 % or 90 % took the
//! 3σ coverage of the spin with an MEKF attitude (`examples/matrix.rs`) from 0.94 to
//! 0.72 and 0.80, where chains of the spin do carry most of a direction and the
//! amplified scatter is the honest one; at 97 % every matrix cell keeps its coverage.
//!
//! **Records of few chains.** A record shorter than four chains (a short test such as a
//! thrown device, or the first minutes of a long one) has no chain groups; its groups are
//! then contiguous time blocks of its rows ([`BLOCK_ROWS`] row blocks at first, twice as
//! long each time there are `2·`[`GROUPS`] of them, their neighbours merged in pairs, so
//! that there are always between [`GROUPS`] and `2·GROUPS` blocks of a length that grows
//! with the record: about a sixteenth to an eighth of it). A block ends at a chain's end
//! too. Within a chain the rows are the whitened innovations of its initial momenta
//! ([`super::augmented_qr`]), uncorrelated under the model and summing to the chain's
//! information, so deleting a block's deletes its share of the information; errors
//! correlated over less than a block (vibration, noise bursts, a drift over a fraction of
//! the record) stay within it and widen the spread of the delete-one answers. This is
//! not deleting the block's data: the running means keep some of it in the later
//! innovations. The batch path deletes the raw rows of the same blocks
//! ([`time_blocks`]) and refits the initial momenta; on simulated throws the recursive
//! σ was 0.87–3.5 times the batch one (median 1.2). Once there are four completed
//! chains, the chains are the groups, as above. With exponential forgetting
//! the groups' weights differ by orders of magnitude and the equal-weight formula does
//! not hold, so the estimator keeps no groups then and the noise σ is the least-squares
//! one.

use super::normal_equations::NormalEquations;
use super::shared_qr::SharedQr;
use crate::constraints::Constraints;
use crate::solver::unconstrained_minimiser;
use crate::tensor::InertiaVector;
use nalgebra::{Matrix6, SymmetricEigen};

/// Number of jackknife groups.
pub(crate) const GROUPS: usize = 8;
/// Fewest non-empty groups for a jackknife σ.
pub(crate) const MIN_GROUPS: usize = 4;
/// Row blocks in a time block at first (module docs, "Records of few chains").
pub(crate) const BLOCK_ROWS: usize = 16;

/// `√((G − 1)/G · Σ (θ₍g₎ − θ̄)²)` per element from the delete-one-group estimates; `None`
/// with fewer than [`MIN_GROUPS`] of them.
#[must_use]
pub(crate) fn jackknife_sigma(estimates: &[InertiaVector]) -> Option<[f64; 6]> {
    let mut out = [0.0; 6];
    jackknife_sigma_by(estimates.len(), |g, k| estimates[g][k], &mut out).then_some(out)
}

/// [`jackknife_sigma`] of `groups` estimates of `out.len()` values each (`value(g, k)` the
/// `k`-th of estimate `g`), into `out`; false (and `out` as it was) with fewer than
/// [`MIN_GROUPS`] of them.
pub(crate) fn jackknife_sigma_by(
    groups: usize,
    value: impl Fn(usize, usize) -> f64,
    out: &mut [f64],
) -> bool {
    if groups < MIN_GROUPS {
        return false;
    }
    let n = groups as f64;
    for (k, o) in out.iter_mut().enumerate() {
        let mean = (0..groups).map(|g| value(g, k)).sum::<f64>() / n;
        let ss: f64 = (0..groups)
            .map(|g| (value(g, k) - mean) * (value(g, k) - mean))
            .sum();
        *o = crate::math::sqrt((n - 1.0) / n * ss);
    }
    true
}

/// The noise σ reported: element by element the larger of the least-squares σ and the
/// jackknife σ (when there is one), kg m².
#[must_use]
pub(crate) fn robust_sigma(least_squares: &[f64; 6], jackknife: Option<&[f64; 6]>) -> [f64; 6] {
    // An element the least squares fix exactly (an equality, σ 0) stays fixed.
    core::array::from_fn(|k| match jackknife {
        Some(jk) if least_squares[k] > 0.0 => least_squares[k].max(jk[k]),
        _ => least_squares[k],
    })
}

/// The rows of the chain in progress and of the completed chains, by group, and the
/// same rows in time blocks: enough to compute the jackknife σ at any time without
/// holding the rows. The block in progress is kept as normal equations
/// ([`super::normal_equations`]) and factored when it ends.
#[derive(Debug, Clone)]
pub(crate) struct ChainGroups {
    /// The time block in progress.
    block: NormalEquations,
    /// The chain in progress's completed blocks.
    chain: SharedQr,
    groups: [SharedQr; GROUPS],
    chains: usize,
    /// The completed time blocks, oldest first, and how many there are.
    blocks: [SharedQr; 2 * GROUPS],
    closed: usize,
    /// Row blocks in a time block now.
    block_rows: usize,
    /// Row blocks folded into the block in progress.
    in_block: usize,
    /// `(chains, blocks closed so far in all, σ)` at the last computation.
    cached: Option<(usize, usize, Option<[f64; 6]>)>,
    /// Blocks closed so far in all (the cache's key).
    blocks_ever: usize,
}

impl Default for ChainGroups {
    fn default() -> Self {
        Self {
            block: NormalEquations::default(),
            chain: SharedQr::new(0),
            groups: [SharedQr::new(0); GROUPS],
            chains: 0,
            blocks: [SharedQr::new(0); 2 * GROUPS],
            closed: 0,
            block_rows: BLOCK_ROWS,
            in_block: 0,
            cached: None,
            blocks_ever: 0,
        }
    }
}

impl ChainGroups {
    /// The state to add the next row block to along with the estimator's
    /// ([`super::augmented_qr::AugmentedQr::add`]): it holds the rows of the shared
    /// unknowns only, the initial momenta being minimised out already. Call once per row
    /// block: a full time block is closed first.
    pub(crate) fn chain_mut(&mut self) -> &mut NormalEquations {
        if self.in_block >= self.block_rows {
            self.close_block();
        }
        self.in_block += 1;
        &mut self.block
    }

    /// File the block in progress (if it has rows) with the chain's and in the time
    /// blocks; once there are `2·GROUPS`, neighbours are merged in pairs and the blocks
    /// after them are twice as long.
    fn close_block(&mut self) {
        self.in_block = 0;
        if self.block.counts().rows() == 0 {
            return;
        }
        let b = self.block.factor();
        self.block = NormalEquations::default();
        self.chain.merge(&b);
        self.blocks[self.closed] = b;
        self.closed += 1;
        self.blocks_ever += 1;
        if self.closed == self.blocks.len() {
            for i in 0..GROUPS {
                let mut pair = self.blocks[2 * i];
                pair.merge(&self.blocks[2 * i + 1]);
                self.blocks[i] = pair;
            }
            self.closed = GROUPS;
            self.block_rows *= 2;
        }
    }

    /// The chain in progress ended: its last block closes, and its rows are filed in its
    /// group. Nothing happens for a chain without rows.
    pub(crate) fn end_chain(&mut self) {
        self.close_block();
        if self.chain.rows() == 0 {
            return;
        }
        if let Some(g) = self.groups.get_mut(self.chains % GROUPS) {
            g.merge(&self.chain);
        }
        self.chain = SharedQr::new(0);
        self.chains += 1;
    }

    /// The jackknife σ per element, kg m², scaled to include the chain in progress
    /// (module docs); `None` with fewer than [`MIN_GROUPS`] groups or a delete-one-group
    /// problem without a unique solution.
    /// Each delete-one-group problem carries the prior knowledge of `constraints`
    /// ([`super::prior::augment`]), as the estimate does.
    pub(crate) fn sigma(&mut self, constraints: &Constraints) -> Option<[f64; 6]> {
        // The chains' groups change only when a chain ends; the time blocks, when a block
        // closes.
        let key = (
            self.chains,
            if self.by_chain() { 0 } else { self.blocks_ever },
        );
        if let Some((chains, blocks, sigma)) = self.cached {
            if (chains, blocks) == key {
                return sigma.map(|s| self.scaled(s));
            }
        }
        let sigma = self.compute(constraints);
        self.cached = Some((key.0, key.1, sigma));
        sigma.map(|s| self.scaled(s))
    }

    /// Whether the groups are the chains (else the time blocks).
    fn by_chain(&self) -> bool {
        self.chains >= MIN_GROUPS
    }

    /// The jackknife σ of the shared unknown in `column` (the damping's, N m s): each
    /// delete-one-group state's value at its own answer, scaled as [`Self::sigma`]'s; not
    /// cached (asked for once per solve, with that unknown estimated).
    #[must_use]
    pub(crate) fn nuisance_sigma(&self, constraints: &Constraints, column: usize) -> Option<f64> {
        let groups = if self.by_chain() {
            &self.groups[..self.chains.min(GROUPS)]
        } else {
            &self.blocks[..self.closed]
        };
        let mut values = [0.0; 2 * GROUPS];
        let used = delete_one(groups, constraints, |rest, _, j, g| {
            values[g] = rest.leading_at(j)[column];
        })?;
        let one = |v: f64| InertiaVector::from_element(v);
        let estimates: [InertiaVector; 2 * GROUPS] = core::array::from_fn(|g| one(values[g]));
        let s = jackknife_sigma(&estimates[..used])?[0];
        Some(self.scaled([s; 6])[0])
    }

    fn scaled(&self, s: [f64; 6]) -> [f64; 6] {
        let pending = self.block.counts().weight();
        let (done, all) = if self.by_chain() {
            let done: f64 = self.groups.iter().map(SharedQr::weight).sum();
            (done, done + self.chain.weight() + pending)
        } else {
            let done: f64 = self.blocks[..self.closed]
                .iter()
                .map(SharedQr::weight)
                .sum();
            (done, done + pending)
        };
        let f = if all > 0.0 {
            crate::math::sqrt(done / all)
        } else {
            1.0
        };
        s.map(|v| v * f)
    }

    fn compute(&self, constraints: &Constraints) -> Option<[f64; 6]> {
        let groups = if self.by_chain() {
            &self.groups[..self.chains.min(GROUPS)]
        } else {
            &self.blocks[..self.closed]
        };
        delete_one_sigma(groups, constraints, self.by_chain())
    }
}

/// The jackknife σ of the delete-one-group answers of `groups` (module docs), each
/// delete-one problem with the prior knowledge of `constraints`; with `capped` (the
/// groups are chains) each answer's deviation is capped for its group's leverage
/// ([`cap_leverage`]).
fn delete_one_sigma(
    groups: &[SharedQr],
    constraints: &Constraints,
    capped: bool,
) -> Option<[f64; 6]> {
    let mut estimates = [InertiaVector::zeros(); 2 * GROUPS];
    let mut rest_information = [Matrix6::zeros(); 2 * GROUPS];
    let used = delete_one(groups, constraints, |_, reduced, j, g| {
        estimates[g] = *j;
        rest_information[g] = reduced.r.transpose() * reduced.r;
    })?;
    if capped {
        let mut all = SharedQr::new(0);
        for g in groups {
            all.merge(g);
        }
        let reduced = super::prior::augment(&all.reduced(), constraints).0;
        if let Some(full) = unconstrained_minimiser(&reduced.r, &reduced.z) {
            let information = reduced.r.transpose() * reduced.r;
            cap_leverage(
                &information,
                &full,
                &rest_information[..used],
                &mut estimates[..used],
            );
        }
    }
    estimates.get(..used).and_then(jackknife_sigma)
}

/// The largest share of the information along any direction for which a group's
/// delete-one deviation is taken as it is (module docs, "A chain that holds a
/// direction alone").
pub(crate) const MAX_LEVERAGE: f64 = 0.97;

/// Cap each delete-one answer's deviation from the all-groups answer `full`,
/// `d_g = θ₍g₎ − θ̂ = −A₍g₎⁻¹ s_g` (`s_g` the group's score at `θ̂`, `A₍g₎` the other groups'
/// information `rest[g]`, `A` = `information` all groups'), along the directions where
/// the deleted group held more than [`MAX_LEVERAGE`] of the information: with
/// `M_g = A^{-1/2} A₍g₎ A^{-1/2} = Σ μ_i v_i v_iᵀ`, `d_g ← A^{-1/2} (Σ min(1, μ_i/(1 −
/// MAX_LEVERAGE)) v_i v_iᵀ) A^{1/2} d_g`, the deviation the group's score would make if
/// the others held `1 − MAX_LEVERAGE` of the information there. A group below the cap everywhere keeps
/// its answer exactly; nothing changes where `A` is not positive definite or an
/// eigen-decomposition does not converge.
fn cap_leverage(
    information: &Matrix6<f64>,
    full: &InertiaVector,
    rest: &[Matrix6<f64>],
    estimates: &mut [InertiaVector],
) {
    let eigen = |m: Matrix6<f64>| {
        SymmetricEigen::try_new(
            (m + m.transpose()) * 0.5,
            f64::EPSILON,
            crate::math::MAX_DECOMPOSITION_ITERATIONS,
        )
    };
    let Some(a) = eigen(*information) else {
        return;
    };
    if !(a.eigenvalues.min() > 0.0) {
        return;
    }
    let of_eigenvalues = |f: fn(f64) -> f64| {
        a.eigenvectors * Matrix6::from_diagonal(&a.eigenvalues.map(f)) * a.eigenvectors.transpose()
    };
    let half = of_eigenvalues(crate::math::sqrt);
    let inverse_half = of_eigenvalues(|l| 1.0 / crate::math::sqrt(l));
    let floor = 1.0 - MAX_LEVERAGE;
    for (e, r) in estimates.iter_mut().zip(rest) {
        let Some(m) = eigen(inverse_half * r * inverse_half) else {
            continue;
        };
        if m.eigenvalues.min() >= floor {
            continue;
        }
        let shrink = m.eigenvalues.map(|mu| (mu.max(0.0) / floor).min(1.0));
        let t = inverse_half
            * m.eigenvectors
            * Matrix6::from_diagonal(&shrink)
            * m.eigenvectors.transpose()
            * half;
        let capped = full + t * (*e - full);
        if capped.iter().all(|x| x.is_finite()) {
            *e = capped;
        }
    }
}

/// Each delete-one-group problem of `groups` (with the prior knowledge of `constraints`)
/// and its unconstrained answer, handed to `each` with the group's index; the number of
/// groups, or `None` where a problem has no unique answer.
fn delete_one(
    groups: &[SharedQr],
    constraints: &Constraints,
    mut each: impl FnMut(&SharedQr, &super::qr::RecursiveQr, &InertiaVector, usize),
) -> Option<usize> {
    let used = groups.len();
    // The groups before `g` and after it, merged once each way: each delete-one
    // state is then one merge, not `used − 2`.
    let mut before = [SharedQr::new(0); 2 * GROUPS];
    let mut after = [SharedQr::new(0); 2 * GROUPS];
    for g in 1..used {
        before[g] = before[g - 1];
        before[g].merge(&groups[g - 1]);
    }
    for g in (0..used.saturating_sub(1)).rev() {
        after[g] = after[g + 1];
        after[g].merge(&groups[g + 1]);
    }
    for g in 0..used {
        let mut rest = before[g];
        rest.merge(&after[g]);
        let reduced = super::prior::augment(&rest.reduced(), constraints).0;
        each(
            &rest,
            &reduced,
            &unconstrained_minimiser(&reduced.r, &reduced.z)?,
            g,
        );
    }
    Some(used)
}

/// The time block of each row block of chains of the given lengths (in row blocks), as
/// [`ChainGroups`] files them when every chain but the last has ended: `Some(block)` for
/// a closed block, `None` for the last chain's block in progress (which the jackknife
/// leaves in every delete-one problem and scales to).
#[cfg(feature = "std")]
pub(crate) fn time_blocks(chains: &[usize]) -> std::vec::Vec<std::vec::Vec<Option<usize>>> {
    use std::vec::Vec;
    let mut ids: Vec<Vec<Option<usize>>> = Vec::new();
    let (mut closed, mut length, mut in_block) = (0usize, BLOCK_ROWS, 0usize);
    let close = |ids: &mut Vec<Vec<Option<usize>>>, closed: &mut usize, length: &mut usize| {
        *closed += 1;
        if *closed == 2 * GROUPS {
            for id in ids.iter_mut().flatten().flatten() {
                *id /= 2;
            }
            (*closed, *length) = (GROUPS, 2 * *length);
        }
    };
    for (c, &n) in chains.iter().enumerate() {
        ids.push(Vec::with_capacity(n));
        for _ in 0..n {
            if in_block >= length {
                close(&mut ids, &mut closed, &mut length);
                in_block = 0;
            }
            let id = closed;
            if let Some(chain) = ids.last_mut() {
                chain.push(Some(id));
            }
            in_block += 1;
        }
        if c + 1 < chains.len() && in_block > 0 {
            close(&mut ids, &mut closed, &mut length);
            in_block = 0;
        }
    }
    // The block in progress.
    let last = ids.iter().flatten().flatten().copied().max();
    if in_block > 0 {
        if let (Some(chain), Some(open)) = (ids.last_mut(), last) {
            for id in chain.iter_mut().rev().take(in_block) {
                debug_assert_eq!(*id, Some(open));
                *id = None;
            }
        }
    }
    ids
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

    /// Problem: one chain of 1,000 random row blocks, whose groups are time blocks.
    /// Reference: the blocks' definition and the direct delete-one answers. Once there
    /// are `GROUPS` blocks there stay between `GROUPS` and `2·GROUPS`, every closed one as
    /// long as the blocks now (`BLOCK_ROWS · 2^k` row blocks); the closed blocks and the one in progress hold
    /// the whole chain's information (R of their merge against R of all rows, 1e-9); the
    /// σ is the direct delete-one-block jackknife of the closed blocks, scaled by
    /// `√(w_closed / w_all)`, to 1e-9.
    #[test]
    fn a_single_chain_is_grouped_in_time_blocks() {
        let mut rnd = crate::testing::uniform(0x9e37_79b9_7f4a_7c15);
        let constraints = crate::constraints::ConstraintSet::physical()
            .validate()
            .unwrap();
        let mut groups = ChainGroups::default();
        let mut all = SharedQr::new(0);
        for n in 1..=1000 {
            let a: [SVector<f64, SHARED>; 3] =
                core::array::from_fn(|_| SVector::from_fn(|_, _| rnd()));
            let y: [f64; 3] = core::array::from_fn(|_| rnd());
            groups.chain_mut().add(&(a, y), &y, 0.0);
            all.add((a, y), &y, 0.0);
            let length = groups.block_rows;
            assert!(length.is_power_of_two() && length >= BLOCK_ROWS);
            assert!(groups.closed <= 2 * GROUPS, "row block {n}");
            if n > BLOCK_ROWS * GROUPS {
                assert!(groups.closed >= GROUPS, "row block {n}");
            }
            assert_eq!(groups.chains, 0);
            // Every closed block is as long as the blocks now.
            for b in &groups.blocks[..groups.closed] {
                assert_eq!(b.rows(), 3 * length, "row block {n}");
            }
        }
        let mut merged = SharedQr::new(0);
        for b in &groups.blocks[..groups.closed] {
            merged.merge(b);
        }
        merged.merge(&groups.block.factor());
        let (r1, r2) = (merged.reduced().r, all.reduced().r);
        let gram = |r: &nalgebra::Matrix6<f64>| r.transpose() * r;
        assert!((gram(&r1) - gram(&r2)).norm() <= 1e-9 * gram(&r2).norm());
        let direct: std::vec::Vec<InertiaVector> = (0..groups.closed)
            .map(|g| {
                let mut rest = SharedQr::new(0);
                for (h, b) in groups.blocks[..groups.closed].iter().enumerate() {
                    if h != g {
                        rest.merge(b);
                    }
                }
                let reduced = rest.reduced();
                unconstrained_minimiser(&reduced.r, &reduced.z).expect("regular")
            })
            .collect();
        let done: f64 = groups.blocks[..groups.closed]
            .iter()
            .map(SharedQr::weight)
            .sum();
        let f = crate::math::sqrt(done / (done + groups.block.counts().weight()));
        let want = jackknife_sigma(&direct).expect("groups");
        let got = groups.sigma(&constraints).expect("σ");
        for k in 0..6 {
            assert!(
                (got[k] - want[k] * f).abs() <= 1e-9 * want[k],
                "element {k}"
            );
        }
    }

    /// Problem: chains of 7, 300, 1, 45 and 530 row blocks. Reference: [`ChainGroups`]
    /// fed them (every chain ended but the last). [`time_blocks`] gives the same closed
    /// blocks, in order (rows per block), and the same block in progress.
    #[test]
    fn the_batch_time_blocks_are_the_recursive_ones() {
        let lengths = [7usize, 300, 1, 45, 530];
        let mut groups = ChainGroups::default();
        for (c, &n) in lengths.iter().enumerate() {
            for _ in 0..n {
                let a = [SVector::<f64, SHARED>::zeros(); 3];
                groups.chain_mut().add(&(a, [0.0; 3]), &[0.0; 3], 0.0);
            }
            if c + 1 < lengths.len() {
                groups.end_chain();
            }
        }
        let ids = time_blocks(&lengths);
        let want: std::vec::Vec<usize> = groups.blocks[..groups.closed]
            .iter()
            .map(|b| b.rows() / 3)
            .collect();
        let got: std::vec::Vec<usize> = (0..want.len())
            .map(|g| ids.iter().flatten().filter(|&&id| id == Some(g)).count())
            .collect();
        assert_eq!(got, want);
        assert!(ids.iter().flatten().flatten().all(|&id| id < want.len()));
        let pending = ids.iter().flatten().filter(|id| id.is_none()).count();
        assert_eq!(pending, groups.block.counts().rows() / 3);
    }

    #[test]
    fn the_leverage_cap_leaves_even_groups_alone_and_shrinks_a_held_direction() {
        // A full information with unequal scales, and four groups that each hold a
        // quarter of it: every other-groups' information is 3/4 of it, μ = 3/4.
        let a = Matrix6::from_diagonal(&nalgebra::Vector6::new(4.0, 3.0, 2.0, 1.0, 0.5, 0.25));
        let full = InertiaVector::repeat(1.0);
        let even: [InertiaVector; 4] =
            core::array::from_fn(|g| full + InertiaVector::repeat(0.01 * (g as f64 - 1.5)));
        let mut capped = even;
        cap_leverage(&a, &full, &[a * 0.75; 4], &mut capped);
        assert_eq!(
            capped, even,
            "no group above the cap: unchanged, bit for bit"
        );

        // Group 0 holds 99.5 % of the information along the first axis: the others'
        // is 0.005 of it there, and its deviation along that axis is scaled by
        // 0.005/(1 − MAX_LEVERAGE); across it, where it holds a quarter, nothing
        // changes.
        let mut rest = [a * 0.75; 4];
        rest[0][(0, 0)] = 0.005 * a[(0, 0)];
        let mut capped = even;
        cap_leverage(&a, &full, &rest, &mut capped);
        let (before, after) = (even[0] - full, capped[0] - full);
        let scale = 0.005 / (1.0 - MAX_LEVERAGE);
        assert!((after[0] - before[0] * scale).abs() < 1e-15, "{after:?}");
        for k in 1..6 {
            assert!((after[k] - before[k]).abs() < 1e-15, "{k}: {after:?}");
        }
        assert_eq!(&capped[1..], &even[1..]);

        // Not positive definite: nothing to scale by.
        let mut same = even;
        cap_leverage(&Matrix6::zeros(), &full, &rest, &mut same);
        assert_eq!(same, even);
    }
}
