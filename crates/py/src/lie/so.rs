//! `lieflow.lie`: SO(n) and so(n) for any n ≥ 2, and SO(n) × SO(n) (bindings of
//! `lieflow::lie::so` and `lieflow::lie::product`).

use lieflow::lie::so::{self, SOn};
use lieflow::lie::{product, MatrixLieGroup};
use lieflow::{check, Error, Mat, Result};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::convert::real;
use crate::convert::{mat, put_mats, py_mat, py_vec, shape_str, to_mat, vector, ArrayIn};
use crate::errors::IntoPy;
use crate::items::{matrix_item, par_map_items, Input};

/// Applies `f` to every matrix of an array (..., n, n) (`items::par_map_items`).
fn map_mats<'py>(
    py: Python<'py>,
    what: &str,
    a: &ArrayIn<'py>,
    f: fn(&Mat) -> Result<Mat>,
) -> PyResult<Bound<'py, PyAny>> {
    let [r, c] = matrix_item(what, a)?;
    par_map_items(py, &[Input::new(what, a, &[r, c])], &[r, c], |x, out| {
        put_mats(out, &[&f(&to_mat(r, c, x[0]))?])
    })
}

/// `so_hat(c)` (alias `hat_n`): the skew-symmetric matrix with coordinates `c` in the
/// :math:`e_{ij}` basis (:math:`i < j`, +1 at (i, j), −1 at (j, i)), ordered (1,2), (1,3), …,
/// (1,n), (2,3), …, (n−1,n).
///
/// Args:
///     c: shape (d,) with :math:`d = n(n-1)/2` for some :math:`n \ge 2`, or (..., d).
/// Returns:
///     xi: shape (n, n), or (..., n, n).
/// Raises:
///     ShapeError: d is not of the form n(n−1)/2. NonFiniteError: NaN or inf in c.
#[pyfunction]
fn so_hat<'py>(py: Python<'py>, c: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
    let shape = c.as_array().shape().to_vec();
    let d = *shape.last().unwrap_or(&0);
    // n from d first: the output item (n, n) is part of the rule's size check.
    let n = so::n_from_dim(d).unwrap_or(0);
    if n == 0 || shape.is_empty() {
        return Err(Error::shape(
            "c",
            "(..., d) with d = n(n−1)/2 for some n ≥ 2 (1, 3, 6, 10, …)",
            shape_str(&shape),
        ))
        .py();
    }
    par_map_items(py, &[Input::finite("c", &c, &[d])], &[n, n], |x, out| {
        put_mats(out, &[&so::hat_n_unchecked(n, x[0])])
    })
}

/// `so_vee(xi)` (alias `vee_n`): the coordinates of a skew-symmetric matrix in the :math:`e_{ij}`
/// basis (the inverse of `so_hat`).
///
/// Args:
///     xi: shape (n, n), skew-symmetric (relative defect :math:`\|\xi + \xi^\top\| \le 10^{-10}`),
///         or (..., n, n).
/// Returns:
///     c: shape (n(n−1)/2,), or (..., n(n−1)/2).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (not skew).
#[pyfunction]
fn so_vee<'py>(py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
    let [r, c] = matrix_item("xi", &xi)?;
    par_map_items(
        py,
        &[Input::new("xi", &xi, &[r, c])],
        &[so::dim(r)],
        |x, out| {
            out.copy_from_slice(&so::vee_n(&to_mat(r, c, x[0]))?);
            Ok(())
        },
    )
}

/// Exponential map :math:`\mathfrak{so}(n) \to SO(n)`.
///
/// Closed form for n = 2, Rodrigues for n = 3, and for n > 3 scaling and squaring with diagonal
/// Padé approximants (Al-Mohy & Higham 2009, as scipy's expm) followed by one Newton–Schulz step,
/// orthogonal to round-off even for :math:`\|\xi\| \sim 10^3`; the kernel allocates its storage
/// once per thread and size, so repeated calls cost the same.
///
/// Args:
///     xi: skew matrix (n, n), or (..., n, n) (many computed in parallel without the GIL).
/// Returns:
///     R: shape (n, n) or (..., n, n), in SO(n).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (xi not skew),
///     InvalidArgumentError (:math:`\|\xi\| > 2.25 \cdot 10^{14} = 0.05/\varepsilon_\mathrm{mach}`,
///     where more than 0.05 rad of
///     the angles is lost to rounding: the rule of every exponential in lieflow.lie).
#[pyfunction]
fn so_exp<'py>(py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
    map_mats(py, "xi", &xi, so::exp)
}

