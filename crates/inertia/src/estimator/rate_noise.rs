//! The gyro's white rate-noise density, estimated from the telemetered rates (beyond the
//! paper): what the errors-in-variables compensation ([`super::compensation`]) needs when
//! the user states none.
//!
//! # Why
//!
//! Gyro noise enters the momentum rows' regressor (the rotation `φ` over each step), so
//! least squares shrinks `ĵ` towards zero by `(RᵀR)⁻¹ σ² c D ĵ` (module docs of
//! [`super::compensation`]). The shrinkage grows where each chain's rows carry little
//! signal: on the small satellite's MEMS gyro (0.0025 deg/s/√Hz) with 7.5 s chains the
//! diagonal came out 2–3 % low, several σ, whichever way the data's other errors pointed.
//! Given the density the compensation removes it; a datasheet gives the density, and so do
//! the rates themselves.
//!
//! # How
//!
//! The telemetered rate `ω_k` is the gyro's average over the step `h`, so white rate noise
//! of density `N` (rad/s/√Hz) adds independent errors of variance `N²/h` to successive
//! rates. Differences of order `p` of a smooth motion shrink like `(h ω_dyn)^p`, while
//! those of the noise grow: `Var Δ²ω = 6 N²/h`, `Var Δ³ω = 20 N²/h`. With `m_p` the median
//! of the squared differences times their step, `h (Δ^p ω)²` (every axis pooled, so that
//! stretches at different rates count alike; the median of `χ²₁` is 0.4549, and a
//! median ignores the steps where a command switches), `N_p² = m_p / (0.4549 C_p)`
//! (`C_2 = 6`, `C_3 = 20`). Where the noise dominates, `N_2 = N_3`; where the motion
//! shows in the second differences, `N_2 > N_3`, and neither is the noise. So the
//! estimate is `N_3`, and only where `N_2 / N_3 ≤` [`AGREEMENT`] (noise-dominated third
//! differences: the smooth part is at least `AGREEMENT²` smaller in them than in the
//! second ones); otherwise there is none and nothing is compensated.
//!
//! Measured on the simulator's telemetry, in deg/s/√Hz (true density in brackets):
//! small-sat MEMS 2.46–2.52e-3 over seeds (2.5e-3), the lab throw at 4 kHz with its
//! vibration 9.9e-3 (1e-2), the spin with a MEMS gyro at 10 Hz 2.46e-3 (2.5e-3, `N_2/N_3`
//! = 1.09); the paper's slew and spin with the paper's gyro (1e-5), at 10 Hz and at 1 Hz:
//! none (`N_2/N_3` ≥ 1.25; their shrinkage is negligible).
//!
//! Only runs of samples with equal steps (within [`STEP_TOLERANCE`]) count: three for a
//! second difference, four for a third, so a gap or jitter adds nothing, and a time that
//! does not increase or a rate that is not finite starts a new run. Resampled rates are
//! interpolated, which damps their noise: a run that resamples estimates nothing.
//! Rates that take a few values only (quantised, or constant) put the median into a bin
//! holding more than [`TIED`] of the differences: no estimate. Fixed memory: two
//! log-spaced histograms, [`BINS`] bins of 1/50 decade each (the median to within 2.3 %
//! in variance).

use nalgebra::Vector3;

/// Histogram bins per squared-difference histogram.
pub(crate) const BINS: usize = 2500;

/// Bins per decade.
const PER_DECADE: f64 = 50.0;

/// The lowest decade of the histograms, (rad/s)²: squared differences below it (and
/// exact zeros) count in the lowest bin.
const LOWEST_DECADE: f64 = -40.0;

/// Largest `N_2 / N_3` at which the third differences are taken as noise.
pub(crate) const AGREEMENT: f64 = 1.2;

/// Relative tolerance of the equal steps of a run of four samples.
pub(crate) const STEP_TOLERANCE: f64 = 1e-3;

/// Fewest squared third differences (three per sample) before there is an estimate.
pub(crate) const MIN_DIFFERENCES: u64 = 300;

