//! The candidate row models of the discrete momentum estimator: one per rotation source and
//! chain length that the settings leave open, each with its estimator settings; the
//! whole-record candidate's chained siblings (whose jackknife σ is its noise σ); the row
//! sources that candidates differing only in the chain length share; each candidate's
//! errors-in-variables density as the run estimates it (`refresh_gyro_noise`).

use crate::estimator::discrete_momentum::{DiscreteMomentumEstimator, MomentumEstimatorSettings};
use crate::estimator::momentum_rows::{
    MomentumRowSettings, MomentumRows, RhoModel, RotationSource, Stencil,
};
use crate::estimator::recursive::RecursiveSettings;
use crate::pipeline::config::{InertialTorque, PipelineConfig};
use crate::solver::Backend;
use std::boxed::Box;
use std::vec::Vec;

pub(super) type Candidate = DiscreteMomentumEstimator<Box<dyn Backend + Send>>;

/// The candidate row settings for a configuration, given whether the telemetry has gyro
/// rates.
pub(super) fn candidates(c: &PipelineConfig, has_gyro: bool) -> Vec<MomentumRowSettings> {
    let rotations: &[RotationSource] = match c.rotation_source {
        Some(RotationSource::Attitude) => &[RotationSource::Attitude],
        Some(RotationSource::Gyro) => &[RotationSource::Gyro],
        None if has_gyro => &[RotationSource::Gyro, RotationSource::Attitude],
        None => &[RotationSource::Attitude],
    };
    let stencils: &[Stencil] = match c.rho_model {
        RhoModel::Plain => &[Stencil::Plain],
        RhoModel::Held => &[Stencil::Held],
        RhoModel::Smooth => &[Stencil::Smooth],
        RhoModel::Auto => &[Stencil::Adaptive],
    };
    // Short chains, long ones, and the whole record as one chain: the data choose
    // ([`choose`]).
    let chains: Vec<Option<f64>> = match (c.pinned_chain_s, c.max_chain_s) {
        (Some(chain), _) => std::vec![chain],
        (None, Some(l)) => std::vec![
            Some(l / SHORT_CHAIN_DIVISOR),
            Some(l),
            Some(LONG_CHAIN_FACTOR * l),
            None
        ],
        (None, None) => std::vec![None],
    };
    let inertial: &[bool] = match c.inertial_torque {
        InertialTorque::Off => &[false],
        // Both while the record is short ([`InertialTorque::Short`]: the streaming
        // estimator rules the torque's out past it, the batch run leaves them out of a
        // longer record); unweighted fits only, as for `Auto`.
        InertialTorque::Short if c.memory_s.is_none() => &[false, true],
        InertialTorque::Short => &[false],
        InertialTorque::On => &[true],
        // Both, the test deciding at each solve ([`super::select::test_inertial_torque`]).
        InertialTorque::Auto => &[false, true],
    };
    let mut out = Vec::new();
    for max_chain_s in chains {
        for &rotation in rotations {
            for &stencil in stencils {
                for &inertial_torque in inertial {
                    out.push(MomentumRowSettings {
                        rotation,
                        stencil,
                        torque_bias: c.torque_bias,
                        inertial_torque,
                        damping: c.damping,
                        outside: c.outside,
                        max_chain_s,
                    });
                }
            }
        }
    }
    out
}

/// The long chain's length, in `--chain` lengths.
pub(super) const LONG_CHAIN_FACTOR: f64 = 4.0;

/// The short chain's length is `--chain` divided by this.
pub(super) const SHORT_CHAIN_DIVISOR: f64 = 4.0;

/// For a candidate that holds the whole record as one chain, the candidates with the
/// same rows in chains of at least `from_s` (the pipeline passes `--chain`: the shortest
/// chains, with four times the initial momenta, scatter far more than the whole record). One chain is one jackknife group, so the whole
/// record has no jackknife σ of its own; its noise σ is element by element the largest of
/// its least-squares σ and its chained siblings' jackknife σ ([`super::sigma::sibling_jackknife`]),
/// which see the correlated errors the least-squares σ does not. The chooser takes the
/// whole record only where the data cannot tell it from the chains; a chained estimate
/// has more nuisance unknowns in the same rows, so its σ bounds the whole record's from
/// above, and the difference of the answers joins the bias through the model spread.
/// Empty for a candidate with chains, and without chained candidates (`--chain 0`: every
/// candidate is one chain, and σ is its own).
pub(super) fn chained_siblings<'a>(
    rows: &'a MomentumRowSettings,
    all: impl Iterator<Item = &'a MomentumRowSettings> + 'a,
    from_s: f64,
) -> impl Iterator<Item = usize> + 'a {
    all.enumerate()
        .filter(move |(_, r)| is_chained_sibling(rows, r, from_s))
        .map(|(k, _)| k)
}

/// Whether `r` is a chained sibling of the whole-record candidate `rows`
/// ([`chained_siblings`]).
pub(super) fn is_chained_sibling(
    rows: &MomentumRowSettings,
    r: &MomentumRowSettings,
    from_s: f64,
) -> bool {
    rows.max_chain_s.is_none()
        && r.max_chain_s.is_some_and(|l| l >= from_s)
        && r.rows_only() == rows.rows_only()
}

pub(super) fn settings(c: &PipelineConfig, rows: MomentumRowSettings) -> MomentumEstimatorSettings {
    MomentumEstimatorSettings {
        rows,
        recursive: RecursiveSettings {
            solve_every: 1,
            observability: c.observability,
            memory_s: c.memory_s,
            gyro_noise_rad_s_rthz: c.gyro_noise_for(rows.rotation),
        },
    }
}

/// One row source and the candidates it feeds.
pub(super) struct SharedSource {
    pub(super) rows: MomentumRows,
    pub(super) members: Vec<usize>,
}

/// Group candidates by their row settings but for the longest chain (module docs of
/// [`crate::estimator::momentum_rows`], "Chains"): one source per group.
pub(super) fn shared_sources(candidates: &[MomentumRowSettings]) -> Vec<SharedSource> {
    let mut out: Vec<SharedSource> = Vec::new();
    for (i, r) in candidates.iter().enumerate() {
        let key = r.source_key();
        match out.iter_mut().find(|g| *g.rows.settings() == key) {
            Some(g) => g.members.push(i),
            None => out.push(SharedSource {
                rows: MomentumRows::new(key),
                members: std::vec![i],
            }),
        }
    }
    out
}

impl super::DiscreteMomentum {
    /// Where no gyro density is stated, the compensation's density from the rates so far
    /// ([`crate::estimator::rate_noise`]), for every candidate and the shadow, at each row
    /// block; kept while within [`super::DENSITY_REFRESH`] of the new estimate (the estimate moves
    /// with every sample; the answer with its square).
    pub(super) fn refresh_gyro_noise(&mut self) {
        let Some(r) = self.rate_noise.as_deref_mut() else {
            return;
        };
        let g = r.density_rad_s_rthz();
        let close = match (g, self.config.gyro_noise_rad_s_rthz) {
            (Some(a), Some(b)) => (a / b - 1.0).abs() <= super::DENSITY_REFRESH,
            (a, b) => a == b,
        };
        if close {
            return;
        }
        self.config.gyro_noise_rad_s_rthz = g;
        self.config.gyro_noise_estimated = g.is_some();
        let config = self.config;
        for c in self.candidates.iter_mut().chain(self.shadow.as_deref_mut()) {
            c.set_gyro_noise(config.gyro_noise_for(c.row_settings().rotation));
        }
    }
}
