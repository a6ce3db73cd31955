//! `HeavyTop`: binding of `lieflow::systems::tops::heavy_top` (000 §5.2). A thin subclass of
//! `lieflow.System`: constructor and observables.
#![allow(non_snake_case)]

use lieflow::integrate::Block;
use lieflow::systems as core;
use lieflow::Error;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use super::Inertia;
use crate::convert::real;
use crate::convert::{self, py_vec, ArrayIn};
use crate::errors::{to_py, IntoPy};
use crate::items::{map_items, Input};
use crate::system::{PySystem, Thin};

type Any<'py> = Bound<'py, PyAny>;

/// The heavy top (000 §5.2): a rigid body with a fixed point in uniform gravity.
///
/// State :math:`z = (M, \Gamma)` (6,): body angular momentum :math:`M` and
/// :math:`\Gamma = R^\top e_3`, the upward vertical seen in the body.
/// :math:`\dot M = M \times \Omega + mgl\, \Gamma \times \chi`,
/// :math:`\dot\Gamma = \Gamma \times \Omega`, :math:`\Omega = \mathbb{I}^{-1} M`; energy
/// :math:`H = \tfrac12 M \cdot \mathbb{I}^{-1} M + mgl\, \Gamma \cdot \chi`; Casimirs
/// :math:`(\|\Gamma\|^2, M \cdot \Gamma)`; for the Lagrange top (:math:`I_1 = I_2`,
/// :math:`\chi = e_3`) also :math:`M_3` is conserved. With an attitude :math:`R`, :math:`\Gamma`
/// must equal :math:`R^\top e_3` (use `state(M, attitude=R)`).
/// Methods: splitting (default), splitting4, splitting6, splitting8 (the Lie–Poisson splitting:
/// Strang, Suzuki 4, Yoshida 6, Kahan–Li 8), processed6, processed8, processed10
/// (Blanes–Casas–Murua processed splittings, effective orders 6, 8, 10), lgvi, rk4, exact_splitting, exact_splitting4, exact_splitting6 (the exact free
/// rigid body flow and the gravity kick: Strang, Suzuki 4, Yoshida 6; best for fast tops).
///
/// Args:
///     inertia: principal moments (3,) or a (3, 3) symmetric positive-definite matrix;
///     mgl: weight times distance of the centre of mass from the fixed point (>= 0);
///     chi: direction of the centre of mass in the body (normalised; default e3).
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError.
#[pyclass(name = "HeavyTop", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyHeavyTop;

#[pymethods]
impl PyHeavyTop {
    #[new]
    #[pyo3(
        signature = (inertia, mgl, chi = None),
        text_signature = "(inertia, mgl, chi=(0.0, 0.0, 1.0))"
    )]
    fn new(
        inertia: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = real)] mgl: f64,
        chi: Option<ArrayIn<'_>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let chi = match chi {
            Some(c) => convert::vec3("chi", &c)?.into(),
            None => [0.0, 0.0, 1.0],
        };
        let top = match super::inertia(&ArrayIn::named("inertia", inertia)?)? {
            Inertia::Moments(m) => core::HeavyTop::new(m, mgl, chi),
            Inertia::Matrix(m) => core::HeavyTop::from_matrix(&m, mgl, chi),
        }
        .py()?;
        let py = inertia.py();
        super::warn_unphysical(py, top.moments())?;
        let args = (inertia, mgl, py_vec(py, &chi)).into_pyobject(py)?;
        Ok(PySystem::subclass(top, args, &["inertia", "mgl", "chi"]))
    }

    /// Names of the observables that take (states, attitude); `Trajectory` passes its attitude.
    #[classattr]
    fn _attitude_observables() -> (&'static str,) {
        ("spatial_momentum",)
    }

    /// The principal moments of inertia (3,).
    #[getter]
    fn moments<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(py_vec(slf.py(), &top(slf)?.moments()))
    }

    /// mgl (weight times the distance of the centre of mass from the fixed point).
    #[getter]
    fn mgl(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Ok(top(slf)?.mgl())
    }

    /// The unit direction chi of the centre of mass (body frame).
    #[getter]
    fn chi<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(py_vec(slf.py(), &top(slf)?.chi()))
    }

    /// A flat state :math:`z = (M, \Gamma)` from M (..., 3) and either Gamma (..., 3) or the
    /// attitude R (..., 3, 3) (then :math:`\Gamma = R^\top e_3`, the third row of :math:`R`);
    /// leading axes broadcast.
    ///
    /// Raises:
    ///     InvalidArgumentError (neither or both of Gamma and attitude; Gamma = 0), ShapeError,
    ///     NonFiniteError, NotInGroupError (the attitude is not a rotation).
    #[pyo3(signature = (M, Gamma = None, attitude = None))]
    fn state<'py>(
        slf: &Bound<'py, Self>,
        M: ArrayIn<'py>,
        Gamma: Option<ArrayIn<'py>>,
        attitude: Option<ArrayIn<'py>>,
    ) -> PyResult<Any<'py>> {
        let (py, top) = (slf.py(), top(slf)?);
        let m = Input::new("M", &M, &[3]);
        match (&Gamma, &attitude) {
            (Some(g), None) => {
                let g = Input::new("Gamma", g, &[3]);
                map_items(py, &[m, g], &[6], |x, out| {
                    out[..3].copy_from_slice(x[0]);
                    out[3..].copy_from_slice(x[1]);
                    // The checks of an initial state: finite, Γ ≠ 0.
                    lieflow::integrate::check_state(top, out)
                })
            }
            (None, Some(r)) => {
                let r = Input::new("attitude", r, &[3, 3]);
                map_items(py, &[m, r], &[6], |x, out| {
                    // The attitude of an initial state: finite and in SO(3) (ROTATION_TOL).
                    Block::SO3.check("attitude", x[1])?;
                    out[..3].copy_from_slice(x[0]);
                    out[3..].copy_from_slice(&x[1][6..9]); // Γ = Rᵀe₃, the third row of R
                    lieflow::integrate::check_state(top, out)
                })
            }
            _ => Err(to_py(Error::invalid(
                "state",
                "give exactly one of Gamma and attitude",
            ))),
        }
    }

    /// Spatial angular momentum :math:`R M`, vectorised with broadcasting: states (..., 6) and
    /// attitude (..., 3, 3) -> (..., 3). Only its vertical component :math:`M \cdot \Gamma` is
    /// conserved.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn spatial_momentum<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
        attitude: ArrayIn<'py>,
    ) -> PyResult<Any<'py>> {
        super::spatial_momentum(slf.py(), &states, &attitude, 6)
    }
}

/// The core heavy top of a `HeavyTop`.
fn top<'a>(slf: &'a Bound<'_, PyHeavyTop>) -> PyResult<&'a core::HeavyTop> {
    slf.core()
}
