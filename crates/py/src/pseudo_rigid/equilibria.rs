//! Relative equilibria of pseudo-rigid bodies and their stability (001 §8): bindings of
//! `lieflow::pseudo_rigid::{equilibria, stability}` in `lieflow.pseudo_rigid`. Conversions only.
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::pseudo_rigid::dynamics::FullBody;
use lieflow::pseudo_rigid::ellipsoids as ell;
use lieflow::pseudo_rigid::equilibria as eq;
use lieflow::pseudo_rigid::potential::Potential;
use lieflow::pseudo_rigid::stability as st;
use lieflow::pseudo_rigid::PseudoRigidBody;
use lieflow::{Error, Mat};
use numpy::ndarray::Array3;
use numpy::{Complex64, IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::potential::PyPotential;
use crate::convert::{mat, py_mat, py_vec, vector, ArrayIn};
use crate::convert::{real_pair, size};
use crate::errors::{checked, to_py, IntoPy};
use crate::system::PySystem;

type Arr2<'py> = Bound<'py, PyArray2<f64>>;
type Arr3<'py> = Bound<'py, PyArray3<f64>>;

/// Runs `f` on the potential and re-raises the first exception of a callable potential.
fn with_potential<T>(
    potential: &Bound<'_, PyPotential>,
    f: impl FnOnce(&dyn Potential) -> lieflow::Result<T>,
) -> PyResult<T> {
    checked(|| f(&*potential.get().inner))
}

/// The amended potential
/// :math:`V_{\lambda+\gamma}(X) = U(X) + \tfrac12 \langle \lambda+\gamma, B_X^{-1}(\lambda+\gamma) \rangle`
/// (001 (8.11)) for spatial momenta :math:`\lambda = L`, :math:`\gamma = \Gamma` (skew (n, n)) and
/// X on the principal stratum.
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError, DegenerateStratumError.
#[pyfunction]
fn amended_potential(
    X: ArrayIn<'_>,
    lam: ArrayIn<'_>,
    gam: ArrayIn<'_>,
    potential: &Bound<'_, PyPotential>,
) -> PyResult<f64> {
    let (x, l, g) = (mat("X", &X)?, mat("lam", &lam)?, mat("gam", &gam)?);
    with_potential(potential, |p| eq::amended_potential(p, &x, &l, &g))
}

/// The augmented potential
/// :math:`U_{\xi+\eta}(X) = U(X) - \tfrac12 \langle \xi+\eta, B_X(\xi+\eta) \rangle` (001 (8.12)),
/// with :math:`\langle \xi+\eta, B_X(\xi+\eta) \rangle = \|\xi X - X \eta\|^2`, for angular
/// velocities :math:`\xi, \eta` (skew (n, n)).
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
fn augmented_potential(
    X: ArrayIn<'_>,
    xi: ArrayIn<'_>,
    eta: ArrayIn<'_>,
    potential: &Bound<'_, PyPotential>,
) -> PyResult<f64> {
    let (x, a, b) = (mat("X", &X)?, mat("xi", &xi)?, mat("eta", &eta)?);
    with_potential(potential, |p| eq::augmented_potential(p, &x, &a, &b))
}

/// :math:`\partial U_{\xi+\eta}/\partial X` (pairing :math:`\operatorname{tr}(A^\top B)`) as an
/// (n, n) array (001 (8.12)); it vanishes at a relative equilibrium :math:`X_0` with velocities
/// :math:`\xi, \eta`.
///
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError.
#[pyfunction]
fn augmented_gradient<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    xi: ArrayIn<'py>,
    eta: ArrayIn<'py>,
    potential: &Bound<'py, PyPotential>,
) -> PyResult<Arr2<'py>> {
    let (x, a, b) = (mat("X", &X)?, mat("xi", &xi)?, mat("eta", &eta)?);
    let g = with_potential(potential, |p| eq::augmented_gradient(p, &x, &a, &b))?;
    Ok(py_mat(py, &g))
}

