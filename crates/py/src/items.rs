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
use rayon::prelude::*;
use std::borrow::Cow;

use crate::convert::{read_all, shape_str, ArrayIn};
use crate::errors::to_py;

/// A float64 numpy array of any shape.
pub type Out<'py> = Bound<'py, PyArrayDyn<f64>>;

/// One input of [`map_items`]: its name (for errors), the array and the shape of one item.
pub struct Input<'a, 'py> {
    pub what: &'a str,
    pub array: &'a ArrayIn<'py>,
    pub item: &'a [usize],
    /// Whether the rule checks its items finite before the function sees them (otherwise the
    /// function does, with its own message: a domain error may say more).
    pub finite: bool,
}

impl<'a, 'py> Input<'a, 'py> {
    /// The input `what` with items of shape `item`, checked by the mapped function.
    pub fn new(what: &'a str, array: &'a ArrayIn<'py>, item: &'a [usize]) -> Self {
        Input {
            what,
            array,
            item,
            finite: false,
        }
    }

    /// The input `what` with items of shape `item`, each checked finite by the rule
    /// (`NonFiniteError` naming the item and its entry).
    pub fn finite(what: &'a str, array: &'a ArrayIn<'py>, item: &'a [usize]) -> Self {
        Input {
            finite: true,
            ..Input::new(what, array, item)
        }
    }
}

