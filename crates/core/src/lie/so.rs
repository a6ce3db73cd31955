//! SO(n) and so(n) for any n ≥ 2 (000 §3, 001 §2).
//!
//! Coordinates on so(n) use the basis e_ij (i < j, +1 at (i, j), −1 at (j, i)) in the order
//! (1,2), (1,3), …, (1,n), (2,3), …, (n−1,n); the pairing ⟨ξ, η⟩ = ½ tr(ξᵀη) = Σ_{i<j} ξ_ij η_ij
//! (001 (2.8)) makes this basis orthonormal.

use crate::check;
use crate::error::{Error, Result};
use crate::Mat;

/// Dimension n(n−1)/2 of so(n).
pub fn dim(n: usize) -> usize {
    n * (n.saturating_sub(1)) / 2
}

/// The n with n(n−1)/2 = `d`, if there is one with n ≥ 2.
pub fn n_from_dim(d: usize) -> Option<usize> {
    let n = ((1.0 + (1.0 + 8.0 * d as f64).sqrt()) / 2.0).round() as usize;
    (n >= 2 && dim(n) == d).then_some(n)
}

/// Skew-symmetric matrix with coordinates `c` in the e_ij basis (the inverse of [`vee_n`]).
pub fn hat_n(c: &[f64]) -> Result<Mat> {
    let n = n_from_dim(c.len()).ok_or_else(|| {
        Error::shape(
            "so(n) coordinates",
            "a vector of length n(n−1)/2 for some n ≥ 2 (1, 3, 6, 10, …)",
            format!("({},)", c.len()),
        )
    })?;
    check::finite_slice("so(n) coordinates", c)?;
    Ok(hat_n_unchecked(n, c))
}

/// [`hat_n`] for a known n and valid `c` (length n(n−1)/2); for inner loops.
pub fn hat_n_unchecked(n: usize, c: &[f64]) -> Mat {
    let mut m = Mat::zeros(n, n);
    let mut k = 0;
    for i in 0..n {
        for j in i + 1..n {
            m[(i, j)] = c[k];
            m[(j, i)] = -c[k];
            k += 1;
        }
    }
    m
}

/// Tolerance on ‖ξ + ξᵀ‖_F / max(1, ‖ξ‖_F) for accepting a matrix as skew-symmetric.
pub const SKEW_TOL: f64 = 1e-10;

/// Coordinates of a skew-symmetric matrix in the e_ij basis (upper triangle, row by row).
///
/// Errors if `xi` is not square, not finite, or not skew-symmetric to [`SKEW_TOL`] (relative).
pub fn vee_n(xi: &Mat) -> Result<Vec<f64>> {
    let n = check::square("xi", xi, 2)?;
    let defect = skew_defect(xi);
    if defect > SKEW_TOL {
        return Err(Error::NotInGroup {
            what: "xi".into(),
            group: format!("so({n})"),
            defect_name: "‖ξ + ξᵀ‖_F / max(1, ‖ξ‖_F)".into(),
            defect,
            tol: SKEW_TOL,
        });
    }
    Ok(vee_n_unchecked(xi))
}

/// [`vee_n`] without checks: reads the upper triangle.
pub fn vee_n_unchecked(xi: &Mat) -> Vec<f64> {
    let n = xi.nrows();
    let mut c = Vec::with_capacity(dim(n));
    for i in 0..n {
        for j in i + 1..n {
            c.push(xi[(i, j)]);
        }
    }
    c
}

/// Relative skew defect ‖ξ + ξᵀ‖_F / max(1, ‖ξ‖_F).
pub fn skew_defect(xi: &Mat) -> f64 {
    let s = xi + xi.transpose();
    s.norm_l2() / xi.norm_l2().max(1.0)
}

/// Lie bracket [ξ, η] = ξη − ηξ.
pub fn bracket(xi: &Mat, eta: &Mat) -> Mat {
    xi * eta - eta * xi
}

/// Pairing ⟨ξ, η⟩ = ½ tr(ξᵀη) on so(n) (001 (2.8)).
pub fn pairing(xi: &Mat, eta: &Mat) -> f64 {
    let mut s = 0.0;
    for j in 0..xi.ncols() {
        for i in 0..xi.nrows() {
            s += xi[(i, j)] * eta[(i, j)];
        }
    }
    0.5 * s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hat_vee_roundtrip_and_basis_order() {
        let c = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let m = hat_n(&c).unwrap();
        assert_eq!(m.nrows(), 4);
        assert_eq!(m[(0, 1)], 1.0);
        assert_eq!(m[(0, 3)], 3.0);
        assert_eq!(m[(1, 2)], 4.0);
        assert_eq!(m[(3, 2)], -6.0);
        assert_eq!(vee_n(&m).unwrap(), c.to_vec());
        assert!(hat_n(&[1.0, 2.0]).is_err());
        assert_eq!(n_from_dim(1), Some(2));
        assert_eq!(n_from_dim(45), Some(10));
        assert_eq!(n_from_dim(0), None);
    }

    #[test]
    fn pairing_is_sum_over_upper_triangle() {
        let a = hat_n(&[1.0, 2.0, 3.0]).unwrap();
        let b = hat_n(&[4.0, 5.0, 6.0]).unwrap();
        assert!((pairing(&a, &b) - 32.0).abs() < 1e-14);
    }

    #[test]
    fn vee_rejects_non_skew() {
        let mut m = hat_n(&[1.0, 2.0, 3.0]).unwrap();
        m[(0, 0)] = 0.1;
        assert!(matches!(vee_n(&m), Err(Error::NotInGroup { .. })));
    }
}
