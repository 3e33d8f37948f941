//! The least-squares state of the discrete momentum estimator over all its unknowns
//! `[X₀; X₁; τ_b; κ; j]` ([`super::momentum_rows`]): the initial momenta of the chain in
//! progress minimised out exactly by centring, the rest in a [`SharedQr`].
//!
//! Each row block involves one initial-momentum slot `X_p` with coefficient `−I`: row `m`
//! reads `−X_{p,m} + a_m·y = b_m` in the shared unknowns `y = [τ_b; κ; j]`. Minimised over
//! `X_{p,m}`, the rows of a slot leave `Σ_k ((a_k − ā)·y − (b_k − b̄))²` with `ā`, `b̄` their
//! (weighted) means over the chain: the centred rows. Adding a row to `w` rows' worth
//! adds to that sum exactly `w/(w+1) ((a − ā_w)·y − (b − b̄_w))²` (the updating formula of
//! a mean-centred sum of squares; Welford), so each block is folded into the
//! [`SharedQr`] as its three rows minus the slot's running means, times `√(w/(w+1))`, and
//! the means move on. A slot's first block is absorbed whole (it fixes `X_p`). This is
//! the Schur complement that a QR over all 16 unknowns, the initial momenta first, would
//! leave in its trailing rows — the same `R` up to rounding (tested) — for 10 pivots
//! instead of 16, none of them on the slots' identity columns. When a chain ends its
//! initial momenta are minimised out for good: the means are forgotten
//! ([`AugmentedQr::eliminate_anchors`]).

use super::attitude_drift::{local_level_step, AttitudeDrift};
use super::momentum_rows::{AugmentedRow, ANCHOR0, ANCHOR1, J};
use super::normal_equations::NormalEquations;
use super::qr::RecursiveQr;
use super::shared_qr::{SharedBlock, SharedQr, J_SHARED, SHARED};
use super::trend_slot::{Trend, TrendStep};
use super::unknowns::FIRST_SHARED;
use crate::math::sqrt;
use nalgebra::{Matrix3, SVector};

/// A block's right-hand sides as measured.
fn row_y(row: &AugmentedRow) -> [f64; 3] {
    core::array::from_fn(|m| row.b[m])
}

/// The running means of one initial-momentum slot's rows over the chain in progress.
#[derive(Debug, Clone, Copy, PartialEq)]
struct SlotMean {
    /// Blocks folded in (weighted by forgetting).
    weight: f64,
    /// Mean coefficients of each row in the shared unknowns.
    a: [SVector<f64, SHARED>; 3],
    /// Mean right-hand side of each row.
    b: [f64; 3],
    /// Covariance of the mean in units of the rows' white variance, once an attitude
    /// drift is modelled ([`super::attitude_drift`]); `None`: `I/weight`.
    p: Option<Matrix3<f64>>,
    /// Time of the slot's last block, s.
    t_s: f64,
    /// The slot's inertial torque, for blocks that have one
    /// ([`AugmentedRow::trend_s`], [`super::trend_slot`]).
    trend: Option<Trend<SHARED>>,
}

impl SlotMean {
    fn empty() -> Self {
        Self {
            weight: 0.0,
            a: [SVector::<f64, SHARED>::zeros(); 3],
            b: [0.0; 3],
            p: None,
            t_s: 0.0,
            trend: None,
        }
    }
}

/// The least-squares state: the shared unknowns' QR and the chain's slot means.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AugmentedQr {
    shared: SharedQr,
    slots: [SlotMean; 2],
    /// The attitude drift the rows are weighted for, if any ([`Self::set_drift`]).
    drift: Option<AttitudeDrift>,
    /// Time of the block being folded, s ([`Self::advance_to`]).
    now_s: f64,
    /// Whether each slot has an inertial torque ([`Self::with_inertial_torque`]).
    inertial_torque: bool,
}

