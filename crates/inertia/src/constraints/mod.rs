//! The feasible set of the estimator: paper eqs. 9, 55, 57, docs/conventions.md §4, and a-priori bounds.
//!
//! ```text
//! J(j) − ε I ⪰ 0                                  (eq. 57, first LMI)
//! Σ(j) = ½ tr(J) I − J ⪰ 0                        (Consistency::Physical, the default)
//!   or J11 + J22 ≥ J33, J11 + J33 ≥ J22, J22 + J33 ≥ J11   (Consistency::PaperTriangle, eq. 9)
//! l_i ≤ j_i ≤ u_i                                  (a-priori bounds, any element)
//! ```
//!
//! `Σ ⪰ 0` says the body's second-moment matrix is positive semidefinite. It is the exact
//! condition for a J to be realisable by a mass distribution, and it implies the triangle
//! inequalities on the principal moments (eq. 9 holds in *every* frame) and J ⪰ 0. The
//! paper's eq. 9 constrains only the diagonal in body axes, which is necessary, not
//! sufficient: docs/conventions.md §4 gives a positive definite J that passes it and is not physical.
//!
//! A [`ConstraintSet`] is built by the user and turned into [`Constraints`] by
//! [`ConstraintSet::validate`], before any data is read. Validation rejects non-finite or
//! crossed bounds, and finds a strictly interior point (a phase-I problem: maximise the
//! smallest constraint margin). If none exists, the bounds contradict the physical
//! constraints and validation fails with the best margin achievable. The interior point
//! also starts every interior-point solve.

pub(crate) mod description;
mod validated;

use validated::basis;
pub use validated::Constraints;

use crate::tensor::{Component, InertiaVector, COMPONENT_NAMES};
use description::{Lin, Lmi, MAX_LIN};
use nalgebra::Matrix3;

/// Default ε of `J ⪰ εI`, kg m². Above the solvers' tolerances after scaling.
pub(crate) const DEFAULT_EPSILON_KG_M2: f64 = 1e-6;

/// Which physical-consistency condition to impose besides `J ⪰ εI`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Consistency {
    /// `Σ = ½ tr(J) I − J ⪰ 0` (docs/conventions.md §4). The default.
    #[default]
    Physical,
    /// The paper's diagonal triangle inequalities (eq. 9), to reproduce the paper exactly.
    PaperTriangle,
    /// Only `J ⪰ εI`.
    PositiveDefiniteOnly,
}

/// Relative tolerance within which an answer counts as sitting on a bound
/// ([`ConstraintSet::active_bounds`]): `1e-9 · max(|b|, 1e-3 kg m²)`.
pub(crate) const ACTIVE_TOLERANCE: f64 = 1e-9;

fn active_tolerance(v: f64) -> f64 {
    ACTIVE_TOLERANCE * crate::math::abs(v).max(1e-3)
}

/// Which side of an element's interval.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum BoundSide {
    /// `j[k] ≥ lower`.
    Lower,
    /// `j[k] ≤ upper`.
    Upper,
    /// `j[k] = value` (lower and upper bounds equal).
    Fixed,
}

/// An element bound the answer sits on (`ConstraintSet::active_bounds`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ActiveBound {
    /// The element.
    pub component: Component,
    /// Which bound.
    pub side: BoundSide,
    /// The bound, kg m² (products are tensor entries, `J12 = −Σ m x y`).
    pub value_kg_m2: f64,
}

impl core::fmt::Display for ActiveBound {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let (c, v) = (self.component, crate::text::Num(self.value_kg_m2));
        match self.side {
            BoundSide::Lower => write!(f, "{c} at its lower bound {v}"),
            BoundSide::Upper => write!(f, "{c} at its upper bound {v}"),
            BoundSide::Fixed => write!(f, "{c} fixed at {v}"),
        }
    }
}

/// A user's constraint set. Build, then [`validate`](ConstraintSet::validate).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstraintSet {
    /// ε of `J ⪰ εI`, kg m² (default `DEFAULT_EPSILON_KG_M2`).
    pub epsilon_kg_m2: f64,
    /// Consistency condition (default [`Consistency::Physical`]).
    pub consistency: Consistency,
    /// Lower bounds per component of `j` (order of eq. 48), kg m².
    pub lower_kg_m2: [Option<f64>; 6],
    /// Upper bounds per component of `j`, kg m².
    pub upper_kg_m2: [Option<f64>; 6],
    /// A Gaussian prior on `j` (e.g. from CAD), weighed against the data
    /// (`crate::estimator::prior`). Default `None`.
    pub prior: Option<GaussianPrior>,
}

