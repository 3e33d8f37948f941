//! `inertia simulate`.

use crate::args::{ScenarioArg, SimulateArgs};
use crate::config::InertiaFile;
use crate::error::{input, write_failed, CliError};
use inertia::sim::scenario::{Common, Scenario};
use inertia::telemetry::csv::write_samples;
use std::path::{Path, PathBuf};

/// The truth file next to a telemetry file: `X.csv` → `X.truth.json`.
pub fn truth_path(csv: &Path) -> PathBuf {
    csv.with_extension("truth.json")
}

/// The scenario for an argument.
pub fn scenario(s: ScenarioArg) -> Scenario {
    match s {
        ScenarioArg::Slew => Scenario::slew(),
        ScenarioArg::Spin => Scenario::spin(),
    }
}

/// Run the command.
pub fn run(a: &SimulateArgs) -> Result<(), CliError> {
    let sc = scenario(a.scenario);
    if let Some(d) = a.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(input(format!("--duration {d}: must be finite and > 0")));
        }
    }
    if !(a.dt.is_finite() && a.dt > 0.0) {
        return Err(input(format!("--dt {}: must be finite and > 0", a.dt)));
    }
    let numbers = |flag: &str, s: &str, n: usize| -> Result<Vec<f64>, CliError> {
        let v: Vec<f64> = s
            .split(':')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                input(format!(
                    "{flag} {s:?}: expected {n} numbers separated by ':'"
                ))
            })?;
        if v.len() != n || !v.iter().all(|x| x.is_finite()) {
            return Err(input(format!(
                "{flag} {s:?}: expected {n} finite numbers separated by ':'"
            )));
        }
        Ok(v)
    };
    let j0 = inertia::tensor::paper_j_true();
    let inertia_change = match (&a.inertia_step, &a.inertia_ramp) {
        (Some(s), _) => {
            let v = numbers("--inertia-step", s, 2)?;
            Some(inertia::sim::InertiaChange::Step {
                at_s: v[0],
                to_kg_m2: j0 * v[1],
            })
        }
        (None, Some(s)) => {
            let v = numbers("--inertia-ramp", s, 3)?;
            if !(v[1] > v[0]) {
                return Err(input(format!("--inertia-ramp {s:?}: T1 must be after T0")));
            }
            Some(inertia::sim::InertiaChange::Ramp {
                start_s: v[0],
                end_s: v[1],
                to_kg_m2: j0 * v[2],
            })
        }
        (None, None) => None,
    };
    let common = Common {
        inertia_change,
        dt_s: a.dt,
        duration_s: a.duration,
        // Keep the integrator's substep near 5 ms whatever the sample period.
        substeps: ((a.dt / 0.005).round() as usize).max(1),
        disturbance_nm_rthz: a.disturbance,
        gyro_noise_deg_s_rthz: a.gyro_noise,
        seed: a.seed,
        ..Common::paper()
    };
    let out = sc.simulate(&common).map_err(input)?;
    let file = std::fs::File::create(&a.output).map_err(|e| write_failed(&a.output, e))?;
    write_samples(std::io::BufWriter::new(file), &out.samples)
        .map_err(|e| write_failed(&a.output, e))?;
    let truth = truth_path(&a.output);
    // The truth file holds the inertia at the end of the run (after any change).
    let t_end = out.samples.last().map_or(0.0, |s| s.t_s);
    let json = serde_json::to_string_pretty(&InertiaFile::new(&out.inertia_at(t_end)))
        .map_err(crate::error::internal)?;
    std::fs::write(&truth, json + "\n").map_err(|e| write_failed(&truth, e))?;
    eprintln!(
        "wrote {} ({} samples, {} scenario, h = {} s) and {}",
        a.output.display(),
        out.samples.len(),
        sc.name(),
        a.dt,
        truth.display()
    );
    Ok(())
}
