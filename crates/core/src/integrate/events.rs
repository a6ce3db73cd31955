//! Events of a run: event functions g(t, z), located on the method's own trajectory by
//! shortened steps (Brent's method on the step size), never by interpolation.

use crate::error::{Error, Result};

/// The function g(t, z) of an [`Event`].
type EventFn<'a> = Box<dyn FnMut(f64, &[f64]) -> Result<f64> + Send + 'a>;

/// An event function g(t, z) of a run (scipy's `solve_ivp(events=…)`): its zeros are located
/// on the run's trajectory; z is a state in the user frame.
pub struct Event<'a> {
    pub(super) g: EventFn<'a>,
    pub(super) direction: f64,
    pub(super) terminal: u64,
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

/// The event functions of a run and what they found (passed to every
/// [`crate::integrate::Run::advance_to`] of the run; located by the run, see `integrate/locate.rs`).
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
    pub(super) events: Vec<Event<'a>>,
    pub(super) tol: f64,
    pub(super) last: Option<Vec<f64>>,
    pub(super) counts: Vec<u64>,
    pub(super) stopped_by: Option<usize>,
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
    pub(super) fn eval(&mut self, i: usize, t: f64, z: &[f64]) -> Result<f64> {
        let g = (self.events[i].g)(t, z)?;
        if !g.is_finite() {
            return Err(Error::NonFinite {
                what: format!("the value of event function {i}"),
                location: format!("t = {} (it returned {g})", crate::error::fmt_num(t)),
            });
        }
        Ok(g)
    }

    pub(super) fn eval_all(&mut self, t: f64, z: &[f64]) -> Result<Vec<f64>> {
        (0..self.events.len()).map(|i| self.eval(i, t, z)).collect()
    }
}