/// A Gaussian prior on `j`: `j_k ~ N(mean_k, sigma_k²)`, independent elements. Products
/// are tensor entries (`J12 = −Σ m x y`): a CAD tool's products of inertia (`+Σ m x y`)
/// are negated on input ([`ProductConvention`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct GaussianPrior {
    /// Prior mean of `j` (order of eq. 48), kg m².
    pub mean_kg_m2: [f64; 6],
    /// Prior standard deviation of each element, kg m² (> 0; an element known exactly
    /// is an equality bound instead).
    pub sigma_kg_m2: [f64; 6],
}

/// How products of inertia are written in a file or by a tool.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum ProductConvention {
    /// Tensor entries, `J12 = −Σ m x y` (this crate's convention, and the default).
    #[default]
    Tensor,
    /// Products of inertia as CAD tools report them, `I_xy = +Σ m x y = −J12`.
    Cad,
}

impl ProductConvention {
    /// The tensor entry (`J_ik`) of a product written in this convention.
    #[must_use]
    pub(crate) fn to_tensor(self, product: f64) -> f64 {
        match self {
            ProductConvention::Tensor => product,
            ProductConvention::Cad => -product,
        }
    }

    /// A matrix whose off-diagonal entries are products in this convention, in tensor
    /// entries.
    #[must_use]
    pub fn matrix_to_tensor(self, m: &Matrix3<f64>) -> Matrix3<f64> {
        Matrix3::from_fn(|r, c| {
            if r == c {
                m[(r, c)]
            } else {
                self.to_tensor(m[(r, c)])
            }
        })
    }

    /// A bound `lower ≤ x ≤ upper` on `component` written in this convention, as a bound
    /// on the tensor entry: a CAD product bound `lo ≤ +Σ m x y ≤ hi` is
    /// `−hi ≤ J_ik ≤ −lo`; moments are unchanged.
    #[must_use]
    pub fn bound_to_tensor(
        self,
        component: Component,
        lower: Option<f64>,
        upper: Option<f64>,
    ) -> (Option<f64>, Option<f64>) {
        match self {
            ProductConvention::Cad if component.is_product() => {
                (upper.map(|v| -v), lower.map(|v| -v))
            }
            _ => (lower, upper),
        }
    }
}

impl Consistency {
    /// Short name: `physical`, `paper` or `positive-definite` (as on the command line).
    #[must_use]
    pub(crate) fn name(self) -> &'static str {
        match self {
            Consistency::Physical => "physical",
            Consistency::PaperTriangle => "paper",
            Consistency::PositiveDefiniteOnly => "positive-definite",
        }
    }
}

impl Default for ConstraintSet {
    fn default() -> Self {
        Self::physical()
    }
}

/// An element bound written `Jij=LO:HI` (`J33=2.7:3.3`, `J12=:0.05`, `J11=0.9:`, an
/// equality `J12=0:0`): the element and its lower and upper bound, kg m². The error is
/// why the text is not one (without the text itself, which the caller names).
pub fn parse_bound(s: &str) -> Result<(Component, Option<f64>, Option<f64>), &'static str> {
    let (name, range) = s.split_once('=').ok_or("missing `=`")?;
    let k = Component::from_name(name.trim()).ok_or("unknown element")?;
    let (lo, hi) = range.split_once(':').ok_or("missing `:`")?;
    let num = |t: &str| -> Result<Option<f64>, &'static str> {
        let t = t.trim();
        if t.is_empty() {
            return Ok(None);
        }
        let v: f64 = t.parse().map_err(|_| "not a number")?;
        if v.is_finite() {
            Ok(Some(v))
        } else {
            Err("not finite")
        }
    };
    let (l, h) = (num(lo)?, num(hi)?);
    if l.is_none() && h.is_none() {
        return Err("no bound given");
    }
    Ok((k, l, h))
}

