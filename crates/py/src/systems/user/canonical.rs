//! `Canonical`: a canonical Hamiltonian system given by Python callables (the binding of
//! `lieflow::systems::user::canonical`).
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::integrate::problem::Canonical;
use lieflow::systems::user::{CanonicalFn, CanonicalGradientFn};
use lieflow::systems::UserCanonical;
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use crate::convert::{int_opt, named};
use crate::errors::IntoPy;
use crate::system::{PySystem, Thin};

use super::{count, missing, optional, Any, Callee};

/// Calls `c` on `args` for a (2, d) value: its rows into `hq` and `hp`.
fn call_pair(c: &Callee, args: &[&[f64]], hq: &mut [f64], hp: &mut [f64]) -> lieflow::Result<()> {
    let d = hq.len();
    let mut out = vec![0.0; 2 * d];
    c.call(args, &[2, d], &mut out)?;
    hq.copy_from_slice(&out[..d]);
    hp.copy_from_slice(&out[d..]);
    Ok(())
}

/// A canonical Hamiltonian system :math:`H(q, p)` on :math:`T^*\mathbb{R}^d` given by Python
/// callables.
///
/// State :math:`z = (q, p)` (2d,); fields q, p. :math:`\dot q = \partial H/\partial p`,
/// :math:`\dot p = -\partial H/\partial q`. Methods: gauss4 (default),
/// gauss6, midpoint (symplectic Gauss–Legendre, orders 4, 6, 2), rk4. No invariants.
///
/// Args:
///     hamiltonian: callable (q, p) -> float, q and p float64 arrays (d,).
///     gradient: callable (q, p) -> (dH/dq, dH/dp), anything numpy reads as shape (2, d); or
///         None for central differences of H with one Richardson extrapolation (4 calls of H per
///         coordinate, 8d per gradient; relative accuracy about 1e-12 for smooth H varying on
///         the scale of the state; the methods are then symplectic only to that accuracy).
///     dof: the number d >= 1 of degrees of freedom (required).
///     hessian: callable (q, p, dq, dp) -> the derivative of the gradient along (dq, dp),
///         (d(dH/dq), d(dH/dp)) of shape (2, d), or None. With it (and `gradient`)
///         `lieflow.integrate(..., sensitivity=True)` gives every method's exact Jacobians.
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
    #[pyo3(signature = (hamiltonian, gradient=None, dof=None, hessian=None))]
    fn new(
        hamiltonian: Any<'_>,
        gradient: Option<Any<'_>>,
        dof: Option<Any<'_>>,
        hessian: Option<Any<'_>>,
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
                    call_pair(&g, &[q, p], hq, hp)
                },
            ) as CanonicalGradientFn
        });
        let hess = optional(hessian.as_ref())
            .map(|h| Callee::new("hessian", h))
            .transpose()?;
        let mut sys = UserCanonical::new(d, value, grad_fn).py()?;
        if let Some(h) = hess {
            sys = sys.with_hessian(Arc::new(
                move |q: &[f64],
                      p: &[f64],
                      dq: &[f64],
                      dp: &[f64],
                      hq: &mut [f64],
                      hp: &mut [f64]| { call_pair(&h, &[q, p, dq, dp], hq, hp) },
            ));
        }
        let args = (hamiltonian, gradient, dof, hessian).into_pyobject(py)?;
        Ok(PySystem::subclass(
            sys,
            args,
            &["hamiltonian", "gradient", "dof", "hessian"],
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
