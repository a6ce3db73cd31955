//! `Verlet(Composition)`: Störmer–Verlet for a [`Separable`] Hamiltonian H = T(p) + U(q), and its
//! symmetric compositions of order 4 (Suzuki 1990) and 6 (Yoshida 1990).
//!
//! One step of size h is kick–drift–kick: p ← p + (h/2) f(q); q ← q + h ∂T/∂p(p);
//! p ← p + (h/2) f(q), with f = −∂U/∂q (Hairer, Lubich & Wanner, *Geometric Numerical
//! Integration*, §I.3). It is the Strang splitting of the exact flows of T and U: symplectic,
//! symmetric, order 2, and equivariant under every linear symmetry of T and U, so it keeps their
//! quadratic momentum maps exactly (for the pseudo-rigid body L = PXᵀ − XPᵀ and Γ = PᵀX − XᵀP,
//! 001 (7.3)). The energy error stays bounded over exponentially long times.
//!
//! The force at the end of a substep is reused at the start of the next (first same as last), so
//! a step costs one force evaluation per stage. After every drift the position is checked
//! (by [`Separable::force`], which checks and evaluates in one call); a position outside the
//! domain stops the run with [`crate::Error::LeftDomain`] naming the step and the time at its end.

use super::composition::Composition;
use crate::error::Result;
use crate::integrate::method::{Clock, Entry, Integrator, Properties, Stepper};
use crate::integrate::problem::Separable;

/// Störmer–Verlet composed with the given [`Composition`] (order 2, 4 or 6 for the built-in
/// compositions).
#[derive(Clone, Debug, PartialEq)]
pub struct Verlet(pub Composition);

impl Verlet {
    /// Plain Störmer–Verlet, order 2.
    pub fn strang() -> Self {
        Verlet(Composition::strang())
    }

    /// The catalog entries `verlet`, `verlet4`, `verlet6` (Strang, Suzuki's 5-stage order 4,
    /// Yoshida's order 6) of a separable problem: one list for a system and its tangent lift.
    pub fn family<P: Separable + Clone + 'static>() -> Vec<Entry<P>> {
        vec![
            Entry::new("verlet", Verlet::strang),
            Entry::new("verlet4", || Verlet(Composition::suzuki4())),
            Entry::new("verlet6", || Verlet(Composition::yoshida6())),
        ]
    }
}

impl<P: Separable + Clone + 'static> Integrator<P> for Verlet {
    fn properties(&self) -> Properties {
        Properties::geometric(self.0.order())
    }

    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>> {
        let d = problem.dof();
        Ok(Box::new(VerletStepper {
            scratch: problem.scratch(),
            problem: problem.clone(),
            steps: self.0.gammas().iter().map(|g| g * dt).collect(),
            z: vec![0.0; 2 * d],
            f: vec![0.0; d],
            v: vec![0.0; d],
        }))
    }
}

struct VerletStepper<P: Separable> {
    problem: P,
    scratch: P::Scratch,
    /// The substep sizes γ_i h.
    steps: Vec<f64>,
    /// (q, p).
    z: Vec<f64>,
    /// f(q) at the current q.
    f: Vec<f64>,
    v: Vec<f64>,
}

impl<P: Separable> Stepper for VerletStepper<P> {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.z.copy_from_slice(z);
        let d = self.f.len();
        self.problem
            .force(&self.z[..d], &mut self.f, &mut self.scratch)
            .map_err(|v| v.at_start())
    }

    fn get(&self, z: &mut [f64]) {
        z.copy_from_slice(&self.z);
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        match self.f.len() {
            // A 3×3 configuration (the pseudo-rigid body in 3-D): the same loop on stack arrays
            // of constant length, which the compiler unrolls.
            9 => self.advance_fixed::<9>(steps, clock),
            _ => {
                let d = self.f.len();
                let (q, p) = self.z.split_at_mut(d);
                let (f, v) = (&mut self.f[..], &mut self.v[..]);
                kick_drift_kick(
                    &self.problem,
                    &mut self.scratch,
                    &self.steps,
                    [q, p, f, v],
                    steps,
                    clock,
                )
            }
        }
    }
}

impl<P: Separable> VerletStepper<P> {
    /// [`kick_drift_kick`] on copies of the state in arrays of length D = d.
    fn advance_fixed<const D: usize>(&mut self, steps: usize, clock: Clock) -> Result<()> {
        let mut q = [0.0; D];
        let mut p = [0.0; D];
        let mut f = [0.0; D];
        let mut v = [0.0; D];
        q.copy_from_slice(&self.z[..D]);
        p.copy_from_slice(&self.z[D..]);
        f.copy_from_slice(&self.f);
        let parts = [&mut q[..], &mut p[..], &mut f[..], &mut v[..]];
        let result = kick_drift_kick(
            &self.problem,
            &mut self.scratch,
            &self.steps,
            parts,
            steps,
            clock,
        );
        self.z[..D].copy_from_slice(&q);
        self.z[D..].copy_from_slice(&p);
        self.f.copy_from_slice(&f);
        result
    }
}

/// `steps` Verlet steps (each a composition of kick–drift–kick substeps of sizes `hs`) on
/// [q, p, f, v]; f = f(q) on entry and on exit; the state is left where a violation was found.
#[inline(always)]
fn kick_drift_kick<P: Separable>(
    problem: &P,
    scratch: &mut P::Scratch,
    hs: &[f64],
    [q, p, f, v]: [&mut [f64]; 4],
    steps: usize,
    clock: Clock,
) -> Result<()> {
    for k in 0..steps {
        for &h in hs {
            axpy(p, 0.5 * h, f);
            problem.drift(q, p, h, v);
            problem
                .force(q, f, scratch)
                .map_err(|e| clock.left_domain(k, e))?;
            axpy(p, 0.5 * h, f);
        }
    }
    Ok(())
}

/// y ← y + a x.
#[inline]
fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}
