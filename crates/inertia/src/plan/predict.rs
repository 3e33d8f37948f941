//! The predicted σ of the estimate over a planned flight: the information matrix of the
//! discrete momentum rows along the nominal trajectory, under a stated noise model.
//!
//! # Rows
//!
//! The default estimator's rows ([`crate::estimator::momentum_rows`]) state that the
//! inertial angular momentum changes only by torque impulses:
//! `C_k (J ω_k + ρ_k) − X_c − S_k τ_b = 0`, with `X_c` the initial momentum of the chain
//! `c` the node belongs to (a new unknown every `chain_s` seconds) and `S_k = h Σ_{m≤k} C_m`
//! the column of the constant body-frame torque `τ_b`. Rotated to body axes and written
//! in `j` (`J ω = Ω(ω) j`, `Ω(ω) = [[ωx,0,0,ωy,ωz,0],[0,ωy,0,ωx,0,ωz],[0,0,ωz,0,ωx,ωy]]`):
//!
//! ```text
//! Ω(ω_k) j − C_kᵀ X_c − C_kᵀ S_k τ_b = −ρ_k + e_k
//! ```
//!
//! # Noise model
//!
//! `e_k` white between nodes with body-axis covariance
//! `R = J Jᵀ σ_g²/h + (σ_ρ²/2) I`: a gyro of rate-noise density `σ_g` (rad/s/√Hz) makes
//! the rotation over a step of length `h` err by `σ_g √h`, hence the rate by `σ_g/√h` and
//! the momentum by `J σ_g/√h`; wheel-momentum telemetry noise `σ_ρ` per sample, halved
//! by the trapezoid mean of two nodes. The attitude's own error multiplies the total body
//! momentum `Jω + ρ`, which is zero on a plan (every plan starts at rest,
//! [`super::limits`]), so it is left out.
//!
//! # Information and σ
//!
//! With `θ = [j; τ_b]`, `H_θ = [Ω(ω_k), −C_kᵀ S_k]`, `H_X = −C_kᵀ` and `W = R⁻¹`, each
//! chain contributes its Schur complement
//! `Σ H_θᵀ W H_θ − (Σ H_θᵀ W H_X)(Σ H_Xᵀ W H_X)⁻¹(Σ H_Xᵀ W H_θ)` (its `X_c` minimised
//! out), the chain in progress included; the prior adds `diag(1/σ_prior²)` on `j`. The
//! predicted σ of `j` is `√diag(M⁻¹)` of the `j` block, widened by the rotors' relative
//! scale σ `r` as the estimator's consider term does: `√(σ² + (r j)²)`.
//!
//! # What it omits
//!
//! The estimator's discretisation-bias term, its jackknife floor on the noise σ and its
//! choice among chain lengths (it may take longer chains, whose σ is smaller), the
//! gyro bias and the attitude's random walk, unknown disturbance torques beyond a
//! constant `τ_b`, and the error of the prior J itself (the trajectory is the prior's).
//! The book chapter measures how far the prediction is from the estimator's σ and from
//! the spread of its errors over seeds.

use crate::attitude::Quaternion;
use crate::plan::profile::CommandProfile;
use crate::tensor::{j_from_matrix, InertiaVector};
use nalgebra::{Matrix3, Matrix3x6, SMatrix, Vector3};
use std::vec::Vec;

/// The sensor noise the prediction assumes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseModel {
    /// Gyro rate-noise density, rad/s/√Hz.
    pub gyro_rad_s_rthz: f64,
    /// Wheel-momentum telemetry noise per sample (1σ per axis, quantisation LSB/√12
    /// included), N m s.
    pub wheel_nms: f64,
    /// Telemetry period h, s.
    pub telemetry_period_s: f64,
}

/// What the estimator will do with the rows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorModel {
    /// A new initial momentum every this many seconds (`None`: one for the whole
    /// flight). Default the estimator's short chain, 30 s.
    pub chain_s: Option<f64>,
    /// The constant body torque `τ_b` is an unknown (the estimator's default).
    pub torque_bias: bool,
    /// The rotors' relative momentum-scale σ (consider term), 0 for exact wheels.
    pub rotor_relative_sigma: f64,
    /// The prior's σ per element, kg m² (`None`: no prior information).
    pub prior_sigma_kg_m2: Option<[f64; 6]>,
}

