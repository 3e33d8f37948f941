//! The estimator handle: creation on the heap or in caller storage, push, reading the
//! estimate, reset and free.

use crate::engine::Engine;
use crate::estimate::InertiaEstimate;
use crate::message;
use crate::settings::{InertiaSettings, Plan};
use crate::status::{fail, fixes, guard, guard_or, null, pipeline_fail, InertiaStatus};
use core::ffi::{c_char, c_void};
use core::fmt::Write as _;
use core::mem::{align_of, size_of};
use inertia::error_kind::ErrorKind;
use inertia::estimator::Estimate;
use inertia::fix::Fix;
use inertia::pipeline::{check_first_step, Pipeline};
use inertia::telemetry::gate::{Field, Gate, RawExternal, RawSample, SampleError};

/// One telemetry sample at time `t_s` (README "Estimating your own telemetry").
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaSample {
    /// Time, s; increasing from sample to sample.
    pub t_s: f64,
    /// Attitude `[x, y, z, w]`, scalar last, Hamilton, body → inertial; renormalised when
    /// its norm is within 1e-3 of 1 (as the CSV reader does), refused beyond.
    pub q: [f64; 4],
    /// Total rotor angular momentum, N m s, body axes.
    pub rho_nms: [f64; 3],
    /// Known external torque, N m, body axes (zeros when none is known).
    pub tau_nm: [f64; 3],
    /// Gyro rate averaged over `[t_k, t_{k+1}]`, rad/s, body axes; read only when
    /// `has_w` is non-zero.
    pub w_rad_s: [f64; 3],
    /// Non-zero when `w_rad_s` holds a gyro rate. Use the same for every sample.
    pub has_w: u8,
}

/// Measurements of what acts from outside at one sample (`inertia_estimator_push_external`):
/// each read only where its `has_` flag is non-zero, and then given for every sample.
/// With them the default estimator models the gravity gradient (`r_m`), estimates a
/// residual magnetic dipole (`b_t`) and the centre of mass (`f_n`; `tau_nm` then about
/// the body frame's origin), and adds a commanded dipole's torque `m × B` to the known
/// torque (`dipole_am2`, needs `b_t`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct InertiaExternal {
    /// Position of the centre of mass in the attitude's inertial frame (the orbit), m.
    pub r_m: [f64; 3],
    /// Magnetic field, T, body axes.
    pub b_t: [f64; 3],
    /// External force (thrusters), N, body axes.
    pub f_n: [f64; 3],
    /// Commanded magnetic dipole, A m², body axes.
    pub dipole_am2: [f64; 3],
    /// Non-zero when `r_m` holds a position.
    pub has_r: u8,
    /// Non-zero when `b_t` holds a field.
    pub has_b: u8,
    /// Non-zero when `f_n` holds a force.
    pub has_f: u8,
    /// Non-zero when `dipole_am2` holds a commanded dipole.
    pub has_dipole: u8,
}

impl InertiaExternal {
    fn raw(&self) -> RawExternal {
        let given = |flag: u8, v: [f64; 3]| (flag != 0).then_some(v);
        RawExternal {
            position_m: given(self.has_r, self.r_m),
            field_t: given(self.has_b, self.b_t),
            force_n: given(self.has_f, self.f_n),
            dipole_am2: given(self.has_dipole, self.dipole_am2),
        }
    }
}

/// An estimator (opaque).
pub struct InertiaEstimator {
    pub(crate) engine: Engine,
    /// Built by `inertia_estimator_new` (freed with a deallocation) rather than in caller
    /// storage.
    pub(crate) heap: bool,
    pub(crate) stopped: bool,
    /// The library's sample gate (no heap): values, time order, gyro rates all-or-none.
    pub(crate) gate: Gate,
    /// The first sample's time, s.
    pub(crate) t0_s: Option<f64>,
    pub(crate) samples: u64,
    pub(crate) last: Option<Estimate>,
    /// The memory and resampling settings, for the library's check of the first step
    /// (`inertia::pipeline::check_first_step`).
    pub(crate) memory_s: Option<f64>,
    pub(crate) resample_s: Option<f64>,
}

