//! Reading telemetry from CSV files (feature `csv`).
//!
//! # Format
//!
//! A header line, then one row per node. Columns are found by name (defaults below,
//! renamable with [`ColumnNames`]); extra columns are ignored. SI units, body axes.
//!
//! | columns | meaning | required |
//! |---|---|---|
//! | `t` | time, s, or ISO-8601/RFC 3339 UTC time stamps (`2026-11-21T09:06:00.1Z`; converted to seconds since the first row) | yes |
//! | `q_x,q_y,q_z,q_w` | attitude quaternion (see [`QuaternionFormat`]) | yes |
//! | `rho_x,rho_y,rho_z` | total rotor angular momentum, N m s | yes |
//! | `tau_x,tau_y,tau_z` | known external torque, N m | no (zero) |
//! | `w_x,w_y,w_z` | gyro rate averaged over `[t_k, t_{k+1}]`, rad/s | for the finite-difference and momentum estimators |
//!
//! # Validation
//!
//! Every error names the file, the line and the column: unparsable numbers, NaN or
//! infinite values, values outside the supported range ([`crate::sample::range`]), missing or duplicated columns, lines longer than [`MAX_LINE_BYTES`]
//! (checked while reading, so a file without line breaks fails fast), lines starting with
//! `#` (there are no comment lines: every non-blank line is data), quaternions whose norm differs from 1 by more than
//! [`CsvOptions::unit_tolerance`] (smaller deviations are renormalised and counted),
//! non-increasing time, and, only when [`CsvOptions::period_tolerance`] is set, a step
//! that differs from the first one by more than that (relative). What concerns pairs of
//! samples as rows (the rotation of a step, gaps) is the estimators' to check and count,
//! once ([`crate::estimator::rows`]).
//!
//! Messages are one line of bounded length: quoted file content is cut after
//! [`crate::text::MAX_QUOTED_CHARS`] characters, numbers use [`crate::text::Num`].
//!
//! ISO time stamps are converted to elapsed seconds across UTC leap seconds
//! (`23:59:60`; [`super::time_stamp`]).
//!
//! Irregular sampling is accepted: the variational rows handle unequal steps. Consecutive quaternions of opposite
//! sign (`q` and `−q` are the same attitude) are accepted and counted. Nothing is dropped:
//! a row is either returned or reported as an error (only blank lines, which hold
//! nothing, are skipped), and [`ReadStats`] counts what was read, renormalised and
//! sign-flipped.
//!
//! The reader is an iterator and holds one row at a time: memory does not grow with the
//! file.

use super::line_cap::{LineCap, LineTooLong};
use super::time_stamp::{Clock, StampError};
use crate::attitude::Quaternion;
use crate::sample::{check_value, Quantity, Sample};
use crate::text::{Clipped, Num, Quoted};
use nalgebra::Vector3;
use std::collections::HashMap;
use std::fs::File;
use std::io::Read;
use std::path::Path;

/// The longest line accepted, bytes (1 MiB).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Default tolerance on `| |q| − 1 |` below which quaternions are renormalised.
pub const DEFAULT_UNIT_TOLERANCE: f64 = 1e-3;

/// Where the scalar part of the quaternion is stored, and what the quaternion means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum QuaternionFormat {
    /// Hamilton, body → inertial, the four columns are the vector part then the scalar
    /// (this crate's convention). The default.
    #[default]
    HamiltonScalarLast,
    /// Hamilton, body → inertial, but the column named for `q_x` holds the scalar:
    /// columns `[q_x, q_y, q_z, q_w]` hold `[w, x, y, z]`.
    HamiltonScalarFirst,
    /// JPL/Shuster (inertial → body attitude matrix, scalar last). Converted with
    /// [`Quaternion::from_jpl_xyzw`].
    Jpl,
    /// Hamilton, scalar last, but mapping inertial → body (the conjugate of this crate's
    /// meaning): [`Quaternion::from_hamilton_inertial_to_body_xyzw`].
    Conjugate,
}

/// The unit of the gyro rate columns `w_*`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GyroUnit {
    /// rad/s (the default).
    #[default]
    RadPerS,
    /// deg/s: converted to rad/s as read.
    DegPerS,
}

