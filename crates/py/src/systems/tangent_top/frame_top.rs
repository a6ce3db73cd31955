//! `FrameTop`: binding of `lieflow::systems::tangent_top::frame_top` (002 §V), a thin subclass of
//! `lieflow.System`.
#![allow(non_snake_case)]

use lieflow::systems::{FrameTop, RiemannianFrameTop, SpaceTop};
use lieflow::Error;
use nalgebra::{Matrix3, Vector3};
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use super::space_form::{Kind, PySpace};
use crate::convert::{mat, real, vector, ArrayIn};
use crate::errors::{checked, to_py, IntoPy};
use crate::system::{PySystem, Thin};

type Any<'py> = Bound<'py, PyAny>;

/// The inertia tensor from (3,) principal moments or a (3, 3) symmetric matrix, row-major.
fn inertia_tensor(ob: &Any<'_>) -> PyResult<[f64; 9]> {
    let a = ArrayIn::named("inertia", ob)?;
    let v = a.as_array();
    match v.shape() {
        [3] => {
            let d = vector("inertia", &a)?;
            Ok([d[0], 0.0, 0.0, 0.0, d[1], 0.0, 0.0, 0.0, d[2]])
        }
        [3, 3] => {
            let m = mat("inertia", &a)?;
            Ok(std::array::from_fn(|k| m[(k / 3, k % 3)]))
        }
        s => Err(to_py(Error::shape(
            "inertia",
            "(3,) principal moments or a (3, 3) inertia tensor",
            format!("{s:?}"),
        ))),
    }
}

/// The tangent Euler top on a three-dimensional space form (002 §V): a rigid body whose centre x
/// moves on `space` (`lieflow.spaces.Euclidean(3)`, `Sphere(3, radius)`, `Hyperbolic(3, radius)`)
/// and whose axes are an orthonormal frame tangent there;
/// :math:`L = \tfrac12 m\, g(\dot x, \dot x) + \tfrac12 \omega \cdot \mathbb{I}\omega` with
/// :math:`\omega` the angular velocity relative to parallel transport.
///
/// The configuration space is the frame bundle, which is the isometry group G (SE(3), SO(4),
/// :math:`SO^+(1,3)`): the columns of :math:`g` are :math:`x/r, e_1, e_2, e_3`
/// (:math:`g = \begin{pmatrix} 1 & 0 \\ x & R \end{pmatrix}` on :math:`\mathbb{R}^3`), and the top
/// is a left-invariant Lie–Poisson system on G with body momenta :math:`\Pi = \mathbb{I}\omega`,
/// :math:`P = m v` (v the body velocity): :math:`\dot\Pi = \Pi \times \omega` (the free Euler
/// top), :math:`\dot P = P \times \omega + (\kappa/m)\, \Pi \times P` (:math:`\kappa` the
/// curvature), :math:`\dot g = g\xi`. Integrals: :math:`H`, :math:`T = P \cdot P/(2m)` and
/// :math:`H - T`, the Casimirs :math:`\Pi \cdot P` and :math:`P \cdot P + \kappa\, \Pi \cdot \Pi`,
/// the six Killing momenta (`killing_momenta`).
///
/// Args:
///     space: a `lieflow.spaces` space.
///     mass: m > 0.
///     inertia: the body's inertia tensor, (3,) principal moments or (3, 3) symmetric positive
///         definite (for a mass distribution with Euler tensor E,
///         :math:`\mathbb{I} = \operatorname{tr}(E)\, \mathrm{Id} - E`).
///
/// Methods: exact (default), splitting, splitting4, splitting6, rk4. `exact` is the exact flow:
/// T commutes with the rotational energy, whose flow is the free rigid body's (elliptic
/// functions), and T's flow is a one-parameter subgroup followed by a turn of the frame. The
/// splittings split the rotational energy into the three axis rotations (orders 2, 4, 6); all of
/// these keep the Casimirs, T and the Killing momenta to round-off. rk4 integrates the field,
/// as a baseline. States are flat: (g row-major (16), Pi (3), P (3)); make them with
/// `top.state(x, R, xdot, omega)`. Invariants: :math:`\Pi \cdot P`,
/// :math:`P \cdot P + \kappa\, \Pi \cdot \Pi`, :math:`T`, then the six Killing momenta.
///
/// On a chart (`lieflow.spaces.Riemannian(metric, frame)`) the top is minimally coupled to the
/// frame's connection C: the spin still obeys the free Euler equations exactly, and the centre
/// moves by Wong's equations of the spatial spin :math:`\sigma = R\Pi` in C (the curvature force of
/// 002 (122), orthogonal to xdot, so T is conserved). States (x, p, R row-major, Pi), 18 values.
/// Methods: midpoint (default), midpoint4, midpoint6 (the Lie midpoint rule and its compositions),
/// rkmk4, rk4; all but rk4 move the spin by its exact flow, so :math:`H - T` and
/// :math:`\Pi \cdot \Pi` are kept to round-off, R stays a rotation and H oscillates without
/// drift. Invariants: :math:`H - T`, :math:`\Pi \cdot \Pi`. No Killing momenta.
#[pyclass(name = "FrameTop", module = "lieflow", extends = PySystem, frozen)]
pub struct PyFrameTop {
    space: Py<PySpace>,
}

