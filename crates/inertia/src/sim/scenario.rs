//! The two numerical examples of paper §VI, with every parameter overridable.
//!
//! * [`Scenario::Slew`]: a three-axis stabilised spacecraft performs rest-to-rest slews
//!   about several body axes on reaction wheels, under a [`SlewController`] that uses a
//!   nominal inertia `diag(1, 2, 3)` kg m², not `J_true`. Default 300 s, six slews,
//!   wheel momentum up to about 0.2 N m s.
//! * [`Scenario::Spin`]: spinning at 0.5 rad/s about the major axis (J33) with some
//!   nutation; the only control input is a 2 s raised-cosine pulse on the x wheel 30 s
//!   into the run (Δρ = 0.05 N m s). Default 180 s. The paper bounds J33 within 10 % of
//!   3 kg m² in this case ([`SPIN_J33_NOMINAL`]).
//!
//! Common defaults ([`Common::paper`]): `J_true` of §VI, h = 0.1 s, disturbance torque
//! 1e-8 N m/√Hz, gyro noise 1e-5 deg/s/√Hz, 20 RK4 substeps per sample.

use super::control::{Slew, SlewController, WheelPulse};
use super::{simulate, Realism, SimConfig, SimError, SimOutput, Zero};
use crate::attitude::Quaternion;
use crate::dynamics::GyrostatState;
use crate::tensor::paper_j_true;
use nalgebra::{Matrix3, Vector3};

/// How much [`physical_j_true`] adds to every principal moment of the paper's J, kg m².
pub(crate) const PHYSICAL_SHIFT_KG_M2: f64 = 1e-4;

/// The paper's J made physical with the least change of one kind: `J + δ I` with `δ` =
/// `PHYSICAL_SHIFT_KG_M2` (1e-4 kg m²) raises every principal moment by δ and so `J1 + J2 − J3` by
/// δ, from −4.9e-5 to +5.1e-5 kg m² (the axes and the products of inertia unchanged;
/// the diagonal moves by 1e-4 of J11).
#[must_use]
pub fn physical_j_true() -> Matrix3<f64> {
    paper_j_true() + Matrix3::identity() * PHYSICAL_SHIFT_KG_M2
}

/// The nominal J33 of the spin case's a-priori bound, kg m².
pub const SPIN_J33_NOMINAL: f64 = 3.0;
/// The relative half-width of that bound (10 %).
pub const SPIN_J33_TOLERANCE: f64 = 0.10;

/// Settings shared by both scenarios.
#[derive(Debug, Clone, PartialEq)]
pub struct Common {
    /// True inertia, kg m².
    pub inertia_kg_m2: Matrix3<f64>,
    /// Integration node period h, s (the telemetry period unless
    /// [`Realism::telemetry_every`] > 1).
    pub dt_s: f64,
    /// Duration, s (`None`: the scenario's default).
    pub duration_s: Option<f64>,
    /// RK4 substeps per sample.
    pub substeps: usize,
    /// Unknown disturbance torque spectral density, N m/√Hz.
    pub disturbance_nm_rthz: f64,
    /// Gyro rate noise spectral density, deg/s/√Hz.
    pub gyro_noise_deg_s_rthz: f64,
    /// Noise seed.
    pub seed: u64,
    /// A change of inertia during the run.
    pub inertia_change: Option<super::InertiaChange>,
    /// Sensors, actuators, environment and telemetry beyond the paper's model
    /// (`Default`: none, the paper's simulator bit for bit). With
    /// [`Realism::telemetry_every`] = n the telemetry period is `n · dt_s` and the
    /// duration is counted in telemetry periods.
    pub realism: Realism,
}

impl Common {
    /// The paper's settings (§VI) with a physical truth: [`physical_j_true`] instead of
    /// the paper's J, which breaks the triangle inequality `J1 + J2 ≥ J3` of its
    /// principal moments by 4.9e-5 kg m² (the default of `inertia simulate`; `reproduce`
    /// keeps the paper's J, [`Self::paper`]).
    #[must_use]
    pub fn physical() -> Self {
        Self {
            inertia_kg_m2: physical_j_true(),
            ..Self::paper()
        }
    }

    /// The paper's settings (§VI).
    #[must_use]
    pub fn paper() -> Self {
        Self {
            inertia_kg_m2: paper_j_true(),
            dt_s: 0.1,
            duration_s: None,
            substeps: 20,
            disturbance_nm_rthz: 1e-8,
            gyro_noise_deg_s_rthz: 1e-5,
            seed: 1,
            inertia_change: None,
            realism: Realism::default(),
        }
    }

    /// The paper's settings with every noise source off.
    #[must_use]
    pub fn noise_free() -> Self {
        Self {
            disturbance_nm_rthz: 0.0,
            gyro_noise_deg_s_rthz: 0.0,
            ..Self::paper()
        }
    }
}

impl Default for Common {
    fn default() -> Self {
        Self::paper()
    }
}

/// The slew manoeuvre plan.
#[derive(Debug, Clone, PartialEq)]
pub struct SlewPlan {
    /// Default duration, s.
    pub duration_s: f64,
    /// The slews.
    pub slews: Vec<Slew>,
    /// Inertia the controller uses, kg m².
    pub nominal_inertia_kg_m2: Matrix3<f64>,
    /// Closed-loop natural frequency, rad/s.
    pub natural_freq_rad_s: f64,
    /// Damping ratio.
    pub damping: f64,
    /// The rotors' momentum at rest, body axes, N m s: a momentum-biased spacecraft's
    /// stored momentum (zero: the paper's slew, with no total momentum).
    pub momentum_bias_nms: Vector3<f64>,
}

