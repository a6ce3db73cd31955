//! Fixed-size SO(3) and so(3) ≅ R³ on nalgebra types: the fast path of rigid-body loops.
//!
//! Physics hat map (000 §3.3, corrected): hat(w) x = w × x and [hat u, hat v] = hat(u × v).
//! (The seed prints the first row of ŵ as (0, −ω₁, ω₂); the isomorphism property it proves needs
//! (0, −ω₃, ω₂), which is what [`hat`] uses and what the tests check.)
//!
//! The free functions work on `Vector3`/`Matrix3` without allocation. As everywhere in
//! [`crate::lie`], the plain name is checked and returns a `Result` ([`exp`], [`log`], [`vee`], the
//! Jacobians); its `_unchecked` twin ([`exp_unchecked`], [`log_unchecked`], [`vee_unchecked`],
//! [`jacobian_right_unchecked`], [`jacobian_left_unchecked`]) skips the checks for inner loops.
//! [`SO3`] is the validated rotation type that implements [`MatrixLieGroup`] (algebra R³,
//! pairing the dot product, ad_u v = u × v).
//!
//! Relation to the general so(n) coordinates of [`crate::lie::so`] (basis e_ij, i < j, in the
//! order (1,2), (1,3), (2,3)): hat(w) has e_ij coordinates c = (−w₃, w₂, −w₁) ([`to_eij`],
//! [`from_eij`]); the map is an isometry (both pairings are the dot product of the coordinates).

use nalgebra::{Matrix3, Vector3};

use crate::check;
use crate::error::{Error, Result};
use crate::lie::MatrixLieGroup;
use crate::Mat;

/// hat(w) = [[0, −w3, w2], [w3, 0, −w1], [−w2, w1, 0]], so hat(w) x = w × x (000 §3.3, corrected).
#[inline]
pub fn hat(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// Inverse of [`hat`] on skew matrices (reads the skew part, so it is exact on so(3)); no
/// checks (see [`vee`]).
#[inline]
pub fn vee_unchecked(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        0.5 * (m[(2, 1)] - m[(1, 2)]),
        0.5 * (m[(0, 2)] - m[(2, 0)]),
        0.5 * (m[(1, 0)] - m[(0, 1)]),
    )
}

/// Inverse of [`hat`]: `m` finite and skew to [`super::SKEW_TOL`] (relative defect
/// ‖m + mᵀ‖_F / max(1, ‖m‖_F)), else [`Error::NonFinite`] / [`Error::NotInGroup`].
pub fn vee(m: &Matrix3<f64>) -> Result<Vector3<f64>> {
    check::finite_slice("xi", m.as_slice())?;
    let defect = (m + m.transpose()).norm() / m.norm().max(1.0);
    if defect > super::SKEW_TOL {
        return Err(Error::NotInGroup {
            what: "xi".into(),
            group: "so(3)".into(),
            defect_name: "‖ξ + ξᵀ‖_F / max(1, ‖ξ‖_F)".into(),
            defect,
            tol: super::SKEW_TOL,
        });
    }
    Ok(vee_unchecked(m))
}

/// The e_ij coordinates (DESIGN.md, order (1,2), (1,3), (2,3)) of hat(w): c = (−w₃, w₂, −w₁),
/// so that `hat_n(&to_eij(w)) == hat(w)` (`hat_n` of the so(n) module).
#[inline]
pub fn to_eij(w: &Vector3<f64>) -> [f64; 3] {
    [-w.z, w.y, -w.x]
}

/// Inverse of [`to_eij`]: w = (−c₃, c₂, −c₁).
#[inline]
pub fn from_eij(c: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(-c[2], c[1], -c[0])
}

/// Below this θ² the trigonometric coefficients are evaluated by their Taylor series (truncation
/// error O(θ⁸) < 1e-21 relative; the closed forms would lose up to ~1e-16/θ² there).
const SERIES_T2: f64 = 1e-4;

/// The coefficients of Rodrigues' formula and of the Jacobians at θ = |w|, from one `sin_cos` of
/// θ/2 (so 1 − cos θ = 2 sin²(θ/2) has no cancellation).
#[derive(Clone, Copy, Debug)]
struct Coeffs {
    /// θ² = |w|².
    t2: f64,
    /// sin θ / θ.
    a: f64,
    /// (1 − cos θ) / θ².
    b: f64,
    /// (θ − sin θ) / θ³.
    c: f64,
    /// sin(θ/2), cos(θ/2) (zero and one in the series branch).
    half: (f64, f64),
}

impl Coeffs {
    /// NaN coefficients beyond [`super::EXP_MAX_NORM`] (the rule of
    /// [`super::ANGLE_ROUNDING_TOL`]; the checked maps refuse there first).
    #[inline]
    fn new(w: &Vector3<f64>) -> Self {
        let t2 = w.norm_squared();
        if t2.is_nan() || t2 > super::EXP_MAX_NORM * super::EXP_MAX_NORM {
            let nan = f64::NAN;
            return Coeffs {
                t2: nan,
                a: nan,
                b: nan,
                c: nan,
                half: (nan, nan),
            };
        }
        if t2 < SERIES_T2 {
            Coeffs {
                t2,
                a: 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0)),
                b: 0.5 - t2 / 24.0 * (1.0 - t2 / 30.0 * (1.0 - t2 / 56.0)),
                c: 1.0 / 6.0 - t2 / 120.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0)),
                half: (0.0, 1.0),
            }
        } else {
            let t = t2.sqrt();
            let (sh, ch) = (0.5 * t).sin_cos();
            let s = 2.0 * sh * ch;
            Coeffs {
                t2,
                a: s / t,
                b: 2.0 * sh * sh / t2,
                c: (t - s) / (t2 * t),
                half: (sh, ch),
            }
        }
    }

    /// Whether J_l, J_r are singular: θ = 2πk, k ≥ 1, to [`JACOBIAN_INV_TOL`] in sin(θ/2).
    #[inline]
    fn singular(&self) -> bool {
        self.t2 >= SERIES_T2 && self.half.0.abs() < JACOBIAN_INV_TOL
    }

    /// The coefficient γ(θ) = 1/θ² − (1 + cos θ)/(2θ sin θ) = 1/θ² − cot(θ/2)/(2θ) of ŵ² in
    /// J⁻¹ (unbounded where [`Coeffs::singular`]).
    #[inline]
    fn gamma(&self) -> f64 {
        let t2 = self.t2;
        if t2 < SERIES_T2 {
            // cot x = 1/x − x/3 − x³/45 − 2x⁵/945 − …, x = θ/2.
            return 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
        }
        let (sh, ch) = self.half;
        1.0 / t2 - ch / (2.0 * t2.sqrt() * sh)
    }
}

