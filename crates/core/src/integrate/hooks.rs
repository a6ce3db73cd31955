//! Failures of functions from outside lieflow (user closures, a binding's callables) during a run.
//!
//! Such a function may fail where its caller cannot return the error: a problem kind's kernel
//! (a gradient, a metric) returns plain numbers. It then records the error with [`fail`] and
//! hands NaN to the method. The record is kept per thread (the thread that runs the kernel is
//! the one that steps the run), so two runs on two threads never see each other's failures.
//!
//! A [`super::Run`] of a problem that [`calls_out`](super::Problem::calls_out) steps one step at
//! a time, takes the record after every step ([`take_failure`]) and ends at the first failure:
//! the error is located at its step ([`Failure::located`]), the run's checked state is the one
//! before that step, and no step is ever taken again (the function's side effects happen once).
//! Code that evaluates such a problem outside a run takes the record after the call the same way.

use std::cell::RefCell;

use crate::error::{fmt_num, Error, Result};

thread_local! {
    /// The first failure recorded on this thread and not yet taken.
    static PENDING: RefCell<Option<Error>> = const { RefCell::new(None) };
}

/// Records the failure `e` of a foreign function on this thread (the first one is kept until
/// [`take_failure`]); the caller goes on with a stand-in value (NaN).
pub fn fail(e: Error) {
    PENDING.with(|p| {
        let mut p = p.borrow_mut();
        if p.is_none() {
            *p = Some(e);
        }
    });
}

/// The failure recorded on this thread since the last call, if any (and forgets it).
pub fn take_failure() -> Option<Error> {
    PENDING.with(|p| p.borrow_mut().take())
}

/// Whether a failure is recorded on this thread and not yet taken.
pub fn pending() -> bool {
    PENDING.with(|p| p.borrow().is_some())
}

/// Runs the foreign function `f` for a kernel that cannot return its error: `f`'s error is
/// recorded ([`fail`]); once a failure is pending `f` is not called at all (the step is lost,
/// and the function must not be called again with the NaN its failure left). Returns whether
/// `f` ran and succeeded; the caller then fills its outputs with NaN.
pub fn call(f: impl FnOnce() -> Result<()>) -> bool {
    if pending() {
        return false;
    }
    match f() {
        Ok(()) => true,
        Err(e) => {
            fail(e);
            false
        }
    }
}

/// A failure during a run: the error and where it happened.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    /// The error (as returned or recorded by the function, or the check of its value).
    pub error: Error,
    /// The method's name in the system's catalog ("the method" for a method value).
    pub method: String,
    /// The step (absolute, from the start of the run) in which it failed; 0 for the initial
    /// state (a method that evaluates the system when it is set, e.g. Verlet's first force).
    pub step: u64,
    /// The time at the end of that step (unused for step 0).
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

    /// The error located at its step (an error that names its step already, a solver's or a
    /// domain violation, is returned as it is).
    pub fn located(&self) -> Error {
        let place = self.place();
        let mut e = self.error.clone();
        match &mut e {
            Error::NotConverged { .. } | Error::LeftDomain { .. } | Error::Interrupted { .. } => {}
            Error::Raised { place: p, .. } => *p = place,
            Error::NonFinite { location, .. } => *location = format!("{location}, {place}"),
            Error::InvalidArgument { message, .. } => *message = format!("{message} ({place})"),
            Error::Shape { got, .. } => *got = format!("{got}, {place}"),
            _ => return e.map_what(|what| format!("{what} ({place})")),
        }
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failures_are_located() {
        let f = Failure {
            error: Error::NonFinite {
                what: "the gradient of H".into(),
                location: "dH/dq[0] = NaN".into(),
            },
            method: "gauss4".into(),
            step: 17,
            t: 0.17,
            dt: 0.01,
        };
        let msg = f.located().to_string();
        assert!(msg.contains("dH/dq[0] = NaN, in step 17 of gauss4 (t = 0.17, dt = 0.01)"));
    }

    #[test]
    fn a_failure_is_kept_per_thread_and_taken_once() {
        fail(Error::invalid("a", "first"));
        fail(Error::invalid("b", "second"));
        std::thread::spawn(|| assert_eq!(take_failure(), None))
            .join()
            .unwrap();
        assert_eq!(take_failure(), Some(Error::invalid("a", "first")));
        assert_eq!(take_failure(), None);
    }
}
