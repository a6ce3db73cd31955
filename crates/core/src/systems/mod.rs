//! The mechanical systems of the source texts, one folder per text, each system a
//! [`crate::integrate::Problem`] with the problem kinds it has and a
//! [`crate::integrate::Catalog`] of methods; the methods that only some of these systems have
//! live next to them.
//!
//! * [`tops`] (000 §3–§5, Lie–Poisson): [`RigidBody`] z = M (3), or (M, R) with R ∈ SO(3)
//!   row-major when it carries its attitude; [`GeneralizedRigidBody`] z = e_ij coordinates of
//!   M ∈ so(n) (n(n−1)/2, `lie::so::vee_n`); [`HeavyTop`] z = (M, Γ) (6), or (M, Γ, R) with
//!   Γ = Rᵀe₃; [`SphericalPendulum`] z = (q, L) (6), |q| = 1, q·L = 0; their own methods in
//!   [`tops::methods`] ([`Exact`], [`ExactSplitting`], [`Dmv`], [`Lgvi`], [`Isospectral`]).
//! * [`tangent_top`] (002): [`TangentTop`] z = (x¹, x², θ, p₁, p₂, p_θ) (6), the tangent Euler
//!   top on a [`Surface`]; [`ChargedParticle`] z = (x¹, x², p₁, p₂) (4), its magnetic analogue;
//!   §IV [`RelativisticTangentTop`] (Minkowski, or −dt² + g over a surface),
//!   [`StaticFieldTop`] (the static field −e^{2φ}dt² + dx², or + g over a surface) and
//!   [`WeakFieldTop`] (its weak-field
//!   limit) z = (x, y, θ, p_x, p_y, p_θ) (6).
//! * [`rolling`] (003): §1 [`RollingDisks`] z = (θ₁, θ₂, p₁, p₂) (4), two disks rolling against
//!   each other; §2 [`RollingSpheres`] z = (z₁, z₂, u, Ω₁, Ω₂) (27), two spheres rolling against
//!   each other (z_k ∈ SO(3) row-major, u ∈ S²).
//! * [`user`] (issue 15, user-defined systems): [`UserCanonical`] z = (q, p) (2d), H(q, p) from
//!   functions; [`UserSeparable`] z = (q, p) (2d), H = ½ pᵀM⁻¹p + U(q); [`LiePoisson`] z = μ ∈ g*
//!   (so(3), se(3), so(n) or structure constants, [`crate::lie::structure`]).
//! * [`test_problems`], the problem kinds the texts' systems do not cover: [`Pendulum`]
//!   z = (q, p) (2), canonical; [`SphereParticle`] z = (q, p) (6), a particle on the sphere
//!   |q| = l, q·p = 0 (holonomic); [`RollingDisk`] z = (x, y, θ, φ, p_x, p_y, p_θ, p_φ) (8), the
//!   vertical rolling disk (nonholonomic).

pub mod rolling;
pub mod tangent_top;
pub mod test_problems;
pub mod tops;
pub mod user;

pub use rolling::{RollingDisks, RollingSpheres};
pub use tangent_top::{
    ChargedParticle, FrameTop, Graph, HyperbolicPlane, MetricSurface, Plane, Potential,
    PotentialValue, RelativisticTangentTop, Revolution, Riemannian, RiemannianFrameTop, SpaceForm,
    SpaceTop, Sphere, StaticFieldTop, Surface, TangentTop, WeakFieldTop,
};
pub use test_problems::{Pendulum, RollingDisk, SphereParticle};
pub use tops::methods::{Dmv, Exact, ExactSplitting, Isospectral, Lgvi};
pub use tops::{GeneralizedRigidBody, HeavyTop, RigidBody, SphericalPendulum};
pub use user::{
    Algebra, KineticMass, LieHamiltonian, LiePoisson, Side, UserCanonical, UserSeparable,
};
