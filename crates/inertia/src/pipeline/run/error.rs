//! Why a run cannot go on ([`RunError`]): the typed error every front end renders in its
//! own vocabulary.

use super::super::{PipelineError, MAX_RESAMPLE_FACTOR};
use crate::error_kind::ErrorKind;
use crate::fix::Fix;
use crate::telemetry::gate::SampleError;
use crate::text::Num;

/// Why a run cannot go on, and at which input sample.
///
/// Its message names no place (a front end puts its file line or array row first) and no
/// front end's option ([`Self::fixes`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RunError {
    /// 0-based index of the input sample at fault (`None`: the whole input).
    pub sample: Option<usize>,
    /// What is wrong.
    pub kind: RunErrorKind,
}

/// What is wrong with a run's input or settings.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RunErrorKind {
    /// The estimator needs gyro rates and the input has none.
    #[error("the {estimator} estimator needs gyro rates (w_x,w_y,w_z)")]
    NeedsGyro {
        /// The estimator.
        estimator: &'static str,
    },
    /// A sample the sample gate refuses (`crate::telemetry::gate::Order`): time not
    /// increasing, gyro rates given for some samples and not for others.
    #[error(transparent)]
    Sample(SampleError),
    /// A memory shorter than the sample period forgets each sample before the next.
    #[error("the memory {} s is shorter than the sample period {} s; the memory must span several samples", Num(*.memory_s), Num(*.step_s))]
    MemoryShorterThanStep {
        /// The memory time constant, s.
        memory_s: f64,
        /// The sample period (the resampling period where resampling), s.
        step_s: f64,
    },
    /// The input ended before the estimator could make one estimate.
    #[error("too few samples for an estimate: the {estimator} estimator needs at least {need}, got {got}{}", resampled(*.got, *.read))]
    TooFewSamples {
        /// The estimator.
        estimator: &'static str,
        /// Its minimum (the estimator's capabilities in the registry).
        need: usize,
        /// Samples it saw (after resampling).
        got: usize,
        /// Input samples read.
        read: usize,
    },
    /// A run with a spacecraft file's rotors was given a sample without one speed per
    /// rotor.
    #[error("expected {expected} rotor speeds (one per rotor of the spacecraft file: {names}), got {got}")]
    RotorSpeeds {
        /// Rotors in the spacecraft file.
        expected: usize,
        /// Speeds given.
        got: usize,
        /// The rotors' names, comma-separated.
        names: std::string::String,
    },
    /// Not one throttle per thruster of the spacecraft file.
    #[error("expected {expected} thruster throttles (one per thruster of the spacecraft file: {names}), got {got}")]
    Throttles {
        /// Thrusters in the spacecraft file.
        expected: usize,
        /// Throttles given.
        got: usize,
        /// The thrusters' names, comma-separated.
        names: std::string::String,
    },
    /// The input gives a force (`f_*`) and the spacecraft file's thrusters give one too.
    #[error("the force is given twice: by the telemetry's force columns (f_x,f_y,f_z) and by the spacecraft file's thrusters; give one")]
    ForceTwice,
    /// The rotor momentum the wheel speeds give is outside the supported range.
    #[error("the rotor momentum from the wheel speeds (columns {columns}) is {} N m s on one axis, outside the supported range (magnitude at most {} N m s): check the speeds' unit and the spin inertias", Num(*.value_nms), Num(*.limit_nms))]
    RotorMomentumOutOfRange {
        /// The component, N m s.
        value_nms: f64,
        /// The largest magnitude supported, N m s.
        limit_nms: f64,
        /// The speed columns, comma-separated.
        columns: std::string::String,
    },
    /// Several records in a run that is not a batch run.
    #[error("several records are estimated together only over all their samples at once (a batch run): each record's initial momenta and body torque are unknowns of that one solve")]
    RecordsNeedBatch,
    /// Several records for an estimator without the discrete momentum rows.
    #[error("several records need the discrete momentum rows: the {estimator} estimator takes one record per run")]
    RecordsNeedRows {
        /// The estimator.
        estimator: &'static str,
    },
    /// Several records with the rotor calibration.
    #[error("several records are not supported with the rotor calibration: one record per run")]
    RecordsWithCalibration,
    /// A record ended (or another begun) before it had a sample.
    #[error("record {record} has no samples")]
    EmptyRecord {
        /// The record, from 1.
        record: usize,
    },
    /// An earlier error stopped the run.
    #[error("the run stopped on an earlier error ({0}); start a new one")]
    Stopped(std::string::String),
    /// The pipeline or the estimator stopped.
    #[error(transparent)]
    Pipeline(PipelineError),
}

