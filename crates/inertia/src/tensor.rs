//! The inertia tensor and its six-component vector `j` (paper eqs. 7–9 and 48).
//!
//! `j = [J11, J22, J33, J12, J13, J23]ᵀ` in body axes, kg m². The matrix is symmetric,
//! `J = Σ m_i S(r_i)ᵀ S(r_i)` (eq. 7). A physically realisable J has a positive
//! semidefinite second-moment matrix `Σ = ½ tr(J) I − J` (docs/conventions.md §4), which implies both
//! `J ⪰ 0` and the triangle inequalities on the principal moments; the paper's eq. 9 tests
//! only the diagonal in body axes, which is necessary but not sufficient.
//!
//! # Sign of the products of inertia
//!
//! `J12`, `J13`, `J23` are the **tensor entries**, `J12 = −Σ m x y` (so that `H = J ω`).
//! Many CAD tools report the *product of inertia* `P_xy = +Σ m x y`; their tensor entry is
//! `−P_xy`. Every input of prior knowledge here (bounds, nominal J) takes tensor entries:
//! negate a CAD tool's products first (`docs/conventions.md` §6).

use nalgebra::{Matrix3, SymmetricEigen, Vector3, Vector6};

/// Six inertia components in the paper's order `[J11, J22, J33, J12, J13, J23]` (eq. 48).
pub type InertiaVector = Vector6<f64>;

/// Names of the six components in the order of eq. 48.
pub const COMPONENT_NAMES: [&str; 6] = ["J11", "J22", "J33", "J12", "J13", "J23"];

/// `(row, col)` of each component of `j` in `J`.
pub const COMPONENT_INDEX: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

/// One of the six components of `j`, in the order of eq. 48. Products are tensor
/// entries (`J12 = −Σ m x y`; see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Component {
    /// `J11 = Σ m (y² + z²)`.
    J11,
    /// `J22 = Σ m (x² + z²)`.
    J22,
    /// `J33 = Σ m (x² + y²)`.
    J33,
    /// `J12 = −Σ m x y`.
    J12,
    /// `J13 = −Σ m x z`.
    J13,
    /// `J23 = −Σ m y z`.
    J23,
}

impl Component {
    /// All six, in the order of eq. 48.
    pub const ALL: [Component; 6] = [
        Component::J11,
        Component::J22,
        Component::J33,
        Component::J12,
        Component::J13,
        Component::J23,
    ];

    /// Position in `j`.
    #[must_use]
    pub const fn index(self) -> usize {
        self as usize
    }

    /// Name, e.g. `J12`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        COMPONENT_NAMES[self as usize]
    }

    /// `(row, col)` in `J`.
    #[must_use]
    pub(crate) const fn position(self) -> (usize, usize) {
        COMPONENT_INDEX[self as usize]
    }

    /// Whether this is a product of inertia.
    #[must_use]
    pub(crate) const fn is_product(self) -> bool {
        self.index() >= 3
    }

    /// By name, case-insensitive; `J21` is `J12` and so on.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        let b = name.as_bytes();
        if b.len() != 3 || !(b[0] == b'J' || b[0] == b'j') {
            return None;
        }
        let (r, c) = (
            b[1].wrapping_sub(b'1') as usize,
            b[2].wrapping_sub(b'1') as usize,
        );
        Self::ALL.into_iter().find(|k| {
            let (i, j) = k.position();
            (i, j) == (r, c) || (i, j) == (c, r)
        })
    }
}

impl core::fmt::Display for Component {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// Symmetric 3×3 matrix from `j` (eq. 48).
#[must_use]
pub fn matrix_from_j(j: &InertiaVector) -> Matrix3<f64> {
    Matrix3::new(j[0], j[3], j[4], j[3], j[1], j[5], j[4], j[5], j[2])
}

/// `j` from a matrix (the upper triangle is read; symmetry is the caller's business).
#[must_use]
pub fn j_from_matrix(m: &Matrix3<f64>) -> InertiaVector {
    InertiaVector::new(
        m[(0, 0)],
        m[(1, 1)],
        m[(2, 2)],
        m[(0, 1)],
        m[(0, 2)],
        m[(1, 2)],
    )
}

/// The second-moment matrix `Σ = ½ tr(J) I − J` (docs/conventions.md §4).
#[must_use]
pub fn second_moment(j: &Matrix3<f64>) -> Matrix3<f64> {
    Matrix3::identity() * (0.5 * j.trace()) - j
}

/// Principal moments (ascending) and the principal axes as columns of a rotation matrix
/// from principal to body axes. Std only (uses an iterative eigen-solver).
#[must_use]
pub fn principal(j: &Matrix3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
    // Bounded iterations; the closed form when they do not converge.
    let e = SymmetricEigen::try_new(*j, f64::EPSILON, crate::math::MAX_DECOMPOSITION_ITERATIONS)
        .unwrap_or_else(|| {
            let (values, vectors) = crate::eigen3::symmetric_eigen3(j);
            SymmetricEigen {
                eigenvalues: values,
                eigenvectors: Matrix3::from_columns(&vectors),
            }
        });
    let mut idx = [0usize, 1, 2];
    idx.sort_unstable_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
    let vals = Vector3::new(
        e.eigenvalues[idx[0]],
        e.eigenvalues[idx[1]],
        e.eigenvalues[idx[2]],
    );
    let mut axes = Matrix3::zeros();
    for (c, &i) in idx.iter().enumerate() {
        axes.set_column(c, &e.eigenvectors.column(i));
    }
    if axes.determinant() < 0.0 {
        let c = -axes.column(2);
        axes.set_column(2, &c);
    }
    (vals, axes)
}

/// Relative Frobenius error `‖Ĵ − J‖_F / ‖J‖_F` (the paper's "normalized inertia error").
#[must_use]
pub fn relative_frobenius_error(estimate: &Matrix3<f64>, truth: &Matrix3<f64>) -> f64 {
    (estimate - truth).norm() / truth.norm()
}

/// The true inertia of the paper's section VI examples, kg m².
#[must_use]
pub fn paper_j_true() -> Matrix3<f64> {
    Matrix3::new(
        1.0035, 0.0368, -0.0678, //
        0.0368, 2.0047, -0.0755, //
        -0.0678, -0.0755, 2.9918,
    )
}

/// The paper's diagonal triangle inequalities (eq. 9): the three slacks
/// `[J11 + J22 − J33, J11 + J33 − J22, J22 + J33 − J11]`, each ≥ 0 when satisfied.
#[must_use]
pub fn diagonal_triangle_slacks(j: &Matrix3<f64>) -> [f64; 3] {
    let (a, b, c) = (j[(0, 0)], j[(1, 1)], j[(2, 2)]);
    [a + b - c, a + c - b, b + c - a]
}

/// Normalised error of each element, in the order of eq. 48: moments relative to their
/// own true value, `(Ĵ_ii − J_ii)/J_ii`; products relative to the geometric mean of the
/// two moments they couple, `(Ĵ_ij − J_ij)/√(J_ii J_jj)`. (A product's error relative to
/// its own value is meaningless when the product is near zero.)
#[must_use]
pub fn normalized_element_errors(estimate: &Matrix3<f64>, truth: &Matrix3<f64>) -> [f64; 6] {
    core::array::from_fn(|k| {
        let (r, c) = COMPONENT_INDEX[k];
        let scale = if r == c {
            truth[(r, r)]
        } else {
            crate::math::sqrt(truth[(r, r)] * truth[(c, c)])
        };
        (estimate[(r, c)] - truth[(r, c)]) / scale
    })
}
