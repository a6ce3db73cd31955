//! The equations of motion of 001 in `lieflow.pseudo_rigid`: bindings of
//! `lieflow::pseudo_rigid::{dynamics, momentum, reduced}` — the Riemann field (3.20), E (4.8), the
//! Euler–Lagrange field of Prop. 4.2 (its n = 3 form (5.5) as the fast path), the reduced
//! Hamiltonian (7.24) and the reduced field (7.25)–(7.28). Conversions only.
//!
//! Every function follows the module's vectorisation rule (`crate::items`): leading axes
//! broadcast, n is read from the first matrix argument. A potential made of Python callables is
//! called on this thread (its exception re-raised); the built-in ones map in parallel.
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::lie::so3;
use lieflow::pseudo_rigid::dynamics::FullBody;
use lieflow::pseudo_rigid::momentum as mo;
use lieflow::pseudo_rigid::potential::{Potential, Zero as CoreZero};
use lieflow::pseudo_rigid::reduced::ReducedState;
use nalgebra::{Matrix3, Vector3};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use super::potential::PyPotential;
use super::{m, Kind, Kind::*};
use crate::convert::{put_mats, ArrayIn};
use crate::errors::{checked, IntoPy};
use crate::items::{map_items_n, matrix_item, par_map_items_n, Input};

type Any<'py> = Bound<'py, PyAny>;

/// The body of dimension n with the given potential (the free body for None).
fn body(n: usize, potential: Option<&Bound<'_, PyPotential>>) -> PyResult<FullBody> {
    let u: Arc<dyn Potential> = match potential {
        Some(p) => p.get().inner.clone(),
        None => Arc::new(CoreZero),
    };
    FullBody::new(n, u).py()
}

/// n of the matrix argument `what`, (..., n, n).
fn n_of(what: &str, a: &ArrayIn<'_>) -> PyResult<usize> {
    Ok(matrix_item(what, a)?[0])
}

/// `f(items, out)` over the items of `args` (every input checked finite), the outputs of kinds
/// `outs` written one after another into `out`; on this thread when the body's potential calls
/// Python (`calls_out`, its exception re-raised first), else in parallel. Returns one array, or
/// a tuple of them.
fn map_body<'py, F>(
    py: Python<'py>,
    n: usize,
    calls_out: bool,
    args: &[(&str, &ArrayIn<'py>, Kind)],
    outs: &[Kind],
    f: F,
) -> PyResult<Any<'py>>
where
    F: Fn(&[&[f64]], &mut [f64]) -> lieflow::Result<()> + Sync + Send,
{
    let items: Vec<Vec<usize>> = args.iter().map(|a| a.2.shape(n)).collect();
    let inputs: Vec<Input> = args
        .iter()
        .zip(&items)
        .map(|(a, item)| Input::finite(a.0, a.1, item))
        .collect();
    let outs: Vec<Vec<usize>> = outs.iter().map(|o| o.shape(n)).collect();
    let outs: Vec<&[usize]> = outs.iter().map(Vec::as_slice).collect();
    checked(|| {
        Ok(match calls_out {
            true => map_items_n(py, &inputs, &outs, f),
            false => par_map_items_n(py, &inputs, &outs, f),
        })
    })?
}

/// The tuple `values` of a mapping as a dict under `keys`.
fn dict<'py>(py: Python<'py>, keys: &[&str], values: &Any<'py>) -> PyResult<Bound<'py, PyDict>> {
    let values = values.cast::<PyTuple>()?;
    let d = PyDict::new(py);
    for (k, v) in keys.iter().zip(values.iter()) {
        d.set_item(*k, v)?;
    }
    Ok(d)
}

/// A 3×3 matrix written row-major into `out`.
fn put3(out: &mut [f64], a: &Matrix3<f64>) {
    for i in 0..3 {
        for j in 0..3 {
            out[3 * i + j] = a[(i, j)];
        }
    }
}

/// An n = 3 item (a, Omega, Lambda) as the vectors of 001 §5 (physics hat map, hat(ω) = Ω),
/// after the checks of the general form ([`mo::check_velocities`]).
fn vectors3(x: &[&[f64]]) -> lieflow::Result<[Vector3<f64>; 3]> {
    mo::check_velocities(x[0], &m(3, x[1]), &m(3, x[2]))?;
    let vee = |v: &[f64]| so3::vee_unchecked(&Matrix3::from_row_slice(v));
    Ok([Vector3::from_column_slice(x[0]), vee(x[1]), vee(x[2])])
}

/// The reduced state (a, p_a, p_Omega, p_Lambda) of an item.
fn reduced_state(n: usize, x: &[&[f64]]) -> ReducedState {
    ReducedState {
        a: x[0].to_vec(),
        p_a: x[1].to_vec(),
        p_omega: m(n, x[2]),
        p_lambda: m(n, x[3]),
    }
}

/// The Riemann-ellipsoid equations (001 (3.20)) in :math:`Q = X X^\top`, :math:`N = X V^\top`:
/// :math:`\dot Q = N + N^\top`, :math:`\dot N = N^\top Q^{-1} N - 2 Q\, \partial U/\partial Q`; the
/// force term is computed as :math:`X (\partial U/\partial X)^\top` at :math:`X = Q^{1/2}` (the
/// same for every X with :math:`X X^\top = Q`, U being :math:`SO(n) \times SO(n)`-invariant).
/// With :math:`N = X V^\top` from `riemann_variables`, :math:`\dot N` is
/// :math:`V V^\top - X (\partial U/\partial X)^\top`, the Riemann form of
/// :math:`\ddot X = -\partial U/\partial X`.
///
/// Args:
///     Q: (n, n), symmetric positive definite.
///     N: (n, n).
///     potential: a `lieflow.potentials` potential (default: the free body).
/// Returns:
///     (Qdot, Ndot): two (n, n) arrays.
/// Raises:
///     NotInGroupError (Q not symmetric to 1e-10 relative, or not positive definite),
///     ShapeError, NonFiniteError, InvalidArgumentError (a potential of another dimension).
#[pyfunction]
#[pyo3(signature = (Q, N, potential=None))]
pub fn riemann_vector_field<'py>(
    py: Python<'py>,
    Q: ArrayIn<'py>,
    N: ArrayIn<'py>,
    potential: Option<Bound<'py, PyPotential>>,
) -> PyResult<Any<'py>> {
    let n = n_of("Q", &Q)?;
    let body = body(n, potential.as_ref())?;
    let args = [("Q", &Q, Mat), ("N", &N, Mat)];
    let calls_out = body.potential().calls_out();
    map_body(py, n, calls_out, &args, &[Mat, Mat], |x, out| {
        let (q_dot, n_dot) = body.riemann_vector_field(&m(n, x[0]), &m(n, x[1]))?;
        put_mats(out, &[&q_dot, &n_dot])
    })
}

