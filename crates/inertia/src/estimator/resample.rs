//! Resampling irregular telemetry onto a uniform grid (4-point Lagrange interpolation).
//!
//! The variable-step variational row is O(h³) on a jittered grid (see
//! [`crate::discrete`]); rows built on a uniform grid are O(h⁴). Interpolating the
//! telemetry with a cubic through the four nearest nodes is itself O(h⁴), so resampled
//! rows keep the O(h⁴) residual (`tests/integration/discrete_convergence.rs`). Attitude is
//! interpolated in the tangent space: rotation vectors `log(q_ref† q_i)` relative to the
//! second of the four nodes, then `q = q_ref exp(r(t))`; rotor momentum, torque and gyro
//! rate component by component. Output time `t` is produced once the input brackets it
//! with two nodes on each side; gaps (a step longer than
//! `crate::sample::GAP_RATIO` times the previous) restart the grid after the gap.
//! Streaming, fixed size, no allocation.

use super::InvalidArgument;
use crate::attitude::Quaternion;
use crate::sample::{is_gap, Sample};
use nalgebra::Vector3;

/// Streaming resampler to period `h`.
#[derive(Debug, Clone, Copy)]
pub struct Resampler {
    h_s: f64,
    nodes: [Option<Sample>; 4],
    next_t: Option<f64>,
}

pub(crate) fn lagrange_weights(t: &[f64; 4], x: f64) -> [f64; 4] {
    core::array::from_fn(|i| {
        let mut w = 1.0;
        for (k, tk) in t.iter().enumerate() {
            if k != i {
                w *= (x - tk) / (t[i] - tk);
            }
        }
        w
    })
}

impl Resampler {
    /// Resample to period `h_s`, starting at the first input time. `h_s` must be finite
    /// and positive.
    pub fn new(h_s: f64) -> Result<Self, InvalidArgument> {
        if !(h_s.is_finite() && h_s > 0.0) {
            return Err(InvalidArgument {
                name: "h_s",
                value: h_s,
                expected: "a finite period > 0 s",
            });
        }
        Ok(Self {
            h_s,
            nodes: [None; 4],
            next_t: None,
        })
    }

    /// Feed an input sample (times increasing); `out` receives each output sample that
    /// became available, in time order.
    pub fn push(&mut self, s: &Sample, mut out: impl FnMut(Sample)) {
        if let (Some(a), Some(b)) = (self.nodes[2], self.nodes[3]) {
            if is_gap(b.t_s - a.t_s, s.t_s - b.t_s) {
                // A gap: flush nothing across it, restart the grid at this sample.
                self.nodes = [None; 4];
                self.next_t = None;
            }
        }
        self.nodes.rotate_left(1);
        self.nodes[3] = Some(*s);
        if self.next_t.is_none() {
            // The grid starts at the first node after a (re)start.
            self.next_t = self.nodes.iter().flatten().next().map(|n| n.t_s);
        }
        let [Some(n0), Some(n1), Some(n2), Some(n3)] = self.nodes else {
            // Before four nodes exist: the first interval is interpolated with the first
            // four nodes once they arrive (handled below when n0 is the first node).
            return;
        };
        let t = [n0.t_s, n1.t_s, n2.t_s, n3.t_s];
        while let Some(x) = self.next_t {
            // Serve [t0, t2) from the first window, then the middle interval [t1, t2).
            if x >= t[2] {
                break;
            }
            out(interpolate(&[n0, n1, n2, n3], &t, x));
            let next = x + self.h_s;
            // A period below the resolution of t (x + h = x) cannot advance the grid:
            // move on to the next interval rather than loop.
            self.next_t = Some(if next > x { next } else { t[2] });
        }
    }
}

fn interpolate(n: &[Sample; 4], t: &[f64; 4], x: f64) -> Sample {
    let w = lagrange_weights(t, x);
    let q_ref = n[1].q;
    let mut r = Vector3::zeros();
    let mut rho = Vector3::zeros();
    let mut tau = Vector3::zeros();
    let mut omega = Some(Vector3::zeros());
    let mut position = Some(Vector3::zeros());
    let mut field = Some(Vector3::zeros());
    let mut force = Some(Vector3::zeros());
    for i in 0..4 {
        let e = &n[i].external;
        position = position.zip(e.position_m).map(|(o, v)| o + v * w[i]);
        field = field.zip(e.field_t).map(|(o, v)| o + v * w[i]);
        force = force.zip(e.force_n).map(|(o, v)| o + v * w[i]);
        r += q_ref.conjugate().mul(&n[i].q).log() * w[i];
        rho += n[i].rho_nms * w[i];
        tau += n[i].tau_nm * w[i];
        omega = omega.zip(n[i].omega_rad_s).map(|(o, w_i)| o + w_i * w[i]);
    }
    Sample {
        t_s: x,
        q: q_ref.mul(&Quaternion::exp(&r)),
        rho_nms: rho,
        tau_nm: tau,
        omega_rad_s: omega,
        external: crate::sample::External {
            position_m: position,
            field_t: field,
            force_n: force,
        },
    }
}
