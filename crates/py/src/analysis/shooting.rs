//! `lieflow.periodic_orbit`'s native part: the binding of `lieflow::analysis::periodic`
//! (shooting, monodromy, multipliers, the attitude's drift). Conversions only; the
//! `PeriodicOrbit` object is built in Python (python/lieflow/periodic.py).

use lieflow::analysis::periodic::{self as core, Fix, Options};
use lieflow::Error;
use numpy::{Complex64, IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{py_mat, py_vec, real, real_matrix, real_vec, size};

const IDENTITY: [f64; 9] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
use crate::errors::{checked, to_py};
use crate::system::PySystem;

fn complex(v: &[(f64, f64)]) -> Vec<Complex64> {
    v.iter().map(|&(re, im)| Complex64::new(re, im)).collect()
}

/// The periodic orbit of `method`'s map with `steps` steps per period near `state0` and
/// `period` (`lieflow.periodic_orbit`, which checks the arguments' kinds): a dict of its
/// quantities (state0, period, energy, monodromy, multipliers, trivial, normal, stable,
/// residual, iterations, drift, levels, tangent; `levels` to keep instead of the guess's;
/// `fix = "arclength"` with `arclength = (u0, tangent, step)`: the continuation's corrector).
/// A relative orbit: with an attitude, of the body carrying it
/// (drift: the rotation vector of R(T) R(0)ᵀ); else `relative` of the system's symmetry
/// (drift: ζ with z(T) = exp(ζ)·z(0), from the guess `drift`), or of the body carrying the
/// identity attitude where the system has no symmetry lieflow can act with.
#[pyfunction]
#[pyo3(signature = (system, state0, period, method, steps, fix, tol, max_iter, attitude = None,
                    relative = false, drift = None, levels = None, arclength = None))]
#[allow(clippy::too_many_arguments)]
pub fn _periodic_orbit<'py>(
    py: Python<'py>,
    system: PyRef<'py, PySystem>,
    state0: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = real)] period: f64,
    method: &str,
    #[pyo3(from_py_with = size)] steps: usize,
    fix: &str,
    #[pyo3(from_py_with = real)] tol: f64,
    #[pyo3(from_py_with = size)] max_iter: usize,
    attitude: Option<&Bound<'py, PyAny>>,
    relative: bool,
    drift: Option<&Bound<'py, PyAny>>,
    levels: Option<&Bound<'py, PyAny>>,
    arclength: Option<(Bound<'py, PyAny>, Bound<'py, PyAny>, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    let levels = levels.map(real_vec).transpose()?;
    let fix = match (fix, arclength) {
        ("arclength", Some((from, tangent, step))) => Fix::Arclength {
            from: real_vec(&from)?,
            tangent: real_vec(&tangent)?,
            step,
        },
        ("energy", None) => Fix::Energy,
        ("period", None) => Fix::Period,
        (other, _) => {
            return Err(to_py(Error::invalid(
                "fix",
                format!("expected \"energy\" or \"period\", got {other:?}"),
            )))
        }
    };
    if !(tol > 0.0 && tol < 1.0) || max_iter == 0 {
        return Err(to_py(Error::invalid(
            "tol",
            format!(
                "expected 0 < tol < 1 and max_iter >= 1, got tol = {tol}, max_iter = {max_iter}"
            ),
        )));
    }
    let (z0, batched) = system.normalize(state0)?;
    if batched {
        return Err(to_py(Error::invalid(
            "state0",
            "one initial state: the shooting solves for one orbit",
        )));
    }
    let sys = system.sys.clone();
    let symmetric = attitude.is_none() && relative && sys.symmetry().is_some();
    let attitude = match attitude {
        None if relative && !symmetric => {
            if sys.lift().is_none() {
                return Err(to_py(Error::invalid(
                    "relative",
                    format!(
                        "{} has neither a symmetry whose action lieflow knows nor an attitude",
                        sys.name()
                    ),
                )));
            }
            Some(IDENTITY)
        }
        None => None,
        Some(a) => Some(real_matrix::<3, 3>(a).map(|m| std::array::from_fn(|k| m[k / 3][k % 3]))?),
    };
    let drift = drift.map(real_vec).transpose()?;
    if drift.is_some() && !symmetric {
        return Err(to_py(Error::invalid(
            "drift",
            "a guess of ζ is for a relative orbit of the system's symmetry (relative=True)",
        )));
    }
    let options = Options {
        steps,
        fix,
        tol,
        max_iter,
        relative: symmetric,
        levels,
    };
    let solve = || {
        checked(|| {
            let orbit = core::periodic_orbit(
                sys.as_ref(),
                method,
                &z0,
                period,
                drift.as_deref(),
                &options,
            )?;
            let drift = match &attitude {
                Some(a) => Some(core::attitude_drift(sys.as_ref(), method, &orbit, a)?.to_vec()),
                None => orbit.drift.clone(),
            };
            Ok((orbit, drift))
        })
    };
    let (orbit, drift) = if sys.calls_out() {
        solve()?
    } else {
        py.detach(solve)?
    };
    orbit_dict(py, &orbit, drift, attitude)
}

