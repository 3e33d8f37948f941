//! The wheel-speed telemetry's time tag: `ρ` telemetered `δ` late, `ρ_meas(t) = ρ(t − δ)`,
//! known or estimated, and the consider term its uncertainty adds to σ (issue #31).
//!
//! # Why a shift and not a column
//!
//! To first order `ρ(t) = ρ_meas(t + δ) ≈ ρ_meas(t) + δ ρ̇(t)`, so `δ` could be one more
//! unknown of the momentum rows (`discrete_momentum.rs`) with the column
//! `C_k N(φ_k) ρ̇̄_k`. But wheel speeds are often held between telemetry updates (a
//! staircase), whose `ρ̇` is a train of spikes: the column must then come from a smoothed
//! `ρ̇`, and on the lab throw ([`crate::sim::presets`], speed held at 100 Hz, so 5 ms late
//! on average) the rows corrected by `5 ms × ρ̇` smoothed over four updates are 2.7e-3
//! off, against 5e-4 for the same rows with `ρ` read 5 ms later by interpolation: the
//! estimate leans on the spin-up's corners, where a smoothed `ρ̇` is wrong. So the time
//! tag is applied exactly, as a shift of the speed telemetry ([`shift_rho`]), and
//! estimated by profiling (`estimate`).
//!
//! # The profile
//!
//! For each trial `δ` the record's `ρ` is read at `t + δ` (the cubic through the four
//! nearest samples, held at the ends of each stretch between gaps, [`shift_rho`]) and the
//! estimator's plain discrete momentum rows are fitted by least squares in `[τ_b; j]`,
//! with each chain's initial momentum `L̄₀` and a torque fixed in the inertial frame `τ_I`
//! minimised out per chain ([`crate::estimator::momentum_rows`], "Inertial torque"): a
//! disturbance of either kind must not pass for a time tag. `δ̂` minimises the residual
//! sum of squares `RSS(δ)`: on a grid of `GRID` steps each side over `±H`,
//! `H = min(MAX_HALF_RANGE_S, T/10)` with `T` the shortest stretch between gaps (of
//! at least 16 samples), then on a fine grid over two steps each side of the best node,
//! whose least-squares parabola's vertex is `δ̂` (the profile wiggles at the sample
//! period where the speeds are held; the parabola smooths that). Only the rows of each
//! stretch whose samples keep every trial's `t + δ` inside it are fitted, so every trial
//! fits the same rows.
//!
//! # σ
//!
//! `δ̂`'s standard deviation is the sandwich over time blocks: with `r_k` the rows'
//! residuals at `δ̂` and `d_k = ∂r_k/∂δ` with `[τ_b; j]` and each chain's unknowns
//! minimised out (the least-squares residual of the column `d` on the same regressors),
//! `var δ̂ = B/(B−1) · Σ_b (Σ_{k∈b} d_k r_k)² / (Σ_k d_k²)²` over `B` = `BLOCKS`
//! contiguous blocks of rows, so residuals correlated within a block count once. Its
//! effect on the answer, the consider term, is `|∂ĵ/∂δ| σ_δ` per element, `∂ĵ/∂δ` from
//! the same fit at `δ̂ ±` one grid step, as `d_k` (`DelayFit::consider_kg_m2`).
//!
//! Without a time tag, where the speeds are held between updates
//! (`crate::telemetry::held_speeds`) the σ of a run's final answer carries the move of
//! the plain fit's `ĵ` for their mean lag instead (`held_lag_move`): a bias the data show
//! and the answer keeps.
//!
//! What σ leaves out: the plain rows' own O(h²) bias (about −50 µs at 10 Hz, within 2σ
//! on the slew), and the difference between this fit's `∂ĵ/∂δ` and the estimator's.
//! The samples' times must increase strictly (the run's sample gate checks that). Cost:
//! about 90 fits of the record's rows, and some 0.3 KB per sample while it runs.

use super::momentum_rows::{MomentumRowSettings, MomentumRows, OutsideTorques, Stencil, J, TORQUE};
use super::plain_fit::{fit, residuals, rhs, Fit, Rows};
use crate::sample::Sample;
use nalgebra::Vector3;
use std::vec::Vec;