/// Why a constraint set is unusable.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ConstraintError {
    /// A bound or ε is NaN or infinite.
    #[error("{what} is not finite ({value})")]
    NonFinite {
        /// Which value.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// ε must be positive.
    #[error("epsilon must be > 0 kg m², got {0}")]
    NonPositiveEpsilon(f64),
    /// A lower bound above its upper bound.
    #[error("bounds on {component} contradict each other: lower {} > upper {} kg m²", crate::text::Num(*.lower), crate::text::Num(*.upper))]
    CrossedBounds {
        /// Component name (J11 … J23).
        component: &'static str,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// A prior mean that is not finite, or a prior σ that is not finite and > 0.
    #[error("prior on {component}: {what} must be {expected}, got {}", crate::text::Num(*.value))]
    InvalidPrior {
        /// Component name (J11 … J23).
        component: &'static str,
        /// `mean` or `sigma`.
        what: &'static str,
        /// The value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// No J satisfies every constraint strictly.
    #[error("the bounds contradict J ⪰ εI and the {consistency} condition: no inertia satisfies all of them (best achievable margin {margin:.3e} kg m²)")]
    Infeasible {
        /// Name of the consistency condition.
        consistency: &'static str,
        /// The largest smallest-margin found (≤ 0).
        margin: f64,
    },
}

impl ConstraintSet {
    /// `J ⪰ εI` and `Σ ⪰ 0`: the default.
    #[must_use]
    pub fn physical() -> Self {
        Self {
            epsilon_kg_m2: DEFAULT_EPSILON_KG_M2,
            consistency: Consistency::Physical,
            lower_kg_m2: [None; 6],
            upper_kg_m2: [None; 6],
            prior: None,
        }
    }

    /// The paper's set (eq. 57): `J ⪰ εI` and the diagonal triangle inequalities.
    #[must_use]
    pub fn paper() -> Self {
        Self {
            consistency: Consistency::PaperTriangle,
            ..Self::physical()
        }
    }

    /// Only `J ⪰ εI`.
    #[must_use]
    pub fn positive_definite() -> Self {
        Self {
            consistency: Consistency::PositiveDefiniteOnly,
            ..Self::physical()
        }
    }

    /// Add `lower ≤ j[component] ≤ upper` (either side optional), intersecting with any
    /// bound already present. Products are tensor entries (`J12 = −Σ m x y`; negate a CAD
    /// tool's products of inertia). Bad values are caught by [`Self::validate`].
    #[must_use]
    pub fn with_bounds(
        mut self,
        component: Component,
        lower: Option<f64>,
        upper: Option<f64>,
    ) -> Self {
        let c = component.index();
        if let Some(l) = lower {
            self.lower_kg_m2[c] = Some(self.lower_kg_m2[c].map_or(l, |o| o.max(l)));
        }
        if let Some(u) = upper {
            self.upper_kg_m2[c] = Some(self.upper_kg_m2[c].map_or(u, |o| o.min(u)));
        }
        self
    }

    /// Add `|j[component] − nominal| ≤ fraction · |nominal|` (the paper's spin case bounds
    /// J33 within 10 % of 3 kg m²: `with_nominal(Component::J33, 3.0, 0.10)`).
    #[must_use]
    pub fn with_nominal(self, component: Component, nominal: f64, fraction: f64) -> Self {
        let w = (fraction * nominal).abs();
        self.with_bounds(component, Some(nominal - w), Some(nominal + w))
    }

    /// Bound every element to a nominal J (e.g. from CAD) within `fraction`: a moment
    /// `J_ii` within `fraction · |J_ii|`, a product `J_ik` within
    /// `fraction · √(J_ii J_kk)`. `nominal` holds tensor entries (`J12 = −Σ m x y`).
    #[must_use]
    pub(crate) fn with_nominal_inertia(mut self, nominal: &Matrix3<f64>, fraction: f64) -> Self {
        let j: InertiaVector = crate::tensor::j_from_matrix(nominal);
        for k in Component::ALL {
            let (r, c) = k.position();
            let w = if k.is_product() {
                fraction * crate::math::sqrt(crate::math::abs(nominal[(r, r)] * nominal[(c, c)]))
            } else {
                fraction * crate::math::abs(nominal[(r, r)])
            };
            self = self.with_bounds(k, Some(j[k.index()] - w), Some(j[k.index()] + w));
        }
        self
    }

    /// Fix `j[component] = value` (an equality: the solver eliminates it, and the
    /// observability test runs on the remaining elements).
    #[must_use]
    pub fn with_equality(self, component: Component, value: f64) -> Self {
        self.with_bounds(component, Some(value), Some(value))
    }

    /// Fix every product of inertia at zero: J diagonal in the body axes of the
    /// telemetry (a symmetric design whose axes are the principal axes).
    #[must_use]
    pub fn diagonal(self) -> Self {
        self.with_equality(Component::J12, 0.0)
            .with_equality(Component::J13, 0.0)
            .with_equality(Component::J23, 0.0)
    }

    /// A Gaussian prior: `nominal` (tensor entries) with a standard deviation per element
    /// (order of eq. 48), kg m².
    #[must_use]
    pub fn with_prior(mut self, nominal: &Matrix3<f64>, sigma_kg_m2: [f64; 6]) -> Self {
        let j: InertiaVector = crate::tensor::j_from_matrix(nominal);
        self.prior = Some(GaussianPrior {
            mean_kg_m2: core::array::from_fn(|k| j[k]),
            sigma_kg_m2,
        });
        self
    }

    /// A Gaussian prior with a relative standard deviation, as
    /// `Self::with_nominal_inertia` scales its bounds: a moment `J_ii` with
    /// `fraction · |J_ii|`, a product `J_ik` with `fraction · √(J_ii J_kk)`.
    #[must_use]
    pub fn with_relative_prior(self, nominal: &Matrix3<f64>, fraction: f64) -> Self {
        let sigma = Component::ALL.map(|k| {
            let (r, c) = k.position();
            if k.is_product() {
                fraction * crate::math::sqrt(crate::math::abs(nominal[(r, r)] * nominal[(c, c)]))
            } else {
                fraction * crate::math::abs(nominal[(r, r)])
            }
        });
        self.with_prior(nominal, sigma)
    }

    /// The elements fixed by an equality (`lower == upper`), with their values.
    #[must_use]
    pub(crate) fn fixed(&self) -> [Option<f64>; 6] {
        core::array::from_fn(|k| match (self.lower_kg_m2[k], self.upper_kg_m2[k]) {
            (Some(l), Some(u)) if l == u => Some(l),
            _ => None,
        })
    }

    /// The element bounds that `j` sits on (within `1e-9` of the bound's size, at least
    /// 1e-12 kg m²): the bounds that hold the answer, which the data alone would have
    /// put elsewhere. An equality is always active ([`BoundSide::Fixed`]).
    pub(crate) fn active_bounds(
        &self,
        j: &InertiaVector,
    ) -> impl Iterator<Item = ActiveBound> + '_ {
        let j = *j;
        Component::ALL.into_iter().flat_map(move |c| {
            let k = c.index();
            if let (Some(l), Some(u)) = (self.lower_kg_m2[k], self.upper_kg_m2[k]) {
                if l == u {
                    let fixed = ActiveBound {
                        component: c,
                        side: BoundSide::Fixed,
                        value_kg_m2: l,
                    };
                    return Some(fixed).into_iter().chain(None);
                }
            }
            let on = move |b: f64| crate::math::abs(j[k] - b) <= active_tolerance(b);
            let lower = self.lower_kg_m2[k].filter(|b| on(*b)).map(|b| ActiveBound {
                component: c,
                side: BoundSide::Lower,
                value_kg_m2: b,
            });
            let upper = self.upper_kg_m2[k].filter(|b| on(*b)).map(|b| ActiveBound {
                component: c,
                side: BoundSide::Upper,
                value_kg_m2: b,
            });
            lower.into_iter().chain(upper)
        })
    }

    /// `true` when any element bound is set (a-priori knowledge that can pin one open
    /// direction of J).
    #[must_use]
    pub(crate) fn has_bounds(&self) -> bool {
        self.lower_kg_m2
            .iter()
            .chain(&self.upper_kg_m2)
            .any(Option::is_some)
    }

    /// `true` when a bound keeps J away from zero along its scale: a lower bound above zero
    /// or an upper bound below it. Without rotor momentum or known torque (`y ≡ 0`) the
    /// data fix J only up to scale, and the estimators pull it toward the smallest
    /// feasible scale: only such a bound (or a Gaussian prior) gives it one. Equalities at
    /// zero (`--diagonal`) do not.
    #[must_use]
    pub(crate) fn has_scale_bound(&self) -> bool {
        self.lower_kg_m2.iter().flatten().any(|&l| l > 0.0)
            || self.upper_kg_m2.iter().flatten().any(|&u| u < 0.0)
    }

    /// Check the set and find a strictly interior point.
    pub fn validate(&self) -> Result<Constraints, ConstraintError> {
        let eps = self.epsilon_kg_m2;
        if !eps.is_finite() {
            return Err(ConstraintError::NonFinite {
                what: "epsilon",
                value: eps,
            });
        }
        if eps <= 0.0 {
            return Err(ConstraintError::NonPositiveEpsilon(eps));
        }
        for (name, (lower, upper)) in COMPONENT_NAMES
            .iter()
            .zip(self.lower_kg_m2.iter().zip(&self.upper_kg_m2))
        {
            for (b, what) in [(lower, "a lower bound"), (upper, "an upper bound")] {
                if let Some(v) = b {
                    if !v.is_finite() {
                        return Err(ConstraintError::NonFinite { what, value: *v });
                    }
                }
            }
            if let (Some(l), Some(u)) = (lower, upper) {
                if l > u {
                    return Err(ConstraintError::CrossedBounds {
                        component: name,
                        lower: *l,
                        upper: *u,
                    });
                }
            }
        }
        let mut c = Constraints {
            set: *self,
            lmis: [Lmi::zero(); 2],
            n_lmi: 0,
            lins: [Lin::zero(); MAX_LIN],
            n_lin: 0,
            interior: InertiaVector::zeros(),
            fixed: [None; 6],
        };
        // J − εI ⪰ 0.
        c.push_lmi(Lmi {
            f0: -Matrix3::identity() * eps,
            fk: basis(),
        });
        match self.consistency {
            Consistency::Physical => {
                let mut fk = basis();
                for (k, f) in fk.iter_mut().enumerate() {
                    let tr = if k < 3 { 1.0 } else { 0.0 };
                    *f = Matrix3::identity() * (0.5 * tr) - *f;
                }
                c.push_lmi(Lmi {
                    f0: Matrix3::zeros(),
                    fk,
                });
            }
            Consistency::PaperTriangle => {
                for (p, q, r) in [(0, 1, 2), (0, 2, 1), (1, 2, 0)] {
                    let mut a = InertiaVector::zeros();
                    a[p] = 1.0;
                    a[q] = 1.0;
                    a[r] = -1.0;
                    c.push_lin(Lin { a, b: 0.0 });
                }
            }
            Consistency::PositiveDefiniteOnly => {}
        }
        if let Some(p) = &self.prior {
            for (k, name) in COMPONENT_NAMES.iter().enumerate() {
                let (m, sd) = (p.mean_kg_m2[k], p.sigma_kg_m2[k]);
                if !m.is_finite() {
                    return Err(ConstraintError::InvalidPrior {
                        component: name,
                        what: "mean",
                        value: m,
                        expected: "finite",
                    });
                }
                if !(sd.is_finite() && sd > 0.0) {
                    return Err(ConstraintError::InvalidPrior {
                        component: name,
                        what: "sigma",
                        value: sd,
                        expected:
                            "finite and > 0 kg m² (an exactly known element is an equality bound)",
                    });
                }
            }
        }
        let fixed = self.fixed();
        for i in (0..6).filter(|&i| fixed[i].is_none()) {
            if let Some(l) = self.lower_kg_m2[i] {
                c.push_lin(Lin {
                    a: InertiaVector::ith(i, 1.0),
                    b: l,
                });
            }
            if let Some(u) = self.upper_kg_m2[i] {
                c.push_lin(Lin {
                    a: InertiaVector::ith(i, -1.0),
                    b: -u,
                });
            }
        }
        // Equalities are eliminated: their values move into the constant terms, and the
        // constraints no longer depend on those elements.
        c.fixed = fixed;
        for l in &mut c.lmis[..c.n_lmi] {
            for (k, v) in fixed.iter().enumerate() {
                if let Some(v) = v {
                    l.f0 += l.fk[k] * *v;
                    l.fk[k] = Matrix3::zeros();
                }
            }
        }
        for l in &mut c.lins[..c.n_lin] {
            for (k, v) in fixed.iter().enumerate() {
                if let Some(v) = v {
                    l.b -= l.a[k] * *v;
                    l.a[k] = 0.0;
                }
            }
        }
        let (interior, margin) = c.phase_one();
        if margin <= 0.0 || !margin.is_finite() {
            return Err(ConstraintError::Infeasible {
                consistency: self.consistency_name(),
                margin,
            });
        }
        c.interior = c.with_fixed(&interior);
        Ok(c)
    }

    fn consistency_name(&self) -> &'static str {
        match self.consistency {
            Consistency::Physical => "physical-consistency (Σ = ½ tr(J) I − J ⪰ 0)",
            Consistency::PaperTriangle => "diagonal triangle (eq. 9)",
            Consistency::PositiveDefiniteOnly => "positive-definiteness",
        }
    }
}
