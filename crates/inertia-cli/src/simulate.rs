//! `inertia simulate`.
//!
//! The paper's scenarios or a spacecraft preset, with the library's realism settings
//! (`inertia::sim::Realism`) from the command line. The outside measurements go to
//! extra columns (`inertia::telemetry::csv::ExternalColumns`), read back by the CSV
//! reader: with gravity gradient on `r_x,r_y,r_z`, the orbit position in the inertial
//! frame, m; with a magnetic field `b_x,b_y,b_z`, the magnetometer's reading, T, body
//! axes (a magnetorquer's torque with that field is in `tau_*`); with thrusters
//! `f_x,f_y,f_z`, their force, N, body axes (their torque about the origin is in
//! `tau_*`). With a spacecraft
//! file (`--spacecraft`), the rotors' speed columns replace `rho_*`
//! (`inertia::sim::rotors`). With `--commands PLAN.csv` (an `inertia plan` profile) the
//! spacecraft starts at rest and flies those wheel torque commands instead of the
//! scenario's manoeuvres, for the profile's length unless `--duration` is given.
//!
//! A run is held in memory (at most [`MAX_SAMPLES`] samples, about 0.25 kB each; at most
//! [`MAX_INTEGRATION_STEPS`] integrator steps) and the
//! files are put in place when it is complete ([`Pending`]). `-o -` writes the CSV to
//! standard output and no truth file.

use crate::args::{AttitudeArg, PresetArg, ScenarioArg, SimulateArgs};
use crate::config::InertiaFile;
use crate::error::{input, read_failed, write_failed, CliError};
use crate::output::{is_special, is_stdio, to_stdout, Pending};
use inertia::plan::CommandProfile;
use inertia::sim::gyro::arw_deg_rthr_to_deg_s_rthz;
use inertia::sim::presets::Preset;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{
    AttitudeSource, CommandHold, Environment, Magnetic, Magnetorquer, Orbit, SimConfig, SimOutput,
    Thrusters, MAX_SAMPLES,
};
use inertia::telemetry::csv::{write_samples_external, write_samples_with_speeds, ExternalColumns};
use inertia::text::Num;
use nalgebra::Vector3;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Most integrator steps of one run: [`MAX_SAMPLES`] samples at the default 0.1 s period
/// and 5 ms steps. Beyond it a run would take hours (`--dt 1e6` integrates each node in
/// 2·10⁸ steps).
const MAX_INTEGRATION_STEPS: f64 = MAX_SAMPLES as f64 * 20.0;

/// The truth file next to a telemetry file: `X.csv` → `X.truth.json`.
pub fn truth_path(csv: &Path) -> PathBuf {
    csv.with_extension("truth.json")
}

/// The scenario for an argument.
pub fn scenario(s: ScenarioArg) -> Scenario {
    match s {
        ScenarioArg::Slew => Scenario::slew(),
        ScenarioArg::Spin => Scenario::spin(),
    }
}

/// `n` finite numbers separated by ':'.
fn numbers(flag: &str, s: &str, n: usize) -> Result<Vec<f64>, CliError> {
    let v: Vec<f64> = s
        .split(':')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            input(format!(
                "{flag} {s:?}: expected {n} numbers separated by ':'"
            ))
        })?;
    if v.len() != n || !v.iter().all(|x| x.is_finite()) {
        return Err(input(format!(
            "{flag} {s:?}: expected {n} finite numbers separated by ':'"
        )));
    }
    Ok(v)
}

/// A vector option `X:Y:Z`.
fn vector(flag: &str, s: &Option<String>) -> Result<Option<Vector3<f64>>, CliError> {
    s.as_deref()
        .map(|s| numbers(flag, s, 3).map(|v| Vector3::new(v[0], v[1], v[2])))
        .transpose()
}

