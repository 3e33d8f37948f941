//! Per-rotor speed telemetry from the simulated rotor momentum, for a spacecraft file's
//! rotors ([`crate::spacecraft`]).
//!
//! The simulator's wheels are three orthogonal-wheel equivalents whose sum `ρ` (body
//! axes) it integrates (`super::wheels`). A spacecraft with `m` rotors on axes `a_i`
//! (`A = [a_1 … a_m]`, which must span the three body axes) carries that momentum as the
//! minimum-norm split `h = Aᵀ(AAᵀ)⁻¹ ρ` (as a pseudo-inverse wheel allocator does), and
//! rotor `i` spins at `ω_i = h_i / J_i`, telemetered in its speed unit:
//! `ω̃_i = ω_i / u_i`. So `Σ_i J_i u_i ω̃_i a_i = ρ` exactly, and a spacecraft file whose
//! spin inertias differ from the ones used here is a file with those inertias wrong.

use super::SimError;
use crate::sample::Sample;
use crate::spacecraft::{Rotor, RotorErrors, Spacecraft, SpeedUnit};
use nalgebra::{Matrix3, Vector3};
use std::vec::Vec;

/// A four-wheel pyramid, the usual reaction-wheel layout: axes 35.26° from the body z
/// axis, at azimuths 0°, 90°, 180°, 270° (`rw1` … `rw4`); speeds in rpm in columns
/// `rw1_rpm` …; spin inertias `spin_inertia_kg_m2`, each ± `relative_sigma` of itself,
/// their errors related as `errors`; axes exact.
#[must_use]
pub fn pyramid(
    spin_inertia_kg_m2: [f64; 4],
    relative_sigma: f64,
    errors: RotorErrors,
) -> Spacecraft {
    let (c, s) = ((2.0f64 / 3.0).sqrt(), (1.0f64 / 3.0).sqrt());
    let axes = [[c, 0.0, s], [0.0, c, s], [-c, 0.0, s], [0.0, -c, s]];
    Spacecraft {
        rotors: (0..4)
            .map(|i| Rotor {
                name: std::format!("rw{}", i + 1),
                axis: axes[i],
                spin_inertia_kg_m2: spin_inertia_kg_m2[i],
                spin_inertia_sigma_kg_m2: relative_sigma * spin_inertia_kg_m2[i],
                spin_axis_sigma_deg: 0.0,
                time_tag_sigma_s: 0.0,
                speed_column: std::format!("rw{}_rpm", i + 1),
                speed_unit: SpeedUnit::Rpm,
                max_torque_nm: None,
                max_momentum_nms: None,
            })
            .collect(),
        rotor_errors: errors,
        ..Spacecraft::default()
    }
}

/// The wheels as flown and the spacecraft file that describes them: the file is
/// [`pyramid`] with each spin inertia drawn off `true_j` by a relative error of σ
/// `inertia_sigma` (one draw for all with [`RotorErrors::Shared`], one per wheel with
/// `Independent`) and stating that σ and a tilt σ `tilt_deg`; the flown wheels have the
/// true inertias and each axis tilted from the file's by two draws of σ `tilt_deg`
/// towards [`Rotor::tilt_directions`]. Draws in that order from `rng`: the common error,
/// the wheels' errors, the tilts.
pub fn drawn_pyramid(
    true_j: [f64; 4],
    inertia_sigma: f64,
    errors: RotorErrors,
    tilt_deg: f64,
    rng: &mut impl rand::Rng,
) -> (Spacecraft, Spacecraft) {
    use rand_distr::{Distribution, StandardNormal};
    let mut normal = || -> f64 { StandardNormal.sample(&mut *rng) };
    let common = normal();
    let stated_j: [f64; 4] = core::array::from_fn(|i| {
        let z = match errors {
            RotorErrors::Shared => common,
            RotorErrors::Independent => normal(),
        };
        true_j[i] * (1.0 + z * inertia_sigma)
    });
    let mut stated = pyramid(stated_j, inertia_sigma, errors);
    let mut flown = pyramid(true_j, 0.0, errors);
    let t = tilt_deg.to_radians();
    for (r, s) in flown.rotors.iter_mut().zip(&mut stated.rotors) {
        let [e1, e2] = r.tilt_directions();
        let a = Vector3::from(r.axis) + e1 * (t * normal()) + e2 * (t * normal());
        r.axis = a.normalize().into();
        s.spin_axis_sigma_deg = tilt_deg;
    }
    (flown, stated)
}

/// `spacecraft` with every σ of its rotors zero: its values taken as exact.
#[must_use]
pub fn stated_exact(spacecraft: &Spacecraft) -> Spacecraft {
    let mut sc = spacecraft.clone();
    for r in &mut sc.rotors {
        r.spin_inertia_sigma_kg_m2 = 0.0;
        r.spin_axis_sigma_deg = 0.0;
        r.time_tag_sigma_s = 0.0;
    }
    sc
}

