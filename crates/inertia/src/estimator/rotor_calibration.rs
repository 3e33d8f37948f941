//! The rotors' parameters estimated with J (issue #31 "Per-rotor parameters"): each
//! rotor's spin-inertia error and the two small tilts of its axis, as unknowns of the
//! discrete momentum rows in a batch run, each with the spacecraft file's σ as its prior
//! (`calibrate_rotors`; the run is `pipeline::Run`'s, which re-linearises once).
//!
//! **The model.** The file states each rotor's spin inertia `J_i` and axis `a_i`; the
//! true ones are `J_i (1 + ε_i)` and `a_i + θ_1,i e_1,i + θ_2,i e_2,i` (to first order in
//! the tilts, [`crate::spacecraft::Rotor::tilt_directions`]), so the true rotor momentum is
//!
//! ```text
//! ρ(t) = Σ_i J_i ω̃_i(t) [(1 + ε_i) a_i + θ_1,i e_1,i + θ_2,i e_2,i]
//!      = ρ_file(t) + Σ_v z_v δρ_v(t),       z_v ~ N(0, 1) a priori,
//! ```
//!
//! with one independent standard normal source `z_v` per error the file gives a σ
//! (the sources of `super::rotor_inertia`: one shared spin-inertia source or one per
//! rotor, two tilts per rotor, one time tag per rotor) and `δρ_v` that source's 1σ change
//! of the momentum (read at the run's wheel-speed time tag). A rotor whose telemetry
//! lags that time tag by `δ_i` (its speed read at `t` is the one of `t − δ_i`) has the
//! momentum `ρ_i(t + δ_i) ≈ ρ_i(t) + δ_i ρ̇_i(t)`: its source is `δ_i = z σ_δ,i` with
//! `δρ = σ_δ,i ρ̇_i`, the slope of the interpolated speeds
//! (`super::wheel_delay::shift_rho`) at the rotor's time tag. The rows of [`super::momentum_rows`] are linear in
//! `ρ` (`ρ` enters their right-hand side `b`), so the rows of the true momentum are
//!
//! ```text
//! A x − Σ_v z_v Δb_v = b_file,        Δb_v = b(ρ_file + δρ_v) − b(ρ_file),
//! ```
//!
//! exactly: `z` is one more block of shared unknowns, its column `−Δb_v` the rows'
//! response to the source, formed by building the rows again from the changed momentum
//! (`columns`). (The adaptive stencil's curvature column is also linear in `ρ`; its
//! change, `κ Σ_v z_v …`, is of second order in the small `κ z` and left out.) The tilts'
//! first-order model leaves out `θ²/2` of a rotor's momentum along its axis, 1.5e-4 of
//! it at 1°, and a time tag's leaves out the curvature of `ρ_i` over `δ_i`: the run
//! estimates once about the file's values, then once more about the rotors moved to
//! that estimate (exactly: axes turned, inertias scaled, speeds read at the estimated
//! time tags; each rotor's
//! source directions turned with its axis by the smallest rotation, so that the second
//! pass's values are in the first's directions), its prior still the file's σ about the
//! file's values (a prior mean `−ẑ`), and reports the sum.
//!
//! **The prior.** Each `z_v` is a row `s z_v = s μ_v` beside the data rows (`μ_v` its
//! prior mean, 0 but in the second pass), `s²` the rows' residual variance (less the prior
//! rows' share `s² |ẑ − μ|²`) at the parameters held at their prior mean, then at the
//! estimate that weight gives (none where there is no residual: no fit): in the
//! rows' own noise units it is the file's statement `z_v ~ N(μ_v, 1)`. The least-squares
//! covariance of the answer then includes the parameters' uncertainty after the data,
//! and `j`'s reduced problem has them minimised out.
//!
//! **The overall scale.** Without a known torque the rows are homogeneous in `(J, h, ρ)`:
//! scaling all three leaves them satisfied, and shrinks their residual with them. A
//! parameter that can scale `ρ` would let least squares shrink J towards zero, bounded
//! only by its prior (the residual's gain from shrinking grows with the number of rows,
//! so the bias does too). So each
//! column is made free of the momentum's own scale: less its projection `γ_v` on the
//! column of `δρ = ρ` (`Δb_ρ = b(2ρ) − b(ρ)`, over all rows). The model then moves the
//! momentum only across its own scale, and that scale is the gauge: the rows give J at the
//! file's scale; the parameters found imply the scale `ĉ = Σ_v ẑ_v γ_v`, so the answer is
//! `ĵ (1 + ĉ)`, and the part the data leave open, `σ_c = √(γᵀ C γ)` (the posterior `C`),
//! is a consider term `σ_c |ĵ_k|` (`RotorFit::apply`). A scale common to every rotor has
//! a zero column and keeps its prior (the issue's "one overall scale unobservable, fixed
//! by a prior on the rotors' inertia"). A known torque would fix it and breaks the rows'
//! homogeneity, which this gauge does not handle: the run makes no calibration then
//! ([`NotMade::KnownTorque`]). The projection is made over the rows as built, before the
//! chains' initial momenta and J are minimised out: a column that J can partly absorb
//! keeps some of the shrinking direction after that reduction (a reviewer's argument, not
//! measured); where it would matter, with little total momentum, the run makes no
//! calibration (below).
//!
//! **What the data fix.** With `C` the parameters' posterior covariance (whitened units)
//! the data's information is `C⁻¹ − I`; a combination is fixed by the data where its
//! eigenvalue exceeds 1, the prior's information ([`RotorFit::data_fixed`]). With no
//! total angular momentum, six of the nine entries of the rotor momentum's calibration
//! are indistinguishable from J (`J ω = −ρ` holds for `(M J, M ρ)` with `M J`
//! symmetric), and along them least squares also shrinks the residual, as above: the tilts
//! estimated on the zero-momentum slew were 1–4 σ off and worse than the file's, and on
//! the small satellite so were the spin-inertia differences. So the run estimates the
//! parameters only where the record's total momentum stands out from its scatter by
//! [`MIN_MOMENTUM_SIGNIFICANCE`] (`total_momentum`); below it they stay a
//! consider term. Time tags alone are estimated whatever the momentum: their columns,
//! `δ_i ρ̇_i`, are no calibration `M ρ` of the rotor momentum for J to take up (on the
//! slew without a momentum bias, the calibrated error was that of the record with every
//! wheel on time, `tests/integration/rotor_time_tags.rs`); where the file also states
//! tilts or spin inertias and the record has no total momentum (or the calibration of
//! all gives no fit), the run calibrates the time tags alone, keeps the rest as a
//! consider term and widens each time tag's σ by the rest's share
//! (`pipeline::run::rotors::batch_with_tags`).
//!
//! **σ.** The posterior covariance takes the rows' errors as independent; along a chain
//! they are not (`super::jackknife`): on 120 s slews it alone would leave the time tags
//! found up to 8σ off. So each parameter's σ, and the overall scale's `σ_c`, is no
//! smaller than its jackknife over the same delete-one groups as J's
//! (`RotorFit::with_jackknife`; the worst time tag on those slews, with and without a
//! momentum bias, is then 2.2σ off).