fn expected_str(item: &[usize]) -> String {
    if item.is_empty() {
        "a scalar or an array".into()
    } else {
        let one = shape_str(item);
        let inner: Vec<String> = item.iter().map(|d| d.to_string()).collect();
        format!("{one} or (..., {})", inner.join(", "))
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

/// The most inputs one mapped function takes.
const MAX_INPUTS: usize = 6;

/// The number of items from which [`par_map_items`] runs on the thread pool.
const PAR_MIN: usize = 256;

/// A mapping of the inputs' items, read and checked once: the broadcast leading axes, the data of
/// every input (row-major, as read), and each input's stride in items along each leading axis
/// (0 where it is broadcast).
struct Plan<'a> {
    names: Vec<&'a str>,
    lead: Vec<usize>,
    /// The item shapes of the outputs; an item's outputs are written one after another.
    outs: Vec<&'a [usize]>,
    count: usize,
    out_len: usize,
    /// The inputs' data: borrowed from numpy where contiguous and the GIL stays held, a copy
    /// for the mapping that releases it (another Python thread may then write the array).
    data: Vec<Cow<'a, [f64]>>,
    items: Vec<&'a [usize]>,
    finite: Vec<bool>,
    strides: Vec<Vec<usize>>,
}

impl<'a> Plan<'a> {
    fn new(inputs: &[Input<'a, '_>], outs: &[&'a [usize]], copy: bool) -> PyResult<Self> {
        assert!(
            inputs.len() <= MAX_INPUTS,
            "at most {MAX_INPUTS} mapped inputs"
        );
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
                "leading axes that broadcast together (the same length, or 1)",
                got.join(", "),
            ))
        })?;
        let names: Vec<&str> = inputs.iter().map(|i| i.what).collect();
        // The one guard of every mapped output: its size is checked before it is allocated
        // (a broadcast input of 10¹⁰ items is refused, not an abort of the process).
        let out_len: usize = outs.iter().map(|o| o.iter().product::<usize>()).sum();
        let count: usize = lead.iter().product();
        for shape in outs
            .iter()
            .map(|o| lead.iter().chain(*o).copied().collect::<Vec<_>>())
            .chain([vec![count, out_len]])
        {
            check::array_size(&names.join(", "), &shape).map_err(to_py)?;
        }
        let mut data = Vec::with_capacity(inputs.len());
        let mut strides = Vec::with_capacity(inputs.len());
        for ((inp, v), l) in inputs.iter().zip(&views).zip(&leads) {
            // Each input is read once as it is (its own size, checked), never broadcast in memory.
            // Borrowed only in C order (numpy's `as_slice` also accepts Fortran order, whose
            // flat order is not the items').
            data.push(match v.to_slice() {
                Some(s) if !copy => Cow::Borrowed(s),
                _ => Cow::Owned(read_all(inp.what, v)?),
            });
            let mut st = vec![0; lead.len()];
            let mut step = 1;
            for (j, &n) in l.iter().enumerate().rev() {
                if n != 1 {
                    st[lead.len() - l.len() + j] = step;
                }
                step *= n;
            }
            strides.push(st);
        }
        Ok(Plan {
            names,
            count,
            out_len,
            lead,
            outs: outs.to_vec(),
            data,
            items: inputs.iter().map(|i| i.item).collect(),
            finite: inputs.iter().map(|i| i.finite).collect(),
            strides,
        })
    }

    /// The index of item k along the leading axes, as errors write it ("7, 12").
    fn index(&self, k: usize) -> String {
        let mut r = k;
        let mut idx = vec![0; self.lead.len()];
        for (i, &n) in idx.iter_mut().zip(&self.lead).rev() {
            (*i, r) = (r % n, r / n);
        }
        let idx: Vec<String> = idx.iter().map(|i| i.to_string()).collect();
        idx.join(", ")
    }

    /// Item k of every input checked finite, `f` applied, its output checked representable;
    /// an error names the item by its index along the leading axes (`states[7, 12]`, or
    /// `states[7, 12]: state` where it names another thing than an input).
    fn call<F>(&self, k: usize, f: &F, out: &mut [f64]) -> lieflow::Result<()>
    where
        F: Fn(&[&[f64]], &mut [f64]) -> lieflow::Result<()>,
    {
        let mut items: [&[f64]; MAX_INPUTS] = [&[]; MAX_INPUTS];
        for (i, item) in items.iter_mut().take(self.data.len()).enumerate() {
            let len: usize = self.items[i].iter().product();
            let (mut r, mut at) = (k, 0);
            for (&n, &st) in self.lead.iter().zip(&self.strides[i]).rev() {
                at += (r % n) * st;
                r /= n;
            }
            *item = &self.data[i][at * len..(at + 1) * len];
        }
        let items = &items[..self.data.len()];
        let name = |e: Error| match self.lead.is_empty() {
            true => e,
            false => e.map_what(|w| match self.names.contains(&w) {
                true => format!("{w}[{}]", self.index(k)),
                false => format!("{}[{}]: {w}", self.names.join(", "), self.index(k)),
            }),
        };
        let mut finite = true;
        for (i, item) in items.iter().enumerate() {
            if self.finite[i] {
                check::finite_items(self.names[i], item, self.items[i])
                    .map_err(|(_, e)| name(e))?;
            } else {
                finite &= item.iter().all(|x| x.is_finite());
            }
        }
        f(items, out).map_err(name)?;
        let at = (!self.lead.is_empty()).then(|| self.index(k));
        representable(&self.names.join(", "), finite, out, at.as_deref())
    }

    /// Every item mapped on this thread.
    fn run<'py, F>(self, py: Python<'py>, f: &F) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(&[&[f64]], &mut [f64]) -> lieflow::Result<()>,
    {
        let mut out = self.buffer()?;
        for k in 0..self.count {
            let o = &mut out[k * self.out_len..(k + 1) * self.out_len];
            self.call(k, f, o).map_err(to_py)?;
        }
        self.finish(py, out)
    }

    /// The buffer of every item's outputs (sizes checked in [`Plan::new`]).
    fn buffer(&self) -> PyResult<Vec<f64>> {
        check::zeros(&self.names.join(", "), &[self.count, self.out_len]).map_err(to_py)
    }

    /// The outputs as numpy returns them: an array (...lead, ...out item) each, or a Python float
    /// where that shape is () (one scalar-valued item, like numpy's scalar results); one output
    /// alone, several as a tuple.
    fn finish<'py>(self, py: Python<'py>, out: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
        let one = |shape: Vec<usize>, data: Vec<f64>| -> PyResult<Bound<'py, PyAny>> {
            match shape.is_empty() {
                true => Ok(PyFloat::new(py, data[0]).into_any()),
                false => Ok(array(py, &shape, data)?.into_any()),
            }
        };
        let shape = |o: &[usize]| self.lead.iter().chain(o).copied().collect::<Vec<_>>();
        if let [o] = self.outs[..] {
            return one(shape(o), out);
        }
        let mut parts = Vec::with_capacity(self.outs.len());
        let mut at = 0;
        for o in &self.outs {
            let len: usize = o.iter().product();
            let mut data =
                check::zeros(&self.names.join(", "), &[self.count, len]).map_err(to_py)?;
            for (k, d) in data
                .chunks_exact_mut(len.max(1))
                .enumerate()
                .take(self.count)
            {
                d.copy_from_slice(&out[k * self.out_len + at..k * self.out_len + at + len]);
            }
            parts.push(one(shape(o), data)?);
            at += len;
        }
        Ok(pyo3::types::PyTuple::new(py, parts)?.into_any())
    }
}

