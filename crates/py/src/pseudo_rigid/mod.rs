//! `lieflow.pseudo_rigid`: bindings of `lieflow::pseudo_rigid` (001: generalized pseudo-rigid
//! bodies on GL+(n)). Conversions only; every formula lives in the core crate.
//!
//! Every function of arrays follows the one vectorisation rule of the bindings (`crate::items`):
//! its arguments may carry leading axes, which broadcast as numpy's ((..., n, n) for a matrix,
//! (..., n) for a vector), and its results carry the broadcast leading axes; n is read from the
//! first argument (the first matrix argument in `dynamics`). `stratum` and `reduce` (dictionaries)
//! and `adjoint_motion` (a trajectory) take one item.
//!
//! Conventions: so(n) elements are skew (n, n) arrays; matrices on so(n) + so(n) are in the e_ij
//! basis (i < j, row by row) with the xi block first; pairing <xi, eta> = tr(xi.T @ eta) / 2.
#![allow(non_snake_case)]

pub mod dynamics;
pub mod ellipsoids;
pub mod equilibria;
pub mod gravity;
pub mod potential;
pub mod right_reduced;
pub mod system;

use lieflow::lie::gl::STRATUM_TOL;
use lieflow::pseudo_rigid::{
    connection as cn, momentum as mo, riemann, strata, Action, BiInertia, Body,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::real;
use crate::convert::{mat, put_mats, py_mat, py_vec, to_mat, ArrayIn};
use crate::errors::IntoPy;
use crate::items::{matrix_item, par_map_items_n, Input};

type Any<'py> = Bound<'py, PyAny>;

/// The kinds of item of the functions of this module, with n read from the first argument
/// (..., n, n).
#[derive(Clone, Copy)]
enum Kind {
    /// (n, n).
    Mat,
    /// (n,).
    Vector,
    /// ().
    Scalar,
    /// A matrix on so(n) + so(n): (n(n−1), n(n−1)).
    Dense,
    /// (n(n−1),).
    DenseVector,
    /// A matrix on one so(n): (n(n−1)/2, n(n−1)/2).
    Half,
}
use Kind::*;

impl Kind {
    fn shape(self, n: usize) -> Vec<usize> {
        let d = n * n.saturating_sub(1);
        match self {
            Mat => vec![n, n],
            Vector => vec![n],
            Scalar => vec![],
            Dense => vec![d, d],
            DenseVector => vec![d],
            Half => vec![d / 2, d / 2],
        }
    }
}

/// The functions of this module under the one vectorisation rule (`crate::items`): `f(n, items,
/// out)` on every item of the arguments (name, array, kind), whose leading axes broadcast, n from
/// the first argument (..., n, n); the outputs of kinds `outs` are written one after another into
/// `out` (one array, or a tuple of them).
fn map<'py, F>(
    py: Python<'py>,
    args: &[(&str, &ArrayIn<'py>, Kind)],
    outs: &[Kind],
    f: F,
) -> PyResult<Any<'py>>
where
    F: Fn(usize, &[&[f64]], &mut [f64]) -> lieflow::Result<()> + Sync + Send,
{
    let [n, _] = matrix_item(args[0].0, args[0].1)?;
    if outs.iter().any(|o| matches!(o, Dense)) {
        dense_fits(args[0].1)?;
    }
    let items: Vec<Vec<usize>> = args.iter().map(|a| a.2.shape(n)).collect();
    let outs: Vec<Vec<usize>> = outs.iter().map(|o| o.shape(n)).collect();
    let inputs: Vec<Input> = args
        .iter()
        .zip(&items)
        .map(|(a, item)| Input::new(a.0, a.1, item))
        .collect();
    let outs: Vec<&[usize]> = outs.iter().map(Vec::as_slice).collect();
    par_map_items_n(py, &inputs, &outs, |x, out| f(n, x, out))
}

/// For the functions that form a dense n(n−1)×n(n−1) matrix: refuses sizes that cannot be
/// allocated (an abort would take the Python process down) with InvalidArgumentError.
fn dense_fits(X: &ArrayIn<'_>) -> PyResult<()> {
    let [n, _] = matrix_item("X", X)?;
    let d = n * n.saturating_sub(1);
    lieflow::check::dense_size("X", d, d).py()
}

/// An (n, n) item as a matrix.
fn m(n: usize, x: &[f64]) -> lieflow::Mat {
    to_mat(n, n, x)
}

/// The bi-inertia tensor at the item X.
fn bi(n: usize, x: &[f64]) -> lieflow::Result<BiInertia> {
    BiInertia::new(&m(n, x))
}

/// Left inertia tensor :math:`A^L_X(\xi) = X X^\top \xi + \xi X X^\top` (001 (2.11)).
///
/// Args:
///     X: (n, n) with det X > 0; xi: (n, n) skew.
/// Returns:
///     (n, n) skew array.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0` or xi not skew).
#[pyfunction]
pub fn left_inertia<'py>(py: Python<'py>, X: ArrayIn<'py>, xi: ArrayIn<'py>) -> PyResult<Any<'py>> {
    map(
        py,
        &[("X", &X, Mat), ("xi", &xi, Mat)],
        &[Mat],
        |n, x, out| put_mats(out, &[&bi(n, x[0])?.left(&m(n, x[1]))?]),
    )
}

