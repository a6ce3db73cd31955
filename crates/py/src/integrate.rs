//! `lieflow.Integration`: a native run in progress (a batch of `lieflow::integrate::Run`s). The
//! chunked driver `lieflow.integrate` (Python: progress, Ctrl-C) resumes the same native
//! steppers chunk after chunk, so a run validates once, keeps its clock, and never converts its
//! state back and forth.

use std::sync::{Arc, Mutex};

use lieflow::integrate::{Batch, Event, Events, Run, System, Until};
use lieflow::{check, Error};
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::convert::{int, named, real, vector, Real};
use crate::convert::{shape_str, ArrayIn};
use crate::errors::{raised, to_py, IntoPy};
use crate::items::{array, Out};

/// The result of `System._run`: states (b, k, d), attitude (b, k, 3, 3) or None, final states
/// (b, d), final attitude (b, 3, 3) or None.
pub(crate) type RunOut<'py> = (
    Out<'py>,
    Option<Out<'py>>,
    Bound<'py, PyArray2<f64>>,
    Option<Bound<'py, PyArray3<f64>>>,
);

/// Current states (b, d) and attitudes (b, 3, 3) or None.
type States<'py> = (Bound<'py, PyArray2<f64>>, Option<Bound<'py, PyArray3<f64>>>);

/// A located event as Python sees it: (index of the event function, t, state (d,), attitude
/// (3, 3) or None, absolute step).
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
    pool: Option<rayon::ThreadPool>,
    /// Length of a state without the attitude.
    d: usize,
    attitude: bool,
    save_every: u64,
    /// Steps done (the same for every member).
    done: u64,
    /// Whether the run saves at given times (`save_at`).
    at: bool,
    /// The event functions (a single run only).
    events: Option<Mutex<Events<'static>>>,
    /// The states (full, flat) saved by the call that failed, before its error (one run only).
    partial: Option<Vec<f64>>,
    /// The index of the first member in the ensemble the batch is a part of (`lieflow.ensemble`
    /// runs one batch per task), if given: errors name members by their ensemble index.
    first_member: Option<usize>,
}

/// Error `e` of member `i` of a batch of `b` named by its member: its index in the ensemble
/// (`first + i`) when the batch is a part of one, its index in the batch when `b` > 1.
fn of_member(e: Error, i: usize, b: usize, first: Option<usize>) -> Error {
    match first {
        Some(f) => e.in_member(f + i),
        None if b > 1 => e.in_member(i),
        None => e,
    }
}

/// The most worker threads a run may ask for (a pool of 10¹² threads would never finish
/// starting).
const MAX_THREADS: usize = 1024;

/// A count ≥ 1 from a Python integer.
fn count(what: &str, v: i64) -> PyResult<usize> {
    usize::try_from(v).ok().filter(|&u| u >= 1).ok_or_else(|| {
        to_py(Error::invalid(
            what,
            format!("expected {what} ≥ 1, got {v}"),
        ))
    })
}

