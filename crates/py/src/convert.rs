//! numpy ⇄ lieflow conversions. Inputs are accepted as any array-like of real numbers (lists,
//! bool/int/float arrays) and cast to float64; anything else (complex, datetime, strings, objects,
//! ragged lists) is a `TypeError` ([`ArrayIn`]); shapes are checked here and reported as
//! `ShapeError`; finiteness is checked by the core functions.

use std::ops::Deref;

use lieflow::{check, Error, Mat};
use nalgebra::{Matrix3, Vector3};
use numpy::ndarray::{Array1, Array2, ArrayViewD};
use numpy::npyffi::PY_ARRAY_API;
use numpy::{
    AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayDescrMethods, PyArrayDyn,
    PyArrayLikeDyn, PyReadonlyArrayDyn, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyByteArray, PyBytes, PyComplex, PyFloat, PyInt, PyString};
use pyo3::Borrowed;

use crate::errors::{argument_type_error, to_py};

/// Any array-like input of real numbers (bool, int, uint or float data: arrays, lists, scalars),
/// cast to float64; a float64 array is borrowed without a copy. Anything else is refused with a
/// `TypeError` that says what was expected and what came (pyo3 prefixes it with
/// `argument 'name':`): complex (the imaginary part would be lost), datetime/timedelta, str,
/// bytes, object arrays and ragged nested lists. The one extractor of every array argument;
/// derefs to the read-only array (`.as_array()`).
pub struct ArrayIn<'py>(PyArrayLikeDyn<'py, f64, AllowTypeChange>);

impl<'py> Deref for ArrayIn<'py> {
    type Target = PyReadonlyArrayDyn<'py, f64>;

    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

const EXPECTED_REAL: &str = "expected an array-like of real numbers (bool, int or float)";

/// What errors raised while an argument is extracted call it: pyo3 then notes the argument's
/// name ("while processing 'x'") and `LieflowError.__str__` puts it in ("argument 'x' has the
/// wrong shape: …", "invalid argument 'n': …"; see `errors::register`).
pub const ARGUMENT: &str = "argument";

/// numpy dtype kinds cast to float64 without loss of meaning: bool, int, uint, float.
fn real_kind(kind: u8) -> bool {
    matches!(kind, b'b' | b'i' | b'u' | b'f')
}

impl<'a, 'py> FromPyObject<'a, 'py> for ArrayIn<'py> {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        // Fast path, zero-copy: a float64 array. Its size is held to the same limit as every
        // buffer (check::array_size): a broadcast view of 10¹⁰ rows costs nothing to borrow,
        // but every consumer either makes an output as large or reads it whole.
        if let Ok(a) = ob.cast::<PyArrayDyn<f64>>() {
            check::array_size(ARGUMENT, a.shape()).map_err(to_py)?;
            return Ok(ArrayIn(ob.extract()?));
        }
        let py = ob.py();
        let type_name = || {
            ob.get_type()
                .name()
                .map_or_else(|_| "object".to_string(), |n| n.to_string())
        };
        if ob.is_instance_of::<PyString>()
            || ob.is_instance_of::<PyBytes>()
            || ob.is_instance_of::<PyByteArray>()
        {
            return Err(argument_type_error(
                py,
                format!("{EXPECTED_REAL}, got a {}", type_name()),
            ));
        }
        if ob.is_none() {
            return Err(argument_type_error(
                py,
                format!("{EXPECTED_REAL}, got None"),
            ));
        }
        let given_array = ob.cast::<PyUntypedArray>().is_ok();
        // numpy's own reading of the object (np.asarray, no cast), to look at its dtype.
        let array: Bound<'py, PyUntypedArray> = if given_array {
            ob.cast::<PyUntypedArray>()?.to_owned()
        } else {
            // SAFETY: PyArray_FromAny with no requested dtype and no flags is np.asarray(ob); it
            // returns a new reference or NULL with an exception set.
            let ptr = unsafe {
                PY_ARRAY_API.PyArray_FromAny(
                    py,
                    ob.as_ptr(),
                    std::ptr::null_mut(),
                    0,
                    0,
                    0,
                    std::ptr::null_mut(),
                )
            };
            // SAFETY: as above.
            let any = unsafe { Bound::from_owned_ptr_or_err(py, ptr) }.map_err(|e| {
                argument_type_error(
                    py,
                    format!(
                        "{EXPECTED_REAL}, got a {} that numpy cannot read as an array: {}",
                        type_name(),
                        e.value(py)
                    ),
                )
            })?;
            any.cast_into::<PyUntypedArray>()?
        };
        let dtype = array.dtype();
        if !real_kind(dtype.kind()) {
            let what = if given_array {
                format!("an array of dtype {}", dtype.str()?)
            } else if dtype.kind() == b'O' {
                format!(
                    "a {} that is ragged or holds non-numbers (numpy reads it as dtype object)",
                    type_name()
                )
            } else {
                format!(
                    "a {} (numpy reads it as dtype {})",
                    type_name(),
                    dtype.str()?
                )
            };
            return Err(argument_type_error(
                py,
                format!("{EXPECTED_REAL}, got {what}"),
            ));
        }
        // The float64 copy of a non-float64 array (e.g. an int broadcast view of 10¹⁰ rows) is
        // checked like every other buffer (check::array_size) before it is made, not left to
        // numpy's MemoryError.
        check::array_size(ARGUMENT, array.shape()).map_err(to_py)?;
        Ok(ArrayIn(array.as_any().extract()?))
    }
}

