//! Monte Carlo of the lab throw with every effect, each throw tumbling its own way
//! (`Preset::throw().with_drawn_tumble(seed)`), through the default estimator streaming
//! and batch (a solve every 50 samples): how many answers, how many determined, and of
//! those how many have an element beyond 3σ.
//!
//! `cargo run --release -p inertia-cli --example throw_sigma -- [THROWS]` (default 60,
//! seeds from `FROM`, default 0; `WHEEL_DELAY=off|SECONDS|estimate` the wheel speeds'
//! time tag, off when unset; `WITHOUT=vibration,speed,inertial,drag` lab effects left
//! out; `INERTIAL=off|on|auto|short` the inertial torque, the default when unset;
//! `DAMPING=1` the damping `D` estimated (`--damping`); `DETAIL=1`
//! each determined answer beyond 3σ on stderr: seed, worst element and the parts of its
//! σ). Results: the book, "What you tell the run: the wheel speeds' time tag" and "A
//! torque fixed in the inertial frame".

use inertia::estimator::observability::Observability;
use inertia::estimator::Estimate;
use inertia::pipeline::{InertialTorque, PipelineSettings, Run};
use inertia::sample::Sample;
use inertia::sim::presets::{LabEffect, Preset};
use inertia::tensor::j_from_matrix;
use nalgebra::Matrix3;
use rayon::prelude::*;

fn estimate(samples: &[Sample], batch: bool) -> Option<Estimate> {
    let wheel_delay = std::env::var("WHEEL_DELAY").map_or(Default::default(), |v| {
        inertia::pipeline::parse_wheel_delay(&v).unwrap_or_else(|e| panic!("WHEEL_DELAY: {e}"))
    });
    let config = PipelineSettings {
        solve_every: 50,
        wheel_delay,
        damping: std::env::var("DAMPING").is_ok_and(|v| v == "1"),
        inertial_torque: std::env::var("INERTIAL").map_or(Default::default(), |v| {
            v.parse::<InertialTorque>()
                .unwrap_or_else(|e| panic!("INERTIAL: {e}"))
        }),
        ..PipelineSettings::default()
    }
    .validate()
    .ok()?;
    let mut run = Run::new(config, batch).ok()?;
    let mut last = None;
    for s in samples {
        run.push(s, |e| last = Some(*e)).ok()?;
    }
    run.finish(|e| last = Some(*e)).ok()?;
    last
}

/// Answered with σ, determined, determined beyond 3σ.
fn judge(e: Option<Estimate>, truth: &Matrix3<f64>) -> (bool, bool, bool) {
    let Some((e, j, s)) = e.and_then(|e| Some((e, e.j()?, e.uncertainty?.sigma_kg_m2))) else {
        return (false, false, false);
    };
    let t = j_from_matrix(truth);
    let determined = matches!(e.observability, Observability::Determined { .. });
    let beyond = (0..6).any(|k| (j[k] - t[k]).abs() > 3.0 * s[k]);
    if std::env::var("DETAIL").is_ok() && determined && beyond {
        let u = e.uncertainty.unwrap();
        let k = (0..6)
            .max_by(|&a, &b| ((j[a] - t[a]).abs() / s[a]).total_cmp(&((j[b] - t[b]).abs() / s[b])))
            .unwrap();
        eprintln!(
            "element {k}: z {:.2} err {:.2e} sigma {:.2e} noise {:.2e} bias {:.2e} tag {:.2e}",
            (j[k] - t[k]) / s[k],
            j[k] - t[k],
            s[k],
            u.noise_kg_m2[k],
            u.bias_kg_m2[k],
            u.time_tag_kg_m2[k]
        );
    }
    (true, determined, determined && beyond)
}

fn main() {
    let n: u64 = std::env::args()
        .nth(1)
        .map_or(60, |a| a.parse().expect("THROWS"));
    let from: u64 = std::env::var("FROM").map_or(0, |v| v.parse().expect("FROM"));
    let runs: Vec<[(bool, bool, bool); 2]> = (from..from + n)
        .into_par_iter()
        .map(|seed| {
            let without: Vec<LabEffect> = std::env::var("WITHOUT")
                .unwrap_or_default()
                .split(',')
                .filter(|w| !w.is_empty())
                .map(|w| match w {
                    "vibration" => LabEffect::Vibration,
                    "speed" => LabEffect::SpeedTelemetry,
                    "inertial" => LabEffect::InertialTorque,
                    "drag" => LabEffect::Drag,
                    _ => panic!("WITHOUT: {w}"),
                })
                .collect();
            let mut p = Preset::throw_without(&without).with_drawn_tumble(seed);
            p.common.seed = seed;
            let out = p.simulate().expect("simulation");
            [false, true].map(|batch| {
                let r = judge(estimate(&out.samples, batch), &out.inertia_kg_m2);
                if r.2 && std::env::var("DETAIL").is_ok() {
                    eprintln!("seed {seed} (batch: {batch}) determined beyond 3σ");
                }
                r
            })
        })
        .collect();
    println!("| run | throws | answered | determined | determined beyond 3σ |");
    println!("|---|---|---|---|---|");
    for (k, name) in ["streaming", "batch"].iter().enumerate() {
        let count = |f: fn(&(bool, bool, bool)) -> bool| runs.iter().filter(|r| f(&r[k])).count();
        println!(
            "| {name} | {n} | {} | {} | {} |",
            count(|r| r.0),
            count(|r| r.1),
            count(|r| r.2)
        );
    }
}
