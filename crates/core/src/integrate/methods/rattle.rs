//! `Rattle(Composition)`: the RATTLE method for a [`Constrained`] system H = ½ pᵀM⁻¹p + U(q) on
//! the constraint manifold g(q) = c (c = 0, or c = g(q₀) for a level-set constraint,
//! [`Constrained::level_set`]), and its symmetric compositions (Andersen, "Rattle: a velocity
//! version of the Shake algorithm", J. Comput. Phys. 52 (1983); Hairer, Lubich & Wanner,
//! *Geometric Numerical Integration*, §VII.1.4). With f = −∂U/∂q and G = ∂g/∂q, one step of
//! size h is
//!
//! p_{n+1/2} = p_n + h/2 (f(q_n) − G(q_n)ᵀλ),
//! q_{n+1} = q_n + h M⁻¹ p_{n+1/2},   g(q_{n+1}) = c,
//! p_{n+1} = p_{n+1/2} + h/2 (f(q_{n+1}) − G(q_{n+1})ᵀμ),   G(q_{n+1}) M⁻¹ p_{n+1} = 0.
//!
//! It is of order 2, symmetric, and a symplectic map of the constrained phase space
//! T*{g = c} = {g(q) = c, G(q) M⁻¹p = 0} (HLW §VII.1.4); it is equivariant under every
//! linear symmetry of M, U and g, so it keeps their momentum maps (the vertical angular momentum of
//! a particle on a sphere; L and Γ of an incompressible pseudo-rigid body). Both constraints hold
//! at every step end to round-off. The composition S_{γ_s h} ∘ … ∘ S_{γ_1 h} of these steps with
//! the palindromic weights of a [`Composition`] (HLW §V.3; negative γ are fine: the step is
//! symmetric and defined for h < 0) is again symmetric and symplectic on T*{g = c}, of the
//! composition's order: `Rattle(Composition::suzuki4())` order 4,
//! `Rattle(Composition::yoshida6())` order 6. Every substep solves the constraints, so they hold
//! to round-off after each substep, not only at the end of a step.
//!
//! **Level sets.** When [`Constrained::level_set`] holds, the stepper records c = g(q₀) when it
//! is set to a state ([`Stepper::set`]) and solves g(q) = c in every substep; c stays fixed for
//! the run, so the constraint does not drift by accumulated round-off.
//!
//! **Solves.** With ν = (h²/2)λ and the rows W_b = M⁻¹G_b(q_n)ᵀ (from [`Separable::velocity`],
//! linear), the position is q_{n+1} = q̃ − Σ_b ν_b W_b with q̃ = q_n + h M⁻¹(p_n + h/2 f(q_n)), and
//! ν solves g(q̃ − Σ ν_b W_b) = c by Newton's method (the m×m Jacobian G(q_{n+1}^{(k)}) Wᵀ is
//! refactored every iteration) under the rule of [`crate::convergence`] ([`RULE`]: the position
//! update relative to ‖q‖_∞; on a tangent lift each block's against its own, [`Blocks`]); then
//! p_{n+1/2} = p̃ − G(q_n)ᵀν/h. The multiplier μ solves the
//! linear m×m system (G M⁻¹Gᵀ)(q_{n+1}) κ = G M⁻¹ p̃ (κ = hμ/2). G, W and f at
//! q_{n+1} are reused by the next (sub)step.
//!
//! **The index-1 field.** [`constrained_field`] (and its allocation-free form
//! [`constrained_field_into`]) evaluates the vector field of the constrained motion on
//! T*{g = c}: q̇ = M⁻¹p, ṗ = f − Gᵀλ with λ = (G M⁻¹Gᵀ)⁻¹(G M⁻¹f + D²g(q)[M⁻¹p, M⁻¹p]) (the
//! multiplier for which d²/dt² g(q(t)) = 0), the limit of RATTLE's λ and μ as h → 0.

