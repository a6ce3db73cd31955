//! The driver loop of a [`Run`]: whole steps on the grid in chunks (the finiteness guard, the replay
//! that names a failing step, retraction, saves), and single steps with events, output times and
//! an end time between grid times (shortened steps of the run's method).

use super::events::Events;
use super::method::Clock;
use super::problem::Problem;
use super::run::{too_many, Make, Run, Until, RETRACT_EVERY};
use crate::error::{Error, Result};

impl Run {
    /// The driver: whole steps on the grid, output times, events, and the last shortened step.
    pub(super) fn drive<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        make: Make<'_>,
        until: Until,
        out: &mut Vec<f64>,
        mut events: Option<&mut Events<'_>>,
    ) -> Result<usize> {
        if let Some(t) = self.ended {
            return Err(Error::invalid(
                "steps",
                format!(
                    "the run ended at t = {} (a terminal event or its end time); start a new run \
                     from its final state",
                    crate::error::fmt_num(t)
                ),
            ));
        }
        let before = out.len();
        let (end, finish) = match until {
            Until::Steps(n) => (
                self.clock.done.checked_add(n).ok_or_else(|| {
                    Error::invalid("steps", format!("{n} more steps overflow the step count"))
                })?,
                None,
            ),
            Until::Time(t) => {
                let (k, on_grid) = self.grid_index("t", t)?;
                if k < self.clock.done {
                    return Err(Error::invalid(
                        "t",
                        format!(
                            "expected a time not before the run's current time {}, got {}",
                            crate::error::fmt_num(self.time()),
                            crate::error::fmt_num(t)
                        ),
                    ));
                }
                (k, (!on_grid).then_some(t))
            }
        };
        if let Some(ev) = events.as_deref_mut() {
            if ev.last.is_none() {
                self.user.copy_from_slice(&self.buf);
                problem.to_user(&mut self.user);
                let g = ev.eval_all(self.time(), &self.user)?;
                ev.last = Some(g);
            }
        }
        let now = self.time();
        self.emit_before(problem, make, now, None, out)?;
        while self.clock.done < end {
            if let Some(ev) = events.as_deref_mut() {
                self.one_step(problem, make, None, end, Some(ev), out)?;
                if self.ended.is_some() {
                    break;
                }
            } else {
                let t_next = self.clock.time(1);
                self.emit_before(problem, make, t_next, None, out)?;
                let n = self.whole_steps(end);
                self.steps(problem, n, end, out)?;
                let now = self.time();
                self.emit_before(problem, make, now, None, out)?;
            }
        }
        if let (Some(t), None) = (finish, self.ended) {
            self.one_step(problem, make, Some(t), end, events, out)?;
        }
        Ok((out.len() - before) / self.buf.len())
    }

    /// Steps of size dt from `clock.done` to the next stop: `end`, a save, a retraction or the
    /// grid step at or before the next output time.
    pub(super) fn whole_steps(&self, end: u64) -> u64 {
        let done = self.clock.done;
        let mut stop = end;
        match &self.at {
            None => stop = stop.min((done / self.save_every + 1) * self.save_every),
            Some(o) => {
                if let Some(&t) = o.times.get(o.next) {
                    let (k, _) = self.clock.grid_of(t);
                    stop = stop.min(k.max(done + 1));
                }
            }
        }
        if self.retract {
            stop = stop.min((done / RETRACT_EVERY + 1) * RETRACT_EVERY);
        }
        stop - done
    }

    /// `n` steps of size dt from the checked state (not past a save or a retraction), then
    /// [`Run::commit`]. On an error the steps are taken again one by one from the checked state
    /// so that the error names the failing step and the checked state is the one before it.
    fn steps<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        n: u64,
        end: u64,
        out: &mut Vec<f64>,
    ) -> Result<()> {
        if self.single {
            return self.single_steps(problem, n, end, out);
        }
        let done = self.clock.done;
        let stop = done + n;
        // The one finiteness guard of every method and system: after each chunk (at most
        // RETRACT_EVERY or save_every steps), before the state is retracted, saved or handed on,
        // so a NaN/inf is reported with the step that made it and never passed on as the next
        // chunk's input.
        let r = self.stepper.advance(n as usize, self.clock);
        let mut r = self.failed(r, 0);
        if r.is_ok() {
            self.stepper.get(&mut self.next);
            if let Err(e) = problem.check_finite(&self.next) {
                r = Err(self.non_finite(problem.name(), done, stop, e));
            }
        }
        match r {
            Ok(()) => std::mem::swap(&mut self.buf, &mut self.next),
            Err(e @ Error::Raised { .. }) => return Err(e),
            Err(e) if n > 1 => self.replay(problem, n, e)?,
            Err(e) => return Err(e),
        }
        self.commit(problem, done, stop, end, out)
    }

    /// [`Run::steps`] of a problem that calls out: one step at a time, each checked and
    /// committed; the first failure ends the run with the checked state before its step.
    fn single_steps<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        n: u64,
        end: u64,
        out: &mut Vec<f64>,
    ) -> Result<()> {
        for _ in 0..n {
            let done = self.clock.done;
            let r = self.stepper.advance(1, self.clock);
            self.failed(r, done + 1)?;
            self.stepper.get(&mut self.next);
            if let Err(e) = problem.check_finite(&self.next) {
                return Err(self.non_finite(problem.name(), done, done + 1, e));
            }
            std::mem::swap(&mut self.buf, &mut self.next);
            self.commit(problem, done, done + 1, end, out)?;
        }
        Ok(())
    }

    /// After the error `first` in `n` steps from the checked state: the same steps one at a
    /// time from it. Returns the error of the failing step (the clock and the checked state at
    /// the step before it, the stepper where it stopped), or Ok with the state after the `n`
    /// steps checked (steps that failed together but pass one by one).
    pub(super) fn replay<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        n: u64,
        first: Error,
    ) -> Result<()> {
        let done = self.clock.done;
        if self.stepper.set(&self.buf).is_err() {
            return Err(first);
        }
        for k in 0..n {
            let clock = Clock {
                done: done + k,
                ..self.clock
            };
            let mut r = self.stepper.advance(1, clock);
            if r.is_ok() {
                self.stepper.get(&mut self.next);
                if let Err(e) = problem.check_finite(&self.next) {
                    r = Err(self.non_finite(problem.name(), done + k, done + k + 1, e));
                }
            }
            if let Err(e) = r {
                self.clock.done = done + k;
                return Err(e);
            }
            std::mem::swap(&mut self.buf, &mut self.next);
        }
        Ok(())
    }

    /// The checked state in `buf` is the state at step `stop` (reached from `from`): moves the
    /// clock, retracts, saves.
    pub(super) fn commit<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        from: u64,
        stop: u64,
        end: u64,
        out: &mut Vec<f64>,
    ) -> Result<()> {
        if self.retract_at(problem, stop) {
            let r = self.stepper.set(&self.buf);
            self.failed(r, stop)?;
        }
        self.save(problem, from, stop, end, out)
    }

    /// Moves the clock to `stop` and retracts the checked state when a retraction is due there;
    /// returns whether it did (the stepper must then be set to it).
    pub(super) fn retract_at<P: Problem + ?Sized>(&mut self, problem: &P, stop: u64) -> bool {
        self.clock.done = stop;
        let due = self.retract && stop % RETRACT_EVERY == 0;
        if due {
            problem.space().retract(&mut self.buf);
        }
        due
    }

    /// Saves the checked state at step `stop` (reached from `from`) when it is a saved step,
    /// checking it at `end`.
    pub(super) fn save<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        from: u64,
        stop: u64,
        end: u64,
        out: &mut Vec<f64>,
    ) -> Result<()> {
        let save = self.at.is_none() && stop % self.save_every == 0;
        // The state is checked in the user frame: where it is saved, or in the scratch (the
        // last state of a call, which a member of a block sizes only now).
        let (z, at) = match save {
            true => {
                out.try_reserve(self.buf.len()).map_err(|_| too_many())?;
                let at = out.len();
                (&mut *out, at)
            }
            false if stop == end => {
                self.user.clear();
                (&mut self.user, 0)
            }
            false => return Ok(()),
        };
        z.extend_from_slice(&self.buf);
        problem.to_user(&mut z[at..]);
        if let Err(e) = problem.check_finite(&z[at..]) {
            if save {
                z.truncate(at);
            }
            return Err(self.non_finite(problem.name(), from, stop, e));
        }
        Ok(())
    }

    /// One step with its events: of size dt, or (`finish`) the shortened step to the time
    /// `finish` that ends the run. Saves the output times inside the step (shortened steps from
    /// the state at its start) and ends the run at a terminal event.
    fn one_step<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        make: Make<'_>,
        finish: Option<f64>,
        end: u64,
        events: Option<&mut Events<'_>>,
        out: &mut Vec<f64>,
    ) -> Result<()> {
        let j = self.clock.done;
        let t_j = self.clock.time(0);
        let t_next = match finish {
            None => {
                let r = self.stepper.advance(1, self.clock);
                let mut r = self.failed(r, j + 1);
                if r.is_ok() {
                    self.stepper.get(&mut self.next);
                    if let Err(e) = problem.check_finite(&self.next) {
                        r = Err(self.non_finite(problem.name(), j, j + 1, e));
                    }
                }
                r?;
                self.clock.time(1)
            }
            Some(t) => {
                let z = self.branch(problem, make, t - t_j)?;
                self.next.copy_from_slice(&z);
                t
            }
        };
        // The main stepper has moved to step j + 1; on an error below it goes back to the
        // checked state at step j.
        let stop = match self.events_in_step(problem, make, t_j, t_next, events) {
            Ok(stop) => stop.or_else(|| finish.map(|t| (t, self.next.clone()))),
            Err(e) => {
                self.reset();
                return Err(e);
            }
        };
        if let Some((t_end, z)) = stop {
            let mut user = z.clone();
            problem.to_user(&mut user);
            if let Err(e) = self.emit_before(problem, make, t_end, Some(&user), out) {
                self.reset();
                return Err(e);
            }
            let r = self.stepper.set(&z);
            self.failed(r, j + 1)?;
            self.buf.copy_from_slice(&z);
            self.ended = Some(t_end);
            if self.at.is_none() {
                out.try_reserve(user.len()).map_err(|_| too_many())?;
                out.extend_from_slice(&user);
            }
            return Ok(());
        }
        if let Err(e) = self.emit_before(problem, make, t_next, None, out) {
            self.reset();
            return Err(e);
        }
        std::mem::swap(&mut self.buf, &mut self.next);
        self.commit(problem, j, j + 1, end, out)?;
        let now = self.time();
        self.emit_before(problem, make, now, None, out)
    }

    /// The state (internal frame) one step of size `h` (≥ 0) from the checked state: a stepper
    /// of the run's method built for h. Its errors name the step (steps_done + 1) and the time
    /// it reaches.
    pub(super) fn branch<P: Problem + ?Sized>(
        &self,
        problem: &P,
        make: Make<'_>,
        h: f64,
    ) -> Result<Vec<f64>> {
        use crate::error::fmt_num;
        if h <= 0.0 {
            return Ok(self.buf.clone());
        }
        let make = make.ok_or_else(|| {
            Error::invalid(
                "t_eval",
                "an output time or an event between grid times needs a shortened step: advance \
                 the run with Run::advance_to",
            )
        })?;
        let j = self.clock.done;
        let t_j = self.clock.time(0);
        let mut stepper = make(h)?;
        let r = stepper.set(&self.buf);
        self.failed_at(r, j + 1, t_j + h)?;
        // A clock whose step j + 1 ends at t_j + h (errors name that step and time).
        let clock = Clock {
            t0: t_j - j as f64 * h,
            dt: h,
            done: j,
        };
        let r = stepper.advance(1, clock);
        self.failed_at(r, j + 1, t_j + h)?;
        let mut z = self.buf.clone();
        stepper.get(&mut z);
        if let Err(e) = problem.check_finite(&z) {
            return Err(Error::LeftDomain {
                what: format!("{} state", problem.name()),
                t: t_j + h,
                message: format!(
                    "the shortened step {} (dt = {}, from t = {}) produced a non-finite value \
                     ({e})",
                    j + 1,
                    fmt_num(h),
                    fmt_num(t_j)
                ),
            });
        }
        Ok(z)
    }

    /// Saves the pending output times τ ≤ now (within round-off: the checked state), τ < `hi`
    /// (shortened steps from the checked state) and, when the state at `hi` is given, τ = hi.
    pub(super) fn emit_before<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        make: Make<'_>,
        hi: f64,
        at_hi: Option<&[f64]>,
        out: &mut Vec<f64>,
    ) -> Result<()> {
        let Some(o) = &self.at else {
            return Ok(());
        };
        let now = self.clock.time(0);
        let mut next = o.next;
        while let Some(&t) = self.at.as_ref().and_then(|o| o.times.get(next)) {
            let tol = self.clock.grid_tol(t);
            let z = if t <= now + tol {
                let mut z = self.buf.clone();
                problem.to_user(&mut z);
                z
            } else if t < hi - tol {
                let mut z = self.branch(problem, make, t - now)?;
                problem.to_user(&mut z);
                z
            } else if let (Some(z), true) = (at_hi, t <= hi + tol) {
                z.to_vec()
            } else {
                break;
            };
            if let Err(e) = problem.check_finite(&z) {
                let j = self.clock.done;
                return Err(self.non_finite(problem.name(), j, j + 1, e));
            }
            out.try_reserve(z.len()).map_err(|_| too_many())?;
            out.extend_from_slice(&z);
            next += 1;
            if let Some(o) = self.at.as_mut() {
                o.next = next;
            }
        }
        Ok(())
    }
}
