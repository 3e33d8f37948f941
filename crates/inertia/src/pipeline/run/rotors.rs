//! The spacecraft file's rotor uncertainty in a run: measured as a consider term
//! ([`crate::estimator::rotor_inertia`]) or, asked for in a batch run, estimated with J
//! ([`crate::estimator::rotor_calibration`]).

use super::{batch_with, BatchOutput, Mode, Pipeline, PipelineConfig};
use super::{PipelineError, Run, RunError, RunErrorKind};
use crate::estimator::rotor_calibration::{
    self, NotMade, RotorCalibration, RotorFit, MIN_MOMENTUM_SIGNIFICANCE,
};
use crate::estimator::rotor_inertia::{
    self, Change, RotorInertiaConsider, RotorInertiaError, Source,
};
use crate::pipeline::interface::BatchInputs;
use crate::sample::Sample;
use crate::spacecraft::Spacecraft;
use std::vec::Vec;

/// A batch estimate with the rotor parameters, or why they were not estimated (then
/// they are left to the consider term).
pub(super) enum Calibrated {
    /// The estimate and the parameters.
    Done(std::boxed::Box<BatchOutput>, RotorCalibration),
    /// Not estimated, and why.
    NotMade(NotMade),
}

/// The batch estimate of `samples` (their rotor momentum from `sc`'s rotors, `speeds` one
/// per rotor and sample, read `delay_s` late) with the rotor parameters
/// ([`crate::estimator::rotor_calibration`]): estimated about the file's values, then once
/// more about those estimates (the tilts' first-order model re-linearised where the
/// estimate moved), each time with the file's σ about the file's values as the prior.
/// The parameters are reported against the file's values. None with a known torque, with
/// a record whose total momentum does not stand out from its scatter by
/// [`MIN_MOMENTUM_SIGNIFICANCE`] (unless every parameter is a time tag), or where the
/// rows give no fit of them ([`NotMade`]).
pub(super) fn calibrated_batch(
    samples: &[Sample],
    config: &PipelineConfig,
    sc: &Spacecraft,
    speeds: &[f64],
    delay_s: f64,
) -> Result<Calibrated, PipelineError> {
    let m = sc.rotors.len();
    if m == 0 || speeds.len() != samples.len() * m {
        return Ok(Calibrated::NotMade(NotMade::NoFit));
    }
    // A known torque fixes the momentum's scale that the calibration takes as its gauge
    // ([`crate::estimator::rotor_calibration`], "The overall scale").
    if samples
        .iter()
        .any(|s| s.tau_nm != nalgebra::Vector3::zeros())
    {
        return Ok(Calibrated::NotMade(NotMade::KnownTorque));
    }
    let sources = rotor_inertia::sources(sc);
    let momenta = |sc: &Spacecraft, sources: &[Source], tags_s: &[f64]| -> Vec<_> {
        sources
            .iter()
            .map(|s| {
                rotor_inertia::source_momentum(samples, speeds, sc, &s.change, delay_s, tags_s)
            })
            .collect()
    };
    let first = batch_with(
        samples,
        config,
        &BatchInputs {
            momenta: momenta(sc, &sources, &[]),
            prior_mean: vec![0.0; sources.len()],
            records: Vec::new(),
        },
    )?;
    let (Some(fit), Some(j)) = (
        first.diagnostics.rotor_calibration.clone(),
        first.estimate.j(),
    ) else {
        return Ok(Calibrated::NotMade(NotMade::NoFit));
    };
    let momentum = rotor_calibration::total_momentum(samples, &j);
    // Time tags alone need no total momentum: their columns, `δ_i ρ̇_i`, are not a
    // calibration of the rotor momentum (`M ρ`) that J can take up.
    let tags_only = sources
        .iter()
        .all(|s| matches!(s.change, Change::TimeTag { .. }));
    if !tags_only && !(momentum.1 >= MIN_MOMENTUM_SIGNIFICANCE) {
        return Ok(Calibrated::NotMade(NotMade::NoMomentum {
            ratio: momentum.0,
            significance: momentum.1,
        }));
    }
    // The rotors at the estimate, and the samples' momentum from them (each rotor read at
    // its own time tag).
    let (moved, tags_s) = moved(sc, &sources, &fit.value);
    let mut again: Vec<Sample> = samples.to_vec();
    let rho = rotor_inertia::momentum(samples, speeds, &moved, delay_s, &tags_s);
    for (s, r) in again.iter_mut().zip(rho) {
        s.rho_nms = r;
    }
    // The same sources about the moved rotors: each rotor's directions turned with its axis
    // (the file's tilt directions carried along, so that the second pass's values add to
    // the first's; `Rotor::tilt_directions` of a moved axis may be others).
    let turns: Vec<nalgebra::Matrix3<f64>> = sc
        .rotors
        .iter()
        .zip(&moved.rotors)
        .map(|(a, b)| minimal_rotation(&a.axis.into(), &b.axis.into()))
        .collect();
    let second_sources: Vec<Source> = sources
        .iter()
        .map(|s| Source {
            change: match &s.change {
                Change::Directions(d) => {
                    Change::Directions(d.iter().zip(&turns).map(|(d, t)| t * d).collect())
                }
                tag @ Change::TimeTag { .. } => tag.clone(),
            },
            ..s.clone()
        })
        .collect();
    let second = batch_with(
        &again,
        config,
        &BatchInputs {
            momenta: momenta(&moved, &second_sources, &tags_s),
            prior_mean: fit.value.iter().map(|z| -z).collect(),
            records: Vec::new(),
        },
    )?;
    let Some(f) = second.diagnostics.rotor_calibration.as_ref() else {
        return Ok(Calibrated::NotMade(NotMade::NoFit));
    };
    let total = RotorFit {
        value: f.value.iter().zip(&fit.value).map(|(a, b)| a + b).collect(),
        ..f.clone()
    };
    let report = RotorCalibration::new(&sources, &total, momentum);
    Ok(Calibrated::Done(std::boxed::Box::new(second), report))
}

