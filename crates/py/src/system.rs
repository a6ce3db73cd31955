//! `lieflow.System`: the one base class of every system class. It implements the whole protocol
//! `lieflow.integrate` drives, once, from the core system's state space and catalog: `methods()`,
//! named fields, `energy`, `invariants`, `_normalize_state`, `_start`/`_run` (native runs with
//! the GIL released, a batch in parallel), `__reduce__` (pickling) and `__repr__`. A system
//! class is a thin subclass: its constructor and its own observables. It keeps nothing of its
//! own (a unit struct) unless it must keep data that is not the core system; its methods reach
//! the typed core system through the base ([`Thin::core`], a downcast of the one
//! `Arc<dyn System>`), and its constructor is [`PySystem::subclass`] (or [`PySystem::init`]).

use std::sync::{Arc, Mutex};

use lieflow::integrate::{Block, Catalog, Resolved, Space, System};
use lieflow::{check, Error};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::exceptions::{PyRuntimeError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyCFunction, PyDict, PyList, PyTuple, PyType};
use pyo3::{PyClass, PyClassInitializer, PyTypeInfo};

use crate::convert::{read_all, shape_str, ArrayIn};
use crate::convert::{size_opt, vector};
use crate::errors::{checked, to_py, IntoPy};
use crate::integrate::{args, Integration, RunOut};
use crate::items::{map_items, Input};

/// Base class of every lieflow system (RigidBody, HeavyTop, PseudoRigidBody, …): the
/// integration protocol over a native system.
///
/// A state is a flat float64 vector of length `state_dim` cut into named blocks (`fields`);
/// systems on SO(3) can carry an attitude R (3, 3) along (`has_attitude`). Systems pickle (by
/// their constructor arguments), so they can be sent to other processes.
#[pyclass(module = "lieflow", name = "System", subclass, frozen)]
pub struct PySystem {
    pub(crate) sys: Arc<dyn System>,
    lifted: Option<Arc<dyn System>>,
    pub(crate) args: Py<PyTuple>,
    names: &'static [&'static str],
    /// The methods resolved so far, by (lifted, name; None: the default): a system object is
    /// frozen, so a method is looked up once for all its runs.
    resolved: Mutex<Vec<MethodOf>>,
}

/// A resolved method of a system object: (lifted, name; None: the default), the method.
type MethodOf = (bool, Option<String>, Arc<Resolved>);

impl PySystem {
    /// The core system, or with `attitude` the one carrying its attitude (None where it cannot).
    fn carrying(&self, attitude: bool) -> Option<&Arc<dyn System>> {
        match attitude {
            true => self.lifted.as_ref(),
            false => Some(&self.sys),
        }
    }

