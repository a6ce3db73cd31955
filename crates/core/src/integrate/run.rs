//! Structure-preserving integration: state spaces, problem kinds, methods as values, and the one
//! driver that owns time.
//!
//! - [`space`]: a state is one flat vector cut into named blocks ([`Space`]: ℝᵏ, SO(3), S², n×n
//!   matrices, so(n)*) with membership checks, retraction and named views;
//! - [`problem`]: the kinds a system can implement ([`problem::VectorField`], [`problem::Split`],
//!   [`problem::Separable`], [`problem::Canonical`], [`problem::Constrained`],
//!   [`problem::Nonholonomic`], [`problem::GroupField`], [`problem::Symmetric`]);
//! - [`methods`]: one file per method family, each generic over the kind it needs;
//! - [`method`]: the [`Integrator`] and [`Stepper`] traits, each system's [`Catalog`] of named
//!   methods, and [`System`], any catalogued problem as a trait object;
//! - this module: the driver. A [`Run`] validates once, owns the clock and the stepper for the
//!   whole run (callers that work in chunks resume the same run), retracts curved blocks every
//!   [`RETRACT_EVERY`] steps for methods that keep the manifold, and saves every
//!   `save_every`-th state, or the states at given times ([`Run::save_at`]); it locates
//!   [`Events`] and ends at a time ([`Until::Time`]), off its grid always by a shortened step of
//!   the method, never by interpolation; [`integrate`] and [`integrate_batch`] (rayon) are built
//!   on it.
//!
//! ```
//! use lieflow::integrate::{integrate, Problem};
//! use lieflow::systems::RigidBody;
//! let body = RigidBody::new([1.0, 2.0, 3.0])?;
//! let traj = integrate(&body, "splitting4", &[1.0, 0.5, -0.3], 1e-2, 1000, 100)?;
//! assert_eq!(traj.len(), 11);
//! let (h0, h1) = (body.energy(traj.state(0))?, body.energy(traj.state(10))?);
//! assert!((h1 - h0).abs() < 1e-9);
//! # Ok::<(), lieflow::Error>(())
//! ```

pub mod batch;
pub mod clock;
pub mod forcing;
pub mod hooks;
pub mod method;
pub mod methods;
pub mod problem;
pub mod space;

pub use batch::Batch;
pub use method::{BatchStepper, Catalog, Clock, Entry, Integrator, Properties, Stepper, System};
pub use problem::Problem;
pub use space::{Block, Space};

use crate::check;
use crate::error::{Error, Result};

/// Steps between two retractions of the curved blocks (SO(3), S²) of a state. A retraction moves
/// the state by round-off (‖RᵀR − I‖ ~ 1e-15) and keeps the rounding errors of many products of
/// rotations from accumulating (without it ‖RᵀR − I‖ reaches ~6e-12 after 10⁶ steps).
pub const RETRACT_EVERY: u64 = 256;

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

/// How far [`Run::advance_to`] goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Until {
    /// This many more steps of size dt (fewer when a terminal event ends the run first).
    Steps(u64),
    /// To this time: steps of size dt to the last grid time t₀ + k·dt ≤ t, then, when t lies
    /// between two grid times, one shortened step of size t − (t₀ + k·dt), which ends the run
    /// at t.
    Time(f64),
}

/// The function g(t, z) of an [`Event`].
type EventFn<'a> = Box<dyn FnMut(f64, &[f64]) -> Result<f64> + Send + 'a>;

/// An event function g(t, z) of a run (scipy's `solve_ivp(events=…)`): its zeros are located
/// on the run's trajectory; z is a state in the user frame.
pub struct Event<'a> {
    g: EventFn<'a>,
    direction: f64,
    terminal: u64,
}

impl<'a> Event<'a> {
    /// The event function `g`, not terminal, counted in either direction.
    pub fn new(g: impl FnMut(f64, &[f64]) -> Result<f64> + Send + 'a) -> Self {
        Event {
            g: Box::new(g),
            direction: 0.0,
            terminal: 0,
        }
    }

    /// The run ends at the `count`-th occurrence of this event (0: never; scipy's
    /// `terminal = True` is 1).
    pub fn terminal(mut self, count: u64) -> Self {
        self.terminal = count;
        self
    }

