//! Where the discrete momentum estimator splits a row source's chains
//! ([`super::momentum_rows`], "Chains"): a chain that only grows too long is split by a
//! clock, not restarted, so that rows do not depend on the chain length.

use super::momentum_rows::MomentumRows;

/// Splits a row source's chains into chains no longer than
/// [`MomentumRowSettings::max_chain_s`] (module docs, "Chains").
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ChainClock {
    max_chain_s: Option<f64>,
    /// The source's epoch the current chain belongs to (`None` before the first row).
    source_epoch: Option<u64>,
    /// Start of the current chain, s.
    start_s: f64,
    /// Splits so far.
    splits: u64,
}

impl ChainClock {
    /// A clock for chains of at most `max_chain_s` (`None`: the source's chains whole).
    #[must_use]
    pub(crate) fn new(max_chain_s: Option<f64>) -> Self {
        Self {
            max_chain_s,
            source_epoch: None,
            start_s: 0.0,
            splits: 0,
        }
    }

    /// The epoch of the row `source` just gave: the source's restarts plus this clock's
    /// splits. A split falls at the start of the row's newest interval once the chain
    /// spans [`MomentumRowSettings::max_chain_s`] there (the first
    /// [`super::jackknife::MIN_GROUPS`] chains a quarter of it, so that the jackknife over
    /// chains has its groups early).
    pub(crate) fn epoch(&mut self, source: &MomentumRows) -> u64 {
        if self.source_epoch != Some(source.epoch()) {
            self.source_epoch = Some(source.epoch());
            self.start_s = source.chain_start_s();
        }
        let epoch = source.epoch() + self.splits;
        if let (Some(max), Some(b)) = (self.max_chain_s, source.interval_start_s()) {
            let early = super::jackknife::MIN_GROUPS as u64;
            let max = if epoch < early {
                max / early as f64
            } else {
                max
            };
            if b - self.start_s >= max {
                self.splits += 1;
                self.start_s = b;
            }
        }
        source.epoch() + self.splits
    }
}
