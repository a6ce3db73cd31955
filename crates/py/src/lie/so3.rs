use numpy::PyArray2;
use pyo3::prelude::*;

use crate::convert::{py_mat3, vec3, ArrayIn};

/// hat(w): the skew matrix with hat(w) x = w × x (physics convention).
#[pyfunction]
fn hat<'py>(py: Python<'py>, w: ArrayIn<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    Ok(py_mat3(py, &lieflow::lie::so3::hat(&vec3("w", &w)?)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(hat, m)?)?;
    Ok(())
}
