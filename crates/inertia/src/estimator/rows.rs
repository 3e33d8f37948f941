//! Row sources: turn a stream of samples into 3-row blocks `H_k j = y_k`.
//!
//! * [`VariationalRows`]: the discrete variational rows of eqs. 53–54 (see
//!   [`crate::discrete`]), from nodes k, k+1, k+2.
//! * [`FiniteDifferenceRows`]: the paper's finite-difference baseline (§VI), eq. 26 at node
//!   k with `ω̇` differenced from the gyro rates.

use crate::attitude::{incremental_rotation, skew};
use crate::discrete::{check_phi, check_unit, g_matrix, Row, RowError, RowInput};
use crate::sample::{is_gap, Sample};
use nalgebra::Vector3;

/// A stateful source of rows fed one sample at a time.
pub trait RowSource {
    /// Feed the next sample. Returns the block that the new sample completes, if any.
    fn push(&mut self, s: &Sample) -> Option<Result<Row, RowError>>;
    /// Forget buffered samples (e.g. across a gap).
    fn reset(&mut self);
    /// Gaps seen so far (`crate::sample::is_gap`).
    fn gaps(&self) -> usize;
}

/// Three consecutive nodes and the incremental rotations of their two intervals.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stencil {
    /// Nodes k, k+1, k+2.
    pub(crate) nodes: [Sample; 3],
    /// `φ_k`, `φ_{k+1}`.
    pub(crate) phi: [Vector3<f64>; 2],
}

/// The last two samples and the φ of the interval between them. A step longer than
/// [`crate::sample::GAP_RATIO`] times the previous one is a gap: the window restarts after
/// it, so no row spans it. Each φ is computed and checked once, when its interval arrives.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Window {
    a: Option<Sample>,
    b: Option<Sample>,
    phi_ab: Vector3<f64>,
    gaps: usize,
}

impl Window {
    /// Forget the buffered samples, keep the gap count.
    pub(crate) fn reset(&mut self) {
        *self = Window {
            gaps: self.gaps,
            ..Window::default()
        };
    }

    /// Gaps seen so far.
    pub(crate) fn gaps(&self) -> usize {
        self.gaps
    }

    /// Feed a sample; the stencil it completes, if any.
    pub(crate) fn push(&mut self, s: &Sample) -> Option<Result<Stencil, RowError>> {
        // Each sample's attitude is checked once, as it arrives (node 2 of its first row).
        if let Err(e) = check_unit(&s.q, 2) {
            return Some(Err(e));
        }
        let Some(b) = self.b else {
            self.b = Some(*s);
            return None;
        };
        if let Some(a) = self.a {
            if is_gap(b.t_s - a.t_s, s.t_s - b.t_s) {
                self.gaps += 1;
                self.a = None;
                self.b = Some(*s);
                return None;
            }
        }
        let phi = incremental_rotation(&b.q, &s.q);
        if let Err(e) = check_phi(&phi, b.t_s, s.t_s) {
            // Restart after the bad step so that later rows do not span it.
            self.a = None;
            self.b = Some(*s);
            return Some(Err(e));
        }
        let out = self.a.map(|a| Stencil {
            nodes: [a, b, *s],
            phi: [self.phi_ab, phi],
        });
        self.a = Some(b);
        self.b = Some(*s);
        self.phi_ab = phi;
        out.map(Ok)
    }
}

/// Variational rows (eqs. 53–54).
#[derive(Debug, Clone, Copy, Default)]
pub struct VariationalRows {
    w: Window,
}

impl RowSource for VariationalRows {
    fn push(&mut self, s: &Sample) -> Option<Result<Row, RowError>> {
        Some(self.w.push(s)?.and_then(|st| {
            let [a, b, c] = st.nodes;
            RowInput {
                t_k_s: a.t_s,
                phi_k: st.phi[0],
                phi_k1: st.phi[1],
                rho_k_nms: 0.5 * (a.rho_nms + b.rho_nms),
                rho_k1_nms: 0.5 * (b.rho_nms + c.rho_nms),
                tau_k1_nm: b.tau_nm,
                h_s: b.t_s - a.t_s,
                h1_s: c.t_s - b.t_s,
            }
            .row_checked_phi()
        }))
    }

    fn reset(&mut self) {
        self.w.reset();
    }

    fn gaps(&self) -> usize {
        self.w.gaps()
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
        Some(self.w.push(s)?.and_then(|st| {
            let [a, b, c] = st.nodes;
            fd_row(&a, &b, &c)
        }))
    }

    fn reset(&mut self) {
        self.w.reset();
    }

    fn gaps(&self) -> usize {
        self.w.gaps()
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
    let finite = |v: &Vector3<f64>| v.iter().all(|x| x.is_finite());
    let (Some(wa), Some(wb)) = (a.omega_rad_s, b.omega_rad_s) else {
        return Err(RowError::MissingGyroRate);
    };
    if !(finite(&wa) && finite(&wb)) {
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
    let w = (wa * h1 + wb * h0) / (h0 + h1);
    let wdot = (wb - wa) / (0.5 * (h0 + h1));
    let rho_dot = (c.rho_nms - a.rho_nms) / (h0 + h1);
    Ok(Row {
        h: g_matrix(&wdot) + skew(&w) * g_matrix(&w),
        y: b.tau_nm - w.cross(&b.rho_nms) - rho_dot,
        // The gyro noise of these rows (differenced rates) is not modelled.
        noise_s: 0.0,
    })
}

impl<S: RowSource + ?Sized> RowSource for &mut S {
    fn push(&mut self, s: &Sample) -> Option<Result<Row, RowError>> {
        (**self).push(s)
    }
    fn reset(&mut self) {
        (**self).reset();
    }
    fn gaps(&self) -> usize {
        (**self).gaps()
    }
}