/// The core top, on a space form or on a chart.
fn top<'a>(slf: &'a Bound<'_, PyFrameTop>) -> PyResult<&'a dyn SpaceTop> {
    match slf.core::<FrameTop>() {
        Ok(t) => Ok(t),
        Err(_) => Ok(slf.core::<RiemannianFrameTop>()?),
    }
}

/// The top on a space form, or an InvalidArgumentError naming `what` on a chart.
fn form_top<'a>(slf: &'a Bound<'_, PyFrameTop>, what: &str) -> PyResult<&'a FrameTop> {
    slf.core::<FrameTop>().map_err(|_| {
        to_py(Error::invalid(
            what,
            format!(
                "{what} needs the isometries of a space form (Euclidean, Sphere, Hyperbolic); no \
                 Killing fields are known for a Riemannian chart"
            ),
        ))
    })
}

#[pymethods]
impl PyFrameTop {
    #[new]
    fn new(
        py: Python<'_>,
        space: Bound<'_, PySpace>,
        #[pyo3(from_py_with = real)] mass: f64,
        inertia: Bound<'_, PyAny>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let tensor = inertia_tensor(&inertia)?;
        let args = (space.clone(), mass, inertia).into_pyobject(py)?;
        let this = PyFrameTop {
            space: space.clone().unbind(),
        };
        let names = &["space", "mass", "inertia"];
        Ok(match &space.get().inner {
            Kind::Form(form) => {
                PySystem::init(this, FrameTop::new(*form, mass, &tensor).py()?, args, names)
            }
            Kind::Chart { chart, .. } => PySystem::init(
                this,
                RiemannianFrameTop::new(chart.clone(), mass, &tensor).py()?,
                args,
                names,
            ),
        })
    }

    /// The space form.
    #[getter]
    fn space(&self, py: Python<'_>) -> Py<PySpace> {
        self.space.clone_ref(py)
    }

    /// The mass m.
    #[getter]
    fn mass(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Ok(top(slf)?.body().mass())
    }

