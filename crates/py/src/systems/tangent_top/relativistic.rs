//! `RelativisticTangentTop`, `WeakFieldTop` and `StaticFieldTop` (flat or over a surface): bindings of `lieflow::systems::tangent_top::relativistic`
//! (002 §IV). Thin subclasses of `lieflow.System`.

use lieflow::systems::tangent_top::relativistic as core;
use lieflow::Error;
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use super::surface::PySurface;
use crate::convert::ArrayIn;
use crate::convert::{real, real_opt, reals, reals_opt, shape_str, Real};
use crate::errors::{to_py, IntoPy};
use crate::items::{map_items, par_map_items, Input};
use crate::system::{PySystem, Thin};

/// The relativistic tangent Euler top in 1+2 Minkowski space-time (002 (87)–(96); physical sign of
/// the Lagrangian,
/// :math:`L = -m/\gamma + \tfrac12 \dot\theta^2 (I\gamma + \gamma^3 \dot x^\top K(\theta) \dot x)`),
/// or, with `surface`, the top on the static space-time :math:`-dt^2 + g` over that surface
/// (002 (97)–(103)): :math:`L = -m/\gamma + \tfrac12 s^2 (I\gamma + \gamma^3 u^\top K(\theta) u)`,
/// :math:`v^2 = g(\dot x, \dot x)`, :math:`s = \dot\theta + w(\dot x)` with :math:`w` the surface's
/// connection 1-form, :math:`u` the components of :math:`\dot x` in the surface's orthonormal frame
/// (for the symmetric top :math:`L = -m/\gamma + \tfrac12 I s^2 (\gamma + \gamma^3 v^2 / 2)`).
/// State (x1, x2, theta, p1, p2, p_theta) in the chart; fields x, theta, p, p_theta; speeds
/// :math:`v < 1`. Invariants: (p_x, p_y) and, for the symmetric top, p_theta (Minkowski); p_theta
/// (symmetric top) and the Killing momenta of the affine isometries (surface). Methods: gauss4
/// (default), gauss6, midpoint, rk4.
///
/// Args:
///     mass > 0; inertia: the scalar :math:`\operatorname{tr} I` (the symmetric top) or the
///         second-moment tensor :math:`\int \xi \xi^\top dm` as (I11, I12, I22) or a symmetric
///         (2, 2) array, positive semidefinite; surface: a `lieflow.surfaces` surface, or None for the
///         Minkowski plane.
/// Raises:
///     InvalidArgumentError, ShapeError, NonFiniteError, TypeError (surface not a lieflow
///     surface).
#[pyclass(name = "RelativisticTangentTop", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyRelativisticTangentTop;

#[pymethods]
impl PyRelativisticTangentTop {
    #[new]
    #[pyo3(signature = (mass, inertia, surface = None))]
    fn new(
        #[pyo3(from_py_with = real)] mass: f64,
        inertia: &Bound<'_, PyAny>,
        surface: Option<Bound<'_, PySurface>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let surf = surface.as_ref().map(|s| s.get().inner.clone());
        let top = match (moments(inertia)?, surf) {
            (Inertia::Trace(i), None) => core::RelativisticTangentTop::symmetric(mass, i),
            (Inertia::Trace(i), Some(s)) => core::RelativisticTangentTop::on_surface(s, mass, i),
            (Inertia::Moments(m), None) => core::RelativisticTangentTop::new(mass, m),
            (Inertia::Moments(m), Some(s)) => {
                core::RelativisticTangentTop::on_surface_with_moments(s, mass, m)
            }
        }
        .py()?;
        let args = (mass, inertia, surface).into_pyobject(inertia.py())?;
        Ok(PySystem::subclass(
            top,
            args,
            &["mass", "inertia", "surface"],
        ))
    }