impl Integration {
    /// Validates everything once and starts one run per row of `z0`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn start(
        sys: Arc<dyn System>,
        z0: &ArrayIn<'_>,
        attitude0: Option<&ArrayIn<'_>>,
        dt: f64,
        method: Option<&str>,
        save_every: i64,
        t0: f64,
        threads: Option<i64>,
        steps: Option<i64>,
        first_member: Option<usize>,
    ) -> PyResult<Self> {
        let save_every = count("save_every", save_every)?;
        let calls_out = sys.calls_out();
        let threads = if calls_out { Some(1) } else { threads };
        let method = match method {
            Some(m) => m,
            None => sys.methods().first().map_or("", |(name, _)| name),
        };
        let pool = match threads {
            None => None,
            Some(n) => {
                let n = count("threads", n)?;
                if n > MAX_THREADS {
                    return Err(to_py(Error::invalid(
                        "threads",
                        format!("at most {MAX_THREADS} worker threads, got {n}"),
                    )));
                }
                Some(
                    rayon::ThreadPoolBuilder::new()
                        .num_threads(n)
                        .build()
                        .map_err(|e| to_py(Error::invalid("threads", e.to_string())))?,
                )
            }
        };
        let full = sys.space().dim();
        let d = if attitude0.is_some() { full - 9 } else { full };
        let z = z0.as_array();
        if z.ndim() != 2 || z.shape()[1] != d {
            return Err(to_py(Error::shape(
                "z0",
                format!("(b, {d})"),
                shape_str(z.shape()),
            )));
        }
        let b = z.shape()[0];
        // Each member's run keeps its state several times (buffer, stepper state, scratch) and a
        // few hundred bytes more: about 64 + 8·d floats measured; check twice that against the
        // memory available before building any (a huge batch is refused, not killed).
        check::array_size("state0", &[b, 2 * (64 + 8 * full)]).py()?;
        // The whole trajectory the caller will keep: (b, steps / save_every + 1, full) floats,
        // refused before the first step when it cannot be held.
        if let Some(steps) = steps {
            let saved = count("steps", steps)? / save_every + 1;
            check::array_size("steps", &[b, saved, full]).map_err(|e| match e {
                Error::InvalidArgument { what, message } => to_py(Error::invalid(
                    what,
                    format!(
                        "the {saved} states of the trajectory: {message}; save less often \
                         (save_every)"
                    ),
                )),
                other => to_py(other),
            })?;
        }
        let mut states: Vec<Vec<f64>> = z
            .outer_iter()
            .map(|r| r.iter().copied().collect())
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
                s.extend(r.iter());
            }
        }
        // Set up on the run's threads (members in blocks validated in parallel, the first error
        // kept); a system that calls Python is set up on this thread, which holds the GIL.
        let start = || Batch::start(&*sys, method, &states, dt, save_every, t0);
        let runs = match &pool {
            Some(p) if !calls_out => p.install(start),
            _ => start(),
        }
        .map_err(|(i, e)| match i {
            Some(i) => of_member(e, i, b, first_member),
            None => e,
        })
        .py()?;
        Ok(Integration {
            method: method.to_string(),
            sys,
            calls_out,
            runs: Mutex::new(runs),
            pool,
            d,
            attitude: attitude0.is_some(),
            save_every: save_every as u64,
            done: 0,
            at: false,
            events: None,
            partial: None,
            first_member,
        })
    }

    /// Splits (b, k, full) data into states (b, k, d) and attitudes (b, k, 3, 3).
    fn split<'py>(
        &self,
        py: Python<'py>,
        data: &[f64],
        b: usize,
        k: usize,
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        let full = self.d + if self.attitude { 9 } else { 0 };
        let mut z = check::zeros("steps", &[b, k, self.d]).py()?;
        let mut r = check::zeros("steps", &[b, k, if self.attitude { 9 } else { 0 }]).py()?;
        for (i, s) in data.chunks_exact(full).enumerate() {
            z[i * self.d..(i + 1) * self.d].copy_from_slice(&s[..self.d]);
            r[i * (full - self.d)..(i + 1) * (full - self.d)].copy_from_slice(&s[self.d..]);
        }
        let states = array(py, &[b, k, self.d], z)?;
        let att = if self.attitude {
            Some(array(py, &[b, k, 3, 3], r)?)
        } else {
            None
        };
        Ok((states, att))
    }

    /// (b, d) states and (b, 3, 3) attitudes or None from b full flat states.
    fn states_of<'py>(&self, py: Python<'py>, data: &[f64], b: usize) -> PyResult<States<'py>> {
        let (z, r) = self.split(py, data, b, 1)?;
        let z = z.reshape([b, self.d])?.cast_into::<PyArray2<f64>>()?;
        let r = match r {
            Some(r) => Some(r.reshape([b, 3, 3])?.cast_into::<PyArray3<f64>>()?),
            None => None,
        };
        Ok((z, r))
    }

    /// Advances every member `until` (in parallel with the GIL released; a run with events, or
    /// of a system that calls Python, in this thread) and returns the states saved, (b, k, d) and (b, k, 3, 3) or None. After an
    /// error of a single run, what it saved before the error is kept for `take_partial`.
    fn drive<'py>(
        &mut self,
        py: Python<'py>,
        until: Until,
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        let full = self.d + if self.attitude { 9 } else { 0 };
        let sys = &*self.sys;
        let batch = self.runs.get_mut().unwrap_or_else(|p| p.into_inner());
        let b = batch.len();
        // The states saved every save_every-th step (and a terminal event's) by these steps,
        // checked before any step is taken and then reserved fallibly (an oversized request is
        // an InvalidArgumentError, not an abort). Output times were checked by `save_at`.
        let mut per_run = 0;
        let mut expected = 0;
        let steps = match until {
            Until::Steps(n) => Some(n),
            // To a time: the grid steps there, and the end state saved last.
            Until::Time(t) => match batch.runs().first() {
                Some(r) => Some(r.grid_steps(t).py()?.saturating_sub(self.done)),
                None => None,
            },
        };
        if let (false, Some(steps)) = (self.at, steps) {
            let k = (self.done + steps) / self.save_every - self.done / self.save_every;
            expected = k as usize;
            let k = k + u64::from(self.events.is_some() || matches!(until, Until::Time(_)));
            per_run = check::array_size(
                "steps",
                &[b, usize::try_from(k).unwrap_or(usize::MAX), full],
            )
            .map_err(|e| match e {
                Error::InvalidArgument { what, message } => to_py(Error::invalid(
                    what,
                    format!(
                        "the {k} states saved by these steps: {message}; save less often \
                         (save_every) or advance fewer steps at a time"
                    ),
                )),
                other => to_py(other),
            })? / b.max(1);
        }
        let plain = !self.at && self.events.is_none();
        let events = self
            .events
            .as_mut()
            .map(|m| m.get_mut().unwrap_or_else(|p| p.into_inner()));
        let pool = &self.pool;
        let first = self.first_member;
        let one = |i: usize, run: &mut Run, events: Option<&mut Events<'static>>| {
            let mut out = Vec::new();
            if out.try_reserve_exact(per_run).is_err() {
                let e = Error::invalid(
                    "steps",
                    format!(
                        "cannot allocate the {per_run} values these steps save; save less \
                         often (save_every) or run in chunks"
                    ),
                );
                return (out, Err(e));
            }
            let r = match until {
                Until::Steps(n) if plain => run.advance(sys, n, &mut out),
                _ => run.advance_to(sys, until, &mut out, events),
            };
            (out, r.map_err(|e| of_member(e, i, b, first)))
        };
        let parallel = |runs: &mut [Run]| {
            let mut work = || {
                runs.par_iter_mut()
                    .enumerate()
                    .map(|(i, run)| one(i, run, None))
                    .collect::<Vec<_>>()
            };
            match pool {
                Some(p) => p.install(work),
                None => work(),
            }
        };
        // Plain steps of a batch in SIMD lanes: the core's batch driver (groups of members in
        // parallel, the same results bit for bit as one run per member).
        let outs: Vec<(Vec<f64>, lieflow::Result<usize>)> = match until {
            Until::Steps(n) if plain && !self.calls_out && batch.in_lanes() => {
                let mut outs = Vec::with_capacity(b);
                for i in 0..b {
                    let mut out = Vec::new();
                    if out.try_reserve_exact(per_run).is_err() {
                        let e = Error::invalid(
                            "steps",
                            format!(
                                "cannot allocate the {per_run} values these steps save; save \
                                 less often (save_every) or run in chunks"
                            ),
                        );
                        return Err(to_py(of_member(e, i, b, first)));
                    }
                    outs.push(out);
                }
                let results = py.detach(|| match pool {
                    Some(p) => p.install(|| batch.advance(sys, n, &mut outs)),
                    None => batch.advance(sys, n, &mut outs),
                });
                outs.into_iter()
                    .zip(results)
                    .enumerate()
                    .map(|(i, (out, r))| (out, r.map_err(|e| of_member(e, i, b, first))))
                    .collect()
            }
            _ => {
                let runs = batch.runs_mut().py()?;
                match (events, runs.first_mut()) {
                    (Some(ev), Some(run)) if self.calls_out => {
                        vec![one(0, run, Some(ev))]
                    }
                    (Some(ev), Some(run)) => py.detach(|| vec![one(0, run, Some(ev))]),
                    // A system that calls Python runs on this thread with the GIL held (its
                    // callables need it for the whole chunk anyway), member after member; the
                    // first failure ends the call (no callable runs after an exception).
                    _ if self.calls_out => {
                        let mut outs = Vec::with_capacity(b);
                        for (i, run) in runs.iter_mut().enumerate() {
                            let (out, r) = one(i, run, None);
                            let failed = r.is_err();
                            outs.push((out, r));
                            if failed {
                                break;
                            }
                        }
                        outs
                    }
                    _ => py.detach(|| parallel(runs)),
                }
            }
        };
        let batch = self.runs.get_mut().unwrap_or_else(|p| p.into_inner());
        self.done = match (batch.runs().first(), until) {
            (Some(r), _) => r.steps_done(),
            (None, Until::Steps(n)) => self.done + n,
            (None, Until::Time(_)) => self.done,
        };
        let mut data = Vec::with_capacity(b);
        let mut error = None;
        for (out, r) in outs {
            match r {
                Ok(_) => data.push(out),
                Err(e) => {
                    if b == 1 {
                        self.partial = Some(out);
                    }
                    error.get_or_insert(e);
                }
            }
        }
        if let Some(e) = error {
            return Err(to_py(e));
        }
        let k = data.first().map_or(expected, |o| o.len() / full.max(1));
        if data.iter().any(|o| o.len() != k * full) {
            return Err(to_py(Error::invalid(
                "steps",
                "the members of the batch saved different numbers of states",
            )));
        }
        let mut flat = check::zeros("steps", &[b, k * full]).py()?;
        for (d, o) in flat.chunks_exact_mut((k * full).max(1)).zip(&data) {
            d.copy_from_slice(o);
        }
        self.split(py, &flat, b, k)
    }

    /// `_run`: the initial states and the states saved in `steps` more steps, and the final
    /// states.
    pub(crate) fn run_all<'py>(&mut self, py: Python<'py>, steps: i64) -> PyResult<RunOut<'py>> {
        let (z0, r0) = self.state(py)?;
        let (rest, r_rest) = self.advance(py, steps)?;
        let (zf, rf) = self.state(py)?;
        let np = py.import("numpy")?;
        let join = |first: Bound<'py, PyAny>, rest: Out<'py>| -> PyResult<Out<'py>> {
            let first = np.call_method1("expand_dims", (first, 1))?;
            Ok(np
                .call_method1("concatenate", ((first, rest), 1))?
                .cast_into()?)
        };
        let states = join(z0.into_any(), rest)?;
        let att = match (r0, r_rest) {
            (Some(r0), Some(r)) => Some(join(r0.into_any(), r)?),
            _ => None,
        };
        Ok((states, att, zf, rf))
    }
}

