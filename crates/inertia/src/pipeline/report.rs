//! The end-of-run report (feature `serde`): one [`Report`] serialises to the versioned
//! JSON schema of `inertia estimate --json` and displays as its text report.
//!
//! Schema version `SCHEMA_VERSION`. Keys (units in the README's conventions; products
//! of inertia are tensor entries, `J12 = −Σ m x y`): `schema_version`, the input summary
//! (`file`, `sample_period_s`, `renormalised`, `sign_flips`, `min_step_s`, `max_step_s`,
//! and `records` when there are several, when the samples came from files), `estimator`, `solver`, `constraints`, `batch`,
//! `samples`, `gaps`, `t`, `status` ([`Observability::code`]), `reason`, `condition`,
//! `inertia` (3×3, kg m²), `j`, `sigma`, `principal_moments`, `principal_moments_sigma`,
//! `principal_axes` (columns), `solver_status`, `iterations`, `relative_error` (against a
//! given truth), `excitation`, `active_bounds` (`component`, `side`, `value_kg_m2` of each
//! element bound the answer sits on), `residual_consistency` (the span whose residuals stand out
//! most: `ratio`, `t_start_s`, `t_end_s`; [`crate::estimator::consistency`]),
//! `gyro_density_ratio` (the residual variance over the part the stated gyro density
//! implies). Absent values are `null`.
//!
//! [`Observability::code`]: crate::estimator::observability::Observability::code

mod text;
mod warning;
pub use text::ReportText;
pub(crate) use warning::Warning;
pub use warning::WarningEntry;

use super::config::PipelineConfig;
use super::diagnostics::Diagnostics;
use super::status::PhysicalMargin;
use crate::constraints::ActiveBound;
use crate::estimator::consistency::{Worst, DENSITY_OVERSTATED_RATIO, INCONSISTENT_RATIO, SHIFT_Z};
use crate::estimator::discrete_momentum::{TORQUE_CHI2, TORQUE_SHIFT_Z};
use crate::estimator::excitation::Excitation;
use crate::estimator::momentum_rows::MomentumRowSettings;
use crate::estimator::observability::{Observability, Unobservable};
use crate::estimator::Estimate;
use crate::fix::{Fix, FixNames, Fixes};
use crate::solver::SolveStatus;
use crate::telemetry::convention::Verdict;
use crate::telemetry::glitch::{Glitch, GlitchCheck};
use crate::tensor::{principal, relative_frobenius_error, COMPONENT_NAMES};
use crate::text::{Counted, Num};
use core::fmt::{self, Write};
use nalgebra::Matrix3;
use std::string::{String, ToString};

/// Steps where the attitude jumped against the gyro, kept.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Glitches {
    /// How many steps.
    pub count: usize,
    /// The first ones.
    pub listed: std::vec::Vec<Glitch>,
}

/// Version of the JSON report; it changes whenever a key is removed or changes meaning.
pub(crate) const SCHEMA_VERSION: u32 = 1;

/// Where the samples came from (a telemetry file).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct InputSummary {
    /// File name.
    pub file: String,
    /// The first step, s.
    pub sample_period_s: f64,
    /// Quaternions renormalised on reading.
    pub renormalised: usize,
    /// Quaternion sign flips accepted on reading.
    pub sign_flips: usize,
    /// Shortest step, s.
    pub min_step_s: f64,
    /// Longest step, s.
    pub max_step_s: f64,
    /// Whether the attitude was integrated from the gyro rates (the input had no
    /// quaternions).
    pub attitude_from_gyro: bool,
    /// Records estimated together ([`crate::pipeline::Run::next_record`]): the file names
    /// are then comma-separated, and `t` is the last record's own time. Written only
    /// above 1.
    #[serde(skip_serializing_if = "is_one")]
    pub records: usize,
}

fn is_one(n: &usize) -> bool {
    *n == 1
}