/// Column names. Defaults are those of the table in the module docs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColumnNames {
    /// Time.
    pub t: String,
    /// Quaternion, in storage order.
    pub q: [String; 4],
    /// Rotor momentum.
    pub rho: [String; 3],
    /// Known torque.
    pub tau: [String; 3],
    /// Gyro rate.
    pub w: [String; 3],
}

impl Default for ColumnNames {
    fn default() -> Self {
        let v =
            |p: &str, s: &[&str]| -> Vec<String> { s.iter().map(|c| format!("{p}_{c}")).collect() };
        let arr3 = |v: Vec<String>| -> [String; 3] { [v[0].clone(), v[1].clone(), v[2].clone()] };
        let q = v("q", &["x", "y", "z", "w"]);
        Self {
            t: "t".into(),
            q: [q[0].clone(), q[1].clone(), q[2].clone(), q[3].clone()],
            rho: arr3(v("rho", &["x", "y", "z"])),
            tau: arr3(v("tau", &["x", "y", "z"])),
            w: arr3(v("w", &["x", "y", "z"])),
        }
    }
}

impl ColumnNames {
    /// Rename one column, e.g. `rename("t", "time")`. Returns `false` for an unknown key.
    pub fn rename(&mut self, key: &str, name: &str) -> bool {
        let d = Self::default();
        if key == d.t {
            self.t = name.into();
            return true;
        }
        for (dst, def) in self
            .q
            .iter_mut()
            .zip(&d.q)
            .chain(self.rho.iter_mut().zip(&d.rho))
            .chain(self.tau.iter_mut().zip(&d.tau))
            .chain(self.w.iter_mut().zip(&d.w))
        {
            if key == def {
                *dst = name.into();
                return true;
            }
        }
        false
    }
}

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
        }
    }
}

/// Counts of what was read.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReadStats {
    /// Data rows returned.
    pub rows: usize,
    /// Quaternions renormalised (within the tolerance).
    pub renormalised: usize,
    /// Quaternions whose sign was opposite to the previous one's (same attitude).
    pub sign_flips: usize,
    /// Rows rejected (the reader stops at the first; this is 0 or 1).
    pub rejected: usize,
    /// Shortest and longest step, s (0 before two rows).
    pub min_step_s: f64,
    /// Longest step, s.
    pub max_step_s: f64,
}

impl ReadStats {
    /// Count the step of `dt` s into the next row, whose quaternion `q` follows `prev`
    /// (before that row is counted in `rows`): the shortest and longest step, and a sign
    /// opposite to the previous quaternion's.
    pub fn step(
        &mut self,
        dt: f64,
        prev: &crate::attitude::Quaternion,
        q: &crate::attitude::Quaternion,
    ) {
        self.min_step_s = if self.rows > 1 {
            self.min_step_s.min(dt)
        } else {
            dt
        };
        self.max_step_s = self.max_step_s.max(dt);
        if prev.v.dot(&q.v) + prev.s * q.s < 0.0 {
            self.sign_flips += 1;
        }
    }
}

