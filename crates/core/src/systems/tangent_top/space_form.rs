//! The three-dimensional space forms of 002 §V and their orthonormal frame bundles as matrix
//! groups: Euclidean space ℝ³, the sphere S³(r) = {x ∈ ℝ⁴ : |x| = r} and hyperbolic space
//! H³(r) = {x ∈ ℝ⁴ : x₀² − |x⃗|² = r², x₀ > 0} (the hyperboloid in Minkowski space, with the
//! Riemannian metric g(a, b) = −a₀b₀ + a⃗·b⃗ on its tangent vectors).
//!
//! # The frame bundle is the isometry group
//! An orthonormal frame e = (e₁, e₂, e₃) at x is the 4×4 matrix g = [x/r | e₁ e₂ e₃] ∈ SO(4)
//! (sphere), ∈ SO⁺(1,3) (hyperboloid: gᵀηg = η, η = diag(1, −1, −1, −1)), or
//! g = [[1, 0], [x, e]] ∈ SE(3) (Euclidean, the translation in the first column). In all three,
//! g⁻¹ġ = ξ̂(Ω, v) = [[0, −σvᵀ/ℓ], [v/ℓ, Ω̂]] with v_i = g(e_i, ẋ) the body velocity, Ω the
//! angular velocity of the frame relative to parallel transport (the ambient derivative of e_j
//! differs from ∇_ẋ e_j only along x, orthogonal to every e_i), σ = +1, −1, 0 and ℓ = r, r, 1
//! (sphere, hyperboloid, Euclidean). The bracket in (Ω, v) is
//! [(Ω₁, v₁), (Ω₂, v₂)] = (Ω₁ × Ω₂ + κ v₁ × v₂, Ω₁ × v₂ − Ω₂ × v₁), κ = σ/ℓ² the curvature.
//!
//! # Reference frames
//! A state's frame is e = Ê(x)R with R ∈ SO(3) and the global, smooth, orthonormal field
//! - Euclidean: the constant frame Ê = 1;
//! - sphere: Ê_i = x·(i, j, k)_i / r, the right multiplication of the quaternion x by the units
//!   (the left-invariant fields of SU(2)), so [x/r | Ê] is the left multiplication L(x/r);
//! - hyperboloid: Ê_i = B(x)e_i, B(x) = [[x₀/r, x⃗ᵀ/r], [x⃗/r, 1 + x⃗x⃗ᵀ/(r(x₀ + r))]] the pure boost
//!   taking (r, 0, 0, 0) to x (x₀ + r ≥ 2r: no singularity).
//!
//! [`SpaceForm::reference`] is the matrix F(x) = g at R = 1, so that g = F(x)·diag(1, R).

use crate::check;
use crate::error::{Error, Result};
use crate::lie::so3;
use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};

/// Relative tolerance of the membership checks (a point on the space, a velocity tangent to it,
/// a frame in the group), relative to the scale of the values.
pub const SPACE_TOL: f64 = 1e-10;

/// A three-dimensional space form (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpaceForm {
    /// ℝ³, κ = 0.
    Euclidean,
    /// S³(r) ⊂ ℝ⁴, κ = 1/r².
    Sphere {
        /// The radius r.
        radius: f64,
    },
    /// H³(r) ⊂ ℝ¹'³, κ = −1/r².
    Hyperbolic {
        /// The radius r.
        radius: f64,
    },
}

impl SpaceForm {
    /// S³ of radius r > 0.
    pub fn sphere(radius: f64) -> Result<Self> {
        check_radius(radius)?;
        Ok(SpaceForm::Sphere { radius })
    }

    /// H³ of radius r > 0 (sectional curvature −1/r²).
    pub fn hyperbolic(radius: f64) -> Result<Self> {
        check_radius(radius)?;
        Ok(SpaceForm::Hyperbolic { radius })
    }

