//! Torques of outside measurements (`estimator/external_torque.rs`): the gravity gradient
//! from the positions, a residual magnetic dipole from the field, the centre of mass from
//! the force.
//!
//! * Physics: on noise-free data with the true attitude each is recovered exactly (J to
//!   rounding, the dipole and the centre of mass to rounding); left out, J is biased.
//! * Honest σ: with gyro noise the dipole and the centre of mass lie within 3σ of the
//!   truth, and the centre of mass within 1 mm.
//! * Independent paths: the streaming and the batch runs give the same J.

use inertia::estimator::external_torque::OutsideEstimates;
use inertia::estimator::momentum_rows::OutsideTorques;
use inertia::pipeline::{Pipeline, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::control::SlewController;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{simulate, AttitudeSource, InputLaw, Orbit, SimOutput};
use inertia::tensor::relative_frobenius_error;
use nalgebra::{Matrix3, Vector3};

/// A residual dipole, A m² (body axes).
const DIPOLE_AM2: [f64; 3] = [0.05, -0.03, 0.02];
/// A constant field in the inertial frame, T.
const FIELD_T: [f64; 3] = [2.0e-5, -1.0e-5, 2.5e-5];
/// A centre of mass 2 cm or so from the origin, m (body axes).
const CENTRE_M: [f64; 3] = [0.02, -0.012, 0.015];

/// A smooth thruster force in body axes, N.
fn force_n(t_s: f64) -> Vector3<f64> {
    Vector3::new(
        0.02 * (0.05 * t_s).sin(),
        0.015 * (0.031 * t_s + 1.0).cos(),
        0.01 + 0.01 * (0.02 * t_s).sin(),
    )
}

fn common(noise: bool, seed: u64) -> Common {
    let mut c = Common::physical();
    c.seed = seed;
    if !noise {
        c.gyro_noise_deg_s_rthz = 0.0;
        c.disturbance_nm_rthz = 0.0;
        c.realism.attitude = AttitudeSource::Truth;
    }
    c
}

/// The paper's slew, its controller unchanged, with an unknown `torque` acting.
fn slew_under(torque: &dyn InputLaw, noise: bool, seed: u64) -> SimOutput {
    let c = common(noise, seed);
    let scenario = Scenario::slew();
    let Scenario::Slew(plan) = &scenario else {
        unreachable!()
    };
    let cfg = scenario.config(&c);
    let control = SlewController::new(
        plan.nominal_inertia_kg_m2,
        cfg.initial.q,
        plan.slews.clone(),
        plan.natural_freq_rad_s,
        plan.damping,
    )
    .expect("controller");
    simulate(&cfg, &control, torque).expect("sim")
}

/// The slew scenario with the dipole's torque `m × B` and the force's torque about the
/// centre of mass `F × c` acting (the torque about the origin, reported, is zero); the
/// samples carry the field and the force as measured (exactly).
fn slew_with(dipole: bool, force: bool, noise: bool, seed: u64) -> SimOutput {
    let (m, b_i, com) = (
        Vector3::from(DIPOLE_AM2),
        Vector3::from(FIELD_T),
        Vector3::from(CENTRE_M),
    );
    let torque = move |t_s: f64, x: &inertia::dynamics::GyrostatState| {
        let b = x.q.conjugate().rotate(&b_i);
        let mut tau = Vector3::zeros();
        if dipole {
            tau += m.cross(&b);
        }
        if force {
            tau += force_n(t_s).cross(&com);
        }
        tau
    };
    let mut out = slew_under(&torque, noise, seed);
    for (s, truth) in out.samples.iter_mut().zip(&out.truth) {
        // The reported torque about the origin is zero; the sim wrote the acting one.
        s.tau_nm = Vector3::zeros();
        if dipole {
            s.external.field_t = Some(truth.state.q.conjugate().rotate(&b_i));
        }
        if force {
            s.external.force_n = Some(force_n(s.t_s));
        }
    }
    out
}

fn run(samples: &[Sample], outside: OutsideTorques) -> Pipeline {
    let mut p = Pipeline::new(&PipelineSettings {
        outside,
        solve_every: 100,
        ..PipelineSettings::default()
    })
    .expect("pipeline");
    for s in samples {
        p.push(s).expect("push");
    }
    p
}

fn error(p: &Pipeline, truth: &Matrix3<f64>) -> f64 {
    let e = p.last().expect("an estimate");
    relative_frobenius_error(&e.inertia().unwrap_or_else(|| panic!("J: {e:?}")), truth)
}

fn outside(p: &Pipeline) -> OutsideEstimates {
    p.diagnostics().outside.expect("outside torques reported")
}

fn none() -> OutsideTorques {
    OutsideTorques {
        gravity_gradient: false,
        residual_dipole: false,
        centre_of_mass: false,
        ..OutsideTorques::default()
    }
}

/// With the positions the gravity-gradient rows are exact on ideal data, and the batch
/// run agrees; with the gyro's noise, left out (positions not used) J is biased by far
/// more than modelled.
#[test]
fn the_gravity_gradient_from_the_positions_is_exact_and_left_out_biases_j() {
    let orbit = |mut c: Common| {
        c.realism.environment.orbit = Some(Orbit::circular(500e3));
        c
    };
    let c = orbit(common(false, 1));
    let out = Scenario::slew().simulate(&c).expect("sim");
    assert!(out.samples.iter().all(|s| s.external.position_m.is_some()));
    let modelled = run(&out.samples, OutsideTorques::default());
    let e = error(&modelled, &c.inertia_kg_m2);
    assert!(e < 1e-8, "modelled: {e:.3e}");
    assert!(outside(&modelled).gravity_gradient);
    let config = PipelineSettings::default().validate().expect("valid");
    let batch = inertia::pipeline::batch(&out.samples, &config).expect("batch");
    let jb = batch.estimate.inertia().expect("J");
    assert!(relative_frobenius_error(&jb, &c.inertia_kg_m2) < 1e-8);
    for seed in 1..=3 {
        let c = orbit(common(true, seed));
        let out = Scenario::slew().simulate(&c).expect("sim");
        let e_in = error(
            &run(&out.samples, OutsideTorques::default()),
            &c.inertia_kg_m2,
        );
        let left_out = run(&out.samples, none());
        assert!(left_out.diagnostics().outside.is_none());
        let e_out = error(&left_out, &c.inertia_kg_m2);
        assert!(
            e_out > 5.0 * e_in,
            "seed {seed}: left out {e_out:.3e}, modelled {e_in:.3e}"
        );
    }
}

/// The residual dipole and the centre of mass are recovered to rounding on ideal data,
/// and J with them; left out, J is biased.
#[test]
fn the_dipole_and_the_centre_of_mass_are_exact_on_ideal_data() {
    let out = slew_with(true, true, false, 1);
    let truth = common(false, 1).inertia_kg_m2;
    let p = run(&out.samples, OutsideTorques::default());
    let e = error(&p, &truth);
    assert!(e < 1e-8, "J: {e:.3e}");
    let o = outside(&p);
    let m = o.residual_dipole_am2.expect("dipole");
    let c = o.centre_of_mass_m.expect("centre of mass");
    for i in 0..3 {
        assert!((m.value[i] - DIPOLE_AM2[i]).abs() < 1e-6, "{m:?}");
        assert!((c.value[i] - CENTRE_M[i]).abs() < 1e-7, "{c:?}");
    }
    let without = run(&out.samples, none());
    let e_out = error(&without, &truth);
    assert!(e_out > 100.0 * e, "left out {e_out:.3e} vs {e:.3e}");
}

/// With the gyro's noise, over seeds: the centre of mass within 1 mm and both within 3σ.
#[test]
fn with_noise_the_centre_of_mass_is_within_a_millimetre_and_both_within_three_sigma() {
    for seed in 1..=3 {
        let out = slew_with(true, true, true, seed);
        let p = run(&out.samples, OutsideTorques::default());
        let o = outside(&p);
        let (m, c) = (o.residual_dipole_am2.unwrap(), o.centre_of_mass_m.unwrap());
        let (sm, sc) = (m.sigma_all().expect("σ"), c.sigma_all().expect("σ"));
        for i in 0..3 {
            let dc = (c.value[i] - CENTRE_M[i]).abs();
            assert!(dc < 1e-3, "seed {seed}: c {c:?}");
            assert!(dc <= 3.0 * sc[i], "seed {seed}: c {c:?}");
            let dm = (m.value[i] - DIPOLE_AM2[i]).abs();
            assert!(dm <= 3.0 * sm[i], "seed {seed}: m {m:?}");
        }
    }
}

/// A spacecraft file's thrusters with throttle columns: the run computes the torque about
/// the origin and the force, and gives the same answer as the force and torque given
/// directly; the centre of mass within 1 mm and 3σ. Throttles for a file without
/// thrusters, or a force given twice, are refused.
#[test]
fn the_spacecraft_files_thrusters_give_the_force_and_the_centre_of_mass() {
    use inertia::pipeline::{Run, RunErrorKind};
    use inertia::sim::Thrusters;
    use inertia::spacecraft::Spacecraft;
    let centre = Vector3::new(0.012, -0.01, 0.013);
    let thrusters = Thrusters {
        centre_of_mass_m: centre,
        ..Thrusters::cube_pairs(0.02, 0.3)
    };
    let mut c = Common::paper();
    c.realism.environment.thrusters = Some(thrusters);
    let out = Scenario::slew().simulate(&c).expect("sim");
    // The file: the simulator's thrusters, each with its throttle column.
    let mut toml = String::new();
    for (i, t) in thrusters.iter().enumerate() {
        let v = |x: Vector3<f64>| format!("[{:e}, {:e}, {:e}]", x.x, x.y, x.z);
        toml += &format!(
            "[[thruster]]\nname = \"t{i}\"\nposition_m = {}\ndirection = {}\nthrust_n = {:e}\ncolumn = \"t{i}\"\n",
            v(t.position_m),
            v(t.direction),
            t.thrust_n
        );
    }
    let sc = Spacecraft::parse(&toml, "sc.toml").expect("spacecraft");
    let config = PipelineSettings::default().validate().expect("valid");
    let mut run = Run::new(config, false)
        .expect("run")
        .with_spacecraft(sc.clone());
    let mut direct = Run::new(config, false).expect("run");
    for s in &out.samples {
        let throttles: Vec<f64> = thrusters
            .thrusts_n(s.t_s)
            .zip(thrusters.iter())
            .map(|(f, t)| f / t.thrust_n)
            .collect();
        // The telemetry without the thrusters' torque and force: the file gives them.
        let (f, tau) = inertia::spacecraft::thrusters::force_and_torque(&sc.thrusters, &throttles);
        let bare = Sample {
            tau_nm: s.tau_nm - tau,
            external: Default::default(),
            ..*s
        };
        run.push_with_actuators(&bare, &[], &throttles, |_| {})
            .expect("push");
        let given = Sample {
            tau_nm: bare.tau_nm + tau,
            external: inertia::sample::External {
                force_n: Some(f),
                ..Default::default()
            },
            ..*s
        };
        direct.push(&given, |_| {}).expect("push");
    }
    run.finish(|_| {}).expect("finish");
    direct.finish(|_| {}).expect("finish");
    let (a, b) = (
        run.last().unwrap().j().unwrap(),
        direct.last().unwrap().j().unwrap(),
    );
    for k in 0..6 {
        assert!(
            (a[k] - b[k]).abs() <= 1e-12 * a[k].abs().max(1.0),
            "{a:?} vs {b:?}"
        );
    }
    let o = run
        .pipeline()
        .expect("streaming")
        .diagnostics()
        .outside
        .expect("outside");
    let com = o.centre_of_mass_m.expect("centre of mass");
    let sigma = com.sigma_all().expect("σ");
    for i in 0..3 {
        let d = (com.value[i] - centre[i]).abs();
        assert!(d < 1e-3 && d <= 3.0 * sigma[i], "{com:?}");
    }
    // Refusals: throttles the file does not have; the force given twice.
    let mut r = Run::new(config, false).expect("run").with_spacecraft(sc);
    let e = r
        .push_with_actuators(&out.samples[0], &[], &[1.0], |_| {})
        .unwrap_err();
    assert!(
        matches!(
            e.kind,
            RunErrorKind::Throttles {
                expected: 6,
                got: 1,
                ..
            }
        ),
        "{e}"
    );
    let mut forced = out.samples[0];
    forced.external.force_n = Some(Vector3::zeros());
    let e = r
        .push_with_actuators(&forced, &[], &[0.0; 6], |_| {})
        .unwrap_err();
    assert!(matches!(e.kind, RunErrorKind::ForceTwice), "{e}");
}

/// A force that keeps its direction in the body (one thruster) gives no torque for the
/// centre of mass along it: that direction is reported as not determined, and the
/// components across it are still within 3σ. With forces in every direction nothing is.
#[test]
fn a_centre_of_mass_along_a_fixed_force_is_reported_as_not_determined() {
    let com = Vector3::from(CENTRE_M);
    let along_z = |t_s: f64| Vector3::new(0.0, 0.0, 0.02 * (1.0 + (0.05 * t_s).sin()));
    let torque = move |t_s: f64, _: &inertia::dynamics::GyrostatState| along_z(t_s).cross(&com);
    let mut out = slew_under(&torque, true, 1);
    for s in &mut out.samples {
        s.tau_nm = Vector3::zeros();
        s.external.force_n = Some(along_z(s.t_s));
    }
    let p = run(&out.samples, OutsideTorques::default());
    let e = outside(&p).centre_of_mass_m.expect("centre of mass");
    let d = Vector3::from(
        e.undetermined_direction
            .expect("a direction not determined"),
    );
    assert!(d.z.abs() > 0.999, "{e:?}");
    for ((value, truth), sigma) in e.value.iter().zip(CENTRE_M).zip(e.sigma).take(2) {
        let sigma = sigma.expect("σ across the force");
        assert!((value - truth).abs() <= 3.0 * sigma, "{e:?}");
    }
    let full = slew_with(false, true, true, 1);
    let o = outside(&run(&full.samples, OutsideTorques::default()));
    assert_eq!(o.centre_of_mass_m.expect("c").undetermined_direction, None);
}

/// The batch run (an independent path: dense QR per chain and once over the shared
/// unknowns) reports the dipole and the centre of mass too, within the streaming run's
/// σ of its values and within 3σ of the truth.
#[test]
fn the_batch_run_reports_the_dipole_and_the_centre_of_mass_as_the_streaming_run() {
    let out = slew_with(true, true, true, 2);
    let streaming = outside(&run(&out.samples, OutsideTorques::default()));
    let config = PipelineSettings::default().validate().expect("valid");
    let batch = inertia::pipeline::batch(&out.samples, &config).expect("batch");
    let b = batch
        .diagnostics
        .outside
        .expect("outside torques in the batch report");
    for (s, b, truth) in [
        (
            streaming.residual_dipole_am2,
            b.residual_dipole_am2,
            DIPOLE_AM2,
        ),
        (streaming.centre_of_mass_m, b.centre_of_mass_m, CENTRE_M),
    ] {
        let (s, b) = (s.expect("streaming"), b.expect("batch"));
        let (ss, bs) = (s.sigma_all().expect("σ"), b.sigma_all().expect("σ"));
        for i in 0..3 {
            assert!((s.value[i] - b.value[i]).abs() <= ss[i], "{s:?} vs {b:?}");
            assert!((b.value[i] - truth[i]).abs() <= 3.0 * bs[i], "{b:?}");
        }
    }
}
