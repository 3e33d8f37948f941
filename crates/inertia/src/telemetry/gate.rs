//! The sample gate: the one place that checks a raw sample before it becomes a
//! [`Sample`], for every front end (the CSV reader, Python's arrays, the C API).
//!
//! A [`RawSample`] holds the numbers as read, in storage order. [`Gate::check`] refuses it
//! with a typed [`SampleError`] naming the [`Field`] at fault, or returns the sample:
//!
//! 1. each value finite and within the supported range ([`crate::sample::range`]), in the
//!    order time, quaternion, ρ, τ, ω;
//! 2. the quaternion read in its [`QuaternionFormat`] (Hamilton scalar last or first, or
//!    JPL, eq. 1's convention, or Hamilton inertial → body), its norm within [`GateOptions::unit_tolerance`] of 1, then
//!    renormalised (and counted);
//! 3. across samples (`Order`): time increasing, gyro rates given for every sample or
//!    none, and, in strict mode ([`GateOptions::period_tolerance`]), a uniform step;
//! 4. ρ (and with it nothing else) negated where the data use the opposite sign
//!    ([`GateOptions::negate_rho`]); gyro rates stored in deg/s converted to rad/s
//!    before their range check ([`GateOptions::gyro_unit`]).
//!
//! A front end keeps only its locating (a file's line and column name, an array's name and
//! row, a C sample's index) and the rendering of the message. A refused sample leaves the
//! gate as it was. [`ReadStats`] counts what was accepted, renormalised and sign-flipped.
//! The gate holds no heap memory (the C API's caller storage holds one).

use crate::attitude::Quaternion;
use crate::error_kind::ErrorKind;
use crate::sample::{check_value, External, Quantity, Sample};
use crate::text::Num;
use nalgebra::Vector3;

mod read_stats;
pub use read_stats::ReadStats;

/// Default tolerance on `| |q| − 1 |` below which quaternions are renormalised.
pub const DEFAULT_UNIT_TOLERANCE: f64 = 1e-3;

/// Where the scalar part of the quaternion is stored, and what the quaternion means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum QuaternionFormat {
    /// Hamilton, body → inertial, the four values are the vector part then the scalar
    /// (this crate's convention). The default.
    #[default]
    HamiltonScalarLast,
    /// Hamilton, body → inertial, scalar first: `[w, x, y, z]`.
    HamiltonScalarFirst,
    /// JPL/Shuster (inertial → body attitude matrix, scalar last). Converted with
    /// [`Quaternion::from_jpl_xyzw`].
    Jpl,
    /// Hamilton, scalar last, but mapping inertial → body (the conjugate of this crate's
    /// meaning): [`Quaternion::from_hamilton_inertial_to_body_xyzw`].
    Conjugate,
}

/// The unit of the gyro rates as stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GyroUnit {
    /// rad/s (the default).
    #[default]
    RadPerS,
    /// deg/s: converted to rad/s as read, before the range check.
    DegPerS,
}

impl GyroUnit {
    /// The factor that turns a stored rate into rad/s.
    #[must_use]
    pub(crate) fn to_rad_s(self) -> f64 {
        match self {
            Self::RadPerS => 1.0,
            Self::DegPerS => core::f64::consts::PI / 180.0,
        }
    }
}

/// One sample as a front end read it: the numbers in storage order, unchecked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawSample {
    /// Time, s.
    pub t_s: f64,
    /// The quaternion's four values in storage order ([`QuaternionFormat`]).
    pub q: [f64; 4],
    /// Total rotor angular momentum, N m s, as stored (before any negation).
    pub rho_nms: [f64; 3],
    /// Known external torque, N m (`None`: zero).
    pub tau_nm: Option<[f64; 3]>,
    /// Gyro rate averaged over the step, in [`GateOptions::gyro_unit`] (rad/s by
    /// default; `None`: not measured).
    pub w_rad_s: Option<[f64; 3]>,
    /// The measurements of outside effects, as stored ([`RawExternal`]; default none).
    pub external: RawExternal,
}

