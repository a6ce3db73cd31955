//! `lieflow.pseudo_rigid.RightReduced` and `reduced_euler_lagrange`: bindings of
//! `lieflow::pseudo_rigid::right_reduced` (001 §3, reduction by the right SO(n) action). A thin
//! subclass of `lieflow.System`: constructor, reduce/reconstruct and observables.
#![allow(non_snake_case)]

use lieflow::pseudo_rigid::right_reduced::{self as rr, RightReduced as Core};
use lieflow::{Error, Mat};
use pyo3::prelude::*;
use pyo3::PyClassInitializer;

use super::potential::{PyPotential, Zero};
use crate::convert::{int, mat, py_mat, ArrayIn};
use crate::errors::{raised, to_py, IntoPy};
use crate::system::{PySystem, Thin};

type Any<'py> = Bound<'py, PyAny>;

/// A pseudo-rigid body reduced by its right SO(n) symmetry, the relabelling of its particles
/// (001 §3): a system on :math:`T^*GL^+(n)/SO(n)` in the Riemann variables :math:`Q = X X^\top`,
/// :math:`N = X P^\top`.
///
/// :math:`H = \tfrac12 \operatorname{tr}(N^\top Q^{-1} N) + U`, the motion is the Riemann system
/// (001 (3.20)) and the Poisson structure (9.1). The circulation
/// :math:`\Gamma = P^\top X - X^\top P` is the momentum map of the symmetry: its spectral
/// invariants are the Casimirs (the reduced spaces :math:`\Gamma^{-1}(\gamma)/G_\gamma` of
/// 001 (3.27)), and with `reconstruct=True` the system carries X along, so the full motion and
/// its circulation come back with `reconstruct(states)`.
///
/// Args:
///     n: dimension (>= 2).
///     potential: a `lieflow.potentials` potential, right SO(n)-invariant (every built-in one
///         is; a Callable potential is checked at the initial state: InvalidArgumentError if
///         U(Xh) != U(X)). Default Zero().
///     reconstruct: carry X (state (Q, N, X), 3n² values) instead of (Q, N) (2n² values).
///
/// Methods: verlet (default), verlet4, verlet6, rk4. The Verlet methods are the full body's
/// Störmer–Verlet step reduced: a kick
/// :math:`N \leftarrow N - \tau C (\partial U/\partial X(C))^\top` (:math:`C C^\top = Q`) and the
/// exact drift :math:`Q \leftarrow Q + \tau (N + N^\top) + \tau^2 K`,
/// :math:`N \leftarrow N + \tau K`, :math:`K = N^\top Q^{-1} N`, and their Suzuki /
/// Yoshida compositions: Poisson maps that keep the Casimirs to round-off and reconstruct
/// exactly the full Verlet motion of the same steps. rk4 integrates the Riemann field, as a
/// baseline. Q cannot see the sign of :math:`\det X`: integrate motions that collapse through
/// :math:`\det X = 0` with the full `PseudoRigidBody`.
///
/// States are flat: (Q row-major, N row-major[, X row-major]); make them with `body.reduce(X, P)`.
/// Invariants: :math:`\tfrac12 \operatorname{tr}((L^\top L)^k)` then
/// :math:`\tfrac12 \operatorname{tr}((\Gamma^\top \Gamma)^k)`,
/// :math:`k = 1, \dots, \lfloor n/2 \rfloor` (the full body's values).
#[pyclass(module = "lieflow.pseudo_rigid", name = "RightReduced", extends = PySystem, frozen)]
pub struct PyRightReduced {
    potential: Py<PyPotential>,
}

fn body<'a>(slf: &'a Bound<'_, PyRightReduced>) -> PyResult<&'a Core> {
    slf.core()
}

fn flat(m: &Mat, out: &mut [f64]) {
    let n = m.nrows();
    for (k, o) in out.iter_mut().enumerate() {
        *o = m[(k / n, k % n)];
    }
}

