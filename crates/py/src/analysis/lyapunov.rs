//! The native part of `lieflow.lyapunov` (binding of `lieflow::analysis::lyapunov`): a
//! computation in progress that `lieflow.lyapunov` (python/lieflow/chaos.py) advances by chunks
//! of segments, so that Ctrl-C is noticed between them. Conversions only.

use std::sync::{Arc, Mutex, MutexGuard};

use lieflow::analysis::lyapunov::LyapunovRun;
use lieflow::integrate::System;
use lieflow::Error;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::errors::{to_py, IntoPy};
use crate::integrate::args;
use crate::system::PySystem;

/// A Lyapunov computation in progress (internal to `lieflow.lyapunov`).
#[pyclass(module = "lieflow", name = "_Lyapunov", frozen)]
pub struct PyLyapunov {
    system: Arc<dyn System>,
    inner: Mutex<Option<LyapunovRun>>,
    /// The system calls Python callables: it runs with the GIL held.
    calls_out: bool,
}

/// The computation, locked (a poisoned lock: the computation as it was left).
type Locked<'a> = MutexGuard<'a, Option<LyapunovRun>>;

impl PyLyapunov {
    fn lock(&self) -> Locked<'_> {
        self.inner.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// The computation of a lock, unless it has been finished.
fn running<'a>(g: &'a mut Locked<'_>) -> PyResult<&'a mut LyapunovRun> {
    g.as_mut().ok_or_else(|| {
        to_py(Error::invalid(
            "run",
            "the computation has been finished (result() was called)",
        ))
    })
}

#[pymethods]
impl PyLyapunov {
    /// Starts the computation for `system` from `state0` (one state (d,), or one array per
    /// field), `steps` steps of size `dt` of `method` (None: the system's default),
    /// renormalised every `renormalise_every` steps.
    ///
    /// Raises:
    ///     TypeError, InvalidArgumentError, UnsupportedMethodError, ShapeError, NonFiniteError.
    #[new]
    fn new(
        system: PyRef<'_, PySystem>,
        state0: &Bound<'_, PyAny>,
        dt: &Bound<'_, PyAny>,
        steps: &Bound<'_, PyAny>,
        method: &Bound<'_, PyAny>,
        renormalise_every: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let steps = args::count("steps", steps)?;
        let every = args::count("renormalise_every", renormalise_every)?;
        let dt = args::step(dt)?;
        let method = args::method(method)?;
        let (z0, batched) = system.normalize(state0)?;
        if batched {
            return Err(to_py(Error::shape(
                "state0",
                format!("one state ({},)", system.sys.space().dim()),
                "a batch (b, d)",
            )));
        }
        let sys = &system.sys;
        let name = match &method {
            Some(m) => sys.resolve(m).py()?.name,
            None => sys.resolve_default().py()?.name,
        };
        let too_many = |n: u64, what: &str| {
            usize::try_from(n).map_err(|_| to_py(Error::invalid(what, "too large")))
        };
        let steps = too_many(steps, "steps")?;
        let every = too_many(every, "renormalise_every")?;
        let inner = LyapunovRun::new(sys.as_ref(), name, &z0, dt, steps, every).py()?;
        Ok(PyLyapunov {
            calls_out: sys.calls_out(),
            system: sys.clone(),
            inner: Mutex::new(Some(inner)),
        })
    }

    /// Advances by at most `segments` segments (the GIL released unless the system calls
    /// Python); returns how many were done.
    fn advance(&self, py: Python<'_>, segments: usize) -> PyResult<usize> {
        let system = self.system.as_ref();
        let mut g = self.lock();
        let run = running(&mut g)?;
        let r = match self.calls_out {
            true => run.advance(system, segments),
            false => py.detach(|| run.advance(system, segments)),
        };
        r.py()
    }

    /// The number of segments of the whole run.
    #[getter]
    fn segments(&self) -> PyResult<usize> {
        Ok(running(&mut self.lock())?.segments())
    }

    /// The segments done so far.
    #[getter]
    fn segments_done(&self) -> PyResult<usize> {
        Ok(running(&mut self.lock())?.segments_done())
    }

    /// (exponents (e,) sorted descending, times (k,), running (k, e) in the QR's column
    /// order, final state (d,)) of the k segments done; ends the computation.
    #[allow(clippy::type_complexity)]
    fn result<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        let mut g = self.lock();
        running(&mut g)?;
        let l = g.take().expect("checked above").finish();
        let (k, e) = (l.times.len(), l.exponents.len());
        let running = Array2::from_shape_vec((k, e), l.running)
            .map_err(|err| to_py(Error::shape("running", "(k, e)", err.to_string())))?;
        Ok((
            l.exponents.into_pyarray(py),
            l.times.into_pyarray(py),
            running.into_pyarray(py),
            l.state.into_pyarray(py),
        ))
    }
}
