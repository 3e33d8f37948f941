//! The outside-torque cells of the Monte Carlo matrix (issue #31): each outside effect of
//! `sim::Environment` on the paper's slew and on the small satellite (paper gyro, gyro-
//! propagated attitude, 10 Hz aligned commands), estimated twice on the same telemetry:
//! **modelled** (the samples carry the measurement the model needs: the orbit position,
//! the magnetometer's field, the thrusters' force) and **left out** (the same samples
//! without it), beside the effect-free cell of the same spacecraft and the momentum RLS.
//!
//! Effects: gravity gradient on a 500 km equatorial orbit; a residual dipole of 0.05 A m²
//! (body axes `(0.03, −0.03, 0.028)`) in a constant 3e-5 T field (magnetometer noise
//! 1e-7 T), and the same dipole in Earth's dipole field on a 500 km orbit inclined 60°
//! (the field turning along the orbit; the gravity gradient too, both modelled); thrusters (`Thrusters::cube_pairs(0.02 N, 0.3 m)`, the default firing) with
//! the centre of mass 2 cm from the origin (`(0.012, −0.01, 0.013)` m).
//!
//! Columns: the default estimator's median / 95 % relative Frobenius error; its ratio to
//! the effect-free cell's median; the worst element's 3σ coverage; the determined answers
//! and how many are beyond 3σ; the left-out median / 95 %; the momentum RLS (which uses
//! no outside measurement); and for the dipole and the centre of mass, the median error of
//! the estimated vector (norm), the fraction of components within 3σ and the median ratio
//! of the σ's norm to the error's.

use inertia::estimator::external_torque::Estimated3;
use inertia::estimator::observability::Observability;
use inertia::estimator::Estimate;
use inertia::pipeline::{Pipeline, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::presets::Preset;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{AttitudeSource, CommandHold, Magnetic, Orbit, Thrusters};
use inertia::tensor::{j_from_matrix, relative_frobenius_error};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

/// The residual dipole, A m² (norm 0.05).
const DIPOLE_AM2: [f64; 3] = [0.03, -0.03, 0.028];
/// The constant field, T (norm 3e-5).
const FIELD_T: [f64; 3] = [1.8e-5, 1.2e-5, -2.08e-5];
/// The centre of mass, m (norm 2 cm).
const CENTRE_M: [f64; 3] = [0.012, -0.01, 0.013];

#[derive(Clone, Copy, PartialEq)]
enum Effect {
    None,
    GravityGradient,
    Dipole,
    OrbitDipole,
    CentreOfMass,
}

impl Effect {
    const ALL: [Effect; 5] = [
        Effect::None,
        Effect::GravityGradient,
        Effect::Dipole,
        Effect::OrbitDipole,
        Effect::CentreOfMass,
    ];

    fn name(self) -> &'static str {
        match self {
            Effect::None => "effect-free",
            Effect::GravityGradient => "gravity gradient 500 km",
            Effect::Dipole => "residual dipole 0.05 A m² in 3e-5 T",
            Effect::OrbitDipole => {
                "residual dipole 0.05 A m², Earth's field and gravity gradient, 500 km at 60°"
            }
            Effect::CentreOfMass => "thrusters, centre of mass 2 cm off",
        }
    }
}

/// An outside-torque cell: spacecraft and effect.
pub struct OutsideCell {
    pub label: String,
    small_sat: bool,
    effect: Effect,
}

/// Every outside-torque cell.
pub fn cells() -> Vec<OutsideCell> {
    let mut out = Vec::new();
    for small_sat in [false, true] {
        for effect in Effect::ALL {
            let craft = if small_sat { "small-sat" } else { "slew" };
            out.push(OutsideCell {
                label: format!("outside | {craft} | {}", effect.name()),
                small_sat,
                effect,
            });
        }
    }
    out
}