/// Largest time tag searched, s, each side of zero.
pub(crate) const MAX_HALF_RANGE_S: f64 = 0.25;

/// Grid steps each side of zero in the search.
pub(crate) const GRID: usize = 20;

/// Contiguous blocks of rows in the sandwich σ of `δ̂`.
pub(crate) const BLOCKS: usize = 16;

/// What the run knows of the wheel-speed telemetry's time tag.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum WheelDelay {
    /// Taken as right (default).
    #[default]
    Off,
    /// Known: `ρ` telemetered this many seconds late (negative: early).
    KnownS(f64),
    /// Estimated from the data (`estimate`).
    Estimate,
}

impl core::str::FromStr for WheelDelay {
    type Err = ();

    /// `off`, `estimate`, or the delay in seconds (finite).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "off" => Ok(WheelDelay::Off),
            "estimate" => Ok(WheelDelay::Estimate),
            _ => match s.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(WheelDelay::KnownS(x)),
                _ => Err(()),
            },
        }
    }
}

/// The wheel-speed time tag a run applied.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DelayFit {
    /// `δ`, s: `ρ` was read at `t + δ`.
    pub delay_s: f64,
    /// Its standard deviation, s (zero when given).
    pub sigma_s: f64,
    /// Whether it was estimated (`estimate`) or given.
    pub estimated: bool,
    /// The half-width of the search, s (zero when given).
    pub half_range_s: f64,
    /// `∂ĵ/∂δ`, kg m² / s, of the profile's fit (zero when given).
    pub dj_ds: [f64; 6],
}

impl DelayFit {
    /// A time tag the user gave.
    #[must_use]
    pub(crate) fn known(delay_s: f64) -> Self {
        Self {
            delay_s,
            sigma_s: 0.0,
            estimated: false,
            half_range_s: 0.0,
            dj_ds: [0.0; 6],
        }
    }

    /// The consider term per element, `|∂ĵ/∂δ| σ_δ`, kg m².
    #[must_use]
    pub(crate) fn consider_kg_m2(&self) -> [f64; 6] {
        core::array::from_fn(|k| (self.dj_ds[k] * self.sigma_s).abs())
    }
}

/// Why the time tag could not be estimated.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DelayError {
    /// Too few rows inside the search window, or no rotor momentum change among them.
    #[error("the wheel-speed time tag cannot be estimated from these data: {0}")]
    NotEstimable(&'static str),
}

/// Read every sample's `ρ` at `t + delay_s`: the cubic through the four nearest samples
/// (linear in the first and last interval), the first or last value beyond the record's
/// ends.
pub fn shift_rho(samples: &mut [Sample], delay_s: f64) {
    if delay_s == 0.0 || samples.is_empty() {
        return;
    }
    let rho: Vec<Vector3<f64>> = samples.iter().map(|s| s.rho_nms).collect();
    let t: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
    for (a, b) in segments(&t) {
        for k in a..=b {
            samples[k].rho_nms = interpolate(&t[a..=b], &rho[a..=b], k - a, t[k] + delay_s);
        }
    }
}

/// The stretches of samples between gaps ([`crate::sample::is_gap`]), first and last
/// index of each: a time tag reads the speeds within a stretch, never across a gap (as
/// between the records of a run).
fn segments(t: &[f64]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for k in 2..t.len() {
        if crate::sample::is_gap(t[k - 1] - t[k - 2], t[k] - t[k - 1]) {
            out.push((start, k - 1));
            start = k;
        }
    }
    if !t.is_empty() {
        out.push((start, t.len() - 1));
    }
    out
}

/// `ρ` at time `x`, interpolated, starting the search at sample `k`.
fn interpolate(t: &[f64], rho: &[Vector3<f64>], k: usize, x: f64) -> Vector3<f64> {
    interpolate_from(t, rho, k, x).0
}