use super::momentum_rows::{MomentumRowSettings, MomentumRows};
use super::EstimatorError;
use crate::sample::Sample;
use nalgebra::{DMatrix, Vector3};
use std::vec::Vec;

/// The rotor parameters after the data, in the sources' whitened units (a value of 1 is
/// the file's 1σ).
#[derive(Debug, Clone, PartialEq)]
pub struct RotorFit {
    /// Each source's value `ẑ_v` at the answer.
    pub value: Vec<f64>,
    /// Each source's σ after the data: its posterior σ (1 where the data add nothing to
    /// the prior), or its jackknife's where larger (`Self::with_jackknife`).
    pub sigma: Vec<f64>,
    /// How many independent combinations of the sources the data fix better than the
    /// prior (eigenvalues of the data's information beyond the prior's).
    pub data_fixed: usize,
    /// The overall scale of the rotor momentum the estimate implies, `ĉ = Σ_v ẑ_v γ_v`
    /// ([module docs](self), "The overall scale"): J is the rows' answer times `1 + ĉ`.
    pub scale: f64,
    /// Its σ, `√(γᵀ C γ)` (or its jackknife's where larger, `Self::with_jackknife`): the
    /// part of the rotors' uncertainty the rows cannot fix.
    pub scale_sigma: f64,
}

