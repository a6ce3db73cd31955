//! The Cayley map so(n) → SO(n) and its inverse.

use super::{check_algebra, check_rotation};
use crate::error::{Error, Result};
use crate::Mat;
use faer::linalg::solvers::Solve;

/// Cayley map cay(ξ) = (I − ξ/2)⁻¹ (I + ξ/2), so(n) → SO(n), a second-order approximation of
/// exp (cay ξ = exp ξ + O(|ξ|³)). I − ξ/2 is always invertible (eigenvalues 1 − iθ/2).
///
/// Defined for every ξ (its angles 2 atan(θ_j/2) tend to π): both factors are scaled by
/// c = 1/max(1, max |ξ_ij|), cay ξ = (cI − cξ/2)⁻¹ (cI + cξ/2), so the solve sees entries of
/// order one and the result is finite and orthogonal for every finite ξ.
///
/// For n = 3 the closed form of [`crate::lie::so3::cayley`] is used, accurate for every finite ξ. For
/// n ≥ 4 the solve mixes the scales of the rotation planes: with a zero angle (always present
/// for odd n) beside a huge one it loses accuracy like ε·|ξ|², so the result is checked, and a
/// rotation that is not orthogonal to 1e-12 is refused with [`Error::InvalidArgument`] naming the
/// scale (never a NaN or a wrong rotation).
pub fn cayley(xi: &Mat) -> Result<Mat> {
    let n = check_algebra("xi", xi)?;
    if n == 3 {
        let w = nalgebra::Vector3::new(xi[(2, 1)], xi[(0, 2)], xi[(1, 0)]);
        let r = crate::lie::so3::cayley(&w);
        return Ok(Mat::from_fn(3, 3, |i, j| r[(i, j)]));
    }
    let m = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .fold(1.0f64, |m, (i, j)| m.max(xi[(i, j)].abs()));
    let c = 1.0 / m;
    let half = xi * faer::Scale(0.5 * c);
    let minus = Mat::identity(n, n) * faer::Scale(c) - &half;
    let plus = Mat::identity(n, n) * faer::Scale(c) + &half;
    let r = minus.partial_piv_lu().solve(&plus);
    let defect = (r.transpose() * &r - Mat::identity(n, n)).norm_max();
    if defect.is_nan() || defect > 1e-12 {
        return Err(Error::invalid(
            "xi",
            format!(
                "the Cayley map of a ξ with entries up to {} lost its accuracy (orthogonality \
                 defect {}): a zero angle beside a huge one; scale ξ down",
                crate::error::fmt_num(m),
                crate::error::fmt_num(defect)
            ),
        ));
    }
    Ok(r)
}

/// [`cayley_inv`] refuses rotations with σ_min(I + R) below this (an eigenvalue −1 of R, i.e. a
/// rotation angle π, is not in the image of the Cayley map; near it ξ grows like 2 tan(θ/2)).
pub const CAYLEY_TOL: f64 = 1e-8;

/// Inverse Cayley map ξ = 2 (I + R)⁻¹ (R − I), the exact inverse of [`cayley`]
/// (from (I − ξ/2) R = I + ξ/2).
///
/// Errors: `R` not a rotation → [`Error::NotInGroup`]; I + R singular (smallest singular value
/// below [`CAYLEY_TOL`]) → [`Error::InvalidArgument`].
pub fn cayley_inv(r: &Mat) -> Result<Mat> {
    let n = check_rotation("R", r)?;
    let plus = r + Mat::identity(n, n);
    let smin = plus
        .singular_values()
        .map_err(|_| Error::NotConverged {
            what: "SVD of I + R in so::cayley_inv".into(),
            iterations: 0,
            residual: f64::NAN,
            tol: 0.0,
        })?
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    if smin < CAYLEY_TOL {
        return Err(Error::invalid(
            "R",
            format!(
                "I + R is singular (smallest singular value {smin:.3e} < {CAYLEY_TOL:.0e}): R has \
                 an eigenvalue −1 (a rotation by π), outside the image of the Cayley map"
            ),
        ));
    }
    let minus = r - Mat::identity(n, n);
    let xi = plus.partial_piv_lu().solve(&minus) * faer::Scale(2.0);
    Ok((&xi - xi.transpose()) * faer::Scale(0.5))
}
