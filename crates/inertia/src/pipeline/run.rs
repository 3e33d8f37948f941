//! The run every front end shares: the policy between the samples a front end has read
//! and the [`Pipeline`] (or the batch estimate, eq. 57), so that the command line, Python
//! and C refuse the same data with the same typed error ([`RunError`]).
//!
//! ```text
//! samples ─▶ Run::push ─▶ [time order, gyro columns, memory and resampling against the
//!                          first step] ─▶ Pipeline::push_each (streaming) or kept (batch)
//!          Run::finish ─▶ [batch estimate] ─▶ at least the estimator's minimum samples
//! ```
//!
//! * A sample's index is its 0-based position in the input; a front end maps it to its
//!   file line or array row. An error is tied to the sample that caused it: for a step too
//!   large for the rows, the sample that ends the step, among the last [`RECENT`].
//! * A sample refused before it reaches the estimator (time order, gyro columns, a memory
//!   shorter than the step) leaves the run as it was; after an error of the pipeline or the
//!   estimator the run is stopped, and every later push is refused
//!   ([`RunErrorKind::Stopped`]).
//! * The messages describe the fix in words; [`RunError::fixes`] carries it typed, for each
//!   front end to name in its own vocabulary ([`crate::fix`]).
//! * Several records of one spacecraft (passes, throws) go into one batch run with
//!   [`Run::next_record`] between them: one J, each record its own time axis, initial
//!   momenta and torques.

mod consider;
mod error;
mod records;
#[cfg(all(feature = "serde", feature = "csv"))]
mod report;
mod rotors;

pub use crate::estimator::rotor_calibration::MIN_MOMENTUM_SIGNIFICANCE;
pub use error::{RunError, RunErrorKind};

use super::{batch_with, BatchOutput, Pipeline, PipelineConfig, PipelineError};
use crate::estimator::rotor_calibration::RotorCalibration;
use crate::estimator::rotor_inertia::{RotorInertiaConsider, RotorInertiaError};
use crate::estimator::wheel_delay::{self, DelayError, DelayFit, WheelDelay};
use crate::estimator::Estimate;
use crate::sample::Sample;
use crate::spacecraft::Spacecraft;
use crate::telemetry::gate::Order;
use crate::telemetry::gyro_range::GyroRange;
use crate::telemetry::held_speeds::HeldSpeeds;
use std::collections::VecDeque;
use std::vec::Vec;

/// How many recent samples a run keeps to find the sample that ends a step.
pub const RECENT: usize = 8;

/// A setting that the first step `dt` (s) of the data shows to be meaningless: a memory
/// shorter than the sample period (`resample_s` where resampling, else `dt`). Resampling
/// to more than [`super::MAX_RESAMPLE_FACTOR`] samples per step the pipeline refuses at every
/// step. For engines that hold no [`Run`] (the C API's caller storage).
pub fn check_first_step(
    memory_s: Option<f64>,
    resample_s: Option<f64>,
    dt: f64,
) -> Result<(), RunErrorKind> {
    if let Some(m) = memory_s {
        let step = resample_s.unwrap_or(dt);
        if m < step {
            return Err(RunErrorKind::MemoryShorterThanStep {
                memory_s: m,
                step_s: step,
            });
        }
    }
    Ok(())
}

/// The input sample a pipeline error belongs to: for a step too large for the rows, the
/// sample among `(time, index)` that ends the step; else `index`, the sample pushed.
fn locate(
    e: &PipelineError,
    index: usize,
    mut samples: impl Iterator<Item = (f64, usize)>,
) -> usize {
    e.step_end_s()
        .and_then(|end| samples.find(|(t, _)| PipelineError::ends_step(*t, end)))
        .map_or(index, |(_, i)| i)
}

/// Most samples a streaming run keeps for the held speeds' lag term (about 14 MB); a
/// longer record gets none (its warning does not say that σ carries it).
const KEEP_MAX: usize = 1 << 16;

enum Mode {
    Streaming(std::boxed::Box<Pipeline>),
    Batch {
        samples: Vec<Sample>,
        out: Option<std::boxed::Box<BatchOutput>>,
    },
}

