//! Relative equilibria of the pseudo-rigid body, the augmented and amended potentials (001 §8).
//!
//! # Conventions and the formulas used (derived again; checked in `tests/equilibria.rs`)
//! A vertical velocity at X is Ẋ = ξX + Xηᵀ = ξX − Xη for ξ ⊕ η ∈ so(n) ⊕ so(n) (001 (6.19)).
//! With the pairing ⟨ξ, η⟩ = ½tr(ξᵀη) of DESIGN.md,
//!
//! ⟨ξ ⊕ η, B_X(ξ ⊕ η)⟩ = ‖ξX − Xη‖² (tr pairing),
//!
//! because ⟨ξ, A^L_X ξ⟩ = ‖ξX‖², ⟨η, A^R_X η⟩ = ‖Xη‖² and the two cross terms of 001 (6.9) give
//! −2 tr(ξᵀXηXᵀ) = −2⟨ξX, Xη⟩. Hence the augmented potential (001 (8.12)) is
//! U_{ξ⊕η}(X) = U(X) − ½‖W‖² with W = ξX − Xη, and since d(½‖W‖²) = ⟨W, ξ dX − dX η⟩,
//!
//! ∂U_{ξ⊕η}/∂X = ∂U/∂X − (ξᵀW − Wηᵀ) = ∂U/∂X + ξW − Wη.
//!
//! For the curve X(t) = e^{tξ} X₀ e^{−tη}: Ẋ = ξX − Xη = W, Ẍ = ξW − Wη, so Ẍ = −∂U/∂X holds
//! iff ∂U_{ξ⊕η}/∂X(X₀) = 0 — the whole n×n gradient: its diagonal (in the SVD frame) is the force
//! balance in the semi-axes, its off-diagonal part is the derivative along the group orbit, which
//! vanishes iff the velocities satisfy 001 (8.6) (on the principal stratum the orbit directions
//! ζ₁A − Aζ₂ span the off-diagonal matrices).
//!
//! The amended potential (001 (8.8), (8.11)) is V_{λ⊕γ}(X) = U(X) + ½⟨λ ⊕ γ, B_X⁻¹(λ ⊕ γ)⟩.
//! Legendre: with v = B_X⁻¹J, ∂/∂X ½⟨J, B_X⁻¹J⟩ = −½⟨v, (∂B_X)v⟩ = −∂/∂X ½⟨v, B_X v⟩|_v fixed, so
//! ∂V_J/∂X = ∂U_v/∂X (the same matrix), while V_J(X) + U_v(X) = 2U(X).
//!
//! # Relative equilibria through diag(a)
//! Representative X₀ = A₀ = diag(a), R₀ = S₀ = I, so body and spatial quantities agree at t = 0:
//! Ω = ξ, Λ = η (constant body velocities), λ ⊕ γ = B_A(Ω ⊕ Λ) = L ⊕ Γ at (X₀, P₀) with
//! P₀ = ΩA − AΛ (001 (7.3), (8.4)), and the motion is R(t) = e^{tΩ}, S(t) = e^{tΛ}
//! (Ṙ = RΩ, Ṡ = SΛ), X(t) = e^{tΩ} A e^{−tΛ}, P(t) = e^{tΩ}(ΩA − AΛ)e^{−tΛ} (001 (8.2)–(8.3)).
//!
//! - Force balance (p_a = 0): F_k(a) = ∂/∂a_k [U(a) − ½‖ΩA − AΛ‖²] = (∂U/∂X)_kk + (ΩW − WΛ)_kk.
//!   At fixed body momenta the same force is ∂/∂a_k [U(a) + K(a; μ, ν)] with the pair formula of
//!   [`super::reduced`] (Legendre again: ∂K/∂a|_(μ,ν) = −∂K/∂a|_(Ω,Λ)).
//! - 001 (8.6): [Ω ⊕ Λ, B_A(Ω ⊕ Λ)] = [Ω, p_Ω] ⊕ [Λ, p_Λ] = 0. Split Ω ⊕ Λ into eigencomponents
//!   of B_A (001 (8.15)): [v, B_A v] = Σ_{λ<λ'} (λ' − λ)[v_λ, v_λ'] (001 (8.16)). Components in
//!   one plane (i, j) commute, and e_ij, e_kl commute for disjoint planes (001 (8.17)); so (8.6)
//!   holds for **every** A when the planes carrying Ω and Λ are pairwise disjoint (a matching),
//!   in particular for Ω = ω e_ij, Λ = μ e_ij with any (ω, μ) — not only along the two
//!   eigen-directions. Velocities coupling planes that share an axis satisfy (8.6) only where
//!   B_A has repeated eigenvalues, and typically only where two semi-axes coincide (B_A singular,
//!   seed-errata §8); the solvers report this instead of picking a point.
//! - One plane, exactly: with Ω = ω e_ij, Λ = μ e_ij, ½‖W‖² = ½((ωa_j − μa_i)² + (ωa_i − μa_j)²),
//!   whose a-gradient is ((ω² + μ²)a_i − 2ωμ a_j, (ω² + μ²)a_j − 2ωμ a_i) on (i, j) and 0 elsewhere.
//!   With g = ∂U/∂a, force balance is g_k = 0 for k ∉ {i, j} and
//!
//!   (ω + μ)² = (g_i − g_j)/(a_i − a_j),  (ω − μ)² = (g_i + g_j)/(a_i + a_j),
//!
//!   (the components along the eigen-directions e_ij ⊕ ±e_ij, eigenvalues (a_i ∓ a_j)²): up to four
//!   real solutions (±, ±), none if a right-hand side is negative.
//!   Example U = (k/2)|X|²: g = k a, both right-hand sides equal k: (ω, μ) = (±√k, 0), (0, ±√k)
//!   for every shape — a whole family, and g_k = k a_k ≠ 0 off the plane (a_k = 0 is outside
//!   GL⁺(n)), so a rest shape needs another term ([`super::potential::SaintVenantKirchhoff`], …).

