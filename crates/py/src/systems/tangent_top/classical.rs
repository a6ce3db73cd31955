//! `TangentTop` and `ChargedParticle`: bindings of `lieflow::systems::tangent_top::classical` (002 §II–III),
//! thin subclasses of `lieflow.System`.
#![allow(non_snake_case)]

use lieflow::systems::{ChargedParticle, TangentTop};
use lieflow::Error;
use numpy::ndarray::arr2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PySlice};
use pyo3::PyClassInitializer;

pub(crate) use super::surface::PySurface;
use crate::convert::{mat, ArrayIn};
use crate::convert::{real, reals, Real};
use crate::errors::{to_py, IntoPy};
use crate::system::{PySystem, Thin};

type Any<'py> = Bound<'py, PyAny>;

/// `states[..., k]` for an index or slice `k`.
fn pick<'py>(a: &Any<'py>, k: Any<'py>) -> PyResult<Any<'py>> {
    let py = a.py();
    a.call_method1("__getitem__", ((py.Ellipsis(), k),))
}

/// The Euler tensor from a scalar I = tr I (a symmetric body) or a (2, 2) array.
fn tensor(inertia: &Any<'_>) -> PyResult<[f64; 4]> {
    if let Ok(Real(i)) = inertia.extract::<Real>() {
        return Ok([0.5 * i, 0.0, 0.0, 0.5 * i]);
    }
    let a = ArrayIn::named("inertia", inertia)?;
    let m = mat("inertia", &a)?;
    if m.nrows() != 2 || m.ncols() != 2 {
        return Err(to_py(Error::shape(
            "inertia",
            "a number (tr I) or (2, 2)",
            format!("({}, {})", m.nrows(), m.ncols()),
        )));
    }
    Ok([m[(0, 0)], m[(0, 1)], m[(1, 0)], m[(1, 1)]])
}

/// The tangent Euler top on a surface (002 §II–III): a rigid planar body carried as an
/// orthonormal frame tangent to the surface; configuration (x1, x2, theta), theta the angle from
/// the surface's E1 to the body's E1.
/// :math:`L = \tfrac12 m\, g(\dot x, \dot x) + \tfrac12 I (\dot\theta + w(\dot x))^2` with
/// :math:`w` the connection 1-form (002 (43); the cross term of (45)/(47) with the corrected
/// sign); with `embedded=True` the body moves as embedded in :math:`\mathbb{R}^3` and L gains the
/// second-fundamental-form
/// term of 002 (37) (for a symmetric body, (39)), which for an anisotropic body depends on theta.
/// State (x1, x2, theta, p1, p2, p_theta); fields x (2), theta, p (3), xdot (2), thetadot.
/// Invariants: p_theta (unless embedded and anisotropic) and the Killing momenta of the affine
/// isometries. Methods: gauss4 (default), gauss6, midpoint (symplectic Gauss–Legendre), rk4.
///
/// Args:
///     surface: a `lieflow.surfaces` surface.
///     mass: m > 0.
///     inertia: the scalar :math:`I`, the trace of the Euler tensor (a symmetric body, tensor
///         :math:`\tfrac{I}{2} \mathrm{Id}`), or the (2, 2) Euler tensor
///         :math:`\int \xi \xi^\top dm` (symmetric positive semi-definite).
///     embedded: include the embedding term (surfaces with an embedding in :math:`\mathbb{R}^3`
///         only).
/// Raises:
///     InvalidArgumentError, ShapeError.
#[pyclass(name = "TangentTop", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyTangentTop;