impl Default for EstimatorModel {
    fn default() -> Self {
        Self {
            chain_s: Some(crate::pipeline::DEFAULT_MAX_CHAIN_S),
            torque_bias: true,
            rotor_relative_sigma: 0.0,
            prior_sigma_kg_m2: None,
        }
    }
}

/// σ per element over time.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// Times, s.
    pub t_s: Vec<f64>,
    /// σ per element (order of eq. 48), kg m², at each time (∞ where J is not yet
    /// determined).
    pub sigma_kg_m2: Vec<[f64; 6]>,
    /// The relative Frobenius σ `√(Σ_i w_i σ_i²)/‖J‖_F` (`w` = 1 on the diagonal, 2 off
    /// it) at each time.
    pub relative_sigma: Vec<f64>,
}

impl Prediction {
    /// The first time at which `3 σ_F ≤ target` (relative), if any.
    #[must_use]
    pub fn time_to(&self, target: f64) -> Option<f64> {
        self.t_s
            .iter()
            .zip(&self.relative_sigma)
            .find(|(_, s)| 3.0 * **s <= target)
            .map(|(t, _)| *t)
    }

    /// σ at the last time.
    #[must_use]
    pub fn last(&self) -> Option<[f64; 6]> {
        self.sigma_kg_m2.last().copied()
    }
}

/// `Ω(ω)` with `J ω = Ω(ω) j`.
#[must_use]
pub(crate) fn omega_matrix(w: &Vector3<f64>) -> Matrix3x6<f64> {
    Matrix3x6::new(
        w.x, 0.0, 0.0, w.y, w.z, 0.0, //
        0.0, w.y, 0.0, w.x, 0.0, w.z, //
        0.0, 0.0, w.z, 0.0, w.x, w.y,
    )
}

/// Relative Frobenius σ of per-element σ for inertia `j`.
#[must_use]
pub(crate) fn relative_sigma(sigma: &[f64; 6], j: &Matrix3<f64>) -> f64 {
    let s2: f64 = (0..6)
        .map(|i| if i < 3 { 1.0 } else { 2.0 } * sigma[i] * sigma[i])
        .sum();
    s2.sqrt() / j.norm()
}

/// The information of `θ = [j; τ_b]` accumulated along a trajectory (module docs).
#[derive(Debug, Clone)]
pub(crate) struct Information {
    closed: SMatrix<f64, 9, 9>,
    ajj: SMatrix<f64, 9, 9>,
    ajx: SMatrix<f64, 9, 3>,
    axx: Matrix3<f64>,
    w: Matrix3<f64>,
    torque_bias: bool,
}

impl Information {
    pub(crate) fn new(j: &Matrix3<f64>, noise: &NoiseModel, torque_bias: bool) -> Self {
        let h = noise.telemetry_period_s;
        let r = j * j.transpose() * (noise.gyro_rad_s_rthz.powi(2) / h)
            + Matrix3::identity() * (0.5 * noise.wheel_nms.powi(2));
        let w = r.try_inverse().unwrap_or_else(Matrix3::zeros);
        Self {
            closed: SMatrix::zeros(),
            ajj: SMatrix::zeros(),
            ajx: SMatrix::zeros(),
            axx: Matrix3::zeros(),
            w,
            torque_bias,
        }
    }

    /// One node's rows: body rate `omega`, attitude matrix `c` (body → inertial) and the
    /// torque column's running sum `s` (inertial).
    pub(crate) fn push(&mut self, omega: &Vector3<f64>, c: &Matrix3<f64>, s: &Matrix3<f64>) {
        let mut ht = SMatrix::<f64, 3, 9>::zeros();
        ht.fixed_view_mut::<3, 6>(0, 0)
            .copy_from(&omega_matrix(omega));
        if self.torque_bias {
            ht.fixed_view_mut::<3, 3>(0, 6)
                .copy_from(&(-c.transpose() * s));
        }
        let hx = -c.transpose();
        let wt = self.w * ht;
        self.ajj += ht.transpose() * wt;
        self.ajx += wt.transpose() * hx;
        self.axx += hx.transpose() * self.w * hx;
    }

