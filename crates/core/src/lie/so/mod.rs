//! SO(n) and so(n) for any n ≥ 2 (000 §3, 001 §2).
//!
//! Coordinates on so(n) use the basis e_ij (i < j, +1 at (i, j), −1 at (j, i)) in the order
//! (1,2), (1,3), …, (1,n), (2,3), …, (n−1,n); the pairing ⟨ξ, η⟩ = ½ tr(ξᵀη) = Σ_{i<j} ξ_ij η_ij
//! (001 (2.8)) makes this basis orthonormal.

use crate::check;
use crate::error::{Error, Result};
use crate::lie::MatrixLieGroup;
use crate::Mat;
use nalgebra::{Matrix3, Vector3};

mod cayley;
mod dexp;
mod exp;
mod log;

pub use cayley::{cayley, cayley_inv, CAYLEY_TOL};
pub(crate) use dexp::{bernoulli_coefficients, dexp_series_dense};
pub use dexp::{
    dexp, dexp_derivative, dexp_inv, jacobian_left, jacobian_left_inv, jacobian_right,
    jacobian_right_inv,
};
pub use exp::{exp, exp_into, exp_unchecked, ExpWork};
use log::log_rotation;
pub use log::{log, LOG_PI_TOL};

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

pub use super::SKEW_TOL;

/// Coordinates of a skew-symmetric matrix in the e_ij basis (upper triangle, row by row).
///
/// Errors if `xi` is not square, not finite, or not skew-symmetric to [`SKEW_TOL`] (relative).
pub fn vee_n(xi: &Mat) -> Result<Vec<f64>> {
    check_algebra("xi", xi)?;
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
    let n = xi.nrows();
    if xi.ncols() != n {
        return f64::INFINITY;
    }
    let (mut sym, mut all) = (0.0, 0.0);
    for j in 0..n {
        for i in 0..n {
            let x = xi[(i, j)];
            let d = x + xi[(j, i)];
            sym += d * d;
            all += x * x;
        }
    }
    sym.sqrt() / all.sqrt().max(1.0)
}

/// Lie bracket [ξ, η] = ξη − ηξ. Unchecked (see [`ad`]); never panics: operands of different
/// or non-square shapes give a matrix of NaN.
pub fn bracket(xi: &Mat, eta: &Mat) -> Mat {
    let n = xi.nrows();
    if xi.ncols() != n || eta.nrows() != n || eta.ncols() != n {
        return nan_mat(n, xi.ncols());
    }
    xi * eta - eta * xi
}

/// Pairing ⟨ξ, η⟩ = ½ tr(ξᵀη) on so(n) (001 (2.8)). Unchecked; NaN for operands of different
/// shapes.
pub fn pairing(xi: &Mat, eta: &Mat) -> f64 {
    if xi.nrows() != eta.nrows() || xi.ncols() != eta.ncols() {
        return f64::NAN;
    }
    let mut s = 0.0;
    for j in 0..xi.ncols() {
        for i in 0..xi.nrows() {
            s += xi[(i, j)] * eta[(i, j)];
        }
    }
    0.5 * s
}

// ---------------------------------------------------------------------------------------------
// Validation

/// Checks that `xi` is a finite n×n skew-symmetric matrix with n ≥ 2 (skew to [`SKEW_TOL`],
/// relative); returns n.
pub fn check_algebra(what: &str, xi: &Mat) -> Result<usize> {
    let n = check::square(what, xi, 2)?;
    check_skew(what, xi, n)?;
    Ok(n)
}

/// [`check_algebra`] for a second argument that must have the same size n.
pub fn check_algebra_of(what: &str, xi: &Mat, n: usize) -> Result<()> {
    check::square_of(what, xi, n)?;
    check_skew(what, xi, n)
}

fn check_skew(what: &str, xi: &Mat, n: usize) -> Result<()> {
    let defect = skew_defect(xi);
    if defect > SKEW_TOL {
        return Err(Error::NotInGroup {
            what: what.into(),
            group: format!("so({n})"),
            defect_name: "‖ξ + ξᵀ‖_F / max(1, ‖ξ‖_F)".into(),
            defect,
            tol: SKEW_TOL,
        });
    }
    Ok(())
}

/// Tolerance on the orthogonality defect ‖RᵀR − I‖_F (absolute) for accepting a matrix as a
/// rotation in every function that takes an element of SO(n).
pub const ROTATION_TOL: f64 = 1e-10;

