//! `lieflow.Integration`: a native run in progress (a batch of `lieflow::integrate::Run`s). The
//! chunked driver `lieflow.integrate` (Python: progress, Ctrl-C) resumes the same native
//! steppers chunk after chunk, so a run validates once, keeps its clock, and never converts its
//! state back and forth.

use std::sync::{Arc, Mutex};

use lieflow::integrate::{Run, System};
use lieflow::{check, Error};
use numpy::{PyArray2, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::convert::int;
use crate::convert::{shape_str, ArrayIn};
use crate::errors::{to_py, IntoPy};
use crate::items::{array, Out};

/// Errors raised by Python callables that a system calls from native code (a callable
/// potential or surface): such a system runs single-threaded, and the first error is re-raised
/// afterwards.
pub(crate) trait Callbacks: Send + Sync {
    /// The first recorded exception, if any (and forget it).
    fn take_error(&self) -> PyResult<()>;
}

/// Where native code that called Python keeps the first exception until it can be raised (the
/// native side goes on with NaN, which stops the computation at the next check).
#[derive(Default)]
pub(crate) struct ErrorSlot(Mutex<Option<PyErr>>);

impl ErrorSlot {
    /// Keeps `e` unless an earlier error is waiting.
    pub(crate) fn record(&self, e: PyErr) {
        let mut slot = self.0.lock().unwrap_or_else(|p| p.into_inner());
        slot.get_or_insert(e);
    }
}

impl Callbacks for ErrorSlot {
    fn take_error(&self) -> PyResult<()> {
        let mut slot = self.0.lock().unwrap_or_else(|p| p.into_inner());
        slot.take().map_or(Ok(()), Err)
    }
}

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

/// A native integration in progress (made by `System._start`); `advance(steps)` continues it.
#[pyclass(module = "lieflow", name = "Integration")]
pub struct Integration {
    /// The method's name.
    #[pyo3(get)]
    method: String,
    sys: Arc<dyn System>,
    callbacks: Option<Arc<dyn Callbacks>>,
    runs: Mutex<Vec<Run>>,
    pool: Option<rayon::ThreadPool>,
    /// Length of a state without the attitude.
    d: usize,
    attitude: bool,
    save_every: u64,
    /// Steps done (the same for every member).
    done: u64,
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
        callbacks: Option<Arc<dyn Callbacks>>,
        z0: &ArrayIn<'_>,
        attitude0: Option<&ArrayIn<'_>>,
        dt: f64,
        method: Option<&str>,
        save_every: i64,
        t0: f64,
        threads: Option<i64>,
        steps: Option<i64>,
    ) -> PyResult<Self> {
        let save_every = count("save_every", save_every)?;
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
        let runs = states
            .iter()
            .enumerate()
            .map(|(i, z)| {
                Run::new(&*sys, method, z, dt, save_every, t0).map_err(|e| {
                    if b > 1 {
                        e.in_member(i)
                    } else {
                        e
                    }
                })
            })
            .collect::<lieflow::Result<Vec<_>>>()
            .py()?;
        Ok(Integration {
            method: method.to_string(),
            sys,
            callbacks,
            runs: Mutex::new(runs),
            pool,
            d,
            attitude: attitude0.is_some(),
            save_every: save_every as u64,
            done: 0,
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
    ///     (every `save_every`-th step counted from the start of the run).
    /// Raises:
    ///     InvalidArgumentError (steps < 1), ConvergenceError, LeftDomainError (naming the
    ///     absolute time); the exception of a Python callable the system called.
    fn advance<'py>(
        &mut self,
        py: Python<'py>,
        #[pyo3(from_py_with = int)] steps: i64,
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        let steps = count("steps", steps)? as u64;
        let k = (self.done + steps) / self.save_every - self.done / self.save_every;
        let full = self.d + if self.attitude { 9 } else { 0 };
        let sys = &*self.sys;
        let runs = self.runs.get_mut().unwrap_or_else(|p| p.into_inner());
        let b = runs.len();
        // The saved states of this call (b, k, full), checked before any step is taken and then
        // allocated fallibly (an oversized request is an InvalidArgumentError, not an abort).
        let per_run = check::array_size(
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
        let pool = &self.pool;
        let result = py.detach(|| {
            let mut work = move || {
                runs.par_iter_mut()
                    .enumerate()
                    .map(|(i, run)| {
                        let mut out = Vec::new();
                        out.try_reserve_exact(per_run).map_err(|_| {
                            Error::invalid(
                                "steps",
                                format!(
                                    "cannot allocate the {per_run} values these steps save; \
                                     save less often (save_every) or run in chunks"
                                ),
                            )
                        })?;
                        run.advance(sys, steps, &mut out).map(|_| out).map_err(|e| {
                            if b > 1 {
                                e.in_member(i)
                            } else {
                                e
                            }
                        })
                    })
                    .collect::<lieflow::Result<Vec<Vec<f64>>>>()
            };
            match pool {
                Some(p) => p.install(work),
                None => work(),
            }
        });
        if let Some(c) = &self.callbacks {
            c.take_error()?;
        }
        let outs = result.py()?;
        self.done += steps;
        let mut data = check::zeros("steps", &[b, per_run]).py()?;
        for (d, o) in data.chunks_exact_mut(per_run.max(1)).zip(&outs) {
            d.copy_from_slice(o);
        }
        self.split(py, &data, b, k as usize)
    }

    /// The current states (b, d) and attitudes (b, 3, 3) or None.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<States<'py>> {
        let runs = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        let b = runs.len();
        let data: Vec<f64> = runs.iter().flat_map(|r| r.state(&*self.sys)).collect();
        let (z, r) = self.split(py, &data, b, 1)?;
        let z = z.reshape([b, self.d])?.cast_into::<PyArray2<f64>>()?;
        let r = match r {
            Some(r) => Some(r.reshape([b, 3, 3])?.cast_into::<PyArray3<f64>>()?),
            None => None,
        };
        Ok((z, r))
    }

    /// The time of the current states.
    #[getter]
    fn time(&self) -> f64 {
        let runs = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        runs.first().map_or(0.0, |r| r.time())
    }
}
