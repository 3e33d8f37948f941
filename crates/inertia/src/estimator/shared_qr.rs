//! The least-squares state in the unknowns every chain of discrete momentum rows shares,
//! `y = [m; c; τ_b; κ; D; j]` (`SHARED` = 17, [`super::momentum_rows`]), the chains' initial
//! momenta already minimised out ([`super::augmented_qr`]): a fixed-size QR factor
//! folded by Householder reflections, one per pivot for each 3-row block
//! (the crate's `householder` module; the factor of paper eqs. 60–61 up to rounding).
//!
//! Because `j` comes last, the trailing 6×6 block of `R` (and of `z`) is the problem in
//! `j` with every other unknown minimised out exactly: `min_y ‖R y − z‖²` is
//! `‖R_jj j − z_j‖² + const` for each `j`. [`SharedQr::reduced`] hands that block to the constrained
//! solvers and the observability test, which then see the same `(R, z, ρ²)` as for the
//! paper's rows.

use super::qr::RecursiveQr;
use super::unknowns::Block;
pub(crate) use super::unknowns::SHARED;
use crate::givens::{rotate_transposed as rotate, wavefront};
use crate::householder::reflect_transposed as reflect;
use crate::math::sqrt;
use nalgebra::{Matrix3, Matrix6, SMatrix, SVector, Vector6};

/// Position of `j` among the shared unknowns.
pub(crate) const J_SHARED: usize = Block::J.shared_column();
/// The first shared unknown after the disturbance torque `τ_b`, and how many there are.
const AFTER_TORQUE: usize = Block::BodyTorque.shared_column() + 3;
const AFTER_TORQUE_REST: usize = SHARED - AFTER_TORQUE;

/// A 3-row block in the shared unknowns with its right-hand sides.
pub(crate) type SharedBlock = ([SVector<f64, SHARED>; 3], [f64; 3]);

/// The counters every state of rows keeps beside its factor: the energy of the
/// right-hand sides as measured, the rows and their weight, and the sum of their
/// errors-in-variables coefficients ([`super::momentum_rows::AugmentedRow::noise_s`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct RowCounts {
    pub(super) y_energy: f64,
    pub(super) rows: usize,
    pub(super) weight: f64,
    pub(super) noise_s: f64,
}

impl RowCounts {
    /// Count `M` rows with right-hand sides `y` (as measured) and errors-in-variables
    /// coefficient `noise_s` in all.
    pub(super) fn count<const M: usize>(&mut self, y: &[f64; M], noise_s: f64) {
        for y in y {
            self.y_energy += y * y;
        }
        self.rows += M;
        self.weight += M as f64;
        self.noise_s += noise_s;
    }

    /// The counts of both sets of rows.
    fn merge(&mut self, other: &RowCounts) {
        self.y_energy += other.y_energy;
        self.rows += other.rows;
        self.weight += other.weight;
        self.noise_s += other.noise_s;
    }

    /// Weigh the rows by `λ` (forgetting): every count but the rows themselves.
    fn scale(&mut self, lambda: f64) {
        self.y_energy *= lambda;
        self.weight *= lambda;
        self.noise_s *= lambda;
    }

    /// Scalar rows counted.
    #[must_use]
    pub(crate) fn rows(&self) -> usize {
        self.rows
    }

    /// Row weight counted (rows, discounted by forgetting).
    #[must_use]
    pub(crate) fn weight(&self) -> f64 {
        self.weight
    }
}

/// `(R, z, ρ²)` over the shared unknowns, and counters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SharedQr {
    /// `Rᵀ`: the rows of `R` contiguous, for the reflections
    /// (the crate's `householder` module).
    pub(super) rt: SMatrix<f64, SHARED, SHARED>,
    pub(super) z: SVector<f64, SHARED>,
    rss: f64,
    counts: RowCounts,
    /// Nuisance unknowns introduced so far (degrees of freedom the residual does not have).
    nuisance: f64,
}

#[cfg_attr(not(feature = "std"), allow(dead_code))]
impl SharedQr {
    /// The empty state; `nuisance` unknowns (the disturbance torque) are counted from the
    /// start.
    #[must_use]
    pub(crate) fn new(nuisance: usize) -> Self {
        Self {
            rt: SMatrix::zeros(),
            z: SVector::zeros(),
            rss: 0.0,
            counts: RowCounts::default(),
            nuisance: nuisance as f64,
        }
    }

