//! `lieflow.PseudoRigidBody` and `lieflow.potentials`: bindings of
//! `lieflow::pseudo_rigid::{system, potential}` (001 §3–§7). Conversions only.
//!
//! The body implements the integration protocol (`methods`, `state_dim`, `_normalize_state`,
//! `_run`, `energy`, `casimirs`, `_fields` and the observables `angular_momentum`,
//! `circulation`, `singular_values`). State layout: z = (X row-major, P row-major), d = 2n².
#![allow(non_snake_case)]

use std::fmt;
use std::sync::{Arc, Mutex};

use lieflow::integrate::{integrate_batch, Method, State, System};
use lieflow::pseudo_rigid::potential::{
    self as pot, Harmonic as CoreHarmonic, SaintVenantKirchhoff as CoreSvk, Sum,
    Volumetric as CoreVolumetric, Workspace, Zero as CoreZero,
};
use lieflow::pseudo_rigid::PseudoRigidBody as CoreBody;
use lieflow::{Error, Mat};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArray2, PyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::convert::{mat, py_mat, ArrayIn};
use crate::errors::{shift_time, to_py, IntoPy};

/// An SO(n)×SO(n)-invariant potential U(X) of a pseudo-rigid body (001 §4.1). Build one with
/// `Harmonic(k)`, `SaintVenantKirchhoff(lam, mu)`, `Volumetric(kappa, gamma)`, `Zero()` or
/// `Callable(U, grad_U)`; add potentials with `+`.
#[pyclass(module = "lieflow.potentials", frozen, name = "Potential")]
#[derive(Clone)]
pub struct PyPotential {
    inner: Arc<dyn pot::Potential>,
    desc: String,
    callback: Option<Arc<CallablePotential>>,
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
    fn __add__(&self, other: &PyPotential) -> PyPotential {
        PyPotential {
            inner: Arc::new(Sum::new(vec![self.inner.clone(), other.inner.clone()])),
            desc: format!("{} + {}", self.desc, other.desc),
            callback: self.callback.clone().or_else(|| other.callback.clone()),
        }
    }

    fn __repr__(&self) -> String {
        self.desc.clone()
    }
}