/// ŵ² = w wᵀ − |w|² I, without a matrix product.
#[inline]
fn hat_sq(w: &Vector3<f64>, t2: f64) -> Matrix3<f64> {
    w * w.transpose() - Matrix3::from_diagonal_element(t2)
}

/// Rodrigues' formula exp(ŵ) = I + (sin θ/θ) ŵ + ((1 − cos θ)/θ²) ŵ², θ = |w| (from
/// ŵ³ = −θ² ŵ; checked against an independent matrix exponential in the tests), with Taylor
/// coefficients for θ < 1e-2. One `sin_cos`, no allocation; orthogonal to ~1e-15 for θ up to
/// 1e3 and beyond. No checks: NaN for |w| > [`super::EXP_MAX_NORM`] (see [`exp`]).
#[inline]
pub fn exp_unchecked(w: &Vector3<f64>) -> Matrix3<f64> {
    let k = Coeffs::new(w);
    Matrix3::identity() + hat(w) * k.a + hat_sq(w, k.t2) * k.b
}

/// The checks of the exponential-type maps of so(3): `w` (called `what`) finite
/// ([`Error::NonFinite`]) and |w| ≤ [`super::EXP_MAX_NORM`] (the rule of
/// [`super::ANGLE_ROUNDING_TOL`], [`Error::InvalidArgument`] naming `map`).
pub fn check_exp_arg(what: &str, map: &str, w: &Vector3<f64>) -> Result<()> {
    check::finite_slice(what, w.as_slice())?;
    super::check_exp_norm(what, map, super::scaled_norm(w.iter()))
}

/// Exponential so(3) → SO(3): [`exp_unchecked`] (Rodrigues) with the checks of
/// [`check_exp_arg`].
pub fn exp(w: &Vector3<f64>) -> Result<Matrix3<f64>> {
    check_exp_arg("w", "exp", w)?;
    Ok(exp_unchecked(w))
}

/// exp(ŵ) and J_l(w) together from one `sin_cos` (the SE(3) exponential needs both).
#[inline]
pub(crate) fn exp_and_jacobian_left(w: &Vector3<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
    let k = Coeffs::new(w);
    let (h, h2) = (hat(w), hat_sq(w, k.t2));
    (
        Matrix3::identity() + h * k.a + h2 * k.b,
        Matrix3::identity() + h * k.b + h2 * k.c,
    )
}

/// Rotation angle θ ∈ [0, π] of R, cos θ = (tr R − 1)/2, and s = vee((R − Rᵀ)/2) = sin θ · axis.
/// θ comes from whichever of cos θ, sin θ = |s| is well conditioned: acos where |cos θ| ≤ ½,
/// asin elsewhere (as accurate as atan2, and about twice as fast).
#[inline]
fn angle_cos_sin(r: &Matrix3<f64>) -> (f64, f64, Vector3<f64>) {
    let s = vee_unchecked(r);
    let c = 0.5 * (r.trace() - 1.0);
    let n = s.norm().min(1.0);
    let theta = if c.abs() <= 0.5 {
        c.acos()
    } else if c > 0.0 {
        n.asin()
    } else {
        std::f64::consts::PI - n.asin()
    };
    (theta, c, s)
}

/// Principal logarithm of a rotation: the w with |w| = θ ∈ [0, π] and exp(ŵ) = R.
///
/// θ from cos θ = (tr R − 1)/2 and sin θ = |s| with s = vee((R − Rᵀ)/2) = sin θ · a. For cos θ > 0 the
/// result is (θ / sin θ) s (series near 0). For cos θ ≤ 0 (so near π, where s carries no
/// precision) the axis comes from the symmetric part (R + Rᵀ)/2 − cos θ I = (1 − cos θ) a aᵀ:
/// its column with the largest diagonal entry, normalized, with the sign of s.
///
/// Exactly at θ = π (s = 0) both ±π a are logarithms; this function returns the one whose
/// first nonzero component is positive (the tie rule of the canonical quaternion,
/// [`super::rotations::canonical`]: the logarithm and the quaternion name the same axis).
/// [`log`] refuses angles within [`LOG_PI_TOL`] of π instead. No checks: `r` is assumed to be a rotation (see [`log`]).
pub fn log_unchecked(r: &Matrix3<f64>) -> Vector3<f64> {
    let (theta, c, s) = angle_cos_sin(r);
    if c > 0.0 {
        let t2 = theta * theta;
        let f = if t2 < SERIES_T2 {
            // θ / sin θ = 1 + θ²/6 + 7θ⁴/360 + 31θ⁶/15120 + …
            1.0 + t2 / 6.0 + 7.0 * t2 * t2 / 360.0 + 31.0 * t2 * t2 * t2 / 15120.0
        } else {
            theta / s.norm()
        };
        return s * f;
    }
    // Column i of (R + Rᵀ)/2 − cos θ I, i the largest diagonal entry (≥ (1 − cos θ)/3).
    let i = if r[(0, 0)] >= r[(1, 1)] && r[(0, 0)] >= r[(2, 2)] {
        0
    } else if r[(1, 1)] >= r[(2, 2)] {
        1
    } else {
        2
    };
    let mut axis = Vector3::from_fn(|j, _| {
        if j == i {
            r[(i, i)] - c
        } else {
            0.5 * (r[(j, i)] + r[(i, j)])
        }
    });
    axis /= axis.norm();
    // The sign of sin θ·axis; at θ = π exactly (s = 0) the rule of the canonical quaternion
    // (rotations::canonical): the first nonzero component positive.
    let along = axis.dot(&s);
    let first = axis.iter().copied().find(|&c| c != 0.0).unwrap_or(1.0);
    if along < 0.0 || (along == 0.0 && first < 0.0) {
        axis = -axis;
    }
    axis * theta
}