#[cfg_attr(not(feature = "std"), allow(dead_code))]
impl AugmentedQr {
    /// The empty state; `shared_nuisance` unknowns (the disturbance torque) are counted
    /// from the start.
    #[must_use]
    pub(crate) fn new(shared_nuisance: usize) -> Self {
        Self {
            shared: SharedQr::new(shared_nuisance),
            slots: [SlotMean::empty(); 2],
            drift: None,
            now_s: 0.0,
            inertial_torque: false,
        }
    }

    /// The state with an inertial torque per slot ([`super::trend_slot`]) or without.
    #[must_use]
    pub(crate) fn with_inertial_torque(self, on: bool) -> Self {
        Self {
            inertial_torque: on,
            ..self
        }
    }

    /// Weigh the blocks folded from now on for an attitude that drifts
    /// ([`super::attitude_drift`]; `None`: centred as without drift, the default). The
    /// pipeline passes its latest estimate of `J` here after each answer.
    pub(crate) fn set_drift(&mut self, drift: Option<AttitudeDrift>) {
        self.drift = drift;
    }

    /// The time of the next block, s (for the drift between a slot's blocks).
    pub(crate) fn advance_to(&mut self, t_s: f64) {
        self.now_s = t_s;
    }

    /// Fold a 3-row block into this state and, when given, into `chain`, the state of the
    /// chain in progress alone (the jackknife's, [`super::jackknife::ChainGroups`]): the
    /// same centred rows go into both, since the chain's initial momenta are its own.
    ///
    /// The block must involve one slot with coefficient `−I` (as every block of
    /// [`super::momentum_rows::MomentumRows`] does) and no other.
    pub(crate) fn add(&mut self, row: &AugmentedRow, chain: Option<&mut NormalEquations>) {
        if let Some(block) = self.centre(row, chain) {
            self.shared.add(block, &row_y(row), row.noise_s);
        }
    }

    /// [`Self::add`] of the same block to two states (two candidates sharing their rows,
    /// [`super::discrete_momentum::DiscreteMomentumEstimator::fold_shared_pair`]), their
    /// reflections interleaved (`SharedQr::add_pair`): the same states as two
    /// [`Self::add`], bit for bit.
    pub(crate) fn add_pair(
        (a, chain_a): (&mut Self, Option<&mut NormalEquations>),
        (b, chain_b): (&mut Self, Option<&mut NormalEquations>),
        row: &AugmentedRow,
    ) {
        let y = row_y(row);
        match (a.centre(row, chain_a), b.centre(row, chain_b)) {
            (Some(x), Some(w)) => {
                SharedQr::add_pair((&mut a.shared, x), (&mut b.shared, w), &y, row.noise_s)
            }
            (Some(x), None) => a.shared.add(x, &y, row.noise_s),
            (None, Some(w)) => b.shared.add(w, &y, row.noise_s),
            (None, None) => {}
        }
    }

