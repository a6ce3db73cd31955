//! Python bindings of lieflow: thin PyO3 wrappers that convert arrays and errors and call
//! `lieflow`. No mathematics lives here. The folders mirror `crates/core/src`: `lie/`,
//! `pseudo_rigid/`, `systems/`, `analysis.rs`, `integrate.rs` and `elliptic.rs`; `system.rs` is the one base
//! class of every system class.

mod analysis;
mod batch;
mod convert;
mod elliptic;
mod errors;
mod integrate;
mod items;
mod lie;
mod pseudo_rigid;
mod sensitivity;
mod system;
mod systems;

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
    // Named as the Python module that re-exports it, so that potentials pickle by reference.
    let potentials = PyModule::new(m.py(), "lieflow.potentials")?;
    pseudo_rigid::potential::register(&potentials)?;
    m.add("potentials", potentials)?;
    let surfaces = PyModule::new(m.py(), "lieflow.surfaces")?;
    systems::tangent_top::surface::register(&surfaces)?;
    m.add("surfaces", surfaces)?;
    let spaces = PyModule::new(m.py(), "lieflow.spaces")?;
    systems::tangent_top::space_form::register(&spaces)?;
    m.add("spaces", spaces)?;
    add_submodule(m, "elliptic", elliptic::register)?;
    add_submodule(m, "ellipsoids", pseudo_rigid::ellipsoids::register)?;
    add_submodule(m, "continuation", analysis::register)?;
    m.add_class::<system::PySystem>()?;
    m.add_class::<integrate::Integration>()?;
    m.add_class::<sensitivity::PyTangent>()?;
    m.add_function(wrap_pyfunction!(analysis::shooting::_periodic_orbit, m)?)?;
    m.add_function(wrap_pyfunction!(analysis::shooting::_periodic_family, m)?)?;
    m.add_class::<analysis::lyapunov::PyLyapunov>()?;
    systems::register(m)?;
    system::add_system::<
        pseudo_rigid::system::PyPseudoRigidBody,
        lieflow::pseudo_rigid::PseudoRigidBody,
    >(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
