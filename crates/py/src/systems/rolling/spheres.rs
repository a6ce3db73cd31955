//! `RollingSpheres`: binding of `lieflow::systems::rolling::spheres` (003 §2), a thin subclass of
//! `lieflow.System`: constructor, states and observables.
#![allow(non_snake_case)]

use lieflow::systems::RollingSpheres;
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use crate::convert::ArrayIn;
use crate::convert::{real, real_matrix, real_vec, reals};
use crate::errors::{to_py, IntoPy};
use crate::system::{PySystem, Thin};
use lieflow::Error;

type Any<'py> = Bound<'py, PyAny>;

/// Two rigid spheres rolling against each other without slipping, free in space (003 §2).
///
/// Sphere k has radius r_k, mass m_k, centre of mass gamma_k (‖gamma_k‖ < r_k, in the reference
/// sphere centred at 0) and second-moment matrix about its centre of mass
/// I_k = int (p - gamma_k)(p - gamma_k)^T dm (symmetric positive semi-definite; the moment of
/// inertia tensor is tr(I_k) 1 - I_k). State (z1, z2, u, Omega1, Omega2) (27,): attitudes
/// z_k in SO(3) (row-major), u in S^2 the unit vector from centre 1 to centre 2, body angular
/// velocities Omega_k; du/dt = (alpha1 z1 Omega1 + alpha2 z2 Omega2) x u (003 (10),
/// alpha_k = r_k/(r1 + r2)). Energy: the kinetic energy of both bodies (centre-of-mass frame);
/// invariants: the total angular momentum (3,). Methods: midpoint (default; symmetric Lie-group
/// midpoint, order 2, bounded energy error), midpoint4, rkmk4, rk4.
///
/// Args:
///     r1, r2, m1, m2 > 0; gamma1, gamma2 (3,); inertia1, inertia2 (3, 3).
/// Raises:
///     InvalidArgumentError, NonFiniteError.
#[pyclass(name = "RollingSpheres", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyRollingSpheres;

/// Maps `f(system, state) -> values` over states (..., 27) -> (..., *shape).
fn observe<'py>(
    slf: &Bound<'py, PyRollingSpheres>,
    states: ArrayIn<'py>,
    shape: &[usize],
    f: impl Fn(&RollingSpheres, &[f64], &mut [f64]) -> lieflow::Result<()>,
) -> PyResult<Any<'py>> {
    let sys = slf.core::<RollingSpheres>()?;
    slf.base()
        .map_states(slf.py(), &states, shape, |z, out| f(sys, z, out))
}