/// The outside measurements of a [`RawSample`] ([`crate::sample::External`]), unchecked;
/// each given for every sample or none.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RawExternal {
    /// Inertial position, m.
    pub position_m: Option<[f64; 3]>,
    /// Magnetic field, T, body axes.
    pub field_t: Option<[f64; 3]>,
    /// External force, N, body axes.
    pub force_n: Option<[f64; 3]>,
    /// Commanded magnetic dipole (magnetorquers), A m², body axes: its torque
    /// `m × B` is added to the known torque (needs the field).
    pub dipole_am2: Option<[f64; 3]>,
}

/// Which outside measurement ([`RawExternal`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ExternalKind {
    /// The position.
    Position,
    /// The magnetic field.
    Field,
    /// The force.
    Force,
    /// The commanded dipole.
    Dipole,
}

impl ExternalKind {
    const ALL: [ExternalKind; 4] = [
        ExternalKind::Position,
        ExternalKind::Field,
        ExternalKind::Force,
        ExternalKind::Dipole,
    ];

    /// Its value of `raw`.
    fn of(self, raw: &RawExternal) -> Option<[f64; 3]> {
        match self {
            ExternalKind::Position => raw.position_m,
            ExternalKind::Field => raw.field_t,
            ExternalKind::Force => raw.force_n,
            ExternalKind::Dipole => raw.dipole_am2,
        }
    }

    /// Its field, axis `k`.
    #[must_use]
    pub(crate) fn field(self, k: usize) -> Field {
        match self {
            ExternalKind::Position => Field::Position(k),
            ExternalKind::Field => Field::MagneticField(k),
            ExternalKind::Force => Field::Force(k),
            ExternalKind::Dipole => Field::Dipole(k),
        }
    }

    fn quantity(self, k: usize) -> Quantity {
        match self {
            ExternalKind::Position => Quantity::Position(k),
            ExternalKind::Field => Quantity::Field(k),
            ExternalKind::Force => Quantity::Force(k),
            ExternalKind::Dipole => Quantity::Dipole(k),
        }
    }

    /// Name for messages.
    #[must_use]
    pub(crate) fn name(self) -> &'static str {
        match self {
            ExternalKind::Position => "positions (r_x,r_y,r_z)",
            ExternalKind::Field => "magnetic fields (b_x,b_y,b_z)",
            ExternalKind::Force => "forces (f_x,f_y,f_z)",
            ExternalKind::Dipole => "commanded dipoles (dipole_x,dipole_y,dipole_z)",
        }
    }
}

/// A value of a sample: what a front end maps to its column, array element or C field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Field {
    /// The time.
    Time,
    /// The quaternion's value at storage position `0..4`.
    Quaternion(usize),
    /// The quaternion as a whole (its norm).
    QuaternionNorm,
    /// Rotor momentum, axis `0..3`.
    Rho(usize),
    /// Known torque, axis `0..3`.
    Tau(usize),
    /// Gyro rate, axis `0..3`.
    Rate(usize),
    /// Inertial position, axis `0..3`.
    Position(usize),
    /// Magnetic field, axis `0..3`.
    MagneticField(usize),
    /// External force, axis `0..3`.
    Force(usize),
    /// Commanded magnetic dipole, axis `0..3`.
    Dipole(usize),
}

