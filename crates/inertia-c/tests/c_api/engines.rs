//! The fixed-size engine that runs in caller storage gives the library pipeline's
//! estimates bit for bit (J, σ, status, reason, after every sample), for both of its
//! estimators, with bounds, compensation, memory and `solve_every`; and each C setting
//! reaches the pipeline (a changed setting changes the answer).

use crate::common;
use common::*;
use inertia::sim::scenario::{Common, Scenario};
use inertia_c::*;

fn compare(scenario: Scenario, settings: InertiaSettings, label: &str) -> usize {
    let run = scenario.simulate(&Common::paper()).unwrap();
    let mut storage = Box::new(Storage([0; 1 << 16]));
    let (heap, fixed) = (new(&settings), init(&mut storage, &settings));
    let mut answers = 0;
    for (k, s) in run.samples.iter().enumerate() {
        let c = c_sample(s);
        assert_eq!(
            push(heap, &c),
            InertiaStatus::Ok,
            "{label} {k}: {}",
            last_error()
        );
        assert_eq!(
            push(fixed, &c),
            InertiaStatus::Ok,
            "{label} {k}: {}",
            last_error()
        );
        let (a, b) = (get(heap), get(fixed));
        assert!(
            same(&a, &b),
            "{label}: sample {k}: pipeline {a:?} fixed {b:?}"
        );
        answers += usize::from(a.has_answer == 1);
    }
    free(heap);
    free(fixed);
    answers
}

fn variational() -> InertiaSettings {
    InertiaSettings {
        estimator: estimator_id("variational"),
        ..inertia_settings_default()
    }
}

#[test]
fn variational_slew_physical() {
    assert!(compare(Scenario::slew(), variational(), "slew") > 2000);
}

#[test]
fn variational_spin_paper_constraints_and_j33_bound() {
    let mut s = variational();
    s.constraints = InertiaConstraintKind::Paper as u32;
    s.bound_lower_kg_m2[2] = 2.7;
    s.bound_upper_kg_m2[2] = 3.3;
    assert!(compare(Scenario::spin(), s, "spin") > 1000);
}

/// Prior knowledge (issue 13) in caller storage as on the heap: an equality and a
/// Gaussian prior on the spin, where the data alone lean on the constraint set.
#[test]
fn variational_spin_with_an_equality_and_a_gaussian_prior() {
    let mut s = variational();
    let truth = inertia::tensor::j_from_matrix(&Common::paper().inertia_kg_m2);
    s.bound_lower_kg_m2[3] = truth[3];
    s.bound_upper_kg_m2[3] = truth[3];
    s.prior_mean_kg_m2 = core::array::from_fn(|k| truth[k] * 1.01);
    s.prior_sigma_kg_m2 = core::array::from_fn(|k| 0.05 * truth[k].abs().max(0.5));
    assert!(compare(Scenario::spin(), s, "spin, prior") > 1000);
    let run = Scenario::spin().simulate(&Common::paper()).unwrap();
    let e = new(&s);
    for x in &run.samples {
        assert_eq!(push(e, &c_sample(x)), InertiaStatus::Ok, "{}", last_error());
    }
    let out = get(e);
    free(e);
    assert_eq!(out.j[3], truth[3], "the equality holds exactly");
    assert!(out.prior_chi2.is_finite(), "{out:?}");
    assert!(
        out.prior_data_share[3].is_nan(),
        "a fixed element has no share"
    );
    assert!(out.prior_data_share[0] > 0.0 && out.prior_data_share[0] <= 1.0);
}

#[test]
fn variational_with_compensation_memory_and_every() {
    let mut s = variational();
    s.gyro_noise_deg_s_rthz = 1e-5;
    s.memory_s = 60.0;
    s.solve_every = 3;
    assert!(compare(Scenario::slew(), s, "slew, compensated") > 500);
}

#[test]
fn finite_difference_slew() {
    let s = InertiaSettings {
        estimator: estimator_id("finite-difference"),
        ..inertia_settings_default()
    };
    assert!(compare(Scenario::slew(), s, "slew, finite difference") > 2000);
}

/// Each C setting reaches the estimator: the final J moves when it changes.
#[test]
fn settings_reach_the_estimator() {
    let run = Scenario::slew().simulate(&Common::paper()).unwrap();
    let final_j = |s: &InertiaSettings| final_estimate(s, &run.samples);
    let base = final_j(&variational());
    assert_eq!(base.has_answer, 1);
    for (name, s) in [
        (
            "memory_s",
            InertiaSettings {
                memory_s: 30.0,
                ..variational()
            },
        ),
        (
            "gyro_noise",
            InertiaSettings {
                gyro_noise_deg_s_rthz: 1e-3,
                ..variational()
            },
        ),
        ("constraints", {
            let mut s = variational();
            s.bound_upper_kg_m2[0] = 0.9; // J11 ≈ 1: the bound holds the answer
            s
        }),
        ("estimator", inertia_settings_default()),
    ] {
        let e = final_j(&s);
        assert!(e.j != base.j, "{name}: the same J as without it");
    }
    let no_sigma = final_j(&InertiaSettings {
        uncertainty: 0,
        ..variational()
    });
    assert_eq!((base.has_sigma, no_sigma.has_sigma), (1, 0));
    // A consider parameter moves σ, not J: each element's σ is √(σ² + (r ĵ)²).
    let r = 0.02;
    let scaled = final_j(&InertiaSettings {
        rotor_scale_sigma: r,
        ..variational()
    });
    assert_eq!(scaled.j, base.j);
    for k in 0..6 {
        let want = (base.sigma[k].powi(2) + (r * base.j[k]).powi(2)).sqrt();
        assert!(
            (scaled.sigma[k] - want).abs() <= 1e-12 * want,
            "element {k}"
        );
    }
}