    /// The inertia tensor, (3, 3).
    #[getter]
    fn inertia<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
        let i = top(slf)?.body().inertia();
        let rows: Vec<Vec<f64>> = (0..3)
            .map(|r| (0..3).map(|c| i[(r, c)]).collect())
            .collect();
        numpy::PyArray2::from_vec2(slf.py(), &rows)
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
    }

    /// The flat state of the body at the point x with frame :math:`\hat E(x) R`
    /// (:math:`\hat E` = `space.reference_frame`),
    /// velocity xdot (ambient components, tangent at x) and angular velocity omega relative to
    /// parallel transport (body frame).
    ///
    /// Args:
    ///     x: (3,) on R^3, (4,) on the sphere and the hyperboloid; R: (3, 3) rotation;
    ///     xdot: like x; omega: (3,).
    /// Returns:
    ///     (22,) state (g row-major, Pi, P) on a space form; (18,) state (x, p, R row-major,
    ///     Pi) on a Riemannian chart, :math:`p = m g \dot x + C^\top R \Pi` the canonical momentum.
    /// Raises:
    ///     ShapeError, NonFiniteError, InvalidArgumentError (x not on the space, xdot not tangent),
    ///     NotInGroupError (R not a rotation), the exception of a callable.
    fn state<'py>(
        slf: &Bound<'py, Self>,
        x: ArrayIn<'_>,
        R: ArrayIn<'_>,
        xdot: ArrayIn<'_>,
        omega: ArrayIn<'_>,
    ) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
        let r = mat("R", &R)?;
        if r.nrows() != 3 || r.ncols() != 3 {
            return Err(to_py(Error::shape(
                "R",
                "(3, 3)",
                format!("({}, {})", r.nrows(), r.ncols()),
            )));
        }
        let r = Matrix3::from_fn(|i, j| r[(i, j)]);
        let w = vector("omega", &omega)?;
        if w.len() != 3 {
            return Err(to_py(Error::shape(
                "omega",
                "(3,)",
                format!("({},)", w.len()),
            )));
        }
        let (x, xd) = (vector("x", &x)?, vector("xdot", &xdot)?);
        let t = top(slf)?;
        let z = checked(|| t.state(&x, &r, &xd, &Vector3::from_column_slice(&w)))?;
        Ok(numpy::PyArray1::from_vec(slf.py(), z))
    }

    /// The centre's point x of states (..., 22) -> (..., d).
    fn position<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let t = top(slf)?;
        let d = t.point_dim();
        slf.base().map_states(slf.py(), &states, &[d], |z, out| {
            out.copy_from_slice(&t.position(z)?);
            Ok(())
        })
    }

    /// The body frame R relative to the reference frame :math:`\hat E(x)`: (..., 22) -> (..., 3,
    /// 3).
    fn frame<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let t = top(slf)?;
        slf.base().map_states(slf.py(), &states, &[3, 3], |z, out| {
            let r = t.frame(z)?;
            for (k, o) in out.iter_mut().enumerate() {
                *o = r[(k / 3, k % 3)];
            }
            Ok(())
        })
    }

    /// The velocity xdot (ambient components): (..., 22) -> (..., d).
    fn velocity<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let t = top(slf)?;
        let d = t.point_dim();
        slf.base().map_states(slf.py(), &states, &[d], |z, out| {
            out.copy_from_slice(&t.velocity(z)?);
            Ok(())
        })
    }

    /// The angular velocity :math:`\omega = \mathbb{I}^{-1} \Pi` relative to parallel transport
    /// (body frame): (..., 22) -> (..., 3).
    fn angular_velocity<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let t = top(slf)?;
        slf.base().map_states(slf.py(), &states, &[3], |z, out| {
            out.copy_from_slice(t.angular_velocity(z)?.as_slice());
            Ok(())
        })
    }

    /// The six Killing momenta :math:`(J_\Pi, J_P)`, the spatial momentum
    /// :math:`\operatorname{Ad}^*_{g^{-1}}(\Pi, P)`: on the sphere and the hyperboloid the momenta
    /// of the rotations about, and the translations (boosts) along, the axes at the base point,
    /// :math:`K = \begin{pmatrix} 0 & -r J_P^\top \\ r J_P & \hat J_\Pi \end{pmatrix}
    /// = m (\dot x x^\top - x \dot x^\top) + e \hat\Pi e^\top`; on :math:`\mathbb{R}^3` the angular
    /// momentum about the origin :math:`x \times m\dot x + R\Pi`, then the momentum
    /// :math:`m\dot x`. (..., 22) -> (..., 6).
    fn killing_momenta<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let t = form_top(slf, "killing_momenta")?;
        slf.base().map_states(slf.py(), &states, &[6], |z, out| {
            out.copy_from_slice(&t.killing_momenta(z)?);
            Ok(())
        })
    }

    /// On the 3-sphere: the so(4) body momentum
    /// :math:`M = \begin{pmatrix} 0 & -r P^\top \\ r P & \hat\Pi \end{pmatrix}` of the frame
    /// :math:`g \in SO(4)` whose first column is :math:`x/r`, with :math:`\dot M = [M, \xi]` for
    /// :math:`\xi = g^{-1} \dot g` and the pairing
    /// :math:`\langle M, \xi \rangle = \tfrac12 \operatorname{tr}(M^\top \xi)`; the top is
    /// `lf.LiePoisson(("so", 4), H)` with :math:`H(M) = \tfrac12 \langle M, J^{-1} M \rangle`,
    /// J = `group_inertia()`. (..., 22) -> (..., 4, 4).
    ///
    /// Raises:
    ///     InvalidArgumentError (not on the sphere).
    fn group_momentum<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let t = form_top(slf, "group_momentum")?;
        t.group_inertia().py()?;
        slf.base().map_states(slf.py(), &states, &[4, 4], |z, out| {
            let m = t.group_momentum(z)?;
            for (k, o) in out.iter_mut().enumerate() {
                *o = m[(k / 4, k % 4)];
            }
            Ok(())
        })
    }

    /// On the 3-sphere: the (6, 6) inertia J of the SO(4) top in so(4)'s :math:`e_{ij}`
    /// coordinates (01, 02, 03, 12, 13, 23): :math:`\operatorname{diag}(m r^2, m r^2, m r^2)` and
    /// the inertia tensor read through
    /// :math:`(\xi_{12}, \xi_{13}, \xi_{23}) = (-\Omega_3, \Omega_2, -\Omega_1)`;
    /// :math:`l(\xi) = \tfrac12 \langle \xi, J\xi \rangle`, :math:`M = J\xi`.
    ///
    /// Raises:
    ///     InvalidArgumentError (not on the sphere).
    fn group_inertia<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
        let j = form_top(slf, "group_inertia")?.group_inertia().py()?;
        let rows: Vec<Vec<f64>> = (0..6).map(|r| j[6 * r..6 * r + 6].to_vec()).collect();
        numpy::PyArray2::from_vec2(slf.py(), &rows)
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
    }

    /// :math:`T = P \cdot P / (2m)`, the translational energy (conserved): (..., 22) -> (...).
    fn translational_energy<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Any<'py>> {
        let t = top(slf)?;
        slf.base().map_states(slf.py(), &states, &[], |z, out| {
            out[0] = t.translational_energy(z)?;
            Ok(())
        })
    }

    /// :math:`H - T = \tfrac12 \Pi \cdot \mathbb{I}^{-1} \Pi`, the rotational energy (conserved;
    /// 002 §V's "H - T"): (..., 22) -> (...).
    fn rotational_energy<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let t = top(slf)?;
        slf.base().map_states(slf.py(), &states, &[], |z, out| {
            out[0] = t.rotational_energy(z)?;
            Ok(())
        })
    }
}
