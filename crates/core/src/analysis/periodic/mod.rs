//! Periodic orbits of a method's own map by shooting, their monodromy matrix and Floquet
//! multipliers; relative periodic orbits of the bodies that carry an attitude (issue 27).
//!
//! A periodic orbit of period T is sought as a fixed point of the method's map over N steps of
//! size h = T/N: Φ_h^N(z₀) = z₀ — the orbit the run computes, closing to round-off, not an orbit
//! of the continuous flow approximated afterwards. A periodic orbit of a conservative system is
//! never isolated: it comes with its phase (every point of the orbit is a start), in a family
//! along the energy (fix the energy E or the period T, the other is an unknown) and along the
//! levels of the invariants the method keeps (Casimirs, momentum maps). The shooting equations
//! therefore are, for the unknowns (z₀, T) (fix = energy) or z₀ (fix = period):
//!
//! * Φ_{T/N}^N(z₀) − z₀ = 0 (d equations);
//! * H(z₀) = E (fix = energy, E the guess's energy);
//! * ⟨v, z₀ − ẑ⟩ = 0, the phase: a hyperplane through the guess ẑ across the flow v at ẑ (the
//!   chord of one step of 1e-5·T);
//! * I_j(z₀) = I_j(ẑ), the levels of the invariants ([`crate::integrate::Problem::invariants`]).
//!
//! They are more equations than unknowns but consistent at an orbit, and solved by the
//! Gauss–Newton iteration (the minimum-norm least-squares update, by the SVD): quadratic
//! convergence at an orbit whose only degeneracies are the ones removed. The Jacobian of the
//! first block is [M − I, ∂z_N/∂T] with M = ∂z_N/∂z₀ the monodromy of the method's map, exact to
//! round-off from the tangent lift (the sensitivities of [`crate::integrate::tangent`]); the
//! derivative along the period, at N fixed (the step changes with T), is the central difference
//! of two plain runs over T ± δ (δ = T·ε^(1/3), error ≈ 1e-11 relative: a column of the Newton
//! matrix, never of the result). The gradients of H and of the invariants (rows of the matrix
//! only) are differences too. The iteration stops under the rule of [`crate::convergence`]
//! and the orbit is evaluated once more at the accepted point, so the reported monodromy and
//! residual are those of the returned state.
//!
//! **Floquet multipliers.** The eigenvalues of M. At a periodic orbit of a system with k
//! independent conserved quantities c_j (the energy and the invariants), M maps the tangent
//! space of their common level set into itself and fixes the flow direction f; the
//! multipliers of the orbit's *normal* motion are those of the map M induces on the quotient
//! T(level)/⟨f⟩ (represented on V = T(level) ∩ f⊥ as Vᵀ(I − f̂f̂ᵀ)MV); the other k + 1 are
//! *trivial* (equal to 1 for an exact flow: in Jordan blocks where the period varies along the
//! family; for a relative orbit also the turns exp(−ζ) gives the group directions). The
//! trivial ones are flagged among the eigenvalues of M as those left when each normal
//! multiplier has taken its nearest.
//! The orbit is (spectrally) stable when every normal multiplier lies on or inside the unit
//! circle to [`STABLE_TOL`]. For a method that keeps a modified energy H̃ = H + O(hᵖ) (the
//! symplectic ones), the exact f and T(level) are the modified flow's only to O(hᵖ), and so
//! are the quotient's eigenvalues: they only tell the normal multipliers apart, and the ones
//! reported are M's own eigenvalues nearest to them (exact for the map).

mod family;

pub use family::{
    periodic_family, End, FamilyOptions, Kind, Parameter, PeriodicFamily, SpecialPoint,
};

use super::{eig_error, general_eigenvalues, null_space, range};
use crate::convergence::{Monitor, Rule, Verdict};
use crate::error::{Error, Result};
use crate::integrate::problem::Symmetric;
use crate::integrate::tangent::TangentSystem;
use crate::integrate::{integrate, System};
use crate::numerics::fd::{self, Scheme};
use crate::Mat;

