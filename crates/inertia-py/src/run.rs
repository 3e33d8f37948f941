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
        _ => return None,
    })
}

/// What a run produced.
pub struct Output {
    pub report: Report,
    pub history: Option<Vec<Estimate>>,
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
    let (batch, history, truth) = (settings.batch, settings.history, settings.truth.as_ref());
    let mut run = Run::new(config, batch).map_err(|e| match e {
        // Settings the batch form does not take are argument errors.
        PipelineError::NotApplicable { .. } | PipelineError::NoBatch { .. } => {
            Failure::Argument(format!("batch=True: {e}"))
        }
        other => Failure::Argument(crate::settings::settings_message(other)),
    })?;
    run.check_columns(samples.iter().all(|s| s.omega_rad_s.is_some()))
        .map_err(|e| origin.run_error(&e))?;
    let mut kept = history.then(Vec::new);
    let mut keep = |e: &Estimate| {
        if let Some(h) = kept.as_mut() {
            h.push(*e);
        }
    };
    match rotors {
        Some(r) => {
            // The thrusters' torque and force are in the samples already (`read_csv`).
            let mut spacecraft = r.spacecraft.clone();
            spacecraft.thrusters.clear();
            run = run.with_spacecraft(spacecraft);
            let m = r.spacecraft.rotors.len();
            for (k, s) in samples.iter().enumerate() {
                let w = r.speeds.get(k * m..(k + 1) * m).unwrap_or(&[]);
                run.push_with_speeds(s, w, &mut keep)
                    .map_err(|e| origin.run_error(&e))?;
            }
        }
        None => {
            for s in samples {
                run.push(s, &mut keep).map_err(|e| origin.run_error(&e))?;
            }
        }
    }
    run.finish(&mut keep).map_err(|e| origin.run_error(&e))?;
    let report = run
        .report(origin.label(), stats)
        .ok_or_else(|| Failure::Argument("a finished run without an estimate".into()))?
        .with_truth(truth);
    Ok(Output {
        report,
        history: kept,
    })
}