/// A wheel momentum of the opposite sign stops both engines at the same sample, with the
/// same status and message (naming the fix in C's terms: negate `rho_nms`).
#[test]
fn a_reversed_wheel_momentum_stops_both_engines_alike() {
    let run = Scenario::slew().simulate(&Common::paper()).unwrap();
    for settings in [
        variational(),
        InertiaSettings {
            estimator: estimator_id("finite-difference"),
            ..inertia_settings_default()
        },
    ] {
        let mut storage = Box::new(Storage([0; 1 << 16]));
        let (heap, fixed) = (new(&settings), init(&mut storage, &settings));
        let mut stops = Vec::new();
        for est in [heap, fixed] {
            let stop = run.samples.iter().enumerate().find_map(|(k, s)| {
                let mut c = c_sample(s);
                for r in &mut c.rho_nms {
                    *r = -*r;
                }
                let status = push(est, &c);
                (status != InertiaStatus::Ok).then(|| (k, status, last_error()))
            });
            stops.push(stop.expect("stopped"));
            free(est);
        }
        assert_eq!(stops[0], stops[1]);
        assert_eq!(stops[0].1, InertiaStatus::Data);
        assert!(
            stops[0].2.contains("(in C: negate rho_nms") && !stops[0].2.contains("--"),
            "{}",
            stops[0].2
        );
    }
}

/// A memory shorter than the sample period is refused at the second sample by both engines,
/// as the command line and Python refuse it (`inertia::pipeline::check_first_step`).
#[test]
fn a_memory_shorter_than_the_step_is_refused_by_both_engines() {
    let run = Scenario::slew().simulate(&Common::paper()).unwrap();
    let settings = InertiaSettings {
        memory_s: 0.01,
        ..variational()
    };
    let mut storage = Box::new(Storage([0; 1 << 16]));
    for est in [new(&settings), init(&mut storage, &settings)] {
        assert_eq!(push(est, &c_sample(&run.samples[0])), InertiaStatus::Ok);
        assert_eq!(
            push(est, &c_sample(&run.samples[1])),
            InertiaStatus::InvalidSetting
        );
        let m = last_error();
        assert!(
            m.contains("the memory 0.01 s is shorter than the sample period")
                && m.contains("memory_s"),
            "{m}"
        );
        free(est);
    }
}

/// `inertial_torque` reaches the discrete momentum estimator: on the paper's slew, C with
/// `on` gives the library pipeline's final J with `InertialTorque::On` (to 1e-12
/// relative, as the C example against the CLI), and a different J from `off`.
#[test]
fn the_inertial_torque_reaches_the_discrete_momentum_estimator() {
    use inertia::pipeline::{InertialTorque, Pipeline, PipelineSettings};
    let run = Scenario::slew().simulate(&Common::paper()).unwrap();
    let c_final = |mode: InertiaInertialTorque| {
        let settings = InertiaSettings {
            inertial_torque: mode as u32,
            ..inertia_settings_default()
        };
        final_estimate(&settings, &run.samples).j
    };
    let mut p = Pipeline::new(&PipelineSettings {
        inertial_torque: InertialTorque::On,
        ..PipelineSettings::default()
    })
    .unwrap();
    for x in &run.samples {
        p.push(x).unwrap();
    }
    let library = p.last().and_then(|e| e.j()).expect("answer");
    let on = c_final(InertiaInertialTorque::On);
    let off = c_final(InertiaInertialTorque::Off);
    let gap = |a: &[f64; 6]| {
        (0..6)
            .map(|k| (a[k] - library[k]).abs())
            .fold(0.0, f64::max)
    };
    assert!(
        gap(&on) <= 1e-12 * library.norm(),
        "on: {on:?} against {library:?}"
    );
    assert!(
        gap(&off) > 1e-9 * library.norm(),
        "off gives on's answer: {off:?}"
    );
}

