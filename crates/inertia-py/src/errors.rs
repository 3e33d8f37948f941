//! Python exceptions. Messages are the command line's, word for word: a data error
//! names the file, line and column (`f.csv:9: columns `q_x,q_y,q_z,q_w`: …`) or, for
//! arrays, the argument and row (`q[9]: …`).

use inertia::error_kind::ErrorKind;
use pyo3::create_exception;
use pyo3::exceptions::{PyOSError, PyTypeError, PyValueError};
use pyo3::prelude::*;

create_exception!(
    inertia,
    DataError,
    PyValueError,
    "Bad input data: the message names the file, line and column (or the argument and \
     row) as `inertia estimate` does; `.line` holds the 1-based line of a file when there \
     is one (else None), `.kind` the error's kind (e.g. 'time_not_increasing', as the CLI's \
     JSON error and C's inertia_last_error_kind name it) and `.sample` the 0-based index \
     of the sample at fault (else None)."
);

pub fn value_error(m: impl Into<String>) -> PyErr {
    PyValueError::new_err(m.into())
}

pub fn type_error(m: impl Into<String>) -> PyErr {
    PyTypeError::new_err(m.into())
}

/// A data error, with the line of the file it names (if any) as `.line`, its kind
/// (`inertia::error_kind::ErrorKind`'s name, or None) as `.kind` and the 0-based index of the
/// sample at fault (or None) as `.sample`.
pub fn data_error(
    py: Python<'_>,
    message: String,
    line: Option<u64>,
    kind: Option<ErrorKind>,
    sample: Option<usize>,
) -> PyErr {
    let e = DataError::new_err(message);
    // Setting an attribute on a fresh exception object does not fail in practice; if
    // it did, the message still names the line.
    let v = e.value(py);
    let _ = v.setattr("line", line);
    let _ = v.setattr("kind", kind.map(ErrorKind::name));
    let _ = v.setattr("sample", sample);
    e
}

/// An input that cannot be read (the command line's exit code 3).
pub fn io_error(m: String) -> PyErr {
    PyOSError::new_err(m)
}

/// A failure of a run, before it becomes a Python exception (built without the GIL).
#[derive(Debug)]
pub enum Failure {
    /// Bad data, with the file's line, the kind and the sample's index when known.
    Data {
        message: String,
        line: Option<u64>,
        kind: Option<ErrorKind>,
        sample: Option<usize>,
    },
    /// A bad argument (`ValueError`).
    Argument(String),
    /// A setting the data refuse (`ValueError` with `.kind` and `.sample`, as
    /// [`data_error`]).
    Refused {
        message: String,
        kind: ErrorKind,
        sample: Option<usize>,
    },
    /// An input that cannot be read.
    Io(String),
}

impl Failure {
    pub fn into_py(self, py: Python<'_>) -> PyErr {
        match self {
            Failure::Data {
                message,
                line,
                kind,
                sample,
            } => data_error(py, message, line, kind, sample),
            Failure::Argument(m) => value_error(m),
            Failure::Refused {
                message,
                kind,
                sample,
            } => {
                let e = value_error(message);
                let v = e.value(py);
                let _ = v.setattr("kind", kind.name());
                let _ = v.setattr("sample", sample);
                e
            }
            Failure::Io(m) => io_error(m),
        }
    }
}
