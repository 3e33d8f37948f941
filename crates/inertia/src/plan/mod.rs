//! Planning the calibration manoeuvre: the wheel torque commands that reach a target σ of
//! the inertia soonest within every limit, and the σ the estimator will then show.
//!
//! ```text
//! Vehicle (prior J ± σ, wheels and limits, sensor noise, rates)
//!   ── design ──▶ for each horizon T (5 s grid), A-optimal time shares over the
//!                 rest-to-rest manoeuvres that fit in T (tours, three-phase trains)  (design)
//!   ── schedule ─▶ whole manoeuvres, largest deficit first, at the controller rate
//!   ── scan ────▶ the shortest T whose flown schedule meets the target by T
//!   ── predict ──▶ σ per element over time: information of the momentum rows     (predict)
//!   ── truncate ─▶ at the end of the tour in which 3 σ_F ≤ target
//! ```
//!
//! * `limits`: wheel torque and momentum per wheel through the allocation, body rate;
//!   every limit is linear in the commands because a plan keeps the total angular
//!   momentum at zero (`J ω = −ρ`);
//! * `profile`: the zero-order-hold command profile and its CSV (body axes and per
//!   wheel);
//! * `design`: the convex design and what it guarantees;
//! * `predict`: the prediction's rows, noise model and omissions;
//! * `fixed`: the fixed profiles a plan is compared with (PRBS, chirp, multi-sine,
//!   multi-step), scaled to the same limits.
//!
//! The target is the relative Frobenius σ `σ_F = √(Σ_i w_i σ_i²)/‖J‖_F` (`w` = 1 on the
//! diagonal, 2 off it): met when `3 σ_F ≤ target`.

pub(crate) mod design;
pub(crate) mod fixed;
pub(crate) mod limits;
pub(crate) mod predict;
pub(crate) mod profile;
#[cfg(feature = "sim")]
pub mod rehearse;
#[cfg(feature = "sim")]
pub mod request;

pub use design::{Atom, Design};
pub use limits::{LimitUse, Limits, LimitsError, Wheel};
pub use predict::{EstimatorModel, NoiseModel, Prediction};
pub use profile::CommandProfile;
pub use profile::ProfileError;

use nalgebra::Matrix3;
use std::string::String;
use std::vec::Vec;

/// Step of the minimum-time scan over horizons, s.
pub(crate) const SCAN_STEP_S: f64 = 5.0;

/// What a plan needs to know about the spacecraft.
#[derive(Debug, Clone, PartialEq)]
pub struct Vehicle {
    /// Prior inertia, kg m² (the trajectories and the rate limit use it).
    pub prior_kg_m2: Matrix3<f64>,
    /// Its σ per element, kg m² (`None`: no prior information in the prediction).
    pub prior_sigma_kg_m2: Option<[f64; 6]>,
    /// Wheels, rate limit and margin.
    pub limits: Limits,
    /// Sensor noise and telemetry period.
    pub noise: NoiseModel,
    /// Controller (command) period, s.
    pub controller_period_s: f64,
    /// The rotors' relative momentum-scale σ (the estimator's consider term).
    pub rotor_relative_sigma: f64,
}

/// What the plan aims at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSettings {
    /// Target relative Frobenius error at 3σ (e.g. 0.01); `None`: fly `max_duration_s`.
    pub target_relative: Option<f64>,
    /// The longest plan, s.
    pub max_duration_s: f64,
    /// The estimator's row model for the prediction.
    pub estimator: EstimatorModel,
    /// Prediction output period, s.
    pub every_s: f64,
}

impl Default for PlanSettings {
    fn default() -> Self {
        Self {
            target_relative: Some(0.01),
            max_duration_s: 1800.0,
            estimator: EstimatorModel::default(),
            every_s: 1.0,
        }
    }
}

