//! The rate-integrating gyro: angle random walk, a constant bias and bias instability.
//!
//! Over each integration interval `[t_b, t_b + h]` (h = [`super::SimConfig::dt_s`]) the
//! gyro reports the body-frame delta angle
//!
//! ```text
//! Δθ̃_b = ∫ω dt + n_b + (b₀ + β_b) h,     n_b ~ N(0, σ² h) per axis
//! ```
//!
//! * `σ` is the angle random walk, given as the rate-noise spectral density
//!   [`super::SimConfig::gyro_noise_deg_s_rthz`] in deg/s/√Hz. Datasheets quote ARW in
//!   deg/√h; `1 deg/√h = 1/60 deg/s/√Hz` ([`arw_deg_rthr_to_deg_s_rthz`]), because
//!   `1/√h = 1/√(3600 s)` and `1 deg/s/√Hz = 1 deg/√s`.
//! * `b₀` is a constant bias ([`GyroErrors::bias_deg_h`], deg/h per body axis).
//! * `β` is the bias instability: a first-order Gauss–Markov process per axis with
//!   stationary standard deviation `B` ([`GyroErrors::bias_instability_deg_h`], deg/h) and
//!   correlation time `τ_c` ([`GyroErrors::bias_correlation_s`]),
//!   `β_{b+1} = a β_b + B √(1 − a²) w_b`, `a = e^{−h/τ_c}`, `w_b ~ N(0, 1)`.
//!   It starts at `β = 0` at `t0_s`, so its variance grows as `B² (1 − e^{−2t/τ_c})`,
//!   about `2 B² t/τ_c` for `t ≪ τ_c` (a rate random walk of density `B √(2/τ_c)`).
//!   The bias is held constant over each interval.
//!
//! Decimated telemetry ([`super::Realism::telemetry_every`]) reports the sum of these
//! delta angles over the telemetry step. The gyro-propagated attitude advances by
//! `q̃_{b+1} = q̃_b (q_b† q_{b+1}) exp(n_b + (b₀ + β_b) h)`: an ideal strapdown integration
//! whose only errors are the gyro's.
//!
//! Noise streams: ChaCha8 seeded with the run's seed, stream 1 for the random walk (as
//! the plain integrating gyro of the paper's model, so the default output is unchanged) and stream 4
//! for the bias instability.

use super::sensors::{normal, DEG};
use super::SimError;
use crate::attitude::Quaternion;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Seconds per hour.
const HOUR_S: f64 = 3600.0;

/// Convert an angle random walk in deg/√h to the rate-noise density in deg/s/√Hz
/// (divide by 60).
#[must_use]
pub fn arw_deg_rthr_to_deg_s_rthz(arw_deg_rthr: f64) -> f64 {
    arw_deg_rthr / 60.0
}

/// deg/h to rad/s.
#[must_use]
pub fn deg_h_to_rad_s(deg_h: f64) -> f64 {
    deg_h * DEG / HOUR_S
}

/// Gyro errors beyond the angle random walk. `Default`: none (today's ideal-bias gyro).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GyroErrors {
    /// Constant rate bias, deg/h, body axes.
    pub bias_deg_h: Vector3<f64>,
    /// Bias instability: stationary 1σ of the Gauss–Markov bias, deg/h (≥ 0; 0 = off).
    pub bias_instability_deg_h: f64,
    /// Correlation time of the Gauss–Markov bias, s (finite, > 0).
    pub bias_correlation_s: f64,
}

impl Default for GyroErrors {
    fn default() -> Self {
        Self {
            bias_deg_h: Vector3::zeros(),
            bias_instability_deg_h: 0.0,
            bias_correlation_s: 3600.0,
        }
    }
}

impl GyroErrors {
    /// Whether any bias is modelled.
    #[must_use]
    pub(crate) fn is_active(&self) -> bool {
        self.bias_deg_h != Vector3::zeros() || self.bias_instability_deg_h > 0.0
    }

