//! Bindings of `lieflow::lie::se3`: rigid motions as 4×4 homogeneous matrices [[R, t], [0, 1]],
//! algebra elements as 6-vectors (ω, v) with the rotation first; batched over a leading axis.

use lieflow::lie::se3::{self, SE3};
use lieflow::lie::MatrixLieGroup;
use nalgebra::{Matrix4, Matrix6, Vector3, Vector6};
use pyo3::prelude::*;

use crate::batch::{map_batch, map_pairs, Out};
use crate::convert::ArrayIn;

/// `se3_hat(xi)`: the 4×4 matrix :math:`\begin{pmatrix} \hat\omega & v \\ 0 & 0 \end{pmatrix}` of
/// :math:`\xi = (\omega, v)` (so3_hat for :math:`\hat\omega`).
///
/// Args: xi — (6,) or (..., 6). Returns (4, 4) or (..., 4, 4). Raises ShapeError, NonFiniteError.
#[pyfunction]
fn se3_hat<'py>(py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "xi", &xi, |x: &Vector6<f64>| Ok(se3::hat(x)))
}

/// `se3_vee(X)`: the inverse of `se3_hat`, :math:`\xi = (\omega, v)` of
/// :math:`X = \begin{pmatrix} \hat\omega & v \\ 0 & 0 \end{pmatrix}`.
///
/// Args: X — (4, 4) or (..., 4, 4). Returns (6,) or (..., 6). Raises ShapeError, NonFiniteError,
/// NotInGroupError (last row not zero to 1e-12, or the rotation block not skew to 1e-10).
#[pyfunction]
#[allow(non_snake_case)]
fn se3_vee<'py>(py: Python<'py>, X: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "X", &X, se3::vee)
}

/// `se3_exp(xi)`: exp of :math:`\xi = (\omega, v)` (rotation first) as the 4×4 matrix
/// :math:`\begin{pmatrix} \exp\hat\omega & V(\omega) v \\ 0 & 1 \end{pmatrix}`,
/// :math:`V(\omega) = I + \frac{1 - \cos\theta}{\theta^2} \hat\omega + \frac{\theta - \sin\theta}{\theta^3} \hat\omega^2`
/// (the left Jacobian of SO(3)), :math:`\theta = \|\omega\|`; equal to
/// `scipy.linalg.expm(se3_hat(xi))`.
///
/// Args: xi — (6,) or (..., 6). Returns (4, 4) or (..., 4, 4). Raises ShapeError, NonFiniteError,
/// InvalidArgumentError (:math:`\|\omega\| > 2.25 \cdot 10^{14}`, the rule of so3_exp; a
/// translation beyond the f64 range).
#[pyfunction]
fn se3_exp<'py>(py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "xi", &xi, |x: &Vector6<f64>| Ok(se3::exp(x)?.matrix4()))
}

/// `se3_log(g, strict=False)`: the logarithm :math:`\xi = (\omega, v)` of
/// :math:`g = \begin{pmatrix} R & t \\ 0 & 1 \end{pmatrix}`: ω = `so3_log(R)`
/// (:math:`\|\omega\| \le \pi`) and :math:`v = V(\omega)^{-1} t`. At a rotation angle of
/// :math:`\pi` exactly, `strict=False` returns one of the two logarithms and `strict=True` raises
/// NoUniqueLogError (when :math:`\pi - \theta \le 10^{-12}`).
///
/// Args: g — (4, 4) or (..., 4, 4). Returns (6,) or (..., 6).
/// Raises ShapeError, NonFiniteError, NotInGroupError (last row not (0, 0, 0, 1) to 1e-12, or R
/// not a rotation to 1e-10), NoUniqueLogError (strict only).
#[pyfunction]
#[pyo3(signature = (g, strict = false))]
fn se3_log<'py>(py: Python<'py>, g: ArrayIn<'py>, strict: bool) -> PyResult<Out<'py>> {
    map_batch(py, "g", &g, |m: &Matrix4<f64>| {
        let g = SE3::from_matrix4(m)?;
        if strict {
            g.log()
        } else {
            Ok(se3::log_unchecked(&g))
        }
    })
}

