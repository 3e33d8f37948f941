//! What the pipeline asks of an estimator: the [`Estimator`] trait (`push`,
//! `diagnostics` and `flush`), what it uses and needs ([`Capabilities`]) and a batch run's answer
//! ([`BatchOutput`]). Its registry entry is in [`super::config`], beside the validated
//! settings it is built from; [`super::registry`] lists the entries.

use super::diagnostics::Diagnostics;
use crate::estimator::{Estimate, EstimatorError};
use crate::sample::Sample;

/// A streaming estimator as the pipeline drives it: what every estimator has.
pub(crate) trait Estimator: Send {
    /// Feed one sample; an estimate when one is due.
    fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError>;
    /// What the estimator can say about its run at its latest estimate.
    fn diagnostics(&self) -> Diagnostics;
    /// End of input: the answer at the last completed row block where rows came after
    /// the last solve (`solve_every` > 1), so that a record's end has an answer; none
    /// where the last block was answered.
    fn flush(&mut self) -> Result<Option<Estimate>, EstimatorError>;
}

/// What a batch run has besides its samples and settings.
///
/// * **Rotor parameters** it estimates with J ([`crate::estimator::rotor_calibration`]):
///   each source's 1σ change of every sample's rotor momentum, N m s, and its prior mean
///   (in its σ; 0: the spacecraft file's value); none: no calibration.
/// * **Records**: the index of the first sample of each record after the first, where
///   the samples are several records of one spacecraft (in time order, a gap between
///   each two: [`crate::pipeline::Run::next_record`]); empty: one record. Each record has
///   its own chains (initial momenta, inertial torque) and its own body-frame torque.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct BatchInputs {
    pub(crate) momenta: std::vec::Vec<std::vec::Vec<nalgebra::Vector3<f64>>>,
    pub(crate) prior_mean: std::vec::Vec<f64>,
    pub(crate) records: std::vec::Vec<usize>,
}

impl BatchInputs {
    /// No calibration, one record.
    pub(crate) const NONE: BatchInputs = BatchInputs {
        momenta: std::vec::Vec::new(),
        prior_mean: std::vec::Vec::new(),
        records: std::vec::Vec::new(),
    };

    /// Whether there is no rotor source.
    #[must_use]
    pub(crate) fn is_empty(&self) -> bool {
        self.momenta.is_empty()
    }

    /// The record of sample `i` (0 for the first).
    #[must_use]
    pub(crate) fn record_of(&self, i: usize) -> usize {
        self.records.partition_point(|&start| start <= i)
    }
}

/// The answer of a batch run.
#[derive(Debug, Clone)]
pub struct BatchOutput {
    /// The estimate from all samples.
    pub estimate: Estimate,
    /// What the estimator can say about the run.
    pub diagnostics: Diagnostics,
}

/// What an estimator uses and needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Capabilities {
    /// It needs gyro rates in the telemetry.
    pub needs_gyro: bool,
    /// It keeps J in the constraint set.
    pub constraints: bool,
    /// It compensates errors-in-variables given the gyro noise density.
    pub compensation: bool,
    /// It has an uncertainty model.
    pub uncertainty: bool,
    /// It takes the row-model settings (rotation source, model of ρ, torque bias).
    pub row_model: bool,
    /// It differentiates low-pass-filtered signals (takes `filter_cutoff_hz`).
    pub filter: bool,
}

impl Capabilities {
    /// The fewest input samples for one estimate: two for an estimator of gyro rates alone
    /// (one momentum difference), else [`crate::estimator::MIN_SAMPLES`] (two 3-row blocks
    /// over three nodes).
    #[must_use]
    pub(crate) const fn min_samples(&self) -> usize {
        if self.needs_gyro && !self.constraints {
            2
        } else {
            crate::estimator::MIN_SAMPLES
        }
    }
}
