//! `lieflow.surfaces`: the surfaces of `lieflow::systems::tangent_top::surface` (002 §II–III), built in or
//! from Python callables. A surface pickles by the function of this module and the arguments that
//! made it (callables pickle by reference, so pass module-level functions).
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::systems::tangent_top::surface::{self, Jet, Mat2, Surface, Vec2};
use lieflow::Error;
use numpy::ndarray::arr2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyTuple};

use crate::convert::{real, real_pair, reals};
use crate::convert::{shape_str, ArrayIn};
use crate::errors::{argument_type_error, checked, raised, IntoPy};

type Any<'py> = Bound<'py, PyAny>;

/// A surface in local coordinates :math:`x = (x_1, x_2)` with an orthonormal frame
/// :math:`(E_1, E_2)` and the connection 1-form :math:`w = \alpha_i dx^i` of that frame,
/// :math:`w(v) = \langle \nabla_v E_1, E_2 \rangle` (002 (43)).
/// Made by `Plane`, `Sphere`, `HyperbolicPlane`, `Revolution`, `Torus`, `Graph`, `Quadric` and
/// `MetricSurface` of this module.
#[pyclass(module = "lieflow.surfaces", name = "Surface", frozen)]
pub struct PySurface {
    pub(crate) inner: Arc<dyn Surface>,
    /// The same surface as its type for `MetricSurface` (its `check_frame`), else None.
    metric_surface: Option<Arc<surface::MetricSurface>>,
    /// (function of `lieflow.surfaces`, its arguments), for pickling.
    recipe: (&'static str, Py<PyTuple>),
    desc: String,
}

impl PySurface {
    fn new(
        inner: Arc<dyn Surface>,
        name: &'static str,
        args: Bound<'_, PyTuple>,
    ) -> PyResult<Self> {
        let desc = format!("{name}{}", args.repr()?);
        Ok(PySurface {
            inner,
            metric_surface: None,
            recipe: (name, args.unbind()),
            desc: desc.replace(",)", ")"),
        })
    }

    /// `f(x)` for an x checked to lie in the chart, re-raising a callable's exception.
    fn at<T>(&self, x: Vec2, f: impl FnOnce(Vec2) -> T) -> PyResult<T> {
        checked(|| self.inner.check(x).map_err(|v| v.at_start()))?;
        checked(|| Ok(f(x)))
    }
}

fn mat2(py: Python<'_>, m: Mat2) -> Bound<'_, PyArray2<f64>> {
    arr2(&m).into_pyarray(py)
}

#[pymethods]
impl PySurface {
    /// The Gaussian curvature K at x.
    ///
    /// Raises:
    ///     InvalidArgumentError (x outside the chart).
    fn curvature(&self, #[pyo3(from_py_with = reals::<2>)] x: Vec2) -> PyResult<f64> {
        self.at(x, |x| self.inner.curvature(x))
    }

    /// The metric :math:`g_{ij}` at x, (2, 2).
    ///
    /// Raises:
    ///     InvalidArgumentError (x outside the chart).
    fn metric<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = reals::<2>)] x: Vec2,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(mat2(py, self.at(x, |x| self.inner.metric(x))?))
    }

    /// The orthonormal frame at x, (2, 2): row a holds the components :math:`e_a^i` of
    /// :math:`E_a = e_a^i \partial_i`.
    ///
    /// Raises:
    ///     InvalidArgumentError (x outside the chart).
    fn frame<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = reals::<2>)] x: Vec2,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(mat2(py, self.at(x, |x| self.inner.frame(x))?))
    }

    /// The connection 1-form :math:`(\alpha_1, \alpha_2)` of the frame at x (002 (43)).
    ///
    /// Raises:
    ///     InvalidArgumentError (x outside the chart).
    fn connection(&self, #[pyo3(from_py_with = reals::<2>)] x: Vec2) -> PyResult<Vec2> {
        self.at(x, |x| self.inner.connection(x))
    }

    /// Checks at x that the frame of a `MetricSurface` is orthonormal and positively oriented
    /// for its metric: :math:`g(E_a, E_b) = \delta_{ab}` within `tol`
    /// (:math:`g(E_a, E_b) = e_a^\top g\, e_b` with the rows :math:`e_a` of `frame(x1, x2)`) and
    /// :math:`\det e > 0`; the connection 1-form and the
    /// dynamics on the surface assume it (002 (43)). Returns None.
    ///
    /// Raises:
    ///     InvalidArgumentError (the frame fails the check, names the pair (a, b); x outside the
    ///     chart; tol not a finite number >= 0; a surface other than a MetricSurface, whose frame
    ///     is orthonormal by construction), the exception of a callable.
    #[pyo3(signature = (x, tol = 1e-10))]
    fn check_frame(
        &self,
        #[pyo3(from_py_with = reals::<2>)] x: Vec2,
        #[pyo3(from_py_with = real)] tol: f64,
    ) -> PyResult<()> {
        let Some(ms) = &self.metric_surface else {
            return Err(crate::errors::to_py(Error::invalid(
                "check_frame",
                format!(
                    "only a MetricSurface has a frame given by callables to check; the frame of \
                     {} is orthonormal by construction",
                    self.desc
                ),
            )));
        };
        checked(|| ms.check_frame(x, tol))
    }

    /// The names of the Killing generators, in the order of `TangentTop.killing_momenta`.
    #[getter]
    fn killing_names(&self) -> Vec<&'static str> {
        self.inner.killing_names().to_vec()
    }

    /// Whether the surface comes with an embedding in :math:`\mathbb{R}^3` (needed by
    /// `TangentTop(..., embedded=True)` and `TangentTop.ambient_frame`).
    #[getter]
    fn has_embedding(&self) -> bool {
        self.inner.embedding().is_some()
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Any<'py>, Bound<'py, PyTuple>)> {
        let f = py.import("lieflow.surfaces")?.getattr(self.recipe.0)?;
        Ok((f, self.recipe.1.bind(py).clone()))
    }

    fn __repr__(&self) -> String {
        self.desc.clone()
    }
}

