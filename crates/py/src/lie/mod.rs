//! `lieflow.lie`: bindings of `lieflow::lie`, one file per core module.

mod gl;
mod rotations;
mod se3;
mod so;
mod so3;

use lieflow::Error;
use pyo3::prelude::*;

use crate::batch::{par_fill, read_items, Item, Out};
use crate::convert::{shape_str, ArrayIn};
use crate::errors::to_py;

/// Applies `f` to pairs of items of two (…A)/(b, …A) and (…B)/(b, …B) arrays: a single item is
/// combined with every item of the other batch, two batches must have the same length (an empty
/// batch gives an empty result). An error of the second argument names it, e.g. `h (R)`.
pub(crate) fn map_pairs<'py, A, B, C, F>(
    py: Python<'py>,
    names: [&str; 2],
    a: &ArrayIn<'py>,
    b: &ArrayIn<'py>,
    f: F,
) -> PyResult<Out<'py>>
where
    A: Item + Sync,
    B: Item + Sync,
    C: Item,
    F: Fn(&A, &B) -> lieflow::Result<C> + Sync + Send,
{
    let (xs, bx) = read_items::<A>(names[0], a)?;
    let (ys, by) = read_items::<B>(names[1], b)?;
    let n = if xs.is_empty() || ys.is_empty() {
        0
    } else {
        xs.len().max(ys.len())
    };
    if bx && by && xs.len() != ys.len() {
        let batch = |len: usize, item: Vec<usize>| shape_str(&[vec![len], item].concat());
        return Err(to_py(Error::shape(
            names[1],
            format!(
                "a batch of the same length as {} {}",
                names[0],
                batch(xs.len(), A::shape())
            ),
            batch(ys.len(), B::shape()),
        )));
    }
    let what = format!("{}, {}", names[0], names[1]);
    par_fill(py, &what, n, bx || by, |k| {
        f(&xs[k.min(xs.len() - 1)], &ys[k.min(ys.len() - 1)])
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    so::register(m)?;
    so3::register(m)?;
    gl::register(m)?;
    se3::register(m)?;
    rotations::register(m)?;
    Ok(())
}
