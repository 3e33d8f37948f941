//! Structured, seeded fuzzing of the estimation path (issue 11): simulated telemetry,
//! corrupted by [`mutate`], through the library's CSV reader and pipeline with random
//! estimators and options ([`case`]).
//!
//! ```sh
//! cargo run --release -p inertia-cli --example fuzz -- --cases 20000 --seed 1 --jobs 2
//! cargo run --release -p inertia-cli --example fuzz -- --seconds 60          # bounded run
//! ```
//!
//! Oracle: no panic (caught), no hang (a case running longer than `--limit-s`, default
//! 5 s, stops the campaign with its file saved), no NaN/inf in any estimate, σ,
//! excitation figure or report, and every error about a line names it. Findings are
//! saved under `--out` (default `target/fuzz-findings`) as the CSV plus its settings; the
//! exit code is 1 when there were any. Case `i` of seed `s` is the same on every run.

mod case;
mod mutate;

use inertia::sim::scenario::{Common, Scenario};
use mutate::{Rng, Table};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

struct Args {
    cases: u64,
    /// First case index (replay one finding: `--from I --cases I+1`).
    from: u64,
    seconds: f64,
    seed: u64,
    jobs: u64,
    limit_s: f64,
    out: PathBuf,
}

fn args() -> Args {
    let mut a = Args {
        cases: u64::MAX,
        from: 0,
        seconds: f64::INFINITY,
        seed: 1,
        jobs: 1,
        limit_s: 5.0,
        out: PathBuf::from("target/fuzz-findings"),
    };
    let v: Vec<String> = std::env::args().skip(1).collect();
    for pair in v.chunks(2) {
        let val = pair.get(1).map_or("", String::as_str);
        let num = || {
            val.parse::<f64>()
                .unwrap_or_else(|_| panic!("{}: not a number", pair[0]))
        };
        match pair[0].as_str() {
            "--cases" => a.cases = num() as u64,
            "--seconds" => a.seconds = num(),
            "--from" => a.from = num() as u64,
            "--seed" => a.seed = num() as u64,
            "--jobs" => a.jobs = (num() as u64).max(1),
            "--limit-s" => a.limit_s = num(),
            "--out" => a.out = PathBuf::from(val),
            other => panic!("unknown option {other}"),
        }
    }
    if a.cases == u64::MAX && a.seconds.is_infinite() {
        a.cases = 1000;
    }
    a
}

/// Clean telemetry: slew and spin, 100–400 samples, with and without gyro columns.
fn corpus() -> Vec<String> {
    let mut out = Vec::new();
    for scenario in [Scenario::slew(), Scenario::spin()] {
        for duration in [10.0, 20.0, 40.0] {
            let run = scenario
                .simulate(&Common {
                    duration_s: Some(duration),
                    ..Common::paper()
                })
                .expect("simulation");
            let mut buf = Vec::new();
            inertia::telemetry::csv::write_samples(&mut buf, &run.samples).expect("write");
            let text = String::from_utf8(buf).expect("utf-8");
            let mut no_gyro = Table::parse(&text);
            no_gyro.header.truncate(11);
            for r in &mut no_gyro.rows {
                r.truncate(11);
            }
            out.push(no_gyro.to_csv());
            out.push(text);
        }
    }
    out
}

/// Case `i`: its file and its plan.
fn make(corpus: &[String], seed: u64, i: u64) -> (String, case::Plan) {
    let mut rng = Rng::new(seed.wrapping_mul(0x1000_0000_01b3) ^ i);
    let base = rng.pick(corpus);
    let mut t = Table::parse(base);
    mutate::mutate(&mut t, &mut rng);
    (t.to_csv(), case::plan(&mut rng))
}

fn save(
    out: &std::path::Path,
    kind: &str,
    seed: u64,
    i: u64,
    csv: &str,
    plan: &case::Plan,
    what: &str,
) {
    let _ = std::fs::create_dir_all(out);
    let stem = out.join(format!("{kind}-s{seed}-c{i}"));
    let _ = std::fs::write(stem.with_extension("csv"), csv);
    let _ = std::fs::write(stem.with_extension("txt"), format!("{what}\n{plan:#?}\n"));
}

