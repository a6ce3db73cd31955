//! `lieflow.Forced`: a system with an external force or torque, Rayleigh damping or double-bracket
//! dissipation (issue 15), the binding of `lieflow::integrate::forcing::Forced`. A thin subclass
//! of `lieflow.System` over the wrapped system's core; the force callable is called like the
//! user systems' callables (`user.rs`: on the integrating thread, exceptions re-raised naming the
//! step, wrong shapes and NaN typed errors).

use std::sync::Arc;

use lieflow::integrate::forcing::{momentum_block, Dissipation, ForceFn, Forced};
use lieflow::integrate::Block;
use lieflow::Error;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use pyo3::PyClassInitializer;

use super::Callee;
use crate::convert::{read_all, real, ArrayIn};
use crate::errors::{to_py, IntoPy};
use crate::system::{PySystem, Thin};

/// An optional argument that is given and not None.
fn given<'py>(a: &Option<Bound<'py, PyAny>>) -> Option<Bound<'py, PyAny>> {
    a.as_ref().filter(|x| !x.is_none()).cloned()
}

/// Rayleigh coefficients: a number c ≥ 0 (C = c·I) or a symmetric PSD matrix (d, d).
fn damping_values(d: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if let Ok(c) = real(d) {
        return Ok(vec![c]);
    }
    let a = ArrayIn::named("damping", d)?;
    read_all("damping", &a.as_array())
}

/// A system with an external force or torque, Rayleigh damping or double-bracket dissipation.
///
/// The equations are those of `system` plus the non-conservative terms: a force F(t, state) on one
/// momentum block (the body torque on M of RigidBody/HeavyTop, a force matrix on a
/// PseudoRigidBody's P, a force on p of a canonical system, ...), Rayleigh damping
/// :math:`\dot p = -C\, \partial H/\partial p` of a canonical system, or double-bracket
/// dissipation (Bloch, Krishnaprasad, Marsden & Ratiu 1996) of a Lie-Poisson system,
/// :math:`\dot\mu = \operatorname{ad}^*_{\partial H/\partial\mu} \mu + \alpha \operatorname{ad}^*_w \mu`,
/// :math:`w = \operatorname{ad}^*_{\partial H/\partial\mu} \mu` (the rigid body:
/// :math:`\dot M = M \times \Omega + \alpha M \times (M \times \Omega)`), which lowers the energy
/// and keeps every Casimir exactly.
///
/// Methods: for every symmetric second-order method m of `system`, m (the Strang composition
/// :math:`\mathrm{kick}(h/2) \circ m(h) \circ \mathrm{kick}(h/2)`, order 2), m4 and m6 (its Suzuki
/// and Yoshida compositions, orders 4 and 6); the first is the default. The kicks are exact for a force that does not
/// depend on its block, otherwise implicit midpoint steps (symmetric, order 2); double-bracket
/// dissipation is stepped by the Lie midpoint rule on the coadjoint orbit. The free part keeps
/// what its method keeps (the group, the sphere); energy and invariants are those of `system`.
///
/// Args:
///     system: a lieflow system (RigidBody, HeavyTop, PseudoRigidBody, Pendulum, Canonical,
///         Separable, LiePoisson, ...); with an attitude (`attitude0=` of `lf.integrate`) the
///         force sees the state with R.
///     force: callable (t, state) -> array of the block's shape ((3,) for M, (n, n) for P,
///         (d,) for p; the coordinates (n(n-1)/2,) for an so(n)* block), state the flat float64
///         state (state_dim,) in the system's frame (the body frame for a torque); or None.
///     block: the block the force acts on; None for the first of M, P, p, L, mu the system has.
///     depends_on_block: False declares that the force does not depend on its block (one call
///         per kick instead of the implicit iteration; a false claim lowers the order to 1).
///     damping: Rayleigh damping of a canonical system: c >= 0 (:math:`C = c\,\mathrm{Id}`) or a
///         symmetric positive semi-definite matrix (d, d); or None.
///     dissipation: the double-bracket coefficient alpha >= 0 of a Lie-Poisson system without
///         attitude (RigidBody, GeneralizedRigidBody, LiePoisson); or None.
/// Raises:
///     ArgumentTypeError (system not a lieflow system, force not callable),
///     InvalidArgumentError (no term given, unknown or curved block, damping or dissipation the
///     system does not have, negative coefficients, a damping matrix that is not symmetric
///     positive semi-definite), ShapeError (damping of the wrong size).
///
/// A force callable runs in the integrating thread with the GIL (runs are single-threaded; a
/// batch runs member after member); its exceptions are re-raised with a note naming the step, a
/// value of the wrong shape is a ShapeError, NaN or inf a NonFiniteError.
#[pyclass(name = "Forced", module = "lieflow", extends = PySystem, frozen)]
pub struct PyForced {
    block: Option<String>,
}

