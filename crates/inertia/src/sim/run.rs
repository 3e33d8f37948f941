//! The simulation loop: integration on the controller's grid, sensors, telemetry.
//!
//! Time grid: integration nodes `t_b = t0_s + b·dt_s`; telemetry nodes every
//! [`super::Realism::telemetry_every`]-th of them. Each integration interval is split at the
//! command ticks inside it ([`super::commands`]), and each piece into equal RK4 substeps
//! no longer than `dt_s/substeps`; without ticks inside, the interval has exactly
//! `substeps` substeps (the paper's simulator). The gyro, the gyro-propagated attitude and
//! the MEKF run once per integration interval; the star tracker, the wheel telemetry and
//! the known torque are sampled at the telemetry nodes (the MEKF's tracker at its rate).

use super::commands::Ticker;
use super::gyro::Gyro;
use super::magnetic::MagnetometerNoise;
use super::mekf::Mekf;
use super::sensors::{self, DEG};
use super::star_tracker::StarTrackerNoise;
use super::thrusters::ForceSensor;
use super::vibration::RotorAngle;
use super::wheels::{RhoHistory, RhoSpan, WheelSensor};
use super::{
    AttitudeSource, FilterSample, InertiaChange, InputLaw, SimConfig, SimError, SimOutput,
    TruthSample,
};
use crate::attitude::Quaternion;
use crate::dynamics::{rk4_step, GyrostatState};
use crate::sample::{External, Sample};
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::Distribution;
use std::collections::VecDeque;