/// Calls `f(*args)` and reads the array it returns, which must have `shape` (row-major); on an
/// exception or a wrong return records the error on this thread (`lieflow::integrate::hooks`)
/// and gives NaN (a run ends after that step; a direct call raises the error).
pub(crate) fn call_floats<const N: usize>(
    f: &Py<PyAny>,
    args: &[f64],
    what: &str,
    shape: &[usize],
) -> [f64; N] {
    if lieflow::integrate::hooks::pending() {
        return [f64::NAN; N];
    }
    Python::attach(|py| {
        let out = PyTuple::new(py, args)
            .and_then(|a| f.bind(py).call1(a))
            .and_then(|v| ArrayIn::named(&format!("the value of {what}"), &v))
            .map_err(|e| raised(what, e))
            .and_then(|a| {
                let v = a.as_array();
                if v.shape() != shape {
                    return Err(Error::shape(what, shape_str(shape), shape_str(v.shape())));
                }
                let mut out = [0.0; N];
                for (o, x) in out.iter_mut().zip(v.iter()) {
                    *o = *x;
                }
                Ok(out)
            });
        out.unwrap_or_else(|e| {
            lieflow::integrate::hooks::fail(e);
            [f64::NAN; N]
        })
    })
}

/// A chart's domain from a Python callable `domain(*x)` returning a bool; an exception or another
/// value records the error on this thread (`lieflow::integrate::hooks`) and reads as outside.
pub(crate) fn domain_closure<const D: usize>(
    d: Py<PyAny>,
    what: &'static str,
) -> impl Fn([f64; D]) -> bool + Send + Sync + 'static {
    move |x: [f64; D]| {
        if lieflow::integrate::hooks::pending() {
            return false;
        }
        Python::attach(|py| {
            let f = d.bind(py);
            PyTuple::new(py, x)
                .and_then(|a| f.call1(a))
                .and_then(|v| domain_value(f, &v))
                .unwrap_or_else(|e| {
                    lieflow::integrate::hooks::fail(raised(what, e));
                    false
                })
        })
    }
}

/// The value of a `domain(x1, x2)` callable: a bool or a numpy bool; anything else (a number,
/// NaN, a string, a list) is an `ArgumentTypeError` naming `domain`, not read by its truthiness.
fn domain_value(f: &Any<'_>, v: &Any<'_>) -> PyResult<bool> {
    if let Ok(b) = v.cast::<PyBool>() {
        return Ok(b.is_true());
    }
    let numpy_bool = v
        .get_type()
        .fully_qualified_name()
        .is_ok_and(|n| n == "numpy.bool" || n == "numpy.bool_");
    if numpy_bool {
        return v.is_truthy();
    }
    let name = |o: &Any<'_>| {
        o.getattr("__qualname__")
            .or_else(|_| o.get_type().name().map(|n| n.into_any()))
            .map_or_else(|_| "?".to_string(), |n| n.to_string())
    };
    Err(argument_type_error(
        v.py(),
        format!(
            "argument 'domain': the callable `{}` must return a bool (or numpy bool), got a {} ({})",
            name(f),
            name(&v.get_type().into_any()),
            v.repr().map_or_else(|_| "?".into(), |r| r.to_string())
        ),
    ))
}

