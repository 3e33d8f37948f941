//! The library pipeline: memory in seconds (resampling, jitter, gaps), every registered
//! estimator through one API, and constructors that reject bad input with typed errors.

use inertia::constraints::ConstraintSet;
use inertia::discrete::RowError;
use inertia::estimator::momentum::{MomentumRls, MomentumSettings};
use inertia::estimator::resample::Resampler;
use inertia::estimator::{Estimate, EstimatorError};
use inertia::pipeline::registry::ESTIMATORS;
use inertia::pipeline::{self, Pipeline, PipelineError, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{InertiaChange, SimOutput};
use inertia::solver::native::{NativeSettings, NativeSolver};
use inertia::tensor::{matrix_from_j, relative_frobenius_error, Component};
use nalgebra::{Matrix3, Vector3};

/// The paper's slew at step `dt_s` with J stepping by +10 % at 150 s.
fn stepped_slew(dt_s: f64) -> SimOutput {
    let j0 = Scenario::slew()
        .simulate(&Common::noise_free())
        .unwrap()
        .inertia_kg_m2;
    Scenario::slew()
        .simulate(&Common {
            dt_s,
            inertia_change: Some(InertiaChange::Step {
                at_s: 150.0,
                to_kg_m2: j0 * 1.1,
            }),
            ..Common::paper()
        })
        .unwrap()
}

fn run(samples: &[Sample], settings: &PipelineSettings) -> Vec<Estimate> {
    let mut p = Pipeline::new(settings).unwrap();
    let mut out = Vec::new();
    for s in samples {
        p.push_each(s, |e| out.push(*e)).unwrap();
    }
    out
}

/// Error of the estimate nearest `t_s` against the true J at that time.
fn error_at(history: &[Estimate], out: &SimOutput, t_s: f64) -> f64 {
    let e = history
        .iter()
        .min_by(|a, b| (a.t_s - t_s).abs().total_cmp(&(b.t_s - t_s).abs()))
        .unwrap();
    assert!((e.t_s - t_s).abs() < 0.2, "no estimate near {t_s}");
    relative_frobenius_error(&e.inertia().expect("an answer"), &out.inertia_at(t_s))
}

fn with_memory(memory_s: f64, resample_s: Option<f64>) -> PipelineSettings {
    PipelineSettings {
        memory_s: Some(memory_s),
        resample_s,
        uncertainty: false,
        ..PipelineSettings::default()
    }
}

/// Memory is a time constant in seconds: a 30 s memory tracks a +10 % step in J the same
/// way on the raw 10 Hz telemetry, resampled to 20 Hz, and on a ±20 % jittered grid.
#[test]
fn memory_in_seconds_is_independent_of_the_sampling() {
    let raw = stepped_slew(0.1);
    let base = error_at(&run(&raw.samples, &with_memory(30.0, None)), &raw, 220.0);
    let resampled = error_at(
        &run(&raw.samples, &with_memory(30.0, Some(0.05))),
        &raw,
        220.0,
    );
    // Jitter: the same run simulated at 0.02 s, kept at steps of 4, 5 or 6 fine steps.
    let fine = stepped_slew(0.02);
    let mut jittered = Vec::new();
    let (mut k, mut state) = (0usize, 12345u64);
    while k < fine.samples.len() {
        jittered.push(fine.samples[k]);
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        k += 4 + (state >> 33) as usize % 3;
    }
    let jitter = error_at(&run(&jittered, &with_memory(30.0, None)), &fine, 220.0);
    eprintln!("error at 220 s: raw {base:.3e}, resampled {resampled:.3e}, jittered {jitter:.3e}");
    for (what, e) in [("resampled", resampled), ("jittered", jitter)] {
        assert!(
            (e / base - 1.0).abs() < 0.2,
            "{what}: {e:e} against {base:e} on the raw grid"
        );
    }
    // And the memory does its job: once the slews after the step have excited every
    // axis it has forgotten the old J; without it the estimate is a blend of both.
    let late = error_at(&run(&raw.samples, &with_memory(30.0, None)), &raw, 290.0);
    let none = error_at(
        &run(
            &raw.samples,
            &PipelineSettings {
                uncertainty: false,
                ..PipelineSettings::default()
            },
        ),
        &raw,
        290.0,
    );
    assert!(
        late < 0.5 * none,
        "at 290 s: memory {late:e}, none {none:e}"
    );
}

/// Across a gap of an hour, a 30 s memory forgets everything before it: the estimate
/// after the gap equals the one from the data after the gap alone.
#[test]
fn memory_decays_across_a_gap() {
    let out = Scenario::slew().simulate(&Common::paper()).unwrap();
    let (before, after) = out.samples.split_at(1200);
    let mut gapped: Vec<Sample> = before.to_vec();
    gapped.extend(after.iter().map(|s| Sample {
        t_s: s.t_s + 3600.0,
        ..*s
    }));
    let settings = with_memory(30.0, None);
    let whole = run(&gapped, &settings);
    let alone = run(after, &settings);
    let (a, b) = (whole.last().unwrap(), alone.last().unwrap());
    let (ja, jb) = (a.j().unwrap(), b.j().unwrap());
    assert!(
        (ja - jb).norm() <= 1e-9 * jb.norm(),
        "with the old data {ja:?}, without {jb:?}"
    );
    let mut p = Pipeline::new(&settings).unwrap();
    for s in &gapped {
        p.push(s).unwrap();
    }
    assert_eq!(p.diagnostics().gaps, 1);
}

/// Every registered estimator runs through the same API and returns the same type, and
/// the batch form agrees with the recursive one where both exist.
#[test]
fn every_registered_estimator_runs_through_the_pipeline() {
    let out = Scenario::slew().simulate(&Common::paper()).unwrap();
    for entry in ESTIMATORS {
        let settings = PipelineSettings {
            estimator: entry.name.into(),
            ..PipelineSettings::default()
        };
        let history = run(&out.samples, &settings);
        let last = history.last().expect("estimates");
        let err = relative_frobenius_error(&last.inertia().unwrap(), &out.inertia_kg_m2);
        assert!(err < 2e-4, "{}: {err:e}", entry.name);
        assert_eq!(last.uncertainty.is_some(), entry.capabilities.uncertainty);
        if entry.has_batch() {
            let config = PipelineSettings {
                uncertainty: false,
                ..settings
            }
            .validate()
            .unwrap();
            let b = pipeline::batch(&out.samples, &config).unwrap();
            let jb = b.estimate.j().unwrap();
            let jr = last.j().unwrap();
            assert!((jb - jr).norm() < 1e-7 * jr.norm(), "{}", entry.name);
            assert!(b.diagnostics.excitation.is_some());
        }
    }
}

#[test]
fn settings_are_validated_with_typed_errors() {
    let v = |s: PipelineSettings| s.validate().map(drop).unwrap_err();
    let d = PipelineSettings::default;
    assert!(matches!(
        v(PipelineSettings {
            estimator: "kalman".into(),
            ..d()
        }),
        PipelineError::UnknownEstimator { .. }
    ));
    assert!(matches!(
        v(PipelineSettings {
            solver: "mosek".into(),
            ..d()
        }),
        PipelineError::UnknownSolver { .. }
    ));
    #[cfg(not(feature = "clarabel"))]
    assert!(matches!(
        v(PipelineSettings {
            solver: "clarabel".into(),
            ..d()
        }),
        PipelineError::SolverUnavailable { .. }
    ));
    for (field, s) in [
        (
            "solve_every",
            PipelineSettings {
                solve_every: 0,
                ..d()
            },
        ),
        (
            "memory_s",
            PipelineSettings {
                memory_s: Some(0.0),
                ..d()
            },
        ),
        (
            "memory_s",
            PipelineSettings {
                memory_s: Some(f64::NAN),
                ..d()
            },
        ),
        (
            "resample_s",
            PipelineSettings {
                resample_s: Some(-1.0),
                ..d()
            },
        ),
        (
            "gyro_noise_deg_s_rthz",
            PipelineSettings {
                gyro_noise_deg_s_rthz: Some(f64::INFINITY),
                ..d()
            },
        ),
    ] {
        match v(s) {
            PipelineError::InvalidSetting { field: f, .. } => assert_eq!(f, field),
            other => panic!("{field}: {other}"),
        }
    }
    // Options an estimator would ignore are refused, not ignored.
    let momentum = |s: PipelineSettings| PipelineSettings {
        estimator: "momentum".into(),
        ..s
    };
    assert!(matches!(
        v(momentum(PipelineSettings {
            gyro_noise_deg_s_rthz: Some(1e-5),
            ..d()
        })),
        PipelineError::NotApplicable {
            setting: "gyro_noise_deg_s_rthz",
            ..
        }
    ));
    assert!(matches!(
        v(momentum(PipelineSettings {
            constraints: ConstraintSet::paper(),
            ..d()
        })),
        PipelineError::NotApplicable {
            setting: "constraints",
            ..
        }
    ));
    assert!(matches!(
        v(PipelineSettings {
            constraints: ConstraintSet::physical().with_bounds(
                Component::J11,
                Some(2.0),
                Some(1.0)
            ),
            ..d()
        }),
        PipelineError::Constraints(_)
    ));
    // Batch refuses memory and resampling.
    let c = PipelineSettings {
        memory_s: Some(10.0),
        ..d()
    }
    .validate()
    .unwrap();
    assert!(matches!(
        pipeline::batch(&[], &c),
        Err(PipelineError::NotApplicable {
            setting: "memory_s",
            ..
        })
    ));
}

#[test]
fn constructors_reject_bad_input() {
    for h in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert_eq!(Resampler::new(h).unwrap_err().name, "h_s");
    }
    for p0 in [0.0, -1.0, f64::NAN] {
        let e = MomentumRls::new(MomentumSettings {
            p0,
            ..MomentumSettings::default()
        });
        assert_eq!(e.unwrap_err().name, "p0");
    }
    let e = MomentumRls::new(MomentumSettings {
        memory_s: Some(0.0),
        ..MomentumSettings::default()
    });
    assert_eq!(e.unwrap_err().name, "memory_s");
    let mut bad = NativeSettings::default();
    bad.barrier.gap_tolerance = -1.0;
    assert!(NativeSolver::new(bad).is_err());
    use inertia::attitude::Quaternion;
    use inertia::sim::control::{Slew, SlewController};
    let slew = |start_s, duration_s, axis| Slew {
        axis,
        angle_rad: 1.0,
        start_s,
        duration_s,
    };
    let x = Vector3::x();
    for (what, slews, wn) in [
        ("frequency", vec![slew(0.0, 10.0, x)], 0.0),
        ("duration", vec![slew(0.0, 0.0, x)], 0.5),
        ("overlap", vec![slew(0.0, 10.0, x), slew(5.0, 10.0, x)], 0.5),
        ("axis", vec![slew(0.0, 10.0, Vector3::zeros())], 0.5),
    ] {
        assert!(
            SlewController::new(Matrix3::identity(), Quaternion::IDENTITY, slews, wn, 0.7).is_err(),
            "{what}"
        );
    }
    // The momentum RLS without gyro rates: a typed error, not NaN.
    let mut s = Scenario::slew().simulate(&Common::paper()).unwrap().samples[0];
    s.omega_rad_s = None;
    let err = MomentumRls::default().push(&s).unwrap_err();
    assert!(
        matches!(
            err,
            EstimatorError::Row {
                source: RowError::MissingGyroRate,
                ..
            }
        ),
        "{err}"
    );
}

