//! `lieflow.elliptic`: bindings of `lieflow::numerics::elliptic` (Jacobi elliptic functions and the
//! elliptic integrals of the first kind, parameter m = k^2 as in scipy.special), vectorised with
//! numpy broadcasting.

use lieflow::numerics::elliptic;
use pyo3::prelude::*;

use crate::convert::ArrayIn;
use crate::items::{map_items, Input};

type Any<'py> = Bound<'py, PyAny>;

fn scalar<'a, 'py>(what: &'a str, a: &'a ArrayIn<'py>) -> Input<'a, 'py> {
    Input::new(what, a, &[])
}

/// Jacobi elliptic functions
/// :math:`(\operatorname{sn}, \operatorname{cn}, \operatorname{dn})(u \mid m)` by the descending
/// Landen transformation (Abramowitz & Stegun 16.4), as `scipy.special.ellipj` (which also returns
/// the amplitude).
///
/// Args:
///     u: argument; m: parameter :math:`m = k^2`, :math:`0 \le m < 1`. Broadcast together.
/// Returns:
///     (sn, cn, dn), floats or arrays of the broadcast shape.
/// Raises:
///     InvalidArgumentError (m outside [0, 1)), NonFiniteError, ShapeError.
#[pyfunction]
fn ellipj<'py>(
    py: Python<'py>,
    u: ArrayIn<'py>,
    m: ArrayIn<'py>,
) -> PyResult<(Any<'py>, Any<'py>, Any<'py>)> {
    let r = map_items(py, &[scalar("u", &u), scalar("m", &m)], &[3], |x, out| {
        let (sn, cn, dn) = elliptic::ellipj(x[0][0], x[1][0])?;
        out.copy_from_slice(&[sn, cn, dn]);
        Ok(())
    })?;
    // (..., 3) -> three (...) arrays (numpy scalars for scalar inputs).
    let r = py.import("numpy")?.getattr("moveaxis")?.call1((r, -1, 0))?;
    Ok((r.get_item(0)?, r.get_item(1)?, r.get_item(2)?))
}

/// Complete elliptic integral of the first kind K(m) (A&S 17.6, by the AGM), as
/// `scipy.special.ellipk`.
///
/// Raises:
///     InvalidArgumentError (m outside [0, 1)), ShapeError.
#[pyfunction]
fn ellipk<'py>(py: Python<'py>, m: ArrayIn<'py>) -> PyResult<Any<'py>> {
    map_items(py, &[scalar("m", &m)], &[], |x, out| {
        out[0] = elliptic::ellipk(x[0][0])?;
        Ok(())
    })
}

/// Incomplete elliptic integral of the first kind F(phi | m) for any real phi (Carlson's R_F),
/// as `scipy.special.ellipkinc`; it inverts the amplitude: sn(F(phi | m) | m) = sin(phi).
///
/// Raises:
///     InvalidArgumentError (m outside [0, 1)), NonFiniteError, ShapeError.
#[pyfunction]
fn ellipf<'py>(py: Python<'py>, phi: ArrayIn<'py>, m: ArrayIn<'py>) -> PyResult<Any<'py>> {
    map_items(
        py,
        &[scalar("phi", &phi), scalar("m", &m)],
        &[],
        |x, out| {
            out[0] = elliptic::ellipf(x[0][0], x[1][0])?;
            Ok(())
        },
    )
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(ellipj, m)?)?;
    m.add_function(wrap_pyfunction!(ellipk, m)?)?;
    m.add_function(wrap_pyfunction!(ellipf, m)?)?;
    Ok(())
}
