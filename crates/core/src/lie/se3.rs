//! The special Euclidean group SE(3) = SO(3) ⋉ R³ of rigid motions x ↦ R x + t, for the heavy
//! top and variational integrators.
//!
//! Representation: [`SE3`] stores the rotation R and translation t separately (not nalgebra's
//! `Isometry3`, whose unit quaternion would make R a derived quantity); its matrix is the 4×4
//! homogeneous [[R, t], [0, 1]].
//!
//! Algebra coordinates ξ = (ω, v) ∈ R⁶ with the ROTATION FIRST: ξ̂ = [[ω̂, v], [0, 0]] (ω̂ the
//! physics hat map of [`so3::hat`]). The pairing is the dot product on R⁶, so a dual element is
//! (μ, p) = (angular, linear) in the same order. 6×6 matrices ([`ad_matrix`], [`SE3::adjoint_matrix`])
//! act on these coordinates.
//!
//! As everywhere in [`crate::lie`], the plain name is checked ([`exp`], [`log`], [`vee`], the
//! Jacobians) and [`exp_unchecked`], [`log_unchecked`] skip the checks for inner loops.

use nalgebra::{Matrix3, Matrix4, Matrix6, Vector3, Vector6};

use crate::check;
use crate::error::{Error, Result};
use crate::lie::{so3, MatrixLieGroup};
use crate::Mat;

/// Tolerance on the last row of a homogeneous matrix: max |[m₃₀, m₃₁, m₃₂, m₃₃ − 1]| ≤ this.
pub const HOMOGENEOUS_TOL: f64 = 1e-12;

/// A rigid motion x ↦ R x + t with R ∈ SO(3) (validated to [`so3::ROTATION_TOL`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SE3 {
    rot: Matrix3<f64>,
    trans: Vector3<f64>,
}

/// ω and v of ξ = (ω, v).
#[inline]
fn split(xi: &Vector6<f64>) -> (Vector3<f64>, Vector3<f64>) {
    (xi.fixed_rows::<3>(0).into(), xi.fixed_rows::<3>(3).into())
}

/// (ω, v) ↦ ξ.
#[inline]
fn join(w: &Vector3<f64>, v: &Vector3<f64>) -> Vector6<f64> {
    Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z)
}

/// The 4×4 matrix [[ω̂, v], [0, 0]] of ξ = (ω, v).
pub fn hat(xi: &Vector6<f64>) -> Matrix4<f64> {
    let (w, v) = split(xi);
    let mut m = Matrix4::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&so3::hat(&w));
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(&v);
    m
}

/// Inverse of [`hat`]: `m` finite, its last row zero ([`HOMOGENEOUS_TOL`]) and its rotation
/// block skew ([`so3::vee`]), else [`Error::NonFinite`] / [`Error::NotInGroup`].
pub fn vee(m: &Matrix4<f64>) -> Result<Vector6<f64>> {
    check::finite_slice("xi", m.as_slice())?;
    let defect = (0..4).map(|j| m[(3, j)].abs()).fold(0.0, f64::max);
    if defect > HOMOGENEOUS_TOL {
        return Err(Error::NotInGroup {
            what: "xi".into(),
            group: "se(3)".into(),
            defect_name: "max |last row|".into(),
            defect,
            tol: HOMOGENEOUS_TOL,
        });
    }
    let w = so3::vee(&m.fixed_view::<3, 3>(0, 0).into())?;
    Ok(join(&w, &m.fixed_view::<3, 1>(0, 3).into()))
}

/// Exponential exp(ξ̂) = [[exp(ω̂), V(ω) v], [0, 1]] with V(ω) = I + ((1 − cos θ)/θ²) ω̂ +
/// ((θ − sin θ)/θ³) ω̂² = J_l(ω) ([`so3::jacobian_left`]), stable near θ = 0 by series.
/// No checks (NaN beyond the rule of [`crate::lie::ANGLE_ROUNDING_TOL`]; see [`exp`]).
pub fn exp_unchecked(xi: &Vector6<f64>) -> SE3 {
    let (w, v) = split(xi);
    let (rot, jl) = so3::exp_and_jacobian_left(&w);
    SE3 { rot, trans: jl * v }
}

