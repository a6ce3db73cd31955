//! `Canonical`, `Separable` and `LiePoisson`: bindings of `lieflow::systems::user` (issue 15),
//! systems whose Hamiltonian is given by Python callables (or, for `LiePoisson`, by a symmetric
//! matrix: the native quadratic path). Thin subclasses of `lieflow.System`.
//!
//! The callables are called from the native kernels on the thread that integrates, which holds
//! the GIL (a run of these systems is single-threaded; a batch of states runs member after
//! member). An exception travels as the core's `Error::Raised` (recorded on the thread when the
//! kernel cannot return it, `lieflow::integrate::hooks`): the kernel goes on with NaN, the core
//! ends the run after that step, never taking a step twice, and the exception is re-raised with
//! a note naming the step ("lieflow: raised in step 17 of gauss4 (t = …, dt = …)"). A value of
//! the wrong shape is a `ShapeError`, a non-finite one a `NonFiniteError`, both naming the
//! callable and the step; a value that is not a real array (a string, None) is the
//! `ArgumentTypeError` of reading it, re-raised like an exception. The systems pickle by their
//! constructor arguments (callables by reference: pass module-level functions).
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::integrate::problem::Canonical;
use lieflow::systems::user::{CanonicalFn, CanonicalGradientFn, GradientFn, ScalarFn};
use lieflow::systems::{
    Algebra, KineticMass, LieHamiltonian, LiePoisson as CoreLiePoisson, UserCanonical,
    UserSeparable,
};
use lieflow::Error;
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray1, PyArray3, PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyList, PyString, PyTuple};
use pyo3::PyClassInitializer;

use crate::convert::{int_opt, mat, named, read_all, shape_str, ArrayIn, Real};
use crate::errors::{argument_type_error, raised, to_py, IntoPy};
use crate::system::{PySystem, Thin};

type Any<'py> = Bound<'py, PyAny>;

/// A user callable as errors name it: its `__qualname__` (or `__name__`, or repr).
pub(crate) fn callable_name(f: &Any<'_>) -> String {
    ["__qualname__", "__name__"]
        .iter()
        .find_map(|a| f.getattr(*a).ok().and_then(|n| n.extract::<String>().ok()))
        .or_else(|| f.repr().ok().map(|r| r.to_string()))
        .unwrap_or_else(|| "?".into())
}

/// A Python callable of a user system: `f(*arrays)` must return an array of a fixed shape.
#[derive(Clone)]
pub(crate) struct Callee {
    f: Arc<Py<PyAny>>,
    /// "the value of the hamiltonian `H`", for errors.
    what: Arc<str>,
}

impl Callee {
    /// The argument `arg` (named `name`, e.g. "hamiltonian") if it is callable; otherwise an
    /// `ArgumentTypeError` naming it.
    pub(crate) fn new(name: &str, arg: &Any<'_>) -> PyResult<Self> {
        if !arg.is_callable() {
            return Err(argument_type_error(
                arg.py(),
                format!(
                    "argument '{name}': expected a callable, got a {}",
                    arg.get_type()
                        .name()
                        .map_or_else(|_| "?".to_string(), |n| n.to_string())
                ),
            ));
        }
        Ok(Callee {
            f: Arc::new(arg.clone().unbind()),
            what: format!("the value of {name} `{}`", callable_name(arg)).into(),
        })
    }

    /// The exception `e` as the core error that carries it.
    fn raised(&self, e: PyErr) -> Error {
        raised(&*self.what, e)
    }

    /// Calls f with one float64 array per slice of `args` and reads its value of `shape` into
    /// `out` (row-major), checked finite.
    fn call(&self, args: &[&[f64]], shape: &[usize], out: &mut [f64]) -> lieflow::Result<()> {
        Python::attach(|py| {
            let called = PyTuple::new(py, args.iter().map(|x| PyArray1::from_slice(py, x)))
                .and_then(|a| self.f.bind(py).call1(a));
            self.read(called, shape, out)
        })
    }

