//! One call for the front ends (CLI, Python): a spacecraft's [`Vehicle`] and what the user
//! asked for → the plan, rehearsed or not.

use crate::pipeline::PipelineSettings;
use crate::plan::rehearse::FlightSettings;
use crate::plan::{
    plan, plan_full, plan_rehearsed, EstimatorModel, Plan, PlanError, PlanSettings, Vehicle,
};
use std::vec::Vec;

/// What the user asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Request {
    /// Target relative Frobenius error at 3σ.
    pub target_relative: f64,
    /// Fly exactly this long instead of stopping at the target, s.
    pub duration_s: Option<f64>,
    /// The longest plan, s.
    pub max_duration_s: f64,
    /// The estimator's short momentum chain, s (`None`: chains end only at gaps).
    pub chain_s: Option<f64>,
    /// Rehearsal flights (0: the information matrix alone decides where to stop).
    pub rehearsals: u64,
    /// Unknown white disturbance torque density of the rehearsals, N m/√Hz.
    pub disturbance_nm_rthz: f64,
}

impl Default for Request {
    fn default() -> Self {
        Self {
            target_relative: 0.01,
            duration_s: None,
            max_duration_s: 1800.0,
            chain_s: Some(crate::pipeline::DEFAULT_MAX_CHAIN_S),
            rehearsals: 8,
            disturbance_nm_rthz: 1e-8,
        }
    }
}

/// The plan and, when rehearsed, what the estimator reported.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// The plan.
    pub plan: Plan,
    /// Rehearsal times, s, and the median reported relative σ at each (empty without).
    pub rehearsal: (Vec<f64>, Vec<f64>),
    /// When the rehearsal's median met the target, s.
    pub reported_target_met_s: Option<f64>,
    /// Rehearsal flights flown.
    pub rehearsals: u64,
}

/// Plan as asked (module docs).
pub fn make(v: &Vehicle, r: &Request) -> Result<Outcome, PlanError> {
    if !(r.target_relative.is_finite() && r.target_relative > 0.0) {
        return Err(PlanError::Setting(
            "target",
            "must be finite and > 0".into(),
        ));
    }
    if let Some(c) = r.chain_s {
        if !(c.is_finite() && c > 0.0) {
            return Err(PlanError::Setting(
                "chain_s",
                "must be finite and > 0".into(),
            ));
        }
    }
    if !(r.disturbance_nm_rthz.is_finite() && r.disturbance_nm_rthz >= 0.0) {
        return Err(PlanError::Setting(
            "disturbance",
            "must be finite and >= 0".into(),
        ));
    }
    let settings = PlanSettings {
        target_relative: r.duration_s.is_none().then_some(r.target_relative),
        max_duration_s: r.duration_s.unwrap_or(r.max_duration_s),
        estimator: EstimatorModel {
            chain_s: r.chain_s,
            ..EstimatorModel::default()
        },
        ..PlanSettings::default()
    };
    let none = |plan| Outcome {
        plan,
        rehearsal: (Vec::new(), Vec::new()),
        reported_target_met_s: None,
        rehearsals: 0,
    };
    if r.duration_s.is_some() {
        return Ok(none(plan_full(v, &settings)?));
    }
    if r.rehearsals == 0 {
        return Ok(none(plan(v, &settings)?));
    }
    let flight = FlightSettings {
        duration_s: settings.max_duration_s,
        disturbance_nm_rthz: r.disturbance_nm_rthz,
        estimator: PipelineSettings {
            // One solve per second of telemetry.
            solve_every: ((1.0 / v.noise.telemetry_period_s).round() as usize).max(1),
            max_chain_s: r.chain_s,
            ..PipelineSettings::default()
        },
    };
    let rp = plan_rehearsed(v, &settings, &flight, r.rehearsals)?;
    Ok(Outcome {
        plan: rp.plan,
        rehearsal: (rp.t_s, rp.median_reported_relative_sigma),
        reported_target_met_s: rp.reported_target_met_s,
        rehearsals: rp.seeds,
    })
}
