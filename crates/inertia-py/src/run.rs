//! One estimation run over samples held in memory: what `inertia estimate` does with a
//! file, through the same library [`Run`] (the run policy is the library's), with the
//! messages placed at the array row or file line and their fixes named as keyword
//! arguments. Runs without the GIL.

use crate::errors::Failure;
use crate::samples::{Naming, Stats};
use crate::settings::RunSettings;
use inertia::estimator::Estimate;
use inertia::fix::{Fix, Fixes};
use inertia::pipeline::report::Report;
use inertia::pipeline::{PipelineConfig, PipelineError, Run, RunError, RunErrorKind};
use inertia::sample::Sample;

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
    /// Arrays pushed one sample at a time (`inertia.Estimator`).
    pub fn arrays() -> Self {
        Origin::Memory {
            naming: Naming::Arrays,
            label: "<stream>".into(),
        }
    }

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

    /// A run's error, tied to the sample that caused it (the CLI's wording, with the fixes
    /// as keyword arguments).
    pub fn run_error(&self, e: &RunError) -> Failure {
        let fixes = Fixes {
            fixes: e.fixes(),
            names: keyword_names,
            label: "keyword",
        };
        match (&e.kind, self) {
            // Settings the data show to be meaningless, and arrays without gyro rates, are
            // argument errors.
            (RunErrorKind::MemoryShorterThanStep { .. }, _) => {
                let (at, _) = self.at(e.sample);
                Failure::Refused {
                    message: format!("{e} ({}){fixes}", at.trim_end_matches(':')),
                    kind: e.error_kind(),
                    sample: e.sample,
                }
            }
            // Settings the batch form does not take.
            (
                RunErrorKind::Pipeline(
                    PipelineError::NotApplicable { .. } | PipelineError::NoBatch { .. },
                ),
                _,
            ) => Failure::Argument(format!("batch=True: {e}")),
            // Several records where the run cannot take them: the arguments.
            (
                RunErrorKind::RecordsNeedBatch
                | RunErrorKind::RecordsNeedRows { .. }
                | RunErrorKind::RecordsWithCalibration,
                _,
            ) => Failure::Argument(format!("{e}{fixes}")),
            (RunErrorKind::NeedsGyro { .. }, Origin::Memory { .. }) => Failure::Refused {
                message: format!("w: {e}"),
                kind: e.error_kind(),
                sample: e.sample,
            },
            _ => {
                let (at, line) = match (&e.kind, self) {
                    // The file's header lacks the columns.
                    (RunErrorKind::NeedsGyro { .. }, Origin::File { name, .. }) => {
                        (format!("{name}:1:"), Some(1))
                    }
                    _ => self.at(e.sample),
                };
                let columns = if e.is_step_too_large() {
                    format!(" columns `{}`:", self.q_columns())
                } else {
                    String::new()
                };
                Failure::Data {
                    message: format!("{at}{columns} {e}{fixes}"),
                    line,
                    kind: Some(e.error_kind()),
                    sample: e.sample,
                }
            }
        }
    }
}

/// How Python names a fix ([`inertia::fix`]): as keyword arguments.
pub fn keyword_names(fix: Fix) -> Option<&'static str> {
    Some(match fix {
        Fix::Jpl => "jpl=True",
        Fix::ScalarFirst => "scalar_first=True",
        Fix::ScalarLast => "scalar_first=False",
        Fix::NegateRho => "negate_rho=True",
        Fix::KeepGlitches => "glitches=\"keep\"",
        Fix::Memory => "memory",
        Fix::Resample => "resample",
        Fix::GyroNoise => "gyro_noise",
        Fix::PriorSigma => "prior_sigma",
        Fix::Products => "products",
        Fix::GyroDegrees => "gyro_unit=\"deg/s\"",
        Fix::GyroRadians => "gyro_unit=\"rad/s\"",
        Fix::Conjugate => "conjugate=True",
        Fix::InertialTorqueOn => "inertial_torque=\"on\"",
        Fix::Batch => "batch=True",
        _ => return None,
    })
}

/// What a run produced.
pub struct Output {
    pub report: Report,
    pub history: Option<Vec<Estimate>>,
}

/// One record of a run: its samples, the spacecraft file's rotors and their speeds, what
/// reading counted, and where the samples came from.
pub struct Record<'a> {
    pub samples: &'a [Sample],
    pub rotors: Option<&'a crate::Rotors>,
    pub stats: &'a Stats,
    pub origin: &'a Origin,
}

