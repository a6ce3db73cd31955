//! The driver: a [`Run`] validates once, owns the clock and the stepper for the whole run,
//! retracts, saves, takes shortened steps to output times and end times, and guards every chunk.

use super::events::Events;
use std::sync::Arc;

use super::hooks;
use super::method::{Clock, Integrator, Properties, Resolved, Stepper, System};
use super::problem::Problem;
use crate::check;
use crate::error::{Error, Result};

/// Steps between two retractions of the curved blocks (SO(3), S²) of a state. A retraction moves
/// the state by round-off (‖RᵀR − I‖ ~ 1e-15) and keeps the rounding errors of many products of
/// rotations from accumulating (without it ‖RᵀR − I‖ reaches ~6e-12 after 10⁶ steps).
pub const RETRACT_EVERY: u64 = 256;

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

/// The steppers of a run's shortened steps: its method, built for a step size.
pub(super) type Make<'m> = Option<&'m dyn Fn(f64) -> Result<Box<dyn Stepper>>>;

/// Output times of a run that saves at given times.
pub(super) struct Outputs {
    pub(super) times: Vec<f64>,
    pub(super) next: usize,
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
/// [`Run::advance_to`] builds from the run's resolved method ([`Run::advance_to_with`]
/// from a method value); [`Run::advance`] takes none. Events ([`Events`]) are located the same
/// way.
pub struct Run {
    pub(super) stepper: Box<dyn Stepper>,
    /// Whether the driver retracts the state onto its space every [`RETRACT_EVERY`] steps (a
    /// method that keeps the manifold, on a curved space).
    pub(super) retract: bool,
    pub(super) save_every: u64,
    pub(super) clock: Clock,
    /// The state (internal frame) at `clock.done`, the last that passed the checks.
    pub(super) buf: Vec<f64>,
    /// Scratch: the state after the steps in progress (internal frame). Empty while the run is
    /// a member of a block of lanes (the block has its own; [`Run::go_alone`] sizes it).
    pub(super) next: Vec<f64>,
    /// Scratch: a state in the user frame (events, located steps; empty as `next`).
    pub(super) user: Vec<f64>,
    /// The method, resolved once (a run of a catalogued system): shortened steps and errors.
    pub(super) method: Option<Arc<Resolved>>,
    /// The problem calls functions from outside lieflow ([`Problem::calls_out`]): one step per
    /// call of the stepper, a failure ends the run at its step, no step is taken twice.
    pub(super) single: bool,
    pub(super) at: Option<Outputs>,
    /// The time at which the run ended between grid times (a terminal event, [`Until::Time`]).
    pub(super) ended: Option<f64>,
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
        Run::start(system, z0, dt, save_every, t0, false, || {
            let m = system.resolve(method)?;
            Ok((m.stepper(dt)?, m.properties, Some(m)))
        })
    }

