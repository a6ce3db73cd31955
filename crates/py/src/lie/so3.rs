//! Bindings of `lieflow::lie::so3`: the fixed-size SO(3)/so(3) fast path, batched over a leading
//! axis (run in parallel with rayon, the GIL released; see `crate::batch`).

use lieflow::lie::so3::{self, SO3};
use lieflow::lie::MatrixLieGroup;
use nalgebra::{Matrix3, Vector3};
use pyo3::prelude::*;

use crate::batch::{map_batch, map_pairs, Out};
use crate::convert::ArrayIn;

/// `so3_hat(w)` (alias `hat`): the skew matrix :math:`\hat w` with :math:`\hat w x = w \times x`
/// (physics convention, 000 §3.3 corrected):
/// :math:`\hat w = \begin{pmatrix} 0 & -w_3 & w_2 \\ w_3 & 0 & -w_1 \\ -w_2 & w_1 & 0 \end{pmatrix}`.
///
/// Args: w — shape (3,) or (..., 3). Returns (3, 3) or (..., 3, 3).
/// Raises ShapeError, NonFiniteError.
#[pyfunction]
fn so3_hat<'py>(py: Python<'py>, w: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "w", &w, |w: &Vector3<f64>| Ok(so3::hat(w)))
}

/// `so3_vee(xi)` (alias `vee`): the inverse of `so3_hat`, w with :math:`\hat w = \xi`.
///
/// Args: xi — a skew-symmetric (3, 3) matrix or (..., 3, 3). Returns (3,) or (..., 3).
/// Raises ShapeError, NonFiniteError, NotInGroupError (xi not skew: relative defect
/// :math:`\|\xi + \xi^\top\|_F / \max(1, \|\xi\|_F) > 10^{-10}`).
#[pyfunction]
fn so3_vee<'py>(py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "xi", &xi, so3::vee)
}

/// `so3_exp(w)`: the rotation :math:`\exp(\hat w)` by Rodrigues' formula
/// :math:`R = I + \frac{\sin\theta}{\theta} \hat w + \frac{1 - \cos\theta}{\theta^2} \hat w^2`,
/// :math:`\theta = \|w\|` (rotation by :math:`\theta` about :math:`w/\theta`).
///
/// Args: w — (3,) or (..., 3). Returns (3, 3) or (..., 3, 3). Raises ShapeError, NonFiniteError,
/// InvalidArgumentError (:math:`\|w\| > 2.25 \cdot 10^{14} = 0.05/\varepsilon_\mathrm{mach}`, where
/// more than 0.05 rad of the angle is
/// lost to rounding: the rule of every exponential in lieflow.lie).
#[pyfunction]
fn so3_exp<'py>(py: Python<'py>, w: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "w", &w, so3::exp)
}

/// `so3_log(R, strict=False)`: the principal logarithm w (:math:`\|w\| = \theta \in [0, \pi]`,
/// :math:`\exp(\hat w) = R`), accurate near :math:`\theta = 0` and near :math:`\theta = \pi` (axis
/// from the symmetric part of R there).
///
/// At :math:`\theta = \pi` exactly both :math:`\pm\pi \cdot \mathrm{axis}` are logarithms: with
/// `strict=False` one of them is returned (the one whose first nonzero component is positive: the
/// tie rule of `to_quaternion`'s canonical :math:`w \ge 0`, so both give the same axis); with
/// `strict=True` NoUniqueLogError is raised when :math:`\pi - \theta \le 10^{-12}`. A matrix within
/// the tolerance of a rotation but not orthogonal to round-off is read as the nearest rotation.
///
/// Args: R — a rotation (3, 3) or (..., 3, 3). Returns (3,) or (..., 3).
/// Raises ShapeError, NonFiniteError, NotInGroupError
/// (:math:`\|R^\top R - I\|_F` or :math:`|\det R - 1| > 10^{-10}`), NoUniqueLogError (strict only).
#[pyfunction]
#[pyo3(signature = (R, strict = false))]
#[allow(non_snake_case)]
fn so3_log<'py>(py: Python<'py>, R: ArrayIn<'py>, strict: bool) -> PyResult<Out<'py>> {
    map_batch(py, "R", &R, |m: &Matrix3<f64>| {
        let g = SO3::new(*m)?;
        if strict {
            g.log()
        } else {
            Ok(so3::log_unchecked(g.matrix3()))
        }
    })
}

/// `so3_cayley(w)`: the Cayley map
/// :math:`\operatorname{cay}(w) = (I - \hat w/2)^{-1} (I + \hat w/2) = I + \frac{4}{4 + \|w\|^2} (\hat w + \hat w^2/2)`,
/// a rotation about w by the angle :math:`2 \arctan(\|w\|/2)` (agrees with exp to second order);
/// defined and computed scale-safely for every finite w (the angle tends to :math:`\pi` as
/// :math:`\|w\| \to \infty`).
///
/// Args: w — (3,) or (..., 3). Returns (3, 3) or (..., 3, 3). Raises ShapeError, NonFiniteError.
#[pyfunction]
fn so3_cayley<'py>(py: Python<'py>, w: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "w", &w, |w: &Vector3<f64>| Ok(so3::cayley(w)))
}

