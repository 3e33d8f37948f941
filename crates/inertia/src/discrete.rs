//! Discrete variational gyrostat rows, paper eqs. 46–54 with the corrections of docs/conventions.md §1–§2.
//!
//! For nodes `k, k+1, k+2` with attitudes `q`, the forced discrete gyrostat equation
//! (eq. 46, torque sign per docs/conventions.md §1) is linear in `j` (eq. 48):
//!
//! ```text
//! N(φ_{k+1}) (G(φ_{k+1}) j + h/2 ρ̄_{k+1}) − M(φ_k) (G(φ_k) j + h/2 ρ̄_k) = + h²/2 τ_{k+1}
//! H_k = N(φ_{k+1}) G(φ_{k+1}) − M(φ_k) G(φ_k)                                  (eq. 53)
//! y_k = M(φ_k) h/2 ρ̄_k − N(φ_{k+1}) h/2 ρ̄_{k+1} + h²/2 τ_{k+1}                (eq. 54, corrected)
//! ```
//!
//! * `φ_k = vec(q_k† q_{k+1})` belongs to the interval `[t_k, t_{k+1}]` (docs/conventions.md §2).
//! * `ρ̄_k` is the rotor momentum of that interval: the trapezoid `(ρ(t_k) + ρ(t_{k+1}))/2`
//!   of node samples keeps the residual `H_k j − y_k` of an exact trajectory `O(h⁴)`.
//! * `τ_{k+1}` is the known external torque at the shared node `t_{k+1}`.
//! * The printed eq. 54 has `− h²/2 τ_{k+1}`; that sign makes the residual `O(h²)`. The
//!   tests in `tests/integration/discrete_convergence.rs` measure both orders.
//!
//! # Unequal steps
//!
//! With intervals `h₀ = t_{k+1} − t_k` and `h₁ = t_{k+2} − t_{k+1}`, the discrete
//! Euler–Lagrange equation at the shared node combines each interval's discrete Lagrangian
//! `(2/h) φᵀJφ + …` with its own `1/h`. Multiplied by `h̄ = (h₀ + h₁)/2` so that it
//! reduces to eqs. 53–54 when `h₀ = h₁`:
//!
//! ```text
//! H_k = (h̄/h₁) N(φ₁) G(φ₁) − (h̄/h₀) M(φ₀) G(φ₀)
//! y_k = (h̄/2) (M(φ₀) ρ̄₀ − N(φ₁) ρ̄₁) + (h̄²/2) τ_{k+1}
//! ```
//!
//! Its continuum limit is `((h₀ + h₁)/4)(L̇ + ω × L − τ) = 0`, i.e. eq. 26; the residual
//! on a ±20 % jittered grid is measured in `tests/integration/discrete_convergence.rs`.
//!
//! Units: `h` in s, `ρ` in N m s, `τ` in N m, `j` in kg m²; `H_k` has units of rad
//! (dimensionless) squared and `y_k` of N m s².

use crate::attitude::{incremental_rotation, skew, Quaternion};
use crate::math::{abs, sqrt};
use crate::sample::Sample;
use nalgebra::{Matrix3, Matrix3x6, Vector3};

/// Largest accepted `|φ|`. `|φ| = sin(θ/2)` for a step rotation θ, so `|φ| → 1` as the
/// step approaches 180°, where eq. 37 breaks down and the direction of rotation becomes
/// ambiguous. 0.99 is a step of about 164°.
pub(crate) const MAX_PHI_NORM: f64 = 0.99;

/// Tolerance on `| |q| − 1 |` for attitude quaternions handed to the row builder.
/// Telemetry readers renormalise within their own documented tolerance first.
pub(crate) const UNIT_NORM_TOLERANCE: f64 = 1e-9;

/// Why a row could not be formed.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum RowError {
    /// A quaternion is not unit length (or not finite).
    #[error(
        "attitude quaternion at node {node} has norm {norm} (needs 1 ± {UNIT_NORM_TOLERANCE:e})"
    )]
    NonUnitQuaternion {
        /// Which of the three nodes (0, 1 or 2 relative to k).
        node: usize,
        /// Its norm.
        norm: f64,
    },
    /// The rotation over one step is too large for eq. 37 (`|φ| < 1`).
    #[error("the rotation over the step from t = {} s to t = {} s gives |φ| = {phi_norm:.6} ≥ {MAX_PHI_NORM} (a step of {angle_deg:.1}°): the sample period is too long for the motion", crate::text::Num(*.t0_s), crate::text::Num(*.t1_s))]
    StepTooLarge {
        /// Start of the step, s.
        t0_s: f64,
        /// End of the step, s.
        t1_s: f64,
        /// `|φ|`.
        phi_norm: f64,
        /// The step rotation angle, degrees.
        angle_deg: f64,
    },
    /// The row needs gyro rates and the sample has none.
    #[error("this row model needs gyro rates (w_x, w_y, w_z) and the sample has none")]
    MissingGyroRate,
    /// A non-finite rotor momentum, torque or step.
    #[error("non-finite input: {what}")]
    NonFinite {
        /// Which input.
        what: &'static str,
    },
}

