//! The lab effects of the simulator (`Preset::throw`, issue #30 item 6): each against its
//! specification. The gyro's vibration at the rotor frequency, the wheel-speed telemetry's
//! quantisation and hold, the aerodynamic torque fixed in the inertial frame and the air
//! drag `−D ω`.

use inertia::attitude::Quaternion;
use inertia::dynamics::GyrostatState;
use inertia::sim::presets::{LabEffect, Preset, THROW};
use inertia::sim::{
    simulate, Environment, Realism, RotorVibration, SimConfig, SimError, SimOutput, WheelTelemetry,
    Zero,
};
use nalgebra::{Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const ALL: [LabEffect; 4] = LabEffect::ALL;

/// The throw with only the effects in `on`, every noise off.
fn throw_with(on: &[LabEffect]) -> SimOutput {
    let mut p = Preset::throw_with(on);
    p.common.gyro_noise_deg_s_rthz = 0.0;
    p.common.disturbance_nm_rthz = 0.0;
    p.simulate().expect("valid settings")
}

fn inertial_momentum_change(out: &SimOutput) -> Vector3<f64> {
    let j = out.inertia_kg_m2;
    let last = out.truth.len() - 1;
    out.truth[last].state.inertial_momentum(&j) - out.truth[0].state.inertial_momentum(&j)
}

/// ∫ C(q) τ dt over the truth nodes (Simpson; an even number of intervals).
fn inertial_impulse(
    out: &SimOutput,
    torque: impl Fn(&GyrostatState) -> Vector3<f64>,
) -> Vector3<f64> {
    let n = out.truth.len() - 1;
    assert!(n.is_multiple_of(2));
    let h = out.truth[1].t_s - out.truth[0].t_s;
    let f = |k: usize| out.truth[k].state.q.rotate(&torque(&out.truth[k].state));
    let mut s = f(0) + f(n);
    for k in 1..n {
        s += f(k) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * (h / 3.0)
}

fn random_unit_quaternion(rng: &mut ChaCha8Rng) -> Quaternion {
    let v = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    Quaternion::new(v, rng.random_range(-1.0..1.0))
        .normalize()
        .expect("non-zero")
}

/// The environment's torque: the drag part is `−D ω` and the inertial part rotated back to
/// the inertial frame is the set torque, both to machine precision, at 1000 random
/// attitudes and rates.
#[test]
fn drag_is_minus_d_omega_and_the_inertial_torque_is_fixed_in_the_inertial_frame() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let tau_i = Vector3::new(2e-4, -1.5e-4, 1e-4);
    let d = 4e-6;
    let j = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0));
    for _ in 0..1000 {
        let q = random_unit_quaternion(&mut rng);
        let w = Vector3::new(
            rng.random_range(-20.0..20.0),
            rng.random_range(-20.0..20.0),
            rng.random_range(-20.0..20.0),
        );
        let drag = Environment {
            damping_nms: d,
            ..Environment::default()
        };
        let t = drag.torque_nm(0.3, &q, &w, &j);
        assert!((t + w * d).norm() <= 1e-15 * (w * d).norm(), "{t} vs −Dω");
        let aero = Environment {
            inertial_torque_nm: tau_i,
            ..Environment::default()
        };
        let t = aero.torque_nm(0.3, &q, &w, &j);
        assert!((q.rotate(&t) - tau_i).norm() <= 1e-15 * tau_i.norm() * 4.0);
        // Fixed in the inertial frame, so not in the body frame.
        assert!(t.norm() > 0.0);
    }
}

/// Through the simulator: the inertial torque alone changes the inertial momentum by
/// `τ_I T` (relative 1e-9 over the 0.5 s throw); the drag alone by `∫ C(q)(−D ω) dt`
/// (relative 1e-6); neither is in `tau_nm`; without them the momentum is conserved.
#[test]
fn air_torques_change_the_inertial_momentum_as_specified() {
    let aero = throw_with(&[LabEffect::InertialTorque]);
    let t_end = aero.truth.last().expect("samples").t_s;
    let expected = Vector3::from(THROW.inertial_torque_nm) * t_end;
    let dh = inertial_momentum_change(&aero);
    assert!(
        (dh - expected).norm() < 1e-9 * expected.norm(),
        "{dh} vs {expected}"
    );
    assert!(aero.samples.iter().all(|s| s.tau_nm == Vector3::zeros()));

    let drag = throw_with(&[LabEffect::Drag]);
    let expected = inertial_impulse(&drag, |x| -x.omega_rad_s * THROW.damping_nms);
    let dh = inertial_momentum_change(&drag);
    assert!(
        (dh - expected).norm() < 1e-6 * expected.norm(),
        "{dh} vs {expected}"
    );

    let free = throw_with(&[]);
    assert!(inertial_momentum_change(&free).norm() < 1e-6 * expected.norm());
}