/// Orthogonality defect ‖RᵀR − I‖_F of a square matrix.
pub fn orthogonality_defect(r: &Mat) -> f64 {
    let n = r.ncols();
    let g = r.transpose() * r;
    let mut s = 0.0;
    for j in 0..n {
        for i in 0..n {
            let d = g[(i, j)] - if i == j { 1.0 } else { 0.0 };
            s += d * d;
        }
    }
    s.sqrt()
}

/// Whether `r` is in SO(n): ‖RᵀR − I‖_F ≤ `tol` and det R > 0.
///
/// Errors on a non-square or non-finite `r` and on a `tol` that is not a finite positive number.
pub fn is_rotation(r: &Mat, tol: f64) -> Result<bool> {
    check::square("R", r, 2)?;
    check::positive("tol", tol)?;
    Ok(orthogonality_defect(r) <= tol && r.determinant() > 0.0)
}

/// Checks that `r` is a finite n×n rotation (‖RᵀR − I‖_F ≤ [`ROTATION_TOL`], det R > 0);
/// returns n. The error message carries both the orthogonality defect and the determinant.
pub fn check_rotation(what: &str, r: &Mat) -> Result<usize> {
    let n = check::square(what, r, 2)?;
    rotation_error(what, r, n)?;
    Ok(n)
}

/// [`check_rotation`] for a given size n ≥ 1 (SO(1) = {1} is allowed: the SVD coordinates of
/// GL⁺(1) use it).
pub fn check_rotation_of(what: &str, r: &Mat, n: usize) -> Result<()> {
    check::square_of(what, r, n)?;
    rotation_error(what, r, n)
}

fn rotation_error(what: &str, r: &Mat, n: usize) -> Result<()> {
    let defect = orthogonality_defect(r);
    let det = r.determinant();
    // NaN (an overflow of RᵀR or det R for a huge matrix) is a defect too.
    if defect.is_nan() || defect > ROTATION_TOL || det.is_nan() || det <= 0.0 {
        return Err(Error::NotInGroup {
            what: what.into(),
            group: format!("SO({n})"),
            defect_name: format!("‖RᵀR − I‖_F (det R = {det:.6})"),
            defect,
            tol: ROTATION_TOL,
        });
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// so(3) coordinates

/// The e_ij coordinates c of `so3::hat(w)`: c = (−w3, w2, −w1), so that
/// `hat_n(&so3_to_e_ij(w)) = so3::hat(w)` (DESIGN.md: the physics hat map differs from the e_ij
/// basis at n = 3 in order and sign).
pub fn so3_to_e_ij(w: &Vector3<f64>) -> [f64; 3] {
    [-w.z, w.y, -w.x]
}

/// Inverse of [`so3_to_e_ij`]: w = (−c3, c2, −c1).
pub fn e_ij_to_so3(c: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(-c[2], c[1], -c[0])
}

pub(super) fn to_matrix3(m: &Mat) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[(i, j)])
}

pub(super) fn from_matrix3(m: &Matrix3<f64>) -> Mat {
    Mat::from_fn(3, 3, |i, j| m[(i, j)])
}

pub(super) fn nan_mat(r: usize, c: usize) -> Mat {
    Mat::from_fn(r, c, |_, _| f64::NAN)
}

/// The norm |ξ| = √⟨ξ, ξ⟩ of the pairing (001 (2.8)), i.e. the Euclidean norm of the e_ij
/// coordinates; |ξ|² = Σ θ_j² over the rotation angles θ_j of exp ξ.
pub fn norm(xi: &Mat) -> f64 {
    pairing(xi, xi).sqrt()
}

// ---------------------------------------------------------------------------------------------
// Adjoint and coadjoint actions

/// Adjoint action Ad_g ξ = g ξ gᵀ (= g ξ g⁻¹ on SO(n)).
pub fn adjoint(g: &Mat, xi: &Mat) -> Result<Mat> {
    let n = check_rotation("g", g)?;
    check_algebra_of("xi", xi, n)?;
    Ok(g * xi * g.transpose())
}

/// ad_ξ η = [ξ, η] = ξη − ηξ.
pub fn ad(xi: &Mat, eta: &Mat) -> Result<Mat> {
    let n = check_algebra("xi", xi)?;
    check_algebra_of("eta", eta, n)?;
    Ok(bracket(xi, eta))
}

