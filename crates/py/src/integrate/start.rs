//! Setting up a run: `Integration::start` (every argument checked once, the members started on
//! the run's threads) and its output times (`save_times`).

use std::sync::{Arc, Mutex};

use lieflow::integrate::{with_threads, Batch, Clock, Resolved, System};
use lieflow::{check, Error};
use pyo3::prelude::*;

use super::drive::of_member;
use super::{args, Integration};
use crate::errors::{to_py, IntoPy};

/// The most worker threads a run may ask for (a pool of 10¹² threads would never finish
/// starting).
const MAX_THREADS: usize = 1024;

impl Integration {
    /// Starts one run per member of `states` (b members' full states one after the other: the
    /// system's state, with its attitude appended where given) with the method `resolved` (the name `method`, None for
    /// the default), every argument checked once, and the states saved at
    /// `t_eval` when given (then checked against the run: not before t₀, not after the end
    /// t₀ + steps·dt).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn start(
        sys: Arc<dyn System>,
        states: Vec<f64>,
        batched: bool,
        attitude: usize,
        dt: f64,
        resolved: lieflow::Result<Arc<Resolved>>,
        method: Option<&str>,
        save_every: u64,
        t0: f64,
        threads: Option<usize>,
        steps: Option<u64>,
        first_member: Option<usize>,
        t_eval: Option<Vec<f64>>,
    ) -> PyResult<Self> {
        let calls_out = sys.calls_out();
        let threads = if calls_out { Some(1) } else { threads };
        if let Some(n) = threads.filter(|&n| n > MAX_THREADS) {
            return Err(to_py(Error::invalid(
                "threads",
                format!("at most {MAX_THREADS} worker threads, got {n}"),
            )));
        }
        let method = resolved.as_ref().map_or(method.unwrap_or(""), |m| m.name);
        let full = sys.space().dim();
        let d = full - attitude * attitude;
        let members: Vec<&[f64]> = states.chunks_exact(full.max(1)).collect();
        let b = members.len();
        let save = usize::try_from(save_every).unwrap_or(usize::MAX);
        // Each member's run keeps its state several times (buffer, stepper state, scratch) and a
        // few hundred bytes more: about 64 + 8·d floats measured; check twice that against the
        // memory available before building any (a huge batch is refused, not killed).
        check::array_size("state0", &[b, 2 * (64 + 8 * full)]).py()?;
        // The whole trajectory the caller will keep: (b, steps / save_every + 1, full) floats,
        // refused before the first step when it cannot be held (with t_eval, `save_at` checks
        // the states it keeps).
        if let (Some(steps), None) = (steps, &t_eval) {
            let saved = usize::try_from(steps / save_every + 1).unwrap_or(usize::MAX);
            check::array_size("steps", &[b, saved, full]).map_err(|e| match e {
                Error::InvalidArgument { what, message } => to_py(Error::invalid(
                    what,
                    format!(
                        "the {saved} states of the trajectory: {message}; save less often \
                         (save_every)"
                    ),
                )),
                other => to_py(other),
            })?;
        }
        // Set up on the run's threads (members in blocks validated in parallel, the first error
        // kept); a system that calls Python is set up on this thread, which holds the GIL.
        let start = || match &resolved {
            Ok(m) => Batch::resolved(&*sys, m, &members, dt, save, t0),
            Err(_) => Batch::start(&*sys, method, &members, dt, save, t0),
        };
        let runs = if calls_out {
            start()
        } else {
            with_threads(threads, || Ok(start())).py()?
        }
        .map_err(|(i, e)| match i {
            Some(i) => of_member(e, i, b, first_member),
            None => e,
        })
        .py()?;
        if let Ok(m) = &resolved {
            warn_unresolved(&*sys, m, &members, dt)?;
        }
        drop(members);
        let mut run = Integration {
            method: method.to_string(),
            sys,
            calls_out,
            runs: Mutex::new(runs),
            threads,
            d,
            attitude,
            batched,
            save_every,
            t0,
            dt,
            done: 0,
            at: None,
            saved: 0,
            initial: states,
            events: None,
            partial: None,
            first_member,
        };
        if let Some(times) = t_eval {
            let last = times.last().copied();
            run.save_times(times)?;
            if let (Some(steps), Some(last)) = (steps, last) {
                let end = t0 + steps as f64 * dt;
                let c = Clock { t0, dt, done: 0 };
                if last > end + c.grid_tol(end) {
                    return Err(to_py(Error::invalid(
                        "t_eval",
                        format!(
                            "the times must not pass the end t0 + steps * dt = {}, got {}",
                            args::float_repr(end),
                            args::float_repr(last)
                        ),
                    )));
                }
            }
        }
        Ok(run)
    }

    /// The states saved at `times` instead of every `save_every`-th state (see `save_at`).
    pub(super) fn save_times(&mut self, times: Vec<f64>) -> PyResult<()> {
        let full = self.full();
        let batch = self.runs.get_mut().unwrap_or_else(|p| p.into_inner());
        check::array_size("t_eval", &[batch.len(), times.len(), full]).py()?;
        // Output times need the members' own steppers (shortened steps).
        for run in batch.runs_mut().py()?.iter_mut() {
            run.save_at(&times).py()?;
        }
        self.at = Some(times);
        Ok(())
    }
}