#[pymethods]
impl PyForced {
    #[new]
    #[pyo3(signature = (system, force=None, block=None, depends_on_block=None, damping=None, dissipation=None))]
    fn new(
        system: Bound<'_, PyAny>,
        force: Option<Bound<'_, PyAny>>,
        block: Option<Bound<'_, PyAny>>,
        depends_on_block: Option<Bound<'_, PyAny>>,
        damping: Option<Bound<'_, PyAny>>,
        dissipation: Option<Bound<'_, PyAny>>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let py = system.py();
        let (force_fn, block_arg, damping_arg, dissipation_arg) = (
            given(&force),
            given(&block),
            given(&damping),
            given(&dissipation),
        );
        let base_obj = system.cast::<PySystem>().map_err(|_| {
            crate::errors::argument_type_error(
                py,
                format!(
                    "argument 'system': expected a lieflow system, got {}",
                    system
                        .get_type()
                        .name()
                        .map_or_else(|_| "?".into(), |n| n.to_string())
                ),
            )
        })?;
        let base = base_obj.get();
        if force_fn.is_none() && damping_arg.is_none() && dissipation_arg.is_none() {
            return Err(to_py(Error::invalid(
                "Forced",
                "give a force, damping or dissipation (none was given)",
            )));
        }
        let depends = match given(&depends_on_block) {
            None => true,
            Some(v) => v.extract::<bool>().map_err(|_| {
                crate::errors::argument_type_error(
                    py,
                    "argument 'depends_on_block': expected a bool".into(),
                )
            })?,
        };
        let space = base.sys.space();
        let mut sys = Forced::new(base.sys.clone());
        let mut chosen = None;
        if let Some(f) = &force_fn {
            let name = match &block_arg {
                Some(b) => b.extract::<String>().map_err(|_| {
                    crate::errors::argument_type_error(
                        py,
                        "argument 'block': expected a str".into(),
                    )
                })?,
                None => momentum_block(base.sys.name(), &space).py()?.to_string(),
            };
            let shape = match space.blocks().iter().find(|(n, _)| *n == name) {
                Some((_, Block::SoDual(n))) => vec![lieflow::lie::so::dim(*n)],
                Some((_, b)) => b.shape(),
                None => vec![],
            };
            let callee = Callee::new("force", f)?;
            let force: ForceFn = Arc::new(move |t: f64, z: &[f64], out: &mut [f64]| {
                callee.call_at(t, z, &shape, out)
            });
            sys = sys.with_force(&name, force, depends).py()?;
            chosen = Some(name);
        }
        if let Some(d) = &damping_arg {
            sys = sys
                .with_dissipation(&Dissipation::Rayleigh(damping_values(d)?))
                .py()?;
        }
        if let Some(a) = &dissipation_arg {
            let alpha = real(a).map_err(|_| {
                crate::errors::argument_type_error(
                    py,
                    "argument 'dissipation': expected a number α ≥ 0".into(),
                )
            })?;
            sys = sys
                .with_dissipation(&Dissipation::DoubleBracket(alpha))
                .py()?;
        }
        let args = (
            system.clone(),
            force,
            block,
            depends_on_block,
            damping,
            dissipation,
        )
            .into_pyobject(py)?;
        let names = &[
            "system",
            "force",
            "block",
            "depends_on_block",
            "damping",
            "dissipation",
        ];
        let this = PyForced { block: chosen };
        Ok(PySystem::init(
            this,
            sys,
            args.cast_into::<PyTuple>()?,
            names,
        ))
    }

    /// The block the force acts on (None without a force).
    #[getter]
    fn block(&self) -> Option<String> {
        self.block.clone()
    }

    /// The terms acting on the free system, in order ("force on M", "Rayleigh damping", ...).
    #[getter]
    fn terms(slf: &Bound<'_, Self>) -> PyResult<Vec<String>> {
        Ok(slf.core::<Forced>()?.terms())
    }

    /// The free system.
    #[getter]
    fn system<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        slf.base().args.bind(slf.py()).get_item(0)
    }
}
