//! Bindings of `lieflow::lie::so3`: the fixed-size SO(3)/so(3) fast path, batched over a leading
//! axis (run in parallel with rayon, the GIL released; see `crate::batch`).

use lieflow::lie::so3::{self, SO3};
use lieflow::lie::MatrixLieGroup;
use nalgebra::{Matrix3, Vector3};
use pyo3::prelude::*;

use crate::batch::{map_batch, Out};
use crate::convert::ArrayIn;

/// `hat(w)`: the skew matrix ŵ with ŵ x = w × x (physics convention, 000 §3.3 corrected):
/// ŵ = [[0, −w3, w2], [w3, 0, −w1], [−w2, w1, 0]].
///
/// Args: w — shape (3,) or a batch (b, 3). Returns (3, 3) or (b, 3, 3).
/// Raises ShapeError, NonFiniteError.
#[pyfunction]
fn hat<'py>(py: Python<'py>, w: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "w", &w, |w: &Vector3<f64>| Ok(so3::hat(w)))
}

/// `vee(xi)`: the inverse of `hat`, w with ŵ = xi.
///
/// Args: xi — a skew-symmetric (3, 3) matrix or a batch (b, 3, 3). Returns (3,) or (b, 3).
/// Raises ShapeError, NonFiniteError, NotInGroupError (xi not skew: relative defect
/// ‖ξ + ξᵀ‖_F / max(1, ‖ξ‖_F) > 1e-10).
#[pyfunction]
fn vee<'py>(py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "xi", &xi, so3::vee)
}

/// `so3_exp(w)`: the rotation exp(ŵ) by Rodrigues' formula
/// R = I + (sin θ/θ) ŵ + ((1 − cos θ)/θ²) ŵ², θ = ‖w‖ (rotation by θ about w/θ).
///
/// Args: w — (3,) or (b, 3). Returns (3, 3) or (b, 3, 3). Raises ShapeError, NonFiniteError,
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
/// (the one whose component at the largest diagonal entry of R is positive); with `strict=True`
/// NoUniqueLogError is raised when π − θ ≤ 1e-12.
///
/// Args: R — a rotation (3, 3) or a batch (b, 3, 3). Returns (3,) or (b, 3).
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
            Ok(so3::log_unchecked(m))
        }
    })
}

/// `so3_cayley(w)`: the Cayley map cay(w) = (I − ŵ/2)⁻¹ (I + ŵ/2) = I + 4/(4 + ‖w‖²)(ŵ + ŵ²/2),
/// a rotation about w by the angle 2·atan(‖w‖/2) (agrees with exp to second order); defined and
/// computed scale-safely for every finite w (the angle tends to π as ‖w‖ → ∞).
///
/// Args: w — (3,) or (b, 3). Returns (3, 3) or (b, 3, 3). Raises ShapeError, NonFiniteError.
#[pyfunction]
fn so3_cayley<'py>(py: Python<'py>, w: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "w", &w, |w: &Vector3<f64>| Ok(so3::cayley(w)))
}

/// `so3_cayley_inv(R)`: the inverse Cayley map, w = 2·vee(R − Rᵀ)/(1 + tr R).
///
/// Args: R — a rotation (3, 3) or a batch (b, 3, 3). Returns (3,) or (b, 3).
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
/// Args: w — (3,) or (b, 3). Returns (3, 3) or (b, 3, 3).
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
/// Args: w — (3,) or (b, 3). Returns (3, 3) or (b, 3, 3).
/// Raises ShapeError, NonFiniteError, InvalidArgumentError (inverse at ‖w‖ = 2πk, k ≥ 1;
/// ‖w‖ > 2.25e14, the rule of so3_exp).
#[pyfunction]
#[pyo3(signature = (w, inverse = false))]
fn so3_jacobian_left<'py>(py: Python<'py>, w: ArrayIn<'py>, inverse: bool) -> PyResult<Out<'py>> {
    jacobian(py, &w, inverse, so3::jacobian_left, so3::jacobian_left_inv)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(hat, m)?)?;
    m.add_function(wrap_pyfunction!(vee, m)?)?;
    m.add_function(wrap_pyfunction!(so3_exp, m)?)?;
    m.add_function(wrap_pyfunction!(so3_log, m)?)?;
    m.add_function(wrap_pyfunction!(so3_cayley, m)?)?;
    m.add_function(wrap_pyfunction!(so3_cayley_inv, m)?)?;
    m.add_function(wrap_pyfunction!(so3_jacobian_right, m)?)?;
    m.add_function(wrap_pyfunction!(so3_jacobian_left, m)?)?;
    Ok(())
}