impl RotorFit {
    /// From the posterior covariance `c` of the sources (whitened) and their values.
    #[must_use]
    pub(crate) fn from_covariance(value: Vec<f64>, c: &DMatrix<f64>, gamma: &[f64]) -> Self {
        let n = value.len();
        let g = nalgebra::DVector::from_column_slice(gamma);
        let scale = value.iter().zip(gamma).map(|(z, g)| z * g).sum();
        let scale_sigma = (g.transpose() * c * &g)[(0, 0)].max(0.0).sqrt();
        let sigma = (0..n).map(|v| c[(v, v)].max(0.0).sqrt()).collect();
        // The data's information C⁻¹ − I, through C's eigenvalues λ: 1/λ − 1 > 1 ⇔ λ < ½.
        let data_fixed = c
            .clone()
            .symmetric_eigen()
            .eigenvalues
            .iter()
            .filter(|&&l| l < 0.5)
            .count();
        Self {
            value,
            sigma,
            data_fixed,
            scale,
            scale_sigma,
        }
    }
}

impl RotorFit {
    /// Each σ, and the overall scale's, no smaller than the jackknife's over the rows'
    /// chain groups (`jackknife`: one per source, then the scale's; `None`: none): the
    /// posterior covariance takes the rows' errors as independent, and along a chain they
    /// are not (`super::jackknife`). The count of combinations the data fix stays the
    /// least-squares one.
    #[must_use]
    pub(crate) fn with_jackknife(mut self, jackknife: Option<&[f64]>) -> Self {
        let n = self.sigma.len();
        if let Some(jk) = jackknife.filter(|jk| jk.len() == n + 1) {
            for (s, j) in self.sigma.iter_mut().zip(jk) {
                if j.is_finite() {
                    *s = s.max(*j);
                }
            }
            if jk[n].is_finite() {
                self.scale_sigma = self.scale_sigma.max(jk[n]);
            }
        }
        self
    }
}

/// Why a calibration asked for was not made (the rotors' σ is then their consider term,
/// `super::rotor_inertia`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum NotMade {
    /// The record's total angular momentum is `ratio` of the rotors' (RMS) and
    /// `significance` times its scatter along the record, below
    /// [`MIN_MOMENTUM_SIGNIFICANCE`]: the tilts cannot be told from J.
    NoMomentum {
        /// Its ratio to the rotors' momentum.
        ratio: f64,
        /// Its ratio to its own scatter.
        significance: f64,
    },
    /// The record has a known torque, which fixes the momentum's scale that the
    /// calibration takes as its gauge ([module docs](self), "The overall scale").
    KnownTorque,
    /// The rows gave no fit of the parameters (no answer, no residual to weigh the prior
    /// by, or not one speed per rotor and sample).
    NoFit,
}

impl core::fmt::Display for NotMade {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.write(f, "the rotors were not calibrated")
    }
}

impl NotMade {
    /// The message: `what` was not calibrated, why, and what σ takes its place.
    pub(crate) fn write(&self, f: &mut core::fmt::Formatter<'_>, what: &str) -> core::fmt::Result {
        write!(f, "{what}: ")?;
        match self {
            NotMade::NoMomentum {
                ratio,
                significance,
            } => write!(
                f,
                "the record's total angular momentum is {:.1} % of its rotors' and {:.2} \
                 times its own scatter (below {}): without a momentum the wheels' errors \
                 cannot be told from J",
                ratio * 100.0,
                significance,
                crate::text::Num(MIN_MOMENTUM_SIGNIFICANCE)
            )?,
            NotMade::KnownTorque => f.write_str(
                "the record has a known torque, which fixes the momentum's scale that the \
                 calibration takes as given (not supported)",
            )?,
            NotMade::NoFit => {
                f.write_str("the rows gave no fit of all the rotors' parameters together")?
            }
        }
        f.write_str("; their σ from the spacecraft file is a consider term instead")
    }
}

/// Per row, per source, the column; and per source its `γ_v` ([`columns`]).
pub(crate) type Columns = (Vec<Vec<Vector3<f64>>>, Vec<f64>);

/// The rotor parameters a batch run estimated with J, in the spacecraft file's units:
/// what the report, the JSON and Python carry.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RotorCalibration {
    /// Each parameter: `spin inertia` (one scale shared by every rotor), `rw1 spin
    /// inertia`, `rw1 axis tilt 1`, `rw1 time tag`, … (`super::rotor_inertia`'s sources).
    pub sources: Vec<std::string::String>,
    /// Each one's unit: `relative` (the spin inertia's relative error; for a shared
    /// scale, that of the rotor with the largest σ), `deg` (a tilt of the axis towards
    /// [`crate::spacecraft::Rotor::tilt_directions`]) or `s` (the rotor's speed read that
    /// much later than the run's wheel-speed time tag).
    pub unit: Vec<&'static str>,
    /// The file's σ (the prior), in the unit.
    pub prior_sigma: Vec<f64>,
    /// The estimate: the true value less the file's, in the unit.
    pub value: Vec<f64>,
    /// Its σ after the data, in the unit.
    pub sigma: Vec<f64>,
    /// How many independent combinations the data fix better than the prior
    /// ([`RotorFit::data_fixed`]); the others are the prior's.
    pub data_fixed: usize,
    /// The record's total angular momentum over its rotors' (RMS).
    pub momentum_ratio: f64,
    /// The record's total angular momentum over its scatter along the record: below
    /// [`MIN_MOMENTUM_SIGNIFICANCE`], the tilts cannot be told from J and no parameter
    /// is estimated, unless every one is a time tag.
    pub momentum_significance: f64,
}