impl InertiaEstimator {
    fn new(engine: Engine, heap: bool, plan: &Plan) -> Self {
        Self {
            engine,
            heap,
            stopped: false,
            gate: Gate::default(),
            t0_s: None,
            samples: 0,
            last: None,
            memory_s: plan.memory_s,
            resample_s: plan.resample_s,
        }
    }

    fn push(&mut self, s: &InertiaSample, external: &InertiaExternal) -> InertiaStatus {
        if self.stopped {
            let status = fail(
                InertiaStatus::Stopped,
                format_args!("the estimator stopped on an earlier error: reset it"),
            );
            message::set_kind(Some(ErrorKind::Stopped), Some(self.samples));
            return status;
        }
        let has_w = s.has_w != 0;
        if !has_w && self.engine.needs_gyro() {
            let status = fail(
                InertiaStatus::Data,
                format_args!("this estimator needs gyro rates (has_w) in every sample"),
            );
            message::set_kind(Some(ErrorKind::NeedsGyro), Some(self.samples));
            return status;
        }
        // The library's sample gate; a refused sample leaves it (and this estimator) as
        // it was. `InertiaSample::q` is scalar last, Hamilton: the gate's default.
        let before = self.gate;
        let sample = match self.gate.check(&RawSample {
            t_s: s.t_s,
            q: s.q,
            rho_nms: s.rho_nms,
            tau_nm: Some(s.tau_nm),
            w_rad_s: has_w.then_some(s.w_rad_s),
            external: external.raw(),
        }) {
            Ok(sample) => sample,
            Err(e) => {
                let status = match e {
                    SampleError::NotFinite { .. } => InertiaStatus::NotFinite,
                    SampleError::OutOfRange { .. } | SampleError::NonUnitQuaternion { .. } => {
                        InertiaStatus::OutOfRange
                    }
                    _ => InertiaStatus::Data,
                };
                let status = fail(
                    status,
                    format_args!("sample {}: {}: {e}", self.samples, field_name(e.field())),
                );
                message::set_kind(Some(e.error_kind()), Some(self.samples));
                return status;
            }
        };
        if let (Some(t0), 1) = (self.t0_s, self.samples) {
            if let Err(e) = check_first_step(self.memory_s, self.resample_s, s.t_s - t0) {
                self.gate = before;
                let status = fail(
                    InertiaStatus::InvalidSetting,
                    format_args!("sample 1: {e}{}", fixes(&[Fix::Memory])),
                );
                message::set_kind(Some(ErrorKind::MemoryShorterThanStep), Some(1));
                return status;
            }
        }
        self.t0_s.get_or_insert(s.t_s);
        self.samples += 1;
        match self.engine.push(&sample) {
            Ok(Some(e)) => {
                self.last = Some(e);
                InertiaStatus::Ok
            }
            Ok(None) => InertiaStatus::Ok,
            Err(e) => {
                self.stopped = true;
                pipeline_fail(&e)
            }
        }
    }

    fn reset(&mut self) -> InertiaStatus {
        // Stopped until the reset succeeds.
        self.stopped = true;
        if let Err(e) = self.engine.reset() {
            return pipeline_fail(&e);
        }
        self.stopped = false;
        self.gate = Gate::default();
        self.t0_s = None;
        self.samples = 0;
        self.last = None;
        InertiaStatus::Ok
    }
}

