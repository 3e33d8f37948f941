//! One estimator over a stream of samples, as history rows: shared by `estimate` and
//! `reproduce`.

use crate::error::{internal, CliError};
use inertia::constraints::{ConstraintSet, Constraints};
use inertia::estimator::momentum::MomentumRls;
use inertia::estimator::observability::Observability;
use inertia::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
use inertia::estimator::rows::{FiniteDifferenceRows, RowSource, VariationalRows};
use inertia::estimator::{Estimate, EstimatorError};
use inertia::sim::scenario::{Scenario, SPIN_J33_NOMINAL, SPIN_J33_TOLERANCE};
use inertia::sim::SimOutput;
use inertia::solver::native::NativeSolver;
use inertia::solver::{Backend, Solution, SolveError};
use inertia::telemetry::Sample;
use inertia::tensor::InertiaVector;
use nalgebra::{Matrix6, Vector6};

/// Which estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum EstimatorKind {
    /// The discrete variational estimator (paper Algorithm 1).
    Variational,
    /// The paper's finite-difference SDP baseline (eq. 26, differenced gyro rates).
    FiniteDifference,
    /// The momentum-based RLS baseline (Norman, Peck & O'Shaughnessy), unconstrained.
    Momentum,
}

impl EstimatorKind {
    /// Display name.
    pub fn name(self) -> &'static str {
        match self {
            EstimatorKind::Variational => "variational",
            EstimatorKind::FiniteDifference => "finite-difference",
            EstimatorKind::Momentum => "momentum",
        }
    }

    /// Whether the estimator needs gyro rates.
    pub fn needs_gyro(self) -> bool {
        !matches!(self, EstimatorKind::Variational)
    }
}

/// Which solver backend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum SolverKind {
    /// Pure-Rust barrier method (default).
    #[default]
    Native,
    /// Clarabel (only in builds with the `clarabel` feature).
    Clarabel,
}

/// A backend chosen at run time.
pub enum AnyBackend {
    /// Native.
    Native(NativeSolver),
    /// Clarabel.
    #[cfg(feature = "clarabel")]
    Clarabel(Box<inertia::solver::clarabel_backend::ClarabelSolver>),
}

impl AnyBackend {
    /// The backend for `kind`, or a message when this build lacks it.
    pub fn new(kind: SolverKind) -> Result<Self, String> {
        match kind {
            SolverKind::Native => Ok(AnyBackend::Native(NativeSolver::default())),
            #[cfg(feature = "clarabel")]
            SolverKind::Clarabel => Ok(AnyBackend::Clarabel(Box::default())),
            #[cfg(not(feature = "clarabel"))]
            SolverKind::Clarabel => Err("this build has no Clarabel backend (rebuild with `--features clarabel`, which needs system OpenBLAS)".into()),
        }
    }
}

impl Backend for AnyBackend {
    fn name(&self) -> &'static str {
        match self {
            AnyBackend::Native(b) => b.name(),
            #[cfg(feature = "clarabel")]
            AnyBackend::Clarabel(b) => b.name(),
        }
    }

    fn solve_scaled(
        &mut self,
        r: &Matrix6<f64>,
        z: &Vector6<f64>,
        constraints: &Constraints,
        warm: Option<&InertiaVector>,
    ) -> Result<Solution, SolveError> {
        match self {
            AnyBackend::Native(b) => b.solve_scaled(r, z, constraints, warm),
            #[cfg(feature = "clarabel")]
            AnyBackend::Clarabel(b) => b.solve_scaled(r, z, constraints, warm),
        }
    }
}

/// Status of one history row.
#[derive(Debug, Clone, PartialEq)]
pub enum RowStatus {
    /// The data determine J.
    Determined,
    /// The prior bounds fix what the data leave open.
    FromPrior(String),
    /// No answer.
    NotObservable(String),
    /// The momentum RLS (no observability test).
    Rls,
}

impl RowStatus {
    /// Short code for CSV and JSON.
    pub fn code(&self) -> &'static str {
        match self {
            RowStatus::Determined => "determined",
            RowStatus::FromPrior(_) => "from_prior",
            RowStatus::NotObservable(_) => "not_observable",
            RowStatus::Rls => "rls",
        }
    }

    /// The reason, if any.
    pub fn reason(&self) -> Option<&str> {
        match self {
            RowStatus::FromPrior(r) | RowStatus::NotObservable(r) => Some(r),
            _ => None,
        }
    }
}