/// The one vectorisation rule of the bindings: applies `f(items, out)` to every combination of
/// items along the leading axes of the inputs, which broadcast as numpy's do; an item is the
/// trailing block of shape `Input::item` (a state (d,), an attitude (3, 3), a scalar ()), `out`
/// one of shape `out_item`. Returns an array (...lead, ...out_item), or a Python float when that
/// shape is (). Inputs made with [`Input::finite`] are checked finite item by item
/// (`NonFiniteError` naming the item and its entry); an output item from finite inputs must be
/// finite ([`representable`]); shape mismatches are `ShapeError`s. Runs on this
/// thread with the GIL held: for functions that may call Python (user systems' callables); pure
/// Rust functions use [`par_map_items`].
pub fn map_items<'py, F>(
    py: Python<'py>,
    inputs: &[Input<'_, 'py>],
    out_item: &[usize],
    f: F,
) -> PyResult<Bound<'py, PyAny>>
where
    F: Fn(&[&[f64]], &mut [f64]) -> lieflow::Result<()>,
{
    Plan::new(inputs, &[out_item], false)?.run(py, &f)
}

/// [`map_items`] for functions of several outputs, of item shapes `outs` (on this thread, with the
/// GIL held: for functions that may call Python); returns the tuple of the arrays.
pub fn map_items_n<'py, F>(
    py: Python<'py>,
    inputs: &[Input<'_, 'py>],
    outs: &[&[usize]],
    f: F,
) -> PyResult<Bound<'py, PyAny>>
where
    F: Fn(&[&[f64]], &mut [f64]) -> lieflow::Result<()>,
{
    Plan::new(inputs, outs, false)?.run(py, &f)
}

/// [`map_items`] for functions of pure Rust: from [`PAR_MIN`] items on, the items are mapped on
/// the thread pool with the GIL released (the first error found is raised).
pub fn par_map_items<'py, F>(
    py: Python<'py>,
    inputs: &[Input<'_, 'py>],
    out_item: &[usize],
    f: F,
) -> PyResult<Bound<'py, PyAny>>
where
    F: Fn(&[&[f64]], &mut [f64]) -> lieflow::Result<()> + Sync + Send,
{
    par_map_items_n(py, inputs, &[out_item], f)
}

/// [`par_map_items`] for functions of several outputs, of item shapes `outs`: `f` writes an
/// item's outputs one after another into `out`; returns the tuple of the arrays.
pub fn par_map_items_n<'py, F>(
    py: Python<'py>,
    inputs: &[Input<'_, 'py>],
    outs: &[&[usize]],
    f: F,
) -> PyResult<Bound<'py, PyAny>>
where
    F: Fn(&[&[f64]], &mut [f64]) -> lieflow::Result<()> + Sync + Send,
{
    let plan = Plan::new(inputs, outs, true)?;
    if plan.count < PAR_MIN || plan.out_len == 0 {
        return plan.run(py, &f);
    }
    let mut out = plan.buffer()?;
    py.detach(|| {
        out.par_chunks_mut(plan.out_len)
            .with_min_len(PAR_MIN)
            .enumerate()
            .try_for_each(|(k, o)| plan.call(k, &f, o))
    })
    .map_err(to_py)?;
    plan.finish(py, out)
}

/// The item shape (r, c) of an array of matrices (..., r, c).
pub fn matrix_item(what: &str, a: &ArrayIn<'_>) -> PyResult<[usize; 2]> {
    let s = a.as_array().shape().to_vec();
    let [.., r, c] = s[..] else {
        return Err(to_py(Error::shape(
            what,
            "(n, n) or (..., n, n)",
            shape_str(&s),
        )));
    };
    check::dense_size(what, r, c).map_err(to_py)?;
    Ok([r, c])
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
