//! 000 §3–§5: the Lie–Poisson bodies. The free rigid body on so(3)* ([`RigidBody`]) and so(n)*
//! ([`GeneralizedRigidBody`]), the heavy top on se(3)* ([`HeavyTop`]) and the spherical pendulum
//! on e(3)* ([`SphericalPendulum`]); `top` holds what the SO(3) bodies share (frames, layout, the
//! sub-flows of their splittings in SIMD lanes), [`methods`] the integrators only these bodies
//! have (the exact flow, DMV, the LGVI, the isospectral midpoint), and [`inertia`] the inertia
//! of a body from its masses (000 §3.1).

pub mod generalized;
pub mod heavy_top;
pub mod inertia;
pub mod methods;
pub mod rigid_body;
pub mod spherical_pendulum;
pub(crate) mod top;

pub use generalized::GeneralizedRigidBody;
pub use heavy_top::HeavyTop;
pub use rigid_body::RigidBody;
pub use spherical_pendulum::SphericalPendulum;
