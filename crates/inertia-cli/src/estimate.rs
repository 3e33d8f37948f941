//! `inertia estimate`: arguments → pipeline settings → the library's pipeline over the
//! file → the library's report.

use crate::args::EstimateArgs;
use crate::config::{self, settings_error, InertiaFile};
use crate::error::{input, internal, read_failed, telemetry, CliError};
use crate::history::HistoryFile;
use crate::output::{is_stdio, to_stdout};
use inertia::discrete::RowError;
use inertia::estimator::EstimatorError;
use inertia::pipeline::report::{InputSummary, Report};
use inertia::pipeline::{self, Pipeline, PipelineConfig, PipelineError};
use inertia::telemetry::csv::TelemetryReader;
use inertia::telemetry::read_ahead::ReadAhead;
use inertia::text::Num;
use std::collections::VecDeque;
use std::io::{IsTerminal, Read};

/// How many recent samples' lines are kept to name the line of an error.
const RECENT: usize = 8;

use inertia::pipeline::MAX_RESAMPLE_FACTOR;

/// The telemetry: a file, or standard input for `-`.
fn open(path: &std::path::Path) -> Result<(Box<dyn Read + Send>, String), CliError> {
    if is_stdio(path) {
        return Ok((Box::new(std::io::stdin()), "<stdin>".into()));
    }
    let f = std::fs::File::open(path).map_err(|e| read_failed(path, e))?;
    Ok((Box::new(f), path.display().to_string()))
}

/// Settings that the first step of the data shows to be meaningless: a memory shorter
/// than the step, or resampling to more than [`MAX_RESAMPLE_FACTOR`] samples per step.
fn check_against_step(config: &PipelineConfig, dt: f64, at: &str) -> Result<(), CliError> {
    if let Some(m) = config.memory_s() {
        let step = config.resample_s().unwrap_or(dt);
        if m < step {
            return Err(input(format!(
                "--memory {}: shorter than the sample period {} s ({at}); the memory must span several samples",
                Num(m),
                Num(step)
            )));
        }
    }
    if let Some(r) = config.resample_s() {
        if dt / r > MAX_RESAMPLE_FACTOR {
            return Err(input(format!(
                "--resample {}: {} resampled samples per input step of {} s ({at}); at most {}",
                Num(r),
                Num((dt / r).round()),
                Num(dt),
                Num(MAX_RESAMPLE_FACTOR)
            )));
        }
    }
    Ok(())
}

/// The line of the sample that ends a step too large for |φ| < 1, among the recent
/// `(time, line)` pairs: the reader may be ahead of the estimator (resampling reads the
/// next samples first, and the half-rate shadow's step ends at a later sample).
fn step_end_line(e: &PipelineError, recent: &VecDeque<(f64, u64)>) -> Option<u64> {
    let end = e.step_end_s()?;
    recent
        .iter()
        .find(|(t, _)| PipelineError::ends_step(*t, end))
        .map(|&(_, line)| line)
}

