//! The rotors' uncertainty as a consider parameter (issues #30 "What the user said", #31
//! "Per-rotor parameters"): how far `ĵ` moves for each independent 1σ error of the
//! rotors' spin inertias, axes and time tags, and the σ that this adds.
//!
//! A relative error `ε_i` of rotor `i`'s spin inertia scales its momentum `ρ_i` by
//! `1 + ε_i`; a small tilt of its axis by angles `(θ_1, θ_2)` towards the two directions
//! perpendicular to it ([`crate::spacecraft::Rotor::tilt_directions`]) adds
//! `|ρ_i| (θ_1 e_1 + θ_2 e_2)`. The error sources are independent standard normal `z_v`,
//! each moving some rotors by their σ (`s_i = σ_i/J_i`, `σ_θ,i` the tilt's):
//!
//! * **shared** spin-inertia errors (the default): one source for every rotor,
//!   `ε_i = z s_i` (wheels of one model whose catalogue value is off);
//! * **independent** spin-inertia errors: one source per rotor with a σ, `ε_i = z_i s_i`;
//! * **axis tilts**: two sources per rotor with a tilt σ, `θ_j = z σ_θ,i` (mounting
//!   errors are each wheel's own);
//! * **time tags**: one source per rotor with a time-tag σ, its telemetry lagging the
//!   run's wheel-speed time tag by `δ_i = z σ_δ,i` (the speed read at `t` is the one of
//!   `t − δ_i`, as for `--wheel-delay`), so that its momentum is `ρ_i(t + δ_i) ≈ ρ_i(t) +
//!   δ_i ρ̇_i(t)` of its interpolated speeds (`Change::TimeTag`).
//!
//! Each source's move `m_v = ĵ(z_v = 1) − ĵ` is measured on the estimator itself: the
//! run's estimator (same settings, same samples, the run's wheel-speed time tag applied to
//! each rotor's momentum as to the sum) is run once more with the momenta changed by that
//! 1σ error, in the row model the run's own answer chose (rotation source, stencil, chain
//! length, inertial torque, body torque held or estimated:
//! `PipelineConfig::pinned_to`), so that the move is the answer's sensitivity and not a
//! switch of model (without it, a streaming and a batch run of the same data gave moves
//! 5× apart). It is a secant over one σ (a time tag's: the slope of its speeds times σ),
//! so it includes what that model does (its constraints, its chains' momenta). The consider term per element is
//!
//! ```text
//! c_k = √(Σ_v m_v,k²)
//! ```
//!
//! (one source: `|m_k|`, which with equal `s_i = r` and no known torque is `r |ĵ_k|`, the
//! common scale's, `super::uncertainty::Uncertainty::with_rotor_scale`). Cost: one run of
//! the estimator per source, plus one. What it leaves out: the curvature of `ĵ(z)` beyond
//! one σ (`tests/integration/rotor_inertia.rs` measures the move over 0.1 σ against the one
//! over 1σ).

use crate::sample::Sample;
use crate::spacecraft::{RotorErrors, Spacecraft};
use crate::tensor::InertiaVector;
use nalgebra::Vector3;
use std::vec::Vec;

/// What the rotors' uncertainty does to the answer.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RotorInertiaConsider {
    /// How the spin-inertia errors are related.
    pub errors: RotorErrors,
    /// Each rotor's relative σ `σ_i/J_i`, in the spacecraft file's order.
    pub relative_sigma: Vec<f64>,
    /// Each independent 1σ error source: `spin inertia` (shared), `rw1 spin inertia`,
    /// `rw1 axis tilt 1`, ….
    pub sources: Vec<std::string::String>,
    /// The answer's move `m_v` for each source, kg m², in the order of [`Self::sources`].
    pub moves_kg_m2: Vec<[f64; 6]>,
}