/// Create an estimator on the heap (any estimator). On success `*out` holds it; free it
/// with `inertia_estimator_free`. On failure `*out` is set to NULL (when `out` is not
/// NULL).
///
/// # Safety
/// `settings` is NULL or points to an `InertiaSettings`; `out` is NULL or points to
/// writable storage for a pointer.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_new(
    settings: *const InertiaSettings,
    out: *mut *mut InertiaEstimator,
) -> InertiaStatus {
    guard(|| {
        if out.is_null() || settings.is_null() {
            return null("inertia_estimator_new: `settings` and `out` must not be NULL");
        }
        // SAFETY: `out` is non-null and, by the contract, points to a writable pointer.
        unsafe { out.write(core::ptr::null_mut()) };
        // SAFETY: `settings` is non-null and, by the contract, points to an
        // `InertiaSettings`; every field type accepts any bit pattern (no enums, no bool).
        let s = unsafe { settings.read() };
        let plan = match Plan::from_c(&s) {
            Ok(p) => p,
            Err(status) => return status,
        };
        let settings = plan.pipeline_settings();
        let pipeline = match Pipeline::new(&settings) {
            Ok(p) => p,
            Err(e) => return pipeline_fail(&e),
        };
        let est = Box::new(InertiaEstimator::new(
            Engine::Pipeline { pipeline, settings },
            true,
            &plan,
        ));
        // SAFETY: as above, `out` is valid for writes.
        unsafe { out.write(Box::into_raw(est)) };
        InertiaStatus::Ok
    })
}

/// Bytes of storage `inertia_estimator_init` needs.
#[no_mangle]
pub extern "C" fn inertia_estimator_size() -> usize {
    size_of::<InertiaEstimator>()
}

/// Alignment, bytes, of the storage `inertia_estimator_init` needs.
#[no_mangle]
pub extern "C" fn inertia_estimator_align() -> usize {
    align_of::<InertiaEstimator>()
}

/// Build an estimator in caller storage, with no heap allocation then or later: the
/// `variational` or `finite-difference` estimator (any other is
/// `INERTIA_STATUS_NEEDS_HEAP`). `storage` must hold `inertia_estimator_size()` bytes
/// aligned to `inertia_estimator_align()`. On success `*out` is the estimator (it
/// points into `storage`); end it with `inertia_estimator_free` (which frees nothing,
/// and drops nothing that holds memory) before reusing the storage.
///
/// # Safety
/// `storage` is NULL or valid for writes of `len` bytes, not used by anything else while
/// the estimator lives; `settings` is NULL or points to an `InertiaSettings`; `out` is
/// NULL or points to writable storage for a pointer.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_init(
    storage: *mut c_void,
    len: usize,
    settings: *const InertiaSettings,
    out: *mut *mut InertiaEstimator,
) -> InertiaStatus {
    guard(|| {
        if storage.is_null() || settings.is_null() || out.is_null() {
            return null(
                "inertia_estimator_init: `storage`, `settings` and `out` must not be NULL",
            );
        }
        // SAFETY: `out` is non-null and points to a writable pointer (contract).
        unsafe { out.write(core::ptr::null_mut()) };
        if len < inertia_estimator_size() || !storage.cast::<InertiaEstimator>().is_aligned() {
            return fail(
                InertiaStatus::BadStorage,
                format_args!(
                    "inertia_estimator_init: storage of {len} bytes at an address aligned to {}: needs {} bytes aligned to {}",
                    1usize << (storage as usize).trailing_zeros().min(63),
                    inertia_estimator_size(),
                    inertia_estimator_align()
                ),
            );
        }
        // SAFETY: non-null, points to an `InertiaSettings` (contract); all field types
        // accept any bit pattern.
        let s = unsafe { settings.read() };
        let (plan, engine) = match Plan::from_c(&s).and_then(|p| Ok((p.fixed_engine()?, p))) {
            Ok((e, p)) => (p, e),
            Err(status) => return status,
        };
        let est = storage.cast::<InertiaEstimator>();
        // SAFETY: `storage` is non-null, aligned and at least `size_of::<InertiaEstimator>()`
        // bytes long (checked above) and valid for writes (contract); `write` does not
        // read or drop what was there.
        unsafe { est.write(InertiaEstimator::new(engine, false, &plan)) };
        // SAFETY: `out` is valid for writes (contract).
        unsafe { out.write(est) };
        InertiaStatus::Ok
    })
}

