//! Each rotor's speed read at its own instant (issue #31 "Per-rotor parameters", a
//! time-tag offset per wheel): a four-wheel pyramid whose wheels' telemetry is skewed by
//! draws of the spacecraft file's `time_tag_sigma_s`, on the paper's slew (120 s) with
//! and without a momentum bias. Reference: the simulated J, the same record with every wheel on time
//! (effect-free), and the file's time tags taken as exact (uncorrected).

use crate::common::wheels::{batch_with_wheels as run, median};
use inertia::estimator::observability::Observability;
use inertia::estimator::rotor_calibration::NotMade;
use inertia::estimator::Estimate;
use inertia::pipeline::{Run, MIN_MOMENTUM_SIGNIFICANCE};
use inertia::sample::Sample;
use inertia::sim::rotors::{pyramid, speeds_each};
use inertia::sim::scenario::{Common, Scenario, SlewPlan};
use inertia::spacecraft::{RotorErrors, Spacecraft};
use inertia::tensor::relative_frobenius_error;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

const TRUE_J: [f64; 4] = [1.5e-3, 1.6e-3, 1.7e-3, 1.8e-3];

/// The file's σ of each wheel's own time tag, s: half the telemetry period.
const TAG_SIGMA_S: f64 = 0.05;

/// The 120 s slew at 10 Hz (seed `seed`, the wheels' momentum at rest `bias` N m s along
/// (0.3, −0.2, 1)), its wheels' speeds read `tags_s[i]` late: samples, speeds, truth.
fn slew(seed: u64, bias: f64, tags_s: &[f64; 4]) -> (Vec<Sample>, Vec<f64>, Matrix3<f64>) {
    let wheels = pyramid(TRUE_J, 0.0, RotorErrors::Independent);
    let sim = |skew_s: f64| {
        let mut common = Common {
            duration_s: Some(120.0),
            seed,
            ..Common::physical()
        };
        common.realism.wheels.skew_s = skew_s;
        Scenario::Slew(SlewPlan {
            momentum_bias_nms: Vector3::new(0.3, -0.2, 1.0) * bias,
            ..SlewPlan::default()
        })
        .simulate(&common)
        .expect("sim")
    };
    let on_time = sim(0.0);
    let late: Vec<_> = tags_s.iter().map(|&t| sim(t)).collect();
    let records: Vec<&[Sample]> = late.iter().map(|o| o.samples.as_slice()).collect();
    let speeds = speeds_each(&records, &wheels).expect("speeds");
    (on_time.samples, speeds, on_time.inertia_kg_m2)
}

/// Each wheel's skew, s: draws of [`TAG_SIGMA_S`], within the telemetry period.
fn drawn_tags(seed: u64) -> [f64; 4] {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(700 + seed);
    let n = Normal::new(0.0, TAG_SIGMA_S).expect("normal");
    core::array::from_fn(|_| n.sample(&mut rng).clamp(-0.099, 0.099))
}

/// The file: the true wheels, each time tag ± `sigma_s`.
fn stated(sigma_s: f64) -> Spacecraft {
    let mut sc = pyramid(TRUE_J, 0.0, RotorErrors::Independent);
    for r in &mut sc.rotors {
        r.time_tag_sigma_s = sigma_s;
    }
    sc
}

/// The largest |error|/σ over J's six elements.
fn worst_z(e: &Estimate, truth: &Matrix3<f64>) -> f64 {
    let t = inertia::tensor::j_from_matrix(truth);
    let (j, s) = (e.j().expect("j"), e.sigma_kg_m2().expect("σ"));
    (0..6)
        .map(|k| (j[k] - t[k]).abs() / s[k])
        .fold(0.0, f64::max)
}

/// The calibration of the drawn skews `tags` from the run `r`: each time tag's
/// |error|/σ (the simulator's skew reads ahead; the report's value is how late each wheel
/// is), after checking that the data fix all four.
fn tag_z(r: &Run, tags: &[f64; 4], seed: u64) -> Vec<f64> {
    let c = r.rotor_calibration().expect("calibrated");
    assert_eq!((c.data_fixed, c.sources.len()), (4, 4), "seed {seed}");
    assert!(c.unit.iter().all(|&u| u == "s"), "{:?}", c.unit);
    c.value
        .iter()
        .zip(&c.sigma)
        .zip(tags)
        .map(|((v, s), t)| (v + t).abs() / s)
        .collect()
}

