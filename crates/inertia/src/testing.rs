//! Helpers shared by the unit tests.

/// A reproducible stream of uniform numbers in `[-0.5, 0.5)` (xorshift64), for random
/// test problems without a dependency on `rand` in `no_std` builds.
pub(crate) fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// Sample standard deviation (the simulator's noise-statistics tests).
#[cfg(feature = "sim")]
pub(crate) fn sample_std(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// Default momentum row settings with the given rotation source and longest chain.
pub(crate) fn rows(
    rotation: crate::estimator::momentum_rows::RotationSource,
    max_chain_s: Option<f64>,
) -> crate::estimator::momentum_rows::MomentumRowSettings {
    crate::estimator::momentum_rows::MomentumRowSettings {
        rotation,
        max_chain_s,
        ..Default::default()
    }
}
