//! `RigidBody`: the binding of `lieflow::systems::tops::rigid_body` (000 §3–§4). A thin
//! subclass of `lieflow.System`: constructor and observables.
#![allow(non_snake_case)]

use lieflow::systems as core;
use lieflow::Error;
use numpy::{PyArray1, PyArray2, PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use super::Inertia;
use crate::convert::{py_mat3, py_vec, shape_str, ArrayIn};
use crate::errors::{to_py, IntoPy};
use crate::items::{array, map_items, Input};
use crate::system::{PySystem, Thin};

type Any<'py> = Bound<'py, PyAny>;

/// A free rigid body (Euler top) on so(3)* (000 §3–§4).
///
/// State :math:`z = M`, the body angular momentum (3,). Euler's equation
/// :math:`\dot M = M \times \Omega` with :math:`\Omega = \mathbb{I}^{-1} M`; energy
/// :math:`H = \tfrac12 M \cdot \mathbb{I}^{-1} M`; Casimir :math:`\|M\|^2`. Carries an attitude
/// :math:`R` (:math:`\dot R = R \hat\Omega`) when `integrate(..., attitude=R0)` is given;
/// :math:`R M` is conserved.
/// Methods: splitting (default), splitting4, splitting6, splitting8 (the symmetric splitting
/// into three axis rotations: Strang, Suzuki 4, Yoshida 6, Kahan–Li 8), processed6, processed8,
/// processed10 (Blanes–Casas–Murua processed splittings, effective orders 6, 8, 10), isospectral, lgvi, dmv (discrete
/// Moser-Veselov), dmv4, dmv6, dmv8, dmv10 (preprocessed DMV, Hairer & Vilmart 2006), rk4,
/// rkmk4, exact (the exact flow, to round-off at any dt).
///
/// Args:
///     inertia: principal moments (3,) > 0, or a (3, 3) symmetric positive-definite matrix
///         (diagonalised once; states stay in the given body frame).
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError (non-positive or non-symmetric inertia).
#[pyclass(name = "RigidBody", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyRigidBody;

#[pymethods]
impl PyRigidBody {
    #[new]
    #[pyo3(signature = (inertia))]
    fn new(inertia: &Bound<'_, PyAny>) -> PyResult<PyClassInitializer<Self>> {
        let body = match super::inertia(&ArrayIn::named("inertia", inertia)?)? {
            Inertia::Moments(m) => core::RigidBody::new(m),
            Inertia::Matrix(m) => core::RigidBody::from_matrix(&m),
        }
        .py()?;
        super::warn_unphysical(inertia.py(), body.moments())?;
        let args = (inertia,).into_pyobject(inertia.py())?;
        Ok(PySystem::subclass(body, args, &["inertia"]))
    }

    /// Names of the observables that take (states, attitude); `Trajectory` passes its attitude.
    #[classattr]
    fn _attitude_observables() -> (&'static str,) {
        ("spatial_momentum",)
    }

    /// The principal moments of inertia (3,).
    #[getter]
    fn moments<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(py_vec(slf.py(), &slf.core::<core::RigidBody>()?.moments()))
    }

    /// The principal frame :math:`Q \in SO(3)` (columns = principal axes,
    /// :math:`\mathbb{I} = Q \operatorname{diag}(\mathrm{moments})\, Q^\top`) when the inertia was
    /// given as a matrix, else None.
    #[getter]
    fn frame<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let frame = slf.core::<core::RigidBody>()?.frame();
        Ok(frame.map(|q| py_mat3(slf.py(), &q)))
    }

    /// Body angular velocity :math:`\Omega = \mathbb{I}^{-1} M`, vectorised: (..., 3) -> (..., 3).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn angular_velocity<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let body = slf.core::<core::RigidBody>()?;
        map_items(
            slf.py(),
            &[Input::new("states", &states, &[3])],
            &[3],
            |m, out| {
                out.copy_from_slice(&body.angular_velocity(m[0])?);
                Ok(())
            },
        )
    }

    /// Spatial angular momentum :math:`R M` (000 Theorem 4.2), conserved; vectorised with numpy
    /// broadcasting: states (..., 3) and attitude (..., 3, 3) -> (..., 3).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn spatial_momentum<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
        attitude: ArrayIn<'py>,
    ) -> PyResult<Any<'py>> {
        super::spatial_momentum(slf.py(), &states, &attitude, 3)
    }

    /// The exact body momentum :math:`M(t)` from :math:`M(0) = M_0` by Jacobi elliptic functions
    /// (000 §4; the classical solution :math:`M_1 = a_1 \operatorname{cn} u`,
    /// :math:`M_2 = a_2 \operatorname{sn} u`, :math:`M_3 = a_3 \operatorname{dn} u` in suitably
    /// ordered principal axes, :math:`u = u_0 + \lambda t`; see
    /// `lieflow::systems::RigidBody::exact_momentum`), and with `attitude` = R0 also the attitude
    /// :math:`R(t) = R_0 B_0^\top Z(\phi(t))\, B(t)` through the conserved spatial momentum
    /// :math:`R M` (Celledoni, Fassò, Säfström & Zanna 2008), the angle :math:`\phi` from
    /// Carlson's :math:`R_J` (`lieflow::systems::RigidBody::exact_motion`); accurate to a few
    /// :math:`\varepsilon (1 + \omega t)` at every t.
    ///
    /// Args:
    ///     M0: (3,) or (..., 3); t: a time or a 1-D array of times (k,);
    ///     attitude: None, or R0 (3, 3) or (..., 3, 3) (broadcast with M0), a rotation.
    /// Returns:
    ///     M: (..., 3) for a scalar t, (..., k, 3) for an array of times; with `attitude`
    ///     the pair (M, R) with R (..., 3, 3) or (..., k, 3, 3).
    /// Raises:
    ///     ShapeError, NonFiniteError, NotInGroupError (R0 not a rotation),
    ///     InvalidArgumentError (t so large that a phase of the motion is lost to rounding).
    #[pyo3(signature = (M0, t, attitude=None))]
    fn exact_solution<'py>(
        slf: &Bound<'py, Self>,
        M0: ArrayIn<'py>,
        t: ArrayIn<'py>,
        attitude: Option<ArrayIn<'py>>,
    ) -> PyResult<Any<'py>> {
        let (py, body) = (slf.py(), slf.core::<core::RigidBody>()?);
        let tv = t.as_array();
        if tv.ndim() > 1 {
            return Err(to_py(Error::shape(
                "t",
                "a scalar or a 1-D array (k,)",
                shape_str(tv.shape()),
            )));
        }
        let times: Vec<f64> = tv.iter().copied().collect();
        let Some(r0) = attitude else {
            let out_item: Vec<usize> = tv.shape().iter().copied().chain([3]).collect();
            return map_items(py, &[Input::new("M0", &M0, &[3])], &out_item, |m, out| {
                for (o, &ti) in out.chunks_exact_mut(3).zip(&times) {
                    o.copy_from_slice(&body.exact_momentum(m[0], ti)?);
                }
                Ok(())
            });
        };
        // (M, R) of each item side by side, then split into the two arrays.
        let out_item: Vec<usize> = tv.shape().iter().copied().chain([12]).collect();
        let both = map_items(
            py,
            &[
                Input::new("M0", &M0, &[3]),
                Input::new("attitude", &r0, &[3, 3]),
            ],
            &out_item,
            |x, out| {
                for (o, &ti) in out.chunks_exact_mut(12).zip(&times) {
                    let (m, r) = body.exact_motion(x[0], x[1], ti)?;
                    o[..3].copy_from_slice(&m);
                    o[3..].copy_from_slice(&r);
                }
                Ok(())
            },
        )?;
        let both = both.cast::<PyArrayDyn<f64>>()?.readonly();
        let v = both.as_array();
        let lead = &v.shape()[..v.ndim() - 1];
        let (mut m, mut r) = (Vec::new(), Vec::new());
        for item in v.iter().copied().collect::<Vec<f64>>().chunks_exact(12) {
            m.extend_from_slice(&item[..3]);
            r.extend_from_slice(&item[3..]);
        }
        let shape = |tail: &[usize]| lead.iter().chain(tail).copied().collect::<Vec<usize>>();
        let m = array(py, &shape(&[3]), m)?;
        let r = array(py, &shape(&[3, 3]), r)?;
        Ok((m, r).into_pyobject(py)?.into_any())
    }
}
