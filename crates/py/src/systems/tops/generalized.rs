//! `GeneralizedRigidBody`: the binding of `lieflow::systems::tops::generalized` (the so(n)
//! body). A thin subclass of `lieflow.System`: constructor and observables.
#![allow(non_snake_case)]

use lieflow::lie::so;
use lieflow::systems as core;
use lieflow::{Error, Mat};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use crate::convert::{py_vec, shape_str, ArrayIn};
use crate::errors::IntoPy;
use crate::items::{map_items, Input};
use crate::system::{PySystem, Thin};

type Any<'py> = Bound<'py, PyAny>;

/// The generalized rigid body on so(n)* (Euler–Arnold / Manakov equations; the form of the
/// pseudo-rigid body's reduced equation 001 (7.25)).
///
/// :math:`M = J\Omega + \Omega J` with :math:`J` the mass matrix; :math:`\dot M = [M, \Omega]`;
/// energy :math:`H = \tfrac12 \sum_{i<j} M_{ij}^2 / (J_i + J_j)` (principal frame); Casimirs
/// :math:`C_k = \tfrac12 \operatorname{tr}((M^\top M)^k)`,
/// :math:`k = 1, \dots, \lfloor n/2 \rfloor` (they fix the spectrum of :math:`M`). State
/// :math:`z` = the :math:`e_{ij}` coordinates of the skew matrix :math:`M` (:math:`i < j`, row by row),
/// length n(n-1)/2; `state(M)` and `matrix(z)` convert.
/// Methods: isospectral (default), rk4, rkmk4.
///
/// Args:
///     J: principal entries (n,) (n >= 2, J_i >= 0, J_i + J_j > 0), or a symmetric
///         positive-semidefinite (n, n) matrix (diagonalised once).
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError.
#[pyclass(name = "GeneralizedRigidBody", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyGeneralizedRigidBody;

#[pymethods]
impl PyGeneralizedRigidBody {
    #[new]
    #[pyo3(signature = (J))]
    fn new(J: &Bound<'_, PyAny>) -> PyResult<PyClassInitializer<Self>> {
        let a = ArrayIn::named("J", J)?;
        let v = a.as_array();
        let body = match v.ndim() {
            1 => core::GeneralizedRigidBody::new(&v.iter().copied().collect::<Vec<_>>()),
            2 => core::GeneralizedRigidBody::from_matrix(&Mat::from_fn(
                v.shape()[0],
                v.shape()[1],
                |i, j| v[[i, j]],
            )),
            _ => Err(Error::shape(
                "J",
                "(n,) principal entries or an (n, n) symmetric matrix",
                shape_str(v.shape()),
            )),
        }
        .py()?;
        Ok(PySystem::subclass(
            body,
            (J,).into_pyobject(J.py())?,
            &["J"],
        ))
    }

    /// The dimension n (M is n × n).
    #[getter]
    fn n(slf: &Bound<'_, Self>) -> PyResult<usize> {
        Ok(body(slf)?.n())
    }

    /// The principal entries :math:`J_i` (n,).
    #[getter]
    fn moments<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(py_vec(slf.py(), body(slf)?.principal()))
    }

    /// Flat state z (:math:`e_{ij}` coordinates, `lieflow.lie.vee_n`) of skew matrices: (..., n, n)
    /// -> (..., n(n-1)/2).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, NotInGroupError (M not skew-symmetric).
    fn state<'py>(slf: &Bound<'py, Self>, M: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let n = body(slf)?.n();
        map_items(
            slf.py(),
            &[Input::new("M", &M, &[n, n])],
            &[so::dim(n)],
            |m, out| {
                let m = Mat::from_fn(n, n, |i, j| m[0][i * n + j]);
                out.copy_from_slice(&so::vee_n(&m)?);
                Ok(())
            },
        )
    }

    /// The skew matrices M of flat states: (..., n(n-1)/2) -> (..., n, n).
    ///
    /// Raises:
    ///     ShapeError.
    fn matrix<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let n = body(slf)?.n();
        map_items(
            slf.py(),
            &[Input::new("states", &states, &[so::dim(n)])],
            &[n, n],
            |z, out| {
                let m = so::hat_n(z[0])?;
                for (k, o) in out.iter_mut().enumerate() {
                    *o = m[(k / n, k % n)];
                }
                Ok(())
            },
        )
    }
}

/// The core body of a `GeneralizedRigidBody`.
fn body<'a>(
    slf: &'a Bound<'_, PyGeneralizedRigidBody>,
) -> PyResult<&'a core::GeneralizedRigidBody> {
    slf.core()
}
