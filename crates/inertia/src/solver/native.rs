//! The native backend: a log-barrier method on the 6-variable problem.
//!
//! First an exact active-set solve of the linear constraints alone
//! (the `active_set` module); when its answer satisfies the LMIs strictly it is optimal
//! and is returned. Otherwise the barrier method:
//! objective `‖R j − z‖²`, passed to the barrier method in least-squares form (the
//! Newton systems are factored without forming `RᵀR`). The start is the previous
//! answer pulled 1 % towards the constraint set's interior point (strictly feasible by
//! convexity) when warm starting is on, else the interior point itself. Pure Rust, no
//! allocation, `no_std`-capable.

use super::{Backend, Residuals, Solution, SolveError, SolveStatus};
pub use crate::barrier::BarrierSettings;
use crate::barrier::{self, Problem};
use crate::constraints::Constraints;
use crate::tensor::InertiaVector;
use nalgebra::{Matrix6, Vector6};

/// Settings of the native solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NativeSettings {
    /// Barrier-method settings (gap 1e-12 on the objective scaled to `f(0) = 1` by default).
    pub barrier: BarrierSettings,
    /// Start from the previous answer when one is given. Default `true`.
    pub warm_start: bool,
}

impl Default for NativeSettings {
    fn default() -> Self {
        Self {
            barrier: BarrierSettings::default(),
            warm_start: true,
        }
    }
}

/// An invalid native setting.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("native solver setting `{field}` = {value} is invalid: {why}")]
pub struct SettingsError {
    /// Field name.
    pub field: &'static str,
    /// Its value.
    pub value: f64,
    /// What it must be.
    pub why: &'static str,
}

impl NativeSettings {
    /// Check the settings.
    pub(crate) fn validate(&self) -> Result<(), SettingsError> {
        let b = &self.barrier;
        let positive = |field, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(SettingsError {
                    field,
                    value,
                    why: "must be finite and > 0",
                })
            }
        };
        positive("gap_tolerance", b.gap_tolerance)?;
        positive("acceptable_gap", b.acceptable_gap)?;
        if !(b.gap_rel_tolerance >= 0.0) {
            return Err(SettingsError {
                field: "gap_rel_tolerance",
                value: b.gap_rel_tolerance,
                why: "must be >= 0",
            });
        }
        if let Some(t0) = b.t0 {
            positive("t0", t0)?;
        }
        positive("newton_tolerance", b.newton_tolerance)?;
        if !(b.mu.is_finite() && b.mu > 1.0) {
            return Err(SettingsError {
                field: "mu",
                value: b.mu,
                why: "must be finite and > 1",
            });
        }
        if b.max_newton_steps == 0 || b.max_centering_steps == 0 {
            return Err(SettingsError {
                field: "max_newton_steps",
                value: 0.0,
                why: "must be at least 1",
            });
        }
        Ok(())
    }
}

/// The pure-Rust backend.
#[derive(Debug, Clone, Copy, Default)]
pub struct NativeSolver {
    settings: NativeSettings,
    /// The LMI face's last eigendecomposition ([`super::lmi_face::EigenMemo`]).
    memo: super::lmi_face::EigenMemo,
    /// The last answer, when it lay on an LMI face ([`Backend::solve_on_last_face`]).
    last_face: Option<Vector6<f64>>,
}

impl NativeSolver {
    /// A solver with the given (validated) settings.
    pub fn new(settings: NativeSettings) -> Result<Self, SettingsError> {
        settings.validate()?;
        Ok(Self {
            settings,
            memo: super::lmi_face::EigenMemo::default(),
            last_face: None,
        })
    }

    #[cfg(test)]
    pub(crate) fn memo(&self) -> &super::lmi_face::EigenMemo {
        &self.memo
    }

    #[cfg(test)]
    pub(crate) fn last_face(&self) -> Option<Vector6<f64>> {
        self.last_face
    }
}

impl Backend for NativeSolver {
    fn name(&self) -> &'static str {
        "native"
    }

    fn solve_scaled(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        warm: Option<&InertiaVector>,
    ) -> Result<Solution, SolveError> {
        let (sol, on_face) = self.solve_noting_face(r, z, constraints, warm)?;
        self.last_face = on_face.then_some(sol.j);
        Ok(sol)
    }

    fn solve_on_last_face(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        warm: &InertiaVector,
    ) -> Option<Solution> {
        let last = self
            .last_face
            .filter(|j| crate::math::same_bits(j.as_slice(), warm.as_slice()));
        if !self.settings.warm_start || !constraints.lins().is_empty() || last.is_none() {
            return None;
        }
        let found = face_solution(r, z, constraints, warm, 0, &mut self.memo)
            .filter(|(_, margin)| *margin > FACE_FIRST_MARGIN);
        self.last_face = found.map(|(s, _)| s.j);
        found.map(|(s, _)| s)
    }
}

