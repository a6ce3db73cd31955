//! `lieflow.pseudo_rigid`: bindings of `lieflow::pseudo_rigid` (001: generalized pseudo-rigid
//! bodies on GL+(n)). Conversions only; every formula lives in the core crate.
//!
//! Conventions: so(n) elements are skew (n, n) arrays; matrices on so(n) + so(n) are in the e_ij
//! basis (i < j, row by row) with the xi block first; pairing <xi, eta> = tr(xi.T @ eta) / 2.
#![allow(non_snake_case)]

pub mod ellipsoids;
pub mod equilibria;
pub mod gravity;
pub mod potential;
pub mod system;

use lieflow::lie::gl::STRATUM_TOL;
use lieflow::pseudo_rigid::{
    connection as cn, momentum as mo, riemann, strata, Action, BiInertia, Body,
};
use lieflow::Mat;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::real;
use crate::convert::{mat, py_mat, py_vec, vector, ArrayIn};
use crate::errors::IntoPy;

type Arr2<'py> = Bound<'py, PyArray2<f64>>;
type Arr1<'py> = Bound<'py, PyArray1<f64>>;

fn at(X: &ArrayIn<'_>) -> PyResult<BiInertia> {
    BiInertia::new(&mat("X", X)?).py()
}

/// [`at`] for the functions that return a dense n(n−1)×n(n−1) matrix: refuses sizes that cannot
/// be allocated (an abort would take the Python process down) with InvalidArgumentError.
fn at_dense(X: &ArrayIn<'_>) -> PyResult<BiInertia> {
    let b = at(X)?;
    let d = b.n() * (b.n() - 1);
    lieflow::check::dense_size("X", d, d).py()?;
    Ok(b)
}

fn pair<'py>(py: Python<'py>, (a, b): (Mat, Mat)) -> (Arr2<'py>, Arr2<'py>) {
    (py_mat(py, &a), py_mat(py, &b))
}

/// Left inertia tensor A^L_X(xi) = X X^T xi + xi X X^T (001 (2.11)).
///
/// Args:
///     X: (n, n) with det X > 0; xi: (n, n) skew.
/// Returns:
///     (n, n) skew array.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (det X <= 0 or xi not skew).
#[pyfunction]
pub fn left_inertia<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    xi: ArrayIn<'py>,
) -> PyResult<Arr2<'py>> {
    Ok(py_mat(py, &at(&X)?.left(&mat("xi", &xi)?).py()?))
}

/// Right inertia tensor A^R_X(xi) = X^T X xi + xi X^T X (001 (2.11)).
///
/// Args and errors as `left_inertia`.
#[pyfunction]
pub fn right_inertia<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    xi: ArrayIn<'py>,
) -> PyResult<Arr2<'py>> {
    Ok(py_mat(py, &at(&X)?.right(&mat("xi", &xi)?).py()?))
}

/// The bi-inertia tensor B_X (001 (6.9)) as an (n(n-1), n(n-1)) matrix in the e_ij basis, xi
/// block first: [[A^L_X, -2 Ad_X], [-2 Ad_X^T, A^R_X]]. Symmetric on all of GL+(n), positive
/// definite when the singular values of X are distinct (6.14).
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (det X <= 0).
#[pyfunction]
pub fn bi_inertia<'py>(py: Python<'py>, X: ArrayIn<'py>) -> PyResult<Arr2<'py>> {
    Ok(py_mat(py, &at_dense(&X)?.try_matrix().py()?))
}

/// B_X(xi + eta) = (A^L_X xi - 2 X eta X^T, -2 X^T xi X + A^R_X eta) (001 (6.9), (6.10)).
///
/// Returns:
///     (top, bottom): two (n, n) skew arrays.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn bi_inertia_apply<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    xi: ArrayIn<'py>,
    eta: ArrayIn<'py>,
) -> PyResult<(Arr2<'py>, Arr2<'py>)> {
    let r = at(&X)?.apply(&mat("xi", &xi)?, &mat("eta", &eta)?).py()?;
    Ok(pair(py, r))
}

