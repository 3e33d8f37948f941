//! Reading telemetry from CSV files (feature `csv`).
//!
//! # Format
//!
//! A header line, then one row per node. Columns are found by name (defaults below,
//! renamable with `ColumnNames`); extra columns are ignored. SI units, body axes.
//!
//! | columns | meaning | required |
//! |---|---|---|
//! | `t` | time, s, or ISO-8601/RFC 3339 UTC time stamps (`2026-11-21T09:06:00.1Z`; converted to seconds since the first row) | yes |
//! | `q_x,q_y,q_z,q_w` | attitude quaternion (see [`QuaternionFormat`]) | yes, unless the file has gyro rates, no column that looks like a quaternion's, and no quaternion option or renamed quaternion column: the attitude is then integrated from the rates ([`GateOptions::attitude_from_gyro`](super::gate::GateOptions::attitude_from_gyro)) |
//! | `rho_x,rho_y,rho_z` | total rotor angular momentum, N m s | yes |
//! | `tau_x,tau_y,tau_z` | known external torque, N m | no (zero) |
//! | `w_x,w_y,w_z` | gyro rate averaged over `[t_k, t_{k+1}]`, rad/s | for the finite-difference and momentum estimators |
//! | `r_x,r_y,r_z` | position of the centre of mass in the attitude's inertial frame (the orbit), m | no: given, the gravity-gradient torque is modelled |
//! | `b_x,b_y,b_z` | magnetic field, T, body axes | no: given, a residual magnetic dipole is estimated |
//! | `dipole_x,dipole_y,dipole_z` | commanded magnetic dipole (magnetorquers), A m², body axes | no (needs `b_*`): its torque `m × B` is added to the known torque |
//! | `f_x,f_y,f_z` | external force (thrusters), N, body axes | no: given, the centre of mass is estimated (`tau_*` then taken about the body frame's origin) |
//!
//! # Validation
//!
//! Every error names the file, the line and the column. The reader refuses what is about
//! the file: unparsable numbers, missing or duplicated columns, lines longer than
//! `MAX_LINE_BYTES` (1 MiB) (checked while reading, so a file without line breaks fails fast),
//! lines starting with `#` (there are no comment lines: every non-blank line is data). The
//! values themselves go through the sample gate that Python's arrays and the C API also use
//! ([`super::gate`], [`TelemetryError::Sample`]): NaN or infinite values, values outside the
//! supported range ([`crate::sample::range`]), quaternions whose norm differs from 1 by
//! more than [`CsvOptions::unit_tolerance`] (smaller deviations are renormalised and
//! counted), non-increasing time, gyro columns blank in a row after rows that had rates,
//! and, only when [`CsvOptions::period_tolerance`] is set, a step that differs from the
//! first one by more than that (relative). What concerns pairs of
//! samples as rows (the rotation of a step, gaps) is the estimators' to check and count,
//! once ([`crate::estimator::rows`]).
//!
//! Messages are one line of bounded length: quoted file content is cut after
//! `MAX_QUOTED_CHARS` (80) characters, numbers use [`crate::text::Num`].
//!
//! ISO time stamps are converted to elapsed seconds across UTC leap seconds
//! (`23:59:60`), counting the leap seconds of the IERS table and any the file shows.
//!
//! Irregular sampling is accepted: the variational rows handle unequal steps. Consecutive quaternions of opposite
//! sign (`q` and `−q` are the same attitude) are accepted and counted. Nothing is dropped:
//! a row is either returned or reported as an error (only blank lines, which hold
//! nothing, are skipped), and [`ReadStats`] counts what was read, renormalised and
//! sign-flipped.
//!
//! The reader is an iterator and holds one row at a time: memory does not grow with the
//! file.

use super::gate::{Field, Gate, GateOptions, RawExternal, RawSample};
pub use super::gate::{GyroUnit, QuaternionFormat, ReadStats, DEFAULT_UNIT_TOLERANCE};
use super::line_cap::{LineCap, LineTooLong};
use super::time_stamp::{Clock, StampError};
use crate::sample::Sample;

