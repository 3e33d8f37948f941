//! The design: A-optimal time shares over a library of feasible rest-to-rest manoeuvres,
//! then a schedule of whole manoeuvres that follows the shares.
//!
//! # Library
//!
//! The unit is a *doublet* about a body direction `u`: the rate `ω = a(t) u` rises at the
//! largest acceleration `α` to the largest rate `a` the limits allow along `u`
//! (`Limits::along`) or that the doublet's length leaves time for,
//! coasts, returns to rest, does the same at `−a`, and ends at rest with the wheels at
//! zero momentum and the attitude back near its start.
//!
//! A manoeuvre of the library is a *tour*: doublets about every direction of one set
//! that spans J (the three axes; the four body diagonals; the six face diagonals), back
//! to back, each of one length (4 to 24 s). A tour, not a doublet, is the unit because
//! the estimator's σ is a jackknife over its momentum chains (30 s by default): every
//! chain must determine J on its own, and a doublet about one direction determines only
//! the column `J u`.
//!
//! A torque-limited spacecraft gains from rates built up over longer doublets, and from
//! working every wheel at once: the library also holds *three-phase trains*, a doublet of
//! period `T` (8 to 120 s) on each body axis at once, the y axis `T/3` and the z axis
//! `2T/3` behind x, repeated over about 30 s, with a triangular rate (full torque
//! throughout) or a quick ramp and coasts; each is scaled as a whole to the margin of its
//! tightest limit (`Limits::scale_to_fit`), so that the rate direction
//! sweeps the body while every wheel works.
//!
//! Only tours that fit in one estimator chain are offered, where any does. A train's
//! rate direction always spans the body, and at the high rates of its longer periods the
//! attitude turns far within each chain, so every chain of a train determines J.
//!
//! # Time shares (convex)
//!
//! With `m_u` the information per second of tour `u` (its rows only, flown alone, the
//! initial momentum of each estimator chain minimised out, `predict`), time shares `w` on the simplex give the
//! information `M(w) = T Σ_u w_u m_u` after `T` seconds. The target is the relative
//! Frobenius σ, `σ_F² = tr(F M⁻¹)` with `F = diag(1,1,1,2,2,2)/‖J‖_F²`, so the shares
//! minimise `Φ(w) = tr(F (Σ w_u m_u)⁻¹)`: A-optimal (weighted) design, convex in `w`.
//! The multiplicative algorithm `w_u ← w_u √d_u / Σ_v w_v √d_v`,
//! `d_u = tr(F M⁻¹ m_u M⁻¹)`, decreases `Φ`; since `Φ` is convex and `Σ w_u d_u = Φ`,
//! every `w` satisfies `Φ(w) − Φ* ≤ max_u d_u − Φ(w)` (Kiefer–Wolfowitz), which
//! [`Design::gap`] reports relative to `Φ(w)`.
//!
//! # What is guaranteed
//!
//! The shares are optimal to within [`Design::gap`] over the convex hull of the library,
//! for the time-averaged information of the white-noise row model; the prior's J sets
//! the trajectories. Not guaranteed: optimality over manoeuvres outside the library, the
//! ordering (whole tours are sequenced to follow the shares, largest deficit first),
//! the end effects of chains that straddle two tours, and the noise model itself
//! (`predict`, "What it omits").

use crate::plan::limits::{Limits, LimitsError};
use crate::plan::predict::{information, EstimatorModel, NoiseModel};
use crate::plan::profile::CommandProfile;
use nalgebra::{Matrix3, SMatrix, Vector3};
use std::vec::Vec;

/// One manoeuvre of the library: a tour of doublets.
#[derive(Debug, Clone, PartialEq)]
pub struct Atom {
    /// The direction set's name (`axes`, `body-diagonals`, `face-diagonals`).
    pub set: &'static str,
    /// Length of each doublet, s.
    pub doublet_s: f64,
    /// Rotation directions, body axes, unit.
    pub(crate) directions: Vec<Vector3<f64>>,
    /// Peak rate of each doublet, rad/s.
    pub(crate) peak_rate_rad_s: Vec<f64>,
    /// The commands (from t = 0).
    pub(crate) commands: Vec<Vector3<f64>>,
}

