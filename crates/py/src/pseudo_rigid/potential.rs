//! `lieflow.potentials`: bindings of `lieflow::pseudo_rigid::potential` (001 §4.1). Potentials
//! pickle (by the function and arguments that made them).
#![allow(non_snake_case)]

use std::fmt;
use std::sync::{Arc, Mutex};

use lieflow::pseudo_rigid::potential::{
    self as pot, Harmonic as CoreHarmonic, SaintVenantKirchhoff as CoreSvk, Sum,
    Volumetric as CoreVolumetric, Workspace, Zero as CoreZero,
};
use lieflow::{Error, Mat};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::convert::{mat, py_mat, ArrayIn};
use crate::errors::{to_py, IntoPy};
use crate::system::Callbacks;

/// An SO(n)×SO(n)-invariant potential U(X) of a pseudo-rigid body (001 §4.1). Build one with
/// `Harmonic(k)`, `SaintVenantKirchhoff(lam, mu)`, `Volumetric(kappa, gamma)`, `Zero()` or
/// `Callable(U, grad_U)`; add potentials with `+`.
#[pyclass(module = "lieflow.potentials", frozen, name = "Potential")]
#[derive(Clone)]
pub struct PyPotential {
    pub(crate) inner: Arc<dyn pot::Potential>,
    desc: String,
    /// How to rebuild it, (callable, args), for `__reduce__` (pickling).
    recipe: Arc<(Py<PyAny>, Py<PyTuple>)>,
    pub(crate) callback: Option<Arc<CallablePotential>>,
}

#[pymethods]
impl PyPotential {
    /// U(X) for an (n, n) array X.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, NotInGroupError (det X <= 0 for a volumetric term).
    fn value(&self, X: ArrayIn<'_>) -> PyResult<f64> {
        let v = pot::value(&*self.inner, &mat("X", &X)?).py()?;
        self.take_callback_error()?;
        Ok(v)
    }

    /// The gradient dU/dX (pairing tr(A^T B)) at an (n, n) array X, as an (n, n) array.
    fn gradient<'py>(
        &self,
        py: Python<'py>,
        X: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let g = pot::gradient(&*self.inner, &mat("X", &X)?).py()?;
        self.take_callback_error()?;
        Ok(py_mat(py, &g))
    }

    /// The sum of two potentials.
    fn __add__(slf: &Bound<'_, Self>, other: &Bound<'_, PyPotential>) -> PyResult<PyPotential> {
        let py = slf.py();
        let (a, b) = (slf.get(), other.get());
        let add = py.import("operator")?.getattr("add")?;
        Ok(PyPotential {
            inner: Arc::new(Sum::new(vec![a.inner.clone(), b.inner.clone()])),
            desc: format!("{} + {}", a.desc, b.desc),
            recipe: Arc::new((add.unbind(), PyTuple::new(py, [slf, other])?.unbind())),
            callback: a.callback.clone().or_else(|| b.callback.clone()),
        })
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> (Py<PyAny>, Py<PyTuple>) {
        (self.recipe.0.clone_ref(py), self.recipe.1.clone_ref(py))
    }

    fn __repr__(&self) -> String {
        self.desc.clone()
    }
}

impl PyPotential {
    /// A potential made by the function `lieflow.potentials.NAME(*args)`.
    fn new<'py, A: IntoPyObject<'py>>(
        py: Python<'py>,
        inner: Arc<dyn pot::Potential>,
        desc: String,
        name: &str,
        args: impl IntoIterator<Item = A, IntoIter: ExactSizeIterator>,
    ) -> PyResult<Self> {
        let f = py.import("lieflow.potentials")?.getattr(name)?;
        Ok(PyPotential {
            inner,
            desc,
            recipe: Arc::new((f.unbind(), PyTuple::new(py, args)?.unbind())),
            callback: None,
        })
    }

    /// Re-raises the first Python exception raised by a callable potential, if any.
    fn take_callback_error(&self) -> PyResult<()> {
        match &self.callback {
            Some(c) => c.take_error(),
            None => Ok(()),
        }
    }
}

/// A potential given by Python callables (the slow path: every evaluation takes the GIL).
pub(crate) struct CallablePotential {
    value: Py<PyAny>,
    gradient: Py<PyAny>,
    error: Mutex<Option<PyErr>>,
}

impl fmt::Debug for CallablePotential {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("CallablePotential")
    }
}

impl CallablePotential {
    fn record(&self, e: PyErr) {
        let mut slot = self.error.lock().unwrap_or_else(|p| p.into_inner());
        slot.get_or_insert(e);
    }

    pub(crate) fn take_error(&self) -> PyResult<()> {
        let mut slot = self.error.lock().unwrap_or_else(|p| p.into_inner());
        match slot.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    fn call<'py>(
        &self,
        py: Python<'py>,
        f: &Py<PyAny>,
        x: faer::MatRef<'_, f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = Mat::from_fn(x.nrows(), x.ncols(), |i, j| x[(i, j)]);
        f.bind(py).call1((py_mat(py, &m),))
    }
}

impl pot::Potential for CallablePotential {
    fn value(&self, x: faer::MatRef<'_, f64>, _ws: &mut Workspace) -> f64 {
        Python::attach(|py| {
            match self
                .call(py, &self.value, x)
                .and_then(|v| v.extract::<f64>())
            {
                Ok(v) => v,
                Err(e) => {
                    self.record(e);
                    f64::NAN
                }
            }
        })
    }

