//! The momentum balance the simulator's torque tests check: the change of the body's
//! total inertial momentum against the inertial impulse of the torques.

use inertia::dynamics::GyrostatState;
use inertia::sim::SimOutput;
use nalgebra::Vector3;

/// ∫ C(q) τ dt over the truth nodes (Simpson; an even number of intervals).
pub fn inertial_impulse(
    out: &SimOutput,
    torque: impl Fn(f64, &GyrostatState) -> Vector3<f64>,
) -> Vector3<f64> {
    let n = out.truth.len() - 1;
    assert!(n.is_multiple_of(2));
    let h = out.truth[1].t_s - out.truth[0].t_s;
    let f = |k: usize| {
        let t = &out.truth[k];
        t.state.q.rotate(&torque(t.t_s, &t.state))
    };
    let mut s = f(0) + f(n);
    for k in 1..n {
        s += f(k) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * (h / 3.0)
}

pub fn inertial_momentum_change(out: &SimOutput) -> Vector3<f64> {
    let j = out.inertia_kg_m2;
    let last = out.truth.len() - 1;
    out.truth[last].state.inertial_momentum(&j) - out.truth[0].state.inertial_momentum(&j)
}