/// The doublet lengths of the library, s (rounded to whole multiples of four controller
/// periods).
pub(crate) const DOUBLET_S: [f64; 6] = [4.0, 6.0, 8.0, 12.0, 16.0, 24.0];

/// The library's time shares.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// The library.
    pub atoms: Vec<Atom>,
    /// Time share of each (sums to 1).
    pub weights: Vec<f64>,
    /// Relative optimality gap bound `(max_u d_u − Φ)/Φ` (module docs).
    pub gap: f64,
    /// `σ_F √T` of the shares: the relative Frobenius σ after `T` s is this over `√T`.
    pub(crate) sigma_root_s: f64,
    /// Information per second of each doublet.
    per_s: Vec<SMatrix<f64, 6, 6>>,
    /// `F` of the objective.
    f: SMatrix<f64, 6, 6>,
}

impl Design {
    /// `Φ(w) = tr(F (Σ w_u m_u)⁻¹)` for any shares `w` (∞ where singular).
    #[must_use]
    #[cfg(test)]
    pub(crate) fn objective(&self, w: &[f64]) -> f64 {
        let m: SMatrix<f64, 6, 6> = self.per_s.iter().zip(w).map(|(m, w)| m * *w).sum();
        m.cholesky()
            .map_or(f64::INFINITY, |c| (self.f * c.inverse()).trace())
    }
}

/// The three direction sets.
#[must_use]
pub(crate) fn direction_sets() -> [(&'static str, Vec<Vector3<f64>>); 3] {
    let axes = std::vec![Vector3::x(), Vector3::y(), Vector3::z()];
    let mut face = Vec::new();
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        for s in [1.0, -1.0] {
            let mut v = Vector3::zeros();
            v[a] = 1.0;
            v[b] = s;
            face.push(v.normalize());
        }
    }
    let body = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
        .iter()
        .map(|(sy, sz)| Vector3::new(1.0, *sy, *sz).normalize())
        .collect();
    [
        ("axes", axes),
        ("body-diagonals", body),
        ("face-diagonals", face),
    ]
}

/// Every direction of the sets.
#[must_use]
#[cfg(test)]
pub(crate) fn directions() -> Vec<Vector3<f64>> {
    direction_sets().into_iter().flat_map(|(_, d)| d).collect()
}

/// The doublet about `u` (module docs) at controller period `period_s`, lasting
/// `doublet_s` rounded to whole multiples of four periods: its peak rate and commands.
pub(crate) fn doublet(
    u: &Vector3<f64>,
    limits: &Limits,
    j: &Matrix3<f64>,
    period_s: f64,
    doublet_s: f64,
) -> Result<(f64, Vec<Vector3<f64>>), LimitsError> {
    let (a_max, alpha) = limits.along(u, j)?;
    let quarter = ((doublet_s / (4.0 * period_s)).round() as usize).max(1);
    let n1 = ((a_max / (alpha * period_s)).ceil() as usize).clamp(1, quarter);
    let a = a_max.min(alpha * period_s * n1 as f64);
    let accel = a / (n1 as f64 * period_s);
    let nc = quarter - n1;
    // ρ̇ = −J u ȧ: rate up, coast, down to rest, down to −a, coast, back to rest.
    let up = -(j * u) * accel;
    let mut c = Vec::with_capacity(4 * quarter);
    for (cmd, n) in [
        (up, n1),
        (Vector3::zeros(), 2 * nc),
        (-up, 2 * n1),
        (Vector3::zeros(), 2 * nc),
        (up, n1),
    ] {
        c.extend(core::iter::repeat_n(cmd, n));
    }
    Ok((a, c))
}