use super::gauss::DenseLu;
use crate::convergence::{self, Blocks, Failed, Rule, Verdict};
use crate::error::Result;
use crate::integrate::method::{Clock, Entry, Integrator, Properties, Stepper};
use crate::integrate::methods::Composition;
use crate::integrate::problem::{Constrained, Separable, Violation};
use crate::integrate::tangent::{constraint_second, SeparableTangent};
use crate::numerics::linalg::norm;

/// RATTLE composed with the weights of a [`Composition`] (`Composition::strang()`: RATTLE
/// itself, order 2). Symplectic on the constraint manifold, symmetric.
#[derive(Clone, Debug, PartialEq)]
pub struct Rattle(pub Composition);

impl Rattle {
    /// RATTLE itself (order 2).
    pub fn new() -> Self {
        Rattle(Composition::strang())
    }

    /// The catalog entries `rattle`, `rattle4`, `rattle6` (Strang, Suzuki's order 4, Yoshida's
    /// order 6) of a constrained problem: one list for a system and its tangent lift.
    pub fn family<P: Constrained + Clone + 'static>() -> Vec<Entry<P>> {
        vec![
            Entry::new("rattle", Rattle::new),
            Entry::new("rattle4", || Rattle(Composition::suzuki4())),
            Entry::new("rattle6", || Rattle(Composition::yoshida6())),
        ]
    }
}

impl Default for Rattle {
    fn default() -> Self {
        Self::new()
    }
}

/// The stopping rule of the Newton iteration for the position multipliers
/// ([`crate::convergence`]; the position update relative to ‖q‖_∞; ended at once at 4ε, where
/// the next Newton update would be round-off).
pub const RULE: Rule = Rule {
    tol: convergence::TOL,
    floor: 4.0 * f64::EPSILON,
    max_iter: 50,
};

/// Why a constrained step failed.
pub(crate) enum Failure {
    /// The multiplier iteration did not converge.
    NotConverged(Failed),
    /// A state outside the problem's domain, or constraints that lost rank.
    Domain(Violation),
}

impl Failure {
    /// The error naming step k + 1 of this call; `solve` names the iteration, `tol` its
    /// tolerance.
    pub(crate) fn into_error(self, clock: &Clock, k: usize, solve: &str, tol: f64) -> crate::Error {
        match self {
            Failure::NotConverged(failed) => clock.not_converged(k, solve, failed, tol),
            Failure::Domain(v) => clock.left_domain(k, v),
        }
    }
}

/// The violation for a constraint matrix C M⁻¹Cᵀ that is singular or not finite.
pub(crate) fn singular(name: &str) -> Violation {
    Violation {
        what: format!("{name} constraints"),
        message: "the constraint matrix C M⁻¹ Cᵀ became singular or non-finite (the constraints \
                  lost rank, or the motion blew up); reduce dt or check the constraints"
            .into(),
    }
}

/// m constraint rows C (m×d, row-major) at a point, the rows W_b = M⁻¹C_bᵀ, and the LU of the
/// m×m matrix C M⁻¹Cᵀ (or of another product with the rows W): the linear algebra RATTLE and its
/// nonholonomic variant share.
pub(crate) struct Rows {
    m: usize,
    d: usize,
    /// The rows C.
    pub(crate) c: Vec<f64>,
    /// The rows F along which the multipliers act (F = C unless `distinct`: a tangent lift,
    /// [`Constrained::constraint_forces`], [`crate::integrate::problem::Nonholonomic::constraint_forces`]).
    pub(crate) f: Vec<f64>,
    pub(crate) distinct: bool,
    /// The rows W = M⁻¹Fᵀ.
    pub(crate) w: Vec<f64>,
    /// The number B of diagonal blocks of S = C M⁻¹Fᵀ ([`Separable::diagonal_blocks`]: 1 + k
    /// for a tangent lift, whose S is block lower-triangular with one repeated diagonal block
    /// S₀₀; 1 otherwise), and its blocks S_j0 below the diagonal.
    pub(crate) blocks: usize,
    low: Vec<f64>,
    /// The LU of S₀₀ (of S when B = 1).
    lu: DenseLu,
    rhs: Vec<f64>,
}