    /// Only zeros where g increases (`direction` > 0: from g < 0 to g ≥ 0) or decreases (< 0);
    /// 0 counts both, as in scipy.
    pub fn direction(mut self, direction: f64) -> Self {
        self.direction = direction;
        self
    }
}

/// A located event: the zero of event function `event` at time `t`, with the state there
/// (user frame), found in step `step` (absolute, counted from the start of the run).
#[derive(Clone, Debug, PartialEq)]
pub struct Hit {
    /// Index of the event function.
    pub event: usize,
    /// The time of the zero.
    pub t: f64,
    /// The state at `t` (user frame): one step of the method, of size t − tⱼ, from the state at
    /// the start tⱼ of the step in which g changed sign.
    pub state: Vec<f64>,
    /// The absolute number of that step.
    pub step: u64,
}

/// The event functions of a run and what they found (passed to every [`Run::advance_to`] of
/// the run).
///
/// After every step the functions are evaluated on the new state; where one changes sign (in
/// its direction) between two steps, its zero is located on the method's own trajectory: the
/// step from the state at its start tⱼ is taken again with shortened sizes h ∈ (0, dt) and
/// g(tⱼ + h, Φ_h(zⱼ)) is solved for h by Brent's method (bisection, secant and inverse
/// quadratic interpolation) to round-off in t (plus `tol`). No interpolation: the state at an
/// event is a state of the method (it keeps what the method keeps). A value of g exactly 0 at a
/// step is an event at that step (at most once: a start at g = 0 is no event). When several
/// events fall in one step they are reported in time order, and a terminal one drops the later
/// ones.
pub struct Events<'a> {
    events: Vec<Event<'a>>,
    tol: f64,
    last: Option<Vec<f64>>,
    counts: Vec<u64>,
    stopped_by: Option<usize>,
    /// The events located so far, in time order (take them as they are read).
    pub hits: Vec<Hit>,
}

impl<'a> Events<'a> {
    /// The event functions `events`; `tol` ≥ 0: an absolute tolerance in time added to
    /// round-off (0 locates the zeros to round-off).
    ///
    /// Errors: a non-finite or negative `tol`, a non-finite direction ([`Error::InvalidArgument`]).
    pub fn new(events: Vec<Event<'a>>, tol: f64) -> Result<Self> {
        if !(tol.is_finite() && tol >= 0.0) {
            return Err(Error::invalid(
                "event_tol",
                format!("expected a finite tolerance ≥ 0, got {tol}"),
            ));
        }
        if let Some((i, e)) = events
            .iter()
            .enumerate()
            .find(|(_, e)| !e.direction.is_finite())
        {
            return Err(Error::invalid(
                "direction",
                format!(
                    "event {i}: expected a finite number (its sign: > 0 rising, < 0 falling, 0 \
                     both), got {}",
                    e.direction
                ),
            ));
        }
        let n = events.len();
        Ok(Events {
            events,
            tol,
            last: None,
            counts: vec![0; n],
            stopped_by: None,
            hits: Vec::new(),
        })
    }

    /// How many times each event occurred.
    pub fn counts(&self) -> &[u64] {
        &self.counts
    }

    /// The terminal event that ended the run, if one did.
    pub fn stopped_by(&self) -> Option<usize> {
        self.stopped_by
    }

    /// g_i(t, z), checked finite.
    fn eval(&mut self, i: usize, t: f64, z: &[f64]) -> Result<f64> {
        let g = (self.events[i].g)(t, z)?;
        if !g.is_finite() {
            return Err(Error::NonFinite {
                what: format!("the value of event function {i}"),
                location: format!("t = {} (it returned {g})", crate::error::fmt_num(t)),
            });
        }
        Ok(g)
    }

    fn eval_all(&mut self, t: f64, z: &[f64]) -> Result<Vec<f64>> {
        (0..self.events.len()).map(|i| self.eval(i, t, z)).collect()
    }
}

/// Whether g going from `a` to `b` over a step is an event of the given direction.
fn crosses(a: f64, b: f64, direction: f64) -> bool {
    let up = a < 0.0 && b >= 0.0;
    let down = a > 0.0 && b <= 0.0;
    (up && direction >= 0.0) || (down && direction <= 0.0)
}

