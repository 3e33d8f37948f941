//! Estimators against simulated truth (paper §§IV–VI).

use inertia::attitude::Quaternion;
use inertia::constraints::{ConstraintSet, Constraints};
use inertia::estimator::batch;
use inertia::estimator::momentum::MomentumRls;
use inertia::estimator::observability::{Observability, ObservabilitySettings, Unobservable};
use inertia::estimator::recursive::{RecursiveEstimator, RecursiveSettings};
use inertia::estimator::rows::{FiniteDifferenceRows, RowSource, VariationalRows};
use inertia::estimator::{Estimate, EstimatorError};
use inertia::sample::Sample;
use inertia::sim::scenario::{Common, Scenario, SPIN_J33_NOMINAL, SPIN_J33_TOLERANCE};
use inertia::sim::SimOutput;
use inertia::solver::native::NativeSolver;
use inertia::solver::SolveStatus;
use inertia::tensor::{
    matrix_from_j, normalized_element_errors, relative_frobenius_error, second_moment, Component,
    COMPONENT_NAMES,
};
use nalgebra::{Matrix3, Vector3};

fn spin_set() -> ConstraintSet {
    ConstraintSet::paper().with_nominal(Component::J33, SPIN_J33_NOMINAL, SPIN_J33_TOLERANCE)
}

/// Run the recursive estimator over every sample; returns all estimates.
fn run<S: RowSource + Default>(samples: &[Sample], c: Constraints) -> Vec<Estimate> {
    let mut est = RecursiveEstimator::new(
        S::default(),
        c,
        NativeSolver::default(),
        RecursiveSettings::default(),
    )
    .unwrap();
    samples
        .iter()
        .filter_map(|s| est.push(s).unwrap())
        .collect()
}

fn final_error(estimates: &[Estimate], truth: &Matrix3<f64>) -> f64 {
    let j = estimates.last().unwrap().inertia().expect("an answer");
    relative_frobenius_error(&j, truth)
}

fn error_at(estimates: &[Estimate], t: f64, truth: &Matrix3<f64>) -> f64 {
    let e = estimates
        .iter()
        .find(|e| (e.t_s - t).abs() < 1e-6)
        .expect("estimate at t");
    e.inertia()
        .map_or(f64::INFINITY, |j| relative_frobenius_error(&j, truth))
}

fn momentum_history(samples: &[Sample]) -> Vec<(f64, Matrix3<f64>)> {
    let mut m = MomentumRls::default();
    samples
        .iter()
        .filter_map(|s| {
            // The RLS state itself, physical or not (its estimates withhold an
            // unphysical J).
            m.push(s)
                .expect("valid samples")
                .map(|_| (s.t_s, m.inertia()))
        })
        .collect()
}

#[test]
fn noise_free_slew_error_is_the_order_h2_bias() {
    let c = ConstraintSet::paper().validate().unwrap();
    let e1 = {
        let out = Scenario::slew().simulate(&Common::noise_free()).unwrap();
        final_error(&run::<VariationalRows>(&out.samples, c), &out.inertia_kg_m2)
    };
    let e2 = {
        let common = Common {
            dt_s: 0.05,
            substeps: 10,
            ..Common::noise_free()
        };
        let out = Scenario::slew().simulate(&common).unwrap();
        final_error(&run::<VariationalRows>(&out.samples, c), &out.inertia_kg_m2)
    };
    assert!(e1 < 2e-4, "h = 0.1 s: {e1:e}");
    let ratio = e1 / e2;
    assert!(
        (3.5..4.5).contains(&ratio),
        "h halved: {e1:e} / {e2:e} = {ratio}"
    );
}

#[test]
fn paper_noise_slew_final_error_and_early_advantage_over_momentum() {
    let out = Scenario::slew().simulate(&Common::paper()).unwrap();
    let jt = out.inertia_kg_m2;
    let est = run::<VariationalRows>(&out.samples, ConstraintSet::paper().validate().unwrap());
    let e = final_error(&est, &jt);
    assert!(e < 1e-3, "final {e:e}");
    let mom = momentum_history(&out.samples);
    for t in [20.0, 25.0, 30.0] {
        let ev = error_at(&est, t, &jt);
        let (_, jm) = mom.iter().find(|(tm, _)| (tm - t).abs() < 1e-6).unwrap();
        let em = relative_frobenius_error(jm, &jt);
        assert!(ev < em, "t = {t}: variational {ev:e} vs momentum {em:e}");
    }
}

