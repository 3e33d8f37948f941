//! How well the data determine each direction of `j`, and what motion would help.
//!
//! From the SVD `R = U Σ Vᵀ` of the least-squares factor:
//!
//! * the singular values say how strongly each direction of `j` is excited;
//! * `Cov(ĵ) ≈ s² (RᵀR)⁻¹ = s² V Σ⁻² Vᵀ` with `s² = ρ²/(rows − 6)` gives a standard
//!   deviation per element (sensor noise only; see the README on errors-in-variables);
//! * the right singular vector of the smallest singular value is the combination of
//!   elements the data separate worst, and its dominant entries name them.
//!
//! Advice follows from the structure of the rows (eq. 47: `J φ = G(φ) j`): a moment
//! `J_ii` is seen through rotation about body axis i, and a product `J_ij` through
//! simultaneous rotation about axes i and j, i.e. about an axis between them. Without
//! any rotor momentum change or known torque (`y ≡ 0`) only the ratios of the elements
//! are seen, whatever the motion.

use super::observability::ObservabilitySettings;
use super::qr::RecursiveQr;
use crate::tensor::{InertiaVector, COMPONENT_INDEX, COMPONENT_NAMES};
use nalgebra::SVD;

/// The excitation report.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Excitation {
    /// Singular values of `R`, descending.
    pub singular_values: [f64; 6],
    /// The least-excited combination of elements (unit vector in `j`-space; with `y ≡ 0`
    /// this is the scale of J).
    pub weakest_direction: InertiaVector,
    /// Least-squares standard deviation of each element, kg m² (`None` without enough
    /// rows or with a singular `R`).
    #[cfg_attr(feature = "serde", serde(rename = "element_sigma_kg_m2"))]
    pub element_sigma: Option<[f64; 6]>,
    /// Elements dominating the weakest direction, when it is poorly excited.
    pub weak_elements: Vec<&'static str>,
    /// What would help, in words (empty when the excitation is good).
    pub advice: Vec<String>,
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// Diagnose the excitation of a least-squares state. A direction is poorly excited when
/// its singular value is below `σ_1 / condition_threshold`: the same test by which the
/// observability check refuses to call J determined, so the report never says
/// "determined" and "barely separate" at once.
#[must_use]
pub fn diagnose(qr: &RecursiveQr, settings: &ObservabilitySettings) -> Excitation {
    // A decomposition that does not converge (bounded iterations) reports nothing
    // excited: zero singular values, no σ.
    let (singular_values, v_t) = SVD::try_new(
        qr.r,
        false,
        true,
        f64::EPSILON,
        crate::math::MAX_DECOMPOSITION_ITERATIONS,
    )
    .and_then(|s| Some((s.singular_values, s.v_t?)))
    .unwrap_or_else(|| (nalgebra::Vector6::zeros(), nalgebra::Matrix6::identity()));
    let mut order = [0usize, 1, 2, 3, 4, 5];
    order.sort_unstable_by(|&a, &b| singular_values[b].total_cmp(&singular_values[a]));
    let sv: [f64; 6] = order.map(|i| singular_values[i]);
    let weakest = InertiaVector::from_fn(|k, _| v_t[(order[5], k)]);
    // With y ≡ 0 the residual is zero by construction: no variance to report.
    let v = v_t.transpose();
    let element_sigma = super::uncertainty::noise_sigma(qr, &singular_values, &v);
    let mut weak_elements = Vec::new();
    let mut advice = Vec::new();
    if qr.y_energy == 0.0 {
        advice.push(
            "no rotor momentum change and no known torque: the data fix only the ratios of the elements, not the scale of J; command a reaction-wheel momentum change (or apply a known torque), or bound an element a priori".to_string(),
        );
    }
    // Every poorly excited direction (with y ≡ 0, the weakest one is the scale of J
    // itself and is left out: the motion question is about the others).
    let skip_scale = usize::from(qr.y_energy == 0.0);
    let weak: Vec<usize> = (0..6 - skip_scale)
        .filter(|&i| sv[0] > 0.0 && sv[i] * settings.condition_threshold < sv[0])
        .collect();
    if let Some(&first_weak) = weak.first() {
        let mut axes = [false; 3];
        for (k, name) in COMPONENT_NAMES.iter().enumerate() {
            let involved = weak.iter().any(|&i| v_t[(order[i], k)].abs() >= 0.3);
            if involved {
                weak_elements.push(*name);
                let (r, c) = COMPONENT_INDEX[k];
                axes[r] = true;
                axes[c] = true;
            }
        }
        let named: Vec<&str> = (0..3).filter(|&i| axes[i]).map(|i| AXES[i]).collect();
        let products: Vec<&str> = weak_elements
            .iter()
            .copied()
            .filter(|n| n.as_bytes()[1] != n.as_bytes()[2])
            .collect();
        let mut text = format!(
            "the data barely separate {} ({} weak direction(s), the strongest of them {:.1e} of the best): rotate about body axis {}",
            weak_elements.join(", "),
            weak.len(),
            sv[first_weak] / sv[0],
            named.join(" and ")
        );
        if !products.is_empty() {
            text.push_str(&format!(
                ", including slews about an axis between them (products of inertia {} need simultaneous rates about both axes)",
                products.join(", ")
            ));
        }
        text.push_str("; a pure spin about one principal axis excites only that axis");
        advice.push(text);
    }
    Excitation {
        singular_values: sv,
        weakest_direction: weakest,
        element_sigma,
        weak_elements,
        advice,
    }
}
