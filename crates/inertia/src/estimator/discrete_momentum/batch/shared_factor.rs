//! The shared factor of a batch reduction (`super`), kept for the values of the unknowns
//! the rows share beyond `j`: the outside torques' ([`crate::estimator::external_torque`])
//! and the rotor parameters' ([`crate::estimator::rotor_calibration`]), each with its σ.

use crate::estimator as est;
use crate::tensor::InertiaVector;

/// The first column index of the rotor parameters' unknowns
/// ([`crate::estimator::rotor_calibration`]) in a batch reduction's shared columns: past
/// the rows' own unknowns, source `v` at `ROTOR + v`.
pub(crate) const ROTOR: usize = crate::estimator::unknowns::UNKNOWNS;

/// The shared factor of a batch reduction, kept for the values of the outside torques
/// ([`crate::estimator::external_torque`]) and the rotor parameters
/// ([`crate::estimator::rotor_calibration`]): `R` (upper triangular over the shared columns
/// used, `j` last, with the rotors' prior rows), `Qᵀy`, the columns, the residual variance
/// and the weight `s` of the rotors' prior rows.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SharedFactor {
    pub(super) r: nalgebra::DMatrix<f64>,
    pub(super) qty: nalgebra::DVector<f64>,
    pub(super) columns: std::vec::Vec<usize>,
    pub(crate) s2: f64,
    pub(crate) prior_weight: f64,
    /// The rotor parameters' shares of the momentum's own scale (their `γ_v`).
    pub(super) gamma: std::vec::Vec<f64>,
    /// The rotor parameters' jackknife σ (whitened), over the same groups as `j`'s, then
    /// that of the overall scale they imply.
    pub(super) rotor_jackknife: Option<std::vec::Vec<f64>>,
}

/// A 3-vector unknown's value and σ per component.
pub(crate) type ValueSigma = ([f64; 3], [Option<f64>; 3]);

impl SharedFactor {
    /// The unknowns before `j` at `j`: back-substitution with `j` fixed.
    fn leading_at(&self, j: &InertiaVector) -> nalgebra::DVector<f64> {
        let lead = self.columns.len() - 6;
        let mut x = nalgebra::DVector::zeros(lead);
        for i in (0..lead).rev() {
            let d = self.r[(i, i)];
            if d == 0.0 {
                continue;
            }
            let mut s = self.qty[i];
            for k in i + 1..lead {
                s -= self.r[(i, k)] * x[k];
            }
            for k in 0..6 {
                s -= self.r[(i, lead + k)] * j[k];
            }
            x[i] = s / d;
        }
        x
    }

    /// The rotor parameters at `j`, with their posterior covariance (whitened: the file's
    /// σ is 1) and each one's σ no smaller than its jackknife's, where the rows estimate
    /// them.
    #[must_use]
    pub(crate) fn rotors_at(
        &self,
        j: &InertiaVector,
    ) -> Option<crate::estimator::rotor_calibration::RotorFit> {
        let at: std::vec::Vec<usize> = (0..self.columns.len())
            .filter(|&p| (ROTOR..ROTOR + self.gamma.len()).contains(&self.columns[p]))
            .collect();
        if at.is_empty() || !(self.prior_weight > 0.0) {
            return None;
        }
        let x = self.leading_at(j);
        let n = self.columns.len();
        let e = nalgebra::DMatrix::from_fn(n, at.len(), |i, v| f64::from(u8::from(i == at[v])));
        let u = self.r.transpose().solve_lower_triangular(&e);
        let u = u?;
        let c = (u.transpose() * u) * (self.prior_weight * self.prior_weight);
        Some(
            crate::estimator::rotor_calibration::RotorFit::from_covariance(
                at.iter().map(|&p| x[p]).collect(),
                &c,
                &self.gamma,
            )
            .with_jackknife(self.rotor_jackknife.as_deref()),
        )
    }

    /// The residual dipole and the centre of mass at `j` (where the rows use them), each
    /// with its least-squares σ per component (every other unknown free).
    #[must_use]
    pub(crate) fn at(&self, j: &InertiaVector) -> [Option<ValueSigma>; 2] {
        use est::momentum_rows::{CENTRE_OF_MASS, DIPOLE};
        let n = self.columns.len();
        let x = self.leading_at(j);
        let sigma = |p: usize| {
            let mut e = nalgebra::DVector::zeros(n);
            e[p] = 1.0;
            self.r
                .transpose()
                .solve_lower_triangular(&e)
                .filter(|_| self.s2.is_finite() && self.r[(p, p)] != 0.0)
                .map(|u| crate::math::sqrt(self.s2 * u.norm_squared()))
        };
        [DIPOLE, CENTRE_OF_MASS].map(|block| {
            let at: std::vec::Vec<usize> = (block..block + 3)
                .filter_map(|k| self.columns.iter().position(|&c| c == k))
                .collect();
            (at.len() == 3).then(|| {
                (
                    [x[at[0]], x[at[1]], x[at[2]]],
                    [sigma(at[0]), sigma(at[1]), sigma(at[2])],
                )
            })
        })
    }
}
