//! Runs through a spacecraft file's wheels, and the medians the rotor tests compare.

use inertia::estimator::Estimate;
use inertia::pipeline::{PipelineSettings, Run};
use inertia::sample::Sample;
use inertia::spacecraft::Spacecraft;

/// The batch answer of `samples` with `sc`'s four rotors (`speeds`: four per sample),
/// their parameters calibrated with J or not, and the run.
pub fn batch_with_wheels(
    samples: &[Sample],
    speeds: &[f64],
    sc: Spacecraft,
    calibrate: bool,
) -> (Estimate, Run) {
    let config = PipelineSettings {
        calibrate_rotors: calibrate,
        ..PipelineSettings::default()
    }
    .validate()
    .expect("settings");
    let mut r = Run::new(config, true).expect("run").with_spacecraft(sc);
    let mut last = None;
    for (k, s) in samples.iter().enumerate() {
        r.push_with_speeds(s, &speeds[4 * k..4 * k + 4], |e| last = Some(*e))
            .expect("push");
    }
    r.finish(|e| last = Some(*e)).expect("finish");
    (last.expect("an estimate"), r)
}

/// The median (the upper one of an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
