//! Why a pipeline cannot be built or cannot go on ([`PipelineError`]), with the fixes its
//! messages recommend ([`crate::fix`]) and its kind as every front end reports it.

use crate::constraints::ConstraintError;
use crate::estimator::{EstimatorError, InvalidArgument};
use crate::fix::Fix;
use crate::sample::OutOfRange;
use crate::telemetry::convention::Verdict;
use crate::telemetry::glitch::Glitch;
use std::string::String;

/// Most resampled samples per input step (`resample_s`): a finer grid is refused
/// ([`PipelineError::ResampleTooFine`]) rather than left to produce billions of samples.
pub const MAX_RESAMPLE_FACTOR: f64 = 100.0;

/// Why a pipeline cannot be built or cannot go on.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PipelineError {
    /// No estimator of that name.
    #[error("unknown estimator `{name}` (known: {known})")]
    UnknownEstimator {
        /// The name given.
        name: String,
        /// The registered names, comma-separated.
        known: String,
    },
    /// No solver backend of that name.
    #[error("unknown solver `{name}` (known: {known})")]
    UnknownSolver {
        /// The name given.
        name: String,
        /// The registered names, comma-separated.
        known: String,
    },
    /// The backend exists but not in this build.
    #[error("solver `{name}`: {why}")]
    SolverUnavailable {
        /// Backend name.
        name: &'static str,
        /// Why.
        why: &'static str,
    },
    /// A setting is out of range.
    #[error("setting `{field}` = {} is invalid: expected {expected}", crate::text::Num(*.value))]
    InvalidSetting {
        /// The setting.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A setting named a value it does not have.
    #[error("setting `{setting}`: unknown value `{}` (known: {expected})", crate::text::Clipped::new(.value))]
    UnknownChoice {
        /// The setting.
        setting: &'static str,
        /// The value given.
        value: String,
        /// The values it has.
        expected: &'static str,
    },
    /// A setting that needs another one.
    #[error("setting `{setting}` needs `{needs}` {requirement}: {why}")]
    NeedsSetting {
        /// The setting.
        setting: &'static str,
        /// The setting it needs.
        needs: &'static str,
        /// What that one must be (`"> 0"`, `"on"`).
        requirement: &'static str,
        /// Why.
        why: &'static str,
    },
    /// A setting the chosen estimator does not use (rather than ignore it silently).
    #[error("setting `{setting}` does not apply to the {estimator} estimator")]
    NotApplicable {
        /// The setting.
        setting: &'static str,
        /// The estimator.
        estimator: &'static str,
    },
    /// The estimator has no batch form.
    #[error("the {estimator} estimator has no batch form")]
    NoBatch {
        /// The estimator.
        estimator: &'static str,
    },
    /// The attitude disagrees with the gyro rates, and another reading of the quaternion
    /// columns agrees ([`crate::telemetry::convention`]).
    #[error("the attitude quaternions disagree with the gyro rates (median relative mismatch {as_read:.2} over {steps} steps; {fixed:.2e} when read differently): {fix}")]
    AttitudeConvention {
        /// The fix, in words.
        fix: &'static str,
        /// The fix, typed ([`Self::fixes`]).
        fixes: &'static [Fix],
        /// Median relative mismatch as read.
        as_read: f64,
        /// Median relative mismatch with the fix.
        fixed: f64,
        /// Steps compared.
        steps: usize,
    },
    /// The data fit a negative-definite J whose negation would be determined
    /// ([`Unobservable::AtFloor`] with `mirror_determined`): the wheel momentum ρ has the
    /// opposite sign of this library's convention (the rotors' own momentum, body axes,
    /// docs/conventions.md §1), or so has the known torque τ; until gyro rates have
    /// confirmed the quaternion convention, a conjugated quaternion cannot be ruled out.
    ///
    /// [`Unobservable::AtFloor`]: crate::estimator::observability::Unobservable::AtFloor
    #[error("{}", ReversedMessage { sample, tau_given, quaternions })]
    ReversedMomentum {
        /// 0-based index of the input sample whose estimate showed it (`None`: a batch
        /// answer, from the whole record).
        sample: Option<usize>,
        /// Whether the telemetry had a non-zero known torque.
        tau_given: bool,
        /// The quaternion convention check's verdict: [`Verdict::Consistent`] where the
        /// gyro rates confirmed it (then only the sign of ρ or τ is left).
        quaternions: Verdict,
    },
    /// One step of the attitude jumps against the gyro ([`crate::telemetry::glitch`]),
    /// and the policy is [`crate::telemetry::glitch::GlitchPolicy::Stop`].
    #[error("{glitch} (the step ends at this line; keep glitches to estimate anyway)")]
    AttitudeGlitch {
        /// 0-based index of the input sample that ends the step.
        sample: usize,
        /// The step.
        glitch: Glitch,
    },
    /// A sample holds a value outside the supported range ([`crate::sample::range`]).
    #[error("input sample {sample}: {source}")]
    OutOfRange {
        /// 0-based index of the input sample.
        sample: usize,
        /// Which value, and how far out.
        source: OutOfRange,
    },
    /// Resampling would put more than [`MAX_RESAMPLE_FACTOR`] samples in one input step.
    #[error("input sample {sample}: resampling to {} s would make {} samples of the step of {} s (at most {})", crate::text::Num(*.period_s), crate::text::Num((*.step_s / *.period_s).round()), crate::text::Num(*.step_s), crate::text::Num(MAX_RESAMPLE_FACTOR))]
    ResampleTooFine {
        /// 0-based index of the input sample that ends the step.
        sample: usize,
        /// The step, s.
        step_s: f64,
        /// The resampling period, s.
        period_s: f64,
    },
    /// The constraint set is unusable.
    #[error("constraints: {0}")]
    Constraints(#[from] ConstraintError),
    /// The estimator stopped on the data.
    #[error("{}{source}", sample.map(|s| std::format!("input sample {s}: ")).unwrap_or_default())]
    Estimator {
        /// 0-based index of the input sample that stopped it, when one did.
        sample: Option<usize>,
        /// What went wrong.
        source: EstimatorError,
    },
}

impl PipelineError {
    /// The settings its message recommends changing ([`crate::fix`]), in its order.
    #[must_use]
    pub fn fixes(&self) -> &'static [Fix] {
        match self {
            PipelineError::AttitudeConvention { fixes, .. } => fixes,
            PipelineError::ReversedMomentum { quaternions, .. } => match quaternions {
                Verdict::Consistent(_) => &[Fix::NegateRho],
                _ => &[Fix::NegateRho, Fix::Conjugate],
            },
            PipelineError::AttitudeGlitch { .. } => &[Fix::KeepGlitches],
            PipelineError::ResampleTooFine { .. } => &[Fix::Resample],
            _ => &[],
        }
    }

    /// Its kind, as every front end reports it.
    #[must_use]
    pub fn error_kind(&self) -> crate::error_kind::ErrorKind {
        use crate::error_kind::ErrorKind as K;
        match self {
            PipelineError::AttitudeConvention { .. } => K::AttitudeConvention,
            PipelineError::ReversedMomentum { .. } => K::ReversedMomentum,
            PipelineError::AttitudeGlitch { .. } => K::AttitudeGlitch,
            PipelineError::OutOfRange { .. } => K::OutOfRange,
            PipelineError::Estimator { source, .. } => match source {
                EstimatorError::Solve(_) => K::Solver,
                EstimatorError::TooFewSamples { .. } => K::TooFewSamples,
                EstimatorError::Row { .. } => K::Row,
                _ => K::InvalidSetting,
            },
            _ => K::InvalidSetting,
        }
    }

    pub(crate) fn from_argument(a: InvalidArgument) -> Self {
        PipelineError::InvalidSetting {
            field: a.name,
            value: a.value,
            expected: a.expected,
        }
    }
}