impl<'py> ArrayIn<'py> {
    /// Extracts the argument `what` from `ob` outside pyo3's argument parsing (e.g. one part of
    /// a tuple), naming it the way pyo3 does: a note "while processing 'what'" on the error,
    /// which an `ArgumentTypeError`'s message repeats.
    pub fn named(what: &str, ob: &Bound<'py, PyAny>) -> PyResult<Self> {
        ob.extract().inspect_err(|e: &PyErr| {
            let note = format!("while processing '{what}'");
            // add_note exists from Python 3.11 on; without it the message stays unnamed.
            let _ = e.value(ob.py()).call_method1("add_note", (note,));
        })
    }
}

/// A shape as numpy prints it: "(3,)", "(2, 3)".
pub fn shape_str(shape: &[usize]) -> String {
    let s: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    if s.len() == 1 {
        format!("({},)", s[0])
    } else {
        format!("({})", s.join(", "))
    }
}

fn shape_err(what: &str, expected: &str, v: &ArrayViewD<'_, f64>) -> PyErr {
    to_py(Error::shape(what, expected, shape_str(v.shape())))
}

/// The entries of `v` in row-major order, in a buffer that is size-checked and allocated
/// fallibly ([`check::zeros`]): the one place inputs are copied, so a huge (e.g. broadcast)
/// input is an `InvalidArgumentError` naming `what`, never an abort.
pub fn read_all(what: &str, v: &ArrayViewD<'_, f64>) -> PyResult<Vec<f64>> {
    let mut data = check::zeros(what, v.shape()).map_err(to_py)?;
    match v.as_slice() {
        Some(c) => data.copy_from_slice(c),
        None => data.iter_mut().zip(v.iter()).for_each(|(d, x)| *d = *x),
    }
    Ok(data)
}

/// An r×c matrix from row-major data (an item of `crate::items`).
pub fn to_mat(r: usize, c: usize, x: &[f64]) -> Mat {
    Mat::from_fn(r, c, |i, j| x[i * c + j])
}

/// Matrices written row-major one after another into `out` (an item's outputs in
/// `crate::items`); a result of another size than `out` is an error, never a panic.
pub fn put_mats(out: &mut [f64], mats: &[&Mat]) -> lieflow::Result<()> {
    let len: usize = mats.iter().map(|a| a.nrows() * a.ncols()).sum();
    if len != out.len() {
        return Err(Error::invalid(
            "result",
            format!("{len} entries where the output item has {}", out.len()),
        ));
    }
    let mut k = 0;
    for a in mats {
        for i in 0..a.nrows() {
            for j in 0..a.ncols() {
                out[k] = a[(i, j)];
                k += 1;
            }
        }
    }
    Ok(())
}