/// Why the gate refused a sample.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SampleError {
    /// A value is NaN or infinite.
    #[error("value {value} is not finite")]
    NotFinite {
        /// Which.
        field: Field,
        /// The value.
        value: f64,
    },
    /// A value outside the supported range ([`crate::sample::range`]).
    #[error("value {} is outside the supported range (magnitude at most {} {unit})", Num(*.value), Num(*.limit))]
    OutOfRange {
        /// Which.
        field: Field,
        /// The value.
        value: f64,
        /// The largest magnitude supported.
        limit: f64,
        /// Its unit.
        unit: &'static str,
    },
    /// The quaternion's norm is too far from 1.
    #[error("quaternion norm {norm:.6} differs from 1 by more than {tolerance:e}")]
    NonUnitQuaternion {
        /// Its norm.
        norm: f64,
        /// The tolerance.
        tolerance: f64,
    },
    /// Time does not increase.
    #[error("time {} s does not increase (previous row: {} s)", Num(*.t_s), Num(*.previous_s))]
    TimeNotIncreasing {
        /// This sample's time, s.
        t_s: f64,
        /// The previous sample's, s.
        previous_s: f64,
    },
    /// In strict mode, the step differs from the first one.
    #[error("step {} s differs from the sample period {} s by more than {tolerance:e} (relative); resample or split the data", Num(*.dt_s), Num(*.period_s))]
    NonUniformPeriod {
        /// This step, s.
        dt_s: f64,
        /// The period set by the first step, s.
        period_s: f64,
        /// The relative tolerance.
        tolerance: f64,
    },
    /// Without quaternions the attitude is integrated from the gyro rates, and this
    /// sample has none.
    #[error("no attitude: without quaternion columns the attitude is integrated from the gyro rates (w_x,w_y,w_z), which this sample lacks")]
    NoAttitude,
    /// Gyro rates given for some samples and not for others.
    #[error("gyro rates {} here but {} for the earlier samples: give them for every sample or none", given(*.given_here), given(!*.given_here))]
    GyroChanged {
        /// Whether this sample has them.
        given_here: bool,
    },
    /// An outside measurement given for some samples and not for others.
    #[error("{} {} here but {} for the earlier samples: give them for every sample or none", .what.name(), given(*.given_here), given(!*.given_here))]
    ExternalChanged {
        /// Which.
        what: ExternalKind,
        /// Whether this sample has it.
        given_here: bool,
    },
    /// A commanded dipole without the magnetic field its torque needs.
    #[error("commanded dipoles (dipole_x,dipole_y,dipole_z) need the magnetic field (b_x,b_y,b_z) for their torque m × B")]
    DipoleWithoutField,
    /// A position at the centre of the attracting body, where the gravity gradient has
    /// no direction.
    #[error(
        "position (r_x,r_y,r_z) zero: the position is from the centre of the attracting body, in m"
    )]
    PositionAtCentre,
    /// Positions with an attitude integrated from the gyro, whose inertial frame is the
    /// first body frame, not the positions'.
    #[error("positions (r_x,r_y,r_z) need the attitude in their inertial frame, and without quaternions it is integrated from the gyro in an arbitrary one")]
    PositionWithoutAttitude,
}

fn given(yes: bool) -> &'static str {
    if yes {
        "given"
    } else {
        "missing"
    }
}

impl SampleError {
    /// The value at fault.
    #[must_use]
    pub fn field(&self) -> Field {
        match self {
            SampleError::NotFinite { field, .. } | SampleError::OutOfRange { field, .. } => *field,
            SampleError::NonUnitQuaternion { .. } => Field::QuaternionNorm,
            SampleError::TimeNotIncreasing { .. } | SampleError::NonUniformPeriod { .. } => {
                Field::Time
            }
            SampleError::GyroChanged { .. } | SampleError::NoAttitude => Field::Rate(0),
            SampleError::ExternalChanged { what, .. } => what.field(0),
            SampleError::DipoleWithoutField => Field::Dipole(0),
            SampleError::PositionWithoutAttitude | SampleError::PositionAtCentre => {
                Field::Position(0)
            }
        }
    }

    /// Its kind, as every front end reports it.
    #[must_use]
    pub fn error_kind(&self) -> ErrorKind {
        match self {
            SampleError::NotFinite { .. } => ErrorKind::NotFinite,
            SampleError::OutOfRange { .. } => ErrorKind::OutOfRange,
            SampleError::NonUnitQuaternion { .. } => ErrorKind::NonUnitQuaternion,
            SampleError::TimeNotIncreasing { .. } => ErrorKind::TimeNotIncreasing,
            SampleError::NonUniformPeriod { .. } => ErrorKind::NonUniformPeriod,
            SampleError::GyroChanged { .. } => ErrorKind::GyroChanged,
            SampleError::NoAttitude => ErrorKind::NeedsGyro,
            SampleError::ExternalChanged { .. }
            | SampleError::DipoleWithoutField
            | SampleError::PositionWithoutAttitude => ErrorKind::Columns,
            SampleError::PositionAtCentre => ErrorKind::OutOfRange,
        }
    }
}

