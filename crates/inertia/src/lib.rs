//! # inertia — on-orbit inertia estimation from attitude telemetry
//!
//! Implements (and extends) Manchester & Peck, *Recursive Inertia Estimation with
//! Semidefinite Programming*. Attitude quaternions `q_k`, rotor momenta `ρ_k` and known
//! torques `τ_k` are turned, through the discrete variational gyrostat equation, into
//! linear rows `H_k j = y_k` in the six inertia components
//! `j = [J11, J22, J33, J12, J13, J23]ᵀ` — with no numerical differentiation of rates.
//!
//! ## The problem
//!
//! ```text
//! minimise_j   ‖H_{1:N} j − y_{1:N}‖²  =  ‖R j − z‖² + const       (eqs. 55, 59)
//! subject to   J(j) − εI ⪰ 0,
//!              Σ(j) = ½ tr(J) I − J ⪰ 0          (physical consistency, docs/conventions.md §4)
//!              or the paper's J11 + J22 ≥ J33 (and cyclic)            (eq. 9)
//!              l_i ≤ j_i ≤ u_i                    (a-priori bounds)
//! H_k = N(φ_{k+1}) G(φ_{k+1}) − M(φ_k) G(φ_k)                          (eq. 53)
//! y_k = M(φ_k) h/2 ρ̄_k − N(φ_{k+1}) h/2 ρ̄_{k+1} + h²/2 τ_{k+1}         (eq. 54, docs/conventions.md §1)
//! ```
//!
//! ## Conventions
//!
//! * **Units: SI.** Time s, angles rad, rates rad/s, rotor momentum N m s, torque N m,
//!   inertia kg m². Noise spectral densities carry their units in their names
//!   (`gyro_noise_deg_s_rthz` is deg/s/√Hz, `disturbance_nm_rthz` is N m/√Hz).
//! * **Frames:** every vector (ω, ρ, τ) and J are in body axes; the inertial frame appears
//!   only through the attitude.
//! * **Quaternions:** `[x, y, z, w]`, scalar **last**, Hamilton product, mapping **body →
//!   inertial**: `x_I = q x_B q†`. Scalar-first and JPL/Shuster inputs are converted by
//!   named constructors in [`attitude`]; nothing converts implicitly.
//! * **Intervals and nodes:** `φ_k = vec(q_k† q_{k+1})` (scalar part made ≥ 0) belongs to
//!   `[t_k, t_{k+1}]`; `ρ̄_k` is the trapezoid mean of the node samples over that interval;
//!   `τ_{k+1}` is the node value; a gyro rate in telemetry is the average over the interval
//!   that starts at its node.
//!
//! ## Example: estimate J from a simulated slew
//!
//! ```
//! use inertia::constraints::ConstraintSet;
//! use inertia::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
//! use inertia::estimator::rows::VariationalRows;
//! use inertia::sim::scenario::{Common, Scenario};
//! use inertia::solver::native::NativeSolver;
//! use inertia::tensor::relative_frobenius_error;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // 120 s of the paper's slew manoeuvres at its noise levels.
//! let run = Scenario::slew().simulate(&Common { duration_s: Some(120.0), ..Common::paper() })?;
//! // J ⪰ εI and Σ = ½ tr(J) I − J ⪰ 0, checked before any data is read.
//! let constraints = ConstraintSet::physical().validate()?;
//! let mut estimator = RecursiveEstimator::new(
//!     VariationalRows::default(),
//!     constraints,
//!     NativeSolver::default(),
//!     RecursiveSettings::default(),
//! )?;
//! for sample in &run.samples {
//!     estimator.push(sample)?; // Some(estimate) at every sample once J is observable
//! }
//! let estimate = estimator.last().expect("estimates");
//! let j = estimate.inertia().expect("the data determine J");
//! assert!(relative_frobenius_error(&j, &run.inertia_kg_m2) < 1e-3);
//! # Ok(())
//! # }
//! ```
//!
//! ## Modules
//!
//! * [`attitude`] — quaternion algebra (§II.C, eqs. 18–25);
//! * [`tensor`] — J ↔ j, principal moments, physical consistency (eqs. 7–9, 48);
//! * [`dynamics`] — the gyrostat equation and an RK4 step (eq. 26);
//! * [`discrete`] — G, M, N and the rows H_k, y_k (eqs. 47–54);
//! * [`telemetry`] — the sample record;
//! * [`constraints`] — the feasible set (eqs. 9, 55, 57, docs/conventions.md §4, prior bounds);
//! * [`solver`] — constrained least squares (eqs. 57, 59): the native solver (fast path,
//!   active set, one-LMI-face Newton, barrier method) and Clarabel (feature `clarabel`);
//! * [`estimator`] — Algorithm 1 (recursive), eq. 57 (batch), the finite-difference and
//!   momentum baselines, observability (eqs. 58–61, §VI); beyond the paper:
//!   errors-in-variables compensation, uncertainty, excitation diagnostics, resampling of
//!   irregular telemetry;
//! * `sim` (feature `sim`) — simulator, sensors and the §VI scenarios.

#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]
#![warn(unnameable_types)]
// Dead code is judged on the default build: with fewer features some helpers lose the
// callers that the missing modules (pipeline, simulator, reader) hold.
#![cfg_attr(
    not(all(feature = "sim", feature = "csv", feature = "spacecraft")),
    allow(dead_code)
)]

pub mod attitude;
mod barrier;
#[cfg(feature = "std")]
pub mod choice;
pub mod constraints;
pub mod discrete;
pub(crate) mod discrete_momentum;
pub mod dynamics;
mod eigen3;
pub mod error_kind;
pub mod estimator;
#[cfg(feature = "std")]
mod estimators;
pub mod fix;
mod givens;
mod householder;
mod math;
#[cfg(feature = "std")]
pub mod pipeline;
#[cfg(feature = "std")]
pub mod plan;
#[cfg(feature = "serde")]
pub mod run_description;
pub mod sample;
#[cfg(feature = "sim")]
pub mod sim;
pub mod solver;
#[cfg(feature = "std")]
pub mod spacecraft;
pub mod telemetry;
pub mod tensor;
#[cfg(test)]
mod testing;
pub mod text;
