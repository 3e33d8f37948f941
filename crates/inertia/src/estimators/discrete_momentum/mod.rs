//! The discrete momentum estimator ([`crate::estimator::discrete_momentum`]) in the
//! pipeline, with the row model chosen from the data.
//!
//! The wheel momentum between samples is estimated with `j` by default
//! ([`Stencil::Adaptive`]). Where the settings leave a choice open (the rotation source
//! when the telemetry has gyro rates, and the chain length: `--chain`, a quarter and 4×
//! as long, and the whole record as one chain, whose σ comes from its chained siblings'
//! jackknife: [`chained_siblings`]), every candidate row model folds every sample (the
//! candidates that differ only in the chain length from one shared row source), and each
//! solve uses the candidate [`pick`] picks: first by fit ([`choose`]: of those whose
//! residual variance `ρ²/(rows − unknowns)` the data cannot tell from the smallest, the
//! one with the longest chains; a noisier rotation source, or chains long enough for an
//! attitude drift to show, leave larger residuals), then by steadiness ([`steadier`]: the
//! same rows in longer chains whose jackknife σ is clearly smaller).
//! The σ of the answer is assembled here from the chosen candidate's noise σ
//! ([`crate::estimator::jackknife`]) and three bias terms: the discretisation bias from a
//! half-rate shadow of the first candidate, the spread of indistinguishable candidates,
//! and the cross-check of the rotation sources ([`reconcile`]). A candidate that has fitted
//! markedly worse than the best for long is ruled out and no longer folded
//! ([`standing`]).

mod standing;
pub(crate) mod twins;

use crate::pipeline::registry::{self, BatchOutput, Capabilities, Estimator, EstimatorEntry};
use crate::pipeline::{PipelineConfig, PipelineError};
use standing::{Standing, RULE_OUT_AFTER};
use twins::Twins;
use crate::constraints::Constraints;
use crate::eigen3::symmetric_eigen3;
use crate::estimator::attitude_drift::AttitudeDrift;
use crate::estimator::audit::{audit, audit_at, reversed_at_floor};
use crate::estimator::compensation::compensate;
use crate::estimator::consistency::{self, ResidualSegments, Worst};
use crate::estimator::discrete_momentum::{
    reduce_batch, torque_tested, BatchReduction, DiscreteMomentumEstimator,
    MomentumEstimatorSettings, TorqueTest,
};
use crate::estimator::excitation::{diagnose, Excitation};
use crate::estimator::jackknife::robust_sigma;
use crate::estimator::momentum_rows::{
    MomentumRowSettings, MomentumRows, RhoModel, RotationSource, Stencil,
};
use crate::estimator::observability::{Observability, Unobservable};
use crate::estimator::prior;
use crate::estimator::qr::RecursiveQr;
use crate::estimator::recursive::RecursiveSettings;
use crate::estimator::uncertainty::{noise_sigma, with_bias, with_bias_at};
use crate::estimator::{batch, Estimate, EstimatorError};
use crate::sample::Sample;
use crate::solver::{unconstrained_minimiser, Backend};
use crate::tensor::{matrix_from_j, InertiaVector};
use nalgebra::Vector3;
use std::boxed::Box;
use std::vec::Vec;

/// Registry entry.
pub(crate) const DISCRETE_MOMENTUM: EstimatorEntry = EstimatorEntry {
    name: "discrete-momentum",
    summary: "discrete conservation of angular momentum (telescoped paper rows), unknown constant torque, Richardson O(h^4) rows, constrained (default)",
    capabilities: Capabilities {
        needs_gyro: false,
        constraints: true,
        compensation: true,
        uncertainty: true,
        row_model: true,
    },
    build,
    batch: Some(run_batch),
};

type Candidate = DiscreteMomentumEstimator<Box<dyn Backend + Send>>;

/// The candidate row settings for a configuration, given whether the telemetry has gyro
/// rates.
fn candidates(c: &PipelineConfig, has_gyro: bool) -> Vec<MomentumRowSettings> {
    let rotations: &[RotationSource] = match c.rotation_source {
        Some(RotationSource::Attitude) => &[RotationSource::Attitude],
        Some(RotationSource::Gyro) => &[RotationSource::Gyro],
        None if has_gyro => &[RotationSource::Gyro, RotationSource::Attitude],
        None => &[RotationSource::Attitude],
    };
    let stencils: &[Stencil] = match c.rho_model {
        RhoModel::Plain => &[Stencil::Plain],
        RhoModel::Held => &[Stencil::Held],
        RhoModel::Smooth => &[Stencil::Smooth],
        RhoModel::Auto => &[Stencil::Adaptive],
    };
    // Short chains, long ones, and the whole record as one chain: the data choose
    // ([`choose`]).
    let chains: Vec<Option<f64>> = match c.max_chain_s {
        Some(l) => std::vec![
            Some(l / SHORT_CHAIN_DIVISOR),
            Some(l),
            Some(LONG_CHAIN_FACTOR * l),
            None
        ],
        None => std::vec![None],
    };
    let mut out = Vec::new();
    for max_chain_s in chains {
        for &rotation in rotations {
            for &stencil in stencils {
                out.push(MomentumRowSettings {
                    rotation,
                    stencil,
                    torque_bias: c.torque_bias,
                    max_chain_s,
                });
            }
        }
    }
    out
}

/// The long chain's length, in `--chain` lengths.
pub(crate) const LONG_CHAIN_FACTOR: f64 = 4.0;
/// The short chain's length is `--chain` divided by this.
pub(crate) const SHORT_CHAIN_DIVISOR: f64 = 4.0;

/// How many times smaller a longer chain's jackknife σ must be than that of the chain
/// [`choose`] picked for it to take its place ([`steadier`]): the
/// jackknife σ of 8 groups has a relative standard error of about 0.27, so this is about
/// two of them.
pub(crate) const STEADIER: f64 = 1.5;

/// `√(Σ σ_ii² + 2 Σ σ_ij²)`: the Frobenius norm of a symmetric matrix of element σ.
fn frobenius(sigma: &[f64; 6]) -> f64 {
    (sigma[..3].iter().map(|s| s * s).sum::<f64>()
        + 2.0 * sigma[3..].iter().map(|s| s * s).sum::<f64>())
    .sqrt()
}

/// For a candidate that holds the whole record as one chain, the candidates with the
/// same rows in chains of at least `from_s` (the pipeline passes `--chain`: the shortest
/// chains, with four times the initial momenta, scatter far more than the whole record). One chain is one jackknife group, so the whole
/// record has no jackknife σ of its own; its noise σ is element by element the largest of
/// its least-squares σ and its chained siblings' jackknife σ ([`sibling_jackknife`]),
/// which see the correlated errors the least-squares σ does not. The chooser takes the
/// whole record only where the data cannot tell it from the chains; a chained estimate
/// has more nuisance unknowns in the same rows, so its σ bounds the whole record's from
/// above, and the difference of the answers joins the bias through the model spread.
/// Empty for a candidate with chains, and without chained candidates (`--chain 0`: every
/// candidate is one chain, and σ is its own).
fn chained_siblings<'a>(
    rows: &'a MomentumRowSettings,
    all: impl Iterator<Item = &'a MomentumRowSettings> + 'a,
    from_s: f64,
) -> impl Iterator<Item = usize> + 'a {
    all.enumerate()
        .filter(move |(_, r)| is_chained_sibling(rows, r, from_s))
        .map(|(k, _)| k)
}

/// Whether `r` is a chained sibling of the whole-record candidate `rows`
/// ([`chained_siblings`]).
fn is_chained_sibling(rows: &MomentumRowSettings, r: &MomentumRowSettings, from_s: f64) -> bool {
    rows.max_chain_s.is_none()
        && r.max_chain_s.is_some_and(|l| l >= from_s)
        && r.rows_only() == rows.rows_only()
}

/// Element by element the largest of the jackknife σ given (`None`: none).
fn sibling_jackknife(sigmas: impl Iterator<Item = Option<[f64; 6]>>) -> Option<[f64; 6]> {
    sigmas
        .flatten()
        .reduce(|a, b| core::array::from_fn(|k| a[k].max(b[k])))
}

fn settings(c: &PipelineConfig, rows: MomentumRowSettings) -> MomentumEstimatorSettings {
    MomentumEstimatorSettings {
        rows,
        recursive: RecursiveSettings {
            solve_every: 1,
            observability: c.observability,
            memory_s: c.memory_s,
            gyro_noise_rad_s_rthz: c.gyro_noise_rad_s_rthz,
        },
    }
}

/// The model-uncertainty part of σ: per element, the largest difference between the
/// chosen candidate's (`best`) unconstrained `ĵ` and that of any other candidate the data
/// cannot tell apart from it: a residual variance within `1 + 3√(2/ν)` of the chosen
/// one's, with `ν` the chosen one's residual degrees of freedom (three standard deviations
/// of the ratio of two variance estimates with ν degrees of freedom each). When two models of the
/// wheels, or two rotation sources, fit the data equally well, neither is known to be
/// right, and the answer is uncertain by at least their difference. Zero when the chosen
/// model fits significantly best.
fn model_spread(
    best: &RecursiveQr,
    others: impl Iterator<Item = RecursiveQr>,
    gyro: Option<f64>,
    constraints: &Constraints,
) -> [f64; 6] {
    let mut out = [0.0; 6];
    let v_best = best.residual_variance();
    let dof = best.residual_dof();
    if !(dof > 0.0) {
        return out;
    }
    let ratio = 1.0 + 3.0 * libm::sqrt(2.0 / dof);
    // The chosen candidate's answer once another is comparable (none may be).
    let mut j_best: Option<Option<InertiaVector>> = None;
    for qr in others {
        if !(qr.residual_variance() <= ratio * v_best) {
            continue;
        }
        let Some(j_best) = *j_best.get_or_insert_with(|| own_solution(best, gyro, constraints))
        else {
            return out;
        };
        if let Some(j) = own_solution(&qr, gyro, constraints) {
            for (o, (a, b)) in out.iter_mut().zip(j.iter().zip(j_best.iter())) {
                *o = o.max((a - b).abs());
            }
        }
    }
    out
}