/// `docs/conventions.md` §6: the products of inertia are tensor entries, `J12 = −Σ m x y`
/// (so that `H = J ω`), the opposite sign of a CAD tool's product of inertia.
#[test]
fn products_of_inertia_are_tensor_entries() {
    // Point masses: J = Σ m (|r|² I − r rᵀ).
    let masses = [
        (2.0, Vector3::new(1.0, 1.0, 0.0)),
        (1.0, Vector3::new(0.5, -0.2, 0.3)),
    ];
    let j: Matrix3<f64> = masses
        .iter()
        .map(|(m, r)| (Matrix3::identity() * r.norm_squared() - r * r.transpose()) * *m)
        .sum();
    let pxy: f64 = masses.iter().map(|(m, r)| m * r.x * r.y).sum();
    assert!((j[(0, 1)] + pxy).abs() < 1e-15);
    let jv = inertia::tensor::j_from_matrix(&j);
    assert_eq!(jv[Component::J12.index()], j[(0, 1)]);
    assert_eq!(matrix_from_j(&jv), j);
    // The angular momentum of a rigid body spinning about z: H = J ω, also from Σ m r × (ω × r).
    let w = Vector3::new(0.0, 0.0, 1.0);
    let h: Vector3<f64> = masses.iter().map(|(m, r)| r.cross(&w.cross(r)) * *m).sum();
    assert!((j * w - h).norm() < 1e-14);
}

