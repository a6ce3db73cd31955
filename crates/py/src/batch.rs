//! Batched bindings of fixed-size items (3-vectors, 3×3 and 4×4 matrices, 6-vectors): read one
//! item or a (b, …item) batch, map it in parallel with rayon and the GIL released, write the
//! result straight into the new numpy array. Errors in a batch name the item, e.g. `R[2]`.

use lieflow::{check, Error};
use nalgebra::SMatrix;
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn};
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::convert::{read_all, shape_str, ArrayIn};
use crate::errors::to_py;
use crate::items::representable;

/// A numpy array of floats whose shape depends on whether the input was batched.
pub type Out<'py> = Bound<'py, PyArrayDyn<f64>>;

/// A fixed-size item of a batch (a k-vector or an r×c matrix), read from and written to
/// numpy's row-major order.
pub trait Item: Sized {
    /// Number of floats.
    const LEN: usize;
    /// The numpy shape of one item.
    fn shape() -> Vec<usize>;
    /// From `LEN` row-major floats.
    fn load(s: &[f64]) -> Self;
    /// Into `LEN` row-major floats.
    fn store(&self, out: &mut [f64]);
}

impl<const R: usize, const C: usize> Item for SMatrix<f64, R, C> {
    const LEN: usize = R * C;
    fn shape() -> Vec<usize> {
        if C == 1 {
            vec![R]
        } else {
            vec![R, C]
        }
    }
    fn load(s: &[f64]) -> Self {
        SMatrix::from_row_slice(s)
    }
    fn store(&self, out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = self[(k / C, k % C)];
        }
    }
}

/// Reads an array of shape `item` or (b, *item) into flat row-major data, checking finiteness
/// (a non-finite entry is named by its item, `what[k]`, and its place in the item). Returns the
/// data and whether the input was batched.
fn read<A: Item>(what: &str, a: &ArrayIn<'_>) -> PyResult<(Vec<f64>, bool)> {
    let item = A::shape();
    let v = a.as_array();
    let s = v.shape();
    let batched = if s == item {
        false
    } else if s.len() == item.len() + 1 && s[1..] == item[..] {
        true
    } else {
        let inner: Vec<String> = item.iter().map(|d| d.to_string()).collect();
        return Err(to_py(Error::shape(
            what,
            format!("{} or a batch (b, {})", shape_str(&item), inner.join(", ")),
            shape_str(s),
        )));
    };
    // Checked and allocated fallibly: a broadcast view of 10¹⁰ items is refused, not an abort.
    let data = read_all(what, &v)?;
    check::finite_items(what, &data, &item).map_err(|(k, e)| {
        to_py(if batched {
            e.map_what(|w| format!("{w}[{k}]"))
        } else {
            e
        })
    })?;
    Ok((data, batched))
}

/// (…item) or (b, …item) → the items.
pub fn read_items<A: Item>(what: &str, a: &ArrayIn<'_>) -> PyResult<(Vec<A>, bool)> {
    let (data, batched) = read::<A>(what, a)?;
    let mut items = Vec::new();
    items.try_reserve_exact(data.len() / A::LEN).map_err(|_| {
        to_py(Error::invalid(
            what,
            "cannot allocate its items; split the input",
        ))
    })?;
    items.extend(data.chunks_exact(A::LEN).map(A::load));
    Ok((items, batched))
}

/// Fills a new array of `n` items `f(0), …, f(n − 1)` (shape `B::shape()` when not `batched`)
/// in parallel with the GIL released, writing straight into the buffer that becomes the numpy
/// array. The first error (with its batch index when `batched`) becomes the Python exception.
/// The buffer is checked and allocated fallibly (an oversized batch is an `InvalidArgumentError`
/// naming the input `what`).
pub fn par_fill<'py, B, F>(
    py: Python<'py>,
    what: &str,
    n: usize,
    batched: bool,
    f: F,
) -> PyResult<Out<'py>>
where
    B: Item,
    F: Fn(usize) -> lieflow::Result<B> + Sync + Send,
{
    let mut data = check::zeros(what, &[n, B::LEN]).map_err(to_py)?;
    py.detach(|| {
        data.par_chunks_mut(B::LEN)
            .with_min_len(256)
            .enumerate()
            .try_for_each(|(k, out)| {
                // Every input of a batch is finite (read checks it): a non-finite result is
                // refused (items::representable).
                f(k).and_then(|b| {
                    b.store(out);
                    representable(what, true, out, None)
                })
                .map_err(|e| {
                    if batched {
                        e.map_what(|w| format!("{w}[{k}]"))
                    } else {
                        e
                    }
                })
            })
    })
    .map_err(to_py)?;
    let mut shape = B::shape();
    if batched {
        shape.insert(0, n);
    }
    Ok(ArrayD::from_shape_vec(IxDyn(&shape), data)
        .expect("n · B::LEN floats fill the shape (b, …B::shape())")
        .into_pyarray(py))
}

/// Applies `f` to every item of a (…A) or (b, …A) array: the batched bindings in one call.
pub fn map_batch<'py, A, B, F>(
    py: Python<'py>,
    what: &str,
    x: &ArrayIn<'py>,
    f: F,
) -> PyResult<Out<'py>>
where
    A: Item,
    B: Item,
    F: Fn(&A) -> lieflow::Result<B> + Sync + Send,
{
    let (data, batched) = read::<A>(what, x)?;
    let n = data.len() / A::LEN;
    par_fill(py, what, n, batched, |k| {
        f(&A::load(&data[k * A::LEN..(k + 1) * A::LEN]))
    })
}
