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
    ] {
        let mut all = vec!["simulate", "--scenario", "slew", "--output", out];
        all.extend_from_slice(args);
        let o = inertia(&all);
        assert!(!o.status.success(), "{args:?} was accepted");
        assert!(stderr(&o).contains(names), "{args:?}: {}", stderr(&o));
        assert!(!std::path::Path::new(out).exists(), "{args:?} wrote a file");
    }
}
