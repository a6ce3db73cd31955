//! `lieflow.lie`: bindings of `lieflow::lie`, one file per core module.

mod gl;
mod rotations;
mod se3;
mod so;
mod so3;

use pyo3::prelude::*;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    so::register(m)?;
    so3::register(m)?;
    gl::register(m)?;
    se3::register(m)?;
    rotations::register(m)?;
    Ok(())
}