    /// The chain in progress, its initial momentum minimised out.
    fn open(&self) -> SMatrix<f64, 9, 9> {
        match self.axx.try_inverse() {
            Some(inv) if self.axx.trace() > 0.0 => self.ajj - self.ajx * inv * self.ajx.transpose(),
            _ => SMatrix::zeros(),
        }
    }

    /// End the chain: the next node starts a new initial momentum.
    pub(crate) fn close_chain(&mut self) {
        self.closed += self.open();
        self.ajj = SMatrix::zeros();
        self.ajx = SMatrix::zeros();
        self.axx = Matrix3::zeros();
    }

    /// The information of `j` alone, `τ_b` minimised out (6 × 6).
    pub(crate) fn of_j(&self) -> SMatrix<f64, 6, 6> {
        let m = self.closed + self.open();
        let a = m.fixed_view::<6, 6>(0, 0).into_owned();
        if !self.torque_bias {
            return a;
        }
        let b = m.fixed_view::<6, 3>(0, 6).into_owned();
        let c = m.fixed_view::<3, 3>(6, 6).into_owned();
        // τ_b is determined once the attitude has turned; before, minimise it out with a
        // vanishing regulariser (it then takes its information from nothing).
        let reg = Matrix3::identity() * (1e-12 * (c.trace() + 1e-300));
        match (c + reg).try_inverse() {
            Some(inv) => a - b * inv * b.transpose(),
            None => a,
        }
    }
}

/// σ per element from the information of `j`, the prior and the consider term.
fn sigma_from(m: &SMatrix<f64, 6, 6>, model: &EstimatorModel, j: &InertiaVector) -> [f64; 6] {
    let mut m = *m;
    if let Some(p) = model.prior_sigma_kg_m2 {
        for i in 0..6 {
            m[(i, i)] += 1.0 / (p[i] * p[i]);
        }
    }
    // σ_i² = Σ_λ v_i²/λ over the determined directions; an element with a share of an
    // undetermined direction (λ ≤ 1e-12 λ_max) is undetermined (∞).
    let e = m.symmetric_eigen();
    let tol = 1e-12 * e.eigenvalues.amax();
    let r = model.rotor_relative_sigma;
    core::array::from_fn(|i| {
        let mut var = 0.0;
        for (k, l) in e.eigenvalues.iter().enumerate() {
            let v2 = e.eigenvectors[(i, k)].powi(2);
            if *l > tol {
                var += v2 / l;
            } else if v2 > 1e-9 {
                return f64::INFINITY;
            }
        }
        if tol > 0.0 {
            (var + (r * j[i]).powi(2)).sqrt()
        } else {
            f64::INFINITY
        }
    })
}

/// The nominal flight of `profile` from rest for `duration_s` with inertia `j`: at each
/// telemetry node its time, body rate `ω = −J⁻¹ρ` and attitude (module docs of
/// [`super::limits`]).
#[must_use]
pub(crate) fn nominal(
    profile: &CommandProfile,
    j: &Matrix3<f64>,
    period_s: f64,
    duration_s: f64,
) -> Vec<(f64, Vector3<f64>, Quaternion)> {
    let j_inv = j.try_inverse().unwrap_or_else(Matrix3::zeros);
    let n = (duration_s / period_s).round() as usize;
    // ρ at any time: the hold integrated exactly.
    let ticks = profile.momentum_at_ticks();
    let rho_at = |t: f64| -> Vector3<f64> {
        let x = (t - profile.t0_s) / profile.period_s;
        if x <= 0.0 {
            return Vector3::zeros();
        }
        let k = (x.floor() as usize).min(ticks.len() - 1);
        let frac = (x - k as f64).max(0.0);
        ticks[k]
            + profile.at(profile.t0_s + (k as f64 + 0.5) * profile.period_s)
                * (frac * profile.period_s)
    };
    let mut q = Quaternion::IDENTITY;
    let mut out = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let t = profile.t0_s + k as f64 * period_s;
        let w = -(j_inv * rho_at(t));
        out.push((t, w, q));
        // Midpoint rotation over the step (the rate is piecewise linear in time).
        let wm = -(j_inv * rho_at(t + 0.5 * period_s));
        q = q.mul(&Quaternion::exp(&(wm * period_s)));
    }
    out
}

