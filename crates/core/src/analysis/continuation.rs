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
//!   monitor change is where the verdict differs. Each is located by bisection (with a secant
//!   step for the smooth τ) in the arclength σ from the previous point, every trial point being
//!   a corrected point of the branch, until the parameter is known to [`LOCATE_TOL`].
//! - **Switching.** At a simple branch point ker DF is two-dimensional; the direction of the
//!   other branch is the kernel vector orthogonal to the tangent of the followed one (exact for
//!   the symmetry-breaking pitchforks of relative equilibria; in general the start of a Newton
//!   correction that lands on the other branch), and continuation starts from the branch point
//!   along it.

use crate::error::{Error, Result};
use crate::Mat;
use faer::linalg::solvers::Solve;

/// How precisely special points are located: the parameter to this relative tolerance
/// (relative to 1 + |π|).
pub const LOCATE_TOL: f64 = 1e-11;

/// Newton iterations of the corrector.
const MAX_NEWTON: usize = 12;

/// A corrector whose update stops decreasing is accepted below this relative size.
const STAGNATION: f64 = 1e-10;

/// A one-parameter family: the zero set of F: ℝᴺ → ℝᴺ⁻¹ near a regular point is a curve.
pub trait Family {
    /// N, the number of unknowns.
    fn unknowns(&self) -> usize;

    /// F(u), N − 1 values; an error where u lies outside the family's domain.
    fn residual(&self, u: &[f64]) -> Result<Vec<f64>>;