/// `se3_Ad(g, xi=None)`: the adjoint action
/// :math:`\operatorname{Ad}_g (\omega, v) = (R\omega, t \times R\omega + R v)` on
/// :math:`(\omega, v)` coordinates, so that
/// :math:`\exp(\operatorname{Ad}_g \xi) = g \exp(\xi) g^{-1}`; without `xi`, its 6×6 matrix
/// :math:`\operatorname{Ad}_g = \begin{pmatrix} R & 0 \\ \hat t R & R \end{pmatrix}`.
///
/// Args: g — (4, 4) or (..., 4, 4); xi — (6,) or (..., 6) (leading axes
/// broadcast). Returns (6,) or (..., 6); without xi (6, 6) or (..., 6, 6).
/// Raises ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
#[pyo3(name = "se3_Ad", signature = (g, xi = None))]
fn se3_adjoint<'py>(
    py: Python<'py>,
    g: ArrayIn<'py>,
    xi: Option<ArrayIn<'py>>,
) -> PyResult<Out<'py>> {
    match xi {
        None => map_batch(py, "g", &g, |m: &Matrix4<f64>| {
            Ok(SE3::from_matrix4(m)?.adjoint_matrix())
        }),
        Some(xi) => map_pairs(
            py,
            ["g", "xi"],
            &g,
            &xi,
            |m: &Matrix4<f64>, x: &Vector6<f64>| Ok(SE3::from_matrix4(m)?.adjoint(x)),
        ),
    }
}

/// `se3_ad(xi, eta)`: the bracket
/// :math:`\operatorname{ad}_{(\omega_1, v_1)} (\omega_2, v_2) = (\omega_1 \times \omega_2, \omega_1 \times v_2 - \omega_2 \times v_1)`
/// (the commutator of the 4×4 matrices).
///
/// Args: xi, eta — (6,) or (..., 6) (leading axes broadcast). Returns (6,) or (..., 6).
/// Raises ShapeError, NonFiniteError.
#[pyfunction]
fn se3_ad<'py>(py: Python<'py>, xi: ArrayIn<'py>, eta: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_pairs(
        py,
        ["xi", "eta"],
        &xi,
        &eta,
        |x: &Vector6<f64>, y: &Vector6<f64>| Ok(SE3::ad(x, y)),
    )
}

/// `se3_ad_star(xi, mu)`: the coadjoint action
/// :math:`\operatorname{ad}^*_{(\omega, v)} (\mu, p) = (\mu \times \omega + p \times v, p \times \omega)`,
/// the transpose of :math:`\operatorname{ad}_\xi` under the dot-product pairing.
///
/// Args: xi, mu — (6,) or (..., 6) (leading axes broadcast). Returns (6,) or (..., 6).
/// Raises ShapeError, NonFiniteError.
#[pyfunction]
fn se3_ad_star<'py>(py: Python<'py>, xi: ArrayIn<'py>, mu: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_pairs(
        py,
        ["xi", "mu"],
        &xi,
        &mu,
        |x: &Vector6<f64>, m: &Vector6<f64>| Ok(SE3::ad_star(x, m)),
    )
}

/// `se3_act(g, x)`: the rigid motion of a point, :math:`g \cdot x = R x + t`.
///
/// Args: g — (4, 4) or (..., 4, 4); x — (3,) or (..., 3) (leading axes broadcast). Returns
/// (3,) or (..., 3). Raises ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
fn se3_act<'py>(py: Python<'py>, g: ArrayIn<'py>, x: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_pairs(
        py,
        ["g", "x"],
        &g,
        &x,
        |m: &Matrix4<f64>, x: &Vector3<f64>| Ok(SE3::from_matrix4(m)?.act(x)),
    )
}

