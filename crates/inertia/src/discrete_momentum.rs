//! The discrete momentum form of the variational rows: paper eqs. 46–54 telescoped into a
//! discrete conservation of inertial angular momentum (beyond the paper; the derivation is
//! restated here and each step is tested in `tests/integration/discrete_momentum.rs`).
//!
//! # Derivation
//!
//! For the interval k (nodes k, k+1, step `h_k`), with `φ_k = vec(q_k† q_{k+1})`, `ρ̄_k`
//! the trapezoid `(ρ_k + ρ_{k+1})/2` and `C_k` the body → inertial matrix of `q_k`, define
//! the **interval momentum**
//!
//! ```text
//! L_k := C_k N(φ_k) [ (2/h_k) G(φ_k) j + ρ̄_k ]          (N m s; ≈ C (J ω + ρ) mid-interval)
//! ```
//!
//! * With `f_k = [φ_k; √(1 − |φ_k|²)]` and `R(f)` its rotation matrix, `R(f)ᵀ N(φ) = M(φ)`
//!   exactly, and `C_{k+1} = C_k R(f_k)`, so `C_{k+1} M(φ_k) = C_k N(φ_k)`.
//! * Divided by `h̄/2`, the unequal-step discrete Euler–Lagrange equation at node k+1
//!   ([`crate::discrete`], torque sign of docs/conventions.md §1) reads
//!   `N(φ_{k+1}) P_{k+1} − M(φ_k) P_k = h̄_{k+1} τ_{k+1}` with `P_k = (2/h_k) G(φ_k) j + ρ̄_k`
//!   and `h̄_{k+1} = (h_k + h_{k+1})/2`. Multiplied by `C_{k+1}`:
//!
//! ```text
//! L_{k+1} − L_k = h̄_{k+1} C_{k+1} τ_{k+1}        exactly:  C_{k+1} (H_k j − y_k) = (h̄/2)(L_{k+1} − L_k − h̄ C_{k+1} τ_{k+1})
//! ```
//!
//! The discrete momentum changes only by the torque impulses (**plus** sign). Summed from
//! the first interval of a chain, each interval gives three rows linear in `j`, the
//! chain's initial momentum `L̄₀` and an unknown constant body-frame torque `τ_b`:
//!
//! ```text
//! (2/h_k) C_k N(φ_k) G(φ_k) j − L̄₀ − S_k τ_b = −C_k N(φ_k) ρ̄_k + T_k
//! S_k = Σ_{m=1..k} h̄_m C_m,   T_k = Σ_{m=1..k} h̄_m C_m τ_m
//! ```
//!
//! Noise in `φ` enters each row once (the paper's rows are rotated first differences of
//! these, so they difference it). The rows share the O(h²) discretisation bias of the
//! discrete Lagrangian, even in `h`; [`crate::estimator::momentum_rows`] removes its
//! leading term by Richardson extrapolation against the stride-2 subgrid.
//!
//! Units: `h` in s, `ρ` in N m s, `τ` in N m, `j` in kg m²; the rows are in N m s.

use crate::discrete::{g_matrix, n_matrix};
use nalgebra::{Matrix3, Matrix3x6, Vector3};

/// The coefficients of one interval's momentum: `L_k = a j − b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct IntervalMomentum {
    /// `(2/h) C N(φ) G(φ)`, 3×6, s⁻¹.
    pub(crate) a: Matrix3x6<f64>,
    /// `−C N(φ) ρ̄`, N m s.
    pub(crate) b: Vector3<f64>,
    /// `C N(φ)`, the rotor momentum's coefficient ([`Self::rotor`]).
    pub(crate) cn: Matrix3<f64>,
}

impl IntervalMomentum {
    /// The coefficients for attitude `c` (body → inertial) at the interval's start, its
    /// incremental rotation `φ`, its trapezoid rotor momentum `ρ̄` and its length `h_s`.
    #[must_use]
    pub(crate) fn new(
        c: &Matrix3<f64>,
        phi: &Vector3<f64>,
        rho_bar_nms: &Vector3<f64>,
        h_s: f64,
    ) -> Self {
        let cn = c * n_matrix(phi);
        Self {
            a: cn * g_matrix(phi) * (2.0 / h_s),
            b: -(cn * rho_bar_nms),
            cn,
        }
    }

    /// `b` of the same interval for another rotor momentum `ρ̄` (N m s): `−C N(φ) ρ̄`.
    #[must_use]
    pub(crate) fn rotor(&self, rho_bar_nms: &Vector3<f64>) -> Vector3<f64> {
        -(self.cn * rho_bar_nms)
    }

    /// `L = a j − b` for a given `j`, N m s.
    #[cfg(test)]
    #[must_use]
    pub(crate) fn momentum(&self, j: &crate::tensor::InertiaVector) -> Vector3<f64> {
        self.a * j - self.b
    }
}
