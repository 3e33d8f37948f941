//! The Monte Carlo matrix of the README: the discrete momentum estimator beside the paper's
//! variational estimator and the momentum RLS baseline, in the same runs, across
//! spacecraft, attitude sources, telemetry timing and seeds, on the library's
//! flight-realistic simulator (`inertia::sim`, `Realism`).
//!
//! ```sh
//! cargo run --release -p inertia-cli --example matrix -- 50           # seeds per cell
//! cargo run --release -p inertia-cli --example matrix -- 3 "spin |"   # cells whose label contains "spin |"
//! ```
//!
//! The first argument is the number of seeds per cell (default 50), the optional second a
//! case-insensitive substring of the cell label (`scenario | attitude | telemetry`, as in
//! the table) that selects the cells to run. Progress and per-cell timings go to stderr,
//! the markdown table to stdout, then the wall time. 58 cells × 2 seeds take about 2 s on
//! two cores (the slowest cells, small-sat's 600 s at 10 Hz, about 0.1 s per run), so
//! 50 seeds take about a minute: every cell runs the same number of seeds.
//!
//! **Spacecraft.** The paper's `slew` and `spin` cases (`Scenario::slew()`,
//! `Scenario::spin()` with `Common::paper()`: J of §VI, 300 s / 180 s, disturbance torque
//! 1e-8 N m/√Hz) and `small-sat` (`Preset::small_sat()`: its own inertia, wheels with
//! 1e-5 N m s quantisation, disturbance and 600 s of slews; only its attitude source, gyro
//! and command timing are varied like the others').
//!
//! **Attitude sources** (all from the simulator's own models; the telemetered rates are
//! always the gyro's delta angle over the telemetry step divided by the step):
//!
//! * `truth`: the true attitude (`AttitudeSource::Truth`), rates from the paper's gyro
//!   (1e-5 deg/s/√Hz);
//! * `paper gyro`: attitude propagated from the paper's gyro (`GyroPropagated`);
//! * `FOG-propagated`: propagated from a FOG, ARW 0.02 deg/√h;
//! * `MEMS-propagated`: propagated from a MEMS gyro, ARW 0.15 deg/√h;
//! * `star tracker + FOG`: a star tracker 5″/5″/40″ (1σ, boresight on body z) sampled at
//!   every telemetry node (`AttitudeSource::StarTracker`), rates from the FOG;
//! * `MEKF`: on `slew` and `spin`, the simulator's MEKF fusing the same star tracker at
//!   10 Hz (whatever the telemetry rate) with the FOG, bias-corrected rates; on
//!   `small-sat`, the preset unchanged: MEKF of its MEMS gyro (ARW 0.15 deg/√h, turn-on
//!   bias 2/−1.5/1 deg/h, bias instability 0.5 deg/h over 600 s) and its 5 Hz tracker.
//!
//! Gyro bias and bias instability (`GyroErrors`) are **off** in every cell except the
//! small-sat MEKF cell, where they are the preset's: the other gyros are angle random walk
//! only, so a propagated attitude drifts by the random walk alone.
//!
//! **Telemetry timing.** Wheel torque commands are always held (`CommandHold`) at 10 Hz:
//! `10 Hz aligned` ticks on the telemetry nodes (phase 0); `10 Hz mid-way` ticks half-way
//! between them (`phase_s = 0.05`); `1 Hz` integrates at 10 Hz with aligned 10 Hz commands
//! and writes every tenth node (`telemetry_every = 10`), so the rate is the gyro's average
//! over the second and the run keeps its duration (301 samples for the slew).
//!
//! **Extra cells** (paper gyro, 10 Hz aligned): an unknown constant torque of 1e-5 N m per
//! body axis (slew and spin), and gravity gradient on a 500 km equatorial circular orbit
//! (slew and small-sat). Neither torque is in the telemetry: the estimators are not given
//! it.
//!
//! **Estimators**, all on the same telemetry, through `Pipeline` with its defaults except:
//! a solve every 50 samples, uncertainty on, and J ⪰ εI only for the constrained ones (the
//! paper's J lies slightly outside Σ ⪰ 0, docs/conventions.md §4); the momentum RLS takes
//! no constraints. The error is the final ‖Ĵ − J‖_F/‖J‖_F against the simulator's J.
//! "3σ coverage" is the worst element's fraction of runs (with a σ) within ±3σ; "σ_F /
//! error" the median ratio of the stated Frobenius σ to ‖Ĵ − J‖_F; "determined beyond 3σ"
//! is the fraction of answers marked `Determined` whose ‖Ĵ − J‖_F exceeds 3 × the stated
//! Frobenius σ, with the number of determined answers. The last three columns repeat the
//! discrete momentum estimator given the cell's gyro noise density (`gyro_noise_deg_s_rthz`,
//! errors-in-variables compensation), as a user with the gyro's datasheet would.
//!
//! **Lab cells** (`matrix_lab/lab.rs`): the hand-thrown device of `Preset::throw()`, with
//! all its lab effects, none, each alone and all but each, running the default estimator,
//! the momentum RLS and the filtered equation-error baseline; their table follows the main
//! one (cells whose label contains the filter; `throw` selects only them).
//!
//! **Outside-torque cells** (`matrix_outside/outside.rs`): gravity gradient, a residual
//! magnetic dipole and thrusters with the centre of mass off the origin, each modelled
//! (the samples carry the orbit position, the field, the force) and left out, beside the
//! effect-free cell; their table follows (`outside` selects only them).
//!
//! The environment variable `CHAIN=S` sets the discrete momentum estimator's `--chain`
//! (`0`: none) for experiments; unset, the default; `INERTIAL_TORQUE=off|on|auto|short` its
//! `--inertial-torque` (unset: the default, `short`); `DAMPING=1` its `--damping`. `DIGITS=1` prints the medians with
//! four significant digits. `WHEEL_DELAY=off|SECONDS|estimate` sets the lab cells' wheel
//! speed time tag (every estimator; unset: off).

