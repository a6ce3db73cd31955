//! `lieflow.Integration`: a native run in progress (a batch of `lieflow::integrate::Run`s). The
//! chunked driver `lieflow.integrate` (Python: progress, Ctrl-C) resumes the same native
//! steppers chunk after chunk, so a run validates once, keeps its clock, and never converts its
//! state back and forth.

pub(crate) mod args;
mod drive;
mod output;
mod start;

use std::sync::{Arc, Mutex};

use lieflow::integrate::{Batch, Event, Events, System, Until};
use lieflow::{check, Error};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;

use crate::convert::{named, real, real_opt, vector, ArrayIn, Real};
use crate::errors::{raised, to_py, IntoPy};
use crate::items::Out;

/// The result of `System._run`: states (b, k, d), attitude (b, k, n, n) or None, final states
/// (b, d), final attitude (b, n, n) or None.
pub(crate) type RunOut<'py> = (Out<'py>, Option<Out<'py>>, Out<'py>, Option<Out<'py>>);

/// Current states (b, d) and attitudes (b, n, n) or None.
type States<'py> = (Out<'py>, Option<Out<'py>>);

/// One call of a run as `lieflow.integrate` assembles it: the times (k,), states (b, k, d) and
/// attitudes (b, k, n, n) or None of its samples, the current states (b, d) and attitudes, the
/// steps done, the end time of an ended run, the time of the current state (with output times
/// snapped to, and without), and the events found (None without events).
type Chunk<'py> = (
    Bound<'py, PyArray1<f64>>,
    Out<'py>,
    Option<Out<'py>>,
    Out<'py>,
    Option<Out<'py>>,
    u64,
    Option<f64>,
    (f64, f64),
    Option<Vec<Found<'py>>>,
);

/// `_whole`'s arrays of a trajectory: times, states, attitudes, final states and attitudes, the
/// time of the final state, initial states and attitudes.
type Whole<'py> = (
    Bound<'py, PyArray1<f64>>,
    Out<'py>,
    Option<Out<'py>>,
    Out<'py>,
    Option<Out<'py>>,
    f64,
    Out<'py>,
    Option<Out<'py>>,
);

/// A located event as Python sees it: (index of the event function, t, state (d,), attitude
/// (n, n) or None, absolute step).
type Found<'py> = (
    usize,
    f64,
    Bound<'py, PyArray1<f64>>,
    Option<Bound<'py, PyArray2<f64>>>,
    u64,
);

/// A native integration in progress (made by `System._start`); `advance(steps)` continues it.
///
/// Output control (issue 15): `save_at(t_eval)` saves at given times (shortened steps between
/// grid times), `set_events(...)` locates the zeros of Python event functions (a single run),
/// `finish(t)` takes the last shortened step to an end time; after an error `take_partial()` and
/// `checked_state()` give what was computed before it.
#[pyclass(module = "lieflow", name = "Integration")]
pub struct Integration {
    /// The method's name.
    #[pyo3(get)]
    method: String,
    sys: Arc<dyn System>,
    /// The system calls Python callables (`Problem::calls_out`): its runs stay on the calling
    /// thread, which holds the GIL, and an exception ends the run that raised it.
    calls_out: bool,
    /// One run per member, in SIMD lanes where the method has them for the system.
    runs: Mutex<Batch>,
    /// The worker threads (None: rayon's global pool), for the core's `with_threads`.
    threads: Option<usize>,
    /// Length of a state without the attitude.
    d: usize,
    /// The size n of the attitude (an n×n matrix after the state), 0 without one.
    attitude: usize,
    /// Whether the initial state was a batch (b, d) (else one state (d,), b = 1).
    #[pyo3(get)]
    batched: bool,
    #[pyo3(get)]
    save_every: u64,
    #[pyo3(get)]
    t0: f64,
    #[pyo3(get)]
    dt: f64,
    /// Steps done (the same for every member).
    done: u64,
    /// The output times, if the run saves at given times (`save_at`).
    at: Option<Vec<f64>>,
    /// The samples handed out so far (the initial states included).
    saved: usize,
    /// The initial states (b·full values), the first samples of a run that saves every
    /// `save_every`-th state.
    initial: Vec<f64>,
    /// The event functions (a single run only).
    events: Option<Mutex<Events<'static>>>,
    /// The states (full, flat) saved by the call that failed, before its error (one run only).
    partial: Option<Vec<f64>>,
    /// The index of the first member in the ensemble the batch is a part of (`lieflow.ensemble`
    /// runs one batch per task), if given: errors name members by their ensemble index.
    first_member: Option<usize>,
}

