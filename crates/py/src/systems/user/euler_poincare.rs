//! `EulerPoincare`: a system of a reduced Lagrangian ℓ(ξ) or ℓ(ξ, a) given by Python callables or
//! an inertia matrix (the binding of `lieflow::systems::user::euler_poincare`): its Lie–Poisson
//! form is the system integrated, and the class adds the Legendre transform and the diamond map.
#![allow(non_snake_case)]

use std::sync::Arc;

use lieflow::systems::user::{
    Action, EulerPoincare as CoreEp, HessianFn, Lagrangian, LagrangianFn, LagrangianGradientFn,
};
use lieflow::Error;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::convert::{read_all, shape_str, ArrayIn};
use crate::errors::{argument_type_error, to_py, IntoPy};
use crate::items::{map_items, Input};
use crate::system::PySystem;

use super::lie_poisson::{algebra, side};
use super::{optional, Any, Callee};

/// Mechanics from a reduced Lagrangian (000 §4): the Euler–Poincaré equations of
/// :math:`l(\xi)` on a Lie algebra :math:`\mathfrak{g}`, or of :math:`l(\xi, a)` with an advected
/// parameter :math:`a` (a symmetry-breaking parameter such as the heavy top's vertical
/// :math:`\Gamma`), integrated in their Lie–Poisson form.
///
/// The state is the momentum :math:`\mu = \partial l/\partial\xi` (d,), followed by a (m,) with a
/// parameter. The equations (left, body frame):
/// :math:`\dot\mu = \operatorname{ad}^*_\xi \mu + \partial l/\partial a \diamond a`,
/// :math:`\dot a = -\xi \cdot a`, with the diamond
/// :math:`\langle b \diamond a, \eta \rangle = -\langle b, \eta \cdot a \rangle`; right (spatial
/// frame, `side="right"`):
/// :math:`\dot\mu = -\operatorname{ad}^*_\xi \mu - \partial l/\partial a \diamond a`,
/// :math:`\dot a = \xi \cdot a` (derived by the mirror :math:`g \mapsto g^{-1}`; the notes' right
/// version keeps the sign of the parameter term, which the mirror test contradicts).
/// :math:`\xi` is found from :math:`\mu` by inverting the Legendre transform (Newton's method to
/// round-off for a non-quadratic :math:`l`; a singular :math:`\partial^2 l/\partial\xi^2` is an
/// InvalidArgumentError naming the point), and the energy is
/// :math:`E = \langle \mu, \xi \rangle - l`. The algebras, conventions and Casimirs
/// (`invariants`) are `LiePoisson`'s. With `integrate(..., attitude=g0)` the configuration g (a
/// rotation (3, 3), an (n, n) element of SO(n), or a homogeneous (4, 4) element of SE(3)) is
/// carried along, :math:`\dot g = g\xi` (left) or :math:`\dot g = \xi g` (right), and, without a
/// parameter, the Noether momentum joins the invariants (`noether`, 000 Theorems 4.3-4.4).
/// Methods: variational (default; the discrete Euler–Poincaré method: the Lie group
/// variational integrator of l, symplectic and symmetric, order 2, keeping the coadjoint orbit
/// and the Noether momentum to round-off), variational4, variational6 (its compositions of
/// orders 4 and 6), rkmk4, midpoint, midpoint4 (the Lie midpoint rule and its composition),
/// rk4.
///
/// Args:
///     algebra: "so3", "se3", ("so", n) or structure constants (d, d, d), as `LiePoisson`.
///     lagrangian: l(xi) -> float, or l(xi, a) -> float with an `action`; or None with `inertia`.
///     inertia: a symmetric positive definite (d, d) matrix :math:`\mathbb{I}` for
///         :math:`l = \tfrac12 \langle \xi, \mathbb{I}\xi \rangle`: the native
///         path (no Python call per step; no parameter).
///     gradient: :math:`\partial l/\partial\xi` as a callable xi -> (d,), or with a parameter
///         (xi, a) -> (dl/dxi (d,), dl/da (m,)); None: central differences of l.
///     hessian: :math:`\partial^2 l/\partial\xi^2` as a callable (xi[, a]) -> (d, d); None:
///         central differences of the gradient.
///     side: "left" (default) or "right".
///     action: None (no parameter), "vector" (the defining representation of so3 or ("so", n)
///         on :math:`\mathbb{R}^n`: :math:`\xi \cdot a = \hat\xi a`, m = n; on se3 its rotation
///         part on :math:`\mathbb{R}^3`: a direction
///         fixed in space, such as gravity for a vehicle in a fluid), or a callable
///         (xi, a) -> xi.a, linear in both, with `parameter_dim` m.
///     parameter_dim: m for a callable action.
/// Raises:
///     ArgumentTypeError, InvalidArgumentError (a bad inertia; an action that is not a
///     representation: the Jacobi identity of the semidirect product fails), ShapeError.
#[pyclass(name = "EulerPoincare", module = "lieflow", extends = PySystem, frozen)]
pub struct PyEulerPoincare {
    ep: CoreEp,
}

