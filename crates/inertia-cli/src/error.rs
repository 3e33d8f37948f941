//! Errors with exit codes: 2 for bad usage or bad data, 1 for internal failures.

use std::fmt;

/// A failure of the command.
#[derive(Debug)]
pub enum CliError {
    /// Bad arguments or bad input data (exit code 2).
    Input(String),
    /// Something went wrong inside (exit code 1).
    Internal(String),
}

impl CliError {
    /// The process exit code.
    pub fn code(&self) -> u8 {
        match self {
            CliError::Input(_) => 2,
            CliError::Internal(_) => 1,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Input(m) | CliError::Internal(m) => f.write_str(m),
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
pub fn write_failed(path: &std::path::Path, e: impl fmt::Display) -> CliError {
    CliError::Internal(format!("cannot write {}: {e}", path.display()))
}
