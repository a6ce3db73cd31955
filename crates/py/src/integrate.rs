//! `lieflow.Integration`: a native run in progress (a batch of `lieflow::integrate::Run`s). The
//! chunked driver `lieflow.integrate` (Python: progress, Ctrl-C) resumes the same native
//! steppers chunk after chunk, so a run validates once, keeps its clock, and never converts its
//! state back and forth.

use std::sync::{Arc, Mutex};

use lieflow::integrate::{with_threads, Batch, Clock, Event, Events, Resolved, Run, System, Until};
use lieflow::{check, Error};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::convert::{named, real, real_opt, vector, ArrayIn, Real};
use crate::errors::{raised, to_py, IntoPy};
use crate::items::{array, Out};

/// The result of `System._run`: states (b, k, d), attitude (b, k, 3, 3) or None, final states
/// (b, d), final attitude (b, 3, 3) or None.
pub(crate) type RunOut<'py> = (Out<'py>, Option<Out<'py>>, Out<'py>, Option<Out<'py>>);

/// Current states (b, d) and attitudes (b, 3, 3) or None.
type States<'py> = (Out<'py>, Option<Out<'py>>);

/// One call of a run as `lieflow.integrate` assembles it: the times (k,), states (b, k, d) and
/// attitudes (b, k, 3, 3) or None of its samples, the current states (b, d) and attitudes, the
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
    /// The worker threads (None: rayon's global pool), for the core's `with_threads`.
    threads: Option<usize>,
    /// Length of a state without the attitude.
    d: usize,
    attitude: bool,
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