/// The Hessian of the augmented potential :math:`U_{\xi+\eta}` (001 (8.12)) at X, pairing
/// :math:`\operatorname{tr}(A^\top B)`:
/// :math:`D^2U_{\xi+\eta}(X)[V] = D^2U(X)[V] + \xi W_V - W_V \eta` with
/// :math:`W_V = \xi V - V \eta` (the kinetic part :math:`-\tfrac12 \|\xi X - X \eta\|^2` is
/// quadratic in X).
///
/// Returns:
///     with V an (n, n) direction: :math:`D^2U_{\xi+\eta}(X)[V]`, (n, n); without V: the symmetric
///     (n^2, n^2) matrix in the row-major vec(X) basis (column i*n + j is the product with the unit
///     matrix E_ij, flattened row-major).
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError, InvalidArgumentError (n^4 too large).
#[pyfunction]
#[pyo3(signature = (X, xi, eta, potential, V = None))]
fn augmented_hessian<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    xi: ArrayIn<'py>,
    eta: ArrayIn<'py>,
    potential: &Bound<'py, PyPotential>,
    V: Option<ArrayIn<'py>>,
) -> PyResult<Arr2<'py>> {
    let (x, a, b) = (mat("X", &X)?, mat("xi", &xi)?, mat("eta", &eta)?);
    let h = match V {
        Some(v) => {
            let v = mat("V", &v)?;
            with_potential(potential, |p| eq::augmented_hessian(p, &x, &a, &b, &v))?
        }
        None => with_potential(potential, |p| eq::augmented_hessian_matrix(p, &x, &a, &b))?,
    };
    Ok(py_mat(py, &h))
}

/// The Hessian of the amended potential
/// :math:`V_{\lambda+\gamma}(X) = U(X) + \tfrac12 \langle \lambda+\gamma, B_X^{-1}(\lambda+\gamma) \rangle`
/// (001 (8.11)), analytic: with :math:`\kappa = \xi+\eta = B_X^{-1}(\lambda+\gamma)` and its
/// derivative :math:`d\kappa[V] = -B_X^{-1}(J(V, W) + J(X, W_V))` (J the momentum map,
/// :math:`W = \xi X - X \eta`, :math:`W_V = \xi V - V \eta`), it is the augmented Hessian at
/// :math:`\kappa` plus a positive semidefinite term:
/// :math:`\langle Y, D^2V[V] \rangle = \langle Y, D^2U_\kappa[V] \rangle + \langle d\kappa[Y], B_X\, d\kappa[V] \rangle`.
///
/// Returns:
///     with V an (n, n) direction: :math:`D^2V_{\lambda+\gamma}(X)[V]`, (n, n); without V: the
///     symmetric (n^2, n^2) matrix in the row-major vec(X) basis.
/// Raises:
///     ShapeError, NonFiniteError, NotInGroupError, DegenerateStratumError (X off the principal
///     stratum), InvalidArgumentError (n^4 too large).
#[pyfunction]
#[pyo3(signature = (X, lam, gam, potential, V = None))]
fn amended_hessian<'py>(
    py: Python<'py>,
    X: ArrayIn<'py>,
    lam: ArrayIn<'py>,
    gam: ArrayIn<'py>,
    potential: &Bound<'py, PyPotential>,
    V: Option<ArrayIn<'py>>,
) -> PyResult<Arr2<'py>> {
    let (x, l, g) = (mat("X", &X)?, mat("lam", &lam)?, mat("gam", &gam)?);
    let h = match V {
        Some(v) => {
            let v = mat("V", &v)?;
            with_potential(potential, |p| eq::amended_hessian(p, &x, &l, &g, &v))?
        }
        None => with_potential(potential, |p| eq::amended_hessian_matrix(p, &x, &l, &g))?,
    };
    Ok(py_mat(py, &h))
}

/// The admissible velocity directions :math:`\xi + \eta` for the diagonal shape
/// :math:`A = \operatorname{diag}(a)`: those that satisfy condition (8.6),
/// :math:`[\xi+\eta, B_A(\xi+\eta)] = 0` — the eigen-directions :math:`e_{ij} + (\pm e_{ij})` of
/// :math:`B_A` (8.15) and, for n >= 4, sums over pairwise disjoint planes (8.17)–(8.18).
///
/// Returns:
///     a list of dicts with keys xi, eta ((n, n) skew), planes (list of (i, j), 0-based),
///     signs, eigenvalues (of :math:`B_A`, :math:`(a_i \mp a_j)^2`) and description.
/// Raises:
///     ShapeError, NonFiniteError, InvalidArgumentError (:math:`a_i \le 0`),
///     DegenerateStratumError.
#[pyfunction]
fn equilibrium_directions<'py>(
    py: Python<'py>,
    a: ArrayIn<'py>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let dirs = eq::equilibrium_directions(&vector("a", &a)?).py()?;
    dirs.iter()
        .map(|d| {
            let dict = PyDict::new(py);
            dict.set_item("xi", py_mat(py, &d.xi))?;
            dict.set_item("eta", py_mat(py, &d.eta))?;
            dict.set_item("planes", d.planes.clone())?;
            dict.set_item("signs", d.signs.clone())?;
            dict.set_item("eigenvalues", d.eigenvalues.clone())?;
            dict.set_item("description", d.description.clone())?;
            Ok(dict)
        })
        .collect()
}

