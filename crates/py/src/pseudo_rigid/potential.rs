//! `lieflow.potentials`: bindings of `lieflow::pseudo_rigid::potential` (001 §4.1). Potentials
//! pickle (by the function and arguments that made them).
#![allow(non_snake_case)]

use std::fmt;
use std::sync::Arc;

use lieflow::pseudo_rigid::potential::{
    self as pot, Harmonic as CoreHarmonic, SaintVenantKirchhoff as CoreSvk,
    SelfGravity as CoreSelfGravity, Stretch as CoreStretch, Sum, Volumetric as CoreVolumetric,
    Workspace, Zero as CoreZero,
};
use lieflow::{Error, Mat};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::convert::{mat, py_mat, ArrayIn};
use crate::convert::{named, real, Real};
use crate::errors::{checked, raised, to_py, IntoPy};

/// An :math:`SO(n) \times SO(n)`-invariant potential :math:`U(X)` of a pseudo-rigid body
/// (001 §4.1). Build one with `Harmonic(k)`, `SaintVenantKirchhoff(lam, mu)`,
/// `Volumetric(kappa, gamma)`, `Stretch(k)`, `SelfGravity(G, rho)` (n = 3 only), `Zero()` or
/// `Callable(U, grad_U, hess_U=None)`; add potentials with `+`.
#[pyclass(module = "lieflow.potentials", frozen, name = "Potential")]
#[derive(Clone)]
pub struct PyPotential {
    pub(crate) inner: Arc<dyn pot::Potential>,
    desc: String,
    /// How to rebuild it, (callable, args), for `__reduce__` (pickling).
    recipe: Arc<(Py<PyAny>, Py<PyTuple>)>,
}

#[pymethods]
impl PyPotential {
    /// U(X) for an (n, n) array X.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0` for a volumetric
    ///     term).
    fn value(&self, X: ArrayIn<'_>) -> PyResult<f64> {
        // A callable's own error (exception, non-finite return) first, then the core's.
        let x = mat("X", &X)?;
        checked(|| pot::value(&*self.inner, &x))
    }

    /// The gradient :math:`\partial U/\partial X` (pairing :math:`\operatorname{tr}(A^\top B)`) at
    /// an (n, n) array X, as an (n, n) array.
    fn gradient<'py>(
        &self,
        py: Python<'py>,
        X: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let x = mat("X", &X)?;
        let g = checked(|| pot::gradient(&*self.inner, &x))?;
        Ok(py_mat(py, &g))
    }

    /// The Hessian of U at X applied to a direction V, D²U(X)[V] = d/de dU/dX(X + e V) at e = 0,
    /// as an (n, n) array H with sum(W * H) = D²U(X)[V, W] (symmetric in V and W).
    ///
    /// Raises:
    ///     ShapeError (X not square, V not of the shape of X), NonFiniteError,
    ///     NotInGroupError (:math:`\det X \le 0` for a volumetric term).
    fn hessian<'py>(
        &self,
        py: Python<'py>,
        X: ArrayIn<'py>,
        V: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (x, v) = (mat("X", &X)?, mat("V", &V)?);
        let h = checked(|| pot::hessian_product(&*self.inner, &x, &v))?;
        Ok(py_mat(py, &h))
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
        })
    }
}

/// A potential given by Python callables (the slow path: every evaluation takes the GIL).
pub(crate) struct CallablePotential {
    value: Py<PyAny>,
    gradient: Py<PyAny>,
    /// `hessian(X, V)`, or `None` for central differences of `gradient`.
    hessian: Option<Py<PyAny>>,
}

impl fmt::Debug for CallablePotential {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("CallablePotential")
    }
}

impl CallablePotential {
    /// Records the error `e` of a callable on this thread (`lieflow::integrate::hooks`): a run
    /// ends after that step, a direct call raises it.
    fn record(&self, e: PyErr) {
        lieflow::integrate::hooks::fail(raised("a callable potential", e));
    }

