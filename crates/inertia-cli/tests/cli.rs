//! End-to-end tests of the `inertia` binary.

#[path = "cli/bad_inputs.rs"]
mod bad_inputs;
#[path = "cli/plan.rs"]
mod plan;
#[path = "cli/records.rs"]
mod records;
#[path = "cli/settings_file.rs"]
mod settings_file;
#[path = "cli/simulate_effects.rs"]
mod simulate_effects;
#[path = "cli/simulate_options.rs"]
mod simulate_options;
#[path = "cli/solve_every.rs"]
mod solve_every;
#[path = "cli/spacecraft.rs"]
mod spacecraft;
#[path = "cli/torque_scale.rs"]
mod torque_scale;

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
    // The readable report. `simulate`'s truth is physical by default (the paper's J +
    // 1e-4 I), so the default physical set and J ⪰ εI alone both determine it.
    for set in ["physical", "positive-definite"] {
        let o = inertia(&[
            "estimate",
            csv.to_str().unwrap(),
            "--truth",
            truth.to_str().unwrap(),
            "--constraints",
            set,
        ]);
        let text = stdout(&o);
        assert!(text.contains("J [kg m²] ="), "{text}");
        assert!(text.contains("principal moments"));
        assert!(text.contains("status: determined"), "{set}: {text}");
        assert!(text.contains("relative Frobenius error vs truth"));
    }
    // The paper's own J lies just outside Σ ⪰ 0: the default estimator is precise enough
    // to see it, and says so instead of "determined".
    let paper = dir.path().join("paper.csv");
    let o = inertia(&[
        "simulate",
        "--scenario",
        "slew",
        "--duration",
        "150",
        "--paper-inertia",
        "-o",
        paper.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let conflict = stdout(&inertia(&["estimate", paper.to_str().unwrap()]));
    assert!(
        conflict.contains("the data contradict the constraint set"),
        "{conflict}"
    );
    let text = stdout(&inertia(&[
        "estimate",
        paper.to_str().unwrap(),
        "--constraints",
        "positive-definite",
    ]));
    // J ⪰ εI alone: determined only with the violation within its σ (said in a
    // warning), otherwise the model check fails (`tests/status.rs` at 300 s).
    assert!(
        text.contains("status: model check failed: not a physical inertia")
            || (text.contains("status: determined")
                && text.contains("within 3 σ of a physical inertia")),
        "{text}"
    );
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
        "| discrete momentum |",
        "Final estimates",
    ] {
        assert!(summary.contains(needle), "summary lacks {needle:?}");
    }
    // Both estimators' errors beside the baselines' in the total-error figures' data.
    for stem in ["fig03_slew_total_error", "fig08_spin_total_error"] {
        let data = std::fs::read_to_string(out.join(format!("{stem}.csv"))).unwrap();
        let header: Vec<&str> = data.lines().next().unwrap().split(',').collect();
        for column in [
            "variational",
            "discrete_momentum",
            "momentum",
            "finite_difference",
        ] {
            assert!(header.contains(&column), "{stem}: {header:?}");
        }
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
    // The wheels' momentum with the opposite sign (columns rho_x..rho_z).
    assert!(header.starts_with("t,q_x,q_y,q_z,q_w,rho_x,rho_y,rho_z,"));
    let reversed = write("rho.csv", header, &|_, r| {
        for c in r.iter_mut().take(8).skip(5) {
            *c = if let Some(s) = c.strip_prefix('-') {
                s.to_string()
            } else {
                format!("-{c}")
            };
        }
    });
    let base = json(&inertia(&["estimate", csv.to_str().unwrap(), "--json"]));
    let cases: [(&PathBuf, &[&str]); 5] = [
        (&sf, &["--scalar-first"]),
        (&jpl, &["--jpl"]),
        (&flipped, &[]),
        (&renamed, &["--column", "t=time"]),
        (&reversed, &["--negate-rho"]),
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
    // Without the option the reversed momentum stops the run, naming the option, the file
    // and the line.
    let o = inertia(&["estimate", reversed.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = stderr(&o);
    let at = err.find("rho.csv:").expect("the file named") + "rho.csv:".len();
    let line: String = err[at..].chars().take_while(char::is_ascii_digit).collect();
    assert!(
        err.contains("--negate-rho") && line.parse::<usize>().is_ok_and(|l| l > 1),
        "{err}"
    );
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

/// Exit code 3 and one line naming what could not be read or written.
fn assert_io_error(args: &[&str], needles: &[&str]) {
    let o = inertia(args);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(3), "{e}");
    assert_eq!(e.lines().count(), 1, "one line: {e}");
    for n in needles {
        assert!(e.contains(n), "{e:?} lacks {n:?}");
    }
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
    // The line is the one that ends the step, also when resampling reads ahead, and the
    // step's times print without float noise.
    for e in ["variational", "discrete-momentum"] {
        assert_bad(
            &p,
            &["--resample", "0.1", "--estimator", e],
            &["step.csv:8", "s to t = 0.6 s gives"],
        );
    }
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
    assert_io_error(
        &["estimate", p.to_str().unwrap()],
        &["cannot read", "nope.csv"],
    );
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
        reason.contains("forget old data with a memory") && reason.contains("times the rest"),
        "{reason}"
    );
    assert_eq!(without["fixes"], serde_json::json!(["memory"]), "{without}");
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

// Issue 11: never hang, never NaN, never a silent drop.

/// The arguments of `inertia simulate` for 2 s of the slew into `out`.
fn simulate_2s_slew(out: &str) -> [&str; 7] {
    [
        "simulate",
        "--scenario",
        "slew",
        "--duration",
        "2",
        "-o",
        out,
    ]
}

/// The files in `dir` (names), sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn io_failures_exit_3_and_name_the_path() {
    let d = tempfile::tempdir().unwrap();
    let ok = simulate(d.path(), "ok", "slew", "2");
    let ok = ok.to_str().unwrap();
    // An unreadable input: a directory.
    assert_io_error(
        &["estimate", d.path().to_str().unwrap()],
        &["Is a directory"],
    );
    // An unwritable output, found before the data are read: bad data and a bad -o give 3.
    let bad = bad_file(d.path(), "bad", 5, &|l| field(l, 2, "abc"));
    let nowhere = d.path().join("no/such/dir/h.csv");
    assert_io_error(
        &[
            "estimate",
            bad.to_str().unwrap(),
            "-o",
            nowhere.to_str().unwrap(),
        ],
        &["cannot write", "no/such/dir/h.csv"],
    );
    assert_io_error(
        &["estimate", ok, "-o", d.path().to_str().unwrap()],
        &["is a directory"],
    );
    assert_io_error(
        &[
            "simulate",
            "--scenario",
            "slew",
            "-o",
            nowhere.to_str().unwrap(),
        ],
        &["cannot write", "h.csv"],
    );
    // --truth that cannot be read is I/O; one that is not an inertia file is bad input.
    let missing = d.path().join("missing.json");
    assert_io_error(
        &["estimate", ok, "--truth", missing.to_str().unwrap()],
        &["missing.json"],
    );
    assert_bad(Path::new(ok), &["--truth", ok], &["ok.csv:1:"]);
}

#[test]
fn duplicated_columns_and_comment_lines_are_errors() {
    let d = tempfile::tempdir().unwrap();
    // A second rho_x column at the end: which one is meant?
    let src = simulate(d.path(), "src", "slew", "2");
    let text: String = std::fs::read_to_string(&src)
        .unwrap()
        .lines()
        .enumerate()
        .map(|(i, l)| format!("{l},{}\n", if i == 0 { "rho_x" } else { "5" }))
        .collect();
    let dup = d.path().join("dup.csv");
    std::fs::write(&dup, text).unwrap();
    assert_bad(
        &dup,
        &[],
        &[
            "dup.csv:1",
            "column `rho_x` appears twice (columns 6 and 15)",
        ],
    );
    // A data line starting with `#` was skipped silently; now it is an error.
    let p = bad_file(d.path(), "hash", 6, &|l| format!("#{l}"));
    assert_bad(&p, &[], &["hash.csv:6", "starts with `#`"]);
}

#[test]
fn iso_time_stamps_across_a_leap_second() {
    let d = tempfile::tempdir().unwrap();
    let src = simulate(d.path(), "src", "slew", "30");
    // Stamps 0.1 s apart, through 2016-12-31T23:59:60.
    let start = 86_399.0 - 10.0; // seconds of 2016-12-31
    let text: String = std::fs::read_to_string(&src)
        .unwrap()
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                return format!("{l}\n");
            }
            let tenths = (start * 10.0) as u64 + i as u64 - 1;
            let (s, f) = (tenths / 10, tenths % 10);
            let stamp = if s < 86_400 {
                format!("2016-12-31T23:59:{:02}.{f}Z", s - 86_340)
            } else if s == 86_400 {
                format!("2016-12-31T23:59:60.{f}Z")
            } else {
                let s = s - 86_401;
                format!("2017-01-01T00:{:02}:{:02}.{f}Z", s / 60, s % 60)
            };
            let rest = l.split_once(',').unwrap().1;
            format!("{stamp},{rest}\n")
        })
        .collect();
    assert!(text.contains("23:59:60.5Z"));
    let leap = d.path().join("leap.csv");
    std::fs::write(&leap, text).unwrap();
    let o = inertia(&["estimate", leap.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["samples"], 301);
    for k in ["min_step_s", "max_step_s"] {
        let h = v[k].as_f64().unwrap();
        assert!((h - 0.1).abs() < 1e-6, "{k} {h}");
    }
    assert_eq!(v["gaps"], 0);
}

#[test]
fn resources_are_bounded() {
    let d = tempfile::tempdir().unwrap();
    // 3 MiB without a line break, and a 10 MB header: one short line.
    let flat = d.path().join("flat.csv");
    std::fs::write(&flat, vec![b'7'; 3 << 20]).unwrap();
    assert_bad(
        &flat,
        &[],
        &["flat.csv:1", "line longer than 1048576 bytes"],
    );
    let ok = simulate(d.path(), "ok", "slew", "2");
    let text = std::fs::read_to_string(&ok).unwrap();
    let header = format!("{}{}", "x".repeat(10_000_000), text);
    let wide = d.path().join("wide.csv");
    std::fs::write(&wide, header).unwrap();
    let o = inertia(&["estimate", wide.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).len() < 200, "{}", stderr(&o));
    // A 500 kB header without the columns: the message quotes a bounded part of it.
    let names: Vec<String> = (0..50_000).map(|i| format!("c{i}")).collect();
    let header = format!("{}\n1\n", names.join(","));
    std::fs::write(&wide, header).unwrap();
    let o = inertia(&["estimate", wide.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).len() < 400, "{}", stderr(&o));
    // Resampling to 1000 samples per step, a memory shorter than the step.
    let ok = ok.to_str().unwrap();
    let o = inertia(&["estimate", ok, "--resample", "0.0001"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("resampling to 0.0001 s would make 1000 samples of the step of 0.1 s")
            && stderr(&o).contains("(option: --resample)"),
        "{}",
        stderr(&o)
    );
    let o = inertia(&[
        "estimate",
        ok,
        "--memory",
        "0.01",
        "--estimator",
        "variational",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("the memory 0.01 s is shorter than the sample period 0.1 s")
            && stderr(&o).contains("(option: --memory)"),
        "{}",
        stderr(&o)
    );
    // Durations that cannot be simulated: exit 2 naming --duration, no file.
    let out = d.path().join("long.csv");
    for dur in ["1e12", "1e30", "NaN", "-5", "inf"] {
        let o = inertia(&[
            "simulate",
            "--scenario",
            "slew",
            &format!("--duration={dur}"),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{dur}: {}", stderr(&o));
        assert!(stderr(&o).contains("--duration"), "{dur}: {}", stderr(&o));
        assert_eq!(stderr(&o).lines().count(), 1);
    }
    assert!(!out.exists());
    // Node periods that would take hours: 2·10⁸ steps per node, 10⁵ nodes per sample.
    for args in [
        &["--dt=1e6", "--duration=4e6"][..],
        &["--dt=1e-6", "--telemetry-dt=0.1"][..],
    ] {
        let mut all = vec![
            "simulate",
            "--scenario",
            "slew",
            "-o",
            out.to_str().unwrap(),
        ];
        all.extend_from_slice(args);
        let o = inertia(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("integration steps"), "{}", stderr(&o));
    }
    assert!(!out.exists());
}

#[test]
fn standard_streams() {
    use std::io::{Read, Write};
    use std::process::Stdio;
    let d = tempfile::tempdir().unwrap();
    // simulate -o - writes the CSV to standard output, and no file named `-`.
    let o = Command::new(env!("CARGO_BIN_EXE_inertia"))
        .args([
            "simulate",
            "--scenario",
            "slew",
            "--duration",
            "20",
            "-o",
            "-",
        ])
        .current_dir(d.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).starts_with("t,q_x"));
    assert!(listing(d.path()).is_empty(), "{:?}", listing(d.path()));
    // estimate - reads standard input.
    let mut child = Command::new(env!("CARGO_BIN_EXE_inertia"))
        .args(["estimate", "-", "--json"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(&o.stdout).unwrap();
    let e = child.wait_with_output().unwrap();
    assert!(e.status.success(), "{}", stderr(&e));
    assert_eq!(json(&e)["samples"], 201);
    // estimate -o -: the report is on standard output, so it is refused.
    let csv = simulate(d.path(), "ok", "slew", "2");
    let o = inertia(&["estimate", csv.to_str().unwrap(), "-o", "-"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("-o -"), "{}", stderr(&o));
    // A reader that stops early (`| head`) ends the output quietly, not with a panic.
    let mut child = Command::new(env!("CARGO_BIN_EXE_inertia"))
        .args(["simulate", "--scenario", "slew", "-o", "-"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 16];
    child.stdout.take().unwrap().read_exact(&mut first).unwrap();
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
}

#[test]
fn failed_runs_leave_no_output() {
    let d = tempfile::tempdir().unwrap();
    // Bad data late in the file: the history written so far is not left behind, and a
    // history from an earlier run is untouched.
    let bad = bad_file(d.path(), "late", 18, &|l| field(l, 6, "NaN"));
    let hist = d.path().join("h.csv");
    std::fs::write(&hist, "earlier\n").unwrap();
    let before = listing(d.path());
    assert_bad(&bad, &["-o", hist.to_str().unwrap()], &["late.csv:18"]);
    assert_eq!(std::fs::read_to_string(&hist).unwrap(), "earlier\n");
    assert_eq!(listing(d.path()), before);
    // A simulation whose truth file cannot be written leaves no CSV either (it used to
    // write the CSV, then fail on the truth file).
    std::fs::create_dir(d.path().join("sim.truth.json")).unwrap();
    let before = listing(d.path());
    let out = d.path().join("sim.csv");
    assert_io_error(
        &simulate_2s_slew(out.to_str().unwrap()),
        &["sim.truth.json", "is a directory"],
    );
    assert_eq!(listing(d.path()), before);
}

#[test]
fn messages_are_compact_and_true() {
    let d = tempfile::tempdir().unwrap();
    // Times print in at most 12 significant digits.
    let p = bad_file(d.path(), "big", 5, &|l| field(l, 0, "9876543210.123456789"));
    assert_bad(
        &p,
        &[],
        &[
            "big.csv:6",
            "s does not increase (previous row: 9876543210.12 s)",
        ],
    );
    // Beyond the supported range, the value itself is the error, in the same form.
    let p = bad_file(d.path(), "huge", 5, &|l| field(l, 0, "1e308"));
    assert_bad(&p, &[], &["huge.csv:5", "value 1e308 is outside"]);
    // One gap (lines 6-10 removed), in the singular.
    let src = simulate(d.path(), "gap_src", "slew", "2");
    let text: Vec<String> = std::fs::read_to_string(&src)
        .unwrap()
        .lines()
        .enumerate()
        .filter(|(i, _)| !(5..10).contains(i))
        .map(|(_, l)| l.to_string())
        .collect();
    let p2 = d.path().join("gap2.csv");
    std::fs::write(&p2, text.join("\n") + "\n").unwrap();
    let o = inertia(&[
        "estimate",
        p2.to_str().unwrap(),
        "--estimator",
        "variational",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains(", 1 gap)"), "{}", stdout(&o));
    // Times in the report without float noise (the file's last time is 0.7000000000000001).
    let csv = simulate(d.path(), "seven", "slew", "0.7");
    let o = inertia(&[
        "estimate",
        csv.to_str().unwrap(),
        "--estimator",
        "variational",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("t = 0.7 s"), "{}", stdout(&o));
    // Too few samples: the count the estimator needs and the count it got are true.
    let csv = simulate(d.path(), "short", "slew", "0.3");
    let o = inertia(&["estimate", csv.to_str().unwrap(), "--resample", "0.1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("needs at least 4, got 2 (4 read, 2 on the resampling grid)"),
        "{}",
        stderr(&o)
    );
}

/// A bound that holds the answer is reported as active, in the text and the JSON; a bound
/// the answer does not touch is not.
#[test]
fn active_bounds_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "slew", "slew", "300");
    let run = |bound: &str| {
        let o = inertia(&[
            "estimate",
            csv.to_str().unwrap(),
            "--bound",
            bound,
            "--json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        json(&o)["active_bounds"].clone()
    };
    let active = run("J33=10:11");
    assert_eq!(active.as_array().map(Vec::len), Some(1), "{active}");
    assert_eq!(active[0]["component"], "J33");
    assert_eq!(active[0]["side"], "lower");
    assert_eq!(active[0]["value_kg_m2"], 10.0);
    assert_eq!(run("J33=2.7:3.3").as_array().map(Vec::len), Some(0));
    // An equality is accepted, holds the element, and is reported as fixed; one that
    // contradicts J ⪰ εI is still an error.
    let fixed = inertia(&[
        "estimate",
        csv.to_str().unwrap(),
        "--bound",
        "J33=3:3",
        "--json",
    ]);
    assert!(fixed.status.success(), "{}", stderr(&fixed));
    let j = json(&fixed);
    assert!((j["j"][2].as_f64().unwrap() - 3.0).abs() <= 1e-8, "{j}");
    assert_eq!(j["active_bounds"][0]["side"], "fixed");
    let o = inertia(&["estimate", csv.to_str().unwrap(), "--bound", "J11=-1:-1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("contradict"), "{}", stderr(&o));
    let o = inertia(&["estimate", csv.to_str().unwrap(), "--bound", "J33=10:11"]);
    assert!(
        stdout(&o).contains(
            "active bounds (they, not the data, hold the answer there): J33 at its lower bound 10"
        ),
        "{}",
        stdout(&o)
    );
}

/// One quaternion turned by 90°: the run stops (exit 2) naming its line; with
/// `--glitches keep` it estimates, and the report lists the two steps around it.
#[test]
fn an_attitude_glitch_names_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "slew", "slew", "300");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (ix, iw) = (col("q_x"), col("q_w"));
    // Line 1502 (sample 1500): q ← (sin 45°, 0, 0, cos 45°) ⊗ q, a 90° turn about x.
    let mut f: Vec<String> = lines[1501].split(',').map(str::to_string).collect();
    let q: Vec<f64> = (ix..=iw).map(|k| f[k].parse().unwrap()).collect();
    let (s, c) = (
        std::f64::consts::FRAC_1_SQRT_2,
        std::f64::consts::FRAC_1_SQRT_2,
    );
    let turned = [
        c * q[0] + s * q[3],
        c * q[1] - s * q[2],
        c * q[2] + s * q[1],
        c * q[3] - s * q[0],
    ];
    for (k, v) in turned.iter().enumerate() {
        f[ix + k] = v.to_string();
    }
    lines[1501] = f.join(",");
    let bad = dir.path().join("glitch.csv");
    std::fs::write(&bad, lines.join("\n")).unwrap();
    for extra in [&[][..], &["--batch"][..]] {
        let mut args = vec!["estimate", bad.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = inertia(&args);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains("glitch.csv:1502:") && e.contains("90.000°"),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    let o = inertia(&[
        "estimate",
        bad.to_str().unwrap(),
        "--glitches",
        "keep",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j = json(&o);
    assert_eq!(j["glitches"]["count"], 2, "{j}");
    assert!(j["inertia"].is_array());
}

/// Issue 11's reproductions: one value far outside the supported range (gyro, rotor
/// momentum, torque), with the estimator and mode that hung, failed or printed NaN on
/// it. Each is now an error naming the file, the line and the column, with the range.
#[test]
fn values_outside_the_supported_range_name_line_and_column() {
    let d = tempfile::tempdir().unwrap();
    let cases: [(usize, &str, &str, &[&str]); 8] = [
        (11, "w_x", "1e308", &["--estimator", "finite-difference"]),
        (
            11,
            "w_x",
            "1e308",
            &["--estimator", "finite-difference", "--batch"],
        ),
        (7, "rho_z", "1e15", &[]),
        (8, "tau_x", "1e308", &["--batch"]),
        (5, "rho_x", "1e308", &["--estimator", "momentum"]),
        (5, "rho_x", "1e20", &["--estimator", "momentum"]),
        (6, "rho_y", "1e160", &[]),
        (0, "t", "2e10", &[]),
    ];
    for (i, (col, name, value, extra)) in cases.into_iter().enumerate() {
        let file = format!("range{i}");
        let p = bad_file(d.path(), &file, 9, &|l| field(l, col, value));
        assert_bad(
            &p,
            extra,
            &[
                &format!("{file}.csv:9:"),
                &format!("`{name}`"),
                "outside the supported range",
            ],
        );
    }
}

/// Inside the range, at its limits: every estimator, recursive and batch, exits 0 with
/// finite numbers (no NaN or inf in the report, no null in J or σ), and the
/// unconstrained baseline warns when its answer is not a physical inertia.
#[test]
fn values_at_the_limits_give_finite_reports() {
    let d = tempfile::tempdir().unwrap();
    let src = simulate(d.path(), "edge_src", "slew", "20");
    let text = std::fs::read_to_string(&src).unwrap();
    for (col, value) in [(5, "1e6"), (7, "-1e6"), (8, "1e4"), (11, "100")] {
        let edited: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(i, l)| {
                if (50..53).contains(&i) {
                    field(l, col, value)
                } else {
                    l.to_string()
                }
            })
            .collect();
        let p = d.path().join(format!("edge{col}.csv"));
        std::fs::write(&p, edited.join("\n") + "\n").unwrap();
        let path = p.to_str().unwrap();
        for est in [
            "discrete-momentum",
            "variational",
            "finite-difference",
            "momentum",
        ] {
            for batch in [false, true] {
                if batch && est == "momentum" {
                    continue;
                }
                // A gyro rate of 100 rad/s on three rows is also an attitude glitch (the
                // attitude does not turn with it): kept, to reach the estimators.
                let mut args = vec!["estimate", path, "--estimator", est, "--glitches", "keep"];
                if batch {
                    args.push("--batch");
                }
                let o = inertia(&args);
                assert_eq!(o.status.code(), Some(0), "{est} {col}: {}", stderr(&o));
                let out = stdout(&o);
                assert!(
                    !out.contains("NaN") && !out.contains("inf "),
                    "{est} {col}: {out}"
                );
                // The baseline's unphysical J is refused, not reported (issue 13).
                if est == "momentum" && col == 5 {
                    assert!(
                        out.contains("not a physical inertia") && out.contains("no estimate"),
                        "{out}"
                    );
                }
                args.push("--json");
                let v = json(&inertia(&args));
                for key in ["inertia", "sigma"] {
                    let nulls = v[key].to_string().matches("null").count();
                    assert!(
                        v[key].is_null() || nulls == 0,
                        "{est} {col} {key}: {}",
                        v[key]
                    );
                }
            }
        }
    }
}

/// Prior knowledge on the command line (issue 13): an equality bound is accepted and
/// eliminated (`--bound J12=0:0` was an infeasibility error), `--diagonal` is the three
/// product equalities, and a CAD prior's products convention is applied and checked.
#[test]
fn equalities_and_a_cad_prior() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "spin", "spin", "60");
    let path = csv.to_str().unwrap();
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(csv.with_extension("truth.json")).unwrap())
            .unwrap();
    let m: Vec<Vec<f64>> = serde_json::from_value(truth["inertia_kg_m2"].clone()).unwrap();

    // Equalities: the answer holds them exactly, the report calls them fixed.
    let by_bounds = json(&inertia(&[
        "estimate", path, "--bound", "J12=0:0", "--bound", "J13=0:0", "--bound", "J23=0:0",
        "--json",
    ]));
    let diagonal = json(&inertia(&["estimate", path, "--diagonal", "--json"]));
    assert_eq!(by_bounds["j"], diagonal["j"]);
    for k in 3..6 {
        assert_eq!(diagonal["j"][k].as_f64(), Some(0.0), "{}", diagonal["j"]);
    }
    let fixed = diagonal["active_bounds"].as_array().unwrap();
    assert_eq!(fixed.len(), 3, "{}", diagonal["active_bounds"]);
    assert!(fixed.iter().all(|b| b["side"] == "fixed"));

    // A CAD prior: the same J written with +Σ m x y products and marked "cad", or given
    // with --products cad, gives the tensor file's answer.
    let write = |name: &str, sign: f64, mark: Option<&str>| {
        let rows: Vec<Vec<f64>> = (0..3)
            .map(|r| {
                (0..3)
                    .map(|c| {
                        if r == c {
                            m[r][c] * 1.02
                        } else {
                            sign * m[r][c]
                        }
                    })
                    .collect()
            })
            .collect();
        let mut v = serde_json::json!({ "inertia_kg_m2": rows });
        if let Some(mark) = mark {
            v["products_of_inertia"] = mark.into();
        }
        let p = dir.path().join(name);
        std::fs::write(&p, v.to_string()).unwrap();
        p
    };
    let tensor = write("tensor.json", 1.0, None);
    let cad = write("cad.json", -1.0, Some("cad"));
    let cad_unmarked = write("cad-unmarked.json", -1.0, None);
    let run = |p: &Path, extra: &[&str]| {
        let mut args = vec![
            "estimate",
            path,
            "--prior",
            p.to_str().unwrap(),
            "--prior-sigma",
            "5%",
            "--json",
        ];
        args.extend_from_slice(extra);
        json(&inertia(&args))
    };
    let a = run(&tensor, &[]);
    assert!(
        a["prior"]["chi2"].as_f64().unwrap() >= 0.0,
        "{}",
        a["prior"]
    );
    assert_eq!(a["prior"]["rows"], 6);
    assert_eq!(run(&cad, &[])["j"], a["j"]);
    assert_eq!(run(&cad_unmarked, &["--products", "cad"])["j"], a["j"]);
    // The products read in the wrong convention: a prior 2 × |J_ik| off in each product.
    assert_ne!(run(&cad_unmarked, &[])["j"], a["j"]);
    // A file and an option that disagree, and a prior without σ, are input errors.
    let o = inertia(&[
        "estimate",
        path,
        "--prior",
        cad.to_str().unwrap(),
        "--prior-sigma",
        "5%",
        "--products",
        "tensor",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("products_of_inertia is \"cad\" but --products asks for tensor"),
        "{}",
        stderr(&o)
    );
    let o = inertia(&["estimate", path, "--prior", tensor.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--prior-sigma"), "{}", stderr(&o));
    // An equality that contradicts the physical set is still an error.
    let o = inertia(&[
        "estimate", path, "--bound", "J11=1:1", "--bound", "J22=1:1", "--bound", "J33=5:5",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("contradict"), "{}", stderr(&o));
}

/// `-o /dev/null` writes to the device and leaves it one (the temporary-file-and-rename
/// of a regular output would put a file in its place as root, and fail otherwise: it
/// did, and later runs of other programs read that file). `-o` naming a symbolic link
/// replaces the link with the new file and never writes through it: the file it named is
/// untouched.
#[cfg(unix)]
#[test]
fn outputs_to_devices_and_symbolic_links() {
    use std::os::unix::fs::FileTypeExt;
    let d = tempfile::tempdir().unwrap();
    let input = simulate(d.path(), "s", "slew", "5");
    for args in [
        &["estimate", input.to_str().unwrap(), "-o", "/dev/null"][..],
        &simulate_2s_slew("/dev/null")[..],
    ] {
        let o = inertia(args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        let kind = std::fs::symlink_metadata("/dev/null").unwrap().file_type();
        assert!(kind.is_char_device(), "{args:?}: /dev/null is now {kind:?}");
    }
    // Nothing written beside the device.
    assert!(!Path::new("/dev/null.truth.json").exists());
    let real = d.path().join("real.csv");
    std::fs::write(&real, "earlier\n").unwrap();
    let link = d.path().join("link.csv");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let before = listing(d.path());
    let o = inertia(&[
        "estimate",
        input.to_str().unwrap(),
        "-o",
        link.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_file());
    assert!(std::fs::read_to_string(&link).unwrap().starts_with("t,J11"));
    assert_eq!(std::fs::read_to_string(&real).unwrap(), "earlier\n");
    // No temporary file left beside either.
    assert_eq!(listing(d.path()), before);
}

/// The rotation source: with a star tracker's attitude beside a gyro, the gyro's rows are
/// chosen (they fit better), the report says so in its `rows:` line and JSON
/// `row_model.rotation`, and `--rotation-source` overrides it.
#[test]
fn the_rotation_source_is_chosen_reported_and_overridable() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("st.csv");
    let o = inertia(&[
        "simulate",
        "--scenario",
        "slew",
        "--attitude",
        "star-tracker",
        "--duration",
        "120",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let truth = dir.path().join("st.truth.json");
    for (extra, rotation) in [
        (&[][..], "gyro"),
        (&["--rotation-source", "gyro"][..], "gyro"),
        (&["--rotation-source", "attitude"][..], "attitude"),
    ] {
        let mut args = vec!["estimate", csv.to_str().unwrap()];
        args.extend_from_slice(extra);
        let text = inertia(&args);
        assert!(text.status.success(), "{extra:?}: {}", stderr(&text));
        assert!(
            stdout(&text).contains(&format!("rows: rotation from {rotation},")),
            "{extra:?}: {}",
            stdout(&text)
        );
        args.extend_from_slice(&["--json", "--truth", truth.to_str().unwrap()]);
        let v = json(&inertia(&args));
        assert_eq!(v["row_model"]["rotation"], rotation, "{extra:?}");
        if extra.is_empty() {
            let err = v["relative_error"].as_f64().unwrap();
            assert!(err < 1e-4, "default: {err}");
        }
    }
}

/// Each `simulate` option changes what it names and nothing else, by its specification:
/// the same 20 s of the slew with one option at a time against the same run without it.
#[test]
fn simulate_options_change_what_they_name() {
    let dir = tempfile::tempdir().unwrap();
    let sim = |name: &str, extra: &[&str]| -> Vec<Vec<f64>> {
        let out = dir.path().join(format!("{name}.csv"));
        let mut args = vec!["simulate", "--scenario", "slew", "--duration", "20"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", out.to_str().unwrap()]);
        let o = inertia(&args);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        std::fs::read_to_string(&out)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect()
    };
    let cols = |rows: &[Vec<f64>], c: std::ops::Range<usize>| -> Vec<Vec<f64>> {
        rows.iter().map(|r| r[c.clone()].to_vec()).collect()
    };
    let (q, rho, w) = (1..5, 5..8, 11..14);
    let base = sim("base", &["--attitude", "truth"]);
    assert_eq!(base.len(), 201);

    // The attitude source changes the quaternions only.
    let gyro = sim("gyro", &["--attitude", "gyro"]);
    assert_ne!(cols(&gyro, q.clone()), cols(&base, q.clone()));
    assert_eq!(cols(&gyro, rho.clone()), cols(&base, rho.clone()));
    assert_eq!(cols(&gyro, w.clone()), cols(&base, w.clone()));
    assert_eq!(cols(&gyro, 8..11), cols(&base, 8..11), "τ");

    // Wheel white noise: ρ only, with the stated 1σ.
    let noisy = sim(
        "noise",
        &["--attitude", "truth", "--wheel-noise-nms", "1e-4"],
    );
    assert_eq!(cols(&noisy, q.clone()), cols(&base, q.clone()));
    assert_eq!(cols(&noisy, w.clone()), cols(&base, w.clone()));
    for axis in 0..3 {
        let d: Vec<f64> = noisy
            .iter()
            .zip(&base)
            .map(|(a, b)| a[5 + axis] - b[5 + axis])
            .collect();
        let sd = (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
        assert!((sd / 1e-4 - 1.0).abs() < 0.2, "axis {axis}: σ {sd:e}");
    }

    // Spin-inertia scale error per axis: telemetered = (1 + ε) true.
    let scaled = sim(
        "scale",
        &["--attitude", "truth", "--wheel-scale-error", "0.01:0:-0.01"],
    );
    assert_eq!(cols(&scaled, w.clone()), cols(&base, w.clone()));
    for (a, b) in scaled.iter().zip(&base) {
        for (axis, f) in [1.01, 1.0, 0.99].into_iter().enumerate() {
            let (x, y) = (a[5 + axis], f * b[5 + axis]);
            assert!((x - y).abs() <= 1e-12 * (1e-9 + y.abs()), "{x} vs {y}");
        }
    }

    // Misalignment: ρ turned by 1° about body z.
    let turned = sim(
        "misaligned",
        &["--attitude", "truth", "--wheel-misalignment-deg", "0:0:1"],
    );
    assert_eq!(cols(&turned, w.clone()), cols(&base, w.clone()));
    let (s, c) = 1f64.to_radians().sin_cos();
    for (a, b) in turned.iter().zip(&base) {
        let expect = [c * b[5] - s * b[6], s * b[5] + c * b[6], b[7]];
        for k in 0..3 {
            assert!((a[5 + k] - expect[k]).abs() <= 1e-12 + 1e-9 * expect[k].abs());
        }
    }

    // Gyro bias instability: the rates change, the true attitude does not.
    let drifting = sim(
        "instability",
        &[
            "--attitude",
            "truth",
            "--gyro-bias-instability-deg-h",
            "50",
            "--gyro-bias-correlation-s",
            "10",
        ],
    );
    assert_eq!(cols(&drifting, q.clone()), cols(&base, q.clone()));
    assert_eq!(cols(&drifting, rho.clone()), cols(&base, rho.clone()));
    assert_ne!(cols(&drifting, w.clone()), cols(&base, w.clone()));

    // The star tracker's roll noise (40″) is about the boresight given, 5″ across it.
    let tracker = sim(
        "tracker",
        &[
            "--attitude",
            "star-tracker",
            "--star-tracker-boresight",
            "1:0:0",
        ],
    );
    let mut sum = [0.0f64; 3];
    for (a, b) in tracker.iter().zip(&base) {
        // Body-frame error: q_true⁻¹ ⊗ q_tracker, small angle 2 vec(·).
        let (qt, qm) = (&b[1..5], &a[1..5]);
        let (x1, y1, z1, w1) = (-qt[0], -qt[1], -qt[2], qt[3]);
        let (x2, y2, z2, w2) = (qm[0], qm[1], qm[2], qm[3]);
        let v = [
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ];
        let sign = (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2).signum();
        for k in 0..3 {
            let arcsec = 2.0 * sign * v[k] * 180.0 / core::f64::consts::PI * 3600.0;
            sum[k] += arcsec * arcsec;
        }
    }
    let sd: Vec<f64> = sum.iter().map(|s| (s / base.len() as f64).sqrt()).collect();
    assert!((sd[0] / 40.0 - 1.0).abs() < 0.2, "roll about x: {sd:?}");
    assert!(
        (sd[1] / 5.0 - 1.0).abs() < 0.2 && (sd[2] / 5.0 - 1.0).abs() < 0.2,
        "{sd:?}"
    );

    // The MEKF's raw rates: the same attitude, the rates without its bias estimate.
    let mekf = sim(
        "mekf",
        &["--attitude", "mekf", "--gyro-bias-deg-h", "5:-5:5"],
    );
    let raw = sim(
        "raw",
        &[
            "--attitude",
            "mekf",
            "--gyro-bias-deg-h",
            "5:-5:5",
            "--mekf-raw-rates",
        ],
    );
    assert_eq!(cols(&raw, q.clone()), cols(&mekf, q.clone()));
    assert_eq!(cols(&raw, rho.clone()), cols(&mekf, rho.clone()));
    assert_ne!(cols(&raw, w.clone()), cols(&mekf, w.clone()));

    // The orbit's inclination: out of the equatorial plane (r_z) only when inclined.
    let orbit = |i: &str| {
        let rows = sim(
            &format!("orbit{i}"),
            &[
                "--attitude",
                "truth",
                "--gravity-gradient-altitude-km",
                "500",
                "--orbit-inclination-deg",
                i,
            ],
        );
        rows.iter().map(|r| r[16].abs()).fold(0.0, f64::max)
    };
    assert!(orbit("0") < 1e-6);
    assert!(orbit("60") > 1e3);

    // The microsatellite preset.
    let micro = dir.path().join("micro.csv");
    let o = inertia(&[
        "simulate",
        "--preset",
        "microsat",
        "--duration",
        "10",
        "-o",
        micro.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let truth: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("micro.truth.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(truth["inertia_kg_m2"][0][0], 4.6);
}

/// The simulator's options also go by names that carry their units (SI, or the density's
/// unit): the same file either way.
#[test]
fn simulate_options_with_units_in_their_names_are_the_same_options() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, options: &[&str]| -> String {
        let out = dir.path().join(format!("{name}.csv"));
        let mut args = vec!["simulate", "--scenario", "slew", "--controller-hz", "10"];
        args.extend_from_slice(options);
        args.extend_from_slice(&["-o", out.to_str().unwrap()]);
        let o = inertia(&args);
        assert!(o.status.success(), "{options:?}: {}", stderr(&o));
        std::fs::read_to_string(out).unwrap()
    };
    let short = run(
        "short",
        &[
            "--duration",
            "6",
            "--dt",
            "0.05",
            "--telemetry-dt",
            "0.1",
            "--gyro-noise",
            "1e-4",
            "--disturbance",
            "1e-7",
            "--command-phase",
            "0.05",
        ],
    );
    let long = run(
        "long",
        &[
            "--duration-s",
            "6",
            "--dt-s",
            "0.05",
            "--telemetry-dt-s",
            "0.1",
            "--gyro-noise-deg-s-rthz",
            "1e-4",
            "--disturbance-nm-rthz",
            "1e-7",
            "--command-phase-s",
            "0.05",
        ],
    );
    assert_eq!(short, long);
    assert_eq!(short.lines().count(), 62);
    let help = stdout(&inertia(&["simulate", "--help"]));
    assert!(help.contains("duration-s") && help.contains("disturbance-nm-rthz"));
}

/// Control characters in what a file holds (a terminal escape sequence in its header or
/// a field) are printed escaped: the message is one line of text, never a command to the
/// terminal.
#[test]
fn control_characters_in_a_file_are_printed_escaped() {
    let d = tempfile::tempdir().unwrap();
    let esc = "\u{1b}]0;retitled\u{7}";
    for (name, f) in [
        (
            "header",
            Box::new(move |l: &str| l.replace("rho_z", &format!("rho_z{esc}")))
                as Box<dyn Fn(&str) -> String>,
        ),
        (
            "duplicate",
            Box::new(move |l: &str| format!("{l},{esc},{esc}")),
        ),
    ] {
        let p = bad_file(d.path(), name, 1, &*f);
        let o = inertia(&["estimate", p.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(
            !e.trim_end_matches('\n').chars().any(char::is_control),
            "{name}: {e:?}"
        );
        assert!(e.contains("\\u{1b}"), "{name}: the escape is shown: {e:?}");
    }
    let p = bad_file(d.path(), "field", 5, &|l| field(l, 1, &format!("0.1{esc}")));
    let e = stderr(&inertia(&["estimate", p.to_str().unwrap()]));
    assert!(
        !e.trim_end_matches('\n').chars().any(char::is_control),
        "{e:?}"
    );
}
