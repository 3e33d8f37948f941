//! `inertia estimate --batch a.csv b.csv …`: several records of one spacecraft estimated
//! together; refused by name where they cannot be; an error named in its own file.

use super::{bad_file, field, inertia, json, simulate, stderr};

#[test]
fn several_files_are_records_of_one_j() {
    let d = tempfile::tempdir().unwrap();
    let files: Vec<String> = (0..3)
        .map(|k| {
            simulate(d.path(), &format!("r{k}"), "slew", "40")
                .to_str()
                .unwrap()
                .to_string()
        })
        .collect();
    let mut args = vec!["estimate", "--batch", "--json"];
    args.extend(files.iter().map(String::as_str));
    let o = inertia(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let all = json(&o);
    assert_eq!(all["records"], 3);
    assert_eq!(
        all["gaps"], 0,
        "the gaps between records are not the data's"
    );
    assert_eq!(all["samples"], 3 * 401);
    // Each record's own time: the last one's.
    assert!(
        (all["t"].as_f64().unwrap() - 40.0).abs() < 1e-9,
        "{}",
        all["t"]
    );
    assert_eq!(all["file"], files.join(", "));
    let one = json(&inertia(&["estimate", "--batch", "--json", &files[0]]));
    assert!(one.get("records").is_none());
    for k in 0..3 {
        let (s3, s1) = (
            all["sigma"][k].as_f64().unwrap(),
            one["sigma"][k].as_f64().unwrap(),
        );
        assert!(s3 < s1, "J{k}{k}: σ {s3} of three records, {s1} of one");
    }
    // The text report says it.
    let mut args = vec!["estimate", "--batch"];
    args.extend(files.iter().map(String::as_str));
    let text = super::stdout(&inertia(&args));
    assert!(text.contains("records: 3, estimated together"), "{text}");
}

#[test]
fn records_are_refused_by_option_and_errors_name_their_file() {
    let d = tempfile::tempdir().unwrap();
    let a = simulate(d.path(), "a", "slew", "2");
    let (a, a_s) = (a.to_str().unwrap(), a.display().to_string());
    let o = inertia(&["estimate", a, a]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("(option: --batch)"), "{}", stderr(&o));
    assert!(
        stderr(&o).starts_with(&format!("inertia: {a_s}:")),
        "{}",
        stderr(&o)
    );
    let o = inertia(&["estimate", "--batch", "--estimator", "momentum", a, a]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("momentum estimator"), "{}", stderr(&o));
    // A step too large in the second file, found by the batch solve at the end.
    let step = bad_file(d.path(), "step", 8, &|l| {
        let l = field(l, 1, "1");
        let l = field(&l, 2, "0");
        let l = field(&l, 3, "0");
        field(&l, 4, "0")
    });
    let o = inertia(&["estimate", "--batch", a, step.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("step.csv:8:"), "{}", stderr(&o));
}
