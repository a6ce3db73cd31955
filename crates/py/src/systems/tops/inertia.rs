//! `lieflow.inertia_tensor`, `lieflow.mass_matrix`, `lieflow.spatial_inertia`: the inertia of a
//! body (000 §3.1, (4.1); bindings of `lieflow::systems::tops::inertia`).

use lieflow::systems::tops::inertia::{self as core, Solid};
use lieflow::Error;
use nalgebra::Matrix3;
use numpy::PyArray2;
use pyo3::prelude::*;

use crate::convert::{mat, py_mat3, real_opt, shape_str, vector, ArrayIn};
use crate::errors::{to_py, IntoPy};
use crate::items::{map_items, Input};

/// Reads (masses, positions) or (shape, mass, semi_axes): the mass matrix J (n, J row-major).
fn mass_matrix_of_args(
    masses: Option<ArrayIn<'_>>,
    positions: Option<ArrayIn<'_>>,
    shape: Option<&str>,
    mass: Option<f64>,
    semi_axes: Option<ArrayIn<'_>>,
) -> PyResult<(usize, Vec<f64>)> {
    let usage = "give masses and positions, or shape=\"ellipsoid\"|\"box\" with mass and \
                 semi_axes";
    match (masses, positions, shape, mass, semi_axes) {
        (Some(m), Some(x), None, None, None) => {
            let masses = vector("masses", &m)?;
            let v = x.as_array();
            if v.ndim() != 2 || v.shape()[0] != masses.len() {
                return Err(to_py(Error::shape(
                    "positions",
                    format!("({}, n): one row per mass", masses.len()),
                    shape_str(v.shape()),
                )));
            }
            let flat = crate::convert::read_all("positions", &v)?;
            core::mass_matrix(&masses, &flat).py()
        }
        (None, None, Some(shape), Some(mass), Some(a)) => {
            let solid = match shape {
                "ellipsoid" => Solid::Ellipsoid,
                "box" => Solid::Box,
                other => {
                    return Err(to_py(Error::invalid(
                        "shape",
                        format!("expected \"ellipsoid\" or \"box\", got {other:?}"),
                    )))
                }
            };
            let a = vector("semi_axes", &a)?;
            Ok((a.len(), core::mass_matrix_of(solid, mass, &a).py()?))
        }
        _ => Err(to_py(Error::invalid("masses", usage))),
    }
}

/// The inertia tensor :math:`\mathbb{I} = \sum_k m_k (\|x_k\|^2 \mathrm{Id} - x_k x_k^\top)` (3, 3)
/// of a body (000 §3.1): of point masses (`masses` (k,), `positions` (k, 3) in the body frame),
/// or of a homogeneous solid in its principal frame (`shape` "ellipsoid"
/// (:math:`\mathbb{I} = \frac{m}{5} \operatorname{diag}(b^2 + c^2, a^2 + c^2, a^2 + b^2)`) or "box"
/// (:math:`\frac{m}{3} \operatorname{diag}(\dots)`, semi-axes the half-sides), with `mass` and
/// `semi_axes` (a, b, c)). Its kinetic energy is
/// :math:`\tfrac12 \langle \Omega, \mathbb{I}\Omega \rangle`: pass it to `RigidBody`, `HeavyTop`
/// or `EulerPoincare("so3", inertia=...)`.
///
/// Raises:
///     InvalidArgumentError (neither or both forms, negative masses, all masses zero, a
///     non-positive mass or semi-axis, an unknown shape), ShapeError (positions not (k, 3)),
///     NonFiniteError.
#[pyfunction]
#[pyo3(signature = (masses=None, positions=None, *, shape=None, mass=None, semi_axes=None))]
pub fn inertia_tensor<'py>(
    py: Python<'py>,
    masses: Option<ArrayIn<'py>>,
    positions: Option<ArrayIn<'py>>,
    shape: Option<String>,
    #[pyo3(from_py_with = real_opt)] mass: Option<f64>,
    semi_axes: Option<ArrayIn<'py>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (n, j) = mass_matrix_of_args(masses, positions, shape.as_deref(), mass, semi_axes)?;
    if n != 3 {
        return Err(to_py(Error::shape(
            "positions",
            "three-dimensional positions (k, 3) or semi-axes (3,)",
            format!("n = {n}"),
        )));
    }
    Ok(py_mat3(py, &core::from_mass_matrix(&j, "positions").py()?))
}

