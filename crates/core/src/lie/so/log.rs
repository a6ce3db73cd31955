//! The principal logarithm SO(n) → so(n).

use super::exp::orthogonalize;
use super::{check_rotation, norm};
use crate::error::{Error, Result};
use crate::lie::so3;
use crate::Mat;

/// Rotations whose largest angle is within this distance of π are refused by [`log`], for every
/// n (the same tolerance as [`so3::LOG_PI_TOL`]): at π the logarithm is not unique, and within
/// round-off of π a rounding-level change of R decides between the candidates ±θJ. Below it the
/// logarithm is unique and computed to a backward error at round-off (exp(log R) = R); its
/// forward condition number grows like 1/(π − θ), which is the problem's, not the method's.
pub const LOG_PI_TOL: f64 = so3::LOG_PI_TOL;

fn check_angle(what: &str, angle: f64) -> Result<()> {
    let distance = std::f64::consts::PI - angle;
    if distance < LOG_PI_TOL {
        return Err(Error::NoUniqueLog {
            what: what.into(),
            angle,
            distance,
        });
    }
    Ok(())
}

/// Principal logarithm SO(n) → so(n): the ξ with exp ξ = R and all rotation angles in [0, π).
///
/// With C = (R + Rᵀ)/2 = cos √S and A = (R − Rᵀ)/2 = ξ sinc √S (S = ξᵀξ, see [`exp`](super::exp)), C and A
/// commute and ξ = g(C) A with g(cos θ) = θ / sin θ. The method never resolves individual
/// rotation planes, so clustered or equal angles cost nothing (a plane split is ill-conditioned
/// for close angles, the logarithm is not):
///
/// - C = U diag(λ) Uᵀ (symmetric eigendecomposition, ascending λ = cos θ). The eigenvalues are
///   split once, at the midpoint of the widest gap among those in [−3/4, −1/4] (with the window's
///   ends as extra points; a gap of at least 1/(2(n + 1))), into an obtuse block V_o (the m
///   smallest) and an acute block V_a. Each block is an invariant subspace of R known to
///   ε / gap, independent of the clustering inside it.
/// - Acute block (angles below the split, at most 0.77π): ξ_a = g_a(C) A with g_a = θ / sin θ
///   on λ above the split and 0 below. g is smooth there (g(1) = 1, g ≤ 3.7), so g_a(C) is a
///   well-conditioned function of C; near θ = 0 the result keeps the relative accuracy of A.
/// - Obtuse block: −R_o = −V_oᵀ R V_o (m even: −1 eigenvalues and rotation pairs come in pairs)
///   has the acute angles π − θ_k, so η = log(−R_o) = ½{g(−Λ_o), −V_oᵀ A V_o} by the same formula
///   (in the eigenbasis, entrywise). With J the complex structure of the block, η = −Σ (π − θ_k)
///   J_k, so J = −polar(η) (an SVD of the m×m η, made exactly a complex structure by
///   Newton–Schulz steps; m = 2 in closed form) and ξ_o = π J + η. The polar factor is only as
///   accurate as ε / (π − θ) — the forward conditioning of the problem — but its error between
///   planes of equal π − θ commutes with η, so exp(ξ_o) = R_o to round-off. The singular
///   values of η are the π − θ_k: the smallest decides the refusal within [`LOG_PI_TOL`] of π.
///
/// Chosen over inverse scaling and squaring with Padé (Higham's logm) because it works in the
/// real symmetric eigenbasis that the structure provides (one eigendecomposition and two or
/// three n×n products, as the previous plane-by-plane version), is exactly skew, and handles
/// angles near π without square roots of a near −I matrix. n = 2: θ = atan2(R₁₂, R₁₁).
/// n = 3 with tr R ≥ 1: ξ = (θ / |A|) A, θ = atan2(|A|, (tr R − 1)/2).
///
/// Errors: `R` not a finite n×n rotation (‖RᵀR − I‖_F > [`ROTATION_TOL`](super::ROTATION_TOL) or det R ≤ 0) →
/// [`Error::NotInGroup`]; a rotation angle within [`LOG_PI_TOL`] of π → [`Error::NoUniqueLog`]
/// (carrying the angle).
pub fn log(r: &Mat) -> Result<Mat> {
    check_rotation("R", r)?;
    log_rotation(r)
}

/// [`log`] for an R already known to be a (finite, square) rotation.
pub(super) fn log_rotation(r: &Mat) -> Result<Mat> {
    let n = r.nrows();
    let a = (r - r.transpose()) * faer::Scale(0.5);
    match n {
        2 => {
            let angle = a[(0, 1)].atan2(0.5 * (r[(0, 0)] + r[(1, 1)]));
            check_angle("R", angle.abs())?;
            Ok(Mat::from_fn(2, 2, |i, j| match (i, j) {
                (0, 1) => angle,
                (1, 0) => -angle,
                _ => 0.0,
            }))
        }
        3 => {
            let cos = 0.5 * (r[(0, 0)] + r[(1, 1)] + r[(2, 2)] - 1.0);
            if cos < 0.0 {
                return log_spectral(r, &a);
            }
            let s = norm(&a);
            let angle = s.atan2(cos);
            let f = if s > 0.0 { angle / s } else { 1.0 };
            Ok(a * faer::Scale(f))
        }
        _ => log_spectral(r, &a),
    }
}

