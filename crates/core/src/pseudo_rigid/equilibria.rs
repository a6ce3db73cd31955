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

use crate::check;
use crate::error::{Error, Result};
use crate::lie::{gl, so};
use crate::numerics::fd::{self, Scheme::Central};
use crate::numerics::linalg::norm;
use crate::pseudo_rigid::inertia::BiInertia;
use crate::pseudo_rigid::momentum::momentum_map_unchecked;
use crate::pseudo_rigid::potential::{self, Potential};
use crate::Mat;
use faer::linalg::solvers::Solve;

// ---------------------------------------------------------------------------------------------
// Augmented and amended potentials

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

/// The augmented potential U_{ξ⊕η}(X) = U(X) − ½⟨ξ ⊕ η, B_X(ξ ⊕ η)⟩ = U(X) − ½‖ξX − Xη‖²
/// (001 (8.12); module docs). ξ, η: skew n×n spatial angular velocities.
///
/// Errors: X not square n ≥ 2 or not finite, det X ≤ 0 for a potential defined on GL⁺(n) only,
/// ξ, η not skew n×n, a non-finite result.
pub fn augmented_potential(pot: &dyn Potential, x: &Mat, xi: &Mat, eta: &Mat) -> Result<f64> {
    let u = potential::value(pot, x)?;
    check_pair(("xi", "eta"), xi, eta, x.nrows())?;
    let w = vertical(x, xi, eta);
    finite("augmented potential", u - 0.5 * w.norm_l2().powi(2))
}

/// ∂U_{ξ⊕η}/∂X = ∂U/∂X + ξW − Wη with W = ξX − Xη (001 (8.12); module docs), the gradient for
/// the pairing tr(AᵀB). It vanishes at X₀ iff e^{tξ}X₀e^{−tη} solves Hamilton's equations.
///
/// Errors as [`augmented_potential`].
pub fn augmented_gradient(pot: &dyn Potential, x: &Mat, xi: &Mat, eta: &Mat) -> Result<Mat> {
    let g = potential::gradient(pot, x)?;
    check_pair(("xi", "eta"), xi, eta, x.nrows())?;
    finite_mat("augmented gradient", g - kinetic_gradient(x, xi, eta))
}

/// The amended potential V_{λ⊕γ}(X) = U(X) + ½⟨λ ⊕ γ, B_X⁻¹(λ ⊕ γ)⟩ (001 (8.11), (8.8)) for
/// spatial momenta λ = L, γ = Γ (skew n×n), with the closed-form B_X⁻¹ of
/// [`BiInertia::solve`] (001 (7.9)).
///
/// Errors: X ∉ GL⁺(n), [`Error::DegenerateStratum`] off the principal stratum (B_X singular),
/// λ, γ not skew n×n, a non-finite result.
pub fn amended_potential(pot: &dyn Potential, x: &Mat, lam: &Mat, gam: &Mat) -> Result<f64> {
    let b = BiInertia::new(x)?;
    let (xi, eta) = b.solve(lam, gam)?;
    let u = potential::value(pot, x)?;
    let k = so::pairing(lam, &xi) + so::pairing(gam, &eta);
    finite("amended potential", u + 0.5 * k)
}

/// ∂V_{λ⊕γ}/∂X (001 (8.11)): with ξ ⊕ η = B_X⁻¹(λ ⊕ γ), the Legendre identity gives
/// ∂U/∂X + ξW − Wη, W = ξX − Xη — the augmented gradient at those velocities (module docs).
///
/// Errors as [`amended_potential`].
pub fn amended_gradient(pot: &dyn Potential, x: &Mat, lam: &Mat, gam: &Mat) -> Result<Mat> {
    let b = BiInertia::new(x)?;
    let (xi, eta) = b.solve(lam, gam)?;
    let g = potential::gradient(pot, x)?;
    finite_mat("amended gradient", g - kinetic_gradient(x, &xi, &eta))
}

// ---------------------------------------------------------------------------------------------
// Hessians of the augmented and amended potentials
//
// Notation: L_X(ξ ⊕ η) = ξX − Xη (the vertical vector, [`super::connection::vertical_vector`]).
// Its adjoint for ⟨ξ ⊕ η, ζ ⊕ θ⟩ = ½tr(ξᵀζ) + ½tr(ηᵀθ) against tr(AᵀY): since tr(ξᵀM) =
// ⟨ξ, M − Mᵀ⟩ for skew ξ, tr((ξX − Xη)ᵀY) = ⟨ξ, YXᵀ − XYᵀ⟩ + ⟨η, YᵀX − XᵀY⟩, so
//
//   L_X*(Y) = (YXᵀ − XYᵀ) ⊕ (YᵀX − XᵀY) = J(X, Y)   (the momentum map, 001 (7.3)),
//
// in e_ij coordinates (L_X*Y)_ξ,ij = (YXᵀ − XYᵀ)_ij, (L_X*Y)_η,ij = (YᵀX − XᵀY)_ij, and
// B_X = L_X* L_X (001 (6.9); [`super::connection::bi_connection`] is B_X⁻¹ L_X*).
// With κ = ξ ⊕ η, W = L_X κ and G(X, κ) = ∂/∂X ½‖L_X κ‖² = ξᵀW − Wηᵀ = −(ξW − Wη) (linear in X):
//
// - augmented (001 (8.12)): G is linear in X, so D²U_κ(X)[V] = D²U(X)[V] − G(V, κ)
//   = D²U(X)[V] + ξW_V − W_Vη, W_V = ξV − Vη.
// - amended (001 (8.11)): ∇V(X) = ∇U(X) − G(X, κ(X)), κ(X) = B_X⁻¹(λ ⊕ γ). Differentiating
//   B_X κ = λ ⊕ γ: Dκ[V] = −B_X⁻¹((D_X B_X)[V] κ), (D_X B_X)[V] κ = L_V*(L_X κ) + L_X*(L_V κ)
//   = J(V, W) + J(X, W_V). With δκ = δξ ⊕ δη = Dκ[V] and W' = L_X δκ,
//   D_κ G(X, κ)[δκ] = −(ξW' − W'η) − (δξW − Wδη), and
//   D²V(X)[V] = D²U(X)[V] − G(V, κ) − D_κ G(X, κ)[Dκ[V]] = D²U_κ(X)[V] − D_κ G(X, κ)[Dκ[V]].
// - the relation: ⟨Y, D_κ G(X, κ)[δκ]⟩ = ⟨δκ, (D_X B_X)[Y] κ⟩ = −⟨δκ, B_X Dκ[Y]⟩, hence for all
//   X on the principal stratum and all Y, V
//
//   ⟨Y, D²V_{λ⊕γ}(X)[V]⟩ = ⟨Y, D²U_κ(X)[V]⟩ + ⟨Dκ[Y], B_X Dκ[V]⟩
//                         = ⟨Y, D²U_κ(X)[V]⟩ + tr((L_X Dκ[Y])ᵀ L_X Dκ[V]):
//
//   the amended Hessian is the augmented one (at κ = B_X⁻¹(λ ⊕ γ)) plus a positive
//   semidefinite term (checked in `tests/equilibria.rs`).

