//! The corrector: Newton's method on F(v) = 0 with the pseudo-arclength condition t·(v − u) = s.

use super::{dot, Family};
use crate::convergence::{self, Rule, Verdict};
use crate::error::{Error, Result};
use crate::numerics::linalg::norm;
use crate::Mat;
use faer::linalg::solvers::Solve;

/// Newton iterations of the corrector.
const MAX_NEWTON: usize = 12;

/// A corrector whose update stops decreasing is accepted below this relative size (near a
/// branch point the matrix is ill-conditioned and the update stagnates above round-off).
const STAGNATION: f64 = 1e-10;

/// Newton's method for F(v) = 0, t·(v − u) = s from v = u + s t. Returns the point and the
/// number of iterations.
pub(super) fn correct(
    family: &dyn Family,
    u: &[f64],
    t: &[f64],
    s: f64,
    tol: f64,
) -> Result<(Vec<f64>, usize)> {
    let guess: Vec<f64> = u.iter().zip(t).map(|(a, b)| a + s * b).collect();
    correct_from(family, u, t, s, tol, guess)
}

/// [`correct`] from the initial guess `v` (on the hyperplane or not).
pub(super) fn correct_from(
    family: &dyn Family,
    u: &[f64],
    t: &[f64],
    s: f64,
    tol: f64,
    mut v: Vec<f64>,
) -> Result<(Vec<f64>, usize)> {
    let n = u.len();
    let scale = 1.0 + norm(u);
    // The rule of crate::convergence: done at once below `tol`, accepted below STAGNATION.
    let rule = Rule {
        tol: STAGNATION.max(tol),
        floor: tol,
        max_iter: MAX_NEWTON,
    };
    let mut monitor = convergence::Monitor::new(rule);
    let failed = loop {
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
        if v.iter().any(|x| !x.is_finite()) {
            dn = f64::INFINITY;
        }
        match monitor.check(dn, scale) {
            Verdict::Continue => {}
            Verdict::Converged => {
                let f = family.residual(&v)?;
                if f.iter().all(|x| x.is_finite()) {
                    return Ok((v, monitor.iterations()));
                }
                break monitor.failed(f64::INFINITY);
            }
            Verdict::Failed(failed) => break failed,
        }
    };
    Err(Error::NotConverged {
        what: "continuation corrector (Newton on F(u) = 0 with the arclength condition)".into(),
        iterations: failed.iterations,
        residual: failed.residual,
        tol: rule.tol,
    })
}
