//! `inertia monte-carlo`: error statistics over many seeds.
//!
//! Run i simulates the scenario with seed `SEED + i` and runs the paper's estimators
//! ([`crate::runner::paper_estimators`]). Runs execute in parallel (rayon) and are
//! collected in run order, so every output is identical whatever the thread count. At each
//! sample time the relative Frobenius errors of the runs that gave an answer are reduced
//! to their 5/50/95 % percentiles (linear interpolation); the fraction of runs with an
//! answer is written beside them.

use crate::args::MonteCarloArgs;
use crate::error::{input, write_failed, CliError};
use crate::plot::{self, Panel, Series, COLORS};
use crate::reproduce::total_error;
use crate::runner::{paper_estimators, PAPER_ESTIMATOR_NAMES};
use crate::simulate::scenario;
use inertia::sim::scenario::Common;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::io::IsTerminal;

/// Percentile `p` (0–1) of sorted finite values, linear interpolation.
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let x = p * (sorted.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x - x.floor());
    if i + 1 < sorted.len() {
        sorted[i] * (1.0 - f) + sorted[i + 1] * f
    } else {
        sorted[i]
    }
}

/// One run: per estimator, the error at each sample (NaN without an answer).
type RunErrors = Vec<Vec<f64>>;

/// Run the command.
pub fn run(a: &MonteCarloArgs) -> Result<(), CliError> {
    if a.runs == 0 {
        return Err(input("--runs 0: must be at least 1"));
    }
    for (name, v) in [
        ("--gyro-noise", a.gyro_noise),
        ("--disturbance", a.disturbance),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(input(format!("{name} {v}: must be finite and >= 0")));
        }
    }
    if let Some(d) = a.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(input(format!("--duration {d}: must be finite and > 0")));
        }
    }
    plot::register_font()?;
    std::fs::create_dir_all(&a.out).map_err(|e| write_failed(&a.out, e))?;
    let sc = scenario(a.scenario);
    let common = |seed: u64| Common {
        seed,
        duration_s: a.duration,
        gyro_noise_deg_s_rthz: a.gyro_noise,
        disturbance_nm_rthz: a.disturbance,
        ..Common::paper()
    };
    let progress = std::io::stderr().is_terminal().then(|| {
        let p = indicatif::ProgressBar::new(a.runs);
        p.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        p
    });
    let results: Vec<Result<RunErrors, CliError>> = (0..a.runs)
        .into_par_iter()
        .map(|i| {
            let out = sc
                .simulate(&common(a.seed.wrapping_add(i)))
                .map_err(input)?;
            let runs = paper_estimators(&sc, &out, a.gyro_noise)?;
            let errors = runs
                .iter()
                .map(|r| {
                    let mut e = vec![f64::NAN; out.samples.len()];
                    let mut k = 0;
                    for h in &r.history {
                        while k < out.samples.len() && out.samples[k].t_s < h.t_s - 1e-9 {
                            k += 1;
                        }
                        if k < out.samples.len() {
                            e[k] = total_error(h, &out.inertia_kg_m2);
                        }
                    }
                    e
                })
                .collect();
            if let Some(p) = &progress {
                p.inc(1);
            }
            Ok(errors)
        })
        .collect();
    if let Some(p) = progress {
        p.finish_and_clear();
    }
    let runs: Vec<RunErrors> = results.into_iter().collect::<Result<_, _>>()?;
    // Labels from the plan; the time grid from the configuration (as the simulator
    // computes it), with no extra run.
    let labels: Vec<&str> = PAPER_ESTIMATOR_NAMES.iter().map(|n| n.0).collect();
    let files: Vec<&str> = PAPER_ESTIMATOR_NAMES.iter().map(|n| n.1).collect();
    let cfg = sc.config(&common(a.seed));
    let times: Vec<f64> = (0..cfg.samples)
        .map(|k| cfg.t0_s + k as f64 * cfg.dt_s)
        .collect();
    let n_est = labels.len();
    let n_t = times.len();
    // Percentiles at each time.
    let mut stats = vec![vec![[f64::NAN; 4]; n_t]; n_est]; // p5, p50, p95, answered
    let mut column = Vec::with_capacity(runs.len());
    for (e, st) in stats.iter_mut().enumerate() {
        for (k, cell) in st.iter_mut().enumerate() {
            column.clear();
            column.extend(runs.iter().map(|r| r[e][k]).filter(|v| v.is_finite()));
            column.sort_by(f64::total_cmp);
            *cell = [
                percentile(&column, 0.05),
                percentile(&column, 0.50),
                percentile(&column, 0.95),
                column.len() as f64 / runs.len() as f64,
            ];
        }
    }
    let name = sc.name();
    // CSV of percentiles.
    let path = a.out.join(format!("{name}_error_percentiles.csv"));
    let mut w = csv::Writer::from_path(&path).map_err(|e| write_failed(&path, e))?;
    let mut header = vec!["t".to_string()];
    for f in &files {
        for s in ["p5", "p50", "p95", "answered"] {
            header.push(format!("{f}_{s}"));
        }
    }
    w.write_record(&header)
        .map_err(|e| write_failed(&path, e))?;
    for (k, t) in times.iter().enumerate() {
        let mut rec = vec![t.to_string()];
        for st in &stats {
            rec.extend(st[k].iter().map(|v| {
                if v.is_finite() {
                    v.to_string()
                } else {
                    String::new()
                }
            }));
        }
        w.write_record(&rec).map_err(|e| write_failed(&path, e))?;
    }
    w.flush().map_err(|e| write_failed(&path, e))?;
    // Final errors per run.
    let path = a.out.join(format!("{name}_final_errors.csv"));
    let mut w = csv::Writer::from_path(&path).map_err(|e| write_failed(&path, e))?;
    let mut header = vec!["run".to_string(), "seed".to_string()];
    header.extend(files.iter().map(|f| f.to_string()));
    w.write_record(&header)
        .map_err(|e| write_failed(&path, e))?;
    for (i, r) in runs.iter().enumerate() {
        let mut rec = vec![i.to_string(), a.seed.wrapping_add(i as u64).to_string()];
        rec.extend(r.iter().map(|e| e[n_t - 1].to_string()));
        w.write_record(&rec).map_err(|e| write_failed(&path, e))?;
    }
    w.flush().map_err(|e| write_failed(&path, e))?;
    // Figure: medians thick, 5 % and 95 % thin.
    let mut series = Vec::new();
    for (e, (label, color)) in labels.iter().zip(COLORS).enumerate() {
        for (q, width, lab) in [
            (1, 3, label.to_string()),
            (0, 1, String::new()),
            (2, 1, String::new()),
        ] {
            series.push(Series {
                name: lab,
                points: times
                    .iter()
                    .zip(&stats[e])
                    .map(|(t, s)| (*t, s[q]))
                    .collect(),
                color,
                width,
            });
        }
    }
    plot::figure(
        &a.out.join(format!("{name}_error_percentiles")),
        &format!(
            "{name}: error over {} runs (median thick, 5 % and 95 % thin), gyro {:e} deg/s/√Hz",
            runs.len(),
            a.gyro_noise
        ),
        "time [s]",
        &[Panel::total_error(series)],
    )?;
    // Summary.
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Monte Carlo: {name}, {} runs (seeds {}–{}), gyro {:e} deg/s/√Hz, disturbance {:e} N m/√Hz\n",
        runs.len(),
        a.seed,
        a.seed.wrapping_add(a.runs - 1),
        a.gyro_noise,
        a.disturbance
    );
    let _ = writeln!(
        s,
        "Final relative Frobenius error (t = {} s):\n",
        times[n_t - 1]
    );
    let _ = writeln!(
        s,
        "| estimator | 5 % | median | 95 % | runs with an answer |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|");
    for (label, st) in labels.iter().zip(&stats) {
        let f = st[n_t - 1];
        let _ = writeln!(
            s,
            "| {label} | {:.2e} | {:.2e} | {:.2e} | {:.0} % |",
            f[0],
            f[1],
            f[2],
            100.0 * f[3]
        );
    }
    let path = a.out.join(format!("{name}_summary.md"));
    std::fs::write(&path, &s).map_err(|e| write_failed(&path, e))?;
    print!("{s}");
    eprintln!(
        "wrote percentiles (CSV, PNG, SVG), final errors and a summary to {}/",
        a.out.display()
    );
    Ok(())
}