/// A worker's running case and since when.
type Slot = Arc<Mutex<Option<(u64, Instant)>>>;

#[derive(Default)]
struct Counts {
    cases: AtomicU64,
    estimates: AtomicU64,
    findings: AtomicU64,
}

fn main() {
    let a = Arc::new(args());
    std::panic::set_hook(Box::new(|_| {}));
    let corpus = Arc::new(corpus());
    let counts = Arc::new(Counts::default());
    let stop = Arc::new(AtomicBool::new(false));
    let start = Instant::now();
    // Per worker: the case running and since when.
    let running: Vec<Slot> = (0..a.jobs).map(|_| Arc::new(Mutex::new(None))).collect();
    let workers: Vec<_> = (0..a.jobs)
        .map(|w| {
            let (a, corpus, counts, stop, slot) = (
                Arc::clone(&a),
                Arc::clone(&corpus),
                Arc::clone(&counts),
                Arc::clone(&stop),
                Arc::clone(&running[w as usize]),
            );
            std::thread::spawn(move || {
                let mut i = a.from + w;
                while i < a.cases && !stop.load(Ordering::Relaxed) {
                    if start.elapsed().as_secs_f64() > a.seconds {
                        break;
                    }
                    let (csv, plan) = make(&corpus, a.seed, i);
                    *slot.lock().unwrap() = Some((i, Instant::now()));
                    let result = catch_unwind(AssertUnwindSafe(|| case::run(&csv, &plan)));
                    *slot.lock().unwrap() = None;
                    counts.cases.fetch_add(1, Ordering::Relaxed);
                    let finding = match result {
                        Ok(Ok(case::Outcome::Estimate)) => {
                            counts.estimates.fetch_add(1, Ordering::Relaxed);
                            None
                        }
                        Ok(Ok(case::Outcome::Refused)) => None,
                        Ok(Err(case::Finding::NonFinite(what))) => Some(("non-finite", what)),
                        Ok(Err(case::Finding::NoLine(what))) => Some(("no-line", what)),
                        Err(p) => {
                            let msg = p
                                .downcast_ref::<String>()
                                .cloned()
                                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                                .unwrap_or_default();
                            Some(("panic", msg))
                        }
                    };
                    if let Some((kind, what)) = finding {
                        counts.findings.fetch_add(1, Ordering::Relaxed);
                        eprintln!(
                            "{kind} at case {i} ({}{}): {what}",
                            plan.settings.estimator,
                            if plan.batch { ", batch" } else { "" }
                        );
                        save(&a.out, kind, a.seed, i, &csv, &plan, &what);
                    }
                    i += a.jobs;
                }
            })
        })
        .collect();
    // Watchdog: a case over the limit is a hang; save it and stop.
    while workers.iter().any(|w| !w.is_finished()) {
        std::thread::sleep(Duration::from_millis(100));
        for slot in &running {
            if let Some((i, since)) = *slot.lock().unwrap() {
                if since.elapsed().as_secs_f64() > a.limit_s {
                    let (csv, plan) = make(&corpus, a.seed, i);
                    save(
                        &a.out,
                        "hang",
                        a.seed,
                        i,
                        &csv,
                        &plan,
                        "over the time limit",
                    );
                    eprintln!(
                        "hang at case {i} ({}): over {} s; saved under {}",
                        plan.settings.estimator,
                        a.limit_s,
                        a.out.display()
                    );
                    stop.store(true, Ordering::Relaxed);
                    summary(&counts, start);
                    std::process::exit(2);
                }
            }
        }
    }
    for w in workers {
        if w.join().is_err() {
            eprintln!("a fuzz worker panicked outside a case (a bug of the fuzzer)");
            std::process::exit(3);
        }
    }
    summary(&counts, start);
    if counts.findings.load(Ordering::Relaxed) > 0 {
        std::process::exit(1);
    }
}

fn summary(c: &Counts, start: Instant) {
    let n = c.cases.load(Ordering::Relaxed);
    let s = start.elapsed().as_secs_f64();
    println!(
        "fuzz: {n} cases in {s:.1} s ({:.0} cases/s), {} with an estimate, {} findings",
        n as f64 / s,
        c.estimates.load(Ordering::Relaxed),
        c.findings.load(Ordering::Relaxed)
    );
}
