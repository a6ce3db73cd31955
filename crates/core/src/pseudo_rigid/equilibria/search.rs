//! The solvers: relative equilibria for given velocities or momenta by a multistart
//! Levenberg–Marquardt search over the semi-axes, and for a given shape in one plane exactly.

use super::admissible::{commutator, is_matching, support};
use super::{
    amended_force, basis, check_axes, diag, equilibrium_residual, gap, kinetic_gradient,
    require_distinct, RelativeEquilibrium,
};
use crate::check;
use crate::error::{Error, Result};
use crate::lie::so;
use crate::numerics::fd::{self, Scheme::Central};
use crate::numerics::linalg::norm;
use crate::pseudo_rigid::inertia::BiInertia;
use crate::pseudo_rigid::potential::{self, Potential};
use crate::Mat;
use faer::linalg::solvers::Solve;

/// A residual r(a) ∈ R^m and its scale (for the relative tolerance); None where undefined.
type Residual<'a> = dyn Fn(&[f64]) -> Option<(Vec<f64>, f64)> + 'a;

/// Relative tolerance of the solvers: converged when ‖r‖ ≤ TOL·scale.
const TOL: f64 = 1e-11;

/// Central-difference Jacobian of r at a, steps 1e-6·max(|a_k|, 1e-3).
fn jacobian(f: &Residual<'_>, a: &[f64]) -> Option<Mat> {
    let h: Vec<f64> = a.iter().map(|x| 1e-6 * x.abs().max(1e-3)).collect();
    fd::jacobian(&|y| f(y).map(|(r, _)| r).ok_or(()), a, &h, Central).ok()
}

/// Levenberg–Marquardt (Newton for square well-conditioned systems) from `a0`, iterates kept in
/// (0, ∞). Returns the converged point, or None.
fn solve_from(f: &Residual<'_>, a0: &[f64]) -> Option<Vec<f64>> {
    let n = a0.len();
    let mut a = a0.to_vec();
    let (mut r, mut scale) = f(&a)?;
    let m = r.len();
    let mut mu = 1e-8;
    for _ in 0..200 {
        let rn = norm(&r);
        if rn <= TOL * scale.max(f64::MIN_POSITIVE) {
            return Some(a);
        }
        let jac = jacobian(f, &a)?;
        let jtj = jac.transpose() * &jac;
        let rv = Mat::from_fn(m, 1, |i, _| r[i]);
        let jtr = jac.transpose() * &rv;
        let dmax = (0..n).map(|k| jtj[(k, k)]).fold(0.0, f64::max);
        let mut accepted = false;
        for _ in 0..30 {
            let lhs = Mat::from_fn(n, n, |i, j| {
                jtj[(i, j)] + if i == j { mu * dmax.max(1e-300) } else { 0.0 }
            });
            let step = lhs.partial_piv_lu().solve(&jtr);
            let trial: Vec<f64> = (0..n).map(|k| a[k] - step[(k, 0)]).collect();
            let ok = trial.iter().all(|t| t.is_finite() && *t > 0.0);
            if ok {
                if let Some((rt, st)) = f(&trial) {
                    if rt.iter().all(|x| x.is_finite()) && norm(&rt) < rn {
                        a = trial;
                        r = rt;
                        scale = st;
                        mu = (mu / 10.0).max(1e-12);
                        accepted = true;
                        break;
                    }
                }
            }
            mu *= 10.0;
        }
        if !accepted {
            let rn = norm(&r);
            return (rn <= 1e3 * TOL * scale).then_some(a);
        }
    }
    None
}

/// Grid of starts in the box (per axis `m` points, small distinct offsets per axis so that no
/// start has two equal coordinates).
fn grid(n: usize, lo: f64, hi: f64, m: usize) -> Vec<Vec<f64>> {
    let total = m.checked_pow(n as u32).unwrap_or(usize::MAX);
    (0..total)
        .map(|mut idx| {
            (0..n)
                .map(|k| {
                    let g = idx % m;
                    idx /= m;
                    let off = 0.5 + 0.2 * (k as f64 + 1.0) / (n as f64 + 1.0) - 0.1;
                    lo + (hi - lo) * (g as f64 + off) / m as f64
                })
                .collect()
        })
        .collect()
}