#[pymethods]
impl Integration {
    /// Advances every member by `steps` steps (in parallel, GIL released).
    ///
    /// Returns:
    ///     (states (b, k, d), attitude (b, k, n, n) or None): the states saved in these steps
    ///     (every `save_every`-th step counted from the start of the run, or those at the
    ///     output times of `save_at`; with events, the terminal event's state last).
    /// Raises:
    ///     InvalidArgumentError (steps < 1, an ended run), ConvergenceError, LeftDomainError
    ///     (naming the absolute step and time), NonFiniteError (an event function's value); the
    ///     exception of a Python callable the system or an event function called.
    fn advance<'py>(
        &mut self,
        py: Python<'py>,
        steps: &Bound<'py, PyAny>,
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        let steps = args::count("steps", steps)?;
        let (outs, k) = self.drive(py, Until::Steps(steps))?;
        self.saved_arrays(py, &outs, k)
    }

    /// One call of `lieflow.integrate`'s loop: `steps` more steps, or with `t` to the time t
    /// (as `finish`). Returns the samples of the call with their times (the initial states
    /// first in the first call of a run that saves every `save_every`-th state), the current
    /// states, the steps done, the end time of an ended run, the time of the current state
    /// (snapped to the last output time within round-off, and not), and the events found.
    ///
    /// Raises as `advance`.
    #[pyo3(signature = (steps, t = None))]
    fn _chunk<'py>(
        &mut self,
        py: Python<'py>,
        steps: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = real_opt)] t: Option<f64>,
    ) -> PyResult<Chunk<'py>> {
        let until = match t {
            Some(t) => Until::Time(t),
            None => Until::Steps(args::count("steps", steps)?),
        };
        let before = self.ended();
        let (outs, mut k) = self.drive(py, until)?;
        let ended = self.ended();
        // A terminal event's state, saved last (not with output times).
        let last = ended.filter(|_| before.is_none() && self.at.is_none());
        if let (0, Some(times)) = (self.members(), &self.at) {
            // An empty batch saves nothing natively: its samples are the output times passed.
            let now = self.t0 + self.done as f64 * self.dt;
            let tol = 8.0 * f64::EPSILON * now.abs().max(self.t0.abs());
            let passed = match until {
                Until::Time(_) => times.len(),
                Until::Steps(_) => times.iter().take_while(|&&t| t <= now + tol).count(),
            };
            k = passed.saturating_sub(self.saved);
        }
        let current = self.state(py)?;
        self.chunk_of(py, &outs, k, last, ended, current, true)
    }

    /// A plain run (no output times, no events, nothing done yet) in one call, as
    /// `lieflow.integrate` takes a run that fits in one: `steps` steps, returned as the
    /// trajectory's arrays (t (k,), states (b, k, d), attitudes (b, k, n, n) or None, final
    /// states (b, d), final attitudes or None, t_final, initial states (b, d), initial attitudes
    /// or None), without the axis b for a single initial state.
    ///
    /// Raises as `advance`; InvalidArgumentError for a run with output times or events or
    /// already advanced.
    fn _whole<'py>(&mut self, py: Python<'py>, steps: &Bound<'py, PyAny>) -> PyResult<Whole<'py>> {
        let steps = args::count("steps", steps)?;
        if self.at.is_some() || self.events.is_some() || self.done > 0 {
            return Err(to_py(Error::invalid(
                "steps",
                "_whole takes a plain run from its start",
            )));
        }
        let (outs, k) = self.drive(py, Until::Steps(steps))?;
        let b = self.members();
        let lead: &[usize] = if self.batched { &[b] } else { &[] };
        let (states, att, times) = self.samples(py, &outs, k, None, lead)?;
        let (z, za) = self.arrays(py, self.current(py)?, lead)?;
        let (z0, za0) = self.arrays(py, self.initial.clone(), lead)?;
        let t = PyArray1::from_vec(py, times);
        Ok((t, states, att, z, za, self.t_final(None, true), z0, za0))
    }

    /// After a failed call of a single run: `_chunk`'s tuple of the states that call saved
    /// before its error (with the initial states when they are still due), ending at the last
    /// checked state (`checked_state`, `steps_done`); None otherwise (then forgotten).
    fn _partial<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Chunk<'py>>> {
        if self.batched {
            return Ok(None);
        }
        let Some(data) = self.partial.take() else {
            return Ok(None);
        };
        let k = data.len() / self.full().max(1);
        let current = self.checked_state(py)?;
        self.chunk_of(py, &[data], k, None, None, current, false)
            .map(Some)
    }

    /// `_chunk`'s tuple of a run before its first call completed: its initial samples and
    /// states, at step 0 and time t₀ — also when a call did complete but its result never
    /// reached the caller (Ctrl-C raised as the call returned), so the initial sample is
    /// always there.
    fn _head<'py>(&mut self, py: Python<'py>) -> PyResult<Chunk<'py>> {
        let current = self.initial_states(py)?;
        let saved = std::mem::replace(&mut self.saved, 0);
        let c = self.chunk_of(py, &[], 0, None, None, current, false);
        self.saved = saved;
        let mut c = c?;
        (c.5, c.7) = (0, (self.t0, self.t0));
        Ok(c)
    }

    /// The initial states (b, d) and attitudes (b, n, n) or None.
    fn _initial<'py>(&self, py: Python<'py>) -> PyResult<States<'py>> {
        self.initial_states(py)
    }

    /// The number of members b.
    #[getter]
    fn members(&self) -> usize {
        self.initial.len() / self.full().max(1)
    }

    /// The sample times t₀ + j·save_every·dt, j = 0 … steps // save_every, of a run of `steps`
    /// steps that saves every `save_every`-th state.
    fn _sample_times<'py>(
        &self,
        py: Python<'py>,
        steps: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let k = args::count("steps", steps)? / self.save_every + 1;
        let mut t = check::zeros("steps", &[usize::try_from(k).unwrap_or(usize::MAX)]).py()?;
        let every = self.save_every as f64 * self.dt;
        for (j, t) in t.iter_mut().enumerate() {
            *t = self.t0 + j as f64 * every;
        }
        Ok(PyArray1::from_vec(py, t))
    }

    /// Advances every member to the time `t`: steps of size dt to the last grid time ≤ t, then,
    /// when t lies between grid times, one shortened step to t, which ends the run there.
    ///
    /// Returns and raises as `advance` (InvalidArgumentError for a time before the current one).
    fn finish<'py>(
        &mut self,
        py: Python<'py>,
        #[pyo3(from_py_with = real)] t: f64,
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        let (outs, k) = self.drive(py, Until::Time(t))?;
        self.saved_arrays(py, &outs, k)
    }

    /// Saves the states at the times `t_eval` (1-D, strictly increasing, none before the
    /// current time) instead of every `save_every`-th state; a time between grid times is
    /// reached by one shortened step of the method from the grid state before it.
    ///
    /// Raises:
    ///     ShapeError (not 1-D, empty), NonFiniteError, InvalidArgumentError (unsorted, before
    ///     the current time, too many to keep).
    fn save_at(&mut self, t_eval: ArrayIn<'_>) -> PyResult<()> {
        let times = vector("t_eval", &t_eval)?;
        self.save_times(times)
    }

    /// Locates the zeros of the event functions `functions[i](t, state)` (state (d,) as in the
    /// trajectory, without the attitude) after every step, in `directions[i]` (> 0 rising,
    /// < 0 falling, 0 both); the run ends at the `terminal[i]`-th occurrence (0: never).
    /// `tol` ≥ 0: an absolute tolerance in time added to round-off. A single run only.
    ///
    /// Raises:
    ///     InvalidArgumentError (a batch, lengths that differ, a NaN or infinite direction, a
    ///     bad tol).
    fn set_events(
        &mut self,
        py: Python<'_>,
        functions: Vec<Py<PyAny>>,
        directions: ArrayIn<'_>,
        terminal: Vec<u64>,
        #[pyo3(from_py_with = real)] tol: f64,
    ) -> PyResult<()> {
        let directions = vector("directions", &directions)?;
        if let Some(i) = functions.iter().position(|f| !f.bind(py).is_callable()) {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "invalid functions: expected callables g(t, state), functions[{i}] is a {}",
                functions[i]
                    .bind(py)
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".to_string(), |n| n.to_string())
            )));
        }
        let b = self.runs.get_mut().unwrap_or_else(|p| p.into_inner()).len();
        if b != 1 {
            return Err(to_py(Error::invalid(
                "events",
                format!(
                    "events are located in a single run, got a batch of {b}; integrate the \
                     members one by one"
                ),
            )));
        }
        if directions.len() != functions.len() || terminal.len() != functions.len() {
            return Err(to_py(Error::invalid(
                "events",
                "one direction and one terminal count per event function",
            )));
        }
        let d = self.d;
        let list = functions
            .into_iter()
            .zip(directions.into_iter().zip(terminal))
            .enumerate()
            .map(|(i, (f, (direction, terminal)))| {
                Event::new(move |t: f64, z: &[f64]| {
                    Python::attach(|py| {
                        let state = PyArray1::from_slice(py, &z[..d]);
                        let value = f.bind(py).call1((t, state)).and_then(|v| {
                            let what = format!("the value returned by events[{i}]");
                            named(&what, v.extract::<Real>()).map(|r| r.0)
                        });
                        value.map_err(|e| raised(format!("event function {i}"), e))
                    })
                })
                .direction(direction)
                .terminal(terminal)
            })
            .collect();
        self.events = Some(Mutex::new(Events::new(list, tol).py()?));
        Ok(())
    }

    /// The events located since the last call (and forgets them), in time order: a list of
    /// (index of the event function, t, state (d,), attitude (n, n) or None, absolute step).
    fn events_found<'py>(&mut self, py: Python<'py>) -> PyResult<Vec<Found<'py>>> {
        let Some(events) = &mut self.events else {
            return Ok(Vec::new());
        };
        let events = events.get_mut().unwrap_or_else(|p| p.into_inner());
        let d = self.d;
        let attitude = self.attitude;
        std::mem::take(&mut events.hits)
            .into_iter()
            .map(|h| {
                let state = PyArray1::from_slice(py, &h.state[..d]);
                let att = if attitude > 0 {
                    Some(PyArray1::from_slice(py, &h.state[d..]).reshape([attitude, attitude])?)
                } else {
                    None
                };
                Ok((h.event, h.t, state, att, h.step))
            })
            .collect()
    }

    /// The terminal event function that ended the run, if one did.
    #[getter]
    fn stopped_by(&mut self) -> Option<usize> {
        let events = self.events.as_mut()?;
        events
            .get_mut()
            .unwrap_or_else(|p| p.into_inner())
            .stopped_by()
    }

    /// The time at which the run ended between grid times (a terminal event or `finish`), or
    /// None.
    #[getter]
    fn ended(&self) -> Option<f64> {
        let batch = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        batch.runs().first().and_then(|r| r.ended())
    }

    /// Grid steps done (after an error: those that passed the checks).
    #[getter]
    fn steps_done(&self) -> u64 {
        let batch = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        batch.runs().first().map_or(0, |r| r.steps_done())
    }

    /// The number of grid steps from the start of the run to the last grid time ≤ t.
    ///
    /// Raises:
    ///     InvalidArgumentError (t before t0, non-finite, beyond 2⁶³ steps).
    fn steps_to(&self, #[pyo3(from_py_with = real)] t: f64) -> PyResult<u64> {
        let batch = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        match batch.runs().first() {
            Some(r) => r.grid_steps(t).py(),
            None => Ok(0),
        }
    }

    /// After a failed `advance`/`finish` of a single run: the states (1, k, d) and attitudes
    /// (1, k, n, n) or None saved by that call before its error (then forgotten); None otherwise.
    fn take_partial<'py>(
        &mut self,
        py: Python<'py>,
    ) -> PyResult<Option<(Out<'py>, Option<Out<'py>>)>> {
        let Some(data) = self.partial.take() else {
            return Ok(None);
        };
        let k = data.len() / self.full().max(1);
        self.arrays(py, data, &[1, k]).map(Some)
    }

    /// The last states that passed the checks (b, d) and attitudes (b, n, n) or None: the
    /// current states, and after an error the states before the failing step (at
    /// `steps_done`), where the stepper's own `state()` may already be outside the domain.
    fn checked_state<'py>(&self, py: Python<'py>) -> PyResult<States<'py>> {
        let batch = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        let runs = batch.runs();
        let data: Vec<f64> = runs
            .iter()
            .flat_map(|r| r.checked_state(&*self.sys))
            .collect();
        self.states_of(py, data, runs.len())
    }

    /// The current states (b, d) and attitudes (b, n, n) or None.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<States<'py>> {
        let data = self.current(py)?;
        self.states_of(py, data, self.members())
    }

    /// The time of the current states (absolute; the end time of an ended run).
    #[getter]
    fn time(&self) -> f64 {
        let batch = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        batch.runs().first().map_or(0.0, |r| r.time())
    }
}
