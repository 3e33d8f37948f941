//! What a user asks of the pipeline ([`PipelineSettings`], with documented defaults) and
//! what it runs with after validation ([`PipelineConfig`]).

use super::config::{InertialTorque, PipelineConfig};
use super::error::PipelineError;
use super::registry::{self, EstimatorEntry};
use crate::constraints::ConstraintSet;
use crate::estimator::momentum_rows::{OutsideTorques, RhoModel, RotationSource};
use crate::estimator::observability::ObservabilitySettings;
use crate::estimator::wheel_delay::{self, WheelDelay};
use crate::telemetry::glitch::GlitchPolicy;

/// Settings of an estimation run. Every field has a documented default
/// ([`Default`]); [`PipelineSettings::validate`] checks them all before any data is read.
#[derive(Debug, Clone, PartialEq)]
pub struct PipelineSettings {
    /// Estimator, by its registered name ([`registry::ESTIMATORS`]). Default
    /// `"discrete-momentum"` (as in the CLI, Python and C); `"variational"` is the
    /// paper's Algorithm 1.
    pub estimator: String,
    /// Solver backend, by its registered name ([`registry::BACKENDS`]). Default
    /// `"native"`.
    pub solver: String,
    /// The feasible set of J. Default [`ConstraintSet::physical`]. Estimators without
    /// constraints (the momentum RLS) accept only the default.
    pub constraints: ConstraintSet,
    /// Solve every this many row blocks (default 1: every sample).
    pub solve_every: usize,
    /// Memory time constant, s: data older by Δt weigh `exp(−Δt/memory)`, with Δt from
    /// the samples' own time stamps. `None` (default): no forgetting.
    pub memory_s: Option<f64>,
    /// Resample irregular telemetry onto a uniform grid of this period, s, before
    /// estimation ([`crate::estimator::resample`]). `None` (default): as it comes.
    pub resample_s: Option<f64>,
    /// Gyro rate-noise density from the datasheet, deg/s/√Hz, for errors-in-variables
    /// compensation (`crate::estimator::compensation`). `None` (default): none.
    pub gyro_noise_deg_s_rthz: Option<f64>,
    /// Attach a standard deviation to each estimate where the estimator has an
    /// uncertainty model (default `true`; costs about 10 % of throughput).
    pub uncertainty: bool,
    /// Relative standard deviation of the rotor momentum's scale, common to every wheel
    /// (the wheels' spin inertia, or the speed-to-momentum factor, known to ±this): a
    /// consider parameter that widens σ by `this · |ĵ|` per element ([`super::status`]),
    /// since the momentum rows fix J's scale only as well as ρ's. `None` (default): ρ's
    /// scale taken as exact.
    pub rotor_scale_sigma: Option<f64>,
    /// Relative standard deviation of the known torque's scale (`tau_*`, a spacecraft
    /// file's thrusters, commanded magnetorquer dipoles: a thrust or a dipole known to
    /// ±this): a consider parameter that widens the final answer's σ of a run by the move
    /// of `ĵ` for the known torque (and force) scaled by `1 + this` (`Run`'s batch
    /// re-solve, pinned to the row model; `this · |ĵ|` where a streaming run could not
    /// keep its samples). `None` (default): the known torque taken as exact.
    pub torque_scale_sigma: Option<f64>,
    /// The low-pass cutoff, Hz, of an estimator that differentiates filtered signals (the
    /// equation-error baseline). `None` (default): the estimator's own default.
    pub filter_cutoff_hz: Option<f64>,
    /// Thresholds of the observability test.
    pub observability: ObservabilitySettings,
    /// Source of the incremental rotations (discrete momentum estimator). `None`
    /// (default): the gyro and the attitude are both tried when the telemetry has gyro
    /// rates, and the rows that fit better are used.
    pub rotation_source: Option<RotationSource>,
    /// What the rotor momentum does between samples (discrete momentum estimator):
    /// default [`RhoModel::Auto`], decided from the data.
    pub rho_model: RhoModel,
    /// Estimate an unknown constant body-frame disturbance torque (discrete momentum
    /// estimator; default `true`).
    pub torque_bias: bool,
    /// Whether to estimate a disturbance torque constant in the inertial frame, per chain
    /// (discrete momentum estimator; default [`InertialTorque::Short`]: tested for on a
    /// record shorter than 30 s, not estimated on a longer one).
    pub inertial_torque: InertialTorque,
    /// Estimate a linear damping torque `−D ω` (air drag on a tumbling body; discrete
    /// momentum estimator; default `false`): one more shared unknown `D`, N m s
    /// ([`crate::estimator::momentum_rows`], "Damping").
    pub damping: bool,
    /// Estimate the spacecraft file's rotor parameters (each rotor's spin-inertia scale
    /// and axis tilts, wherever the file gives them a σ) with J, the file's σ as their
    /// priors, in place of their consider term (discrete momentum estimator, batch runs;
    /// default `false`; [`crate::estimator::rotor_calibration`]).
    pub calibrate_rotors: bool,
    /// The torques of outside measurements (positions, magnetic field, force) the
    /// discrete momentum rows model where the telemetry gives them: gravity gradient,
    /// a residual magnetic dipole, the centre of mass (default: each one;
    /// [`crate::estimator::external_torque`]).
    pub outside: OutsideTorques,
    /// Short momentum chain, s (discrete momentum estimator): bounds how far a
    /// drifting attitude error can rotate the conserved momentum
    /// ([`crate::estimator::momentum_rows::MomentumRowSettings::max_chain_s`]). Chains
    /// a quarter and 4× as long and the whole record as one chain are folded too, and each
    /// solve takes the longest that fits as well, or a longer one that is clearly
    /// steadier (`estimators/discrete_momentum/select.rs`). Default
    /// [`DEFAULT_MAX_CHAIN_S`]; `None`: chains end only at gaps.
    pub max_chain_s: Option<f64>,
    /// Angle random walk of the attitude solution, deg/√h (discrete momentum estimator):
    /// for an attitude propagated from a gyro, that gyro's ARW. Given with
    /// `gyro_noise_deg_s_rthz`, the momentum rows are weighted for the attitude's drift
    /// (generalised least squares, `crate::estimator::attitude_drift`) from the first
    /// answer on, refolded from the first sample (up to an hour at 10 Hz is kept for
    /// that), beside the same rows unweighted; each answer is the weighted one unless
    /// the unweighted one's bias σ exceeds its noise σ (`drift_weighted` in `super::Diagnostics`
    /// says which; so it needs `uncertainty`). Twice the work per sample. `None`
    /// (default): unweighted, right for a star tracker or an MEKF, whose attitude error
    /// is bounded.
    pub attitude_drift_deg_rth: Option<f64>,
    /// What to do with a step where the attitude jumps against the gyro
    /// ([`crate::telemetry::glitch`]; telemetry with gyro rates). Default
    /// [`GlitchPolicy::Stop`].
    pub glitches: GlitchPolicy,
    /// The wheel-speed telemetry's time tag ([`crate::estimator::wheel_delay`]): the
    /// speeds are read `δ` later than their time stamps, `δ` given or estimated, and its
    /// σ widens the answer's (a consider term). Any estimator, through a
    /// [`super::Run`] only (a [`super::Pipeline`] or a batch call refuses it). The run
    /// then keeps every sample and gives its estimates at the end of the input. Default
    /// [`WheelDelay::Off`].
    pub wheel_delay: WheelDelay,
}