/// "Determined" is withdrawn on deliberately broken telemetry.
mod status {
    use inertia::attitude::Quaternion;
    use inertia::constraints::ConstraintSet;
    use inertia::estimator::observability::{Observability, Unobservable};
    use inertia::fix::Fix;
    use inertia::pipeline::{Pipeline, PipelineError, PipelineSettings};
    use inertia::sample::Sample;
    use inertia::sim::scenario::{Common, Scenario};
    use inertia::telemetry::convention::Verdict;
    use inertia::tensor::{matrix_from_j, relative_frobenius_error};

    fn run(
        samples: &[Sample],
        settings: &PipelineSettings,
    ) -> Result<Observability, PipelineError> {
        let mut p = Pipeline::new(settings)?;
        for s in samples {
            p.push(s)?;
        }
        Ok(p.last().expect("estimates").observability)
    }

    fn slew() -> Vec<Sample> {
        Scenario::slew()
            .simulate(&Common {
                duration_s: Some(120.0),
                ..Common::paper()
            })
            .expect("sim")
            .samples
    }

    fn settings(estimator: &str) -> PipelineSettings {
        PipelineSettings {
            estimator: estimator.into(),
            constraints: ConstraintSet::positive_definite(),
            ..PipelineSettings::default()
        }
    }

