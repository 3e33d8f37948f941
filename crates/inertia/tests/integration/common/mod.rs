//! Seeded random constrained least-squares problems for solver tests.
#![allow(dead_code)]

pub mod momentum_balance;
pub mod wheels;

use inertia::attitude::Quaternion;
use inertia::constraints::ConstraintSet;
use inertia::tensor::{j_from_matrix, InertiaVector};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// One problem: `minimise ‖R j − z‖²` over a constraint set.
#[derive(Debug, Clone)]
pub struct RandomProblem {
    pub r: Matrix6<f64>,
    pub z: Vector6<f64>,
    pub set: ConstraintSet,
    pub label: &'static str,
}

fn gaussian6(rng: &mut ChaCha8Rng) -> Matrix6<f64> {
    Matrix6::from_fn(|_, _| {
        // Box–Muller.
        let u: f64 = rng.random::<f64>().max(1e-300);
        let v: f64 = rng.random();
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    })
}

/// Upper-triangular R with condition number `cond`.
pub fn random_r(rng: &mut ChaCha8Rng, cond: f64) -> Matrix6<f64> {
    let u = gaussian6(rng).qr().q();
    let v = gaussian6(rng).qr().q();
    let s = Vector6::from_fn(|i, _| cond.powf(-(i as f64) / 5.0));
    let a = u * Matrix6::from_diagonal(&s) * v.transpose();
    let qr = a.qr();
    let mut r = qr.r();
    for i in 0..6 {
        if r[(i, i)] < 0.0 {
            for k in 0..6 {
                r[(i, k)] = -r[(i, k)];
            }
        }
    }
    r * rng.random_range(0.01..100.0)
}

/// A random symmetric J: principal moments (possibly unphysical) in a random frame.
pub fn random_j(rng: &mut ChaCha8Rng, physical: bool) -> InertiaVector {
    let mut m = Vector3::from_fn(|_, _| rng.random_range(0.2..3.0));
    if !physical {
        // Break the triangle inequality, or definiteness.
        match rng.random_range(0..3) {
            0 => m[2] = m[0] + m[1] + rng.random_range(0.01..1.0),
            1 => m[0] = -rng.random_range(0.0..0.5),
            _ => m[1] = rng.random_range(-0.1..0.05),
        }
    }
    let c = Quaternion::exp(&Vector3::from_fn(|_, _| rng.random_range(-2.0..2.0))).to_matrix();
    j_from_matrix(&(c * Matrix3::from_diagonal(&m) * c.transpose()))
}

fn random_set(rng: &mut ChaCha8Rng, anchor: &InertiaVector) -> ConstraintSet {
    let mut set = match rng.random_range(0..3) {
        0 => ConstraintSet::physical(),
        1 => ConstraintSet::paper(),
        _ => ConstraintSet::positive_definite(),
    };
    // Bounds around a physical anchor, some of them tight.
    for k in 0..6 {
        if rng.random_bool(0.25) {
            let w = rng.random_range(0.001..0.5);
            let lo = rng
                .random_bool(0.8)
                .then(|| anchor[k] - w * rng.random_range(0.0..1.0));
            let hi = rng
                .random_bool(0.8)
                .then(|| anchor[k] + w * rng.random_range(0.0..1.0));
            set = set.with_bounds(inertia::tensor::Component::ALL[k], lo, hi);
        }
    }
    set
}

/// `n` problems from `seed`: conditions from 1 to 1e8, constraints inactive, active and
/// absent, the counterexample of docs/conventions.md §4, and a J exactly on the boundary.
pub fn problems(seed: u64, n: usize) -> Vec<RandomProblem> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(n + 2);
    out.push(RandomProblem {
        r: Matrix6::identity(),
        z: j_from_matrix(&Matrix3::new(
            1.75, 0.0, 0.75, 0.0, 1.0, 0.0, 0.75, 0.0, 1.75,
        )),
        set: ConstraintSet::physical(),
        label: "errata counterexample",
    });
    out.push(RandomProblem {
        // A flat plate: λ3 = λ1 + λ2 exactly, on the boundary of Σ ⪰ 0.
        r: random_r(&mut rng, 10.0),
        z: Vector6::zeros(),
        set: ConstraintSet::physical(),
        label: "flat plate",
    });
    let plate = j_from_matrix(&Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0)));
    out[1].z = out[1].r * plate;
    while out.len() < n {
        let cond = 10f64.powf(rng.random_range(0.0..8.0));
        let r = random_r(&mut rng, cond);
        let anchor = random_j(&mut rng, true);
        let target = if rng.random_bool(0.5) {
            random_j(&mut rng, false)
        } else {
            anchor + Vector6::from_fn(|_, _| rng.random_range(-0.3..0.3))
        };
        let noise =
            Vector6::from_fn(|_, _| rng.random_range(-1.0..1.0)) * (r * target).norm() * 1e-3;
        let set = random_set(&mut rng, &anchor);
        if set.validate().is_err() {
            continue;
        }
        out.push(RandomProblem {
            r,
            z: r * target + noise,
            set,
            label: "random",
        });
    }
    out
}
