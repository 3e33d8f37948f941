//! Monte Carlo of the spacecraft file's rotor spin-inertia σ (book, "Status and
//! uncertainty", "What you tell the run: the spacecraft file").
//!
//! ```sh
//! cargo run --release -p inertia-cli --example rotor_inertia -- 50   # seeds per cell
//! ```
//!
//! **Data.** The paper's slew (`Scenario::slew()`, `Common::physical()`: physical truth,
//! the paper's sensors, 300 s at 10 Hz) and the small-sat preset (`Preset::small_sat()`,
//! MEMS gyro and star tracker through an MEKF, 600 s of slews), their rotor momentum carried
//! by a four-wheel pyramid (axes 35.26° from body z, true spin inertias 1.5, 1.6, 1.7,
//! 1.8 g m², speeds in rpm, `sim::rotors`).
//!
//! **What is stated.** Spin inertias drawn off the truth by relative errors of σ `s`
//! (1 %, 2 % or 5 %): one error for all (`shared`) or one per wheel (`independent`), and
//! the file says so with that σ; and/or each wheel's true axis tilted from the file's by
//! two angles of σ 0.1° or 0.5°, the file stating that σ. The draws are seeded by the
//! run's seed.
//!
//! **Columns.** Median relative Frobenius error; "3σ cov.": the fraction of runs with
//! every element within ±3σ, with the σ stated and with the same wrong inertias stated
//! exact (the σ of before the spacecraft file); "determined beyond 3σ": the fraction of
//! runs whose answer is `Determined` and outside ±3σ in some element; "withheld": no
//! answer.

use inertia::estimator::observability::Observability;
use inertia::estimator::Estimate;
use inertia::pipeline::{PipelineSettings, Run};
use inertia::sample::Sample;
use inertia::sim::presets::Preset;
use inertia::sim::rotors::{drawn_pyramid, stated_exact};
use inertia::sim::scenario::{Common, Scenario};
use inertia::spacecraft::{RotorErrors, Spacecraft};
use inertia::tensor::relative_frobenius_error;
use nalgebra::Matrix3;
use rand::SeedableRng;
use rayon::prelude::*;

const TRUE_J: [f64; 4] = [1.5e-3, 1.6e-3, 1.7e-3, 1.8e-3];

fn run(samples: &[Sample], speeds: &[f64], sc: Spacecraft) -> Option<Estimate> {
    let config = PipelineSettings::default().validate().ok()?;
    let mut r = Run::new(config, false).ok()?.with_spacecraft(sc);
    let mut last = None;
    for (k, s) in samples.iter().enumerate() {
        r.push_with_speeds(s, &speeds[4 * k..4 * k + 4], |e| last = Some(*e))
            .ok()?;
    }
    r.finish(|e| last = Some(*e)).ok()?;
    last
}

/// (error, within 3σ, determined beyond 3σ, withheld) of one answer.
type Judged = (f64, bool, bool, bool);

/// One seed's answers: with the σ stated, and stated exact.
type Pair = (Judged, Judged);

fn judge(e: Option<Estimate>, truth: &Matrix3<f64>) -> Judged {
    let Some(e) = e else {
        return (f64::NAN, false, false, true);
    };
    let Some(m) = e.inertia() else {
        return (f64::NAN, false, false, true);
    };
    let within = e.within_3sigma(truth) == Some(true);
    let determined = matches!(e.observability, Observability::Determined { .. });
    (
        relative_frobenius_error(&m, truth),
        within,
        determined && !within,
        false,
    )
}