    #[test]
    fn a_wrong_quaternion_convention_stops_with_the_option_that_fixes_it() {
        let good = slew();
        for (name, f, fixes) in [
            (
                "conjugated",
                (|q: &Quaternion| q.conjugate()) as fn(&Quaternion) -> Quaternion,
                &[Fix::Conjugate] as &[Fix],
            ),
            (
                "scalar first",
                |q: &Quaternion| {
                    let [w, x, y, z] = q.to_wxyz();
                    Quaternion::from_xyzw([w, x, y, z])
                },
                &[Fix::ScalarFirst],
            ),
            (
                // A scalar-last file read with --scalar-first: (w, x, y, z) := (x, y, z, w).
                "scalar last read as scalar first",
                |q: &Quaternion| {
                    let [x, y, z, w] = q.to_xyzw();
                    Quaternion::from_wxyz([x, y, z, w])
                },
                &[Fix::ScalarLast],
            ),
            (
                // Conjugated (inertial → body) quaternions stored scalar first.
                "scalar first and conjugated",
                |q: &Quaternion| {
                    let [w, x, y, z] = q.conjugate().to_wxyz();
                    Quaternion::from_xyzw([w, x, y, z])
                },
                &[Fix::ScalarFirst, Fix::Conjugate],
            ),
            (
                // Conjugated quaternions stored scalar last, read as scalar first.
                "scalar last read as scalar first, conjugated",
                |q: &Quaternion| {
                    let [x, y, z, w] = q.conjugate().to_xyzw();
                    Quaternion::from_wxyz([x, y, z, w])
                },
                &[Fix::ScalarLast, Fix::Conjugate],
            ),
        ] {
            let bad: Vec<Sample> = good.iter().map(|s| Sample { q: f(&s.q), ..*s }).collect();
            for estimator in ["discrete-momentum", "variational"] {
                let e = run(&bad, &settings(estimator)).expect_err(name);
                assert!(
                    matches!(e, PipelineError::AttitudeConvention { .. }) && e.fixes() == fixes,
                    "{name}, {estimator}: {e}"
                );
                // The message says it in words, and names no option of a front end.
                assert!(!e.to_string().contains("--"), "{e}");
                let b =
                    inertia::pipeline::batch(&bad, &settings(estimator).validate().expect("valid"))
                        .expect_err("batch");
                assert_eq!(b.fixes(), fixes, "{b}");
            }
        }
        // Gyro rates of the opposite sign: the rates are named, not the quaternions.
        let negated: Vec<Sample> = good
            .iter()
            .map(|s| Sample {
                omega_rad_s: s.omega_rad_s.map(|w| -w),
                ..*s
            })
            .collect();
        let e = run(&negated, &settings("discrete-momentum")).expect_err("negated gyro");
        assert!(
            matches!(e, PipelineError::AttitudeConvention { .. })
                && e.to_string().contains("sign of w_x"),
            "{e}"
        );
        // The good data pass the same check.
        assert!(run(&good, &settings("discrete-momentum")).is_ok());
    }

