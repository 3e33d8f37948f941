//! The discrete momentum estimator (beyond the paper): the rows of
//! [`super::momentum_rows`] in a fixed-size QR over `[X₀; X₁; τ_b; κ; j]`
//! (`super::augmented_qr`), the nuisance unknowns minimised out exactly (the torque
//! `τ_b` held at zero instead where the data give no evidence of one, `torque_tested`),
//! and the same observability test, constraint sets and solvers as Algorithm 1 on the
//! reduced problem in `j`.
//!
//! * [`DiscreteMomentumEstimator`] — recursive, no allocation per sample;
//! * `reduce_batch` — every row stacked, one dense Householder QR per chain and one for
//!   the shared unknowns: an independent code path that must agree with the recursive one.

use super::augmented_qr::AugmentedQr;
use super::chain_clock::ChainClock;
use super::external_torque::{Estimated3, OutsideEstimates};
use super::jackknife::ChainGroups;
use super::momentum_rows::{
    AugmentedRow, MomentumRowSettings, MomentumRows, CENTRE_OF_MASS, DAMPING, DIPOLE, TORQUE,
};

use crate::tensor::InertiaVector;

const _: () = assert!(
    super::unknowns::Block::Damping.column() + 1 == super::unknowns::Block::J.column(),
    "DampingRow: D is the last unknown before j"
);
use super::qr::RecursiveQr;
use super::recursive::{estimate_from, RecursiveSettings};
use super::svd_tracker::SvdTracker;
use super::{Estimate, EstimatorError};
use crate::constraints::Constraints;
use crate::sample::Sample;
use crate::solver::Backend;
use nalgebra::{Vector3, Vector6};

/// The 1 − 10⁻³ quantile of χ²₃: below it, the data give no evidence of a constant
/// disturbance torque (`torque_tested`).
pub const TORQUE_CHI2: f64 = 16.27;

/// A torque the χ² test keeps is still held at zero where holding it moves no element of
/// the answer by more than this many of the answer's jackknife σ (`torque_tested`).
pub const TORQUE_SHIFT_Z: f64 = 5.0;

/// The outcome of the test for a constant disturbance torque at a solve.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TorqueTest {
    /// `Δρ²/s²`: how much of the residual the torque unknowns explain, in noise
    /// variances (χ²₃ when there is no torque and the rows' errors are independent; with
    /// several records' torques, put on χ²₃'s scale at the test's threshold,
    /// `equivalent_chi2_scale` in the batch reduction).
    pub chi2: f64,
    /// Whether `τ_b` was held at zero (`chi2 ≤` [`TORQUE_CHI2`], or the answer's shift
    /// within [`TORQUE_SHIFT_Z`] of its σ).
    pub held_at_zero: bool,
    /// The largest shift of an element of the answer when the torque is held at zero,
    /// in the answer's jackknife σ; `None` where the χ² test decided alone.
    pub shift_z: Option<f64>,
    /// Whether the answer's σ carries that shift as model uncertainty: where the torque
    /// was held at zero by it, or kept while the two models' residual variances are ones
    /// the data do not tell apart ([`models_told_apart`]).
    pub shift_in_sigma: bool,
    /// That shift per element, `|ĵ − ĵ|τ_b=0|`, kg m², where [`Self::shift_in_sigma`]:
    /// the model uncertainty the answer's σ carries.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub model_shift_kg_m2: Option<[f64; 6]>,
}

/// Whether the residual variances with and without the torque differ by more than the
/// data's own resolution, the rule by which the discrete momentum estimator's candidate
/// row models are told apart: relative `1 + 3√(2/ν)` with `ν` residual degrees of
/// freedom. Holding the torque adds `χ²` noise variances to `ρ²` and frees 3 degrees of
/// freedom, so the variance grows by the factor `(1 + χ²/ν)(1 − 3/ν) ≈ 1 + (χ² − 3)/ν`,
/// and the models are told apart where `χ² − 3 > 3√(2ν)`. It is looser than the χ²
/// test, which assumes independent errors: errors correlated along the chain (vibration
/// beating with held wheel speeds) raise `χ²` without a torque.
#[must_use]
pub fn models_told_apart(chi2: f64, dof: f64) -> bool {
    chi2 - 3.0 > 3.0 * crate::math::sqrt(2.0 * dof.max(0.0))
}