/// The E term of 001 (4.8),
/// :math:`E = D(-(\Omega^2 + \Lambda^2) A + \Omega A \Lambda + \Lambda A \Omega)` with
/// :math:`A = \operatorname{diag}(a)` and D the diagonal part: :math:`E = \partial K/\partial A` at
/// fixed :math:`\Omega`, :math:`\Lambda` and :math:`\dot A`, K the kinetic energy (4.5). At n = 3
/// through the vector form (5.4),
/// :math:`E_1 = a_1 (w_2^2 + w_3^2 + l_2^2 + l_3^2) - 2 a_2 w_3 l_3 - 2 a_3 w_2 l_2` and cyclically
/// (:math:`\hat w = \Omega`, :math:`\hat l = \Lambda`).
///
/// Args:
///     a: (n,) singular values, all > 0; Omega, Lambda: (n, n) skew body velocities.
/// Returns:
///     (n,) array, the diagonal of E.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (Omega, Lambda not skew),
///     InvalidArgumentError (some :math:`a_i \le 0`).
#[pyfunction]
pub fn e_term<'py>(
    py: Python<'py>,
    a: ArrayIn<'py>,
    Omega: ArrayIn<'py>,
    Lambda: ArrayIn<'py>,
) -> PyResult<Any<'py>> {
    let n = n_of("Omega", &Omega)?;
    let args = [
        ("a", &a, Vector),
        ("Omega", &Omega, Mat),
        ("Lambda", &Lambda, Mat),
    ];
    map_body(py, n, false, &args, &[Vector], |x, out| {
        if n == 3 {
            let [a, w, l] = vectors3(x)?;
            out.copy_from_slice(mo::e_term_3(&a, &w, &l).as_slice());
        } else {
            out.copy_from_slice(&mo::e_term(x[0], &m(n, x[1]), &m(n, x[2]))?);
        }
        Ok(())
    })
}