/// Solves B_X(xi + eta) = lam + gam by the closed form in the SVD frame (001 (7.6)-(7.9)), in
/// O(n^3) work: lam' = R^T lam R, gam' = S^T gam S,
/// xi'_ij = ((a_i^2 + a_j^2) lam'_ij + 2 a_i a_j gam'_ij) / (a_i^2 - a_j^2)^2 (and symmetrically
/// for eta'), rotated back.
///
/// Returns:
///     (xi, eta): two (n, n) skew arrays.
/// Raises:
///     DegenerateStratumError if two singular values of X coincide (gap <= 1e-8 * a_1; the
///     message gives the smallest gap), ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn bi_inertia_solve<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    lam: ArrayIn<'py>,
    gam: ArrayIn<'py>,
) -> PyResult<(Arr2<'py>, Arr2<'py>)> {
    let r = at(&X)?.solve(&mat("lam", &lam)?, &mat("gam", &gam)?).py()?;
    Ok(pair(py, r))
}

/// Eigen-decomposition of B_X (001 (8.14)-(8.15)): eigenvalues (a_i - a_j)^2 and (a_i + a_j)^2
/// (i < j) with orthonormal eigenvectors (R e_ij R^T + (+/-) S e_ij S^T) / sqrt(2). Valid on all
/// of GL+(n).
///
/// Returns:
///     (values, vectors): (n(n-1),) non-decreasing and (n(n-1), n(n-1)) with the eigenvectors
///     as columns in e_ij coordinates (xi block first): B = V diag(values) V^T.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn bi_inertia_eigen<'py>(py: Python<'py>, X: ArrayIn<'py>) -> PyResult<(Arr1<'py>, Arr2<'py>)> {
    let (vals, vecs) = at_dense(&X)?.eigen().py()?;
    Ok((py_vec(py, &vals), py_mat(py, &vecs)))
}

/// The quadratic form <xi + eta, B_X(xi + eta)> in SVD coordinates (001 (6.14)); equals
/// ‖xi X + X eta^T‖_F^2.
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn bi_inertia_quadratic_form(
    X: ArrayIn<'_>,
    xi: ArrayIn<'_>,
    eta: ArrayIn<'_>,
) -> PyResult<f64> {
    at(&X)?
        .quadratic_form(&mat("xi", &xi)?, &mat("eta", &eta)?)
        .py()
}

/// Left connection omega^L_X(Y) = (A^L_X)^{-1}(Y X^T - X Y^T) (001 (2.14)); defined on all of
/// GL+(n) (omega^L(xi X) = xi, (2.16)).
///
/// Args:
///     X: (n, n) with det X > 0; Y: (n, n) tangent vector.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn left_connection<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    Y: ArrayIn<'py>,
) -> PyResult<Arr2<'py>> {
    Ok(py_mat(
        py,
        &cn::left_connection(&at(&X)?, &mat("Y", &Y)?).py()?,
    ))
}

/// Right connection omega^R_X(Y) = (A^R_X)^{-1}(Y^T X - X^T Y) (001 (2.15)); defined on all of
/// GL+(n) (omega^R(X eta^T) = eta, (2.17)).
///
/// Args and errors as `left_connection`.
#[pyfunction]
pub fn right_connection<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    Y: ArrayIn<'py>,
) -> PyResult<Arr2<'py>> {
    Ok(py_mat(
        py,
        &cn::right_connection(&at(&X)?, &mat("Y", &Y)?).py()?,
    ))
}

