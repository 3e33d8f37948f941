//! `inertia estimate`: arguments → pipeline settings → the library's pipeline over the
//! file → the library's report.

use crate::args::EstimateArgs;
use crate::config::{self, settings_error, InertiaFile};
use crate::error::{input, internal, CliError};
use crate::history::HistoryFile;
use inertia::discrete::RowError;
use inertia::estimator::EstimatorError;
use inertia::pipeline::report::{InputSummary, Report};
use inertia::pipeline::{self, Pipeline, PipelineError};
use inertia::telemetry::csv::TelemetryReader;
use std::io::IsTerminal;

/// Run the command.
pub fn run(a: &EstimateArgs) -> Result<(), CliError> {
    let options = config::csv_options(&a.input)?;
    let settings = config::pipeline_settings(a)?;
    let config = settings.validate().map_err(settings_error)?;
    let truth = a.truth.as_deref().map(InertiaFile::read).transpose()?;
    let mut reader = TelemetryReader::open(&a.file, options).map_err(input)?;
    let file = reader.file().to_string();
    let entry = config.estimator();
    if entry.capabilities.needs_gyro && !reader.has_gyro() {
        return Err(input(format!(
            "{file}:1: the {} estimator needs gyro-rate columns w_x,w_y,w_z",
            entry.name
        )));
    }
    let q_columns = reader.quaternion_columns();
    // An error of the estimator, tied to the line of the sample that caused it.
    let data_error = |e: PipelineError, line: Option<u64>| {
        let at = line.map_or_else(|| format!("{file}:"), |l| format!("{file}:{l}:"));
        match e {
            PipelineError::Estimator {
                source: EstimatorError::Solve(s),
                ..
            } => internal(format!("{at} {s}")),
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
    let size = std::fs::metadata(&a.file).map(|m| m.len()).unwrap_or(0);
    let progress = (std::io::stderr().is_terminal() && !a.json && size > 1 << 20).then(|| {
        let p = indicatif::ProgressBar::new(size);
        p.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {bytes}/{total_bytes} {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        p
    });
    let mut history = a.output.as_deref().map(HistoryFile::create).transpose()?;
    let mut first_times = [f64::NAN; 2];
    let (last, excitation, samples, gaps, row_model, torque, residuals, density_ratio) = if a.batch
    {
        let mut all = Vec::new();
        let mut lines = Vec::new();
        while let Some(item) = reader.next() {
            all.push(item.map_err(input)?);
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
                } => lines.get(*sample).copied(),
                _ => None,
            };
            data_error(e, line)
        })?;
        if let Some(h) = history.as_mut() {
            h.write(&out.estimate)?;
        }
        (
            Some(out.estimate),
            out.excitation,
            all.len(),
            out.gaps,
            out.row_model,
            None,
            None,
            None,
        )
    } else {
        let mut p = Pipeline::from_config(config).map_err(settings_error)?;
        let mut write_error = None;
        while let Some(item) = reader.next() {
            let s = item.map_err(input)?;
            let n = p.input_samples();
            if n < 2 {
                first_times[n] = s.t_s;
            }
            p.push_each(&s, |e| {
                if let (Some(h), None) = (history.as_mut(), &write_error) {
                    write_error = h.write(e).err();
                }
            })
            .map_err(|e| data_error(e, Some(reader.last_line())))?;
            if let Some(e) = write_error.take() {
                return Err(e);
            }
            if let Some(pb) = &progress {
                if n.is_multiple_of(4096) {
                    pb.set_position(reader.byte_position());
                }
            }
        }
        (
            p.last().copied(),
            p.excitation(),
            p.estimator_samples(),
            p.gaps(),
            p.row_model(),
            p.torque_bias_nm(),
            p.residual_consistency(),
            p.gyro_density_ratio(),
        )
    };
    if let Some(p) = progress {
        p.finish_and_clear();
    }
    if let Some(h) = history {
        h.finish()?;
    }
    let stats = reader.stats();
    let Some(last) = last else {
        return Err(input(format!(
            "{file}: too few samples for an estimate ({} read; the {} estimator needs at least {})",
            stats.rows,
            entry.name,
            if entry.capabilities.needs_gyro && !entry.capabilities.constraints {
                2
            } else {
                inertia::estimator::MIN_SAMPLES
            }
        )));
    };
    let report = Report::new(&last, &config, a.batch, samples, gaps)
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
        .with_excitation(excitation)
        .with_row_model(row_model, torque)
        .with_residual_tests(residuals, density_ratio)
        .with_truth(truth.as_ref());
    if a.json {
        println!(
            "{}",
            serde_json::to_string(&report).map_err(|e| internal(format!("JSON: {e}")))?
        );
    } else {
        print!("{report}");
    }
    Ok(())
}