/// D_κ κ(X)[V] = −B_X⁻¹(J(V, W) + J(X, W_V)) at κ = ξ ⊕ η (module notes above).
fn velocity_derivative(b: &BiInertia, xi: &Mat, eta: &Mat, v: &Mat) -> Result<(Mat, Mat)> {
    let x = b.x();
    let w = vertical(x, xi, eta);
    let wv = vertical(v, xi, eta);
    let (l1, g1) = momentum_map_unchecked(v, &w);
    let (l2, g2) = momentum_map_unchecked(x, &wv);
    let (dxi, deta) = b.solve(&(l1 + l2), &(g1 + g2))?;
    Ok((-dxi, -deta))
}

/// The derivative D_κ κ(X)\[V\] of the velocities κ(X) = B_X⁻¹(λ ⊕ γ) at fixed momenta, as the
/// pair (δξ, δη) = −B_X⁻¹(L_V*L_X κ + L_X*L_V κ) (module notes on the Hessians; L_X κ = ξX − Xη,
/// L_X*Y = J(X, Y) = (YXᵀ − XYᵀ) ⊕ (YᵀX − XᵀY)).
///
/// Errors as [`amended_potential`], and V not n×n or not finite.
pub fn amended_velocity_derivative(x: &Mat, lam: &Mat, gam: &Mat, v: &Mat) -> Result<(Mat, Mat)> {
    let b = BiInertia::new(x)?;
    check::square_of("V", v, b.n())?;
    let (xi, eta) = b.solve(lam, gam)?;
    velocity_derivative(&b, &xi, &eta, v)
}

/// D²U_{ξ⊕η}(X)\[V\] = D²U(X)\[V\] − (ξᵀW_V − W_Vηᵀ) = D²U(X)\[V\] + ξW_V − W_Vη with
/// W_V = ξV − Vη (001 (8.12); the kinetic part −½‖ξX − Xη‖² is quadratic in X). The directional
/// Hessian for the pairing tr(AᵀB): d/dε ∂U_{ξ⊕η}/∂X(X + εV) at ε = 0; symmetric.
///
/// Errors as [`augmented_potential`], and V not n×n or not finite.
pub fn augmented_hessian(
    pot: &dyn Potential,
    x: &Mat,
    xi: &Mat,
    eta: &Mat,
    v: &Mat,
) -> Result<Mat> {
    let h = potential::hessian_product(pot, x, v)?;
    check_pair(("xi", "eta"), xi, eta, x.nrows())?;
    finite_mat("augmented Hessian", h - kinetic_gradient(v, xi, eta))
}

/// D²V_{λ⊕γ}(X)\[V\] (001 (8.11)), analytic (module notes on the Hessians): with
/// κ = ξ ⊕ η = B_X⁻¹(λ ⊕ γ), W = ξX − Xη, W_V = ξV − Vη, δξ ⊕ δη = Dκ\[V\]
/// ([`amended_velocity_derivative`]) and W' = δξX − Xδη,
///
/// D²V\[V\] = D²U(X)\[V\] + (ξW_V − W_Vη) + (ξW' − W'η) + (δξW − Wδη)
///        = [`augmented_hessian`] at κ + (ξW' − W'η) + (δξW − Wδη).
///
/// Symmetric, and ⟨Y, D²V\[V\]⟩ = ⟨Y, D²U_κ\[V\]⟩ + ⟨Dκ\[Y\], B_X Dκ\[V\]⟩.
///
/// Errors as [`amended_potential`], and V not n×n or not finite.
pub fn amended_hessian(pot: &dyn Potential, x: &Mat, lam: &Mat, gam: &Mat, v: &Mat) -> Result<Mat> {
    let b = BiInertia::new(x)?;
    let (xi, eta) = b.solve(lam, gam)?;
    let h = potential::hessian_product(pot, x, v)?;
    finite_mat("amended Hessian", h + amended_kinetic(&b, &xi, &eta, v)?)
}

/// The kinetic part of D²V[V] at κ = ξ ⊕ η: −G(V, κ) − D_κG(X, κ)[Dκ[V]].
fn amended_kinetic(b: &BiInertia, xi: &Mat, eta: &Mat, v: &Mat) -> Result<Mat> {
    let x = b.x();
    let w = vertical(x, xi, eta);
    let (dxi, deta) = velocity_derivative(b, xi, eta, v)?;
    let w1 = vertical(x, &dxi, &deta);
    let dg = xi * &w1 - &w1 * eta + &dxi * &w - &w * &deta;
    Ok(dg - kinetic_gradient(v, xi, eta))
}

/// The n²×n² matrix of a linear map on n×n matrices in the row-major vec basis: column i·n + j
/// is f(E_ij) flattened row-major (as [`potential::hessian`]).
fn dense_operator(n: usize, what: &str, mut f: impl FnMut(&Mat) -> Result<Mat>) -> Result<Mat> {
    let m = n.saturating_mul(n);
    check::dense_size(what, m, m)?;
    let mut h = Mat::zeros(m, m);
    let mut e = Mat::zeros(n, n);
    for i in 0..n {
        for j in 0..n {
            e[(i, j)] = 1.0;
            let col = f(&e)?;
            e[(i, j)] = 0.0;
            for p in 0..n {
                for q in 0..n {
                    h[(p * n + q, i * n + j)] = col[(p, q)];
                }
            }
        }
    }
    Ok(h)
}