    /// "Euclidean(3)", "Sphere(3, radius=r)", "Hyperbolic(3, radius=r)".
    pub fn name(&self) -> String {
        match self {
            SpaceForm::Euclidean => "Euclidean(3)".into(),
            SpaceForm::Sphere { radius } => format!("Sphere(3, radius={radius})"),
            SpaceForm::Hyperbolic { radius } => format!("Hyperbolic(3, radius={radius})"),
        }
    }

    /// σ = +1 (sphere), −1 (hyperboloid), 0 (Euclidean): the sign of the curvature.
    pub fn sigma(&self) -> f64 {
        match self {
            SpaceForm::Euclidean => 0.0,
            SpaceForm::Sphere { .. } => 1.0,
            SpaceForm::Hyperbolic { .. } => -1.0,
        }
    }

    /// ℓ: the radius, or 1 for Euclidean space (the unit of the translation column).
    pub fn length(&self) -> f64 {
        match self {
            SpaceForm::Euclidean => 1.0,
            SpaceForm::Sphere { radius } | SpaceForm::Hyperbolic { radius } => *radius,
        }
    }

    /// The sectional curvature κ = σ/ℓ².
    pub fn curvature(&self) -> f64 {
        self.sigma() / (self.length() * self.length())
    }

    /// The dimension of the ambient space the points live in: 3 (Euclidean) or 4.
    pub fn ambient_dim(&self) -> usize {
        match self {
            SpaceForm::Euclidean => 3,
            _ => 4,
        }
    }

    /// The first ambient row of g that holds x (Euclidean: row 1, below the homogeneous 1).
    fn first_row(&self) -> usize {
        4 - self.ambient_dim()
    }

    /// g(a, b) of two ambient vectors tangent at a point (the hyperboloid's −a₀b₀ + a⃗·b⃗).
    pub fn metric(&self, a: &[f64], b: &[f64]) -> f64 {
        let s: f64 = a.iter().zip(b).map(|(p, q)| p * q).sum();
        match self {
            SpaceForm::Hyperbolic { .. } => s - 2.0 * a[0] * b[0],
            _ => s,
        }
    }

    /// Checks a point x (ambient, finite): |x| = r on the sphere, x₀² − |x⃗|² = r² and x₀ > 0 on
    /// the hyperboloid, to [`SPACE_TOL`] relative.
    pub fn check_point(&self, x: &[f64]) -> Result<()> {
        check::len_of("x", x, self.ambient_dim())?;
        check::finite_slice("x", x)?;
        let r = self.length();
        let (defect, what) = match self {
            SpaceForm::Euclidean => return Ok(()),
            SpaceForm::Sphere { .. } => {
                let n2: f64 = x.iter().map(|v| v * v).sum();
                ((n2.sqrt() - r).abs() / r, "| |x| − r | / r")
            }
            SpaceForm::Hyperbolic { .. } => {
                if x[0] <= 0.0 {
                    return Err(Error::invalid(
                        "x",
                        format!(
                            "a point of {} has x₀ > 0 (the upper sheet); got x₀ = {}",
                            self.name(),
                            x[0]
                        ),
                    ));
                }
                let q = x[0] * x[0] - x[1..].iter().map(|v| v * v).sum::<f64>();
                let scale = x.iter().map(|v| v * v).sum::<f64>();
                ((q - r * r).abs() / scale, "|x₀² − |x⃗|² − r²| / |x|²")
            }
        };
        if defect.is_nan() || defect > SPACE_TOL {
            return Err(Error::invalid(
                "x",
                format!(
                    "not a point of {}: {what} = {defect:.3e} (tolerance {SPACE_TOL:.0e})",
                    self.name()
                ),
            ));
        }
        Ok(())
    }

