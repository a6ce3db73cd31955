//! Condition 001 (8.6) at A = diag(a): its residual, the admissible velocity directions
//! (eigenvectors of B_A over disjoint planes, 001 (8.15)–(8.18)), and the planes a velocity
//! pair acts in.

use super::{basis, check_axes, check_pair, diag};
use crate::check;
use crate::error::Result;
use crate::lie::so;
use crate::pseudo_rigid::inertia::BiInertia;
use crate::Mat;

fn norm_pair(x: &Mat, y: &Mat) -> f64 {
    (so::pairing(x, x) + so::pairing(y, y)).sqrt()
}

/// The commutator [κ' ⊕ μ', B_A(κ' ⊕ μ')] = [κ', p_Ω] ⊕ [μ', p_Λ] of 001 (8.6) at A = diag(a).
pub(super) fn commutator(a: &[f64], xi: &Mat, eta: &Mat) -> Result<(Mat, Mat)> {
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
pub(super) fn support(xi: &Mat, eta: &Mat) -> Vec<(usize, usize)> {
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
pub(super) fn is_matching(planes: &[(usize, usize)]) -> bool {
    let mut seen = std::collections::BTreeSet::new();
    planes
        .iter()
        .all(|&(i, j)| seen.insert(i) && seen.insert(j))
}