/// The discretisation-bias part of σ: the same rows on every other sample (step 2h) are
/// biased `2^p` times as much as on every sample for a method of order `p`, so
/// `|ĵ(h) − ĵ(2h)|/(2^p − 1)` measures the bias of `ĵ(h)` from the data (Richardson's
/// error estimate; unconstrained solutions of both). The order actually reached depends
/// on the wheels between samples (O(h⁴) for the Richardson stencils when their model of
/// `ρ` holds, less when the commands change several times per telemetry step), so the
/// conservative `p = 2` is used: `|ĵ(h) − ĵ(2h)|/3`. It catches what the noise σ cannot:
/// a bias shared by every chain, such as the remainder at 1 Hz telemetry.
fn discretisation_bias(
    full: &RecursiveQr,
    half: &RecursiveQr,
    gyro: Option<f64>,
    constraints: &Constraints,
) -> [f64; 6] {
    match (
        own_solution(full, gyro, constraints),
        own_solution(half, gyro, constraints),
    ) {
        (Some(a), Some(b)) => core::array::from_fn(|k| (a[k] - b[k]).abs() / 3.0),
        _ => [0.0; 6],
    }
}

/// Without excitation (`y ≡ 0`) only a Gaussian prior could give this estimator's answer
/// its scale, and it does not do so reliably: on a pure spin with a 5 % prior its answers
/// were 24 % off with a stated σ of 3 % (`tests/prior.rs`; the variational estimator's
/// are right). Such an answer is withdrawn: known failure, README "Prior knowledge".
fn scale_from_prior(e: &mut Estimate, data: &RecursiveQr, constraints: &Constraints) {
    if constraints.set().prior.is_some() && data.y_energy == 0.0 && e.j().is_some() {
        e.observability = Observability::NotObservable(Unobservable::NoExcitation);
        e.solution = None;
        e.uncertainty = None;
    }
}

/// The unconstrained least-squares `j` of a reduced state, errors-in-variables
/// compensated like the estimate when a gyro noise density is given (the compensation's
/// size depends on the step and the row model, so uncompensated solutions would differ
/// by it and not by what is being measured).
///
/// The prior knowledge of `constraints` is stacked on first ([`prior::augment`]), as for
/// the estimate: without it the directions the data leave open would count as bias.
fn own_solution(
    qr: &RecursiveQr,
    gyro: Option<f64>,
    constraints: &Constraints,
) -> Option<InertiaVector> {
    let augmented;
    let qr = if prior::applies(constraints) {
        augmented = prior::augment(qr, constraints).0;
        &augmented
    } else {
        qr
    };
    match gyro.and_then(|g| compensate(qr, g)) {
        Some((r, z)) => unconstrained_minimiser(&r, &z),
        None => unconstrained_minimiser(&qr.r, &qr.z),
    }
}

/// A reduced state's unconstrained answer ([`own_solution`]) and its least-squares σ
/// ([`twins::least_squares_sigma`]) from the same rows: with prior knowledge stacked on
/// for both, so that a strong prior does not leave a σ of the data alone beside an answer
/// the prior holds ([`twins`]).
fn own_answer(
    qr: &RecursiveQr,
    gyro: Option<f64>,
    constraints: &Constraints,
) -> Option<(InertiaVector, [f64; 6])> {
    let augmented;
    let solved = if prior::applies(constraints) {
        augmented = prior::augment(qr, constraints).0;
        &augmented
    } else {
        qr
    };
    Some((
        own_solution(qr, gyro, constraints)?,
        twins::least_squares_sigma(solved)?,
    ))
}

/// Sample `a` as a node of the stride-2 grid: its gyro rate (the average over the step
/// to `b`) becomes the mean of `a`'s and `b`'s rates, the average over the double step
/// when the two steps are equal (the step after `b` is not known when `b` arrives; with
/// unequal steps the shadow's bias estimate is approximate, and only it uses this).
fn double_step(a: &Sample, b: &Sample) -> Sample {
    Sample {
        omega_rad_s: a.omega_rad_s.zip(b.omega_rad_s).map(|(x, y)| (x + y) * 0.5),
        ..*a
    }
}

/// `√(a² + b²)` element by element.
fn quadrature(a: &[f64; 6], b: &[f64; 6]) -> [f64; 6] {
    core::array::from_fn(|k| (a[k] * a[k] + b[k] * b[k]).sqrt())
}

/// The candidate to solve, from `(residual variance, residual degrees of freedom, chain
/// length)` per candidate: of those whose residual variance is within `1 + 3√(2/ν)` of
/// the smallest (`ν` its degrees of freedom: the data cannot tell them apart), the one
/// with the longest chains (more of the momentum's history ties `j` down), then the
/// smallest variance. Chains that a drifting attitude or a varying torque would spoil
/// fit worse, and lose. `0` when no variance is finite.
fn choose(candidates: impl Iterator<Item = (f64, f64, Option<f64>)> + Clone, from_s: f64) -> usize {
    let length = |c: Option<f64>| c.unwrap_or(f64::INFINITY);
    let candidates = candidates.map(|(v, d, c)| {
        if length(c) >= from_s {
            (v, d, c)
        } else {
            (f64::INFINITY, d, c)
        }
    });
    let (mut v_min, mut dof) = (f64::INFINITY, 0.0);
    for (v, d, _) in candidates.clone() {
        if v < v_min {
            (v_min, dof) = (v, d);
        }
    }
    if !v_min.is_finite() || !(dof > 0.0) {
        return 0;
    }
    let limit = v_min * (1.0 + 3.0 * (2.0 / dof).sqrt());
    let mut out: Option<(usize, f64, f64)> = None;
    for (i, (v, _, chain)) in candidates.enumerate() {
        if !(v <= limit) {
            continue;
        }
        let better = match out {
            None => true,
            Some((_, l, vb)) => length(chain) > l || (length(chain) == l && v < vb),
        };
        if better {
            out = Some((i, length(chain), v));
        }
    }
    out.map_or(0, |o| o.0)
}

/// The candidate to use and the shortest chain still in the running: [`choose`]'s pick
/// by fit, unless [`steadier`] finds the same rows in longer chains clearly steadier;
/// then [`choose`]'s pick among the chains at least that long (where the data cannot
/// tell a longer chain, or the whole record, from it, the longer one), and the shorter
/// chains are out of the running (not alternatives for the model spread or the
/// cross-check either). `fits` as for [`choose`]; `jackknife(i)`, candidate `i`'s
/// jackknife σ (`None`: none, or ruled out).
fn pick(
    fits: &[(f64, f64, Option<f64>)],
    rows: &[MomentumRowSettings],
    mut jackknife: impl FnMut(usize) -> Option<[f64; 6]>,
) -> (usize, f64) {
    let fitted = choose(fits.iter().copied(), 0.0);
    let steady = steadier(fitted, rows, &mut jackknife);
    if steady == fitted {
        return (fitted, 0.0);
    }
    let from_s = rows
        .get(steady)
        .and_then(|r| r.max_chain_s)
        .unwrap_or(f64::INFINITY);
    (choose(fits.iter().copied(), from_s), from_s)
}

/// Whether a candidate with these rows is still in the running ([`pick`]).
fn in_running(rows: &MomentumRowSettings, from_s: f64) -> bool {
    rows.max_chain_s.unwrap_or(f64::INFINITY) >= from_s
}

/// The shortest chain that is an alternative to the chosen candidate for the model spread
/// and the cross-check: in the running ([`pick`]), and no shorter than `--chain` (`chain_s`)
/// unless the chosen one is. The shortest chains (`--chain`/[`SHORT_CHAIN_DIVISOR`]) are
/// there for drifts that only they remove; where they are not chosen, the scatter of their
/// answers, with four times the initial momenta, is their noise, not a model
/// uncertainty of the chosen answer.
fn alternatives_from_s(chosen: &MomentumRowSettings, from_s: f64, chain_s: Option<f64>) -> f64 {
    let length = chosen.max_chain_s.unwrap_or(f64::INFINITY);
    from_s.max(length.min(chain_s.unwrap_or(0.0)))
}

/// The candidate to use instead of `fitted`: one with the same rows in longer chains
/// whose jackknife σ is [`STEADIER`] times smaller, the smallest such. Shorter chains fit
/// better wherever the rows' errors drift (the fit test sees the drift), but each chain's
/// initial momenta cost information: where the scatter of the answer across chains,
/// which includes the drift's effect on it, is clearly smaller for longer chains, the
/// drift costs less than the extra unknowns. `fitted` itself when it is the whole record
/// or has no jackknife σ.
fn steadier(
    fitted: usize,
    rows: &[MomentumRowSettings],
    jackknife: &mut impl FnMut(usize) -> Option<[f64; 6]>,
) -> usize {
    let Some(r0) = rows.get(fitted) else {
        return fitted;
    };
    let Some(length) = r0.max_chain_s else {
        return fitted;
    };
    let Some(s0) = jackknife(fitted) else {
        return fitted;
    };
    let mut best = (fitted, frobenius(&s0) / STEADIER);
    for (i, r) in rows.iter().enumerate() {
        let longer = r.max_chain_s.is_some_and(|l| l > length);
        if !longer || r.rows_only() != r0.rows_only() {
            continue;
        }
        if let Some(s) = jackknife(i) {
            let s = frobenius(&s);
            if s < best.1 {
                best = (i, s);
            }
        }
    }
    best.0
}