/// Every estimator of the library's registry, selected by its C id (its index from 1;
/// 0 the default), gives the library pipeline's estimate of the same name after every
/// sample of the paper's slew, bit for bit (J and σ); an id past the registry is refused.
#[test]
fn every_registered_estimator_by_id_is_the_pipelines() {
    use inertia::pipeline::registry::ESTIMATORS;
    use inertia::pipeline::{Pipeline, PipelineSettings};
    let run = Scenario::slew().simulate(&Common::paper()).unwrap();
    let ids = (0..=ESTIMATORS.len()).map(|k| u32::try_from(k).unwrap());
    for id in ids {
        let name = match id {
            0 => PipelineSettings::DEFAULT_ESTIMATOR,
            k => ESTIMATORS[k as usize - 1].name,
        };
        assert!(id == 0 || estimator_id(name) == id);
        let est = new(&InertiaSettings {
            estimator: id,
            ..inertia_settings_default()
        });
        // C's default inertial torque is off (the library's tests for one on a short
        // record).
        let mut p = Pipeline::new(&PipelineSettings {
            estimator: name.into(),
            inertial_torque: inertia::pipeline::InertialTorque::Off,
            ..PipelineSettings::default()
        })
        .unwrap();
        // The pipeline takes each sample as C's gate passes it (renormalised), and its
        // estimate is, as C keeps it, the one the last push returned.
        let mut gate = inertia::telemetry::gate::Gate::default();
        let (mut answers, mut last) = (0, None);
        for (k, x) in run.samples.iter().enumerate() {
            let c = c_sample(x);
            assert_eq!(
                push(est, &c),
                InertiaStatus::Ok,
                "{name} {k}: {}",
                last_error()
            );
            let gated = gate
                .check(&inertia::telemetry::gate::RawSample {
                    t_s: c.t_s,
                    q: c.q,
                    rho_nms: c.rho_nms,
                    tau_nm: Some(c.tau_nm),
                    w_rad_s: (c.has_w == 1).then_some(c.w_rad_s),
                    external: Default::default(),
                })
                .unwrap();
            if let Some(e) = p.push(&gated).unwrap() {
                last = Some(e);
            }
            let c = get(est);
            match last.and_then(|e: inertia::estimator::Estimate| e.j()) {
                Some(j) => {
                    answers += 1;
                    assert_eq!(c.has_answer, 1, "{name} {k}");
                    let bits = |a: &[f64]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&c.j), bits(j.as_slice()), "{name} {k}: J");
                    match last.and_then(|e| e.sigma_kg_m2()) {
                        Some(s) => {
                            assert_eq!(c.has_sigma, 1, "{name} {k}");
                            assert_eq!(bits(&c.sigma), bits(&s), "{name} {k}: σ");
                        }
                        None => assert_eq!(c.has_sigma, 0, "{name} {k}"),
                    }
                }
                None => assert_eq!(c.has_answer, 0, "{name} {k}"),
            }
        }
        free(est);
        assert!(answers > 0, "{name}: no answer");
    }
    let mut est = core::ptr::null_mut();
    let past = InertiaSettings {
        estimator: u32::try_from(ESTIMATORS.len() + 1).unwrap(),
        ..inertia_settings_default()
    };
    // SAFETY: valid pointers.
    let status = unsafe { inertia_estimator_new(&past, &mut est) };
    assert_eq!(status, InertiaStatus::InvalidSetting);
    assert!(
        last_error().contains("setting `estimator`"),
        "{}",
        last_error()
    );
}

/// `gyro_noise_estimate` reaches the discrete momentum estimator: on the paper's spin with
/// a MEMS gyro (2.5e-3 deg/s/√Hz, whose density the estimator finds in the rates), C's
/// default gives the library pipeline's final J with no density stated (estimated), and
/// `gyro_noise_estimate = 0` the pipeline's with a stated 0 (no compensation), each to
/// 1e-12 relative, and the two differ.
#[test]
fn the_gyro_density_estimate_reaches_the_discrete_momentum_estimator() {
    use inertia::pipeline::{Pipeline, PipelineSettings};
    let run = Scenario::spin()
        .simulate(&Common {
            gyro_noise_deg_s_rthz: 2.5e-3,
            ..Common::paper()
        })
        .unwrap();
    let c_final = |estimate: u8| {
        let settings = InertiaSettings {
            gyro_noise_estimate: estimate,
            solve_every: 50,
            ..inertia_settings_default()
        };
        final_estimate(&settings, &run.samples).j
    };
    let library = |gyro: Option<f64>| {
        let mut p = Pipeline::new(&PipelineSettings {
            gyro_noise_deg_s_rthz: gyro,
            solve_every: 50,
            ..PipelineSettings::default()
        })
        .unwrap();
        for x in &run.samples {
            p.push(x).unwrap();
        }
        let estimated = p.diagnostics().gyro_noise_estimated_rad_s_rthz;
        assert_eq!(estimated.is_some(), gyro.is_none(), "{estimated:?}");
        p.last().and_then(|e| e.j()).expect("answer")
    };
    let (estimated, none) = (library(None), library(Some(0.0)));
    let gap = |a: &[f64; 6], b: &inertia::tensor::InertiaVector| {
        (0..6).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max)
    };
    let (c_estimated, c_none) = (c_final(1), c_final(0));
    assert!(gap(&c_estimated, &estimated) <= 1e-12 * estimated.norm());
    assert!(gap(&c_none, &none) <= 1e-12 * none.norm());
    assert!(
        gap(&c_estimated, &none) > 1e-9 * none.norm(),
        "{c_estimated:?}"
    );
}
