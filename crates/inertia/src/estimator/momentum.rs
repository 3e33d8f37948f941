//! The momentum-based recursive least-squares baseline (Norman, Peck & O'Shaughnessy
//! 2011, inertia part; paper §VI).
//!
//! Inertial angular momentum is conserved up to the known external torque:
//!
//! ```text
//! C(q_k) (J ω_k + ρ_k) − h_N = ∫_0^{t_k} C(q) τ dt
//! ⇒ [C(q_k) G(ω_k), −I] [j; h_N] = ∫_0^{t_k} C(q) τ dt − C(q_k) ρ_k
//! ```
//!
//! with unknowns `j` and the initial inertial momentum `h_N`, the node rate `ω_k` the mean
//! of the gyro rates of the two adjacent intervals, and the torque integral by the
//! trapezoid rule. Standard covariance-form RLS from `x = 0` with a large initial
//! covariance `P_0 = p0 I`, optional forgetting with a memory in seconds (each update
//! weighs the past by `exp(−Δt/memory)`, `Δt` the actual step), no constraints.
//!
//! The baseline makes no observability test: its estimates carry
//! [`Observability::Unchecked`]. A non-finite state is reported as
//! [`Unobservable::Diverged`], and a J that is not a physical inertia (a principal moment
//! ≤ 0, or a broken triangle inequality) as [`Unobservable::NotPhysical`]: never as an
//! answer.

use super::observability::{Observability, Unobservable};
use super::{Estimate, EstimatorError, InvalidArgument};
use crate::discrete::{g_matrix, RowError};
use crate::sample::Sample;
use crate::solver::{Residuals, Solution, SolveStatus};
use crate::tensor::{matrix_from_j, InertiaVector};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Relative tolerance of the triangle test of [`not_physical`]: `Σ`'s smallest eigenvalue
/// may be down to `−1e-3 · tr(J)`.
pub(crate) const NOT_PHYSICAL_TOLERANCE: f64 = 1e-3;

/// Why a finite `j` is not a physical inertia, if it is not: a principal moment ≤ 0, or
/// `Σ = ½ tr(J) I − J` below `−NOT_PHYSICAL_TOLERANCE · tr(J)` (a triangle inequality of
/// the principal moments broken; docs/conventions.md §4).
#[must_use]
pub fn not_physical(j: &InertiaVector) -> Option<Unobservable> {
    let m = matrix_from_j(j);
    let min_moment_kg_m2 = crate::eigen3::symmetric_eigen3(&m).0.min();
    let sigma = Matrix3::identity() * (0.5 * m.trace()) - m;
    let min_second_moment_kg_m2 = crate::eigen3::symmetric_eigen3(&sigma).0.min();
    // A flat body's J sits on the triangle boundary (the paper's nearly does): there a
    // violation within the noise is not a refusal.
    let tolerance = NOT_PHYSICAL_TOLERANCE * crate::math::abs(m.trace());
    (!(min_moment_kg_m2 > 0.0 && min_second_moment_kg_m2 >= -tolerance)).then_some(
        Unobservable::NotPhysical {
            min_moment_kg_m2,
            min_second_moment_kg_m2,
        },
    )
}

/// Default initial covariance scale (units of the unknowns squared).
pub(crate) const DEFAULT_P0: f64 = 1e6;

/// Settings of the momentum RLS.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MomentumSettings {
    /// Initial covariance `P_0 = p0 I` (default `DEFAULT_P0`); finite and > 0.
    pub p0: f64,
    /// Memory time constant, s (`None`, the default: no forgetting); finite and > 0.
    pub memory_s: Option<f64>,
}

impl Default for MomentumSettings {
    fn default() -> Self {
        Self {
            p0: DEFAULT_P0,
            memory_s: None,
        }
    }
}

/// The RLS state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MomentumRls {
    x: SVector<f64, 9>,
    p: SMatrix<f64, 9, 9>,
    memory_s: Option<f64>,
    prev: Option<(Sample, Vector3<f64>)>,
    torque_integral: Vector3<f64>,
    samples: usize,
    updates: usize,
}

impl Default for MomentumRls {
    fn default() -> Self {
        Self::from_valid(MomentumSettings::default())
    }
}

impl MomentumRls {
    /// A new estimator; rejects a non-positive or non-finite `p0` or memory.
    pub fn new(settings: MomentumSettings) -> Result<Self, InvalidArgument> {
        if !(settings.p0.is_finite() && settings.p0 > 0.0) {
            return Err(InvalidArgument {
                name: "p0",
                value: settings.p0,
                expected: "a finite initial covariance > 0",
            });
        }
        if let Some(m) = settings.memory_s {
            if !(m.is_finite() && m > 0.0) {
                return Err(InvalidArgument {
                    name: "memory_s",
                    value: m,
                    expected: "a finite memory > 0 s",
                });
            }
        }
        Ok(Self::from_valid(settings))
    }