/// [`log`] refuses rotations whose angle θ has π − θ ≤ `LOG_PI_TOL`: there the two
/// candidate logarithms ±θ a are 2θ apart while a rounding-level change of R (~1e-16 per entry,
/// which moves θ by about as much) decides between them. [`log_unchecked`] always returns one.
pub const LOG_PI_TOL: f64 = 1e-12;

/// Principal logarithm SO(3) → so(3) ([`log_unchecked`]) with checks: `r` a finite rotation
/// ([`check_rotation`]), and [`Error::NoUniqueLog`] when π − θ ≤ [`LOG_PI_TOL`].
pub fn log(r: &Matrix3<f64>) -> Result<Vector3<f64>> {
    check_rotation("R", r)?;
    let theta = angle_cos_sin(r).0;
    let distance = std::f64::consts::PI - theta;
    if distance <= LOG_PI_TOL {
        return Err(Error::NoUniqueLog {
            what: "R".into(),
            angle: theta,
            distance,
        });
    }
    Ok(log_unchecked(r))
}

/// Tolerance on ‖RᵀR − I‖_F and |det R − 1| for accepting a matrix as a rotation.
pub const ROTATION_TOL: f64 = 1e-10;

/// The defects (‖RᵀR − I‖_F, det R) of a candidate rotation.
#[inline]
pub fn rotation_defect(r: &Matrix3<f64>) -> (f64, f64) {
    (
        (r.transpose() * r - Matrix3::identity()).norm(),
        r.determinant(),
    )
}

/// Whether `r` is finite, with ‖RᵀR − I‖_F ≤ `tol` and |det R − 1| ≤ `tol`.
pub fn is_rotation(r: &Matrix3<f64>, tol: f64) -> bool {
    let (o, d) = rotation_defect(r);
    o <= tol && (d - 1.0).abs() <= tol
}

/// The rotation nearest to `m` in the Frobenius norm (polar factor, by nalgebra's SVD):
/// m = U Σ Vᵀ ↦ U diag(1, 1, det(U Vᵀ)) Vᵀ. Unique when rank m ≥ 2 and, if det m < 0, σ₂ > σ₃.
/// Errors on non-finite input.
pub fn project(m: &Matrix3<f64>) -> Result<Matrix3<f64>> {
    check::finite_slice("M", m.as_slice())?;
    // Scale-free: the SVD of M/c, c a power of two near max |M_ij| (M at 1e300 is projected
    // like M at 1).
    let c = check::ldexp(1.0, check::pow2_floor(m.amax()));
    let svd = (m / c).svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return Err(Error::NotConverged {
            what: "the SVD of M in so3::project (nalgebra returned no singular vectors)".into(),
            iterations: 0,
            residual: f64::NAN,
            tol: 0.0,
        });
    };
    let mut d = Matrix3::identity();
    d[(2, 2)] = (u * vt).determinant().signum();
    Ok(u * d * vt)
}

/// The rotation factor U of the polar decomposition R = UH of a matrix near SO(3) (U = [`project`]
/// of R, H = UᵀR symmetric) and its derivative: δU = Uω̂ with (tr H·I − H)ω = (UᵀδR − δRᵀU)^∨.
/// (From UᵀδR = ω̂H + δH, δH symmetric: UᵀδR − δRᵀU = ω̂H + Hω̂ = ((tr H·I − H)ω)^; tr H·I − H
/// has the eigenvalues σ_i + σ_j of pairs of singular values, so it is invertible for rank ≥ 2.)
/// What a Runge–Kutta lift's Jacobian reads an attitude's direction by, since the method leaves
/// SO(3) ([`crate::integrate::tangent`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolarTangent {
    u: Matrix3<f64>,
    /// (tr H·I − H)⁻¹.
    inv: Matrix3<f64>,
}

impl PolarTangent {
    /// The polar factors of `r`; errors as [`project`], and [`Error::NotInGroup`] where
    /// tr H·I − H is singular (rank R < 2).
    pub fn new(r: &Matrix3<f64>) -> Result<Self> {
        let u = project(r)?;
        let x = u.transpose() * r;
        let h = (x + x.transpose()) * 0.5;
        let a = Matrix3::identity() * h.trace() - h;
        let Some(inv) = a.try_inverse().filter(|m| m.iter().all(|v| v.is_finite())) else {
            return Err(Error::NotInGroup {
                what: "R".into(),
                group: "GL(3) of rank ≥ 2 (a polar factor with a derivative)".into(),
                defect_name: "det(tr H·I − H)".into(),
                defect: a.determinant(),
                tol: 0.0,
            });
        };
        Ok(PolarTangent { u, inv })
    }

