//! Pseudo-arclength continuation of a one-parameter family of solutions of F(u) = 0,
//! F: ℝᴺ → ℝᴺ⁻¹ (Keller 1977; Allgower & Georg, *Introduction to Numerical Continuation
//! Methods*, ch. 2, 8), with the detection and location of folds, simple branch points and
//! changes of a monitored verdict (stability), and branch switching at a simple branch point.
//!
//! The layer knows no system: a [`Family`] gives F and (optionally) its Jacobian; the caller
//! gives the parameter to report (any function of u, e.g. an eccentricity) and, optionally, a
//! monitor (a stability verdict) evaluated at every point.
//!
//! # The method
//! - **Tangent.** t spans ker DF(u) (the right singular vector of the (N−1)×N Jacobian with
//!   the smallest singular value), oriented so that t·t_prev > 0.
//! - **Step.** Predictor v = u + s t; corrector: Newton's method on the N×N system
//!   F(v) = 0, t·(v − u) = s (the pseudo-arclength condition). The step s grows by 1.5 after an
//!   easy step (≤ 3 Newton iterations) up to `max_step` and halves after a failed one (or one
//!   whose tangent turns by more than 30°), down to `min_step`.
//! - **Test functions** between consecutive points: a simple branch point is where
//!   τ_B = det [DF(u); tᵀ] changes sign (the augmented Jacobian is singular there and only there
//!   on a regular branch); a fold in the parameter π is where τ_F = ∇π·t changes sign; a
//!   monitor change is where the verdict differs. Each is located in the arclength σ from the
//!   previous point: secant steps and bisection on corrected points (each corrected from the
//!   Hermite interpolant of the bracket), then, for a smooth test, the root of the cubic through
//!   the test at four well-determined points around it. The bracket is narrowed to
//!   [`LOCATE_TOL`]; what is reached depends on the test's own accuracy: branch points of the
//!   ellipsoid families to ~1e-10 in the parameter, folds in the parameter's value to ~1e-10 (in
//!   position to ~1e-6: the parameter is flat there), a verdict's margin as well as the
//!   margin is computed (an energy–momentum Hessian by finite differences: ~1e-8).
//! - **Switching.** At a simple branch point ker DF is two-dimensional; the direction of the
//!   other branch is the kernel vector orthogonal to the tangent of the followed one (exact for
//!   the symmetry-breaking pitchforks of relative equilibria; in general the start of a Newton
//!   correction that lands on the other branch), and continuation starts from the branch point
//!   along it.

mod corrector;
mod locate;
mod tangent;

use crate::error::{Error, Result};
use crate::numerics::fd::{self, Scheme::Richardson};
use crate::numerics::linalg::norm;
use crate::Mat;
use corrector::correct;
use tangent::{branch_test, tangent};

pub use tangent::switch_direction;

/// The bracket of a special point is narrowed until the parameter is known to this relative
/// tolerance (relative to 1 + |π|); the accuracy reached also depends on the test (module docs).
pub const LOCATE_TOL: f64 = 1e-11;

/// A fold is tested only where |dπ/ds| exceeds this (relative to 1 + |π|) on one side: a
/// parameter constant along the family has a derivative of round-off size and random sign.
const FOLD_FLOOR: f64 = 1e-8;

/// A one-parameter family: the zero set of F: ℝᴺ → ℝᴺ⁻¹ near a regular point is a curve.
pub trait Family {
    /// N, the number of unknowns.
    fn unknowns(&self) -> usize;

    /// F(u), N − 1 values; an error where u lies outside the family's domain.
    fn residual(&self, u: &[f64]) -> Result<Vec<f64>>;

    /// DF(u), an (N−1)×N matrix. The default is central differences with steps
    /// 1e-4·max(1, |u_k|) and one Richardson extrapolation (error ~1e-12 relative for smooth F).
    fn jacobian(&self, u: &[f64]) -> Result<Mat> {
        let h: Vec<f64> = u.iter().map(|x| 1e-4 * x.abs().max(1.0)).collect();
        fd::jacobian(&|v: &[f64]| self.residual(v), u, &h, Richardson)
    }
}

