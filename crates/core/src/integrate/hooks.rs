//! What a run of user functions needs from its stepper: where a function failed ([`Failure`],
//! kept in a [`FailureLog`] the bindings read) and the context the functions run in
//! ([`Session`]: the Python bindings hold the GIL for a whole call of a stepper).

use std::sync::{Arc, Mutex};

use crate::error::{fmt_num, Error};

/// A user function's failure during a run: its error and where it happened.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    /// The function's error (as returned by it, or the check of its value).
    pub error: Error,
    /// The method's name in the system's catalog.
    pub method: &'static str,
    /// The step (absolute, from the start of the run) in which it failed; 0 for the initial
    /// state (a method that evaluates the system when it is set, e.g. Verlet's first force).
    pub step: u64,
    /// The time at the end of that step (NaN for step 0: a stepper is set before it knows t₀).
    pub t: f64,
    /// The step size.
    pub dt: f64,
}

impl Failure {
    /// "in step k of METHOD (t = …, dt = …)", or "at the initial state of METHOD".
    pub fn place(&self) -> String {
        if self.step == 0 {
            format!("at the initial state of {}", self.method)
        } else {
            format!(
                "in step {} of {} (t = {}, dt = {})",
                self.step,
                self.method,
                fmt_num(self.t),
                fmt_num(self.dt)
            )
        }
    }

    /// The error located at its step.
    pub fn located(&self) -> Error {
        let place = self.place();
        let mut e = self.error.clone();
        match &mut e {
            Error::NonFinite { location, .. } => *location = format!("{location}, {place}"),
            Error::InvalidArgument { message, .. } | Error::LeftDomain { message, .. } => {
                *message = format!("{message} ({place})")
            }
            Error::Shape { got, .. } => *got = format!("{got}, {place}"),
            _ => return e.map_what(|what| format!("{what} ({place})")),
        }
        e
    }
}

/// The first [`Failure`] of a system's user functions in its runs (shared by the system and every
/// stepper made from it); bindings read it to say where a run stopped.
#[derive(Debug, Default)]
pub struct FailureLog(Mutex<Option<Failure>>);

impl FailureLog {
    /// The recorded failure, if any (and forget it).
    pub fn take(&self) -> Option<Failure> {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).take()
    }

    /// Keeps `f` unless a failure is already kept.
    pub fn record(&self, f: Failure) {
        let mut slot = self.0.lock().unwrap_or_else(|p| p.into_inner());
        if slot.is_none() {
            *slot = Some(f);
        }
    }
}

/// Runs its argument inside whatever context the functions need: a binding to an interpreter
/// enters it once around a whole call of a stepper instead of once per function call (the
/// Python bindings hold the GIL for the chunk, which on a worker thread saves creating and
/// destroying a thread state per call, ~7 µs).
pub type Session = Arc<dyn Fn(&mut dyn FnMut()) + Send + Sync>;
