//! Closed-form eigen-decomposition of a symmetric 3×3 matrix, for the per-sample path.
//!
//! Eigenvalues by the trigonometric formula (Smith 1961), with the one cosine it needs
//! taken as the root of a cubic by Newton's method rather than as `cos(acos(·)/3)`: no
//! transcendental call, and accurate where `acos` is ill-conditioned. The eigenvalue
//! farthest from the other two (simple unless all three coincide) anchors the
//! decomposition: its eigenvector is the best-conditioned cross product of two rows of
//! `F − λI`, and the other two come from a 2×2 Jacobi rotation in the plane orthogonal to
//! it (any orthonormal pair there is valid for a double eigenvalue). Every eigenvalue is
//! returned as the Rayleigh quotient of its vector. About 150 flops, four square roots and
//! no transcendental function, against an iterative QR sweep; `tests` compare it with nalgebra's solver.

use crate::math::{abs, sqrt};
use nalgebra::{Matrix3, Vector3};

/// Eigenvalues ascending and the matching orthonormal eigenvectors.
#[must_use]
pub(crate) fn symmetric_eigen3(f: &Matrix3<f64>) -> (Vector3<f64>, [Vector3<f64>; 3]) {
    let q = f.trace() * (1.0 / 3.0);
    let p1 = f[(0, 1)] * f[(0, 1)] + f[(0, 2)] * f[(0, 2)] + f[(1, 2)] * f[(1, 2)];
    let d = Vector3::new(f[(0, 0)] - q, f[(1, 1)] - q, f[(2, 2)] - q);
    let p2 = d.norm_squared() + 2.0 * p1;
    let scale = f
        .iter()
        .fold(0.0, |m, &x| if abs(x) > m { abs(x) } else { m });
    if p2 <= (1e-300f64).max(f64::EPSILON * f64::EPSILON * scale * scale) {
        // A multiple of the identity: any basis.
        return (
            Vector3::repeat(q),
            [Vector3::x(), Vector3::y(), Vector3::z()],
        );
    }
    let p = sqrt(p2 * (1.0 / 6.0));
    let b = (f - Matrix3::identity() * q) * (1.0 / p);
    let r = (b.determinant() / 2.0).clamp(-1.0, 1.0);
    // The eigenvalues are q + 2p cos(φ + 2πk/3), φ = acos(r)/3 ∈ [0, π/3]. The one
    // farthest from the other two is the largest when r > 0 (φ < π/6), else the smallest;
    // with x = |r| it is q ± 2p c, c = cos(acos(x)/3) the largest root of 4c³ − 3c = x.
    let (sign, x) = if r > 0.0 { (1.0, r) } else { (-1.0, -r) };
    let anchor = q + sign * 2.0 * p * cos_third_acos(x);
    let a = f - Matrix3::identity() * anchor;
    let (r0, r1, r2) = (
        a.row(0).transpose(),
        a.row(1).transpose(),
        a.row(2).transpose(),
    );
    let (c01, c02, c12) = (r0.cross(&r1), r0.cross(&r2), r1.cross(&r2));
    let (n01, n02, n12) = (c01.norm_squared(), c02.norm_squared(), c12.norm_squared());
    let (best, nb) = if n01 >= n02 && n01 >= n12 {
        (c01, n01)
    } else if n02 >= n12 {
        (c02, n02)
    } else {
        (c12, n12)
    };
    let v0 = if nb > 0.0 {
        best * (1.0 / sqrt(nb))
    } else {
        Vector3::x()
    };
    let l0 = v0.dot(&(f * v0));
    // An orthonormal basis (e1, e2) of v0⊥ (Duff et al. 2017: one division, no square
    // root, accurate for every unit v0), and a 2×2 Jacobi rotation in it.
    let sz = if v0.z >= 0.0 { 1.0 } else { -1.0 };
    let ka = -1.0 / (sz + v0.z);
    let kb = v0.x * v0.y * ka;
    let e1 = Vector3::new(1.0 + sz * v0.x * v0.x * ka, sz * kb, -sz * v0.x);
    let e2 = Vector3::new(kb, sz + v0.y * v0.y * ka, -v0.y);
    let (fe1, fe2) = (f * e1, f * e2);
    let (m11, m12, m22) = (e1.dot(&fe1), e1.dot(&fe2), e2.dot(&fe2));
    let (c, s) = if m12 == 0.0 {
        (1.0, 0.0)
    } else {
        let tau = (m22 - m11) / (2.0 * m12);
        let t = if tau >= 0.0 { 1.0 } else { -1.0 } / (abs(tau) + sqrt(1.0 + tau * tau));
        let c = 1.0 / sqrt(1.0 + t * t);
        (c, c * t)
    };
    let u1 = e1 * c - e2 * s;
    let u2 = e1 * s + e2 * c;
    // Rayleigh quotients, with F u from F e1 and F e2.
    let l1 = u1.dot(&(fe1 * c - fe2 * s));
    let l2 = u2.dot(&(fe1 * s + fe2 * c));
    // Ascending, by a three-element sorting network.
    let mut pairs = [(l0, v0), (l1, u1), (l2, u2)];
    for (i, k) in [(0, 1), (1, 2), (0, 1)] {
        if pairs[k].0 < pairs[i].0 {
            pairs.swap(i, k);
        }
    }
    (
        Vector3::new(pairs[0].0, pairs[1].0, pairs[2].0),
        [pairs[0].1, pairs[1].1, pairs[2].1],
    )
}