/// Exponential se(3) → SE(3) ([`exp_unchecked`]) with checks: ξ finite, |ω| within the rule of
/// all exponentials ([`so3::check_exp_arg`], [`crate::lie::ANGLE_ROUNDING_TOL`]) and the
/// translation V(ω) v representable (an overflow error naming v otherwise).
pub fn exp(xi: &Vector6<f64>) -> Result<SE3> {
    check::finite_slice("xi", xi.as_slice())?;
    let (w, _) = split(xi);
    so3::check_exp_arg("ω", "the SE(3) exponential", &w)?;
    let g = exp_unchecked(xi);
    if g.trans.iter().any(|x| !x.is_finite()) {
        return Err(Error::overflow(
            "xi",
            format!(
                "the translation V(ω) v of the SE(3) exponential exceeds the f64 range                  (|v| = {})",
                crate::error::fmt_num(crate::lie::scaled_norm(xi.iter().skip(3)))
            ),
        ));
    }
    Ok(g)
}

/// Logarithm: ω = [`so3::log_unchecked`] of R (θ ∈ [0, π]; at θ = π one of the two, as
/// documented there) and v = V(ω)⁻¹ t = J_l⁻¹(ω) t, which is regular for θ ≤ π. No checks (see
/// [`log`]).
pub fn log_unchecked(g: &SE3) -> Vector6<f64> {
    let w = so3::log_unchecked(&g.rot);
    let v = so3::jacobian_left_inv_principal(&w) * g.trans;
    join(&w, &v)
}

/// Principal logarithm SE(3) → se(3) ([`log_unchecked`]), with [`Error::NoUniqueLog`] when the
/// rotation angle is within [`so3::LOG_PI_TOL`] of π (as [`so3::log`]).
pub fn log(g: &SE3) -> Result<Vector6<f64>> {
    so3::log(&g.rot)?;
    Ok(log_unchecked(g))
}

/// The 6×6 left Jacobian [[J_l(ω), 0], [Q(ω, v), J_l(ω)]] of exp on (ω, v) coordinates
/// (Barfoot's 𝒥 with the blocks reordered), or its inverse [[J_l⁻¹, 0], [−J_l⁻¹ Q J_l⁻¹, J_l⁻¹]]:
/// exp(ξ + δ) = exp(J_l(ξ) δ) exp(ξ) to first order. Checked as [`so3::jacobian_left`] (and
/// [`so3::jacobian_left_inv`]); an overflow error when Q exceeds the f64 range (huge v).
fn jacobian_left_block(xi: &Vector6<f64>, inverse: bool) -> Result<Matrix6<f64>> {
    check::finite_slice("xi", xi.as_slice())?;
    let (w, v) = split(xi);
    let j = if inverse {
        so3::jacobian_left_inv(&w)?
    } else {
        so3::jacobian_left(&w)?
    };
    let q = so3::jacobian_left_derivative(&w, &v);
    let q = if inverse { -(j * q * j) } else { q };
    if q.iter().any(|x| !x.is_finite()) {
        return Err(check::overflow_error("xi", "the SE(3) Jacobian"));
    }
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&j);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&j);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&q);
    Ok(m)
}

/// Left Jacobian J_l(ξ) of the SE(3) exponential (see `jacobian_left_block`).
pub fn jacobian_left(xi: &Vector6<f64>) -> Result<Matrix6<f64>> {
    jacobian_left_block(xi, false)
}

/// Right Jacobian J_r(ξ) = J_l(−ξ): exp(ξ + δ) = exp(ξ) exp(J_r(ξ) δ) to first order.
pub fn jacobian_right(xi: &Vector6<f64>) -> Result<Matrix6<f64>> {
    jacobian_left_block(&-xi, false)
}