impl RotorInertiaConsider {
    /// The consider term per element, `√(Σ_v m_v,k²)`, kg m² ([module docs](self)).
    #[must_use]
    pub(crate) fn consider_kg_m2(&self) -> [f64; 6] {
        core::array::from_fn(|k| {
            self.moves_kg_m2
                .iter()
                .map(|m| m[k] * m[k])
                .sum::<f64>()
                .sqrt()
        })
    }
}

/// Why the consider term could not be computed.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RotorInertiaError {
    /// The estimator gave no answer on the data, or on the data with the rotors'
    /// inertia changed.
    #[error("the rotors' share of the answer cannot be computed: {0}")]
    NotComputable(&'static str),
}

/// The moves of `spacecraft`'s 1σ error sources ([module docs](self)) from the run's
/// `samples`, the rotors' stored speeds `speeds` (`samples.len()` rows of one value per
/// rotor, flat) and the wheel-speed time tag `delay_s` the run applied; `solve` runs the
/// estimator over samples and gives its final answer, and is called first on `samples`
/// themselves.
pub(crate) fn consider(
    samples: &[Sample],
    speeds: &[f64],
    spacecraft: &Spacecraft,
    delay_s: f64,
    mut solve: impl FnMut(&[Sample]) -> Option<InertiaVector>,
) -> Result<RotorInertiaConsider, RotorInertiaError> {
    let m = spacecraft.rotors.len();
    if m == 0 || speeds.len() != samples.len() * m {
        return Err(RotorInertiaError::NotComputable(
            "one speed per rotor and sample is needed",
        ));
    }
    let relative_sigma: Vec<f64> = spacecraft
        .rotors
        .iter()
        .map(crate::spacecraft::Rotor::relative_sigma)
        .collect();
    let sources = sources(spacecraft);
    let sources: Vec<(std::string::String, Change)> =
        sources.into_iter().map(|s| (s.label, s.change)).collect();
    if sources.is_empty() {
        return Err(RotorInertiaError::NotComputable("no rotor has a σ"));
    }
    let base = solve(samples).ok_or(RotorInertiaError::NotComputable(
        "the estimator gave no answer",
    ))?;
    let mut scaled: Vec<Sample> = samples.to_vec();
    let mut moves = Vec::with_capacity(sources.len());
    for (_, change) in &sources {
        let delta = source_momentum(samples, speeds, spacecraft, change, delay_s, &[]);
        for ((x, s), d) in scaled.iter_mut().zip(samples).zip(&delta) {
            x.rho_nms = s.rho_nms + d;
        }
        let j = solve(&scaled).ok_or(RotorInertiaError::NotComputable(
            "the estimator gave no answer with the rotors changed",
        ))?;
        moves.push(core::array::from_fn(|k| j[k] - base[k]));
    }
    Ok(RotorInertiaConsider {
        errors: spacecraft.rotor_errors,
        relative_sigma,
        sources: sources.into_iter().map(|s| s.0).collect(),
        moves_kg_m2: moves,
    })
}

/// An independent 1σ error source of the rotors ([`sources`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Source {
    /// `spin inertia` (shared), `rw1 spin inertia`, `rw1 axis tilt 1`, ….
    pub(crate) label: std::string::String,
    /// What its 1σ changes.
    pub(crate) change: Change,
    /// Its σ in [`Self::unit`]: the relative σ of the spin inertia (the largest of the
    /// rotors' for a shared source), the tilt's σ in degrees, or the time tag's in s.
    pub(crate) sigma: f64,
    /// `relative`, `deg` or `s`.
    pub(crate) unit: &'static str,
}

/// The half-step of the central difference that gives a time tag's column, relative to
/// its σ.
const TIME_TAG_STEP: f64 = 0.01;

/// The smallest half-step of that difference per second of time stamp: 1e4 times the
/// precision of a time stamp (`f64::EPSILON` per second), so that the difference keeps
/// four digits.
const TIME_RESOLUTION: f64 = 1e4 * f64::EPSILON;