/// Bi-connection omega^B_X(Y) = B_X^{-1}((Y X^T - X Y^T) + (Y^T X - X^T Y)) (001 (6.18)), via
/// the closed-form inverse. omega^B(xi X + X eta^T) = (xi, eta) (6.19).
///
/// Returns:
///     (xi, eta): two (n, n) skew arrays.
/// Raises:
///     DegenerateStratumError (coincident singular values), ShapeError, NonFiniteError,
///     NotInGroupError.
#[pyfunction]
pub fn bi_connection<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    Y: ArrayIn<'py>,
) -> PyResult<(Arr2<'py>, Arr2<'py>)> {
    let r = cn::bi_connection(&at(&X)?, &mat("Y", &Y)?).py()?;
    Ok(pair(py, r))
}

/// The vertical vector (xi + eta)_P(X) = xi X + X eta^T (001 (6.17)).
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (det X <= 0, xi or eta not skew).
#[pyfunction]
pub fn vertical_vector<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    xi: ArrayIn<'py>,
    eta: ArrayIn<'py>,
) -> PyResult<Arr2<'py>> {
    let v = cn::vertical_vector(&at(&X)?, &mat("xi", &xi)?, &mat("eta", &eta)?).py()?;
    Ok(py_mat(py, &v))
}

/// Horizontal part of Y at X for an action (001 (2.18)-(2.22), (6.4)-(6.7), (6.23)): Y minus
/// its orthogonal projection (metric tr(Y^T Z)) onto the orbit's tangent space. "left": the
/// result H has H X^T = X H^T; "right": H^T X = X^T H; "two-sided": both. Defined on every
/// stratum (the two-sided projection uses the least-squares inverse of B_X).
///
/// Args:
///     X: (n, n) with det X > 0; Y: (n, n); action: "two-sided" (default), "left" or "right".
/// Raises:
///     InvalidArgumentError (unknown action), ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
#[pyo3(signature = (X, Y, action = "two-sided"))]
pub fn horizontal_part<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    Y: ArrayIn<'py>,
    action: &str,
) -> PyResult<Arr2<'py>> {
    let action: Action = action.parse().py()?;
    Ok(py_mat(
        py,
        &cn::horizontal_part(&at(&X)?, &mat("Y", &Y)?, action).py()?,
    ))
}

/// Locked inertia tensor from the metric tr(Y^T Z) (001 (2.27), (6.24)): the matrix of
/// tr(V(e_a)^T V(e_b)) with V(xi) = xi X ("left"), X xi^T ("right") or xi X + X eta^T
/// ("two-sided", xi block first). Equals A^L_X, A^R_X, B_X.
///
/// Raises:
///     InvalidArgumentError (unknown action), ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
#[pyo3(signature = (X, action = "two-sided"))]
pub fn locked_inertia<'py>(py: Python<'py>, X: ArrayIn<'py>, action: &str) -> PyResult<Arr2<'py>> {
    let action: Action = action.parse().py()?;
    Ok(py_mat(
        py,
        &cn::locked_inertia(&at_dense(&X)?, action).py()?,
    ))
}

/// Angular momentum L = V X^T - X V^T (001 (2.29), (7.3)) of a velocity or momentum V at X.
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (det X <= 0).
#[pyfunction]
pub fn angular_momentum<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    V: ArrayIn<'py>,
) -> PyResult<Arr2<'py>> {
    Ok(py_mat(
        py,
        &mo::angular_momentum(&mat("X", &X)?, &mat("V", &V)?).py()?,
    ))
}

/// Circulation Gamma = V^T X - X^T V (001 (2.29), (7.3)) of a velocity or momentum V at X.
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (det X <= 0).
#[pyfunction]
pub fn circulation<'py>(py: Python<'py>, X: ArrayIn<'py>, V: ArrayIn<'py>) -> PyResult<Arr2<'py>> {
    Ok(py_mat(
        py,
        &mo::circulation(&mat("X", &X)?, &mat("V", &V)?).py()?,
    ))
}

type BodyTuple<'py> = (
    Arr2<'py>,
    Arr1<'py>,
    Arr2<'py>,
    Arr2<'py>,
    Arr1<'py>,
    Arr2<'py>,
);

