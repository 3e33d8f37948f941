//! "Determined" is withdrawn on deliberately broken telemetry.

use inertia::attitude::Quaternion;
use inertia::constraints::ConstraintSet;
use inertia::estimator::observability::{Observability, Unobservable};
use inertia::fix::Fix;
use inertia::pipeline::{Pipeline, PipelineError, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::scenario::{Common, Scenario};
use inertia::telemetry::convention::Verdict;
use inertia::tensor::{matrix_from_j, relative_frobenius_error};

fn run(samples: &[Sample], settings: &PipelineSettings) -> Result<Observability, PipelineError> {
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
            let b = inertia::pipeline::batch(&bad, &settings(estimator).validate().expect("valid"))
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
            Observability::NotObservable(Unobservable::Uncertain { relative_sigma, threshold, .. })
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