impl Rows {
    /// Storage for the m rows of length d of `problem` (its diagonal blocks).
    pub(crate) fn new<P: Separable>(problem: &P, m: usize, d: usize) -> Self {
        let blocks = problem.diagonal_blocks().max(1);
        let blocks = if m % blocks == 0 && d % blocks == 0 {
            blocks
        } else {
            1
        };
        let m0 = m / blocks;
        Rows {
            m,
            d,
            c: vec![0.0; m * d],
            f: Vec::new(),
            distinct: false,
            w: vec![0.0; m * d],
            blocks,
            low: vec![0.0; (blocks - 1) * m0 * m0],
            lu: DenseLu::new(m0),
            rhs: vec![0.0; m],
        }
    }

    /// The force rows F (C unless they are distinct).
    pub(crate) fn forces(&self) -> &[f64] {
        if self.distinct {
            &self.f
        } else {
            &self.c
        }
    }

    /// The rows C and F from `fill(c, f)`, which writes C and returns whether it wrote distinct
    /// force rows F (the storage of F is sized at the first call).
    pub(crate) fn fill(&mut self, fill: impl FnOnce(&mut [f64], &mut [f64]) -> bool) {
        self.f.resize(self.c.len(), 0.0);
        self.distinct = fill(&mut self.c, &mut self.f);
    }

    /// C = G(q) and the force rows F at q ([`Constrained::constraint_forces`]).
    pub(crate) fn load<P: Constrained>(&mut self, problem: &P, q: &[f64], s: &mut P::Scratch) {
        self.fill(|c, f| {
            problem.constraint_jacobian(q, c, s);
            problem.constraint_forces(q, f, s)
        });
    }

    /// W_b = M⁻¹F_b for the current rows F.
    pub(crate) fn update_w<P: Separable>(&mut self, problem: &P) {
        let d = self.d;
        let forces = if self.distinct { &self.f } else { &self.c };
        for (fb, wb) in forces.chunks_exact(d).zip(self.w.chunks_exact_mut(d)) {
            problem.velocity(fb, wb);
        }
    }

    /// Factors the m×m matrix S_ab = B_a · W_b for rows B (m×d, row-major; `None`: B = C) and
    /// the current W; false when S is singular or not finite.
    ///
    /// With B diagonal blocks only S₀₀ and the S_j0 are formed, from the columns where the rows
    /// of a lift are not zero (block 0 and block j): O(B m₀² d/B) instead of O(m² d).
    pub(crate) fn factor_with(&mut self, rows: Option<&[f64]>) -> bool {
        let (m, d, blocks) = (self.m, self.d, self.blocks);
        let rows = rows.unwrap_or(&self.c);
        let (m0, n0) = (m / blocks, d / blocks);
        let mat = self.lu.matrix();
        let w = &self.w;
        // Row a of the rows, and of W, over the columns of block j.
        let part = |a: usize, j: usize| a * d + j * n0..a * d + (j + 1) * n0;
        for a in 0..m0 {
            for b in 0..m0 {
                mat[(a, b)] = dot(&rows[part(a, 0)], &w[part(b, 0)]);
            }
        }
        for j in 1..blocks {
            for a in 0..m0 {
                let r = j * m0 + a;
                for b in 0..m0 {
                    self.low[((j - 1) * m0 + a) * m0 + b] = dot(&rows[part(r, 0)], &w[part(b, 0)])
                        + dot(&rows[part(r, j)], &w[part(b, j)]);
                }
            }
        }
        self.lu.factor()
    }

