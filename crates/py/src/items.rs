//! Vectorised observables: apply a per-item function over the leading axes of numpy arrays, with
//! numpy broadcasting of the leading axes between several inputs.
//!
//! An *item* is the trailing block of an array (a state vector (d,), an attitude (3, 3), a
//! scalar ()), and the leading axes are any batch/time axes: `energy` maps (..., d) to (...),
//! `spatial_momentum` maps (..., 3) and (..., 3, 3) to (..., 3).

use lieflow::{check, Error};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyFloat;

use crate::convert::{shape_str, ArrayIn};
use crate::errors::to_py;

/// A float64 numpy array of any shape.
pub type Out<'py> = Bound<'py, PyArrayDyn<f64>>;

/// One input of [`map_items`]: its name (for errors), the array and the shape of one item.
pub struct Input<'a, 'py> {
    pub what: &'a str,
    pub array: &'a ArrayIn<'py>,
    pub item: &'a [usize],
}

impl<'a, 'py> Input<'a, 'py> {
    /// The input `what` with items of shape `item`.
    pub fn new(what: &'a str, array: &'a ArrayIn<'py>, item: &'a [usize]) -> Self {
        Input { what, array, item }
    }
}

fn expected_str(item: &[usize]) -> String {
    if item.is_empty() {
        "a scalar or an array".into()
    } else {
        let inner: Vec<String> = item.iter().map(|d| d.to_string()).collect();
        format!("(..., {})", inner.join(", "))
    }
}

/// The last line of defence of "no silent NaN from finite input", shared by every vectorised
/// result (mapped items here, batched items in `batch`, n×n batches in `lie::so`): an output
/// item `out` that is not finite although its inputs were is refused with an
/// `InvalidArgumentError` naming the inputs `what` (and the item `at` of a batch) instead of
/// being returned. Core functions should refuse such input themselves with a better message;
/// this catches what they miss. (No mapped function of the API has a legitimate infinite value.)
pub fn representable(
    what: &str,
    inputs_finite: bool,
    out: &[f64],
    at: Option<&str>,
) -> lieflow::Result<()> {
    if !inputs_finite || out.iter().all(|x| x.is_finite()) {
        return Ok(());
    }
    let what = match at {
        Some(k) => format!("{what}[{k}]"),
        None => what.to_string(),
    };
    Err(Error::invalid(
        what,
        "the result is not representable: it overflows to inf or NaN for this finite input \
         (its scale is outside the range the computation supports)",
    ))
}

/// numpy's broadcasting of several shapes; `None` if they do not broadcast.
fn broadcast(shapes: &[&[usize]]) -> Option<Vec<usize>> {
    let n = shapes.iter().map(|s| s.len()).max().unwrap_or(0);
    let mut out = vec![1; n];
    for s in shapes {
        for (k, &d) in s.iter().enumerate() {
            let o = &mut out[n - s.len() + k];
            if *o == 1 {
                *o = d;
            } else if d != 1 && d != *o {
                return None;
            }
        }
    }
    Some(out)
}