    /// Checks that an ambient velocity is tangent at x: x·ẋ = 0 (sphere), x₀ẋ₀ − x⃗·ẋ⃗ = 0
    /// (hyperboloid), to [`SPACE_TOL`] relative to |x||ẋ|.
    pub fn check_tangent(&self, x: &[f64], xdot: &[f64]) -> Result<()> {
        check::len_of("xdot", xdot, self.ambient_dim())?;
        check::finite_slice("xdot", xdot)?;
        let (dot, scale) = match self {
            SpaceForm::Euclidean => return Ok(()),
            SpaceForm::Sphere { .. } => (dot(x, xdot), norm(x) * norm(xdot)),
            SpaceForm::Hyperbolic { .. } => (-self.metric(x, xdot), norm(x) * norm(xdot)),
        };
        if dot.is_nan() || dot.abs() > SPACE_TOL * scale {
            return Err(Error::invalid(
                "xdot",
                format!(
                    "the velocity must be tangent to {} at x (⟨x, ẋ⟩ = 0 in the ambient \
                     metric); got ⟨x, ẋ⟩/(|x||ẋ|) = {:.3e} (tolerance {SPACE_TOL:.0e})",
                    self.name(),
                    dot / scale
                ),
            ));
        }
        Ok(())
    }

    /// F(x): the frame-bundle element of the reference frame Ê(x) (module docs), 4×4. x is
    /// assumed on the space.
    pub fn reference(&self, x: &[f64]) -> Matrix4<f64> {
        match self {
            SpaceForm::Euclidean => {
                let mut f = Matrix4::identity();
                for i in 0..3 {
                    f[(i + 1, 0)] = x[i];
                }
                f
            }
            SpaceForm::Sphere { radius } => {
                let q = Vector4::from_column_slice(x) / *radius;
                // Columns q·1, q·i, q·j, q·k: the left multiplication by q.
                Matrix4::new(
                    q[0], -q[1], -q[2], -q[3], //
                    q[1], q[0], -q[3], q[2], //
                    q[2], q[3], q[0], -q[1], //
                    q[3], -q[2], q[1], q[0],
                )
            }
            SpaceForm::Hyperbolic { radius } => {
                let r = *radius;
                let v = Vector3::new(x[1], x[2], x[3]);
                let mut f = Matrix4::zeros();
                f[(0, 0)] = x[0] / r;
                let block = Matrix3::identity() + v * v.transpose() / (r * (x[0] + r));
                for i in 0..3 {
                    f[(0, i + 1)] = v[i] / r;
                    f[(i + 1, 0)] = v[i] / r;
                    for j in 0..3 {
                        f[(i + 1, j + 1)] = block[(i, j)];
                    }
                }
                f
            }
        }
    }

    /// g⁻¹ for g in the group: gᵀ (sphere), ηgᵀη (hyperboloid), [[1, 0], [−Rᵀx, Rᵀ]]
    /// (Euclidean).
    pub fn inverse(&self, g: &Matrix4<f64>) -> Matrix4<f64> {
        match self {
            SpaceForm::Sphere { .. } => g.transpose(),
            SpaceForm::Hyperbolic { .. } => {
                let mut h = g.transpose();
                for i in 1..4 {
                    h[(0, i)] = -h[(0, i)];
                    h[(i, 0)] = -h[(i, 0)];
                }
                h
            }
            SpaceForm::Euclidean => {
                let r = g.fixed_view::<3, 3>(1, 1).transpose();
                let x = g.fixed_view::<3, 1>(1, 0).into_owned();
                let mut h = Matrix4::identity();
                h.fixed_view_mut::<3, 3>(1, 1).copy_from(&r);
                h.fixed_view_mut::<3, 1>(1, 0).copy_from(&(-(r * x)));
                h
            }
        }
    }

    /// ξ̂(Ω, v) = [[0, −σvᵀ/ℓ], [v/ℓ, Ω̂]] (module docs).
    pub fn hat(&self, omega: &Vector3<f64>, v: &Vector3<f64>) -> Matrix4<f64> {
        let (s, l) = (self.sigma(), self.length());
        let mut x = Matrix4::zeros();
        x.fixed_view_mut::<3, 3>(1, 1).copy_from(&so3::hat(omega));
        for i in 0..3 {
            x[(i + 1, 0)] = v[i] / l;
            x[(0, i + 1)] = -s * v[i] / l;
        }
        x
    }