/// The vibration at a constant rotor speed: the difference of the reported rates with and
/// without it is a sinusoid whose spectrum peaks at the rotor frequency, with amplitude
/// `A sinc(Ω h/2)` and the set phase per axis (least-squares fit at the rotor frequency,
/// relative 1e-9), and it is absent on the rotor axis. The body's motion is unchanged.
#[test]
fn gyro_vibration_peaks_at_the_rotor_frequency_with_the_set_amplitude() {
    let inertia_w = 5e-6;
    let speed = 600.0;
    let amplitude = Vector3::new(0.02, 0.03, 0.0);
    let phase = Vector3::new(0.4, 0.4 + core::f64::consts::FRAC_PI_2, 0.0);
    let h = 2.5e-4;
    let run = |vibration: RotorVibration| {
        let cfg = SimConfig {
            inertia_kg_m2: Preset::throw().common.inertia_kg_m2,
            initial: GyrostatState {
                q: Quaternion::IDENTITY,
                omega_rad_s: Vector3::new(5.0, -4.0, 7.0),
                rho_nms: Vector3::z() * (inertia_w * speed),
            },
            t0_s: 0.0,
            dt_s: h,
            samples: 2001,
            substeps: 2,
            disturbance_nm_rthz: 0.0,
            gyro_noise_deg_s_rthz: 0.0,
            seed: 3,
            inertia_change: None,
            realism: Realism {
                vibration,
                ..Realism::default()
            },
        };
        simulate(&cfg, &Zero, &Zero).expect("valid settings")
    };
    let on = run(RotorVibration {
        amplitude_rad_s: amplitude,
        phase_rad: phase,
        rotor_spin_inertia_kg_m2: inertia_w,
    });
    let off = run(RotorVibration::default());
    assert_eq!(on.truth, off.truth, "the vibration is a sensor error");
    let n = on.samples.len() - 1; // the last sample has no rate
    let d: Vec<Vector3<f64>> = (0..n)
        .map(|k| {
            on.samples[k].omega_rad_s.expect("rate") - off.samples[k].omega_rad_s.expect("rate")
        })
        .collect();
    let f_rotor = speed / core::f64::consts::TAU;
    // Spectrum: the largest periodogram value over 1 Hz steps to Nyquist is within 1 Hz of
    // the rotor frequency.
    let t_mid = |k: usize| (k as f64 + 0.5) * h;
    let power = |axis: usize, f: f64| {
        let (mut c, mut s) = (0.0, 0.0);
        for (k, v) in d.iter().enumerate() {
            let a = core::f64::consts::TAU * f * t_mid(k);
            c += v[axis] * a.cos();
            s += v[axis] * a.sin();
        }
        c * c + s * s
    };
    let peak = (1..2000)
        .map(|f| f as f64)
        .max_by(|a, b| power(0, *a).total_cmp(&power(0, *b)))
        .expect("frequencies");
    assert!(
        (peak - f_rotor).abs() <= 1.0,
        "peak {peak} Hz, rotor {f_rotor} Hz"
    );
    let sinc = {
        let x = speed * h / 2.0;
        x.sin() / x
    };
    for axis in 0..2 {
        // Fit a sin(Ω t) + b cos(Ω t) at the interval mid-points.
        let (mut ss, mut cc, mut sc, mut ys, mut yc) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (k, v) in d.iter().enumerate() {
            let (s, c) = (speed * t_mid(k)).sin_cos();
            ss += s * s;
            cc += c * c;
            sc += s * c;
            ys += v[axis] * s;
            yc += v[axis] * c;
        }
        let det = ss * cc - sc * sc;
        let a = (ys * cc - yc * sc) / det;
        let b = (yc * ss - ys * sc) / det;
        let fitted = a.hypot(b);
        let expected = amplitude[axis] * sinc;
        assert!(
            (fitted - expected).abs() < 1e-9 * expected,
            "axis {axis}: amplitude {fitted} vs A sinc = {expected}"
        );
        // a sin + b cos = R sin(Ω t + φ): φ = atan2(b, a).
        let fitted_phase = b.atan2(a);
        let dp = (fitted_phase - phase[axis]).rem_euclid(core::f64::consts::TAU);
        assert!(
            dp.min(core::f64::consts::TAU - dp) < 1e-9,
            "axis {axis} phase"
        );
    }
    assert!(d.iter().all(|v| v.z == 0.0));
}