    /// The block centred on its slot's running means (module docs), which move on, and
    /// added to `chain` too; `None` for a slot's first block, which is absorbed (counted).
    fn centre(
        &mut self,
        row: &AugmentedRow,
        chain: Option<&mut NormalEquations>,
    ) -> Option<SharedBlock> {
        let p = usize::from(row.a[(0, ANCHOR1)] != 0.0);
        debug_assert!((0..3).all(|m| (0..6).all(|k| {
            let want = if k == 3 * p + m { -1.0 } else { 0.0 };
            row.a[(m, ANCHOR0 + k)] == want
        })));
        let y = row_y(row);
        let a: [SVector<f64, SHARED>; 3] =
            core::array::from_fn(|m| row.a.fixed_view::<1, SHARED>(m, FIRST_SHARED).transpose());
        let slot = &mut self.slots[p];
        let w = slot.weight;
        let trend = self.inertial_torque;
        let absorb = |slot: &mut SlotMean| {
            *slot = SlotMean {
                weight: 1.0,
                a,
                b: y,
                p: None,
                t_s: self.now_s,
                trend: trend.then(|| Trend::start(row.trend_s)),
            };
        };
        if w == 0.0 {
            absorb(slot);
            self.shared.count_absorbed(&y, row.noise_s);
            if let Some(c) = chain {
                c.count_absorbed(&y, row.noise_s);
            }
            return None;
        }
        if let Some(trend) = slot.trend.as_mut() {
            let s = row.trend_s;
            let q = self.drift.map_or_else(Matrix3::zeros, |d| {
                d.process(&slot.a, &slot.b, row.noise_s, self.now_s - slot.t_s)
            });
            let step = trend.step((&a, &y), s, (&mut slot.a, &mut slot.b), &q);
            slot.weight = w + 1.0;
            slot.t_s = self.now_s;
            let block = match step {
                Some(TrendStep::Row(block)) => block,
                // The torque fixed, or a state that cannot go on (the slot restarts at
                // the block, with its unknowns counted again).
                other => {
                    if other.is_none() {
                        absorb(slot);
                        self.shared.add_nuisance(6);
                    }
                    self.shared.count_absorbed(&y, row.noise_s);
                    if let Some(c) = chain {
                        c.count_absorbed(&y, row.noise_s);
                    }
                    return None;
                }
            };
            if let Some(c) = chain {
                c.add(&block, &y, row.noise_s);
            }
            return Some(block);
        }
        // Weighted for a drift, or once weighted (the covariance of the mean is then no
        // longer `I/w`): the local-level filter; otherwise the centring above.
        if self.drift.is_some() || slot.p.is_some() {
            let q = self.drift.map_or_else(Matrix3::zeros, |d| {
                d.process(&slot.a, &slot.b, row.noise_s, self.now_s - slot.t_s)
            });
            let mut p = slot.p.unwrap_or_else(|| Matrix3::identity() / w);
            if let Some(block) = local_level_step(&a, &y, &mut slot.a, &mut slot.b, &mut p, &q) {
                slot.p = Some(p);
                slot.weight = w + 1.0;
                slot.t_s = self.now_s;
                if let Some(c) = chain {
                    c.add(&block, &y, row.noise_s);
                }
                return Some(block);
            }
            // A non-finite covariance: centred as without drift from here on.
            slot.p = None;
        }
        slot.t_s = self.now_s;
        let (f, g) = (sqrt(w / (w + 1.0)), 1.0 / (w + 1.0));
        let mut centred = [SVector::<f64, SHARED>::zeros(); 3];
        let mut beta = [0.0; 3];
        for m in 0..3 {
            let da = a[m] - slot.a[m];
            let db = y[m] - slot.b[m];
            centred[m] = da * f;
            beta[m] = db * f;
            slot.a[m] += da * g;
            slot.b[m] += db * g;
        }
        slot.weight = w + 1.0;
        if let Some(c) = chain {
            c.add(&(centred, beta), &y, row.noise_s);
        }
        Some((centred, beta))
    }

    /// Count `n` more nuisance unknowns (a new chain's initial momenta).
    pub(crate) fn add_nuisance(&mut self, n: usize) {
        self.shared.add_nuisance(n);
    }

    /// Minimise the initial-momentum unknowns out of the rows so far (a chain ended):
    /// their rows are in the shared state already, centred; the means are forgotten.
    pub(crate) fn eliminate_anchors(&mut self) {
        self.slots = [SlotMean::empty(); 2];
    }

    /// Weigh the whole state by `λ` (exponential forgetting, `0 < λ ≤ 1`): the means are
    /// those of the weighted rows still.
    pub(crate) fn scale(&mut self, lambda: f64) {
        self.shared.scale(lambda);
        for s in &mut self.slots {
            s.weight *= lambda;
            if let Some(p) = &mut s.p {
                *p /= lambda;
            }
            if let Some(t) = &mut s.trend {
                t.scale(lambda);
            }
        }
    }

    /// The state in the shared unknowns.
    #[must_use]
    pub(crate) fn shared(&self) -> &SharedQr {
        &self.shared
    }

    /// Scalar rows folded in.
    #[must_use]
    pub(crate) fn rows(&self) -> usize {
        self.shared.rows()
    }