struct DiscreteMomentum {
    config: PipelineConfig,
    candidates: Vec<Candidate>,
    /// The row sources: candidates that differ only in the longest chain share one
    /// ([`DiscreteMomentumEstimator::fold_shared`]), so each row is formed once.
    sources: Vec<SharedSource>,
    /// The candidates' row settings.
    rows: Vec<MomentumRowSettings>,
    /// The candidates' fits at the last solve ([`choose`]), kept so that a push does not
    /// allocate.
    fits: Vec<(f64, f64, Option<f64>)>,
    /// The shortest chain of an alternative at the last solve ([`alternatives_from_s`]).
    from_s: f64,
    /// Which candidates the data have not ruled out.
    standing: Standing,
    /// Row blocks beyond the limit that rule a candidate out ([`standing`]).
    rule_out_after: usize,
    /// Whether the attitude is the gyro's integral ([`twins`]).
    twins: Twins,
    chosen: usize,
    since_solve: usize,
    /// Per candidate: its last own estimate and noise σ, and the row blocks since.
    checks: Vec<Option<CrossCheck>>,
    /// The first candidate's rows on every other sample, for the discretisation bias.
    shadow: Option<Box<Candidate>>,
    /// Per candidate, its residual record (none under forgetting).
    residuals: Vec<ResidualSegments>,
    /// The residuals' ratio to the stated gyro density at the last solve.
    density_ratio: Option<f64>,
    /// Input samples so far.
    samples: usize,
    /// Samples that completed a row block (the cross-check's clock).
    blocks: usize,
    /// The even sample waiting for its successor (the shadow's next sample).
    held: Option<Sample>,
    /// The other candidates' answers for [`reconcile`], kept between solves so that a
    /// push does not allocate.
    others: Vec<(InertiaVector, [f64; 6])>,
    /// The attitude drift the candidates' rows are weighted for
    /// ([`crate::estimator::attitude_drift`]), from the latest answer.
    drift: Option<AttitudeDrift>,
    /// With a drift to weight for and no answer yet: the samples so far, refolded with
    /// the weights once the first answer gives `Ĵ` ([`DiscreteMomentum::replayed`]);
    /// `None` otherwise, and past [`REPLAY_CAP`] samples.
    replay: Option<Vec<Sample>>,
    /// Once the rows are weighted for a drift: the same run unweighted, kept beside it
    /// (weighting a drift that the rows' discretisation bias outweighs costs accuracy),
    /// and whether its answer was the one given at the last solve
    /// ([`unweighted_is_better`]).
    unweighted: Option<(Box<DiscreteMomentum>, bool)>,
}

/// Whether the unweighted rows' answer `e` is to be given rather than the rows
/// weighted for an attitude drift: where its bias σ (discretisation and model spread)
/// exceeds its noise σ (Frobenius norms). The weighting whitens a random walk, which
/// brings out what the rows' errors have in common from one interval to the next: the
/// discretisation bias of long steps. Measured on the README's matrix with the
/// densities given, the weighted rows lower the error of every 10 Hz spin by 20–24 %
/// and raise it 1.6–2.9× at 1 Hz (paper and FOG gyro), where this test keeps the
/// unweighted answer; the σ of the two answers ranks them the wrong way round in both.
/// Without a σ to tell (none at this solve), the unweighted answer.
fn unweighted_is_better(e: &Estimate) -> bool {
    e.uncertainty
        .is_none_or(|u| frobenius(&u.bias_kg_m2) > frobenius(&u.noise_kg_m2))
}

/// Most samples kept for the drift weighting's replay (an hour at 10 Hz, 4.3 MB): with
/// no answer by then, the rows are not weighted at all (weighting only the rows after
/// the first answer is worse than none).
pub(crate) const REPLAY_CAP: usize = 36_000;

/// One row source and the candidates it feeds.
struct SharedSource {
    rows: MomentumRows,
    members: Vec<usize>,
}

/// Group candidates by their row settings but for the longest chain (module docs of
/// [`crate::estimator::momentum_rows`], "Chains"): one source per group.
fn shared_sources(candidates: &[MomentumRowSettings]) -> Vec<SharedSource> {
    let mut out: Vec<SharedSource> = Vec::new();
    for (i, r) in candidates.iter().enumerate() {
        let key = r.rows_only();
        match out.iter_mut().find(|g| *g.rows.settings() == key) {
            Some(g) => g.members.push(i),
            None => out.push(SharedSource {
                rows: MomentumRows::new(key),
                members: std::vec![i],
            }),
        }
    }
    out
}

/// A candidate's own answer, for the cross-check: `(ĵ, noise σ)` when it was determined
/// at the last refresh, `age` row blocks ago.
#[derive(Clone, Copy)]
struct CrossCheck {
    answer: Option<(InertiaVector, [f64; 6])>,
    age: usize,
    /// The answer was beyond the check's threshold when it was solved: a disagreement
    /// found with a fresh answer.
    beyond: bool,
}

/// Row blocks between refreshes of a candidate's own answer for the cross-check, at
/// least; later in a record, a [`CROSS_CHECK_SHARE`]th of the blocks so far (not under
/// forgetting, [`cross_check_every`]).
const CROSS_CHECK_EVERY: usize = 50;

/// The cross-check's answers are refreshed once the blocks since the last refresh are
/// this share of the record so far (or [`CROSS_CHECK_EVERY`], whichever is more). An
/// answer from `n` blocks moves by about `σ √(Δn/n)` over `Δn` more (a random walk of
/// the estimate, `σ ∝ 1/√n`), so an answer refreshed every `n/20` blocks is at most about
/// `0.2 σ` old, against the [`DISAGREE_Z`] `= 5 σ` the check looks for; and the refreshes
/// of a record of `N` blocks are `O(log N)`, not `N/50`, each a full solve of a candidate
/// whose warm starts are that old.
const CROSS_CHECK_SHARE: usize = 20;

/// Row blocks between refreshes of a determined answer for the cross-check after
/// `blocks` row blocks ([`CROSS_CHECK_SHARE`]): [`CROSS_CHECK_EVERY`] where its age
/// matters, that is where it is `near` the check (it differs from the present answer by
/// more than half the threshold, so that its verdict may flip, and once beyond, its
/// difference joins σ) and under forgetting (the answers rest on the last memory's blocks
/// however long the record). So an answer older than [`CROSS_CHECK_EVERY`] blocks is only
/// used while it is within half the threshold, where it changes neither σ nor the
/// verdict; one that comes near is refreshed at once if it is that old. Nor does an
/// answer that has aged past the threshold tell a disagreement: it is solved again first,
/// and kept while beyond only if it was beyond when solved. (An answer not determined is
/// solved again at every block, so that it joins the check as soon as it is.)
fn cross_check_every(blocks: usize, forgetting: bool, near: bool) -> usize {
    if forgetting || near {
        CROSS_CHECK_EVERY
    } else {
        CROSS_CHECK_EVERY.max(blocks / CROSS_CHECK_SHARE)
    }
}

/// `|ĵ_a − ĵ_b| / √(σ_a² + σ_b²)` (noise σ, without the model spread) beyond which two
/// candidates disagree: far in the tail of any honest σ, so that only an inconsistency
/// of the data trips it ([`reconcile`]).
pub(crate) const DISAGREE_Z: f64 = 5.0;

/// Reconcile a determined answer with the other candidates' own answers `(ĵ, noise σ)`.
/// Where one differs by more than [`DISAGREE_Z`] noise σ, the data are inconsistent and
/// either answer may be the right one: the difference joins the bias part of σ, so that
/// the stated σ covers both. If σ then exceeds `max_relative_sigma · ‖Ĵ‖_F`, the answer
/// is withdrawn ([`Unobservable::SourcesDisagree`]).
/// `eig` are the eigenpairs of `e`'s `J` ([`symmetric_eigen3`]).
fn reconcile(
    e: &mut Estimate,
    eig: &Eigen,
    others: &[(InertiaVector, [f64; 6])],
    max_relative_sigma: f64,
) {
    let (Some(j), Some(u)) = (e.j(), e.uncertainty) else {
        return;
    };
    let mut bias = u.bias_kg_m2;
    let mut worst: f64 = 0.0;
    for (jb, sigma) in others {
        let Some(z) = disagreement_beyond(&j, &u.noise_kg_m2, jb, sigma, DISAGREE_Z) else {
            continue;
        };
        worst = worst.max(z);
        for (b, (x, y)) in bias.iter_mut().zip(j.iter().zip(jb.iter())) {
            *b = b.max((x - y).abs());
        }
    }
    if worst == 0.0 {
        return;
    }
    let u = with_bias_at(&u.noise_kg_m2, &bias, eig);
    let relative = u.frobenius_sigma_kg_m2() / matrix_from_j(&j).norm();
    if relative <= max_relative_sigma {
        e.uncertainty = Some(u);
    } else {
        e.observability = Observability::NotObservable(Unobservable::SourcesDisagree { z: worst });
        e.solution = None;
        e.uncertainty = None;
    }
}

/// Only candidates whose residual variance is within this factor of the chosen one's are
/// cross-checked: one that fits much worse (a star tracker's differenced noise against a
/// gyro) is the worse model, not evidence against the chosen one.
pub(crate) const COMPARABLE_FIT: f64 = 2.0;

/// Largest `|a − b| / √(σ_a² + σ_b²)` over the elements.
fn disagreement(a: &InertiaVector, sa: &[f64; 6], b: &InertiaVector, sb: &[f64; 6]) -> f64 {
    (0..6)
        .map(|k| (a[k] - b[k]).abs() / (sa[k] * sa[k] + sb[k] * sb[k]).sqrt())
        .fold(0.0, f64::max)
}

/// [`disagreement`] where it exceeds `z`, `None` otherwise: the same verdict, but the
/// usual case, every element well inside `z` (at every solve, for each candidate), is
/// told by squares, without a `√` and a division per element. The squares' test lets
/// through everything within a relative `1e-9` of `z`, whose exact value then decides.
fn disagreement_beyond(
    a: &InertiaVector,
    sa: &[f64; 6],
    b: &InertiaVector,
    sb: &[f64; 6],
    z: f64,
) -> Option<f64> {
    let near = z * z * (1.0 - 1e-9);
    let candidate = (0..6).any(|k| {
        let d = a[k] - b[k];
        let s2 = sa[k] * sa[k] + sb[k] * sb[k];
        // Squares decide only where neither they nor `near · s2` can underflow or
        // overflow to a wrong verdict (a `|d|` whose square underflows is then within
        // 1e-8 σ); elsewhere, a zero, infinite or NaN variance or difference included,
        // the exact value does.
        !((1e-290..=1e290).contains(&s2) && d * d <= near * s2)
    });
    if !candidate {
        return None;
    }
    Some(disagreement(a, sa, b, sb)).filter(|d| *d > z)
}

/// Eigenpairs of a symmetric 3×3 matrix ([`symmetric_eigen3`]).
type Eigen = (Vector3<f64>, [Vector3<f64>; 3]);

/// Placeholder eigenpairs for an estimate without `J`.
const NO_EIGEN: Eigen = (
    Vector3::new(0.0, 0.0, 0.0),
    [Vector3::new(0.0, 0.0, 0.0); 3],
);

fn build(c: &PipelineConfig) -> Result<Box<dyn Estimator>, PipelineError> {
    Ok(Box::new(DiscreteMomentum::new(c)?))
}