/// The spacecraft file and the rotors' speeds, where a calibration of every error was not
/// made (for want of a total momentum, or of a fit) and the file states both time tags
/// and other errors: the time tags need no total momentum (their columns `δ_i ρ̇_i` are
/// no calibration of the rotor momentum that J could take up), so they are calibrated
/// alone ([`batch_with_tags`]) and the rest stays a consider term
/// ([`Run::apply_rotor_consider`]).
pub(super) fn tags_alone(
    why: NotMade,
    sc: &Spacecraft,
    speeds: &[f64],
) -> Option<(Spacecraft, Vec<f64>)> {
    let tagged = sc.rotors.iter().any(|r| r.time_tag_sigma_s > 0.0);
    let retry = matches!(why, NotMade::NoMomentum { .. } | NotMade::NoFit);
    (retry && tagged && without_time_tags(sc).has_inertia_sigma())
        .then(|| (sc.clone(), speeds.to_vec()))
}

/// `sc` without its rotors' time-tag σ.
pub(super) fn without_time_tags(sc: &Spacecraft) -> Spacecraft {
    let mut rest = sc.clone();
    for r in &mut rest.rotors {
        r.time_tag_sigma_s = 0.0;
    }
    rest
}

/// `sc` with its rotors' time-tag σ alone.
fn time_tags_only(sc: &Spacecraft) -> Spacecraft {
    let mut tags = sc.clone();
    for r in &mut tags.rotors {
        r.spin_inertia_sigma_kg_m2 = 0.0;
        r.spin_axis_sigma_deg = 0.0;
    }
    tags
}

