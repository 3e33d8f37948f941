//! Unit tests of the equation-error baseline: the filter against polynomials and its
//! convergence order, recovery of a known J, invariance under a change of body frame.

use super::filter::SavitzkyGolay;
use super::*;
use crate::discrete::RowError;
use crate::sim::presets::{LabEffect, Preset};
use crate::sim::SimOutput;
use crate::tensor::{matrix_from_j, relative_frobenius_error};
use nalgebra::Rotation3;

const ALL: [LabEffect; 4] = [
    LabEffect::Vibration,
    LabEffect::SpeedTelemetry,
    LabEffect::InertialTorque,
    LabEffect::Drag,
];

/// The throw with no lab effect, gyro noise `gyro_deg_s_rthz`, seed `seed`.
fn bare_throw(gyro_deg_s_rthz: f64, seed: u64) -> SimOutput {
    let mut p = Preset::throw_without(&ALL);
    p.common.gyro_noise_deg_s_rthz = gyro_deg_s_rthz;
    p.common.seed = seed;
    p.simulate().expect("valid settings")
}

fn run(samples: &[Sample], settings: EquationErrorSettings) -> (EquationError, Estimate) {
    let mut e = EquationError::new(settings);
    for s in samples {
        e.push(s).expect("valid samples");
    }
    let t = samples.last().map_or(0.0, |s| s.t_s);
    let est = e.estimate(t);
    (e, est)
}

/// The error with a 25 Hz cutoff (a window of 251 samples at 4 kHz: the default's 33
/// leave the ω̇ of the noisiest gyro below too noisy for a physical J).
fn error(samples: &[Sample], truth: &Matrix3<f64>) -> f64 {
    let (_, e) = run(
        samples,
        EquationErrorSettings {
            cutoff_hz: Some(25.0),
            ..EquationErrorSettings::default()
        },
    );
    relative_frobenius_error(&e.inertia().expect("an answer"), truth)
}

/// Smoothing is exact for polynomials of degree ≤ 5, the first derivative for degree ≤ 4
/// and the second for degree ≤ 5 (order 4, symmetric window); the first derivative is
/// not exact at degree 5 (so the order test below can fail).
#[test]
fn savitzky_golay_is_exact_on_polynomials_of_its_degree() {
    let f = SavitzkyGolay::new(6);
    let h = 0.01;
    let at = |d: i32, i: usize| ((i as f64 - 6.0) * h).powi(d);
    for d in 0..=5 {
        let y: Vec<f64> = (0..f.window_len()).map(|i| at(d, i)).collect();
        let dot = |w: &[f64]| w.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>();
        let exact1 = if d == 1 { 1.0 } else { 0.0 };
        let exact2 = if d == 2 { 2.0 } else { 0.0 };
        let exact0 = if d == 0 { 1.0 } else { 0.0 };
        assert!(
            (dot(&f.smooth) - exact0).abs() < 1e-12,
            "smooth, degree {d}"
        );
        assert!(
            (dot(&f.d2) / (h * h) - exact2).abs() < 1e-8,
            "d2, degree {d}"
        );
        if d <= 4 {
            assert!((dot(&f.d1) / h - exact1).abs() < 1e-10, "d1, degree {d}");
        } else {
            // x⁵ at 0 has zero derivative, but the fit sees a cubic-like slope.
            let y5: Vec<f64> = (0..f.window_len()).map(|i| at(5, i) + at(1, i)).collect();
            let d1: f64 = f.d1.iter().zip(&y5).map(|(a, b)| a * b).sum::<f64>() / h;
            assert!((d1 - 1.0).abs() > 1e-9, "d1 exact at degree 5: {d1}");
        }
    }
}

/// With a window of fixed length in samples, the differentiators' error on a smooth
/// signal falls as h⁴: fitted order over four halvings of h, first and second
/// derivative of sin(3t + 0.2) at t = 0.4.
#[test]
fn differentiation_converges_at_fourth_order_in_the_step() {
    let f = SavitzkyGolay::new(10);
    let (w, p, t0) = (3.0, 0.2, 0.4);
    let mut e1 = Vec::new();
    let mut e2 = Vec::new();
    let steps: Vec<f64> = (0..5).map(|k| 0.02 / 2f64.powi(k)).collect();
    for &h in &steps {
        let y: Vec<f64> = (0..f.window_len())
            .map(|i| (w * (t0 + (i as f64 - 10.0) * h) + p).sin())
            .collect();
        let dot = |wt: &[f64]| wt.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>();
        e1.push((dot(&f.d1) / h - w * (w * t0 + p).cos()).abs());
        e2.push((dot(&f.d2) / (h * h) + w * w * (w * t0 + p).sin()).abs());
    }
    let order = |e: &[f64]| {
        let n = e.len() as f64;
        let xs: Vec<f64> = steps.iter().map(|h| h.ln()).collect();
        let ys: Vec<f64> = e.iter().map(|v| v.ln()).collect();
        let mx = xs.iter().sum::<f64>() / n;
        let my = ys.iter().sum::<f64>() / n;
        let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
        sxy / sxx
    };
    let (o1, o2) = (order(&e1), order(&e2));
    assert!(
        (3.8..4.2).contains(&o1),
        "first derivative order {o1}: {e1:?}"
    );
    assert!(
        (3.8..4.2).contains(&o2),
        "second derivative order {o2}: {e2:?}"
    );
}