/// Body coordinates (R, a, S, Omega, adot, Lambda) of (X, V) (001 (2.4), (2.33), §4.1):
/// X = R diag(a) S^T,
/// Omega = R^T dR/dt, Lambda = S^T dS/dt, from R^T V S = Omega A + Adot - A Lambda.
///
/// Returns:
///     (R, a, S, Omega, adot, Lambda).
/// Raises:
///     DegenerateStratumError (coincident singular values: Omega, Lambda undetermined),
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn to_body<'py>(py: Python<'py>, X: ArrayIn<'py>, V: ArrayIn<'py>) -> PyResult<BodyTuple<'py>> {
    let b = mo::to_body(&mat("X", &X)?, &mat("V", &V)?).py()?;
    Ok((
        py_mat(py, &b.r),
        py_vec(py, &b.a),
        py_mat(py, &b.s),
        py_mat(py, &b.omega),
        py_vec(py, &b.adot),
        py_mat(py, &b.lambda),
    ))
}

/// (X, V) from body coordinates: X = R A S^T, V = R (Omega A + Adot - A Lambda) S^T
/// (001 (2.4), (2.33), §4.1).
///
/// Args:
///     R, S: (n, n) rotations; a: (n,) positive; Omega, Lambda: (n, n) skew; adot: (n,).
/// Returns:
///     (X, V).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (R, S not rotations, Omega, Lambda not skew),
///     InvalidArgumentError (some a_i <= 0).
#[pyfunction]
pub fn from_body<'py>(
    py: Python<'py>,
    R: ArrayIn<'py>,
    a: ArrayIn<'py>,
    S: ArrayIn<'py>,
    Omega: ArrayIn<'py>,
    adot: ArrayIn<'py>,
    Lambda: ArrayIn<'py>,
) -> PyResult<(Arr2<'py>, Arr2<'py>)> {
    let body = Body {
        r: mat("R", &R)?,
        a: vector("a", &a)?,
        s: mat("S", &S)?,
        omega: mat("Omega", &Omega)?,
        adot: vector("adot", &adot)?,
        lambda: mat("Lambda", &Lambda)?,
    };
    Ok(pair(py, body.to_state().py()?))
}

/// Kinetic energy K = tr(V^T V) / 2 (001 (3.2); equal to (4.5), (4.12), (6.28)).
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn kinetic_energy(X: ArrayIn<'_>, V: ArrayIn<'_>) -> PyResult<f64> {
    mo::kinetic_energy(&mat("X", &X)?, &mat("V", &V)?).py()
}

/// Stratum and isotropy of X under the two-sided SO(n) x SO(n) action (001 (6.2), (9.2), (9.3)).
///
/// Args:
///     X: (n, n) with det X > 0; tol: relative tolerance for coinciding singular values
///     (default 1e-8).
/// Returns:
///     dict with "singular_values", "multiplicities", "min_gap", "principal", "dim_vertical"
///     (rank of (xi, eta) -> xi X + X eta^T), "dim_horizontal", "isotropy" (e.g. "(Z2)^2",
///     "S(O(2)×O(1))", "SO(3)") and "isotropy_dim".
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError, InvalidArgumentError (tol < 0).
#[pyfunction]
#[pyo3(signature = (X, tol = STRATUM_TOL), text_signature = "(X, tol=1e-8)")]
pub fn stratum<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    #[pyo3(from_py_with = real)] tol: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let info = strata::classify(&mat("X", &X)?, tol).py()?;
    let d = PyDict::new(py);
    d.set_item("singular_values", py_vec(py, &info.stratum.a))?;
    d.set_item("multiplicities", info.stratum.multiplicities.clone())?;
    d.set_item("min_gap", info.stratum.min_gap)?;
    d.set_item("principal", info.stratum.is_principal())?;
    d.set_item("dim_vertical", info.dim_vertical)?;
    d.set_item("dim_horizontal", info.dim_horizontal)?;
    d.set_item("isotropy", info.isotropy)?;
    d.set_item("isotropy_dim", info.isotropy_dim)?;
    Ok(d)
}
// The text_signature above spells the default out for help() and the stubs.
const _: () = assert!(STRATUM_TOL == 1e-8);

