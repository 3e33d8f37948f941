//! Rows of the discrete momentum estimator (`discrete_momentum.rs`, the interval momentum) from a stream of
//! samples: plain, or Richardson-extrapolated to O(h⁴).
//!
//! # Unknowns
//!
//! `x = [X₀; X₁; τ_b; κ; j]` (`UNKNOWNS` = 16; the blocks are named in
//! `super::unknowns`): two 3-vectors of initial momentum
//! (the plain rows use only `X₀ = L̄₀`), the constant body-frame disturbance torque `τ_b`
//! (columns zero when [`MomentumRowSettings::torque_bias`] is off), the scalar `κ` of
//! [`Stencil::Adaptive`] (zero column otherwise) and `j` last, so that the trailing 6×6
//! block of a QR factor is the reduced problem in `j` alone.
//!
//! # Plain rows
//!
//! One 3-row block per interval k: `A_k j − X₀ − S_k τ_b = b_k + T_k`
//! (`discrete_momentum.rs`). Exact when `ρ` is linear and `τ` constant across each
//! interval apart from the O(h²) bias of the discrete Lagrangian; that is the case when
//! the wheel commands are held over each telemetry step and change at the samples.
//!
//! # Richardson rows
//!
//! With `F_k` the plain row of interval k and `F^{2h}` the same row built on the stride-2
//! subgrid over `[c−1, c+1]` (φ of the double step, the same trapezoid rule for `ρ̄`, the
//! subgrid's own torque sums), the row centred on node c is
//!
//! ```text
//! (4/3) · ½ (F_{c−1} + F_c) − (1/3) F^{2h}_{[c−1, c+1]}
//! ```
//!
//! whose O(h²) bias cancels (the bias is even in h). Each parity p of `c−1` has its own
//! subgrid and so its own initial momentum: the row's constant is
//! `X_p = (4/3) L̄₀ − (1/3) L̄₀^{2h,p}`. What `ρ̄` of the double step is depends on what the
//! wheels do between samples ([`Stencil`]): its trapezoid for smooth `ρ`, the mean of the
//! two steps' trapezoids for commands held over each step, and that mean corrected by an
//! estimated `κ Δ²ρ` for either, or for commands that change between samples
//! ([`Stencil::Adaptive`], the default; `tests/integration/discrete_momentum.rs` measures each).
//!
//! # Rotation source
//!
//! `φ_k` from the attitude (`vec(q_k† q_{k+1})`) or from the gyro's delta angle over the
//! interval (`w_k h_k`, the sample's average rate over the following interval,
//! docs/conventions.md). `C_k` always comes from the attitude. A star tracker's white
//! attitude noise enters `φ` differenced; a gyro's enters once.
//!
//! # Chains
//!
//! A gap (`crate::sample::is_gap`) or a step that rotates too far restarts the chain:
//! the sums restart and the initial momenta become new unknowns; `MomentumRows::epoch`
//! counts the restarts so the estimator can eliminate the old ones. A chain that only
//! grows too long ([`MomentumRowSettings::max_chain_s`]) is split by a `ChainClock`
//! instead: its rows go on (no interval lost, the sums running), only the initial
//! momenta are new unknowns from the split on. The sums' values at the split are then a
//! constant offset of every later row of the chain (`S τ_b`, `T`), which the new initial
//! momenta absorb: the same least-squares problem as restarting the sums. Rows therefore
//! do not depend on the chain length, and candidates that differ only in it can share
//! one row source.
//!
//! # Inertial torque
//!
//! A disturbance torque constant in the *inertial* frame, `τ_I` (N m; an aerodynamic or
//! solar force whose direction is fixed in space, or any slow drift of the momentum over
//! a short record), enters the impulse sum as `Σ h̄_m C_m (C_mᵀ τ_I) = s_k τ_I` with the
//! scalar `s_k = Σ_{m=1..k} h̄_m` (the time from the chain's first interval's midpoint to
//! interval k's): the row gains `− s_k τ_I`, and the Richardson row the same
//! combination of the three `s`. With [`MomentumRowSettings::inertial_torque`] each
//! block carries its `s` (`AugmentedRow::trend_s`) and the torque is one more unknown of
//! the block's initial-momentum slot: minimised out with it per chain (and per parity,
//! so the Richardson rows' two slots each have their own), as a linear trend of the
//! inertial momentum (`estimator/trend_slot.rs`). A split chain's torque before and after the
//! split are then two unknowns, like its initial momenta.

