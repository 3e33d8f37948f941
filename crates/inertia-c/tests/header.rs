//! `include/inertia.h` is what cbindgen makes of the crate now. On a difference the
//! test fails and shows how to refresh it: `INERTIA_BLESS=1 cargo test -p inertia-c --test header`.

use std::path::Path;

#[test]
fn the_checked_in_header_is_current() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).unwrap();
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen runs on the crate")
        .write(&mut generated);
    let generated = String::from_utf8(generated).unwrap();
    let path = crate_dir.join("include/inertia.h");
    if std::env::var_os("INERTIA_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        checked_in == generated,
        "{} is not what cbindgen generates from the crate now; refresh it with\n  INERTIA_BLESS=1 cargo test -p inertia-c --test header\n(first differing line: {:?})",
        path.display(),
        checked_in
            .lines()
            .zip(generated.lines())
            .find(|(a, b)| a != b)
    );
    // Every exported function is declared.
    for f in [
        "inertia_settings_default",
        "inertia_estimator_new",
        "inertia_estimator_size",
        "inertia_estimator_align",
        "inertia_estimator_init",
        "inertia_estimator_push",
        "inertia_estimator_get",
        "inertia_estimator_reason",
        "inertia_estimator_reset",
        "inertia_estimator_free",
        "inertia_last_error_message",
        "inertia_status_name",
    ] {
        assert!(
            generated.contains(&format!("{f}(")),
            "{f} missing from the header"
        );
    }
}
