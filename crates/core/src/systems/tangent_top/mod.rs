//! 002: the tangent Euler top. Surfaces with their metric, frame and connection ([`surface`]),
//! the classical tangent top and its magnetic analogue ([`classical`]), and the relativistic and
//! weak-field tops of 002 §IV ([`relativistic`]).

pub mod classical;
pub mod relativistic;
pub mod surface;

pub use classical::{ChargedParticle, TangentTop};
pub use relativistic::{Potential, PotentialValue, RelativisticTangentTop, WeakFieldTop};
pub use surface::{Graph, HyperbolicPlane, MetricSurface, Plane, Revolution, Sphere, Surface};