/// Reads a pair (dl/dxi, dl/da) returned by a gradient callable.
fn pair(g: &Callee, args: &[&[f64]], dxi: &mut [f64], da: &mut [f64]) -> lieflow::Result<()> {
    g.call_pair(args, dxi, da)
}

#[pymethods]
impl PyEulerPoincare {
    #[new]
    #[pyo3(signature = (algebra, lagrangian=None, inertia=None, gradient=None, hessian=None, side=None, action=None, parameter_dim=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        algebra: Any<'_>,
        lagrangian: Option<Any<'_>>,
        inertia: Option<Any<'_>>,
        gradient: Option<Any<'_>>,
        hessian: Option<Any<'_>>,
        side: Option<Any<'_>>,
        action: Option<Any<'_>>,
        parameter_dim: Option<Any<'_>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let py = algebra.py();
        let alg = self::algebra(&algebra)?;
        let side_of = self::side(side.as_ref())?;
        let dim = alg.dim().py()?;
        let parameter = match optional(action.as_ref()) {
            None => None,
            Some(a) => Some(self::action(
                a,
                dim,
                optional(parameter_dim.as_ref()),
                &alg,
            )?),
        };
        let with_a = parameter.is_some();
        let lag = match (optional(lagrangian.as_ref()), optional(inertia.as_ref())) {
            (Some(_), Some(_)) => {
                return Err(to_py(Error::invalid(
                    "inertia",
                    "give the Lagrangian either as a callable (lagrangian) or as an inertia \
                     matrix (inertia), not both",
                )))
            }
            (None, None) => {
                return Err(argument_type_error(
                    py,
                    "EulerPoincare() needs the Lagrangian: a callable `lagrangian` or an \
                     `inertia` matrix"
                        .into(),
                ))
            }
            (None, Some(i)) => {
                for (name, v) in [("gradient", &gradient), ("hessian", &hessian)] {
                    if optional(v.as_ref()).is_some() {
                        return Err(to_py(Error::invalid(
                            name,
                            "a quadratic Lagrangian (an inertia matrix) has its own derivatives; \
                             pass None",
                        )));
                    }
                }
                let a = ArrayIn::named("inertia", i)?;
                if a.as_array().ndim() != 2 {
                    return Err(to_py(Error::shape(
                        "inertia",
                        "a symmetric positive definite (d, d) matrix",
                        shape_str(a.as_array().shape()),
                    )));
                }
                Lagrangian::Quadratic(read_all("inertia", &a.as_array())?)
            }
            (Some(l), None) => {
                let l = Callee::new("lagrangian", l)?;
                let value: LagrangianFn = Arc::new(move |xi: &[f64], a: &[f64]| match with_a {
                    true => l.scalar(&[xi, a]),
                    false => l.scalar(&[xi]),
                });
                let gradient = optional(gradient.as_ref())
                    .map(|g| Callee::new("gradient", g))
                    .transpose()?
                    .map(|g| -> LagrangianGradientFn {
                        Arc::new(
                            move |xi: &[f64], a: &[f64], dxi: &mut [f64], da: &mut [f64]| {
                                match with_a {
                                    true => pair(&g, &[xi, a], dxi, da),
                                    false => g.call(&[xi], &[xi.len()], dxi),
                                }
                            },
                        )
                    });
                let hessian = optional(hessian.as_ref())
                    .map(|h| Callee::new("hessian", h))
                    .transpose()?
                    .map(|h| -> HessianFn {
                        Arc::new(move |xi: &[f64], a: &[f64], out: &mut [f64]| {
                            let d = xi.len();
                            match with_a {
                                true => h.call(&[xi, a], &[d, d], out),
                                false => h.call(&[xi], &[d, d], out),
                            }
                        })
                    });
                Lagrangian::Function {
                    value,
                    gradient,
                    hessian,
                }
            }
        };
        let ep = CoreEp::new(alg, lag, side_of, parameter).py()?;
        let sys = ep.clone();
        let side = side_of.name();
        let args = (
            algebra,
            lagrangian,
            inertia,
            gradient,
            hessian,
            side,
            action,
            parameter_dim,
        )
            .into_pyobject(py)?;
        let names = &[
            "algebra",
            "lagrangian",
            "inertia",
            "gradient",
            "hessian",
            "side",
            "action",
            "parameter_dim",
        ];
        Ok(PySystem::init(PyEulerPoincare { ep }, sys, args, names))
    }

    /// Names of the observables that take (states, attitude); `Trajectory` passes its attitude.
    #[classattr]
    fn _attitude_observables() -> (&'static str,) {
        ("noether",)
    }

    /// :math:`\dim\mathfrak{g}` (the length of mu).
    #[getter]
    fn dim(&self) -> usize {
        self.ep.dims().0
    }

    /// Whether the Lagrangian is the native quadratic form (given as an inertia matrix).
    #[getter]
    fn is_quadratic(&self) -> bool {
        self.ep.system().is_quadratic()
    }

    /// The dimension m of the parameter a (0 without one).
    #[getter]
    fn parameter_dim(&self) -> usize {
        self.ep.dims().1
    }

    /// The invariance the Lagrangian has: "left" or "right".
    #[getter]
    fn side(&self) -> &'static str {
        self.ep.system().side().name()
    }

    /// The state (mu[, a]) of the velocity xi (d,) and parameter a (m,):
    /// :math:`\mu = \partial l/\partial\xi\,(\xi, a)`.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, the callables' errors.
    #[pyo3(signature = (xi, a=None))]
    fn state<'py>(
        &self,
        py: Python<'py>,
        xi: Any<'py>,
        a: Option<Any<'py>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (d, m) = self.ep.dims();
        let xi = vector("xi", &xi, d)?;
        let a = self.parameter(a.as_ref(), m)?;
        let mut mu = vec![0.0; d];
        self.ep.legendre().momentum(&xi, &a, &mut mu).py()?;
        mu.extend_from_slice(&a);
        Ok(PyArray1::from_vec(py, mu))
    }

    /// The velocity xi (d,) of a state (mu[, a]): the inverse Legendre transform.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError, InvalidArgumentError (a singular
    ///     :math:`\partial^2 l/\partial\xi^2` on the way), ConvergenceError, the callables' errors.
    fn velocity<'py>(
        &self,
        py: Python<'py>,
        state: Any<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (d, m) = self.ep.dims();
        let z = vector("state", &state, d + m)?;
        let mut xi = vec![0.0; d];
        self.ep
            .legendre()
            .velocity(&z[..d], &z[d..], &mut xi)
            .py()?;
        Ok(PyArray1::from_vec(py, xi))
    }

    /// The Noether momentum of states (..., d[+m]) at group elements g (..., n, n) (the motion's
    /// configuration, body to space; n = 3 for so3, n for ("so", n), 4 for se3 as homogeneous
    /// matrices): :math:`\operatorname{Ad}^*_{g^{-1}} \mu` for a left-invariant Lagrangian
    /// (000 Theorem 4.3: the spatial momentum :math:`R M` of the rigid body),
    /// :math:`\operatorname{Ad}^*_g \mu` for a right-invariant one (Theorem 4.4);
    /// conserved along a motion. With a parameter only the components that fix the reference
    /// parameter are (Theorem 4.11: for the heavy top the vertical one, (R M)[2]); the whole
    /// vector (..., d) is returned. Leading axes broadcast.
    ///
    /// Raises:
    ///     InvalidArgumentError (structure constants: no group), NotInGroupError, ShapeError,
    ///     NonFiniteError.
    fn noether<'py>(
        slf: &Bound<'py, Self>,
        states: ArrayIn<'py>,
        g: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let ep = &slf.get().ep;
        let (d, m) = ep.dims();
        let n = ep.group_size().ok_or_else(|| {
            to_py(Error::invalid(
                "g",
                "an algebra given by structure constants has no matrix group here: no Noether \
                 momentum",
            ))
        })?;
        map_items(
            slf.py(),
            &[
                Input::new("states", &states, &[d + m]),
                Input::new("g", &g, &[n, n]),
            ],
            &[d],
            |x, out| {
                lieflow::check::finite_slice("states", x[0])?;
                ep.noether(&x[0][..d], x[1], out)
            },
        )
    }

    /// The diamond :math:`b \diamond a \in \mathfrak{g}^*` (d,) of :math:`b \in V` (m,: a
    /// derivative :math:`\partial l/\partial a`) and :math:`a \in V^*` (m,):
    /// :math:`\langle b \diamond a, \eta \rangle = -\langle b, \eta \cdot a \rangle` for every
    /// :math:`\eta \in \mathfrak{g}`.
    fn diamond<'py>(
        &self,
        py: Python<'py>,
        b: Any<'py>,
        a: Any<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (d, m) = self.ep.dims();
        if m == 0 {
            return Err(to_py(Error::invalid(
                "a",
                "the system has no parameter (no action): no diamond map",
            )));
        }
        let (b, a) = (vector("b", &b, m)?, vector("a", &a, m)?);
        let mut out = vec![0.0; d];
        self.ep.diamond(&b, &a, &mut out);
        Ok(PyArray1::from_vec(py, out))
    }
}