#[pymethods]
impl PyRightReduced {
    #[new]
    #[pyo3(signature = (n, potential=None, reconstruct=false))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = int)] n: i64,
        potential: Option<Bound<'_, PyPotential>>,
        reconstruct: bool,
    ) -> PyResult<PyClassInitializer<Self>> {
        let size = usize::try_from(n)
            .map_err(|_| to_py(Error::invalid("n", format!("expected n ≥ 2, got {n}"))))?;
        let potential = match potential {
            Some(p) => p,
            None => Bound::new(py, Zero(py)?)?,
        };
        let mut core = Core::new(size, potential.get().inner.clone()).py()?;
        if reconstruct {
            core = core.reconstructing();
        }
        let args = (n, potential.clone(), reconstruct).into_pyobject(py)?;
        let this = PyRightReduced {
            potential: potential.unbind(),
        };
        Ok(PySystem::init(
            this,
            core,
            args,
            &["n", "potential", "reconstruct"],
        ))
    }

    /// The dimension n.
    #[getter(n)]
    fn get_n(slf: &Bound<'_, Self>) -> PyResult<usize> {
        Ok(body(slf)?.n())
    }

    /// Whether X is carried along (state (Q, N, X)).
    #[getter]
    fn reconstruct_configuration(slf: &Bound<'_, Self>) -> PyResult<bool> {
        Ok(body(slf)?.is_reconstructing())
    }

    /// The potential.
    #[getter]
    fn potential(&self, py: Python<'_>) -> Py<PyPotential> {
        self.potential.clone_ref(py)
    }

    /// The reduced state of a full one: :math:`(Q, N) = (X X^\top, X P^\top)` (001 (3.4)), then X
    /// when the system reconstructs.
    ///
    /// Args:
    ///     X: (n, n) with :math:`\det X > 0`; P: (n, n).
    /// Returns:
    ///     (d,) flat state.
    /// Raises:
    ///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0`).
    fn reduce<'py>(
        slf: &Bound<'py, Self>,
        X: ArrayIn<'py>,
        P: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
        let z = body(slf)?.reduce(&mat("X", &X)?, &mat("P", &P)?).py()?;
        Ok(numpy::PyArray1::from_vec(slf.py(), z))
    }

    /// The full states :math:`(X, P = N^\top X^{-\top})` of states (..., d) of a reconstructing
    /// system -> ((..., n, n), (..., n, n)).
    ///
    /// Raises:
    ///     InvalidArgumentError (the system does not carry X), ShapeError, NonFiniteError.
    fn reconstruct<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let b = body(slf)?;
        let n = b.n();
        let both = slf
            .base()
            .map_states(slf.py(), &states, &[2, n, n], |z, out| {
                let (x, p) = b.reconstruct(z)?;
                flat(&x, &mut out[..n * n]);
                flat(&p, &mut out[n * n..]);
                Ok(())
            })?;
        // (..., 2, n, n) -> the two (..., n, n) halves.
        let py = slf.py();
        let all = pyo3::types::PySlice::full(py);
        let half = |k: usize| both.get_item((pyo3::types::PyEllipsis::get(py), k, &all, &all));
        Ok((half(0)?, half(1)?).into_pyobject(py)?.into_any())
    }

    /// The three terms of the reduced Hamiltonian 001 (3.31) at the state's circulation gamma:
    /// [:math:`\tfrac12 \langle Y, Y \rangle` (the horizontal kinetic energy, on
    /// :math:`T^*(GL^+(n)/SO(n))`), :math:`\tfrac12 \langle \gamma, (A^R_X)^{-1} \gamma \rangle`
    /// (the locked energy of the relabelling), U]; they add up to H.
    /// States (..., d) -> (..., 3).
    fn hamiltonian_parts<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let b = body(slf)?;
        slf.base().map_states(slf.py(), &states, &[3], |z, out| {
            out.copy_from_slice(&b.hamiltonian_parts(z)?);
            Ok(())
        })
    }

    /// Angular momentum :math:`L = N^\top - N` (001 (2.29), (3.10)) of states (..., d) -> (..., n,
    /// n).
    fn angular_momentum<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let b = body(slf)?;
        let n = b.n();
        slf.base().map_states(slf.py(), &states, &[n, n], |z, out| {
            flat(&b.angular_momentum(z)?, out);
            Ok(())
        })
    }

    /// The circulation at the representative C (the Cholesky factor of Q):
    /// :math:`\Gamma_C = C^{-1} N C - C^\top N^\top C^{-\top}`, conjugate to the circulation of
    /// every X over (Q, N) (equal to it up to a rotation of the labels). States (..., d) -> (...,
    /// n, n).
    fn circulation<'py>(slf: &Bound<'py, Self>, states: ArrayIn<'py>) -> PyResult<Any<'py>> {
        let b = body(slf)?;
        let n = b.n();
        slf.base().map_states(slf.py(), &states, &[n, n], |z, out| {
            flat(&b.circulation(z)?, out);
            Ok(())
        })
    }
}

