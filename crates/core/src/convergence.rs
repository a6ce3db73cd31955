//! The one stopping rule of lieflow's iterative solves: the Newton, simplified Newton and
//! fixed-point iterations of the implicit methods (Gauss–Legendre, the Lie midpoint and the
//! implicit kicks of forced systems, RATTLE and its nonholonomic variant, the isospectral
//! midpoint, the LGVI, DMV), the Legendre inversion of the relativistic tops and the corrector of
//! continuation.
//!
//! After each iteration the solver hands [`Monitor::check`] the size d_k of its update and the
//! scale s of its unknowns (each solver names its norm and scale); with the solver's [`Rule`]
//! (tol, floor, max_iter) the verdict is:
//!
//! * d_k not finite: failure (the iteration diverged);
//! * d_k ≤ floor·s: converged at once (the update is round-off: nothing is left to gain);
//! * d_k ≤ tol·s and d_k ≥ d_{k−1}: converged (the update stopped decreasing: round-off reached);
//! * k = max_iter: converged if d_k ≤ tol·s, else failure;
//! * otherwise: iterate on.
//!
//! So an iterate is accepted once its update is below the tolerance, and the iteration then goes
//! on towards round-off while the update keeps decreasing — the rule of Hairer, McLachlan &
//! Razakarivony, "Achieving Brouwer's law with implicit Runge–Kutta methods", BIT 48 (2008),
//! without which a solve stopped at a tolerance leaves a systematic O(tol) error per step (a linear
//! energy drift over long runs). A solve never fails with its last update below the tolerance (a
//! sequence still shrinking far below it at max_iter is a solution), and every failure reports
//! its true last update d_k/s (∞ for a diverged iteration) with the tolerance.
//!
//! The floor is where a solver's own iteration has nothing left to gain: ε² for the simplified
//! Newton iteration of Gauss, a few ε for the Newton iterations of RATTLE and the LGVI (whose next
//! update would be round-off), 0 (an exactly zero update) for the Lie midpoint. DMV also stops
//! where its contraction rate bounds the error left below round-off (always below the tolerance),
//! and the Legendre inversion takes one more Newton step after converging.

/// The acceptance tolerance of the step solves of the integrators, relative to their scale.
pub const TOL: f64 = 1e-12;

/// A stopping rule (module docs): tolerance and round-off floor relative to the solve's scale,
/// and the number of iterations allowed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rule {
    /// An iterate whose update is at most tol·s is a solution.
    pub tol: f64,
    /// An update at most floor·s ends the iteration at once (0: only a zero update).
    pub floor: f64,
    /// Iterations allowed.
    pub max_iter: usize,
}

impl Rule {
    /// The rule for a tangent lift's solve with `blocks` diagonal blocks (the state and its
    /// directions, [`crate::integrate::tangent`]): the directions start converging when the
    /// state has, at its rate, so twice the iterations (with the plain limit a step that
    /// converges plainly could fail with its directions). The rule itself for `blocks` ≤ 1.
    pub fn for_blocks(self, blocks: usize) -> Rule {
        match blocks > 1 {
            true => Rule {
                max_iter: 2 * self.max_iter,
                ..self
            },
            false => self,
        }
    }
}

/// A solve that failed: the iterations taken and the last update relative to the scale (∞ for
/// a diverged iteration or a singular linear system).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Failed {
    /// Iterations taken.
    pub iterations: usize,
    /// The last update, relative to the scale.
    pub residual: f64,
}

/// The verdict of [`Monitor::check`] after one iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// Iterate on.
    Continue,
    /// Stop: the last iterate is the solution.
    Converged,
    /// Stop: no solution.
    Failed(Failed),
}

/// One solve under a [`Rule`]: counts the iterations and remembers the last update.
#[derive(Clone, Copy, Debug)]
pub struct Monitor {
    rule: Rule,
    iterations: usize,
    last: f64,
}

impl Monitor {
    /// A solve about to start.
    #[inline]
    pub fn new(rule: Rule) -> Self {
        Monitor {
            rule,
            iterations: 0,
            last: f64::INFINITY,
        }
    }

    /// The verdict after an iteration whose update has size `update`, the unknowns scale
    /// `scale` (module docs).
    #[inline]
    pub fn check(&mut self, update: f64, scale: f64) -> Verdict {
        self.iterations += 1;
        let prev = std::mem::replace(&mut self.last, update);
        let Rule {
            tol,
            floor,
            max_iter,
        } = self.rule;
        if !update.is_finite() {
            return Verdict::Failed(self.failed(f64::INFINITY));
        }
        let below = update <= tol * scale;
        if update <= floor * scale || (below && update >= prev) {
            Verdict::Converged
        } else if self.iterations >= max_iter {
            if below {
                Verdict::Converged
            } else {
                Verdict::Failed(self.failed(update / scale))
            }
        } else {
            Verdict::Continue
        }
    }

    /// The last update (∞ before the first).
    #[inline]
    pub fn last(&self) -> f64 {
        self.last
    }

    /// The iterations taken.
    #[inline]
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// A failure after the iterations taken, with `residual`.
    pub fn failed(&self, residual: f64) -> Failed {
        Failed {
            iterations: self.iterations,
            residual,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RULE: Rule = Rule {
        tol: 1e-12,
        floor: 1e-30,
        max_iter: 5,
    };

    fn run(updates: &[f64]) -> Verdict {
        let mut m = Monitor::new(RULE);
        for &d in updates {
            match m.check(d, 1.0) {
                Verdict::Continue => {}
                v => return v,
            }
        }
        Verdict::Continue
    }

    #[test]
    fn the_rule() {
        // Decreasing below the tolerance: on to stagnation.
        assert_eq!(run(&[1e-3, 1e-13, 1e-15, 1e-14]), Verdict::Converged);
        assert_eq!(run(&[1e-3, 1e-13, 1e-15]), Verdict::Continue);
        // Stagnation above the tolerance is no solution; at the last iteration it fails.
        assert_eq!(run(&[1e-3, 1e-3, 1e-3]), Verdict::Continue);
        assert_eq!(
            run(&[1e-3, 1e-4, 1e-5, 1e-6, 1e-7]),
            Verdict::Failed(Failed {
                iterations: 5,
                residual: 1e-7
            })
        );
        // Still decreasing below the tolerance at the last iteration: a solution.
        assert_eq!(run(&[1e-3, 1e-13, 1e-14, 1e-15, 1e-16]), Verdict::Converged);
        // The floor ends it at once; zero always does.
        assert_eq!(run(&[1e-31]), Verdict::Converged);
        assert_eq!(run(&[1.0, 0.0]), Verdict::Converged);
        // Not finite: diverged.
        assert_eq!(
            run(&[1.0, f64::NAN]),
            Verdict::Failed(Failed {
                iterations: 2,
                residual: f64::INFINITY
            })
        );
    }
}