    /// Residual sum of squares `ρ²` (weighted).
    #[must_use]
    #[cfg_attr(not(feature = "std"), allow(dead_code))]
    pub(crate) fn rss(&self) -> f64 {
        self.shared.rss()
    }

    /// Residual degrees of freedom: rows minus `j` minus the nuisance unknowns (weighted).
    #[must_use]
    pub(crate) fn residual_dof(&self) -> f64 {
        self.shared.residual_dof()
    }

    /// Residual sum of squares per residual degree of freedom, `∞` without any.
    #[must_use]
    #[cfg_attr(not(feature = "std"), allow(dead_code))]
    pub(crate) fn residual_variance(&self) -> f64 {
        self.shared.residual_variance()
    }

    /// The reduced problem in `j` ([`SharedQr::reduced`]).
    #[must_use]
    pub(crate) fn reduced(&self) -> RecursiveQr {
        self.shared.reduced()
    }

    /// The nuisance unknowns `[X₀; X₁; τ_b; κ]` at a given `j`: `τ_b` and `κ` by
    /// back-substitution, the current chain's initial momenta from the means; zero for
    /// unknowns the rows never involved.
    #[must_use]
    pub(crate) fn nuisance_at(&self, j: &crate::tensor::InertiaVector) -> SVector<f64, J> {
        let lead = self.shared.leading_at(j);
        let y = SVector::<f64, SHARED>::from_fn(|i, _| {
            if i < J_SHARED {
                lead[i]
            } else {
                j[i - J_SHARED]
            }
        });
        let mut x = SVector::<f64, J>::zeros();
        for (p, s) in self.slots.iter().enumerate() {
            if s.weight > 0.0 {
                for m in 0..3 {
                    x[3 * p + m] = s.a[m].dot(&y) - s.b[m];
                }
            }
        }
        x.fixed_rows_mut::<J_SHARED>(FIRST_SHARED).copy_from(&lead);
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimator::momentum_rows::UNKNOWNS;
    use crate::givens::fold_row;
    use nalgebra::{SMatrix, Vector3};

    /// The reference: every row over all 16 unknowns folded by Givens rotations into a
    /// dense `R`, a chain's initial momenta eliminated by dropping their rows.
    #[derive(Clone, Copy)]
    struct Dense {
        r: SMatrix<f64, UNKNOWNS, UNKNOWNS>,
        z: SVector<f64, UNKNOWNS>,
        rss: f64,
    }

    impl Dense {
        fn new() -> Self {
            Self {
                r: SMatrix::zeros(),
                z: SVector::zeros(),
                rss: 0.0,
            }
        }
        fn add(&mut self, row: &AugmentedRow) {
            for m in 0..3 {
                let a: SVector<f64, UNKNOWNS> = row.a.row(m).transpose();
                self.rss += fold_row(&mut self.r, &a, Some((&mut self.z, row.b[m]))).powi(2);
            }
        }
        fn eliminate(&mut self) {
            for i in 0..crate::estimator::unknowns::PER_CHAIN {
                self.r.row_mut(i).fill(0.0);
                self.z[i] = 0.0;
            }
        }
        fn scale(&mut self, lambda: f64) {
            self.r *= lambda.sqrt();
            self.z *= lambda.sqrt();
            self.rss *= lambda;
        }
    }

    /// `R` and `z` in the shared unknowns within `tol` of the reference's largest entry (its
    /// trailing block: the same Cholesky factor of the same Schur complement), `ρ²` within
    /// `100 tol` relative.
    fn assert_shared(s: &SharedQr, d: &Dense, what: &str, tol: f64) {
        let r = d.r.fixed_view::<SHARED, SHARED>(FIRST_SHARED, FIRST_SHARED);
        let scale = d.r.amax();
        assert!((s.rt.transpose() - r).amax() <= tol * scale, "{what}: R");
        let z = d.z.fixed_rows::<SHARED>(FIRST_SHARED);
        assert!((s.z - z).amax() <= tol * d.z.amax(), "{what}: z");
        assert!(
            (s.rss() - d.rss).abs() <= 100.0 * tol * d.rss,
            "{what}: rss {} {}",
            s.rss(),
            d.rss
        );
    }

    /// A random block on slot `p`: `−I` in its columns, random elsewhere.
    fn block(rnd: &mut impl FnMut() -> f64, p: usize) -> AugmentedRow {
        let mut a = SMatrix::<f64, 3, UNKNOWNS>::from_fn(|_, _| rnd());
        for m in 0..3 {
            for k in 0..crate::estimator::unknowns::PER_CHAIN {
                a[(m, k)] = if k == ANCHOR0 + 3 * p + m { -1.0 } else { 0.0 };
            }
        }
        AugmentedRow {
            a,
            b: Vector3::from_fn(|_, _| rnd()),
            noise_s: rnd().abs(),
            trend_s: 0.0,
        }
    }

    /// Problem: the chains of [`centring_is_the_dense_fold_with_the_initial_momenta_first`]
    /// through the drift weighting's local-level filter ([`super::super::attitude_drift`])
    /// with no growth (`J = 0`, so no momentum to drift), switched on in the middle of
    /// the first chain. Reference: [`Dense`]. The filter's covariance takes over from the
    /// centring's `I/w` and follows the forgetting (`P/λ`): the same state, 1e-12.
    #[test]
    fn the_drift_filter_without_growth_is_the_centring() {
        let mut rnd = crate::testing::uniform(0x2545_f491_4f6c_dd1d);
        let mut qr = AugmentedQr::new(3);
        let mut dense = Dense::new();
        let still = AttitudeDrift::new(0.1, 1e-3, crate::tensor::InertiaVector::zeros());
        let mut t_s = 0.0;
        for chain in 0..5 {
            for k in 0..20 + 7 * chain {
                let p = if chain == 2 { 0 } else { k % 2 };
                let row = block(&mut rnd, p);
                if chain == 0 && k == 5 {
                    qr.set_drift(still);
                }
                if chain == 3 && k == 9 {
                    qr.scale(0.9);
                    dense.scale(0.9);
                }
                t_s += 0.1;
                qr.advance_to(t_s);
                qr.add(&row, None);
                dense.add(&row);
            }
            assert_shared(qr.shared(), &dense, &format!("chain {chain}"), 1e-12);
            qr.eliminate_anchors();
            dense.eliminate();
        }
        assert!(
            qr.slots.iter().all(|s| s.p.is_none()),
            "forgotten with the chain"
        );
    }

    /// Problem: five chains of random blocks alternating between the two slots (as
    /// Richardson rows do; the third chain on one slot only), with forgetting in the
    /// fourth. Reference: [`Dense`], for the estimator's state and for each chain's alone
    /// (but the fourth's: under forgetting the estimator keeps no chain states).
    /// Also the initial momenta and `τ_b` at the least-squares `j`, against the dense
    /// back-substitution (1e-9 relative).
    #[test]
    fn centring_is_the_dense_fold_with_the_initial_momenta_first() {
        let mut rnd = crate::testing::uniform(0x2545_f491_4f6c_dd1d);
        let mut qr = AugmentedQr::new(3);
        let mut dense = Dense::new();
        for chain in 0..5 {
            let mut mine = NormalEquations::default();
            let mut reference = Dense::new();
            for k in 0..20 + 7 * chain {
                let p = if chain == 2 { 0 } else { k % 2 };
                let row = block(&mut rnd, p);
                if chain == 3 && k == 9 {
                    qr.scale(0.9);
                    dense.scale(0.9);
                }
                qr.add(&row, (chain != 3).then_some(&mut mine));
                dense.add(&row);
                reference.add(&row);
            }
            assert_shared(
                qr.shared(),
                &dense,
                &format!("estimator, chain {chain}"),
                1e-12,
            );
            if chain != 3 {
                reference.eliminate();
                // The chain's normal equations, factored ([`NormalEquations::factor`]).
                assert_shared(&mine.factor(), &reference, &format!("chain {chain}"), 1e-9);
                assert_eq!(mine.counts().rows(), 3 * (20 + 7 * chain));
            }
            // The nuisance unknowns at the least-squares j, against the dense solution.
            // Back-substitution; unknowns no row involved (a slot unused) are zero.
            let mut x = SVector::<f64, UNKNOWNS>::zeros();
            for i in (0..UNKNOWNS).rev() {
                if dense.r[(i, i)] != 0.0 {
                    let s: f64 = (i + 1..UNKNOWNS).map(|k| dense.r[(i, k)] * x[k]).sum();
                    x[i] = (dense.z[i] - s) / dense.r[(i, i)];
                }
            }
            let j = crate::tensor::InertiaVector::from_fn(|i, _| x[J + i]);
            let got = qr.nuisance_at(&j);
            for i in 0..J {
                let want = if chain == 2 && (3..6).contains(&i) {
                    0.0
                } else {
                    x[i]
                };
                assert!(
                    (got[i] - want).abs() <= 1e-9 * x.amax(),
                    "chain {chain}, unknown {i}: {} against {want}",
                    got[i]
                );
            }
            qr.eliminate_anchors();
            dense.eliminate();
        }
    }

    /// Two states fed the same blocks in pairs ([`AugmentedQr::add_pair`], with a chain
    /// state on one of them) are bit for bit the states fed one [`AugmentedQr::add`] at a
    /// time, a chain ending in each of them at different times, so that their slots'
    /// first blocks (absorbed, not folded) fall at different times: every branch of the
    /// pairing.
    #[test]
    fn folding_in_pairs_is_folding_one_at_a_time() {
        let mut rnd = crate::testing::uniform(0x6a09_e667_f3bc_c908);
        let (mut a, mut b) = (AugmentedQr::new(3), AugmentedQr::new(3));
        let (mut a1, mut b1) = (a, b);
        let (mut chain, mut chain1) = (NormalEquations::default(), NormalEquations::default());
        for k in 0..40 {
            if k == 17 {
                b.eliminate_anchors();
                b1.eliminate_anchors();
            }
            if k == 28 {
                a.eliminate_anchors();
                a1.eliminate_anchors();
            }
            let row = block(&mut rnd, k % 2);
            AugmentedQr::add_pair((&mut a, Some(&mut chain)), (&mut b, None), &row);
            a1.add(&row, Some(&mut chain1));
            b1.add(&row, None);
        }
        assert_eq!((a, b), (a1, b1));
        assert_eq!(chain, chain1);
    }

    /// `held` is `want`: `R` and `z` to 1e-12 of their largest entry (up to the signs of
    /// rows), `ρ²` to 1e-10 relative.
    fn assert_same_reduced(held: &RecursiveQr, want: &RecursiveQr) {
        let scale = want.r.amax();
        for i in 0..6 {
            let sign = held.r[(i, i)].signum() * want.r[(i, i)].signum();
            for k in 0..6 {
                assert!((held.r[(i, k)] - sign * want.r[(i, k)]).abs() <= 1e-12 * scale);
            }
            assert!((held.z[i] - sign * want.z[i]).abs() <= 1e-12 * want.z.amax());
        }
        assert!((held.rss - want.rss).abs() <= 1e-10 * want.rss);
    }

    /// Holding the torque at zero ([`SharedQr::reduced_without_torque`]) is folding the
    /// same rows with the torque's columns zeroed: the reduced `R` and `z` to 1e-12 of
    /// their largest entry (up to the signs of rows), `ρ²` to 1e-10 relative, and the
    /// growth of `ρ²` is the difference of the two states' `ρ²`; three nuisance unknowns
    /// fewer. Two chains, Richardson-like alternating slots.
    #[test]
    fn holding_the_torque_at_zero_is_dropping_its_columns() {
        let mut rnd = crate::testing::uniform(0xbb67_ae85_84ca_a73b);
        let (mut with, mut without) = (AugmentedQr::new(3), AugmentedQr::new(0));
        for k in 0..60 {
            if k == 25 {
                with.eliminate_anchors();
                without.eliminate_anchors();
            }
            let row = block(&mut rnd, k % 2);
            let mut zeroed = row;
            for m in 0..3 {
                for t in crate::estimator::momentum_rows::TORQUE
                    ..crate::estimator::momentum_rows::TORQUE + 3
                {
                    zeroed.a[(m, t)] = 0.0;
                }
            }
            with.add(&row, None);
            without.add(&zeroed, None);
        }
        let (held, growth) = with.shared().reduced_without_torque();
        let want = without.reduced();
        assert_same_reduced(&held, &want);
        assert!((growth - (want.rss - with.rss())).abs() <= 1e-10 * want.rss);
        assert!(growth > 0.0);
    }

    /// Holding the damping at zero ([`SharedQr::damping_row`] folded into the reduced
    /// state, [`RecursiveQr::holding_at_zero`]) is folding the same rows with its column
    /// zeroed, with the torque free and with the torque held at zero as well: `R` and `z`
    /// to 1e-12 of their largest entry (up to the signs of rows), `ρ²` to 1e-10 relative,
    /// one nuisance unknown fewer.
    #[test]
    fn holding_the_damping_at_zero_is_dropping_its_column() {
        use crate::estimator::momentum_rows::{DAMPING, TORQUE};
        let mut rnd = crate::testing::uniform(0x3c6e_f372_fe94_f82b);
        let mut with = AugmentedQr::new(4);
        let (mut no_d, mut neither) = (AugmentedQr::new(0), AugmentedQr::new(0));
        for k in 0..60 {
            if k == 25 {
                for q in [&mut with, &mut no_d, &mut neither] {
                    q.eliminate_anchors();
                }
            }
            let row = block(&mut rnd, k % 2);
            let (mut d0, mut both0) = (row, row);
            for m in 0..3 {
                d0.a[(m, DAMPING)] = 0.0;
                both0.a[(m, DAMPING)] = 0.0;
                for t in TORQUE..TORQUE + 3 {
                    both0.a[(m, t)] = 0.0;
                }
            }
            with.add(&row, None);
            no_d.add(&d0, None);
            neither.add(&both0, None);
        }
        let shared = with.shared();
        for (torque_held, start, want) in [
            (false, shared.reduced(), no_d.reduced()),
            (true, shared.reduced_without_torque().0, neither.reduced()),
        ] {
            let (r_dj, z_d) = shared.damping_row(torque_held).expect("the rows use D");
            let held = start.holding_at_zero(&r_dj, z_d);
            assert_same_reduced(&held, &want);
            assert!(held.rss > start.rss);
            assert_eq!(held.nuisance, start.nuisance - 1.0);
        }
    }

    /// Merging a chain's state (its rows in a wavefront) is folding its rows one by one.
    #[test]
    fn merging_is_folding_the_rows_one_by_one() {
        let mut rnd = crate::testing::uniform(0x9e37_79b9_7f4a_7c15);
        let (mut base, mut chain) = (AugmentedQr::new(0), AugmentedQr::new(0));
        for k in 0..30 {
            base.add(&block(&mut rnd, k % 2), None);
            chain.add(&block(&mut rnd, k % 2), None);
        }
        let (base, chain) = (*base.shared(), *chain.shared());
        let mut merged = base;
        merged.merge(&chain);
        let mut r = base.rt.transpose();
        let mut z = base.z;
        let mut rss = base.rss();
        for i in 0..SHARED {
            let a: SVector<f64, SHARED> = chain.rt.column(i).into_owned();
            if a.iter().any(|v| *v != 0.0) {
                rss += fold_row(&mut r, &a, Some((&mut z, chain.z[i]))).powi(2);
            }
        }
        rss += chain.rss();
        assert_eq!((merged.rt, merged.z), (r.transpose(), z));
        assert_eq!(merged.rss(), rss);
        assert_eq!(merged.rows(), base.rows() + chain.rows());
    }
}
