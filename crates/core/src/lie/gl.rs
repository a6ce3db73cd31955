//! GL⁺(n): real n×n matrices with det X > 0, the configuration space of a generalized
//! pseudo-rigid body (001 (2.1)).
//!
//! - membership ([`check_gl_plus`]),
//! - SVD coordinates X = R A Sᵀ with R, S ∈ SO(n) and A = diag(a₁ ≥ … ≥ aₙ > 0) (001 (2.4)),
//!   computed with faer's SVD and the sign fix of DESIGN.md ([`svd_coordinates`], [`from_svd`]),
//! - the polar decomposition X = R P ([`polar`]),
//! - the stratum of X: which singular values coincide (001 §6.1, (9.2); [`stratum`]).

use crate::check;
use crate::error::{Error, Result};
use crate::lie::so;
use crate::Mat;

/// Default relative tolerance for deciding that two singular values coincide:
/// a_i and a_(i+1) are treated as equal when a_i − a_(i+1) ≤ `STRATUM_TOL` · a₁.
///
/// The same tolerance decides when a function that needs the principal stratum (distinct
/// singular values) refuses X with [`Error::DegenerateStratum`]. Near the threshold those
/// functions are ill-conditioned: the inverse of the bi-inertia tensor has condition number
/// ((a_i + a_j)/(a_i − a_j))², about 4·10¹⁶ at a relative gap of 10⁻⁸.
pub const STRATUM_TOL: f64 = 1e-8;

/// Determinant of a square matrix (faer LU).
pub fn det(x: &Mat) -> f64 {
    x.determinant()
}

/// sign(det X) ∈ {−1, 0, 1} and ln|det X| from an LU factorization with partial pivoting
/// (faer): det X = sign(P) Π u_ii. The log-determinant is finite for every finite nonsingular X
/// of any size and scale (det diag(1, …, 2000) = 2000! ≈ 10⁵⁷³⁵ overflows, its logarithm does
/// not). A zero pivot gives (0, −∞); NaN input gives (NaN, NaN).
pub fn det_sign_ln(x: &Mat) -> (f64, f64) {
    let n = x.nrows();
    if n == 0 {
        return (1.0, 0.0);
    }
    let lu = x.partial_piv_lu();
    let u = lu.U();
    // sign of the row permutation: (−1)^(n − number of cycles).
    let (fwd, _) = lu.P().arrays();
    let mut seen = vec![false; n];
    let mut cycles = 0;
    for i in 0..n {
        if !seen[i] {
            cycles += 1;
            let mut j = i;
            while !seen[j] {
                seen[j] = true;
                j = fwd[j];
            }
        }
    }
    let mut sign = if (n - cycles) % 2 == 0 { 1.0 } else { -1.0 };
    let mut ln = 0.0;
    for i in 0..n {
        let d = u[(i, i)];
        if d.is_nan() {
            return (f64::NAN, f64::NAN);
        }
        if d == 0.0 {
            return (0.0, f64::NEG_INFINITY);
        }
        sign *= d.signum();
        ln += d.abs().ln();
    }
    (sign, ln)
}

/// The one GL⁺(n) membership test: X finite and square (n ≥ 1) with det X > 0, decided on the
/// sign of the LU factorization ([`det_sign_ln`]), never on the product of the pivots (which
/// overflows or underflows for large n or extreme scales although det X > 0 is plain).
///
/// Errors: [`Error::Shape`] if not square, [`Error::NonFinite`] for NaN/inf, and
/// [`Error::NotInGroup`] with the determinant in the message if det X ≤ 0 (numerically: if a
/// pivot is zero or the sign is negative, i.e. also for X singular to working precision).
pub fn check_gl_plus(what: &str, x: &Mat) -> Result<usize> {
    let n = check::square(what, x, 1)?;
    check_det_positive(what, &format!("GL+({n})"), x)?;
    Ok(n)
}

/// The sign test of [`check_gl_plus`] on a finite square `x`, with the group named `group` in the
/// error (e.g. "GL+(3) (the domain of this potential)").
pub fn check_det_positive(what: &str, group: &str, x: &Mat) -> Result<()> {
    let (sign, ln) = det_sign_ln(x);
    if sign.is_nan() || sign <= 0.0 {
        let det = sign * ln.exp();
        let (defect_name, defect) = if det.is_finite() || sign.is_nan() {
            ("det X (must be > 0)".to_string(), det)
        } else {
            (
                format!("sign of det X (|det X| = e^{ln:.6e}, beyond the f64 range; must be > 0)"),
                sign,
            )
        };
        return Err(Error::NotInGroup {
            what: what.into(),
            group: group.into(),
            defect_name,
            defect,
            tol: 0.0,
        });
    }
    Ok(())
}