fn resampled(got: usize, read: usize) -> std::string::String {
    if got == read {
        std::string::String::new()
    } else {
        std::format!(" ({read} read, {got} on the resampling grid)")
    }
}

impl core::fmt::Display for RunError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        use crate::estimator::EstimatorError;
        match &self.kind {
            // The place is the front end's to name: not the pipeline's "input sample i: ".
            RunErrorKind::Pipeline(PipelineError::Estimator { source, .. }) => match source {
                EstimatorError::Solve(s) => write!(f, "the solver failed on these data: {s}"),
                other => write!(f, "{other}"),
            },
            RunErrorKind::Pipeline(PipelineError::ReversedMomentum {
                tau_given,
                quaternions,
                ..
            }) => write!(
                f,
                "{}",
                super::super::error::ReversedMessage {
                    sample: &None,
                    tau_given,
                    quaternions,
                }
            ),
            RunErrorKind::Pipeline(PipelineError::OutOfRange { source, .. }) => {
                write!(f, "{source}")
            }
            RunErrorKind::Pipeline(PipelineError::ResampleTooFine {
                step_s, period_s, ..
            }) => write!(
                f,
                "resampling to {} s would make {} samples of the step of {} s (at most {})",
                Num(*period_s),
                Num((*step_s / *period_s).round()),
                Num(*step_s),
                Num(MAX_RESAMPLE_FACTOR)
            ),
            other => write!(f, "{other}"),
        }
    }
}

impl std::error::Error for RunError {}

impl RunError {
    /// Whether a step of the attitude was too large for the rows (`|φ| ≥ 1`): a front end
    /// names its quaternion columns.
    #[must_use]
    pub fn is_step_too_large(&self) -> bool {
        self.pipeline()
            .and_then(PipelineError::step_end_s)
            .is_some()
    }

    pub(super) fn at(sample: usize, kind: RunErrorKind) -> Self {
        Self {
            sample: Some(sample),
            kind,
        }
    }

    /// The settings its message recommends changing ([`crate::fix`]).
    #[must_use]
    pub fn fixes(&self) -> &'static [Fix] {
        match &self.kind {
            RunErrorKind::MemoryShorterThanStep { .. } => &[Fix::Memory],
            RunErrorKind::RecordsNeedBatch => &[Fix::Batch],
            RunErrorKind::Pipeline(e) => e.fixes(),
            _ => &[],
        }
    }

    /// Its kind, as every front end reports it.
    #[must_use]
    pub fn error_kind(&self) -> ErrorKind {
        match &self.kind {
            RunErrorKind::NeedsGyro { .. } => ErrorKind::NeedsGyro,
            RunErrorKind::RotorSpeeds { .. }
            | RunErrorKind::Throttles { .. }
            | RunErrorKind::ForceTwice => ErrorKind::Columns,
            RunErrorKind::RotorMomentumOutOfRange { .. } => ErrorKind::OutOfRange,
            RunErrorKind::Sample(e) => e.error_kind(),
            RunErrorKind::MemoryShorterThanStep { .. } => ErrorKind::MemoryShorterThanStep,
            RunErrorKind::TooFewSamples { .. } | RunErrorKind::EmptyRecord { .. } => {
                ErrorKind::TooFewSamples
            }
            RunErrorKind::RecordsNeedBatch
            | RunErrorKind::RecordsNeedRows { .. }
            | RunErrorKind::RecordsWithCalibration => ErrorKind::InvalidSetting,
            RunErrorKind::Stopped(_) => ErrorKind::Stopped,
            RunErrorKind::Pipeline(e) => e.error_kind(),
        }
    }

    /// The pipeline's error, where the pipeline or the estimator stopped.
    #[must_use]
    pub(crate) fn pipeline(&self) -> Option<&PipelineError> {
        match &self.kind {
            RunErrorKind::Pipeline(e) => Some(e),
            _ => None,
        }
    }
}
