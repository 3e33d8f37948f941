//! `inertia plan`: the spacecraft file → `inertia::plan` → the command CSV, the predicted
//! σ (CSV) and a figure. All the planning is in the library.

use crate::args::PlanArgs;
use crate::error::{input, write_failed, CliError};
use crate::output::{to_stdout, Pending};
use crate::plot::{figure, register_font, Panel, Series, COLORS};
use inertia::plan::request::{make, Chain, Request};
use inertia::plan::Vehicle;
use inertia::spacecraft::Spacecraft;
use inertia::tensor::COMPONENT_NAMES;
use inertia::text::Num;
use std::io::Write;
use std::path::Path;

/// Run the command.
pub fn run(a: &PlanArgs) -> Result<(), CliError> {
    let file = a.spacecraft.display().to_string();
    let sc = Spacecraft::load(&a.spacecraft).map_err(|e| input(e.to_string()))?;
    let v = Vehicle::from_spacecraft(&sc, &file).map_err(input)?;
    let chain = match a.chain.trim() {
        "auto" => Chain::Choose,
        text => match text.parse::<f64>() {
            Ok(c) if c.is_finite() && c >= 0.0 => Chain::Fixed((c > 0.0).then_some(c)),
            _ => {
                return Err(input(format!(
                    "--chain {text:?}: expected a length in s (finite, >= 0; 0: none) or `auto`"
                )))
            }
        },
    };
    let request = Request {
        target_relative: a.target,
        duration_s: a.duration,
        max_duration_s: a.max_duration,
        chain,
        rehearsals: a.rehearsals,
        disturbance_nm_rthz: a.disturbance,
    };
    let out = make(&v, &request).map_err(input)?;
    let plan = out.plan;
    let rehearsal =
        (out.rehearsals > 0).then_some((out.rehearsal, out.reported_target_met_s, out.rehearsals));
    let names: Vec<String> = v.limits.wheels.iter().map(|w| w.name.clone()).collect();
    let alloc = v.limits.allocation().map_err(input)?;
    let (pending, mut w) = Pending::create(&a.output)?;
    plan.profile
        .write_csv(&mut w, &names, &alloc)
        .map_err(|e| write_failed(&a.output, e))?;
    pending.commit(w)?;
    let pred_path = a.output.with_extension("prediction.csv");
    let (pending, mut w) = Pending::create(&pred_path)?;
    write_prediction(&mut w, &plan.prediction, rehearsal.as_ref().map(|r| &r.0))
        .map_err(|e| write_failed(&pred_path, e))?;
    pending.commit(w)?;
    draw(
        &a.output,
        a.target,
        &plan.prediction,
        rehearsal.as_ref().map(|r| &r.0),
    )?;

    let mut lines: Vec<String> = Vec::new();
    let shares: Vec<String> = plan
        .design
        .weights
        .iter()
        .zip(&plan.design.atoms)
        .filter(|(w, _)| **w > 0.005)
        .map(|(w, m)| format!("{} {} s {:.0} %", m.set, Num(m.doublet_s), w * 100.0))
        .collect();
    lines.push(format!(
        "plan: {} s of wheel torque commands at {} Hz, {} manoeuvre{} ({}); design horizon {} s, A-optimality gap {:.1e}",
        Num(plan.profile.duration_s()),
        Num(1.0 / v.controller_period_s),
        plan.order.len(),
        if plan.order.len() == 1 { "" } else { "s" },
        shares.join(", "),
        Num(plan.horizon_s),
        plan.design.gap,
    ));
    let angle = match v.limits.max_angle_rad {
        Some(_) => format!(", angle {:.2}", plan.limit_use.angle),
        None => String::new(),
    };
    lines.push(format!(
        "limits used (margin {:.2}): wheel torque {:.2}, wheel momentum {:.2}, rate {:.2}{angle}",
        v.limits.margin, plan.limit_use.torque, plan.limit_use.momentum, plan.limit_use.rate
    ));
    let t = |x: Option<f64>| {
        x.map_or("not within the plan".to_string(), |t| {
            format!("{} s", Num(t))
        })
    };
    lines.push(format!(
        "target 3σ_F ≤ {}: information matrix {}",
        Num(a.target),
        // With --duration the plan has no target of its own: when the prediction meets it.
        t(plan
            .target_met_s
            .or_else(|| plan.prediction.time_to(a.target)))
    ));
    if let Some((_, reported, seeds)) = &rehearsal {
        lines.push(format!(
            "rehearsal (estimator on the prior J, median of {seeds} flights): {}",
            t(*reported)
        ));
    }
    let chain_text = |c: Option<f64>| c.map_or("none".to_string(), |c| format!("{} s", Num(c)));
    let chain_flag = out.chain_s.map_or(0.0, |c| c);
    if out.chain_trials.is_empty() {
        lines.push(format!(
            "estimator chain: {}; estimate with --chain {}",
            chain_text(out.chain_s),
            Num(chain_flag)
        ));
    } else {
        let tried: Vec<String> = out
            .chain_trials
            .iter()
            .map(|(c, t_met)| format!("{} → {}", chain_text(*c), t(*t_met)))
            .collect();
        lines.push(format!(
            "estimator chain: {} (rehearsed {}); estimate with --chain {}",
            chain_text(out.chain_s),
            tried.join(", "),
            Num(chain_flag)
        ));
    }
    if let Some(s) = plan.prediction.last() {
        let parts: Vec<String> = COMPONENT_NAMES
            .iter()
            .zip(s)
            .map(|(n, x)| format!("{n} {x:.2e}"))
            .collect();
        lines.push(format!(
            "predicted σ at the end, kg m²: {}",
            parts.join(", ")
        ));
    }
    to_stdout(|w| lines.iter().try_for_each(|l| writeln!(w, "{l}")))?;
    eprintln!(
        "wrote {}, {} and {} (.svg)",
        a.output.display(),
        pred_path.display(),
        a.output.with_extension("png").display()
    );
    Ok(())
}