/// Right inertia tensor :math:`A^R_X(\xi) = X^\top X \xi + \xi X^\top X` (001 (2.11)).
///
/// Args and errors as `left_inertia`.
#[pyfunction]
pub fn right_inertia<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    xi: ArrayIn<'py>,
) -> PyResult<Any<'py>> {
    map(
        py,
        &[("X", &X, Mat), ("xi", &xi, Mat)],
        &[Mat],
        |n, x, out| put_mats(out, &[&bi(n, x[0])?.right(&m(n, x[1]))?]),
    )
}

/// The bi-inertia tensor :math:`B_X` (001 (6.9)) as an (n(n-1), n(n-1)) matrix in the
/// :math:`e_{ij}` basis, xi block first:
/// :math:`\begin{pmatrix} A^L_X & -2 \operatorname{Ad}_X \\ -2 \operatorname{Ad}_X^\top & A^R_X \end{pmatrix}`.
/// Symmetric on all of :math:`GL^+(n)`, positive definite when the singular values of X are
/// distinct (6.14).
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0`).
#[pyfunction]
pub fn bi_inertia<'py>(py: Python<'py>, X: ArrayIn<'py>) -> PyResult<Any<'py>> {
    map(py, &[("X", &X, Mat)], &[Dense], |n, x, out| {
        put_mats(out, &[&bi(n, x[0])?.try_matrix()?])
    })
}

/// :math:`B_X(\xi + \eta) = (A^L_X \xi - 2 X \eta X^\top, -2 X^\top \xi X + A^R_X \eta)`
/// (001 (6.9), (6.10)).
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
) -> PyResult<Any<'py>> {
    let args = [("X", &X, Mat), ("xi", &xi, Mat), ("eta", &eta, Mat)];
    map(py, &args, &[Mat, Mat], |n, x, out| {
        let (a, b) = bi(n, x[0])?.apply(&m(n, x[1]), &m(n, x[2]))?;
        put_mats(out, &[&a, &b])
    })
}

/// Solves :math:`B_X(\xi + \eta) = \lambda + \gamma` by the closed form in the SVD frame
/// (001 (7.6)-(7.9)), in :math:`O(n^3)` work: :math:`\lambda' = R^\top \lambda R`,
/// :math:`\gamma' = S^\top \gamma S`,
/// :math:`\xi'_{ij} = ((a_i^2 + a_j^2) \lambda'_{ij} + 2 a_i a_j \gamma'_{ij}) / (a_i^2 - a_j^2)^2`
/// (and symmetrically for :math:`\eta'`), rotated back.
///
/// Returns:
///     (xi, eta): two (n, n) skew arrays.
/// Raises:
///     DegenerateStratumError if two singular values of X coincide (gap :math:`\le 10^{-8} a_1`;
///     the message gives the smallest gap), ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn bi_inertia_solve<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    lam: ArrayIn<'py>,
    gam: ArrayIn<'py>,
) -> PyResult<Any<'py>> {
    let args = [("X", &X, Mat), ("lam", &lam, Mat), ("gam", &gam, Mat)];
    map(py, &args, &[Mat, Mat], |n, x, out| {
        let (a, b) = bi(n, x[0])?.solve(&m(n, x[1]), &m(n, x[2]))?;
        put_mats(out, &[&a, &b])
    })
}

