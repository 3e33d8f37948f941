//! Thrusters and the centre of mass.
//!
//! # Conventions (read these)
//!
//! * **Origin.** Thruster positions `r_i` are in body axes, m, from the body frame's
//!   **origin**: the point the telemetry's known torque `tau_nm` is taken about. The true
//!   **centre of mass** `c` ([`Thrusters::centre_of_mass_m`], body axes, m, from the same
//!   origin) is where the body's rotation is about; the dynamics need the torque about it.
//! * **Force** of thruster i: `F_i(t) = f_i(t) d̂_i` (N, body axes), `d̂_i` its unit
//!   direction ([`Thruster::direction`], normalised on use), `f_i(t)` its thrust.
//! * **Torque on the body** (about the centre of mass, what the dynamics integrate):
//!   `Σ (r_i − c) × F_i = Σ r_i × F_i − c × F`, `F = Σ F_i`.
//! * **Telemetry.** `tau_nm` gets the **known** part `Σ r_i × F_i` (about the origin, as a
//!   user computes it from the thruster layout assuming `c = 0`), and
//!   `external.force_n = F + n` with optional white force-sensor noise `n ~ N(0, σ² I)`
//!   (σ = [`Thrusters::force_noise_n`], N per axis and sample; noise stream 6 of the
//!   run's seed). The rest, `−c × F`, is the **unknown** torque from which the
//!   estimator can learn `c`: `τ_true = τ_reported − c × F` at every node, exactly (with
//!   the noise-free force).
//!
//! # Firing law ([`Firing`])
//!
//! The `n` thrusters fire **one at a time, in turn**: the `k`-th window (k = 0, 1, …)
//! opens at `t_k = start_s + k · period_s` and belongs to thruster `k mod n`, which
//! fires for `burn_s ≤ period_s` with the thrust
//!
//! ```text
//! f(t) = F_max sin⁴(π (t − t_k)/burn_s) = F_max [½ (1 − cos(2π (t − t_k)/burn_s))]²
//! ```
//!
//! and zero outside its windows and before `start_s`. The pulse is smooth: it and its
//! first three derivatives vanish at the window's ends, so RK4 steps across an edge and
//! node-sampled telemetry integrate it accurately. Its impulse is `⅜ F_max burn_s`.
//!
//! [`Thrusters::cube_pairs`] is a layout for tests: three pairs whose torques about the
//! origin are ±a F_max about each body axis in turn, the pair's forces alike, so the
//! wheels give back over the pair's second burn what they took over its first, while
//! the force (along +z, +x, +y in turn) does not vanish and changes direction.

use super::SimError;
use crate::sample::range;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// The most thrusters of one [`Thrusters`] (a fixed array, so that the settings stay
/// `Copy`).
pub const MAX_THRUSTERS: usize = 12;

/// The noise stream of the force sensor.
const STREAM: u64 = 6;

/// One thruster.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Thruster {
    /// Position of its point of application, m, body axes, from the origin (finite).
    pub position_m: Vector3<f64>,
    /// Direction of its force, body axes (normalised on use; finite, non-zero).
    pub direction: Vector3<f64>,
    /// Largest thrust `F_max`, N (finite, in 0..=`range::FORCE_N`).
    pub thrust_n: f64,
}

/// When the thrusters fire (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Firing {
    /// Opening of the first window, s (finite).
    pub start_s: f64,
    /// Time between window openings, s (finite, > 0).
    pub period_s: f64,
    /// Length of each burn, s (finite, in (0, period_s]).
    pub burn_s: f64,
}

impl Default for Firing {
    /// A 4 s burn every 10 s from 5 s: with six thrusters each fires once a minute.
    fn default() -> Self {
        Self {
            start_s: 5.0,
            period_s: 10.0,
            burn_s: 4.0,
        }
    }
}

impl Firing {
    /// The window open at `t_s`, as (window number k, time since it opened), if a burn
    /// is under way.
    #[must_use]
    fn window(&self, t_s: f64) -> Option<(u64, f64)> {
        let since = t_s - self.start_s;
        if !(since >= 0.0) {
            return None;
        }
        let k = (since / self.period_s).floor();
        let into = since - k * self.period_s;
        (into < self.burn_s && k < u64::MAX as f64).then_some((k as u64, into))
    }
}