/// A skew (n, n) pair from a Python pair.
fn pair(what: &str, v: &Bound<'_, PyAny>) -> PyResult<(Mat, Mat)> {
    let (a, b): (ArrayIn<'_>, ArrayIn<'_>) = v.extract().map_err(|_| {
        to_py(Error::invalid(
            what,
            "expected a pair of skew (n, n) arrays",
        ))
    })?;
    Ok((mat(what, &a)?, mat(what, &b)?))
}

/// Relative equilibria of a pseudo-rigid body with the given potential (001 §8), represented at the
/// diagonal shape :math:`X_0 = \operatorname{diag}(a)` (so body and spatial quantities agree at
/// t = 0). Exactly one way of asking:
///
/// * ``velocities=(xi, eta)``: the shapes a in the box ``bounds`` (Newton from ``starts ** n`` grid
///   points) for which the angular velocities xi, eta (skew (n, n)) give a relative equilibrium;
/// * ``shape=a, plane=(i, j)``: every rotation :math:`\xi = w e_{ij}`, :math:`\eta = m e_{ij}` in
///   that plane (0-based) that makes diag(a) a relative equilibrium, solved exactly;
/// * ``momenta=(lam, gam)``: the critical points of the amended potential (8.8), (8.11) over
///   shapes at the given body momenta.
///
/// Degenerate situations are answered, not hidden: coincident semi-axes (B_A singular) raise
/// DegenerateStratumError; a whole family of solutions raises InvalidArgumentError naming it.
///
/// Solutions with coincident semi-axes (where B_A is singular, so no RelativeEquilibrium exists)
/// found next to principal ones are named in a UserWarning, not returned.
///
/// Returns:
///     a list of RelativeEquilibrium (empty: none in the box).
/// Raises:
///     InvalidArgumentError, ShapeError, NonFiniteError, DegenerateStratumError.
#[pyfunction]
#[pyo3(signature = (potential, *, shape = None, velocities = None, momenta = None, plane = None,
                    bounds = (0.05, 5.0), starts = 6, incompressible = false),
       text_signature = "(potential, *, shape=None, velocities=None, momenta=None, plane=None, \
                         bounds=(0.05, 5.0), starts=6, incompressible=False)")]