    /// The density of the rate random walk with the same short-time growth as the
    /// Gauss–Markov bias, `B √(2/τ_c)`, rad/s/√s (what a filter that models the bias as
    /// a random walk should assume).
    #[must_use]
    pub(crate) fn rate_random_walk_rad_s_rts(&self) -> f64 {
        deg_h_to_rad_s(self.bias_instability_deg_h) * (2.0 / self.bias_correlation_s).sqrt()
    }

    /// Check every field.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        if !self.bias_deg_h.iter().all(|v| v.is_finite()) {
            return Err(SimError::InvalidSetting {
                field: "gyro.bias_deg_h",
                value: self.bias_deg_h.norm(),
                why: "must be finite",
            });
        }
        if !(self.bias_instability_deg_h.is_finite() && self.bias_instability_deg_h >= 0.0) {
            return Err(SimError::InvalidSetting {
                field: "gyro.bias_instability_deg_h",
                value: self.bias_instability_deg_h,
                why: "must be finite and >= 0",
            });
        }
        if !(self.bias_correlation_s.is_finite() && self.bias_correlation_s > 0.0) {
            return Err(SimError::InvalidSetting {
                field: "gyro.bias_correlation_s",
                value: self.bias_correlation_s,
                why: "must be finite and > 0",
            });
        }
        Ok(())
    }
}

/// A gyro during a run, sampled once per integration interval of length `h_s`.
#[derive(Debug, Clone)]
pub(crate) struct Gyro {
    rng: ChaCha8Rng,
    noise: Normal<f64>,
    h_s: f64,
    active: bool,
    constant_rad_s: Vector3<f64>,
    gm_rng: ChaCha8Rng,
    gm_a: f64,
    gm_step: Normal<f64>,
    gm_rad_s: Vector3<f64>,
}

impl Gyro {
    /// A gyro of rate-noise density `noise_deg_s_rthz` (deg/s/√Hz) and `errors`, sampled
    /// every `h_s` seconds, with the noise streams of `seed` (module docs).
    #[must_use]
    pub(crate) fn new(noise_deg_s_rthz: f64, errors: &GyroErrors, h_s: f64, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(1);
        let mut gm_rng = ChaCha8Rng::seed_from_u64(seed);
        gm_rng.set_stream(4);
        let sigma = (noise_deg_s_rthz * DEG * h_s.sqrt()).abs();
        let a = (-h_s / errors.bias_correlation_s).exp();
        let b = deg_h_to_rad_s(errors.bias_instability_deg_h);
        Self {
            rng,
            noise: normal(sigma),
            h_s,
            active: errors.is_active(),
            constant_rad_s: errors.bias_deg_h.map(deg_h_to_rad_s),
            gm_rng,
            gm_a: a,
            gm_step: normal(b * (1.0 - a * a).max(0.0).sqrt()),
            gm_rad_s: Vector3::zeros(),
        }
    }

    /// The true bias over the current interval, rad/s (constant + Gauss–Markov).
    #[must_use]
    pub(crate) fn bias_rad_s(&self) -> Vector3<f64> {
        self.constant_rad_s + self.gm_rad_s
    }

