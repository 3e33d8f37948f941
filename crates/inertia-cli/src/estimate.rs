//! `inertia estimate`.

use crate::args::EstimateArgs;
use crate::config::{self, InertiaFile};
use crate::error::{input, internal, CliError};
use crate::history::HistoryWriter;
use crate::runner::{AnyBackend, EstimatorKind, HistoryRow, Runner};
use inertia::estimator::batch;
use inertia::estimator::excitation::{diagnose, Excitation};
use inertia::estimator::observability::ObservabilitySettings;
use inertia::estimator::rows::{FiniteDifferenceRows, VariationalRows};
use inertia::estimator::EstimatorError;
use inertia::telemetry::csv::{ReadStats, TelemetryReader};
use inertia::tensor::{matrix_from_j, principal, relative_frobenius_error};
use nalgebra::Matrix3;
use serde_json::json;
use std::io::IsTerminal;

/// Run the command.
pub fn run(a: &EstimateArgs) -> Result<(), CliError> {
    let options = config::csv_options(&a.input)?;
    let nominal = match (&a.nominal, &a.tolerance) {
        (Some(p), Some(t)) => Some((InertiaFile::read(p)?, config::parse_fraction(t)?)),
        _ => None,
    };
    let constraints = config::constraints(
        a.constraints,
        &a.bounds,
        nominal.as_ref().map(|(m, p)| (m, *p)),
    )?;
    let truth = a.truth.as_deref().map(InertiaFile::read).transpose()?;
    if a.every == 0 {
        return Err(input("--every 0: must be at least 1"));
    }
    if let Some(g) = a.gyro_noise {
        if !(g.is_finite() && g >= 0.0) {
            return Err(input(format!(
                "--gyro-noise {g}: must be finite and >= 0 deg/s/√Hz"
            )));
        }
    }
    let gyro_rad = a.gyro_noise.map(f64::to_radians);
    if let Some(h) = a.resample {
        if !(h.is_finite() && h > 0.0) {
            return Err(input(format!("--resample {h}: must be finite and > 0 s")));
        }
        if a.batch {
            return Err(input(
                "--resample applies to the recursive estimators, not --batch",
            ));
        }
    }
    if let Some(m) = a.memory {
        if !(m.is_finite() && m > 0.0) {
            return Err(input(format!("--memory {m}: must be finite and > 0 s")));
        }
        if a.batch {
            return Err(input(
                "--memory applies to the recursive estimators, not --batch",
            ));
        }
    }
    if a.batch && a.estimator == EstimatorKind::Momentum {
        return Err(input(
            "--batch applies to the variational and finite-difference estimators; the momentum baseline is recursive only",
        ));
    }
    let mut backend = AnyBackend::new(a.solver).map_err(input)?;
    let mut reader = TelemetryReader::open(&a.file, options).map_err(input)?;
    let file = reader.file().to_string();
    if a.estimator.needs_gyro() && !reader.has_gyro() {
        return Err(input(format!(
            "{file}:1: the {} estimator needs gyro-rate columns w_x,w_y,w_z",
            a.estimator.name()
        )));
    }
    let size = std::fs::metadata(&a.file).map(|m| m.len()).unwrap_or(0);
    let progress = (std::io::stderr().is_terminal() && !a.json && size > 1 << 20).then(|| {
        let p = indicatif::ProgressBar::new(size);
        p.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {bytes}/{total_bytes} {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        p
    });
    let mut history = a.output.as_deref().map(HistoryWriter::create).transpose()?;
    let row_error = |e: EstimatorError, line: u64| match e {
        EstimatorError::Solve(e) => internal(format!("{file}:{line}: {e}")),
        EstimatorError::Row { source, .. } => input(format!("{file}:{line}: {source}")),
        other => input(format!("{file}:{line}: {other}")),
    };

    let mut last: Option<HistoryRow> = None;
    let excitation: Option<Excitation>;
    let mut samples = 0usize;
    let mut h_s = f64::NAN;
    let mut t_prev = f64::NAN;
    if a.batch {
        let mut all = Vec::new();
        for item in reader.by_ref() {
            all.push(item.map_err(input)?);
        }
        samples = all.len();
        if all.len() > 1 {
            h_s = all[1].t_s - all[0].t_s;
        }
        let obs = ObservabilitySettings::default();
        let est = match a.estimator {
            EstimatorKind::Variational => batch::estimate(
                &all,
                VariationalRows::default(),
                &constraints,
                &mut backend,
                &obs,
                gyro_rad,
            ),
            _ => batch::estimate(
                &all,
                FiniteDifferenceRows::default(),
                &constraints,
                &mut backend,
                &obs,
                None,
            ),
        };
        let est = est.map_err(|e| match e {
            EstimatorError::Row { sample, source } => {
                input(format!("{file}: sample {sample}: {source}"))
            }
            EstimatorError::Solve(e) => internal(e),
            other => input(format!("{file}: {other}")),
        })?;
        let row = HistoryRow::from_estimate(&est);
        if let Some(h) = history.as_mut() {
            h.write(&row)?;
        }
        last = Some(row);
        excitation = match a.estimator {
            EstimatorKind::Variational => batch::reduce(&all, VariationalRows::default()).ok(),
            _ => batch::reduce(&all, FiniteDifferenceRows::default()).ok(),
        }
        .map(|q| diagnose(&q));
    } else {
        // The first two samples fix the period, and with it the forgetting factor.
        let mut head = Vec::with_capacity(2);
        for item in reader.by_ref().take(2) {
            head.push(item.map_err(input)?);
        }
        let forgetting = match (a.memory, head.as_slice()) {
            (Some(tau), [s0, s1]) => (-(s1.t_s - s0.t_s) / tau).exp(),
            _ => 1.0,
        };
        let settings = inertia::estimator::recursive::RecursiveSettings {
            solve_every: a.every,
            forgetting,
            gyro_noise_rad_s_rthz: gyro_rad,
            ..Default::default()
        };
        let mut runner =
            Runner::with_settings(a.estimator, constraints, backend, settings).map_err(input)?;
        let mut pending = head.into_iter();
        let mut resampler = a.resample.map(inertia::estimator::resample::Resampler::new);
        let mut ready: Vec<inertia::telemetry::Sample> = Vec::with_capacity(4);
        loop {
            let input_sample = match pending.next() {
                Some(s) => s,
                None => match reader.next() {
                    Some(item) => item.map_err(input)?,
                    None => break,
                },
            };
            ready.clear();
            match resampler.as_mut() {
                Some(r) => r.push(&input_sample, |u| ready.push(u)),
                None => ready.push(input_sample),
            }
            for s in ready.drain(..) {
                samples += 1;
                if samples == 2 {
                    h_s = s.t_s - t_prev;
                }
                t_prev = s.t_s;
                if let Some(row) = runner
                    .push(&s)
                    .map_err(|e| row_error(e, reader.last_line()))?
                {
                    if let Some(h) = history.as_mut() {
                        h.write(&row)?;
                    }
                    last = Some(row);
                }
                if let Some(p) = &progress {
                    if samples.is_multiple_of(4096) {
                        p.set_position(reader.byte_position());
                    }
                }
            }
        }
        excitation = runner.qr().map(diagnose);
    }
    if let Some(p) = progress {
        p.finish_and_clear();
    }
    if let Some(h) = history {
        h.finish()?;
    }
    let stats = reader.stats();
    let Some(last) = last else {
        return Err(input(format!(
            "{file}: too few samples for an estimate ({samples} read; at least {} needed)",
            inertia::estimator::MIN_SAMPLES + 2
        )));
    };
    let report = Report {
        file: &file,
        a,
        stats,
        samples,
        h_s,
        last: &last,
        truth: truth.as_ref(),
        excitation: excitation.as_ref(),
    };
    if a.json {
        println!("{}", report.json());
    } else {
        print!("{}", report.text());
    }
    Ok(())
}

struct Report<'a> {
    file: &'a str,
    a: &'a EstimateArgs,
    stats: ReadStats,
    samples: usize,
    h_s: f64,
    last: &'a HistoryRow,
    truth: Option<&'a Matrix3<f64>>,
    excitation: Option<&'a Excitation>,
}

