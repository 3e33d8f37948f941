//! The batch estimator of eq. 57: stack every row, one Householder QR, one solve.
//!
//! Deliberately a different code path from the recursive Givens update (nalgebra's dense
//! QR of the full `3N × 6` matrix), so that the two can be checked against each other.

use super::observability::{assess, ObservabilitySettings};
use super::qr::RecursiveQr;
use super::rows::RowSource;
use super::{Estimate, EstimatorError, MIN_SAMPLES};
use crate::constraints::Constraints;
use crate::sample::Sample;
use crate::solver::Backend;
use nalgebra::{DMatrix, DVector, Matrix6, Vector6};

/// The stacked system reduced to `(R, z, ρ²)` by a dense QR.
pub fn reduce<S: RowSource>(
    samples: &[Sample],
    mut source: S,
) -> Result<RecursiveQr, EstimatorError> {
    if samples.len() < MIN_SAMPLES {
        return Err(EstimatorError::TooFewSamples {
            need: MIN_SAMPLES,
            got: samples.len(),
        });
    }
    let mut noise_s = 0.0;
    let mut h = Vec::with_capacity(samples.len() * 18);
    let mut y = Vec::with_capacity(samples.len() * 3);
    for (i, s) in samples.iter().enumerate() {
        if let Some(row) = source.push(s) {
            let row = row.map_err(|source| EstimatorError::Row { sample: i, source })?;
            noise_s += row.noise_s;
            for r in 0..3 {
                h.extend(row.h.row(r).iter());
                y.push(row.y[r]);
            }
        }
    }
    let m = y.len();
    let hm = DMatrix::from_row_slice(m, 6, &h);
    let yv = DVector::from_vec(y);
    let y_energy = yv.norm_squared();
    let qr = hm.qr();
    let (q, r) = (qr.q(), qr.r());
    // Fewer than six rows (a gap right after the first steps): R has fewer rows; the
    // missing ones are zero (rank deficient, for the observability test to report).
    let qty = q.transpose() * &yv;
    let mut rr = Matrix6::from_fn(|i, k| if i < r.nrows() { r[(i, k)] } else { 0.0 });
    let mut z = Vector6::from_fn(|i, _| qty.get(i).copied().unwrap_or(0.0));
    for i in 0..6 {
        if rr[(i, i)] < 0.0 {
            for k in 0..6 {
                rr[(i, k)] = -rr[(i, k)];
            }
            z[i] = -z[i];
        }
    }
    Ok(RecursiveQr {
        r: rr,
        z,
        rss: (y_energy - z.norm_squared()).max(0.0),
        y_energy,
        rows: m,
        weight: m as f64,
        noise_s,
        nuisance: 0.0,
    })
}

/// Estimate J from all samples at once.
pub fn estimate<S: RowSource>(
    samples: &[Sample],
    source: S,
    constraints: &Constraints,
    backend: &mut dyn Backend,
    observability: &ObservabilitySettings,
    gyro_noise_rad_s_rthz: Option<f64>,
) -> Result<Estimate, EstimatorError> {
    let qr = reduce(samples, source)?;
    solve_reduced(
        &qr,
        samples.last().map_or(0.0, |s| s.t_s),
        constraints,
        backend,
        observability,
        gyro_noise_rad_s_rthz,
    )
}

/// The estimate (stamped `t_s`) from a reduced least-squares state.
pub(crate) fn solve_reduced(
    qr: &RecursiveQr,
    t_s: f64,
    constraints: &Constraints,
    backend: &mut dyn Backend,
    observability: &ObservabilitySettings,
    gyro_noise_rad_s_rthz: Option<f64>,
) -> Result<Estimate, EstimatorError> {
    let (solved, fit) = super::prior::augment(qr, constraints);
    let observability = super::recursive::with_prior(
        assess(
            &solved,
            constraints.set().has_bounds(),
            &super::recursive::combined_settings(observability, fit.as_ref()),
        ),
        qr,
        fit.as_ref(),
        constraints,
        observability,
    );
    let (solution, observability) = super::recursive::solve_with(
        backend,
        &solved,
        constraints,
        observability,
        gyro_noise_rad_s_rthz,
        None,
    )?;
    Ok(Estimate {
        t_s,
        rows: qr.rows,
        observability,
        solution,
        uncertainty: None,
        prior: fit,
    })
}
