//! A star tracker: the true attitude with white noise per tracker axis.
//!
//! The tracker frame has its z axis along the boresight `b` (a body axis,
//! [`StarTracker::boresight_body`], default +z). Its x axis is `unit(ŷ_B × b)`, or
//! `unit(b × x̂_B)` when the boresight is within 30° of ±ŷ_B; its y axis completes a
//! right-handed frame, `y = b × x`. For the default boresight +z the tracker axes are the
//! body axes.
//!
//! A measurement is `q̃ = q exp(δθ)` with the body-frame error rotation
//! `δθ = E (σ ⊙ n)`, `E = [x y b]`, `n ~ N(0, I)` and
//! `σ` = [`StarTracker::noise_arcsec`] (cross-boresight x, cross-boresight y, roll about
//! the boresight) in arcsec, 1σ, converted to rad. So `log(q† q̃)` projected on the tracker
//! axes has standard deviations `σ`. Samples are independent (white). Noise stream:
//! ChaCha8 seeded with the run's seed, stream 2.

use super::SimError;
use crate::attitude::Quaternion;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// One arcsecond in radians.
pub const ARCSEC: f64 = core::f64::consts::PI / (180.0 * 3600.0);

/// Star tracker settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StarTracker {
    /// 1σ noise, arcsec, about the tracker's x and y (cross-boresight) and z (roll about
    /// the boresight) axes; each finite and ≥ 0 (> 0 for the MEKF). Default
    /// 5″/5″/40″, typical of CubeSat-class trackers (a few arcsec across the boresight,
    /// tens of arcsec about it).
    pub noise_arcsec: Vector3<f64>,
    /// Boresight direction in body axes (normalised on use; non-zero). Default +z.
    pub boresight_body: Vector3<f64>,
    /// Measurement rate for the MEKF's updates, Hz (`None`: one update per telemetry
    /// node). `1/(rate_hz · dt_s)` must be a whole number of integration intervals.
    /// The [`super::AttitudeSource::StarTracker`] source samples the tracker at every
    /// telemetry node whatever this is.
    pub rate_hz: Option<f64>,
}

impl Default for StarTracker {
    fn default() -> Self {
        Self {
            noise_arcsec: Vector3::new(5.0, 5.0, 40.0),
            boresight_body: Vector3::z(),
            rate_hz: None,
        }
    }
}

impl StarTracker {
    /// The tracker axes in body axes, as the columns `[x y b]` (module docs).
    #[must_use]
    pub(crate) fn axes(&self) -> Matrix3<f64> {
        let b = self
            .boresight_body
            .try_normalize(0.0)
            .unwrap_or_else(Vector3::z);
        let yb = Vector3::y().cross(&b);
        let x = if yb.norm() >= 0.5 {
            yb.normalize()
        } else {
            b.cross(&Vector3::x()).normalize()
        };
        let y = b.cross(&x);
        Matrix3::from_columns(&[x, y, b])
    }

    /// The body-frame covariance of the error rotation `δθ`, rad².
    #[must_use]
    pub(crate) fn covariance_rad2(&self) -> Matrix3<f64> {
        let e = self.axes();
        let s = self.noise_arcsec * ARCSEC;
        e * Matrix3::from_diagonal(&s.component_mul(&s)) * e.transpose()
    }

    /// Check every field.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        if !self.noise_arcsec.iter().all(|v| v.is_finite() && *v >= 0.0) {
            return Err(SimError::InvalidSetting {
                field: "star_tracker.noise_arcsec",
                value: self.noise_arcsec.min(),
                why: "each must be finite and >= 0",
            });
        }
        let n = self.boresight_body.norm();
        if !(n.is_finite() && n > 0.0) {
            return Err(SimError::InvalidSetting {
                field: "star_tracker.boresight_body",
                value: n,
                why: "must be a finite, non-zero vector",
            });
        }
        if let Some(r) = self.rate_hz {
            if !(r.is_finite() && r > 0.0) {
                return Err(SimError::InvalidSetting {
                    field: "star_tracker.rate_hz",
                    value: r,
                    why: "must be finite and > 0",
                });
            }
        }
        Ok(())
    }
}

