//! The C API's contract: status codes for NULL, NaN, bad settings and storage, refused
//! samples that change nothing, a stop after a data error until reset, and the last
//! error message copied out like `snprintf`.

use crate::common;
use common::*;
use core::ptr::{null, null_mut};
use inertia::sim::scenario::{Common, Scenario};
use inertia_c::*;

fn variational() -> InertiaSettings {
    InertiaSettings {
        estimator: estimator_id("variational"),
        ..inertia_settings_default()
    }
}

fn slew() -> Vec<InertiaSample> {
    let c = Common {
        duration_s: Some(60.0),
        ..Common::paper()
    };
    Scenario::slew()
        .simulate(&c)
        .unwrap()
        .samples
        .iter()
        .map(c_sample)
        .collect()
}

#[test]
fn null_pointers_are_refused() {
    let s = variational();
    let mut est = null_mut();
    let mut storage = Box::new(Storage([0; 1 << 16]));
    let x = slew()[0];
    // SAFETY: every pointer is NULL or valid: the functions must refuse the NULL ones.
    unsafe {
        assert_eq!(
            inertia_estimator_new(null(), &mut est),
            InertiaStatus::NullPointer
        );
        assert_eq!(
            inertia_estimator_new(&s, null_mut()),
            InertiaStatus::NullPointer
        );
        let p = storage.0.as_mut_ptr().cast();
        assert_eq!(
            inertia_estimator_init(null_mut(), 1 << 16, &s, &mut est),
            InertiaStatus::NullPointer
        );
        assert_eq!(
            inertia_estimator_init(p, 1 << 16, null(), &mut est),
            InertiaStatus::NullPointer
        );
        assert_eq!(
            inertia_estimator_init(p, 1 << 16, &s, null_mut()),
            InertiaStatus::NullPointer
        );
        assert_eq!(
            inertia_estimator_push(null_mut(), &x),
            InertiaStatus::NullPointer
        );
        let e = init(&mut storage, &s);
        assert_eq!(
            inertia_estimator_push(e, null()),
            InertiaStatus::NullPointer
        );
        assert_eq!(
            inertia_estimator_get(null(), null_mut()),
            InertiaStatus::NullPointer
        );
        assert_eq!(
            inertia_estimator_get(e, null_mut()),
            InertiaStatus::NullPointer
        );
        assert_eq!(
            inertia_estimator_reset(null_mut()),
            InertiaStatus::NullPointer
        );
        assert_eq!(inertia_estimator_reason(null(), null_mut(), 0), 0);
        assert_eq!(
            inertia_last_error_message(null_mut(), 0),
            last_error().len()
        );
        inertia_estimator_free(null_mut());
        inertia_estimator_free(e);
    }
    assert!(
        last_error().contains("must not be NULL"),
        "{}",
        last_error()
    );
}

