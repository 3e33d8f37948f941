//! One estimation run over samples held in memory: what `inertia estimate` does with a
//! file (`crates/inertia-cli/src/estimate.rs`), with the same checks, the same library
//! calls (`Pipeline::push_each` or `pipeline::batch`, then `Report::of_pipeline` or
//! `Report::of_batch`) and the same messages. Runs without the GIL.

use crate::errors::Failure;
use crate::samples::{Naming, Stats};
use crate::settings::RunSettings;
use inertia::discrete::RowError;
use inertia::estimator::{Estimate, EstimatorError};
use inertia::pipeline::report::{InputSummary, Report};
use inertia::pipeline::{self, Pipeline, PipelineConfig, PipelineError, MAX_RESAMPLE_FACTOR};
use inertia::sample::Sample;
use inertia::text::Num;

/// How many recent samples the command line keeps to name the line of an error.
const RECENT: usize = 8;

/// Where the samples came from, to name them in messages.
#[derive(Debug, Clone)]
pub enum Origin {
    /// A telemetry file: its name, each sample's line and the quaternion columns' names.
    File {
        name: String,
        lines: Vec<u64>,
        q_columns: String,
    },
    /// Arrays or a table (`label` is the input summary's `file`: `<arrays>`, …).
    Memory { naming: Naming, label: String },
}

impl Origin {
    /// The summary's file name.
    pub fn label(&self) -> &str {
        match self {
            Origin::File { name, .. } => name,
            Origin::Memory { label, .. } => label,
        }
    }

    /// `f.csv:12:` or `sample 10:`; the file's line.
    fn at(&self, sample: Option<usize>) -> (String, Option<u64>) {
        match self {
            Origin::File { name, lines, .. } => match sample.and_then(|i| lines.get(i)) {
                Some(&l) => (format!("{name}:{l}:"), Some(l)),
                None => (format!("{name}:"), None),
            },
            Origin::Memory { naming, label } => match sample {
                Some(i) => (naming.sample(i), None),
                None => (format!("{label}:"), None),
            },
        }
    }

    fn q_columns(&self) -> String {
        match self {
            Origin::File { q_columns, .. } => q_columns.clone(),
            Origin::Memory { naming, .. } => naming.quaternion_columns(),
        }
    }

    /// An error of the estimator, tied to the sample that caused it (the CLI's wording).
    fn data_error(&self, e: PipelineError, sample: Option<usize>) -> Failure {
        let (at, line) = self.at(sample);
        let m = match e {
            PipelineError::Estimator {
                source: EstimatorError::Solve(s),
                ..
            } => format!("{at} the solver failed on these data: {s}"),
            PipelineError::Estimator {
                source:
                    EstimatorError::Row {
                        source: r @ RowError::StepTooLarge { .. },
                        ..
                    },
                ..
            } => format!("{at} columns `{}`: {r}", self.q_columns()),
            PipelineError::Estimator {
                source: EstimatorError::Row { source, .. },
                ..
            } => format!("{at} {source}"),
            PipelineError::Estimator { source, .. } => format!("{at} {source}"),
            other => format!("{at} {other}"),
        };
        Failure::Data(python_options(m), line)
    }
}

/// The message with the keyword arguments for the command-line options it names
/// (`--jpl`, `--scalar-first`, `--negate-rho`, `--glitches keep`), after it.
pub fn python_options(m: String) -> String {
    let names: Vec<&str> = [
        ("--scalar-first", "scalar_first=True"),
        ("--jpl", "jpl=True"),
        ("--negate-rho", "negate_rho=True"),
        ("--glitches keep", "glitches=\"keep\""),
    ]
    .iter()
    .filter(|(cli, _)| m.contains(cli))
    .map(|(_, py)| *py)
    .collect();
    if names.is_empty() {
        m
    } else {
        format!("{m} [in Python: {}]", names.join(", "))
    }
}

/// What a run produced.
pub struct Output {
    pub report: Report,
    pub history: Option<Vec<Estimate>>,
}

/// Settings that the first step of the data shows to be meaningless (the CLI's
/// `check_against_step`, with the keyword arguments' names).
pub fn check_against_step(config: &PipelineConfig, dt: f64, at: &str) -> Result<(), Failure> {
    if let Some(m) = config.memory_s() {
        let step = config.resample_s().unwrap_or(dt);
        if m < step {
            return Err(Failure::Argument(format!(
                "memory={}: shorter than the sample period {} s ({at}); the memory must span several samples",
                Num(m),
                Num(step)
            )));
        }
    }
    if let Some(r) = config.resample_s() {
        if dt / r > MAX_RESAMPLE_FACTOR {
            return Err(Failure::Argument(format!(
                "resample={}: {} resampled samples per input step of {} s ({at}); at most {}",
                Num(r),
                Num((dt / r).round()),
                Num(dt),
                Num(MAX_RESAMPLE_FACTOR)
            )));
        }
    }
    Ok(())
}

