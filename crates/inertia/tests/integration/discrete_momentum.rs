//! The discrete momentum form (inertia::discrete_momentum, estimator::momentum_rows,
//! estimator::discrete_momentum): the exact identity with the paper's rows, conservation
//! orders on exact trajectories (plain O(h²), Richardson O(h⁴)), recovery of a known J with
//! an unknown constant torque, the stencils for smooth and held wheel momentum, recursive vs
//! batch, gaps, and the rotation sources.

use inertia::attitude::Quaternion;
use inertia::constraints::ConstraintSet;
use inertia::discrete::RowInput;
use inertia::discrete_momentum::IntervalMomentum;
use inertia::dynamics::GyrostatState;
use inertia::estimator::discrete_momentum::{
    reduce_batch, torque_tested, DiscreteMomentumEstimator, MomentumEstimatorSettings, TORQUE_CHI2,
    TORQUE_SHIFT_Z,
};
use inertia::estimator::momentum_rows::{
    MomentumRowSettings, MomentumRows, RotationSource, Stencil, ANCHOR0, ANCHOR1, J,
};
use inertia::estimator::observability::Observability;
use inertia::sample::Sample;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{simulate, AttitudeSource, CommandHold, InputLaw, Realism};
use inertia::solver::native::NativeSolver;
use inertia::tensor::{j_from_matrix, paper_j_true, relative_frobenius_error};
use nalgebra::{Matrix3x6, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::trajectory;
use trajectory::{exact_samples, rho_dot, torque};

fn random_unit(rng: &mut ChaCha8Rng, scale: f64) -> Quaternion {
    Quaternion::exp(&Vector3::from_fn(|_, _| rng.random_range(-scale..scale)))
}

#[test]
fn paper_rows_are_rotated_differences_of_interval_momenta() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..200 {
        let q0 = random_unit(&mut rng, 3.0);
        let q1 = q0.mul(&random_unit(&mut rng, 0.4));
        let q2 = q1.mul(&random_unit(&mut rng, 0.4));
        let rho: [Vector3<f64>; 3] =
            core::array::from_fn(|_| Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0)));
        let tau = Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let (h0, h1) = (rng.random_range(0.05..0.5), rng.random_range(0.05..0.5));
        let j = nalgebra::Vector6::from_fn(|_, _| rng.random_range(-2.0..2.0));
        let input = RowInput::from_nodes(
            0.0,
            [&q0, &q1, &q2],
            [&rho[0], &rho[1], &rho[2]],
            &tau,
            h0,
            h1,
        )
        .expect("input");
        let row = input.row().expect("row");
        let c1 = q1.to_matrix();
        let l0 = IntervalMomentum::new(&q0.to_matrix(), &input.phi_k, &input.rho_k_nms, h0);
        let l1 = IntervalMomentum::new(&c1, &input.phi_k1, &input.rho_k1_nms, h1);
        let hbar = 0.5 * (h0 + h1);
        let lhs = c1 * (row.h * j - row.y);
        let rhs = (l1.momentum(&j) - l0.momentum(&j) - c1 * tau * hbar) * (0.5 * hbar);
        assert!(
            (lhs - rhs).norm() <= 1e-12 * (1.0 + lhs.norm()),
            "identity off by {:e}",
            (lhs - rhs).norm()
        );
    }
}

/// The paper's slew with `common`'s noise and an external torque `torque(t, state)`
/// (body axes, N m) acting on it and left out of the telemetry.
pub(crate) fn slew_with_hidden_torque(
    common: &Common,
    torque: impl Fn(f64, &GyrostatState) -> Vector3<f64> + Send + Sync + 'static,
) -> inertia::sim::SimOutput {
    let sc = Scenario::slew();
    let cfg = sc.config(common);
    let Scenario::Slew(plan) = &sc else {
        unreachable!()
    };
    let ctrl = inertia::sim::control::SlewController::new(
        plan.nominal_inertia_kg_m2,
        cfg.initial.q,
        plan.slews.clone(),
        plan.natural_freq_rad_s,
        plan.damping,
    )
    .expect("controller");
    let mut run = simulate(&cfg, &ctrl, &torque).expect("sim");
    for s in &mut run.samples {
        s.tau_nm = Vector3::zeros();
    }
    run
}

