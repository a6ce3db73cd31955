//! `Splitting(Composition)`: the palindromic Strang step of a [`Split`] problem's exact flows,
//! composed to order 2, 4, 6 or 8 ([`Composition`]); `ProcessedSplitting(Processed)`: the same
//! kernel conjugated by a processor ([`Processed`]), effective order 6, 8 or 10.
//!
//! Each flow is the exact flow of a piece of the Hamiltonian, so the method is a Poisson map: it
//! keeps every Casimir of the bracket and every momentum map the pieces share, and is symplectic
//! where the pieces are Hamiltonian on a symplectic space. The first and last flows of consecutive
//! steps are fused (they are the same flow), unless the problem checks every step
//! ([`Split::CHECKED`]). The fusion is lazy: the time of the outer flow that ends a step is kept
//! pending and applied with the next step (or, on a copy, when the state is read), so the
//! sequence of operations — and the result, bit for bit — does not depend on how a run is cut
//! into calls of [`Stepper::advance`]. A processed method keeps the kernel's variable
//! y = P(x): the processor runs when a state is set, its inverse on a copy when one is read.
//!
//! A problem whose flows also run on many members at once ([`Split::lanes`]) gets a
//! [`BatchStepper`] for batches: the members' states side by side in one block, the same fused
//! sequence, each member's lazy outer flow kept apart. Its one-member stepper is that batch
//! stepper of one member, so that a member ends bit for bit where it would alone by
//! construction (and one body runs the same kernel, without a dispatch per flow).

use std::sync::Arc;

use super::composition::{run_sequence, Composition, Processed, Sequence};
use crate::error::Result;
use crate::integrate::method::{BatchStepper, Clock, Integrator, Properties, Stepper};
use crate::integrate::problem::{Program, Split, SplitLanes};

/// The splitting method of a [`Split`] problem with the given composition.
#[derive(Clone, Debug, PartialEq)]
pub struct Splitting(pub Composition);

impl Splitting {
    /// Strang splitting, order 2.
    pub fn strang() -> Self {
        Splitting(Composition::strang())
    }
}

/// The processed splitting method of a [`Split`] problem: the kernel of the [`Processed`]
/// composition every step, its processor when a state is set and read.
#[derive(Clone, Debug, PartialEq)]
pub struct ProcessedSplitting(pub Processed);

/// A splitting scheme as flow sequences: the kernel's step (fractions of h, from
/// [`Composition::sequence`]) and the processor P and P⁻¹ (times; empty without processing).
#[derive(Clone, Debug)]
struct Scheme {
    seq: Sequence,
    pre: Sequence,
    post: Sequence,
}

impl Scheme {
    fn plain(c: &Composition, flows: usize) -> Self {
        Scheme {
            seq: c.sequence(flows),
            pre: Vec::new(),
            post: Vec::new(),
        }
    }

    fn processed(p: &Processed, flows: usize, h: f64) -> Self {
        let (pre, post) = p.sequences(flows);
        let times = |s: Sequence| s.into_iter().map(|(i, c)| (i, c * h)).collect();
        Scheme {
            seq: p.kernel().sequence(flows),
            pre: times(pre),
            post: times(post),
        }
    }

    /// The flows of P on a state just loaded.
    fn enter<P: Split>(&self, problem: &P, w: &mut P::Work) {
        for &(i, tau) in &self.pre {
            problem.flow(i, tau, w);
        }
    }

    /// A kernel state with `pending` outer-flow time, as the method's state in `z`.
    fn leave<P: Split>(&self, problem: &P, w: &P::Work, pending: f64, z: &mut [f64]) {
        if pending == 0.0 && self.post.is_empty() {
            return problem.store(w, z);
        }
        let mut w = w.clone();
        if pending != 0.0 {
            problem.flow(self.seq[0].0, pending, &mut w);
        }
        for &(i, tau) in &self.post {
            problem.flow(i, tau, &mut w);
        }
        problem.store(&w, z);
    }

