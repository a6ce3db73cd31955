//! `lieflow.ellipsoids`: the self-gravitating fluid ellipsoids (binding of
//! `lieflow::pseudo_rigid::ellipsoids`; EFE ch. 5–7, 001 §8). Conversions only.
#![allow(non_snake_case)]

use lieflow::pseudo_rigid::ellipsoids::{Figure, Fluid};
use pyo3::prelude::*;

use super::equilibria::RelativeEquilibrium;
use crate::convert::real;
use crate::errors::IntoPy;

fn figure(
    G: f64,
    rho: f64,
    make: impl FnOnce(&Fluid) -> lieflow::Result<Figure>,
) -> PyResult<RelativeEquilibrium> {
    let fluid = Fluid::new(G, rho).py()?;
    let fig = make(&fluid).py()?;
    RelativeEquilibrium::ellipsoid(&fluid, fig)
}

/// The Maclaurin spheroid of eccentricity e (:math:`0 \le e < 1`):
/// :math:`a = (1, 1, \sqrt{1 - e^2})` in rigid rotation (EFE ch. 5), a relative equilibrium of
/// `PseudoRigidBody(3, SelfGravity(G, rho), incompressible=True)`.
///
/// Raises:
///     InvalidArgumentError (e outside [0, 1), G or rho not > 0).
#[pyfunction]
#[pyo3(signature = (e, *, G = 1.0, rho = 1.0))]
fn maclaurin(
    #[pyo3(from_py_with = real)] e: f64,
    #[pyo3(from_py_with = real)] G: f64,
    #[pyo3(from_py_with = real)] rho: f64,
) -> PyResult<RelativeEquilibrium> {
    figure(G, rho, |f| f.maclaurin(e))
}

/// The Jacobi ellipsoid with :math:`a_1 = 1`, :math:`a_2` = `a2_over_a1` in (0, 1] (EFE ch. 6 §39:
/// rigid rotation, :math:`a_1^2 a_2^2 A_{12} = a_3^2 A_3`; a2_over_a1 = 1 is the Maclaurin spheroid
/// where they branch off).
///
/// Raises:
///     InvalidArgumentError.
#[pyfunction]
#[pyo3(signature = (a2_over_a1, *, G = 1.0, rho = 1.0))]
fn jacobi(
    #[pyo3(from_py_with = real)] a2_over_a1: f64,
    #[pyo3(from_py_with = real)] G: f64,
    #[pyo3(from_py_with = real)] rho: f64,
) -> PyResult<RelativeEquilibrium> {
    figure(G, rho, |f| f.jacobi(a2_over_a1))
}

/// The Dedekind ellipsoid with :math:`a_1 = 1`, :math:`a_2` = `a2_over_a1` in (0, 1]: the adjoint
/// (:math:`X \mapsto X^\top`) of the
/// Jacobi ellipsoid with the same axes — a stationary figure with internal motion.
///
/// Raises:
///     InvalidArgumentError.
#[pyfunction]
#[pyo3(signature = (a2_over_a1, *, G = 1.0, rho = 1.0))]
fn dedekind(
    #[pyo3(from_py_with = real)] a2_over_a1: f64,
    #[pyo3(from_py_with = real)] G: f64,
    #[pyo3(from_py_with = real)] rho: f64,
) -> PyResult<RelativeEquilibrium> {
    figure(G, rho, |f| f.dedekind(a2_over_a1))
}

/// The Riemann S-type ellipsoid with :math:`a_1 = 1`, :math:`a_2` = `a2_over_a1` in (0, 1] and
/// :math:`f = \zeta/\Omega` (EFE ch. 7; f = 0 Jacobi, :math:`f = \infty` Dedekind, f = -2
/// irrotational).
///
/// Raises:
///     InvalidArgumentError (also when no such ellipsoid exists for :math:`a_3/a_1` in (1e-4,
///     1.5)).
#[pyfunction]
#[pyo3(signature = (a2_over_a1, f, *, G = 1.0, rho = 1.0))]
fn riemann_s(
    #[pyo3(from_py_with = real)] a2_over_a1: f64,
    #[pyo3(from_py_with = real)] f: f64,
    #[pyo3(from_py_with = real)] G: f64,
    #[pyo3(from_py_with = real)] rho: f64,
) -> PyResult<RelativeEquilibrium> {
    figure(G, rho, |fl| fl.riemann_s(a2_over_a1, f))
}

/// The Maclaurin spheroid where the Jacobi ellipsoids branch off (:math:`a_1^4 A_{11} = a_3^2 A_3`;
/// EFE: e = 0.81267, :math:`\Omega^2/(\pi G\rho) = 0.37423`), located by bisection to round-off.
///
/// Raises:
///     InvalidArgumentError.
#[pyfunction]
#[pyo3(signature = (*, G = 1.0, rho = 1.0))]
fn maclaurin_jacobi_bifurcation(
    #[pyo3(from_py_with = real)] G: f64,
    #[pyo3(from_py_with = real)] rho: f64,
) -> PyResult<RelativeEquilibrium> {
    figure(G, rho, |f| f.maclaurin_jacobi_bifurcation())
}

/// Adds the functions to `lieflow.ellipsoids` (index_symbols is re-exported in Python).
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(maclaurin, m)?)?;
    m.add_function(wrap_pyfunction!(jacobi, m)?)?;
    m.add_function(wrap_pyfunction!(dedekind, m)?)?;
    m.add_function(wrap_pyfunction!(riemann_s, m)?)?;
    m.add_function(wrap_pyfunction!(maclaurin_jacobi_bifurcation, m)?)?;
    Ok(())
}
