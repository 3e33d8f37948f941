//! Monte Carlo of the rotor calibration (`--batch --calibrate-rotors`; book, "Status and
//! uncertainty", "Calibrating the rotors").
//!
//! ```sh
//! cargo run --release -p inertia-cli --example rotor_calibration -- 20   # seeds per cell
//! ```
//!
//! **Data.** The paper's slew (`Common::physical()`, 300 s at 10 Hz) and the small-sat
//! preset (MEMS gyro and star tracker through an MEKF, 600 s), each without and with a
//! momentum bias (the wheels' momentum at rest along (0.3, −0.2, 1): 0.1 N m s on the
//! slew, 0.01 N m s on the small satellite), carried by a four-wheel pyramid (true spin
//! inertias 1.5–1.8 g m², speeds in rpm).
//!
//! **Errors.** The true wheels differ from the spacecraft file's by draws of its σ: each
//! axis tilted by two angles of σ 0.5°, and/or each spin inertia off by an independent
//! relative error of σ 2 %, or each wheel's speed read at its own instant, skewed by a
//! draw of σ 50 ms (within the 0.1 s telemetry period; `sim::rotors::speeds_each`), or
//! both tilts and skews; the file states those σ.
//!
//! **Columns.** The median significance of the record's total angular momentum (its
//! norm over its scatter along the record, `pipeline::MIN_MOMENTUM_SIGNIFICANCE`); median
//! relative Frobenius error of: the same record with the true wheels
//! (effect-free); the file's wheels taken as exact (uncalibrated); the calibrated batch
//! run; then the calibrated median over the effect-free one; "3σ cov.": the calibrated
//! runs with every element within ±3σ; "determined beyond 3σ"; "calibrated": the runs
//! with a calibration (the others had too little total momentum and kept the consider
//! term; with tilts and time tags, the time tags alone are calibrated then); the median count of combinations the data fix, of the sources. On
//! stderr, for the time tags: how many were found within 3σ of the drawn skew.

use inertia::estimator::observability::Observability;
use inertia::estimator::rotor_calibration::NotMade;
use inertia::estimator::Estimate;
use inertia::pipeline::{PipelineSettings, Run};
use inertia::sample::Sample;
use inertia::sim::presets::Preset;
use inertia::sim::rotors::{drawn_pyramid, speeds_each, stated_exact};
use inertia::sim::scenario::{Common, Scenario, SlewPlan};
use inertia::spacecraft::{RotorErrors, Spacecraft};
use inertia::tensor::relative_frobenius_error;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rayon::prelude::*;

const TRUE_J: [f64; 4] = [1.5e-3, 1.6e-3, 1.7e-3, 1.8e-3];

/// One answer and its run.
fn run(
    samples: &[Sample],
    speeds: &[f64],
    sc: Spacecraft,
    calibrate: bool,
) -> (Option<Estimate>, Option<Run>) {
    let Ok(config) = (PipelineSettings {
        calibrate_rotors: calibrate,
        ..PipelineSettings::default()
    })
    .validate() else {
        return (None, None);
    };
    let Ok(r) = Run::new(config, true) else {
        return (None, None);
    };
    let mut r = r.with_spacecraft(sc);
    let mut last = None;
    for (k, s) in samples.iter().enumerate() {
        if r.push_with_speeds(s, &speeds[4 * k..4 * k + 4], |e| last = Some(*e))
            .is_err()
        {
            return (None, None);
        }
    }
    if r.finish(|e| last = Some(*e)).is_err() {
        return (None, None);
    }
    (last, Some(r))
}

/// The true wheels and the file ([module docs](self), "Errors").
fn drawn(seed: u64, tilt_deg: f64, scale: f64) -> (Spacecraft, Spacecraft) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2000 + seed);
    drawn_pyramid(TRUE_J, scale, RotorErrors::Independent, tilt_deg, &mut rng)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Each wheel's own time-tag skew, s: draws of σ `sigma_s` within the telemetry period.
fn drawn_skews(seed: u64, sigma_s: f64) -> [f64; 4] {
    use rand_distr::{Distribution, StandardNormal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3000 + seed);
    core::array::from_fn(|_| {
        let z: f64 = StandardNormal.sample(&mut rng);
        (z * sigma_s).clamp(-0.099, 0.099)
    })
}

