//! `RollingDisks`: binding of `lieflow::systems::rolling::disks` (003 §1), a thin subclass of
//! `lieflow.System`, and its relative equilibria.

use lieflow::systems::rolling::disks::DisksEquilibrium;
use lieflow::systems::RollingDisks;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use pyo3::PyClassInitializer;

use crate::convert::ArrayIn;
use crate::convert::{named, real, real_opt, real_pair, reals, Real};
use crate::errors::IntoPy;
use crate::system::{PySystem, Thin};
use numpy::{PyArrayDescrMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::types::PyComplex;

type Any<'py> = Bound<'py, PyAny>;

/// A point of the plane from a complex number (a real number is one) or a 2-vector.
fn point(what: &str, v: &Any<'_>) -> PyResult<[f64; 2]> {
    let complex = v.is_instance_of::<PyComplex>()
        || v.cast::<PyUntypedArray>()
            .is_ok_and(|a| a.ndim() == 0 && a.dtype().kind() == b'c');
    if complex {
        let part = |name: &str| named(what, real(&v.getattr(name)?));
        return Ok([part("real")?, part("imag")?]);
    }
    // A real number is the complex number x + 0i.
    if let Ok(Real(x)) = v.extract::<Real>() {
        return Ok([x, 0.0]);
    }
    named(what, reals::<2>(v))
}

/// Two disks rolling against each other in the plane without slipping (003 §1). Disk k has
/// radius :math:`r_k`, centre of mass :math:`\gamma_k` in its reference disk (a complex number or
/// a 2-vector), mass :math:`m_k` and moment of inertia :math:`I_k` about its centre (003 (6): the
/// integral of :math:`\|p\|^2`). The rolling constraint integrates to
/// :math:`R\phi - r_1\theta_1 - r_2\theta_2 = c` (:math:`R = r_1 + r_2`, c the rolling constant),
/// leaving the two disk angles :math:`\theta = (\theta_1, \theta_2)`; the centre of mass of the
/// pair is at the origin. State (theta1, theta2, p1, p2); fields theta (2), p (2), thetadot (2),
/// phi (the direction of the contact point from disk 1's centre).
/// :math:`H = \tfrac12 p^\top M(\theta)^{-1} p`; invariant: the angular momentum
/// :math:`J = p_1 + p_2`. Methods: gauss4
/// (default), gauss6, midpoint (symplectic Gauss–Legendre), rk4.
///
/// Raises:
///     InvalidArgumentError (:math:`r, m \le 0`, :math:`\|\gamma\| \ge r`,
///     :math:`I \le m \|\gamma\|^2`), TypeError.
#[pyclass(name = "RollingDisks", module = "lieflow", extends = PySystem, frozen)]
#[derive(Default)]
pub struct PyRollingDisks;

#[pymethods]
impl PyRollingDisks {
    #[new]
    #[pyo3(signature = (r1, r2, gamma1, gamma2, m1, m2, inertia1, inertia2, rolling_constant = 0.0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = real)] r1: f64,
        #[pyo3(from_py_with = real)] r2: f64,
        gamma1: Any<'_>,
        gamma2: Any<'_>,
        #[pyo3(from_py_with = real)] m1: f64,
        #[pyo3(from_py_with = real)] m2: f64,
        #[pyo3(from_py_with = real)] inertia1: f64,
        #[pyo3(from_py_with = real)] inertia2: f64,
        #[pyo3(from_py_with = real)] rolling_constant: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let (g1, g2) = (point("gamma1", &gamma1)?, point("gamma2", &gamma2)?);
        let disks = RollingDisks::new([r1, r2], [g1, g2], [m1, m2], [inertia1, inertia2])
            .and_then(|d| d.with_rolling_constant(rolling_constant))
            .py()?;
        let args =
            (r1, r2, g1, g2, m1, m2, inertia1, inertia2, rolling_constant).into_pyobject(py)?;
        let names = &[
            "r1",
            "r2",
            "gamma1",
            "gamma2",
            "m1",
            "m2",
            "inertia1",
            "inertia2",
            "rolling_constant",
        ];
        Ok(PySystem::subclass(disks, args, names))
    }

    /// The rolling constant c.
    #[getter]
    fn rolling_constant(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Ok(slf.core::<RollingDisks>()?.rolling_constant())
    }

    /// The state :math:`(\theta, M(\theta)\dot\theta)` from the angles and their rates.
    ///
    /// Raises:
    ///     NonFiniteError.
    fn state(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] theta: [f64; 2],
        #[pyo3(from_py_with = reals::<2>)] thetadot: [f64; 2],
    ) -> PyResult<Vec<f64>> {
        slf.core::<RollingDisks>()?.state(theta, thetadot).py()
    }

    /// The mass matrix :math:`M(\theta)` of :math:`T = \tfrac12 \dot\theta^\top M \dot\theta` (2,
    /// 2).
    fn mass_matrix(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] theta: [f64; 2],
    ) -> PyResult<[[f64; 2]; 2]> {
        slf.core::<RollingDisks>()?.mass_matrix(theta).py()
    }

    /// The locked inertia :math:`(1, 1)\, M(\theta)\, (1, 1)^\top`: the moment of inertia of the
    /// pair rotating rigidly about its centre of mass.
    fn locked_inertia(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = reals::<2>)] theta: [f64; 2],
    ) -> PyResult<f64> {
        slf.core::<RollingDisks>()?.locked_inertia(theta).py()
    }

    /// Named views for `Trajectory`: theta (..., 2), p (..., 2), thetadot (..., 2), phi (...).
    fn _fields<'py>(slf: &Bound<'py, Self>, states: &Any<'py>) -> PyResult<Bound<'py, PyDict>> {
        let py = slf.py();
        let (base, disks) = (slf.base(), slf.core::<RollingDisks>()?);
        let fields = base._fields(py, states.extract()?)?;
        let states = ArrayIn::named("states", states)?;
        let v = base.map_states(py, &states, &[2], |z, out| {
            out.copy_from_slice(&disks.velocities(z)?);
            Ok(())
        })?;
        let phi = base.map_states(py, &states, &[], |z, out| {
            out[0] = disks.phi([z[0], z[1]]);
            Ok(())
        })?;
        fields.set_item("thetadot", v)?;
        fields.set_item("phi", phi)?;
        Ok(fields)
    }

    /// The total angular momentum about the centre of mass, :math:`J = p_1 + p_2`,
    /// (..., 4) -> (...).
    fn angular_momentum<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let disks = slf.core::<RollingDisks>()?;
        slf.base().map_states(slf.py(), &states, &[], |z, out| {
            out[0] = disks.angular_momentum(z)?;
            Ok(())
        })
    }

    /// Where the pieces are, in the centre-of-mass frame (003 (4)): a dict of arrays
    /// "centres" (..., 2, 2) (the disks' centres), "masses" (..., 2, 2) (their centres of
    /// mass) and "contact" (..., 2) (the contact point), from states (..., 4).
    fn positions<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (py, base, disks) = (slf.py(), slf.base(), slf.core::<RollingDisks>()?);
        let out = PyDict::new(py);
        let centres = base.map_states(py, &states, &[2, 2], |z, o| {
            o.copy_from_slice(disks.positions(z)?.centres.as_flattened());
            Ok(())
        })?;
        let masses = base.map_states(py, &states, &[2, 2], |z, o| {
            o.copy_from_slice(disks.positions(z)?.masses.as_flattened());
            Ok(())
        })?;
        let contact = base.map_states(py, &states, &[2], |z, o| {
            o.copy_from_slice(&disks.positions(z)?.contact);
            Ok(())
        })?;
        out.set_item("centres", centres)?;
        out.set_item("masses", masses)?;
        out.set_item("contact", contact)?;
        Ok(out)
    }

    /// Every rotational relative equilibrium (the pair rotating rigidly about its centre of mass)
    /// with theta1 in `theta1_range` (default: one turn of disk 1), in the gauge where the contact
    /// point lies in the direction :math:`\phi = 0` from disk 1's centre, for the rolling constant
    /// `rolling_constant` (default: the system's). They are the configurations in which both
    /// centres of mass and the contact point are collinear; stable where the locked inertia is
    /// maximal along the rolling direction (003 §1, corrected; see the module docs of
    /// `lieflow::systems::rolling::disks`).
    ///
    /// Raises:
    ///     InvalidArgumentError (an empty range), NonFiniteError.
    #[pyo3(signature = (rolling_constant = None, theta1_range = (0.0, std::f64::consts::TAU)),
           text_signature = "($self, rolling_constant=None, theta1_range=(0.0, 6.283185307179586))")]
    fn relative_equilibria(
        slf: &Bound<'_, Self>,
        #[pyo3(from_py_with = real_opt)] rolling_constant: Option<f64>,
        #[pyo3(from_py_with = real_pair)] theta1_range: (f64, f64),
    ) -> PyResult<Vec<PyDisksEquilibrium>> {
        let disks = slf.core::<RollingDisks>()?.clone();
        let disks = match rolling_constant {
            Some(c) => disks.with_rolling_constant(c).py()?,
            None => disks,
        };
        let eqs = disks.relative_equilibria(theta1_range).py()?;
        Ok(eqs
            .into_iter()
            .map(|eq| PyDisksEquilibrium {
                eq,
                disks: disks.clone(),
            })
            .collect())
    }
}

