//! Events of a run: event functions g(t, z), located on the method's own trajectory by
//! shortened steps (Brent's method on the step size), never by interpolation.

use super::problem::Problem;
use super::run::{Make, Run};
use crate::check;
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

    pub(super) fn eval_all(&mut self, t: f64, z: &[f64]) -> Result<Vec<f64>> {
        (0..self.events.len()).map(|i| self.eval(i, t, z)).collect()
    }
}

/// Whether g going from `a` to `b` over a step is an event of the given direction.
fn crosses(a: f64, b: f64, direction: f64) -> bool {
    let up = a < 0.0 && b >= 0.0;
    let down = a > 0.0 && b <= 0.0;
    (up && direction >= 0.0) || (down && direction <= 0.0)
}

impl Run {
    /// The events of the step from the checked state (time `t_j`) to `next` (time `t_next`):
    /// located, recorded, and the time and state (internal frame) of a terminal one.
    pub(super) fn events_in_step<P: Problem + ?Sized>(
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
}
