use super::*;

fn raw(t_s: f64) -> RawSample {
    RawSample {
        t_s,
        q: [0.0, 0.0, 0.0, 1.0],
        rho_nms: [0.1, 0.0, 0.0],
        tau_nm: None,
        w_rad_s: Some([0.0, 0.01, 0.0]),
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
