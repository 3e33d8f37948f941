//! The prior rows against nalgebra's normal equations (moved from
//! tests/integration/prior.rs: it drives `augment` and `noise_sigma`, which are
//! crate-internal).

use crate::constraints::ConstraintSet;
use crate::sim::scenario::Common;

/// The prior rows against the normal equations, formed and solved with nalgebra:
/// `(RᵀR/s² + Σ_p⁻¹) j = Rᵀz/s² + Σ_p⁻¹ μ` and `P = (RᵀR/s² + Σ_p⁻¹)⁻¹`.
#[test]
fn prior_rows_match_the_normal_equations() {
    use crate::estimator::qr::RecursiveQr;
    use crate::estimator::uncertainty::noise_sigma;
    use nalgebra::{Matrix6, Vector6};
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    for rank in [3usize, 6] {
        let mut qr = RecursiveQr::new();
        for _ in 0..60 {
            let mut h = Vector6::from_fn(|_, _| rng.random_range(-1.0..1.0));
            for k in rank..6 {
                h[k] = 0.0;
            }
            qr.add_row(&h, rng.random_range(-1.0..1.0));
        }
        let truth = Common::paper().inertia_kg_m2;
        let set = ConstraintSet::physical().with_relative_prior(&truth, 0.05);
        let c = set.validate().unwrap();
        let (aug, fit) = crate::estimator::prior::augment(&qr, &c);
        let p = set.prior.unwrap();
        let s2 = qr.rss / qr.residual_dof();
        let w = Matrix6::from_diagonal(&Vector6::from_fn(|k, _| 1.0 / p.sigma_kg_m2[k].powi(2)));
        let mu = Vector6::from_fn(|k, _| p.mean_kg_m2[k]);
        let a = qr.r.transpose() * qr.r / s2 + w;
        let b = qr.r.transpose() * qr.z / s2 + w * mu;
        let cov = a.try_inverse().unwrap();
        let j_ref = cov * b;
        let j = crate::solver::unconstrained_minimiser(&aug.r, &aug.z).unwrap();
        assert!(
            (j - j_ref).norm() <= 1e-10 * j_ref.norm(),
            "rank {rank}: {j} vs {j_ref}"
        );
        let svd = aug.r.svd(false, true);
        let sigma = noise_sigma(&aug, &svd.singular_values, &svd.v_t.unwrap().transpose()).unwrap();
        for k in 0..6 {
            let reference = cov[(k, k)].sqrt();
            assert!(
                (sigma[k] - reference).abs() <= 1e-9 * reference,
                "rank {rank} element {k}"
            );
            let share = fit.unwrap().data_share[k].unwrap();
            let ref_share = 1.0 - cov[(k, k)] / p.sigma_kg_m2[k].powi(2);
            assert!(
                (share - ref_share).abs() < 1e-9,
                "rank {rank} element {k}: {share} vs {ref_share}"
            );
        }
    }
}