use inertia::constraints::ConstraintSet;
use inertia::estimator::Estimate;
use inertia::pipeline::{Pipeline, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::gyro::arw_deg_rthr_to_deg_s_rthz;
use inertia::sim::presets::Preset;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{
    AttitudeSource, CommandHold, GyroErrors, MekfSettings, Orbit, SimOutput, StarTracker,
};
use inertia::tensor::relative_frobenius_error;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use std::sync::Mutex;
use std::time::{Duration, Instant};

#[path = "matrix_lab/lab.rs"]
mod lab;
#[path = "matrix_outside/outside.rs"]
mod outside;
#[path = "matrix_stats/stats.rs"]
mod stats;
use stats::{quantile, Paired, Stats};

/// The discrete momentum estimator's `--inertial-torque` from `INERTIAL_TORQUE`
/// (unset or not a mode, or another estimator: the default).
fn inertial_torque_from_env(estimator: &str) -> inertia::pipeline::InertialTorque {
    std::env::var("INERTIAL_TORQUE")
        .ok()
        .filter(|_| estimator == "discrete-momentum")
        .and_then(|v| v.parse().ok())
        .unwrap_or_default()
}

/// The discrete momentum estimator's `--damping` from `DAMPING=1` (other estimators: off).
fn damping_from_env(estimator: &str) -> bool {
    estimator == "discrete-momentum" && std::env::var("DAMPING").is_ok_and(|v| v == "1")
}

/// The paper's gyro, deg/s/√Hz.
const PAPER_GYRO: f64 = 1e-5;
/// FOG angle random walk, deg/√h.
const FOG_ARW: f64 = 0.02;
/// MEMS angle random walk, deg/√h.
const MEMS_ARW: f64 = 0.15;
/// Star-tracker rate of the MEKF on the paper's scenarios, Hz.
const MEKF_TRACKER_HZ: f64 = 10.0;
/// The unknown constant torque, N m per body axis.
const CONSTANT_TORQUE_NM: f64 = 1e-5;
/// Orbit altitude of the gravity-gradient cells, m.
const ORBIT_ALTITUDE_M: f64 = 500e3;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Craft {
    Slew,
    Spin,
    SmallSat,
}

impl Craft {
    fn name(self) -> &'static str {
        match self {
            Craft::Slew => "slew",
            Craft::Spin => "spin",
            Craft::SmallSat => "small-sat",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Attitude {
    Truth,
    PaperGyro,
    Fog,
    Mems,
    StarTrackerFog,
    Mekf,
}

impl Attitude {
    const ALL: [Attitude; 6] = [
        Attitude::Truth,
        Attitude::PaperGyro,
        Attitude::Fog,
        Attitude::Mems,
        Attitude::StarTrackerFog,
        Attitude::Mekf,
    ];

    fn name(self, craft: Craft) -> &'static str {
        match (self, craft) {
            (Attitude::Truth, _) => "truth",
            (Attitude::PaperGyro, _) => "paper gyro",
            (Attitude::Fog, _) => "FOG-propagated",
            (Attitude::Mems, _) => "MEMS-propagated",
            (Attitude::StarTrackerFog, _) => "star tracker + FOG",
            (Attitude::Mekf, Craft::SmallSat) => "MEKF (preset: MEMS with bias + tracker 5 Hz)",
            (Attitude::Mekf, _) => "MEKF (tracker 10 Hz + FOG)",
        }
    }

    fn source(self) -> AttitudeSource {
        match self {
            Attitude::Truth => AttitudeSource::Truth,
            Attitude::PaperGyro | Attitude::Fog | Attitude::Mems => AttitudeSource::GyroPropagated,
            Attitude::StarTrackerFog => AttitudeSource::StarTracker,
            Attitude::Mekf => AttitudeSource::Mekf,
        }
    }

    /// Gyro rate-noise density, deg/s/√Hz.
    fn gyro_deg_s_rthz(self) -> f64 {
        match self {
            Attitude::Truth | Attitude::PaperGyro => PAPER_GYRO,
            Attitude::Fog | Attitude::StarTrackerFog | Attitude::Mekf => {
                arw_deg_rthr_to_deg_s_rthz(FOG_ARW)
            }
            Attitude::Mems => arw_deg_rthr_to_deg_s_rthz(MEMS_ARW),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Timing {
    Aligned,
    MidWay,
    OneHz,
}

impl Timing {
    const ALL: [Timing; 3] = [Timing::Aligned, Timing::MidWay, Timing::OneHz];

    fn name(self) -> &'static str {
        match self {
            Timing::Aligned => "10 Hz aligned",
            Timing::MidWay => "10 Hz mid-way",
            Timing::OneHz => "1 Hz",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Extra {
    None,
    ConstantTorque,
    GravityGradient,
}

#[derive(Clone, Copy, Debug)]
struct Cell {
    craft: Craft,
    attitude: Attitude,
    timing: Timing,
    extra: Extra,
}

impl Cell {
    fn telemetry(&self) -> String {
        let extra = match self.extra {
            Extra::None => "",
            Extra::ConstantTorque => ", unknown 1e-5 N m",
            Extra::GravityGradient => ", gravity gradient 500 km",
        };
        format!("{}{extra}", self.timing.name())
    }

    fn label(&self) -> String {
        format!(
            "{} | {} | {}",
            self.craft.name(),
            self.attitude.name(self.craft),
            self.telemetry()
        )
    }

    /// The scenario and its settings for `seed`.
    fn setup(&self, seed: u64) -> (Scenario, Common) {
        let (scenario, mut common) = match self.craft {
            Craft::Slew => (Scenario::slew(), Common::paper()),
            Craft::Spin => (Scenario::spin(), Common::paper()),
            Craft::SmallSat => {
                let p = Preset::small_sat();
                (p.scenario, p.common)
            }
        };
        common.seed = seed;
        let r = &mut common.realism;
        if !(self.craft == Craft::SmallSat && self.attitude == Attitude::Mekf) {
            common.gyro_noise_deg_s_rthz = self.attitude.gyro_deg_s_rthz();
            r.attitude = self.attitude.source();
            r.gyro = GyroErrors::default();
            r.star_tracker = StarTracker {
                rate_hz: (self.attitude == Attitude::Mekf).then_some(MEKF_TRACKER_HZ),
                ..StarTracker::default()
            };
            r.mekf = MekfSettings::default();
        }
        r.commands = Some(CommandHold {
            phase_s: if self.timing == Timing::MidWay {
                0.05
            } else {
                0.0
            },
            ..CommandHold::at(10.0)
        });
        r.telemetry_every = if self.timing == Timing::OneHz { 10 } else { 1 };
        match self.extra {
            Extra::None => {}
            Extra::ConstantTorque => {
                r.environment.constant_torque_nm = Vector3::repeat(CONSTANT_TORQUE_NM);
            }
            Extra::GravityGradient => {
                r.environment.orbit = Some(Orbit::circular(ORBIT_ALTITUDE_M));
            }
        }
        (scenario, common)
    }

    fn simulate(&self, seed: u64) -> SimOutput {
        let (scenario, common) = self.setup(seed);
        scenario
            .simulate(&common)
            .unwrap_or_else(|e| panic!("{}: simulation failed: {e}", self.label()))
    }
}

impl Cell {
    /// The attitude's angle random walk a user states with the densities, deg/√h: that
    /// of the gyro it is propagated from; none for a truth, star-tracker or MEKF
    /// attitude (bounded errors). `DRIFT=0` states none anywhere.
    fn attitude_drift_deg_rth(&self, common: &Common) -> Option<f64> {
        let propagated = common.realism.attitude == AttitudeSource::GyroPropagated;
        let off = std::env::var("DRIFT").is_ok_and(|v| v == "0");
        (propagated && !off).then_some(common.gyro_noise_deg_s_rthz * 60.0)
    }
}

fn cells() -> Vec<Cell> {
    let mut cells = Vec::new();
    for craft in [Craft::Slew, Craft::Spin, Craft::SmallSat] {
        for attitude in Attitude::ALL {
            for timing in Timing::ALL {
                cells.push(Cell {
                    craft,
                    attitude,
                    timing,
                    extra: Extra::None,
                });
            }
        }
    }
    for (craft, extra) in [
        (Craft::Slew, Extra::ConstantTorque),
        (Craft::Spin, Extra::ConstantTorque),
        (Craft::Slew, Extra::GravityGradient),
        (Craft::SmallSat, Extra::GravityGradient),
    ] {
        cells.push(Cell {
            craft,
            attitude: Attitude::PaperGyro,
            timing: Timing::Aligned,
            extra,
        });
    }
    cells
}

/// The estimators run on every telemetry: name, and whether it is given the gyro's noise
/// density (errors-in-variables compensation; a datasheet number a user has).
const ESTIMATORS: [(&str, bool); 4] = [
    ("discrete-momentum", false),
    ("variational", false),
    ("momentum", false),
    ("discrete-momentum", true),
];

/// One estimator's outcome on one run.
struct Outcome {
    /// The final estimate.
    estimate: Option<Estimate>,
    /// The largest residual variance ratio of a span to the rest
    /// (`Pipeline::residual_consistency`).
    residual_ratio: Option<f64>,
    /// The residual variance over the part the stated gyro density implies
    /// (`Pipeline::gyro_density_ratio`).
    density_ratio: Option<f64>,
}

fn estimate(
    samples: &[Sample],
    estimator: &str,
    gyro_deg_s_rthz: Option<f64>,
    attitude_drift_deg_rth: Option<f64>,
) -> Option<Outcome> {
    let mut p = Pipeline::new(&PipelineSettings {
        estimator: estimator.into(),
        gyro_noise_deg_s_rthz: gyro_deg_s_rthz,
        attitude_drift_deg_rth,
        // The momentum RLS takes no constraints.
        constraints: if estimator == "momentum" {
            ConstraintSet::physical()
        } else {
            ConstraintSet::positive_definite()
        },
        solve_every: 50,
        uncertainty: true,
        max_chain_s: match std::env::var("CHAIN")
            .ok()
            .and_then(|v| v.parse::<f64>().ok())
        {
            Some(c) if c > 0.0 => Some(c),
            Some(_) => None,
            None => PipelineSettings::default().max_chain_s,
        },
        inertial_torque: inertial_torque_from_env(estimator),
        damping: damping_from_env(estimator),
        ..PipelineSettings::default()
    })
    .ok()?;
    for s in samples {
        p.push(s).ok()?;
    }
    Some(Outcome {
        estimate: p.last().copied(),
        residual_ratio: p.diagnostics().residual_consistency.map(|w| w.ratio),
        density_ratio: p.diagnostics().gyro_density_ratio,
    })
}

/// One run: the simulator's J, the three estimates and the time of the simulation and of
/// each estimator, s.
struct Run {
    truth: Matrix3<f64>,
    estimates: [Option<Outcome>; 4],
    seconds: [f64; 5],
}

impl Run {
    /// Estimator `k`'s final relative Frobenius error, if it answered.
    fn error(&self, k: usize) -> Option<f64> {
        let j = self.estimates[k].as_ref()?.estimate.as_ref()?.inertia()?;
        Some(relative_frobenius_error(&j, &self.truth))
    }
}

fn run(cell: &Cell, seed: u64) -> Run {
    let t = Instant::now();
    let (_, common) = cell.setup(seed);
    let out = cell.simulate(seed);
    let mut seconds = [t.elapsed().as_secs_f64(), 0.0, 0.0, 0.0, 0.0];
    let estimates = core::array::from_fn(|k| {
        let t = Instant::now();
        let (name, density) = ESTIMATORS[k];
        let e = estimate(
            &out.samples,
            name,
            density.then_some(common.gyro_noise_deg_s_rthz),
            density
                .then(|| cell.attitude_drift_deg_rth(&common))
                .flatten(),
        );
        seconds[k + 1] = t.elapsed().as_secs_f64();
        e
    });
    Run {
        truth: out.inertia_kg_m2,
        estimates,
        seconds,
    }
}

/// Per-cell progress: runs left and thread seconds spent (simulation, DM, variational,
/// RLS; wall-clock time of the worker thread, so it includes time the thread waited).
#[derive(Clone, Default)]
struct Progress {
    left: u64,
    seconds: [f64; 5],
}

fn fmt_duration(d: Duration) -> String {
    format!("{:.2} s", d.as_secs_f64())
}

fn main() {
    let mut args = std::env::args().skip(1);
    let seeds: u64 = args
        .next()
        .map(|s| {
            s.parse()
                .unwrap_or_else(|_| panic!("seeds per cell: expected a number, got {s:?}"))
        })
        .unwrap_or(50);
    let filter = args.next().map(|s| s.to_lowercase());
    let cells: Vec<Cell> = cells()
        .into_iter()
        .filter(|c| {
            filter
                .as_deref()
                .is_none_or(|f| c.label().to_lowercase().contains(f))
        })
        .collect();
    let lab_cells = lab::cells()
        .iter()
        .filter(|c| {
            filter
                .as_deref()
                .is_none_or(|f| c.label.to_lowercase().contains(f))
        })
        .count();
    let outside_cells = outside::cells()
        .iter()
        .filter(|c| {
            filter
                .as_deref()
                .is_none_or(|f| c.label.to_lowercase().contains(f))
        })
        .count();
    if cells.is_empty() && lab_cells == 0 && outside_cells == 0 {
        eprintln!("no cell label contains {:?}", filter.unwrap_or_default());
        std::process::exit(2);
    }
    if cells.is_empty() {
        lab::table(seeds, filter.as_deref());
        outside::table(seeds, filter.as_deref());
        return;
    }
    eprintln!(
        "{} cells × {seeds} seeds on {} threads",
        cells.len(),
        rayon::current_num_threads()
    );

    let start = Instant::now();
    let progress = Mutex::new(vec![
        Progress {
            left: seeds,
            ..Progress::default()
        };
        cells.len()
    ]);
    let done = std::sync::atomic::AtomicUsize::new(0);
    let jobs: Vec<(usize, u64)> = (0..cells.len())
        .flat_map(|c| (1..=seeds).map(move |s| (c, s)))
        .collect();
    let runs: Vec<Run> = jobs
        .par_iter()
        .map(|&(c, seed)| {
            let r = run(&cells[c], seed);
            let mut p = progress.lock().unwrap_or_else(|e| e.into_inner());
            let cell = &mut p[c];
            cell.left -= 1;
            for (a, b) in cell.seconds.iter_mut().zip(r.seconds) {
                *a += b;
            }
            if cell.left == 0 {
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                let s = cell.seconds;
                eprintln!(
                    "[{:>8}] {n}/{} {}: {:.2} thread-s (sim {:.2}, DM {:.2}, variational {:.2}, RLS {:.2}, DM with density {:.2})",
                    fmt_duration(start.elapsed()),
                    cells.len(),
                    cells[c].label(),
                    s.iter().sum::<f64>(),
                    s[0],
                    s[1],
                    s[2],
                    s[3],
                    s[4],
                );
            }
            r
        })
        .collect();
    let wall = start.elapsed();

    println!(
        "| scenario | attitude | telemetry | discrete momentum (default): median / 95 % | variational: median / 95 % | momentum RLS: median / 95 % | DM/RLS (DM better in / seeds, sign test p) | DM 3σ coverage (worst element) | DM σ_F / error (median) | DM determined beyond 3σ | variational determined beyond 3σ | DM given the gyro density: median / 95 % | its 3σ coverage | its determined beyond 3σ | DM residual ratio: median / max (withdrawn) | variational residual ratio: median / max (withdrawn) | DM given the density: residual / density variance, median / min (withdrawn) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (c, cell) in cells.iter().enumerate() {
        let mut stats = vec![Stats::default(); 4];
        let mut paired = Paired::default();
        for r in runs
            .iter()
            .zip(&jobs)
            .filter(|(_, job)| job.0 == c)
            .map(|(r, _)| r)
        {
            for (s, e) in stats.iter_mut().zip(&r.estimates) {
                s.record(e.as_ref(), &r.truth);
            }
            paired.record(r.error(0), r.error(2));
        }
        println!(
            "| {} | {} | {} | {} | {} | {} | {:.2} {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} ({}) |",
            cell.craft.name(),
            cell.attitude.name(cell.craft),
            cell.telemetry(),
            stats[0].errors(),
            stats[1].errors(),
            stats[2].errors(),
            quantile(&stats[0].errors, 0.5) / quantile(&stats[2].errors, 0.5),
            paired,
            stats[0].coverage(),
            stats[0].sigma_ratio(),
            stats[0].determined_beyond(),
            stats[1].determined_beyond(),
            stats[3].errors(),
            stats[3].coverage(),
            stats[3].determined_beyond(),
            stats[0].residual_ratio(),
            stats[1].residual_ratio(),
            stats[3].density_ratio(),
            stats[3].inconsistent,
        );
    }
    let busy: f64 = runs.iter().flat_map(|r| r.seconds).sum();
    lab::table(seeds, filter.as_deref());
    outside::table(seeds, filter.as_deref());
    println!();
    println!(
        "{} cells × {seeds} seeds per cell; wall time {} on {} threads ({:.2} thread-s in the runs).",
        cells.len(),
        fmt_duration(wall),
        rayon::current_num_threads(),
        busy
    );
}
