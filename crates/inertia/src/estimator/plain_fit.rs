//! The least-squares fit of the plain discrete momentum rows
//! ([`super::momentum_rows`], plain stencil) in `[τ_b; j]`, with each chain's initial
//! momentum `L̄₀` and a torque fixed in the inertial frame `τ_I` minimised out per chain
//! and component: the small, exact fit that the wheel-speed time tag's profile
//! ([`super::wheel_delay`]) uses to ask how `ĵ` moves when the rotor momentum does. The rows' right-hand side is linear in
//! `ρ` and the known torque, and their regressors do not depend on either, so one set of
//! regressors fits any right-hand side ([`fit`]).

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use std::vec::Vec;

/// Regressors of one scalar row: `[τ_b (3); j (6)]`, each chain's `[L̄₀_m, τ_I,m]`, the
/// right-hand side.
pub(crate) const X: usize = 9;
const W: usize = X + 3;

/// One chain's cross-products per component `m`, over `[x (9); −1; −s; y]`.
type Moments = [SMatrix<f64, W, W>; 3];

/// One interval's rows: the chain it belongs to, `−S_k` (the body torque's columns),
/// `A_k` (j's), the inertial torque's coefficient `s_k`, the right-hand side (the plain
/// rows of [`super::momentum_rows`]).
pub(crate) type Block = (usize, Matrix3<f64>, SMatrix<f64, 3, 6>, f64, Vector3<f64>);

/// Rows to fit, one 3-row block per interval.
pub(crate) struct Rows {
    pub(crate) blocks: Vec<Block>,
    pub(crate) chains: usize,
}
/// The least-squares fit: `[τ_b; j]`, the RSS, the rows' degrees of freedom.
pub(crate) struct Fit {
    pub(crate) theta: SVector<f64, X>,
    /// Per chain and component: `[L̄₀_m, τ_I,m]`.
    pub(crate) nuisance: Vec<[nalgebra::Vector2<f64>; 3]>,
    pub(crate) rss: f64,
    pub(crate) dof: f64,
}

/// Fit the rows' right-hand sides `y` (one 3-vector per block).
pub(crate) fn fit(r: &Rows, y: &[Vector3<f64>]) -> Option<Fit> {
    let mut per_chain: Vec<Moments> = vec![[SMatrix::zeros(); 3]; r.chains];
    let mut count = vec![0usize; r.chains];
    for ((chain, ms, a, si, _), yk) in r.blocks.iter().zip(y) {
        count[*chain] += 1;
        for m in 0..3 {
            let mut w = SVector::<f64, W>::zeros();
            for i in 0..3 {
                w[i] = ms[(m, i)];
            }
            for i in 0..6 {
                w[3 + i] = a[(m, i)];
            }
            w[X] = -1.0;
            w[X + 1] = -si;
            w[X + 2] = yk[m];
            per_chain[*chain][m] += w * w.transpose();
        }
    }
    let mut n = SMatrix::<f64, X, X>::zeros();
    let mut rhs = SVector::<f64, X>::zeros();
    let mut yy = 0.0;
    let mut rows = 0usize;
    let mut used = Vec::with_capacity(r.chains);
    for (mom, &c) in per_chain.iter().zip(&count) {
        // A chain of fewer than 3 intervals fits its two unknowns per component exactly.
        let ok = c >= 3;
        used.push(ok);
        if !ok {
            continue;
        }
        rows += 3 * c;
        for m in mom {
            let zz = m.fixed_view::<2, 2>(X, X).into_owned();
            let zi = zz.try_inverse()?;
            let xz = m.fixed_view::<X, 2>(0, X);
            let yz = m.fixed_view::<1, 2>(X + 2, X);
            n += m.fixed_view::<X, X>(0, 0) - xz * zi * xz.transpose();
            rhs += m.fixed_view::<X, 1>(0, X + 2) - xz * zi * yz.transpose();
            yy += m[(X + 2, X + 2)] - (yz * zi * yz.transpose())[(0, 0)];
        }
    }
    // Equilibrate before the Cholesky factor: the columns differ in scale by orders.
    let d = SVector::<f64, X>::from_fn(|i, _| {
        let v = n[(i, i)];
        if v > 0.0 {
            1.0 / v.sqrt()
        } else {
            0.0
        }
    });
    if d.iter().any(|&x| x == 0.0) {
        return None;
    }
    let ns = SMatrix::<f64, X, X>::from_fn(|i, j| n[(i, j)] * d[i] * d[j]);
    let chol = ns.cholesky()?;
    let theta = chol.solve(&rhs.component_mul(&d)).component_mul(&d);
    let rss = (yy - rhs.dot(&theta)).max(0.0);
    let nuisance = per_chain
        .iter()
        .zip(&used)
        .map(|(mom, &ok)| {
            core::array::from_fn(|m| {
                if !ok {
                    return nalgebra::Vector2::zeros();
                }
                let mm = &mom[m];
                let zz = mm.fixed_view::<2, 2>(X, X).into_owned();
                let zi = zz.try_inverse().unwrap_or_else(nalgebra::Matrix2::zeros);
                let zy = mm.fixed_view::<2, 1>(X, X + 2).into_owned();
                let zx = mm.fixed_view::<2, X>(X, 0).into_owned();
                zi * (zy - zx * theta)
            })
        })
        .collect();
    let dof = rows as f64 - X as f64 - 6.0 * used.iter().filter(|&&u| u).count() as f64;
    Some(Fit {
        theta,
        nuisance,
        rss,
        dof,
    })
}

pub(crate) fn rhs(r: &Rows) -> Vec<Vector3<f64>> {
    r.blocks.iter().map(|b| b.4).collect()
}

/// `RSS(δ)` and `ĵ(δ)`, or `None` where the fit is singular.
/// Residuals of `y` per block under `f`.
pub(crate) fn residuals(r: &Rows, y: &[Vector3<f64>], f: &Fit) -> Vec<Vector3<f64>> {
    r.blocks
        .iter()
        .zip(y)
        .map(|((chain, ms, a, si, _), yk)| {
            Vector3::from_fn(|m, _| {
                let mut pred = 0.0;
                for i in 0..3 {
                    pred += ms[(m, i)] * f.theta[i];
                }
                for i in 0..6 {
                    pred += a[(m, i)] * f.theta[3 + i];
                }
                let nu = f.nuisance[*chain][m];
                pred += -nu[0] - si * nu[1];
                yk[m] - pred
            })
        })
        .collect()
}