/// Default longest momentum chain, s.
pub const DEFAULT_MAX_CHAIN_S: f64 = 30.0;

impl Default for PipelineSettings {
    fn default() -> Self {
        Self {
            estimator: Self::DEFAULT_ESTIMATOR.into(),
            solver: Self::DEFAULT_SOLVER.into(),
            ..Self::unnamed()
        }
    }
}

impl PipelineSettings {
    /// [`Self::default`] with empty estimator and solver names, built without the heap: for
    /// [`Self::check`] where the registry entry is already chosen (the C API's).
    #[must_use]
    pub(crate) fn unnamed() -> Self {
        Self {
            estimator: std::string::String::new(),
            solver: std::string::String::new(),
            constraints: ConstraintSet::physical(),
            solve_every: 1,
            memory_s: None,
            resample_s: None,
            gyro_noise_deg_s_rthz: None,
            rotor_scale_sigma: None,
            torque_scale_sigma: None,
            filter_cutoff_hz: None,
            uncertainty: true,
            observability: ObservabilitySettings::default(),
            rotation_source: None,
            rho_model: RhoModel::Auto,
            torque_bias: true,
            inertial_torque: InertialTorque::Short,
            damping: false,
            calibrate_rotors: false,
            outside: OutsideTorques::default(),
            max_chain_s: Some(DEFAULT_MAX_CHAIN_S),
            attitude_drift_deg_rth: None,
            glitches: GlitchPolicy::Stop,
            wheel_delay: WheelDelay::Off,
        }
    }
}