/// A star tracker during a run.
#[derive(Debug, Clone)]
pub(crate) struct StarTrackerNoise {
    rng: ChaCha8Rng,
    axes: Matrix3<f64>,
    sigma_rad: Vector3<f64>,
}

impl StarTrackerNoise {
    /// The tracker `settings` with the noise stream of `seed` (module docs).
    #[must_use]
    pub(crate) fn new(settings: &StarTracker, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(2);
        Self {
            rng,
            axes: settings.axes(),
            sigma_rad: settings.noise_arcsec * ARCSEC,
        }
    }

    /// One measurement of the true attitude `q` (body → inertial).
    pub(crate) fn measure(&mut self, q: &Quaternion) -> Quaternion {
        let n: Vector3<f64> = Vector3::from_fn(|_, _| StandardNormal.sample(&mut self.rng));
        let d = self.axes * self.sigma_rad.component_mul(&n);
        q.mul(&Quaternion::exp(&d)).normalize().unwrap_or(*q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::scenario::{Common, Scenario};
    use crate::sim::{AttitudeSource, Realism};
    use crate::testing::sample_std;

    /// Star tracker: per-axis error std within 4 % of the specification, cross-boresight and
    /// roll separately, for the default boresight (+z) and a tilted one; errors uncorrelated
    /// between tracker axes. 4000 samples per case (sampling error of a std ≈ 1.1 %).
    #[test]
    fn star_tracker_noise_matches_its_specification() {
        let q = Quaternion::exp(&Vector3::new(0.3, -1.1, 0.7));
        for (seed, boresight) in [(11, Vector3::z()), (12, Vector3::new(1.0, 1.0, 0.5))] {
            let st = StarTracker {
                noise_arcsec: Vector3::new(5.0, 8.0, 40.0),
                boresight_body: boresight,
                rate_hz: None,
            };
            let e = st.axes();
            assert!((e.transpose() * e - Matrix3::identity()).norm() < 1e-14);
            assert!((e.column(2) - boresight.normalize()).norm() < 1e-15);
            assert!(e.determinant() > 0.0);
            let mut noise = StarTrackerNoise::new(&st, seed);
            let errs: Vec<Vector3<f64>> = (0..4000)
                .map(|_| e.transpose() * q.conjugate().mul(&noise.measure(&q)).log() / ARCSEC)
                .collect();
            for axis in 0..3 {
                let v: Vec<f64> = errs.iter().map(|x| x[axis]).collect();
                let rel = sample_std(&v) / st.noise_arcsec[axis] - 1.0;
                eprintln!(
                    "tracker {boresight:?} axis {axis}: std {:.3}″ ({rel:+.4})",
                    sample_std(&v)
                );
                assert!(rel.abs() < 0.04, "axis {axis}: std off by {rel:+.3}");
            }
            let corr =
                errs.iter().map(|x| x[0] * x[2]).sum::<f64>() / (errs.len() as f64 * 5.0 * 40.0);
            assert!(corr.abs() < 0.06, "x-roll correlation {corr}");
        }
    }

    /// The star-tracker source in the simulator: exactly the tracker's stream applied to
    /// the true attitude at every node.
    #[test]
    fn star_tracker_source_is_the_tracker_on_the_truth() {
        let realism = Realism {
            attitude: AttitudeSource::StarTracker,
            ..Realism::default()
        };
        let out = Scenario::slew()
            .simulate(&Common {
                duration_s: Some(60.0),
                seed: 5,
                realism,
                ..Common::paper()
            })
            .unwrap();
        let mut st = StarTrackerNoise::new(&realism.star_tracker, 5);
        for (s, t) in out.samples.iter().zip(&out.truth) {
            assert_eq!(s.q, st.measure(&t.state.q));
        }
    }
}