/// Coadjoint action ad*_ξ μ = [μ, ξ] with so(n)* ≅ so(n) through the pairing ½ tr(ξᵀη)
/// (000 §3.3): from ⟨ad*_ξ μ, η⟩ = ⟨μ, [ξ, η]⟩ = ½ tr(μᵀξη − ξμᵀη) for skew μ, ξ.
pub fn ad_star(xi: &Mat, mu: &Mat) -> Result<Mat> {
    let n = check_algebra("xi", xi)?;
    check_algebra_of("mu", mu, n)?;
    Ok(bracket(mu, xi))
}

// ---------------------------------------------------------------------------------------------
// Casimirs

/// Spectral invariants ½tr((ξᵀξ)^k), k = 1…⌊n/2⌋, of a skew matrix: they determine its
/// coadjoint orbit (the Casimirs of so(n)*).
pub fn spectral_invariants(xi: &Mat) -> Vec<f64> {
    let n = xi.nrows();
    let sym = xi.transpose() * xi;
    let mut pow = sym.clone();
    let mut out = Vec::with_capacity(n / 2);
    for k in 0..n / 2 {
        if k > 0 {
            pow = &pow * &sym;
        }
        out.push(0.5 * (0..n).map(|i| pow[(i, i)]).sum::<f64>());
    }
    out
}

