//! Monte Carlo of `inertia plan` on the public peer's three spacecraft (book, "Planning the
//! calibration manoeuvre").
//!
//! ```sh
//! cargo run --release -p inertia-cli --example plan -- 20      # seeds per profile
//! ```
//!
//! **Spacecraft.** `satellite-inertia-id` (commit `aea6bfa8`), `config_sat1.yaml`,
//! `config_sat2.yaml`, `config_sat3.yaml`: diagonal inertias 0.26/0.26/0.16,
//! 6.53/5.96/4.53 and 10.6/14.2/15.3 kg m²; three orthogonal wheels of largest torque
//! 0.01, 0.1 and 0.1 N m and momentum `max_speed × inertia` = 460 × 1e-4 = 0.046,
//! 900 × 0.002 = 1.8 and 1500 × 0.003 = 4.5 N m s; commands at 1 Hz (its `sim.dt`).
//! Gyro: the peer's IMU default, 1e-4 rad/s white per 1 s sample, i.e. 1e-4 rad/s/√Hz;
//! telemetry at 10 Hz, attitude propagated from the gyro, exact wheel momentum, unknown
//! white disturbance torque 1e-8 N m/√Hz.
//!
//! **Prior.** The planner does not know the truth: its J is the truth with the diagonal
//! off by +8 %, −6 %, +5 % and products of 2 % of the mean moment, ±10 % (1σ); the
//! margin on every limit is `min(0.9, 1/(1 + 3 · 0.1))`.
//!
//! **Profiles.** The plan (`inertia::plan::request::make`, as `inertia plan`: target 1 %
//! relative Frobenius at 3σ, 8 rehearsal flights on the prior J, the estimator's chain
//! chosen by rehearsal among 30, 60 and 120 s, or the second argument's) and every fixed
//! profile of `inertia::plan::fixed` at horizons of 120 and 300 s, scaled to the same
//! limits. All are flown on the same seeds. The fixed profiles are flown with the
//! estimator's default 30 s chain and, where the plan chose another, with the plan's too;
//! the best fixed profile at each is the one with the shortest *achieved* median time.
//!
//! **Flights.** Each profile for its own length (the plan until its end, a fixed profile
//! for its horizon): the simulator with the true inertia, the estimator with its defaults
//! (`discrete-momentum`) and the chain above, solved every 1 s. Time to target: the first estimate whose
//! reported σ gives `3 σ_F ≤ 1 %` (σ_F with the true ‖J‖). Predicted σ: the
//! information-matrix σ_F at the plan's end, over the RMS of the final errors over seeds
//! (the achieved error σ), and the rehearsal's median reported σ_F over the check
//! flights' median, at the plan's end or the rehearsal's (it stops at its target),
//! whichever is first. Coverage: the fraction of flights whose final
//! estimate has every element within ±3 reported σ. Saturation: the largest
//! wheel-momentum use of the true flights and the largest commanded torque use (1 = the
//! limit).

use inertia::pipeline::PipelineSettings;
use inertia::plan::rehearse::{fly, median_reported, Flight, FlightSettings};
use inertia::plan::request::{make, Chain, Request};
use inertia::plan::{
    fixed_profiles, CommandProfile, EstimatorModel, Limits, NoiseModel, PlanSettings, Vehicle,
    Wheel,
};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

const GYRO_RAD_S_RTHZ: f64 = 1e-4;
const TARGET: f64 = 0.01;
/// The longest plan, and the longest fixed profile, s.
const HORIZON_S: f64 = 300.0;

struct Sat {
    name: &'static str,
    truth: Matrix3<f64>,
    torque: f64,
    momentum: f64,
}

fn sats() -> [Sat; 3] {
    [
        Sat {
            name: "sat1",
            truth: Matrix3::from_diagonal(&Vector3::new(0.26, 0.26, 0.16)),
            torque: 0.01,
            momentum: 460.0 * 1e-4,
        },
        Sat {
            name: "sat2",
            truth: Matrix3::from_diagonal(&Vector3::new(6.53, 5.96, 4.53)),
            torque: 0.1,
            momentum: 900.0 * 0.002,
        },
        Sat {
            name: "sat3",
            truth: Matrix3::from_diagonal(&Vector3::new(10.6, 14.2, 15.3)),
            torque: 0.1,
            momentum: 1500.0 * 0.003,
        },
    ]
}