/// `so3_cayley_inv(R)`: the inverse Cayley map,
/// :math:`w = 2 (R - R^\top)^\vee / (1 + \operatorname{tr} R)`.
///
/// Args: R — a rotation (3, 3) or (..., 3, 3). Returns (3,) or (..., 3).
/// Raises ShapeError, NonFiniteError, NotInGroupError, InvalidArgumentError (rotation by
/// :math:`\pi`: :math:`1 + \operatorname{tr} R \le 10^{-12}`, where :math:`R + I` is singular).
#[pyfunction]
#[allow(non_snake_case)]
fn so3_cayley_inv<'py>(py: Python<'py>, R: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "R", &R, |m: &Matrix3<f64>| {
        so3::cayley_inv(SO3::new(*m)?.matrix3())
    })
}

/// Shared body of the two Jacobian bindings: J(w), or J⁻¹(w) when `inverse`.
fn jacobian<'py>(
    py: Python<'py>,
    w: &ArrayIn<'py>,
    inverse: bool,
    forward: fn(&Vector3<f64>) -> lieflow::Result<Matrix3<f64>>,
    backward: fn(&Vector3<f64>) -> lieflow::Result<Matrix3<f64>>,
) -> PyResult<Out<'py>> {
    map_batch(py, "w", w, if inverse { backward } else { forward })
}

/// `so3_jacobian_right(w, inverse=False)`: the right Jacobian
/// :math:`J_r(w) = I - \frac{1 - \cos\theta}{\theta^2} \hat w + \frac{\theta - \sin\theta}{\theta^3} \hat w^2`,
/// so that :math:`\exp(w + \delta) \approx \exp(w) \exp(J_r(w) \delta)`; with `inverse=True` its
/// inverse
/// :math:`J_r^{-1} = I + \hat w/2 + \left(\frac{1}{\theta^2} - \frac{1 + \cos\theta}{2\theta \sin\theta}\right) \hat w^2`.
///
/// Args: w — (3,) or (..., 3). Returns (3, 3) or (..., 3, 3).
/// Raises ShapeError, NonFiniteError, InvalidArgumentError (inverse at :math:`\|w\| = 2\pi k`,
/// :math:`k \ge 1`; :math:`\|w\| > 2.25 \cdot 10^{14}`, the rule of so3_exp).
#[pyfunction]
#[pyo3(signature = (w, inverse = false))]
fn so3_jacobian_right<'py>(py: Python<'py>, w: ArrayIn<'py>, inverse: bool) -> PyResult<Out<'py>> {
    jacobian(
        py,
        &w,
        inverse,
        so3::jacobian_right,
        so3::jacobian_right_inv,
    )
}

/// `so3_jacobian_left(w, inverse=False)`: the left Jacobian (:math:`\operatorname{dexp}_w`)
/// :math:`J_l(w) = I + \frac{1 - \cos\theta}{\theta^2} \hat w + \frac{\theta - \sin\theta}{\theta^3} \hat w^2 = J_r(w)^\top`,
/// so that :math:`\exp(w + \delta) \approx \exp(J_l(w) \delta) \exp(w)`; with `inverse=True` its
/// inverse
/// :math:`J_l^{-1} = I - \hat w/2 + \left(\frac{1}{\theta^2} - \frac{1 + \cos\theta}{2\theta \sin\theta}\right) \hat w^2`.
///
/// Args: w — (3,) or (..., 3). Returns (3, 3) or (..., 3, 3).
/// Raises ShapeError, NonFiniteError, InvalidArgumentError (inverse at :math:`\|w\| = 2\pi k`,
/// :math:`k \ge 1`; :math:`\|w\| > 2.25 \cdot 10^{14}`, the rule of so3_exp).
#[pyfunction]
#[pyo3(signature = (w, inverse = false))]
fn so3_jacobian_left<'py>(py: Python<'py>, w: ArrayIn<'py>, inverse: bool) -> PyResult<Out<'py>> {
    jacobian(py, &w, inverse, so3::jacobian_left, so3::jacobian_left_inv)
}

/// `so3_compose(R1, R2)`: the product R1 @ R2 of two rotations.
///
/// Args: R1, R2 — (3, 3) or (..., 3, 3); leading axes broadcast as numpy's. Returns (3, 3) or (..., 3, 3).
/// Raises ShapeError, NonFiniteError, NotInGroupError
/// (:math:`\|R^\top R - I\|_F` or :math:`|\det R - 1| > 10^{-10}`).
#[pyfunction]
#[allow(non_snake_case)]
fn so3_compose<'py>(py: Python<'py>, R1: ArrayIn<'py>, R2: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_pairs(
        py,
        ["R1", "R2"],
        &R1,
        &R2,
        |a: &Matrix3<f64>, b: &Matrix3<f64>| {
            let b = SO3::new(*b).map_err(|e| e.map_what(|w| format!("R2 ({w})")))?;
            Ok(*SO3::new(*a)?.compose(&b).matrix3())
        },
    )
}

