//! lieflow errors as Python exceptions: `LieflowError` (a `ValueError`) and one subclass per kind.

use pyo3::create_exception;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;

create_exception!(
    lieflow,
    LieflowError,
    PyValueError,
    "Base class of every lieflow error."
);
create_exception!(
    lieflow,
    NotInGroupError,
    LieflowError,
    "An argument is not in the required group (e.g. not a rotation, det ≤ 0)."
);
create_exception!(
    lieflow,
    ShapeError,
    LieflowError,
    "An array has the wrong shape."
);
create_exception!(
    lieflow,
    NonFiniteError,
    LieflowError,
    "An input contains NaN or inf."
);
create_exception!(
    lieflow,
    DegenerateStratumError,
    LieflowError,
    "Coincident singular values where the principal stratum is required."
);
create_exception!(
    lieflow,
    NoUniqueLogError,
    LieflowError,
    "The principal logarithm is not unique (rotation by π)."
);
create_exception!(
    lieflow,
    InvalidArgumentError,
    LieflowError,
    "A scalar argument is out of its domain (dt ≤ 0, steps < 1, …)."
);
create_exception!(
    lieflow,
    UnsupportedMethodError,
    LieflowError,
    "The integration method is not supported by the system."
);
create_exception!(
    lieflow,
    ConvergenceError,
    LieflowError,
    "An iterative solver did not converge."
);
create_exception!(
    lieflow,
    LeftDomainError,
    LieflowError,
    "A trajectory left its configuration space (e.g. det X ≤ 0)."
);

create_exception!(
    lieflow,
    LieflowWarning,
    pyo3::exceptions::PyUserWarning,
    "A warning of lieflow: the reading it chose of ambiguous input, or a setting that makes a \
     result empty or inaccurate; each names what it saw and how to silence it."
);

/// `lieflow.ArgumentTypeError`, a `TypeError` whose message names the argument. pyo3 records the
/// argument an extraction failed on in a note ("while processing 'w'", Python ≥ 3.11) after the
/// error is made, so the name is read from the note when the message is shown. (Defined in
/// Python: with the abi3 feature a native class cannot subclass an exception before 3.12.)
const ARGUMENT_TYPE_ERROR: &std::ffi::CStr = cr#"
class ArgumentTypeError(TypeError):
    """An argument of the wrong type (e.g. a complex or string array where real numbers are
    expected); str() names the argument: "argument 'w': expected ..., got ..."."""

    __module__ = "lieflow"

    def __str__(self):
        message = super().__str__()
        for note in getattr(self, "__notes__", ()):
            if isinstance(note, str) and note.startswith("while processing '"):
                return f"argument {note[len('while processing '):]}: {message}"
        return message


def _lieflow_error_str(self):
    """LieflowError.__str__: an error raised while an argument is read calls it "argument"
    (convert::ARGUMENT); pyo3 notes which one ("while processing 'x'"), and this puts the name
    in: "argument 'x' has the wrong shape: ...", "invalid argument 'n': ..."."""
    message = ValueError.__str__(self)
    if message.startswith(("argument ", "invalid argument:")):
        for note in getattr(self, "__notes__", ()):
            if isinstance(note, str) and note.startswith("while processing '"):
                name = note[len("while processing "):]
                return message.replace("argument", f"argument {name}", 1)
    return message
"#;

static ARGUMENT_TYPE_ERROR_MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();
static ARGUMENT_TYPE_ERROR_TYPE: PyOnceLock<Py<PyType>> = PyOnceLock::new();

fn argument_type_error_module(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    ARGUMENT_TYPE_ERROR_MODULE
        .get_or_try_init(py, || {
            Ok::<_, PyErr>(
                PyModule::from_code(
                    py,
                    ARGUMENT_TYPE_ERROR,
                    c"lieflow/_argument_type_error.py",
                    c"lieflow._argument_type_error",
                )?
                .unbind(),
            )
        })
        .map(|m| m.bind(py))
}

fn argument_type_error_type(py: Python<'_>) -> PyResult<&Py<PyType>> {
    ARGUMENT_TYPE_ERROR_TYPE.get_or_try_init(py, || {
        Ok(argument_type_error_module(py)?
            .getattr("ArgumentTypeError")?
            .cast_into::<PyType>()?
            .unbind())
    })
}

/// An `ArgumentTypeError` (a `TypeError`) with the message `msg`; raised while pyo3 extracts an
/// argument, its message names that argument.
pub fn argument_type_error(py: Python<'_>, msg: String) -> PyErr {
    match argument_type_error_type(py) {
        Ok(t) => PyErr::from_type(t.bind(py).clone(), msg),
        Err(_) => PyTypeError::new_err(msg),
    }
}

/// Rust spellings in core messages and their Python equivalents (advice in the caller's
/// language).
const SPELLINGS: [(&str, &str); 1] = [("check_det = false", "check_det=False")];

