//! The one clock of a run: which step a stepper is taking and at what time, and the errors that
//! name them (a [`Violation`] of the domain found in a step, a solver that did not converge).

use crate::convergence::Failed;
use crate::error::Error;

/// The one clock of a run: the time t₀ of step 0, the step size and the steps already done.
/// Steppers name absolute times in their errors through it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clock {
    /// Time of step 0 of the whole run.
    pub t0: f64,
    /// The step size.
    pub dt: f64,
    /// Steps done before the current call of
    /// [`Stepper::advance`](crate::integrate::Stepper::advance).
    pub done: u64,
}

impl Clock {
    /// The time after `k` more steps.
    pub fn time(&self, k: usize) -> f64 {
        self.t0 + (self.done + k as u64) as f64 * self.dt
    }

    /// Round-off of grid times near `t`: 8ε·max(|t|, |t₀|).
    pub fn grid_tol(&self, t: f64) -> f64 {
        8.0 * f64::EPSILON * t.abs().max(self.t0.abs())
    }

    /// The grid step k with t₀ + k·dt = t within round-off (true) or t₀ + k·dt < t < t₀ +
    /// (k+1)·dt (false); k = 0 for t ≤ t₀.
    pub fn grid_of(&self, t: f64) -> (u64, bool) {
        let time = |k: u64| self.t0 + k as f64 * self.dt;
        let tol = self.grid_tol(t);
        let x = ((t - self.t0) / self.dt).floor();
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

    /// The error for a domain violation found during step `k + 1` of this call (k steps done).
    pub fn left_domain(&self, k: usize, v: Violation) -> Error {
        let step = self.done + k as u64 + 1;
        Error::LeftDomain {
            what: v.what,
            t: self.time(k + 1),
            message: format!(
                "{} (found in step {step}, dt = {})",
                v.message,
                crate::error::fmt_num(self.dt)
            ),
        }
    }

    /// The error for an implicit solve of step `k + 1` of this call that failed under the
    /// [`crate::convergence`] rule with tolerance `tol` (its last update is above it, or not
    /// finite: the iteration does not contract at this step size).
    pub fn not_converged(&self, k: usize, what: &str, failed: Failed, tol: f64) -> Error {
        Error::NotConverged {
            what: format!(
                "{what} in step {} (t = {}, dt = {}; reduce dt)",
                self.done + k as u64 + 1,
                crate::error::fmt_num(self.time(k + 1)),
                crate::error::fmt_num(self.dt)
            ),
            iterations: failed.iterations,
            residual: failed.residual,
            tol,
        }
    }
}

/// A state found outside the domain of a problem during a step (det X ≤ 0, a coordinate
/// singularity, …); the method turns it into [`crate::Error::LeftDomain`] with the time.
#[derive(Clone, Debug, PartialEq)]
pub struct Violation {
    /// What left the domain.
    pub what: String,
    /// Why, and what to do about it (in words that suit every caller).
    pub message: String,
}

impl Violation {
    /// The error for a state handed to a stepper (not reached by a step) outside the domain.
    pub fn at_start(self) -> crate::Error {
        crate::Error::invalid("state", format!("{}: {}", self.what, self.message))
    }
}
