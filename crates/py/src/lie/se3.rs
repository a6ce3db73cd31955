//! Bindings of `lieflow::lie::se3`: rigid motions as 4×4 homogeneous matrices [[R, t], [0, 1]],
//! algebra elements as 6-vectors (ω, v) with the rotation first; batched over a leading axis.

use lieflow::lie::se3::{self, SE3};
use lieflow::lie::MatrixLieGroup;
use lieflow::Error;
use nalgebra::{Matrix4, Vector6};
use pyo3::prelude::*;

use crate::batch::{map_batch, par_fill, read_items, Out};
use crate::convert::ArrayIn;
use crate::errors::to_py;

/// `se3_exp(xi)`: exp of ξ = (ω, v) (rotation first) as the 4×4 matrix [[exp(ω̂), V(ω) v], [0, 1]],
/// V(ω) = I + ((1 − cos θ)/θ²) ω̂ + ((θ − sin θ)/θ³) ω̂² (the left Jacobian of SO(3)), θ = ‖ω‖;
/// equal to scipy.linalg.expm([[ω̂, v], [0, 0]]).
///
/// Args: xi — (6,) or (b, 6). Returns (4, 4) or (b, 4, 4). Raises ShapeError, NonFiniteError,
/// InvalidArgumentError (‖ω‖ > 2.25e14, the rule of so3_exp; a translation beyond the f64 range).
#[pyfunction]
fn se3_exp<'py>(py: Python<'py>, xi: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "xi", &xi, |x: &Vector6<f64>| Ok(se3::exp(x)?.matrix4()))
}

/// `se3_log(g, strict=False)`: the logarithm ξ = (ω, v) of g = [[R, t], [0, 1]]: ω = so3_log(R)
/// (‖ω‖ ≤ π) and v = V(ω)⁻¹ t. At a rotation angle of π exactly, `strict=False` returns one of the
/// two logarithms and `strict=True` raises NoUniqueLogError (when π − θ ≤ 1e-12).
///
/// Args: g — (4, 4) or (b, 4, 4). Returns (6,) or (b, 6).
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

/// `se3_Ad(g)`: the 6×6 matrix of the adjoint action on (ω, v) coordinates,
/// Ad_g = [[R, 0], [t̂ R, R]], i.e. Ad_g (ω, v) = (R ω, t × R ω + R v), so that
/// exp(Ad_g ξ) = g exp(ξ) g⁻¹.
///
/// Args: g — (4, 4) or (b, 4, 4). Returns (6, 6) or (b, 6, 6).
/// Raises ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
#[pyo3(name = "se3_Ad")]
fn se3_ad<'py>(py: Python<'py>, g: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "g", &g, |m: &Matrix4<f64>| {
        Ok(SE3::from_matrix4(m)?.adjoint_matrix())
    })
}

/// `se3_inverse(g)`: (R, t)⁻¹ = (Rᵀ, −Rᵀ t) as a 4×4 matrix.
///
/// Args: g — (4, 4) or (b, 4, 4). Returns the same shape.
/// Raises ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
fn se3_inverse<'py>(py: Python<'py>, g: ArrayIn<'py>) -> PyResult<Out<'py>> {
    map_batch(py, "g", &g, |m: &Matrix4<f64>| {
        Ok(SE3::from_matrix4(m)?.inverse().matrix4())
    })
}

/// `se3_compose(g, h)`: the product g·h = (R_g R_h, R_g t_h + t_g) as a 4×4 matrix.
///
/// Args: g, h — (4, 4) or (b, 4, 4); a single matrix is combined with every element of a batch,
/// two batches must have the same length. Returns (4, 4) or (b, 4, 4).
/// Raises ShapeError (incl. batch lengths that differ), NonFiniteError, NotInGroupError.
#[pyfunction]
fn se3_compose<'py>(py: Python<'py>, g: ArrayIn<'py>, h: ArrayIn<'py>) -> PyResult<Out<'py>> {
    let (gs, bg) = read_items::<Matrix4<f64>>("g", &g)?;
    let (hs, bh) = read_items::<Matrix4<f64>>("h", &h)?;
    // A single element broadcasts over the other batch; an empty batch gives an empty result.
    let n = if gs.is_empty() || hs.is_empty() {
        0
    } else {
        gs.len().max(hs.len())
    };
    if bg && bh && gs.len() != hs.len() {
        return Err(to_py(Error::shape(
            "h",
            format!("a batch of the same length as g ({}, 4, 4)", gs.len()),
            format!("({}, 4, 4)", hs.len()),
        )));
    }
    par_fill(py, "g, h", n, bg || bh, |k| {
        let g = SE3::from_matrix4(&gs[k.min(gs.len() - 1)])?;
        let h = SE3::from_matrix4(&hs[k.min(hs.len() - 1)])
            .map_err(|e| e.map_what(|w| format!("h ({w})")))?;
        Ok(g.compose(&h).matrix4())
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(se3_exp, m)?)?;
    m.add_function(wrap_pyfunction!(se3_log, m)?)?;
    m.add_function(wrap_pyfunction!(se3_ad, m)?)?;
    m.add_function(wrap_pyfunction!(se3_inverse, m)?)?;
    m.add_function(wrap_pyfunction!(se3_compose, m)?)?;
    Ok(())
}