#[allow(clippy::too_many_arguments)]
fn relative_equilibria(
    potential: &Bound<'_, PyPotential>,
    shape: Option<ArrayIn<'_>>,
    velocities: Option<Bound<'_, PyAny>>,
    momenta: Option<Bound<'_, PyAny>>,
    plane: Option<Bound<'_, PyAny>>,
    #[pyo3(from_py_with = real_pair)] bounds: (f64, f64),
    #[pyo3(from_py_with = size)] starts: usize,
    incompressible: bool,
) -> PyResult<Vec<RelativeEquilibrium>> {
    if incompressible && shape.is_none() {
        return Err(to_py(Error::invalid(
            "incompressible",
            "for the incompressible body give shape= and plane= (the volume is the shape's); the \
             self-gravitating figures are in lieflow.ellipsoids",
        )));
    }
    let plane = plane
        .map(|p| {
            p.extract::<(usize, usize)>().map_err(|_| {
                to_py(Error::shape(
                    "plane",
                    "a pair (i, j) of axis indices",
                    p.repr().map_or_else(|_| "?".into(), |r| r.to_string()),
                ))
            })
        })
        .transpose()?;
    let search = match (&shape, &velocities, &momenta, plane) {
        (Some(a), None, None, Some(plane)) => {
            let a = vector("shape", a)?;
            eq::Search {
                equilibria: with_potential(potential, |p| {
                    eq::equilibria_for_shape(p, &a, plane, incompressible)
                })?,
                coincident: Vec::new(),
            }
        }
        (None, Some(v), None, None) => {
            let (xi, eta) = pair("velocities", v)?;
            with_potential(potential, |p| {
                eq::search_velocities(p, &xi, &eta, bounds, starts)
            })?
        }
        (None, None, Some(m), None) => {
            let (lam, gam) = pair("momenta", m)?;
            with_potential(potential, |p| {
                eq::search_momenta(p, &lam, &gam, bounds, starts)
            })?
        }
        _ => {
            return Err(to_py(Error::invalid(
                "arguments",
                "give exactly one of: shape= with plane=, velocities=, momenta=",
            )))
        }
    };
    if !search.coincident.is_empty() {
        let py = potential.py();
        let msg = format!(
            "relative_equilibria: left out {} solution(s) with coincident semi-axes (off the \
             principal stratum, where B_A is singular): {:?}",
            search.coincident.len(),
            search.coincident
        );
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &std::ffi::CString::new(msg)?,
            1,
        )?;
    }
    let pot = potential.get().inner.clone();
    Ok(search
        .equilibria
        .into_iter()
        .map(|inner| RelativeEquilibrium {
            inner,
            potential: pot.clone(),
            incompressible,
            figure: None,
        })
        .collect())
}

/// A relative equilibrium :math:`X(t) = \exp(t\xi)\, A_0 \exp(-t\eta)` (001 (8.2)–(8.3)) through
/// the diagonal shape :math:`A_0 = \operatorname{diag}(\mathrm{shape})`, with constant body
/// velocities :math:`\xi, \eta` and momenta :math:`L, \Gamma`.
#[pyclass(module = "lieflow.pseudo_rigid", name = "RelativeEquilibrium", frozen)]
pub struct RelativeEquilibrium {
    inner: eq::RelativeEquilibrium,
    potential: Arc<dyn Potential>,
    /// Whether it is a relative equilibrium of the incompressible body (:math:`\det X` kept).
    incompressible: bool,
    /// For the ellipsoidal figures of `lieflow.ellipsoids`: the fluid, the figure and its
    /// physical quantities (the body is then incompressible).
    figure: Option<(ell::Fluid, ell::Figure, ell::Quantities)>,
}

impl RelativeEquilibrium {
    /// The relative equilibrium of an ellipsoidal figure of equilibrium.
    pub(crate) fn ellipsoid(fluid: &ell::Fluid, fig: ell::Figure) -> PyResult<Self> {
        Ok(RelativeEquilibrium {
            inner: fluid.relative_equilibrium(&fig).py()?,
            potential: fluid.potential(),
            incompressible: true,
            figure: Some((fluid.clone(), fig.clone(), fluid.quantities(&fig).py()?)),
        })
    }

    /// The fluid and figure (ellipsoids only).
    pub(crate) fn figure(&self) -> Option<(&ell::Fluid, &ell::Figure)> {
        self.figure.as_ref().map(|(f, g, _)| (f, g))
    }

    /// A physical quantity of an ellipsoidal figure, or AttributeError naming it.
    fn quantity(&self, name: &str, pick: fn(&ell::Quantities) -> f64) -> PyResult<f64> {
        match &self.figure {
            Some((_, _, q)) => Ok(pick(q)),
            None => Err(pyo3::exceptions::PyAttributeError::new_err(format!(
                "'{name}' is defined for the ellipsoidal figures of lieflow.ellipsoids only"
            ))),
        }
    }
}