#[pymethods]
impl PyRollingSpheres {
    #[new]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = real)] r1: f64,
        #[pyo3(from_py_with = real)] r2: f64,
        #[pyo3(from_py_with = reals::<3>)] gamma1: [f64; 3],
        #[pyo3(from_py_with = reals::<3>)] gamma2: [f64; 3],
        #[pyo3(from_py_with = real)] m1: f64,
        #[pyo3(from_py_with = real)] m2: f64,
        #[pyo3(from_py_with = real_matrix::<3, 3>)] inertia1: [[f64; 3]; 3],
        #[pyo3(from_py_with = real_matrix::<3, 3>)] inertia2: [[f64; 3]; 3],
    ) -> PyResult<PyClassInitializer<Self>> {
        let sys = RollingSpheres::new(r1, r2, gamma1, gamma2, m1, m2, inertia1, inertia2).py()?;
        let args = (r1, r2, gamma1, gamma2, m1, m2, inertia1, inertia2).into_pyobject(py)?;
        let names = &[
            "r1", "r2", "gamma1", "gamma2", "m1", "m2", "inertia1", "inertia2",
        ];
        Ok(PySystem::subclass(sys, args, names))
    }

    /// e = m1 m2 / (m1 + m2) times R^2 = (r1 + r2)^2: the kinetic energy is this times L of 003 (8).
    #[getter]
    fn scale(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Ok(slf.core::<RollingSpheres>()?.scale())
    }

    /// (alpha1, alpha2) = (r1, r2) / (r1 + r2).
    #[getter]
    fn alphas(slf: &Bound<'_, Self>) -> PyResult<[f64; 2]> {
        Ok(slf.core::<RollingSpheres>()?.alphas())
    }

    /// The state (27,) from z1, z2 (3, 3) rotations, u (3,) unit, Omega1, Omega2 (3,).
    ///
    /// Raises:
    ///     NotInGroupError, NonFiniteError.
    fn state(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = real_matrix::<3, 3>)] z1: [[f64; 3]; 3],
        #[pyo3(from_py_with = real_matrix::<3, 3>)] z2: [[f64; 3]; 3],
        #[pyo3(from_py_with = reals::<3>)] u: [f64; 3],
        #[pyo3(from_py_with = reals::<3>)] Omega1: [f64; 3],
        #[pyo3(from_py_with = reals::<3>)] Omega2: [f64; 3],
    ) -> PyResult<Vec<f64>> {
        let sys = slf.core::<RollingSpheres>()?;
        sys.state(z1, z2, u, Omega1, Omega2).py()
    }

    /// The planar state (003 §2.4 <-> §1): z_k the rotation by theta_k about e3,
    /// u = (cos phi, sin phi, 0), Omega_k = (0, 0, thetadot_k); then dphi/dt =
    /// (r1 thetadot_1 + r2 thetadot_2)/(r1 + r2). It stays planar when gamma_k is
    /// perpendicular to e3 and e3 is an eigenvector of I_k. 003 §1's disk moment of inertia
    /// (about the disk's centre) is I_k[0,0] + I_k[1,1] + m_k ‖gamma_k‖^2.
    fn planar_state(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] theta: [f64; 2],
        #[pyo3(from_py_with = real)] phi: f64,
        #[pyo3(from_py_with = reals::<2>)] thetadot: [f64; 2],
    ) -> PyResult<Vec<f64>> {
        let sys = slf.core::<RollingSpheres>()?;
        sys.planar_state(theta, phi, thetadot).py()
    }

    /// The planar coordinates (theta1, theta2, phi, thetadot_1, thetadot_2) of one state on
    /// the planar subbundle (to `tol`).
    ///
    /// Raises:
    ///     InvalidArgumentError (off the planar subbundle), ShapeError.
    #[pyo3(signature = (state, tol = 1e-9))]
    fn to_planar(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = real_vec)] state: Vec<f64>,
        #[pyo3(from_py_with = real)] tol: f64,
    ) -> PyResult<[f64; 5]> {
        if !(tol >= 0.0 && tol.is_finite()) {
            return Err(to_py(Error::invalid(
                "tol",
                format!("expected a finite tolerance ≥ 0, got {tol}"),
            )));
        }
        slf.core::<RollingSpheres>()?.to_planar(&state, tol).py()
    }

    /// Total angular momentum about the centre of mass (conserved), (..., 27) -> (..., 3).
    fn angular_momentum<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[3], |s, z, out| {
            out.copy_from_slice(&s.angular_momentum(z)?);
            Ok(())
        })
    }

    /// Body momenta dKE/dOmega_k (physical units), (..., 27) -> (..., 2, 3); their component
    /// along gamma_k is the (non-conserved) momentum of the material rotation about it.
    fn body_momenta<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[2, 3], |s, z, out| {
            out.copy_from_slice(s.body_momenta(z)?.as_flattened());
            Ok(())
        })
    }

    /// Spatial momenta P_k conjugate to the spatial angular velocities (P1 + P2 = total
    /// angular momentum), (..., 27) -> (..., 2, 3).
    fn spatial_momenta<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[2, 3], |s, z, out| {
            out.copy_from_slice(s.spatial_momenta(z)?.as_flattened());
            Ok(())
        })
    }

    /// du/dt of the rolling constraint 003 (10), (..., 27) -> (..., 3).
    fn udot<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[3], |s, z, out| {
            out.copy_from_slice(&s.udot(z)?);
            Ok(())
        })
    }

    /// The contact point, (..., 27) -> (..., 3).
    fn contact_point<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[3], |s, z, out| {
            out.copy_from_slice(&s.contact_point(z)?);
            Ok(())
        })
    }

    /// The geometric centres a_1, a_2 of 003 (4), (..., 27) -> (..., 2, 3).
    fn centres<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[2, 3], |s, z, out| {
            out.copy_from_slice(s.centres(z)?.as_flattened());
            Ok(())
        })
    }

    /// The centres of mass, (..., 27) -> (..., 2, 3).
    fn centres_of_mass<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[2, 3], |s, z, out| {
            out.copy_from_slice(s.centres_of_mass(z)?.as_flattened());
            Ok(())
        })
    }

    /// Body angular accelerations (dOmega1/dt, dOmega2/dt), (..., 27) -> (..., 2, 3).
    fn accelerations<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[2, 3], |s, z, out| {
            out.copy_from_slice(s.accelerations(z)?.as_flattened());
            Ok(())
        })
    }
}
