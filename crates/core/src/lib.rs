//! # lieflow
//!
//! Geometry and structure-preserving simulation of mechanical systems on Lie groups: matrix Lie
//! groups and algebras ([`lie`]), generalized pseudo-rigid bodies on GL⁺(n) ([`pseudo_rigid`]),
//! Lie–Poisson systems such as the free rigid body and the heavy top ([`systems`]), and integrators
//! that keep momentum maps, Casimirs and the group itself ([`integrate`]).
//!
//! Equation numbers such as `001 (6.9)` refer to the source documents listed in the repository's
//! `DESIGN.md`.
//!
//! ```
//! use lieflow::lie::so3;
//! use nalgebra::Vector3;
//! // A rotation by 90° about z maps x to y.
//! let r = so3::exp(&Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
//! let y = r * Vector3::x();
//! assert!((y - Vector3::y()).norm() < 1e-15);
//! ```

pub mod analysis;
pub mod check;
pub mod elliptic;
pub mod error;
pub mod integrate;
pub mod lie;
pub mod pseudo_rigid;
pub mod systems;

pub use error::{Error, Result};

/// Dense real matrix of runtime size (faer), used for n×n work with n a runtime value.
pub type Mat = faer::Mat<f64>;