/// `se3_jacobian_left(xi, inverse=False)`: the 6×6 left Jacobian of exp on :math:`(\omega, v)`
/// coordinates, :math:`\begin{pmatrix} J_l(\omega) & 0 \\ Q(\omega, v) & J_l(\omega) \end{pmatrix}`
/// (Barfoot's Q block), so that :math:`\exp(\xi + \delta) \approx \exp(J_l(\xi) \delta) \exp(\xi)`;
/// with `inverse=True` its inverse.
///
/// Args: xi — (6,) or (..., 6). Returns (6, 6) or (..., 6, 6).
/// Raises ShapeError, NonFiniteError, InvalidArgumentError (inverse at
/// :math:`\|\omega\| = 2\pi k`, :math:`k \ge 1`; :math:`\|\omega\| > 2.25 \cdot 10^{14}`, the rule
/// of so3_exp; a Jacobian beyond the f64 range).
#[pyfunction]
#[pyo3(signature = (xi, inverse = false))]
fn se3_jacobian_left<'py>(py: Python<'py>, xi: ArrayIn<'py>, inverse: bool) -> PyResult<Out<'py>> {
    let f: fn(&Vector6<f64>) -> lieflow::Result<Matrix6<f64>> = if inverse {
        se3::jacobian_left_inv
    } else {
        se3::jacobian_left
    };
    map_batch(py, "xi", &xi, f)
}

/// `se3_jacobian_right(xi, inverse=False)`: the 6×6 right Jacobian :math:`J_r(\xi) = J_l(-\xi)`,
/// so that :math:`\exp(\xi + \delta) \approx \exp(\xi) \exp(J_r(\xi) \delta)`; with `inverse=True`
/// its inverse.
///
/// Args: xi — (6,) or (..., 6). Returns (6, 6) or (..., 6, 6). Raises as se3_jacobian_left.
#[pyfunction]
#[pyo3(signature = (xi, inverse = false))]
fn se3_jacobian_right<'py>(py: Python<'py>, xi: ArrayIn<'py>, inverse: bool) -> PyResult<Out<'py>> {
    let f: fn(&Vector6<f64>) -> lieflow::Result<Matrix6<f64>> = if inverse {
        se3::jacobian_right_inv
    } else {
        se3::jacobian_right
    };
    map_batch(py, "xi", &xi, f)
}

/// `se3_inverse(g)`: :math:`(R, t)^{-1} = (R^\top, -R^\top t)` as a 4×4 matrix.
///
/// Args: g — (4, 4) or (..., 4, 4). Returns the same shape.
/// Raises ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
fn se3_inverse<'py>(py: Python<'py>, g: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "g", &g, |m: &Matrix4<f64>| {
        Ok(SE3::from_matrix4(m)?.inverse().matrix4())
    })
}

/// `se3_compose(g, h)`: the product :math:`g h = (R_g R_h, R_g t_h + t_g)` as a 4×4 matrix.
///
/// Args: g, h — (4, 4) or (..., 4, 4); leading axes broadcast as numpy's. Returns (4, 4) or
/// (..., 4, 4). Raises ShapeError (incl. leading axes that do not broadcast), NonFiniteError,
/// NotInGroupError.
#[pyfunction]
fn se3_compose<'py>(py: Python<'py>, g: ArrayIn<'py>, h: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_pairs(
        py,
        ["g", "h"],
        &g,
        &h,
        |a: &Matrix4<f64>, b: &Matrix4<f64>| {
            let h = SE3::from_matrix4(b).map_err(|e| e.map_what(|w| format!("h ({w})")))?;
            Ok(SE3::from_matrix4(a)?.compose(&h).matrix4())
        },
    )
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(se3_exp, m)?)?;
    m.add_function(wrap_pyfunction!(se3_log, m)?)?;
    m.add_function(wrap_pyfunction!(se3_hat, m)?)?;
    m.add_function(wrap_pyfunction!(se3_vee, m)?)?;
    m.add_function(wrap_pyfunction!(se3_adjoint, m)?)?;
    m.add_function(wrap_pyfunction!(se3_ad, m)?)?;
    m.add_function(wrap_pyfunction!(se3_ad_star, m)?)?;
    m.add_function(wrap_pyfunction!(se3_act, m)?)?;
    m.add_function(wrap_pyfunction!(se3_jacobian_left, m)?)?;
    m.add_function(wrap_pyfunction!(se3_jacobian_right, m)?)?;
    m.add_function(wrap_pyfunction!(se3_inverse, m)?)?;
    m.add_function(wrap_pyfunction!(se3_compose, m)?)?;
    Ok(())
}