/// A 2-D array as a matrix (at most [`check::MAX_DENSE_ENTRIES`] entries).
pub fn mat(what: &str, a: &ArrayIn<'_>) -> PyResult<Mat> {
    let v = a.as_array();
    if v.ndim() != 2 {
        return Err(shape_err(what, "a 2-D array (n, n)", &v));
    }
    let (r, c) = (v.shape()[0], v.shape()[1]);
    check::dense_size(what, r, c).map_err(to_py)?;
    Ok(to_mat(r, c, &read_all(what, &v)?))
}

/// A 1-D array.
pub fn vector(what: &str, a: &ArrayIn<'_>) -> PyResult<Vec<f64>> {
    let v = a.as_array();
    if v.ndim() != 1 {
        return Err(shape_err(what, "a 1-D array", &v));
    }
    read_all(what, &v)
}

/// A 3-vector.
pub fn vec3(what: &str, a: &ArrayIn<'_>) -> PyResult<Vector3<f64>> {
    let v = a.as_array();
    if v.shape() != [3] {
        return Err(shape_err(what, "(3,)", &v));
    }
    Ok(Vector3::new(v[[0]], v[[1]], v[[2]]))
}

/// Matrix → 2-D numpy array.
pub fn py_mat<'py>(py: Python<'py>, m: &Mat) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]).into_pyarray(py)
}

/// Slice → 1-D numpy array.
pub fn py_vec<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
    Array1::from(v.to_vec()).into_pyarray(py)
}

/// 3×3 matrix → numpy.
pub fn py_mat3<'py>(py: Python<'py>, m: &Matrix3<f64>) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((3, 3), |(i, j)| m[(i, j)]).into_pyarray(py)
}

// ---------------------------------------------------------------- scalars and small arrays

const EXPECTED_NUMBER: &str = "expected a real number (bool, int or float)";

/// The name of `ob`'s type, for messages.
fn type_name(ob: &Bound<'_, PyAny>) -> String {
    ob.get_type()
        .name()
        .map_or_else(|_| "object".to_string(), |n| n.to_string())
}

/// A real number argument: a Python or numpy bool, int or float, or a 0-d array of one. The one
/// extractor of every `f64` parameter. Refused with an `ArgumentTypeError` naming the argument:
/// complex numbers (numpy's `__float__` would drop the imaginary part), strings, bytes, None,
/// arrays of other than one element, datetime and other non-numbers; an int too large for a
/// float is an `InvalidArgumentError`. NaN and inf pass (finiteness is the core's check).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Real(pub f64);