use crate::attitude::Quaternion;
use crate::discrete::{check_phi, check_unit, RowError};
use crate::discrete_momentum::IntervalMomentum;
use crate::sample::{is_gap, Sample};
use nalgebra::{Matrix3, Matrix3x6, SMatrix, Vector3};

pub use super::external_torque::OutsideTorques;
use super::external_torque::TorqueMaps;
use super::unknowns::Block;
pub(crate) use super::unknowns::UNKNOWNS;
/// Column of the first initial-momentum unknown.
pub(crate) const ANCHOR0: usize = Block::Anchor0.column();
/// Column of the second initial-momentum unknown (Richardson rows, odd centres).
pub(crate) const ANCHOR1: usize = Block::Anchor1.column();
/// Column of the disturbance torque `τ_b`.
pub(crate) const TORQUE: usize = Block::BodyTorque.column();
/// Column of the wheel-momentum curvature coefficient `κ` ([`Stencil::Adaptive`]).
pub(crate) const KAPPA: usize = Block::Kappa.column();
/// Column of the damping coefficient `D` ([`MomentumRowSettings::damping`]).
pub(crate) const DAMPING: usize = Block::Damping.column();
/// Column of the residual magnetic dipole `m` ([`MomentumRowSettings::residual_dipole`]).
pub(crate) const DIPOLE: usize = Block::Dipole.column();
/// Column of the centre of mass `c` ([`MomentumRowSettings::centre_of_mass`]).
pub(crate) const CENTRE_OF_MASS: usize = Block::CentreOfMass.column();
/// Column of `j`.
pub(crate) const J: usize = Block::J.column();

/// Where the incremental rotation `φ_k` comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum RotationSource {
    /// `vec(q_k† q_{k+1})` of the telemetered attitude.
    Attitude,
    /// The gyro's delta angle `w_k h_k` (needs `w_*` in the telemetry).
    Gyro,
}

/// What the telemetry's rotor momentum does between samples: which rows to use (the
/// pipeline's setting; [`Stencil`] is what one row model does).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum RhoModel {
    /// Estimate it from the data: [`Stencil::Adaptive`] (default).
    #[default]
    Auto,
    /// `ρ` is smooth across two steps (a continuous law, or commands much faster than the
    /// telemetry): [`Stencil::Smooth`].
    Smooth,
    /// `ρ` is linear within each step (wheel torque commands held over each telemetry
    /// step, changing at the samples): [`Stencil::Held`].
    Held,
    /// Plain rows ([`Stencil::Plain`]), O(h²), whatever `ρ` does.
    Plain,
}

/// The rows' stencil: one interval, or a Richardson combination of two intervals and
/// their double step.
///
/// The body momentum `Jω + ρ` is smooth even where the wheel torque jumps (the wheels'
/// torque is internal), but `ω` and `ρ` separately have kinks there. The dynamics part of
/// a row measures the *mean* of `ω` over its interval (`φ ≈ ∫ω`), so its `ρ` part must
/// be the mean of `ρ` over the same interval for the kinks to cancel. Within one
/// telemetry step the trapezoid `(ρ_k + ρ_{k+1})/2` is that mean when `ρ` is linear
/// (commands held over the step). Over the double step the mean is the average of the two
/// trapezoids ([`Stencil::Held`]), exact for kinks at the middle node; for smooth `ρ` it is
/// off by `h²ρ̈/12`, which the Richardson combination does not remove, so smooth `ρ` uses
/// the double step's own trapezoid `(ρ_{c−1} + ρ_{c+1})/2`, whose O(h²) term scales like
/// the single steps' ([`Stencil::Smooth`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Stencil {
    /// One interval per row: O(h²).
    #[default]
    Plain,
    /// Richardson, double-step `ρ̄` its trapezoid: O(h⁴) for smooth `ρ`.
    Smooth,
    /// Richardson, double-step `ρ̄` the mean of its two steps' trapezoids: O(h⁴) for `ρ`
    /// linear within each step.
    Held,
    /// [`Stencil::Held`] with each step's `ρ̄` corrected by `κ Δ²ρ_c`, `κ` one unknown
    /// estimated with `j`: the mean of `ρ` over a step minus its trapezoid is
    /// `−(p(1−p)/2) Δ²ρ` for wheel torque commands that change a fraction `p` into each
    /// step (to first order in how much consecutive command changes differ), and
    /// `−Δ²ρ/12` for smooth `ρ`. One stencil for smooth `ρ` (κ = −1/12), commands held
    /// over each step (κ = 0) and commands that change between samples (κ = −1/8
    /// mid-way), without knowing which.
    Adaptive,
}