fn median(mut v: Vec<f64>) -> f64 {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// One row: spin-inertia errors (how related, relative σ) and axis tilt σ, deg.
struct Case {
    errors: RotorErrors,
    inertia_sigma: f64,
    tilt_sigma_deg: f64,
}

impl Case {
    fn label(&self) -> String {
        let errors = match self.errors {
            RotorErrors::Shared => "shared",
            RotorErrors::Independent => "independent",
        };
        match (self.inertia_sigma > 0.0, self.tilt_sigma_deg > 0.0) {
            (true, false) => format!(
                "spin inertia, {errors} | {:.0} %",
                self.inertia_sigma * 100.0
            ),
            (false, true) => format!("axis tilt | {} deg", self.tilt_sigma_deg),
            _ => format!(
                "spin inertia, {errors}, and axis tilt | {:.0} %, {} deg",
                self.inertia_sigma * 100.0,
                self.tilt_sigma_deg
            ),
        }
    }

    /// The stated file (inertias drawn off the truth by their σ, nominal axes), and the
    /// true wheels (true inertias, axes tilted by draws of the tilt σ), for one seed.
    fn draw(&self, seed: u64, sigma_stated: bool) -> (Spacecraft, Spacecraft) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1000 + seed);
        let (truth, stated) = drawn_pyramid(
            TRUE_J,
            self.inertia_sigma,
            self.errors,
            self.tilt_sigma_deg,
            &mut rng,
        );
        let stated = if sigma_stated {
            stated
        } else {
            stated_exact(&stated)
        };
        (stated, truth)
    }
}

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(50);
    let start = std::time::Instant::now();
    let cases = [
        Case {
            errors: RotorErrors::Shared,
            inertia_sigma: 0.01,
            tilt_sigma_deg: 0.0,
        },
        Case {
            errors: RotorErrors::Shared,
            inertia_sigma: 0.05,
            tilt_sigma_deg: 0.0,
        },
        Case {
            errors: RotorErrors::Independent,
            inertia_sigma: 0.01,
            tilt_sigma_deg: 0.0,
        },
        Case {
            errors: RotorErrors::Independent,
            inertia_sigma: 0.05,
            tilt_sigma_deg: 0.0,
        },
        Case {
            errors: RotorErrors::Shared,
            inertia_sigma: 0.0,
            tilt_sigma_deg: 0.1,
        },
        Case {
            errors: RotorErrors::Shared,
            inertia_sigma: 0.0,
            tilt_sigma_deg: 0.5,
        },
        Case {
            errors: RotorErrors::Independent,
            inertia_sigma: 0.02,
            tilt_sigma_deg: 0.5,
        },
    ];
    println!("| data | errors | σ stated | median error | 3σ cov. | determined beyond 3σ | stated exact: 3σ cov. | determined beyond 3σ | withheld |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for data in ["slew", "small-sat"] {
        for case in &cases {
            let rows: Vec<_> = (1..=seeds)
                .into_par_iter()
                .map(|seed| {
                    let out = match data {
                        "slew" => Scenario::slew().simulate(&Common {
                            seed,
                            ..Common::physical()
                        }),
                        _ => {
                            let mut p = Preset::small_sat();
                            p.common.seed = seed;
                            p.simulate()
                        }
                    }
                    .expect("sim");
                    let truth = out.inertia_kg_m2;
                    let (stated, true_wheels) = case.draw(seed, true);
                    let (exact, _) = case.draw(seed, false);
                    let speeds =
                        inertia::sim::rotors::speeds(&out.samples, &true_wheels).expect("speeds");
                    let with = judge(run(&out.samples, &speeds, stated), &truth);
                    let exact = judge(run(&out.samples, &speeds, exact), &truth);
                    (with, exact)
                })
                .collect();
            let n = rows.len() as f64;
            let frac = |f: &dyn Fn(&Pair) -> bool| rows.iter().filter(|r| f(r)).count() as f64 / n;
            println!(
                "| {data} | {} | {:.2e} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
                case.label(),
                median(rows.iter().map(|r| r.0 .0).collect()),
                frac(&|r| r.0 .1),
                frac(&|r| r.0 .2),
                frac(&|r| r.1 .1),
                frac(&|r| r.1 .2),
                frac(&|r| r.1 .3),
            );
        }
    }
    eprintln!(
        "{seeds} seeds per cell: {:.0} s",
        start.elapsed().as_secs_f64()
    );
}