/// The Hessian of U_{ξ⊕η} (001 (8.12)) as an n²×n² matrix in the row-major vec(X) basis: column
/// i·n + j is [`augmented_hessian`] at V = E_ij flattened row-major. Symmetric.
///
/// Errors as [`augmented_hessian`], and [`Error::InvalidArgument`] when n⁴ exceeds
/// [`check::MAX_DENSE_ENTRIES`].
pub fn augmented_hessian_matrix(pot: &dyn Potential, x: &Mat, xi: &Mat, eta: &Mat) -> Result<Mat> {
    let n = check::square("X", x, 2)?;
    check::dense_size("augmented Hessian", n * n, n * n)?;
    let u = potential::hessian(pot, x)?;
    check_pair(("xi", "eta"), xi, eta, n)?;
    let k = dense_operator(n, "augmented Hessian", |e| Ok(kinetic_gradient(e, xi, eta)))?;
    finite_mat("augmented Hessian", u - k)
}

/// The Hessian of V_{λ⊕γ} (001 (8.11)) as an n²×n² matrix in the row-major vec(X) basis: column
/// i·n + j is [`amended_hessian`] at V = E_ij flattened row-major. Symmetric.
///
/// Errors as [`amended_hessian`], and [`Error::InvalidArgument`] when n⁴ exceeds
/// [`check::MAX_DENSE_ENTRIES`].
pub fn amended_hessian_matrix(pot: &dyn Potential, x: &Mat, lam: &Mat, gam: &Mat) -> Result<Mat> {
    let n = check::square("X", x, 2)?;
    check::dense_size("amended Hessian", n * n, n * n)?;
    let b = BiInertia::new(x)?;
    let (xi, eta) = b.solve(lam, gam)?;
    let u = potential::hessian(pot, x)?;
    let k = dense_operator(n, "amended Hessian", |e| amended_kinetic(&b, &xi, &eta, e))?;
    finite_mat("amended Hessian", u + k)
}

// ---------------------------------------------------------------------------------------------
// Condition (8.6) and its solutions

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

fn norm_pair(x: &Mat, y: &Mat) -> f64 {
    (so::pairing(x, x) + so::pairing(y, y)).sqrt()
}

/// The commutator [κ' ⊕ μ', B_A(κ' ⊕ μ')] = [κ', p_Ω] ⊕ [μ', p_Λ] of 001 (8.6) at A = diag(a).
fn commutator(a: &[f64], xi: &Mat, eta: &Mat) -> Result<(Mat, Mat)> {
    let (p, q) = BiInertia::new(&diag(a))?.apply(xi, eta)?;
    Ok((so::bracket(xi, &p), so::bracket(eta, &q)))
}

/// The norm (pairing of DESIGN.md, summed over both factors) of [κ' ⊕ μ', B_A(κ' ⊕ μ')]
/// (001 (8.6)) at A = diag(a) for body velocities κ' = Ω (`xi_body`), μ' = Λ (`eta_body`). Zero
/// iff the velocities are admissible for a relative equilibrium through A.
///
/// Errors: a not n ≥ 2 positive finite values, Ω, Λ not skew n×n.
pub fn equilibrium_residual(a: &[f64], xi_body: &Mat, eta_body: &Mat) -> Result<f64> {
    let n = check_axes(a)?;
    check_pair(("xi_body", "eta_body"), xi_body, eta_body, n)?;
    let (c1, c2) = commutator(a, xi_body, eta_body)?;
    Ok(norm_pair(&c1, &c2))
}

/// An admissible velocity direction for A = diag(a) (001 (8.15)–(8.18)): ξ ⊕ η = Σ_k e_{i_k j_k} ⊕
/// s_k e_{i_k j_k} over pairwise disjoint planes, an eigenvector of B_A in each plane.
#[derive(Debug, Clone, PartialEq)]
pub struct Direction {
    /// Ω (skew n×n).
    pub xi: Mat,
    /// Λ (skew n×n).
    pub eta: Mat,
    /// The planes (i, j), i < j, 0-based, pairwise disjoint.
    pub planes: Vec<(usize, usize)>,
    /// The sign s_k = ±1 of each plane: e_ij ⊕ s e_ij has eigenvalue (a_i − s a_j)² (001 (8.15)).
    pub signs: Vec<f64>,
    /// The eigenvalue (a_i − s a_j)² of each plane's component.
    pub eigenvalues: Vec<f64>,
    /// A readable description, e.g. "e_12 ⊕ e_12 + e_34 ⊕ −e_34" (1-based indices).
    pub description: String,
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

fn direction(n: usize, a: &[f64], planes: &[(usize, usize, f64)]) -> Result<Direction> {
    let (mut xi, mut eta) = (Mat::zeros(n, n), Mat::zeros(n, n));
    let mut text = Vec::new();
    for &(i, j, s) in planes {
        let e = basis(n, i, j);
        xi += &e;
        eta += &e * faer::Scale(s);
        let sign = if s > 0.0 { "" } else { "−" };
        text.push(format!("e_{0}{1} ⊕ {sign}e_{0}{1}", i + 1, j + 1));
    }
    Ok(Direction {
        xi,
        eta,
        planes: planes.iter().map(|p| (p.0, p.1)).collect(),
        signs: planes.iter().map(|p| p.2).collect(),
        eigenvalues: planes
            .iter()
            .map(|&(i, j, s)| crate::pseudo_rigid::inertia::eigenvalue("a", a[i], a[j], s))
            .collect::<Result<_>>()?,
        description: text.join(" + "),
    })
}

/// The admissible velocity directions for A = diag(a) listed in 001 §8: the eigenvectors
/// e_ij ⊕ ±e_ij of B_A with eigenvalues (a_i ∓ a_j)² (001 (8.15)), then, for n ≥ 4, the sums over
/// two disjoint planes with every sign choice (001 (8.16)–(8.18): eigenvectors with distinct
/// eigenvalues combine when they commute). Each satisfies (8.6) for every a; so does any sum
/// over pairwise disjoint planes and any ω e_ij ⊕ μ e_ij in one plane (module docs).
///
/// Errors: a not n ≥ 2 positive finite values; an overflow error where an eigenvalue
/// (a_i ∓ a_j)² exceeds the f64 range.
pub fn equilibrium_directions(a: &[f64]) -> Result<Vec<Direction>> {
    let n = check_axes(a)?;
    // n(n − 1) directions of two n×n blocks each: refuse what cannot be held
    check::dense_size(
        "a",
        n.saturating_mul(n.saturating_sub(1)),
        n.saturating_mul(2 * n),
    )?;
    let mut planes = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            planes.push((i, j));
        }
    }
    let mut out = Vec::new();
    for &(i, j) in &planes {
        for s in [1.0, -1.0] {
            out.push(direction(n, a, &[(i, j, s)])?);
        }
    }
    for (k, &(i, j)) in planes.iter().enumerate() {
        for &(p, q) in &planes[k + 1..] {
            if p == i || p == j || q == i || q == j {
                continue;
            }
            for s in [1.0, -1.0] {
                for t in [1.0, -1.0] {
                    out.push(direction(n, a, &[(i, j, s), (p, q, t)])?);
                }
            }
        }
    }
    Ok(out)
}

