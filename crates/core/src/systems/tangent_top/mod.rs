//! 002: the tangent Euler top. Surfaces with their metric, frame and connection ([`surface`]),
//! the classical tangent top and its magnetic analogue ([`classical`]), and the relativistic and
//! weak-field tops of 002 §IV ([`relativistic`]), and the top on the three-dimensional space
//! forms of 002 §V ([`space_form`], [`frame_top`]).

pub mod classical;
pub mod frame_top;
pub mod relativistic;
pub mod space_form;
pub mod surface;

pub use classical::{ChargedParticle, TangentTop};
pub use frame_top::FrameTop;
pub use relativistic::{
    Potential, PotentialValue, RelativisticTangentTop, StaticFieldTop, WeakFieldTop,
};
pub use space_form::SpaceForm;
pub use surface::{Graph, HyperbolicPlane, MetricSurface, Plane, Revolution, Sphere, Surface};