/// Push one sample. An estimate is formed when the sample completes a row block and a
/// solve is due; read it with `inertia_estimator_get`. Refused samples (NULL, NaN,
/// outside the supported range, time not increasing, `has_w` changing) leave the
/// estimator as it was. Other data errors (`INERTIA_STATUS_DATA`, `_SOLVER`) stop it
/// until `inertia_estimator_reset`.
///
/// # Safety
/// `est` is NULL or an estimator from `inertia_estimator_new`/`_init` not yet freed, not
/// used concurrently; `sample` is NULL or points to an `InertiaSample`.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_push(
    est: *mut InertiaEstimator,
    sample: *const InertiaSample,
) -> InertiaStatus {
    // SAFETY: by the contract a non-null `est` is a live estimator used by no one else.
    let Some(e) = (unsafe { est.as_mut() }) else {
        return null("inertia_estimator_push: `est` must not be NULL");
    };
    if sample.is_null() {
        return null("inertia_estimator_push: `sample` must not be NULL");
    }
    // SAFETY: non-null, points to an `InertiaSample` (contract); its fields accept any
    // bit pattern.
    let s = unsafe { sample.read() };
    let status = guard(|| e.push(&s, &InertiaExternal::default()));
    if status == InertiaStatus::Panic {
        // A panic may have left the state half-updated: stopped until reset.
        e.stopped = true;
    }
    status
}

/// `inertia_estimator_push` with the sample's outside measurements (`external` NULL: none,
/// as `inertia_estimator_push`). Each measurement is given for every sample or none; a
/// refused sample leaves the estimator as it was.
///
/// # Safety
/// As `inertia_estimator_push`; `external` is NULL or points to an `InertiaExternal`.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_push_external(
    est: *mut InertiaEstimator,
    sample: *const InertiaSample,
    external: *const InertiaExternal,
) -> InertiaStatus {
    // SAFETY: by the contract a non-null `est` is a live estimator used by no one else.
    let Some(e) = (unsafe { est.as_mut() }) else {
        return null("inertia_estimator_push_external: `est` must not be NULL");
    };
    if sample.is_null() {
        return null("inertia_estimator_push_external: `sample` must not be NULL");
    }
    // SAFETY: non-null, points to an `InertiaSample` (contract); any bit pattern.
    let s = unsafe { sample.read() };
    // SAFETY: NULL or points to an `InertiaExternal` (contract); any bit pattern.
    let x = unsafe { external.as_ref() }.copied().unwrap_or_default();
    let status = guard(|| e.push(&s, &x));
    if status == InertiaStatus::Panic {
        e.stopped = true;
    }
    status
}

/// What the estimator made of the outside measurements at its last estimate
/// (`inertia_estimator_outside`): each vector with its σ per component, valid where its
/// `has_` flag is non-zero.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct InertiaOutside {
    /// The residual magnetic dipole, A m², body axes.
    pub dipole_am2: [f64; 3],
    /// Its σ, A m² (NaN for a component the data never separated).
    pub dipole_sigma_am2: [f64; 3],
    /// A direction (unit, body axes) along which the data do not determine the dipole,
    /// where `dipole_undetermined` is non-zero.
    pub dipole_undetermined_direction: [f64; 3],
    /// The centre of mass, m, body axes from the known torque's origin.
    pub centre_of_mass_m: [f64; 3],
    /// Its σ, m (NaN for a component the data never separated).
    pub centre_of_mass_sigma_m: [f64; 3],
    /// A direction along which the data do not determine the centre of mass, where
    /// `centre_of_mass_undetermined` is non-zero.
    pub centre_of_mass_undetermined_direction: [f64; 3],
    /// Non-zero when the gravity-gradient torque was modelled.
    pub gravity_gradient: u8,
    /// Non-zero when the dipole (and its σ) were estimated.
    pub has_dipole: u8,
    /// Non-zero when the centre of mass (and its σ) were estimated.
    pub has_centre_of_mass: u8,
    /// Non-zero when a direction of the dipole is not determined.
    pub dipole_undetermined: u8,
    /// Non-zero when a direction of the centre of mass is not determined.
    pub centre_of_mass_undetermined: u8,
}