/// Run the command.
pub fn run(a: &EstimateArgs) -> Result<(), CliError> {
    if a.output.as_deref().is_some_and(is_stdio) {
        return Err(input(
            "-o -: the report goes to standard output; give the history a file name (e.g. -o history.csv)",
        ));
    }
    let options = config::csv_options(&a.input)?;
    let settings = config::pipeline_settings(a)?;
    let config = settings.validate().map_err(settings_error)?;
    let truth = a.truth.as_deref().map(InertiaFile::read).transpose()?;
    let mut history = a.output.as_deref().map(HistoryFile::create).transpose()?;
    let (source, name) = open(&a.file)?;
    let reader = TelemetryReader::new(source, &name, options).map_err(telemetry)?;
    let file = reader.file().to_string();
    let entry = config.estimator();
    if entry.capabilities.needs_gyro && !reader.has_gyro() {
        return Err(input(format!(
            "{file}:1: the {} estimator needs gyro-rate columns w_x,w_y,w_z",
            entry.name
        )));
    }
    let q_columns = reader.quaternion_columns();
    // Parsing overlaps the estimator.
    let mut reader = ReadAhead::new(reader);
    // An error of the estimator, tied to the line of the sample that caused it.
    let data_error = |e: PipelineError, line: Option<u64>| {
        let at = line.map_or_else(|| format!("{file}:"), |l| format!("{file}:{l}:"));
        match e {
            PipelineError::Estimator {
                source: EstimatorError::Solve(s),
                ..
            } => input(format!("{at} the solver failed on these data: {s}")),
            PipelineError::Estimator {
                source:
                    EstimatorError::Row {
                        source: r @ RowError::StepTooLarge { .. },
                        ..
                    },
                ..
            } => input(format!("{at} columns `{q_columns}`: {r}")),
            PipelineError::Estimator {
                source: EstimatorError::Row { source, .. },
                ..
            } => input(format!("{at} {source}")),
            PipelineError::Estimator { source, .. } => input(format!("{at} {source}")),
            other => input(format!("{at} {other}")),
        }
    };
    let size = if is_stdio(&a.file) {
        0
    } else {
        std::fs::metadata(&a.file).map_or(0, |m| m.len())
    };
    let progress = (std::io::stderr().is_terminal() && !a.json && size > 1 << 20).then(|| {
        let p = indicatif::ProgressBar::new(size);
        p.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {bytes}/{total_bytes} {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        p
    });
    let mut first_times = [f64::NAN; 2];
    let (report, samples) = if a.batch {
        let mut all = Vec::new();
        let mut lines = Vec::new();
        while let Some(item) = reader.next() {
            all.push(item.map_err(telemetry)?);
            lines.push(reader.last_line());
        }
        for (t, s) in first_times.iter_mut().zip(&all) {
            *t = s.t_s;
        }
        let out = pipeline::batch(&all, &config).map_err(|e| {
            let line = match &e {
                PipelineError::Estimator {
                    source: EstimatorError::Row { sample, .. },
                    ..
                }
                | PipelineError::AttitudeGlitch { sample, .. } => lines.get(*sample).copied(),
                _ => None,
            };
            data_error(e, line)
        })?;
        if let Some(h) = history.as_mut() {
            h.write(&out.estimate)?;
        }
        (Some(Report::of_batch(&out, &config, all.len())), all.len())
    } else {
        let mut p = Pipeline::from_config(config).map_err(settings_error)?;
        let mut write_error = None;
        let mut recent = VecDeque::with_capacity(RECENT);
        while let Some(item) = reader.next() {
            let s = item.map_err(telemetry)?;
            if recent.len() == RECENT {
                recent.pop_front();
            }
            recent.push_back((s.t_s, reader.last_line()));
            let n = p.input_samples();
            if n < 2 {
                first_times[n] = s.t_s;
            }
            if n == 1 {
                let at = format!("{file}:{}", reader.last_line());
                check_against_step(&config, first_times[1] - first_times[0], &at)?;
            }
            p.push_each(&s, |e| {
                if let (Some(h), None) = (history.as_mut(), &write_error) {
                    write_error = h.write(e).err();
                }
            })
            .map_err(|e| {
                let line = step_end_line(&e, &recent).unwrap_or(reader.last_line());
                data_error(e, Some(line))
            })?;
            if let Some(e) = write_error.take() {
                return Err(e);
            }
            if let Some(pb) = &progress {
                if n.is_multiple_of(4096) {
                    pb.set_position(reader.byte_position());
                }
            }
        }
        (Report::of_pipeline(&p), p.estimator_samples())
    };
    if let Some(p) = progress {
        p.finish_and_clear();
    }
    if let Some(h) = history {
        h.finish()?;
    }
    let stats = reader
        .finish()
        .ok_or_else(|| internal("the telemetry reader thread failed"))?;
    let Some(report) = report else {
        let need = if entry.capabilities.needs_gyro && !entry.capabilities.constraints {
            2
        } else {
            inertia::estimator::MIN_SAMPLES
        };
        let resampled = if samples == stats.rows {
            String::new()
        } else {
            format!(" ({} read, {samples} on the --resample grid)", stats.rows)
        };
        return Err(input(format!(
            "{file}: too few samples for an estimate: the {} estimator needs at least {need}, got {samples}{resampled}",
            entry.name,
        )));
    };
    let report = report
        .with_input(InputSummary {
            file: file.clone(),
            sample_period_s: config
                .resample_s()
                .unwrap_or(first_times[1] - first_times[0]),
            renormalised: stats.renormalised,
            sign_flips: stats.sign_flips,
            min_step_s: stats.min_step_s,
            max_step_s: stats.max_step_s,
        })
        .with_truth(truth.as_ref());
    if a.json {
        let json = serde_json::to_string(&report).map_err(|e| internal(format!("JSON: {e}")))?;
        to_stdout(|w| writeln!(w, "{json}"))
    } else {
        to_stdout(|w| write!(w, "{report}"))
    }
}