/// A three-phase train (module docs): period `period_T_s`, `ramp` of each quarter spent
/// accelerating (1: a triangle), about `train_s` long, scaled to the limits.
fn three_phase(
    limits: &Limits,
    j: &Matrix3<f64>,
    period_s: f64,
    doublet_s: f64,
    ramp: f64,
    train_s: f64,
) -> Result<Atom, LimitsError> {
    let quarter = ((doublet_s / (4.0 * period_s)).round() as usize).max(1);
    let n1 = ((quarter as f64 * ramp).round() as usize).clamp(1, quarter);
    let nc = quarter - n1;
    // One doublet's rate acceleration, unit amplitude.
    let mut one = Vec::with_capacity(4 * quarter);
    for (x, n) in [
        (1.0, n1),
        (0.0, 2 * nc),
        (-1.0, 2 * n1),
        (0.0, 2 * nc),
        (1.0, n1),
    ] {
        one.extend(core::iter::repeat_n(x, n));
    }
    let len = one.len();
    let reps = ((train_s / (len as f64 * period_s)).round() as usize).max(1);
    let lag = len / 3;
    let total = reps * len + 2 * lag;
    let accel: Vec<Vector3<f64>> = (0..total)
        .map(|k| {
            Vector3::from_fn(|i, _| {
                let t = k as isize - (i * lag) as isize;
                if t >= 0 && (t as usize) < reps * len {
                    one[t as usize % len]
                } else {
                    0.0
                }
            })
        })
        .collect();
    let shape = CommandProfile::new(0.0, period_s, accel.iter().map(|a| -(j * a)).collect());
    let scale = limits.scale_to_fit(&shape, j)?;
    let peak_a = scale * n1 as f64 * period_s;
    Ok(Atom {
        set: if n1 == quarter {
            "three-phase triangle"
        } else {
            "three-phase ramp"
        },
        doublet_s: len as f64 * period_s,
        directions: std::vec![Vector3::x(), Vector3::y(), Vector3::z()],
        peak_rate_rad_s: std::vec![peak_a; 3],
        commands: shape.scaled(scale).torque_nm,
    })
}

/// The library: a tour per direction set and doublet length, and the three-phase trains.
pub(crate) fn library(
    limits: &Limits,
    j: &Matrix3<f64>,
    period_s: f64,
) -> Result<Vec<Atom>, LimitsError> {
    let mut out = Vec::new();
    for (set, dirs) in direction_sets() {
        for d in DOUBLET_S {
            let mut commands = Vec::new();
            let mut peak = Vec::new();
            for u in &dirs {
                let (a, c) = doublet(u, limits, j, period_s, d)?;
                peak.push(a);
                commands.extend(c);
            }
            let doublet_s = commands.len() as f64 * period_s / dirs.len() as f64;
            if out
                .iter()
                .any(|a: &Atom| a.set == set && a.doublet_s == doublet_s)
            {
                continue;
            }
            out.push(Atom {
                set,
                doublet_s,
                directions: dirs.clone(),
                peak_rate_rad_s: peak,
                commands,
            });
        }
    }
    for t in THREE_PHASE_S {
        for ramp in [1.0, 0.25] {
            let a = three_phase(limits, j, period_s, t, ramp, 30.0)?;
            if !out
                .iter()
                .any(|b| b.set == a.set && b.doublet_s == a.doublet_s)
            {
                out.push(a);
            }
        }
    }
    Ok(out)
}

/// The three-phase trains' periods, s.
pub(crate) const THREE_PHASE_S: [f64; 6] = [8.0, 12.0, 16.0, 20.0, 24.0, 30.0];

/// The library with its chain rule (module docs): tours that fit in one chain (where any
/// does) and the three-phase trains.
pub(crate) fn library_for(
    limits: &Limits,
    j: &Matrix3<f64>,
    period_s: f64,
    chain_s: Option<f64>,
) -> Result<Vec<Atom>, LimitsError> {
    let mut atoms = library(limits, j, period_s)?;
    if let Some(c) = chain_s {
        let fits = |a: &Atom| {
            a.set.starts_with("three-phase") || a.commands.len() as f64 * period_s <= c + 1e-9
        };
        if atoms.iter().any(fits) {
            atoms.retain(fits);
        }
    }
    Ok(atoms)
}

