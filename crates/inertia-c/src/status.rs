//! Statuses and error messages: what every entry point returns, the message of the last
//! error (a thread-local buffer, [`crate::message`]), the fixes of a library error named as
//! a C caller applies them, and panics caught at the boundary.

use crate::message::{self, record};
use core::ffi::c_char;
use core::panic::AssertUnwindSafe;
use inertia::estimator::EstimatorError;
use inertia::fix::{Fix, Fixes};
use inertia::pipeline::PipelineError;

/// What a function did: `INERTIA_STATUS_OK`, or why not.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaStatus {
    /// Success.
    Ok = 0,
    /// A required pointer was null.
    NullPointer = 1,
    /// A number given was NaN or infinite.
    NotFinite = 2,
    /// A sample value is outside the supported range (README "Supported range"),
    /// including a quaternion whose norm differs from 1 by more than 1e-3.
    OutOfRange = 3,
    /// A setting is invalid, or does not apply to the chosen estimator.
    InvalidSetting = 4,
    /// The storage given to `inertia_estimator_init` is too small or misaligned.
    BadStorage = 5,
    /// The chosen estimator or setting cannot run in caller storage: use
    /// `inertia_estimator_new`.
    NeedsHeap = 6,
    /// The data were refused: time not increasing, a step too large, an attitude glitch,
    /// a quaternion convention that disagrees with the gyro, missing gyro rates. After this
    /// code from `inertia_estimator_push` (except for a time that does not increase, which
    /// changes nothing) the estimator is stopped until `inertia_estimator_reset`.
    Data = 7,
    /// The solver failed on the data; the estimator is stopped until reset.
    Solver = 8,
    /// The estimator stopped on an earlier error: reset it.
    Stopped = 9,
    /// An internal error (a bug) was caught; the estimator is stopped until reset.
    Panic = 10,
}

/// An error: the status and its message, recorded for `inertia_last_error_message`.
pub(crate) fn fail(status: InertiaStatus, msg: core::fmt::Arguments<'_>) -> InertiaStatus {
    record(msg);
    status
}

pub(crate) fn status_of(e: &PipelineError) -> InertiaStatus {
    match e {
        PipelineError::Estimator {
            source: EstimatorError::Solve(_),
            ..
        } => InertiaStatus::Solver,
        PipelineError::Estimator {
            source: EstimatorError::InvalidSetting { .. },
            ..
        }
        | PipelineError::UnknownEstimator { .. }
        | PipelineError::UnknownSolver { .. }
        | PipelineError::SolverUnavailable { .. }
        | PipelineError::InvalidSetting { .. }
        | PipelineError::NotApplicable { .. }
        | PipelineError::NeedsSetting { .. }
        | PipelineError::NoBatch { .. }
        | PipelineError::Constraints(_) => InertiaStatus::InvalidSetting,
        PipelineError::OutOfRange { .. } => InertiaStatus::OutOfRange,
        _ => InertiaStatus::Data,
    }
}

/// Record a library error. `Estimator` errors are written here rather than by their
/// `Display`, which formats the sample index into a `String`.
pub(crate) fn pipeline_fail(e: &PipelineError) -> InertiaStatus {
    match e {
        PipelineError::Estimator {
            sample: Some(s),
            source,
        } => fail(status_of(e), format_args!("input sample {s}: {source}")),
        PipelineError::Estimator {
            sample: None,
            source,
        } => fail(status_of(e), format_args!("{source}")),
        other => fail(
            status_of(e),
            format_args!("{other}{}", fixes(other.fixes())),
        ),
    }
}

/// How a C caller applies a fix ([`inertia::fix`]): what to change before pushing, or
/// the `InertiaSettings` field.
fn c_names(fix: Fix) -> Option<&'static str> {
    Some(match fix {
        Fix::Jpl => "conjugate q before pushing (JPL to Hamilton)",
        Fix::ScalarFirst => "q is [w, x, y, z]: push [x, y, z, w]",
        Fix::ScalarLast => "q is already [x, y, z, w]: push it unchanged",
        Fix::NegateRho => "negate rho_nms (and tau_nm) before pushing",
        Fix::KeepGlitches => "glitches = 1 (keep)",
        Fix::Memory => "memory_s",
        Fix::Resample => "resample_s",
        Fix::GyroNoise => "gyro_noise_deg_s_rthz",
        _ => return None,
    })
}