/// Riemann-ellipsoid variables (001 (3.4)): Q = X X^T (quadrupole), N = X V^T (shear);
/// N = (-L + dQ/dt) / 2 (3.10).
///
/// Returns:
///     (Q, N).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn riemann_variables<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    V: ArrayIn<'py>,
) -> PyResult<(Arr2<'py>, Arr2<'py>)> {
    Ok(pair(
        py,
        riemann::riemann_variables(&mat("X", &X)?, &mat("V", &V)?).py()?,
    ))
}

/// Poisson bracket {f, g} of functions of (Q, N) from the structure functions (001 (9.1)):
/// {Q_ij, Q_kl} = 0, {Q_ij, N_kl} = d_il Q_jk + d_jl Q_ik, {N_ij, N_kl} = d_il N_kj - d_jk N_il.
///
/// Args:
///     Q, N: (n, n); dfdQ, dfdN, dgdQ, dgdN: (n, n) gradients (entries taken as coordinates).
/// Raises:
///     ShapeError, NonFiniteError.
#[pyfunction]
pub fn riemann_bracket(
    Q: ArrayIn<'_>,
    N: ArrayIn<'_>,
    dfdQ: ArrayIn<'_>,
    dfdN: ArrayIn<'_>,
    dgdQ: ArrayIn<'_>,
    dgdN: ArrayIn<'_>,
) -> PyResult<f64> {
    let (fq, fnn) = (mat("dfdQ", &dfdQ)?, mat("dfdN", &dfdN)?);
    let (gq, gn) = (mat("dgdQ", &dgdQ)?, mat("dgdN", &dgdN)?);
    riemann::poisson_bracket(&mat("Q", &Q)?, &mat("N", &N)?, (&fq, &fnn), (&gq, &gn)).py()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(left_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(right_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(bi_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(bi_inertia_apply, m)?)?;
    m.add_function(wrap_pyfunction!(bi_inertia_solve, m)?)?;
    m.add_function(wrap_pyfunction!(bi_inertia_eigen, m)?)?;
    m.add_function(wrap_pyfunction!(bi_inertia_quadratic_form, m)?)?;
    m.add_function(wrap_pyfunction!(left_connection, m)?)?;
    m.add_function(wrap_pyfunction!(right_connection, m)?)?;
    m.add_function(wrap_pyfunction!(bi_connection, m)?)?;
    m.add_function(wrap_pyfunction!(vertical_vector, m)?)?;
    m.add_function(wrap_pyfunction!(horizontal_part, m)?)?;
    m.add_function(wrap_pyfunction!(locked_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(angular_momentum, m)?)?;
    m.add_function(wrap_pyfunction!(circulation, m)?)?;
    m.add_function(wrap_pyfunction!(to_body, m)?)?;
    m.add_function(wrap_pyfunction!(from_body, m)?)?;
    m.add_function(wrap_pyfunction!(kinetic_energy, m)?)?;
    m.add_function(wrap_pyfunction!(stratum, m)?)?;
    m.add_function(wrap_pyfunction!(riemann_variables, m)?)?;
    m.add_function(wrap_pyfunction!(riemann_bracket, m)?)?;
    m.add_function(wrap_pyfunction!(reduce, m)?)?;
    m.add_function(wrap_pyfunction!(reconstruct, m)?)?;
    m.add_function(wrap_pyfunction!(adjoint_motion, m)?)?;
    equilibria::register(m)?;
    gravity::register(m)?;
    Ok(())
}

/// Reduction (X, P) -> (a, p_a, p_Omega, p_Lambda) on the principal stratum (001 §7):
/// X = R diag(a) S^T (a decreasing), p_a = diag(R^T P S), p_Omega = R^T L R, p_Lambda = S^T Γ S
/// (001 (2.32), (6.27)).
///
/// Returns:
///     dict with "a", "p_a" ((n,) arrays), "p_Omega", "p_Lambda", "R", "S" ((n, n) arrays).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (det X <= 0), DegenerateStratumError.
#[pyfunction]
pub fn reduce<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    P: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyDict>> {
    let (st, r, s) = lieflow::pseudo_rigid::reduced::reduce(&mat("X", &X)?, &mat("P", &P)?).py()?;
    let d = PyDict::new(py);
    d.set_item("a", py_vec(py, &st.a))?;
    d.set_item("p_a", py_vec(py, &st.p_a))?;
    d.set_item("p_Omega", py_mat(py, &st.p_omega))?;
    d.set_item("p_Lambda", py_mat(py, &st.p_lambda))?;
    d.set_item("R", py_mat(py, &r))?;
    d.set_item("S", py_mat(py, &s))?;
    Ok(d)
}

/// Reconstruction (R, S, a, p_a, p_Omega, p_Lambda) -> (X, P), the inverse of `reduce`:
/// X = R A S^T, P = R(Omega A + diag(p_a) - A Lambda) S^T with Omega + Lambda =
/// B_A^{-1}(p_Omega + p_Lambda) (001 (7.9)).
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (R, S not rotations, p's not skew),
///     InvalidArgumentError (a_i <= 0), DegenerateStratumError (equal a_i).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn reconstruct<'py>(
    py: Python<'py>,
    R: ArrayIn<'py>,
    S: ArrayIn<'py>,
    a: ArrayIn<'py>,
    p_a: ArrayIn<'py>,
    p_Omega: ArrayIn<'py>,
    p_Lambda: ArrayIn<'py>,
) -> PyResult<(Arr2<'py>, Arr2<'py>)> {
    let st = lieflow::pseudo_rigid::reduced::ReducedState {
        a: vector("a", &a)?,
        p_a: vector("p_a", &p_a)?,
        p_omega: mat("p_Omega", &p_Omega)?,
        p_lambda: mat("p_Lambda", &p_Lambda)?,
    };
    Ok(pair(
        py,
        lieflow::pseudo_rigid::reduced::reconstruct(&mat("R", &R)?, &mat("S", &S)?, &st).py()?,
    ))
}

type ArrD<'py> = Bound<'py, numpy::PyArrayDyn<f64>>;

/// Dedekind's adjoint motion X -> X^T, P -> P^T of stacked frames (..., n, n) (000 §5.3): maps
/// motions to motions and swaps angular momentum and circulation.
///
/// Returns:
///     (X^T, P^T) with the shapes of the inputs.
/// Raises:
///     ShapeError, NonFiniteError.
#[pyfunction]
pub fn adjoint_motion<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    P: ArrayIn<'py>,
) -> PyResult<(ArrD<'py>, ArrD<'py>)> {
    use numpy::IntoPyArray;
    let (xv, pv) = (X.as_array(), P.as_array());
    let shape = xv.shape().to_vec();
    let k = shape.len();
    if k < 2 || shape[k - 1] != shape[k - 2] || pv.shape() != shape.as_slice() {
        return Err(crate::errors::to_py(lieflow::Error::shape(
            "X, P",
            "two arrays of the same shape (..., n, n)",
            format!("{:?} and {:?}", shape, pv.shape()),
        )));
    }
    let n = shape[k - 1];
    let xs: Vec<f64> = xv.iter().copied().collect();
    let ps: Vec<f64> = pv.iter().copied().collect();
    let (xt, pt) = lieflow::pseudo_rigid::dynamics::adjoint_motion(n, &xs, &ps).py()?;
    let arr = |v: Vec<f64>| {
        numpy::ndarray::ArrayD::from_shape_vec(numpy::ndarray::IxDyn(&shape), v)
            .map(|a| a.into_pyarray(py))
            .map_err(|e| crate::errors::to_py(lieflow::Error::invalid("X", e.to_string())))
    };
    Ok((arr(xt)?, arr(pt)?))
}