/// The planes (i, j), i < j, on which Ω or Λ has a nonzero entry (relative tolerance 1e-14).
fn support(xi: &Mat, eta: &Mat) -> Vec<(usize, usize)> {
    let n = xi.nrows();
    let scale = xi.norm_l2().max(eta.norm_l2());
    let tol = 1e-14 * scale;
    let mut out = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            if xi[(i, j)].abs() > tol || eta[(i, j)].abs() > tol {
                out.push((i, j));
            }
        }
    }
    out
}

/// Whether the planes are pairwise disjoint (then (8.6) holds for every A).
fn is_matching(planes: &[(usize, usize)]) -> bool {
    let mut seen = std::collections::BTreeSet::new();
    planes
        .iter()
        .all(|&(i, j)| seen.insert(i) && seen.insert(j))
}

// ---------------------------------------------------------------------------------------------
// Relative equilibria

/// The Euclidean norm of the diagonal of `m`, without overflow of the squares (entries beyond
/// 1e154 have a representable norm).
fn diagonal_norm(m: &Mat) -> f64 {
    (0..m.nrows().min(m.ncols())).fold(0.0, |r: f64, k| r.hypot(m[(k, k)]))
}

/// How well a [`RelativeEquilibrium`] satisfies its conditions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Residuals {
    /// ‖∇_a U_{ξ⊕η}‖ (Euclidean norm over k): the force balance in the semi-axes.
    pub force: f64,
    /// The (8.6) residual ‖[Ω ⊕ Λ, B_A(Ω ⊕ Λ)]‖ ([`equilibrium_residual`]).
    pub commutator: f64,
    /// ‖∂U_{ξ⊕η}/∂X(A₀)‖_F = ‖Ẍ + ∂U/∂X‖ at t = 0 along the curve: the full equation of motion
    /// (zero iff both of the above vanish, on the principal stratum).
    pub motion: f64,
}

/// A relative equilibrium through the representative X₀ = A₀ = diag(a) (R₀ = S₀ = I, so body
/// and spatial quantities agree at t = 0): X(t) = e^{tΩ} A₀ e^{−tΛ} (001 (8.2)–(8.3)).
#[derive(Debug, Clone, PartialEq)]
pub struct RelativeEquilibrium {
    /// The semi-axes a (A₀ = diag(a)); any order, all > 0.
    pub a: Vec<f64>,
    /// Body angular velocity Ω = ξ (skew n×n, constant).
    pub xi: Mat,
    /// Body velocity Λ = η of the right action (skew n×n, constant).
    pub eta: Mat,
    /// Angular momentum λ = L = P₀X₀ᵀ − X₀P₀ᵀ = the ξ block of B_A(Ω ⊕ Λ) (001 (7.3), (8.4)).
    pub lam: Mat,
    /// Circulation γ = Γ = P₀ᵀX₀ − X₀ᵀP₀ = the η block of B_A(Ω ⊕ Λ) (001 (7.3), (8.4)).
    pub gam: Mat,
    /// Energy H = ½‖ΩA − AΛ‖² + U(A) (001 (3.22)).
    pub energy: f64,
    /// Residuals of the defining conditions.
    pub residuals: Residuals,
    /// The multiplier p of the incompressibility constraint det X = det A₀ (the force balance
    /// is ∂U_{ξ⊕η}/∂X = p cof X, [`RelativeEquilibrium::incompressible`]); 0 for a compressible
    /// body.
    pub pressure: f64,
}

impl RelativeEquilibrium {
    /// The candidate with body velocities (Ω, Λ) at A₀ = diag(a), with its momenta, energy and
    /// residuals (it is a relative equilibrium iff the residuals vanish; nothing is solved here).
    ///
    /// Errors: a not n ≥ 2 positive finite values, Ω, Λ not skew n×n, U not finite at A₀.
    pub fn from_velocities(pot: &dyn Potential, a: &[f64], xi: &Mat, eta: &Mat) -> Result<Self> {
        let n = check_axes(a)?;
        check_pair(("xi", "eta"), xi, eta, n)?;
        let x0 = diag(a);
        let (lam, gam) = BiInertia::new(&x0)?.apply(xi, eta)?;
        let grad = augmented_gradient(pot, &x0, xi, eta)?;
        let p0 = vertical(&x0, xi, eta);
        let energy = finite(
            "energy",
            0.5 * p0.norm_l2().powi(2) + potential::value(pot, &x0)?,
        )?;
        let residuals = Residuals {
            force: diagonal_norm(&grad),
            commutator: equilibrium_residual(a, xi, eta)?,
            motion: grad.norm_l2(),
        };
        Ok(RelativeEquilibrium {
            a: a.to_vec(),
            xi: xi.clone(),
            eta: eta.clone(),
            lam,
            gam,
            energy,
            residuals,
            pressure: 0.0,
        })
    }

    /// The candidate with body velocities (Ω, Λ) at A₀ = diag(a) for an incompressible body
    /// (holonomic constraint det X = det A₀, [`super::PseudoRigidBody::incompressible`]): the
    /// pressure p is the least-squares multiplier of the force balance ∂U_{ξ⊕η}/∂X(A₀) = p cof A₀
    /// (cof A₀ = diag(∏_{j≠i} a_j) = ∇_a ∏ a_j), and the residuals are those of
    /// ∂U_{ξ⊕η}/∂X − p cof A₀.
    ///
    /// Errors as [`RelativeEquilibrium::from_velocities`].
    pub fn incompressible(pot: &dyn Potential, a: &[f64], xi: &Mat, eta: &Mat) -> Result<Self> {
        let mut re = Self::from_velocities(pot, a, xi, eta)?;
        let n = a.len();
        let cof: Vec<f64> = (0..n)
            .map(|i| (0..n).filter(|&j| j != i).map(|j| a[j]).product())
            .collect();
        let mut grad = augmented_gradient(pot, &diag(a), xi, eta)?;
        let c2: f64 = cof.iter().map(|c| c * c).sum();
        let p = (0..n).map(|k| grad[(k, k)] * cof[k]).sum::<f64>() / c2;
        for k in 0..n {
            grad[(k, k)] -= p * cof[k];
        }
        re.residuals.force = diagonal_norm(&grad);
        re.residuals.motion = grad.norm_l2();
        re.pressure = finite("pressure", p)?;
        Ok(re)
    }