/// `so3_inverse(R)`: :math:`R^{-1} = R^\top`.
///
/// Args: R — (3, 3) or (..., 3, 3). Returns the same shape.
/// Raises ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
#[allow(non_snake_case)]
fn so3_inverse<'py>(py: Python<'py>, R: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "R", &R, |m: &Matrix3<f64>| {
        Ok(*SO3::new(*m)?.inverse().matrix3())
    })
}

/// `so3_act(R, x)`: the rotated vector :math:`R x`.
///
/// Args: R — (3, 3) or (..., 3, 3); x — (3,) or (..., 3) (leading axes
/// broadcast). Returns (3,) or (..., 3). Raises ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
#[allow(non_snake_case)]
fn so3_act<'py>(py: Python<'py>, R: ArrayIn<'py>, x: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_pairs(
        py,
        ["R", "x"],
        &R,
        &x,
        |m: &Matrix3<f64>, x: &Vector3<f64>| Ok(SO3::new(*m)?.act(x)),
    )
}

/// `so3_Ad(R, w)`: the adjoint action :math:`\operatorname{Ad}_R w = R w`
/// (:math:`R \hat w R^\top = \widehat{R w}`).
///
/// Args: R — (3, 3) or (..., 3, 3); w — (3,) or (..., 3) (broadcast as in so3_act). Returns (3,) or
/// (..., 3). Raises ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
#[pyo3(name = "so3_Ad")]
#[allow(non_snake_case)]
fn so3_adjoint<'py>(py: Python<'py>, R: ArrayIn<'py>, w: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_pairs(
        py,
        ["R", "w"],
        &R,
        &w,
        |m: &Matrix3<f64>, w: &Vector3<f64>| Ok(SO3::new(*m)?.adjoint(w)),
    )
}

/// `so3_ad(u, v)`: the bracket :math:`\operatorname{ad}_u v = u \times v`
/// (:math:`[\hat u, \hat v] = \widehat{u \times v}`).
///
/// Args: u, v — (3,) or (..., 3) (leading axes broadcast). Returns (3,) or (..., 3).
/// Raises ShapeError, NonFiniteError.
#[pyfunction]
fn so3_ad<'py>(py: Python<'py>, u: ArrayIn<'py>, v: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_pairs(
        py,
        ["u", "v"],
        &u,
        &v,
        |u: &Vector3<f64>, v: &Vector3<f64>| Ok(SO3::ad(u, v)),
    )
}

/// `so3_ad_star(xi, mu)`: the coadjoint action
/// :math:`\operatorname{ad}^*_\xi \mu = \mu \times \xi`, so that
/// :math:`\langle \operatorname{ad}^*_\xi \mu, \eta \rangle = \langle \mu, \xi \times \eta \rangle`
/// (dot-product pairing; 000 §3.3).
///
/// Args: xi, mu — (3,) or (..., 3) (leading axes broadcast). Returns (3,) or (..., 3).
/// Raises ShapeError, NonFiniteError.
#[pyfunction]
fn so3_ad_star<'py>(py: Python<'py>, xi: ArrayIn<'py>, mu: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_pairs(
        py,
        ["xi", "mu"],
        &xi,
        &mu,
        |x: &Vector3<f64>, m: &Vector3<f64>| Ok(SO3::ad_star(x, m)),
    )
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(so3_hat, m)?)?;
    m.add_function(wrap_pyfunction!(so3_vee, m)?)?;
    m.add_function(wrap_pyfunction!(so3_compose, m)?)?;
    m.add_function(wrap_pyfunction!(so3_inverse, m)?)?;
    m.add_function(wrap_pyfunction!(so3_act, m)?)?;
    m.add_function(wrap_pyfunction!(so3_adjoint, m)?)?;
    m.add_function(wrap_pyfunction!(so3_ad, m)?)?;
    m.add_function(wrap_pyfunction!(so3_ad_star, m)?)?;
    m.add_function(wrap_pyfunction!(so3_exp, m)?)?;
    m.add_function(wrap_pyfunction!(so3_log, m)?)?;
    m.add_function(wrap_pyfunction!(so3_cayley, m)?)?;
    m.add_function(wrap_pyfunction!(so3_cayley_inv, m)?)?;
    m.add_function(wrap_pyfunction!(so3_jacobian_right, m)?)?;
    m.add_function(wrap_pyfunction!(so3_jacobian_left, m)?)?;
    Ok(())
}