/// Why no plan.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// The limits are unusable.
    #[error(transparent)]
    Limits(#[from] LimitsError),
    /// A setting is out of range.
    #[error("plan setting `{0}`: {1}")]
    Setting(&'static str, String),
    /// The spacecraft file lacks a key a plan needs.
    #[error("{file}: `{key}` is needed to plan a manoeuvre ({why})")]
    Missing {
        /// The file.
        file: String,
        /// The key.
        key: String,
        /// What it gives.
        why: &'static str,
    },
}

/// The largest fraction of a limit a plan uses: 0.9, less where the prior is uncertain
/// (the rate is `J⁻¹ρ` of the prior J; a J smaller by 3σ turns faster by `1/(1 − 3r)`).
#[must_use]
pub(crate) fn margin_for(prior_relative_sigma: f64) -> f64 {
    (1.0 / (1.0 + 3.0 * prior_relative_sigma)).min(0.9)
}

/// A plan: the commands, the design behind them and the prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The wheel torque commands.
    pub profile: CommandProfile,
    /// The time shares over the library.
    pub design: Design,
    /// The horizon the design was made for, s.
    pub horizon_s: f64,
    /// The tours flown, in order: index into `design.atoms` and end time, s.
    pub order: Vec<(usize, f64)>,
    /// Predicted σ over the plan.
    pub prediction: Prediction,
    /// When the target is met, s (None: not within `max_duration_s`, or no target).
    pub target_met_s: Option<f64>,
    /// How close the commands come to each limit (≤ margin).
    pub limit_use: LimitUse,
}

impl Vehicle {
    /// The vehicle of a spacecraft file: its wheels with `max_torque_nm` and
    /// `max_momentum_nms`, `[prior]`, `[sensors]` and `[limits]`; `file` names it in
    /// errors. The prior's σ sets the margin (`margin_for`); the rotors' stated σ is
    /// the consider term. The prior does not inform the prediction (the default
    /// estimator does not use it).
    pub fn from_spacecraft(
        sc: &crate::spacecraft::Spacecraft,
        file: &str,
    ) -> Result<Vehicle, PlanError> {
        let missing = |key: String, why| PlanError::Missing {
            file: file.into(),
            key,
            why,
        };
        let mut wheels = Vec::with_capacity(sc.rotors.len());
        for (i, r) in sc.rotors.iter().enumerate() {
            wheels.push(Wheel {
                name: r.name.clone(),
                axis: nalgebra::Vector3::from(r.axis),
                max_torque_nm: r.max_torque_nm.ok_or_else(|| {
                    missing(
                        std::format!("rotor[{i}].max_torque_nm"),
                        "the wheel's torque limit",
                    )
                })?,
                max_momentum_nms: r.max_momentum_nms.ok_or_else(|| {
                    missing(
                        std::format!("rotor[{i}].max_momentum_nms"),
                        "the wheel's momentum limit",
                    )
                })?,
            });
        }
        let prior = sc
            .prior
            .as_ref()
            .ok_or_else(|| missing("prior".into(), "the prior J and its σ"))?;
        let sensors = sc
            .sensors
            .ok_or_else(|| missing("sensors".into(), "noise densities and rates"))?;
        let j = Matrix3::from_fn(|r, c| prior.inertia_kg_m2[r][c]);
        let r = (0..3)
            .map(|i| prior.sigma_kg_m2[i] / j[(i, i)])
            .fold(0.0, f64::max);
        Ok(Vehicle {
            prior_kg_m2: j,
            prior_sigma_kg_m2: None,
            limits: Limits {
                wheels,
                max_rate_rad_s: sc.max_rate_deg_s.map(f64::to_radians),
                max_angle_rad: sc.max_angle_deg.map(f64::to_radians),
                margin: margin_for(r),
            },
            noise: NoiseModel {
                gyro_rad_s_rthz: sensors.gyro_noise_deg_s_rthz.to_radians(),
                wheel_nms: sensors.wheel_noise_nms,
                telemetry_period_s: 1.0 / sensors.telemetry_hz,
            },
            controller_period_s: 1.0 / sensors.controller_hz,
            rotor_relative_sigma: sc.stated_relative_sigma(),
        })
    }