/// J_l(ξ)⁻¹ (errors where J_l(ω) is singular, |ω| = 2πk, as [`so3::jacobian_left_inv`]).
pub fn jacobian_left_inv(xi: &Vector6<f64>) -> Result<Matrix6<f64>> {
    jacobian_left_block(xi, true)
}

/// J_r(ξ)⁻¹ = J_l(−ξ)⁻¹.
pub fn jacobian_right_inv(xi: &Vector6<f64>) -> Result<Matrix6<f64>> {
    jacobian_left_block(&-xi, true)
}

/// The 6×6 matrix of ad_ξ on (ω, v) coordinates: [[ω̂, 0], [v̂, ω̂]], i.e.
/// [(ω₁, v₁), (ω₂, v₂)] = (ω₁ × ω₂, ω₁ × v₂ − ω₂ × v₁) (commutator of the 4×4 matrices).
pub fn ad_matrix(xi: &Vector6<f64>) -> Matrix6<f64> {
    let (w, v) = split(xi);
    let wh = so3::hat(&w);
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&wh);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&wh);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&so3::hat(&v));
    m
}

impl SE3 {
    /// Validates R ([`so3::SO3::new`]: finite, orthogonal, det 1) and t (finite).
    pub fn new(rot: Matrix3<f64>, trans: Vector3<f64>) -> Result<Self> {
        so3::SO3::new(rot)?;
        check::finite_slice("t", trans.as_slice())?;
        Ok(SE3 { rot, trans })
    }

    /// Without checks (R must be a rotation).
    #[inline]
    pub fn new_unchecked(rot: Matrix3<f64>, trans: Vector3<f64>) -> Self {
        SE3 { rot, trans }
    }

    /// From a 4×4 homogeneous matrix [[R, t], [0, 1]]: the last row must be (0, 0, 0, 1) to
    /// [`HOMOGENEOUS_TOL`] ([`Error::NotInGroup`]), R a rotation and everything finite.
    pub fn from_matrix4(m: &Matrix4<f64>) -> Result<Self> {
        check::finite_slice("g", m.as_slice())?;
        let defect = (0..4)
            .map(|j| (m[(3, j)] - if j == 3 { 1.0 } else { 0.0 }).abs())
            .fold(0.0, f64::max);
        if defect > HOMOGENEOUS_TOL {
            return Err(Error::NotInGroup {
                what: "g".into(),
                group: "SE(3)".into(),
                defect_name: "max |last row − (0, 0, 0, 1)|".into(),
                defect,
                tol: HOMOGENEOUS_TOL,
            });
        }
        SE3::new(
            m.fixed_view::<3, 3>(0, 0).into(),
            m.fixed_view::<3, 1>(0, 3).into(),
        )
    }

    /// The rotation R.
    #[inline]
    pub fn rot(&self) -> &Matrix3<f64> {
        &self.rot
    }

    /// The translation t.
    #[inline]
    pub fn trans(&self) -> &Vector3<f64> {
        &self.trans
    }

    /// The homogeneous matrix [[R, t], [0, 1]].
    pub fn matrix4(&self) -> Matrix4<f64> {
        let mut m = Matrix4::identity();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rot);
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.trans);
        m
    }

    /// The 6×6 matrix of Ad_g on (ω, v) coordinates: [[R, 0], [t̂ R, R]], i.e.
    /// Ad_g (ω, v) = (R ω, t × R ω + R v) (from g ξ̂ g⁻¹).
    pub fn adjoint_matrix(&self) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rot);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&self.rot);
        m.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(so3::hat(&self.trans) * self.rot));
        m
    }
}

impl MatrixLieGroup for SE3 {
    type Algebra = Vector6<f64>;
    type Point = Vector3<f64>;

    fn dim(&self) -> usize {
        6
    }

    fn identity_like(&self) -> Self {
        SE3 {
            rot: Matrix3::identity(),
            trans: Vector3::zeros(),
        }
    }

