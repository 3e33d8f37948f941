//! The checks of the attitude against the gyro that every streaming run makes on its
//! input before estimating: a step where the attitude jumps against the gyro
//! ([`crate::telemetry::glitch`]) and a quaternion convention that the rates contradict
//! ([`crate::telemetry::convention`]). One type, so that the pipeline and a fixed-size
//! build (the C API's caller storage) make them alike.

use super::PipelineError;
use crate::sample::Sample;
use crate::telemetry::convention::{ConventionCheck, Verdict, STEPS_NEEDED};
use crate::telemetry::glitch::{GlitchCheck, GlitchPolicy};

/// The glitch and convention checks of one stream.
#[derive(Debug, Clone, Default)]
pub struct AttitudeChecks {
    glitch: GlitchCheck,
    convention: ConventionCheck,
}

impl AttitudeChecks {
    /// Check input sample `index`: a glitch stops the run under [`GlitchPolicy::Stop`]
    /// (it is counted either way), and a wrong convention stops it once the first
    /// [`STEPS_NEEDED`] steps show it.
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
        if self.convention.steps() < STEPS_NEEDED {
            self.convention.push(s);
            convention_error(&self.convention)?;
        }
        Ok(())
    }

    /// The glitch check.
    #[must_use]
    pub fn glitches(&self) -> &GlitchCheck {
        &self.glitch
    }

    /// The convention check's verdict so far.
    #[must_use]
    pub fn verdict(&self) -> Verdict {
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
            as_read,
            fixed,
            steps: check.steps(),
        }),
        _ => Ok(()),
    }
}