/// Rotation per step beyond which a method of finite order resolves the motion badly: a
/// quarter turn (fewer than 4 steps per turn; the errors go like (h·rate)^p).
const MAX_TURN_PER_STEP: f64 = std::f64::consts::FRAC_PI_2;

/// A `LieflowWarning` where a step turns the fastest member by more than
/// [`MAX_TURN_PER_STEP`] rad at the start ([`lieflow::integrate::Problem::rate`]); never for an
/// exact flow.
fn warn_unresolved(
    sys: &dyn System,
    method: &Resolved,
    members: &[&[f64]],
    dt: f64,
) -> PyResult<()> {
    if method.properties.exact {
        return Ok(());
    }
    let rate = members
        .iter()
        .filter_map(|z| sys.rate(z))
        .fold(0.0_f64, f64::max);
    let turn = rate * dt;
    // A rate beyond f64 (a state near overflow) says nothing a step could act on.
    if turn > MAX_TURN_PER_STEP && turn.is_finite() {
        Python::attach(|py| {
            crate::errors::warn(
                py,
                &format!(
                    "dt = {} turns the motion by {} rad per step (rate {} rad per unit time at \
                     the start): beyond a quarter turn per step {} (order {}) resolves it badly \
                     and its errors are no longer small; take dt <= {}",
                    args::float_repr(dt),
                    args::float_repr(significant(turn, 4, false)),
                    args::float_repr(significant(rate, 4, false)),
                    method.name,
                    method.properties.order,
                    args::float_repr(significant(MAX_TURN_PER_STEP / rate, 3, true))
                ),
            )
        })?;
    }
    Ok(())
}

/// x to `digits` significant digits for a message (rounded to nearest, or down with `down`: a
/// step safely below a bound), as the double nearest that decimal, so that its repr is short at
/// any exponent (1.453e+153, not the 1.4530000000000006e+153 of scaling by a power of ten).
fn significant(x: f64, digits: usize, down: bool) -> f64 {
    let decimal = format!("{:.*e}", digits - 1, x);
    let rounded: f64 = decimal.parse().unwrap_or(x);
    if !(down && rounded > x) {
        return rounded;
    }
    let Some((mantissa, exponent)) = decimal.split_once('e') else {
        return rounded;
    };
    let unit = 10f64.powi(1 - digits as i32);
    let lower = mantissa.parse::<f64>().map(|m| m - unit).unwrap_or(x);
    format!("{lower:.*}e{exponent}", digits - 1)
        .parse()
        .unwrap_or(x)
}