    fn validate(&self) -> Result<(), PlanError> {
        self.limits.validate()?;
        let bad = |k, w: &str| Err(PlanError::Setting(k, w.into()));
        if !(self.controller_period_s.is_finite() && self.controller_period_s > 0.0) {
            return bad("controller_period_s", "must be finite and > 0");
        }
        let h = self.noise.telemetry_period_s;
        if !(h.is_finite() && h > 0.0) {
            return bad("telemetry_period_s", "must be finite and > 0");
        }
        let ratio = self.controller_period_s / h;
        if (ratio - ratio.round()).abs() > 1e-9 * ratio || ratio.round() < 1.0 {
            return bad(
                "controller_period_s",
                "must be a whole multiple of the telemetry period",
            );
        }
        if !(self.noise.gyro_rad_s_rthz >= 0.0 && self.noise.wheel_nms >= 0.0)
            || self.noise.gyro_rad_s_rthz + self.noise.wheel_nms <= 0.0
        {
            return bad("noise", "some sensor noise must be > 0 (and none negative)");
        }
        if self.prior_kg_m2.cholesky().is_none() {
            return bad("prior_kg_m2", "must be symmetric positive definite");
        }
        Ok(())
    }
}

/// Plan the manoeuvre (module docs): stop at the end of the tour in which the
/// information-matrix σ meets the target.
pub(crate) fn plan(v: &Vehicle, s: &PlanSettings) -> Result<Plan, PlanError> {
    let full = plan_full(v, s)?;
    let met = s.target_relative.and_then(|t| full.prediction.time_to(t));
    Ok(match met {
        Some(t) => full.truncated_after(t, v)?,
        None => full,
    })
}

/// The whole schedule to `max_duration_s` with its prediction, not truncated.
pub(crate) fn plan_full(v: &Vehicle, s: &PlanSettings) -> Result<Plan, PlanError> {
    v.validate()?;
    if !(s.max_duration_s.is_finite() && s.max_duration_s > 0.0) {
        return Err(PlanError::Setting(
            "max_duration_s",
            "must be finite and > 0".into(),
        ));
    }
    if let Some(t) = s.target_relative {
        if !(t.is_finite() && t > 0.0) {
            return Err(PlanError::Setting("target_relative", "must be > 0".into()));
        }
    }
    // Minimum time: the shortest horizon T (a grid of SCAN_STEP_S) for which the design
    // over the manoeuvres that fit in T, flown, meets the target by T.
    if s.target_relative.is_some() {
        let mut t = SCAN_STEP_S;
        while t <= s.max_duration_s + 1e-9 {
            if let Some(pl) = plan_for_horizon(v, s, t)? {
                if pl.target_met_s.is_some_and(|m| m <= t + 1e-9) {
                    return Ok(pl);
                }
            }
            t += SCAN_STEP_S;
        }
    }
    plan_for_horizon(v, s, s.max_duration_s.min(600.0))?.ok_or(PlanError::Setting(
        "max_duration_s",
        "no manoeuvre of the library fits".into(),
    ))
}

/// The design for horizon `horizon_s` (the library's manoeuvres that fit in it and the
/// three-phase trains made for it, [`design::trains_for`]), scheduled to
/// `max_duration_s`, with its prediction (`None` when nothing fits).
pub(crate) fn plan_for_horizon(
    v: &Vehicle,
    s: &PlanSettings,
    horizon_s: f64,
) -> Result<Option<Plan>, PlanError> {
    let j = &v.prior_kg_m2;
    let p = v.controller_period_s;
    let model = EstimatorModel {
        rotor_relative_sigma: v.rotor_relative_sigma,
        prior_sigma_kg_m2: v.prior_sigma_kg_m2,
        ..s.estimator
    };
    let mut atoms: Vec<design::Atom> = design::library_for(&v.limits, j, p, s.estimator.chain_s)?
        .into_iter()
        .filter(|a| a.commands.len() as f64 * p <= horizon_s + 1e-9)
        .collect();
    atoms.extend(design::trains_for(&v.limits, j, p, horizon_s)?);
    if atoms.is_empty() {
        return Ok(None);
    }
    let design = design::design_over(atoms, j, &v.noise, p, s.estimator.chain_s, Some(horizon_s));
    let (mut profile, order) = design::schedule(&design, p, s.max_duration_s);
    // Each manoeuvre keeps the angle limit alone and returns the rate to rest, but
    // rotations do not commute: in sequence they may leave a net rotation that adds up.
    // The whole plan is scaled down where it does.
    if v.limits.max_angle_rad.is_some() && v.limits.use_of(&profile, j)?.worst() > v.limits.margin {
        profile = profile.scaled(v.limits.scale_to_fit(&profile, j)?);
    }
    let prediction = predict::predict(
        &profile,
        j,
        &v.noise,
        &model,
        profile.duration_s(),
        s.every_s,
    );
    let target_met_s = s.target_relative.and_then(|t| prediction.time_to(t));
    let limit_use = v.limits.use_of(&profile, j)?;
    Ok(Some(Plan {
        profile,
        design,
        horizon_s,
        order,
        prediction,
        target_met_s,
        limit_use,
    }))
}