/// What the shooting keeps fixed along the family of the orbit (module docs).
#[derive(Clone, Debug, PartialEq)]
pub enum Fix {
    /// The energy of the guess; the period is an unknown.
    Energy,
    /// The period given; the energy is an unknown.
    Period,
    /// The pseudo-arclength condition of a continuation: ⟨t, u − u₀⟩ = s in the unknowns
    /// u = (z, T, ζ) (d + 1 + dim g values; [`PeriodicOrbit::tangent`]'s layout), which passes
    /// folds of both the energy and the period.
    Arclength {
        /// u₀, the last orbit of the family.
        from: Vec<f64>,
        /// t, its tangent.
        tangent: Vec<f64>,
        /// s.
        step: f64,
    },
}

/// The shooting's discretisation and stopping rule ([`periodic_orbit`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// N, the method's steps per period (the step is T/N).
    pub steps: usize,
    /// Energy or period fixed.
    pub fix: Fix,
    /// An update of the unknowns below tol (relative: the state to max(1, ‖ẑ‖∞), the period to
    /// itself) is accepted; the iteration then goes on while the update decreases.
    pub tol: f64,
    /// Gauss–Newton iterations allowed.
    pub max_iter: usize,
    /// A relative periodic orbit Φ_T(z₀) = exp(ζ)·z₀ of the system's symmetry.
    pub relative: bool,
    /// The levels to keep (the invariants, then for a relative orbit the momentum map);
    /// default: the guess's.
    pub levels: Option<Vec<f64>>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            steps: 1000,
            fix: Fix::Energy,
            tol: 1e-10,
            max_iter: 30,
            relative: false,
            levels: None,
        }
    }
}

/// A normal multiplier of modulus above 1 + STABLE_TOL makes the orbit unstable.
pub const STABLE_TOL: f64 = 1e-6;

/// An orbit whose relative residual ‖Φ(z₀) − z₀‖∞/max(1, ‖z₀‖∞) exceeds this after the
/// iteration stopped is not returned (the equations had no solution near the guess).
const RESIDUAL_LIMIT: f64 = 1e-6;

/// The step, relative to the period, whose chord gives the flow's direction at the guess
/// (the phase plane's normal).
const PHASE_STEP: f64 = 1e-5;

/// Singular values below this times the largest are zero in the least-squares update.
const RCOND: f64 = 1e-10;

/// Equations that hold to this size times √N, relative, are solved (the round-off of a run of
/// N steps, whose implicit solves stop at their own round-off) once the update stagnates
/// below [`SETTLED_UPDATE`].
const ROUNDOFF: f64 = 1e4 * f64::EPSILON;

/// A stagnating update at most this (relative) is round-off amplified along the family's
/// near-null directions.
const SETTLED_UPDATE: f64 = 1e-6;

/// A periodic orbit of a method's map ([`periodic_orbit`]).
#[derive(Clone, Debug)]
pub struct PeriodicOrbit {
    /// The point of the orbit on the phase hyperplane (user frame).
    pub state0: Vec<f64>,
    /// The period T.
    pub period: f64,
    /// The method's steps per period (the step is T/steps).
    pub steps: usize,
    /// H(state0).
    pub energy: f64,
    /// M = ∂z_N/∂z₀ at state0 (e × e); of exp(−ζ)·z_N for a relative orbit.
    pub monodromy: Mat,
    /// The eigenvalues of M (re, im), by descending modulus.
    pub multipliers: Vec<(f64, f64)>,
    /// Which of [`PeriodicOrbit::multipliers`] are trivial (module docs).
    pub trivial: Vec<bool>,
    /// The normal multipliers: the eigenvalues of the map M induces across the flow on the
    /// level set of the conserved quantities, by descending modulus.
    pub normal: Vec<(f64, f64)>,
    /// ‖Φ(state0) − state0‖∞, absolute.
    pub residual: f64,
    /// The Gauss–Newton iterations taken.
    pub iterations: usize,
    /// ζ of a relative orbit: Φ_T(state0) = exp(ζ)·state0 (the monodromy and the
    /// multipliers are those of exp(−ζ)·Φ_T); None for a periodic one.
    pub drift: Option<Vec<f64>>,
    /// The levels the orbit keeps: the invariants, then (relative) the momentum map.
    pub levels: Vec<f64>,
    /// The tangent of the orbit's family at fixed levels: (δz, δT, δζ) of unit length, d + 1 +
    /// dim g values, the direction in which the energy grows (the null vector of the shooting
    /// equations without the energy's).
    pub tangent: Vec<f64>,
}

