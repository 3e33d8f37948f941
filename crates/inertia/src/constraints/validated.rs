//! The validated constraint set ([`Constraints`]): the LMIs and linear inequalities the
//! solvers see (paper eqs. 9, 55, 57), the elements fixed by equalities, and the strictly
//! interior point found by the phase-I problem ([`super::ConstraintSet::validate`]).

use super::description::{Lin, Lmi, MAX_LIN};
use super::ConstraintSet;
use crate::barrier::{self, BarrierSettings, Problem};
use crate::tensor::{InertiaVector, COMPONENT_INDEX};
use nalgebra::{Matrix3, SMatrix, SVector};

/// `F_k = ∂J/∂j_k`: the symmetric basis matrices of eq. 48.
pub(super) fn basis() -> [Matrix3<f64>; 6] {
    let mut fk = [Matrix3::zeros(); 6];
    for (k, &(r, c)) in COMPONENT_INDEX.iter().enumerate() {
        fk[k][(r, c)] = 1.0;
        fk[k][(c, r)] = 1.0;
    }
    fk
}

/// A validated constraint set in the form the solvers use: up to two 3×3 LMIs
/// `F0 + Σ j_k F_k ⪰ 0` and up to `MAX_LIN` (16) linear inequalities `aᵀ j ≥ b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constraints {
    pub(super) set: ConstraintSet,
    pub(super) lmis: [Lmi<6>; 2],
    pub(super) n_lmi: usize,
    pub(super) lins: [Lin<6>; MAX_LIN],
    pub(super) n_lin: usize,
    pub(super) interior: InertiaVector,
    pub(super) fixed: [Option<f64>; 6],
}

impl Constraints {
    pub(super) fn push_lmi(&mut self, l: Lmi<6>) {
        self.lmis[self.n_lmi] = l;
        self.n_lmi += 1;
    }

    pub(super) fn push_lin(&mut self, l: Lin<6>) {
        self.lins[self.n_lin] = l;
        self.n_lin += 1;
    }

    /// The elements fixed by equalities, with their values. The LMIs and linear
    /// inequalities do not depend on them (their values are in the constant terms), and
    /// [`crate::solver::solve`] eliminates them from the objective.
    #[must_use]
    pub fn fixed(&self) -> &[Option<f64>; 6] {
        &self.fixed
    }

    /// `j` with its fixed elements set to their values.
    #[must_use]
    pub(crate) fn with_fixed(&self, j: &InertiaVector) -> InertiaVector {
        let mut out = *j;
        for (o, v) in out.iter_mut().zip(&self.fixed) {
            if let Some(v) = v {
                *o = *v;
            }
        }
        out
    }

    /// The set this was validated from.
    #[must_use]
    pub fn set(&self) -> &ConstraintSet {
        &self.set
    }

    /// The LMIs `F0 + Σ j_k F_k ⪰ 0`.
    #[must_use]
    pub(crate) fn lmis(&self) -> &[Lmi<6>] {
        &self.lmis[..self.n_lmi]
    }

    /// The linear inequalities `aᵀ j ≥ b`.
    #[must_use]
    pub(crate) fn lins(&self) -> &[Lin<6>] {
        &self.lins[..self.n_lin]
    }

    /// A strictly interior point (found at validation).
    #[must_use]
    pub fn interior(&self) -> &InertiaVector {
        &self.interior
    }

    /// Smallest margin of `j`: the least eigenvalue of every LMI and the least linear slack
    /// (kg m²). Positive means strictly feasible. Std only (eigen-decomposition).
    #[must_use]
    pub fn margin(&self, j: &InertiaVector) -> f64 {
        let mut m = f64::INFINITY;
        for l in self.lmis() {
            m = m.min(crate::eigen3::symmetric_eigen3(&l.eval(j)).0.min());
        }
        for l in self.lins() {
            m = m.min(l.eval(j));
        }
        m
    }

