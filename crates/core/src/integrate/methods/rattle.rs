//! `Rattle`: the RATTLE method for a [`Constrained`] system H = ½ pᵀM⁻¹p + U(q) on the
//! constraint manifold g(q) = 0 (Andersen, "Rattle: a velocity version of the Shake algorithm",
//! J. Comput. Phys. 52 (1983); Hairer, Lubich & Wanner, *Geometric Numerical Integration*,
//! §VII.1.4). With f = −∂U/∂q and G = ∂g/∂q, one step of size h is
//!
//! p_{n+1/2} = p_n + h/2 (f(q_n) − G(q_n)ᵀλ),
//! q_{n+1} = q_n + h M⁻¹ p_{n+1/2},   g(q_{n+1}) = 0,
//! p_{n+1} = p_{n+1/2} + h/2 (f(q_{n+1}) − G(q_{n+1})ᵀμ),   G(q_{n+1}) M⁻¹ p_{n+1} = 0.
//!
//! It is of order 2, symmetric, and a symplectic map of the constrained phase space
//! T*{g = 0} = {g(q) = 0, G(q) M⁻¹p = 0} (HLW §VII.1.4); it is equivariant under every
//! linear symmetry of M, U and g, so it keeps their momentum maps (the vertical angular momentum of
//! a particle on a sphere). Both constraints hold at every step end to round-off.
//!
//! **Solves.** With ν = (h²/2)λ and the rows W_b = M⁻¹G_b(q_n)ᵀ (from [`Separable::velocity`],
//! linear), the position is q_{n+1} = q̃ − Σ_b ν_b W_b with q̃ = q_n + h M⁻¹(p_n + h/2 f(q_n)), and
//! ν solves g(q̃ − Σ ν_b W_b) = 0 by Newton's method (the m×m Jacobian G(q_{n+1}^{(k)}) Wᵀ is
//! refactored every iteration), until the position update is below [`TOL`]·‖q‖_∞ (or stagnates
//! below [`STAGNATION_TOL`]·‖q‖_∞); then p_{n+1/2} = p̃ − G(q_n)ᵀν/h. The multiplier μ solves the
//! linear m×m system (G M⁻¹Gᵀ)(q_{n+1}) κ = G M⁻¹ p̃ (κ = hμ/2). G, W and f at
//! q_{n+1} are reused by the next step.

use super::gauss::DenseLu;
use crate::error::Result;
use crate::integrate::method::{Clock, Integrator, Properties, Stepper};
use crate::integrate::problem::{Constrained, Separable, Violation};

/// RATTLE (order 2, symplectic on the constraint manifold, symmetric).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Rattle;

/// Relative tolerance of the Newton iteration for the position multipliers (on the position
/// update, relative to ‖q‖_∞).
pub const TOL: f64 = 4.0 * f64::EPSILON;
/// An iteration whose update stops decreasing is accepted below this relative bound.
pub const STAGNATION_TOL: f64 = 1e-12;
/// Maximal number of Newton iterations per step.
pub const MAX_ITER: usize = 50;

/// Why a constrained step failed.
pub(crate) enum Failure {
    /// The multiplier iteration did not converge: (iterations, last relative update).
    NotConverged(usize, f64),
    /// A state outside the problem's domain, or constraints that lost rank.
    Domain(Violation),
}