fn check_bounds(bounds: (f64, f64), starts: usize, n: usize) -> Result<()> {
    let (lo, hi) = bounds;
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return Err(Error::invalid(
            "bounds",
            format!("expected 0 < lo < hi (finite), got ({lo}, {hi})"),
        ));
    }
    let total = (starts as f64).powi(n as i32);
    if starts == 0 || total > 1e6 {
        return Err(Error::invalid(
            "starts",
            format!("expected 1 ≤ starts with starts^n ≤ 10⁶ (n = {n}), got {starts}"),
        ));
    }
    Ok(())
}

/// The full outcome of [`search_velocities`] / [`search_momenta`].
#[derive(Debug, Clone, PartialEq)]
pub struct Search {
    /// The relative equilibria on the principal stratum (what `equilibria_for_*` returns).
    pub equilibria: Vec<RelativeEquilibrium>,
    /// Semi-axes a of the solutions with coincident entries (gap ≤ 1e-7·bounds.1) found in the
    /// box, deduplicated. B_A is singular there (seed-errata §8), so they carry no
    /// [`RelativeEquilibrium`]; `equilibria_for_*` drop them when principal solutions exist.
    pub coincident: Vec<Vec<f64>>,
}

/// Outcome of the multistart solve.
struct Found {
    principal: Vec<Vec<f64>>,
    coincident: Vec<Vec<f64>>,
}

/// Multistart solve of r(a) = 0 in the box, deduplicated; the family check (a singular
/// Jacobian at a principal solution means a continuum of solutions) is the caller's.
fn multistart(f: &Residual<'_>, n: usize, bounds: (f64, f64), starts: usize) -> Found {
    let (lo, hi) = bounds;
    let slack = 1e-9 * hi;
    let mut found = Found {
        principal: Vec::new(),
        coincident: Vec::new(),
    };
    for a0 in grid(n, lo, hi, starts) {
        let Some(a) = solve_from(f, &a0) else {
            continue;
        };
        if a.iter().any(|&x| x < lo - slack || x > hi + slack) {
            continue;
        }
        let (g, _) = gap(&a);
        let coincident = g <= 1e-7 * hi;
        let list = if coincident {
            &mut found.coincident
        } else {
            &mut found.principal
        };
        let dup = list
            .iter()
            .any(|b| b.iter().zip(&a).all(|(x, y)| (x - y).abs() <= 1e-6 * hi));
        if !dup {
            list.push(a);
        }
    }
    found
}

