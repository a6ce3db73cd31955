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
/// [`MatrixLieGroup::pairing`].
///
/// Elements carry their own size where it is a runtime value (SO(n)), so constructors of the
/// algebra that need it take `&self` as a size witness.
pub trait MatrixLieGroup: Clone + std::fmt::Debug {
    /// An element of the Lie algebra.
    type Algebra: Clone + std::fmt::Debug;

    /// Dimension of the group (the number of algebra coordinates).
    fn dim(&self) -> usize;
    /// The identity of the same size as `self`.
    fn identity_like(&self) -> Self;
    /// Group product `self · other`.
    fn compose(&self, other: &Self) -> Self;
    /// Group inverse.
    fn inverse(&self) -> Self;
    /// Exponential map 𝔤 → G.
    fn exp(xi: &Self::Algebra) -> Self;
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
    /// `exp(xi).matrix() = expm(algebra_matrix(xi))`.
    fn algebra_matrix(xi: &Self::Algebra) -> Mat;
    /// Coordinates of an algebra element.
    fn coords(xi: &Self::Algebra) -> Vec<f64>;
    /// The algebra element with coordinates `c` (of length `self.dim()`).
    fn algebra_from_coords(&self, c: &[f64]) -> Self::Algebra;
}