impl Failure {
    /// The error naming step k + 1 of this call; `solve` names the iteration, `tol` its
    /// tolerance.
    pub(crate) fn into_error(self, clock: &Clock, k: usize, solve: &str, tol: f64) -> crate::Error {
        match self {
            Failure::NotConverged(iterations, residual) => {
                clock.not_converged(k, solve, iterations, residual, tol)
            }
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
    /// The rows W = M⁻¹Cᵀ.
    pub(crate) w: Vec<f64>,
    lu: DenseLu,
    rhs: Vec<f64>,
}

impl Rows {
    /// Storage for m rows of length d.
    pub(crate) fn new(m: usize, d: usize) -> Self {
        Rows {
            m,
            d,
            c: vec![0.0; m * d],
            w: vec![0.0; m * d],
            lu: DenseLu::new(m),
            rhs: vec![0.0; m],
        }
    }

    /// W_b = M⁻¹C_b for the current rows C.
    pub(crate) fn update_w<P: Separable>(&mut self, problem: &P) {
        for (cb, wb) in self
            .c
            .chunks_exact(self.d)
            .zip(self.w.chunks_exact_mut(self.d))
        {
            problem.velocity(cb, wb);
        }
    }

    /// Factors the m×m matrix S_ab = B_a · W_b for rows B (m×d, row-major; `None`: B = C) and
    /// the current W; false when S is singular or not finite.
    pub(crate) fn factor_with(&mut self, rows: Option<&[f64]>) -> bool {
        let (m, d) = (self.m, self.d);
        let rows = rows.unwrap_or(&self.c);
        let mat = self.lu.matrix();
        for a in 0..m {
            for b in 0..m {
                mat[(a, b)] = dot(&rows[a * d..(a + 1) * d], &self.w[b * d..(b + 1) * d]);
            }
        }
        self.lu.factor()
    }

    /// Solves the factored system in place (m values).
    pub(crate) fn solve(&mut self, x: &mut [f64]) {
        self.lu.solve(x);
    }

    /// p ← p − Cᵀκ with κ such that C M⁻¹p = 0 afterwards (the projection of the last RATTLE
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
        self.lu.solve(&mut self.rhs);
        for a in 0..m {
            axpy(p, -self.rhs[a], &self.c[a * d..(a + 1) * d]);
        }
        true
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
    fn properties(&self) -> Properties {
        Properties::geometric(2)
    }

    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>> {
        let (d, m) = (problem.dof(), problem.constraints());
        Ok(Box::new(RattleStepper {
            scratch: problem.scratch(),
            problem: problem.clone(),
            h: dt,
            q: vec![0.0; d],
            p: vec![0.0; d],
            f: vec![0.0; d],
            v: vec![0.0; d],
            qn: vec![0.0; d],
            rows: Rows::new(m, d),
            jac: vec![0.0; m * d],
            g: vec![0.0; m],
            nu: vec![0.0; m],
        }))
    }
}

struct RattleStepper<P: Separable> {
    problem: P,
    scratch: P::Scratch,
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
    nu: Vec<f64>,
}

impl<P: Constrained> RattleStepper<P> {
    /// f, G and W at the current q.
    fn load(&mut self) -> std::result::Result<(), Violation> {
        self.problem
            .force(&self.q, &mut self.f, &mut self.scratch)?;
        self.problem.constraint_jacobian(&self.q, &mut self.rows.c);
        self.rows.update_w(&self.problem);
        Ok(())
    }

    fn step(&mut self) -> std::result::Result<(), Failure> {
        let RattleStepper {
            problem,
            scratch,
            h,
            q,
            p,
            f,
            v,
            qn,
            rows,
            jac,
            g,
            nu,
        } = self;
        let (h, d, m) = (*h, q.len(), g.len());
        // p̃ = p + h/2 f(q_n); q̃ = q_n + h M⁻¹p̃.
        axpy(p, 0.5 * h, f);
        problem.velocity(p, v);
        qn.copy_from_slice(q);
        axpy(qn, h, v);
        // Newton for ν: g(q̃ − Σ ν_b W_b) = 0.
        nu.fill(0.0);
        if m > 0 {
            let scale = max_abs(q).max(f64::MIN_POSITIVE);
            let mut prev = f64::INFINITY;
            for iter in 1..=MAX_ITER {
                problem.constraint(qn, g);
                problem.constraint_jacobian(qn, jac);
                if !rows.factor_with(Some(jac)) {
                    return Err(Failure::Domain(singular(problem.name())));
                }
                rows.solve(g);
                let mut norm = 0.0f64;
                for (k, qk) in qn.iter_mut().enumerate() {
                    let dq: f64 = (0..m).map(|b| g[b] * rows.w[b * d + k]).sum();
                    *qk -= dq;
                    norm = norm.max(dq.abs());
                }
                axpy(nu, 1.0, g);
                if !norm.is_finite() {
                    return Err(Failure::NotConverged(iter, f64::INFINITY));
                }
                if norm <= TOL * scale || (norm >= prev && norm <= STAGNATION_TOL * scale) {
                    break;
                }
                if iter == MAX_ITER {
                    return Err(Failure::NotConverged(iter, norm / scale));
                }
                prev = norm;
            }
        }
        // p_{n+1/2} = p̃ − G(q_n)ᵀν/h.
        for (b, &nb) in nu.iter().enumerate() {
            axpy(p, -nb / h, &rows.c[b * d..(b + 1) * d]);
        }
        q.copy_from_slice(qn);
        problem.force(q, f, scratch).map_err(Failure::Domain)?;
        problem.constraint_jacobian(q, &mut rows.c);
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
                    "RATTLE position constraint (Newton iteration for the multipliers)",
                    TOL,
                )
            })?;
        }
        Ok(())
    }
}