/// The paper's slew for its first `duration_s`, with `common`'s noise.
pub(crate) fn slew_for(duration_s: f64, common: Common) -> inertia::sim::SimOutput {
    Scenario::slew()
        .simulate(&Common {
            duration_s: Some(duration_s),
            ..common
        })
        .expect("sim")
}

/// Largest drift `‖(A_k j − b_k) − (A_0 j − b_0)‖` over rows of the same anchor: the
/// conserved quantity's error.
fn max_drift(samples: &[Sample], settings: MomentumRowSettings) -> f64 {
    let j = j_from_matrix(&paper_j_true());
    let mut src = MomentumRows::new(settings);
    let mut first: [Option<Vector3<f64>>; 2] = [None; 2];
    let mut worst: f64 = 0.0;
    for s in samples {
        let Some(row) = src.push(s).expect("row") else {
            continue;
        };
        let a: Matrix3x6<f64> = row.a.fixed_view::<3, 6>(0, J).into_owned();
        let d = a * j - row.b;
        let slot = if row.a[(0, ANCHOR1)] != 0.0 { 1 } else { 0 };
        assert!(row.a[(0, ANCHOR0)] != 0.0 || slot == 1);
        match first[slot] {
            None => first[slot] = Some(d),
            Some(d0) => worst = worst.max((d - d0).norm()),
        }
    }
    worst
}