#[pymethods]
impl PyTangentTop {
    #[new]
    #[pyo3(signature = (surface, mass, inertia, embedded=false))]
    fn new(
        surface: Bound<'_, PySurface>,
        #[pyo3(from_py_with = real)] mass: f64,
        inertia: Any<'_>,
        embedded: bool,
    ) -> PyResult<PyClassInitializer<Self>> {
        let s = surface.get();
        let mut top = TangentTop::with_tensor(s.inner.clone(), mass, tensor(&inertia)?).py()?;
        if embedded {
            top = top.embedded().py()?;
        }
        let args = (surface.clone(), mass, inertia, embedded).into_pyobject(surface.py())?;
        let names = &["surface", "mass", "inertia", "embedded"];
        Ok(PySystem::subclass(top, args, names))
    }

    /// The Euler tensor (2, 2).
    #[getter]
    fn tensor(slf: &Bound<'_, Self>) -> PyResult<[[f64; 2]; 2]> {
        let t = slf.core::<TangentTop>()?.tensor();
        Ok([[t[0], t[1]], [t[2], t[3]]])
    }

    /// The canonical state from x (2,), theta and the velocities (Legendre transform of (47)).
    ///
    /// Raises:
    ///     InvalidArgumentError (x outside the chart), NonFiniteError.
    fn state(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
        #[pyo3(from_py_with = real)] theta: f64,
        #[pyo3(from_py_with = reals::<2>)] xdot: [f64; 2],
        #[pyo3(from_py_with = real)] thetadot: f64,
    ) -> PyResult<Vec<f64>> {
        let top = slf.core::<TangentTop>()?;
        crate::errors::checked(|| top.state(x, theta, xdot, thetadot))
    }