/// Step control and limits of [`follow`].
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// The first arclength step.
    pub step: f64,
    /// The largest step.
    pub max_step: f64,
    /// The smallest step: below it the branch ends (reported in [`Branch::end`]).
    pub min_step: f64,
    /// The largest number of points.
    pub max_points: usize,
    /// Newton tolerance on the correction, relative to 1 + |u|.
    pub tol: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            step: 1e-2,
            max_step: 5e-2,
            min_step: 1e-9,
            max_points: 2000,
            tol: 1e-13,
        }
    }
}

/// A point of a branch.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// The solution u (F(u) = 0 to the Newton tolerance).
    pub u: Vec<f64>,
    /// The unit tangent, oriented along the direction of continuation.
    pub tangent: Vec<f64>,
    /// The parameter π(u).
    pub parameter: f64,
    /// The monitor's verdicts (empty without a monitor).
    pub stable: Vec<bool>,
    /// The monitor's margins (see [`Indicator`]).
    pub margins: Vec<f64>,
}

/// A monitored verdict at a point: whether it holds, and a continuous margin whose change of
/// sign marks where it changes (e.g. the smallest eigenvalue of a Hessian). Where the margins
/// of two points have opposite signs the change is located as the root of the margin (a smooth
/// test); otherwise by bisection on the verdict. A margin of NaN means "no margin": bisection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Indicator {
    /// The verdict.
    pub stable: bool,
    /// The margin (> 0 where stable, up to the verdict's tolerance), or NaN.
    pub margin: f64,
}

/// The kind of a special point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A simple branch point (τ_B = det[DF; tᵀ] changes sign): another branch crosses.
    Branch,
    /// A fold (turning point) of the parameter (dπ/ds changes sign).
    Fold,
    /// A monitored verdict changes (e.g. stable → unstable).
    Stability,
}

impl Kind {
    /// "branch", "fold" or "stability".
    pub fn name(self) -> &'static str {
        match self {
            Kind::Branch => "branch",
            Kind::Fold => "fold",
            Kind::Stability => "stability",
        }
    }
}

/// A located special point.
#[derive(Clone, Debug, PartialEq)]
pub struct Special {
    /// What happens there.
    pub kind: Kind,
    /// The point (for [`Kind::Stability`] the first point on the far side, within the
    /// location tolerance).
    pub point: Point,
    /// It lies between `points[index − 1]` and `points[index]` of the branch.
    pub index: usize,
    /// For [`Kind::Stability`]: which of the monitor's verdicts changes.
    pub verdict: Option<usize>,
}

/// Why continuation ended.
#[derive(Clone, Debug, PartialEq)]
pub enum End {
    /// The parameter reached the requested value (the last point has π = stop).
    Reached,
    /// The largest number of points was reached.
    MaxPoints,
    /// The corrector failed at the smallest step (the message says why): the family ends, or
    /// leaves the domain of F, there.
    Stuck(String),
}

/// A followed branch.
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    /// The points in the order of continuation.
    pub points: Vec<Point>,
    /// Special points in the order met.
    pub special: Vec<Special>,
    /// Why it ended.
    pub end: End,
}

/// The parameter π(u) to report and stop on.
pub type Parameter<'a> = &'a dyn Fn(&[f64]) -> Result<f64>;
/// Verdicts to monitor along the branch (e.g. the spectral and the energy–momentum stability);
/// the same number at every point.
pub type Monitor<'a> = &'a dyn Fn(&[f64]) -> Result<Vec<Indicator>>;

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// What is evaluated at every point.
struct Probe<'a> {
    family: &'a dyn Family,
    parameter: Parameter<'a>,
    monitor: Option<Monitor<'a>>,
    tol: f64,
}