impl DiscreteMomentum {
    fn new(c: &PipelineConfig) -> Result<Self, PipelineError> {
        // Validate the estimator settings now; candidates are built at the first sample.
        MomentumEstimatorSettings::validate(&settings(c, MomentumRowSettings::default())).map_err(
            |source| PipelineError::Estimator {
                sample: None,
                source,
            },
        )?;
        Ok(Self::empty(c))
    }

    /// The estimator before its first sample, for validated settings.
    fn empty(c: &PipelineConfig) -> Self {
        DiscreteMomentum {
            config: *c,
            candidates: Vec::new(),
            sources: Vec::new(),
            rows: Vec::new(),
            fits: Vec::new(),
            from_s: 0.0,
            standing: Standing::default(),
            rule_out_after: RULE_OUT_AFTER,
            twins: Twins::default(),
            chosen: 0,
            since_solve: 0,
            checks: Vec::new(),
            shadow: None,
            residuals: Vec::new(),
            density_ratio: None,
            samples: 0,
            blocks: 0,
            held: None,
            others: Vec::new(),
            drift: None,
            replay: c.attitude_drift_deg_rth.map(|_| Vec::new()),
            unweighted: None,
        }
    }

    /// The state whose answer was given at the last solve (the unweighted twin's where
    /// [`unweighted_is_better`]), for the diagnostics of the report.
    fn given(&self) -> &Self {
        match &self.unweighted {
            Some((twin, true)) => twin,
            _ => self,
        }
    }

    /// The run so far refolded from its first sample with the rows weighted for `drift`
    /// (the first answer's `Ĵ`), and its answer at the last sample: rows folded before
    /// an estimate of `J` exists cannot be weighted, and left unweighted beside weighted
    /// ones they cost more than the weighting gains (README, "Weighting").
    fn replayed(
        &self,
        samples: &[Sample],
        drift: AttitudeDrift,
    ) -> Result<(Self, Option<Estimate>), EstimatorError> {
        let mut fresh = Self {
            replay: None,
            drift: Some(drift),
            ..Self::empty(&self.config)
        };
        fresh.rule_out_after = self.rule_out_after;
        let mut last = None;
        for s in samples {
            last = fresh.push_sample(s)?;
        }
        Ok((fresh, last))
    }

    fn start(&mut self, first: &Sample) -> Result<(), EstimatorError> {
        for rows in candidates(&self.config, first.omega_rad_s.is_some()) {
            let backend = registry::build_backend(self.config.backend);
            self.candidates.push(DiscreteMomentumEstimator::new(
                settings(&self.config, rows),
                self.config.constraints,
                backend,
            )?);
        }
        // A whole-record candidate's σ comes from its chained siblings' jackknife: its own
        // chain groups would hold one chain.
        let rows: Vec<MomentumRowSettings> =
            self.candidates.iter().map(|c| *c.row_settings()).collect();
        self.sources = shared_sources(&rows);
        self.fits.reserve(rows.len());
        for (c, r) in self.candidates.iter_mut().zip(&rows) {
            if chained_siblings(r, rows.iter(), 0.0).next().is_some() {
                c.stop_jackknife();
            }
        }
        self.rows = rows;
        if self.config.uncertainty {
            if let Some(first) = self.candidates.first() {
                let mut shadow = DiscreteMomentumEstimator::new(
                    settings(&self.config, *first.row_settings()),
                    self.config.constraints,
                    registry::build_backend(self.config.backend),
                )?;
                // Only its least-squares state is used ([`discretisation_bias`]).
                shadow.stop_jackknife();
                self.shadow = Some(Box::new(shadow));
            }
        }
        self.standing = Standing::new(self.candidates.len(), self.rule_out_after);
        self.set_drift(self.drift);
        Ok(())
    }

    /// One sample through every candidate, and the chosen answer when a solve is due.
    fn push_sample(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        if self.candidates.is_empty() {
            self.start(s)?;
        }
        let mut folded = false;
        let record = self.config.memory_s.is_none();
        self.residuals
            .resize_with(self.candidates.len(), ResidualSegments::new);
        for src in &mut self.sources {
            let standing = &self.standing;
            let wanted = |i: &usize| *i == 0 || standing.live(*i);
            if !src.members.iter().any(wanted) {
                continue;
            }
            let row = src.rows.push(s).map_err(|source| EstimatorError::Row {
                sample: self.samples,
                source,
            })?;
            let Some(row) = row else {
                continue;
            };
            folded = true;
            // In pairs, their folds interleaved (`fold_shared_pair`), the odd one alone.
            let mut waiting: Option<usize> = None;
            for &i in src.members.iter().filter(|i| wanted(i)) {
                match waiting.take() {
                    None => waiting = Some(i),
                    Some(h) => {
                        // Members are in increasing order ([`shared_sources`]).
                        let (low, high) = self.candidates.split_at_mut(i);
                        match (low.get_mut(h), high.first_mut()) {
                            (Some(a), Some(b)) => {
                                Candidate::fold_shared_pair(a, b, &row, &src.rows, s.t_s);
                            }
                            _ => unreachable!("members of a source in increasing order"),
                        }
                    }
                }
            }
            if let Some(h) = waiting {
                if let Some(c) = self.candidates.get_mut(h) {
                    c.fold_shared(&row, &src.rows, s.t_s);
                }
            }
            if record {
                for &i in src.members.iter().filter(|i| wanted(i)) {
                    let c = &self.candidates[i];
                    self.residuals[i].record(c.qr().rss(), c.qr().residual_dof(), s.t_s);
                }
            }
        }
        if let Some(shadow) = self.shadow.as_mut() {
            // Every other sample, its gyro rate averaged over the double step: fed one
            // sample late, when the second rate is known.
            if self.samples.is_multiple_of(2) {
                self.held = Some(*s);
            } else if let Some(a) = self.held.take() {
                // The shadow's double step can turn too far for a row where the data's
                // single steps do not: it is dropped, and with it the bias term, rather
                // than stopping the run.
                if shadow.fold(&double_step(&a, s)).is_err() {
                    self.shadow = None;
                }
            }
        }
        self.samples += 1;
        if !folded {
            return Ok(None);
        }
        self.rule_out();
        self.blocks += 1;
        if self.twins.due(self.blocks) {
            self.check_twins();
        }
        for k in self.checks.iter_mut().flatten() {
            k.age += 1;
        }
        self.since_solve += 1;
        if self.since_solve < self.config.solve_every {
            return Ok(None);
        }
        self.fits.clear();
        for (i, c) in self.candidates.iter().enumerate() {
            self.fits.push(self.fit(i, c));
        }
        let (candidates, standing) = (&mut self.candidates, &self.standing);
        let (chosen, from_s) = pick(&self.fits, &self.rows, |i| {
            candidates
                .get_mut(i)
                .filter(|_| standing.live(i))
                .and_then(|c| c.jackknife_sigma())
        });
        self.chosen = chosen;
        self.from_s = self.rows.get(chosen).map_or(from_s, |r| {
            alternatives_from_s(r, from_s, self.config.max_chain_s)
        });
        let Some(c) = self.candidates.get_mut(self.chosen) else {
            return Ok(None);
        };
        if c.qr().rows() < 6 {
            return Ok(None);
        }
        self.since_solve = 0;
        let mut e = c.solve_now(s.t_s)?;
        // The eigenpairs of Ĵ, once for σ's principal moments, the cross-check and the
        // audit (a withdrawn answer has none, and none of them runs).
        let eig = e
            .j()
            .map_or(NO_EIGEN, |j| symmetric_eigen3(&matrix_from_j(&j)));
        let best = *c.reduced();
        let noise = self.noise_sigma(self.chosen);
        if self.config.uncertainty {
            if let (Some(_), Some(noise)) = (e.j(), noise) {
                let others = self
                    .candidates
                    .iter()
                    .enumerate()
                    .filter(|&(i, c)| {
                        i != self.chosen
                            && self.standing.live(i)
                            && in_running(c.row_settings(), self.from_s)
                    })
                    .map(|(_, c)| c.qr().reduced());
                let spread = model_spread(
                    &best,
                    others,
                    self.config.gyro_noise_rad_s_rthz,
                    &self.config.constraints,
                );
                let discretisation = match (self.candidates.first(), self.shadow.as_deref()) {
                    (Some(first), Some(shadow)) => discretisation_bias(
                        &first.qr().reduced(),
                        &shadow.qr().reduced(),
                        self.config.gyro_noise_rad_s_rthz,
                        &self.config.constraints,
                    ),
                    _ => [0.0; 6],
                };
                let bias = quadrature(&spread, &discretisation);
                e.uncertainty = Some(with_bias_at(&noise, &bias, &eig));
            }
        }
        // An answer on the floor whose negation would be determined (a reversed ρ: the
        // pipeline stops there) is told as that, before the cross-check, which would
        // withdraw it as the rotation sources' disagreement.
        let (epsilon, max_relative_sigma) = (
            self.config.constraints.set().epsilon_kg_m2,
            self.config.observability.max_relative_sigma,
        );
        if let Some(c) = self.candidates.get(self.chosen) {
            if reversed_at_floor(&e, c.solved(), epsilon, max_relative_sigma, &eig.0) {
                audit_at(
                    &mut e,
                    c.solved(),
                    epsilon,
                    max_relative_sigma,
                    Some(&eig.0),
                );
                return Ok(Some(e));
            }
        }
        self.cross_check(&mut e, &eig, s.t_s)?;
        let Some(c) = self.candidates.get(self.chosen) else {
            return Ok(Some(e));
        };
        audit_at(
            &mut e,
            c.solved(),
            self.config.constraints.set().epsilon_kg_m2,
            self.config.observability.max_relative_sigma,
            Some(&eig.0),
        );
        scale_from_prior(&mut e, c.reduced(), &self.config.constraints);
        // The density describes the gyro: its rows are the ones to compare with it (with
        // an attitude better than the gyro, the attitude's rows are quieter).
        // Under forgetting the counts are discounted and the test is not made.
        let described = self
            .candidates
            .iter()
            .enumerate()
            .find(|&(i, c)| {
                (i == 0 || self.standing.live(i))
                    && c.row_settings().rotation == RotationSource::Gyro
            })
            .map(|(_, c)| c);
        self.density_ratio = match (self.config.gyro_noise_rad_s_rthz, e.j(), described) {
            (Some(g), Some(j), Some(d)) if record => {
                consistency::gyro_density_ratio(&d.qr().reduced(), &j, g)
            }
            _ => None,
        };
        // The answer as the data gave it, withdrawn or not, is the reference of the spans
        // that start after it.
        if let (Some(j), Some(sigma)) = (e.j(), e.sigma_kg_m2()) {
            for r in &mut self.residuals {
                r.note(&j, &sigma);
            }
        }
        consistency::check(
            &mut e,
            self.residuals.get(self.chosen).filter(|_| record),
            self.density_ratio,
        );
        Ok(Some(e))
    }

