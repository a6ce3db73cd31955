//! The user-defined systems (issue 15): `Canonical`, `Separable` and `LiePoisson`, bindings of
//! `lieflow::systems::user`, whose Hamiltonian is given by Python callables (or, for `LiePoisson`,
//! by a symmetric matrix: the native quadratic path), and `Forced`, any system with a force given
//! by a Python callable; thin subclasses of `lieflow.System`. This file holds what they share:
//! the calling of a user callable (`Callee`) and the argument helpers.
//!
//! The callables are called from the native kernels on the thread that integrates, which holds
//! the GIL (a run of these systems is single-threaded; a batch of states runs member after
//! member). An exception travels as the core's `Error::Raised` (recorded on the thread when the
//! kernel cannot return it, `lieflow::integrate::hooks`): the kernel goes on with NaN, the core
//! ends the run after that step, never taking a step twice, and the exception is re-raised with
//! a note naming the step ("lieflow: raised in step 17 of gauss4 (t = …, dt = …)"). A value of
//! the wrong shape is a `ShapeError`, a non-finite one a `NonFiniteError`, both naming the
//! callable and the step; a value that is not a real array (a string, None) is the
//! `ArgumentTypeError` of reading it, re-raised like an exception. The systems pickle by their
//! constructor arguments (callables by reference: pass module-level functions).
#![allow(non_snake_case)]

pub(crate) mod canonical;
pub(crate) mod euler_poincare;
pub(crate) mod forced;
pub(crate) mod lie_poisson;
pub(crate) mod separable;

use std::sync::Arc;

use lieflow::Error;
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyTuple};

use crate::convert::{shape_str, ArrayIn};
use crate::errors::{argument_type_error, raised, to_py};

type Any<'py> = Bound<'py, PyAny>;

/// A user callable as errors name it: its `__qualname__` (or `__name__`, or repr).
pub(crate) fn callable_name(f: &Any<'_>) -> String {
    ["__qualname__", "__name__"]
        .iter()
        .find_map(|a| f.getattr(*a).ok().and_then(|n| n.extract::<String>().ok()))
        .or_else(|| f.repr().ok().map(|r| r.to_string()))
        .unwrap_or_else(|| "?".into())
}

/// A Python callable of a user system: `f(*arrays)` must return an array of a fixed shape.
#[derive(Clone)]
pub(crate) struct Callee {
    f: Arc<Py<PyAny>>,
    /// "the value of the hamiltonian `H`", for errors.
    what: Arc<str>,
}

impl Callee {
    /// The argument `arg` (named `name`, e.g. "hamiltonian") if it is callable; otherwise an
    /// `ArgumentTypeError` naming it.
    pub(crate) fn new(name: &str, arg: &Any<'_>) -> PyResult<Self> {
        if !arg.is_callable() {
            return Err(argument_type_error(
                arg.py(),
                format!(
                    "argument '{name}': expected a callable, got a {}",
                    arg.get_type()
                        .name()
                        .map_or_else(|_| "?".to_string(), |n| n.to_string())
                ),
            ));
        }
        Ok(Callee {
            f: Arc::new(arg.clone().unbind()),
            what: format!("the value of {name} `{}`", callable_name(arg)).into(),
        })
    }

    /// The exception `e` as the core error that carries it.
    fn raised(&self, e: PyErr) -> Error {
        raised(&*self.what, e)
    }

    /// Calls f with one float64 array per slice of `args` and reads its value of `shape` into
    /// `out` (row-major), checked finite.
    fn call(&self, args: &[&[f64]], shape: &[usize], out: &mut [f64]) -> lieflow::Result<()> {
        Python::attach(|py| {
            let called = PyTuple::new(py, args.iter().map(|x| PyArray1::from_slice(py, x)))
                .and_then(|a| self.f.bind(py).call1(a));
            self.read(called, shape, out)
        })
    }

    /// Calls f(t, z) (a float and a float64 array) and reads its value like [`Callee::call`].
    pub(crate) fn call_at(
        &self,
        t: f64,
        z: &[f64],
        shape: &[usize],
        out: &mut [f64],
    ) -> lieflow::Result<()> {
        Python::attach(|py| {
            let called = self.f.bind(py).call1((t, PyArray1::from_slice(py, z)));
            self.read(called, shape, out)
        })
    }

