//! The system classes: `RigidBody`, `GeneralizedRigidBody`, `HeavyTop`, `SphericalPendulum`
//! (bindings of `lieflow::systems`, 000 §3–§5). Each extends [`LiePoissonSystem`] (the
//! integration protocol) with its constructor and observables. Conversions only.
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::integrate::{State, System};
use lieflow::lie::so;
use lieflow::systems as core;
use lieflow::{Error, Mat};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use pyo3::PyClassInitializer;

use super::items::{map_items, shape_str, Input};
use super::{method_names, normalize_flat, LiePoissonSystem};
use crate::convert::{self, py_mat3, py_vec, ArrayIn};
use crate::errors::{to_py, IntoPy};

type Any<'py> = Bound<'py, PyAny>;

/// Row-major copy of a (3, 3) array.
fn row_major9(v: &[f64]) -> [f64; 9] {
    let mut r = [0.0; 9];
    r.copy_from_slice(v);
    r
}

/// The 3-vector in a slice of length 3.
fn vec3(v: &[f64]) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

/// The base-class part of a system object: the protocol over a copy of the core system.
fn with_base<S: System + Clone + Send + Sync + 'static>(
    sys: &S,
) -> PyClassInitializer<LiePoissonSystem> {
    PyClassInitializer::from(LiePoissonSystem::new(Arc::new(sys.clone())))
}

/// Principal moments (3,) or a symmetric positive-definite matrix (3, 3).
enum Inertia {
    Moments([f64; 3]),
    Matrix([f64; 9]),
}

fn inertia(a: &ArrayIn<'_>) -> PyResult<Inertia> {
    let v = a.as_array();
    let data: Vec<f64> = v.iter().copied().collect();
    match v.shape() {
        [3] => Ok(Inertia::Moments(vec3(&data))),
        [3, 3] => Ok(Inertia::Matrix(row_major9(&data))),
        s => Err(to_py(Error::shape(
            "inertia",
            "(3,) principal moments or a (3, 3) symmetric positive-definite matrix",
            shape_str(s),
        ))),
    }
}

/// Copies slices of the last axis of states (..., d) into named fields.
fn slices<'py>(
    py: Python<'py>,
    states: &ArrayIn<'py>,
    d: usize,
    parts: &[(&str, usize, usize)],
) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    for &(name, start, len) in parts {
        let inputs = [Input {
            what: "states",
            array: states,
            item: &[d],
        }];
        let v = map_items(py, &inputs, &[len], |z, out| {
            out.copy_from_slice(&z[0][start..start + len]);
            Ok(())
        })?;
        dict.set_item(name, v)?;
    }
    Ok(dict)
}

/// Spatial angular momentum R M (000 Theorem 4.2) of states whose first three entries are M.
fn spatial_momentum<'py>(
    py: Python<'py>,
    states: &ArrayIn<'py>,
    attitude: &ArrayIn<'py>,
    d: usize,
) -> PyResult<Any<'py>> {
    let inputs = [
        Input {
            what: "states",
            array: states,
            item: &[d],
        },
        Input {
            what: "attitude",
            array: attitude,
            item: &[3, 3],
        },
    ];
    map_items(py, &inputs, &[3], |x, out| {
        let s = State::with_attitude(x[0][..3].to_vec(), row_major9(x[1]));
        out.copy_from_slice(&core::RigidBody::spatial_momentum(&s)?);
        Ok(())
    })
}

/// A free rigid body (Euler top) on so(3)* (000 §3–§4).
///
/// State z = M, the body angular momentum (3,). Euler's equation dM/dt = M x Omega with
/// Omega = I^{-1} M; energy H = M . I^{-1} M / 2; Casimir [|M|^2]. Carries an attitude R
/// (dR/dt = R hat(Omega)) when `integrate(..., attitude=R0)` is given; R M is conserved.
/// Methods: splitting, splitting4, splitting6, isospectral, lgvi, rk4.
///
/// Args:
///     inertia: principal moments (3,) > 0, or a (3, 3) symmetric positive-definite matrix
///         (diagonalised once; states stay in the given body frame).
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError (non-positive or non-symmetric inertia).
#[pyclass(name = "RigidBody", module = "lieflow", extends = LiePoissonSystem, frozen)]
pub struct PyRigidBody {
    body: core::RigidBody,
}

#[pymethods]
impl PyRigidBody {
    #[new]
    #[pyo3(signature = (inertia))]
    fn new(inertia: ArrayIn<'_>) -> PyResult<PyClassInitializer<Self>> {
        let body = match self::inertia(&inertia)? {
            Inertia::Moments(m) => core::RigidBody::new(m),
            Inertia::Matrix(m) => core::RigidBody::from_matrix(&m),
        }
        .py()?;
        Ok(with_base(&body).add_subclass(PyRigidBody { body }))
    }

