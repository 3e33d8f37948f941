//! What a user can change to get past an error or a refusal, as a value rather than as
//! the words of one front end.
//!
//! The library's messages describe a fix in words ("read them as JPL", "negate the rotor
//! momentum") and never name a command-line flag, a keyword argument or a C field; the
//! errors and statuses that have one carry it as [`Fix`]es
//! ([`crate::pipeline::PipelineError::fixes`], [`Unobservable::fixes`]). Each front end
//! renders them in its own vocabulary after the message with [`Fixes`]: the CLI as its
//! options (`--jpl`), Python as keyword arguments (`jpl=True`), C as what the caller changes
//! before pushing. Without a front end's names, `Fix::setting` names the library's own
//! setting.
//!
//! [`Unobservable::fixes`]: crate::estimator::observability::Unobservable::fixes

// The crate-internal helpers here serve the std front ends (pipeline, CSV reader).
#![cfg_attr(not(feature = "std"), allow(dead_code))]

use core::fmt;

/// One change of the settings or of the input that a message recommends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Fix {
    /// Read the quaternions as JPL/Shuster (conjugated: inertial → body).
    Jpl,
    /// Read the quaternion columns scalar first (`[w, x, y, z]`).
    ScalarFirst,
    /// Read the quaternion columns scalar last (`[x, y, z, w]`, the default): the
    /// scalar-first reading was asked for a scalar-last file.
    ScalarLast,
    /// Negate the rotor momentum ρ (and the known torque τ) as read.
    NegateRho,
    /// Estimate across attitude glitches rather than stop at the first.
    KeepGlitches,
    /// Forget old data with a memory time constant (an inertia that changes), or one
    /// that spans several samples.
    Memory,
    /// A resampling period of at most [`crate::pipeline::MAX_RESAMPLE_FACTOR`] samples
    /// per input step.
    Resample,
    /// The stated gyro rate-noise density (deg/s/√Hz).
    GyroNoise,
    /// The prior's standard deviation.
    PriorSigma,
    /// The sign convention of the prior's products of inertia.
    Products,
    /// Read the gyro rates as deg/s (they are 180/π times the attitude's rates).
    GyroDegrees,
    /// Read the gyro rates as rad/s (they are π/180 times the attitude's rates).
    GyroRadians,
    /// Read the quaternions conjugated: Hamilton, inertial → body.
    Conjugate,
    /// Estimate a disturbance torque fixed in the inertial frame, per chain.
    InertialTorqueOn,
    /// Estimate over all samples at once (batch).
    Batch,
}

impl Fix {
    /// The library's own name for the setting it changes (the settings' field, or the
    /// CSV options' field), for messages read without a front end.
    #[must_use]
    pub(crate) const fn setting(self) -> &'static str {
        match self {
            Fix::Jpl => "format = jpl",
            Fix::ScalarFirst => "format = scalar-first",
            Fix::ScalarLast => "format = scalar-last",
            Fix::NegateRho => "negate_rho = true",
            Fix::KeepGlitches => "glitches = keep",
            Fix::Memory => "memory_s",
            Fix::Resample => "resample_s",
            Fix::GyroNoise => "gyro_noise_deg_s_rthz",
            Fix::PriorSigma => "prior sigma",
            Fix::Products => "products of inertia convention",
            Fix::GyroDegrees => "gyro_unit = deg/s",
            Fix::GyroRadians => "gyro_unit = rad/s",
            Fix::Conjugate => "format = conjugate",
            Fix::InertialTorqueOn => "inertial_torque = on",
            Fix::Batch => "batch = true",
        }
    }
}

/// How a front end names a fix: `None` where it has no such setting (then the library's
/// [`Fix::setting`] is shown).
pub(crate) type FixNames = fn(Fix) -> Option<&'static str>;

/// The library's names ([`Fix::setting`]).
#[must_use]
#[cfg_attr(not(feature = "serde"), allow(dead_code))] // used by the report
pub(crate) fn library_names(fix: Fix) -> Option<&'static str> {
    Some(fix.setting())
}

/// ` (label: a, b)` after a message, or nothing without fixes.
#[derive(Clone, Copy)]
pub struct Fixes<'a> {
    /// The fixes, in the order the message gives them.
    pub fixes: &'a [Fix],
    /// How this front end calls them.
    pub names: FixNames,
    /// What they are in this front end (`option`, `keyword`).
    pub label: &'static str,
}

impl fmt::Display for Fixes<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, fix) in self.fixes.iter().enumerate() {
            let name = (self.names)(*fix).unwrap_or(fix.setting());
            if k == 0 {
                write!(f, " ({}: {name}", self.label)?;
            } else {
                write!(f, ", {name}")?;
            }
        }
        if !self.fixes.is_empty() {
            f.write_str(")")?;
        }
        Ok(())
    }
}
