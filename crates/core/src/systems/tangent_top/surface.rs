//! Two-dimensional Riemannian surfaces in local coordinates, the stage of the tangent Euler top
//! (002 §II–III).
//!
//! A [`Surface`] gives, at a point x = (x¹, x²) of its chart:
//! - the metric g_ij(x) and its first derivatives ∂_k g_ij;
//! - a local orthonormal frame Ê_a = e_a^i ∂_i (a = 1, 2), positively oriented;
//! - the connection 1-form w = α_i dx^i of that frame, w(v) = ⟨∇_v Ê₁, Ê₂⟩ (the entry ω̂ of
//!   002 (43), written there as α dx¹ + β dx²), and its first derivatives ∂_k α_i; so
//!   ∇_v Ê₁ = w(v) Ê₂ and ∇_v Ê₂ = −w(v) Ê₁;
//! - the Gaussian curvature K, with Cartan's second structure equation dw = −K dA, i.e.
//!   K = −(∂₁α₂ − ∂₂α₁)/√det g (the sign follows from w(v) = ⟨∇_v Ê₁, Ê₂⟩; on the unit sphere
//!   α = (0, cos ϑ) gives dw = −sin ϑ dϑ∧dφ = −dA, K = 1);
//! - its domain, the Killing fields of its isometry group lifted to the frame bundle (the
//!   generators on (x¹, x², θ) that [`crate::systems::TangentTop`] turns into momenta), and
//!   optionally an [`Embedding`] in ℝ³.
//!
//! **Lifting an isometry to the frame angle.** An orientation-preserving isometry φ maps the
//! reference frame at x to dφ Ê₁(x) = cos ψ Ê₁(φx) + sin ψ Ê₂(φx) for an angle ψ(x), so it moves a
//! body at angle θ (E₁ = cos θ Ê₁ + sin θ Ê₂, 002 (41)) to θ + ψ(x). For a one-parameter group with
//! Killing field X the θ-component of the generator is ψ̇ = ⟨∇_{Ê₁}X, Ê₂⟩ − w(X) (differentiate
//! dφ_t Ê₁ along t and use [X, dφ_t Ê₁] = 0).
//!
//! Built-ins with closed forms (each derived below and checked against finite differences in
//! `tests/tangent_top.rs`): [`Plane`], [`Sphere`], [`HyperbolicPlane`], [`Revolution`], [`Graph`];
//! and the
//! numerical [`MetricSurface`] for a metric and frame given as closures.

use std::fmt;
use std::sync::Arc;

use crate::check;
use crate::error::{Error, Result};
use crate::integrate::problem::Violation;

/// A point or covector of the chart, (x¹, x²).
pub type Vec2 = [f64; 2];
/// A 2×2 matrix, `m[i][j]`.
pub type Mat2 = [[f64; 2]; 2];
/// A generator on the configuration space (x¹, x², θ) of the top.
pub type Vec3 = [f64; 3];

/// Everything the tangent top's kernels need at one point: g, ∂g, α, ∂α.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// g_ij.
    pub g: Mat2,
    /// `dg[k][i][j]` = ∂_k g_ij.
    pub dg: [Mat2; 2],
    /// α_i, w = α_i dx^i (002 (43)).
    pub alpha: Vec2,
    /// `dalpha[k][i]` = ∂_k α_i.
    pub dalpha: Mat2,
}

/// The shape operator of an embedded surface in the reference frame, W_aμ = e_a^α h_αμ
/// = −⟨Ê_a, ∂_μ n⟩, and its first derivatives: the normal turns by dn(v) = −(W v)_a Ê_a, so a body
/// point ξ^a E_a of the tangent top moves out of the tangent plane at the rate ⟨W v, ξ⟩ in the
/// reference frame (002 (35)–(37)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shape {
    /// `w[a][μ]` = W_aμ.
    pub w: Mat2,
    /// `dw[k][a][μ]` = ∂_k W_aμ.
    pub dw: [Mat2; 2],
}

/// A surface embedded in ℝ³ (002 §II.D): position, unit normal n = Ê₁ × Ê₂, the second
/// fundamental form h_ij = ⟨∂_i ∂_j X, n⟩ (the scalar form H_p of 002 (31) for this n) and the
/// shape operator in the frame with its derivatives ([`Shape`]).
pub trait Embedding {
    /// The point X(x) ∈ ℝ³.
    fn position(&self, x: Vec2) -> [f64; 3];
    /// The unit normal n = Ê₁ × Ê₂ at X(x) (ambient components).
    fn normal(&self, x: Vec2) -> [f64; 3];
    /// h_ij = ⟨∂_i ∂_j X, n⟩.
    fn second_fundamental_form(&self, x: Vec2) -> Mat2;
    /// The ambient components of a tangent vector v^i ∂_i: v^i ∂_i X.
    fn tangent(&self, x: Vec2, v: Vec2) -> [f64; 3];
    /// W = e h and ∂W at x ([`Shape`]).
    fn shape(&self, x: Vec2) -> Shape;
}

