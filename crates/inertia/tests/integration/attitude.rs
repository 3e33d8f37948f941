//! Quaternion conventions (paper §II.C, docs/conventions.md §3): property tests and known rotations.

use approx::assert_relative_eq;
use inertia::attitude::{incremental_rotation, skew, Quaternion};
use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

fn vec3(max: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-max..max, -max..max, -max..max).prop_map(|(a, b, c)| Vector3::new(a, b, c))
}

/// Rotation vectors with angle below π (where log is the inverse of exp).
fn rotvec() -> impl Strategy<Value = Vector3<f64>> {
    vec3(1.8).prop_filter("angle < π", |v| v.norm() < PI - 1e-3)
}

fn unit_q() -> impl Strategy<Value = Quaternion> {
    (vec3(1.0), -1.0..1.0f64)
        .prop_filter("non-zero", |(v, s)| v.norm_squared() + s * s > 1e-3)
        .prop_map(|(v, s)| Quaternion::new(v, s).normalize().unwrap())
}

/// Shuster's attitude matrix (inertial → body) of a JPL quaternion [q1 q2 q3 q4]:
/// A = (q4² − |q|²) I + 2 q qᵀ − 2 q4 [q×].
fn shuster_attitude_matrix(c: [f64; 4]) -> Matrix3<f64> {
    let q = Vector3::new(c[0], c[1], c[2]);
    let q4 = c[3];
    Matrix3::identity() * (q4 * q4 - q.dot(&q)) + 2.0 * q * q.transpose() - 2.0 * q4 * skew(&q)
}

/// Shuster's product: q ⊗ p = [q4 p + p4 q − q × p; q4 p4 − q·p].
fn shuster_product(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let (q, q4) = (Vector3::new(a[0], a[1], a[2]), a[3]);
    let (p, p4) = (Vector3::new(b[0], b[1], b[2]), b[3]);
    let v = q4 * p + p4 * q - q.cross(&p);
    [v.x, v.y, v.z, q4 * p4 - q.dot(&p)]
}

proptest! {
    #[test]
    fn exp_log_round_trip(theta in rotvec()) {
        let back = Quaternion::exp(&theta).log();
        prop_assert!((back - theta).norm() < 1e-12 * (1.0 + theta.norm()));
    }

    #[test]
    fn log_exp_round_trip_up_to_sign(q in unit_q()) {
        let back = Quaternion::exp(&q.log());
        let p = q.positive_scalar();
        prop_assert!((back.v - p.v).norm() < 1e-12 && (back.s - p.s).abs() < 1e-12);
    }

    #[test]
    fn matrix_round_trip(q in unit_q()) {
        let back = Quaternion::from_matrix(&q.to_matrix());
        let p = q.positive_scalar();
        prop_assert!((back.v - p.v).norm() < 1e-12 && (back.s - p.s).abs() < 1e-12);
    }

    #[test]
    fn matrix_is_a_rotation_matching_rotate(q in unit_q(), x in vec3(10.0)) {
        let c = q.to_matrix();
        prop_assert!((c.transpose() * c - Matrix3::identity()).norm() < 1e-13);
        prop_assert!((c.determinant() - 1.0).abs() < 1e-13);
        prop_assert!((c * x - q.rotate(&x)).norm() < 1e-12 * (1.0 + x.norm()));
        // Sandwich product of eq. 22.
        let sandwich = q.mul(&Quaternion::pure(&x)).mul(&q.conjugate());
        prop_assert!((sandwich.v - q.rotate(&x)).norm() < 1e-12 * (1.0 + x.norm()));
    }

    #[test]
    fn rotation_preserves_norm_and_angles(q in unit_q(), a in vec3(5.0), b in vec3(5.0)) {
        let (ra, rb) = (q.rotate(&a), q.rotate(&b));
        prop_assert!((ra.norm() - a.norm()).abs() < 1e-12);
        prop_assert!((ra.dot(&rb) - a.dot(&b)).abs() < 1e-11);
    }

    #[test]
    fn product_preserves_norm(a in unit_q(), b in unit_q()) {
        prop_assert!((a.mul(&b).norm() - 1.0).abs() < 1e-14);
    }

    /// A rotation q1 followed by q2 is q3 = q2 q1.
    #[test]
    fn composition_order(q1 in unit_q(), q2 in unit_q(), x in vec3(3.0)) {
        let q3 = q2.mul(&q1);
        prop_assert!((q3.rotate(&x) - q2.rotate(&q1.rotate(&x))).norm() < 1e-12);
        prop_assert!((q3.to_matrix() - q2.to_matrix() * q1.to_matrix()).norm() < 1e-13);
    }

    /// φ does not depend on the signs of q_k and q_{k+1}, and is vec of the
    /// positive-scalar increment.
    #[test]
    fn incremental_rotation_sign_invariant(q in unit_q(), d in vec3(0.5)) {
        let q1 = q.mul(&Quaternion::exp(&d));
        let phi = incremental_rotation(&q, &q1);
        let neg = |p: &Quaternion| Quaternion::new(-p.v, -p.s);
        prop_assert!((incremental_rotation(&neg(&q), &q1) - phi).norm() < 1e-14);
        prop_assert!((incremental_rotation(&q, &neg(&q1)) - phi).norm() < 1e-14);
        // φ = sin(|d|/2) d/|d|.
        let expect = d * if d.norm() > 0.0 { (0.5 * d.norm()).sin() / d.norm() } else { 0.5 };
        prop_assert!((phi - expect).norm() < 1e-13);
    }

    /// JPL/Shuster: A(q) maps inertial to body; our converted quaternion maps body to
    /// inertial with C = Aᵀ, and Shuster's product order is the reverse of Hamilton's.
    #[test]
    fn jpl_conversion_matches_shuster(a in unit_q(), b in unit_q()) {
        let (ja, jb) = (a.to_xyzw(), b.to_xyzw());
        let ha = Quaternion::from_jpl_xyzw(ja);
        prop_assert!((ha.to_matrix() - shuster_attitude_matrix(ja).transpose()).norm() < 1e-13);
        // Shuster's q ⊗ p equals Hamilton p q for the converted quaternions.
        let prod = Quaternion::from_jpl_xyzw(shuster_product(ja, jb));
        let ham = Quaternion::from_jpl_xyzw(jb).mul(&ha);
        prop_assert!((prod.v - ham.v).norm() < 1e-14 && (prod.s - ham.s).abs() < 1e-14);
    }
}

