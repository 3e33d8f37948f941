//! The current estimate as C reads it: status, reason, J, σ and the prior's diagnostics.

use crate::estimator::InertiaEstimator;
use inertia::estimator::observability::{Observability, Unobservable};
use inertia::tensor::matrix_from_j;

/// How an estimate stands.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaEstimateStatus {
    /// No estimate yet (too few samples).
    None = 0,
    /// The data determine J.
    Determined = 1,
    /// The data leave a direction open that the bounds pin: an answer, leaning on them.
    FromPrior = 2,
    /// The data do not determine J: no answer (see the reason).
    NotObservable = 3,
    /// An answer with no observability test (the momentum baseline), or without a σ.
    Unchecked = 4,
    /// An answer with its σ that a model check refutes (it is not a physical inertia
    /// beyond 3σ; see the reason): shown, not promised.
    ModelCheckFailed = 5,
}

/// Why an estimate is not `DETERMINED` (the library's `Unobservable`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaReason {
    /// No reason: determined, unchecked, or no estimate yet.
    None = 0,
    /// No rotor momentum or known torque has excited the motion.
    NoExcitation = 1,
    /// Fewer than six independent rows.
    RankDeficient = 2,
    /// The rows explain too little (relative σ of J over the threshold).
    Uncertain = 3,
    /// The gyro noise outweighs the excitation (compensated information not definite).
    NoiseDominated = 4,
    /// The estimate is not finite.
    Diverged = 5,
    /// The answer rests on the J ⪰ εI floor.
    AtFloor = 6,
    /// The constraints moved the answer further than the noise allows.
    ConflictsWithConstraints = 7,
    /// The rotation from the attitude and from the gyro give different answers.
    SourcesDisagree = 8,
    /// A span of the record has residuals far larger than the rest.
    Inconsistent = 9,
    /// The residuals are smaller than the stated gyro density implies.
    DensityOverstated = 10,
    /// The rows are ill-conditioned.
    IllConditioned = 11,
    /// A reason this version of the header does not name.
    Other = 12,
    /// The data contradict the Gaussian prior (`prior_chi2` above its threshold).
    PriorConflict = 13,
    /// Not a physical inertia: the momentum baseline's unconstrained J (no answer), or a
    /// constrained answer beyond 3σ of the physical set (`MODEL_CHECK_FAILED`).
    NotPhysical = 14,
}

/// The current estimate.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaEstimate {
    /// Status of the estimate.
    pub status: InertiaEstimateStatus,
    /// Why it is not determined (`INERTIA_REASON_NONE` when it is).
    pub reason: InertiaReason,
    /// Non-zero when `j` and `inertia` hold an answer (otherwise NaN).
    pub has_answer: u8,
    /// Non-zero when `sigma` holds standard deviations (otherwise NaN).
    pub has_sigma: u8,
    /// Time of the newest sample used, s (NaN before the first estimate).
    pub t_s: f64,
    /// `[J11, J22, J33, J12, J13, J23]`, kg m².
    pub j: [f64; 6],
    /// J as a row-major 3×3 matrix, kg m².
    pub inertia: [[f64; 3]; 3],
    /// Standard deviation per element of `j`, kg m².
    pub sigma: [f64; 6],
    /// σ₁/σ₆ of the least-squares state when determined (otherwise NaN).
    pub condition: f64,
    /// Scalar rows used.
    pub rows: u64,
    /// Samples pushed since creation or the last reset.
    pub samples: u64,
    /// With a Gaussian prior: the fraction of the information on each element from the
    /// data (the rest from the prior); NaN without a prior or for a fixed element.
    pub prior_data_share: [f64; 6],
    /// With a Gaussian prior: the prior-data disagreement χ² (NaN without a prior).
    pub prior_chi2: f64,
}

impl InertiaEstimator {
    pub(crate) fn estimate(&self) -> InertiaEstimate {
        let nan = f64::NAN;
        let mut out = InertiaEstimate {
            status: InertiaEstimateStatus::None,
            reason: InertiaReason::None,
            has_answer: 0,
            has_sigma: 0,
            t_s: nan,
            j: [nan; 6],
            inertia: [[nan; 3]; 3],
            sigma: [nan; 6],
            condition: nan,
            rows: 0,
            samples: self.samples,
            prior_data_share: [nan; 6],
            prior_chi2: nan,
        };
        let Some(e) = self.last else { return out };
        out.t_s = e.t_s;
        out.rows = e.rows as u64;
        out.status = match e.observability {
            Observability::Determined { .. } => InertiaEstimateStatus::Determined,
            Observability::FromPrior(_) => InertiaEstimateStatus::FromPrior,
            Observability::NotObservable(_) => InertiaEstimateStatus::NotObservable,
            Observability::ModelCheckFailed(_) => InertiaEstimateStatus::ModelCheckFailed,
            _ => InertiaEstimateStatus::Unchecked,
        };
        out.reason = e.observability.reason().map_or(InertiaReason::None, reason);
        if let Some(c) = e.observability.condition() {
            out.condition = c;
        }
        if let Some(j) = e.j() {
            out.has_answer = 1;
            out.j = core::array::from_fn(|k| j[k]);
            let m = matrix_from_j(&j);
            out.inertia = core::array::from_fn(|r| core::array::from_fn(|c| m[(r, c)]));
        }
        if let Some(s) = e.sigma_kg_m2() {
            out.has_sigma = 1;
            out.sigma = s;
        }
        if let Some(p) = e.prior {
            out.prior_chi2 = p.chi2;
            out.prior_data_share = p.data_share.map(|d| d.unwrap_or(f64::NAN));
        }
        out
    }
}

fn reason(r: Unobservable) -> InertiaReason {
    match r {
        Unobservable::NoExcitation => InertiaReason::NoExcitation,
        Unobservable::RankDeficient { .. } => InertiaReason::RankDeficient,
        Unobservable::Uncertain { .. } => InertiaReason::Uncertain,
        Unobservable::NoiseDominated => InertiaReason::NoiseDominated,
        Unobservable::Diverged => InertiaReason::Diverged,
        Unobservable::AtFloor { .. } => InertiaReason::AtFloor,
        Unobservable::ConflictsWithConstraints { .. } => InertiaReason::ConflictsWithConstraints,
        Unobservable::SourcesDisagree { .. } => InertiaReason::SourcesDisagree,
        Unobservable::Inconsistent { .. } => InertiaReason::Inconsistent,
        Unobservable::DensityOverstated { .. } => InertiaReason::DensityOverstated,
        Unobservable::IllConditioned { .. } => InertiaReason::IllConditioned,
        Unobservable::PriorConflict { .. } => InertiaReason::PriorConflict,
        Unobservable::NotPhysical { .. } | Unobservable::Unphysical { .. } => {
            InertiaReason::NotPhysical
        }
        _ => InertiaReason::Other,
    }
}
