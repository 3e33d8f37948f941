//! Spacecraft presets beside the paper's two scenarios: a 12U-class small satellite and a
//! three-axis microsatellite, each a slew [`Scenario`] with its own [`Common`] settings.
//!
//! The numbers are representative of published datasheets of the named equipment
//! classes, not of one product; every one can be overridden on the returned
//! [`Preset::common`] and [`Preset::scenario`].
//!
//! | | [`Preset::small_sat`] | [`Preset::microsat`] |
//! |---|---|---|
//! | inertia | 12U CubeSat, about 20 kg in 22.6 × 22.6 × 34 cm (`m(a² + b²)/12` ≈ 0.28, 0.28, 0.17 kg m²), made asymmetric by deployed panels, with products of inertia | about 60 kg, 0.6 × 0.6 × 0.7 m: 4.6, 5.1, 3.7 kg m² with products |
//! | gyro | tactical MEMS IMU (STIM300 class): ARW 0.15 deg/√h, turn-on bias of a few deg/h, bias instability 0.5 deg/h | fibre-optic gyro (µFORS / DSP-1760 class): ARW 0.02 deg/√h, bias 0.3 deg/h, bias instability 0.05 deg/h |
//! | star tracker | CubeSat tracker: 5″/5″/40″ (1σ cross-boresight/roll), 5 Hz | microsat tracker: 3″/3″/25″, 10 Hz |
//! | attitude | MEKF | MEKF |
//! | wheels | 3 × ~50 mN m s CubeSat wheels, 10 Hz commands; speed LSB ≈ 1 rpm on a ~1e-4 kg m² rotor: 1e-5 N m s | 3 × ~0.2 N m s wheels, 5 Hz commands; 0.1 rpm on a ~4e-4 kg m² rotor: 4e-6 N m s |
//! | manoeuvre | six 30–45° slews of 60 s, 600 s | six 30–60° slews of 90 s, 900 s |
//!
//! Both telemeter at 10 Hz (integration step 0.1 s, 20 RK4 substeps) and keep the white
//! disturbance torque; no environmental torque is on by default (set
//! [`super::Realism::environment`]).
//!
//! [`Preset::throw`] is a laboratory record instead: a small device thrown by hand,
//! tumbling free for 0.5 s while one flywheel spins up ([`THROW`] lists its numbers). It
//! is a [`Scenario::Spin`] (initial tumble, one raised-cosine wheel pulse) with the lab's
//! sensors: a MEMS IMU at 4 kHz whose gyro vibrates at the rotor frequency, the attitude
//! integrated from that gyro, the flywheel's speed telemetered quantised and held at
//! 100 Hz, and air acting as a torque fixed in the inertial frame (aerodynamic force off
//! the centre of mass) and a drag `−D ω`. Each effect can be switched off on the returned
//! settings ([`Preset::throw_without`]).

use super::control::Slew;
use super::control::WheelPulse;
use super::scenario::{Common, Scenario, SlewPlan, SpinPlan};
use super::{
    AttitudeSource, CommandHold, Environment, GyroErrors, MekfSettings, Realism, RotorVibration,
    SimError, SimOutput, StarTracker, WheelTelemetry,
};
use crate::sim::gyro::arw_deg_rthr_to_deg_s_rthz;
use nalgebra::{Matrix3, Vector3};

/// A named spacecraft: a scenario and its settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Preset {
    /// Short name (`small-sat`, `microsat`).
    pub name: &'static str,
    /// The manoeuvre.
    pub scenario: Scenario,
    /// Inertia, sensors and everything else.
    pub common: Common,
}

fn slews(list: &[([f64; 3], f64, f64)], duration_s: f64) -> Vec<Slew> {
    let deg = core::f64::consts::PI / 180.0;
    list.iter()
        .map(|&(axis, angle_deg, start_s)| Slew {
            axis: Vector3::from(axis),
            angle_rad: angle_deg * deg,
            start_s,
            duration_s,
        })
        .collect()
}

/// The numbers of [`Preset::throw`].
///
/// A 0.5 kg device of 12 × 8 × 5 cm (`m(b² + c²)/12` ≈ 3.7e-4, 7.0e-4, 8.7e-4 kg m², with
/// small products) thrown tumbling at about 10 rad/s; a flywheel of spin inertia 5e-6
/// kg m² on body z spun from rest to 600 rad/s (about 5700 rpm, 95 Hz) by a raised-cosine
/// torque between 0.1 s and 0.3 s; a MEMS gyro of 0.01 deg/s/√Hz sampled at 4 kHz; the
/// speed telemetered in steps of 10 rpm at 100 Hz; an aerodynamic force of about 0.05 N
/// acting 5 mm off the centre of mass (2.7e-4 N m, fixed in the inertial frame); air drag
/// D = 4e-6 N m s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThrowNumbers {
    /// Spin inertia of the flywheel, kg m².
    pub rotor_spin_inertia_kg_m2: f64,
    /// Final flywheel speed, rad/s.
    pub rotor_speed_rad_s: f64,
    /// Gyro vibration amplitude across the rotor axis, rad/s.
    pub vibration_rad_s: f64,
    /// Speed telemetry step, rad/s.
    pub speed_step_rad_s: f64,
    /// Speed telemetry rate, Hz.
    pub speed_hz: f64,
    /// Aerodynamic torque fixed in the inertial frame, N m.
    pub inertial_torque_nm: [f64; 3],
    /// Air drag coefficient D, N m s.
    pub damping_nms: f64,
}