fn positive(field: &'static str, v: Option<f64>, unit: &'static str) -> Result<(), PipelineError> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0) => Err(PipelineError::InvalidSetting {
            field,
            value: x,
            expected: unit,
        }),
        _ => Ok(()),
    }
}

impl PipelineSettings {
    /// The estimator of [`Self::default`]: the discrete momentum estimator.
    pub const DEFAULT_ESTIMATOR: &'static str = "discrete-momentum";
    /// The solver backend of [`Self::default`].
    pub const DEFAULT_SOLVER: &'static str = "native";

    /// Check every setting and the combination, and validate the constraint set (a
    /// phase-I search for a strictly feasible J).
    pub fn validate(&self) -> Result<PipelineConfig, PipelineError> {
        let estimator = registry::estimator(&self.estimator)?;
        let backend = registry::backend(&self.solver)?;
        self.check(estimator)?;
        let constraints = self.constraints.validate()?;
        Ok(PipelineConfig {
            estimator,
            backend,
            constraints,
            solve_every: self.solve_every,
            memory_s: self.memory_s,
            resample_s: self.resample_s,
            gyro_noise_rad_s_rthz: self.gyro_noise_deg_s_rthz.map(f64::to_radians),
            gyro_noise_estimated: false,
            uncertainty: self.uncertainty && estimator.capabilities.uncertainty,
            rotor_scale_sigma: self.rotor_scale_sigma.filter(|&r| r > 0.0),
            torque_scale_sigma: self.torque_scale_sigma.filter(|&r| r > 0.0),
            filter_cutoff_hz: self.filter_cutoff_hz,
            observability: self.observability,
            rotation_source: self.rotation_source,
            rho_model: self.rho_model,
            torque_bias: self.torque_bias,
            inertial_torque: self.inertial_torque,
            damping: self.damping,
            calibrate_rotors: self.calibrate_rotors,
            outside: self.outside,
            max_chain_s: self.max_chain_s,
            attitude_drift_deg_rth: self.attitude_drift_deg_rth,
            glitches: self.glitches,
            wheel_delay: self.wheel_delay,
            wheel_delay_consider: None,
            rotor_inertia_consider: None,
            torque_scale_consider: None,
            rotor_inertia_relative_sigma: 0.0,
            pinned_chain_s: None,
        })
    }