/// The steppers of a run's shortened steps: its method, built for a step size.
type Make<'m> = Option<&'m dyn Fn(f64) -> Result<Box<dyn Stepper>>>;

/// Output times of a run that saves at given times.
struct Outputs {
    times: Vec<f64>,
    next: usize,
}

/// An integration in progress: one stepper, one clock, states validated once.
///
/// The run does not hold the problem (so that it can live in a Python object next to an
/// `Arc<dyn System>`); every call takes it again, and it must be the one the run was made for.
///
/// A run steps with dt on the grid t₀ + k·dt and saves every `save_every`-th state, or, after
/// [`Run::save_at`], the states at given times. A time between two grid times is reached by one
/// shortened step of the same method from the grid state before it (a step of another size,
/// not an interpolation; the run itself goes on on its grid, so its states do not depend on the
/// output times). Shortened steps need a stepper of another size, which
/// [`Run::advance_to`] builds from the system and the method's name ([`Run::advance_to_with`]
/// from a method value); [`Run::advance`] takes none. Events ([`Events`]) are located the same
/// way.
pub struct Run {
    stepper: Box<dyn Stepper>,
    retract: Option<space::Space>,
    save_every: u64,
    clock: Clock,
    /// The state (internal frame) at `clock.done`, the last that passed the checks.
    buf: Vec<f64>,
    /// Scratch: the state after the steps in progress (internal frame).
    next: Vec<f64>,
    /// Scratch: a state in the user frame.
    user: Vec<f64>,
    /// The method's name (a run of a catalogued system), for shortened steps and errors.
    method: Option<String>,
    /// The problem calls functions from outside lieflow ([`Problem::calls_out`]): one step per
    /// call of the stepper, a failure ends the run at its step, no step is taken twice.
    single: bool,
    at: Option<Outputs>,
    /// The time at which the run ended between grid times (a terminal event, [`Until::Time`]).
    ended: Option<f64>,
}

impl Run {
    /// Starts a run of `system` with its method called `method`, from `z0` (user frame) at time
    /// `t0`, step `dt`, saving every `save_every`-th state.
    ///
    /// Errors: `dt` ≤ 0 or non-finite, `save_every` < 1, non-finite `t0`
    /// ([`Error::InvalidArgument`]); an unknown method ([`Error::UnsupportedMethod`]); a state of
    /// the wrong length, non-finite or off its space or constraints.
    pub fn new<S: System + ?Sized>(
        system: &S,
        method: &str,
        z0: &[f64],
        dt: f64,
        save_every: usize,
        t0: f64,
    ) -> Result<Run> {
        Run::start(system, Some(method), z0, dt, save_every, t0, || {
            system.stepper(method, dt)
        })
    }

    /// Starts a run of `problem` with a method value (see [`Run::new`]).
    pub fn with<P: Problem, M: Integrator<P> + ?Sized>(
        problem: &P,
        method: &M,
        z0: &[f64],
        dt: f64,
        save_every: usize,
        t0: f64,
    ) -> Result<Run> {
        Run::start(problem, None, z0, dt, save_every, t0, || {
            Ok((method.stepper(problem, dt)?, method.properties()))
        })
    }

    /// Validates the arguments and the state once, then builds the stepper and sets its state.
    fn start<P: Problem + ?Sized>(
        problem: &P,
        method: Option<&str>,
        z0: &[f64],
        dt: f64,
        save_every: usize,
        t0: f64,
        stepper: impl FnOnce() -> Result<(Box<dyn Stepper>, Properties)>,
    ) -> Result<Run> {
        check_run(dt, save_every, t0)?;
        check_state(problem, z0)?;
        // A failure recorded on this thread that no caller took belongs to no run.
        let _ = hooks::take_failure();
        let (stepper, properties) = stepper()?;
        let space = problem.space();
        let mut buf = z0.to_vec();
        problem.to_internal(&mut buf);
        let mut run = Run {
            stepper,
            retract: (properties.manifold && space.is_curved()).then_some(space),
            save_every: save_every as u64,
            clock: Clock { t0, dt, done: 0 },
            next: buf.clone(),
            user: buf.clone(),
            method: method.map(str::to_string),
            single: problem.calls_out(),
            at: None,
            ended: None,
            buf,
        };
        let r = run.stepper.set(&run.buf);
        run.failed(r, 0)?;
        Ok(run)
    }

