//! Python bindings of lieflow: thin PyO3 wrappers that convert arrays and errors and call
//! `lieflow`. No mathematics lives here.

mod batch;
#[allow(dead_code)] // some converters are only used once every binding lands
mod convert;
mod errors;
mod integrate;
mod lie;
mod pseudo_rigid;
mod pseudo_rigid_dynamics;

use pyo3::prelude::*;

/// Adds a submodule `name` filled by `fill` to `parent`.
fn add_submodule<'py>(
    parent: &Bound<'py, PyModule>,
    name: &str,
    fill: fn(&Bound<'py, PyModule>) -> PyResult<()>,
) -> PyResult<()> {
    let m = PyModule::new(parent.py(), name)?;
    fill(&m)?;
    parent.add_submodule(&m)
}

/// The native extension of lieflow; import `lieflow` instead.
#[pymodule]
fn _lieflow(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    add_submodule(m, "lie", lie::register)?;
    add_submodule(m, "pseudo_rigid", pseudo_rigid::register)?;
    integrate::register(m)?;
    pseudo_rigid_dynamics::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
