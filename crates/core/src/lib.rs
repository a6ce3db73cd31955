//! # lieflow
//!
//! Geometry and structure-preserving simulation of mechanical systems on Lie groups: matrix Lie
//! groups and algebras ([`lie`]), generalized pseudo-rigid bodies on GL⁺(n) ([`pseudo_rigid`]),
//! the systems of the source texts such as the free rigid body, the heavy top, the tangent top
//! and rolling bodies ([`systems`]), and integrators that keep momentum maps, Casimirs and the
//! group itself ([`integrate`]). Around them: stability of relative equilibria and continuation of
//! their families ([`analysis`]), numerical kernels that know no mechanics (elliptic functions,
//! SIMD lanes, rotation angles, finite differences: [`numerics`]), the one stopping rule of every
//! iterative solve ([`convergence`]) and the input validation shared by every module ([`check`]).
//!
//! Equation numbers such as `001 (6.9)` refer to the source documents listed in the repository's
//! `DESIGN.md`.
//!
//! ```
//! use lieflow::lie::so3;
//! use nalgebra::Vector3;
//! // A rotation by 90° about z maps x to y.
//! let r = so3::exp(&Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2)).unwrap();
//! let y = r * Vector3::x();
//! assert!((y - Vector3::y()).norm() < 1e-15);
//! ```
//!
//! A free rigid body integrated by a 4th-order Lie–Poisson splitting (methods are chosen by name
//! from the system's catalog, or passed as values to `integrate_with`): the Casimir ‖M‖² and the
//! energy are kept to round-off level over 10⁴ steps, and the motion agrees with the exact
//! Jacobi-elliptic solution.
//!
//! ```
//! use lieflow::integrate::{integrate, Problem};
//! use lieflow::systems::RigidBody;
//!
//! let body = RigidBody::new([1.0, 2.0, 3.0])?;
//! let m0 = [1.0, 0.5, -0.3];
//! let traj = integrate(&body, "splitting4", &m0, 1e-2, 10_000, 100)?; // to t = 100
//! let (first, last) = (traj.state(0), traj.state(traj.len() - 1));
//! assert!((body.energy(last)? - body.energy(first)?).abs() < 1e-12);
//! assert!((body.invariants(last)?[0] - body.invariants(first)?[0]).abs() < 1e-12);
//! let exact = body.exact_momentum(&m0, traj.t[traj.len() - 1])?;
//! assert!(last.iter().zip(exact).all(|(a, b)| (a - b).abs() < 1e-7));
//! # Ok::<(), lieflow::Error>(())
//! ```

pub mod analysis;
pub mod check;
pub mod convergence;

pub mod error;
pub mod integrate;
pub mod lie;
pub mod numerics;

pub mod pseudo_rigid;

pub mod systems;

pub use error::{Error, Result};

/// Dense real matrix of runtime size (faer), used for n×n work with n a runtime value.
pub type Mat = faer::Mat<f64>;
