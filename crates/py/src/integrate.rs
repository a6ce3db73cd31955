//! The native half of `lieflow.integrate`: the Lie–Poisson systems of `lieflow::systems` as Python
//! classes and the integration protocol they share (see `python/lieflow/integrate.py`, which does
//! the chunking, progress display and Ctrl-C handling in Python).
//!
//! Every system class derives from [`LiePoissonSystem`], which holds the core system as a
//! `dyn System` and implements the protocol once: `state_dim`, `_normalize_state`, `_run` (the
//! batch in parallel with the GIL released), and the vectorised `energy` and `casimirs`. The
//! subclasses (in [`systems`]) add constructors, the static `methods()` and their own
//! observables; the elliptic functions behind the exact rigid-body solution are in [`elliptic`].

mod elliptic;
mod items;
mod systems;

use std::sync::Arc;

use lieflow::integrate::{integrate, integrate_batch, Method, State, System, Trajectory};
use lieflow::{check, Error};
use numpy::ndarray::{Array2, Array3, ArrayViewD};
use numpy::{IntoPyArray, PyArray2, PyArray3};
use pyo3::prelude::*;

use crate::convert::ArrayIn;
use crate::errors::{shift_time, to_py, IntoPy};
use items::{array, map_items, shape_str, Input, Out};

/// A core system usable from any thread.
pub(crate) type Dyn = Arc<dyn System + Send + Sync>;

/// The names of `methods`.
pub(crate) fn method_names(methods: &[Method]) -> Vec<&'static str> {
    methods.iter().map(|m| m.name()).collect()
}

/// The result of `_run`: states (b, k, d), attitude (b, k, 3, 3) or None, final z (b, d), final
/// attitude (b, 3, 3) or None.
type RunOut<'py> = (
    Out<'py>,
    Option<Out<'py>>,
    Bound<'py, PyArray2<f64>>,
    Option<Bound<'py, PyArray3<f64>>>,
);

/// Base class of the Lie–Poisson systems (RigidBody, GeneralizedRigidBody, HeavyTop,
/// SphericalPendulum): the protocol `lieflow.integrate` drives.
///
/// A state is a flat float64 vector z of length `state_dim` (layout fixed by each system);
/// systems on SO(3) can carry an attitude R (3, 3) along.
#[pyclass(module = "lieflow", subclass, frozen)]
pub struct LiePoissonSystem {
    sys: Dyn,
}

impl LiePoissonSystem {
    pub(crate) fn new(sys: Dyn) -> Self {
        LiePoissonSystem { sys }
    }

    /// Reads (b, d) initial states and an optional (b, 3, 3) attitude.
    fn initial_states(
        &self,
        z0: &ArrayIn<'_>,
        attitude0: Option<&ArrayIn<'_>>,
    ) -> PyResult<Vec<State>> {
        let d = self.sys.dim();
        let z = z0.as_array();
        if z.ndim() != 2 || z.shape()[1] != d {
            return Err(to_py(Error::shape(
                "z0",
                format!("(b, {d})"),
                shape_str(z.shape()),
            )));
        }
        let b = z.shape()[0];
        let mut states: Vec<State> = z
            .outer_iter()
            .map(|row| State::new(row.iter().copied().collect()))
            .collect();
        if let Some(a) = attitude0 {
            let a = a.as_array();
            if a.shape() != [b, 3, 3] {
                return Err(to_py(Error::shape(
                    "attitude",
                    format!("({b}, 3, 3)"),
                    shape_str(a.shape()),
                )));
            }
            for (s, r) in states.iter_mut().zip(a.outer_iter()) {
                let mut m = [0.0; 9];
                for (o, v) in m.iter_mut().zip(r.iter()) {
                    *o = *v;
                }
                s.attitude = Some(m);
            }
        }
        Ok(states)
    }
}

/// Parses flat initial states: (d,) or a batch (b, d), finite. Returns ((b, d), batched).
pub(crate) fn normalize_flat<'py>(
    py: Python<'py>,
    d: usize,
    v: &ArrayViewD<'_, f64>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, bool)> {
    let bad = || {
        to_py(Error::shape(
            "state0",
            format!("({d},) or a batch (b, {d})"),
            shape_str(v.shape()),
        ))
    };
    let batched = match v.ndim() {
        1 => false,
        2 => true,
        _ => return Err(bad()),
    };
    if v.shape()[v.ndim() - 1] != d {
        return Err(bad());
    }
    let data: Vec<f64> = v.iter().copied().collect();
    check::finite_slice("state0", &data).py()?;
    let b = data.len() / d;
    let z = Array2::from_shape_vec((b, d), data).map_err(|_| bad())?;
    Ok((z.into_pyarray(py), batched))
}

/// The Python exception for an error of a run over `states0`; an invalid member of a batch is
/// named ("batch member i: …").
fn in_batch(py: Python<'_>, sys: &dyn System, states0: &[State], e: Error) -> PyErr {
    let member = match states0 {
        [_, _, ..] => states0
            .iter()
            .position(|s| sys.check_state(s).as_ref().err() == Some(&e)),
        _ => None,
    };
    let err = to_py(e);
    match member {
        Some(i) => PyErr::from_type(
            err.get_type(py),
            format!("batch member {i}: {}", err.value(py)),
        ),
        None => err,
    }
}

/// Row-major (b, …) data from the trajectories' pieces.
fn stack<'a>(pieces: impl Iterator<Item = &'a [f64]>, capacity: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(capacity);
    for p in pieces {
        out.extend_from_slice(p);
    }
    out
}

