//! `SphericalPendulum`: binding of `lieflow::systems::tops::spherical_pendulum` (000 §5.1). A thin
//! subclass of `lieflow.System`: constructor and observables.

use lieflow::systems as core;
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use crate::convert::real;
use crate::convert::ArrayIn;
use crate::errors::IntoPy;
use crate::items::{map_items, Input};
use crate::system::{PySystem, Thin};

type Any<'py> = Bound<'py, PyAny>;

/// The spherical pendulum (000 §5.1) as a Lie–Poisson system on se(3)*.
///
/// State :math:`z = (q, L)` (6,): :math:`q` the unit vector from the pivot to the bob
/// (:math:`e_3` up) and :math:`L = m l^2\, q \times \dot q` the angular momentum about the
/// pivot. :math:`\dot q = L \times q / (m l^2)`, :math:`\dot L = m g l\, e_3 \times q`; energy
/// :math:`H = \|L\|^2 / (2 m l^2) + m g l\, q_3`; Casimirs :math:`(\|q\|^2, q \cdot L)` (a state
/// needs :math:`\|q\| = 1` and :math:`q \cdot L = 0`); the vertical momentum :math:`L_3` is
/// conserved.
/// Methods: splitting, splitting4, splitting6, rk4.
///
/// Args:
///     mass > 0, length > 0, g >= 0.
/// Raises:
///     InvalidArgumentError.
#[pyclass(name = "SphericalPendulum", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PySphericalPendulum;

#[pymethods]
impl PySphericalPendulum {
    #[new]
    #[pyo3(signature = (mass = 1.0, length = 1.0, g = 9.81))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = real)] mass: f64,
        #[pyo3(from_py_with = real)] length: f64,
        #[pyo3(from_py_with = real)] g: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let pendulum = core::SphericalPendulum::new(mass, length, g).py()?;
        let args = (mass, length, g).into_pyobject(py)?;
        Ok(PySystem::subclass(pendulum, args, &["mass", "length", "g"]))
    }

    /// The mass of the bob.
    #[getter]
    fn mass(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Ok(slf.core::<core::SphericalPendulum>()?.mass())
    }

    /// The length of the rod.
    #[getter]
    fn length(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Ok(slf.core::<core::SphericalPendulum>()?.length())
    }

    /// The gravitational acceleration.
    #[getter]
    fn g(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Ok(slf.core::<core::SphericalPendulum>()?.gravity())
    }

    /// The state (q, L) from the spherical coordinates of 000 §5.1.1 (theta from the downward
    /// vertical): :math:`q = (\sin\theta \cos\phi, \sin\theta \sin\phi, -\cos\theta)`,
    /// :math:`L = m l^2\, q \times \dot q`. The four
    /// arguments broadcast like numpy arrays; the result has shape (..., 6).
    ///
    /// Raises:
    ///     ShapeError (shapes that do not broadcast), NonFiniteError.
    #[pyo3(signature = (theta, phi, thetadot = None, phidot = None))]
    fn state_from_spherical<'py>(
        slf: &Bound<'py, Self>,
        theta: ArrayIn<'py>,
        phi: ArrayIn<'py>,
        thetadot: Option<ArrayIn<'py>>,
        phidot: Option<ArrayIn<'py>>,
    ) -> PyResult<Any<'py>> {
        let (py, pendulum) = (slf.py(), slf.core::<core::SphericalPendulum>()?);
        let zero = || -> PyResult<ArrayIn<'py>> { 0.0f64.into_pyobject(py)?.extract() };
        let thetadot = thetadot.map_or_else(zero, Ok)?;
        let phidot = phidot.map_or_else(zero, Ok)?;
        map_items(
            py,
            &[
                Input::new("theta", &theta, &[]),
                Input::new("phi", &phi, &[]),
                Input::new("thetadot", &thetadot, &[]),
                Input::new("phidot", &phidot, &[]),
            ],
            &[6],
            |x, out| {
                let s = pendulum.state_from_spherical(x[0][0], x[1][0], x[2][0], x[3][0])?;
                out.copy_from_slice(&s);
                Ok(())
            },
        )
    }

    /// The vertical angular momentum :math:`L_3` (conserved), vectorised: (..., 6) -> (...).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn vertical_momentum<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let pendulum = slf.core::<core::SphericalPendulum>()?;
        map_items(
            slf.py(),
            &[Input::new("states", &states, &[6])],
            &[],
            |z, out| {
                out[0] = pendulum.vertical_momentum(z[0])?;
                Ok(())
            },
        )
    }
}