/// The record of `data` with `seed` and a momentum bias of `bias` N m s along
/// (0.3, −0.2, 1), its wheel telemetry skewed by `skew_s`.
fn record(data: &str, seed: u64, bias: f64, skew_s: f64) -> (Vec<Sample>, Matrix3<f64>) {
    let dir = Vector3::new(0.3, -0.2, 1.0) * bias;
    let out = match data {
        "slew" => {
            let mut common = Common {
                seed,
                ..Common::physical()
            };
            common.realism.wheels.skew_s = skew_s;
            Scenario::Slew(SlewPlan {
                momentum_bias_nms: dir,
                ..SlewPlan::default()
            })
            .simulate(&common)
        }
        _ => {
            let mut p = Preset::small_sat();
            p.common.seed = seed;
            p.common.realism.wheels.skew_s = skew_s;
            if let Scenario::Slew(plan) = &mut p.scenario {
                plan.momentum_bias_nms = dir;
            }
            p.simulate()
        }
    }
    .expect("sim");
    (out.samples, out.inertia_kg_m2)
}

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let start = std::time::Instant::now();
    println!("| data | momentum bias, N m s | total momentum / its scatter | errors | effect-free | uncalibrated | calibrated | / effect-free | 3σ cov. | determined beyond 3σ | calibrated | data fix |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (data, bias) in [
        ("slew", 0.0),
        ("slew", 0.1),
        ("small-sat", 0.0),
        ("small-sat", 0.01),
    ] {
        for (label, tilt, scale, tag) in [
            ("axis tilt 0.5°", 0.5, 0.0, 0.0),
            ("spin inertia 2 %, independent", 0.0, 0.02, 0.0),
            ("both", 0.5, 0.02, 0.0),
            ("time tag 50 ms per wheel", 0.0, 0.0, 0.05),
            ("axis tilt 0.5° and time tag 50 ms", 0.5, 0.0, 0.05),
        ] {
            let rows: Vec<_> = (1..=seeds)
                .into_par_iter()
                .map(|seed| {
                    let (samples, truth) = record(data, seed, bias, 0.0);
                    let (truth_sc, mut stated) = drawn(seed, tilt, scale);
                    let speeds = inertia::sim::rotors::speeds(&samples, &truth_sc).expect("speeds");
                    // The file's wheels with each time tag ± `tag`, and the speeds read at
                    // the drawn skews; the effect-free run keeps the on-time speeds.
                    let skews = drawn_skews(seed, tag);
                    let skewed = (tag > 0.0).then(|| {
                        for r in &mut stated.rotors {
                            r.time_tag_sigma_s = tag;
                        }
                        let late: Vec<Vec<Sample>> = skews
                            .iter()
                            .map(|&s| record(data, seed, bias, s).0)
                            .collect();
                        let records: Vec<&[Sample]> = late.iter().map(Vec::as_slice).collect();
                        speeds_each(&records, &truth_sc).expect("speeds")
                    });
                    let free_speeds = speeds.clone();
                    let speeds = skewed.unwrap_or(speeds);
                    let err = |e: &Option<Estimate>| {
                        e.and_then(|e| e.inertia())
                            .map_or(f64::NAN, |m| relative_frobenius_error(&m, &truth))
                    };
                    let free = err(&run(&samples, &free_speeds, truth_sc, false).0);
                    let plain = err(&run(&samples, &speeds, stated_exact(&stated), false).0);
                    let (cal, r) = run(&samples, &speeds, stated, true);
                    let within = cal.and_then(|e| e.within_3sigma(&truth)) == Some(true);
                    let determined = cal.is_some_and(|e| {
                        matches!(e.observability, Observability::Determined { .. })
                    });
                    let fit = r.as_ref().and_then(|r| r.rotor_calibration().cloned());
                    // The time tags' |error|/σ (the simulator's skew reads ahead; the
                    // report's value is how late each wheel is).
                    let tag_z: Vec<f64> = fit
                        .as_ref()
                        .filter(|_| tag > 0.0)
                        .map(|f| {
                            // The time tags: the parameters in s, one per wheel in order.
                            f.value
                                .iter()
                                .zip(&f.sigma)
                                .zip(&f.unit)
                                .filter(|(_, u)| **u == "s")
                                .zip(&skews)
                                .map(|(((v, s), _), t)| (v + t).abs() / s)
                                .collect()
                        })
                        .unwrap_or_default();
                    let ratio = fit.as_ref().map(|f| f.momentum_significance).or_else(|| {
                        match r.as_ref().and_then(Run::rotor_calibration_not_made) {
                            Some(NotMade::NoMomentum { significance, .. }) => Some(significance),
                            _ => None,
                        }
                    });
                    (
                        free,
                        plain,
                        err(&cal),
                        within,
                        determined && !within,
                        fit.as_ref().map(|f| (f.data_fixed, f.sources.len())),
                        ratio.unwrap_or(f64::NAN),
                        tag_z,
                    )
                })
                .collect();
            let n = rows.len() as f64;
            let (f, p, c) = (
                median(rows.iter().map(|r| r.0).collect()),
                median(rows.iter().map(|r| r.1).collect()),
                median(rows.iter().map(|r| r.2).collect()),
            );
            type Row = (
                f64,
                f64,
                f64,
                bool,
                bool,
                Option<(usize, usize)>,
                f64,
                Vec<f64>,
            );
            let frac = |g: &dyn Fn(&Row) -> bool| rows.iter().filter(|r| g(r)).count() as f64 / n;
            let fixed: Vec<f64> = rows
                .iter()
                .filter_map(|r| r.5.map(|x| x.0 as f64))
                .collect();
            let of = rows.iter().find_map(|r| r.5.map(|x| x.1)).unwrap_or(0);
            let fixed = if fixed.is_empty() {
                "—".to_string()
            } else {
                format!("{:.0} of {of}", median(fixed))
            };
            println!(
                "| {data} | {bias} | {:.2} | {label} | {f:.2e} | {p:.2e} | {c:.2e} | {:.2} | {:.2} | {:.2} | {:.2} | {fixed} |",
                median(rows.iter().map(|r| r.6).collect()),
                c / f,
                frac(&|r| r.3),
                frac(&|r| r.4),
                frac(&|r| r.5.is_some()),
            );
            let z: Vec<f64> = rows.iter().flat_map(|r| r.7.iter().copied()).collect();
            if !z.is_empty() {
                eprintln!(
                    "{data}, bias {bias}, {label}: time tags within 3σ {} of {}, worst {:.2}σ",
                    z.iter().filter(|&&z| z <= 3.0).count(),
                    z.len(),
                    z.iter().fold(0.0f64, |a, &b| a.max(b))
                );
            }
        }
    }
    eprintln!(
        "{seeds} seeds per cell: {:.0} s",
        start.elapsed().as_secs_f64()
    );
}
