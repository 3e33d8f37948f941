//! Reading telemetry from files.
//!
//! With the `csv` feature, [`csv::TelemetryReader`] streams [`crate::sample::Sample`]s
//! from a CSV file with validation that names the file, line and column of every problem.

pub mod convention;
#[cfg(feature = "csv")]
pub mod csv;
pub mod gate;
pub mod glitch;
pub(crate) mod gyro_range;
pub(crate) mod held_speeds;
#[cfg(feature = "csv")]
mod line_cap;
#[cfg(feature = "csv")]
pub mod read_ahead;
#[cfg(feature = "csv")]
pub(crate) mod time_stamp;
