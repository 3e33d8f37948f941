//! The momentum-based recursive least-squares baseline (Norman, Peck & O'Shaughnessy
//! 2011, inertia part; paper §VI).
//!
//! Inertial angular momentum is conserved up to the known external torque:
//!
//! ```text
//! C(q_k) (J ω_k + ρ_k) − h_N = ∫_0^{t_k} C(q) τ dt
//! ⇒ [C(q_k) G(ω_k), −I] [j; h_N] = ∫_0^{t_k} C(q) τ dt − C(q_k) ρ_k
//! ```
//!
//! with unknowns `j` and the initial inertial momentum `h_N`, the node rate `ω_k` the mean
//! of the gyro rates of the two adjacent intervals, and the torque integral by the
//! trapezoid rule. Standard covariance-form RLS from `x = 0` with a large initial
//! covariance `P_0 = p0 I`, optional forgetting, no constraints.

use crate::attitude::Quaternion;
use crate::discrete::g_matrix;
use crate::telemetry::Sample;
use crate::tensor::{matrix_from_j, InertiaVector};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Initial covariance scale (default 1e6; units of the unknowns squared).
pub const DEFAULT_P0: f64 = 1e6;

/// The RLS state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MomentumRls {
    x: SVector<f64, 9>,
    p: SMatrix<f64, 9, 9>,
    forgetting: f64,
    prev: Option<Sample>,
    prev_rate: Option<Vector3<f64>>,
    torque_integral: Vector3<f64>,
    samples: usize,
}

impl Default for MomentumRls {
    fn default() -> Self {
        Self::new(DEFAULT_P0, 1.0)
    }
}

impl MomentumRls {
    /// A new estimator with `P_0 = p0 I` and forgetting factor `forgetting` (1: none).
    #[must_use]
    pub fn new(p0: f64, forgetting: f64) -> Self {
        Self {
            x: SVector::zeros(),
            p: SMatrix::identity() * p0,
            forgetting,
            prev: None,
            prev_rate: None,
            torque_integral: Vector3::zeros(),
            samples: 0,
        }
    }

    /// Feed a sample; returns the current `j` once a row has been used.
    ///
    /// The row at node k needs the gyro rate of interval k−1, so the first sample only
    /// primes the state.
    pub fn push(&mut self, s: &Sample) -> Option<InertiaVector> {
        self.samples += 1;
        let c = s.q.to_matrix();
        let out = if let (Some(prev), Some(prev_rate)) = (self.prev, self.prev_rate) {
            let dt = s.t_s - prev.t_s;
            self.torque_integral += 0.5 * dt * (rotate(&prev.q, &prev.tau_nm) + c * s.tau_nm);
            let w = 0.5 * (prev_rate + s.omega_rad_s);
            let mut a = SMatrix::<f64, 3, 9>::zeros();
            a.fixed_view_mut::<3, 6>(0, 0)
                .copy_from(&(c * g_matrix(&w)));
            a.fixed_view_mut::<3, 3>(0, 6)
                .copy_from(&(-Matrix3::identity()));
            let b = self.torque_integral - c * s.rho_nms;
            self.update(&a, &b);
            Some(self.j())
        } else {
            None
        };
        self.prev = Some(*s);
        self.prev_rate = Some(s.omega_rad_s);
        out
    }

    fn update(&mut self, a: &SMatrix<f64, 3, 9>, b: &Vector3<f64>) {
        let pa = self.p * a.transpose();
        let s = Matrix3::identity() * self.forgetting + a * pa;
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        let k = pa * s_inv;
        self.x += k * (b - a * self.x);
        self.p = (self.p - k * a * self.p) / self.forgetting;
        self.p = (self.p + self.p.transpose()) * 0.5;
    }

    /// Current `j`.
    #[must_use]
    pub fn j(&self) -> InertiaVector {
        InertiaVector::from_fn(|i, _| self.x[i])
    }

    /// Current J, kg m².
    #[must_use]
    pub fn inertia(&self) -> Matrix3<f64> {
        matrix_from_j(&self.j())
    }

    /// Row blocks used so far.
    #[must_use]
    pub fn updates(&self) -> usize {
        self.samples.saturating_sub(1)
    }

    /// Estimated initial inertial momentum `h_N`, N m s.
    #[must_use]
    pub fn initial_momentum(&self) -> Vector3<f64> {
        Vector3::new(self.x[6], self.x[7], self.x[8])
    }
}

fn rotate(q: &Quaternion, v: &Vector3<f64>) -> Vector3<f64> {
    q.rotate(v)
}