/// The scenario and its settings from the arguments (`commands_duration`: the length of
/// a `--commands` profile, the default duration then).
fn settings(
    a: &SimulateArgs,
    commands_duration: Option<f64>,
) -> Result<(Scenario, Common), CliError> {
    let (mut sc, mut common) = match (a.preset, a.scenario) {
        (Some(p), _) => {
            let p = match p {
                PresetArg::SmallSat => Preset::small_sat(),
                PresetArg::Microsat => Preset::microsat(),
                PresetArg::Throw => Preset::throw(),
            };
            (p.scenario, p.common)
        }
        (None, Some(s)) if a.paper_inertia => (scenario(s), Common::paper()),
        (None, Some(s)) => (scenario(s), Common::physical()),
        // `--commands`: the scenario only carries the settings; the commands fly.
        (None, None) if a.commands.is_some() => (Scenario::slew(), Common::physical()),
        (None, None) => return Err(input("one of --scenario and --preset is required")),
    };
    if let Some(j) = &a.inertia {
        let v = numbers("--inertia", j, 6)?;
        common.inertia_kg_m2 = nalgebra::Matrix3::new(
            v[0], v[3], v[4], //
            v[3], v[1], v[5], //
            v[4], v[5], v[2],
        );
    }
    if let Some(v) = vector("--momentum-bias", &a.momentum_bias)? {
        match &mut sc {
            Scenario::Slew(p) => p.momentum_bias_nms = v,
            Scenario::Spin(_) => {
                return Err(input(
                    "--momentum-bias: the spin starts with its own momentum; give it with a slew",
                ))
            }
        }
    }
    if let Some(d) = a.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(input(format!(
                "--duration {}: must be finite and > 0",
                Num(d)
            )));
        }
    }
    let dt = a.dt.unwrap_or(common.dt_s);
    if !(dt.is_finite() && dt > 0.0) {
        return Err(input(format!("--dt {dt}: must be finite and > 0")));
    }
    let j0 = common.inertia_kg_m2;
    common.inertia_change = match (&a.inertia_step, &a.inertia_ramp) {
        (Some(s), _) => {
            let v = numbers("--inertia-step", s, 2)?;
            Some(inertia::sim::InertiaChange::Step {
                at_s: v[0],
                to_kg_m2: j0 * v[1],
            })
        }
        (None, Some(s)) => {
            let v = numbers("--inertia-ramp", s, 3)?;
            if !(v[1] > v[0]) {
                return Err(input(format!("--inertia-ramp {s:?}: T1 must be after T0")));
            }
            Some(inertia::sim::InertiaChange::Ramp {
                start_s: v[0],
                end_s: v[1],
                to_kg_m2: j0 * v[2],
            })
        }
        (None, None) => None,
    };
    if a.dt.is_some() || a.preset.is_none() {
        // Keep the integrator's substep near 5 ms whatever the node period (a preset
        // keeps its own substeps at its own period).
        common.substeps = ((dt / 0.005).round() as usize).max(1);
    }
    common.dt_s = dt;
    common.duration_s = a.duration.or(commands_duration);
    common.seed = a.seed;
    if let Some(d) = a.disturbance {
        common.disturbance_nm_rthz = d;
    }
    if let Some(g) = a.gyro_noise {
        common.gyro_noise_deg_s_rthz = g;
    }
    if let Some(arw) = a.gyro_arw_deg_rthr {
        common.gyro_noise_deg_s_rthz = arw_deg_rthr_to_deg_s_rthz(arw);
    }
    let r = &mut common.realism;
    if let Some(t) = a.telemetry_dt {
        let n = t / dt;
        let every = n.round();
        if !(t.is_finite() && every >= 1.0 && (n - every).abs() <= 1e-9 * every) {
            return Err(input(format!(
                "--telemetry-dt {t}: must be a whole multiple (>= 1) of --dt {}",
                dt
            )));
        }
        r.telemetry_every = every as usize;
    }
    let period = dt * r.telemetry_every as f64;
    let duration = a
        .duration
        .or(commands_duration)
        .unwrap_or_else(|| sc.default_duration_s());
    if SimConfig::samples_for(duration, period) > MAX_SAMPLES {
        return Err(input(format!(
            "--duration {}: more than {MAX_SAMPLES} samples at the telemetry period {} s (a run is held in memory); at most {} s",
            Num(duration),
            Num(period),
            Num((MAX_SAMPLES - 1) as f64 * period)
        )));
    }
    let samples = SimConfig::samples_for(duration, period);
    let steps = samples as f64 * r.telemetry_every as f64 * common.substeps as f64;
    if steps > MAX_INTEGRATION_STEPS {
        return Err(input(format!(
            "--dt {} with a duration of {} s: {} integration steps ({samples} samples, {} nodes per sample, {} steps of at most 5 ms per node); at most {}",
            Num(dt),
            Num(duration),
            Num(steps),
            r.telemetry_every,
            common.substeps,
            Num(MAX_INTEGRATION_STEPS)
        )));
    }
    if let Some(b) = vector("--gyro-bias-deg-h", &a.gyro_bias_deg_h)? {
        r.gyro.bias_deg_h = b;
    }
    if let Some(b) = a.gyro_bias_instability_deg_h {
        r.gyro.bias_instability_deg_h = b;
    }
    if let Some(t) = a.gyro_bias_correlation_s {
        r.gyro.bias_correlation_s = t;
    }
    if let Some(s) = a.attitude {
        r.attitude = match s {
            AttitudeArg::Truth => AttitudeSource::Truth,
            AttitudeArg::Gyro => AttitudeSource::GyroPropagated,
            AttitudeArg::StarTracker => AttitudeSource::StarTracker,
            AttitudeArg::Mekf => AttitudeSource::Mekf,
        };
    }
    if let Some(v) = vector("--star-tracker-arcsec", &a.star_tracker_arcsec)? {
        r.star_tracker.noise_arcsec = v;
    }
    if let Some(v) = vector("--star-tracker-boresight", &a.star_tracker_boresight)? {
        r.star_tracker.boresight_body = v;
    }
    if let Some(hz) = a.star_tracker_hz {
        r.star_tracker.rate_hz = Some(hz);
    }
    if a.mekf_raw_rates {
        r.mekf.bias_corrected_rates = false;
    }
    if let Some(hz) = a.controller_hz {
        r.commands = Some(CommandHold {
            rate_hz: hz,
            phase_s: a.command_phase,
        });
    } else if a.command_phase != 0.0 {
        match r.commands.as_mut() {
            Some(c) => c.phase_s = a.command_phase,
            None => return Err(input("--command-phase needs --controller-hz")),
        }
    }
    if let Some(q) = a.wheel_quantization_nms {
        r.wheels.quantization_nms = q;
    }
    if let Some(n) = a.wheel_noise_nms {
        r.wheels.noise_nms = n;
    }
    if let Some(s) = a.wheel_skew_s {
        r.wheels.skew_s = s;
    }
    if let Some(v) = vector("--wheel-scale-error", &a.wheel_scale_error)? {
        r.wheels.scale_error = v;
    }
    if let Some(v) = vector("--wheel-misalignment-deg", &a.wheel_misalignment_deg)? {
        r.wheels.misalignment_deg = v;
    }
    if let Some(km) = a.gravity_gradient_altitude_km {
        if !(km >= 0.0) {
            return Err(input(format!(
                "--gravity-gradient-altitude-km {}: must be >= 0 (an orbit above the surface)",
                Num(km)
            )));
        }
        r.environment.orbit = Some(Orbit {
            inclination_deg: a.orbit_inclination_deg,
            ..Orbit::circular(km * 1e3)
        });
    }
    if let Some(v) = vector("--constant-torque-nm", &a.constant_torque_nm)? {
        r.environment.constant_torque_nm = v;
    }
    if let Some(v) = vector("--inertial-torque-nm", &a.inertial_torque_nm)? {
        r.environment.inertial_torque_nm = v;
    }
    if let Some(d) = a.drag_nms {
        r.environment.damping_nms = d;
    }
    magnetic_and_thrusters(a, &mut r.environment)?;
    if let Some(v) = vector("--gyro-vibration-rad-s", &a.gyro_vibration_rad_s)? {
        r.vibration.amplitude_rad_s = v;
    }
    if let Some(i) = a.rotor_spin_inertia_kg_m2 {
        r.vibration.rotor_spin_inertia_kg_m2 = i;
    }
    if let Some(hz) = a.wheel_hold_hz {
        r.wheels.hold_hz = Some(hz);
    }
    Ok((sc, common))
}

