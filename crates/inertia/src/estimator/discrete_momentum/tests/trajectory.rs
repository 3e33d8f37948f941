//! Exact (finely integrated, noise-free) gyrostat trajectories with smooth inputs, shared by
//! the convergence tests of the paper's rows and of the discrete momentum rows.
#![allow(dead_code)]

use crate::attitude::Quaternion;
use crate::dynamics::GyrostatState;
use crate::sample::Sample;
use crate::sim::{simulate, InputLaw, SimConfig};
use crate::tensor::paper_j_true;
use nalgebra::Vector3;

/// A smooth wheel-momentum rate, N m.
pub(crate) fn rho_dot(t: f64, _x: &GyrostatState) -> Vector3<f64> {
    Vector3::new(
        0.05 * (0.7 * t).sin(),
        0.03 * (1.1 * t).cos(),
        -0.04 * (0.5 * t + 1.0).sin(),
    )
}

/// A smooth known external torque, N m.
pub(crate) fn torque(t: f64, _x: &GyrostatState) -> Vector3<f64> {
    Vector3::new(
        0.02 * (0.9 * t).cos(),
        -0.015 * (1.3 * t).sin(),
        0.01 * (0.4 * t).sin() + 0.005,
    )
}

/// A noise-free run of `duration_s` from a tumbling initial state, sample period `dt`.
pub(crate) fn config(dt: f64, substeps: usize, duration_s: f64) -> SimConfig {
    SimConfig {
        inertia_kg_m2: paper_j_true(),
        initial: GyrostatState {
            q: Quaternion::exp(&Vector3::new(0.3, -0.2, 0.5)),
            omega_rad_s: Vector3::new(0.6, -0.4, 0.8),
            rho_nms: Vector3::new(0.1, -0.2, 0.3),
        },
        t0_s: 0.0,
        dt_s: dt,
        samples: SimConfig::samples_for(duration_s, dt),
        substeps,
        disturbance_nm_rthz: 0.0,
        gyro_noise_deg_s_rthz: 0.0,
        seed: 0,
        inertia_change: None,
        realism: Default::default(),
    }
}

/// Telemetry of that run, integrated with 64 RK4 substeps per sample.
pub(crate) fn exact_samples(
    h: f64,
    duration_s: f64,
    rho: &dyn InputLaw,
    tau: &dyn InputLaw,
) -> Vec<Sample> {
    simulate(&config(h, 64, duration_s), rho, tau)
        .expect("valid config")
        .samples
}
