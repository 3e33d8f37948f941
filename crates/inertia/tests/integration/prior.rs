//! Prior knowledge (issue 13): equalities eliminated, a Gaussian prior as rows, the
//! observability of the problem actually solved, and the momentum baseline's refusal of
//! an unphysical J — on simulated data whose excitation leaves directions of J open.

use inertia::constraints::ConstraintSet;
use inertia::estimator::observability::{Observability, Unobservable};
use inertia::estimator::Estimate;
use inertia::pipeline::{Pipeline, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::control::WheelPulse;
use inertia::sim::realism::AttitudeSource;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{simulate, Zero};
use inertia::tensor::{j_from_matrix, relative_frobenius_error};
use nalgebra::{Matrix3, Vector3};

/// Equal wheel torque on all three body axes from rest (the peer benchmark's profile):
/// the body turns about one fixed axis, and the data determine only part of J.
fn equal_torque(common: Common) -> Vec<Sample> {
    let mut cfg = Scenario::spin().config(&common);
    cfg.initial.omega_rad_s = Vector3::zeros();
    let pulse = WheelPulse {
        axis: Vector3::new(1.0, 1.0, 1.0).normalize(),
        delta_rho_nms: 0.2,
        start_s: 5.0,
        duration_s: 100.0,
    };
    simulate(&cfg, &pulse, &Zero).unwrap().samples
}

fn run(estimator: &str, constraints: ConstraintSet, samples: &[Sample]) -> Estimate {
    let mut p = Pipeline::new(&PipelineSettings {
        estimator: estimator.into(),
        constraints,
        ..PipelineSettings::default()
    })
    .unwrap();
    for s in samples {
        p.push(s).unwrap();
    }
    *p.last().unwrap()
}

/// True attitude and white wheel-momentum noise (1e-4 N m s), no unmodelled torque.
/// (With the attitude propagated from a noisy gyro, or an unmodelled random torque, the
/// gyro noise and the disturbance give the open directions a spurious, biased
/// excitation that the residuals do not reveal: README, "Prior knowledge".)
fn quiet(seed: u64, truth: Matrix3<f64>) -> Common {
    let mut c = Common {
        duration_s: Some(300.0),
        seed,
        inertia_kg_m2: truth,
        disturbance_nm_rthz: 0.0,
        ..Common::paper()
    };
    c.realism.attitude = AttitudeSource::Truth;
    c.realism.wheels.noise_nms = 1e-4;
    c
}

/// A CAD-like prior: the truth with an error of `sigma` per element drawn from its
/// own distribution (seeded), reported with that σ.
fn cad_prior(truth: &Matrix3<f64>, fraction: f64, seed: u64) -> (Matrix3<f64>, [f64; 6]) {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let sigma = ConstraintSet::physical()
        .with_relative_prior(truth, fraction)
        .prior
        .unwrap()
        .sigma_kg_m2;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1000 + seed);
    let mut j = j_from_matrix(truth);
    for k in 0..6 {
        j[k] += sigma[k] * Normal::new(0.0, 1.0).unwrap().sample(&mut rng);
    }
    (inertia::tensor::matrix_from_j(&j), sigma)
}