/// The report of one run.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Report {
    /// `SCHEMA_VERSION`.
    pub schema_version: u32,
    /// Where the samples came from.
    #[serde(flatten)]
    pub input: Option<InputSummary>,
    /// Estimator name.
    pub estimator: &'static str,
    /// Solver backend name (`none` for estimators that solve nothing).
    pub solver: &'static str,
    /// Consistency condition (`physical`, `paper`, `positive-definite`).
    pub constraints: &'static str,
    /// Whether all samples were used at once (eq. 57).
    pub batch: bool,
    /// Samples the estimator saw (after resampling).
    pub samples: usize,
    /// Gaps in the time stamps.
    pub gaps: usize,
    /// Time of the estimate, s.
    pub t: f64,
    /// Status code.
    pub status: &'static str,
    /// Why the data fall short, when they do.
    pub reason: Option<String>,
    /// The settings the reason recommends changing ([`crate::fix`]).
    pub fixes: std::vec::Vec<Fix>,
    /// `σ_1/σ_6` of `R` when determined.
    pub condition: Option<f64>,
    /// J, kg m², rows.
    pub inertia: Option<[[f64; 3]; 3]>,
    /// `[J11, J22, J33, J12, J13, J23]`, kg m².
    pub j: Option<[f64; 6]>,
    /// Standard deviation per element, kg m².
    pub sigma: Option<[f64; 6]>,
    /// Its part from the wheel momentum's stated scale uncertainty (a consider parameter,
    /// `rotor_scale_sigma`), kg m²; `null` without one.
    pub rotor_scale_sigma_kg_m2: Option<[f64; 6]>,
    /// Its part from the known torque's stated scale uncertainty (a consider parameter,
    /// `torque_scale_sigma`), kg m²; `null` without one.
    pub torque_scale_sigma_kg_m2: Option<[f64; 6]>,
    /// The wheel-speed time tag applied ([`crate::estimator::wheel_delay`]): `δ` with its
    /// σ, whether estimated, and its consider part of `sigma` per element, kg m²;
    /// `null` without one.
    pub wheel_delay: Option<WheelDelayEntry>,
    /// The spacecraft file's rotors and their spin-inertia consider term
    /// (`crate::estimator::rotor_inertia`); `null` without rotors with a σ.
    pub rotor_inertia: Option<RotorInertiaEntry>,
    /// The rotor parameters estimated with J, against the spacecraft file's values
    /// ([`crate::estimator::rotor_calibration`]); `null` without a calibration made.
    pub rotor_calibration: Option<crate::estimator::rotor_calibration::RotorCalibration>,
    /// Principal moments, ascending, kg m².
    pub principal_moments: Option<[f64; 3]>,
    /// Their standard deviations, kg m².
    pub principal_moments_sigma: Option<[f64; 3]>,
    /// Principal axes (columns, body axes), rows of the matrix.
    pub principal_axes: Option<[[f64; 3]; 3]>,
    /// How the solver obtained the answer.
    pub solver_status: Option<SolveStatus>,
    /// Solver iterations.
    pub iterations: Option<u32>,
    /// Relative Frobenius error against a given truth.
    pub relative_error: Option<f64>,
    /// The excitation report.
    pub excitation: Option<Excitation>,
    /// The row model used (discrete momentum estimator): rotation source, plain or
    /// Richardson rows, torque bias.
    pub row_model: Option<MomentumRowSettings>,
    /// The estimated constant body-frame disturbance torque, N m.
    pub torque_bias_nm: Option<[f64; 3]>,
    /// The estimated damping coefficient `D` of a torque `−D ω`, N m s (only with
    /// `damping` on).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping_nms: Option<f64>,
    /// Its least-squares σ, N m s (white-noise σ; only with `damping` on).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping_sigma_nms: Option<f64>,
    /// The torques of outside measurements: whether the gravity gradient was modelled,
    /// the residual magnetic dipole (A m²) and the centre of mass (m) with their σ (only
    /// where the telemetry gives positions, the field or a force).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outside: Option<crate::estimator::external_torque::OutsideEstimates>,
    /// The test for that torque: `chi2`, and whether it was held at zero for want of
    /// evidence (`held_at_zero`; then `torque_bias_nm` is `null`).
    pub torque_test: Option<crate::estimator::discrete_momentum::TorqueTest>,
    /// The element bounds the answer sits on: they, not the data, hold it there.
    pub active_bounds: std::vec::Vec<ActiveBound>,
    /// How the Gaussian prior sat with the data (`chi2`, `rows`, and per element the
    /// fraction of the information from the data, `data_share`; `null` for an element
    /// fixed by an equality).
    pub prior: Option<crate::estimator::prior::PriorFit>,
    /// Steps where the attitude jumped against the gyro, kept (`--glitches keep`): how
    /// many, and the first `crate::telemetry::glitch::LISTED`.
    pub glitches: Option<Glitches>,
    /// The span whose residuals stand out most from the rest.
    pub residual_consistency: Option<Worst>,
    /// The residual variance over the part the gyro density alone implies.
    pub gyro_density_ratio: Option<f64>,
    /// Where no gyro density was stated: the density estimated from the telemetered rates,
    /// deg/s/√Hz, that the errors-in-variables compensation used
    /// (`crate::estimator::rate_noise`); `null` where none was stated and the rates'
    /// differences show the motion more than the noise (nothing compensated), or where one
    /// was stated.
    pub gyro_noise_estimated_deg_s_rthz: Option<f64>,
    /// With an attitude drift stated (`attitude_drift_deg_rth`): whether the answer came
    /// from the rows weighted for it (`false`: the unweighted rows', whose bias outweighed
    /// their noise, or no answer yet to weight with); `null` without one.
    pub drift_weighted: Option<bool>,
    /// With both rotation sources in play: whether the attitude was found to be the
    /// gyro's own integral (its rows then the gyro's, folded once: the rotation source
    /// is the gyro); `null` until the test has decided (3000 row blocks) or without both
    /// sources.
    pub attitude_is_gyro_integral: Option<bool>,
    /// Every warning the text report prints, in its order: `kind` and `message`
    /// (`Warning`). None contradicts the status ([`super::status`]).
    pub warnings: std::vec::Vec<WarningEntry>,
    #[serde(skip)]
    wheel_delay_error: Option<crate::estimator::wheel_delay::DelayError>,
    #[serde(skip)]
    held_speeds: Option<(usize, f64, bool)>,
    #[serde(skip)]
    gyro_range: std::vec::Vec<crate::telemetry::gyro_range::ClippedAxis>,
    #[serde(skip)]
    rotor_inertia_error: Option<(crate::estimator::rotor_inertia::RotorInertiaError, f64)>,
    #[serde(skip)]
    calibration_not_made: Option<crate::estimator::rotor_calibration::NotMade>,
    #[serde(skip)]
    observability: Observability,
    #[serde(skip)]
    physical: Option<PhysicalMargin>,
    #[serde(skip)]
    attitude: Option<Verdict>,
}