    /// Measure one interval with true increment `q_b† q_{b+1}` and true `∫ω dt` (rad).
    /// Returns the increment corrupted by the gyro's error (for the gyro-propagated
    /// attitude) and the measured delta angle, rad; then advances the bias.
    pub(crate) fn measure(
        &mut self,
        true_increment: &Quaternion,
        true_angle: &Vector3<f64>,
    ) -> (Quaternion, Vector3<f64>) {
        let n = Vector3::from_fn(|_, _| self.noise.sample(&mut self.rng));
        if !self.active {
            let inc = true_increment.mul(&Quaternion::exp(&n));
            return (inc, true_angle + n);
        }
        let e = n + self.bias_rad_s() * self.h_s;
        let w = Vector3::from_fn(|_, _| self.gm_step.sample(&mut self.gm_rng));
        self.gm_rad_s = self.gm_rad_s * self.gm_a + w;
        (true_increment.mul(&Quaternion::exp(&e)), true_angle + e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::sample_std;

    /// Gyro angle random walk: the delta angles over h have std `σ √h` with
    /// σ = ARW/60 deg/s/√Hz for ARW in deg/√h (0.15 deg/√h here), within 4 % (9000 values).
    #[test]
    fn gyro_angle_random_walk_in_deg_per_root_hour() {
        assert_eq!(arw_deg_rthr_to_deg_s_rthz(0.15), 0.0025);
        let h = 0.1;
        let mut g = Gyro::new(
            arw_deg_rthr_to_deg_s_rthz(0.15),
            &GyroErrors::default(),
            h,
            3,
        );
        let v: Vec<f64> = (0..3000)
            .flat_map(|_| {
                let (_, d) = g.measure(&Quaternion::IDENTITY, &Vector3::zeros());
                [d.x, d.y, d.z]
            })
            .collect();
        // 0.15 deg/√h = 0.15 deg / √(3600 s): over h the angle std is 0.15 deg √(h/3600 s).
        let expected = 0.15 * DEG * (h / 3600.0).sqrt();
        let rel = sample_std(&v) / expected - 1.0;
        eprintln!("ARW: delta-angle std relative error {rel:+.4}");
        assert!(rel.abs() < 0.04, "ARW std off by {rel:+.3}");
    }

    /// Constant bias: delta angle = ∫ω + b h exactly (no noise).
    #[test]
    fn gyro_constant_bias() {
        let b = Vector3::new(10.0, -5.0, 3.0);
        let errors = GyroErrors {
            bias_deg_h: b,
            ..GyroErrors::default()
        };
        let mut g = Gyro::new(0.0, &errors, 0.1, 1);
        for _ in 0..100 {
            let (_, d) = g.measure(&Quaternion::IDENTITY, &Vector3::zeros());
            assert!((d / 0.1 - b * (DEG / 3600.0)).norm() < 1e-20);
        }
    }

    /// Bias instability: the Gauss–Markov bias starts at 0 and its variance grows as
    /// B²(1 − e^{−2t/τ}) (B = 1 deg/h, τ = 100 s), within 15 % at t = 10, 100 and 1000 s
    /// over 300 seeds × 3 axes; the constant bias does not move.
    #[test]
    fn gyro_bias_instability_growth() {
        let errors = GyroErrors {
            bias_deg_h: Vector3::zeros(),
            bias_instability_deg_h: 1.0,
            bias_correlation_s: 100.0,
        };
        let checkpoints = [10usize, 100, 1000];
        let mut at: Vec<Vec<f64>> = vec![Vec::new(); checkpoints.len()];
        for seed in 0..300 {
            let mut g = Gyro::new(0.0, &errors, 1.0, seed);
            assert_eq!(g.bias_rad_s(), Vector3::zeros());
            for step in 1..=1000 {
                g.measure(&Quaternion::IDENTITY, &Vector3::zeros());
                if let Some(i) = checkpoints.iter().position(|&c| c == step) {
                    let b = g.bias_rad_s() / deg_h_to_rad_s(1.0);
                    at[i].extend([b.x, b.y, b.z]);
                }
            }
        }
        for (i, &t) in checkpoints.iter().enumerate() {
            let var = at[i].iter().map(|b| b * b).sum::<f64>() / at[i].len() as f64;
            let expected = 1.0 - (-2.0 * t as f64 / 100.0).exp();
            let rel = var / expected - 1.0;
            eprintln!("bias instability t = {t} s: variance {var:.4} vs {expected:.4} ({rel:+.3})");
            assert!(rel.abs() < 0.15, "t = {t} s: variance off by {rel:+.3}");
        }
    }
}
