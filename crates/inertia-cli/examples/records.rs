//! Monte Carlo of several records estimated together (`inertia estimate --batch a.csv
//! b.csv …`, `Run::next_record`; book, "Several records").
//!
//! ```sh
//! cargo run --release -p inertia-cli --example records -- 20   # sets of records per cell
//! cargo run --release -p inertia-cli --example records -- 100 slews   # one kind of data
//! WHEEL_DELAY=estimate cargo run --release -p inertia-cli --example records -- 20
//! ```
//!
//! `WHEEL_DELAY`: the wheel speeds' time tag (`off`, seconds or `estimate`), off when unset;
//! `INERTIAL`: the inertial torque (`off`, `on`, `auto`, `short`), the default when unset.
//!
//! **Data.** Each set is `n` records of one spacecraft, each record with its own seed,
//! initial state and disturbances:
//!
//! * **throws:** the lab throw (`Preset::throw`: 0.5 s at 4 kHz, MEMS gyro, the attitude
//!   integrated from it, the flywheel's speed quantised and held, vibration, air drag and
//!   an aerodynamic torque fixed in space), each throw tumbling its own way
//!   (`Preset::with_drawn_tumble`: the initial rate turned about a drawn axis, the
//!   aerodynamic torque along a drawn direction);
//! * **slews:** the paper's slew (`Common::physical()`) cut to 60 s, each record with its
//!   own momentum bias (0–0.15 N m s) and its own constant body torque (1e-6 N m along a
//!   drawn direction).
//!
//! **Columns.** The records estimated alone that gave J with σ (the others were
//! refused or gave no σ); median relative Frobenius error of each record estimated alone
//! (batch, the default settings) and of the set estimated together; their ratio; the median
//! ratio of the σ of J's diagonal (together over alone); "3σ cov.": the runs with every
//! element within ±3σ; "determined beyond 3σ": runs called determined with an element
//! beyond 3σ, alone (of all records) and together.

use inertia::estimator::observability::Observability;
use inertia::estimator::Estimate;
use inertia::pipeline::{InertialTorque, PipelineSettings, Run};
use inertia::sample::Sample;
use inertia::sim::presets::Preset;
use inertia::sim::scenario::{Common, Scenario, SlewPlan};
use inertia::tensor::{j_from_matrix, relative_frobenius_error};
use nalgebra::{Matrix3, Unit, Vector3};
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

/// The batch answer over `records` (a record boundary between each two).
fn pooled(records: &[Vec<Sample>]) -> Option<Estimate> {
    let config = PipelineSettings {
        wheel_delay: wheel_delay_from_env(),
        inertial_torque: std::env::var("INERTIAL").map_or(Default::default(), |v| {
            v.parse::<InertialTorque>()
                .unwrap_or_else(|e| panic!("INERTIAL: {e}"))
        }),
        ..PipelineSettings::default()
    }
    .validate()
    .ok()?;
    let mut run = Run::new(config, true).ok()?;
    for (k, r) in records.iter().enumerate() {
        if k > 0 {
            run.next_record().ok()?;
        }
        for s in r {
            run.push(s, |_| {}).ok()?;
        }
    }
    let mut last = None;
    run.finish(|e| last = Some(*e)).ok()?;
    last
}

/// The wheel speeds' time tag from `WHEEL_DELAY` (`off`, seconds or `estimate`), off when
/// unset; a value it cannot read stops the run.
fn wheel_delay_from_env() -> inertia::estimator::wheel_delay::WheelDelay {
    std::env::var("WHEEL_DELAY").map_or(Default::default(), |v| {
        inertia::pipeline::parse_wheel_delay(&v).unwrap_or_else(|e| panic!("WHEEL_DELAY: {e}"))
    })
}

/// A unit vector drawn uniformly.
fn direction(rng: &mut impl Rng) -> Unit<Vector3<f64>> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if (0.1..1.0).contains(&v.norm()) {
            return Unit::new_normalize(v);
        }
    }
}