/// A two-dimensional Riemannian surface in a local chart with an orthonormal frame (module docs).
///
/// Object safe; systems hold it as `Arc<dyn Surface>` (cheap to clone).
pub trait Surface: Send + Sync + fmt::Debug {
    /// A short name for messages ("Sphere", …).
    fn name(&self) -> &'static str;

    /// The chart's domain in words ("0 < ϑ < π", …), for errors.
    fn domain(&self) -> &'static str;

    /// Whether x is a finite point of the chart's domain.
    fn contains(&self, x: Vec2) -> bool;

    /// [`Surface::contains`] as a [`Violation`] naming the domain.
    fn check(&self, x: Vec2) -> std::result::Result<(), Violation> {
        if self.contains(x) {
            Ok(())
        } else {
            Err(Violation {
                what: format!("{} chart", self.name()),
                message: format!(
                    "the point x = ({}, {}) lies outside the chart's domain {}",
                    x[0],
                    x[1],
                    self.domain()
                ),
            })
        }
    }

    /// The metric g_ij(x).
    fn metric(&self, x: Vec2) -> Mat2;

    /// Whether the surface is given by functions from outside lieflow (closures of a user or
    /// of a binding), which a system on it then calls ([`crate::integrate::Problem::calls_out`]).
    fn calls_out(&self) -> bool {
        false
    }

    /// `[k][i][j]` = ∂_k g_ij(x).
    fn metric_derivatives(&self, x: Vec2) -> [Mat2; 2];

    /// The orthonormal frame: `e[a][i]` = e_a^i, Ê_a = e_a^i ∂_i (positively oriented).
    fn frame(&self, x: Vec2) -> Mat2;

    /// α_i(x) of w = α_i dx^i, w(v) = ⟨∇_v Ê₁, Ê₂⟩ (002 (43)).
    fn connection(&self, x: Vec2) -> Vec2;

    /// `[k][i]` = ∂_k α_i(x).
    fn connection_derivatives(&self, x: Vec2) -> Mat2;

    /// g, ∂g, α, ∂α at once (surfaces that share work between them override it).
    fn geometry(&self, x: Vec2) -> Geometry {
        Geometry {
            g: self.metric(x),
            dg: self.metric_derivatives(x),
            alpha: self.connection(x),
            dalpha: self.connection_derivatives(x),
        }
    }

    /// The Gaussian curvature K = −(∂₁α₂ − ∂₂α₁)/√det g (Cartan: dw = −K dA).
    fn curvature(&self, x: Vec2) -> f64 {
        let da = self.connection_derivatives(x);
        -(da[0][1] - da[1][0]) / det(&self.metric(x)).sqrt()
    }

    /// The number of Killing generators [`Surface::killing`] lists.
    fn killing_count(&self) -> usize {
        0
    }

    /// The names of the Killing generators, in order.
    fn killing_names(&self) -> &'static [&'static str] {
        &[]
    }

    /// The k-th Killing generator lifted to (x¹, x², θ): (X¹, X², ψ̇) (module docs); zeros for
    /// k ≥ [`Surface::killing_count`].
    fn killing(&self, _k: usize, _x: Vec2) -> Vec3 {
        [0.0; 3]
    }

    /// Whether the k-th generator is affine in (x, θ): its momentum p_A X^A is then quadratic in
    /// the canonical state, and the Gauss methods keep it to round-off.
    fn killing_is_affine(&self, _k: usize) -> bool {
        false
    }

    /// The embedding in ℝ³, for embedded surfaces.
    fn embedding(&self) -> Option<&dyn Embedding> {
        None
    }
}

/// The momenta J_k = p_A X_k^A of a surface's Killing generators lifted to the frame bundle, at
/// a state z = (x¹, x², θ, p₁, p₂, p_θ) of a body carried by a frame (the tangent tops), in the
/// order of [`Surface::killing`]; with `affine_only`, those of the affine generators only (the
/// ones quadratic in z). Noether's theorem makes them conserved for every Lagrangian on the frame
/// bundle invariant under the lifted isometries.
pub fn killing_momenta(surface: &dyn Surface, z: &[f64], affine_only: bool) -> Vec<f64> {
    let x = [z[0], z[1]];
    (0..surface.killing_count())
        .filter(|&k| !affine_only || surface.killing_is_affine(k))
        .map(|k| {
            let xk = surface.killing(k, x);
            (0..3).map(|a| z[3 + a] * xk[a]).sum()
        })
        .collect()
}

