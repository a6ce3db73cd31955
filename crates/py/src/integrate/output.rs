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
    /// The states (b, k, d) and attitudes (b, k, 3, 3) or None of `data` (b·k full states).
    pub(super) fn split<'py>(
        &self,
        py: Python<'py>,
        data: Vec<f64>,
        b: usize,
        k: usize,
    ) -> PyResult<(Out<'py>, Option<Out<'py>>)> {
        self.arrays(py, data, &[b, k])
    }

    /// The states (*lead, d) and attitudes (*lead, 3, 3) or None of `data` (full states).
    pub(super) fn arrays<'py>(
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
            let states = py
                .detach(|| with_threads(self.threads, || Ok(batch.states(sys))))
                .py()?;
            states.into_iter().flatten().collect()
        } else {
            (0..b).flat_map(|i| batch.state(sys, i)).collect()
        })
    }

    /// The length of a state with its attitude.
    pub(super) fn full(&self) -> usize {
        self.d + if self.attitude { 9 } else { 0 }
    }

    /// The samples of one call, `flat` (b members × k states), with the initial states before
    /// them while they are due (the first call of a run that saves every `save_every`-th
    /// state), and their times: t₀ + n·(save_every·dt) for the run's n-th sample (a terminal
    /// event's state, saved last, at its time `ended`), or the output times of `save_at`.
    pub(super) fn samples(
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

    /// One call's samples (`flat`, k per member; `last`: the time of a terminal event's state
    /// saved last) as `_chunk` returns them, with the current states and the end time.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn chunk_of<'py>(
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
    pub(super) fn initial_states<'py>(&self, py: Python<'py>) -> PyResult<States<'py>> {
        self.states_of(py, self.initial.clone(), self.members())
    }
}