/// A Python exception raised by the callable `what` as the core error that carries it
/// ([`lieflow::Error::Raised`]): it travels with the run it ended and [`to_py`] raises it again.
pub fn raised(what: impl Into<String>, e: PyErr) -> lieflow::Error {
    lieflow::Error::Raised {
        what: what.into(),
        place: String::new(),
        payload: lieflow::error::Payload(std::sync::Arc::new(e)),
    }
}

/// `f()`, a native call outside a run that may call Python callables: the first failure a
/// callable recorded on this thread meanwhile ([`lieflow::integrate::hooks`]) is raised in place
/// of the core's result (the NaN it caused), else the result converted.
pub fn checked<T>(f: impl FnOnce() -> lieflow::Result<T>) -> PyResult<T> {
    use lieflow::integrate::hooks::take_failure;
    let _ = take_failure();
    let r = f();
    match take_failure() {
        Some(e) => Err(to_py(e)),
        None => r.py(),
    }
}

/// Issues a `lieflow.LieflowWarning` attributed to the user's line: the innermost Python frame
/// outside the lieflow package, however many of lieflow's own functions lie between (as
/// `warnings.warn(skip_file_prefixes=...)` does from Python 3.12 on).
pub fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    let category = py.get_type::<LieflowWarning>();
    let message = std::ffi::CString::new(message.replace('\0', " "))?;
    PyErr::warn(py, &category, &message, user_level(py).unwrap_or(1))
}

/// The `warnings` stack level of the innermost frame whose module is not lieflow's (1: the frame
/// that called the native function).
fn user_level(py: Python<'_>) -> PyResult<i32> {
    let mut frame = py.import("sys")?.getattr("_getframe")?.call1((0,))?;
    let mut level = 1;
    loop {
        let module: String = (frame.getattr("f_globals")?.get_item("__name__"))
            .and_then(|name| name.extract())
            .unwrap_or_default();
        let back = frame.getattr("f_back")?;
        if !(module == "lieflow" || module.starts_with("lieflow.")) || back.is_none() {
            return Ok(level);
        }
        frame = back;
        level += 1;
    }
}

/// Converts a core error into the matching Python exception (a Python exception carried by
/// [`lieflow::Error::Raised`] is raised again, with a note naming the step of the run it ended).
pub fn to_py(e: lieflow::Error) -> PyErr {
    use lieflow::Error as E;
    if let E::Raised { payload, place, .. } = &e {
        if let Some(err) = payload.0.downcast_ref::<PyErr>() {
            return Python::attach(|py| {
                let err = err.clone_ref(py);
                if !place.is_empty() {
                    let note = format!("lieflow: raised {place}; the run stopped there");
                    // add_note exists from Python 3.11 on.
                    let _ = err.value(py).call_method1("add_note", (note,));
                }
                err
            });
        }
    }
    let msg = SPELLINGS
        .iter()
        .fold(e.to_string(), |m, (rust, python)| m.replace(rust, python));
    match e {
        E::NotInGroup { .. } => NotInGroupError::new_err(msg),
        E::Shape { .. } => ShapeError::new_err(msg),
        E::NonFinite { .. } => NonFiniteError::new_err(msg),
        E::DegenerateStratum { .. } => DegenerateStratumError::new_err(msg),
        E::NoUniqueLog { .. } => NoUniqueLogError::new_err(msg),
        E::InvalidArgument { .. } => InvalidArgumentError::new_err(msg),
        E::UnsupportedMethod { .. } => UnsupportedMethodError::new_err(msg),
        E::NotConverged { .. } => ConvergenceError::new_err(msg),
        E::LeftDomain { .. } => LeftDomainError::new_err(msg),
        E::Interrupted { .. } => pyo3::exceptions::PyKeyboardInterrupt::new_err(msg),
        E::Raised { .. } => pyo3::exceptions::PyRuntimeError::new_err(msg),
    }
}

/// `lieflow::Result<T>` → `PyResult<T>`.
pub trait IntoPy<T> {
    /// Maps the error with [`to_py`].
    fn py(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for lieflow::Result<T> {
    fn py(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    let base = py.get_type::<LieflowError>();
    base.setattr(
        "__str__",
        argument_type_error_module(py)?.getattr("_lieflow_error_str")?,
    )?;
    m.add("LieflowError", base)?;
    m.add("NotInGroupError", py.get_type::<NotInGroupError>())?;
    m.add("ShapeError", py.get_type::<ShapeError>())?;
    m.add("NonFiniteError", py.get_type::<NonFiniteError>())?;
    m.add(
        "DegenerateStratumError",
        py.get_type::<DegenerateStratumError>(),
    )?;
    m.add("NoUniqueLogError", py.get_type::<NoUniqueLogError>())?;
    m.add(
        "InvalidArgumentError",
        py.get_type::<InvalidArgumentError>(),
    )?;
    m.add(
        "UnsupportedMethodError",
        py.get_type::<UnsupportedMethodError>(),
    )?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    m.add("LeftDomainError", py.get_type::<LeftDomainError>())?;
    m.add("LieflowWarning", py.get_type::<LieflowWarning>())?;
    m.add("ArgumentTypeError", argument_type_error_type(py)?.bind(py))?;
    Ok(())
}
