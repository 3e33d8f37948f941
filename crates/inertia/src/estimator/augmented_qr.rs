//! The least-squares state of the discrete momentum estimator: a fixed-size QR factor over
//! the unknowns `[nuisance; j]` ([`super::momentum_rows`]), folded by Givens rotations like
//! [`super::qr::RecursiveQr`] (paper eqs. 60–61).
//!
//! Because `j` comes last, the trailing 6×6 block of `R` (and of `z`) is the problem in `j`
//! with every nuisance unknown minimised out exactly: `min_x ‖R x − z‖² = ‖R_jj j − z_j‖² +
//! const` for each `j`. [`AugmentedQr::reduced`] hands that block to the constrained
//! solvers and the observability test, which then see the same `(R, z, ρ²)` as for the
//! paper's rows. Eliminating the initial momenta of a finished chain is dropping the rows
//! of `R` in which they appear ([`AugmentedQr::eliminate_anchors`]).

use super::momentum_rows::{AugmentedRow, ANCHOR0, J, TORQUE, UNKNOWNS};
use super::qr::RecursiveQr;
use crate::givens::{rotate_transposed as rotate, wavefront};
use crate::householder::{fold_block_transposed as fold_block, reflect_transposed as reflect};
use crate::math::sqrt;
use nalgebra::{Matrix6, SMatrix, SVector, Vector6};

/// `(R, z, ρ²)` over the 16 unknowns, and counters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AugmentedQr {
    /// `Rᵀ`: the rows of `R` contiguous, for the rotations
    /// ([`crate::givens::rotate_transposed`]).
    rt: SMatrix<f64, UNKNOWNS, UNKNOWNS>,
    z: SVector<f64, UNKNOWNS>,
    rss: f64,
    y_energy: f64,
    rows: usize,
    weight: f64,
    /// Nuisance unknowns introduced so far (degrees of freedom the residual does not have).
    nuisance: f64,
    /// Sum of the rows' errors-in-variables coefficients ([`AugmentedRow::noise_s`]).
    noise_s: f64,
}

impl AugmentedQr {
    /// The empty state; `shared_nuisance` unknowns (the disturbance torque) are counted
    /// from the start.
    #[must_use]
    pub fn new(shared_nuisance: usize) -> Self {
        Self {
            rt: SMatrix::zeros(),
            z: SVector::zeros(),
            rss: 0.0,
            y_energy: 0.0,
            rows: 0,
            weight: 0.0,
            nuisance: shared_nuisance as f64,
            noise_s: 0.0,
        }
    }

    /// Fold a 3-row block into this state and, when given, into `chain`, the state of the
    /// chain in progress alone (the jackknife's, [`super::jackknife::ChainGroups`]).
    ///
    /// The chain's initial momenta are the leading unknowns and no other chain's rows
    /// involve them (its predecessor's were eliminated when it ended), so the leading rows
    /// of `R` and `z` are the same in both states, number for number: each row is rotated
    /// through them once, here, and only its remainder, in the shared unknowns, is folded
    /// into each state's trailing rows. The result is exactly that of folding the block
    /// into each state separately; `chain`'s own leading rows stay zero (they are this
    /// state's), which is what eliminating them at the chain's end leaves. The block is
    /// folded by one Householder reflection per pivot ([`crate::householder`]: the factor
    /// of folding its rows one by one, up to rounding, for a third of the `√` and
    /// divisions), with `R` stored transposed so that each reflection runs over
    /// contiguous memory.
    pub fn add(&mut self, row: &AugmentedRow, chain: Option<&mut AugmentedQr>) {
        let mut a: [SVector<f64, UNKNOWNS>; 3] = core::array::from_fn(|i| row.a.row(i).transpose());
        let mut beta: [f64; 3] = core::array::from_fn(|i| row.b[i]);
        fold_block(
            &mut self.rt,
            &mut self.z,
            &mut a,
            &mut beta,
            ANCHOR0..TORQUE,
        );
        if let Some(c) = chain {
            // The chain's reflections beside this state's: independent, overlapped.
            let (mut rest, mut left) = (a, beta);
            for i in TORQUE..UNKNOWNS {
                reflect(&mut self.rt, &mut self.z, &mut a, &mut beta, i);
                reflect(&mut c.rt, &mut c.z, &mut rest, &mut left, i);
            }
            for (y, left) in row.b.iter().zip(left) {
                c.count_row(*y, left);
            }
            c.noise_s += row.noise_s;
        } else {
            fold_block(
                &mut self.rt,
                &mut self.z,
                &mut a,
                &mut beta,
                TORQUE..UNKNOWNS,
            );
        }
        for (y, left) in row.b.iter().zip(beta) {
            self.count_row(*y, left);
        }
        self.noise_s += row.noise_s;
    }

