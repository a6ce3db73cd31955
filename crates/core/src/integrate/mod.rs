//! Structure-preserving integration: state spaces, problem kinds, methods as values, and the one
//! driver that owns time.
//!
//! - [`space`]: a state is one flat vector cut into named blocks ([`Space`]: ℝᵏ, SO(3), S², n×n
//!   matrices, so(n)*) with membership checks, retraction and named views;
//! - [`problem`]: the kinds a system can implement ([`problem::VectorField`], [`problem::Split`],
//!   [`problem::Separable`], [`problem::Canonical`], [`problem::Constrained`],
//!   [`problem::Nonholonomic`], [`problem::GroupField`], [`problem::Symmetric`]);
//! - [`methods`]: one file per method family, each generic over the kind it needs;
//! - [`method`]: the [`Integrator`] and [`Stepper`] traits, each system's [`Catalog`] of named
//!   methods, and [`System`], any catalogued problem as a trait object;
//! - this module: the driver. A [`Run`] validates once, owns the clock and the stepper for the
//!   whole run (callers that work in chunks resume the same run), retracts curved blocks every
//!   [`RETRACT_EVERY`] steps for methods that keep the manifold, and saves every
//!   `save_every`-th state, or the states at given times ([`Run::save_at`]); it locates
//!   [`Events`] and ends at a time ([`Until::Time`]), off its grid always by a shortened step of
//!   the method, never by interpolation; [`integrate`] and [`integrate_batch`] (rayon) are built
//!   on it.
//!
//! ```
//! use lieflow::integrate::{integrate, Problem};
//! use lieflow::systems::RigidBody;
//! let body = RigidBody::new([1.0, 2.0, 3.0])?;
//! let traj = integrate(&body, "splitting4", &[1.0, 0.5, -0.3], 1e-2, 1000, 100)?;
//! assert_eq!(traj.len(), 11);
//! let (h0, h1) = (body.energy(traj.state(0))?, body.energy(traj.state(10))?);
//! assert!((h1 - h0).abs() < 1e-9);
//! # Ok::<(), lieflow::Error>(())
//! ```

pub mod batch;
pub mod clock;
mod drive;
pub mod events;
pub mod forcing;
pub mod hooks;
mod locate;
pub mod method;
pub mod methods;
pub mod problem;
pub mod run;
pub mod space;
pub mod tangent;
pub mod trajectory;

pub use batch::Batch;
pub use events::{Event, Events, Hit};
pub use method::{
    kind_methods, BatchStepper, Catalog, Clock, Entry, Integrator, Properties, Resolved, Stepper,
    System,
};
pub use problem::Problem;
pub use run::{check_state, energy_checked, invariants_checked, Run, Until, RETRACT_EVERY};
pub use space::{Block, Space};
pub use trajectory::{integrate, integrate_batch, integrate_with, with_threads, Trajectory};