/// Copy what the estimator made of the outside measurements into `*out` (all flags zero
/// before an estimate, or for estimators that do not model them).
///
/// # Safety
/// `est` is NULL or a live estimator; `out` is NULL or points to writable storage for an
/// `InertiaOutside`.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_outside(
    est: *const InertiaEstimator,
    out: *mut InertiaOutside,
) -> InertiaStatus {
    // SAFETY: a non-null `est` is a live estimator (contract).
    let Some(e) = (unsafe { est.as_ref() }) else {
        return null("inertia_estimator_outside: `est` must not be NULL");
    };
    if out.is_null() {
        return null("inertia_estimator_outside: `out` must not be NULL");
    }
    guard(|| {
        let mut o = InertiaOutside::default();
        if let Some(x) = e.engine.outside() {
            o.gravity_gradient = u8::from(x.gravity_gradient);
            let sigma = |v: &inertia::estimator::external_torque::Estimated3| {
                v.sigma.map(|s| s.unwrap_or(f64::NAN))
            };
            let direction = |v: &inertia::estimator::external_torque::Estimated3| {
                (
                    u8::from(v.undetermined_direction.is_some()),
                    v.undetermined_direction.unwrap_or_default(),
                )
            };
            if let Some(v) = x.residual_dipole_am2 {
                o.has_dipole = 1;
                o.dipole_am2 = v.value;
                o.dipole_sigma_am2 = sigma(&v);
                (o.dipole_undetermined, o.dipole_undetermined_direction) = direction(&v);
            }
            if let Some(v) = x.centre_of_mass_m {
                o.has_centre_of_mass = 1;
                o.centre_of_mass_m = v.value;
                o.centre_of_mass_sigma_m = sigma(&v);
                (
                    o.centre_of_mass_undetermined,
                    o.centre_of_mass_undetermined_direction,
                ) = direction(&v);
            }
        }
        // SAFETY: `out` is non-null and valid for writes (contract).
        unsafe { out.write(o) };
        InertiaStatus::Ok
    })
}

/// Copy the current estimate into `*out` (status `INERTIA_ESTIMATE_STATUS_NONE` before
/// the first).
///
/// # Safety
/// `est` is NULL or a live estimator; `out` is NULL or points to writable storage for an
/// `InertiaEstimate`.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_get(
    est: *const InertiaEstimator,
    out: *mut InertiaEstimate,
) -> InertiaStatus {
    // SAFETY: a non-null `est` is a live estimator (contract).
    let Some(e) = (unsafe { est.as_ref() }) else {
        return null("inertia_estimator_get: `est` must not be NULL");
    };
    if out.is_null() {
        return null("inertia_estimator_get: `out` must not be NULL");
    }
    guard(|| {
        let estimate = e.estimate();
        // SAFETY: `out` is non-null and valid for writes (contract).
        unsafe { out.write(estimate) };
        InertiaStatus::Ok
    })
}

/// Copy the reason of the current estimate in words (empty when there is none) into
/// `buf` (`len` bytes, always NUL-terminated when `len > 0`, cut at a character
/// boundary). Returns the length of the whole message without the NUL, like
/// `snprintf`.
///
/// # Safety
/// `est` is NULL or a live estimator; `buf` is NULL or valid for writes of `len` bytes.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_reason(
    est: *const InertiaEstimator,
    buf: *mut c_char,
    len: usize,
) -> usize {
    // SAFETY: a non-null `est` is a live estimator (contract).
    let Some(e) = (unsafe { est.as_ref() }) else {
        return 0;
    };
    guard_or(0, || {
        let mut m = message::Buffer::new();
        if let Some(r) = e.last.and_then(|l| l.observability.reason()) {
            let _ = write!(m, "{r}");
        }
        // SAFETY: `buf` is NULL or valid for `len` bytes (contract).
        unsafe { m.copy_to(buf, len) }
    })
}