    /// Count a folded scalar row with right-hand side `y` and leftover `left`.
    fn count_row(&mut self, y: f64, left: f64) {
        self.y_energy += y * y;
        self.rss += left * left;
        self.rows += 1;
        self.weight += 1.0;
    }

    /// Fold another state's rows into this one: afterwards this is the state of both sets
    /// of rows (their unknowns identified column by column).
    pub fn merge(&mut self, other: &AugmentedQr) {
        // Its non-zero rows, folded in a wavefront ([`wavefront`]).
        let mut a = [SVector::<f64, UNKNOWNS>::zeros(); UNKNOWNS];
        let mut beta = [0.0; UNKNOWNS];
        let mut n = 0;
        for i in 0..UNKNOWNS {
            let row = other.rt.column(i);
            if row.iter().all(|v| *v == 0.0) {
                continue;
            }
            a[n] = row.into_owned();
            beta[n] = other.z[i];
            n += 1;
        }
        wavefront(0..UNKNOWNS, n, |m, i| {
            rotate(&mut self.rt, &mut a[m], &mut self.z, &mut beta[m], i);
        });
        for left in &beta[..n] {
            self.rss += left * left;
        }
        self.rss += other.rss;
        self.y_energy += other.y_energy;
        self.rows += other.rows;
        self.weight += other.weight;
        self.nuisance += other.nuisance;
        self.noise_s += other.noise_s;
    }

    /// Count `n` more nuisance unknowns (a new chain's initial momenta).
    pub fn add_nuisance(&mut self, n: usize) {
        self.nuisance += n as f64;
    }

    /// Minimise the initial-momentum unknowns out of the rows so far (a chain ended):
    /// they occupy the leading columns, so only the leading rows of `R` involve them.
    pub fn eliminate_anchors(&mut self) {
        for i in ANCHOR0..TORQUE {
            for k in 0..UNKNOWNS {
                self.rt[(k, i)] = 0.0;
            }
            self.z[i] = 0.0;
        }
    }

    /// Weigh the whole state by `λ` (exponential forgetting, `0 < λ ≤ 1`).
    pub fn scale(&mut self, lambda: f64) {
        let s = sqrt(lambda);
        self.rt *= s;
        self.z *= s;
        self.rss *= lambda;
        self.y_energy *= lambda;
        self.weight *= lambda;
        self.nuisance *= lambda;
        self.noise_s *= lambda;
    }

    /// Scalar rows folded in.
    #[must_use]
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Row weight folded in (rows, discounted by forgetting).
    #[must_use]
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// Residual sum of squares `ρ²` (weighted).
    #[must_use]
    pub fn rss(&self) -> f64 {
        self.rss
    }

    /// Residual degrees of freedom: rows minus `j` minus the nuisance unknowns (weighted).
    #[must_use]
    pub fn residual_dof(&self) -> f64 {
        self.weight - 6.0 - self.nuisance
    }

    /// Residual sum of squares per residual degree of freedom, `∞` without any.
    #[must_use]
    pub fn residual_variance(&self) -> f64 {
        let dof = self.residual_dof();
        if dof > 0.0 {
            self.rss / dof
        } else {
            f64::INFINITY
        }
    }

    /// The reduced problem in `j`: the trailing 6×6 block, with the nuisance unknowns
    /// counted in [`RecursiveQr::nuisance`].
    #[must_use]
    pub fn reduced(&self) -> RecursiveQr {
        RecursiveQr {
            r: Matrix6::from_fn(|i, k| self.rt[(J + k, J + i)]),
            z: Vector6::from_fn(|i, _| self.z[J + i]),
            rss: self.rss,
            y_energy: self.y_energy,
            rows: self.rows,
            weight: self.weight,
            noise_s: self.noise_s,
            nuisance: self.nuisance,
        }
    }