/// det of a 2×2 matrix.
pub fn det(m: &Mat2) -> f64 {
    m[0][0] * m[1][1] - m[0][1] * m[1][0]
}

/// The inverse of a 2×2 matrix (non-finite entries if it is singular).
pub fn inverse(m: &Mat2) -> Mat2 {
    let d = det(m);
    [[m[1][1] / d, -m[0][1] / d], [-m[1][0] / d, m[0][0] / d]]
}

const ZERO2: Mat2 = [[0.0; 2]; 2];

fn finite2(x: Vec2) -> bool {
    x[0].is_finite() && x[1].is_finite()
}

/// Whether a length scale s > 0 has s² and 1/s² both normal and finite.
fn normal_and_invertible(s: f64) -> bool {
    let s2 = s * s;
    s2 >= f64::MIN_POSITIVE && (1.0 / s2).is_finite()
}

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
    fn curvature(&self, _x: Vec2) -> f64 {
        -1.0
    }
    fn killing_count(&self) -> usize {
        3
    }
    fn killing_names(&self) -> &'static [&'static str] {
        &["E (translation)", "H (dilation)", "F"]
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

/// A profile function s ↦ (f(s), f′(s), f″(s), f‴(s)) (the third derivative enters only the
/// shape operator's derivative, i.e. the embedded top).
pub type Profile = Arc<dyn Fn(f64) -> [f64; 4] + Send + Sync>;

/// A surface of revolution X(s, φ) = (r(s) cos φ, r(s) sin φ, z(s)) about the z axis, from the
/// profile functions r and z with their first three derivatives, on s_min < s < s_max with
/// r(s) > 0. Coordinates x = (s, φ); with λ = √(r′² + z′²):
/// g = diag(λ², r²), Ê₁ = ∂s/λ, Ê₂ = ∂φ/r.
///
/// **Connection.** θ¹ = λ ds, θ² = r dφ: dθ¹ = 0, dθ² = r′ ds∧dφ = −w∧θ¹, so w = (r′/λ) dφ,
/// α = (0, r′/λ), ∂_s α_φ = z′(r″z′ − r′z″)/λ³, K = z′(r′z″ − r″z′)/(λ⁴ r) (the sphere's profile
/// r = R sin s, z = R cos s gives back [`Sphere`]). The Killing field ∂/∂φ moves the frame along
/// (ψ = 0): X_φ = (0, 1, 0), momentum p_φ (002 §III.A).
///
/// **Embedding.** n = Ê₁ × Ê₂ = (−z′ cos φ, −z′ sin φ, r′)/λ,
/// h = diag((r′z″ − z′r″)/λ, r z′/λ), so W = e h = diag((r′z″ − z′r″)/λ², z′/λ).
#[derive(Clone)]
pub struct Revolution {
    r: Profile,
    z: Profile,
    range: (f64, f64),
    /// Made by [`Revolution::new`] from the caller's functions.
    user: bool,
}

impl fmt::Debug for Revolution {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Revolution")
            .field("range", &self.range)
            .finish_non_exhaustive()
    }
}

impl Revolution {
    /// The surface of the profile r(s), z(s) (each returning the value and its first three
    /// derivatives) on s_min < s < s_max. Errors: a non-finite or empty range.
    pub fn new(
        r: impl Fn(f64) -> [f64; 4] + Send + Sync + 'static,
        z: impl Fn(f64) -> [f64; 4] + Send + Sync + 'static,
        range: (f64, f64),
    ) -> Result<Self> {
        Ok(Revolution {
            user: true,
            ..Revolution::built_in(r, z, range)?
        })
    }

    /// [`Revolution::new`] for the profiles of lieflow's own surfaces.
    fn built_in(
        r: impl Fn(f64) -> [f64; 4] + Send + Sync + 'static,
        z: impl Fn(f64) -> [f64; 4] + Send + Sync + 'static,
        range: (f64, f64),
    ) -> Result<Self> {
        check::finite_slice("range", &[range.0, range.1])?;
        if range.0 >= range.1 {
            return Err(Error::invalid(
                "range",
                format!("expected s_min < s_max, got ({}, {})", range.0, range.1),
            ));
        }
        Ok(Revolution {
            r: Arc::new(r),
            z: Arc::new(z),
            range,
            user: false,
        })
    }