/// The cutoff sets the window: 25 Hz at 4 kHz is a window of 251 samples, the default
/// cutoff (200 Hz at 4 kHz) one of 33, and a cutoff too high for the rate still gives
/// the smallest window.
#[test]
fn window_follows_the_cutoff() {
    assert_eq!(SavitzkyGolay::for_cutoff(25.0, 4000.0).window_len(), 251);
    assert_eq!(
        SavitzkyGolay::for_cutoff(4000.0 * DEFAULT_CUTOFF_FRACTION, 4000.0).window_len(),
        33
    );
    assert_eq!(SavitzkyGolay::for_cutoff(1e9, 10.0).window_len(), 7);
}

/// Recovery of a known J on the throw with no lab effect: the error falls as the gyro
/// noise falls (0.1, 0.01, 0.001 deg/s/√Hz, median of 5 seeds), down to the filter's
/// bias on noise-free data (below 1e-3).
#[test]
fn recovers_a_known_j_and_the_error_falls_with_the_noise() {
    let truth = Preset::throw().common.inertia_kg_m2;
    let noiseless = error(&bare_throw(0.0, 1).samples, &truth);
    assert!(noiseless < 1e-3, "noise-free error {noiseless}");
    let mut medians = Vec::new();
    for noise in [0.1, 0.01, 0.001] {
        let mut e: Vec<f64> = (1..=5)
            .map(|seed| error(&bare_throw(noise, seed).samples, &truth))
            .collect();
        e.sort_by(f64::total_cmp);
        medians.push(e[2]);
    }
    eprintln!("errors {medians:?}, noise-free {noiseless}");
    assert!(
        medians[0] > 3.0 * medians[1] && medians[1] > 2.0 * medians[2].max(noiseless),
        "errors at 0.1/0.01/0.001 deg/s/√Hz: {medians:?}, noise-free {noiseless}"
    );
}

/// A change of body frame: with every body vector rotated by R (ω, ρ, τ; the attitude
/// composed with Rᵀ), the estimate is R Ĵ Rᵀ (relative 1e-9) and its σ of the
/// rotation-invariant trace agrees.
#[test]
fn invariant_under_a_change_of_body_frame() {
    let out = bare_throw(0.01, 2);
    let r = Rotation3::from_scaled_axis(Vector3::new(0.3, -0.7, 1.1));
    let rq = crate::attitude::Quaternion::from_matrix(r.matrix());
    let rotated: Vec<Sample> = out
        .samples
        .iter()
        .map(|s| Sample {
            q: s.q.mul(&rq.conjugate()),
            rho_nms: r * s.rho_nms,
            tau_nm: r * s.tau_nm,
            omega_rad_s: s.omega_rad_s.map(|w| r * w),
            ..*s
        })
        .collect();
    let (_, a) = run(&out.samples, EquationErrorSettings::default());
    let (_, b) = run(&rotated, EquationErrorSettings::default());
    let ja = matrix_from_j(&a.j().expect("answer"));
    let jb = matrix_from_j(&b.j().expect("answer"));
    let expected = r.matrix() * ja * r.matrix().transpose();
    assert!(
        (jb - expected).norm() < 1e-9 * ja.norm(),
        "{jb} vs R J Rᵀ {expected}"
    );
}

/// The streaming estimate after the last sample is the one-solve estimate, bit for bit.
#[test]
fn streaming_and_one_solve_agree() {
    let out = bare_throw(0.01, 3);
    let mut e = EquationError::new(EquationErrorSettings::default());
    let mut last = None;
    for s in &out.samples {
        last = e.push(s).expect("valid").or(last);
    }
    let (_, once) = run(
        &out.samples,
        EquationErrorSettings {
            solve_every: usize::MAX,
            ..EquationErrorSettings::default()
        },
    );
    assert_eq!(last.and_then(|e| e.j()), once.j());
}

/// A constant body-frame torque biases the torque-free fit; with the torque as unknowns
/// the fit recovers both J (error below 1e-3, noise-free) and the torque (relative 5e-2: 1e-5 N m against rows of 3e-2 N m).
#[test]
fn body_torque_unknowns_absorb_a_constant_body_torque() {
    let tau = Vector3::new(2e-4, -1e-4, 1.5e-4);
    let mut p = Preset::throw_without(&ALL);
    p.common.gyro_noise_deg_s_rthz = 0.0;
    p.common.realism.environment.constant_torque_nm = tau;
    let out = p.simulate().expect("valid");
    let truth = p.common.inertia_kg_m2;
    let plain = error(&out.samples, &truth);
    let (e, est) = run(
        &out.samples,
        EquationErrorSettings {
            body_torque: true,
            cutoff_hz: Some(25.0),
            ..EquationErrorSettings::default()
        },
    );
    let with = relative_frobenius_error(&est.inertia().expect("answer"), &truth);
    let t = e.body_torque_nm().expect("torque");
    assert!(
        with < 1e-3 && plain > 10.0 * with,
        "with {with}, without {plain}"
    );
    eprintln!("with {with}, without {plain}, torque {t}");
    assert!((t - tau).norm() < 5e-2 * tau.norm(), "{t} vs {tau}");
}

/// A non-uniform step is refused with the reason; a sample without a gyro rate names
/// its index.
#[test]
fn refuses_non_uniform_steps_and_missing_rates() {
    let out = bare_throw(0.0, 1);
    let mut samples = out.samples[..20].to_vec();
    samples[10].t_s += 1e-4;
    let mut e = EquationError::new(EquationErrorSettings::default());
    let err = samples.iter().map(|s| e.push(s)).find_map(Result::err);
    assert!(
        matches!(err, Some(EstimatorError::InvalidSetting { field: "t", .. })),
        "{err:?}"
    );
    let mut e = EquationError::new(EquationErrorSettings::default());
    let mut s = out.samples[0];
    s.omega_rad_s = None;
    assert!(matches!(
        e.push(&s),
        Err(EstimatorError::Row {
            sample: 0,
            source: RowError::MissingGyroRate
        })
    ));
}
