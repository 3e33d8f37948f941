//! `inertia.simulate`: the command line's `simulate` options as keyword arguments
//! (`--gyro-arw-deg-rthr` is `gyro_arw_deg_rthr=`, `X:Y:Z` options take three numbers),
//! mapped onto the library's `sim` settings as `crates/inertia-cli/src/simulate.rs`
//! maps them.

use crate::errors::{value_error, Failure};
use crate::kwargs::Kwargs;
use crate::samples::{Checker, Naming, Row};
use crate::settings::Convention;
use crate::Telemetry;
use inertia::sim::gyro::arw_deg_rthr_to_deg_s_rthz;
use inertia::sim::presets::Preset;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{
    AttitudeSource, CommandHold, Environment, InertiaChange, Magnetic, Magnetorquer, Orbit,
    SimConfig, Thrusters, MAX_SAMPLES,
};
use inertia::telemetry::gate::RawExternal;
use inertia::text::Num;
use nalgebra::Vector3;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Most integrator steps of one run (as the command line).
const MAX_INTEGRATION_STEPS: f64 = MAX_SAMPLES as f64 * 20.0;

fn settings(kw: &Kwargs<'_>) -> PyResult<(Scenario, Common, &'static str)> {
    let scenario = kw.choice("scenario", &["slew", "spin"])?;
    let preset = kw.choice("preset", &["small-sat", "microsat"])?;
    let paper_inertia = kw.bool("paper_inertia", false)?;
    if paper_inertia && preset.is_some() {
        return Err(value_error(
            "paper_inertia: only for scenario (a preset has its own inertia)",
        ));
    }
    let (sc, mut common, name) = match (preset, scenario) {
        (Some(_), Some(_)) => return Err(value_error("scenario and preset: give one")),
        (Some(p), None) => {
            let p = if p == "microsat" { Preset::microsat() } else { Preset::small_sat() };
            (p.scenario, p.common, p.name)
        }
        (None, Some(s)) => {
            let sc = if s == "spin" { Scenario::spin() } else { Scenario::slew() };
            let name = sc.name();
            // As `inertia simulate`: the physical truth unless the paper's J is asked for.
            let common = if paper_inertia {
                Common::paper()
            } else {
                Common::physical()
            };
            (sc, common, name)
        }
        (None, None) => return Err(value_error("scenario or preset: one is required (scenario=\"slew\", \"spin\"; preset=\"small-sat\", \"microsat\")")),
    };
    let duration = kw.f64("duration")?;
    if let Some(d) = duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(value_error(format!(
                "duration={}: must be finite and > 0",
                Num(d)
            )));
        }
    }
    let dt = kw.f64("dt")?.unwrap_or(0.1);
    if !(dt.is_finite() && dt > 0.0) {
        return Err(value_error(format!(
            "dt={}: must be finite and > 0",
            Num(dt)
        )));
    }
    let j0 = common.inertia_kg_m2;
    let step = kw.numbers::<2>("inertia_step")?;
    let ramp = kw.numbers::<3>("inertia_ramp")?;
    common.inertia_change = match (step, ramp) {
        (Some(_), Some(_)) => return Err(value_error("inertia_step and inertia_ramp: give one")),
        (Some([at, scale]), None) => Some(InertiaChange::Step {
            at_s: at,
            to_kg_m2: j0 * scale,
        }),
        (None, Some([t0, t1, scale])) => {
            if !(t1 > t0) {
                return Err(value_error("inertia_ramp: T1 must be after T0"));
            }
            Some(InertiaChange::Ramp {
                start_s: t0,
                end_s: t1,
                to_kg_m2: j0 * scale,
            })
        }
        (None, None) => None,
    };
    common.dt_s = dt;
    common.duration_s = duration;
    common.substeps = ((dt / 0.005).round() as usize).max(1);
    common.seed = kw
        .take("seed")?
        .map(|v| v.extract::<u64>())
        .transpose()
        .map_err(|_| crate::errors::type_error("seed: expected an integer >= 0"))?
        .unwrap_or(1);
    if let Some(d) = kw.finite("disturbance")? {
        common.disturbance_nm_rthz = d;
    }
    let gyro_noise = kw.finite("gyro_noise")?;
    let arw = kw.finite("gyro_arw_deg_rthr")?;
    match (gyro_noise, arw) {
        (Some(_), Some(_)) => {
            return Err(value_error(
                "gyro_noise and gyro_arw_deg_rthr: give one (ARW = 60 × density)",
            ))
        }
        (Some(g), None) => common.gyro_noise_deg_s_rthz = g,
        (None, Some(a)) => common.gyro_noise_deg_s_rthz = arw_deg_rthr_to_deg_s_rthz(a),
        (None, None) => {}
    }
    let r = &mut common.realism;
    if let Some(t) = kw.f64("telemetry_dt")? {
        let n = t / dt;
        let every = n.round();
        if !(t.is_finite() && every >= 1.0 && (n - every).abs() <= 1e-9 * every) {
            return Err(value_error(format!(
                "telemetry_dt={t}: must be a whole multiple (>= 1) of dt={dt}"
            )));
        }
        r.telemetry_every = every as usize;
    }
    let period = dt * r.telemetry_every as f64;
    let duration = duration.unwrap_or_else(|| sc.default_duration_s());
    let samples = SimConfig::samples_for(duration, period);
    if samples > MAX_SAMPLES {
        return Err(value_error(format!(
            "duration={}: more than {MAX_SAMPLES} samples at the telemetry period {} s (a run is held in memory); at most {} s",
            Num(duration),
            Num(period),
            Num((MAX_SAMPLES - 1) as f64 * period)
        )));
    }
    let steps = samples as f64 * r.telemetry_every as f64 * common.substeps as f64;
    if steps > MAX_INTEGRATION_STEPS {
        return Err(value_error(format!(
            "dt={} with a duration of {} s: {} integration steps; at most {}",
            Num(dt),
            Num(duration),
            Num(steps),
            Num(MAX_INTEGRATION_STEPS)
        )));
    }
    if let Some(b) = kw.vector("gyro_bias_deg_h")? {
        r.gyro.bias_deg_h = Vector3::from(b);
    }
    if let Some(b) = kw.finite("gyro_bias_instability_deg_h")? {
        r.gyro.bias_instability_deg_h = b;
    }
    if let Some(t) = kw.finite("gyro_bias_correlation_s")? {
        r.gyro.bias_correlation_s = t;
    }
    if let Some(s) = kw.choice("attitude", &["truth", "gyro", "star-tracker", "mekf"])? {
        r.attitude = match s {
            "truth" => AttitudeSource::Truth,
            "gyro" => AttitudeSource::GyroPropagated,
            "star-tracker" => AttitudeSource::StarTracker,
            _ => AttitudeSource::Mekf,
        };
    }
    if let Some(v) = kw.vector("star_tracker_arcsec")? {
        r.star_tracker.noise_arcsec = Vector3::from(v);
    }
    if let Some(v) = kw.vector("star_tracker_boresight")? {
        r.star_tracker.boresight_body = Vector3::from(v);
    }
    if let Some(hz) = kw.finite("star_tracker_hz")? {
        r.star_tracker.rate_hz = Some(hz);
    }
    if kw.bool("mekf_raw_rates", false)? {
        r.mekf.bias_corrected_rates = false;
    }
    let phase = kw.finite("command_phase")?.unwrap_or(0.0);
    if let Some(hz) = kw.finite("controller_hz")? {
        r.commands = Some(CommandHold {
            rate_hz: hz,
            phase_s: phase,
        });
    } else if phase != 0.0 {
        match r.commands.as_mut() {
            Some(c) => c.phase_s = phase,
            None => return Err(value_error("command_phase: needs controller_hz")),
        }
    }
    if let Some(q) = kw.finite("wheel_quantization_nms")? {
        r.wheels.quantization_nms = q;
    }
    if let Some(n) = kw.finite("wheel_noise_nms")? {
        r.wheels.noise_nms = n;
    }
    if let Some(s) = kw.finite("wheel_skew_s")? {
        r.wheels.skew_s = s;
    }
    if let Some(v) = kw.vector("wheel_scale_error")? {
        r.wheels.scale_error = Vector3::from(v);
    }
    if let Some(v) = kw.vector("wheel_misalignment_deg")? {
        r.wheels.misalignment_deg = Vector3::from(v);
    }
    let inclination = kw.finite("orbit_inclination_deg")?.unwrap_or(0.0);
    if let Some(km) = kw.finite("gravity_gradient_altitude_km")? {
        r.environment.orbit = Some(Orbit {
            inclination_deg: inclination,
            ..Orbit::circular(km * 1e3)
        });
    }
    if let Some(v) = kw.vector("constant_torque_nm")? {
        r.environment.constant_torque_nm = Vector3::from(v);
    }
    magnetic_and_thrusters(kw, &mut r.environment)?;
    Ok((sc, common, name))
}