/// The speed telemetry's quantisation during the spin-up: the error of the telemetered ρ
/// against the true one is within ±q/2, with mean 0 and variance q²/12 (uniform: each
/// quarter of [−q/2, q/2] holds a quarter of the errors, ±0.05).
#[test]
fn speed_quantisation_error_is_uniform_within_half_a_step() {
    let mut p = Preset::throw_without(&[
        LabEffect::Vibration,
        LabEffect::InertialTorque,
        LabEffect::Drag,
    ]);
    p.common.realism.wheels.hold_hz = None;
    let q = p.common.realism.wheels.quantization_nms;
    assert!(q > 0.0);
    let out = p.simulate().expect("valid settings");
    let errors: Vec<f64> = out
        .samples
        .iter()
        .zip(&out.truth)
        .filter(|(s, _)| s.t_s > 0.1 && s.t_s < 0.3)
        .map(|(s, t)| s.rho_nms.z - t.state.rho_nms.z)
        .collect();
    let n = errors.len() as f64;
    assert!(n > 700.0);
    assert!(errors.iter().all(|e| e.abs() <= 0.5 * q * (1.0 + 1e-9)));
    let mean = errors.iter().sum::<f64>() / n;
    let var = errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0);
    assert!(
        mean.abs() < 4.0 * q / (12.0 * n).sqrt(),
        "mean {mean} of q {q}"
    );
    assert!(
        (var / (q * q / 12.0) - 1.0).abs() < 0.15,
        "variance {var} vs q²/12"
    );
    for quarter in 0..4 {
        let lo = -0.5 * q + 0.25 * q * quarter as f64;
        let count = errors
            .iter()
            .filter(|e| **e >= lo && **e < lo + 0.25 * q)
            .count();
        let share = count as f64 / n;
        assert!((share - 0.25).abs() < 0.05, "quarter {quarter}: {share}");
    }
    // Only the body-z rotor moves: x and y stay exactly 0.
    assert!(out
        .samples
        .iter()
        .all(|s| s.rho_nms.x == 0.0 && s.rho_nms.y == 0.0));
}

/// The hold: at 4 kHz with speed telemetry at 100 Hz, ρ̃ is a staircase with steps every
/// 40 samples starting at the first; each step's value is the quantised true ρ at its
/// first sample; and a hold rate that is not a whole fraction of the telemetry rate is
/// refused, naming its field.
#[test]
fn held_speed_telemetry_is_the_stated_staircase() {
    let out = throw_with(&[LabEffect::SpeedTelemetry]);
    let q = THROW.rotor_spin_inertia_kg_m2 * THROW.speed_step_rad_s;
    let m = 40;
    for (i, s) in out.samples.iter().enumerate() {
        let tick = (i / m) * m;
        assert_eq!(s.rho_nms, out.samples[tick].rho_nms, "sample {i}");
        let truth = out.truth[tick].state.rho_nms;
        assert_eq!(s.rho_nms, truth.map(|v| (v / q).round() * q), "sample {i}");
    }
    let changes = out
        .samples
        .windows(2)
        .filter(|w| w[0].rho_nms != w[1].rho_nms)
        .count();
    assert!(changes > 10 && changes <= out.samples.len() / m);

    let mut p = Preset::throw();
    p.common.realism.wheels.hold_hz = Some(300.0);
    match p.simulate() {
        Err(SimError::InvalidSetting { field, .. }) => assert_eq!(field, "wheels.hold_hz"),
        other => panic!(
            "expected a refusal, got {:?}",
            other.map(|o| o.samples.len())
        ),
    }
}

/// The preset is the lab's record: 0.5 s at 4 kHz, the rotor spun from rest to its final
/// speed, a tumble near 10 rad/s; each effect off when asked is its default (that each is
/// on in the preset is a unit test of `sim::presets`).
#[test]
fn throw_preset_is_the_lab_record() {
    let p = Preset::throw();
    let out = p.simulate().expect("valid settings");
    assert_eq!(out.samples.len(), 2001);
    assert!((out.samples[1].t_s - 2.5e-4).abs() < 1e-15);
    let last = out.truth.last().expect("samples").state;
    let speed = last.rho_nms.norm() / THROW.rotor_spin_inertia_kg_m2;
    assert!((speed - THROW.rotor_speed_rad_s).abs() < 1e-9 * speed);
    let w = out.truth[0].state.omega_rad_s.norm();
    assert!((5.0..15.0).contains(&w));
    let bare = Preset::throw_without(&ALL).common.realism;
    assert_eq!(bare.wheels, WheelTelemetry::default());
    assert_eq!(bare.environment, Environment::default());
    assert_eq!(Preset::by_name("throw").map(|p| p.name), Some("throw"));
}