/// The Euler–Lagrange equations of 001 Prop. 4.2 in body coordinates :math:`X = R A S^\top`,
/// :math:`\Omega = R^\top \dot R`, :math:`\Lambda = S^\top \dot S`: (4.11a)
/// :math:`\ddot A = E - \partial U/\partial A`, (4.11b) :math:`\dot p_\Omega = [p_\Omega, \Omega]`,
/// (4.11c) :math:`\dot p_\Lambda = [p_\Lambda, \Lambda]`, with E of (4.8) and the body momenta
/// (4.15) :math:`p_\Omega = A^2 \Omega + \Omega A^2 - 2 A \Lambda A = R^\top L R`,
/// :math:`p_\Lambda = A^2 \Lambda + \Lambda A^2 - 2 A \Omega A = S^\top \Gamma S`. At n = 3
/// through the vector form (5.5): :math:`\ddot a = E - \nabla U(a)`, :math:`\dot m = m \times w`,
/// :math:`\dot c = c \times l` (:math:`\hat w = \Omega`, :math:`\hat l = \Lambda`,
/// :math:`\hat m = p_\Omega`, :math:`\hat c = p_\Lambda`).
///
/// Args:
///     a: (n,) singular values, all > 0; Omega, Lambda: (n, n) skew; potential: a
///     `lieflow.potentials` potential (default: the free body).
/// Returns:
///     dict with "p_Omega", "p_Lambda" ((n, n)), "E", "addot" ((n,): E and the acceleration
///     :math:`\ddot a`), "p_Omegadot", "p_Lambdadot" ((n, n)).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (Omega, Lambda not skew),
///     InvalidArgumentError (some :math:`a_i \le 0`, a potential of another dimension).
#[pyfunction]
#[pyo3(signature = (a, Omega, Lambda, potential=None))]
pub fn lagrange_vector_field<'py>(
    py: Python<'py>,
    a: ArrayIn<'py>,
    Omega: ArrayIn<'py>,
    Lambda: ArrayIn<'py>,
    potential: Option<Bound<'py, PyPotential>>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = n_of("Omega", &Omega)?;
    let body = body(n, potential.as_ref())?;
    let args = [
        ("a", &a, Vector),
        ("Omega", &Omega, Mat),
        ("Lambda", &Lambda, Mat),
    ];
    let outs = [Mat, Mat, Vector, Vector, Mat, Mat];
    let calls_out = body.potential().calls_out();
    let values = map_body(py, n, calls_out, &args, &outs, |x, out| {
        let vv = 2 * n * n;
        if n == 3 {
            let [a, w, l] = vectors3(x)?;
            let r = body.lagrange_vector_field_3d(&a, &w, &l)?;
            put3(&mut out[..9], &so3::hat(&r.m));
            put3(&mut out[9..18], &so3::hat(&r.c));
            out[18..21].copy_from_slice(r.e.as_slice());
            out[21..24].copy_from_slice(r.a_ddot.as_slice());
            put3(&mut out[24..33], &so3::hat(&r.m_dot));
            put3(&mut out[33..], &so3::hat(&r.c_dot));
            return Ok(());
        }
        let r = body.lagrange_vector_field(x[0], &m(n, x[1]), &m(n, x[2]))?;
        put_mats(&mut out[..vv], &[&r.p_omega, &r.p_lambda])?;
        out[vv..vv + n].copy_from_slice(&r.e);
        out[vv + n..vv + 2 * n].copy_from_slice(&r.a_ddot);
        put_mats(&mut out[vv + 2 * n..], &[&r.p_omega_dot, &r.p_lambda_dot])?;
        Ok(())
    })?;
    let keys = [
        "p_Omega",
        "p_Lambda",
        "E",
        "addot",
        "p_Omegadot",
        "p_Lambdadot",
    ];
    dict(py, &keys, &values)
}

