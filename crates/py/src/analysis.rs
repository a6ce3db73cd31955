//! `lieflow.continuation`: pseudo-arclength continuation of families of relative equilibria
//! (binding of `lieflow::analysis::continuation` for the ellipsoid families of
//! `lieflow::pseudo_rigid::ellipsoids`). Conversions only; `Branch.plot` calls the Python
//! presentation in `lieflow.continuation`.
//! The Lyapunov spectrum (`lieflow.lyapunov`) and the periodic orbits (`lieflow.periodic_orbit`)
//! are in `analysis/lyapunov.rs` and `analysis/shooting.rs` (core: `analysis::periodic`).
#![allow(non_snake_case)]

pub(crate) mod lyapunov;
pub(crate) mod shooting;

use lieflow::analysis::continuation::{self as cont, End, Options};
use lieflow::pseudo_rigid::ellipsoids::{self as ell, EllipsoidFamily, Sense};
use lieflow::Error;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::convert::{real, real_opt, size};
use crate::errors::{to_py, IntoPy};
use crate::pseudo_rigid::equilibria::RelativeEquilibrium;

/// The names of the monitored verdicts, in the order of `ell::follow`.
const VERDICTS: [&str; 2] = ["spectral", "energy_momentum"];

/// A followed family of relative equilibria.
#[pyclass(module = "lieflow.continuation", name = "Branch", frozen)]
pub struct Branch {
    family: EllipsoidFamily,
    parameter: String,
    stop: f64,
    opts: Options,
    monitored: bool,
    inner: cont::Branch,
}

/// A special point of a branch: `kind` ("branch", "fold" or "stability"), the parameter's value
/// as the attribute of its name (e.g. `.e`; the other parameters of the family too), `point`.
#[pyclass(module = "lieflow.continuation", name = "SpecialPoint", frozen)]
pub struct SpecialPoint {
    family: EllipsoidFamily,
    parameter: String,
    inner: cont::Special,
}

fn figure_of(family: &EllipsoidFamily, u: &[f64]) -> PyResult<RelativeEquilibrium> {
    let fig = family.figure(u).py()?;
    RelativeEquilibrium::ellipsoid(&family.fluid, fig)
}

#[allow(clippy::too_many_arguments)]
fn run(
    py: Python<'_>,
    family: EllipsoidFamily,
    start: Vec<f64>,
    parameter: String,
    stop: f64,
    monitored: bool,
    direction: Option<Vec<f64>>,
    opts: Options,
) -> PyResult<Branch> {
    let inner = py
        .detach(|| {
            ell::follow(
                &family,
                &start,
                &parameter,
                stop,
                monitored,
                direction.as_deref(),
                &opts,
            )
        })
        .py()?;
    Ok(Branch {
        family,
        parameter,
        stop,
        opts,
        monitored,
        inner,
    })
}

/// Follows the family of `start` (a relative equilibrium from `lieflow.ellipsoids`; the family
/// keeps its :math:`f = \zeta/\Omega` and its volume) in the named `parameter` ("e", "a2_over_a1",
/// "a3_over_a1", "Omega2_over_piGrho", "L", "f") until it reaches `stop`, by pseudo-arclength
/// continuation of the reduced equations (semi-axes, velocities, pressure: no symmetry
/// degeneracy). Branch points and folds of the parameter and, with `stability=True`, changes of
/// the spectral and energy–momentum verdicts are located (to ~1e-10 in the parameter or better:
/// the Maclaurin energy–momentum change lies 1e-13 from the closed-form branch point). Special
/// points are reported up to `stop`. If a point cannot be evaluated the branch ends there
/// (`end` = "stuck: ...") and what was found is returned. Not picklable.
///
/// Args:
///     start: the first point.
///     parameter: the parameter to follow and stop on.
///     stop: its final value.
///     stability: evaluate both stability verdicts at every point (slower).
///     step, max_step: the first and the largest arclength step (in the unknowns a, Omega,
///         Lambda, p scaled by their magnitudes at the start, max(abs(u_k), 1)); max_points: a
///         bound.
///
/// Returns:
///     Branch.
///
/// Raises:
///     InvalidArgumentError (start not an ellipsoid, unknown parameter), ConvergenceError.
#[pyfunction]
#[pyo3(signature = (start, parameter = "e", stop = 0.9, *, stability = true, step = 1e-2,
                    max_step = 5e-2, max_points = 2000))]