/// A rotational relative equilibrium of `RollingDisks`: the pair rotating rigidly about its centre
/// of mass with any angular velocity :math:`\omega \ne 0` (the equilibria and their stability do
/// not depend on it).
#[pyclass(name = "RollingDisksEquilibrium", module = "lieflow", frozen)]
pub struct PyDisksEquilibrium {
    eq: DisksEquilibrium,
    disks: RollingDisks,
}

#[pymethods]
impl PyDisksEquilibrium {
    /// theta1.
    #[getter]
    fn theta1(&self) -> f64 {
        self.eq.theta[0]
    }

    /// theta2.
    #[getter]
    fn theta2(&self) -> f64 {
        self.eq.theta[1]
    }

    /// Stable (a strict minimum of the amended potential): perturbations of the shape stay
    /// small for all time.
    #[getter]
    fn stable(&self) -> bool {
        self.eq.stable
    }

    /// The critical point is degenerate (the stability verdict is inconclusive).
    #[getter]
    fn degenerate(&self) -> bool {
        self.eq.degenerate
    }

    /// The contact point P (centre-of-mass frame, gauge :math:`\phi = 0`).
    #[getter]
    fn contact_point(&self) -> [f64; 2] {
        self.eq.contact
    }

    /// The range of :math:`|\omega|` for which it is a relative equilibrium: :math:`(0, \infty)`,
    /// every rotation.
    #[getter]
    fn angular_velocity_range(&self) -> (f64, f64) {
        (0.0, f64::INFINITY)
    }

    /// The locked inertia there.
    #[getter]
    fn locked_inertia(&self) -> f64 {
        self.eq.locked_inertia
    }

    /// The second derivative of the locked inertia along the rolling direction :math:`(r_2, -r_1)`:
    /// negative where stable.
    #[getter]
    fn curvature(&self) -> f64 {
        self.eq.curvature
    }

    /// The state of the rotation with angular velocity omega.
    ///
    /// Raises:
    ///     NonFiniteError.
    #[pyo3(signature = (omega = 1.0))]
    fn state(&self, #[pyo3(from_py_with = real)] omega: f64) -> PyResult<Vec<f64>> {
        self.eq.state(&self.disks, omega).py()
    }

    fn __repr__(&self) -> String {
        format!(
            "RollingDisksEquilibrium(theta1={:.6}, theta2={:.6}, stable={})",
            self.eq.theta[0],
            self.eq.theta[1],
            if self.eq.stable { "True" } else { "False" }
        )
    }
}
