//! Attitude algebra: unit quaternions as used in paper §II.C (eqs. 18–25).
//!
//! # Conventions (read these)
//!
//! * **Storage: vector first, scalar last**, `q = [v; s] = [x, y, z, w]` (eq. 18).
//! * **Product: Hamilton**, eq. 19: `q1 q2 = [v1 × v2 + s1 v2 + s2 v1; s1 s2 − v1·v2]`.
//! * **Meaning: body → inertial.** `x_I = q x_B q†` (eq. 22), so [`Quaternion::to_matrix`]
//!   returns the direction cosine matrix `C` with `x_I = C x_B`.
//! * **Composition:** a rotation `q1` followed by `q2` is `q3 = q2 q1`.
//! * **Body rate:** `ω̂ = 2 q† q̇` (eq. 24); `q̇ = ½ q ω̂` with ω in body axes.
//! * **Incremental rotation:** `f_k = q_k† q_{k+1}` (eq. 30) and
//!   `φ_k = vec(f_k)` with the sign of `f_k` chosen so that its scalar part is ≥ 0
//!   (eq. 37 needs `√(1 − φ·φ) ≥ 0`). For a constant body rate ω over a step h,
//!   `φ = sin(h|ω|/2) ω/|ω| ≈ (h/2) ω`.
//! * **Rotation vector:** `θ = angle · axis`; [`Quaternion::exp`] and [`Quaternion::log`]
//!   convert (angle in `[0, π]` after sign resolution).
//!
//! Telemetry rarely agrees on these. Two other conventions are common and must be
//! converted **explicitly** at the input boundary; there is no implicit conversion:
//!
//! * scalar-first storage `[w, x, y, z]`: [`Quaternion::from_wxyz`];
//! * JPL / Shuster (`q` maps inertial → body, product in the opposite order):
//!   [`Quaternion::from_jpl_xyzw`]. Shuster's attitude matrix `A(q)` maps inertial
//!   components to body components; because `A(q) = C(q)ᵀ` for the same four numbers,
//!   a JPL quaternion has **the same components** as the Hamilton body→inertial
//!   quaternion of the same attitude. The conversion is therefore a relabelling, kept as
//!   a named function so that the reading is deliberate and documented.
//! * Hamilton inertial → body: [`Quaternion::from_hamilton_inertial_to_body_xyzw`]
//!   (the conjugate).
//!
//! ```
//! use inertia::attitude::Quaternion;
//! use nalgebra::Vector3;
//! use approx::assert_relative_eq;
//! // 90° about z takes the body x axis to the inertial y axis.
//! let q = Quaternion::exp(&Vector3::new(0.0, 0.0, core::f64::consts::FRAC_PI_2));
//! assert_relative_eq!(q.rotate(&Vector3::x()), Vector3::y(), epsilon = 1e-15);
//! ```

use crate::math::{abs, atan2, cos, sin, sqrt};
use nalgebra::{Matrix3, Vector3};

/// A quaternion `[v; s]`, vector part first, scalar part last, Hamilton product.
///
/// Attitude quaternions map body to inertial (`x_I = q x_B q†`). See the module docs.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Quaternion {
    /// Vector part `v = [x, y, z]`.
    pub v: Vector3<f64>,
    /// Scalar part `s = w`.
    pub s: f64,
}

/// The skew-symmetric cross-product matrix `S(x)` of eq. 4: `S(x) y = x × y`.
#[must_use]
#[inline]
pub fn skew(x: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -x.z, x.y, x.z, 0.0, -x.x, -x.y, x.x, 0.0)
}

impl Quaternion {
    /// The identity rotation `[0, 0, 0, 1]`.
    pub const IDENTITY: Quaternion = Quaternion {
        v: Vector3::new(0.0, 0.0, 0.0),
        s: 1.0,
    };

    /// From vector part and scalar part.
    #[must_use]
    pub const fn new(v: Vector3<f64>, s: f64) -> Self {
        Self { v, s }
    }

    /// From `[x, y, z, w]` (scalar **last**, this crate's storage), Hamilton, body→inertial.
    #[must_use]
    pub fn from_xyzw(c: [f64; 4]) -> Self {
        Self::new(Vector3::new(c[0], c[1], c[2]), c[3])
    }

