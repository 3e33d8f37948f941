//! The momentum RLS baseline ([`crate::estimator::momentum`]) in the pipeline.

use crate::estimator::momentum::{MomentumRls, MomentumSettings};
use crate::estimator::{Estimate, EstimatorError};
use crate::pipeline::config::EstimatorEntry;
use crate::pipeline::config::PipelineConfig;
use crate::pipeline::diagnostics::Diagnostics;
use crate::pipeline::error::PipelineError;
use crate::pipeline::interface::{Capabilities, Estimator};
use crate::sample::Sample;
use std::boxed::Box;

/// Registry entry.
pub(crate) const MOMENTUM: EstimatorEntry = EstimatorEntry {
    name: "momentum",
    summary: "momentum-based RLS baseline (Norman, Peck & O'Shaughnessy 2011), unconstrained, needs gyro rates",
    capabilities: Capabilities {
        needs_gyro: true,
        constraints: false,
        compensation: false,
        uncertainty: false,
        row_model: false,
        filter: false,
    },
    build,
    batch: None,
};

struct Momentum {
    rls: MomentumRls,
    every: usize,
    /// The last update's estimate where `every` held it back, for [`Estimator::flush`].
    held: Option<Estimate>,
}

fn build(c: &PipelineConfig) -> Result<Box<dyn Estimator>, PipelineError> {
    let rls = MomentumRls::new(MomentumSettings {
        memory_s: c.memory_s,
        ..MomentumSettings::default()
    })
    .map_err(PipelineError::from_argument)?;
    Ok(Box::new(Momentum {
        rls,
        every: c.solve_every,
        held: None,
    }))
}

impl Estimator for Momentum {
    fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        let e = self.rls.push(s)?;
        if self.rls.updates().is_multiple_of(self.every) {
            self.held = None;
            return Ok(e);
        }
        if e.is_some() {
            self.held = e;
        }
        Ok(None)
    }

    fn flush(&mut self) -> Result<Option<Estimate>, EstimatorError> {
        Ok(self.held.take())
    }

    fn diagnostics(&self) -> Diagnostics {
        Diagnostics::default()
    }
}