/// The lab throw's numbers.
pub const THROW: ThrowNumbers = ThrowNumbers {
    rotor_spin_inertia_kg_m2: 5e-6,
    rotor_speed_rad_s: 600.0,
    vibration_rad_s: 0.02,
    speed_step_rad_s: 10.0 * core::f64::consts::PI / 30.0,
    speed_hz: 100.0,
    inertial_torque_nm: [2e-4, -1.5e-4, 1e-4],
    damping_nms: 4e-6,
};

/// A lab effect of [`Preset::throw`] that can be switched off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LabEffect {
    /// The gyro's vibration at the rotor frequency.
    Vibration,
    /// Quantisation and hold of the speed telemetry.
    SpeedTelemetry,
    /// The aerodynamic torque fixed in the inertial frame.
    InertialTorque,
    /// The air drag `−D ω`.
    Drag,
}

impl LabEffect {
    /// Every lab effect.
    pub const ALL: [LabEffect; 4] = [
        LabEffect::Vibration,
        LabEffect::SpeedTelemetry,
        LabEffect::InertialTorque,
        LabEffect::Drag,
    ];
}

impl Preset {
    /// The hand-thrown lab device (module docs, [`THROW`]).
    #[must_use]
    pub fn throw() -> Self {
        let n = THROW;
        let rho_max = n.rotor_spin_inertia_kg_m2 * n.rotor_speed_rad_s;
        let plan = SpinPlan {
            duration_s: 0.5,
            initial_omega_rad_s: Vector3::new(5.0, -4.0, 7.0),
            pulse: WheelPulse {
                axis: Vector3::z(),
                delta_rho_nms: rho_max,
                start_s: 0.1,
                duration_s: 0.2,
            },
        };
        let realism = Realism {
            attitude: AttitudeSource::GyroPropagated,
            wheels: WheelTelemetry {
                quantization_nms: n.rotor_spin_inertia_kg_m2 * n.speed_step_rad_s,
                hold_hz: Some(n.speed_hz),
                ..WheelTelemetry::default()
            },
            environment: Environment {
                inertial_torque_nm: Vector3::from(n.inertial_torque_nm),
                damping_nms: n.damping_nms,
                ..Environment::default()
            },
            vibration: RotorVibration {
                amplitude_rad_s: Vector3::new(n.vibration_rad_s, n.vibration_rad_s, 0.0),
                phase_rad: Vector3::new(0.0, core::f64::consts::FRAC_PI_2, 0.0),
                rotor_spin_inertia_kg_m2: n.rotor_spin_inertia_kg_m2,
            },
            ..Realism::default()
        };
        Self {
            name: "throw",
            scenario: Scenario::Spin(plan),
            common: Common {
                inertia_kg_m2: Matrix3::new(
                    3.7e-4, 1.2e-5, -8e-6, //
                    1.2e-5, 7.0e-4, 1.5e-5, //
                    -8e-6, 1.5e-5, 8.7e-4,
                ),
                dt_s: 2.5e-4,
                duration_s: None,
                substeps: 2,
                disturbance_nm_rthz: 0.0,
                gyro_noise_deg_s_rthz: 0.01,
                seed: 1,
                inertia_change: None,
                realism,
            },
        }
    }

    /// [`Preset::throw`] without the effects listed.
    #[must_use]
    pub fn throw_without(off: &[LabEffect]) -> Self {
        let mut p = Self::throw();
        let r = &mut p.common.realism;
        for e in off {
            match e {
                LabEffect::Vibration => r.vibration = RotorVibration::default(),
                LabEffect::SpeedTelemetry => r.wheels = WheelTelemetry::default(),
                LabEffect::InertialTorque => r.environment.inertial_torque_nm = Vector3::zeros(),
                LabEffect::Drag => r.environment.damping_nms = 0.0,
            }
        }
        p
    }