/// The fixes after a message, as a C caller applies them.
pub(crate) fn fixes(fixes: &'static [Fix]) -> Fixes<'static> {
    Fixes {
        fixes,
        names: c_names,
        label: "in C",
    }
}

/// Run `f` with panics caught: a panic becomes `INERTIA_STATUS_PANIC` with its message.
pub(crate) fn guard(f: impl FnOnce() -> InertiaStatus) -> InertiaStatus {
    guard_or(InertiaStatus::Panic, f)
}

/// Run `f` with panics caught: a panic records its message and gives `on_panic`.
pub(crate) fn guard_or<T>(on_panic: T, f: impl FnOnce() -> T) -> T {
    match std::panic::catch_unwind(AssertUnwindSafe(f)) {
        Ok(s) => s,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .copied()
                .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
                .unwrap_or("(no message)");
            record(format_args!("internal error (a bug in inertia): {what}"));
            on_panic
        }
    }
}
pub(crate) fn null(what: &str) -> InertiaStatus {
    fail(InertiaStatus::NullPointer, format_args!("{what}"))
}

/// Copy the message of the last error on this thread into `buf` (`len` bytes, always
/// NUL-terminated when `len > 0`, cut at a character boundary). Returns the length of the
/// whole message without the NUL (0 when there was no error), like `snprintf`: a return
/// value `>= len` means it was cut.
///
/// # Safety
/// `buf` is NULL or valid for writes of `len` bytes.
#[no_mangle]
pub unsafe extern "C" fn inertia_last_error_message(buf: *mut c_char, len: usize) -> usize {
    // SAFETY: forwarded contract.
    guard_or(0, || unsafe { message::last_to(buf, len) })
}

/// The name of a status code (a static string, e.g. `"INERTIA_STATUS_DATA"`;
/// `"INERTIA_STATUS_UNKNOWN"` for a value that is none).
#[no_mangle]
pub extern "C" fn inertia_status_name(status: i32) -> *const c_char {
    use InertiaStatus as S;
    let all = [
        S::Ok,
        S::NullPointer,
        S::NotFinite,
        S::OutOfRange,
        S::InvalidSetting,
        S::BadStorage,
        S::NeedsHeap,
        S::Data,
        S::Solver,
        S::Stopped,
        S::Panic,
    ];
    let Some(status) = all.into_iter().find(|s| *s as i32 == status) else {
        return c"INERTIA_STATUS_UNKNOWN".as_ptr();
    };
    let s: &'static core::ffi::CStr = match status {
        InertiaStatus::Ok => c"INERTIA_STATUS_OK",
        InertiaStatus::NullPointer => c"INERTIA_STATUS_NULL_POINTER",
        InertiaStatus::NotFinite => c"INERTIA_STATUS_NOT_FINITE",
        InertiaStatus::OutOfRange => c"INERTIA_STATUS_OUT_OF_RANGE",
        InertiaStatus::InvalidSetting => c"INERTIA_STATUS_INVALID_SETTING",
        InertiaStatus::BadStorage => c"INERTIA_STATUS_BAD_STORAGE",
        InertiaStatus::NeedsHeap => c"INERTIA_STATUS_NEEDS_HEAP",
        InertiaStatus::Data => c"INERTIA_STATUS_DATA",
        InertiaStatus::Solver => c"INERTIA_STATUS_SOLVER",
        InertiaStatus::Stopped => c"INERTIA_STATUS_STOPPED",
        InertiaStatus::Panic => c"INERTIA_STATUS_PANIC",
    };
    s.as_ptr()
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::fmt::Write as _;

    #[test]
    fn a_panic_becomes_a_status_and_a_message() {
        let status = guard(|| panic!("boom {}", 42));
        assert_eq!(status, InertiaStatus::Panic);
        let mut buf = [0u8; 128];
        // SAFETY: `buf` is writable for its length.
        let n = unsafe { inertia_last_error_message(buf.as_mut_ptr().cast(), buf.len()) };
        let text = core::str::from_utf8(&buf[..n]).unwrap();
        assert_eq!(text, "internal error (a bug in inertia): boom 42");
        assert_eq!(guard_or(7usize, || panic!("again")), 7);
    }

    #[test]
    fn messages_are_cut_at_character_boundaries() {
        let mut m = message::Buffer::new();
        let long = "é".repeat(message::CAPACITY); // 2 bytes each
        write!(m, "{long}").unwrap();
        let mut out = [0xFFu8; 6];
        // SAFETY: `out` is writable for its length.
        let n = unsafe { m.copy_to(out.as_mut_ptr().cast(), out.len()) };
        assert_eq!(n, 2 * message::CAPACITY);
        // 5 bytes of room: two whole "é" and the NUL.
        assert_eq!(&out[..5], "éé\0".as_bytes());
        let mut empty = [0xFFu8; 1];
        // SAFETY: as above.
        unsafe { m.copy_to(empty.as_mut_ptr().cast(), 1) };
        assert_eq!(empty[0], 0);
    }
}