#[pymethods]
impl RelativeEquilibrium {
    /// The semi-axes a, of shape (n,); A0 = diag(a).
    #[getter]
    fn shape<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        py_vec(py, &self.inner.a)
    }

    /// The semi-axes a (n,) (the same as `shape`).
    #[getter]
    fn a<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        py_vec(py, &self.inner.a)
    }

    /// The pressure: the multiplier p of :math:`\det X = \det A_0` in
    /// :math:`\partial U_{\xi+\eta}/\partial X = p \operatorname{cof} X` (0 for a
    /// compressible body).
    #[getter]
    fn pressure(&self) -> f64 {
        self.inner.pressure
    }

    /// Whether this is a relative equilibrium of the incompressible body.
    #[getter]
    fn incompressible(&self) -> bool {
        self.incompressible
    }

    /// Ellipsoids: the eccentricity :math:`\sqrt{1 - a_3^2/\max(a_1, a_2)^2}`.
    #[getter]
    fn e(&self) -> PyResult<f64> {
        self.quantity("e", |q| q.e)
    }

    /// Ellipsoids: :math:`a_2/a_1`.
    #[getter]
    fn a2_over_a1(&self) -> PyResult<f64> {
        self.quantity("a2_over_a1", |q| q.a2_over_a1)
    }

    /// Ellipsoids: :math:`a_3/a_1`.
    #[getter]
    fn a3_over_a1(&self) -> PyResult<f64> {
        self.quantity("a3_over_a1", |q| q.a3_over_a1)
    }

    /// Ellipsoids: the figure's angular velocity Omega about x3.
    #[getter]
    fn Omega(&self) -> PyResult<f64> {
        self.quantity("Omega", |q| q.omega3)
    }

    /// Ellipsoids: the vorticity zeta of the internal motion in the figure's frame.
    #[getter]
    fn zeta(&self) -> PyResult<f64> {
        self.quantity("zeta", |q| q.zeta)
    }

    /// Ellipsoids: :math:`f = \zeta/\Omega` (0 Jacobi, :math:`\infty` Dedekind, -2 irrotational).
    #[getter]
    fn f(&self) -> PyResult<f64> {
        self.quantity("f", |q| q.f)
    }

    /// Ellipsoids: :math:`\Omega^2/(\pi G \rho)`, :math:`\rho` the density of the figure.
    #[getter]
    fn Omega2_over_piGrho(&self) -> PyResult<f64> {
        self.quantity("Omega2_over_piGrho", |q| q.omega2_over_pi_g_rho)
    }

    /// Ellipsoids: the angular momentum about :math:`x_3` in units of
    /// :math:`\sqrt{G M^3 \bar a}`, :math:`\bar a = (a_1 a_2 a_3)^{1/3}` (EFE's units).
    #[getter]
    fn angular_momentum(&self) -> PyResult<f64> {
        self.quantity("angular_momentum", |q| q.angular_momentum)
    }

    /// Ellipsoids: the circulation (x3 component of Gamma, 001 (7.3)) in the units of
    /// `angular_momentum`.
    #[getter]
    fn circulation(&self) -> PyResult<f64> {
        self.quantity("circulation", |q| q.circulation)
    }

    /// Ellipsoids: all physical quantities as a dict (the energy in units of
    /// :math:`G M^2/\bar a`).
    #[getter]
    fn quantities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let Some((_, _, q)) = &self.figure else {
            return Err(pyo3::exceptions::PyAttributeError::new_err(
                "'quantities' is defined for the ellipsoidal figures of lieflow.ellipsoids only",
            ));
        };
        let d = PyDict::new(py);
        for (k, v) in [
            ("e", q.e),
            ("a2_over_a1", q.a2_over_a1),
            ("a3_over_a1", q.a3_over_a1),
            ("Omega", q.omega3),
            ("zeta", q.zeta),
            ("f", q.f),
            ("Omega2_over_piGrho", q.omega2_over_pi_g_rho),
            ("angular_momentum", q.angular_momentum),
            ("circulation", q.circulation),
            ("energy", q.energy),
        ] {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// The angular velocity :math:`\xi = \Omega` (skew (n, n)).
    #[getter]
    fn xi<'py>(&self, py: Python<'py>) -> Arr2<'py> {
        py_mat(py, &self.inner.xi)
    }

    /// The velocity of the right action :math:`\eta = \Lambda` (skew (n, n)).
    #[getter]
    fn eta<'py>(&self, py: Python<'py>) -> Arr2<'py> {
        py_mat(py, &self.inner.eta)
    }

    /// The angular momentum :math:`L = P X^\top - X P^\top` at :math:`X_0` (001 (7.3)).
    #[getter]
    fn L<'py>(&self, py: Python<'py>) -> Arr2<'py> {
        py_mat(py, &self.inner.lam)
    }

    /// The circulation :math:`\Gamma = P^\top X - X^\top P` at :math:`X_0` (001 (7.3)).
    #[getter]
    fn Gamma<'py>(&self, py: Python<'py>) -> Arr2<'py> {
        py_mat(py, &self.inner.gam)
    }

    /// The energy :math:`H = \tfrac12 \operatorname{tr}(P^\top P) + U(X)` along the motion.
    #[getter]
    fn energy(&self) -> f64 {
        self.inner.energy
    }

    /// {"force": :math:`\|\nabla_a U_{\xi+\eta}\|`, "commutator": the (8.6) residual, "motion":
    /// :math:`\|\partial U_{\xi+\eta}/\partial X\,(A_0)\|`}.
    #[getter]
    fn residuals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = &self.inner.residuals;
        let d = PyDict::new(py);
        d.set_item("force", r.force)?;
        d.set_item("commutator", r.commutator)?;
        d.set_item("motion", r.motion)?;
        Ok(d)
    }

    /// The motion (X(t), P(t)) at k times: two (k, n, n) arrays.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn motion<'py>(&self, py: Python<'py>, t: ArrayIn<'py>) -> PyResult<(Arr3<'py>, Arr3<'py>)> {
        let times: Vec<f64> = t.as_array().iter().copied().collect();
        let frames = self.inner.motion(&times).py()?;
        let n = self.inner.n();
        let stack = |pick: fn(&(Mat, Mat)) -> &Mat| {
            Array3::from_shape_fn((frames.len(), n, n), |(k, i, j)| pick(&frames[k])[(i, j)])
                .into_pyarray(py)
        };
        Ok((stack(|f| &f.0), stack(|f| &f.1)))
    }

    /// The two stability verdicts (001 §8): `energy_momentum` (the Hessian of the reduced
    /// Hamiltonian on the symplectic leaf: positive definite => nonlinearly stable; indefinite
    /// => inconclusive) and `spectral` (eigenvalues of the linearised reduced equations
    /// (7.24)–(7.28) on the leaf: a positive real part => unstable). For the incompressible
    /// figures of `lieflow.ellipsoids` both are computed for the full constrained dynamics in
    /// the co-moving frame, on the symplectic normal space (valid at coincident axes).
    ///
    /// Raises:
    ///     InvalidArgumentError (not a reduced equilibrium to 1e-8), DegenerateStratumError.
    fn stability(&self) -> PyResult<Stability> {
        if let Some((fluid, fig)) = self.figure() {
            let s = fluid.stability(fig).py()?;
            return Ok(Stability {
                energy_momentum: Verdict::new(s.energy_momentum, ENERGY_MOMENTUM),
                spectral: Verdict::new(s.spectral, SPECTRAL),
            });
        }
        if self.incompressible {
            let n = self.inner.n();
            let body = PseudoRigidBody::incompressible(n, self.potential.clone()).py()?;
            let z = body.state(&self.inner.x0(), &self.inner.p0()).py()?;
            let mut xi = lieflow::lie::so::vee_n(&self.inner.xi).py()?;
            xi.extend(lieflow::lie::so::vee_n(&self.inner.eta).py()?);
            let s = lieflow::analysis::comoving::stability(&body, &z, &xi).py()?;
            return Ok(Stability {
                energy_momentum: Verdict::new(s.energy_momentum, ENERGY_MOMENTUM),
                spectral: Verdict::new(s.spectral, SPECTRAL),
            });
        }
        let n = self.inner.n();
        let body = FullBody::new(n, self.potential.clone()).py()?;
        let s = st::stability(&body, &self.inner.a, &self.inner.xi, &self.inner.eta).py()?;
        Ok(Stability {
            energy_momentum: Verdict::new(s.energy_momentum, ENERGY_MOMENTUM),
            spectral: Verdict::new(s.spectral, SPECTRAL),
        })
    }

    /// The body whose relative equilibrium this is (the incompressible body for the
    /// ellipsoids), as a ``lieflow.System`` over (X, P): for integrating or shooting its orbits.
    #[getter]
    fn body(&self, py: Python<'_>) -> PyResult<Py<PySystem>> {
        let body: Arc<dyn lieflow::integrate::System> = Arc::new(self.core_body()?);
        Py::new(py, PySystem::derived(py, body))
    }

    /// The state (X0, P0) at t = 0, flat (2 n^2,) in the layout of ``body``.
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let z = self
            .core_body()?
            .state(&self.inner.x0(), &self.inner.p0())
            .py()?;
        Ok(py_vec(py, &z))
    }

    /// The oscillatory normal modes of the linearised motion about the equilibrium in the
    /// co-moving frame, on the symplectic normal space (the spectral verdict's eigenvalues
    /// with positive imaginary part), by ascending frequency: the starts of its Lyapunov
    /// families (``lieflow.periodic_orbit.from_mode``).
    ///
    /// Returns:
    ///     A list of ``NormalMode``.
    ///
    /// Raises:
    ///     InvalidArgumentError (not a relative equilibrium to 1e-8).
    fn normal_modes(&self) -> PyResult<Vec<NormalMode>> {
        let body = self.core_body()?;
        let z = body.state(&self.inner.x0(), &self.inner.p0()).py()?;
        let mut xi = lieflow::lie::so::vee_n(&self.inner.xi).py()?;
        xi.extend(lieflow::lie::so::vee_n(&self.inner.eta).py()?);
        let s = lieflow::analysis::comoving::stability(&body, &z, &xi).py()?;
        Ok(s.modes
            .into_iter()
            .enumerate()
            .map(|(index, m)| NormalMode { index, inner: m })
            .collect())
    }

    fn __repr__(&self) -> String {
        if let Some((_, _, q)) = &self.figure {
            return format!(
                "RelativeEquilibrium(a={:?}, e={:.6}, f={:.6}, Omega2_over_piGrho={:.6}, \
                 residual={:.1e})",
                self.inner.a, q.e, q.f, q.omega2_over_pi_g_rho, self.inner.residuals.motion
            );
        }
        format!(
            "RelativeEquilibrium(shape={:?}, energy={:.6e}, residual={:.1e})",
            self.inner.a, self.inner.energy, self.inner.residuals.motion
        )
    }
}