/// The rotors' spin-inertia consider term as the report carries it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RotorInertiaEntry {
    /// The rotors' names, in the spacecraft file's order.
    pub rotors: std::vec::Vec<String>,
    /// Each rotor's relative σ of its spin inertia.
    pub relative_sigma: std::vec::Vec<f64>,
    /// How their spin-inertia errors are related (`shared` or `independent`).
    pub errors: crate::spacecraft::RotorErrors,
    /// Each rotor's axis tilt σ, deg.
    pub axis_sigma_deg: std::vec::Vec<f64>,
    /// Each rotor's own time-tag σ, s.
    pub time_tag_sigma_s: std::vec::Vec<f64>,
    /// The independent 1σ error sources (`spin inertia`, `rw1 axis tilt 1`, `rw1 time
    /// tag`, …).
    pub sources: std::vec::Vec<String>,
    /// The answer's move for each source, kg m².
    pub moves_kg_m2: std::vec::Vec<[f64; 6]>,
    /// Its consider part of σ per element, kg m².
    pub sigma_kg_m2: [f64; 6],
}

/// The wheel-speed time tag as the report carries it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WheelDelayEntry {
    /// `δ`, s: the speeds were read this much later than their time stamps.
    pub delay_s: f64,
    /// Its standard deviation, s (zero when given).
    pub sigma_s: f64,
    /// Whether it was estimated from the data.
    pub estimated: bool,
    /// Its consider part of σ per element, `|∂ĵ/∂δ| σ_δ`, kg m².
    pub sigma_kg_m2: [f64; 6],
}

