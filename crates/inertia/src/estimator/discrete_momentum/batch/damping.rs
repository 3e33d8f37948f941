//! The damping `D` in the batch reduction (`estimator/unknowns.rs`, block `Damping`):
//! its row of the shared factor, for `D` at the answer's `j`, and the reduced states
//! with `D` held at zero, the model without the drag that joins the model spread.

use crate::estimator::qr::RecursiveQr;
use crate::tensor::InertiaVector;
use nalgebra::{DMatrix, Vector6};

/// The damping's row of an upper-triangular factor over the shared unknowns, `j` last:
/// `r_dd D + r_dj·j = z_d` once the unknowns after it are fixed, and its least-squares σ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DampingRow {
    pub(super) r_dd: f64,
    pub(super) r_dj: Vector6<f64>,
    pub(super) z_d: f64,
    pub(super) sigma_nms: Option<f64>,
}

impl DampingRow {
    /// `D` at `j` with its σ (the unknowns between `D` and `j` are none: `D` is the last
    /// before `j`, [`crate::estimator::unknowns::Block::ALL`]).
    #[must_use]
    pub(crate) fn at(&self, j: &InertiaVector) -> (f64, Option<f64>) {
        ((self.z_d - self.r_dj.dot(j)) / self.r_dd, self.sigma_nms)
    }
}

/// The reduced states with the damping `D` held at zero instead of estimated: the answers
/// of the model without the drag, alternatives for the model spread
/// ([`crate::estimator::qr::RecursiveQr::holding_at_zero`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct WithoutDamping {
    /// With the disturbance torque free ([`super::BatchReduction::qr`]).
    pub(crate) torque_free: RecursiveQr,
    /// With the disturbance torque held at zero as well
    /// ([`super::BatchReduction::without_torque`]); `None` where the torque is not estimated.
    pub(crate) torque_held: Option<RecursiveQr>,
}

impl WithoutDamping {
    /// The state that matches the torque test's outcome (`torque_held`: it held the torque
    /// at zero).
    #[must_use]
    pub(crate) fn for_torque(&self, torque_held: bool) -> Option<&RecursiveQr> {
        if torque_held {
            self.torque_held.as_ref()
        } else {
            Some(&self.torque_free)
        }
    }
}

/// `qr` with the damping held at zero, from the damping's row `(r_dd, r_dj, z_d, _)` of
/// the same factor; `None` where the rows do not use `D`.
pub(super) fn without_damping(
    qr: &RecursiveQr,
    (r_dd, r_dj, z_d, _): &(f64, Vector6<f64>, f64, DMatrix<f64>),
) -> Option<RecursiveQr> {
    (*r_dd != 0.0).then(|| qr.holding_at_zero(r_dj, *z_d))
}