impl PeriodicOrbit {
    /// Whether every normal multiplier has modulus at most 1 + [`STABLE_TOL`] (spectral
    /// stability; for a symplectic map all lie on the unit circle then).
    pub fn stable(&self) -> bool {
        self.normal
            .iter()
            .all(|&(re, im)| re.hypot(im) <= 1.0 + STABLE_TOL)
    }
}

/// One shot from z₀ over T: the end state, the monodromy and the end's derivative along T.
struct Shot {
    end: Vec<f64>,
    monodromy: Mat,
    along: Vec<f64>,
}

/// The system's lift for `method`, refused where its directions are not the state's values.
fn lift_of(system: &dyn System, method: &str) -> Result<std::sync::Arc<dyn TangentSystem>> {
    system.resolve(method)?;
    let lift = Some(())
        .filter(|_| system.tangent_methods().contains(&method))
        .and_then(|_| system.tangent_for(method))
        .ok_or_else(|| Error::InvalidArgument {
            what: "method".into(),
            message: format!(
                "{} has no tangent maps for {method:?}, which the monodromy matrix needs \
                 (methods with them: {:?})",
                system.name(),
                system.tangent_methods()
            ),
        })?;
    if lift.tangent_dim() != lift.base_dim() {
        return Err(Error::InvalidArgument {
            what: "system".into(),
            message: format!(
                "periodic orbits of states with SO(3) blocks ({}: {} values, {} directions) are \
                 not built; shoot the reduced state and pass its attitude for the drift",
                system.name(),
                lift.base_dim(),
                lift.tangent_dim()
            ),
        });
    }
    Ok(lift)
}

/// The end of N steps of size T/N from z₀ (a plain run).
fn end_of(
    system: &dyn System,
    method: &str,
    z0: &[f64],
    period: f64,
    n: usize,
) -> Result<Vec<f64>> {
    let traj = integrate(system, method, z0, period / n as f64, n, n)?;
    Ok(traj.state(1).to_vec())
}

fn shoot(
    system: &dyn System,
    lift: &dyn TangentSystem,
    method: &str,
    z0: &[f64],
    period: f64,
    n: usize,
) -> Result<Shot> {
    let (d, p) = (lift.base_dim(), lift.parameter_names().len());
    let seed = lift.seed(z0)?;
    let traj = integrate(lift, method, &seed, period / n as f64, n, n)?;
    let (mut end, mut jac, mut pjac) = (vec![0.0; d], vec![0.0; d * d], vec![0.0; d * p]);
    lift.jacobian(traj.state(1), &mut end, &mut jac, &mut pjac);
    // ∂z_N/∂T at N fixed: the step is T/N, so T ± δ changes every step.
    let delta = period * f64::EPSILON.cbrt();
    let (tp, tm) = (period + delta, period - delta);
    let (zp, zm) = (
        end_of(system, method, z0, tp, n)?,
        end_of(system, method, z0, tm, n)?,
    );
    let span = (tp / n as f64 - tm / n as f64) * n as f64;
    let along = zp.iter().zip(&zm).map(|(a, b)| (a - b) / span).collect();
    Ok(Shot {
        end,
        monodromy: Mat::from_fn(d, d, |i, j| jac[i * d + j]),
        along,
    })
}

/// The conserved quantities' values and their gradients (rows): H, the invariants, and for a
/// relative orbit the momentum map.
fn conserved(
    system: &dyn System,
    sym: Option<&dyn Symmetric>,
    z: &[f64],
) -> Result<(Vec<f64>, Mat)> {
    let values = |x: &[f64]| -> Result<Vec<f64>> {
        let mut v = vec![system.energy(x)?];
        v.extend(system.invariants(x)?);
        if let Some(s) = sym {
            v.extend(s.momentum_map(x)?);
        }
        Ok(v)
    };
    Ok((
        values(z)?,
        fd::jacobian(&values, z, &steps_of(z), Scheme::Richardson)?,
    ))
}