    fn call<'py>(
        &self,
        py: Python<'py>,
        f: &Py<PyAny>,
        x: faer::MatRef<'_, f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        f.bind(py).call1((py_mat(py, &x.to_owned()),))
    }

    /// Adds the (n, n) array returned by the callable `f` (`what` names the quantity in
    /// errors) to `out`, or records the error (also for a non-finite entry: NonFiniteError
    /// naming the callable and the entry) and fills `out` with NaN.
    fn add_returned(
        &self,
        what: &str,
        f: &Bound<'_, PyAny>,
        returned: PyResult<Bound<'_, PyAny>>,
        mut out: faer::MatMut<'_, f64>,
    ) {
        let n = out.nrows();
        let what = format!("{what} returned by the callable {}", callable_name(f));
        let m = returned.and_then(|g| {
            let g = ArrayIn::named(&what, &g)?;
            let m = mat(&what, &g)?;
            if m.nrows() != n || m.ncols() != n {
                return Err(to_py(Error::shape(
                    &what,
                    format!("({n}, {n})"),
                    format!("({}, {})", m.nrows(), m.ncols()),
                )));
            }
            lieflow::check::finite_mat(&what, &m).py()?;
            Ok(m)
        });
        match m {
            Ok(m) => out += &m,
            Err(e) => {
                self.record(e);
                out.fill(f64::NAN);
            }
        }
    }
}

/// A user callable as errors name it: its `__qualname__` (or `__name__`, or repr) in backquotes.
fn callable_name(f: &Bound<'_, PyAny>) -> String {
    let name = ["__qualname__", "__name__"]
        .iter()
        .find_map(|a| f.getattr(*a).ok().and_then(|n| n.extract::<String>().ok()))
        .or_else(|| f.repr().ok().map(|r| r.to_string()))
        .unwrap_or_else(|| "?".into());
    format!("`{name}`")
}

impl pot::Potential for CallablePotential {
    fn calls_out(&self) -> bool {
        true
    }

