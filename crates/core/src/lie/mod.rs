//! Matrix Lie groups and their Lie algebras.
//!
//! Every group speaks the same verbs through [`MatrixLieGroup`] (compose, inverse, exp, log, Ad,
//! ad, ad*), so integrators and the generic property tests are written once.
//!
//! Conventions (DESIGN.md): on so(n) the pairing is ⟨ξ, η⟩ = ½ tr(ξᵀη) (001 (2.8)); the basis
//! e_ij (i < j) has +1 at (i, j) and −1 at (j, i). On so(3) ≅ R³ the physics hat map is used
//! ([`so3::hat`]), with the dot product as pairing.

/// Tolerance on ‖ξ + ξᵀ‖_F / max(1, ‖ξ‖_F) for accepting a matrix as skew-symmetric (so(n)
/// and so(3) alike).
pub const SKEW_TOL: f64 = 1e-10;

/// The rule of [`ANGLE_ROUNDING_TOL`]: `Ok` when |ξ| = `norm` ≤ [`EXP_MAX_NORM`], else
/// [`crate::Error::InvalidArgument`] about `what` naming the map, |ξ| and the angle lost.
/// `norm` should come from [`scaled_norm`] so that it is finite for every finite input.
pub fn check_exp_norm(what: &str, map: &str, norm: f64) -> Result<()> {
    if norm <= EXP_MAX_NORM {
        return Ok(());
    }
    Err(crate::Error::invalid(
        what,
        format!(
            "{map} needs |{what}| ≤ {EXP_MAX_NORM:.3e}, got |{what}| = {}: beyond it more than \
             ε_mach·|{what}| > {ANGLE_ROUNDING_TOL} rad of the rotation angle is lost to rounding",
            crate::error::fmt_num(norm)
        ),
    ))
}

/// √(Σ xᵢ²) without overflow or underflow (scaled by the largest |xᵢ|): finite for every finite
/// input, and +inf/NaN only for non-finite input.
pub fn scaled_norm<'a>(x: impl IntoIterator<Item = &'a f64> + Clone) -> f64 {
    let m = x.clone().into_iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if m == 0.0 || !m.is_finite() {
        return if x.into_iter().any(|v| v.is_nan()) {
            f64::NAN
        } else {
            m
        };
    }
    let s: f64 = x.into_iter().map(|v| (v / m) * (v / m)).sum();
    m * s.sqrt()
}

pub mod gl;
pub mod product;
pub mod rotations;
pub mod se3;
pub mod so;
pub mod so3;
pub mod structure;

use crate::numerics::angle::{ANGLE_ROUNDING_TOL, EXP_MAX_NORM};
use crate::{Mat, Result};

/// A matrix Lie group G with Lie algebra 𝔤, the dual 𝔤* identified with 𝔤 through
/// [`MatrixLieGroup::pairing`]: the one place where the verbs of every group are declared
/// (DESIGN.md, "Group verbs").
///
/// Elements carry their own size where it is a runtime value (SO(n)), so constructors of the
/// algebra that need it take `&self` as a size witness. Checked verbs return a `Result`; the
/// `_unchecked` twin of [`MatrixLieGroup::exp`] is for inner loops on known-good input. The
/// Jacobians are dim × dim matrices acting on algebra coordinates ([`MatrixLieGroup::coords`]):
/// exp(ξ + δ) = exp(ξ) exp(J_r(ξ) δ) = exp(J_l(ξ) δ) exp(ξ) to first order in δ.
pub trait MatrixLieGroup: Clone + std::fmt::Debug {
    /// An element of the Lie algebra.
    type Algebra: Clone + std::fmt::Debug;
    /// A vector of the defining representation, on which [`MatrixLieGroup::act`] acts.
    type Point: Clone + std::fmt::Debug;

    /// Dimension of the group (the number of algebra coordinates).
    fn dim(&self) -> usize;
    /// The identity of the same size as `self`.
    fn identity_like(&self) -> Self;
    /// Group product `self · other`.
    fn compose(&self, other: &Self) -> Self;
    /// Group inverse.
    fn inverse(&self) -> Self;
    /// The action g · x on a vector of the defining representation.
    fn act(&self, x: &Self::Point) -> Self::Point;
    /// Exponential map 𝔤 → G, with the checks of the group's free `exp` (finite ξ, the rule of
    /// [`ANGLE_ROUNDING_TOL`]).
    fn exp(xi: &Self::Algebra) -> Result<Self>;
    /// [`MatrixLieGroup::exp`] without checks (NaN for invalid input), for inner loops.
    fn exp_unchecked(xi: &Self::Algebra) -> Self;
    /// Principal logarithm G → 𝔤 (an error where it is not unique).
    fn log(&self) -> Result<Self::Algebra>;
    /// Adjoint action Ad_g ξ = d/dt g exp(tξ) g⁻¹ at t = 0.
    fn adjoint(&self, xi: &Self::Algebra) -> Self::Algebra;
    /// Lie bracket ad_ξ η = [ξ, η].
    fn ad(xi: &Self::Algebra, eta: &Self::Algebra) -> Self::Algebra;
    /// Coadjoint action ad*_ξ μ, defined by ⟨ad*_ξ μ, η⟩ = ⟨μ, ad_ξ η⟩.
    fn ad_star(xi: &Self::Algebra, mu: &Self::Algebra) -> Self::Algebra;
    /// Pairing ⟨μ, ξ⟩ between 𝔤* (identified with 𝔤) and 𝔤.
    fn pairing(mu: &Self::Algebra, xi: &Self::Algebra) -> f64;
    /// The group element as a matrix (its defining representation).
    fn matrix(&self) -> Mat;
    /// The algebra element as a matrix in the same representation, so that
    /// `exp(xi).matrix() = expm(hat(xi))`.
    fn hat(xi: &Self::Algebra) -> Mat;
    /// Inverse of [`MatrixLieGroup::hat`]: errors if `m` is not (to the group's tolerance) the
    /// matrix of an algebra element.
    fn vee(m: &Mat) -> Result<Self::Algebra>;
    /// Coordinates of an algebra element.
    fn coords(xi: &Self::Algebra) -> Vec<f64>;
    /// The algebra element with coordinates `c` (of length `self.dim()`).
    fn algebra_from_coords(&self, c: &[f64]) -> Self::Algebra;
    /// Right Jacobian J_r(ξ) of exp: exp(ξ + δ) = exp(ξ) exp(J_r(ξ) δ) + O(δ²).
    fn jacobian_right(xi: &Self::Algebra) -> Result<Mat>;
    /// Left Jacobian J_l(ξ) of exp: exp(ξ + δ) = exp(J_l(ξ) δ) exp(ξ) + O(δ²); J_l(ξ) = J_r(−ξ)
    /// = Ad_exp(ξ) J_r(ξ).
    fn jacobian_left(xi: &Self::Algebra) -> Result<Mat>;
    /// J_r(ξ)⁻¹ (an error where J_r is singular or its series diverges).
    fn jacobian_right_inv(xi: &Self::Algebra) -> Result<Mat>;
    /// J_l(ξ)⁻¹ (an error where J_l is singular or its series diverges).
    fn jacobian_left_inv(xi: &Self::Algebra) -> Result<Mat>;
}

/// A nalgebra matrix as a [`Mat`] (the Jacobians of the fixed-size groups).
pub(crate) fn to_mat<R: nalgebra::Dim, C: nalgebra::Dim, S: nalgebra::RawStorage<f64, R, C>>(
    m: &nalgebra::Matrix<f64, R, C, S>,
) -> Mat {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}