#[pymethods]
impl LiePoissonSystem {
    /// Length d of the flat state vector z.
    #[getter]
    fn state_dim(&self) -> usize {
        self.sys.dim()
    }

    /// Whether the system can carry an attitude R in SO(3) along (`integrate(..., attitude=R0)`).
    #[getter]
    fn has_attitude(&self) -> bool {
        self.sys.has_attitude()
    }

    /// Parses an initial state: (d,) or a batch (b, d) of flat states.
    ///
    /// Returns:
    ///     (z0, batched): z0 a (b, d) float64 array (b = 1 when not batched).
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn _normalize_state<'py>(
        &self,
        py: Python<'py>,
        state0: ArrayIn<'py>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, bool)> {
        normalize_flat(py, self.sys.dim(), &state0.as_array())
    }

    /// Integrates every row of `z0` by `steps` steps of size `dt` with `method`, saving every
    /// `save_every`-th state (and the initial one). The rows run in parallel (rayon) with the GIL
    /// released. Use `lieflow.integrate`, which calls this in chunks.
    ///
    /// Args:
    ///     z0: (b, d) initial states; attitude0: (b, 3, 3) rotations or None; dt > 0;
    ///     steps >= 1; save_every >= 1; method: a name from `methods()`; t0 (keyword): the
    ///     time of z0, added to the time a LeftDomainError names.
    /// Returns:
    ///     (states (b, k, d), attitude (b, k, 3, 3) or None, z_final (b, d),
    ///     attitude_final (b, 3, 3) or None), k = steps // save_every + 1.
    /// Raises:
    ///     InvalidArgumentError (dt, steps, save_every, unknown method, constraints),
    ///     UnsupportedMethodError, ShapeError, NonFiniteError, NotInGroupError (attitude),
    ///     ConvergenceError (implicit methods), LeftDomainError (the state became non-finite).
    #[pyo3(signature = (z0, attitude0, dt, steps, save_every, method, *, t0 = 0.0))]
    #[allow(clippy::too_many_arguments)]
    fn _run<'py>(
        &self,
        py: Python<'py>,
        z0: ArrayIn<'py>,
        attitude0: Option<ArrayIn<'py>>,
        dt: f64,
        steps: usize,
        save_every: usize,
        method: &str,
        t0: f64,
    ) -> PyResult<RunOut<'py>> {
        let method = Method::from_name(method).py()?;
        let states0 = self.initial_states(&z0, attitude0.as_ref())?;
        let sys = &*self.sys;
        let trajs: Vec<Trajectory> = py
            .detach(|| {
                if let [s] = states0.as_slice() {
                    integrate(sys, method, s, dt, steps, save_every).map(|t| vec![t])
                } else {
                    integrate_batch(sys, method, &states0, dt, steps, save_every, None)
                }
            })
            .map_err(|e| in_batch(py, sys, &states0, shift_time(e, t0)))?;
        let (b, d, k) = (states0.len(), sys.dim(), steps / save_every + 1);
        let states = stack(trajs.iter().map(|t| t.states.as_slice()), b * k * d);
        let z_final = stack(trajs.iter().map(|t| t.final_state.z.as_slice()), b * d);
        let states = array(py, &[b, k, d], states)?;
        let z_final = Array2::from_shape_vec((b, d), z_final)
            .map_err(|_| to_py(Error::shape("z_final", format!("({b}, {d})"), "")))?
            .into_pyarray(py);
        if attitude0.is_none() {
            return Ok((states, None, z_final, None));
        }
        let att = stack(
            trajs
                .iter()
                .map(|t| t.attitude.as_deref().unwrap_or_default()),
            b * k * 9,
        );
        let att_final = stack(
            trajs
                .iter()
                .map(|t| t.final_state.attitude.as_ref().map_or(&[][..], |r| &r[..])),
            b * 9,
        );
        let att = array(py, &[b, k, 3, 3], att)?;
        let att_final = Array3::from_shape_vec((b, 3, 3), att_final)
            .map_err(|_| to_py(Error::shape("attitude_final", format!("({b}, 3, 3)"), "")))?
            .into_pyarray(py);
        Ok((states, Some(att), z_final, Some(att_final)))
    }

    /// The energy (Hamiltonian) of states, vectorised: (..., d) -> (...).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn energy<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d = [self.sys.dim()];
        let inputs = [Input {
            what: "states",
            array: &states,
            item: &d,
        }];
        map_items(py, &inputs, &[], |z, out| {
            out[0] = self.sys.energy(z[0])?;
            Ok(())
        })
    }

    /// The Casimir functions (exact invariants of the reduced dynamics) of states, vectorised:
    /// (..., d) -> (..., c). See each system for the list.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn casimirs<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d = self.sys.dim();
        let c = self.sys.casimirs(&vec![0.0; d]).py()?.len();
        let inputs = [Input {
            what: "states",
            array: &states,
            item: &[d],
        }];
        map_items(py, &inputs, &[c], |z, out| {
            out.copy_from_slice(&self.sys.casimirs(z[0])?);
            Ok(())
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "<lieflow {} (state_dim={})>",
            self.sys.name(),
            self.sys.dim()
        )
    }
}

/// Registers the system classes and the `elliptic` submodule in the top-level native module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<LiePoissonSystem>()?;
    systems::register(m)?;
    let e = PyModule::new(m.py(), "elliptic")?;
    elliptic::register(&e)?;
    m.add_submodule(&e)
}