    #[test]
    fn attitude_and_gyro_that_disagree_widen_sigma_or_are_not_determined() {
        // A gyro scale factor error: the attitude (propagated from the true rates) and the
        // gyro fit equally well but give J differing by the scale factor. Which is right
        // the data cannot say: σ must cover both, and a gross disagreement is refused.
        let good = slew();
        let scaled = |f: f64| -> Vec<Sample> {
            good.iter()
                .map(|s| Sample {
                    omega_rad_s: s.omega_rad_s.map(|w| w * f),
                    ..*s
                })
                .collect()
        };
        let truth = inertia::tensor::j_from_matrix(&inertia::tensor::paper_j_true());
        for recursive in [true, false] {
            let last = |samples: &[Sample]| -> inertia::estimator::Estimate {
                let s = settings("discrete-momentum");
                if recursive {
                    let mut p = Pipeline::new(&s).expect("pipeline");
                    for x in samples {
                        p.push(x).expect("push");
                    }
                    *p.last().expect("estimate")
                } else {
                    inertia::pipeline::batch(samples, &s.validate().expect("valid"))
                        .expect("batch")
                        .estimate
                }
            };
            let e = last(&scaled(1.02));
            assert!(
                matches!(e.observability, Observability::Determined { .. }),
                "{:?}",
                e.observability
            );
            let (j, sigma) = (e.j().expect("j"), e.sigma_kg_m2().expect("σ"));
            for k in 0..6 {
                assert!(
                    (j[k] - truth[k]).abs() <= 3.0 * sigma[k],
                    "recursive {recursive}, element {k}: error {:e} vs σ {:e}",
                    j[k] - truth[k],
                    sigma[k]
                );
            }
            assert!(sigma[2] > 0.005 * truth[2], "σ widened: {sigma:?}");
            let e = last(&scaled(1.5));
            assert!(
                matches!(
                    e.observability,
                    Observability::NotObservable(Unobservable::SourcesDisagree { z }) if z > 5.0
                ),
                "recursive {recursive}: {:?}",
                e.observability
            );
        }
    }