    /// Solves the factored system in place (m values): block forward substitution with S₀₀.
    pub(crate) fn solve(&mut self, x: &mut [f64]) {
        solve_blocks(&mut self.lu, &self.low, self.blocks, x, |_| true);
    }

    /// [`Rows::solve`] for the blocks the monitor still iterates: an accepted block's update is
    /// zero (its unknowns stay), so a direction's is S₀₀⁻¹x_j once the state's is accepted.
    pub(crate) fn solve_active(&mut self, x: &mut [f64], monitor: &Blocks) {
        solve_blocks(&mut self.lu, &self.low, self.blocks, x, |b| {
            monitor.active(b)
        });
    }

    /// p ← p − Fᵀκ with κ such that C M⁻¹p = 0 afterwards (the projection of the last RATTLE
    /// substep; `v` is scratch of length d). False when C M⁻¹Cᵀ is singular.
    pub(crate) fn project<P: Separable>(
        &mut self,
        problem: &P,
        p: &mut [f64],
        v: &mut [f64],
    ) -> bool {
        let (m, d) = (self.m, self.d);
        if m == 0 {
            return true;
        }
        if !self.factor_with(None) {
            return false;
        }
        problem.velocity(p, v);
        for a in 0..m {
            self.rhs[a] = dot(&self.c[a * d..(a + 1) * d], v);
        }
        solve_blocks(&mut self.lu, &self.low, self.blocks, &mut self.rhs, |_| {
            true
        });
        let forces = if self.distinct { &self.f } else { &self.c };
        for a in 0..m {
            axpy(p, -self.rhs[a], &forces[a * d..(a + 1) * d]);
        }
        true
    }
}

/// x ← S⁻¹x for S block lower-triangular with B diagonal blocks S₀₀ (factored in `lu`) and
/// the blocks S_j0 (`low`) below: x₀ = S₀₀⁻¹x₀, x_j = S₀₀⁻¹(x_j − S_j0 x₀); x_b = 0 for a
/// block b that is not `active`.
fn solve_blocks(
    lu: &mut DenseLu,
    low: &[f64],
    blocks: usize,
    x: &mut [f64],
    active: impl Fn(usize) -> bool,
) {
    let m0 = x.len() / blocks;
    let (x0, rest) = x.split_at_mut(m0);
    if active(0) {
        lu.solve(x0);
    } else {
        x0.fill(0.0);
    }
    for (j, xj) in rest.chunks_exact_mut(m0).enumerate() {
        if !active(j + 1) {
            xj.fill(0.0);
            continue;
        }
        for (a, xa) in xj.iter_mut().enumerate() {
            *xa -= dot(&low[(j * m0 + a) * m0..(j * m0 + a + 1) * m0], x0);
        }
        lu.solve(xj);
    }
}

/// The scales of a block solve ([`Blocks`]) of unknowns in `blocks` equal blocks (the state's
/// and its directions' parts of `data` and `iterate`): the state's its data's ‖·‖_∞, as in the
/// plain solve; a direction's the larger of its data's and its iterate's (a direction's data
/// may vanish where its solution does not: a parameter direction at t = 0). At least the least
/// positive number.
pub(crate) fn block_scales(data: &[f64], iterate: &[f64], scales: &mut [f64]) {
    let n = data.len() / scales.len();
    for (b, s) in scales.iter_mut().enumerate() {
        let part = b * n..(b + 1) * n;
        let own = max_abs(&data[part.clone()]);
        *s = match b {
            0 => own,
            _ => own.max(max_abs(&iterate[part])),
        }
        .max(f64::MIN_POSITIVE);
    }
}

/// x·y.
#[inline]
pub(crate) fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// y ← y + a x.
#[inline]
pub(crate) fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

/// ‖v‖_∞.
#[inline]
pub(crate) fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

