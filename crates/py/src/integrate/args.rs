//! The arguments of a run as `lieflow.integrate` passes them on, read and checked here once, in
//! its words: a TypeError for a wrong type, an InvalidArgumentError for a wrong value.

use lieflow::Error;
use numpy::{PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyInt, PyString};

use crate::errors::to_py;

/// An argument as given (`from_py_with`): read in the order of `lieflow.integrate`'s checks,
/// not in pyo3's order of parameters, and with its words.
pub(crate) fn given<'py>(ob: &Bound<'py, PyAny>) -> PyResult<Option<Bound<'py, PyAny>>> {
    Ok(Some(ob.clone()))
}

fn type_name(ob: &Bound<'_, PyAny>) -> String {
    ob.get_type()
        .name()
        .map_or_else(|_| "object".to_string(), |n| n.to_string())
}

/// `repr(ob)`, cut to `max` characters (Python's `{ob!r:.60}`).
fn repr(ob: &Bound<'_, PyAny>, max: usize) -> String {
    let r = ob
        .repr()
        .map_or_else(|_| "?".to_string(), |r| r.to_string());
    r.chars().take(max).collect()
}

/// `repr(v)` of a float, as Python prints it.
pub(crate) fn float_repr(v: f64) -> String {
    Python::attach(|py| repr(PyFloat::new(py, v).as_any(), usize::MAX))
}

/// An integer ≥ 1 (≤ 2⁶³ − 1): an int or what has `__index__`, bools refused.
pub(crate) fn count(name: &str, ob: &Bound<'_, PyAny>) -> PyResult<u64> {
    let py = ob.py();
    let bad = || {
        PyTypeError::new_err(format!(
            "invalid {name}: expected an integer >= 1, got {} {}",
            type_name(ob),
            repr(ob, usize::MAX)
        ))
    };
    if ob.is_instance_of::<PyBool>() {
        return Err(bad());
    }
    let n = if ob.is_exact_instance_of::<PyInt>() {
        ob.clone()
    } else {
        py.import("operator")?
            .call_method1("index", (ob,))
            .map_err(|e| {
                if e.is_instance_of::<PyTypeError>(py) {
                    bad()
                } else {
                    e
                }
            })?
    };
    let invalid = |m: String| to_py(Error::invalid(name, m));
    match n.extract::<i64>() {
        Ok(v) if v >= 1 => Ok(v as u64),
        Ok(v) => Err(invalid(format!("expected an integer >= 1, got {v}"))),
        Err(_) if n.gt(0)? => Err(invalid(format!(
            "expected an integer <= 2**63 - 1, got {}",
            n.str()?
        ))),
        Err(_) => Err(invalid(format!(
            "expected an integer >= 1, got {}",
            n.str()?
        ))),
    }
}

/// [`count`] of an optional argument (None: not given).
pub(crate) fn count_opt(name: &str, ob: Option<&Bound<'_, PyAny>>) -> PyResult<Option<u64>> {
    match ob.filter(|o| !o.is_none()) {
        Some(o) => count(name, o).map(Some),
        None => Ok(None),
    }
}

/// A real number (bool excluded) or a 0-d numeric array, as a float; None for anything else.
fn real(ob: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    if let Ok(f) = ob.cast::<PyFloat>() {
        return Ok(Some(f.value()));
    }
    if ob.is_instance_of::<PyBool>() {
        return Ok(None);
    }
    let py = ob.py();
    let real = ob.is_instance_of::<PyInt>()
        || ob.is_instance(&py.import("numbers")?.getattr("Real")?)?
        || ob
            .cast::<PyUntypedArray>()
            .is_ok_and(|a| a.ndim() == 0 && matches!(a.dtype().kind(), b'i' | b'u' | b'f'));
    if !real {
        return Ok(None);
    }
    Ok(Some(py.get_type::<PyFloat>().call1((ob,))?.extract()?))
}

/// The time step: a real number, finite and > 0.
pub(crate) fn step(ob: &Bound<'_, PyAny>) -> PyResult<f64> {
    let Some(dt) = real(ob)? else {
        return Err(PyTypeError::new_err(format!(
            "invalid dt: expected a real number > 0, got {} {}",
            type_name(ob),
            repr(ob, usize::MAX)
        )));
    };
    if !(0.0 < dt && dt < f64::INFINITY) {
        let got = float_repr(dt);
        return Err(to_py(Error::invalid(
            "dt",
            format!("expected a finite number > 0, got {got}"),
        )));
    }
    Ok(dt)
}

