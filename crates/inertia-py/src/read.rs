//! Reading a telemetry file into a [`Telemetry`]: the library's CSV reader, with a
//! spacecraft file's rotor speeds and thrusters' throttles applied as the run applies
//! them.

use crate::errors::Failure;
use crate::{Rotors, Telemetry};
use inertia::telemetry::csv::{CsvOptions, TelemetryError, TelemetryReader};

fn telemetry_failure(e: TelemetryError) -> Failure {
    match e {
        TelemetryError::Io { .. } => Failure::Io(e.to_string()),
        other => Failure::Data {
            line: other.line(),
            kind: Some(other.error_kind()),
            sample: None,
            message: other.to_string(),
        },
    }
}

pub fn read(
    path: &std::path::Path,
    options: CsvOptions,
    spacecraft: Option<(inertia::spacecraft::Spacecraft, (String, String))>,
) -> Result<Telemetry, Failure> {
    let f = std::fs::File::open(path)
        .map_err(|e| Failure::Io(format!("cannot read {}: {e}", path.display())))?;
    let name = path.display().to_string();
    let mut reader = TelemetryReader::new(f, &name, options).map_err(telemetry_failure)?;
    let (mut samples, mut lines, mut speeds) = (Vec::new(), Vec::new(), Vec::new());
    while let Some(item) = reader.next() {
        let mut s = item.map_err(telemetry_failure)?;
        if let Some((sc, _)) = &spacecraft {
            // The rotor momentum as the run computes it (for `.rho`; the run recomputes).
            if !sc.rotors.is_empty() {
                s.rho_nms = sc.momentum_nms(reader.last_speeds());
                speeds.extend_from_slice(reader.last_speeds());
            }
            // The thrusters' torque about the origin and force, as the run computes them
            // (the run is then given the file without its thrusters).
            if !sc.thrusters.is_empty() {
                if s.external.force_n.is_some() {
                    return Err(Failure::Data {
                        line: Some(reader.last_line()),
                        kind: Some(inertia::error_kind::ErrorKind::Columns),
                        sample: Some(samples.len()),
                        message: format!(
                            "{}:{}: the force is given twice: by the file's f_x,f_y,f_z and by the spacecraft file's thrusters; give one",
                            reader.file(),
                            reader.last_line()
                        ),
                    });
                }
                let (force, torque) = inertia::spacecraft::thrusters::force_and_torque(
                    &sc.thrusters,
                    reader.last_throttles(),
                );
                s.tau_nm += torque;
                s.external.force_n = Some(force);
            }
        }
        samples.push(s);
        lines.push(reader.last_line());
    }
    let st = reader.stats();
    Ok(Telemetry {
        samples,
        lines: Some(lines),
        file: Some(reader.file().to_string()),
        stats: st,
        q_columns: reader.quaternion_columns(),
        label: reader.file().to_string(),
        rotors: spacecraft.map(|(spacecraft, source)| Rotors {
            spacecraft,
            source,
            speeds,
        }),
    })
}
