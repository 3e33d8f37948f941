//! Samples from arrays (or a DataFrame's columns), checked by the library's sample gate
//! (`inertia::telemetry::gate`), the one the CSV reader and the C API use: finite values in
//! the supported range, the quaternion convention applied, quaternions within the unit
//! tolerance renormalised (and counted), sign flips counted, time increasing, gyro rates
//! and each outside measurement (`r`, `b`, `f`, `dipole`) all-or-none, and the period
//! uniform in strict mode. Here are only the names: the row (0-based) and the argument or
//! column in place of the file's line and column.

use crate::errors::Failure;
use crate::settings::Convention;
use inertia::sample::Sample;
use inertia::telemetry::gate::{
    ExternalKind, Field, Gate, GateOptions, RawExternal, RawSample, SampleError,
};
/// One row of raw values, in storage order.
#[derive(Debug, Clone, Copy)]
pub struct Row {
    pub t: f64,
    pub q: [f64; 4],
    pub rho: [f64; 3],
    pub tau: Option<[f64; 3]>,
    pub w: Option<[f64; 3]>,
    /// The outside measurements `r`, `b`, `f`, `dipole` (checked by the gate).
    pub external: RawExternal,
}

/// How values are named in messages.
#[derive(Debug, Clone)]
pub enum Naming {
    /// Arguments `t`, `q`, `rho`, `tau`, `w`, `r`, `b`, `f`, `dipole`: `q[12, 3]`.
    Arrays,
    /// A table's columns ([`FRAME_COLUMNS`] of them), in the order t, q (4), rho, tau, w,
    /// r, b, f, dipole (3 each): `row 12: column `q_w``.
    Frame(Vec<String>),
}

/// Argument names and the offset of their first column in [`Naming::Frame`].
const GROUPS: [(&str, usize); 9] = [
    ("t", 0),
    ("q", 1),
    ("rho", 5),
    ("tau", 8),
    ("w", 11),
    ("r", 14),
    ("b", 17),
    ("f", 20),
    ("dipole", 23),
];

/// How many columns [`Naming::Frame`] names.
pub const FRAME_COLUMNS: usize = 26;

/// The outside measurements' arguments, in [`RawExternal`]'s order (position, field,
/// force, dipole).
pub const EXTERNAL_ARGUMENTS: [&str; 4] = ["r", "b", "f", "dipole"];

/// The group ([`GROUPS`] index) of an outside measurement.
fn external_group(what: ExternalKind) -> usize {
    match what {
        ExternalKind::Position => 5,
        ExternalKind::Field => 6,
        ExternalKind::Force => 7,
        ExternalKind::Dipole => 8,
    }
}

impl Naming {
    /// Where a value is: group `g` (index into [`GROUPS`]), component `k`, row `i`.
    pub fn value(&self, g: usize, k: Option<usize>, i: usize) -> String {
        let (arg, off) = GROUPS[g];
        match (self, k) {
            (Naming::Arrays, Some(k)) => format!("{arg}[{i}, {k}]"),
            (Naming::Arrays, None) => format!("{arg}[{i}]"),
            (Naming::Frame(c), k) => format!("row {i}: column `{}`", c[off + k.unwrap_or(0)]),
        }
    }

    /// Where the quaternion of row `i` is.
    pub fn quaternion(&self, i: usize) -> String {
        match self {
            Naming::Arrays => format!("q[{i}]"),
            Naming::Frame(c) => format!("row {i}: columns `{}`", c[1..5].join(",")),
        }
    }

    /// The quaternion columns, for the estimator's messages (as the CLI names them).
    pub fn quaternion_columns(&self) -> String {
        match self {
            Naming::Arrays => "q".into(),
            Naming::Frame(c) => c[1..5].join(","),
        }
    }

    /// Where sample `i` is, for the estimator's messages.
    pub fn sample(&self, i: usize) -> String {
        match self {
            Naming::Arrays => format!("sample {i}:"),
            Naming::Frame(_) => format!("row {i}:"),
        }
    }
}

/// What the gate counts: the CSV reader's counts, for arrays too.
pub type Stats = inertia::telemetry::csv::ReadStats;

impl Naming {
    /// Where `field` of row `i` is.
    pub fn field(&self, field: Field, i: usize) -> String {
        match field {
            Field::Time => self.value(0, None, i),
            Field::Quaternion(k) => self.value(1, Some(k), i),
            Field::QuaternionNorm => self.quaternion(i),
            Field::Rho(k) => self.value(2, Some(k), i),
            Field::Tau(k) => self.value(3, Some(k), i),
            Field::Rate(k) => self.value(4, Some(k), i),
            Field::Position(k) => self.value(5, Some(k), i),
            Field::MagneticField(k) => self.value(6, Some(k), i),
            Field::Force(k) => self.value(7, Some(k), i),
            Field::Dipole(k) => self.value(8, Some(k), i),
        }
    }
}

/// The library's sample gate over one sequence of rows.
#[derive(Debug, Clone)]
pub struct Checker {
    gate: Gate,
}

impl Checker {
    /// A gate reading rows with the convention `c`.
    pub fn new(c: &Convention) -> Self {
        Self {
            gate: Gate::new(GateOptions {
                quaternion: c.format,
                unit_tolerance: c.unit_tolerance,
                period_tolerance: c.period_tolerance,
                negate_rho: c.negate_rho,
                gyro_unit: c.gyro_unit,
                attitude_from_gyro: c.attitude_from_gyro,
            }),
        }
    }

    /// Counts so far.
    pub fn stats(&self) -> Stats {
        self.gate.stats()
    }

    /// Row `i` as a sample, or the gate's refusal placed at the row and argument.
    pub fn sample(&mut self, row: &Row, i: usize, naming: &Naming) -> Result<Sample, Failure> {
        let raw = RawSample {
            t_s: row.t,
            q: row.q,
            rho_nms: row.rho,
            tau_nm: row.tau,
            w_rad_s: row.w,
            external: row.external,
        };
        self.gate.check(&raw).map_err(|e| Failure::Data {
            message: match e {
                // The rates as a whole, not one axis.
                SampleError::GyroChanged { .. } => format!("{}: {e}", naming.value(4, None, i)),
                // A measurement as a whole: given for some rows only, a dipole without the
                // field, positions without quaternions.
                SampleError::ExternalChanged { what, .. } => {
                    format!("{}: {e}", naming.value(external_group(what), None, i))
                }
                SampleError::DipoleWithoutField => format!("{}: {e}", naming.value(8, None, i)),
                SampleError::PositionWithoutAttitude => {
                    format!("{}: {e}", naming.value(5, None, i))
                }
                _ => format!("{}: {e}", naming.field(e.field(), i)),
            },
            line: None,
            kind: Some(e.error_kind()),
            sample: Some(i),
        })
    }
}