impl Plan {
    /// This plan cut at the end of the tour in progress at `t_s` (the prediction with it).
    pub(crate) fn truncated_after(&self, t_s: f64, v: &Vehicle) -> Result<Plan, PlanError> {
        let k = self
            .order
            .iter()
            .position(|(_, end)| *end >= t_s - 1e-9)
            .unwrap_or(self.order.len().saturating_sub(1));
        let end = self.order.get(k).map_or(0.0, |o| o.1);
        let n = (end / self.profile.period_s).round() as usize;
        let keep = self
            .prediction
            .t_s
            .iter()
            .take_while(|x| **x <= end + 1e-9)
            .count();
        let profile = self.profile.truncated(n);
        let limit_use = v.limits.use_of(&profile, &v.prior_kg_m2)?;
        Ok(Plan {
            profile,
            design: self.design.clone(),
            horizon_s: self.horizon_s,
            order: self.order[..=k.min(self.order.len().saturating_sub(1))].to_vec(),
            prediction: Prediction {
                t_s: self.prediction.t_s[..keep].to_vec(),
                sigma_kg_m2: self.prediction.sigma_kg_m2[..keep].to_vec(),
                relative_sigma: self.prediction.relative_sigma[..keep].to_vec(),
            },
            target_met_s: self.target_met_s,
            limit_use,
        })
    }
}

/// A plan checked by rehearsal ([`rehearse`]): the schedule runs until both the
/// information-matrix σ and the median σ the estimator reports over the rehearsal's
/// flights meet the target, and stops at the end of that tour.
#[cfg(feature = "sim")]
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RehearsedPlan {
    /// The plan (its `target_met_s` is the information-matrix time).
    pub plan: Plan,
    /// Estimate times of the rehearsal, s.
    pub t_s: Vec<f64>,
    /// The median reported relative σ over the rehearsal's flights at each time.
    pub median_reported_relative_sigma: Vec<f64>,
    /// When that median meets the target, s.
    pub reported_target_met_s: Option<f64>,
    /// Rehearsal flights flown.
    pub(crate) seeds: u64,
}

/// Plan, then choose the design horizon by rehearsal: the designs for horizons from the
/// information-matrix minimum `T*` up to 8 T* (steps of ×1.25) are each rehearsed on the
/// prior J with `seeds` seeds, and the one whose median reported σ meets the target
/// soonest is kept, cut at the end of the manoeuvre in which both its information σ and
/// its rehearsal meet the target.
#[cfg(feature = "sim")]
pub(crate) fn plan_rehearsed(
    v: &Vehicle,
    s: &PlanSettings,
    flight: &rehearse::FlightSettings,
    seeds: u64,
) -> Result<RehearsedPlan, PlanError> {
    let first = plan_full(v, s)?;
    let target = s.target_relative.unwrap_or(0.0);
    let mut best: Option<RehearsedPlan> = None;
    let mut horizon = first.horizon_s;
    let mut tried = Vec::new();
    while horizon <= (8.0 * first.horizon_s).min(s.max_duration_s) + 1e-9 {
        let h = (horizon / SCAN_STEP_S).round().max(1.0) * SCAN_STEP_S;
        horizon *= 1.25;
        if tried.contains(&h) {
            continue;
        }
        tried.push(h);
        let Some(candidate) = plan_for_horizon(v, s, h)? else {
            continue;
        };
        // Rehearse no longer than the best so far needs.
        let bound = best
            .as_ref()
            .and_then(|b| b.reported_target_met_s)
            .unwrap_or(s.max_duration_s)
            .min(candidate.profile.duration_s());
        let fs = rehearse::FlightSettings {
            duration_s: bound,
            ..flight.clone()
        };
        let flights = rehearse::rehearse(v, &candidate.profile, &fs, seeds.max(1))
            .map_err(|e| PlanError::Setting("rehearsal", std::format!("{e}")))?;
        let (t_s, med, reported) = rehearse::median_reported(&flights, target);
        let better = match (best.as_ref().map(|b| b.reported_target_met_s), reported) {
            (None, _) | (Some(None), Some(_)) => true,
            (Some(Some(b)), Some(r)) => r < b,
            _ => false,
        };
        if better {
            best = Some(RehearsedPlan {
                plan: candidate,
                t_s,
                median_reported_relative_sigma: med,
                reported_target_met_s: reported,
                seeds,
            });
        }
    }
    let mut best = best.unwrap_or(RehearsedPlan {
        plan: first,
        t_s: Vec::new(),
        median_reported_relative_sigma: Vec::new(),
        reported_target_met_s: None,
        seeds,
    });
    if let (Some(a), Some(b)) = (best.plan.target_met_s, best.reported_target_met_s) {
        best.plan = best.plan.truncated_after(a.max(b), v)?;
    }
    Ok(best)
}

