//! Torques from outside measurements ([`crate::sample::External`]) in the momentum rows:
//! each is linear in unknowns the rows already have or gain, so it enters the impulse
//! sum `T_k = Σ h̄_m C_m τ_m` of [`super::momentum_rows`] (`discrete_momentum.rs`'s
//! derivation) as a coefficient instead of a known value.
//!
//! # Torques (body axes, N m)
//!
//! * **Gravity gradient** (given the position `r` in the attitude's inertial frame):
//!   `τ_gg = 3μ/|r|³ r̂_B × (J r̂_B)`, `r̂_B = Cᵀ r̂`, is `Γ j` with
//!   `Γ = 3μ/|r|³ [r̂_B]× G(r̂_B)` (`G` of eq. 47: `J v = G(v) j`). No new unknown: the
//!   rows' `j` columns gain `−Σ h̄ C Γ`. It carries an absolute scale that the exchange
//!   of momentum with the wheels lacks (it sees `J` itself, not only its action).
//! * **Residual magnetic dipole** `m` (A m², fixed in the body), given the measured field
//!   `B` (T, body axes): `τ = m × B = −[B]× m`; the column block `Dipole` (module
//!   `unknowns`) of columns `+Σ h̄ C [B]×`.
//! * **Centre of mass** `c` (m, body axes, from the origin about which the known torque
//!   `τ_known` is given), given the external force `F` (N, body axes, e.g. the
//!   thrusters'): the torque about the centre of mass is `τ_known − c × F =
//!   τ_known + [F]× c`; the column block `CentreOfMass` of columns `−Σ h̄ C [F]×`.
//!
//! The row reads `A j − X₀ − S τ_b − E_j j − E_m m − E_c c = b + T`, each `E` the impulse
//! sum of its torque's map. The sums follow the same quadrature (and, for Richardson
//! rows, the same combination) as the known torque's.

use crate::attitude::skew;
use crate::discrete::g_matrix;
use crate::math::sqrt;
use crate::sample::External;
use nalgebra::{Matrix3, Matrix3x6, Vector3};

/// Earth's gravitational parameter, m³/s² (WGS 84 / EGM96 value): the default μ of the
/// gravity-gradient torque.
pub const EARTH_MU_M3_S2: f64 = 3.986_004_418e14;

/// Which torques of outside measurements the rows model, where the samples give the
/// measurement (each on by default: a measurement given is a torque to model).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct OutsideTorques {
    /// The gravity-gradient torque, from the positions. Off where the known torque
    /// already holds it.
    pub gravity_gradient: bool,
    /// The gravitational parameter μ of the gravity gradient, m³/s² (default Earth's,
    /// [`EARTH_MU_M3_S2`]).
    pub gravity_mu_m3_s2: f64,
    /// A residual magnetic dipole, from the magnetic field.
    pub residual_dipole: bool,
    /// The centre of mass, from the external force.
    pub centre_of_mass: bool,
}

impl Default for OutsideTorques {
    fn default() -> Self {
        Self {
            gravity_gradient: true,
            gravity_mu_m3_s2: EARTH_MU_M3_S2,
            residual_dipole: true,
            centre_of_mass: true,
        }
    }
}

impl OutsideTorques {
    /// Whether μ is usable (finite, positive).
    #[must_use]
    pub(crate) fn valid(&self) -> bool {
        self.gravity_mu_m3_s2.is_finite() && self.gravity_mu_m3_s2 > 0.0
    }
}

/// A 3-vector unknown of an outside torque as estimated: its value and its σ per
/// component (the larger of the least-squares and the jackknife σ, as for `j`'s noise σ;
/// `None` where there is none).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Estimated3 {
    /// The value.
    pub value: [f64; 3],
    /// Its σ per component (`None` for a component the rows never separated from the
    /// others, or without residual degrees of freedom).
    pub sigma: [Option<f64>; 3],
    /// A direction (unit, body axes) along which the data do not determine it: the
    /// least-squares σ along it exceeds `UNDETERMINED_RATIO` times the σ across it (a
    /// dipole along a field that keeps its direction in the body, a centre of mass along a
    /// force that does, give no torque). Its component along it is then not an estimate.
    pub undetermined_direction: Option<[f64; 3]>,
}