/// Principal logarithm :math:`SO(n) \to \mathfrak{so}(n)` (all rotation angles in
/// :math:`[0, \pi)`).
///
/// Args:
///     R: rotation (n, n) (:math:`\|R^\top R - I\|_F \le 10^{-10}`, :math:`\det R > 0`), or
///         (..., n, n) (many
///         computed in parallel without the GIL).
/// Returns:
///     xi: skew matrix (n, n) or (..., n, n) with so_exp(xi) = R.
/// Raises:
///     NotInGroupError: R not a rotation (the message gives :math:`\|R^\top R - I\|_F` and
///     :math:`\det R`).
///     NoUniqueLogError: a rotation angle within 1e-12 of :math:`\pi`, for every n (:math:`\pi`
///     within round-off;
///     below it the log is computed accurately, also for clustered angles; the message gives
///     the angle).
///     ShapeError, NonFiniteError.
#[pyfunction]
#[allow(non_snake_case)]
fn so_log<'py>(py: Python<'py>, R: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
    map_mats(py, "R", &R, so::log)
}

/// `so_cayley(xi)` (alias `cayley`): the Cayley map
/// :math:`\operatorname{cay}(\xi) = (I - \xi/2)^{-1} (I + \xi/2)`,
/// :math:`\mathfrak{so}(n) \to SO(n)`.
///
/// Args:
///     xi: skew matrix (n, n).
/// Returns:
///     R: rotation (n, n).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (not skew).
#[pyfunction]
fn so_cayley<'py>(py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    Ok(py_mat(py, &so::cayley(&mat("xi", &xi)?).py()?))
}

/// `so_cayley_inv(R)` (alias `cayley_inv`): the inverse Cayley map
/// :math:`\xi = 2 (I + R)^{-1} (R - I)`, the exact inverse of `so_cayley`.
///
/// Args:
///     R: rotation (n, n).
/// Returns:
///     xi: skew matrix (n, n).
/// Raises:
///     InvalidArgumentError: :math:`I + R` singular (R has an eigenvalue :math:`-1`).
///     NotInGroupError, ShapeError, NonFiniteError.
#[pyfunction]
#[allow(non_snake_case)]
fn so_cayley_inv<'py>(py: Python<'py>, R: ArrayIn<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    Ok(py_mat(py, &so::cayley_inv(&mat("R", &R)?).py()?))
}

/// `so_dexp(xi, eta)` (alias `dexp`): the right-trivialized derivative of exp,
/// :math:`\operatorname{dexp}_\xi \eta = \sum_k \operatorname{ad}_\xi^k \eta / (k+1)!`, so that
/// :math:`\frac{d}{dt} \exp(\xi + t\eta) |_{t=0} = \operatorname{dexp}_\xi(\eta) \exp(\xi)`
/// (and :math:`\exp(\xi) \operatorname{dexp}_{-\xi}(\eta)`, the left-trivialized form). Any
/// :math:`\xi`.
///
/// Args:
///     xi, eta: skew matrices (n, n).
/// Returns:
///     skew matrix (n, n).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (not skew), InvalidArgumentError
///     (:math:`\|\xi\| > 2.25 \cdot 10^{14}`).
#[pyfunction]
fn so_dexp<'py>(
    py: Python<'py>,
    xi: ArrayIn<'py>,
    eta: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let r = so::dexp(&mat("xi", &xi)?, &mat("eta", &eta)?).py()?;
    Ok(py_mat(py, &r))
}

