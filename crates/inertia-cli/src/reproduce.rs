//! `inertia reproduce`: the paper's §VI examples on built-in simulated data.
//!
//! Both scenarios at the paper's noise levels; the variational, finite-difference and
//! momentum estimators with the paper's constraint set (the spin case adds J33 within
//! 10 % of 3 kg m² for the SDP-based ones), plus the variational estimator with the
//! default physical set as an extra row. Writes figures 1–10 (PNG, SVG), the data behind
//! each as CSV, every estimate history, and `summary.md`.

use crate::args::ReproduceArgs;
use crate::error::{internal, write_failed, CliError};
use crate::history::HistoryFile;
use crate::plot::{self, Panel, Series, COLORS};
use crate::runner::{paper_estimators, Run};
use inertia::estimator::Estimate;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::SimOutput;
use inertia::tensor::{
    matrix_from_j, normalized_element_errors, relative_frobenius_error, COMPONENT_NAMES,
};
use nalgebra::Matrix3;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// Times at which the summary reports errors, s (the end is added).
const REPORT_TIMES: [f64; 4] = [10.0, 30.0, 60.0, 120.0];

struct Case {
    scenario: Scenario,
    out: SimOutput,
    runs: Vec<Run>,
    constraint_note: &'static str,
}

/// The runs whose 3σ envelopes are drawn: the paper's estimator (first) and the discrete
/// momentum estimator.
fn enveloped(case: &Case) -> impl Iterator<Item = (usize, &Run)> {
    case.runs
        .iter()
        .enumerate()
        .filter(|(n, r)| *n == 0 || r.file == "discrete_momentum")
}

/// The 3σ envelopes for element `k` ([`enveloped`]), normalised like the errors.
fn sigma_series(case: &Case, k: usize, truth: &Matrix3<f64>) -> Vec<Series> {
    let (r, c) = inertia::tensor::COMPONENT_INDEX[k];
    let scale = if r == c {
        truth[(r, r)]
    } else {
        (truth[(r, r)] * truth[(c, c)]).sqrt()
    };
    enveloped(case)
        .map(|(n, run)| Series {
            name: format!("{}: 3σ", run.label),
            points: run
                .history
                .iter()
                .map(|h| {
                    (
                        h.t_s,
                        h.uncertainty
                            .map_or(f64::NAN, |u| 3.0 * u.sigma_kg_m2[k] / scale),
                    )
                })
                .collect(),
            color: COLORS[n % COLORS.len()],
            width: 1,
        })
        .collect()
}

/// One series per estimator run, plotting `metric` of each history row.
fn run_series(case: &Case, metric: impl Fn(&Estimate) -> f64) -> Vec<Series> {
    case.runs
        .iter()
        .zip(COLORS)
        .enumerate()
        .map(|(n, (r, color))| Series {
            name: r.label.into(),
            points: r.history.iter().map(|h| (h.t_s, metric(h))).collect(),
            color,
            width: main_width(n, r),
        })
        .collect()
}

/// The paper's estimator (first) and `estimate`'s default drawn thicker than the others.
fn main_width(n: usize, run: &Run) -> u32 {
    if n == 0 || run.file == "discrete_momentum" {
        3
    } else {
        2
    }
}

/// Relative Frobenius error of a history row (`NaN` without an answer).
pub fn total_error(r: &Estimate, truth: &Matrix3<f64>) -> f64 {
    r.j().map_or(f64::NAN, |j| {
        relative_frobenius_error(&matrix_from_j(&j), truth)
    })
}

/// The row at time `t` (the last at or before it).
fn at(history: &[Estimate], t: f64) -> Option<&Estimate> {
    history.iter().take_while(|r| r.t_s <= t + 1e-9).last()
}