    /// [`Preset::throw`] with only the effects listed.
    #[must_use]
    pub fn throw_with(on: &[LabEffect]) -> Self {
        let off: std::vec::Vec<LabEffect> = LabEffect::ALL
            .into_iter()
            .filter(|e| !on.contains(e))
            .collect();
        Self::throw_without(&off)
    }

    /// The 12U-class small satellite (module docs).
    #[must_use]
    pub fn small_sat() -> Self {
        let plan = SlewPlan {
            duration_s: 600.0,
            slews: slews(
                &[
                    ([1.0, 0.0, 0.0], 40.0, 10.0),
                    ([0.0, 1.0, 0.0], -35.0, 110.0),
                    ([0.0, 0.0, 1.0], 45.0, 210.0),
                    ([1.0, 1.0, 0.0], 30.0, 310.0),
                    ([0.0, 1.0, -1.0], -40.0, 410.0),
                    ([1.0, 1.0, 1.0], 45.0, 510.0),
                ],
                60.0,
            ),
            nominal_inertia_kg_m2: Matrix3::from_diagonal(&Vector3::new(0.3, 0.3, 0.2)),
            natural_freq_rad_s: 0.2,
            damping: 0.8,
            momentum_bias_nms: Vector3::zeros(),
        };
        let realism = Realism {
            attitude: AttitudeSource::Mekf,
            gyro: GyroErrors {
                bias_deg_h: Vector3::new(2.0, -1.5, 1.0),
                bias_instability_deg_h: 0.5,
                bias_correlation_s: 600.0,
            },
            star_tracker: StarTracker {
                noise_arcsec: Vector3::new(5.0, 5.0, 40.0),
                boresight_body: Vector3::z(),
                rate_hz: Some(5.0),
            },
            mekf: MekfSettings::default(),
            wheels: WheelTelemetry {
                quantization_nms: 1e-5,
                ..WheelTelemetry::default()
            },
            commands: Some(CommandHold::at(10.0)),
            ..Realism::default()
        };
        Self {
            name: "small-sat",
            scenario: Scenario::Slew(plan),
            common: Common {
                inertia_kg_m2: Matrix3::new(
                    0.31, -0.006, 0.004, //
                    -0.006, 0.27, 0.002, //
                    0.004, 0.002, 0.18,
                ),
                dt_s: 0.1,
                duration_s: None,
                substeps: 20,
                disturbance_nm_rthz: 1e-8,
                gyro_noise_deg_s_rthz: arw_deg_rthr_to_deg_s_rthz(0.15),
                seed: 1,
                inertia_change: None,
                realism,
            },
        }
    }

    /// The three-axis microsatellite (module docs).
    #[must_use]
    pub fn microsat() -> Self {
        let plan = SlewPlan {
            duration_s: 900.0,
            slews: slews(
                &[
                    ([1.0, 0.0, 0.0], 45.0, 10.0),
                    ([0.0, 1.0, 0.0], -60.0, 160.0),
                    ([0.0, 0.0, 1.0], 50.0, 310.0),
                    ([1.0, 1.0, 0.0], 30.0, 460.0),
                    ([0.0, 1.0, -1.0], -45.0, 610.0),
                    ([1.0, 1.0, 1.0], 60.0, 760.0),
                ],
                90.0,
            ),
            nominal_inertia_kg_m2: Matrix3::from_diagonal(&Vector3::new(4.5, 5.0, 3.5)),
            natural_freq_rad_s: 0.15,
            damping: 0.8,
            momentum_bias_nms: Vector3::zeros(),
        };
        let realism = Realism {
            attitude: AttitudeSource::Mekf,
            gyro: GyroErrors {
                bias_deg_h: Vector3::new(0.3, -0.2, 0.25),
                bias_instability_deg_h: 0.05,
                bias_correlation_s: 1800.0,
            },
            star_tracker: StarTracker {
                noise_arcsec: Vector3::new(3.0, 3.0, 25.0),
                boresight_body: Vector3::z(),
                rate_hz: Some(10.0),
            },
            mekf: MekfSettings {
                initial_bias_sigma_deg_h: 1.0,
                ..MekfSettings::default()
            },
            wheels: WheelTelemetry {
                quantization_nms: 4e-6,
                ..WheelTelemetry::default()
            },
            commands: Some(CommandHold::at(5.0)),
            ..Realism::default()
        };
        Self {
            name: "microsat",
            scenario: Scenario::Slew(plan),
            common: Common {
                inertia_kg_m2: Matrix3::new(
                    4.6, 0.05, -0.08, //
                    0.05, 5.1, 0.03, //
                    -0.08, 0.03, 3.7,
                ),
                dt_s: 0.1,
                duration_s: None,
                substeps: 20,
                disturbance_nm_rthz: 5e-8,
                gyro_noise_deg_s_rthz: arw_deg_rthr_to_deg_s_rthz(0.02),
                seed: 1,
                inertia_change: None,
                realism,
            },
        }
    }