/// The arguments of a run as `lieflow.integrate` passes them on, read and checked here once, in
/// its words: a TypeError for a wrong type, an InvalidArgumentError for a wrong value.
pub(crate) mod args {
    use lieflow::Error;
    use numpy::{PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
    use pyo3::exceptions::PyTypeError;
    use pyo3::prelude::*;
    use pyo3::types::{PyBool, PyFloat, PyInt, PyString};

    use crate::errors::to_py;

    /// An argument as given (`from_py_with`): read in the order of `lieflow.integrate`'s checks,
    /// not in pyo3's order of parameters, and with its words.
    pub(crate) fn given<'py>(ob: &Bound<'py, PyAny>) -> PyResult<Option<Bound<'py, PyAny>>> {
        Ok(Some(ob.clone()))
    }

    fn type_name(ob: &Bound<'_, PyAny>) -> String {
        ob.get_type()
            .name()
            .map_or_else(|_| "object".to_string(), |n| n.to_string())
    }

    /// `repr(ob)`, cut to `max` characters (Python's `{ob!r:.60}`).
    fn repr(ob: &Bound<'_, PyAny>, max: usize) -> String {
        let r = ob
            .repr()
            .map_or_else(|_| "?".to_string(), |r| r.to_string());
        r.chars().take(max).collect()
    }

    /// `repr(v)` of a float, as Python prints it.
    pub(crate) fn float_repr(v: f64) -> String {
        Python::attach(|py| repr(PyFloat::new(py, v).as_any(), usize::MAX))
    }

    /// An integer ≥ 1 (≤ 2⁶³ − 1): an int or what has `__index__`, bools refused.
    pub(crate) fn count(name: &str, ob: &Bound<'_, PyAny>) -> PyResult<u64> {
        let py = ob.py();
        let bad = || {
            PyTypeError::new_err(format!(
                "invalid {name}: expected an integer >= 1, got {} {}",
                type_name(ob),
                repr(ob, usize::MAX)
            ))
        };
        if ob.is_instance_of::<PyBool>() {
            return Err(bad());
        }
        let n = if ob.is_exact_instance_of::<PyInt>() {
            ob.clone()
        } else {
            py.import("operator")?
                .call_method1("index", (ob,))
                .map_err(|e| {
                    if e.is_instance_of::<PyTypeError>(py) {
                        bad()
                    } else {
                        e
                    }
                })?
        };
        let invalid = |m: String| to_py(Error::invalid(name, m));
        match n.extract::<i64>() {
            Ok(v) if v >= 1 => Ok(v as u64),
            Ok(v) => Err(invalid(format!("expected an integer >= 1, got {v}"))),
            Err(_) if n.gt(0)? => Err(invalid(format!(
                "expected an integer <= 2**63 - 1, got {}",
                n.str()?
            ))),
            Err(_) => Err(invalid(format!(
                "expected an integer >= 1, got {}",
                n.str()?
            ))),
        }
    }

    /// [`count`] of an optional argument (None: not given).
    pub(crate) fn count_opt(name: &str, ob: Option<&Bound<'_, PyAny>>) -> PyResult<Option<u64>> {
        match ob.filter(|o| !o.is_none()) {
            Some(o) => count(name, o).map(Some),
            None => Ok(None),
        }
    }

    /// A real number (bool excluded) or a 0-d numeric array, as a float; None for anything else.
    fn real(ob: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
        if let Ok(f) = ob.cast::<PyFloat>() {
            return Ok(Some(f.value()));
        }
        if ob.is_instance_of::<PyBool>() {
            return Ok(None);
        }
        let py = ob.py();
        let real = ob.is_instance_of::<PyInt>()
            || ob.is_instance(&py.import("numbers")?.getattr("Real")?)?
            || ob
                .cast::<PyUntypedArray>()
                .is_ok_and(|a| a.ndim() == 0 && matches!(a.dtype().kind(), b'i' | b'u' | b'f'));
        if !real {
            return Ok(None);
        }
        Ok(Some(py.get_type::<PyFloat>().call1((ob,))?.extract()?))
    }

    /// The time step: a real number, finite and > 0.
    pub(crate) fn step(ob: &Bound<'_, PyAny>) -> PyResult<f64> {
        let Some(dt) = real(ob)? else {
            return Err(PyTypeError::new_err(format!(
                "invalid dt: expected a real number > 0, got {} {}",
                type_name(ob),
                repr(ob, usize::MAX)
            )));
        };
        if !(0.0 < dt && dt < f64::INFINITY) {
            let got = float_repr(dt);
            return Err(to_py(Error::invalid(
                "dt",
                format!("expected a finite number > 0, got {got}"),
            )));
        }
        Ok(dt)
    }

    /// A time: a real number, finite.
    pub(crate) fn time(name: &str, ob: &Bound<'_, PyAny>) -> PyResult<f64> {
        let Some(t) = real(ob)? else {
            return Err(PyTypeError::new_err(format!(
                "invalid {name}: expected a real number, got {} {}",
                type_name(ob),
                repr(ob, 60)
            )));
        };
        if !t.is_finite() {
            let got = float_repr(t);
            return Err(to_py(Error::invalid(
                name,
                format!("expected a finite number, got {got}"),
            )));
        }
        Ok(t)
    }

    /// A method's name, or None for the system's default.
    pub(crate) fn method(ob: &Bound<'_, PyAny>) -> PyResult<Option<String>> {
        if ob.is_none() {
            return Ok(None);
        }
        match ob.cast::<PyString>() {
            Ok(s) => Ok(Some(s.to_cow()?.into_owned())),
            Err(_) => Err(PyTypeError::new_err(format!(
                "invalid method: expected a name (str), got {} {}",
                type_name(ob),
                repr(ob, usize::MAX)
            ))),
        }
    }

    /// The initial attitudes of `b` members, (b·9) values: one (3, 3) shared by a batch, or one
    /// per member (b, 3, 3) of a batch; real numbers only (the rule of every array argument),
    /// finite (a NaN named by its member and its entry).
    pub(crate) fn attitude(ob: &Bound<'_, PyAny>, b: usize, batched: bool) -> PyResult<Vec<f64>> {
        let check_shape = |shape: &[usize]| {
            if shape == [3, 3] || batched && shape == [b, 3, 3] {
                return Ok(());
            }
            let want = if batched {
                format!("(3, 3) or ({b}, 3, 3)")
            } else {
                "(3, 3)".to_string()
            };
            Err(to_py(Error::shape(
                "attitude",
                want,
                crate::convert::shape_str(shape),
            )))
        };
        // A float64 array is read in place; anything else through numpy.asarray.
        let read = ob
            .cast::<numpy::PyArrayDyn<f64>>()
            .ok()
            .and_then(|a| a.try_readonly().ok());
        let (shape, flat) = match read {
            Some(v) => {
                let v = v.as_array();
                check_shape(v.shape())?;
                (v.shape().to_vec(), v.iter().copied().collect::<Vec<f64>>())
            }
            None => as_float_array(ob, check_shape)?,
        };
        if let Some(k) = flat.iter().position(|v| !v.is_finite()) {
            let (m, e) = (k / 9, k % 9);
            let what = if shape.len() == 3 {
                format!("batch member {m}: attitude")
            } else {
                "attitude".to_string()
            };
            return Err(to_py(Error::NonFinite {
                what,
                location: format!("({}, {})", e / 3, e % 3),
            }));
        }
        Ok(if shape.len() == 2 {
            flat.repeat(b)
        } else {
            flat
        })
    }

    /// `ob` through numpy.asarray as (shape, row-major float64 entries): a TypeError unless
    /// real numbers (bool, int or float); the shape checked by `check_shape` before reading.
    fn as_float_array(
        ob: &Bound<'_, PyAny>,
        check_shape: impl Fn(&[usize]) -> PyResult<()>,
    ) -> PyResult<(Vec<usize>, Vec<f64>)> {
        let py = ob.py();
        let expected =
            "invalid attitude: expected an array-like of real numbers (bool, int or float)";
        let np = py.import("numpy")?;
        let a = np.call_method1("asarray", (ob,)).map_err(|e| {
            if e.is_instance_of::<pyo3::exceptions::PyValueError>(py) {
                PyTypeError::new_err(format!(
                    "{expected}, got a {} that numpy cannot read as an array: {}",
                    type_name(ob),
                    e.value(py)
                ))
            } else {
                e
            }
        })?;
        let arr = a.cast::<PyUntypedArray>()?;
        let text = ob.is_instance_of::<PyString>() || ob.is_instance_of::<pyo3::types::PyBytes>();
        if text || !matches!(arr.dtype().kind(), b'b' | b'i' | b'u' | b'f') {
            return Err(PyTypeError::new_err(format!(
                "{expected}, got a {} (numpy dtype {})",
                type_name(ob),
                arr.dtype().str()?
            )));
        }
        let shape = arr.shape().to_vec();
        check_shape(&shape)?;
        let flat = np
            .call_method1("ascontiguousarray", (a, "float64"))?
            .call_method0("ravel")?
            .extract::<Vec<f64>>()?;
        Ok((shape, flat))
    }
}

