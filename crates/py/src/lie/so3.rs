//! Bindings of `lieflow::lie::so3`: the fixed-size SO(3)/so(3) fast path, batched over a leading
//! axis (run in parallel with rayon, the GIL released; see `crate::batch`).

use lieflow::lie::so3::{self, SO3};
use lieflow::lie::MatrixLieGroup;
use nalgebra::{Matrix3, Vector3};
use pyo3::prelude::*;

use crate::batch::{map_batch, map_pairs, Out};
use crate::convert::ArrayIn;

/// `so3_hat(w)` (alias `hat`): the skew matrix ŵ with ŵ x = w × x (physics convention, 000 §3.3 corrected):
/// ŵ = [[0, −w3, w2], [w3, 0, −w1], [−w2, w1, 0]].
///
/// Args: w — shape (3,) or (..., 3). Returns (3, 3) or (..., 3, 3).
/// Raises ShapeError, NonFiniteError.
#[pyfunction]
fn so3_hat<'py>(py: Python<'py>, w: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "w", &w, |w: &Vector3<f64>| Ok(so3::hat(w)))
}

/// `so3_vee(xi)` (alias `vee`): the inverse of `so3_hat`, w with ŵ = xi.
///
/// Args: xi — a skew-symmetric (3, 3) matrix or (..., 3, 3). Returns (3,) or (..., 3).
/// Raises ShapeError, NonFiniteError, NotInGroupError (xi not skew: relative defect
/// ‖ξ + ξᵀ‖_F / max(1, ‖ξ‖_F) > 1e-10).
#[pyfunction]
fn so3_vee<'py>(py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "xi", &xi, so3::vee)
}

/// `so3_exp(w)`: the rotation exp(ŵ) by Rodrigues' formula
/// R = I + (sin θ/θ) ŵ + ((1 − cos θ)/θ²) ŵ², θ = ‖w‖ (rotation by θ about w/θ).
///
/// Args: w — (3,) or (..., 3). Returns (3, 3) or (..., 3, 3). Raises ShapeError, NonFiniteError,
/// InvalidArgumentError (‖w‖ > 2.25e14 = 0.05/ε_mach, where more than 0.05 rad of the angle is
/// lost to rounding: the rule of every exponential in lieflow.lie).
#[pyfunction]
fn so3_exp<'py>(py: Python<'py>, w: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "w", &w, so3::exp)
}

/// `so3_log(R, strict=False)`: the principal logarithm w (‖w‖ = θ ∈ [0, π], exp(ŵ) = R),
/// accurate near θ = 0 and near θ = π (axis from the symmetric part of R there).
///
/// At θ = π exactly both ±π·axis are logarithms: with `strict=False` one of them is returned
/// (the one whose first nonzero component is positive: the tie rule of `to_quaternion`'s
/// canonical w ≥ 0, so both give the same axis); with `strict=True` NoUniqueLogError is raised
/// when π − θ ≤ 1e-12. A matrix within the tolerance of a rotation but not orthogonal to
/// round-off is read as the nearest rotation.
///
/// Args: R — a rotation (3, 3) or (..., 3, 3). Returns (3,) or (..., 3).
/// Raises ShapeError, NonFiniteError, NotInGroupError (‖RᵀR − I‖_F or abs(det R − 1) > 1e-10),
/// NoUniqueLogError (strict only).
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

/// `so3_cayley(w)`: the Cayley map cay(w) = (I − ŵ/2)⁻¹ (I + ŵ/2) = I + 4/(4 + ‖w‖²)(ŵ + ŵ²/2),
/// a rotation about w by the angle 2·atan(‖w‖/2) (agrees with exp to second order); defined and
/// computed scale-safely for every finite w (the angle tends to π as ‖w‖ → ∞).
///
/// Args: w — (3,) or (..., 3). Returns (3, 3) or (..., 3, 3). Raises ShapeError, NonFiniteError.
#[pyfunction]
fn so3_cayley<'py>(py: Python<'py>, w: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "w", &w, |w: &Vector3<f64>| Ok(so3::cayley(w)))
}

/// `so3_cayley_inv(R)`: the inverse Cayley map, w = 2·vee(R − Rᵀ)/(1 + tr R).
///
/// Args: R — a rotation (3, 3) or (..., 3, 3). Returns (3,) or (..., 3).
/// Raises ShapeError, NonFiniteError, NotInGroupError, InvalidArgumentError (rotation by π:
/// 1 + tr R ≤ 1e-12, where R + I is singular).
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
/// J_r(w) = I − ((1 − cos θ)/θ²) ŵ + ((θ − sin θ)/θ³) ŵ², so that
/// exp(w + δ) ≈ exp(w) exp(J_r(w) δ); with `inverse=True` its inverse
/// J_r⁻¹ = I + ŵ/2 + (1/θ² − (1 + cos θ)/(2θ sin θ)) ŵ².
///
/// Args: w — (3,) or (..., 3). Returns (3, 3) or (..., 3, 3).
/// Raises ShapeError, NonFiniteError, InvalidArgumentError (inverse at ‖w‖ = 2πk, k ≥ 1;
/// ‖w‖ > 2.25e14, the rule of so3_exp).
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

/// `so3_jacobian_left(w, inverse=False)`: the left Jacobian (dexp_w)
/// J_l(w) = I + ((1 − cos θ)/θ²) ŵ + ((θ − sin θ)/θ³) ŵ² = J_r(w)ᵀ, so that
/// exp(w + δ) ≈ exp(J_l(w) δ) exp(w); with `inverse=True` its inverse
/// J_l⁻¹ = I − ŵ/2 + (1/θ² − (1 + cos θ)/(2θ sin θ)) ŵ².
///
/// Args: w — (3,) or (..., 3). Returns (3, 3) or (..., 3, 3).
/// Raises ShapeError, NonFiniteError, InvalidArgumentError (inverse at ‖w‖ = 2πk, k ≥ 1;
/// ‖w‖ > 2.25e14, the rule of so3_exp).
#[pyfunction]
#[pyo3(signature = (w, inverse = false))]
fn so3_jacobian_left<'py>(py: Python<'py>, w: ArrayIn<'py>, inverse: bool) -> PyResult<Out<'py>> {
    jacobian(py, &w, inverse, so3::jacobian_left, so3::jacobian_left_inv)
}

/// `so3_compose(R1, R2)`: the product R1 @ R2 of two rotations.
///
/// Args: R1, R2 — (3, 3) or (..., 3, 3); leading axes broadcast as numpy's. Returns (3, 3) or (..., 3, 3).
/// Raises ShapeError, NonFiniteError, NotInGroupError (‖RᵀR − I‖_F or abs(det R − 1) > 1e-10).
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

/// `so3_inverse(R)`: R⁻¹ = Rᵀ.
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

/// `so3_act(R, x)`: the rotated vector R x.
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

/// `so3_Ad(R, w)`: the adjoint action Ad_R w = R w (R ŵ Rᵀ = (R w)^).
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

/// `so3_ad(u, v)`: the bracket ad_u v = u × v ([û, v̂] = (u × v)^).
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

/// `so3_ad_star(xi, mu)`: the coadjoint action ad*_ξ μ = μ × ξ, so that
/// ⟨ad*_ξ μ, η⟩ = ⟨μ, ξ × η⟩ (dot-product pairing; 000 §3.3).
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
