//! `inertia estimate`: arguments → pipeline settings → the library's [`Run`] over the
//! file's samples → the library's report. The run policy is the library's; here are only
//! the file, its lines and the options' names.

use crate::args::EstimateArgs;
use crate::config::{self, settings_error, InertiaFile};
use crate::error::{input, internal, read_failed, telemetry, telemetry_at, CliError};
use crate::history::HistoryFile;
use crate::output::{is_stdio, to_stdout};
use inertia::fix::{Fix, Fixes};
use inertia::pipeline::{Run, RunError, RunErrorKind, RECENT};
use inertia::telemetry::csv::TelemetryReader;
use inertia::telemetry::read_ahead::ReadAhead;
use std::collections::VecDeque;
use std::io::{IsTerminal, Read};

/// The telemetry: a file, or standard input for `-`.
fn open(path: &std::path::Path) -> Result<(Box<dyn Read + Send>, String), CliError> {
    if is_stdio(path) {
        return Ok((Box::new(std::io::stdin()), "<stdin>".into()));
    }
    let f = std::fs::File::open(path).map_err(|e| read_failed(path, e))?;
    Ok((Box::new(f), path.display().to_string()))
}

/// How the command line names a fix ([`inertia::fix`]): as its options.
pub fn option_names(fix: Fix) -> Option<&'static str> {
    Some(match fix {
        Fix::Jpl => "--jpl",
        Fix::ScalarFirst => "--scalar-first",
        Fix::ScalarLast => "drop --scalar-first",
        Fix::NegateRho => "--negate-rho",
        Fix::KeepGlitches => "--glitches keep",
        Fix::Memory => "--memory",
        Fix::Resample => "--resample",
        Fix::GyroNoise => "--gyro-noise",
        Fix::PriorSigma => "--prior-sigma",
        Fix::Products => "--products",
        Fix::GyroDegrees => "--gyro-unit deg/s",
        Fix::GyroRadians => "--gyro-unit rad/s",
        Fix::Conjugate => "--conjugate",
        Fix::InertialTorqueOn => "--inertial-torque on",
        Fix::Batch => "--batch",
        _ => return None,
    })
}

/// A run's error as the command line prints it: `file:line:`, the message, the options
/// that fix it.
fn run_error(e: &RunError, file: &str, line: Option<u64>, q_columns: &str) -> CliError {
    let at = line.map_or_else(|| format!("{file}:"), |l| format!("{file}:{l}:"));
    let columns = if e.is_step_too_large() {
        format!(" columns `{q_columns}`:")
    } else {
        String::new()
    };
    let fixes = Fixes {
        fixes: e.fixes(),
        names: option_names,
        label: "option",
    };
    CliError::Refused {
        message: format!("{at}{columns} {e}{fixes}"),
        kind: e.error_kind(),
        sample: e.sample,
        line,
    }
}