    /// The sphere of radius R as a surface of revolution: r = R sin s, z = R cos s, 0 < s < π.
    pub fn sphere(radius: f64) -> Result<Self> {
        check::positive("radius", radius)?;
        let rr = radius;
        Revolution::built_in(
            move |s| {
                let (sn, cs) = s.sin_cos();
                [rr * sn, rr * cs, -rr * sn, -rr * cs]
            },
            move |s| {
                let (sn, cs) = s.sin_cos();
                [rr * cs, -rr * sn, -rr * cs, rr * sn]
            },
            (0.0, std::f64::consts::PI),
        )
    }

    /// The torus of radii a > b > 0: r = a + b cos s, z = b sin s, s ∈ (−π, π) (the inner circle
    /// s = ±π is left out of the chart).
    pub fn torus(a: f64, b: f64) -> Result<Self> {
        check::positive("a", a)?;
        check::positive("b", b)?;
        if b >= a {
            return Err(Error::invalid(
                "b",
                format!("a torus needs b < a, got a = {a}, b = {b}"),
            ));
        }
        Revolution::built_in(
            move |s| {
                let (sn, cs) = s.sin_cos();
                [a + b * cs, -b * sn, -b * cs, b * sn]
            },
            move |s| {
                let (sn, cs) = s.sin_cos();
                [b * sn, b * cs, -b * sn, -b * cs]
            },
            (-std::f64::consts::PI, std::f64::consts::PI),
        )
    }

    /// (r, r′, r″, z′, z″, λ) at s.
    fn profile(&self, s: f64) -> (f64, f64, f64, f64, f64, f64) {
        let [r, dr, ddr, _] = (self.r)(s);
        let [_, dz, ddz, _] = (self.z)(s);
        (r, dr, ddr, dz, ddz, (dr * dr + dz * dz).sqrt())
    }
}

impl Surface for Revolution {
    fn name(&self) -> &'static str {
        "Revolution"
    }
    fn calls_out(&self) -> bool {
        self.user
    }
    fn domain(&self) -> &'static str {
        "s_min < s < s_max with r(s) > 0 and a regular profile"
    }
    fn contains(&self, x: Vec2) -> bool {
        if !(finite2(x) && x[0] > self.range.0 && x[0] < self.range.1) {
            return false;
        }
        let (r, dr, ddr, dz, ddz, l) = self.profile(x[0]);
        r > 0.0
            && normal_and_invertible(r)
            && normal_and_invertible(l)
            && [r, dr, ddr, dz, ddz, l].iter().all(|v| v.is_finite())
    }
    fn metric(&self, x: Vec2) -> Mat2 {
        let (r, _, _, _, _, l) = self.profile(x[0]);
        [[l * l, 0.0], [0.0, r * r]]
    }
    fn metric_derivatives(&self, x: Vec2) -> [Mat2; 2] {
        let (r, dr, ddr, dz, ddz, _) = self.profile(x[0]);
        [
            [[2.0 * (dr * ddr + dz * ddz), 0.0], [0.0, 2.0 * r * dr]],
            ZERO2,
        ]
    }
    fn frame(&self, x: Vec2) -> Mat2 {
        let (r, _, _, _, _, l) = self.profile(x[0]);
        [[1.0 / l, 0.0], [0.0, 1.0 / r]]
    }
    fn connection(&self, x: Vec2) -> Vec2 {
        let (_, dr, _, _, _, l) = self.profile(x[0]);
        [0.0, dr / l]
    }
    fn connection_derivatives(&self, x: Vec2) -> Mat2 {
        let (_, dr, ddr, dz, ddz, l) = self.profile(x[0]);
        [[0.0, dz * (ddr * dz - dr * ddz) / (l * l * l)], ZERO2[1]]
    }
    fn geometry(&self, x: Vec2) -> Geometry {
        let (r, dr, ddr, dz, ddz, l) = self.profile(x[0]);
        Geometry {
            g: [[l * l, 0.0], [0.0, r * r]],
            dg: [
                [[2.0 * (dr * ddr + dz * ddz), 0.0], [0.0, 2.0 * r * dr]],
                ZERO2,
            ],
            alpha: [0.0, dr / l],
            dalpha: [[0.0, dz * (ddr * dz - dr * ddz) / (l * l * l)], [0.0, 0.0]],
        }
    }
    fn curvature(&self, x: Vec2) -> f64 {
        let (r, dr, ddr, dz, ddz, l) = self.profile(x[0]);
        dz * (dr * ddz - ddr * dz) / (l * l * l * l * r)
    }
    fn killing_count(&self) -> usize {
        1
    }
    fn killing_names(&self) -> &'static [&'static str] {
        &["rotation about z"]
    }
    fn killing(&self, k: usize, _x: Vec2) -> Vec3 {
        if k == 0 {
            [0.0, 1.0, 0.0]
        } else {
            [0.0; 3]
        }
    }
    fn killing_is_affine(&self, k: usize) -> bool {
        k == 0
    }
    fn embedding(&self) -> Option<&dyn Embedding> {
        Some(self)
    }
}