fn write_csv(path: &Path, header: &[String], rows: &[Vec<f64>]) -> Result<(), CliError> {
    let mut w = csv::Writer::from_path(path).map_err(|e| write_failed(path, e))?;
    w.write_record(header).map_err(|e| write_failed(path, e))?;
    for r in rows {
        w.write_record(r.iter().map(|v| {
            if v.is_finite() {
                v.to_string()
            } else {
                String::new()
            }
        }))
        .map_err(|e| write_failed(path, e))?;
    }
    w.flush().map_err(|e| write_failed(path, e))
}

/// Time series figure (signals) plus its CSV.
fn signal_figure(
    dir: &Path,
    stem: &str,
    title: &str,
    y_label: &str,
    prefix: &str,
    data: &[(f64, [f64; 3])],
) -> Result<(), CliError> {
    let series: Vec<Series> = ["x", "y", "z"]
        .iter()
        .enumerate()
        .map(|(i, ax)| Series {
            name: format!("{prefix}_{ax}"),
            points: data.iter().map(|(t, v)| (*t, v[i])).collect(),
            color: COLORS[i],
            width: 2,
        })
        .collect();
    plot::figure(
        &dir.join(stem),
        title,
        "time [s]",
        &[Panel {
            title: String::new(),
            y_label: y_label.into(),
            log_y: false,
            series,
        }],
    )?;
    let header: Vec<String> = ["t", "x", "y", "z"]
        .iter()
        .map(|c| {
            if *c == "t" {
                "t".into()
            } else {
                format!("{prefix}_{c}")
            }
        })
        .collect();
    let rows: Vec<Vec<f64>> = data
        .iter()
        .map(|(t, v)| vec![*t, v[0], v[1], v[2]])
        .collect();
    write_csv(&dir.join(format!("{stem}.csv")), &header, &rows)
}

/// The error figures (total, moments, products) of one case, with their CSVs.
fn error_figures(dir: &Path, case: &Case, first_fig: usize) -> Result<(), CliError> {
    let name = case.scenario.name();
    let truth = &case.out.inertia_kg_m2;
    let what = if name == "slew" {
        "slew maneuvers"
    } else {
        "spinning case"
    };
    // Total error.
    let series = run_series(case, |h| total_error(h, truth));
    // The 3σ envelopes: ‖ΔJ‖_F has variance Σ_diag σ² + 2 Σ_off σ².
    let jt_norm = truth.norm();
    let mut series = series;
    for (n, run) in enveloped(case) {
        series.push(Series {
            name: format!("{}: 3σ", run.label),
            points: run
                .history
                .iter()
                .map(|h| {
                    let v = h
                        .uncertainty
                        .map_or(f64::NAN, |u| u.frobenius_sigma_kg_m2());
                    (h.t_s, 3.0 * v / jt_norm)
                })
                .collect(),
            color: COLORS[n % COLORS.len()],
            width: 1,
        });
    }
    let stem = format!("fig{:02}_{name}_total_error", first_fig);
    plot::figure(
        &dir.join(&stem),
        &format!("Figure {first_fig}. Normalized inertia error, {what}"),
        "time [s]",
        &[Panel::total_error(series)],
    )?;
    let mut header = vec!["t".to_string()];
    header.extend(case.runs.iter().map(|r| r.file.to_string()));
    let rows: Vec<Vec<f64>> = (0..case.out.samples.len())
        .filter_map(|k| {
            let t = case.out.samples[k].t_s;
            let vals: Vec<f64> = case
                .runs
                .iter()
                .map(|r| {
                    r.history
                        .iter()
                        .find(|h| (h.t_s - t).abs() < 1e-9)
                        .map_or(f64::NAN, |h| total_error(h, truth))
                })
                .collect();
            vals.iter().any(|v| v.is_finite()).then(|| {
                let mut row = vec![t];
                row.extend(vals);
                row
            })
        })
        .collect();
    write_csv(&dir.join(format!("{stem}.csv")), &header, &rows)?;

    // Element errors: moments (0..3) and products (3..6).
    for (offset, kind, fig) in [
        (0usize, "moment", first_fig + 1),
        (3, "product", first_fig + 2),
    ] {
        let panels: Vec<Panel> = (offset..offset + 3)
            .map(|k| Panel {
                title: COMPONENT_NAMES[k].into(),
                y_label: if k < 3 {
                    "|ΔJ_ii| / J_ii".into()
                } else {
                    "|ΔJ_ij| / √(J_ii J_jj)".into()
                },
                log_y: true,
                series: {
                    let mut v = run_series(case, |h| {
                        h.j().map_or(f64::NAN, |j| {
                            normalized_element_errors(&matrix_from_j(&j), truth)[k].abs()
                        })
                    });
                    v.extend(sigma_series(case, k, truth));
                    v
                },
            })
            .collect();
        let stem = format!("fig{fig:02}_{name}_{kind}_errors");
        plot::figure(
            &dir.join(&stem),
            &format!("Figure {fig}. Normalized {kind} of inertia errors, {what}"),
            "time [s]",
            &panels,
        )?;
        let mut header = vec!["t".to_string()];
        for r in &case.runs {
            for name in &COMPONENT_NAMES[offset..offset + 3] {
                header.push(format!("{}_{name}", r.file));
            }
        }
        let rows: Vec<Vec<f64>> = case
            .out
            .samples
            .iter()
            .map(|s| {
                let mut row = vec![s.t_s];
                for r in &case.runs {
                    let h = r.history.iter().find(|h| (h.t_s - s.t_s).abs() < 1e-9);
                    for k in offset..offset + 3 {
                        row.push(h.and_then(|h| h.j()).map_or(f64::NAN, |j| {
                            normalized_element_errors(&matrix_from_j(&j), truth)[k]
                        }));
                    }
                }
                row
            })
            .collect();
        write_csv(&dir.join(format!("{stem}.csv")), &header, &rows)?;
    }
    Ok(())
}