impl RelativeEquilibrium {
    /// The body of this equilibrium: incompressible or free, with its potential.
    fn core_body(&self) -> PyResult<PseudoRigidBody> {
        let n = self.inner.n();
        match self.incompressible {
            true => PseudoRigidBody::incompressible(n, self.potential.clone()),
            false => PseudoRigidBody::new(n, self.potential.clone(), true),
        }
        .py()
    }
}

/// A normal mode of a relative equilibrium (``RelativeEquilibrium.normal_modes``): an eigenvalue
/// :math:`\lambda = \sigma + i\omega` of the co-moving linearisation (:math:`\sigma = 0` for a
/// stable equilibrium) and its eigenvector v in the state's coordinates; the linear motion about
/// the equilibrium in the co-moving frame is :math:`\operatorname{Re}(v e^{\lambda t})`.
#[pyclass(module = "lieflow.pseudo_rigid", name = "NormalMode", frozen)]
pub struct NormalMode {
    index: usize,
    inner: lieflow::analysis::comoving::Mode,
}

#[pymethods]
impl NormalMode {
    /// Its position in ``normal_modes()`` (by ascending frequency).
    #[getter]
    fn index(&self) -> usize {
        self.index
    }

    /// :math:`\omega`, the imaginary part of the eigenvalue: the mode's angular frequency.
    #[getter]
    fn frequency(&self) -> f64 {
        self.inner.eigenvalue.1
    }

