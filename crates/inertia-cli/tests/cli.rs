//! End-to-end tests of the `inertia` binary.

#[path = "cli/bad_inputs.rs"]
mod bad_inputs;
#[path = "cli/bad_rows.rs"]
mod bad_rows;
#[path = "cli/messages.rs"]
mod messages;
#[path = "cli/outputs.rs"]
mod outputs;
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
#[path = "cli/time_stamps.rs"]
mod time_stamps;
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

// Issue 11: never hang, never NaN, never a silent drop.

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
