//! Statuses and error messages: what every entry point returns, the message of the last
//! error (a thread-local buffer, [`crate::message`]), the fixes of a library error named as
//! a C caller applies them, and panics caught at the boundary.

use crate::message::{self, record};
use core::ffi::c_char;
use core::panic::AssertUnwindSafe;
use inertia::error_kind::ErrorKind;
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
        // A setting that is NaN or infinite, as the library's check finds it.
        PipelineError::InvalidSetting { value, .. } if !value.is_finite() => {
            InertiaStatus::NotFinite
        }
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
    let status = pipeline_message(e);
    let sample = match e {
        PipelineError::Estimator { sample, .. } => sample.map(|s| s as u64),
        _ => None,
    };
    message::set_kind(Some(e.error_kind()), sample);
    status
}

fn pipeline_message(e: &PipelineError) -> InertiaStatus {
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
        Fix::GyroDegrees => "multiply w_rad_s by pi/180 before pushing (the rates are in deg/s)",
        Fix::GyroRadians => "the rates are already rad/s: do not convert them",
        Fix::Conjugate => "conjugate q before pushing (inertial to body)",
        Fix::InertialTorqueOn => "inertial_torque = 1 (on)",
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

/// The kind of the last error (`inertia_last_error_kind`): the same kinds, with the same
/// names, as the command line's JSON error (`"kind"`) and Python's `DataError.kind`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertiaErrorKind {
    /// No error, or one of no particular kind (a NULL pointer, a bad setting field).
    None = 0,
    /// A value is NaN or infinite.
    NotFinite = 1,
    /// A value is outside the supported range.
    OutOfRange = 2,
    /// The quaternion's norm differs from 1 by more than 1e-3.
    NonUnitQuaternion = 3,
    /// Time does not increase.
    TimeNotIncreasing = 4,
    /// Gyro rates given for some samples and not for others.
    GyroChanged = 5,
    /// The estimator needs gyro rates.
    NeedsGyro = 6,
    /// A memory shorter than the sample period.
    MemoryShorterThanStep = 7,
    /// A setting is invalid or does not apply.
    InvalidSetting = 8,
    /// The data show the rotor momentum with the opposite sign.
    ReversedMomentum = 9,
    /// The quaternion convention disagrees with the gyro.
    AttitudeConvention = 10,
    /// The attitude jumps against the gyro.
    AttitudeGlitch = 11,
    /// A step or row the estimator cannot use.
    Row = 12,
    /// The solver failed.
    Solver = 13,
    /// An earlier error stopped the estimator.
    Stopped = 14,
    /// A kind this version of the header does not name.
    Other = 15,
}

/// The C kinds, the library's, and their names (checked against the library's in tests).
const KINDS: [(InertiaErrorKind, Option<ErrorKind>, &core::ffi::CStr); 16] = {
    use ErrorKind as L;
    use InertiaErrorKind as C;
    [
        (C::None, None, c"none"),
        (C::NotFinite, Some(L::NotFinite), c"not_finite"),
        (C::OutOfRange, Some(L::OutOfRange), c"out_of_range"),
        (
            C::NonUnitQuaternion,
            Some(L::NonUnitQuaternion),
            c"non_unit_quaternion",
        ),
        (
            C::TimeNotIncreasing,
            Some(L::TimeNotIncreasing),
            c"time_not_increasing",
        ),
        (C::GyroChanged, Some(L::GyroChanged), c"gyro_changed"),
        (C::NeedsGyro, Some(L::NeedsGyro), c"needs_gyro"),
        (
            C::MemoryShorterThanStep,
            Some(L::MemoryShorterThanStep),
            c"memory_shorter_than_step",
        ),
        (
            C::InvalidSetting,
            Some(L::InvalidSetting),
            c"invalid_setting",
        ),
        (
            C::ReversedMomentum,
            Some(L::ReversedMomentum),
            c"reversed_momentum",
        ),
        (
            C::AttitudeConvention,
            Some(L::AttitudeConvention),
            c"attitude_convention",
        ),
        (
            C::AttitudeGlitch,
            Some(L::AttitudeGlitch),
            c"attitude_glitch",
        ),
        (C::Row, Some(L::Row), c"row"),
        (C::Solver, Some(L::Solver), c"solver"),
        (C::Stopped, Some(L::Stopped), c"stopped"),
        (C::Other, None, c"other"),
    ]
};

/// The kind of the last error on this thread (`INERTIA_ERROR_KIND_NONE` when there was
/// none, or it has no particular kind).
#[no_mangle]
pub extern "C" fn inertia_last_error_kind() -> InertiaErrorKind {
    match message::last_kind().0 {
        None => InertiaErrorKind::None,
        Some(k) => KINDS
            .iter()
            .find(|(_, l, _)| *l == Some(k))
            .map_or(InertiaErrorKind::Other, |(c, _, _)| *c),
    }
}

/// The 0-based index of the sample the last error on this thread is about (counted since
/// creation or the last reset), or -1 when it is about no one sample.
#[no_mangle]
pub extern "C" fn inertia_last_error_sample() -> i64 {
    message::last_kind()
        .1
        .and_then(|s| i64::try_from(s).ok())
        .unwrap_or(-1)
}

/// The name of an error kind (a static string, e.g. `"time_not_increasing"`, the name the
/// command line and Python give it; `"other"` for a value that is none).
#[no_mangle]
pub extern "C" fn inertia_error_kind_name(kind: i32) -> *const c_char {
    KINDS
        .iter()
        .find(|(c, _, _)| *c as i32 == kind)
        .map_or(c"other", |(_, _, n)| n)
        .as_ptr()
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::fmt::Write as _;

    #[test]
    fn the_kinds_are_named_as_the_library_names_them() {
        for (k, (c, l, name)) in KINDS.iter().enumerate() {
            assert_eq!(*c as usize, k);
            if let Some(l) = l {
                assert_eq!(name.to_str().unwrap(), l.name());
            }
        }
    }

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
