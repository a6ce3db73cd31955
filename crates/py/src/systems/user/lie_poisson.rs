//! `LiePoisson`: a Lie–Poisson system on g* with a Hamiltonian given by a Python callable or a
//! symmetric matrix (the binding of `lieflow::systems::user::lie_poisson`).
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::systems::user::{GradientFn, ScalarFn};
use lieflow::systems::{Algebra, LieHamiltonian, LiePoisson as CoreLiePoisson, Side};
use lieflow::Error;
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3};
use pyo3::prelude::*;
use pyo3::types::{PyList, PyString, PyTuple};
use pyo3::PyClassInitializer;

use crate::convert::{int_opt, named, read_all, shape_str, ArrayIn};
use crate::errors::{argument_type_error, to_py, IntoPy};
use crate::system::{PySystem, Thin};

use super::{optional, Any, Callee};

/// The `algebra` argument: "so3", "se3", ("so", n) or structure constants (d, d, d).
pub(super) fn algebra(a: &Any<'_>) -> PyResult<Algebra> {
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

/// The `side` argument: None or "left" (left-invariant), "right".
pub(super) fn side(s: Option<&Any<'_>>) -> PyResult<Side> {
    let Some(s) = optional(s) else {
        return Ok(Side::Left);
    };
    let name = s.cast::<PyString>().map_err(|_| {
        argument_type_error(
            s.py(),
            "argument 'side': expected \"left\" or \"right\"".into(),
        )
    })?;
    match name.extract::<String>()?.as_str() {
        "left" => Ok(Side::Left),
        "right" => Ok(Side::Right),
        other => Err(to_py(Error::invalid(
            "side",
            format!("expected \"left\" or \"right\", got {other:?}"),
        ))),
    }
}

/// A Lie–Poisson system on :math:`\mathfrak{g}^*`:
/// :math:`\dot\mu = \operatorname{ad}^*_{\partial H/\partial\mu} \mu` (left-invariant), or
/// :math:`\dot\mu = -\operatorname{ad}^*_{\partial H/\partial\mu} \mu` (`side="right"`).
///
/// With :math:`[e_i, e_j] = C_{ij}^k e_k` and :math:`\mu` the coordinates dual to :math:`e_k`
/// (the pairing is the dot product),
/// :math:`(\operatorname{ad}^*_\xi \mu)_j = \sum_{i,k} C_{ij}^k \xi_i \mu_k`; on so(3) this is
/// :math:`\dot M = M \times \Omega` for :math:`H = \tfrac12 M \cdot \mathbb{I}^{-1} M` (the rigid
/// body's sign). State mu (d,); fields: M (so3), M and Gamma (se3:
/// :math:`\dot M = M \times \Omega + \Gamma \times V`, :math:`\dot\Gamma = \Gamma \times \Omega`
/// with :math:`(\Omega, V) = \partial H/\partial\mu`, Kirchhoff's equations with :math:`\Gamma`
/// the impulse), M (so(n)*, :math:`e_{ij}` coordinates as `GeneralizedRigidBody`; fields show
/// the skew matrix), mu (structure constants). Casimirs (`invariants`): :math:`\|M\|^2` (so3);
/// :math:`\|\Gamma\|^2`, :math:`M \cdot \Gamma` (se3);
/// :math:`\tfrac12 \operatorname{tr}((M^\top M)^k)`, :math:`k = 1, \dots, \lfloor n/2 \rfloor`
/// (so(n)); none for structure constants; or the `casimirs` given.
/// `side` is the invariance the system is reduced from (000 §4.1, Theorems 4.3-4.4): "left"
/// (body frame, as above) or "right" (spatial frame: the sign of the bracket flips; a right
/// run from :math:`\mu_0` is the negated left run of :math:`H(-\mu)` from :math:`-\mu_0`, the
/// mirror :math:`g \mapsto g^{-1}`).
/// Methods: rkmk4 (default; Runge–Kutta–Munthe-Kaas, order 4, explicit), midpoint (the Lie
/// midpoint, symmetric, order 2), midpoint4 (its Suzuki composition, order 4), rk4 (baseline,
/// keeps no Casimir). All but rk4 advance by the coadjoint action, so every Casimir is kept to
/// round-off.
///
/// Args:
///     algebra: "so3", "se3", ("so", n) with n >= 2, or structure constants C (d, d, d),
///         C[i, j, k] = :math:`C_{ij}^k` (antisymmetric in i, j and satisfying Jacobi: checked).
///     hamiltonian: a callable mu -> float (mu a float64 array (d,)), or a symmetric (d, d)
///         matrix A for :math:`H = \tfrac12 \mu \cdot A\mu` (the native path: no Python call per
///         step, runs in parallel).
///     gradient: a callable mu -> dH/dmu (d,), or None (central differences of H, see
///         `Canonical`); must be None for a matrix hamiltonian.
///     casimirs: None (the algebra's), or a sequence of callables mu -> float to monitor as
///         `invariants` in their place.
///     side: "left" (default) or "right".
///     hessian: a callable (mu, dmu) -> :math:`D^2 H(\mu)[d\mu]` (d,), the derivative of
///         `gradient` along dmu, or None. With `gradient` it gives the runs with ``sensitivity=True`` (every
///         method: the exact Jacobian of the discrete flow); a matrix hamiltonian needs none.
/// Raises:
///     ArgumentTypeError, InvalidArgumentError, ShapeError, NonFiniteError.
#[pyclass(name = "LiePoisson", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyLiePoisson;

#[pymethods]
impl PyLiePoisson {
    #[new]
    #[pyo3(signature = (algebra, hamiltonian, gradient=None, casimirs=None, side=None, hessian=None))]
    fn new(
        algebra: Any<'_>,
        hamiltonian: Any<'_>,
        gradient: Option<Any<'_>>,
        casimirs: Option<Any<'_>>,
        side: Option<Any<'_>>,
        hessian: Option<Any<'_>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let py = hamiltonian.py();
        let alg = self::algebra(&algebra)?;
        let side_of = self::side(side.as_ref())?;
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
            for (name, v) in [("gradient", &gradient), ("hessian", &hessian)] {
                if optional(v.as_ref()).is_some() {
                    return Err(to_py(Error::invalid(
                        name,
                        format!(
                            "a quadratic Hamiltonian (a matrix) has its derivatives A mu, A dmu; \
                             pass {name}=None"
                        ),
                    )));
                }
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
        let mut sys = CoreLiePoisson::new(alg, ham, cas).py()?.with_side(side_of);
        if let Some(h) = optional(hessian.as_ref())
            .map(|h| Callee::new("hessian", h))
            .transpose()?
        {
            sys = sys.with_hessian(Arc::new(move |mu: &[f64], dmu: &[f64], out: &mut [f64]| {
                h.call(&[mu, dmu], &[mu.len()], out)
            }));
        }
        let side = side_of.name();
        let args = (algebra, hamiltonian, gradient, casimirs, side, hessian).into_pyobject(py)?;
        let names = &[
            "algebra",
            "hamiltonian",
            "gradient",
            "casimirs",
            "side",
            "hessian",
        ];
        Ok(PySystem::subclass(sys, args, names))
    }

    /// The invariance the system is reduced from: "left" or "right".
    #[getter]
    fn side(slf: &Bound<'_, Self>) -> PyResult<&'static str> {
        Ok(slf.core::<CoreLiePoisson>()?.side().name())
    }

    /// :math:`\dim\mathfrak{g}` (the length d of a state).
    #[getter]
    fn dim(slf: &Bound<'_, Self>) -> PyResult<usize> {
        Ok(slf.core::<CoreLiePoisson>()?.dim())
    }

    /// Whether H is the native quadratic form (given as a matrix).
    #[getter]
    fn is_quadratic(slf: &Bound<'_, Self>) -> PyResult<bool> {
        Ok(slf.core::<CoreLiePoisson>()?.is_quadratic())
    }

    /// The structure constants C (d, d, d), C[i, j, k] = :math:`C_{ij}^k`,
    /// :math:`[e_i, e_j] = C_{ij}^k e_k`.
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