    /// Calls f(t, z) (a float and a float64 array) and reads its value like [`Callee::call`].
    pub(crate) fn call_at(
        &self,
        t: f64,
        z: &[f64],
        shape: &[usize],
        out: &mut [f64],
    ) -> lieflow::Result<()> {
        Python::attach(|py| {
            let called = self.f.bind(py).call1((t, PyArray1::from_slice(py, z)));
            self.read(called, shape, out)
        })
    }

    /// Reads the value of a call of `shape` into `out`, checked finite (or keeps its exception).
    fn read(
        &self,
        called: PyResult<Any<'_>>,
        shape: &[usize],
        out: &mut [f64],
    ) -> lieflow::Result<()> {
        let value = called.map_err(|e| self.raised(e))?;

        // Fast paths: a float, a float64 array; anything else is read like every argument.
        match (shape.is_empty(), value.cast::<PyFloat>()) {
            (true, Ok(f)) => out[0] = f.value(),
            _ => match value.cast::<PyArrayDyn<f64>>().map(|a| a.try_readonly()) {
                Ok(Ok(a)) => self.copy(&a.as_array(), shape, out)?,
                _ => {
                    let a = ArrayIn::named(&self.what, &value).map_err(|e| self.raised(e))?;
                    self.copy(&a.as_array(), shape, out)?
                }
            },
        }
        match out.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(i) => Err(Error::NonFinite {
                what: self.what.to_string(),
                location: if shape.is_empty() {
                    format!("its value ({})", out[i])
                } else {
                    let mut idx = Vec::new();
                    let mut r = i;
                    for s in shape.iter().rev() {
                        idx.push(r % s);
                        r /= s;
                    }
                    idx.reverse();
                    let idx: Vec<String> = idx.iter().map(|k| k.to_string()).collect();
                    format!("entry [{}] = {}", idx.join(", "), out[i])
                },
            }),
        }
    }

    /// `v` into `out` if it has `shape`, else a ShapeError.
    fn copy(
        &self,
        v: &numpy::ndarray::ArrayViewD<'_, f64>,
        shape: &[usize],
        out: &mut [f64],
    ) -> lieflow::Result<()> {
        if v.shape() != shape {
            return Err(Error::shape(
                &*self.what,
                shape_str(shape),
                shape_str(v.shape()),
            ));
        }
        for (o, x) in out.iter_mut().zip(v.iter()) {
            *o = *x;
        }
        Ok(())
    }

    fn scalar(&self, args: &[&[f64]]) -> lieflow::Result<f64> {
        let mut out = [0.0];
        self.call(args, &[], &mut out)?;
        Ok(out[0])
    }
}

fn optional<'a, 'py>(a: Option<&'a Any<'py>>) -> Option<&'a Any<'py>> {
    a.filter(|x| !x.is_none())
}

/// A missing required argument: a TypeError naming it, as Python's own.
fn missing(py: Python<'_>, class: &str, name: &str, what: &str) -> PyErr {
    argument_type_error(
        py,
        format!("{class}() missing the argument '{name}' ({what})"),
    )
}

/// A count argument (`dof`) as usize; negative is an `InvalidArgumentError`.
fn count(name: &str, v: i64) -> PyResult<usize> {
    usize::try_from(v).map_err(|_| {
        to_py(Error::invalid(
            name,
            format!("expected an int ≥ 1, got {v}"),
        ))
    })
}

// ---------------------------------------------------------------------------------------------