/// The reduced state to solve, and the torque test: `with` has the disturbance torque
/// `τ_b` minimised out, `without` (when the torque is estimated at all) holds it at zero,
/// with the growth of `ρ²` that costs (`super::shared_qr::SharedQr::reduced_without_torque`).
///
/// A nested-model test (beyond the paper): with `s² = ρ²/ν` of `with`, `Δρ²/s²` is
/// χ²-distributed with 3 degrees of freedom when there is no torque. There is no test
/// (`None`, the torque estimated) where that is not a finite number: no residual degrees
/// of freedom yet, rows fitted exactly, or a non-finite state. At or below
/// [`TORQUE_CHI2`] the data give no evidence of one and `τ_b` is held at zero: three
/// unknowns fewer, measured in the README's matrix to lower the median error in 43 of
/// 58 cells and raise it in 8, by at most 3 % (the paper's spin 3.0e-6 → 2.8e-6, four
/// of the 1 Hz spins by 2–3×).
///
/// Errors correlated along the chain (a propagated attitude's random walk, a short
/// record's vibration) make `s²` too small and the statistic too large, which errs
/// toward keeping a torque that is not there, and three unknowns more cost a short record
/// 5–10× its error. So where the χ² test keeps the torque and the answer has a jackknife
/// σ (`sigma`, `super::jackknife`: correlated errors count there as they are), the
/// torque is held at zero unless holding it moves some element of the answer by more than
/// [`TORQUE_SHIFT_Z`] of that σ: the torque must matter to the answer, not only to the
/// residuals. The held answer's σ then carries the move `|ĵ − ĵ|τ_b=0|`
/// ([`TorqueTest::model_shift_kg_m2`]), the two models being ones the data do not tell
/// apart. Where the torque moves the answer by more and is kept, its σ carries the same
/// move unless the residual variances tell the two models apart
/// ([`models_told_apart`]): the kept answer is then no better founded than the held
/// one (on the lab throw whose vibration beats with its held wheel speeds, a spurious
/// 1e-4 N m torque moved J12 by 5–6 of its jackknife σ, away from the truth). A real
/// torque is told apart by far (the 1e-5 N m on the slew: χ²₃ > 1,600 against 400).
/// The move is taken with the prior knowledge of `constraints` stacked on, as the
/// answer is. (Measuring the move against its own jackknife σ instead fails where the
/// torque is real: the delete-one answers without it then scatter with the torque's
/// effect on each group, and a 1e-5 N m torque on the slew was dropped at 1e-2 error.)
#[must_use]
pub(crate) fn torque_tested(
    with: RecursiveQr,
    without: Option<(RecursiveQr, f64)>,
    sigma: Option<[f64; 6]>,
    constraints: &Constraints,
) -> (RecursiveQr, Option<TorqueTest>) {
    let Some((without, growth)) = without else {
        return (with, None);
    };
    // No test without a noise scale (no residual degrees of freedom, or rows fitted
    // exactly) or on a non-finite state: the torque stays as set.
    let s2 = with.residual_variance();
    let chi2 = growth / s2;
    if !(s2.is_finite() && s2 > 0.0 && chi2.is_finite() && chi2 >= 0.0) {
        return (with, None);
    }
    let mut test = TorqueTest {
        chi2,
        held_at_zero: chi2 <= TORQUE_CHI2,
        shift_z: None,
        shift_in_sigma: false,
        model_shift_kg_m2: None,
    };
    if !test.held_at_zero {
        if let Some((d, z)) = sigma.and_then(|sd| shift(&with, &without, &sd, constraints)) {
            test.shift_z = Some(z);
            test.held_at_zero = z <= TORQUE_SHIFT_Z;
            if test.held_at_zero || !models_told_apart(chi2, with.residual_dof()) {
                test.shift_in_sigma = true;
                test.model_shift_kg_m2 = Some(d.map(f64::abs));
            }
        }
    }
    (if test.held_at_zero { without } else { with }, Some(test))
}

