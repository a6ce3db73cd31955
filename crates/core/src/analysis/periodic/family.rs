//! Families of periodic orbits by pseudo-arclength continuation of the shooting (issue 27).
//!
//! The shooting equations of [`periodic_orbit`] are overdetermined (the map, the phase, the
//! slice, the levels; consistent at an orbit) and re-based at each guess, so a family is not a
//! [`crate::analysis::continuation::Family`] (N − 1 equations in N unknowns, Newton's method):
//! it is followed here with the shooting itself as corrector ([`Fix::Arclength`]: the
//! Gauss–Newton iteration with the pseudo-arclength row) and the orbit's own family tangent
//! ([`PeriodicOrbit::tangent`]) as predictor.
//!
//! - **Step.** The state moves by `step` of its size (max(1, ‖z₀‖∞)) along the tangent; the step
//!   grows by 1.5 after an easy orbit (≤ 7 iterations) up to `max_step` and halves after a
//!   failed one, down to 1e-4 of the first.
//! - **Acceptance.** An orbit whose state lies further than half a step from the prediction,
//!   or whose tangent turned by more than arccos 0.9 ≈ 26°, is refused (another family).
//! - **Special points** between consecutive orbits: a change of stability (the normal
//!   multipliers) is located by bisection on the secant of the unknowns (12 halvings) and named
//!   by how the multipliers left the unit circle at the orbit found on the unstable side
//!   ([`Kind`]); a turn of the parameter is a [`Kind::Fold`]. Where the energy and the period
//!   reverse together the continuation would retrace the family in invariant terms (so it does
//!   past the end where the orbits shrink onto an equilibrium: their amplitude changes sign):
//!   it ends there ([`End::TurnedBack`]).

use super::{periodic_orbit, Fix, Options, PeriodicOrbit, STABLE_TOL};
use crate::error::{Error, Result};
use crate::integrate::System;

/// Halvings of the secant that locate a change of stability (to 2⁻¹² of the step).
const BISECTIONS: usize = 12;

/// A corrected orbit further than this many steps from its prediction is refused.
const MAX_CORRECTION: f64 = 0.5;

/// An orbit whose tangent has a smaller |cosine| with the last one is refused.
const MIN_COSINE: f64 = 0.9;

/// Gauss–Newton iterations of a corrector.
const CORRECTOR_ITERATIONS: usize = 30;

/// An orbit found in at most this many iterations lets the step grow.
const EASY_ITERATIONS: usize = 7;

/// The quantity a family's values, stop and folds refer to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parameter {
    /// The energy H(z₀).
    Energy,
    /// The period T.
    Period,
}

impl Parameter {
    /// Its value at an orbit.
    pub fn of(self, orbit: &PeriodicOrbit) -> f64 {
        match self {
            Parameter::Energy => orbit.energy,
            Parameter::Period => orbit.period,
        }
    }
}

/// How the continuation of [`periodic_family`] proceeds.
#[derive(Clone, Debug, PartialEq)]
pub struct FamilyOptions {
    /// What `stop` and the folds refer to.
    pub parameter: Parameter,
    /// Stop once the parameter passes this value.
    pub stop: Option<f64>,
    /// The first step, relative to the state's size.
    pub step: f64,
    /// The largest step.
    pub max_step: f64,
    /// The largest number of orbits (the start included).
    pub max_points: usize,
    /// Towards higher energy (> 0) or lower (< 0) at the start.
    pub direction: f64,
    /// The shooting's tolerance.
    pub tol: f64,
}

impl Default for FamilyOptions {
    fn default() -> Self {
        FamilyOptions {
            parameter: Parameter::Energy,
            stop: None,
            step: 0.02,
            max_step: 0.05,
            max_points: 40,
            direction: 1.0,
            tol: 1e-10,
        }
    }
}

/// What happens at a special point of a family.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A normal multiplier through −1.
    PeriodDoubling,
    /// Through +1: a fold or a branch point of orbits of the same period.
    Tangent,
    /// Two pairs collide on the unit circle and leave it as a quadruplet.
    Krein,
    /// The parameter turns back (not located beyond the orbits).
    Fold,
}

impl Kind {
    /// "period_doubling", "tangent", "krein" or "fold".
    pub fn name(self) -> &'static str {
        match self {
            Kind::PeriodDoubling => "period_doubling",
            Kind::Tangent => "tangent",
            Kind::Krein => "krein",
            Kind::Fold => "fold",
        }
    }

    /// How the normal multipliers of an unstable orbit left the unit circle: by the one of
    /// largest modulus (off the real axis: Krein; on it: −1 or +1).
    fn of(orbit: &PeriodicOrbit) -> Kind {
        let out = orbit
            .normal
            .iter()
            .filter(|&&(re, im)| re.hypot(im) > 1.0 + STABLE_TOL)
            .max_by(|a, b| a.0.hypot(a.1).total_cmp(&b.0.hypot(b.1)));
        match out {
            None => Kind::Tangent,
            Some(&(re, im)) if im.abs() > STABLE_TOL * re.hypot(im) => Kind::Krein,
            Some(&(re, _)) if re < 0.0 => Kind::PeriodDoubling,
            Some(_) => Kind::Tangent,
        }
    }
}