impl PyPotential {
    fn new(inner: Arc<dyn pot::Potential>, desc: String) -> Self {
        PyPotential {
            inner,
            desc,
            callback: None,
        }
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
struct CallablePotential {
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

    fn take_error(&self) -> PyResult<()> {
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
fn Harmonic(k: f64) -> PyResult<PyPotential> {
    Ok(PyPotential::new(
        Arc::new(CoreHarmonic::new(k).py()?),
        format!("Harmonic({k})"),
    ))
}

/// Isotropic Saint Venant–Kirchhoff energy U = (lam/2)(tr E)^2 + mu tr(E^2), E = (X^T X - I)/2.
///
/// Raises:
///     InvalidArgumentError: mu <= 0, lam < 0 or not finite.
#[pyfunction]
fn SaintVenantKirchhoff(lam: f64, mu: f64) -> PyResult<PyPotential> {
    Ok(PyPotential::new(
        Arc::new(CoreSvk::new(lam, mu).py()?),
        format!("SaintVenantKirchhoff({lam}, {mu})"),
    ))
}

/// Polytropic volumetric (gas) term U = kappa (det(X)^(1-gamma) - 1)/(gamma - 1), gamma > 1, and
/// U = -kappa ln det X for gamma = 1. Defined only for det X > 0 (integrations always check it).
///
/// Raises:
///     InvalidArgumentError: kappa <= 0, gamma < 1 or not finite.
#[pyfunction]
#[pyo3(signature = (kappa, gamma=1.4))]
fn Volumetric(kappa: f64, gamma: f64) -> PyResult<PyPotential> {
    Ok(PyPotential::new(
        Arc::new(CoreVolumetric::polytropic(kappa, gamma).py()?),
        format!("Volumetric({kappa}, {gamma})"),
    ))
}

/// U = 0, the free body (motions X(t) = X0 + t P0).
#[pyfunction]
fn Zero() -> PyPotential {
    PyPotential::new(Arc::new(CoreZero), "Zero()".into())
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
        value: value.unbind(),
        gradient: gradient.unbind(),
        error: Mutex::new(None),
    });
    Ok(PyPotential {
        inner: cb.clone(),
        desc: "Callable(...)".into(),
        callback: Some(cb),
    })
}

/// A generalized pseudo-rigid body on T*GL+(n) with H = tr(P^T P)/2 + U(X) (001 (3.22)).
///
/// Args:
///     n: dimension (>= 2).
///     potential: a `lieflow.potentials` potential (default: Zero(), the free body).
///     check_det: stop with LeftDomainError (naming the time) when det X <= 0 (always on for a
///         volumetric potential; the equations extend to all n×n matrices otherwise).
///
/// Integrate with `lf.integrate(body, (X0, P0), dt=..., steps=..., method=...)`, methods
/// "verlet", "verlet4", "verlet6" (Störmer–Verlet and its order-4/6 compositions) and "reduced"
/// (reduced-space splitting on the principal stratum, 001 §7, order 2, exact coadjoint orbits).
/// States are flat: z = (X row-major, P row-major), length 2n².
#[pyclass(module = "lieflow", frozen, name = "PseudoRigidBody")]
pub struct PyPseudoRigidBody {
    body: CoreBody,
    potential: PyPotential,
}

type Dyn<'py> = Bound<'py, PyArrayDyn<f64>>;

impl PyPseudoRigidBody {
    fn d(&self) -> usize {
        self.body.dim()
    }

    /// Rows of a (..., d) array, with the leading shape.
    fn rows(&self, states: &ArrayIn<'_>) -> PyResult<(Vec<usize>, Vec<f64>)> {
        let v = states.as_array();
        let d = self.d();
        if v.ndim() == 0 || v.shape()[v.ndim() - 1] != d {
            let s: Vec<String> = v.shape().iter().map(|x| x.to_string()).collect();
            return Err(to_py(Error::shape(
                "states",
                format!("(..., {d})"),
                format!("({})", s.join(", ")),
            )));
        }
        let lead = v.shape()[..v.ndim() - 1].to_vec();
        Ok((lead, v.iter().copied().collect()))
    }

    /// Applies `f` to every state row; output shape = leading shape + `extra`.
    fn map<'py>(
        &self,
        py: Python<'py>,
        states: &ArrayIn<'py>,
        extra: &[usize],
        f: impl Fn(&[f64]) -> lieflow::Result<Vec<f64>>,
    ) -> PyResult<Dyn<'py>> {
        let (mut shape, data) = self.rows(states)?;
        let mut out = Vec::new();
        for z in data.chunks_exact(self.d()) {
            out.extend(f(z).py()?);
        }
        self.potential.take_callback_error()?;
        shape.extend_from_slice(extra);
        let arr = ArrayD::from_shape_vec(IxDyn(&shape), out)
            .map_err(|e| to_py(Error::invalid("states", e.to_string())))?;
        Ok(arr.into_pyarray(py))
    }

    fn flat(m: &Mat) -> Vec<f64> {
        let n = m.nrows();
        (0..n * n).map(|k| m[(k / n, k % n)]).collect()
    }
}

#[pymethods]
impl PyPseudoRigidBody {
    #[new]
    #[pyo3(signature = (n, potential=None, check_det=true))]
    fn new(n: i64, potential: Option<Bound<'_, PyPotential>>, check_det: bool) -> PyResult<Self> {
        let n = usize::try_from(n)
            .map_err(|_| to_py(Error::invalid("n", format!("expected n ≥ 2, got {n}"))))?;
        let potential = potential.map_or_else(Zero, |p| p.get().clone());
        Ok(PyPseudoRigidBody {
            body: CoreBody::new(n, potential.inner.clone(), check_det).py()?,
            potential,
        })
    }

    /// The dimension n.
    #[getter]
    fn n(&self) -> usize {
        self.body.n()
    }

    /// Length d = 2n² of the flat state (X, P).
    #[getter]
    fn state_dim(&self) -> usize {
        self.d()
    }

    /// False: the pseudo-rigid body carries no attitude.
    #[getter]
    fn has_attitude(&self) -> bool {
        false
    }

    /// Whether det X > 0 is enforced during integrations.
    #[getter]
    fn check_det(&self) -> bool {
        self.body.check_det()
    }

    /// The potential.
    #[getter]
    fn potential(&self) -> PyPotential {
        self.potential.clone()
    }

