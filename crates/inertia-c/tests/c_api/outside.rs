//! Outside measurements through the C API (`inertia_estimator_push_external`,
//! `inertia_estimator_outside`): the same answers as the library's pipeline given the
//! same samples, the estimated centre of mass within 3σ of the simulator's, and a bad
//! measurement refused with the field's name.

use crate::common::*;
use inertia::pipeline::{InertialTorque, Pipeline, PipelineSettings};
use inertia::sample::Sample;
use inertia::sim::scenario::{Common, Scenario};
use inertia::sim::{Orbit, Thrusters};
use inertia_c::*;
use nalgebra::Vector3;

fn external(s: &Sample) -> InertiaExternal {
    let e = &s.external;
    let v = |x: Option<Vector3<f64>>| x.map_or([0.0; 3], Into::into);
    InertiaExternal {
        r_m: v(e.position_m),
        b_t: v(e.field_t),
        f_n: v(e.force_n),
        dipole_am2: [0.0; 3],
        has_r: u8::from(e.position_m.is_some()),
        has_b: u8::from(e.field_t.is_some()),
        has_f: u8::from(e.force_n.is_some()),
        has_dipole: 0,
    }
}

fn outside(est: *const InertiaEstimator) -> InertiaOutside {
    let mut out = InertiaOutside::default();
    // SAFETY: `est` is live; `out` is writable.
    let status = unsafe { inertia_estimator_outside(est, &mut out) };
    assert_eq!(status, InertiaStatus::Ok);
    out
}

/// Gravity gradient and thrusters with the centre of mass 2 cm off: the C estimates equal
/// the pipeline's, and the centre of mass is within 3σ and 1 mm of the truth.
#[test]
fn outside_measurements_give_the_pipelines_answer_and_the_centre_of_mass() {
    let centre = Vector3::new(0.012, -0.01, 0.013);
    let mut common = Common::paper();
    common.realism.environment.orbit = Some(Orbit::circular(500e3));
    common.realism.environment.thrusters = Some(Thrusters {
        centre_of_mass_m: centre,
        ..Thrusters::cube_pairs(0.02, 0.3)
    });
    let out = Scenario::slew().simulate(&common).expect("sim");
    let settings = inertia_settings_default();
    let est = new(&settings);
    for s in &out.samples {
        // SAFETY: `est` is live; the pointers are valid.
        let status = unsafe { inertia_estimator_push_external(est, &c_sample(s), &external(s)) };
        assert_eq!(status, InertiaStatus::Ok, "{}", last_error());
    }
    let c = get(est);
    let o = outside(est);
    free(est);
    // The C default leaves the inertial torque off (the library's default is `short`).
    let mut p = Pipeline::new(&PipelineSettings {
        inertial_torque: InertialTorque::Off,
        ..PipelineSettings::default()
    })
    .expect("pipeline");
    // The pipeline takes each sample as C's gate passes it (renormalised).
    let mut gate = inertia::telemetry::gate::Gate::default();
    for s in &out.samples {
        let c = c_sample(s);
        let x = external(s);
        let raw = inertia::telemetry::gate::RawSample {
            t_s: c.t_s,
            q: c.q,
            rho_nms: c.rho_nms,
            tau_nm: Some(c.tau_nm),
            w_rad_s: Some(c.w_rad_s).filter(|_| c.has_w != 0),
            external: inertia::telemetry::gate::RawExternal {
                position_m: Some(x.r_m),
                field_t: None,
                force_n: Some(x.f_n),
                dipole_am2: None,
            },
        };
        p.push(&gate.check(&raw).expect("gate")).expect("push");
    }
    let j = p.last().and_then(|e| e.j()).expect("J");
    for k in 0..6 {
        assert_eq!(c.j[k], j[k], "element {k}");
    }
    assert_eq!(o.gravity_gradient, 1);
    assert_eq!(o.has_dipole, 0);
    assert_eq!(o.has_centre_of_mass, 1);
    for i in 0..3 {
        let d = (o.centre_of_mass_m[i] - centre[i]).abs();
        assert!(d < 1e-3 && d <= 3.0 * o.centre_of_mass_sigma_m[i], "{o:?}");
    }
}

/// A commanded dipole without the field is refused with the field's name, and the
/// estimator is as before (the next good sample is taken).
#[test]
fn a_dipole_without_the_field_is_refused_by_name() {
    let out = Scenario::slew().simulate(&Common::paper()).expect("sim");
    let est = new(&inertia_settings_default());
    let s = c_sample(&out.samples[0]);
    let bad = InertiaExternal {
        dipole_am2: [0.1, 0.0, 0.0],
        has_dipole: 1,
        ..InertiaExternal::default()
    };
    // SAFETY: `est` is live; the pointers are valid.
    let status = unsafe { inertia_estimator_push_external(est, &s, &bad) };
    assert_eq!(status, InertiaStatus::Data);
    let m = last_error();
    assert!(
        m.contains("external.dipole_am2[0]") && m.contains("magnetic field"),
        "{m}"
    );
    // SAFETY: as above; NULL `external` is a plain push.
    let status = unsafe { inertia_estimator_push_external(est, &s, core::ptr::null()) };
    assert_eq!(status, InertiaStatus::Ok, "{}", last_error());
    free(est);
}