    /// The Lagrangian of 002 (90) / (102) (physical sign, the negative of the text's):
    /// :math:`L = -m/\gamma + \tfrac12 s^2 (I\gamma + \gamma^3 u^\top K(\theta) u)` with
    /// :math:`s = \dot\theta + w(\dot x)`, :math:`u` the components of :math:`\dot x` in the
    /// surface's orthonormal frame (Cartesian in the Minkowski plane),
    /// :math:`\gamma = (1 - g(\dot x, \dot x))^{-1/2}`.
    ///
    /// Args:
    ///     x: (2,) in the chart; theta; xdot: (2,); thetadot.
    /// Returns:
    ///     float.
    /// Raises:
    ///     InvalidArgumentError (v >= 1, x outside the chart), NonFiniteError.
    fn lagrangian(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
        #[pyo3(from_py_with = real)] theta: f64,
        #[pyo3(from_py_with = reals::<2>)] xdot: [f64; 2],
        #[pyo3(from_py_with = real)] thetadot: f64,
    ) -> PyResult<f64> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        crate::errors::checked(|| top.lagrangian([x[0], x[1], theta], [xdot[0], xdot[1], thetadot]))
    }

    /// :math:`F(\theta)` of the spin about a centre in straight uniform motion with velocity
    /// :math:`u`, 002 (91): with :math:`\dot x = u` held fixed,
    /// :math:`L = -m/\gamma + \tfrac12 F(\theta) \dot\theta^2`,
    /// :math:`F = I\gamma + \gamma^3 u^\top K(\theta) u` (period :math:`\pi` in :math:`\theta`).
    /// The text's (91) prints the cross term as :math:`-2 I_3 \sin\theta \cos\theta`; with
    /// :math:`I_{12} = \int \xi_1 \xi_2\, dm` it is :math:`+2 I_{12} \sin\theta \cos\theta`. Maps
    /// over the broadcast leading axes of theta and velocity.
    ///
    /// Args:
    ///     theta: angle(s) of the body from the x axis; velocity: (..., 2), speed < 1.
    /// Returns:
    ///     float, or an array of the broadcast shape.
    /// Raises:
    ///     InvalidArgumentError (speed >= 1), NonFiniteError, ShapeError.
    fn prescribed_inertia<'py>(
        slf: &Bound<'py, Self>,
        theta: ArrayIn<'py>,
        velocity: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        let inputs = [
            Input::finite("theta", &theta, &[]),
            Input::finite("velocity", &velocity, &[2]),
        ];
        par_map_items(slf.py(), &inputs, &[], |x, out| {
            out[0] = top.prescribed_inertia(x[0][0], [x[1][0], x[1][1]])?;
            Ok(())
        })
    }

    /// The spin rate :math:`|\dot\theta| = \sqrt{2E / F(\theta)}` about a centre in straight
    /// uniform motion with velocity :math:`u`, at spin energy
    /// :math:`E = \tfrac12 F(\theta) \dot\theta^2` (conserved), 002 (92) (the text's
    /// :math:`\dot\theta^2 = E/F` with its F half of this one). Fastest with the
    /// body's larger second moment along u, slowest across it. Maps over the broadcast leading
    /// axes.
    ///
    /// Args:
    ///     theta: angle(s); energy: E >= 0; velocity: (..., 2), speed < 1.
    /// Returns:
    ///     float, or an array of the broadcast shape.
    /// Raises:
    ///     InvalidArgumentError (speed >= 1, E < 0), NonFiniteError, ShapeError.
    fn prescribed_spin_rate<'py>(
        slf: &Bound<'py, Self>,
        theta: ArrayIn<'py>,
        energy: ArrayIn<'py>,
        velocity: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        prescribed(slf.py(), [&theta, &energy, &velocity], |th, e, u| {
            top.prescribed_spin_rate(th, e, u)
        })
    }

    /// The effective potential :math:`V(\theta) = -E / F(\theta)` of the spin about a centre in
    /// straight uniform motion with velocity :math:`u`, at spin energy E:
    /// :math:`\tfrac12 \dot\theta^2 + V = 0` and :math:`\ddot\theta = -V'(\theta)` (002 (92) calls
    /// :math:`E/F`, which is :math:`\dot\theta^2`, the effective potential). Maps over the
    /// broadcast leading axes.
    ///
    /// Args:
    ///     theta: angle(s); energy: E >= 0; velocity: (..., 2), speed < 1.
    /// Returns:
    ///     float, or an array of the broadcast shape.
    /// Raises:
    ///     InvalidArgumentError (speed >= 1, E < 0), NonFiniteError, ShapeError.
    fn prescribed_potential<'py>(
        slf: &Bound<'py, Self>,
        theta: ArrayIn<'py>,
        energy: ArrayIn<'py>,
        velocity: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        prescribed(slf.py(), [&theta, &energy, &velocity], |th, e, u| {
            top.prescribed_potential(th, e, u)
        })
    }

    /// The canonical state from the position x (2,), the angle theta and the velocities.
    ///
    /// Raises:
    ///     InvalidArgumentError (v >= 1, x outside the surface's chart, a Legendre map not
    ///     invertible), NonFiniteError.
    fn state(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
        #[pyo3(from_py_with = real)] theta: f64,
        #[pyo3(from_py_with = reals::<2>)] xdot: [f64; 2],
        #[pyo3(from_py_with = real)] thetadot: f64,
    ) -> PyResult<Vec<f64>> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        crate::errors::checked(|| top.state(x, theta, xdot, thetadot))
    }

    /// The velocities (xdot, ydot, thetadot) of states, vectorised: (..., 6) -> (..., 3).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, InvalidArgumentError.
    fn velocities<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        slf.base().map_states(slf.py(), &states, &[3], |z, out| {
            out.copy_from_slice(&top.velocities(z)?);
            Ok(())
        })
    }

    /// The speed :math:`v = \sqrt{g(\dot x, \dot x)}` and the covariant spin rate
    /// :math:`s = \dot\theta + w(\dot x)` of
    /// states (both constant along a motion of the symmetric top), vectorised:
    /// (..., 6) -> (..., 2).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, InvalidArgumentError.
    fn speed_and_spin<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        slf.base().map_states(slf.py(), &states, &[2], |z, out| {
            let (v, s) = top.speed_and_spin(z)?;
            out.copy_from_slice(&[v, s]);
            Ok(())
        })
    }

    /// The momentum of the symmetric top as a function of its speed v and spin momentum
    /// :math:`J = p_\theta`, 002 (94) (physical sign, :math:`J = p_\theta`; the text's J is half
    /// of it): :math:`|p| = m\gamma v\, (1 + J^2 (1 - v^2)(4 - v^2) / (2 I_0 m (2 - v^2)^2))` with
    /// :math:`\gamma = (1 - v^2)^{-1/2}`, :math:`I_0 = \tfrac12 \operatorname{tr} I`; on a surface
    /// :math:`|p|` is the norm of :math:`p_x - p_\theta \alpha` in the inverse metric. The text
    /// concludes that :math:`|p|` fixes v; it does not for :math:`J^2 / (2 I_0 m) > 7.34`, where
    /// :math:`v \mapsto |p|` decreases on an interval.
    /// Maps over the broadcast leading axes of v and p_theta.
    ///
    /// Args:
    ///     v: speed(s), 0 <= v < 1; p_theta: the spin momentum J.
    /// Returns:
    ///     float, or an array of the broadcast shape.
    /// Raises:
    ///     InvalidArgumentError (v outside [0, 1), an anisotropic top), NonFiniteError, ShapeError.
    fn momentum_94<'py>(
        slf: &Bound<'py, Self>,
        v: ArrayIn<'py>,
        p_theta: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        relation(slf.py(), ("v", &v), ("p_theta", &p_theta), |v, j| {
            top.momentum_94(v, j)
        })
    }

    /// The spin rate of the symmetric top from its speed v and spin momentum
    /// :math:`J = p_\theta`, 002 (95):
    /// :math:`\dot\theta = J / (2 I_0 \gamma (1 + v^2 \gamma^2 / 2))`,
    /// :math:`I_0 = \tfrac12 \operatorname{tr} I`; on a surface the covariant spin rate
    /// :math:`s = \dot\theta + w(\dot x)`. Maps over the broadcast
    /// leading axes of v and p_theta.
    ///
    /// Args:
    ///     v: speed(s), 0 <= v < 1; p_theta: the spin momentum J.
    /// Returns:
    ///     float, or an array of the broadcast shape.
    /// Raises:
    ///     InvalidArgumentError (v outside [0, 1), an anisotropic top), NonFiniteError, ShapeError.
    fn spin_rate_95<'py>(
        slf: &Bound<'py, Self>,
        v: ArrayIn<'py>,
        p_theta: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        relation(slf.py(), ("v", &v), ("p_theta", &p_theta), |v, j| {
            top.spin_rate_95(v, j)
        })
    }

    /// The energy of the symmetric top from its speed v and spin rate thetadot, 002 (96) (physical
    /// sign):
    /// :math:`E = m\gamma + I_0 \dot\theta^2 (\gamma + \tfrac52 v^2 \gamma^3 + \tfrac32 v^4 \gamma^5)`,
    /// :math:`I_0 = \tfrac12 \operatorname{tr} I`; on a surface with thetadot the covariant spin
    /// rate :math:`s = \dot\theta + w(\dot x)`. Maps over the broadcast leading axes of v and
    /// thetadot.
    ///
    /// Args:
    ///     v: speed(s), 0 <= v < 1; thetadot: spin rate(s).
    /// Returns:
    ///     float, or an array of the broadcast shape.
    /// Raises:
    ///     InvalidArgumentError (v outside [0, 1), an anisotropic top), NonFiniteError, ShapeError.
    fn energy_96<'py>(
        slf: &Bound<'py, Self>,
        v: ArrayIn<'py>,
        thetadot: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        relation(slf.py(), ("v", &v), ("thetadot", &thetadot), |v, w| {
            top.energy_96(v, w)
        })
    }

    /// All Killing momenta :math:`J = p_A X^A` of the surface's isometry group (the Minkowski plane
    /// and Plane: translations x, y and the rotation; Sphere: the ambient angular momentum x, y, z;
    /// HyperbolicPlane: the Möbius generators E, H, F; Revolution: p_phi), (..., 6) -> (..., k).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, InvalidArgumentError (x outside the chart).
    fn killing_momenta<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::RelativisticTangentTop>()?;
        let k = top.surface().killing_count();
        slf.base().map_states(slf.py(), &states, &[k], |z, out| {
            out.copy_from_slice(&top.killing_momenta(z)?);
            Ok(())
        })
    }
}