/// Eigen-decomposition of :math:`B_X` (001 (8.14)-(8.15)): eigenvalues :math:`(a_i - a_j)^2` and
/// :math:`(a_i + a_j)^2` (:math:`i < j`) with orthonormal eigenvectors
/// :math:`(R e_{ij} R^\top \pm S e_{ij} S^\top) / \sqrt2`. Valid on all of :math:`GL^+(n)`.
///
/// Returns:
///     (values, vectors): (n(n-1),) non-decreasing and (n(n-1), n(n-1)) with the eigenvectors
///     as columns in :math:`e_{ij}` coordinates (xi block first):
///     :math:`B = V \operatorname{diag}(\mathrm{values}) V^\top`.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn bi_inertia_eigen<'py>(py: Python<'py>, X: ArrayIn<'py>) -> PyResult<Any<'py>> {
    map(py, &[("X", &X, Mat)], &[DenseVector, Dense], |n, x, out| {
        let (vals, vecs) = bi(n, x[0])?.eigen()?;
        out[..vals.len()].copy_from_slice(&vals);
        put_mats(&mut out[vals.len()..], &[&vecs])
    })
}

/// The quadratic form :math:`\langle \xi + \eta, B_X(\xi + \eta) \rangle` in SVD coordinates
/// (001 (6.14)); equals :math:`\|\xi X + X \eta^\top\|_F^2`.
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn bi_inertia_quadratic_form<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    xi: ArrayIn<'py>,
    eta: ArrayIn<'py>,
) -> PyResult<Any<'py>> {
    let args = [("X", &X, Mat), ("xi", &xi, Mat), ("eta", &eta, Mat)];
    map(py, &args, &[Scalar], |n, x, out| {
        out[0] = bi(n, x[0])?.quadratic_form(&m(n, x[1]), &m(n, x[2]))?;
        Ok(())
    })
}

/// Left connection :math:`\omega^L_X(Y) = (A^L_X)^{-1}(Y X^\top - X Y^\top)` (001 (2.14)); defined
/// on all of :math:`GL^+(n)` (:math:`\omega^L(\xi X) = \xi`, (2.16)).
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
) -> PyResult<Any<'py>> {
    map(
        py,
        &[("X", &X, Mat), ("Y", &Y, Mat)],
        &[Mat],
        |n, x, out| put_mats(out, &[&cn::left_connection(&bi(n, x[0])?, &m(n, x[1]))?]),
    )
}

/// Right connection :math:`\omega^R_X(Y) = (A^R_X)^{-1}(Y^\top X - X^\top Y)` (001 (2.15));
/// defined on all of :math:`GL^+(n)` (:math:`\omega^R(X \eta^\top) = \eta`, (2.17)).
///
/// Args and errors as `left_connection`.
#[pyfunction]
pub fn right_connection<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    Y: ArrayIn<'py>,
) -> PyResult<Any<'py>> {
    map(
        py,
        &[("X", &X, Mat), ("Y", &Y, Mat)],
        &[Mat],
        |n, x, out| put_mats(out, &[&cn::right_connection(&bi(n, x[0])?, &m(n, x[1]))?]),
    )
}

/// Bi-connection
/// :math:`\omega^B_X(Y) = B_X^{-1}((Y X^\top - X Y^\top) + (Y^\top X - X^\top Y))`
/// (001 (6.18)), via the closed-form inverse.
/// :math:`\omega^B(\xi X + X \eta^\top) = (\xi, \eta)` (6.19).
///
/// Returns:
///     (xi, eta): two (n, n) skew arrays.
/// Raises:
///     DegenerateStratumError (coincident singular values), ShapeError, NonFiniteError,
///     NotInGroupError.
#[pyfunction]
pub fn bi_connection<'py>(py: Python<'py>, X: ArrayIn<'py>, Y: ArrayIn<'py>) -> PyResult<Any<'py>> {
    map(
        py,
        &[("X", &X, Mat), ("Y", &Y, Mat)],
        &[Mat, Mat],
        |n, x, out| {
            let (a, b) = cn::bi_connection(&bi(n, x[0])?, &m(n, x[1]))?;
            put_mats(out, &[&a, &b])
        },
    )
}

