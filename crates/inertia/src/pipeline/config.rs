//! What a pipeline runs with once its settings are validated ([`PipelineConfig`], made
//! by [`super::PipelineSettings::validate`]): the registry entries, the validated
//! constraint set and the estimators' settings. The estimators read this, never the
//! settings, so that they do not depend on the registry that lists them.

use super::error::PipelineError;
use super::interface::{BatchInputs, BatchOutput, Capabilities, Estimator};
use crate::constraints::Constraints;
use crate::estimator::momentum_rows::{RhoModel, RotationSource};
use crate::estimator::observability::ObservabilitySettings;
use crate::estimator::wheel_delay::WheelDelay;
use crate::sample::Sample;
use crate::solver::Backend;
use crate::telemetry::glitch::GlitchPolicy;
use std::boxed::Box;

/// Validated settings: what a [`super::Pipeline`] runs with.
#[derive(Debug, Clone, Copy)]
pub struct PipelineConfig {
    pub(crate) estimator: &'static EstimatorEntry,
    pub(crate) backend: &'static BackendEntry,
    pub(crate) constraints: Constraints,
    pub(crate) solve_every: usize,
    pub(crate) memory_s: Option<f64>,
    pub(crate) resample_s: Option<f64>,
    pub(crate) gyro_noise_rad_s_rthz: Option<f64>,
    /// Whether `gyro_noise_rad_s_rthz` is the discrete momentum estimator's estimate from
    /// the rates (`crate::estimator::rate_noise`), not a stated density: no answer is
    /// withdrawn for it (the density-overstated test, a noise-dominated compensation).
    pub(crate) gyro_noise_estimated: bool,
    pub(crate) uncertainty: bool,
    pub(crate) rotor_scale_sigma: Option<f64>,
    /// Relative σ of the known torque's scale ([`super::PipelineSettings::torque_scale_sigma`]).
    pub(crate) torque_scale_sigma: Option<f64>,
    pub(crate) filter_cutoff_hz: Option<f64>,
    pub(crate) observability: ObservabilitySettings,
    pub(crate) rotation_source: Option<RotationSource>,
    pub(crate) rho_model: RhoModel,
    pub(crate) torque_bias: bool,
    pub(crate) inertial_torque: InertialTorque,
    pub(crate) damping: bool,
    pub(crate) calibrate_rotors: bool,
    pub(crate) outside: crate::estimator::momentum_rows::OutsideTorques,
    pub(crate) max_chain_s: Option<f64>,
    pub(crate) attitude_drift_deg_rth: Option<f64>,
    pub(crate) glitches: GlitchPolicy,
    pub(crate) wheel_delay: WheelDelay,
    /// The time tag's consider term per element, kg m², once a run has applied it.
    pub(crate) wheel_delay_consider: Option<[f64; 6]>,
    /// The rotors' spin-inertia consider term per element, kg m², once a run with a
    /// spacecraft file has computed it ([`crate::estimator::rotor_inertia`]).
    pub(crate) rotor_inertia_consider: Option<[f64; 6]>,
    /// The known torque's scale consider term per element, kg m², once a run has computed
    /// it for its final answer (`Run::torque_scale_term`).
    pub(crate) torque_scale_consider: Option<[f64; 6]>,
    /// `√Σ_i s_i²` of a spacecraft file's rotors' relative spin-inertia σ (0 without).
    pub(crate) rotor_inertia_relative_sigma: f64,
    /// One chain length for the discrete momentum estimator's candidates (`Some(None)`:
    /// the whole record), in place of the choice among [`Self::max_chain_s`]'s: a run that
    /// re-estimates perturbed data in the row model its answer used
    /// ([`Self::pinned_to`]).
    pub(crate) pinned_chain_s: Option<Option<f64>>,
}