/// The magnetic options and the thrusters' (after the orbit's), as the command line's.
fn magnetic_and_thrusters(kw: &Kwargs<'_>, env: &mut Environment) -> PyResult<()> {
    let field = kw.vector("magnetic_field_t")?;
    let residual = kw.vector("residual_dipole_am2")?;
    let magnetorquer = kw.finite("magnetorquer_am2")?;
    let noise = kw.finite("magnetometer_noise_t")?;
    let bias = kw.vector("magnetometer_bias_t")?;
    if field.is_some()
        || residual.is_some()
        || magnetorquer.is_some()
        || noise.is_some()
        || bias.is_some()
    {
        let mut m = match field {
            Some(b) => Magnetic::constant(Vector3::from(b)),
            None if env.orbit.is_some() => Magnetic::dipole(),
            None => {
                return Err(value_error(
                    "the magnetic options need a field: gravity_gradient_altitude_km (Earth's dipole field on that orbit) or magnetic_field_t",
                ))
            }
        };
        m.residual_dipole_am2 = residual.map(Vector3::from).unwrap_or_default();
        m.magnetorquer = magnetorquer.map(Magnetorquer::sine);
        if let Some(s) = noise {
            m.magnetometer.noise_t = s;
        }
        if let Some(b) = bias {
            m.magnetometer.bias_t = Vector3::from(b);
        }
        env.magnetic = Some(m);
    }
    let thrust = kw.finite("thrusters")?;
    let arm = kw.finite("thruster_arm_m")?;
    let centre = kw.vector("centre_of_mass_m")?;
    let force_noise = kw.finite("force_noise_n")?;
    match thrust {
        Some(thrust) => {
            let mut t = Thrusters::cube_pairs(thrust, arm.unwrap_or(0.3));
            if let Some(c) = centre {
                t.centre_of_mass_m = Vector3::from(c);
            }
            if let Some(s) = force_noise {
                t.force_noise_n = s;
            }
            env.thrusters = Some(t);
        }
        None => {
            if let Some(name) = [
                (arm.is_some(), "thruster_arm_m"),
                (centre.is_some(), "centre_of_mass_m"),
                (force_noise.is_some(), "force_noise_n"),
            ]
            .into_iter()
            .find_map(|(given, name)| given.then_some(name))
            {
                return Err(value_error(format!("{name}: needs thrusters")));
            }
        }
    }
    Ok(())
}

