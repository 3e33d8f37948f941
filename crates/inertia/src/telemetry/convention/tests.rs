//! The gyro-unit check (rates in deg/s read as rad/s, or the
//! reverse, named as such) on honest data whose attitude is noisy: a star tracker
//! (5″/5″/40″, 10 Hz) with a FOG gyro on the paper's slew, the Monte Carlo matrix's
//! `slew | star tracker + FOG | 10 Hz` cell. There the differenced attitude of a step at
//! rest turns by its noise alone (~3e-3 rad/s), and the ratio of the gyro's rate to
//! it is noise; once its median fell by chance within 10 % of π/180, and the run stopped
//! with "the gyro rates are in rad/s, not deg/s" (here seed 19 of 20; in the matrix, whose
//! truth is the paper's J, one seed of 20 too); and the same steps hid real deg/s rates
//! (seed 1: not named). Now the same data in deg/s are named on every seed.

use super::{ConventionCheck, Reading, Verdict};
use crate::pipeline::{Pipeline, PipelineError, PipelineSettings};
use crate::sample::Sample;
use crate::sim::gyro::arw_deg_rthr_to_deg_s_rthz;
use crate::sim::scenario::{Common, Scenario};
use crate::sim::{AttitudeSource, CommandHold, StarTracker};
use std::vec::Vec;

/// The matrix's FOG, deg/√h.
const FOG_ARW: f64 = 0.02;

fn star_tracker_slew(seed: u64) -> Vec<Sample> {
    let mut c = Common {
        seed,
        gyro_noise_deg_s_rthz: arw_deg_rthr_to_deg_s_rthz(FOG_ARW),
        ..Common::physical()
    };
    c.realism.attitude = AttitudeSource::StarTracker;
    c.realism.star_tracker = StarTracker::default();
    c.realism.commands = Some(CommandHold::at(10.0));
    Scenario::slew().simulate(&c).unwrap().samples
}

fn unit_verdict(samples: &[Sample]) -> Option<Reading> {
    let mut check = ConventionCheck::default();
    for s in samples {
        check.push(s);
        if let Verdict::Wrong { reading, .. } = check.verdict() {
            if matches!(reading, Reading::GyroDegrees | Reading::GyroRadians) {
                return Some(reading);
            }
        }
    }
    None
}

#[test]
fn a_noisy_attitude_is_not_taken_for_a_gyro_unit() {
    let mut named = Vec::new();
    for seed in 1..=20 {
        let s = star_tracker_slew(seed);
        if let Some(r) = unit_verdict(&s) {
            named.push((seed, r));
        }
        // In deg/s the rates are named, on every seed.
        let deg: Vec<Sample> = s
            .iter()
            .map(|x| Sample {
                omega_rad_s: x.omega_rad_s.map(|w| w * (180.0 / core::f64::consts::PI)),
                ..*x
            })
            .collect();
        assert_eq!(
            unit_verdict(&deg),
            Some(Reading::GyroDegrees),
            "seed {seed}"
        );
    }
    assert!(named.is_empty(), "honest rad/s data named: {named:?}");
    // And the pipeline runs through the seed that stopped.
    let mut p = Pipeline::new(&PipelineSettings::default()).unwrap();
    for (i, s) in star_tracker_slew(19).iter().enumerate() {
        if let Err(e) = p.push(s) {
            assert!(
                !matches!(e, PipelineError::AttitudeConvention { .. }),
                "{i}: {e}"
            );
        }
    }
}