    /// The rotation factor U.
    pub fn rotation(&self) -> &Matrix3<f64> {
        &self.u
    }

    /// ω of δU = Uω̂ for the variation δR of R.
    pub fn apply(&self, dr: &Matrix3<f64>) -> Vector3<f64> {
        let s = self.u.transpose() * dr;
        let skew = s - s.transpose();
        self.inv * Vector3::new(skew[(2, 1)], skew[(0, 2)], skew[(1, 0)])
    }
}

/// Cayley map cay(w) = (I − ŵ/2)⁻¹ (I + ŵ/2) = I + 4/(4 + |w|²) (ŵ + ŵ²/2).
///
/// Scaling: the ½ makes cay agree with exp to second order (cay(w) = exp(ŵ) + O(|w|³)); cay(w)
/// is the rotation about w/|w| by the angle 2 atan(|w|/2) (eigenvalue (2 + iθ)/(2 − iθ)).
///
/// Defined for every w (the angle tends to π as |w| → ∞); for |w| > 1e100 it is evaluated in
/// the scale-safe form I + 4θ/(4 + θ²) û + 2θ²/(4 + θ²) û² with û = w/θ and θ from
/// [`super::scaled_norm`], so it is finite and a rotation for every finite w.
#[inline]
pub fn cayley(w: &Vector3<f64>) -> Matrix3<f64> {
    let t2 = w.norm_squared();
    if t2 <= 1e200 {
        let f = 4.0 / (4.0 + t2);
        return Matrix3::identity() + (hat(w) + hat_sq(w, t2) * 0.5) * f;
    }
    let t = super::scaled_norm(w.iter());
    let u = w / t;
    let (a, b) = (4.0 / (4.0 / t + t), 2.0 / (4.0 / t / t + 1.0));
    Matrix3::identity() + hat(&u) * a + hat_sq(&u, 1.0) * b
}

/// [`cayley_inv`] errors when 1 + tr R ≤ `CAYLEY_INV_TOL` (a rotation by π, where R + I is
/// singular and cay⁻¹ is undefined).
pub const CAYLEY_INV_TOL: f64 = 1e-12;

/// A rotation I + a ŵ + b ŵ² ([`exp`] or [`cayley`] of w) that acts on vectors by increments:
/// v ↦ v + (b w × (w × v) + a w × v), the increment formed first and added to v once.
///
/// Why: a rotation matrix formed explicitly has its diagonal 1 − b(|w|² − w_i²) rounded to an
/// ulp of 1, so it is orthogonal only to about ε; when the rotation is the same at every step (a
/// steady rotation, a symmetric body) that defect is the same every step and the lengths it
/// should keep (|M|², |q|², RᵀR) drift linearly in the number of steps. In the increment form
/// the coefficients' defect 2b − a² − b²|w|² enters as O(|w|²ε), and the one rounding onto v
/// of an increment that varies from step to step by many of its own ulps is unbiased: the
/// errors random-walk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rodrigues {
    w: Vector3<f64>,
    a: f64,
    b: f64,
}

impl Rodrigues {
    /// exp(ŵ) (NaN beyond [`super::EXP_MAX_NORM`], as [`exp`]).
    #[inline]
    pub fn exp(w: &Vector3<f64>) -> Self {
        let k = Coeffs::new(w);
        Rodrigues {
            w: *w,
            a: k.a,
            b: k.b,
        }
    }

    /// cay(w) = (I − ŵ/2)⁻¹(I + ŵ/2) (as [`cayley`], with its scaled form for huge w).
    #[inline]
    pub fn cayley(w: &Vector3<f64>) -> Self {
        let t2 = w.norm_squared();
        if t2 <= 1e200 {
            let f = 4.0 / (4.0 + t2);
            return Rodrigues {
                w: *w,
                a: f,
                b: 0.5 * f,
            };
        }
        let t = super::scaled_norm(w.iter());
        Rodrigues {
            w: w / t,
            a: 4.0 / (4.0 / t + t),
            b: 2.0 / (4.0 / t / t + 1.0),
        }
    }

    /// The inverse (transposed) rotation.
    #[inline]
    pub fn inverse(&self) -> Self {
        Rodrigues {
            w: -self.w,
            ..*self
        }
    }

    /// (M − I) v, the increment of [`Rodrigues::apply`].
    #[inline]
    pub fn increment(&self, v: &Vector3<f64>) -> Vector3<f64> {
        let wv = self.w.cross(v);
        self.w.cross(&wv) * self.b + wv * self.a
    }

    /// v ↦ M v, as v + (M − I) v.
    #[inline]
    pub fn apply(&self, v: &mut Vector3<f64>) {
        let d = self.increment(v);
        *v += d;
    }

    /// R ↦ R Mᵀ: every row r of R becomes M r.
    #[inline]
    pub fn right_mul_transpose(&self, r: &mut Matrix3<f64>) {
        for i in 0..3 {
            let mut row = Vector3::new(r[(i, 0)], r[(i, 1)], r[(i, 2)]);
            self.apply(&mut row);
            for j in 0..3 {
                r[(i, j)] = row[j];
            }
        }
    }

    /// R ↦ R M: every row r of R becomes Mᵀ r.
    #[inline]
    pub fn right_mul(&self, r: &mut Matrix3<f64>) {
        self.inverse().right_mul_transpose(r);
    }

