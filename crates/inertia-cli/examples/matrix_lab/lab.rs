//! The lab cells of the Monte Carlo matrix: the hand-thrown device of
//! `Preset::throw()` (0.5 s at 4 kHz, one flywheel spun up, issue #30), with all its lab
//! effects, none, each alone and all but each, and (all effects or none) with each seed's
//! throw tumbling its own way (`Preset::with_drawn_tumble`), running the default estimator, the momentum
//! RLS and the filtered equation-error baseline side by side on the same telemetry.
//!
//! Each estimator runs through `Run` (`WHEEL_DELAY=off|SECONDS|estimate`: the wheel speeds'
//! time tag, for every estimator; off when unset) with a solve every 50 samples and the default
//! (physical) constraint set (the device's J is physical; the RLS and the equation-error
//! baseline take none). The table gives, per estimator, the median and 95 % final relative
//! Frobenius error, and for those with a σ the fraction of runs with the truth within ±3σ
//! per element (J11 J22 J33 J12 J13 J23); "DM / best" is the default's median over the
//! better of the two baselines' medians. The equation-error baseline filters at
//! [`LAB_CUTOFF_HZ`] (`--filter-cutoff-hz`), below the rotor's vibration and the speed
//! telemetry's 100 Hz staircase: the baseline at its best on the throw, not at its
//! default (a twentieth of the sample rate, 200 Hz here, which lets both through).

use inertia::estimator::wheel_delay::WheelDelay;
use inertia::estimator::Estimate;
use inertia::pipeline::{PipelineSettings, Run};
use inertia::sample::Sample;
use inertia::sim::presets::{LabEffect, Preset};
use inertia::tensor::{j_from_matrix, relative_frobenius_error};
use nalgebra::Matrix3;
use rayon::prelude::*;

const EFFECTS: [(LabEffect, &str); 4] = [
    (LabEffect::Vibration, "vibration"),
    (LabEffect::SpeedTelemetry, "speed telemetry"),
    (LabEffect::InertialTorque, "inertial torque"),
    (LabEffect::Drag, "drag"),
];

/// The equation-error baseline's cutoff in the lab cells, Hz.
pub const LAB_CUTOFF_HZ: f64 = 25.0;

/// The estimators of the lab cells: registry name and column label.
const ESTIMATORS: [(&str, &str); 3] = [
    ("discrete-momentum", "discrete momentum (default)"),
    ("momentum", "momentum RLS"),
    ("equation-error", "equation error"),
];

/// A lab cell: its label and the effects switched off.
pub struct LabCell {
    pub label: String,
    off: Vec<LabEffect>,
    /// Each seed's throw tumbling its own way (`Preset::with_drawn_tumble`).
    drawn: bool,
}

/// Every lab cell.
pub fn cells() -> Vec<LabCell> {
    let all: Vec<LabEffect> = EFFECTS.iter().map(|e| e.0).collect();
    let mut cells = vec![
        LabCell {
            label: "throw | all effects".into(),
            off: Vec::new(),
            drawn: false,
        },
        LabCell {
            label: "throw | none".into(),
            off: all.clone(),
            drawn: false,
        },
        LabCell {
            label: "throw, drawn tumble | all effects".into(),
            off: Vec::new(),
            drawn: true,
        },
        LabCell {
            label: "throw, drawn tumble | none".into(),
            off: all.clone(),
            drawn: true,
        },
    ];
    for (e, name) in EFFECTS {
        cells.push(LabCell {
            label: format!("throw | only {name}"),
            off: all.iter().copied().filter(|x| *x != e).collect(),
            drawn: false,
        });
    }
    for (e, name) in EFFECTS {
        cells.push(LabCell {
            label: format!("throw | all but {name}"),
            off: vec![e],
            drawn: false,
        });
    }
    cells
}

/// The wheel speeds' time tag from `WHEEL_DELAY` (`off`, seconds or `estimate`; every
/// estimator), off when unset; a value it cannot read stops the matrix.
fn wheel_delay_from_env() -> WheelDelay {
    std::env::var("WHEEL_DELAY").map_or(WheelDelay::Off, |v| {
        inertia::pipeline::parse_wheel_delay(&v).unwrap_or_else(|e| panic!("WHEEL_DELAY: {e}"))
    })
}

fn estimate(samples: &[Sample], name: &str) -> Option<Estimate> {
    let config = PipelineSettings {
        estimator: name.into(),
        solve_every: 50,
        uncertainty: true,
        inertial_torque: super::inertial_torque_from_env(name),
        damping: super::damping_from_env(name),
        filter_cutoff_hz: (name == "equation-error").then_some(LAB_CUTOFF_HZ),
        wheel_delay: wheel_delay_from_env(),
        ..PipelineSettings::default()
    }
    .validate()
    .ok()?;
    let mut run = Run::new(config, false).ok()?;
    let mut last = None;
    for s in samples {
        run.push(s, |e| last = Some(*e)).ok()?;
    }
    run.finish(|e| last = Some(*e)).ok()?;
    last
}

