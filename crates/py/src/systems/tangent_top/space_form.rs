//! `lieflow.spaces`: the three-dimensional spaces the `FrameTop` moves on (002 §V): the space
//! forms of `lieflow::systems::tangent_top::space_form` and a Riemannian chart given by callables
//! (`lieflow::systems::tangent_top::riemannian`). A space pickles by the function of this module
//! and its arguments.
#![allow(non_snake_case)]

use lieflow::systems::tangent_top::riemannian::Riemannian as Chart;
use lieflow::systems::tangent_top::space_form::SpaceForm;
use lieflow::Error;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use super::surface::{call_floats, callable, domain_closure};
use crate::convert::{int, real, reals, vector, ArrayIn};
use crate::errors::{checked, to_py, IntoPy};

type Any<'py> = Bound<'py, PyAny>;

/// What a `Space` is: a space form, or a chart with the callables it was made of.
pub(crate) enum Kind {
    Form(SpaceForm),
    Chart {
        chart: Chart,
        /// (metric, frame, domain), for pickling and the repr.
        args: Py<PyTuple>,
    },
}

/// A three-dimensional Riemannian space with an orthonormal reference frame field
/// :math:`\hat E(x)`: made by `Euclidean`, `Sphere`, `Hyperbolic` and `Riemannian` of this
/// module. Points: :math:`x \in \mathbb{R}^3` (Euclidean), unit vectors of :math:`\mathbb{R}^4`
/// times the radius (Sphere), the upper sheet :math:`x_0^2 - x_1^2 - x_2^2 - x_3^2 = r^2`,
/// :math:`x_0 > 0`, of the hyperboloid in Minkowski space (Hyperbolic; metric
/// :math:`-a_0 b_0 + a \cdot b` on tangent vectors), chart coordinates (Riemannian).
#[pyclass(module = "lieflow.spaces", name = "Space", frozen)]
pub struct PySpace {
    pub(crate) inner: Kind,
}

impl PySpace {
    /// The space form, or an InvalidArgumentError naming `what` for a chart.
    fn form(&self, what: &str) -> PyResult<SpaceForm> {
        match &self.inner {
            Kind::Form(f) => Ok(*f),
            Kind::Chart { .. } => Err(to_py(Error::invalid(
                what,
                format!(
                    "{what} is defined for the space forms (Euclidean, Sphere, Hyperbolic); a \
                     Riemannian chart has none"
                ),
            ))),
        }
    }
}

#[pymethods]
impl PySpace {
    /// The sectional curvature: 0, :math:`1/r^2` or :math:`-1/r^2`.
    ///
    /// Raises:
    ///     InvalidArgumentError (a Riemannian chart, whose curvature varies).
    #[getter]
    fn curvature(&self) -> PyResult<f64> {
        Ok(self.form("curvature")?.curvature())
    }

    /// The radius r (1 for Euclidean space, which has none).
    ///
    /// Raises:
    ///     InvalidArgumentError (a Riemannian chart).
    #[getter]
    fn radius(&self) -> PyResult<f64> {
        Ok(self.form("radius")?.length())
    }

    /// The number of components of a point: 3 (Euclidean, a Riemannian chart) or 4.
    #[getter]
    fn ambient_dim(&self) -> usize {
        match &self.inner {
            Kind::Form(f) => f.ambient_dim(),
            Kind::Chart { .. } => 3,
        }
    }

    /// Checks at x that the frame of a `Riemannian` chart is orthonormal and positively oriented
    /// for its metric: :math:`E^\top g E = 1` within `tol` (E the matrix whose columns are the
    /// rows of `frame(x1, x2, x3)`) and :math:`\det E > 0`. Returns None.
    ///
    /// Raises:
    ///     InvalidArgumentError (the frame fails the check, names the pair (a, b); x outside the
    ///     chart; tol not a finite number >= 0; a space form, whose frame is orthonormal by
    ///     construction), the exception of a callable.
    #[pyo3(signature = (x, tol = 1e-10))]
    fn check_frame(
        &self,
        #[pyo3(from_py_with = reals::<3>)] x: [f64; 3],
        #[pyo3(from_py_with = real)] tol: f64,
    ) -> PyResult<()> {
        match &self.inner {
            Kind::Chart { chart, .. } => checked(|| chart.check_frame(x, tol)),
            Kind::Form(f) => Err(to_py(Error::invalid(
                "check_frame",
                format!(
                    "only a Riemannian chart has a frame given by callables to check; the frame \
                     of {} is orthonormal by construction",
                    f.name()
                ),
            ))),
        }
    }