/// The inertia argument: the scalar tr I (the symmetric top) or the second-moment tensor.
enum Inertia {
    Trace(f64),
    Moments([f64; 3]),
}

/// The inertia from a number (tr I), (3,) (I11, I12, I22) or a symmetric (2, 2) tensor.
fn moments(inertia: &Bound<'_, PyAny>) -> PyResult<Inertia> {
    if let Ok(Real(i)) = inertia.extract::<Real>() {
        return Ok(Inertia::Trace(i));
    }
    let a = ArrayIn::named("inertia", inertia)?;
    let v = a.as_array();
    match v.shape() {
        [3] => Ok(Inertia::Moments([v[[0]], v[[1]], v[[2]]])),
        [2, 2] => {
            let m = [v[[0, 0]], v[[0, 1]], v[[1, 0]], v[[1, 1]]];
            lieflow::check::finite_slice("inertia", &m).map_err(to_py)?;
            let scale = m[0].abs() + m[3].abs();
            if (m[1] - m[2]).abs() > 1e-12 * scale {
                return Err(to_py(Error::invalid(
                    "inertia",
                    format!("expected a symmetric (2, 2) second-moment tensor, got {m:?}"),
                )));
            }
            Ok(Inertia::Moments([m[0], 0.5 * (m[1] + m[2]), m[3]]))
        }
        shape => Err(to_py(Error::shape(
            "inertia",
            "a number (tr I), (3,) (I11, I12, I22) or (2, 2)",
            shape_str(shape),
        ))),
    }
}