/// Record `k` of set `set` in `cell`: samples (times from 0) and the true J.
fn record(cell: &str, set: u64, k: usize) -> (Vec<Sample>, Matrix3<f64>) {
    let seed = 1000 * set + k as u64;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let out = match cell {
        "throws" => {
            let mut p = Preset::throw().with_drawn_tumble(seed);
            p.common.seed = seed;
            p.simulate()
        }
        _ => {
            let mut common = Common {
                duration_s: Some(60.0),
                seed,
                ..Common::physical()
            };
            common.realism.environment.constant_torque_nm = direction(&mut rng).into_inner() * 1e-6;
            Scenario::Slew(SlewPlan {
                momentum_bias_nms: direction(&mut rng).into_inner() * rng.random_range(0.0..0.15),
                ..SlewPlan::default()
            })
            .simulate(&common)
        }
    }
    .expect("simulation");
    (out.samples, out.inertia_kg_m2)
}

/// Error, all within 3σ, determined beyond 3σ, σ of the diagonal.
type Judged = (f64, bool, bool, [f64; 3]);

/// [`Judged`] of `e` against `truth`.
fn judge(e: &Estimate, truth: &Matrix3<f64>) -> Option<Judged> {
    let (j, s) = (e.j()?, e.uncertainty?.sigma_kg_m2);
    let t = j_from_matrix(truth);
    let within = (0..6).all(|k| (j[k] - t[k]).abs() <= 3.0 * s[k]);
    let determined = matches!(e.observability, Observability::Determined { .. });
    Some((
        relative_frobenius_error(&e.inertia()?, truth),
        within,
        determined && !within,
        [s[0], s[1], s[2]],
    ))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

fn main() {
    let sets: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(20);
    println!("| data | records | answered alone | alone | together | together / alone | σ together / alone | 3σ cov. alone | 3σ cov. together | det. beyond 3σ alone | det. beyond 3σ together |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let filter = std::env::args().nth(2);
    for (cell, n) in [("throws", 5), ("throws", 10), ("slews", 4), ("slews", 8)] {
        if filter.as_deref().is_some_and(|f| f != cell) {
            continue;
        }
        let runs: Vec<_> = (0..sets)
            .into_par_iter()
            .map(|set| {
                let recs: Vec<(Vec<Sample>, Matrix3<f64>)> =
                    (0..n).map(|k| record(cell, set, k)).collect();
                let truth = recs[0].1;
                let alone: Vec<_> = recs
                    .iter()
                    .map(|r| pooled(core::slice::from_ref(&r.0)).and_then(|e| judge(&e, &truth)))
                    .collect();
                let samples: Vec<Vec<Sample>> = recs.into_iter().map(|r| r.0).collect();
                let together = pooled(&samples).and_then(|e| judge(&e, &truth));
                (alone, together)
            })
            .collect();
        let alone: Vec<_> = runs.iter().flat_map(|r| r.0.iter().flatten()).collect();
        let together: Vec<_> = runs.iter().filter_map(|r| r.1.as_ref()).collect();
        let share = |v: &[&Judged], f: fn(&Judged) -> bool| {
            format!("{}/{}", v.iter().filter(|x| f(x)).count(), v.len())
        };
        let sigma_ratio = median(
            runs.iter()
                .filter_map(|(a, t)| {
                    let t = t.as_ref()?;
                    let a: Vec<f64> = a
                        .iter()
                        .flatten()
                        .map(|x| x.3[0] + x.3[1] + x.3[2])
                        .collect();
                    Some((t.3[0] + t.3[1] + t.3[2]) / median(a))
                })
                .collect(),
        );
        let (ea, et) = (
            median(alone.iter().map(|x| x.0).collect()),
            median(together.iter().map(|x| x.0).collect()),
        );
        println!(
            "| {cell} | {n} | {}/{} | {ea:.2e} | {et:.2e} | {:.2} | {sigma_ratio:.2} | {} | {} | {} | {} |",
            alone.len(),
            sets as usize * n,
            et / ea,
            share(&alone, |x| x.1),
            share(&together, |x| x.1),
            share(&alone, |x| x.2),
            share(&together, |x| x.2),
        );
    }
}
