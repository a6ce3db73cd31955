//! The system classes of `lieflow::systems`: the Lie–Poisson systems of 000 §3–§5 (`RigidBody`,
//! `GeneralizedRigidBody`, `HeavyTop`, `SphericalPendulum`) and the test problems of the
//! mechanics core (`Pendulum`, `SphereParticle`, `RollingDisk`), the user-defined systems
//! (`Canonical`, `Separable`, `LiePoisson`: `user.rs`), thin subclasses of
//! `lieflow.System`, and the helpers the bodies on SO(3) share.

mod forced;
mod heavy_top;
pub(crate) mod pendulum;
mod relativistic_top;
mod rigid_body;
mod rolling_disk;
mod rolling_disks;
mod rolling_spheres;
mod spherical_pendulum;
pub mod surfaces;
pub mod tangent_top;
mod user;

use lieflow::systems::RigidBody;
use lieflow::Error;
use pyo3::prelude::*;

use crate::convert::{shape_str, ArrayIn};
use crate::errors::{to_py, IntoPy};
use crate::items::{map_items, Input};
use crate::system::{add_system, add_with_methods};
use lieflow::integrate::System;

/// Principal moments (3,) or a symmetric positive-definite matrix (3, 3).
enum Inertia {
    Moments([f64; 3]),
    Matrix([f64; 9]),
}

fn inertia(a: &ArrayIn<'_>) -> PyResult<Inertia> {
    let v = a.as_array();
    let data: Vec<f64> = v.iter().copied().collect();
    match v.shape() {
        [3] => Ok(Inertia::Moments([data[0], data[1], data[2]])),
        [3, 3] => {
            let mut m = [0.0; 9];
            m.copy_from_slice(&data);
            Ok(Inertia::Matrix(m))
        }
        s => Err(to_py(Error::shape(
            "inertia",
            "(3,) principal moments or a (3, 3) symmetric positive-definite matrix",
            shape_str(s),
        ))),
    }
}

/// Spatial angular momentum R M (000 Theorem 4.2) of states whose first three entries are M,
/// with attitudes R; leading axes broadcast: (..., d), (..., 3, 3) -> (..., 3).
fn spatial_momentum<'py>(
    py: Python<'py>,
    states: &ArrayIn<'py>,
    attitude: &ArrayIn<'py>,
    d: usize,
) -> PyResult<Bound<'py, PyAny>> {
    map_items(
        py,
        &[
            Input::new("states", states, &[d]),
            Input::new("attitude", attitude, &[3, 3]),
        ],
        &[3],
        |x, out| {
            // The whole state (not only M: a NaN in the heavy top's Gamma is bad input too).
            lieflow::check::finite_slice("states", x[0])?;
            lieflow::check::finite_slice("attitude", x[1])?;
            let z = [&x[0][..3], x[1]].concat();
            out.copy_from_slice(&RigidBody::spatial_momentum(&z)?);
            Ok(())
        },
    )
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    use lieflow::systems as core;
    add_system::<rigid_body::PyRigidBody, core::RigidBody>(m)?;
    add_system::<rigid_body::PyGeneralizedRigidBody, core::GeneralizedRigidBody>(m)?;
    add_system::<heavy_top::PyHeavyTop, core::HeavyTop>(m)?;
    add_system::<spherical_pendulum::PySphericalPendulum, core::SphericalPendulum>(m)?;
    add_system::<pendulum::PyPendulum, core::Pendulum>(m)?;
    add_system::<pendulum::PySphereParticle, core::SphereParticle>(m)?;
    add_system::<rolling_disk::PyRollingDisk, core::RollingDisk>(m)?;
    add_system::<rolling_spheres::PyRollingSpheres, core::RollingSpheres>(m)?;
    add_system::<rolling_disks::PyRollingDisks, core::RollingDisks>(m)?;
    m.add_class::<rolling_disks::PyDisksEquilibrium>()?;
    add_system::<relativistic_top::PyRelativisticTangentTop, core::RelativisticTangentTop>(m)?;
    add_system::<relativistic_top::PyWeakFieldTop, core::WeakFieldTop>(m)?;
    add_system::<tangent_top::PyTangentTop, core::TangentTop>(m)?;
    add_system::<tangent_top::PyChargedParticle, core::ChargedParticle>(m)?;
    add_system::<user::PyCanonical, core::UserCanonical>(m)?;
    add_system::<user::PySeparable, core::UserSeparable>(m)?;
    add_system::<user::PyLiePoisson, core::LiePoisson>(m)?;
    // A forced system has the methods of the system it wraps; on the class, a forced
    // canonical system's (those of a forced `Pendulum`).
    let pendulum = core::Pendulum::new(1.0, 1.0, 9.81).py()?;
    let forced = lieflow::integrate::forcing::Forced::new(std::sync::Arc::new(pendulum));
    let names = forced.methods().into_iter().map(|(n, _)| n).collect();
    add_with_methods::<forced::PyForced>(m, names)
}
