//! `lieflow.PseudoRigidBody`: binding of `lieflow::pseudo_rigid::system` (001 §3–§7). A thin
//! subclass of `lieflow.System`: constructor and observables. State z = (X row-major,
//! P row-major), d = 2n².
#![allow(non_snake_case)]

use lieflow::pseudo_rigid::PseudoRigidBody as CoreBody;
use lieflow::{Error, Mat};
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use super::potential::{PyPotential, Zero};
use crate::convert::ArrayIn;
use crate::convert::{int, mat, py_mat};
use crate::errors::{to_py, IntoPy};
use crate::system::{PySystem, Thin};

type Any<'py> = Bound<'py, PyAny>;

/// A generalized pseudo-rigid body on :math:`T^*GL^+(n)` with
/// :math:`H = \tfrac12 \operatorname{tr}(P^\top P) + U(X)` (001 (3.22)).
///
/// Args:
///     n: dimension (>= 2).
///     potential: a `lieflow.potentials` potential (default: Zero(), the free body).
///     check_det: stop with LeftDomainError (naming the time) when :math:`\det X \le 0` (always
///         on for a volumetric potential and for an incompressible body; the equations extend to
///         all n×n matrices otherwise).
///     incompressible: hold the volume, :math:`\det X = \det X_0` (a fluid or incompressible
///         elastic ellipsoid; the pressure is the multiplier of the constraint).
///
/// Integrate with `lf.integrate(body, (X0, P0), dt=..., steps=..., method=...)`.
/// Methods: verlet (default), verlet4, verlet6 (Störmer–Verlet and its order-4/6
/// compositions), reduced (reduced-space splitting on the principal stratum, 001 §7, order 2,
/// exact coadjoint orbits). The incompressible body has its own methods instead:
/// "rattle" (the default, order 2), "rattle4" and "rattle6" (RATTLE and its Suzuki / Yoshida
/// compositions, orders 4 and 6): symplectic on :math:`T^*\{\det X = \det X_0\}`, they keep
/// :math:`\det X`, L and :math:`\Gamma` to round-off (`body.methods()` on the instance lists
/// them). Its states must move without changing the volume,
/// :math:`\langle \operatorname{cof} X, P \rangle = \det(X) \operatorname{tr}(X^{-1} P) = 0`
/// (InvalidArgumentError otherwise): make P so with `body.project_momentum(X, P)`. States are
/// flat: z = (X row-major, P row-major), length 2n²; fields X and P. Invariants:
/// :math:`\tfrac12 \operatorname{tr}((L^\top L)^k)` then
/// :math:`\tfrac12 \operatorname{tr}((\Gamma^\top \Gamma)^k)`,
/// :math:`k = 1, \dots, \lfloor n/2 \rfloor`, then :math:`\det X` for the incompressible body.
#[pyclass(module = "lieflow", name = "PseudoRigidBody", extends = PySystem, frozen)]
pub struct PyPseudoRigidBody {
    potential: Py<PyPotential>,
}

/// The core body of a `PseudoRigidBody`.
fn body<'a>(slf: &'a Bound<'_, PyPseudoRigidBody>) -> PyResult<&'a CoreBody> {
    slf.core()
}

/// Row-major values of an n×n matrix.
fn flat(m: &Mat, out: &mut [f64]) -> lieflow::Result<()> {
    let n = m.nrows();
    for (k, o) in out.iter_mut().enumerate() {
        *o = m[(k / n, k % n)];
    }
    Ok(())
}