impl Stencil {
    /// Whether the rows are Richardson combinations.
    #[must_use]
    pub(crate) fn richardson(&self) -> bool {
        !matches!(self, Stencil::Plain)
    }
}

/// How the rows are formed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MomentumRowSettings {
    /// Source of `φ` (default [`RotationSource::Attitude`]).
    pub rotation: RotationSource,
    /// The rows' stencil (default [`Stencil::Plain`]).
    pub stencil: Stencil,
    /// Estimate a constant body-frame disturbance torque `τ_b` (default `true`).
    pub torque_bias: bool,
    /// Estimate a constant inertial-frame disturbance torque `τ_I` per chain (and per
    /// Richardson parity), beside its initial momentum (module docs, "Inertial torque";
    /// default `false`).
    pub inertial_torque: bool,
    /// Estimate a linear damping torque `−D ω` (air drag; module docs, "Damping";
    /// default `false`).
    pub damping: bool,
    /// The torques of outside measurements the rows model where the samples give them
    /// ([`super::external_torque`]; default: every one).
    pub outside: OutsideTorques,
    /// Longest chain, s (the first `super::jackknife::MIN_GROUPS` chains a quarter of
    /// it): a chain is split (its initial momentum becomes a new unknown) once it spans
    /// this long, so that a slowly drifting attitude error (a gyro-propagated attitude's
    /// random walk) rotates the momentum by at most the drift within one chain. `None`:
    /// chains end only at gaps. The rows themselves do not depend on it: the split is
    /// the estimator's `ChainClock`'s, downstream of `MomentumRows`.
    pub max_chain_s: Option<f64>,
}

impl Default for MomentumRowSettings {
    fn default() -> Self {
        Self {
            rotation: RotationSource::Attitude,
            stencil: Stencil::Plain,
            torque_bias: true,
            inertial_torque: false,
            damping: false,
            outside: OutsideTorques::default(),
            max_chain_s: None,
        }
    }
}

#[cfg_attr(not(feature = "std"), allow(dead_code))]
impl MomentumRowSettings {
    /// The model but for the chain length, which only [`super::chain_clock::ChainClock`] uses: candidates
    /// equal in it fit the same model in different chains.
    #[must_use]
    pub(crate) fn rows_only(&self) -> Self {
        Self {
            max_chain_s: None,
            ..*self
        }
    }

    /// The settings the rows themselves depend on: [`Self::rows_only`] but for the
    /// inertial torque, which only the state uses. Candidates equal in it can share one
    /// row source.
    #[must_use]
    pub(crate) fn source_key(&self) -> Self {
        Self {
            inertial_torque: false,
            ..self.rows_only()
        }
    }

    /// Initial-momentum unknowns of one chain: `X₀`, and `X₁` for Richardson rows.
    #[must_use]
    pub(crate) fn anchors_per_chain(&self) -> usize {
        if self.stencil.richardson() {
            6
        } else {
            3
        }
    }

    /// Unknowns besides `j` the rows involve in one chain: the initial momenta and, with
    /// [`Self::inertial_torque`], a torque for each.
    #[must_use]
    pub(crate) fn nuisance_per_chain(&self) -> usize {
        self.anchors_per_chain() * (1 + usize::from(self.inertial_torque))
    }

    /// Unknowns besides `j` shared by every chain (`τ_b`, `κ`, `D`; the outside torques'
    /// `m` and `c` count from the first row that uses them, [`AugmentedRow::external_unknowns`]).
    #[must_use]
    pub(crate) fn shared_nuisance(&self) -> usize {
        let torque = if self.torque_bias { 3 } else { 0 };
        torque + usize::from(self.stencil == Stencil::Adaptive) + usize::from(self.damping)
    }
}

