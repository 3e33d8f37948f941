//! The limits a command profile must respect, and the check of a profile against them.
//!
//! # Wheels and allocation
//!
//! `m` wheels on unit axes `a_i` (`A = [a_1 … a_m]`, spanning the body) carry the body-axis
//! rotor momentum `ρ` as the minimum-norm split `h = A⁺ ρ`, `A⁺ = Aᵀ(AAᵀ)⁻¹` (a
//! pseudo-inverse allocator, as [`crate::sim::rotors`] telemeters it), and the wheel torque
//! commands `ρ̇` as `ḣ = A⁺ ρ̇`. Wheel `i` must keep `|ḣ_i| ≤ τ_max,i` (motor torque) and
//! `|h_i| ≤ h_max,i` (momentum: the speed limit times the spin inertia).
//!
//! # Rate from the momentum
//!
//! A plan starts at rest with the wheels at zero momentum, so the total angular momentum is
//! zero and stays zero up to the unknown disturbances: `J ω + ρ = 0` in body axes at every
//! instant (eq. 26 with `τ = 0`: `d/dt (Jω + ρ) + ω × (Jω + ρ) = 0` keeps it at zero). So
//! `ρ(t) = ∫ ρ̇ dt` exactly, the body rate is `ω = −J⁻¹ ρ`, and every limit of a profile is
//! a linear function of its commands: the momentum and rate peak at a command tick
//! (`ρ` is piecewise linear between them). The rate is computed with the prior J; the
//! margin ([`Limits::margin`]) keeps the true rate inside the limit for a J off by less
//! than `1 − margin` of itself.

use crate::plan::profile::CommandProfile;
use nalgebra::{DMatrix, Matrix3, Vector3};
use std::string::String;
use std::vec::Vec;

/// One reaction wheel.
#[derive(Debug, Clone, PartialEq)]
pub struct Wheel {
    /// Name (column names of the per-wheel export).
    pub name: String,
    /// Spin axis, body axes, unit.
    pub axis: Vector3<f64>,
    /// Largest motor torque, N m.
    pub max_torque_nm: f64,
    /// Largest stored momentum, N m s (speed limit × spin inertia).
    pub max_momentum_nms: f64,
}

/// Every limit of a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// The wheels.
    pub wheels: Vec<Wheel>,
    /// Largest body rate magnitude, rad/s (`None`: none but the wheels').
    pub max_rate_rad_s: Option<f64>,
    /// Largest rotation of the body from its attitude at the start of the plan, rad (a
    /// pointing budget; `None`: none).
    pub max_angle_rad: Option<f64>,
    /// Fraction of each limit a plan may use, in (0, 1] (default 0.9).
    pub margin: f64,
}

/// Why limits cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LimitsError {
    /// The wheels' axes do not span the body.
    #[error(
        "the wheels' axes must span the three body axes (smallest eigenvalue of A Aᵀ {0:.3e})"
    )]
    AxesDoNotSpan(f64),
    /// A limit is missing or not positive.
    #[error("wheel `{wheel}`: {what} must be finite and > 0 (got {value})")]
    BadLimit {
        /// Wheel name.
        wheel: String,
        /// Which limit.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// No wheel.
    #[error("no wheel: a plan needs reaction wheels with torque and momentum limits")]
    NoWheel,
    /// The rate limit or the margin is out of range.
    #[error("{0}")]
    Other(&'static str),
}

/// How close a profile comes to each limit: the largest ratio of use to limit (≤ 1 is
/// inside), over the whole profile.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LimitUse {
    /// Largest `|ḣ_i| / τ_max,i`.
    pub torque: f64,
    /// Largest `|h_i| / h_max,i`.
    pub momentum: f64,
    /// Largest `|ω| / ω_max` (0 without a rate limit).
    pub rate: f64,
    /// Largest rotation from the start over its limit (0 without an angle limit).
    pub angle: f64,
}

