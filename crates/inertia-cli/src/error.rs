//! Errors with exit codes: 2 for bad usage or bad data, 3 for I/O failures, 1 for
//! internal failures (a bug: nothing in a user's data or arguments leads there).

use inertia::error_kind::ErrorKind;
use inertia::telemetry::csv::TelemetryError;
use inertia::text::Clipped;
use std::fmt;
use std::path::Path;

/// The longest message printed, characters (longer ones are cut with an ellipsis).
pub const MAX_MESSAGE_CHARS: usize = 1000;

/// A failure of the command.
#[derive(Debug)]
pub enum CliError {
    /// Bad arguments or bad input data (exit code 2).
    Input(String),
    /// Data the library refused (exit code 2), with the refusal's kind, the 0-based index
    /// of the sample at fault and its line: `estimate --json` prints them as JSON.
    Refused {
        /// The message.
        message: String,
        /// Its kind.
        kind: ErrorKind,
        /// The sample at fault.
        sample: Option<usize>,
        /// Its line in the file.
        line: Option<u64>,
    },
    /// A file or stream could not be read or written (exit code 3).
    Io(String),
    /// Something went wrong inside (exit code 1).
    Internal(String),
}

impl CliError {
    /// The process exit code.
    pub fn code(&self) -> u8 {
        match self {
            CliError::Input(_) | CliError::Refused { .. } => 2,
            CliError::Io(_) => 3,
            CliError::Internal(_) => 1,
        }
    }
}

impl fmt::Display for CliError {
    /// One line of at most [`MAX_MESSAGE_CHARS`] characters.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Input(m)
            | CliError::Io(m)
            | CliError::Internal(m)
            | CliError::Refused { message: m, .. } => {
                write!(f, "{}", Clipped::with_limit(m, MAX_MESSAGE_CHARS))
            }
        }
    }
}

/// `CliError::Input` from anything displayable.
pub fn input(e: impl fmt::Display) -> CliError {
    CliError::Input(e.to_string())
}

/// `CliError::Internal` from anything displayable.
pub fn internal(e: impl fmt::Display) -> CliError {
    CliError::Internal(e.to_string())
}

/// An I/O failure writing `path`.
pub fn write_failed(path: &Path, e: impl fmt::Display) -> CliError {
    CliError::Io(format!("cannot write {}: {e}", path.display()))
}

/// An I/O failure reading `path`.
pub fn read_failed(path: &Path, e: impl fmt::Display) -> CliError {
    CliError::Io(format!("cannot read {}: {e}", path.display()))
}

/// A telemetry error: I/O failures are [`CliError::Io`], the rest bad input.
pub fn telemetry(e: TelemetryError) -> CliError {
    telemetry_at(e, None)
}

/// A telemetry error at input sample `sample` (0-based).
pub fn telemetry_at(e: TelemetryError, sample: Option<usize>) -> CliError {
    match e {
        TelemetryError::Io { .. } => CliError::Io(e.to_string()),
        other => CliError::Refused {
            kind: other.error_kind(),
            line: other.line(),
            sample: sample.filter(|_| other.line() != Some(1)),
            message: other.to_string(),
        },
    }
}

impl CliError {
    /// The JSON error `estimate --json` prints on standard output:
    /// `{"error": {"kind", "sample", "line", "message"}}` (`kind` is the library's
    /// [`ErrorKind::name`], `null` for an error of no kind).
    pub fn json(&self) -> serde_json::Value {
        let (kind, sample, line) = match self {
            CliError::Refused {
                kind, sample, line, ..
            } => (Some(kind.name()), *sample, *line),
            _ => (None, None, None),
        };
        serde_json::json!({
            "error": {
                "kind": kind,
                "sample": sample,
                "line": line,
                "message": self.to_string(),
            }
        })
    }
}