impl Estimated3 {
    /// Its σ where every component has one.
    #[must_use]
    pub fn sigma_all(&self) -> Option<[f64; 3]> {
        match self.sigma {
            [Some(a), Some(b), Some(c)] => Some([a, b, c]),
            _ => None,
        }
    }
}

/// The ratio of the largest to the smallest least-squares σ of a 3-vector unknown's
/// principal directions beyond which the largest is not determined by the data
/// ([`Estimated3::undetermined_direction`]): a direction the rows cannot see shows as a
/// pivot of rounding size, 10⁸ or more below the others.
pub(crate) const UNDETERMINED_RATIO: f64 = 1e6;

/// The direction of `covariance` (a 3×3 least-squares covariance, infinite on the axis
/// of an unknown never separated) along which the σ exceeds [`UNDETERMINED_RATIO`] times
/// the smallest, if any.
#[must_use]
pub(crate) fn undetermined(covariance: &Matrix3<f64>) -> Option<[f64; 3]> {
    for i in 0..3 {
        if !covariance[(i, i)].is_finite() {
            return Some(Vector3::ith(i, 1.0).into());
        }
    }
    let (values, vectors) = crate::eigen3::symmetric_eigen3(covariance);
    let (mut lo, mut hi) = (0, 0);
    for i in 1..3 {
        if values[i] < values[lo] {
            lo = i;
        }
        if values[i] > values[hi] {
            hi = i;
        }
    }
    let ratio2 = UNDETERMINED_RATIO * UNDETERMINED_RATIO;
    (!(values[hi] <= ratio2 * values[lo].max(0.0))).then(|| vectors[hi].into())
}

/// What the rows made of the outside measurements at the last answer.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct OutsideEstimates {
    /// Whether the gravity-gradient torque was modelled (positions given and the
    /// torque on).
    pub gravity_gradient: bool,
    /// The residual magnetic dipole, A m², body axes, where estimated.
    pub residual_dipole_am2: Option<Estimated3>,
    /// The centre of mass, m, body axes from the known torque's origin, where estimated.
    pub centre_of_mass_m: Option<Estimated3>,
}

impl OutsideEstimates {
    /// These estimates with consider terms added to their σ in quadrature, per component:
    /// `moves[0]` the residual dipole's (A m²), `moves[1]` the centre of mass's (m). A
    /// component without σ (not separated from the others) stays without.
    #[must_use]
    pub(crate) fn widened(mut self, moves: &[[f64; 3]; 2]) -> Self {
        for (e, m) in [&mut self.residual_dipole_am2, &mut self.centre_of_mass_m]
            .into_iter()
            .zip(moves)
        {
            if let Some(e) = e.as_mut() {
                for (sigma, m) in e.sigma.iter_mut().zip(m) {
                    *sigma = sigma.map(|v| crate::math::sqrt(v * v + m * m));
                }
            }
        }
        self
    }

    /// The move of each estimate from `self` to `other`, per component (zero where either
    /// lacks it): the dipole's and the centre of mass's, as [`Self::widened`] takes them.
    #[must_use]
    pub(crate) fn moves_to(&self, other: &Self) -> [[f64; 3]; 2] {
        let d = |a: &Option<Estimated3>, b: &Option<Estimated3>| match (a, b) {
            (Some(a), Some(b)) => core::array::from_fn(|k| {
                let m = (b.value[k] - a.value[k]).abs();
                if m.is_finite() {
                    m
                } else {
                    0.0
                }
            }),
            _ => [0.0; 3],
        };
        [
            d(&self.residual_dipole_am2, &other.residual_dipole_am2),
            d(&self.centre_of_mass_m, &other.centre_of_mass_m),
        ]
    }

    /// Whether there is anything to report.
    #[must_use]
    pub(crate) fn any(&self) -> bool {
        self.gravity_gradient
            || self.residual_dipole_am2.is_some()
            || self.centre_of_mass_m.is_some()
    }
}

/// The unknown torque's maps at one node, body axes: `τ = Γ j + P_m m + P_c c`; or their
/// impulse sums in the inertial frame (`Σ h̄ C ·`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TorqueMaps {
    /// `Γ` (gravity gradient), N m per kg m².
    pub(crate) j: Matrix3x6<f64>,
    /// `−[B]×` (residual dipole), N m per A m².
    pub(crate) dipole: Matrix3<f64>,
    /// `[F]×` (centre of mass), N m per m.
    pub(crate) centre_of_mass: Matrix3<f64>,
}