/// One run over a sequence of samples, streaming or batch.
pub struct Run {
    config: PipelineConfig,
    mode: Mode,
    /// Input samples accepted.
    input: usize,
    first_t_s: [f64; 2],
    /// Time order and gyro rates all-or-none, as the sample gate checks them.
    order: Order,
    /// `(time, index)` of the last [`RECENT`] samples.
    recent: VecDeque<(f64, usize)>,
    stopped: Option<std::string::String>,
    /// Streaming with a wheel-speed time tag to apply: the samples, kept until
    /// [`Self::finish`] reads the speeds `δ` later ([`crate::estimator::wheel_delay`]).
    held: Option<Vec<Sample>>,
    /// The time tag applied at [`Self::finish`], or why it could not be estimated.
    delay: Option<Result<DelayFit, DelayError>>,
    /// Whether the wheel speeds look held between updates ([`HeldSpeeds`]).
    speeds: HeldSpeeds,
    /// Streaming without a time tag: the samples so far, at most [`KEEP_MAX`] (dropped
    /// beyond), for the held speeds' lag term at [`Self::finish`].
    kept: Option<Vec<Sample>>,
    /// Whether a gyro axis stops at a range limit the attitude exceeds ([`GyroRange`]).
    gyro_range: GyroRange,
    /// The spacecraft file's rotors, whose speeds give each sample's rotor momentum.
    rotors: Option<Spacecraft>,
    /// Their stored speeds, one per rotor and sample (kept only where a rotor's spin
    /// inertia has a σ, for its consider term at [`Self::finish`]).
    rotor_speeds: Vec<f64>,
    /// The rotors' consider term, once computed, or why it could not be.
    rotor_consider: Option<Result<RotorInertiaConsider, RotorInertiaError>>,
    /// The relative σ that widened σ where the rotors' consider term could not be
    /// computed.
    rotor_fallback_sigma: f64,
    /// The rotor parameters estimated, once the batch estimate is made.
    calibration: Option<RotorCalibration>,
    /// A calibration asked for and not made, and why: the rotors' σ is then their
    /// consider term.
    calibration_not_made: Option<crate::estimator::rotor_calibration::NotMade>,
    /// The rotors' time tags to calibrate alone, and their speeds, where the rest could
    /// not be (`rotors::tags_alone`).
    tags_alone: Option<(Spacecraft, Vec<f64>)>,
    /// Several records ([`Self::next_record`]).
    records: records::Records,
    /// Whether any sample carried a known torque (for the torque scale's term).
    known_torque: bool,
    /// The known torque's scale term of the residual dipole and the centre of mass, once
    /// computed (`torque_scale_term`): added to their σ in the report.
    outside_scale_move: Option<[[f64; 3]; 2]>,
}

impl core::fmt::Debug for Run {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Run")
            .field("config", &self.config)
            .field("input", &self.input)
            .field("stopped", &self.stopped)
            .finish_non_exhaustive()
    }
}

impl Run {
    /// A run of `config`'s estimator: streaming, or over all samples at once (`batch`,
    /// which the estimator must have, without memory or resampling).
    pub fn new(config: PipelineConfig, batch: bool) -> Result<Self, PipelineError> {
        if config.calibrate_rotors && !batch {
            return Err(PipelineError::NeedsSetting {
                setting: "calibrate_rotors",
                needs: "batch",
                requirement: "(one solve over the whole record)",
                why: "the rotors' parameters are unknowns of the whole record's rows, reduced at once",
            });
        }
        let mode = if batch {
            super::batch_applies(&config)?;
            Mode::Batch {
                samples: Vec::new(),
                out: None,
            }
        } else {
            Mode::Streaming(std::boxed::Box::new(Pipeline::from_config(
                config.with_delay_applied(),
            )?))
        };
        Ok(Self {
            config,
            mode,
            input: 0,
            first_t_s: [f64::NAN; 2],
            order: Order::default(),
            recent: VecDeque::with_capacity(RECENT),
            stopped: None,
            held: (!batch && config.wheel_delay != WheelDelay::Off).then(Vec::new),
            // With a memory the answer forgets what the record's terms would count. With a
            // time tag the held samples are kept, for the known torque's scale.
            kept: (!batch
                && config.memory_s.is_none()
                && (config.wheel_delay == WheelDelay::Off || config.torque_scale_sigma.is_some()))
            .then(Vec::new),
            delay: None,
            speeds: HeldSpeeds::default(),
            gyro_range: GyroRange::default(),
            rotors: None,
            rotor_speeds: Vec::new(),
            rotor_consider: None,
            rotor_fallback_sigma: 0.0,
            calibration: None,
            calibration_not_made: None,
            tags_alone: None,
            records: records::Records::default(),
            known_torque: false,
            outside_scale_move: None,
        })
    }

