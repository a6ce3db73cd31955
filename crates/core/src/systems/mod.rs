//! Lie–Poisson systems of 000 §3–§5: the free rigid body on so(3)* and so(n)*, the heavy top and
//! the spherical pendulum. Each implements [`crate::integrate::System`].
//!
//! State layouts (flat f64 arrays, see each type):
//! * [`RigidBody`]: z = M (3), optional attitude R (3×3 row-major);
//! * [`GeneralizedRigidBody`]: z = e_ij coordinates of M ∈ so(n) (n(n−1)/2, `lie::so::vee_n`);
//! * [`HeavyTop`]: z = (M, Γ) (6), optional attitude R with Γ = Rᵀe₃;
//! * [`SphericalPendulum`]: z = (q, L) (6), |q| = 1, q·L = 0.

pub mod heavy_top;
pub mod rigid_body;
pub mod spherical_pendulum;
mod top;

pub use heavy_top::HeavyTop;
pub use rigid_body::{GeneralizedRigidBody, RigidBody};
pub use spherical_pendulum::SphericalPendulum;