/// An orbit's quantities as the dict `PeriodicOrbit` is built from.
fn orbit_dict<'py>(
    py: Python<'py>,
    orbit: &core::PeriodicOrbit,
    drift: Option<Vec<f64>>,
    attitude: Option<[f64; 9]>,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("state0", py_vec(py, &orbit.state0))?;
    out.set_item("period", orbit.period)?;
    out.set_item("steps", orbit.steps)?;
    out.set_item("energy", orbit.energy)?;
    out.set_item("monodromy", py_mat(py, &orbit.monodromy))?;
    out.set_item("multipliers", complex(&orbit.multipliers).into_pyarray(py))?;
    out.set_item("trivial", orbit.trivial.clone().into_pyarray(py))?;
    out.set_item("normal", complex(&orbit.normal).into_pyarray(py))?;
    out.set_item("stable", orbit.stable())?;
    out.set_item("residual", orbit.residual)?;
    out.set_item("iterations", orbit.iterations)?;
    out.set_item("levels", py_vec(py, &orbit.levels))?;
    out.set_item("tangent", py_vec(py, &orbit.tangent))?;
    out.set_item("drift", drift.map(|w| py_vec(py, &w)))?;
    let attitude = attitude.map(|a| py_mat(py, &lieflow::Mat::from_fn(3, 3, |i, j| a[3 * i + j])));
    out.set_item("attitude", attitude)?;
    Ok(out)
}

/// The fields of the start orbit the continuation reads (a tuple, in the order below) (its state, period, steps,
/// energy, normal multipliers, drift ζ of the system's symmetry, levels and tangent), as the
/// core's orbit (the monodromy and the rest are not read: left empty).
fn start_of(orbit: &Bound<'_, PyAny>) -> PyResult<(core::PeriodicOrbit, Option<[f64; 9]>)> {
    // (state0, period, steps, energy, normal multipliers, residual, iterations, drift, levels,
    // tangent, attitude), as Python's `periodic_family` passes them.
    let get = |k: usize| orbit.get_item(k);
    let attitude = get(10)?;
    let attitude = match attitude.is_none() {
        true => None,
        false => {
            Some(real_matrix::<3, 3>(&attitude).map(|m| std::array::from_fn(|k| m[k / 3][k % 3]))?)
        }
    };
    let drift = get(7)?;
    let drift = match attitude.is_none() && !drift.is_none() {
        true => Some(real_vec(&drift)?),
        false => None,
    };
    let normal = get(4)?;
    let normal: Vec<Complex64> = normal
        .cast::<numpy::PyArray1<Complex64>>()?
        .readonly()
        .as_array()
        .to_vec();
    let orbit = core::PeriodicOrbit {
        state0: real_vec(&get(0)?)?,
        period: real(&get(1)?)?,
        steps: size(&get(2)?)?,
        energy: real(&get(3)?)?,
        monodromy: lieflow::Mat::zeros(0, 0),
        multipliers: Vec::new(),
        trivial: Vec::new(),
        normal: normal.iter().map(|c| (c.re, c.im)).collect(),
        residual: real(&get(5)?)?,
        iterations: size(&get(6)?)?,
        drift,
        levels: real_vec(&get(8)?)?,
        tangent: real_vec(&get(9)?)?,
    };
    Ok((orbit, attitude))
}

/// The family of periodic orbits through the orbit whose fields `start` holds ([`start_of`];
/// Python's `periodic_family`, which checks the arguments' kinds): a dict with
/// `points` (the orbits after the start, as `_periodic_orbit`'s dicts), `special` (tuples
/// kind, index, value, orbit dict) and `end`. Ctrl-C ends it between orbits.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn _periodic_family<'py>(
    py: Python<'py>,
    system: PyRef<'py, PySystem>,
    start: &Bound<'py, PyAny>,
    method: &str,
    parameter: &str,
    stop: Option<f64>,
    #[pyo3(from_py_with = real)] step: f64,
    #[pyo3(from_py_with = real)] max_step: f64,
    #[pyo3(from_py_with = size)] max_points: usize,
    #[pyo3(from_py_with = real)] direction: f64,
    #[pyo3(from_py_with = real)] tol: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let parameter = match parameter {
        "energy" => core::Parameter::Energy,
        "period" => core::Parameter::Period,
        other => {
            return Err(to_py(Error::invalid(
                "parameter",
                format!("expected \"energy\" or \"period\", got {other:?}"),
            )))
        }
    };
    let (start, attitude) = start_of(start)?;
    let options = core::FamilyOptions {
        parameter,
        stop,
        step,
        max_step,
        max_points,
        direction,
        tol,
    };
    let sys = system.sys.clone();
    let follow = || {
        checked(|| {
            let mut found = 0;
            let mut progress = |_: &core::PeriodicOrbit| {
                found += 1;
                Python::attach(|py| py.check_signals())
                    .map_err(|_| Error::Interrupted { steps_done: found })
            };
            core::periodic_family(sys.as_ref(), method, &start, &options, &mut progress)
        })
    };
    let family = if sys.calls_out() {
        follow()?
    } else {
        py.detach(follow)?
    };
    // Each orbit as `_periodic_orbit` gives it (with an attitude: its drift).
    let dict = |o: &core::PeriodicOrbit| -> PyResult<Bound<'py, PyDict>> {
        let drift = match &attitude {
            Some(a) => Some(checked(|| core::attitude_drift(sys.as_ref(), method, o, a))?.to_vec()),
            None => o.drift.clone(),
        };
        orbit_dict(py, o, drift, attitude)
    };
    let out = PyDict::new(py);
    let points = family.points[1..]
        .iter()
        .map(&dict)
        .collect::<PyResult<Vec<_>>>()?;
    out.set_item("points", points)?;
    let special = family
        .special
        .iter()
        .map(|sp| Ok((sp.kind.name(), sp.index, sp.value, dict(&sp.orbit)?)))
        .collect::<PyResult<Vec<_>>>()?;
    out.set_item("special", special)?;
    out.set_item("end", family.end.to_string())?;
    Ok(out)
}
