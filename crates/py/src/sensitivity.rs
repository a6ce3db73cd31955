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
    /// The lifted states (..., n) of states (..., d) with the identity as directions (e = d, or
    /// d − 6 with an attitude: its directions left-trivialised): n = d + (e + p)·w, each
    /// direction of w = e values, or of w = d for a Runge–Kutta lift (ambient on SO(3) blocks).
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
        let width = t.space().dim();
        let mut out = Vec::with_capacity(data.len() / d * width);
        for z in data.chunks_exact(d) {
            out.extend(t.seed(z).py()?);
        }
        let mut lifted = shape;
        *lifted.last_mut().expect("checked above") = width;
        numpy::ndarray::ArrayD::from_shape_vec(lifted, out)
            .map(|a| a.into_pyarray(py))
            .map_err(|e| to_py(Error::shape("state0", "(..., d)", e.to_string())))
    }

    /// The number e of directions and of a Jacobian's rows (the state's d less 6 per SO(3)
    /// block: left-trivialised).
    #[getter]
    fn directions(&self) -> usize {
        self.inner.tangent_dim()
    }

    /// The names of the parameters the lift differentiates along.
    #[getter]
    fn parameters(&self) -> Vec<&'static str> {
        self.inner.parameter_names()
    }

    /// (states (..., d), Jacobians (..., e, e), parameter Jacobians (..., e, p)) of lifted
    /// states (..., n).
    fn split<'py>(
        &self,
        py: Python<'py>,
        lifted: ArrayIn<'py>,
    ) -> PyResult<(Array<'py>, Array<'py>, Array<'py>)> {
        let t = &self.inner;
        let (d, e, np) = (t.base_dim(), t.tangent_dim(), t.parameter_names().len());
        let width = t.space().dim();
        let v = lifted.as_array();
        let shape = v.shape().to_vec();
        if shape.last() != Some(&width) {
            return Err(to_py(Error::shape(
                "states",
                format!("(..., {width})"),
                format!("{shape:?}"),
            )));
        }
        let data = read_all("states", &v)?;
        let n = data.len() / width;
        let (mut zs, mut js, mut ps) = (
            vec![0.0; n * d],
            vec![0.0; n * e * e],
            vec![0.0; n * e * np],
        );
        for (i, l) in data.chunks_exact(width).enumerate() {
            t.jacobian(
                l,
                &mut zs[i * d..(i + 1) * d],
                &mut js[i * e * e..(i + 1) * e * e],
                &mut ps[i * e * np..(i + 1) * e * np],
            );
        }
        let lead = &shape[..shape.len() - 1];
        let zshape: Vec<usize> = lead.iter().copied().chain([d]).collect();
        let jshape: Vec<usize> = lead.iter().copied().chain([e, e]).collect();
        let pshape: Vec<usize> = lead.iter().copied().chain([e, np]).collect();
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
            numpy::ndarray::ArrayD::from_shape_vec(pshape, ps)
                .map_err(err)?
                .into_pyarray(py),
        ))
    }
}