    /// :math:`2\pi/\omega`.
    #[getter]
    fn period(&self) -> f64 {
        std::f64::consts::TAU / self.inner.eigenvalue.1
    }

    /// :math:`\lambda = \sigma + i\omega`.
    #[getter]
    fn eigenvalue<'py>(&self, py: Python<'py>) -> Bound<'py, pyo3::types::PyComplex> {
        pyo3::types::PyComplex::from_doubles(py, self.inner.eigenvalue.0, self.inner.eigenvalue.1)
    }

    /// v (complex, (2 n^2,)), unit length in the state scaled by its positions' and momenta's
    /// sizes, turned so that its real part (the displacement at t = 0) is the longest.
    #[getter]
    fn vector<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<Complex64>> {
        let v: Vec<Complex64> = self
            .inner
            .re
            .iter()
            .zip(&self.inner.im)
            .map(|(&a, &b)| Complex64::new(a, b))
            .collect();
        v.into_pyarray(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "NormalMode(index={}, frequency={:.10}, eigenvalue={:.3e}{:+.10}j)",
            self.index, self.inner.eigenvalue.1, self.inner.eigenvalue.0, self.inner.eigenvalue.1
        )
    }
}

/// The two stability verdicts of a relative equilibrium.
#[pyclass(module = "lieflow.pseudo_rigid", name = "Stability", frozen, get_all)]
pub struct Stability {
    /// The energy–momentum verdict (Hessian of H on the symplectic leaf).
    energy_momentum: Verdict,
    /// The spectral verdict (linearisation of the reduced equations on the leaf).
    spectral: Verdict,
}