    /// (Ω, v) of ξ̂ (the inverse of [`SpaceForm::hat`]).
    pub fn vee(&self, x: &Matrix4<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let l = self.length();
        (
            Vector3::new(x[(3, 2)], x[(1, 3)], x[(2, 1)]),
            Vector3::new(x[(1, 0)], x[(2, 0)], x[(3, 0)]) * l,
        )
    }

    /// exp ξ̂(Ω, v) − 1 ([`expm1`]): the increment of g ↦ g exp ξ̂.
    pub fn expm1(&self, omega: &Vector3<f64>, v: &Vector3<f64>) -> Matrix4<f64> {
        expm1(&self.hat(omega, v))
    }

    /// x, the point of the frame g (ambient components).
    pub fn position(&self, g: &Matrix4<f64>) -> Vec<f64> {
        let (k, l) = (self.first_row(), self.length());
        (k..4)
            .map(|i| g[(i, 0)] * if k == 0 { l } else { 1.0 })
            .collect()
    }

    /// The ambient components of Σ c_i e_i for the frame e of g (a body vector in space).
    pub fn ambient(&self, g: &Matrix4<f64>, c: &Vector3<f64>) -> Vec<f64> {
        (self.first_row()..4)
            .map(|i| (0..3).map(|j| g[(i, j + 1)] * c[j]).sum())
            .collect()
    }

    /// The body components g(e_i, a) of an ambient tangent vector a at the frame g.
    pub fn body(&self, g: &Matrix4<f64>, a: &[f64]) -> Vector3<f64> {
        let k = self.first_row();
        Vector3::from_fn(|i, _| {
            let e: Vec<f64> = (k..4).map(|r| g[(r, i + 1)]).collect();
            self.metric(&e, a)
        })
    }

    /// R ∈ SO(3), the frame of g relative to the reference frame at its point:
    /// diag(1, R) = F(x)⁻¹g.
    pub fn relative_frame(&self, g: &Matrix4<f64>) -> Matrix3<f64> {
        let d = self.inverse(&self.reference(&self.position(g))) * g;
        d.fixed_view::<3, 3>(1, 1).into_owned()
    }

    /// Checks g (finite) against its group to [`SPACE_TOL`] relative: gᵀg = 1 and det g = 1
    /// (sphere); gᵀηg = η and g₀₀ > 0 (hyperboloid); the row (1, 0, 0, 0) and an SO(3) block
    /// (Euclidean).
    pub fn check_frame(&self, what: &str, g: &Matrix4<f64>) -> Result<()> {
        check::finite_slice(what, g.as_slice())?;
        let scale = g.norm_squared().max(1.0);
        let defect = (self.inverse(g) * g - Matrix4::identity()).norm() / scale
            + match self {
                SpaceForm::Euclidean => {
                    Vector4::new(g[(0, 0)] - 1.0, g[(0, 1)], g[(0, 2)], g[(0, 3)]).norm()
                        + (g.fixed_view::<3, 3>(1, 1).determinant() - 1.0).abs()
                }
                SpaceForm::Sphere { .. } => (g.determinant() - 1.0).abs(),
                SpaceForm::Hyperbolic { .. } => {
                    if g[(0, 0)] <= 0.0 {
                        f64::INFINITY
                    } else {
                        (g.determinant() - 1.0).abs() / scale
                    }
                }
            };
        if defect.is_nan() || defect > SPACE_TOL {
            let group = match self {
                SpaceForm::Euclidean => "SE(3)",
                SpaceForm::Sphere { .. } => "SO(4)",
                SpaceForm::Hyperbolic { .. } => "SO⁺(1,3)",
            };
            return Err(Error::NotInGroup {
                what: what.into(),
                group: format!("{group} (the orthonormal frames of {})", self.name()),
                defect_name: "‖g⁻¹g − 1‖ + |det g − 1| (relative)".into(),
                defect,
                tol: SPACE_TOL,
            });
        }
        Ok(())
    }
}