/// `G(φ)` of eq. 47: `J φ = G(φ) j`.
#[must_use]
#[inline]
pub(crate) fn g_matrix(phi: &Vector3<f64>) -> Matrix3x6<f64> {
    let (a, b, c) = (phi.x, phi.y, phi.z);
    Matrix3x6::new(
        a, 0.0, 0.0, b, c, 0.0, //
        0.0, b, 0.0, a, 0.0, c, //
        0.0, 0.0, c, 0.0, a, b,
    )
}

/// `√(1 − φ·φ)`, the scalar part of `f` in eq. 37.
#[must_use]
#[inline]
pub(crate) fn phi_scalar(phi: &Vector3<f64>) -> f64 {
    sqrt((1.0 - phi.norm_squared()).max(0.0))
}

/// `M(φ) = √(1 − φ·φ) I − S(φ)` (eq. 50).
#[must_use]
#[inline]
pub(crate) fn m_matrix(phi: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::identity() * phi_scalar(phi) - skew(phi)
}

/// `N(φ) = √(1 − φ·φ) I + S(φ)` (eq. 51).
#[must_use]
#[inline]
pub(crate) fn n_matrix(phi: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::identity() * phi_scalar(phi) + skew(phi)
}

/// One 3-row block `H_k j = y_k` (eq. 52).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// `H_k` (3×6).
    pub h: Matrix3x6<f64>,
    /// `y_k` (3).
    pub y: Vector3<f64>,
    /// Errors-in-variables coefficient, s: white gyro noise of density σ (rad/s/√Hz)
    /// perturbs each φ by `δφ ≈ n/2` with per-axis variance `σ² h/4`, so to first order
    /// it adds `σ² · noise_s · D`, `D = diag(1, 1, 1, 2, 2, 2)`, to `E[H_kᵀ H_k]`;
    /// `noise_s = (h̄²/h₀ + h̄²/h₁)/4` (`h/2` for equal steps). Zero for rows whose noise
    /// is not modelled.
    pub noise_s: f64,
}

/// The inputs of one row once incremental rotations are known.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RowInput {
    /// Time of node k, s (names the steps in errors).
    pub t_k_s: f64,
    /// `φ_k`, the incremental rotation of interval `[t_k, t_{k+1}]`.
    pub phi_k: Vector3<f64>,
    /// `φ_{k+1}`, of interval `[t_{k+1}, t_{k+2}]`.
    pub phi_k1: Vector3<f64>,
    /// `ρ̄_k`, rotor momentum of interval k (trapezoid of node values), N m s.
    pub rho_k_nms: Vector3<f64>,
    /// `ρ̄_{k+1}`, rotor momentum of interval k+1, N m s.
    pub rho_k1_nms: Vector3<f64>,
    /// `τ_{k+1}`, known external torque at node k+1, N m.
    pub tau_k1_nm: Vector3<f64>,
    /// Length of interval k, `h₀`, s.
    pub h_s: f64,
    /// Length of interval k+1, `h₁`, s (equal to `h_s` for uniform sampling).
    pub h1_s: f64,
}

/// Check the incremental rotation of the step `[t0_s, t1_s]` against [`MAX_PHI_NORM`].
pub(crate) fn check_phi(phi: &Vector3<f64>, t0_s: f64, t1_s: f64) -> Result<(), RowError> {
    let n = phi.norm();
    if !n.is_finite() {
        return Err(RowError::NonFinite {
            what: "incremental rotation",
        });
    }
    if n >= MAX_PHI_NORM {
        let angle_deg = 2.0 * libm::asin(n.min(1.0)) * 180.0 / core::f64::consts::PI;
        return Err(RowError::StepTooLarge {
            t0_s,
            t1_s,
            phi_norm: n,
            angle_deg,
        });
    }
    Ok(())
}