/// Run the command.
pub fn run(a: &EstimateArgs) -> Result<(), CliError> {
    if a.output.as_deref().is_some_and(is_stdio) {
        return Err(input(
            "-o -: the report goes to standard output; give the history a file name (e.g. -o history.csv)",
        ));
    }
    let described = config::description(a)?;
    let spacecraft = config::spacecraft(&described)?;
    let options = config::csv_options(&described, spacecraft.as_ref())?;
    let settings = config::pipeline_settings(&described)?;
    let batch = described.batch.unwrap_or(false);
    let config = settings.validate().map_err(settings_error)?;
    let truth = a.truth.as_deref().map(InertiaFile::read).transpose()?;
    let mut history = a.output.as_deref().map(HistoryFile::create).transpose()?;
    let mut run = Run::new(config, batch).map_err(settings_error)?;
    if let Some(s) = spacecraft {
        run = run.with_spacecraft(s);
    }
    // The file and line of the samples a run's error may name: every one in batch mode or
    // where the run keeps the samples for the wheel speeds' time tag (the estimate at the
    // end names any sample), the last `RECENT` streaming.
    let mut lines: VecDeque<(usize, u64)> = VecDeque::new();
    let keep = if batch || run.holds_samples() {
        usize::MAX
    } else {
        RECENT
    };
    let place = |lines: &VecDeque<(usize, u64)>, n: usize, e: &RunError| {
        let first = n - lines.len();
        e.sample
            .and_then(|i| lines.get(i.checked_sub(first)?).copied())
    };
    if a.files.len() > 1 {
        let first = a.files[0].display().to_string();
        run.check_records()
            .map_err(|e| run_error(&e, &first, None, ""))?;
    }
    let mut names: Vec<String> = Vec::new();
    let mut q_columns = String::new();
    let mut stats: Option<inertia::telemetry::csv::ReadStats> = None;
    let mut write_error = None;
    for (k, path) in a.files.iter().enumerate() {
        let (source, name) = open(path)?;
        let reader = TelemetryReader::new(source, &name, options.clone()).map_err(telemetry)?;
        let file = reader.file().to_string();
        q_columns = reader.quaternion_columns();
        if k > 0 {
            // An empty record is the one before.
            let previous = names.last().unwrap_or(&file);
            run.next_record()
                .map_err(|e| run_error(&e, previous, None, &q_columns))?;
        }
        run.check_columns(reader.has_gyro())
            .map_err(|e| run_error(&e, &file, Some(1), &q_columns))?;
        names.push(file);
        // Parsing overlaps the estimator.
        let mut reader = ReadAhead::new(reader);
        let size = if is_stdio(path) {
            0
        } else {
            std::fs::metadata(path).map_or(0, |m| m.len())
        };
        let progress = (std::io::stderr().is_terminal() && !a.json && size > 1 << 20).then(|| {
            let p = indicatif::ProgressBar::new(size);
            p.set_style(
                indicatif::ProgressStyle::with_template("{bar:40} {bytes}/{total_bytes} {eta}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            p
        });
        while let Some(item) = reader.next() {
            let s = item.map_err(|e| telemetry_at(e, Some(run.input_samples())))?;
            if lines.len() == keep {
                lines.pop_front();
            }
            lines.push_back((k, reader.last_line()));
            let n = run.input_samples();
            run.push_with_actuators(&s, reader.last_speeds(), reader.last_throttles(), |e| {
                if let (Some(h), None) = (history.as_mut(), &write_error) {
                    write_error = h.write(e).err();
                }
            })
            .map_err(|e| {
                let at = place(&lines, n + 1, &e);
                let file = at.map_or(&names[k], |(f, _)| &names[f]);
                run_error(&e, file, at.map(|p| p.1), &q_columns)
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
        if let Some(p) = progress {
            p.finish_and_clear();
        }
        let read = reader
            .finish()
            .ok_or_else(|| internal("the telemetry reader thread failed"))?;
        stats = Some(stats.map_or(read, |s| s.merged(&read)));
    }
    let n = run.input_samples();
    run.finish(|e| {
        if let (Some(h), None) = (history.as_mut(), &write_error) {
            write_error = h.write(e).err();
        }
    })
    .map_err(|e| {
        let at = place(&lines, n, &e);
        let file = match (&e.kind, at) {
            (RunErrorKind::EmptyRecord { .. }, _) => names.last().cloned().unwrap_or_default(),
            (_, Some((f, _))) => names[f].clone(),
            (_, None) => names.join(", "),
        };
        run_error(&e, &file, at.map(|p| p.1), &q_columns)
    })?;
    if let Some(e) = write_error.take() {
        return Err(e);
    }
    if let Some(h) = history {
        h.finish()?;
    }
    let stats = stats.ok_or_else(|| internal("no input file"))?;
    let file = names.join(", ");
    let report = run
        .report(&file, &stats)
        .ok_or_else(|| internal("a finished run without an estimate"))?
        .with_truth(truth.as_ref());
    if a.json {
        let json = serde_json::to_string(&report).map_err(|e| internal(format!("JSON: {e}")))?;
        to_stdout(|w| writeln!(w, "{json}"))
    } else {
        to_stdout(|w| write!(w, "{}", report.text(option_names, "option")))
    }
}