    /// From `[w, x, y, z]` (scalar **first**), Hamilton, body→inertial.
    #[must_use]
    pub fn from_wxyz(c: [f64; 4]) -> Self {
        Self::new(Vector3::new(c[1], c[2], c[3]), c[0])
    }

    /// From a JPL/Shuster quaternion `[q1, q2, q3, q4]` (scalar last) describing the
    /// inertial→body attitude matrix `A(q)`. The components are the same as the Hamilton
    /// body→inertial quaternion (see module docs); no arithmetic is done.
    #[must_use]
    pub fn from_jpl_xyzw(c: [f64; 4]) -> Self {
        Self::from_xyzw(c)
    }

    /// From a Hamilton quaternion `[x, y, z, w]` that maps inertial → body (the conjugate
    /// of this crate's meaning).
    #[must_use]
    pub fn from_hamilton_inertial_to_body_xyzw(c: [f64; 4]) -> Self {
        Self::from_xyzw(c).conjugate()
    }

    /// Components as `[x, y, z, w]` (scalar last).
    #[must_use]
    pub fn to_xyzw(&self) -> [f64; 4] {
        [self.v.x, self.v.y, self.v.z, self.s]
    }

    /// Components as `[w, x, y, z]` (scalar first).
    #[must_use]
    pub fn to_wxyz(&self) -> [f64; 4] {
        [self.s, self.v.x, self.v.y, self.v.z]
    }

    /// A pure quaternion `x̂ = [x; 0]` (eq. 23).
    #[must_use]
    pub fn pure(x: &Vector3<f64>) -> Self {
        Self::new(*x, 0.0)
    }

    /// Hamilton product `self · rhs` (eq. 19).
    #[must_use]
    #[inline]
    pub fn mul(&self, rhs: &Quaternion) -> Quaternion {
        Quaternion::new(
            self.v.cross(&rhs.v) + self.s * rhs.v + rhs.s * self.v,
            self.s * rhs.s - self.v.dot(&rhs.v),
        )
    }

    /// Conjugate `q† = [−v; s]` (eq. 21).
    #[must_use]
    #[inline]
    pub fn conjugate(&self) -> Quaternion {
        Quaternion::new(-self.v, self.s)
    }

    /// Euclidean norm of the four components.
    #[must_use]
    #[inline]
    pub fn norm(&self) -> f64 {
        sqrt(self.norm_squared())
    }

    /// Squared norm.
    #[must_use]
    #[inline]
    pub(crate) fn norm_squared(&self) -> f64 {
        self.v.norm_squared() + self.s * self.s
    }

    /// `self / |self|`. Returns `None` for a zero or non-finite quaternion.
    #[must_use]
    pub fn normalize(&self) -> Option<Quaternion> {
        let n = self.norm();
        if n.is_finite() && n > 0.0 {
            Some(Quaternion::new(self.v / n, self.s / n))
        } else {
            None
        }
    }

    /// The same rotation with scalar part ≥ 0 (`q` and `−q` are the same rotation).
    #[must_use]
    #[inline]
    pub fn positive_scalar(&self) -> Quaternion {
        if self.s < 0.0 {
            Quaternion::new(-self.v, -self.s)
        } else {
            *self
        }
    }

    /// Rotate a body vector into inertial axes: `x_I = q x_B q†` (eq. 22).
    #[must_use]
    pub fn rotate(&self, x: &Vector3<f64>) -> Vector3<f64> {
        // x + 2 s (v × x) + 2 v × (v × x), valid for unit q.
        let t = 2.0 * self.v.cross(x);
        x + self.s * t + self.v.cross(&t)
    }

    /// Direction cosine matrix `C` with `x_I = C x_B`:
    /// `C = (s² − v·v) I + 2 v vᵀ + 2 s S(v)`.
    #[must_use]
    pub fn to_matrix(&self) -> Matrix3<f64> {
        let v = &self.v;
        let s = self.s;
        Matrix3::identity() * (s * s - v.dot(v)) + 2.0 * v * v.transpose() + 2.0 * s * skew(v)
    }

