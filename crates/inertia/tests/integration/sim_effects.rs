//! Magnetic field, dipoles, magnetometer, thrusters and the centre of mass in the
//! simulator (`inertia::sim::magnetic`, `inertia::sim::thrusters`), each against its
//! specification. Figures quoted in comments are from the seeds used here.

use crate::common::momentum_balance::{inertial_impulse, inertial_momentum_change};
use inertia::dynamics::GyrostatState;
use inertia::sim::environment::{gravity_gradient_torque_nm, EARTH_RADIUS_M};
use inertia::sim::magnetic::{dipole_field_t, EARTH_DIPOLE_T};
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::thrusters::MAX_THRUSTERS;
use inertia::sim::{
    AttitudeSource, FieldModel, Firing, Magnetic, Magnetometer, Magnetorquer, Orbit, Realism,
    SimError, SimOutput, Thruster, Thrusters, WheelTelemetry,
};
use nalgebra::Vector3;

fn fnv(h: u64, x: f64) -> u64 {
    (h ^ x.to_bits()).wrapping_mul(0x100000001b3)
}

/// FNV-1a over every field of every sample (the outside measurements included, a
/// missing one hashed as a marker) and of the truth.
fn full_hash(out: &SimOutput) -> u64 {
    let mut h = 0xcbf29ce484222325u64;
    let v3 = |h: &mut u64, v: Option<Vector3<f64>>| match v {
        Some(v) => v.iter().for_each(|x| *h = fnv(*h, *x)),
        None => *h = fnv(*h, -7.0),
    };
    for s in &out.samples {
        for x in [s.t_s, s.q.v.x, s.q.v.y, s.q.v.z, s.q.s] {
            h = fnv(h, x);
        }
        v3(&mut h, Some(s.rho_nms));
        v3(&mut h, Some(s.tau_nm));
        v3(&mut h, s.omega_rad_s);
        v3(&mut h, s.external.position_m);
        v3(&mut h, s.external.field_t);
        v3(&mut h, s.external.force_n);
    }
    for t in &out.truth {
        let x = &t.state;
        for v in [x.q.v.x, x.q.v.y, x.q.v.z, x.q.s] {
            h = fnv(h, v);
        }
        v3(&mut h, Some(x.omega_rad_s));
        v3(&mut h, Some(x.rho_nms));
    }
    h
}

/// Every older effect on at once (orbit with gravity gradient, constant, inertial and
/// drag torques, star tracker, wheel noise, noise on): the settings of the regression
/// guard.
fn older_effects() -> Realism {
    let mut r = Realism {
        attitude: AttitudeSource::StarTracker,
        wheels: WheelTelemetry {
            noise_nms: 1e-5,
            ..WheelTelemetry::default()
        },
        ..Realism::default()
    };
    r.environment.orbit = Some(Orbit {
        inclination_deg: 51.6,
        raan_deg: 30.0,
        arg_latitude_deg: 10.0,
        ..Orbit::circular(500e3)
    });
    r.environment.constant_torque_nm = Vector3::new(1e-5, -2e-5, 3e-5);
    r.environment.inertial_torque_nm = Vector3::new(-3e-6, 1e-6, 2e-6);
    r.environment.damping_nms = 1e-4;
    r
}

/// With the new effects off, a run is bit for bit what the simulator produced before
/// they existed (hashes taken at 3c61b60): the paper's slew and spin, and the slew with
/// every older environmental effect on.
#[test]
fn runs_without_the_new_effects_are_unchanged() {
    let run = |sc: Scenario, realism: Realism| {
        sc.simulate(&Common {
            duration_s: Some(60.0),
            seed: 3,
            realism,
            ..Common::paper()
        })
        .unwrap()
    };
    let hashes = [
        full_hash(&run(Scenario::slew(), Realism::default())),
        full_hash(&run(Scenario::spin(), Realism::default())),
        full_hash(&run(Scenario::slew(), older_effects())),
        full_hash(&run(Scenario::spin(), older_effects())),
    ];
    assert_eq!(
        hashes,
        [
            0x2df42dafff693db,
            0x283988ba27569e2d,
            0x6373d42108c5e67a,
            0xdc87297c6aff0517
        ]
    );
}

