//! Bindings of `lieflow::lie::rotations`: quaternions and Euler angles ↔ rotation matrices in
//! scipy's conventions, mapped over any leading axes (`crate::items::map_items`).

#![allow(non_snake_case)]

use lieflow::lie::rotations::{self, EulerSequence, Quat};
use nalgebra::Matrix3;
use pyo3::prelude::*;

use crate::convert::ArrayIn;
use crate::errors::IntoPy;
use crate::items::{map_items, Input};

/// A 3×3 item (row-major) as a matrix.
fn matrix(item: &[f64]) -> Matrix3<f64> {
    Matrix3::from_row_slice(item)
}

/// Writes a matrix to a row-major item.
fn store(m: &Matrix3<f64>, out: &mut [f64]) {
    for (k, o) in out.iter_mut().enumerate() {
        *o = m[(k / 3, k % 3)];
    }
}

/// `to_quaternion(R, scalar_first=True)`: the unit quaternion of a rotation (Shepperd's method),
/// canonical sign: :math:`w \ge 0` (where :math:`w = 0`, the first non-zero of x, y, z is
/// positive), i.e. scipy's `Rotation.from_matrix(R).as_quat(canonical=True)`. Hamilton
/// convention, :math:`R v = q v \bar q`.
///
/// Args: R — (..., 3, 3) rotations (any leading axes); scalar_first — (w, x, y, z) if True
/// (default), scipy's default order (x, y, z, w) if False.
/// A matrix within that tolerance but not orthogonal to round-off is read as the nearest
/// rotation (as scipy's `from_matrix`), as by every function taking rotations.
/// Returns: (..., 4). Raises ShapeError, NonFiniteError, NotInGroupError
/// (:math:`\|R^\top R - I\|_F` or :math:`|\det R - 1| > 10^{-10}`).
#[pyfunction]
#[pyo3(signature = (R, scalar_first = true))]
fn to_quaternion<'py>(
    py: Python<'py>,
    R: ArrayIn<'py>,
    scalar_first: bool,
) -> PyResult<Bound<'py, PyAny>> {
    map_items(py, &[Input::new("R", &R, &[3, 3])], &[4], |x, out| {
        let [w, a, b, c] = rotations::to_quaternion(&matrix(x[0]))?;
        out.copy_from_slice(&if scalar_first {
            [w, a, b, c]
        } else {
            [a, b, c, w]
        });
        Ok(())
    })
}

/// `from_quaternion(q, scalar_first=True)`: the rotation matrix of a quaternion, normalised
/// first (scale-safely: any non-zero finite size), as scipy's `Rotation.from_quat(q).as_matrix()`;
/// :math:`q` and :math:`-q` give the same rotation.
///
/// Args: q — (..., 4) (any leading axes); scalar_first — q = (w, x, y, z) if True (default),
/// (x, y, z, w) (scipy's default order) if False.
/// Returns: (..., 3, 3). Raises ShapeError, NonFiniteError, InvalidArgumentError (the zero
/// quaternion).
#[pyfunction]
#[pyo3(signature = (q, scalar_first = true))]
fn from_quaternion<'py>(
    py: Python<'py>,
    q: ArrayIn<'py>,
    scalar_first: bool,
) -> PyResult<Bound<'py, PyAny>> {
    map_items(py, &[Input::new("q", &q, &[4])], &[3, 3], |x, out| {
        let q = x[0];
        let q: Quat = if scalar_first {
            [q[0], q[1], q[2], q[3]]
        } else {
            [q[3], q[0], q[1], q[2]]
        };
        store(&rotations::from_quaternion(&q)?, out);
        Ok(())
    })
}

/// `to_euler(R, seq)`: the Euler angles (radians) of rotations in scipy's sequence convention:
/// those of scipy's `Rotation.from_matrix(R).as_euler(seq)` (the same method, Bernardes &
/// Viollet 2022), equal except that an angle of exactly :math:`\pm\pi` may come out with the other
/// sign (the same rotation): lieflow starts from the canonical quaternion (:math:`w \ge 0`), scipy
/// from the
/// sign its `from_matrix` returns.
///
/// seq: 3 letters from x, y, z; upper case = intrinsic (about the rotating axes: "XYZ" is
/// :math:`R = R_x(a) R_y(b) R_z(c)`), lower case = extrinsic (about the fixed axes: "xyz" is
/// :math:`R = R_z(c) R_y(b) R_x(a)`); no two consecutive letters equal: the 6 proper-Euler ("ZXZ",
/// …) and 6 Tait–Bryan ("XYZ", …) sequences. Angles are in the order of the letters.
///
/// Ranges (scipy's): first and third angle in :math:`[-\pi, \pi]`; the middle one in
/// :math:`[0, \pi]` (proper Euler) or :math:`[-\pi/2, \pi/2]` (Tait–Bryan). Gimbal lock (middle
/// angle within 1e-7 of 0 or :math:`\pi`, resp. :math:`\pm\pi/2`):
/// as scipy, the third angle is set to 0 and the first carries the rotation about the common
/// axis; unlike scipy, no warning is issued (never NaN). Inside that 1e-7 band
/// from_euler(to_euler(R)) reproduces R to ~1e-7 only, as scipy's.
///
/// Args: R — (..., 3, 3) rotations; seq — the sequence. Returns: (..., 3).
/// Raises ShapeError, NonFiniteError, NotInGroupError, InvalidArgumentError (bad seq).
#[pyfunction]
fn to_euler<'py>(py: Python<'py>, R: ArrayIn<'py>, seq: &str) -> PyResult<Bound<'py, PyAny>> {
    let seq: EulerSequence = seq.parse().py()?;
    map_items(py, &[Input::new("R", &R, &[3, 3])], &[3], |x, out| {
        out.copy_from_slice(&rotations::to_euler(&matrix(x[0]), seq)?);
        Ok(())
    })
}

/// `from_euler(angles, seq)`: the rotation matrices of Euler angles (radians, in the order of
/// the letters of seq; any values), as scipy's `Rotation.from_euler(seq, angles).as_matrix()`.
/// seq as in `to_euler`: "XYZ" is :math:`R_x(a) R_y(b) R_z(c)`, "xyz" is
/// :math:`R_z(c) R_y(b) R_x(a)`.
///
/// Args: angles — (..., 3) (any leading axes); seq — the sequence. Returns: (..., 3, 3).
/// Raises ShapeError, NonFiniteError, InvalidArgumentError (bad seq; an angle beyond
/// 2.25e14 rad, where more than 0.05 rad of it is lost to rounding: the rule of every
/// exponential in lieflow.lie).
#[pyfunction]
fn from_euler<'py>(
    py: Python<'py>,
    angles: ArrayIn<'py>,
    seq: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let seq: EulerSequence = seq.parse().py()?;
    map_items(
        py,
        &[Input::new("angles", &angles, &[3])],
        &[3, 3],
        |x, out| {
            let a = x[0];
            store(&rotations::from_euler(&[a[0], a[1], a[2]], seq)?, out);
            Ok(())
        },
    )
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(to_quaternion, m)?)?;
    m.add_function(wrap_pyfunction!(from_quaternion, m)?)?;
    m.add_function(wrap_pyfunction!(to_euler, m)?)?;
    m.add_function(wrap_pyfunction!(from_euler, m)?)?;
    Ok(())
}