impl NativeSolver {
    /// [`Backend::solve_scaled`], and whether the answer lies on an LMI face.
    fn solve_noting_face(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        warm: Option<&InertiaVector>,
    ) -> Result<(Solution, bool), SolveError> {
        let problem = Problem {
            a: *r,
            b: *z,
            c: Vector6::zeros(),
            lmis: constraints.lmis(),
            lins: constraints.lins(),
        };
        // Exact answer when only linear constraints are active (module docs of
        // `active_set`); the LMIs are then checked, strictly.
        if let Some(a) = super::active_set::solve_linear(r, z, constraints) {
            let lmis_hold = constraints
                .lmis()
                .iter()
                .all(|l| l.eval(&a.j).cholesky().is_some());
            if lmis_hold {
                let sol = Solution {
                    j: a.j,
                    objective: (r * a.j - z).norm_squared(),
                    status: SolveStatus::Optimal,
                    iterations: a.iterations,
                    residuals: Residuals {
                        primal: 0.0,
                        dual: a.dual_residual,
                        gap: a.gap,
                    },
                };
                return Ok((sol, false));
            }
        }
        // One LMI face active: Newton on its KKT system from the previous answer.
        if let Some(w) = warm.filter(|_| self.settings.warm_start) {
            if let Some((sol, _)) = face_solution(r, z, constraints, w, 0, &mut self.memo) {
                return Ok((sol, true));
            }
        }
        let interior = constraints.interior();
        let start = match warm {
            Some(w) if self.settings.warm_start && w.iter().all(|v| v.is_finite()) => {
                let x = w * 0.99 + interior * 0.01;
                if barrier::strictly_feasible(&problem, &x) {
                    x
                } else {
                    *interior
                }
            }
            _ => *interior,
        };
        let out = barrier::solve(&problem, &start, &self.settings.barrier).map_err(|e| {
            SolveError::Failed {
                backend: "native",
                why: match e {
                    barrier::BarrierError::NotInterior => "start point not interior",
                    barrier::BarrierError::Numerical => "singular Newton system",
                },
            }
        })?;
        // Polish: if the barrier answer sits on one LMI face, solve that face exactly.
        if out.converged {
            if let Some((sol, _)) =
                face_solution(r, z, constraints, &out.x, out.newton_steps, &mut self.memo)
            {
                return Ok((sol, true));
            }
        }
        let sol = Solution {
            j: out.x,
            objective: (r * out.x - z).norm_squared(),
            status: if out.converged {
                SolveStatus::Optimal
            } else {
                SolveStatus::Inaccurate
            },
            iterations: out.newton_steps,
            residuals: Residuals {
                primal: 0.0,
                dual: out.dual_residual,
                gap: out.gap,
            },
        };
        Ok((sol, false))
    }
}

/// The least [`super::lmi_face::FaceSolution::multiplier_margin`] for which
/// [`Backend::solve_on_last_face`] gives the face's answer: a thousand times the face
/// solver's dual tolerance. Below it the unconstrained answer could lie on the face to
/// within that tolerance, and the whole way (the fast path first) decides, as it did
/// before the shortcut.
const FACE_FIRST_MARGIN: f64 = 1e-9;

/// Try the exact face solver on each LMI that is nearly active at `start`: the answer
/// and its multiplier margin.
fn face_solution(
    r: &Matrix6<f64>,
    z: &Vector6<f64>,
    constraints: &Constraints,
    start: &InertiaVector,
    prior_steps: u32,
    memo: &mut super::lmi_face::EigenMemo,
) -> Option<(Solution, f64)> {
    let scale = start.amax().max(1.0);
    for (i, l) in constraints.lmis().iter().enumerate() {
        // Only nearly active LMIs: F − 1e-3·scale·I not positive definite.
        let shifted = l.eval(start) - nalgebra::Matrix3::identity() * (1e-3 * scale);
        if shifted.cholesky().is_some() {
            continue;
        }
        if let Some(f) = super::lmi_face::solve(r, z, constraints, i, start, memo) {
            let sol = Solution {
                j: f.j,
                objective: (r * f.j - z).norm_squared(),
                status: SolveStatus::Optimal,
                iterations: prior_steps + f.steps.max(1),
                residuals: Residuals {
                    primal: (-f.eigenvalue).max(0.0),
                    dual: f.dual_residual,
                    gap: (f.mu * f.eigenvalue).abs(),
                },
            };
            return Some((sol, f.multiplier_margin));
        }
    }
    None
}