impl Integration {
    /// Starts one run per member of `states` (b members of the system's states, with their
    /// attitudes appended where given) with the method `resolved` (the name `method`, None for
    /// the default), every argument checked once, and the states saved at
    /// `t_eval` when given (then checked against the run: not before t₀, not after the end
    /// t₀ + steps·dt).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn start(
        sys: Arc<dyn System>,
        mut states: Vec<Vec<f64>>,
        batched: bool,
        attitude: bool,
        dt: f64,
        resolved: lieflow::Result<Arc<Resolved>>,
        method: Option<&str>,
        save_every: u64,
        t0: f64,
        threads: Option<usize>,
        steps: Option<u64>,
        first_member: Option<usize>,
        t_eval: Option<Vec<f64>>,
    ) -> PyResult<Self> {
        let calls_out = sys.calls_out();
        let threads = if calls_out { Some(1) } else { threads };
        if let Some(n) = threads.filter(|&n| n > MAX_THREADS) {
            return Err(to_py(Error::invalid(
                "threads",
                format!("at most {MAX_THREADS} worker threads, got {n}"),
            )));
        }
        let method = resolved.as_ref().map_or(method.unwrap_or(""), |m| m.name);
        let full = sys.space().dim();
        let d = if attitude { full - 9 } else { full };
        let b = states.len();
        let save = usize::try_from(save_every).unwrap_or(usize::MAX);
        // Each member's run keeps its state several times (buffer, stepper state, scratch) and a
        // few hundred bytes more: about 64 + 8·d floats measured; check twice that against the
        // memory available before building any (a huge batch is refused, not killed).
        check::array_size("state0", &[b, 2 * (64 + 8 * full)]).py()?;
        // The whole trajectory the caller will keep: (b, steps / save_every + 1, full) floats,
        // refused before the first step when it cannot be held (with t_eval, `save_at` checks
        // the states it keeps).
        if let (Some(steps), None) = (steps, &t_eval) {
            let saved = usize::try_from(steps / save_every + 1).unwrap_or(usize::MAX);
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
        // Set up on the run's threads (members in blocks validated in parallel, the first error
        // kept); a system that calls Python is set up on this thread, which holds the GIL.
        let start = || match &resolved {
            Ok(m) => Batch::resolved(&*sys, m, &states, dt, save, t0),
            Err(_) => Batch::start(&*sys, method, &states, dt, save, t0),
        };
        let runs = if calls_out {
            start()
        } else {
            with_threads(threads, || Ok(start())).py()?
        }
        .map_err(|(i, e)| match i {
            Some(i) => of_member(e, i, b, first_member),
            None => e,
        })
        .py()?;
        let initial = states.drain(..).flatten().collect();
        let mut run = Integration {
            method: method.to_string(),
            sys,
            calls_out,
            runs: Mutex::new(runs),
            threads,
            d,
            attitude,
            batched,
            save_every,
            t0,
            dt,
            done: 0,
            at: None,
            saved: 0,
            initial,
            events: None,
            partial: None,
            first_member,
        };
        if let Some(times) = t_eval {
            let last = times.last().copied();
            run.save_times(times)?;
            if let (Some(steps), Some(last)) = (steps, last) {
                let end = t0 + steps as f64 * dt;
                let c = Clock { t0, dt, done: 0 };
                if last > end + c.grid_tol(end) {
                    return Err(to_py(Error::invalid(
                        "t_eval",
                        format!(
                            "the times must not pass the end t0 + steps * dt = {}, got {}",
                            args::float_repr(end),
                            args::float_repr(last)
                        ),
                    )));
                }
            }
        }
        Ok(run)
    }

    /// The states (b, k, d) and attitudes (b, k, 3, 3) or None of `data` (b·k full states).
    fn split<'py>(
        &self,
        py: Python<'py>,
        data: Vec<f64>,
        b: usize,
        k: usize,
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        self.arrays(py, data, &[b, k])
    }

    /// The states (*lead, d) and attitudes (*lead, 3, 3) or None of `data` (full states).
    fn arrays<'py>(
        &self,
        py: Python<'py>,
        data: Vec<f64>,
        lead: &[usize],
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        let shape = |item: &[usize]| [lead, item].concat();
        if !self.attitude {
            return Ok((array(py, &shape(&[self.d]), data)?, None));
        }
        let full = self.full();
        let n = data.len() / full;
        let mut z = check::zeros("steps", &[n, self.d]).py()?;
        let mut r = check::zeros("steps", &[n, 9]).py()?;
        for ((s, z), r) in data
            .chunks_exact(full)
            .zip(z.chunks_exact_mut(self.d))
            .zip(r.chunks_exact_mut(9))
        {
            z.copy_from_slice(&s[..self.d]);
            r.copy_from_slice(&s[self.d..]);
        }
        let states = array(py, &shape(&[self.d]), z)?;
        Ok((states, Some(array(py, &shape(&[3, 3]), r)?)))
    }

    /// (b, d) states and (b, 3, 3) attitudes or None from b full flat states.
    fn states_of<'py>(&self, py: Python<'py>, data: Vec<f64>, b: usize) -> PyResult<States<'py>> {
        self.arrays(py, data, &[b])
    }

    /// The current full states of the members, one after the other.
    fn current(&self, py: Python<'_>) -> PyResult<Vec<f64>> {
        let mut batch = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        let b = batch.len();
        let sys = &*self.sys;
        Ok(if !self.calls_out && batch.in_lanes() {
            // Batches in lanes: read in parallel on the run's threads, GIL released.
            let batch = &mut *batch;
            let states = py
                .detach(|| with_threads(self.threads, || Ok(batch.states(sys))))
                .py()?;
            states.into_iter().flatten().collect()
        } else {
            (0..b).flat_map(|i| batch.state(sys, i)).collect()
        })
    }

    /// Advances every member `until` (in parallel with the GIL released; a run with events, or
    /// of a system that calls Python, in this thread) and returns the states saved, (b, k, d) and (b, k, 3, 3) or None. After an
    /// error of a single run, what it saved before the error is kept for `take_partial`.
    fn drive(&mut self, py: Python<'_>, until: Until) -> PyResult<(Vec<f64>, usize)> {
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
        if let (None, Some(steps)) = (&self.at, steps) {
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
        let plain = self.at.is_none() && self.events.is_none();
        let events = self
            .events
            .as_mut()
            .map(|m| m.get_mut().unwrap_or_else(|p| p.into_inner()));
        let threads = self.threads;
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
            // One member runs on this thread: handing it to the pool costs a thread's wake-up
            // (microseconds), more than a short run.
            if let [run] = runs {
                return Ok(vec![one(0, run, None)]);
            }
            let mut work = || {
                runs.par_iter_mut()
                    .enumerate()
                    .map(|(i, run)| one(i, run, None))
                    .collect::<Vec<_>>()
            };
            with_threads(threads, || Ok(work()))
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
                let results = py
                    .detach(|| with_threads(threads, || Ok(batch.advance(sys, n, &mut outs))))
                    .py()?;
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
                    _ => py.detach(|| parallel(runs)).py()?,
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
        Ok((flat, k))
    }

    /// The length of a state with its attitude.
    fn full(&self) -> usize {
        self.d + if self.attitude { 9 } else { 0 }
    }

    /// The samples of one call, `flat` (b members × k states), with the initial states before
    /// them while they are due (the first call of a run that saves every `save_every`-th
    /// state), and their times: t₀ + n·(save_every·dt) for the run's n-th sample (a terminal
    /// event's state, saved last, at its time `ended`), or the output times of `save_at`.
    fn samples(
        &mut self,
        flat: Vec<f64>,
        k: usize,
        last: Option<f64>,
    ) -> (Vec<f64>, usize, Vec<f64>) {
        let full = self.full();
        let b = self.members();
        let (flat, k) = if self.at.is_none() && self.saved == 0 {
            let mut out = Vec::with_capacity(flat.len() + self.initial.len());
            for i in 0..b {
                out.extend_from_slice(&self.initial[i * full..(i + 1) * full]);
                out.extend_from_slice(&flat[i * k * full..(i + 1) * k * full]);
            }
            (out, k + 1)
        } else {
            (flat, k)
        };
        let n0 = self.saved;
        let times = match &self.at {
            Some(times) => times[n0.min(times.len())..(n0 + k).min(times.len())].to_vec(),
            None => {
                let every = self.save_every as f64 * self.dt;
                (n0..n0 + k)
                    .map(|n| match last {
                        Some(t) if n + 1 == n0 + k => t,
                        _ => self.t0 + n as f64 * every,
                    })
                    .collect()
            }
        };
        self.saved += k;
        (flat, k, times)
    }

    /// The time of the current state: the end time of an ended run, else t₀ + steps·dt, or the
    /// time of the last sample when that sample is the current state (a grid sample, or with
    /// `snap` an output time within round-off of it), so that a run continued from it with
    /// t0 = t_final starts exactly at its last sample.
    fn t_final(&self, ended: Option<f64>, snap: bool) -> f64 {
        if let Some(t) = ended {
            return t;
        }
        let t = self.t0 + self.done as f64 * self.dt;
        let clock = Clock {
            t0: self.t0,
            dt: self.dt,
            done: 0,
        };
        match &self.at {
            Some(times) if snap && self.saved > 0 => match times.get(self.saved - 1) {
                Some(&last) if (last - t).abs() <= clock.grid_tol(t) => last,
                _ => t,
            },
            Some(_) => t,
            None if self.done.is_multiple_of(self.save_every) => {
                self.t0 + (self.done / self.save_every) as f64 * (self.save_every as f64 * self.dt)
            }
            None => t,
        }
    }

    /// One call's samples (`flat`, k per member; `last`: the time of a terminal event's state
    /// saved last) as `_chunk` returns them, with the current states and the end time.
    #[allow(clippy::too_many_arguments)]
    fn chunk_of<'py>(
        &mut self,
        py: Python<'py>,
        flat: Vec<f64>,
        k: usize,
        last: Option<f64>,
        ended: Option<f64>,
        current: States<'py>,
        snap: bool,
    ) -> PyResult<Chunk<'py>> {
        let b = self.members();
        let (flat, k, times) = self.samples(flat, k, last);
        let (states, att) = self.split(py, flat, b, k)?;
        let hits = match self.events.is_some() {
            true => Some(self.events_found(py)?),
            false => None,
        };
        let t = PyArray1::from_vec(py, times);
        let t_final = (self.t_final(ended, snap), self.t_final(ended, false));
        Ok((
            t, states, att, current.0, current.1, self.done, ended, t_final, hits,
        ))
    }

    /// The states saved at `times` instead of every `save_every`-th state (see `save_at`).
    fn save_times(&mut self, times: Vec<f64>) -> PyResult<()> {
        let full = self.full();
        let batch = self.runs.get_mut().unwrap_or_else(|p| p.into_inner());
        check::array_size("t_eval", &[batch.len(), times.len(), full]).py()?;
        // Output times need the members' own steppers (shortened steps).
        for run in batch.runs_mut().py()?.iter_mut() {
            run.save_at(&times).py()?;
        }
        self.at = Some(times);
        Ok(())
    }

    /// `_run`: the initial states and the states saved in `steps` steps, and the final states.
    pub(crate) fn run_all<'py>(&mut self, py: Python<'py>, steps: u64) -> PyResult<RunOut<'py>> {
        let (flat, k) = self.drive(py, Until::Steps(steps))?;
        let b = self.members();
        let (flat, k, _) = self.samples(flat, k, None);
        let (states, att) = self.split(py, flat, b, k)?;
        let (zf, rf) = self.state(py)?;
        Ok((states, att, zf, rf))
    }

    /// The initial states (b, d) and attitudes (b, 3, 3) or None.
    fn initial_states<'py>(&self, py: Python<'py>) -> PyResult<States<'py>> {
        self.states_of(py, self.initial.clone(), self.members())
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
        steps: &Bound<'py, PyAny>,
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        let steps = args::count("steps", steps)?;
        let b = self.initial.len() / self.full().max(1);
        let (flat, k) = self.drive(py, Until::Steps(steps))?;
        self.split(py, flat, b, k)
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
        let (flat, mut k) = self.drive(py, until)?;
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
        self.chunk_of(py, flat, k, last, ended, current, true)
    }

    /// A plain run (no output times, no events, nothing done yet) in one call, as
    /// `lieflow.integrate` takes a run that fits in one: `steps` steps, returned as the
    /// trajectory's arrays (t (k,), states (b, k, d), attitudes (b, k, 3, 3) or None, final
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
        let (flat, k) = self.drive(py, Until::Steps(steps))?;
        let (flat, k, times) = self.samples(flat, k, None);
        let b = self.members();
        let lead: &[usize] = if self.batched { &[b] } else { &[] };
        let (states, att) = self.arrays(py, flat, &[lead, &[k]].concat())?;
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
        self.chunk_of(py, data, k, None, None, current, false)
            .map(Some)
    }

    /// `_chunk`'s tuple of a run before its first call completed: its initial samples and
    /// states, at step 0 and time t₀.
    fn _head<'py>(&mut self, py: Python<'py>) -> PyResult<Chunk<'py>> {
        let current = self.initial_states(py)?;
        let mut c = self.chunk_of(py, Vec::new(), 0, None, None, current, false)?;
        (c.5, c.7) = (0, (self.t0, self.t0));
        Ok(c)
    }

    /// The initial states (b, d) and attitudes (b, 3, 3) or None.
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
        let b = self.initial.len() / self.full().max(1);
        let (flat, k) = self.drive(py, Until::Time(t))?;
        self.split(py, flat, b, k)
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
        self.split(py, data, 1, k).map(Some)
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
        self.states_of(py, data, runs.len())
    }

    /// The current states (b, d) and attitudes (b, 3, 3) or None.
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