#[allow(clippy::too_many_arguments)]
fn follow(
    py: Python<'_>,
    start: PyRef<'_, RelativeEquilibrium>,
    parameter: &str,
    #[pyo3(from_py_with = real)] stop: f64,
    stability: bool,
    #[pyo3(from_py_with = real)] step: f64,
    #[pyo3(from_py_with = real)] max_step: f64,
    #[pyo3(from_py_with = size)] max_points: usize,
) -> PyResult<Branch> {
    let Some((fluid, fig)) = start.figure() else {
        return Err(to_py(Error::invalid(
            "start",
            "continuation follows the figures of lieflow.ellipsoids (maclaurin, jacobi, \
             dedekind, riemann_s)",
        )));
    };
    if !stop.is_finite() {
        return Err(to_py(Error::invalid(
            "stop",
            format!("expected a finite value, got {stop}"),
        )));
    }
    let min_step = Options::default().min_step;
    if !(step >= min_step && max_step >= step && max_step.is_finite()) {
        return Err(to_py(Error::invalid(
            "step",
            format!(
                "expected {min_step:e} <= step <= max_step < inf, got step = {step}, \
                 max_step = {max_step}"
            ),
        )));
    }
    if max_points < 2 {
        return Err(to_py(Error::invalid(
            "max_points",
            format!("expected at least 2, got {max_points}"),
        )));
    }
    let family = EllipsoidFamily::of(fluid, fig).py()?;
    let opts = Options {
        step,
        max_step,
        max_points,
        ..Options::default()
    };
    let u = family.unknowns_of(fig);
    run(
        py,
        family,
        u,
        parameter.to_owned(),
        stop,
        stability,
        None,
        opts,
    )
}

#[pymethods]
impl Branch {
    /// The points (relative equilibria) in the order of continuation.
    #[getter]
    fn points(&self) -> PyResult<Vec<RelativeEquilibrium>> {
        self.inner
            .points
            .iter()
            .map(|p| figure_of(&self.family, &p.u))
            .collect()
    }

    /// The name of the followed parameter.
    #[getter]
    fn parameter(&self) -> &str {
        &self.parameter
    }

    /// The parameter's values at the points.
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_iter(py, self.inner.points.iter().map(|p| p.parameter))
    }

    /// A named parameter of the family at every point (e.g. "Omega2_over_piGrho").
    fn values_of<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let v: Vec<f64> = self
            .inner
            .points
            .iter()
            .map(|p| self.family.parameter(name, &p.u))
            .collect::<lieflow::Result<_>>()
            .py()?;
        Ok(PyArray1::from_vec(py, v))
    }

    /// The spectral stability flag at every point (bool array; empty if not monitored).
    #[getter]
    fn stability<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        self.flags(py, 0)
    }

    /// The energy–momentum verdict at every point (True: the Hessian is definite).
    #[getter]
    fn energy_momentum<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        self.flags(py, 1)
    }

    /// The special points in the order met.
    #[getter]
    fn special_points(&self) -> Vec<SpecialPoint> {
        self.inner
            .special
            .iter()
            .map(|s| SpecialPoint {
                family: self.family.clone(),
                parameter: self.parameter.clone(),
                inner: s.clone(),
            })
            .collect()
    }

    /// Why continuation ended: "reached", "max_points" or "stuck: <reason>".
    #[getter]
    fn end(&self) -> String {
        match &self.inner.end {
            End::Reached => "reached".into(),
            End::MaxPoints => "max_points".into(),
            End::Stuck(why) => format!("stuck: {why}"),
        }
    }

    /// Follows the other branch through a special point of kind "branch" (the kernel direction
    /// orthogonal to the branch the point was found on), in `parameter` (default: this
    /// branch's) until `stop` (default: this branch's). `direction`: None (the default) goes
    /// the way the parameter moves towards `stop`; +1 the way a1 - a2 grows, -1 the other way.
    ///
    /// Raises:
    ///     InvalidArgumentError (not a branch point of this family).
    #[pyo3(signature = (point, *, stop = None, parameter = None, direction = None))]
    fn switch(
        &self,
        py: Python<'_>,
        point: PyRef<'_, SpecialPoint>,
        #[pyo3(from_py_with = real_opt)] stop: Option<f64>,
        parameter: Option<&str>,
        #[pyo3(from_py_with = real_opt)] direction: Option<f64>,
    ) -> PyResult<Branch> {
        if point.inner.kind != cont::Kind::Branch {
            return Err(to_py(Error::invalid(
                "point",
                format!(
                    "expected a special point of kind 'branch', got '{}'",
                    point.inner.kind.name()
                ),
            )));
        }
        // The family the point was found on (not necessarily this branch's).
        let family = point.family.clone();
        let parameter = parameter.unwrap_or(&self.parameter).to_owned();
        let stop = stop.unwrap_or(self.stop);
        if !stop.is_finite() {
            return Err(to_py(Error::invalid(
                "stop",
                format!("expected a finite value, got {stop}"),
            )));
        }
        let sense = match direction {
            None => Sense::Towards(&parameter, stop),
            Some(1.0) => Sense::Splitting,
            Some(-1.0) => Sense::Joining,
            Some(d) => {
                return Err(to_py(Error::invalid(
                    "direction",
                    format!("expected None, 1 or -1, got {d}"),
                )))
            }
        };
        let dir = family.switch_direction(&point.inner.point, sense).py()?;
        let u = &point.inner.point.u;
        run(
            py,
            family,
            u.clone(),
            parameter,
            stop,
            self.monitored,
            Some(dir),
            self.opts.clone(),
        )
    }

    /// Plots the branch (matplotlib): `y` against `x` (parameter names; default x = this
    /// branch's parameter, y = "Omega2_over_piGrho"), stable segments solid and unstable ones
    /// dashed, special points marked. Returns the Axes.
    #[pyo3(signature = (ax = None, *, x = None, y = "Omega2_over_piGrho", **kwargs))]
    fn plot<'py>(
        slf: &Bound<'py, Self>,
        ax: Option<Bound<'py, PyAny>>,
        x: Option<&str>,
        y: &str,
        kwargs: Option<&Bound<'py, pyo3::types::PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        let f = py.import("lieflow.continuation")?.getattr("_plot_branch")?;
        let x = x.unwrap_or(&slf.get().parameter).to_owned();
        let args = PyTuple::new(
            py,
            [slf.clone().into_any(), ax.into_pyobject(py)?.into_any()],
        )?;
        let kw = pyo3::types::PyDict::new(py);
        if let Some(k) = kwargs {
            kw.update(k.as_mapping())?;
        }
        kw.set_item("x", x)?;
        kw.set_item("y", y)?;
        f.call(args, Some(&kw))
    }

    fn __len__(&self) -> usize {
        self.inner.points.len()
    }

    fn __repr__(&self) -> String {
        let (first, last) = (
            self.inner.points.first().map_or(f64::NAN, |p| p.parameter),
            self.inner.points.last().map_or(f64::NAN, |p| p.parameter),
        );
        format!(
            "Branch({} points, {} from {first:.6} to {last:.6}, {} special points, end={})",
            self.inner.points.len(),
            self.parameter,
            self.inner.special.len(),
            self.end()
        )
    }
}

