//! The checks of the attitude against the gyro that every streaming run makes on its
//! input before estimating: a step where the attitude jumps against the gyro
//! ([`crate::telemetry::glitch`]) and a quaternion convention that the rates contradict
//! ([`crate::telemetry::convention`]); and, on its estimates, a wheel momentum of the
//! opposite sign ([`reversed_momentum`]). One type, so that the pipeline and a fixed-size
//! build (the C API's caller storage) make them alike.

use super::PipelineError;
use crate::estimator::observability::{Observability, Unobservable};
use crate::estimator::Estimate;
use crate::sample::Sample;
use crate::telemetry::convention::{ConventionCheck, Verdict};
use crate::telemetry::glitch::{GlitchCheck, GlitchPolicy};

/// The glitch and convention checks of one stream.
#[derive(Debug, Clone, Default)]
pub struct AttitudeChecks {
    glitch: GlitchCheck,
    convention: ConventionCheck,
    /// Whether any sample so far had a non-zero known torque.
    tau_given: bool,
}

impl AttitudeChecks {
    /// Check input sample `index`: a glitch stops the run under [`GlitchPolicy::Stop`]
    /// (it is counted either way), and a wrong convention stops it once the first
    /// `crate::telemetry::convention::STEPS_NEEDED` steps show it.
    pub fn push(
        &mut self,
        index: usize,
        s: &Sample,
        policy: GlitchPolicy,
    ) -> Result<(), PipelineError> {
        if let Some(glitch) = self.glitch.push(s) {
            if policy == GlitchPolicy::Stop {
                return Err(PipelineError::AttitudeGlitch {
                    sample: index,
                    glitch,
                });
            }
        }
        if !self.convention.decided() {
            self.convention.push(s);
            convention_error(&self.convention)?;
        }
        self.tau_given |= s.tau_nm != nalgebra::Vector3::zeros();
        Ok(())
    }

    /// Check estimate `e` of input sample `index`: stop where it shows a wheel momentum
    /// of the opposite sign ([`PipelineError::ReversedMomentum`]).
    pub fn estimate(&self, index: usize, e: &Estimate) -> Result<(), PipelineError> {
        reversed_momentum(e, Some(index), self.tau_given, || self.convention.verdict())
    }

    /// The glitch check.
    #[must_use]
    pub(crate) fn glitches(&self) -> &GlitchCheck {
        &self.glitch
    }

    /// The convention check's verdict so far.
    #[must_use]
    pub(crate) fn verdict(&self) -> Verdict {
        self.convention.verdict()
    }
}

/// The error of a convention check whose verdict is wrong.
pub(crate) fn convention_error(check: &ConventionCheck) -> Result<(), PipelineError> {
    match check.verdict() {
        Verdict::Wrong {
            reading,
            as_read,
            fixed,
        } => Err(PipelineError::AttitudeConvention {
            fix: reading.fix(),
            fixes: reading.fixes(),
            as_read,
            fixed,
            steps: check.steps(),
        }),
        _ => Ok(()),
    }
}

/// [`PipelineError::ReversedMomentum`] where estimate `e` (of input sample `sample`; `None`
/// for a batch answer) rests on the floor and the negated least-squares answer would be
/// determined ([`Unobservable::AtFloor`], `mirror_determined`); `tau_given`, whether the
/// telemetry had a non-zero known torque; `verdict`, the convention check's (asked only
/// then).
pub(crate) fn reversed_momentum(
    e: &Estimate,
    sample: Option<usize>,
    tau_given: bool,
    verdict: impl FnOnce() -> Verdict,
) -> Result<(), PipelineError> {
    match e.observability {
        Observability::NotObservable(Unobservable::AtFloor {
            mirror_determined: true,
            ..
        }) => Err(PipelineError::ReversedMomentum {
            sample,
            tau_given,
            quaternions: verdict(),
        }),
        _ => Ok(()),
    }
}
