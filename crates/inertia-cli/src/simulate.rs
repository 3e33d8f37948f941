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
    let common = Common {
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
    let json = serde_json::to_string_pretty(&InertiaFile::new(&out.inertia_kg_m2))
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