/// The window of cos θ in which [`log`] splits the spectrum of C into its acute and obtuse
/// blocks (θ from 0.58π to 0.77π).
const LOG_SPLIT_WINDOW: (f64, f64) = (-0.75, -0.25);

/// g(λ) = θ / sin θ at λ = cos θ for the acute range λ ≥ −0.75 (clamped to λ ≤ 1): smooth,
/// g(1) = 1, computed as atan2(s, λ) / s with s = √((1 − λ)(1 + λ)) (both relatively accurate).
fn theta_over_sin(lambda: f64) -> f64 {
    let l = lambda.min(1.0);
    let s = ((1.0 - l) * (1.0 + l)).sqrt();
    if s > 0.0 {
        s.atan2(l) / s
    } else {
        1.0
    }
}

/// The number m of eigenvalues (ascending `lam`) below the midpoint of the widest gap in
/// [`LOG_SPLIT_WINDOW`] (0 when all are above the window's upper end).
fn log_split(lam: &[f64]) -> usize {
    let (lo, hi) = LOG_SPLIT_WINDOW;
    if !lam.first().is_some_and(|&l| l < hi) {
        return 0;
    }
    let (mut best_gap, mut best_m, mut prev) = (-1.0, 0, lo);
    for j in 0..=lam.len() {
        if j < lam.len() && lam[j] < lo {
            continue;
        }
        let next = if j < lam.len() { lam[j].min(hi) } else { hi };
        if next - prev > best_gap {
            (best_gap, best_m) = (next - prev, j);
        }
        if j == lam.len() || lam[j] >= hi {
            break;
        }
        prev = lam[j];
    }
    best_m
}

/// Makes a square matrix exactly skew in place: X ← (X − Xᵀ)/2.
fn skew_in_place(x: &mut Mat) {
    let n = x.nrows();
    for j in 0..n {
        x[(j, j)] = 0.0;
        for i in j + 1..n {
            let v = 0.5 * (x[(i, j)] - x[(j, i)]);
            x[(i, j)] = v;
            x[(j, i)] = -v;
        }
    }
}

/// The spectral logarithm (n ≥ 3; n = 3 only for angles > π/2), see [`log`].
fn log_spectral(r: &Mat, a: &Mat) -> Result<Mat> {
    let n = r.nrows();
    let not_converged = |what: &str| Error::NotConverged {
        what: format!("{what} in so::log"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    };
    let c = Mat::from_fn(n, n, |i, j| 0.5 * (r[(i, j)] + r[(j, i)]));
    let eig = c
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|_| not_converged("symmetric eigendecomposition"))?;
    let (u, lam) = (eig.U(), eig.S().column_vector());
    let lam: Vec<f64> = (0..n).map(|j| lam[j]).collect();
    let m = log_split(&lam);
    if m % 2 == 1 {
        // Unreachable for a rotation to ROTATION_TOL: the pairs of eigenvalues of C agree to
        // ~1e-10, far below the split gap ≥ 1/(2(n + 1)).
        return Err(not_converged("the acute/obtuse split of the spectrum"));
    }
    // Acute block: ξ = U diag(g_a) (Uᵀ A).
    let mut w = u.transpose() * a;
    let obtuse_a = (m > 0).then(|| -(w.subrows(0, m) * u.subcols(0, m)));
    for (i, &l) in lam.iter().enumerate() {
        let g = if i < m { 0.0 } else { theta_over_sin(l) };
        for j in 0..n {
            w[(i, j)] *= g;
        }
    }
    let mut xi = u * &w;
    // Obtuse block: η = log(−R_o) entrywise in the eigenbasis, then ξ_o = π J + η.
    if let Some(an) = obtuse_a {
        let g: Vec<f64> = lam[..m].iter().map(|&l| theta_over_sin(-l)).collect();
        let mut eta = Mat::from_fn(m, m, |k, l| 0.5 * (g[k] + g[l]) * an[(k, l)]);
        skew_in_place(&mut eta);
        let pi = std::f64::consts::PI;
        // The singular values of η are the π − θ_k (η's 2×2 form when m = 2).
        let svd = if m == 2 {
            None
        } else {
            Some(
                eta.svd()
                    .map_err(|_| not_converged("SVD of the obtuse block"))?,
            )
        };
        let sigma_min = match &svd {
            None => eta[(0, 1)].abs(),
            Some(svd) => {
                let s = svd.S().column_vector();
                (0..m).map(|k| s[k]).fold(f64::INFINITY, f64::min)
            }
        };
        check_angle("R", pi - sigma_min)?;
        let xo = match svd {
            None => {
                let x = eta[(0, 1)];
                let t = x - pi.copysign(x);
                Mat::from_fn(2, 2, |k, l| [[0.0, t], [-t, 0.0]][k][l])
            }
            Some(svd) => {
                // The SVD's backward error is relative to ‖η‖, not to each σ: with angles both
                // near and far from π its polar factor UVᵀ has a symmetric part ~ε‖η‖/σ_min.
                // Its skew part commutes with η to round-off; Newton–Schulz steps (odd
                // polynomials in J, so they keep the commutation) make it a complex structure
                // again (J² = −I).
                let mut j = svd.U() * svd.V().transpose();
                skew_in_place(&mut j);
                let mut j = orthogonalize(j);
                skew_in_place(&mut j);
                let mut xo = j * faer::Scale(-pi);
                xo += &eta;
                xo
            }
        };
        let vo = u.subcols(0, m);
        xi += vo * xo * vo.transpose();
    }
    skew_in_place(&mut xi);
    Ok(xi)
}
