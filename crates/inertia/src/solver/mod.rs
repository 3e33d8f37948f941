//! Constrained least squares over the inertia components (paper eqs. 57, 59).
//!
//! ```text
//! minimise_j  ‖R j − z‖²   subject to  j ∈ C   (a validated constraint set)
//! ```
//!
//! with `R` 6×6 upper triangular from the QR factor of the stacked rows (eqs. 58–61).
//! The paper writes this as an SDP through a Schur-complement LMI (eq. 14); every backend
//! here takes the quadratic objective directly, which is equivalent and better conditioned.
//!
//! [`solve`] is the one entry point. It
//! 1. rejects non-finite data;
//! 2. takes the **fast path**: when `R` is well enough conditioned for a triangular solve
//!    and the unconstrained minimiser `R⁻¹ z` is strictly feasible, it is returned exactly,
//!    with no iterations ([`SolveStatus::Unconstrained`]). Where the warm start is the
//!    backend's last answer and that answer lay on an LMI face (a recursive run whose
//!    data sit just outside the set, as the paper's slew does), that face is tried first
//!    ([`Backend::solve_on_last_face`]): the fast path would fail there, and the face's
//!    Newton steps are what the backend would take next. Its answer is taken only where
//!    the objective presses on the face a thousand times more clearly than the face
//!    solver's dual tolerance (`multiplier_margin`); otherwise the fast path follows, as
//!    before. Both could succeed only where the face solver's tolerance, magnified by an
//!    ill-conditioned `R`, cannot separate the face from the interior;
//! 3. otherwise scales the data so that the objective is O(1) (`σ² = ‖z‖²`, the
//!    objective at j = 0; when `z = 0`, `‖R‖²_F ‖j_c‖²` with `j_c` the constraint set's
//!    interior point) and hands `(R/σ, z/σ)` to a [`Backend`].
//!
//! Backends: [`native::NativeSolver`] (pure Rust, default) and, with the `clarabel`
//! feature, `clarabel_backend::ClarabelSolver` (the reference conic solver).

mod active_set;
#[cfg(feature = "clarabel")]
pub mod clarabel_backend;
mod lmi_face;
pub mod native;

use crate::constraints::Constraints;
use crate::tensor::InertiaVector;
use nalgebra::{Matrix6, Vector6};

/// How a solution was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum SolveStatus {
    /// The unconstrained minimiser is strictly feasible and was returned exactly.
    Unconstrained,
    /// Solved to the backend's tolerances.
    Optimal,
    /// Stopped at an iteration limit; the point is feasible but less accurate.
    Inaccurate,
    /// A recursive least-squares update with no constraints and no solve (the momentum
    /// RLS baseline).
    RecursiveLeastSquares,
}

/// Optimality residuals of an answer, in the scaled problem's units (objective O(1)).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Residuals {
    /// Largest constraint violation, kg m² (0 for strictly feasible answers).
    pub primal: f64,
    /// Dual residual (stationarity of the Lagrangian) relative to the objective's
    /// gradient.
    pub dual: f64,
    /// Complementarity (duality) gap, scaled units.
    pub gap: f64,
}

/// A solver's answer.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Solution {
    /// The estimate `j`, kg m².
    pub j: InertiaVector,
    /// `‖R j − z‖²` in the original units (0 for the momentum RLS, which has no `R`).
    pub objective: f64,
    /// How it was obtained.
    pub status: SolveStatus,
    /// Iterations of the backend (0 on the fast path).
    pub iterations: u32,
    /// Optimality residuals.
    pub residuals: Residuals,
}

/// Why a solve failed.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SolveError {
    /// `R` or `z` has NaN or infinite entries.
    #[error("the least-squares data contain NaN or infinite values")]
    NonFinite,
    /// The backend failed numerically.
    #[error("{backend} solver failed: {why}")]
    Failed {
        /// Backend name.
        backend: &'static str,
        /// What went wrong.
        why: &'static str,
    },
}

/// A constrained least-squares backend for `minimise ‖R j − z‖², j ∈ C`, on data already
/// scaled by [`solve`] (objective O(1)). `warm` is the previous answer, if any.
pub trait Backend {
    /// Short name, e.g. `native` or `clarabel`.
    fn name(&self) -> &'static str;