impl PyEulerPoincare {
    fn parameter(&self, a: Option<&Any<'_>>, m: usize) -> PyResult<Vec<f64>> {
        match (optional(a), m) {
            (None, 0) => Ok(Vec::new()),
            (None, m) => Err(to_py(Error::invalid(
                "a",
                format!("the system has a parameter: pass a ({m},)"),
            ))),
            (Some(_), 0) => Err(to_py(Error::invalid(
                "a",
                "the system has no parameter (no action): pass a=None",
            ))),
            (Some(a), m) => vector("a", a, m),
        }
    }
}

/// A float vector of length n named `what`, finite.
fn vector(what: &str, v: &Any<'_>, n: usize) -> PyResult<Vec<f64>> {
    let x = crate::convert::vector(what, &ArrayIn::named(what, v)?)?;
    if x.len() != n {
        return Err(to_py(Error::shape(
            what,
            format!("({n},)"),
            format!("({},)", x.len()),
        )));
    }
    lieflow::check::finite_slice(what, &x).py()?;
    Ok(x)
}

/// The `action` argument with its parameter dimension.
fn action(
    a: &Any<'_>,
    d: usize,
    parameter_dim: Option<&Any<'_>>,
    alg: &lieflow::systems::Algebra,
) -> PyResult<(Action, usize)> {
    if let Ok(s) = a.cast::<PyString>() {
        let name = s.extract::<String>()?;
        if name != "vector" {
            return Err(to_py(Error::invalid(
                "action",
                format!(
                    "unknown action {name:?}; expected \"vector\" or a callable (xi, a) -> xi.a"
                ),
            )));
        }
        // The core refuses the vector action where it has no dimension.
        return Ok((Action::Vector, Action::vector_dim(alg).unwrap_or(0)));
    }
    let f = Callee::new("action", a)?;
    let m = match parameter_dim {
        Some(m) => m.extract::<usize>().map_err(|_| {
            argument_type_error(
                a.py(),
                "argument 'parameter_dim': expected a positive int".into(),
            )
        })?,
        None => {
            return Err(to_py(Error::invalid(
                "parameter_dim",
                "a callable action needs the dimension m of the parameter (parameter_dim=m)",
            )))
        }
    };
    if m == 0 {
        return Err(to_py(Error::invalid(
            "parameter_dim",
            "expected m >= 1, got 0",
        )));
    }
    lieflow::check::array_size("action", &[d, m, m]).py()?;
    // The matrices A_i of a -> e_i.a, column by column (the action is linear in both).
    let mut mats = vec![0.0; d * m * m];
    let mut col = vec![0.0; m];
    for i in 0..d {
        let mut e = vec![0.0; d];
        e[i] = 1.0;
        for q in 0..m {
            let mut f_q = vec![0.0; m];
            f_q[q] = 1.0;
            f.call(&[&e, &f_q], &[m], &mut col).py()?;
            for p in 0..m {
                mats[i * m * m + p * m + q] = col[p];
            }
        }
    }
    Ok((Action::Matrices(mats), m))
}