/// SVD coordinates (R, a, S) of X ∈ GL⁺(n): X = R diag(a) Sᵀ (001 (2.4), S⁻¹ = Sᵀ).
#[derive(Debug, Clone)]
pub struct SvdCoordinates {
    /// R ∈ SO(n) (left singular vectors).
    pub r: Mat,
    /// Singular values a₁ ≥ … ≥ aₙ > 0.
    pub a: Vec<f64>,
    /// S ∈ SO(n) (right singular vectors).
    pub s: Mat,
}

impl SvdCoordinates {
    /// Smallest gap a_i − a_(i+1) between consecutive singular values (+∞ for n = 1).
    pub fn min_gap(&self) -> f64 {
        self.a
            .windows(2)
            .map(|w| w[0] - w[1])
            .fold(f64::INFINITY, f64::min)
    }

    /// Ok if the singular values are distinct to [`STRATUM_TOL`] (relative to a₁), i.e. X lies
    /// on the principal stratum (001 Lemma 2.1, §6.1); otherwise [`Error::DegenerateStratum`]
    /// with the smallest gap, naming `what`.
    pub fn require_principal(&self, what: &str) -> Result<()> {
        let gap = self.min_gap();
        let tol = STRATUM_TOL * self.a[0];
        if gap <= tol {
            return Err(Error::DegenerateStratum {
                what: what.into(),
                gap,
                tol,
            });
        }
        Ok(())
    }

    /// The singular values scaled to a₁ ∈ [1, 2): (ã, c) with a = c·ã and c a power of two
    /// (exact). Formulas homogeneous in a are evaluated on ã and rescaled once at the end, so
    /// that a_i² or a_i⁴ neither overflow nor underflow where the result is representable.
    pub fn unit(&self) -> (Vec<f64>, f64) {
        let c = check::ldexp(1.0, check::pow2_floor(self.a[0]));
        (self.a.iter().map(|&v| v / c).collect(), c)
    }

    /// X = R diag(a) Sᵀ.
    pub fn matrix(&self) -> Mat {
        let n = self.a.len();
        let ra = Mat::from_fn(n, n, |i, j| self.r[(i, j)] * self.a[j]);
        ra * self.s.transpose()
    }
}