#[test]
fn bad_settings_name_the_setting() {
    let mut est = null_mut();
    let cases: Vec<(InertiaSettings, InertiaStatus, &str)> = vec![
        (
            InertiaSettings {
                memory_s: f64::NAN,
                ..variational()
            },
            InertiaStatus::NotFinite,
            "memory_s",
        ),
        (
            InertiaSettings {
                memory_s: -1.0,
                ..variational()
            },
            InertiaStatus::InvalidSetting,
            "memory_s",
        ),
        (
            InertiaSettings {
                estimator: 9,
                ..variational()
            },
            InertiaStatus::InvalidSetting,
            "estimator",
        ),
        (
            InertiaSettings {
                glitches: 2,
                ..variational()
            },
            InertiaStatus::InvalidSetting,
            "glitches",
        ),
        (
            InertiaSettings {
                rotation_source: 3,
                ..inertia_settings_default()
            },
            InertiaStatus::InvalidSetting,
            "`rotation_source` = 3 is invalid: expected 0 to 2",
        ),
        (
            InertiaSettings {
                solver: 3,
                ..inertia_settings_default()
            },
            InertiaStatus::InvalidSetting,
            "`solver` = 3 is invalid: expected 0 (default) to 2",
        ),
        (
            InertiaSettings {
                solve_every: 0,
                ..variational()
            },
            InertiaStatus::InvalidSetting,
            "solve_every",
        ),
        (
            InertiaSettings {
                gyro_noise_deg_s_rthz: -1e-5,
                ..variational()
            },
            InertiaStatus::InvalidSetting,
            "gyro_noise",
        ),
        (
            InertiaSettings {
                torque_bias: 0,
                ..variational()
            },
            InertiaStatus::InvalidSetting,
            "torque_bias",
        ),
        (
            InertiaSettings {
                rotor_scale_sigma: f64::NAN,
                ..inertia_settings_default()
            },
            InertiaStatus::NotFinite,
            "rotor_scale_sigma",
        ),
        (
            InertiaSettings {
                rotor_scale_sigma: 1.5,
                ..inertia_settings_default()
            },
            InertiaStatus::InvalidSetting,
            "rotor_scale_sigma",
        ),
        (
            InertiaSettings {
                inertial_torque: 4,
                ..inertia_settings_default()
            },
            InertiaStatus::InvalidSetting,
            "inertial_torque",
        ),
        (
            InertiaSettings {
                inertial_torque: InertiaInertialTorque::On as u32,
                ..variational()
            },
            InertiaStatus::InvalidSetting,
            "inertial_torque",
        ),
        (
            InertiaSettings {
                attitude_drift_deg_rth: 0.036,
                ..inertia_settings_default()
            },
            InertiaStatus::InvalidSetting,
            "gyro_noise_deg_s_rthz",
        ),
        (
            InertiaSettings {
                attitude_drift_deg_rth: 0.036,
                gyro_noise_deg_s_rthz: 6e-4,
                uncertainty: 0,
                ..inertia_settings_default()
            },
            InertiaStatus::InvalidSetting,
            "uncertainty",
        ),
        (
            InertiaSettings {
                attitude_drift_deg_rth: -1.0,
                ..inertia_settings_default()
            },
            InertiaStatus::InvalidSetting,
            "attitude_drift_deg_rth",
        ),
        (
            InertiaSettings {
                attitude_drift_deg_rth: 0.036,
                gyro_noise_deg_s_rthz: 6e-4,
                ..variational()
            },
            InertiaStatus::InvalidSetting,
            "attitude_drift_deg_rth",
        ),
        (
            {
                let mut s = variational();
                s.bound_lower_kg_m2[2] = 4.0;
                s.bound_upper_kg_m2[2] = 3.0;
                s
            },
            InertiaStatus::InvalidSetting,
            "J33",
        ),
        (
            {
                let mut s = variational();
                s.bound_lower_kg_m2[0] = f64::NAN;
                s
            },
            InertiaStatus::NotFinite,
            "J11",
        ),
    ];
    for (s, status, word) in cases {
        // SAFETY: valid pointers.
        let got = unsafe { inertia_estimator_new(&s, &mut est) };
        assert_eq!(got, status, "{word}");
        assert!(est.is_null());
        assert!(last_error().contains(word), "{word}: {}", last_error());
    }
}

/// Problem: settings the library refuses, given through C (heap and caller storage) and
/// through `PipelineSettings::validate` (the CLI's and Python's path). Reference: the
/// library's message. C keeps no checks of its own for these values: each is refused
/// with the library's message, through both of C's constructors (NaN as `NOT_FINITE`).
#[test]
fn bad_settings_get_the_library_message_in_c() {
    use inertia::pipeline::PipelineSettings;
    let lib = |f: fn(&mut PipelineSettings)| {
        let mut p = PipelineSettings {
            estimator: "variational".into(),
            ..PipelineSettings::default()
        };
        f(&mut p);
        p.validate().expect_err("refused").to_string()
    };
    /// The same bad value set in C's settings and in the library's.
    type Case = (fn(&mut InertiaSettings), fn(&mut PipelineSettings));
    let cases: Vec<Case> = vec![
        (|s| s.solve_every = 0, |p| p.solve_every = 0),
        (|s| s.memory_s = -1.0, |p| p.memory_s = Some(-1.0)),
        (
            |s| s.resample_s = f64::INFINITY,
            |p| p.resample_s = Some(f64::INFINITY),
        ),
        (
            |s| s.gyro_noise_deg_s_rthz = -2.0,
            |p| p.gyro_noise_deg_s_rthz = Some(-2.0),
        ),
        (|s| s.max_chain_s = -3.0, |p| p.max_chain_s = Some(-3.0)),
        (
            |s| s.rotor_scale_sigma = 1.5,
            |p| p.rotor_scale_sigma = Some(1.5),
        ),
        (
            |s| s.attitude_drift_deg_rth = -1.0,
            |p| p.attitude_drift_deg_rth = Some(-1.0),
        ),
        (
            |s| s.gyro_noise_deg_s_rthz = f64::NAN,
            |p| p.gyro_noise_deg_s_rthz = Some(f64::NAN),
        ),
    ];
    let mut storage = Box::new(Storage([0; 1 << 16]));
    let size = inertia_estimator_size();
    for (c, l) in cases {
        let want = lib(l);
        let mut s = variational();
        c(&mut s);
        let mut est = null_mut();
        // SAFETY: valid pointers; the storage is valid for `size` bytes.
        unsafe {
            assert_ne!(inertia_estimator_new(&s, &mut est), InertiaStatus::Ok);
            assert!(last_error().contains(&want), "{want} | {}", last_error());
            let p: *mut u8 = storage.0.as_mut_ptr();
            assert_ne!(
                inertia_estimator_init(p.cast(), size, &s, &mut est),
                InertiaStatus::Ok
            );
            assert!(last_error().contains(&want), "{want} | {}", last_error());
        }
    }
}

