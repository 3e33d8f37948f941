//! `simulate` refuses options it cannot honour, naming the option the user typed: a value
//! out of range names its option (with the simulator's setting beside it), an orbit below
//! the surface is refused, and an orbit inclination without an orbit is not silently
//! dropped.

use super::{inertia, stderr};

/// Problem: one bad value per option kind. Reference: the option's name in the message,
/// a failed exit and no file written.
#[test]
fn bad_simulate_options_name_the_option() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("x.csv");
    let out = out.to_str().expect("utf-8");
    for (args, names) in [
        (&["--gyro-arw-deg-rthr=-1"][..], "--gyro-arw-deg-rthr"),
        (&["--wheel-skew-s=nan"][..], "--wheel-skew-s"),
        (&["--star-tracker-hz=-1"][..], "--star-tracker-hz"),
        (&["--drag-nms=-1"][..], "--drag-nms"),
        (
            &["--gravity-gradient-altitude-km=-100"][..],
            "--gravity-gradient-altitude-km",
        ),
        (
            &["--orbit-inclination-deg=30"][..],
            "--gravity-gradient-altitude-km",
        ),
        (&["--duration=-5"][..], "--duration"),
        (&["--momentum-bias=0:0"][..], "--momentum-bias"),
    ] {
        let mut all = vec!["simulate", "--scenario", "slew", "--output", out];
        all.extend_from_slice(args);
        let o = inertia(&all);
        assert!(!o.status.success(), "{args:?} was accepted");
        assert!(stderr(&o).contains(names), "{args:?}: {}", stderr(&o));
        assert!(!std::path::Path::new(out).exists(), "{args:?} wrote a file");
    }
}

/// Problem: a momentum bias on the spin (which starts with its own momentum), and a
/// spacecraft file with thrusters but no rotors (whose speeds `simulate --spacecraft`
/// writes). Reference: each refused by the option's name and what to do instead, and no
/// file written.
#[test]
fn a_bias_on_the_spin_and_a_file_without_rotors_are_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("x.csv");
    let out = out.to_str().expect("utf-8");
    let sc = dir.path().join("thrusters.toml");
    std::fs::write(
        &sc,
        "[[thruster]]\nname = \"t1\"\nposition_m = [0.3, 0.0, 0.0]\ndirection = [0.0, 1.0, 0.0]\nthrust_n = 0.02\ncolumn = \"t1_throttle\"\n",
    )
    .expect("write");
    let sc = sc.to_str().expect("utf-8");
    for (args, says) in [
        (
            ["spin", "--momentum-bias", "0:0:0.1"],
            &["--momentum-bias: the spin"][..],
        ),
        (
            ["slew", "--spacecraft", sc],
            &["thrusters.toml: the file lists no rotors", "--thrusters"][..],
        ),
    ] {
        let mut all = vec!["simulate", "-o", out, "--scenario"];
        all.extend_from_slice(&args);
        let o = inertia(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let e = stderr(&o);
        assert!(says.iter().all(|s| e.contains(s)), "{args:?}: {e}");
        assert!(!std::path::Path::new(out).exists(), "{args:?} wrote a file");
    }
}