/// The vertical vector :math:`(\xi + \eta)_P(X) = \xi X + X \eta^\top` (001 (6.17)).
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0`, xi or eta not skew).
#[pyfunction]
pub fn vertical_vector<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    xi: ArrayIn<'py>,
    eta: ArrayIn<'py>,
) -> PyResult<Any<'py>> {
    let args = [("X", &X, Mat), ("xi", &xi, Mat), ("eta", &eta, Mat)];
    map(py, &args, &[Mat], |n, x, out| {
        put_mats(
            out,
            &[&cn::vertical_vector(
                &bi(n, x[0])?,
                &m(n, x[1]),
                &m(n, x[2]),
            )?],
        )
    })
}

/// Horizontal part of Y at X for an action (001 (2.18)-(2.22), (6.4)-(6.7), (6.23)): Y minus
/// its orthogonal projection (metric :math:`\operatorname{tr}(Y^\top Z)`) onto the orbit's tangent
/// space. "left": the result H has :math:`H X^\top = X H^\top`; "right":
/// :math:`H^\top X = X^\top H`; "two-sided": both. Defined on every
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
) -> PyResult<Any<'py>> {
    let action: Action = action.parse().py()?;
    map(
        py,
        &[("X", &X, Mat), ("Y", &Y, Mat)],
        &[Mat],
        |n, x, out| {
            put_mats(
                out,
                &[&cn::horizontal_part(&bi(n, x[0])?, &m(n, x[1]), action)?],
            )
        },
    )
}

/// Locked inertia tensor from the metric :math:`\operatorname{tr}(Y^\top Z)` (001 (2.27), (6.24)):
/// the matrix of :math:`\operatorname{tr}(V(e_a)^\top V(e_b))` with :math:`V(\xi) = \xi X`
/// ("left"), :math:`X \xi^\top` ("right") or :math:`\xi X + X \eta^\top` ("two-sided", xi block
/// first). Equals :math:`A^L_X`, :math:`A^R_X`, :math:`B_X`.
///
/// Raises:
///     InvalidArgumentError (unknown action), ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
#[pyo3(signature = (X, action = "two-sided"))]
pub fn locked_inertia<'py>(py: Python<'py>, X: ArrayIn<'py>, action: &str) -> PyResult<Any<'py>> {
    let action: Action = action.parse().py()?;
    dense_fits(&X)?;
    let out = match action {
        Action::TwoSided => Dense,
        _ => Half,
    };
    map(py, &[("X", &X, Mat)], &[out], |n, x, out| {
        put_mats(out, &[&cn::locked_inertia(&bi(n, x[0])?, action)?])
    })
}

/// Angular momentum :math:`L = V X^\top - X V^\top` (001 (2.29), (7.3)) of a velocity or momentum V
/// at X.
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0`).
#[pyfunction]
pub fn angular_momentum<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    V: ArrayIn<'py>,
) -> PyResult<Any<'py>> {
    map(
        py,
        &[("X", &X, Mat), ("V", &V, Mat)],
        &[Mat],
        |n, x, out| put_mats(out, &[&mo::angular_momentum(&m(n, x[0]), &m(n, x[1]))?]),
    )
}