/// The shift `d = ĵ − ĵ|τ_b=0` of the unconstrained answers, with prior knowledge, and
/// its largest `|d_k|/σ_k` over the elements with `σ_k > 0`.
fn shift(
    with: &RecursiveQr,
    without: &RecursiveQr,
    sigma: &[f64; 6],
    constraints: &Constraints,
) -> Option<([f64; 6], f64)> {
    let solve = |qr: &RecursiveQr| {
        let a = super::prior::augment(qr, constraints).0;
        crate::solver::unconstrained_minimiser(&a.r, &a.z)
    };
    let d = solve(with)? - solve(without)?;
    // NaN is kept (no test then), and without an element with σ > 0 there is none.
    let z = (0..6)
        .filter(|&k| sigma[k] > 0.0)
        .map(|k| d[k].abs() / sigma[k])
        .reduce(|a, b| {
            if a.is_nan() || b.is_nan() {
                f64::NAN
            } else {
                a.max(b)
            }
        })?;
    z.is_finite().then(|| (core::array::from_fn(|k| d[k]), z))
}

/// Settings of the discrete momentum estimator.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MomentumEstimatorSettings {
    /// How rows are formed.
    pub rows: MomentumRowSettings,
    /// Solve cadence, memory, observability thresholds, and the gyro rate-noise density
    /// for errors-in-variables compensation (`super::compensation` with the rows'
    /// `super::momentum_rows::AugmentedRow::noise_s`).
    pub recursive: RecursiveSettings,
}

impl MomentumEstimatorSettings {
    /// Check the settings.
    pub(crate) fn validate(&self) -> Result<(), EstimatorError> {
        if !self.rows.outside.valid() {
            return Err(EstimatorError::InvalidSetting {
                field: "rows.outside.gravity_mu_m3_s2",
                why: "must be finite and > 0",
            });
        }
        self.recursive.validate()
    }
}

/// The recursive discrete momentum estimator.
#[derive(Debug, Clone)]
pub struct DiscreteMomentumEstimator<B: Backend> {
    source: MomentumRows,
    /// Splits the source's chains at the longest chain ([`ChainClock`]).
    clock: ChainClock,
    qr: AugmentedQr,
    /// The jackknife's chain groups; `None` with forgetting or after
    /// [`DiscreteMomentumEstimator::stop_jackknife`].
    groups: Option<ChainGroups>,
    /// Whether the groups' σ joins the noise σ (else they serve the torque test only,
    /// [`Self::jackknife_for_torque_only`]).
    jackknife_in_sigma: bool,
    /// Whether the compensation's gyro density is the run's estimate
    /// (`Self::set_gyro_noise`), not a stated one.
    gyro_noise_estimated: bool,
    svd: SvdTracker,
    sv: Vector6<f64>,
    reduced: RecursiveQr,
    /// `reduced` with the prior knowledge stacked on ([`super::prior::augment`]).
    solved: RecursiveQr,
    constraints: Constraints,
    backend: B,
    settings: MomentumEstimatorSettings,
    samples: usize,
    since_solve: usize,
    last_block_t_s: Option<f64>,
    epoch: u64,
    /// Whether the chain in progress has had its initial momenta counted.
    chain_counted: bool,
    /// Whether the residual dipole's and the centre of mass's unknowns are counted.
    external_counted: [bool; 2],
    /// At the last solve, the torque test ([`torque_tested`]).
    torque_test: Option<TorqueTest>,
    last: Option<Estimate>,
}

#[cfg_attr(not(feature = "std"), allow(dead_code))]
impl<B: Backend> DiscreteMomentumEstimator<B> {
    /// A new estimator.
    pub fn new(
        settings: MomentumEstimatorSettings,
        constraints: Constraints,
        backend: B,
    ) -> Result<Self, EstimatorError> {
        settings.validate()?;
        let r = &settings.rows;
        Ok(Self {
            source: MomentumRows::new(*r),
            clock: ChainClock::new(r.max_chain_s),
            qr: AugmentedQr::new(r.shared_nuisance()).with_inertial_torque(r.inertial_torque),
            // The delete-a-group jackknife weighs its groups equally: with forgetting they
            // are not, and it is not kept ([`super::jackknife`]).
            groups: settings
                .recursive
                .memory_s
                .is_none()
                .then(ChainGroups::default),
            jackknife_in_sigma: true,
            gyro_noise_estimated: false,
            svd: SvdTracker::new(),
            sv: Vector6::zeros(),
            reduced: RecursiveQr::new(),
            solved: RecursiveQr::new(),
            constraints,
            backend,
            settings,
            samples: 0,
            since_solve: 0,
            last_block_t_s: None,
            epoch: 0,
            chain_counted: false,
            external_counted: [false; 2],
            torque_test: None,
            last: None,
        })
    }

