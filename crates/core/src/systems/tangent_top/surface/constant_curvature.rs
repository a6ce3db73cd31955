//! The surfaces of constant curvature with closed forms (002 §II–III): the Euclidean [`Plane`]
//! (K = 0, SE(2)), the round [`Sphere`] (K = 1/R², SO(3)) and the [`HyperbolicPlane`] (K = −1,
//! SL(2, ℝ), 002 (67)–(77)).

use super::{
    finite2, normal_and_invertible, Embedding, Mat2, SecondGeometry, Shape, Surface, Vec2, Vec3,
    ZERO2,
};
use crate::check;
use crate::error::Result;

/// The Euclidean plane in Cartesian coordinates x = (x, y): g = I, Ê = (∂x, ∂y), α = 0, K = 0,
/// embedded as z = 0 with n = e_z. Isometries SE(2) (002 (62)–(66)): the generators (translation
/// along x, along y, rotation about the origin) are (1, 0, 0), (0, 1, 0) and (−y, x, 1) — a
/// rotation by ψ turns the constant frame by ψ.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Plane;

impl Surface for Plane {
    fn name(&self) -> &'static str {
        "Plane"
    }
    fn domain(&self) -> &'static str {
        "ℝ²"
    }
    fn contains(&self, x: Vec2) -> bool {
        finite2(x)
    }
    fn metric(&self, _x: Vec2) -> Mat2 {
        [[1.0, 0.0], [0.0, 1.0]]
    }
    fn metric_derivatives(&self, _x: Vec2) -> [Mat2; 2] {
        [ZERO2; 2]
    }
    fn frame(&self, _x: Vec2) -> Mat2 {
        [[1.0, 0.0], [0.0, 1.0]]
    }
    fn connection(&self, _x: Vec2) -> Vec2 {
        [0.0; 2]
    }
    fn connection_derivatives(&self, _x: Vec2) -> Mat2 {
        ZERO2
    }
    fn has_second_derivatives(&self) -> bool {
        true
    }
    fn second_derivatives(&self, _x: Vec2) -> SecondGeometry {
        SecondGeometry::ZERO
    }
    fn curvature(&self, _x: Vec2) -> f64 {
        0.0
    }
    fn killing_count(&self) -> usize {
        3
    }
    fn killing_names(&self) -> &'static [&'static str] {
        &["translation x", "translation y", "rotation"]
    }
    fn killing(&self, k: usize, x: Vec2) -> Vec3 {
        match k {
            0 => [1.0, 0.0, 0.0],
            1 => [0.0, 1.0, 0.0],
            2 => [-x[1], x[0], 1.0],
            _ => [0.0; 3],
        }
    }
    fn killing_is_affine(&self, k: usize) -> bool {
        k < 3
    }
    fn embedding(&self) -> Option<&dyn Embedding> {
        Some(self)
    }
}

impl Embedding for Plane {
    fn position(&self, x: Vec2) -> [f64; 3] {
        [x[0], x[1], 0.0]
    }
    fn normal(&self, _x: Vec2) -> [f64; 3] {
        [0.0, 0.0, 1.0]
    }
    fn second_fundamental_form(&self, _x: Vec2) -> Mat2 {
        ZERO2
    }
    fn tangent(&self, _x: Vec2, v: Vec2) -> [f64; 3] {
        [v[0], v[1], 0.0]
    }
    fn shape(&self, _x: Vec2) -> Shape {
        Shape {
            w: ZERO2,
            dw: [ZERO2; 2],
        }
    }
    fn has_shape_second(&self) -> bool {
        true
    }
    fn shape_second(&self, _x: Vec2) -> [[Mat2; 2]; 2] {
        [[ZERO2; 2]; 2]
    }
}

/// The sphere of radius R in colatitude and longitude x = (ϑ, φ), 0 < ϑ < π:
/// X = R(sin ϑ cos φ, sin ϑ sin φ, cos ϑ), g = diag(R², R² sin²ϑ), Ê₁ = ∂ϑ/R, Ê₂ = ∂φ/(R sin ϑ)
/// (n = Ê₁ × Ê₂ the outward normal).
///
/// **Connection.** The coframe θ¹ = R dϑ, θ² = R sin ϑ dφ has dθ¹ = 0 and
/// dθ² = R cos ϑ dϑ∧dφ = −w∧θ², so w = cos ϑ dφ: α = (0, cos ϑ) (the sign of 002 (79), whose
/// cross term is +𝕀 cos ϑ dφ dψ; directly, ⟨∂_φ Ê₁, Ê₂⟩ = cos ϑ in ℝ³). K = 1/R².
///
/// **Isometries** SO(3), the rotations about the ambient axes e_x, e_y, e_z: with Ẋ = ω × X,
/// ϑ̇ = (ω × X̂)·Ê₁, φ̇ = (ω × X̂)·Ê₂ / sin ϑ and ψ̇ = ⟨∇_{Ê₁}X, Ê₂⟩ − w(X) = ω·n − cos ϑ φ̇:
/// X_x = (−sin φ, −cot ϑ cos φ, cos φ / sin ϑ), X_y = (cos φ, −cot ϑ sin φ, sin φ / sin ϑ),
/// X_z = (0, 1, 0). Their momenta are the components of the ambient angular momentum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// R > 0.
    pub radius: f64,
}