    /// The supported integration methods.
    fn methods(&self) -> Vec<&'static str> {
        self.body.methods().iter().map(|m| m.name()).collect()
    }

    fn __repr__(&self) -> String {
        format!(
            "PseudoRigidBody(n={}, potential={}, check_det={})",
            self.n(),
            self.potential.desc,
            if self.body.check_det() {
                "True"
            } else {
                "False"
            }
        )
    }

    /// Parses an initial state: a pair (X0, P0) of (n, n) arrays or (b, n, n) batches, or flat
    /// states (d,) / (b, d). Returns (z0 of shape (b, d), batched).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn _normalize_state<'py>(
        &self,
        py: Python<'py>,
        state0: Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, bool)> {
        let d = self.d();
        let (rows, batched): (Vec<Vec<f64>>, bool) =
            if state0.is_instance_of::<PyTuple>() || state0.is_instance_of::<PyList>() {
                let len = state0.len()?;
                if len != 2 {
                    return Err(to_py(Error::shape(
                        "state0",
                        "a pair (X0, P0)",
                        format!("a sequence of length {len}"),
                    )));
                }
                let x: ArrayIn<'_> = state0.get_item(0)?.extract()?;
                let p: ArrayIn<'_> = state0.get_item(1)?.extract()?;
                let (xs, bx) = crate::convert::mats("X0", &x)?;
                let (ps, bp) = crate::convert::mats("P0", &p)?;
                if bx != bp || xs.len() != ps.len() {
                    return Err(to_py(Error::shape(
                        "P0",
                        format!("the shape of X0 ({} matrices)", xs.len()),
                        format!("{} matrices", ps.len()),
                    )));
                }
                let mut rows = Vec::with_capacity(xs.len());
                for (x, p) in xs.iter().zip(&ps) {
                    rows.push(self.body.state(x, p).py()?.z);
                }
                (rows, bx)
            } else {
                let a: ArrayIn<'_> = state0.extract()?;
                let (rows, batched) = crate::convert::vectors("state0", &a)?;
                for r in &rows {
                    lieflow::check::len_of("state0", r, d).py()?;
                    lieflow::check::finite_slice("state0", r).py()?;
                }
                (rows, batched)
            };
        let flat: Vec<f64> = rows.concat();
        let arr = numpy::ndarray::Array2::from_shape_vec((rows.len(), d), flat)
            .map_err(|e| to_py(Error::invalid("state0", e.to_string())))?;
        Ok((arr.into_pyarray(py), batched))
    }

    /// Integrates a batch z0 (b, d) (the integration protocol): returns
    /// (states (b, k, d), None, z_final (b, d), None) with k = steps // save_every + 1.
    /// `t0` (keyword, default 0) is the time of z0, added to the time a LeftDomainError names
    /// (for drivers that integrate in chunks).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, InvalidArgumentError (dt, steps, save_every, method, an
    ///     attitude), UnsupportedMethodError, NotInGroupError (det X0 <= 0),
    ///     DegenerateStratumError ("reduced" off the principal stratum), LeftDomainError (det X
    ///     reached 0 at the time named in the message).
    #[allow(clippy::type_complexity, clippy::too_many_arguments)]
    #[pyo3(signature = (z0, attitude0, dt, steps, save_every, method, *, t0=0.0))]
    fn _run<'py>(
        &self,
        py: Python<'py>,
        z0: ArrayIn<'py>,
        attitude0: Option<Bound<'py, PyAny>>,
        dt: f64,
        steps: i64,
        save_every: i64,
        method: &str,
        t0: f64,
    ) -> PyResult<(
        Dyn<'py>,
        Option<Py<PyAny>>,
        Bound<'py, PyArray2<f64>>,
        Option<Py<PyAny>>,
    )> {
        if attitude0.as_ref().is_some_and(|a| !a.is_none()) {
            return Err(to_py(Error::invalid(
                "attitude",
                "PseudoRigidBody carries no attitude",
            )));
        }
        let method = Method::from_name(method).py()?;
        let positive = |what: &str, v: i64| {
            usize::try_from(v).ok().filter(|&u| u >= 1).ok_or_else(|| {
                to_py(Error::invalid(
                    what,
                    format!("expected {what} ≥ 1, got {v}"),
                ))
            })
        };
        let (steps, save_every) = (
            positive("steps", steps)?,
            positive("save_every", save_every)?,
        );
        let v = z0.as_array();
        let d = self.d();
        if v.ndim() != 2 || v.shape()[1] != d {
            let s: Vec<String> = v.shape().iter().map(|x| x.to_string()).collect();
            return Err(to_py(Error::shape(
                "z0",
                format!("(b, {d})"),
                format!("({})", s.join(", ")),
            )));
        }
        let states0: Vec<State> = v
            .outer_iter()
            .map(|r| State::new(r.iter().copied().collect()))
            .collect();
        let body = &self.body;
        let threads = if self.potential.callback.is_some() {
            Some(1)
        } else {
            None
        };
        let res =
            py.detach(|| integrate_batch(body, method, &states0, dt, steps, save_every, threads));
        self.potential.take_callback_error()?;
        let trajs = res.map_err(|e| shift_time(e, t0)).py()?;
        let b = trajs.len();
        let k = steps / save_every + 1;
        let mut all = Vec::with_capacity(b * k * d);
        let mut fin = Vec::with_capacity(b * d);
        for t in &trajs {
            all.extend_from_slice(&t.states);
            fin.extend_from_slice(&t.final_state.z);
        }
        let states = ArrayD::from_shape_vec(IxDyn(&[b, k, d]), all)
            .map_err(|e| to_py(Error::invalid("states", e.to_string())))?;
        let fin = numpy::ndarray::Array2::from_shape_vec((b, d), fin)
            .map_err(|e| to_py(Error::invalid("states", e.to_string())))?;
        Ok((states.into_pyarray(py), None, fin.into_pyarray(py), None))
    }

    /// H = tr(P^T P)/2 + U(X) (001 (3.22)) of states (..., d) -> (...).
    fn energy<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Dyn<'py>> {
        self.map(py, &states, &[], |z| Ok(vec![self.body.energy(z)?]))
    }

    /// Spectral invariants tr((L^T L)^k)/2 then tr((Γ^T Γ)^k)/2, k = 1..n//2, of states
    /// (..., d) -> (..., 2 (n//2)): the Casimirs of the reduced space (coadjoint orbits of
    /// p_Omega = R^T L R and p_Lambda = S^T Γ S, 001 §7).
    fn casimirs<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Dyn<'py>> {
        let c = 2 * (self.n() / 2);
        self.map(py, &states, &[c], |z| self.body.casimirs(z))
    }

    /// Angular momentum L = P X^T - X P^T (001 (7.3)) of states (..., d) -> (..., n, n).
    fn angular_momentum<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Dyn<'py>> {
        let n = self.n();
        self.map(py, &states, &[n, n], |z| {
            Ok(Self::flat(&self.body.momenta(z)?.0))
        })
    }

    /// Circulation Γ = P^T X - X^T P (001 (7.3)) of states (..., d) -> (..., n, n).
    fn circulation<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Dyn<'py>> {
        let n = self.n();
        self.map(py, &states, &[n, n], |z| {
            Ok(Self::flat(&self.body.momenta(z)?.1))
        })
    }

    /// Singular values a_1 >= ... >= a_n of X (the semi-axes), states (..., d) -> (..., n).
    fn singular_values<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Dyn<'py>> {
        let n = self.n();
        self.map(py, &states, &[n], |z| self.body.singular_values(z))
    }

    /// {"X": (..., n, n), "P": (..., n, n)} views of states (..., d).
    fn _fields<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Bound<'py, PyDict>> {
        let n = self.n();
        let nn = n * n;
        let x = self.map(py, &states, &[n, n], |z| Ok(z[..nn].to_vec()))?;
        let p = self.map(py, &states, &[n, n], |z| Ok(z[nn..].to_vec()))?;
        let d = PyDict::new(py);
        d.set_item("X", x)?;
        d.set_item("P", p)?;
        Ok(d)
    }
}

/// Registers `PseudoRigidBody` in the top-level module and the `potentials` submodule.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPseudoRigidBody>()?;
    let p = PyModule::new(m.py(), "potentials")?;
    p.add_class::<PyPotential>()?;
    p.add_function(wrap_pyfunction!(Harmonic, &p)?)?;
    p.add_function(wrap_pyfunction!(SaintVenantKirchhoff, &p)?)?;
    p.add_function(wrap_pyfunction!(Volumetric, &p)?)?;
    p.add_function(wrap_pyfunction!(Zero, &p)?)?;
    p.add_function(wrap_pyfunction!(Callable, &p)?)?;
    m.add_submodule(&p)
}