    fn from_valid(settings: MomentumSettings) -> Self {
        Self {
            x: SVector::zeros(),
            p: SMatrix::identity() * settings.p0,
            memory_s: settings.memory_s,
            prev: None,
            torque_integral: Vector3::zeros(),
            samples: 0,
            updates: 0,
        }
    }

    /// Feed a sample; returns the current estimate once a row has been used.
    ///
    /// The row at node k needs the gyro rate of interval k−1, so the first sample only
    /// primes the state. A sample without a gyro rate is an error
    /// ([`RowError::MissingGyroRate`]).
    pub fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        let index = self.samples;
        self.samples += 1;
        let rate = gyro_sample(s, index)?;
        let c = s.q.to_matrix();
        let out = if let Some((prev, prev_rate)) = self.prev {
            let dt = s.t_s - prev.t_s;
            self.torque_integral += 0.5 * dt * (prev.q.rotate(&prev.tau_nm) + c * s.tau_nm);
            let w = 0.5 * (prev_rate + rate);
            let mut a = SMatrix::<f64, 3, 9>::zeros();
            a.fixed_view_mut::<3, 6>(0, 0)
                .copy_from(&(c * g_matrix(&w)));
            a.fixed_view_mut::<3, 3>(0, 6)
                .copy_from(&(-Matrix3::identity()));
            let b = self.torque_integral - c * s.rho_nms;
            let lambda = self.memory_s.map_or(1.0, |m| libm::exp(-dt / m));
            self.update(&a, &b, lambda);
            self.updates += 1;
            Some(self.estimate(s.t_s))
        } else {
            None
        };
        self.prev = Some((*s, rate));
        Ok(out)
    }

    fn estimate(&self, t_s: f64) -> Estimate {
        let j = self.j();
        let finite = j.iter().all(|v| v.is_finite());
        let observability = if !finite {
            Observability::NotObservable(Unobservable::Diverged)
        } else if let Some(reason) = not_physical(&j) {
            Observability::NotObservable(reason)
        } else {
            Observability::Unchecked
        };
        Estimate {
            t_s,
            rows: 3 * self.updates,
            solution: observability.has_answer().then_some(Solution {
                j,
                objective: 0.0,
                status: SolveStatus::RecursiveLeastSquares,
                iterations: 0,
                residuals: Residuals::default(),
            }),
            uncertainty: None,
            prior: None,
            observability,
        }
    }

    fn update(&mut self, a: &SMatrix<f64, 3, 9>, b: &Vector3<f64>, lambda: f64) {
        let pa = self.p * a.transpose();
        let s = Matrix3::identity() * lambda + a * pa;
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        let k = pa * s_inv;
        self.x += k * (b - a * self.x);
        self.p = (self.p - k * a * self.p) / lambda;
        self.p = (self.p + self.p.transpose()) * 0.5;
    }

    /// Current `j`.
    #[must_use]
    pub(crate) fn j(&self) -> InertiaVector {
        InertiaVector::from_fn(|i, _| self.x[i])
    }

    /// Current J, kg m².
    #[must_use]
    pub fn inertia(&self) -> Matrix3<f64> {
        matrix_from_j(&self.j())
    }

    /// Row blocks used so far.
    #[must_use]
    pub(crate) fn updates(&self) -> usize {
        self.updates
    }
}

/// The gyro rate of sample `index`, checking what an estimator of gyro rates uses: a rate
/// present ([`RowError::MissingGyroRate`]) and finite time, rate, rotor momentum and
/// torque ([`RowError::NonFinite`]).
pub(crate) fn gyro_sample(s: &Sample, index: usize) -> Result<Vector3<f64>, EstimatorError> {
    let row_error = |source| EstimatorError::Row {
        sample: index,
        source,
    };
    let rate = s.omega_rad_s.ok_or(row_error(RowError::MissingGyroRate))?;
    if !rate
        .iter()
        .chain(s.rho_nms.iter())
        .chain(s.tau_nm.iter())
        .chain(core::iter::once(&s.t_s))
        .all(|v| v.is_finite())
    {
        return Err(row_error(RowError::NonFinite {
            what: "time, gyro rate, rotor momentum or torque",
        }));
    }
    Ok(rate)
}