/// The sample that ends a step too large for |φ| < 1, among the `RECENT` samples up to
/// `i` (as the CLI finds its line).
fn step_end(e: &PipelineError, samples: &[Sample], i: usize) -> Option<usize> {
    let end = e.step_end_s()?;
    let from = (i + 1).saturating_sub(RECENT);
    samples[from..=i]
        .iter()
        .position(|s| PipelineError::ends_step(s.t_s, end))
        .map(|k| from + k)
}

/// Estimate from `samples` as `inertia estimate` does from a file.
pub fn run(
    samples: &[Sample],
    stats: &Stats,
    origin: &Origin,
    config: PipelineConfig,
    settings: &RunSettings,
) -> Result<Output, Failure> {
    let (batch, history, truth) = (settings.batch, settings.history, settings.truth.as_ref());
    let entry = config.estimator();
    if entry.capabilities.needs_gyro && samples.iter().any(|s| s.omega_rad_s.is_none()) {
        return Err(match origin {
            Origin::File { name, .. } => Failure::Data(
                format!(
                    "{name}:1: the {} estimator needs gyro-rate columns w_x,w_y,w_z",
                    entry.name
                ),
                Some(1),
            ),
            Origin::Memory { .. } => Failure::Argument(format!(
                "w: the {} estimator needs gyro rates (w_x,w_y,w_z)",
                entry.name
            )),
        });
    }
    let mut kept = history.then(Vec::new);
    let (report, used) = if batch {
        let out = pipeline::batch(samples, &config).map_err(|e| {
            let sample = match &e {
                PipelineError::Estimator {
                    source: EstimatorError::Row { sample, .. },
                    ..
                }
                | PipelineError::AttitudeGlitch { sample, .. } => Some(*sample),
                _ => None,
            };
            match (&e, origin) {
                // Settings the batch form does not take are argument errors.
                (PipelineError::NotApplicable { .. } | PipelineError::NoBatch { .. }, _) => {
                    Failure::Argument(format!("batch=True: {e}"))
                }
                _ => origin.data_error(e, sample),
            }
        })?;
        if let Some(h) = kept.as_mut() {
            h.push(out.estimate);
        }
        (
            Some(Report::of_batch(&out, &config, samples.len())),
            samples.len(),
        )
    } else {
        let mut p = Pipeline::from_config(config).map_err(|e| Failure::Argument(e.to_string()))?;
        for (i, s) in samples.iter().enumerate() {
            if i == 1 {
                let (at, _) = origin.at(Some(1));
                check_against_step(&config, s.t_s - samples[0].t_s, at.trim_end_matches(':'))?;
            }
            p.push_each(s, |e| {
                if let Some(h) = kept.as_mut() {
                    h.push(*e);
                }
            })
            .map_err(|e| {
                let at = step_end(&e, samples, i).unwrap_or(i);
                origin.data_error(e, Some(at))
            })?;
        }
        (Report::of_pipeline(&p), p.estimator_samples())
    };
    let Some(report) = report else {
        let need = if entry.capabilities.needs_gyro && !entry.capabilities.constraints {
            2
        } else {
            inertia::estimator::MIN_SAMPLES
        };
        let resampled = if used == samples.len() {
            String::new()
        } else {
            format!(" ({} read, {used} on the resample grid)", samples.len())
        };
        let (at, _) = origin.at(None);
        return Err(Failure::Data(
            format!(
                "{at} too few samples for an estimate: the {} estimator needs at least {need}, got {used}{resampled}",
                entry.name
            ),
            None,
        ));
    };
    let period = match samples {
        [a, b, ..] => b.t_s - a.t_s,
        _ => f64::NAN,
    };
    let report = report
        .with_input(InputSummary {
            file: origin.label().to_string(),
            sample_period_s: config.resample_s().unwrap_or(period),
            renormalised: stats.renormalised,
            sign_flips: stats.sign_flips,
            min_step_s: stats.min_step_s,
            max_step_s: stats.max_step_s,
        })
        .with_truth(truth);
    Ok(Output {
        report,
        history: kept,
    })
}