impl Sphere {
    /// A sphere of radius R > 0.
    pub fn new(radius: f64) -> Result<Self> {
        check::positive("radius", radius)?;
        Ok(Sphere { radius })
    }
}

impl Surface for Sphere {
    fn name(&self) -> &'static str {
        "Sphere"
    }
    fn domain(&self) -> &'static str {
        "0 < ϑ < π (the poles are coordinate singularities)"
    }
    /// Also refuses points so close to a pole that g₂₂ = R² sin²ϑ or its inverse is not a normal
    /// finite number (the frame and the metric's inverse would overflow).
    fn contains(&self, x: Vec2) -> bool {
        finite2(x)
            && x[0] > 0.0
            && x[0] < std::f64::consts::PI
            && normal_and_invertible(self.radius * x[0].sin())
    }
    fn metric(&self, x: Vec2) -> Mat2 {
        let r2 = self.radius * self.radius;
        let s = x[0].sin();
        [[r2, 0.0], [0.0, r2 * s * s]]
    }
    fn metric_derivatives(&self, x: Vec2) -> [Mat2; 2] {
        let r2 = self.radius * self.radius;
        let (s, c) = x[0].sin_cos();
        [[[0.0, 0.0], [0.0, 2.0 * r2 * s * c]], ZERO2]
    }
    fn frame(&self, x: Vec2) -> Mat2 {
        let r = self.radius;
        [[1.0 / r, 0.0], [0.0, 1.0 / (r * x[0].sin())]]
    }
    fn connection(&self, x: Vec2) -> Vec2 {
        [0.0, x[0].cos()]
    }
    fn connection_derivatives(&self, x: Vec2) -> Mat2 {
        [[0.0, -x[0].sin()], [0.0, 0.0]]
    }
    fn has_second_derivatives(&self) -> bool {
        true
    }
    /// ∂²_ϑ g₂₂ = 2R² cos 2ϑ, ∂²_ϑ α₂ = −cos ϑ; the rest zero.
    fn second_derivatives(&self, x: Vec2) -> SecondGeometry {
        let r2 = self.radius * self.radius;
        let mut s = SecondGeometry::ZERO;
        s.d2g[0][0][1][1] = 2.0 * r2 * (2.0 * x[0]).cos();
        s.d2alpha[0][0][1] = -x[0].cos();
        s
    }
    fn curvature(&self, _x: Vec2) -> f64 {
        1.0 / (self.radius * self.radius)
    }
    fn killing_count(&self) -> usize {
        3
    }
    fn killing_names(&self) -> &'static [&'static str] {
        &["rotation about x", "rotation about y", "rotation about z"]
    }
    fn killing(&self, k: usize, x: Vec2) -> Vec3 {
        let (s, c) = x[0].sin_cos();
        let (sp, cp) = x[1].sin_cos();
        match k {
            0 => [-sp, -c / s * cp, cp / s],
            1 => [cp, -c / s * sp, sp / s],
            2 => [0.0, 1.0, 0.0],
            _ => [0.0; 3],
        }
    }
    fn killing_is_affine(&self, k: usize) -> bool {
        k == 2
    }
    fn embedding(&self) -> Option<&dyn Embedding> {
        Some(self)
    }
}

impl Embedding for Sphere {
    fn position(&self, x: Vec2) -> [f64; 3] {
        let n = self.normal(x);
        n.map(|v| self.radius * v)
    }
    fn normal(&self, x: Vec2) -> [f64; 3] {
        let (s, c) = x[0].sin_cos();
        let (sp, cp) = x[1].sin_cos();
        [s * cp, s * sp, c]
    }
    /// h = −g/R for the outward normal.
    fn second_fundamental_form(&self, x: Vec2) -> Mat2 {
        let s = x[0].sin();
        [[-self.radius, 0.0], [0.0, -self.radius * s * s]]
    }
    fn tangent(&self, x: Vec2, v: Vec2) -> [f64; 3] {
        let (s, c) = x[0].sin_cos();
        let (sp, cp) = x[1].sin_cos();
        let r = self.radius;
        [
            r * (c * cp * v[0] - s * sp * v[1]),
            r * (c * sp * v[0] + s * cp * v[1]),
            -r * s * v[0],
        ]
    }
    /// W = −diag(1, sin ϑ) (∂_μ n = ∂_μ X / R).
    fn shape(&self, x: Vec2) -> Shape {
        let (s, c) = x[0].sin_cos();
        Shape {
            w: [[-1.0, 0.0], [0.0, -s]],
            dw: [[[0.0, 0.0], [0.0, -c]], ZERO2],
        }
    }
    fn has_shape_second(&self) -> bool {
        true
    }
    /// ∂²_ϑ W₂₂ = sin ϑ; the rest zero.
    fn shape_second(&self, x: Vec2) -> [[Mat2; 2]; 2] {
        let mut d = [[ZERO2; 2]; 2];
        d[0][0][1][1] = x[0].sin();
        d
    }
}

