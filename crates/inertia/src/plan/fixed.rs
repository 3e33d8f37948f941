//! The fixed excitation profiles a plan is compared with, at the same limits.
//!
//! Shapes follow the public peer `satellite-inertia-id` (`control/torque_generators.py`,
//! commit `25c9d901`): a pseudo-random binary sequence per axis (its own sequence on each
//! axis, switch time 5 s), a linear chirp 0.005 → 0.05 Hz (the same on all three axes,
//! as the peer applies it), the peer's multi-sine (two sines per axis at 0.002–0.008 Hz
//! with its amplitude ratios and phases) and its multi-step (+1, −1, 0, +1, −1, 0 over
//! the horizon, the same on all axes). Two variants give the equal-on-all-axes shapes
//! their best chance: the chirp with the axes a third of a period apart
//! (`chirp-3axis`) and the steps staggered by one step per axis (`multi-step-3axis`).
//!
//! Each is built with unit amplitude over a horizon, then scaled by
//! `Limits::scale_to_fit` to use the same fraction of its tightest
//! limit (torque, wheel momentum or rate) as a plan does: the largest amplitude at
//! which it flies.

use crate::plan::limits::{Limits, LimitsError};
use crate::plan::profile::CommandProfile;
use core::f64::consts::PI;
use nalgebra::{Matrix3, Vector3};
use std::vec::Vec;

/// The fixed profiles' names.
pub(crate) const NAMES: [&str; 6] = [
    "prbs",
    "chirp",
    "chirp-3axis",
    "multi-sine",
    "multi-step",
    "multi-step-3axis",
];

/// A ±1 pseudo-random binary sequence (xorshift64*, seeded per axis).
fn binary(seed: u64, n: usize) -> Vec<f64> {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|_| {
            x ^= x >> 12;
            x ^= x << 25;
            x ^= x >> 27;
            if x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 63 == 1 {
                1.0
            } else {
                -1.0
            }
        })
        .collect()
}

/// The unit-amplitude shape `name` over `horizon_s` at controller period `period_s`
/// (`None` for an unknown name).
#[must_use]
pub(crate) fn shape(name: &str, period_s: f64, horizon_s: f64) -> Option<CommandProfile> {
    let n = (horizon_s / period_s).round() as usize;
    let t = |k: usize| k as f64 * period_s;
    let cmds: Vec<Vector3<f64>> = match name {
        "prbs" => {
            let per = ((5.0 / period_s).round() as usize).max(1);
            let bits: Vec<Vec<f64>> = (0..3).map(|i| binary(1 + i, n / per + 2)).collect();
            (0..n)
                .map(|k| Vector3::new(bits[0][k / per], bits[1][k / per], bits[2][k / per]))
                .collect()
        }
        "chirp" | "chirp-3axis" => {
            let (f0, f1) = (0.005, 0.05);
            let phase = if name == "chirp" { 0.0 } else { 2.0 * PI / 3.0 };
            (0..n)
                .map(|k| {
                    let tk = t(k) + 0.5 * period_s;
                    let arg = 2.0 * PI * (f0 * tk + 0.5 * (f1 - f0) * tk * tk / horizon_s);
                    Vector3::from_fn(|i, _| (arg + phase * i as f64).cos())
                })
                .collect()
        }
        "multi-sine" => {
            let f = [[0.002, 0.005], [0.003, 0.007], [0.004, 0.008]];
            let a = [[0.003, 0.0015], [0.0035, 0.002], [0.0025, 0.0015]];
            let p = [[0.0, 0.0], [PI / 4.0, 0.0], [-PI / 3.0, 0.0]];
            (0..n)
                .map(|k| {
                    let tk = t(k) + 0.5 * period_s;
                    Vector3::from_fn(|i, _| {
                        (0..2)
                            .map(|m| a[i][m] * (2.0 * PI * f[i][m] * tk + p[i][m]).sin())
                            .sum()
                    })
                })
                .collect()
        }
        "multi-step" | "multi-step-3axis" => {
            let level = [1.0, -1.0, 0.0, 1.0, -1.0, 0.0];
            let stagger = usize::from(name == "multi-step-3axis");
            (0..n)
                .map(|k| {
                    let step = (6 * k) / n.max(1);
                    Vector3::from_fn(|i, _| level[(step + 6 - (i * stagger) % 6) % 6])
                })
                .collect()
        }
        _ => return None,
    };
    Some(CommandProfile::new(0.0, period_s, cmds))
}

/// The fixed profile `name` over `horizon_s`, scaled to the limits.
pub(crate) fn fixed(
    name: &str,
    period_s: f64,
    horizon_s: f64,
    limits: &Limits,
    j: &Matrix3<f64>,
) -> Result<Option<CommandProfile>, LimitsError> {
    let Some(p) = shape(name, period_s, horizon_s) else {
        return Ok(None);
    };
    let s = limits.scale_to_fit(&p, j)?;
    Ok(Some(p.scaled(s)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::limits::Wheel;

    /// Every fixed profile, scaled, uses exactly the margin of its tightest limit and no
    /// more of any.
    #[test]
    fn scaled_profiles_use_the_margin() {
        let lim = Limits {
            wheels: (0..3)
                .map(|i| Wheel {
                    name: std::format!("rw{i}"),
                    axis: Vector3::ith(i, 1.0),
                    max_torque_nm: 0.01,
                    max_momentum_nms: 0.046,
                })
                .collect(),
            max_rate_rad_s: Some(0.05),
            max_angle_rad: None,
            margin: 0.9,
        };
        let j = Matrix3::from_diagonal(&Vector3::new(0.26, 0.26, 0.16));
        for name in NAMES {
            let p = fixed(name, 1.0, 300.0, &lim, &j).unwrap().unwrap();
            assert_eq!(p.torque_nm.len(), 300);
            let u = lim.use_of(&p, &j).unwrap();
            assert!((u.worst() - 0.9).abs() < 1e-9, "{name}: {u:?}");
        }
        assert!(shape("nope", 1.0, 10.0).is_none());
    }
}
