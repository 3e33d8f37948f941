//! The reference backend: Clarabel (feature `clarabel`, needs system OpenBLAS:
//! `apt-get install -y libopenblas-dev`; run with `OPENBLAS_NUM_THREADS=1`).
//!
//! Clarabel solves `min ½xᵀPx + qᵀx s.t. Ax + s = b, s ∈ K`. We pass the objective as
//! `P = 2RᵀR`, `q = −2Rᵀz` (faster than the Schur-complement LMI of eq. 14 and the same
//! answer), each linear inequality `aᵀj ≥ b` as a row `−aᵀ` of a nonnegative cone with
//! right-hand side `−b`, and each LMI `F0 + Σ j_k F_k ⪰ 0` as a 3×3 PSD triangle cone:
//! `s = svec(F0 + Σ j_k F_k)`, `svec` taking the upper triangle column by column with
//! off-diagonal entries multiplied by √2.

use super::{Backend, Residuals, Solution, SolveError, SolveStatus};
use crate::constraints::Constraints;
use crate::tensor::InertiaVector;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::{Matrix3, Matrix6, Vector6};

/// `svec` of a symmetric 3×3 matrix in Clarabel's order.
fn svec(m: &Matrix3<f64>) -> [f64; 6] {
    let r2 = core::f64::consts::SQRT_2;
    [
        m[(0, 0)],
        r2 * m[(0, 1)],
        m[(1, 1)],
        r2 * m[(0, 2)],
        r2 * m[(1, 2)],
        m[(2, 2)],
    ]
}

/// Clarabel with tight tolerances.
#[derive(Debug, Clone)]
pub struct ClarabelSolver {
    /// Clarabel's settings (defaults: gap and feasibility tolerances 1e-10, 200 iterations,
    /// quiet).
    pub settings: DefaultSettings<f64>,
    /// Re-solve with the data rescaled by the first answer's objective (default `true`;
    /// the reference in accuracy tests). `false` is Clarabel as one would call it once
    /// (the speed comparison).
    pub two_pass: bool,
}

impl ClarabelSolver {
    /// One Clarabel call per solve.
    #[must_use]
    pub fn single_pass() -> Self {
        Self {
            two_pass: false,
            ..Self::default()
        }
    }
}

impl Default for ClarabelSolver {
    fn default() -> Self {
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_iter(200)
            .tol_gap_abs(1e-10)
            .tol_gap_rel(1e-10)
            .tol_feas(1e-10)
            .tol_ktratio(1e-8)
            .build()
            .unwrap_or_default();
        Self {
            settings,
            two_pass: true,
        }
    }
}

impl Backend for ClarabelSolver {
    fn name(&self) -> &'static str {
        "clarabel"
    }

    fn solve_scaled(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        _warm: Option<&InertiaVector>,
    ) -> Result<Solution, SolveError> {
        // Two passes: the second rescales so that the optimal objective is O(1), which
        // Clarabel's absolute tolerances need when the optimum is far below ‖z‖².
        let first = self.solve_once(r, z, constraints)?;
        let obj = first.objective;
        if !(self.two_pass && obj > 0.0 && obj < 1e-2) {
            return Ok(first);
        }
        let s = 1.0 / crate::math::sqrt(obj);
        let mut second = self.solve_once(&(r * s), &(z * s), constraints)?;
        second.iterations += first.iterations;
        second.objective = (r * second.j - z).norm_squared();
        Ok(second)
    }
}

impl ClarabelSolver {
    fn solve_once(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
    ) -> Result<Solution, SolveError> {
        let p = r.transpose() * r * 2.0;
        let q: Vec<f64> = (r.transpose() * z * -2.0).iter().copied().collect();
        // Upper triangle of P in CSC.
        let mut p_rows = [[0.0f64; 6]; 6];
        for (i, row) in p_rows.iter_mut().enumerate() {
            for (k, v) in row.iter_mut().enumerate() {
                if k >= i {
                    *v = p[(i, k)];
                }
            }
        }
        let pm = CscMatrix::from(&p_rows);

        let mut a_rows: Vec<[f64; 6]> = Vec::new();
        let mut b = Vec::new();
        let mut cones = Vec::new();
        let lins = constraints.lins();
        if !lins.is_empty() {
            for l in lins {
                a_rows.push(core::array::from_fn(|k| -l.a[k]));
                b.push(-l.b);
            }
            cones.push(SupportedConeT::NonnegativeConeT(lins.len()));
        }
        for lmi in constraints.lmis() {
            let cols: [[f64; 6]; 6] = core::array::from_fn(|k| svec(&lmi.fk[k]));
            a_rows
                .extend((0..6).map(|row| -> [f64; 6] { core::array::from_fn(|k| -cols[k][row]) }));
            b.extend_from_slice(&svec(&lmi.f0));
            cones.push(SupportedConeT::PSDTriangleConeT(3));
        }
        let am = CscMatrix::from(&a_rows);
        let fail = |why| SolveError::Failed {
            backend: "clarabel",
            why,
        };
        let mut solver = DefaultSolver::new(&pm, &q, &am, &b, &cones, self.settings.clone())
            .map_err(|_| fail("problem data rejected"))?;
        solver.solve();
        let s = &solver.solution;
        let status = match s.status {
            SolverStatus::Solved => SolveStatus::Optimal,
            SolverStatus::AlmostSolved | SolverStatus::MaxIterations => SolveStatus::Inaccurate,
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                return Err(fail("reported the constraints infeasible"))
            }
            _ => return Err(fail("did not converge")),
        };
        let j = Vector6::from_iterator(s.x.iter().copied());
        let primal = (-constraints.margin(&j)).max(0.0);
        Ok(Solution {
            j,
            objective: (r * j - z).norm_squared(),
            status,
            iterations: s.iterations,
            residuals: Residuals {
                primal,
                dual: s.r_dual,
                gap: (s.obj_val - s.obj_val_dual).abs(),
            },
        })
    }
}