    /// (M − I) R, the increment of R ↦ M R (every column c of R becomes M c).
    #[inline]
    pub fn left_increment(&self, r: &Matrix3<f64>) -> Matrix3<f64> {
        let mut d = Matrix3::zeros();
        for j in 0..3 {
            d.set_column(j, &self.increment(&r.column(j).into_owned()));
        }
        d
    }
}

/// Inverse Cayley map: ŵ = 2 (R + I)⁻¹ (R − I), in closed form w = 2 vee(R − Rᵀ) / (1 + tr R)
/// (from tr cay(w) = 3 − 4|w|²/(4 + |w|²), i.e. 1 + tr R = 16/(4 + |w|²), and
/// R − Rᵀ = 8/(4 + |w|²) ŵ). Error [`Error::InvalidArgument`] when 1 + tr R ≤ [`CAYLEY_INV_TOL`].
#[inline]
pub fn cayley_inv(r: &Matrix3<f64>) -> Result<Vector3<f64>> {
    let d = 1.0 + r.trace();
    if d.is_nan() || d <= CAYLEY_INV_TOL {
        return Err(Error::invalid(
            "R",
            format!(
                "the inverse Cayley map needs R + I invertible (rotation angle < π): \
                 1 + tr R = {d:.3e} ≤ {CAYLEY_INV_TOL:.0e}"
            ),
        ));
    }
    Ok(vee_unchecked(r) * (4.0 / d))
}

/// Right Jacobian of exp (the right-trivialized differential):
/// J_r(w) = I − ((1 − cos θ)/θ²) ŵ + ((θ − sin θ)/θ³) ŵ², so that
/// exp(w + δ) = exp(w) exp(J_r(w) δ) + O(|δ|²). Standard closed form (not in the seeds; e.g.
/// Solà, Deray, Atchuthan, "A micro Lie theory for state estimation in robotics", 2018, SO(3)
/// appendix); checked against central differences of [`exp`] in the tests.
///
/// No checks: NaN for |w| > [`super::EXP_MAX_NORM`] (see [`jacobian_right`]).
#[inline]
pub fn jacobian_right_unchecked(w: &Vector3<f64>) -> Matrix3<f64> {
    let k = Coeffs::new(w);
    Matrix3::identity() - hat(w) * k.b + hat_sq(w, k.t2) * k.c
}

/// Left Jacobian of exp (the left-trivialized differential, dexp_w):
/// J_l(w) = I + ((1 − cos θ)/θ²) ŵ + ((θ − sin θ)/θ³) ŵ² = J_r(−w) = J_r(w)ᵀ = exp(ŵ) J_r(w),
/// so that exp(w + δ) = exp(J_l(w) δ) exp(w) + O(|δ|²). It is also the V matrix of the SE(3)
/// exponential ([`crate::lie::se3::exp`]).
///
/// No checks: NaN for |w| > [`super::EXP_MAX_NORM`] (see [`jacobian_left`]).
#[inline]
pub fn jacobian_left_unchecked(w: &Vector3<f64>) -> Matrix3<f64> {
    let k = Coeffs::new(w);
    Matrix3::identity() + hat(w) * k.b + hat_sq(w, k.t2) * k.c
}

/// The right Jacobian J_r(w) ([`jacobian_right_unchecked`]) with the checks of
/// [`check_exp_arg`].
pub fn jacobian_right(w: &Vector3<f64>) -> Result<Matrix3<f64>> {
    check_exp_arg("w", "the so(3) Jacobian", w)?;
    Ok(jacobian_right_unchecked(w))
}

/// The left Jacobian J_l(w) ([`jacobian_left_unchecked`]) with the checks of
/// [`check_exp_arg`].
pub fn jacobian_left(w: &Vector3<f64>) -> Result<Matrix3<f64>> {
    check_exp_arg("w", "the so(3) Jacobian", w)?;
    Ok(jacobian_left_unchecked(w))
}

/// The coefficients (θ − sin θ)/θ³, (θ²/2 + cos θ − 1)/θ⁴ and
/// ½ [(θ²/2 + cos θ − 1)/θ⁴ + 3 (θ − sin θ − θ³/6)/θ⁵] of Barfoot's Q at θ² = `t2`: by their
/// Taylor series Σ (−1)ᵏ θ²ᵏ/(2k + j)! below θ = 1 (the closed forms cancel like ε/θ⁵ there;
/// twelve terms leave a truncation error below 1e-30), closed forms above.
pub(crate) fn q_coefficients(t2: f64) -> (f64, f64, f64) {
    if t2 < 1.0 {
        // s[j] = Σ_k (−1)ᵏ θ²ᵏ/(2k + j)! for j = 3, 4, 5.
        let series = |j: u32| {
            let mut fact: f64 = (1..=j).map(f64::from).product();
            let (mut sum, mut pow) = (0.0, 1.0);
            for k in 0..12u32 {
                sum += pow / fact;
                pow *= -t2;
                fact *= f64::from((2 * k + j + 1) * (2 * k + j + 2));
            }
            sum
        };
        let (c1, c2) = (series(3), series(4));
        return (c1, c2, 0.5 * (c2 - 3.0 * series(5)));
    }
    let t = t2.sqrt();
    let (s, c) = t.sin_cos();
    let c2 = (0.5 * t2 + c - 1.0) / (t2 * t2);
    (
        (t - s) / (t2 * t),
        c2,
        0.5 * (c2 + 3.0 * (t - s - t2 * t / 6.0) / (t2 * t2 * t)),
    )
}