/// One estimate in a history.
#[derive(Debug, Clone, PartialEq)]
pub struct HistoryRow {
    /// Time, s.
    pub t_s: f64,
    /// `j` when an answer exists.
    pub j: Option<InertiaVector>,
    /// Status.
    pub status: RowStatus,
    /// Condition number of R (variational and finite-difference estimators).
    pub condition: Option<f64>,
    /// Solver iterations (0 on the fast path).
    pub iterations: Option<u32>,
    /// Standard deviation per element and per principal moment (variational estimator).
    pub uncertainty: Option<inertia::estimator::uncertainty::Uncertainty>,
}

impl HistoryRow {
    /// From a library estimate.
    pub fn from_estimate(e: &Estimate) -> Self {
        let (status, condition) = match e.observability {
            Observability::Determined { condition } => (RowStatus::Determined, Some(condition)),
            Observability::FromPrior(r) => (RowStatus::FromPrior(r.to_string()), None),
            Observability::NotObservable(r) => (RowStatus::NotObservable(r.to_string()), None),
        };
        Self {
            t_s: e.t_s,
            j: e.j(),
            status,
            condition,
            iterations: e.solution.map(|s| s.iterations),
            uncertainty: None,
        }
    }
}

/// An estimator of any kind.
pub enum Runner {
    /// Variational, with its half-rate shadow (every other sample) for the
    /// discretisation-bias part of the uncertainty, and a sample counter.
    Variational(
        Box<RecursiveEstimator<VariationalRows, AnyBackend>>,
        Box<RecursiveEstimator<VariationalRows, AnyBackend>>,
        usize,
    ),
    /// Finite difference.
    FiniteDifference(Box<RecursiveEstimator<FiniteDifferenceRows, AnyBackend>>),
    /// Momentum.
    Momentum(Box<MomentumRls>, usize),
}

fn recursive<S: RowSource>(
    source: S,
    constraints: Constraints,
    backend: AnyBackend,
    settings: RecursiveSettings,
) -> Result<Box<RecursiveEstimator<S, AnyBackend>>, EstimatorError> {
    Ok(Box::new(RecursiveEstimator::new(
        source,
        constraints,
        backend,
        settings,
    )?))
}

impl Runner {
    /// A new runner with explicit settings.
    pub fn with_settings(
        kind: EstimatorKind,
        constraints: Constraints,
        backend: AnyBackend,
        settings: RecursiveSettings,
    ) -> Result<Self, EstimatorError> {
        let (every, forgetting) = (settings.solve_every, settings.forgetting);
        Ok(match kind {
            EstimatorKind::Variational => {
                let half_backend = match &backend {
                    AnyBackend::Native(b) => AnyBackend::Native(*b),
                    #[cfg(feature = "clarabel")]
                    AnyBackend::Clarabel(b) => AnyBackend::Clarabel(b.clone()),
                };
                // The shadow sees every other sample: twice the step, the same memory. It
                // only measures the slowly varying discretisation bias, so it solves every
                // 8th of its samples (a bias estimate at most 1.6 s old at h = 0.1 s).
                let half_settings = RecursiveSettings {
                    forgetting: settings.forgetting * settings.forgetting,
                    solve_every: settings.solve_every.div_ceil(2).max(8),
                    ..settings
                };
                Runner::Variational(
                    recursive(VariationalRows::default(), constraints, backend, settings)?,
                    recursive(
                        VariationalRows::default(),
                        constraints,
                        half_backend,
                        half_settings,
                    )?,
                    0,
                )
            }
            EstimatorKind::FiniteDifference => Runner::FiniteDifference(recursive(
                FiniteDifferenceRows::default(),
                constraints,
                backend,
                settings,
            )?),
            EstimatorKind::Momentum => Runner::Momentum(
                Box::new(MomentumRls::new(
                    inertia::estimator::momentum::DEFAULT_P0,
                    forgetting,
                )),
                every.max(1),
            ),
        })
    }

    /// The least-squares state (the SDP-based estimators only).
    pub fn qr(&self) -> Option<&inertia::estimator::qr::RecursiveQr> {
        match self {
            Runner::Variational(e, ..) => Some(e.qr()),
            Runner::FiniteDifference(e) => Some(e.qr()),
            Runner::Momentum(..) => None,
        }
    }