fn fitted_order(settings: MomentumRowSettings, rho: &dyn InputLaw, tau: &dyn InputLaw) -> f64 {
    let pts: Vec<(f64, f64)> = [0.2, 0.1, 0.05, 0.025]
        .iter()
        .map(|&h| {
            let d = max_drift(&exact_samples(h, 8.0, rho, tau), settings);
            (f64::ln(h), d.ln())
        })
        .collect();
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

#[test]
fn conservation_is_second_order_plain_and_fourth_order_with_richardson() {
    for stencil in [Stencil::Plain, Stencil::Smooth] {
        let richardson = stencil.richardson();
        let settings = MomentumRowSettings {
            stencil,
            torque_bias: false,
            ..Default::default()
        };
        let p = fitted_order(settings, &rho_dot, &torque);
        let (lo, hi) = if richardson { (3.7, 4.3) } else { (1.8, 2.2) };
        assert!(
            (lo..=hi).contains(&p),
            "richardson {richardson}: order {p:.3} not in [{lo}, {hi}]"
        );
    }
}

/// The positive-definite constraint set, validated.
fn pd() -> inertia::constraints::Constraints {
    ConstraintSet::positive_definite()
        .validate()
        .expect("valid")
}

pub(crate) fn estimator(rows: MomentumRowSettings) -> DiscreteMomentumEstimator<NativeSolver> {
    DiscreteMomentumEstimator::new(
        MomentumEstimatorSettings {
            rows,
            ..Default::default()
        },
        ConstraintSet::positive_definite()
            .validate()
            .expect("valid"),
        NativeSolver::default(),
    )
    .expect("valid settings")
}

pub(crate) fn final_error(
    samples: &[Sample],
    rows: MomentumRowSettings,
    truth: &nalgebra::Matrix3<f64>,
) -> f64 {
    let mut e = estimator(rows);
    for s in samples {
        e.push(s).expect("push");
    }
    let last = e.last().expect("estimates");
    assert!(matches!(
        last.observability,
        Observability::Determined { .. }
    ));
    relative_frobenius_error(&last.inertia().expect("answer"), truth)
}

#[test]
fn recovers_j_on_the_paper_scenarios_without_gyro_noise() {
    // Richardson rows: the O(h²) bias cancels, so the error is far below the plain rows'.
    for (sc, plain_max, rich_max) in [
        (Scenario::slew(), 3e-5, 1e-6),
        (Scenario::spin(), 2e-4, 1e-6),
    ] {
        let run = sc
            .simulate(&Common {
                gyro_noise_deg_s_rthz: 0.0,
                ..Common::paper()
            })
            .expect("sim");
        for rotation in [RotationSource::Attitude, RotationSource::Gyro] {
            let rows = |richardson| MomentumRowSettings {
                rotation,
                stencil: if richardson {
                    Stencil::Smooth
                } else {
                    Stencil::Plain
                },
                ..Default::default()
            };
            let plain = final_error(&run.samples, rows(false), &run.inertia_kg_m2);
            let rich = final_error(&run.samples, rows(true), &run.inertia_kg_m2);
            // The gyro's angle increments carry an O(h³) coning remainder per step.
            let rich_max = if rotation == RotationSource::Gyro {
                20.0 * rich_max
            } else {
                rich_max
            };
            assert!(
                plain < plain_max,
                "{} {rotation:?} plain {plain:e}",
                sc.name()
            );
            assert!(
                rich < rich_max,
                "{} {rotation:?} Richardson {rich:e}",
                sc.name()
            );
        }
    }
}

#[test]
fn an_unknown_constant_torque_is_estimated_and_does_not_bias_j() {
    // Simulate with a constant torque, then hide it from the telemetry.
    let tau_b = Vector3::new(1e-5, -2e-5, 1.5e-5);
    let run = slew_with_hidden_torque(&Common::noise_free(), move |_, _| tau_b);
    let rows = |torque_bias| MomentumRowSettings {
        stencil: Stencil::Smooth,
        torque_bias,
        ..Default::default()
    };
    let with = final_error(&run.samples, rows(true), &run.inertia_kg_m2);
    let without = final_error(&run.samples, rows(false), &run.inertia_kg_m2);
    assert!(with < 2e-6, "with the torque unknown: {with:e}");
    assert!(
        without > 100.0 * with,
        "without it: {without:e} vs {with:e}"
    );
    let mut e = estimator(rows(true));
    for s in &run.samples {
        e.push(s).expect("push");
    }
    let est = e.torque_bias_nm().expect("torque estimate");
    assert!(
        (est - tau_b).norm() < 1e-3 * tau_b.norm(),
        "{est:?} vs {tau_b:?}"
    );
}

#[test]
fn a_constant_torque_is_held_at_zero_only_where_the_data_give_no_evidence_of_one() {
    // The paper's slew with its gyro noise but no random disturbance torque, so that the
    // rows' errors are independent, as the test assumes. Without a torque the χ²₃
    // statistic stays below its 1 − 10⁻³ quantile in (nearly) every seed and the torque
    // is held at zero, with the error within 3 of the stated σ_F (the noise σ: a bare
    // estimator keeps no bias terms); with 1e-5 N m hidden from the telemetry it is
    // kept in every seed, far above the threshold, and estimated.
    let rows = MomentumRowSettings {
        stencil: Stencil::Smooth,
        ..Default::default()
    };
    let (mut held, mut kept) = (0, 0);
    for seed in 0..8 {
        let common = Common {
            disturbance_nm_rthz: 0.0,
            seed,
            ..Common::paper()
        };
        let quiet = slew_for(120.0, common.clone());
        let mut e = estimator(rows);
        for s in &quiet.samples {
            e.push(s).expect("push");
        }
        let test = e.torque_test().expect("the torque is estimated, so tested");
        if test.held_at_zero {
            held += 1;
            assert!(
                e.torque_bias_nm().is_none(),
                "held at zero: no torque reported"
            );
            let j = e.last().and_then(|l| l.inertia()).expect("an answer");
            let sigma = e.robust_noise_sigma().expect("σ");
            let sigma_f = (0..6)
                .map(|k| sigma[k] * sigma[k] * if k < 3 { 1.0 } else { 2.0 })
                .sum::<f64>()
                .sqrt();
            let error = (j - quiet.inertia_kg_m2).norm();
            assert!(
                error <= 3.0 * sigma_f,
                "seed {seed}: {error:e} against σ_F {sigma_f:e}"
            );
        }
        // The same run with a constant body torque the telemetry does not carry.
        let tau = Vector3::new(1e-5, -5e-6, 8e-6);
        let mut pushed = common;
        pushed.realism.environment.constant_torque_nm = tau;
        let mut e = estimator(rows);
        for s in &slew_for(120.0, pushed).samples {
            e.push(s).expect("push");
        }
        let test = e.torque_test().expect("tested");
        assert!(
            !test.held_at_zero && test.chi2 > 100.0 * TORQUE_CHI2,
            "seed {seed}: {test:?}"
        );
        let est = e.torque_bias_nm().expect("kept");
        assert!(
            (est - tau).norm() < 0.05 * tau.norm(),
            "seed {seed}: {est:?}"
        );
        kept += 1;
    }
    assert!(held >= 7, "held at zero in {held} of 8 seeds");
    assert_eq!(kept, 8);
}

#[test]
fn the_torque_test_needs_a_finite_noise_scale() {
    // (with, without, growth) → the state solved and the test. A residual variance of
    // 1 (ρ² 10 over 10 degrees of freedom): growth 3 is χ² 3, held at zero; growth 30
    // is kept. Without residual degrees of freedom, with an exact fit, or with a NaN,
    // there is no test and the torque stays estimated (the fuzz found a NaN χ² in the
    // report before this).
    use inertia::estimator::qr::RecursiveQr;
    let with = |rss: f64, weight: f64| RecursiveQr {
        rss,
        rows: weight as usize,
        weight,
        nuisance: 0.0,
        ..RecursiveQr::new()
    };
    let without = |w: &RecursiveQr, growth: f64| {
        let mut held = *w;
        held.rss += growth;
        held.z[0] = 1.0; // tells the two states apart
        (held, growth)
    };
    let w = with(10.0, 16.0); // ν = 16 − 6 = 10
    let (solved, test) = torque_tested(w, Some(without(&w, 3.0)), None, &pd());
    let test = test.expect("a noise scale");
    assert!(test.held_at_zero && (test.chi2 - 3.0).abs() < 1e-12);
    assert_eq!(solved.z[0], 1.0, "the state without the torque");
    let (solved, test) = torque_tested(w, Some(without(&w, 30.0)), None, &pd());
    assert!(!test.expect("tested").held_at_zero);
    assert_eq!(solved.z[0], 0.0, "the state with the torque");
    for (w, growth, what) in [
        (with(10.0, 6.0), 3.0, "no residual degrees of freedom"),
        (with(0.0, 16.0), 3.0, "an exact fit"),
        (with(0.0, 16.0), 0.0, "an exact fit both ways"),
        (with(f64::NAN, 16.0), 3.0, "a NaN"),
    ] {
        let (solved, test) = torque_tested(w, Some(without(&w, growth)), None, &pd());
        assert!(test.is_none(), "{what}: {test:?}");
        assert_eq!(solved.z[0], 0.0, "{what}: the state with the torque");
    }
    assert!(
        torque_tested(w, None, None, &pd()).1.is_none(),
        "the torque not estimated"
    );
}

#[test]
fn recursive_and_batch_agree_with_gaps_and_chains() {
    let run = slew_for(120.0, Common::paper());
    // A one-minute gap in the middle.
    let mut samples = run.samples.clone();
    samples.retain(|s| !(50.0..110.0).contains(&s.t_s));
    for stencil in [
        Stencil::Plain,
        Stencil::Smooth,
        Stencil::Held,
        Stencil::Adaptive,
    ] {
        for max_chain_s in [None, Some(20.0)] {
            let rows = MomentumRowSettings {
                stencil,
                max_chain_s,
                ..Default::default()
            };
            let gaps = assert_recursive_matches_batch(&samples, rows, 1e-9);
            assert_eq!(gaps, 1, "{stencil:?} chain {max_chain_s:?}");
        }
    }
}

/// Recursive and batch reductions of `samples` give the same unconstrained `j` (to
/// `tolerance`, relative), residual (to 1e-4: the batch residual `‖y‖² − ‖Qᵀy‖²`
/// cancels) and nuisance count, the same torque test (its χ² to 1e-3, the same
/// decision unless within 1e-3 of the threshold), and see the same gaps; returns the
/// gaps.
pub(crate) fn assert_recursive_matches_batch(
    samples: &[Sample],
    rows: MomentumRowSettings,
    tolerance: f64,
) -> usize {
    let mut e = estimator(rows);
    for s in samples {
        e.push(s).expect("push");
    }
    let rec =
        inertia::solver::unconstrained_minimiser(&e.reduced().r, &e.reduced().z).expect("regular");
    let b = reduce_batch(samples, &rows).expect("batch");
    let what = format!("{:?} chain {:?}", rows.stencil, rows.max_chain_s);
    let (tested, test) = torque_tested(b.qr, b.without_torque, b.jackknife_sigma_kg_m2, &pd());
    let rec_test = e.torque_test();
    assert_eq!(test.is_some(), rec_test.is_some(), "{what}");
    if let (Some(bt), Some(rt)) = (test, rec_test) {
        assert!(
            (bt.chi2 - rt.chi2).abs() <= 1e-3 * bt.chi2,
            "{what}: {bt:?} {rt:?}"
        );
        // The shift test's yardstick, the jackknife σ, differs between the paths
        // ([`inertia::estimator::jackknife`]): its decisions must agree away from the
        // threshold.
        let near = |z: Option<f64>| z.is_some_and(|z| (z / TORQUE_SHIFT_Z - 1.0).abs() < 0.5);
        if (bt.chi2 / TORQUE_CHI2 - 1.0).abs() > 1e-3 && !near(bt.shift_z) && !near(rt.shift_z) {
            assert_eq!(bt.held_at_zero, rt.held_at_zero, "{what}");
        }
    }
    let bat = inertia::solver::unconstrained_minimiser(&tested.r, &tested.z).expect("regular");
    assert!(
        (rec - bat).norm() < tolerance * bat.norm(),
        "{what}: {:e}",
        (rec - bat).norm() / bat.norm()
    );
    assert!(
        (tested.rss - e.reduced().rss).abs() < 1e-4 * tested.rss,
        "{what}: rss {:e} vs {:e}",
        tested.rss,
        e.reduced().rss
    );
    assert_eq!(tested.nuisance, e.reduced().nuisance, "{what}");
    assert_eq!(b.gaps, e.gaps(), "{what}");
    b.gaps
}

#[test]
fn a_gap_starts_a_new_chain() {
    let run = slew_for(20.0, Common::noise_free());
    let mut src = MomentumRows::new(MomentumRowSettings::default());
    let mut rows = 0;
    for s in run.samples.iter().filter(|s| !(8.0..12.0).contains(&s.t_s)) {
        rows += usize::from(src.push(s).expect("row").is_some());
    }
    assert_eq!(src.gaps(), 1);
    assert_eq!(src.epoch(), 1);
    // One row per interval, none across the gap.
    assert_eq!(
        rows,
        run.samples
            .iter()
            .filter(|s| !(8.0..12.0).contains(&s.t_s))
            .count()
            - 2
    );
}

/// A chain split by new initial momenta while its sums `S`, `T` run on (what
/// `ChainClock` does) is the same least-squares problem as the chain restarted there with
/// its sums from zero (what a gap does): the sums' values at the split are a constant
/// offset of every later row, which the new initial momenta absorb. Problem: the paper's
/// slew with paper gyro noise and a known torque (so that `T` is not zero), plain rows
/// with the attitude's rotation (a restart then loses no row), split at three samples.
/// Reference: fresh row sources from each split sample. Tolerance: `R`, `z` of the
/// reduced problem to 1e-9 of their largest entry, `ρ²` to 1e-9 relative; the rows
/// counted equal.
#[test]
fn splitting_a_chain_is_restarting_its_sums() {
    use inertia::estimator::augmented_qr::AugmentedQr;
    let run = slew_for(60.0, Common::paper());
    let samples: Vec<Sample> = run
        .samples
        .iter()
        .map(|s| Sample {
            tau_nm: Vector3::new(1e-3, -2e-3, 5e-4),
            ..*s
        })
        .collect();
    let rows = MomentumRowSettings::default();
    let splits = [100, 250, 420];
    // Split: one source, the initial momenta eliminated after the row ending at a split.
    let mut split = AugmentedQr::new(rows.shared_nuisance());
    let mut src = MomentumRows::new(rows);
    for (k, s) in samples.iter().enumerate() {
        if let Some(row) = src.push(s).expect("row") {
            split.add(&row, None);
        }
        if splits.contains(&k) {
            split.eliminate_anchors();
        }
    }
    // Restarted: a fresh source from each split sample on.
    let mut restarted = AugmentedQr::new(rows.shared_nuisance());
    let bounds = [0, splits[0], splits[1], splits[2], samples.len() - 1];
    for w in bounds.windows(2) {
        let mut src = MomentumRows::new(rows);
        for s in &samples[w[0]..=w[1]] {
            if let Some(row) = src.push(s).expect("row") {
                restarted.add(&row, None);
            }
        }
        restarted.eliminate_anchors();
    }
    let (a, b) = (split.reduced(), restarted.reduced());
    assert_eq!(a.rows, b.rows);
    assert!(
        (a.r - b.r).amax() <= 1e-9 * b.r.amax(),
        "R: {:e}",
        (a.r - b.r).amax()
    );
    assert!(
        (a.z - b.z).amax() <= 1e-9 * b.z.amax(),
        "z: {:e}",
        (a.z - b.z).amax()
    );
    assert!((a.rss - b.rss).abs() <= 1e-9 * b.rss, "{} {}", a.rss, b.rss);
}

/// Candidates that differ only in the longest chain may share one row source
/// (`fold_shared`): an estimator fed that way holds exactly the state of one that forms its
/// own rows, for Richardson rows from the gyro with chains of 20 s and the whole record.
#[test]
fn a_shared_row_source_gives_the_state_of_an_own_one() {
    let run = slew_for(120.0, Common::paper());
    let base = MomentumRowSettings {
        rotation: RotationSource::Gyro,
        stencil: Stencil::Adaptive,
        ..Default::default()
    };
    let mut shared = MomentumRows::new(base);
    let chains = [Some(20.0), None];
    let estimators = || -> Vec<_> {
        chains
            .iter()
            .map(|&max_chain_s| {
                estimator(MomentumRowSettings {
                    max_chain_s,
                    ..base
                })
            })
            .collect()
    };
    let (mut own, mut fed) = (estimators(), estimators());
    for s in &run.samples {
        for e in &mut own {
            e.fold(s).expect("fold");
        }
        if let Some(row) = shared.push(s).expect("row") {
            for e in &mut fed {
                e.fold_shared(&row, &shared, s.t_s);
            }
        }
    }
    for (a, b) in own.iter().zip(&fed) {
        assert_eq!(a.qr(), b.qr(), "{:?}", a.row_settings().max_chain_s);
    }
    assert!(own[0].qr().residual_dof() < own[1].qr().residual_dof());
}

#[test]
fn gyro_rotation_needs_gyro_rates() {
    let run = slew_for(2.0, Common::noise_free());
    let mut src = MomentumRows::new(MomentumRowSettings {
        rotation: RotationSource::Gyro,
        ..Default::default()
    });
    let mut s = run.samples[0];
    s.omega_rad_s = None;
    assert!(src.push(&s).expect("first").is_none());
    let err = src
        .push(&run.samples[1])
        .expect_err("no rate on the first interval");
    assert_eq!(err, inertia::discrete::RowError::MissingGyroRate);
}

#[test]
fn each_stencil_is_exact_for_its_wheel_model_and_the_adaptive_one_for_all() {
    // Truth attitude, no gyro noise, no disturbance: what is left is discretisation and
    // the model of ρ between samples. The continuous controller makes ρ smooth; commands
    // held over each 0.1 s step make it piecewise linear with kinks at the samples;
    // commands that change mid-way between samples put the kinks inside the steps.
    for (name, commands) in [
        ("continuous", None),
        ("held, aligned", Some(CommandHold::at(10.0))),
        (
            "held, mid-way",
            Some(CommandHold {
                phase_s: 0.05,
                ..CommandHold::at(10.0)
            }),
        ),
    ] {
        let run = Scenario::slew()
            .simulate(&Common {
                gyro_noise_deg_s_rthz: 0.0,
                disturbance_nm_rthz: 0.0,
                realism: Realism {
                    attitude: AttitudeSource::Truth,
                    commands,
                    ..Default::default()
                },
                ..Common::paper()
            })
            .expect("sim");
        let error = |stencil| {
            let rows = MomentumRowSettings {
                stencil,
                ..Default::default()
            };
            final_error(&run.samples, rows, &run.inertia_kg_m2)
        };
        let [smooth, held, adaptive, plain] = [
            Stencil::Smooth,
            Stencil::Held,
            Stencil::Adaptive,
            Stencil::Plain,
        ]
        .map(error);
        eprintln!(
            "{name}: smooth {smooth:.2e}, held {held:.2e}, adaptive {adaptive:.2e}, plain {plain:.2e}"
        );
        let fixed_best = smooth.min(held);
        match name {
            "continuous" => assert!(smooth < 1e-7 && held > 20.0 * smooth, "{name}"),
            "held, aligned" => assert!(held < 1e-7 && smooth > 20.0 * held, "{name}"),
            _ => assert!(fixed_best > 1e-6, "{name}: no fixed stencil fits"),
        }
        assert!(
            adaptive < 1e-9 && plain > 1000.0 * adaptive,
            "{name}: adaptive {adaptive:e}"
        );
        assert!(adaptive < 3.0 * fixed_best, "{name}");
        // The pipeline's default (the adaptive stencil, its choice of rotation source and
        // chain length, its σ) gets the same accuracy, and its σ covers it.
        let mut p = inertia::pipeline::Pipeline::new(&inertia::pipeline::PipelineSettings {
            estimator: "discrete-momentum".into(),
            constraints: ConstraintSet::positive_definite(),
            ..Default::default()
        })
        .expect("pipeline");
        for s in &run.samples {
            p.push(s).expect("push");
        }
        assert_eq!(
            p.diagnostics().row_model.expect("row model").stencil,
            Stencil::Adaptive
        );
        let e = p.last().expect("estimate");
        let pipeline_error =
            relative_frobenius_error(&e.inertia().expect("answer"), &run.inertia_kg_m2);
        assert!(pipeline_error < 1e-8, "{name}: pipeline {pipeline_error:e}");
        assert_eq!(e.within_3sigma(&run.inertia_kg_m2), Some(true), "{name}");
    }
}

#[test]
fn jackknife_sigma_covers_correlated_row_errors_that_the_least_squares_sigma_misses() {
    // Truth attitude: the rows' errors are the paper's white disturbance torque, which
    // integrates into a random walk of the momentum along each chain. The least-squares σ
    // takes the rows as independent; the jackknife over chains does not.
    let seeds = 12;
    let (mut within_ls, mut within_jk, mut total) = (0u32, 0u32, 0u32);
    let (mut z2_ls, mut z2_jk) = (0.0, 0.0);
    for seed in 1..=seeds {
        let run = Scenario::slew()
            .simulate(&Common {
                seed,
                realism: Realism {
                    attitude: AttitudeSource::Truth,
                    ..Default::default()
                },
                ..Common::paper()
            })
            .expect("sim");
        let mut e = estimator(MomentumRowSettings {
            stencil: Stencil::Smooth,
            max_chain_s: Some(30.0),
            ..Default::default()
        });
        for s in &run.samples {
            e.push(s).expect("push");
        }
        let j = e.last().and_then(|l| l.j()).expect("answer");
        let truth = j_from_matrix(&run.inertia_kg_m2);
        let ls = e.noise_sigma().expect("least-squares sigma");
        let robust = e.robust_noise_sigma().expect("sigma");
        assert!(e.jackknife_sigma().is_some(), "10 chains: a jackknife");
        for k in 0..6 {
            let err = (j[k] - truth[k]).abs();
            total += 1;
            within_ls += u32::from(err <= 3.0 * ls[k]);
            within_jk += u32::from(err <= 3.0 * robust[k]);
            z2_ls += (err / ls[k]).powi(2);
            z2_jk += (err / robust[k]).powi(2);
        }
    }
    let n = f64::from(total);
    let (cov_ls, cov_jk) = (f64::from(within_ls) / n, f64::from(within_jk) / n);
    let (rms_ls, rms_jk) = ((z2_ls / n).sqrt(), (z2_jk / n).sqrt());
    eprintln!(
        "3σ coverage: least squares {cov_ls:.2} (rms z {rms_ls:.1}), with the jackknife \
         {cov_jk:.2} (rms z {rms_jk:.1}), {total} elements"
    );
    assert!(rms_ls > 4.0 && cov_ls < 0.7, "correlated errors exist");
    assert!(cov_jk >= 0.9, "jackknife coverage {cov_jk}");
}

#[test]
fn jackknife_of_identical_groups_is_zero_and_of_known_spread_is_exact() {
    use inertia::estimator::jackknife::jackknife_sigma;
    use inertia::tensor::InertiaVector;
    let same = [InertiaVector::repeat(1.0); 5];
    assert_eq!(jackknife_sigma(&same), Some([0.0; 6]));
    assert_eq!(jackknife_sigma(&same[..3]), None, "too few groups");
    // Four estimates ±d about the mean: (G−1)/G Σ d² = 3/4 · 4 d² = 3 d².
    let d = 0.01;
    let spread: Vec<InertiaVector> = [1.0, -1.0, 1.0, -1.0]
        .iter()
        .map(|s| InertiaVector::repeat(2.0 + s * d))
        .collect();
    let sigma = jackknife_sigma(&spread).expect("four groups");
    for s in sigma {
        assert!((s - 3f64.sqrt() * d).abs() < 1e-15, "{s}");
    }
}

#[test]
fn recursive_and_batch_agree_with_constant_wheel_momentum_and_a_rowless_first_chain() {
    // A constant ρ leaves the adaptive stencil's κ column zero; a first chain of two
    // nodes and a gap give no Richardson row. Both paths must see the same problem.
    let run = slew_for(120.0, Common::paper());
    let rho0 = Vector3::new(0.02, -0.01, 0.015);
    let mut samples: Vec<Sample> = run
        .samples
        .iter()
        .map(|s| Sample {
            rho_nms: rho0,
            ..*s
        })
        .collect();
    // Two nodes, then a 5 s gap.
    samples.retain(|s| !(0.15..5.0).contains(&s.t_s));
    for max_chain_s in [None, Some(20.0)] {
        let rows = MomentumRowSettings {
            stencil: Stencil::Adaptive,
            max_chain_s,
            ..Default::default()
        };
        assert_recursive_matches_batch(&samples, rows, 1e-8);
    }
}

#[test]
fn recursive_and_batch_jackknife_agree() {
    // The batch files the last chain too; the recursive one scales its completed chains'
    // σ to the chain in progress. With eleven chains they agree to within a quarter.
    let run = slew_for(330.0, Common::paper());
    let rows = MomentumRowSettings {
        stencil: Stencil::Smooth,
        max_chain_s: Some(30.0),
        ..Default::default()
    };
    let mut e = estimator(rows);
    for s in &run.samples {
        e.push(s).expect("push");
    }
    let rec = e.jackknife_sigma().expect("recursive");
    let bat = reduce_batch(&run.samples, &rows)
        .expect("batch")
        .jackknife_sigma_kg_m2
        .expect("batch jackknife");
    for k in 0..6 {
        let ratio = rec[k] / bat[k];
        assert!((0.75..=1.33).contains(&ratio), "element {k}: {ratio}");
    }
}

#[test]
fn errors_in_variables_compensation_removes_the_noisy_gyro_bias() {
    // The small-satellite preset with its attitude propagated from a MEMS gyro (ARW
    // 0.15 deg/√h, no bias): the gyro noise in φ shrinks the estimate (errors in
    // variables), so the trace of Ĵ comes out low in every seed. Given the gyro's
    // density, the compensated estimate is unbiased in the trace and closer overall.
    let preset = inertia::sim::presets::Preset::small_sat();
    let mut common = preset.common.clone();
    common.realism = Realism {
        attitude: AttitudeSource::GyroPropagated,
        wheels: common.realism.wheels,
        commands: common.realism.commands,
        ..Default::default()
    };
    let seeds = 3;
    // Mean relative Frobenius error and mean signed relative trace error.
    let (mut plain, mut compensated) = ((0.0, 0.0), (0.0, 0.0));
    for seed in 1..=seeds {
        let run = preset
            .scenario
            .simulate(&Common {
                seed,
                ..common.clone()
            })
            .expect("sim");
        let error = |gyro: Option<f64>| {
            let mut p = inertia::pipeline::Pipeline::new(&inertia::pipeline::PipelineSettings {
                estimator: "discrete-momentum".into(),
                constraints: ConstraintSet::positive_definite(),
                gyro_noise_deg_s_rthz: gyro,
                solve_every: 100,
                ..Default::default()
            })
            .expect("pipeline");
            for s in &run.samples {
                p.push(s).expect("push");
            }
            let j = p.last().and_then(|e| e.inertia()).expect("answer");
            let trace = j.trace() / run.inertia_kg_m2.trace() - 1.0;
            if gyro.is_none() {
                assert!(trace < 0.0, "seed {seed}: shrunk, trace {trace:e}");
            }
            (
                relative_frobenius_error(&j, &run.inertia_kg_m2) / seeds as f64,
                trace / seeds as f64,
            )
        };
        let (e, t) = error(None);
        (plain.0, plain.1) = (plain.0 + e, plain.1 + t);
        let (e, t) = error(Some(common.gyro_noise_deg_s_rthz));
        (compensated.0, compensated.1) = (compensated.0 + e, compensated.1 + t);
    }
    eprintln!(
        "mean error, trace error: uncompensated {:.2e} {:+.2e}, compensated {:.2e} {:+.2e}",
        plain.0, plain.1, compensated.0, compensated.1
    );
    // Measured: uncompensated 6.3e-4 with the trace 3.2e-4 low; compensated 4.9e-4,
    // the trace 0.6e-4 high.
    assert!(
        compensated.1.abs() < 0.35 * plain.1.abs(),
        "trace: {compensated:?} vs {plain:?}"
    );
    assert!(
        compensated.0 < 0.9 * plain.0,
        "{compensated:?} vs {plain:?}"
    );
}
