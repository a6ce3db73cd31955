//! 002: the tangent Euler top. Surfaces with their metric, frame and connection ([`surface`]),
//! the classical tangent top and its magnetic analogue ([`classical`]), and the relativistic and
//! weak-field tops of 002 §IV ([`relativistic`]), and the top of 002 §V on the three-dimensional
//! space forms ([`space_form`]) and on a general Riemannian 3-manifold in a chart
//! ([`riemannian`]), both in [`frame_top`].

pub mod classical;
pub mod frame_top;
pub mod relativistic;
pub mod riemannian;
pub mod space_form;
pub mod surface;

pub use classical::{ChargedParticle, TangentTop};
pub use frame_top::{Body, FrameTop, RiemannianFrameTop, SpaceTop};
pub use relativistic::{
    Potential, PotentialValue, RelativisticTangentTop, StaticFieldTop, WeakFieldTop,
};
pub use riemannian::Riemannian;
pub use space_form::SpaceForm;
pub use surface::{Graph, HyperbolicPlane, MetricSurface, Plane, Revolution, Sphere, Surface};
