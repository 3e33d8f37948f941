//! Sensor models: an integrating (delta-angle) rate gyro.
//!
//! Over each sample interval `[t_k, t_{k+1}]` the gyro reports the body-frame angle
//! increment `∫ω dt + n_k`, with `n_k ~ N(0, σ² h)` per axis for a rate noise spectral
//! density σ (rad/s/√Hz; the angle random walk). The reported rate is that increment over
//! h, i.e. the average rate over the interval. The attitude solution is propagated from
//! the same noisy increments, `q̃_{k+1} = q̃_k (q_k† q_{k+1}) exp(n_k)`, i.e. an ideal
//! (coning-compensated) strapdown integration whose only error is the gyro noise.
//!
//! The simulator now samples the gyro through [`super::gyro::Gyro`], which draws the same
//! noise from the same stream and adds bias and bias instability when they are set;
//! [`IntegratingGyro`] remains as the plain model.

use crate::attitude::Quaternion;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Degrees to radians.
pub const DEG: f64 = core::f64::consts::PI / 180.0;

/// An integrating gyro with white rate noise.
#[derive(Debug, Clone)]
pub struct IntegratingGyro {
    rng: ChaCha8Rng,
    noise: Normal<f64>,
    h_s: f64,
}

impl IntegratingGyro {
    /// `noise_deg_s_rthz` is the rate noise spectral density in deg/s/√Hz, `h_s` the
    /// sample period; the noise stream is stream 1 of ChaCha8 seeded with `seed`.
    #[must_use]
    pub fn new(noise_deg_s_rthz: f64, h_s: f64, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(1);
        let sigma = (noise_deg_s_rthz * DEG * h_s.sqrt()).abs();
        Self {
            rng,
            noise: normal(sigma),
            h_s,
        }
    }

    /// Measure one interval with true increment `q_k† q_{k+1}` and true `∫ω dt`.
    /// Returns the noisy increment and the reported average rate, rad/s.
    pub fn measure(
        &mut self,
        true_increment: &Quaternion,
        true_angle: &Vector3<f64>,
    ) -> (Quaternion, Vector3<f64>) {
        let n = Vector3::from_fn(|_, _| self.noise.sample(&mut self.rng));
        let inc = true_increment.mul(&Quaternion::exp(&n));
        (inc, (true_angle + n) / self.h_s)
    }
}

/// A zero-mean normal distribution with standard deviation `sigma`; a non-finite or
/// negative `sigma` (rejected earlier by [`super::SimConfig::validate`]) gives zero noise.
#[must_use]
pub fn normal(sigma: f64) -> Normal<f64> {
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