    /// The reference frame :math:`\hat E(x)`: a (d, 3) array whose columns are the ambient
    /// components of :math:`\hat E_1, \hat E_2, \hat E_3` at the point x (d = `ambient_dim`).
    /// Euclidean: the constant frame; Sphere: :math:`x i/r, x j/r, x k/r` (quaternion products,
    /// the left-invariant fields of SU(2)); Hyperbolic: the boost taking (r, 0, 0, 0) to x applied
    /// to :math:`e_1, e_2, e_3`; Riemannian: the chart
    /// components of the frame the callable gives (the transpose of its value).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, InvalidArgumentError (x not on the space), the exception
    ///     of a callable.
    fn reference_frame<'py>(
        &self,
        py: Python<'py>,
        x: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let x = vector("x", &x)?;
        let rows: Vec<Vec<f64>> = match &self.inner {
            Kind::Form(form) => {
                form.check_point(&x).py()?;
                let f = form.reference(&x);
                let k = 4 - form.ambient_dim();
                (k..4)
                    .map(|i| (1..4).map(|j| f[(i, j)]).collect())
                    .collect()
            }
            Kind::Chart { chart, .. } => {
                let x: [f64; 3] = x
                    .as_slice()
                    .try_into()
                    .map_err(|_| to_py(Error::shape("x", "(3,)", format!("({},)", x.len()))))?;
                checked(|| chart.check_point(x))?;
                let e = checked(|| Ok(chart.frame(x)))?;
                (0..3)
                    .map(|i| (0..3).map(|j| e[(i, j)]).collect())
                    .collect()
            }
        };
        PyArray2::from_vec2(py, &rows)
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Any<'py>, Bound<'py, PyTuple>)> {
        let m = py.import("lieflow.spaces")?;
        Ok(match &self.inner {
            Kind::Form(SpaceForm::Euclidean) => (m.getattr("Euclidean")?, PyTuple::new(py, [3])?),
            Kind::Form(SpaceForm::Sphere { radius }) => {
                (m.getattr("Sphere")?, (3, *radius).into_pyobject(py)?)
            }
            Kind::Form(SpaceForm::Hyperbolic { radius }) => {
                (m.getattr("Hyperbolic")?, (3, *radius).into_pyobject(py)?)
            }
            Kind::Chart { args, .. } => (m.getattr("Riemannian")?, args.bind(py).clone()),
        })
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(match &self.inner {
            Kind::Form(f) => f.name(),
            Kind::Chart { args, .. } => format!("Riemannian{}", args.bind(py).repr()?),
        })
    }

    /// Space forms hash by value; a chart by identity.
    fn __hash__(slf: &Bound<'_, Self>) -> u64 {
        let (kind, r) = match &slf.get().inner {
            Kind::Form(SpaceForm::Euclidean) => (0u64, 1.0f64),
            Kind::Form(SpaceForm::Sphere { radius }) => (1, *radius),
            Kind::Form(SpaceForm::Hyperbolic { radius }) => (2, *radius),
            Kind::Chart { .. } => return slf.as_ptr() as u64,
        };
        kind.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ r.to_bits()
    }

    /// Space forms are equal by value; a chart only to itself.
    fn __eq__(slf: &Bound<'_, Self>, other: &Bound<'_, PyAny>) -> bool {
        let Ok(o) = other.cast::<PySpace>() else {
            return false;
        };
        match (&slf.get().inner, &o.get().inner) {
            (Kind::Form(a), Kind::Form(b)) => a == b,
            _ => slf.as_ptr() == o.as_ptr(),
        }
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

/// Euclidean space :math:`\mathbb{R}^3` (curvature 0; frame bundle SE(3)).
///
/// Raises:
///     InvalidArgumentError (n != 3).
#[pyfunction]
#[pyo3(signature = (n=3))]
fn Euclidean(#[pyo3(from_py_with = int)] n: i64) -> PyResult<PySpace> {
    three(n)?;
    Ok(PySpace {
        inner: Kind::Form(SpaceForm::Euclidean),
    })
}

/// The 3-sphere of radius r in :math:`\mathbb{R}^4` (curvature :math:`1/r^2`; frame bundle SO(4)).
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
        inner: Kind::Form(SpaceForm::sphere(radius).py()?),
    })
}