#[test]
fn ninety_degrees_about_z_takes_x_to_y() {
    let q = Quaternion::exp(&Vector3::new(0.0, 0.0, FRAC_PI_2));
    assert_relative_eq!(q.rotate(&Vector3::x()), Vector3::y(), epsilon = 1e-15);
    assert_relative_eq!(q.rotate(&Vector3::y()), -Vector3::x(), epsilon = 1e-15);
    let c = q.to_matrix();
    assert_relative_eq!(c * Vector3::x(), Vector3::y(), epsilon = 1e-15);
    let h = FRAC_PI_2 / 2.0;
    assert_relative_eq!(q.s, h.cos(), epsilon = 1e-15);
    assert_relative_eq!(q.v, Vector3::new(0.0, 0.0, h.sin()), epsilon = 1e-15);
}

/// Storage conversions for one attitude (90° about z): a table of the same rotation in
/// every supported input convention.
#[test]
fn conversion_table() {
    let r = std::f64::consts::FRAC_1_SQRT_2;
    let ours = Quaternion::from_xyzw([0.0, 0.0, r, r]);
    let table = [
        (
            "scalar first [w,x,y,z]",
            Quaternion::from_wxyz([r, 0.0, 0.0, r]),
        ),
        (
            "JPL [q1,q2,q3,q4]",
            Quaternion::from_jpl_xyzw([0.0, 0.0, r, r]),
        ),
        (
            "Hamilton inertial->body [x,y,z,w]",
            Quaternion::from_hamilton_inertial_to_body_xyzw([0.0, 0.0, -r, r]),
        ),
    ];
    for (name, q) in table {
        assert_relative_eq!(q.to_matrix(), ours.to_matrix(), epsilon = 1e-15);
        assert!(q == ours, "{name}: {q:?}");
    }
    assert_eq!(ours.to_wxyz(), [r, 0.0, 0.0, r]);
    assert_eq!(ours.to_xyzw(), [0.0, 0.0, r, r]);
}

/// Body rate: ω̂ = 2 q† q̇ (eq. 24) with a finite difference of q(t) = q0 exp(ω t).
#[test]
fn body_rate_definition() {
    let w = Vector3::new(0.3, -0.2, 0.5);
    let q0 = Quaternion::exp(&Vector3::new(0.1, 0.2, 0.3));
    let dt = 1e-6;
    let qp = q0.mul(&Quaternion::exp(&(w * dt)));
    let qm = q0.mul(&Quaternion::exp(&(-w * dt)));
    let qdot = Quaternion::new((qp.v - qm.v) / (2.0 * dt), (qp.s - qm.s) / (2.0 * dt));
    let what = q0.conjugate().mul(&qdot);
    assert_relative_eq!(2.0 * what.v, w, epsilon = 1e-9);
    assert!(what.s.abs() < 1e-9);
}