impl Default for SlewPlan {
    fn default() -> Self {
        let deg = core::f64::consts::PI / 180.0;
        let slew = |axis: [f64; 3], angle_deg: f64, start_s: f64| Slew {
            axis: Vector3::from(axis),
            angle_rad: angle_deg * deg,
            start_s,
            duration_s: 30.0,
        };
        Self {
            duration_s: 300.0,
            slews: vec![
                slew([1.0, 0.0, 0.0], 40.0, 5.0),
                slew([0.0, 1.0, 0.0], -50.0, 55.0),
                slew([0.0, 0.0, 1.0], 60.0, 105.0),
                slew([1.0, 1.0, 0.0], 45.0, 155.0),
                slew([0.0, 1.0, -1.0], -50.0, 205.0),
                slew([1.0, 1.0, 1.0], 60.0, 255.0),
            ],
            nominal_inertia_kg_m2: Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0)),
            natural_freq_rad_s: 0.2,
            damping: 0.8,
            momentum_bias_nms: Vector3::zeros(),
        }
    }
}

impl SlewPlan {
    /// The plan's slews `times` times over, one plan's duration apart, for `times` plans'
    /// duration (a long run of the same manoeuvres).
    #[must_use]
    pub fn repeated(&self, times: usize) -> SlewPlan {
        let slews = (0..times)
            .flat_map(|k| {
                let shift = k as f64 * self.duration_s;
                self.slews.iter().map(move |s| Slew {
                    start_s: s.start_s + shift,
                    ..*s
                })
            })
            .collect();
        SlewPlan {
            duration_s: times as f64 * self.duration_s,
            slews,
            ..self.clone()
        }
    }
}

/// The spin case.
#[derive(Debug, Clone, PartialEq)]
pub struct SpinPlan {
    /// Default duration, s.
    pub duration_s: f64,
    /// Initial body rate, rad/s (spin about z with nutation).
    pub initial_omega_rad_s: Vector3<f64>,
    /// The wheel pulse.
    pub pulse: WheelPulse,
}

impl Default for SpinPlan {
    fn default() -> Self {
        Self {
            duration_s: 180.0,
            initial_omega_rad_s: Vector3::new(0.02, -0.015, 0.5),
            pulse: WheelPulse {
                axis: Vector3::x(),
                delta_rho_nms: 0.05,
                start_s: 30.0,
                duration_s: 2.0,
            },
        }
    }
}

/// A §VI scenario.
#[derive(Debug, Clone, PartialEq)]
pub enum Scenario {
    /// Three-axis stabilised slews.
    Slew(SlewPlan),
    /// Major-axis spin with one wheel pulse.
    Spin(SpinPlan),
}

impl Scenario {
    /// The slew case with default plan.
    #[must_use]
    pub fn slew() -> Self {
        Scenario::Slew(SlewPlan::default())
    }

    /// The spin case with default plan.
    #[must_use]
    pub fn spin() -> Self {
        Scenario::Spin(SpinPlan::default())
    }

    /// Short name (`slew` or `spin`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Scenario::Slew(_) => "slew",
            Scenario::Spin(_) => "spin",
        }
    }

    /// Default duration of this scenario, s.
    #[must_use]
    pub fn default_duration_s(&self) -> f64 {
        match self {
            Scenario::Slew(p) => p.duration_s,
            Scenario::Spin(p) => p.duration_s,
        }
    }

    /// The simulator configuration for `common`.
    #[must_use]
    pub fn config(&self, common: &Common) -> SimConfig {
        let duration = common
            .duration_s
            .unwrap_or_else(|| self.default_duration_s());
        let initial = match self {
            Scenario::Slew(p) => GyrostatState {
                q: Quaternion::IDENTITY,
                omega_rad_s: Vector3::zeros(),
                rho_nms: p.momentum_bias_nms,
            },
            Scenario::Spin(p) => GyrostatState {
                q: Quaternion::IDENTITY,
                omega_rad_s: p.initial_omega_rad_s,
                rho_nms: Vector3::zeros(),
            },
        };
        SimConfig {
            inertia_kg_m2: common.inertia_kg_m2,
            initial,
            t0_s: 0.0,
            dt_s: common.dt_s,
            samples: SimConfig::samples_for(
                duration,
                common.dt_s * common.realism.telemetry_every.max(1) as f64,
            ),
            substeps: common.substeps,
            disturbance_nm_rthz: common.disturbance_nm_rthz,
            gyro_noise_deg_s_rthz: common.gyro_noise_deg_s_rthz,
            seed: common.seed,
            inertia_change: common.inertia_change,
            realism: common.realism,
        }
    }

    /// Simulate the scenario.
    pub fn simulate(&self, common: &Common) -> Result<SimOutput, SimError> {
        let cfg = self.config(common);
        match self {
            Scenario::Slew(p) => {
                let ctrl = SlewController::new(
                    p.nominal_inertia_kg_m2,
                    cfg.initial.q,
                    p.slews.clone(),
                    p.natural_freq_rad_s,
                    p.damping,
                )?;
                simulate(&cfg, &ctrl, &Zero)
            }
            Scenario::Spin(p) => simulate(&cfg, &p.pulse, &Zero),
        }
    }
}
