//! `LieMidpoint(Composition)`: the implicit Lie-group midpoint rule for a [`GroupField`]
//! ż = ξ(z)·z, and its symmetric compositions (orders 4 and 6).
//!
//! One step of size h from z solves, for the increment k in the Lie algebra,
//!
//! k = h ξ(exp(k/2)·z),   z ← exp(k)·z,
//!
//! i.e. the field is frozen at the group midpoint exp(k/2)·z of the step (the RKMK form of the
//! implicit midpoint rule *without* the dexp⁻¹ correction, which would only change the method at
//! O(h³) and would make it non-symmetric: dexp⁻¹_{−x} ≠ dexp⁻¹_x at first order in x). Every step
//! is one group action, so the state stays on the orbit of z₀ to round-off (SO(3), S², Casimirs),
//! as with [`crate::integrate::methods::Rkmk4`].
//!
//! **Symmetry.** The step with −h from z' = exp(k)·z is solved by k' = −k: exp(−k/2)·z' =
//! exp(k/2)·z, so −h ξ(exp(k'/2)·z') = −h ξ(exp(k/2)·z) = −k. Hence Φ_{−h} ∘ Φ_h = id (HLW
//! §V.1), the order is even (2), and the symmetric compositions of [`Composition`] lift it to
//! order 4 (`LieMidpoint(Composition::triple_jump4())`, `suzuki4()`) or 6 (HLW §V.3). For a
//! ρ-reversible field (ρ an involution with ρ(exp(x)·z) = exp(σx)·ρz and ξ(ρz) = −σξ(z), e.g.
//! ρ flipping the sign of velocities), the method is ρ-reversible, which is what gives the
//! energy of reversible (nonholonomic) systems its bounded, drift-free error over long times
//! (HLW §XI, reversible perturbation theory) where the method is not symplectic.
//!
//! **The implicit solve** is a fixed-point iteration from k = h ξ(z) (a contraction for
//! h·Lip(ξ) < 2) under the rule of [`crate::convergence`] ([`RULE`]: ‖Δk‖_∞ relative to
//! max(‖k‖_∞, 1), accepted below 10⁻¹² or the field's own [`GroupField::solve_tolerance`], then on until the update vanishes or stops decreasing,
//! so that an early stop does not leave a systematic O(tol) energy drift);
//! [`crate::Error::NotConverged`] names a step whose update is still above the tolerance after
//! [`RULE`]`.max_iter` iterations. A non-finite increment stops the run with
//! [`crate::Error::LeftDomain`]. On a tangent lift ([`GroupField::diagonal_blocks`]) each
//! block of k is measured against its own scale ([`Blocks`]): the state's as in the plain
//! solve, a direction's the larger of its iterate's and its first iterate's.

use crate::convergence::{self, Blocks, Failed, Rule, Verdict};
use crate::error::Result;
use crate::integrate::method::{Clock, Integrator, Properties, Stepper};
use crate::integrate::methods::Composition;
use crate::integrate::problem::{GroupField, Violation};

/// The stopping rule of the fixed-point iteration ([`crate::convergence`]; ‖Δk‖_∞ relative to
/// max(‖k‖_∞, 1); ended at once by a zero update only).
pub const RULE: Rule = Rule {
    tol: convergence::TOL,
    floor: 0.0,
    max_iter: 60,
};

/// The implicit Lie-group midpoint rule composed with the weights of a [`Composition`]
/// (`Composition::strang()`: the rule itself, order 2). Symmetric; keeps the group orbit.
#[derive(Clone, Debug, PartialEq)]
pub struct LieMidpoint(pub Composition);

impl LieMidpoint {
    /// The rule itself (order 2).
    pub fn new() -> Self {
        LieMidpoint(Composition::strang())
    }
}

impl Default for LieMidpoint {
    fn default() -> Self {
        Self::new()
    }
}

impl<P: GroupField + Clone + 'static> Integrator<P> for LieMidpoint {
    /// Order of the composition, symmetric, keeps the orbit (`manifold`, `invariants`: the
    /// Casimirs of the action, as `Rkmk4`); not symplectic (claimed false: it is the implicit
    /// midpoint in exponential coordinates only, which is symplectic for a canonical linear
    /// action, not in general).
    fn properties(&self) -> Properties {
        Properties {
            order: self.0.order(),
            symplectic: false,
            symmetric: true,
            invariants: true,
            manifold: true,
            exact: false,
        }
    }

    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>> {
        let (n, g) = (problem.space().dim(), problem.algebra_dim());
        let blocks = problem.diagonal_blocks().max(1);
        let blocks = if g % blocks == 0 { blocks } else { 1 };
        let rule = Rule {
            tol: problem.solve_tolerance().max(RULE.tol),
            ..RULE
        };
        Ok(Box::new(MidpointStepper {
            scratch: problem.scratch(),
            problem: problem.clone(),
            gammas: self.0.gammas().to_vec(),
            h: dt,
            y: vec![0.0; n],
            yt: vec![0.0; n],
            k: vec![0.0; g],
            half: vec![0.0; g],
            knew: vec![0.0; g],
            dz: vec![0.0; n],
            carry: vec![0.0; n],
            start: vec![0.0; g],
            monitor: Blocks::new(rule, blocks),
            updates: vec![0.0; blocks],
            scales: vec![0.0; blocks],
        }))
    }
}