    /// Check every setting but the names against `estimator`'s capabilities, without the
    /// heap (all of [`Self::validate`] but the registry look-ups and the constraint set's
    /// phase-I search).
    pub fn check(&self, estimator: &EstimatorEntry) -> Result<(), PipelineError> {
        if self.solve_every == 0 {
            return Err(PipelineError::InvalidSetting {
                field: "solve_every",
                value: 0.0,
                expected: "at least 1",
            });
        }
        positive("memory_s", self.memory_s, "a finite memory > 0 s")?;
        positive("resample_s", self.resample_s, "a finite period > 0 s")?;
        positive("max_chain_s", self.max_chain_s, "a finite duration > 0 s")?;
        positive(
            "attitude_drift_deg_rth",
            self.attitude_drift_deg_rth,
            "a finite angle random walk > 0 deg/√h",
        )?;
        if let Some(g) = self.gyro_noise_deg_s_rthz {
            if !(g.is_finite() && g >= 0.0) {
                return Err(PipelineError::InvalidSetting {
                    field: "gyro_noise_deg_s_rthz",
                    value: g,
                    expected: "a finite density >= 0 deg/s/√Hz",
                });
            }
            // 0 (no compensation) applies to every estimator.
            if g > 0.0 && !estimator.capabilities.compensation {
                return Err(PipelineError::NotApplicable {
                    setting: "gyro_noise_deg_s_rthz",
                    estimator: estimator.name,
                });
            }
        }
        if self.attitude_drift_deg_rth.is_some()
            && !self.gyro_noise_deg_s_rthz.is_some_and(|g| g > 0.0)
        {
            return Err(PipelineError::NeedsSetting {
                setting: "attitude_drift_deg_rth",
                needs: "gyro_noise_deg_s_rthz",
                requirement: "> 0",
                why: "the drift is weighed against the gyro's noise",
            });
        }
        if self.attitude_drift_deg_rth.is_some() && !self.uncertainty {
            return Err(PipelineError::NeedsSetting {
                setting: "attitude_drift_deg_rth",
                needs: "uncertainty",
                requirement: "on",
                why: "the weighted rows' answer is given unless the unweighted rows' bias σ exceeds their noise σ",
            });
        }
        for (field, r) in [
            ("rotor_scale_sigma", self.rotor_scale_sigma),
            ("torque_scale_sigma", self.torque_scale_sigma),
        ] {
            let Some(r) = r else { continue };
            if !(r.is_finite() && (0.0..1.0).contains(&r)) {
                return Err(PipelineError::InvalidSetting {
                    field,
                    value: r,
                    expected: "a finite relative σ in [0, 1)",
                });
            }
            if !(self.uncertainty && estimator.capabilities.uncertainty) {
                return Err(PipelineError::NeedsSetting {
                    setting: field,
                    needs: "uncertainty",
                    requirement: "on",
                    why: "it widens σ, which the estimator must give",
                });
            }
        }
        if let Some(f) = self.filter_cutoff_hz {
            positive("filter_cutoff_hz", Some(f), "a finite cutoff > 0 Hz")?;
            if !estimator.capabilities.filter {
                return Err(PipelineError::NotApplicable {
                    setting: "filter_cutoff_hz",
                    estimator: estimator.name,
                });
            }
        }
        if !estimator.capabilities.constraints && self.constraints != ConstraintSet::physical() {
            return Err(PipelineError::NotApplicable {
                setting: "constraints",
                estimator: estimator.name,
            });
        }
        if !estimator.capabilities.row_model {
            let defaults = PipelineSettings::unnamed();
            for (setting, changed) in [
                (
                    "rotation_source",
                    self.rotation_source != defaults.rotation_source,
                ),
                ("rho_model", self.rho_model != defaults.rho_model),
                ("torque_bias", self.torque_bias != defaults.torque_bias),
                // Off and the default (off past a short record) ask for no torque.
                (
                    "inertial_torque",
                    !matches!(
                        self.inertial_torque,
                        InertialTorque::Short | InertialTorque::Off
                    ),
                ),
                ("damping", self.damping != defaults.damping),
                (
                    "calibrate_rotors",
                    self.calibrate_rotors != defaults.calibrate_rotors,
                ),
                ("outside", self.outside != defaults.outside),
                ("max_chain_s", self.max_chain_s != defaults.max_chain_s),
                (
                    "attitude_drift_deg_rth",
                    self.attitude_drift_deg_rth != defaults.attitude_drift_deg_rth,
                ),
            ] {
                if changed {
                    return Err(PipelineError::NotApplicable {
                        setting,
                        estimator: estimator.name,
                    });
                }
            }
        }
        // The test that chooses the inertial torque compares unweighted fits.
        if self.inertial_torque == InertialTorque::Auto && self.memory_s.is_some() {
            return Err(PipelineError::NeedsSetting {
                setting: "inertial_torque",
                needs: "memory_s",
                requirement: "unset",
                why: "the test that chooses the torque needs unweighted rows (give on or off with a memory)",
            });
        }
        if let WheelDelay::KnownS(d) = self.wheel_delay {
            if !(d.is_finite() && d.abs() <= wheel_delay::MAX_HALF_RANGE_S) {
                return Err(PipelineError::InvalidSetting {
                    field: "wheel_delay",
                    value: d,
                    expected: "a finite time tag within the search's ±MAX_HALF_RANGE_S (0.25 s)",
                });
            }
        }
        if !self.outside.valid() {
            return Err(PipelineError::InvalidSetting {
                field: "outside.gravity_mu_m3_s2",
                value: self.outside.gravity_mu_m3_s2,
                expected: "finite and > 0",
            });
        }
        // The observability thresholds are checked by the estimators' own settings.
        let o = &self.observability;
        if !(o.condition_threshold.is_finite() && o.condition_threshold > 1.0) {
            return Err(PipelineError::InvalidSetting {
                field: "observability.condition_threshold",
                value: o.condition_threshold,
                expected: "finite and > 1",
            });
        }
        if !(o.max_relative_sigma.is_finite() && o.max_relative_sigma > 0.0) {
            return Err(PipelineError::InvalidSetting {
                field: "observability.max_relative_sigma",
                value: o.max_relative_sigma,
                expected: "finite and > 0",
            });
        }
        Ok(())
    }
}

/// The wheel-speed time tag setting from its text: `off`, `estimate`, or the delay in
/// seconds ([`WheelDelay`]).
pub fn parse_wheel_delay(s: &str) -> Result<WheelDelay, PipelineError> {
    s.trim().parse().map_err(|()| PipelineError::UnknownChoice {
        setting: "wheel_delay",
        value: s.into(),
        expected: "off, estimate, or the delay in seconds",
    })
}
