//! Row sources: turn a stream of samples into 3-row blocks `H_k j = y_k`.
//!
//! * [`VariationalRows`]: the discrete variational rows of eqs. 53–54 (see
//!   [`crate::discrete`]), from nodes k, k+1, k+2.
//! * [`FiniteDifferenceRows`]: the paper's finite-difference baseline (§VI), eq. 26 at node
//!   k with `ω̇` differenced from the gyro rates.

use crate::attitude::skew;
use crate::discrete::{g_matrix, Row, RowError, RowInput};
use crate::telemetry::Sample;

/// A step longer than this many times the previous one is a gap: no row spans it.
pub const GAP_RATIO: f64 = 3.0;

/// A stateful source of rows fed one sample at a time.
pub trait RowSource {
    /// Feed the next sample. Returns the block that the new sample completes, if any.
    fn push(&mut self, s: &Sample) -> Option<Result<Row, RowError>>;
    /// Forget buffered samples (e.g. across a gap).
    fn reset(&mut self);
    /// Gaps seen so far (steps longer than [`GAP_RATIO`] times the previous step).
    fn gaps(&self) -> usize;
}

/// The last three samples. A step longer than [`GAP_RATIO`] times the previous one is a
/// gap (missing samples, a pause): the window restarts after it, so no row spans it.
#[derive(Debug, Clone, Copy, Default)]
struct Window {
    a: Option<Sample>,
    b: Option<Sample>,
    gaps: usize,
}

impl Window {
    /// Forget the buffered samples, keep the gap count.
    fn reset(&mut self) {
        *self = Window {
            gaps: self.gaps,
            ..Window::default()
        };
    }

    fn push(&mut self, s: &Sample) -> Option<(Sample, Sample)> {
        if let (Some(a), Some(b)) = (self.a, self.b) {
            let (h0, h1) = (b.t_s - a.t_s, s.t_s - b.t_s);
            if h1 > GAP_RATIO * h0 {
                self.gaps += 1;
                self.a = None;
                self.b = Some(*s);
                return None;
            }
        }
        let out = match (self.a, self.b) {
            (Some(a), Some(b)) => Some((a, b)),
            _ => None,
        };
        self.a = self.b;
        self.b = Some(*s);
        out
    }
}

/// Variational rows (eqs. 53–54).
#[derive(Debug, Clone, Copy, Default)]
pub struct VariationalRows {
    w: Window,
}

impl RowSource for VariationalRows {
    fn push(&mut self, s: &Sample) -> Option<Result<Row, RowError>> {
        let (a, b) = self.w.push(s)?;
        Some(RowInput::from_samples([&a, &b, s]).and_then(|r| r.row()))
    }

    fn reset(&mut self) {
        self.w.reset();
    }

    fn gaps(&self) -> usize {
        self.w.gaps
    }
}

/// Finite-difference rows of eq. 26 at node k (the middle of three samples):
///
/// ```text
/// ω_k = (h₁ w̄_{k−1} + h₀ w̄_k)/(h₀ + h₁),   ω̇_k = (w̄_k − w̄_{k−1}) / ((h₀ + h₁)/2)
/// ρ̇_k = (ρ_{k+1} − ρ_{k−1})/(h₀ + h₁)
/// [G(ω̇_k) + S(ω_k) G(ω_k)] j = τ_k − ω_k × ρ_k − ρ̇_k
/// ```
///
/// where `w̄_k` is the gyro rate averaged over `[t_k, t_{k+1}]` (so it belongs to the
/// interval's midpoint) and `h₀`, `h₁` are the two intervals (equal for uniform
/// sampling, where these are the usual central differences).
#[derive(Debug, Clone, Copy, Default)]
pub struct FiniteDifferenceRows {
    w: Window,
}

impl RowSource for FiniteDifferenceRows {
    fn push(&mut self, s: &Sample) -> Option<Result<Row, RowError>> {
        let (a, b) = self.w.push(s)?;
        Some(fd_row(&a, &b, s))
    }

    fn reset(&mut self) {
        self.w.reset();
    }

    fn gaps(&self) -> usize {
        self.w.gaps
    }
}

fn fd_row(a: &Sample, b: &Sample, c: &Sample) -> Result<Row, RowError> {
    let h0 = b.t_s - a.t_s;
    let h1 = c.t_s - b.t_s;
    if !(h0 > 0.0 && h1 > 0.0 && h0.is_finite() && h1.is_finite()) {
        return Err(RowError::NonFinite {
            what: "sample period",
        });
    }
    let finite = |v: &nalgebra::Vector3<f64>| v.iter().all(|x| x.is_finite());
    if !(finite(&a.omega_rad_s) && finite(&b.omega_rad_s)) {
        return Err(RowError::NonFinite { what: "gyro rate" });
    }
    if !(finite(&a.rho_nms) && finite(&b.rho_nms) && finite(&c.rho_nms)) {
        return Err(RowError::NonFinite {
            what: "rotor momentum",
        });
    }
    if !finite(&b.tau_nm) {
        return Err(RowError::NonFinite {
            what: "known torque",
        });
    }
    let w = (a.omega_rad_s * h1 + b.omega_rad_s * h0) / (h0 + h1);
    let wdot = (b.omega_rad_s - a.omega_rad_s) / (0.5 * (h0 + h1));
    let rho_dot = (c.rho_nms - a.rho_nms) / (h0 + h1);
    Ok(Row {
        h: g_matrix(&wdot) + skew(&w) * g_matrix(&w),
        y: b.tau_nm - w.cross(&b.rho_nms) - rho_dot,
        // The gyro noise of these rows (differenced rates) is not modelled.
        noise_s: 0.0,
    })
}