#[test]
fn paper_noise_spin_with_j33_bound() {
    let out = Scenario::spin().simulate(&Common::paper()).unwrap();
    let jt = out.inertia_kg_m2;
    let est = run::<VariationalRows>(&out.samples, spin_set().validate().unwrap());
    let e = final_error(&est, &jt);
    assert!(e < 1e-3, "final {e:e}");
    // Before the wheel pulse (t < 30 s) y ≡ 0: the data fix J's direction, the J33 bound
    // its scale (J33 at its lower bound 2.7, −9.75 %), and every element is within 10 %
    // (paper §VI), products normalised by √(J_ii J_jj). Answers start within 2 s; the
    // 10 % claim is checked from 5 s on, because in the first second the direction itself
    // is still uncertain by ~1 % (which the estimate's σ says), on top of the 9.75 %.
    let before: Vec<_> = est.iter().filter(|e| e.t_s < 30.0).collect();
    let answered: Vec<_> = before.iter().filter(|e| e.inertia().is_some()).collect();
    assert!(
        answered.len() > 250,
        "{} answers before the pulse",
        answered.len()
    );
    assert!(answered[0].t_s < 2.0, "first answer at {}", answered[0].t_s);
    for e in &answered {
        assert_eq!(
            e.observability,
            Observability::FromPrior(Unobservable::NoExcitation)
        );
        if e.t_s < 5.0 {
            continue;
        }
        let j = e.inertia().unwrap();
        for (k, err) in normalized_element_errors(&j, &jt).iter().enumerate() {
            assert!(
                err.abs() < 0.10,
                "t = {}: {} off by {err:.4}",
                e.t_s,
                COMPONENT_NAMES[k]
            );
        }
    }
    // The momentum baseline learns nothing before the pulse.
    let mom = momentum_history(&out.samples);
    let (_, jm) = mom.iter().find(|(t, _)| (t - 29.0).abs() < 1e-6).unwrap();
    assert!(relative_frobenius_error(jm, &jt) > 0.99);
    let e29 = error_at(&est, 29.0, &jt);
    assert!(e29 < 0.1, "{e29}");
}

#[test]
fn recursive_equals_batch_at_every_step() {
    for (sc, set) in [
        (Scenario::slew(), ConstraintSet::paper()),
        (Scenario::spin(), spin_set()),
        (
            Scenario::spin(),
            ConstraintSet::physical().with_nominal(Component::J33, 3.0, 0.1),
        ),
    ] {
        let common = Common {
            duration_s: Some(60.0),
            ..Common::paper()
        };
        let out = sc.simulate(&common).unwrap();
        let c = set.validate().unwrap();
        let mut rec = RecursiveEstimator::new(
            VariationalRows::default(),
            c,
            NativeSolver::default(),
            RecursiveSettings::default(),
        )
        .unwrap();
        let mut checked = (0, 0);
        for (k, s) in out.samples.iter().enumerate() {
            let Some(e) = rec.push(s).unwrap() else {
                continue;
            };
            if k % 37 != 0 {
                continue;
            }
            let b = batch::estimate(
                &out.samples[..=k],
                VariationalRows::default(),
                &c,
                &mut NativeSolver::default(),
                &ObservabilitySettings::default(),
                None,
            )
            .unwrap();
            // The least-squares states agree.
            let qb = batch::reduce(&out.samples[..=k], VariationalRows::default()).unwrap();
            let qr = rec.qr();
            assert!((qr.r - qb.r).norm() <= 1e-10 * qb.r.norm(), "R at {k}");
            assert!(
                (qr.z - qb.z).norm() <= 1e-9 * qb.z.norm().max(1e-300),
                "z at {k}"
            );
            assert_eq!(
                std::mem::discriminant(&e.observability),
                std::mem::discriminant(&b.observability)
            );
            match (e.solution, b.solution) {
                (Some(x), Some(y)) => {
                    let rel = (x.j - y.j).norm() / y.j.norm();
                    if x.status == SolveStatus::Unconstrained
                        && y.status == SolveStatus::Unconstrained
                    {
                        assert!(
                            rel < 1e-8,
                            "{} k={k}: unconstrained differ by {rel:e}",
                            sc.name()
                        );
                        checked.0 += 1;
                    } else {
                        // Constrained: the same problem solved to the solver's tolerance.
                        let dobj = (x.objective - y.objective).abs() / y.objective.max(1e-300);
                        assert!(
                            rel < 1e-4 || dobj < 1e-6,
                            "{} k={k}: {rel:e} {dobj:e}",
                            sc.name()
                        );
                        checked.1 += 1;
                    }
                }
                (None, None) => {}
                other => panic!("k={k}: answers differ {other:?}"),
            }
        }
        assert!(checked.0 + checked.1 > 10, "{checked:?}");
    }
}

