//! Batches: many runs of one problem with one method, started together and advanced together.
//!
//! A [`Batch`] holds one [`Run`] per member (its clock, its checked state, what it saves, its
//! errors) and, where the method offers one for the problem ([`Integrator::batch_stepper`],
//! e.g. a splitting whose flows run in SIMD lanes), one [`BatchStepper`] per group of
//! [`GROUP`] members, which then holds the members' states and steps them together. The driver
//! does for every member what [`Run::advance`] does (saves, retractions, the finiteness guard
//! after every chunk, the replay that names the failing step), with the members' states read
//! from the block. A member that fails, or that needs work a block does not do (output times,
//! events, a shortened last step: [`Batch::runs_mut`]), goes on with a one-member stepper that
//! continues it exactly ([`BatchStepper::detach`]), so its results never depend on the path.
//! Groups are advanced in parallel (rayon, on the current pool); without a batch stepper every
//! member is its own task, as before.
//!
//! Reproducibility: a member's states are, bit for bit, those of the same run alone, whatever
//! the batch size, the member's position, the threads, and the chunks in which the batch is
//! advanced (the tests check it for the rigid body's splittings).

use rayon::prelude::*;

use std::sync::Arc;

use super::method::{BatchStepper, Clock, Integrator, Resolved, Stepper, System};
use super::problem::Problem;
use super::run::{check_start, Run};
use crate::check;
use crate::error::{Error, Result};

/// Members per batch stepper (and per parallel task of the lanes): large enough for the SIMD
/// kernels, small enough that a block stays in the L1 cache and that two threads get many tasks.
pub const GROUP: usize = 256;

/// A block of members stepped together.
struct Lanes {
    stepper: Box<dyn BatchStepper>,
    /// Whether member j's state is in the block (false once it goes on alone: its run's own
    /// stepper then holds it).
    live: Vec<bool>,
}

/// Runs of one problem advanced together (module docs).
pub struct Batch {
    runs: Vec<Run>,
    /// One entry per group of [`GROUP`] runs: its block, if the method has a batch stepper.
    lanes: Vec<Option<Lanes>>,
}

/// The one-member stepper of a member whose state is in a block: it holds nothing (the block
/// does); a member that leaves the block gets the block's exact copy ([`BatchStepper::detach`])
/// instead. Saves the set-up of one stepper per member of a large batch.
struct InBlock;

impl Stepper for InBlock {
    fn set(&mut self, _z: &[f64]) -> Result<()> {
        Ok(())
    }

    fn get(&self, _z: &mut [f64]) {}

    fn advance(&mut self, _steps: usize, _clock: Clock) -> Result<()> {
        Err(Error::invalid(
            "steps",
            "internal: a member in a block of lanes was stepped alone",
        ))
    }
}

impl Batch {
    /// Starts one run per initial state of `states0` (user frame) of `system` with its method
    /// called `method` at time `t0`, step `dt`, saving every `save_every`-th state, each exactly
    /// as [`Run::new`] would, as one batch: in blocks where the method has a batch stepper for
    /// the system (the members then get no one-member stepper of their own until they leave
    /// the block).
    ///
    /// Errors: those of [`Run::new`] and of the batch stepper's `set`, with the index of the
    /// first member that has one; a batch whose runs would not fit in the memory available
    /// ([`check::BuildBudget`], no member named).
    pub fn start<S: System + ?Sized, Z: AsRef<[f64]> + Sync>(
        system: &S,
        method: &str,
        states0: &[Z],
        dt: f64,
        save_every: usize,
        t0: f64,
    ) -> std::result::Result<Batch, (Option<usize>, Error)> {
        // An unknown method is reported after the first member's own errors, as by Run::new
        // (and an empty batch has none).
        let method = match system.resolve(method) {
            Ok(m) => m,
            Err(e) => {
                return match states0.first() {
                    Some(z) => Err((
                        Some(0),
                        check_start(system, z.as_ref(), dt, save_every, t0)
                            .err()
                            .unwrap_or(e),
                    )),
                    None => Ok(Batch {
                        runs: Vec::new(),
                        lanes: Vec::new(),
                    }),
                }
            }
        };
        Batch::resolved(system, &method, states0, dt, save_every, t0)
    }

