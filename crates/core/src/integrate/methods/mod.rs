//! The methods, one file per family, each generic over the problem kind it needs
//! ([`crate::integrate::problem`]).

pub mod composition;
pub mod rk4;
pub mod splitting;
pub mod verlet;

pub use composition::Composition;
pub use rk4::Rk4;
pub use splitting::Splitting;
pub use verlet::Verlet;
