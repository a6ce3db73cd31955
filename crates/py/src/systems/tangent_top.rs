//! `lieflow.surfaces` and `TangentTop`: bindings of `lieflow::systems::{surface, tangent_top}`
//! (002 §II–III). Surfaces pickle by the function and arguments that made them; `TangentTop` is a
//! thin subclass of `lieflow.System`.
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::systems::{surface, TangentTop};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use pyo3::PyClassInitializer;

use crate::convert::ArrayIn;
use crate::errors::IntoPy;
use crate::items::{map_items, Input};
use crate::system::PySystem;

type Any<'py> = Bound<'py, PyAny>;

/// A surface in local coordinates x = (x1, x2) with an orthonormal frame (E1, E2) (002 §II):
/// `Plane()`, `Sphere(radius)`, `HyperbolicPlane()`.
#[pyclass(module = "lieflow.surfaces", name = "Surface", frozen)]
pub struct PySurface {
    inner: Arc<dyn surface::Surface>,
    /// How to rebuild it: (name, args) of the function in `lieflow.surfaces`.
    recipe: (&'static str, Vec<f64>),
}

#[pymethods]
impl PySurface {
    /// The Gaussian curvature K at x.
    ///
    /// Raises:
    ///     InvalidArgumentError (x outside the chart).
    fn curvature(&self, x: [f64; 2]) -> PyResult<f64> {
        self.inner.check(x).map_err(|v| v.at_start()).py()?;
        Ok(self.inner.curvature(x))
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Any<'py>, Bound<'py, PyTuple>)> {
        let f = py.import("lieflow.surfaces")?.getattr(self.recipe.0)?;
        Ok((f, PyTuple::new(py, self.recipe.1.clone())?))
    }

    fn __repr__(&self) -> String {
        let args: Vec<String> = self.recipe.1.iter().map(|a| a.to_string()).collect();
        format!("{}({})", self.recipe.0, args.join(", "))
    }
}

/// The Euclidean plane, Cartesian x = (x, y), E = (d/dx, d/dy).
#[pyfunction]
fn Plane() -> PySurface {
    PySurface {
        inner: Arc::new(surface::Plane),
        recipe: ("Plane", vec![]),
    }
}

/// The sphere of radius R, x = (colatitude, longitude), E1 = d/dtheta / R,
/// E2 = d/dphi / (R sin theta).
///
/// Raises:
///     InvalidArgumentError (R <= 0).
#[pyfunction]
fn Sphere(radius: f64) -> PyResult<PySurface> {
    Ok(PySurface {
        inner: Arc::new(surface::Sphere::new(radius).py()?),
        recipe: ("Sphere", vec![radius]),
    })
}

/// The hyperbolic plane in the Poincaré half-plane y > 0 (002 (67)), E1 = y d/dx, E2 = y d/dy.
#[pyfunction]
fn HyperbolicPlane() -> PySurface {
    PySurface {
        inner: Arc::new(surface::HyperbolicPlane),
        recipe: ("HyperbolicPlane", vec![]),
    }
}

/// Fills the `surfaces` submodule.
pub fn register_surfaces(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySurface>()?;
    m.add_function(wrap_pyfunction!(Plane, m)?)?;
    m.add_function(wrap_pyfunction!(Sphere, m)?)?;
    m.add_function(wrap_pyfunction!(HyperbolicPlane, m)?)?;
    Ok(())
}

/// The tangent Euler top on a surface (002 §II–III): a rigid body carried as an orthonormal frame
/// tangent to the surface; configuration (x1, x2, theta), theta the angle from E1 to the body's
/// E1; L = m g(xdot, xdot)/2 + I (thetadot + w(xdot))^2 / 2 with w the connection 1-form (002
/// (43); the cross term of (45)/(47) with the corrected sign). State (x1, x2, theta, p1, p2,
/// p_theta); fields x (2), theta (1), p (3: the momenta conjugate to x1, x2, theta). Invariants: p_theta and the Killing momenta of the affine
/// isometries. Methods: midpoint, gauss4, gauss6 (symplectic Gauss–Legendre), rk4.
///
/// Args:
///     surface: a `lieflow.surfaces` surface; mass > 0; inertia: I = tr of the inertia tensor > 0.
/// Raises:
///     InvalidArgumentError.
#[pyclass(name = "TangentTop", module = "lieflow", extends = PySystem, frozen)]
pub struct PyTangentTop {
    top: TangentTop,
}

#[pymethods]
impl PyTangentTop {
    #[new]
    fn new(
        surface: Bound<'_, PySurface>,
        mass: f64,
        inertia: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let top = TangentTop::new(surface.get().inner.clone(), mass, inertia).py()?;
        let args = (surface.clone(), mass, inertia).into_pyobject(surface.py())?;
        let base = PySystem::new(top.clone(), args, &["surface", "mass", "inertia"]);
        Ok(PyClassInitializer::from(base).add_subclass(PyTangentTop { top }))
    }

