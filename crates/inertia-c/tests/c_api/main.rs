//! The C API's contract and engine tests, one binary. `header` and `no_alloc` stay
//! binaries of their own (`no_alloc` counts allocations process-wide).

mod common;

mod api;
mod bad_inputs;
mod engines;
mod outside;
