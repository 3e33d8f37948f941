//! The discrete momentum rows of all samples at once (paper eq. 57's batch form for the
//! momentum rows): a dense Householder QR per chain over the columns the rows use, the
//! chain's initial momenta minimised out, then once over the stacked shared rows; with
//! the delete-a-group jackknife over chains or time blocks ([`crate::estimator::jackknife`]),
//! the state with the body torque held at zero ([`super::torque_tested`]) and the
//! damping's row. Independent of the recursive path: the two must agree.

use super::*;
use crate::estimator as est;
use crate::estimator::momentum_rows::{CENTRE_OF_MASS, DIPOLE};

mod damping;
use damping::without_damping;
pub(crate) use damping::{DampingRow, WithoutDamping};
mod shared_factor;
pub(crate) use shared_factor::{SharedFactor, ROTOR};

/// A row, its rotor parameters' columns ([`est::rotor_calibration::columns`]) and its
/// record ([`crate::pipeline::interface::BatchInputs::records`]).
type RowWithRotors<'a> = (AugmentedRow, &'a [Vector3<f64>], usize);

/// The batch reduction: the reduced problem in `j` and what goes with it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BatchReduction {
    /// The reduced least-squares state in `j`.
    pub(crate) qr: RecursiveQr,
    /// Gaps in the time stamps.
    pub(crate) gaps: usize,
    /// The delete-a-group jackknife σ per element over the chains
    /// ([`crate::estimator::jackknife`]), kg m²; `None` with too few chains.
    pub(crate) jackknife_sigma_kg_m2: Option<[f64; 6]>,
    /// The reduced state with the disturbance torque held at zero, and the growth of `ρ²`
    /// that costs ([`torque_tested`]); `None` when the torque is not estimated.
    pub(crate) without_torque: Option<(RecursiveQr, f64)>,
    /// The damping's row of the shared factor, where the rows estimate one.
    pub(crate) damping: Option<DampingRow>,
    /// The reduced states with the damping held at zero, where the rows estimate it.
    pub(crate) without_damping: Option<WithoutDamping>,
    /// The shared factor, for the outside torques' and the rotors' values, where the rows
    /// use them.
    pub(crate) shared: Option<SharedFactor>,
}

/// A delete-one-group answer: `j`, the damping `D` (where the rows estimate it) and the
/// rotor parameters (whitened, where the rows estimate them).
type Deleted = (InertiaVector, Option<f64>, Option<std::vec::Vec<f64>>);

#[cfg(test)]
impl BatchReduction {
    /// The damping `D` (N m s) that fits best at `j`, with its least-squares σ, where the
    /// rows estimate one.
    #[must_use]
    pub(crate) fn damping_at(&self, j: &InertiaVector) -> Option<(f64, Option<f64>)> {
        self.damping.map(|d| d.at(j))
    }
}

/// The factor that puts a χ² of `k` degrees of freedom on the scale of the torque test's
/// χ²₃ ([`super::TORQUE_CHI2`], its 0.999 quantile), matched at the 0.999 quantiles: 1 for
/// `k ≤ 3`, else `TORQUE_CHI2 / q_k` with `q_k` the Wilson–Hilferty approximation of
/// χ²_k's 0.999 quantile, `k (1 − 2/(9k) + z √(2/(9k)))³`, `z = 3.0902` (within 2 % of
/// the exact quantile for `k ≥ 3`; 16.5 for `k = 3` against 16.27).
#[must_use]
pub(crate) fn equivalent_chi2_scale(k: usize) -> f64 {
    if k <= 3 {
        return 1.0;
    }
    let k = k as f64;
    let a = 2.0 / (9.0 * k);
    let q = k * (1.0 - a + 3.0902 * crate::math::sqrt(a)).powi(3);
    super::TORQUE_CHI2 / q
}