/// A fixed profile at the same limits and its prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedRun {
    /// Its name (`fixed::NAMES`).
    pub name: &'static str,
    /// The horizon it was built and scaled over, s.
    pub horizon_s: f64,
    /// The commands.
    pub profile: CommandProfile,
    /// Predicted σ over the horizon.
    pub prediction: Prediction,
    /// Predicted time to the target, s.
    pub target_met_s: Option<f64>,
}

/// Every fixed profile at each horizon of `horizons_s`, scaled to the vehicle's limits,
/// with its prediction under the same model as `plan`'s.
pub fn fixed_profiles(
    v: &Vehicle,
    s: &PlanSettings,
    horizons_s: &[f64],
) -> Result<Vec<FixedRun>, PlanError> {
    v.validate()?;
    let j = &v.prior_kg_m2;
    let model = EstimatorModel {
        rotor_relative_sigma: v.rotor_relative_sigma,
        prior_sigma_kg_m2: v.prior_sigma_kg_m2,
        ..s.estimator
    };
    let mut out = Vec::new();
    for name in fixed::NAMES {
        for &hz in horizons_s {
            let Some(profile) = fixed::fixed(name, v.controller_period_s, hz, &v.limits, j)? else {
                continue;
            };
            let prediction = predict::predict(&profile, j, &v.noise, &model, hz, s.every_s);
            let target_met_s = s.target_relative.and_then(|t| prediction.time_to(t));
            out.push(FixedRun {
                name,
                horizon_s: hz,
                profile,
                prediction,
                target_met_s,
            });
        }
    }
    Ok(out)
}

/// A test spacecraft as the peer's (`satellite-inertia-id`): prior `prior_kg_m2`, three
/// orthogonal wheels of `torque_nm` and `momentum_nms`, its gyro (1e-4 rad/s/√Hz), 10 Hz
/// telemetry, 1 Hz commands, margin 0.77.
#[cfg(test)]
pub(crate) fn peer_vehicle(
    prior_kg_m2: Matrix3<f64>,
    torque_nm: f64,
    momentum_nms: f64,
) -> Vehicle {
    Vehicle {
        prior_kg_m2,
        prior_sigma_kg_m2: None,
        limits: Limits {
            wheels: (0..3)
                .map(|i| Wheel {
                    name: std::format!("rw{i}"),
                    axis: nalgebra::Vector3::ith(i, 1.0),
                    max_torque_nm: torque_nm,
                    max_momentum_nms: momentum_nms,
                })
                .collect(),
            max_rate_rad_s: None,
            max_angle_rad: None,
            margin: 0.77,
        },
        noise: NoiseModel {
            gyro_rad_s_rthz: 1e-4,
            wheel_nms: 0.0,
            telemetry_period_s: 0.1,
        },
        controller_period_s: 1.0,
        rotor_relative_sigma: 0.0,
    }
}