/// A canonical Hamiltonian system H(q, p) on T*R^d given by Python callables.
///
/// State z = (q, p) (2d,); fields q, p. q' = dH/dp, p' = -dH/dq. Methods: gauss4 (default),
/// gauss6, midpoint (symplectic Gauss–Legendre, orders 4, 6, 2), rk4. No invariants.
///
/// Args:
///     hamiltonian: callable (q, p) -> float, q and p float64 arrays (d,).
///     gradient: callable (q, p) -> (dH/dq, dH/dp), anything numpy reads as shape (2, d); or
///         None for central differences of H with one Richardson extrapolation (4 calls of H per
///         coordinate, 8d per gradient; relative accuracy about 1e-12 for smooth H varying on
///         the scale of the state; the methods are then symplectic only to that accuracy).
///     dof: the number d >= 1 of degrees of freedom (required).
/// Raises:
///     ArgumentTypeError (not callable, no dof), InvalidArgumentError (dof < 1).
///
/// The callables run in the integrating thread with the GIL (runs of this system are single-
/// threaded; a batch of states runs member after member). An exception they raise is re-raised
/// with a note naming the step; a value of the wrong shape is a ShapeError, NaN or inf a
/// NonFiniteError, both naming the callable and the step.
#[pyclass(name = "Canonical", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyCanonical;

#[pymethods]
impl PyCanonical {
    #[new]
    #[pyo3(signature = (hamiltonian, gradient=None, dof=None))]
    fn new(
        hamiltonian: Any<'_>,
        gradient: Option<Any<'_>>,
        dof: Option<Any<'_>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let py = hamiltonian.py();
        let h = Callee::new("hamiltonian", &hamiltonian)?;
        let g = optional(gradient.as_ref())
            .map(|g| Callee::new("gradient", g))
            .transpose()?;
        let d = match optional(dof.as_ref()) {
            Some(v) => count("dof", named("dof", int_opt(v))?.unwrap_or(0))?,
            None => {
                return Err(missing(
                    py,
                    "Canonical",
                    "dof",
                    "the number of degrees of freedom",
                ))
            }
        };
        let value: CanonicalFn = Arc::new(move |q: &[f64], p: &[f64]| h.scalar(&[q, p]));
        let grad_fn: Option<CanonicalGradientFn> = g.map(|g| {
            Arc::new(
                move |q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]| {
                    let d = q.len();
                    let mut out = vec![0.0; 2 * d];
                    g.call(&[q, p], &[2, d], &mut out)?;
                    hq.copy_from_slice(&out[..d]);
                    hp.copy_from_slice(&out[d..]);
                    Ok(())
                },
            ) as CanonicalGradientFn
        });
        let sys = UserCanonical::new(d, value, grad_fn).py()?;
        let args = (hamiltonian, gradient, dof).into_pyobject(py)?;
        Ok(PySystem::subclass(
            sys,
            args,
            &["hamiltonian", "gradient", "dof"],
        ))
    }

    /// The number d of degrees of freedom.
    #[getter]
    fn dof(slf: &Bound<'_, Self>) -> PyResult<usize> {
        Ok(Canonical::dof(slf.core::<UserCanonical>()?))
    }

    /// Whether the gradient is computed by finite differences (no `gradient` was given).
    #[getter]
    fn finite_differences(slf: &Bound<'_, Self>) -> PyResult<bool> {
        Ok(slf.core::<UserCanonical>()?.finite_differences())
    }
}

// ---------------------------------------------------------------------------------------------

/// The mass argument: a number, a vector (diagonal) or a matrix.
fn kinetic_mass(m: &Any<'_>) -> PyResult<KineticMass> {
    if let Ok(Real(x)) = m.extract::<Real>() {
        return Ok(KineticMass::Scalar(x));
    }
    let a = ArrayIn::named("mass", m)?;
    let v = a.as_array();
    match v.ndim() {
        1 => Ok(KineticMass::Diagonal(read_all("mass", &v)?)),
        2 => Ok(KineticMass::Matrix(mat("mass", &a)?)),
        _ => Err(to_py(Error::shape(
            "mass",
            "a number, a vector (d,) (diagonal) or a matrix (d, d)",
            shape_str(v.shape()),
        ))),
    }
}