    /// This run with a spacecraft file's rotors ([`crate::spacecraft`]): every sample's
    /// rotor momentum is computed from its rotors' speeds ([`Self::push_with_speeds`]),
    /// and where a rotor's spin inertia, axis or time tag has a σ the run keeps the
    /// samples until [`Self::finish`], which measures their consider term by running the
    /// estimator once more per error source (one for shared spin-inertia errors or one per
    /// rotor for independent ones, two per tilted axis, one per time tag), plus once
    /// (`crate::estimator::rotor_inertia`), and widens σ by it.
    #[must_use]
    pub fn with_spacecraft(mut self, spacecraft: Spacecraft) -> Self {
        if spacecraft.has_inertia_sigma() && matches!(self.mode, Mode::Streaming(_)) {
            self.held.get_or_insert_with(Vec::new);
        }
        self.config.rotor_inertia_relative_sigma = spacecraft.stated_relative_sigma();
        self.rotors = Some(spacecraft);
        self
    }

    /// [`Self::push`] for a run with a spacecraft file's rotors: `speeds` are the sample's
    /// rotor speeds in the file's order and stored units, and the sample's `rho_nms` is
    /// replaced by the momentum they give. Without rotors, `speeds` must be empty.
    pub fn push_with_speeds(
        &mut self,
        s: &Sample,
        speeds: &[f64],
        on_estimate: impl FnMut(&Estimate),
    ) -> Result<(), RunError> {
        self.push_with_actuators(s, speeds, &[], on_estimate)
    }