fn vehicle(s: &Sat) -> Vehicle {
    let d = s.truth.diagonal();
    let p = 0.02 * d.mean();
    let prior = Matrix3::new(
        1.08 * d.x,
        p,
        -p, //
        p,
        0.94 * d.y,
        p, //
        -p,
        p,
        1.05 * d.z,
    );
    Vehicle {
        prior_kg_m2: prior,
        prior_sigma_kg_m2: None,
        limits: Limits {
            wheels: (0..3)
                .map(|i| Wheel {
                    name: format!("rw{}", i + 1),
                    axis: Vector3::ith(i, 1.0),
                    max_torque_nm: s.torque,
                    max_momentum_nms: s.momentum,
                })
                .collect(),
            max_rate_rad_s: None,
            max_angle_rad: None,
            margin: (1.0f64 / 1.3).min(0.9),
        },
        noise: NoiseModel {
            gyro_rad_s_rthz: GYRO_RAD_S_RTHZ,
            wheel_nms: 0.0,
            telemetry_period_s: 0.1,
        },
        controller_period_s: 1.0,
        rotor_relative_sigma: 0.0,
    }
}

/// The estimator's short chain (the second argument: a length in s, or `auto`, the
/// default: `inertia plan`'s choice by rehearsal).
fn chain() -> Chain {
    match std::env::args().nth(2).as_deref() {
        None | Some("auto") => Chain::Choose,
        Some(x) => Chain::Fixed(Some(x.parse().expect("chain: a length in s or `auto`"))),
    }
}

fn chain_label(c: Option<f64>) -> String {
    c.map_or("one chain".into(), |c| format!("{c:.0} s chains"))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[v.len() / 2]
}

fn fmt_t(t: f64) -> String {
    if t.is_finite() {
        format!("{t:.0} s")
    } else {
        "not met".into()
    }
}

/// One profile's check flights, summarised.
struct Row {
    label: String,
    /// Median achieved time (∞ if not reached by half the flights).
    time: f64,
    lo: f64,
    hi: f64,
    reached: usize,
    flights: Vec<Flight>,
    torque_use: f64,
}

