//! `lieflow.lie`: GL+(n) — SVD coordinates, polar decomposition, strata (bindings of
//! `lieflow::lie::gl`).
#![allow(non_snake_case)]

use lieflow::lie::gl;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::real;
use crate::convert::{mat, py_mat, py_vec, vector, ArrayIn};
use crate::errors::IntoPy;

type Arr2<'py> = Bound<'py, PyArray2<f64>>;

/// SVD coordinates of :math:`X \in GL^+(n)` (001 (2.4)):
/// :math:`X = R \operatorname{diag}(a) S^\top` with :math:`R, S \in SO(n)` and
/// :math:`a_0 \ge \dots \ge a_{n-1} > 0` (sign fix: the last columns of U and V are flipped
/// together when :math:`\det U < 0`).
///
/// Args:
///     X: (n, n) array with :math:`\det X > 0`.
/// Returns:
///     (R, a, S): (n, n), (n,), (n, n) arrays.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0`, the determinant is in
///     the message).
#[pyfunction]
pub fn svd_coordinates<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
) -> PyResult<(Arr2<'py>, Bound<'py, PyArray1<f64>>, Arr2<'py>)> {
    let c = gl::svd_coordinates(&mat("X", &X)?).py()?;
    Ok((py_mat(py, &c.r), py_vec(py, &c.a), py_mat(py, &c.s)))
}

/// :math:`X = R \operatorname{diag}(a) S^\top` from SVD coordinates (001 (2.6)), the inverse of
/// `svd_coordinates`.
///
/// Args:
///     R, S: (n, n) rotations; a: (n,) positive singular values (any order).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (R or S not in SO(n)),
///     InvalidArgumentError (some :math:`a_i \le 0`).
#[pyfunction]
pub fn from_svd<'py>(
    py: Python<'py>,
    R: ArrayIn<'py>,
    a: ArrayIn<'py>,
    S: ArrayIn<'py>,
) -> PyResult<Arr2<'py>> {
    let x = gl::from_svd(&mat("R", &R)?, &vector("a", &a)?, &mat("S", &S)?).py()?;
    Ok(py_mat(py, &x))
}

/// Polar decomposition :math:`X = R P` of :math:`X \in GL^+(n)`: :math:`R \in SO(n)` (the nearest
/// rotation) and :math:`P = (X^\top X)^{1/2}` symmetric positive definite.
///
/// Returns:
///     (R, P): two (n, n) arrays.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0`).
#[pyfunction]
pub fn polar<'py>(py: Python<'py>, X: ArrayIn<'py>) -> PyResult<(Arr2<'py>, Arr2<'py>)> {
    let (r, p) = gl::polar(&mat("X", &X)?).py()?;
    Ok((py_mat(py, &r), py_mat(py, &p)))
}

/// Stratum of :math:`X \in GL^+(n)` under the two-sided :math:`SO(n) \times SO(n)` action
/// (001 §6.1, (9.2)): which singular values coincide,
/// :math:`a_i - a_{i+1} \le \mathrm{tol} \cdot a_1`.
///
/// Args:
///     X: (n, n) array with :math:`\det X > 0`.
///     tol: relative tolerance (default 1e-8, the one used by every principal-stratum check).
/// Returns:
///     dict with "singular_values" (n,), "multiplicities" (list of block sizes from the
///     largest value down), "min_gap", "tol" (absolute) and "principal" (bool).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError, InvalidArgumentError (tol < 0).
#[pyfunction]
#[pyo3(signature = (X, tol = gl::STRATUM_TOL), text_signature = "(X, tol=1e-8)")]
pub fn stratum<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    #[pyo3(from_py_with = real)] tol: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let st = gl::stratum(&mat("X", &X)?, tol).py()?;
    stratum_dict(py, &st)
}
// The text_signature above spells the default out for help() and the stubs.
const _: () = assert!(gl::STRATUM_TOL == 1e-8);

/// The dict returned by `stratum`.
fn stratum_dict<'py>(py: Python<'py>, st: &gl::Stratum) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("singular_values", py_vec(py, &st.a))?;
    d.set_item("multiplicities", st.multiplicities.clone())?;
    d.set_item("min_gap", st.min_gap)?;
    d.set_item("tol", st.tol)?;
    d.set_item("principal", st.is_principal())?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(svd_coordinates, m)?)?;
    m.add_function(wrap_pyfunction!(from_svd, m)?)?;
    m.add_function(wrap_pyfunction!(polar, m)?)?;
    m.add_function(wrap_pyfunction!(stratum, m)?)?;
    Ok(())
}
