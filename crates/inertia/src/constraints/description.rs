//! Descriptions of the constraints as data: 3×3 LMIs and linear inequalities in `N`
//! variables. [`super::Constraints`] holds them; every solver backend and the phase-I
//! search read them. No algorithm lives here.

use nalgebra::{Matrix3, SVector};

/// Most linear inequalities in a validated constraint set (3 triangle + 12 bounds).
pub(crate) const MAX_LIN: usize = 16;

/// A 3×3 LMI `F0 + Σ_k x_k F_k ⪰ 0` in `N` variables.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Lmi<const N: usize> {
    /// Constant term.
    pub(crate) f0: Matrix3<f64>,
    /// Coefficient of each variable.
    pub(crate) fk: [Matrix3<f64>; N],
}

impl<const N: usize> Lmi<N> {
    /// The zero LMI.
    #[must_use]
    pub(crate) fn zero() -> Self {
        Self {
            f0: Matrix3::zeros(),
            fk: [Matrix3::zeros(); N],
        }
    }

    /// `F0 + Σ x_k F_k`.
    #[must_use]
    #[inline]
    pub(crate) fn eval(&self, x: &SVector<f64, N>) -> Matrix3<f64> {
        let mut m = self.f0;
        for k in 0..N {
            m += self.fk[k] * x[k];
        }
        m
    }
}

/// A linear inequality `aᵀ x ≥ b` in `N` variables.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Lin<const N: usize> {
    /// Coefficients.
    pub(crate) a: SVector<f64, N>,
    /// Right-hand side.
    pub(crate) b: f64,
}

impl<const N: usize> Lin<N> {
    /// The zero inequality `0 ≥ 0`.
    #[must_use]
    pub(crate) fn zero() -> Self {
        Self {
            a: SVector::zeros(),
            b: 0.0,
        }
    }

    /// The slack `aᵀ x − b` (≥ 0 when satisfied).
    #[must_use]
    #[inline]
    pub(crate) fn eval(&self, x: &SVector<f64, N>) -> f64 {
        self.a.dot(x) - self.b
    }
}