    /// The supported integration methods (the same for every rigid body).
    #[staticmethod]
    fn methods() -> PyResult<Vec<&'static str>> {
        Ok(method_names(core::RigidBody::new([1.0; 3]).py()?.methods()))
    }

    /// Names of the observables that take (states, attitude); `Trajectory` passes its attitude.
    #[classattr]
    fn _attitude_observables() -> (&'static str,) {
        ("spatial_momentum",)
    }

    /// The principal moments of inertia (3,).
    #[getter]
    fn moments<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        py_vec(py, &self.body.moments())
    }

    /// The principal frame Q in SO(3) (columns = principal axes, I = Q diag(moments) Q^T) when
    /// the inertia was given as a matrix, else None.
    #[getter]
    fn frame<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f64>>> {
        self.body.frame().map(|q| py_mat3(py, &q))
    }

    /// Body angular velocity Omega = I^{-1} M, vectorised: (..., 3) -> (..., 3).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn angular_velocity<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let inputs = [Input {
            what: "states",
            array: &states,
            item: &[3],
        }];
        map_items(py, &inputs, &[3], |m, out| {
            out.copy_from_slice(&self.body.angular_velocity(m[0])?);
            Ok(())
        })
    }

    /// Spatial angular momentum R M (000 Theorem 4.2), conserved; vectorised with numpy
    /// broadcasting: states (..., 3) and attitude (..., 3, 3) -> (..., 3).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn spatial_momentum<'py>(
        &self,
        py: Python<'py>,
        states: ArrayIn<'py>,
        attitude: ArrayIn<'py>,
    ) -> PyResult<Any<'py>> {
        spatial_momentum(py, &states, &attitude, 3)
    }

    /// The exact body momentum M(t) from M(0) = M0 by Jacobi elliptic functions (000 §4; the
    /// classical solution M1 = a1 cn u, M2 = a2 sn u, M3 = a3 dn u in suitably ordered principal
    /// axes, u = u0 + lambda t; see `lieflow::systems::RigidBody::exact_momentum`).
    ///
    /// Args:
    ///     M0: (3,) or (..., 3); t: a time or a 1-D array of times (k,).
    /// Returns:
    ///     (..., 3) for a scalar t, (..., k, 3) for an array of times.
    /// Raises:
    ///     InvalidArgumentError (M0 on the separatrix |M|^2 = 2 H I_mid, where the elliptic
    ///     modulus is 1), ShapeError, NonFiniteError.
    fn exact_solution<'py>(
        &self,
        py: Python<'py>,
        M0: ArrayIn<'py>,
        t: ArrayIn<'py>,
    ) -> PyResult<Any<'py>> {
        let tv = t.as_array();
        if tv.ndim() > 1 {
            return Err(to_py(Error::shape(
                "t",
                "a scalar or a 1-D array (k,)",
                shape_str(tv.shape()),
            )));
        }
        let times: Vec<f64> = tv.iter().copied().collect();
        let out_item: Vec<usize> = tv.shape().iter().copied().chain([3]).collect();
        let inputs = [Input {
            what: "M0",
            array: &M0,
            item: &[3],
        }];
        map_items(py, &inputs, &out_item, |m, out| {
            for (o, &ti) in out.chunks_exact_mut(3).zip(&times) {
                o.copy_from_slice(&self.body.exact_momentum(m[0], ti)?);
            }
            Ok(())
        })
    }

    /// Named views for `Trajectory`: {"M": (..., 3)}.
    fn _fields<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Bound<'py, PyDict>> {
        slices(py, &states, 3, &[("M", 0, 3)])
    }
}

/// The generalized rigid body on so(n)* (Euler–Arnold / Manakov equations; the form of the
/// pseudo-rigid body's reduced equation 001 (7.25)).
///
/// M = J Omega + Omega J with J the mass matrix; dM/dt = [M, Omega]; energy
/// H = sum_{i<j} M_ij^2 / (J_i + J_j) / 2 (principal frame); Casimirs C_k = tr((M^T M)^k) / 2,
/// k = 1 .. n // 2 (they fix the spectrum of M). State z = the e_ij coordinates of the skew
/// matrix M (i < j, row by row), length n(n-1)/2; `state(M)` and `matrix(z)` convert.
/// Methods: isospectral, rk4.
///
/// Args:
///     J: principal entries (n,) (n >= 2, J_i >= 0, J_i + J_j > 0), or a symmetric
///         positive-semidefinite (n, n) matrix (diagonalised once).
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError.
#[pyclass(name = "GeneralizedRigidBody", module = "lieflow", extends = LiePoissonSystem, frozen)]
pub struct PyGeneralizedRigidBody {
    body: core::GeneralizedRigidBody,
}