impl Report<'_> {
    fn inertia(&self) -> Option<Matrix3<f64>> {
        self.last.j.map(|j| matrix_from_j(&j))
    }

    fn json(&self) -> String {
        let m = self.inertia();
        let rows = |m: &Matrix3<f64>| -> Vec<Vec<f64>> {
            (0..3)
                .map(|r| (0..3).map(|c| m[(r, c)]).collect())
                .collect()
        };
        let pr = m.map(|m| principal(&m));
        let v = json!({
            "file": self.file,
            "estimator": self.a.estimator.name(),
            "batch": self.a.batch,
            "samples": self.samples,
            "sample_period_s": self.h_s,
            "renormalised": self.stats.renormalised,
            "sign_flips": self.stats.sign_flips,
            "gaps": self.stats.gaps,
            "min_step_s": self.stats.min_step_s,
            "max_step_s": self.stats.max_step_s,
            "t": self.last.t_s,
            "status": self.last.status.code(),
            "reason": self.last.status.reason(),
            "condition": self.last.condition,
            "inertia": m.as_ref().map(rows),
            "j": self.last.j.map(|j| j.iter().copied().collect::<Vec<_>>()),
            "principal_moments": pr.map(|(v, _)| v.iter().copied().collect::<Vec<_>>()),
            "sigma": self.last.uncertainty.map(|u| u.sigma_kg_m2),
            "principal_moments_sigma": self.last.uncertainty.map(|u| u.principal_sigma_kg_m2),
            "principal_axes": pr.map(|(_, ax)| rows(&ax)),
            "relative_error": match (m, self.truth) {
                (Some(m), Some(t)) => Some(relative_frobenius_error(&m, t)),
                _ => None,
            },
            "excitation": self.excitation.map(|x| json!({
                "singular_values": x.singular_values,
                "element_sigma_kg_m2": x.element_sigma,
                "weakest_direction": x.weakest_direction.iter().copied().collect::<Vec<_>>(),
                "weak_elements": x.weak_elements,
                "advice": x.advice,
            })),
        });
        v.to_string()
    }

    fn text(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let st = &self.stats;
        let steps = if (st.max_step_s - st.min_step_s) <= 1e-9 * st.max_step_s {
            format!("h = {:.6} s", self.h_s)
        } else {
            format!("steps {:.6}–{:.6} s", st.min_step_s, st.max_step_s)
        };
        let _ = writeln!(
            s,
            "{}: {} samples, {steps} ({} renormalised, {} sign flips, {} gaps)",
            self.file, self.samples, st.renormalised, st.sign_flips, st.gaps
        );
        let _ = writeln!(
            s,
            "estimator: {}{}, constraints: {}, t = {} s",
            self.a.estimator.name(),
            if self.a.batch {
                " (batch)"
            } else {
                " (recursive)"
            },
            clap::ValueEnum::to_possible_value(&self.a.constraints)
                .map_or_else(String::new, |v| v.get_name().to_string()),
            self.last.t_s
        );
        let status = match (&self.last.status, self.last.condition) {
            (crate::runner::RowStatus::Determined, Some(c)) => {
                format!("determined by the data (condition number {c:.3e})")
            }
            (crate::runner::RowStatus::FromPrior(r), _) => {
                format!("answer leans on the prior bounds: {r}")
            }
            (crate::runner::RowStatus::NotObservable(r), _) => format!("NOT OBSERVABLE: {r}"),
            (crate::runner::RowStatus::Rls, _) => "recursive least squares (unconstrained)".into(),
            (_, None) => "determined".into(),
        };
        let _ = writeln!(s, "status: {status}");
        match self.inertia() {
            None => {
                let _ = writeln!(s, "no estimate: the data cannot determine J");
            }
            Some(m) => {
                let _ = writeln!(s, "J [kg m²] =");
                for r in 0..3 {
                    let _ = writeln!(
                        s,
                        "  [ {:>12.6} {:>12.6} {:>12.6} ]",
                        m[(r, 0)],
                        m[(r, 1)],
                        m[(r, 2)]
                    );
                }
                if let Some(u) = self.last.uncertainty {
                    let _ = writeln!(s, "elements, ± one standard deviation (noise and discretisation bias) [kg m²]:");
                    let j = self.last.j.unwrap_or_default();
                    for (k, name) in inertia::tensor::COMPONENT_NAMES.iter().enumerate() {
                        let _ = writeln!(s, "  {name} = {:>12.6} ± {:.2e}", j[k], u.sigma_kg_m2[k]);
                    }
                }
                let (pm, ax) = principal(&m);
                match self.last.uncertainty {
                    Some(u) => {
                        let ps = u.principal_sigma_kg_m2;
                        let _ = writeln!(
                            s,
                            "principal moments [kg m²]: {:.6} ± {:.1e}  {:.6} ± {:.1e}  {:.6} ± {:.1e}",
                            pm[0], ps[0], pm[1], ps[1], pm[2], ps[2]
                        );
                    }
                    None => {
                        let _ = writeln!(
                            s,
                            "principal moments [kg m²]: {:.6}  {:.6}  {:.6}",
                            pm[0], pm[1], pm[2]
                        );
                    }
                }
                let _ = writeln!(s, "principal axes (columns, body axes):");
                for r in 0..3 {
                    let _ = writeln!(
                        s,
                        "  [ {:>9.5} {:>9.5} {:>9.5} ]",
                        ax[(r, 0)],
                        ax[(r, 1)],
                        ax[(r, 2)]
                    );
                }
                if let Some(t) = self.truth {
                    let _ = writeln!(
                        s,
                        "relative Frobenius error vs truth: {:.3e}",
                        relative_frobenius_error(&m, t)
                    );
                }
            }
        }
        if let Some(x) = self.excitation {
            let sv = x.singular_values;
            let _ = writeln!(
                s,
                "excitation: singular values of R {}",
                sv.iter()
                    .map(|v| format!("{v:.2e}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            );
            if let Some(sig) = x.element_sigma {
                let _ = writeln!(
                    s,
                    "  1-sigma per element (sensor noise only) [kg m²]: {}",
                    inertia::tensor::COMPONENT_NAMES
                        .iter()
                        .zip(sig)
                        .map(|(n, v)| format!("{n} {v:.1e}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
            for a in &x.advice {
                let _ = writeln!(s, "  warning: {a}");
            }
        }
        s
    }
}