use std::collections::HashMap;
use std::fs::File;
use std::io::Read;
use std::path::Path;

/// The longest line accepted, bytes (1 MiB).
pub(crate) const MAX_LINE_BYTES: usize = 1 << 20;

/// Reading options.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvOptions {
    /// Quaternion storage and convention.
    pub quaternion: QuaternionFormat,
    /// Column names.
    pub columns: ColumnNames,
    /// Quaternions with `| |q| − 1 |` up to this are renormalised (and counted); beyond it
    /// they are an error. Default [`DEFAULT_UNIT_TOLERANCE`].
    pub unit_tolerance: f64,
    /// When set, the relative tolerance on the uniformity of the sample period (strict
    /// mode: a deviating step is an error). Default `None`: irregular steps are accepted.
    pub period_tolerance: Option<f64>,
    /// Field delimiter. Default `,`.
    pub delimiter: u8,
    /// The `rho_*` columns hold the rotor momentum with the opposite sign of this
    /// library's convention (e.g. the wheels' reaction on the body): negate them as they
    /// are read. Default `false`. The pipeline stops where the data show a reversed sign
    /// ([`crate::pipeline::PipelineError::ReversedMomentum`]).
    pub negate_rho: bool,
    /// The unit of the `w_*` columns. Default rad/s.
    pub gyro_unit: GyroUnit,
    /// Columns of the rotors' speeds (a spacecraft file's, [`crate::spacecraft`]), each
    /// required and read as a finite number in its stored unit
    /// ([`TelemetryReader::last_speeds`]; negated with [`Self::negate_rho`]). When given,
    /// the rotor momentum comes from them (the run computes it) and the file must not also
    /// have the `rho_*` columns. Default none.
    pub speed_columns: Vec<String>,
    /// Columns of the thrusters' throttles (a spacecraft file's,
    /// [`crate::spacecraft::thrusters`]), each required and read as a finite number
    /// ([`TelemetryReader::last_throttles`]). Default none.
    pub thruster_columns: Vec<String>,
}

impl Default for CsvOptions {
    fn default() -> Self {
        Self {
            quaternion: QuaternionFormat::default(),
            columns: ColumnNames::default(),
            unit_tolerance: DEFAULT_UNIT_TOLERANCE,
            period_tolerance: None,
            delimiter: b',',
            negate_rho: false,
            gyro_unit: GyroUnit::RadPerS,
            speed_columns: Vec::new(),
            thruster_columns: Vec::new(),
        }
    }
}

#[derive(Debug, Clone)]
struct Indices {
    t: usize,
    /// `None` where the file has no quaternion columns and the attitude is integrated from
    /// the gyro rates ([`GateOptions::attitude_from_gyro`]).
    q: Option<[usize; 4]>,
    /// `None` where the rotor momentum comes from the rotors' speeds.
    rho: Option<[usize; 3]>,
    tau: Option<[usize; 3]>,
    w: Option<[usize; 3]>,
    /// Position, field, force, dipole ([`RawExternal`]'s order).
    external: [Option<[usize; 3]>; 4],
    speeds: Vec<usize>,
    thrusters: Vec<usize>,
}

/// A streaming, validating CSV telemetry reader.
pub struct TelemetryReader<R: Read> {
    reader: csv::Reader<LineCap<R>>,
    record: csv::StringRecord,
    /// 1-based line of the last record read.
    line: u64,
    file: String,
    idx: Indices,
    headers: Vec<String>,
    /// The checks of every sample's values ([`super::gate`]).
    gate: Gate,
    /// For ISO time stamps: the first row's (seconds, nanoseconds) on the clock's scale.
    time_origin: Option<(i64, i64)>,
    /// Converts ISO time stamps, counting leap seconds.
    clock: Clock,
    failed: bool,
    /// The last row's rotor speeds, as stored (negated with `negate_rho`).
    speeds: Vec<f64>,
    /// The last row's thruster throttles.
    throttles: Vec<f64>,
    negate_speeds: bool,
}

