//! Shared by the tests: driving the C API from Rust.
#![allow(dead_code)]

use inertia::sample::Sample;
use inertia_c::*;

pub fn c_sample(s: &Sample) -> InertiaSample {
    InertiaSample {
        t_s: s.t_s,
        q: [s.q.v.x, s.q.v.y, s.q.v.z, s.q.s],
        rho_nms: s.rho_nms.into(),
        tau_nm: s.tau_nm.into(),
        w_rad_s: s.omega_rad_s.map_or([0.0; 3], Into::into),
        has_w: u8::from(s.omega_rad_s.is_some()),
    }
}

/// A heap estimator with `settings` fed every sample (each push must succeed), freed;
/// its final estimate.
pub fn final_estimate(settings: &InertiaSettings, samples: &[Sample]) -> InertiaEstimate {
    let est = new(settings);
    for x in samples {
        assert_eq!(
            push(est, &c_sample(x)),
            InertiaStatus::Ok,
            "{}",
            last_error()
        );
    }
    let e = get(est);
    free(est);
    e
}

/// Storage for one estimator in caller memory, aligned for it.
#[repr(C, align(64))]
pub struct Storage(pub [u8; 1 << 16]);

/// A heap estimator (panics on failure, with the message).
pub fn new(settings: &InertiaSettings) -> *mut InertiaEstimator {
    let mut est = core::ptr::null_mut();
    // SAFETY: valid pointers.
    let status = unsafe { inertia_estimator_new(settings, &mut est) };
    assert_eq!(status, InertiaStatus::Ok, "{}", last_error());
    est
}

/// An estimator in `storage` (panics on failure, with the message).
pub fn init(storage: &mut Storage, settings: &InertiaSettings) -> *mut InertiaEstimator {
    assert!(inertia_estimator_size() <= storage.0.len());
    assert!(inertia_estimator_align() <= 64);
    let mut est = core::ptr::null_mut();
    // SAFETY: `storage` is large and aligned enough, and outlives the estimator.
    let status = unsafe {
        inertia_estimator_init(
            storage.0.as_mut_ptr().cast(),
            storage.0.len(),
            settings,
            &mut est,
        )
    };
    assert_eq!(status, InertiaStatus::Ok, "{}", last_error());
    est
}

pub fn push(est: *mut InertiaEstimator, s: &InertiaSample) -> InertiaStatus {
    // SAFETY: `est` is live, `s` valid.
    unsafe { inertia_estimator_push(est, s) }
}

pub fn get(est: *const InertiaEstimator) -> InertiaEstimate {
    let mut out = core::mem::MaybeUninit::uninit();
    // SAFETY: `est` is live; `out` is writable.
    let status = unsafe { inertia_estimator_get(est, out.as_mut_ptr()) };
    assert_eq!(status, InertiaStatus::Ok);
    // SAFETY: written on success.
    unsafe { out.assume_init() }
}

pub fn last_error() -> String {
    let mut buf = [0u8; 2048];
    // SAFETY: `buf` is writable for its length.
    let n = unsafe { inertia_last_error_message(buf.as_mut_ptr().cast(), buf.len()) };
    String::from_utf8_lossy(&buf[..n.min(buf.len() - 1)]).into_owned()
}

pub fn free(est: *mut InertiaEstimator) {
    // SAFETY: `est` is live and not used again.
    unsafe { inertia_estimator_free(est) }
}

/// Bitwise equality of two estimates (NaN equal to NaN).
pub fn same(a: &InertiaEstimate, b: &InertiaEstimate) -> bool {
    let bits = |e: &InertiaEstimate| {
        let mut v: Vec<u64> = vec![e.t_s.to_bits(), e.condition.to_bits(), e.rows, e.samples];
        v.extend(
            e.j.iter()
                .chain(&e.sigma)
                .chain(e.inertia.iter().flatten())
                .chain(&e.prior_data_share)
                .chain([&e.prior_chi2])
                .map(|x| x.to_bits()),
        );
        v
    };
    a.status == b.status
        && a.reason == b.reason
        && a.has_answer == b.has_answer
        && a.has_sigma == b.has_sigma
        && bits(a) == bits(b)
}

/// The C id of an estimator of the library's registry (`INERTIA_ESTIMATOR_*`: its index
/// from 1).
pub fn estimator_id(name: &str) -> u32 {
    let k = inertia::pipeline::registry::ESTIMATORS
        .iter()
        .position(|e| e.name == name)
        .unwrap_or_else(|| panic!("no estimator {name}"));
    u32::try_from(k + 1).unwrap()
}
