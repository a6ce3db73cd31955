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
use crate::errors::to_py;
use crate::items::{map_items, Input};

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
    m.add_class::<rigid_body::PyRigidBody>()?;
    m.add_class::<rigid_body::PyGeneralizedRigidBody>()?;
    m.add_class::<heavy_top::PyHeavyTop>()?;
    m.add_class::<spherical_pendulum::PySphericalPendulum>()?;
    m.add_class::<pendulum::PyPendulum>()?;
    m.add_class::<pendulum::PySphereParticle>()?;
    m.add_class::<rolling_disk::PyRollingDisk>()?;
    m.add_class::<rolling_spheres::PyRollingSpheres>()?;
    m.add_class::<rolling_disks::PyRollingDisks>()?;
    m.add_class::<rolling_disks::PyDisksEquilibrium>()?;
    m.add_class::<relativistic_top::PyRelativisticTangentTop>()?;
    m.add_class::<relativistic_top::PyWeakFieldTop>()?;
    m.add_class::<tangent_top::PyTangentTop>()?;
    m.add_class::<tangent_top::PyChargedParticle>()?;
    m.add_class::<user::PyCanonical>()?;
    m.add_class::<user::PySeparable>()?;
    m.add_class::<user::PyLiePoisson>()?;
    m.add_class::<forced::PyForced>()?;
    Ok(())
}
