//! `--settings RUN.toml`: a run file gives the options by their names; it reproduces the
//! same options on the command line exactly, options given override it, and an unknown
//! key or a bad value is refused naming the file, the line and the key.

use super::{inertia, json, simulate, stderr};

/// Options that change the answer (each is tested on its own elsewhere), as a run file
/// and as command-line options.
const RUN: &str = r#"
# The run's settings, by the long options' names.
estimator = "discrete-momentum"
memory = 400.0
every = 2
rho_model = "held"
inertial_torque = "on"
chain = 20
bounds = ["J33=2.7:3.3"]
gyro_noise = 1e-5
"#;

const OPTIONS: &[&str] = &[
    "--estimator",
    "discrete-momentum",
    "--memory",
    "400",
    "--every",
    "2",
    "--rho-model",
    "held",
    "--inertial-torque",
    "on",
    "--chain",
    "20",
    "--bound",
    "J33=2.7:3.3",
    "--gyro-noise",
    "1e-5",
];

/// Problem: one run described by a TOML file and by the same options on the command line.
/// Reference: the command line's JSON report. The same report, byte for byte (J, σ,
/// status, the row model chosen), and not the default run's.
#[test]
fn a_run_file_is_the_same_options_on_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "slew", "slew", "120");
    let csv = csv.to_str().unwrap();
    let run = dir.path().join("run.toml");
    std::fs::write(&run, RUN).unwrap();
    let by_file = inertia(&[
        "estimate",
        csv,
        "--json",
        "--settings",
        run.to_str().unwrap(),
    ]);
    assert!(by_file.status.success(), "{}", stderr(&by_file));
    let mut args = vec!["estimate", csv, "--json"];
    args.extend_from_slice(OPTIONS);
    let by_options = inertia(&args);
    assert!(by_options.status.success(), "{}", stderr(&by_options));
    assert_eq!(json(&by_file), json(&by_options));
    let default = json(&inertia(&["estimate", csv, "--json"]));
    assert_ne!(json(&by_file)["j"], default["j"]);
    // JSON holds the same.
    let run_json = dir.path().join("run.json");
    std::fs::write(
        &run_json,
        r#"{"estimator": "discrete-momentum", "memory": 400.0, "every": 2, "rho_model": "held",
            "inertial_torque": "on", "chain": 20, "bounds": ["J33=2.7:3.3"], "gyro_noise": 1e-5}"#,
    )
    .unwrap();
    let o = inertia(&[
        "estimate",
        csv,
        "--json",
        "--settings",
        run_json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(json(&o), json(&by_options));
}

/// Problem: a run file and options that give some of the same settings. Reference: the
/// options alone for what they give, the file for the rest. The options win.
#[test]
fn options_given_override_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "slew", "slew", "60");
    let csv = csv.to_str().unwrap();
    let run = dir.path().join("run.toml");
    std::fs::write(&run, "estimator = \"momentum\"\nmemory = 30\n").unwrap();
    let run = run.to_str().unwrap();
    let both = json(&inertia(&[
        "estimate",
        csv,
        "--json",
        "--settings",
        run,
        "--estimator",
        "variational",
    ]));
    let options = json(&inertia(&[
        "estimate",
        csv,
        "--json",
        "--estimator",
        "variational",
        "--memory",
        "30",
    ]));
    assert_eq!(both, options);
    let file_only = json(&inertia(&["estimate", csv, "--json", "--settings", run]));
    assert_ne!(file_only["j"], both["j"]);
    let momentum = json(&inertia(&[
        "estimate",
        csv,
        "--json",
        "--estimator",
        "momentum",
        "--memory",
        "30",
    ]));
    assert_eq!(file_only, momentum);
}

/// Problem: run files with a misspelt key, a value of the wrong kind, an unknown name, a
/// value the settings refuse, a nominal without its tolerance. Reference: the file's name,
/// the line and the key in each parse error; exit code 2 for each.
#[test]
fn a_bad_run_file_names_the_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "slew", "slew", "20");
    let csv = csv.to_str().unwrap();
    for (name, text, needles) in [
        (
            "unknown.toml",
            "every = 2\n\nmemroy = 30\n",
            &["unknown.toml:3: `memroy`: unknown key `memroy`"][..],
        ),
        (
            "type.toml",
            "memory = \"long\"\n",
            &["type.toml:1: `memory`: invalid type: string \"long\", expected a number"][..],
        ),
        (
            "choice.toml",
            "# a comment\nrho_model = \"cubic\"\n",
            &["choice.toml:2: `rho_model`:", "auto, smooth, held, plain"][..],
        ),
        (
            "unknown.json",
            "{\n  \"every\": 2,\n  \"chian\": 3\n}\n",
            &["unknown.json:3: `chian`: unknown key `chian`"][..],
        ),
        // Validation is the settings' own, in the options' words.
        (
            "value.toml",
            "memory = -1\n",
            &["--memory -1: expected"][..],
        ),
        (
            "nominal.toml",
            "nominal = \"j.json\"\n",
            &["--nominal: needs --tolerance"][..],
        ),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let o = inertia(&["estimate", csv, "--settings", path.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
        for needle in needles {
            assert!(stderr(&o).contains(needle), "{name}: {}", stderr(&o));
        }
    }
    // Control characters in the file are printed escaped.
    let path = dir.path().join("escape.toml");
    std::fs::write(&path, "rho_model = \"\\u001b]0;retitled\\u0007\"\n").unwrap();
    let e = stderr(&inertia(&[
        "estimate",
        csv,
        "--settings",
        path.to_str().unwrap(),
    ]));
    assert!(!e.trim_end().chars().any(char::is_control), "{e:?}");
    // A run file that is not there is an input error naming it.
    let o = inertia(&["estimate", csv, "--settings", "no-such-run.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no-such-run.toml"), "{}", stderr(&o));
}