    /// The unit quaternion of a rotation matrix `C` (body → inertial), scalar part ≥ 0.
    /// Uses Shepperd's method, accurate for every rotation angle.
    #[must_use]
    pub fn from_matrix(c: &Matrix3<f64>) -> Quaternion {
        let tr = c.trace();
        let (x, y, z, w);
        if tr >= c[(0, 0)] && tr >= c[(1, 1)] && tr >= c[(2, 2)] {
            let r = sqrt(1.0 + tr);
            w = 0.5 * r;
            let f = 0.5 / r;
            x = (c[(2, 1)] - c[(1, 2)]) * f;
            y = (c[(0, 2)] - c[(2, 0)]) * f;
            z = (c[(1, 0)] - c[(0, 1)]) * f;
        } else if c[(0, 0)] >= c[(1, 1)] && c[(0, 0)] >= c[(2, 2)] {
            let r = sqrt(1.0 + 2.0 * c[(0, 0)] - tr);
            x = 0.5 * r;
            let f = 0.5 / r;
            w = (c[(2, 1)] - c[(1, 2)]) * f;
            y = (c[(0, 1)] + c[(1, 0)]) * f;
            z = (c[(0, 2)] + c[(2, 0)]) * f;
        } else if c[(1, 1)] >= c[(2, 2)] {
            let r = sqrt(1.0 + 2.0 * c[(1, 1)] - tr);
            y = 0.5 * r;
            let f = 0.5 / r;
            w = (c[(0, 2)] - c[(2, 0)]) * f;
            x = (c[(0, 1)] + c[(1, 0)]) * f;
            z = (c[(1, 2)] + c[(2, 1)]) * f;
        } else {
            let r = sqrt(1.0 + 2.0 * c[(2, 2)] - tr);
            z = 0.5 * r;
            let f = 0.5 / r;
            w = (c[(1, 0)] - c[(0, 1)]) * f;
            x = (c[(0, 2)] + c[(2, 0)]) * f;
            y = (c[(1, 2)] + c[(2, 1)]) * f;
        }
        Quaternion::new(Vector3::new(x, y, z), w).positive_scalar()
    }

    /// The unit quaternion of rotation vector `θ` (angle `|θ|` about `θ/|θ|`, eq. 20).
    #[must_use]
    pub fn exp(theta: &Vector3<f64>) -> Quaternion {
        let a2 = theta.norm_squared();
        let a = sqrt(a2);
        // sin(a/2)/a, with its series near zero.
        let k = if a < 1e-4 {
            0.5 - a2 / 48.0
        } else {
            sin(0.5 * a) / a
        };
        Quaternion::new(theta * k, cos(0.5 * a))
    }

    /// The rotation vector of a unit quaternion, angle in `[0, π]` (sign of `q` resolved).
    #[must_use]
    pub fn log(&self) -> Vector3<f64> {
        let q = self.positive_scalar();
        let vn = q.v.norm();
        if vn < 1e-12 {
            // angle ≈ 2|v|; θ = 2 v / s to third order.
            return q.v * (2.0 / q.s);
        }
        let angle = 2.0 * atan2(vn, q.s);
        q.v * (angle / vn)
    }

    /// Rotation angle in `[0, π]`.
    #[must_use]
    pub fn angle(&self) -> f64 {
        let q = self.positive_scalar();
        2.0 * atan2(q.v.norm(), abs(q.s))
    }
}

impl core::ops::Mul for Quaternion {
    type Output = Quaternion;
    fn mul(self, rhs: Quaternion) -> Quaternion {
        Quaternion::mul(&self, &rhs)
    }
}

/// The incremental rotation `φ_k = vec(q_k† q_{k+1})` (eqs. 30, 37), with the sign of
/// `q_k† q_{k+1}` chosen so that its scalar part is ≥ 0. The result does not depend on
/// the signs of `q_k` and `q_{k+1}`.
#[must_use]
#[inline]
pub fn incremental_rotation(q_k: &Quaternion, q_k1: &Quaternion) -> Vector3<f64> {
    q_k.conjugate().mul(q_k1).positive_scalar().v
}