/// Within 3σ in at least 95 % of them, none beyond 5σ.
fn assert_tags_covered(z: &[f64]) {
    let within = z.iter().filter(|&&z| z <= 3.0).count() as f64 / z.len() as f64;
    let worst = z.iter().fold(0.0f64, |a, &b| a.max(b));
    assert!(
        within >= 0.95 && worst <= 5.0,
        "{within} within 3σ, worst {worst}"
    );
}

/// Problem: each wheel's speed read late by a draw of 50 ms (σ of the file), on the slew
/// with a momentum bias (`bias` N m s), 6 seeds. Reference: the simulated J and skews; the
/// record with every wheel on time; the file's time tags taken as exact. Returns the
/// medians (effect-free, uncorrected, calibrated) and the largest momentum significance
/// after checking that every calibrated
/// answer is determined with the truth within 3σ, that the time tags are covered by their
/// σ, and that the uncorrected answers leave the truth beyond 3σ in at least
/// `plain_beyond_at_least` of 6.
fn calibrated_cell(bias: f64, plain_beyond_at_least: usize) -> (f64, f64, f64, f64) {
    let (mut free, mut plain, mut calibrated) = (Vec::new(), Vec::new(), Vec::new());
    let (mut plain_beyond, mut z, mut significances) = (0, Vec::new(), Vec::new());
    for seed in 1..=6 {
        let tags = drawn_tags(seed);
        let (samples, speeds, truth) = slew(seed, bias, &tags);
        let (free_samples, free_speeds, _) = slew(seed, bias, &[0.0; 4]);
        let err = |e: &Estimate| relative_frobenius_error(&e.inertia().expect("J"), &truth);
        free.push(err(&run(&free_samples, &free_speeds, stated(0.0), false).0));
        let p = run(&samples, &speeds, stated(0.0), false).0;
        plain.push(err(&p));
        plain_beyond += usize::from(worst_z(&p, &truth) > 3.0);
        let (cal, r) = run(&samples, &speeds, stated(TAG_SIGMA_S), true);
        calibrated.push(err(&cal));
        let significance = r.rotor_calibration().map(|c| c.momentum_significance);
        significances.push(significance.unwrap_or(f64::NAN));
        assert!(
            matches!(cal.observability, Observability::Determined { .. })
                && cal.within_3sigma(&truth) == Some(true),
            "seed {seed}: {:?}, {}",
            cal.observability,
            worst_z(&cal, &truth)
        );
        z.extend(tag_z(&r, &tags, seed));
    }
    assert_tags_covered(&z);
    assert!(
        plain_beyond >= plain_beyond_at_least,
        "{plain_beyond} of 6 uncorrected beyond 3σ"
    );
    (
        median(free),
        median(plain),
        median(calibrated),
        significances.into_iter().fold(0.0, f64::max),
    )
}

/// [`calibrated_cell`] with a momentum bias of 0.1 N m s (uncorrected: 4 of 6 beyond 3σ,
/// up to 9.8σ): the median error under a twentieth of the uncorrected one (measured:
/// 3.9e-5 against 2.9e-3; the effect-free one is 1.9e-6, and on three of these 120 s
/// records the estimator takes 7.5 s chains, where the time tags are found less well; on
/// the 300 s slew of the Monte Carlo the calibrated median is within 1.1× the effect-free
/// one); the time tags within 3σ (worst 2.1σ; their least-squares σ alone, without the
/// chains' jackknife, would leave them up to 8σ off).
#[test]
fn each_wheels_own_time_tag_is_calibrated() {
    let (f, p, c, _) = calibrated_cell(0.1, 3);
    assert!(
        c <= 0.05 * p,
        "calibrated {c:e}, uncorrected {p:e}, effect-free {f:e}"
    );
}