/// The keyword behind a simulator setting, so that its error names what the caller gave
/// (`None`: a setting no keyword sets on its own), as the command line names its options.
fn keyword_of(field: &str) -> Option<&'static str> {
    Some(match field {
        "dt_s" => "dt",
        "samples" => "duration (with dt)",
        "telemetry_every" => "telemetry_dt",
        "gyro_noise_deg_s_rthz" => "gyro_noise or gyro_arw_deg_rthr",
        "disturbance_nm_rthz" => "disturbance",
        "gyro.bias_deg_h" => "gyro_bias_deg_h",
        "gyro.bias_instability_deg_h" => "gyro_bias_instability_deg_h",
        "gyro.bias_correlation_s" => "gyro_bias_correlation_s",
        "star_tracker.noise_arcsec" => "star_tracker_arcsec",
        "star_tracker.boresight_body" => "star_tracker_boresight",
        "star_tracker.rate_hz" => "star_tracker_hz",
        "commands.rate_hz" => "controller_hz",
        "commands.phase_s" => "command_phase",
        "wheels.quantization_nms" => "wheel_quantization_nms",
        "wheels.noise_nms" => "wheel_noise_nms",
        "wheels.skew_s" => "wheel_skew_s",
        "wheels.scale_error" => "wheel_scale_error",
        "wheels.misalignment_deg" => "wheel_misalignment_deg",
        "environment.orbit.altitude_m" => "gravity_gradient_altitude_km",
        "environment.orbit.inclination_deg" => "orbit_inclination_deg",
        "environment.constant_torque_nm" => "constant_torque_nm",
        "environment.magnetic.field" => "magnetic_field_t",
        "environment.magnetic.residual_dipole_am2" => "residual_dipole_am2",
        "environment.magnetic.magnetorquer.amplitude_am2" => "magnetorquer_am2",
        "environment.magnetic.magnetometer.noise_t" => "magnetometer_noise_t",
        "environment.magnetic.magnetometer.bias_t" => "magnetometer_bias_t",
        "environment.thrusters.units.thrust_n" => "thrusters",
        "environment.thrusters.units.position_m" => "thruster_arm_m",
        "environment.thrusters.centre_of_mass_m" => "centre_of_mass_m",
        "environment.thrusters.force_noise_n" => "force_noise_n",
        _ => return None,
    })
}

