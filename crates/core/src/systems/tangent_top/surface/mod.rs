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
//! - optionally the second derivatives ∂²g, ∂²α ([`SecondGeometry`]; and ∂²W of an embedding),
//!   in closed form for [`Plane`], [`Sphere`], [`HyperbolicPlane`] and (intrinsically)
//!   [`Revolution`]: the Hessian of the tangent top's Hamiltonian, its tangent lift, needs them;
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
//! Built-ins with closed forms (each derived in its docs and checked against finite differences in
//! `tests/tangent_top.rs`): [`Plane`], [`Sphere`], [`HyperbolicPlane`], [`Revolution`], [`Graph`];
//! and the
//! numerical [`MetricSurface`] for a metric and frame given as closures.

mod constant_curvature;
mod graph;
mod metric;
mod revolution;

use std::fmt;

use crate::integrate::problem::Violation;

pub use constant_curvature::{HyperbolicPlane, Plane, Sphere};
pub use graph::{Graph, Jet};
pub use metric::{DomainFn, MatrixField, MetricSurface};
pub use revolution::{Profile, Revolution};

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

/// The second derivatives of g and α at one point, for the Hessian of the tangent top's
/// Hamiltonian (its tangent lift): `d2g[k][l]` = ∂_k∂_l g, `d2alpha[k][l]` = ∂_k∂_l α (both
/// symmetric in k, l).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SecondGeometry {
    /// `d2g[k][l][i][j]` = ∂_k∂_l g_ij.
    pub d2g: [[Mat2; 2]; 2],
    /// `d2alpha[k][l][i]` = ∂_k∂_l α_i.
    pub d2alpha: [[Vec2; 2]; 2],
}

impl SecondGeometry {
    /// Zero (a flat chart with a parallel frame).
    pub const ZERO: SecondGeometry = SecondGeometry {
        d2g: [[ZERO2; 2]; 2],
        d2alpha: [[[0.0; 2]; 2]; 2],
    };

    /// NaN (a surface without second derivatives).
    pub const NAN: SecondGeometry = SecondGeometry {
        d2g: [[[[f64::NAN; 2]; 2]; 2]; 2],
        d2alpha: [[[f64::NAN; 2]; 2]; 2],
    };
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

    /// Whether [`Embedding::shape_second`] is given (the embedded top's tangent lift needs it).
    fn has_shape_second(&self) -> bool {
        false
    }

    /// `[k][l][a][μ]` = ∂_k∂_l W_aμ at x; NaN unless [`Embedding::has_shape_second`].
    fn shape_second(&self, _x: Vec2) -> [[Mat2; 2]; 2] {
        [[[[f64::NAN; 2]; 2]; 2]; 2]
    }
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

    /// Whether [`Surface::second_derivatives`] is given in closed form (the tangent lift of a
    /// top on the surface needs it: the Hessian of its Hamiltonian).
    fn has_second_derivatives(&self) -> bool {
        false
    }

    /// ∂²g and ∂²α at x ([`SecondGeometry`]); NaN unless
    /// [`Surface::has_second_derivatives`].
    fn second_derivatives(&self, _x: Vec2) -> SecondGeometry {
        SecondGeometry::NAN
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

/// The label of the k-th Killing momentum: "J(name)" with the generator's name
/// ([`Surface::killing_names`]; "J(generator k)" for a generator without one).
pub fn killing_momentum_name(surface: &dyn Surface, k: usize) -> String {
    match surface.killing_names().get(k) {
        Some(name) => format!("J({name})"),
        None => format!("J(generator {k})"),
    }
}

/// The labels of [`killing_momenta`] ([`killing_momentum_name`]).
pub fn killing_momentum_names(surface: &dyn Surface, affine_only: bool) -> Vec<String> {
    (0..surface.killing_count())
        .filter(|&k| !affine_only || surface.killing_is_affine(k))
        .map(|k| killing_momentum_name(surface, k))
        .collect()
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

/// The product of 2×2 matrices.
pub fn mul(a: &Mat2, b: &Mat2) -> Mat2 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
}

/// The sum of 2×2 matrices.
pub fn add(a: &Mat2, b: &Mat2) -> Mat2 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] + b[i][j]))
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