/// Every returned estimate satisfies its constraints to the solver tolerance.
#[test]
fn estimates_satisfy_their_constraints() {
    let out = Scenario::spin().simulate(&Common::paper()).unwrap();
    for set in [
        spin_set(),
        ConstraintSet::physical().with_nominal(Component::J33, 3.0, 0.1),
    ] {
        let c = set.validate().unwrap();
        for e in run::<VariationalRows>(&out.samples, c) {
            if let Some(j) = e.j() {
                assert!(c.margin(&j) > -1e-9, "t={} margin {}", e.t_s, c.margin(&j));
                let jm = matrix_from_j(&j);
                assert!(jm.symmetric_eigenvalues().min() >= set.epsilon_kg_m2 - 1e-9);
                assert!((j[2] - 3.0).abs() <= 0.3 + 1e-9);
                if set.consistency == inertia::constraints::Consistency::Physical {
                    assert!(second_moment(&jm).symmetric_eigenvalues().min() > -1e-9);
                }
            }
        }
    }
}

/// Telemetry expressed in a body frame B' with x_B' = C x_B.
fn rotate_body(out: &SimOutput, c: &Matrix3<f64>) -> Vec<Sample> {
    let qc = Quaternion::from_matrix(&c.transpose());
    out.samples
        .iter()
        .map(|s| Sample {
            t_s: s.t_s,
            q: s.q.mul(&qc),
            rho_nms: c * s.rho_nms,
            tau_nm: c * s.tau_nm,
            omega_rad_s: s.omega_rad_s.map(|w| c * w),
            external: Default::default(),
        })
        .collect()
}

/// Both invariances hold to the solver tolerance (1e-7 relative): the physical constraint
/// set is active at the end, because the paper's J_true lies just outside it
/// (see `paper_j_true_is_slightly_unphysical`), and the constrained solve sees the data
/// through its own scaling.
#[test]
fn change_of_body_frame_gives_c_j_ct_and_scaling_scales_j() {
    let common = Common {
        duration_s: Some(120.0),
        ..Common::paper()
    };
    let out = Scenario::slew().simulate(&common).unwrap();
    let phys = ConstraintSet::physical().validate().unwrap();
    let j0 = run::<VariationalRows>(&out.samples, phys)
        .last()
        .unwrap()
        .inertia()
        .unwrap();
    let c = Quaternion::exp(&Vector3::new(0.7, -1.1, 0.4)).to_matrix();
    let j1 = run::<VariationalRows>(&rotate_body(&out, &c), phys)
        .last()
        .unwrap()
        .inertia()
        .unwrap();
    let expect = c * j0 * c.transpose();
    assert!(
        (j1 - expect).norm() < 1e-7 * j0.norm(),
        "{:e}",
        (j1 - expect).norm()
    );

    let k = 3.7;
    let scaled: Vec<Sample> = out
        .samples
        .iter()
        .map(|s| Sample {
            rho_nms: s.rho_nms * k,
            tau_nm: s.tau_nm * k,
            ..*s
        })
        .collect();
    let j2 = run::<VariationalRows>(&scaled, phys)
        .last()
        .unwrap()
        .inertia()
        .unwrap();
    assert!((j2 - j0 * k).norm() < 1e-7 * j2.norm());
}

#[test]
fn baselines_recover_j_true_from_noise_free_data() {
    let out = Scenario::slew().simulate(&Common::noise_free()).unwrap();
    let jt = out.inertia_kg_m2;
    let fd = run::<FiniteDifferenceRows>(&out.samples, ConstraintSet::paper().validate().unwrap());
    let e = final_error(&fd, &jt);
    assert!(e < 2e-4, "finite difference {e:e}");
    let mut m = MomentumRls::default();
    for s in &out.samples {
        m.push(s).expect("valid samples");
    }
    let e = relative_frobenius_error(&m.inertia(), &jt);
    assert!(e < 2e-4, "momentum {e:e}");
}