/// The reduced least-squares state of all samples at once, by dense Householder QR: per
/// chain over `[X₀ X₁ τ_b κ j]` (the columns the rows use), keeping the rows free of the chain's initial momenta, then
/// once over the stacked `[τ_b j]` rows of every chain (and, for the jackknife, of every
/// chain but one group's). With rotor `sources` (each one's 1σ change of every sample's
/// rotor momentum), their parameters are shared unknowns after the torque's, with a
/// prior row each ([`crate::estimator::rotor_calibration`]).
pub(crate) fn reduce_batch(
    samples: &[Sample],
    settings: &MomentumRowSettings,
    sources: &crate::pipeline::interface::BatchInputs,
) -> Result<BatchReduction, EstimatorError> {
    use est::jackknife::{jackknife_sigma, GROUPS, MIN_GROUPS};
    use est::momentum_rows::J;
    use est::unknowns::FIRST_SHARED;
    use nalgebra::{DMatrix, DVector};
    if samples.len() < est::MIN_SAMPLES {
        return Err(EstimatorError::TooFewSamples {
            need: est::MIN_SAMPLES,
            got: samples.len(),
        });
    }
    let mut source = MomentumRows::new(*settings);
    let mut clock = ChainClock::new(settings.max_chain_s);
    use std::{vec, vec::Vec};
    // Each chain with its record: the rows restart at each record's first sample (no row
    // spans two records, whatever the gap between them), which starts a chain.
    let mut chains: Vec<(usize, Vec<AugmentedRow>)> = vec![(0, Vec::new())];
    let mut epoch = 0;
    let (mut record, mut gaps) = (0, 0);
    for (i, s) in samples.iter().enumerate() {
        if sources.record_of(i) != record {
            record = sources.record_of(i);
            gaps += source.gaps();
            source = MomentumRows::new(*settings);
            clock = ChainClock::new(settings.max_chain_s);
        }
        let row = source
            .push(s)
            .map_err(|source| EstimatorError::Row { sample: i, source })?;
        if let Some(row) = row {
            let e = clock.epoch(&source);
            if e != epoch || chains.last().is_some_and(|c| c.0 != record) {
                epoch = e;
                chains.push((record, Vec::new()));
            }
            if let Some(c) = chains.last_mut() {
                c.1.push(row);
            }
        }
    }
    chains.retain(|c| !c.1.is_empty());
    let gaps = gaps + source.gaps();
    // The rotor parameters' columns, per row, in the chains' order.
    let (rotor_columns, gamma) = if sources.is_empty() {
        (Vec::new(), Vec::new())
    } else {
        est::rotor_calibration::columns(samples, settings, &sources.momenta)?
    };
    let n_rotor = sources.momenta.len();
    let mut next = 0;
    let chains: Vec<Vec<RowWithRotors>> = chains
        .into_iter()
        .map(|(record, c)| {
            c.into_iter()
                .map(|r| {
                    let ex = rotor_columns.get(next).map_or(&[][..], |v| &v[..]);
                    next += 1;
                    (r, ex, record)
                })
                .collect()
        })
        .collect();
    // Every record after the first has its own body torque: three columns past the rotor
    // parameters', record `r` at `record_torque + 3 (r − 1)`.
    let record_torque = ROTOR + n_rotor;
    // A row's coefficient of column `k` (a rotor parameter's or a later record's torque
    // past the rows' own; the body torque's own columns are the first record's).
    let coef = |(r, ex, record): &RowWithRotors, i: usize, k: usize| {
        if (TORQUE..TORQUE + 3).contains(&k) {
            if *record == 0 {
                r.a[(i, k)]
            } else {
                0.0
            }
        } else if k < ROTOR {
            r.a[(i, k)]
        } else if k < record_torque {
            ex[k - ROTOR][i]
        } else {
            let q = k - record_torque;
            if *record == 1 + q / 3 {
                r.a[(i, TORQUE + q % 3)]
            } else {
                0.0
            }
        }
    };
    // Householder QR of an m×n system (zero-padded to at least n rows): (R, Qᵀy, ‖y‖²).
    let factor = |a: DMatrix<f64>, y: DVector<f64>| {
        let (m, n) = a.shape();
        let rows = m.max(n);
        let a = a.resize_vertically(rows, 0.0);
        let y = y.resize_vertically(rows, 0.0);
        let energy = y.norm_squared();
        let qr = a.qr();
        let qty = qr.q().transpose() * &y;
        (qr.r(), qty.rows(0, n).into_owned(), energy)
    };
    // Only the columns the rows use: a zero column would leave its row of R holding
    // information about the others, which dropping that row would lose. The shared
    // columns (τ_b, κ) by the data as a whole (a constant ρ leaves κ's column zero), the
    // initial momenta chain by chain (a short Richardson chain may use only X₀).
    let uses = |r: &RowWithRotors, k: usize| (0..3).any(|i| coef(r, i, k) != 0.0);
    // The torque's columns first, every record's (held at zero by dropping them, below),
    // the rotor parameters', then the rest in order: the damping's last before j.
    let torque_columns = TORQUE..TORQUE + 3;
    // The records with rows, in order (a record may have none: too few samples).
    let mut present: Vec<usize> = chains.iter().flatten().map(|r| r.2).collect();
    present.dedup();
    let records = present.last().map_or(1, |r| r + 1);
    let shared_columns: Vec<usize> = torque_columns
        .clone()
        .chain(record_torque..record_torque + 3 * (records - 1))
        .filter(|&k| chains.iter().flatten().any(|r| uses(r, k)))
        .chain(ROTOR..ROTOR + n_rotor)
        .chain(
            (FIRST_SHARED..J)
                .filter(|k| !torque_columns.contains(k))
                .filter(|&k| chains.iter().flatten().any(|r| uses(r, k))),
        )
        .chain(J..J + 6)
        .collect();
    let rotor_at = shared_columns.iter().position(|&k| k == ROTOR);
    let shared = shared_columns.len();
    // A chain's rows (those given) free of its initial momenta, in the shared unknowns:
    // (rows of R, Qᵀy), and the chain's (rss, ‖y‖², scalar rows).
    let reduce_chain = |chain: &[&RowWithRotors]| {
        // The initial momenta the chain uses, then (with an inertial torque) each one's
        // torque, whose column is the initial momentum's times the block's `s`
        // ([`crate::estimator::momentum_rows`], "Inertial torque"), then the shared unknowns.
        let used: Vec<usize> = (0..settings.anchors_per_chain())
            .filter(|&k| chain.iter().any(|r| uses(r, k)))
            .collect();
        let trends = if settings.inertial_torque {
            used.len()
        } else {
            0
        };
        let anchors = used.len() + trends;
        let m = 3 * chain.len();
        let columns = anchors + shared;
        let a = DMatrix::from_fn(m, columns, |i, k| {
            let row = chain[i / 3];
            if k < used.len() {
                row.0.a[(i % 3, used[k])]
            } else if k < anchors {
                row.0.a[(i % 3, used[k - used.len()])] * row.0.trend_s
            } else {
                coef(row, i % 3, shared_columns[k - anchors])
            }
        });
        let y = DVector::from_fn(m, |i, _| chain[i / 3].0.b[i % 3]);
        let (r, qty, energy) = factor(a, y);
        let mut block = (Vec::new(), Vec::new());
        for i in anchors..columns {
            block.0.extend((anchors..columns).map(|k| r[(i, k)]));
            block.1.push(qty[i]);
        }
        let rss = (energy - qty.norm_squared()).max(0.0);
        (block, (rss, energy, m))
    };
    let mut blocks: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    let (mut rss, mut y_energy, mut rows) = (0.0, 0.0, 0);
    let noise_s: f64 = chains.iter().flatten().map(|r| r.0.noise_s).sum();
    let mut nuisance = settings.shared_nuisance() as f64;
    // The outside torques' unknowns, where the rows use them (as the recursive path).
    for block in [DIPOLE, CENTRE_OF_MASS] {
        if shared_columns
            .iter()
            .any(|k| (block..block + 3).contains(k))
        {
            nuisance += 3.0;
        }
    }
    // The later records' body torques.
    nuisance += shared_columns
        .iter()
        .filter(|&&k| k >= record_torque)
        .count() as f64;
    for chain in &chains {
        nuisance += settings.nuisance_per_chain() as f64;
        let (block, (r, e, m)) = reduce_chain(&chain.iter().collect::<Vec<_>>());
        (rss, y_energy, rows) = (rss + r, y_energy + e, rows + m);
        blocks.push(block);
    }
    // Where the damping's column is among the shared ones.
    let damping_at = shared_columns.iter().position(|&k| k == DAMPING);
    // The stacked shared rows of the chains' `blocks` that `keep` selects, without their
    // first `drop` columns (the torque's, held at zero), and the rotor parameters' prior
    // rows of weight `w` (none at 0): (R, z, rss) in j, and (all columns kept) the
    // damping's row of the factor `(r_dd, r_dj, z_d)`.
    let solve_with =
        |blocks: &[(Vec<f64>, Vec<f64>)], keep: &dyn Fn(usize) -> bool, drop: usize, w: f64| {
            let (mut a, mut y) = (Vec::new(), Vec::new());
            for (_, block) in blocks.iter().enumerate().filter(|(c, _)| keep(*c)) {
                for row in block.0.chunks(shared) {
                    a.extend_from_slice(&row[drop..]);
                }
                y.extend_from_slice(&block.1);
            }
            let n = shared - drop;
            if let Some(at) = rotor_at.filter(|_| w > 0.0) {
                for v in 0..n_rotor {
                    let mut row = vec![0.0; n];
                    row[at + v - drop] = w;
                    a.extend_from_slice(&row);
                    y.push(w * sources.prior_mean.get(v).copied().unwrap_or(0.0));
                }
            }
            // A column no kept row uses (a deleted record's torque) is pinned at zero by a
            // row of its own: left empty, its row of R would hold information about the
            // others that the reduction to j drops.
            let rows_kept = y.len();
            for k in 0..n {
                if (0..rows_kept).all(|i| a[i * n + k] == 0.0) {
                    let mut row = vec![0.0; n];
                    row[k] = 1.0;
                    a.extend_from_slice(&row);
                    y.push(0.0);
                }
            }
            let m = y.len();
            let (r, qty, energy) = factor(DMatrix::from_row_slice(m, n, &a), DVector::from_vec(y));
            let off = n - 6;
            let mut rr = nalgebra::Matrix6::from_fn(|i, k| r[(off + i, off + k)]);
            let mut z = Vector6::from_fn(|i, _| qty[off + i]);
            for i in 0..6 {
                if rr[(i, i)] < 0.0 {
                    for k in 0..6 {
                        rr[(i, k)] = -rr[(i, k)];
                    }
                    z[i] = -z[i];
                }
            }
            let rss = (energy - qty.norm_squared()).max(0.0);
            let damping = damping_at.filter(|&p| p >= drop).map(|p| {
                let p = p - drop;
                let r_dj = Vector6::from_fn(|i, _| r[(p, off + i)]);
                (r[(p, p)], r_dj, qty[p], r.clone())
            });
            let full = (drop == 0).then_some((r, qty));
            (rr, z, rss, damping, full)
        };
    // Every shared unknown's least-squares value (j unconstrained) from a full factor.
    let shared_solution = |(r, qty): &(DMatrix<f64>, DVector<f64>)| {
        let n = r.ncols();
        let r = r.rows(0, n).into_owned();
        r.solve_upper_triangular(&qty.rows(0, n).into_owned())
    };
    // The rotor parameters' values (whitened) from a full factor, then the overall scale
    // they imply, `Σ_v γ_v z_v` ([`crate::estimator::rotor_calibration`]).
    let rotor_values = |full: &Option<(DMatrix<f64>, DVector<f64>)>| {
        let x = shared_solution(full.as_ref()?)?;
        let at = rotor_at.filter(|_| n_rotor > 0)?;
        let z: Vec<f64> = (0..n_rotor).map(|v| x[at + v]).collect();
        let scale = z.iter().zip(&gamma).map(|(z, g)| z * g).sum::<f64>();
        Some(z.into_iter().chain([scale]).collect::<Vec<f64>>())
    };
    // The rotor parameters' prior weight `s`, the rows' residual σ: first with the
    // parameters held at their prior mean (a prior row of far more weight than any data row; with
    // them free, the rows fit a zero J and a zero rotor momentum exactly), then once more
    // at the parameters that prior weight gives.
    let prior_weight = if n_rotor > 0 {
        let dof = rows as f64 - 6.0 - nuisance;
        let scale = crate::math::sqrt(y_energy / rows.max(1) as f64);
        let sigma_at = |w: f64| {
            let (_, _, shared_rss, _, full) = solve_with(&blocks, &|_| true, 0, w);
            // The data rows' share of ρ²: less the prior rows' `w² |ẑ − μ|²`.
            let penalty = full.as_ref().and_then(|f| {
                let x = shared_solution(f)?;
                let at = rotor_at?;
                Some(
                    w * w
                        * (0..n_rotor)
                            .map(|v| {
                                let mu = sources.prior_mean.get(v).copied().unwrap_or(0.0);
                                (x[at + v] - mu).powi(2)
                            })
                            .sum::<f64>(),
                )
            })?;
            let s = crate::math::sqrt((rss + shared_rss - penalty) / dof);
            (s.is_finite() && s > 0.0).then_some(s)
        };
        // Without a residual to weigh the prior by (rows fitted exactly, too few of them)
        // no prior: the parameters then have no fit ([`SharedFactor::rotors_at`]).
        sigma_at(scale * 1e6).and_then(sigma_at).unwrap_or(0.0)
    } else {
        0.0
    };
    let solve_shared = |blocks: &[(Vec<f64>, Vec<f64>)], keep: &dyn Fn(usize) -> bool, drop| {
        solve_with(blocks, keep, drop, prior_weight)
    };
    let (rr, z, shared_rss, damping_factor, full) = solve_shared(&blocks, &|_| true, 0);
    let damping_of = |row: &Option<(f64, Vector6<f64>, f64, DMatrix<f64>)>, j: &InertiaVector| {
        row.as_ref()
            .map(|(r_dd, r_dj, z_d, _)| (z_d - r_dj.dot(j)) / r_dd)
    };
    // The torque's columns, when the rows use them: the same rows without them hold it
    // at zero ([`torque_tested`]), at the cost of the growth of ρ².
    let torque = if settings.torque_bias {
        shared_columns
            .iter()
            .filter(|&&k| torque_columns.contains(&k) || k >= record_torque)
            .count()
    } else {
        0
    };
    let without_torque = (torque > 0).then(|| {
        let (r, z, held_rss, held_damping, _) = solve_shared(&blocks, &|_| true, torque);
        // With several records' torques, `k > 3` unknowns: the growth on the scale of
        // the test's χ²₃, matched at its threshold ([`equivalent_chi2_scale`]).
        let growth = (held_rss - shared_rss).max(0.0) * equivalent_chi2_scale(torque);
        let qr = RecursiveQr {
            r,
            z,
            rss: rss + held_rss,
            y_energy,
            rows,
            weight: rows as f64,
            noise_s,
            nuisance: nuisance - torque as f64,
        };
        let twin = held_damping.and_then(|d| without_damping(&qr, &d));
        ((qr, growth), twin)
    });
    let (without_torque, held_twin) = without_torque.unzip();
    rss += shared_rss;
    // The jackknife's groups: the chains, or with fewer than MIN_GROUPS of them, time
    // blocks ([`crate::estimator::jackknife`], "Records of few chains"): each delete-one problem
    // the raw rows of every other block, each chain's initial momenta fitted again —
    // independent of the recursive path's innovations.
    let mut time_block_scale = 1.0;
    let estimates: Option<Vec<_>> = if chains.len() >= MIN_GROUPS {
        (0..chains.len().min(GROUPS))
            .map(|g| {
                let (r, z, _, d, f) = solve_shared(&blocks, &|c| c % GROUPS != g, 0);
                let j = crate::solver::unconstrained_minimiser(&r, &z)?;
                Some((j, damping_of(&d, &j), rotor_values(&f)))
            })
            .collect()
    } else {
        // The same blocks as the recursive path: the last chain's block in progress is
        // in every delete-one problem and σ is scaled to it, as there.
        let lengths: Vec<usize> = chains.iter().map(Vec::len).collect();
        let ids = est::jackknife::time_blocks(&lengths);
        let count = ids.iter().flatten().flatten().max().map_or(0, |m| m + 1);
        let pending = ids.iter().flatten().filter(|id| id.is_none()).count();
        let all = ids.iter().map(Vec::len).sum::<usize>();
        time_block_scale = crate::math::sqrt((all - pending) as f64 / all.max(1) as f64);
        (0..count)
            .map(|g| {
                let without: Vec<(Vec<f64>, Vec<f64>)> = chains
                    .iter()
                    .zip(&ids)
                    .map(|(chain, ids)| {
                        let kept: Vec<&RowWithRotors> = chain
                            .iter()
                            .zip(ids)
                            .filter(|(_, &id)| id != Some(g))
                            .map(|(r, _)| r)
                            .collect();
                        reduce_chain(&kept).0
                    })
                    .collect();
                let (r, z, _, d, f) = solve_shared(&without, &|_| true, 0);
                let j = crate::solver::unconstrained_minimiser(&r, &z)?;
                Some((j, damping_of(&d, &j), rotor_values(&f)))
            })
            .collect()
    };
    let estimates: Option<Vec<Deleted>> = estimates;
    // With at least MIN_GROUPS records, the records are groups too: what differs from one
    // pass or throw to the next is then in σ. Their few groups make a noisy σ (with four
    // records, three degrees of freedom), so the larger of the two is kept, element by
    // element (on 100 sets of four 60 s slews: chains alone 2 of 100 determined beyond
    // 3σ, records alone 3, `examples/records.rs`).
    // Each chain's group: its record's place among the records with rows.
    let group_of_chain: Vec<usize> = chains
        .iter()
        .map(|c| {
            let r = c.first().map_or(0, |r| r.2);
            present.iter().position(|&p| p == r).unwrap_or(0)
        })
        .collect();
    let by_record: Option<Vec<Deleted>> = (present.len() >= MIN_GROUPS)
        .then(|| {
            (0..present.len().min(GROUPS))
                .map(|g| {
                    let keep = |c: usize| group_of_chain[c] % GROUPS != g;
                    let (r, z, _, d, f) = solve_shared(&blocks, &keep, 0);
                    let j = crate::solver::unconstrained_minimiser(&r, &z)?;
                    Some((j, damping_of(&d, &j), rotor_values(&f)))
                })
                .collect()
        })
        .flatten();
    let larger = |a: Option<[f64; 6]>, b: Option<[f64; 6]>| match (a, b) {
        (Some(a), Some(b)) => Some(core::array::from_fn(|k| a[k].max(b[k]))),
        (a, b) => a.or(b),
    };
    // The delete-one answers' D, as one more element of the jackknife.
    let damping_sigma = |e: &[Deleted], scale: f64| {
        let d: Option<Vec<InertiaVector>> = e
            .iter()
            .map(|(_, d, _)| d.map(InertiaVector::from_element))
            .collect();
        jackknife_sigma(&d?).map(|s| s.map(|v| v * scale))
    };
    let damping_jackknife = larger(
        estimates
            .as_deref()
            .and_then(|e| damping_sigma(e, time_block_scale)),
        by_record.as_deref().and_then(|e| damping_sigma(e, 1.0)),
    )
    .map(|s| s[0]);
    // The delete-one answers' rotor parameters and their overall scale, as more elements
    // of the jackknife: their σ is then no smaller than the spread the chains' correlated
    // errors give them.
    let rotor_sigma = |e: &[Deleted], scale: f64| {
        let v: Vec<&[f64]> = e
            .iter()
            .map(|(_, _, v)| v.as_deref())
            .collect::<Option<_>>()?;
        let mut out = vec![0.0; v.first()?.len()];
        if v.iter().any(|x| x.len() != out.len()) {
            return None;
        }
        est::jackknife::jackknife_sigma_by(v.len(), |g, k| v[g][k], &mut out)
            .then(|| out.iter().map(|x| x * scale).collect::<Vec<f64>>())
    };
    let rotor_jackknife: Option<Vec<f64>> = match (
        estimates
            .as_deref()
            .and_then(|e| rotor_sigma(e, time_block_scale)),
        by_record.as_deref().and_then(|e| rotor_sigma(e, 1.0)),
    ) {
        (Some(a), Some(b)) => Some(a.iter().zip(&b).map(|(x, y)| x.max(*y)).collect()),
        (a, b) => a.or(b),
    };
    let j_sigma = |e: &[Deleted], scale: f64| {
        let j: Vec<InertiaVector> = e.iter().map(|(j, _, _)| *j).collect();
        jackknife_sigma(&j).map(|s| s.map(|v| v * scale))
    };
    let jackknife_sigma_kg_m2 = larger(
        estimates
            .as_deref()
            .and_then(|e| j_sigma(e, time_block_scale)),
        by_record.as_deref().and_then(|e| j_sigma(e, 1.0)),
    );
    let qr = RecursiveQr {
        r: rr,
        z,
        rss,
        y_energy,
        rows,
        weight: rows as f64,
        noise_s,
        nuisance,
    };
    let without_damping = damping_factor
        .as_ref()
        .and_then(|d| without_damping(&qr, d))
        .map(|torque_free| WithoutDamping {
            torque_free,
            torque_held: held_twin.flatten(),
        });
    Ok(BatchReduction {
        qr,
        gaps,
        jackknife_sigma_kg_m2,
        without_torque,
        without_damping,
        shared: full
            .filter(|_| {
                n_rotor > 0
                    || shared_columns
                        .iter()
                        .any(|&k| (DIPOLE..CENTRE_OF_MASS + 3).contains(&k))
            })
            .map(|(r, qty)| SharedFactor {
                r,
                qty,
                columns: shared_columns.clone(),
                s2: est::qr::residual_variance(rss, rows as f64 - 6.0 - nuisance),
                prior_weight,
                gamma: gamma.clone(),
                rotor_jackknife: rotor_jackknife.clone(),
            }),
        damping: damping_factor
            .zip(damping_at)
            .map(|((r_dd, r_dj, z_d, r), p)| {
                let s2 = est::qr::residual_variance(rss, rows as f64 - 6.0 - nuisance);
                // e_pᵀ (RᵀR)⁻¹ e_p = ‖R⁻ᵀ e_p‖².
                let mut e = DVector::zeros(shared);
                e[p] = 1.0;
                let ls = r
                    .transpose()
                    .solve_lower_triangular(&e)
                    .filter(|_| s2.is_finite() && r_dd != 0.0)
                    .map(|u| crate::math::sqrt(s2 * u.norm_squared()));
                let sigma_nms = match (ls, damping_jackknife) {
                    (Some(l), Some(k)) => Some(l.max(k)),
                    (l, k) => l.or(k),
                };
                DampingRow {
                    r_dd,
                    r_dj,
                    z_d,
                    sigma_nms,
                }
            }),
    })
}
