//! The Monte Carlo matrix of the README: the discrete momentum estimator beside the paper's
//! variational estimator and the momentum RLS baseline, in the same runs, across
//! scenarios, attitude sources, telemetry rates and seeds.
//!
//! ```sh
//! cargo run --release -p inertia-cli --example matrix -- 50    # seeds per cell (default 50)
//! ```
//!
//! Attitude sources are built from the simulator's truth and gyro: `truth` (true attitude,
//! paper gyro rates), `paper gyro` / `FOG` / `MEMS` (attitude propagated from a gyro of
//! 1e-5 deg/s/√Hz, 0.02 deg/√h, 0.15 deg/√h; rates from the same gyro) and `ST + FOG`
//! (true attitude times white star-tracker noise 5″/5″/40″ about body x/y/z with the
//! boresight on z; rates from a FOG). `1 Hz` keeps every tenth node of the 10 Hz run, with
//! the gyro rate averaged over the second. The constant-torque cells add an unknown
//! 1e-5 N m per axis (body) that is not in the telemetry. Every estimator runs with
//! J ⪰ εI only: the paper's J lies slightly outside Σ ⪰ 0 (docs/conventions.md §4).

use inertia::attitude::Quaternion;
use inertia::constraints::ConstraintSet;
use inertia::dynamics::GyrostatState;
use inertia::estimator::observability::Observability;
use inertia::estimator::Estimate;
use inertia::pipeline::{Pipeline, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::SimOutput;
use inertia::tensor::relative_frobenius_error;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;

const ARCSEC: f64 = std::f64::consts::PI / 180.0 / 3600.0;
const PAPER_GYRO: f64 = 1e-5;
/// 0.02 deg/√h in deg/s/√Hz.
const FOG: f64 = 0.02 / 60.0;
/// 0.15 deg/√h in deg/s/√Hz.
const MEMS: f64 = 0.15 / 60.0;

#[derive(Clone, Copy, Debug)]
enum Attitude {
    Truth,
    PaperGyro,
    Fog,
    Mems,
    StarTrackerFog,
}

impl Attitude {
    fn name(self) -> &'static str {
        match self {
            Attitude::Truth => "truth",
            Attitude::PaperGyro => "paper gyro",
            Attitude::Fog => "FOG-propagated",
            Attitude::Mems => "MEMS-propagated",
            Attitude::StarTrackerFog => "star tracker + FOG",
        }
    }
    fn gyro(self) -> f64 {
        match self {
            Attitude::Truth | Attitude::PaperGyro => PAPER_GYRO,
            Attitude::Fog | Attitude::StarTrackerFog => FOG,
            Attitude::Mems => MEMS,
        }
    }
}

#[derive(Clone, Copy)]
struct Cell {
    scenario: &'static str,
    attitude: Attitude,
    decimate: usize,
    torque: bool,
}