/// The two three-phase trains (triangle and quick ramp) of one doublet per axis that fill
/// `horizon_s` exactly (period `0.6 horizon`, the lags `0.4 horizon`): the longest build-up
/// of rate a rest-to-rest flight of that length allows. (Trains longer than the horizon,
/// which build rate up beyond it and return to rest after, were tried: the time-share
/// relaxation assumes every manoeuvre is flown within the horizon, and with them the
/// planned time to target grew.)
pub(crate) fn trains_for(
    limits: &Limits,
    j: &Matrix3<f64>,
    period_s: f64,
    horizon_s: f64,
) -> Result<Vec<Atom>, LimitsError> {
    let t = 0.6 * horizon_s;
    if t < 4.0 * period_s {
        return Ok(Vec::new());
    }
    [1.0, 0.25]
        .iter()
        .map(|r| three_phase(limits, j, period_s, t, *r, t))
        .collect()
}

/// The A-optimal shares over the library with its chain rule (module docs).
#[cfg(test)]
fn design(
    limits: &Limits,
    j: &Matrix3<f64>,
    noise: &NoiseModel,
    period_s: f64,
    chain_s: Option<f64>,
) -> Result<Design, LimitsError> {
    let atoms = library_for(limits, j, period_s, chain_s)?;
    Ok(design_over(atoms, j, noise, period_s, chain_s, None))
}

/// The A-optimal shares over `atoms` (module docs); with a horizon, a manoeuvre longer
/// than it counts with the information of its first `horizon_s` seconds only (what it
/// gives by then).
#[must_use]
pub(crate) fn design_over(
    atoms: Vec<Atom>,
    j: &Matrix3<f64>,
    noise: &NoiseModel,
    period_s: f64,
    chain_s: Option<f64>,
    horizon_s: Option<f64>,
) -> Design {
    // Each tour alone, the estimator's chains, no torque unknown: information per second.
    let model = EstimatorModel {
        chain_s,
        torque_bias: false,
        ..EstimatorModel::default()
    };
    let per_s: Vec<SMatrix<f64, 6, 6>> = atoms
        .iter()
        .map(|a| {
            let p = CommandProfile::new(0.0, period_s, a.commands.clone());
            let d = horizon_s.map_or(p.duration_s(), |h| p.duration_s().min(h));
            information(&p, j, noise, &model, d) / d
        })
        .collect();
    let jn2 = j.norm_squared();
    let f =
        SMatrix::<f64, 6, 6>::from_diagonal(&nalgebra::Vector6::new(1.0, 1.0, 1.0, 2.0, 2.0, 2.0))
            / jn2;
    let n = atoms.len();
    let mut w = std::vec![1.0 / n as f64; n];
    let mut gap = f64::INFINITY;
    let mut phi = f64::INFINITY;
    for _ in 0..5000 {
        let m: SMatrix<f64, 6, 6> = per_s.iter().zip(&w).map(|(m, w)| m * *w).sum();
        let Some(inv) = m.cholesky().map(|c| c.inverse()) else {
            break;
        };
        let g = inv * f * inv;
        phi = (f * inv).trace();
        let d: Vec<f64> = per_s.iter().map(|m| (g * m).trace().max(0.0)).collect();
        let dmax = d.iter().copied().fold(0.0, f64::max);
        gap = (dmax - phi) / phi;
        if gap < 1e-4 {
            break;
        }
        let z: f64 = w.iter().zip(&d).map(|(w, d)| w * d.sqrt()).sum();
        for (wi, di) in w.iter_mut().zip(&d) {
            *wi *= di.sqrt() / z;
        }
    }
    Design {
        atoms,
        weights: w,
        gap,
        sigma_root_s: phi.sqrt(),
        per_s,
        f,
    }
}