/// `f(theta, energy, velocity)` over the broadcast leading axes (the prescribed-motion
/// functions of 002 (92)).
fn prescribed<'py>(
    py: Python<'py>,
    [theta, energy, velocity]: [&ArrayIn<'py>; 3],
    f: impl Fn(f64, f64, [f64; 2]) -> lieflow::Result<f64> + Sync + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let inputs = [
        Input::finite("theta", theta, &[]),
        Input::finite("energy", energy, &[]),
        Input::finite("velocity", velocity, &[2]),
    ];
    par_map_items(py, &inputs, &[], |x, out| {
        out[0] = f(x[0][0], x[1][0], [x[2][0], x[2][1]])?;
        Ok(())
    })
}

/// `f(v, y)` over the broadcast leading axes of two arrays of scalars (the relations (94)–(96));
/// the core's name of J is the argument's, `p_theta`.
fn relation<'py>(
    py: Python<'py>,
    v: (&str, &ArrayIn<'py>),
    y: (&str, &ArrayIn<'py>),
    f: impl Fn(f64, f64) -> lieflow::Result<f64> + Sync + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let inputs = [Input::finite(v.0, v.1, &[]), Input::finite(y.0, y.1, &[])];
    par_map_items(py, &inputs, &[], |x, out| {
        out[0] = f(x[0][0], x[1][0])
            .map_err(|e| e.map_what(|w| if w == "J" { y.0.into() } else { w.into() }))?;
        Ok(())
    })
}

/// The tangent top in the weak-field limit of a static space-time with potential :math:`\phi`
/// (002 (115)–(120), (115) with its :math:`dt^2` restored and the sign of the spin–field coupling of
/// (118) corrected). State (x, y, theta, p_x, p_y, p_theta). Methods: gauss4 (default), gauss6,
/// midpoint, rk4.
///
/// Args:
///     mass: m > 0.
///     inertia: tr I > 0.
///     gm: a point mass, :math:`\phi = -gm/r` (give exactly one of gm and g).
///     g: a uniform field, :math:`\phi = g \cdot x`, (2,).
/// Raises:
///     InvalidArgumentError.
#[pyclass(name = "WeakFieldTop", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyWeakFieldTop;

#[pymethods]
impl PyWeakFieldTop {
    #[new]
    #[pyo3(signature = (mass, inertia, gm = None, g = None))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = real)] mass: f64,
        #[pyo3(from_py_with = real)] inertia: f64,
        #[pyo3(from_py_with = real_opt)] gm: Option<f64>,
        #[pyo3(from_py_with = reals_opt::<2>)] g: Option<[f64; 2]>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let top = core::WeakFieldTop::new(mass, inertia, potential(gm, g)?).py()?;
        let args = (mass, inertia, gm, g).into_pyobject(py)?;
        Ok(PySystem::subclass(
            top,
            args,
            &["mass", "inertia", "gm", "g"],
        ))
    }

    /// The canonical state from the position x (2,), the angle theta and the velocities.
    ///
    /// Raises:
    ///     InvalidArgumentError (outside the weak-field domain), NonFiniteError.
    fn state(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
        #[pyo3(from_py_with = real)] theta: f64,
        #[pyo3(from_py_with = reals::<2>)] xdot: [f64; 2],
        #[pyo3(from_py_with = real)] thetadot: f64,
    ) -> PyResult<Vec<f64>> {
        let top = slf.core::<core::WeakFieldTop>()?;
        top.state(x, theta, xdot, thetadot).py()
    }

    /// The Lagrangian 002 (118) (coupling sign corrected, physical sign, rest energy dropped):
    ///
    /// .. math::
    ///
    ///     L = \tfrac12 m v^2 - m\phi + I_0 \dot\theta^2 (1 - \phi + v^2)
    ///         + I_0 \dot\theta\, (G_y \dot x - G_x \dot y),
    ///
    /// :math:`I_0 = \tfrac12 \operatorname{tr} I`, :math:`G = \nabla\phi`.
    ///
    /// Args:
    ///     x: (2,); theta; xdot: (2,); thetadot.
    /// Returns:
    ///     float.
    /// Raises:
    ///     InvalidArgumentError (phi not finite at x), NonFiniteError.
    fn lagrangian(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
        #[pyo3(from_py_with = real)] theta: f64,
        #[pyo3(from_py_with = reals::<2>)] xdot: [f64; 2],
        #[pyo3(from_py_with = real)] thetadot: f64,
    ) -> PyResult<f64> {
        let top = slf.core::<core::WeakFieldTop>()?;
        top.lagrangian([x[0], x[1], theta], [xdot[0], xdot[1], thetadot])
            .py()
    }

    /// The angular momentum :math:`x p_y - y p_x` of states (conserved for a central potential),
    /// vectorised: (..., 6) -> (...).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn angular_momentum<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::WeakFieldTop>()?;
        map_items(
            slf.py(),
            &[Input::new("states", &states, &[6])],
            &[],
            |z, out| {
                out[0] = top.angular_momentum(z[0])?;
                Ok(())
            },
        )
    }
}