/// A special point of a family.
#[derive(Clone, Debug)]
pub struct SpecialPoint {
    /// What happens there.
    pub kind: Kind,
    /// It lies after `points[index]`.
    pub index: usize,
    /// The parameter there.
    pub value: f64,
    /// The orbit there (for a change of stability: on the unstable side, within 2⁻¹² of the
    /// step; for a fold: the orbit at the turn).
    pub orbit: PeriodicOrbit,
}

/// Why the continuation ended.
#[derive(Clone, Debug, PartialEq)]
pub enum End {
    /// The parameter passed `stop`.
    Stop,
    /// `max_points` orbits.
    MaxPoints,
    /// The corrector failed at the smallest step.
    Stuck,
    /// Energy and period reversed together after the orbit with this energy and period.
    TurnedBack {
        /// The last orbit's energy.
        energy: f64,
        /// Its period.
        period: f64,
    },
}

impl std::fmt::Display for End {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            End::Stop => write!(f, "stop"),
            End::MaxPoints => write!(f, "max_points"),
            End::Stuck => write!(f, "stuck: the corrector failed at the smallest step"),
            End::TurnedBack { energy, period } => write!(
                f,
                "turned back: energy and period reverse together after E = {energy:.10}, \
                 T = {period:.10} (the family's end, e.g. on an equilibrium its orbits shrink \
                 onto)"
            ),
        }
    }
}

/// A followed family.
#[derive(Clone, Debug)]
pub struct PeriodicFamily {
    /// The orbits in the order of continuation (the start first).
    pub points: Vec<PeriodicOrbit>,
    /// The special points in the order met.
    pub special: Vec<SpecialPoint>,
    /// Why it ended.
    pub end: End,
}

/// u = (z, T, ζ): the unknowns of an orbit ([`PeriodicOrbit::tangent`]'s layout).
fn unknowns(orbit: &PeriodicOrbit) -> Vec<f64> {
    let mut u = orbit.state0.clone();
    u.push(orbit.period);
    if let Some(zeta) = &orbit.drift {
        u.extend_from_slice(zeta);
    }
    u
}

/// The continuation's settings for one family (the start's method, steps, levels).
struct Corrector<'a> {
    system: &'a dyn System,
    method: &'a str,
    shooting: Options,
    state_dim: usize,
}

impl Corrector<'_> {
    /// The orbit at arclength h from u₀ along t; `None` where the shooting fails (errors of
    /// user code and interruptions are passed on).
    fn correct(&self, u0: &[f64], t: &[f64], h: f64) -> Result<Option<PeriodicOrbit>> {
        let d = self.state_dim;
        let u: Vec<f64> = u0.iter().zip(t).map(|(a, b)| a + h * b).collect();
        let options = Options {
            fix: Fix::Arclength {
                from: u0.to_vec(),
                tangent: t.to_vec(),
                step: h,
            },
            ..self.shooting.clone()
        };
        let drift = (u.len() > d + 1).then(|| &u[d + 1..]);
        match periodic_orbit(self.system, self.method, &u[..d], u[d], drift, &options) {
            Ok(orbit) => Ok(Some(orbit)),
            Err(e @ (Error::Raised { .. } | Error::Interrupted { .. })) => Err(e),
            Err(_) => Ok(None),
        }
    }

    /// The change of stability between orbits a and b (consecutive), by bisection on the
    /// secant of their unknowns.
    fn locate(
        &self,
        a: &PeriodicOrbit,
        b: &PeriodicOrbit,
        index: usize,
        parameter: Parameter,
    ) -> Result<SpecialPoint> {
        let (ua, ub) = (unknowns(a), unknowns(b));
        let chord: Vec<f64> = ub.iter().zip(&ua).map(|(x, y)| x - y).collect();
        let length = chord.iter().map(|x| x * x).sum::<f64>().sqrt();
        let direction: Vec<f64> = chord.iter().map(|x| x / length).collect();
        let (mut lo, mut hi) = (0.0, 1.0);
        let mut unstable = if b.stable() { a.clone() } else { b.clone() };
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            let Some(orbit) = self.correct(&ua, &direction, mid * length)? else {
                break;
            };
            if orbit.stable() == a.stable() {
                lo = mid;
            } else {
                hi = mid;
                unstable = orbit;
            }
        }
        Ok(SpecialPoint {
            kind: Kind::of(&unstable),
            index,
            value: parameter.of(&unstable),
            orbit: unstable,
        })
    }
}