impl Branch {
    fn flags<'py>(&self, py: Python<'py>, k: usize) -> Bound<'py, PyArray1<bool>> {
        let v: Vec<bool> = if self.monitored {
            self.inner.points.iter().map(|p| p.stable[k]).collect()
        } else {
            Vec::new()
        };
        PyArray1::from_vec(py, v)
    }
}

#[pymethods]
impl SpecialPoint {
    /// "branch", "fold" or "stability".
    #[getter]
    fn kind(&self) -> &'static str {
        self.inner.kind.name()
    }

    /// For kind "stability": which verdict changes ("spectral" or "energy_momentum").
    #[getter]
    fn verdict(&self) -> Option<&'static str> {
        self.inner.verdict.map(|k| VERDICTS[k])
    }

    /// The followed parameter's value.
    #[getter]
    fn value(&self) -> f64 {
        self.inner.point.parameter
    }

    /// The verdicts at the point (spectral, energy_momentum) if monitored (for kind
    /// "stability": on the far side of the change).
    #[getter]
    fn stable(&self) -> Vec<bool> {
        self.inner.point.stable.clone()
    }

    /// The relative equilibrium there.
    #[getter]
    fn point(&self) -> PyResult<RelativeEquilibrium> {
        figure_of(&self.family, &self.inner.point.u)
    }

    /// The family's parameters by name (e.g. `.e`, `.Omega2_over_piGrho`).
    fn __getattr__(&self, name: &str) -> PyResult<f64> {
        if ell::PARAMETERS.contains(&name) {
            self.family.parameter(name, &self.inner.point.u).py()
        } else {
            Err(pyo3::exceptions::PyAttributeError::new_err(format!(
                "'SpecialPoint' has no attribute '{name}'"
            )))
        }
    }

    fn __repr__(&self) -> String {
        let verdict = self
            .inner
            .verdict
            .map_or(String::new(), |k| format!(", verdict={}", VERDICTS[k]));
        format!(
            "SpecialPoint(kind={}{verdict}, {}={:.12})",
            self.inner.kind.name(),
            self.parameter,
            self.inner.point.parameter
        )
    }
}

/// Adds `follow`, `Branch` and `SpecialPoint` to `lieflow.continuation`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(follow, m)?)?;
    m.add_class::<Branch>()?;
    m.add_class::<SpecialPoint>()?;
    Ok(())
}
