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
//! **Blocks.** A tangent lift's solve ([`crate::integrate::tangent`]) has the unknowns of the
//! state and of its directions, block lower-triangular: the state's iterates are the plain
//! solve's, and each direction's solution is linear in its own data and moves with the state's
//! iterate. [`Blocks`] applies the rule to each block against its own scale (never one scale
//! for all: directions of 10¹⁰ made the state's update meaningless, and the reverse): the state
//! as in the plain solve (same verdict, same iteration); once it is accepted it is no longer
//! updated ([`Blocks::active`]), and each direction goes on under the rule, counted afresh, until
//! it is accepted too. A state still moving at round-off made the directions chase it: the
//! rolling disk's lift at dt = 1.5 stagnated at 2.7e-12 of the lifted momenta (its directions
//! 2e-11 of their own) where the plain solve had converged at 8e-14.
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

/// The rule ([`Monitor`]) on a solve whose unknowns are a state (block 0) and its directions
/// (blocks 1…B−1; module docs): each block's update against its own scale; the state under the
/// rule as in the plain solve; once it is accepted it and then each accepted direction stay
/// fixed ([`Blocks::active`]) while the others iterate, each under the rule from the state's
/// acceptance (so up to about 2·max_iter iterations in all). With one block, [`Monitor`] itself.
/// Allocated once per stepper, [`Blocks::start`]ed for each solve.
#[derive(Clone, Debug)]
pub struct Blocks {
    rule: Rule,
    /// The state's monitor, then the directions' (started when the state is accepted).
    monitors: Vec<Monitor>,
    /// Whether block b is accepted (no longer updated).
    done: Vec<bool>,
    iterations: usize,
}

impl Blocks {
    /// A monitor of `blocks` ≥ 1 blocks under `rule`.
    pub fn new(rule: Rule, blocks: usize) -> Self {
        let blocks = blocks.max(1);
        Blocks {
            rule,
            monitors: vec![Monitor::new(rule); blocks],
            done: vec![false; blocks],
            iterations: 0,
        }
    }

    /// The number of blocks.
    #[inline]
    pub fn blocks(&self) -> usize {
        self.done.len()
    }

    /// A solve about to start.
    pub fn start(&mut self) {
        self.monitors[0] = Monitor::new(self.rule);
        self.done.fill(false);
        self.iterations = 0;
    }

    /// Whether block b's unknowns still iterate (false once it is accepted: the solver leaves
    /// them as they are).
    #[inline]
    pub fn active(&self, b: usize) -> bool {
        !self.done[b]
    }

    /// The verdict after an iteration whose update of block b has size `updates[b]`, its
    /// unknowns scale `scales[b]` (an accepted block's entries are not read).
    pub fn check(&mut self, updates: &[f64], scales: &[f64]) -> Verdict {
        self.iterations += 1;
        let iterations = self.iterations;
        let failed = |residual| {
            Verdict::Failed(Failed {
                iterations,
                residual,
            })
        };
        let n = self.done.len();
        if !self.done[0] {
            // A direction that diverges fails the solve at once; the others wait for the state.
            if updates[1..n].iter().any(|u| !u.is_finite()) {
                return failed(f64::INFINITY);
            }
            match self.monitors[0].check(updates[0], scales[0]) {
                Verdict::Converged => self.done[0] = true,
                verdict => return verdict,
            }
            for m in &mut self.monitors[1..] {
                *m = Monitor::new(self.rule);
            }
        }
        let (mut verdict, mut worst) = (Verdict::Converged, None::<f64>);
        for b in 1..n {
            if self.done[b] {
                continue;
            }
            match self.monitors[b].check(updates[b], scales[b]) {
                Verdict::Converged => self.done[b] = true,
                Verdict::Continue => verdict = Verdict::Continue,
                Verdict::Failed(f) => worst = Some(worst.map_or(f.residual, |w| w.max(f.residual))),
            }
        }
        worst.map_or(verdict, failed)
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

    /// Runs a block monitor on (updates, scales) per iteration: the verdicts and, after each,
    /// which blocks still iterate.
    fn run_blocks(steps: &[(&[f64], &[f64])]) -> Vec<(Verdict, Vec<bool>)> {
        let mut m = Blocks::new(RULE, steps[0].0.len());
        m.start();
        let mut out = Vec::new();
        for (u, s) in steps {
            let v = m.check(u, s);
            out.push((v, (0..m.blocks()).map(|b| m.active(b)).collect()));
            if v != Verdict::Continue {
                break;
            }
        }
        out
    }

    #[test]
    fn the_rule_on_blocks() {
        let last = |steps: &[(&[f64], &[f64])]| run_blocks(steps).last().unwrap().0;
        // One block: the rule itself.
        for updates in [
            &[1e-3, 1e-13, 1e-15, 1e-14][..],
            &[1e-3, 1e-4, 1e-5, 1e-6, 1e-7],
            &[1.0, f64::NAN],
        ] {
            let steps: Vec<(&[f64], &[f64])> = updates
                .iter()
                .map(|u| (std::slice::from_ref(u), &[1.0][..]))
                .collect();
            assert_eq!(last(&steps), run(updates));
        }
        // Each block against its own scale: a direction of 10¹⁰ whose update is 1e-3 is
        // converged, and does not hide the state's update.
        let s: &[f64] = &[1.0, 1e10];
        let steps: [(&[f64], &[f64]); 4] = [
            (&[1e-3, 1e8], s),
            (&[1e-14, 1e-3], s),
            (&[1e-14, 1e-4], s),
            (&[0.0, 2e-4], s),
        ];
        let verdicts = run_blocks(&steps);
        // The state stops as in the plain solve (iteration 3), then stays; the direction is
        // counted afresh: below the tolerance at 3, stagnating at 4.
        assert_eq!(verdicts[1], (Verdict::Continue, vec![true, true]));
        assert_eq!(verdicts[2], (Verdict::Continue, vec![false, true]));
        assert_eq!(verdicts[3], (Verdict::Converged, vec![false, false]));
        // The state's failure is the plain one (the directions' updates are not read).
        let s: &[f64] = &[1.0, 1.0];
        let mut steps: Vec<(&[f64], &[f64])> = vec![(&[1e-3, 1e-20], s); 5];
        steps[4] = (&[1e-7, 1e-20], s);
        assert_eq!(
            last(&steps),
            Verdict::Failed(Failed {
                iterations: 5,
                residual: 1e-7
            })
        );
        // A direction has max_iter iterations from the state's acceptance (at 2), and fails
        // with its own last update relative to its scale.
        let mut steps: Vec<(&[f64], &[f64])> = vec![(&[1e-3, 1.0], s), (&[0.0, 1.0], s)];
        steps.extend([(&[0.0, 1e-9][..], s); 4]);
        assert_eq!(
            last(&steps),
            Verdict::Failed(Failed {
                iterations: 6,
                residual: 1e-9
            })
        );
        // A diverged direction fails the solve at once, before or after the state's acceptance.
        for steps in [
            [(&[1e-3, f64::INFINITY][..], s)],
            [(&[0.0, f64::NAN][..], s)],
        ] {
            assert_eq!(
                last(&steps),
                Verdict::Failed(Failed {
                    iterations: 1,
                    residual: f64::INFINITY
                })
            );
        }
        // A restarted monitor iterates every block again.
        let mut m = Blocks::new(RULE, 2);
        assert_eq!(m.check(&[0.0, 0.0], s), Verdict::Converged);
        m.start();
        assert!(m.active(0) && m.active(1));
    }
}
