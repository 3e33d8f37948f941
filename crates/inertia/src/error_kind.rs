//! What kind of refusal an error is, as one value that every front end reports the same
//! way: the CLI in its JSON error (`"kind"`), Python as `DataError.kind`, C as
//! `inertia_last_error_kind()`. The names ([`ErrorKind::name`]) are stable, snake case.
//!
//! The typed errors map onto it: [`crate::telemetry::gate::SampleError::error_kind`],
//! [`crate::pipeline::RunError::error_kind`] and, with the `csv` feature,
//! `telemetry::csv::TelemetryError::error_kind`.

use core::fmt;

macro_rules! kinds {
    ($($(#[$doc:meta])* $v:ident = $name:literal,)*) => {
        /// The kind of an error or refusal.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        #[non_exhaustive]
        pub enum ErrorKind {
            $($(#[$doc])* $v,)*
        }

        impl ErrorKind {
            /// Every kind, in declaration order.
            pub(crate) const ALL: &'static [ErrorKind] = &[$(ErrorKind::$v,)*];

            /// The stable snake-case name.
            #[must_use]
            pub const fn name(self) -> &'static str {
                match self {
                    $(ErrorKind::$v => $name,)*
                }
            }
        }
    };
}

kinds! {
    /// A value is NaN or infinite.
    NotFinite = "not_finite",
    /// A value is outside the supported range.
    OutOfRange = "out_of_range",
    /// A quaternion's norm differs from 1 by more than the tolerance.
    NonUnitQuaternion = "non_unit_quaternion",
    /// Time does not increase (a repeated time included).
    TimeNotIncreasing = "time_not_increasing",
    /// In strict mode, a step differs from the sample period.
    NonUniformPeriod = "non_uniform_period",
    /// Gyro rates given for some samples and not for others.
    GyroChanged = "gyro_changed",
    /// The estimator needs gyro rates and the input has none.
    NeedsGyro = "needs_gyro",
    /// A required column is missing, or given twice.
    Columns = "columns",
    /// A field is not a number, or the file's structure is broken.
    Unparsable = "unparsable",
    /// The input ended before one estimate.
    TooFewSamples = "too_few_samples",
    /// A memory shorter than the sample period.
    MemoryShorterThanStep = "memory_shorter_than_step",
    /// A setting is invalid or does not apply.
    InvalidSetting = "invalid_setting",
    /// The data show the rotor momentum with the opposite sign.
    ReversedMomentum = "reversed_momentum",
    /// The quaternion convention disagrees with the gyro.
    AttitudeConvention = "attitude_convention",
    /// The attitude jumps against the gyro.
    AttitudeGlitch = "attitude_glitch",
    /// A step or a row the estimator cannot use (e.g. a rotation too large for the rows).
    Row = "row",
    /// The solver failed on the data.
    Solver = "solver",
    /// An earlier error stopped the run.
    Stopped = "stopped",
    /// The input could not be read.
    Io = "io",
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl core::str::FromStr for ErrorKind {
    type Err = ();

    fn from_str(s: &str) -> Result<Self, ()> {
        Self::ALL.iter().copied().find(|k| k.name() == s).ok_or(())
    }
}
