//! The fixed-size least-squares state of the recursive estimator (paper eqs. 58–61).
//!
//! Stacking rows `H_k j = y_k`, the thin QR factor `H_{1:N} = Q R` reduces
//! `‖H_{1:N} j − y_{1:N}‖²` to `‖R j − z‖² + ρ²` with `z = Qᵀ y` and `ρ²` the part of
//! `‖y‖²` no `j` can explain. [`RecursiveQr::add_row`] folds one new row into `(R, z, ρ²)`
//! by six Givens rotations of `[R; h]` (eqs. 60–61), without allocating; a 3-row block is
//! three calls. `R` keeps a non-negative diagonal.

use crate::givens::fold_row;
use crate::math::sqrt;
use nalgebra::{Matrix3x6, Matrix6, Vector3, Vector6};

/// `(R, z, ρ²)` and counters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecursiveQr {
    /// Upper-triangular factor.
    pub r: Matrix6<f64>,
    /// `Qᵀ y` (first six components).
    pub z: Vector6<f64>,
    /// Residual sum of squares not explainable by any `j`.
    pub rss: f64,
    /// `Σ ‖y_k‖²`: zero exactly when no rotor momentum or known torque ever excited the rows.
    pub y_energy: f64,
    /// Scalar rows folded in.
    pub rows: usize,
    /// Effective number of rows: the sum of their current weights (equals `rows` without
    /// forgetting). Degrees of freedom of the noise statistics use this.
    pub weight: f64,
    /// Sum of the rows' errors-in-variables coefficients `noise_s` (weighted like the
    /// rows), s; see [`crate::discrete::Row::noise_s`].
    pub noise_s: f64,
    /// Unknowns besides `j` that were minimised out of the rows (weighted like the rows):
    /// degrees of freedom the residual does not have. Zero for the paper's rows.
    pub nuisance: f64,
}

impl Default for RecursiveQr {
    fn default() -> Self {
        Self::new()
    }
}

impl RecursiveQr {
    /// The empty state.
    #[must_use]
    pub fn new() -> Self {
        Self {
            r: Matrix6::zeros(),
            z: Vector6::zeros(),
            rss: 0.0,
            y_energy: 0.0,
            rows: 0,
            weight: 0.0,
            noise_s: 0.0,
            nuisance: 0.0,
        }
    }

    /// Fold one scalar row `hᵀ j = y` into the factor.
    pub fn add_row(&mut self, h: &Vector6<f64>, y: f64) {
        self.y_energy += y * y;
        let left = fold_row(&mut self.r, h, Some((&mut self.z, y)));
        self.rss += left * left;
        self.rows += 1;
        self.weight += 1.0;
    }

    /// Fold a 3-row block `H_k j = y_k` into the factor.
    pub fn add_block(&mut self, h: &Matrix3x6<f64>, y: &Vector3<f64>) {
        for i in 0..3 {
            self.add_row(&h.row(i).transpose(), y[i]);
        }
    }

    /// Fold a row block, including its errors-in-variables coefficient.
    pub(crate) fn add(&mut self, row: &crate::discrete::Row) {
        self.add_block(&row.h, &row.y);
        self.noise_s += row.noise_s;
    }

    /// Residual degrees of freedom: effective rows minus `j`'s six and the nuisance
    /// unknowns.
    #[must_use]
    pub(crate) fn residual_dof(&self) -> f64 {
        residual_dof(self.weight, self.nuisance)
    }

    /// Residual sum of squares per residual degree of freedom, `∞` without any.
    #[must_use]
    pub(crate) fn residual_variance(&self) -> f64 {
        residual_variance(self.rss, self.residual_dof())
    }

    /// The state with one unknown eliminated before `j` held at zero instead of
    /// minimised out: its row of the factor `r_u u + r_jᵀ j = z_u` (`u` the last unknown
    /// before `j`), without its column, folded in. The residual grows by what `u`
    /// explained; the rows are the same, and one nuisance unknown fewer is counted.
    #[must_use]
    pub(crate) fn holding_at_zero(&self, r_j: &Vector6<f64>, z_u: f64) -> RecursiveQr {
        let mut out = *self;
        let left = fold_row(&mut out.r, r_j, Some((&mut out.z, z_u)));
        out.rss += left * left;
        out.nuisance -= 1.0;
        out
    }

    /// Multiply the whole state by `√λ` (exponential forgetting of old rows, `0 < λ ≤ 1`).
    pub(crate) fn scale(&mut self, lambda: f64) {
        let s = sqrt(lambda);
        self.r *= s;
        self.z *= s;
        self.rss *= lambda;
        self.y_energy *= lambda;
        self.weight *= lambda;
        self.noise_s *= lambda;
    }
}

/// Residual degrees of freedom of a least-squares state: its (weighted) rows minus `j`'s
/// six unknowns and the nuisance unknowns.
#[must_use]
pub(crate) fn residual_dof(weight: f64, nuisance: f64) -> f64 {
    weight - 6.0 - nuisance
}

/// `ρ²` per residual degree of freedom, `∞` without any.
#[must_use]
pub(crate) fn residual_variance(rss: f64, dof: f64) -> f64 {
    if dof > 0.0 {
        rss / dof
    } else {
        f64::INFINITY
    }
}