#[pymethods]
impl Integration {
    /// Advances every member by `steps` steps (in parallel, GIL released).
    ///
    /// Returns:
    ///     (states (b, k, d), attitude (b, k, 3, 3) or None): the states saved in these steps
    ///     (every `save_every`-th step counted from the start of the run, or those at the
    ///     output times of `save_at`; with events, the terminal event's state last).
    /// Raises:
    ///     InvalidArgumentError (steps < 1, an ended run), ConvergenceError, LeftDomainError
    ///     (naming the absolute step and time), NonFiniteError (an event function's value); the
    ///     exception of a Python callable the system or an event function called.
    fn advance<'py>(
        &mut self,
        py: Python<'py>,
        #[pyo3(from_py_with = int)] steps: i64,
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        let steps = count("steps", steps)? as u64;
        self.drive(py, Until::Steps(steps))
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
        self.drive(py, Until::Time(t))
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
        let full = self.d + if self.attitude { 9 } else { 0 };
        let batch = self.runs.get_mut().unwrap_or_else(|p| p.into_inner());
        check::array_size("t_eval", &[batch.len(), times.len(), full]).py()?;
        // Output times need the members' own steppers (shortened steps).
        for run in batch.runs_mut().py()?.iter_mut() {
            run.save_at(&times).py()?;
        }
        self.at = true;
        Ok(())
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
    /// (index of the event function, t, state (d,), attitude (3, 3) or None, absolute step).
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
                let att = if attitude {
                    Some(PyArray1::from_slice(py, &h.state[d..]).reshape([3, 3])?)
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
    /// (1, k, 3, 3) or None saved by that call before its error (then forgotten); None otherwise.
    fn take_partial<'py>(
        &mut self,
        py: Python<'py>,
    ) -> PyResult<Option<(Out<'py>, Option<Out<'py>>)>> {
        let Some(data) = self.partial.take() else {
            return Ok(None);
        };
        let full = self.d + if self.attitude { 9 } else { 0 };
        let k = data.len() / full.max(1);
        self.split(py, &data, 1, k).map(Some)
    }