fn summary(cases: &[Case], seed: u64, elapsed_s: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Reproduction of the paper's numerical examples (§VI)\n"
    );
    let _ = writeln!(
        s,
        "Simulated telemetry: h = 0.1 s, disturbance torque 1e-8 N m/√Hz, gyro noise 1e-5 deg/s/√Hz, seed {seed}. \
         Error: relative Frobenius norm ‖Ĵ − J‖_F/‖J‖_F. \"n/a\" means the estimator reported that the data do not (yet) determine J.\n"
    );
    for case in cases {
        let truth = &case.out.inertia_kg_m2;
        let end = case.out.samples.last().map_or(0.0, |s| s.t_s);
        let _ = writeln!(
            s,
            "## {} case\n\n{}\n",
            case.scenario.name(),
            case.constraint_note
        );
        let mut head = String::from("| estimator |");
        let mut rule = String::from("|---|");
        for t in REPORT_TIMES.iter().filter(|t| **t < end) {
            let _ = write!(head, " {t:.0} s |");
            rule.push_str("---|");
        }
        let _ = write!(head, " end ({end:.0} s) |");
        rule.push_str("---|");
        let _ = writeln!(s, "{head}\n{rule}");
        for r in &case.runs {
            let mut line = format!("| {} |", r.label);
            for t in REPORT_TIMES.iter().filter(|t| **t < end).chain([&end]) {
                let cell = match at(&r.history, *t) {
                    Some(h) if h.j().is_some() => {
                        let e = total_error(h, truth);
                        if h.observability.code() == "from_prior" {
                            format!("{e:.2e} (prior)")
                        } else {
                            format!("{e:.2e}")
                        }
                    }
                    Some(_) => "n/a".into(),
                    None => "—".into(),
                };
                let _ = write!(line, " {cell} |");
            }
            let _ = writeln!(s, "{line}");
        }
        let _ = writeln!(s, "\nFinal estimates, kg m²:\n");
        let _ = writeln!(s, "| | {} |", COMPONENT_NAMES.join(" | "));
        let _ = writeln!(s, "|---|---|---|---|---|---|---|");
        let jt = inertia::tensor::j_from_matrix(truth);
        let _ = writeln!(
            s,
            "| truth | {} |",
            jt.iter()
                .map(|v| format!("{v:.5}"))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        for r in &case.runs {
            let cells = r.history.last().and_then(|h| h.j()).map_or_else(
                || vec!["n/a".to_string(); 6],
                |j| j.iter().map(|v| format!("{v:.5}")).collect(),
            );
            let _ = writeln!(s, "| {} | {} |", r.label, cells.join(" | "));
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s, "Generated by `inertia reproduce` in {elapsed_s:.1} s.");
    s
}

/// Run the command.
pub fn run(a: &ReproduceArgs) -> Result<(), CliError> {
    let start = Instant::now();
    plot::register_font()?;
    let dir = &a.out;
    std::fs::create_dir_all(dir).map_err(|e| write_failed(dir, e))?;
    let mut cases = Vec::new();
    for scenario in [Scenario::slew(), Scenario::spin()] {
        let common = Common {
            seed: a.seed,
            ..Common::paper()
        };
        let out = scenario.simulate(&common).map_err(internal)?;
        let runs = paper_estimators(&scenario, &out, common.gyro_noise_deg_s_rthz)?;
        let constraint_note = if scenario.name() == "spin" {
            "SDP-based estimators: the paper's constraints (J ⪰ εI, eq. 9) and J33 within 10 % of 3 kg m²; the last row uses the exact physical set (Σ ⪰ 0) with the same bound."
        } else {
            "SDP-based estimators: the paper's constraints (J ⪰ εI, eq. 9); the last row uses the exact physical set (Σ ⪰ 0). No a-priori information."
        };
        cases.push(Case {
            scenario,
            out,
            runs,
            constraint_note,
        });
    }
    for case in &cases {
        let name = case.scenario.name();
        let rho: Vec<(f64, [f64; 3])> = case
            .out
            .samples
            .iter()
            .map(|s| (s.t_s, [s.rho_nms.x, s.rho_nms.y, s.rho_nms.z]))
            .collect();
        let w: Vec<(f64, [f64; 3])> = case
            .out
            .samples
            .iter()
            .filter_map(|s| s.omega_rad_s.map(|w| (s.t_s, [w.x, w.y, w.z])))
            .collect();
        let (rho_fig, w_fig, err_fig) = if name == "slew" { (1, 2, 3) } else { (7, 6, 8) };
        let what = if name == "slew" {
            "during slew maneuvers"
        } else {
            "for spinning case"
        };
        signal_figure(
            dir,
            &format!("fig{rho_fig:02}_{name}_rotor_momentum"),
            &format!("Figure {rho_fig}. Rotor momentum components {what}"),
            "ρ [N m s]",
            "rho",
            &rho,
        )?;
        signal_figure(
            dir,
            &format!("fig{w_fig:02}_{name}_body_rates"),
            &format!("Figure {w_fig}. Body angular velocity components {what}"),
            "ω [rad/s]",
            "w",
            &w,
        )?;
        error_figures(dir, case, err_fig)?;
        for r in &case.runs {
            let path = dir.join(format!("history_{name}_{}.csv", r.file));
            let mut h = HistoryFile::create(&path)?;
            for row in &r.history {
                h.write(row)?;
            }
            h.finish()?;
        }
    }
    let text = summary(&cases, a.seed, start.elapsed().as_secs_f64());
    let path = dir.join("summary.md");
    std::fs::write(&path, &text).map_err(|e| write_failed(&path, e))?;
    println!("{text}");
    eprintln!(
        "wrote figures 1-10 (PNG and SVG), their data (CSV), estimate histories and summary.md to {}/",
        dir.display()
    );
    Ok(())
}