impl<P: Constrained + Clone + 'static> Integrator<P> for Rattle {
    /// The order of the composition; symplectic on T*{g = c}, symmetric, keeps the constraints
    /// and the invariants of linear symmetries (`invariants`, `manifold`).
    fn properties(&self) -> Properties {
        Properties::geometric(self.0.order())
    }

    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>> {
        let (d, m) = (problem.dof(), problem.constraints());
        let rows = Rows::new(problem, m, d);
        let blocks = rows.blocks;
        Ok(Box::new(RattleStepper {
            scratch: problem.scratch(),
            problem: problem.clone(),
            gammas: self.0.gammas().to_vec(),
            h: dt,
            q: vec![0.0; d],
            p: vec![0.0; d],
            f: vec![0.0; d],
            v: vec![0.0; d],
            qn: vec![0.0; d],
            rows,
            jac: vec![0.0; m * d],
            g: vec![0.0; m],
            g0: vec![0.0; m],
            nu: vec![0.0; m],
            monitor: Blocks::new(RULE, blocks),
            updates: vec![0.0; blocks],
            scales: vec![0.0; blocks],
        }))
    }
}

struct RattleStepper<P: Separable> {
    problem: P,
    scratch: P::Scratch,
    /// The weights of the composition.
    gammas: Vec<f64>,
    h: f64,
    q: Vec<f64>,
    p: Vec<f64>,
    /// f(q) at the current q.
    f: Vec<f64>,
    v: Vec<f64>,
    /// The Newton iterate of q_{n+1}.
    qn: Vec<f64>,
    /// G(q) and W = M⁻¹Gᵀ at the current q.
    rows: Rows,
    /// G at the Newton iterate, g there, the multipliers ν = (h²/2)λ.
    jac: Vec<f64>,
    g: Vec<f64>,
    /// The level c of the constraint g(q) = c (0, or g(q₀) for a level set).
    g0: Vec<f64>,
    nu: Vec<f64>,
    /// The rule on the blocks of the unknowns (one but for a lift), each block's position
    /// update and scale.
    monitor: Blocks,
    updates: Vec<f64>,
    scales: Vec<f64>,
}

impl<P: Constrained> RattleStepper<P> {
    /// f, G and W at the current q.
    fn load(&mut self) -> std::result::Result<(), Violation> {
        self.problem
            .force(&self.q, &mut self.f, &mut self.scratch)?;
        self.rows.load(&self.problem, &self.q, &mut self.scratch);
        self.rows.update_w(&self.problem);
        Ok(())
    }