    /// The base part of a system object over `sys`, built from the constructor arguments `args`
    /// (named `names`, used by `__repr__`; `__reduce__` passes them to the class again).
    pub(crate) fn new<S: lieflow::integrate::Catalog>(
        sys: S,
        args: Bound<'_, PyTuple>,
        names: &'static [&'static str],
    ) -> Self {
        PySystem {
            lifted: System::lift(&sys),
            sys: Arc::new(sys),
            args: args.unbind(),
            names,
            resolved: Mutex::new(Vec::new()),
        }
    }

    /// A bare system object over a core system made by another (the tangent lift of
    /// `lieflow.integrate(..., sensitivity=True)`): no constructor arguments, no attitude.
    pub(crate) fn derived(py: Python<'_>, sys: Arc<dyn System>) -> Self {
        PySystem {
            lifted: None,
            sys,
            args: PyTuple::empty(py).unbind(),
            names: &[],
            resolved: Mutex::new(Vec::new()),
        }
    }

    /// The initializer of a system object of the subclass `C` over the core system `sys` (base
    /// part as [`PySystem::new`]), for a class that keeps nothing of its own.
    pub(crate) fn subclass<C, S>(
        sys: S,
        args: Bound<'_, PyTuple>,
        names: &'static [&'static str],
    ) -> PyClassInitializer<C>
    where
        C: PyClass<BaseType = PySystem> + Default,
        S: Catalog,
    {
        Self::init(C::default(), sys, args, names)
    }

    /// The initializer of a system object of the subclass `C` over `sys` whose subclass part
    /// `this` keeps data that is not the core system (the Python object it was built from).
    pub(crate) fn init<C, S>(
        this: C,
        sys: S,
        args: Bound<'_, PyTuple>,
        names: &'static [&'static str],
    ) -> PyClassInitializer<C>
    where
        C: PyClass<BaseType = PySystem>,
        S: Catalog,
    {
        PyClassInitializer::from(PySystem::new(sys, args, names)).add_subclass(this)
    }

    /// The core system as its concrete type `S`; an internal-error `RuntimeError` naming both
    /// types if it is another (a subclass asking for the wrong type: a bug of the bindings).
    pub(crate) fn core<S: 'static>(&self) -> PyResult<&S> {
        self.sys.as_any().downcast_ref::<S>().ok_or_else(|| {
            PyRuntimeError::new_err(format!(
                "lieflow internal error: the core system {} is not a {}",
                self.sys.name(),
                std::any::type_name::<S>()
            ))
        })
    }

    /// The method `method` (None: the default) of the core system `sys` (the lifted one when
    /// `lifted`), resolved once per system object.
    fn resolve(
        &self,
        sys: &Arc<dyn System>,
        lifted: bool,
        method: Option<&str>,
    ) -> lieflow::Result<Arc<Resolved>> {
        let mut cache = self.resolved.lock().unwrap_or_else(|p| p.into_inner());
        let hit = cache
            .iter()
            .find(|(l, m, _)| *l == lifted && m.as_deref() == method);
        if let Some((_, _, r)) = hit {
            return Ok(r.clone());
        }
        let r = match method {
            Some(m) => sys.resolve(m)?,
            None => sys.resolve_default()?,
        };
        cache.push((lifted, method.map(str::to_string), r.clone()));
        Ok(r)
    }

    /// The core system of a run: the lifted one when an attitude is given.
    fn runner(&self, attitude: bool) -> PyResult<&Arc<dyn System>> {
        if !attitude {
            return Ok(&self.sys);
        }
        self.lifted.as_ref().ok_or_else(|| {
            to_py(Error::invalid(
                "attitude",
                format!("{} carries no attitude", self.sys.name()),
            ))
        })
    }

    /// Reads an initial state (see `_normalize_state`): the rows (b·d values) and whether it is
    /// a batch.
    pub(crate) fn normalize(&self, state0: &Bound<'_, PyAny>) -> PyResult<(Vec<f64>, bool)> {
        let space = self.sys.space();
        let d = space.dim();
        let blocks = space.blocks().len();
        let sequence = state0.is_instance_of::<PyTuple>() || state0.is_instance_of::<PyList>();
        if sequence && blocks > 1 && state0.len()? == blocks {
            // One array per block, unless these are flat states (a batch of length `blocks`).
            let first = ArrayIn::named("state0", &state0.get_item(0)?)?;
            let shape = space.blocks()[0].1.shape();
            if first.as_array().shape().ends_with(&shape) {
                return from_blocks(&space, state0);
            }
        }
        let a = ArrayIn::named("state0", state0)?;
        let v = a.as_array();
        if !(v.ndim() == 1 || v.ndim() == 2) || v.shape()[v.ndim() - 1] != d {
            return Err(to_py(Error::shape(
                "state0",
                format!("({d},) or a batch (b, {d})"),
                shape_str(v.shape()),
            )));
        }
        let data = read_all("state0", &v)?;
        finite_members("state0", &data, &[d], v.ndim() == 2)?;
        Ok((data, v.ndim() == 2))
    }

    /// Applies `f(state) -> values` to every state (..., d), checking finiteness; output
    /// (..., *out_item).
    pub(crate) fn map_states<'py>(
        &self,
        py: Python<'py>,
        states: &ArrayIn<'py>,
        out_item: &[usize],
        f: impl Fn(&[f64], &mut [f64]) -> lieflow::Result<()>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let d = [self.sys.space().dim()];
        let inputs = [Input::new("states", states, &d)];
        // A callable's exception (recorded on this thread) comes before the NaN it caused.
        checked(|| {
            Ok(map_items(py, &inputs, out_item, |z, out| {
                check::finite_slice("states", z[0])?;
                f(z[0], out)
            }))
        })?
    }
}

/// A system object seen from its subclass `C`: the base part and the typed core system, e.g.
/// `slf.core::<core::Pendulum>()?` in a method taking `slf: &Bound<'_, Self>`.
pub(crate) trait Thin {
    /// The base part (`lieflow.System`) of the object.
    fn base(&self) -> &PySystem;

    /// The core system as its concrete type `S` ([`PySystem::core`]).
    fn core<S: 'static>(&self) -> PyResult<&S> {
        self.base().core()
    }
}