    /// `r`, with a failure a foreign function recorded meanwhile ([`hooks`]) in its place, located
    /// at step `step` (0: the initial state) in a run that steps one step at a time.
    fn failed<T>(&self, r: Result<T>, step: u64) -> Result<T> {
        self.failed_at(r, step, self.clock.t0 + step as f64 * self.clock.dt)
    }

    /// [`Run::failed`] for a step that ends at time `t` (a shortened step).
    fn failed_at<T>(&self, r: Result<T>, step: u64, t: f64) -> Result<T> {
        let e = match (hooks::take_failure(), r) {
            (Some(e), _) => e,
            (None, Ok(v)) => return Ok(v),
            (None, Err(e)) if self.single => e,
            (None, Err(e)) => return Err(e),
        };
        if !self.single {
            // A function of a problem that does not declare it ([`Problem::calls_out`]): its
            // step is not known, and no step is taken again.
            return Err(e);
        }
        let f = hooks::Failure {
            error: e,
            method: self.method.clone().unwrap_or_else(|| "the method".into()),
            step,
            t,
            dt: self.clock.dt,
        };
        Err(f.located())
    }

    /// Sets the stepper back to the checked state after an error (whatever that costs: the run
    /// is over; a failure it records is dropped).
    fn reset(&mut self) {
        let _ = self.stepper.set(&self.buf);
        let _ = hooks::take_failure();
    }

    /// Steps done so far on the grid (after an error: the steps that passed the checks).
    pub fn steps_done(&self) -> u64 {
        self.clock.done
    }

    /// The current time t₀ + steps_done·dt, or the time at which the run ended between grid
    /// times ([`Run::ended`]).
    pub fn time(&self) -> f64 {
        self.ended.unwrap_or(self.clock.time(0))
    }

    /// The time at which the run ended between grid times (a terminal event or
    /// [`Until::Time`]); it then advances no more.
    pub fn ended(&self) -> Option<f64> {
        self.ended
    }

    /// The current state (user frame). After an error it is where the stepper stopped: for a
    /// domain violation the first state found outside (see [`Run::checked_state`]).
    pub fn state<P: Problem + ?Sized>(&self, problem: &P) -> Vec<f64> {
        let mut z = self.buf.clone();
        self.stepper.get(&mut z);
        problem.to_user(&mut z);
        z
    }

    /// The last state that passed the driver's checks (user frame), at [`Run::time`]: the
    /// current state, and after an error of [`Run::advance`] the state before the failing step
    /// (at the step that error names, minus one): where a partial trajectory ends.
    pub fn checked_state<P: Problem + ?Sized>(&self, problem: &P) -> Vec<f64> {
        let mut z = self.buf.clone();
        problem.to_user(&mut z);
        z
    }