/// Thrusters, their firing law and the centre of mass (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Thrusters {
    /// The thrusters, in firing order (`None` slots are skipped).
    pub units: [Option<Thruster>; MAX_THRUSTERS],
    /// The firing law.
    pub firing: Firing,
    /// The true centre of mass `c`, m, body axes, from the origin (finite).
    pub centre_of_mass_m: Vector3<f64>,
    /// 1σ white noise of the telemetered force per axis and sample, N (finite, ≥ 0;
    /// default 0).
    pub force_noise_n: f64,
}

impl Thrusters {
    /// These thrusters (at most [`MAX_THRUSTERS`]) with the default [`Firing`], the
    /// centre of mass at the origin and a noise-free force.
    #[cfg(test)]
    fn new(units: &[Thruster]) -> Result<Self, SimError> {
        if units.len() > MAX_THRUSTERS {
            return Err(SimError::InvalidSetting {
                field: "environment.thrusters.units",
                value: units.len() as f64,
                why: "at most 12 thrusters",
            });
        }
        let mut slots = [None; MAX_THRUSTERS];
        for (slot, u) in slots.iter_mut().zip(units) {
            *slot = Some(*u);
        }
        Ok(Self {
            units: slots,
            firing: Firing::default(),
            centre_of_mass_m: Vector3::zeros(),
            force_noise_n: 0.0,
        })
    }

    /// Six thrusters of thrust `thrust_n` (N) at `arm_m` (m) from the origin, firing in
    /// the order: at `(0, ±a, 0)` along +z (torque ±a F about x), at `(0, 0, ±a)` along +x
    /// (±a F about y), at `(±a, 0, 0)` along +y (±a F about z). Default firing, centre of
    /// mass at the origin, noise-free force.
    #[must_use]
    pub fn cube_pairs(thrust_n: f64, arm_m: f64) -> Self {
        let unit = |p: Vector3<f64>, d: Vector3<f64>| Thruster {
            position_m: p * arm_m,
            direction: d,
            thrust_n,
        };
        let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
        let mut units = [None; MAX_THRUSTERS];
        for (slot, u) in units.iter_mut().zip([
            unit(y, z),
            unit(-y, z),
            unit(z, x),
            unit(-z, x),
            unit(x, y),
            unit(-x, y),
        ]) {
            *slot = Some(u);
        }
        Self {
            units,
            firing: Firing::default(),
            centre_of_mass_m: Vector3::zeros(),
            force_noise_n: 0.0,
        }
    }

    /// The thrusters, in firing order.
    pub fn iter(&self) -> impl Iterator<Item = &Thruster> {
        self.units.iter().flatten()
    }