mod admissible;
mod potentials;
mod relative;
mod search;

use crate::check;
use crate::error::{Error, Result};
use crate::lie::{gl, so};
use crate::Mat;

pub use admissible::{equilibrium_directions, equilibrium_residual, Direction};
pub use potentials::{
    amended_gradient, amended_hessian, amended_hessian_matrix, amended_potential,
    amended_velocity_derivative, augmented_gradient, augmented_hessian, augmented_hessian_matrix,
    augmented_potential,
};
pub use relative::{amended_force, force_balance, RelativeEquilibrium, Residuals};
pub use search::{
    equilibria_for_momenta, equilibria_for_shape, equilibria_for_velocities, search_momenta,
    search_velocities, Search,
};

fn check_pair(what: (&str, &str), xi: &Mat, eta: &Mat, n: usize) -> Result<()> {
    so::check_algebra_of(what.0, xi, n)?;
    so::check_algebra_of(what.1, eta, n)
}

fn finite(what: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::NonFinite {
            what: what.into(),
            location: "the result".into(),
        })
    }
}

fn finite_mat(what: &str, m: Mat) -> Result<Mat> {
    check::finite_mat(what, &m)?;
    Ok(m)
}

/// W = ξX − Xη, the vertical velocity of ξ ⊕ η at X (001 (6.19), η skew).
fn vertical(x: &Mat, xi: &Mat, eta: &Mat) -> Mat {
    xi * x - x * eta
}

/// ∂/∂X of ½‖ξX − Xη‖² at fixed ξ ⊕ η: ξᵀW − Wηᵀ = −(ξW − Wη) (module docs).
fn kinetic_gradient(x: &Mat, xi: &Mat, eta: &Mat) -> Mat {
    let w = vertical(x, xi, eta);
    -(xi * &w - &w * eta)
}

fn diag(a: &[f64]) -> Mat {
    Mat::from_fn(a.len(), a.len(), |i, j| if i == j { a[i] } else { 0.0 })
}

/// Checks semi-axes: n ≥ 2, finite, all > 0; returns n.
fn check_axes(a: &[f64]) -> Result<usize> {
    let n = a.len();
    if n < 2 {
        return Err(Error::shape("a", "(n,) with n ≥ 2", format!("({n},)")));
    }
    check::finite_slice("a", a)?;
    if let Some(i) = a.iter().position(|&ai| ai <= 0.0) {
        return Err(Error::invalid(
            "a",
            format!(
                "semi-axes must be > 0 (A = diag(a) ∈ GL⁺(n)), got a[{i}] = {}",
                a[i]
            ),
        ));
    }
    Ok(n)
}

/// Smallest |a_i − a_j| (i ≠ j) and the tolerance [`gl::STRATUM_TOL`]·max a.
fn gap(a: &[f64]) -> (f64, f64) {
    let mut g = f64::INFINITY;
    for i in 0..a.len() {
        for j in i + 1..a.len() {
            g = g.min((a[i] - a[j]).abs());
        }
    }
    (g, gl::STRATUM_TOL * a.iter().copied().fold(0.0, f64::max))
}

fn require_distinct(what: &str, a: &[f64]) -> Result<()> {
    let (g, tol) = gap(a);
    if g <= tol {
        return Err(Error::DegenerateStratum {
            what: format!("{what} at a = {a:?}"),
            gap: g,
            tol,
        });
    }
    Ok(())
}

fn basis(n: usize, i: usize, j: usize) -> Mat {
    Mat::from_fn(n, n, |p, q| {
        if (p, q) == (i, j) {
            1.0
        } else if (p, q) == (j, i) {
            -1.0
        } else {
            0.0
        }
    })
}
