//! `NonholonomicRattle`: a RATTLE-type discrete Lagrange–d'Alembert method for a
//! [`Nonholonomic`] system H = ½ pᵀM⁻¹p + U(q) with linear velocity constraints A(q) M⁻¹p = 0,
//! in the spirit of McLachlan & Perlmutter, "Integrators for nonholonomic mechanical systems",
//! J. Nonlinear Sci. 16 (2006) (their RATTLE-type discretizations of the Lagrange–d'Alembert
//! principle; cf. also Cortés & Martínez, Nonlinearity 14 (2001)). With f = −∂U/∂q, one step of
//! size h is
//!
//! p_{n+1/2} = p_n + h/2 f(q_n) − h/2 A(q_n)ᵀμ,
//! q_{n+1} = q_n + h M⁻¹p_{n+1/2},   A(q̄) M⁻¹p_{n+1/2} = 0 at q̄ = (q_n + q_{n+1})/2,
//! p_{n+1} = p_{n+1/2} + h/2 f(q_{n+1}) − h/2 A(q_{n+1})ᵀν,   A(q_{n+1}) M⁻¹p_{n+1} = 0.
//!
//! **Derivation notes.** (i) *Symmetry.* Apply the step with −h to (q_{n+1}, p_{n+1}): its first
//! substep gives p_{n+1} − h/2 f(q_{n+1}) + h/2 A(q_{n+1})ᵀμ' = p_{n+1/2} for μ' = ν, then
//! q = q_{n+1} − h M⁻¹p_{n+1/2} = q_n with the same midpoint q̄, where the half-step momentum
//! satisfies the constraint; the last substep with multiplier μ returns p_n, which satisfies
//! A(q_n)M⁻¹p_n = 0. By uniqueness of the multipliers (near h = 0) Φ_{−h} = Φ_h⁻¹. The same
//! computation with (q_{n+1}, −p_{n+1}) and step +h shows reversibility, ρ∘Φ_h∘ρ = Φ_h⁻¹ for
//! ρ(q, p) = (q, −p), since T is even in p. (ii) *Consistency.* As A(q_n)M⁻¹p_n = 0,
//! A(q̄)M⁻¹p_n = O(h), and the midpoint condition gives μ = (AM⁻¹Aᵀ)⁻¹(A M⁻¹ f + (A'v)v) + O(h),
//! the Lagrange–d'Alembert multiplier of the continuous equations Mq̈ = f − Aᵀμ; a symmetric
//! consistent method has even order, so the order is 2. (iii) *What it keeps.* The constraint
//! A(q)M⁻¹p = 0 at every step end (a linear projection, to round-off), and every linear momentum
//! ⟨p, e⟩ with A(q)e = 0 and ⟨f(q), e⟩ = 0 for all q (a cyclic direction free of constraint
//! forces: the turning momentum J φ̇ of the rolling disk without a spring). Nonholonomic flows
//! are not Hamiltonian, so the method claims no symplecticity and, for a general system, no
//! invariant; it keeps the energy only up to a bounded O(h²) error on the tested systems.
//!
//! **Solves.** With w = (h/2)μ and the rows W_b = M⁻¹A_b(q_n)ᵀ, the midpoint condition
//! F(w) = A(q̄(w)) M⁻¹(p̃ − A(q_n)ᵀw) = 0 (p̃ = p_n + h/2 f(q_n)) is solved by a simplified Newton
//! iteration with the matrix A(q̄^{(k)}) Wᵀ (the neglected derivative of A along q̄ is O(h)), under
//! the rule of [`crate::convergence`] ([`RULE`]: the momentum update relative to ‖p̃‖_∞; on a
//! tangent lift each block's against its own, [`crate::convergence::Blocks`]); the last
//! substep is the linear projection of RATTLE ([`super::rattle`]).
//!
//! **Force rows.** The multipliers act on the momenta along the rows F(q) of
//! [`Nonholonomic::constraint_forces`] (A(q) for a mechanical system): A(q_n)ᵀw above is F(q_n)ᵀw,
//! W_b = M⁻¹F_b(q_n)ᵀ, and the projection is p ← p − F(q_{n+1})ᵀκ; the conditions use A. On a
//! tangent lift ([`crate::integrate::tangent`]) the constraint rows Ã = \[\[A, 0\], \[DA\[δq\], A\]\]
//! and the force rows (the derivative of −Aᵀλ, paired the other way) make every matrix of the
//! step block lower-triangular with the plain one on its diagonal: the base unknowns iterate as in
//! the plain run (and stay once accepted), and the converged step is the derivative of the plain
//! one.

use super::rattle::{axpy, block_scales, dot, singular, Failure, Rows};
use crate::convergence::{self, Blocks, Rule, Verdict};
use crate::error::Result;
use crate::integrate::method::{Clock, Integrator, Properties, Stepper};
use crate::integrate::problem::{Nonholonomic, Separable, Violation};

/// The RATTLE-type nonholonomic method (order 2, symmetric and reversible, not symplectic).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct NonholonomicRattle;

/// The stopping rule of the multiplier iteration ([`crate::convergence`]; the momentum update
/// relative to ‖p̃‖_∞; ended at once at 4ε).
pub const RULE: Rule = Rule {
    tol: convergence::TOL,
    floor: 4.0 * f64::EPSILON,
    max_iter: 50,
};