/// [`calibrated_cell`] without a momentum bias: time tags alone need no total momentum
/// (their columns `δ_i ρ̇_i` are no calibration of the rotor momentum that J can take
/// up), so the run calibrates them (uncorrected: 2 of 6 beyond 3σ): the median error
/// within 2× the effect-free one (measured: 1.3e-6 against 1.6e-6).
#[test]
fn time_tags_alone_are_calibrated_without_total_momentum() {
    let (f, p, c, significance) = calibrated_cell(0.0, 2);
    assert!(significance < MIN_MOMENTUM_SIGNIFICANCE, "{significance}");
    assert!(
        c <= 2.0 * f,
        "calibrated {c:e}, uncorrected {p:e}, effect-free {f:e}"
    );
}

/// Problem: the same wheels and file without a calibration asked for. Reference: the
/// simulated J, and the same runs with the tags taken as exact (up to 9.8σ off). Each
/// time tag's σ is a consider term: every element's σ wider than with the tags exact,
/// every answer within 3σ (measured: worst 2.0σ).
#[test]
fn each_wheels_time_tag_sigma_widens_sigma() {
    for seed in 1..=6 {
        let (samples, speeds, truth) = slew(seed, 0.1, &drawn_tags(seed));
        let (e, r) = run(&samples, &speeds, stated(TAG_SIGMA_S), false);
        let exact = run(&samples, &speeds, stated(0.0), false).0;
        let (wide, narrow) = (e.sigma_kg_m2().expect("σ"), exact.sigma_kg_m2().expect("σ"));
        assert!(
            wide.iter().zip(&narrow).all(|(w, n)| w > n),
            "seed {seed}: {wide:?} against {narrow:?}"
        );
        assert_eq!(e.within_3sigma(&truth), Some(true), "seed {seed}");
        let c = r
            .rotor_inertia()
            .and_then(|c| c.as_ref().ok())
            .expect("the consider term");
        assert_eq!(c.sources.len(), 4);
        assert!(
            c.sources.iter().all(|s| s.ends_with("time tag")),
            "{:?}",
            c.sources
        );
    }
}

/// Problem: the skewed wheels on the slew with no total momentum, calibration asked for,
/// and the file also states a tilt of σ 0.5° for every axis (the true axes untilted), 6
/// seeds. The tilts need a total momentum; the time tags do not. Reference: the simulated
/// J and skews; the record with every wheel on time (effect-free); the same file without
/// a calibration (every error a consider term). The run says why the tilts were not
/// calibrated, calibrates the time tags alone (their σ covering the draws, and wider than
/// with the time tags alone in the file) and keeps the tilts as a consider term: every
/// answer within 3σ, the median error within 2× the
/// effect-free one and under a hundredth of the all-consider one (measured: 1.3e-6
/// against 1.6e-6 effect-free and 2.0e-3 with every error a consider term).
#[test]
fn with_a_tilt_and_no_total_momentum_the_time_tags_alone_are_calibrated() {
    let (mut free, mut mixed, mut considered, mut z) = (vec![], vec![], vec![], vec![]);
    for seed in 1..=6 {
        let tags = drawn_tags(seed);
        let (samples, speeds, truth) = slew(seed, 0.0, &tags);
        let (free_samples, free_speeds, _) = slew(seed, 0.0, &[0.0; 4]);
        let err = |e: &Estimate| relative_frobenius_error(&e.inertia().expect("J"), &truth);
        let mut sc = stated(TAG_SIGMA_S);
        for r in &mut sc.rotors {
            r.spin_axis_sigma_deg = 0.5;
        }
        let (e, r) = run(&samples, &speeds, sc.clone(), true);
        assert!(
            matches!(
                r.rotor_calibration_not_made(),
                Some(NotMade::NoMomentum { .. })
            ),
            "{:?}",
            r.rotor_calibration_not_made()
        );
        z.extend(tag_z(&r, &tags, seed));
        // Each time tag's σ also carries the tilts', which are not estimated: wider than
        // with the file's time tags alone.
        let alone = run(&samples, &speeds, stated(TAG_SIGMA_S), true).1;
        let (wide, narrow) = (
            &r.rotor_calibration().expect("calibrated").sigma,
            &alone.rotor_calibration().expect("calibrated").sigma,
        );
        assert!(
            wide.iter().zip(narrow).all(|(w, n)| w > n),
            "seed {seed}: {wide:?} against {narrow:?}"
        );
        let c = r
            .rotor_inertia()
            .and_then(|c| c.as_ref().ok())
            .expect("the tilts' consider term");
        assert_eq!(c.sources.len(), 8, "{:?}", c.sources);
        assert!(c.sources.iter().all(|s| s.contains("axis tilt")));
        let report = r.report("slew.csv", &Default::default()).expect("report");
        let w = report
            .warnings
            .iter()
            .find(|w| w.kind == "rotor_calibration_not_made")
            .expect("the warning");
        assert!(
            w.message
                .contains("other than their time tags were not calibrated with J (the time tags"),
            "{}",
            w.message
        );
        // The report's consider term is the tilts' alone.
        let entry = report.rotor_inertia.as_ref().expect("the consider term");
        assert!(entry.time_tag_sigma_s.iter().all(|&t| t == 0.0));
        assert_eq!(
            e.within_3sigma(&truth),
            Some(true),
            "seed {seed}: {}",
            worst_z(&e, &truth)
        );
        mixed.push(err(&e));
        considered.push(err(&run(&samples, &speeds, sc, false).0));
        free.push(err(&run(&free_samples, &free_speeds, stated(0.0), false).0));
    }
    assert_tags_covered(&z);
    let (f, m, c) = (median(free), median(mixed), median(considered));
    assert!(
        m <= 2.0 * f && m <= 0.01 * c,
        "tags calibrated {m:e}, effect-free {f:e}, all considered {c:e}"
    );
}