impl PipelineError {
    /// For a step too large for the rows (`|φ| ≥ 1`), the time its end sample has, s,
    /// and otherwise `None`: how a caller that holds the samples' lines finds the line to
    /// name ([`Self::ends_step`]); the estimator may be behind the reader (resampling
    /// reads ahead, the half-rate shadow's step ends at a later sample).
    #[must_use]
    pub(crate) fn step_end_s(&self) -> Option<f64> {
        match self {
            PipelineError::Estimator {
                source:
                    EstimatorError::Row {
                        source: crate::discrete::RowError::StepTooLarge { t1_s, .. },
                        ..
                    },
                ..
            } => Some(*t1_s),
            _ => None,
        }
    }

    /// Whether a sample at `t_s` is at or after the step end `step_end_s` (to 1e-9 of its
    /// size): the first such sample ends the step.
    #[must_use]
    pub(crate) fn ends_step(t_s: f64, step_end_s: f64) -> bool {
        t_s >= step_end_s - 1e-9 * (1.0 + step_end_s.abs())
    }
}

/// The message of [`PipelineError::ReversedMomentum`].
pub(crate) struct ReversedMessage<'a> {
    pub(crate) sample: &'a Option<usize>,
    pub(crate) tau_given: &'a bool,
    pub(crate) quaternions: &'a Verdict,
}

impl core::fmt::Display for ReversedMessage<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        if let Some(s) = self.sample {
            write!(f, "input sample {s}: ")?;
        }
        f.write_str("the data fit a negative-definite J whose negation would be determined: the wheel momentum rho has the opposite sign of this library's convention (the rotors' own momentum in body axes, docs/conventions.md §1; negate it)")?;
        if *self.tau_given {
            f.write_str(", or the known torque tau has")?;
        }
        match self.quaternions {
            Verdict::Consistent(_) => Ok(()),
            Verdict::Undecided => f.write_str(", or the quaternions are conjugated (read them conjugated): gyro rates have not confirmed the quaternion convention (there are none, or too few turning steps yet)"),
            _ => f.write_str(", or the quaternions are conjugated (read them conjugated): the attitude disagrees with the gyro rates too"),
        }
    }
}