    /// Saves the states at the times `times` (strictly increasing, none before the current
    /// time) instead of every `save_every`-th state: one state per time, by a shortened step
    /// from the grid state before it when the time is not a grid time (within round-off,
    /// 8ε·max(|t|, |t₀|)).
    ///
    /// Errors: no time ([`Error::Shape`]), non-finite times ([`Error::NonFinite`]), unsorted
    /// times or one before the current time ([`Error::InvalidArgument`]).
    pub fn save_at(&mut self, times: &[f64]) -> Result<()> {
        use crate::error::fmt_num;
        if times.is_empty() {
            return Err(Error::shape("t_eval", "(k,) with k ≥ 1", "(0,)"));
        }
        check::finite_slice("t_eval", times)?;
        if let Some(i) = times.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::invalid(
                "t_eval",
                format!(
                    "expected strictly increasing times, got t_eval[{}] = {} after {}",
                    i + 1,
                    fmt_num(times[i + 1]),
                    fmt_num(times[i])
                ),
            ));
        }
        let now = self.time();
        if let Some(&first) = times.first() {
            if first < now - self.grid_tol(first) {
                return Err(Error::invalid(
                    "t_eval",
                    format!(
                        "the times must not precede the run's current time {}, got {}",
                        fmt_num(now),
                        fmt_num(first)
                    ),
                ));
            }
        }
        self.at = Some(Outputs {
            times: times.to_vec(),
            next: 0,
        });
        Ok(())
    }

    /// The number of grid steps from the start of the run to the last grid time ≤ `t` (within
    /// round-off, 8ε·max(|t|, |t₀|)).
    ///
    /// Errors: `t` non-finite or before t₀, or beyond 2⁶³ steps ([`Error::InvalidArgument`]).
    pub fn grid_steps(&self, t: f64) -> Result<u64> {
        self.grid_index("t", t).map(|(k, _)| k)
    }

    /// Advances by `steps` steps, appending to `out` the state (user frame) at every step number
    /// (counted from the start of the run) that is a multiple of `save_every`, or, after
    /// [`Run::save_at`], the states at the output times on the grid (a time between grid times
    /// needs a shortened step: [`Run::advance_to`]). Returns how many states were appended.
    ///
    /// Stops with [`Error::LeftDomain`] (naming the absolute step and time) when the state
    /// becomes non-finite or leaves the problem's domain. After an error the run is left where
    /// the stepper stopped ([`Run::state`]); [`Run::checked_state`] is the last state that
    /// passed, at [`Run::steps_done`] (the steps are taken again one by one from the last
    /// checked state to find the failing one).
    pub fn advance<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        steps: u64,
        out: &mut Vec<f64>,
    ) -> Result<usize> {
        self.drive(problem, None, Until::Steps(steps), out, None)
    }

    /// [`Run::advance`] to `until`, with the shortened steps that output times between grid
    /// times, [`Until::Time`] and `events` take (built by `system` with the run's method; the
    /// run must come from [`Run::new`]). Events found are appended to `events.hits`; a terminal
    /// one ends the run at the event ([`Run::ended`], [`Run::state`] the event's state; in a
    /// run that saves every `save_every`-th state the event's state is saved last).
    ///
    /// Errors: those of [`Run::advance`]; an event function's error, or a non-finite value of
    /// one ([`Error::NonFinite`]); an ended run ([`Error::InvalidArgument`]).
    pub fn advance_to<S: System + ?Sized>(
        &mut self,
        system: &S,
        until: Until,
        out: &mut Vec<f64>,
        events: Option<&mut Events<'_>>,
    ) -> Result<usize> {
        let name = self.method.clone();
        let make = |h: f64| match &name {
            Some(m) => system.stepper(m, h).map(|(s, _)| s),
            None => Err(Error::invalid(
                "method",
                "the run was made with a method value (Run::with): take its shortened steps \
                 with Run::advance_to_with",
            )),
        };
        self.drive(system, Some(&make), until, out, events)
    }

    /// [`Run::advance_to`] for a run made with a method value ([`Run::with`]).
    pub fn advance_to_with<P: Problem, M: Integrator<P> + ?Sized>(
        &mut self,
        problem: &P,
        method: &M,
        until: Until,
        out: &mut Vec<f64>,
        events: Option<&mut Events<'_>>,
    ) -> Result<usize> {
        let make = |h: f64| method.stepper(problem, h);
        self.drive(problem, Some(&make), until, out, events)
    }
}