fn simulate(cell: &Cell, seed: u64) -> SimOutput {
    let sc = if cell.scenario == "slew" {
        Scenario::slew()
    } else {
        Scenario::spin()
    };
    let common = Common {
        gyro_noise_deg_s_rthz: cell.attitude.gyro(),
        seed,
        ..Common::paper()
    };
    let mut run = if cell.torque {
        let cfg = sc.config(&common);
        let constant = |_t: f64, _x: &GyrostatState| Vector3::new(1e-5, 1e-5, 1e-5);
        let out = match &sc {
            Scenario::Slew(p) => {
                let ctrl = inertia::sim::control::SlewController::new(
                    p.nominal_inertia_kg_m2,
                    cfg.initial.q,
                    p.slews.clone(),
                    p.natural_freq_rad_s,
                    p.damping,
                )
                .expect("controller");
                inertia::sim::simulate(&cfg, &ctrl, &constant)
            }
            Scenario::Spin(p) => inertia::sim::simulate(&cfg, &p.pulse, &constant),
        };
        let mut out = out.expect("simulation");
        for s in &mut out.samples {
            s.tau_nm = Vector3::zeros();
        }
        out
    } else {
        sc.simulate(&common).expect("simulation")
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let cross = Normal::new(0.0, 5.0 * ARCSEC).expect("normal");
    let roll = Normal::new(0.0, 40.0 * ARCSEC).expect("normal");
    for (s, t) in run.samples.iter_mut().zip(&run.truth) {
        match cell.attitude {
            Attitude::Truth => s.q = t.state.q,
            Attitude::StarTrackerFog => {
                let e = Vector3::new(
                    cross.sample(&mut rng),
                    cross.sample(&mut rng),
                    roll.sample(&mut rng),
                );
                s.q = t.state.q.mul(&Quaternion::exp(&e));
            }
            _ => {}
        }
    }
    if cell.decimate > 1 {
        let n = cell.decimate;
        let all = run.samples.clone();
        run.samples = all
            .chunks(n)
            .filter(|c| c.len() == n)
            .map(|c| {
                let w = c
                    .iter()
                    .map(|s| s.omega_rad_s.unwrap_or_default())
                    .sum::<Vector3<f64>>()
                    / n as f64;
                Sample {
                    omega_rad_s: Some(w),
                    ..c[0]
                }
            })
            .collect();
    }
    run
}

fn estimate(samples: &[Sample], estimator: &str) -> Option<Estimate> {
    let mut p = Pipeline::new(&PipelineSettings {
        estimator: estimator.into(),
        // The momentum RLS takes no constraints.
        constraints: if estimator == "momentum" {
            ConstraintSet::physical()
        } else {
            ConstraintSet::positive_definite()
        },
        solve_every: 50,
        ..PipelineSettings::default()
    })
    .ok()?;
    for s in samples {
        p.push(s).ok()?;
    }
    p.last().copied()
}

#[derive(Default, Clone)]
struct Stats {
    errors: Vec<f64>,
    element_within: [usize; 6],
    with_sigma: usize,
    determined: usize,
    determined_outside: usize,
    failed: usize,
}

fn record(stats: &mut Stats, e: Option<Estimate>, truth: &Matrix3<f64>) {
    let Some(e) = e else {
        stats.failed += 1;
        return;
    };
    let Some(j) = e.inertia() else {
        stats.failed += 1;
        return;
    };
    stats.errors.push(relative_frobenius_error(&j, truth));
    if let (Some(sig), Some(jv)) = (e.sigma_kg_m2(), e.j()) {
        stats.with_sigma += 1;
        let t = inertia::tensor::j_from_matrix(truth);
        for k in 0..6 {
            if (jv[k] - t[k]).abs() <= 3.0 * sig[k] {
                stats.element_within[k] += 1;
            }
        }
        if matches!(e.observability, Observability::Determined { .. }) {
            stats.determined += 1;
            if e.within_3sigma(truth) == Some(false) {
                stats.determined_outside += 1;
            }
        }
    }
}

fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[((s.len() - 1) as f64 * q).round() as usize]
}

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(50);
    let mut cells = Vec::new();
    for scenario in ["slew", "spin"] {
        for attitude in [
            Attitude::Truth,
            Attitude::PaperGyro,
            Attitude::Fog,
            Attitude::Mems,
            Attitude::StarTrackerFog,
        ] {
            for decimate in [1, 10] {
                cells.push(Cell {
                    scenario,
                    attitude,
                    decimate,
                    torque: false,
                });
            }
        }
        cells.push(Cell {
            scenario,
            attitude: Attitude::PaperGyro,
            decimate: 1,
            torque: true,
        });
    }
    let estimators = ["discrete-momentum", "variational", "momentum"];
    println!("| scenario | attitude | telemetry | discrete momentum: median / 95 % | variational: median / 95 % | momentum RLS: median / 95 % | DM/RLS | DM 3σ coverage (worst element) | DM determined beyond 3σ |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for cell in &cells {
        let results: Vec<[Option<Estimate>; 3]> = (1..=seeds)
            .into_par_iter()
            .map(|seed| {
                let run = simulate(cell, seed);
                estimators.map(|e| estimate(&run.samples, e))
            })
            .collect();
        let truth = inertia::tensor::paper_j_true();
        let mut stats = vec![Stats::default(); 3];
        for r in &results {
            for k in 0..3 {
                record(&mut stats[k], r[k], &truth);
            }
        }
        let fmt = |s: &Stats| {
            let mut out = format!(
                "{:.1e} / {:.1e}",
                quantile(&s.errors, 0.5),
                quantile(&s.errors, 0.95)
            );
            if s.failed > 0 {
                out += &format!(" ({} no answer)", s.failed);
            }
            out
        };
        let dm = &stats[0];
        let coverage = if dm.with_sigma > 0 {
            dm.element_within.iter().copied().min().unwrap_or(0) as f64 / dm.with_sigma as f64
        } else {
            f64::NAN
        };
        let outside = if dm.determined > 0 {
            format!(
                "{:.2} of {}",
                dm.determined_outside as f64 / dm.determined as f64,
                dm.determined
            )
        } else {
            "none determined".into()
        };
        println!(
            "| {} | {} | {}{} | {} | {} | {} | {:.2} | {:.2} | {} |",
            cell.scenario,
            cell.attitude.name(),
            if cell.decimate == 1 { "10 Hz" } else { "1 Hz" },
            if cell.torque {
                ", unknown 1e-5 N m"
            } else {
                ""
            },
            fmt(&stats[0]),
            fmt(&stats[1]),
            fmt(&stats[2]),
            quantile(&stats[0].errors, 0.5) / quantile(&stats[2].errors, 0.5),
            coverage,
            outside
        );
    }
}