impl<'a, 'py> FromPyObject<'a, 'py> for Real {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        // Fast path: float and its subclasses (np.float64).
        if let Ok(f) = ob.cast::<PyFloat>() {
            return Ok(Real(f.value()));
        }
        let py = ob.py();
        let ob = ob.to_owned();
        if ob.is_instance_of::<PyBool>() {
            return Ok(Real(if ob.is_truthy()? { 1.0 } else { 0.0 }));
        }
        if ob.is_instance_of::<PyInt>() {
            return ob.extract::<f64>().map(Real).map_err(|_| {
                to_py(Error::invalid(
                    ARGUMENT,
                    "an int too large for a float (about ±1.8e308)",
                ))
            });
        }
        let refuse =
            |what: String| argument_type_error(py, format!("{EXPECTED_NUMBER}, got {what}"));
        if ob.is_none() {
            return Err(refuse("None".into()));
        }
        if ob.is_instance_of::<PyString>()
            || ob.is_instance_of::<PyBytes>()
            || ob.is_instance_of::<PyByteArray>()
            || ob.is_instance_of::<PyComplex>()
        {
            return Err(refuse(format!("a {}", type_name(&ob))));
        }
        // numpy scalars and arrays: look at numpy's reading (np.asarray, no cast).
        let is_numpy = ob.cast::<PyUntypedArray>().is_ok()
            || ob
                .get_type()
                .module()
                .is_ok_and(|m| m.to_string().starts_with("numpy"));
        if is_numpy {
            // SAFETY: np.asarray(ob) (no dtype, no flags): a new reference or NULL with an
            // exception set.
            let ptr = unsafe {
                PY_ARRAY_API.PyArray_FromAny(
                    py,
                    ob.as_ptr(),
                    std::ptr::null_mut(),
                    0,
                    0,
                    0,
                    std::ptr::null_mut(),
                )
            };
            // SAFETY: as above.
            let any = unsafe { Bound::from_owned_ptr_or_err(py, ptr) }?;
            let array = any.cast_into::<PyUntypedArray>()?;
            let dtype = array.dtype();
            if !real_kind(dtype.kind()) {
                return Err(refuse(format!(
                    "a {} of dtype {}",
                    type_name(&ob),
                    dtype.str()?
                )));
            }
            if array.ndim() != 0 {
                return Err(refuse(format!(
                    "an array of shape {}",
                    shape_str(array.shape())
                )));
            }
            return Ok(Real(array.call_method0("item")?.extract::<f64>()?));
        }
        // Other numbers (Fraction, Decimal, …) through __float__; anything else is refused.
        ob.extract::<f64>()
            .map(Real)
            .map_err(|_| refuse(format!("a {}", type_name(&ob))))
    }
}

/// Reads a fixed-shape array argument (a point (N,), a matrix (R, C)) through [`ArrayIn`]; a
/// wrong shape is a `ShapeError` naming the argument.
fn fixed<const N: usize>(ob: Borrowed<'_, '_, PyAny>, shape: &[usize]) -> PyResult<[f64; N]> {
    let a: ArrayIn<'_> = ob.extract()?;
    let v = a.as_array();
    if v.shape() != shape {
        return Err(shape_err(ARGUMENT, &shape_str(shape), &v));
    }
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(v.iter()) {
        *o = *x;
    }
    Ok(out)
}

/// A fixed-length vector argument (a point x of a surface, a 3-vector), read like every array
/// ([`ArrayIn`]: complex, strings, None refused); a wrong length is a `ShapeError` naming the
/// argument.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reals<const N: usize>(pub [f64; N]);

impl<'a, 'py, const N: usize> FromPyObject<'a, 'py> for Reals<N> {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        fixed::<N>(ob, &[N]).map(Reals)
    }
}

/// A fixed-shape R×C matrix argument, read like [`Reals`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RealMatrix<const R: usize, const C: usize>(pub [[f64; C]; R]);

impl<'a, 'py, const R: usize, const C: usize> FromPyObject<'a, 'py> for RealMatrix<R, C> {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let a: ArrayIn<'_> = ob.extract()?;
        let v = a.as_array();
        if v.shape() != [R, C] {
            return Err(shape_err(ARGUMENT, &shape_str(&[R, C]), &v));
        }
        let mut out = [[0.0; C]; R];
        for (i, row) in out.iter_mut().enumerate() {
            for (j, o) in row.iter_mut().enumerate() {
                *o = v[[i, j]];
            }
        }
        Ok(RealMatrix(out))
    }
}

/// An integer argument (a count, a size, an index): a Python or numpy int (a bool is refused
/// by the parameters that say so, not here). Refused: floats, strings, None and the like
/// (`ArgumentTypeError`); an int outside i64 is an `InvalidArgumentError` naming the argument
/// (not an `OverflowError`). The range of the parameter is the core's (or the binding's) check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Int(pub i64);

impl<'a, 'py> FromPyObject<'a, 'py> for Int {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let py = ob.py();
        let ob = ob.to_owned();
        // Integers are what has __index__ (int, numpy ints, bool).
        let index = ob.call_method0("__index__").map_err(|_| {
            argument_type_error(py, format!("expected an int, got a {}", type_name(&ob)))
        })?;
        index.extract::<i64>().map(Int).map_err(|_| {
            to_py(Error::invalid(
                ARGUMENT,
                format!(
                    "{} is out of range (at most {} in magnitude)",
                    index
                        .str()
                        .map_or_else(|_| "the int".into(), |s| s.to_string()),
                    i64::MAX
                ),
            ))
        })
    }
}