/// The information of `j` (6 × 6) from flying `profile` for `duration_s`.
#[must_use]
pub(crate) fn information(
    profile: &CommandProfile,
    j: &Matrix3<f64>,
    noise: &NoiseModel,
    model: &EstimatorModel,
    duration_s: f64,
) -> SMatrix<f64, 6, 6> {
    let (info, _) = run(profile, j, noise, model, duration_s, None);
    info.of_j()
}

/// The predicted σ every `every_s` seconds over `duration_s` of flying `profile`.
#[must_use]
pub(crate) fn predict(
    profile: &CommandProfile,
    j: &Matrix3<f64>,
    noise: &NoiseModel,
    model: &EstimatorModel,
    duration_s: f64,
    every_s: f64,
) -> Prediction {
    run(profile, j, noise, model, duration_s, Some(every_s)).1
}

fn run(
    profile: &CommandProfile,
    j: &Matrix3<f64>,
    noise: &NoiseModel,
    model: &EstimatorModel,
    duration_s: f64,
    every_s: Option<f64>,
) -> (Information, Prediction) {
    let h = noise.telemetry_period_s;
    let jv = j_from_matrix(j);
    let mut info = Information::new(j, noise, model.torque_bias);
    let mut s = Matrix3::zeros();
    let mut out = Prediction {
        t_s: Vec::new(),
        sigma_kg_m2: Vec::new(),
        relative_sigma: Vec::new(),
    };
    let chain_nodes = model.chain_s.map(|c| ((c / h).round() as usize).max(2));
    let every_nodes = every_s.map(|e| ((e / h).round() as usize).max(1));
    for (k, (t, w, q)) in nominal(profile, j, h, duration_s).iter().enumerate() {
        if let Some(n) = chain_nodes {
            if k > 0 && k % n == 0 {
                info.close_chain();
            }
        }
        let c = q.to_matrix();
        if k > 0 {
            s += c * h;
        }
        info.push(w, &c, &s);
        if let Some(e) = every_nodes {
            if k > 0 && k % e == 0 {
                let sigma = sigma_from(&info.of_j(), model, &jv);
                out.t_s.push(*t - profile.t0_s);
                out.relative_sigma.push(relative_sigma(&sigma, j));
                out.sigma_kg_m2.push(sigma);
            }
        }
    }
    (info, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rotation at constant rate about x from a step of momentum: Ω(ω) = ωx on J11, J12,
    /// J13 only; the other three elements stay undetermined (σ = ∞), and σ of J11 falls as
    /// 1/√T once the chain holds more than the step.
    #[test]
    fn one_axis_determines_one_column_only() {
        let j = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0));
        let mut cmds = std::vec![Vector3::zeros(); 200];
        for (k, c) in cmds.iter_mut().enumerate() {
            // A square wave of momentum on x: rate changes sign every 10 s.
            *c = Vector3::new(if (k / 10) % 2 == 0 { 1e-3 } else { -1e-3 }, 0.0, 0.0);
        }
        let p = CommandProfile::new(0.0, 1.0, cmds);
        let noise = NoiseModel {
            gyro_rad_s_rthz: 1e-5,
            wheel_nms: 0.0,
            telemetry_period_s: 0.1,
        };
        let model = EstimatorModel {
            chain_s: None,
            torque_bias: false,
            ..EstimatorModel::default()
        };
        let pr = predict(&p, &j, &noise, &model, 200.0, 10.0);
        let last = pr.last().unwrap();
        assert!(last[0].is_finite() && last[3].is_finite() && last[4].is_finite());
        assert!(pr.relative_sigma.last().unwrap().is_infinite());
        let i100 = pr
            .t_s
            .iter()
            .position(|t| (*t - 100.0).abs() < 1e-9)
            .unwrap();
        let ratio = pr.sigma_kg_m2[i100][0] / last[0];
        assert!((ratio - 2f64.sqrt()).abs() < 0.1, "{ratio}");
    }
}