/// Bad lab settings are refused, naming their field.
#[test]
fn invalid_lab_settings_name_their_field() {
    type Set = fn(&mut Realism);
    let cases: [(&str, Set); 4] = [
        ("environment.damping_nms", |r| {
            r.environment.damping_nms = -1.0
        }),
        ("environment.inertial_torque_nm", |r| {
            r.environment.inertial_torque_nm = Vector3::new(f64::NAN, 0.0, 0.0)
        }),
        ("vibration.rotor_spin_inertia_kg_m2", |r| {
            r.vibration.rotor_spin_inertia_kg_m2 = 0.0
        }),
        ("vibration.amplitude_rad_s", |r| {
            r.vibration.amplitude_rad_s = Vector3::new(f64::INFINITY, 0.0, 0.0)
        }),
    ];
    for (name, set) in cases {
        let mut p = Preset::throw();
        set(&mut p.common.realism);
        match p.simulate() {
            Err(SimError::InvalidSetting { field, .. }) => assert_eq!(field, name),
            other => panic!("{name}: expected a refusal, got {:?}", other.is_ok()),
        }
    }
}

/// The equation-error baseline by name through the pipeline: on the noise-free throw
/// with no lab effect it recovers J (relative Frobenius error below 1e-3) with a σ,
/// and a memory, which it has none of, is refused naming the setting.
#[test]
fn equation_error_baseline_through_the_pipeline() {
    use inertia::pipeline::{Pipeline, PipelineError, PipelineSettings};
    let out = throw_with(&[]);
    let settings = PipelineSettings {
        estimator: "equation-error".into(),
        solve_every: 100,
        ..PipelineSettings::default()
    };
    let mut p = Pipeline::new(&settings).expect("valid settings");
    for s in &out.samples {
        p.push(s).expect("valid samples");
    }
    let e = p.last().expect("an estimate");
    let j = e.inertia().expect("an answer");
    let err = inertia::tensor::relative_frobenius_error(&j, &out.inertia_kg_m2);
    assert!(err < 1e-3, "error {err}");
    assert!(e.sigma_kg_m2().is_some());
    let with_memory = PipelineSettings {
        memory_s: Some(1.0),
        ..settings
    };
    assert!(matches!(
        Pipeline::new(&with_memory),
        Err(PipelineError::InvalidSetting {
            field: "memory_s",
            ..
        })
    ));
}

/// Problem: the throw with every lab effect (seed 1). Reference: the simulated J.
/// `filter_cutoff_hz` reaches the equation-error baseline: at 25 Hz (below the rotor's
/// vibration and the 100 Hz speed staircase) its error is at least 3 times smaller than
/// at its default cutoff (a twentieth of 4 kHz, which passes both; measured 3.2e-2
/// against 2.0e-1 from the CLI); another estimator refuses the setting, naming it.
#[test]
fn the_filter_cutoff_reaches_the_equation_error_baseline_only() {
    use inertia::pipeline::{Pipeline, PipelineSettings};
    let mut p = Preset::throw();
    p.common.seed = 1;
    let run = p.simulate().expect("sim");
    let error = |cutoff: Option<f64>| {
        let mut e = Pipeline::new(&PipelineSettings {
            estimator: "equation-error".into(),
            filter_cutoff_hz: cutoff,
            ..PipelineSettings::default()
        })
        .expect("settings");
        for s in &run.samples {
            e.push(s).expect("push");
        }
        let j = e.last().and_then(|x| x.inertia()).expect("answer");
        inertia::tensor::relative_frobenius_error(&j, &run.inertia_kg_m2)
    };
    let (tuned, default) = (error(Some(25.0)), error(None));
    assert!(
        3.0 * tuned < default,
        "25 Hz {tuned:e}, default {default:e}"
    );
    let refused = PipelineSettings {
        filter_cutoff_hz: Some(25.0),
        ..PipelineSettings::default()
    }
    .validate()
    .map(drop)
    .unwrap_err();
    assert!(
        refused.to_string().contains("filter_cutoff_hz"),
        "{refused}"
    );
}