    /// The metric of the configuration space at :math:`\eta = (x_1, x_2, \theta)`, 002 (47) with
    /// the sign of its cross terms corrected:
    /// :math:`g_{AB} = \begin{pmatrix} m g + I a a^\top & I a \\ I a^\top & I \end{pmatrix}` with
    /// :math:`g` the surface's metric, :math:`a = (\alpha_1, \alpha_2)` its connection 1-form and
    /// :math:`I` the trace of the Euler tensor; for the embedded top :math:`m g` becomes
    /// :math:`G(x, \theta) = m g + W^\top Q(\theta) W` (002 (37), (39)). The Lagrangian is
    /// :math:`L = \tfrac12 \dot\eta^\top g_{AB} \dot\eta` and the canonical momenta of `state` are
    /// :math:`p = g_{AB} \dot\eta`.
    ///
    /// Args:
    ///     x: (2,) in the surface's chart; theta: the body's angle.
    /// Returns:
    ///     (3, 3) symmetric positive definite array.
    /// Raises:
    ///     InvalidArgumentError (x outside the chart), NonFiniteError.
    fn metric<'py>(
        slf: &Bound<'py, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
        #[pyo3(from_py_with = real)] theta: f64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let top = slf.core::<TangentTop>()?;
        let g = crate::errors::checked(|| top.metric([x[0], x[1], theta]))?;
        Ok(arr2(&g).into_pyarray(slf.py()))
    }

    /// The Lagrangian of the top, 002 (43)–(47) (cross term with the corrected sign):
    /// :math:`L = \tfrac12 m\, g(\dot x, \dot x) + \tfrac12 I (\dot\theta + \alpha_i \dot x^i)^2`
    /// with :math:`I` the trace of the Euler tensor and :math:`\alpha` the connection 1-form of the
    /// surface's frame; for the embedded top :math:`m g` becomes
    /// :math:`G(x, \theta) = m g + W^\top Q(\theta) W` (002 (37), (39)).
    ///
    /// Args:
    ///     x: (2,) in the surface's chart; theta; xdot: (2,); thetadot.
    /// Returns:
    ///     float.
    /// Raises:
    ///     InvalidArgumentError (x outside the chart, L beyond the float range), NonFiniteError.
    fn lagrangian(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
        #[pyo3(from_py_with = real)] theta: f64,
        #[pyo3(from_py_with = reals::<2>)] xdot: [f64; 2],
        #[pyo3(from_py_with = real)] thetadot: f64,
    ) -> PyResult<f64> {
        let top = slf.core::<TangentTop>()?;
        let (eta, etadot) = ([x[0], x[1], theta], [xdot[0], xdot[1], thetadot]);
        crate::errors::checked(|| top.lagrangian(eta, etadot))
    }

    /// Named views for `Trajectory`: x (..., 2), theta (...), p (..., 3), and the velocities
    /// xdot (..., 2) and thetadot (...).
    fn _fields<'py>(slf: &Bound<'py, Self>, states: &Any<'py>) -> PyResult<Bound<'py, PyDict>> {
        let py = slf.py();
        let fields = slf.base()._fields(py, states.extract()?)?;
        if let Some(theta) = fields.get_item("theta")? {
            fields.set_item("theta", pick(&theta, 0i64.into_pyobject(py)?.into_any())?)?;
        }
        let v = Self::velocities(slf, states.extract()?)?;
        fields.set_item("xdot", pick(&v, PySlice::new(py, 0, 2, 1).into_any())?)?;
        fields.set_item("thetadot", pick(&v, 2i64.into_pyobject(py)?.into_any())?)?;
        Ok(fields)
    }

    /// The velocities (x1dot, x2dot, thetadot) of states, vectorised: (..., 6) -> (..., 3).
    fn velocities<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let top = slf.core::<TangentTop>()?;
        slf.base().map_states(slf.py(), &states, &[3], |z, out| {
            out.copy_from_slice(&top.velocities(z)?);
            Ok(())
        })
    }

    /// The body's angular momentum p_theta (kept exactly by the Gauss methods when conserved),
    /// (..., 6) -> (...).
    fn p_theta<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let top = slf.core::<TangentTop>()?;
        slf.base().map_states(slf.py(), &states, &[], |z, out| {
            out[0] = top.p_theta(z)?;
            Ok(())
        })
    }

    /// All Killing momenta :math:`J = p_A X^A` of the surface's isometry group (Plane: translations
    /// x, y and the rotation; Sphere: the ambient angular momentum x, y, z; HyperbolicPlane: the
    /// Möbius generators E, H, F; Revolution and Torus: p_phi), (..., 6) -> (..., k).
    fn killing_momenta<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let top = slf.core::<TangentTop>()?;
        let k = top.surface().killing_count();
        slf.base().map_states(slf.py(), &states, &[k], |z, out| {
            out.copy_from_slice(&top.killing_momenta(z)?);
            Ok(())
        })
    }

    /// The body in :math:`\mathbb{R}^3` for a surface with an embedding: rows (position c, E1, E2),
    /// (..., 6) -> (..., 3, 3).
    ///
    /// Raises:
    ///     InvalidArgumentError (the surface has no embedding).
    fn ambient_frame<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let top = slf.core::<TangentTop>()?;
        if top.surface().embedding().is_none() {
            return Err(to_py(Error::invalid(
                "ambient_frame",
                format!("the {} chart has no embedding in R^3", top.surface().name()),
            )));
        }
        slf.base().map_states(slf.py(), &states, &[3, 3], |z, out| {
            let f = top.ambient_frame(z)?.expect("checked above");
            out.copy_from_slice(f.as_flattened());
            Ok(())
        })
    }

    /// The charged particle equivalent to tops with this p_theta (002 §III.B, Routh form): its
    /// path x(t) is the centre's. See `ChargedParticle`.
    ///
    /// Raises:
    ///     InvalidArgumentError (an anisotropic embedded top depends on theta and has none).
    fn magnetic_analogue<'py>(
        slf: &Bound<'py, Self>,
        #[pyo3(from_py_with = real)] p_theta: f64,
    ) -> PyResult<Any<'py>> {
        let py = slf.py();
        let cls = py.import("lieflow")?.getattr("ChargedParticle")?;
        cls.call1((slf.clone(), p_theta))
    }
}

