//! End-to-end tests of the `inertia` binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn inertia(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_inertia"))
        .args(args)
        .output()
        .expect("run inertia")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Simulate `scenario` for `duration` s into `dir/name.csv`.
fn simulate(dir: &Path, name: &str, scenario: &str, duration: &str) -> PathBuf {
    let path = dir.join(format!("{name}.csv"));
    let o = inertia(&[
        "simulate",
        "--scenario",
        scenario,
        "--duration",
        duration,
        "-o",
        path.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    path
}

fn json(o: &Output) -> serde_json::Value {
    serde_json::from_str(stdout(o).trim()).unwrap_or_else(|e| panic!("{e}: {}", stdout(o)))
}

#[test]
fn simulate_then_estimate_recovers_j_true() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "slew", "slew", "150");
    let truth = dir.path().join("slew.truth.json");
    assert!(truth.exists());
    for est in ["variational", "finite-difference", "momentum"] {
        let o = inertia(&[
            "estimate",
            csv.to_str().unwrap(),
            "--estimator",
            est,
            "--truth",
            truth.to_str().unwrap(),
            "--json",
        ]);
        assert!(o.status.success(), "{est}: {}", stderr(&o));
        let v = json(&o);
        let err = v["relative_error"].as_f64().unwrap();
        assert!(err < 1e-3, "{est}: {err}");
        assert_eq!(v["samples"], 1501);
        assert_eq!(v["j"].as_array().unwrap().len(), 6);
        assert_eq!(v["principal_moments"].as_array().unwrap().len(), 3);
    }
    // The readable report (J ⪰ εI: the paper's J lies just outside Σ ⪰ 0).
    let o = inertia(&[
        "estimate",
        csv.to_str().unwrap(),
        "--truth",
        truth.to_str().unwrap(),
        "--constraints",
        "positive-definite",
    ]);
    let text = stdout(&o);
    assert!(text.contains("J [kg m²] ="), "{text}");
    assert!(text.contains("principal moments"));
    assert!(text.contains("status: determined"), "{text}");
    // With the default physical set the default estimator is precise enough to see that
    // the paper's J is not physically consistent, and says so instead of "determined".
    let conflict = stdout(&inertia(&["estimate", csv.to_str().unwrap()]));
    assert!(
        conflict.contains("the data contradict the constraint set"),
        "{conflict}"
    );
    assert!(text.contains("relative Frobenius error vs truth"));
    // Batch agrees with recursive.
    let o = inertia(&["estimate", csv.to_str().unwrap(), "--batch", "--json"]);
    let b = json(&o);
    let o = inertia(&["estimate", csv.to_str().unwrap(), "--json"]);
    let r = json(&o);
    for k in 0..6 {
        let (x, y) = (b["j"][k].as_f64().unwrap(), r["j"][k].as_f64().unwrap());
        assert!((x - y).abs() < 1e-6 * (1.0 + y.abs()), "{k}: {x} vs {y}");
    }
}