fn rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    core::array::from_fn(|r| core::array::from_fn(|c| m[(r, c)]))
}

impl Report {
    /// The report of `estimate`, produced by a pipeline with `config` from `samples`
    /// samples (the estimator's diagnostics: [`Self::with_diagnostics`]).
    #[must_use]
    pub(crate) fn new(
        estimate: &Estimate,
        config: &PipelineConfig,
        batch: bool,
        samples: usize,
    ) -> Self {
        let m = estimate.inertia();
        let pr = m.map(|m| principal(&m));
        Self {
            schema_version: SCHEMA_VERSION,
            input: None,
            estimator: config.estimator().name,
            // An estimator without constraints solves nothing.
            solver: if config.estimator().capabilities.constraints {
                config.backend().name
            } else {
                "none"
            },
            constraints: config.constraints().set().consistency.name(),
            batch,
            samples,
            gaps: 0,
            t: estimate.t_s,
            status: estimate.observability.code(),
            reason: estimate.observability.reason().map(|r| r.to_string()),
            fixes: estimate
                .observability
                .reason()
                .map(|r| r.fixes().to_vec())
                .unwrap_or_default(),
            condition: estimate.observability.condition(),
            inertia: m.as_ref().map(rows),
            j: estimate.j().map(|j| core::array::from_fn(|k| j[k])),
            sigma: estimate.sigma_kg_m2(),
            rotor_scale_sigma_kg_m2: estimate
                .uncertainty
                .map(|u| u.rotor_scale_kg_m2)
                .filter(|p| p.iter().any(|&v| v > 0.0)),
            torque_scale_sigma_kg_m2: estimate
                .uncertainty
                .map(|u| u.torque_scale_kg_m2)
                .filter(|p| p.iter().any(|&v| v > 0.0)),
            principal_moments: pr.map(|(v, _)| [v[0], v[1], v[2]]),
            principal_moments_sigma: estimate.uncertainty.map(|u| u.principal_sigma_kg_m2),
            principal_axes: pr.map(|(_, ax)| rows(&ax)),
            solver_status: estimate.solution.map(|s| s.status),
            iterations: estimate.solution.map(|s| s.iterations),
            relative_error: None,
            excitation: None,
            row_model: None,
            torque_bias_nm: None,
            damping_nms: None,
            damping_sigma_nms: None,
            outside: None,
            torque_test: None,
            active_bounds: estimate
                .j()
                .map(|j| config.constraints().set().active_bounds(&j).collect())
                .unwrap_or_default(),
            prior: estimate.prior,
            glitches: None,
            residual_consistency: None,
            gyro_density_ratio: None,
            gyro_noise_estimated_deg_s_rthz: None,
            drift_weighted: None,
            attitude_is_gyro_integral: None,
            warnings: std::vec::Vec::new(),
            wheel_delay: None,
            wheel_delay_error: None,
            held_speeds: None,
            gyro_range: std::vec::Vec::new(),
            rotor_inertia: None,
            rotor_calibration: None,
            rotor_inertia_error: None,
            calibration_not_made: None,
            observability: estimate.observability,
            physical: super::status::physical_margin(estimate),
            attitude: None,
        }
        .refreshed()
    }

    /// The warnings, in the text report's order.
    #[must_use]
    pub(crate) fn warning_list(&self) -> std::vec::Vec<Warning> {
        let mut w = std::vec::Vec::new();
        // A failed physicality check is the status line itself: not said twice.
        if let Some(p) = self.physical.filter(|_| {
            !matches!(
                self.observability,
                Observability::ModelCheckFailed(Unobservable::Unphysical { .. })
            )
        }) {
            w.push(Warning::NotPhysical(p));
        }
        if let Some(v) = self.attitude_disagreement() {
            w.push(Warning::AttitudeGyroDisagree(v));
        }
        if let Some(x) = self
            .residual_consistency
            .filter(|x| x.ratio > INCONSISTENT_RATIO && self.observability.has_answer())
        {
            w.push(Warning::SpanStandsOut(x, self.sigma.is_some()));
        }
        if let Some(x) = &self.excitation {
            w.extend(x.advice.iter().cloned().map(Warning::Excitation));
        }
        if let Some(e) = self.wheel_delay_error {
            w.push(Warning::WheelDelayNotEstimated(e));
        }
        if let Some((every, period_s, in_sigma)) = self.held_speeds {
            w.push(Warning::HeldWheelSpeeds(every, period_s, in_sigma));
        }
        w.extend(
            self.gyro_range
                .iter()
                .copied()
                .map(Warning::GyroAtRangeLimit),
        );
        if let Some((e, r)) = self.rotor_inertia_error {
            w.push(Warning::RotorInertiaNotComputed(e, r));
        }
        if let Some(why) = self.calibration_not_made {
            w.push(Warning::RotorCalibrationNotMade(
                why,
                self.rotor_calibration.is_some(),
            ));
        }
        w
    }