#[test]
fn storage_must_fit_and_only_fixed_estimators_go_there() {
    let mut storage = Box::new(Storage([0; 1 << 16]));
    let mut est = null_mut();
    let p: *mut u8 = storage.0.as_mut_ptr();
    let size = inertia_estimator_size();
    // SAFETY: the storage is valid for the lengths given.
    unsafe {
        let s = variational();
        assert_eq!(
            inertia_estimator_init(p.cast(), size - 1, &s, &mut est),
            InertiaStatus::BadStorage
        );
        assert_eq!(
            inertia_estimator_init(p.add(1).cast(), size, &s, &mut est),
            InertiaStatus::BadStorage
        );
        assert!(
            last_error().contains(&format!("needs {size} bytes")),
            "{}",
            last_error()
        );
        let d = inertia_settings_default();
        assert_eq!(
            inertia_estimator_init(p.cast(), size, &d, &mut est),
            InertiaStatus::NeedsHeap
        );
        assert!(
            last_error().contains("discrete-momentum"),
            "{}",
            last_error()
        );
        let r = InertiaSettings {
            resample_s: 0.1,
            ..variational()
        };
        assert_eq!(
            inertia_estimator_init(p.cast(), size, &r, &mut est),
            InertiaStatus::NeedsHeap
        );
        assert!(est.is_null());
        assert_eq!(
            inertia_estimator_init(p.cast(), size, &s, &mut est),
            InertiaStatus::Ok
        );
        assert_eq!(est.cast::<u8>(), p);
        inertia_estimator_free(est);
    }
}

#[test]
fn refused_samples_change_nothing() {
    let data = slew();
    let (a, b) = (new(&variational()), new(&variational()));
    for (k, x) in data.iter().enumerate() {
        if k % 50 == 7 {
            let bad = [
                (
                    InertiaSample {
                        q: [f64::NAN, 0.0, 0.0, 1.0],
                        ..*x
                    },
                    InertiaStatus::NotFinite,
                ),
                (
                    InertiaSample {
                        rho_nms: [0.0, 2e6, 0.0],
                        ..*x
                    },
                    InertiaStatus::OutOfRange,
                ),
                (
                    InertiaSample {
                        q: [0.1, 0.0, 0.0, 1.0],
                        ..*x
                    },
                    InertiaStatus::OutOfRange,
                ),
                (
                    InertiaSample {
                        t_s: x.t_s - 0.2,
                        ..*x
                    },
                    InertiaStatus::Data,
                ),
                (
                    InertiaSample {
                        has_w: 1 - x.has_w,
                        ..*x
                    },
                    InertiaStatus::Data,
                ),
            ];
            for (s, status) in bad {
                assert_eq!(push(a, &s), status, "{}", last_error());
            }
        }
        assert_eq!(push(a, x), InertiaStatus::Ok, "{}", last_error());
        assert_eq!(push(b, x), InertiaStatus::Ok);
        assert!(same(&get(a), &get(b)), "sample {k}");
    }
    assert_eq!(get(a).has_answer, 1);
    free(a);
    free(b);
}

#[test]
fn a_data_error_stops_until_reset() {
    let data = slew();
    let mut storage = Box::new(Storage([0; 1 << 16]));
    for est in [new(&variational()), init(&mut storage, &variational())] {
        for x in &data[..100] {
            assert_eq!(push(est, x), InertiaStatus::Ok);
        }
        // A 90° attitude jump over one step: a glitch against the gyro.
        let mut x = data[100];
        let q = inertia::attitude::Quaternion::from_xyzw(x.q);
        let turn =
            inertia::attitude::Quaternion::from_xyzw([0.0, 0.0, 0.5f64.sqrt(), 0.5f64.sqrt()]);
        let turned = q.mul(&turn);
        x.q = [turned.v.x, turned.v.y, turned.v.z, turned.s];
        assert_eq!(push(est, &x), InertiaStatus::Data, "{}", last_error());
        assert!(last_error().contains("glitch"), "{}", last_error());
        assert_eq!(push(est, &data[101]), InertiaStatus::Stopped);
        // SAFETY: `est` is live.
        assert_eq!(unsafe { inertia_estimator_reset(est) }, InertiaStatus::Ok);
        assert_eq!(get(est).status, InertiaEstimateStatus::None);
        assert_eq!(get(est).samples, 0);
        for x in &data {
            assert_eq!(push(est, x), InertiaStatus::Ok, "{}", last_error());
        }
        assert_eq!(get(est).has_answer, 1);
        free(est);
    }
}