    /// Constructor arguments of an example instance (for `methods()` on the class).
    #[classattr]
    fn _example_args() -> (PySurface, f64, f64) {
        (Plane(), 1.0, 1.0)
    }

    /// The canonical state from x (2,), theta and the velocities (Legendre transform of (47)).
    ///
    /// Raises:
    ///     InvalidArgumentError (x outside the chart), NonFiniteError.
    fn state(&self, x: [f64; 2], theta: f64, xdot: [f64; 2], thetadot: f64) -> PyResult<Vec<f64>> {
        self.top.state(x, theta, xdot, thetadot).py()
    }

    /// Named views for `Trajectory`: x (..., 2), theta (...), p (..., 3), and the velocities
    /// xdot (..., 2) and thetadot (...).
    fn _fields<'py>(
        slf: &Bound<'py, Self>,
        states: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let py = slf.py();
        let fields = slf.as_super().get()._fields(py, states.extract()?)?;
        let pick = |a: &Bound<'py, PyAny>, k: Bound<'py, PyAny>| {
            a.call_method1("__getitem__", ((py.Ellipsis(), k),))
        };
        if let Some(theta) = fields.get_item("theta")? {
            fields.set_item("theta", pick(&theta, 0i64.into_pyobject(py)?.into_any())?)?;
        }
        let v = slf.get().velocities(py, states.extract()?)?;
        let first_two = pyo3::types::PySlice::new(py, 0, 2, 1).into_any();
        fields.set_item("xdot", pick(&v, first_two)?)?;
        fields.set_item("thetadot", pick(&v, 2i64.into_pyobject(py)?.into_any())?)?;
        Ok(fields)
    }

    /// The velocities (x1dot, x2dot, thetadot) of states, vectorised: (..., 6) -> (..., 3).
    fn velocities<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        map_items(
            py,
            &[Input::new("states", &states, &[6])],
            &[3],
            |z, out| {
                out.copy_from_slice(&self.top.velocities(z[0])?);
                Ok(())
            },
        )
    }

    /// The body's angular momentum p_theta (kept exactly by the Gauss methods), (..., 6) -> (...).
    fn p_theta<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        map_items(py, &[Input::new("states", &states, &[6])], &[], |z, out| {
            out[0] = self.top.p_theta(z[0])?;
            Ok(())
        })
    }

    /// All Killing momenta J = p_A X^A of the surface's isometry group (Plane: translations x, y
    /// and the rotation; Sphere: the ambient angular momentum x, y, z; HyperbolicPlane: the
    /// Möbius generators E, H, F), (..., 6) -> (..., k).
    fn killing_momenta<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let probe = self
            .top
            .killing_momenta(&[0.3, 0.7, 0.0, 0.0, 0.0, 0.0])
            .py()?
            .len();
        map_items(
            py,
            &[Input::new("states", &states, &[6])],
            &[probe],
            |z, out| {
                out.copy_from_slice(&self.top.killing_momenta(z[0])?);
                Ok(())
            },
        )
    }
}