impl PipelineConfig {
    /// The compensation's gyro density for rows whose rotation comes from `rotation`: a
    /// stated density applies to every row (an attitude propagated from that gyro carries
    /// its noise); an estimated one describes the telemetered rates, so only the
    /// gyro-rotation rows.
    #[must_use]
    pub(crate) fn gyro_noise_for(
        &self,
        rotation: crate::estimator::momentum_rows::RotationSource,
    ) -> Option<f64> {
        match rotation {
            crate::estimator::momentum_rows::RotationSource::Attitude
                if self.gyro_noise_estimated =>
            {
                None
            }
            _ => self.gyro_noise_rad_s_rthz,
        }
    }

    /// The density the rotation-source twins are compared at
    /// (`crate::estimators::discrete_momentum::twins`): one for both, so that their
    /// difference is the measurements', not the compensation's; none when estimated (it
    /// would apply to one of them only, [`Self::gyro_noise_for`]).
    #[must_use]
    pub(crate) fn twin_gyro_noise(&self) -> Option<f64> {
        self.gyro_noise_rad_s_rthz
            .filter(|_| !self.gyro_noise_estimated)
    }

    /// A wheel-speed time tag is applied by a [`super::Run`] alone, which holds the record
    /// ([`crate::estimator::wheel_delay`]); a [`super::Pipeline`] or a batch call given
    /// one refuses it rather than ignore it.
    pub(crate) fn check_no_wheel_delay(&self) -> Result<(), PipelineError> {
        if self.wheel_delay == WheelDelay::Off {
            return Ok(());
        }
        Err(PipelineError::NeedsSetting {
            setting: "wheel_delay",
            needs: "Run",
            requirement: "to apply it",
            why: "the speeds are read later over the whole record, which only a run holds",
        })
    }

    /// Refuse the rotor calibration outside a [`super::Run`] with a spacecraft file, which
    /// alone holds the rotors' speeds and σ (rather than ignore it).
    pub(crate) fn check_no_calibration(&self) -> Result<(), PipelineError> {
        if !self.calibrate_rotors {
            return Ok(());
        }
        Err(PipelineError::NeedsSetting {
            setting: "calibrate_rotors",
            needs: "Run",
            requirement: "with a spacecraft file",
            why: "the rotors' parameters need their speeds and σ, which only a run with the file holds",
        })
    }

    /// This configuration with its wheel-speed time tag applied by the run: the time tag
    /// off for the pipeline or batch call, its consider term kept.
    pub(crate) fn with_delay_applied(mut self) -> Self {
        self.wheel_delay = WheelDelay::Off;
        self
    }

    /// The relative σ of the rotor momentum the user stated: the common scale's
    /// ([`PipelineSettings::rotor_scale_sigma`]) and a spacecraft file's rotors'
    /// (`√Σ_i (σ_i/J_i)²`), in quadrature; 0 without either. The residual-span test widens
    /// its reference σ by it ([`crate::estimator::consistency`]).
    #[must_use]
    pub(crate) fn stated_relative_sigma(&self) -> f64 {
        let r = self.rotor_scale_sigma.unwrap_or(0.0);
        crate::math::sqrt(
            r * r + self.rotor_inertia_relative_sigma * self.rotor_inertia_relative_sigma,
        )
    }

    /// This configuration with the row model an answer used (`rows`, and whether its
    /// constant torque was held at zero, `torque`) fixed instead of chosen from the data:
    /// its rotation source, stencil, chain length, inertial torque, and the body torque
    /// estimated or not. For re-running the estimator on slightly changed data (the
    /// rotors' consider term, [`crate::estimator::rotor_inertia`]) so that the change
    /// measures the answer's sensitivity, not a switch of the model.
    #[must_use]
    pub(crate) fn pinned_to(
        mut self,
        rows: Option<crate::estimator::momentum_rows::MomentumRowSettings>,
        torque: Option<crate::estimator::discrete_momentum::TorqueTest>,
    ) -> Self {
        use crate::estimator::momentum_rows::Stencil;
        let Some(r) = rows else {
            return self;
        };
        self.rotation_source = Some(r.rotation);
        self.rho_model = match r.stencil {
            Stencil::Plain => RhoModel::Plain,
            Stencil::Smooth => RhoModel::Smooth,
            Stencil::Held => RhoModel::Held,
            Stencil::Adaptive => RhoModel::Auto,
        };
        self.torque_bias = r.torque_bias && !torque.is_some_and(|t| t.held_at_zero);
        self.inertial_torque = if r.inertial_torque {
            InertialTorque::On
        } else {
            InertialTorque::Off
        };
        self.damping = r.damping;
        self.outside = r.outside;
        self.pinned_chain_s = Some(r.max_chain_s);
        self
    }