/// The paper's slew, noise-free, `duration_s` long, with `realism`.
fn slew(duration_s: f64, realism: Realism) -> SimOutput {
    Scenario::slew()
        .simulate(&Common {
            duration_s: Some(duration_s),
            realism,
            ..Common::noise_free()
        })
        .expect("valid settings")
}

/// An inclined orbit at 500 km (both hemispheres within a few minutes).
fn orbit() -> Orbit {
    Orbit {
        inclination_deg: 51.6,
        raan_deg: 30.0,
        arg_latitude_deg: 40.0,
        ..Orbit::circular(500e3)
    }
}

/// The field model of the specification, written out here: `−B0 (R_E/r)³ [3 (ẑ·r̂) r̂ − ẑ]`.
fn spec_field_t(r: &Vector3<f64>) -> Vector3<f64> {
    let n = r.norm();
    let rhat = r / n;
    -(3.0 * rhat.z * rhat - Vector3::z()) * EARTH_DIPOLE_T * (EARTH_RADIUS_M / n).powi(3)
}

/// The magnetorquer law of the specification: `A_i sin(2π t/P_i + φ_i)`.
fn spec_dipole_am2(m: &Magnetorquer, t: f64) -> Vector3<f64> {
    Vector3::from_fn(|i, _| {
        m.amplitude_am2[i] * (2.0 * std::f64::consts::PI * t / m.period_s[i] + m.phase_rad[i]).sin()
    })
}

/// The firing law of the specification, written out here: each thruster's force `F_i(t)`.
fn spec_forces_n(th: &Thrusters, t: f64) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let units: Vec<Thruster> = th.units.iter().flatten().copied().collect();
    let f = &th.firing;
    let k = ((t - f.start_s) / f.period_s).floor();
    let into = t - f.start_s - k * f.period_s;
    units
        .iter()
        .enumerate()
        .map(|(i, u)| {
            let on = t >= f.start_s && into < f.burn_s && (k as usize) % units.len() == i;
            let thrust = if on {
                u.thrust_n * (std::f64::consts::PI * into / f.burn_s).sin().powi(4)
            } else {
                0.0
            };
            (u.position_m, u.direction.normalize() * thrust)
        })
        .collect()
}

/// Wilson–Hilferty: the two-sided 99 % band of a χ² variable with `nu` degrees of freedom.
fn chi2_band_99(nu: f64) -> (f64, f64) {
    let z = 2.575_829_3;
    let c = 2.0 / (9.0 * nu);
    let q = |s: f64| nu * (1.0 - c + s * z * c.sqrt()).powi(3);
    (q(-1.0), q(1.0))
}

/// Per axis: mean, sample std, and whether `(n−1) s²/σ²` is within its 99 % χ² band.
fn noise_stats(errors: &[Vector3<f64>], sigma: f64) -> [(f64, f64, bool); 3] {
    let n = errors.len() as f64;
    let (lo, hi) = chi2_band_99(n - 1.0);
    std::array::from_fn(|i| {
        let m = errors.iter().map(|e| e[i]).sum::<f64>() / n;
        let ss: f64 = errors.iter().map(|e| (e[i] - m).powi(2)).sum();
        let stat = ss / (sigma * sigma);
        (m, (ss / (n - 1.0)).sqrt(), (lo..=hi).contains(&stat))
    })
}