#[test]
fn json_matches_the_last_history_row() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "spin", "spin", "60");
    let hist = dir.path().join("h.csv");
    let o = inertia(&[
        "estimate",
        csv.to_str().unwrap(),
        "--constraints",
        "paper",
        "--bound",
        "J33=2.7:3.3",
        "--every",
        "10",
        "-o",
        hist.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    let mut r = csv::Reader::from_path(&hist).unwrap();
    let header = r.headers().unwrap().clone();
    assert_eq!(
        &header.iter().take(8).collect::<Vec<_>>(),
        &["t", "J11", "J22", "J33", "J12", "J13", "J23", "status"]
    );
    let rows: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
    assert!(rows.len() > 50, "{} rows", rows.len());
    let last = rows.last().unwrap();
    assert_eq!(last[0].parse::<f64>().unwrap(), v["t"].as_f64().unwrap());
    for k in 0..6 {
        assert_eq!(
            last[k + 1].parse::<f64>().unwrap(),
            v["j"][k].as_f64().unwrap()
        );
    }
    assert_eq!(&last[7], v["status"].as_str().unwrap());
    // Standard deviations: in the history (sJ11..sJ23) and the JSON, the same numbers.
    let sj = header.iter().position(|h| h == "sJ11").unwrap();
    for k in 0..6 {
        let s_hist: f64 = last[sj + k].parse().unwrap();
        assert_eq!(s_hist, v["sigma"][k].as_f64().unwrap());
        assert!(s_hist > 0.0 && s_hist < 0.05, "{s_hist}");
    }
    assert_eq!(v["principal_moments_sigma"].as_array().unwrap().len(), 3);
    // Before the pulse the answers lean on the bound, and say so.
    assert!(rows.iter().any(|r| &r[7] == "from_prior"));
}

#[test]
fn reproduce_writes_every_figure_and_table() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("results");
    let o = inertia(&["reproduce", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    for stem in [
        "fig01_slew_rotor_momentum",
        "fig02_slew_body_rates",
        "fig03_slew_total_error",
        "fig04_slew_moment_errors",
        "fig05_slew_product_errors",
        "fig06_spin_body_rates",
        "fig07_spin_rotor_momentum",
        "fig08_spin_total_error",
        "fig09_spin_moment_errors",
        "fig10_spin_product_errors",
    ] {
        for ext in ["png", "svg", "csv"] {
            let p = out.join(format!("{stem}.{ext}"));
            let len = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
            assert!(len > 1000, "{} missing or tiny ({len} bytes)", p.display());
        }
        let png = std::fs::read(out.join(format!("{stem}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    }
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    for needle in [
        "## slew case",
        "## spin case",
        "| variational |",
        "| momentum |",
        "| finite difference |",
        "variational, physical set",
        "Final estimates",
    ] {
        assert!(summary.contains(needle), "summary lacks {needle:?}");
    }
    assert!(stderr(&o).contains("summary.md"));
}

/// Input conventions: the same telemetry stored scalar-first, as JPL, and with renamed
/// columns gives the same estimate; flipping the sign of quaternions changes nothing but
/// the count of sign flips.
#[test]
fn input_conventions_give_the_same_answer() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "slew", "slew", "120");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    let write = |name: &str, header: &str, f: &dyn Fn(usize, &mut Vec<String>)| -> PathBuf {
        let mut s = String::from(header);
        s.push('\n');
        for (i, r) in rows.iter().enumerate() {
            let mut r = r.clone();
            f(i, &mut r);
            s.push_str(&r.join(","));
            s.push('\n');
        }
        let p = dir.path().join(name);
        std::fs::write(&p, s).unwrap();
        p
    };
    // Scalar first: columns q_x..q_w hold w, x, y, z.
    let sf = write("sf.csv", header, &|_, r| {
        r[1..5].rotate_right(1);
    });
    // JPL: same components (see attitude docs).
    let jpl = write("jpl.csv", header, &|_, r| {
        let _ = r;
    });
    let flipped = write("flip.csv", header, &|i, r| {
        if i % 2 == 1 {
            for c in r.iter_mut().take(5).skip(1) {
                *c = if let Some(s) = c.strip_prefix('-') {
                    s.to_string()
                } else {
                    format!("-{c}")
                };
            }
        }
    });
    let renamed = write("ren.csv", &header.replacen("t,", "time,", 1), &|_, _| {});
    let base = json(&inertia(&["estimate", csv.to_str().unwrap(), "--json"]));
    let cases: [(&PathBuf, &[&str]); 4] = [
        (&sf, &["--scalar-first"]),
        (&jpl, &["--jpl"]),
        (&flipped, &[]),
        (&renamed, &["--column", "t=time"]),
    ];
    for (p, extra) in cases {
        let mut args = vec!["estimate", p.to_str().unwrap(), "--json"];
        args.extend_from_slice(extra);
        let o = inertia(&args);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        let v = json(&o);
        for k in 0..6 {
            let (x, y) = (v["j"][k].as_f64().unwrap(), base["j"][k].as_f64().unwrap());
            assert!(
                (x - y).abs() < 1e-9 * (1.0 + y.abs()),
                "{extra:?} {k}: {x} vs {y}"
            );
        }
    }
    let v = json(&inertia(&["estimate", flipped.to_str().unwrap(), "--json"]));
    assert_eq!(v["sign_flips"].as_u64().unwrap(), 1200);
    // Reading a scalar-last file as scalar-first is caught (non-unit or huge steps), not
    // silently accepted... or gives a different answer.
    let o = inertia(&[
        "estimate",
        csv.to_str().unwrap(),
        "--scalar-first",
        "--json",
    ]);
    if o.status.success() {
        let v = json(&o);
        let d: f64 = (0..6)
            .map(|k| (v["j"][k].as_f64().unwrap_or(0.0) - base["j"][k].as_f64().unwrap()).abs())
            .sum();
        assert!(d > 1e-3);
    }
}

/// A small valid file with one line replaced.
fn bad_file(dir: &Path, name: &str, line: usize, replace: &dyn Fn(&str) -> String) -> PathBuf {
    let src = simulate(dir, &format!("{name}_src"), "slew", "2");
    let text = std::fs::read_to_string(&src).unwrap();
    let out: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i + 1 == line {
                replace(l)
            } else {
                l.to_string()
            }
        })
        .collect();
    let p = dir.join(format!("{name}.csv"));
    std::fs::write(&p, out.join("\n") + "\n").unwrap();
    p
}

fn field(line: &str, col: usize, value: &str) -> String {
    let mut f: Vec<String> = line.split(',').map(str::to_string).collect();
    f[col] = value.to_string();
    f.join(",")
}

fn assert_bad(p: &Path, extra: &[&str], needles: &[&str]) {
    let mut args = vec!["estimate", p.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = inertia(&args);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "one line: {e}");
    assert!(!e.contains("panicked"), "{e}");
    for n in needles {
        assert!(e.contains(n), "{e:?} lacks {n:?}");
    }
}

#[test]
fn bad_number() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "num", 5, &|l| field(l, 2, "abc"));
    assert_bad(&p, &[], &["num.csv:5", "`q_y`", "\"abc\""]);
}