    fn add_gradient(
        &self,
        x: faer::MatRef<'_, f64>,
        mut out: faer::MatMut<'_, f64>,
        _ws: &mut Workspace,
    ) {
        let n = x.nrows();
        Python::attach(|py| {
            let g = self.call(py, &self.gradient, x).and_then(|g| {
                let g: ArrayIn<'_> = g.extract()?;
                let m = mat("gradient", &g)?;
                if m.nrows() != n || m.ncols() != n {
                    return Err(to_py(Error::shape(
                        "gradient returned by the callable",
                        format!("({n}, {n})"),
                        format!("({}, {})", m.nrows(), m.ncols()),
                    )));
                }
                Ok(m)
            });
            match g {
                Ok(m) => {
                    for i in 0..n {
                        for j in 0..n {
                            out[(i, j)] += m[(i, j)];
                        }
                    }
                }
                Err(e) => {
                    self.record(e);
                    for i in 0..n {
                        for j in 0..n {
                            out[(i, j)] = f64::NAN;
                        }
                    }
                }
            }
        });
    }
}

/// Harmonic potential U = (k/2) tr(X^T X), dU/dX = k X (000 §5.3); k > 0.
///
/// Raises:
///     InvalidArgumentError: k <= 0 or not finite.
#[pyfunction]
fn Harmonic(py: Python<'_>, k: f64) -> PyResult<PyPotential> {
    let inner = Arc::new(CoreHarmonic::new(k).py()?);
    PyPotential::new(py, inner, format!("Harmonic({k})"), "Harmonic", [k])
}

/// Isotropic Saint Venant–Kirchhoff energy U = (lam/2)(tr E)^2 + mu tr(E^2), E = (X^T X - I)/2.
///
/// Raises:
///     InvalidArgumentError: mu <= 0, lam < 0 or not finite.
#[pyfunction]
fn SaintVenantKirchhoff(py: Python<'_>, lam: f64, mu: f64) -> PyResult<PyPotential> {
    let inner = Arc::new(CoreSvk::new(lam, mu).py()?);
    let desc = format!("SaintVenantKirchhoff({lam}, {mu})");
    PyPotential::new(py, inner, desc, "SaintVenantKirchhoff", [lam, mu])
}

/// Polytropic volumetric (gas) term U = kappa (det(X)^(1-gamma) - 1)/(gamma - 1), gamma > 1, and
/// U = -kappa ln det X for gamma = 1. Defined only for det X > 0 (integrations always check it).
///
/// Raises:
///     InvalidArgumentError: kappa <= 0, gamma < 1 or not finite.
#[pyfunction]
#[pyo3(signature = (kappa, gamma=1.4))]
fn Volumetric(py: Python<'_>, kappa: f64, gamma: f64) -> PyResult<PyPotential> {
    let inner = Arc::new(CoreVolumetric::polytropic(kappa, gamma).py()?);
    let desc = format!("Volumetric({kappa}, {gamma})");
    PyPotential::new(py, inner, desc, "Volumetric", [kappa, gamma])
}

/// U = 0, the free body (motions X(t) = X0 + t P0).
#[pyfunction]
pub(crate) fn Zero(py: Python<'_>) -> PyResult<PyPotential> {
    PyPotential::new(py, Arc::new(CoreZero), "Zero()".into(), "Zero", [0.0; 0])
}

/// A potential from Python callables: `value(X) -> float` and `gradient(X) -> (n, n) array`,
/// both called with an (n, n) float64 array. This is the slow path (each call takes the GIL);
/// U must be SO(n)×SO(n)-invariant (a function of the singular values of X) for L and Γ to be
/// conserved. Exceptions raised by the callables are re-raised by the integration.
///
/// Raises:
///     TypeError: value or gradient not callable.
#[pyfunction]
fn Callable(value: Bound<'_, PyAny>, gradient: Bound<'_, PyAny>) -> PyResult<PyPotential> {
    for (what, f) in [("value", &value), ("gradient", &gradient)] {
        if !f.is_callable() {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "{what} must be callable"
            )));
        }
    }
    let cb = Arc::new(CallablePotential {
        value: value.clone().unbind(),
        gradient: gradient.clone().unbind(),
        error: Mutex::new(None),
    });
    let py = value.py();
    let f = py.import("lieflow.potentials")?.getattr("Callable")?;
    let args = PyTuple::new(py, [&value, &gradient])?.unbind();
    Ok(PyPotential {
        inner: cb.clone(),
        desc: "Callable(...)".into(),
        recipe: Arc::new((f.unbind(), args)),
        callback: Some(cb),
    })
}

impl Callbacks for CallablePotential {
    fn take_error(&self) -> PyResult<()> {
        CallablePotential::take_error(self)
    }
}

/// Fills the `potentials` submodule.
pub fn register(p: &Bound<'_, PyModule>) -> PyResult<()> {
    p.add_class::<PyPotential>()?;
    p.add_function(wrap_pyfunction!(Harmonic, p)?)?;
    p.add_function(wrap_pyfunction!(SaintVenantKirchhoff, p)?)?;
    p.add_function(wrap_pyfunction!(Volumetric, p)?)?;
    p.add_function(wrap_pyfunction!(Zero, p)?)?;
    p.add_function(wrap_pyfunction!(Callable, p)?)?;
    Ok(())
}
