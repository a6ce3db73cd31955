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
/// A_i = a1 a2 a3 int_0^inf du / ((a_i^2 + u) D) and
/// A_ij = a1 a2 a3 int_0^inf du / ((a_i^2 + u)(a_j^2 + u) D), D = sqrt(prod_k (a_k^2 + u)).
///
/// A_i by Carlson's R_D (A_i = 2/3 a1 a2 a3 R_D(a_j^2, a_k^2, a_i^2)), all six A_ij by the
/// trapezoidal rule in ln u; a few ulp for axis ratios down to 1e-3, near-coincident and equal
/// axes. sum(A) = 2; a sphere of radius r has A_i = 2/3, A_ij = 2/(5 r^2).
///
/// Args:
///     a: the three semi-axes (any order), finite and > 0.
/// Returns:
///     (A, Aij): A of shape (3,), Aij of shape (3, 3) (symmetric, diagonal included).
/// Raises:
///     ShapeError (a not of shape (3,)), NonFiniteError, InvalidArgumentError (a_i <= 0, an
///     axis ratio below 2**-250, or A_ij beyond the float range).
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