/// `so_dexp_inv(xi, eta)` (alias `dexp_inv`): the inverse of `so_dexp` (Bernoulli series
/// :math:`\sum_k \frac{B_k}{k!} \operatorname{ad}_\xi^k \eta`), for :math:`\|\xi\| < \pi` where
/// :math:`\|\xi\|^2 = \tfrac12 \operatorname{tr}(\xi^\top \xi)`.
///
/// Args:
///     xi, eta: skew matrices (n, n).
/// Returns:
///     skew matrix (n, n) with so_dexp(xi, result) = eta.
/// Raises:
///     InvalidArgumentError: :math:`\|\xi\| \ge \pi`. ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
fn so_dexp_inv<'py>(
    py: Python<'py>,
    xi: ArrayIn<'py>,
    eta: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let r = so::dexp_inv(&mat("xi", &xi)?, &mat("eta", &eta)?).py()?;
    Ok(py_mat(py, &r))
}

/// `so_Ad(g, xi)` (alias `Ad`): the adjoint action :math:`\operatorname{Ad}_g \xi = g \xi g^\top`
/// of SO(n) on :math:`\mathfrak{so}(n)`.
///
/// Args:
///     g: rotation (n, n). xi: skew matrix (n, n).
/// Returns:
///     skew matrix (n, n).
/// Raises:
///     NotInGroupError (g not a rotation or xi not skew), ShapeError, NonFiniteError.
#[pyfunction]
#[pyo3(name = "so_Ad")]
fn so_adjoint<'py>(
    py: Python<'py>,
    g: ArrayIn<'py>,
    xi: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let r = so::adjoint(&mat("g", &g)?, &mat("xi", &xi)?).py()?;
    Ok(py_mat(py, &r))
}

/// `so_ad(xi, eta)` (alias `ad`):
/// :math:`\operatorname{ad}_\xi \eta = [\xi, \eta] = \xi\eta - \eta\xi` on
/// :math:`\mathfrak{so}(n)`.
///
/// Args:
///     xi, eta: skew matrices (n, n).
/// Returns:
///     skew matrix (n, n).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (not skew).
#[pyfunction]
fn so_ad<'py>(
    py: Python<'py>,
    xi: ArrayIn<'py>,
    eta: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let r = so::ad(&mat("xi", &xi)?, &mat("eta", &eta)?).py()?;
    Ok(py_mat(py, &r))
}

/// `so_ad_star(xi, mu)` (alias `ad_star`): the coadjoint action
/// :math:`\operatorname{ad}^*_\xi \mu = [\mu, \xi]`, with :math:`\mathfrak{so}(n)^*` identified
/// with :math:`\mathfrak{so}(n)` by the pairing
/// :math:`\langle \xi, \eta \rangle = \tfrac12 \operatorname{tr}(\xi^\top \eta)`, so that
/// :math:`\langle \operatorname{ad}^*_\xi \mu, \eta \rangle = \langle \mu, [\xi, \eta] \rangle`
/// (000 §3.3).
///
/// Args:
///     xi, mu: skew matrices (n, n).
/// Returns:
///     skew matrix (n, n).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (not skew).
#[pyfunction]
fn so_ad_star<'py>(
    py: Python<'py>,
    xi: ArrayIn<'py>,
    mu: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let r = so::ad_star(&mat("xi", &xi)?, &mat("mu", &mu)?).py()?;
    Ok(py_mat(py, &r))
}

/// Whether R is in SO(n): :math:`\|R^\top R - I\|_F \le \mathrm{tol}` and :math:`\det R > 0`.
///
/// Args:
///     R: square matrix (n, n). tol: positive tolerance (default 1e-10).
/// Returns:
///     bool.
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError (tol not a positive number).
#[pyfunction]
#[pyo3(signature = (R, tol = so::ROTATION_TOL), text_signature = "(R, tol=1e-10)")]
#[allow(non_snake_case)]
fn is_rotation(R: ArrayIn<'_>, #[pyo3(from_py_with = real)] tol: f64) -> PyResult<bool> {
    so::is_rotation(&mat("R", &R)?, tol).py()
}
// The text_signature above spells the default out for help() and the stubs.
const _: () = assert!(so::ROTATION_TOL == 1e-10);

/// Nearest rotation to M in the Frobenius norm: :math:`U D V^\top` from the SVD
/// :math:`M = U \Sigma V^\top` with
/// :math:`D = \operatorname{diag}(1, \dots, 1, \operatorname{sign} \det(U V^\top))` (the polar
/// factor when :math:`\det M > 0`).
///
/// Args:
///     M: square matrix (n, n).
/// Returns:
///     R: rotation (n, n).
/// Raises:
///     ShapeError, NonFiniteError.
#[pyfunction]
#[allow(non_snake_case)]
fn project_to_so<'py>(py: Python<'py>, M: ArrayIn<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    Ok(py_mat(py, &so::project_to_so(&mat("M", &M)?).py()?))
}