/// What is wrong, where.
#[derive(Debug, thiserror::Error)]
pub enum TelemetryError {
    /// The file could not be opened or read.
    #[error("{file}: {source}")]
    Io {
        /// File name.
        file: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A line is longer than [`MAX_LINE_BYTES`] (found before it is read whole).
    #[error("{file}:{line}: line longer than {limit} bytes (no line break?)")]
    LineTooLong {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// The limit, bytes.
        limit: usize,
    },
    /// Two header columns have the same name.
    #[error("{file}:1: column `{}` appears twice (columns {first} and {second})", Clipped::new(.column))]
    DuplicateColumn {
        /// File name.
        file: String,
        /// The name.
        column: String,
        /// Its first position (1-based).
        first: usize,
        /// Its second position (1-based).
        second: usize,
    },
    /// The CSV structure is broken (e.g. a row with a different number of fields).
    #[error("{file}:{line}: malformed CSV: {}", Clipped::with_limit(.message, 300))]
    Malformed {
        /// File name.
        file: String,
        /// Line (1-based).
        line: u64,
        /// The parser's message.
        message: String,
    },
    /// A required column is absent from the header.
    #[error("{file}:1: missing column `{}` (columns present: {})", Clipped::new(.column), Clipped::new(.present))]
    MissingColumn {
        /// File name.
        file: String,
        /// The column.
        column: String,
        /// The header's columns.
        present: String,
    },
    /// A field is not a number (or, in the time column, not a time stamp).
    #[error("{file}:{line}: column `{}`: cannot parse {} as a number{hint}", Clipped::new(.column), Quoted(.value))]
    Parse {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// Column.
        column: String,
        /// The field.
        value: String,
        /// Extra explanation (may be empty).
        hint: &'static str,
    },
    /// A field is NaN or infinite.
    #[error("{file}:{line}: column `{}`: value {value} is not finite", Clipped::new(.column))]
    NonFinite {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// Column.
        column: String,
        /// The value.
        value: f64,
    },
    /// A value outside the supported range ([`crate::sample::range`]).
    #[error("{file}:{line}: column `{}`: value {} is outside the supported range (magnitude at most {} {unit})", Clipped::new(.column), Num(*.value), Num(*.limit))]
    OutOfRange {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// Column.
        column: String,
        /// The value.
        value: f64,
        /// The largest magnitude supported.
        limit: f64,
        /// Its unit.
        unit: &'static str,
    },
    /// A quaternion's norm is too far from 1.
    #[error("{file}:{line}: columns `{}`: quaternion norm {norm:.6} differs from 1 by more than {tolerance:e}", Clipped::new(.columns))]
    NonUnitQuaternion {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// The quaternion columns.
        columns: String,
        /// Its norm.
        norm: f64,
        /// The tolerance.
        tolerance: f64,
    },
    /// Time does not increase.
    #[error("{file}:{line}: column `{}`: time {} s does not increase (previous row: {} s)", Clipped::new(.column), Num(*.t), Num(*.previous))]
    NonIncreasingTime {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// Column.
        column: String,
        /// This row's time.
        t: f64,
        /// Previous row's time.
        previous: f64,
    },
    /// The sample period changed.
    #[error("{file}:{line}: column `{}`: step {} s differs from the sample period {} s by more than {tolerance:e} (relative); resample or split the file", Clipped::new(.column), Num(*.dt), Num(*.period))]
    NonUniformPeriod {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// Column.
        column: String,
        /// This step.
        dt: f64,
        /// The period set by the first step.
        period: f64,
        /// The tolerance.
        tolerance: f64,
    },
}

impl TelemetryError {
    /// The 1-based line of the problem, when it is tied to one.
    #[must_use]
    pub fn line(&self) -> Option<u64> {
        match self {
            TelemetryError::Io { .. } => None,
            TelemetryError::MissingColumn { .. } | TelemetryError::DuplicateColumn { .. } => {
                Some(1)
            }
            TelemetryError::LineTooLong { line, .. }
            | TelemetryError::Malformed { line, .. }
            | TelemetryError::Parse { line, .. }
            | TelemetryError::NonFinite { line, .. }
            | TelemetryError::OutOfRange { line, .. }
            | TelemetryError::NonUnitQuaternion { line, .. }
            | TelemetryError::NonIncreasingTime { line, .. }
            | TelemetryError::NonUniformPeriod { line, .. } => Some(*line),
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct Indices {
    t: usize,
    q: [usize; 4],
    rho: [usize; 3],
    tau: Option<[usize; 3]>,
    w: Option<[usize; 3]>,
}

/// A streaming, validating CSV telemetry reader.
pub struct TelemetryReader<R: Read> {
    reader: csv::Reader<LineCap<R>>,
    record: csv::StringRecord,
    /// 1-based line of the last record read.
    line: u64,
    file: String,
    options: CsvOptions,
    idx: Indices,
    headers: Vec<String>,
    stats: ReadStats,
    prev: Option<Sample>,
    period: Option<f64>,
    /// For ISO time stamps: the first row's (seconds, nanoseconds) on the clock's scale.
    time_origin: Option<(i64, i64)>,
    /// Converts ISO time stamps, counting leap seconds.
    clock: Clock,
    failed: bool,
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
        let idx = Indices {
            t: need(&c.t)?,
            q: [
                need(&c.q[0])?,
                need(&c.q[1])?,
                need(&c.q[2])?,
                need(&c.q[3])?,
            ],
            rho: [need(&c.rho[0])?, need(&c.rho[1])?, need(&c.rho[2])?],
            tau: optional3(&c.tau)?,
            w: optional3(&c.w)?,
        };
        Ok(Self {
            reader,
            record: csv::StringRecord::new(),
            file: file.to_string(),
            options,
            idx,
            headers,
            stats: ReadStats::default(),
            prev: None,
            period: None,
            time_origin: None,
            clock: Clock::default(),
            failed: false,
            line: 0,
        })
    }

    /// Counts so far.
    #[must_use]
    pub fn stats(&self) -> ReadStats {
        self.stats
    }

    /// `true` when the file has gyro-rate columns.
    #[must_use]
    pub fn has_gyro(&self) -> bool {
        self.idx.w.is_some()
    }

    /// `true` when the file has known-torque columns.
    #[must_use]
    pub fn has_torque(&self) -> bool {
        self.idx.tau.is_some()
    }

    /// Bytes consumed so far (for progress reporting).
    #[must_use]
    pub fn byte_position(&self) -> u64 {
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

    fn field(&self, line: u64, i: usize) -> Result<f64, TelemetryError> {
        let raw = self.record.get(i).unwrap_or("").trim();
        let v: f64 = raw.parse().map_err(|_| TelemetryError::Parse {
            file: self.file.clone(),
            line,
            column: self.headers[i].clone(),
            value: raw.to_string(),
            hint: "",
        })?;
        if !v.is_finite() {
            return Err(TelemetryError::NonFinite {
                file: self.file.clone(),
                line,
                column: self.headers[i].clone(),
                value: v,
            });
        }
        Ok(v)
    }

    /// `v`, read from column `i`, when it lies in the supported range of `quantity`.
    fn in_range(
        &self,
        line: u64,
        i: usize,
        quantity: Quantity,
        v: f64,
    ) -> Result<f64, TelemetryError> {
        check_value(quantity, v).map_err(|_| {
            let (limit, unit) = quantity.limit();
            TelemetryError::OutOfRange {
                file: self.file.clone(),
                line,
                column: self.headers[i].clone(),
                value: v,
                limit,
                unit,
            }
        })?;
        Ok(v)
    }

    /// Three columns of `kind` (`Quantity::Rho`, …), each within the supported range.
    fn vec3(
        &self,
        line: u64,
        i: &[usize; 3],
        kind: fn(usize) -> Quantity,
    ) -> Result<Vector3<f64>, TelemetryError> {
        let mut v = Vector3::zeros();
        for (axis, &col) in i.iter().enumerate() {
            v[axis] = self.in_range(line, col, kind(axis), self.field(line, col)?)?;
        }
        Ok(v)
    }

    /// The names of the quaternion columns, comma-separated (for messages).
    #[must_use]
    pub fn quaternion_columns(&self) -> String {
        self.idx.q.map(|i| self.headers[i].clone()).join(",")
    }

    /// The time column: seconds, or an ISO-8601/RFC 3339 time stamp converted to seconds
    /// since the first row's.
    fn time(&mut self, line: u64) -> Result<f64, TelemetryError> {
        let i = self.idx.t;
        let raw = self.record.get(i).unwrap_or("").trim();
        if self.time_origin.is_none() {
            if let Ok(v) = raw.parse::<f64>() {
                return if v.is_finite() {
                    Ok(v)
                } else {
                    Err(TelemetryError::NonFinite {
                        file: self.file.clone(),
                        line,
                        column: self.headers[i].clone(),
                        value: v,
                    })
                };
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
        if self.prev.is_some() && self.time_origin.is_none() {
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
        let t = self.time(line)?;
        let t = self.in_range(line, self.idx.t, Quantity::Time, t)?;
        let c = [
            self.field(line, self.idx.q[0])?,
            self.field(line, self.idx.q[1])?,
            self.field(line, self.idx.q[2])?,
            self.field(line, self.idx.q[3])?,
        ];
        let raw = match self.options.quaternion {
            QuaternionFormat::HamiltonScalarLast => Quaternion::from_xyzw(c),
            QuaternionFormat::HamiltonScalarFirst => Quaternion::from_wxyz(c),
            QuaternionFormat::Jpl => Quaternion::from_jpl_xyzw(c),
            QuaternionFormat::Conjugate => Quaternion::from_hamilton_inertial_to_body_xyzw(c),
        };
        let norm = raw.norm();
        if (norm - 1.0).abs() > self.options.unit_tolerance {
            return Err(TelemetryError::NonUnitQuaternion {
                file: self.file.clone(),
                line,
                columns: self.quaternion_columns(),
                norm,
                tolerance: self.options.unit_tolerance,
            });
        }
        let mut q = raw;
        if norm != 1.0 {
            if let Some(n) = raw.normalize() {
                if (norm - 1.0).abs() > 1e-12 {
                    self.stats.renormalised += 1;
                }
                q = n;
            }
        }
        let rho = self.vec3(line, &self.idx.rho, Quantity::Rho)?;
        let tau = match self.idx.tau {
            Some(i) => self.vec3(line, &i, Quantity::Tau)?,
            None => Vector3::zeros(),
        };
        let w = match self.idx.w {
            Some(i) => Some(match self.options.gyro_unit {
                GyroUnit::RadPerS => self.vec3(line, &i, Quantity::Rate)?,
                GyroUnit::DegPerS => {
                    self.vec3(line, &i, Quantity::Rate)? * (core::f64::consts::PI / 180.0)
                }
            }),
            None => None,
        };
        if let Some(prev) = self.prev {
            let dt = t - prev.t_s;
            if !(dt > 0.0) {
                return Err(TelemetryError::NonIncreasingTime {
                    file: self.file.clone(),
                    line,
                    column: self.headers[self.idx.t].clone(),
                    t,
                    previous: prev.t_s,
                });
            }
            if let Some(tol) = self.options.period_tolerance {
                match self.period {
                    None => self.period = Some(dt),
                    Some(p) => {
                        if (dt - p).abs() > tol * p {
                            return Err(TelemetryError::NonUniformPeriod {
                                file: self.file.clone(),
                                line,
                                column: self.headers[self.idx.t].clone(),
                                dt,
                                period: p,
                                tolerance: tol,
                            });
                        }
                    }
                }
            }
            self.stats.step(dt, &prev.q, &q);
        }
        Ok(Sample {
            t_s: t,
            q,
            rho_nms: if self.options.negate_rho { -rho } else { rho },
            tau_nm: tau,
            omega_rad_s: w,
        })
    }
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
        match &item {
            Ok(s) => {
                self.stats.rows += 1;
                self.prev = Some(*s);
            }
            Err(_) => {
                self.stats.rejected += 1;
                self.failed = true;
            }
        }
        Some(item)
    }
}

#[cfg(test)]
mod tests;

/// Write samples as CSV in the default format (scalar-last Hamilton quaternion; the gyro
/// columns `w_*` only when every sample has a rate). Used by the simulator's command-line
/// front end and by tests.
pub fn write_samples<W: std::io::Write>(out: W, samples: &[Sample]) -> std::io::Result<()> {
    write_samples_with(out, samples, [], |_| [])
}

/// [`write_samples`] with `N` extra columns named `names`, valued `extra(sample)`. Streams:
/// one row at a time.
pub fn write_samples_with<W: std::io::Write, const N: usize>(
    out: W,
    samples: &[Sample],
    names: [&str; N],
    extra: impl Fn(&Sample) -> [f64; N],
) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    let with_rates = samples.iter().all(|s| s.omega_rad_s.is_some());
    let header = [
        "t", "q_x", "q_y", "q_z", "q_w", "rho_x", "rho_y", "rho_z", "tau_x", "tau_y", "tau_z",
        "w_x", "w_y", "w_z",
    ];
    let n = if with_rates { 14 } else { 11 };
    w.write_record(header[..n].iter().chain(&names))?;
    for s in samples {
        let rate = s.omega_rad_s.unwrap_or_default();
        let v = [
            s.t_s,
            s.q.v.x,
            s.q.v.y,
            s.q.v.z,
            s.q.s,
            s.rho_nms.x,
            s.rho_nms.y,
            s.rho_nms.z,
            s.tau_nm.x,
            s.tau_nm.y,
            s.tau_nm.z,
            rate.x,
            rate.y,
            rate.z,
        ];
        w.write_record(v[..n].iter().chain(&extra(s)).map(|x| format!("{x:?}")))?;
    }
    w.flush()
}
