//! The system classes of `lieflow`, one folder per source text as in `lieflow::systems`: the
//! bodies of 000 (`tops/`: `RigidBody`, `GeneralizedRigidBody`, `HeavyTop`,
//! `SphericalPendulum`), the tangent tops of 002 (`tangent_top/`: the surfaces, `TangentTop`,
//! `ChargedParticle`, `RelativisticTangentTop`, `WeakFieldTop`, `StaticFieldTop`), the rolling
//! bodies of 003 (`rolling/`: `RollingDisks`, `RollingSpheres`), the user-defined systems (`user/`:
//! `Canonical`, `Separable`, `LiePoisson`, and `Forced`, which wraps any system) and the test
//! problems of the mechanics core (`test_problems/`: `Pendulum`, `SphereParticle`,
//! `RollingDisk`). Every class is a thin subclass of `lieflow.System`.

pub mod rolling;
pub mod tangent_top;
pub mod test_problems;
pub mod tops;
pub mod user;

use pyo3::prelude::*;

use crate::errors::IntoPy;
use crate::system::{add_system, add_with_methods};
use lieflow::integrate::System;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    use lieflow::systems as core;
    tops::inertia::register(m)?;
    add_system::<tops::rigid_body::PyRigidBody, core::RigidBody>(m)?;
    add_system::<tops::generalized::PyGeneralizedRigidBody, core::GeneralizedRigidBody>(m)?;
    add_system::<tops::heavy_top::PyHeavyTop, core::HeavyTop>(m)?;
    add_system::<tops::spherical_pendulum::PySphericalPendulum, core::SphericalPendulum>(m)?;
    add_system::<test_problems::pendulum::PyPendulum, core::Pendulum>(m)?;
    add_system::<test_problems::pendulum::PySphereParticle, core::SphereParticle>(m)?;
    add_system::<test_problems::rolling_disk::PyRollingDisk, core::RollingDisk>(m)?;
    add_system::<rolling::spheres::PyRollingSpheres, core::RollingSpheres>(m)?;
    add_system::<rolling::disks::PyRollingDisks, core::RollingDisks>(m)?;
    m.add_class::<rolling::disks::PyDisksEquilibrium>()?;
    add_system::<tangent_top::relativistic::PyRelativisticTangentTop, core::RelativisticTangentTop>(
        m,
    )?;
    add_system::<tangent_top::relativistic::PyWeakFieldTop, core::WeakFieldTop>(m)?;
    add_system::<tangent_top::relativistic::PyStaticFieldTop, core::StaticFieldTop>(m)?;
    add_system::<tangent_top::classical::PyTangentTop, core::TangentTop>(m)?;
    add_system::<tangent_top::classical::PyChargedParticle, core::ChargedParticle>(m)?;
    add_system::<tangent_top::frame_top::PyFrameTop, core::FrameTop>(m)?;
    add_system::<user::canonical::PyCanonical, core::UserCanonical>(m)?;
    add_system::<user::separable::PySeparable, core::UserSeparable>(m)?;
    add_system::<user::lie_poisson::PyLiePoisson, core::LiePoisson>(m)?;
    add_system::<user::euler_poincare::PyEulerPoincare, core::user::EulerPoincare>(m)?;
    // A forced system has the methods of the system it wraps; on the class, a forced
    // canonical system's (those of a forced `Pendulum`).
    let pendulum = core::Pendulum::new(1.0, 1.0, 9.81).py()?;
    let forced = lieflow::integrate::forcing::Forced::new(std::sync::Arc::new(pendulum));
    let names = forced.methods().into_iter().map(|(n, _)| n).collect();
    add_with_methods::<user::forced::PyForced>(m, names)
}