    /// The candidate with body momenta (λ, γ) at A₀ = diag(a): Ω ⊕ Λ = B_A⁻¹(λ ⊕ γ) (001 (7.9)),
    /// then [`RelativeEquilibrium::from_velocities`].
    ///
    /// Errors: as `from_velocities`, and [`Error::DegenerateStratum`] for coincident a_i.
    pub fn from_momenta(pot: &dyn Potential, a: &[f64], lam: &Mat, gam: &Mat) -> Result<Self> {
        let n = check_axes(a)?;
        check_pair(("lam", "gam"), lam, gam, n)?;
        require_distinct("B_A⁻¹ (body velocities from momenta)", a)?;
        let (xi, eta) = BiInertia::new(&diag(a))?.solve(lam, gam)?;
        Self::from_velocities(pot, a, &xi, &eta)
    }

    /// The dimension n.
    pub fn n(&self) -> usize {
        self.a.len()
    }

    /// X₀ = diag(a).
    pub fn x0(&self) -> Mat {
        diag(&self.a)
    }

    /// P₀ = Ẋ(0) = ΩA₀ − A₀Λ.
    pub fn p0(&self) -> Mat {
        vertical(&self.x0(), &self.xi, &self.eta)
    }

    /// (X(t), P(t)) = (e^{tΩ} A₀ e^{−tΛ}, e^{tΩ}(ΩA₀ − A₀Λ) e^{−tΛ}) at the given times
    /// (001 (8.3); R(t) = e^{tΩ}, S(t) = e^{tΛ} solve Ṙ = RΩ, Ṡ = SΛ).
    ///
    /// Errors: a non-finite time or |tΩ|, |tΛ| beyond [`crate::numerics::angle::EXP_MAX_NORM`].
    pub fn motion(&self, times: &[f64]) -> Result<Vec<(Mat, Mat)>> {
        check::finite_slice("times", times)?;
        let (x0, p0) = (self.x0(), self.p0());
        times
            .iter()
            .map(|&t| {
                let r = so::exp(&(&self.xi * faer::Scale(t)))?;
                let s = so::exp(&(&self.eta * faer::Scale(t)))?;
                Ok((&r * &x0 * s.transpose(), &r * &p0 * s.transpose()))
            })
            .collect()
    }
}

/// The force balance F_k = ∂/∂a_k [U(a) − ½‖ΩA − AΛ‖²] = (∂U_{ξ⊕η}/∂X)_kk at A = diag(a) for
/// body velocities (Ω, Λ) (module docs; zero at a relative equilibrium with p_a = 0).
///
/// Errors: as [`RelativeEquilibrium::from_velocities`].
pub fn force_balance(pot: &dyn Potential, a: &[f64], xi: &Mat, eta: &Mat) -> Result<Vec<f64>> {
    let n = check_axes(a)?;
    let g = augmented_gradient(pot, &diag(a), xi, eta)?;
    Ok((0..n).map(|k| g[(k, k)]).collect())
}

/// The amended force ∂/∂a_k [U(a) + K(a; μ, ν)] at fixed body momenta (μ, ν) (001 (8.8)), with
/// the pair formula of [`super::reduced`]: K = Σ_{i<j} ¼((μ_ij + ν_ij)²/(a_i − a_j)² +
/// (μ_ij − ν_ij)²/(a_i + a_j)²), so ∂K/∂a_i gets −½(s²/d₋³ + t²/d₊³) and ∂K/∂a_j gets
/// ½(s²/d₋³ − t²/d₊³) from each pair (s = μ_ij + ν_ij, t = μ_ij − ν_ij, d∓ = a_i ∓ a_j).
/// Equals minus ṗ_a of the reduced vector field.
///
/// Errors: a invalid or with coincident entries ([`Error::DegenerateStratum`]), μ, ν not skew.
pub fn amended_force(pot: &dyn Potential, a: &[f64], lam: &Mat, gam: &Mat) -> Result<Vec<f64>> {
    let n = check_axes(a)?;
    check_pair(("lam", "gam"), lam, gam, n)?;
    require_distinct("amended force", a)?;
    let g = potential::gradient(pot, &diag(a))?;
    let mut f: Vec<f64> = (0..n).map(|k| g[(k, k)]).collect();
    for i in 0..n {
        for j in i + 1..n {
            let (s, t) = (lam[(i, j)] + gam[(i, j)], lam[(i, j)] - gam[(i, j)]);
            let (dm, dp) = (a[i] - a[j], a[i] + a[j]);
            let (qm, qp) = (0.5 * s * s / dm.powi(3), 0.5 * t * t / dp.powi(3));
            f[i] += -qm - qp;
            f[j] += qm - qp;
        }
    }
    check::finite_slice("amended force", &f)?;
    Ok(f)
}

// ---------------------------------------------------------------------------------------------
// Solvers

/// A residual r(a) ∈ R^m and its scale (for the relative tolerance); None where undefined.
type Residual<'a> = dyn Fn(&[f64]) -> Option<(Vec<f64>, f64)> + 'a;

/// Relative tolerance of the solvers: converged when ‖r‖ ≤ TOL·scale.
const TOL: f64 = 1e-11;

/// Central-difference Jacobian of r at a, steps 1e-6·max(|a_k|, 1e-3).
fn jacobian(f: &Residual<'_>, a: &[f64]) -> Option<Mat> {
    let h: Vec<f64> = a.iter().map(|x| 1e-6 * x.abs().max(1e-3)).collect();
    fd::jacobian(&|y| f(y).map(|(r, _)| r).ok_or(()), a, &h, Central).ok()
}