/// One 3-row block `a x = b` in the unknowns `x` ([`UNKNOWNS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AugmentedRow {
    /// Coefficients, 3×16.
    pub(crate) a: SMatrix<f64, 3, UNKNOWNS>,
    /// Right-hand side, N m s.
    pub(crate) b: Vector3<f64>,
    /// Errors-in-variables coefficient, s⁻¹: a gyro rate-noise density σ (rad/s/√Hz),
    /// entering `φ` as a white angle noise, adds `σ² · noise_s · D` to the expected
    /// `AᵀA` of the block's `j` columns (`D` of [`super::compensation`]). Plain rows:
    /// `noise_s = 1/h` (`φ` is a half angle, so its noise variance is `σ² h/4`, and
    /// `A = (2/h) C N G(φ)`); Richardson rows: `Σ_i c_i² h_i/4` with `c_i` the stencil's
    /// coefficient on `δφ_i` (`c_i = 1/h`, so `noise_s = 1/(2h)`, for equal steps).
    pub(crate) noise_s: f64,
    /// The coefficient `s` of the block's inertial torque, s, for a state that estimates
    /// one ([`MomentumRowSettings::inertial_torque`]): the block then reads
    /// `−X_p − s τ_{I,p} + a_rest x = b` (module docs, "Inertial torque"); only
    /// differences of `s` within a chain matter.
    pub(crate) trend_s: f64,
}

impl AugmentedRow {
    /// The outside torques' unknowns the block uses: `m` and `c` (3 each) where their
    /// columns are not zero ([`super::external_torque`]).
    #[must_use]
    pub(crate) fn external_unknowns(&self) -> [bool; 2] {
        let uses = |c: usize| (0..3).any(|i| (0..3).any(|k| self.a[(i, c + k)] != 0.0));
        [uses(DIPOLE), uses(CENTRE_OF_MASS)]
    }
}

/// A plain row's parts, kept for the Richardson combination.
#[derive(Debug, Clone, Copy)]
struct Plain {
    /// The interval's momentum coefficients (`a` the row's in `j`).
    m: IntervalMomentum,
    /// `b_k + T_k`.
    rhs: Vector3<f64>,
    /// `S_k`.
    s: Matrix3<f64>,
    /// `Σ h̄` to the same node: the inertial torque's coefficient.
    si: f64,
    /// `W_k = Σ h̄_m C_m ω̂_m` to the same node: the damping's coefficient.
    w: Vector3<f64>,
    /// The outside torques' impulse sums to the same node.
    e: TorqueMaps,
}

/// A node as the rows need it.
#[derive(Debug, Clone, Copy)]
struct Node {
    t_s: f64,
    q: Quaternion,
    c: Matrix3<f64>,
    rho_nms: Vector3<f64>,
    tau_nm: Vector3<f64>,
    omega_rad_s: Option<Vector3<f64>>,
    /// The body rate at the node from its two intervals' rotations, once it is interior
    /// (with [`MomentumRowSettings::damping`] only).
    omega_hat: Option<Vector3<f64>>,
    /// The outside torques' maps at the node, inertial frame (`C P`), where any applies.
    maps: Option<TorqueMaps>,
}

/// The row source.
#[derive(Debug, Clone)]
pub(crate) struct MomentumRows {
    settings: MomentumRowSettings,
    /// The last three nodes of the chain, newest last (`None` before they exist).
    nodes: [Option<Node>; 3],
    /// Times of the two nodes before `nodes[0]`, older first (the stride-2 subgrid's
    /// interior weights need them).
    t_older_s: [Option<f64>; 2],
    /// Incremental rotation of the newest interval (`nodes[1]` → `nodes[2]`), as a unit
    /// quaternion.
    f_last: Quaternion,
    /// Nodes in the chain so far.
    count: usize,
    /// Time of the chain's first node, s.
    chain_start_s: f64,
    /// `S`, `T` of the unit-step grid, up to the newest interior node.
    s: Matrix3<f64>,
    t: Vector3<f64>,
    /// `Σ h̄` of the unit-step grid (the inertial torque's impulse per N m).
    si: f64,
    /// `W` of the unit-step grid (the damping's impulse per N m s).
    w: Vector3<f64>,
    /// The outside torques' impulse sums of the unit-step grid.
    e: TorqueMaps,
    /// The same per parity of the stride-2 subgrid.
    s2: [Matrix3<f64>; 2],
    t2: [Vector3<f64>; 2],
    si2: [f64; 2],
    w2: [Vector3<f64>; 2],
    e2: [TorqueMaps; 2],
    prev: Option<Plain>,
    /// The gyro's angle increment over the previous interval (coning term).
    alpha_prev: Option<Vector3<f64>>,
    epoch: u64,
    gaps: usize,
    /// Whether a node had a gravity-gradient map.
    gravity: bool,
}

