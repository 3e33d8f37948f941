//! Generalised least squares for a drifting attitude (beyond the paper): the momentum
//! rows of a chain weighted for the random walk of a gyro-propagated attitude.
//!
//! Each momentum row block reads `−X_p + a·y = b` (`super::augmented_qr`): the chain's
//! inertial momentum `X_p` is a constant. With an attitude propagated from a gyro, the
//! measured body→inertial matrix `C_k` carries an angle error `θ_k` that random-walks, so
//! the block's error has two parts (design note §5, "GLS"):
//!
//! * white: the noise of the incremental rotation `φ_k` through `(2/h) C N G(φ) j`, of
//!   covariance `r I` per row with `r = σ_g² · noise_s · s`, `σ_g` the rate-noise density of
//!   the rotation's source, `noise_s` the block's errors-in-variables coefficient
//!   (`super::momentum_rows::AugmentedRow::noise_s`) and `s = tr(J²)/3` (isotropic
//!   approximation of `C J Jᵀ Cᵀ`);
//! * a random walk: `C_k (θ_k × h_k) = Θ_k × Π` with `Π = C h` the inertial momentum
//!   (`≈ X_p`) and `Θ_k = C_k θ_k`, whose increment over `Δt` has covariance
//!   `σ_a² Δt I` (`σ_a` the attitude's angle random walk, rad/√s). Its covariance grows
//!   by `Q = σ_a² Δt [Π×][Π×]ᵀ = σ_a² Δt (|Π|² I − Π Πᵀ)`; along `Π` nothing drifts.
//!
//! So within a chain `X_p` is a random walk seen through white noise: the local-level
//! model, filtered for each initial-momentum slot on its own (the two slots of the
//! Richardson rows share one attitude walk; their correlation is not modelled, so the
//! rows are GLS per slot). Its Kalman filter, in units of `r`, gives the innovations of `a` and `b`, which,
//! whitened by the innovation covariance `F = P + I` (Cholesky `F = L Lᵀ`, rows `L⁻¹ v`),
//! are independent with unit variance: the GLS rows of the chain (de Jong's augmented
//! filter: the gains do not depend on the data, so the same filter whitens the
//! regressors and the right-hand side). With `Q = 0` it is the centring of
//! `super::augmented_qr`: `P = I/w`, rows scaled by `√(w/(w+1))`, gain `1/(w+1)`.
//!
//! The errors-in-variables compensation ([`super::compensation`]) still counts each
//! whitened block's full `noise_s`, while whitening by `F = P + Q + I` leaves it less of
//! the white noise: with a large drift it over-corrects a little.
//!
//! `Π` and `s` need a first estimate of `J` (the pipeline refolds the run from its first
//! sample at its first answer, [`crate::pipeline`]), and the ratio `σ_a²/σ_g²` needs
//! both densities from the user: with a star tracker or an MEKF the attitude error is
//! bounded and there is no drift to model. Measured on the README's matrix, the weighting
//! matters where the momentum is large (a spin); where the wheels hold the total momentum
//! near zero (slews) `Q ≈ 0` and the rows are unchanged.

use crate::tensor::{matrix_from_j, InertiaVector};
use nalgebra::{Matrix3, SVector, Vector3};

/// The drift model of [`super::augmented_qr::AugmentedQr`]: the ratio of densities and
/// the estimate of `J` that sets `Π` and `s` (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AttitudeDrift {
    /// `σ_a²/σ_g²` (dimensionless): the attitude's angle random walk (rad/√s) squared
    /// over the rotation source's rate-noise density (rad/s/√Hz) squared.
    pub(crate) ratio_s: f64,
    /// The estimate of `j` the weights are formed with.
    pub(crate) j: InertiaVector,
}

#[cfg_attr(not(feature = "std"), allow(dead_code))]
impl AttitudeDrift {
    /// The model for an attitude random walk of `attitude_deg_rth` (deg/√h) against a
    /// rate-noise density of `gyro_deg_s_rthz` (deg/s/√Hz), at the estimate `j`; `None`
    /// where the ratio is not a finite positive number or `j` is not finite.
    #[must_use]
    pub(crate) fn new(
        attitude_deg_rth: f64,
        gyro_deg_s_rthz: f64,
        j: InertiaVector,
    ) -> Option<Self> {
        // deg/√h → deg/√s is /60; the degrees cancel in the ratio.
        let a = attitude_deg_rth / 60.0;
        let ratio_s = (a * a) / (gyro_deg_s_rthz * gyro_deg_s_rthz);
        (ratio_s.is_finite() && ratio_s > 0.0 && j.iter().all(|x| x.is_finite()))
            .then_some(Self { ratio_s, j })
    }