    /// Fold one sample into the least-squares state without solving. Returns whether it
    /// completed a row block.
    pub(crate) fn fold(&mut self, s: &Sample) -> Result<bool, EstimatorError> {
        let index = self.samples;
        self.samples += 1;
        let row = self.source.push(s).map_err(|source| EstimatorError::Row {
            sample: index,
            source,
        })?;
        let Some(row) = row else {
            return Ok(false);
        };
        let epoch = self.clock.epoch(&self.source);
        self.fold_row(&row, epoch, s.t_s);
        Ok(true)
    }

    /// Fold a row block that `source` just gave, at time `t_s`, in place of one from this
    /// estimator's own source: for candidates that differ only in the longest chain and
    /// so share their rows (module docs of [`super::momentum_rows`], "Chains"). `source`
    /// must have this estimator's row settings but for `max_chain_s`, and the same source
    /// must feed it every block from the first on.
    pub(crate) fn fold_shared(&mut self, row: &AugmentedRow, source: &MomentumRows, t_s: f64) {
        debug_assert_eq!(
            source.settings().source_key(),
            self.settings.rows.source_key()
        );
        let epoch = self.clock.epoch(source);
        self.fold_row(row, epoch, t_s);
    }

    /// [`Self::fold_shared`] for two candidates fed by the same source, their folds
    /// interleaved ([`AugmentedQr::add_pair`]): the same states as two
    /// [`Self::fold_shared`], bit for bit, faster.
    pub(crate) fn fold_shared_pair(
        a: &mut Self,
        b: &mut Self,
        row: &AugmentedRow,
        source: &MomentumRows,
        t_s: f64,
    ) {
        for e in [&*a, &*b] {
            debug_assert_eq!(source.settings().source_key(), e.settings.rows.source_key());
        }
        let (ea, eb) = (a.clock.epoch(source), b.clock.epoch(source));
        a.before_fold(ea, t_s);
        b.before_fold(eb, t_s);
        a.count_external(row);
        b.count_external(row);
        AugmentedQr::add_pair(
            (&mut a.qr, a.groups.as_mut().map(ChainGroups::chain_mut)),
            (&mut b.qr, b.groups.as_mut().map(ChainGroups::chain_mut)),
            row,
        );
    }

    fn fold_row(&mut self, row: &AugmentedRow, epoch: u64, t_s: f64) {
        self.before_fold(epoch, t_s);
        self.count_external(row);
        self.qr
            .add(row, self.groups.as_mut().map(ChainGroups::chain_mut));
    }

    /// The outside torques' unknowns count from the first row block that uses them
    /// ([`super::external_torque`]).
    fn count_external(&mut self, row: &AugmentedRow) {
        for (counted, uses) in self
            .external_counted
            .iter_mut()
            .zip(row.external_unknowns())
        {
            if uses && !*counted {
                self.qr.add_nuisance(3);
                *counted = true;
            }
        }
    }

    /// A new chain's bookkeeping and forgetting, before a row block at `t_s` is folded.
    fn before_fold(&mut self, epoch: u64, t_s: f64) {
        if epoch != self.epoch {
            self.epoch = epoch;
            self.qr.eliminate_anchors();
            if let Some(g) = self.groups.as_mut() {
                g.end_chain();
            }
            self.chain_counted = false;
        }
        // A chain's initial momenta count as unknowns from its first row (a chain that
        // ended before giving a row has none), as in the batch reduction.
        if !self.chain_counted {
            self.qr
                .add_nuisance(self.settings.rows.nuisance_per_chain());
            self.chain_counted = true;
        }
        if let (Some(m), Some(t0)) = (self.settings.recursive.memory_s, self.last_block_t_s) {
            self.qr.scale(libm::exp(-(t_s - t0) / m));
        }
        self.last_block_t_s = Some(t_s);
        self.qr.advance_to(t_s);
        self.since_solve += 1;
    }