/// `ρ` at time `x`, interpolated, starting the search at sample `k`; and the start of
/// the interval that holds `x`, for the next search.
fn interpolate_from(t: &[f64], rho: &[Vector3<f64>], k: usize, x: f64) -> (Vector3<f64>, usize) {
    let n = t.len();
    if x <= t[0] {
        return (rho[0], 0);
    }
    if x >= t[n - 1] {
        return (rho[n - 1], n - 1);
    }
    // The interval [t_i, t_{i+1}] holding x, searched from k (the shift is small).
    let mut i = k.min(n - 2);
    while t[i] > x {
        i -= 1;
    }
    while t[i + 1] < x {
        i += 1;
    }
    if i == 0 || i + 2 >= n {
        let w = (x - t[i]) / (t[i + 1] - t[i]);
        return (rho[i] * (1.0 - w) + rho[i + 1] * w, i);
    }
    // The cubic through the four nearest samples (as the resampler's): smooth in x
    // across the samples, so the profile in δ has no kink where x crosses one.
    let w = super::resample::lagrange_weights(&[t[i - 1], t[i], t[i + 1], t[i + 2]], x);
    (
        rho[i - 1] * w[0] + rho[i] * w[1] + rho[i + 1] * w[2] + rho[i + 2] * w[3],
        i,
    )
}

/// A stretch of rows to fit: its first and last sample, and the first and last sample of
/// the stretch between gaps that holds it ([`segments`]).
type Window = (usize, usize, usize, usize);

fn rows(samples: &[Sample], windows: &[Window], delay_s: f64, outside: &OutsideTorques) -> Rows {
    let t: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
    let rho: Vec<Vector3<f64>> = samples.iter().map(|s| s.rho_nms).collect();
    let mut out = Rows {
        blocks: Vec::with_capacity(windows.iter().map(|w| w.1 + 1 - w.0).sum()),
        chains: 0,
    };
    // The estimator's own plain rows ([`super::momentum_rows`]), each block's inertial
    // torque coefficient with it; a chain is an epoch of theirs that gave rows.
    let mut source = MomentumRows::new(MomentumRowSettings {
        stencil: Stencil::Plain,
        torque_bias: true,
        inertial_torque: true,
        outside: *outside,
        ..MomentumRowSettings::default()
    });
    let mut epoch = None;
    // Between windows the samples jump a gap: the rows restart their chain there.
    let samples_in = windows
        .iter()
        .flat_map(|&(lo, hi, a, b)| (lo..=hi).map(move |k| (k, a, b)));
    // The shifted times increase with k: the search for each starts where the last ended.
    let mut cursor = 0;
    let mut segment_start = usize::MAX;
    for (k, a, b) in samples_in {
        let s = &samples[k];
        if a != segment_start {
            segment_start = a;
            cursor = 0;
        }
        let (rho_k, i) = interpolate_from(&t[a..=b], &rho[a..=b], cursor, t[k] + delay_s);
        cursor = i;
        let shifted = Sample {
            rho_nms: rho_k,
            ..*s
        };
        // A step the rows cannot use restarts the chain, as in the estimator.
        let Ok(Some(row)) = source.push(&shifted) else {
            continue;
        };
        if epoch != Some(source.epoch()) {
            epoch = Some(source.epoch());
            out.chains += 1;
        }
        out.blocks.push((
            out.chains - 1,
            row.a.fixed_view::<3, 3>(0, TORQUE).into_owned(),
            row.a.fixed_view::<3, 6>(0, J).into_owned(),
            row.trend_s,
            row.b,
        ));
    }
    out
}

/// `RSS(δ)` and `ĵ(δ)`, or `None` where the fit is singular.
fn profile(
    samples: &[Sample],
    windows: &[Window],
    delay_s: f64,
    outside: &OutsideTorques,
) -> Option<(f64, Fit)> {
    let r = rows(samples, windows, delay_s, outside);
    let f = fit(&r, &rhs(&r))?;
    Some((f.rss, f))
}