impl<C: PyClass<BaseType = PySystem>> Thin for Bound<'_, C> {
    fn base(&self) -> &PySystem {
        self.as_super().get()
    }
}

/// Checks that the states (or state blocks of shape `item`) in `data` are finite; a NaN or inf is
/// named by its batch member (when `batched`) and its entry in the item.
fn finite_members(what: &str, data: &[f64], item: &[usize], batched: bool) -> PyResult<()> {
    check::finite_items(what, data, item)
        .map_err(|(k, e)| to_py(if batched { e.in_member(k) } else { e }))
}

/// Reads one block of a tuple-form state: an array whose trailing shape is the block's view
/// shape; returns the rows of block values and the leading shape.
fn block_rows(name: &str, block: Block, a: &ArrayIn<'_>) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let v = a.as_array();
    let item = block.shape();
    let s = v.shape();
    let k = item.len();
    if s.len() < k || s.len() > k + 1 || s[s.len() - k..] != item[..] {
        return Err(to_py(Error::shape(
            name,
            format!("{} or a batch (b, ...)", shape_str(&item)),
            shape_str(s),
        )));
    }
    let data = read_all(name, &v)?;
    finite_members(name, &data, &item, s.len() > k)?;
    let rows = match block {
        Block::SoDual(n) => {
            let mut out = Vec::new();
            for m in data.chunks_exact(n * n) {
                let m = lieflow::Mat::from_fn(n, n, |i, j| m[i * n + j]);
                out.extend(lieflow::lie::so::vee_n(&m).py()?);
            }
            out
        }
        _ => data,
    };
    Ok((rows, s[..s.len() - k].to_vec()))
}

/// A (b, d) array from rows, or a ShapeError.
fn rows_array<'py>(
    py: Python<'py>,
    rows: Vec<f64>,
    d: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let b = rows.len().checked_div(d).unwrap_or(0);
    Array2::from_shape_vec((b, d), rows)
        .map(|a| a.into_pyarray(py))
        .map_err(|e| to_py(Error::shape("state0", format!("(b, {d})"), e.to_string())))
}

/// Parses a state in tuple form: one array per block (a batch along a leading axis).
fn from_blocks(space: &Space, parts: &Bound<'_, PyAny>) -> PyResult<(Vec<f64>, bool)> {
    let mut columns = Vec::new();
    let mut lead: Option<Vec<usize>> = None;
    for (k, (name, block, _)) in space.ranges().enumerate() {
        let a = ArrayIn::named(name, &parts.get_item(k)?)?;
        let (rows, l) = block_rows(name, block, &a)?;
        match &lead {
            Some(first) if *first != l => {
                return Err(to_py(Error::shape(
                    name,
                    format!("the leading shape of the other parts {}", shape_str(first)),
                    shape_str(&l),
                )))
            }
            _ => lead = Some(l),
        }
        columns.push((rows, block.len()));
    }
    let lead = lead.unwrap_or_default();
    let b = lead.iter().product::<usize>();
    let d = space.dim();
    let mut z = check::zeros("state0", &[b, d]).py()?;
    let mut at = 0;
    for i in 0..b {
        for (rows, len) in &columns {
            z[at..at + len].copy_from_slice(&rows[i * len..(i + 1) * len]);
            at += len;
        }
    }
    Ok((z, !lead.is_empty()))
}

#[pymethods]
impl PySystem {
    /// The names of the integration methods (of the system object, or on a class those of its
    /// kind); the first is the default.
    #[classattr]
    fn methods() -> Methods {
        Methods
    }

    /// Length d of the flat state vector.
    #[getter]
    fn state_dim(&self) -> usize {
        self.sys.space().dim()
    }

