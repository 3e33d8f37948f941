//! One fuzz case: random settings, the file through the library's CSV reader and
//! pipeline (recursive or batch, as `inertia estimate` runs them), and the oracle.

use super::mutate::Rng;
use inertia::constraints::ConstraintSet;
use inertia::estimator::momentum_rows::{RhoModel, RotationSource};
use inertia::estimator::{Estimate, EstimatorError};
use inertia::pipeline::report::Report;
use inertia::pipeline::{self, Pipeline, PipelineError, PipelineSettings};
use inertia::telemetry::csv::{CsvOptions, TelemetryError, TelemetryReader};
use inertia::tensor::Component;

const ESTIMATORS: &[&str] = &[
    "discrete-momentum",
    "variational",
    "finite-difference",
    "momentum",
];

/// What a case ran with, for the findings log.
#[derive(Debug, Clone)]
pub struct Plan {
    pub settings: PipelineSettings,
    pub batch: bool,
}

/// Random settings, mostly valid for the chosen estimator (a few invalid ones test the
/// typed refusals).
pub fn plan(rng: &mut Rng) -> Plan {
    let estimator = *rng.pick(ESTIMATORS);
    let momentum = estimator == "momentum";
    let dm = estimator == "discrete-momentum";
    let batch = !momentum && rng.chance(0.3);
    let mut s = PipelineSettings {
        estimator: estimator.into(),
        ..PipelineSettings::default()
    };
    if !momentum {
        if rng.chance(0.2) {
            s.constraints = ConstraintSet::paper();
        }
        if rng.chance(0.3) {
            let c = *rng.pick(&Component::ALL);
            let nominal = *rng.pick(&[1.0, 2.0, 3.0, 0.5, 100.0]);
            s.constraints = s.constraints.with_nominal(c, nominal, 0.1);
        }
        if estimator != "finite-difference" && rng.chance(0.25) {
            s.gyro_noise_deg_s_rthz = Some(*rng.pick(&[0.0, 1e-5, 1e-3, 0.1]));
        }
    }
    if !batch {
        if rng.chance(0.2) {
            s.memory_s = Some(*rng.pick(&[0.5, 5.0, 60.0, 1e4]));
        }
        if rng.chance(0.15) {
            s.resample_s = Some(*rng.pick(&[0.05, 0.1, 0.13, 0.5]));
        }
    }
    if dm {
        if rng.chance(0.3) {
            s.rotation_source = Some(*rng.pick(&[RotationSource::Attitude, RotationSource::Gyro]));
        }
        if rng.chance(0.3) {
            s.rho_model = *rng.pick(&[
                RhoModel::Auto,
                RhoModel::Smooth,
                RhoModel::Held,
                RhoModel::Plain,
            ]);
        }
        // The drift weighting (needs the gyro density; refused in batch runs).
        if rng.chance(0.2) {
            s.attitude_drift_deg_rth = Some(*rng.pick(&[6e-4, 0.02, 0.15, 10.0]));
        }
    }
    if rng.chance(0.1) {
        s.uncertainty = false;
    }
    Plan { settings: s, batch }
}

/// What the oracle found wrong.
#[derive(Debug)]
pub enum Finding {
    /// A non-finite number in an answer, a σ or the report.
    NonFinite(String),
    /// An error about a line of the file that does not name one.
    NoLine(String),
}

/// How a case ended (when it did not panic or hang).
pub enum Outcome {
    /// An estimate was produced.
    Estimate,
    /// A typed error (file, settings or estimator).
    Refused,
}

fn finite(x: &[f64]) -> bool {
    x.iter().all(|v| v.is_finite())
}

/// The oracle on one estimate: J, σ and the principal moments' σ finite when present.
fn check_estimate(e: &Estimate) -> Result<(), Finding> {
    if let Some(j) = e.j() {
        if !finite(j.as_slice()) {
            return Err(Finding::NonFinite(format!("J = {:?}", j.as_slice())));
        }
    }
    if let Some(u) = e.uncertainty {
        if !(finite(&u.sigma_kg_m2) && finite(&u.principal_sigma_kg_m2)) {
            return Err(Finding::NonFinite(format!("sigma = {:?}", u.sigma_kg_m2)));
        }
    }
    if !e.t_s.is_finite() {
        return Err(Finding::NonFinite(format!("t = {}", e.t_s)));
    }
    Ok(())
}

