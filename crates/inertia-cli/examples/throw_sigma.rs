//! Monte Carlo of the lab throw with every effect, each throw tumbling its own way
//! (`Preset::throw().with_drawn_tumble(seed)`), through the default estimator streaming
//! and batch (a solve every 50 samples): how many answers, how many determined, and of
//! those how many have an element beyond 3σ.
//!
//! `cargo run --release -p inertia-cli --example throw_sigma -- [THROWS]` (default 60,
//! seeds from `FROM`, default 0; `WHEEL_DELAY=off|SECONDS|estimate` the wheel speeds'
//! time tag, off when unset). Results: the book, "What you tell the run: the wheel
//! speeds' time tag".

use inertia::estimator::observability::Observability;
use inertia::estimator::Estimate;
use inertia::pipeline::{PipelineSettings, Run};
use inertia::sample::Sample;
use inertia::sim::presets::Preset;
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
            let mut p = Preset::throw().with_drawn_tumble(seed);
            p.common.seed = seed;
            let out = p.simulate().expect("simulation");
            [false, true].map(|batch| judge(estimate(&out.samples, batch), &out.inertia_kg_m2))
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