/// The checks across samples: time increasing and gyro rates all-or-none. Also used by
/// [`crate::pipeline::Run`] for samples that did not come through a [`Gate`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Order {
    last_t_s: Option<f64>,
    gyro: Option<bool>,
    /// Which outside measurements the accepted samples have ([`ExternalKind::ALL`] order).
    external: Option<[bool; 4]>,
}

impl Order {
    /// Whether a sample at `t_s`, with gyro rates or not, may follow the accepted ones.
    pub(crate) fn check(&self, t_s: f64, has_gyro: bool) -> Result<(), SampleError> {
        if let Some(g) = self.gyro {
            if g != has_gyro {
                return Err(SampleError::GyroChanged {
                    given_here: has_gyro,
                });
            }
        }
        if let Some(previous_s) = self.last_t_s {
            if !(t_s > previous_s) {
                return Err(SampleError::TimeNotIncreasing { t_s, previous_s });
            }
        }
        Ok(())
    }

    /// Whether a sample with the outside measurements `given` (in [`ExternalKind::ALL`]
    /// order) may follow the accepted ones.
    pub(crate) fn check_external(&self, given: [bool; 4]) -> Result<(), SampleError> {
        if let Some(before) = self.external {
            for (k, what) in ExternalKind::ALL.into_iter().enumerate() {
                if before[k] != given[k] {
                    return Err(SampleError::ExternalChanged {
                        what,
                        given_here: given[k],
                    });
                }
            }
        }
        Ok(())
    }

    /// Record an accepted sample.
    pub(crate) fn accept(&mut self, t_s: f64, has_gyro: bool) {
        self.last_t_s = Some(t_s);
        self.gyro = Some(has_gyro);
    }

    /// Record an accepted sample's outside measurements.
    pub(crate) fn accept_external(&mut self, given: [bool; 4]) {
        self.external = Some(given);
    }

    /// The time of the last accepted sample, s.
    #[must_use]
    pub(crate) fn last_t_s(&self) -> Option<f64> {
        self.last_t_s
    }
}

/// How the gate reads the values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GateOptions {
    /// Quaternion storage and convention.
    pub quaternion: QuaternionFormat,
    /// Quaternions with `| |q| − 1 |` up to this are renormalised (and counted); beyond it
    /// they are refused. Default [`DEFAULT_UNIT_TOLERANCE`].
    pub unit_tolerance: f64,
    /// When set, the relative tolerance on the uniformity of the step (strict mode).
    pub period_tolerance: Option<f64>,
    /// ρ holds the rotor momentum with the opposite sign of this library's convention:
    /// negate it.
    pub negate_rho: bool,
    /// The unit of the stored gyro rates. Default rad/s.
    pub gyro_unit: GyroUnit,
    /// No quaternions are given (a front end's input has no attitude): the attitude is
    /// integrated from the gyro rates instead, `q_0 = 1` and `q_{k+1} = q_k ⊗ exp(ω̄_k
    /// h_k)` with `ω̄_k` the rate averaged over `[t_k, t_{k+1}]` (exact for a rate
    /// constant over the step, no coning correction;
    /// the inertial frame is the first sample's body frame, which the momentum rows do not
    /// care about), and every sample must have a rate ([`SampleError::NoAttitude`]). The
    /// attitude then drifts with the gyro's noise; [`RawSample::q`] is ignored. Default
    /// `false`.
    pub attitude_from_gyro: bool,
}

impl Default for GateOptions {
    fn default() -> Self {
        Self {
            quaternion: QuaternionFormat::default(),
            unit_tolerance: DEFAULT_UNIT_TOLERANCE,
            period_tolerance: None,
            negate_rho: false,
            gyro_unit: GyroUnit::RadPerS,
            attitude_from_gyro: false,
        }
    }
}

