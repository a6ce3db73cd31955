//! The methods, one file per family, each generic over the problem kind it needs
//! ([`crate::integrate::problem`]).

pub mod composition;
pub mod gauss;
pub mod lie_midpoint;
pub mod nonholonomic;
pub mod rattle;
pub mod rk4;
pub mod rkmk;
pub mod splitting;
pub mod verlet;

pub use composition::{Composition, Processed};
pub use gauss::{Gauss, IMPLICIT_MIDPOINT};
pub use lie_midpoint::LieMidpoint;
pub use nonholonomic::NonholonomicRattle;
pub use rattle::Rattle;
pub use rk4::Rk4;
pub use rkmk::Rkmk4;
pub use splitting::{ProcessedSplitting, Splitting};
pub use verlet::Verlet;

use crate::integrate::method::Entry;
use crate::integrate::problem::{GroupField, VectorField};

/// The catalog of a general (non-separable) canonical system: the symplectic Gauss–Legendre
/// methods "gauss4" (the default), "gauss6", "midpoint", and "rk4" as the non-geometric
/// baseline.
pub fn canonical_catalog<P: VectorField + Clone + 'static>() -> Vec<Entry<P>> {
    vec![
        Entry::new("gauss4", || Gauss(2)),
        Entry::new("gauss6", || Gauss(3)),
        Entry::new("midpoint", || IMPLICIT_MIDPOINT),
        Entry::new("rk4", || Rk4),
    ]
}

/// The catalog of a [`GroupField`] system with a vector field (the Lie–Poisson systems): RKMK4
/// "rkmk4", the Lie midpoint "midpoint" and its Suzuki composition "midpoint4" (all on the group
/// orbit), and "rk4" as the baseline, in that order.
pub fn group_field_catalog<P: GroupField + VectorField + Clone + 'static>() -> Vec<Entry<P>> {
    vec![
        Entry::new("rkmk4", || Rkmk4),
        Entry::new("midpoint", LieMidpoint::new),
        Entry::new("midpoint4", || LieMidpoint(Composition::suzuki4())),
        Entry::new("rk4", || Rk4),
    ]
}

/// The kind boilerplate of a canonical system `$t` (a [`Canonical`] problem), written once:
/// Hamilton's equations ([`Canonical::hamilton_field`]) as its vector field, its catalog
/// (`$catalog`, e.g. [`canonical_catalog`]) for it and for its tangent lift, Rayleigh damping as
/// its own dissipation ([`crate::integrate::forcing::rayleigh`]), and `$tangent` (`&$t` ↦ its
/// lift, where it has one) as [`Catalog::tangent`](crate::integrate::method::Catalog::tangent).
///
/// [`Canonical`]: crate::integrate::problem::Canonical
/// [`Canonical::hamilton_field`]: crate::integrate::problem::Canonical::hamilton_field
macro_rules! canonical_system {
    ($t:ty, $catalog:expr, $tangent:expr) => {
        impl $crate::integrate::problem::VectorField for $t {
            /// Hamilton's equations q̇ = ∂H/∂p, ṗ = −∂H/∂q.
            fn field(&self, z: &[f64], dz: &mut [f64]) {
                $crate::integrate::problem::Canonical::hamilton_field(self, z, dz);
            }
        }

        impl $crate::integrate::method::Catalog for $t {
            fn kind_catalog() -> Vec<$crate::integrate::method::Entry<Self>> {
                $catalog
            }

            fn dissipation(
                &self,
                d: &$crate::integrate::forcing::Dissipation,
            ) -> $crate::Result<std::sync::Arc<dyn $crate::integrate::forcing::Perturbation>> {
                $crate::integrate::forcing::rayleigh(self, d)
            }

            fn tangent(
                &self,
            ) -> Option<std::sync::Arc<dyn $crate::integrate::method::TangentSystem>> {
                ($tangent)(self)
            }
        }

        /// The same methods on the tangent lift.
        impl $crate::integrate::method::Catalog for $crate::integrate::tangent::Tangent<$t> {
            fn kind_catalog() -> Vec<$crate::integrate::method::Entry<Self>> {
                $catalog
            }
        }
    };
}
pub(crate) use canonical_system;