    /// The names of the state's blocks, in order (views of a trajectory carry these names).
    #[getter]
    fn fields(&self) -> Vec<&'static str> {
        self.sys.space().blocks().iter().map(|(n, _)| *n).collect()
    }

    /// Whether the system can carry an attitude R in SO(3) along (`integrate(..., attitude=R0)`).
    #[getter]
    fn has_attitude(&self) -> bool {
        self.lifted.is_some()
    }

    /// The names of the system's parameters θ, in order: the columns of
    /// `Trajectory.parameter_jacobian` (e.g. ``("I1", "I2", "I3")`` for a `RigidBody`); empty
    /// where the system has none it differentiates along.
    #[getter]
    fn parameters(&self) -> Vec<&'static str> {
        self.sys.parameters()
    }

    /// The methods whose Jacobians `lieflow.integrate(..., sensitivity=True)` computes for this
    /// system (those of its catalog that a tangent lift lists; empty where the system has none
    /// yet); with `attitude=True` those of a run that carries the attitude.
    #[pyo3(signature = (attitude = false))]
    fn sensitivity_methods(&self, attitude: bool) -> Vec<&'static str> {
        self.carrying(attitude)
            .map(|s| s.tangent_methods())
            .unwrap_or_default()
    }

    /// The tangent lift of the system (with `attitude`: of the system carrying its attitude) for
    /// `lieflow.integrate(..., sensitivity=True)` (issue 26): (a system object over the lift
    /// that runs `method`, its layout), or None where the system has none; without a method the
    /// system's lift of its non-Runge–Kutta methods (the same directions and Jacobians' shape).
    #[pyo3(signature = (attitude = false, method = None))]
    fn _tangent(
        &self,
        py: Python<'_>,
        attitude: bool,
        method: Option<&str>,
    ) -> PyResult<Option<(Py<PySystem>, Py<crate::sensitivity::PyTangent>)>> {
        let lift = self.carrying(attitude).and_then(|s| match method {
            Some(m) => s.tangent_for(m),
            None => s.tangent(),
        });
        let Some(t) = lift else {
            return Ok(None);
        };
        let sys: Arc<dyn System> = t.clone();
        Ok(Some((
            Py::new(py, PySystem::derived(py, sys))?,
            Py::new(py, crate::sensitivity::PyTangent { inner: t })?,
        )))
    }

    /// Parses an initial state: a flat state (d,) or a batch (b, d), or a tuple with one array
    /// per field (e.g. (M, Gamma), (X, P)), each with an optional leading batch axis.
    ///
    /// Returns:
    ///     (z0, batched): z0 a (b, d) float64 array (b = 1 when not batched).
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn _normalize_state<'py>(
        &self,
        py: Python<'py>,
        state0: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, bool)> {
        let (rows, batched) = self.normalize(state0)?;
        Ok((rows_array(py, rows, self.sys.space().dim())?, batched))
    }

    /// Starts a native run of the initial state(s) `state0` (the chunked driver of
    /// `lieflow.integrate` resumes it with `_chunk`). Every argument is read and checked here,
    /// once, in the order and the words of `lieflow.integrate`.
    ///
    /// Args:
    ///     state0: as `_normalize_state` reads it; attitude0: None, one (n, n) group element
    ///     (a rotation (3, 3) for the SO(3) bodies; shared by a batch) or one per member
    ///     (b, n, n); dt > 0; method: a name from `methods()`, or
    ///     None for the first (the system's default); save_every >= 1; t0 (keyword): the time
    ///     of state0; threads (keyword): None for all cores, or the number of threads; steps
    ///     (keyword): the steps the caller will take in all, to refuse a trajectory that cannot
    ///     be kept before any; first_member (keyword): the ensemble index of the first member
    ///     when state0 is a part of an ensemble (`lieflow.ensemble`): errors then name members
    ///     by it ("batch member 7"); t_eval (keyword): the output times (1-D, float64, finite),
    ///     within [t0, t0 + steps·dt]; single (keyword): refuse a batch (a run with events).
    /// Raises:
    ///     TypeError, InvalidArgumentError, UnsupportedMethodError, ShapeError, NonFiniteError,
    ///     NotInGroupError (state constraints and attitude).
    #[pyo3(signature = (state0, attitude0, dt, method, save_every, t0 = None, threads = None, steps = None, first_member = None, t_eval = None, single = false))]
    #[allow(clippy::too_many_arguments)]
    fn _start<'py>(
        &self,
        state0: &Bound<'py, PyAny>,
        attitude0: &Bound<'py, PyAny>,
        dt: &Bound<'py, PyAny>,
        method: &Bound<'py, PyAny>,
        save_every: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = args::given)] t0: Option<Bound<'py, PyAny>>,
        #[pyo3(from_py_with = args::given)] threads: Option<Bound<'py, PyAny>>,
        #[pyo3(from_py_with = args::given)] steps: Option<Bound<'py, PyAny>>,
        #[pyo3(from_py_with = size_opt)] first_member: Option<usize>,
        t_eval: Option<ArrayIn<'py>>,
        single: bool,
    ) -> PyResult<Integration> {
        let steps = args::count_opt("steps", steps.as_ref())?;
        let save_every = args::count("save_every", save_every)?;
        let dt = args::step(dt)?;
        let t0 = t0.as_ref().map_or(Ok(0.0), |t| args::time("t0", t))?;
        let method = args::method(method)?;
        let times = t_eval.map(|t| vector("t_eval", &t)).transpose()?;
        if times.is_some() && save_every != 1 {
            return Err(to_py(Error::invalid(
                "save_every",
                "t_eval gives the output times; leave save_every at 1",
            )));
        }
        let (rows, batched) = self.normalize(state0)?;
        let d = self.sys.space().dim();
        let b = rows.len().checked_div(d).unwrap_or(0);
        if single && batched {
            return Err(to_py(Error::invalid(
                "events",
                format!(
                    "events are located in a single run, got a batch of {b} initial states; \
                     integrate the members one by one"
                ),
            )));
        }
        let with_attitude = !attitude0.is_none();
        let sys = self.runner(with_attitude)?.clone();
        // The size n of the attitude: the lifted system's last block (n, n).
        let n = match with_attitude {
            true => sys
                .space()
                .blocks()
                .last()
                .map_or(0, |(_, blk)| blk.shape()[0]),
            false => 0,
        };
        let attitude = match with_attitude {
            true => Some(args::attitude(attitude0, b, batched, n)?),
            false => None,
        };
        let threads = args::count_opt("threads", threads.as_ref())?;
        let resolved = self.resolve(&sys, with_attitude, method.as_deref());
        // The members' full states one after the other (each with its attitude).
        let states = match &attitude {
            None => rows,
            Some(a) => {
                let mut states = Vec::with_capacity(b * (d + n * n));
                for (z, r) in rows.chunks_exact(d.max(1)).zip(a.chunks_exact(n * n)) {
                    states.extend_from_slice(z);
                    states.extend_from_slice(r);
                }
                states
            }
        };
        Integration::start(
            sys,
            states,
            batched,
            n,
            dt,
            resolved,
            method.as_deref(),
            save_every,
            t0,
            threads.map(|n| usize::try_from(n).unwrap_or(usize::MAX)),
            steps,
            first_member,
            times,
        )
    }

    /// Integrates `state0` by `steps` steps in one native run (arguments as `_start`).
    ///
    /// Returns:
    ///     (states (b, k, d), attitude (b, k, 3, 3) or None, z_final (b, d), attitude_final
    ///     (b, 3, 3) or None), k = steps // save_every + 1.
    /// Raises:
    ///     as `_start`, and ConvergenceError, LeftDomainError (naming the time) during the run.
    #[pyo3(signature = (state0, attitude0, dt, steps, save_every, method, *, t0 = None, threads = None, first_member = None))]
    #[allow(clippy::too_many_arguments)]
    fn _run<'py>(
        &self,
        py: Python<'py>,
        state0: &Bound<'py, PyAny>,
        attitude0: &Bound<'py, PyAny>,
        dt: &Bound<'py, PyAny>,
        steps: &Bound<'py, PyAny>,
        save_every: &Bound<'py, PyAny>,
        method: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = args::given)] t0: Option<Bound<'py, PyAny>>,
        #[pyo3(from_py_with = args::given)] threads: Option<Bound<'py, PyAny>>,
        #[pyo3(from_py_with = size_opt)] first_member: Option<usize>,
    ) -> PyResult<RunOut<'py>> {
        let mut run = self._start(
            state0,
            attitude0,
            dt,
            method,
            save_every,
            t0,
            threads,
            Some(steps.clone()),
            first_member,
            None,
            false,
        )?;
        let n = args::count("steps", steps)?;
        run.run_all(py, n)
    }

    /// The energy (Hamiltonian) of states, vectorised: (..., d) -> (...).
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn energy<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.map_states(py, &states, &[], |z, out| {
            out[0] = lieflow::integrate::energy_checked(&*self.sys, z)?;
            Ok(())
        })
    }

    /// The invariants the system's geometric methods keep exactly (Casimirs, momentum maps) of
    /// states, vectorised: (..., d) -> (..., c). See each system for the list.
    ///
    /// Raises:
    ///     ShapeError, NonFiniteError.
    fn invariants<'py>(
        &self,
        py: Python<'py>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.map_states(py, &states, &[self.sys.invariant_count()], |z, out| {
            out.copy_from_slice(&lieflow::integrate::invariants_checked(&*self.sys, z)?);
            Ok(())
        })
    }

    /// A short label for each value `invariants` returns, in its order (``"|M|²"``,
    /// ``"M·Γ"``, ``"J(rotation about z)"``, …): what plots and tables name them by.
    #[getter]
    fn invariant_names(&self) -> Vec<String> {
        self.sys.invariant_names()
    }

    /// The same as `invariants` (the Casimirs of the Lie–Poisson systems).
    fn casimirs<'py>(&self, py: Python<'py>, states: ArrayIn<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.invariants(py, states)
    }

    /// Named views of states (..., d): {field: (..., *shape)} (so(n)* blocks as skew matrices).
    pub(crate) fn _fields<'py>(
        &self,
        py: Python<'py>,
        states: ArrayIn<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        let d = [self.sys.space().dim()];
        for (name, block, range) in self.sys.space().ranges() {
            let inputs = [Input::new("states", &states, &d)];
            let v = map_items(py, &inputs, &block.shape(), |z, out| {
                block.view(&z[0][range.clone()], out);
                Ok(())
            })?;
            dict.set_item(name, v)?;
        }
        Ok(dict)
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyType>, Bound<'py, PyTuple>)> {
        Ok((slf.get_type(), slf.get().args.bind(slf.py()).clone()))
    }

    fn __repr__(slf: &Bound<'_, Self>) -> PyResult<String> {
        let this = slf.get();
        let args = this.args.bind(slf.py());
        let mut parts = Vec::new();
        for (name, value) in this.names.iter().zip(args.iter()) {
            parts.push(format!("{name}={}", value.repr()?));
        }
        Ok(format!("{}({})", slf.get_type().name()?, parts.join(", ")))
    }
}