/// Run the simulator. `rho_dot` is the wheel control law, `known_torque` the external
/// torque that is reported in telemetry.
pub fn simulate(
    cfg: &SimConfig,
    rho_dot: &dyn InputLaw,
    known_torque: &dyn InputLaw,
) -> Result<SimOutput, SimError> {
    cfg.validate()?;
    let re = &cfg.realism;
    let j = cfg.inertia_kg_m2;
    let j_inv = j
        .try_inverse()
        .unwrap_or_else(|| Matrix3::from_element(f64::NAN));
    let n_tel = cfg.samples;
    let every = re.telemetry_every;
    let n_base = n_tel.checked_mul(every).ok_or(SimError::InvalidSetting {
        field: "telemetry_every",
        value: every as f64,
        why: "samples * telemetry_every overflows",
    })?;
    let h = cfg.dt_s;
    let h_tel = h * every as f64;
    let sub = cfg.substeps;
    let dt = h / sub as f64;
    let eps = 1e-9 * h;

    let mut dist_rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    dist_rng.set_stream(0);
    let dist = sensors::normal(cfg.disturbance_nm_rthz / dt.sqrt());
    let mut gyro = Gyro::new(cfg.gyro_noise_deg_s_rthz, &re.gyro, h, cfg.seed);
    let mut tracker = StarTrackerNoise::new(&re.star_tracker, cfg.seed);
    let mut wheel_sensor = WheelSensor::new(&re.wheels, cfg.seed);
    let wheels_active = re.wheels.is_active();
    let skew = re.wheels.skew_s;
    let skewed = skew != 0.0;
    let env = re.environment;
    let env_on = env.is_active();
    let mut magnetometer = env
        .magnetic
        .map(|m| MagnetometerNoise::new(&m.magnetometer, cfg.seed));
    let mut force_sensor = env
        .thrusters
        .map(|t| ForceSensor::new(t.force_noise_n, cfg.seed));
    let vibration = re.vibration;
    let vibrating = vibration.is_active();
    let mut rotor = RotorAngle::default();
    let hold_every = re.wheels.hold_every(h_tel)?;

    let mut x = cfg.initial;
    x.q = x.q.normalize().unwrap_or(Quaternion::IDENTITY);
    let t0 = cfg.t0_s;
    let rho0 = x.rho_nms;
    let mut q_meas = x.q;
    let (mut mekf, tracker_every) = if re.attitude == AttitudeSource::Mekf {
        let f = Mekf::new(
            tracker.measure(&x.q),
            re.star_tracker.covariance_rad2(),
            cfg.gyro_noise_deg_s_rthz * DEG,
            re.gyro.rate_random_walk_rad_s_rts(),
            &re.mekf,
        );
        (Some(f), re.tracker_every(h)?)
    } else {
        (None, every)
    };
    let corrected_rates = re.mekf.bias_corrected_rates;
    let mut hold = re
        .commands
        .map(|c| (Ticker::new(c, t0, eps), rho_dot.eval(t0, &x)));
    let mut step_applied = false;

    let mut history = RhoHistory::default();
    let mut pending: VecDeque<(usize, f64)> = VecDeque::new();
    let mut rho_tel: Vec<Vector3<f64>> = Vec::with_capacity(if skewed { n_tel } else { 0 });
    let mut samples = Vec::with_capacity(n_tel);
    let mut truth = Vec::with_capacity(n_tel);
    let mut filter = Vec::new();
    // The telemetry sample being built: (sample, sum of delta angles over its step).
    let mut open: Option<(Sample, Option<Vector3<f64>>)> = None;
    let j0 = cfg.inertia_kg_m2;

    for b in 0..n_base {
        let t_b = t0 + b as f64 * h;
        let x_b = x;
        if let Some(f) = mekf.as_mut() {
            if b > 0 && b % tracker_every == 0 {
                f.update(&tracker.measure(&x_b.q));
            }
        }
        if b % every == 0 {
            let i = b / every;
            let q_tel = match re.attitude {
                AttitudeSource::Truth => x_b.q,
                AttitudeSource::GyroPropagated => q_meas,
                AttitudeSource::StarTracker => tracker.measure(&x_b.q),
                AttitudeSource::Mekf => mekf.as_ref().map_or(q_meas, Mekf::attitude),
            };
            let rho = if skewed {
                rho_tel.push(x_b.rho_nms);
                pending.push_back((i, t_b + skew));
                x_b.rho_nms
            } else if wheels_active {
                wheel_sensor.measure(&x_b.rho_nms)
            } else {
                x_b.rho_nms
            };
            let (tau_nm, external) = node_telemetry(
                &env,
                t_b,
                &x_b,
                known_torque.eval(t_b, &x_b),
                magnetometer.as_mut(),
                force_sensor.as_mut(),
            );
            open = Some((
                Sample {
                    t_s: t_b,
                    q: q_tel,
                    rho_nms: rho,
                    tau_nm,
                    omega_rad_s: None,
                    external,
                },
                None,
            ));
            truth.push(TruthSample {
                t_s: t_b,
                state: x_b,
                gyro_bias_rad_s: gyro.bias_rad_s(),
            });
            if let Some(f) = &mekf {
                let p = f.covariance();
                filter.push(FilterSample {
                    t_s: t_b,
                    bias_rad_s: f.bias_rad_s(),
                    attitude_sigma_rad: Vector3::new(p[(0, 0)], p[(1, 1)], p[(2, 2)])
                        .map(|v| v.max(0.0).sqrt()),
                    bias_sigma_rad_s: Vector3::new(p[(3, 3)], p[(4, 4)], p[(5, 5)])
                        .map(|v| v.max(0.0).sqrt()),
                });
            }
            if skewed {
                serve(
                    &mut pending,
                    t_b,
                    eps,
                    t0,
                    rho0,
                    &history,
                    &mut wheel_sensor,
                    &mut rho_tel,
                );
            }
        }

        // Integrate [t_b, t_b + h], split at the command ticks.
        let end = t_b + h;
        let mut seg_start = t_b;
        let mut angle = Vector3::zeros();
        let mut vib_angle = Vector3::zeros();
        let mut last_rd: Option<Vector3<f64>> = None;
        loop {
            if let Some((ticker, cmd)) = hold.as_mut() {
                if ticker.next_s <= seg_start + eps {
                    *cmd = rho_dot.eval(seg_start, &x);
                    while ticker.next_s <= seg_start + eps {
                        ticker.advance();
                    }
                    last_rd = None;
                }
            }
            let seg_end = match &hold {
                Some((ticker, _)) if ticker.next_s < end - eps => ticker.next_s,
                _ => end,
            };
            let whole = seg_start == t_b && seg_end == end;
            let (m, sdt) = if whole {
                (sub, dt)
            } else {
                let len = seg_end - seg_start;
                let m = ((len / dt) - 1e-9).ceil().max(1.0) as usize;
                (m, len / m as f64)
            };
            let seg_dist = if whole {
                dist
            } else {
                sensors::normal(cfg.disturbance_nm_rthz / sdt.sqrt())
            };
            for s in 0..m {
                let t = seg_start + s as f64 * sdt;
                let d = Vector3::from_fn(|_, _| seg_dist.sample(&mut dist_rng));
                let (jm, jm_inv, jdot) = match &cfg.inertia_change {
                    None => (j, j_inv, Matrix3::zeros()),
                    Some(c) => {
                        // A step inside this substep: apply it at the substep's start,
                        // conserving angular momentum Jω.
                        if let InertiaChange::Step { at_s, to_kg_m2 } = *c {
                            if !step_applied && at_s > t0 - 0.5 * dt && at_s <= t + 0.5 * sdt {
                                let inv = to_kg_m2.try_inverse().unwrap_or(j_inv);
                                x.omega_rad_s = inv * (c.inertia_at(&j0, t - sdt) * x.omega_rad_s);
                                step_applied = true;
                            }
                        }
                        let jm = c.inertia_at(&j0, t + 0.5 * sdt);
                        let inv = jm.try_inverse().unwrap_or(j_inv);
                        (jm, inv, c.rate_at(&j0, t + 0.5 * sdt))
                    }
                };
                let held = hold.as_ref().map(|(_, cmd)| *cmd);
                let f = |tt: f64, xx: &GyrostatState| {
                    let rd = match held {
                        Some(c) => c,
                        None => rho_dot.eval(tt, xx),
                    };
                    let tau = known_torque.eval(tt, xx) + d - jdot * xx.omega_rad_s;
                    if env_on {
                        (
                            rd,
                            tau + env.total_torque_nm(tt, &xx.q, &xx.omega_rad_s, &jm),
                        )
                    } else {
                        (rd, tau)
                    }
                };
                let x_start = x;
                let (next, da) = rk4_step(&jm, &jm_inv, t, sdt, &x, &f);
                x = next;
                angle += da;
                if vibrating {
                    vib_angle += rotor.substep(&vibration, &x_start.rho_nms, &x.rho_nms, sdt);
                }
                if skewed {
                    let (rd0, rd1) = match held {
                        Some(c) => (c, c),
                        None => {
                            let rd0 = last_rd.unwrap_or_else(|| rho_dot.eval(t, &x_start));
                            let rd1 = rho_dot.eval(t + sdt, &x);
                            last_rd = Some(rd1);
                            (rd0, rd1)
                        }
                    };
                    history.push(RhoSpan {
                        t0: t,
                        t1: t + sdt,
                        rho0: x_start.rho_nms,
                        rho1: x.rho_nms,
                        rd0,
                        rd1,
                    });
                }
            }
            if seg_end == end {
                break;
            }
            seg_start = seg_end;
        }

        // Sensors over the interval.
        let increment = x_b.q.conjugate().mul(&x.q);
        let (noisy_increment, measured) = if vibrating {
            // The vibration is a sensor error: it enters the measured delta angle.
            gyro.measure(
                &increment.mul(&Quaternion::exp(&vib_angle)),
                &(angle + vib_angle),
            )
        } else {
            gyro.measure(&increment, &angle)
        };
        q_meas = q_meas
            .mul(&noisy_increment)
            .normalize()
            .unwrap_or(Quaternion::IDENTITY);
        let reported = match mekf.as_mut() {
            Some(f) => {
                let corrected = f.propagate(&measured, h);
                if corrected_rates {
                    corrected
                } else {
                    measured
                }
            }
            None => measured,
        };
        if let Some((_, sum)) = open.as_mut() {
            *sum = Some(sum.map_or(reported, |s| s + reported));
        }
        if skewed {
            serve(
                &mut pending,
                end,
                eps,
                t0,
                rho0,
                &history,
                &mut wheel_sensor,
                &mut rho_tel,
            );
            history.prune_before(end - skew.abs() - 2.0 * h);
        }
        if (b + 1) % every == 0 {
            if let Some((mut sample, sum)) = open.take() {
                sample.omega_rad_s = sum.map(|s| s / h_tel);
                samples.push(sample);
            }
        }
    }
    if skewed {
        // Requests past the end (only by rounding): the latest ρ.
        serve(
            &mut pending,
            f64::INFINITY,
            eps,
            t0,
            rho0,
            &history,
            &mut wheel_sensor,
            &mut rho_tel,
        );
        for (s, r) in samples.iter_mut().zip(&rho_tel) {
            s.rho_nms = *r;
        }
    }
    if hold_every > 1 {
        // Zero-order hold of the wheel-speed telemetry (wheels module docs).
        for chunk in samples.chunks_mut(hold_every) {
            let held = chunk[0].rho_nms;
            for s in chunk.iter_mut() {
                s.rho_nms = held;
            }
        }
    }
    Ok(SimOutput {
        samples,
        truth,
        inertia_kg_m2: j,
        inertia_change: cfg.inertia_change,
        orbit: env.orbit,
        filter,
    })
}

