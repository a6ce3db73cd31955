//! User-defined systems (issue 15): Hamiltonians given as functions, integrated with the generic
//! methods of [`crate::integrate::methods`].
//!
//! * [`UserCanonical`]: H(q, p) on T*ℝᵈ, state z = (q, p), with the gradient (∂H/∂q, ∂H/∂p) or,
//!   without it, central differences of H ([`FD_STEP`]); kinds [`Canonical`](crate::integrate::problem::Canonical) and
//!   [`VectorField`](crate::integrate::problem::VectorField); methods "gauss4" (default), "gauss6", "midpoint", "rk4"
//!   ([`crate::integrate::methods::canonical_catalog`]).
//! * [`UserSeparable`]: H = ½ pᵀM⁻¹p + U(q) with a constant positive-definite mass M (a matrix, or
//!   a scalar or vector for a diagonal one) and U, ∇U functions; kinds [`Separable`](crate::integrate::problem::Separable) (Störmer–
//!   Verlet and its compositions "verlet" (default), "verlet4", "verlet6"), [`Canonical`](crate::integrate::problem::Canonical) (the
//!   Gauss methods) and [`VectorField`](crate::integrate::problem::VectorField) ("rk4").
//! * [`LiePoisson`]: a Lie–Poisson system on g* (so(3), se(3), so(n) or structure constants),
//!   μ̇ = ad*_{∂H/∂μ} μ, with H a function or a quadratic form ½ μᵀAμ (the native path); kinds
//!   [`GroupField`](crate::integrate::problem::GroupField) (the coadjoint action: "rkmk4" (default), the Lie midpoint "midpoint" and its
//!   Suzuki composition "midpoint4", all of which keep the coadjoint orbit, i.e. every Casimir, to
//!   round-off) and [`VectorField`](crate::integrate::problem::VectorField) ("rk4", the baseline).
//!
//! **Lie–Poisson conventions.** Coordinates μ_k of g* are dual to a basis e_k of g (the pairing
//! is the dot product of coordinates), with [e_i, e_j] = C_ij^k e_k. Then (ad_ξ)_{kj} =
//! Σ_i ξ_i C_ij^k, ad*_ξ μ = ad_ξᵀ μ, i.e. (ad*_ξ μ)_j = Σ_{i,k} C_ij^k ξ_i μ_k, and the equation
//! is μ̇ = ad*_{∇H} μ. Sign check on so(3) (e_k the physics basis, C_ij^k = ε_ijk, [û, v̂] =
//! (u × v)^): ad*_Ω M = −Ω × M = M × Ω, Euler's Ṁ = M × Ω for H = ½ M·I⁻¹M (000 §4; the sign of
//! [`crate::systems::RigidBody`], tested against it). On se(3) with ξ = (ω, v) (rotation first, the
//! bracket of [`crate::lie::se3::ad_matrix`]) and μ = (M, Γ): Ṁ = M × Ω + Γ × V, Γ̇ = Γ × Ω with
//! (Ω, V) = ∇H, Kirchhoff's equations of a body in an ideal fluid (Γ the impulse) and the heavy
//! top's (Γ the vertical); Casimirs |Γ|², M·Γ. On so(n) in the e_ij coordinates of
//! [`crate::lie::so::vee_n`] (pairing ½ tr(ξᵀη), 001 (2.8)): Ṁ = [M, Ω], the sign of
//! [`crate::systems::GeneralizedRigidBody`]; Casimirs ½ tr((MᵀM)^k), k = 1…⌊n/2⌋.
//!
//! **Left and right.** A left-invariant Lagrangian reduces to μ̇ = ad*_ξ μ with ξ = ∇H(μ) (000
//! §4.1, the body frame); a right-invariant one to μ̇ = −ad*_ξ μ (the spatial frame). Derived
//! by the mirror g ↦ g⁻¹: if g(t) has right velocity ξ = ġg⁻¹, then h = g⁻¹ has left velocity
//! h⁻¹ḣ = −ξ, so the right system of ℓ is the left system of ℓ̃(η) = ℓ(−η), whose momentum is
//! μ̃ = −μ; its equation d/dt μ̃ = ad*_η μ̃ reads μ̇ = −ad*_ξ μ. [`Side`] chooses the sign
//! ([`LiePoisson::with_side`]); the coadjoint action then takes ξ(μ) = +∇H(μ). The test: a
//! right-invariant run from μ₀ is, bit for bit, the negated left-invariant run of H̃(μ) = H(−μ)
//! from −μ₀ (negation commutes exactly with every operation of the methods).
//!
//! **The coadjoint action as a [`GroupField`](crate::integrate::problem::GroupField).** G acts on g* by g·μ = Ad*_{g⁻¹} μ =
//! Ad_{g⁻¹}ᵀ μ, whose infinitesimal generator is ξ·μ = −ad*_ξ μ; so ξ(μ) = −∇H(μ) gives
//! ξ(μ)·μ = ad*_{∇H} μ. exp(ξ)·μ is computed by the group maps of [`crate::lie`] where the group
//! is built in: so(3) μ ↦ exp(ξ̂) μ ([`so3::exp`](crate::lie::so3::exp); dexp⁻¹ = J_l⁻¹, [`so3::jacobian_left_inv`](crate::lie::so3::jacobian_left_inv),
//! as [`crate::systems::RigidBody`]); so(n) M ↦ g M gᵀ (the kernels of [`crate::systems::GeneralizedRigidBody`]);
//! se(3) μ ↦ Ad_{exp(−ξ)}ᵀ μ ([`se3::exp`](crate::lie::se3::exp), [`se3::SE3::adjoint_matrix`](crate::lie::se3::SE3::adjoint_matrix)). For structure
//! constants, exp(ξ)·μ = exp(−ad_ξᵀ) μ by the Taylor series of the exponential applied to μ
//! (scaled so that each factor has ‖ad_ξ‖ ≤ ½, summed to a term below 10⁻¹⁸ of the sum): an exact
//! coadjoint map up to round-off, so the orbit (every Casimir) is kept to round-off as with the
//! built-in groups. dexp⁻¹_u = Σ_k B_k/k! ad_uᵏ by its Bernoulli series for se(3) and structure
//! constants (NaN beyond ‖ad_u‖_∞ ≥ π, where the series converges slowly; RKMK then stops with
//! the step named).
//!
//! **Which methods, and why.** The orbit-preserving methods are the ones the kind [`GroupField`](crate::integrate::problem::GroupField)
//! supports for any g: RKMK4 (explicit, order 4, energy error drifting like RK4's at O(h⁴)) and
//! the Lie midpoint (symmetric, order 2, and its composition of order 4; bounded energy error
//! for reversible systems such as the rigid body and Kirchhoff's body). The isospectral
//! symplectic midpoint of [`super::isospectral`](crate::systems::tops::methods::isospectral) would generalise to any H on so(n)* (replace
//! Ω_ij = M_ij/d_ij by Ω = hat(∇H)), but its kernel is written for the rigid body's diagonal
//! map; it is not offered here. RK4 is the non-geometric baseline.
//!
//! **Failures of user functions.** The functions return [`Result`]; a kernel that cannot return
//! an error (the problem kinds' kernels do not) records it ([`hooks::fail`](crate::integrate::hooks::fail)) and hands NaN to the
//! method. These systems [call out](crate::integrate::Problem::calls_out), so a run steps them one step at a time
//! and ends after the step in which a function failed, with that function's error located ("in
//! step k of gauss4, t = …, dt = …"), never taking a step twice. Values are checked: a
//! non-finite H or gradient entry is [`Error::NonFinite`] naming the entry. Evaluation of H
//! outside the kernels ([`Problem::energy`](crate::integrate::Problem::energy), the Casimirs) returns the error.
//!
//! **Finite differences** (a function given without its gradient): each derivative is a central
//! difference with one Richardson extrapolation ([`crate::numerics`]' finite differences, four
//! evaluations per coordinate), with steps h_l = [`FD_STEP`]·max(|x_l|, ‖x‖_∞) (x = (q, p) or
//! μ; [`FD_STEP`] alone at x = 0). The error is O(h⁴) truncation plus O(ε|H|/h) round-off:
//! about 1e-12 relative to the scale of H/x for smooth H whose variation scale is that of x
//! (measured 2e-13 … 3e-12 on the tests' pendulum and rigid body). Such a gradient is not exactly
//! the gradient of a function, so the Gauss and Verlet methods are symplectic only up to it: the
//! energy error of a long run may drift by about that much per unit time. Pass the gradient
//! where long runs or non-smooth scales matter.