#[pymethods]
impl PyGeneralizedRigidBody {
    #[new]
    #[pyo3(signature = (J))]
    fn new(J: ArrayIn<'_>) -> PyResult<PyClassInitializer<Self>> {
        let v = J.as_array();
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
        Ok(with_base(&body).add_subclass(PyGeneralizedRigidBody { body }))
    }

    /// The supported integration methods (the same for every n).
    #[staticmethod]
    fn methods() -> PyResult<Vec<&'static str>> {
        Ok(method_names(
            core::GeneralizedRigidBody::new(&[1.0, 1.0]).py()?.methods(),
        ))
    }

    /// The dimension n (M is n x n).
    #[getter]
    fn n(&self) -> usize {
        self.body.n()
    }

    /// The principal entries J_i (n,).
    #[getter]
    fn moments<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        py_vec(py, self.body.principal())
    }

    /// Flat state z (e_ij coordinates, `lieflow.lie.vee_n`) of skew matrices: (..., n, n) ->
    /// (..., n(n-1)/2).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, NotInGroupError (M not skew-symmetric).
    fn state<'py>(&self, py: Python<'py>, M: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let n = self.body.n();
        let inputs = [Input {
            what: "M",
            array: &M,
            item: &[n, n],
        }];
        map_items(py, &inputs, &[so::dim(n)], |m, out| {
            let m = Mat::from_fn(n, n, |i, j| m[0][i * n + j]);
            out.copy_from_slice(&so::vee_n(&m)?);
            Ok(())
        })
    }

    /// The skew matrices M of flat states: (..., n(n-1)/2) -> (..., n, n).
    ///
    /// Raises:
    ///     ShapeError.
    fn matrix<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let n = self.body.n();
        let inputs = [Input {
            what: "states",
            array: &states,
            item: &[so::dim(n)],
        }];
        map_items(py, &inputs, &[n, n], |z, out| {
            let m = so::hat_n(z[0])?;
            for (k, o) in out.iter_mut().enumerate() {
                *o = m[(k / n, k % n)];
            }
            Ok(())
        })
    }

    /// Named views for `Trajectory`: {"M": (..., n, n)}.
    fn _fields<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        dict.set_item("M", self.matrix(py, states)?)?;
        Ok(dict)
    }
}

/// The heavy top (000 §5.2): a rigid body with a fixed point in uniform gravity.
///
/// State z = (M, Gamma) (6,): body angular momentum M and Gamma = R^T e3, the upward vertical
/// seen in the body. dM/dt = M x Omega + mgl Gamma x chi, dGamma/dt = Gamma x Omega,
/// Omega = I^{-1} M; energy H = M . I^{-1} M / 2 + mgl Gamma . chi; Casimirs [|Gamma|^2,
/// M . Gamma]; for the Lagrange top (I1 = I2, chi = e3) also M3 is conserved. With an attitude
/// R, Gamma must equal R^T e3 (use `state(M, attitude=R)`).
/// Methods: splitting, splitting4, splitting6, lgvi, rk4.
///
/// Args:
///     inertia: principal moments (3,) or a (3, 3) symmetric positive-definite matrix;
///     mgl: weight times distance of the centre of mass from the fixed point (>= 0);
///     chi: direction of the centre of mass in the body (normalised; default e3).
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError.
#[pyclass(name = "HeavyTop", module = "lieflow", extends = LiePoissonSystem, frozen)]
pub struct PyHeavyTop {
    top: core::HeavyTop,
}