#[test]
fn under_excited_data_are_refused_without_prior_and_determined_with_it() {
    let truth = Common::paper().inertia_kg_m2;
    let seeds = 30u64;
    let (mut covered, mut elements) = (0usize, 0usize);
    let (mut err_post, mut err_prior) = (Vec::new(), Vec::new());
    for seed in 1..=seeds {
        let data = equal_torque(quiet(seed, truth));
        let alone = run("discrete-momentum", ConstraintSet::physical(), &data);
        assert!(
            matches!(
                alone.observability,
                Observability::NotObservable(Unobservable::RankDeficient { .. })
                    | Observability::NotObservable(Unobservable::Uncertain { .. })
                    | Observability::NotObservable(Unobservable::IllConditioned { .. })
            ),
            "seed {seed}: {}",
            alone.observability
        );
        let (mean, sigma) = cad_prior(&truth, 0.05, seed);
        let e = run(
            "discrete-momentum",
            ConstraintSet::physical().with_prior(&mean, sigma),
            &data,
        );
        assert!(
            matches!(e.observability, Observability::FromPrior(_)),
            "seed {seed}: {}",
            e.observability
        );
        let fit = e.prior.unwrap();
        assert!(!fit.conflicts(), "seed {seed}: χ² {}", fit.chi2);
        // The body turns about one fixed axis: the data determine three directions of j
        // (much better than the prior), the prior the other three. With relative prior σ
        // equal per direction, the data shares sum to the data's rank.
        let shares: Vec<f64> = fit.data_share.iter().map(|d| d.unwrap()).collect();
        let total: f64 = shares.iter().sum();
        assert!((total - 3.0).abs() < 0.3, "seed {seed}: {shares:?}");
        let j = e.j().unwrap();
        let s = e.sigma_kg_m2().unwrap();
        let t = j_from_matrix(&truth);
        for k in 0..6 {
            elements += 1;
            covered += usize::from((j[k] - t[k]).abs() <= 3.0 * s[k]);
            // σ never claims more than data and prior together can give.
            assert!(s[k] <= sigma[k] * (1.0 + 1e-9), "seed {seed} element {k}");
        }
        err_post.push(relative_frobenius_error(&e.inertia().unwrap(), &truth));
        err_prior.push(relative_frobenius_error(&mean, &truth));
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (post, prior) = (median(&mut err_post), median(&mut err_prior));
    let coverage = covered as f64 / elements as f64;
    println!(
        "median error: prior {prior:.3e}, with the data {post:.3e}; 3σ coverage {coverage:.3}"
    );
    assert!(coverage >= 0.9, "3σ coverage {coverage}");
    assert!(
        post < 0.7 * prior,
        "the data must improve on the prior: {post} vs {prior}"
    );
}

#[test]
fn a_prior_wrong_by_more_than_its_sigma_is_refused() {
    let truth = Common::paper().inertia_kg_m2;
    let data = equal_torque(quiet(3, truth));
    // A CAD model 30 % too heavy, stated with 2 % σ: every element 15 σ off (10 % too heavy, 5 σ, gives χ² = 18.8: not flagged; README).
    let sigma = ConstraintSet::physical()
        .with_relative_prior(&truth, 0.02)
        .prior
        .unwrap()
        .sigma_kg_m2;
    let wrong = truth * 1.30;
    let e = run(
        "discrete-momentum",
        ConstraintSet::physical().with_prior(&wrong, sigma),
        &data,
    );
    println!("wrong prior: {} {:?}", e.observability, e.prior);
    assert!(
        matches!(
            e.observability,
            Observability::NotObservable(Unobservable::PriorConflict { .. })
        ),
        "{}",
        e.observability
    );
    // The same prior, right: accepted.
    let e = run(
        "discrete-momentum",
        ConstraintSet::physical().with_prior(&truth, sigma),
        &data,
    );
    assert!(
        matches!(e.observability, Observability::FromPrior(_)),
        "{}",
        e.observability
    );
}

#[test]
fn diagonal_equalities_determine_a_diagonal_body_and_are_exact() {
    let truth = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0));
    let data = equal_torque(quiet(2, truth));
    for est in ["discrete-momentum", "variational"] {
        let alone = run(est, ConstraintSet::physical(), &data);
        assert!(
            !alone.observability.has_answer(),
            "{est}: {}",
            alone.observability
        );
        let e = run(est, ConstraintSet::physical().diagonal(), &data);
        // The data alone determine three directions: the equalities the other three.
        assert!(
            matches!(e.observability, Observability::FromPrior(_)),
            "{est}: {}",
            e.observability
        );
        let j = e.j().unwrap();
        assert_eq!([j[3], j[4], j[5]], [0.0; 3], "{est}: fixed elements exact");
        if let Some(s) = e.sigma_kg_m2() {
            assert_eq!(
                [s[3], s[4], s[5]],
                [0.0; 3],
                "{est}: fixed elements have σ 0"
            );
        }
        let err = relative_frobenius_error(&e.inertia().unwrap(), &truth);
        assert!(err < 1e-4, "{est}: {err}");
        assert!(e.within_3sigma(&truth).unwrap(), "{est}");
    }
}