struct MidpointStepper<P: GroupField> {
    problem: P,
    scratch: P::Scratch,
    /// The weights of the composition.
    gammas: Vec<f64>,
    h: f64,
    y: Vec<f64>,
    yt: Vec<f64>,
    k: Vec<f64>,
    half: Vec<f64>,
    knew: Vec<f64>,
    /// The substep's increment exp(k)·y − y where the problem forms it
    /// ([`GroupField::act_increment`]), and the carry of its compensated sum.
    dz: Vec<f64>,
    carry: Vec<f64>,
    /// The first iterate h ξ(y), the rule on the blocks of k (one but for a lift: the state's
    /// and each direction's algebra coordinates), each block's update and scale.
    start: Vec<f64>,
    monitor: Blocks,
    updates: Vec<f64>,
    scales: Vec<f64>,
}

/// Why a substep failed.
enum Failure {
    NotFinite,
    NotConverged(Failed),
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

impl<P: GroupField> MidpointStepper<P> {
    /// One midpoint substep of size h on y.
    fn substep(&mut self, h: f64) -> std::result::Result<(), Failure> {
        let MidpointStepper {
            problem,
            scratch,
            y,
            yt,
            k,
            half,
            knew,
            dz,
            carry,
            start,
            monitor,
            updates,
            scales,
            ..
        } = self;
        problem.generator(y, k, scratch);
        k.iter_mut().for_each(|x| *x *= h);
        start.copy_from_slice(k);
        let g0 = k.len() / monitor.blocks();
        monitor.start();
        loop {
            for (hi, ki) in half.iter_mut().zip(k.iter()) {
                *hi = 0.5 * ki;
            }
            yt.copy_from_slice(y);
            problem.act(half, yt, scratch);
            problem.generator(yt, knew, scratch);
            // Each block's update (none once accepted) and scale: the state's max(‖k‖_∞, 1),
            // a direction's the larger of its iterate's and its first iterate's.
            let parts = knew.chunks_exact_mut(g0).zip(k.chunks_exact_mut(g0));
            for (b, ((kn, kb), sb)) in parts.zip(start.chunks_exact(g0)).enumerate() {
                let mut d = 0.0f64;
                if monitor.active(b) {
                    for (kn, ki) in kn.iter_mut().zip(kb.iter_mut()) {
                        *kn *= h;
                        d = d.max((*kn - *ki).abs());
                        *ki = *kn;
                    }
                }
                if !d.is_finite() {
                    return Err(Failure::NotFinite);
                }
                updates[b] = d;
                scales[b] = match b {
                    0 => inf_norm(kb).max(1.0),
                    _ => inf_norm(kb).max(inf_norm(sb)).max(f64::MIN_POSITIVE),
                };
            }
            match monitor.check(updates, scales) {
                Verdict::Continue => {}
                Verdict::Converged => break,
                Verdict::Failed(failed) => return Err(Failure::NotConverged(failed)),
            }
        }
        if problem.act_increment(k, y, dz, scratch) {
            // Kahan's compensated y += dz (as in Rkmk4: at a steady motion the increment of a
            // component kept by the symmetry repeats itself below that component's ulp).
            crate::numerics::linalg::compensated_add(y, carry, dz);
        } else {
            problem.act(k, y, scratch);
        }
        Ok(())
    }
}

impl<P: GroupField> Stepper for MidpointStepper<P> {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.y.copy_from_slice(z);
        self.carry.fill(0.0);
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        z.copy_from_slice(&self.y);
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        let h = self.h;
        for s in 0..steps {
            for i in 0..self.gammas.len() {
                match self.substep(self.gammas[i] * h) {
                    Ok(()) => {}
                    Err(Failure::NotFinite) => {
                        return Err(clock.left_domain(
                            s,
                            Violation {
                                what: format!("{} state", self.problem.name()),
                                message: "the midpoint increment in the Lie algebra is not \
                                          finite (the motion blew up or left the domain of the \
                                          field); reduce dt"
                                    .into(),
                            },
                        ))
                    }
                    Err(Failure::NotConverged(failed)) => {
                        return Err(clock.not_converged(
                            s,
                            "Lie midpoint fixed-point iteration",
                            failed,
                            self.problem.solve_tolerance().max(RULE.tol),
                        ))
                    }
                }
            }
        }
        Ok(())
    }
}