impl TorqueMaps {
    /// No outside torque.
    pub(crate) const ZERO: TorqueMaps = TorqueMaps {
        j: Matrix3x6::new(
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, //
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, //
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        ),
        dipole: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        centre_of_mass: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };

    /// The maps at a node of attitude `c` (body → inertial) with the measurements `e`,
    /// for the torques `modelled`; `None` where none applies.
    #[must_use]
    pub(crate) fn at(c: &Matrix3<f64>, e: &External, modelled: &OutsideTorques) -> Option<Self> {
        let mut out = Self::ZERO;
        let mut any = false;
        let mu = modelled.gravity_mu_m3_s2;
        if let (true, Some(r)) = (modelled.gravity_gradient, e.position_m) {
            let n2 = r.norm_squared();
            if n2 > 0.0 {
                let n = sqrt(n2);
                let rb: Vector3<f64> = c.transpose() * (r / n);
                out.j = skew(&rb) * g_matrix(&rb) * (3.0 * mu / (n2 * n));
                any = true;
            }
        }
        if let (true, Some(b)) = (modelled.residual_dipole, e.field_t) {
            out.dipole = -skew(&b);
            any = true;
        }
        if let (true, Some(f)) = (modelled.centre_of_mass, e.force_n) {
            out.centre_of_mass = skew(&f);
            any = true;
        }
        any.then_some(out)
    }

    /// `self + other · k`.
    #[must_use]
    pub(crate) fn add_scaled(&self, other: &TorqueMaps, k: f64) -> Self {
        Self {
            j: self.j + other.j * k,
            dipole: self.dipole + other.dipole * k,
            centre_of_mass: self.centre_of_mass + other.centre_of_mass * k,
        }
    }

    /// `c · self`: the maps rotated to the inertial frame.
    #[must_use]
    pub(crate) fn rotated(&self, c: &Matrix3<f64>) -> Self {
        Self {
            j: c * self.j,
            dipole: c * self.dipole,
            centre_of_mass: c * self.centre_of_mass,
        }
    }

    /// `self · a + other · b`.
    #[must_use]
    pub(crate) fn combine(&self, a: f64, other: &TorqueMaps, b: f64) -> Self {
        Self::ZERO.add_scaled(self, a).add_scaled(other, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::attitude::Quaternion;

    /// The gravity-gradient map times `j` is the torque `3μ/r³ r̂_B × (J r̂_B)`; the
    /// dipole's and the centre of mass's maps are `m × B` and `−c × F`.
    #[test]
    fn the_maps_give_the_torques() {
        let q = Quaternion::exp(&Vector3::new(0.3, -0.2, 0.5));
        let c = q.to_matrix();
        let jm = Matrix3::new(2.0, 0.1, -0.2, 0.1, 3.0, 0.15, -0.2, 0.15, 4.0);
        let j = crate::tensor::j_from_matrix(&jm);
        let (r, b, f) = (
            Vector3::new(6.0e6, 2.0e6, -1.0e6),
            Vector3::new(1e-5, -2e-5, 3e-5),
            Vector3::new(0.5, -1.0, 2.0),
        );
        let e = External {
            position_m: Some(r),
            field_t: Some(b),
            force_n: Some(f),
        };
        let all = OutsideTorques::default();
        let maps = TorqueMaps::at(&c, &e, &all).unwrap();
        let rb = c.transpose() * r.normalize();
        let gg = rb.cross(&(jm * rb)) * (3.0 * EARTH_MU_M3_S2 / r.norm().powi(3));
        assert!((maps.j * j - gg).norm() <= 1e-12 * gg.norm(), "{gg}");
        let m = Vector3::new(0.05, -0.02, 0.01);
        assert!((maps.dipole * m - m.cross(&b)).norm() < 1e-20);
        let com = Vector3::new(0.02, 0.0, -0.01);
        assert!((maps.centre_of_mass * com + com.cross(&f)).norm() < 1e-15);
        let none = OutsideTorques {
            gravity_gradient: false,
            residual_dipole: false,
            centre_of_mass: false,
            ..all
        };
        assert!(TorqueMaps::at(&c, &e, &none).is_none());
        assert!(TorqueMaps::at(&c, &External::NONE, &all).is_none());
    }
}