/// Applies `f(items, out)` to every combination of items along the (broadcast) leading axes of
/// the inputs; `out` has `out_item` shape. Returns an array of shape (...lead, ...out_item), or a
/// Python float when that shape is () (one scalar-valued item, like numpy's scalar results).
/// Shape mismatches become `ShapeError`; an error of `f` in a batch names the item by its index
/// along the leading axes (`states[7, 12]`, or `states[7, 12]: state` where it names another
/// thing than an input).
pub fn map_items<'py, F>(
    py: Python<'py>,
    inputs: &[Input<'_, 'py>],
    out_item: &[usize],
    f: F,
) -> PyResult<Bound<'py, PyAny>>
where
    F: Fn(&[&[f64]], &mut [f64]) -> lieflow::Result<()>,
{
    let views: Vec<_> = inputs.iter().map(|i| i.array.as_array()).collect();
    let mut leads = Vec::with_capacity(inputs.len());
    for (inp, v) in inputs.iter().zip(&views) {
        let s = v.shape();
        let k = inp.item.len();
        if s.len() < k || s[s.len() - k..] != *inp.item {
            return Err(to_py(Error::shape(
                inp.what,
                expected_str(inp.item),
                shape_str(s),
            )));
        }
        leads.push(&s[..s.len() - k]);
    }
    let lead = broadcast(&leads).ok_or_else(|| {
        let got: Vec<String> = inputs
            .iter()
            .zip(&views)
            .map(|(i, v)| format!("{} {}", i.what, shape_str(v.shape())))
            .collect();
        to_py(Error::shape(
            "inputs",
            "leading axes that broadcast together",
            got.join(", "),
        ))
    })?;
    // The one guard of every mapped output: its size is checked and it is allocated fallibly
    // (a broadcast input of 10¹⁰ items is refused, not an abort of the process).
    let shape: Vec<usize> = lead.iter().chain(out_item).copied().collect();
    let names: Vec<&str> = inputs.iter().map(|i| i.what).collect();
    let mut out = check::zeros(&names.join(", "), &shape).map_err(to_py)?;
    let count: usize = lead.iter().product();
    // Every input is read item by item from its broadcast view (no broadcast copy in memory).
    let mut streams = Vec::with_capacity(inputs.len());
    for (inp, v) in inputs.iter().zip(&views) {
        let full: Vec<usize> = lead.iter().chain(inp.item).copied().collect();
        // Broadcasting to a shape computed from this very input cannot fail.
        let b = v
            .broadcast(IxDyn(&full))
            .ok_or_else(|| to_py(Error::shape(inp.what, shape_str(&full), "")))?;
        streams.push(b.into_iter());
    }
    let mut scratch: Vec<Vec<f64>> = inputs
        .iter()
        .map(|i| vec![0.0; i.item.iter().product()])
        .collect();
    let out_len: usize = out_item.iter().product();
    for k in 0..count {
        for (s, it) in scratch.iter_mut().zip(&mut streams) {
            // `zip` asks the slice first, so the stream is read by exactly one item.
            for (x, y) in s.iter_mut().zip(it.by_ref()) {
                *x = *y;
            }
        }
        let items: Vec<&[f64]> = scratch.iter().map(|s| s.as_slice()).collect();
        let o = &mut out[k * out_len..(k + 1) * out_len];
        // The item's index along the leading axes, for errors in a batch.
        let at = || {
            let mut r = k;
            let mut idx = vec![0; lead.len()];
            for (i, &n) in idx.iter_mut().zip(&lead).rev() {
                (*i, r) = (r % n, r / n);
            }
            idx.iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        f(&items, o).map_err(|e| {
            to_py(if count > 1 {
                e.map_what(|w| match names.contains(&w) {
                    true => format!("{w}[{}]", at()),
                    false => format!("{}[{}]: {w}", names.join(", "), at()),
                })
            } else {
                e
            })
        })?;
        let finite = items.iter().all(|s| s.iter().all(|x| x.is_finite()));
        let at = (count > 1).then(at);
        representable(&names.join(", "), finite, o, at.as_deref()).map_err(to_py)?;
    }
    if shape.is_empty() {
        return Ok(PyFloat::new(py, out[0]).into_any());
    }
    Ok(array(py, &shape, out)?.into_any())
}

/// A numpy array of the given shape from row-major data: a small one copied into an array
/// numpy allocates (cheaper than handing numpy a Rust buffer to own), a large one moved.
pub fn array<'py>(py: Python<'py>, shape: &[usize], data: Vec<f64>) -> PyResult<Out<'py>> {
    let got = data.len();
    if got <= SMALL && shape.iter().product::<usize>() == got {
        // SAFETY: the array is new, C-contiguous, of `got` elements, all written before it is
        // returned.
        let a = unsafe { PyArrayDyn::<f64>::new(py, IxDyn(shape), false) };
        unsafe { a.as_slice_mut() }
            .map_err(|e| to_py(Error::invalid("output", e.to_string())))?
            .copy_from_slice(&data);
        return Ok(a);
    }
    ArrayD::from_shape_vec(IxDyn(shape), data)
        .map(|a| a.into_pyarray(py))
        .map_err(|_| {
            to_py(Error::shape(
                "output",
                shape_str(shape),
                format!("{got} values"),
            ))
        })
}

/// The size up to which [`array`] copies.
const SMALL: usize = 1 << 12;