    /// The growth `Q` of the mean's covariance, in units of the block's white variance,
    /// over `dt_s` since the slot's previous block, for a slot whose running means are
    /// `a` (coefficients in the shared unknowns, `j` last) and `b` (right-hand side), and
    /// a block of coefficient `noise_s`. `Π` comes from the means, not from the block
    /// being whitened, so that the weights do not depend on that block's noise.
    #[must_use]
    pub(crate) fn process<const N: usize>(
        &self,
        a: &[SVector<f64, N>; 3],
        b: &[f64; 3],
        noise_s: f64,
        dt_s: f64,
    ) -> Matrix3<f64> {
        let jm = matrix_from_j(&self.j);
        let s = (jm * jm).trace() / 3.0;
        if !(s > 0.0 && noise_s > 0.0 && dt_s > 0.0) {
            return Matrix3::zeros();
        }
        // Π ≈ X̄ = ā·y − b̄ at y = [0; …; 0; j] (the torque and curvature are small).
        let pi = Vector3::from_fn(|m, _| {
            (0..6).map(|k| a[m][N - 6 + k] * self.j[k]).sum::<f64>() - b[m]
        });
        let q = (Matrix3::identity() * pi.norm_squared() - pi * pi.transpose())
            * (self.ratio_s * dt_s / (noise_s * s));
        if q.iter().all(|x| x.is_finite()) {
            q
        } else {
            Matrix3::zeros()
        }
    }
}