    /// (R₁, t₁)(R₂, t₂) = (R₁ R₂, R₁ t₂ + t₁).
    fn compose(&self, other: &Self) -> Self {
        SE3 {
            rot: self.rot * other.rot,
            trans: self.rot * other.trans + self.trans,
        }
    }

    /// (R, t)⁻¹ = (Rᵀ, −Rᵀ t).
    fn inverse(&self) -> Self {
        let rt = self.rot.transpose();
        SE3 {
            rot: rt,
            trans: -(rt * self.trans),
        }
    }

    /// A point: g · x = R x + t.
    #[inline]
    fn act(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.rot * x + self.trans
    }

    /// [`exp`].
    fn exp(xi: &Vector6<f64>) -> Result<Self> {
        exp(xi)
    }

    /// [`exp_unchecked`].
    fn exp_unchecked(xi: &Vector6<f64>) -> Self {
        exp_unchecked(xi)
    }

    /// [`log`].
    fn log(&self) -> Result<Vector6<f64>> {
        log(self)
    }

    /// Ad_g (ω, v) = (R ω, t × R ω + R v).
    fn adjoint(&self, xi: &Vector6<f64>) -> Vector6<f64> {
        let (w, v) = split(xi);
        let rw = self.rot * w;
        join(&rw, &(self.trans.cross(&rw) + self.rot * v))
    }

    /// ad_(ω₁, v₁) (ω₂, v₂) = (ω₁ × ω₂, ω₁ × v₂ − ω₂ × v₁).
    fn ad(xi: &Vector6<f64>, eta: &Vector6<f64>) -> Vector6<f64> {
        let ((w1, v1), (w2, v2)) = (split(xi), split(eta));
        join(&w1.cross(&w2), &(w1.cross(&v2) - w2.cross(&v1)))
    }

    /// ad*_(ω, v) (μ, p) = (μ × ω + p × v, p × ω) = ad_ξᵀ (μ, p) (the transpose of
    /// [`ad_matrix`] under the dot-product pairing).
    fn ad_star(xi: &Vector6<f64>, mu: &Vector6<f64>) -> Vector6<f64> {
        let ((w, v), (m, p)) = (split(xi), split(mu));
        join(&(m.cross(&w) + p.cross(&v)), &p.cross(&w))
    }

    /// The dot product on R⁶: ⟨(μ, p), (ω, v)⟩ = μ·ω + p·v.
    fn pairing(mu: &Vector6<f64>, xi: &Vector6<f64>) -> f64 {
        mu.dot(xi)
    }

    fn matrix(&self) -> Mat {
        super::to_mat(&self.matrix4())
    }

    /// [`hat`].
    fn hat(xi: &Vector6<f64>) -> Mat {
        super::to_mat(&hat(xi))
    }

    /// [`vee`] of a 4×4 matrix.
    fn vee(m: &Mat) -> Result<Vector6<f64>> {
        check::square_of("xi", m, 4)?;
        vee(&Matrix4::from_fn(|i, j| m[(i, j)]))
    }

    fn coords(xi: &Vector6<f64>) -> Vec<f64> {
        xi.as_slice().to_vec()
    }

    fn algebra_from_coords(&self, c: &[f64]) -> Vector6<f64> {
        Vector6::from_column_slice(c)
    }

    /// [`jacobian_right`].
    fn jacobian_right(xi: &Vector6<f64>) -> Result<Mat> {
        jacobian_right(xi).map(|j| super::to_mat(&j))
    }

    /// [`jacobian_left`].
    fn jacobian_left(xi: &Vector6<f64>) -> Result<Mat> {
        jacobian_left(xi).map(|j| super::to_mat(&j))
    }

    /// [`jacobian_right_inv`].
    fn jacobian_right_inv(xi: &Vector6<f64>) -> Result<Mat> {
        jacobian_right_inv(xi).map(|j| super::to_mat(&j))
    }

    /// [`jacobian_left_inv`].
    fn jacobian_left_inv(xi: &Vector6<f64>) -> Result<Mat> {
        jacobian_left_inv(xi).map(|j| super::to_mat(&j))
    }
}