/// Rejects a continuum of solutions: the Jacobian of r at a solution has a null direction.
fn check_isolated(f: &Residual<'_>, a: &[f64], what: &str) -> Result<()> {
    let jac = jacobian(f, a).ok_or_else(|| Error::NonFinite {
        what: format!("{what}: Jacobian of the equilibrium conditions"),
        location: format!("a = {a:?}"),
    })?;
    let sv = jac.singular_values().map_err(|e| Error::NotConverged {
        what: format!("SVD of the equilibrium Jacobian ({e:?})"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    })?;
    let (smax, smin) = (sv[0], sv[sv.len() - 1]);
    if smin <= 1e-6 * smax.max(f64::MIN_POSITIVE) {
        return Err(Error::invalid(
            what,
            format!(
                "a continuum of relative equilibria passes through a = {a:?}: the Jacobian of the \
                 equilibrium conditions in the semi-axes is singular there (singular values \
                 {sv:?}); the solution is a whole family, not an isolated shape (e.g. U = (k/2)|X|² \
                 with ω² = k: every shape balances)"
            ),
        ));
    }
    Ok(())
}

fn coincident_error(what: &str, found: &Found) -> Error {
    let a = &found.coincident[0];
    let (g, tol) = gap(a);
    Error::DegenerateStratum {
        what: format!(
            "{what} (every solution found in the box has coincident semi-axes, a = {:?}; B_A is \
             singular there and the body velocities are not determined by the motion)",
            found.coincident
        ),
        gap: g,
        tol: tol.max(1e-7 * a.iter().copied().fold(0.0, f64::max)),
    }
}

/// All relative equilibria with the given constant body velocities (Ω, Λ) = (ξ, η) through
/// shapes A = diag(a) in the box bounds.0 ≤ a_k ≤ bounds.1: Newton (Levenberg–Marquardt) on the
/// force balance [`force_balance`](super::force_balance) from a grid of `starts`ⁿ points,
/// deduplicated.
///
/// Condition (8.6) first: if the planes carrying Ω and Λ are pairwise disjoint it holds for every
/// shape and only the force balance is solved; otherwise the force balance and the (8.6)
/// commutators are solved together (least squares), and if no shape satisfies them the answer is
/// an [`Error::InvalidArgument`] saying that (8.6) fails.
///
/// Returned: the solutions on the principal stratum (distinct semi-axes; the order of a is the
/// body frame's, so a permutation that keeps (Ω, Λ) — e.g. swapping a_i, a_j for a plane (i, j)
/// motion — is a separate entry). Errors instead of an arbitrary pick:
/// [`Error::DegenerateStratum`] if the only solutions have coincident semi-axes (B_A singular,
/// seed-errata §8); [`Error::InvalidArgument`] naming the family if a solution is not isolated.
/// An empty vector means no relative equilibrium in the box.
///
/// Solutions with coincident semi-axes found **alongside** principal ones are not returned here
/// (B_A is singular there, so they are not [`RelativeEquilibrium`]s with determined velocities);
/// [`search_velocities`] returns them too, as [`Search::coincident`].
pub fn equilibria_for_velocities(
    pot: &dyn Potential,
    xi: &Mat,
    eta: &Mat,
    bounds: (f64, f64),
    starts: usize,
) -> Result<Vec<RelativeEquilibrium>> {
    Ok(search_velocities(pot, xi, eta, bounds, starts)?.equilibria)
}

/// [`equilibria_for_velocities`] with the coincident-axis solutions it drops: the same search,
/// the same errors (an error when only coincident-axis solutions exist), and
/// [`Search::coincident`] listing the shapes with coincident semi-axes found in the box.
pub fn search_velocities(
    pot: &dyn Potential,
    xi: &Mat,
    eta: &Mat,
    bounds: (f64, f64),
    starts: usize,
) -> Result<Search> {
    let n = so::check_algebra("xi", xi)?;
    so::check_algebra_of("eta", eta, n)?;
    check_bounds(bounds, starts, n)?;
    let matched = is_matching(&support(xi, eta));
    let f = |a: &[f64]| -> Option<(Vec<f64>, f64)> {
        let x = diag(a);
        let g = potential::gradient(pot, &x).ok()?;
        let k = kinetic_gradient(&x, xi, eta);
        let scale = g.norm_l2() + k.norm_l2() + f64::MIN_POSITIVE;
        let mut r: Vec<f64> = (0..a.len()).map(|i| g[(i, i)] - k[(i, i)]).collect();
        if !matched {
            let (c1, c2) = commutator(a, xi, eta).ok()?;
            r.extend(so::vee_n_unchecked(&c1));
            r.extend(so::vee_n_unchecked(&c2));
        }
        r.iter().all(|v| v.is_finite()).then_some((r, scale))
    };
    let found = multistart(&f, n, bounds, starts);
    if found.principal.is_empty() && !found.coincident.is_empty() {
        return Err(coincident_error(
            "relative equilibria for these velocities",
            &found,
        ));
    }
    if !matched && found.principal.is_empty() {
        let probe: Vec<f64> = (0..n)
            .map(|k| bounds.0 + (bounds.1 - bounds.0) * (k as f64 + 0.5) / n as f64)
            .collect();
        let res = equilibrium_residual(&probe, xi, eta)?;
        return Err(Error::invalid(
            "velocities (xi, eta)",
            format!(
                "condition 001 (8.6) [Ω ⊕ Λ, B_A(Ω ⊕ Λ)] = 0 fails at every shape in the box \
                 (e.g. residual {res:.3e} at a = {probe:?}): Ω and Λ act in planes {:?} that share \
                 an axis, which needs repeated eigenvalues of B_A",
                support(xi, eta)
                    .iter()
                    .map(|(i, j)| (i + 1, j + 1))
                    .collect::<Vec<_>>()
            ),
        ));
    }
    let mut out = Vec::new();
    for a in &found.principal {
        check_isolated(&f, a, "relative equilibria for these velocities")?;
        out.push(RelativeEquilibrium::from_velocities(pot, a, xi, eta)?);
    }
    Ok(Search {
        equilibria: out,
        coincident: found.coincident,
    })
}

/// Central-difference Hessian norm scale of U in the semi-axes (for tolerances only).
fn stiffness(pot: &dyn Potential, a: &[f64]) -> Result<f64> {
    let n = a.len();
    let mut s: f64 = 0.0;
    let mut y = a.to_vec();
    for k in 0..n {
        let h = 1e-5 * a[k];
        y[k] = a[k] + h;
        let gp = potential::gradient(pot, &diag(&y))?;
        y[k] = a[k] - h;
        let gm = potential::gradient(pot, &diag(&y))?;
        y[k] = a[k];
        for i in 0..n {
            s = s.max(((gp[(i, i)] - gm[(i, i)]) / (2.0 * h)).abs());
        }
    }
    Ok(s)
}

/// All body velocities Ω = ω e_ij, Λ = μ e_ij in one plane (i, j) (0-based, i < j) for which the
/// shape A = diag(a) is a relative equilibrium, solved exactly (module docs): with g = ∂U/∂a,
/// g_k = 0 off the plane and (ω + μ)² = (g_i − g_j)/(a_i − a_j), (ω − μ)² = (g_i + g_j)/(a_i + a_j).
/// Returns every real solution, sign-symmetric ones included (up to four; only ω = μ = 0 when
/// the shape is at rest).
///
/// `incompressible`: the body keeps det X = ∏a (001 §1, the fluid's volume); the pressure p
/// enters as the multiplier, g ↦ g − p·cof A with cof A = diag(∏_{l≠k} a_l), p fixed by the
/// force balance off the plane (least squares when n > 3, then checked), and the results are
/// [`RelativeEquilibrium::incompressible`].
///
/// Errors: [`Error::InvalidArgument`] when the shape cannot rotate in that plane (a force off the
/// plane, or a negative right-hand side), [`Error::DegenerateStratum`] for coincident semi-axes,
/// bad a or plane.
pub fn equilibria_for_shape(
    pot: &dyn Potential,
    a: &[f64],
    plane: (usize, usize),
    incompressible: bool,
) -> Result<Vec<RelativeEquilibrium>> {
    let n = check_axes(a)?;
    let (i, j) = plane;
    if !(i < j && j < n) {
        return Err(Error::invalid(
            "plane",
            format!("expected (i, j) with 0 ≤ i < j < n = {n}, got ({i}, {j})"),
        ));
    }
    require_distinct("relative equilibria for a shape", a)?;
    let mut g: Vec<f64> = {
        let gm = potential::gradient(pot, &diag(a))?;
        (0..n).map(|k| gm[(k, k)]).collect()
    };
    check::finite_slice("∂U/∂a", &g)?;
    if incompressible {
        // The pressure balancing the forces off the plane (least squares), then g − p·cof A.
        let cof: Vec<f64> = (0..n)
            .map(|k| (0..n).filter(|&l| l != k).map(|l| a[l]).product())
            .collect();
        let off: Vec<usize> = (0..n).filter(|&k| k != i && k != j).collect();
        let c2: f64 = off.iter().map(|&k| cof[k] * cof[k]).sum();
        let p = off.iter().map(|&k| g[k] * cof[k]).sum::<f64>() / c2;
        for (gk, ck) in g.iter_mut().zip(&cof) {
            *gk -= p * ck;
        }
    }
    let gmax = g.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let amax = a.iter().copied().fold(0.0, f64::max);
    let tol = 1e-9 * (gmax + stiffness(pot, a)? * amax);
    let name = format!("shape a = {a:?} in plane ({}, {})", i + 1, j + 1);
    if let Some(k) = (0..n).find(|&k| k != i && k != j && g[k].abs() > tol) {
        return Err(Error::invalid(
            "a",
            format!(
                "the {name} cannot rotate in that plane: the force ∂U/∂a_{} = {:.3e} off the plane \
                 is not balanced by any rotation in it",
                k + 1,
                g[k]
            ),
        ));
    }
    let u2 = (g[i] - g[j]) / (a[i] - a[j]);
    let v2 = (g[i] + g[j]) / (a[i] + a[j]);
    let rtol = tol / amax;
    for (val, what) in [(u2, "(ω + μ)²"), (v2, "(ω − μ)²")] {
        if val < -rtol {
            return Err(Error::invalid(
                "a",
                format!(
                    "the {name} cannot rotate in that plane: force balance needs {what} = \
                     {val:.6e} < 0"
                ),
            ));
        }
    }
    let roots = |v: f64| -> Vec<f64> {
        if v <= rtol {
            vec![0.0]
        } else {
            vec![v.sqrt(), -v.sqrt()]
        }
    };
    let mut out = Vec::new();
    for u in roots(u2) {
        for v in roots(v2) {
            let (w, m) = (0.5 * (u + v), 0.5 * (u - v));
            let e = basis(n, i, j);
            let (xi, eta) = (&e * faer::Scale(w), &e * faer::Scale(m));
            out.push(if incompressible {
                RelativeEquilibrium::incompressible(pot, a, &xi, &eta)?
            } else {
                RelativeEquilibrium::from_velocities(pot, a, &xi, &eta)?
            });
        }
    }
    Ok(out)
}

/// All relative equilibria with given body momenta (λ, γ) = (μ, ν) = (p_Ω, p_Λ) at X₀ = diag(a)
/// (R₀ = S₀ = I): critical points a of the amended potential V(a) = U(a) + K(a; μ, ν) (001 (8.8),
/// (8.11), [`amended_force`]) in the box, by Newton from `starts`ⁿ grid points, deduplicated. If
/// the planes of μ and ν are not pairwise disjoint, the commutators [μ, Ω], [ν, Λ] (001 (8.7))
/// are solved together with the force. Errors as [`equilibria_for_velocities`].
///
/// Coincident-axis solutions found alongside principal ones are dropped as in
/// [`equilibria_for_velocities`]; [`search_momenta`] returns them.
pub fn equilibria_for_momenta(
    pot: &dyn Potential,
    lam: &Mat,
    gam: &Mat,
    bounds: (f64, f64),
    starts: usize,
) -> Result<Vec<RelativeEquilibrium>> {
    Ok(search_momenta(pot, lam, gam, bounds, starts)?.equilibria)
}

/// [`equilibria_for_momenta`] with the coincident-axis solutions it drops
/// ([`Search::coincident`]); otherwise identical.
pub fn search_momenta(
    pot: &dyn Potential,
    lam: &Mat,
    gam: &Mat,
    bounds: (f64, f64),
    starts: usize,
) -> Result<Search> {
    let n = so::check_algebra("lam", lam)?;
    so::check_algebra_of("gam", gam, n)?;
    check_bounds(bounds, starts, n)?;
    let matched = is_matching(&support(lam, gam));
    let f = |a: &[f64]| -> Option<(Vec<f64>, f64)> {
        let mut r = amended_force(pot, a, lam, gam).ok()?;
        let g = potential::gradient(pot, &diag(a)).ok()?;
        let scale = g.norm_l2() + norm(&r) + f64::MIN_POSITIVE;
        if !matched {
            let (xi, eta) = BiInertia::new(&diag(a)).ok()?.solve(lam, gam).ok()?;
            r.extend(so::vee_n_unchecked(&so::bracket(lam, &xi)));
            r.extend(so::vee_n_unchecked(&so::bracket(gam, &eta)));
        }
        r.iter().all(|v| v.is_finite()).then_some((r, scale))
    };
    let found = multistart(&f, n, bounds, starts);
    if found.principal.is_empty() && !found.coincident.is_empty() {
        return Err(coincident_error(
            "relative equilibria for these momenta",
            &found,
        ));
    }
    if !matched && found.principal.is_empty() {
        return Err(Error::invalid(
            "momenta (lam, gam)",
            format!(
                "condition 001 (8.7) fails at every shape in the box: μ and ν act in planes {:?} \
                 that share an axis",
                support(lam, gam)
                    .iter()
                    .map(|(i, j)| (i + 1, j + 1))
                    .collect::<Vec<_>>()
            ),
        ));
    }
    let mut out = Vec::new();
    for a in &found.principal {
        check_isolated(&f, a, "relative equilibria for these momenta")?;
        out.push(RelativeEquilibrium::from_momenta(pot, a, lam, gam)?);
    }
    Ok(Search {
        equilibria: out,
        coincident: found.coincident,
    })
}
