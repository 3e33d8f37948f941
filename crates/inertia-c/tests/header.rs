//! `include/inertia.h` is what cbindgen makes of the crate now, with the estimator and
//! solver ids generated from the library's registry. On a difference the test fails and
//! shows how to refresh it: `INERTIA_BLESS=1 cargo test -p inertia-c --test header`.

use inertia::pipeline::registry::{BACKENDS, ESTIMATORS};
use inertia::pipeline::PipelineSettings;
use std::fmt::Write;
use std::path::Path;

/// `INERTIA_<KIND>_<NAME>` constants for a registry's entries: 0 the default, entry
/// `k − 1` is `k` (the mapping `crates/inertia-c/src/settings.rs` applies).
fn ids(kind: &str, field: &str, names: &[(&str, &str)], default: &str) -> String {
    let constant = |name: &str| format!("INERTIA_{kind}_{}", name.replace('-', "_").to_uppercase());
    let mut out = format!(
        "// Ids of `InertiaSettings::{field}`, in the order of the library's registry\n// (`inertia::pipeline::registry`); 0 is the library's default ({default}).\nenum {{\n  {} = 0,\n",
        constant("default")
    );
    for (k, (name, summary)) in names.iter().enumerate() {
        writeln!(
            out,
            "  // `{name}`: {summary}.\n  {} = {},",
            constant(name),
            k + 1
        )
        .unwrap();
    }
    out + "};\n"
}

/// The registry's ids as C constants (the header's `after_includes`).
fn registry_ids() -> String {
    let estimators: Vec<_> = ESTIMATORS.iter().map(|e| (e.name, e.summary)).collect();
    let backends: Vec<_> = BACKENDS.iter().map(|e| (e.name, e.summary)).collect();
    format!(
        "\n{}\n{}",
        ids(
            "ESTIMATOR",
            "estimator",
            &estimators,
            PipelineSettings::DEFAULT_ESTIMATOR
        ),
        ids(
            "SOLVER",
            "solver",
            &backends,
            PipelineSettings::DEFAULT_SOLVER
        )
    )
}

#[test]
fn the_checked_in_header_is_current() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).unwrap();
    config.after_includes = Some(registry_ids());
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
    // Every registered estimator and backend has its id.
    for (k, name) in ESTIMATORS.iter().map(|e| e.name).enumerate() {
        let line = format!(
            "INERTIA_ESTIMATOR_{} = {},",
            name.replace('-', "_").to_uppercase(),
            k + 1
        );
        assert!(generated.contains(&line), "{line} missing from the header");
    }
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