/// Follows the family of periodic (or relative periodic) orbits through `start` (from
/// [`periodic_orbit`], with its tangent and levels), at the start's levels, with `method` and
/// the start's steps per period; `shooting` gives the Gauss–Newton iterations' limit and
/// nothing else (the tolerance is `options.tol`). `progress` sees every accepted orbit and
/// may end the continuation with an error (an interruption).
///
/// # Errors
/// [`Error::InvalidArgument`] for steps or counts out of range or a start without a tangent;
/// those of `progress`; the errors of user code in the system ([`Error::Raised`]).
pub fn periodic_family(
    system: &dyn System,
    method: &str,
    start: &PeriodicOrbit,
    options: &FamilyOptions,
    progress: &mut dyn FnMut(&PeriodicOrbit) -> Result<()>,
) -> Result<PeriodicFamily> {
    let d = start.state0.len();
    let k = d + 1 + start.drift.as_ref().map_or(0, Vec::len);
    if start.tangent.len() != k {
        return Err(Error::invalid(
            "orbit",
            format!(
                "a periodic orbit with its family tangent ({k} values), got {}",
                start.tangent.len()
            ),
        ));
    }
    let FamilyOptions {
        parameter,
        stop,
        step,
        max_step,
        max_points,
        direction,
        tol,
    } = *options;
    if !(step > 0.0 && step.is_finite() && max_step >= step && max_step.is_finite()) {
        return Err(Error::invalid(
            "step",
            format!(
                "expected 0 < step <= max_step, finite; got step = {step}, max_step = {max_step}"
            ),
        ));
    }
    if max_points == 0 || !(tol > 0.0 && tol < 1.0) || direction.is_nan() {
        return Err(Error::invalid(
            "max_points",
            format!(
                "expected max_points >= 1, 0 < tol < 1 and a direction; got {max_points}, \
                 {tol}, {direction}"
            ),
        ));
    }
    let corrector = Corrector {
        system,
        method,
        shooting: Options {
            steps: start.steps,
            fix: Fix::Energy,
            tol,
            max_iter: CORRECTOR_ITERATIONS,
            relative: start.drift.is_some(),
            levels: Some(start.levels.clone()),
        },
        state_dim: d,
    };
    let scale = start.state0.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
    let sign = if direction < 0.0 { -1.0 } else { 1.0 };
    let mut tan: Vec<f64> = start.tangent.iter().map(|x| sign * x).collect();
    let mut points = vec![start.clone()];
    let mut special = Vec::new();
    let mut ds = step;
    let mut end = End::MaxPoints;
    while points.len() < max_points {
        let last = points.last().expect("the start");
        let u0 = unknowns(last);
        let largest = tan[..d].iter().fold(1e-300_f64, |m, x| m.max(x.abs()));
        let h = ds * scale / largest;
        // The new orbit continues the family when the corrector stayed near the prediction and
        // the tangent turned little; else (another family, or none) a shorter step.
        let new = corrector.correct(&u0, &tan, h)?.filter(|new| {
            let moved = (0..d).fold(0.0_f64, |m, i| {
                m.max((new.state0[i] - (u0[i] + h * tan[i])).abs())
            }) / (ds * scale);
            let turn = new
                .tangent
                .iter()
                .zip(&tan)
                .map(|(a, b)| a * b)
                .sum::<f64>();
            moved <= MAX_CORRECTION && turn.abs() >= MIN_COSINE
        });
        let Some(new) = new else {
            if ds <= 1e-4 * step {
                end = End::Stuck;
                break;
            }
            ds *= 0.5;
            continue;
        };
        let index = points.len() - 1;
        if let Some(before) = points.len().checked_sub(2).map(|i| &points[i]) {
            let reverses =
                |f: fn(&PeriodicOrbit) -> f64| (f(last) - f(before)) * (f(&new) - f(last)) < 0.0;
            if reverses(|o| o.energy) && reverses(|o| o.period) {
                end = End::TurnedBack {
                    energy: last.energy,
                    period: last.period,
                };
                break;
            }
            let (a, b, c) = (parameter.of(before), parameter.of(last), parameter.of(&new));
            if (b - a) * (c - b) < 0.0 {
                special.push(SpecialPoint {
                    kind: Kind::Fold,
                    index,
                    value: b,
                    orbit: last.clone(),
                });
            }
        }
        if last.stable() != new.stable() {
            special.push(corrector.locate(last, &new, index, parameter)?);
        }
        progress(&new)?;
        // The new tangent oriented as the family goes (it may turn at a fold of the energy).
        let along = new
            .tangent
            .iter()
            .zip(&tan)
            .map(|(a, b)| a * b)
            .sum::<f64>();
        let sign = if along < 0.0 { -1.0 } else { 1.0 };
        tan = new.tangent.iter().map(|x| sign * x).collect();
        if new.iterations <= EASY_ITERATIONS {
            ds = max_step.min(1.5 * ds);
        }
        let passed =
            stop.is_some_and(|s| (parameter.of(&new) - s) * (parameter.of(start) - s) <= 0.0);
        points.push(new);
        if passed {
            end = End::Stop;
            break;
        }
    }
    Ok(PeriodicFamily {
        points,
        special,
        end,
    })
}