/// The potential of `WeakFieldTop` and `StaticFieldTop`: exactly one of gm (a point mass,
/// phi = -gm/r) or g (a uniform field phi = g.x).
fn potential(gm: Option<f64>, g: Option<[f64; 2]>) -> PyResult<core::Potential> {
    match (gm, g) {
        (Some(gm), None) => core::Potential::point_mass(gm),
        (None, Some(g)) => core::Potential::uniform(g),
        _ => Err(Error::invalid("potential", "give exactly one of gm and g")),
    }
    .map_err(to_py)
}

/// The symmetric relativistic tangent top on the static space-time
/// :math:`-e^{2\phi} dt^2 + dx^2 + dy^2` of a potential :math:`\phi`, or, with `surface`,
/// :math:`-e^{2\phi} dt^2 + g` over that surface, to second order in the body's size
/// (002 (115)-(117), derived again; physical sign): with :math:`Q = g(\dot x, \dot x)`,
/// :math:`b = e^{2\phi} - Q`, :math:`I_0 = \tfrac12 \operatorname{tr} I`,
/// :math:`s = \dot\theta + w(\dot x)` (:math:`w` the surface's connection 1-form;
/// :math:`s = \dot\theta` in the plane), :math:`G` the components of :math:`d\phi` and :math:`u`
/// those of :math:`\dot x` in an orthonormal frame, :math:`c = G_2 u_1 - G_1 u_2`
/// (:math:`G_y \dot x - G_x \dot y` in the plane),
///
/// .. math::
///
///     L = -m \sqrt{b} + I_0 s^2 / \sqrt{b} - I_0 e^{2\phi} G^2 / (2 \sqrt{b})
///         + I_0 (s^2 Q + 2 e^{2\phi} s c + e^{4\phi} G^2) / (2 b^{3/2}).
///
/// In the plane, weak fields and slow motion give `WeakFieldTop` (002 (118)) plus :math:`-m`;
/// :math:`\phi = 0` gives `RelativisticTangentTop` (flat or on the same surface). :math:`\phi` is
/// a function of the chart coordinates (x1, x2). State (x1, x2, theta, p1, p2, p_theta); speeds
/// :math:`\sqrt{Q}` below :math:`e^\phi`. Invariants: p_theta, and in the plane
/// :math:`x p_y - y p_x` (point mass) or the momentum across a uniform field; on a surface the
/// Killing momenta of its affine isometries that keep :math:`\phi` (e.g. :math:`J_z` on the
/// sphere in ``g=(k, 0)``, :math:`\phi = k\theta`); the energy is conserved. Methods: gauss4
/// (default), gauss6, midpoint, rk4.
///
/// Args:
///     mass: m > 0.
///     inertia: tr I > 0.
///     gm: a point mass at the chart's origin, :math:`\phi = -gm/r` (give exactly one of gm and
///         g).
///     g: a uniform field of the chart, :math:`\phi = g \cdot x`, (2,).
///     surface: a `lieflow.surfaces` surface, or None for the plane.
/// Raises:
///     InvalidArgumentError, TypeError (surface not a lieflow surface).
#[pyclass(name = "StaticFieldTop", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyStaticFieldTop;