impl LimitUse {
    /// The largest of the four.
    #[must_use]
    pub(crate) fn worst(&self) -> f64 {
        self.torque
            .max(self.momentum)
            .max(self.rate)
            .max(self.angle)
    }
}

impl Limits {
    /// Check the wheels, the rate limit and the margin.
    pub(crate) fn validate(&self) -> Result<(), LimitsError> {
        if self.wheels.is_empty() {
            return Err(LimitsError::NoWheel);
        }
        for w in &self.wheels {
            for (what, value) in [
                ("max_torque_nm", w.max_torque_nm),
                ("max_momentum_nms", w.max_momentum_nms),
            ] {
                if !(value.is_finite() && value > 0.0) {
                    return Err(LimitsError::BadLimit {
                        wheel: w.name.clone(),
                        what,
                        value,
                    });
                }
            }
        }
        if let Some(r) = self.max_rate_rad_s {
            if !(r.is_finite() && r > 0.0) {
                return Err(LimitsError::Other("the rate limit must be finite and > 0"));
            }
        }
        if let Some(a) = self.max_angle_rad {
            if !(a.is_finite() && a > 0.0 && a <= core::f64::consts::PI) {
                return Err(LimitsError::Other(
                    "the angle limit must be finite, > 0 and at most 180°",
                ));
            }
        }
        if !(self.margin > 0.0 && self.margin <= 1.0) {
            return Err(LimitsError::Other("the margin must be in (0, 1]"));
        }
        self.allocation().map(|_| ())
    }

    /// The allocation `A⁺ = Aᵀ(AAᵀ)⁻¹` (m × 3).
    pub fn allocation(&self) -> Result<DMatrix<f64>, LimitsError> {
        let aat: Matrix3<f64> = self
            .wheels
            .iter()
            .map(|w| w.axis * w.axis.transpose())
            .sum();
        let smallest = aat.symmetric_eigenvalues().min();
        let inv = aat
            .try_inverse()
            .filter(|_| smallest > 1e-6 * aat.trace())
            .ok_or(LimitsError::AxesDoNotSpan(smallest))?;
        let m = self.wheels.len();
        Ok(DMatrix::from_fn(m, 3, |i, c| {
            (self.wheels[i].axis.transpose() * inv)[c]
        }))
    }

    /// How close `profile` comes to each limit, with the body rate `ω = −J⁻¹ρ` of the
    /// nominal inertia `j_kg_m2` (module docs).
    pub fn use_of(
        &self,
        profile: &CommandProfile,
        j_kg_m2: &Matrix3<f64>,
    ) -> Result<LimitUse, LimitsError> {
        let alloc = self.allocation()?;
        let j_inv = j_kg_m2
            .try_inverse()
            .ok_or(LimitsError::Other("the prior inertia is singular"))?;
        let per_wheel = |v: &Vector3<f64>, limit: fn(&Wheel) -> f64| -> f64 {
            let h = &alloc * nalgebra::DVector::from_column_slice(v.as_slice());
            self.wheels
                .iter()
                .zip(h.iter())
                .map(|(w, x)| x.abs() / limit(w))
                .fold(0.0, f64::max)
        };
        let mut out = LimitUse {
            torque: 0.0,
            momentum: 0.0,
            rate: 0.0,
            angle: self
                .max_angle_rad
                .map_or(0.0, |a| profile.max_angle_rad(&j_inv) / a),
        };
        for c in &profile.torque_nm {
            out.torque = out.torque.max(per_wheel(c, |w| w.max_torque_nm));
        }
        for rho in profile.momentum_at_ticks() {
            out.momentum = out.momentum.max(per_wheel(&rho, |w| w.max_momentum_nms));
            if let Some(r) = self.max_rate_rad_s {
                out.rate = out.rate.max((j_inv * rho).norm() / r);
            }
        }
        Ok(out)
    }