fn row(
    label: String,
    v: &Vehicle,
    s: &Sat,
    profile: &CommandProfile,
    seeds: u64,
    fs: &FlightSettings,
) -> Row {
    // Each profile is flown for its own length: the estimate at its end is the answer.
    let fs = FlightSettings {
        duration_s: profile.duration_s(),
        ..fs.clone()
    };
    let flights: Vec<Flight> = (1..=seeds)
        .into_par_iter()
        .map(|seed| fly(v, profile, &s.truth, &fs, seed).expect("flies"))
        .collect();
    let times: Vec<f64> = flights
        .iter()
        .map(|f| f.reached(TARGET).unwrap_or(f64::INFINITY))
        .collect();
    let reached: Vec<f64> = times.iter().copied().filter(|t| t.is_finite()).collect();
    Row {
        label,
        time: median(times),
        lo: reached.iter().copied().fold(f64::INFINITY, f64::min),
        hi: reached.iter().copied().fold(0.0, f64::max),
        reached: reached.len(),
        torque_use: v
            .limits
            .use_of(profile, &v.prior_kg_m2)
            .expect("limits")
            .torque,
        flights,
    }
}

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let request = Request {
        target_relative: TARGET,
        max_duration_s: HORIZON_S,
        chain: chain(),
        rehearsals: 8,
        disturbance_nm_rthz: 1e-8,
        ..Request::default()
    };
    let flights_at = |chain_s: Option<f64>| FlightSettings {
        duration_s: HORIZON_S,
        disturbance_nm_rthz: 1e-8,
        estimator: PipelineSettings {
            solve_every: 10,
            max_chain_s: chain_s,
            ..PipelineSettings::default()
        },
    };
    let default_chain = Some(inertia::pipeline::DEFAULT_MAX_CHAIN_S);
    println!(
        "Seeds per profile: {seeds}; estimator chain {:?}.\n",
        request.chain
    );
    println!(
        "| spacecraft | profile (estimator chain) | time to 1 % (3σ), predicted: information / rehearsal | achieved: median [min, max] | reached | information σ_F / RMS error | rehearsal σ_F / reported σ_F | 3σ coverage | peak wheel momentum use | peak torque use |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for s in sats() {
        let v = vehicle(&s);
        let out = make(&v, &request).expect("plan");
        let pl = &out.plan;
        let (rehearsal_t, rehearsal_sigma) = &out.rehearsal;
        let fs = flights_at(out.chain_s);
        let end = pl.profile.duration_s();
        let plan_row = row("plan".into(), &v, &s, &pl.profile, seeds, &fs);
        // Information σ_F at the plan's end against the RMS of the final errors.
        let info_sf = *pl.prediction.relative_sigma.last().unwrap_or(&f64::NAN);
        let w = [1.0, 1.0, 1.0, 2.0, 2.0, 2.0];
        let ok: Vec<&Flight> = plan_row
            .flights
            .iter()
            .filter(|f| f.error.is_finite())
            .collect();
        let ms: f64 = ok
            .iter()
            .map(|f| {
                (0..6)
                    .map(|i| w[i] * f.element_error_kg_m2[i].powi(2))
                    .sum::<f64>()
            })
            .sum::<f64>()
            / ok.len().max(1) as f64;
        let rms_f = ms.sqrt() / s.truth.norm();
        // The rehearsal's median reported σ_F at the plan's end against the check flights'.
        let at = |t: &[f64], x: &[f64], end: f64| -> f64 {
            t.iter()
                .zip(x)
                .rfind(|(t, _)| **t <= end + 1e-9)
                .map_or(f64::NAN, |(_, x)| *x)
        };
        // At the plan's end, or the rehearsal's, whichever is first (a rehearsal stops
        // where its target is met).
        let end = end.min(rehearsal_t.last().copied().unwrap_or(end));
        let rehearsal_sf = at(rehearsal_t, rehearsal_sigma, end);
        let (ct, cmed, _) = median_reported(&plan_row.flights, TARGET);
        let check_sf = at(&ct, &cmed, end);
        let cov = |r: &Row| {
            r.flights.iter().filter(|f| f.covered).count() as f64 / r.flights.len() as f64
        };
        let mom = |r: &Row| r.flights.iter().map(|f| f.momentum_use).fold(0.0, f64::max);
        println!(
            "| {} | plan, {:.0} s ({}) | {} / {} | {} [{:.0}, {:.0}] | {}/{} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
            s.name,
            pl.profile.duration_s(),
            chain_label(out.chain_s),
            fmt_t(pl.target_met_s.unwrap_or(f64::INFINITY)),
            fmt_t(out.reported_target_met_s.unwrap_or(f64::INFINITY)),
            fmt_t(plan_row.time),
            plan_row.lo,
            plan_row.hi,
            plan_row.reached,
            seeds,
            info_sf / rms_f,
            rehearsal_sf / check_sf,
            cov(&plan_row),
            mom(&plan_row),
            plan_row.torque_use,
        );
        let settings = PlanSettings {
            target_relative: Some(TARGET),
            max_duration_s: HORIZON_S,
            estimator: EstimatorModel {
                chain_s: out.chain_s,
                ..EstimatorModel::default()
            },
            ..PlanSettings::default()
        };
        let fixed = fixed_profiles(&v, &settings, &[120.0, 300.0]).expect("fixed");
        // The fixed profiles with the estimator's default chain, and with the plan's.
        let mut chains = std::vec![default_chain];
        if out.chain_s != default_chain {
            chains.push(out.chain_s);
        }
        let mut rows: Vec<(Row, Option<f64>)> = Vec::new();
        for chain_s in chains {
            let fs = flights_at(chain_s);
            let at_chain: Vec<(Row, Option<f64>)> = fixed
                .iter()
                .map(|f| {
                    (
                        row(
                            format!("{} {:.0} s ({})", f.name, f.horizon_s, chain_label(chain_s)),
                            &v,
                            &s,
                            &f.profile,
                            seeds,
                            &fs,
                        ),
                        f.target_met_s,
                    )
                })
                .collect();
            let (best, best_pred) = at_chain
                .iter()
                .min_by(|a, b| a.0.time.total_cmp(&b.0.time))
                .expect("fixed profiles");
            println!(
                "| {} | best fixed: {} | {} / – | {} [{:.0}, {:.0}] | {}/{} | – | – | {:.2} | {:.2} | {:.2} |",
                s.name,
                best.label,
                fmt_t(best_pred.unwrap_or(f64::INFINITY)),
                fmt_t(best.time),
                best.lo,
                best.hi,
                best.reached,
                seeds,
                cov(best),
                mom(best),
                best.torque_use,
            );
            rows.extend(at_chain);
        }
        eprintln!(
            "{}: shares {:?} (gap {:.1e}); every fixed profile, achieved median: {}",
            s.name,
            pl.design
                .weights
                .iter()
                .zip(&pl.design.atoms)
                .filter(|(w, _)| **w > 0.005)
                .map(|(w, a)| format!("{} {:.0} s: {:.2}", a.set, a.doublet_s, w))
                .collect::<Vec<_>>(),
            pl.design.gap,
            rows.iter()
                .map(|(r, _)| format!("{} {}", r.label, fmt_t(r.time)))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}