type Series2 = (Vec<f64>, Vec<f64>);

fn write_prediction(
    w: &mut dyn Write,
    p: &inertia::plan::Prediction,
    rehearsal: Option<&Series2>,
) -> std::io::Result<()> {
    writeln!(
        w,
        "# predicted σ per element (information matrix of the momentum rows), kg m²; \
         rel_sigma: relative Frobenius σ (1σ); rehearsal_rel_sigma: median σ the estimator \
         reported in rehearsal (empty where none)"
    )?;
    writeln!(
        w,
        "t_s,sigma_J11,sigma_J22,sigma_J33,sigma_J12,sigma_J13,sigma_J23,rel_sigma,rehearsal_rel_sigma"
    )?;
    for (k, t) in p.t_s.iter().enumerate() {
        let r = rehearsal.and_then(|(rt, rs)| {
            rt.iter()
                .zip(rs)
                .find(|(x, _)| (**x - t).abs() < 1e-6)
                .map(|(_, s)| *s)
                .filter(|s| s.is_finite())
        });
        let sig: Vec<String> = p.sigma_kg_m2[k]
            .iter()
            .map(|x| Num(*x).to_string())
            .collect();
        writeln!(
            w,
            "{},{},{},{}",
            Num(*t),
            sig.join(","),
            Num(p.relative_sigma[k]),
            r.map(|x| Num(x).to_string()).unwrap_or_default()
        )?;
    }
    Ok(())
}

fn draw(
    output: &Path,
    target: f64,
    p: &inertia::plan::Prediction,
    rehearsal: Option<&Series2>,
) -> Result<(), CliError> {
    register_font()?;
    let finite = |x: f64| if x.is_finite() { x } else { f64::NAN };
    let mut series = vec![Series {
        name: "predicted 3σ_F (information matrix)".into(),
        points: p
            .t_s
            .iter()
            .zip(&p.relative_sigma)
            .map(|(t, s)| (*t, finite(3.0 * s)))
            .collect(),
        color: COLORS[0],
        width: 2,
    }];
    if let Some((t, s)) = rehearsal {
        series.push(Series {
            name: "3σ_F the estimator reports (rehearsal median)".into(),
            points: t
                .iter()
                .zip(s)
                .filter(|(t, _)| **t <= p.t_s.last().copied().unwrap_or(0.0) + 1e-9)
                .map(|(t, s)| (*t, finite(3.0 * s)))
                .collect(),
            color: COLORS[1],
            width: 2,
        });
    }
    let end = p.t_s.last().copied().unwrap_or(1.0);
    series.push(Series {
        name: format!("target {}", Num(target)),
        points: vec![(0.0, target), (end, target)],
        color: COLORS[5],
        width: 1,
    });
    let panel = Panel {
        title: String::new(),
        y_label: "3σ relative Frobenius".into(),
        log_y: true,
        series,
    };
    figure(
        &output.with_extension(""),
        "inertia plan: predicted σ of J over the manoeuvre",
        "time, s",
        &[panel],
    )
}