#[pymethods]
impl PyHeavyTop {
    #[new]
    #[pyo3(
        signature = (inertia, mgl, chi = None),
        text_signature = "(inertia, mgl, chi=(0.0, 0.0, 1.0))"
    )]
    fn new(
        inertia: ArrayIn<'_>,
        mgl: f64,
        chi: Option<ArrayIn<'_>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let chi = match chi {
            Some(c) => convert::vec3("chi", &c)?.into(),
            None => [0.0, 0.0, 1.0],
        };
        let top = match self::inertia(&inertia)? {
            Inertia::Moments(m) => core::HeavyTop::new(m, mgl, chi),
            Inertia::Matrix(m) => core::HeavyTop::from_matrix(&m, mgl, chi),
        }
        .py()?;
        Ok(with_base(&top).add_subclass(PyHeavyTop { top }))
    }

    /// The supported integration methods (the same for every heavy top).
    #[staticmethod]
    fn methods() -> PyResult<Vec<&'static str>> {
        Ok(method_names(
            core::HeavyTop::new([1.0; 3], 1.0, [0.0, 0.0, 1.0])
                .py()?
                .methods(),
        ))
    }

    /// Names of the observables that take (states, attitude); `Trajectory` passes its attitude.
    #[classattr]
    fn _attitude_observables() -> (&'static str,) {
        ("spatial_momentum",)
    }

    /// The principal moments of inertia (3,).
    #[getter]
    fn moments<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        py_vec(py, &self.top.moments())
    }

    /// mgl (weight times the distance of the centre of mass from the fixed point).
    #[getter]
    fn mgl(&self) -> f64 {
        self.top.mgl()
    }

    /// The unit direction chi of the centre of mass (body frame).
    #[getter]
    fn chi<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        py_vec(py, &self.top.chi())
    }

    /// A flat state z = (M, Gamma) from M (..., 3) and either Gamma (..., 3) or the attitude R
    /// (..., 3, 3) (then Gamma = R^T e3, the third row of R); leading axes broadcast.
    ///
    /// Raises:
    ///     InvalidArgumentError (neither or both of Gamma and attitude), ShapeError.
    #[pyo3(signature = (M, Gamma = None, attitude = None))]
    fn state<'py>(
        &self,
        py: Python<'py>,
        M: ArrayIn<'py>,
        Gamma: Option<ArrayIn<'py>>,
        attitude: Option<ArrayIn<'py>>,
    ) -> PyResult<Any<'py>> {
        let m = Input {
            what: "M",
            array: &M,
            item: &[3],
        };
        match (&Gamma, &attitude) {
            (Some(g), None) => {
                let g = Input {
                    what: "Gamma",
                    array: g,
                    item: &[3],
                };
                map_items(py, &[m, g], &[6], |x, out| {
                    out[..3].copy_from_slice(x[0]);
                    out[3..].copy_from_slice(x[1]);
                    Ok(())
                })
            }
            (None, Some(r)) => {
                let r = Input {
                    what: "attitude",
                    array: r,
                    item: &[3, 3],
                };
                map_items(py, &[m, r], &[6], |x, out| {
                    let s = self.top.state_with_attitude(vec3(x[0]), row_major9(x[1]));
                    out.copy_from_slice(&s.z);
                    Ok(())
                })
            }
            _ => Err(to_py(Error::invalid(
                "state",
                "give exactly one of Gamma and attitude",
            ))),
        }
    }

    /// Parses an initial state: z (6,) or (b, 6), or a pair (M, Gamma) of (3,) or (b, 3) arrays.
    ///
    /// Returns:
    ///     (z0 (b, 6), batched).
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn _normalize_state<'py>(
        &self,
        py: Python<'py>,
        state0: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, bool)> {
        if let Ok(pair) = state0.cast::<PyTuple>() {
            if pair.len() == 2 {
                let m: ArrayIn<'py> = pair.get_item(0)?.extract()?;
                let g: ArrayIn<'py> = pair.get_item(1)?.extract()?;
                // A pair of 3-vectors (or batches of them); two 6-vectors are a batch of states.
                let last3 = |a: &ArrayIn<'py>| a.as_array().shape().last() == Some(&3);
                if last3(&m) || last3(&g) {
                    let z: ArrayIn<'py> = self.state(py, m, Some(g), None)?.extract()?;
                    return normalize_flat(py, 6, &z.as_array());
                }
            }
        }
        let z: ArrayIn<'py> = state0.extract()?;
        normalize_flat(py, 6, &z.as_array())
    }

    /// Spatial angular momentum R M, vectorised with broadcasting: states (..., 6) and
    /// attitude (..., 3, 3) -> (..., 3). Only its vertical component M . Gamma is conserved.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn spatial_momentum<'py>(
        &self,
        py: Python<'py>,
        states: ArrayIn<'py>,
        attitude: ArrayIn<'py>,
    ) -> PyResult<Any<'py>> {
        spatial_momentum(py, &states, &attitude, 6)
    }

    /// Named views for `Trajectory`: {"M": (..., 3), "Gamma": (..., 3)}.
    fn _fields<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Bound<'py, PyDict>> {
        slices(py, &states, 6, &[("M", 0, 3), ("Gamma", 3, 3)])
    }
}