    /// [`Batch::start`] with a method already resolved ([`System::resolve`]) for `problem`.
    pub fn resolved<P: Problem + ?Sized, Z: AsRef<[f64]> + Sync>(
        problem: &P,
        method: &Arc<Resolved>,
        states0: &[Z],
        dt: f64,
        save_every: usize,
        t0: f64,
    ) -> std::result::Result<Batch, (Option<usize>, Error)> {
        // With blocks the groups are set up in parallel (on the current rayon pool); without,
        // member after member on the calling thread, as before (a system may call back into
        // a host language that this thread holds locked, such as Python's GIL). The error is
        // the one of the first member that has one.
        let group = |(g, chunk): (usize, &[Z])| {
            start_group(problem, method, chunk, g * GROUP, dt, save_every, t0)
        };
        // One member has no block to share: it steps alone (bit for bit the same).
        let in_lanes = states0.len() > 1
            && dt.is_finite()
            && dt > 0.0
            && method.batch_stepper(dt, 0).is_some();
        let groups: Vec<_> = if in_lanes {
            states0.par_chunks(GROUP).enumerate().map(group).collect()
        } else {
            // Each member's run holds a stepper of its own, of a size no formula gives: the
            // memory taken is watched as they are built (from the second group on: one group
            // is small, and reading the memory available costs more than a short run).
            let budget =
                (states0.len() > GROUP).then(|| check::BuildBudget::new("state0", states0.len()));
            let mut groups = Vec::with_capacity(states0.len().div_ceil(GROUP));
            for (g, chunk) in states0.chunks(GROUP).enumerate() {
                if let Some(budget) = &budget {
                    budget.check(g * GROUP).map_err(|e| (None, e))?;
                }
                groups.push(group((g, chunk)));
            }
            groups
        };
        let mut runs = Vec::with_capacity(states0.len());
        let mut lanes = Vec::with_capacity(groups.len());
        for group in groups {
            let (r, l) = group.map_err(|(i, e)| (Some(i), e))?;
            runs.extend(r);
            lanes.push(l);
        }
        Ok(Batch { runs, lanes })
    }

    /// The runs `runs` (made by [`Run::new`] for `system` with its method called `method`, all
    /// with the same dt, t₀ and saving, not yet advanced) as one batch, in blocks where the
    /// method has a batch stepper for the system.
    ///
    /// Errors: those of the batch stepper's `set` (the runs' states were checked already).
    pub fn new<S: System + ?Sized>(system: &S, method: &str, runs: Vec<Run>) -> Result<Batch> {
        let method = match runs.first().and_then(|r| r.method.clone()) {
            Some(m) if m.name == method => m,
            _ => system.resolve(method)?,
        };
        Batch::build(runs, |n, dt| method.batch_stepper(dt, n))
    }

    /// [`Batch::new`] for runs made with a method value ([`Run::with`]).
    pub fn with<P: Problem, M: Integrator<P> + ?Sized>(
        problem: &P,
        method: &M,
        runs: Vec<Run>,
    ) -> Result<Batch> {
        Batch::build(runs, |n, dt| method.batch_stepper(problem, dt, n))
    }

    fn build(
        runs: Vec<Run>,
        make: impl Fn(usize, f64) -> Option<Result<Box<dyn BatchStepper>>>,
    ) -> Result<Batch> {
        let mut lanes = Vec::with_capacity(runs.len().div_ceil(GROUP));
        for chunk in runs.chunks(GROUP) {
            let lead = &chunk[0];
            let together = chunk.iter().all(|r| {
                r.clock == lead.clock
                    && r.save_every == lead.save_every
                    && r.retract == lead.retract
                    && r.at.is_none()
                    && r.ended.is_none()
            });
            let block = match make(chunk.len(), lead.clock.dt).filter(|_| together) {
                None => None,
                Some(stepper) => {
                    let mut stepper = stepper?;
                    for (j, run) in chunk.iter().enumerate() {
                        stepper.set(j, &run.buf)?;
                    }
                    Some(Lanes {
                        stepper,
                        live: vec![true; chunk.len()],
                    })
                }
            };
            lanes.push(block);
        }
        Ok(Batch { runs, lanes })
    }

    /// The number of members.
    pub fn len(&self) -> usize {
        self.runs.len()
    }

    /// Whether the batch has no member.
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Whether some members are stepped in blocks (a batch stepper is in use).
    pub fn in_lanes(&self) -> bool {
        self.lanes.iter().any(Option::is_some)
    }

    /// The members' runs, for their clocks, times and checked states. [`Run::state`] of a
    /// member in a block is not current (it is the checked state): read the current state with
    /// [`Batch::state`].
    pub fn runs(&self) -> &[Run] {
        &self.runs
    }

    /// The members' runs, to advance them one by one (output times, events, shortened steps):
    /// every member in a block first goes on with a one-member stepper that continues it
    /// exactly ([`BatchStepper::detach`]); the batch steps no block after that.
    pub fn runs_mut(&mut self) -> Result<&mut [Run]> {
        for (slot, runs) in self.lanes.iter_mut().zip(self.runs.chunks_mut(GROUP)) {
            leave_lanes(slot, runs)?;
        }
        Ok(&mut self.runs)
    }

