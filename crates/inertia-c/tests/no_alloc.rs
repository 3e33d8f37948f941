//! What allocates, counted with a counting global allocator (`allocation-counter`).
//!
//! * Caller storage (`inertia_estimator_init`, variational and finite-difference): zero
//!   allocations over `init`, whole simulated runs of pushes (fast-path and constrained
//!   solves, σ's half-rate shadow), reading every estimate and reason, refused samples
//!   with their error messages, `reset` and a second run. Required, not just measured.
//! * Heap (`inertia_estimator_new`): creation and the first pushes allocate; after the
//!   first 100 samples of a slew no push allocates, for every estimator (required;
//!   printed with `cargo test -p inertia-c --test no_alloc -- --nocapture`).

#[path = "c_api/common/mod.rs"]
mod common;
use common::*;
use inertia::sim::scenario::{Common, Scenario};
use inertia_c::*;

fn settings(kind: &str) -> InertiaSettings {
    InertiaSettings {
        estimator: estimator_id(kind),
        ..inertia_settings_default()
    }
}

#[test]
fn caller_storage_never_allocates() {
    for (scenario, kind) in [
        (Scenario::slew(), "variational"),
        (Scenario::spin(), "variational"),
        (Scenario::slew(), "finite-difference"),
    ] {
        let name = scenario.name();
        let mut s = settings(kind);
        if name == "spin" {
            s.constraints = InertiaConstraintKind::Paper as u32;
            s.bound_lower_kg_m2[2] = 2.7;
            s.bound_upper_kg_m2[2] = 3.3;
        }
        let samples: Vec<InertiaSample> = scenario
            .simulate(&Common::paper())
            .unwrap()
            .samples
            .iter()
            .map(c_sample)
            .collect();
        let mut storage = Box::new(Storage([0; 1 << 16]));
        let (mut answers, mut refused, mut reason_bytes) = (0usize, 0usize, 0usize);
        let mut reason = [0u8; 512];
        let info = allocation_counter::measure(|| {
            let est = init(&mut storage, &s);
            for round in 0..2 {
                for (k, x) in samples.iter().enumerate() {
                    assert_eq!(push(est, x), InertiaStatus::Ok);
                    let e = get(est);
                    answers += usize::from(e.has_answer == 1);
                    // SAFETY: `reason` is writable for its length.
                    reason_bytes += unsafe {
                        inertia_estimator_reason(est, reason.as_mut_ptr().cast(), reason.len())
                    };
                    if k == 100 {
                        // Refused samples leave the estimator as it was.
                        let nan = InertiaSample {
                            t_s: f64::NAN,
                            ..*x
                        };
                        let back = InertiaSample {
                            t_s: x.t_s - 1.0,
                            ..*x
                        };
                        assert_eq!(push(est, &nan), InertiaStatus::NotFinite);
                        assert_eq!(push(est, &back), InertiaStatus::Data);
                        refused += 2;
                    }
                }
                if round == 0 {
                    // SAFETY: `est` is live.
                    assert_eq!(unsafe { inertia_estimator_reset(est) }, InertiaStatus::Ok);
                }
            }
            free(est);
        });
        assert!(
            answers > samples.len() && refused == 4 && reason_bytes > 0,
            "{name}: {answers} answers, {refused} refused, {reason_bytes} reason bytes"
        );
        assert_eq!(
            info.count_total, 0,
            "{name} {kind:?} in caller storage: {} allocations ({} bytes)",
            info.count_total, info.bytes_total
        );
        println!(
            "{name} {kind:?}, caller storage: {} samples x 2 runs, {answers} answers: {} allocations",
            samples.len(),
            info.count_total
        );
    }
}

/// Heap estimators: creation and the first samples allocate (the discrete momentum
/// estimator builds its candidates at the first sample); after the first 100 samples no
/// push allocates, for every estimator. Printed with `-- --nocapture`.
#[test]
fn heap_estimators_do_not_allocate_after_warm_up() {
    let samples: Vec<InertiaSample> = Scenario::slew()
        .simulate(&Common::paper())
        .unwrap()
        .samples
        .iter()
        .map(c_sample)
        .collect();
    for kind in [
        "discrete-momentum",
        "variational",
        "finite-difference",
        "momentum",
    ] {
        let mut est = core::ptr::null_mut();
        let creation = allocation_counter::measure(|| est = new(&settings(kind)));
        let warm_up = allocation_counter::measure(|| {
            for x in &samples[..100] {
                assert_eq!(push(est, x), InertiaStatus::Ok);
            }
        });
        let mut answers = 0;
        let rest = allocation_counter::measure(|| {
            for x in &samples[100..] {
                assert_eq!(push(est, x), InertiaStatus::Ok);
                answers += usize::from(get(est).has_answer == 1);
            }
        });
        println!(
            "{kind}, heap: creation {} allocations, first 100 pushes {}, next {} pushes {} ({answers} answers)",
            creation.count_total,
            warm_up.count_total,
            samples.len() - 100,
            rest.count_total
        );
        free(est);
        assert!(creation.count_total > 0 && answers > 2000);
        assert_eq!(
            rest.count_total, 0,
            "{kind:?}: {} allocations ({} bytes) after warm-up",
            rest.count_total, rest.bytes_total
        );
    }
}

/// Control: the counter sees allocations (so the test above can fail).
#[test]
fn the_counter_counts() {
    let info = allocation_counter::measure(|| {
        let v: Vec<f64> = Vec::with_capacity(std::hint::black_box(16));
        std::hint::black_box(v);
    });
    assert_eq!(info.count_total, 1);
}