/// The reduced Euler–Lagrange equation (001 (3.17)) of a right SO(n)-invariant Lagrangian
/// :math:`L(Q, N)` in the Riemann variables :math:`Q = X X^\top`, :math:`N = X \dot X^\top`:
///
/// .. math::
///
///     \frac{d}{dt} (\partial L/\partial N)^\top
///         = (\partial L/\partial N - (\partial L/\partial N)^\top) N^\top Q^{-1}
///         + 2\, \partial L/\partial Q, \qquad \dot Q = N + N^\top.
///
/// For :math:`L = \tfrac12 \operatorname{tr}(N^\top Q^{-1} N) - U(Q)` it is the Riemann field
/// (001 (3.20)). :math:`\partial L/\partial Q` is the gradient over symmetric matrices (Q's
/// variations are symmetric). The Hessian of L in N and the mixed derivative along
/// :math:`\dot Q` are central differences of the gradient (steps :math:`\varepsilon^{1/3}`
/// relative).
///
/// Args:
///     lagrangian: L(Q, N) -> float, Q and N (n, n) arrays.
///     Q: (n, n) symmetric positive definite; N: (n, n).
///     gradient: optional (Q, N) -> (dL/dQ, dL/dN), two (n, n) arrays; without it the gradient is
///         a central difference of `lagrangian` (steps :math:`\varepsilon^{1/3}` relative) and
///         the Hessian a difference of that (steps :math:`\varepsilon^{2/9}`), so :math:`\dot N`
///         has about 7 digits instead of 10.
/// Returns:
///     :math:`(\dot Q, \dot N)`, two (n, n) arrays.
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError (Q not positive definite, or the Hessian
///     of L in N singular: L not regular); an exception of `lagrangian` or `gradient` propagates.
#[pyfunction]
#[pyo3(signature = (lagrangian, Q, N, gradient=None))]
pub fn reduced_euler_lagrange<'py>(
    py: Python<'py>,
    lagrangian: Bound<'py, PyAny>,
    Q: ArrayIn<'py>,
    N: ArrayIn<'py>,
    gradient: Option<Bound<'py, PyAny>>,
) -> PyResult<(Any<'py>, Any<'py>)> {
    for (what, f) in [
        ("lagrangian", Some(&lagrangian)),
        ("gradient", gradient.as_ref()),
    ] {
        if let Some(f) = f {
            if !f.is_callable() {
                return Err(crate::errors::argument_type_error(
                    py,
                    format!(
                        "{what} must be a callable (Q, N) -> ..., got {}",
                        f.get_type().name()?
                    ),
                ));
            }
        }
    }
    let (q, nn) = (mat("Q", &Q)?, mat("N", &N)?);
    let n = q.nrows();
    let value = |q: &Mat, nn: &Mat| -> lieflow::Result<f64> {
        let v = lagrangian
            .call1((py_mat(py, q), py_mat(py, nn)))
            .map_err(|e| raised("the lagrangian", e))?;
        v.extract::<f64>().map_err(|_| {
            let got = v
                .get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default();
            Error::invalid(
                "lagrangian",
                format!("the lagrangian must return a real number, got a {got}"),
            )
        })
    };
    let mut grad = |q: &Mat, nn: &Mat| -> lieflow::Result<(Mat, Mat)> {
        if let Some(g) = &gradient {
            let r = g
                .call1((py_mat(py, q), py_mat(py, nn)))
                .map_err(|e| raised("the gradient", e))?;
            let (a, b): (Bound<'_, PyAny>, Bound<'_, PyAny>) = r.extract().map_err(|_| {
                Error::invalid(
                    "gradient",
                    "the gradient must return a pair (dL/dQ, dL/dN) of (n, n) arrays",
                )
            })?;
            let conv = |what: &str, x: &Bound<'_, PyAny>| -> lieflow::Result<Mat> {
                let arr = ArrayIn::named(what, x).map_err(|e| raised(what, e))?;
                let m = mat(what, &arr).map_err(|e| raised(what, e))?;
                lieflow::check::square_of(what, &m, n)?;
                lieflow::check::finite_mat(what, &m)?;
                Ok(m)
            };
            return Ok((conv("dL/dQ", &a)?, conv("dL/dN", &b)?));
        }
        rr::lagrangian_gradient(&value, q, nn)
    };
    let (qd, nd) = rr::euler_lagrange(&mut grad, &q, &nn, gradient.is_none()).py()?;
    Ok((py_mat(py, &qd).into_any(), py_mat(py, &nd).into_any()))
}
