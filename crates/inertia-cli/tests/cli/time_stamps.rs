//! Time stamps as telemetry writes them: jitter, gaps, ISO 8601 with a leap second, duplicated columns and comment lines.

use super::*;

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