/// The magnetic options and the thrusters' (after the orbit's).
fn magnetic_and_thrusters(a: &SimulateArgs, env: &mut Environment) -> Result<(), CliError> {
    let field = vector("--magnetic-field-t", &a.magnetic_field_t)?;
    let residual = vector("--residual-dipole-am2", &a.residual_dipole_am2)?;
    let bias = vector("--magnetometer-bias-t", &a.magnetometer_bias_t)?;
    let any = field.is_some()
        || residual.is_some()
        || a.magnetorquer_am2.is_some()
        || a.magnetometer_noise_t.is_some()
        || bias.is_some();
    if any {
        let mut m = match field {
            Some(b) => Magnetic::constant(b),
            None if env.orbit.is_some() => Magnetic::dipole(),
            None => {
                return Err(input(
                    "the magnetic options need a field: --gravity-gradient-altitude-km (Earth's dipole field on that orbit) or --magnetic-field-t",
                ))
            }
        };
        m.residual_dipole_am2 = residual.unwrap_or_default();
        m.magnetorquer = a.magnetorquer_am2.map(Magnetorquer::sine);
        if let Some(s) = a.magnetometer_noise_t {
            m.magnetometer.noise_t = s;
        }
        if let Some(b) = bias {
            m.magnetometer.bias_t = b;
        }
        env.magnetic = Some(m);
    }
    if let Some(thrust) = a.thrusters {
        let mut t = Thrusters::cube_pairs(thrust, a.thruster_arm_m);
        if let Some(c) = vector("--centre-of-mass-m", &a.centre_of_mass_m)? {
            t.centre_of_mass_m = c;
        }
        if let Some(s) = a.force_noise_n {
            t.force_noise_n = s;
        }
        env.thrusters = Some(t);
    }
    Ok(())
}