    /// Feed a sample; returns a history row when an estimate was produced.
    pub fn push(&mut self, s: &Sample) -> Result<Option<HistoryRow>, EstimatorError> {
        match self {
            Runner::Variational(e, half, n) => {
                if (*n).is_multiple_of(2) {
                    half.push(s)?;
                }
                *n += 1;
                Ok(e.push(s)?.map(|est| {
                    let mut row = HistoryRow::from_estimate(&est);
                    if let (Some(j), Some(noise)) = (est.j(), e.noise_sigma()) {
                        let j_half = half.last().and_then(|h| h.j());
                        row.uncertainty = Some(inertia::estimator::uncertainty::combine(
                            &noise,
                            &j,
                            j_half.as_ref(),
                        ));
                    }
                    row
                }))
            }
            Runner::FiniteDifference(e) => Ok(e.push(s)?.map(|e| HistoryRow::from_estimate(&e))),
            Runner::Momentum(m, every) => {
                let Some(j) = m.push(s) else { return Ok(None) };
                let n = m.updates();
                Ok((n % *every == 0).then_some(HistoryRow {
                    t_s: s.t_s,
                    j: Some(j),
                    status: RowStatus::Rls,
                    condition: None,
                    iterations: None,
                    uncertainty: None,
                }))
            }
        }
    }
}

/// One estimator's history over a run.
pub struct Run {
    /// Display label.
    pub label: &'static str,
    /// File-name stem.
    pub file: &'static str,
    /// Every estimate.
    pub history: Vec<HistoryRow>,
}

/// Labels and file stems of [`paper_estimators`], in its order.
pub const PAPER_ESTIMATOR_NAMES: [(&str, &str); 5] = [
    ("variational", "variational"),
    ("finite difference", "finite_difference"),
    ("momentum", "momentum"),
    ("variational, physical set", "variational_physical"),
    ("variational, bias-compensated", "variational_compensated"),
];

/// The paper's comparison (§VI) on one simulated run: the variational, finite-difference
/// and momentum estimators with the paper's constraint set (the spin case adds J33 within
/// 10 % of 3 kg m² for the SDP-based ones), and the variational estimator with the
/// default physical set.
///
/// A fifth run, beyond the paper, is the variational estimator with errors-in-variables
/// bias compensation for the gyro noise density `gyro_noise_rad_s_rthz` (paper set).
pub fn paper_estimators(
    scenario: &Scenario,
    out: &SimOutput,
    gyro_noise_rad_s_rthz: f64,
) -> Result<Vec<Run>, CliError> {
    let spin = scenario.name() == "spin";
    let bound = |s: ConstraintSet| {
        if spin {
            s.with_nominal(2, SPIN_J33_NOMINAL, SPIN_J33_TOLERANCE)
        } else {
            s
        }
    };
    let plan: [(EstimatorKind, ConstraintSet); 5] = [
        (EstimatorKind::Variational, bound(ConstraintSet::paper())),
        (
            EstimatorKind::FiniteDifference,
            bound(ConstraintSet::paper()),
        ),
        (EstimatorKind::Momentum, ConstraintSet::paper()),
        (EstimatorKind::Variational, bound(ConstraintSet::physical())),
        (EstimatorKind::Variational, bound(ConstraintSet::paper())),
    ];
    let mut runs = Vec::with_capacity(plan.len());
    for ((label, file), (kind, set)) in PAPER_ESTIMATOR_NAMES.into_iter().zip(plan) {
        let c = set.validate().map_err(internal)?;
        let backend = AnyBackend::new(SolverKind::Native).map_err(internal)?;
        let settings = RecursiveSettings {
            gyro_noise_rad_s_rthz: (file == "variational_compensated")
                .then_some(gyro_noise_rad_s_rthz),
            ..RecursiveSettings::default()
        };
        let mut runner = Runner::with_settings(kind, c, backend, settings).map_err(internal)?;
        let mut history = Vec::with_capacity(out.samples.len());
        for s in &out.samples {
            if let Some(r) = runner.push(s).map_err(internal)? {
                history.push(r);
            }
        }
        runs.push(Run {
            label,
            file,
            history,
        });
    }
    Ok(runs)
}
