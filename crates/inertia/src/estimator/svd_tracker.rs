//! Singular values of the 6×6 factor `R`, tracked from sample to sample.
//!
//! One-sided (Hestenes) Jacobi: rotate the columns of `B = R V` until they are mutually
//! orthogonal; then `σ_k = ‖b_k‖` and `V` holds the right singular vectors. The method
//! converges to full accuracy from any orthogonal `V`, but from the previous sample's `V`
//! (`R` changes by one row block per sample) it needs one or two sweeps instead of six,
//! which makes the observability test cheap enough to run at every sample. `V` is
//! re-orthonormalised every 256 updates against round-off drift. Fixed size, no
//! allocation.

use crate::math::sqrt;
use nalgebra::{Matrix6, Vector6};

/// Sweeps at most per update.
const MAX_SWEEPS: u32 = 30;
/// Columns count as orthogonal when `|b_iᵀb_j| ≤ TOL ‖b_i‖ ‖b_j‖`; the singular values
/// are then accurate to about `TOL²` relative (second order).
const TOL: f64 = 1e-13;

/// The tracked right singular vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SvdTracker {
    v: Matrix6<f64>,
    updates: u32,
}

impl Default for SvdTracker {
    fn default() -> Self {
        Self::new()
    }
}

impl SvdTracker {
    /// Start from `V = I`.
    #[must_use]
    pub fn new() -> Self {
        Self {
            v: Matrix6::identity(),
            updates: 0,
        }
    }

    /// The tracked right singular vectors (columns, in the order of the last
    /// [`Self::singular_values`]).
    #[must_use]
    pub fn v(&self) -> &Matrix6<f64> {
        &self.v
    }

    /// Singular values of `r` (unordered), updating the tracked `V`.
    pub fn singular_values(&mut self, r: &Matrix6<f64>) -> Vector6<f64> {
        self.updates = self.updates.wrapping_add(1);
        if self.updates.is_multiple_of(256) {
            reorthonormalise(&mut self.v);
        }
        let mut b = r * self.v;
        let mut norms = Vector6::from_fn(|k, _| b.column(k).norm_squared());
        for _ in 0..MAX_SWEEPS {
            let mut rotated = false;
            for i in 0..5 {
                for k in i + 1..6 {
                    let (alpha, beta) = (norms[i], norms[k]);
                    let gamma = b.column(i).dot(&b.column(k));
                    if gamma == 0.0 || gamma.abs() <= TOL * sqrt(alpha * beta) {
                        continue;
                    }
                    rotated = true;
                    let zeta = (beta - alpha) / (2.0 * gamma);
                    let t = zeta.signum() / (zeta.abs() + sqrt(1.0 + zeta * zeta));
                    let c = 1.0 / sqrt(1.0 + t * t);
                    let s = c * t;
                    rotate(&mut b, i, k, c, s);
                    rotate(&mut self.v, i, k, c, s);
                    // Hestenes: the rotation moves t·γ between the two column norms.
                    norms[i] = alpha - t * gamma;
                    norms[k] = beta + t * gamma;
                }
            }
            if !rotated {
                break;
            }
        }
        Vector6::from_fn(|k, _| b.column(k).norm())
    }
}

fn rotate(m: &mut Matrix6<f64>, i: usize, k: usize, c: f64, s: f64) {
    for row in 0..6 {
        let (x, y) = (m[(row, i)], m[(row, k)]);
        m[(row, i)] = c * x - s * y;
        m[(row, k)] = s * x + c * y;
    }
}

fn reorthonormalise(v: &mut Matrix6<f64>) {
    for k in 0..6 {
        for i in 0..k {
            let d = v.column(i).dot(&v.column(k));
            let ci = v.column(i).into_owned();
            let mut ck = v.column_mut(k);
            ck -= ci * d;
        }
        let n = v.column(k).norm();
        if n > 0.0 {
            v.column_mut(k).unscale_mut(n);
        }
    }
}