#[pymethods]
impl PyStaticFieldTop {
    #[new]
    #[pyo3(signature = (mass, inertia, gm = None, g = None, surface = None))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = real)] mass: f64,
        #[pyo3(from_py_with = real)] inertia: f64,
        #[pyo3(from_py_with = real_opt)] gm: Option<f64>,
        #[pyo3(from_py_with = reals_opt::<2>)] g: Option<[f64; 2]>,
        surface: Option<Bound<'_, PySurface>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let phi = potential(gm, g)?;
        let top = match &surface {
            None => core::StaticFieldTop::new(mass, inertia, phi),
            Some(s) => core::StaticFieldTop::on_surface(s.get().inner.clone(), mass, inertia, phi),
        }
        .py()?;
        let args = (mass, inertia, gm, g, surface).into_pyobject(py)?;
        Ok(PySystem::subclass(
            top,
            args,
            &["mass", "inertia", "gm", "g", "surface"],
        ))
    }

    /// All Killing momenta :math:`J = p_A X^A` of the spatial slice's isometry group (the plane:
    /// translations x, y and the rotation :math:`x p_y - y p_x + p_\theta`; Sphere: the ambient
    /// angular momentum x, y, z; HyperbolicPlane: the Möbius generators E, H, F; Revolution:
    /// p_phi), (..., 6) -> (..., k). Conserved where the isometry also keeps phi.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, InvalidArgumentError (x outside the chart).
    fn killing_momenta<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::StaticFieldTop>()?;
        let k = top.surface().killing_count();
        slf.base().map_states(slf.py(), &states, &[k], |z, out| {
            out.copy_from_slice(&top.killing_momenta(z)?);
            Ok(())
        })
    }

    /// The canonical state from the position x (2,) in the chart, the angle theta and the
    /// velocities.
    ///
    /// Raises:
    ///     InvalidArgumentError (a speed not below :math:`e^\phi`, x outside the surface's chart,
    ///     phi not finite at x, a Legendre map not invertible), NonFiniteError.
    fn state(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
        #[pyo3(from_py_with = real)] theta: f64,
        #[pyo3(from_py_with = reals::<2>)] xdot: [f64; 2],
        #[pyo3(from_py_with = real)] thetadot: f64,
    ) -> PyResult<Vec<f64>> {
        let top = slf.core::<core::StaticFieldTop>()?;
        crate::errors::checked(|| top.state(x, theta, xdot, thetadot))
    }

    /// The Lagrangian of 002 (117) (derived again, physical sign; the class docstring).
    ///
    /// Args:
    ///     x: (2,) in the chart; theta; xdot: (2,); thetadot.
    /// Returns:
    ///     float.
    /// Raises:
    ///     InvalidArgumentError (a speed not below :math:`e^\phi`, x outside the chart, phi not
    ///     finite at x), NonFiniteError.
    fn lagrangian(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
        #[pyo3(from_py_with = real)] theta: f64,
        #[pyo3(from_py_with = reals::<2>)] xdot: [f64; 2],
        #[pyo3(from_py_with = real)] thetadot: f64,
    ) -> PyResult<f64> {
        let top = slf.core::<core::StaticFieldTop>()?;
        crate::errors::checked(|| top.lagrangian([x[0], x[1], theta], [xdot[0], xdot[1], thetadot]))
    }

    /// The velocities (xdot, ydot, thetadot) of states, vectorised: (..., 6) -> (..., 3).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, InvalidArgumentError.
    fn velocities<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::StaticFieldTop>()?;
        slf.base().map_states(slf.py(), &states, &[3], |z, out| {
            out.copy_from_slice(&top.velocities(z)?);
            Ok(())
        })
    }

    /// The angular momentum :math:`x p_y - y p_x` of states (conserved for a central potential),
    /// vectorised: (..., 6) -> (...).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn angular_momentum<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let top = slf.core::<core::StaticFieldTop>()?;
        map_items(
            slf.py(),
            &[Input::new("states", &states, &[6])],
            &[],
            |z, out| {
                out[0] = top.angular_momentum(z[0])?;
                Ok(())
            },
        )
    }
}