    /// Fold a block of `M` rows (consumed: zero afterwards, its right-hand sides the
    /// leftover) into this state, one reflection per pivot. `y` are the rows' right-hand sides as measured (for the energy
    /// counter) and `noise_s` their errors-in-variables coefficient.
    pub(crate) fn add<const M: usize>(
        &mut self,
        block: ([SVector<f64, SHARED>; M], [f64; M]),
        y: &[f64; M],
        noise_s: f64,
    ) {
        let (mut a, mut beta) = block;
        // Unrolled: each reflection's loops get fixed lengths (4 % faster on the
        // 1M-sample run than the loop over pivots).
        const _: () = assert!(SHARED == 17, "one literal per pivot below");
        macro_rules! one {
            ($($i:literal)*) => {$(
                reflect(&mut self.rt, &mut self.z, &mut a, &mut beta, $i);
            )*};
        }
        one!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16);
        self.count(y, &beta, noise_s);
    }

    /// [`Self::add`] of a block to each of two states, their reflections interleaved
    /// pivot by pivot so that the processor overlaps their `√` and divisions, on which
    /// each pivot waits: the same states as two [`Self::add`], bit for bit. The blocks'
    /// rows share `y` and `noise_s` (one row block, centred for each state).
    pub(crate) fn add_pair(
        (s, (mut a, mut beta)): (&mut Self, SharedBlock),
        (o, (mut a2, mut beta2)): (&mut Self, SharedBlock),
        y: &[f64; 3],
        noise_s: f64,
    ) {
        const _: () = assert!(SHARED == 17, "one literal per pivot below");
        macro_rules! both {
            ($($i:literal)*) => {$(
                reflect(&mut s.rt, &mut s.z, &mut a, &mut beta, $i);
                reflect(&mut o.rt, &mut o.z, &mut a2, &mut beta2, $i);
            )*};
        }
        both!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16);
        s.count(y, &beta, noise_s);
        o.count(y, &beta2, noise_s);
    }

    /// Count a block of rows that needed no fold (its leftover is zero: the rows fix
    /// unknowns of their own, such as a chain's first block its initial momenta).
    pub(crate) fn count_absorbed(&mut self, y: &[f64; 3], noise_s: f64) {
        self.count(y, &[0.0; 3], noise_s);
    }

    fn count<const M: usize>(&mut self, y: &[f64; M], left: &[f64; M], noise_s: f64) {
        for left in left {
            self.rss += left * left;
        }
        self.counts.count(y, noise_s);
    }

    /// Fold another state's rows into this one: afterwards this is the state of both sets
    /// of rows (their unknowns identified column by column).
    pub(crate) fn merge(&mut self, other: &SharedQr) {
        // Its non-zero rows, folded in a wavefront ([`wavefront`]).
        let mut a = [SVector::<f64, SHARED>::zeros(); SHARED];
        let mut beta = [0.0; SHARED];
        let mut n = 0;
        for i in 0..SHARED {
            let row = other.rt.column(i);
            if row.iter().all(|v| *v == 0.0) {
                continue;
            }
            a[n] = row.into_owned();
            beta[n] = other.z[i];
            n += 1;
        }
        wavefront(0..SHARED, n, |m, i| {
            rotate(&mut self.rt, &mut a[m], &mut self.z, &mut beta[m], i);
        });
        for left in &beta[..n] {
            self.rss += left * left;
        }
        self.rss += other.rss;
        self.counts.merge(&other.counts);
        self.nuisance += other.nuisance;
    }

    /// A state from its parts: `Rᵀ`, `z`, `ρ²` and the counters, no nuisance unknowns
    /// counted ([`super::normal_equations::NormalEquations::factor`]).
    pub(super) fn from_parts(
        rt: SMatrix<f64, SHARED, SHARED>,
        z: SVector<f64, SHARED>,
        rss: f64,
        counts: RowCounts,
    ) -> Self {
        Self {
            rt,
            z,
            rss,
            counts,
            nuisance: 0.0,
        }
    }

    /// Count `n` more nuisance unknowns (a new chain's initial momenta).
    pub(crate) fn add_nuisance(&mut self, n: usize) {
        self.nuisance += n as f64;
    }

    /// Weigh the whole state by `λ` (exponential forgetting, `0 < λ ≤ 1`).
    pub(crate) fn scale(&mut self, lambda: f64) {
        let s = sqrt(lambda);
        self.rt *= s;
        self.z *= s;
        self.rss *= lambda;
        self.counts.scale(lambda);
        self.nuisance *= lambda;
    }

    /// Scalar rows folded in.
    #[must_use]
    pub(crate) fn rows(&self) -> usize {
        self.counts.rows
    }

    /// Row weight folded in (rows, discounted by forgetting).
    #[must_use]
    pub(crate) fn weight(&self) -> f64 {
        self.counts.weight
    }

    /// Residual sum of squares `ρ²` (weighted).
    #[must_use]
    #[cfg_attr(not(feature = "std"), allow(dead_code))]
    pub(crate) fn rss(&self) -> f64 {
        self.rss
    }

    /// Residual degrees of freedom: rows minus `j` minus the nuisance unknowns (weighted).
    #[must_use]
    pub(crate) fn residual_dof(&self) -> f64 {
        super::qr::residual_dof(self.counts.weight, self.nuisance)
    }

    /// Residual sum of squares per residual degree of freedom, `∞` without any.
    #[must_use]
    #[cfg_attr(not(feature = "std"), allow(dead_code))]
    pub(crate) fn residual_variance(&self) -> f64 {
        super::qr::residual_variance(self.rss, self.residual_dof())
    }

    /// The reduced problem in `j`: the trailing 6×6 block, with the nuisance unknowns
    /// counted in [`RecursiveQr::nuisance`].
    #[must_use]
    pub(crate) fn reduced(&self) -> RecursiveQr {
        RecursiveQr {
            r: Matrix6::from_fn(|i, k| self.rt[(J_SHARED + k, J_SHARED + i)]),
            z: Vector6::from_fn(|i, _| self.z[J_SHARED + i]),
            rss: self.rss,
            y_energy: self.counts.y_energy,
            rows: self.counts.rows,
            weight: self.counts.weight,
            noise_s: self.counts.noise_s,
            nuisance: self.nuisance,
        }
    }

    /// The least-squares standard deviation of the shared unknown in column `column`
    /// with every other unknown free: `s √(e_cᵀ (RᵀR)⁻¹ e_c)`, `s²` the residual variance
    /// per degree of freedom. Unknowns the rows do not use (a zero pivot) are not in the
    /// problem. `None` where the column is unused or there is no residual degree of
    /// freedom. White-noise σ: it knows nothing of correlated residuals.
    #[must_use]
    pub(crate) fn marginal_sigma(&self, column: usize) -> Option<f64> {
        let s2 = self.residual_variance();
        if !s2.is_finite() || self.rt[(column, column)] == 0.0 {
            return None;
        }
        // Rᵀ u = e_c, forward substitution (Rᵀ is lower triangular); then e_cᵀ(RᵀR)⁻¹e_c
        // = ‖u‖².
        let mut u = SVector::<f64, SHARED>::zeros();
        for i in column..SHARED {
            let d = self.rt[(i, i)];
            if d == 0.0 {
                continue;
            }
            let mut v = if i == column { 1.0 } else { 0.0 };
            for k in column..i {
                v -= self.rt[(i, k)] * u[k];
            }
            u[i] = v / d;
        }
        Some(sqrt(s2 * u.norm_squared()))
    }

    /// The unscaled covariance `(RᵀR)⁻¹` of the three shared unknowns from `column` on,
    /// every other unknown free (times the residual variance, their least-squares
    /// covariance): `UᵀU` with `Rᵀ U = [e_c e_{c+1} e_{c+2}]`. A zero pivot (an unknown
    /// the rows never separated from the ones before it) gives an infinite variance on
    /// its own axis.
    #[must_use]
    pub(crate) fn block_covariance(&self, column: usize) -> Matrix3<f64> {
        let mut u = [SVector::<f64, SHARED>::zeros(); 3];
        let mut cov = Matrix3::zeros();
        for (b, u) in u.iter_mut().enumerate() {
            if self.rt[(column + b, column + b)] == 0.0 {
                cov[(b, b)] = f64::INFINITY;
                continue;
            }
            for i in column..SHARED {
                let d = self.rt[(i, i)];
                if d == 0.0 {
                    continue;
                }
                let mut v = if i == column + b { 1.0 } else { 0.0 };
                for k in column..i {
                    v -= self.rt[(i, k)] * u[k];
                }
                u[i] = v / d;
            }
        }
        for a in 0..3 {
            for b in 0..3 {
                if cov[(a, a)].is_finite() && cov[(b, b)].is_finite() {
                    cov[(a, b)] = u[a].dot(&u[b]);
                }
            }
        }
        cov
    }

    /// The reduced problem in `j` with the disturbance torque `τ_b` held at zero instead of
    /// minimised out, and the growth of `ρ²` that costs. The unknowns before `τ_b` fit
    /// their own rows exactly at any `τ_b`, so `‖R y − z‖²` at `τ_b = 0` is, up to them,
    /// `‖R_τr r − z_τ‖² + ‖R_rr r − z_r‖²` in the unknowns after it `r = [κ; D; j]`: the
    /// three rows of `R` that hold `τ_b`, without its columns, folded into the
    /// trailing factor (one Householder reflection per pivot, the crate's `householder`
    /// module). Their leftover is what `τ_b` explained.
    /// The three torque unknowns are no longer counted as nuisance. Without forgetting
    /// only (the count of the torque unknowns is not weighted).
    #[must_use]
    pub(crate) fn reduced_without_torque(&self) -> (RecursiveQr, f64) {
        let (rt, z, growth) = self.folded_without_torque();
        let off = J_SHARED - AFTER_TORQUE;
        let reduced = RecursiveQr {
            r: Matrix6::from_fn(|i, k| rt[(off + k, off + i)]),
            z: Vector6::from_fn(|i, _| z[off + i]),
            rss: self.rss + growth,
            y_energy: self.counts.y_energy,
            rows: self.counts.rows,
            weight: self.counts.weight,
            noise_s: self.counts.noise_s,
            nuisance: self.nuisance - 3.0,
        };
        (reduced, growth)
    }

    /// `Rᵀ` and `z` of the unknowns after `τ_b`, `[κ; D; j]`, with `τ_b` held at zero
    /// ([`Self::reduced_without_torque`]), and the growth of `ρ²` that costs.
    fn folded_without_torque(
        &self,
    ) -> (
        SMatrix<f64, AFTER_TORQUE_REST, AFTER_TORQUE_REST>,
        SVector<f64, AFTER_TORQUE_REST>,
        f64,
    ) {
        // The unknowns before τ_b (the outside torques' `m`, `c`) keep their rows: they
        // fit them exactly whatever τ_b is (or the rows are zero where unused), so only the
        // rows after τ_b hold the reduced problem.
        const T0: usize = Block::BodyTorque.shared_column();
        const REST: usize = AFTER_TORQUE_REST;
        // Rᵀ of the trailing factor, and the torque's rows of R without its columns.
        let mut rt = SMatrix::<f64, REST, REST>::from_fn(|i, k| {
            self.rt[(i + AFTER_TORQUE, k + AFTER_TORQUE)]
        });
        let mut z = SVector::<f64, REST>::from_fn(|i, _| self.z[i + AFTER_TORQUE]);
        let mut a: [SVector<f64, REST>; 3] =
            core::array::from_fn(|t| SVector::from_fn(|k, _| self.rt[(k + AFTER_TORQUE, T0 + t)]));
        let mut beta: [f64; 3] = core::array::from_fn(|t| self.z[T0 + t]);
        for i in 0..REST {
            reflect(&mut rt, &mut z, &mut a, &mut beta, i);
        }
        let growth: f64 = beta.iter().map(|b| b * b).sum();
        (rt, z, growth)
    }

    /// The damping's row of the factor, `r_dd D + r_djᵀ j = z_d` once `j` is fixed (`D`
    /// is the last unknown before `j`), as `(r_dj, z_d)`: with the disturbance torque
    /// held at zero where `torque_held` ([`Self::reduced_without_torque`]), free
    /// otherwise. `None` where the rows do not use `D`.
    #[must_use]
    pub(crate) fn damping_row(&self, torque_held: bool) -> Option<(Vector6<f64>, f64)> {
        const D: usize = Block::Damping.shared_column();
        const _: () = assert!(D + 1 == J_SHARED, "D is the last unknown before j");
        let row = if torque_held {
            let (rt, z, _) = self.folded_without_torque();
            let (d, off) = (D - AFTER_TORQUE, J_SHARED - AFTER_TORQUE);
            (rt[(d, d)], Vector6::from_fn(|k, _| rt[(off + k, d)]), z[d])
        } else {
            let r_dj = Vector6::from_fn(|k, _| self.rt[(J_SHARED + k, D)]);
            (self.rt[(D, D)], r_dj, self.z[D])
        };
        (row.0 != 0.0).then_some((row.1, row.2))
    }

    /// `[τ_b; κ]` at a given `j`: back-substitution through the leading rows; zero for
    /// unknowns the rows never involved.
    #[must_use]
    pub(crate) fn leading_at(&self, j: &crate::tensor::InertiaVector) -> SVector<f64, J_SHARED> {
        let mut x = SVector::<f64, J_SHARED>::zeros();
        for i in (0..J_SHARED).rev() {
            let d = self.rt[(i, i)];
            if d == 0.0 {
                continue;
            }
            let mut s = self.z[i];
            for k in i + 1..J_SHARED {
                s -= self.rt[(k, i)] * x[k];
            }
            for k in 0..6 {
                s -= self.rt[(J_SHARED + k, i)] * j[k];
            }
            x[i] = s / d;
        }
        x
    }
}
