//! ker DF(u): the tangent of the branch, the branch-point test function τ_B = det[DF; tᵀ], and the
//! direction of the other branch at a simple branch point (switching).

use super::{dot, Family, Point};
use crate::error::{Error, Result};
use crate::numerics::linalg::norm;
use crate::Mat;

/// The unit vectors spanning ker DF(u) (the `k` right singular vectors with the smallest
/// singular values), and DF.
fn kernel(family: &dyn Family, u: &[f64], k: usize) -> Result<(Vec<Vec<f64>>, Mat)> {
    let n = u.len();
    let j = family.jacobian(u)?;
    // Pad to N×N with a zero row so that the SVD returns all N right singular vectors.
    let jp = Mat::from_fn(n, n, |r, c| if r + 1 < n { j[(r, c)] } else { 0.0 });
    let svd = jp.svd().map_err(|e| Error::NotConverged {
        what: format!("SVD of the Jacobian of the family ({e:?})"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    })?;
    let v = svd.V();
    Ok((
        (0..k)
            .map(|i| (0..n).map(|r| v[(r, n - 1 - i)]).collect())
            .collect(),
        j,
    ))
}

/// The unit tangent at u oriented along `along` (t·along ≥ 0).
pub(super) fn tangent(family: &dyn Family, u: &[f64], along: &[f64]) -> Result<(Vec<f64>, Mat)> {
    let (mut ker, j) = kernel(family, u, 1)?;
    let mut t = ker.remove(0);
    if dot(&t, along) < 0.0 {
        t.iter_mut().for_each(|x| *x = -*x);
    }
    Ok((t, j))
}

/// det [DF; tᵀ], the branch-point test function.
pub(super) fn branch_test(j: &Mat, t: &[f64]) -> f64 {
    let n = t.len();
    let m = Mat::from_fn(n, n, |r, c| if r + 1 < n { j[(r, c)] } else { t[c] });
    m.determinant()
}

/// The direction of the other branch at a simple branch point: the unit vector of the
/// two-dimensional ker DF(u) orthogonal to the followed branch's tangent (module docs).
///
/// Errors: the kernel is not two-dimensional to working accuracy (the second smallest singular
/// value of DF must be below 1e-6·max(1, ‖DF‖)).
pub fn switch_direction(family: &dyn Family, point: &Point) -> Result<Vec<f64>> {
    let (ker, j) = kernel(family, &point.u, 2)?;
    let n = point.u.len();
    // Singular values, to check that the kernel is two-dimensional.
    let sv = Mat::from_fn(n, n, |r, c| if r + 1 < n { j[(r, c)] } else { 0.0 })
        .singular_values()
        .map_err(|e| Error::NotConverged {
            what: format!("singular values at the branch point ({e:?})"),
            iterations: 0,
            residual: f64::NAN,
            tol: 0.0,
        })?;
    // Relative to max(1, ‖DF‖): at a branch point of a single equation DF vanishes entirely.
    let ratio = sv[n - 2] / sv[0].max(1.0);
    if ratio > 1e-6 {
        return Err(Error::invalid(
            "branch point",
            format!(
                "ker DF is one-dimensional there (second smallest singular value / \
                 max(1, |DF|) = {ratio:.1e}): not a branch point to working accuracy"
            ),
        ));
    }
    // The kernel vector orthogonal to the tangent: project both basis vectors.
    let t = &point.tangent;
    let mut best = Vec::new();
    let mut best_norm = 0.0;
    for v in &ker {
        let c = dot(v, t);
        let w: Vec<f64> = v.iter().zip(t).map(|(a, b)| a - c * b).collect();
        let nw = norm(&w);
        if nw > best_norm {
            best_norm = nw;
            best = w;
        }
    }
    Ok(best.iter().map(|x| x / best_norm).collect())
}