/// A separable system H = p^T M^{-1} p / 2 + U(q) with a constant kinetic mass M and U given by
/// Python callables.
///
/// State z = (q, p) (2d,); fields q, p. q' = M^{-1} p, p' = -grad U(q). Methods: verlet
/// (default), verlet4, verlet6 (Störmer–Verlet and its compositions of orders 4 and 6: one call
/// of the gradient per stage), gauss4, gauss6, midpoint, rk4. No invariants.
///
/// Args:
///     mass: M > 0 as a number (M = m I; then `dof` is required), a vector (d,) of
///         positive entries (diagonal M) or a symmetric positive-definite matrix (d, d).
///     potential: callable q -> U(q), q a float64 array (d,).
///     gradient: callable q -> grad U (d,), or None for central differences (see `Canonical`).
///     dof: the number of degrees of freedom (needed for a scalar mass; must agree otherwise).
/// Raises:
///     ArgumentTypeError, InvalidArgumentError (a mass that is not positive definite),
///     ShapeError (a mass of the wrong shape, a dof that disagrees).
///
/// The callables are called as those of `Canonical` (exceptions re-raised naming the step, also
/// at the initial state: Verlet evaluates the force when it starts).
#[pyclass(name = "Separable", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PySeparable;

#[pymethods]
impl PySeparable {
    #[new]
    #[pyo3(signature = (mass, potential, gradient=None, dof=None))]
    fn new(
        mass: Any<'_>,
        potential: Any<'_>,
        gradient: Option<Any<'_>>,
        dof: Option<Any<'_>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let py = potential.py();
        let kinetic = self::kinetic_mass(&mass)?;
        let u = Callee::new("potential", &potential)?;
        let g = optional(gradient.as_ref())
            .map(|g| Callee::new("gradient", g))
            .transpose()?;
        let d = match optional(dof.as_ref()) {
            Some(v) => Some(count("dof", named("dof", int_opt(v))?.unwrap_or(0))?),
            None => None,
        };
        if matches!(kinetic, KineticMass::Scalar(_)) && d.is_none() {
            return Err(missing(
                py,
                "Separable",
                "dof",
                "the number of degrees of freedom, needed with a scalar mass",
            ));
        }
        let value: ScalarFn = Arc::new(move |q: &[f64]| u.scalar(&[q]));
        let grad_fn: Option<GradientFn> = g.map(|g| {
            Arc::new(move |q: &[f64], out: &mut [f64]| g.call(&[q], &[q.len()], out)) as GradientFn
        });
        let sys = UserSeparable::new(kinetic, d, value, grad_fn).py()?;
        let args = (mass, potential, gradient, dof).into_pyobject(py)?;
        let names = &["mass", "potential", "gradient", "dof"];
        Ok(PySystem::subclass(sys, args, names))
    }

    /// The number d of degrees of freedom.
    #[getter]
    fn dof(slf: &Bound<'_, Self>) -> PyResult<usize> {
        let sys = slf.core::<UserSeparable>()?;
        Ok(lieflow::integrate::problem::Separable::dof(sys))
    }

    /// Whether grad U is computed by finite differences (no `gradient` was given).
    #[getter]
    fn finite_differences(slf: &Bound<'_, Self>) -> PyResult<bool> {
        Ok(slf.core::<UserSeparable>()?.finite_differences())
    }
}

// ---------------------------------------------------------------------------------------------