fn setup(cell: &OutsideCell, seed: u64) -> (Scenario, Common) {
    let (scenario, mut common) = if cell.small_sat {
        let p = Preset::small_sat();
        (p.scenario, p.common)
    } else {
        (Scenario::slew(), Common::paper())
    };
    common.seed = seed;
    common.gyro_noise_deg_s_rthz = 1e-5;
    let r = &mut common.realism;
    r.attitude = AttitudeSource::GyroPropagated;
    r.gyro = Default::default();
    r.star_tracker = Default::default();
    r.mekf = Default::default();
    r.commands = Some(CommandHold::at(10.0));
    let env = &mut r.environment;
    match cell.effect {
        Effect::None => {}
        Effect::GravityGradient => env.orbit = Some(Orbit::circular(500e3)),
        Effect::Dipole => {
            env.magnetic = Some(Magnetic {
                residual_dipole_am2: Vector3::from(DIPOLE_AM2),
                ..Magnetic::constant(Vector3::from(FIELD_T))
            });
        }
        Effect::OrbitDipole => {
            env.orbit = Some(Orbit {
                inclination_deg: 60.0,
                ..Orbit::circular(500e3)
            });
            env.magnetic = Some(Magnetic {
                residual_dipole_am2: Vector3::from(DIPOLE_AM2),
                ..Magnetic::dipole()
            });
        }
        Effect::CentreOfMass => {
            env.thrusters = Some(Thrusters {
                centre_of_mass_m: Vector3::from(CENTRE_M),
                ..Thrusters::cube_pairs(0.02, 0.3)
            });
        }
    }
    (scenario, common)
}

struct OutsideRun {
    truth: Matrix3<f64>,
    /// Default estimator modelled, left out; momentum RLS.
    estimates: [Option<Estimate>; 3],
    /// The estimated dipole or centre of mass (modelled).
    vector: Option<Estimated3>,
}

fn pipeline(samples: &[Sample], estimator: &str) -> Option<Pipeline> {
    let mut p = Pipeline::new(&PipelineSettings {
        estimator: estimator.into(),
        solve_every: 50,
        constraints: if estimator == "momentum" {
            inertia::constraints::ConstraintSet::physical()
        } else {
            inertia::constraints::ConstraintSet::positive_definite()
        },
        ..PipelineSettings::default()
    })
    .ok()?;
    for s in samples {
        p.push(s).ok()?;
    }
    Some(p)
}

