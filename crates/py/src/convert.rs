//! numpy ⇄ lieflow conversions. Inputs are accepted as any array-like (lists, int arrays) and
//! cast to float64; shapes are checked here and reported as `ShapeError`; finiteness is checked
//! by the core functions.

use lieflow::{Error, Mat};
use nalgebra::{Matrix3, Vector3};
use numpy::ndarray::{Array1, Array2, Array3, ArrayViewD};
use numpy::{AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayLikeDyn};
use pyo3::prelude::*;

use crate::errors::to_py;

/// Any array-like input, cast to float64.
pub type ArrayIn<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// A shape as numpy prints it: "(3,)", "(2, 3)".
pub fn shape_str(shape: &[usize]) -> String {
    let s: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    if s.len() == 1 {
        format!("({},)", s[0])
    } else {
        format!("({})", s.join(", "))
    }
}

fn shape_err(what: &str, expected: &str, v: &ArrayViewD<'_, f64>) -> PyErr {
    to_py(Error::shape(what, expected, shape_str(v.shape())))
}

fn view_to_mat(v: &ArrayViewD<'_, f64>) -> Mat {
    Mat::from_fn(v.shape()[0], v.shape()[1], |i, j| v[[i, j]])
}

/// A 2-D array as a matrix.
pub fn mat(what: &str, a: &ArrayIn<'_>) -> PyResult<Mat> {
    let v = a.as_array();
    if v.ndim() != 2 {
        return Err(shape_err(what, "a 2-D array (n, n)", &v));
    }
    Ok(view_to_mat(&v))
}

/// A 2-D array (one matrix) or a 3-D array (a batch along the leading axis).
/// Returns the matrices and whether the input was batched.
pub fn mats(what: &str, a: &ArrayIn<'_>) -> PyResult<(Vec<Mat>, bool)> {
    let v = a.as_array();
    match v.ndim() {
        2 => Ok((vec![view_to_mat(&v)], false)),
        3 => {
            let (b, r, c) = (v.shape()[0], v.shape()[1], v.shape()[2]);
            Ok((
                (0..b)
                    .map(|k| Mat::from_fn(r, c, |i, j| v[[k, i, j]]))
                    .collect(),
                true,
            ))
        }
        _ => Err(shape_err(what, "(n, n) or a batch (b, n, n)", &v)),
    }
}

/// A 1-D array.
pub fn vector(what: &str, a: &ArrayIn<'_>) -> PyResult<Vec<f64>> {
    let v = a.as_array();
    if v.ndim() != 1 {
        return Err(shape_err(what, "a 1-D array", &v));
    }
    Ok(v.iter().copied().collect())
}

/// A 1-D array (one vector) or a 2-D array (a batch along the leading axis).
pub fn vectors(what: &str, a: &ArrayIn<'_>) -> PyResult<(Vec<Vec<f64>>, bool)> {
    let v = a.as_array();
    match v.ndim() {
        1 => Ok((vec![v.iter().copied().collect()], false)),
        2 => Ok((
            v.outer_iter()
                .map(|r| r.iter().copied().collect())
                .collect(),
            true,
        )),
        _ => Err(shape_err(what, "(d,) or a batch (b, d)", &v)),
    }
}

/// A 3-vector.
pub fn vec3(what: &str, a: &ArrayIn<'_>) -> PyResult<Vector3<f64>> {
    let v = a.as_array();
    if v.shape() != [3] {
        return Err(shape_err(what, "(3,)", &v));
    }
    Ok(Vector3::new(v[[0]], v[[1]], v[[2]]))
}

/// Matrix → 2-D numpy array.
pub fn py_mat<'py>(py: Python<'py>, m: &Mat) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]).into_pyarray(py)
}

/// Matrices of one shape → 3-D numpy array (batch axis first).
pub fn py_mats<'py>(py: Python<'py>, ms: &[Mat]) -> Bound<'py, PyArray3<f64>> {
    let (r, c) = ms.first().map_or((0, 0), |m| (m.nrows(), m.ncols()));
    Array3::from_shape_fn((ms.len(), r, c), |(k, i, j)| ms[k][(i, j)]).into_pyarray(py)
}

/// Slice → 1-D numpy array.
pub fn py_vec<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
    Array1::from(v.to_vec()).into_pyarray(py)
}

/// Equal-length vectors → 2-D numpy array (batch axis first).
pub fn py_vecs<'py>(py: Python<'py>, vs: &[Vec<f64>]) -> Bound<'py, PyArray2<f64>> {
    let d = vs.first().map_or(0, |v| v.len());
    Array2::from_shape_fn((vs.len(), d), |(k, i)| vs[k][i]).into_pyarray(py)
}

/// 3×3 matrix → numpy.
pub fn py_mat3<'py>(py: Python<'py>, m: &Matrix3<f64>) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((3, 3), |(i, j)| m[(i, j)]).into_pyarray(py)
}
