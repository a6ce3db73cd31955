//! The augmented potential U_{ξ⊕η} (001 (8.12)) and the amended potential V_{λ⊕γ} (001 (8.8),
//! (8.11)): values, gradients, the derivative of the velocities at fixed momenta, and the
//! Hessians (directional and as n²×n² matrices).

use super::{check_pair, finite, finite_mat, kinetic_gradient, vertical};
use crate::check;
use crate::error::Result;
use crate::lie::so;
use crate::pseudo_rigid::inertia::BiInertia;
use crate::pseudo_rigid::momentum::momentum_map_unchecked;
use crate::pseudo_rigid::potential::{self, Potential};
use crate::Mat;

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
/// Errors: X ∉ GL⁺(n), [`Error::DegenerateStratum`](crate::Error::DegenerateStratum) off the
/// principal stratum (B_X singular), λ, γ not skew n×n, a non-finite result.
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
// Notation: L_X(ξ ⊕ η) = ξX − Xη (the vertical vector, [`crate::pseudo_rigid::connection::vertical_vector`]).
// Its adjoint for ⟨ξ ⊕ η, ζ ⊕ θ⟩ = ½tr(ξᵀζ) + ½tr(ηᵀθ) against tr(AᵀY): since tr(ξᵀM) =
// ⟨ξ, M − Mᵀ⟩ for skew ξ, tr((ξX − Xη)ᵀY) = ⟨ξ, YXᵀ − XYᵀ⟩ + ⟨η, YᵀX − XᵀY⟩, so
//
//   L_X*(Y) = (YXᵀ − XYᵀ) ⊕ (YᵀX − XᵀY) = J(X, Y)   (the momentum map, 001 (7.3)),
//
// in e_ij coordinates (L_X*Y)_ξ,ij = (YXᵀ − XYᵀ)_ij, (L_X*Y)_η,ij = (YᵀX − XᵀY)_ij, and
// B_X = L_X* L_X (001 (6.9); [`crate::pseudo_rigid::connection::bi_connection`] is B_X⁻¹ L_X*).
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
/// Errors as [`augmented_hessian`], and [`Error::InvalidArgument`](crate::Error::InvalidArgument)
/// when n⁴ exceeds [`check::MAX_DENSE_ENTRIES`].
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
/// Errors as [`amended_hessian`], and [`Error::InvalidArgument`](crate::Error::InvalidArgument)
/// when n⁴ exceeds [`check::MAX_DENSE_ENTRIES`].
pub fn amended_hessian_matrix(pot: &dyn Potential, x: &Mat, lam: &Mat, gam: &Mat) -> Result<Mat> {
    let n = check::square("X", x, 2)?;
    check::dense_size("amended Hessian", n * n, n * n)?;
    let b = BiInertia::new(x)?;
    let (xi, eta) = b.solve(lam, gam)?;
    let u = potential::hessian(pot, x)?;
    let k = dense_operator(n, "amended Hessian", |e| amended_kinetic(&b, &xi, &eta, e))?;
    finite_mat("amended Hessian", u + k)
}