    /// The one-member stepper: the problem's kernel of many members ([`Split::lanes`]) on one,
    /// where it has one (so a member gives the same bits alone and in a batch by construction),
    /// else its flows one by one.
    fn stepper<P: Split + Clone + 'static>(self, problem: &P, dt: f64) -> Box<dyn Stepper> {
        if let Some(one) = self.members(problem, dt, 1) {
            return Box::new(Alone(one));
        }
        Box::new(SplittingStepper {
            scheme: self,
            problem: problem.clone(),
            h: dt,
            work: None,
            pending: 0.0,
        })
    }

    fn batch<P: Split + Clone + 'static>(
        self,
        problem: &P,
        dt: f64,
        members: usize,
    ) -> Option<Result<Box<dyn BatchStepper>>> {
        let batch = self.members(problem, dt, members)?;
        Some(Ok(Box::new(batch)))
    }

    /// The batch stepper of `members` members, if the problem has [`Split::lanes`] (and does
    /// not check every step).
    fn members<P: Split + Clone + 'static>(
        &self,
        problem: &P,
        dt: f64,
        members: usize,
    ) -> Option<SplittingBatch<P>> {
        if P::CHECKED {
            return None;
        }
        let lanes = problem.lanes()?;
        let d = lanes.dim();
        let seq = &self.seq;
        let c_last = if seq.len() > 1 {
            seq[seq.len() - 1].1
        } else {
            0.0
        };
        let inner = seq[1..seq.len().saturating_sub(1)]
            .iter()
            .map(|&(i, c)| (i, c * dt))
            .collect();
        Some(SplittingBatch {
            problem: problem.clone(),
            lanes,
            d,
            n: members,
            block: vec![0.0; d * members],
            pending: vec![0.0; members],
            first: vec![0.0; members],
            inner,
            scheme: self.clone(),
            h: dt,
            c_last,
        })
    }
}

impl<P: Split + Clone + 'static> Integrator<P> for Splitting {
    fn properties(&self) -> Properties {
        Properties::geometric(self.0.order())
    }

    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>> {
        Ok(Scheme::plain(&self.0, problem.flows()).stepper(problem, dt))
    }

    fn batch_stepper(
        &self,
        problem: &P,
        dt: f64,
        members: usize,
    ) -> Option<Result<Box<dyn BatchStepper>>> {
        Scheme::plain(&self.0, problem.flows()).batch(problem, dt, members)
    }
}

impl<P: Split + Clone + 'static> Integrator<P> for ProcessedSplitting {
    fn properties(&self) -> Properties {
        Properties::geometric(self.0.order())
    }

    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>> {
        Ok(Scheme::processed(&self.0, problem.flows(), dt).stepper(problem, dt))
    }

    fn batch_stepper(
        &self,
        problem: &P,
        dt: f64,
        members: usize,
    ) -> Option<Result<Box<dyn BatchStepper>>> {
        Scheme::processed(&self.0, problem.flows(), dt).batch(problem, dt, members)
    }
}

/// The batch stepper of a [`Splitting`] over a problem with [`Split::lanes`]: the members'
/// flat states component by component in `block`, each member's pending outer-flow time.
struct SplittingBatch<P: Split> {
    problem: P,
    lanes: Arc<dyn SplitLanes>,
    d: usize,
    n: usize,
    block: Vec<f64>,
    /// Per member: the time of the outer flow not yet applied (as `SplittingStepper::pending`).
    pending: Vec<f64>,
    /// Scratch: the time of each member's first outer flow in a call.
    first: Vec<f64>,
    /// The inner flows with their times c·h.
    inner: Vec<(usize, f64)>,
    scheme: Scheme,
    h: f64,
    c_last: f64,
}