#[test]
fn messages_are_copied_like_snprintf() {
    let s = InertiaSettings {
        memory_s: -2.0,
        ..variational()
    };
    let mut est = null_mut();
    // SAFETY: valid pointers.
    let got = unsafe { inertia_estimator_new(&s, &mut est) };
    assert_eq!(got, InertiaStatus::InvalidSetting);
    let whole = last_error();
    let mut small = [0xAAu8; 8];
    // SAFETY: `small` is writable for its length.
    let n = unsafe { inertia_last_error_message(small.as_mut_ptr().cast(), small.len()) };
    assert_eq!(n, whole.len());
    assert_eq!(&small[..7], &whole.as_bytes()[..7]);
    assert_eq!(small[7], 0);
    // Each thread has its own.
    std::thread::spawn(|| assert_eq!(last_error(), ""))
        .join()
        .unwrap();
    let name = |code: i32| {
        // SAFETY: `inertia_status_name` returns a static NUL-terminated string.
        unsafe { std::ffi::CStr::from_ptr(inertia_status_name(code)) }
            .to_str()
            .unwrap()
            .to_owned()
    };
    assert_eq!(name(InertiaStatus::Data as i32), "INERTIA_STATUS_DATA");
    assert_eq!(name(99), "INERTIA_STATUS_UNKNOWN");
}

#[test]
fn the_default_settings_are_the_pipelines() {
    // The C defaults, and the row-model values the fixed engine treats as defaults, are
    // `PipelineSettings::default()`'s, the estimator included.
    let d = inertia::pipeline::PipelineSettings::default();
    let c = inertia_settings_default();
    assert_eq!(d.estimator, "discrete-momentum");
    assert_eq!(c.estimator, 0); // the library's default, `d.estimator`
    assert_eq!(d.max_chain_s, Some(c.max_chain_s));
    assert_eq!(
        (d.torque_bias, d.uncertainty),
        (c.torque_bias == 1, c.uncertainty == 1)
    );
    assert_eq!(d.rotation_source, None);
    assert_eq!(
        d.rho_model,
        inertia::estimator::momentum_rows::RhoModel::Auto
    );
    assert_eq!(
        (
            d.memory_s,
            d.resample_s,
            d.gyro_noise_deg_s_rthz,
            d.solve_every
        ),
        (None, None, None, 1)
    );
    assert_eq!(
        d.constraints,
        inertia::constraints::ConstraintSet::physical()
    );
}

/// The header's named constants of the other choices select the library's value of the
/// same name (`Choice::ALL` by index; a rotation source's 0 is "from the data").
#[test]
fn the_choice_constants_are_the_librarys_values() {
    use inertia::choice::Choice;
    use inertia::constraints::Consistency;
    use inertia::estimator::momentum_rows::{RhoModel, RotationSource};
    use inertia::pipeline::InertialTorque;
    use inertia::telemetry::glitch::GlitchPolicy;
    fn name<T: Choice>(id: u32) -> &'static str {
        T::ALL[id as usize].choice_name()
    }
    for (id, n) in [
        (InertiaConstraintKind::Physical as u32, "physical"),
        (InertiaConstraintKind::Paper as u32, "paper"),
        (
            InertiaConstraintKind::PositiveDefinite as u32,
            "positive-definite",
        ),
    ] {
        assert_eq!(name::<Consistency>(id), n);
    }
    for (id, n) in [
        (InertiaRhoModel::Auto as u32, "auto"),
        (InertiaRhoModel::Smooth as u32, "smooth"),
        (InertiaRhoModel::Held as u32, "held"),
        (InertiaRhoModel::Plain as u32, "plain"),
    ] {
        assert_eq!(name::<RhoModel>(id), n);
    }
    for (id, n) in [
        (InertiaInertialTorque::Off as u32, "off"),
        (InertiaInertialTorque::On as u32, "on"),
        (InertiaInertialTorque::Auto as u32, "auto"),
        (InertiaInertialTorque::Short as u32, "short"),
    ] {
        assert_eq!(name::<InertialTorque>(id), n);
    }
    for (id, n) in [
        (InertiaGlitchPolicy::Stop as u32, "stop"),
        (InertiaGlitchPolicy::Keep as u32, "keep"),
    ] {
        assert_eq!(name::<GlitchPolicy>(id), n);
    }
    assert_eq!(InertiaRotationSource::Auto as u32, 0);
    for (id, n) in [
        (InertiaRotationSource::Attitude as u32, "attitude"),
        (InertiaRotationSource::Gyro as u32, "gyro"),
    ] {
        assert_eq!(name::<RotationSource>(id - 1), n);
    }
}
