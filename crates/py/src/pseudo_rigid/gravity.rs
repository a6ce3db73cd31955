//! `lieflow.pseudo_rigid.index_symbols`: binding of `lieflow::pseudo_rigid::gravity` (the index
//! symbols of a homogeneous ellipsoid, Chandrasekhar EFE ch. 3). Conversions only.

use lieflow::pseudo_rigid::gravity;
use nalgebra::Matrix3;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::convert::{py_mat3, py_vec, reals};
use crate::errors::IntoPy;

/// (A (3,), A_ij (3, 3)).
type Symbols<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>);

/// Chandrasekhar's index symbols of the ellipsoid with semi-axes a (EFE ch. 3 §21):
/// :math:`A_i = a_1 a_2 a_3 \int_0^\infty du / ((a_i^2 + u) D)` and
/// :math:`A_{ij} = a_1 a_2 a_3 \int_0^\infty du / ((a_i^2 + u)(a_j^2 + u) D)`,
/// :math:`D = \sqrt{\prod_k (a_k^2 + u)}`.
///
/// :math:`A_i` by Carlson's :math:`R_D` (:math:`A_i = \tfrac23 a_1 a_2 a_3 R_D(a_j^2, a_k^2,
/// a_i^2)`), all six :math:`A_{ij}` by the trapezoidal rule in :math:`\ln u`; a few ulp for axis
/// ratios down to 1e-3, near-coincident and equal axes. :math:`\sum_i A_i = 2`; a sphere of radius
/// r has :math:`A_i = 2/3`, :math:`A_{ij} = 2/(5 r^2)`.
///
/// Args:
///     a: the three semi-axes (any order), finite and > 0.
/// Returns:
///     (A, Aij): A of shape (3,), Aij of shape (3, 3) (symmetric, diagonal included).
/// Raises:
///     ShapeError (a not of shape (3,)), NonFiniteError, InvalidArgumentError (:math:`a_i \le 0`,
///     an axis ratio below :math:`2^{-250}`, or :math:`A_{ij}` beyond the float range).
#[pyfunction]
pub fn index_symbols<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = reals::<3>)] a: [f64; 3],
) -> PyResult<Symbols<'py>> {
    let (ai, aij) = gravity::index_symbols(&a).py()?;
    Ok((
        py_vec(py, &ai),
        py_mat3(py, &Matrix3::from_fn(|i, j| aij[i][j])),
    ))
}

/// Adds `index_symbols` to the `pseudo_rigid` submodule.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(index_symbols, m)?)?;
    Ok(())
}