/// The derivative of the left Jacobian, DJ_l(ω)\[v\] = Σ_{n,m ≥ 0} ω̂ⁿ v̂ ω̂ᵐ/(n + m + 2)! (the
/// series of J_l = Σ ω̂ⁿ/(n + 1)! differentiated term by term), in closed form: Barfoot's
/// Q(ω, v) (Barfoot, "State Estimation for Robotics", 2017, §7.1.5; ρ = v, φ = ω), the
/// lower-left block of the SE(3) left Jacobian,
/// Q = ½ v̂ + c₁ (ω̂v̂ + v̂ω̂ + ω̂v̂ω̂) + c₂ (ω̂²v̂ + v̂ω̂² − 3 ω̂v̂ω̂) + c₃ (ω̂v̂ω̂² + ω̂²v̂ω̂) with the
/// coefficients of `q_coefficients` (checked against central differences of exp in the tests).
pub fn jacobian_left_derivative(w: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
    let (c1, c2, c3) = q_coefficients(w.norm_squared());
    let (wh, vh) = (hat(w), hat(v));
    let (wv, vw, wvw) = (wh * vh, vh * wh, wh * vh * wh);
    vh * 0.5
        + (wv + vw + wvw) * c1
        + (wh * wv + vw * wh - wvw * 3.0) * c2
        + (wvw * wh + wh * wvw) * c3
}

/// J_r⁻¹ and J_l⁻¹ are singular where sin(θ/2) = 0, θ = 2πk (k ≥ 1); they error when
/// |sin(θ/2)| < `JACOBIAN_INV_TOL` there.
pub const JACOBIAN_INV_TOL: f64 = 1e-12;

/// I + (σ/2) ŵ + γ(θ) ŵ²: J_r⁻¹ for σ = 1, J_l⁻¹ for σ = −1.
#[inline]
fn jacobian_inv(w: &Vector3<f64>, k: &Coeffs, sigma: f64) -> Matrix3<f64> {
    Matrix3::identity() + hat(w) * (0.5 * sigma) + hat_sq(w, k.t2) * k.gamma()
}

fn checked_jacobian_inv(w: &Vector3<f64>, sigma: f64) -> Result<Matrix3<f64>> {
    check_exp_arg("w", "the inverse so(3) Jacobian", w)?;
    let k = Coeffs::new(w);
    if k.singular() {
        return Err(Error::invalid(
            "w",
            format!(
                "the so(3) Jacobian is singular at |w| = 2πk (k ≥ 1); |w| = {:.15}",
                w.norm()
            ),
        ));
    }
    Ok(jacobian_inv(w, &k, sigma))
}

/// J_r⁻¹(w) = I + ½ ŵ + γ(θ) ŵ², γ = 1/θ² − (1 + cos θ)/(2θ sin θ) (series 1/12 + θ²/720 +
/// θ⁴/30240 near 0). Error [`Error::InvalidArgument`] at θ = 2πk, k ≥ 1 (see
/// [`JACOBIAN_INV_TOL`]) and beyond [`super::EXP_MAX_NORM`] ([`check_exp_arg`]).
#[inline]
pub fn jacobian_right_inv(w: &Vector3<f64>) -> Result<Matrix3<f64>> {
    checked_jacobian_inv(w, 1.0)
}

/// J_l⁻¹(w) = I − ½ ŵ + γ(θ) ŵ² = J_r⁻¹(w)ᵀ (γ and errors as in [`jacobian_right_inv`]).
#[inline]
pub fn jacobian_left_inv(w: &Vector3<f64>) -> Result<Matrix3<f64>> {
    checked_jacobian_inv(w, -1.0)
}

/// J_l⁻¹(w) without the singularity check, for |w| ≤ π (outputs of [`log`]), where
/// sin(θ/2) ≥ sin(θ/2)|_{θ=10⁻²} and γ is regular.
#[inline]
pub(crate) fn jacobian_left_inv_principal(w: &Vector3<f64>) -> Matrix3<f64> {
    jacobian_inv(w, &Coeffs::new(w), -1.0)
}

/// Checks that `r` is finite and in SO(3): ‖RᵀR − I‖_F and |det R − 1| at most [`ROTATION_TOL`]
/// (Error::NotInGroup naming the failed measure, or Error::NonFinite).
pub fn check_rotation(what: &str, r: &Matrix3<f64>) -> Result<()> {
    check::finite_slice(what, r.as_slice())?;
    let (o, d) = rotation_defect(r);
    let not_in = |defect_name: &str, defect: f64| Error::NotInGroup {
        what: what.into(),
        group: "SO(3)".into(),
        defect_name: defect_name.into(),
        defect,
        tol: ROTATION_TOL,
    };
    // NaN (an overflow of RᵀR for a huge matrix) is a defect too.
    if o.is_nan() || o > ROTATION_TOL {
        return Err(not_in("‖RᵀR − I‖_F", o));
    }
    if d.is_nan() || (d - 1.0).abs() > ROTATION_TOL {
        return Err(not_in("|det R − 1|", (d - 1.0).abs()));
    }
    Ok(())
}

/// Below this ‖RᵀR − I‖_F a matrix is a rotation to round-off and [`rotation_of`] keeps it.
const ROUNDOFF_DEFECT: f64 = 1e-14;

/// The rotation a matrix within [`ROTATION_TOL`] of SO(3) stands for: `r` itself where it is
/// orthogonal to round-off (‖RᵀR − I‖_F ≤ 1e-14), else the nearest rotation ([`project`]), so
/// that every conversion reads the same rotation to round-off (a matrix 1e-10 off keeps no
/// 1e-10 error in its quaternion, logarithm or angles). Errors: those of [`check_rotation`].
pub fn rotation_of(what: &str, r: &Matrix3<f64>) -> Result<Matrix3<f64>> {
    check_rotation(what, r)?;
    if rotation_defect(r).0 <= ROUNDOFF_DEFECT {
        Ok(*r)
    } else {
        project(r)
    }
}

