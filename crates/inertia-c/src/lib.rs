//! C API of the `inertia` estimator, for flight software.
//!
//! The header `include/inertia.h` is generated from this crate by cbindgen
//! (`tests/header.rs` regenerates it and fails when the checked-in copy differs).
//!
//! # Two ways to hold an estimator
//!
//! * **On the heap**: [`inertia_estimator_new`] / [`inertia_estimator_free`]. Every
//!   estimator of the library, through [`inertia::pipeline::Pipeline`] (the default,
//!   `discrete-momentum`, among them). Creation and the first pushes allocate (the
//!   discrete momentum estimator builds its candidates from the first samples);
//!   `tests/no_alloc.rs` requires that no push after the first 100 samples of a slew
//!   does, a measurement rather than a guarantee for every input.
//! * **In caller storage**: [`inertia_estimator_size`], [`inertia_estimator_align`],
//!   [`inertia_estimator_init`]. The `variational` and `finite-difference` estimators
//!   with the native solver, in fixed-size state. Neither `init`, nor a push, nor reading
//!   the estimate, nor `reset` allocates: `tests/no_alloc.rs` counts every allocation over
//!   whole simulated runs and requires zero.
//!
//! # Errors
//!
//! Every function returns an [`InertiaStatus`]; none panics across the boundary (each
//! entry point runs under `catch_unwind`; a caught panic is [`InertiaStatus::Panic`]) and
//! none aborts. Null pointers and non-finite numbers are refused with their own codes. The
//! message of the last error on the calling thread is copied out by
//! [`inertia_last_error_message`] (a fixed thread-local buffer: recording it does not
//! allocate).

#![allow(clippy::missing_safety_doc)] // each `unsafe extern fn` documents its contract

// In the order of the header's declarations (cbindgen follows the modules; the blank
// lines keep rustfmt from sorting them).
mod settings;

mod estimator;

mod estimate;

mod status;

mod engine;
mod message;

pub use estimate::{InertiaEstimate, InertiaEstimateStatus, InertiaReason};
pub use estimator::*;
pub use settings::*;
pub use status::*;
