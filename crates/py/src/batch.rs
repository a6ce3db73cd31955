//! Typed items for the vectorisation rule of [`crate::items`]: fixed-size items (3-vectors, 3×3
//! and 4×4 matrices, 6-vectors) as nalgebra types, mapped over any leading axes in parallel with
//! the GIL released. Errors in a batch name the item, e.g. `R[2]`.

use nalgebra::SMatrix;
use pyo3::prelude::*;

use crate::convert::ArrayIn;
use crate::items::{par_map_items, Input};

/// The result: an array (..., *item).
pub type Out<'py> = Bound<'py, PyAny>;

/// A fixed-size item of a batch (a k-vector or an r×c matrix), read from and written to
/// numpy's row-major order.
pub trait Item: Sized {
    /// The numpy shape of one item.
    fn shape() -> Vec<usize>;
    /// From `LEN` row-major floats.
    fn load(s: &[f64]) -> Self;
    /// Into `LEN` row-major floats.
    fn store(&self, out: &mut [f64]);
}

impl<const R: usize, const C: usize> Item for SMatrix<f64, R, C> {
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

/// Applies `f` to every item of an array of shape (..., *A::shape()): [`par_map_items`] for
/// typed items.
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
    let item = A::shape();
    if let ([n], [a, b]) = (item.as_slice(), x.as_array().shape()) {
        if a == n && b == n {
            crate::errors::warn(
                py,
                &format!(
                    "{what} of shape ({n}, {n}) is read as {n} items of shape ({n},), one per \
                     row (the last axis is the item, the leading ones a batch); for one item \
                     pass shape ({n},) (a matrix's vector by vee); if {n} items are meant, \
                     silence this with warnings.filterwarnings(\"ignore\", \"{what} of \
                     shape\", lieflow.LieflowWarning)"
                ),
            )?;
        }
    }
    par_map_items(
        py,
        &[Input::finite(what, x, &item)],
        &B::shape(),
        |x, out| f(&A::load(x[0])).map(|b| b.store(out)),
    )
}

/// Applies `f` to pairs of items of two arrays (..., *A::shape()) and (..., *B::shape()) whose
/// leading axes broadcast together.
pub fn map_pairs<'py, A, B, C, F>(
    py: Python<'py>,
    names: [&str; 2],
    a: &ArrayIn<'py>,
    b: &ArrayIn<'py>,
    f: F,
) -> PyResult<Out<'py>>
where
    A: Item,
    B: Item,
    C: Item,
    F: Fn(&A, &B) -> lieflow::Result<C> + Sync + Send,
{
    let (ia, ib) = (A::shape(), B::shape());
    let inputs = [
        Input::finite(names[0], a, &ia),
        Input::finite(names[1], b, &ib),
    ];
    par_map_items(py, &inputs, &C::shape(), |x, out| {
        f(&A::load(x[0]), &B::load(x[1])).map(|c| c.store(out))
    })
}