/// The dipole model against its formula: over the equator `|B| = B0 (R_E/r)³` along +ẑ,
/// over the poles twice that along −ẑ (relative 1e-12), directly and at the orbit's
/// positions (an equatorial orbit, a polar one at u = ±90°).
#[test]
fn dipole_field_at_the_equator_and_the_poles() {
    for alt in [0.0, 500e3, 35_786e3] {
        let r = EARTH_RADIUS_M + alt;
        let b_eq = EARTH_DIPOLE_T * (EARTH_RADIUS_M / r).powi(3);
        let mag = Magnetic::dipole();
        let equatorial = Orbit {
            arg_latitude_deg: 77.0,
            ..Orbit::circular(alt)
        };
        for t in [0.0, 1234.5] {
            let b = mag.field_inertial_t(Some(&equatorial), t);
            assert!((b - Vector3::z() * b_eq).norm() <= 1e-12 * b_eq, "{b}");
        }
        for (u, sign) in [(90.0, 1.0), (-90.0, -1.0)] {
            let polar = Orbit {
                inclination_deg: 90.0,
                arg_latitude_deg: u,
                ..Orbit::circular(alt)
            };
            let r_pole = polar.position_m(0.0);
            assert!((r_pole.z - sign * r).abs() < 1e-6 * r);
            let b = mag.field_inertial_t(Some(&polar), 0.0);
            assert!(
                (b.norm() / (2.0 * b_eq) - 1.0).abs() <= 1e-12,
                "{} vs {}",
                b.norm(),
                2.0 * b_eq
            );
            // Along −ẑ over both: into the Earth over the north pole, out of it over
            // the south pole.
            assert!(
                (b + Vector3::z() * 2.0 * b_eq).norm() <= 1e-12 * b_eq,
                "{b}"
            );
            assert!(b.dot(&r_pole) * sign < 0.0);
        }
        // Anywhere: the formula of the specification.
        let r_any = Vector3::new(0.3, -0.5, 0.7).normalize() * r;
        let b = dipole_field_t(&r_any);
        assert!((b - spec_field_t(&r_any)).norm() <= 1e-12 * b.norm());
    }
}

/// The magnetometer without noise reads `C(q)ᵀ B_I` with the true attitude, B_I from the
/// sample's own position (dipole model on an inclined orbit; a constant field without
/// an orbit), relative 1e-14 at every node; the rest of the telemetry is unchanged.
#[test]
fn magnetometer_reads_the_field_in_body_axes() {
    let quiet = Magnetometer {
        noise_t: 0.0,
        bias_t: Vector3::zeros(),
    };
    let mut realism = Realism::default();
    realism.environment.orbit = Some(orbit());
    realism.environment.magnetic = Some(Magnetic {
        magnetometer: quiet,
        ..Magnetic::dipole()
    });
    let out = slew(120.0, realism);
    let mut turned = 0.0f64;
    for (s, t) in out.samples.iter().zip(&out.truth) {
        let b_i = spec_field_t(&s.external.position_m.unwrap());
        let expected = t.state.q.to_matrix().transpose() * b_i;
        let b = s.external.field_t.expect("field in every sample");
        assert!(
            (b - expected).norm() <= 1e-14 * b_i.norm(),
            "{b} vs {expected}"
        );
        turned = turned.max(b.angle(&b_i));
    }
    assert!(
        turned > 0.5,
        "the body turned the field by {turned} rad at most"
    );

    let b_i = Vector3::new(1e-5, -2e-5, 2e-5);
    let mut realism = Realism::default();
    realism.environment.magnetic = Some(Magnetic {
        magnetometer: quiet,
        ..Magnetic::constant(b_i)
    });
    let out = slew(120.0, realism);
    let plain = slew(120.0, Realism::default());
    for ((s, t), p) in out.samples.iter().zip(&out.truth).zip(&plain.samples) {
        let expected = t.state.q.to_matrix().transpose() * b_i;
        assert!((s.external.field_t.unwrap() - expected).norm() <= 1e-14 * b_i.norm());
        assert_eq!(s.external.position_m, None);
        assert_eq!(
            (s.q, s.rho_nms, s.tau_nm, s.omega_rad_s),
            (p.q, p.rho_nms, p.tau_nm, p.omega_rad_s)
        );
    }
}