/// The largest share of the differences that the median's bin may hold; more, and the
/// differences take a few values only (quantised or constant rates).
pub(crate) const TIED: f64 = 0.1;

/// Median of `χ²₁`.
const CHI2_1_MEDIAN: f64 = 0.454_936_423_119_572_8;

/// The running estimate (module docs).
#[derive(Debug, Clone)]
pub(crate) struct RateNoise {
    /// The last (up to) four samples' times and rates, oldest first.
    last: [(f64, Vector3<f64>); 4],
    /// How many of `last` are filled (a run of equal steps).
    filled: usize,
    /// Histograms of `h (Δ²ω)²` and `h (Δ³ω)²`, per component.
    second: [u64; BINS],
    third: [u64; BINS],
    /// Squared third differences counted.
    third_count: u64,
}

impl Default for RateNoise {
    fn default() -> Self {
        RateNoise {
            last: [(0.0, Vector3::zeros()); 4],
            filled: 0,
            second: [0; BINS],
            third: [0; BINS],
            third_count: 0,
        }
    }
}

fn bin(x: f64) -> usize {
    if !(x > 0.0) {
        return 0;
    }
    let b = (libm::log10(x) - LOWEST_DECADE) * PER_DECADE;
    if b < 0.0 {
        0
    } else {
        (b as usize).min(BINS - 1)
    }
}

/// The median of a histogram's values, interpolated within its bin on the log scale;
/// `None` when empty or when the median's bin holds more than [`TIED`] of the values.
fn median(h: &[u64; BINS]) -> Option<f64> {
    let n: u64 = h.iter().sum();
    if n == 0 {
        return None;
    }
    let half = n as f64 / 2.0;
    let mut below = 0.0;
    for (i, &c) in h.iter().enumerate() {
        let c = c as f64;
        if below + c >= half {
            if c > TIED * n as f64 {
                return None;
            }
            let frac = if c > 0.0 { (half - below) / c } else { 0.0 };
            return Some(libm::pow(
                10.0,
                LOWEST_DECADE + (i as f64 + frac) / PER_DECADE,
            ));
        }
        below += c;
    }
    None
}

impl RateNoise {
    /// One sample's time and gyro rate (`None`: no rate, which ends the run).
    pub(crate) fn push(&mut self, t_s: f64, omega_rad_s: Option<Vector3<f64>>) {
        let Some(w) = omega_rad_s.filter(|w| w.iter().all(|x| x.is_finite())) else {
            self.filled = 0;
            return;
        };
        if !t_s.is_finite() {
            self.filled = 0;
            return;
        }
        if self.filled > 0 {
            let (t_prev, _) = self.last[self.filled - 1];
            let h = t_s - t_prev;
            let h0 = if self.filled >= 2 {
                t_prev - self.last[self.filled - 2].0
            } else {
                h
            };
            if !(h > 0.0) || libm::fabs(h - h0) > STEP_TOLERANCE * h0 {
                // A new run from the previous sample.
                self.last[0] = self.last[self.filled - 1];
                self.filled = 1;
                if !(h > 0.0) {
                    self.filled = 0;
                }
            }
        }
        if self.filled == 4 {
            self.last.copy_within(1..4, 0);
            self.filled = 3;
        }
        self.last[self.filled] = (t_s, w);
        self.filled += 1;
        let n = self.filled;
        if n >= 3 {
            let (a, b, c) = (self.last[n - 3].1, self.last[n - 2].1, self.last[n - 1].1);
            let h = t_s - self.last[n - 2].0;
            let d2 = c - b * 2.0 + a;
            for x in d2.iter() {
                self.second[bin(h * x * x)] += 1;
            }
        }
        if n == 4 {
            let l = &self.last;
            let h = l[3].0 - l[2].0;
            let d3 = l[3].1 - l[2].1 * 3.0 + l[1].1 * 3.0 - l[0].1;
            for x in d3.iter() {
                self.third[bin(h * x * x)] += 1;
            }
            self.third_count += 3;
        }
    }

