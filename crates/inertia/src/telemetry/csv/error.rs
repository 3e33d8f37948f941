//! What is wrong with a telemetry file, where: the reader's errors, each naming the file,
//! the line and the column.

use super::super::gate::{Field, SampleError};
use crate::error_kind::ErrorKind;
use crate::text::{Clipped, Quoted};

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
    /// A line is longer than `MAX_LINE_BYTES` (1 MiB) (found before it is read whole).
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
    /// The file has the `rho_*` columns and the rotors' speed columns: the rotor momentum
    /// would be given twice.
    #[error("{file}:1: column `{}` holds the rotor momentum, which the spacecraft file's rotor speeds give: remove one of them (or rename the column)", Clipped::new(.column))]
    MomentumTwice {
        /// File name.
        file: String,
        /// The `rho_*` column present.
        column: String,
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
    /// A value the sample gate refused ([`crate::telemetry::gate`]).
    #[error("{file}:{line}: {} `{}`: {source}", noun(.source), Clipped::new(.column))]
    Sample {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// The column (the quaternion's columns, comma-separated, for its norm).
        column: String,
        /// What is wrong.
        source: SampleError,
    },
}

/// `column`, or `columns` for the quaternion's norm.
fn noun(e: &SampleError) -> &'static str {
    if e.field() == Field::QuaternionNorm {
        "columns"
    } else {
        "column"
    }
}

impl TelemetryError {
    /// The 1-based line of the problem, when it is tied to one.
    #[must_use]
    pub fn line(&self) -> Option<u64> {
        match self {
            TelemetryError::Io { .. } => None,
            TelemetryError::MissingColumn { .. }
            | TelemetryError::DuplicateColumn { .. }
            | TelemetryError::MomentumTwice { .. } => Some(1),
            TelemetryError::LineTooLong { line, .. }
            | TelemetryError::Malformed { line, .. }
            | TelemetryError::Parse { line, .. }
            | TelemetryError::Sample { line, .. } => Some(*line),
        }
    }

    /// Its kind, as every front end reports it.
    #[must_use]
    pub fn error_kind(&self) -> ErrorKind {
        match self {
            TelemetryError::Io { .. } => ErrorKind::Io,
            TelemetryError::DuplicateColumn { .. }
            | TelemetryError::MissingColumn { .. }
            | TelemetryError::MomentumTwice { .. } => ErrorKind::Columns,
            TelemetryError::LineTooLong { .. }
            | TelemetryError::Malformed { .. }
            | TelemetryError::Parse { .. } => ErrorKind::Unparsable,
            TelemetryError::Sample { source, .. } => source.error_kind(),
        }
    }
}