/// The hyperbolic plane in the Poincaré half-plane x = (x, y), y > 0, g = (dx² + dy²)/y²
/// (002 (67)), Ê₁ = y∂x, Ê₂ = y∂y.
///
/// **Connection.** θ¹ = dx/y, θ² = dy/y: dθ² = 0 = −w∧θ¹ and dθ¹ = dx∧dy/y² = w∧θ² give
/// w = dx/y, α = (1/y, 0) (the cross term of 002 (68)); dw = dx∧dy/y² = dA, K = −1.
///
/// **Isometries** SL(2, ℝ) by z ↦ g(z) = (az + b)/(cz + d), z = x + iy (002 (69)). dg multiplies
/// tangent vectors by g′(z) = (cz + d)⁻², and Im g(z) = y|g′(z)|, so dg Ê₁(z) = e^{i arg g′(z)}
/// Ê₁(g(z)): the frame angle moves by ψ = arg g′(z) = −2 arg(cz + d) (002 (74)–(75) and (77);
/// 002 (76) prints this phase with the opposite sign). For a holomorphic Killing field ż = f(z),
/// ψ̇ = Im f′(z). The one-parameter groups exp(tE), exp(tH), exp(tF) give
/// f = 1, 2z, −z², so X_E = (1, 0, 0), X_H = (2x, 2y, 0), X_F = (y² − x², −2xy, −2y).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HyperbolicPlane;

impl Surface for HyperbolicPlane {
    fn name(&self) -> &'static str {
        "HyperbolicPlane"
    }
    fn domain(&self) -> &'static str {
        "y > 0 (the upper half-plane)"
    }
    /// Also refuses y so small that g = 1/y² overflows.
    fn contains(&self, x: Vec2) -> bool {
        finite2(x) && x[1] > 0.0 && normal_and_invertible(x[1])
    }
    fn metric(&self, x: Vec2) -> Mat2 {
        let a = 1.0 / (x[1] * x[1]);
        [[a, 0.0], [0.0, a]]
    }
    fn metric_derivatives(&self, x: Vec2) -> [Mat2; 2] {
        let d = -2.0 / (x[1] * x[1] * x[1]);
        [ZERO2, [[d, 0.0], [0.0, d]]]
    }
    fn frame(&self, x: Vec2) -> Mat2 {
        [[x[1], 0.0], [0.0, x[1]]]
    }
    fn connection(&self, x: Vec2) -> Vec2 {
        [1.0 / x[1], 0.0]
    }
    fn connection_derivatives(&self, x: Vec2) -> Mat2 {
        [[0.0, 0.0], [-1.0 / (x[1] * x[1]), 0.0]]
    }
    fn has_second_derivatives(&self) -> bool {
        true
    }
    /// ∂²_y g = 6/y⁴ Id, ∂²_y α₁ = 2/y³; the rest zero.
    fn second_derivatives(&self, x: Vec2) -> SecondGeometry {
        let y = x[1];
        let mut s = SecondGeometry::ZERO;
        let d = 6.0 / (y * y * y * y);
        s.d2g[1][1] = [[d, 0.0], [0.0, d]];
        s.d2alpha[1][1][0] = 2.0 / (y * y * y);
        s
    }
    fn curvature(&self, _x: Vec2) -> f64 {
        -1.0
    }
    fn killing_count(&self) -> usize {
        3
    }
    fn killing_names(&self) -> &'static [&'static str] {
        &["translation E", "dilation H", "special conformal F"]
    }
    fn killing(&self, k: usize, x: Vec2) -> Vec3 {
        let (a, b) = (x[0], x[1]);
        match k {
            0 => [1.0, 0.0, 0.0],
            1 => [2.0 * a, 2.0 * b, 0.0],
            2 => [b * b - a * a, -2.0 * a * b, -2.0 * b],
            _ => [0.0; 3],
        }
    }
    fn killing_is_affine(&self, k: usize) -> bool {
        k < 2
    }
}