/// Levenberg–Marquardt (Newton for square well-conditioned systems) from `a0`, iterates kept in
/// (0, ∞). Returns the converged point, or None.
fn solve_from(f: &Residual<'_>, a0: &[f64]) -> Option<Vec<f64>> {
    let n = a0.len();
    let mut a = a0.to_vec();
    let (mut r, mut scale) = f(&a)?;
    let m = r.len();
    let mut mu = 1e-8;
    for _ in 0..200 {
        let rn = norm(&r);
        if rn <= TOL * scale.max(f64::MIN_POSITIVE) {
            return Some(a);
        }
        let jac = jacobian(f, &a)?;
        let jtj = jac.transpose() * &jac;
        let rv = Mat::from_fn(m, 1, |i, _| r[i]);
        let jtr = jac.transpose() * &rv;
        let dmax = (0..n).map(|k| jtj[(k, k)]).fold(0.0, f64::max);
        let mut accepted = false;
        for _ in 0..30 {
            let lhs = Mat::from_fn(n, n, |i, j| {
                jtj[(i, j)] + if i == j { mu * dmax.max(1e-300) } else { 0.0 }
            });
            let step = lhs.partial_piv_lu().solve(&jtr);
            let trial: Vec<f64> = (0..n).map(|k| a[k] - step[(k, 0)]).collect();
            let ok = trial.iter().all(|t| t.is_finite() && *t > 0.0);
            if ok {
                if let Some((rt, st)) = f(&trial) {
                    if rt.iter().all(|x| x.is_finite()) && norm(&rt) < rn {
                        a = trial;
                        r = rt;
                        scale = st;
                        mu = (mu / 10.0).max(1e-12);
                        accepted = true;
                        break;
                    }
                }
            }
            mu *= 10.0;
        }
        if !accepted {
            let rn = norm(&r);
            return (rn <= 1e3 * TOL * scale).then_some(a);
        }
    }
    None
}

/// Grid of starts in the box (per axis `m` points, small distinct offsets per axis so that no
/// start has two equal coordinates).
fn grid(n: usize, lo: f64, hi: f64, m: usize) -> Vec<Vec<f64>> {
    let total = m.checked_pow(n as u32).unwrap_or(usize::MAX);
    (0..total)
        .map(|mut idx| {
            (0..n)
                .map(|k| {
                    let g = idx % m;
                    idx /= m;
                    let off = 0.5 + 0.2 * (k as f64 + 1.0) / (n as f64 + 1.0) - 0.1;
                    lo + (hi - lo) * (g as f64 + off) / m as f64
                })
                .collect()
        })
        .collect()
}

fn check_bounds(bounds: (f64, f64), starts: usize, n: usize) -> Result<()> {
    let (lo, hi) = bounds;
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return Err(Error::invalid(
            "bounds",
            format!("expected 0 < lo < hi (finite), got ({lo}, {hi})"),
        ));
    }
    let total = (starts as f64).powi(n as i32);
    if starts == 0 || total > 1e6 {
        return Err(Error::invalid(
            "starts",
            format!("expected 1 ≤ starts with starts^n ≤ 10⁶ (n = {n}), got {starts}"),
        ));
    }
    Ok(())
}

/// The full outcome of [`search_velocities`] / [`search_momenta`].
#[derive(Debug, Clone, PartialEq)]
pub struct Search {
    /// The relative equilibria on the principal stratum (what `equilibria_for_*` returns).
    pub equilibria: Vec<RelativeEquilibrium>,
    /// Semi-axes a of the solutions with coincident entries (gap ≤ 1e-7·bounds.1) found in the
    /// box, deduplicated. B_A is singular there (seed-errata §8), so they carry no
    /// [`RelativeEquilibrium`]; `equilibria_for_*` drop them when principal solutions exist.
    pub coincident: Vec<Vec<f64>>,
}

/// Outcome of the multistart solve.
struct Found {
    principal: Vec<Vec<f64>>,
    coincident: Vec<Vec<f64>>,
}

/// Multistart solve of r(a) = 0 in the box, deduplicated; the family check (a singular
/// Jacobian at a principal solution means a continuum of solutions) is the caller's.
fn multistart(f: &Residual<'_>, n: usize, bounds: (f64, f64), starts: usize) -> Found {
    let (lo, hi) = bounds;
    let slack = 1e-9 * hi;
    let mut found = Found {
        principal: Vec::new(),
        coincident: Vec::new(),
    };
    for a0 in grid(n, lo, hi, starts) {
        let Some(a) = solve_from(f, &a0) else {
            continue;
        };
        if a.iter().any(|&x| x < lo - slack || x > hi + slack) {
            continue;
        }
        let (g, _) = gap(&a);
        let coincident = g <= 1e-7 * hi;
        let list = if coincident {
            &mut found.coincident
        } else {
            &mut found.principal
        };
        let dup = list
            .iter()
            .any(|b| b.iter().zip(&a).all(|(x, y)| (x - y).abs() <= 1e-6 * hi));
        if !dup {
            list.push(a);
        }
    }
    found
}

