//! `RollingSpheres`: binding of `lieflow::systems::rolling::spheres` (003 §2), a thin subclass of
//! `lieflow.System`: constructor, states and observables.
#![allow(non_snake_case)]

use lieflow::systems::rolling::spheres::STATE_DIM;
use lieflow::systems::RollingSpheres;
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use crate::convert::ArrayIn;
use crate::convert::{real, real_matrix, real_vec, reals};
use crate::errors::{to_py, IntoPy};
use crate::items::{par_map_items, Input};
use crate::system::{PySystem, Thin};
use lieflow::Error;

type Any<'py> = Bound<'py, PyAny>;

/// Two rigid spheres rolling against each other without slipping, free in space (003 §2).
///
/// Sphere k has radius :math:`r_k`, mass :math:`m_k`, centre of mass :math:`\gamma_k`
/// (:math:`\|\gamma_k\| < r_k`, in the reference sphere centred at 0) and second-moment matrix
/// about its centre of mass :math:`I_k = \int (p - \gamma_k)(p - \gamma_k)^\top dm` (symmetric
/// positive semi-definite; the moment of inertia tensor is
/// :math:`\operatorname{tr}(I_k)\, \mathrm{Id} - I_k`). State (z1, z2, u, Omega1, Omega2) (27,):
/// attitudes :math:`z_k \in SO(3)` (row-major), :math:`u \in S^2` the unit vector from centre 1 to
/// centre 2, body angular velocities :math:`\Omega_k`;
/// :math:`\dot u = (\alpha_1 z_1 \Omega_1 + \alpha_2 z_2 \Omega_2) \times u` (003 (10),
/// :math:`\alpha_k = r_k/(r_1 + r_2)`). Energy: the kinetic energy of both bodies (centre-of-mass
/// frame); invariants: the total angular momentum (3,). Methods: midpoint (default; symmetric
/// Lie-group midpoint, order 2, bounded energy error), midpoint4, rkmk4, rk4.
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