/// Start again from no data with the same settings (also clears a stop). Allocates for a
/// heap estimator (the pipeline is rebuilt); not in caller storage.
///
/// # Safety
/// `est` is NULL or a live estimator not used concurrently.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_reset(est: *mut InertiaEstimator) -> InertiaStatus {
    // SAFETY: a non-null `est` is a live estimator used by no one else (contract).
    let Some(e) = (unsafe { est.as_mut() }) else {
        return null("inertia_estimator_reset: `est` must not be NULL");
    };
    guard(|| e.reset())
}

/// End an estimator: free it when `inertia_estimator_new` made it; for one in caller
/// storage, end it in place (the storage is the caller's again). NULL is ignored.
///
/// # Safety
/// `est` is NULL or a live estimator, not used again afterwards.
#[no_mangle]
pub unsafe extern "C" fn inertia_estimator_free(est: *mut InertiaEstimator) {
    if est.is_null() {
        return;
    }
    let _ = guard(|| {
        // SAFETY: `est` is a live estimator (contract); reading `heap` is a plain read.
        let heap = unsafe { (*est).heap };
        if heap {
            // SAFETY: `heap` means `est` came from `Box::into_raw` in
            // `inertia_estimator_new`, and it is not used again (contract).
            drop(unsafe { Box::from_raw(est) });
        } else {
            // SAFETY: `est` was written in place by `inertia_estimator_init` and is not
            // used again (contract): drop it where it is, without deallocating.
            unsafe { core::ptr::drop_in_place(est) };
        }
        InertiaStatus::Ok
    });
}

/// The `InertiaSample` field of a gate's [`Field`].
fn field_name(f: Field) -> &'static str {
    const Q: [&str; 4] = ["q[0]", "q[1]", "q[2]", "q[3]"];
    const RHO: [&str; 3] = ["rho_nms[0]", "rho_nms[1]", "rho_nms[2]"];
    const TAU: [&str; 3] = ["tau_nm[0]", "tau_nm[1]", "tau_nm[2]"];
    const W: [&str; 3] = ["w_rad_s[0]", "w_rad_s[1]", "w_rad_s[2]"];
    const R: [&str; 3] = ["external.r_m[0]", "external.r_m[1]", "external.r_m[2]"];
    const B: [&str; 3] = ["external.b_t[0]", "external.b_t[1]", "external.b_t[2]"];
    const F: [&str; 3] = ["external.f_n[0]", "external.f_n[1]", "external.f_n[2]"];
    const DIPOLE: [&str; 3] = [
        "external.dipole_am2[0]",
        "external.dipole_am2[1]",
        "external.dipole_am2[2]",
    ];
    match f {
        Field::Time => "t_s",
        Field::Quaternion(k) => Q.get(k).copied().unwrap_or("q"),
        Field::QuaternionNorm => "q",
        Field::Rho(k) => RHO.get(k).copied().unwrap_or("rho_nms"),
        Field::Tau(k) => TAU.get(k).copied().unwrap_or("tau_nm"),
        Field::Rate(k) => W.get(k).copied().unwrap_or("w_rad_s"),
        Field::Position(k) => R.get(k).copied().unwrap_or("r_m"),
        Field::MagneticField(k) => B.get(k).copied().unwrap_or("b_t"),
        Field::Force(k) => F.get(k).copied().unwrap_or("f_n"),
        Field::Dipole(k) => DIPOLE.get(k).copied().unwrap_or("dipole_am2"),
    }
}
