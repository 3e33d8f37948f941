//! The state of the chain in progress for the jackknife ([`super::jackknife`]) as
//! normal equations: `AᵀA`, `Aᵀβ` and `βᵀβ` over the shared unknowns `[τ_b; κ; j]` of
//! the chain's centred rows ([`super::augmented_qr`]), factored once, when the chain
//! ends (beyond the paper).
//!
//! The estimator's own state stays a QR factor ([`super::shared_qr`]): its residual `ρ²`
//! chooses between row models and its `R` carries `j` to the noise level. The chain's
//! state only feeds the delete-one-group estimates, whose spread is the jackknife σ.
//! Adding a block to the normal equations is 195 multiply-adds with no dependence
//! between them; a Householder fold waits at each of its 10 pivots for a `√` and
//! divisions. On the 1M-sample run the chain folds were 13 % of the time (7.8–8.0 s
//! instead of 8.8–9.0 s with normal equations, the candidates' own folds interleaved in
//! pairs, `SharedQr::add_pair`).
//!
//! `NormalEquations::factor` is the Cholesky factor `RᵀR = AᵀA`, `Rᵀz = Aᵀβ`,
//! `ρ² = βᵀβ − ‖z‖²`: the QR factor of the same rows up to rounding (tested), the
//! diagonal non-negative as [`SharedQr`] keeps it. Its rounding error grows as the
//! square of the rows' condition number, scaled column by column (Cholesky is
//! invariant to that scaling), where the QR's grows as the condition number. Measured,
//! it does not matter here: on the 1M-sample run every jackknife σ agrees with the QR
//! chain states' to 2e-9 relative and every `Ĵ` and status is the same, and the Monte
//! Carlo matrix (58 cells × 50 seeds) is unchanged to its four digits. A pivot that has
//! lost all but `PIVOT_DIGITS` (12) of its digits is taken as a direction the chain does not
//! determine, as an exactly dependent column leaves its row of `R` zero in the QR. `ρ²`
//! from the difference can lose the digits `βᵀβ` has over it; it enters the
//! delete-one problems only through the weight of a prior ([`super::prior::augment`]).

use super::shared_qr::{RowCounts, SharedBlock, SharedQr, SHARED};
use crate::math::sqrt;
use nalgebra::{SMatrix, SVector};

/// A pivot of the Cholesky factor at or below `10^−PIVOT_DIGITS` of its diagonal entry of
/// `AᵀA` is a direction the rows do not determine (its row of `R` is left zero): a
/// condition number of the scaled rows beyond 10⁶.
pub(crate) const PIVOT_DIGITS: i32 = 12;

/// `AᵀA`, `Aᵀβ`, `βᵀβ` of a chain's centred rows in the shared unknowns, and the same
/// counters as [`SharedQr`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct NormalEquations {
    /// `AᵀA`, upper triangle (column-major: column `k` holds rows `0..=k`).
    ata: SMatrix<f64, SHARED, SHARED>,
    atb: SVector<f64, SHARED>,
    btb: f64,
    counts: RowCounts,
}

impl Default for NormalEquations {
    fn default() -> Self {
        Self {
            ata: SMatrix::zeros(),
            atb: SVector::zeros(),
            btb: 0.0,
            counts: RowCounts::default(),
        }
    }
}

impl NormalEquations {
    /// Add a block of rows `a` with right-hand sides `beta` (as folded into the
    /// estimator's [`SharedQr::add`]); `y` are the rows' right-hand sides as measured and
    /// `noise_s` their errors-in-variables coefficient.
    pub(crate) fn add(&mut self, block: &SharedBlock, y: &[f64; 3], noise_s: f64) {
        let (a, beta) = block;
        // Columns before the block's first non-zero one add nothing (the outside torques'
        // leading columns where the samples have no such measurement): skipped.
        let start = (0..SHARED)
            .find(|&k| a.iter().any(|r| r[k] != 0.0))
            .unwrap_or(SHARED);
        for k in start..SHARED {
            let col = &mut self.ata.as_mut_slice()[k * SHARED + start..k * SHARED + k + 1];
            let (a0, a1, a2) = (a[0][k], a[1][k], a[2][k]);
            for (i, m) in col.iter_mut().enumerate() {
                let i = i + start;
                *m += a[0][i] * a0 + a[1][i] * a1 + a[2][i] * a2;
            }
            self.atb[k] += a0 * beta[0] + a1 * beta[1] + a2 * beta[2];
        }
        self.btb += beta.iter().map(|b| b * b).sum::<f64>();
        self.counts.count(y, noise_s);
    }