#[cfg_attr(not(feature = "std"), allow(dead_code))]
impl MomentumRows {
    /// A new source.
    #[must_use]
    pub(crate) fn new(settings: MomentumRowSettings) -> Self {
        Self {
            settings,
            nodes: [None; 3],
            t_older_s: [None; 2],
            f_last: Quaternion::IDENTITY,
            count: 0,
            chain_start_s: 0.0,
            s: Matrix3::zeros(),
            t: Vector3::zeros(),
            si: 0.0,
            w: Vector3::zeros(),
            e: TorqueMaps::ZERO,
            s2: [Matrix3::zeros(); 2],
            t2: [Vector3::zeros(); 2],
            si2: [0.0; 2],
            w2: [Vector3::zeros(); 2],
            e2: [TorqueMaps::ZERO; 2],
            prev: None,
            alpha_prev: None,
            epoch: 0,
            gaps: 0,
            gravity: false,
        }
    }

    /// The settings.
    #[must_use]
    pub(crate) fn settings(&self) -> &MomentumRowSettings {
        &self.settings
    }

    /// Chains started so far minus one: changes whenever the initial momenta of later
    /// rows are new unknowns.
    #[must_use]
    pub(crate) fn epoch(&self) -> u64 {
        self.epoch
    }

    /// Gaps seen so far.
    #[must_use]
    pub(crate) fn gaps(&self) -> usize {
        self.gaps
    }

    /// Whether the gravity-gradient torque entered the rows (a sample with a position,
    /// the torque on).
    #[must_use]
    pub(crate) fn gravity_gradient(&self) -> bool {
        self.gravity
    }

    /// Time of the chain's first node, s.
    #[must_use]
    pub(crate) fn chain_start_s(&self) -> f64 {
        self.chain_start_s
    }

    /// Start time of the newest interval, s (after a push that gave a row: the interval
    /// the row ends with).
    #[must_use]
    pub(crate) fn interval_start_s(&self) -> Option<f64> {
        self.nodes[1].map(|n| n.t_s)
    }

    /// Start a new chain with `first` (or empty).
    fn restart(&mut self, first: Option<Node>) {
        let had_rows = self.count >= 2;
        *self = Self {
            epoch: self.epoch + u64::from(had_rows),
            gaps: self.gaps,
            gravity: self.gravity,
            ..Self::new(self.settings)
        };
        if let Some(n) = first {
            self.nodes[2] = Some(n);
            self.count = 1;
            self.chain_start_s = n.t_s;
        }
    }