/// The `algebra` argument: "so3", "se3", ("so", n) or structure constants (d, d, d).
fn algebra(a: &Any<'_>) -> PyResult<Algebra> {
    let names = "\"so3\", \"se3\", (\"so\", n) or structure constants (d, d, d)";
    if let Ok(s) = a.cast::<PyString>() {
        return match s.extract::<String>()?.as_str() {
            "so3" => Ok(Algebra::So3),
            "se3" => Ok(Algebra::Se3),
            other => Err(to_py(Error::invalid(
                "algebra",
                format!("unknown algebra {other:?}; expected {names}"),
            ))),
        };
    }
    let pair = a.is_instance_of::<PyTuple>() || a.is_instance_of::<PyList>();
    if pair && a.len()? == 2 && a.get_item(0)?.is_instance_of::<PyString>() {
        let name: String = a.get_item(0)?.extract()?;
        if name != "so" {
            return Err(to_py(Error::invalid(
                "algebra",
                format!("unknown algebra ({name:?}, n); expected {names}"),
            )));
        }
        let n = named("algebra", int_opt(&a.get_item(1)?))?.unwrap_or(0);
        let n = usize::try_from(n).map_err(|_| {
            to_py(Error::invalid(
                "algebra",
                format!("so(n) needs n ≥ 2, got n = {n}"),
            ))
        })?;
        return Ok(Algebra::So(n));
    }
    let c = ArrayIn::named("algebra", a)?;
    let v = c.as_array();
    let s = v.shape();
    if s.len() != 3 || s[0] != s[1] || s[1] != s[2] || s[0] == 0 {
        return Err(to_py(Error::shape("algebra", names, shape_str(s))));
    }
    Ok(Algebra::Constants(read_all("algebra", &v)?))
}

/// A Lie–Poisson system on g*: d mu/dt = ad*_{dH/dmu} mu.
///
/// With [e_i, e_j] = C_ij^k e_k and mu the coordinates dual to e_k (the pairing is the dot
/// product), (ad*_xi mu)_j = sum_{i,k} C_ij^k xi_i mu_k; on so(3) this is dM/dt = M x Omega for
/// H = M . I^{-1} M / 2 (the rigid body's sign). State mu (d,); fields: M (so3), M and Gamma
/// (se3: dM/dt = M x Omega + Gamma x V, dGamma/dt = Gamma x Omega with (Omega, V) = dH/dmu,
/// Kirchhoff's equations with Gamma the impulse), M (so(n)*, e_ij coordinates as
/// `GeneralizedRigidBody`; fields show the skew matrix), mu (structure constants).
/// Casimirs (`invariants`): ‖M‖^2 (so3); ‖Gamma‖^2, M . Gamma (se3); tr((M^T M)^k)/2,
/// k = 1..n//2 (so(n)); none for structure constants; or the `casimirs` given.
/// Methods: rkmk4 (default; Runge–Kutta–Munthe-Kaas, order 4, explicit), midpoint (the Lie
/// midpoint, symmetric, order 2), midpoint4 (its Suzuki composition, order 4), rk4 (baseline,
/// keeps no Casimir). All but rk4 advance by the coadjoint action, so every Casimir is kept to
/// round-off.
///
/// Args:
///     algebra: "so3", "se3", ("so", n) with n >= 2, or structure constants C (d, d, d),
///         C[i, j, k] = C_ij^k (antisymmetric in i, j and satisfying Jacobi: checked).
///     hamiltonian: a callable mu -> float (mu a float64 array (d,)), or a symmetric (d, d)
///         matrix A for H = mu . A mu / 2 (the native path: no Python call per step, runs in
///         parallel).
///     gradient: a callable mu -> dH/dmu (d,), or None (central differences of H, see
///         `Canonical`); must be None for a matrix hamiltonian.
///     casimirs: None (the algebra's), or a sequence of callables mu -> float to monitor as
///         `invariants` in their place.
/// Raises:
///     ArgumentTypeError, InvalidArgumentError, ShapeError, NonFiniteError.
#[pyclass(name = "LiePoisson", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyLiePoisson;