/// `Verdict.kind` of the energy–momentum verdict.
const ENERGY_MOMENTUM: &str = "energy_momentum";
/// `Verdict.kind` of the spectral verdict.
const SPECTRAL: &str = "spectral";

/// One verdict: the eigenvalues it rests on and whether they prove stability.
#[pyclass(module = "lieflow.pseudo_rigid", name = "Verdict", frozen)]
#[derive(Clone)]
pub struct Verdict {
    eigenvalues: Vec<Complex64>,
    /// "energy_momentum" (eigenvalues of a Hessian, real) or "spectral" (of a linearisation).
    #[pyo3(get)]
    kind: &'static str,
    /// Whether the verdict is "stable".
    #[pyo3(get)]
    stable: bool,
    /// Whether the verdict decides: stable by a definite Hessian, or unstable by a positive
    /// real part; an indefinite Hessian or a purely imaginary spectrum is not conclusive.
    #[pyo3(get)]
    conclusive: bool,
    /// The smallest real part of the eigenvalues (for the energy–momentum Hessian its smallest
    /// eigenvalue: positive where definite).
    #[pyo3(get)]
    min_real_part: f64,
    /// The largest real part of the eigenvalues (for the spectral verdict: positive where
    /// unstable).
    #[pyo3(get)]
    max_real_part: f64,
    /// The tolerance the verdict used.
    #[pyo3(get)]
    tol: f64,
}

impl Verdict {
    fn new(v: st::Verdict, kind: &'static str) -> Self {
        Verdict {
            eigenvalues: v
                .eigenvalues
                .iter()
                .map(|&(re, im)| Complex64::new(re, im))
                .collect(),
            kind,
            stable: v.stable,
            conclusive: v.conclusive,
            min_real_part: v.min_real_part,
            max_real_part: v.max_real_part,
            tol: v.tol,
        }
    }
}

#[pymethods]
impl Verdict {
    /// The eigenvalues (complex array; real for the energy–momentum Hessian).
    #[getter]
    fn eigenvalues<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<Complex64>> {
        PyArray1::from_vec(py, self.eigenvalues.clone())
    }

    /// Python spelling; the number that decides: the Hessian's smallest eigenvalue, or the
    /// spectrum's largest real part.
    fn __repr__(&self) -> String {
        let py_bool = |b: bool| if b { "True" } else { "False" };
        let (name, value) = match self.kind {
            ENERGY_MOMENTUM => ("min_eigenvalue", self.min_real_part),
            _ => ("max_real_part", self.max_real_part),
        };
        format!(
            "Verdict(kind='{}', stable={}, conclusive={}, {name}={value:.3e}, {} eigenvalues)",
            self.kind,
            py_bool(self.stable),
            py_bool(self.conclusive),
            self.eigenvalues.len()
        )
    }
}

#[pymethods]
impl Stability {
    fn __repr__(&self) -> String {
        format!(
            "Stability(energy_momentum={}, spectral={})",
            self.energy_momentum.__repr__(),
            self.spectral.__repr__()
        )
    }
}

/// Adds the functions and classes to `lieflow.pseudo_rigid`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(amended_potential, m)?)?;
    m.add_function(wrap_pyfunction!(augmented_potential, m)?)?;
    m.add_function(wrap_pyfunction!(augmented_gradient, m)?)?;
    m.add_function(wrap_pyfunction!(augmented_hessian, m)?)?;
    m.add_function(wrap_pyfunction!(amended_hessian, m)?)?;
    m.add_function(wrap_pyfunction!(equilibrium_directions, m)?)?;
    m.add_function(wrap_pyfunction!(relative_equilibria, m)?)?;
    m.add_class::<RelativeEquilibrium>()?;
    m.add_class::<NormalMode>()?;
    m.add_class::<Stability>()?;
    m.add_class::<Verdict>()?;
    Ok(())
}