pub(crate) fn callable(what: &str, f: &Any<'_>) -> PyResult<Py<PyAny>> {
    if f.is_callable() {
        Ok(f.clone().unbind())
    } else {
        Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "{what} must be callable"
        )))
    }
}

/// A surface made of native code.
fn native(
    py: Python<'_>,
    inner: impl Surface + 'static,
    name: &'static str,
    args: &[f64],
) -> PyResult<PySurface> {
    PySurface::new(Arc::new(inner), name, PyTuple::new(py, args)?)
}

/// The Euclidean plane, Cartesian x = (x, y), :math:`E = (\partial_x, \partial_y)`. Killing
/// generators: translations along x and y, the rotation about the origin.
#[pyfunction]
pub(crate) fn Plane(py: Python<'_>) -> PyResult<PySurface> {
    native(py, surface::Plane, "Plane", &[])
}

/// The sphere of radius R, x = (colatitude, longitude), :math:`E_1 = \partial_\theta / R`,
/// :math:`E_2 = \partial_\phi / (R \sin\theta)`. Killing generators: rotations about the ambient x,
/// y, z axes.
///
/// Raises:
///     InvalidArgumentError (R <= 0).
#[pyfunction]
fn Sphere(py: Python<'_>, #[pyo3(from_py_with = real)] radius: f64) -> PyResult<PySurface> {
    native(py, surface::Sphere::new(radius).py()?, "Sphere", &[radius])
}

/// The hyperbolic plane in the Poincaré half-plane :math:`y > 0` (002 (67)),
/// :math:`E_1 = y\, \partial_x`, :math:`E_2 = y\, \partial_y`. Killing generators: the Möbius
/// one-parameter groups of E, H, F in :math:`\mathfrak{sl}(2, \mathbb{R})`. Not embedded.
#[pyfunction]
fn HyperbolicPlane(py: Python<'_>) -> PyResult<PySurface> {
    native(py, surface::HyperbolicPlane, "HyperbolicPlane", &[])
}

/// The surface of revolution :math:`X(s, \phi) = (r(s) \cos\phi, r(s) \sin\phi, z(s))` about the z
/// axis on :math:`s_{\min} < s < s_{\max}` (where :math:`r > 0`), coordinates
/// :math:`x = (s, \phi)`, :math:`E_1 = \partial_s / \|X_s\|`, :math:`E_2 = \partial_\phi / r`. `r`
/// and `z` are callables s -> (f, f', f'', f''') (the third derivative enters only the embedded
/// top). Killing generator: the rotation about z (momentum p_phi). Slow path: every evaluation
/// calls Python; exceptions raised by the callables are re-raised.
///
/// Raises:
///     TypeError (not callable), InvalidArgumentError (an empty or non-finite range).
#[pyfunction]
fn Revolution<'py>(
    r: Any<'py>,
    z: Any<'py>,
    #[pyo3(from_py_with = real_pair)] s_range: (f64, f64),
) -> PyResult<PySurface> {
    let py = r.py();
    let profile =
        |what: &'static str, f: Py<PyAny>| move |s: f64| call_floats::<4>(&f, &[s], what, &[4]);
    let inner = surface::Revolution::new(
        profile("r(s)", callable("r", &r)?),
        profile("z(s)", callable("z", &z)?),
        s_range,
    )
    .py()?;
    let args = (r, z, s_range).into_pyobject(py)?;
    PySurface::new(Arc::new(inner), "Revolution", args)
}

/// The torus of radii :math:`a > b > 0` as a surface of revolution: :math:`r = a + b \cos s`,
/// :math:`z = b \sin s`, :math:`-\pi < s < \pi`.
///
/// Raises:
///     InvalidArgumentError (not a > b > 0).
#[pyfunction]
fn Torus(
    py: Python<'_>,
    #[pyo3(from_py_with = real)] a: f64,
    #[pyo3(from_py_with = real)] b: f64,
) -> PyResult<PySurface> {
    native(py, surface::Revolution::torus(a, b).py()?, "Torus", &[a, b])
}

