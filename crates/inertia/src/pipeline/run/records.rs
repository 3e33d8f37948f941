//! Several records of one spacecraft in one batch run ([`Run::next_record`]): files of
//! separate passes or throws whose J is the same, each with its own initial momenta and
//! disturbances.
//!
//! The run lays the records end to end on one time axis: each later record's times are
//! shifted so that its first sample follows the previous record's last by a gap of
//! [`GAP_STEPS`] of that record's last step (at least [`MIN_GAP_S`]), at which every check
//! and time tag restarts ([`crate::sample::is_gap`]). The batch reduction restarts its rows
//! at each record's first sample, so no row spans two records: each record has its own
//! chains, hence its own initial momenta and inertial torque. The answer's time is the
//! last record's own. The batch reduction gives each record its own body-frame torque and,
//! with four records or more, deletes whole records in its jackknife as well as chains,
//! keeping the larger σ ([`crate::estimator::discrete_momentum`]).

use super::{Mode, Run, RunError, RunErrorKind};
use crate::sample::Sample;
use std::vec::Vec;

/// The gap between two records, in steps of the earlier record's last step.
pub(crate) const GAP_STEPS: f64 = 1000.0;
/// The shortest gap between two records, s.
pub(crate) const MIN_GAP_S: f64 = 1.0;

/// Where the records start and how the current one's times are shifted.
#[derive(Debug, Clone, Default)]
pub(super) struct Records {
    /// The index of each later record's first sample.
    pub(super) starts: Vec<usize>,
    /// Added to the current record's times, s.
    offset_s: f64,
    /// A record begun and not yet given a sample.
    pending: bool,
    /// The last accepted sample's (shifted) time and the step before it, s.
    last_t_s: Option<f64>,
    last_step_s: f64,
}

impl Records {
    /// `s` on the run's time axis (shifted into the current record's place).
    pub(super) fn shifted(&self, s: &Sample) -> Sample {
        let offset = match (self.pending, self.last_t_s) {
            (true, Some(last)) => last + (GAP_STEPS * self.last_step_s).max(MIN_GAP_S) - s.t_s,
            _ => self.offset_s,
        };
        Sample {
            t_s: s.t_s + offset,
            ..*s
        }
    }

    /// `s` (as [`Self::shifted`] gave it, from input sample `t_in_s`) was accepted.
    pub(super) fn accepted(&mut self, s: &Sample, t_in_s: f64) {
        if self.pending {
            self.offset_s = s.t_s - t_in_s;
            self.pending = false;
        } else if let Some(last) = self.last_t_s {
            self.last_step_s = s.t_s - last;
        }
        self.last_t_s = Some(s.t_s);
    }

    /// Number of records.
    #[must_use]
    pub(super) fn count(&self) -> usize {
        self.starts.len() + 1
    }

    /// Added to the current (last) record's times, s.
    #[must_use]
    pub(super) fn offset_s(&self) -> f64 {
        self.offset_s
    }

    /// A record begun and never given a sample, at the end of the input.
    #[must_use]
    pub(super) fn empty_last(&self) -> Option<RunError> {
        self.pending.then(|| RunError {
            sample: None,
            kind: RunErrorKind::EmptyRecord {
                record: self.count(),
            },
        })
    }
}

impl Run {
    /// End the current record and begin the next, of the same spacecraft: the samples
    /// pushed from now on are another pass or throw, whose J is this one's, with its own
    /// initial momenta and disturbance torques and its own time axis (it may start at
    /// zero again). The run lays the records end to end, each after a gap of 1000 of the
    /// previous record's last steps (at least 1 s), at which every row and check restarts;
    /// the batch solve gives each record its own body-frame torque and, with four records
    /// or more, deletes whole records in its jackknife too. Batch runs of an estimator
    /// with the discrete momentum rows only ([`Self::check_records`]); a record must have
    /// a sample.
    pub fn next_record(&mut self) -> Result<(), RunError> {
        self.check_records()?;
        let whole = |kind| RunError { sample: None, kind };
        let start = self.input;
        if self.records.pending || self.records.starts.last().copied().unwrap_or(0) == start {
            return Err(whole(RunErrorKind::EmptyRecord {
                record: self.records.count(),
            }));
        }
        self.records.starts.push(start);
        self.records.pending = true;
        Ok(())
    }

    /// Whether this run can take several records ([`Self::next_record`]): a front end that
    /// knows it has several checks before it reads the first.
    pub fn check_records(&self) -> Result<(), RunError> {
        let whole = |kind| RunError { sample: None, kind };
        if !matches!(self.mode, Mode::Batch { .. }) {
            return Err(whole(RunErrorKind::RecordsNeedBatch));
        }
        let entry = self.config.estimator();
        if !entry.capabilities.row_model {
            return Err(whole(RunErrorKind::RecordsNeedRows {
                estimator: entry.name,
            }));
        }
        if self.config.calibrate_rotors {
            return Err(whole(RunErrorKind::RecordsWithCalibration));
        }
        Ok(())
    }

    /// Number of records so far ([`Self::next_record`]).
    #[must_use]
    pub fn records(&self) -> usize {
        self.records.count()
    }
}
