//! The known torque's scale as a consider parameter (book, "Status and uncertainty").
//!
//! A thruster's thrust, a torque rod's dipole or an actuator's torque law is known only to
//! a relative σ `r`. The momentum rows' right-hand side is linear in the rotor momentum and
//! the known torque, `b = b_ρ + b_τ` (the impulse sums of [`super::momentum_rows`]), and
//! the plain fit's regressors depend on neither ([`super::plain_fit`]). So its answer
//! splits as `ĵ = ĵ_ρ + ĵ_τ`, and a scale error `ε` of the known torque moves it by
//! `ε ĵ_τ` exactly. The consider term is `r |ĵ_τ|` per element, `ĵ_τ` the plain fit of
//! the rows with the rotor momentum set to zero.
//!
//! Without rotor momentum J scales with the known torque exactly and no residual can see
//! a scale error; with wheels a scale error also shows as a conflict between the two, in
//! the residuals and the jackknife, and the term is the part of `ĵ` the torque alone sets.
//! The gravity gradient is a model of J, not a measured torque: it has no such scale. The
//! centre of mass's columns (`−c × F`) are not in the plain fit.

use super::external_torque::OutsideTorques;
use super::plain_fit::{fit, rhs};
use super::wheel_delay::{rows, segments, Window};
use crate::sample::Sample;
use nalgebra::Vector3;
use std::vec::Vec;

/// `r |ĵ_τ|` per element (module docs) over `samples`, kg m²; `None` where `r` is not
/// positive, the samples carry no known torque, or the fit is singular.
#[must_use]
pub(crate) fn torque_scale_move(
    samples: &[Sample],
    outside: &OutsideTorques,
    r: f64,
) -> Option<[f64; 6]> {
    if !(r > 0.0) || samples.iter().all(|s| s.tau_nm == Vector3::zeros()) {
        return None;
    }
    let without_rotors: Vec<Sample> = samples
        .iter()
        .map(|s| Sample {
            rho_nms: Vector3::zeros(),
            ..*s
        })
        .collect();
    let t: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
    let windows: Vec<Window> = segments(&t)
        .into_iter()
        .filter(|&(a, b)| b >= a + 8)
        .map(|(a, b)| (a, b, a, b))
        .collect();
    let r_rows = rows(&without_rotors, &windows, 0.0, outside);
    let f = fit(&r_rows, &rhs(&r_rows))?;
    let out: [f64; 6] = core::array::from_fn(|k| (r * f.theta[3 + k]).abs());
    out.iter().all(|x| x.is_finite()).then_some(out)
}
