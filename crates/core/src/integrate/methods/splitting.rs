//! `Splitting(Composition)`: the palindromic Strang step of a [`Split`] problem's exact flows,
//! composed to order 2, 4 or 6 ([`Composition`]).
//!
//! Each flow is the exact flow of a piece of the Hamiltonian, so the method is a Poisson map: it
//! keeps every Casimir of the bracket and every momentum map the pieces share, and is symplectic
//! where the pieces are Hamiltonian on a symplectic space. The first and last flows of consecutive
//! steps are fused (they are the same flow), unless the problem checks every step
//! ([`Split::CHECKED`]). The fusion is lazy: the time of the outer flow that ends a step is kept
//! pending and applied with the next step (or, on a copy, when the state is read), so the
//! sequence of operations — and the result, bit for bit — does not depend on how a run is cut
//! into calls of [`Stepper::advance`].

use super::composition::{run_sequence, Composition};
use crate::error::Result;
use crate::integrate::method::{Clock, Integrator, Properties, Stepper};
use crate::integrate::problem::Split;

/// The splitting method of a [`Split`] problem with the given composition.
#[derive(Clone, Debug, PartialEq)]
pub struct Splitting(pub Composition);

impl Splitting {
    /// Strang splitting, order 2.
    pub fn strang() -> Self {
        Splitting(Composition::strang())
    }
}

impl<P: Split + Clone + 'static> Integrator<P> for Splitting {
    fn properties(&self) -> Properties {
        Properties::geometric(self.0.order())
    }

    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>> {
        Ok(Box::new(SplittingStepper {
            seq: self.0.sequence(problem.flows()),
            problem: problem.clone(),
            h: dt,
            work: None,
            pending: 0.0,
        }))
    }
}

struct SplittingStepper<P: Split> {
    problem: P,
    seq: Vec<(usize, f64)>,
    h: f64,
    work: Option<P::Work>,
    /// Time of the outer flow `seq[0]` not yet applied (lazy first-same-as-last fusion).
    pending: f64,
}

impl<P: Split> Stepper for SplittingStepper<P> {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.work = Some(self.problem.load(z)?);
        self.pending = 0.0;
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        if let Some(w) = &self.work {
            if self.pending == 0.0 {
                self.problem.store(w, z);
            } else {
                let mut w = w.clone();
                self.problem.flow(self.seq[0].0, self.pending, &mut w);
                self.problem.store(&w, z);
            }
        }
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        let Some(w) = self.work.as_mut() else {
            return Ok(());
        };
        let p = &self.problem;
        let flow = |i: usize, tau: f64, w: &mut P::Work| p.flow(i, tau, w);
        if P::CHECKED {
            for k in 0..steps {
                run_sequence(&self.seq, self.h, 1, w, flow);
                p.check_step(w).map_err(|v| clock.left_domain(k, v))?;
            }
            return Ok(());
        }
        let (h, seq) = (self.h, &self.seq);
        let (outer, c0) = seq[0];
        let inner = &seq[1..seq.len().saturating_sub(1)];
        let c_last = if seq.len() > 1 {
            seq[seq.len() - 1].1
        } else {
            0.0
        };
        for _ in 0..steps {
            self.pending += c0 * h;
            if inner.is_empty() && seq.len() == 1 {
                continue; // a single flow: its times add up until the state is read
            }
            flow(outer, self.pending, w);
            for &(i, c) in inner {
                flow(i, c * h, w);
            }
            self.pending = c_last * h;
        }
        Ok(())
    }
}