/// Rejects a continuum of solutions: the Jacobian of r at a solution has a null direction.
fn check_isolated(f: &Residual<'_>, a: &[f64], what: &str) -> Result<()> {
    let jac = jacobian(f, a).ok_or_else(|| Error::NonFinite {
        what: format!("{what}: Jacobian of the equilibrium conditions"),
        location: format!("a = {a:?}"),
    })?;
    let sv = jac.singular_values().map_err(|e| Error::NotConverged {
        what: format!("SVD of the equilibrium Jacobian ({e:?})"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    })?;
    let (smax, smin) = (sv[0], sv[sv.len() - 1]);
    if smin <= 1e-6 * smax.max(f64::MIN_POSITIVE) {
        return Err(Error::invalid(
            what,
            format!(
                "a continuum of relative equilibria passes through a = {a:?}: the Jacobian of the \
                 equilibrium conditions in the semi-axes is singular there (singular values \
                 {sv:?}); the solution is a whole family, not an isolated shape (e.g. U = (k/2)|X|² \
                 with ω² = k: every shape balances)"
            ),
        ));
    }
    Ok(())
}

fn coincident_error(what: &str, found: &Found) -> Error {
    let a = &found.coincident[0];
    let (g, tol) = gap(a);
    Error::DegenerateStratum {
        what: format!(
            "{what} (every solution found in the box has coincident semi-axes, a = {:?}; B_A is \
             singular there and the body velocities are not determined by the motion)",
            found.coincident
        ),
        gap: g,
        tol: tol.max(1e-7 * a.iter().copied().fold(0.0, f64::max)),
    }
}

/// All relative equilibria with the given constant body velocities (Ω, Λ) = (ξ, η) through
/// shapes A = diag(a) in the box bounds.0 ≤ a_k ≤ bounds.1: Newton (Levenberg–Marquardt) on the
/// force balance [`force_balance`] from a grid of `starts`ⁿ points, deduplicated.
///
/// Condition (8.6) first: if the planes carrying Ω and Λ are pairwise disjoint it holds for every
/// shape and only the force balance is solved; otherwise the force balance and the (8.6)
/// commutators are solved together (least squares), and if no shape satisfies them the answer is
/// an [`Error::InvalidArgument`] saying that (8.6) fails.
///
/// Returned: the solutions on the principal stratum (distinct semi-axes; the order of a is the
/// body frame's, so a permutation that keeps (Ω, Λ) — e.g. swapping a_i, a_j for a plane (i, j)
/// motion — is a separate entry). Errors instead of an arbitrary pick:
/// [`Error::DegenerateStratum`] if the only solutions have coincident semi-axes (B_A singular,
/// seed-errata §8); [`Error::InvalidArgument`] naming the family if a solution is not isolated.
/// An empty vector means no relative equilibrium in the box.
///
/// Solutions with coincident semi-axes found **alongside** principal ones are not returned here
/// (B_A is singular there, so they are not [`RelativeEquilibrium`]s with determined velocities);
/// [`search_velocities`] returns them too, as [`Search::coincident`].
pub fn equilibria_for_velocities(
    pot: &dyn Potential,
    xi: &Mat,
    eta: &Mat,
    bounds: (f64, f64),
    starts: usize,
) -> Result<Vec<RelativeEquilibrium>> {
    Ok(search_velocities(pot, xi, eta, bounds, starts)?.equilibria)
}

/// [`equilibria_for_velocities`] with the coincident-axis solutions it drops: the same search,
/// the same errors (an error when only coincident-axis solutions exist), and
/// [`Search::coincident`] listing the shapes with coincident semi-axes found in the box.
pub fn search_velocities(
    pot: &dyn Potential,
    xi: &Mat,
    eta: &Mat,
    bounds: (f64, f64),
    starts: usize,
) -> Result<Search> {
    let n = so::check_algebra("xi", xi)?;
    so::check_algebra_of("eta", eta, n)?;
    check_bounds(bounds, starts, n)?;
    let matched = is_matching(&support(xi, eta));
    let f = |a: &[f64]| -> Option<(Vec<f64>, f64)> {
        let x = diag(a);
        let g = potential::gradient(pot, &x).ok()?;
        let k = kinetic_gradient(&x, xi, eta);
        let scale = g.norm_l2() + k.norm_l2() + f64::MIN_POSITIVE;
        let mut r: Vec<f64> = (0..a.len()).map(|i| g[(i, i)] - k[(i, i)]).collect();
        if !matched {
            let (c1, c2) = commutator(a, xi, eta).ok()?;
            r.extend(so::vee_n_unchecked(&c1));
            r.extend(so::vee_n_unchecked(&c2));
        }
        r.iter().all(|v| v.is_finite()).then_some((r, scale))
    };
    let found = multistart(&f, n, bounds, starts);
    if found.principal.is_empty() && !found.coincident.is_empty() {
        return Err(coincident_error(
            "relative equilibria for these velocities",
            &found,
        ));
    }
    if !matched && found.principal.is_empty() {
        let probe: Vec<f64> = (0..n)
            .map(|k| bounds.0 + (bounds.1 - bounds.0) * (k as f64 + 0.5) / n as f64)
            .collect();
        let res = equilibrium_residual(&probe, xi, eta)?;
        return Err(Error::invalid(
            "velocities (xi, eta)",
            format!(
                "condition 001 (8.6) [Ω ⊕ Λ, B_A(Ω ⊕ Λ)] = 0 fails at every shape in the box \
                 (e.g. residual {res:.3e} at a = {probe:?}): Ω and Λ act in planes {:?} that share \
                 an axis, which needs repeated eigenvalues of B_A",
                support(xi, eta)
                    .iter()
                    .map(|(i, j)| (i + 1, j + 1))
                    .collect::<Vec<_>>()
            ),
        ));
    }
    let mut out = Vec::new();
    for a in &found.principal {
        check_isolated(&f, a, "relative equilibria for these velocities")?;
        out.push(RelativeEquilibrium::from_velocities(pot, a, xi, eta)?);
    }
    Ok(Search {
        equilibria: out,
        coincident: found.coincident,
    })
}

/// Central-difference Hessian norm scale of U in the semi-axes (for tolerances only).
fn stiffness(pot: &dyn Potential, a: &[f64]) -> Result<f64> {
    let n = a.len();
    let mut s: f64 = 0.0;
    let mut y = a.to_vec();
    for k in 0..n {
        let h = 1e-5 * a[k];
        y[k] = a[k] + h;
        let gp = potential::gradient(pot, &diag(&y))?;
        y[k] = a[k] - h;
        let gm = potential::gradient(pot, &diag(&y))?;
        y[k] = a[k];
        for i in 0..n {
            s = s.max(((gp[(i, i)] - gm[(i, i)]) / (2.0 * h)).abs());
        }
    }
    Ok(s)
}

/// All body velocities Ω = ω e_ij, Λ = μ e_ij in one plane (i, j) (0-based, i < j) for which the
/// shape A = diag(a) is a relative equilibrium, solved exactly (module docs): with g = ∂U/∂a,
/// g_k = 0 off the plane and (ω + μ)² = (g_i − g_j)/(a_i − a_j), (ω − μ)² = (g_i + g_j)/(a_i + a_j).
/// Returns every real solution, sign-symmetric ones included (up to four; only ω = μ = 0 when
/// the shape is at rest).
///
/// `incompressible`: the body keeps det X = ∏a (001 §1, the fluid's volume); the pressure p
/// enters as the multiplier, g ↦ g − p·cof A with cof A = diag(∏_{l≠k} a_l), p fixed by the
/// force balance off the plane (least squares when n > 3, then checked), and the results are
/// [`RelativeEquilibrium::incompressible`].
///
/// Errors: [`Error::InvalidArgument`] when the shape cannot rotate in that plane (a force off the
/// plane, or a negative right-hand side), [`Error::DegenerateStratum`] for coincident semi-axes,
/// bad a or plane.
pub fn equilibria_for_shape(
    pot: &dyn Potential,
    a: &[f64],
    plane: (usize, usize),
    incompressible: bool,
) -> Result<Vec<RelativeEquilibrium>> {
    let n = check_axes(a)?;
    let (i, j) = plane;
    if !(i < j && j < n) {
        return Err(Error::invalid(
            "plane",
            format!("expected (i, j) with 0 ≤ i < j < n = {n}, got ({i}, {j})"),
        ));
    }
    require_distinct("relative equilibria for a shape", a)?;
    let mut g: Vec<f64> = {
        let gm = potential::gradient(pot, &diag(a))?;
        (0..n).map(|k| gm[(k, k)]).collect()
    };
    check::finite_slice("∂U/∂a", &g)?;
    if incompressible {
        // The pressure balancing the forces off the plane (least squares), then g − p·cof A.
        let cof: Vec<f64> = (0..n)
            .map(|k| (0..n).filter(|&l| l != k).map(|l| a[l]).product())
            .collect();
        let off: Vec<usize> = (0..n).filter(|&k| k != i && k != j).collect();
        let c2: f64 = off.iter().map(|&k| cof[k] * cof[k]).sum();
        let p = off.iter().map(|&k| g[k] * cof[k]).sum::<f64>() / c2;
        for (gk, ck) in g.iter_mut().zip(&cof) {
            *gk -= p * ck;
        }
    }
    let gmax = g.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let amax = a.iter().copied().fold(0.0, f64::max);
    let tol = 1e-9 * (gmax + stiffness(pot, a)? * amax);
    let name = format!("shape a = {a:?} in plane ({}, {})", i + 1, j + 1);
    if let Some(k) = (0..n).find(|&k| k != i && k != j && g[k].abs() > tol) {
        return Err(Error::invalid(
            "a",
            format!(
                "the {name} cannot rotate in that plane: the force ∂U/∂a_{} = {:.3e} off the plane \
                 is not balanced by any rotation in it",
                k + 1,
                g[k]
            ),
        ));
    }
    let u2 = (g[i] - g[j]) / (a[i] - a[j]);
    let v2 = (g[i] + g[j]) / (a[i] + a[j]);
    let rtol = tol / amax;
    for (val, what) in [(u2, "(ω + μ)²"), (v2, "(ω − μ)²")] {
        if val < -rtol {
            return Err(Error::invalid(
                "a",
                format!(
                    "the {name} cannot rotate in that plane: force balance needs {what} = \
                     {val:.6e} < 0"
                ),
            ));
        }
    }
    let roots = |v: f64| -> Vec<f64> {
        if v <= rtol {
            vec![0.0]
        } else {
            vec![v.sqrt(), -v.sqrt()]
        }
    };
    let mut out = Vec::new();
    for u in roots(u2) {
        for v in roots(v2) {
            let (w, m) = (0.5 * (u + v), 0.5 * (u - v));
            let e = basis(n, i, j);
            let (xi, eta) = (&e * faer::Scale(w), &e * faer::Scale(m));
            out.push(if incompressible {
                RelativeEquilibrium::incompressible(pot, a, &xi, &eta)?
            } else {
                RelativeEquilibrium::from_velocities(pot, a, &xi, &eta)?
            });
        }
    }
    Ok(out)
}

/// All relative equilibria with given body momenta (λ, γ) = (μ, ν) = (p_Ω, p_Λ) at X₀ = diag(a)
/// (R₀ = S₀ = I): critical points a of the amended potential V(a) = U(a) + K(a; μ, ν) (001 (8.8),
/// (8.11), [`amended_force`]) in the box, by Newton from `starts`ⁿ grid points, deduplicated. If
/// the planes of μ and ν are not pairwise disjoint, the commutators [μ, Ω], [ν, Λ] (001 (8.7))
/// are solved together with the force. Errors as [`equilibria_for_velocities`].
///
/// Coincident-axis solutions found alongside principal ones are dropped as in
/// [`equilibria_for_velocities`]; [`search_momenta`] returns them.
pub fn equilibria_for_momenta(
    pot: &dyn Potential,
    lam: &Mat,
    gam: &Mat,
    bounds: (f64, f64),
    starts: usize,
) -> Result<Vec<RelativeEquilibrium>> {
    Ok(search_momenta(pot, lam, gam, bounds, starts)?.equilibria)
}

/// [`equilibria_for_momenta`] with the coincident-axis solutions it drops
/// ([`Search::coincident`]); otherwise identical.
pub fn search_momenta(
    pot: &dyn Potential,
    lam: &Mat,
    gam: &Mat,
    bounds: (f64, f64),
    starts: usize,
) -> Result<Search> {
    let n = so::check_algebra("lam", lam)?;
    so::check_algebra_of("gam", gam, n)?;
    check_bounds(bounds, starts, n)?;
    let matched = is_matching(&support(lam, gam));
    let f = |a: &[f64]| -> Option<(Vec<f64>, f64)> {
        let mut r = amended_force(pot, a, lam, gam).ok()?;
        let g = potential::gradient(pot, &diag(a)).ok()?;
        let scale = g.norm_l2() + norm(&r) + f64::MIN_POSITIVE;
        if !matched {
            let (xi, eta) = BiInertia::new(&diag(a)).ok()?.solve(lam, gam).ok()?;
            r.extend(so::vee_n_unchecked(&so::bracket(lam, &xi)));
            r.extend(so::vee_n_unchecked(&so::bracket(gam, &eta)));
        }
        r.iter().all(|v| v.is_finite()).then_some((r, scale))
    };
    let found = multistart(&f, n, bounds, starts);
    if found.principal.is_empty() && !found.coincident.is_empty() {
        return Err(coincident_error(
            "relative equilibria for these momenta",
            &found,
        ));
    }
    if !matched && found.principal.is_empty() {
        return Err(Error::invalid(
            "momenta (lam, gam)",
            format!(
                "condition 001 (8.7) fails at every shape in the box: μ and ν act in planes {:?} \
                 that share an axis",
                support(lam, gam)
                    .iter()
                    .map(|(i, j)| (i + 1, j + 1))
                    .collect::<Vec<_>>()
            ),
        ));
    }
    let mut out = Vec::new();
    for a in &found.principal {
        check_isolated(&f, a, "relative equilibria for these momenta")?;
        out.push(RelativeEquilibrium::from_momenta(pot, a, lam, gam)?);
    }
    Ok(Search {
        equilibria: out,
        coincident: found.coincident,
    })
}