impl TelemetryReader<File> {
    /// Open a file.
    pub fn open(path: &Path, options: CsvOptions) -> Result<Self, TelemetryError> {
        let file = path.display().to_string();
        let f = File::open(path).map_err(|source| TelemetryError::Io {
            file: file.clone(),
            source,
        })?;
        Self::new(f, &file, options)
    }
}

impl<R: Read> TelemetryReader<R> {
    /// Read from any reader; `file` names it in messages.
    pub fn new(input: R, file: &str, options: CsvOptions) -> Result<Self, TelemetryError> {
        let mut reader = csv::ReaderBuilder::new()
            .delimiter(options.delimiter)
            .from_reader(LineCap::new(input, MAX_LINE_BYTES));
        let headers: Vec<String> = reader
            .headers()
            .map_err(|e| csv_error(file, e))?
            .iter()
            .map(|h| h.trim().to_string())
            .collect();
        // The header's line.
        let _ = reader.get_mut().claim_line();
        let mut seen = HashMap::with_capacity(headers.len());
        for (j, h) in headers.iter().enumerate() {
            if let Some(i) = seen.insert(h.as_str(), j) {
                return Err(TelemetryError::DuplicateColumn {
                    file: file.to_string(),
                    column: h.clone(),
                    first: i + 1,
                    second: j + 1,
                });
            }
        }
        let find = |name: &str| headers.iter().position(|h| h == name);
        let need = |name: &str| {
            find(name).ok_or_else(|| TelemetryError::MissingColumn {
                file: file.to_string(),
                column: name.to_string(),
                present: headers.join(","),
            })
        };
        let c = &options.columns;
        let optional3 = |names: &[String; 3]| -> Result<Option<[usize; 3]>, TelemetryError> {
            let found: Vec<Option<usize>> = names.iter().map(|n| find(n)).collect();
            if found.iter().all(Option::is_none) {
                return Ok(None);
            }
            // Some present: all must be.
            Ok(Some([need(&names[0])?, need(&names[1])?, need(&names[2])?]))
        };
        // No quaternion column at all, and gyro rates: the attitude is integrated from them.
        // Not where the user said anything about quaternions (a convention, renamed
        // columns) or the header has columns that look like one under other names: then
        // the missing column is the error, as without gyro rates.
        let from_gyro = c.q.iter().all(|n| find(n).is_none())
            && c.w.iter().all(|n| find(n).is_some())
            && options.quaternion == QuaternionFormat::default()
            && c.q == ColumnNames::default().q
            && !headers.iter().any(|h| looks_like_quaternion(h));
        let idx = Indices {
            t: need(&c.t)?,
            q: if from_gyro {
                None
            } else {
                Some([
                    need(&c.q[0])?,
                    need(&c.q[1])?,
                    need(&c.q[2])?,
                    need(&c.q[3])?,
                ])
            },
            rho: if options.speed_columns.is_empty() {
                Some([need(&c.rho[0])?, need(&c.rho[1])?, need(&c.rho[2])?])
            } else {
                if let Some(present) = c.rho.iter().find(|n| find(n).is_some()) {
                    return Err(TelemetryError::MomentumTwice {
                        file: file.to_string(),
                        column: present.clone(),
                    });
                }
                None
            },
            tau: optional3(&c.tau)?,
            w: optional3(&c.w)?,
            external: [
                optional3(&c.r)?,
                optional3(&c.b)?,
                optional3(&c.f)?,
                optional3(&c.dipole)?,
            ],
            speeds: options
                .speed_columns
                .iter()
                .map(|n| need(n))
                .collect::<Result<_, _>>()?,
            thrusters: options
                .thruster_columns
                .iter()
                .map(|n| need(n))
                .collect::<Result<_, _>>()?,
        };
        let gate = Gate::new(GateOptions {
            quaternion: options.quaternion,
            unit_tolerance: options.unit_tolerance,
            period_tolerance: options.period_tolerance,
            negate_rho: options.negate_rho,
            gyro_unit: options.gyro_unit,
            attitude_from_gyro: idx.q.is_none(),
        });
        Ok(Self {
            reader,
            record: csv::StringRecord::new(),
            file: file.to_string(),
            idx,
            headers,
            gate,
            time_origin: None,
            clock: Clock::default(),
            failed: false,
            line: 0,
            speeds: Vec::with_capacity(options.speed_columns.len()),
            throttles: Vec::with_capacity(options.thruster_columns.len()),
            negate_speeds: options.negate_rho,
        })
    }