fn run(cell: &OutsideCell, seed: u64) -> OutsideRun {
    let (scenario, common) = setup(cell, seed);
    let out = scenario
        .simulate(&common)
        .unwrap_or_else(|e| panic!("{}: simulation failed: {e}", cell.label));
    let modelled = pipeline(&out.samples, "discrete-momentum");
    let stripped: Vec<Sample> = out
        .samples
        .iter()
        .map(|s| Sample {
            external: Default::default(),
            ..*s
        })
        .collect();
    let left_out = pipeline(&stripped, "discrete-momentum");
    let rls = pipeline(&out.samples, "momentum");
    let o = modelled.as_ref().and_then(|p| p.diagnostics().outside);
    OutsideRun {
        truth: out.inertia_kg_m2,
        vector: o.and_then(|o| match cell.effect {
            Effect::Dipole | Effect::OrbitDipole => o.residual_dipole_am2,
            Effect::CentreOfMass => o.centre_of_mass_m,
            _ => None,
        }),
        estimates: [modelled, left_out, rls].map(|p| p.and_then(|p| p.last().copied())),
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

fn errors(runs: &[&OutsideRun], k: usize) -> Vec<f64> {
    runs.iter()
        .filter_map(|r| {
            Some(relative_frobenius_error(
                &r.estimates[k]?.inertia()?,
                &r.truth,
            ))
        })
        .collect()
}

/// The worst element's 3σ coverage and (determined, of which beyond 3σ).
fn coverage(runs: &[&OutsideRun], k: usize) -> (Option<f64>, usize, usize) {
    let (mut within, mut with_sigma, mut det, mut beyond) = ([0usize; 6], 0, 0, 0);
    for r in runs {
        let Some(e) = r.estimates[k] else { continue };
        if let (Some(sig), Some(jv)) = (e.sigma_kg_m2(), e.j()) {
            with_sigma += 1;
            let t = j_from_matrix(&r.truth);
            for i in 0..6 {
                within[i] += usize::from((jv[i] - t[i]).abs() <= 3.0 * sig[i]);
            }
        }
        if matches!(e.observability, Observability::Determined { .. }) {
            det += 1;
            beyond += usize::from(e.within_3sigma(&r.truth) == Some(false));
        }
    }
    let worst = (with_sigma > 0).then(|| {
        within
            .iter()
            .map(|&w| w as f64 / with_sigma as f64)
            .fold(1.0, f64::min)
    });
    (worst, det, beyond)
}

/// Run the outside-torque cells whose label contains `filter` over seeds 1..=seeds and
/// print their table.
pub fn table(seeds: u64, filter: Option<&str>) {
    let cells: Vec<OutsideCell> = cells()
        .into_iter()
        .filter(|c| filter.is_none_or(|f| c.label.to_lowercase().contains(f)))
        .collect();
    if cells.is_empty() {
        return;
    }
    let jobs: Vec<(usize, u64)> = (0..cells.len())
        .flat_map(|c| (1..=seeds).map(move |s| (c, s)))
        .collect();
    let runs: Vec<OutsideRun> = jobs.par_iter().map(|&(c, s)| run(&cells[c], s)).collect();
    let of = |c: usize| -> Vec<&OutsideRun> {
        runs.iter()
            .zip(&jobs)
            .filter(|(_, j)| j.0 == c)
            .map(|(r, _)| r)
            .collect()
    };
    println!();
    println!("| outside cell | DM modelled: median / 95 % | / effect-free median | its 3σ coverage (worst element) | determined (beyond 3σ) | DM left out: median / 95 % | momentum RLS: median / 95 % | estimated m or c: median error | its components within 3σ (σ / error, median) |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for (c, cell) in cells.iter().enumerate() {
        let mine = of(c);
        let free = cells
            .iter()
            .position(|o| o.small_sat == cell.small_sat && o.effect == Effect::None)
            .map(|f| quantile(&errors(&of(f), 0), 0.5));
        let m = errors(&mine, 0);
        let (cov, det, beyond) = coverage(&mine, 0);
        let pair = |v: &[f64]| format!("{:.1e} / {:.1e}", quantile(v, 0.5), quantile(v, 0.95));
        let (truth, unit) = match cell.effect {
            Effect::Dipole | Effect::OrbitDipole => (Some(DIPOLE_AM2), "A m²"),
            Effect::CentreOfMass => (Some(CENTRE_M), "m"),
            _ => (None, ""),
        };
        let (vec_error, vec_cov) = match truth {
            Some(t) => {
                let t = Vector3::from(t);
                let v: Vec<&Estimated3> = mine.iter().filter_map(|r| r.vector.as_ref()).collect();
                let errs: Vec<f64> = v
                    .iter()
                    .map(|e| (Vector3::from(e.value) - t).norm())
                    .collect();
                let (mut inside, mut n, mut ratios) = (0, 0, Vec::new());
                for e in &v {
                    if let Some(s) = e.sigma_all() {
                        for i in 0..3 {
                            n += 1;
                            inside += usize::from((e.value[i] - t[i]).abs() <= 3.0 * s[i]);
                        }
                        ratios.push(Vector3::from(s).norm() / (Vector3::from(e.value) - t).norm());
                    }
                }
                (
                    format!("{:.1e} {unit}", quantile(&errs, 0.5)),
                    if n > 0 {
                        format!(
                            "{:.2} ({:.1})",
                            inside as f64 / n as f64,
                            quantile(&ratios, 0.5)
                        )
                    } else {
                        "no σ".into()
                    },
                )
            }
            None => ("—".into(), "—".into()),
        };
        println!(
            "| {} | {} | {} | {} | {det} ({beyond}) | {} | {} | {vec_error} | {vec_cov} |",
            cell.label,
            pair(&m),
            free.map_or("—".into(), |f| format!("{:.2}", quantile(&m, 0.5) / f)),
            cov.map_or("no σ".into(), |v| format!("{v:.2}")),
            pair(&errors(&mine, 1)),
            pair(&errors(&mine, 2)),
        );
    }
    println!();
    println!(
        "{} outside cells × {seeds} seeds per cell (seeds 1–{seeds}).",
        cells.len()
    );
}