/// Problem: per-rotor records simulated with one skew for every wheel, then with one skew
/// each. Reference: the speeds of one record with that skew, and each rotor's record's.
/// [`speeds_each`] gives them exactly; records of other lengths, or not one per rotor,
/// are refused.
#[test]
fn per_rotor_records_with_one_skew_are_that_records_speeds() {
    let (samples, speeds, _) = slew(1, 0.1, &[0.03; 4]);
    let wheels = pyramid(TRUE_J, 0.0, RotorErrors::Independent);
    let mut common = Common {
        duration_s: Some(120.0),
        seed: 1,
        ..Common::physical()
    };
    common.realism.wheels.skew_s = 0.03;
    let one = Scenario::Slew(SlewPlan {
        momentum_bias_nms: Vector3::new(0.3, -0.2, 1.0) * 0.1,
        ..SlewPlan::default()
    })
    .simulate(&common)
    .expect("sim");
    let direct = inertia::sim::rotors::speeds(&one.samples, &wheels).expect("speeds");
    assert_eq!(speeds, direct);
    // The attitude is the same record's: the skew moves the wheels' telemetry only.
    assert!(samples.iter().zip(&one.samples).all(|(a, b)| a.q == b.q));
    // Distinct skews: rotor i's speeds are record i's.
    let skews = [0.03, -0.02, 0.05, 0.0];
    let records: Vec<Vec<Sample>> = skews
        .iter()
        .map(|&k| {
            let mut c = common.clone();
            c.realism.wheels.skew_s = k;
            Scenario::Slew(SlewPlan {
                momentum_bias_nms: Vector3::new(0.3, -0.2, 1.0) * 0.1,
                ..SlewPlan::default()
            })
            .simulate(&c)
            .expect("sim")
            .samples
        })
        .collect();
    let each = speeds_each(
        &records.iter().map(Vec::as_slice).collect::<Vec<_>>(),
        &wheels,
    )
    .expect("speeds");
    for (i, r) in records.iter().enumerate() {
        let own = inertia::sim::rotors::speeds(r, &wheels).expect("speeds");
        assert!(
            (0..r.len()).all(|k| each[4 * k + i] == own[4 * k + i]),
            "rotor {i}"
        );
    }
    assert_ne!(each, speeds);
    let short = &samples[..10];
    let records: Vec<&[Sample]> = vec![&samples, &samples, &samples, short];
    assert!(speeds_each(&records, &wheels).is_err());
    assert!(speeds_each(&records[..3], &wheels).is_err());
}