/// The gate over one sequence of samples.
#[derive(Debug, Clone, Copy, Default)]
pub struct Gate {
    options: GateOptions,
    order: Order,
    prev_q: Option<Quaternion>,
    /// The previous sample's gyro rate, rad/s (integrating the attitude).
    prev_w: Option<Vector3<f64>>,
    period_s: Option<f64>,
    stats: ReadStats,
}

fn value(field: Field, quantity: Quantity, v: f64) -> Result<f64, SampleError> {
    if !v.is_finite() {
        return Err(SampleError::NotFinite { field, value: v });
    }
    check_value(quantity, v).map_err(|_| {
        let (limit, unit) = quantity.limit();
        SampleError::OutOfRange {
            field,
            value: v,
            limit,
            unit,
        }
    })?;
    Ok(v)
}

fn vec3(
    v: [f64; 3],
    field: fn(usize) -> Field,
    quantity: fn(usize) -> Quantity,
) -> Result<Vector3<f64>, SampleError> {
    let mut out = Vector3::zeros();
    for k in 0..3 {
        out[k] = value(field(k), quantity(k), v[k])?;
    }
    Ok(out)
}

impl Gate {
    /// A gate reading with `options`.
    #[must_use]
    pub fn new(options: GateOptions) -> Self {
        Self {
            options,
            stats: ReadStats {
                attitude_from_gyro: options.attitude_from_gyro,
                ..ReadStats::default()
            },
            ..Self::default()
        }
    }

    /// Counts so far.
    #[must_use]
    pub fn stats(&self) -> ReadStats {
        self.stats
    }

    /// Count a sample refused by its front end before the gate saw it (unparsable).
    pub(crate) fn reject(&mut self) {
        self.stats.rejected += 1;
    }

    /// The next sample, checked; a refused one leaves the gate as it was (but counted in
    /// [`ReadStats::rejected`]).
    pub fn check(&mut self, raw: &RawSample) -> Result<Sample, SampleError> {
        self.checked(raw).inspect_err(|_| self.reject())
    }

    fn checked(&mut self, raw: &RawSample) -> Result<Sample, SampleError> {
        let t_s = value(Field::Time, Quantity::Time, raw.t_s)?;
        let (q, renormalised) = if self.options.attitude_from_gyro {
            (Quaternion::IDENTITY, false)
        } else {
            self.quaternion(raw)?
        };
        let rho = vec3(raw.rho_nms, Field::Rho, Quantity::Rho)?;
        let tau = match raw.tau_nm {
            Some(v) => vec3(v, Field::Tau, Quantity::Tau)?,
            None => Vector3::zeros(),
        };
        let to_rad_s = self.options.gyro_unit.to_rad_s();
        let w = raw
            .w_rad_s
            .map(|v| vec3(v.map(|x| x * to_rad_s), Field::Rate, Quantity::Rate))
            .transpose()?;
        if self.options.attitude_from_gyro && w.is_none() {
            return Err(SampleError::NoAttitude);
        }
        let (external, dipole_torque) = self.external(&raw.external)?;
        let tau = tau + dipole_torque;
        for k in 0..3 {
            value(Field::Tau(k), Quantity::Tau(k), tau[k])?;
        }
        self.order.check(t_s, w.is_some())?;
        let given = ExternalKind::ALL.map(|what| what.of(&raw.external).is_some());
        self.order.check_external(given)?;
        let q = match (self.options.attitude_from_gyro, self.prev_q, self.prev_w) {
            (true, Some(p), Some(pw)) => {
                let h = t_s - self.order.last_t_s().unwrap_or(t_s);
                let next = p.mul(&Quaternion::exp(&(pw * h)));
                next.normalize().unwrap_or(next)
            }
            _ => q,
        };
        let mut sample = self.accept(t_s, q, renormalised, rho, tau, w)?;
        self.order.accept_external(given);
        sample.external = external;
        Ok(sample)
    }

