//! The attitude drift weighting's replay: rows folded before the first answer cannot be
//! weighted for the drift (the weights need `Ĵ`), so the samples are kept until then and the
//! run is refolded from its first sample with the weights; the unweighted run goes on
//! beside it, and its answer is given where its bias outweighs its noise
//! ([`unweighted_is_better`]).

use super::sigma::frobenius;
use super::DiscreteMomentum;
use crate::estimator::attitude_drift::AttitudeDrift;
use crate::estimator::{Estimate, EstimatorError};
use crate::sample::Sample;
use std::boxed::Box;

/// Whether the unweighted rows' answer `e` is to be given rather than the rows
/// weighted for an attitude drift: where its bias σ (discretisation and model spread)
/// exceeds its noise σ (Frobenius norms). The weighting whitens a random walk, which
/// brings out what the rows' errors have in common from one interval to the next: the
/// discretisation bias of long steps. Measured on the README's matrix with the
/// densities given, the weighted rows lower the error of every 10 Hz spin by 20–24 %
/// and raise it 1.6–2.9× at 1 Hz (paper and FOG gyro), where this test keeps the
/// unweighted answer; the σ of the two answers ranks them the wrong way round in both.
/// Without a σ to tell (none at this solve), the unweighted answer.
pub(super) fn unweighted_is_better(e: &Estimate) -> bool {
    e.uncertainty
        .is_none_or(|u| frobenius(&u.bias_kg_m2) > frobenius(&u.noise_kg_m2))
}

/// Most samples kept for the drift weighting's replay (an hour at 10 Hz, 4.3 MB): with
/// no answer by then, the rows are not weighted at all (weighting only the rows after
/// the first answer is worse than none).
pub(super) const REPLAY_CAP: usize = 36_000;

impl DiscreteMomentum {
    /// The state whose answer was given at the last solve (the unweighted twin's where
    /// [`unweighted_is_better`]), for the diagnostics of the report.
    pub(super) fn given(&self) -> &Self {
        match &self.unweighted {
            Some((twin, true)) => twin,
            _ => self,
        }
    }

    /// The run so far refolded from its first sample with the rows weighted for `drift`
    /// (the first answer's `Ĵ`), and its answer at the last sample: rows folded before
    /// an estimate of `J` exists cannot be weighted, and left unweighted beside weighted
    /// ones they cost more than the weighting gains (README, "Weighting").
    pub(super) fn replayed(
        &self,
        samples: &[Sample],
        drift: AttitudeDrift,
    ) -> Result<(Self, Option<Estimate>), EstimatorError> {
        let mut fresh = Self {
            replay: None,
            drift: Some(drift),
            ..Self::empty(&self.config)
        };
        fresh.rule_out_after = self.rule_out_after;
        let mut last = None;
        for s in samples {
            last = fresh.push_sample(s)?;
        }
        Ok((fresh, last))
    }

    /// Weigh every candidate's (and the shadow's) rows for `drift` from now on.
    pub(super) fn set_drift(&mut self, drift: Option<AttitudeDrift>) {
        self.drift = drift;
        for c in &mut self.candidates {
            c.set_drift(drift);
        }
        if let Some(shadow) = self.shadow.as_deref_mut() {
            shadow.set_drift(drift);
        }
    }

    /// Keep sample `s` for the replay while the first answer is awaited, up to
    /// [`REPLAY_CAP`] samples.
    pub(super) fn keep_for_replay(&mut self, s: &Sample) {
        if let Some(buffer) = self.replay.as_mut() {
            if buffer.len() < REPLAY_CAP {
                buffer.push(*s);
            } else {
                self.replay = None;
            }
        }
    }

    /// The answer to give, from this run's answer `e` and the unweighted twin's `twin` at
    /// the same sample: at the first answer, with a drift to weight for, the run is
    /// replayed with the rows weighted ([`Self::replayed`]) and goes on as the unweighted
    /// twin; later answers update the weights ([`Self::set_drift`]); the twin's answer is
    /// given where [`unweighted_is_better`].
    pub(super) fn weigh_for_drift(
        &mut self,
        e: Option<Estimate>,
        twin: Option<Estimate>,
    ) -> Option<Estimate> {
        let (mut e, mut twin) = (e, twin);
        let drift = match (
            self.config.attitude_drift_deg_rth,
            self.config.gyro_noise_rad_s_rthz,
            e.as_ref().and_then(Estimate::j),
        ) {
            (Some(a), Some(g), Some(j)) => AttitudeDrift::new(a, g.to_degrees(), j),
            _ => None,
        };
        if let Some(d) = drift {
            if self.unweighted.is_some() {
                // Weighted already: the latest answer's Ĵ for the rows to come.
                self.set_drift(Some(d));
            } else if let Some(samples) = self.replay.take() {
                // The first answer: the run refolded from its first sample with the
                // rows weighted, the run so far going on unweighted beside it. Should
                // the refold fail where the unweighted run did not, the run stays
                // unweighted.
                if let Ok((fresh, last)) = self.replayed(&samples, d) {
                    let old = core::mem::replace(self, fresh);
                    self.unweighted = Some((Box::new(old), false));
                    (e, twin) = (last, e);
                }
            }
            // Past [`REPLAY_CAP`] samples before the first answer the rows stay
            // unweighted: weighting only the rows to come is worse than none.
        }
        // The unweighted answer where its discretisation and model bias outweigh its
        // noise ([`unweighted_is_better`]).
        if let (Some((_, twin_given)), Some(t)) = (self.unweighted.as_mut(), twin) {
            let take_twin = unweighted_is_better(&t);
            *twin_given = take_twin;
            if take_twin {
                e = Some(t);
            }
        }
        e
    }
}