pub mod attitude;
mod canonical;
mod euler_poincare;
mod lie_poisson;
mod separable;

use std::sync::Arc;

use crate::check;
use crate::error::{Error, Result};
use crate::integrate::space::{Block, Space};
use crate::numerics::fd::{self, Scheme};

pub use crate::lie::structure::Algebra;
pub use attitude::Side;
pub use canonical::UserCanonical;
pub use euler_poincare::{
    Action, EulerPoincare, HessianFn, Lagrangian, LagrangianFn, LagrangianGradientFn,
    LagrangianHessianFn, Legendre,
};
pub use lie_poisson::{LieHamiltonian, LieHessianFn, LiePoisson, LieScratch};
pub use separable::{HessianProductFn, KineticMass, UserSeparable};

/// H(q, p) of a [`UserCanonical`].
pub type CanonicalFn = Arc<dyn Fn(&[f64], &[f64]) -> Result<f64> + Send + Sync>;
/// The gradient of a [`UserCanonical`]: (q, p, ∂H/∂q out, ∂H/∂p out).
pub type CanonicalGradientFn =
    Arc<dyn Fn(&[f64], &[f64], &mut [f64], &mut [f64]) -> Result<()> + Send + Sync>;
/// The Hessian product of a [`CanonicalFn`]: (q, p, dq, dp, ∂H_q out, ∂H_p out), the derivative
/// of the gradient (∂H/∂q, ∂H/∂p) along (dq, dp).
pub type CanonicalHessianFn =
    Arc<dyn Fn(&[f64], &[f64], &[f64], &[f64], &mut [f64], &mut [f64]) -> Result<()> + Send + Sync>;
