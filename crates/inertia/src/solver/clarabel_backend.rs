//! The reference backend: Clarabel (feature `clarabel`, needs system OpenBLAS:
//! `apt-get install -y libopenblas-dev`; run with `OPENBLAS_NUM_THREADS=1`).
//!
//! Clarabel solves `min ½xᵀPx + qᵀx s.t. Ax + s = b, s ∈ K`. We pass the objective as
//! `P = 2RᵀR`, `q = −2Rᵀz` (faster than the Schur-complement LMI of eq. 14 and the same
//! answer), each linear inequality `aᵀj ≥ b` as a row `−aᵀ` of a nonnegative cone with
//! right-hand side `−b`, and each LMI `F0 + Σ j_k F_k ⪰ 0` as a 3×3 PSD triangle cone:
//! `s = svec(F0 + Σ j_k F_k)`, `svec` taking the upper triangle column by column with
//! off-diagonal entries multiplied by √2.
//!
//! Clarabel's objective leaves out the constant `‖z‖²`, and its relative gap tolerance is
//! measured against that objective, `‖R j − z‖² − ‖z‖²`. Where the constraints barely
//! press (the optimum's `‖R j − z‖²` far below `‖z‖²`: data just outside the set, as the
//! paper's slew with the paper's J) a tolerance on that sum says little about the part
//! that matters, and Clarabel stops inside the set, short of the active face by
//! `gap / multiplier` (on the 3,000 s slew: `λ_min(Σ) = 9e-6`, the objective 1.9 times the
//! optimum's, J 3.4e-6 from it). The second pass therefore moves the origin to the first
//! answer `j₁` and measures steps in units of its residual: `j = j₁ + t e` with
//! `t = ‖R j₁ − z‖`, so that the objective `‖R e − (z − R j₁)/t‖²` is O(1) *including* the
//! constant Clarabel leaves out, and its tolerances are relative to the part that matters.
//! Where that pass stalls short of its tolerances but confirms the first answer's
//! certificate (no worse, and no better than the first pass's gap tolerance), its answer
//! is taken as optimal; where it fails, the first answer is returned as inaccurate.

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
    /// Re-solve from the first answer, in units of its residual, where that residual is
    /// far below the data's scale (module docs; default `true`, the reference in accuracy
    /// tests). `false` is Clarabel as one would call it once (the speed comparison).
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
        // Two passes: the second, where the first answer's objective is far below the
        // data's scale (`‖z‖² = 1` here), from that answer in units of its residual (module
        // docs).
        let first = self.solve_once(r, z, constraints, None)?;
        let obj = first.objective;
        if !(self.two_pass && obj > 0.0 && obj < 1e-2) {
            return Ok(first);
        }
        let t = crate::math::sqrt(obj);
        let z_shifted = (z - r * first.j) / t;
        let Ok(mut second) = self.solve_once(r, &z_shifted, constraints, Some((&first.j, t)))
        else {
            // The refinement failed: the first answer stands, unconfirmed.
            return Ok(Solution {
                status: SolveStatus::Inaccurate,
                ..first
            });
        };
        second.iterations += first.iterations;
        second.objective = (r * second.j - z).norm_squared();
        if second.status == SolveStatus::Inaccurate
            && first.status == SolveStatus::Optimal
            && self.confirms(&first, &second, constraints)
        {
            second.status = SolveStatus::Optimal;
        }
        Ok(second)
    }
}

impl ClarabelSolver {
    /// Whether a second pass that stopped short of its own tolerances (Clarabel stalls
    /// there on some problems: the inactive constraints' slacks, in units of the
    /// residual, are 1e5 and more times the active one's) still holds the first pass's
    /// certificate: it is no worse than the first answer in objective and in
    /// feasibility, and no better by more than the first pass's gap tolerance (a larger
    /// improvement refutes that certificate, as on some problems with `cond(R)` ~ 1e7).
    fn confirms(&self, first: &Solution, second: &Solution, constraints: &Constraints) -> bool {
        let tol = self.settings.tol_feas * first.j.amax().max(1.0);
        let feasible = constraints.margin(&second.j) >= constraints.margin(&first.j).min(0.0) - tol;
        let gain = first.objective - second.objective;
        feasible && (0.0..=self.settings.tol_gap_abs).contains(&gain)
    }

    /// One Clarabel call. With `origin = Some((j₀, t))` the variable is `e`, the answer
    /// `j = j₀ + t e`: `(r, z)` are the data in `e` (`z` the residual at `j₀` over `t`), and
    /// the constraints are shifted to `j₀` and divided by `t` (a positive scaling of each
    /// cone). The returned solution is in `j`, its objective `‖r e − z‖²`.
    fn solve_once(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        origin: Option<(&InertiaVector, f64)>,
    ) -> Result<Solution, SolveError> {
        let (j0, t) = origin.map_or((Vector6::zeros(), 1.0), |(j0, t)| (*j0, t));
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
                b.push(-(l.b - l.a.dot(&j0)) / t);
            }
            cones.push(SupportedConeT::NonnegativeConeT(lins.len()));
        }
        for lmi in constraints.lmis() {
            let cols: [[f64; 6]; 6] = core::array::from_fn(|k| svec(&lmi.fk[k]));
            a_rows
                .extend((0..6).map(|row| -> [f64; 6] { core::array::from_fn(|k| -cols[k][row]) }));
            b.extend(svec(&lmi.eval(&j0)).iter().map(|v| v / t));
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
        let e = Vector6::from_iterator(s.x.iter().copied());
        let j = j0 + e * t;
        let primal = (-constraints.margin(&j)).max(0.0);
        Ok(Solution {
            j,
            objective: (r * e - z).norm_squared(),
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