    /// Feed a sample; the row block it completes, if any.
    pub(crate) fn push(&mut self, s: &Sample) -> Result<Option<AugmentedRow>, RowError> {
        check_unit(&s.q, 2)?;
        let c = s.q.to_matrix();
        let node = Node {
            t_s: s.t_s,
            q: s.q,
            c,
            rho_nms: s.rho_nms,
            tau_nm: s.tau_nm,
            omega_rad_s: s.omega_rad_s,
            omega_hat: None,
            maps: TorqueMaps::at(&c, &s.external, &self.settings.outside).map(|m| m.rotated(&c)),
        };
        let finite = |v: &Vector3<f64>| v.iter().all(|x| x.is_finite());
        if !finite(&node.rho_nms) {
            return Err(RowError::NonFinite {
                what: "rotor momentum",
            });
        }
        if !finite(&node.tau_nm) {
            return Err(RowError::NonFinite {
                what: "known torque",
            });
        }
        self.gravity |= node.maps.is_some_and(|m| m.j != TorqueMaps::ZERO.j);
        let Some(b) = self.nodes[2] else {
            self.restart(Some(node));
            return Ok(None);
        };
        let h = node.t_s - b.t_s;
        if !(h.is_finite() && h > 0.0) {
            return Err(RowError::NonFinite {
                what: "sample period",
            });
        }
        if let Some(a) = self.nodes[1] {
            if is_gap(b.t_s - a.t_s, h) {
                self.gaps += 1;
                self.restart(Some(node));
                return Ok(None);
            }
        }
        let f = match self.settings.rotation {
            RotationSource::Attitude => b.q.conjugate().mul(&node.q).positive_scalar(),
            RotationSource::Gyro => {
                let w = b.omega_rad_s.ok_or(RowError::MissingGyroRate)?;
                if !finite(&w) {
                    return Err(RowError::NonFinite { what: "gyro rate" });
                }
                // `w h` is the angle integral ∫ω dt, not the rotation vector: the
                // classical two-increment coning term (α_{k−1} × α_k)/12 restores it to
                // O(h⁴) per step.
                let alpha = w * h;
                let theta = match self.alpha_prev {
                    Some(a) => alpha + a.cross(&alpha) / 12.0,
                    None => alpha,
                };
                self.alpha_prev = Some(alpha);
                Quaternion::exp(&theta).positive_scalar()
            }
        };
        if let Err(e) = check_phi(&f.v, b.t_s, node.t_s) {
            self.restart(Some(node));
            return Err(e);
        }
        // Node b is interior once it has a predecessor: add its impulse to the sums.
        if let Some(a) = self.nodes[1] {
            let hbar = 0.5 * (node.t_s - a.t_s);
            self.s += b.c * hbar;
            self.t += b.c * b.tau_nm * hbar;
            self.si += hbar;
            if let Some(maps) = &b.maps {
                self.e = self.e.add_scaled(maps, hbar);
            }
            if self.settings.damping {
                // The rate at b interpolated between its two intervals' mean rates; a
                // rotation vector is the same in both ends' body axes.
                let (h0, w0, w1) = (b.t_s - a.t_s, self.f_last.log(), f.log());
                let omega = (w0 * (h / h0) + w1 * (h0 / h)) / (h0 + h);
                self.w += b.c * omega * hbar;
                if let Some(n) = self.nodes[2].as_mut() {
                    n.omega_hat = Some(omega);
                }
            }
        }
        let m = IntervalMomentum::new(&b.c, &f.v, &(0.5 * (b.rho_nms + node.rho_nms)), h);
        let plain = Plain {
            m,
            rhs: m.b + self.t,
            s: self.s,
            si: self.si,
            w: self.w,
            e: self.e,
        };
        let f_prev = self.f_last;
        self.t_older_s = [self.t_older_s[1], self.nodes[0].map(|n| n.t_s)];
        self.nodes = [self.nodes[1], self.nodes[2], Some(node)];
        self.f_last = f;
        self.count += 1;
        let prev = self.prev.replace(plain);
        if !self.settings.stencil.richardson() {
            return Ok(Some(self.assemble(
                &plain.m.a,
                &plain.rhs,
                (&plain.s, plain.si, &plain.w, &plain.e),
                ANCHOR0,
                1.0 / h,
            )));
        }
        // Richardson: centre c = nodes[1], needs the previous interval.
        let (Some(prev), Some(cm1)) = (prev, self.nodes[0]) else {
            return Ok(None);
        };
        let f2 = f_prev.mul(&f).positive_scalar();
        check_phi(&f2.v, cm1.t_s, node.t_s).inspect_err(|_| self.restart(Some(node)))?;
        // Index of c−1 in the chain: count − 3.
        let parity = (self.count - 3) % 2;
        // c−1 is interior of its subgrid when the subgrid has a node before it.
        if self.count >= 5 {
            if let Some(t_before) = self.t_older_s[0] {
                let hbar2 = 0.5 * (node.t_s - t_before);
                self.s2[parity] += cm1.c * hbar2;
                self.t2[parity] += cm1.c * cm1.tau_nm * hbar2;
                self.si2[parity] += hbar2;
                if let Some(omega) = cm1.omega_hat {
                    self.w2[parity] += cm1.c * omega * hbar2;
                }
                if let Some(maps) = &cm1.maps {
                    self.e2[parity] = self.e2[parity].add_scaled(maps, hbar2);
                }
            }
        }
        let h2 = node.t_s - cm1.t_s;
        let rho2 = match self.settings.stencil {
            Stencil::Smooth => (cm1.rho_nms + node.rho_nms) * 0.5,
            // The mean over the double step of ρ linear within each step.
            _ => {
                let (h0, h1) = (b.t_s - cm1.t_s, node.t_s - b.t_s);
                ((cm1.rho_nms + b.rho_nms) * h0 + (b.rho_nms + node.rho_nms) * h1) / (2.0 * h2)
            }
        };
        let m2 = IntervalMomentum::new(&cm1.c, &f2.v, &rho2, h2);
        let (w, v) = (2.0 / 3.0, 1.0 / 3.0);
        let a = (prev.m.a + plain.m.a) * w - m2.a * v;
        let rhs = (prev.rhs + plain.rhs) * w - (m2.b + self.t2[parity]) * v;
        let s = (prev.s + plain.s) * w - self.s2[parity] * v;
        let si = (prev.si + plain.si) * w - self.si2[parity] * v;
        let wd = (prev.w + plain.w) * w - self.w2[parity] * v;
        let e = prev
            .e
            .add_scaled(&plain.e, 1.0)
            .combine(w, &self.e2[parity], -v);
        let anchor = if parity == 0 { ANCHOR0 } else { ANCHOR1 };
        let (h0, h1) = (b.t_s - cm1.t_s, node.t_s - b.t_s);
        let c0 = 4.0 / (3.0 * h0) - 2.0 / (3.0 * h2);
        let c1 = 4.0 / (3.0 * h1) - 2.0 / (3.0 * h2);
        let noise_s = 0.25 * (c0 * c0 * h0 + c1 * c1 * h1);
        let mut row = self.assemble(&a, &rhs, (&s, si, &wd, &e), anchor, noise_s);
        if self.settings.stencil == Stencil::Adaptive {
            // Every ρ̄ of the stencil moves by κ Δ²ρ_c (h̄² times the second divided
            // difference at c): the κ column is minus the stencil's b for ρ̄ := Δ²ρ_c.
            let hbar = 0.5 * (h0 + h1);
            let d2 =
                (node.rho_nms - b.rho_nms) * (hbar / h1) - (b.rho_nms - cm1.rho_nms) * (hbar / h0);
            // The three intervals' `C N(φ)`, as computed above.
            let col = (prev.m.rotor(&d2) + plain.m.rotor(&d2)) * w - m2.rotor(&d2) * v;
            for i in 0..3 {
                row.a[(i, KAPPA)] = -col[i];
            }
        }
        Ok(Some(row))
    }