impl Embedding for Revolution {
    fn position(&self, x: Vec2) -> [f64; 3] {
        let r = (self.r)(x[0])[0];
        let z = (self.z)(x[0])[0];
        let (sp, cp) = x[1].sin_cos();
        [r * cp, r * sp, z]
    }
    fn normal(&self, x: Vec2) -> [f64; 3] {
        let (_, dr, _, dz, _, l) = self.profile(x[0]);
        let (sp, cp) = x[1].sin_cos();
        [-dz * cp / l, -dz * sp / l, dr / l]
    }
    fn second_fundamental_form(&self, x: Vec2) -> Mat2 {
        let (r, dr, ddr, dz, ddz, l) = self.profile(x[0]);
        [[(dr * ddz - dz * ddr) / l, 0.0], [0.0, r * dz / l]]
    }
    fn tangent(&self, x: Vec2, v: Vec2) -> [f64; 3] {
        let (r, dr, _, dz, _, _) = self.profile(x[0]);
        let (sp, cp) = x[1].sin_cos();
        [
            dr * cp * v[0] - r * sp * v[1],
            dr * sp * v[0] + r * cp * v[1],
            dz * v[0],
        ]
    }
    /// W₁₁ = k/λ², W₂₂ = z′/λ with k = r′z″ − z′r″, λ² = r′² + z′²; ∂_s by the quotient rule
    /// (k′ = r′z‴ − z′r‴, (λ²)′ = 2(r′r″ + z′z″)).
    fn shape(&self, x: Vec2) -> Shape {
        let [_, dr, ddr, dddr] = (self.r)(x[0]);
        let [_, dz, ddz, dddz] = (self.z)(x[0]);
        let l2 = dr * dr + dz * dz;
        let l = l2.sqrt();
        let dl2 = 2.0 * (dr * ddr + dz * ddz);
        let k = dr * ddz - dz * ddr;
        let dk = dr * dddz - dz * dddr;
        Shape {
            w: [[k / l2, 0.0], [0.0, dz / l]],
            dw: [
                [
                    [dk / l2 - k * dl2 / (l2 * l2), 0.0],
                    [0.0, ddz / l - 0.5 * dz * dl2 / (l2 * l)],
                ],
                ZERO2,
            ],
        }
    }
}

/// The derivatives of a function f(x, y) at a point, up to third order.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Jet {
    /// f.
    pub value: f64,
    /// (f_x, f_y).
    pub gradient: Vec2,
    /// [[f_xx, f_xy], [f_xy, f_yy]].
    pub hessian: Mat2,
    /// (f_xxx, f_xxy, f_xyy, f_yyy).
    pub third: [f64; 4],
}

impl Jet {
    fn is_finite(&self) -> bool {
        self.value.is_finite()
            && finite2(self.gradient)
            && self.hessian.iter().flatten().all(|v| v.is_finite())
            && self.third.iter().all(|v| v.is_finite())
    }

    /// f_ijk (symmetric; the number of y's among i, j, k picks the entry).
    fn t(&self, i: usize, j: usize, k: usize) -> f64 {
        self.third[i + j + k]
    }
}

/// A graph z = f(x, y) over the plane, coordinates x = (x, y), from the jet of f (value and
/// derivatives to third order; [`Jet`]).
///
/// With p = f_x, q = f_y, u = 1 + p², D = 1 + p² + q²: g_ij = δ_ij + f_i f_j (det g = D),
/// ∂_k g_ij = f_ik f_j + f_i f_jk; the frame is Gram–Schmidt of (∂x, ∂y),
/// Ê₁ = ∂x/√u, Ê₂ = (−pq ∂x + u ∂y)/√(uD); n = (−p, −q, 1)/√D = Ê₁ × Ê₂; h_ij = f_ij/√D.
///
/// **Connection.** In ℝ³, Ê₁ = (1, 0, p)/√u and Ê₂ = (−pq, u, q)/√(uD); the tangential part of
/// ∂_i Ê₁ is ∇_{∂_i}Ê₁, so α_i = ⟨∂_i Ê₁, Ê₂⟩ = f_xi q/(u√D) (the ∂_i(1/√u) part is along Ê₁).
/// K = (f_xx f_yy − f_xy²)/D².
/// No Killing fields in general (a quadric of revolution is better served by [`Revolution`]).
#[derive(Clone)]
pub struct Graph {
    jet: Arc<dyn Fn(Vec2) -> Jet + Send + Sync>,
    /// Made by [`Graph::new`] from the caller's function.
    user: bool,
}

