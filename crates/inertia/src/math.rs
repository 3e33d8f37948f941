//! Scalar functions that work with and without the standard library.
//!
//! The per-sample path must build for `no_std` flight targets, where `f64::sqrt` and
//! friends are unavailable; these wrappers use `libm` there and the standard library's
//! intrinsics otherwise, so results are bit-identical to ordinary `std` code.

#[cfg(feature = "std")]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f64) -> f64 {
        x.sqrt()
    }
    #[inline]
    pub(crate) fn sin(x: f64) -> f64 {
        x.sin()
    }
    #[inline]
    pub(crate) fn cos(x: f64) -> f64 {
        x.cos()
    }
    #[inline]
    pub(crate) fn atan2(y: f64, x: f64) -> f64 {
        y.atan2(x)
    }
    #[inline]
    pub(crate) fn ln(x: f64) -> f64 {
        x.ln()
    }
}

#[cfg(not(feature = "std"))]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f64) -> f64 {
        libm::sqrt(x)
    }
    #[inline]
    pub(crate) fn sin(x: f64) -> f64 {
        libm::sin(x)
    }
    #[inline]
    pub(crate) fn cos(x: f64) -> f64 {
        libm::cos(x)
    }
    #[inline]
    pub(crate) fn atan2(y: f64, x: f64) -> f64 {
        libm::atan2(y, x)
    }
    #[inline]
    pub(crate) fn ln(x: f64) -> f64 {
        libm::log(x)
    }
}

pub(crate) use imp::{atan2, cos, ln, sin, sqrt};

/// `|x|` without `std`.
#[inline]
pub(crate) fn abs(x: f64) -> f64 {
    if x < 0.0 {
        -x
    } else {
        x
    }
}

/// Most iterations of nalgebra's iterative decompositions (SVD, symmetric eigen). Their
/// plain constructors iterate without bound, which on matrices they cannot converge on
/// (non-finite or wildly scaled entries) never returns; every call here goes through
/// `try_new` with this bound and handles the failure.
pub(crate) const MAX_DECOMPOSITION_ITERATIONS: usize = 10_000;

/// Whether two arrays hold the same numbers bit for bit (`+0` and `−0` differ, a NaN
/// equals only the same NaN): the key of the solver's exact-match memos.
pub(crate) fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}