    /// One RATTLE step of size h.
    fn step(&mut self, h: f64) -> std::result::Result<(), Failure> {
        let RattleStepper {
            problem,
            scratch,
            q,
            p,
            f,
            v,
            qn,
            rows,
            jac,
            g,
            g0,
            nu,
            monitor,
            updates,
            scales,
            ..
        } = self;
        let (d, m) = (q.len(), g.len());
        // p̃ = p + h/2 f(q_n); q̃ = q_n + h M⁻¹p̃.
        axpy(p, 0.5 * h, f);
        problem.velocity(p, v);
        qn.copy_from_slice(q);
        axpy(qn, h, v);
        // Newton for ν: g(q̃ − Σ ν_b W_b) = c.
        nu.fill(0.0);
        if m > 0 {
            let n0 = d / monitor.blocks();
            monitor.start();
            loop {
                problem.constraint(qn, g, scratch);
                for (gb, cb) in g.iter_mut().zip(g0.iter()) {
                    *gb -= cb;
                }
                problem.constraint_jacobian(qn, jac, scratch);
                if !rows.factor_with(Some(jac)) {
                    return Err(Failure::Domain(singular(problem.name())));
                }
                rows.solve_active(g, monitor);
                updates.fill(0.0);
                for (k, qk) in qn.iter_mut().enumerate() {
                    let dq: f64 = (0..m).map(|b| g[b] * rows.w[b * d + k]).sum();
                    *qk -= dq;
                    updates[k / n0] = updates[k / n0].max(dq.abs());
                }
                axpy(nu, 1.0, g);
                block_scales(q, qn, scales);
                match monitor.check(updates, scales) {
                    Verdict::Continue => {}
                    Verdict::Converged => break,
                    Verdict::Failed(failed) => return Err(Failure::NotConverged(failed)),
                }
            }
            // q_{n+1} = q̃ − Σ_b ν_b W_b once, from the ν that corrects p below: the iterate took
            // the corrections one by one and rounded away the last, ulp-sized ones, which p then
            // received alone. The residual g(q) − c is computed with a bias (|q|² rounded near
            // l² for the sphere), so those last corrections had one sign, and the momentum map
            // drifted linearly ((q × p)₃ of the particle on a sphere: 6e-12 after 10⁶ steps).
            for (k, qk) in qn.iter_mut().enumerate() {
                let dq: f64 = (0..m).map(|b| nu[b] * rows.w[b * d + k]).sum();
                *qk = (q[k] + h * v[k]) - dq;
            }
        }
        // p_{n+1/2} = p̃ − G(q_n)ᵀν/h.
        for (b, &nb) in nu.iter().enumerate() {
            axpy(p, -nb / h, &rows.forces()[b * d..(b + 1) * d]);
        }
        q.copy_from_slice(qn);
        problem.force(q, f, scratch).map_err(Failure::Domain)?;
        rows.load(problem, q, scratch);
        rows.update_w(problem);
        // p_{n+1} = p_{n+1/2} + h/2 f(q_{n+1}) − G(q_{n+1})ᵀκ, G M⁻¹p_{n+1} = 0.
        axpy(p, 0.5 * h, f);
        if !rows.project(problem, p, v) {
            return Err(Failure::Domain(singular(problem.name())));
        }
        Ok(())
    }
}

impl<P: Constrained> Stepper for RattleStepper<P> {
    /// Sets the state; for a level-set constraint ([`Constrained::level_set`]) records
    /// c = g(q₀), the level the run keeps.
    fn set(&mut self, z: &[f64]) -> Result<()> {
        let d = self.q.len();
        self.q.copy_from_slice(&z[..d]);
        self.p.copy_from_slice(&z[d..]);
        self.load().map_err(|v| v.at_start())?;
        if self.problem.level_set() {
            self.problem
                .constraint(&self.q, &mut self.g0, &mut self.scratch);
        } else {
            self.g0.fill(0.0);
        }
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        let d = self.q.len();
        z[..d].copy_from_slice(&self.q);
        z[d..].copy_from_slice(&self.p);
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        let h = self.h;
        for k in 0..steps {
            for i in 0..self.gammas.len() {
                self.step(self.gammas[i] * h).map_err(|e| {
                    e.into_error(
                        &clock,
                        k,
                        "RATTLE position constraint (Newton iteration for the multipliers)",
                        RULE.tol,
                    )
                })?;
            }
        }
        Ok(())
    }
}

/// The workspace of [`constrained_field_into`] (allocated once per problem size): the rows G,
/// W = M⁻¹Gᵀ and the LU of G M⁻¹Gᵀ, the force and the velocity.
pub struct FieldWork {
    rows: Rows,
    f: Vec<f64>,
    v: Vec<f64>,
}

impl FieldWork {
    /// A workspace for `problem` (its d and m).
    pub fn new<P: Constrained>(problem: &P) -> Self {
        let (d, m) = (problem.dof(), problem.constraints());
        FieldWork {
            rows: Rows::new(problem, m, d),
            f: vec![0.0; d],
            v: vec![0.0; d],
        }
    }
}

