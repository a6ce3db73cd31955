//! `RollingDisk`: binding of `lieflow::systems::test_problems::rolling_disk`, the nonholonomic test problem of
//! the mechanics core. A thin subclass of `lieflow.System`.

use lieflow::systems as core;
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use crate::convert::ArrayIn;
use crate::convert::{real, reals};
use crate::errors::IntoPy;
use crate::items::{map_items, Input};
use crate::system::{PySystem, Thin};

/// The vertical rolling disk (Bloch, Nonholonomic Mechanics and Control, §1.4):
/// :math:`q = (x, y, \theta, \phi)` (contact point, rolling angle, heading), :math:`p = M\dot q`
/// with :math:`M = \operatorname{diag}(m, m, I, J)`, rolling without slipping
/// :math:`\dot x = R \cos\phi\, \dot\theta`, :math:`\dot y = R \sin\phi\, \dot\theta`, in the
/// potential :math:`U = \mathrm{spring}\, (1 - \cos\phi) + m\, \mathrm{tilt}\, x`.
/// State (q, p); fields q, p. Method: nonholonomic (a reversible discrete Lagrange–d'Alembert
/// method of RATTLE type; the constraints hold to round-off at every step).
///
/// Args:
///     mass, radius, roll_inertia, turn_inertia > 0; spring, tilt finite (default 0).
/// Raises:
///     InvalidArgumentError.
#[pyclass(name = "RollingDisk", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyRollingDisk;

#[pymethods]
impl PyRollingDisk {
    #[new]
    #[pyo3(signature = (mass, radius, roll_inertia, turn_inertia, spring = 0.0, tilt = 0.0))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = real)] mass: f64,
        #[pyo3(from_py_with = real)] radius: f64,
        #[pyo3(from_py_with = real)] roll_inertia: f64,
        #[pyo3(from_py_with = real)] turn_inertia: f64,
        #[pyo3(from_py_with = real)] spring: f64,
        #[pyo3(from_py_with = real)] tilt: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let disk = core::RollingDisk::new(mass, radius, roll_inertia, turn_inertia)
            .and_then(|d| d.with_potential(spring, tilt))
            .py()?;
        let args = (mass, radius, roll_inertia, turn_inertia, spring, tilt).into_pyobject(py)?;
        let names = &[
            "mass",
            "radius",
            "roll_inertia",
            "turn_inertia",
            "spring",
            "tilt",
        ];
        Ok(PySystem::subclass(disk, args, names))
    }

    /// The state (q, p) rolling with the rates :math:`\dot\theta` (`thetadot`), :math:`\dot\phi`
    /// (`phidot`) from :math:`q = (x, y, \theta, \phi)`.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn state(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<4>)] q: [f64; 4],
        #[pyo3(from_py_with = real)] thetadot: f64,
        #[pyo3(from_py_with = real)] phidot: f64,
    ) -> PyResult<Vec<f64>> {
        slf.core::<core::RollingDisk>()?
            .state(q, thetadot, phidot)
            .py()
    }

    /// The relative residual :math:`\|A(q) M^{-1} p\| / \|M^{-1} p\|` of the rolling constraints,
    /// vectorised: (..., 8) -> (...).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn constraint_residual<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let disk = slf.core::<core::RollingDisk>()?;
        map_items(
            slf.py(),
            &[Input::new("states", &states, &[8])],
            &[],
            |z, out| {
                out[0] = disk.constraint_residual(z[0])?;
                Ok(())
            },
        )
    }
}