/// The batch estimate of the records of `samples`, with the time tags of `tags` (the
/// spacecraft file and its speeds; [`tags_alone`]) calibrated where given; their
/// calibration goes to `calibration`. Each time tag's σ also carries the file's other
/// errors, which are not estimated: in quadrature, its move when the calibration is made
/// again with the rotors moved by each other error's 1σ (the row model pinned to the
/// answer's). Where one of those calibrations gives no answer, each time tag's σ is at
/// least the file's. Where the time tags cannot be calibrated either, they join the
/// rest's consider term `considered` ([`with_tags_considered`]). (Several records are
/// not calibrated: `Run::next_record` refuses the calibration.)
pub(super) fn batch_with_tags(
    samples: &[Sample],
    config: &PipelineConfig,
    tags: Option<(Spacecraft, Vec<f64>)>,
    delay_s: f64,
    starts: &[usize],
    calibration: &mut Option<RotorCalibration>,
    considered: &mut Option<Result<RotorInertiaConsider, RotorInertiaError>>,
) -> Result<BatchOutput, PipelineError> {
    let Some((file, speeds)) = tags else {
        return crate::pipeline::batch_of_records(samples, config, starts);
    };
    let only = time_tags_only(&file);
    let Ok(Calibrated::Done(o, mut c)) = calibrated_batch(samples, config, &only, &speeds, delay_s)
    else {
        let config = with_tags_considered(samples, config, &only, &speeds, delay_s, considered);
        return crate::pipeline::batch_of_records(samples, &config, starts);
    };
    let pinned = config.pinned_to(o.diagnostics.row_model, o.diagnostics.torque_test);
    let others = rotor_inertia::sources(&without_time_tags(&file));
    let mut extra = vec![0.0; c.value.len()];
    let mut computed = true;
    for v in 0..others.len() {
        let z: Vec<f64> = (0..others.len())
            .map(|k| f64::from(u8::from(k == v)))
            .collect();
        let (moved_file, _) = moved(&file, &others, &z);
        let rho = rotor_inertia::momentum(samples, &speeds, &moved_file, delay_s, &[]);
        let changed: Vec<Sample> = samples
            .iter()
            .zip(rho)
            .map(|(s, r)| Sample { rho_nms: r, ..*s })
            .collect();
        let again = calibrated_batch(
            &changed,
            &pinned,
            &time_tags_only(&moved_file),
            &speeds,
            delay_s,
        );
        match again {
            Ok(Calibrated::Done(_, cv))
                if cv.value.len() == c.value.len() && cv.value.iter().all(|x| x.is_finite()) =>
            {
                for ((e, a), b) in extra.iter_mut().zip(&cv.value).zip(&c.value) {
                    *e += (a - b) * (a - b);
                }
            }
            _ => computed = false,
        }
    }
    for ((s, e), p) in c.sigma.iter_mut().zip(&extra).zip(&c.prior_sigma) {
        *s = crate::math::sqrt(*s * *s + e);
        if !computed {
            *s = s.max(*p);
        }
    }
    *calibration = Some(c);
    Ok(*o)
}

/// `config` with the time tags of `only` (a file with time tags alone) as a consider
/// term beside the rest's, `considered`, where they could not be calibrated: measured as
/// [`Run::apply_rotor_consider`] measures it and added to the rest's sources (σ of
/// independent sources adds in quadrature); where either cannot be computed, σ widened
/// by the time tags' share of the rotor momentum, as that fallback does.
fn with_tags_considered(
    samples: &[Sample],
    config: &PipelineConfig,
    only: &Spacecraft,
    speeds: &[f64],
    delay_s: f64,
    considered: &mut Option<Result<RotorInertiaConsider, RotorInertiaError>>,
) -> PipelineConfig {
    let mut solved = *config;
    let mut first = true;
    let solve = |s: &[Sample]| -> Option<crate::tensor::InertiaVector> {
        let o = crate::pipeline::batch_of_records(s, &solved, &[]).ok()?;
        if core::mem::take(&mut first) {
            solved = solved.pinned_to(o.diagnostics.row_model, o.diagnostics.torque_test);
        }
        o.estimate.j()
    };
    let mut out = *config;
    match (
        considered.as_mut(),
        rotor_inertia::consider(samples, speeds, only, delay_s, solve),
    ) {
        (Some(Ok(rest)), Ok(tags)) => {
            rest.sources.extend(tags.sources);
            rest.moves_kg_m2.extend(tags.moves_kg_m2);
            out.rotor_inertia_consider = Some(rest.consider_kg_m2());
        }
        _ => {
            let r = rotor_inertia::time_tag_relative_sigma(samples, speeds, only, delay_s);
            let old = out.rotor_scale_sigma.unwrap_or(0.0);
            out.rotor_scale_sigma = Some(crate::math::sqrt(old * old + r * r));
        }
    }
    out
}

/// The smallest rotation taking the unit vector `a` to the unit vector `b` (Rodrigues:
/// `I + [v]× + [v]×² / (1 + c)`, `v = a × b`, `c = a·b`).
fn minimal_rotation(
    a: &nalgebra::Vector3<f64>,
    b: &nalgebra::Vector3<f64>,
) -> nalgebra::Matrix3<f64> {
    let v = a.cross(b);
    let c = a.dot(b);
    let k = crate::attitude::skew(&v);
    if c <= -1.0 + 1e-12 {
        // Opposite: no axis is smallest; not a small tilt, and not reached by `moved`.
        return nalgebra::Matrix3::identity();
    }
    nalgebra::Matrix3::identity() + k + k * k / (1.0 + c)
}

