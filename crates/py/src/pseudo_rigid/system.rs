//! `lieflow.PseudoRigidBody`: binding of `lieflow::pseudo_rigid::system` (001 §3–§7). A thin
//! subclass of `lieflow.System`: constructor and observables. State z = (X row-major,
//! P row-major), d = 2n².
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::pseudo_rigid::PseudoRigidBody as CoreBody;
use lieflow::{Error, Mat};
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use super::potential::{PyPotential, Zero};
use crate::convert::int;
use crate::convert::ArrayIn;
use crate::errors::{to_py, IntoPy};
use crate::integrate::Callbacks;
use crate::system::PySystem;

type Any<'py> = Bound<'py, PyAny>;

/// A generalized pseudo-rigid body on T*GL+(n) with H = tr(P^T P)/2 + U(X) (001 (3.22)).
///
/// Args:
///     n: dimension (>= 2).
///     potential: a `lieflow.potentials` potential (default: Zero(), the free body).
///     check_det: stop with LeftDomainError (naming the time) when det X <= 0 (always on for a
///         volumetric potential; the equations extend to all n×n matrices otherwise).
///
/// Integrate with `lf.integrate(body, (X0, P0), dt=..., steps=..., method=...)`, methods
/// "verlet" (the default), "verlet4", "verlet6" (Störmer–Verlet and its order-4/6
/// compositions) and "reduced" (reduced-space splitting on the principal stratum, 001 §7,
/// order 2, exact coadjoint orbits). States are flat: z = (X row-major, P row-major), length
/// 2n²; fields X and P. Invariants: tr((L^T L)^k)/2 then tr((Γ^T Γ)^k)/2, k = 1..n//2.
#[pyclass(module = "lieflow", name = "PseudoRigidBody", extends = PySystem, frozen)]
pub struct PyPseudoRigidBody {
    body: CoreBody,
    potential: Py<PyPotential>,
}

impl PyPseudoRigidBody {
    fn n(&self) -> usize {
        self.body.n()
    }
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
    #[pyo3(signature = (n, potential=None, check_det=true))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = int)] n: i64,
        potential: Option<Bound<'_, PyPotential>>,
        check_det: bool,
    ) -> PyResult<PyClassInitializer<Self>> {
        let size = usize::try_from(n)
            .map_err(|_| to_py(Error::invalid("n", format!("expected n ≥ 2, got {n}"))))?;
        let potential = match potential {
            Some(p) => p,
            None => Bound::new(py, Zero(py)?)?,
        };
        let pot = potential.get();
        let body = CoreBody::new(size, pot.inner.clone(), check_det).py()?;
        let callbacks = pot.callback.clone().map(|c| c as Arc<dyn Callbacks>);
        let args = (n, potential.clone(), check_det).into_pyobject(py)?;
        let base = PySystem::new(body.clone(), args, &["n", "potential", "check_det"])
            .with_callbacks(callbacks);
        Ok(
            PyClassInitializer::from(base).add_subclass(PyPseudoRigidBody {
                body,
                potential: potential.unbind(),
            }),
        )
    }

    /// Constructor arguments of an example instance (for `methods()` on the class).
    #[classattr]
    fn _example_args() -> (i64,) {
        (2,)
    }

    /// The dimension n.
    #[getter(n)]
    fn get_n(&self) -> usize {
        self.n()
    }

    /// Whether det X > 0 is enforced during integrations.
    #[getter]
    fn check_det(&self) -> bool {
        self.body.check_det()
    }

    /// The potential.
    #[getter]
    fn potential(&self, py: Python<'_>) -> Py<PyPotential> {
        self.potential.clone_ref(py)
    }

    /// Angular momentum L = P X^T - X P^T (001 (7.3)) of states (..., d) -> (..., n, n).
    fn angular_momentum<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let n = slf.get().n();
        observe(slf, states, &[n, n], |b, z, out| {
            flat(&b.momenta(z)?.0, out)
        })
    }

    /// Circulation Γ = P^T X - X^T P (001 (7.3)) of states (..., d) -> (..., n, n).
    fn circulation<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let n = slf.get().n();
        observe(slf, states, &[n, n], |b, z, out| {
            flat(&b.momenta(z)?.1, out)
        })
    }

    /// Singular values a_1 >= ... >= a_n of X (the semi-axes), states (..., d) -> (..., n).
    fn singular_values<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let n = slf.get().n();
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
    let body = &slf.get().body;
    let base = slf.as_super().get();
    base.map_states(slf.py(), &states, shape, |z, out| f(body, z, out))
}