#[test]
fn momentum_baseline_never_reports_an_unphysical_inertia() {
    let truth = Common::paper().inertia_kg_m2;
    for seed in 1..=10 {
        let data = equal_torque(Common {
            dt_s: 1.0,
            ..quiet(seed, truth)
        });
        let e = run("momentum", ConstraintSet::physical(), &data);
        match e.inertia() {
            Some(j) => {
                let m = inertia::tensor::j_from_matrix(&j);
                assert!(
                    inertia::estimator::momentum::not_physical(&m).is_none(),
                    "seed {seed}: {j}"
                );
            }
            None => assert!(
                matches!(
                    e.observability,
                    Observability::NotObservable(Unobservable::NotPhysical { .. })
                        | Observability::NotObservable(Unobservable::Diverged)
                ),
                "seed {seed}: {}",
                e.observability
            ),
        }
    }
}

/// A pure spin (the paper's spin before its wheel pulse, `y ≡ 0`): the data fix J only
/// up to scale and are refused alone; a CAD prior supplies the scale, and σ covers the
/// error. With the true attitude every run is answered. With the attitude propagated
/// from the paper's gyro the noise in the rows biases the direction the data fix
/// (errors in variables) while their residuals state it sharply, so a right prior can
/// be refused as conflicting: the test asks only that no answer given misses by more
/// than 3σ, and reports how many were refused. The discrete momentum estimator refuses
/// every pure spin with a prior (a known failure).
#[test]
fn a_pure_spin_takes_its_scale_from_the_prior() {
    let truth = Common::paper().inertia_kg_m2;
    for attitude in [AttitudeSource::Truth, AttitudeSource::GyroPropagated] {
        let (mut covered, mut n, mut refused, mut runs) = (0, 0, 0, 0);
        let mut errors = Vec::new();
        for seed in 1..=20u64 {
            let mut common = Common {
                duration_s: Some(29.0),
                seed,
                ..Common::paper()
            };
            common.realism.attitude = attitude;
            let sim = Scenario::spin().simulate(&common).unwrap();
            for est in ["variational", "discrete-momentum"] {
                runs += 1;
                let alone = run(est, ConstraintSet::physical(), &sim.samples);
                assert!(
                    !alone.observability.has_answer(),
                    "{est} seed {seed}: {}",
                    alone.observability
                );
                let (mean, sigma) = cad_prior(&truth, 0.05, seed);
                let e = run(
                    est,
                    ConstraintSet::physical().with_prior(&mean, sigma),
                    &sim.samples,
                );
                match e.observability {
                    // The discrete momentum estimator does not take the scale from a
                    // prior: it refuses (its answers were 24 % off with a stated 3 % σ).
                    Observability::NotObservable(Unobservable::NoExcitation)
                        if est == "discrete-momentum" =>
                    {
                        refused += 1;
                        continue;
                    }
                    Observability::FromPrior(Unobservable::NoExcitation)
                        if est == "variational" => {}
                    Observability::NotObservable(Unobservable::PriorConflict { .. }) => {
                        refused += 1;
                        continue;
                    }
                    other => panic!("{est} seed {seed}: {other}"),
                }
                let (j, s, t) = (
                    e.j().unwrap(),
                    e.sigma_kg_m2().unwrap(),
                    j_from_matrix(&truth),
                );
                for k in 0..6 {
                    n += 1;
                    covered += usize::from((j[k] - t[k]).abs() <= 3.0 * s[k]);
                }
                errors.push(relative_frobenius_error(&e.inertia().unwrap(), &truth));
            }
        }
        errors.sort_by(f64::total_cmp);
        let coverage = covered as f64 / n.max(1) as f64;
        println!(
            "pure spin, {attitude:?} attitude, 5 % prior: {refused}/{runs} refused; answered: median error {:.3e}, 3σ coverage {coverage:.3}",
            errors.get(errors.len() / 2).copied().unwrap_or(f64::NAN)
        );
        // Only the discrete momentum estimator's runs are refused on true attitudes.
        if attitude == AttitudeSource::Truth {
            assert_eq!(refused, runs / 2);
        }
        assert!(n == 0 || coverage >= 0.9, "{coverage}");
    }
}