/// `sc` with each rotor's spin inertia and axis moved by the sources' values `z` (in
/// their σ): the inertia by its relative error, the axis turned by its two tilts (exactly,
/// not to first order); and each rotor's own time tag, s. The σ stay relative to the
/// moved values.
fn moved(sc: &Spacecraft, sources: &[Source], z: &[f64]) -> (Spacecraft, Vec<f64>) {
    let mut out = sc.clone();
    let mut tags_s = vec![0.0; sc.rotors.len()];
    for (s, zv) in sources.iter().zip(z) {
        if let Change::TimeTag { rotor, sigma_s } = s.change {
            if let Some(t) = tags_s.get_mut(rotor) {
                *t += zv * sigma_s;
            }
        }
    }
    for (i, r) in out.rotors.iter_mut().enumerate() {
        let axis = nalgebra::Vector3::from(r.axis);
        let mut scale = 0.0;
        let mut tilt = nalgebra::Vector3::zeros();
        for (s, zv) in sources.iter().zip(z) {
            let Change::Directions(directions) = &s.change else {
                continue;
            };
            let d = directions[i] * *zv;
            scale += d.dot(&axis);
            tilt += d - axis * d.dot(&axis);
        }
        let relative = r.relative_sigma();
        r.spin_inertia_kg_m2 *= 1.0 + scale;
        r.spin_inertia_sigma_kg_m2 = relative * r.spin_inertia_kg_m2;
        // A tilt by the angle |t| towards t.
        let angle = tilt.norm();
        if angle > 0.0 {
            let a = axis * angle.cos() + tilt / angle * angle.sin();
            r.axis = a.normalize().into();
        }
    }
    (out, tags_s)
}

impl Run {
    /// Refuse a rotor calibration without a spacecraft file whose rotors have a σ.
    pub(super) fn check_calibration(&self, index: usize) -> Result<(), RunError> {
        if self.config.calibrate_rotors
            && !self.rotors.as_ref().is_some_and(|r| r.has_inertia_sigma())
        {
            return Err(RunError::at(
                index,
                RunErrorKind::Pipeline(PipelineError::NeedsSetting {
                    setting: "calibrate_rotors",
                    needs: "spacecraft",
                    requirement: "with a σ for some rotor's spin inertia, axis or time tag",
                    why: "the rotors' parameters are estimated about the file's values, the file's σ their prior",
                }),
            ));
        }
        Ok(())
    }

    /// The rotor parameters estimated with J (`None` without a calibration asked for, or
    /// before [`Self::finish`]), in the spacecraft file's units.
    #[must_use]
    pub fn rotor_calibration(&self) -> Option<&RotorCalibration> {
        self.calibration.as_ref()
    }

    /// A calibration asked for and not made, and why; the rotors' σ is then their consider
    /// term ([`Self::rotor_inertia`]).
    #[must_use]
    pub fn rotor_calibration_not_made(&self) -> Option<NotMade> {
        self.calibration_not_made
    }

    /// Compute the rotors' consider term from the run's `samples` (where a spacecraft file's
    /// rotor has a spin-inertia σ) and put it into the configuration ([`super::status`]).
    /// Where it cannot be computed, σ is widened as if every rotor shared the file's
    /// relative σ, the root sum square of all
    /// ([`crate::spacecraft::Spacecraft::stated_relative_sigma`], with the time tags' share
    /// of these samples' rotor momentum, `rotor_inertia::time_tag_relative_sigma`; the
    /// common scale's term, [`super::status`]), and the reason kept
    /// ([`Self::rotor_inertia`]).
    pub(super) fn apply_rotor_consider(&mut self, samples: &[Sample]) {
        let Some(file) = self.rotors.as_ref().filter(|r| r.has_inertia_sigma()) else {
            return;
        };
        // Time tags calibrated alone are not considered.
        let rest;
        let sc = if self.tags_alone.is_some() {
            rest = without_time_tags(file);
            &rest
        } else {
            file
        };
        if self.rotor_consider.is_some() {
            return;
        }
        let delay_s = match &self.delay {
            Some(Ok(d)) => d.delay_s,
            _ => 0.0,
        };
        // The first solve is the data's own; the later ones (the data changed by each
        // error source) keep the row model it chose, so that they measure its
        // sensitivity rather than a switch of model.
        let mut config = self.config.with_delay_applied();
        let batch_mode = matches!(self.mode, Mode::Batch { .. });
        let mut first = true;
        let starts = self.records.starts.clone();
        let solve = |s: &[Sample]| -> Option<crate::tensor::InertiaVector> {
            let (j, rows, torque) = if batch_mode {
                let o = crate::pipeline::batch_of_records(s, &config, &starts).ok()?;
                (
                    o.estimate.j(),
                    o.diagnostics.row_model,
                    o.diagnostics.torque_test,
                )
            } else {
                let mut p = Pipeline::from_config(config).ok()?;
                for x in s {
                    p.push_each(x, |_| {}).ok()?;
                }
                let d = p.diagnostics();
                (p.last()?.j(), d.row_model, d.torque_test)
            };
            if core::mem::take(&mut first) {
                config = config.pinned_to(rows, torque);
            }
            j
        };
        let c = rotor_inertia::consider(samples, &self.rotor_speeds, sc, delay_s, solve);
        match &c {
            Ok(c) => self.config.rotor_inertia_consider = Some(c.consider_kg_m2()),
            Err(_) => {
                // The file's relative σ, with the time tags' on these samples.
                let tags = rotor_inertia::time_tag_relative_sigma(
                    samples,
                    &self.rotor_speeds,
                    sc,
                    delay_s,
                );
                let r = crate::math::sqrt(sc.stated_relative_sigma().powi(2) + tags * tags);
                self.rotor_fallback_sigma = r;
                let old = self.config.rotor_scale_sigma.unwrap_or(0.0);
                self.config.rotor_scale_sigma = Some(crate::math::sqrt(old * old + r * r));
                // Now in the common scale's: not twice in the checks' reference σ.
                self.config.rotor_inertia_relative_sigma = 0.0;
            }
        }
        self.rotor_consider = Some(c);
        self.rotor_speeds = Vec::new();
    }
}

