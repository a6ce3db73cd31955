//! The location of a special point between two points of a branch: secant and bisection steps on
//! corrected points started from the cubic Hermite interpolant, then the root of the cubic
//! through the test at four well-determined points.

use super::corrector::{correct, correct_from};
use super::{dot, Point, Probe, Probed};
use crate::error::Result;
use crate::numerics::linalg::norm;

impl Probe<'_> {
    /// The corrected point at arclength σ from `from` along its tangent.
    fn at(&self, from: &Point, sigma: f64) -> Result<Probed> {
        let (v, _) = correct(self.family, &from.u, &from.tangent, sigma, self.tol)?;
        self.probe(v, &from.tangent)
    }

    /// Locates where `test` changes sign between `a` (σ = 0) and `b` (σ = s): secant steps
    /// (every third a bisection) on corrected points until the parameter is known to
    /// `rel_tol`·(1 + |π|) or the corrector fails repeatedly (within ~1e-9 of a branch point the
    /// corrected points are ill-determined: the two branches cross). Each trial point is
    /// corrected from the cubic Hermite interpolant of the current bracket (its error O(Δσ⁴)
    /// stays inside Newton's basin, which shrinks near a branch point). For a `smooth` test the
    /// result is the root of the test's linear interpolation on the last bracket, the point
    /// there by Hermite interpolation between corrected points at σ ± δ, δ = 10⁻³|s|, away from
    /// the ill-determined neighbourhood (error O(δ⁴)); otherwise (a verdict) the corrected point
    /// on the far side of the change. A point that cannot be evaluated ends the search with the
    /// bracket found so far.
    pub(super) fn locate(
        &self,
        a: &Probed,
        b: &Probed,
        s: f64,
        rel_tol: f64,
        smooth: bool,
        test: &dyn Fn(&Probed) -> f64,
    ) -> Probed {
        let (mut lo, mut hi) = (0.0, s);
        let (mut flo, mut fhi) = (test(a), test(b));
        let (mut near, mut far) = (a.clone(), b.clone());
        let tol = rel_tol * (1.0 + a.point.parameter.abs());
        let dpds = (b.point.parameter - a.point.parameter).abs() / s.abs().max(f64::MIN_POSITIVE);
        let ta = &a.point.tangent;
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
            let guess = hermite(&near, &far, ta, (mid - lo) / (hi - lo), hi - lo);
            let trial = correct_from(self.family, &a.point.u, ta, mid, self.tol, guess)
                .and_then(|(v, _)| self.probe(v, ta));
            match trial {
                Err(_) => {
                    bad = Some(mid);
                    failures += 1;
                }
                Ok(p) => {
                    let fm = test(&p);
                    if fm == 0.0 {
                        return p;
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
            return far;
        }
        let frac = flo / (flo - fhi);
        let root = lo
            + if frac.is_finite() {
                frac.clamp(0.0, 1.0)
            } else {
                0.5
            } * (hi - lo);
        // Refine on four well-determined points σ = r + kδ, k = ±1, ±2, around the current
        // estimate r: the root of the cubic through the test's values there (error O(δ⁴)),
        // repeated until it settles (the first estimate may come from a wide bracket); the point
        // by Hermite interpolation between k = −1 and k = 1.
        let delta = 1e-3 * s.abs();
        let mut r = root;
        let mut stencil: Option<Vec<Probed>> = None;
        for _ in 0..6 {
            let pts: Option<Vec<Probed>> = [-2.0, -1.0, 1.0, 2.0]
                .iter()
                .map(|k| self.at(&a.point, r + k * delta).ok())
                .collect();
            let Some(pts) = pts else {
                break;
            };
            let xs: Vec<f64> = [-2.0, -1.0, 1.0, 2.0]
                .iter()
                .map(|k| r + k * delta)
                .collect();
            let ys: Vec<f64> = pts.iter().map(test).collect();
            let next = cubic_root(&xs, &ys, r);
            let moved = (next - r).abs();
            if moved <= 2.0 * delta {
                stencil = Some(pts);
                let settled = moved <= 1e-12 * (1.0 + r.abs());
                r = next;
                if settled {
                    break;
                }
            } else {
                stencil = None;
                r = next;
            }
        }
        let (left, right, w, h) = match stencil {
            Some(mut c) if (r - root).abs() <= (hi - lo).abs() + 4.0 * delta => {
                // The stencil was centred at the previous estimate: the Hermite interval
                // [c₋₁, c₁] contains the root (it moved by at most 2δ; clamp to the interval).
                let right = c.swap_remove(2);
                let left = c.swap_remove(1);
                let w = ((r - sigma_of(&left, &a.point)) / (2.0 * delta)).clamp(0.0, 1.0);
                (left, right, w, 2.0 * delta)
            }
            _ => (near, far.clone(), (root - lo) / (hi - lo), hi - lo),
        };
        let u = hermite(&left, &right, ta, w, h);
        // The branch's own direction there (at a branch point the kernel is two-dimensional and
        // the probe's tangent arbitrary): the interpolated slope.
        let (d0, d1) = (slope(&left, ta), slope(&right, ta));
        let mut t: Vec<f64> = d0
            .iter()
            .zip(&d1)
            .map(|(x, y)| (1.0 - w) * x + w * y)
            .collect();
        let nt = norm(&t);
        t.iter_mut().for_each(|x| *x /= nt);
        if u.iter().chain(&t).any(|x| !x.is_finite()) {
            return far;
        }
        match self.probe(u, ta) {
            Ok(mut p) => {
                p.point.tangent = t;
                p
            }
            Err(_) => far,
        }
    }
}

/// The arclength coordinate σ = t_a·(u − u_a) of a point relative to `a`.
fn sigma_of(p: &Probed, a: &Point) -> f64 {
    p.point
        .u
        .iter()
        .zip(&a.u)
        .zip(&a.tangent)
        .map(|((x, y), t)| (x - y) * t)
        .sum()
}

/// The root near `x0` of the cubic through the four points (x_k, y_k) (Lagrange form, Newton's
/// method); `x0` if it does not converge.
fn cubic_root(xs: &[f64], ys: &[f64], x0: f64) -> f64 {
    let eval = |x: f64| -> (f64, f64) {
        let (mut v, mut dv) = (0.0, 0.0);
        for i in 0..4 {
            let (mut l, mut dl) = (1.0, 0.0);
            for j in (0..4).filter(|&j| j != i) {
                let d = xs[i] - xs[j];
                dl = dl * (x - xs[j]) / d + l / d;
                l *= (x - xs[j]) / d;
            }
            v += ys[i] * l;
            dv += ys[i] * dl;
        }
        (v, dv)
    };
    let mut x = x0;
    for _ in 0..30 {
        let (v, dv) = eval(x);
        let step = v / dv;
        if !step.is_finite() {
            return x0;
        }
        x -= step;
        if step.abs() <= 1e-16 * (1.0 + x.abs()) {
            return x;
        }
    }
    if x.is_finite() {
        x
    } else {
        x0
    }
}

/// du/dσ = t/(t·t_a) at a point, σ measured along t_a.
fn slope(p: &Probed, ta: &[f64]) -> Vec<f64> {
    let c = dot(&p.point.tangent, ta);
    p.point.tangent.iter().map(|x| x / c).collect()
}

/// The cubic Hermite interpolant between two points of a branch (their u and slopes along t_a)
/// at the fraction w of the interval of length h in σ.
fn hermite(p0: &Probed, p1: &Probed, ta: &[f64], w: f64, h: f64) -> Vec<f64> {
    let (d0, d1) = (slope(p0, ta), slope(p1, ta));
    let (h00, h10, h01, h11) = (
        (1.0 + 2.0 * w) * (1.0 - w) * (1.0 - w),
        w * (1.0 - w) * (1.0 - w),
        w * w * (3.0 - 2.0 * w),
        w * w * (w - 1.0),
    );
    (0..p0.point.u.len())
        .map(|k| h00 * p0.point.u[k] + h10 * h * d0[k] + h01 * p1.point.u[k] + h11 * h * d1[k])
        .collect()
}