    /// With the wheel speeds' update period (samples, s) where they look held and no time
    /// tag was asked for ([`crate::telemetry::held_speeds`]).
    #[must_use]
    #[cfg_attr(not(feature = "csv"), allow(dead_code))] // used by Run::report
    pub(crate) fn with_held_speeds(mut self, held: Option<(usize, f64, bool)>) -> Self {
        self.held_speeds = held;
        self.refreshed()
    }

    /// With the gyro axes found at their range limit
    /// ([`crate::telemetry::gyro_range`]).
    #[must_use]
    #[cfg_attr(not(feature = "csv"), allow(dead_code))] // used by Run::report
    pub(crate) fn with_gyro_range(
        mut self,
        clipped: std::vec::Vec<crate::telemetry::gyro_range::ClippedAxis>,
    ) -> Self {
        self.gyro_range = clipped;
        self.refreshed()
    }

    /// With the wheel-speed time tag the run applied, or why it could not be estimated.
    #[must_use]
    #[cfg_attr(not(feature = "csv"), allow(dead_code))] // used by Run::report
    pub(crate) fn with_wheel_delay(
        mut self,
        delay: Option<
            &Result<
                crate::estimator::wheel_delay::DelayFit,
                crate::estimator::wheel_delay::DelayError,
            >,
        >,
    ) -> Self {
        match delay {
            Some(Ok(f)) => {
                self.wheel_delay = Some(WheelDelayEntry {
                    delay_s: f.delay_s,
                    sigma_s: f.sigma_s,
                    estimated: f.estimated,
                    sigma_kg_m2: f.consider_kg_m2(),
                });
            }
            Some(Err(e)) => self.wheel_delay_error = Some(*e),
            None => {}
        }
        self.refreshed()
    }

    /// With the rotors' spin-inertia consider term the run computed (`spacecraft`'s
    /// rotors), or why it could not be and the relative σ that widened σ instead.
    #[must_use]
    #[cfg_attr(not(feature = "csv"), allow(dead_code))] // used by Run::report
    pub(crate) fn with_rotor_inertia(
        mut self,
        spacecraft: Option<&crate::spacecraft::Spacecraft>,
        consider: Option<
            &Result<
                crate::estimator::rotor_inertia::RotorInertiaConsider,
                crate::estimator::rotor_inertia::RotorInertiaError,
            >,
        >,
        fallback_relative_sigma: f64,
    ) -> Self {
        let (Some(sc), Some(c)) = (spacecraft, consider) else {
            return self;
        };
        match c {
            Ok(c) => {
                self.rotor_inertia = Some(RotorInertiaEntry {
                    rotors: sc.rotors.iter().map(|r| r.name.clone()).collect(),
                    relative_sigma: c.relative_sigma.clone(),
                    errors: c.errors,
                    axis_sigma_deg: sc.rotors.iter().map(|r| r.spin_axis_sigma_deg).collect(),
                    time_tag_sigma_s: sc.rotors.iter().map(|r| r.time_tag_sigma_s).collect(),
                    sources: c.sources.clone(),
                    moves_kg_m2: c.moves_kg_m2.clone(),
                    sigma_kg_m2: c.consider_kg_m2(),
                });
            }
            Err(e) => {
                self.rotor_inertia_error = Some((*e, fallback_relative_sigma));
            }
        }
        self.refreshed()
    }