/// A rotation: a 3×3 matrix R with RᵀR = I and det R = 1 (to [`ROTATION_TOL`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SO3(Matrix3<f64>);

impl SO3 {
    /// Validates `r`: finite ([`Error::NonFinite`]), ‖RᵀR − I‖_F ≤ [`ROTATION_TOL`] and
    /// |det R − 1| ≤ [`ROTATION_TOL`] ([`Error::NotInGroup`] with the measured defect).
    pub fn new(r: Matrix3<f64>) -> Result<Self> {
        Ok(SO3(rotation_of("R", &r)?))
    }

    /// Wraps `r` without checks (for matrices known to be rotations, e.g. outputs of [`exp`]).
    #[inline]
    pub fn new_unchecked(r: Matrix3<f64>) -> Self {
        SO3(r)
    }

    /// The rotation matrix.
    #[inline]
    pub fn matrix3(&self) -> &Matrix3<f64> {
        &self.0
    }

    /// The rotation angle θ ∈ [0, π].
    pub fn angle(&self) -> f64 {
        angle_cos_sin(&self.0).0
    }
}

impl MatrixLieGroup for SO3 {
    type Algebra = Vector3<f64>;
    type Point = Vector3<f64>;

    fn dim(&self) -> usize {
        3
    }

    fn identity_like(&self) -> Self {
        SO3(Matrix3::identity())
    }

    fn compose(&self, other: &Self) -> Self {
        SO3(self.0 * other.0)
    }

    /// R⁻¹ = Rᵀ.
    fn inverse(&self) -> Self {
        SO3(self.0.transpose())
    }

    /// R x.
    fn act(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.0 * x
    }

    /// Rodrigues' formula, [`exp`].
    fn exp(xi: &Vector3<f64>) -> Result<Self> {
        exp(xi).map(SO3)
    }

    /// [`exp_unchecked`].
    fn exp_unchecked(xi: &Vector3<f64>) -> Self {
        SO3(exp_unchecked(xi))
    }

    /// [`log`] (R is already a rotation: only the refusal within [`LOG_PI_TOL`] of π can fail).
    fn log(&self) -> Result<Vector3<f64>> {
        log(&self.0)
    }

    /// Ad_R w = R w (R ŵ Rᵀ = (R w)^).
    fn adjoint(&self, xi: &Vector3<f64>) -> Vector3<f64> {
        self.0 * xi
    }

    /// ad_u v = u × v ([û, v̂] = (u × v)^).
    fn ad(xi: &Vector3<f64>, eta: &Vector3<f64>) -> Vector3<f64> {
        xi.cross(eta)
    }

    /// ad*_ξ μ = μ × ξ: ⟨μ, ξ × η⟩ = ⟨μ × ξ, η⟩ (000 §3.3: ad*_Ω Π = [Π, Ω̂] ≅ Π × Ω).
    fn ad_star(xi: &Vector3<f64>, mu: &Vector3<f64>) -> Vector3<f64> {
        mu.cross(xi)
    }

    /// The dot product (= ½ tr(μ̂ᵀ ξ̂), the so(n) pairing of 001 (2.8)).
    fn pairing(mu: &Vector3<f64>, xi: &Vector3<f64>) -> f64 {
        mu.dot(xi)
    }

    fn matrix(&self) -> Mat {
        super::to_mat(&self.0)
    }

    /// [`hat`].
    fn hat(xi: &Vector3<f64>) -> Mat {
        super::to_mat(&hat(xi))
    }

    /// [`vee`] of a 3×3 matrix.
    fn vee(m: &Mat) -> Result<Vector3<f64>> {
        check::square_of("xi", m, 3)?;
        vee(&Matrix3::from_fn(|i, j| m[(i, j)]))
    }

    fn coords(xi: &Vector3<f64>) -> Vec<f64> {
        vec![xi.x, xi.y, xi.z]
    }

    fn algebra_from_coords(&self, c: &[f64]) -> Vector3<f64> {
        Vector3::new(c[0], c[1], c[2])
    }

    /// [`jacobian_right`].
    fn jacobian_right(xi: &Vector3<f64>) -> Result<Mat> {
        jacobian_right(xi).map(|j| super::to_mat(&j))
    }

    /// [`jacobian_left`].
    fn jacobian_left(xi: &Vector3<f64>) -> Result<Mat> {
        jacobian_left(xi).map(|j| super::to_mat(&j))
    }

    /// [`jacobian_right_inv`].
    fn jacobian_right_inv(xi: &Vector3<f64>) -> Result<Mat> {
        jacobian_right_inv(xi).map(|j| super::to_mat(&j))
    }

