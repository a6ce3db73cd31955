//! The integrators only the tops have, each implemented by the bodies it applies to: the exact
//! free rigid body flow and its splittings with gravity ([`exact`]), discrete Moser–Veselov and
//! its preprocessed versions ([`dmv`]), the Lie group variational integrator ([`lgvi`]) and the
//! isospectral symplectic midpoint on so(n)* ([`isospectral`]).

pub mod dmv;
pub mod exact;
pub mod isospectral;
pub mod lgvi;

pub use dmv::Dmv;
pub use exact::{Exact, ExactSplitting};
pub use isospectral::Isospectral;
pub use lgvi::Lgvi;