    /// The outside measurements checked, and the commanded dipole's torque `m × B`, N m.
    fn external(&self, raw: &RawExternal) -> Result<(External, Vector3<f64>), SampleError> {
        let mut v = [None; 4];
        for (k, what) in ExternalKind::ALL.into_iter().enumerate() {
            if let Some(x) = what.of(raw) {
                let mut out = Vector3::zeros();
                for i in 0..3 {
                    out[i] = value(what.field(i), what.quantity(i), x[i])?;
                }
                v[k] = Some(out);
            }
        }
        let [position_m, field_t, force_n, dipole] = v;
        if position_m.is_some() && self.options.attitude_from_gyro {
            return Err(SampleError::PositionWithoutAttitude);
        }
        if position_m.is_some_and(|r| r == Vector3::zeros()) {
            return Err(SampleError::PositionAtCentre);
        }
        let torque = match (dipole, field_t) {
            (Some(m), Some(b)) => m.cross(&b),
            (Some(_), None) => return Err(SampleError::DipoleWithoutField),
            (None, _) => Vector3::zeros(),
        };
        Ok((
            External {
                position_m,
                field_t,
                force_n,
            },
            torque,
        ))
    }

    /// The quaternion of `raw` in this library's convention, and whether it was
    /// renormalised.
    fn quaternion(&self, raw: &RawSample) -> Result<(Quaternion, bool), SampleError> {
        for (k, &v) in raw.q.iter().enumerate() {
            if !v.is_finite() {
                return Err(SampleError::NotFinite {
                    field: Field::Quaternion(k),
                    value: v,
                });
            }
        }
        let read = match self.options.quaternion {
            QuaternionFormat::HamiltonScalarLast => Quaternion::from_xyzw(raw.q),
            QuaternionFormat::HamiltonScalarFirst => Quaternion::from_wxyz(raw.q),
            QuaternionFormat::Jpl => Quaternion::from_jpl_xyzw(raw.q),
            QuaternionFormat::Conjugate => Quaternion::from_hamilton_inertial_to_body_xyzw(raw.q),
        };
        let norm = read.norm();
        let tolerance = self.options.unit_tolerance;
        if !((norm - 1.0).abs() <= tolerance) {
            return Err(SampleError::NonUnitQuaternion { norm, tolerance });
        }
        let mut q = read;
        let mut renormalised = false;
        if norm != 1.0 {
            if let Some(n) = read.normalize() {
                renormalised = (norm - 1.0).abs() > 1e-12;
                q = n;
            }
        }
        Ok((q, renormalised))
    }

    /// The checks across samples (strict period), then the sample accepted.
    fn accept(
        &mut self,
        t_s: f64,
        q: Quaternion,
        renormalised: bool,
        rho: Vector3<f64>,
        tau: Vector3<f64>,
        w: Option<Vector3<f64>>,
    ) -> Result<Sample, SampleError> {
        let mut period_s = self.period_s;
        if let (Some(previous_s), Some(tol)) =
            (self.order.last_t_s(), self.options.period_tolerance)
        {
            let dt_s = t_s - previous_s;
            match period_s {
                None => period_s = Some(dt_s),
                Some(p) if (dt_s - p).abs() > tol * p => {
                    return Err(SampleError::NonUniformPeriod {
                        dt_s,
                        period_s: p,
                        tolerance: tol,
                    })
                }
                Some(_) => {}
            }
        }
        // Accepted: from here on the gate changes.
        self.period_s = period_s;
        if let (Some(previous_s), Some(prev_q)) = (self.order.last_t_s(), self.prev_q) {
            self.stats.step(t_s - previous_s, &prev_q, &q);
        }
        self.stats.renormalised += usize::from(renormalised);
        self.stats.rows += 1;
        self.order.accept(t_s, w.is_some());
        self.prev_q = Some(q);
        self.prev_w = w;
        Ok(Sample {
            t_s,
            q,
            rho_nms: if self.options.negate_rho { -rho } else { rho },
            tau_nm: tau,
            omega_rad_s: w,
            external: External::NONE,
        })
    }
}

#[cfg(test)]
mod tests;