/// What one error source's 1σ changes.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Change {
    /// Per rotor, the change of its momentum's direction per unit of its momentum (`s_i
    /// a_i` for its spin inertia, `σ_θ e_j` for a tilt; zero where the source leaves it).
    Directions(Vec<Vector3<f64>>),
    /// Rotor `rotor`'s telemetry lagging by `sigma_s` more (its speed read at `t` is the
    /// one of `t − σ`): to first order its momentum `σ ρ̇_i(t)`, `ρ̇_i` the slope of the
    /// interpolated speeds ([`super::wheel_delay::shift_rho`]) at the rotor's time tag.
    TimeTag {
        /// The rotor, in the file's order.
        rotor: usize,
        /// The time tag's σ, s.
        sigma_s: f64,
    },
}

/// Rotor `i`'s momentum per sample, its speeds times `per_unit` (N m s per stored unit,
/// body axes), read `shift_s` later ([`super::wheel_delay::shift_rho`]).
fn rotor_momentum(
    samples: &[Sample],
    speeds: &[f64],
    m: usize,
    i: usize,
    per_unit: Vector3<f64>,
    shift_s: f64,
) -> Vec<Sample> {
    let mut rotor: Vec<Sample> = samples.to_vec();
    for (k, x) in rotor.iter_mut().enumerate() {
        x.rho_nms = per_unit * speeds[k * m + i];
    }
    super::wheel_delay::shift_rho(&mut rotor, shift_s);
    rotor
}

/// The samples' rotor momentum `Σ_i J_i u_i ω̃_i(t + δ + δ_i) a_i` with each rotor's
/// speeds read at the run's time tag `delay_s` plus its own `tags_s[i]` (none: 0).
pub(crate) fn momentum(
    samples: &[Sample],
    speeds: &[f64],
    spacecraft: &Spacecraft,
    delay_s: f64,
    tags_s: &[f64],
) -> Vec<Vector3<f64>> {
    // Each rotor's whole momentum: the change its own axis makes, per unit of it.
    let axes = spacecraft
        .rotors
        .iter()
        .map(|r| Vector3::from(r.axis))
        .collect();
    source_momentum(
        samples,
        speeds,
        spacecraft,
        &Change::Directions(axes),
        delay_s,
        tags_s,
    )
}

/// The change of each sample's rotor momentum that a source's `change` makes, each
/// rotor read at the run's time tag `delay_s` plus its own `tags_s[i]` (none: 0), as the
/// sum was: `Σ_i J_i u_i ω̃_i d_i` for directions, `σ ρ̇_i(t)` for a time tag.
pub(crate) fn source_momentum(
    samples: &[Sample],
    speeds: &[f64],
    spacecraft: &Spacecraft,
    change: &Change,
    delay_s: f64,
    tags_s: &[f64],
) -> Vec<Vector3<f64>> {
    let m = spacecraft.rotors.len();
    let shift = |i: usize| delay_s + tags_s.get(i).copied().unwrap_or(0.0);
    let mut out = vec![Vector3::zeros(); samples.len()];
    match change {
        Change::Directions(directions) => {
            for (i, (r, d)) in spacecraft.rotors.iter().zip(directions).enumerate() {
                if *d == Vector3::zeros() {
                    continue;
                }
                let per_unit = d * (r.spin_inertia_kg_m2 * r.speed_unit.to_rad_s());
                let part = rotor_momentum(samples, speeds, m, i, per_unit, shift(i));
                for (o, p) in out.iter_mut().zip(&part) {
                    *o += p.rho_nms;
                }
            }
        }
        &Change::TimeTag { rotor: i, sigma_s } => {
            let Some(r) = spacecraft.rotors.get(i) else {
                return out;
            };
            // The slope at the rotor's time tag times σ (a central difference over a
            // hundredth of σ, or more where the time stamps' precision needs it: a time
            // near 1.7e9 s, Unix time, resolves 0.4 µs). A secant over σ itself left the
            // consider term's changed run without an answer on a Basilisk record
            // (`tests/test_basilisk_outside.py`), and it is a poorer slope for the second
            // pass to converge on.
            let t_max = samples.iter().map(|s| s.t_s.abs()).fold(0.0, f64::max);
            let eps = (sigma_s * TIME_TAG_STEP).max(TIME_RESOLUTION * (1.0 + t_max));
            let at = |s: f64| rotor_momentum(samples, speeds, m, i, r.momentum_per_unit(), s);
            let (late, early) = (at(shift(i) + eps), at(shift(i) - eps));
            for ((o, a), b) in out.iter_mut().zip(&late).zip(&early) {
                *o = (a.rho_nms - b.rho_nms) * (sigma_s / (2.0 * eps));
            }
        }
    }
    out
}