    #[test]
    fn a_half_rate_shadow_that_cannot_form_rows_does_not_stop_the_run() {
        // 45°/s about z at 1 Hz: each step turns 45°, the shadow's double step 90°, and
        // its Richardson stencil (two double steps) 180°, which no row can take.
        let w = core::f64::consts::FRAC_PI_4;
        let samples: Vec<Sample> = (0..60)
            .map(|k| {
                let t = f64::from(k);
                Sample {
                    t_s: t,
                    q: Quaternion::exp(&nalgebra::Vector3::new(0.0, 0.0, w * t)),
                    rho_nms: nalgebra::Vector3::new(0.01 * t.sin(), 0.0, 0.1),
                    tau_nm: nalgebra::Vector3::zeros(),
                    omega_rad_s: Some(nalgebra::Vector3::new(0.0, 0.0, w)),
                    external: Default::default(),
                }
            })
            .collect();
        let mut p = Pipeline::new(&settings("discrete-momentum")).expect("pipeline");
        for (i, s) in samples.iter().enumerate() {
            p.push(s).unwrap_or_else(|e| panic!("sample {i}: {e}"));
        }
    }

    #[test]
    fn a_reversed_wheel_momentum_sign_stops_with_the_option_that_fixes_it() {
        // ρ negated: the least-squares answer is −J (the rows are linear in j and ρ), which
        // the J ⪰ εI floor refuses and whose negation would be determined.
        let negated = |s: &Sample| Sample {
            rho_nms: -s.rho_nms,
            ..*s
        };
        let spin = Scenario::spin()
            .simulate(&Common {
                duration_s: Some(120.0),
                ..Common::paper()
            })
            .expect("sim")
            .samples;
        for (case, good) in [("slew", slew()), ("spin", spin)] {
            let bad: Vec<Sample> = good.iter().map(negated).collect();
            let no_gyro: Vec<Sample> = bad
                .iter()
                .map(|s| Sample {
                    omega_rad_s: None,
                    ..*s
                })
                .collect();
            for estimator in ["discrete-momentum", "variational"] {
                let at = format!("{case}, {estimator}");
                let config = settings(estimator).validate().expect("valid");
                for (name, data) in [("gyro", &bad), ("no gyro", &no_gyro)] {
                    // Before it stops, answers on the floor whose negation is not yet
                    // determined are withdrawn, and the run goes on.
                    let mut p = Pipeline::new(&settings(estimator)).expect("pipeline");
                    let mut withdrawn = 0;
                    let e = data
                        .iter()
                        .find_map(|s| {
                            p.push_each(s, |e| {
                                if let Observability::NotObservable(Unobservable::AtFloor {
                                    mirror_determined: false,
                                    ..
                                }) = e.observability
                                {
                                    withdrawn += 1;
                                }
                            })
                            .err()
                        })
                        .unwrap_or_else(|| panic!("{at}, {name}: not stopped"));
                    let text = e.to_string();
                    let PipelineError::ReversedMomentum {
                        sample: Some(_),
                        tau_given: false,
                        quaternions,
                    } = e
                    else {
                        panic!("{at}, {name}: {e}");
                    };
                    assert!(
                        e.fixes()[0] == Fix::NegateRho
                            && text.contains("negate it")
                            && !text.contains("tau"),
                        "{text}"
                    );
                    // (On the slew the floor comes before the negation is determined; the
                    // spin's first answers after its wheel pulse are determined at once.)
                    if case == "slew" {
                        assert!(withdrawn > 0, "{at}, {name}: stopped at the first estimate");
                    }
                    // Where the gyro has not confirmed the quaternions, a conjugated one is
                    // named too; where it has, it is not.
                    let confirmed = matches!(quaternions, Verdict::Consistent(_));
                    assert_eq!(
                        e.fixes().contains(&Fix::Conjugate),
                        !confirmed,
                        "{at}, {name}: {text}"
                    );
                    // (A JPL quaternion has this library's numbers: reading one as JPL
                    // changes nothing, so JPL is never the advice.)
                    assert_eq!(text.contains("read them conjugated"), !confirmed, "{text}");
                    assert!(
                        !e.fixes().contains(&Fix::Jpl) && !text.contains("JPL"),
                        "{text}"
                    );
                    if name == "no gyro" {
                        assert!(!confirmed, "{at}");
                    }
                }
                // The batch run checks its answer over the whole record, whose quaternion
                // convention the gyro rates confirmed: only the sign of ρ is left.
                let b = inertia::pipeline::batch(&bad, &config).expect_err("batch");
                assert!(
                    matches!(
                        b,
                        PipelineError::ReversedMomentum {
                            sample: None,
                            quaternions: Verdict::Consistent(_),
                            ..
                        }
                    ) && b.fixes() == [Fix::NegateRho],
                    "{at}: {b}"
                );
                // Negated back (what `--negate-rho` does as the file is read), the run is
                // the unreversed one, bit for bit.
                let fixed: Vec<Sample> = bad.iter().map(negated).collect();
                let last = |data: &[Sample]| {
                    let mut p = Pipeline::new(&settings(estimator)).expect("pipeline");
                    for s in data {
                        p.push(s).expect("runs");
                    }
                    *p.last().expect("estimates")
                };
                let (f, g) = (last(&fixed), last(&good));
                assert_eq!(f.j(), g.j(), "{at}");
                assert_eq!(f.observability, g.observability, "{at}");
                assert!(f.j().is_some(), "{at}: {}", f.observability);
            }
        }
    }

