//! A gyro at its range limit (`telemetry::gyro_range`, issue #30 item 3): the run's report
//! names the clipped axis and its limit; gyros within range, noisy or noise-free, in the
//! paper's scenarios and the flight-like presets, are not flagged.

use inertia::pipeline::{PipelineSettings, Run};
use inertia::sample::Sample;
use inertia::sim::presets::Preset;
use inertia::sim::scenario::{Common, Scenario};
use inertia::telemetry::csv::ReadStats;

/// The run's warnings of kind `gyro_at_range_limit`, as the report's JSON has them.
fn range_warnings(samples: &[Sample]) -> Vec<String> {
    let config = PipelineSettings::default().validate().expect("settings");
    let mut run = Run::new(config, false).expect("run");
    for s in samples {
        run.push(s, |_| {}).expect("push");
    }
    run.finish(|_| {}).expect("finish");
    let report = run.report("x.csv", &ReadStats::default()).expect("report");
    report
        .warnings
        .iter()
        .filter(|w| w.kind == "gyro_at_range_limit")
        .map(|w| w.message.clone())
        .collect()
}

#[test]
fn a_clipped_gyro_axis_is_named_with_its_limit() {
    let run = Scenario::slew()
        .simulate(&Common {
            duration_s: Some(120.0),
            ..Common::paper()
        })
        .expect("simulation");
    // The axis the slews turn fastest about, clipped at 70 % of its largest rate.
    let peak = |i: usize| {
        run.samples
            .iter()
            .filter_map(|s| s.omega_rad_s)
            .map(|w| w[i].abs())
            .fold(0.0, f64::max)
    };
    let axis = (0..3)
        .max_by(|&a, &b| peak(a).total_cmp(&peak(b)))
        .expect("axis");
    let limit = 0.7 * peak(axis);
    let clipped: Vec<Sample> = run
        .samples
        .iter()
        .map(|s| {
            let mut s = *s;
            if let Some(w) = s.omega_rad_s.as_mut() {
                w[axis] = w[axis].clamp(-limit, limit);
            }
            s
        })
        .collect();
    let warnings = range_warnings(&clipped);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let name = ["x", "y", "z"][axis];
    assert!(
        warnings[0].contains(&format!("gyro's {name} axis")),
        "{}",
        warnings[0]
    );
    assert!(
        warnings[0].contains(&inertia::text::Num(limit).to_string()),
        "{}",
        warnings[0]
    );
    assert!(range_warnings(&run.samples).is_empty());
}

#[test]
fn gyros_within_range_are_not_flagged() {
    for seed in 1..=3 {
        for scenario in [Scenario::slew(), Scenario::spin()] {
            for common in [Common::paper(), Common::noise_free()] {
                let run = scenario
                    .simulate(&Common {
                        seed,
                        duration_s: Some(60.0),
                        ..common
                    })
                    .expect("simulation");
                assert!(range_warnings(&run.samples).is_empty(), "seed {seed}");
            }
        }
        for name in ["small-sat", "microsat"] {
            let mut p = Preset::by_name(name).expect("preset");
            p.common.seed = seed;
            p.common.duration_s = Some(200.0);
            let out = p.simulate().expect("simulation");
            assert!(
                range_warnings(&out.samples).is_empty(),
                "{name} seed {seed}"
            );
        }
        let mut p = Preset::throw();
        p.common.seed = seed;
        let out = p.simulate().expect("simulation");
        assert!(range_warnings(&out.samples).is_empty(), "throw seed {seed}");
    }
}
