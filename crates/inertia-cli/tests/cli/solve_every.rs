//! `--every N`: a streaming run solves every N row blocks, and the rows after its last
//! solve are answered at the end of the input, so that the record's end always has an
//! answer (`Estimator::flush`), whatever N is.

use super::{inertia, json, simulate, stderr};

#[test]
fn the_end_of_the_record_is_answered_whatever_the_solve_interval() {
    let d = tempfile::tempdir().unwrap();
    let slew = simulate(d.path(), "slew", "slew", "60");
    let path = slew.to_str().unwrap();
    let at = |every: &str| {
        let o = inertia(&["estimate", path, "--json", "--every", every]);
        assert!(o.status.success(), "--every {every}: {}", stderr(&o));
        json(&o)
    };
    let each = at("1");
    assert_eq!(each["status"], "determined", "{each}");
    // 601 samples: every 7 leaves rows after the last solve, and 100,000 never solves
    // before the end. Both answer at the end, as a solve at every block does.
    for every in ["7", "100000"] {
        let e = at(every);
        for key in ["status", "j", "sigma"] {
            assert_eq!(e[key], each[key], "--every {every}: {key}");
        }
    }
    // The history's last row is the end's answer.
    let history = d.path().join("history.csv");
    let o = inertia(&[
        "estimate",
        path,
        "--every",
        "100000",
        "-o",
        history.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&history).unwrap();
    let last = text.lines().last().unwrap();
    assert!(
        last.starts_with("60,") || last.starts_with("60.0,"),
        "{last}"
    );
    assert!(last.contains("determined"), "{last}");
}