    /// Count a block of rows that needed no fold ([`SharedQr::count_absorbed`]).
    pub(crate) fn count_absorbed(&mut self, y: &[f64; 3], noise_s: f64) {
        self.counts.count(y, noise_s);
    }

    /// The rows' counters.
    #[must_use]
    pub(crate) fn counts(&self) -> &RowCounts {
        &self.counts
    }

    /// The factor of these rows (module docs), with no nuisance unknowns counted.
    #[must_use]
    pub(crate) fn factor(&self) -> SharedQr {
        let floor = libm::pow(10.0, -f64::from(PIVOT_DIGITS));
        // Rᵀ stored: column i of `rt` is row i of R.
        let mut rt = SMatrix::<f64, SHARED, SHARED>::zeros();
        let mut z = SVector::<f64, SHARED>::zeros();
        for i in 0..SHARED {
            let diagonal = self.ata[(i, i)];
            let d = diagonal - (0..i).map(|k| rt[(i, k)] * rt[(i, k)]).sum::<f64>();
            if !(diagonal > 0.0 && d > floor * diagonal) {
                continue;
            }
            let r_ii = sqrt(d);
            rt[(i, i)] = r_ii;
            for j in i + 1..SHARED {
                let s = self.ata[(i, j)] - (0..i).map(|k| rt[(i, k)] * rt[(j, k)]).sum::<f64>();
                rt[(j, i)] = s / r_ii;
            }
            z[i] = (self.atb[i] - (0..i).map(|k| rt[(i, k)] * z[k]).sum::<f64>()) / r_ii;
        }
        SharedQr::from_parts(rt, z, (self.btb - z.norm_squared()).max(0.0), self.counts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Problem: chains of 2 (rank 6 of 10), 5 and 40 random 3-row blocks (every fourth
    /// with column 4 zero) after an absorbed block. Reference: the same blocks folded into
    /// a [`SharedQr`] by Householder reflections. Tolerance: `R` and `z` to 1e-9 of their
    /// largest entry, `ρ²` to 1e-6 relative plus 1e-12 of `βᵀβ` (2 blocks fit exactly),
    /// the counters to rounding.
    #[test]
    fn the_factor_of_the_normal_equations_is_the_qr_factor() {
        let mut rnd = crate::testing::uniform(0x51_7cc1_b727_220a);
        for blocks in [2, 5, 40] {
            let mut normal = NormalEquations::default();
            let mut qr = SharedQr::new(0);
            let y0: [f64; 3] = core::array::from_fn(|_| rnd());
            normal.count_absorbed(&y0, 0.5);
            qr.count_absorbed(&y0, 0.5);
            for b in 0..blocks {
                let mut a: [SVector<f64, SHARED>; 3] =
                    core::array::from_fn(|_| SVector::from_fn(|_, _| rnd()));
                if b % 4 == 0 {
                    for row in &mut a {
                        row[4] = 0.0;
                    }
                }
                let beta: [f64; 3] = core::array::from_fn(|_| rnd());
                let y: [f64; 3] = core::array::from_fn(|_| 2.0 * rnd());
                normal.add(&(a, beta), &y, 0.25);
                qr.add((a, beta), &y, 0.25);
            }
            let got = normal.factor();
            let scale = qr.rt.amax();
            assert!(
                (got.rt - qr.rt).amax() <= 1e-9 * scale,
                "{blocks} blocks: R off by {}",
                (got.rt - qr.rt).amax()
            );
            assert!((got.z - qr.z).amax() <= 1e-9 * qr.z.amax(), "{blocks}: z");
            assert!(
                (got.rss() - qr.rss()).abs() <= 1e-6 * qr.rss() + 1e-12 * normal.btb,
                "{blocks}: rss {} against {}",
                got.rss(),
                qr.rss()
            );
            let (got, want) = (got.reduced(), qr.reduced());
            assert_eq!((got.rows, got.weight), (want.rows, want.weight));
            assert!((got.y_energy - want.y_energy).abs() <= 1e-12 * want.y_energy);
            assert!((got.noise_s - want.noise_s).abs() <= 1e-12 * want.noise_s);
        }
    }
}