    /// Solve the scaled problem.
    fn solve_scaled(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        warm: Option<&InertiaVector>,
    ) -> Result<Solution, SolveError>;

    /// The scaled problem's answer on the LMI face that this backend's last answer lay
    /// on, when `warm` is that answer bit for bit, there are no linear constraints and
    /// the objective clearly presses on the face (module docs, step 2); `None`
    /// otherwise ([`solve`] then takes the fast path and the backend as before).
    /// Provided: always `None`.
    fn solve_on_last_face(
        &mut self,
        _r: &Matrix6<f64>,
        _z: &Vector6<f64>,
        _constraints: &Constraints,
        _warm: &InertiaVector,
    ) -> Option<Solution> {
        None
    }
}

/// The one definition of "singular" in this crate: a triangular pivot `|R_ii|` or a
/// singular value of `R` below this fraction of the largest counts as absent. The fast
/// path refuses a triangular solve past it, and the observability test counts the rank
/// with it. (How *weak* a present direction may be before J counts as undetermined is
/// the observability test's condition threshold, which the excitation report shares.)
pub(crate) const SINGULAR_RATIO: f64 = 1e-10;

/// The unconstrained minimiser `R⁻¹ z` of an upper-triangular `R` by back substitution,
/// or `None` when a pivot is below `SINGULAR_RATIO` of the largest.
#[must_use]
pub(crate) fn unconstrained_minimiser(r: &Matrix6<f64>, z: &Vector6<f64>) -> Option<InertiaVector> {
    let dmax = r.diagonal().amax();
    if !(dmax > 0.0) {
        return None;
    }
    let mut x = Vector6::zeros();
    for i in (0..6).rev() {
        let d = r[(i, i)];
        if d.abs() <= SINGULAR_RATIO * dmax {
            return None;
        }
        let mut s = z[i];
        for k in i + 1..6 {
            s -= r[(i, k)] * x[k];
        }
        x[i] = s / d;
    }
    Some(x)
}

/// A least-squares pair with the fixed elements eliminated ([`eliminate_fixed`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Eliminated {
    /// Upper-triangular factor of the reduced problem (with the rows `c x_k = c v_k`).
    pub(crate) r: Matrix6<f64>,
    /// Its right-hand side.
    pub(crate) z: Vector6<f64>,
    /// Residual sum of squares the fixed values add (the data's least-squares `j` need
    /// not have those values).
    pub(crate) extra_rss: f64,
    /// Number of fixed elements.
    pub(crate) fixed: usize,
    /// `c`, the scale of the fixed elements' rows.
    pub(crate) scale: f64,
}

/// Eliminate the elements fixed by equalities from `‖R j − z‖²`: with `j = j_f + P x`
/// (`P` keeps the free elements, `j_f` holds the fixed values) the objective is
/// `‖R P x − (z − R j_f)‖²`, whose columns of the fixed elements are zero. Each fixed
/// element then gets the row `c x_k = c v_k`, `c` the root-mean-square column norm of
/// `R P` (1 when it is zero), so that the returned triangular pair has the reduced
/// problem's singular values besides `c`, and the fixed values as its exact minimiser in
/// those coordinates.
#[must_use]
pub(crate) fn eliminate_fixed(
    r: &Matrix6<f64>,
    z: &Vector6<f64>,
    fixed: &[Option<f64>; 6],
) -> Eliminated {
    let mut out = Eliminated {
        r: *r,
        z: *z,
        extra_rss: 0.0,
        fixed: 0,
        scale: 1.0,
    };
    let mut free_norm2 = 0.0;
    let mut n_free = 0usize;
    for (k, v) in fixed.iter().enumerate() {
        match v {
            Some(v) => {
                out.z -= r.column(k) * *v;
                out.r.column_mut(k).fill(0.0);
                out.fixed += 1;
            }
            None => {
                free_norm2 += r.column(k).norm_squared();
                n_free += 1;
            }
        }
    }
    if out.fixed == 0 {
        return out;
    }
    if n_free > 0 && free_norm2 > 0.0 {
        out.scale = crate::math::sqrt(free_norm2 / n_free as f64);
    }
    let c = out.scale;
    for (k, v) in fixed.iter().enumerate() {
        if let Some(v) = v {
            let left = crate::givens::fold_row(
                &mut out.r,
                &Vector6::ith(k, c),
                Some((&mut out.z, c * *v)),
            );
            out.extra_rss += left * left;
        }
    }
    out
}