#[pymethods]
impl PyLiePoisson {
    #[new]
    #[pyo3(signature = (algebra, hamiltonian, gradient=None, casimirs=None))]
    fn new(
        algebra: Any<'_>,
        hamiltonian: Any<'_>,
        gradient: Option<Any<'_>>,
        casimirs: Option<Any<'_>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let py = hamiltonian.py();
        let alg = self::algebra(&algebra)?;
        let ham = if hamiltonian.is_callable() {
            let h = Callee::new("hamiltonian", &hamiltonian)?;
            let g = optional(gradient.as_ref())
                .map(|g| Callee::new("gradient", g))
                .transpose()?;
            LieHamiltonian::Function {
                value: Arc::new(move |mu: &[f64]| h.scalar(&[mu])),
                gradient: g.map(|g| {
                    Arc::new(move |mu: &[f64], out: &mut [f64]| g.call(&[mu], &[mu.len()], out))
                        as GradientFn
                }),
            }
        } else {
            if optional(gradient.as_ref()).is_some() {
                return Err(to_py(Error::invalid(
                    "gradient",
                    "a quadratic Hamiltonian (a matrix) has its gradient A mu; pass gradient=None",
                )));
            }
            let a = ArrayIn::named("hamiltonian", &hamiltonian).map_err(|e| {
                if e.is_instance_of::<pyo3::exceptions::PyTypeError>(py) {
                    argument_type_error(
                        py,
                        format!(
                            "argument 'hamiltonian': expected a callable or a symmetric (d, d) \
                             matrix, got a {}",
                            hamiltonian
                                .get_type()
                                .name()
                                .map_or_else(|_| "?".to_string(), |n| n.to_string())
                        ),
                    )
                } else {
                    e
                }
            })?;
            if a.as_array().ndim() != 2 {
                return Err(to_py(Error::shape(
                    "hamiltonian",
                    "a callable or a symmetric (d, d) matrix",
                    shape_str(a.as_array().shape()),
                )));
            }
            LieHamiltonian::Quadratic(read_all("hamiltonian", &a.as_array())?)
        };
        let cas = match optional(casimirs.as_ref()) {
            None => None,
            Some(c) => {
                let mut fs: Vec<ScalarFn> = Vec::new();
                let items = c.try_iter().map_err(|_| {
                    argument_type_error(
                        py,
                        "argument 'casimirs': expected None or a sequence of callables".into(),
                    )
                })?;
                for (k, f) in items.enumerate() {
                    let f = Callee::new(&format!("casimirs[{k}]"), &f?)?;
                    fs.push(Arc::new(move |mu: &[f64]| f.scalar(&[mu])));
                }
                Some(fs)
            }
        };
        let sys = CoreLiePoisson::new(alg, ham, cas).py()?;
        let args = (algebra, hamiltonian, gradient, casimirs).into_pyobject(py)?;
        let names = &["algebra", "hamiltonian", "gradient", "casimirs"];
        Ok(PySystem::subclass(sys, args, names))
    }

    /// dim g (the length d of a state).
    #[getter]
    fn dim(slf: &Bound<'_, Self>) -> PyResult<usize> {
        Ok(slf.core::<CoreLiePoisson>()?.dim())
    }

    /// Whether H is the native quadratic form (given as a matrix).
    #[getter]
    fn is_quadratic(slf: &Bound<'_, Self>) -> PyResult<bool> {
        Ok(slf.core::<CoreLiePoisson>()?.is_quadratic())
    }

    /// The structure constants C (d, d, d), C[i, j, k] = C_ij^k, [e_i, e_j] = C_ij^k e_k.
    ///
    /// Raises:
    ///     InvalidArgumentError (an array too large to hold: so(n) for n of some hundreds).
    fn structure_constants<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let sys = slf.core::<CoreLiePoisson>()?;
        let (d, c) = (sys.dim(), sys.structure_constants().py()?);
        let a = Array3::from_shape_vec((d, d, d), c).map_err(|e| {
            to_py(Error::shape(
                "structure_constants",
                "(d, d, d)",
                e.to_string(),
            ))
        })?;
        Ok(a.into_pyarray(slf.py()))
    }
}