#[cfg(all(test, feature = "sim"))]
mod tests {
    use super::*;
    use crate::sim::rotors::{pyramid, speeds};
    use crate::sim::scenario::{Common, Scenario};
    use crate::spacecraft::RotorErrors;

    /// Problem: the time tags could not be calibrated alone (the fallback called
    /// directly) on a 60 s slew with four wheels whose file states tilts of σ 0.5° and
    /// time tags of σ 50 ms; the tilts' consider term measured first. Reference: the
    /// consider term of every source of the file at once. The time tags join the tilts'
    /// sources, and the consider term is the whole file's (the same solves, to 1e-12).
    #[test]
    fn time_tags_not_calibrated_join_the_rest_of_the_consider_term() {
        let mut file = pyramid(
            [1.5e-3, 1.6e-3, 1.7e-3, 1.8e-3],
            0.0,
            RotorErrors::Independent,
        );
        for r in &mut file.rotors {
            r.spin_axis_sigma_deg = 0.5;
            r.time_tag_sigma_s = 0.05;
        }
        let out = Scenario::slew()
            .simulate(&Common {
                duration_s: Some(60.0),
                ..Common::physical()
            })
            .expect("sim");
        let w = speeds(&out.samples, &file).expect("speeds");
        let config = crate::pipeline::PipelineSettings::default()
            .validate()
            .expect("settings");
        let consider = |sc: &Spacecraft| {
            let mut solved = config;
            let mut first = true;
            rotor_inertia::consider(&out.samples, &w, sc, 0.0, |s: &[Sample]| {
                let o = crate::pipeline::batch_of_records(s, &solved, &[]).ok()?;
                if core::mem::take(&mut first) {
                    solved = solved.pinned_to(o.diagnostics.row_model, o.diagnostics.torque_test);
                }
                o.estimate.j()
            })
            .expect("consider")
        };
        let all = consider(&file);
        let rest = consider(&without_time_tags(&file));
        assert_eq!(rest.sources.len(), 8);
        let mut considered = Some(Ok(rest.clone()));
        let with_rest = PipelineConfig {
            rotor_inertia_consider: Some(rest.consider_kg_m2()),
            ..config
        };
        let out_config = with_tags_considered(
            &out.samples,
            &with_rest,
            &time_tags_only(&file),
            &w,
            0.0,
            &mut considered,
        );
        let Some(Ok(joined)) = considered else {
            panic!("the consider term")
        };
        assert_eq!(joined.sources, all.sources);
        let (got, want) = (
            out_config.rotor_inertia_consider.expect("σ"),
            all.consider_kg_m2(),
        );
        for k in 0..6 {
            assert!(
                (got[k] - want[k]).abs() <= 1e-12 * want[k] && got[k] > rest.consider_kg_m2()[k],
                "{got:?} against {want:?}"
            );
        }
    }
}