/// Difference steps 1e-4·max(1, |x_k|).
fn steps_of(x: &[f64]) -> Vec<f64> {
    x.iter().map(|v| 1e-4 * v.abs().max(1.0)).collect()
}

/// The columns ∂(exp(ζ)·z)/∂z (d × d) and ∂(exp(ζ)·z)/∂ζ (d × g) by central differences
/// (one Richardson extrapolation: exact to round-off for a linear action in z).
fn action_jacobians(sym: &dyn Symmetric, zeta: &[f64], z: &[f64]) -> Result<(Mat, Mat)> {
    let in_z = fd::jacobian(
        &|w: &[f64]| sym.act(zeta, w),
        z,
        &steps_of(z),
        Scheme::Richardson,
    )?;
    let in_zeta = fd::jacobian(
        &|x: &[f64]| sym.act(x, z),
        zeta,
        &vec![1e-4; zeta.len()],
        Scheme::Richardson,
    )?;
    Ok((in_z, in_zeta))
}

/// The minimum-norm least-squares solution of A x = b (thin SVD, singular values below
/// [`RCOND`]·σ_max dropped).
fn least_squares(a: &Mat, b: &[f64]) -> Result<Vec<f64>> {
    let svd = a
        .thin_svd()
        .map_err(|e| eig_error("SVD of the shooting matrix", e))?;
    let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
    let smax = if s.nrows() > 0 { s[0] } else { 0.0 };
    let mut x = vec![0.0; a.ncols()];
    for k in 0..s.nrows() {
        if s[k] <= RCOND * smax || s[k] == 0.0 {
            continue;
        }
        let c = (0..a.nrows()).map(|i| u[(i, k)] * b[i]).sum::<f64>() / s[k];
        for (j, xj) in x.iter_mut().enumerate() {
            *xj += c * v[(j, k)];
        }
    }
    Ok(x)
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn unit(v: &[f64]) -> Result<Vec<f64>> {
    let n = dot(v, v).sqrt();
    if !(n > 0.0 && n.is_finite()) {
        return Err(Error::InvalidArgument {
            what: "state0".into(),
            message: "the flow vanishes there (an equilibrium has no period)".into(),
        });
    }
    Ok(v.iter().map(|x| x / n).collect())
}

/// The generators e_k·z of a basis of g at z, as columns (d × g).
fn generators(sym: &dyn Symmetric, z: &[f64]) -> Result<Mat> {
    let g = sym.symmetry_dim();
    let mut e = vec![0.0; g];
    let mut cols = Vec::with_capacity(g);
    for k in 0..g {
        e[k] = 1.0;
        cols.push(sym.generator(&e, z)?);
        e[k] = 0.0;
    }
    Ok(Mat::from_fn(z.len(), g, |i, k| cols[k][i]))
}

/// The generators of the isotropy algebra g_μ of μ = J(z) at z, as columns: ξ_Z(z) for ξ in
/// ker(dJ(z)·ξ_Z(z)), the group directions tangent to the level set of J.
fn isotropy_generators(sym: &dyn Symmetric, z: &[f64]) -> Result<Mat> {
    let gens = generators(sym, z)?;
    let mom = |x: &[f64]| sym.momentum_map(x);
    let dj = fd::jacobian(&mom, z, &steps_of(z), Scheme::Richardson)?;
    Ok(&gens * null_space(&(&dj * &gens))?)
}

/// Finds a periodic orbit of `method`'s map near the guess `z0` with period near `period`
/// (module docs): the Gauss–Newton iteration on the shooting equations. With
/// [`Options::relative`] a relative periodic orbit Φ_T(z₀) = exp(ζ)·z₀ of the system's
/// [`crate::integrate::Problem::symmetry`], ζ found with T, from the guess `drift` of ζ (zero by default).
///
/// # Errors
/// [`Error::InvalidArgument`] (period ≤ 0 or not finite, steps = 0, a method without tangent
/// maps, a state with SO(3) blocks, a guess at an equilibrium, a relative orbit of a system
/// without a symmetry's action), the errors of the runs (shape, constraints,
/// [`Error::NotConverged`] of an implicit step), and [`Error::NotConverged`] when the iteration
/// fails or stops on a point that is not periodic (relative residual above 1e-6).
pub fn periodic_orbit(
    system: &dyn System,
    method: &str,
    z0: &[f64],
    period: f64,
    drift: Option<&[f64]>,
    options: &Options,
) -> Result<PeriodicOrbit> {
    if !(period > 0.0 && period.is_finite()) {
        return Err(Error::InvalidArgument {
            what: "period".into(),
            message: format!("expected a finite time > 0, got {period}"),
        });
    }
    let n = options.steps;
    if n == 0 {
        return Err(Error::InvalidArgument {
            what: "steps".into(),
            message: "expected an integer >= 1 (steps per period), got 0".into(),
        });
    }
    let lift = lift_of(system, method)?;
    let sym = match options.relative {
        false => None,
        true => Some(system.symmetry().ok_or_else(|| Error::InvalidArgument {
            what: "relative".into(),
            message: format!(
                "{} has no symmetry whose action lieflow knows (relative orbits of the \
                 bodies with an attitude: pass the attitude)",
                system.name()
            ),
        })?),
    };
    let g = sym.map_or(0, |s| s.symmetry_dim());
    let mut zeta = match drift {
        Some(x) if x.len() == g => x.to_vec(),
        Some(x) => {
            return Err(Error::shape(
                "drift",
                format!("({g},)"),
                format!("({},)", x.len()),
            ))
        }
        None => vec![0.0; g],
    };
    let d = lift.base_dim();
    if let Fix::Arclength {
        from,
        tangent,
        step,
    } = &options.fix
    {
        let k = d + 1 + g;
        if from.len() != k || tangent.len() != k || !step.is_finite() {
            return Err(Error::invalid(
                "fix",
                format!("an arclength condition needs u₀ and t of {k} values and a finite step"),
            ));
        }
    }
    let period_free = options.fix != Fix::Period;
    let mut guess = z0.to_vec();
    system.project(&mut guess)?;
    let scale = inf_norm(&guess).max(1.0);
    // The slice through the guess: across the orbit of the isotropy group G_μ of its momentum
    // (the other group directions change μ, which its rows fix) and across the flow there (one
    // step's direction, its part along that orbit removed).
    let gens0 = match sym {
        Some(s) => range(&isotropy_generators(s, &guess)?)?,
        None => Mat::zeros(d, 0),
    };
    let v = {
        // One short step: its chord is the flow to O(h) (an exact flow's steps may be long).
        let z1 = end_of(system, method, &guess, PHASE_STEP * period, 1)?;
        let mut v: Vec<f64> = z1.iter().zip(&guess).map(|(a, b)| a - b).collect();
        for k in 0..gens0.ncols() {
            let c = (0..d).map(|i| gens0[(i, k)] * v[i]).sum::<f64>();
            (0..d).for_each(|i| v[i] -= c * gens0[(i, k)]);
        }
        unit(&v)?
    };
    let (mut levels, _) = conserved(system, sym, &guess)?;
    if let Some(target) = &options.levels {
        if target.len() != levels.len() - 1 {
            return Err(Error::shape(
                "levels",
                format!(
                    "({},) (the invariants, then the momentum map)",
                    levels.len() - 1
                ),
                format!("({},)", target.len()),
            ));
        }
        levels[1..].copy_from_slice(target);
    }
    let (mut z, mut t) = (guess.clone(), period);
    let rule = Rule {
        tol: options.tol,
        floor: 4.0 * f64::EPSILON,
        max_iter: options.max_iter,
    };
    let mut monitor = Monitor::new(rule);
    let mut accepted = false;
    // The last two updates.
    let mut updates = [0.0_f64; 2];
    loop {
        let shot = shoot(system, lift.as_ref(), method, &z, t, n)?;
        let target = match sym {
            Some(s) => s.act(&zeta, &z)?,
            None => z.clone(),
        };
        let gap: Vec<f64> = shot.end.iter().zip(&target).map(|(a, b)| a - b).collect();
        // The equations but the energy's in the unknowns (z, τ = δT/T, ζ), and the energy's.
        let (values, grads) = conserved(system, sym, &z)?;
        let unit_row = |c: usize| -> Option<(Vec<f64>, f64)> {
            let row: Vec<f64> = (0..d).map(|j| grads[(c, j)]).collect();
            let norm = dot(&row, &row).sqrt();
            (norm > 0.0 && norm.is_finite()).then(|| {
                (
                    row.iter().map(|x| x / norm).collect(),
                    (levels[c] - values[c]) / norm,
                )
            })
        };
        let mut rows: Vec<(Vec<f64>, f64)> = (1..values.len()).filter_map(unit_row).collect();
        let offset: Vec<f64> = z.iter().zip(&guess).map(|(a, b)| a - b).collect();
        rows.push((v.clone(), -dot(&v, &offset)));
        for k in 0..gens0.ncols() {
            let row: Vec<f64> = (0..d).map(|i| gens0[(i, k)]).collect();
            let c = -dot(&row, &offset);
            rows.push((row, c));
        }
        let (act_z, act_zeta) = match sym {
            Some(s) => action_jacobians(s, &zeta, &z)?,
            None => (Mat::identity(d, d), Mat::zeros(d, 0)),
        };
        let full = Mat::from_fn(d + rows.len(), d + 1 + g, |i, j| {
            if i < d {
                if j < d {
                    shot.monodromy[(i, j)] - act_z[(i, j)]
                } else if j == d {
                    shot.along[i] * t
                } else {
                    -act_zeta[(i, j - d - 1)]
                }
            } else if j < d {
                rows[i - d].0[j]
            } else {
                0.0
            }
        });
        // An iterate whose equations hold to round-off while the update stopped decreasing is
        // an orbit: the update is then round-off amplified along near-null directions.
        let floor = ROUNDOFF * (n as f64).sqrt() * scale;
        let settled = updates[1] > 0.0
            && updates[0] >= 0.5 * updates[1]
            && updates[0] <= SETTLED_UPDATE
            && inf_norm(&gap) <= floor
            && rows.iter().all(|r| r.1.abs() <= floor)
            && (options.fix != Fix::Energy || unit_row(0).map_or(true, |r| r.1.abs() <= floor));
        if accepted || settled {
            let tangent = family_tangent(&full, &grads, t)?;
            let drift = sym.map(|_| zeta.clone());
            let mut orbit = finish(
                system,
                sym,
                z,
                t,
                n,
                drift,
                shot,
                &gap,
                monitor.iterations(),
            )?;
            orbit.tangent = tangent;
            orbit.levels = levels[1..].to_vec();
            return Ok(orbit);
        }
        // Newton's matrix: with the energy's row (fix = energy), without the period's column
        // (fix = period), or with the arclength's row.
        let extra: Option<(Vec<f64>, f64)> = match &options.fix {
            Fix::Energy => unit_row(0).map(|(row, c)| {
                let mut r = row;
                r.resize(d + 1 + g, 0.0);
                (r, c)
            }),
            Fix::Period => None,
            Fix::Arclength {
                from,
                tangent,
                step,
            } => {
                let mut u = z.clone();
                u.push(t);
                u.extend_from_slice(&zeta);
                let along: f64 = (0..u.len()).map(|k| tangent[k] * (u[k] - from[k])).sum();
                // The row in the unknowns (z, τ = δT/T, ζ).
                let mut row = tangent.clone();
                row[d] *= t;
                Some((row, step - along))
            }
        };
        let m = full.nrows() + usize::from(extra.is_some());
        let cols: Vec<usize> = (0..d + 1 + g).filter(|&j| period_free || j != d).collect();
        let a = Mat::from_fn(m, cols.len(), |i, k| {
            let j = cols[k];
            match &extra {
                Some((row, _)) if i == full.nrows() => row[j],
                _ => full[(i, j)],
            }
        });
        let b: Vec<f64> = (0..m)
            .map(|i| {
                if i < d {
                    -gap[i]
                } else if i < full.nrows() {
                    rows[i - d].1
                } else {
                    extra.as_ref().map_or(0.0, |e| e.1)
                }
            })
            .collect();
        let step = least_squares(&a, &b)?;
        let mut full_step = vec![0.0; d + 1 + g];
        for (k, &j) in cols.iter().enumerate() {
            full_step[j] = step[k];
        }
        for (zj, s) in z.iter_mut().zip(&full_step) {
            *zj += s;
        }
        system.project(&mut z)?;
        let mut update = inf_norm(&full_step[..d]) / scale;
        t *= 1.0 + full_step[d];
        update = update.max(full_step[d].abs());
        if t.is_nan() || t <= 0.0 {
            update = f64::INFINITY;
        }
        for (x, s) in zeta.iter_mut().zip(&full_step[d + 1..]) {
            *x += s;
            update = update.max(s.abs());
        }
        updates = [update, updates[0]];
        match monitor.check(update, 1.0) {
            Verdict::Continue => {}
            Verdict::Converged => accepted = true,
            Verdict::Failed(failed) => {
                return Err(Error::NotConverged {
                    what: format!(
                        "periodic orbit (Gauss–Newton on the shooting equations; last \
                         ‖Φ(z) − z‖∞ = {:.3e})",
                        inf_norm(&gap)
                    ),
                    iterations: failed.iterations,
                    residual: failed.residual,
                    tol: rule.tol,
                })
            }
        }
    }
}

/// The family's tangent at an orbit: the null vector of the shooting equations without the
/// energy's (columns z, τ = δT/T, ζ), as (δz, δT, δζ) of unit length, oriented so that the
/// energy grows (rows of `grads`: the energy's first).
fn family_tangent(full: &Mat, grads: &Mat, period: f64) -> Result<Vec<f64>> {
    let n = full.ncols();
    let rows = full.nrows().max(n);
    let padded = Mat::from_fn(
        rows,
        n,
        |i, j| {
            if i < full.nrows() {
                full[(i, j)]
            } else {
                0.0
            }
        },
    );
    let svd = padded
        .svd()
        .map_err(|e| eig_error("SVD (the family's tangent)", e))?;
    let v = svd.V();
    let d = grads.ncols();
    let mut t: Vec<f64> = (0..n).map(|j| v[(j, n - 1)]).collect();
    t[d] *= period;
    let de: f64 = (0..d).map(|j| grads[(0, j)] * t[j]).sum();
    let sign = if de < 0.0 { -1.0 } else { 1.0 };
    let norm = dot(&t, &t).sqrt();
    Ok(t.iter().map(|x| sign * x / norm).collect())
}

/// The orbit at the accepted point: residual, multipliers, their split (module docs).
#[allow(clippy::too_many_arguments)]
fn finish(
    system: &dyn System,
    sym: Option<&dyn Symmetric>,
    z: Vec<f64>,
    period: f64,
    steps: usize,
    drift: Option<Vec<f64>>,
    shot: Shot,
    gap: &[f64],
    iterations: usize,
) -> Result<PeriodicOrbit> {
    let residual = inf_norm(gap);
    if residual.is_nan() || residual > RESIDUAL_LIMIT * inf_norm(&z).max(1.0) {
        return Err(Error::NotConverged {
            what: "periodic orbit (the shooting settled on a point that is not periodic: no \
                   orbit of this period or energy near the guess)"
                .into(),
            iterations,
            residual,
            tol: RESIDUAL_LIMIT,
        });
    }
    let d = z.len();
    // The monodromy of exp(−ζ)·Φ_T, and its flow direction.
    let (m, along) = match (sym, &drift) {
        (Some(s), Some(zeta)) => {
            let back: Vec<f64> = zeta.iter().map(|x| -x).collect();
            let (a, _) = action_jacobians(s, &back, &shot.end)?;
            let along = (0..d)
                .map(|i| (0..d).map(|k| a[(i, k)] * shot.along[k]).sum())
                .collect::<Vec<f64>>();
            (&a * &shot.monodromy, along)
        }
        _ => (shot.monodromy, shot.along),
    };
    let multipliers = by_modulus(general_eigenvalues(&m)?);
    // The level set of the conserved quantities inside the range of M (the states M reaches:
    // for a constrained system the constraint manifold's tangent space).
    let (_, grads) = conserved(system, sym, &z)?;
    let reach = range(&m)?;
    let level = &reach * null_space(&(&grads * &reach))?;
    // W: the flow and the generators tangent to the level set (the isotropy's).
    let f = unit(&along)?;
    let mut w_cols: Vec<Vec<f64>> = vec![f];
    if let Some(s) = sym {
        let iso = isotropy_generators(s, &z)?;
        w_cols.extend((0..iso.ncols()).map(|k| (0..d).map(|i| iso[(i, k)]).collect()));
    }
    let w = range(&Mat::from_fn(d, w_cols.len(), |i, k| w_cols[k][i]))?;
    // V = level ⊖ W, and the map M induces on level/W: Vᵀ(I − WWᵀ)MV.
    let w_in_level = level.transpose() * &w;
    let v = &level * null_space(&w_in_level.transpose().to_owned())?;
    let pm = &m - &w * (w.transpose() * &m);
    let reduced = v.transpose() * &pm * &v;
    let normal = by_modulus(general_eigenvalues(&reduced.to_owned())?);
    // The trivial multipliers: those of M left when each normal one has taken its nearest.
    let mut trivial = vec![true; d];
    for &(re, im) in &normal {
        let nearest = (0..d).filter(|&k| trivial[k]).min_by(|&a, &b| {
            let da = (multipliers[a].0 - re).hypot(multipliers[a].1 - im);
            let db = (multipliers[b].0 - re).hypot(multipliers[b].1 - im);
            da.total_cmp(&db)
        });
        if let Some(k) = nearest {
            trivial[k] = false;
        }
    }
    // Reported: M's own eigenvalues (exact for the map); the quotient only told them apart,
    // with the method's error in its flow and level set (module docs).
    let normal: Vec<(f64, f64)> = (0..d)
        .filter(|&k| !trivial[k])
        .map(|k| multipliers[k])
        .collect();
    Ok(PeriodicOrbit {
        energy: system.energy(&z)?,
        state0: z,
        period,
        steps,
        monodromy: m,
        multipliers,
        trivial,
        normal,
        residual,
        iterations,
        drift,
        levels: Vec::new(),
        tangent: Vec::new(),
    })
}

/// By descending modulus, then descending argument.
fn by_modulus(mut v: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    v.sort_by(|x, y| {
        y.0.hypot(y.1)
            .total_cmp(&x.0.hypot(x.1))
            .then(y.1.atan2(y.0).total_cmp(&x.1.atan2(x.0)))
    });
    v
}

/// The drift of a relative periodic orbit of a body that carries an SO(3) attitude R
/// ([`System::lift`]): its momentum (the reduced state) returns after the period while R
/// does not; R(T) = g R(0) with g = exp(ω̂) a rotation of space (for the free rigid body about
/// the spatial momentum R M, by the angle of Montgomery's formula). Returns ω, the rotation
/// vector of g (‖ω‖ ≤ π), from a run of the system carrying `attitude` (rows of R(0)) over the
/// orbit's steps with the same method.
///
/// # Errors
/// [`Error::InvalidArgument`] for a system without an attitude; the errors of the run
/// ([`Error::NotInGroup`] for an attitude that is not a rotation).
pub fn attitude_drift(
    system: &dyn System,
    method: &str,
    orbit: &PeriodicOrbit,
    attitude: &[f64; 9],
) -> Result<[f64; 3]> {
    let d = orbit.state0.len();
    let lifted = system
        .lift()
        .filter(|l| l.space().dim() == d + 9)
        .ok_or_else(|| Error::InvalidArgument {
            what: "attitude".into(),
            message: format!("{} carries no SO(3) attitude", system.name()),
        })?;
    let mut z0 = orbit.state0.clone();
    z0.extend_from_slice(attitude);
    let n = orbit.steps;
    let traj = integrate(lifted.as_ref(), method, &z0, orbit.period / n as f64, n, n)?;
    let rows = |z: &[f64]| nalgebra::Matrix3::from_row_slice(&z[d..d + 9]);
    let (r0, r1) = (rows(&z0), rows(traj.state(1)));
    let w = crate::lie::so3::log_unchecked(&(r1 * r0.transpose()));
    Ok([w[0], w[1], w[2]])
}