/// Circulation :math:`\Gamma = V^\top X - X^\top V` (001 (2.29), (7.3)) of a velocity or momentum V
/// at X.
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0`).
#[pyfunction]
pub fn circulation<'py>(py: Python<'py>, X: ArrayIn<'py>, V: ArrayIn<'py>) -> PyResult<Any<'py>> {
    map(
        py,
        &[("X", &X, Mat), ("V", &V, Mat)],
        &[Mat],
        |n, x, out| put_mats(out, &[&mo::circulation(&m(n, x[0]), &m(n, x[1]))?]),
    )
}

/// Body coordinates (R, a, S, Omega, adot, Lambda) of (X, V) (001 (2.4), (2.33), §4.1):
/// :math:`X = R \operatorname{diag}(a) S^\top`, :math:`\Omega = R^\top \dot R`,
/// :math:`\Lambda = S^\top \dot S`, from :math:`R^\top V S = \Omega A + \dot A - A \Lambda`.
///
/// Returns:
///     (R, a, S, Omega, adot, Lambda).
/// Raises:
///     DegenerateStratumError (coincident singular values: Omega, Lambda undetermined),
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn to_body<'py>(py: Python<'py>, X: ArrayIn<'py>, V: ArrayIn<'py>) -> PyResult<Any<'py>> {
    let outs = [Mat, Vector, Mat, Mat, Vector, Mat];
    map(py, &[("X", &X, Mat), ("V", &V, Mat)], &outs, |n, x, out| {
        let b = mo::to_body(&m(n, x[0]), &m(n, x[1]))?;
        let (r, a, s) = (&b.r, &b.a, &b.s);
        let (o, ad, l) = (&b.omega, &b.adot, &b.lambda);
        let nn = n * n;
        put_mats(&mut out[..nn], &[r])?;
        out[nn..nn + n].copy_from_slice(a);
        put_mats(&mut out[nn + n..3 * nn + n], &[s, o])?;
        out[3 * nn + n..3 * nn + 2 * n].copy_from_slice(ad);
        put_mats(&mut out[3 * nn + 2 * n..], &[l])
    })
}

/// (X, V) from body coordinates: :math:`X = R A S^\top`,
/// :math:`V = R (\Omega A + \dot A - A \Lambda) S^\top`
/// (001 (2.4), (2.33), §4.1).
///
/// Args:
///     R, S: (n, n) rotations; a: (n,) positive; Omega, Lambda: (n, n) skew; adot: (n,).
/// Returns:
///     (X, V).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (R, S not rotations, Omega, Lambda not skew),
///     InvalidArgumentError (some :math:`a_i \le 0`).
#[pyfunction]
pub fn from_body<'py>(
    py: Python<'py>,
    R: ArrayIn<'py>,
    a: ArrayIn<'py>,
    S: ArrayIn<'py>,
    Omega: ArrayIn<'py>,
    adot: ArrayIn<'py>,
    Lambda: ArrayIn<'py>,
) -> PyResult<Any<'py>> {
    let args = [
        ("R", &R, Mat),
        ("a", &a, Vector),
        ("S", &S, Mat),
        ("Omega", &Omega, Mat),
        ("adot", &adot, Vector),
        ("Lambda", &Lambda, Mat),
    ];
    map(py, &args, &[Mat, Mat], |n, x, out| {
        let body = Body {
            r: m(n, x[0]),
            a: x[1].to_vec(),
            s: m(n, x[2]),
            omega: m(n, x[3]),
            adot: x[4].to_vec(),
            lambda: m(n, x[5]),
        };
        let (X, V) = body.to_state()?;
        put_mats(out, &[&X, &V])
    })
}

/// Kinetic energy :math:`K = \tfrac12 \operatorname{tr}(V^\top V)` (001 (3.2); equal to (4.5),
/// (4.12), (6.28)).
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn kinetic_energy<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    V: ArrayIn<'py>,
) -> PyResult<Any<'py>> {
    map(
        py,
        &[("X", &X, Mat), ("V", &V, Mat)],
        &[Scalar],
        |n, x, out| {
            out[0] = mo::kinetic_energy(&m(n, x[0]), &m(n, x[1]))?;
            Ok(())
        },
    )
}

/// Stratum and isotropy of X under the two-sided :math:`SO(n) \times SO(n)` action (001 (6.2),
/// (9.2), (9.3)).
///
/// Args:
///     X: (n, n) with det X > 0; tol: relative tolerance for coinciding singular values
///     (default 1e-8).
/// Returns:
///     dict with "singular_values", "multiplicities", "min_gap", "principal", "dim_vertical" (rank
///     of :math:`(\xi, \eta) \mapsto \xi X + X \eta^\top`), "dim_horizontal", "isotropy" (e.g.
///     "(Z2)^2", "S(O(2)×O(1))", "SO(3)") and "isotropy_dim".
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

/// Riemann-ellipsoid variables (001 (3.4)): :math:`Q = X X^\top` (quadrupole),
/// :math:`N = X V^\top` (shear); :math:`N = \tfrac12 (-L + \dot Q)` (3.10).
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
) -> PyResult<Any<'py>> {
    map(
        py,
        &[("X", &X, Mat), ("V", &V, Mat)],
        &[Mat, Mat],
        |n, x, out| {
            let (q, nn) = riemann::riemann_variables(&m(n, x[0]), &m(n, x[1]))?;
            put_mats(out, &[&q, &nn])
        },
    )
}

/// Poisson bracket :math:`\{f, g\}` of functions of (Q, N) from the structure functions
/// (001 (9.1)): :math:`\{Q_{ij}, Q_{kl}\} = 0`,
/// :math:`\{Q_{ij}, N_{kl}\} = \delta_{il} Q_{jk} + \delta_{jl} Q_{ik}`,
/// :math:`\{N_{ij}, N_{kl}\} = \delta_{il} N_{kj} - \delta_{jk} N_{il}`.
///
/// Args:
///     Q, N: (n, n); dfdQ, dfdN, dgdQ, dgdN: (n, n) gradients (entries taken as coordinates).
/// Raises:
///     ShapeError, NonFiniteError.
#[pyfunction]
pub fn riemann_bracket<'py>(
    py: Python<'py>,
    Q: ArrayIn<'py>,
    N: ArrayIn<'py>,
    dfdQ: ArrayIn<'py>,
    dfdN: ArrayIn<'py>,
    dgdQ: ArrayIn<'py>,
    dgdN: ArrayIn<'py>,
) -> PyResult<Any<'py>> {
    let args = [
        ("Q", &Q, Mat),
        ("N", &N, Mat),
        ("dfdQ", &dfdQ, Mat),
        ("dfdN", &dfdN, Mat),
        ("dgdQ", &dgdQ, Mat),
        ("dgdN", &dgdN, Mat),
    ];
    map(py, &args, &[Scalar], |n, x, out| {
        let f = (&m(n, x[2]), &m(n, x[3]));
        let g = (&m(n, x[4]), &m(n, x[5]));
        out[0] = riemann::poisson_bracket(&m(n, x[0]), &m(n, x[1]), f, g)?;
        Ok(())
    })
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
    m.add_function(wrap_pyfunction!(loop_circulation, m)?)?;
    m.add_function(wrap_pyfunction!(loop_area, m)?)?;
    m.add_function(wrap_pyfunction!(guichardet_connection, m)?)?;
    m.add_function(wrap_pyfunction!(particle_locked_inertia, m)?)?;
    m.add_function(wrap_pyfunction!(right_reduced::reduced_euler_lagrange, m)?)?;
    crate::system::add_system::<right_reduced::PyRightReduced, lieflow::pseudo_rigid::RightReduced>(
        m,
    )?;
    dynamics::register(m)?;
    equilibria::register(m)?;
    gravity::register(m)?;
    Ok(())
}

/// Reduction (X, P) -> (a, p_a, p_Omega, p_Lambda) on the principal stratum (001 §7):
/// :math:`X = R \operatorname{diag}(a) S^\top` (a decreasing),
/// :math:`p_a = \operatorname{diag}(R^\top P S)`, :math:`p_\Omega = R^\top L R`,
/// :math:`p_\Lambda = S^\top \Gamma S`
/// (001 (2.32), (6.27)).
///
/// Returns:
///     dict with "a", "p_a" ((n,) arrays), "p_Omega", "p_Lambda", "R", "S" ((n, n) arrays).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (:math:`\det X \le 0`), DegenerateStratumError.
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
/// :math:`X = R A S^\top`, :math:`P = R (\Omega A + \operatorname{diag}(p_a) - A \Lambda) S^\top`
/// with :math:`\Omega + \Lambda = B_A^{-1}(p_\Omega + p_\Lambda)` (001 (7.9)).
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError (R, S not rotations, p's not skew),
///     InvalidArgumentError (:math:`a_i \le 0`), DegenerateStratumError (equal :math:`a_i`).
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
) -> PyResult<Any<'py>> {
    let args = [
        ("R", &R, Mat),
        ("S", &S, Mat),
        ("a", &a, Vector),
        ("p_a", &p_a, Vector),
        ("p_Omega", &p_Omega, Mat),
        ("p_Lambda", &p_Lambda, Mat),
    ];
    map(py, &args, &[Mat, Mat], |n, x, out| {
        let st = lieflow::pseudo_rigid::reduced::ReducedState {
            a: x[2].to_vec(),
            p_a: x[3].to_vec(),
            p_omega: m(n, x[4]),
            p_lambda: m(n, x[5]),
        };
        let (X, P) = lieflow::pseudo_rigid::reduced::reconstruct(&m(n, x[0]), &m(n, x[1]), &st)?;
        put_mats(out, &[&X, &P])
    })
}

type ArrD<'py> = Bound<'py, numpy::PyArrayDyn<f64>>;

/// Dedekind's adjoint motion :math:`X \mapsto X^\top`, :math:`P \mapsto P^\top` of stacked frames
/// (..., n, n) (000 §5.3): maps motions to motions and swaps angular momentum and circulation.
///
/// Returns:
///     :math:`(X^\top, P^\top)` with the shapes of the inputs.
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

/// Kelvin's circulation of a material loop (001 §2.5, (2.34)): the integral of
/// :math:`v \cdot dx` around the loop :math:`C = X(C_0)` in space, where :math:`C_0` is the
/// closed polygon through the label points (rows of `labels`; closed back to the first), its
/// particles at :math:`x = X u` moving with :math:`v = V u`.
///
/// Equals :math:`\langle \Gamma, \zeta \rangle = \tfrac12 \operatorname{tr}(\Gamma^\top \zeta)`
/// with :math:`\Gamma = V^\top X - X^\top V` the circulation and :math:`\zeta` =
/// `loop_area(labels)` (2.35): Kelvin's theorem (the integral is constant along a motion for
/// every loop) is the conservation of :math:`\Gamma`. Exact for the polygon (computed in space,
/// segment by segment).
///
/// Args:
///     X: (n, n) with det X > 0; V: (n, n) velocity; labels: (m, n), m >= 3.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
pub fn loop_circulation(X: ArrayIn<'_>, V: ArrayIn<'_>, labels: ArrayIn<'_>) -> PyResult<f64> {
    let labels = mat("labels", &labels)?;
    mo::loop_circulation(&mat("X", &X)?, &mat("V", &V)?, &labels).py()
}

/// The oriented areas
/// :math:`\zeta_{ij} = \int_{S_0} du_i \wedge du_j = \oint u_i\, du_j`
/// (001 (2.36)) of the closed polygon through the rows of `labels` ((m, n), m >= 3): a skew
/// (n, n) array whose (i, j) entry is the area of the loop's projection on the
/// :math:`(u_i, u_j)` plane
/// (counterclockwise positive).
///
/// Raises:
///     ShapeError, NonFiniteError.
#[pyfunction]
pub fn loop_area<'py>(
    py: Python<'py>,
    labels: ArrayIn<'py>,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    Ok(py_mat(py, &mo::loop_area(&mat("labels", &labels)?).py()?))
}

/// Guichardet's connection of N particles (001 §2.3, (2.23)–(2.26)):
/// :math:`\omega = A_Q^{-1} \bigl(\sum_a m_a (v_a x_a^\top - x_a v_a^\top)\bigr) \in \mathfrak{so}(n)`,
/// :math:`A_Q \xi = Q \xi + \xi Q`, :math:`Q = \sum_a m_a x_a x_a^\top`: the rigid rotation that
/// carries the particles' angular momentum (in three dimensions
/// :math:`\omega^\vee = A^{-1} \sum m\, x \times v` with the inertia tensor
/// :math:`A = \operatorname{tr}(Q)\, \mathrm{Id} - Q`, :math:`\omega^\vee` the vector of
/// :math:`\omega`). For particles :math:`x = X u` whose labels have :math:`\sum m\, u u^\top = 1`
/// it is the left connection `left_connection(X, V)` (2.14): the pseudo-rigid body's connection is
/// its continuum case.
///
/// Args:
///     masses: (N,) > 0; positions, velocities: (N, n).
/// Returns:
///     (n, n) skew array.
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError (masses <= 0; particles on a line).
#[pyfunction]
pub fn guichardet_connection<'py>(
    py: Python<'py>,
    masses: ArrayIn<'py>,
    positions: ArrayIn<'py>,
    velocities: ArrayIn<'py>,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let masses = crate::convert::vector("masses", &masses)?;
    let (x, v) = (
        mat("positions", &positions)?,
        mat("velocities", &velocities)?,
    );
    Ok(py_mat(
        py,
        &cn::guichardet_connection(&masses, &x, &v).py()?,
    ))
}

/// The locked inertia of N particles (001 (2.27)): the Gram matrix
/// :math:`\mathbb{I}_{ab} = \sum_\alpha m_\alpha (e_a x_\alpha) \cdot (e_b x_\alpha)` of so(n)'s
/// basis :math:`e_{ij}` (:math:`i < j`, the order of `locked_inertia`), the matrix of :math:`A_Q`; for :math:`x = X u` with
/// :math:`\sum m\, u u^\top = 1` it equals
/// `locked_inertia(X, "left")`.
///
/// Args:
///     masses: (N,) > 0; positions: (N, n).
/// Returns:
///     (d, d) array, d = n(n-1)/2.
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError.
#[pyfunction]
pub fn particle_locked_inertia<'py>(
    py: Python<'py>,
    masses: ArrayIn<'py>,
    positions: ArrayIn<'py>,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let masses = crate::convert::vector("masses", &masses)?;
    let x = mat("positions", &positions)?;
    Ok(py_mat(py, &cn::particle_locked_inertia(&masses, &x).py()?))
}