/// The reduced Hamiltonian (001 (7.24), the form (6.30) at the reduced momenta)
///
/// .. math::
///
///     H = \tfrac12 \langle p_a, p_a \rangle
///         + \tfrac12 \langle p_\Omega + p_\Lambda, B_A^{-1}(p_\Omega + p_\Lambda) \rangle
///         + U(A)
///
/// with :math:`A = \operatorname{diag}(a)` on the principal stratum, evaluated as a sum of pair
/// terms :math:`\tfrac14 ((m + v)^2 / (a_i - a_j)^2 + (m - v)^2 / (a_i + a_j)^2)` over
/// :math:`i < j` (:math:`m = (p_\Omega)_{ij}`, :math:`v = (p_\Lambda)_{ij}`; the eigenvalues of
/// :math:`B_A`, (8.15)).
///
/// Args:
///     a, p_a: (n,) (:math:`a_i > 0`, pairwise distinct); p_Omega, p_Lambda: (n, n) skew — the
///         values of `reduce`'s dict; potential: a `lieflow.potentials` potential (default: the
///         free body).
/// Returns:
///     float (an array for leading axes).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (p's not skew), InvalidArgumentError
///     (:math:`a_i \le 0`, a potential of another dimension), DegenerateStratumError (equal
///     :math:`a_i`).
#[pyfunction]
#[pyo3(signature = (a, p_a, p_Omega, p_Lambda, potential=None))]
pub fn reduced_hamiltonian<'py>(
    py: Python<'py>,
    a: ArrayIn<'py>,
    p_a: ArrayIn<'py>,
    p_Omega: ArrayIn<'py>,
    p_Lambda: ArrayIn<'py>,
    potential: Option<Bound<'py, PyPotential>>,
) -> PyResult<Any<'py>> {
    let n = n_of("p_Omega", &p_Omega)?;
    let body = body(n, potential.as_ref())?;
    let args = [
        ("a", &a, Vector),
        ("p_a", &p_a, Vector),
        ("p_Omega", &p_Omega, Mat),
        ("p_Lambda", &p_Lambda, Mat),
    ];
    let calls_out = body.potential().calls_out();
    map_body(py, n, calls_out, &args, &[Scalar], |x, out| {
        out[0] = reduced_state(n, x).hamiltonian(&body)?;
        Ok(())
    })
}

/// The reduced Hamilton equations (001 (7.25)–(7.28)) on the principal stratum:
/// :math:`\dot a = p_a`, :math:`\dot p_a = -\partial H/\partial a` (7.28), and the Lie–Poisson
/// equations (7.25)–(7.27) :math:`\dot p_\Omega = [p_\Omega, \Omega]`,
/// :math:`\dot p_\Lambda = [p_\Lambda, \Lambda]` with
/// :math:`\Omega + \Lambda = B_A^{-1}(p_\Omega + p_\Lambda)` (7.9), H of `reduced_hamiltonian`.
/// Arguments and errors as `reduced_hamiltonian`.
///
/// Returns:
///     dict with the rate of each variable under its name: "a", "p_a" ((n,)), "p_Omega",
///     "p_Lambda" ((n, n)), so that ``state[k] + dt * field[k]`` is an Euler step.
#[pyfunction]
#[pyo3(signature = (a, p_a, p_Omega, p_Lambda, potential=None))]
pub fn reduced_vector_field<'py>(
    py: Python<'py>,
    a: ArrayIn<'py>,
    p_a: ArrayIn<'py>,
    p_Omega: ArrayIn<'py>,
    p_Lambda: ArrayIn<'py>,
    potential: Option<Bound<'py, PyPotential>>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = n_of("p_Omega", &p_Omega)?;
    let body = body(n, potential.as_ref())?;
    let args = [
        ("a", &a, Vector),
        ("p_a", &p_a, Vector),
        ("p_Omega", &p_Omega, Mat),
        ("p_Lambda", &p_Lambda, Mat),
    ];
    let calls_out = body.potential().calls_out();
    let values = map_body(
        py,
        n,
        calls_out,
        &args,
        &[Vector, Vector, Mat, Mat],
        |x, out| {
            let r = reduced_state(n, x).vector_field(&body)?;
            out[..n].copy_from_slice(&r.a_dot);
            out[n..2 * n].copy_from_slice(&r.p_a_dot);
            put_mats(&mut out[2 * n..], &[&r.p_omega_dot, &r.p_lambda_dot])
        },
    )?;
    dict(py, &["a", "p_a", "p_Omega", "p_Lambda"], &values)
}

/// Adds the functions to `lieflow.pseudo_rigid`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(riemann_vector_field, m)?)?;
    m.add_function(wrap_pyfunction!(e_term, m)?)?;
    m.add_function(wrap_pyfunction!(lagrange_vector_field, m)?)?;
    m.add_function(wrap_pyfunction!(reduced_hamiltonian, m)?)?;
    m.add_function(wrap_pyfunction!(reduced_vector_field, m)?)?;
    Ok(())
}