/// The known torque and the outside measurements of the telemetry node at `t_s` in the
/// true state `x`, given the scenario's known torque `known_nm`: the magnetorquers'
/// torque with the measured field and the thrusters' torque about the origin are added
/// to it ([`super::magnetic`], [`super::thrusters`]).
fn node_telemetry(
    env: &super::Environment,
    t_s: f64,
    x: &GyrostatState,
    known_nm: Vector3<f64>,
    magnetometer: Option<&mut MagnetometerNoise>,
    force_sensor: Option<&mut ForceSensor>,
) -> (Vector3<f64>, External) {
    let mut tau = known_nm;
    let mut external = External {
        position_m: env.orbit.map(|o| o.position_m(t_s)),
        ..External::NONE
    };
    if let (Some(m), Some(sensor)) = (&env.magnetic, magnetometer) {
        let measured = sensor.measure(&m.field_body_t(env.orbit.as_ref(), t_s, &x.q));
        if let Some(torquer) = &m.magnetorquer {
            tau += torquer.dipole_am2(t_s).cross(&measured);
        }
        external.field_t = Some(measured);
    }
    if let (Some(th), Some(sensor)) = (&env.thrusters, force_sensor) {
        let (force, torque) = th.force_and_torque(t_s);
        tau += torque;
        external.force_n = Some(sensor.measure(&force));
    }
    (tau, external)
}

/// Fill the pending ρ requests with times up to `upto_s`.
#[allow(clippy::too_many_arguments)]
fn serve(
    pending: &mut VecDeque<(usize, f64)>,
    upto_s: f64,
    eps: f64,
    t0_s: f64,
    rho0: Vector3<f64>,
    history: &RhoHistory,
    sensor: &mut WheelSensor,
    out: &mut [Vector3<f64>],
) {
    while let Some(&(i, t_req)) = pending.front() {
        if t_req > upto_s + eps {
            break;
        }
        let rho = if t_req <= t0_s {
            rho0
        } else {
            history
                .at(t_req)
                .or_else(|| history.latest())
                .unwrap_or(rho0)
        };
        if let Some(slot) = out.get_mut(i) {
            *slot = sensor.measure(&rho);
        }
        pending.pop_front();
    }
}