    /// [`Self::push_with_speeds`] with the spacecraft file's thrusters' throttles too
    /// (in the file's order; [`crate::spacecraft::thrusters`]): their torque about the
    /// origin joins the sample's known torque and their force is its force (the input
    /// must then give none of its own).
    pub fn push_with_actuators(
        &mut self,
        s: &Sample,
        speeds: &[f64],
        throttles: &[f64],
        on_estimate: impl FnMut(&Estimate),
    ) -> Result<(), RunError> {
        let index = self.input;
        let thrusters = self.rotors.as_ref().map_or(&[][..], |r| &r.thrusters[..]);
        if throttles.len() != thrusters.len() {
            return Err(RunError::at(
                index,
                RunErrorKind::Throttles {
                    expected: thrusters.len(),
                    got: throttles.len(),
                    names: thrusters
                        .iter()
                        .map(|t| t.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                },
            ));
        }
        if !thrusters.is_empty() && s.external.force_n.is_some() {
            return Err(RunError::at(index, RunErrorKind::ForceTwice));
        }
        let expected = self.rotors.as_ref().map_or(0, |r| r.rotors.len());
        let with_speeds = expected > 0;
        if speeds.len() != expected {
            let names = self
                .rotors
                .as_ref()
                .map_or_else(std::string::String::new, |r| {
                    r.rotors
                        .iter()
                        .map(|x| x.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                });
            return Err(RunError::at(
                index,
                RunErrorKind::RotorSpeeds {
                    expected,
                    got: speeds.len(),
                    names,
                },
            ));
        }
        let Some(rotors) = &self.rotors else {
            return self.push_sample(s, on_estimate);
        };
        let mut sample = *s;
        if !rotors.thrusters.is_empty() {
            let (force, torque) =
                crate::spacecraft::thrusters::force_and_torque(&rotors.thrusters, throttles);
            sample.tau_nm += torque;
            sample.external.force_n = Some(force);
        }
        if !with_speeds {
            return self.push_sample(&sample, on_estimate);
        }
        sample.rho_nms = rotors.momentum_nms(speeds);
        // The speeds' momentum only: another value out of range (a thruster torque) is the
        // sample gate's to name, in `push_sample`.
        let rho_only = Sample {
            tau_nm: nalgebra::Vector3::zeros(),
            external: Default::default(),
            ..sample
        };
        if let Err(e) = crate::sample::check_range(&rho_only) {
            return Err(RunError::at(
                index,
                RunErrorKind::RotorMomentumOutOfRange {
                    value_nms: e.value,
                    limit_nms: e.quantity.limit().0,
                    columns: rotors.speed_columns().join(","),
                },
            ));
        }
        let keep = rotors.has_inertia_sigma();
        let before = self.input;
        let r = self.push_sample(&sample, on_estimate);
        if keep && self.input > before {
            self.rotor_speeds.extend_from_slice(speeds);
        }
        r
    }

    /// Where the input's columns are known before its samples (a file's header): refuse
    /// at once an input without the gyro rates the estimator needs.
    pub fn check_columns(&self, has_gyro: bool) -> Result<(), RunError> {
        let entry = self.config.estimator();
        if entry.capabilities.needs_gyro && !has_gyro {
            return Err(RunError {
                sample: None,
                kind: RunErrorKind::NeedsGyro {
                    estimator: entry.name,
                },
            });
        }
        Ok(())
    }

    /// Feed input sample [`Self::input_samples`]; `on_estimate` receives every estimate it
    /// produced, in time order (none in batch mode, nor while the run holds the samples
    /// for a wheel-speed time tag, before [`Self::finish`], which then gives them all).
    /// With a spacecraft file's rotors, [`Self::push_with_speeds`] it is.
    pub fn push(&mut self, s: &Sample, on_estimate: impl FnMut(&Estimate)) -> Result<(), RunError> {
        if self.rotors.is_some() {
            return self.push_with_speeds(s, &[], on_estimate);
        }
        self.push_sample(s, on_estimate)
    }

    fn push_sample(
        &mut self,
        s: &Sample,
        on_estimate: impl FnMut(&Estimate),
    ) -> Result<(), RunError> {
        let index = self.input;
        if let Some(m) = &self.stopped {
            return Err(RunError::at(index, RunErrorKind::Stopped(m.clone())));
        }
        let r = self.accept(index, s, on_estimate);
        // A sample refused before it reached the estimator leaves the run as it was; one
        // the pipeline stopped on ends it.
        if let Err(
            e @ RunError {
                kind: RunErrorKind::Pipeline(_),
                ..
            },
        ) = &r
        {
            self.stopped = Some(std::string::ToString::to_string(e));
        }
        r
    }

    fn accept(
        &mut self,
        index: usize,
        input: &Sample,
        on_estimate: impl FnMut(&Estimate),
    ) -> Result<(), RunError> {
        let shifted = self.records.shifted(input);
        let s = &shifted;
        let has_w = s.omega_rad_s.is_some();
        if index == 0 {
            self.check_columns(has_w).map_err(|e| RunError {
                sample: Some(index),
                ..e
            })?;
            self.check_calibration(index)?;
        }
        self.order
            .check(s.t_s, has_w)
            .map_err(|e| RunError::at(index, RunErrorKind::Sample(e)))?;
        if index < 2 {
            self.first_t_s[index] = s.t_s;
        }
        if index == 1 {
            check_first_step(
                self.config.memory_s(),
                self.config.resample_s(),
                self.first_t_s[1] - self.first_t_s[0],
            )
            .map_err(|kind| RunError::at(index, kind))?;
        }
        self.order.accept(s.t_s, has_w);
        self.records.accepted(s, input.t_s);
        if self.recent.len() == RECENT {
            self.recent.pop_front();
        }
        self.recent.push_back((s.t_s, index));
        self.input += 1;
        self.speeds.push(&s.rho_nms);
        self.known_torque |= s.tau_nm.iter().any(|&x| x != 0.0);
        self.gyro_range.push(s);
        if let Some(held) = &mut self.held {
            held.push(*s);
            return Ok(());
        }
        if let Some(kept) = &mut self.kept {
            if kept.len() < KEEP_MAX {
                kept.push(*s);
            } else {
                self.kept = None;
            }
        }
        match &mut self.mode {
            Mode::Batch { samples, .. } => {
                samples.push(*s);
                Ok(())
            }
            Mode::Streaming(p) => p.push_each(s, on_estimate).map_err(|e| {
                let at = locate(&e, index, self.recent.iter().copied());
                RunError::at(at, RunErrorKind::Pipeline(e))
            }),
        }
    }

    /// End of input: the batch estimate (batch mode; `on_estimate` receives it), and an
    /// error where the input was too short for one estimate.
    pub fn finish(&mut self, mut on_estimate: impl FnMut(&Estimate)) -> Result<(), RunError> {
        if let Some(m) = &self.stopped {
            return Err(RunError {
                sample: None,
                kind: RunErrorKind::Stopped(m.clone()),
            });
        }
        let entry = self.config.estimator();
        let too_few = |got: usize, read: usize| RunError {
            sample: None,
            kind: RunErrorKind::TooFewSamples {
                estimator: entry.name,
                need: entry.capabilities.min_samples(),
                got,
                read,
            },
        };
        if let Some(mut held) = self.held.take() {
            self.apply_delay(&mut held);
            self.apply_rotor_consider(&held);
            let Mode::Streaming(p) = &mut self.mode else {
                unreachable!("only a streaming run holds its samples")
            };
            **p =
                Pipeline::from_config(self.config.with_delay_applied()).map_err(|e| RunError {
                    sample: None,
                    kind: RunErrorKind::Pipeline(e),
                })?;
            for (index, s) in held.iter().enumerate() {
                if let Err(e) = p.push_each(s, &mut on_estimate) {
                    let times = held[..=index].iter().map(|s| s.t_s).zip(0..);
                    let at = locate(&e, index, times);
                    let e = RunError::at(at, RunErrorKind::Pipeline(e));
                    self.stopped = Some(std::string::ToString::to_string(&e));
                    return Err(e);
                }
            }
            // Held for the rotors' consider term, read as time-tagged: the samples the
            // held speeds' lag term needs.
            if self.kept.is_some() {
                self.kept = Some(held);
            }
        }
        if let Mode::Batch { samples, out: None } = &mut self.mode {
            if self.config.wheel_delay != WheelDelay::Off && self.delay.is_none() {
                let mut taken = core::mem::take(samples);
                self.apply_delay(&mut taken);
                if let Mode::Batch { samples, .. } = &mut self.mode {
                    *samples = taken;
                }
            }
        }
        // Speeds held between updates and read at their time stamps: the batch answer's σ
        // carries the move their mean lag makes (`wheel_delay::held_lag_move`), and with a
        // σ of the known torque's scale, the move that scale makes (`torque_scale`); a
        // streaming run's last answer below.
        if let Mode::Batch { samples, out: None } = &self.mode {
            if let Some(c) = self.held_lag_term(samples) {
                self.config.wheel_delay_consider = Some(c);
            }
            let scale = self.torque_scale_term(samples);
            self.config.torque_scale_consider = scale.map(|s| s.0);
            self.outside_scale_move = scale.map(|s| s.1);
        }
        if let Mode::Batch { samples, out: None } = &mut self.mode {
            if self.config.calibrate_rotors {
                self.check_calibration(0)
                    .map_err(|e| RunError { sample: None, ..e })?;
            } else if self.rotor_consider.is_none() {
                let taken = samples.clone();
                self.apply_rotor_consider(&taken);
            }
        }
        // A solve every N samples: the last rows after the last solve are answered too.
        if let Mode::Streaming(p) = &mut self.mode {
            p.flush(&mut on_estimate).map_err(|e| RunError {
                sample: None,
                kind: RunErrorKind::Pipeline(e),
            })?;
        }
        self.widen_streaming_last(&mut on_estimate);
        match &mut self.mode {
            Mode::Streaming(p) => match p.last() {
                Some(_) => Ok(()),
                None => Err(too_few(p.estimator_samples(), self.input)),
            },
            Mode::Batch { samples, out } => {
                if out.is_some() {
                    return Ok(());
                }
                if samples.len() < entry.capabilities.min_samples() {
                    return Err(too_few(samples.len(), samples.len()));
                }
                if let Some(e) = self.records.empty_last() {
                    return Err(e);
                }
                let config = self.config.with_delay_applied();
                let delay_s = match &self.delay {
                    Some(Ok(d)) => d.delay_s,
                    _ => 0.0,
                };
                let o = match self.rotors.as_ref().filter(|_| config.calibrate_rotors) {
                    Some(sc) => {
                        match rotors::calibrated_batch(
                            samples,
                            &config,
                            sc,
                            &self.rotor_speeds,
                            delay_s,
                        ) {
                            Ok(rotors::Calibrated::Done(o, c)) => {
                                self.calibration = Some(c);
                                Ok(*o)
                            }
                            Ok(rotors::Calibrated::NotMade(why)) => {
                                // The rotors' consider term instead, as without the option
                                // (but for time tags that can be calibrated alone).
                                self.calibration_not_made = Some(why);
                                self.config.calibrate_rotors = false;
                                self.tags_alone = rotors::tags_alone(why, sc, &self.rotor_speeds);
                                return self.finish(on_estimate);
                            }
                            Err(e) => Err(e),
                        }
                    }
                    None => rotors::batch_with_tags(
                        samples,
                        &config,
                        self.tags_alone.take(),
                        delay_s,
                        &self.records.starts,
                        &mut self.calibration,
                        &mut self.rotor_consider,
                    ),
                }
                .map_err(|e| {
                    let sample = match &e {
                        PipelineError::Estimator {
                            source: crate::estimator::EstimatorError::Row { sample, .. },
                            ..
                        }
                        | PipelineError::AttitudeGlitch { sample, .. } => Some(*sample),
                        _ => None,
                    };
                    RunError {
                        sample,
                        kind: RunErrorKind::Pipeline(e),
                    }
                })?;
                let mut o = o;
                // Of several records, the answer's time is the last record's own.
                o.estimate.t_s -= self.records.offset_s();
                on_estimate(&o.estimate);
                *out = Some(std::boxed::Box::new(o));
                Ok(())
            }
        }
    }

    /// Find or take the wheel-speed time tag and read the speeds of `samples` that much
    /// later; its consider term goes into the configuration ([`super::status`]). A tag
    /// that cannot be estimated is left at zero, and the reason kept
    /// ([`Self::wheel_delay`]).
    fn apply_delay(&mut self, samples: &mut [Sample]) {
        let fit = match self.config.wheel_delay {
            WheelDelay::Off => return,
            WheelDelay::KnownS(d) => Ok(DelayFit::known(d)),
            WheelDelay::Estimate => wheel_delay::estimate(samples, &self.config.outside),
        };
        if let Ok(f) = &fit {
            wheel_delay::shift_rho(samples, f.delay_s);
            self.config.wheel_delay_consider = Some(f.consider_kg_m2());
        }
        self.delay = Some(fit);
    }

    /// The rotors' spin-inertia consider term (`None` without a spacecraft file whose
    /// rotors have a σ, or before [`Self::finish`]), or why it could not be computed.
    #[must_use]
    pub fn rotor_inertia(&self) -> Option<&Result<RotorInertiaConsider, RotorInertiaError>> {
        self.rotor_consider.as_ref()
    }

    /// The wheel-speed time tag applied (`None` without one asked, or before
    /// [`Self::finish`]), or why it could not be estimated.
    #[must_use]
    pub fn wheel_delay(&self) -> Option<&Result<DelayFit, DelayError>> {
        self.delay.as_ref()
    }

    /// The update period of the wheel speeds, in samples, where they look held between
    /// updates and no time tag was asked for (`HeldSpeeds`); else `None`.
    #[must_use]
    pub fn held_speeds_period_samples(&self) -> Option<usize> {
        (self.config.wheel_delay == WheelDelay::Off)
            .then(|| self.speeds.period_samples())
            .flatten()
    }

    /// Whether the run keeps every sample until [`Self::finish`] (batch, or a wheel-speed
    /// time tag to apply), so that an error there may name any sample.
    #[must_use]
    pub fn holds_samples(&self) -> bool {
        self.held.is_some() || matches!(self.mode, Mode::Batch { .. })
    }

    /// Input samples accepted.
    #[must_use]
    pub fn input_samples(&self) -> usize {
        self.input
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &PipelineConfig {
        &self.config
    }

    /// The input's first step, s (the wheel speeds' hold is counted in input samples).
    fn input_step_s(&self) -> f64 {
        self.first_t_s[1] - self.first_t_s[0]
    }

    /// The sample period, s: the resampling period where resampling, else the first step.
    #[must_use]
    #[cfg_attr(not(all(feature = "serde", feature = "csv")), allow(dead_code))] // used by the report
    pub(crate) fn sample_period_s(&self) -> f64 {
        self.config
            .resample_s()
            .unwrap_or(self.first_t_s[1] - self.first_t_s[0])
    }

    /// The newest estimate.
    #[must_use]
    pub fn last(&self) -> Option<&Estimate> {
        match &self.mode {
            Mode::Streaming(p) => p.last(),
            Mode::Batch { out, .. } => out.as_ref().map(|o| &o.estimate),
        }
    }

    /// The streaming pipeline (`None` in batch mode).
    #[must_use]
    pub fn pipeline(&self) -> Option<&Pipeline> {
        match &self.mode {
            Mode::Streaming(p) => Some(p),
            Mode::Batch { .. } => None,
        }
    }
}
