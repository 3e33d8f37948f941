//! The simulator against conservation laws and a closed-form solution (paper eq. 26).

use approx::assert_relative_eq;
use inertia::attitude::Quaternion;
use inertia::dynamics::GyrostatState;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{simulate, SimConfig, Zero};
use inertia::tensor::paper_j_true;
use nalgebra::{Matrix3, Vector3};

fn torque_free(
    j: Matrix3<f64>,
    initial: GyrostatState,
    duration_s: f64,
) -> inertia::sim::SimOutput {
    let cfg = SimConfig {
        inertia_kg_m2: j,
        initial,
        t0_s: 0.0,
        dt_s: 0.1,
        samples: SimConfig::samples_for(duration_s, 0.1),
        substeps: 20,
        disturbance_nm_rthz: 0.0,
        gyro_noise_deg_s_rthz: 0.0,
        seed: 0,
        inertia_change: None,
        realism: Default::default(),
    };
    simulate(&cfg, &Zero, &Zero).unwrap()
}

/// Torque-free motion with constant rotor momentum conserves kinetic energy ½ωᵀJω and
/// inertial angular momentum C(q)(Jω + ρ); relative drift below 1e-9 over 100 s.
#[test]
fn torque_free_motion_conserves_energy_and_momentum() {
    let j = paper_j_true();
    let x0 = GyrostatState {
        q: Quaternion::exp(&Vector3::new(0.4, -0.1, 0.2)),
        omega_rad_s: Vector3::new(0.3, 0.5, -0.4),
        rho_nms: Vector3::new(0.05, -0.1, 0.2),
    };
    let out = torque_free(j, x0, 100.0);
    let e0 = x0.rotational_energy(&j);
    let h0 = x0.inertial_momentum(&j);
    let mut max_e = 0.0f64;
    let mut max_h = 0.0f64;
    for s in &out.truth {
        max_e = max_e.max((s.state.rotational_energy(&j) - e0).abs() / e0);
        max_h = max_h.max((s.state.inertial_momentum(&j) - h0).norm() / h0.norm());
    }
    assert!(max_e < 1e-9, "energy drift {max_e:e}");
    assert!(max_h < 1e-9, "momentum drift {max_h:e}");
    // Rotor momentum is constant without wheel torque; motion actually happened.
    assert_eq!(out.truth.last().unwrap().state.rho_nms, x0.rho_nms);
    assert!(out.truth.last().unwrap().state.q.angle() > 0.5);
}

/// Axisymmetric body, J = diag(I, I, I3), torque-free: ω3 is constant and the transverse
/// rate rotates at λ = (I3 − I) ω3 / I: ω1 + i ω2 = (ω1(0) + i ω2(0)) e^{iλt}.
#[test]
fn axisymmetric_body_matches_closed_form_nutation() {
    let (i, i3) = (2.0, 3.0);
    let j = Matrix3::from_diagonal(&Vector3::new(i, i, i3));
    let w0 = Vector3::new(0.05, -0.02, 0.5);
    let x0 = GyrostatState {
        q: Quaternion::IDENTITY,
        omega_rad_s: w0,
        rho_nms: Vector3::zeros(),
    };
    let out = torque_free(j, x0, 60.0);
    let lambda = (i3 - i) * w0.z / i;
    let mut max_err = 0.0f64;
    for s in &out.truth {
        let (c, sn) = ((lambda * s.t_s).cos(), (lambda * s.t_s).sin());
        let expect = Vector3::new(w0.x * c - w0.y * sn, w0.x * sn + w0.y * c, w0.z);
        max_err = max_err.max((s.state.omega_rad_s - expect).norm());
    }
    assert!(max_err < 1e-10, "max rate error {max_err:e} rad/s");
    // The inertial momentum direction stays fixed (it is the nutation cone's axis).
    let h0 = x0.inertial_momentum(&j);
    let hend = out.truth.last().unwrap().state.inertial_momentum(&j);
    assert_relative_eq!(h0, hend, epsilon = 1e-10);
}

#[test]
fn scenarios_are_deterministic_for_a_seed() {
    for sc in [Scenario::slew(), Scenario::spin()] {
        let common = Common {
            duration_s: Some(40.0),
            ..Common::paper()
        };
        let a = sc.simulate(&common).unwrap();
        let b = sc.simulate(&common).unwrap();
        assert_eq!(a, b, "{}", sc.name());
        let c = sc.simulate(&Common { seed: 2, ..common }).unwrap();
        assert_ne!(a.samples, c.samples, "{}: seed must matter", sc.name());
        assert_eq!(a.samples.len(), 401);
    }
}

/// Noise levels behave as specified: the measured increments differ from the true ones by
/// the angle random walk σ√h per axis, and the reported rate by σ/√h.
#[test]
fn gyro_noise_has_the_specified_level() {
    let sigma_deg = 1e-2; // deg/s/√Hz, large so the statistics are clean
    let common = Common {
        gyro_noise_deg_s_rthz: sigma_deg,
        disturbance_nm_rthz: 0.0,
        duration_s: Some(300.0),
        ..Common::paper()
    };
    let out = Scenario::slew().simulate(&common).unwrap();
    let h = common.dt_s;
    let mut sum2 = 0.0;
    let mut n = 0.0;
    for (w, t) in out.samples.windows(2).zip(out.truth.windows(2)) {
        let meas = w[0].q.conjugate().mul(&w[1].q);
        let truth = t[0].state.q.conjugate().mul(&t[1].state.q);
        let err = truth.conjugate().mul(&meas).log();
        sum2 += err.norm_squared();
        n += 3.0;
    }
    let got = (sum2 / n).sqrt();
    let expect = sigma_deg.to_radians() * h.sqrt();
    assert!(
        (got / expect - 1.0).abs() < 0.05,
        "noise {got:e} vs {expect:e}"
    );
}

/// The slew scenario keeps wheel momentum in the range the paper's figure 1 shows and
/// returns to rest between slews; the spin scenario's pulse adds the stated Δρ.
#[test]
fn scenario_shapes() {
    let out = Scenario::slew().simulate(&Common::noise_free()).unwrap();
    let max_rho = out
        .samples
        .iter()
        .map(|s| s.rho_nms.norm())
        .fold(0.0, f64::max);
    assert!((0.1..0.5).contains(&max_rho), "max |rho| = {max_rho}");
    let last = out.truth.last().unwrap().state.omega_rad_s.norm();
    assert!(last < 2e-3, "not at rest at the end: {last}");

    let out = Scenario::spin().simulate(&Common::noise_free()).unwrap();
    let before = out.samples[290].rho_nms;
    let after = out.samples.last().unwrap().rho_nms;
    assert_eq!(before, Vector3::zeros());
    assert_relative_eq!(after, Vector3::new(0.05, 0.0, 0.0), epsilon = 1e-12);
    let w = out.samples[0].omega_rad_s.expect("simulated rates");
    assert!((w.z - 0.5).abs() < 0.01 && w.xy().norm() > 0.01);
}