/// The descriptor `methods` of every system class: on a system object its own catalog
/// (`PseudoRigidBody(3, incompressible=True)` has other methods than the free body, `Forced` those
/// of the system it wraps), on a class the catalog of its kind, known without an instance
/// (`_kind_methods`, set by [`add_system`]).
#[pyclass(module = "lieflow", name = "_Methods", frozen)]
pub(crate) struct Methods;

#[pymethods]
impl Methods {
    fn __get__<'py>(
        &self,
        obj: Option<Bound<'py, PyAny>>,
        owner: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyCFunction>> {
        // On the base class the list is unknown: the function raises when called (so that
        // `getattr(lieflow.System, "methods")` and autodoc still work).
        let (py, names): (_, Option<Vec<String>>) = match (obj.filter(|o| !o.is_none()), owner) {
            (Some(obj), _) => {
                let sys = &obj.cast::<PySystem>()?.get().sys;
                let names = sys.methods().iter().map(|(n, _)| n.to_string()).collect();
                (obj.py(), Some(names))
            }
            (None, Some(cls)) => {
                let names = cls.getattr("_kind_methods").ok();
                (cls.py(), names.map(|n| n.extract()).transpose()?)
            }
            (None, None) => return Err(PyTypeError::new_err("methods: no class given")),
        };
        PyCFunction::new_closure(
            py,
            Some(c"methods"),
            Some(c"The names of the integration methods; the first is the default."),
            move |args: &Bound<'_, PyTuple>, kwargs: Option<&Bound<'_, PyDict>>| {
                if !args.is_empty() || kwargs.is_some_and(|k| !k.is_empty()) {
                    return Err(PyTypeError::new_err("methods() takes no arguments"));
                }
                names.clone().ok_or_else(|| {
                    PyTypeError::new_err(
                        "lieflow.System is the base class: call methods() on a system class or \
                         object",
                    )
                })
            },
        )
    }
}

/// Adds the system class `C`, the binding of the core system `S`, to the module `m`, with the
/// names of the methods of `S`'s kind for `C.methods()` on the class.
pub(crate) fn add_system<C: PyClass + PyTypeInfo, S: Catalog>(
    m: &Bound<'_, PyModule>,
) -> PyResult<()> {
    add_with_methods::<C>(m, lieflow::integrate::kind_methods::<S>())
}

/// Adds the system class `C` to `m` with `names` as the methods of its kind.
pub(crate) fn add_with_methods<C: PyClass + PyTypeInfo>(
    m: &Bound<'_, PyModule>,
    names: Vec<&'static str>,
) -> PyResult<()> {
    m.add_class::<C>()?;
    m.py().get_type::<C>().setattr("_kind_methods", names)
}