/// Estimate from `samples` as `inertia estimate` does from a file: the library's [`Run`].
pub fn run(
    samples: &[Sample],
    rotors: Option<&crate::Rotors>,
    stats: &Stats,
    origin: &Origin,
    config: PipelineConfig,
    settings: &RunSettings,
) -> Result<Output, Failure> {
    let record = Record {
        samples,
        rotors,
        stats,
        origin,
    };
    run_records(&[record], config, settings)
}

/// [`run`] over several records of one spacecraft, estimated together
/// ([`Run::next_record`]; `batch=True`).
pub fn run_records(
    records: &[Record<'_>],
    config: PipelineConfig,
    settings: &RunSettings,
) -> Result<Output, Failure> {
    let (batch, history, truth) = (settings.batch, settings.history, settings.truth.as_ref());
    let first = records
        .first()
        .ok_or_else(|| Failure::Argument("no records to estimate from".into()))?;
    let mut run = Run::new(config, batch).map_err(|e| match e {
        // Settings the batch form does not take are argument errors.
        PipelineError::NotApplicable { .. } | PipelineError::NoBatch { .. } => {
            Failure::Argument(format!("batch=True: {e}"))
        }
        other => Failure::Argument(crate::settings::settings_message(other)),
    })?;
    if records.len() > 1 {
        run.check_records()
            .map_err(|e| first.origin.run_error(&e))?;
    }
    let source = |r: &Record<'_>| r.rotors.map(|x| x.source.clone());
    if records.iter().any(|r| source(r) != source(first)) {
        return Err(Failure::Argument(
            "spacecraft: every record must be read with the same spacecraft file (or none)".into(),
        ));
    }
    if let Some(r) = first.rotors {
        // The thrusters' torque and force are in the samples already (`read_csv`).
        let mut spacecraft = r.spacecraft.clone();
        spacecraft.thrusters.clear();
        run = run.with_spacecraft(spacecraft);
    }
    let mut kept = history.then(Vec::new);
    let mut keep = |e: &Estimate| {
        if let Some(h) = kept.as_mut() {
            h.push(*e);
        }
    };
    // Each record's first input sample, to name a sample in its own record.
    let mut starts = Vec::with_capacity(records.len());
    for (k, r) in records.iter().enumerate() {
        let origin = r.origin;
        if k > 0 {
            // An empty record is the one before.
            run.next_record()
                .map_err(|e| records[k - 1].origin.run_error(&e))?;
        }
        run.check_columns(r.samples.iter().all(|s| s.omega_rad_s.is_some()))
            .map_err(|e| origin.run_error(&e))?;
        let start = run.input_samples();
        starts.push(start);
        let local = |e: RunError| RunError {
            sample: e.sample.map(|i| i - start),
            ..e
        };
        match r.rotors {
            Some(rotors) => {
                let m = rotors.spacecraft.rotors.len();
                for (i, s) in r.samples.iter().enumerate() {
                    let w = rotors.speeds.get(i * m..(i + 1) * m).unwrap_or(&[]);
                    run.push_with_speeds(s, w, &mut keep)
                        .map_err(|e| origin.run_error(&local(e)))?;
                }
            }
            None => {
                for s in r.samples {
                    run.push(s, &mut keep)
                        .map_err(|e| origin.run_error(&local(e)))?;
                }
            }
        }
    }
    run.finish(&mut keep).map_err(|e| {
        // The record of the sample named, if any (an empty record: the last).
        let k = match (&e.kind, e.sample) {
            (RunErrorKind::EmptyRecord { .. }, _) => records.len() - 1,
            (_, Some(i)) => starts.partition_point(|&s| s <= i).saturating_sub(1),
            (_, None) => 0,
        };
        let local = RunError {
            sample: e.sample.map(|i| i - starts[k]),
            ..e
        };
        records[k].origin.run_error(&local)
    })?;
    let label = records
        .iter()
        .map(|r| r.origin.label())
        .collect::<Vec<_>>()
        .join(", ");
    let stats = records
        .iter()
        .skip(1)
        .fold(*first.stats, |a, r| a.merged(r.stats));
    let report = run
        .report(&label, &stats)
        .ok_or_else(|| Failure::Argument("a finished run without an estimate".into()))?
        .with_truth(truth);
    Ok(Output {
        report,
        history: kept,
    })
}