    /// The same check on a flown trajectory: the true wheel momenta `ρ` and body rates `ω`
    /// at the telemetry nodes (for the flight checks; torque is checked on the commands).
    #[cfg_attr(not(feature = "sim"), allow(dead_code))] // used by the rehearsal (feature `sim`)
    pub(crate) fn use_of_flight(
        &self,
        rho_nms: &[Vector3<f64>],
        omega_rad_s: &[Vector3<f64>],
    ) -> Result<(f64, f64), LimitsError> {
        let alloc = self.allocation()?;
        let mut momentum: f64 = 0.0;
        for rho in rho_nms {
            let h = &alloc * nalgebra::DVector::from_column_slice(rho.as_slice());
            for (w, x) in self.wheels.iter().zip(h.iter()) {
                momentum = momentum.max(x.abs() / w.max_momentum_nms);
            }
        }
        let rate = match self.max_rate_rad_s {
            Some(r) => omega_rad_s.iter().map(|w| w.norm() / r).fold(0.0, f64::max),
            None => 0.0,
        };
        Ok((momentum, rate))
    }

    /// The factor by which to scale `profile` so that it uses [`Self::margin`] of its
    /// tightest limit. Torque, momentum and rate are linear in the commands (module
    /// docs); the angle is not quite (rotations do not commute), so with an angle limit
    /// the factor is refined until the scaled profile uses the margin to 1e-6, from
    /// below.
    pub(crate) fn scale_to_fit(
        &self,
        profile: &CommandProfile,
        j_kg_m2: &Matrix3<f64>,
    ) -> Result<f64, LimitsError> {
        let worst = self.use_of(profile, j_kg_m2)?.worst();
        if !(worst > 0.0) {
            return Err(LimitsError::Other("the profile commands nothing"));
        }
        let mut s = self.margin / worst;
        if self.max_angle_rad.is_some() {
            let fits = |s: f64| -> Result<f64, LimitsError> {
                Ok(self.use_of(&profile.scaled(s), j_kg_m2)?.worst())
            };
            // Secant steps from the linear guess, then bisection between a scale that fits
            // and one that does not: the result always fits.
            let (mut lo, mut hi) = (0.0, f64::INFINITY);
            for _ in 0..60 {
                let used = fits(s)?;
                if used <= self.margin {
                    lo = s;
                    if used >= self.margin * (1.0 - 1e-6) {
                        break;
                    }
                } else {
                    hi = s;
                }
                let next = s * self.margin * (1.0 - 1e-7) / used;
                s = if next > lo && next < hi {
                    next
                } else if hi.is_finite() {
                    0.5 * (lo + hi)
                } else {
                    2.0 * s
                };
            }
            s = lo;
        }
        Ok(s)
    }