#[pymethods]
impl PyPseudoRigidBody {
    #[new]
    #[pyo3(signature = (n, potential=None, check_det=true, incompressible=false))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = int)] n: i64,
        potential: Option<Bound<'_, PyPotential>>,
        check_det: bool,
        incompressible: bool,
    ) -> PyResult<PyClassInitializer<Self>> {
        let size = usize::try_from(n)
            .map_err(|_| to_py(Error::invalid("n", format!("expected n ≥ 2, got {n}"))))?;
        let potential = match potential {
            Some(p) => p,
            None => Bound::new(py, Zero(py)?)?,
        };
        let pot = potential.get();
        let body = if incompressible {
            CoreBody::incompressible(size, pot.inner.clone())
        } else {
            CoreBody::new(size, pot.inner.clone(), check_det)
        }
        .py()?;
        let args = (n, potential.clone(), check_det, incompressible).into_pyobject(py)?;
        let names = &["n", "potential", "check_det", "incompressible"];
        let this = PyPseudoRigidBody {
            potential: potential.unbind(),
        };
        Ok(PySystem::init(this, body, args, names))
    }

    /// The dimension n.
    #[getter(n)]
    fn get_n(slf: &Bound<'_, Self>) -> PyResult<usize> {
        Ok(body(slf)?.n())
    }

    /// Whether :math:`\det X > 0` is enforced during integrations.
    #[getter]
    fn check_det(slf: &Bound<'_, Self>) -> PyResult<bool> {
        Ok(body(slf)?.check_det())
    }

    /// Whether the volume is held (:math:`\det X = \det X_0`; methods rattle, rattle4, rattle6).
    #[getter]
    fn incompressible(slf: &Bound<'_, Self>) -> PyResult<bool> {
        Ok(body(slf)?.is_incompressible())
    }

    /// The projection of a momentum P onto the states of the incompressible body at X:
    /// :math:`P - \kappa \operatorname{cof} X` with
    /// :math:`\kappa = \langle \operatorname{cof} X, P \rangle / \|\operatorname{cof} X\|^2`
    /// (:math:`\operatorname{cof} X = \det(X) X^{-\top}`), so that
    /// :math:`\langle \operatorname{cof} X, P \rangle = \det(X) \operatorname{tr}(X^{-1} P) = 0`
    /// (the motion keeps the volume).
    ///
    /// Args:
    ///     X: (n, n) with :math:`\det X > 0`; P: (n, n).
    /// Returns:
    ///     (n, n) array.
    /// Raises:
    ///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0`).
    fn project_momentum<'py>(
        slf: &Bound<'py, Self>,
        X: ArrayIn<'py>,
        P: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
        let (x, p) = (mat("X", &X)?, mat("P", &P)?);
        Ok(py_mat(slf.py(), &body(slf)?.project_momentum(&x, &p).py()?))
    }

    /// The potential.
    #[getter]
    fn potential(&self, py: Python<'_>) -> Py<PyPotential> {
        self.potential.clone_ref(py)
    }

    /// Angular momentum :math:`L = P X^\top - X P^\top` (001 (7.3)) of states
    /// (..., d) -> (..., n, n).
    fn angular_momentum<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let n = body(slf)?.n();
        observe(slf, states, &[n, n], |b, z, out| {
            flat(&b.momenta(z)?.0, out)
        })
    }

    /// Circulation :math:`\Gamma = P^\top X - X^\top P` (001 (7.3)) of states
    /// (..., d) -> (..., n, n).
    fn circulation<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let n = body(slf)?.n();
        observe(slf, states, &[n, n], |b, z, out| {
            flat(&b.momenta(z)?.1, out)
        })
    }

    /// Singular values :math:`a_1 \ge \dots \ge a_n` of X (the semi-axes), states
    /// (..., d) -> (..., n).
    fn singular_values<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let n = body(slf)?.n();
        observe(slf, states, &[n], |b, z, out| {
            out.copy_from_slice(&b.singular_values(z)?);
            Ok(())
        })
    }
}

/// An observable `f(body, state, out)` of states (..., d) -> (..., *shape).
fn observe<'py>(
    slf: &Bound<'py, PyPseudoRigidBody>,
    states: ArrayIn<'py>,
    shape: &[usize],
    f: impl Fn(&CoreBody, &[f64], &mut [f64]) -> lieflow::Result<()>,
) -> PyResult<Any<'py>> {
    let body = body(slf)?;
    slf.base()
        .map_states(slf.py(), &states, shape, |z, out| f(body, z, out))
}