impl<P: Nonholonomic + Clone + 'static> Integrator<P> for NonholonomicRattle {
    fn properties(&self) -> Properties {
        Properties {
            order: 2,
            symplectic: false,
            symmetric: true,
            invariants: false,
            manifold: true,
            exact: false,
        }
    }

    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>> {
        let (d, m) = (problem.dof(), problem.constraints());
        let rows = Rows::new(problem, m, d);
        let blocks = rows.blocks;
        Ok(Box::new(NonholonomicStepper {
            scratch: problem.scratch(),
            problem: problem.clone(),
            h: dt,
            q: vec![0.0; d],
            p: vec![0.0; d],
            f: vec![0.0; d],
            v: vec![0.0; d],
            ph: vec![0.0; d],
            qbar: vec![0.0; d],
            rows,
            abar: vec![0.0; m * d],
            r: vec![0.0; m],
            w: vec![0.0; m],
            monitor: Blocks::new(RULE, blocks),
            updates: vec![0.0; blocks],
            scales: vec![0.0; blocks],
        }))
    }
}

struct NonholonomicStepper<P: Separable> {
    problem: P,
    scratch: P::Scratch,
    h: f64,
    q: Vec<f64>,
    p: Vec<f64>,
    /// f(q) at the current q.
    f: Vec<f64>,
    v: Vec<f64>,
    /// p̃ = p_n + h/2 f(q_n), and the iterate of p_{n+1/2}.
    ph: Vec<f64>,
    qbar: Vec<f64>,
    /// A(q), the force rows F (A unless a lift's) and W = M⁻¹Fᵀ at the current q.
    rows: Rows,
    /// A at the midpoint iterate, the residual F, the multipliers w = (h/2)μ.
    abar: Vec<f64>,
    r: Vec<f64>,
    w: Vec<f64>,
    /// The rule on the blocks of the unknowns (one but for a lift), each block's momentum
    /// update and scale.
    monitor: Blocks,
    updates: Vec<f64>,
    scales: Vec<f64>,
}

impl<P: Nonholonomic> NonholonomicStepper<P> {
    /// f, A, the force rows F and W = M⁻¹Fᵀ at the current q.
    fn load(&mut self) -> std::result::Result<(), Violation> {
        let NonholonomicStepper {
            problem,
            scratch,
            q,
            f,
            rows,
            ..
        } = self;
        problem.force(q, f, scratch)?;
        rows.fill(|a, forces| {
            problem.constraint_matrix(q, a, scratch);
            problem.constraint_forces(q, forces, scratch)
        });
        rows.update_w(problem);
        Ok(())
    }

    /// p_{n+1/2} = p̃ − F(q_n)ᵀw into `ph`, its velocity into `v`, the midpoint into `qbar`.
    fn half_step(&mut self) {
        let d = self.q.len();
        self.ph.copy_from_slice(&self.p);
        for (b, &wb) in self.w.iter().enumerate() {
            axpy(&mut self.ph, -wb, &self.rows.forces()[b * d..(b + 1) * d]);
        }
        self.problem.velocity(&self.ph, &mut self.v);
        self.qbar.copy_from_slice(&self.q);
        axpy(&mut self.qbar, 0.5 * self.h, &self.v);
    }

    fn step(&mut self) -> std::result::Result<(), Failure> {
        let (h, d, m) = (self.h, self.q.len(), self.w.len());
        // p̃ = p_n + h/2 f(q_n), kept in p during the iteration.
        axpy(&mut self.p, 0.5 * h, &self.f);
        self.w.fill(0.0);
        self.half_step();
        if m > 0 {
            let n0 = d / self.monitor.blocks();
            self.monitor.start();
            loop {
                self.problem
                    .constraint_matrix(&self.qbar, &mut self.abar, &mut self.scratch);
                for a in 0..m {
                    self.r[a] = dot(&self.abar[a * d..(a + 1) * d], &self.v);
                }
                if !self.rows.factor_with(Some(&self.abar)) {
                    return Err(Failure::Domain(singular(self.problem.name())));
                }
                self.rows.solve_active(&mut self.r, &self.monitor);
                axpy(&mut self.w, 1.0, &self.r);
                self.updates.fill(0.0);
                let forces = self.rows.forces();
                for k in 0..d {
                    let dp: f64 = (0..m).map(|b| self.r[b] * forces[b * d + k]).sum();
                    self.updates[k / n0] = self.updates[k / n0].max(dp.abs());
                }
                self.half_step();
                block_scales(&self.p, &self.ph, &mut self.scales);
                match self.monitor.check(&self.updates, &self.scales) {
                    Verdict::Continue => {}
                    Verdict::Converged => break,
                    Verdict::Failed(failed) => return Err(Failure::NotConverged(failed)),
                }
            }
        }
        // q_{n+1} = q_n + h M⁻¹p_{n+1/2}.
        axpy(&mut self.q, h, &self.v);
        self.p.copy_from_slice(&self.ph);
        self.load().map_err(Failure::Domain)?;
        // p_{n+1} = p_{n+1/2} + h/2 f(q_{n+1}) − F(q_{n+1})ᵀ(h/2)ν, A M⁻¹p_{n+1} = 0.
        axpy(&mut self.p, 0.5 * h, &self.f);
        if !self.rows.project(&self.problem, &mut self.p, &mut self.v) {
            return Err(Failure::Domain(singular(self.problem.name())));
        }
        Ok(())
    }
}

impl<P: Nonholonomic> Stepper for NonholonomicStepper<P> {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        let d = self.q.len();
        self.q.copy_from_slice(&z[..d]);
        self.p.copy_from_slice(&z[d..]);
        self.load().map_err(|v| v.at_start())
    }

    fn get(&self, z: &mut [f64]) {
        let d = self.q.len();
        z[..d].copy_from_slice(&self.q);
        z[d..].copy_from_slice(&self.p);
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        for k in 0..steps {
            self.step().map_err(|e| {
                e.into_error(
                    &clock,
                    k,
                    "nonholonomic RATTLE midpoint constraint (iteration for the multipliers)",
                    RULE.tol,
                )
            })?;
        }
        Ok(())
    }
}