/// A scalar function f(x) (a potential U(q), a Lie–Poisson H(μ), a Casimir).
pub type ScalarFn = Arc<dyn Fn(&[f64]) -> Result<f64> + Send + Sync>;
/// The gradient of a [`ScalarFn`]: (x, ∇f out).
pub type GradientFn = Arc<dyn Fn(&[f64], &mut [f64]) -> Result<()> + Send + Sync>;

/// The base step of the finite differences, ε^{1/5} ≈ 7.4e-4 (the step that balances the O(h⁴)
/// truncation of the Richardson-extrapolated central difference against its O(ε/h) round-off).
pub const FD_STEP: f64 = 7.4e-4;

// ---------------------------------------------------------------------------------------------
// value checks and finite differences

/// `v`, or [`Error::NonFinite`] naming `what`.
pub(super) fn finite_value(what: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::NonFinite {
            what: what.into(),
            location: format!("its value ({v})"),
        })
    }
}

/// Ok if every entry of `v` is finite, else [`Error::NonFinite`] naming `what` and the entry
/// `name[i]`.
pub(super) fn finite_entries(what: &str, name: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::NonFinite {
            what: what.into(),
            location: format!("{name}[{i}] = {}", v[i]),
        }),
    }
}

/// ∇f(x) into `out` by central differences with one Richardson extrapolation (module docs).
pub(super) fn fd_gradient(
    f: &dyn Fn(&[f64]) -> Result<f64>,
    x: &[f64],
    out: &mut [f64],
) -> Result<()> {
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let h: Vec<f64> = x
        .iter()
        .map(|v| {
            let s = v.abs().max(scale);
            FD_STEP * if s > 0.0 { s } else { 1.0 }
        })
        .collect();
    fd::gradient(f, x, &h, Scheme::Richardson, out)
}

pub(super) fn check_dof(what: &str, dof: usize) -> Result<()> {
    if dof == 0 {
        return Err(Error::invalid(
            what,
            "expected at least 1 degree of freedom, got 0",
        ));
    }
    check::array_size(what, &[2, dof]).map(|_| ())
}

/// The state space (q, p) of d degrees of freedom.
pub(super) fn qp_space(d: usize) -> Space {
    Space::new([("q", Block::Real(d)), ("p", Block::Real(d))])
}