    /// Counts so far.
    #[must_use]
    pub fn stats(&self) -> ReadStats {
        self.gate.stats()
    }

    /// `true` when the file has gyro-rate columns.
    #[must_use]
    pub fn has_gyro(&self) -> bool {
        self.idx.w.is_some()
    }

    /// The last row's rotor speeds ([`CsvOptions::speed_columns`], in their order and
    /// stored units); empty without speed columns.
    #[must_use]
    pub fn last_speeds(&self) -> &[f64] {
        &self.speeds
    }

    /// The last row's thruster throttles ([`CsvOptions::thruster_columns`], in their
    /// order); empty without thruster columns.
    #[must_use]
    pub fn last_throttles(&self) -> &[f64] {
        &self.throttles
    }

    /// Bytes consumed so far (for progress reporting).
    #[must_use]
    pub(crate) fn byte_position(&self) -> u64 {
        self.reader.position().byte()
    }

    /// Line (1-based) of the last record read.
    #[must_use]
    pub fn last_line(&self) -> u64 {
        self.line
    }

    /// The file name used in messages.
    #[must_use]
    pub fn file(&self) -> &str {
        &self.file
    }

    /// Column `i` as a number (its checks are the gate's).
    fn field(&self, line: u64, i: usize) -> Result<f64, TelemetryError> {
        let raw = self.record.get(i).unwrap_or("").trim();
        raw.parse().map_err(|_| TelemetryError::Parse {
            file: self.file.clone(),
            line,
            column: self.headers[i].clone(),
            value: raw.to_string(),
            hint: "",
        })
    }

    /// Three columns, or `None` where all three are blank (a gyro rate not given in this
    /// row, which the gate refuses after rows that had one).
    fn vec3(&self, line: u64, i: &[usize; 3]) -> Result<Option<[f64; 3]>, TelemetryError> {
        if i.iter()
            .all(|&c| self.record.get(c).is_none_or(|f| f.trim().is_empty()))
        {
            return Ok(None);
        }
        Ok(Some([
            self.field(line, i[0])?,
            self.field(line, i[1])?,
            self.field(line, i[2])?,
        ]))
    }

    /// The column of `field`, for messages.
    fn column(&self, field: Field) -> String {
        let i = match field {
            Field::Time => self.idx.t,
            Field::Quaternion(k) => match self.idx.q {
                Some(c) => c[k],
                None => return self.quaternion_columns(),
            },
            Field::QuaternionNorm => return self.quaternion_columns(),
            Field::Rho(k) => match self.idx.rho {
                Some(c) => c[k],
                None => {
                    return self
                        .idx
                        .speeds
                        .iter()
                        .map(|&i| self.headers[i].clone())
                        .collect::<Vec<_>>()
                        .join(",")
                }
            },
            Field::Tau(k) => self.idx.tau.map_or(self.idx.t, |c| c[k]),
            Field::Rate(k) => self.idx.w.map_or(self.idx.t, |c| c[k]),
            Field::Position(k) => self.idx.external[0].map_or(self.idx.t, |c| c[k]),
            Field::MagneticField(k) => self.idx.external[1].map_or(self.idx.t, |c| c[k]),
            Field::Force(k) => self.idx.external[2].map_or(self.idx.t, |c| c[k]),
            Field::Dipole(k) => self.idx.external[3].map_or(self.idx.t, |c| c[k]),
        };
        self.headers[i].clone()
    }

