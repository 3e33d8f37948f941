//! Gyro-only telemetry (issue #30, "Real-sensor inputs"): a file without quaternion
//! columns but with gyro rates gets its attitude integrated from the rates
//! (`GateOptions::attitude_from_gyro`), says so, and gives the answer of the attitude it
//! lacked.

use inertia::attitude::Quaternion;
use inertia::estimator::Estimate;
use inertia::pipeline::{PipelineSettings, Run};
use inertia::sample::Sample;
use inertia::sim::scenario::{Common, Scenario};
use inertia::telemetry::csv::{write_samples, CsvOptions, TelemetryReader};
use inertia::tensor::relative_frobenius_error;

/// The CSV text of `samples`, without the quaternion columns.
fn without_quaternions(samples: &[Sample]) -> String {
    let mut out = Vec::new();
    write_samples(&mut out, samples).expect("write");
    String::from_utf8(out)
        .expect("utf-8")
        .lines()
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            [&f[..1], &f[5..]].concat().join(",") + "\n"
        })
        .collect()
}

fn read(text: &str) -> (Vec<Sample>, TelemetryReader<&[u8]>) {
    let mut r =
        TelemetryReader::new(text.as_bytes(), "gyro.csv", CsvOptions::default()).expect("header");
    let mut samples = Vec::new();
    for s in r.by_ref() {
        samples.push(s.expect("row"));
    }
    (samples, r)
}

fn estimate(samples: &[Sample]) -> (Estimate, Run) {
    let config = PipelineSettings::default().validate().expect("settings");
    let mut run = Run::new(config, false).expect("run");
    let mut last = None;
    for s in samples {
        run.push(s, |e| last = Some(*e)).expect("push");
    }
    run.finish(|e| last = Some(*e)).expect("finish");
    (last.expect("estimate"), run)
}

/// Problem: the paper's slew (300 s, 10 Hz, its gyro), written without quaternions.
/// Reference: the simulated attitude, seen from the first sample's body frame, and the
/// answer from the file with quaternions. The integrated attitude within 1e-4 rad of the
/// true one throughout (the gyro's random walk over 300 s is about 1e-5 rad); the answer
/// within 2σ of the quaternions' answer, both within 3σ of the truth; the report says
/// where the attitude came from.
#[test]
fn the_attitude_integrated_from_the_gyro_gives_the_attitudes_answer() {
    let out = Scenario::slew().simulate(&Common::physical()).expect("sim");
    let text = without_quaternions(&out.samples);
    assert!(text.starts_with("t,rho_x,"), "{}", &text[..40]);
    let (samples, reader) = read(&text);
    assert!(reader.stats().attitude_from_gyro);
    let q0 = out.samples[0].q.conjugate();
    let worst = samples
        .iter()
        .zip(&out.samples)
        .map(|(g, t)| q0.mul(&t.q).conjugate().mul(&g.q).angle())
        .fold(0.0, f64::max);
    assert!(worst < 1e-4, "attitude off by {worst} rad");
    assert_eq!(samples[0].q, Quaternion::IDENTITY);
    let (gyro, run) = estimate(&samples);
    let (quaternions, _) = estimate(&out.samples);
    let truth = out.inertia_kg_m2;
    assert_eq!(gyro.within_3sigma(&truth), Some(true));
    assert_eq!(quaternions.within_3sigma(&truth), Some(true));
    let (a, b, s) = (
        gyro.j().expect("j"),
        quaternions.j().expect("j"),
        gyro.sigma_kg_m2().expect("σ"),
    );
    for k in 0..6 {
        assert!(
            (a[k] - b[k]).abs() < 2.0 * s[k],
            "J[{k}]: {} vs {}",
            a[k],
            b[k]
        );
    }
    assert!(relative_frobenius_error(&gyro.inertia().expect("J"), &truth) < 1e-4);
    let report = run.report("gyro.csv", &reader.stats()).expect("report");
    let text = report.text(|_| None, "option").to_string();
    assert!(
        text.contains("attitude: integrated from the gyro rates"),
        "{text}"
    );
}

/// API misuse: without quaternions, a row without gyro rates has no attitude: refused,
/// naming the gyro columns; and a file with some quaternion columns but not all is the
/// missing column's error, not a silent integration.
#[test]
fn without_quaternions_every_row_needs_its_rates() {
    let out = Scenario::slew()
        .simulate(&Common {
            duration_s: Some(5.0),
            ..Common::physical()
        })
        .expect("sim");
    let text = without_quaternions(&out.samples);
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let f: Vec<String> = lines[10].split(',').map(String::from).collect();
    let n = f.len();
    lines[10] = [&f[..n - 3], &[String::new(), String::new(), String::new()]]
        .concat()
        .join(",");
    let broken = lines.join("\n") + "\n";
    let mut r =
        TelemetryReader::new(broken.as_bytes(), "gyro.csv", CsvOptions::default()).expect("header");
    let e = r
        .by_ref()
        .find_map(Result::err)
        .expect("an error")
        .to_string();
    assert!(
        e.starts_with("gyro.csv:11: column `w_x`: no attitude"),
        "{e}"
    );
    let mut full = Vec::new();
    write_samples(&mut full, &out.samples).expect("write");
    let partial = String::from_utf8(full)
        .expect("utf-8")
        .replacen("q_w", "qw", 1);
    let e = TelemetryReader::new(partial.as_bytes(), "gyro.csv", CsvOptions::default())
        .err()
        .expect("refused")
        .to_string();
    assert!(e.contains("missing column `q_w`"), "{e}");
    // Quaternions under other names, or a quaternion convention given: not gyro-only,
    // the missing column is named.
    let renamed = text.replacen("t,", "t,qx,qy,qz,qw,", 1);
    let e = TelemetryReader::new(renamed.as_bytes(), "gyro.csv", CsvOptions::default())
        .err()
        .expect("refused")
        .to_string();
    assert!(e.contains("missing column `q_x`"), "{e}");
    let jpl = CsvOptions {
        quaternion: inertia::telemetry::csv::QuaternionFormat::Jpl,
        ..CsvOptions::default()
    };
    let e = TelemetryReader::new(text.as_bytes(), "gyro.csv", jpl)
        .err()
        .expect("refused")
        .to_string();
    assert!(e.contains("missing column `q_x`"), "{e}");
}