/// A time: a real number, finite.
pub(crate) fn time(name: &str, ob: &Bound<'_, PyAny>) -> PyResult<f64> {
    let Some(t) = real(ob)? else {
        return Err(PyTypeError::new_err(format!(
            "invalid {name}: expected a real number, got {} {}",
            type_name(ob),
            repr(ob, 60)
        )));
    };
    if !t.is_finite() {
        let got = float_repr(t);
        return Err(to_py(Error::invalid(
            name,
            format!("expected a finite number, got {got}"),
        )));
    }
    Ok(t)
}

/// A method's name, or None for the system's default.
pub(crate) fn method(ob: &Bound<'_, PyAny>) -> PyResult<Option<String>> {
    if ob.is_none() {
        return Ok(None);
    }
    match ob.cast::<PyString>() {
        Ok(s) => Ok(Some(s.to_cow()?.into_owned())),
        Err(_) => Err(PyTypeError::new_err(format!(
            "invalid method: expected a name (str), got {} {}",
            type_name(ob),
            repr(ob, usize::MAX)
        ))),
    }
}

/// The initial attitudes (n×n group elements) of `b` members, (b·n²) values: one (n, n)
/// shared by a batch, or one per member (b, n, n) of a batch; real numbers only (the rule of
/// every array argument), finite (a NaN named by its member and its entry).
pub(crate) fn attitude(
    ob: &Bound<'_, PyAny>,
    b: usize,
    batched: bool,
    n: usize,
) -> PyResult<Vec<f64>> {
    let check_shape = |shape: &[usize]| {
        if shape == [n, n] || batched && shape == [b, n, n] {
            return Ok(());
        }
        let want = if batched {
            format!("({n}, {n}) or ({b}, {n}, {n})")
        } else {
            format!("({n}, {n})")
        };
        Err(to_py(Error::shape(
            "attitude",
            want,
            crate::convert::shape_str(shape),
        )))
    };
    // A float64 array is read in place; anything else through numpy.asarray.
    let read = ob
        .cast::<numpy::PyArrayDyn<f64>>()
        .ok()
        .and_then(|a| a.try_readonly().ok());
    let (shape, flat) = match read {
        Some(v) => {
            let v = v.as_array();
            check_shape(v.shape())?;
            (v.shape().to_vec(), v.iter().copied().collect::<Vec<f64>>())
        }
        None => as_float_array(ob, check_shape)?,
    };
    if let Some(k) = flat.iter().position(|v| !v.is_finite()) {
        let (m, e) = (k / (n * n), k % (n * n));
        let what = if shape.len() == 3 {
            format!("batch member {m}: attitude")
        } else {
            "attitude".to_string()
        };
        return Err(to_py(Error::NonFinite {
            what,
            location: format!("({}, {})", e / n, e % n),
        }));
    }
    Ok(if shape.len() == 2 {
        flat.repeat(b)
    } else {
        flat
    })
}

/// `ob` through numpy.asarray as (shape, row-major float64 entries): a TypeError unless
/// real numbers (bool, int or float); the shape checked by `check_shape` before reading.
fn as_float_array(
    ob: &Bound<'_, PyAny>,
    check_shape: impl Fn(&[usize]) -> PyResult<()>,
) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let py = ob.py();
    let expected = "invalid attitude: expected an array-like of real numbers (bool, int or float)";
    let np = py.import("numpy")?;
    let a = np.call_method1("asarray", (ob,)).map_err(|e| {
        if e.is_instance_of::<pyo3::exceptions::PyValueError>(py) {
            PyTypeError::new_err(format!(
                "{expected}, got a {} that numpy cannot read as an array: {}",
                type_name(ob),
                e.value(py)
            ))
        } else {
            e
        }
    })?;
    let arr = a.cast::<PyUntypedArray>()?;
    let text = ob.is_instance_of::<PyString>() || ob.is_instance_of::<pyo3::types::PyBytes>();
    if text || !matches!(arr.dtype().kind(), b'b' | b'i' | b'u' | b'f') {
        return Err(PyTypeError::new_err(format!(
            "{expected}, got a {} (numpy dtype {})",
            type_name(ob),
            arr.dtype().str()?
        )));
    }
    let shape = arr.shape().to_vec();
    check_shape(&shape)?;
    let flat = np
        .call_method1("ascontiguousarray", (a, "float64"))?
        .call_method0("ravel")?
        .extract::<Vec<f64>>()?;
    Ok((shape, flat))
}
