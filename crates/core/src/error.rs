//! The one error type of lieflow.
//!
//! Every fallible public function returns [`Result`]. Messages say what was wrong and what was
//! expected, so that they can be shown to a user unchanged (the Python bindings do exactly that).

/// Everything that can go wrong in lieflow.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A matrix that should lie in a group does not (e.g. ‖RᵀR − I‖ too large, or det ≤ 0).
    #[error("{what} is not in {group}: {defect_name} = {defect:.3e} (tolerance {tol:.1e})")]
    NotInGroup {
        /// The argument, e.g. "R".
        what: String,
        /// The group, e.g. "SO(3)".
        group: String,
        /// What was measured, e.g. "‖RᵀR − I‖_F" or "det X".
        defect_name: String,
        /// The measured defect.
        defect: f64,
        /// The tolerance it was compared with.
        tol: f64,
    },
    /// An array of the wrong shape or size.
    #[error("{what} has the wrong shape: expected {expected}, got {got}")]
    Shape {
        /// The argument.
        what: String,
        /// The expected shape, e.g. "(3, 3)" or "(n, n) with n ≥ 2".
        expected: String,
        /// The shape that was passed.
        got: String,
    },
    /// NaN or ±inf in an input (or produced by a computation that would otherwise return it).
    #[error("{what} contains a non-finite value (NaN or inf) at {location}")]
    NonFinite {
        /// The argument.
        what: String,
        /// Where the first non-finite entry sits, e.g. "(1, 2)".
        location: String,
    },
    /// A function that needs the principal stratum (distinct singular values) got a point off it.
    #[error(
        "{what} needs distinct singular values (the principal stratum, 001 §6.1): the smallest gap \
         a_i − a_(i+1) is {gap:.3e}, below the tolerance {tol:.1e}"
    )]
    DegenerateStratum {
        /// The function or argument.
        what: String,
        /// The smallest gap between consecutive singular values (or the smallest singular value).
        gap: f64,
        /// The tolerance.
        tol: f64,
    },
    /// The principal logarithm is not unique (a rotation by an angle at or near π).
    #[error(
        "the logarithm of {what} is not unique: it contains a rotation by angle {angle:.15} \
         (π = 3.141592653589793, distance {distance:.1e}), at π or within round-off of it, \
         where the logarithms ±θ·axis are equally valid; the principal logarithm needs all \
         rotation angles below π by more than round-off (1e-12)"
    )]
    NoUniqueLog {
        /// The argument.
        what: String,
        /// The offending rotation angle.
        angle: f64,
        /// π − angle.
        distance: f64,
    },
    /// A scalar argument out of its domain (dt ≤ 0, steps < 1, non-positive inertia, …).
    #[error("invalid {what}: {message}")]
    InvalidArgument {
        /// The argument.
        what: String,
        /// What was wrong and what was expected.
        message: String,
    },
    /// A method that the chosen system does not support.
    #[error("method {method:?} is not supported by {system}; supported methods: {supported}")]
    UnsupportedMethod {
        /// The requested method.
        method: String,
        /// The system.
        system: String,
        /// Comma-separated list of the supported methods.
        supported: String,
    },
    /// An iterative solver did not reach its tolerance.
    #[error("{what} did not converge in {iterations} iterations (residual {residual:.3e}, tolerance {tol:.1e})")]
    NotConverged {
        /// The solver.
        what: String,
        /// Iterations taken.
        iterations: usize,
        /// Final residual.
        residual: f64,
        /// Requested tolerance.
        tol: f64,
    },
    /// A simulation left the domain of its configuration space (e.g. det X ≤ 0 in GL+(n)).
    #[error("{what} at t = {}: {message}", fmt_num(*t))]
    LeftDomain {
        /// What left the domain.
        what: String,
        /// Time at which it was detected.
        t: f64,
        /// Explanation.
        message: String,
    },
    /// The computation was interrupted (e.g. by Ctrl-C from Python).
    #[error("interrupted after {steps_done} steps")]
    Interrupted {
        /// Steps completed before the interruption.
        steps_done: usize,
    },
    /// A function from outside lieflow (a binding's callable: a Python function) raised an
    /// error of its own, carried unchanged in `payload` for the binding to raise again.
    #[error("{what} raised an exception{}", if place.is_empty() { String::new() } else { format!(" {place}") })]
    Raised {
        /// The function, e.g. "the value of force `torque`".
        what: String,
        /// Where it was raised in a run ("in step 17 of gauss4 (t = …, dt = …)"), or empty.
        place: String,
        /// The error itself, opaque to lieflow.
        payload: Payload,
    },
}

/// The error of a foreign function inside an [`Error::Raised`]: opaque to lieflow, shared (an
/// error is cloned as it is passed on), equal only to itself.
#[derive(Clone)]
pub struct Payload(pub std::sync::Arc<dyn std::any::Any + Send + Sync>);

impl std::fmt::Debug for Payload {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Payload(..)")
    }
}

impl PartialEq for Payload {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

/// A number for a message: the shortest round-trip form (`0.01`, `123.5`) where that is short,
/// the exponent form (`1e300`, `2.5e-170`) for |x| ≥ 1e7 or |x| < 1e-4, so that huge and tiny
/// values are not printed with hundreds of digits.
pub fn fmt_num(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e7).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Result alias used throughout lieflow.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Shorthand for [`Error::InvalidArgument`].
    pub fn invalid(what: impl Into<String>, message: impl Into<String>) -> Self {
        Error::InvalidArgument {
            what: what.into(),
            message: message.into(),
        }
    }

    /// [`Error::InvalidArgument`] for a result that is not representable in f64: `what` names
    /// the argument, `message` says which quantity overflows (or underflows) and why.
    pub fn overflow(what: impl Into<String>, message: impl std::fmt::Display) -> Self {
        Error::InvalidArgument {
            what: what.into(),
            message: format!("overflow: {message}"),
        }
    }

    /// The same error about member `i` of a batch ("batch member i: " before what it names).
    pub fn in_member(self, i: usize) -> Self {
        self.map_what(|what| format!("batch member {i}: {what}"))
    }

    /// The same error with what it names renamed to `f(what)` (a variant that names nothing,
    /// [`Error::UnsupportedMethod`] or [`Error::Interrupted`], is returned as it is).
    pub fn map_what(mut self, f: impl FnOnce(&str) -> String) -> Self {
        match &mut self {
            Error::NotInGroup { what, .. }
            | Error::Shape { what, .. }
            | Error::NonFinite { what, .. }
            | Error::DegenerateStratum { what, .. }
            | Error::NoUniqueLog { what, .. }
            | Error::InvalidArgument { what, .. }
            | Error::NotConverged { what, .. }
            | Error::LeftDomain { what, .. }
            | Error::Raised { what, .. } => *what = f(what),
            Error::UnsupportedMethod { .. } | Error::Interrupted { .. } => {}
        }
        self
    }

    /// Shorthand for [`Error::Shape`].
    pub fn shape(
        what: impl Into<String>,
        expected: impl Into<String>,
        got: impl Into<String>,
    ) -> Self {
        Error::Shape {
            what: what.into(),
            expected: expected.into(),
            got: got.into(),
        }
    }
}