    fn value(&self, x: faer::MatRef<'_, f64>, _ws: &mut Workspace) -> f64 {
        if lieflow::integrate::hooks::pending() {
            return f64::NAN;
        }
        Python::attach(|py| {
            let value = self
                .call(py, &self.value, x)
                .and_then(|v| {
                    let what = format!(
                        "the value(X) returned by the callable {}",
                        callable_name(self.value.bind(py))
                    );
                    named(&what, v.extract::<Real>()).map(|r| r.0)
                })
                .and_then(|v| {
                    if v.is_finite() {
                        return Ok(v);
                    }
                    let f = self.value.bind(py);
                    Err(to_py(Error::NonFinite {
                        what: format!("the value(X) returned by the callable {}", callable_name(f)),
                        location: format!("its return value ({v})"),
                    }))
                });
            match value {
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
        if lieflow::integrate::hooks::pending() {
            return out.fill(f64::NAN);
        }
        Python::attach(|py| {
            let g = self.call(py, &self.gradient, x);
            self.add_returned("the gradient(X)", self.gradient.bind(py), g, out);
        });
    }

    /// The `hessian(X, V)` callable if given; otherwise the central difference
    /// :math:`(\nabla U(X + h\hat V) - \nabla U(X - h\hat V))\, \|V\|/(2h)` of the gradient
    /// callable along :math:`\hat V = V/\|V\|` with :math:`h = 10^{-6} \max(1, \|X\|)` (Frobenius
    /// norms; error :math:`O(h^2) + O(\varepsilon/h)` relative).
    fn add_hessian(
        &self,
        x: faer::MatRef<'_, f64>,
        v: faer::MatRef<'_, f64>,
        mut out: faer::MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        if lieflow::integrate::hooks::pending() {
            return out.fill(f64::NAN);
        }
        if let Some(hessian) = &self.hessian {
            Python::attach(|py| {
                let h = hessian
                    .bind(py)
                    .call1((py_mat(py, &x.to_owned()), py_mat(py, &v.to_owned())));
                self.add_returned(
                    "the Hessian product hessian(X, V)",
                    hessian.bind(py),
                    h,
                    out,
                );
            });
            return;
        }
        let norm_v = v.norm_l2();
        if norm_v == 0.0 {
            return;
        }
        let h = 1e-6 * x.norm_l2().max(1.0);
        let step = v * faer::Scale(h / norm_v);
        let (n, c) = (x.nrows(), 0.5 * norm_v / h);
        let (mut gp, mut gm) = (Mat::zeros(n, n), Mat::zeros(n, n));
        self.add_gradient((x + &step).as_ref(), gp.as_mut(), ws);
        self.add_gradient((x - &step).as_ref(), gm.as_mut(), ws);
        out += (gp - gm) * faer::Scale(c);
    }
}

/// Harmonic potential :math:`U = \tfrac{k}{2} \operatorname{tr}(X^\top X)`,
/// :math:`\partial U/\partial X = k X` (000 §5.3); k > 0.
///
/// Raises:
///     InvalidArgumentError: k <= 0 or not finite.
#[pyfunction]
fn Harmonic(py: Python<'_>, #[pyo3(from_py_with = real)] k: f64) -> PyResult<PyPotential> {
    let inner = Arc::new(CoreHarmonic::new(k).py()?);
    PyPotential::new(py, inner, format!("Harmonic({k})"), "Harmonic", [k])
}

/// Isotropic Saint Venant–Kirchhoff energy
/// :math:`U = \tfrac{\lambda}{2} (\operatorname{tr} E)^2 + \mu \operatorname{tr}(E^2)`,
/// :math:`E = \tfrac12 (X^\top X - I)` (:math:`\lambda` = `lam`, :math:`\mu` = `mu`).
///
/// Raises:
///     InvalidArgumentError: mu <= 0, lam < 0 or not finite.
#[pyfunction]
fn SaintVenantKirchhoff(
    py: Python<'_>,
    #[pyo3(from_py_with = real)] lam: f64,
    #[pyo3(from_py_with = real)] mu: f64,
) -> PyResult<PyPotential> {
    let inner = Arc::new(CoreSvk::new(lam, mu).py()?);
    let desc = format!("SaintVenantKirchhoff({lam}, {mu})");
    PyPotential::new(py, inner, desc, "SaintVenantKirchhoff", [lam, mu])
}

/// Polytropic volumetric (gas) term :math:`U = \kappa (\det(X)^{1-\gamma} - 1)/(\gamma - 1)`,
/// :math:`\gamma > 1`, and :math:`U = -\kappa \ln\det X` for :math:`\gamma = 1`. Defined only for
/// :math:`\det X > 0` (integrations always check it).
///
/// Raises:
///     InvalidArgumentError: kappa <= 0, gamma < 1 or not finite.
#[pyfunction]
#[pyo3(signature = (kappa, gamma=1.4))]
fn Volumetric(
    py: Python<'_>,
    #[pyo3(from_py_with = real)] kappa: f64,
    #[pyo3(from_py_with = real)] gamma: f64,
) -> PyResult<PyPotential> {
    let inner = Arc::new(CoreVolumetric::polytropic(kappa, gamma).py()?);
    let desc = format!("Volumetric({kappa}, {gamma})");
    PyPotential::new(py, inner, desc, "Volumetric", [kappa, gamma])
}

/// Isotropic quadratic stretch energy :math:`U = \tfrac{k}{2} \sum_i (s_i - 1)^2` over the
/// singular values :math:`s_i` of X; k > 0.
/// :math:`\partial U/\partial X = k (X - \operatorname{polar}(X))`
/// (:math:`\operatorname{polar}(X) = X (X^\top X)^{-1/2}`, the rotation of X on
/// :math:`GL^+(n)`). Defined for every X through the SVD, but smooth only where
/// :math:`\det X \ne 0`.
///
/// Raises:
///     InvalidArgumentError: k <= 0 or not finite.
#[pyfunction]
fn Stretch(py: Python<'_>, #[pyo3(from_py_with = real)] k: f64) -> PyResult<PyPotential> {
    let inner = Arc::new(CoreStretch::new(k).py()?);
    PyPotential::new(py, inner, format!("Stretch({k})"), "Stretch", [k])
}

/// Self-gravity of a homogeneous ellipsoid, :math:`U = -4\pi G\rho\, R_F(s_1^2, s_2^2, s_3^2)` over
/// the singular values :math:`s_i` of X (Chandrasekhar, EFE ch. 3; Carlson's :math:`R_F`): the
/// potential of the Riemann ellipsoids, for n = 3 only. The reference configuration is the unit
/// ball of density :math:`\rho` (mass :math:`M = 4\pi\rho/3`) and the kinetic energy
/// :math:`\tfrac12 \operatorname{tr}(V^\top V)`, i.e. the physical energy divided by :math:`M/5`; a
/// sphere of radius a has :math:`U = -4\pi G\rho / a`, and
/// :math:`\partial U/\partial s_i = 2\pi G \rho' s_i A_i` with the actual density
/// :math:`\rho' = \rho / (s_1 s_2 s_3)` and the index symbols :math:`A_i`
/// (`pseudo_rigid.index_symbols`). Defined for :math:`\det X > 0` (integrations always check it);
/// the Hessian is analytic, also at equal singular values (Maclaurin spheroids).
///
/// Raises:
///     InvalidArgumentError: G or rho <= 0 or not finite; a body or X of another dimension than 3.
#[pyfunction]
#[pyo3(signature = (G=1.0, rho=1.0))]
fn SelfGravity(
    py: Python<'_>,
    #[pyo3(from_py_with = real)] G: f64,
    #[pyo3(from_py_with = real)] rho: f64,
) -> PyResult<PyPotential> {
    let inner = Arc::new(CoreSelfGravity::new(G, rho).py()?);
    let desc = format!("SelfGravity(G={G}, rho={rho})");
    PyPotential::new(py, inner, desc, "SelfGravity", [G, rho])
}

/// :math:`U = 0`, the free body (motions :math:`X(t) = X_0 + t P_0`).
#[pyfunction]
pub(crate) fn Zero(py: Python<'_>) -> PyResult<PyPotential> {
    PyPotential::new(py, Arc::new(CoreZero), "Zero()".into(), "Zero", [0.0; 0])
}

/// A potential from Python callables: `value(X) -> float`, `gradient(X) -> (n, n) array` and
/// optionally `hessian(X, V) -> (n, n) array`, the Hessian applied to a direction,
/// d/de gradient(X + e V) at e = 0; all are called with (n, n) float64 arrays. Without `hessian`,
/// `Potential.hessian` uses central differences of `gradient`:
/// :math:`(g(X + hV/\|V\|) - g(X - hV/\|V\|))\, \|V\| / (2h)` (g = `gradient`) with
/// :math:`h = 10^{-6} \max(1, \|X\|)`
/// (Frobenius norms), accurate to about 1e-6 relative for a smooth gradient.
/// This is the slow path (each call takes the GIL); U must be SO(n)×SO(n)-invariant (a function
/// of the singular values of X) for L and Γ to be conserved. Exceptions raised by the callables
/// are re-raised by the integration.
///
/// Raises:
///     TypeError: value, gradient or hessian not callable.
#[pyfunction]
#[pyo3(signature = (value, gradient, hessian=None))]
fn Callable<'py>(
    value: Bound<'py, PyAny>,
    gradient: Bound<'py, PyAny>,
    hessian: Option<Bound<'py, PyAny>>,
) -> PyResult<PyPotential> {
    let mut fns = vec![("value", &value), ("gradient", &gradient)];
    fns.extend(hessian.as_ref().map(|h| ("hessian", h)));
    for (what, f) in fns {
        if !f.is_callable() {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "{what} must be callable"
            )));
        }
    }
    let cb = Arc::new(CallablePotential {
        value: value.clone().unbind(),
        gradient: gradient.clone().unbind(),
        hessian: hessian.as_ref().map(|h| h.clone().unbind()),
    });
    let py = value.py();
    let f = py.import("lieflow.potentials")?.getattr("Callable")?;
    let mut args = vec![value.clone(), gradient.clone()];
    args.extend(hessian);
    let args = PyTuple::new(py, args)?.unbind();
    Ok(PyPotential {
        inner: cb,
        desc: "Callable(...)".into(),
        recipe: Arc::new((f.unbind(), args)),
    })
}

/// Fills the `potentials` submodule.
pub fn register(p: &Bound<'_, PyModule>) -> PyResult<()> {
    p.add_class::<PyPotential>()?;
    p.add_function(wrap_pyfunction!(Harmonic, p)?)?;
    p.add_function(wrap_pyfunction!(SaintVenantKirchhoff, p)?)?;
    p.add_function(wrap_pyfunction!(Volumetric, p)?)?;
    p.add_function(wrap_pyfunction!(Stretch, p)?)?;
    p.add_function(wrap_pyfunction!(SelfGravity, p)?)?;
    p.add_function(wrap_pyfunction!(Zero, p)?)?;
    p.add_function(wrap_pyfunction!(Callable, p)?)?;
    Ok(())
}