impl<P: Split> SplittingBatch<P> {
    fn column(&self, member: usize) -> impl Iterator<Item = f64> + '_ {
        (0..self.d).map(move |c| self.block[c * self.n + member])
    }

    /// The flows (index, time) in order on one member's flat state `y`: one run of the kernel
    /// (the first flow, then the others, one step), as the flows one by one would do it.
    fn run_flows(&self, y: &mut [f64], flows: &[(usize, f64)]) {
        if let Some((&(outer, t), inner)) = flows.split_first() {
            let program = Program {
                outer,
                fused: 0.0,
                inner,
                steps: 1,
            };
            self.lanes.run(y, &[t], &program);
        }
    }
}

impl<P: Split + Clone + 'static> BatchStepper for SplittingBatch<P> {
    fn members(&self) -> usize {
        self.n
    }

    fn set(&mut self, member: usize, z: &[f64]) -> Result<()> {
        self.problem.load(z)?;
        let processed;
        let y = if self.scheme.pre.is_empty() {
            z
        } else {
            // The processor P, as the one-member stepper's `set` applies it.
            let mut y = z.to_vec();
            self.run_flows(&mut y, &self.scheme.pre);
            processed = y;
            &processed[..]
        };
        for (c, &v) in y.iter().enumerate().take(self.d) {
            self.block[c * self.n + member] = v;
        }
        self.pending[member] = 0.0;
        Ok(())
    }

    fn get(&self, member: usize, z: &mut [f64]) {
        for (zc, v) in z.iter_mut().zip(self.column(member)) {
            *zc = v;
        }
        // On the copy: the pending outer flow, then the inverse processor.
        let pending = self.pending[member];
        if pending != 0.0 {
            self.run_flows(z, &[(self.scheme.seq[0].0, pending)]);
        }
        self.run_flows(z, &self.scheme.post);
    }

    fn advance(&mut self, steps: usize, _clock: Clock) -> Result<()> {
        if steps == 0 {
            return Ok(());
        }
        let (h, (outer, c0)) = (self.h, self.scheme.seq[0]);
        if self.scheme.seq.len() == 1 {
            // A single flow: its times add up until the state is read (as the stepper does).
            for p in &mut self.pending {
                for _ in 0..steps {
                    *p += c0 * h;
                }
            }
            return Ok(());
        }
        for (f, &p) in self.first.iter_mut().zip(&self.pending) {
            *f = p + c0 * h;
        }
        let program = Program {
            outer,
            fused: self.c_last * h + c0 * h,
            inner: &self.inner,
            steps,
        };
        self.lanes.run(&mut self.block, &self.first, &program);
        self.pending.fill(self.c_last * h);
        Ok(())
    }

    fn detach(&self, member: usize) -> Result<Box<dyn Stepper>> {
        let mut one = self
            .scheme
            .members(&self.problem, self.h, 1)
            .expect("a batch stepper has lanes");
        for (c, v) in self.column(member).enumerate() {
            one.block[c] = v;
        }
        one.pending[0] = self.pending[member];
        Ok(Box::new(Alone(one)))
    }
}

/// The one-member stepper of a problem with [`Split::lanes`]: its batch stepper of one member.
struct Alone<P: Split>(SplittingBatch<P>);

impl<P: Split + Clone + 'static> Stepper for Alone<P> {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.0.set(0, z)
    }

    fn get(&self, z: &mut [f64]) {
        self.0.get(0, z)
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        self.0.advance(steps, clock)
    }
}

struct SplittingStepper<P: Split> {
    problem: P,
    scheme: Scheme,
    h: f64,
    work: Option<P::Work>,
    /// Time of the outer flow `seq[0]` not yet applied (lazy first-same-as-last fusion).
    pending: f64,
}

impl<P: Split> Stepper for SplittingStepper<P> {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        let mut w = self.problem.load(z)?;
        self.scheme.enter(&self.problem, &mut w);
        self.work = Some(w);
        self.pending = 0.0;
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        if let Some(w) = &self.work {
            self.scheme.leave(&self.problem, w, self.pending, z);
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
                run_sequence(&self.scheme.seq, self.h, 1, w, flow);
                p.check_step(w).map_err(|v| clock.left_domain(k, v))?;
            }
            return Ok(());
        }
        let (h, seq) = (self.h, &self.scheme.seq);
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
