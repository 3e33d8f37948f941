//! The report of a run's newest estimate: the estimator's report with what the run
//! adds (the time tag, the rotors, the held speeds, the gyro's range, the input, the
//! known torque's scale term of the outside estimates).

use super::{Mode, Run};

impl Run {
    /// The report of the newest estimate (`None` before one), with the input summarised
    /// as `file` with the reader's counts `stats`.
    #[must_use]
    pub fn report(
        &self,
        file: &str,
        stats: &crate::telemetry::csv::ReadStats,
    ) -> Option<crate::pipeline::report::Report> {
        let mut report = match &self.mode {
            Mode::Streaming(p) => crate::pipeline::report::Report::of_pipeline(p)?,
            Mode::Batch { samples, out } => crate::pipeline::report::Report::of_batch(
                out.as_ref()?,
                &self.config,
                samples.len(),
            ),
        };
        // The known torque's scale term of the residual dipole and the centre of mass
        // (`torque_scale_term`) joins their σ.
        if let (Some(o), Some(m)) = (report.outside.as_mut(), self.outside_scale_move) {
            *o = o.widened(&m);
        }
        // With the time tags calibrated alone, the consider term is the rest's.
        let rest = self
            .rotors
            .as_ref()
            .filter(|_| self.calibration.is_some() && self.calibration_not_made.is_some())
            .map(super::rotors::without_time_tags);
        Some(
            report
                .with_wheel_delay(self.delay.as_ref())
                .with_rotor_inertia(
                    rest.as_ref().or(self.rotors.as_ref()),
                    self.rotor_consider.as_ref(),
                    self.rotor_fallback_sigma,
                )
                .with_rotor_calibration(self.calibration.as_ref(), self.calibration_not_made)
                .with_held_speeds(self.held_speeds_period_samples().map(|p| {
                    (
                        p,
                        p as f64 * self.input_step_s(),
                        self.last()
                            .and_then(|e| e.uncertainty)
                            .is_some_and(|u| u.time_tag_kg_m2.iter().any(|&x| x > 0.0)),
                    )
                }))
                .with_gyro_range(self.gyro_range.clipped().collect())
                .with_input(crate::pipeline::report::InputSummary {
                    file: file.into(),
                    sample_period_s: self.sample_period_s(),
                    renormalised: stats.renormalised,
                    sign_flips: stats.sign_flips,
                    min_step_s: stats.min_step_s,
                    max_step_s: stats.max_step_s,
                    attitude_from_gyro: stats.attitude_from_gyro,
                    records: self.records.count(),
                }),
        )
    }
}
