//! Locating the events of a run ([`super::events`]) on the method's own trajectory: after each
//! step the event functions are evaluated; a sign change is solved for the shortened step size
//! by Brent's method, the state at the zero being a state of the method.

use super::events::{Events, Hit};
use super::problem::Problem;
use super::run::{Make, Run};
use crate::error::Result;

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
        if let Err(e) = problem.check_finite(&self.user) {
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
