//! The telemetry reader and the estimator never panic on user data: random corruptions of
//! a valid file give samples or typed errors, and whatever is read can be estimated from
//! without panicking.

use inertia::constraints::ConstraintSet;
use inertia::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
use inertia::estimator::rows::VariationalRows;
use inertia::sim::scenario::{Common, Scenario};
use inertia::solver::native::NativeSolver;
use inertia::telemetry::csv::{write_samples, CsvOptions, TelemetryReader};
use proptest::prelude::*;
use std::sync::OnceLock;

fn valid_file() -> &'static str {
    static FILE: OnceLock<String> = OnceLock::new();
    FILE.get_or_init(|| {
        let out = Scenario::spin()
            .simulate(&Common {
                duration_s: Some(5.0),
                ..Common::paper()
            })
            .unwrap();
        let mut buf = Vec::new();
        write_samples(&mut buf, &out.samples).unwrap();
        String::from_utf8(buf).unwrap()
    })
}

#[derive(Debug, Clone)]
enum Edit {
    /// Replace field `col` of line `line` with `text`.
    Field {
        line: usize,
        col: usize,
        text: String,
    },
    /// Delete a line.
    Delete(usize),
    /// Duplicate a line.
    Duplicate(usize),
    /// Insert a junk line.
    Junk(usize, String),
}

fn edit() -> impl Strategy<Value = Edit> {
    let text = prop_oneof![
        Just("NaN".to_string()),
        Just("inf".to_string()),
        Just("".to_string()),
        Just("-0".to_string()),
        Just("1e308".to_string()),
        Just("2026-11-21T09:06:00Z".to_string()),
        "[ -~]{0,12}",
        (-1e3f64..1e3).prop_map(|v| v.to_string()),
    ];
    prop_oneof![
        (0usize..52, 0usize..15, text.clone()).prop_map(|(line, col, text)| Edit::Field {
            line,
            col,
            text
        }),
        (0usize..52).prop_map(Edit::Delete),
        (0usize..52).prop_map(Edit::Duplicate),
        (0usize..52, "[ -~]{0,40}").prop_map(|(l, s)| Edit::Junk(l, s)),
    ]
}

fn apply(edits: &[Edit]) -> String {
    let mut lines: Vec<String> = valid_file().lines().map(str::to_string).collect();
    for e in edits {
        let n = lines.len();
        match e {
            Edit::Field { line, col, text } => {
                if let Some(l) = lines.get_mut(line % n) {
                    let mut f: Vec<String> = l.split(',').map(str::to_string).collect();
                    let c = col % f.len();
                    f[c] = text.clone();
                    *l = f.join(",");
                }
            }
            Edit::Delete(i) => {
                lines.remove(i % n);
            }
            Edit::Duplicate(i) => {
                let l = lines[i % n].clone();
                lines.insert(i % n, l);
            }
            Edit::Junk(i, s) => lines.insert(i % (n + 1), s.clone()),
        }
        if lines.is_empty() {
            break;
        }
    }
    lines.join("\n")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn corrupted_files_never_panic(edits in prop::collection::vec(edit(), 1..6)) {
        let text = apply(&edits);
        let reader = TelemetryReader::new(text.as_bytes(), "fuzz.csv", CsvOptions::default());
        let Ok(reader) = reader else { return Ok(()); };
        let c = ConstraintSet::physical().validate().unwrap();
        let mut est = RecursiveEstimator::new(VariationalRows::default(), c, NativeSolver::default(), RecursiveSettings::default()).unwrap();
        for item in reader {
            match item {
                Ok(s) => {
                    // Every returned sample is finite with a unit quaternion.
                    prop_assert!(s.t_s.is_finite() && (s.q.norm() - 1.0).abs() < 1e-9);
                    let _ = est.push(&s);
                }
                Err(e) => {
                    // Errors name the file and, when tied to one, a line.
                    let msg = e.to_string();
                    prop_assert!(msg.starts_with("fuzz.csv"), "{msg}");
                    break;
                }
            }
        }
    }
}

/// Errors name the file's own line whatever the line ends and blank lines (the `csv`
/// crate's record positions are a line short after CRLF, rust-csv #395, and name the
/// blank line before a record, #208): a bad number and a short record, on line 9 after
/// two blank lines, with LF and with CRLF line ends, and the last good row's line.
#[test]
fn errors_name_the_physical_line_with_crlf_and_blank_lines() {
    let lines: Vec<&str> = valid_file().lines().collect();
    for eol in ["\n", "\r\n"] {
        for bad in ["number", "short"] {
            // Header, 2 rows, 2 blank lines, rows: the 4th row after the blanks is line 9.
            let mut out: Vec<String> = lines[..3].iter().map(|s| s.to_string()).collect();
            out.extend([String::new(), String::new()]);
            out.extend(lines[3..10].iter().map(|s| s.to_string()));
            let target = 8; // 0-based index of physical line 9
            let mut fields: Vec<String> = out[target].split(',').map(str::to_string).collect();
            match bad {
                "number" => fields[5] = "abc".into(),
                _ => {
                    fields.pop();
                }
            }
            out[target] = fields.join(",");
            let text = out.join(eol) + eol;
            let mut reader =
                TelemetryReader::new(text.as_bytes(), "lines.csv", CsvOptions::default()).unwrap();
            let mut last_good = 0;
            let err = loop {
                match reader.next().expect("an error before the end") {
                    Ok(_) => last_good = reader.last_line(),
                    Err(e) => break e,
                }
            };
            assert_eq!(err.line(), Some(9), "{bad} {eol:?}: {err}");
            assert_eq!(last_good, 8, "{bad} {eol:?}");
            assert!(err.to_string().starts_with("lines.csv:9:"), "{err}");
        }
    }
}