impl RotorCalibration {
    /// `fit` (whitened) in the units of `sources`.
    #[must_use]
    pub(crate) fn new(
        sources: &[super::rotor_inertia::Source],
        fit: &RotorFit,
        (momentum_ratio, momentum_significance): (f64, f64),
    ) -> Self {
        let scale =
            |x: &[f64]| -> Vec<f64> { x.iter().zip(sources).map(|(v, s)| v * s.sigma).collect() };
        Self {
            sources: sources.iter().map(|s| s.label.clone()).collect(),
            unit: sources.iter().map(|s| s.unit).collect(),
            prior_sigma: sources.iter().map(|s| s.sigma).collect(),
            value: scale(&fit.value),
            sigma: scale(&fit.sigma),
            data_fixed: fit.data_fixed,
            momentum_ratio,
            momentum_significance,
        }
    }
}

/// Below this ratio of the record's total angular momentum to its scatter along the record
/// (the norm of the mean inertial momentum `q (Ĵ ω + ρ)` over the RMS of its deviations),
/// the rotor parameters are not estimated. With no momentum bias the ratio was 0.1–0.5 on
/// the slew and the small satellite, whose estimated tilts moved J 1–4 σ (slew) and
/// 30–40 σ (small satellite, MEMS and MEKF) from the truth, and whose estimated
/// spin-inertia differences (small satellite) nearly doubled the error; with a bias of
/// about the rotors' RMS momentum it was 49–167, every tilt was fixed by the data and J
/// was within 3σ (`examples/rotor_calibration.rs`, `tests/integration/rotor_calibration.rs`).
pub const MIN_MOMENTUM_SIGNIFICANCE: f64 = 3.0;

/// The record's total angular momentum at inertia `j`, from the inertial momentum
/// `h_k = q_k (J ω_k + ρ_k)` of each step (`ω` from its incremental rotation,
/// `2 vec(q_k† q_{k+1}) / h`): the norm of its mean over the RMS norm of `ρ` (the ratio),
/// and over the RMS scatter of `h_k` about the mean (the significance: a momentum the
/// record holds is constant, one that is zero leaves only `J`'s error and the noise,
/// which turn with the body). Where it is not significant, six of the nine combinations
/// of the rotors' tilts and scales are indistinguishable from J ([module docs](self),
/// "What the data fix").
#[must_use]
pub(crate) fn total_momentum(samples: &[Sample], j: &crate::tensor::InertiaVector) -> (f64, f64) {
    let jm = crate::tensor::matrix_from_j(j);
    let (mut hs, mut rho2) = (Vec::with_capacity(samples.len()), 0.0);
    for p in samples.windows(2) {
        let dt = p[1].t_s - p[0].t_s;
        if !(dt > 0.0) {
            continue;
        }
        let w = crate::attitude::incremental_rotation(&p[0].q, &p[1].q) * (2.0 / dt);
        let rho = (p[0].rho_nms + p[1].rho_nms) * 0.5;
        hs.push(p[0].q.rotate(&(jm * w + rho)));
        rho2 += rho.norm_squared();
    }
    let n = hs.len() as f64;
    if hs.is_empty() || !(rho2 > 0.0) {
        return (0.0, 0.0);
    }
    let mean: Vector3<f64> = hs.iter().sum::<Vector3<f64>>() / n;
    let scatter = (hs.iter().map(|h| (h - mean).norm_squared()).sum::<f64>() / n).sqrt();
    (mean.norm() / (rho2 / n).sqrt(), mean.norm() / scatter)
}