#[test]
fn nan_value() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "nan", 7, &|l| field(l, 6, "NaN"));
    assert_bad(&p, &[], &["nan.csv:7", "`rho_y`", "not finite"]);
}

#[test]
fn missing_column() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "miss", 1, &|l| l.replace("rho_z", "rho_q"));
    assert_bad(&p, &[], &["miss.csv:1", "missing column `rho_z`"]);
}

#[test]
fn non_unit_quaternion() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "unit", 9, &|l| field(l, 4, "0.9"));
    assert_bad(&p, &[], &["unit.csv:9", "q_x,q_y,q_z,q_w", "norm"]);
}

#[test]
fn non_increasing_time() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "time", 6, &|l| field(l, 0, "0.1"));
    assert_bad(&p, &[], &["time.csv:6", "`t`", "does not increase"]);
}

#[test]
fn non_uniform_period() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "period", 6, &|l| field(l, 0, "0.43"));
    // Irregular steps are accepted by default; strict mode rejects them.
    assert_bad(
        &p,
        &["--period-tolerance", "1e-3"],
        &["period.csv:6", "`t`", "sample period"],
    );
    let o = inertia(&["estimate", p.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn step_too_large() {
    let d = tempfile::tempdir().unwrap();
    // 180° about x relative to its neighbours.
    let p = bad_file(d.path(), "step", 8, &|l| {
        let l = field(l, 1, "1");
        let l = field(&l, 2, "0");
        let l = field(&l, 3, "0");
        field(&l, 4, "0")
    });
    assert_bad(&p, &[], &["step.csv:8", "q_x,q_y,q_z,q_w", "too long"]);
}

#[test]
fn malformed_row() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "mal", 4, &|l| format!("{l},1,2"));
    assert_bad(&p, &[], &["mal.csv:4", "malformed"]);
}

