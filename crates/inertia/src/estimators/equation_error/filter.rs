//! The zero-phase low-pass filter and differentiator of the equation-error baseline: a
//! Savitzky–Golay filter (a least-squares polynomial of order [`ORDER`] over a centred
//! window of `2m + 1` samples, evaluated with its first two derivatives at the centre).
//!
//! For samples `y_{k+i}`, `i = −m…m`, at step h, the polynomial `Σ_d a_d x^d` with
//! `x = i/m` fitted by least squares gives `y(t_k) ≈ a_0`, `ẏ(t_k) ≈ a_1/(m h)` and
//! `ÿ(t_k) ≈ 2 a_2/(m h)²`: each a fixed linear combination of the window (the weights
//! [`SavitzkyGolay::smooth`], [`SavitzkyGolay::d1`], [`SavitzkyGolay::d2`]). The window is
//! symmetric, so the filter has zero phase. With the order 4, the first derivative is
//! exact for polynomials of degree ≤ 4 and the second for degree ≤ 5, so for a window of
//! fixed length in samples the derivatives' error falls as h⁴.
//!
//! Its −3 dB cutoff is about `f_c ≈ (ORDER + 1) f_s / (3.2 N − 4.6)` for `N = 2m + 1`
//! samples at the rate `f_s` (Schafer, "What is a Savitzky–Golay filter?", IEEE Signal
//! Processing Magazine 28(4), 2011), which [`SavitzkyGolay::for_cutoff`] inverts.

use nalgebra::{SMatrix, SVector};
use std::vec::Vec;

/// The polynomial order.
pub(crate) const ORDER: usize = 4;
/// The smallest half-width m (a window of 7 samples for 5 coefficients).
pub(crate) const MIN_HALF_WIDTH: usize = 3;

/// Weights of one window.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SavitzkyGolay {
    /// Half-width m: the window is `2m + 1` samples.
    pub(crate) half_width: usize,
    /// Weights of the smoothed value at the centre.
    pub(crate) smooth: Vec<f64>,
    /// Weights of the first derivative at the centre, per unit step (divide by h).
    pub(crate) d1: Vec<f64>,
    /// Weights of the second derivative at the centre, per unit step² (divide by h²).
    pub(crate) d2: Vec<f64>,
}

impl SavitzkyGolay {
    /// The weights for half-width `m` (at least [`MIN_HALF_WIDTH`]).
    #[must_use]
    pub(crate) fn new(half_width: usize) -> Self {
        let m = half_width.max(MIN_HALF_WIDTH);
        let n = 2 * m + 1;
        let scale = m as f64;
        let powers = |i: usize| {
            let x = (i as f64 - scale) / scale;
            SVector::<f64, 5>::from_fn(|d, _| x.powi(d as i32))
        };
        let mut vtv = SMatrix::<f64, 5, 5>::zeros();
        for i in 0..n {
            let p = powers(i);
            vtv += p * p.transpose();
        }
        // VᵀV of distinct abscissae is positive definite (n > ORDER).
        let inv = vtv
            .cholesky()
            .map(|c| c.inverse())
            .unwrap_or_else(SMatrix::zeros);
        let weight = |d: usize, factor: f64| -> Vec<f64> {
            (0..n)
                .map(|i| (inv.row(d) * powers(i))[0] * factor)
                .collect()
        };
        Self {
            half_width: m,
            smooth: weight(0, 1.0),
            d1: weight(1, 1.0 / scale),
            d2: weight(2, 2.0 / (scale * scale)),
        }
    }

    /// The window whose −3 dB cutoff is nearest `cutoff_hz` at the sample rate
    /// `rate_hz` (module docs), at least [`MIN_HALF_WIDTH`].
    #[must_use]
    pub(crate) fn for_cutoff(cutoff_hz: f64, rate_hz: f64) -> Self {
        let n = ((ORDER + 1) as f64 * rate_hz / cutoff_hz + 4.6) / 3.2;
        let m = ((n - 1.0) / 2.0).round();
        Self::new(if m.is_finite() && m > 0.0 {
            m as usize
        } else {
            0
        })
    }

    /// The window length, samples.
    #[must_use]
    pub(crate) fn window_len(&self) -> usize {
        2 * self.half_width + 1
    }
}

/// `Σ_i w_i y_i` over a window of vectors.
#[must_use]
pub(crate) fn apply<'a>(
    weights: &[f64],
    window: impl Iterator<Item = &'a nalgebra::Vector3<f64>>,
) -> nalgebra::Vector3<f64> {
    weights
        .iter()
        .zip(window)
        .fold(nalgebra::Vector3::zeros(), |acc, (w, y)| acc + y * *w)
}