    /// Weigh every candidate's (and the shadow's) rows for `drift` from now on.
    fn set_drift(&mut self, drift: Option<AttitudeDrift>) {
        self.drift = drift;
        for c in &mut self.candidates {
            c.set_drift(drift);
        }
        if let Some(shadow) = self.shadow.as_deref_mut() {
            shadow.set_drift(drift);
        }
    }

    /// Rule out the candidates the data have ruled out ([`standing`]). The first
    /// keeps folding without its jackknife: the discretisation bias compares it with the
    /// shadow whichever candidate is chosen.
    fn rule_out(&mut self) {
        self.standing.update(
            self.candidates
                .iter()
                .map(|c| (c.qr().residual_variance(), c.qr().residual_dof())),
        );
        for (i, c) in self.candidates.iter_mut().enumerate() {
            if !self.standing.live(i) {
                c.stop_jackknife();
            }
        }
    }

    /// Compare the candidates that differ only in the rotation source ([`twins`]);
    /// once they are found to be one measurement, rule out the attitude's.
    fn check_twins(&mut self) {
        let gyro = self.config.gyro_noise_rad_s_rthz;
        let constraints = &self.config.constraints;
        let answer = |c: &Candidate| own_answer(&c.qr().reduced(), gyro, constraints);
        let standing = &self.standing;
        let pairs = twins::pairs(&self.rows, |i| i == 0 || standing.live(i));
        if pairs.clone().next().is_none() {
            self.twins = Twins::NoPairs;
            return;
        }
        let candidates = &self.candidates;
        let worst = twins::worst(pairs.clone(), |i| answer(&candidates[i]));
        // The chosen candidate's twin, should the chosen one be ruled out.
        let chosen_twin = pairs
            .filter(|&(_, a)| a == self.chosen)
            .find_map(|(g, _)| g);
        self.twins = self.twins.after(worst, self.blocks, self.rule_out_after);
        if self.twins == Twins::Same {
            // Every attitude candidate still folded was compared with its twin (one
            // without keeps the verdict from `Same`): all of them go.
            let attitude = self.candidates.iter_mut().zip(&self.rows).enumerate();
            for (a, (c, _)) in attitude.filter(|(_, (_, r))| r.rotation == RotationSource::Attitude)
            {
                self.standing.rule_out(a);
                c.stop_jackknife();
            }
            // Until the next solve picks again (`solve_every` > 1), the report describes
            // the twin's rows, whose answer is the same within the test's margin.
            if let Some(g) = chosen_twin {
                self.chosen = g;
            }
        }
    }

    /// Per candidate `(residual variance, residual degrees of freedom, chain length)` for
    /// [`choose`], a ruled-out one's variance infinite.
    fn fit(&self, i: usize, c: &Candidate) -> (f64, f64, Option<f64>) {
        let v = if self.standing.live(i) {
            c.qr().residual_variance()
        } else {
            f64::INFINITY
        };
        (v, c.qr().residual_dof(), c.row_settings().max_chain_s)
    }
}

impl DiscreteMomentum {
    /// Withdraw a determined answer that another candidate's own answer contradicts
    /// beyond both σ ([`DISAGREE_Z`]); the other candidates' answers are refreshed every
    /// [`CROSS_CHECK_EVERY`] row blocks, or every [`CROSS_CHECK_SHARE`]th of the record so
    /// far if that is more and there is no forgetting ([`cross_check_every`]).
    fn cross_check(
        &mut self,
        e: &mut Estimate,
        eig: &Eigen,
        t_s: f64,
    ) -> Result<(), EstimatorError> {
        if self.candidates.len() < 2 || !matches!(e.observability, Observability::Determined { .. })
        {
            return Ok(());
        }
        let (Some(j), Some(u)) = (e.j(), e.uncertainty) else {
            return Ok(());
        };
        self.checks.resize(self.candidates.len(), None);
        let best_variance = self
            .candidates
            .get(self.chosen)
            .map_or(f64::INFINITY, |c| c.qr().residual_variance());
        self.others.clear();
        for i in 0..self.candidates.len() {
            let c = &self.candidates[i];
            if i == self.chosen
                || !self.standing.live(i)
                || !in_running(c.row_settings(), self.from_s)
                || c.qr().rows() < 6
                || !(c.qr().residual_variance() <= COMPARABLE_FIT * best_variance)
            {
                continue;
            }
            // How far the kept answer is from the present one: within reach of the
            // check (`cross_check_every`), or beyond it.
            let z = self.checks[i].and_then(|k| k.answer).and_then(|(jb, sb)| {
                disagreement_beyond(&j, &u.noise_kg_m2, &jb, &sb, DISAGREE_Z / 2.0)
            });
            let beyond = z.is_some_and(|z| z > DISAGREE_Z);
            let forgetting = self.config.memory_s.is_some();
            let stale = self.checks[i].is_none_or(|k| {
                k.answer.is_none()
                    || k.age >= cross_check_every(self.blocks, forgetting, z.is_some())
                    // A disagreement is never told by an answer older than this solve
                    // unless that answer disagreed when it was fresh.
                    || (beyond && !k.beyond && k.age > 0)
            });
            if stale {
                let own = self.candidates[i].solve_now(t_s)?;
                // An answer that is not determined is not compared, and is solved again
                // at the next block.
                let answer = match (own.observability, own.j(), self.noise_sigma(i)) {
                    (Observability::Determined { .. }, Some(j), Some(sigma)) => Some((j, sigma)),
                    _ => None,
                };
                let beyond = answer.is_some_and(|(jb, sb)| {
                    disagreement_beyond(&j, &u.noise_kg_m2, &jb, &sb, DISAGREE_Z).is_some()
                });
                self.checks[i] = Some(CrossCheck {
                    answer,
                    age: 0,
                    beyond,
                });
            }
            if let Some(answer) = self.checks[i].and_then(|k| k.answer) {
                self.others.push(answer);
            }
        }
        reconcile(
            e,
            eig,
            &self.others,
            self.config.observability.max_relative_sigma,
        );
        Ok(())
    }

    /// Candidate `i`'s noise σ at its last solve: its own, and for the whole record as one
    /// chain at least its chained siblings' jackknife σ ([`chained_siblings`]).
    fn noise_sigma(&mut self, i: usize) -> Option<[f64; 6]> {
        let rows = *self.candidates.get(i)?.row_settings();
        let own = self.candidates[i].robust_noise_sigma()?;
        let from_s = self.config.max_chain_s.unwrap_or(0.0);
        // No allocation per solve: the siblings are visited in place.
        let mut jackknife = None;
        for c in &mut self.candidates {
            if is_chained_sibling(&rows, c.row_settings(), from_s) {
                jackknife = sibling_jackknife([jackknife, c.jackknife_sigma()].into_iter());
            }
        }
        Some(robust_sigma(&own, jackknife.as_ref()))
    }
}

impl Estimator for DiscreteMomentum {
    fn push(&mut self, s: &Sample) -> Result<Option<Estimate>, EstimatorError> {
        if let Some(buffer) = self.replay.as_mut() {
            if buffer.len() < REPLAY_CAP {
                buffer.push(*s);
            } else {
                self.replay = None;
            }
        }
        let e = self.push_sample(s)?;
        let twin = match self.unweighted.as_mut() {
            Some((t, _)) => t.push_sample(s)?,
            None => None,
        };
        let (mut e, mut twin) = (e, twin);
        let drift = match (
            self.config.attitude_drift_deg_rth,
            self.config.gyro_noise_rad_s_rthz,
            e.as_ref().and_then(Estimate::j),
        ) {
            (Some(a), Some(g), Some(j)) => AttitudeDrift::new(a, g.to_degrees(), j),
            _ => None,
        };
        if let Some(d) = drift {
            if self.unweighted.is_some() {
                // Weighted already: the latest answer's Ĵ for the rows to come.
                self.set_drift(Some(d));
            } else if let Some(samples) = self.replay.take() {
                // The first answer: the run refolded from its first sample with the
                // rows weighted, the run so far going on unweighted beside it. Should
                // the refold fail where the unweighted run did not, the run stays
                // unweighted.
                if let Ok((fresh, last)) = self.replayed(&samples, d) {
                    let old = core::mem::replace(self, fresh);
                    self.unweighted = Some((Box::new(old), false));
                    (e, twin) = (last, e);
                }
            }
            // Past [`REPLAY_CAP`] samples before the first answer the rows stay
            // unweighted: weighting only the rows to come is worse than none.
        }
        // The unweighted answer where its discretisation and model bias outweigh its
        // noise ([`unweighted_is_better`]).
        if let (Some((_, twin_given)), Some(t)) = (self.unweighted.as_mut(), twin) {
            let take_twin = unweighted_is_better(&t);
            *twin_given = take_twin;
            if take_twin {
                e = Some(t);
            }
        }
        Ok(e)
    }

    fn gaps(&self) -> usize {
        self.sources.first().map_or(0, |g| g.rows.gaps())
    }

    fn excitation(&self) -> Option<Excitation> {
        let g = self.given();
        let c = g.candidates.get(g.chosen)?;
        (c.reduced().rows > 0).then(|| diagnose(c.reduced(), &g.config.observability))
    }

    fn row_model(&self) -> Option<MomentumRowSettings> {
        let g = self.given();
        g.candidates.get(g.chosen).map(|c| *c.row_settings())
    }

    fn torque_bias_nm(&self) -> Option<Vector3<f64>> {
        let g = self.given();
        g.candidates.get(g.chosen)?.torque_bias_nm()
    }

    fn torque_test(&self) -> Option<TorqueTest> {
        let g = self.given();
        g.candidates.get(g.chosen)?.torque_test()
    }

    fn residual_consistency(&self) -> Option<Worst> {
        let g = self.given();
        g.residuals.get(g.chosen)?.worst()
    }