impl fmt::Debug for Graph {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Graph").finish_non_exhaustive()
    }
}

/// What the graph's formulas share at one point.
struct GraphLocal {
    j: Jet,
    u: f64,
    d: f64,
    /// ∂_k u, ∂_k D.
    du: Vec2,
    dd: Vec2,
}

impl Graph {
    /// The graph of f given by its jet (module docs of [`Graph`]).
    pub fn new(jet: impl Fn(Vec2) -> Jet + Send + Sync + 'static) -> Self {
        Graph {
            jet: Arc::new(jet),
            user: true,
        }
    }

    /// The quadric z = (a x² + b y²)/2: a paraboloid for ab > 0, a saddle for ab < 0, a cylinder
    /// when one is zero. Errors: a non-finite coefficient.
    pub fn quadric(a: f64, b: f64) -> Result<Self> {
        check::finite_slice("a and b", &[a, b])?;
        Ok(Graph {
            user: false,
            ..Graph::new(move |x| Jet {
                value: 0.5 * (a * x[0] * x[0] + b * x[1] * x[1]),
                gradient: [a * x[0], b * x[1]],
                hessian: [[a, 0.0], [0.0, b]],
                third: [0.0; 4],
            })
        })
    }

    fn local(&self, x: Vec2) -> GraphLocal {
        let j = (self.jet)(x);
        let ([p, q], h) = (j.gradient, j.hessian);
        GraphLocal {
            j,
            u: 1.0 + p * p,
            d: 1.0 + p * p + q * q,
            du: [2.0 * p * h[0][0], 2.0 * p * h[0][1]],
            dd: std::array::from_fn(|k| 2.0 * (p * h[0][k] + q * h[1][k])),
        }
    }

    /// The frame e and its derivatives ∂_k e.
    fn frame_and_derivatives(l: &GraphLocal) -> (Mat2, [Mat2; 2]) {
        let ([p, q], h) = (l.j.gradient, l.j.hessian);
        let (u, d) = (l.u, l.d);
        let a = 1.0 / u.sqrt();
        let c = 1.0 / (u * d).sqrt();
        let e = [[a, 0.0], [-p * q * c, u * c]];
        let de = std::array::from_fn(|k| {
            let da = -0.5 * a * l.du[k] / u;
            let dc = -0.5 * c * (l.du[k] / u + l.dd[k] / d);
            let dpq = h[0][k] * q + p * h[1][k];
            [[da, 0.0], [-dpq * c - p * q * dc, l.du[k] * c + u * dc]]
        });
        (e, de)
    }
}

impl Surface for Graph {
    fn name(&self) -> &'static str {
        "Graph"
    }
    fn calls_out(&self) -> bool {
        self.user
    }
    fn domain(&self) -> &'static str {
        "the points where f and its derivatives are finite"
    }
    fn contains(&self, x: Vec2) -> bool {
        finite2(x) && (self.jet)(x).is_finite()
    }
    fn metric(&self, x: Vec2) -> Mat2 {
        let [p, q] = (self.jet)(x).gradient;
        [[1.0 + p * p, p * q], [p * q, 1.0 + q * q]]
    }
    fn metric_derivatives(&self, x: Vec2) -> [Mat2; 2] {
        let j = (self.jet)(x);
        let (f, h) = (j.gradient, j.hessian);
        std::array::from_fn(|k| {
            std::array::from_fn(|a| std::array::from_fn(|b| h[a][k] * f[b] + f[a] * h[b][k]))
        })
    }
    fn frame(&self, x: Vec2) -> Mat2 {
        Graph::frame_and_derivatives(&self.local(x)).0
    }
    fn connection(&self, x: Vec2) -> Vec2 {
        let l = self.local(x);
        let q = l.j.gradient[1];
        let den = l.u * l.d.sqrt();
        [l.j.hessian[0][0] * q / den, l.j.hessian[0][1] * q / den]
    }
    /// ∂_k α_i = (f_xik q + f_xi f_yk)/(u√D) − α_i (∂_k u/u + ½ ∂_k D/D).
    fn connection_derivatives(&self, x: Vec2) -> Mat2 {
        let l = self.local(x);
        let (q, h) = (l.j.gradient[1], l.j.hessian);
        let den = l.u * l.d.sqrt();
        std::array::from_fn(|k| {
            let dlog = l.du[k] / l.u + 0.5 * l.dd[k] / l.d;
            std::array::from_fn(|i| {
                let alpha = h[0][i] * q / den;
                (l.j.t(0, i, k) * q + h[0][i] * h[1][k]) / den - alpha * dlog
            })
        })
    }
    fn curvature(&self, x: Vec2) -> f64 {
        let l = self.local(x);
        det(&l.j.hessian) / (l.d * l.d)
    }
    fn embedding(&self) -> Option<&dyn Embedding> {
        Some(self)
    }
}