    /// `true` when `j` satisfies every constraint strictly (Cholesky test, no eigenvalues).
    #[must_use]
    pub fn strictly_feasible(&self, j: &InertiaVector) -> bool {
        self.lmis().iter().all(|l| l.eval(j).cholesky().is_some())
            && self.lins().iter().all(|l| l.eval(j) > 0.0)
    }

    /// Phase I: maximise `s` over `(j, s)` subject to `F_i(j) ⪰ s I`, `aᵀj − b ≥ s`,
    /// `s ≤ 1` and a wide box on `j`. Returns the point and its margin `s`.
    pub(super) fn phase_one(&self) -> (InertiaVector, f64) {
        // Start: J = c I with c above every lower bound, off-diagonals mid-bounds. The start
        // need not be feasible: the initial s is set below its smallest margin.
        let scale = self
            .set
            .lower_kg_m2
            .iter()
            .chain(&self.set.upper_kg_m2)
            .flatten()
            .fold(1.0f64, |a, &b| a.max(b.abs()));
        let mut j0 = InertiaVector::zeros();
        for i in 0..6 {
            let (l, u) = (self.set.lower_kg_m2[i], self.set.upper_kg_m2[i]);
            j0[i] = match (l, u) {
                (Some(l), Some(u)) => 0.5 * (l + u),
                (Some(l), None) => l.max(0.0) + scale,
                (None, Some(u)) => u.min(if i < 3 { 2.0 * scale } else { 0.0 }),
                (None, None) => {
                    if i < 3 {
                        2.0 * scale
                    } else {
                        0.0
                    }
                }
            };
        }
        // A box of natural size, so the phase-I centre is a sensible inertia.
        let bound = 10.0 * scale;
        let mut lmis = [Lmi::<7>::zero(); 2];
        for (dst, src) in lmis.iter_mut().zip(self.lmis()) {
            dst.f0 = src.f0;
            dst.fk[..6].copy_from_slice(&src.fk);
            dst.fk[6] = -Matrix3::identity();
        }
        let mut lins = [Lin::<7>::zero(); MAX_LIN + 13];
        let mut n = 0;
        for l in self.lins() {
            lins[n] = Lin {
                a: SVector::<f64, 7>::from_fn(|i, _| if i < 6 { l.a[i] } else { -1.0 }),
                b: l.b,
            };
            n += 1;
        }
        // s ≤ 1 and |j_k| ≤ bound.
        lins[n] = Lin {
            a: SVector::<f64, 7>::ith(6, -1.0),
            b: -1.0,
        };
        n += 1;
        for k in 0..6 {
            for sign in [1.0, -1.0] {
                lins[n] = Lin {
                    a: SVector::<f64, 7>::ith(k, sign),
                    b: -bound,
                };
                n += 1;
            }
        }
        // Initial s strictly below every margin of j0.
        let mut s0 = 0.0f64;
        let mut m0 = f64::INFINITY;
        for l in self.lmis() {
            m0 = m0.min(crate::eigen3::symmetric_eigen3(&l.eval(&j0)).0.min());
        }
        for l in self.lins() {
            m0 = m0.min(l.eval(&j0));
        }
        if m0.is_finite() {
            s0 = m0.min(1.0) - 1.0 - 0.1 * m0.abs();
        }
        let x0 = SVector::<f64, 7>::from_fn(|i, _| if i < 6 { j0[i] } else { s0 });
        let mut c = SVector::<f64, 7>::zeros();
        c[6] = -1.0;
        let problem = Problem {
            a: SMatrix::<f64, 7, 7>::zeros(),
            b: SVector::<f64, 7>::zeros(),
            c,
            lmis: &lmis[..self.n_lmi],
            lins: &lins[..n],
        };
        let settings = BarrierSettings {
            gap_tolerance: 1e-9,
            ..BarrierSettings::default()
        };
        match barrier::solve(&problem, &x0, &settings) {
            Ok(out) => {
                let x = out.x;
                let j = InertiaVector::from_fn(|i, _| x[i]);
                (j, self.margin(&j))
            }
            Err(_) => (j0, m0.min(0.0)),
        }
    }
}