#[test]
fn missing_file_and_bad_options() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("nope.csv");
    assert_bad(&p, &[], &["nope.csv"]);
    let ok = simulate(d.path(), "ok", "slew", "2");
    assert_bad(&ok, &["--bound", "J33=3.3:2.7"], &["J33", "contradict"]);
    assert_bad(
        &ok,
        &["--bound", "J44=1:2"],
        &["--bound", "unknown element"],
    );
    assert_bad(
        &ok,
        &[
            "--bound", "J11=:1", "--bound", "J22=:1", "--bound", "J33=3:",
        ],
        &["no inertia satisfies"],
    );
    // Usage errors come from clap, also with exit code 2.
    let o = inertia(&["estimate", ok.to_str().unwrap(), "--estimator", "magic"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn gyro_columns_required_by_the_baselines() {
    let d = tempfile::tempdir().unwrap();
    let p = bad_file(d.path(), "nogyro", 1, &|l| {
        l.replace("w_x", "a")
            .replace("w_y", "b")
            .replace("w_z", "c")
    });
    assert_bad(
        &p,
        &["--estimator", "momentum"],
        &["nogyro.csv:1", "w_x,w_y,w_z"],
    );
    // The variational estimator does not need them.
    let o = inertia(&["estimate", p.to_str().unwrap()]);
    assert_ne!(o.status.code(), Some(1), "{}", stderr(&o));
}

#[test]
fn unobservable_data_are_reported_not_estimated() {
    let d = tempfile::tempdir().unwrap();
    // The spin case before its wheel pulse, without the J33 bound: y ≡ 0.
    let csv = simulate(d.path(), "spin", "spin", "20");
    let o = inertia(&["estimate", csv.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["status"], "not_observable");
    assert!(v["j"].is_null());
    assert!(v["reason"].as_str().unwrap().contains("up to scale"));
    let advice = v["excitation"]["advice"].as_array().unwrap();
    assert!(advice[0]
        .as_str()
        .unwrap()
        .contains("reaction-wheel momentum change"));
    assert_eq!(
        v["excitation"]["singular_values"].as_array().unwrap().len(),
        6
    );
    let o = inertia(&["estimate", csv.to_str().unwrap()]);
    assert!(stdout(&o).contains("NOT OBSERVABLE"));
}

/// Monte Carlo output is identical whatever the number of threads.
#[test]
fn monte_carlo_is_deterministic_across_thread_counts() {
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.path().join(format!("mc{threads}"));
        let o = Command::new(env!("CARGO_BIN_EXE_inertia"))
            .args([
                "monte-carlo",
                "--scenario",
                "spin",
                "--runs",
                "6",
                "--duration",
                "40",
                "--out",
                out.to_str().unwrap(),
            ])
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stdout(&o).contains("| variational |"));
        for f in [
            "spin_error_percentiles.png",
            "spin_error_percentiles.svg",
            "spin_summary.md",
        ] {
            assert!(out.join(f).exists(), "{f}");
        }
        outputs.push((
            std::fs::read_to_string(out.join("spin_error_percentiles.csv")).unwrap(),
            std::fs::read_to_string(out.join("spin_final_errors.csv")).unwrap(),
        ));
    }
    assert_eq!(outputs[0], outputs[1]);
    // Six runs, and they differ from each other (the seeds matter).
    let finals: Vec<&str> = outputs[0].1.lines().skip(1).collect();
    assert_eq!(finals.len(), 6);
    assert_ne!(finals[0].split(',').nth(2), finals[1].split(',').nth(2));
}

/// A step change of inertia: `--memory` tracks the new J; without it the answer, a blend
/// of the two inertias, is withdrawn by the residual-consistency test, which names the
/// option.
#[test]
fn memory_tracks_a_changed_inertia() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("step.csv");
    let o = inertia(&[
        "simulate",
        "--scenario",
        "slew",
        "--inertia-step",
        "150:1.1",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let truth = dir.path().join("step.truth.json");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "estimate",
            csv.to_str().unwrap(),
            "--constraints",
            "paper",
            "--json",
            "--truth",
            truth.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        json(&inertia(&args))
    };
    let with = run(&["--memory", "30"])["relative_error"].as_f64().unwrap();
    assert!(with < 2e-2, "with memory {with:e}");
    let without = run(&[]);
    assert_eq!(without["status"], "not_observable", "{without}");
    assert!(without["inertia"].is_null());
    let reason = without["reason"].as_str().unwrap();
    assert!(
        reason.contains("--memory") && reason.contains("times the rest"),
        "{reason}"
    );
    assert!(without["residual_consistency"]["ratio"].as_f64().unwrap() > 300.0);
    let o = inertia(&["estimate", csv.to_str().unwrap(), "--memory", "-1"]);
    assert_eq!(o.status.code(), Some(2));
}

/// Irregular telemetry: jittered steps, a gap, and ISO-8601 time stamps.
#[test]
fn jitter_gaps_and_iso_time_stamps() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "slew", "slew", "300");
    let text = std::fs::read_to_string(&csv).unwrap();
    let header = text.lines().next().unwrap().to_string();
    let rows: Vec<Vec<String>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    let write = |name: &str, keep: &dyn Fn(usize) -> bool, time: &dyn Fn(usize, f64) -> String| {
        let mut s = header.clone() + "\n";
        for (i, r) in rows.iter().enumerate().filter(|(i, _)| keep(*i)) {
            let mut r = r.clone();
            r[0] = time(i, r[0].parse().unwrap());
            s.push_str(&r.join(","));
            s.push('\n');
        }
        let p = dir.path().join(name);
        std::fs::write(&p, s).unwrap();
        p
    };
    let pd = ["--constraints", "positive-definite"];
    let base = json(&inertia(&[
        "estimate",
        csv.to_str().unwrap(),
        "--json",
        pd[0],
        pd[1],
    ]));
    // Drop samples irregularly (steps of 0.1, 0.2 s) and one 10 s stretch (a gap).
    let jittered = write(
        "jit.csv",
        &|i| i % 7 != 3 && !(1200..1300).contains(&i),
        &|_, t| t.to_string(),
    );
    let v = json(&inertia(&[
        "estimate",
        jittered.to_str().unwrap(),
        "--json",
        pd[0],
        pd[1],
    ]));
    assert_eq!(v["gaps"].as_u64().unwrap(), 1, "{v}");
    assert!((v["max_step_s"].as_f64().unwrap() - 10.1).abs() < 1e-6);
    assert_eq!(v["status"], "determined");
    for k in 0..6 {
        let (x, y) = (v["j"][k].as_f64().unwrap(), base["j"][k].as_f64().unwrap());
        assert!((x - y).abs() < 2e-3 * (1.0 + y.abs()), "{k}: {x} vs {y}");
    }
    // Resampled to a uniform 0.1 s grid (the gap restarts the grid): the same answer.
    let v = json(&inertia(&[
        "estimate",
        jittered.to_str().unwrap(),
        "--resample",
        "0.1",
        "--json",
        pd[0],
        pd[1],
    ]));
    assert_eq!(v["status"], "determined", "{v}");
    for k in 0..6 {
        let (x, y) = (v["j"][k].as_f64().unwrap(), base["j"][k].as_f64().unwrap());
        assert!(
            (x - y).abs() < 2e-3 * (1.0 + y.abs()),
            "resampled {k}: {x} vs {y}"
        );
    }
    // ISO-8601 time stamps, 0.1 s apart: the same answer as seconds.
    let iso = write("iso.csv", &|_| true, &|i, _| {
        let tenths = 9 * 36000 + 6 * 600 + i; // from 09:06:00.0
        format!(
            "2026-11-21T{:02}:{:02}:{:02}.{}Z",
            tenths / 36000,
            (tenths / 600) % 60,
            (tenths / 10) % 60,
            tenths % 10
        )
    });
    let v = json(&inertia(&[
        "estimate",
        iso.to_str().unwrap(),
        "--json",
        pd[0],
        pd[1],
    ]));
    for k in 0..6 {
        let (x, y) = (v["j"][k].as_f64().unwrap(), base["j"][k].as_f64().unwrap());
        assert!((x - y).abs() < 1e-9 * (1.0 + y.abs()), "{k}: {x} vs {y}");
    }
    assert!((v["t"].as_f64().unwrap() - 300.0).abs() < 1e-9);
    // Mixed clocks are an error naming the line.
    let mixed = write("mixed.csv", &|_| true, &|i, t| {
        if i == 5 {
            "2026-11-21T09:06:00Z".into()
        } else {
            t.to_string()
        }
    });
    assert_bad(&mixed, &[], &["mixed.csv:7", "time stamp"]);
}