/// Magnetometer noise σ = 1e-7 T with a bias: over 3001 samples per axis the sample
/// variance is within its 99 % χ² band and the mean within 3.3 σ/√n of the bias; the
/// noise has its own stream (the paper's noise on, truth and other telemetry unchanged).
#[test]
fn magnetometer_noise_and_bias() {
    let sigma = 1e-7;
    let bias = Vector3::new(2e-7, -1e-7, 5e-8);
    let with = |magnetometer: Magnetometer| {
        let mut realism = Realism::default();
        realism.environment.magnetic = Some(Magnetic {
            magnetometer,
            ..Magnetic::constant(Vector3::new(1e-5, -2e-5, 2e-5))
        });
        Scenario::slew()
            .simulate(&Common {
                seed: 11,
                realism,
                ..Common::paper()
            })
            .unwrap()
    };
    let out = with(Magnetometer {
        noise_t: sigma,
        bias_t: bias,
    });
    let quiet = with(Magnetometer {
        noise_t: 0.0,
        bias_t: Vector3::zeros(),
    });
    assert_eq!(out.samples.len(), 3001);
    let errors: Vec<Vector3<f64>> = out
        .samples
        .iter()
        .zip(&quiet.samples)
        .map(|(s, q)| s.external.field_t.unwrap() - q.external.field_t.unwrap())
        .collect();
    let n = errors.len() as f64;
    for (i, (mean, std, inside)) in noise_stats(&errors, sigma).into_iter().enumerate() {
        eprintln!(
            "magnetometer axis {i}: std/σ {:.4}, (mean − bias)/(σ/√n) {:+.2}",
            std / sigma,
            (mean - bias[i]) / (sigma / n.sqrt())
        );
        assert!(
            inside,
            "axis {i}: std {std:e} outside the 99 % band of {sigma:e}"
        );
        assert!(
            (mean - bias[i]).abs() < 3.3 * sigma / n.sqrt(),
            "axis {i}: mean {mean:e}"
        );
    }
    assert_eq!(out.truth, quiet.truth);
    let plain = Scenario::slew()
        .simulate(&Common {
            seed: 11,
            ..Common::paper()
        })
        .unwrap();
    assert_eq!(out.truth, plain.truth);
    for (a, b) in out.samples.iter().zip(&plain.samples) {
        assert_eq!(
            (a.q, a.rho_nms, a.tau_nm, a.omega_rad_s),
            (b.q, b.rho_nms, b.tau_nm, b.omega_rad_s)
        );
    }
}

/// With magnetorquers the reported known torque is `m_cmd(t_k) × B̃_k` with the measured
/// field, exactly (the slew has no other known torque), even with a biased, noisy
/// magnetometer, and so differs from the torque of the true field.
#[test]
fn reported_torque_is_the_commanded_dipole_times_the_measured_field() {
    let torquer = Magnetorquer {
        phase_rad: Vector3::new(0.1, 0.2, 0.3),
        ..Magnetorquer::sine(0.5)
    };
    let mut realism = Realism::default();
    realism.environment.orbit = Some(orbit());
    realism.environment.magnetic = Some(Magnetic {
        magnetorquer: Some(torquer),
        magnetometer: Magnetometer {
            noise_t: 2e-7,
            bias_t: Vector3::new(1e-6, 0.0, -1e-6),
        },
        ..Magnetic::dipole()
    });
    let out = slew(120.0, realism);
    let mut off_true = 0.0f64;
    for (s, t) in out.samples.iter().zip(&out.truth) {
        let b = s.external.field_t.unwrap();
        assert_eq!(
            s.tau_nm,
            torquer.dipole_am2(s.t_s).cross(&b),
            "t = {}",
            s.t_s
        );
        let spec = spec_dipole_am2(&torquer, s.t_s).cross(&b);
        assert!((s.tau_nm - spec).norm() <= 1e-14 * (0.5 * b.norm()));
        let b_true =
            t.state.q.to_matrix().transpose() * spec_field_t(&s.external.position_m.unwrap());
        off_true =
            off_true.max((s.tau_nm - spec_dipole_am2(&torquer, s.t_s).cross(&b_true)).norm());
    }
    assert!(
        off_true > 1e-7,
        "the magnetometer's error is not in tau: {off_true:e}"
    );
}

