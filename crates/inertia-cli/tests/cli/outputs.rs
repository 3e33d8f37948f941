//! Where the results go: I/O failures exit 3 naming the path, bounded resources, standard streams, devices and symbolic links, and a failed run leaves no output.

use super::*;

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