/// Errors that concern a sample must say which.
fn check_pipeline_error(e: &PipelineError) -> Result<(), Finding> {
    match e {
        // Too few samples, and a batch solve, concern the whole file.
        PipelineError::Estimator {
            sample: None,
            source: EstimatorError::TooFewSamples { .. } | EstimatorError::Solve(_),
        } => Ok(()),
        PipelineError::Estimator { sample: None, .. } => {
            Err(Finding::NoLine(format!("no sample: {e}")))
        }
        _ => Ok(()),
    }
}

fn check_telemetry_error(e: &TelemetryError) -> Result<(), Finding> {
    match (e, e.line()) {
        (TelemetryError::Io { .. }, _) => Ok(()),
        (_, Some(l)) if l >= 1 => Ok(()),
        _ => Err(Finding::NoLine(format!("no line: {e}"))),
    }
}

/// The report text, as the command prints it, must hold no NaN or infinity.
fn check_report(text: &str) -> Result<(), Finding> {
    let bad = |w: &str| {
        let w = w.trim_start_matches(['-', '+']).to_ascii_lowercase();
        w == "inf" || w == "infinity" || w.starts_with("nan")
    };
    match text.lines().find(|l| {
        l.split(|c: char| c.is_whitespace() || c == ',' || c == '[' || c == ']')
            .any(bad)
    }) {
        Some(line) => Err(Finding::NonFinite(format!("report line: {line}"))),
        None => Ok(()),
    }
}

/// Run one case.
pub fn run(csv: &str, plan: &Plan) -> Result<Outcome, Finding> {
    let config = match plan.settings.validate() {
        Ok(c) => c,
        Err(_) => return Ok(Outcome::Refused),
    };
    let mut reader = match TelemetryReader::new(csv.as_bytes(), "fuzz.csv", CsvOptions::default()) {
        Ok(r) => r,
        Err(e) => {
            check_telemetry_error(&e)?;
            return Ok(Outcome::Refused);
        }
    };
    if config.estimator().capabilities.needs_gyro && !reader.has_gyro() {
        return Ok(Outcome::Refused);
    }
    let report = if plan.batch {
        let mut all = Vec::new();
        for item in reader.by_ref() {
            match item {
                Ok(s) => all.push(s),
                Err(e) => {
                    check_telemetry_error(&e)?;
                    return Ok(Outcome::Refused);
                }
            }
        }
        match pipeline::batch(&all, &config) {
            Ok(out) => {
                check_estimate(&out.estimate)?;
                Some(Report::of_batch(&out, &config, all.len()))
            }
            Err(e) => {
                check_pipeline_error(&e)?;
                return Ok(Outcome::Refused);
            }
        }
    } else {
        let mut p = match Pipeline::from_config(config) {
            Ok(p) => p,
            Err(_) => return Ok(Outcome::Refused),
        };
        for item in reader.by_ref() {
            let s = match item {
                Ok(s) => s,
                Err(e) => {
                    check_telemetry_error(&e)?;
                    return Ok(Outcome::Refused);
                }
            };
            let mut bad = Ok(());
            let pushed = p.push_each(&s, |e| {
                if bad.is_ok() {
                    bad = check_estimate(e);
                }
            });
            bad?;
            if let Err(e) = pushed {
                check_pipeline_error(&e)?;
                return Ok(Outcome::Refused);
            }
        }
        Report::of_pipeline(&p)
    };
    // The report as `inertia estimate` builds it (less the file summary).
    let Some(report) = report else {
        return Ok(Outcome::Refused);
    };
    if let Some(x) = &report.excitation {
        if !finite(&x.singular_values) || x.element_sigma.is_some_and(|s| !finite(&s)) {
            return Err(Finding::NonFinite(format!(
                "excitation: {:?} {:?}",
                x.singular_values, x.element_sigma
            )));
        }
    }
    check_report(&report.to_string())?;
    Ok(Outcome::Estimate)
}