/// The charged particle of 002 §III.B that stands for a tangent top with angular momentum
/// p_theta: mass m on the surface with metric g (plus the (39) term for a symmetric embedded
/// top), magnetic potential :math:`A = \alpha` (the frame's connection 1-form) and charge
/// :math:`p_\theta`. The
/// Routhian of the top gives it; 002 (58) prints a different metric, potential and charge (a
/// slip: it is p_theta, not thetadot, that is conserved). State (x1, x2, p1, p2); fields x, p,
/// xdot. :math:`H = \tfrac12 \|p - p_\theta A\|_G^2` (the top's energy minus
/// :math:`p_\theta^2 / (2 I)`).
/// Methods: gauss4 (default), gauss6, midpoint (symplectic Gauss–Legendre), rk4.
///
/// Args:
///     top: a `TangentTop` (not an anisotropic embedded one).
///     charge: p_theta.
/// Raises:
///     InvalidArgumentError.
#[pyclass(name = "ChargedParticle", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyChargedParticle;

#[pymethods]
impl PyChargedParticle {
    #[new]
    fn new(
        top: Bound<'_, PyTangentTop>,
        #[pyo3(from_py_with = real)] charge: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let particle = top.core::<TangentTop>()?.magnetic_analogue(charge).py()?;
        let args = (top.clone(), charge).into_pyobject(top.py())?;
        Ok(PySystem::subclass(particle, args, &["top", "charge"]))
    }

    /// The charge p_theta.
    #[getter]
    fn charge(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Ok(slf.core::<ChargedParticle>()?.charge())
    }

    /// The metric of the particle at x (2, 2): :math:`g`, plus :math:`\frac{I}{2m} h g^{-1} h` for
    /// a symmetric embedded top.
    ///
    /// Raises:
    ///     InvalidArgumentError (x outside the chart).
    fn metric(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
    ) -> PyResult<[[f64; 2]; 2]> {
        let particle = slf.core::<ChargedParticle>()?;
        crate::errors::checked(|| particle.metric(x))
    }

    /// The magnetic potential :math:`A = \alpha` at x.
    ///
    /// Raises:
    ///     InvalidArgumentError (x outside the chart).
    fn potential(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
    ) -> PyResult<[f64; 2]> {
        let particle = slf.core::<ChargedParticle>()?;
        crate::errors::checked(|| particle.potential(x))
    }

    /// The canonical state (x, p), :math:`p = m G \dot x + \mathrm{charge}\, A`, from x and xdot.
    ///
    /// Raises:
    ///     InvalidArgumentError (x outside the chart), NonFiniteError.
    fn state(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] x: [f64; 2],
        #[pyo3(from_py_with = reals::<2>)] xdot: [f64; 2],
    ) -> PyResult<Vec<f64>> {
        let particle = slf.core::<ChargedParticle>()?;
        crate::errors::checked(|| particle.state(x, xdot))
    }

    /// Named views for `Trajectory`: x (..., 2), p (..., 2), xdot (..., 2).
    fn _fields<'py>(slf: &Bound<'py, Self>, states: &Any<'py>) -> PyResult<Bound<'py, PyDict>> {
        let py = slf.py();
        let fields = slf.base()._fields(py, states.extract()?)?;
        fields.set_item("xdot", Self::velocities(slf, states.extract()?)?)?;
        Ok(fields)
    }

    /// The velocities xdot of states, (..., 4) -> (..., 2).
    fn velocities<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let p = slf.core::<ChargedParticle>()?;
        slf.base().map_states(slf.py(), &states, &[2], |z, out| {
            out.copy_from_slice(&p.velocities(z)?);
            Ok(())
        })
    }

    /// The Killing momenta, those of the top at p_theta = charge, (..., 4) -> (..., k).
    fn killing_momenta<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let p = slf.core::<ChargedParticle>()?;
        let k = p.top().surface().killing_count();
        slf.base().map_states(slf.py(), &states, &[k], |z, out| {
            out.copy_from_slice(&p.killing_momenta(z)?);
            Ok(())
        })
    }
}