/// Solve `minimise ‖R j − z‖², j ∈ C` with `backend` (see the module docs). Elements
/// fixed by an equality are eliminated (`eliminate_fixed`) and returned exactly.
pub fn solve(
    backend: &mut dyn Backend,
    r: &Matrix6<f64>,
    z: &Vector6<f64>,
    constraints: &Constraints,
    warm: Option<&InertiaVector>,
) -> Result<Solution, SolveError> {
    if !r.iter().chain(z.iter()).all(|v| v.is_finite()) {
        return Err(SolveError::NonFinite);
    }
    if constraints.fixed().iter().any(Option::is_some) {
        let e = eliminate_fixed(r, z, constraints.fixed());
        let warm = warm.map(|w| constraints.with_fixed(w));
        let mut sol = solve_free(backend, &e.r, &e.z, constraints, warm.as_ref())?;
        sol.j = constraints.with_fixed(&sol.j);
        sol.objective = (r * sol.j - z).norm_squared();
        return Ok(sol);
    }
    solve_free(backend, r, z, constraints, warm)
}

fn solve_free(
    backend: &mut dyn Backend,
    r: &Matrix6<f64>,
    z: &Vector6<f64>,
    constraints: &Constraints,
    warm: Option<&InertiaVector>,
) -> Result<Solution, SolveError> {
    let sigma = objective_scale(r, z, constraints);
    if let Some(w) = warm.filter(|_| constraints.lins().is_empty()) {
        if let Some(mut sol) =
            backend.solve_on_last_face(&(r / sigma), &(z / sigma), constraints, w)
        {
            sol.objective = (r * sol.j - z).norm_squared();
            return Ok(sol);
        }
    }
    if let Some(j) = unconstrained_minimiser(r, z) {
        if constraints.strictly_feasible(&j) {
            return Ok(Solution {
                j,
                objective: (r * j - z).norm_squared(),
                status: SolveStatus::Unconstrained,
                iterations: 0,
                residuals: Residuals::default(),
            });
        }
    }
    let mut sol = backend.solve_scaled(&(r / sigma), &(z / sigma), constraints, warm)?;
    sol.objective = (r * sol.j - z).norm_squared();
    Ok(sol)
}

/// The scale `σ` of the data handed to a backend (module docs, step 3).
fn objective_scale(r: &Matrix6<f64>, z: &Vector6<f64>, constraints: &Constraints) -> f64 {
    let zn = z.norm_squared();
    let sigma2 = if zn > 0.0 {
        zn
    } else {
        r.norm_squared() * constraints.interior().norm_squared()
    };
    if sigma2 > 0.0 {
        crate::math::sqrt(sigma2)
    } else {
        1.0
    }
}

/// A borrowed backend is a backend (so that an unsized one can be handed to [`solve`]).
impl<B: Backend + ?Sized> Backend for &mut B {
    fn name(&self) -> &'static str {
        (**self).name()
    }

    fn solve_scaled(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        warm: Option<&InertiaVector>,
    ) -> Result<Solution, SolveError> {
        (**self).solve_scaled(r, z, constraints, warm)
    }

    fn solve_on_last_face(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        warm: &InertiaVector,
    ) -> Option<Solution> {
        (**self).solve_on_last_face(r, z, constraints, warm)
    }
}

#[cfg(feature = "std")]
impl<B: Backend + ?Sized> Backend for std::boxed::Box<B> {
    fn name(&self) -> &'static str {
        (**self).name()
    }

    fn solve_scaled(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        warm: Option<&InertiaVector>,
    ) -> Result<Solution, SolveError> {
        (**self).solve_scaled(r, z, constraints, warm)
    }

    fn solve_on_last_face(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        warm: &InertiaVector,
    ) -> Option<Solution> {
        (**self).solve_on_last_face(r, z, constraints, warm)
    }
}
