//! `Pendulum` and `SphereParticle`: bindings of `lieflow::systems::{pendulum, sphere_particle}`,
//! the canonical and the holonomically constrained test problems of the mechanics core. Thin
//! subclasses of `lieflow.System`.

use lieflow::systems as core;
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use crate::convert::real;
use crate::convert::ArrayIn;
use crate::errors::IntoPy;
use crate::items::{map_items, Input};
use crate::system::{PySystem, Thin};

/// A planar pendulum in canonical coordinates: q the angle from the downward vertical,
/// :math:`p = m l^2 \dot q`, :math:`H = p^2 / (2 m l^2) - m g l \cos q`. State (q, p); fields q, p.
/// Methods: midpoint (the implicit midpoint rule, Gauss(1)), gauss4, gauss6 (symplectic
/// Gauss–Legendre), verlet, rk4.
///
/// Args:
///     mass > 0, length > 0, g >= 0.
/// Raises:
///     InvalidArgumentError.
#[pyclass(name = "Pendulum", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyPendulum;

#[pymethods]
impl PyPendulum {
    #[new]
    #[pyo3(signature = (mass = 1.0, length = 1.0, g = 9.81))]
    pub(crate) fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = real)] mass: f64,
        #[pyo3(from_py_with = real)] length: f64,
        #[pyo3(from_py_with = real)] g: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let pendulum = core::Pendulum::new(mass, length, g).py()?;
        let args = (mass, length, g).into_pyobject(py)?;
        Ok(PySystem::subclass(pendulum, args, &["mass", "length", "g"]))
    }

    /// The exact state (q, p) at times t of the pendulum released at rest from the angle
    /// `amplitude` (abs(amplitude) < pi), by Jacobi elliptic functions; broadcast: (...) -> (..., 2).
    ///
    /// Raises:
    ///     InvalidArgumentError, NonFiniteError, ShapeError.
    fn exact_solution<'py>(
        slf: &Bound<'py, Self>,
        amplitude: ArrayIn<'py>,
        t: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let inputs = [
            Input::new("amplitude", &amplitude, &[]),
            Input::new("t", &t, &[]),
        ];
        let pendulum = slf.core::<core::Pendulum>()?;
        map_items(slf.py(), &inputs, &[2], |x, out| {
            out.copy_from_slice(&pendulum.exact(x[0][0], x[1][0])?);
            Ok(())
        })
    }
}

/// A particle of mass m on the sphere :math:`\|q\| = l` in gravity g (the spherical pendulum in
/// Cartesian coordinates), :math:`H = \|p\|^2 / (2m) + m g q_3` with the constraint
/// :math:`\tfrac12 (\|q\|^2 - l^2) = 0`. State (q, p) with :math:`\|q\| = l` and
/// :math:`q \cdot p = 0`; fields q, p. Invariant: the vertical angular momentum
/// :math:`(q \times p)_3`. Method: rattle (RATTLE: constraints kept to round-off, symplectic).
///
/// Args:
///     mass > 0, length > 0, g >= 0.
/// Raises:
///     InvalidArgumentError.
#[pyclass(name = "SphereParticle", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PySphereParticle;

#[pymethods]
impl PySphereParticle {
    #[new]
    #[pyo3(signature = (mass = 1.0, length = 1.0, g = 9.81))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = real)] mass: f64,
        #[pyo3(from_py_with = real)] length: f64,
        #[pyo3(from_py_with = real)] g: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let particle = core::SphereParticle::new(mass, length, g).py()?;
        let args = (mass, length, g).into_pyobject(py)?;
        Ok(PySystem::subclass(particle, args, &["mass", "length", "g"]))
    }

    /// States (q, p) of `SphericalPendulum` states (u, L) with the same m, l, g:
    /// (..., 6) -> (..., 6).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    #[pyo3(name = "from_spherical")]
    fn spherical_to_cartesian<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let particle = slf.core::<core::SphereParticle>()?;
        map_items(
            slf.py(),
            &[Input::new("states", &states, &[6])],
            &[6],
            |z, out| {
                out.copy_from_slice(&particle.from_spherical(z[0])?);
                Ok(())
            },
        )
    }
}