    fn assemble(
        &self,
        a: &Matrix3x6<f64>,
        rhs: &Vector3<f64>,
        (s, si, wd, e): (&Matrix3<f64>, f64, &Vector3<f64>, &TorqueMaps),
        anchor: usize,
        noise_s: f64,
    ) -> AugmentedRow {
        let mut out = SMatrix::<f64, 3, UNKNOWNS>::zeros();
        for i in 0..3 {
            out[(i, anchor + i)] = -1.0;
        }
        if self.settings.torque_bias {
            out.fixed_view_mut::<3, 3>(0, TORQUE).copy_from(&(-s));
        }
        if self.settings.damping {
            out.fixed_view_mut::<3, 1>(0, DAMPING).copy_from(wd);
        }
        // The outside torques' impulses (module `external_torque`): zero where none applies.
        out.fixed_view_mut::<3, 3>(0, DIPOLE)
            .copy_from(&(-e.dipole));
        out.fixed_view_mut::<3, 3>(0, CENTRE_OF_MASS)
            .copy_from(&(-e.centre_of_mass));
        out.fixed_view_mut::<3, 6>(0, J).copy_from(&(a - e.j));
        AugmentedRow {
            a: out,
            b: *rhs,
            noise_s,
            trend_s: si,
        }
    }
}

mod display;