/// The spherical pendulum (000 §5.1) as a Lie–Poisson system on se(3)*.
///
/// State z = (q, L) (6,): q the unit vector from the pivot to the bob (e3 up) and
/// L = m l^2 q x dq/dt the angular momentum about the pivot. dq/dt = L x q / (m l^2),
/// dL/dt = m g l e3 x q; energy H = |L|^2 / (2 m l^2) + m g l q3; Casimirs [|q|^2, q . L]
/// (a state needs |q| = 1 and q . L = 0); the vertical momentum L3 is conserved.
/// Methods: splitting, splitting4, splitting6, rk4.
///
/// Args:
///     mass > 0, length > 0, g >= 0.
/// Raises:
///     InvalidArgumentError.
#[pyclass(name = "SphericalPendulum", module = "lieflow", extends = LiePoissonSystem, frozen)]
pub struct PySphericalPendulum {
    pendulum: core::SphericalPendulum,
    mass: f64,
    length: f64,
    g: f64,
}

#[pymethods]
impl PySphericalPendulum {
    #[new]
    #[pyo3(signature = (mass = 1.0, length = 1.0, g = 9.81))]
    fn new(mass: f64, length: f64, g: f64) -> PyResult<PyClassInitializer<Self>> {
        let pendulum = core::SphericalPendulum::new(mass, length, g).py()?;
        Ok(with_base(&pendulum).add_subclass(PySphericalPendulum {
            pendulum,
            mass,
            length,
            g,
        }))
    }

    /// The supported integration methods.
    #[staticmethod]
    fn methods() -> PyResult<Vec<&'static str>> {
        Ok(method_names(
            core::SphericalPendulum::new(1.0, 1.0, 1.0).py()?.methods(),
        ))
    }

    /// The mass of the bob.
    #[getter]
    fn mass(&self) -> f64 {
        self.mass
    }

    /// The length of the rod.
    #[getter]
    fn length(&self) -> f64 {
        self.length
    }

    /// The gravitational acceleration.
    #[getter]
    fn g(&self) -> f64 {
        self.g
    }

    /// The state (q, L) from the spherical coordinates of 000 §5.1.1 (theta from the downward
    /// vertical): q = (sin th cos ph, sin th sin ph, -cos th), L = m l^2 q x dq/dt. The four
    /// arguments broadcast like numpy arrays; the result has shape (..., 6).
    ///
    /// Raises:
    ///     ShapeError (shapes that do not broadcast), NonFiniteError.
    #[pyo3(signature = (theta, phi, theta_dot = None, phi_dot = None))]
    fn state_from_spherical<'py>(
        &self,
        py: Python<'py>,
        theta: ArrayIn<'py>,
        phi: ArrayIn<'py>,
        theta_dot: Option<ArrayIn<'py>>,
        phi_dot: Option<ArrayIn<'py>>,
    ) -> PyResult<Any<'py>> {
        let zero = || -> PyResult<ArrayIn<'py>> { 0.0f64.into_pyobject(py)?.extract() };
        let theta_dot = theta_dot.map_or_else(zero, Ok)?;
        let phi_dot = phi_dot.map_or_else(zero, Ok)?;
        let inputs = [
            Input {
                what: "theta",
                array: &theta,
                item: &[],
            },
            Input {
                what: "phi",
                array: &phi,
                item: &[],
            },
            Input {
                what: "theta_dot",
                array: &theta_dot,
                item: &[],
            },
            Input {
                what: "phi_dot",
                array: &phi_dot,
                item: &[],
            },
        ];
        map_items(py, &inputs, &[6], |x, out| {
            let s = self
                .pendulum
                .state_from_spherical(x[0][0], x[1][0], x[2][0], x[3][0])?;
            out.copy_from_slice(&s.z);
            Ok(())
        })
    }

    /// The vertical angular momentum L3 (conserved), vectorised: (..., 6) -> (...).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn vertical_momentum<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let inputs = [Input {
            what: "states",
            array: &states,
            item: &[6],
        }];
        map_items(py, &inputs, &[], |z, out| {
            out[0] = self.pendulum.vertical_momentum(z[0])?;
            Ok(())
        })
    }

    /// Named views for `Trajectory`: {"q": (..., 3), "L": (..., 3)}.
    fn _fields<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Bound<'py, PyDict>> {
        slices(py, &states, 6, &[("q", 0, 3), ("L", 3, 3)])
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyRigidBody>()?;
    m.add_class::<PyGeneralizedRigidBody>()?;
    m.add_class::<PyHeavyTop>()?;
    m.add_class::<PySphericalPendulum>()?;
    Ok(())
}
