//! The tangent tops of 002 (`lieflow::systems::tangent_top`): the surfaces (`lieflow.surfaces`),
//! the classical top and the charged particle, and the relativistic tops.

pub(crate) mod classical;
pub(crate) mod frame_top;
pub(crate) mod relativistic;
pub mod space_form;
pub mod surface;