/// A point with its test-function values.
#[derive(Clone)]
struct Probed {
    point: Point,
    branch: f64,
    fold: f64,
}

impl Probe<'_> {
    fn probe(&self, u: Vec<f64>, along: &[f64]) -> Result<Probed> {
        let (t, j) = tangent(self.family, &u, along)?;
        let parameter = (self.parameter)(&u)?;
        let h = 1e-6 * (1.0 + norm(&u));
        let step =
            |sg: f64| -> Vec<f64> { u.iter().zip(&t).map(|(a, b)| a + sg * h * b).collect() };
        let fold = ((self.parameter)(&step(1.0))? - (self.parameter)(&step(-1.0))?) / (2.0 * h);
        let verdicts = match self.monitor {
            Some(m) => m(&u)?,
            None => Vec::new(),
        };
        Ok(Probed {
            branch: branch_test(&j, &t),
            fold,
            point: Point {
                u,
                tangent: t,
                parameter,
                stable: verdicts.iter().map(|v| v.stable).collect(),
                margins: verdicts.iter().map(|v| v.margin).collect(),
            },
        })
    }
}

fn sign_change(x: f64, y: f64) -> bool {
    (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0)
}

/// A family in the scaled unknowns w = D⁻¹u, D = diag(`scale`): F(Dw), with the Jacobian
/// DF(Dw)·D.
struct Scaled<'a> {
    family: &'a dyn Family,
    scale: &'a [f64],
}

impl Scaled<'_> {
    /// u = Dw.
    fn unscale(&self, w: &[f64]) -> Vec<f64> {
        w.iter().zip(self.scale).map(|(x, d)| x * d).collect()
    }

    /// A point of the scaled family in the unknowns u: u = Dw, the unit tangent along Dt.
    fn point(&self, mut p: Point) -> Point {
        p.u = self.unscale(&p.u);
        let t = self.unscale(&p.tangent);
        let nt = norm(&t);
        p.tangent = t.iter().map(|x| x / nt).collect();
        p
    }
}

impl Family for Scaled<'_> {
    fn unknowns(&self) -> usize {
        self.family.unknowns()
    }

    fn residual(&self, w: &[f64]) -> Result<Vec<f64>> {
        self.family.residual(&self.unscale(w))
    }

    fn jacobian(&self, w: &[f64]) -> Result<Mat> {
        let mut j = self.family.jacobian(&self.unscale(w))?;
        for (c, d) in self.scale.iter().enumerate() {
            for r in 0..j.nrows() {
                j[(r, c)] *= d;
            }
        }
        Ok(j)
    }
}