    /// Largest rate magnitude `a` and rate acceleration `α` for a rotation at rate
    /// `ω = a u` about the unit body direction `u` (the momentum `ρ = −a J u`): each
    /// wheel's share of `J u` against its momentum and torque limits, and the rate limit,
    /// all times the margin.
    pub(crate) fn along(
        &self,
        u: &Vector3<f64>,
        j_kg_m2: &Matrix3<f64>,
    ) -> Result<(f64, f64), LimitsError> {
        let alloc = self.allocation()?;
        let ju = j_kg_m2 * u;
        let h = &alloc * nalgebra::DVector::from_column_slice(ju.as_slice());
        let mut a = f64::INFINITY;
        let mut alpha = f64::INFINITY;
        for (w, x) in self.wheels.iter().zip(h.iter()) {
            if x.abs() > 0.0 {
                a = a.min(w.max_momentum_nms / x.abs());
                alpha = alpha.min(w.max_torque_nm / x.abs());
            }
        }
        if let Some(r) = self.max_rate_rad_s {
            a = a.min(r);
        }
        Ok((a * self.margin, alpha * self.margin))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn three(tau: f64, h: f64, rate: Option<f64>) -> Limits {
        Limits {
            wheels: (0..3)
                .map(|i| Wheel {
                    name: std::format!("rw{i}"),
                    axis: Vector3::ith(i, 1.0),
                    max_torque_nm: tau,
                    max_momentum_nms: h,
                })
                .collect(),
            max_rate_rad_s: rate,
            max_angle_rad: None,
            margin: 1.0,
        }
    }

    /// A constant torque on x for 10 s: torque use τ/τmax, momentum 10τ/hmax, rate
    /// 10τ/(J11 ωmax); scaling by `scale_to_fit` brings the worst to the margin.
    #[test]
    fn use_and_scale_match_hand_values() {
        let lim = three(0.01, 0.05, Some(0.2));
        let j = Matrix3::from_diagonal(&Vector3::new(0.5, 1.0, 2.0));
        let p = CommandProfile::new(0.0, 1.0, std::vec![Vector3::new(0.004, 0.0, 0.0); 10]);
        let u = lim.use_of(&p, &j).unwrap();
        assert!((u.torque - 0.4).abs() < 1e-12);
        assert!((u.momentum - 0.8).abs() < 1e-12);
        assert!((u.rate - 0.04 / 0.5 / 0.2).abs() < 1e-12);
        let s = lim.scale_to_fit(&p, &j).unwrap();
        let scaled = p.scaled(s);
        assert!((lim.use_of(&scaled, &j).unwrap().worst() - 1.0).abs() < 1e-12);
    }

    /// `along` gives a rate and acceleration whose momentum and torque hit the limits.
    #[test]
    fn along_a_direction_meets_the_tightest_limit() {
        let lim = three(0.01, 0.05, None);
        let j = Matrix3::from_diagonal(&Vector3::new(0.5, 1.0, 2.0));
        let u = Vector3::new(1.0, 1.0, 0.0).normalize();
        let (a, alpha) = lim.along(&u, &j).unwrap();
        let h = j * u * a;
        assert!((h.amax() - 0.05).abs() < 1e-12, "{h}");
        assert!(((j * u * alpha).amax() - 0.01).abs() < 1e-12);
    }

    #[test]
    fn coplanar_wheels_are_refused() {
        let mut lim = three(0.01, 0.05, None);
        lim.wheels[2].axis = Vector3::x();
        assert!(matches!(lim.validate(), Err(LimitsError::AxesDoNotSpan(_))));
    }

    /// A doublet about body x on a diagonal J turns about x only: the angle is the
    /// integral of `ω_x = −ρ_x/J_xx`, worked here on the piecewise-linear `ρ` by the
    /// trapezoid at a fine step; an angle limit scales the profile to its margin.
    #[test]
    fn the_angle_of_a_single_axis_doublet_is_the_rate_integral() {
        let j = Matrix3::from_diagonal(&Vector3::new(0.3, 0.2, 0.1));
        let c = Vector3::new(2e-3, 0.0, 0.0);
        let mut cmds = std::vec![c; 3];
        cmds.extend(std::vec![-c; 6]);
        cmds.extend(std::vec![c; 3]);
        let p = CommandProfile::new(0.0, 1.0, cmds);
        let (mut rho, mut angle, mut worst) = (0.0f64, 0.0f64, 0.0f64);
        let dt = 1e-4;
        for k in 0..12 {
            let cx = p.torque_nm[k].x;
            for _ in 0..10_000 {
                let next = rho + cx * dt;
                angle += -0.5 * (rho + next) / 0.3 * dt;
                rho = next;
                worst = worst.max(angle.abs());
            }
        }
        let got = p.max_angle_rad(&j.try_inverse().unwrap());
        assert!((got - worst).abs() <= 1e-6 * worst, "{got} vs {worst}");
        let mut l = three(1.0, 1.0, None);
        l.max_angle_rad = Some(0.5 * worst);
        let s = l.scale_to_fit(&p, &j).unwrap();
        let used = l.use_of(&p.scaled(s), &j).unwrap();
        assert!(
            used.angle <= l.margin && used.angle >= l.margin * (1.0 - 1e-6),
            "{used:?}"
        );
        assert!((s - 0.5 * l.margin).abs() < 1e-6, "{s}");
    }
}