/// The thrusters' torque about the centre of mass is the reported torque (about the
/// origin) minus `c × F` of the reported force, exactly, at every node; the reported
/// torque and force are those of the layout and the firing law of the specification
/// (relative 1e-14); the force does not vanish while firing and takes three directions.
#[test]
fn thruster_torque_about_the_centre_of_mass() {
    let c = Vector3::new(0.02, -0.01, 0.015);
    let th = Thrusters {
        centre_of_mass_m: c,
        ..Thrusters::cube_pairs(0.02, 0.4)
    };
    let mut realism = Realism::default();
    realism.environment.thrusters = Some(th);
    let out = slew(120.0, realism);
    let mut directions = Vec::<Vector3<f64>>::new();
    let mut firing = 0;
    for s in &out.samples {
        let f = s.external.force_n.expect("force in every sample");
        assert_eq!(
            th.torque_about_com_nm(s.t_s),
            s.tau_nm - c.cross(&f),
            "t = {}",
            s.t_s
        );
        let units = spec_forces_n(&th, s.t_s);
        let f_spec: Vector3<f64> = units.iter().map(|u| u.1).sum();
        let tau_spec: Vector3<f64> = units.iter().map(|(r, f)| r.cross(f)).sum();
        let true_spec: Vector3<f64> = units.iter().map(|(r, f)| (r - c).cross(f)).sum();
        let scale = 0.02 * 0.4;
        assert!((f - f_spec).norm() <= 1e-14 * 0.02);
        assert!((s.tau_nm - tau_spec).norm() <= 1e-14 * scale);
        assert!((th.torque_about_com_nm(s.t_s) - true_spec).norm() <= 1e-14 * scale);
        if f.norm() > 1e-3 {
            firing += 1;
            let d = f.normalize();
            if directions.iter().all(|e| e.dot(&d) < 0.9) {
                directions.push(d);
            }
        }
    }
    assert!(firing > 300, "{firing} nodes with thrust");
    assert_eq!(directions.len(), 3, "{directions:?}");
}