// The extractors of `#[pyo3(from_py_with = …)]` parameters: the parameters keep their Rust
// types (`f64`, `[f64; N]`, `i64`, …) and their literal defaults (shown in the signature), and
// are read by the newtypes above, so every number of the public API is read in one place.

/// `f64` parameters ([`Real`]).
pub fn real(ob: &Bound<'_, PyAny>) -> PyResult<f64> {
    ob.extract::<Real>().map(|r| r.0)
}

/// `Option<f64>` parameters: None or a [`Real`].
pub fn real_opt(ob: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    if ob.is_none() {
        Ok(None)
    } else {
        real(ob).map(Some)
    }
}

/// `(f64, f64)` parameters (a range): a pair of [`Real`]s.
pub fn real_pair(ob: &Bound<'_, PyAny>) -> PyResult<(f64, f64)> {
    let [a, b] = reals::<2>(ob)?;
    Ok((a, b))
}

/// `[f64; N]` parameters ([`Reals`]).
pub fn reals<const N: usize>(ob: &Bound<'_, PyAny>) -> PyResult<[f64; N]> {
    ob.extract::<Reals<N>>().map(|r| r.0)
}

/// `Option<[f64; N]>` parameters: None or [`Reals`].
pub fn reals_opt<const N: usize>(ob: &Bound<'_, PyAny>) -> PyResult<Option<[f64; N]>> {
    if ob.is_none() {
        Ok(None)
    } else {
        reals::<N>(ob).map(Some)
    }
}

/// `[[f64; C]; R]` parameters ([`RealMatrix`]).
pub fn real_matrix<const R: usize, const C: usize>(
    ob: &Bound<'_, PyAny>,
) -> PyResult<[[f64; C]; R]> {
    ob.extract::<RealMatrix<R, C>>().map(|m| m.0)
}

/// `Vec<f64>` parameters: a 1-D array-like of real numbers ([`ArrayIn`]).
pub fn real_vec(ob: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let a: ArrayIn<'_> = ob.extract()?;
    vector(ARGUMENT, &a)
}

/// `i64` parameters ([`Int`]).
pub fn int(ob: &Bound<'_, PyAny>) -> PyResult<i64> {
    ob.extract::<Int>().map(|i| i.0)
}

/// `Option<i64>` parameters: None or an [`Int`].
pub fn int_opt(ob: &Bound<'_, PyAny>) -> PyResult<Option<i64>> {
    if ob.is_none() {
        Ok(None)
    } else {
        int(ob).map(Some)
    }
}

/// `usize` parameters: an [`Int`] ≥ 0 (a negative one is an `InvalidArgumentError`).
pub fn size(ob: &Bound<'_, PyAny>) -> PyResult<usize> {
    let i = int(ob)?;
    usize::try_from(i).map_err(|_| {
        to_py(Error::invalid(
            ARGUMENT,
            format!("expected an int ≥ 0, got {i}"),
        ))
    })
}

/// `Option<usize>` parameters: None or a [`size`].
pub fn size_opt(ob: &Bound<'_, PyAny>) -> PyResult<Option<usize>> {
    if ob.is_none() {
        Ok(None)
    } else {
        size(ob).map(Some)
    }
}

/// Names the argument `what` on an error of reading it outside pyo3's argument parsing (a part
/// of an argument, a callable's value), the way pyo3 names a parameter: a note
/// "while processing 'what'" that `ArgumentTypeError` and `LieflowError` messages show.
pub fn named<T>(what: &str, r: PyResult<T>) -> PyResult<T> {
    r.inspect_err(|e| {
        Python::attach(|py| {
            let note = format!("while processing '{what}'");
            // add_note exists from Python 3.11 on; without it the message stays unnamed.
            let _ = e.value(py).call_method1("add_note", (note,));
        })
    })
}
