//! The warnings a report carries beside its answer: each with its JSON `kind` and the
//! text report's line.

use super::super::status::{PhysicalMargin, PHYSICAL_Z};
use crate::estimator::consistency::{Worst, INCONSISTENT_RATIO, SHIFT_Z};
use crate::text::Num;
use core::fmt;
use std::string::String;

/// One warning of a report.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Warning {
    /// The answer breaks `J1 > 0` or `J1 + J2 ≥ J3` ([`crate::pipeline::status`]): by less than
    /// [`PHYSICAL_Z`] σ when the answer is determined, otherwise it makes no claim.
    NotPhysical(PhysicalMargin),
    /// A span's residuals exceed [`INCONSISTENT_RATIO`] times the rest's, but the answer
    /// did not move by [`SHIFT_Z`] σ with or without it, so it is kept.
    SpanStandsOut(Worst, bool),
    /// The attitude and the gyro rates disagree and no reading of the quaternions fits
    /// (median relative mismatch of the body rates).
    AttitudeGyroDisagree(f64),
    /// What the excitation report advises.
    Excitation(String),
    /// The wheel-speed time tag was to be estimated and could not be: the speeds were
    /// read as time-tagged.
    WheelDelayNotEstimated(crate::estimator::wheel_delay::DelayError),
    /// The wheel speeds change only every this many samples (held between updates of this
    /// period, s), and no time tag was asked for ([`crate::telemetry::held_speeds`]);
    /// `true` where the answer's σ carries the move their mean lag makes.
    HeldWheelSpeeds(usize, f64, bool),
    /// The rotors' consider term could not be computed: σ was widened as if every rotor
    /// shared this relative σ (the file's, root sum square).
    RotorInertiaNotComputed(crate::estimator::rotor_inertia::RotorInertiaError, f64),
    /// A rotor calibration asked for and not made, and why; `true` where the rotors' time
    /// tags were calibrated alone (they need no total momentum).
    RotorCalibrationNotMade(crate::estimator::rotor_calibration::NotMade, bool),
    /// A gyro axis reads its range limit while the attitude turns faster
    /// ([`crate::telemetry::gyro_range`]).
    GyroAtRangeLimit(crate::telemetry::gyro_range::ClippedAxis),
}

/// A `Warning` as the JSON report carries it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct WarningEntry {
    /// `not_physical`, `span_stands_out`, `attitude_gyro_disagree` or `excitation`.
    pub kind: &'static str,
    /// The text report's line.
    pub message: String,
}

impl Warning {
    /// Its JSON `kind`.
    #[must_use]
    pub(crate) fn kind(&self) -> &'static str {
        match self {
            Warning::NotPhysical(_) => "not_physical",
            Warning::SpanStandsOut(..) => "span_stands_out",
            Warning::AttitudeGyroDisagree(_) => "attitude_gyro_disagree",
            Warning::Excitation(_) => "excitation",
            Warning::WheelDelayNotEstimated(_) => "wheel_delay_not_estimated",
            Warning::HeldWheelSpeeds(..) => "held_wheel_speeds",
            Warning::RotorInertiaNotComputed(..) => "rotor_inertia_not_computed",
            Warning::RotorCalibrationNotMade(..) => "rotor_calibration_not_made",
            Warning::GyroAtRangeLimit(_) => "gyro_at_range_limit",
        }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::NotPhysical(p) => {
                write!(
                    f,
                    "the answer breaks J1 > 0 or J1 + J2 ≥ J3 (J1 = {}, J1 + J2 − J3 = {} kg m²)",
                    Num(p.min_moment_kg_m2),
                    Num(p.triangle_kg_m2)
                )?;
                match p.z {
                    Some(z) if z <= PHYSICAL_Z => write!(
                        f,
                        ", by {z:.1} σ: within {PHYSICAL_Z} σ of a physical inertia, so consistent with one at this accuracy"
                    ),
                    _ => f.write_str(
                        ": not a physical inertia, and with no σ nothing says the data support it",
                    ),
                }
            }
            Warning::SpanStandsOut(w, with_sigma) => {
                write!(
                    f,
                    "the residuals between t = {:.1} s and {:.1} s are {} the rest's variance, beyond {INCONSISTENT_RATIO}",
                    w.t_start_s,
                    w.t_end_s,
                    crate::text::Times(w.ratio)
                )?;
                if *with_sigma {
                    write!(f, ", but the answer moves by less than {SHIFT_Z} σ with or without that span: kept (honest residuals of unequal size)")
                } else {
                    f.write_str(": without a σ nothing tells whether that span moved the answer")
                }
            }
            Warning::AttitudeGyroDisagree(m) => write!(
                f,
                "the attitude and the gyro rates disagree (median relative mismatch of the body rates {m:.2}) and no reading of the quaternions or the rates fits: different frames, time tags or units"
            ),
            Warning::Excitation(a) => f.write_str(a),
            Warning::WheelDelayNotEstimated(e) => {
                write!(f, "{e}; the wheel speeds are read as time-tagged")
            }
            Warning::HeldWheelSpeeds(every, period_s, in_sigma) => write!(
                f,
                "the wheel speeds change only every {every} samples (held for {} s between \
                 updates): read at their time stamps they lag by about {} s on average, which \
                 biases J{}; the wheel-speed time tag (wheel_delay: estimate) corrects it",
                Num(*period_s),
                Num(crate::telemetry::held_speeds::mean_lag_s(
                    *every,
                    period_s / *every as f64
                )),
                if *in_sigma {
                    " (σ carries the move of J for that lag)"
                } else {
                    ""
                }
            ),
            Warning::RotorInertiaNotComputed(e, r) => write!(
                f,
                "{e}; σ is widened as if every rotor shared the file's relative σ (root sum square), {}",
                Num(*r)
            ),
            Warning::RotorCalibrationNotMade(why, false) => write!(f, "{why}"),
            Warning::RotorCalibrationNotMade(why, true) => why.write(
                f,
                "the rotors' errors other than their time tags were not calibrated with J (the \
                 time tags, which need no total momentum, were, alone)",
            ),
            Warning::GyroAtRangeLimit(c) => write!(
                f,
                "the gyro's {} axis reads its largest rate, {} rad/s, in {} samples while the \
                 attitude turns faster about it (up to {} rad/s): the gyro is at its range \
                 limit there, and an estimator that uses its rates sees the wrong motion; \
                 drop those spans or estimate without the gyro's rates",
                ["x", "y", "z"][c.axis.min(2)],
                Num(c.limit_rad_s),
                c.samples,
                Num(c.attitude_rate_rad_s)
            ),
        }
    }
}