    /// The current state of member `i` (user frame), as [`Run::state`].
    pub fn state<P: Problem + ?Sized>(&self, problem: &P, i: usize) -> Vec<f64> {
        let run = &self.runs[i];
        match &self.lanes[i / GROUP] {
            Some(l) if l.live[i % GROUP] => {
                let mut z = run.buf.clone();
                l.stepper.get(i % GROUP, &mut z);
                problem.to_user(&mut z);
                z
            }
            _ => run.state(problem),
        }
    }

    /// The current states of all members (user frame), as [`Batch::state`], one after the
    /// other, computed in parallel by groups on the current rayon pool.
    pub fn states<P: Problem + ?Sized>(&mut self, problem: &P) -> Vec<f64> {
        let dim = problem.space().dim();
        let mut all = vec![0.0; self.runs.len() * dim];
        all.par_chunks_mut((GROUP * dim).max(1))
            .zip(self.runs.par_chunks_mut(GROUP))
            .zip(self.lanes.par_iter_mut())
            .for_each(|((all, runs), lanes)| {
                for (j, (z, run)) in all.chunks_exact_mut(dim).zip(&*runs).enumerate() {
                    match lanes {
                        Some(l) if l.live[j] => {
                            z.copy_from_slice(&run.buf);
                            l.stepper.get(j, z);
                        }
                        _ => {
                            z.copy_from_slice(&run.buf);
                            run.stepper.get(z);
                        }
                    }
                    problem.to_user(z);
                }
            });
        all
    }

    /// Advances every member by `steps` steps as [`Run::advance`] does, appending member i's
    /// saved states to `outs[i]`; member i's result is what its `Run::advance` would return
    /// (the error names its failing step; the caller names the member). Groups run in parallel
    /// on the current rayon pool.
    pub fn advance<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        steps: u64,
        outs: &mut [Vec<f64>],
    ) -> Vec<Result<usize>> {
        assert_eq!(outs.len(), self.runs.len(), "one output per member");
        let groups: Vec<Vec<Result<usize>>> = self
            .runs
            .par_chunks_mut(GROUP)
            .zip(outs.par_chunks_mut(GROUP))
            .zip(self.lanes.par_iter_mut())
            .map(|((runs, outs), lanes)| {
                if runs.iter().any(|r| r.at.is_some() || r.ended.is_some()) {
                    // Not a block's work (runs_mut() lets no such run stay in a block).
                    if let Err(e) = leave_lanes(lanes, runs) {
                        return runs.iter().map(|_| Err(e.clone())).collect();
                    }
                }
                match lanes {
                    Some(l) => advance_lanes(l, runs, problem, steps, outs),
                    None => runs
                        .par_iter_mut()
                        .zip(outs.par_iter_mut())
                        .map(|(run, out)| run.advance(problem, steps, out))
                        .collect(),
                }
            })
            .collect();
        groups.into_iter().flatten().collect()
    }
}

/// The runs of one group of [`Batch::start`] (members `first`…) and its block, if any.
fn start_group<P: Problem + ?Sized, Z: AsRef<[f64]>>(
    problem: &P,
    method: &Arc<Resolved>,
    chunk: &[Z],
    first: usize,
    dt: f64,
    save_every: usize,
    t0: f64,
) -> std::result::Result<(Vec<Run>, Option<Lanes>), (usize, Error)> {
    let mut runs = Vec::with_capacity(chunk.len());
    let block = match chunk.len() > 1 && dt.is_finite() && dt > 0.0 {
        true => method
            .batch_stepper(dt, chunk.len())
            .transpose()
            .map_err(|e| (first, e))?,
        false => None,
    };
    let Some(mut stepper) = block else {
        for (j, z) in chunk.iter().enumerate() {
            let run = Run::resolved(problem, method, z.as_ref(), dt, save_every, t0);
            runs.push(run.map_err(|e| (first + j, e))?);
        }
        return Ok((runs, None));
    };
    for (j, z) in chunk.iter().enumerate() {
        let placeholder = || {
            let stepper = Box::new(InBlock) as Box<dyn Stepper>;
            Ok((stepper, method.properties, Some(method.clone())))
        };
        let run = Run::start(problem, z.as_ref(), dt, save_every, t0, true, placeholder)
            .map_err(|e| (first + j, e))?;
        stepper.set(j, &run.buf).map_err(|e| (first + j, e))?;
        runs.push(run);
    }
    let live = vec![true; chunk.len()];
    Ok((runs, Some(Lanes { stepper, live })))
}

/// Ends a group's block: each member still in it goes on with a one-member stepper that
/// continues it exactly.
fn leave_lanes(slot: &mut Option<Lanes>, runs: &mut [Run]) -> Result<()> {
    if let Some(lanes) = slot.take() {
        for (j, run) in runs.iter_mut().enumerate() {
            if lanes.live[j] {
                run.go_alone(lanes.stepper.detach(j)?);
            }
        }
    }
    Ok(())
}