    /// The nuisance unknowns at a given `j`: back-substitution through the leading rows
    /// (`τ_b` and the current chain's initial momenta); zero for unknowns the rows never
    /// involved.
    #[must_use]
    pub fn nuisance_at(&self, j: &crate::tensor::InertiaVector) -> SVector<f64, J> {
        let mut x = SVector::<f64, J>::zeros();
        for i in (0..J).rev() {
            let d = self.rt[(i, i)];
            if d == 0.0 {
                continue;
            }
            let mut s = self.z[i];
            for k in i + 1..J {
                s -= self.rt[(k, i)] * x[k];
            }
            for k in 0..6 {
                s -= self.rt[(J + k, i)] * j[k];
            }
            x[i] = s / d;
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// The old way: each state folds the whole row on its own, by [`fold_row`] on `R`.
    fn dense_add(qr: &mut AugmentedQr, row: &AugmentedRow) {
        let mut r = qr.rt.transpose();
        for i in 0..3 {
            let a: SVector<f64, UNKNOWNS> = row.a.row(i).transpose();
            let left = crate::givens::fold_row(&mut r, &a, Some((&mut qr.z, row.b[i])));
            qr.count_row(row.b[i], left);
        }
        qr.rt = r.transpose();
        qr.noise_s += row.noise_s;
    }

    /// The same state to rounding: `R` and `z` within 1e-12 of their largest entry, `ρ²`
    /// within 1e-10 relative, the counters equal.
    fn assert_close(a: &AugmentedQr, b: &AugmentedQr, what: &str) {
        let r_scale = b.rt.amax().max(1e-300);
        assert!((a.rt - b.rt).amax() <= 1e-12 * r_scale, "{what}: R");
        assert!(
            (a.z - b.z).amax() <= 1e-12 * b.z.amax().max(1e-300),
            "{what}: z"
        );
        assert!(
            (a.rss - b.rss).abs() <= 1e-10 * b.rss,
            "{what}: rss {} {}",
            a.rss,
            b.rss
        );
        assert_eq!(
            (a.y_energy, a.rows, a.weight, a.nuisance, a.noise_s),
            (b.y_energy, b.rows, b.weight, b.nuisance, b.noise_s),
            "{what}: counters"
        );
    }

    /// Folding each block once through the shared leading rows, by reflections, gives
    /// both the estimator's state and the chain's (its initial momenta eliminated) of
    /// folding the rows into each separately by rotations, over several chains of random
    /// rows; merging a chain's state is folding its rows one by one.
    #[test]
    fn folding_once_and_merging_equal_folding_row_by_row() {
        let mut rnd = crate::testing::uniform(0x2545_f491_4f6c_dd1d);
        let (mut once, mut dense) = (AugmentedQr::new(4), AugmentedQr::new(4));
        for chain in 0..5 {
            let (mut mine, mut reference) = (AugmentedQr::new(0), AugmentedQr::new(0));
            for k in 0..20 + 7 * chain {
                let mut row = AugmentedRow {
                    a: SMatrix::from_fn(|_, _| rnd()),
                    b: Vector3::from_fn(|_, _| rnd()),
                    noise_s: rnd().abs(),
                };
                // Rows of a Richardson chain use one of the two initial momenta.
                let unused = if k % 2 == 0 { ANCHOR0 + 3 } else { ANCHOR0 };
                for i in 0..3 {
                    for c in unused..unused + 3 {
                        row.a[(i, c)] = 0.0;
                    }
                }
                once.add(&row, Some(&mut mine));
                dense_add(&mut dense, &row);
                dense_add(&mut reference, &row);
            }
            assert_close(&once, &dense, "estimator");
            reference.eliminate_anchors();
            assert_close(&mine, &reference, "chain");
            // Merging (its rows in a wavefront) is folding them one by one.
            let mut merged = dense;
            merged.merge(&mine);
            let mut r = dense.rt.transpose();
            let mut one_by_one = dense;
            for i in 0..UNKNOWNS {
                let a: SVector<f64, UNKNOWNS> = mine.rt.column(i).into_owned();
                if a.iter().any(|v| *v != 0.0) {
                    let left =
                        crate::givens::fold_row(&mut r, &a, Some((&mut one_by_one.z, mine.z[i])));
                    one_by_one.rss += left * left;
                }
            }
            one_by_one.rt = r.transpose();
            assert_eq!((merged.rt, merged.z), (one_by_one.rt, one_by_one.z));
            assert_eq!(merged.rss, one_by_one.rss + mine.rss);
            once.eliminate_anchors();
            dense.eliminate_anchors();
        }
    }
}
