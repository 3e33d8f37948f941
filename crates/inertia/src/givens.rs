//! Folding a row into an upper-triangular factor by Givens rotations.
//!
//! Given `R` (n×n upper triangular) and a row `aᵀ` (with right-hand side `β`), rotate
//! `[R | z; aᵀ | β]` so that the row becomes zero: afterwards `RᵀR` has gained `a aᵀ`,
//! `Rᵀz` has gained `a β`, and the leftover `β'` is the part of `β` no solution can fit.
//! The diagonal of `R` stays non-negative. Shared by the recursive least-squares state and
//! the interior-point Newton systems; no allocation.

use crate::math::sqrt;
use nalgebra::{SMatrix, SVector};

/// Remove the row `wᵀ` (right-hand side 0) from `[R | z]` by hyperbolic rotations: afterwards
/// `RᵀR` has lost `w wᵀ` and `Rᵀz` is unchanged. Returns `false`, leaving `r` and `z`
/// partly updated, when `RᵀR − w wᵀ` is not positive definite. Never forms `RᵀR`.
pub(crate) fn downdate_row<const N: usize>(
    r: &mut SMatrix<f64, N, N>,
    z: &mut SVector<f64, N>,
    w: &SVector<f64, N>,
) -> bool {
    let mut w = *w;
    let mut v = 0.0;
    for i in 0..N {
        let wi = w[i];
        if wi == 0.0 {
            continue;
        }
        let rii = r[(i, i)];
        let t = wi / rii;
        if !(t.abs() < 1.0) {
            return false;
        }
        let c = 1.0 / sqrt((1.0 - t) * (1.0 + t));
        let s = c * t;
        r[(i, i)] = rii * sqrt((1.0 - t) * (1.0 + t));
        w[i] = 0.0;
        for k in i + 1..N {
            let (rk, wk) = (r[(i, k)], w[k]);
            r[(i, k)] = c * rk - s * wk;
            w[k] = -s * rk + c * wk;
        }
        let zi = z[i];
        z[i] = c * zi - s * v;
        v = -s * zi + c * v;
    }
    true
}

/// Fold `a` (and optionally the right-hand side `(z, β)`) into `r`. Returns the leftover
/// of `β` (0 without a right-hand side).
pub(crate) fn fold_row<const N: usize>(
    r: &mut SMatrix<f64, N, N>,
    a: &SVector<f64, N>,
    mut rhs: Option<(&mut SVector<f64, N>, f64)>,
) -> f64 {
    let mut a = *a;
    let mut beta = rhs.as_ref().map_or(0.0, |(_, b)| *b);
    for i in 0..N {
        rotate::<N, false>(
            r,
            &mut a,
            rhs.as_mut().map(|(z, _)| (&mut **z, &mut beta)),
            i,
        );
    }
    beta
}

/// One rotation of [`fold_row`] with `Rᵀ` stored in `rt`: zero `a[i]` against row `i` of
/// `[R | z]`, updating `β` with `z`. With `Rᵀ` stored, the rows of `R` are contiguous in
/// memory and the rotation runs over two contiguous slices, which the compiler
/// vectorises: the same operations in the same order as [`fold_row`], so the same
/// results bit for bit. Folding a row is rotating it at every pivot in turn; rotations
/// of other rows at other pivots, or of another factor, may be interleaved
/// ([`wavefront`], [`crate::estimator::augmented_qr`]).
#[inline]
pub(crate) fn rotate_transposed<const N: usize>(
    rt: &mut SMatrix<f64, N, N>,
    a: &mut SVector<f64, N>,
    z: &mut SVector<f64, N>,
    beta: &mut f64,
    i: usize,
) {
    rotate::<N, true>(rt, a, Some((z, beta)), i);
}

/// The rotation at pivot `i` on `R` (`TRANSPOSED == false`) or on `Rᵀ`.
#[inline(always)]
fn rotate<const N: usize, const TRANSPOSED: bool>(
    r: &mut SMatrix<f64, N, N>,
    a: &mut SVector<f64, N>,
    rhs: Option<(&mut SVector<f64, N>, &mut f64)>,
    i: usize,
) {
    let ai = a[i];
    if ai == 0.0 {
        return;
    }
    let rii = r[(i, i)];
    let rho = sqrt(rii * rii + ai * ai);
    let (c, s) = (rii / rho, ai / rho);
    r[(i, i)] = rho;
    a[i] = 0.0;
    if TRANSPOSED {
        // Column i of Rᵀ, below the diagonal: row i of R right of it.
        let row = &mut r.as_mut_slice()[i * N + i + 1..(i + 1) * N];
        for (rk, ak) in row.iter_mut().zip(&mut a.as_mut_slice()[i + 1..]) {
            let (x, y) = (*rk, *ak);
            *rk = c * x + s * y;
            *ak = -s * x + c * y;
        }
    } else {
        for k in i + 1..N {
            let (rk, ak) = (r[(i, k)], a[k]);
            r[(i, k)] = c * rk + s * ak;
            a[k] = -s * rk + c * ak;
        }
    }
    if let Some((z, beta)) = rhs {
        let zi = z[i];
        z[i] = c * zi + s * *beta;
        *beta = -s * zi + c * *beta;
    }
}

/// Call `rotate(m, i)` for rows `m < rows` and pivots `i` in `pivots`, in the order of a
/// wavefront: row `m` at pivot `i` comes after row `m − 1` at pivot `i` (as when the rows
/// are folded one after the other, so the results are the same bit for bit) but beside
/// row `m − 1` at pivot `i + 1`, which touches another row of `R`. The rotations of one
/// row depend on each other through `√` and a division per pivot; interleaving rows that
/// do not lets the processor overlap them.
#[inline(always)]
pub(crate) fn wavefront(
    pivots: core::ops::Range<usize>,
    rows: usize,
    mut rotate: impl FnMut(usize, usize),
) {
    for t in pivots.start..pivots.end + rows.saturating_sub(1) {
        for m in 0..rows {
            if let Some(i) = t.checked_sub(m).filter(|i| pivots.contains(i)) {
                rotate(m, i);
            }
        }
    }
}

/// Solve `RᵀR d = g` for upper-triangular `R` by two triangular solves. `None` when a
/// diagonal entry is zero or the result is not finite.
#[must_use]
pub(crate) fn solve_normal<const N: usize>(
    r: &SMatrix<f64, N, N>,
    g: &SVector<f64, N>,
) -> Option<SVector<f64, N>> {
    // Rᵀ w = g (forward), then R d = w (backward).
    let mut w = SVector::<f64, N>::zeros();
    for i in 0..N {
        let mut s = g[i];
        for k in 0..i {
            s -= r[(k, i)] * w[k];
        }
        let d = r[(i, i)];
        if d == 0.0 {
            return None;
        }
        w[i] = s / d;
    }
    let mut x = SVector::<f64, N>::zeros();
    for i in (0..N).rev() {
        let mut s = w[i];
        for k in i + 1..N {
            s -= r[(i, k)] * x[k];
        }
        x[i] = s / r[(i, i)];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}