    /// DF(u), an (N−1)×N matrix. The default is central differences with steps
    /// 1e-6·max(1, |u_k|) and one Richardson extrapolation (error ~1e-12 relative for smooth F).
    fn jacobian(&self, u: &[f64]) -> Result<Mat> {
        let n = u.len();
        let mut cols = Vec::with_capacity(n);
        let mut v = u.to_vec();
        for k in 0..n {
            let h = 1e-4 * u[k].abs().max(1.0);
            let mut d = |h: f64| -> Result<Vec<f64>> {
                v[k] = u[k] + h;
                let fp = self.residual(&v)?;
                v[k] = u[k] - h;
                let fm = self.residual(&v)?;
                v[k] = u[k];
                Ok(fp
                    .iter()
                    .zip(&fm)
                    .map(|(p, m)| (p - m) / (2.0 * h))
                    .collect())
            };
            let (d1, d2) = (d(h)?, d(0.5 * h)?);
            cols.push(
                d1.iter()
                    .zip(&d2)
                    .map(|(a, b)| (4.0 * b - a) / 3.0)
                    .collect::<Vec<f64>>(),
            );
        }
        Ok(Mat::from_fn(n - 1, n, |i, j| cols[j][i]))
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

fn norm(x: &[f64]) -> f64 {
    dot(x, x).sqrt()
}

/// The unit vectors spanning ker DF(u) (the `k` right singular vectors with the smallest
/// singular values), and DF.
fn kernel(family: &dyn Family, u: &[f64], k: usize) -> Result<(Vec<Vec<f64>>, Mat)> {
    let n = u.len();
    let j = family.jacobian(u)?;
    // Pad to N×N with a zero row so that the SVD returns all N right singular vectors.
    let jp = Mat::from_fn(n, n, |r, c| if r + 1 < n { j[(r, c)] } else { 0.0 });
    let svd = jp.svd().map_err(|e| Error::NotConverged {
        what: format!("SVD of the Jacobian of the family ({e:?})"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    })?;
    let v = svd.V();
    Ok((
        (0..k)
            .map(|i| (0..n).map(|r| v[(r, n - 1 - i)]).collect())
            .collect(),
        j,
    ))
}

/// The unit tangent at u oriented along `along` (t·along ≥ 0).
fn tangent(family: &dyn Family, u: &[f64], along: &[f64]) -> Result<(Vec<f64>, Mat)> {
    let (mut ker, j) = kernel(family, u, 1)?;
    let mut t = ker.remove(0);
    if dot(&t, along) < 0.0 {
        t.iter_mut().for_each(|x| *x = -*x);
    }
    Ok((t, j))
}

/// det [DF; tᵀ], the branch-point test function.
fn branch_test(j: &Mat, t: &[f64]) -> f64 {
    let n = t.len();
    let m = Mat::from_fn(n, n, |r, c| if r + 1 < n { j[(r, c)] } else { t[c] });
    m.determinant()
}

/// Newton's method for F(v) = 0, t·(v − u) = s from v = u + s t. Returns the point and the
/// number of iterations.
fn correct(
    family: &dyn Family,
    u: &[f64],
    t: &[f64],
    s: f64,
    tol: f64,
) -> Result<(Vec<f64>, usize)> {
    let n = u.len();
    let mut v: Vec<f64> = u.iter().zip(t).map(|(a, b)| a + s * b).collect();
    let scale = 1.0 + norm(u);
    let mut prev = f64::INFINITY;
    for iter in 1..=MAX_NEWTON {
        let f = family.residual(&v)?;
        let j = family.jacobian(&v)?;
        let m = Mat::from_fn(n, n, |r, c| if r + 1 < n { j[(r, c)] } else { t[c] });
        let rhs = Mat::from_fn(n, 1, |r, _| {
            if r + 1 < n {
                -f[r]
            } else {
                s - dot(t, &v) + dot(t, u)
            }
        });
        let rhs = m.partial_piv_lu().solve(&rhs);
        let mut dn = 0.0f64;
        for (k, vk) in v.iter_mut().enumerate() {
            *vk += rhs[(k, 0)];
            dn = dn.max(rhs[(k, 0)].abs());
        }
        if !dn.is_finite() || v.iter().any(|x| !x.is_finite()) {
            break;
        }
        // Converged, or stagnating at the level of round-off (near a branch point the matrix
        // is ill-conditioned and the update stops decreasing below STAGNATION·scale).
        if dn <= tol * scale || (dn >= prev && dn <= STAGNATION * scale) {
            let f = family.residual(&v)?;
            if f.iter().all(|x| x.is_finite()) {
                return Ok((v, iter));
            }
            break;
        }
        prev = dn;
    }
    Err(Error::NotConverged {
        what: "continuation corrector (Newton on F(u) = 0 with the arclength condition)".into(),
        iterations: MAX_NEWTON,
        residual: f64::NAN,
        tol,
    })
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

    /// The corrected point at arclength σ from `from` along its tangent.
    fn at(&self, from: &Point, sigma: f64) -> Result<Probed> {
        let (v, _) = correct(self.family, &from.u, &from.tangent, sigma, self.tol)?;
        self.probe(v, &from.tangent)
    }

    /// Locates where `test` changes sign between `a` (σ = 0) and `b` (σ = s): secant steps
    /// (every third a bisection) on corrected points until the parameter is known to
    /// `rel_tol`·(1 + |π|) or the corrector fails (within ~1e-9 of a branch point the corrected
    /// points are ill-determined: the two branches cross). For a `smooth` test the result is the
    /// root of the test's linear interpolation on the last bracket, the point there by cubic
    /// Hermite interpolation of the bracket's points and tangents (error O(Δσ⁴)); otherwise
    /// (a verdict) the corrected point on the far side of the change.
    fn locate(
        &self,
        a: &Probed,
        b: &Probed,
        s: f64,
        rel_tol: f64,
        smooth: bool,
        test: &dyn Fn(&Probed) -> f64,
    ) -> Result<Probed> {
        let (mut lo, mut hi) = (0.0, s);
        let (mut flo, mut fhi) = (test(a), test(b));
        let (mut near, mut far) = (a.clone(), b.clone());
        let tol = rel_tol * (1.0 + a.point.parameter.abs());
        let dpds = (b.point.parameter - a.point.parameter).abs() / s.abs().max(f64::MIN_POSITIVE);
        // A trial where the corrector failed (near a branch point): the next trials approach
        // it from the two sides of the bracket in turn.
        let mut bad: Option<f64> = None;
        let mut failures = 0;
        for iter in 0..200 {
            if (hi - lo) * dpds.max(1e-3) <= tol || failures >= 8 {
                break;
            }
            let sec = lo - flo * (hi - lo) / (fhi - flo);
            let mid = if let Some(x) = bad {
                if failures % 2 == 1 {
                    0.5 * (lo + x)
                } else {
                    0.5 * (x + hi)
                }
            } else if smooth && iter % 3 != 2 && sec.is_finite() && sec > lo && sec < hi {
                sec.clamp(lo + 0.01 * (hi - lo), hi - 0.01 * (hi - lo))
            } else {
                0.5 * (lo + hi)
            };
            match self.at(&a.point, mid) {
                Err(_) => {
                    bad = Some(mid);
                    failures += 1;
                }
                Ok(p) => {
                    let fm = test(&p);
                    if fm == 0.0 {
                        return Ok(p);
                    }
                    if (fm > 0.0) == (flo > 0.0) {
                        (lo, flo, near) = (mid, fm, p);
                    } else {
                        (hi, fhi, far) = (mid, fm, p);
                    }
                }
            }
        }
        if !smooth {
            return Ok(far);
        }
        // The root of the interpolated test; the point there by cubic Hermite interpolation
        // between corrected points at σ ± δ, δ = 10⁻³|s|, away from the ill-determined
        // neighbourhood of a branch point (error O(δ⁴)); the bracket's ends if those fail. With σ
        // measured along a's tangent t_a, du/dσ = t/(t·t_a).
        let frac = flo / (flo - fhi);
        let root = lo
            + if frac.is_finite() {
                frac.clamp(0.0, 1.0)
            } else {
                0.5
            } * (hi - lo);
        let delta = 1e-3 * s.abs();
        let along = near.point.tangent.clone();
        let far_fallback = far.clone();
        let (left, right, w, h) = match (
            self.at(&a.point, root - delta),
            self.at(&a.point, root + delta),
        ) {
            (Ok(l), Ok(r)) => (l, r, 0.5, 2.0 * delta),
            _ => (near, far, (root - lo) / (hi - lo), hi - lo),
        };
        let ta = &a.point.tangent;
        let slope = |p: &Probed| -> Vec<f64> {
            let c = dot(&p.point.tangent, ta);
            p.point.tangent.iter().map(|x| x / c).collect()
        };
        let (d0, d1) = (slope(&left), slope(&right));
        let (h00, h10, h01, h11) = (
            (1.0 + 2.0 * w) * (1.0 - w) * (1.0 - w),
            w * (1.0 - w) * (1.0 - w),
            w * w * (3.0 - 2.0 * w),
            w * w * (w - 1.0),
        );
        let u: Vec<f64> = (0..left.point.u.len())
            .map(|k| {
                h00 * left.point.u[k] + h10 * h * d0[k] + h01 * right.point.u[k] + h11 * h * d1[k]
            })
            .collect();
        // The branch's own direction there (at a branch point the kernel is two-dimensional and
        // the probe's tangent arbitrary): the interpolated slope.
        let mut t: Vec<f64> = d0
            .iter()
            .zip(&d1)
            .map(|(x, y)| (1.0 - w) * x + w * y)
            .collect();
        let nt = norm(&t);
        t.iter_mut().for_each(|x| *x /= nt);
        if u.iter().chain(&t).any(|x| !x.is_finite()) {
            return Ok(far_fallback);
        }
        let mut p = self.probe(u, &along)?;
        p.point.tangent = t;
        Ok(p)
    }
}

fn sign_change(x: f64, y: f64) -> bool {
    (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0)
}

/// Follows the family through `start` (a solution, corrected first) until the parameter π
/// reaches `stop`, the corrector fails at the smallest step, or `max_points` points are found.
/// The direction: along `direction` if given (branch switching), else the one in which π moves
/// towards `stop`. Special points (branch points, folds of π, changes of the monitor's verdict)
/// are located to [`LOCATE_TOL`] and listed in order.
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
            crate::check::len_of("direction", d, n)?;
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
        // Special points between prev and next, in the order of their location.
        let mut found: Vec<(f64, Special)> = Vec::new();
        if sign_change(prev.branch, next.branch) {
            let p = probe.locate(&prev, &next, s, LOCATE_TOL, true, &|q| q.branch)?;
            found.push((
                dist(&prev.point, &p.point),
                special_at(Kind::Branch, p, index),
            ));
        }
        if sign_change(prev.fold, next.fold) {
            let p = probe.locate(&prev, &next, s, LOCATE_TOL, true, &|q| q.fold)?;
            found.push((
                dist(&prev.point, &p.point),
                special_at(Kind::Fold, p, index),
            ));
        }
        for (w, (&a, &b)) in prev.point.stable.iter().zip(&next.point.stable).enumerate() {
            if a != b {
                let (ma, mb) = (prev.point.margins[w], next.point.margins[w]);
                let p = if sign_change(ma, mb) {
                    probe.locate(&prev, &next, s, LOCATE_TOL, true, &|q| q.point.margins[w])?
                } else {
                    probe.locate(&prev, &next, s, LOCATE_TOL, false, &|q| {
                        if q.point.stable.get(w) == Some(&a) {
                            1.0
                        } else {
                            -1.0
                        }
                    })?
                };
                let mut sp = special_at(Kind::Stability, p, index);
                sp.verdict = Some(w);
                found.push((dist(&prev.point, &sp.point), sp));
            }
        }
        found.sort_by(|x, y| x.0.total_cmp(&y.0));
        special.extend(found.into_iter().map(|(_, sp)| sp));
        // Stop where the parameter crosses `stop`.
        let (pa, pb) = (prev.point.parameter - stop, next.point.parameter - stop);
        if pa != 0.0 && (pb == 0.0 || sign_change(pa, pb)) {
            let test = |q: &Probed| q.point.parameter - stop;
            // The stop is a regular point: the corrected point there (not an interpolation).
            let p = probe.locate(&prev, &next, s, 1e-15, false, &|q| {
                if q.point.parameter == stop {
                    0.0
                } else {
                    test(q)
                }
            })?;
            let p = if test(&p).abs() < test(&next).abs() {
                p
            } else {
                next.clone()
            };
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

/// The direction of the other branch at a simple branch point: the unit vector of the
/// two-dimensional ker DF(u) orthogonal to the followed branch's tangent (module docs).
///
/// Errors: the kernel is not two-dimensional to working accuracy (the second smallest singular
/// value of DF must be below 1e-6·max(1, ‖DF‖)).
pub fn switch_direction(family: &dyn Family, point: &Point) -> Result<Vec<f64>> {
    let (ker, j) = kernel(family, &point.u, 2)?;
    let n = point.u.len();
    // Singular values, to check that the kernel is two-dimensional.
    let sv = Mat::from_fn(n, n, |r, c| if r + 1 < n { j[(r, c)] } else { 0.0 })
        .singular_values()
        .map_err(|e| Error::NotConverged {
            what: format!("singular values at the branch point ({e:?})"),
            iterations: 0,
            residual: f64::NAN,
            tol: 0.0,
        })?;
    // Relative to max(1, ‖DF‖): at a branch point of a single equation DF vanishes entirely.
    let ratio = sv[n - 2] / sv[0].max(1.0);
    if ratio > 1e-6 {
        return Err(Error::invalid(
            "branch point",
            format!(
                "ker DF is one-dimensional there (second smallest singular value / \
                 max(1, |DF|) = {ratio:.1e}): not a branch point to working accuracy"
            ),
        ));
    }
    // The kernel vector orthogonal to the tangent: project both basis vectors.
    let t = &point.tangent;
    let mut best = Vec::new();
    let mut best_norm = 0.0;
    for v in &ker {
        let c = dot(v, t);
        let w: Vec<f64> = v.iter().zip(t).map(|(a, b)| a - c * b).collect();
        let nw = norm(&w);
        if nw > best_norm {
            best_norm = nw;
            best = w;
        }
    }
    Ok(best.iter().map(|x| x / best_norm).collect())
}
