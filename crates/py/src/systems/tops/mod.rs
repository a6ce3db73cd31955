//! The bodies on SO(3) and so(n) of 000 (`lieflow::systems::tops`): `RigidBody`,
//! `GeneralizedRigidBody`, `HeavyTop`, `SphericalPendulum`, and what their bindings share (the
//! inertia argument, the spatial momentum R M); `inertia`: the inertia of a body from its masses.

pub(crate) mod generalized;
pub(crate) mod heavy_top;
pub(crate) mod inertia;
pub(crate) mod rigid_body;
pub(crate) mod spherical_pendulum;

use lieflow::systems::RigidBody;
use lieflow::Error;
use pyo3::prelude::*;

use crate::convert::{shape_str, ArrayIn};
use crate::errors::to_py;
use crate::items::{map_items, Input};

/// Principal moments (3,) or a symmetric positive-definite matrix (3, 3).
pub(crate) enum Inertia {
    Moments([f64; 3]),
    Matrix([f64; 9]),
}

/// A `LieflowWarning` for principal moments that no mass distribution has: one larger than
/// the sum of the other two (I₃ ≤ I₁ + I₂ for every body, equality for a flat one). Accepted:
/// generalised bodies (and the Euler equations) take any positive moments.
pub(crate) fn warn_unphysical(py: Python<'_>, moments: [f64; 3]) -> PyResult<()> {
    let sum: f64 = moments.iter().sum();
    if let Some(k) = (0..3).find(|&k| moments[k] > (sum - moments[k]) * (1.0 + 1e-12)) {
        crate::errors::warn(
            py,
            &format!(
                "principal moments {moments:?}: I{} exceeds the sum of the other two, which no \
                 rigid body's mass distribution gives (I_i <= I_j + I_k; equality for a flat \
                 one); accepted as a generalised body",
                k + 1
            ),
        )?;
    }
    Ok(())
}

pub(crate) fn inertia(a: &ArrayIn<'_>) -> PyResult<Inertia> {
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
pub(crate) fn spatial_momentum<'py>(
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