/// The rotors' speed columns and values of a spacecraft file.
type Speeds = (Vec<String>, Vec<f64>);

/// Write the telemetry CSV, with the outside measurements' columns (`r_*` with an orbit,
/// `b_*` with a magnetic field, `f_*` with thrusters) and the rotors' speed columns
/// instead of `rho_*` when there is a spacecraft file.
fn write_csv(w: &mut dyn Write, out: &SimOutput, speeds: Option<&Speeds>) -> std::io::Result<()> {
    match speeds {
        Some((names, values)) => {
            let cols = ExternalColumns::of(&out.samples);
            let values_of = |s: &inertia::sample::Sample| cols.values(s);
            write_samples_with_speeds(w, &out.samples, names, values, (&cols.names(), &values_of))
        }
        None => write_samples_external(w, &out.samples),
    }
}

/// Run the command.
pub fn run(a: &SimulateArgs) -> Result<(), CliError> {
    let commands = a
        .commands
        .as_deref()
        .map(|p| -> Result<CommandProfile, CliError> {
            let text = std::fs::read_to_string(p).map_err(|e| read_failed(p, e))?;
            CommandProfile::parse_csv(&text, &p.display().to_string()).map_err(input)
        })
        .transpose()?;
    let (sc, mut common) = settings(a, commands.as_ref().map(CommandProfile::duration_s))?;
    if let Some(p) = &commands {
        // The simulator splits its steps at the commands' ticks.
        common
            .realism
            .commands
            .get_or_insert(CommandHold::at(1.0 / p.period_s));
    }
    let spacecraft = a
        .spacecraft
        .as_deref()
        .map(|p| inertia::spacecraft::Spacecraft::load(p).map_err(|e| input(e.to_string())))
        .transpose()?;
    if let (Some(sc), Some(p)) = (&spacecraft, a.spacecraft.as_deref()) {
        if sc.rotors.is_empty() {
            return Err(input(format!(
                "--spacecraft {}: the file lists no rotors; simulate --spacecraft writes each \
                 rotor's speed (the wheel momentum split among at least three rotors whose \
                 axes span the body), and its thrusters are not simulated from the file (give \
                 --thrusters)",
                p.display()
            )));
        }
    }
    let stdout = is_stdio(&a.output);
    // Create both files first: an unwritable destination fails before the simulation.
    let csv = (!stdout).then(|| Pending::create(&a.output)).transpose()?;
    let truth_file = truth_path(&a.output);
    // Nothing beside a device (`-o /dev/null`): no `/dev/null.truth.json`.
    let special = is_special(&a.output);
    let truth = (!stdout && !special)
        .then(|| Pending::create(&truth_file))
        .transpose()?;
    let out = match &commands {
        None => sc.simulate(&common).map_err(sim_error)?,
        Some(p) => {
            // From rest, the wheels at zero momentum, the commands as the wheel torque.
            let mut cfg = sc.config(&common);
            cfg.initial = inertia::dynamics::GyrostatState {
                q: inertia::attitude::Quaternion::IDENTITY,
                omega_rad_s: Vector3::zeros(),
                rho_nms: Vector3::zeros(),
            };
            inertia::sim::simulate(&cfg, p, &inertia::sim::Zero).map_err(sim_error)?
        }
    };
    let speeds = spacecraft
        .map(|s| -> Result<Speeds, CliError> {
            let v = inertia::sim::rotors::speeds(&out.samples, &s).map_err(sim_error)?;
            Ok((s.speed_columns(), v))
        })
        .transpose()?;
    match csv {
        Some((pending, mut w)) => {
            write_csv(&mut w, &out, speeds.as_ref()).map_err(|e| write_failed(&a.output, e))?;
            pending.commit(w)?;
        }
        None => to_stdout(|w| write_csv(w, &out, speeds.as_ref()))?,
    }
    let written = if let Some((pending, mut w)) = truth {
        // The truth file holds the inertia at the end of the run (after any change).
        let t_end = out.samples.last().map_or(0.0, |s| s.t_s);
        let json = serde_json::to_string_pretty(&InertiaFile::new(&out.inertia_at(t_end)))
            .map_err(crate::error::internal)?;
        writeln!(w, "{json}").map_err(|e| write_failed(&truth_file, e))?;
        pending.commit(w)?;
        format!("{} and {}", a.output.display(), truth_file.display())
    } else if special {
        format!("{} (not a regular file: no truth file)", a.output.display())
    } else {
        "standard output (no truth file)".into()
    };
    eprintln!(
        "wrote {} samples ({} scenario, h = {} s) to {written}",
        out.samples.len(),
        a.preset.map_or(
            if commands.is_some() {
                "commands"
            } else {
                sc.name()
            },
            |p| match p {
                PresetArg::SmallSat => "small-sat",
                PresetArg::Microsat => "microsat",
                PresetArg::Throw => "throw",
            }
        ),
        Num(common.dt_s * common.realism.telemetry_every as f64),
    );
    Ok(())
}