/// The mass matrix :math:`J = \sum_k m_k x_k x_k^\top` (n, n) of a body in :math:`\mathbb{R}^n`
/// (000 §3.1, the inertia of `GeneralizedRigidBody`, whose kinetic energy is
/// :math:`\tfrac12 \langle \Omega, J\Omega + \Omega J \rangle`): of point masses (`masses` (k,),
/// `positions` (k, n)), or of a homogeneous solid (`shape` "ellipsoid": :math:`m a_i^2/(n + 2)`
/// on the diagonal; "box": :math:`m a_i^2/3`) with `mass` and `semi_axes` (n,). In three
/// dimensions :math:`\mathbb{I} = \operatorname{tr}(J)\, \mathrm{Id} - J` (`inertia_tensor`).
///
/// Raises:
///     InvalidArgumentError, ShapeError, NonFiniteError (as `inertia_tensor`).
#[pyfunction]
#[pyo3(signature = (masses=None, positions=None, *, shape=None, mass=None, semi_axes=None))]
pub fn mass_matrix<'py>(
    py: Python<'py>,
    masses: Option<ArrayIn<'py>>,
    positions: Option<ArrayIn<'py>>,
    shape: Option<String>,
    #[pyo3(from_py_with = real_opt)] mass: Option<f64>,
    semi_axes: Option<ArrayIn<'py>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (n, j) = mass_matrix_of_args(masses, positions, shape.as_deref(), mass, semi_axes)?;
    Ok(crate::convert::py_mat(
        py,
        &crate::convert::to_mat(n, n, &j),
    ))
}

/// The spatial inertia :math:`J = R\, \mathbb{I} R^\top` (000 (4.1)) of a body at attitude R
/// (..., 3, 3) with inertia :math:`\mathbb{I}`: principal moments (3,) or a matrix (3, 3)
/// (leading axes broadcast with R): :math:`R\, \mathbb{I}\Omega = J\omega` for the spatial
/// angular velocity :math:`\omega = R\Omega`.
///
/// Raises:
///     NotInGroupError (R not a rotation), ShapeError, NonFiniteError.
#[pyfunction]
#[allow(non_snake_case)]
pub fn spatial_inertia<'py>(
    py: Python<'py>,
    R: ArrayIn<'py>,
    inertia: ArrayIn<'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let i = match inertia.as_array().shape() {
        [3] => {
            let m = vector("inertia", &inertia)?;
            Matrix3::from_diagonal(&nalgebra::Vector3::new(m[0], m[1], m[2]))
        }
        [3, 3] => {
            let m = mat("inertia", &inertia)?;
            Matrix3::from_fn(|a, b| m[(a, b)])
        }
        s => {
            return Err(to_py(Error::shape(
                "inertia",
                "(3,) principal moments or a (3, 3) matrix",
                shape_str(s),
            )))
        }
    };
    map_items(py, &[Input::new("R", &R, &[3, 3])], &[3, 3], |x, out| {
        let jj = core::spatial_inertia(&Matrix3::from_row_slice(x[0]), &i)?;
        for a in 0..3 {
            for b in 0..3 {
                out[a * 3 + b] = jj[(a, b)];
            }
        }
        Ok(())
    })
}

/// Adds the three functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(inertia_tensor, m)?)?;
    m.add_function(wrap_pyfunction!(mass_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(spatial_inertia, m)?)
}