/// The relative σ of the rotor momentum that `spacecraft`'s time tags state on these
/// samples: `√(Σ_i Σ_k |δρ_i,k|²) / √(Σ_k |ρ_k|²)`, `δρ_i` rotor `i`'s time tag's 1σ
/// change ([`Change::TimeTag`]), read at the run's time tag `delay_s`; 0 without time
/// tags or rotor momentum.
pub(crate) fn time_tag_relative_sigma(
    samples: &[Sample],
    speeds: &[f64],
    spacecraft: &Spacecraft,
    delay_s: f64,
) -> f64 {
    let m = spacecraft.rotors.len();
    if m == 0 || speeds.len() != samples.len() * m {
        return 0.0;
    }
    let rho2: f64 = momentum(samples, speeds, spacecraft, delay_s, &[])
        .iter()
        .map(Vector3::norm_squared)
        .sum();
    let tags2: f64 = sources(spacecraft)
        .iter()
        .filter(|s| matches!(s.change, Change::TimeTag { .. }))
        .flat_map(|s| source_momentum(samples, speeds, spacecraft, &s.change, delay_s, &[]))
        .map(|d| d.norm_squared())
        .sum();
    if rho2 > 0.0 {
        crate::math::sqrt(tags2 / rho2)
    } else {
        0.0
    }
}

