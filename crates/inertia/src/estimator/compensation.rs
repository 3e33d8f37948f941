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
//! `‖R' j − z'‖²` with `R'ᵀR' = RᵀR − σ² c D` and `R'ᵀz' = Rᵀ z`, under the same
//! constraints. `(R', z')` come from six hyperbolic downdates of `[R | z]` by the rows
//! `√(σ² c D_ii) e_iᵀ` (right-hand side 0), so `RᵀR` is never formed and the condition
//! number of `R`, not its square, sets the accuracy. When `RᵀR − σ² c D` is not positive definite the noise dominates
//! the excitation and there is no answer, unless a-priori bounds already fix the open
//! direction (`FromPrior`), in which case the uncompensated problem is solved. The cross term `E[δHᵀ δy]` is O(h² σ²) and is
//! neglected. Rows whose noise is not modelled (`noise_s = 0`, e.g. finite differences)
//! are left as they are.

use super::qr::RecursiveQr;
use nalgebra::{Matrix6, Vector6};

/// `D` of the module docs.
pub(crate) const NOISE_GRAM_DIAGONAL: [f64; 6] = [1.0, 1.0, 1.0, 2.0, 2.0, 2.0];

/// The compensated `(R', z')`, or `None` when the noise dominates.
#[must_use]
pub(crate) fn compensate(
    qr: &RecursiveQr,
    gyro_noise_rad_s_rthz: f64,
) -> Option<(Matrix6<f64>, Vector6<f64>)> {
    let k = gyro_noise_rad_s_rthz * gyro_noise_rad_s_rthz * qr.noise_s;
    let (mut r, mut z) = (qr.r, qr.z);
    for (i, d) in NOISE_GRAM_DIAGONAL.iter().enumerate() {
        let mut w = Vector6::zeros();
        w[i] = crate::math::sqrt(k * d);
        if !crate::givens::downdate_row(&mut r, &mut z, &w) {
            return None;
        }
    }
    Some((r, z))
}

/// `qr` as [`super::recursive::solve_with`] solves it: compensated where a density is
/// given and the compensation exists, else as it is. The audit's χ² of the constraints'
/// move (`super::audit`) compares the answer with this problem's own least-squares
/// minimiser; against the uncompensated one it would count the compensation's move,
/// which removes the errors-in-variables shrinkage, as a conflict with the constraints.
#[must_use]
pub(crate) fn as_solved(qr: &RecursiveQr, gyro_noise_rad_s_rthz: Option<f64>) -> RecursiveQr {
    match gyro_noise_rad_s_rthz {
        Some(g) if g > 0.0 && qr.noise_s > 0.0 => {
            compensate(qr, g).map_or(*qr, |(r, z)| RecursiveQr { r, z, ..*qr })
        }
        _ => *qr,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The factored form equals the normal-equation form `(RᵀR − kD, Rᵀz)`.
    #[test]
    fn downdates_match_the_normal_equations() {
        let mut qr = RecursiveQr::new();
        for i in 0..40 {
            let x = i as f64;
            let h = Vector6::from_fn(|k, _| libm::sin((0.3 + 0.2 * k as f64) * x + k as f64));
            qr.add_row(&h, libm::cos(0.3 * x));
        }
        qr.noise_s = 2.0;
        let lmin = (qr.r.transpose() * qr.r).symmetric_eigenvalues().min();
        // k D with k = 0.3 λ_min/2 keeps RᵀR − kD positive definite (D ≤ 2I).
        let g = (0.3 * lmin / 2.0 / qr.noise_s).sqrt();
        let (r, z) = compensate(&qr, g).expect("positive definite");
        let kd = Matrix6::from_diagonal(&Vector6::from_fn(|i, _| {
            g * g * qr.noise_s * NOISE_GRAM_DIAGONAL[i]
        }));
        let a = qr.r.transpose() * qr.r - kd;
        assert!((r.transpose() * r - a).norm() <= 1e-12 * a.norm());
        let b = qr.r.transpose() * qr.z;
        assert!((r.transpose() * z - b).norm() <= 1e-12 * b.norm());
        assert!((0..6).all(|i| r[(i, i)] >= 0.0 && (0..i).all(|k| r[(i, k)] == 0.0)));
        // With k ≥ λ_min (D ≥ I) the noise dominates: no answer.
        assert!(compensate(&qr, (1.01 * lmin / qr.noise_s).sqrt()).is_none());
    }
}