    /// [`Run::new`] with a method already resolved ([`System::resolve`]) for `problem`.
    pub fn resolved<P: Problem + ?Sized>(
        problem: &P,
        method: &Arc<Resolved>,
        z0: &[f64],
        dt: f64,
        save_every: usize,
        t0: f64,
    ) -> Result<Run> {
        Run::start(problem, z0, dt, save_every, t0, false, || {
            Ok((method.stepper(dt)?, method.properties, Some(method.clone())))
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
        Run::start(problem, z0, dt, save_every, t0, false, || {
            Ok((method.stepper(problem, dt)?, method.properties(), None))
        })
    }

    /// Validates the arguments and the state once, then builds the stepper and sets its state
    /// (`in_block`: the run of a member of a block of lanes, without scratch of its own).
    pub(super) fn start<P: Problem + ?Sized>(
        problem: &P,
        z0: &[f64],
        dt: f64,
        save_every: usize,
        t0: f64,
        in_block: bool,
        stepper: impl FnOnce() -> Result<(Box<dyn Stepper>, Properties, Option<Arc<Resolved>>)>,
    ) -> Result<Run> {
        // A failure recorded on this thread that no caller took belongs to no run.
        let _ = hooks::take_failure();
        let checked = check_start(problem, z0, dt, save_every, t0);
        // A foreign function the checks called (a state check that evaluates a user's
        // potential) failed: its error, not the NaN it left, and not left for the next run.
        if let Some(e) = hooks::take_failure() {
            return Err(e);
        }
        checked?;
        let (stepper, properties, method) = stepper()?;
        let space = problem.space();
        let mut buf = z0.to_vec();
        problem.to_internal(&mut buf);
        let scratch = || match in_block {
            true => Vec::new(),
            false => vec![0.0; buf.len()],
        };
        let mut run = Run {
            stepper,
            retract: properties.manifold && space.is_curved(),
            save_every: save_every as u64,
            clock: Clock { t0, dt, done: 0 },
            next: scratch(),
            user: scratch(),
            method,
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
    pub(super) fn failed<T>(&self, r: Result<T>, step: u64) -> Result<T> {
        self.failed_at(r, step, self.clock.t0 + step as f64 * self.clock.dt)
    }

    /// [`Run::failed`] for a step that ends at time `t` (a shortened step).
    pub(super) fn failed_at<T>(&self, r: Result<T>, step: u64, t: f64) -> Result<T> {
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
            method: self.method.as_ref().map_or("the method", |m| m.name).into(),
            step,
            t,
            dt: self.clock.dt,
        };
        Err(f.located())
    }

    /// A member leaving its block of lanes goes on with `stepper` (the block's exact copy of it)
    /// and scratch of its own.
    pub(super) fn go_alone(&mut self, stepper: Box<dyn Stepper>) {
        self.stepper = stepper;
        self.next.resize(self.buf.len(), 0.0);
        self.user.resize(self.buf.len(), 0.0);
    }

    /// Sets the stepper back to the checked state after an error (whatever that costs: the run
    /// is over; a failure it records is dropped).
    pub(super) fn reset(&mut self) {
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

    /// [`Run::checked_state`] written to `z` (the state's length) instead of a new vector.
    pub fn checked_state_into<P: Problem + ?Sized>(&self, problem: &P, z: &mut [f64]) {
        z.copy_from_slice(&self.buf);
        problem.to_user(z);
    }

    /// Replaces the current state by `z` (user frame, checked as a run's initial state) and goes
    /// on from it with the same clock, stepper and retraction schedule: a run that restarts its
    /// directions (a tangent lift re-seeded at its own base state, [`crate::analysis::lyapunov`])
    /// keeps the times and steps of one run.
    ///
    /// Errors: those of the initial state of [`Run::new`]; an ended run
    /// ([`Error::InvalidArgument`]).
    pub fn restart_from<P: Problem + ?Sized>(&mut self, problem: &P, z: &[f64]) -> Result<()> {
        if self.ended.is_some() {
            return Err(Error::invalid(
                "run",
                "the run has ended between grid times; it cannot go on",
            ));
        }
        let _ = hooks::take_failure();
        let checked = check_state(problem, z);
        if let Some(e) = hooks::take_failure() {
            return Err(e);
        }
        checked?;
        self.buf.copy_from_slice(z);
        problem.to_internal(&mut self.buf);
        let r = self.stepper.set(&self.buf);
        self.failed(r, self.clock.done)
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
            if first < now - self.clock.grid_tol(first) {
                // A run at its start names t0 (the argument the times are checked against).
                let since = match (self.clock.done, self.ended) {
                    (0, None) => format!("t0 = {}", fmt_num(now)),
                    _ => format!("the run's current time {}", fmt_num(now)),
                };
                return Err(Error::invalid(
                    "t_eval",
                    format!("the times must not precede {since}, got {}", fmt_num(first)),
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
    /// times, [`Until::Time`] and `events` take (built by the run's resolved method; the run
    /// must come from [`Run::new`] or [`Run::resolved`]). Events found are appended to `events.hits`; a terminal
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
        let method = self.method.clone();
        let make = |h: f64| match &method {
            Some(m) => m.stepper(h),
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
    /// [`Clock::grid_of`] of a time argument `what`, checked (finite, not before t₀, fewer than
    /// 2⁶³ steps away).
    pub(super) fn grid_index(&self, what: &str, t: f64) -> Result<(u64, bool)> {
        use crate::error::fmt_num;
        if !t.is_finite() {
            return Err(Error::invalid(
                what,
                format!("expected a finite time, got {t}"),
            ));
        }
        let t0 = self.clock.t0;
        if t < t0 - self.clock.grid_tol(t) {
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
        Ok(self.clock.grid_of(t))
    }

    /// The error of the finiteness guard: the state after steps `done + 1 ..= stop` (absolute
    /// step numbers) is not finite.
    pub(super) fn non_finite(&self, name: &str, done: u64, stop: u64, e: Error) -> Error {
        use crate::error::fmt_num;
        let steps = if stop == done + 1 {
            format!("step {stop}")
        } else {
            format!("one of the steps {} to {stop}", done + 1)
        };
        // A tangent lift's Jacobian beyond the float range while its state is finite
        // (`Problem::check_finite` of the lift names it so): the derivatives outgrew it.
        let derivatives = matches!(&e, Error::NonFinite { what, .. } if what.contains("Jacobian"));
        let why = match derivatives {
            true => {
                "the derivatives outgrew the float range while the state stayed finite (an \
                 unstable motion's exponential growth, or a long run of a fast one); run \
                 shorter, or from a state of smaller scale"
            }
            false => {
                "the step is too large for this motion (|dt·ω| beyond the range where rotation \
                 angles are resolved, or an overflow), or the motion blows up"
            }
        };
        Error::LeftDomain {
            what: format!("{name} state"),
            t: self.clock.t0 + stop as f64 * self.clock.dt,
            message: format!(
                "{steps} (dt = {}, from t = {}) produced a non-finite value ({e}); {why}",
                fmt_num(self.clock.dt),
                fmt_num(self.clock.t0 + done as f64 * self.clock.dt),
            ),
        }
    }
}

pub(super) fn too_many() -> Error {
    Error::invalid(
        "save_every",
        "the saved states do not fit in memory; save less often",
    )
}

/// The checks of [`Run::new`] before its method: the arguments, then the state.
pub(super) fn check_start<P: Problem + ?Sized>(
    problem: &P,
    z0: &[f64],
    dt: f64,
    save_every: usize,
    t0: f64,
) -> Result<()> {
    check_run(dt, save_every, t0)?;
    check_state(problem, z0)
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