    /// Each thruster's thrust at `t_s`, N (firing order; module docs).
    pub fn thrusts_n(&self, t_s: f64) -> impl Iterator<Item = f64> + '_ {
        let n = self.iter().count() as u64;
        let burn = self.firing.window(t_s).filter(|_| n > 0);
        self.iter().enumerate().map(move |(i, u)| match burn {
            Some((k, into)) if k % n == i as u64 => {
                let s = (core::f64::consts::PI * into / self.firing.burn_s).sin();
                let s2 = s * s;
                u.thrust_n * s2 * s2
            }
            _ => 0.0,
        })
    }

    /// The total force `F = Σ F_i` and its torque about the origin `Σ r_i × F_i` at
    /// `t_s`: (N, N m), body axes.
    #[must_use]
    pub(crate) fn force_and_torque(&self, t_s: f64) -> (Vector3<f64>, Vector3<f64>) {
        let mut force = Vector3::zeros();
        let mut torque = Vector3::zeros();
        for (u, f) in self.iter().zip(self.thrusts_n(t_s)) {
            if f != 0.0 {
                let fi = u.direction.try_normalize(0.0).unwrap_or_default() * f;
                force += fi;
                torque += u.position_m.cross(&fi);
            }
        }
        (force, torque)
    }

    /// The total force at `t_s`, N, body axes.
    #[must_use]
    pub(crate) fn force_n(&self, t_s: f64) -> Vector3<f64> {
        self.force_and_torque(t_s).0
    }

    /// The torque on the body about the centre of mass at `t_s`,
    /// `Σ r_i × F_i − c × F`, N m, body axes.
    #[must_use]
    pub fn torque_about_com_nm(&self, t_s: f64) -> Vector3<f64> {
        let (force, torque) = self.force_and_torque(t_s);
        torque - self.centre_of_mass_m.cross(&force)
    }

    /// Check every field.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        let bad = |field, value, why| Err(SimError::InvalidSetting { field, value, why });
        for u in self.iter() {
            if !u.position_m.iter().all(|v| v.is_finite()) {
                return bad(
                    "environment.thrusters.units.position_m",
                    u.position_m.norm(),
                    "must be finite",
                );
            }
            let d = u.direction.norm();
            if !(d.is_finite() && d > 0.0) {
                return bad(
                    "environment.thrusters.units.direction",
                    d,
                    "must be finite and non-zero",
                );
            }
            if !(u.thrust_n.is_finite() && (0.0..=range::FORCE_N).contains(&u.thrust_n)) {
                return bad(
                    "environment.thrusters.units.thrust_n",
                    u.thrust_n,
                    "must be finite, >= 0 and at most 1e6 N",
                );
            }
        }
        let f = &self.firing;
        if !f.start_s.is_finite() {
            return bad(
                "environment.thrusters.firing.start_s",
                f.start_s,
                "must be finite",
            );
        }
        if !(f.period_s.is_finite() && f.period_s > 0.0) {
            return bad(
                "environment.thrusters.firing.period_s",
                f.period_s,
                "must be finite and > 0",
            );
        }
        if !(f.burn_s.is_finite() && f.burn_s > 0.0 && f.burn_s <= f.period_s) {
            return bad(
                "environment.thrusters.firing.burn_s",
                f.burn_s,
                "must be finite, > 0 and at most the period",
            );
        }
        if !self.centre_of_mass_m.iter().all(|v| v.is_finite()) {
            return bad(
                "environment.thrusters.centre_of_mass_m",
                self.centre_of_mass_m.norm(),
                "must be finite",
            );
        }
        let s = self.force_noise_n;
        if !(s.is_finite() && (0.0..=range::FORCE_N).contains(&s)) {
            return bad(
                "environment.thrusters.force_noise_n",
                s,
                "must be finite, >= 0 and at most 1e6 N",
            );
        }
        Ok(())
    }
}

/// The force sensor's noise stream (stream 6).
pub(crate) struct ForceSensor {
    rng: ChaCha8Rng,
    noise: Normal<f64>,
}

impl ForceSensor {
    pub(crate) fn new(sigma_n: f64, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(STREAM);
        Self {
            rng,
            noise: super::sensors::normal(sigma_n),
        }
    }

    /// The telemetered force for the true force `f_n`.
    pub(crate) fn measure(&mut self, f_n: &Vector3<f64>) -> Vector3<f64> {
        f_n + Vector3::from_fn(|_, _| self.noise.sample(&mut self.rng))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One thruster at a time, in turn; the pulse's peak at mid-burn, zero outside.
    #[test]
    fn firing_in_turn() {
        let th = Thrusters::cube_pairs(0.1, 0.5);
        // Window 1 (from 15 s) belongs to thruster 1; mid-burn at 17 s.
        let f: Vec<f64> = th.thrusts_n(17.0).collect();
        assert!((f[1] - 0.1).abs() < 1e-15 && f.iter().filter(|v| **v != 0.0).count() == 1);
        assert!(th.thrusts_n(4.9).all(|v| v == 0.0));
        assert!(th.thrusts_n(19.5).all(|v| v == 0.0), "between burns");
        // Window 6 (from 65 s) is thruster 0 again: torque +a F about x at 67 s.
        let (force, torque) = th.force_and_torque(67.0);
        assert!((force - Vector3::z() * 0.1).norm() < 1e-15);
        assert!((torque - Vector3::x() * 0.05).norm() < 1e-15);
        // Each pair's torques cancel, so do their impulses.
        let (_, t1) = th.force_and_torque(27.0);
        let (_, t2) = th.force_and_torque(37.0);
        assert!((t1 + t2).norm() < 1e-15 && t1.norm() > 0.0);
    }

    #[test]
    fn too_many_thrusters() {
        let u = Thruster {
            position_m: Vector3::x(),
            direction: Vector3::y(),
            thrust_n: 1.0,
        };
        assert!(Thrusters::new(&[u; 12]).is_ok());
        assert!(matches!(
            Thrusters::new(&[u; 13]),
            Err(SimError::InvalidSetting {
                field: "environment.thrusters.units",
                ..
            })
        ));
    }
}