/// The vertex `x` of the least-squares parabola through `(x, y)` points, where it opens
/// upwards and lies within their span.
fn parabola_vertex(p: &[(f64, f64)]) -> Option<f64> {
    let mut n = nalgebra::Matrix3::<f64>::zeros();
    let mut r = Vector3::<f64>::zeros();
    for &(x, y) in p {
        let v = Vector3::new(1.0, x, x * x);
        n += v * v.transpose();
        r += v * y;
    }
    let c = n.cholesky()?.solve(&r);
    let (lo, hi) = p
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q.0), b.max(q.0))
        });
    let x = -c[1] / (2.0 * c[2]);
    (c[2] > 0.0 && x >= lo && x <= hi).then_some(x)
}

/// Estimate the wheel-speed telemetry's time tag from `samples` ([module docs](self)),
/// the rows modelling the gravity gradient as the run's `outside` says.
pub(crate) fn estimate(
    samples: &[Sample],
    outside: &OutsideTorques,
) -> Result<DelayFit, DelayError> {
    let n = samples.len();
    if n < 8 {
        return Err(DelayError::NotEstimable("too few samples"));
    }
    // The profile's small fit has no residual dipole or centre of mass: refused rather
    // than biased by their torque.
    if samples.iter().any(|s| {
        (outside.residual_dipole && s.external.field_t.is_some())
            || (outside.centre_of_mass && s.external.force_n.is_some())
    }) {
        return Err(DelayError::NotEstimable(
            "its profile does not model a residual magnetic dipole or the centre of mass (the input has a magnetic field or a force): give the time tag in seconds, or leave it off",
        ));
    }
    let t: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
    // The stretches between gaps (records), and the shortest of them that matter.
    let stretches: Vec<(usize, usize)> = segments(&t)
        .into_iter()
        .filter(|&(a, b)| b >= a + 16)
        .collect();
    let shortest = stretches
        .iter()
        .map(|&(a, b)| t[b] - t[a])
        .fold(f64::INFINITY, f64::min);
    let half = MAX_HALF_RANGE_S.min(shortest / 10.0);
    let step = half / GRID as f64;
    // The trials reach ±(H + 2 steps): the fine grid about a node at most H − 1 step
    // out, and the derivative a step beyond; one step more of margin, within each
    // stretch, so that no trial reads a speed across a gap or beyond the record.
    let margin = half + 3.0 * step;
    let windows: Vec<Window> = stretches
        .iter()
        .filter_map(|&(a, b)| {
            let lo = a + t[a..=b].partition_point(|&x| x < t[a] + margin);
            let hi = (a + t[a..=b].partition_point(|&x| x <= t[b] - margin)).checked_sub(1)?;
            (hi >= lo + 8).then_some((lo, hi, a, b))
        })
        .collect();
    if windows.is_empty() || !(half > 0.0) {
        return Err(DelayError::NotEstimable(
            "too few samples inside the search window",
        ));
    }
    let windows = &windows[..];
    let rho0 = samples[windows[0].0].rho_nms;
    if windows
        .iter()
        .all(|&(lo, hi, ..)| samples[lo..=hi].iter().all(|s| s.rho_nms == rho0))
    {
        return Err(DelayError::NotEstimable(
            "the rotor momentum does not change",
        ));
    }
    let eval = |d: f64| profile(samples, windows, d, outside).map_or(f64::INFINITY, |p| p.0);
    let grid: Vec<(f64, f64)> = (0..=2 * GRID)
        .map(|i| {
            let d = -half + step * i as f64;
            (d, eval(d))
        })
        .collect();
    let (best, &(d_best, rss_best)) = grid
        .iter()
        .enumerate()
        .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
        .ok_or(DelayError::NotEstimable("no trial"))?;
    if !rss_best.is_finite() {
        return Err(DelayError::NotEstimable(
            "the rows do not determine the inertia",
        ));
    }
    if best == 0 || best == 2 * GRID {
        return Err(DelayError::NotEstimable(
            "the best time tag lies at the edge of the search",
        ));
    }
    // A fine grid over two coarse steps each side of the best node, and the vertex of
    // the least-squares parabola through it: the profile wiggles at the scale of the
    // sample period where the speed telemetry is held, and the parabola smooths that.
    let fine: Vec<(f64, f64)> = (0..=2 * GRID)
        .map(|i| {
            let x = (i as f64 - GRID as f64) / GRID as f64 * 2.0;
            (x, eval(d_best + x * step))
        })
        .filter(|p| p.1.is_finite())
        .collect();
    let delay = d_best + step * parabola_vertex(&fine).unwrap_or(0.0);
    let r = rows(samples, windows, delay, outside);
    let y = rhs(&r);
    let f = fit(&r, &y).ok_or(DelayError::NotEstimable("singular fit"))?;
    // ∂r/∂δ at fixed unknowns, then residualised on the regressors (the same fit).
    let eps = step;
    // The rows a step either side, one at a time: their right-hand sides and answers.
    let side = |d: f64| {
        let r = rows(samples, windows, d, outside);
        let y = rhs(&r);
        let j = fit(&r, &y).map(|f| f.theta);
        (y, j)
    };
    let (yp, jp) = side(delay + eps);
    let (ym, jm) = side(delay - eps);
    let col: Vec<Vector3<f64>> = yp
        .iter()
        .zip(&ym)
        .map(|(p, m)| (p - m) / (2.0 * eps))
        .collect();
    drop((yp, ym));
    let fd_col = fit(&r, &col).ok_or(DelayError::NotEstimable("singular fit"))?;
    let dcol = residuals(&r, &col, &fd_col);
    let res = residuals(&r, &y, &f);
    let info: f64 = dcol.iter().map(|v| v.norm_squared()).sum();
    let y_energy: f64 = y.iter().map(|v| v.norm_squared()).sum();
    if !(info * half * half > 1e-12 * y_energy) {
        return Err(DelayError::NotEstimable(
            "the rotor momentum does not change",
        ));
    }
    let per = r.blocks.len().div_ceil(BLOCKS).max(1);
    let scores: Vec<f64> = dcol
        .chunks(per)
        .zip(res.chunks(per))
        .map(|(dc, rc)| dc.iter().zip(rc).map(|(a, b)| a.dot(b)).sum())
        .collect();
    let nb = scores.len() as f64;
    let var = if nb > 1.0 {
        nb / (nb - 1.0) * scores.iter().map(|s| s * s).sum::<f64>() / (info * info)
    } else {
        f.rss / f.dof.max(1.0) / info
    };
    let dj_ds = match (jp, jm) {
        (Some(p), Some(m)) => core::array::from_fn(|k| (p[3 + k] - m[3 + k]) / (2.0 * eps)),
        _ => [0.0; 6],
    };
    Ok(DelayFit {
        delay_s: delay,
        sigma_s: var.sqrt(),
        estimated: true,
        half_range_s: half,
        dj_ds,
    })
}