    /// The last states that passed the checks (b, d) and attitudes (b, 3, 3) or None: the
    /// current states, and after an error the states before the failing step (at
    /// `steps_done`), where the stepper's own `state()` may already be outside the domain.
    fn checked_state<'py>(&self, py: Python<'py>) -> PyResult<States<'py>> {
        let batch = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        let runs = batch.runs();
        let data: Vec<f64> = runs
            .iter()
            .flat_map(|r| r.checked_state(&*self.sys))
            .collect();
        self.states_of(py, &data, runs.len())
    }

    /// The current states (b, d) and attitudes (b, 3, 3) or None.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<States<'py>> {
        let mut batch = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        let b = batch.len();
        let sys = &*self.sys;
        let data: Vec<f64> = if !self.calls_out && batch.in_lanes() {
            // Batches in lanes: read in parallel on the run's threads, GIL released.
            let batch = &mut *batch;
            let states = py.detach(|| match &self.pool {
                Some(p) => p.install(|| batch.states(sys)),
                None => batch.states(sys),
            });
            states.into_iter().flatten().collect()
        } else {
            (0..b).flat_map(|i| batch.state(sys, i)).collect()
        };
        self.states_of(py, &data, b)
    }

    /// The time of the current states (absolute; the end time of an ended run).
    #[getter]
    fn time(&self) -> f64 {
        let batch = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        batch.runs().first().map_or(0.0, |r| r.time())
    }
}