/// A simulator error naming the keyword first, the setting (in the simulator's units)
/// beside it.
fn sim_error(e: inertia::sim::SimError) -> Failure {
    let inertia::sim::SimError::InvalidSetting { field, .. } = &e;
    Failure::Argument(match keyword_of(field) {
        Some(k) => format!("{k}: {e}"),
        None => e.to_string(),
    })
}

/// Simulate: `(telemetry, J at the end, J at the start, scenario name, orbit positions
/// (N, 3) m or None)`.
#[pyfunction]
#[pyo3(signature = (kwargs=None))]
pub fn simulate<'py>(
    py: Python<'py>,
    kwargs: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let kw = Kwargs::new(kwargs, py, "simulate")?;
    let (sc, common, name) = settings(&kw)?;
    kw.finish()?;
    let (tel, end, start, positions) = py
        .allow_threads(|| -> Result<_, Failure> {
            let out = sc.simulate(&common).map_err(sim_error)?;
            // The samples as the CSV reader would read them back from `inertia simulate`'s
            // file (the file holds each value exactly; the reader renormalises).
            let mut checker = Checker::new(&Convention::default());
            let samples = out
                .samples
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    let row = Row {
                        t: s.t_s,
                        q: s.q.to_xyzw(),
                        rho: s.rho_nms.into(),
                        tau: Some(s.tau_nm.into()),
                        w: s.omega_rad_s.map(Into::into),
                        // As the file's `r_*`, `b_*`, `f_*` columns (a magnetorquer's
                        // torque is in `tau` already).
                        external: RawExternal {
                            position_m: s.external.position_m.map(Into::into),
                            field_t: s.external.field_t.map(Into::into),
                            force_n: s.external.force_n.map(Into::into),
                            dipole_am2: None,
                        },
                    };
                    checker.sample(&row, i, &Naming::Arrays)
                })
                .collect::<Result<Vec<_>, _>>()?;
            let t_end = out.samples.last().map_or(0.0, |s| s.t_s);
            let positions: Option<Vec<[f64; 3]>> = out.orbit.map(|o| {
                out.samples
                    .iter()
                    .map(|s| o.position_m(s.t_s).into())
                    .collect()
            });
            Ok((
                Telemetry {
                    samples,
                    lines: None,
                    file: None,
                    stats: checker.stats(),
                    q_columns: "q".into(),
                    label: "<simulated>".into(),
                    rotors: None,
                },
                out.inertia_at(t_end),
                out.inertia_kg_m2,
                positions,
            ))
        })
        .map_err(|f| f.into_py(py))?;
    let end = crate::matrix3(py, &end)?;
    let start = crate::matrix3(py, &start)?;
    let positions = positions
        .map(|p| crate::matrix(py, p.into_iter()))
        .transpose()?;
    Ok((Py::new(py, tel)?, end, start, name, positions)
        .into_pyobject(py)?
        .into_any())
}