/// One run: the truth and each estimator's final estimate.
struct LabRun {
    truth: Matrix3<f64>,
    estimates: Vec<Option<Estimate>>,
}

fn run(cell: &LabCell, seed: u64) -> LabRun {
    let mut p = Preset::throw_without(&cell.off);
    if cell.drawn {
        p = p.with_drawn_tumble(seed);
    }
    p.common.seed = seed;
    let out = p
        .simulate()
        .unwrap_or_else(|e| panic!("{}: simulation failed: {e}", cell.label));
    LabRun {
        truth: out.inertia_kg_m2,
        estimates: ESTIMATORS
            .iter()
            .map(|(name, _)| estimate(&out.samples, name))
            .collect(),
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

/// Median and 95 % error, the per-element 3σ coverage (None without a σ), and the
/// determined answers with how many of them have an element beyond 3σ.
fn summarise(runs: &[&LabRun], k: usize) -> (Vec<f64>, usize, Option<[f64; 6]>, (usize, usize)) {
    let mut errors = Vec::new();
    let mut within = [0usize; 6];
    let mut with_sigma = 0;
    let mut failed = 0;
    let mut determined = (0, 0);
    for r in runs {
        let Some((e, j)) = r.estimates[k].and_then(|e| Some((e, e.inertia()?))) else {
            failed += 1;
            continue;
        };
        errors.push(relative_frobenius_error(&j, &r.truth));
        if matches!(
            e.observability,
            inertia::estimator::observability::Observability::Determined { .. }
        ) {
            determined.0 += 1;
            determined.1 += usize::from(e.within_3sigma(&r.truth) == Some(false));
        }
        if let (Some(sig), Some(jv)) = (e.sigma_kg_m2(), e.j()) {
            with_sigma += 1;
            let t = j_from_matrix(&r.truth);
            for i in 0..6 {
                if (jv[i] - t[i]).abs() <= 3.0 * sig[i] {
                    within[i] += 1;
                }
            }
        }
    }
    let coverage = (with_sigma > 0).then(|| within.map(|w| w as f64 / with_sigma as f64));
    (errors, failed, coverage, determined)
}

/// Run the lab cells whose label contains `filter` (lower case) over seeds 1..=seeds and
/// print their table.
pub fn table(seeds: u64, filter: Option<&str>) {
    let cells: Vec<LabCell> = cells()
        .into_iter()
        .filter(|c| filter.is_none_or(|f| c.label.to_lowercase().contains(f)))
        .collect();
    if cells.is_empty() {
        return;
    }
    let jobs: Vec<(usize, u64)> = (0..cells.len())
        .flat_map(|c| (1..=seeds).map(move |s| (c, s)))
        .collect();
    let runs: Vec<LabRun> = jobs.par_iter().map(|&(c, s)| run(&cells[c], s)).collect();
    println!();
    let mut header = String::from("| lab cell |");
    let mut rule = String::from("|---|");
    for (_, label) in ESTIMATORS {
        header += &format!(
            " {label}: median / 95 % (determined, of which beyond 3σ) | its 3σ coverage J11 J22 J33 J12 J13 J23 |"
        );
        rule += "---|---|";
    }
    header += " DM / best baseline |";
    rule += "---|";
    println!("{header}");
    println!("{rule}");
    for (c, cell) in cells.iter().enumerate() {
        let mine: Vec<&LabRun> = runs
            .iter()
            .zip(&jobs)
            .filter(|(_, j)| j.0 == c)
            .map(|(r, _)| r)
            .collect();
        let mut line = format!("| {} |", cell.label);
        let mut medians = Vec::new();
        for k in 0..ESTIMATORS.len() {
            let (errors, failed, coverage, (det, beyond)) = summarise(&mine, k);
            let median = quantile(&errors, 0.5);
            medians.push(median);
            let mut e = format!("{median:.2e} / {:.1e}", quantile(&errors, 0.95));
            if coverage.is_some() {
                e += &format!(" ({det}, {beyond})");
            }
            if failed > 0 {
                e += &format!(" ({failed} no answer)");
            }
            let cov = coverage.map_or("no σ".into(), |c| {
                c.iter()
                    .map(|v| format!("{v:.2}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            });
            line += &format!(" {e} | {cov} |");
        }
        let best = medians[1].min(medians[2]);
        line += &format!(" {:.2} |", medians[0] / best);
        println!("{line}");
    }
    println!();
    println!(
        "{} lab cells × {seeds} seeds per cell (Preset::throw, seeds 1–{seeds}).",
        cells.len()
    );
}
