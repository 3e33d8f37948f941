//! End-to-end throughput of the `inertia` binary: recursive estimation over a
//! 1,000,000-sample telemetry file (the `spin` scenario for 100,000 s), a solve at every
//! sample, the estimate history written. Default (physical) constraint set, and the
//! paper's set with the J33 bound.
//!
//! Run: `cargo bench -p inertia-cli --bench throughput`. Peak memory is reported by
//! `/usr/bin/time -f %M target/release/inertia estimate FILE -o OUT` (README).

use criterion::{criterion_group, criterion_main, Criterion};
use std::path::Path;
use std::process::Command;
use std::time::Duration;

fn inertia(args: &[&str]) {
    let ok = Command::new(env!("CARGO_BIN_EXE_inertia"))
        .args(args)
        .output()
        .expect("run inertia")
        .status
        .success();
    assert!(ok, "inertia {args:?} failed");
}

fn throughput(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("million.csv");
    let out = dir.path().join("history.csv");
    let (csv_s, out_s) = (csv.to_str().unwrap(), out.to_str().unwrap());
    inertia(&[
        "simulate",
        "--scenario",
        "spin",
        "--duration",
        "99999.9",
        "-o",
        csv_s,
    ]);
    let rows = std::fs::read_to_string(&csv).unwrap().lines().count() - 1;
    assert_eq!(rows, 1_000_000);
    let mut g = c.benchmark_group("estimate_1M_samples");
    g.sample_size(10).measurement_time(Duration::from_secs(50));
    g.bench_function("physical", |b| {
        b.iter(|| inertia(&["estimate", csv_s, "-o", out_s]))
    });
    g.bench_function("paper_j33_bound", |b| {
        b.iter(|| {
            inertia(&[
                "estimate",
                csv_s,
                "--constraints",
                "paper",
                "--bound",
                "J33=2.7:3.3",
                "-o",
                out_s,
            ])
        })
    });
    g.finish();
    assert!(Path::new(&out).exists());
}

criterion_group!(benches, throughput);
criterion_main!(benches);