/// The index-1 vector field of a [`Constrained`] system on T*{g = c} (HLW §VII.1.1): for
/// z = (q, p) (2d values, internal frame) writes ż = (M⁻¹p, f − Gᵀλ) into `dz` and the
/// multipliers into `lambda` (m values), with f = −∂U/∂q, G = G(q) and
///
/// λ = (G M⁻¹Gᵀ)⁻¹ (G M⁻¹f + D²g(q)[M⁻¹p, M⁻¹p]),
///
/// the multiplier for which the acceleration constraint d²/dt² g(q(t)) = G q̈ + D²g[q̇, q̇] = 0
/// holds, so the flow keeps g(q) and the hidden constraint G M⁻¹p = 0 of a state on T*{g = c}.
/// The constraint force −Gᵀλ is the limit of RATTLE's −Gᵀλ and −Gᵀμ as h → 0 (for the particle
/// on a sphere: the centripetal force m|v|²/l towards the centre plus minus the radial part of
/// f). The level c plays no part (λ depends on q and p only). No allocation: the scratch `s`
/// serves the problem's kernels, `w` the linear algebra. A [`Violation`] where q lies outside
/// the problem's domain or G M⁻¹Gᵀ is singular or not finite.
pub fn constrained_field_into<P: Constrained>(
    problem: &P,
    z: &[f64],
    dz: &mut [f64],
    lambda: &mut [f64],
    s: &mut P::Scratch,
    w: &mut FieldWork,
) -> std::result::Result<(), Violation> {
    let d = problem.dof();
    let m = problem.constraints();
    let (q, p) = z.split_at(d);
    let FieldWork { rows, f, v } = w;
    problem.force(q, f, s)?;
    problem.velocity(p, v);
    problem.constraint_jacobian(q, &mut rows.c, s);
    rows.update_w(problem);
    if m > 0 {
        if !rows.factor_with(None) {
            return Err(singular(problem.name()));
        }
        // λ_a: D²g_a[v, v] + G_a M⁻¹ f = D²g_a[v, v] + W_a · f (M symmetric).
        problem.constraint_curvature(q, v, lambda, s);
        for (a, la) in lambda.iter_mut().enumerate() {
            *la += dot(&rows.w[a * d..(a + 1) * d], f);
        }
        rows.solve(lambda);
        if lambda.iter().any(|x| !x.is_finite()) {
            return Err(singular(problem.name()));
        }
    }
    let (dq, dp) = dz.split_at_mut(d);
    dq.copy_from_slice(v);
    dp.copy_from_slice(f);
    for (a, &la) in lambda.iter().enumerate() {
        axpy(dp, -la, &rows.c[a * d..(a + 1) * d]);
    }
    Ok(())
}