    #[test]
    fn honest_data_do_not_stop_as_a_reversed_momentum() {
        // Every estimator, several settings, the two scenarios at the paper's and 100×
        // its gyro noise: answers may rest on the floor early, but none stops the run.
        for (scenario, gyro) in [
            (Scenario::slew(), 1e-5),
            (Scenario::spin(), 1e-5),
            (Scenario::slew(), 1e-3),
        ] {
            let samples = scenario
                .simulate(&Common {
                    duration_s: Some(60.0),
                    gyro_noise_deg_s_rthz: gyro,
                    ..Common::paper()
                })
                .expect("sim")
                .samples;
            for estimator in [
                "discrete-momentum",
                "variational",
                "finite-difference",
                "momentum",
            ] {
                let base = PipelineSettings {
                    estimator: estimator.into(),
                    ..PipelineSettings::default()
                };
                for s in [
                    base.clone(),
                    PipelineSettings {
                        solve_every: 5,
                        ..base.clone()
                    },
                    PipelineSettings {
                        memory_s: Some(30.0),
                        ..base.clone()
                    },
                    PipelineSettings {
                        resample_s: Some(0.2),
                        ..base.clone()
                    },
                    PipelineSettings {
                        uncertainty: false,
                        ..base.clone()
                    },
                ] {
                    let mut p = Pipeline::new(&s).expect("pipeline");
                    for x in &samples {
                        if let Err(e) = p.push(x) {
                            assert!(
                                !matches!(e, PipelineError::ReversedMomentum { .. }),
                                "{estimator}, gyro {gyro}, {s:?}: {e}"
                            );
                            break;
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn a_sigma_comparable_to_j_is_not_determined() {
        // An unmodelled disturbance torque 3e5 times the paper's (3e-3 N m/√Hz) over a
        // 120 s slew: J is excited and the rows well conditioned, but the momentum's random
        // walk leaves a σ comparable to J.
        let samples = Scenario::slew()
            .simulate(&Common {
                duration_s: Some(120.0),
                disturbance_nm_rthz: 3e-3,
                ..Common::paper()
            })
            .expect("sim")
            .samples;
        let last = |max_relative_sigma: f64| {
            let mut p = Pipeline::new(&PipelineSettings {
                observability: inertia::estimator::observability::ObservabilitySettings {
                    max_relative_sigma,
                    ..Default::default()
                },
                ..PipelineSettings::default()
            })
            .expect("pipeline");
            for s in &samples {
                p.push(s).expect("runs");
            }
            *p.last().expect("estimates")
        };
        let e = last(inertia::estimator::observability::DEFAULT_MAX_RELATIVE_SIGMA);
        assert!(
            matches!(
                e.observability,
                Observability::NotObservable(Unobservable::Uncertain { relative_sigma, threshold })
                    if relative_sigma > threshold
            ),
            "{}",
            e.observability
        );
        assert!(e.j().is_none(), "no answer is given");
        // The refusal is warranted: with the threshold lifted the answer comes out, its
        // error is comparable to J, and its σ says so.
        let e = last(10.0);
        let (j, sigma) = (e.j().expect("j"), e.sigma_kg_m2().expect("σ"));
        let truth = inertia::tensor::paper_j_true();
        let error = relative_frobenius_error(&matrix_from_j(&j), &truth);
        let relative_sigma = e.uncertainty.expect("σ").frobenius_sigma_kg_m2() / truth.norm();
        assert!(
            error > 0.01 && relative_sigma > 0.1,
            "error {error:.2e}, σ {relative_sigma:.2e}"
        );
        let t = inertia::tensor::j_from_matrix(&truth);
        for k in 0..6 {
            assert!(
                (j[k] - t[k]).abs() <= 3.0 * sigma[k],
                "element {k}: error {:.2e}, σ {:.2e}",
                j[k] - t[k],
                sigma[k]
            );
        }
    }

    #[test]
    fn data_that_contradict_the_constraint_set_lean_on_it() {
        // The paper's J_true lies 2.5e-5 kg m² outside Σ ⪰ 0 (docs/conventions.md §4); the
        // discrete momentum rows resolve that, so the physical set's answer is the set's.
        let samples = slew();
        let physical = PipelineSettings {
            estimator: "discrete-momentum".into(),
            ..PipelineSettings::default()
        };
        let o = run(&samples, &physical).expect("runs");
        assert!(
            matches!(
                o,
                Observability::FromPrior(Unobservable::ConflictsWithConstraints { .. })
            ),
            "{o}"
        );
        // Without that constraint the same data determine J.
        let o = run(&samples, &settings("discrete-momentum")).expect("runs");
        assert!(matches!(o, Observability::Determined { .. }), "{o}");
    }
}

#[test]
fn batch_and_recursive_runs_report_the_same_torque_test() {
    // The discrete momentum estimator on the paper's slew, without a random disturbance (no
    // torque: held at zero) and with 1e-5 N m hidden from the telemetry (kept): the
    // recursive pipeline and the batch run make the same decision, with χ² within 1e-3,
    // and both reports carry it (JSON `torque_test`). The paper's estimator makes no test.
    for torque in [0.0, 1e-5] {
        let mut common = Common {
            disturbance_nm_rthz: 0.0,
            ..Common::paper()
        };
        common.realism.environment.constant_torque_nm = Vector3::new(torque, 0.0, 0.0);
        let out = Scenario::slew().simulate(&common).unwrap();
        let settings = PipelineSettings {
            estimator: "discrete-momentum".into(),
            ..PipelineSettings::default()
        };
        let mut p = Pipeline::new(&settings).unwrap();
        for s in &out.samples {
            p.push(s).unwrap();
        }
        let recursive = p.diagnostics().torque_test.expect("tested");
        let config = settings.validate().unwrap();
        let b = pipeline::batch(&out.samples, &config).unwrap();
        let batch = b.diagnostics.torque_test.expect("tested");
        assert_eq!(
            recursive.held_at_zero,
            torque == 0.0,
            "{torque}: {recursive:?}"
        );
        assert_eq!(batch.held_at_zero, recursive.held_at_zero, "{torque}");
        assert!(
            (batch.chi2 - recursive.chi2).abs() <= 1e-3 * recursive.chi2,
            "{torque}: {batch:?} against {recursive:?}"
        );
        #[cfg(feature = "serde")]
        {
            let report =
                inertia::pipeline::report::Report::of_batch(&b, &config, out.samples.len());
            assert_eq!(report.torque_test, Some(batch));
            let text = report.to_string();
            assert_eq!(text.contains("held at zero"), torque == 0.0, "{text}");
        }
    }
    let paper = PipelineSettings {
        estimator: "variational".into(),
        ..PipelineSettings::default()
    };
    let out = Scenario::slew().simulate(&Common::paper()).unwrap();
    let b = pipeline::batch(&out.samples, &paper.validate().unwrap()).unwrap();
    assert!(b.diagnostics.torque_test.is_none());
}