/// The sources' columns of the rows built from `samples` with `settings`: per row (in the
/// order the rows come), per source, `−Δb_v` less its projection `γ_v` on the column of
/// the momentum's own scale ([module docs](self), "The overall scale"), and the `γ_v`.
/// `sources[v]` is
/// source `v`'s 1σ change of every sample's rotor momentum.
pub(crate) fn columns(
    samples: &[Sample],
    settings: &MomentumRowSettings,
    sources: &[Vec<Vector3<f64>>],
) -> Result<Columns, EstimatorError> {
    let rows = |changed: &dyn Fn(usize, &Sample) -> Sample| {
        let mut source = MomentumRows::new(*settings);
        let mut out = Vec::new();
        for (i, s) in samples.iter().enumerate() {
            let row = source
                .push(&changed(i, s))
                .map_err(|source| EstimatorError::Row { sample: i, source })?;
            if let Some(r) = row {
                out.push(r.b);
            }
        }
        Ok::<_, EstimatorError>(out)
    };
    let nominal = rows(&|_, s| *s)?;
    let column = |changed: Vec<Vector3<f64>>| -> Result<Vec<Vector3<f64>>, EstimatorError> {
        if changed.len() != nominal.len() {
            return Err(EstimatorError::InvalidSetting {
                field: "rotor sources",
                why: "the changed momentum must give the same rows",
            });
        }
        Ok(changed
            .iter()
            .zip(&nominal)
            .map(|(b1, b0)| -(b1 - b0))
            .collect())
    };
    // The column of the momentum's own scale: ρ changed by ρ.
    let own = column(rows(&|_, s| Sample {
        rho_nms: s.rho_nms * 2.0,
        ..*s
    })?)?;
    let own_norm: f64 = own.iter().map(Vector3::norm_squared).sum();
    let mut out = vec![Vec::with_capacity(sources.len()); nominal.len()];
    let mut gamma = Vec::with_capacity(sources.len());
    for delta in sources {
        if delta.len() != samples.len() {
            return Err(EstimatorError::InvalidSetting {
                field: "rotor sources",
                why: "one momentum change per sample",
            });
        }
        let col = column(rows(&|i, s| Sample {
            rho_nms: s.rho_nms + delta[i],
            ..*s
        })?)?;
        let g = if own_norm > 0.0 {
            col.iter().zip(&own).map(|(c, o)| c.dot(o)).sum::<f64>() / own_norm
        } else {
            0.0
        };
        for ((o, c), w) in out.iter_mut().zip(&col).zip(&own) {
            o.push(c - w * g);
        }
        gamma.push(g);
    }
    Ok((out, gamma))
}

impl RotorFit {
    /// `e` (the rows' answer) at the overall scale the parameters imply, `ĵ (1 + ĉ)` with
    /// its σ, and the consider term per element that the scale's σ adds, `σ_c |ĵ_k|`, in
    /// quadrature with `other` (another consider term of the rotors).
    pub(crate) fn apply(
        &self,
        e: &mut super::Estimate,
        other: Option<[f64; 6]>,
    ) -> Option<[f64; 6]> {
        let k = 1.0 + self.scale;
        let j = e.solution.as_mut().map(|s| {
            s.j *= k;
            s.j
        })?;
        if let Some(u) = e.uncertainty.as_mut() {
            for a in [
                &mut u.sigma_kg_m2,
                &mut u.noise_kg_m2,
                &mut u.bias_kg_m2,
                &mut u.model_spread_kg_m2,
                &mut u.rotor_scale_kg_m2,
                &mut u.time_tag_kg_m2,
                &mut u.rotor_inertia_kg_m2,
            ] {
                a.iter_mut().for_each(|x| *x *= k);
            }
            u.principal_sigma_kg_m2.iter_mut().for_each(|x| *x *= k);
        }
        let o = other.unwrap_or([0.0; 6]);
        Some(core::array::from_fn(|i| {
            let c = self.scale_sigma * j[i].abs();
            (c * c + o[i] * o[i]).sqrt()
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_data_fix_the_combinations_whose_posterior_variance_is_below_half() {
        // Posterior variances ¼ (data information 3), 1 (prior only), ½·(1 − 10⁻⁹).
        let c = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![0.25, 1.0, 0.4999]));
        let f = RotorFit::from_covariance(vec![0.1, 0.0, 0.2], &c, &[0.0, 1.0, 0.0]);
        assert_eq!(f.data_fixed, 2);
        assert!((f.sigma[0] - 0.5).abs() < 1e-15 && (f.sigma[1] - 1.0).abs() < 1e-15);
        // The scale: the second source's value and σ, its γ being 1.
        assert!(f.scale == 0.0 && (f.scale_sigma - 1.0).abs() < 1e-15);
    }
}