/// `f(state, Omega, Omega_tilde) -> (3,)` over the broadcast leading axes of states (..., 27)
/// and two pairs of angular velocities (..., 2, 3).
fn pairs<'py>(
    py: Python<'py>,
    states: &ArrayIn<'py>,
    omega: &ArrayIn<'py>,
    omega_tilde: &ArrayIn<'py>,
    f: impl Fn(&[f64], [[f64; 3]; 2], [[f64; 3]; 2]) -> lieflow::Result<[f64; 3]> + Sync + Send,
) -> PyResult<Any<'py>> {
    let inputs = [
        Input::finite("states", states, &[STATE_DIM]),
        Input::finite("Omega", omega, &[2, 3]),
        Input::finite("Omega_tilde", omega_tilde, &[2, 3]),
    ];
    let pair = |x: &[f64]| [[x[0], x[1], x[2]], [x[3], x[4], x[5]]];
    par_map_items(py, &inputs, &[3], |x, out| {
        out.copy_from_slice(&f(x[0], pair(x[1]), pair(x[2]))?);
        Ok(())
    })
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

    /// :math:`e = \frac{m_1 m_2}{m_1 + m_2} R^2` with :math:`R = r_1 + r_2`: the kinetic energy is
    /// this times L of 003 (8).
    #[getter]
    fn scale(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Ok(slf.core::<RollingSpheres>()?.scale())
    }

    /// :math:`(\alpha_1, \alpha_2) = (r_1, r_2) / (r_1 + r_2)`.
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

    /// The planar state (003 §2.4 <-> §1): :math:`z_k` the rotation by :math:`\theta_k` about
    /// :math:`e_3`, :math:`u = (\cos\phi, \sin\phi, 0)`, :math:`\Omega_k = (0, 0, \dot\theta_k)`;
    /// then :math:`\dot\phi = (r_1\dot\theta_1 + r_2\dot\theta_2)/(r_1 + r_2)`. It stays planar
    /// when :math:`\gamma_k` is perpendicular to :math:`e_3` and :math:`e_3` is an eigenvector of
    /// :math:`I_k`. 003 §1's disk moment of inertia (about the disk's centre) is
    /// :math:`I_k[0,0] + I_k[1,1] + m_k \|\gamma_k\|^2`.
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

    /// The Lagrangian L of 003 (8), evaluated as printed with :math:`\dot u` from the rolling
    /// constraint (10):
    ///
    /// .. math::
    ///
    ///     L = \tfrac12 \Omega_1^\top J_1 \Omega_1 + \tfrac12 \Omega_2^\top J_2 \Omega_2
    ///         + \tfrac12 \|\dot u\|^2 - B,
    ///
    ///     B = \dot u \cdot (\alpha_1 b_1 - \alpha_2 b_2) + \alpha_1 \alpha_2\, b_1 \cdot b_2,
    ///
    /// with :math:`b_k = z_k (\Omega_k \times e_k)`, :math:`e_k = \gamma_k / r_k` and the rescaled
    /// tensors :math:`J_k` of 003 §2; ``scale * L`` is the kinetic energy of both bodies
    /// (`energy`, computed in the completed-square form). (..., 27) -> (...).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, NotInGroupError (z_k not rotations, u not a unit vector).
    fn lagrangian<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[], |s, z, out| {
            out[0] = s.lagrangian(z)?;
            Ok(())
        })
    }

    /// The curvature of the rolling distribution (003 §2.2) in closed form,
    ///
    /// .. math::
    ///
    ///     \Delta(X, \tilde X) = \alpha_1 \alpha_2\, u \times ((z_1\Omega_1 - z_2\Omega_2)
    ///     \times (z_1\tilde\Omega_1 - z_2\tilde\Omega_2)),
    ///
    /// for the constrained fields :math:`X, \tilde X` with body angular velocities
    /// :math:`\Omega = (\Omega_1, \Omega_2)` (`Omega`) and
    /// :math:`\tilde\Omega = (\tilde\Omega_1, \tilde\Omega_2)` (`Omega_tilde`), at the
    /// configuration (z1, z2, u) of the states (their velocities are ignored);
    /// :math:`\Delta = -\nu([X, \tilde X])`, see `curvature_by_brackets`. Maps over the broadcast
    /// leading axes of the three arguments.
    ///
    /// Args:
    ///     states: (..., 27); Omega, Omega_tilde: (..., 2, 3), rows the angular velocities of the
    ///     two bodies.
    /// Returns:
    ///     (..., 3) array.
    /// Raises:
    ///     ShapeError, NonFiniteError, NotInGroupError (z_k not rotations, u not a unit vector).
    fn curvature<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
        Omega: ArrayIn<'py>,
        Omega_tilde: ArrayIn<'py>,
    ) -> PyResult<Any<'py>> {
        let sys = slf.core::<RollingSpheres>()?;
        pairs(slf.py(), &states, &Omega, &Omega_tilde, |z, o, ot| {
            sys.curvature(z, o, ot)
        })
    }

    /// The curvature of the rolling distribution (003 §2.2) from the Lie bracket of the constrained
    /// fields, :math:`\Delta(X, \tilde X) = -\nu([X, \tilde X])` with
    /// :math:`\nu(\Omega_1, \Omega_2, v) = v - (\alpha_1 z_1\Omega_1 + \alpha_2 z_2\Omega_2) \times u`:
    /// the bracket from the commutator of the exact flows of :math:`X` and :math:`\tilde X` over
    /// the time s (second differences, symmetrised in :math:`\pm s` and Richardson-extrapolated
    /// from s and 2s; error :math:`O((s \|\Omega\|)^4) + O(\varepsilon / s^2)`: about 1e-9 relative
    /// at the default s for angular velocities of order one). Equal to `curvature` (the closed
    /// form).
    ///
    /// Args:
    ///     states: (..., 27); Omega, Omega_tilde: (..., 2, 3); s: the flow time, > 0.
    /// Returns:
    ///     (..., 3) array.
    /// Raises:
    ///     ShapeError, NonFiniteError, NotInGroupError, InvalidArgumentError (s <= 0).
    #[pyo3(signature = (states, Omega, Omega_tilde, s = 2e-3))]
    fn curvature_by_brackets<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
        Omega: ArrayIn<'py>,
        Omega_tilde: ArrayIn<'py>,
        #[pyo3(from_py_with = real)] s: f64,
    ) -> PyResult<Any<'py>> {
        let sys = slf.core::<RollingSpheres>()?;
        pairs(slf.py(), &states, &Omega, &Omega_tilde, |z, o, ot| {
            sys.curvature_by_brackets(z, o, ot, s)
        })
    }

    /// Total angular momentum about the centre of mass (conserved), (..., 27) -> (..., 3).
    fn angular_momentum<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[3], |s, z, out| {
            out.copy_from_slice(&s.angular_momentum(z)?);
            Ok(())
        })
    }

    /// Body momenta :math:`\partial T/\partial\Omega_k` (T the kinetic energy, physical units),
    /// (..., 27) -> (..., 2, 3); their component along :math:`\gamma_k` is the (non-conserved)
    /// momentum of the material rotation about it.
    fn body_momenta<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[2, 3], |s, z, out| {
            out.copy_from_slice(s.body_momenta(z)?.as_flattened());
            Ok(())
        })
    }

    /// Spatial momenta :math:`P_k` conjugate to the spatial angular velocities (:math:`P_1 + P_2` =
    /// total angular momentum), (..., 27) -> (..., 2, 3).
    fn spatial_momenta<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[2, 3], |s, z, out| {
            out.copy_from_slice(s.spatial_momenta(z)?.as_flattened());
            Ok(())
        })
    }

    /// :math:`\dot u` of the rolling constraint 003 (10), (..., 27) -> (..., 3).
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

    /// The geometric centres :math:`a_1, a_2` of 003 (4), (..., 27) -> (..., 2, 3).
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

    /// Body angular accelerations :math:`(\dot\Omega_1, \dot\Omega_2)`, (..., 27) -> (..., 2, 3).
    fn accelerations<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        observe(slf, states, &[2, 3], |s, z, out| {
            out.copy_from_slice(s.accelerations(z)?.as_flattened());
            Ok(())
        })
    }
}