impl Embedding for Graph {
    fn position(&self, x: Vec2) -> [f64; 3] {
        [x[0], x[1], (self.jet)(x).value]
    }
    fn normal(&self, x: Vec2) -> [f64; 3] {
        let [p, q] = (self.jet)(x).gradient;
        let r = (1.0 + p * p + q * q).sqrt();
        [-p / r, -q / r, 1.0 / r]
    }
    fn second_fundamental_form(&self, x: Vec2) -> Mat2 {
        let j = (self.jet)(x);
        let [p, q] = j.gradient;
        let r = (1.0 + p * p + q * q).sqrt();
        j.hessian.map(|row| row.map(|v| v / r))
    }
    fn tangent(&self, x: Vec2, v: Vec2) -> [f64; 3] {
        let [p, q] = (self.jet)(x).gradient;
        [v[0], v[1], p * v[0] + q * v[1]]
    }
    /// W = e h, ∂_k W = (∂_k e) h + e ∂_k h with ∂_k h_ij = f_ijk/√D − ½ f_ij ∂_k D/D^{3/2}.
    fn shape(&self, x: Vec2) -> Shape {
        let l = self.local(x);
        let (e, de) = Graph::frame_and_derivatives(&l);
        let r = l.d.sqrt();
        let h: Mat2 = l.j.hessian.map(|row| row.map(|v| v / r));
        let dh: [Mat2; 2] = std::array::from_fn(|k| {
            std::array::from_fn(|i| {
                std::array::from_fn(|jj| {
                    l.j.t(i, jj, k) / r - 0.5 * l.j.hessian[i][jj] * l.dd[k] / (l.d * r)
                })
            })
        });
        Shape {
            w: mul(&e, &h),
            dw: std::array::from_fn(|k| add(&mul(&de[k], &h), &mul(&e, &dh[k]))),
        }
    }
}

/// The product of 2×2 matrices.
pub fn mul(a: &Mat2, b: &Mat2) -> Mat2 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
}

/// The sum of 2×2 matrices.
pub fn add(a: &Mat2, b: &Mat2) -> Mat2 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] + b[i][j]))
}

/// A closure of the chart returning a 2×2 matrix.
pub type MatrixField = Arc<dyn Fn(Vec2) -> Mat2 + Send + Sync>;
/// A closure deciding the chart's domain.
pub type DomainFn = Arc<dyn Fn(Vec2) -> bool + Send + Sync>;

/// A general surface from closures: the metric g(x) and an orthonormal frame e(x) (`e[a][i]` =
/// e_a^i). **Numerical**: ∂g by fourth-order central differences (step ε^{1/5}·max(1, |x^k|)), α
/// from its definition α_i = ⟨∇_{∂_i} Ê₁, Ê₂⟩ = g_jk (∂_i e₁^j + Γ^j_{il} e₁^l) e₂^k with the
/// Christoffel symbols of those differences, ∂α by fourth-order differences of α (step
/// 5e-3·max(1, |x^k|)) and K = −(∂₁α₂ − ∂₂α₁)/√det g. Expect errors of about 1e-12 in ∂g and α
/// and 1e-9 in ∂α and K for smooth data of order one. No Killing fields, no embedding.
#[derive(Clone)]
pub struct MetricSurface {
    metric: MatrixField,
    frame: MatrixField,
    domain: Option<DomainFn>,
}

impl fmt::Debug for MetricSurface {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("MetricSurface").finish_non_exhaustive()
    }
}

/// Step of the first-level differences (≈ ε^{1/5}).
const H1: f64 = 7e-4;
/// Step of the differences of α.
const H2: f64 = 5e-3;

/// Fourth-order central difference of f along coordinate k at x with step h·max(1, |x_k|).
fn diff4<const N: usize>(f: impl Fn(Vec2) -> [f64; N], x: Vec2, k: usize, h: f64) -> [f64; N] {
    let h = h * x[k].abs().max(1.0);
    let at = |t: f64| {
        let mut y = x;
        y[k] += t;
        f(y)
    };
    let (p1, m1, p2, m2) = (at(h), at(-h), at(2.0 * h), at(-2.0 * h));
    std::array::from_fn(|i| (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * h))
}

fn flat(m: Mat2) -> [f64; 4] {
    [m[0][0], m[0][1], m[1][0], m[1][1]]
}