/// Everything at once (gravity gradient, residual dipole and magnetorquers in the dipole
/// field, thrusters off the centre of mass): the body's inertial momentum changes by
/// ∫ C(q) τ dt of the total torque computed here from the specification (relative
/// 1e-7 over a 120 s slew); the reported torque alone misses the unknown parts by far
/// more than that. The wheels stay within the slew's usual momentum.
#[test]
fn momentum_balance_with_every_effect() {
    let o = orbit();
    let torquer = Magnetorquer::sine(0.3);
    let m_res = Vector3::new(0.2, -0.1, 0.15);
    let c = Vector3::new(0.02, -0.01, 0.015);
    let th = Thrusters {
        centre_of_mass_m: c,
        firing: Firing {
            start_s: 3.0,
            period_s: 7.0,
            burn_s: 5.0,
        },
        ..Thrusters::cube_pairs(0.02, 0.4)
    };
    let mut realism = Realism::default();
    realism.environment.orbit = Some(o);
    realism.environment.magnetic = Some(Magnetic {
        residual_dipole_am2: m_res,
        magnetorquer: Some(torquer),
        ..Magnetic::dipole()
    });
    realism.environment.thrusters = Some(th);
    let out = slew(120.0, realism);
    let j = out.inertia_kg_m2;
    let field =
        |t: f64, x: &GyrostatState| x.q.to_matrix().transpose() * spec_field_t(&o.position_m(t));
    let unknown = |t: f64, x: &GyrostatState| {
        let f: Vector3<f64> = spec_forces_n(&th, t).iter().map(|u| u.1).sum();
        gravity_gradient_torque_nm(&o.position_m(t), &x.q, &j) + m_res.cross(&field(t, x))
            - c.cross(&f)
    };
    let known = |t: f64, x: &GyrostatState| {
        let thr: Vector3<f64> = spec_forces_n(&th, t).iter().map(|(r, f)| r.cross(f)).sum();
        spec_dipole_am2(&torquer, t).cross(&field(t, x)) + thr
    };
    let dh = inertial_momentum_change(&out);
    let expected = inertial_impulse(&out, |t, x| known(t, x) + unknown(t, x));
    let rel = (dh - expected).norm() / expected.norm();
    eprintln!(
        "momentum balance: |ΔH| {:.3e} N m s, relative error {rel:.1e}",
        dh.norm()
    );
    assert!(rel < 1e-7, "ΔH {dh} vs ∫Cτ {expected}");
    let missed = inertial_impulse(&out, unknown).norm();
    let peak = out
        .truth
        .iter()
        .map(|t| t.state.rho_nms.norm())
        .fold(0.0, f64::max);
    eprintln!("unknown impulse {missed:.3e} N m s, peak wheel momentum {peak:.3} N m s");
    assert!(
        missed > 1e3 * (dh - expected).norm(),
        "unknown part {missed:e}"
    );
    assert!(peak < 0.3, "peak wheel momentum {peak}");
}

/// Force-sensor noise σ = 1e-3 N over 3001 samples per axis: sample variance within its
/// 99 % χ² band, mean within 3.3 σ/√n of zero; its own stream (truth and the other
/// telemetry unchanged, the paper's noise on).
#[test]
fn force_sensor_noise() {
    let sigma = 1e-3;
    let with = |noise: f64| {
        let mut realism = Realism::default();
        realism.environment.thrusters = Some(Thrusters {
            force_noise_n: noise,
            ..Thrusters::cube_pairs(0.01, 0.3)
        });
        Scenario::slew()
            .simulate(&Common {
                seed: 12,
                realism,
                ..Common::paper()
            })
            .unwrap()
    };
    let (noisy, clean) = (with(sigma), with(0.0));
    let errors: Vec<Vector3<f64>> = noisy
        .samples
        .iter()
        .zip(&clean.samples)
        .map(|(a, b)| a.external.force_n.unwrap() - b.external.force_n.unwrap())
        .collect();
    let n = errors.len() as f64;
    assert!(n >= 3000.0);
    for (i, (mean, std, inside)) in noise_stats(&errors, sigma).into_iter().enumerate() {
        eprintln!(
            "force sensor axis {i}: std/σ {:.4}, mean/(σ/√n) {:+.2}",
            std / sigma,
            mean / (sigma / n.sqrt())
        );
        assert!(inside, "axis {i}: std {std:e}");
        assert!(
            mean.abs() < 3.3 * sigma / n.sqrt(),
            "axis {i}: mean {mean:e}"
        );
    }
    assert_eq!(noisy.truth, clean.truth);
    for (a, b) in noisy.samples.iter().zip(&clean.samples) {
        assert_eq!(
            (a.q, a.rho_nms, a.tau_nm, a.omega_rad_s),
            (b.q, b.rho_nms, b.tau_nm, b.omega_rad_s)
        );
    }
}