/// Whole manoeuvres in the order that follows the shares (largest deficit first), as
/// many as fit in `horizon_s`; returns the commands and, per manoeuvre flown, its index
/// and end time.
#[must_use]
pub(crate) fn schedule(
    d: &Design,
    period_s: f64,
    horizon_s: f64,
) -> (CommandProfile, Vec<(usize, f64)>) {
    let mut spent = std::vec![0.0; d.atoms.len()];
    let mut t = 0.0;
    let mut cmds = Vec::new();
    let mut order = Vec::new();
    let dur = |i: usize| d.atoms[i].commands.len() as f64 * period_s;
    // The manoeuvre furthest behind its share, among those that still fit.
    while let Some((i, _)) = d
        .weights
        .iter()
        .enumerate()
        .filter(|(i, w)| **w > 1e-3 && t + dur(*i) <= horizon_s + 1e-9)
        .map(|(i, w)| (i, w * (t + dur(i)) - spent[i]))
        .max_by(|a, b| a.1.total_cmp(&b.1))
    {
        let dur = dur(i);
        cmds.extend_from_slice(&d.atoms[i].commands);
        spent[i] += dur;
        t += dur;
        order.push((i, t));
    }
    (CommandProfile::new(0.0, period_s, cmds), order)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::limits::Wheel;

    fn limits() -> Limits {
        Limits {
            wheels: (0..3)
                .map(|i| Wheel {
                    name: std::format!("rw{i}"),
                    axis: Vector3::ith(i, 1.0),
                    max_torque_nm: 0.01,
                    max_momentum_nms: 0.046,
                })
                .collect(),
            max_rate_rad_s: Some(0.1),
            max_angle_rad: None,
            margin: 0.9,
        }
    }

    /// Each doublet and tour ends at rest with zero wheel momentum and keeps every limit.
    #[test]
    fn tours_are_rest_to_rest_and_feasible() {
        let j = Matrix3::new(0.26, 0.01, -0.005, 0.01, 0.26, 0.002, -0.005, 0.002, 0.16);
        let lim = limits();
        for u in directions() {
            let (_, c) = doublet(&u, &lim, &j, 1.0, 30.0).unwrap();
            let p = CommandProfile::new(0.0, 1.0, c);
            let use_ = lim.use_of(&p, &j).unwrap();
            assert!(use_.worst() > 0.5, "{u}: {use_:?}");
        }
        for a in library(&lim, &j, 1.0).unwrap() {
            let p = CommandProfile::new(0.0, 1.0, a.commands.clone());
            let end = *p.momentum_at_ticks().last().unwrap();
            assert!(end.norm() < 1e-15, "{}: {end}", a.set);
            let use_ = lim.use_of(&p, &j).unwrap();
            assert!(use_.worst() <= 0.9 + 1e-12, "{}: {use_:?}", a.set);
        }
    }

    /// The shares are a distribution with a small gap, and neither uniform shares nor any
    /// one tour alone does better.
    #[test]
    fn shares_are_optimal_over_the_library() {
        let j = Matrix3::new(0.26, 0.01, -0.005, 0.01, 0.26, 0.002, -0.005, 0.002, 0.16);
        let noise = NoiseModel {
            gyro_rad_s_rthz: 1e-4,
            wheel_nms: 0.0,
            telemetry_period_s: 0.1,
        };
        let d = design(&limits(), &j, &noise, 1.0, Some(30.0)).unwrap();
        assert!((d.weights.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        assert!(d.gap < 1e-3, "{}", d.gap);
        let phi = d.objective(&d.weights);
        let n = d.weights.len();
        assert!(phi <= d.objective(&std::vec![1.0 / n as f64; n]));
        for k in 0..n {
            let mut one = std::vec![0.0; n];
            one[k] = 1.0;
            assert!(phi <= d.objective(&one) * (1.0 + d.gap), "{k}");
        }
        let (p, order) = schedule(&d, 1.0, 300.0);
        let longest = d.atoms.iter().map(|a| a.commands.len()).max().unwrap() as f64;
        assert!(p.duration_s() <= 300.0 && p.duration_s() > 300.0 - longest);
        assert_eq!(order.last().unwrap().1, p.duration_s());
    }
}