/// exp(X) − 1 of a 4×4 matrix to the precision of its own size (not of 1): the Taylor series of
/// Y = X/2ˢ (‖Y‖∞ ≤ ½) to the first term below 2⁻⁵⁶ of the first (at most 17 terms; 6 at
/// ‖Y‖ = 10⁻³), then s doublings D ← D(D + 2) (exp(2Y) − 1 = (e^Y − 1)(e^Y + 1)). A step's increment
/// g(exp X − 1) so formed rounds once onto g, without the bias of exp(X) rounded to an ulp of 1 at
/// the same X every step (which made the frame's orthogonality drift linearly, as
/// `so3::Rodrigues` explains).
pub fn expm1(x: &Matrix4<f64>) -> Matrix4<f64> {
    let Some((s, terms)) = expm1_plan(x) else {
        return Matrix4::from_element(f64::NAN);
    };
    let y = x * 0.5f64.powi(s);
    // Horner: Y(1 + Y/2(1 + Y/3(… (1 + Y/terms)))).
    let mut d = Matrix4::identity();
    for k in (2..=terms).rev() {
        d = Matrix4::identity() + y * d / f64::from(k);
    }
    let mut d = y * d;
    for _ in 0..s {
        d = d * (d + Matrix4::identity() * 2.0);
    }
    d
}

/// The scaling s and the number of terms of [`expm1`] at X (None for a non-finite X).
fn expm1_plan(x: &Matrix4<f64>) -> Option<(i32, u32)> {
    let norm = (0..4)
        .map(|i| (0..4).map(|j| x[(i, j)].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if !norm.is_finite() {
        return None;
    }
    // The smallest s ≥ 0 with ‖X‖∞/2ˢ ≤ ½.
    let s = (2.0 * norm).log2().ceil().max(0.0) as i32;
    let ny = norm * 0.5f64.powi(s);
    // Terms: the first k with ‖Y‖^(k−1)/k! ≤ 2⁻⁵⁶ (relative to the first term ‖Y‖).
    let mut terms = 1;
    let mut t = 1.0;
    while terms < 17 && t > f64::EPSILON / 4.0 {
        terms += 1;
        t *= ny / f64::from(terms);
    }
    Some((s, terms))
}

/// D expm1(X)\[δX\]: [`expm1`]'s scaling, series and doublings differentiated step by step
/// (forward mode, the scaling and the number of terms held), so the derivative of the function
/// as it is computed (issue 26: the tangent map of the frame top's flow of T).
pub fn expm1_tangent(x: &Matrix4<f64>, dx: &Matrix4<f64>) -> Matrix4<f64> {
    let Some((s, terms)) = expm1_plan(x) else {
        return Matrix4::from_element(f64::NAN);
    };
    let scale = 0.5f64.powi(s);
    let (y, dy) = (x * scale, dx * scale);
    let one = Matrix4::identity();
    let (mut d, mut dd) = (one, Matrix4::zeros());
    for k in (2..=terms).rev() {
        let kf = f64::from(k);
        dd = (dy * d + y * dd) / kf;
        d = one + y * d / kf;
    }
    let (mut d, mut dd) = (y * d, dy * d + y * dd);
    for _ in 0..s {
        let two = d + one * 2.0;
        dd = dd * two + d * dd;
        d *= two;
    }
    dd
}

/// r > 0, finite, with a finite curvature 1/r² (r ≥ 1e-150).
fn check_radius(radius: f64) -> Result<()> {
    check::positive("radius", radius)?;
    if !(1.0 / (radius * radius)).is_finite() {
        return Err(Error::invalid(
            "radius",
            format!("the curvature 1/r² of a radius {radius:e} exceeds the f64 range (r ≥ 1e-150)"),
        ));
    }
    Ok(())
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(p, q)| p * q).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}