    /// A preset by its [`Preset::name`].
    #[must_use]
    pub fn by_name(name: &str) -> Option<Self> {
        match name {
            "small-sat" => Some(Self::small_sat()),
            "microsat" => Some(Self::microsat()),
            "throw" => Some(Self::throw()),
            _ => None,
        }
    }

    /// Simulate the preset.
    pub fn simulate(&self) -> Result<SimOutput, SimError> {
        self.scenario.simulate(&self.common)
    }

    /// The preset thrown another way, drawn from `seed` (the throw: one throw of a set,
    /// each tumbling its own way): a spin's initial rate turned about a uniformly drawn
    /// axis by an angle uniform in [0, π) (its magnitude kept), and the torque fixed in
    /// the inertial frame along a uniformly drawn direction (its magnitude kept). Other
    /// presets are returned as they are. The noise seed is the preset's own.
    #[must_use]
    pub fn with_drawn_tumble(mut self, seed: u64) -> Self {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        // A stream of its own: the simulator's noise streams share the seed.
        rng.set_stream(0x7475_6d62_6c65);
        // Uniform on the sphere: a normal vector's direction.
        fn direction(rng: &mut impl Rng) -> Vector3<f64> {
            loop {
                let v = Vector3::from_fn(|_, _| rng.sample::<f64, _>(rand_distr::StandardNormal));
                if v.norm() > 1e-9 {
                    break v.normalize();
                }
            }
        }
        if let Scenario::Spin(plan) = &mut self.scenario {
            let axis = nalgebra::Unit::new_normalize(direction(&mut rng));
            let angle = rng.random_range(0.0..core::f64::consts::PI);
            plan.initial_omega_rad_s =
                nalgebra::Rotation3::from_axis_angle(&axis, angle) * plan.initial_omega_rad_s;
            let env = &mut self.common.realism.environment;
            env.inertial_torque_nm = direction(&mut rng) * env.inertial_torque_nm.norm();
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The throw turns the lab effects on, and each can be switched off.
    #[test]
    fn throw_effects_are_on_and_can_be_switched_off() {
        let r = Preset::throw().common.realism;
        assert!(r.vibration.is_active() && r.wheels.is_active() && r.environment.is_active());
        let all = [
            LabEffect::Vibration,
            LabEffect::SpeedTelemetry,
            LabEffect::InertialTorque,
            LabEffect::Drag,
        ];
        let bare = Preset::throw_without(&all).common.realism;
        assert!(!bare.vibration.is_active());
        assert!(!bare.wheels.is_active() && !bare.environment.is_active());
    }

    /// A drawn tumble keeps the rate's and the torque's magnitudes, and the torque's
    /// direction is uniform on the sphere: over 2000 draws, the mean of the unit vector is
    /// within 4/√(3·2000) of zero per axis (a uniform unit vector's component has
    /// variance 1/3). The rate's turn is checked only loosely (the mean angle between the
    /// drawn and the preset's rate between 0.5 and 1.5 rad).
    #[test]
    fn a_drawn_tumble_spreads_its_directions_and_keeps_magnitudes() {
        let base = Preset::throw();
        let Scenario::Spin(plan) = base.scenario else {
            panic!("the throw is a spin")
        };
        let (w0, tau0) = (
            plan.initial_omega_rad_s,
            base.common.realism.environment.inertial_torque_nm,
        );
        let n = 2000;
        let (mut mean_tau, mut mean_angle) = (Vector3::zeros(), 0.0);
        for seed in 0..n {
            let p = Preset::throw().with_drawn_tumble(seed);
            let Scenario::Spin(plan) = p.scenario else {
                panic!("spin")
            };
            let w = plan.initial_omega_rad_s;
            let tau = p.common.realism.environment.inertial_torque_nm;
            assert!((w.norm() - w0.norm()).abs() < 1e-12 * w0.norm());
            assert!((tau.norm() - tau0.norm()).abs() < 1e-12 * tau0.norm());
            mean_tau += tau / tau.norm();
            mean_angle += w.angle(&w0);
        }
        let n = n as f64;
        let bound = 4.0 / (3.0 * n).sqrt();
        assert!((mean_tau / n).amax() < bound, "{}", mean_tau / n);
        // The angle between w and w0 is at most the turn; its mean over uniform axes and
        // turns in [0, π) is well above 0 and below π/2 (a sanity bound, not a law).
        let mean_angle = mean_angle / n;
        assert!((0.5..1.5).contains(&mean_angle), "{mean_angle}");
        // Same seed, same throw.
        assert_eq!(
            Preset::throw().with_drawn_tumble(7).common.realism,
            Preset::throw().with_drawn_tumble(7).common.realism
        );
    }
}