/// 20 s of a pure spin at 0.5 rad/s about body z with a constant wheel bias off the spin
/// axis (so that y ≠ 0; ρ ∥ φ would make y ≡ 0 instead): φ never changes direction and
/// the rows have rank < 6.
fn pure_spin_samples() -> Vec<Sample> {
    let mut out = Scenario::spin()
        .simulate(&Common {
            duration_s: Some(20.0),
            inertia_kg_m2: Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0)),
            ..Common::noise_free()
        })
        .unwrap();
    let w = Vector3::new(0.0, 0.0, 0.5);
    for (k, s) in out.samples.iter_mut().enumerate() {
        s.q = Quaternion::exp(&(w * (k as f64 * 0.1)));
        s.rho_nms = Vector3::new(0.1, 0.0, 0.0);
        s.omega_rad_s = Some(w);
    }
    out.samples
}

#[test]
fn unobservable_data_give_no_answer_and_say_why() {
    // Spin without the J33 bound before the pulse: y ≡ 0, J only up to scale.
    let common = Common {
        duration_s: Some(25.0),
        ..Common::paper()
    };
    let out = Scenario::spin().simulate(&common).unwrap();
    let est = run::<VariationalRows>(&out.samples, ConstraintSet::physical().validate().unwrap());
    let last = est.last().unwrap();
    assert_eq!(
        last.observability,
        Observability::NotObservable(Unobservable::NoExcitation)
    );
    assert!(last.inertia().is_none());

    // A spacecraft at rest (the first 5 s of the slew case): rows of sensor noise only.
    let common = Common {
        duration_s: Some(4.5),
        ..Common::paper()
    };
    let out = Scenario::slew().simulate(&common).unwrap();
    let est = run::<VariationalRows>(&out.samples, ConstraintSet::physical().validate().unwrap());
    assert!(!est.is_empty());
    for e in &est {
        assert!(
            !e.observability.has_answer(),
            "t={}: {:?} {:?}",
            e.t_s,
            e.observability,
            e.inertia()
        );
    }

    // A pure spin about a principal axis with a constant wheel bias: φ never changes
    // direction, the rows have rank < 6.
    let samples = pure_spin_samples();
    let est = run::<VariationalRows>(&samples, ConstraintSet::physical().validate().unwrap());
    let last = est.last().unwrap();
    assert!(
        matches!(
            last.observability,
            Observability::NotObservable(Unobservable::RankDeficient { .. })
        ),
        "{:?}",
        last.observability
    );
}