    /// The estimator's registry entry.
    #[must_use]
    pub fn estimator(&self) -> &'static EstimatorEntry {
        self.estimator
    }

    /// The backend's registry entry.
    #[must_use]
    pub(crate) fn backend(&self) -> &'static BackendEntry {
        self.backend
    }

    /// The validated constraints.
    #[must_use]
    pub(crate) fn constraints(&self) -> &Constraints {
        &self.constraints
    }

    /// Memory time constant, s.
    #[must_use]
    pub(crate) fn memory_s(&self) -> Option<f64> {
        self.memory_s
    }

    /// Resampling period, s.
    #[must_use]
    pub(crate) fn resample_s(&self) -> Option<f64> {
        self.resample_s
    }
}

/// Whether the discrete momentum estimator estimates a disturbance torque constant in the
/// inertial frame, per chain ([`crate::estimator::momentum_rows`], "Inertial torque"):
/// an aerodynamic or solar force whose direction is fixed in space, the momentum's drift
/// over a short record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum InertialTorque {
    /// [`InertialTorque::Auto`] on a record shorter than 30 s (`SHORT_RECORD_S`), from its
    /// first sample, and [`InertialTorque::Off`] once it is longer (default): over a short
    /// record (a thrown device, a test article, a manoeuvre of seconds) a force fixed in
    /// space acts on the whole of one momentum chain, which no chain restart absorbs; over
    /// a long one the chains absorb the momentum's slow drift, and a test would take its
    /// random walk for a torque. With a memory (forgetting) it is `Off`.
    #[default]
    Short,
    /// Not estimated.
    Off,
    /// Always estimated.
    On,
    /// Estimated where a nested χ² test at 10⁻³ and the Bayesian information criterion
    /// both say the data need it (`estimators/discrete_momentum/select.rs`): both models
    /// are folded, and the report says which answered.
    Auto,
}

/// The longest record, s, on which [`InertialTorque::Short`] tests for a torque fixed in
/// the inertial frame: the default chain length ([`super::DEFAULT_MAX_CHAIN_S`]).
pub(crate) const SHORT_RECORD_S: f64 = 30.0;

/// Build a streaming estimator from a validated configuration.
pub(crate) type BuildFn = fn(&PipelineConfig) -> Result<Box<dyn Estimator>, PipelineError>;
/// Estimate from all samples at once, with the rotor parameters' sources where the run
/// estimates them ([`super::interface::BatchInputs`]).
pub(crate) type BatchFn =
    fn(&[Sample], &PipelineConfig, &BatchInputs) -> Result<BatchOutput, PipelineError>;

/// A registered estimator.
#[derive(Debug)]
pub struct EstimatorEntry {
    /// Name, as given in settings and on the command line.
    pub name: &'static str,
    /// One line for help texts.
    pub summary: &'static str,
    /// What it uses and needs.
    pub capabilities: Capabilities,
    pub(crate) build: BuildFn,
    pub(crate) batch: Option<BatchFn>,
}

impl EstimatorEntry {
    /// Whether it can estimate from all samples at once.
    #[must_use]
    pub fn has_batch(&self) -> bool {
        self.batch.is_some()
    }
}

/// A registered solver backend.
#[derive(Debug)]
pub struct BackendEntry {
    /// Name, as given in settings and on the command line.
    pub name: &'static str,
    /// One line for help texts.
    pub summary: &'static str,
    /// Why this build cannot run it, when it cannot.
    pub unavailable: Option<&'static str>,
    pub(crate) build: fn() -> Box<dyn Backend + Send>,
}

impl BackendEntry {
    /// A fresh backend of this (validated) entry.
    pub(crate) fn build(&self) -> Box<dyn Backend + Send> {
        (self.build)()
    }
}