/// The derivative of the index-1 field ([`constrained_field_into`]) along each direction of
/// `dirs` (consecutive 2d values, internal frame) into `out`: δq̇ = v′(p)δp and
/// δṗ = δf − δGᵀλ − Gᵀδλ with δf = f′(q)δq, δG = D²g(q)\[δq, ·\] and, from
/// (G M⁻¹Gᵀ)λ = G M⁻¹f + D²g\[v, v\] differentiated,
///
/// (G M⁻¹Gᵀ)δλ = δG a + G M⁻¹(δf − δGᵀλ) + D³g\[δq, v, v\] + 2D²g\[v, δv\],
///
/// a = M⁻¹(f − Gᵀλ) the acceleration. D²g from [`Constrained::constraint_second`] (else by
/// polarisation, exact to round-off), D³g from [`Constrained::constraint_third`], else by
/// central differences of the curvature along δq (the only approximation, documented where
/// used). A state outside the problem's domain is [`crate::Error::InvalidArgument`].
pub fn constrained_field_tangent<P: Constrained + SeparableTangent>(
    problem: &P,
    z: &[f64],
    dirs: &[f64],
    out: &mut [f64],
) -> Result<()> {
    let (d, m) = (problem.dof(), problem.constraints());
    let mut s = problem.scratch();
    let mut w = FieldWork::new(problem);
    let mut lambda = vec![0.0; m];
    let mut field = vec![0.0; 2 * d];
    constrained_field_into(problem, z, &mut field, &mut lambda, &mut s, &mut w)
        .map_err(|v| v.at_start())?;
    let (q, p) = z.split_at(d);
    let v = w.v.clone();
    // a = M⁻¹(f − Gᵀλ); D²g[v, ·].
    let mut acc = vec![0.0; d];
    problem.velocity_tangent(p, &field[d..], &mut acc);
    let (mut rows_v, mut rows_dq) = (vec![0.0; m * d], vec![0.0; m * d]);
    let (mut wk, mut ck) = (vec![0.0; d], vec![0.0; 2 * m]);
    constraint_second(problem, q, &v, &mut rows_v, &mut wk, &mut ck, &mut s);
    let (mut dv, mut df, mut third, mut qs) =
        (vec![0.0; d], vec![0.0; d], vec![0.0; m * d], vec![0.0; d]);
    let mut rhs = vec![0.0; m];
    for (dz, o) in dirs.chunks_exact(2 * d).zip(out.chunks_exact_mut(2 * d)) {
        let (dq, dp) = dz.split_at(d);
        problem.velocity_tangent(p, dp, &mut dv);
        problem.force_tangent(q, dq, &mut df, &mut s);
        constraint_second(problem, q, dq, &mut rows_dq, &mut wk, &mut ck, &mut s);
        // δf − δGᵀλ.
        for (a, &la) in lambda.iter().enumerate() {
            axpy(&mut df, -la, &rows_dq[a * d..(a + 1) * d]);
        }
        // D³g[δq, v, v]: closed form, or central differences of D²g(q ± hδq)[v, v].
        let cubic: Vec<f64> = if m == 0 {
            Vec::new()
        } else if problem.constraint_third(q, dq, &v, &mut third, &mut s) {
            (0..m)
                .map(|a| dot(&third[a * d..(a + 1) * d], &v))
                .collect()
        } else {
            let h = 1e-4 * norm(q).max(1.0) / norm(dq).max(f64::MIN_POSITIVE);
            let (mut up, mut down) = (vec![0.0; m], vec![0.0; m]);
            for (sign, out) in [(1.0, &mut up), (-1.0, &mut down)] {
                for k in 0..d {
                    qs[k] = q[k] + sign * h * dq[k];
                }
                problem.constraint_curvature(&qs, &v, out, &mut s);
            }
            up.iter()
                .zip(&down)
                .map(|(u, l)| (u - l) / (2.0 * h))
                .collect()
        };
        for a in 0..m {
            let r = a * d..(a + 1) * d;
            rhs[a] = dot(&rows_dq[r.clone()], &acc)
                + dot(&w.rows.w[r.clone()], &df)
                + cubic[a]
                + 2.0 * dot(&rows_v[r], &dv);
        }
        if m > 0 {
            w.rows.solve(&mut rhs);
        }
        let (oq, op) = o.split_at_mut(d);
        oq.copy_from_slice(&dv);
        op.copy_from_slice(&df);
        for (a, &dl) in rhs.iter().enumerate() {
            axpy(op, -dl, &w.rows.c[a * d..(a + 1) * d]);
        }
    }
    Ok(())
}

/// [`constrained_field_into`] with a workspace of its own: writes ż into `dz` (2d values) and
/// returns the multipliers λ (m values); a state outside the problem's domain is
/// [`crate::Error::InvalidArgument`].
pub fn constrained_field<P: Constrained>(
    problem: &P,
    z: &[f64],
    dz: &mut [f64],
    s: &mut P::Scratch,
) -> Result<Vec<f64>> {
    let d = problem.dof();
    crate::check::len_of("state (q, p)", z, 2 * d)?;
    crate::check::len_of("dz", dz, 2 * d)?;
    let mut lambda = vec![0.0; problem.constraints()];
    let mut w = FieldWork::new(problem);
    constrained_field_into(problem, z, dz, &mut lambda, s, &mut w).map_err(|v| v.at_start())?;
    Ok(lambda)
}
