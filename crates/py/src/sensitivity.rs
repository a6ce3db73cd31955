//! The layout of a tangent lift (`lieflow::integrate::tangent`), for
//! `lieflow.integrate(..., sensitivity=True)`: seeds and Jacobians between the lifted states and
//! the system's own.

use std::sync::Arc;

use lieflow::integrate::tangent::TangentSystem;
use lieflow::Error;
use numpy::{IntoPyArray, PyArrayDyn};
use pyo3::prelude::*;

use crate::convert::{read_all, ArrayIn};
use crate::errors::{to_py, IntoPy};

type Array<'py> = Bound<'py, PyArrayDyn<f64>>;

/// The layout of a system's tangent lift (internal to `lieflow.integrate`).
#[pyclass(module = "lieflow", name = "_Tangent", frozen)]
pub struct PyTangent {
    pub(crate) inner: Arc<dyn TangentSystem>,
}

#[pymethods]
impl PyTangent {
    /// The lifted states (..., d(1 + d)) of states (..., d) with the identity as directions.
    fn seed<'py>(
        &self,
        py: Python<'py>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let t = &self.inner;
        let d = t.base_dim();
        let v = states.as_array();
        let shape = v.shape().to_vec();
        if shape.last() != Some(&d) {
            return Err(to_py(Error::shape(
                "state0",
                format!("(..., {d})"),
                format!("{shape:?}"),
            )));
        }
        let data = read_all("state0", &v)?;
        let mut out = Vec::with_capacity(data.len() * (d + 1));
        for z in data.chunks_exact(d) {
            out.extend(t.seed(z).py()?);
        }
        let mut lifted = shape;
        *lifted.last_mut().expect("checked above") = d * (d + 1);
        numpy::ndarray::ArrayD::from_shape_vec(lifted, out)
            .map(|a| a.into_pyarray(py))
            .map_err(|e| to_py(Error::shape("state0", "(..., d)", e.to_string())))
    }

    /// (states (..., d), Jacobians (..., d, d)) of lifted states (..., d(1 + d)).
    fn split<'py>(
        &self,
        py: Python<'py>,
        lifted: ArrayIn<'py>,
    ) -> PyResult<(Array<'py>, Array<'py>)> {
        let t = &self.inner;
        let d = t.base_dim();
        let v = lifted.as_array();
        let shape = v.shape().to_vec();
        if shape.last() != Some(&(d * (d + 1))) {
            return Err(to_py(Error::shape(
                "states",
                format!("(..., {})", d * (d + 1)),
                format!("{shape:?}"),
            )));
        }
        let data = read_all("states", &v)?;
        let n = data.len() / (d * (d + 1));
        let (mut zs, mut js) = (vec![0.0; n * d], vec![0.0; n * d * d]);
        for ((l, z), j) in data
            .chunks_exact(d * (d + 1))
            .zip(zs.chunks_exact_mut(d))
            .zip(js.chunks_exact_mut(d * d))
        {
            t.jacobian(l, z, j);
        }
        let lead = &shape[..shape.len() - 1];
        let zshape: Vec<usize> = lead.iter().copied().chain([d]).collect();
        let jshape: Vec<usize> = lead.iter().copied().chain([d, d]).collect();
        let err = |e: numpy::ndarray::ShapeError| {
            to_py(Error::shape("states", "(..., D)", e.to_string()))
        };
        Ok((
            numpy::ndarray::ArrayD::from_shape_vec(zshape, zs)
                .map_err(err)?
                .into_pyarray(py),
            numpy::ndarray::ArrayD::from_shape_vec(jshape, js)
                .map_err(err)?
                .into_pyarray(py),
        ))
    }
}