/// Check that a quaternion is unit to [`UNIT_NORM_TOLERANCE`].
pub(crate) fn check_unit(q: &Quaternion, node: usize) -> Result<(), RowError> {
    let norm = q.norm();
    if !norm.is_finite() || abs(norm - 1.0) > UNIT_NORM_TOLERANCE {
        return Err(RowError::NonUnitQuaternion { node, norm });
    }
    Ok(())
}

impl RowInput {
    /// Build the input from attitudes at nodes k, k+1, k+2, rotor momentum **node samples**
    /// at the same nodes (averaged to interval values by the trapezoid rule, docs/conventions.md §2),
    /// the known torque at node k+1, and the two interval lengths.
    pub(crate) fn from_nodes(
        t_k_s: f64,
        q: [&Quaternion; 3],
        rho_nodes_nms: [&Vector3<f64>; 3],
        tau_k1_nm: &Vector3<f64>,
        h_s: f64,
        h1_s: f64,
    ) -> Result<Self, RowError> {
        for (node, qi) in q.iter().enumerate() {
            check_unit(qi, node)?;
        }
        Ok(RowInput {
            t_k_s,
            phi_k: incremental_rotation(q[0], q[1]),
            phi_k1: incremental_rotation(q[1], q[2]),
            rho_k_nms: 0.5 * (rho_nodes_nms[0] + rho_nodes_nms[1]),
            rho_k1_nms: 0.5 * (rho_nodes_nms[1] + rho_nodes_nms[2]),
            tau_k1_nm: *tau_k1_nm,
            h_s,
            h1_s,
        })
    }

    /// Build the input from three consecutive telemetry samples (nodes k, k+1, k+2); the
    /// two intervals may differ.
    pub fn from_samples(s: [&Sample; 3]) -> Result<Self, RowError> {
        let h0 = s[1].t_s - s[0].t_s;
        let h1 = s[2].t_s - s[1].t_s;
        if !(h0.is_finite() && h1.is_finite() && h0 > 0.0 && h1 > 0.0) {
            return Err(RowError::NonFinite {
                what: "sample period",
            });
        }
        Self::from_nodes(
            s[0].t_s,
            [&s[0].q, &s[1].q, &s[2].q],
            [&s[0].rho_nms, &s[1].rho_nms, &s[2].rho_nms],
            &s[1].tau_nm,
            h0,
            h1,
        )
    }

    /// The row `H_k`, `y_k` (eqs. 53 and 54, torque sign per docs/conventions.md §1).
    pub fn row(&self) -> Result<Row, RowError> {
        let (t1, t2) = (self.t_k_s + self.h_s, self.t_k_s + self.h_s + self.h1_s);
        check_phi(&self.phi_k, self.t_k_s, t1)?;
        check_phi(&self.phi_k1, t1, t2)?;
        self.row_checked_phi()
    }

    /// [`Self::row`] for incremental rotations already checked by the caller (the row
    /// sources check each φ once, when its interval arrives).
    pub(crate) fn row_checked_phi(&self) -> Result<Row, RowError> {
        if !(self.h_s.is_finite() && self.h_s > 0.0 && self.h1_s.is_finite() && self.h1_s > 0.0) {
            return Err(RowError::NonFinite {
                what: "sample period",
            });
        }
        let finite = |v: &Vector3<f64>| v.iter().all(|c| c.is_finite());
        if !finite(&self.rho_k_nms) || !finite(&self.rho_k1_nms) {
            return Err(RowError::NonFinite {
                what: "rotor momentum",
            });
        }
        if !finite(&self.tau_k1_nm) {
            return Err(RowError::NonFinite {
                what: "known torque",
            });
        }
        let m = m_matrix(&self.phi_k);
        let n = n_matrix(&self.phi_k1);
        let hbar = 0.5 * (self.h_s + self.h1_s);
        let (w0, w1) = (hbar / self.h_s, hbar / self.h1_s);
        let h = n * g_matrix(&self.phi_k1) * w1 - m * g_matrix(&self.phi_k) * w0;
        let y = (m * self.rho_k_nms - n * self.rho_k1_nms) * (0.5 * hbar)
            + self.tau_k1_nm * (0.5 * hbar * hbar);
        let noise_s = 0.25 * hbar * hbar * (1.0 / self.h_s + 1.0 / self.h1_s);
        Ok(Row { h, y, noise_s })
    }
}
