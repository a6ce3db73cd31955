//! The output of a run as Python receives it: the samples of a call with their times, states
//! and attitudes split into numpy arrays, the current states and the time of the final state.

use lieflow::check;
use lieflow::integrate::{with_threads, Clock, Until};
use numpy::PyArray1;
use pyo3::prelude::*;

use super::{Chunk, Integration, RunOut, States};
use crate::errors::IntoPy;
use crate::items::{array, Out};

impl Integration {
    /// The states (*lead, d) and attitudes (*lead, n, n) or None of `data` (full states).
    pub(super) fn arrays<'py>(
        &self,
        py: Python<'py>,
        data: Vec<f64>,
        lead: &[usize],
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        match self.attitude {
            0 => Ok((array(py, &[lead, &[self.d]].concat(), data)?, None)),
            _ => self.arrays_of(py, data.chunks_exact(self.full()), lead),
        }
    }

    /// The states (*lead, d) and attitudes (*lead, n, n) or None of the full states `states`
    /// (as many as `lead` says), copied once.
    fn arrays_of<'a, 'py>(
        &self,
        py: Python<'py>,
        states: impl Iterator<Item = &'a [f64]>,
        lead: &[usize],
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        let shape = |item: &[usize]| [lead, item].concat();
        let n = lead.iter().product();
        let d = self.d;
        let mut z = check::zeros("steps", &[n, d]).py()?;
        let a = self.attitude;
        let mut r = match a {
            0 => Vec::new(),
            _ => check::zeros("steps", &[n, a * a]).py()?,
        };
        let mut rows = r.chunks_exact_mut((a * a).max(1));
        for (s, z) in states.zip(z.chunks_exact_mut(d.max(1))) {
            z.copy_from_slice(&s[..d]);
            if let Some(r) = rows.next() {
                r.copy_from_slice(&s[d..]);
            }
        }
        let states = array(py, &shape(&[d]), z)?;
        let att = match a {
            0 => None,
            _ => Some(array(py, &shape(&[a, a]), r)?),
        };
        Ok((states, att))
    }

    /// The states (b, k, d) and attitudes (b, k, n, n) or None that the members saved in one
    /// call (member i's k full states in `outs[i]`).
    pub(super) fn saved_arrays<'py>(
        &self,
        py: Python<'py>,
        outs: &[Vec<f64>],
        k: usize,
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        let states = outs.iter().flat_map(|o| o.chunks_exact(self.full()));
        self.arrays_of(py, states, &[self.members(), k])
    }

    /// (b, d) states and (b, n, n) attitudes or None from b full flat states.
    pub(super) fn states_of<'py>(
        &self,
        py: Python<'py>,
        data: Vec<f64>,
        b: usize,
    ) -> PyResult<States<'py>> {
        self.arrays(py, data, &[b])
    }

    /// The current full states of the members, one after the other.
    pub(super) fn current(&self, py: Python<'_>) -> PyResult<Vec<f64>> {
        let mut batch = self.runs.lock().unwrap_or_else(|p| p.into_inner());
        let b = batch.len();
        let sys = &*self.sys;
        Ok(if !self.calls_out && batch.in_lanes() {
            // Batches in lanes: read in parallel on the run's threads, GIL released.
            let batch = &mut *batch;
            py.detach(|| with_threads(self.threads, || Ok(batch.states(sys))))
                .py()?
        } else {
            (0..b).flat_map(|i| batch.state(sys, i)).collect()
        })
    }

    /// The length of a state with its attitude.
    pub(super) fn full(&self) -> usize {
        self.d + self.attitude * self.attitude
    }

    /// The samples of one call, `outs` (member i's k full states in `outs[i]`; a member
    /// absent saved none), with the initial states before them while they are due (the first
    /// call of a run that saves every `save_every`-th state), as arrays (*lead, k', d) and
    /// (*lead, k', n, n) or None (`lead`: [b], or [] for a single run), k' samples per member,
    /// and their times: t₀ + n·(save_every·dt) for the run's n-th sample (a terminal event's
    /// state, saved last, at its time `last`), or the output times of `save_at`.
    pub(super) fn samples<'py>(
        &mut self,
        py: Python<'py>,
        outs: &[Vec<f64>],
        k: usize,
        last: Option<f64>,
        lead: &[usize],
    ) -> PyResult<(Out<'py>, Option<Out<'py>>, Vec<f64>)> {
        let full = self.full();
        let b = self.members();
        let initial = self.at.is_none() && self.saved == 0;
        let k = k + usize::from(initial);
        let states = (0..b).flat_map(|i| {
            let first = match initial {
                true => &self.initial[i * full..(i + 1) * full],
                false => &[],
            };
            let saved = outs.get(i).map_or(&[][..], Vec::as_slice);
            first.chunks_exact(full).chain(saved.chunks_exact(full))
        });
        let (z, att) = self.arrays_of(py, states, &[lead, &[k]].concat())?;
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
        Ok((z, att, times))
    }

    /// The time of the current state: the end time of an ended run, else t₀ + steps·dt, or the
    /// time of the last sample when that sample is the current state (a grid sample, or with
    /// `snap` an output time within round-off of it), so that a run continued from it with
    /// t0 = t_final starts exactly at its last sample.
    pub(super) fn t_final(&self, ended: Option<f64>, snap: bool) -> f64 {
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

    /// One call's samples (`outs`, k per member; `last`: the time of a terminal event's state
    /// saved last) as `_chunk` returns them, with the current states and the end time.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn chunk_of<'py>(
        &mut self,
        py: Python<'py>,
        outs: &[Vec<f64>],
        k: usize,
        last: Option<f64>,
        ended: Option<f64>,
        current: States<'py>,
        snap: bool,
    ) -> PyResult<Chunk<'py>> {
        let b = self.members();
        let (states, att, times) = self.samples(py, outs, k, last, &[b])?;
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

    /// `_run`: the initial states and the states saved in `steps` steps, and the final states.
    pub(crate) fn run_all<'py>(&mut self, py: Python<'py>, steps: u64) -> PyResult<RunOut<'py>> {
        let (outs, k) = self.drive(py, Until::Steps(steps))?;
        let b = self.members();
        let (states, att, _) = self.samples(py, &outs, k, None, &[b])?;
        let (zf, rf) = self.state(py)?;
        Ok((states, att, zf, rf))
    }

    /// The initial states (b, d) and attitudes (b, n, n) or None.
    pub(super) fn initial_states<'py>(&self, py: Python<'py>) -> PyResult<States<'py>> {
        self.states_of(py, self.initial.clone(), self.members())
    }
}