/// Follows the family through `start` (a solution, corrected first) until the parameter π
/// reaches `stop`, the corrector fails at the smallest step, or `max_points` points are found.
/// The direction: along `direction` if given (branch switching), else the one in which π moves
/// towards `stop`. Special points (branch points, folds of π, changes of the monitor's verdict)
/// are located to [`LOCATE_TOL`] and listed in order.
///
/// The arclength (the steps of [`Options`], the tangents' normalisation and the arclength
/// condition) is measured in the unknowns scaled by their magnitudes at the start, u_k/d_k with
/// d_k = max(|start_k|, 1): an unknown that is large where the others are of order one (the
/// pressure of a flattened ellipsoid) does not take up the whole step. The points and tangents
/// returned are in u.
///
/// Errors: `start` of the wrong length or not finite, the first correction failing (start is
/// not near the family), a parameter or monitor error.
pub fn follow(
    family: &dyn Family,
    start: &[f64],
    parameter: Parameter<'_>,
    stop: f64,
    monitor: Option<Monitor<'_>>,
    direction: Option<&[f64]>,
    opts: &Options,
) -> Result<Branch> {
    let n = family.unknowns();
    crate::check::len_of("start", start, n)?;
    crate::check::finite_slice("start", start)?;
    if let Some(d) = direction {
        crate::check::len_of("direction", d, n)?;
    }
    let scale: Vec<f64> = start.iter().map(|x| x.abs().max(1.0)).collect();
    let scaled = Scaled {
        family,
        scale: &scale,
    };
    let to_w = |u: &[f64]| -> Vec<f64> { u.iter().zip(&scale).map(|(x, d)| x / d).collect() };
    let scaled = &scaled;
    let param = |w: &[f64]| parameter(&scaled.unscale(w));
    let mon = monitor.map(|m| move |w: &[f64]| m(&scaled.unscale(w)));
    let branch = follow_unscaled(
        scaled,
        &to_w(start),
        &param,
        stop,
        mon.as_ref().map(|m| m as Monitor<'_>),
        direction.map(to_w).as_deref(),
        opts,
    )?;
    Ok(Branch {
        points: branch.points.into_iter().map(|p| scaled.point(p)).collect(),
        special: branch
            .special
            .into_iter()
            .map(|sp| Special {
                point: scaled.point(sp.point),
                ..sp
            })
            .collect(),
        end: branch.end,
    })
}

/// [`follow`] with the arclength measured in the unknowns as they are.
fn follow_unscaled(
    family: &dyn Family,
    start: &[f64],
    parameter: Parameter<'_>,
    stop: f64,
    monitor: Option<Monitor<'_>>,
    direction: Option<&[f64]>,
    opts: &Options,
) -> Result<Branch> {
    let n = family.unknowns();
    if n < 2 {
        return Err(Error::invalid(
            "family",
            "needs at least 2 unknowns (N − 1 ≥ 1 equations)",
        ));
    }
    let probe = Probe {
        family,
        parameter,
        monitor,
        tol: opts.tol,
    };
    // Correct the start onto the family (arclength 0 along the initial direction). A given
    // direction is used as it is (at a branch point the kernel is two-dimensional).
    let mut t = match direction {
        Some(d) => {
            let nd = norm(d);
            if !(nd > 0.0 && nd.is_finite()) {
                return Err(Error::invalid(
                    "direction",
                    "expected a finite nonzero vector",
                ));
            }
            d.iter().map(|x| x / nd).collect()
        }
        None => tangent(family, start, start)?.0,
    };
    // From a given direction the start is taken as a solution (a located branch point, where
    // the corrector's matrix is singular); otherwise it is corrected first.
    let u0 = if direction.is_some() {
        start.to_vec()
    } else {
        correct(family, start, &t, 0.0, opts.tol)?.0
    };
    if direction.is_none() {
        t = tangent(family, &u0, &t)?.0;
        let p0 = parameter(&u0)?;
        let h = 1e-6 * (1.0 + norm(&u0));
        let pp = parameter(
            &u0.iter()
                .zip(&t)
                .map(|(a, b)| a + h * b)
                .collect::<Vec<_>>(),
        )?;
        if (pp - p0) * (stop - p0) < 0.0 {
            t.iter_mut().for_each(|x| *x = -*x);
        }
    }
    let mut prev = probe.probe(u0, &t)?;
    if direction.is_some() {
        // Keep the given direction at the start (the kernel may be two-dimensional there), and
        // no test-function sign at the branch point itself.
        prev.point.tangent = t;
        prev.branch = f64::NAN;
        prev.fold = f64::NAN;
    }
    let mut first_of_switch = direction.is_some();
    let mut points = vec![prev.point.clone()];
    let mut special = Vec::new();
    let mut s = opts.step;
    let end = loop {
        if points.len() >= opts.max_points {
            break End::MaxPoints;
        }
        let step = correct(family, &prev.point.u, &prev.point.tangent, s, opts.tol)
            .and_then(|(v, it)| Ok((probe.probe(v, &prev.point.tangent)?, it)));
        let (next, iters) = match step {
            Ok((p, it)) if dot(&p.point.tangent, &prev.point.tangent) > 0.866 => (p, it),
            other => {
                if s * 0.5 < opts.min_step {
                    let why = match other {
                        Err(e) => e.to_string(),
                        Ok(_) => {
                            "the tangent turns by more than 30° within the smallest step".into()
                        }
                    };
                    break End::Stuck(why);
                }
                s *= 0.5;
                continue;
            }
        };
        let index = points.len();
        // The stop, if the parameter crosses it in this step: the corrected point there.
        let (pa, pb) = (prev.point.parameter - stop, next.point.parameter - stop);
        let stop_point = if pa != 0.0 && (pb == 0.0 || sign_change(pa, pb)) {
            let test = |q: &Probed| q.point.parameter - stop;
            let p = probe.locate(&prev, &next, s, 1e-15, false, &|q| {
                if q.point.parameter == stop {
                    0.0
                } else {
                    test(q)
                }
            });
            Some(if test(&p).abs() < test(&next).abs() {
                p
            } else {
                next.clone()
            })
        } else {
            None
        };
        // Special points between prev and next (and before the stop), in the order met. After
        // a switch the first step starts at the branch point itself, where the tests are
        // degenerate: none are compared there.
        let mut found: Vec<(f64, Special)> = Vec::new();
        let floor = FOLD_FLOOR * (1.0 + prev.point.parameter.abs());
        if !first_of_switch {
            if sign_change(prev.branch, next.branch) {
                let p = probe.locate(&prev, &next, s, LOCATE_TOL, true, &|q| q.branch);
                found.push((
                    dist(&prev.point, &p.point),
                    special_at(Kind::Branch, p, index),
                ));
            }
            if sign_change(prev.fold, next.fold) && prev.fold.abs().max(next.fold.abs()) > floor {
                let p = probe.locate(&prev, &next, s, LOCATE_TOL, true, &|q| q.fold);
                found.push((
                    dist(&prev.point, &p.point),
                    special_at(Kind::Fold, p, index),
                ));
            }
            for (w, (&a, &b)) in prev.point.stable.iter().zip(&next.point.stable).enumerate() {
                if a == b {
                    continue;
                }
                let (ma, mb) = (prev.point.margins[w], next.point.margins[w]);
                let p = if sign_change(ma, mb) {
                    probe.locate(&prev, &next, s, LOCATE_TOL, true, &|q| q.point.margins[w])
                } else {
                    probe.locate(&prev, &next, s, LOCATE_TOL, false, &|q| {
                        if q.point.stable.get(w) == Some(&a) {
                            1.0
                        } else {
                            -1.0
                        }
                    })
                };
                let mut sp = special_at(Kind::Stability, p, index);
                sp.verdict = Some(w);
                // The verdicts on the far side of the change.
                sp.point.stable = next.point.stable.clone();
                found.push((dist(&prev.point, &sp.point), sp));
            }
        }
        first_of_switch = false;
        if let Some(stop_point) = &stop_point {
            let reach = dist(&prev.point, &stop_point.point);
            found.retain(|(d, _)| *d <= reach);
        }
        found.sort_by(|x, y| x.0.total_cmp(&y.0));
        special.extend(found.into_iter().map(|(_, sp)| sp));
        if let Some(p) = stop_point {
            points.push(p.point);
            break End::Reached;
        }
        points.push(next.point.clone());
        prev = next;
        if iters <= 3 {
            s = (1.5 * s).min(opts.max_step);
        }
    };
    Ok(Branch {
        points,
        special,
        end,
    })
}

fn dist(a: &Point, b: &Point) -> f64 {
    let d: Vec<f64> = a.u.iter().zip(&b.u).map(|(x, y)| x - y).collect();
    norm(&d)
}

fn special_at(kind: Kind, p: Probed, index: usize) -> Special {
    Special {
        kind,
        point: p.point,
        index,
        verdict: None,
    }
}