/// The move of the profile's `ĵ` (its plain rows, [`rows`]) when the speeds are read
/// `lag_s` later, per element, kg m²: the bias of an answer that reads at their time
/// stamps speeds held between updates, late by `lag_s` on average
/// ([`crate::telemetry::held_speeds`]). Both fits use the same rows: those whose samples
/// keep `t + lag_s` inside their stretch between gaps. `None` where the rows do not
/// determine `ĵ`.
pub(crate) fn held_lag_move(
    samples: &[Sample],
    outside: &OutsideTorques,
    lag_s: f64,
) -> Option<[f64; 6]> {
    if !(lag_s > 0.0) {
        return None;
    }
    let t: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
    let windows: Vec<Window> = segments(&t)
        .into_iter()
        .filter_map(|(a, b)| {
            let hi = (a + t[a..=b].partition_point(|&x| x <= t[b] - lag_s)).checked_sub(1)?;
            (hi >= a + 8).then_some((a, hi, a, b))
        })
        .collect();
    let j = |d: f64| profile(samples, &windows, d, outside).map(|(_, f)| f.theta);
    let (late, now) = (j(lag_s)?, j(0.0)?);
    let out: [f64; 6] = core::array::from_fn(|k| (late[3 + k] - now[3 + k]).abs());
    out.iter().all(|x| x.is_finite()).then_some(out)
}

#[cfg(test)]
mod tests;
