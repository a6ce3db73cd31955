//! `Separable`: H = p^T M^{-1} p / 2 + U(q) with U given by Python callables (the binding of
//! `lieflow::systems::user::separable`).
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::systems::user::{GradientFn, ScalarFn};
use lieflow::systems::{KineticMass, UserSeparable};
use lieflow::Error;
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use crate::convert::{int_opt, mat, named, read_all, shape_str, ArrayIn, Real};
use crate::errors::{to_py, IntoPy};
use crate::system::{PySystem, Thin};

use super::{count, missing, optional, Any, Callee};

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

/// A separable system :math:`H = \tfrac12 p^\top M^{-1} p + U(q)` with a constant kinetic mass
/// :math:`M` and :math:`U` given by Python callables.
///
/// State :math:`z = (q, p)` (2d,); fields q, p. :math:`\dot q = M^{-1} p`,
/// :math:`\dot p = -\nabla U(q)`. Methods: verlet
/// (default), verlet4, verlet6 (Störmer–Verlet and its compositions of orders 4 and 6: one call
/// of the gradient per stage), gauss4, gauss6, midpoint, rk4. No invariants.
///
/// Args:
///     mass: M > 0 as a number (:math:`M = m\,\mathrm{Id}`; then `dof` is required), a vector
///         (d,) of positive entries (diagonal M) or a symmetric positive-definite matrix (d, d).
///     potential: callable q -> U(q), q a float64 array (d,).
///     gradient: callable q -> grad U (d,), or None for central differences (see `Canonical`).
///     dof: the number of degrees of freedom (needed for a scalar mass; must agree otherwise).
///     hessian: callable (q, v) -> the Hessian product :math:`D^2 U(q)[v]` (d,), or None. With
///         it (and `gradient`) `lieflow.integrate(..., sensitivity=True)` gives the exact Jacobians of the
///         Verlet methods (`sensitivity_methods()`).
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
    #[pyo3(signature = (mass, potential, gradient=None, dof=None, hessian=None))]
    fn new(
        mass: Any<'_>,
        potential: Any<'_>,
        gradient: Option<Any<'_>>,
        dof: Option<Any<'_>>,
        hessian: Option<Any<'_>>,
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
        let h = optional(hessian.as_ref())
            .map(|h| Callee::new("hessian", h))
            .transpose()?;
        let mut sys = UserSeparable::new(kinetic, d, value, grad_fn).py()?;
        if let Some(h) = h {
            sys = sys.with_hessian(Arc::new(move |q: &[f64], v: &[f64], out: &mut [f64]| {
                h.call(&[q, v], &[q.len()], out)
            }));
        }
        let args = (mass, potential, gradient, dof, hessian).into_pyobject(py)?;
        let names = &["mass", "potential", "gradient", "dof", "hessian"];
        Ok(PySystem::subclass(sys, args, names))
    }

    /// The number d of degrees of freedom.
    #[getter]
    fn dof(slf: &Bound<'_, Self>) -> PyResult<usize> {
        let sys = slf.core::<UserSeparable>()?;
        Ok(lieflow::integrate::problem::Separable::dof(sys))
    }

    /// Whether :math:`\nabla U` is computed by finite differences (no `gradient` was given).
    #[getter]
    fn finite_differences(slf: &Bound<'_, Self>) -> PyResult<bool> {
        Ok(slf.core::<UserSeparable>()?.finite_differences())
    }
}

// ---------------------------------------------------------------------------------------------