/// SVD coordinates of X ∈ GL⁺(n) (001 (2.4)): X = R diag(a) Sᵀ with R, S ∈ SO(n) and
/// a₁ ≥ … ≥ aₙ > 0, from faer's SVD X = U Σ Vᵀ with the sign fix of DESIGN.md: when det U < 0,
/// the last columns of U and V are both flipped (det X > 0 forces det U = det V, so both become
/// rotations and the product is unchanged). On the principal stratum the coordinates are unique
/// up to (R D, S D) with D = diag(±1), det D = 1 (001 (2.5)).
///
/// Errors: shape, non-finite, or det X ≤ 0 ([`check_gl_plus`]).
pub fn svd_coordinates(x: &Mat) -> Result<SvdCoordinates> {
    let n = check_gl_plus("X", x)?;
    // Scale-safe: the SVD of X/c with c a power of two near max |X_ij| (exact, so nothing
    // changes for moderate X), then a = c·ã; faer's SVD fails on entries near 1e160 or 1e-170.
    let c = check::ldexp(1.0, check::pow2_exponent_mat(x));
    let xs = x * faer::Scale(1.0 / c);
    let svd = xs.svd().map_err(|e| Error::NotConverged {
        what: format!("SVD of X ({e:?})"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    })?;
    let mut r = svd.U().to_owned();
    let mut s = svd.V().to_owned();
    let a: Vec<f64> = svd.S().column_vector().iter().map(|&v| v * c).collect();
    // a₁ ≥ max |X_ij| can exceed the f64 range although every entry is finite (entries near
    // 1.8e308): the SVD coordinates are not representable.
    if !a[0].is_finite() {
        return Err(check::overflow_error(
            "X",
            "the largest singular value a₁ of X",
        ));
    }
    if det(&r) < 0.0 {
        for i in 0..n {
            r[(i, n - 1)] = -r[(i, n - 1)];
            s[(i, n - 1)] = -s[(i, n - 1)];
        }
    }
    Ok(SvdCoordinates { r, a, s })
}

/// X = R diag(a) Sᵀ from SVD coordinates (the inverse of [`svd_coordinates`], 001 (2.6)).
///
/// Errors: R, S not n×n rotations ([`check_rotation`](crate::lie::so::check_rotation)), a not of
/// length n, non-finite, or some a_i ≤ 0 ([`Error::InvalidArgument`]). The a_i need not be
/// ordered.
pub fn from_svd(r: &Mat, a: &[f64], s: &Mat) -> Result<Mat> {
    let n = a.len();
    if n == 0 {
        return Err(Error::shape("a", "(n,) with n ≥ 1", "(0,)"));
    }
    check::finite_slice("a", a)?;
    for (what, m) in [("R", r), ("S", s)] {
        so::check_rotation_of(what, m, n)?;
    }
    if let Some(i) = a.iter().position(|&ai| ai <= 0.0) {
        return Err(Error::invalid(
            "a",
            format!("singular values must be > 0, got a[{i}] = {}", a[i]),
        ));
    }
    Ok(SvdCoordinates {
        r: r.clone(),
        a: a.to_vec(),
        s: s.clone(),
    }
    .matrix())
}

/// Polar decomposition X = R P of X ∈ GL⁺(n): R ∈ SO(n) the rotation nearest to X in the
/// Frobenius norm and P = (XᵀX)^{1/2} symmetric positive definite; from the SVD coordinates,
/// R = R_svd S_svdᵀ and P = S_svd A S_svdᵀ. Returns (R, P).
pub fn polar(x: &Mat) -> Result<(Mat, Mat)> {
    let c = svd_coordinates(x)?;
    let n = c.a.len();
    let r = &c.r * c.s.transpose();
    let sa = Mat::from_fn(n, n, |i, j| c.s[(i, j)] * c.a[j]);
    let p = sa * c.s.transpose();
    Ok((r, p))
}

/// The stratum of X ∈ GL⁺(n) under the two-sided SO(n)×SO(n) action (001 §6.1, (9.2)): the
/// pattern of coincidences of the singular values.
#[derive(Debug, Clone, PartialEq)]
pub struct Stratum {
    /// Singular values a₁ ≥ … ≥ aₙ.
    pub a: Vec<f64>,
    /// Multiplicities of the groups of coinciding singular values, from the largest down
    /// (e.g. [1, 2] for a₁ > a₂ = a₃); all ones on the principal stratum.
    pub multiplicities: Vec<usize>,
    /// Smallest gap a_i − a_(i+1) (+∞ for n = 1).
    pub min_gap: f64,
    /// Absolute tolerance used: rel_tol · a₁.
    pub tol: f64,
}

impl Stratum {
    /// True on the principal stratum (all singular values distinct).
    pub fn is_principal(&self) -> bool {
        self.multiplicities.iter().all(|&m| m == 1)
    }
}

/// Classifies X ∈ GL⁺(n) by coincidences of its singular values: a_i and a_(i+1) belong to the
/// same group when a_i − a_(i+1) ≤ `rel_tol` · a₁ (001 §6.1, (9.2)). Use [`STRATUM_TOL`] as
/// the default `rel_tol`.
///
/// `rel_tol` ≥ 1 groups every singular value into one group (every gap is below a₁), so it is
/// clamped to 1: the reported absolute tolerance is min(rel_tol, 1)·a₁, finite for every finite
/// `rel_tol`.
///
/// Errors: as [`svd_coordinates`]; [`Error::InvalidArgument`] if `rel_tol` is negative or not
/// finite.
pub fn stratum(x: &Mat, rel_tol: f64) -> Result<Stratum> {
    if !(rel_tol.is_finite() && rel_tol >= 0.0) {
        return Err(Error::invalid(
            "rel_tol",
            format!(
                "expected a finite number ≥ 0, got {}",
                crate::error::fmt_num(rel_tol)
            ),
        ));
    }
    let c = svd_coordinates(x)?;
    Ok(stratum_of(&c.a, rel_tol))
}

/// [`stratum`] from singular values sorted non-increasingly (`rel_tol` clamped to 1, see
/// [`stratum`]).
pub fn stratum_of(a: &[f64], rel_tol: f64) -> Stratum {
    let tol = rel_tol.min(1.0) * a[0];
    let mut multiplicities = vec![1];
    let mut min_gap = f64::INFINITY;
    for w in a.windows(2) {
        let gap = w[0] - w[1];
        min_gap = min_gap.min(gap);
        if gap <= tol {
            *multiplicities.last_mut().expect("non-empty") += 1;
        } else {
            multiplicities.push(1);
        }
    }
    Stratum {
        a: a.to_vec(),
        multiplicities,
        min_gap,
        tol,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identity_and_errors() {
        let i3 = Mat::identity(3, 3);
        let c = svd_coordinates(&i3).unwrap();
        assert_eq!(c.a, vec![1.0; 3]);
        assert!(c.require_principal("test").is_err());
        let st = stratum(&i3, STRATUM_TOL).unwrap();
        assert_eq!(st.multiplicities, vec![3]);
        let mut neg = Mat::identity(3, 3);
        neg[(0, 0)] = -1.0;
        match svd_coordinates(&neg) {
            Err(Error::NotInGroup { defect, .. }) => assert!((defect + 1.0).abs() < 1e-14),
            other => panic!("expected NotInGroup, got {other:?}"),
        }
        assert!(matches!(
            svd_coordinates(&Mat::zeros(2, 3)),
            Err(Error::Shape { .. })
        ));
        // Large n and small scale: det 10⁻⁴⁰⁰ underflows, the check does not.
        let small = Mat::identity(400, 400) * faer::Scale(0.1);
        assert_eq!(check_gl_plus("X", &small), Ok(400));
    }
}