/// `so_compose(g, h)`: the product g @ h of two rotations of one size.
///
/// Args:
///     g, h: rotations (n, n).
/// Returns:
///     rotation (n, n).
/// Raises:
///     NotInGroupError, ShapeError (sizes differ), NonFiniteError.
#[pyfunction]
fn so_compose<'py>(
    py: Python<'py>,
    g: ArrayIn<'py>,
    h: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let g = SOn::new(mat("g", &g)?).py()?;
    let h = mat("h", &h)?;
    so::check_rotation_of("h", &h, g.n()).py()?;
    Ok(py_mat(py, g.compose(&SOn::new(h).py()?).as_mat()))
}

/// `so_inverse(R)`: :math:`R^{-1} = R^\top`.
///
/// Args:
///     R: rotation (n, n), or (..., n, n).
/// Returns:
///     rotation (n, n) or (..., n, n).
/// Raises:
///     NotInGroupError, ShapeError, NonFiniteError.
#[pyfunction]
#[allow(non_snake_case)]
fn so_inverse<'py>(py: Python<'py>, R: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
    map_mats(py, "R", &R, |r| {
        Ok(SOn::new(r.clone())?.inverse().into_mat())
    })
}

/// `so_act(R, x)`: the rotated vector :math:`R x`.
///
/// Args:
///     R: rotation (n, n). x: vector (n,).
/// Returns:
///     vector (n,).
/// Raises:
///     NotInGroupError, ShapeError, NonFiniteError.
#[pyfunction]
#[allow(non_snake_case)]
fn so_act<'py>(
    py: Python<'py>,
    R: ArrayIn<'py>,
    x: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let g = SOn::new(mat("R", &R)?).py()?;
    let x = vector("x", &x)?;
    check::len_of("x", &x, g.n()).py()?;
    Ok(py_vec(py, &g.act(&x)))
}

/// The Jacobian bindings: J(ξ), or J⁻¹(ξ) when `inverse`.
fn jacobian<'py>(
    py: Python<'py>,
    xi: &ArrayIn<'py>,
    inverse: bool,
    forward: fn(&Mat) -> Result<Mat>,
    backward: fn(&Mat) -> Result<Mat>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let xi = mat("xi", xi)?;
    let j = if inverse { backward(&xi) } else { forward(&xi) };
    Ok(py_mat(py, &j.py()?))
}

/// `so_jacobian_left(xi, inverse=False)`: the left Jacobian of exp on so(n), the d × d matrix
/// (:math:`d = n(n-1)/2`) of :math:`\eta \mapsto \operatorname{dexp}_\xi \eta` in :math:`e_{ij}`
/// coordinates, so that :math:`\exp(\xi + \delta) \approx \exp(J_l(\xi) \delta) \exp(\xi)`; with
/// `inverse=True` its inverse (the matrix of so_dexp_inv, for :math:`\|\xi\| < \pi`).
///
/// Args:
///     xi: skew matrix (n, n).
/// Returns:
///     (d, d) matrix.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (not skew), InvalidArgumentError
///     (:math:`\|\xi\| > 2.25 \cdot 10^{14}`; inverse: :math:`\|\xi\| \ge \pi`).
#[pyfunction]
#[pyo3(signature = (xi, inverse = false))]
fn so_jacobian_left<'py>(
    py: Python<'py>,
    xi: ArrayIn<'py>,
    inverse: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    jacobian(py, &xi, inverse, so::jacobian_left, so::jacobian_left_inv)
}

/// `so_jacobian_right(xi, inverse=False)`: the right Jacobian :math:`J_r(\xi) = J_l(-\xi)`, so
/// that :math:`\exp(\xi + \delta) \approx \exp(\xi) \exp(J_r(\xi) \delta)`; with `inverse=True`
/// its inverse.
///
/// Args:
///     xi: skew matrix (n, n).
/// Returns:
///     (d, d) matrix, d = n(n−1)/2.
/// Raises:
///     as so_jacobian_left.
#[pyfunction]
#[pyo3(signature = (xi, inverse = false))]
fn so_jacobian_right<'py>(
    py: Python<'py>,
    xi: ArrayIn<'py>,
    inverse: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    jacobian(py, &xi, inverse, so::jacobian_right, so::jacobian_right_inv)
}