    fn gyro_density_ratio(&self) -> Option<f64> {
        self.given().density_ratio
    }

    fn attitude_is_gyro_integral(&self) -> Option<bool> {
        match self.given().twins {
            Twins::Undecided | Twins::NoPairs => None,
            Twins::Same => Some(true),
            Twins::Independent => Some(false),
        }
    }

    fn drift_weighted(&self) -> Option<bool> {
        self.config
            .attitude_drift_deg_rth
            .map(|_| matches!(self.unweighted, Some((_, false))))
    }
}

fn run_batch(samples: &[Sample], c: &PipelineConfig) -> Result<BatchOutput, PipelineError> {
    let wrap = |source| PipelineError::Estimator {
        sample: match source {
            EstimatorError::Row { sample, .. } => Some(sample),
            _ => None,
        },
        source,
    };
    // The drift weighting needs an estimate of J before each row is folded: recursive
    // runs only.
    if c.attitude_drift_deg_rth.is_some() {
        return Err(PipelineError::NotApplicable {
            setting: "attitude_drift_deg_rth",
            estimator: "discrete-momentum batch",
        });
    }
    let has_gyro = samples.first().is_some_and(|s| s.omega_rad_s.is_some());
    let mut reduced: Vec<(MomentumRowSettings, BatchReduction)> = Vec::new();
    for rows in candidates(c, has_gyro) {
        reduced.push((rows, reduce_batch(samples, &rows).map_err(wrap)?));
    }
    let attitude_is_gyro_integral = drop_batch_twins(&mut reduced, c);
    let fits: Vec<(f64, f64, Option<f64>)> = reduced
        .iter()
        .map(|(rows, b)| {
            (
                b.qr.residual_variance(),
                b.qr.residual_dof(),
                rows.max_chain_s,
            )
        })
        .collect();
    let rows: Vec<MomentumRowSettings> = reduced.iter().map(|(r, _)| *r).collect();
    let (chosen, from_s) = pick(&fits, &rows, |i| {
        reduced.get(i).and_then(|(_, b)| b.jackknife_sigma_kg_m2)
    });
    let from_s = rows
        .get(chosen)
        .map_or(from_s, |r| alternatives_from_s(r, from_s, c.max_chain_s));
    let Some((rows, batch)) = reduced.get(chosen) else {
        return Err(PipelineError::NoBatch {
            estimator: DISCRETE_MOMENTUM.name,
        });
    };
    let qr = &batch.qr;
    let (tested, torque_test) = torque_tested(batch.qr, batch.without_torque);
    let mut backend = registry::build_backend(c.backend);
    let t_s = samples.last().map_or(0.0, |s| s.t_s);
    // One candidate's own answer and noise σ (for the whole record as one chain, at
    // least its chained siblings' jackknife σ: [`chained_siblings`]).
    let mut own = |i: usize| -> Result<(Estimate, Option<[f64; 6]>), PipelineError> {
        let (rows, b) = &reduced[i];
        let sibling = sibling_jackknife(
            chained_siblings(
                rows,
                reduced.iter().map(|(r, _)| r),
                c.max_chain_s.unwrap_or(0.0),
            )
            .map(|k| reduced[k].1.jackknife_sigma_kg_m2),
        );
        // As the recursive solve does: the torque held at zero where the data give no
        // evidence of one.
        let (tested, _) = torque_tested(b.qr, b.without_torque);
        let e = batch::solve_reduced(
            &tested,
            t_s,
            &c.constraints,
            &mut *backend,
            &c.observability,
            c.gyro_noise_rad_s_rthz,
        )
        .map_err(wrap)?;
        // With prior knowledge, σ is the least-squares one of the data and the prior
        // together, or the data's own jackknife σ where that is larger (the batch
        // jackknife's delete-one solves carry no prior: conservative).
        let (solved, _) = prior::augment(&tested, &c.constraints);
        let jackknife = sibling_jackknife([b.jackknife_sigma_kg_m2, sibling].into_iter());
        let svd = nalgebra::SVD::try_new(
            solved.r,
            false,
            true,
            f64::EPSILON,
            crate::math::MAX_DECOMPOSITION_ITERATIONS,
        );
        let noise = svd.and_then(|svd| {
            let v_t = svd.v_t?;
            noise_sigma(&solved, &svd.singular_values, &v_t.transpose())
                .map(|ls| robust_sigma(&prior::zero_fixed(ls, &c.constraints), jackknife.as_ref()))
        });
        Ok((e, noise))
    };
    let (mut estimate, noise) = own(chosen)?;
    // The chosen rows with the prior's: what the audit judges.
    let augmented = prior::augment(&tested, &c.constraints).0;
    if c.uncertainty {
        if let (Some(j), Some(noise)) = (estimate.j(), noise) {
            let others = reduced
                .iter()
                .enumerate()
                .filter(|&(i, (r, _))| i != chosen && in_running(r, from_s))
                .map(|(_, (_, b))| b.qr);
            let spread = model_spread(&tested, others, c.gyro_noise_rad_s_rthz, &c.constraints);
            // As in the recursive path: the first candidate on every other sample.
            let half: Vec<Sample> = samples
                .chunks_exact(2)
                .map(|p| double_step(&p[0], &p[1]))
                .collect();
            let discretisation = match (reduced.first(), c.gyro_noise_rad_s_rthz) {
                (Some((first, full)), gyro) => match reduce_batch(&half, first) {
                    Ok(h) => discretisation_bias(&full.qr, &h.qr, gyro, &c.constraints),
                    Err(_) => [0.0; 6],
                },
                _ => [0.0; 6],
            };
            let bias = quadrature(&spread, &discretisation);
            estimate.uncertainty = Some(with_bias(&noise, &bias, &j));
        }
        // As in the recursive path: a reversed ρ is told before the cross-check.
        let reversed = estimate.j().is_some_and(|j| {
            reversed_at_floor(
                &estimate,
                &augmented,
                c.constraints.set().epsilon_kg_m2,
                c.observability.max_relative_sigma,
                &symmetric_eigen3(&matrix_from_j(&j)).0,
            )
        });
        if !reversed && matches!(estimate.observability, Observability::Determined { .. }) {
            let mut others = Vec::new();
            for (i, (r, b)) in reduced.iter().enumerate() {
                if i == chosen
                    || !in_running(r, from_s)
                    || !(b.qr.residual_variance() <= COMPARABLE_FIT * qr.residual_variance())
                {
                    continue;
                }
                if let (e, Some(sigma)) = own(i)? {
                    if let (Observability::Determined { .. }, Some(jb)) = (e.observability, e.j()) {
                        others.push((jb, sigma));
                    }
                }
            }
            if let Some(j) = estimate.j() {
                let eig = symmetric_eigen3(&matrix_from_j(&j));
                reconcile(
                    &mut estimate,
                    &eig,
                    &others,
                    c.observability.max_relative_sigma,
                );
            }
        }
    }
    audit(
        &mut estimate,
        &augmented,
        c.constraints.set().epsilon_kg_m2,
        c.observability.max_relative_sigma,
    );
    scale_from_prior(&mut estimate, &tested, &c.constraints);
    // The residuals against the stated gyro density, as in the recursive path: the gyro
    // rotation's rows are the ones the density describes. (The span test needs the
    // recursive residuals, which a batch reduction does not form.)
    let gyro_density_ratio = match (c.gyro_noise_rad_s_rthz, estimate.j()) {
        (Some(g), Some(j)) => reduced
            .iter()
            .find(|(rows, _)| rows.rotation == RotationSource::Gyro)
            .and_then(|(_, b)| consistency::gyro_density_ratio(&b.qr, &j, g)),
        _ => None,
    };
    consistency::check(&mut estimate, None, gyro_density_ratio);
    Ok(BatchOutput {
        gyro_density_ratio,
        estimate,
        excitation: Some(diagnose(&tested, &c.observability)),
        gaps: batch.gaps,
        row_model: Some(*rows),
        torque_test,
        attitude_is_gyro_integral,
    })
}