/// The labels of [`spectral_invariants`] of a skew matrix named `symbol` in so(n):
/// "½tr(XᵀX)", "½tr((XᵀX)²)", … (⌊n/2⌋ of them).
pub fn spectral_names(symbol: &str, n: usize) -> Vec<String> {
    const SUPERSCRIPT: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    (1..=n / 2)
        .map(|k| match k {
            1 => format!("½tr({symbol}ᵀ{symbol})"),
            _ => {
                let power: String = k
                    .to_string()
                    .bytes()
                    .map(|d| SUPERSCRIPT[usize::from(d - b'0')])
                    .collect();
                format!("½tr(({symbol}ᵀ{symbol}){power})")
            }
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Projection

/// Nearest rotation to M in the Frobenius norm: R = U D Vᵀ from the SVD M = U Σ Vᵀ with
/// D = diag(1, …, 1, sign det(UVᵀ)) (the sign fix acts on the smallest singular value). For
/// det M > 0 this is the orthogonal polar factor of M. It is unique when the two smallest
/// singular values (of M with det M < 0: the smallest one) are not both zero/tied.
///
/// Scale-free (the nearest rotation to cM is that of M): the SVD is taken of M/c with c a power
/// of two near max |M_ij| ([`check::pow2_exponent_mat`]), so M at 1e300 or 1e-300 is projected
/// like M at 1.
pub fn project_to_so(m: &Mat) -> Result<Mat> {
    check::square("M", m, 2)?;
    let m = check::ldexp_mat(m, -check::pow2_exponent_mat(m));
    let svd = m.svd().map_err(|e| Error::NotConverged {
        what: format!("the SVD of M in so::project_to_so (faer: {e:?})"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    })?;
    let (u, v) = (svd.U(), svd.V());
    let mut r = u * v.transpose();
    if r.determinant() < 0.0 {
        let s = svd.S().column_vector();
        let jmin = (0..s.nrows())
            .min_by(|&a, &b| s[a].total_cmp(&s[b]))
            .unwrap_or(0);
        let n = r.nrows();
        // R − 2 u_j v_jᵀ flips the sign of the j-th singular direction.
        r = Mat::from_fn(n, n, |i, k| r[(i, k)] - 2.0 * u[(i, jmin)] * v[(k, jmin)]);
    }
    Ok(r)
}

// ---------------------------------------------------------------------------------------------
// The group element type

/// An element of SO(n) (n ≥ 2), validated on construction; implements [`MatrixLieGroup`] with
/// the skew matrices as algebra and the e_ij coordinates.
#[derive(Clone, Debug)]
pub struct SOn(Mat);

impl SOn {
    /// Wraps `r` after checking it is a rotation ([`check_rotation`]).
    pub fn new(r: Mat) -> Result<Self> {
        check_rotation("R", &r)?;
        Ok(Self(r))
    }

    /// The identity of SO(n); errors for n < 2.
    pub fn identity(n: usize) -> Result<Self> {
        if n < 2 {
            return Err(Error::invalid("n", format!("SO(n) needs n ≥ 2, got {n}")));
        }
        Ok(Self(Mat::identity(n, n)))
    }

    /// The size n.
    pub fn n(&self) -> usize {
        self.0.nrows()
    }

    /// The rotation matrix.
    pub fn as_mat(&self) -> &Mat {
        &self.0
    }

    /// The rotation matrix, by value.
    pub fn into_mat(self) -> Mat {
        self.0
    }
}

impl MatrixLieGroup for SOn {
    type Algebra = Mat;
    type Point = Vec<f64>;

    fn dim(&self) -> usize {
        dim(self.n())
    }
    fn identity_like(&self) -> Self {
        Self(Mat::identity(self.n(), self.n()))
    }
    fn compose(&self, other: &Self) -> Self {
        Self(&self.0 * &other.0)
    }
    fn inverse(&self) -> Self {
        Self(self.0.transpose().to_owned())
    }
    /// R x (a vector of NaN if x is not of length n).
    fn act(&self, x: &Vec<f64>) -> Vec<f64> {
        let n = self.n();
        if x.len() != n {
            return vec![f64::NAN; n];
        }
        (0..n)
            .map(|i| (0..n).map(|j| self.0[(i, j)] * x[j]).sum())
            .collect()
    }
    /// [`exp`].
    fn exp(xi: &Mat) -> Result<Self> {
        exp(xi).map(Self)
    }
    /// [`exp_unchecked`] (NaN for invalid input).
    fn exp_unchecked(xi: &Mat) -> Self {
        Self(exp_unchecked(xi))
    }
    fn log(&self) -> Result<Mat> {
        log_rotation(&self.0)
    }
    fn adjoint(&self, xi: &Mat) -> Mat {
        &self.0 * xi * self.0.transpose()
    }
    fn ad(xi: &Mat, eta: &Mat) -> Mat {
        bracket(xi, eta)
    }
    fn ad_star(xi: &Mat, mu: &Mat) -> Mat {
        bracket(mu, xi)
    }
    fn pairing(mu: &Mat, xi: &Mat) -> f64 {
        pairing(mu, xi)
    }
    fn matrix(&self) -> Mat {
        self.0.clone()
    }
    fn hat(xi: &Mat) -> Mat {
        xi.clone()
    }
    /// The skew matrix itself, after [`check_algebra`].
    fn vee(m: &Mat) -> Result<Mat> {
        check_algebra("xi", m)?;
        Ok(m.clone())
    }
    fn coords(xi: &Mat) -> Vec<f64> {
        vee_n_unchecked(xi)
    }
    fn algebra_from_coords(&self, c: &[f64]) -> Mat {
        hat_n_unchecked(self.n(), c)
    }
    /// [`jacobian_right`].
    fn jacobian_right(xi: &Mat) -> Result<Mat> {
        jacobian_right(xi)
    }
    /// [`jacobian_left`].
    fn jacobian_left(xi: &Mat) -> Result<Mat> {
        jacobian_left(xi)
    }
    /// [`jacobian_right_inv`].
    fn jacobian_right_inv(xi: &Mat) -> Result<Mat> {
        jacobian_right_inv(xi)
    }
    /// [`jacobian_left_inv`].
    fn jacobian_left_inv(xi: &Mat) -> Result<Mat> {
        jacobian_left_inv(xi)
    }
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
    fn bernoulli_coefficients_match_known_values() {
        // z/(eᶻ − 1) = 1 − z/2 + z²/12 − z⁴/720 + z⁶/30240 − z⁸/1209600 + …
        let b = bernoulli_coefficients();
        let known = [
            1.0,
            -0.5,
            1.0 / 12.0,
            0.0,
            -1.0 / 720.0,
            0.0,
            1.0 / 30240.0,
            0.0,
        ];
        for (k, v) in known.iter().enumerate() {
            assert!((b[k] - v).abs() <= 1e-15 * v.abs(), "b_{k}");
        }
        assert!((b[8] + 1.0 / 1_209_600.0).abs() < 1e-15 / 1_209_600.0);
        // B_10 = 5/66.
        assert!((b[10] - 5.0 / 66.0 / 3_628_800.0).abs() < 1e-15 * b[10]);
    }

    #[test]
    fn vee_rejects_non_skew() {
        let mut m = hat_n(&[1.0, 2.0, 3.0]).unwrap();
        m[(0, 0)] = 0.1;
        assert!(matches!(vee_n(&m), Err(Error::NotInGroup { .. })));
    }
}