    /// Reads the value of a call of `shape` into `out`, checked finite (or keeps its exception).
    fn read(
        &self,
        called: PyResult<Any<'_>>,
        shape: &[usize],
        out: &mut [f64],
    ) -> lieflow::Result<()> {
        let value = called.map_err(|e| self.raised(e))?;

        // Fast paths: a float, a float64 array; anything else is read like every argument.
        match (shape.is_empty(), value.cast::<PyFloat>()) {
            (true, Ok(f)) => out[0] = f.value(),
            _ => match value.cast::<PyArrayDyn<f64>>().map(|a| a.try_readonly()) {
                Ok(Ok(a)) => self.copy(&a.as_array(), shape, out)?,
                _ => {
                    let a = ArrayIn::named(&self.what, &value).map_err(|e| self.raised(e))?;
                    self.copy(&a.as_array(), shape, out)?
                }
            },
        }
        match out.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(i) => Err(Error::NonFinite {
                what: self.what.to_string(),
                location: if shape.is_empty() {
                    format!("its value ({})", out[i])
                } else {
                    let mut idx = Vec::new();
                    let mut r = i;
                    for s in shape.iter().rev() {
                        idx.push(r % s);
                        r /= s;
                    }
                    idx.reverse();
                    let idx: Vec<String> = idx.iter().map(|k| k.to_string()).collect();
                    format!("entry [{}] = {}", idx.join(", "), out[i])
                },
            }),
        }
    }

    /// `v` into `out` if it has `shape`, else a ShapeError.
    fn copy(
        &self,
        v: &numpy::ndarray::ArrayViewD<'_, f64>,
        shape: &[usize],
        out: &mut [f64],
    ) -> lieflow::Result<()> {
        if v.shape() != shape {
            return Err(Error::shape(
                &*self.what,
                shape_str(shape),
                shape_str(v.shape()),
            ));
        }
        for (o, x) in out.iter_mut().zip(v.iter()) {
            *o = *x;
        }
        Ok(())
    }

    /// Calls f with the arrays `args` and reads the pair (first, second) it returns (a tuple or
    /// list of two arrays of the outputs' lengths), checked finite.
    fn call_pair(
        &self,
        args: &[&[f64]],
        first: &mut [f64],
        second: &mut [f64],
    ) -> lieflow::Result<()> {
        Python::attach(|py| {
            let called = PyTuple::new(py, args.iter().map(|x| PyArray1::from_slice(py, x)))
                .and_then(|a| self.f.bind(py).call1(a))
                .map_err(|e| self.raised(e))?;
            let items: Vec<Any<'_>> = match called.len() {
                Ok(2) if !called.is_instance_of::<numpy::PyUntypedArray>() => {
                    vec![called.get_item(0), called.get_item(1)]
                        .into_iter()
                        .collect::<PyResult<_>>()
                        .map_err(|e| self.raised(e))?
                }
                _ => {
                    return Err(Error::shape(
                        &*self.what,
                        format!("a pair (({},), ({},))", first.len(), second.len()),
                        called
                            .get_type()
                            .name()
                            .map_or_else(|_| "?".to_string(), |n| n.to_string()),
                    ))
                }
            };
            let [a, b] = [&items[0], &items[1]];
            self.read(Ok(a.clone()), &[first.len()], first)?;
            self.read(Ok(b.clone()), &[second.len()], second)
        })
    }

    fn scalar(&self, args: &[&[f64]]) -> lieflow::Result<f64> {
        let mut out = [0.0];
        self.call(args, &[], &mut out)?;
        Ok(out[0])
    }
}

fn optional<'a, 'py>(a: Option<&'a Any<'py>>) -> Option<&'a Any<'py>> {
    a.filter(|x| !x.is_none())
}

/// A missing required argument: a TypeError naming it, as Python's own.
fn missing(py: Python<'_>, class: &str, name: &str, what: &str) -> PyErr {
    argument_type_error(
        py,
        format!("{class}() missing the argument '{name}' ({what})"),
    )
}

/// A count argument (`dof`) as usize; negative is an `InvalidArgumentError`.
fn count(name: &str, v: i64) -> PyResult<usize> {
    usize::try_from(v).map_err(|_| {
        to_py(Error::invalid(
            name,
            format!("expected an int ≥ 1, got {v}"),
        ))
    })
}

// ---------------------------------------------------------------------------------------------