/// The `simulate` option behind a simulator setting, so that its error names what the user
/// typed (`None`: a setting no option sets on its own).
fn option_of(field: &str) -> Option<&'static str> {
    Some(match field {
        "dt_s" => "--dt",
        "samples" => "--duration (with --dt)",
        "telemetry_every" => "--telemetry-dt",
        "gyro_noise_deg_s_rthz" => "--gyro-noise or --gyro-arw-deg-rthr",
        "disturbance_nm_rthz" => "--disturbance",
        "gyro.bias_deg_h" => "--gyro-bias-deg-h",
        "gyro.bias_instability_deg_h" => "--gyro-bias-instability-deg-h",
        "gyro.bias_correlation_s" => "--gyro-bias-correlation-s",
        "star_tracker.noise_arcsec" => "--star-tracker-arcsec",
        "star_tracker.boresight_body" => "--star-tracker-boresight",
        "star_tracker.rate_hz" => "--star-tracker-hz",
        "commands.rate_hz" => "--controller-hz",
        "commands.phase_s" => "--command-phase",
        "wheels.quantization_nms" => "--wheel-quantization-nms",
        "wheels.noise_nms" => "--wheel-noise-nms",
        "wheels.skew_s" => "--wheel-skew-s",
        "wheels.scale_error" => "--wheel-scale-error",
        "wheels.misalignment_deg" => "--wheel-misalignment-deg",
        "wheels.hold_hz" => "--wheel-hold-hz",
        "environment.orbit.altitude_m" => "--gravity-gradient-altitude-km",
        "environment.orbit.inclination_deg" => "--orbit-inclination-deg",
        "environment.constant_torque_nm" => "--constant-torque-nm",
        "environment.inertial_torque_nm" => "--inertial-torque-nm",
        "environment.damping_nms" => "--drag-nms",
        "environment.magnetic.field" => "--magnetic-field-t",
        "environment.magnetic.residual_dipole_am2" => "--residual-dipole-am2",
        "environment.magnetic.magnetorquer.amplitude_am2" => "--magnetorquer-am2",
        "environment.magnetic.magnetometer.noise_t" => "--magnetometer-noise-t",
        "environment.magnetic.magnetometer.bias_t" => "--magnetometer-bias-t",
        "environment.thrusters.units.thrust_n" => "--thrusters",
        "environment.thrusters.units.position_m" => "--thruster-arm-m",
        "environment.thrusters.centre_of_mass_m" => "--centre-of-mass-m",
        "environment.thrusters.force_noise_n" => "--force-noise-n",
        "vibration.amplitude_rad_s" => "--gyro-vibration-rad-s",
        "vibration.rotor_spin_inertia_kg_m2" => "--rotor-spin-inertia-kg-m2",
        _ => return None,
    })
}

/// A simulator error in the command line's words: the option first, the setting (in the
/// simulator's units) beside it.
fn sim_error(e: inertia::sim::SimError) -> CliError {
    let inertia::sim::SimError::InvalidSetting { field, .. } = &e;
    match option_of(field) {
        Some(option) => input(format!("{option}: {e}")),
        None => input(e),
    }
}