    /// The estimate over a whole record ([`Self::density_rad_s_rthz`] after every sample).
    #[must_use]
    pub(crate) fn of_record(samples: &[crate::sample::Sample]) -> Option<f64> {
        let mut r = RateNoise::default();
        for s in samples {
            r.push(s.t_s, s.omega_rad_s);
        }
        r.density_rad_s_rthz()
    }

    /// The density `N_3`, rad/s/√Hz, where the third differences are noise (module docs);
    /// `None` before [`MIN_DIFFERENCES`] of them, where they are not, or where the rates do
    /// not vary at all.
    #[must_use]
    pub(crate) fn density_rad_s_rthz(&self) -> Option<f64> {
        let (n2, n3) = self.densities()?;
        (n3 > 0.0 && n2 <= AGREEMENT * n3).then_some(n3)
    }

    /// `(N_2, N_3)`, rad/s/√Hz, once there are enough differences.
    fn densities(&self) -> Option<(f64, f64)> {
        if self.third_count < MIN_DIFFERENCES {
            return None;
        }
        let n = |m: f64, c: f64| libm::sqrt(m / (CHI2_1_MEDIAN * c));
        let (m2, m3) = (median(&self.second)?, median(&self.third)?);
        // The lowest bin holds exact zeros: rates that never change say nothing.
        if m3 <= libm::pow(10.0, LOWEST_DECADE + 1.0 / PER_DECADE) {
            return None;
        }
        Some((n(m2, 6.0), n(m3, 20.0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A standard normal draw (Box–Muller).
    fn normal(rng: &mut impl Rng) -> f64 {
        let (u, v): (f64, f64) = (rng.random(), rng.random());
        libm::sqrt(-2.0 * libm::log(1.0 - u)) * libm::cos(2.0 * core::f64::consts::PI * v)
    }

    fn feed(
        density: f64,
        h: f64,
        n: usize,
        motion: impl Fn(f64) -> Vector3<f64>,
        seed: u64,
    ) -> RateNoise {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let sd = density / h.sqrt();
        let mut r = RateNoise::default();
        for k in 0..n {
            let t = k as f64 * h;
            let w = motion(t)
                + Vector3::new(
                    sd * normal(&mut rng),
                    sd * normal(&mut rng),
                    sd * normal(&mut rng),
                );
            r.push(t, Some(w));
        }
        r
    }

    /// White noise on a slow motion: `N_2` and `N_3` (so both differences' constants)
    /// each within 5 % of the density over seeds, rates and sizes.
    #[test]
    fn white_noise_gives_its_density() {
        for (seed, density, h) in [(1, 4.4e-5, 0.1), (2, 1.7e-4, 2.5e-4), (3, 1e-6, 0.01)] {
            let slow = |t: f64| Vector3::new(0.01 * libm::sin(0.05 * t), 0.02, -0.01);
            let r = feed(density, h, 6000, slow, seed);
            let (n2, n3) = r.densities().expect("enough differences");
            for (what, n) in [("N_2", n2), ("N_3", n3)] {
                assert!(
                    (n / density - 1.0).abs() < 0.05,
                    "seed {seed} {what}: {n} vs {density}"
                );
            }
            assert_eq!(r.density_rad_s_rthz(), Some(n3));
        }
    }

    /// Two stretches at different rates (10 Hz, then 2 Hz after a gap) with the same
    /// density: each difference is weighed by its own step, so the estimate is the
    /// density, as it is for each stretch alone.
    #[test]
    fn stretches_at_different_rates_share_the_density() {
        let density = 4.4e-5;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut r = RateNoise::default();
        let mut t = 0.0;
        for (h, n) in [(0.1, 3000), (0.5, 3000)] {
            t += 10.0;
            for _ in 0..n {
                t += h;
                let sd = density / libm::sqrt(h);
                let w = Vector3::new(
                    0.02 + sd * normal(&mut rng),
                    sd * normal(&mut rng),
                    sd * normal(&mut rng),
                );
                r.push(t, Some(w));
            }
        }
        let got = r.density_rad_s_rthz().expect("noise-dominated");
        assert!((got / density - 1.0).abs() < 0.05, "{got} vs {density}");
    }

    /// A time that does not increase or a rate that is not finite starts a new run: the
    /// differences across it are not counted (each run of 3 samples adds one second and
    /// no third difference).
    #[test]
    fn a_step_back_or_a_bad_rate_starts_a_new_run() {
        let mut r = RateNoise::default();
        let w = Some(Vector3::new(0.1, 0.2, 0.3));
        for t in [0.0, 0.1, 0.2, 0.2, 0.3, 0.4] {
            r.push(t, w);
        }
        assert_eq!(r.third_count, 0, "no run of four equal steps");
        assert_eq!(r.second.iter().sum::<u64>(), 6, "two runs of three");
        let mut r = RateNoise::default();
        for (k, t) in [0.0, 0.1, 0.2, 0.3, 0.4, 0.5].into_iter().enumerate() {
            let bad = k == 3;
            r.push(
                t,
                if bad {
                    Some(Vector3::new(f64::NAN, 0.0, 0.0))
                } else {
                    w
                },
            );
        }
        assert_eq!(r.third_count, 0);
        assert_eq!(
            r.second.iter().sum::<u64>(),
            3,
            "one run of three before the bad rate"
        );
    }

    /// Rates quantised coarser than their noise take a few values: no estimate.
    #[test]
    fn quantised_rates_give_none() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(8);
        let (h, density, lsb) = (0.1, 4.4e-5, 1e-3);
        let mut r = RateNoise::default();
        for k in 0..6000 {
            let sd = density / libm::sqrt(h);
            let q = |x: f64| libm::round(x / lsb) * lsb;
            let w = Vector3::new(
                q(0.02 + sd * normal(&mut rng)),
                q(sd * normal(&mut rng)),
                q(-0.01 + sd * normal(&mut rng)),
            );
            r.push(k as f64 * h, Some(w));
        }
        assert_eq!(r.density_rad_s_rthz(), None);
    }

    /// A motion that shows in the second differences gives no estimate, however long.
    #[test]
    fn a_motion_above_the_noise_gives_none() {
        // The paper's spin-like motion at 1 Hz with a gyro of 1e-5 deg/s/√Hz.
        let fast = |t: f64| Vector3::new(0.05 * libm::sin(0.3 * t), 0.05 * libm::cos(0.3 * t), 0.1);
        let r = feed(1.7e-7, 1.0, 3000, fast, 4);
        let (n2, n3) = r.densities().expect("enough differences");
        assert!(n2 > AGREEMENT * n3, "{n2} {n3}");
        assert_eq!(r.density_rad_s_rthz(), None);
    }

    /// Gaps, uneven steps and missing rates start a new run; too few differences give
    /// none; rates that never change give none.
    #[test]
    fn runs_need_equal_steps_and_enough_rates() {
        let mut r = RateNoise::default();
        let mut t = 0.0;
        for k in 0..400 {
            // Steps alternate 0.1 and 0.2 s: no run of four equal steps.
            t += if k % 2 == 0 { 0.1 } else { 0.2 };
            r.push(t, Some(Vector3::new(k as f64, 0.0, 0.0)));
        }
        assert_eq!(r.third.iter().sum::<u64>(), 0);
        assert_eq!(r.density_rad_s_rthz(), None);
        let mut r = RateNoise::default();
        for k in 0..50 {
            r.push(k as f64 * 0.1, Some(Vector3::new(0.1, 0.0, 0.0)));
            r.push(k as f64 * 0.1 + 0.05, None);
        }
        assert_eq!(r.third.iter().sum::<u64>(), 0);
        let still = feed(0.0, 0.1, 2000, |_| Vector3::new(0.1, 0.2, 0.3), 5);
        assert_eq!(still.density_rad_s_rthz(), None);
        let short = feed(1e-4, 0.1, 50, |_| Vector3::zeros(), 6);
        assert_eq!(short.density_rad_s_rthz(), None);
    }
}