/// Hyperbolic 3-space of radius r, the hyperboloid :math:`x_0^2 - x_1^2 - x_2^2 - x_3^2 = r^2`,
/// :math:`x_0 > 0` in Minkowski :math:`\mathbb{R}^{1,3}` (curvature :math:`-1/r^2`; frame bundle
/// :math:`SO^+(1,3)`).
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
        inner: Kind::Form(SpaceForm::hyperbolic(radius).py()?),
    })
}

/// A Riemannian 3-manifold in one chart (002 §V for a general metric): the metric g(x) and an
/// orthonormal frame field given as callables of the chart coordinates.
///
/// Numerical, like `lieflow.surfaces.MetricSurface`: the connection of the frame (the matrix C
/// whose column j is the axial vector of :math:`A_j = (g(E_a, \nabla_j E_b))_{ab}`) by fourth-order
/// differences of g and the frame, and its derivatives by differences of C (errors about 1e-12
/// in C and 1e-9 in its derivatives for smooth data of order one). Each evaluation of the top's
/// field calls the callables about 330 times. A `FrameTop` on it has no Killing momenta.
///
/// Args:
///     metric: ``metric(x1, x2, x3)`` -> (3, 3) symmetric positive definite :math:`g_{ij}`.
///     frame: ``frame(x1, x2, x3)`` -> (3, 3) whose row a holds the components :math:`e_a^i` of
///         the orthonormal frame vector :math:`E_a` (check it with `check_frame`).
///     domain: optional ``domain(x1, x2, x3)`` -> bool; the chart is where it holds and g is
///         finite and positive definite.
/// Returns:
///     Space.
/// Raises:
///     TypeError (not callable).
#[pyfunction]
#[pyo3(signature = (metric, frame, domain=None))]
fn Riemannian<'py>(
    metric: Any<'py>,
    frame: Any<'py>,
    domain: Option<Any<'py>>,
) -> PyResult<PySpace> {
    let py = metric.py();
    let field = |what: &'static str, f: Py<PyAny>| {
        move |x: [f64; 3]| {
            let v = call_floats::<9>(&f, &x, what, &[3, 3]);
            std::array::from_fn(|i| std::array::from_fn(|j| v[3 * i + j]))
        }
    };
    let dom = match &domain {
        Some(d) => Some(std::sync::Arc::new(domain_closure::<3>(
            callable("domain", d)?,
            "domain(x1, x2, x3)",
        ))
            as lieflow::systems::tangent_top::riemannian::Domain),
        None => None,
    };
    let chart = Chart::new(
        field("metric(x1, x2, x3)", callable("metric", &metric)?),
        field("frame(x1, x2, x3)", callable("frame", &frame)?),
        dom,
    );
    Ok(PySpace {
        inner: Kind::Chart {
            chart,
            args: (metric, frame, domain).into_pyobject(py)?.unbind(),
        },
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySpace>()?;
    m.add_function(wrap_pyfunction!(Riemannian, m)?)?;
    m.add_function(wrap_pyfunction!(Euclidean, m)?)?;
    m.add_function(wrap_pyfunction!(Sphere, m)?)?;
    m.add_function(wrap_pyfunction!(Hyperbolic, m)?)?;
    Ok(())
}
