//! A chain's initial-momentum slot with a constant inertial torque
//! ([`super::momentum_rows`], "Inertial torque"): the slot's blocks read
//! `−X_k + a_k·y = b_k + ε_k` (`ε` white, unit variance, `y` the shared unknowns) with the
//! inertial momentum a linear trend, `X_{k+1} = X_k + (s_{k+1} − s_k) τ_I + w_k` (`w` the
//! attitude drift's random walk, [`super::attitude_drift`], zero without one).
//!
//! A local-linear-trend Kalman filter over `[X; τ_I]` whose estimates are affine in `y`
//! (`X̂_m = A_m·y − B_m`, likewise `τ̂`), as [`super::attitude_drift::local_level_step`]
//! is for the level alone: each block's innovation `(a − A_X)·y − (b − B_X)`, whitened by
//! its covariance `P_XX + I`, is a row of the shared problem, and the sum of their squares
//! is, for every `y`, the residual of the generalised least-squares fit of the slot's
//! `X`, `τ_I` (and drift path) to its blocks — the Schur complement a QR over all the
//! unknowns would leave (tested against the dense problem). The filter starts exactly
//! (no prior on either): the first block fixes `X` and the second `τ_I`, and both are
//! absorbed (no row).

use nalgebra::{Matrix3, Matrix6, SMatrix, SVector};

/// A block's rows in the shared unknowns and their right-hand sides.
pub(crate) type Block<const N: usize> = ([SVector<f64, N>; 3], [f64; 3]);

/// The covariance of the error of `[X̂; τ̂]` in the rows' white variances.
#[derive(Debug, Clone, Copy, PartialEq)]
// In place, not boxed: the estimator allocates nothing per sample (the C engine's storage
// holds it).
#[allow(clippy::large_enum_variant)]
enum Covariance {
    /// `[[a I, b I], [b I, c I]]`: the form it keeps while there is no drift, where the
    /// three components are independent and alike and every step is scalar.
    Kronecker { a: f64, b: f64, c: f64 },
    /// Any other.
    Full(Matrix6<f64>),
}

impl Covariance {
    fn full(&self) -> Matrix6<f64> {
        match *self {
            Covariance::Full(p) => p,
            Covariance::Kronecker { a, b, c } => {
                let i = Matrix3::identity();
                let mut p = Matrix6::zeros();
                p.fixed_view_mut::<3, 3>(0, 0).copy_from(&(i * a));
                p.fixed_view_mut::<3, 3>(0, 3).copy_from(&(i * b));
                p.fixed_view_mut::<3, 3>(3, 0).copy_from(&(i * b));
                p.fixed_view_mut::<3, 3>(3, 3).copy_from(&(i * c));
                p
            }
        }
    }
}

/// The torque part of a slot's state (its level `X̂` is the slot's means).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Trend<const N: usize> {
    /// `τ̂_m = tau_a[m]·y − tau_b[m]`, N m.
    tau_a: [SVector<f64, N>; 3],
    tau_b: [f64; 3],
    /// Covariance of the error of `[X̂; τ̂]`; `None` after one block (`τ` not yet
    /// fixed).
    p: Option<Covariance>,
    /// Before `τ` is fixed: the variance of the first block's level, in the rows' white
    /// variances (1, grown by forgetting).
    first_var: f64,
    /// `s` of the slot's last block, s.
    last_s: f64,
}

/// What a block did to the slot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum TrendStep<const N: usize> {
    /// The block fixed an unknown of the slot: no row.
    Absorbed,
    /// The block's whitened innovation.
    Row(Block<N>),
}

impl<const N: usize> Trend<N> {
    /// The trend of a slot whose first block, at `s`, set its level means.
    #[must_use]
    pub(crate) fn start(s: f64) -> Self {
        Self {
            tau_a: [SVector::zeros(); 3],
            tau_b: [0.0; 3],
            p: None,
            first_var: 1.0,
            last_s: s,
        }
    }

    /// Weigh the state by `λ` (forgetting): the covariance grows by `1/λ`.
    pub(crate) fn scale(&mut self, lambda: f64) {
        if self.p.is_none() {
            self.first_var /= lambda;
        }
        self.p = self.p.map(|p| match p {
            Covariance::Full(p) => Covariance::Full(p / lambda),
            Covariance::Kronecker { a, b, c } => Covariance::Kronecker {
                a: a / lambda,
                b: b / lambda,
                c: c / lambda,
            },
        });
    }