    /// [`jacobian_left_inv`].
    fn jacobian_left_inv(xi: &Vector3<f64>) -> Result<Mat> {
        jacobian_left_inv(xi).map(|j| super::to_mat(&j))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series and the closed forms of Q's coefficients agree at the switch θ = 1.
    #[test]
    fn q_coefficients_continuous_at_the_switch() {
        let (below, above) = (q_coefficients(1.0 - f64::EPSILON), q_coefficients(1.0));
        for (a, b) in [(below.0, above.0), (below.1, above.1), (below.2, above.2)] {
            assert!((a - b).abs() < 1e-14 * b.abs(), "{a} vs {b}");
        }
        // θ → 0: 1/6, 1/24, 1/120.
        let zero = q_coefficients(0.0);
        assert_eq!(
            zero,
            (1.0 / 6.0, 1.0 / 24.0, 0.5 * (1.0 / 24.0 - 3.0 / 120.0))
        );
    }

    /// DJ_l(ω)\[v\] against central differences of J_l, below, at and above the series switch.
    #[test]
    fn jacobian_left_derivative_is_the_derivative() {
        let v = Vector3::new(0.3, -1.1, 0.7);
        for w in [
            Vector3::new(1e-3, -2e-3, 5e-4),
            Vector3::new(0.4, 0.5, -0.6),
            Vector3::new(1.5, -2.0, 0.8),
        ] {
            let h = 1e-6;
            let fd = (jacobian_left_unchecked(&(w + v * h))
                - jacobian_left_unchecked(&(w - v * h)))
                / (2.0 * h);
            let err = (jacobian_left_derivative(&w, &v) - fd).abs().max();
            assert!(err < 1e-9, "|ω| = {}: {err:e}", w.norm());
        }
    }

    #[test]
    fn hat_is_cross_product() {
        let u = Vector3::new(0.3, -1.2, 2.0);
        let v = Vector3::new(-0.7, 0.4, 1.1);
        assert!((hat(&u) * v - u.cross(&v)).norm() < 1e-15);
        assert_eq!(vee(&hat(&u)).unwrap(), u);
    }

    #[test]
    fn exp_rotates_about_axis() {
        let r = exp_unchecked(&Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
        let w = Vector3::new(1e-6, -2e-6, 3e-7);
        let r = exp_unchecked(&w);
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-15);
    }

    #[test]
    fn series_and_closed_form_agree_at_the_switch() {
        // Just below the switch the series is used; compare with the closed forms there.
        let t = SERIES_T2.sqrt() * (1.0 - 1e-9);
        let k = Coeffs::new(&Vector3::new(0.0, t, 0.0));
        let (s, c) = t.sin_cos();
        let h = 0.5 * t;
        assert!((k.a - s / t).abs() < 1e-15);
        assert!((k.b - 2.0 * h.sin().powi(2) / (t * t)).abs() < 1e-15);
        assert!((k.c - (t - s) / t.powi(3)).abs() < 1e-10);
        let gamma = 1.0 / (t * t) - (1.0 + c) / (2.0 * t * s);
        assert!((k.gamma() - gamma).abs() < 1e-10);
    }

    /// The increments of [`Rodrigues`] are exp(ŵ) and cay(w) acting on vectors and on the rows of
    /// R, at small and large angles (and the scaled Cayley branch).
    #[test]
    fn rodrigues_acts_as_the_matrices() {
        let v = Vector3::new(0.3, -1.2, 0.7);
        let r = exp_unchecked(&Vector3::new(0.4, -0.2, 0.1));
        for w in [
            Vector3::new(1e-5, -2e-5, 3e-6),
            Vector3::new(0.01, 0.02, -0.03),
            Vector3::new(0.8, -1.1, 2.0),
            Vector3::new(1e101, -2e101, 3e100),
        ] {
            for (rot, m) in [
                (Rodrigues::exp(&w), exp_unchecked(&w)),
                (Rodrigues::cayley(&w), cayley(&w)),
            ] {
                if !m[(0, 0)].is_finite() {
                    continue;
                }
                let mut x = v;
                rot.apply(&mut x);
                assert!((x - m * v).norm() < 4e-16 * v.norm(), "{w:?}");
                let mut rr = r;
                rot.right_mul(&mut rr);
                assert!((rr - r * m).norm() < 1e-15, "{w:?}");
                let mut rr = r;
                rot.right_mul_transpose(&mut rr);
                assert!((rr - r * m.transpose()).norm() < 1e-15, "{w:?}");
                let mut y = x;
                rot.inverse().apply(&mut y);
                assert!((y - v).norm() < 1e-15 * v.norm(), "{w:?}");
            }
        }
    }

    /// The identity ω̂H + Hω̂ = ((tr H·I − H)ω)^ for symmetric H, and δU = Uω̂ of
    /// [`PolarTangent`] against central differences of the polar factor (ω from
    /// log(U₋ᵀU₊)/2h), near SO(3) (a Runge–Kutta attitude) and far from it.
    #[test]
    fn polar_tangent_is_the_polar_factors_derivative() {
        let h = Matrix3::new(1.3, 0.2, -0.1, 0.2, 0.7, 0.4, -0.1, 0.4, 1.1);
        let w = Vector3::new(0.3, -0.8, 0.5);
        let lhs = hat(&w) * h + h * hat(&w);
        let rhs = hat(&((Matrix3::identity() * h.trace() - h) * w));
        assert!(
            (lhs - rhs).norm() < 1e-15,
            "identity: {:e}",
            (lhs - rhs).norm()
        );
        let dr = Matrix3::new(0.3, -0.5, 0.2, 0.7, 0.1, -0.4, -0.2, 0.6, 0.9);
        let q = exp_unchecked(&Vector3::new(0.4, -0.7, 0.3));
        let near = Matrix3::new(1e-6, 3e-7, 0.0, 3e-7, -2e-6, 1e-6, 0.0, 1e-6, 5e-7);
        for r in [q * (Matrix3::identity() + near), q * h] {
            let p = PolarTangent::new(&r).unwrap();
            let step = 1e-6;
            let u = |s: f64| project(&(r + dr * s)).unwrap();
            let fd = log_unchecked(&(u(-step).transpose() * u(step))) / (2.0 * step);
            let err = (p.apply(&dr) - fd).norm() / fd.norm();
            assert!(err < 1e-9, "{err:e}");
            assert!((p.rotation() - u(0.0)).norm() < 1e-15);
        }
    }
}