/// The graph :math:`z = f(x, y)`, coordinates x = (x, y), frame by Gram–Schmidt of
/// :math:`(\partial_x, \partial_y)`. `f` is a
/// callable (x, y) -> the 10 numbers (f, f_x, f_y, f_xx, f_xy, f_yy, f_xxx, f_xxy, f_xyy, f_yyy).
/// Slow path: every evaluation calls Python; exceptions raised by `f` are re-raised.
///
/// Raises:
///     TypeError (not callable).
#[pyfunction]
fn Graph(f: Any<'_>) -> PyResult<PySurface> {
    let py = f.py();
    let call = callable("f", &f)?;
    let inner = surface::Graph::new(move |x: Vec2| {
        let v = call_floats::<10>(&call, &x, "f(x, y)", &[10]);
        Jet {
            value: v[0],
            gradient: [v[1], v[2]],
            hessian: [[v[3], v[4]], [v[4], v[5]]],
            third: [v[6], v[7], v[8], v[9]],
        }
    });
    let args = (f,).into_pyobject(py)?;
    PySurface::new(Arc::new(inner), "Graph", args)
}

/// The quadric :math:`z = \tfrac12 (a x^2 + b y^2)` as a graph (paraboloid for :math:`ab > 0`,
/// saddle for :math:`ab < 0`).
///
/// Raises:
///     NonFiniteError.
#[pyfunction]
fn Quadric(
    py: Python<'_>,
    #[pyo3(from_py_with = real)] a: f64,
    #[pyo3(from_py_with = real)] b: f64,
) -> PyResult<PySurface> {
    native(py, surface::Graph::quadric(a, b).py()?, "Quadric", &[a, b])
}

/// A surface given by its metric and an orthonormal frame, as callables x1, x2 -> (2, 2) arrays:
/// `metric` :math:`g_{ij}`, `frame` with row a the components of :math:`E_a` (orthonormal for g,
/// positively oriented: `Surface.check_frame` checks it at a point); `domain(x1, x2) -> bool`
/// optionally restricts the chart. The connection 1-form and the derivatives are computed
/// numerically (errors about 1e-12 in alpha, 1e-9 in its derivatives). No Killing generators, no
/// embedding. The slowest path: the differences call the two callables about 180 times per
/// evaluation of a top's vector field, so a gauss4 step costs some thousands of Python calls;
/// prefer a built-in, `Revolution` or `Graph` where one fits.
///
/// Raises:
///     TypeError (not callable).
#[pyfunction]
#[pyo3(signature = (metric, frame, domain=None))]
fn MetricSurface<'py>(
    metric: Any<'py>,
    frame: Any<'py>,
    domain: Option<Any<'py>>,
) -> PyResult<PySurface> {
    let py = metric.py();
    let field = |what: &'static str, f: Py<PyAny>| {
        move |x: Vec2| {
            let v = call_floats::<4>(&f, &x, what, &[2, 2]);
            [[v[0], v[1]], [v[2], v[3]]]
        }
    };
    let dom: Option<surface::DomainFn> = match &domain {
        Some(d) => Some(Arc::new(domain_closure::<2>(
            callable("domain", d)?,
            "domain(x1, x2)",
        ))),
        None => None,
    };
    let inner = surface::MetricSurface::new(
        field("metric(x1, x2)", callable("metric", &metric)?),
        field("frame(x1, x2)", callable("frame", &frame)?),
        dom,
    );
    let args = (metric, frame, domain).into_pyobject(py)?;
    let inner = Arc::new(inner);
    Ok(PySurface {
        metric_surface: Some(inner.clone()),
        ..PySurface::new(inner, "MetricSurface", args)?
    })
}

/// Fills the `surfaces` submodule.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySurface>()?;
    m.add_function(wrap_pyfunction!(Plane, m)?)?;
    m.add_function(wrap_pyfunction!(Sphere, m)?)?;
    m.add_function(wrap_pyfunction!(HyperbolicPlane, m)?)?;
    m.add_function(wrap_pyfunction!(Revolution, m)?)?;
    m.add_function(wrap_pyfunction!(Torus, m)?)?;
    m.add_function(wrap_pyfunction!(Graph, m)?)?;
    m.add_function(wrap_pyfunction!(Quadric, m)?)?;
    m.add_function(wrap_pyfunction!(MetricSurface, m)?)?;
    Ok(())
}