#[test]
fn simulate_realism_options() {
    let dir = tempfile::tempdir().unwrap();
    let read = |p: &Path| std::fs::read_to_string(p).unwrap();
    // A preset, decimated to 1 Hz telemetry with its 10 Hz controller.
    let small = dir.path().join("small.csv");
    let o = inertia(&[
        "simulate",
        "--preset",
        "small-sat",
        "--duration",
        "30",
        "--telemetry-dt",
        "1",
        "-o",
        small.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = read(&small);
    assert!(text.starts_with("t,q_x,q_y,q_z,q_w,rho_x,rho_y,rho_z,tau_x,tau_y,tau_z,w_x,w_y,w_z\n"));
    assert_eq!(text.lines().count(), 32, "header + 31 samples at 1 Hz");
    let truth: serde_json::Value =
        serde_json::from_str(&read(&dir.path().join("small.truth.json"))).unwrap();
    assert_eq!(truth["inertia_kg_m2"][0][0], 0.31);

    // The paper's slew with every effect on; gravity gradient adds r_x,r_y,r_z.
    let all = dir.path().join("all.csv");
    let o = inertia(&[
        "simulate",
        "--scenario",
        "slew",
        "--duration",
        "20",
        "--attitude",
        "star-tracker",
        "--star-tracker-arcsec",
        "5:5:40",
        "--gyro-arw-deg-rthr",
        "0.02",
        "--gyro-bias-deg-h",
        "1:-1:0.5",
        "--controller-hz",
        "10",
        "--command-phase",
        "0.05",
        "--wheel-quantization-nms",
        "1e-4",
        "--wheel-skew-s",
        "-0.05",
        "--gravity-gradient-altitude-km",
        "500",
        "--constant-torque-nm",
        "1e-5:0:-1e-5",
        "-o",
        all.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = read(&all);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(&header[14..], ["r_x", "r_y", "r_z"]);
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 201);
    for row in &rows {
        let r = (row[14] * row[14] + row[15] * row[15] + row[16] * row[16]).sqrt();
        assert!((r - 6_878_137.0).abs() < 1e-3, "orbit radius {r}");
        for rho in &row[5..8] {
            let steps = rho / 1e-4;
            assert!(
                (steps - steps.round()).abs() < 1e-6,
                "ρ {rho} not quantised"
            );
        }
        // The unknown torques are not telemetered.
        assert_eq!(&row[8..11], [0.0, 0.0, 0.0]);
    }
    // `estimate` reads it (extra columns ignored).
    let o = inertia(&["estimate", all.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));

    // Invalid settings name the option or the field.
    let bad = |extra: &[&str], needle: &str| {
        let out = dir.path().join("bad.csv");
        let mut args = vec!["simulate", "--scenario", "slew", "--duration", "5"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", out.to_str().unwrap()]);
        let o = inertia(&args);
        assert!(!o.status.success(), "{extra:?} accepted");
        assert!(stderr(&o).contains(needle), "{extra:?}: {}", stderr(&o));
    };
    bad(&["--telemetry-dt", "0.15"], "--telemetry-dt");
    bad(
        &["--controller-hz", "10", "--command-phase", "0.2"],
        "commands.phase_s",
    );
    bad(&["--command-phase", "0.05"], "--controller-hz");
    bad(&["--star-tracker-arcsec", "1:2"], "--star-tracker-arcsec");
    bad(&["--wheel-skew-s", "0.5"], "wheels.skew_s");
    bad(
        &["--attitude", "mekf", "--star-tracker-hz", "3"],
        "star_tracker.rate_hz",
    );
    bad(&["--preset", "microsat"], "cannot be used with");
    // --help documents the options.
    let help = stdout(&inertia(&["simulate", "--help"]));
    for opt in [
        "--preset",
        "--attitude",
        "--controller-hz",
        "--command-phase",
        "--telemetry-dt",
        "--star-tracker-arcsec",
        "--gyro-arw-deg-rthr",
        "--gyro-bias-deg-h",
        "--wheel-quantization-nms",
        "--wheel-skew-s",
        "--gravity-gradient-altitude-km",
        "--constant-torque-nm",
    ] {
        assert!(help.contains(opt), "{opt} missing from --help");
    }
}