/// Equalities eliminated by the solver against nalgebra's least squares on the free
/// columns: `min ‖R_free x − (z − R_fixed v)‖` by SVD, on random well-posed problems
/// whose answer is interior (so the constraints do not act).
#[test]
fn eliminated_equalities_match_least_squares_on_the_free_columns() {
    use inertia::solver::native::NativeSolver;
    use inertia::solver::{solve, SolveStatus};
    use nalgebra::{DMatrix, DVector, Matrix6, Vector6};
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    // Strictly inside the physical set (the paper's J has moments 1, 2, 3: on its edge).
    let truth = j_from_matrix(&Matrix3::new(
        1.5, 0.05, -0.03, 0.05, 2.0, 0.02, -0.03, 0.02, 2.5,
    ));
    let mut compared = 0;
    for trial in 0..500 {
        let r = Matrix6::from_fn(|i, k| {
            if i <= k {
                rng.random_range(-1.0..1.0) + if i == k { 2.0 } else { 0.0 }
            } else {
                0.0
            }
        });
        let z = r * truth + Vector6::from_fn(|_, _| rng.random_range(-1e-3..1e-3));
        let fixed: Vec<usize> = (0..6).filter(|_| rng.random_bool(0.4)).collect();
        if fixed.is_empty() || fixed.len() == 6 {
            continue;
        }
        let mut set = ConstraintSet::physical();
        for &k in &fixed {
            let v = truth[k] + rng.random_range(-1e-3..1e-3);
            set = set.with_equality(inertia::tensor::Component::ALL[k], v);
        }
        let c = set.validate().unwrap();
        let sol = solve(&mut NativeSolver::default(), &r, &z, &c, None).unwrap();
        let free: Vec<usize> = (0..6).filter(|k| !fixed.contains(k)).collect();
        let a = DMatrix::from_fn(6, free.len(), |i, m| r[(i, free[m])]);
        let mut b = DVector::from_fn(6, |i, _| z[i]);
        for &k in &fixed {
            let v = c.fixed()[k].unwrap();
            assert_eq!(sol.j[k], v, "trial {trial}: element {k} exactly fixed");
            for i in 0..6 {
                b[i] -= r[(i, k)] * v;
            }
        }
        let x = a.svd(true, true).solve(&b, 1e-14).unwrap();
        let mut reference = sol.j;
        for (m, &k) in free.iter().enumerate() {
            reference[k] = x[m];
        }
        if sol.status == SolveStatus::Unconstrained || c.strictly_feasible(&reference) {
            assert!(
                (sol.j - reference).norm() <= 1e-9 * reference.norm(),
                "trial {trial} fixed {fixed:?}: {} vs {}",
                sol.j,
                reference
            );
            compared += 1;
        }
    }
    assert!(compared > 300, "{compared}");
}

/// Equalities the data cannot check are not "determined by the data": a body with a
/// product of inertia 0.1 kg m², forced diagonal, on data that determine three of the six
/// directions, is answered as determined with the prior knowledge (the data cannot tell
/// the equality is wrong, and say so).
#[test]
fn a_wrong_equality_is_not_determined_by_the_data() {
    let truth = Matrix3::new(1.0, 0.1, 0.0, 0.1, 2.0, 0.0, 0.0, 0.0, 3.0);
    let data = equal_torque(quiet(2, truth));
    for est in ["variational", "discrete-momentum"] {
        let e = run(est, ConstraintSet::physical().diagonal(), &data);
        assert!(
            matches!(e.observability, Observability::FromPrior(_)),
            "{est}: {}",
            e.observability
        );
    }
}

/// Equalities the data contradict, on data that determine J: the answer leans on the
/// constraint set (`equality_chi2`), as on an active bound.
#[test]
fn an_equality_the_data_contradict_leans_on_the_constraint_set() {
    let truth = Common::paper().inertia_kg_m2;
    let run_ = Scenario::slew().simulate(&Common::paper()).unwrap();
    let alone = run("variational", ConstraintSet::physical(), &run_.samples);
    assert!(matches!(
        alone.observability,
        Observability::Determined { .. } | Observability::FromPrior(_)
    ));
    // J12 is 0.0368: fixing it at 0 contradicts the data.
    let e = run(
        "variational",
        ConstraintSet::physical().with_equality(inertia::tensor::Component::J12, 0.0),
        &run_.samples,
    );
    assert!(
        matches!(
            e.observability,
            Observability::FromPrior(Unobservable::ConflictsWithConstraints { .. })
        ),
        "{}",
        e.observability
    );
    // Fixed at its true value: no conflict.
    let t = j_from_matrix(&truth);
    let e = run(
        "variational",
        ConstraintSet::physical().with_equality(inertia::tensor::Component::J12, t[3]),
        &run_.samples,
    );
    assert!(
        !matches!(
            e.observability,
            Observability::FromPrior(Unobservable::ConflictsWithConstraints { .. })
                | Observability::NotObservable(_)
        ),
        "{}",
        e.observability
    );
}