type Pair<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// Adjoint action of :math:`SO(n) \times SO(n)` on
/// :math:`\mathfrak{so}(n) \oplus \mathfrak{so}(n)`:
/// :math:`\operatorname{Ad}_{(g,h)}(\xi, \eta) = (g \xi g^\top, h \eta h^\top)` (componentwise,
/// 001 (7.23)).
///
/// Args:
///     g, h: rotations (n, n). xi, eta: skew matrices (n, n).
/// Returns:
///     (xi', eta'): two skew matrices (n, n).
/// Raises:
///     NotInGroupError, ShapeError, NonFiniteError.
#[pyfunction]
#[pyo3(name = "product_Ad")]
fn product_adjoint<'py>(
    py: Python<'py>,
    g: ArrayIn<'py>,
    h: ArrayIn<'py>,
    xi: ArrayIn<'py>,
    eta: ArrayIn<'py>,
) -> PyResult<Pair<'py>> {
    let x = (mat("xi", &xi)?, mat("eta", &eta)?);
    let (a, b) = product::adjoint(&mat("g", &g)?, &mat("h", &h)?, &x).py()?;
    Ok((py_mat(py, &a), py_mat(py, &b)))
}

/// Bracket on :math:`\mathfrak{so}(n) \oplus \mathfrak{so}(n)`, 001 (7.26):
/// :math:`[(\xi', \eta'), (\xi, \eta)] = ([\xi', \xi], [\eta', \eta])`.
///
/// Args:
///     xi1, eta1, xi2, eta2: skew matrices (n, n).
/// Returns:
///     ([xi1, xi2], [eta1, eta2]): two skew matrices (n, n).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (not skew).
#[pyfunction]
fn product_bracket<'py>(
    py: Python<'py>,
    xi1: ArrayIn<'py>,
    eta1: ArrayIn<'py>,
    xi2: ArrayIn<'py>,
    eta2: ArrayIn<'py>,
) -> PyResult<Pair<'py>> {
    let a = (mat("xi1", &xi1)?, mat("eta1", &eta1)?);
    let b = (mat("xi2", &xi2)?, mat("eta2", &eta2)?);
    let (x, y) = product::bracket(&a, &b).py()?;
    Ok((py_mat(py, &x), py_mat(py, &y)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(so_hat, m)?)?;
    m.add_function(wrap_pyfunction!(so_vee, m)?)?;
    m.add_function(wrap_pyfunction!(so_exp, m)?)?;
    m.add_function(wrap_pyfunction!(so_log, m)?)?;
    m.add_function(wrap_pyfunction!(so_compose, m)?)?;
    m.add_function(wrap_pyfunction!(so_inverse, m)?)?;
    m.add_function(wrap_pyfunction!(so_act, m)?)?;
    m.add_function(wrap_pyfunction!(so_cayley, m)?)?;
    m.add_function(wrap_pyfunction!(so_cayley_inv, m)?)?;
    m.add_function(wrap_pyfunction!(so_dexp, m)?)?;
    m.add_function(wrap_pyfunction!(so_dexp_inv, m)?)?;
    m.add_function(wrap_pyfunction!(so_adjoint, m)?)?;
    m.add_function(wrap_pyfunction!(so_ad, m)?)?;
    m.add_function(wrap_pyfunction!(so_ad_star, m)?)?;
    m.add_function(wrap_pyfunction!(so_jacobian_left, m)?)?;
    m.add_function(wrap_pyfunction!(so_jacobian_right, m)?)?;
    m.add_function(wrap_pyfunction!(is_rotation, m)?)?;
    m.add_function(wrap_pyfunction!(project_to_so, m)?)?;
    m.add_function(wrap_pyfunction!(product_adjoint, m)?)?;
    m.add_function(wrap_pyfunction!(product_bracket, m)?)?;
    Ok(())
}
