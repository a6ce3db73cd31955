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
//!   `save_every`-th state; [`integrate`] and [`integrate_batch`] (rayon) are built on it.
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

pub mod method;
pub mod methods;
pub mod problem;
pub mod space;

pub use method::{Catalog, Clock, Entry, Integrator, Properties, Stepper, System};
pub use problem::Problem;
pub use space::{Block, Space};

use crate::check;
use crate::error::{Error, Result};
use rayon::prelude::*;

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

/// An integration in progress: one stepper, one clock, states validated once.
///
/// The run does not hold the problem (so that it can live in a Python object next to an
/// `Arc<dyn System>`); every call takes it again, and it must be the one the run was made for.
pub struct Run {
    stepper: Box<dyn Stepper>,
    retract: Option<space::Space>,
    save_every: u64,
    clock: Clock,
    buf: Vec<f64>,
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
        Run::start(system, z0, dt, save_every, t0, || {
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
        Run::start(problem, z0, dt, save_every, t0, || {
            Ok((method.stepper(problem, dt)?, method.properties()))
        })
    }

    /// Validates the arguments and the state once, then builds the stepper and sets its state.
    fn start<P: Problem + ?Sized>(
        problem: &P,
        z0: &[f64],
        dt: f64,
        save_every: usize,
        t0: f64,
        stepper: impl FnOnce() -> Result<(Box<dyn Stepper>, Properties)>,
    ) -> Result<Run> {
        check_run(dt, save_every, t0)?;
        check_state(problem, z0)?;
        let (mut stepper, properties) = stepper()?;
        let space = problem.space();
        let mut buf = z0.to_vec();
        problem.to_internal(&mut buf);
        stepper.set(&buf)?;
        Ok(Run {
            stepper,
            retract: (properties.manifold && space.is_curved()).then_some(space),
            save_every: save_every as u64,
            clock: Clock { t0, dt, done: 0 },
            buf,
        })
    }

    /// Steps done so far.
    pub fn steps_done(&self) -> u64 {
        self.clock.done
    }

    /// The current time t₀ + steps_done·dt.
    pub fn time(&self) -> f64 {
        self.clock.time(0)
    }

    /// The current state (user frame).
    pub fn state<P: Problem + ?Sized>(&self, problem: &P) -> Vec<f64> {
        let mut z = self.buf.clone();
        self.stepper.get(&mut z);
        problem.to_user(&mut z);
        z
    }

    /// Advances by `steps` steps, appending to `out` the state (user frame) at every step number
    /// (counted from the start of the run) that is a multiple of `save_every`. Returns how many
    /// states were appended. Stops with [`Error::LeftDomain`] (naming the absolute time) when the
    /// state becomes non-finite or leaves the problem's domain.
    pub fn advance<P: Problem + ?Sized>(
        &mut self,
        problem: &P,
        steps: u64,
        out: &mut Vec<f64>,
    ) -> Result<usize> {
        let end = self.clock.done + steps;
        let mut saved = 0;
        while self.clock.done < end {
            let done = self.clock.done;
            let next_save = (done / self.save_every + 1) * self.save_every;
            let mut stop = end.min(next_save);
            if self.retract.is_some() {
                stop = stop.min((done / RETRACT_EVERY + 1) * RETRACT_EVERY);
            }
            self.stepper.advance((stop - done) as usize, self.clock)?;
            // The one finiteness guard of every method and system: after each chunk (at most
            // RETRACT_EVERY or save_every steps), before the state is retracted, saved or
            // handed on, so a NaN/inf is reported with the steps that made it and never
            // passed on as the next chunk's input.
            self.stepper.get(&mut self.buf);
            if let Err(e) = check::finite_slice("state", &self.buf) {
                return Err(self.non_finite(problem.name(), done, stop, e));
            }
            self.clock.done = stop;
            if let Some(space) = &self.retract {
                if stop % RETRACT_EVERY == 0 {
                    space.retract(&mut self.buf);
                    self.stepper.set(&self.buf)?;
                }
            }
            if stop % self.save_every == 0 || stop == end {
                problem.to_user(&mut self.buf);
                if let Err(e) = check::finite_slice("state", &self.buf) {
                    return Err(self.non_finite(problem.name(), done, stop, e));
                }
                if stop % self.save_every == 0 {
                    out.try_reserve(self.buf.len()).map_err(|_| too_many())?;
                    out.extend_from_slice(&self.buf);
                    saved += 1;
                }
                problem.to_internal(&mut self.buf);
            }
        }
        Ok(saved)
    }
}

impl Run {
    /// The error of the finiteness guard: the state after steps `done + 1 ..= stop` (absolute
    /// step numbers) is not finite. The clock stays at `done`, the last finite state.
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

/// Integrates many initial states in parallel (rayon), each exactly as [`integrate`] would.
///
/// `threads`: `None` uses rayon's global pool (all cores); `Some(n)` a pool of n threads. Every
/// input is validated before any work starts; an error names the batch member.
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
    let runs = states0
        .iter()
        .enumerate()
        .map(|(i, z)| Run::new(system, method, z, dt, save_every, 0.0).map_err(|e| e.in_member(i)))
        .collect::<Result<Vec<_>>>()?;
    with_threads(threads, || {
        runs.into_par_iter()
            .zip(states0.par_iter())
            .enumerate()
            .map(|(i, (run, z0))| collect(system, run, z0, steps).map_err(|e| e.in_member(i)))
            .collect()
    })
}