/// [`Batch::advance`] of one group in a block.
fn advance_lanes<P: Problem + ?Sized>(
    lanes: &mut Lanes,
    runs: &mut [Run],
    problem: &P,
    steps: u64,
    outs: &mut [Vec<f64>],
) -> Vec<Result<usize>> {
    let before: Vec<usize> = outs.iter().map(Vec::len).collect();
    let mut results: Vec<Result<()>> = runs.iter().map(|_| Ok(())).collect();
    let was_live = lanes.live.clone();
    // Members that go on alone (they left the block before this call).
    for (j, run) in runs.iter_mut().enumerate() {
        if !lanes.live[j] {
            results[j] = run.advance(problem, steps, &mut outs[j]).map(|_| ());
        }
    }
    let mut end = None;
    if let Some(lead) = lanes.live.iter().position(|&l| l) {
        let start = runs[lead].clock.done;
        match start.checked_add(steps) {
            None => {
                for (j, r) in results.iter_mut().enumerate() {
                    if lanes.live[j] {
                        *r = Err(Error::invalid(
                            "steps",
                            format!("{steps} more steps overflow the step count"),
                        ));
                    }
                }
            }
            Some(e) => {
                end = Some(e);
                step_block(lanes, runs, problem, start, e, outs, &mut results);
            }
        }
    }
    // Members that left the block during this call without an error finish alone.
    if let Some(end) = end {
        for (j, run) in runs.iter_mut().enumerate() {
            if was_live[j] && !lanes.live[j] && results[j].is_ok() && run.clock.done < end {
                let left = end - run.clock.done;
                results[j] = run.advance(problem, left, &mut outs[j]).map(|_| ());
            }
        }
    }
    let dim = runs.first().map_or(1, |r| r.buf.len().max(1));
    results
        .into_iter()
        .zip(outs.iter().zip(before))
        .map(|(r, (o, b))| r.map(|()| (o.len() - b) / dim))
        .collect()
}

/// The block's steps from `start` to `end` for its live members.
#[allow(clippy::too_many_arguments)]
fn step_block<P: Problem + ?Sized>(
    lanes: &mut Lanes,
    runs: &mut [Run],
    problem: &P,
    start: u64,
    end: u64,
    outs: &mut [Vec<f64>],
    results: &mut [Result<()>],
) {
    let mut next = Vec::new();
    let mut done = start;
    while done < end {
        let Some(lead) = lanes.live.iter().position(|&l| l) else {
            return;
        };
        let n = runs[lead].whole_steps(end);
        let clock = runs[lead].clock;
        let stop = done + n;
        if lanes.stepper.advance(n as usize, clock).is_err() {
            // The block failed: every live member goes on alone from its checked state.
            for (j, run) in runs.iter_mut().enumerate() {
                if lanes.live[j] {
                    lanes.live[j] = false;
                    let set = lanes.stepper.detach(j).and_then(|mut s| {
                        s.set(&run.buf)?;
                        run.go_alone(s);
                        Ok(())
                    });
                    if let Err(e) = set {
                        results[j] = Err(e);
                    }
                }
            }
            return;
        }
        for (j, run) in runs.iter_mut().enumerate() {
            if !lanes.live[j] {
                continue;
            }
            next.clone_from(&run.buf);
            lanes.stepper.get(j, &mut next);
            let r = match problem.check_finite(&next) {
                Ok(()) => {
                    run.buf.copy_from_slice(&next);
                    let retracted = run.retract_at(problem, stop);
                    let set = if retracted {
                        lanes.stepper.set(j, &run.buf)
                    } else {
                        Ok(())
                    };
                    set.and_then(|()| run.save(problem, done, stop, end, &mut outs[j]))
                }
                Err(e) => {
                    // The member leaves the block: its own stepper takes the steps again one by
                    // one from the checked state (naming the failing step), or, for a single
                    // step, stands where the block stopped.
                    lanes.live[j] = false;
                    let e = run.non_finite(problem.name(), done, stop, e);
                    match lanes.stepper.detach(j) {
                        Err(d) => Err(d),
                        Ok(s) => {
                            run.go_alone(s);
                            if n > 1 {
                                run.replay(problem, n, e).and_then(|()| {
                                    run.commit(problem, done, stop, end, &mut outs[j])
                                })
                            } else {
                                Err(e)
                            }
                        }
                    }
                }
            };
            if let Err(e) = r {
                if lanes.live[j] {
                    // A save or a retraction failed: the member leaves the block where it is.
                    lanes.live[j] = false;
                    if let Ok(s) = lanes.stepper.detach(j) {
                        run.go_alone(s);
                    }
                }
                results[j] = Err(e);
            }
        }
        done = stop;
    }
}
