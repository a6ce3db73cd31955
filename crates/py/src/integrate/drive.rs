//! `Integration::drive`: every member advanced by one call (in parallel with the GIL released,
//! in SIMD lanes, or on this thread), the states saved gathered, errors named by their member.

use lieflow::integrate::{with_threads, Events, Run, Until};
use lieflow::{check, Error};
use pyo3::prelude::*;
use rayon::prelude::*;

use super::Integration;
use crate::errors::{to_py, IntoPy};

/// Error `e` of member `i` of a batch of `b` named by its member: its index in the ensemble
/// (`first + i`) when the batch is a part of one, its index in the batch when `b` > 1.
pub(super) fn of_member(e: Error, i: usize, b: usize, first: Option<usize>) -> Error {
    match first {
        Some(f) => e.in_member(f + i),
        None if b > 1 => e.in_member(i),
        None => e,
    }
}

impl Integration {
    /// Advances every member `until` (in parallel with the GIL released; a run with events, or
    /// of a system that calls Python, in this thread) and returns the states saved, k full
    /// states per member (member i's in the i-th vector). After an error of a single run, what
    /// it saved before the error is kept for `take_partial`.
    pub(super) fn drive(
        &mut self,
        py: Python<'_>,
        until: Until,
    ) -> PyResult<(Vec<Vec<f64>>, usize)> {
        let full = self.full();
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
        Ok((data, k))
    }
}