impl Run {
    /// The driver: whole steps on the grid, output times, events, and the last shortened step.
    fn drive<P: Problem + ?Sized>(
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
    fn whole_steps(&self, end: u64) -> u64 {
        let done = self.clock.done;
        let mut stop = end;
        match &self.at {
            None => stop = stop.min((done / self.save_every + 1) * self.save_every),
            Some(o) => {
                if let Some(&t) = o.times.get(o.next) {
                    let (k, _) = self.grid_of(t);
                    stop = stop.min(k.max(done + 1));
                }
            }
        }
        if self.retract.is_some() {
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
            if let Err(e) = check::finite_slice("state", &self.next) {
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
            if let Err(e) = check::finite_slice("state", &self.next) {
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
    fn replay<P: Problem + ?Sized>(&mut self, problem: &P, n: u64, first: Error) -> Result<()> {
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
                if let Err(e) = check::finite_slice("state", &self.next) {
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
    fn commit<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        from: u64,
        stop: u64,
        end: u64,
        out: &mut Vec<f64>,
    ) -> Result<()> {
        if self.retract_at(stop) {
            let r = self.stepper.set(&self.buf);
            self.failed(r, stop)?;
        }
        self.save(problem, from, stop, end, out)
    }

    /// Moves the clock to `stop` and retracts the checked state when a retraction is due there;
    /// returns whether it did (the stepper must then be set to it).
    fn retract_at(&mut self, stop: u64) -> bool {
        self.clock.done = stop;
        match &self.retract {
            Some(space) if stop % RETRACT_EVERY == 0 => {
                space.retract(&mut self.buf);
                true
            }
            _ => false,
        }
    }

    /// Saves the checked state at step `stop` (reached from `from`) when it is a saved step,
    /// checking it at `end`.
    fn save<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        from: u64,
        stop: u64,
        end: u64,
        out: &mut Vec<f64>,
    ) -> Result<()> {
        let save = self.at.is_none() && stop % self.save_every == 0;
        if save || stop == end {
            self.user.copy_from_slice(&self.buf);
            problem.to_user(&mut self.user);
            if let Err(e) = check::finite_slice("state", &self.user) {
                return Err(self.non_finite(problem.name(), from, stop, e));
            }
            if save {
                out.try_reserve(self.user.len()).map_err(|_| too_many())?;
                out.extend_from_slice(&self.user);
            }
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
                    if let Err(e) = check::finite_slice("state", &self.next) {
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

    /// The events of the step from the checked state (time `t_j`) to `next` (time `t_next`):
    /// located, recorded, and the time and state (internal frame) of a terminal one.
    fn events_in_step<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        make: Make<'_>,
        t_j: f64,
        t_next: f64,
        events: Option<&mut Events<'_>>,
    ) -> Result<Option<(f64, Vec<f64>)>> {
        self.user.copy_from_slice(&self.next);
        problem.to_user(&mut self.user);
        if let Err(e) = check::finite_slice("state", &self.user) {
            let j = self.clock.done;
            return Err(self.non_finite(problem.name(), j, j + 1, e));
        }
        let Some(ev) = events else {
            return Ok(None);
        };
        let user = self.user.clone();
        let g_new = ev.eval_all(t_next, &user)?;
        let last = ev.last.clone().unwrap_or_else(|| g_new.clone());
        let mut found = Vec::new();
        for i in 0..g_new.len() {
            if crosses(last[i], g_new[i], ev.events[i].direction) {
                let (h, z) = self.locate(problem, make, ev, i, t_j, t_next, last[i], g_new[i])?;
                found.push((i, if h == t_next - t_j { t_next } else { t_j + h }, z));
            }
        }
        found.sort_by(|a, b| a.1.total_cmp(&b.1));
        ev.last = Some(g_new);
        let step = self.clock.done + 1;
        for (i, t, z) in found {
            let mut state = z.clone();
            problem.to_user(&mut state);
            ev.counts[i] += 1;
            ev.hits.push(Hit {
                event: i,
                t,
                state,
                step,
            });
            let terminal = ev.events[i].terminal;
            if terminal > 0 && ev.counts[i] >= terminal {
                ev.stopped_by = Some(i);
                return Ok(Some((t, z)));
            }
        }
        Ok(None)
    }

    /// The zero of event `i` in the step from the checked state (time `t_j`, g = `ga`) to
    /// `next` (time `t_next`, g = `gb`, opposite sign or 0): Brent's method (zeroin) on the
    /// shortened step size h ∈ [0, t_next − t_j]. Returns h and the state (internal frame).
    #[allow(clippy::too_many_arguments)]
    fn locate<P: Problem + ?Sized>(
        &self,
        problem: &P,
        make: Make<'_>,
        ev: &mut Events<'_>,
        i: usize,
        t_j: f64,
        t_next: f64,
        ga: f64,
        gb: f64,
    ) -> Result<(f64, Vec<f64>)> {
        let len = t_next - t_j;
        if gb == 0.0 {
            return Ok((len, self.next.clone()));
        }
        let xtol = ev.tol;
        let mut evaluated: (f64, Vec<f64>) = (len, self.next.clone());
        let mut phi = |h: f64, ev: &mut Events<'_>| -> Result<f64> {
            let z = self.branch(problem, make, h)?;
            let mut user = z.clone();
            problem.to_user(&mut user);
            let g = ev.eval(i, t_j + h, &user)?;
            evaluated = (h, z);
            Ok(g)
        };
        // zeroin (Brent 1973, ch. 4): b is the best estimate, [b, c] brackets the zero.
        let (mut a, mut fa, mut b, mut fb) = (0.0, ga, len, gb);
        let (mut c, mut fc) = (a, fa);
        let (mut d, mut e) = (b - a, b - a);
        for _ in 0..200 {
            if (fb > 0.0 && fc > 0.0) || (fb < 0.0 && fc < 0.0) {
                c = a;
                fc = fa;
                d = b - a;
                e = d;
            }
            if fc.abs() < fb.abs() {
                a = b;
                b = c;
                c = a;
                fa = fb;
                fb = fc;
                fc = fa;
            }
            let tol1 = 2.0 * f64::EPSILON * (t_j + b).abs().max(len) + 0.5 * xtol;
            let xm = 0.5 * (c - b);
            if xm.abs() <= tol1 || fb == 0.0 {
                break;
            }
            if e.abs() >= tol1 && fa.abs() > fb.abs() {
                let s = fb / fa;
                let (mut p, mut q);
                if a == c {
                    p = 2.0 * xm * s;
                    q = 1.0 - s;
                } else {
                    let qq = fa / fc;
                    let r = fb / fc;
                    p = s * (2.0 * xm * qq * (qq - r) - (b - a) * (r - 1.0));
                    q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
                }
                if p > 0.0 {
                    q = -q;
                } else {
                    p = -p;
                }
                if 2.0 * p < (3.0 * xm * q - (tol1 * q).abs()).min((e * q).abs()) {
                    e = d;
                    d = p / q;
                } else {
                    d = xm;
                    e = d;
                }
            } else {
                d = xm;
                e = d;
            }
            a = b;
            fa = fb;
            b += if d.abs() > tol1 { d } else { tol1.copysign(xm) };
            b = b.clamp(0.0, len);
            fb = phi(b, ev)?;
        }
        if b == evaluated.0 {
            return Ok(evaluated);
        }
        if b == 0.0 {
            return Ok((0.0, self.buf.clone()));
        }
        let z = self.branch(problem, make, b)?;
        Ok((b, z))
    }

    /// The state (internal frame) one step of size `h` (≥ 0) from the checked state: a stepper
    /// of the run's method built for h. Its errors name the step (steps_done + 1) and the time
    /// it reaches.
    fn branch<P: Problem + ?Sized>(&self, problem: &P, make: Make<'_>, h: f64) -> Result<Vec<f64>> {
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
        if let Err(e) = check::finite_slice("state", &z) {
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
    fn emit_before<P: Problem + ?Sized>(
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
            let tol = self.grid_tol(t);
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
            if let Err(e) = check::finite_slice("state", &z) {
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

    /// Round-off of grid times near `t`.
    fn grid_tol(&self, t: f64) -> f64 {
        8.0 * f64::EPSILON * t.abs().max(self.clock.t0.abs())
    }

    /// The grid step k with t₀ + k·dt = t within round-off (true) or t₀ + k·dt < t < t₀ +
    /// (k+1)·dt (false); k = 0 for t ≤ t₀.
    fn grid_of(&self, t: f64) -> (u64, bool) {
        let c = self.clock;
        let time = |k: u64| c.t0 + k as f64 * c.dt;
        let tol = self.grid_tol(t);
        let x = ((t - c.t0) / c.dt).floor();
        let mut k = if x.is_nan() || x <= 0.0 {
            0
        } else if x >= 9.2e18 {
            u64::MAX / 2
        } else {
            x as u64
        };
        for _ in 0..4 {
            if k > 0 && time(k) > t + tol {
                k -= 1;
            }
        }
        for _ in 0..4 {
            if time(k + 1) <= t + tol {
                k += 1;
            }
        }
        (k, (time(k) - t).abs() <= tol)
    }

    /// [`Run::grid_of`] of a time argument `what`, checked (finite, not before t₀, fewer than
    /// 2⁶³ steps away).
    fn grid_index(&self, what: &str, t: f64) -> Result<(u64, bool)> {
        use crate::error::fmt_num;
        if !t.is_finite() {
            return Err(Error::invalid(
                what,
                format!("expected a finite time, got {t}"),
            ));
        }
        let t0 = self.clock.t0;
        if t < t0 - self.grid_tol(t) {
            return Err(Error::invalid(
                what,
                format!("expected a time ≥ t0 = {}, got {}", fmt_num(t0), fmt_num(t)),
            ));
        }
        if (t - t0) / self.clock.dt >= 9.2e18 {
            return Err(Error::invalid(
                what,
                format!(
                    "t = {} is more than 2⁶³ steps of dt = {} from t0 = {}",
                    fmt_num(t),
                    fmt_num(self.clock.dt),
                    fmt_num(t0)
                ),
            ));
        }
        Ok(self.grid_of(t))
    }

    /// The error of the finiteness guard: the state after steps `done + 1 ..= stop` (absolute
    /// step numbers) is not finite.
    fn non_finite(&self, name: &str, done: u64, stop: u64, e: Error) -> Error {
        use crate::error::fmt_num;
        let steps = if stop == done + 1 {
            format!("step {stop}")
        } else {
            format!("one of the steps {} to {stop}", done + 1)
        };
        Error::LeftDomain {
            what: format!("{name} state"),
            t: self.clock.t0 + stop as f64 * self.clock.dt,
            message: format!(
                "{steps} (dt = {}, from t = {}) produced a non-finite value ({e}); the step is \
                 too large for this motion (|dt·ω| beyond the range where rotation angles are \
                 resolved, or an overflow), or the motion blows up",
                fmt_num(self.clock.dt),
                fmt_num(self.clock.t0 + done as f64 * self.clock.dt),
            ),
        }
    }
}

fn too_many() -> Error {
    Error::invalid(
        "save_every",
        "the saved states do not fit in memory; save less often",
    )
}

fn check_run(dt: f64, save_every: usize, t0: f64) -> Result<()> {
    check::positive("dt", dt)?;
    if save_every < 1 {
        return Err(Error::invalid(
            "save_every",
            "expected save_every ≥ 1, got 0",
        ));
    }
    if !t0.is_finite() {
        return Err(Error::invalid(
            "t0",
            format!("expected a finite time, got {t0}"),
        ));
    }
    Ok(())
}

/// The energy of a state with the guard of every observable: a non-finite value of a finite
/// state is not passed on but reported as an overflow naming the system (e.g. ½|P|² beyond the
/// f64 range for a state near 1e160).
pub fn energy_checked<P: Problem + ?Sized>(problem: &P, z: &[f64]) -> Result<f64> {
    let h = problem.energy(z)?;
    if !h.is_finite() {
        return Err(not_representable(problem.name(), "energy", z));
    }
    Ok(h)
}

/// The invariants (Casimirs, momentum maps) of a state with the guard of [`energy_checked`].
pub fn invariants_checked<P: Problem + ?Sized>(problem: &P, z: &[f64]) -> Result<Vec<f64>> {
    let c = problem.invariants(z)?;
    if c.iter().any(|v| !v.is_finite()) {
        return Err(not_representable(problem.name(), "invariants", z));
    }
    Ok(c)
}

fn not_representable(name: &str, what: &str, z: &[f64]) -> Error {
    Error::overflow(
        "state",
        format!(
            "the {what} of this {name} state: beyond the f64 range (largest |entry| {})",
            crate::error::fmt_num(z.iter().fold(0.0f64, |m, v| m.max(v.abs())))
        ),
    )
}

/// Checks a state (user frame) against the problem's space and constraints.
pub fn check_state<P: Problem + ?Sized>(problem: &P, z: &[f64]) -> Result<()> {
    problem.space().check("state", z)?;
    problem.check_state(z)
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
        .zip(finals)
        .map(|(states, final_state)| Trajectory {
            t: t.clone(),
            dim: final_state.len(),
            final_state,
            states,
        })
        .collect())
}