fn unflat(v: [f64; 4]) -> Mat2 {
    [[v[0], v[1]], [v[2], v[3]]]
}

impl MetricSurface {
    /// A surface from a metric and an orthonormal frame given as closures, on the points where
    /// `domain` holds (and g is finite and positive definite). Errors: none here; the frame is
    /// checked against the metric at a point by [`MetricSurface::check_frame`].
    pub fn new(
        metric: impl Fn(Vec2) -> Mat2 + Send + Sync + 'static,
        frame: impl Fn(Vec2) -> Mat2 + Send + Sync + 'static,
        domain: Option<DomainFn>,
    ) -> Self {
        MetricSurface {
            metric: Arc::new(metric),
            frame: Arc::new(frame),
            domain,
        }
    }

    /// Checks at x that the frame is orthonormal and positively oriented for the metric
    /// (g(Ê_a, Ê_b) = δ_ab within `tol`, det e > 0). Errors: [`Error::InvalidArgument`].
    pub fn check_frame(&self, x: Vec2, tol: f64) -> Result<()> {
        if !self.contains(x) {
            return Err(Error::invalid(
                "x",
                format!("({}, {}) lies outside the domain", x[0], x[1]),
            ));
        }
        let g = (self.metric)(x);
        let e = (self.frame)(x);
        for a in 0..2 {
            for b in 0..2 {
                let gab = inner(&g, e[a], e[b]);
                let want = if a == b { 1.0 } else { 0.0 };
                if (gab - want).abs().is_nan() || (gab - want).abs() > tol {
                    return Err(Error::invalid(
                        "frame",
                        format!("g(Ê_{}, Ê_{}) = {gab}, expected {want}", a + 1, b + 1),
                    ));
                }
            }
        }
        if det(&e).is_nan() || det(&e) <= 0.0 {
            return Err(Error::invalid(
                "frame",
                "the frame must be positively oriented (det e > 0)",
            ));
        }
        Ok(())
    }

    fn dg(&self, x: Vec2) -> [Mat2; 2] {
        let f = |y: Vec2| flat((self.metric)(y));
        [unflat(diff4(f, x, 0, H1)), unflat(diff4(f, x, 1, H1))]
    }

    fn alpha(&self, x: Vec2) -> Vec2 {
        let g = (self.metric)(x);
        let dg = self.dg(x);
        let e = (self.frame)(x);
        let fe = |y: Vec2| (self.frame)(y)[0];
        let de1 = [diff4(fe, x, 0, H1), diff4(fe, x, 1, H1)];
        std::array::from_fn(|i| {
            // g_jk ∂_i e₁^j e₂^k + Γ_{k,il} e₁^l e₂^k, Γ_{k,il} = ½(∂_i g_kl + ∂_l g_ki − ∂_k g_il).
            let mut a = inner(&g, de1[i], e[1]);
            for k in 0..2 {
                for l in 0..2 {
                    let gam = 0.5 * (dg[i][k][l] + dg[l][k][i] - dg[k][i][l]);
                    a += gam * e[0][l] * e[1][k];
                }
            }
            a
        })
    }
}

/// g(u, v) = g_ij u^i v^j.
pub fn inner(g: &Mat2, u: Vec2, v: Vec2) -> f64 {
    let mut s = 0.0;
    for i in 0..2 {
        for j in 0..2 {
            s += g[i][j] * u[i] * v[j];
        }
    }
    s
}

impl Surface for MetricSurface {
    fn name(&self) -> &'static str {
        "MetricSurface"
    }
    fn calls_out(&self) -> bool {
        true
    }
    fn domain(&self) -> &'static str {
        "the given domain, where g is positive definite"
    }
    fn contains(&self, x: Vec2) -> bool {
        if !finite2(x) || !self.domain.as_ref().map_or(true, |d| d(x)) {
            return false;
        }
        let g = (self.metric)(x);
        g.iter().flatten().all(|v| v.is_finite()) && g[0][0] > 0.0 && det(&g) > 0.0
    }
    fn metric(&self, x: Vec2) -> Mat2 {
        (self.metric)(x)
    }
    fn metric_derivatives(&self, x: Vec2) -> [Mat2; 2] {
        self.dg(x)
    }
    fn frame(&self, x: Vec2) -> Mat2 {
        (self.frame)(x)
    }
    fn connection(&self, x: Vec2) -> Vec2 {
        self.alpha(x)
    }
    fn connection_derivatives(&self, x: Vec2) -> Mat2 {
        let f = |y: Vec2| self.alpha(y);
        [diff4(f, x, 0, H2), diff4(f, x, 1, H2)]
    }
}
