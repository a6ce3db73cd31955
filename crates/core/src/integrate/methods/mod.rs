//! The methods, one file per family, each generic over the problem kind it needs
//! ([`crate::integrate::problem`]).

pub mod composition;
pub mod gauss;
pub mod nonholonomic;
pub mod rattle;
pub mod rk4;
pub mod rkmk;
pub mod splitting;
pub mod verlet;

pub use composition::Composition;
pub use gauss::{Gauss, IMPLICIT_MIDPOINT};
pub use nonholonomic::NonholonomicRattle;
pub use rattle::Rattle;
pub use rk4::Rk4;
pub use rkmk::Rkmk4;
pub use splitting::Splitting;
pub use verlet::Verlet;
