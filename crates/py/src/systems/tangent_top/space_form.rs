//! `lieflow.spaces`: the three-dimensional space forms of `lieflow::systems::tangent_top::space_form`
//! (002 §V) the `FrameTop` moves on. A space pickles by the function of this module and its
//! arguments.
#![allow(non_snake_case)]

use lieflow::systems::tangent_top::space_form::SpaceForm;
use lieflow::Error;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::convert::{int, real, vector, ArrayIn};
use crate::errors::{to_py, IntoPy};

type Any<'py> = Bound<'py, PyAny>;

/// A three-dimensional space form with a global orthonormal reference frame field Ê(x): made by
/// `Euclidean`, `Sphere` and `Hyperbolic` of this module. Points: x in R^3 (Euclidean), unit
/// vectors of R^4 times the radius (Sphere), the upper sheet x0^2 - x1^2 - x2^2 - x3^2 = r^2, x0 > 0, of the
/// hyperboloid in Minkowski space (Hyperbolic; metric -a0 b0 + a.b on tangent vectors).
#[pyclass(module = "lieflow.spaces", name = "Space", frozen)]
pub struct PySpace {
    pub(crate) inner: SpaceForm,
}

#[pymethods]
impl PySpace {
    /// The sectional curvature: 0, 1/r^2 or -1/r^2.
    #[getter]
    fn curvature(&self) -> f64 {
        self.inner.curvature()
    }

    /// The radius r (1 for Euclidean space, which has none).
    #[getter]
    fn radius(&self) -> f64 {
        self.inner.length()
    }

    /// The number of ambient components of a point: 3 (Euclidean) or 4.
    #[getter]
    fn ambient_dim(&self) -> usize {
        self.inner.ambient_dim()
    }

    /// The reference frame Ê(x): a (d, 3) array whose columns are the ambient components of
    /// Ê1, Ê2, Ê3 at the point x (d = `ambient_dim`). Euclidean: the constant frame; Sphere:
    /// x.i/r, x.j/r, x.k/r (quaternion products, the left-invariant fields of SU(2)); Hyperbolic:
    /// the boost taking (r, 0, 0, 0) to x applied to e1, e2, e3.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, InvalidArgumentError (x not on the space).
    fn reference_frame<'py>(
        &self,
        py: Python<'py>,
        x: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let x = vector("x", &x)?;
        self.inner.check_point(&x).py()?;
        let f = self.inner.reference(&x);
        let k = 4 - self.inner.ambient_dim();
        let rows: Vec<Vec<f64>> = (k..4)
            .map(|i| (1..4).map(|j| f[(i, j)]).collect())
            .collect();
        PyArray2::from_vec2(py, &rows)
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Any<'py>, Bound<'py, PyTuple>)> {
        let m = py.import("lieflow.spaces")?;
        Ok(match self.inner {
            SpaceForm::Euclidean => (m.getattr("Euclidean")?, PyTuple::new(py, [3])?),
            SpaceForm::Sphere { radius } => (m.getattr("Sphere")?, (3, radius).into_pyobject(py)?),
            SpaceForm::Hyperbolic { radius } => {
                (m.getattr("Hyperbolic")?, (3, radius).into_pyobject(py)?)
            }
        })
    }

    fn __repr__(&self) -> String {
        self.inner.name()
    }

    fn __hash__(&self) -> u64 {
        let (kind, r) = match self.inner {
            SpaceForm::Euclidean => (0u64, 1.0f64),
            SpaceForm::Sphere { radius } => (1, radius),
            SpaceForm::Hyperbolic { radius } => (2, radius),
        };
        kind.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ r.to_bits()
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PySpace>()
            .map(|o| o.get().inner == self.inner)
            .unwrap_or(false)
    }
}

fn three(n: i64) -> PyResult<()> {
    if n != 3 {
        return Err(to_py(Error::invalid(
            "n",
            format!(
                "the top on a space form is implemented in three dimensions (002 §V's n = 3); \
                 got n = {n}"
            ),
        )));
    }
    Ok(())
}

/// Euclidean space R^3 (curvature 0; frame bundle SE(3)).
///
/// Raises:
///     InvalidArgumentError (n != 3).
#[pyfunction]
#[pyo3(signature = (n=3))]
fn Euclidean(#[pyo3(from_py_with = int)] n: i64) -> PyResult<PySpace> {
    three(n)?;
    Ok(PySpace {
        inner: SpaceForm::Euclidean,
    })
}

/// The 3-sphere of radius r in R^4 (curvature 1/r^2; frame bundle SO(4)).
///
/// Raises:
///     InvalidArgumentError (n != 3, r <= 0).
#[pyfunction]
#[pyo3(signature = (n=3, radius=1.0))]
fn Sphere(
    #[pyo3(from_py_with = int)] n: i64,
    #[pyo3(from_py_with = real)] radius: f64,
) -> PyResult<PySpace> {
    three(n)?;
    Ok(PySpace {
        inner: SpaceForm::sphere(radius).py()?,
    })
}

/// Hyperbolic 3-space of radius r, the hyperboloid x0^2 - x1^2 - x2^2 - x3^2 = r^2, x0 > 0 in Minkowski R^(1,3)
/// (curvature -1/r^2; frame bundle SO+(1,3)).
///
/// Raises:
///     InvalidArgumentError (n != 3, r <= 0).
#[pyfunction]
#[pyo3(signature = (n=3, radius=1.0))]
fn Hyperbolic(
    #[pyo3(from_py_with = int)] n: i64,
    #[pyo3(from_py_with = real)] radius: f64,
) -> PyResult<PySpace> {
    three(n)?;
    Ok(PySpace {
        inner: SpaceForm::hyperbolic(radius).py()?,
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySpace>()?;
    m.add_function(wrap_pyfunction!(Euclidean, m)?)?;
    m.add_function(wrap_pyfunction!(Sphere, m)?)?;
    m.add_function(wrap_pyfunction!(Hyperbolic, m)?)?;
    Ok(())
}