#[test]
fn too_few_samples_and_bad_rows_are_errors() {
    let out = Scenario::slew()
        .simulate(&Common {
            duration_s: Some(1.0),
            ..Common::paper()
        })
        .unwrap();
    let c = ConstraintSet::physical().validate().unwrap();
    let r = batch::estimate(
        &out.samples[..3],
        VariationalRows::default(),
        &c,
        &mut NativeSolver::default(),
        &ObservabilitySettings::default(),
        None,
    );
    assert_eq!(
        r.unwrap_err(),
        EstimatorError::TooFewSamples { need: 4, got: 3 }
    );

    let mut bad = out.samples.clone();
    bad[5].q = Quaternion::new(Vector3::new(0.1, 0.0, 0.0), 1.0);
    let mut est = RecursiveEstimator::new(
        VariationalRows::default(),
        c,
        NativeSolver::default(),
        RecursiveSettings::default(),
    )
    .unwrap();
    let err = bad
        .iter()
        .map(|s| est.push(s))
        .find_map(Result::err)
        .unwrap();
    assert!(
        matches!(err, EstimatorError::Row { sample: 5, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("sample 5"));
}

/// Excitation diagnostics: a pure spin names the elements it cannot separate and the
/// rotation that would help; missing wheel activity is named; good data raise nothing.
#[test]
fn excitation_diagnostics() {
    use inertia::estimator::excitation::diagnose;
    use inertia::estimator::observability::ObservabilitySettings;
    let diagnose_default = |qr: &_| diagnose(qr, &ObservabilitySettings::default());
    let qr_of = |samples: &[Sample]| batch::reduce(samples, VariationalRows::default()).unwrap();

    // Pure spin about body z with a wheel bias off-axis (y ≠ 0, rank-deficient rows).
    let x = diagnose_default(&qr_of(&pure_spin_samples()));
    for e in ["J11", "J22", "J12"] {
        assert!(x.weak_elements.contains(&e), "{:?}", x.weak_elements);
    }
    assert!(!x.weak_elements.contains(&"J13") && !x.weak_elements.contains(&"J23"));
    assert!(
        x.advice.iter().any(|a| a.contains("body axis x and y")),
        "{:?}",
        x.advice
    );

    // The spin case before its wheel pulse: y ≡ 0.
    let out = Scenario::spin()
        .simulate(&Common {
            duration_s: Some(25.0),
            ..Common::paper()
        })
        .unwrap();
    let x = diagnose_default(&qr_of(&out.samples));
    assert!(
        x.advice[0].contains("reaction-wheel momentum change"),
        "{:?}",
        x.advice
    );
    assert!(x.element_sigma.is_none());

    // The full slew: well excited, a standard deviation per element, no warnings. The
    // standard deviations are of the order of the actual errors (paper noise).
    let out = Scenario::slew().simulate(&Common::paper()).unwrap();
    let x = diagnose_default(&qr_of(&out.samples));
    assert!(x.advice.is_empty(), "{:?}", x.advice);
    let sig = x.element_sigma.unwrap();
    assert!(sig.iter().all(|s| *s > 0.0 && *s < 1e-3), "{sig:?}");
    assert!(x.singular_values.windows(2).all(|w| w[0] >= w[1]));
}

/// Errors-in-variables bias compensation: given the gyro noise density, the variational
/// estimate no longer shrinks towards zero as the noise grows (README noise sweep).
#[test]
fn bias_compensation_removes_the_errors_in_variables_shrinkage() {
    let c = ConstraintSet::paper().validate().unwrap();
    for (gyro_deg, plain_min, compensated_max) in [(1e-4, 1e-3, 3e-4), (1e-3, 0.1, 2.5e-2)] {
        let out = Scenario::slew()
            .simulate(&Common {
                gyro_noise_deg_s_rthz: gyro_deg,
                ..Common::paper()
            })
            .unwrap();
        let run = |g: Option<f64>| {
            let mut e = RecursiveEstimator::new(
                VariationalRows::default(),
                c,
                NativeSolver::default(),
                RecursiveSettings {
                    gyro_noise_rad_s_rthz: g,
                    ..RecursiveSettings::default()
                },
            )
            .unwrap();
            let est: Vec<Estimate> = out
                .samples
                .iter()
                .filter_map(|s| e.push(s).unwrap())
                .collect();
            final_error(&est, &out.inertia_kg_m2)
        };
        let (plain, comp) = (run(None), run(Some(gyro_deg.to_radians())));
        assert!(plain > plain_min, "{gyro_deg}: plain {plain:e}");
        assert!(comp < compensated_max, "{gyro_deg}: compensated {comp:e}");
        // The batch estimator compensates the same way.
        let b = batch::estimate(
            &out.samples,
            VariationalRows::default(),
            &c,
            &mut NativeSolver::default(),
            &ObservabilitySettings::default(),
            Some(gyro_deg.to_radians()),
        )
        .unwrap();
        let eb = relative_frobenius_error(&b.inertia().unwrap(), &out.inertia_kg_m2);
        assert!((eb - comp).abs() < 1e-6, "{eb:e} vs {comp:e}");
    }
    // Noise far beyond the excitation: reported, not estimated.
    let out = Scenario::slew()
        .simulate(&Common {
            gyro_noise_deg_s_rthz: 1e-1,
            duration_s: Some(60.0),
            ..Common::paper()
        })
        .unwrap();
    let mut e = RecursiveEstimator::new(
        VariationalRows::default(),
        c,
        NativeSolver::default(),
        RecursiveSettings {
            gyro_noise_rad_s_rthz: Some(1e-1f64.to_radians()),
            ..RecursiveSettings::default()
        },
    )
    .unwrap();
    let last = out
        .samples
        .iter()
        .filter_map(|s| e.push(s).unwrap())
        .last()
        .unwrap();
    assert!(!last.observability.has_answer(), "{:?}", last.observability);
}