    /// Fold a block `(a, b)` at `s` into the slot whose level means are `level_a`,
    /// `level_b`, with the drift's covariance `q` since the slot's last block. `None` when
    /// the state cannot go on (a step `s` that does not increase, or a covariance that is
    /// no longer positive definite); the caller then restarts the slot at the block.
    pub(crate) fn step(
        &mut self,
        (a_new, b_new): (&[SVector<f64, N>; 3], &[f64; 3]),
        s: f64,
        (level_a, level_b): (&mut [SVector<f64, N>; 3], &mut [f64; 3]),
        q: &Matrix3<f64>,
    ) -> Option<TrendStep<N>> {
        let dt = s - self.last_s;
        if !(dt > 0.0 && dt.is_finite()) {
            return None;
        }
        self.last_s = s;
        let Some(p) = self.p else {
            // The second block: τ̂ = (X̂₂ − X̂₁)/Δs exactly, X̂ = the block's.
            for m in 0..3 {
                self.tau_a[m] = (a_new[m] - level_a[m]) / dt;
                self.tau_b[m] = (b_new[m] - level_b[m]) / dt;
                level_a[m] = a_new[m];
                level_b[m] = b_new[m];
            }
            // X̂ is the second block's (variance 1); τ̂'s error is that of the two
            // levels' difference over Δs, the first's variance grown by any forgetting.
            let kronecker = Covariance::Kronecker {
                a: 1.0,
                b: 1.0 / dt,
                c: (1.0 + self.first_var) / (dt * dt),
            };
            self.p = Some(if *q == Matrix3::zeros() {
                kronecker
            } else {
                let mut p = kronecker.full();
                let pt = p.fixed_view::<3, 3>(3, 3) + q / (dt * dt);
                p.fixed_view_mut::<3, 3>(3, 3).copy_from(&pt);
                Covariance::Full(p)
            });
            return Some(TrendStep::Absorbed);
        };
        if let (Covariance::Kronecker { a, b, c }, true) = (p, *q == Matrix3::zeros()) {
            return self.scalar_step(a, b, c, (a_new, b_new), dt, (level_a, level_b));
        }
        let p = p.full();
        // Predict: X += Δs τ, P = F P Fᵀ + diag(Q, 0).
        let mut f = Matrix6::identity();
        f.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(Matrix3::identity() * dt));
        let mut predicted = f * p * f.transpose();
        let pxx = predicted.fixed_view::<3, 3>(0, 0) + q;
        predicted.fixed_view_mut::<3, 3>(0, 0).copy_from(&pxx);
        let l = (pxx + Matrix3::identity()).cholesky()?.l();
        let l_inv = l.try_inverse()?;
        let gain: SMatrix<f64, 6, 3> =
            predicted.fixed_view::<6, 3>(0, 0) * (l_inv.transpose() * l_inv);
        let da: [SVector<f64, N>; 3] =
            core::array::from_fn(|m| a_new[m] - (level_a[m] + self.tau_a[m] * dt));
        let db: [f64; 3] = core::array::from_fn(|m| b_new[m] - (level_b[m] + self.tau_b[m] * dt));
        let mut rows = [SVector::<f64, N>::zeros(); 3];
        let mut beta = [0.0; 3];
        for m in 0..3 {
            level_a[m] += self.tau_a[m] * dt;
            level_b[m] += self.tau_b[m] * dt;
        }
        for m in 0..3 {
            for n in 0..3 {
                rows[m] += da[n] * l_inv[(m, n)];
                beta[m] += db[n] * l_inv[(m, n)];
                level_a[m] += da[n] * gain[(m, n)];
                level_b[m] += db[n] * gain[(m, n)];
                self.tau_a[m] += da[n] * gain[(3 + m, n)];
                self.tau_b[m] += db[n] * gain[(3 + m, n)];
            }
        }
        let next = predicted - gain * predicted.fixed_view::<3, 6>(0, 0);
        if !next.iter().all(|x| x.is_finite()) {
            return None;
        }
        self.p = Some(Covariance::Full((next + next.transpose()) * 0.5));
        Some(TrendStep::Row((rows, beta)))
    }

    /// [`Self::step`] without drift from a covariance `[[a I, b I], [b I, c I]]`: the
    /// same filter, component by component in scalars.
    fn scalar_step(
        &mut self,
        a: f64,
        b: f64,
        c: f64,
        (a_new, b_new): (&[SVector<f64, N>; 3], &[f64; 3]),
        dt: f64,
        (level_a, level_b): (&mut [SVector<f64, N>; 3], &mut [f64; 3]),
    ) -> Option<TrendStep<N>> {
        // Predict, then the innovation's variance `a + 1` and the gains.
        let (a, b) = (a + dt * (2.0 * b + dt * c), b + dt * c);
        let f = a + 1.0;
        let (w, kx, kt) = (1.0 / crate::math::sqrt(f), a / f, b / f);
        // `c − b²/f` is ≥ 0 in exact arithmetic: rounding below zero is clamped, only a
        // non-finite state stops the filter (as in the full path).
        let next = Covariance::Kronecker {
            a: a / f,
            b: b / f,
            c: (c - b * b / f).max(0.0),
        };
        if !(w.is_finite() && a.is_finite() && b.is_finite() && c.is_finite()) {
            return None;
        }
        let mut rows = [SVector::<f64, N>::zeros(); 3];
        let mut beta = [0.0; 3];
        for m in 0..3 {
            level_a[m] += self.tau_a[m] * dt;
            level_b[m] += self.tau_b[m] * dt;
            let da = a_new[m] - level_a[m];
            let db = b_new[m] - level_b[m];
            rows[m] = da * w;
            beta[m] = db * w;
            level_a[m] += da * kx;
            level_b[m] += db * kx;
            self.tau_a[m] += da * kt;
            self.tau_b[m] += db * kt;
        }
        self.p = Some(next);
        Some(TrendStep::Row((rows, beta)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// The least-squares solution of the `rhs.len()` rows of `n` columns in `rows`
    /// (row-major): its first `lead` unknowns and the residual sum of squares.
    fn least_squares(rows: &[f64], rhs: Vec<f64>, n: usize, lead: usize) -> (DVector<f64>, f64) {
        let a = DMatrix::from_row_slice(rhs.len(), n, rows);
        let b = DVector::from_vec(rhs);
        let x = a.clone().svd(true, true).solve(&b, 1e-14).expect("solve");
        let rss = (&a * &x - &b).norm_squared();
        (x.rows(0, lead).into_owned(), rss)
    }

    /// The filter's rows are the dense generalised least-squares problem: for blocks
    /// `−X_k + a_k y = b_k` with `X_k = X₀ + s_k τ + Σ w` (`w` of given covariances),
    /// minimising over `X₀`, `τ`, the drift path and `y` with unit white block noise gives
    /// the same `y` and residual sum of squares as ordinary least squares on the filter's
    /// rows (the first two blocks absorbed), to 1e-9; without drift, with drift, and with
    /// a drift from the middle on (the scalar covariance made full), at unequal steps.
    #[test]
    fn the_trend_filters_rows_are_the_dense_generalised_least_squares() {
        const N: usize = 4;
        for (drift, from) in [(0.0, 0), (0.3, 0), (0.3, 7)] {
            let blocks = 14;
            let mut rnd = crate::testing::uniform(11);
            let a: Vec<[SVector<f64, N>; 3]> = (0..blocks)
                .map(|_| core::array::from_fn(|_| SVector::from_fn(|_, _| rnd())))
                .collect();
            let b: Vec<[f64; 3]> = (0..blocks)
                .map(|_| core::array::from_fn(|_| rnd()))
                .collect();
            let mut s = vec![0.0];
            for k in 1..blocks {
                s.push(s[k - 1] + 0.5 + 0.4 * rnd().abs());
            }
            let qs: Vec<Matrix3<f64>> = (0..blocks)
                .map(|k| {
                    let m = Matrix3::from_fn(|_, _| rnd()) * drift;
                    m * m.transpose() * f64::from(u8::from(k >= from))
                })
                .collect();
            // The blocks whose drift is an unknown (w fixed at zero where q is).
            let drifting: Vec<usize> = (1..blocks).filter(|&k| qs[k] != Matrix3::zeros()).collect();
            // The filter.
            let (mut la, mut lb) = (a[0], b[0]);
            let mut trend = Trend::<N>::start(s[0]);
            let (mut fa, mut fb): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
            for k in 1..blocks {
                match trend
                    .step((&a[k], &b[k]), s[k], (&mut la, &mut lb), &qs[k])
                    .expect("finite")
                {
                    TrendStep::Absorbed => assert_eq!(k, 1),
                    TrendStep::Row((r, beta)) => {
                        for r in &r {
                            fa.extend(r.iter());
                        }
                        fb.extend(beta);
                    }
                }
            }
            let (f_y, f_rss) = least_squares(&fa, fb, N, N);
            // The dense problem: unknowns [y; X₀; τ; w_1..w_{K−1}], the w rows whitened
            // by their covariance (zero covariance: w fixed at zero, left out).
            let nw = 3 * drifting.len();
            let n = N + 6 + nw;
            let mut rows: Vec<f64> = Vec::new();
            let mut rhs = Vec::new();
            for k in 0..blocks {
                for m in 0..3 {
                    let mut r = DVector::zeros(n);
                    r.rows_mut(0, N).copy_from(&a[k][m]);
                    r[N + m] = -1.0;
                    r[N + 3 + m] = -(s[k] - s[0]);
                    for (d, _) in drifting.iter().enumerate().filter(|(_, &i)| i <= k) {
                        r[N + 6 + 3 * d + m] = -1.0;
                    }
                    rows.extend(r.iter());
                    rhs.push(b[k][m]);
                }
            }
            for (d, &k) in drifting.iter().enumerate() {
                let w = qs[k]
                    .cholesky()
                    .expect("pd")
                    .l()
                    .try_inverse()
                    .expect("inv");
                for m in 0..3 {
                    let mut r = DVector::zeros(n);
                    for c in 0..3 {
                        r[N + 6 + 3 * d + c] = w[(m, c)];
                    }
                    rows.extend(r.iter());
                    rhs.push(0.0);
                }
            }
            let (d_y, d_rss) = least_squares(&rows, rhs, n, N);
            assert!(
                (f_y - &d_y).norm() < 1e-9 * d_y.norm(),
                "drift {drift} from {from}"
            );
            assert!(
                (f_rss - d_rss).abs() < 1e-9 * d_rss,
                "drift {drift} from {from}"
            );
        }
    }

    /// Problem: 12 blocks at unequal steps, forgetting `λ` before every block from the
    /// second on (so between the first and the second too), no drift. Reference: the
    /// dense weighted least squares over `[y; X₀; τ]`, block k weighted `λ^(K−1−k)`, and
    /// the filter's rows weighted as the shared state weighs them. Same `y` and residual
    /// to 1e-9.
    #[test]
    fn forgetting_weighs_the_trend_as_the_dense_weighted_fit() {
        const N: usize = 3;
        for lambda in [0.7, 0.999] {
            let blocks = 12;
            let mut rnd = crate::testing::uniform(5);
            let a: Vec<[SVector<f64, N>; 3]> = (0..blocks)
                .map(|_| core::array::from_fn(|_| SVector::from_fn(|_, _| rnd())))
                .collect();
            let b: Vec<[f64; 3]> = (0..blocks)
                .map(|_| core::array::from_fn(|_| rnd()))
                .collect();
            let s: Vec<f64> = (0..blocks).map(|k| k as f64 * 0.7 + 0.1 * rnd()).collect();
            let (mut la, mut lb) = (a[0], b[0]);
            let mut trend = Trend::<N>::start(s[0]);
            let mut rows: Vec<(usize, [SVector<f64, N>; 3], [f64; 3])> = Vec::new();
            for k in 1..blocks {
                trend.scale(lambda);
                if let TrendStep::Row((r, beta)) = trend
                    .step((&a[k], &b[k]), s[k], (&mut la, &mut lb), &Matrix3::zeros())
                    .expect("finite")
                {
                    rows.push((k, r, beta));
                }
            }
            let weight = |k: usize| lambda.powi((blocks - 1 - k) as i32).sqrt();
            let (mut fa, mut fb): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
            for (k, r, beta) in &rows {
                for m in 0..3 {
                    fa.extend(r[m].iter().map(|v| v * weight(*k)));
                    fb.push(beta[m] * weight(*k));
                }
            }
            let (f_y, f_rss) = least_squares(&fa, fb, N, N);
            let n = N + 6;
            let (mut da, mut db): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
            for k in 0..blocks {
                for m in 0..3 {
                    let mut r = DVector::zeros(n);
                    r.rows_mut(0, N).copy_from(&a[k][m]);
                    r[N + m] = -1.0;
                    r[N + 3 + m] = -(s[k] - s[0]);
                    da.extend(r.iter().map(|v| v * weight(k)));
                    db.push(b[k][m] * weight(k));
                }
            }
            let (d_y, d_rss) = least_squares(&da, db, n, N);
            assert!((f_y - &d_y).norm() < 1e-9 * d_y.norm(), "λ {lambda}");
            assert!((f_rss - d_rss).abs() < 1e-9 * d_rss, "λ {lambda}");
        }
    }

    /// A step that does not advance, or a non-finite one, stops the filter.
    #[test]
    fn a_step_that_does_not_advance_is_refused() {
        let (mut la, mut lb) = ([SVector::<f64, 2>::zeros(); 3], [0.0; 3]);
        let a = [SVector::<f64, 2>::zeros(); 3];
        let mut t = Trend::<2>::start(1.0);
        let q = Matrix3::zeros();
        assert!(t
            .step((&a, &[0.0; 3]), 1.0, (&mut la, &mut lb), &q)
            .is_none());
        assert!(t
            .step((&a, &[0.0; 3]), f64::NAN, (&mut la, &mut lb), &q)
            .is_none());
        assert_eq!(
            t.step((&a, &[0.0; 3]), 2.0, (&mut la, &mut lb), &q),
            Some(TrendStep::Absorbed)
        );
    }
}