/// The rotors' stored speeds for each sample (flat: one row of `m` per sample), from each
/// sample's rotor momentum, with the true spin inertias of `spacecraft`.
pub fn speeds(samples: &[Sample], spacecraft: &Spacecraft) -> Result<Vec<f64>, SimError> {
    let axes: Vec<Vector3<f64>> = spacecraft
        .rotors
        .iter()
        .map(|r| Vector3::from(r.axis))
        .collect();
    let aat: Matrix3<f64> = axes.iter().map(|a| a * a.transpose()).sum();
    // The axes must span the body: the smallest eigenvalue of AAᵀ away from zero.
    let smallest = aat.symmetric_eigenvalues().min();
    let inverse = aat
        .try_inverse()
        .filter(|_| smallest > 1e-6 * aat.trace())
        .ok_or(SimError::InvalidSetting {
            field: "spacecraft rotor axes",
            value: smallest,
            why: "the rotors' axes must span the three body axes (smallest eigenvalue of A Aᵀ shown)",
        })?;
    let per_unit: Vec<f64> = spacecraft
        .rotors
        .iter()
        .map(|r| r.spin_inertia_kg_m2 * r.speed_unit.to_rad_s())
        .collect();
    let mut out = Vec::with_capacity(samples.len() * axes.len());
    for s in samples {
        let y = inverse * s.rho_nms;
        out.extend(axes.iter().zip(&per_unit).map(|(a, u)| a.dot(&y) / u));
    }
    Ok(out)
}

/// The rotors' stored speeds where each rotor's telemetry has its own time tag: rotor
/// `i`'s speeds are [`speeds`] of `records[i]`, the same record simulated with the wheel
/// telemetry's skew ([`super::wheels::WheelTelemetry::skew_s`]) set to that rotor's own
/// (the skew changes the telemetered momentum only, not the motion). So rotor `i` reads
/// its true speed at `t + skew_i`, and the summed momentum of the file's rotors is
/// `Σ_i J_i ω_i(t + skew_i) a_i`.
pub fn speeds_each(records: &[&[Sample]], spacecraft: &Spacecraft) -> Result<Vec<f64>, SimError> {
    let m = spacecraft.rotors.len();
    if records.len() != m || m == 0 {
        return Err(SimError::InvalidSetting {
            field: "rotor records",
            value: records.len() as f64,
            why: "one record per rotor is needed",
        });
    }
    let n = records[0].len();
    let mut out = vec![0.0; n * m];
    for (i, r) in records.iter().enumerate() {
        if r.len() != n {
            return Err(SimError::InvalidSetting {
                field: "rotor records",
                value: r.len() as f64,
                why: "every rotor's record must have the same samples",
            });
        }
        let w = speeds(r, spacecraft)?;
        for k in 0..n {
            out[k * m + i] = w[k * m + i];
        }
    }
    Ok(out)
}

#[cfg(all(test, feature = "spacecraft"))]
mod tests {
    use super::*;

    const PYRAMID: &str = r#"
[[rotor]]
name = "rw1"
axis = [0.816497, 0.0, 0.577350]
spin_inertia_kg_m2 = 1.5e-3
speed_column = "s1"
speed_unit = "rpm"
[[rotor]]
name = "rw2"
axis = [0.0, 0.816497, 0.577350]
spin_inertia_kg_m2 = 1.6e-3
speed_column = "s2"
[[rotor]]
name = "rw3"
axis = [-0.816497, 0.0, 0.577350]
spin_inertia_kg_m2 = 1.7e-3
speed_column = "s3"
speed_unit = "deg/s"
[[rotor]]
name = "rw4"
axis = [0.0, -0.816497, 0.577350]
spin_inertia_kg_m2 = 1.8e-3
speed_column = "s4"
"#;

    fn sample(rho: Vector3<f64>) -> Sample {
        Sample {
            t_s: 0.0,
            q: crate::attitude::Quaternion::IDENTITY,
            rho_nms: rho,
            tau_nm: Vector3::zeros(),
            omega_rad_s: None,
            external: Default::default(),
        }
    }

    #[test]
    fn the_speeds_give_back_the_momentum_and_the_split_has_least_norm() {
        let sc = Spacecraft::parse(PYRAMID, "p.toml").unwrap();
        let rho = [Vector3::new(0.1, -0.2, 0.05), Vector3::new(-0.3, 0.0, 0.7)];
        let samples: Vec<Sample> = rho.iter().map(|&r| sample(r)).collect();
        let w = speeds(&samples, &sc).unwrap();
        for (k, r) in rho.iter().enumerate() {
            let back = sc.momentum_nms(&w[4 * k..4 * k + 4]);
            assert!((back - r).norm() < 1e-12 * r.norm(), "{back} vs {r}");
            // Least norm: the wheel momenta h are orthogonal to the null space of A,
            // here (1, -1, 1, -1)/2 in the pyramid's order.
            let h: Vec<f64> = (0..4)
                .map(|i| {
                    w[4 * k + i]
                        * sc.rotors[i].spin_inertia_kg_m2
                        * sc.rotors[i].speed_unit.to_rad_s()
                })
                .collect();
            let null = h[0] - h[1] + h[2] - h[3];
            assert!(null.abs() < 1e-12, "{h:?}");
        }
    }

    #[test]
    fn axes_that_miss_a_body_axis_are_refused() {
        let flat = PYRAMID
            .replace("0.577350", "0.0")
            .replace("0.816497", "1.0");
        let sc = Spacecraft::parse(&flat, "p.toml").unwrap();
        let e = speeds(&[sample(Vector3::x())], &sc).unwrap_err();
        assert!(e.to_string().contains("span the three body axes"), "{e}");
    }
}