    /// The thrusters' throttles of this row into [`Self::throttles`]: finite numbers.
    fn read_throttles(&mut self, line: u64) -> Result<(), TelemetryError> {
        self.throttles.clear();
        for k in 0..self.idx.thrusters.len() {
            let i = self.idx.thrusters[k];
            let v = self.field(line, i)?;
            if !(v.is_finite() && v.abs() <= crate::spacecraft::thrusters::MAX_THROTTLE) {
                return Err(TelemetryError::Parse {
                    file: self.file.clone(),
                    line,
                    column: self.headers[i].clone(),
                    value: self.record.get(i).unwrap_or("").trim().to_string(),
                    hint:
                        " (a throttle: a finite fraction of full thrust, at most 1.5 in magnitude)",
                });
            }
            self.throttles.push(v);
        }
        Ok(())
    }

    /// The rotors' speeds of this row into [`Self::speeds`]: finite numbers.
    fn read_speeds(&mut self, line: u64) -> Result<(), TelemetryError> {
        self.speeds.clear();
        for k in 0..self.idx.speeds.len() {
            let i = self.idx.speeds[k];
            let v = self.field(line, i)?;
            if !v.is_finite() {
                return Err(TelemetryError::Parse {
                    file: self.file.clone(),
                    line,
                    column: self.headers[i].clone(),
                    value: self.record.get(i).unwrap_or("").trim().to_string(),
                    hint: " (a rotor speed must be finite)",
                });
            }
            self.speeds.push(if self.negate_speeds { -v } else { v });
        }
        Ok(())
    }

    /// The names of the quaternion columns, comma-separated (for messages).
    #[must_use]
    pub fn quaternion_columns(&self) -> String {
        match self.idx.q {
            Some(q) => q.map(|i| self.headers[i].clone()).join(","),
            None => "(attitude from the gyro)".into(),
        }
    }

    /// The time column: seconds, or an ISO-8601/RFC 3339 time stamp converted to seconds
    /// since the first row's.
    fn time(&mut self, line: u64) -> Result<f64, TelemetryError> {
        let i = self.idx.t;
        let raw = self.record.get(i).unwrap_or("").trim();
        if self.time_origin.is_none() {
            if let Ok(v) = raw.parse::<f64>() {
                return Ok(v);
            }
        }
        let stamp = self.clock.parse(raw).map_err(|e| TelemetryError::Parse {
            file: self.file.clone(),
            line,
            column: self.headers[i].clone(),
            value: raw.to_string(),
            hint: match e {
                StampError::Unparsable => {
                    " or an ISO-8601 time stamp (e.g. 2026-11-21T09:06:00.1Z)"
                }
                StampError::NotALeapSecond => {
                    " or a time stamp: second 60 exists only at 23:59:60 UTC (a leap second)"
                }
            },
        })?;
        if self.gate.stats().rows > 0 && self.time_origin.is_none() {
            // Seconds so far, a time stamp now: not the same clock.
            return Err(TelemetryError::Parse {
                file: self.file.clone(),
                line,
                column: self.headers[i].clone(),
                value: raw.to_string(),
                hint: " (earlier rows hold seconds, this one a time stamp)",
            });
        }
        let origin = *self.time_origin.get_or_insert(stamp);
        Ok((stamp.0 - origin.0) as f64 + (stamp.1 - origin.1) as f64 * 1e-9)
    }