/// `cos(acos(x)/3)` for `x ∈ [0, 1]`: the root in `[√3/2, 1]` of `4c³ − 3c − x`, where
/// the cubic's slope is at least 6. A quartic least-squares fit (error < 10⁻⁵) and two
/// Newton steps (error ≈ 1.7 e², so < 10⁻¹⁹ before rounding) give it to rounding.
#[inline]
fn cos_third_acos(x: f64) -> f64 {
    // Estrin's scheme: a shorter dependency chain than Horner's.
    let x2 = x * x;
    let mut c = (0.866_034_430_837_299_6 + x * 0.166_376_302_397_459_3)
        + x2 * ((-0.045_857_193_307_658_67 + x * 0.017_504_333_518_257_52)
            - x2 * 0.004_064_674_357_825_797);
    for _ in 0..2 {
        let c2 = c * c;
        c -= (c * (4.0 * c2 - 3.0) - x) / (12.0 * c2 - 3.0);
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Newton root against the trigonometric form on [0, 1].
    #[test]
    fn cos_third_acos_matches_trigonometric_form() {
        for i in 0..=100_000 {
            let x = f64::from(i) / 100_000.0;
            let expect = (x.acos() / 3.0).cos();
            let got = cos_third_acos(x);
            assert!(
                (got - expect).abs() <= 4.0 * f64::EPSILON,
                "{x}: {got} vs {expect}"
            );
        }
    }

    /// Matrices whose anchor eigenvector is a coordinate axis of either sign, or close to
    /// one (where the basis of its orthogonal plane switches branch).
    #[test]
    fn axis_aligned_and_nearly_axis_aligned() {
        let check = |f: &Matrix3<f64>| {
            let (vals, vecs) = symmetric_eigen3(f);
            let scale = f.norm();
            for i in 0..3 {
                let res = (f * vecs[i] - vecs[i] * vals[i]).norm();
                assert!(res < 1e-13 * scale, "{f}: residual {res:e}");
            }
            assert!(vals[0] <= vals[1] && vals[1] <= vals[2]);
            let v = Matrix3::from_columns(&vecs);
            assert!((v.transpose() * v - Matrix3::identity()).norm() < 1e-14);
        };
        let diagonals = [
            [1.0, 2.0, 3.0],
            [3.0, 2.0, 1.0],
            [1.0, 1.0, 5.0],
            [5.0, 1.0, 1.0],
            [1.0, 5.0, 1.0],
            [-2.0, 0.0, 7.0],
        ];
        for d in diagonals {
            for eps in [0.0, 1e-300, 1e-12, -1e-9, 1e-6] {
                let mut f = Matrix3::from_diagonal(&Vector3::from(d));
                f[(0, 2)] = eps;
                f[(2, 0)] = eps;
                f[(1, 2)] = -eps;
                f[(2, 1)] = -eps;
                check(&f);
                check(&(-f));
            }
        }
    }

    /// Agreement with nalgebra's iterative solver on many matrices, including repeated
    /// eigenvalues and near-singular ones.
    #[test]
    fn matches_iterative_solver() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for case in 0..20000 {
            let q = crate::attitude::Quaternion::exp(&Vector3::new(
                rnd() * 6.0,
                rnd() * 6.0,
                rnd() * 6.0,
            ))
            .to_matrix();
            let mut d = Vector3::new(rnd(), rnd(), rnd()) * 4.0;
            match case % 4 {
                1 => d[1] = d[0],
                2 => d[0] = 1e-12 * rnd(),
                3 => d[2] = d[1] + 1e-9,
                _ => {}
            }
            let f = q * Matrix3::from_diagonal(&d) * q.transpose();
            let f = (f + f.transpose()) * 0.5;
            let (vals, vecs) = symmetric_eigen3(&f);
            let mut expect = d;
            expect.as_mut_slice().sort_by(f64::total_cmp);
            let scale = f.norm().max(1e-300);
            for i in 0..3 {
                assert!(
                    (vals[i] - expect[i]).abs() < 1e-13 * scale,
                    "case {case}: {vals} vs {expect}"
                );
                // Residual of each eigenpair.
                let res = (f * vecs[i] - vecs[i] * vals[i]).norm();
                assert!(res < 1e-12 * scale, "case {case}: residual {res:e}");
            }
            let v = Matrix3::from_columns(&vecs);
            assert!((v.transpose() * v - Matrix3::identity()).norm() < 1e-12);
        }
    }
}