/// A field name and a change of the settings that makes it invalid.
type Case = (&'static str, Box<dyn Fn(&mut Realism)>);

/// Every new setting is validated with a typed error naming the field.
#[test]
fn invalid_effect_settings_name_their_field() {
    let try_with = |f: &dyn Fn(&mut Realism)| -> Option<&'static str> {
        let mut r = Realism::default();
        r.environment.orbit = Some(Orbit::circular(500e3));
        r.environment.magnetic = Some(Magnetic {
            magnetorquer: Some(Magnetorquer::sine(0.1)),
            ..Magnetic::dipole()
        });
        r.environment.thrusters = Some(Thrusters::cube_pairs(0.01, 0.3));
        f(&mut r);
        match Scenario::slew().simulate(&Common {
            duration_s: Some(1.0),
            realism: r,
            ..Common::paper()
        }) {
            Err(SimError::InvalidSetting { field, .. }) => Some(field),
            Ok(_) => None,
        }
    };
    fn mag(r: &mut Realism) -> &mut Magnetic {
        r.environment.magnetic.as_mut().unwrap()
    }
    fn thr(r: &mut Realism) -> &mut Thrusters {
        r.environment.thrusters.as_mut().unwrap()
    }
    fn unit(r: &mut Realism) -> &mut Thruster {
        thr(r).units[0].as_mut().unwrap()
    }
    let cases: Vec<Case> = vec![
        (
            "environment.magnetic.field",
            Box::new(|r| r.environment.orbit = None),
        ),
        (
            "environment.magnetic.field",
            Box::new(|r| {
                mag(r).field = FieldModel::Constant {
                    field_t: Vector3::new(0.0, f64::NAN, 0.0),
                }
            }),
        ),
        (
            "environment.magnetic.field",
            Box::new(|r| {
                mag(r).field = FieldModel::Constant {
                    field_t: Vector3::new(0.0, 0.0, 0.1),
                }
            }),
        ),
        (
            "environment.magnetic.residual_dipole_am2",
            Box::new(|r| mag(r).residual_dipole_am2.x = f64::INFINITY),
        ),
        (
            "environment.magnetic.magnetorquer.amplitude_am2",
            Box::new(|r| mag(r).magnetorquer.as_mut().unwrap().amplitude_am2.y = 1e6),
        ),
        (
            "environment.magnetic.magnetorquer.period_s",
            Box::new(|r| mag(r).magnetorquer.as_mut().unwrap().period_s.z = 0.0),
        ),
        (
            "environment.magnetic.magnetorquer.phase_rad",
            Box::new(|r| mag(r).magnetorquer.as_mut().unwrap().phase_rad.x = f64::NAN),
        ),
        (
            "environment.magnetic.magnetometer.noise_t",
            Box::new(|r| mag(r).magnetometer.noise_t = -1e-7),
        ),
        (
            "environment.magnetic.magnetometer.bias_t",
            Box::new(|r| mag(r).magnetometer.bias_t.z = f64::NAN),
        ),
        (
            "environment.thrusters.units.position_m",
            Box::new(|r| unit(r).position_m.x = f64::NAN),
        ),
        (
            "environment.thrusters.units.direction",
            Box::new(|r| unit(r).direction = Vector3::zeros()),
        ),
        (
            "environment.thrusters.units.thrust_n",
            Box::new(|r| unit(r).thrust_n = -1.0),
        ),
        (
            "environment.thrusters.firing.start_s",
            Box::new(|r| thr(r).firing.start_s = f64::INFINITY),
        ),
        (
            "environment.thrusters.firing.period_s",
            Box::new(|r| thr(r).firing.period_s = 0.0),
        ),
        (
            "environment.thrusters.firing.burn_s",
            Box::new(|r| thr(r).firing.burn_s = 11.0),
        ),
        (
            "environment.thrusters.centre_of_mass_m",
            Box::new(|r| thr(r).centre_of_mass_m.y = f64::NAN),
        ),
        (
            "environment.thrusters.force_noise_n",
            Box::new(|r| thr(r).force_noise_n = -1.0),
        ),
    ];
    for (field, f) in &cases {
        assert_eq!(try_with(f.as_ref()), Some(*field), "expected {field}");
    }
    assert_eq!(try_with(&|_| {}), None);
    // An empty set of thrusters is valid and never fires.
    assert_eq!(try_with(&|r| thr(r).units = [None; MAX_THRUSTERS]), None);
}
