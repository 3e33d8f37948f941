//! Sensor model helpers ([`DEG`] and the zero-mean normal noise of every sensor) and the
//! plain integrating (delta-angle) rate gyro of the paper's model.
//!
//! Over each sample interval `[t_k, t_{k+1}]` the gyro reports the body-frame angle
//! increment `∫ω dt + n_k`, with `n_k ~ N(0, σ² h)` per axis for a rate noise spectral
//! density σ (rad/s/√Hz; the angle random walk). The reported rate is that increment over
//! h, i.e. the average rate over the interval. The attitude solution is propagated from
//! the same noisy increments, `q̃_{k+1} = q̃_k (q_k† q_{k+1}) exp(n_k)`, i.e. an ideal
//! (coning-compensated) strapdown integration whose only error is the gyro noise.
//!
//! The gyro of [`super::gyro`] draws that noise from stream 1 and adds bias and bias
//! instability when they are set.

use rand_distr::Normal;

/// Degrees to radians.
pub const DEG: f64 = core::f64::consts::PI / 180.0;

/// A zero-mean normal distribution with standard deviation `sigma`; a non-finite or
/// negative `sigma` (rejected earlier by [`super::SimConfig::validate`]) gives zero noise.
#[must_use]
pub(crate) fn normal(sigma: f64) -> Normal<f64> {
    let s = if sigma.is_finite() && sigma > 0.0 {
        sigma
    } else {
        0.0
    };
    match Normal::new(0.0, s) {
        Ok(n) => n,
        // `Normal::new` fails only for a non-finite or negative deviation, excluded above.
        Err(_) => unreachable!("N(0, s) with finite s >= 0 is valid"),
    }
}