/// The independent 1σ error sources of `spacecraft` ([module docs](self)): a label, and
/// what each changes ([`Change`]).
pub(crate) fn sources(spacecraft: &Spacecraft) -> Vec<Source> {
    let rotors = &spacecraft.rotors;
    let axis = |i: usize| Vector3::from(rotors[i].axis);
    let only = |i: usize, d: Vector3<f64>| -> Vec<Vector3<f64>> {
        (0..rotors.len())
            .map(|k| if k == i { d } else { Vector3::zeros() })
            .collect()
    };
    let mut out = Vec::new();
    match spacecraft.rotor_errors {
        RotorErrors::Shared => {
            let largest = rotors
                .iter()
                .map(|r| r.relative_sigma())
                .fold(0.0, f64::max);
            if largest > 0.0 {
                out.push(Source {
                    label: "spin inertia".into(),
                    change: Change::Directions(
                        (0..rotors.len())
                            .map(|i| axis(i) * rotors[i].relative_sigma())
                            .collect(),
                    ),
                    sigma: largest,
                    unit: "relative",
                });
            }
        }
        RotorErrors::Independent => {
            for (i, r) in rotors.iter().enumerate() {
                if r.relative_sigma() > 0.0 {
                    out.push(Source {
                        label: std::format!("{} spin inertia", r.name),
                        change: Change::Directions(only(i, axis(i) * r.relative_sigma())),
                        sigma: r.relative_sigma(),
                        unit: "relative",
                    });
                }
            }
        }
    }
    for (i, r) in rotors.iter().enumerate() {
        if r.spin_axis_sigma_deg > 0.0 {
            let t = r.spin_axis_sigma_deg.to_radians();
            for (j, e) in r.tilt_directions().iter().enumerate() {
                out.push(Source {
                    label: std::format!("{} axis tilt {}", r.name, j + 1),
                    change: Change::Directions(only(i, e * t)),
                    sigma: r.spin_axis_sigma_deg,
                    unit: "deg",
                });
            }
        }
    }
    for (i, r) in rotors.iter().enumerate() {
        if r.time_tag_sigma_s > 0.0 {
            out.push(Source {
                label: std::format!("{} time tag", r.name),
                change: Change::TimeTag {
                    rotor: i,
                    sigma_s: r.time_tag_sigma_s,
                },
                sigma: r.time_tag_sigma_s,
                unit: "s",
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_moves_add_in_quadrature() {
        let c = RotorInertiaConsider {
            errors: RotorErrors::Independent,
            relative_sigma: vec![0.1, 0.2],
            sources: vec!["a".into(), "b".into()],
            moves_kg_m2: vec![
                [0.1, -0.2, 0.0, 0.0, 0.0, 0.3],
                [0.2, 0.4, 0.0, 0.0, 0.0, 0.8],
            ],
        };
        let x = c.consider_kg_m2();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(
            close(x[0], 0.05f64.sqrt()) && close(x[1], 0.2f64.sqrt()),
            "{x:?}"
        );
        assert!(close(x[5], 0.73f64.sqrt()) && x[2] == 0.0, "{x:?}");
    }

    /// Problem: one rotor on x whose speed ramps, `ω = 2 t` rad/s at `t = 1 … N` s, its
    /// time tag ± 0.1 s. Reference: the ramp's slope times 0.1 s moves every momentum by
    /// `J · 2 · 0.1` against a momentum `J · 2 t`, but the first and the last by half
    /// that (held beyond the record), so the relative σ is `√(4(N − 2) + 2) · 0.1 /
    /// (2 √(Σ t²))`, on Unix time stamps too; without a time-tag σ, 0.
    #[test]
    fn the_time_tags_relative_sigma_is_their_share_of_the_momentum() {
        use crate::spacecraft::{Rotor, SpeedUnit};
        let n = 50;
        let rotor = Rotor {
            name: "x".into(),
            axis: [1.0, 0.0, 0.0],
            spin_inertia_kg_m2: 0.01,
            spin_inertia_sigma_kg_m2: 0.0,
            spin_axis_sigma_deg: 0.0,
            time_tag_sigma_s: 0.1,
            speed_column: "w".into(),
            speed_unit: SpeedUnit::RadPerS,
            max_torque_nm: None,
            max_momentum_nms: None,
        };
        let mut sc = Spacecraft {
            rotors: vec![rotor],
            ..Spacecraft::default()
        };
        let samples: Vec<Sample> = (1..=n)
            .map(|k| Sample {
                t_s: k as f64,
                q: crate::attitude::Quaternion::IDENTITY,
                rho_nms: Vector3::zeros(),
                tau_nm: Vector3::zeros(),
                omega_rad_s: None,
                external: Default::default(),
            })
            .collect();
        let speeds: Vec<f64> = samples.iter().map(|s| 2.0 * s.t_s).collect();
        let t2: f64 = samples.iter().map(|s| s.t_s * s.t_s).sum();
        let expected = (4.0 * (n - 2) as f64 + 2.0).sqrt() * 0.1 / (2.0 * t2.sqrt());
        let got = time_tag_relative_sigma(&samples, &speeds, &sc, 0.0);
        assert!(
            (got - expected).abs() < 1e-9 * expected,
            "{got} vs {expected}"
        );
        // The same ramp on Unix time stamps (1.7e9 s, resolved to 0.24 µs): the difference
        // keeps its step above their precision, and a σ of 10 µs keeps its share.
        let epoch: Vec<Sample> = samples
            .iter()
            .map(|s| Sample {
                t_s: s.t_s + 1.7e9,
                ..*s
            })
            .collect();
        sc.rotors[0].time_tag_sigma_s = 1e-5;
        let got = time_tag_relative_sigma(&epoch, &speeds, &sc, 0.0);
        let expected = expected * 1e-4;
        assert!(
            (got - expected).abs() < 1e-3 * expected,
            "{got} vs {expected}"
        );
        sc.rotors[0].time_tag_sigma_s = 0.0;
        assert_eq!(time_tag_relative_sigma(&samples, &speeds, &sc, 0.0), 0.0);
    }
}