/// One Kalman step of the local-level model (module docs) for a block with coefficients
/// `a` and right-hand side `b`, against the running means `mean_a`, `mean_b` of
/// covariance `p` (units of the white variance), after growth `q`: the whitened
/// innovations, or `None` where `P + Q + I` is not positive definite (non-finite input),
/// in which case nothing moves.
#[must_use]
pub(crate) fn local_level_step<const N: usize>(
    a: &[SVector<f64, N>; 3],
    b: &[f64; 3],
    mean_a: &mut [SVector<f64, N>; 3],
    mean_b: &mut [f64; 3],
    p: &mut Matrix3<f64>,
    q: &Matrix3<f64>,
) -> Option<([SVector<f64, N>; 3], [f64; 3])> {
    let predicted = *p + q;
    let f = predicted + Matrix3::identity();
    let l = f.cholesky()?.l();
    let l_inv = l.try_inverse()?;
    let f_inv = l_inv.transpose() * l_inv;
    let gain = predicted * f_inv;
    let da: [SVector<f64, N>; 3] = core::array::from_fn(|m| a[m] - mean_a[m]);
    let db: [f64; 3] = core::array::from_fn(|m| b[m] - mean_b[m]);
    let mut rows = [SVector::<f64, N>::zeros(); 3];
    let mut beta = [0.0; 3];
    for m in 0..3 {
        for n in 0..3 {
            rows[m] += da[n] * l_inv[(m, n)];
            beta[m] += db[n] * l_inv[(m, n)];
            mean_a[m] += da[n] * gain[(m, n)];
            mean_b[m] += db[n] * gain[(m, n)];
        }
    }
    let next = (Matrix3::identity() - gain) * predicted;
    *p = (next + next.transpose()) * 0.5;
    Some((rows, beta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// A deterministic pseudo-random number in [−1, 1).
    fn noise(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }

    /// The whitened rows' least-squares problem is the dense GLS one: for blocks
    /// `−X_k + a_k y = b_k` with `X_k` a random walk of given covariance seen through unit
    /// white noise, minimising over the whole path `X` and `y` with the full covariance
    /// gives the same `y` and the same residual sum of squares as ordinary least squares
    /// on the filter's rows (the first block absorbed), to 1e-9.
    #[test]
    fn the_filters_rows_are_the_dense_generalised_least_squares() {
        const N: usize = 4;
        let blocks = 12;
        let mut st = 7u64;
        let a: Vec<[SVector<f64, N>; 3]> = (0..blocks)
            .map(|_| core::array::from_fn(|_| SVector::from_fn(|_, _| noise(&mut st))))
            .collect();
        let b: Vec<[f64; 3]> = (0..blocks)
            .map(|_| core::array::from_fn(|_| noise(&mut st)))
            .collect();
        let qs: Vec<Matrix3<f64>> = (0..blocks)
            .map(|_| {
                let m = Matrix3::from_fn(|_, _| 0.5 * noise(&mut st));
                m * m.transpose()
            })
            .collect();
        // The filter: the first block absorbed, the rest whitened.
        let (mut ma, mut mb, mut p) = (a[0], b[0], Matrix3::identity());
        let mut rows = Vec::new();
        let mut rhs = Vec::new();
        for k in 1..blocks {
            let (r, z) = local_level_step(&a[k], &b[k], &mut ma, &mut mb, &mut p, &qs[k])
                .expect("positive definite");
            for m in 0..3 {
                rows.push(r[m].transpose());
                rhs.push(z[m]);
            }
        }
        let am = DMatrix::from_fn(rows.len(), N, |i, j| rows[i][j]);
        let bm = DVector::from_vec(rhs);
        let y_filter = am.clone().svd(true, true).solve(&bm, 1e-14).unwrap();
        let rss_filter = (&am * &y_filter - &bm).norm_squared();
        // Dense GLS: e = b − A y + X_0 + W (X_k = X_0 + W_k, W the walk), covariance
        // Σ = I + cov(W); X_0 free. Stacked: b_k = a_k y − X_0 − W_k − ε_k.
        let n = 3 * blocks;
        let mut cov = DMatrix::<f64>::identity(n, n);
        let mut walk = vec![Matrix3::zeros(); blocks];
        for k in 1..blocks {
            walk[k] = walk[k - 1] + qs[k];
        }
        for k in 0..blocks {
            for l in 0..blocks {
                let c = walk[k.min(l)];
                for m in 0..3 {
                    for o in 0..3 {
                        cov[(3 * k + m, 3 * l + o)] += c[(m, o)];
                    }
                }
            }
        }
        let design = DMatrix::from_fn(n, N + 3, |i, j| {
            let (k, m) = (i / 3, i % 3);
            if j < N {
                a[k][m][j]
            } else {
                -f64::from(u8::from(j - N == m))
            }
        });
        let rhs = DVector::from_fn(n, |i, _| b[i / 3][i % 3]);
        let l = cov.cholesky().unwrap();
        let wd = l.l().solve_lower_triangular(&design).unwrap();
        let wr = l.l().solve_lower_triangular(&rhs).unwrap();
        let x = wd.clone().svd(true, true).solve(&wr, 1e-14).unwrap();
        let rss_dense = (&wd * &x - &wr).norm_squared();
        for i in 0..N {
            assert!(
                (x[i] - y_filter[i]).abs() < 1e-9,
                "y[{i}]: dense {} filter {}",
                x[i],
                y_filter[i]
            );
        }
        assert!(
            (rss_dense - rss_filter).abs() < 1e-9 * rss_dense.max(1.0),
            "rss: dense {rss_dense} filter {rss_filter}"
        );
    }

    /// Without growth the filter is the centring of `augmented_qr`: rows scaled by
    /// `√(w/(w+1))`, means moved by `1/(w+1)`, `P = I/(w+1)`.
    #[test]
    fn without_drift_the_filter_centres() {
        let mut st = 3u64;
        let a0: [SVector<f64, 2>; 3] =
            core::array::from_fn(|_| SVector::from_fn(|_, _| noise(&mut st)));
        let (mut ma, mut mb, mut p) = (a0, [0.5, -0.25, 1.0], Matrix3::identity() / 3.0);
        let (ma0, mb0) = (ma, mb);
        let a: [SVector<f64, 2>; 3] =
            core::array::from_fn(|_| SVector::from_fn(|_, _| noise(&mut st)));
        let b = [1.0, 2.0, 3.0];
        let (r, z) = local_level_step(&a, &b, &mut ma, &mut mb, &mut p, &Matrix3::zeros()).unwrap();
        let w: f64 = 3.0;
        let f = (w / (w + 1.0)).sqrt();
        for m in 0..3 {
            assert!((r[m] - (a[m] - ma0[m]) * f).norm() < 1e-14);
            assert!((z[m] - (b[m] - mb0[m]) * f).abs() < 1e-14);
            assert!((ma[m] - (ma0[m] + (a[m] - ma0[m]) / (w + 1.0))).norm() < 1e-14);
        }
        assert!((p - Matrix3::identity() / (w + 1.0)).norm() < 1e-14);
    }

    /// Nothing drifts along the momentum: `Q Π = 0`, and `Q` scales with `Δt` and the
    /// ratio, and is zero without a momentum.
    #[test]
    fn the_drift_is_across_the_momentum() {
        let j = InertiaVector::new(1.0, 2.0, 3.0, 0.0, 0.0, 0.0);
        let d = AttitudeDrift::new(0.15, 0.15 / 60.0, j).unwrap();
        assert!((d.ratio_s - 1.0).abs() < 1e-12);
        // One row per axis: a = [0; j coefficients = ω components on the diagonal].
        let mut a = [SVector::<f64, 7>::zeros(); 3];
        a[0][1] = 0.5; // J11 · 0.5
        a[1][2] = -0.2;
        let b = [0.0; 3];
        let q = d.process(&a, &b, 10.0, 0.1);
        let pi = Vector3::new(0.5, -0.4, 0.0);
        assert!((q * pi).norm() < 1e-15, "{q}");
        let s = (1.0 + 4.0 + 9.0) / 3.0;
        assert!((q.trace() - 2.0 * pi.norm_squared() * 0.1 / (10.0 * s)).abs() < 1e-15);
        assert_eq!(
            d.process(&[SVector::<f64, 7>::zeros(); 3], &b, 10.0, 0.1),
            Matrix3::zeros()
        );
        assert!(AttitudeDrift::new(0.0, 1e-5, j).is_none());
        assert!(AttitudeDrift::new(0.1, 0.0, j).is_none());
    }
}