    /// With the rotor parameters the run estimated, or the ratio of total to rotor
    /// momentum for which it did not.
    #[must_use]
    #[cfg_attr(not(feature = "csv"), allow(dead_code))] // used by Run::report
    pub(crate) fn with_rotor_calibration(
        mut self,
        calibration: Option<&crate::estimator::rotor_calibration::RotorCalibration>,
        not_made: Option<crate::estimator::rotor_calibration::NotMade>,
    ) -> Self {
        self.rotor_calibration = calibration.cloned();
        self.calibration_not_made = not_made;
        self.refreshed()
    }

    fn attitude_disagreement(&self) -> Option<f64> {
        match self.attitude {
            Some(Verdict::Disagree(m)) => Some(m),
            _ => None,
        }
    }

    fn refreshed(mut self) -> Self {
        self.warnings = self
            .warning_list()
            .iter()
            .map(|w| WarningEntry {
                kind: w.kind(),
                message: w.to_string(),
            })
            .collect();
        self
    }

    /// With the verdict of the attitude-against-gyro convention check.
    #[must_use]
    pub(crate) fn with_attitude_check(mut self, verdict: Verdict) -> Self {
        self.attitude = Some(verdict);
        self.refreshed()
    }

    /// The report of a streaming pipeline's latest estimate (`None` before one): the
    /// estimate, the excitation, the row model and torque, the residual tests and the
    /// glitches kept.
    #[must_use]
    pub fn of_pipeline(p: &super::Pipeline) -> Option<Self> {
        let last = p.last()?;
        Some(
            Self::new(last, p.config(), false, p.estimator_samples())
                .with_diagnostics(p.diagnostics())
                .with_glitches(Some(p.glitches()))
                .with_attitude_check(p.attitude_check()),
        )
    }

    /// The report of a batch run over `samples` samples.
    #[must_use]
    pub fn of_batch(out: &super::BatchOutput, config: &PipelineConfig, samples: usize) -> Self {
        Self::new(&out.estimate, config, true, samples).with_diagnostics(out.diagnostics.clone())
    }

    /// With the input summary.
    #[must_use]
    #[cfg_attr(not(feature = "csv"), allow(dead_code))] // used by Run::report
    pub(crate) fn with_input(mut self, input: InputSummary) -> Self {
        self.input = Some(input);
        self
    }

    /// With the estimator's diagnostics: gaps, excitation, row model and torque, the
    /// residual tests.
    #[must_use]
    pub(crate) fn with_diagnostics(mut self, d: Diagnostics) -> Self {
        self.gaps = d.gaps;
        self.excitation = d.excitation;
        self.row_model = d.row_model;
        self.torque_bias_nm = d.torque_bias_nm.map(|t| [t.x, t.y, t.z]);
        self.damping_nms = d.damping_nms.map(|d| d.0);
        self.damping_sigma_nms = d.damping_nms.and_then(|d| d.1);
        self.outside = d.outside;
        self.torque_test = d.torque_test;
        self.attitude_is_gyro_integral = d.attitude_is_gyro_integral;
        self.drift_weighted = d.drift_weighted;
        self.residual_consistency = d.residual_consistency;
        self.gyro_density_ratio = d.gyro_density_ratio;
        self.gyro_noise_estimated_deg_s_rthz =
            d.gyro_noise_estimated_rad_s_rthz.map(f64::to_degrees);
        self.refreshed()
    }

    /// With the glitches kept, if any.
    #[must_use]
    pub(crate) fn with_glitches(mut self, check: Option<&GlitchCheck>) -> Self {
        self.glitches = check.filter(|c| c.count() > 0).map(|c| Glitches {
            count: c.count(),
            listed: c.listed().copied().collect(),
        });
        self
    }

    /// With the error against a known J (kg m²).
    #[must_use]
    pub fn with_truth(mut self, truth: Option<&Matrix3<f64>>) -> Self {
        self.relative_error = match (self.inertia, truth) {
            (Some(m), Some(t)) => Some(relative_frobenius_error(
                &Matrix3::from_fn(|r, c| m[r][c]),
                t,
            )),
            _ => None,
        };
        self
    }
}
