//! The bad-input table (`tests/data/bad_inputs.json`) through the C API (heap estimator,
//! the default settings): `inertia_last_error_kind` and `_sample` are the table's (as the
//! command line's and Python's). C has no end of input: where the others refuse too few
//! samples, the estimate's status stays NONE.

#[path = "../../../../tests/data/bad_inputs.rs"]
mod table;

use crate::common::*;
use inertia_c::*;

#[test]
fn the_c_api_refuses_the_tables_inputs_with_its_kinds() {
    for case in table::cases() {
        let settings = InertiaSettings {
            memory_s: case.memory_s.unwrap_or(0.0),
            ..inertia_settings_default()
        };
        let est = new(&settings);
        let mut refused = None;
        for (i, r) in case.rows.iter().enumerate() {
            let s = InertiaSample {
                t_s: r.t,
                q: r.q,
                rho_nms: r.rho,
                tau_nm: r.tau,
                w_rad_s: r.w.unwrap_or([0.0; 3]),
                has_w: u8::from(r.w.is_some()),
            };
            if push(est, &s) != InertiaStatus::Ok {
                refused = Some(i);
                break;
            }
        }
        match case.c.as_deref() {
            Some("no_estimate") => {
                assert_eq!(refused, None, "{}: {}", case.name, last_error());
                assert_eq!(
                    get(est).status,
                    InertiaEstimateStatus::None,
                    "{}",
                    case.name
                );
            }
            None => {
                assert_eq!(refused, case.sample, "{}: {}", case.name, last_error());
                let kind = inertia_last_error_kind();
                // SAFETY: a static NUL-terminated string.
                let name =
                    unsafe { core::ffi::CStr::from_ptr(inertia_error_kind_name(kind as i32)) };
                assert_eq!(
                    name.to_str().unwrap(),
                    case.kind,
                    "{}: {}",
                    case.name,
                    last_error()
                );
                assert_eq!(
                    inertia_last_error_sample(),
                    case.sample.map_or(-1, |s| s as i64),
                    "{}",
                    case.name
                );
            }
            Some(other) => panic!("{}: unknown C note {other:?}", case.name),
        }
        free(est);
    }
}