/// The batch form of the test for an attitude that is the gyro's own integral
/// ([`twins`]): over a record of at least [`RULE_OUT_AFTER`] row blocks (the
/// recursive test's horizon), the pairs of candidates that differ only in the rotation
/// source are compared once, on the whole record; within [`twins::TWIN_Z`], the
/// attitude's candidates are left out. `Some(verdict)` where the test was made, `None`
/// for a shorter record or without both sources.
fn drop_batch_twins(
    reduced: &mut Vec<(MomentumRowSettings, BatchReduction)>,
    c: &PipelineConfig,
) -> Option<bool> {
    let rows: Vec<MomentumRowSettings> = reduced.iter().map(|(r, _)| *r).collect();
    let pairs = twins::pairs(&rows, |_| true);
    let blocks = reduced.first().map_or(0, |(_, b)| b.qr.rows / 3);
    if pairs.clone().next().is_none() || blocks < RULE_OUT_AFTER {
        return None;
    }
    let worst = twins::worst(pairs, |i| {
        own_answer(&reduced[i].1.qr, c.gyro_noise_rad_s_rthz, &c.constraints)
    });
    // Every attitude candidate has a twin where the verdict is `Same` ([`twins::worst`]).
    let same = worst.is_some_and(|z| z <= twins::TWIN_Z);
    if same {
        reduced.retain(|(r, _)| r.rotation != RotationSource::Attitude);
    }
    Some(same)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::PipelineSettings;
    use crate::sim::realism::{AttitudeSource, Realism};
    use crate::sim::scenario::{Common, Scenario};

    /// The default settings but J ⪰ εI: the paper's J lies slightly outside Σ ⪰ 0
    /// (docs/conventions.md §4), so that the truth is in the set and the answer carries
    /// no constraint bias.
    fn truth_inside() -> PipelineConfig {
        PipelineSettings {
            constraints: crate::constraints::ConstraintSet::positive_definite(),
            ..PipelineSettings::default()
        }
        .validate()
        .unwrap()
    }

    /// The refresh interval of a determined answer: 50 blocks early on, a twentieth of
    /// the record later, and 50 whatever the record's length under forgetting and for an
    /// answer within reach of the threshold.
    #[test]
    fn cross_check_refreshes_grow_with_the_record_where_the_verdict_is_settled() {
        assert_eq!(cross_check_every(0, false, false), CROSS_CHECK_EVERY);
        assert_eq!(cross_check_every(999, false, false), CROSS_CHECK_EVERY);
        assert_eq!(cross_check_every(10_000, false, false), 500);
        assert_eq!(cross_check_every(1_000_000, false, false), 50_000);
        for (forgetting, near) in [(true, false), (false, true), (true, true)] {
            assert_eq!(
                cross_check_every(1_000_000, forgetting, near),
                CROSS_CHECK_EVERY
            );
        }
    }

    /// Problem: pairs of answers and σ drawn around the threshold (differences of 0–8 σ
    /// per element, in a third of the cases one of them within 1e-12 of exactly
    /// `DISAGREE_Z` σ), differences within a few units of rounding of the threshold,
    /// squares that underflow or overflow, plus zero,
    /// infinite and NaN differences and variances. Reference: the exact `disagreement`
    /// compared with the threshold. The squares' shortcut must give the same verdict and
    /// the same value, every time.
    #[test]
    fn disagreement_beyond_is_the_exact_verdict() {
        let mut rnd = crate::testing::uniform(0x5eed_d15a_9ee0_0001);
        let z = DISAGREE_Z;
        let mut cases = Vec::new();
        for n in 0..20_000 {
            let sa: [f64; 6] = core::array::from_fn(|_| (rnd() + 0.5) * 1e-3);
            let sb: [f64; 6] = core::array::from_fn(|_| (rnd() + 0.5) * 1e-3);
            let a = InertiaVector::from_fn(|_, _| 1.0 + rnd());
            // The largest difference of this case, in σ.
            let level = 8.0 * (rnd() + 0.5);
            let b = InertiaVector::from_fn(|k, _| {
                let s = (sa[k] * sa[k] + sb[k] * sb[k]).sqrt();
                let t = if n % 3 == 0 && k == n % 6 {
                    z * (1.0 + 1e-12 * rnd())
                } else {
                    level * (rnd() + 0.5)
                };
                a[k] + t * s * if rnd() < 0.0 { -1.0 } else { 1.0 }
            });
            cases.push((a, sa, b, sb));
        }
        let a = InertiaVector::repeat(1.0);
        for special in [0.0, f64::INFINITY, f64::NAN] {
            cases.push((a, [special; 6], a, [special; 6]));
            cases.push((a, [special; 6], a.add_scalar(1e-6), [special; 6]));
            cases.push((a, [1e-3; 6], a.add_scalar(special), [1e-3; 6]));
        }
        // Differences of exactly `t σ`, `t` a few units of rounding either side of the
        // threshold: where a test by squares without its margin decides differently.
        for n in 0..20_000 {
            let sa: [f64; 6] = core::array::from_fn(|_| (rnd() + 0.5) * 1e-3);
            let sb: [f64; 6] = core::array::from_fn(|_| (rnd() + 0.5) * 1e-3);
            let k = n % 6;
            let ulps = (rnd() * 16.0).round();
            let s = (sa[k] * sa[k] + sb[k] * sb[k]).sqrt();
            let mut b = InertiaVector::zeros();
            b[k] = z * (1.0 + ulps * f64::EPSILON) * s;
            cases.push((InertiaVector::zeros(), sa, b, sb));
        }
        // Squares that underflow (both to zero: 1e-170 against σ 1e-175 is far beyond)
        // or overflow.
        let zero = InertiaVector::zeros();
        for (d, s) in [
            (1e-170, 1e-175),
            (1e-170, 1e-160),
            (1e154, 3e152),
            (1e154, 1e153),
        ] {
            cases.push((zero, [s; 6], InertiaVector::repeat(d), [s; 6]));
        }
        let mut beyond = 0;
        for (a, sa, b, sb) in &cases {
            let exact = disagreement(a, sa, b, sb);
            let want = (exact > z).then_some(exact);
            let got = disagreement_beyond(a, sa, b, sb, z);
            assert_eq!(
                got.map(f64::to_bits),
                want.map(f64::to_bits),
                "{a:?} {sa:?} {b:?} {sb:?}"
            );
            beyond += usize::from(got.is_some());
        }
        // Both verdicts occur, near the threshold too.
        assert!(beyond > 1000 && beyond < cases.len() - 1000, "{beyond}");
    }

    /// Every sample through a new estimator: the estimator and its last answer.
    fn run_to_the_end(config: &PipelineConfig, samples: &[Sample]) -> (DiscreteMomentum, Estimate) {
        let mut p = DiscreteMomentum::new(config).unwrap();
        let mut last = None;
        for s in samples {
            last = p.push(s).unwrap().or(last);
        }
        (p, last.expect("an answer"))
    }

    /// With star-tracker attitudes the attitude candidates fit far worse than the gyro
    /// ones and are ruled out; every answer (ĵ, status, σ) is still exactly that of the
    /// run that folds them to the end.
    #[test]
    fn ruling_out_candidates_changes_no_answer() {
        let common = Common {
            duration_s: Some(900.0),
            realism: Realism {
                attitude: AttitudeSource::StarTracker,
                ..Realism::default()
            },
            ..Common::paper()
        };
        let config = PipelineSettings::default().validate().unwrap();
        for scenario in [Scenario::slew(), Scenario::spin()] {
            let run = scenario.simulate(&common).unwrap();
            let mut pruned = DiscreteMomentum::new(&config).unwrap();
            let mut full = DiscreteMomentum {
                rule_out_after: usize::MAX,
                ..DiscreteMomentum::new(&config).unwrap()
            };
            let mut answers = 0;
            for s in &run.samples {
                let (a, b) = (pruned.push(s).unwrap(), full.push(s).unwrap());
                assert_eq!(a, b, "t = {}", s.t_s);
                answers += usize::from(a.and_then(|e| e.j()).is_some());
            }
            assert!(answers > 1000);
            // Gyro and attitude rotations, each in shortest, short, long and whole-record
            // chains.
            assert_eq!(pruned.candidates.len(), 8);
            assert!(pruned.standing.live(0));
            assert!([1, 3, 5, 7].iter().all(|&i| !pruned.standing.live(i)));
            assert!((0..8).all(|i| full.standing.live(i)));
            // The star tracker's rotations are not the gyro's: both sources are kept
            // until the fit rules one out.
            assert_eq!(pruned.twins, Twins::Independent);
            assert_eq!(pruned.attitude_is_gyro_integral(), Some(false));
            let batch = run_batch(&run.samples, &config).unwrap();
            assert_eq!(batch.attitude_is_gyro_integral, Some(false));
        }
    }

    /// The paper's gyro-propagated attitude is the gyro's own integral: once its
    /// candidates' answers have matched the gyro's twins within [`twins::TWIN_Z`] of
    /// their σ through [`RULE_OUT_AFTER`] row blocks, they are ruled out (4 folds instead
    /// of 8), and every later answer is the one of the run that folds all 8 to within a
    /// tenth of its σ, with the same status (its figures, such as a χ², move with the
    /// answer); the rotation source reported is the gyro.
    #[test]
    fn an_attitude_that_is_the_gyros_integral_is_not_folded_twice() {
        let common = Common {
            duration_s: Some(400.0),
            ..Common::paper()
        };
        let config = PipelineSettings::default().validate().unwrap();
        let run = Scenario::slew().simulate(&common).unwrap();
        let mut pruned = DiscreteMomentum::new(&config).unwrap();
        let mut full = DiscreteMomentum {
            rule_out_after: usize::MAX,
            ..DiscreteMomentum::new(&config).unwrap()
        };
        let (mut compared, mut worst) = (0, 0.0f64);
        for s in &run.samples {
            let (a, b) = (pruned.push(s).unwrap(), full.push(s).unwrap());
            let (Some(a), Some(b)) = (a, b) else {
                assert_eq!(a.is_some(), b.is_some(), "t = {}", s.t_s);
                continue;
            };
            assert_eq!(
                core::mem::discriminant(&a.observability),
                core::mem::discriminant(&b.observability),
                "t = {}",
                s.t_s
            );
            if let (Some(ja), Some(jb), Some(sb)) = (a.j(), b.j(), b.sigma_kg_m2()) {
                for k in 0..6 {
                    worst = worst.max((ja[k] - jb[k]).abs() / sb[k]);
                }
                compared += 1;
            }
        }
        assert!(compared > 3500, "{compared}");
        assert!(worst <= twins::TWIN_Z, "{worst}");
        assert_eq!(pruned.twins, Twins::Same);
        assert_eq!(full.twins, Twins::Undecided);
        assert_eq!(pruned.attitude_is_gyro_integral(), Some(true));
        assert_eq!(full.attitude_is_gyro_integral(), None);
        assert!([0, 2, 4, 6].iter().all(|&i| pruned.standing.live(i)));
        assert!([1, 3, 5, 7].iter().all(|&i| !pruned.standing.live(i)));
        assert_eq!(
            pruned.row_model().map(|r| r.rotation),
            Some(RotationSource::Gyro)
        );
        // The batch run makes the same test once, on the whole record: the same
        // verdict, and the attitude's candidates left out of the choice. Over a record
        // shorter than the horizon, no test.
        let batch = run_batch(&run.samples, &config).unwrap();
        assert_eq!(batch.attitude_is_gyro_integral, Some(true));
        assert_eq!(
            batch.row_model.map(|r| r.rotation),
            Some(RotationSource::Gyro)
        );
        let short = run_batch(&run.samples[..2000], &config).unwrap();
        assert_eq!(short.attitude_is_gyro_integral, None);
    }

    /// [`pick`] on made-up fits: the shortest chain fits best; a longer chain of the
    /// same rows whose jackknife σ is more than [`STEADIER`] times smaller takes its place
    /// (the smallest such), after which the fit chooses among the chains at least that
    /// long; a margin below [`STEADIER`], another rotation source's steadier chain, or no
    /// jackknife σ for the fitted one leave the fit's pick.
    #[test]
    fn a_clearly_steadier_longer_chain_takes_the_place_of_the_best_fit() {
        let rows = crate::testing::rows;
        let (g, a) = (RotationSource::Gyro, RotationSource::Attitude);
        let all = [
            rows(g, Some(7.5)),
            rows(g, Some(30.0)),
            rows(g, Some(120.0)),
            rows(g, None),
            rows(a, Some(7.5)),
        ];
        let dof = 1e4;
        // Variances: the shortest chains clearly best, the whole record clearly worst.
        let fits = |v: [f64; 5]| -> std::vec::Vec<(f64, f64, Option<f64>)> {
            v.iter()
                .zip(&all)
                .map(|(v, r)| (*v, dof, r.max_chain_s))
                .collect()
        };
        let sigma = |s: f64| Some([s; 6]);
        let jk = |s: [Option<f64>; 5]| move |i: usize| s[i].and_then(sigma);
        let f = fits([1.0, 1.2, 1.3, 2.0, 1.0]);
        // 30 s twice as steady, 120 s 2.5 times: 120 s.
        let steady = jk([Some(5.0), Some(2.5), Some(2.0), None, Some(5.0)]);
        assert_eq!(pick(&f, &all, steady), (2, 120.0));
        // As steady, but the whole record fits as well as 120 s: the whole record.
        let f2 = fits([1.0, 1.2, 1.3, 1.3, 1.0]);
        assert_eq!(pick(&f2, &all, steady).0, 3);
        // Only 1.25 times steadier: the best fit stays.
        let close = jk([Some(5.0), Some(4.0), Some(4.0), None, Some(5.0)]);
        assert_eq!(pick(&f, &all, close), (0, 0.0));
        // The fitted one without a jackknife σ: stays.
        let none = jk([None, Some(1.0), Some(1.0), None, Some(5.0)]);
        assert_eq!(pick(&f, &all, none), (0, 0.0));
        // The attitude's shortest chain fits best; only the gyro's chains are steadier.
        let f3 = fits([1.1, 1.2, 1.3, 2.0, 1.0]);
        let gyro_steady = jk([Some(5.0), Some(1.0), Some(1.0), None, Some(5.0)]);
        assert_eq!(pick(&f3, &all, gyro_steady), (4, 0.0));
        // Alternatives: in the running, and no shorter than `--chain` unless the chosen
        // one is.
        assert_eq!(alternatives_from_s(&all[3], 0.0, Some(30.0)), 30.0);
        assert_eq!(alternatives_from_s(&all[0], 0.0, Some(30.0)), 7.5);
        assert_eq!(alternatives_from_s(&all[2], 120.0, Some(30.0)), 120.0);
        assert_eq!(alternatives_from_s(&all[3], 0.0, None), 0.0);
    }

    /// Where a gyro-propagated attitude drifts within the chains (the paper's spin with
    /// its gyro), the shortest chains fit best, are chosen, and are closer to the truth
    /// than the same rows in `--chain` chains (errors summed over seeds, 3σ coverage per
    /// element); on the small satellite they fit best too but scatter more across chains,
    /// and a longer chain is chosen.
    #[test]
    fn the_shortest_chains_are_chosen_where_they_are_steadier() {
        let config = truth_inside();
        let short = config.max_chain_s.unwrap();
        let (mut chosen_sum, mut chain_sum) = (0.0, 0.0);
        for seed in 1..=3 {
            let common = Common {
                seed,
                realism: Realism {
                    attitude: AttitudeSource::GyroPropagated,
                    ..Realism::default()
                },
                ..Common::paper()
            };
            let run = Scenario::spin().simulate(&common).unwrap();
            let (mut p, e) = run_to_the_end(&config, &run.samples);
            let chosen = *p.candidates[p.chosen].row_settings();
            assert_eq!(
                chosen.max_chain_s,
                Some(short / SHORT_CHAIN_DIVISOR),
                "seed {seed}"
            );
            let truth = crate::tensor::j_from_matrix(&run.inertia_kg_m2);
            let (j, sigma) = (e.j().unwrap(), e.sigma_kg_m2().unwrap());
            for k in 0..6 {
                assert!(
                    (j[k] - truth[k]).abs() <= 3.0 * sigma[k],
                    "seed {seed}, {k}"
                );
            }
            let k = p
                .candidates
                .iter()
                .position(|c| {
                    let r = c.row_settings();
                    r.rotation == chosen.rotation && r.max_chain_s == Some(short)
                })
                .unwrap();
            let own = p.candidates[k].solve_now(e.t_s).unwrap().j().unwrap();
            chosen_sum += (j - truth).norm();
            chain_sum += (own - truth).norm();
        }
        assert!(
            chosen_sum < chain_sum,
            "{chosen_sum:e} against {chain_sum:e}"
        );
        for seed in 1..=2 {
            // Its wheels and slews, the paper's gyro propagating the attitude, 10 Hz wheel
            // commands.
            let preset = crate::sim::presets::Preset::small_sat();
            let mut common = preset.common;
            common.seed = seed;
            common.gyro_noise_deg_s_rthz = 1e-5;
            common.realism = Realism {
                attitude: AttitudeSource::GyroPropagated,
                gyro: Default::default(),
                star_tracker: Default::default(),
                mekf: Default::default(),
                commands: Some(crate::sim::CommandHold::at(10.0)),
                ..common.realism
            };
            let run = preset.scenario.simulate(&common).unwrap();
            let mut p = DiscreteMomentum::new(&config).unwrap();
            for s in &run.samples {
                p.push(s).unwrap();
            }
            let fitted = choose(
                p.candidates.iter().enumerate().map(|(i, c)| p.fit(i, c)),
                0.0,
            );
            let shortest = Some(short / SHORT_CHAIN_DIVISOR);
            assert_eq!(p.rows[fitted].max_chain_s, shortest, "seed {seed}");
            assert!(p.rows[p.chosen].max_chain_s != shortest, "seed {seed}");
        }
    }

    #[test]
    fn a_whole_record_candidate_has_two_chained_siblings_and_others_none() {
        let config = PipelineSettings::default().validate().unwrap();
        let all = candidates(&config, true);
        assert_eq!(all.len(), 8);
        for (i, rows) in all.iter().enumerate() {
            let siblings: std::vec::Vec<usize> =
                chained_siblings(rows, all.iter(), config.max_chain_s.unwrap()).collect();
            if rows.max_chain_s.is_some() {
                assert!(siblings.is_empty(), "{i}");
                continue;
            }
            // The short and the long chains of the same rows (not the shortest).
            let lengths: std::vec::Vec<Option<f64>> =
                siblings.iter().map(|&k| all[k].max_chain_s).collect();
            let short = config.max_chain_s;
            assert_eq!(
                lengths,
                [short, short.map(|l| LONG_CHAIN_FACTOR * l)],
                "{i}"
            );
            assert!(siblings.iter().all(|&k| all[k].rotation == rows.rotation));
        }
        let max = sibling_jackknife(
            [Some([1.0; 6]), None, Some([0.5, 2.0, 0.5, 2.0, 0.5, 2.0])].into_iter(),
        );
        assert_eq!(max, Some([1.0, 2.0, 1.0, 2.0, 1.0, 2.0]));
        assert_eq!(sibling_jackknife([None, None].into_iter()), None);
        // `--chain 0`: every candidate is one chain, with no sibling.
        let unchained = PipelineSettings {
            estimator: "discrete-momentum".into(),
            max_chain_s: None,
            ..PipelineSettings::default()
        }
        .validate()
        .unwrap();
        let all = candidates(&unchained, true);
        assert_eq!(all.len(), 2);
        assert!(all
            .iter()
            .all(|r| chained_siblings(r, all.iter(), 0.0).next().is_none()));
    }

    /// Where nothing drifts (true attitude, 1 Hz slew: the short chains' anchors only
    /// cost information), the whole record is chosen, is closer than the short chains'
    /// answer, and its σ is at least its chained siblings' jackknife σ and covers the
    /// truth; where the attitude drifts (spin, attitude propagated from a FOG-grade
    /// gyro), the whole record fits worse and is not chosen.
    #[test]
    fn the_whole_record_is_chosen_where_nothing_drifts() {
        let config = truth_inside();
        let run_of = |scenario: Scenario, realism: Realism, seed: u64| {
            let common = Common {
                seed,
                realism,
                ..Common::paper()
            };
            scenario.simulate(&common).unwrap()
        };
        let one_hz = Realism {
            attitude: AttitudeSource::Truth,
            telemetry_every: 10,
            ..Realism::default()
        };
        let mut chosen_whole = 0;
        for seed in 1..=4 {
            let run = run_of(Scenario::slew(), one_hz, seed);
            let (mut p, e) = run_to_the_end(&config, &run.samples);
            let chosen = *p.candidates[p.chosen].row_settings();
            if chosen.max_chain_s.is_some() {
                continue;
            }
            chosen_whole += 1;
            let truth = crate::tensor::j_from_matrix(&run.inertia_kg_m2);
            let (j, sigma) = (e.j().unwrap(), e.sigma_kg_m2().unwrap());
            let siblings: std::vec::Vec<usize> = chained_siblings(
                &chosen,
                p.candidates.iter().map(|c| c.row_settings()),
                config.max_chain_s.unwrap(),
            )
            .collect();
            let short = p.candidates[siblings[0]]
                .solve_now(e.t_s)
                .unwrap()
                .j()
                .unwrap();
            let jackknife = sibling_jackknife(
                siblings
                    .iter()
                    .map(|&k| p.candidates[k].jackknife_sigma())
                    .collect::<std::vec::Vec<_>>()
                    .into_iter(),
            )
            .expect("jackknife");
            assert!((j - truth).norm() < (short - truth).norm(), "seed {seed}");
            for k in 0..6 {
                assert!(sigma[k] >= jackknife[k], "seed {seed}, element {k}");
                assert!(
                    (j[k] - truth[k]).abs() <= 3.0 * sigma[k],
                    "seed {seed}, element {k}: error {:e}, σ {:e}, jackknife {:e}",
                    j[k] - truth[k],
                    sigma[k],
                    jackknife[k]
                );
            }
        }
        assert!(chosen_whole >= 3, "{chosen_whole} of 4 seeds");
        let fog = Realism {
            attitude: AttitudeSource::GyroPropagated,
            ..Realism::default()
        };
        for seed in 1..=2 {
            let mut common = Common {
                seed,
                realism: fog,
                ..Common::paper()
            };
            common.gyro_noise_deg_s_rthz = 3.3e-4;
            let run = Scenario::spin().simulate(&common).unwrap();
            let mut p = DiscreteMomentum::new(&config).unwrap();
            for s in &run.samples {
                p.push(s).unwrap();
            }
            let chosen = p.candidates[p.chosen].row_settings();
            assert!(chosen.max_chain_s.is_some(), "seed {seed}: {chosen:?}");
        }
    }
}
