use super::*;

fn raw(t_s: f64) -> RawSample {
    RawSample {
        t_s,
        q: [0.0, 0.0, 0.0, 1.0],
        rho_nms: [0.1, 0.0, 0.0],
        tau_nm: None,
        w_rad_s: Some([0.0, 0.01, 0.0]),
        external: Default::default(),
    }
}

#[test]
fn a_refused_sample_leaves_the_gate_as_it_was() {
    let mut g = Gate::default();
    g.check(&raw(0.0)).unwrap();
    let before = (g.order, g.prev_q, g.period_s, g.stats.rows);
    let e = g.check(&raw(0.0)).unwrap_err();
    assert_eq!(
        e,
        SampleError::TimeNotIncreasing {
            t_s: 0.0,
            previous_s: 0.0
        }
    );
    assert_eq!(before, (g.order, g.prev_q, g.period_s, g.stats.rows));
    assert_eq!(g.stats.rejected, 1);
    g.check(&raw(0.1)).unwrap();
}

#[test]
fn each_field_is_named() {
    let mut g = Gate::default();
    let mut r = raw(0.0);
    r.rho_nms[2] = f64::NAN;
    assert_eq!(g.check(&r).unwrap_err().field(), Field::Rho(2));
    let mut r = raw(0.0);
    r.w_rad_s = Some([0.0, f64::INFINITY, 0.0]);
    assert_eq!(g.check(&r).unwrap_err().field(), Field::Rate(1));
    let mut r = raw(0.0);
    r.q = [0.0, 0.0, 0.5, 1.0];
    let e = g.check(&r).unwrap_err();
    assert_eq!(e.error_kind(), ErrorKind::NonUnitQuaternion);
    assert_eq!(e.field(), Field::QuaternionNorm);
    let mut r = raw(0.0);
    r.rho_nms[0] = 1e300;
    assert_eq!(g.check(&r).unwrap_err().error_kind(), ErrorKind::OutOfRange);
}

#[test]
fn gyro_rates_are_all_or_none_and_the_period_uniform_in_strict_mode() {
    let mut g = Gate::new(GateOptions {
        period_tolerance: Some(0.01),
        ..GateOptions::default()
    });
    g.check(&raw(0.0)).unwrap();
    let mut r = raw(0.1);
    r.w_rad_s = None;
    assert_eq!(
        g.check(&r).unwrap_err(),
        SampleError::GyroChanged { given_here: false }
    );
    g.check(&raw(0.1)).unwrap();
    assert_eq!(
        g.check(&raw(0.3)).unwrap_err().error_kind(),
        ErrorKind::NonUniformPeriod
    );
    g.check(&raw(0.2)).unwrap();
    assert_eq!(g.stats().rows, 3);
}

#[test]
fn conventions_renormalisation_and_negated_rho() {
    let mut g = Gate::new(GateOptions {
        quaternion: QuaternionFormat::HamiltonScalarFirst,
        negate_rho: true,
        ..GateOptions::default()
    });
    let mut r = raw(0.0);
    r.q = [1.0005, 0.0, 0.0, 0.0];
    let s = g.check(&r).unwrap();
    assert_eq!((s.q.s, s.q.v.norm()), (1.0, 0.0));
    assert_eq!(s.rho_nms.x, -0.1);
    assert_eq!(g.stats().renormalised, 1);
}

#[test]
fn outside_measurements_are_checked_all_or_none_and_a_dipole_adds_its_torque() {
    let mut g = Gate::default();
    let mut r = raw(0.0);
    r.external.dipole_am2 = Some([1.0, 0.0, 0.0]);
    assert_eq!(g.check(&r).unwrap_err(), SampleError::DipoleWithoutField);
    r.external.field_t = Some([0.0, 2e-5, 0.0]);
    r.tau_nm = Some([0.0, 0.0, 1e-6]);
    let s = g.check(&r).unwrap();
    // m × B = x̂ × 2e-5 ŷ = 2e-5 ẑ, added to the known torque.
    assert!((s.tau_nm - Vector3::new(0.0, 0.0, 2.1e-5)).norm() < 1e-18);
    assert_eq!(s.external.field_t, Some(Vector3::new(0.0, 2e-5, 0.0)));
    assert_eq!(s.external.position_m, None);
    let mut next = raw(0.1);
    next.external.field_t = Some([0.0, 2e-5, 0.0]);
    let e = g.check(&next).unwrap_err();
    assert_eq!(
        e,
        SampleError::ExternalChanged {
            what: ExternalKind::Dipole,
            given_here: false
        }
    );
    assert_eq!(e.field(), Field::Dipole(0));
    assert_eq!(e.error_kind(), ErrorKind::Columns);
    let mut far = raw(0.1);
    far.external = r.external;
    far.external.field_t = Some([0.0, 1.0, 0.0]);
    assert_eq!(g.check(&far).unwrap_err().field(), Field::MagneticField(1));
    let mut no_attitude = Gate::new(GateOptions {
        attitude_from_gyro: true,
        ..GateOptions::default()
    });
    let mut p = raw(0.0);
    p.external.position_m = Some([7e6, 0.0, 0.0]);
    assert_eq!(
        no_attitude.check(&p).unwrap_err(),
        SampleError::PositionWithoutAttitude
    );
}

#[test]
fn a_position_at_the_centre_is_refused() {
    let mut g = Gate::default();
    let mut r = raw(0.0);
    r.external.position_m = Some([0.0; 3]);
    let e = g.check(&r).unwrap_err();
    assert_eq!(e, SampleError::PositionAtCentre);
    assert_eq!(
        (e.field(), e.error_kind()),
        (Field::Position(0), ErrorKind::OutOfRange)
    );
}