    fn parse_row(&mut self, line: u64) -> Result<Sample, TelemetryError> {
        if self
            .record
            .get(0)
            .is_some_and(|f| f.trim_start().starts_with('#'))
        {
            return Err(TelemetryError::Malformed {
                file: self.file.clone(),
                line,
                message: "the line starts with `#`: comment lines are not supported (every \
                          non-blank line after the header is data)"
                    .into(),
            });
        }
        self.read_throttles(line)?;
        let raw = RawSample {
            t_s: self.time(line)?,
            q: match self.idx.q {
                Some(i) => [
                    self.field(line, i[0])?,
                    self.field(line, i[1])?,
                    self.field(line, i[2])?,
                    self.field(line, i[3])?,
                ],
                None => [0.0, 0.0, 0.0, 1.0],
            },
            rho_nms: match self.idx.rho {
                Some(i) => [
                    self.field(line, i[0])?,
                    self.field(line, i[1])?,
                    self.field(line, i[2])?,
                ],
                None => {
                    self.read_speeds(line)?;
                    [0.0; 3]
                }
            },
            tau_nm: match self.idx.tau {
                Some(i) => Some([
                    self.field(line, i[0])?,
                    self.field(line, i[1])?,
                    self.field(line, i[2])?,
                ]),
                None => None,
            },
            w_rad_s: match self.idx.w {
                Some(i) => self.vec3(line, &i)?,
                None => None,
            },
            external: {
                let mut v = [None; 4];
                for (k, i) in self.idx.external.iter().enumerate() {
                    if let Some(i) = i {
                        v[k] = self.vec3(line, i)?;
                    }
                }
                RawExternal {
                    position_m: v[0],
                    field_t: v[1],
                    force_n: v[2],
                    dipole_am2: v[3],
                }
            },
        };
        self.gate
            .check(&raw)
            .map_err(|source| TelemetryError::Sample {
                file: self.file.clone(),
                line,
                column: self.column(source.field()),
                source,
            })
    }
}

/// Whether a header names what may be a quaternion component (`qx`, `q0`, `q_s`,
/// `quat_w`, …): a file with such a column is not read as gyro-only.
fn looks_like_quaternion(header: &str) -> bool {
    let h = header.to_ascii_lowercase();
    h.contains("quat") || (h.starts_with('q') && h.len() <= 4)
}

/// The reader's error for a CSV error: a line over the limit, an I/O failure, or a
/// malformed file.
fn csv_error(file: &str, e: csv::Error) -> TelemetryError {
    let line = e.position().map_or(0, csv::Position::line);
    let message = e.to_string();
    match e.into_kind() {
        csv::ErrorKind::Io(io) => {
            match io.get_ref().and_then(|x| x.downcast_ref::<LineTooLong>()) {
                Some(l) => TelemetryError::LineTooLong {
                    file: file.to_string(),
                    line: l.line,
                    limit: l.limit,
                },
                None => TelemetryError::Io {
                    file: file.to_string(),
                    source: io,
                },
            }
        }
        _ => TelemetryError::Malformed {
            file: file.to_string(),
            line,
            message,
        },
    }
}

impl<R: Read> Iterator for TelemetryReader<R> {
    type Item = Result<Sample, TelemetryError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        let mut record = core::mem::take(&mut self.record);
        let res = self.reader.read_record(&mut record);
        self.record = record;
        let item = match res {
            Ok(false) => return None,
            Err(e) => {
                let line = self.reader.get_mut().claim_line();
                Err(match (csv_error(&self.file, e), line) {
                    (TelemetryError::Malformed { file, message, .. }, Some(line)) => {
                        TelemetryError::Malformed {
                            file,
                            line,
                            message,
                        }
                    }
                    (other, _) => other,
                })
            }
            Ok(true) => {
                let line = self
                    .reader
                    .get_mut()
                    .claim_line()
                    .unwrap_or_else(|| self.record.position().map_or(0, csv::Position::line));
                self.line = line;
                self.parse_row(line)
            }
        };
        if let Err(e) = &item {
            // The gate counts the samples it refused.
            if !matches!(e, TelemetryError::Sample { .. }) {
                self.gate.reject();
            }
            self.failed = true;
        }
        Some(item)
    }
}

mod columns;
pub use columns::ColumnNames;
mod error;
#[cfg(test)]
mod tests;
mod write;

pub use error::TelemetryError;

pub use write::{
    write_samples, write_samples_external, write_samples_with, write_samples_with_speeds,
    ExternalColumns, ExtraColumns,
};
