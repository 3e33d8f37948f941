//! Folding a block of rows into an upper-triangular factor by Householder reflections:
//! one reflection per pivot for the whole block, where [`crate::givens`] needs one
//! rotation per pivot and row.
//!
//! Given `R` (n×n upper triangular, diagonal ≥ 0) and rows `A` (m×n) with right-hand
//! sides `β`, the reflection at pivot `i` acts on row `i` of `[R | z]` and the rows of
//! `[A | β]`: with `x = (R_ii, A_0i, …, A_{m−1,i})` and `v = x − ‖x‖e₀`, `H = I − 2vvᵀ/vᵀv`
//! maps `x` to `‖x‖e₀`, so `R_ii` becomes `‖x‖ ≥ 0` and the block's column `i` zero.
//! `v₀ = R_ii − ‖x‖` is formed as `−σ/(R_ii + ‖x‖)` (`σ = Σ A_mi²`), without
//! cancellation (Parlett). Afterwards `RᵀR` has gained `AᵀA`, `Rᵀz` has gained `Aᵀβ`,
//! and the block's leftover `β'` has the norm of the part of `β` no solution fits: the
//! same factor as folding the rows one by one by Givens rotations (unique, with a
//! non-negative diagonal, up to rounding), for a `√` and a division per pivot instead of
//! `m`, and about half the arithmetic. The leftover is that of the row-by-row fold up to
//! an orthogonal transformation of the block, so only its sum of squares means anything.

use crate::math::sqrt;
use nalgebra::{SMatrix, SVector};

/// The reflection at pivot `i` of folding the rows `a` with right-hand sides `beta` into
/// `(Rᵀ, z)` (`Rᵀ` stored, so that each row of `R` is contiguous): afterwards column `i` of
/// `a` is zero. Applied at pivots `0..N` in turn (the rows zero before the first), it
/// folds the block, and `beta` holds the block's leftover. Reflections at one pivot
/// of independent states may be interleaved, so that the processor overlaps their `√`
/// and divisions, on which each pivot waits.
#[inline(always)]
pub(crate) fn reflect_transposed<const N: usize, const M: usize>(
    rt: &mut SMatrix<f64, N, N>,
    z: &mut SVector<f64, N>,
    a: &mut [SVector<f64, N>; M],
    beta: &mut [f64; M],
    i: usize,
) {
    let v: [f64; M] = core::array::from_fn(|m| a[m][i]);
    let sigma: f64 = v.iter().map(|x| x * x).sum();
    if sigma == 0.0 {
        return;
    }
    let x0 = rt[(i, i)];
    // 1/σ beside the √, then 1/‖x‖ and 1/p beside each other, p = x₀ + ‖x‖ > 0: with
    // v₀ = −σ/p, vᵀv = −2‖x‖v₀, so `x −= (2/vᵀv)(vᵀx)v` is, per column,
    // `d = v₀ r + Σ vₘ aₘ`, `r += d/‖x‖`, `aₘ −= d p/(‖x‖σ) vₘ`.
    let inv_sigma = 1.0 / sigma;
    let norm = sqrt(x0 * x0 + sigma);
    let p = x0 + norm;
    let (inv_norm, inv_p) = (1.0 / norm, 1.0 / p);
    let v0 = -sigma * inv_p;
    let g = p * inv_norm * inv_sigma;
    rt[(i, i)] = norm;
    for row in a.iter_mut() {
        row[i] = 0.0;
    }
    // Row i of R right of the diagonal: column i of Rᵀ below it.
    let r_row = &mut rt.as_mut_slice()[i * N + i + 1..(i + 1) * N];
    for (kk, rk) in r_row.iter_mut().enumerate() {
        let k = i + 1 + kk;
        let mut d = v0 * *rk;
        for m in 0..M {
            d += v[m] * a[m][k];
        }
        *rk += d * inv_norm;
        let dg = d * g;
        for m in 0..M {
            a[m][k] -= dg * v[m];
        }
    }
    let mut d = v0 * z[i];
    for m in 0..M {
        d += v[m] * beta[m];
    }
    z[i] += d * inv_norm;
    let dg = d * g;
    for m in 0..M {
        beta[m] -= dg * v[m];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fold the rows `a` with right-hand sides `beta` into `(Rᵀ, z)` at the pivots `pivots`
    /// (the rows must be zero before `pivots.start`; `Rᵀ` stored, so that each row of `R` is
    /// contiguous). Afterwards `a` is zero in `pivots` and `beta` holds the block's leftover.
    pub(crate) fn fold_block_transposed<const N: usize, const M: usize>(
        rt: &mut SMatrix<f64, N, N>,
        z: &mut SVector<f64, N>,
        a: &mut [SVector<f64, N>; M],
        beta: &mut [f64; M],
        pivots: core::ops::Range<usize>,
    ) {
        for i in pivots {
            reflect_transposed(rt, z, a, beta, i);
        }
    }

    use crate::givens::fold_row;

    /// Problem: random blocks of 3 rows (some with leading zeros, some with zero
    /// columns), folded into an empty 8×8 state. Reference: the same rows folded one by
    /// one by Givens rotations. Tolerance: 1e-12 relative to the largest entry of `R`
    /// (and of `z`); the leftover's sum of squares to 1e-10 relative.
    #[test]
    fn a_block_by_reflections_is_the_rows_by_rotations() {
        let mut rnd = crate::testing::uniform(0x9e37_79b9_7f4a_7c15);
        let (mut rt, mut z) = (SMatrix::<f64, 8, 8>::zeros(), SVector::<f64, 8>::zeros());
        let (mut r_ref, mut z_ref) = (SMatrix::<f64, 8, 8>::zeros(), SVector::<f64, 8>::zeros());
        let (mut rss, mut rss_ref) = (0.0, 0.0);
        for block in 0..40 {
            let mut a: [SVector<f64, 8>; 3] =
                core::array::from_fn(|_| SVector::from_fn(|_, _| rnd()));
            let mut beta: [f64; 3] = core::array::from_fn(|_| rnd());
            // Leading zeros from column `start`; every fifth block leaves column 5 alone.
            let start = block % 3;
            for row in &mut a {
                for k in 0..start {
                    row[k] = 0.0;
                }
                if block % 5 == 0 {
                    row[5] = 0.0;
                }
            }
            for m in 0..3 {
                rss_ref += fold_row(&mut r_ref, &a[m], Some((&mut z_ref, beta[m]))).powi(2);
            }
            fold_block_transposed(&mut rt, &mut z, &mut a, &mut beta, start..8);
            assert!(a.iter().all(|row| row.iter().all(|v| *v == 0.0)));
            rss += beta.iter().map(|b| b * b).sum::<f64>();
            let scale = r_ref.amax();
            assert!(
                (rt.transpose() - r_ref).amax() <= 1e-12 * scale,
                "block {block}"
            );
            assert!((z - z_ref).amax() <= 1e-12 * z_ref.amax(), "block {block}");
            // Exactly zero for the rotations while the rows fix the unknowns: there,
            // rounding.
            assert!(
                (rss - rss_ref).abs() <= 1e-10 * rss_ref + 1e-28,
                "block {block}: {rss} against {rss_ref}"
            );
            assert!((0..8).all(|i| rt[(i, i)] >= 0.0));
        }
    }
}