    /// Weigh the row blocks folded from now on for an attitude that drifts
    /// ([`super::attitude_drift`]; `None`, the default: unweighted).
    pub(crate) fn set_drift(&mut self, drift: Option<super::attitude_drift::AttitudeDrift>) {
        self.qr.set_drift(drift);
    }

    /// Stop keeping the jackknife's chain groups (their folding is a third of the cost
    /// per row): for a state whose noise σ is not wanted, such as the pipeline's half-rate
    /// shadow or a candidate the data have ruled out. The noise σ is the least-squares
    /// one from then on.
    pub(crate) fn stop_jackknife(&mut self) {
        self.groups = None;
    }

    /// Keep the jackknife's groups for the torque test alone ([`torque_tested`]): the
    /// noise σ is the least-squares one, as after [`Self::stop_jackknife`], which this is
    /// where the torque is not tested. For a state whose σ comes from elsewhere (the
    /// whole record as one chain, whose siblings' jackknife σ it takes).
    pub(crate) fn jackknife_for_torque_only(&mut self) {
        if self.settings.rows.torque_bias && self.settings.recursive.memory_s.is_none() {
            self.jackknife_in_sigma = false;
        } else {
            self.stop_jackknife();
        }
    }

    /// Feed one sample. Returns an estimate when this sample completed a block and a solve
    /// was due.
    pub fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        if !self.fold(s)? {
            return Ok(None);
        }
        if self.since_solve < self.settings.recursive.solve_every || self.qr.rows() < 6 {
            return Ok(None);
        }
        self.solve_now(s.t_s).map(Some)
    }

    /// Solve with the data so far, stamped `t_s`.
    pub(crate) fn solve_now(&mut self, t_s: f64) -> Result<Estimate, EstimatorError> {
        self.since_solve = 0;
        let with = self.qr.reduced();
        let without = (self.settings.rows.torque_bias
            && self.settings.recursive.memory_s.is_none())
        .then(|| self.qr.shared().reduced_without_torque());
        // The yardstick of the torque test's shift: the answer's jackknife σ (its groups
        // keep the torque).
        let yardstick = match (&without, self.groups.as_mut()) {
            (Some(_), Some(g)) => g.sigma(&self.constraints),
            _ => None,
        };
        (self.reduced, self.torque_test) =
            torque_tested(with, without, yardstick, &self.constraints);
        let (solved, fit) = super::prior::augment(&self.reduced, &self.constraints);
        self.solved = solved;
        self.sv = self.svd.singular_values(&self.solved.r);
        let warm = self.last.and_then(|e| e.j());
        let (reduced, solved, sv, constraints) =
            (&self.reduced, &self.solved, &self.sv, &self.constraints);
        let backend = &mut self.backend;
        let mut solve = |settings: &RecursiveSettings| {
            estimate_from(
                &mut *backend,
                reduced,
                solved,
                fit,
                sv,
                constraints,
                settings,
                warm.as_ref(),
                t_s,
            )
        };
        let mut e = solve(&self.settings.recursive)?;
        // An estimated density that outweighs the excitation is no reason to refuse the
        // data: the answer is then the uncompensated one.
        if self.gyro_noise_estimated
            && e.observability
                == super::observability::Observability::NotObservable(
                    super::observability::Unobservable::NoiseDominated,
                )
        {
            e = solve(&RecursiveSettings {
                gyro_noise_rad_s_rthz: None,
                ..self.settings.recursive
            })?;
        }
        self.last = Some(e);
        Ok(e)
    }

    /// The gyro density of the errors-in-variables compensation at the next solves,
    /// rad/s/√Hz (a run's estimate from the rates, `super::rate_noise`; `None`: none).
    pub(crate) fn set_gyro_noise(&mut self, gyro_noise_rad_s_rthz: Option<f64>) {
        self.settings.recursive.gyro_noise_rad_s_rthz = gyro_noise_rad_s_rthz;
        self.gyro_noise_estimated = gyro_noise_rad_s_rthz.is_some();
    }

    /// Least-squares standard deviation per element at the last solve.
    #[must_use]
    pub fn noise_sigma(&self) -> Option<[f64; 6]> {
        super::uncertainty::noise_sigma(&self.solved, &self.sv, self.svd.v())
            .map(|s| super::prior::zero_fixed(s, &self.constraints))
    }

    /// The delete-a-group jackknife σ per element over the completed chains
    /// (`super::jackknife`), kg m²; `None` with too few chains, with forgetting or
    /// after `Self::stop_jackknife`.
    pub fn jackknife_sigma(&mut self) -> Option<[f64; 6]> {
        if !self.jackknife_in_sigma {
            return None;
        }
        // Borrowed apart, not copied: the constraint set is large.
        let Self {
            groups,
            constraints,
            ..
        } = self;
        groups.as_mut()?.sigma(constraints)
    }

    /// The noise σ per element: the larger of the least-squares and the jackknife σ
    /// (`super::jackknife`), kg m² (the torque test's move is added by the caller,
    /// [`Self::torque_model_shift`]).
    pub fn robust_noise_sigma(&mut self) -> Option<[f64; 6]> {
        let ls = self.noise_sigma()?;
        Some(super::jackknife::robust_sigma(
            &ls,
            self.jackknife_sigma().as_ref(),
        ))
    }

    /// The move of the answer between the models with and without the torque, kg m² per
    /// element, where the last solve's torque test could not choose between them
    /// (`torque_tested`, [`TorqueTest::shift_in_sigma`]): a model uncertainty the
    /// answer's σ carries in quadrature, after every noise σ.
    #[must_use]
    pub fn torque_model_shift(&self) -> Option<[f64; 6]> {
        self.torque_test.and_then(|t| t.model_shift_kg_m2)
    }

    /// The reduced least-squares state in `j` at the last solve.
    #[must_use]
    pub(crate) fn reduced(&self) -> &RecursiveQr {
        &self.reduced
    }

    /// [`Self::reduced`] with the damping `D` held at zero instead of estimated (and the
    /// disturbance torque as the torque test left it): the answer of the model without
    /// the drag, an alternative for the model spread. `None` where the rows do not
    /// estimate `D`.
    #[must_use]
    pub(crate) fn reduced_without_damping(&self) -> Option<RecursiveQr> {
        let torque_held = self.torque_test.is_some_and(|t| t.held_at_zero);
        let (r_dj, z_d) = self.qr.shared().damping_row(torque_held)?;
        Some(self.reduced.holding_at_zero(&r_dj, z_d))
    }

    /// `Self::reduced` with the prior knowledge stacked on: the state the last solve
    /// used.
    #[must_use]
    pub(crate) fn solved(&self) -> &RecursiveQr {
        &self.solved
    }

    /// The full least-squares state.
    #[must_use]
    pub(crate) fn qr(&self) -> &AugmentedQr {
        &self.qr
    }

    /// The latest estimate.
    #[must_use]
    pub fn last(&self) -> Option<&Estimate> {
        self.last.as_ref()
    }

    /// The torque test at the last solve (`torque_tested`); `None` when the torque is
    /// not estimated (or under forgetting, where it is kept).
    #[must_use]
    pub fn torque_test(&self) -> Option<TorqueTest> {
        self.torque_test
    }

    /// The constant body-frame disturbance torque, N m, at the latest estimate's `j`
    /// (`None` before an answer, when it is not estimated, or when the last solve held it
    /// at zero).
    #[must_use]
    pub fn torque_bias_nm(&self) -> Option<Vector3<f64>> {
        let j = self.last.and_then(|e| e.j())?;
        let held = self.torque_test.is_some_and(|t| t.held_at_zero);
        (self.settings.rows.torque_bias && !held).then(|| {
            let x = self.qr.nuisance_at(&j);
            Vector3::new(x[TORQUE], x[TORQUE + 1], x[TORQUE + 2])
        })
    }

    /// The damping `D` (N m s) that fits best at `j`, where estimated, with its σ: the
    /// larger of the least-squares σ (every unknown free) and the jackknife σ of the
    /// delete-one-group answers' `D` ([`super::jackknife`]), as for `j`'s noise σ.
    #[must_use]
    pub(crate) fn damping_at(&self, j: &InertiaVector) -> Option<(f64, Option<f64>)> {
        self.settings.rows.damping.then(|| {
            let column = super::unknowns::Block::Damping.shared_column();
            let ls = self.qr.shared().marginal_sigma(column);
            let jackknife = self
                .groups
                .as_ref()
                .filter(|_| self.jackknife_in_sigma)
                .and_then(|g| g.nuisance_sigma(&self.constraints, column));
            let sigma = match (ls, jackknife) {
                (Some(l), Some(k)) => Some(l.max(k)),
                (l, k) => l.or(k),
            };
            (self.qr.nuisance_at(j)[DAMPING], sigma)
        })
    }

    /// The residual dipole and the centre of mass that fit best at `j`, where the rows use
    /// them (their values only: [`Self::outside_at`] gives them with σ).
    #[must_use]
    pub(crate) fn outside_values_at(&self, j: &InertiaVector) -> [Option<[f64; 3]>; 2] {
        let [dipole, centre] = self.external_counted;
        if !(dipole || centre) {
            return [None, None];
        }
        let x = self.qr.nuisance_at(j);
        let v = |c: usize| [x[c], x[c + 1], x[c + 2]];
        [dipole.then(|| v(DIPOLE)), centre.then(|| v(CENTRE_OF_MASS))]
    }

    /// The outside torques at the answer `e` (this estimator's or one made of its
    /// rows): whether the gravity gradient entered this estimator's own rows, and the
    /// residual dipole and centre of mass where the rows use them. Their σ: the larger of
    /// the least-squares σ (every unknown free) and the jackknife σ, as [`Self::damping_at`]'s,
    /// and, in quadrature, the part of `e`'s σ beyond its noise (discretisation bias,
    /// model spread, consider parameters) carried through `∂x/∂j`: `x` is linear in `j`
    /// at the least-squares optimum of the other unknowns. `None` without a `j`.
    #[must_use]
    pub(crate) fn outside_at(&self, e: &super::Estimate) -> Option<OutsideEstimates> {
        let j = e.j()?;
        let [dipole, centre] = self.external_counted;
        if !(dipole || centre) {
            return Some(OutsideEstimates {
                gravity_gradient: self.source.gravity_gradient(),
                ..OutsideEstimates::default()
            });
        }
        let x = self.qr.nuisance_at(&j);
        // The part of σ beyond the noise, per element of j.
        let beyond = e.uncertainty.map_or([0.0; 6], |u| u.beyond_noise_kg_m2());
        let sensitivity: [_; 6] = core::array::from_fn(|k| {
            let mut jk = j;
            jk[k] += 1.0;
            self.qr.nuisance_at(&jk) - x
        });
        let block = |used: bool, column: usize| {
            used.then(|| {
                let shared = column - super::unknowns::FIRST_SHARED;
                let sigma = [0, 1, 2].map(|i| {
                    let ls = self.qr.shared().marginal_sigma(shared + i);
                    let jackknife = self
                        .groups
                        .as_ref()
                        .filter(|_| self.jackknife_in_sigma)
                        .and_then(|g| g.nuisance_sigma(&self.constraints, shared + i));
                    let noise = match (ls, jackknife) {
                        (Some(l), Some(k)) => Some(l.max(k)),
                        (l, k) => l.or(k),
                    }?;
                    let carried: f64 = (0..6)
                        .map(|k| sensitivity[k][column + i] * beyond[k])
                        .map(|v| v * v)
                        .sum();
                    Some(crate::math::sqrt(noise * noise + carried))
                });
                Estimated3 {
                    value: [x[column], x[column + 1], x[column + 2]],
                    sigma,
                    undetermined_direction: super::external_torque::undetermined(
                        &self.qr.shared().block_covariance(shared),
                    ),
                }
            })
        };
        Some(OutsideEstimates {
            gravity_gradient: self.source.gravity_gradient(),
            residual_dipole_am2: block(dipole, DIPOLE),
            centre_of_mass_m: block(centre, CENTRE_OF_MASS),
        })
    }

    /// The row settings.
    #[must_use]
    pub(crate) fn row_settings(&self) -> &MomentumRowSettings {
        &self.settings.rows
    }

    /// Gaps in the time stamps so far.
    #[cfg(test)]
    pub(crate) fn gaps(&self) -> usize {
        self.source.gaps()
    }
}

#[cfg(feature = "std")]
mod batch;
#[cfg(feature = "std")]
pub(crate) use batch::{reduce_batch, BatchReduction};

#[cfg(all(test, feature = "sim"))]
mod tests;
