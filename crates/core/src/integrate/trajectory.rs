//! Whole runs: [`integrate`] and [`integrate_batch`] collect a [`Trajectory`].

use super::batch::Batch;
use super::method::{Integrator, System};
use super::problem::Problem;
use super::run::{too_many, Run};
use crate::error::{Error, Result};

/// A computed trajectory: the saved samples and the final state.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    /// Sample times t₀ + k·save_every·dt.
    pub t: Vec<f64>,
    /// The saved states (user frame), row-major (len × dim).
    pub states: Vec<f64>,
    /// Length of one state.
    pub dim: usize,
    /// The state after all steps (also when `steps` is not a multiple of `save_every`).
    pub final_state: Vec<f64>,
}

impl Trajectory {
    /// Number of saved samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether no sample was saved (never the case for a trajectory returned by [`integrate`]).
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The k-th saved state.
    pub fn state(&self, k: usize) -> &[f64] {
        &self.states[k * self.dim..(k + 1) * self.dim]
    }
}

fn check_steps(steps: usize) -> Result<()> {
    if steps < 1 {
        return Err(Error::invalid("steps", "expected steps ≥ 1, got 0"));
    }
    Ok(())
}

/// Runs `run` for `steps` steps from its start and collects the trajectory.
fn collect<P: Problem + ?Sized>(
    problem: &P,
    mut run: Run,
    z0: &[f64],
    steps: usize,
) -> Result<Trajectory> {
    let dim = z0.len();
    let n_saved = steps / run.save_every as usize + 1;
    let mut states = Vec::new();
    let values = n_saved.checked_mul(dim).ok_or_else(too_many)?;
    states.try_reserve_exact(values).map_err(|_| too_many())?;
    states.extend_from_slice(z0);
    run.advance(problem, steps as u64, &mut states)?;
    let every = run.save_every as f64 * run.clock.dt;
    Ok(Trajectory {
        t: (0..n_saved)
            .map(|k| run.clock.t0 + k as f64 * every)
            .collect(),
        final_state: run.state(problem),
        states,
        dim,
    })
}

/// Integrates `system` from `z0` (user frame) by `steps` steps of size `dt` with its method called
/// `method`, saving every `save_every`-th state and the initial one (t₀ = 0).
///
/// Errors: those of [`Run::new`] and [`Run::advance`], and `steps` < 1.
pub fn integrate<S: System + ?Sized>(
    system: &S,
    method: &str,
    z0: &[f64],
    dt: f64,
    steps: usize,
    save_every: usize,
) -> Result<Trajectory> {
    check_steps(steps)?;
    let run = Run::new(system, method, z0, dt, save_every, 0.0)?;
    collect(system, run, z0, steps)
}

/// [`integrate`] with a method value (`&Splitting(Composition::suzuki4())`, `&Gauss(2)`, …)
/// instead of a catalogued name: any method of the right kind, with any coefficients.
pub fn integrate_with<P: Problem, M: Integrator<P> + ?Sized>(
    problem: &P,
    method: &M,
    z0: &[f64],
    dt: f64,
    steps: usize,
    save_every: usize,
) -> Result<Trajectory> {
    check_steps(steps)?;
    let run = Run::with(problem, method, z0, dt, save_every, 0.0)?;
    collect(problem, run, z0, steps)
}

/// Runs `work` on rayon's global pool (`threads` = None) or on a pool of `threads` threads.
pub fn with_threads<T: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> Result<T> + Send,
) -> Result<T> {
    match threads {
        None => work(),
        Some(0) => Err(Error::invalid("threads", "expected threads ≥ 1, got 0")),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| Error::invalid("threads", format!("cannot build a pool of {n}: {e}")))?
            .install(work),
    }
}

/// Integrates many initial states in parallel (rayon), each exactly as [`integrate`] would (bit
/// for bit), as a [`Batch`]: in blocks of SIMD lanes where the method has a batch stepper for the
/// system, one member at a time otherwise.
///
/// `threads`: `None` uses rayon's global pool (all cores); `Some(n)` a pool of n threads. Every
/// input is validated before any work starts; an error names the batch member (the first
/// member that failed, with its step).
pub fn integrate_batch<S: System + ?Sized>(
    system: &S,
    method: &str,
    states0: &[Vec<f64>],
    dt: f64,
    steps: usize,
    save_every: usize,
    threads: Option<usize>,
) -> Result<Vec<Trajectory>> {
    check_steps(steps)?;
    let start = || {
        Batch::start(system, method, states0, dt, save_every, 0.0).map_err(|(i, e)| match i {
            Some(i) => e.in_member(i),
            None => e,
        })
    };
    let mut batch = with_threads(threads, start)?;
    let n_saved = steps / save_every + 1;
    let mut outs = states0
        .iter()
        .map(|z0| {
            let mut states = Vec::new();
            let values = n_saved.checked_mul(z0.len()).ok_or_else(too_many)?;
            states.try_reserve_exact(values).map_err(|_| too_many())?;
            states.extend_from_slice(z0);
            Ok(states)
        })
        .collect::<Result<Vec<_>>>()?;
    let (results, finals) = with_threads(threads, || {
        let results = batch.advance(system, steps as u64, &mut outs);
        Ok((results, batch.states(system)))
    })?;
    for (i, r) in results.into_iter().enumerate() {
        r.map_err(|e| e.in_member(i))?;
    }
    let every = save_every as f64 * dt;
    let t: Vec<f64> = (0..n_saved).map(|k| k as f64 * every).collect();
    Ok(outs
        .into_iter()
        .zip(finals.chunks_exact(system.space().dim()))
        .map(|(states, final_state)| Trajectory {
            t: t.clone(),
            dim: final_state.len(),
            final_state: final_state.to_vec(),
            states,
        })
        .collect())
}
