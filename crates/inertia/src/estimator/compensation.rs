//! Bias compensation for errors-in-variables (beyond the paper).
//!
//! Gyro noise enters the variational rows through the measured attitude, so it perturbs
//! `H_k` as well as `y_k`. Stacked, `HᵀH` gains `E[δHᵀδH] = σ² c D` with
//! `c = Σ_k noise_s` ([`crate::discrete::Row::noise_s`]) and `D = diag(1, 1, 1, 2, 2, 2)`
//! (first order in `φ`: `δH ≈ G(δφ₁) − G(δφ₀)` and `Σ_i G(e_i)ᵀ G(e_i) = D`). That term
//! acts as a ridge penalty and shrinks the estimate towards zero: the README's noise sweep
//! shows the variational estimator losing 15 % of J at 100× the paper's gyro noise.
//!
//! Given the gyro's rate-noise density σ (a datasheet number), the compensated normal
//! equations `(RᵀR − σ² c D) j = Rᵀ z` are solved as the least-squares problem
//! `‖R' j − z'‖²` with `R'ᵀR' = RᵀR − σ² c D` (Cholesky) and `z' = R'⁻ᵀ Rᵀ z`, under
//! the same constraints. When `RᵀR − σ² c D` is not positive definite the noise dominates
//! the excitation and there is no answer, unless a-priori bounds already fix the open
//! direction (`FromPrior`), in which case the uncompensated problem is solved. The cross term `E[δHᵀ δy]` is O(h² σ²) and is
//! neglected. Rows whose noise is not modelled (`noise_s = 0`, e.g. finite differences)
//! are left as they are.

use super::qr::RecursiveQr;
use nalgebra::{Matrix6, Vector6};

/// `D` of the module docs.
pub const NOISE_GRAM_DIAGONAL: [f64; 6] = [1.0, 1.0, 1.0, 2.0, 2.0, 2.0];

/// The compensated `(R', z')`, or `None` when the noise dominates.
#[must_use]
pub fn compensate(
    qr: &RecursiveQr,
    gyro_noise_rad_s_rthz: f64,
) -> Option<(Matrix6<f64>, Vector6<f64>)> {
    let k = gyro_noise_rad_s_rthz * gyro_noise_rad_s_rthz * qr.noise_s;
    let mut a = qr.r.transpose() * qr.r;
    for (i, d) in NOISE_GRAM_DIAGONAL.iter().enumerate() {
        a[(i, i)] -= k * d;
    }
    let chol = a.cholesky()?;
    let u = chol.l().transpose();
    let b = qr.r.transpose() * qr.z;
    // z' = U⁻ᵀ b, i.e. L z' = b.
    let z = chol.l().solve_lower_triangular(&b)?;
    Some((u, z))
}
