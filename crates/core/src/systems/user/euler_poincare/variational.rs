//! `Variational(Composition)`: the discrete Euler–Poincaré method of an [`EulerPoincare`] system
//! (the Lie group variational integrator of a general reduced Lagrangian; Marsden, Pekarsky &
//! Shkoller 1999, Bou-Rabee & Marsden 2009), and its symmetric compositions.
//!
//! **Derivation (left, no parameter).** The discrete Lagrangian of a step g_k → g_{k+1} =
//! g_k exp(u) is L_d = h ℓ(u/h). Vary g_k ↦ g_k exp(εη_k): f_k = g_k⁻¹g_{k+1} ↦
//! exp(−εη_k) f_k exp(εη_{k+1}). With the right- and left-trivialised derivatives of
//! l_d(f) = h ℓ(log f/h), ⟨μ⁻(f), η⟩ = d/dε l_d(exp(εη) f) and ⟨μ⁺(f), η⟩ = d/dε l_d(f exp(εη)),
//! the discrete action is stationary iff μ⁺(f_{k−1}) = μ⁻(f_k) =: μ_k, the discrete momentum.
//! Since exp(εη) exp(u) = exp(u + ε dexp_u⁻¹η + O(ε²)) (dexp_u w = d/dε exp(u + εw) exp(−u), the
//! right-trivialised differential), μ⁻(exp u) = (dexp_u⁻¹)ᵀ ℓ'(u/h); and μ⁺(f) = Ad_fᵀ μ⁻(f)
//! (f exp(εη) = exp(ε Ad_f η) f). So one step from μ_k solves
//!
//! (dexp_u⁻¹)ᵀ ∂ℓ/∂ξ(u/h) = μ_k   for u,   then   μ_{k+1} = Ad_{exp u}ᵀ μ_k,   g_{k+1} = g_k exp(u):
//!
//! the momentum moves by the coadjoint action (the orbit, i.e. every Casimir, is kept to
//! round-off, and with g the Noether momentum Ad*_{g⁻¹}μ: Ad_{g exp u}^{−ᵀ} Ad_{exp u}ᵀ = Ad_g^{−ᵀ}).
//! On so(3) with ℓ = ½⟨Ω, 𝕀Ω⟩ this is Π_{k+1} = F_kᵀΠ_k of Moser–Veselov and Lee's LGVI, with
//! the exponential in place of their Cayley-type parametrisation of F_k (the discrete
//! Lagrangians differ at O(h³): the methods agree to second order).
//!
//! **An advected parameter** a = g⁻¹a₀ (left): L_d = (h/2)[ℓ(u/h, a_k) + ℓ(u/h, a_{k+1})],
//! a_{k+1} = exp(u)⁻¹·a_k (the trapezoid keeps the method symmetric). The variation of a_k is
//! −η_k·a_k, which by ⟨b ⋄ a, η⟩ = −⟨b, η·a⟩ adds (h/2)∂ℓ/∂a ⋄ a at both ends of a step:
//!
//! (dexp_u⁻¹)ᵀ λ − (h/2) b_k ⋄ a_k = μ_k,   μ_{k+1} = Ad_{exp u}ᵀ (μ_k + (h/2) b_k ⋄ a_k) + (h/2) b_{k+1} ⋄ a_{k+1},
//!
//! with λ = ½[∂ℓ/∂ξ(u/h, a_k) + ∂ℓ/∂ξ(u/h, a_{k+1})], b_j = ∂ℓ/∂a(u/h, a_j). Its first-order
//! expansion is μ̇ = ad*_ξ μ + ∂ℓ/∂a ⋄ a (000 (4.4)). For the heavy top the Casimirs |Γ|² and
//! M·Γ are kept to round-off (a moves by rotations, and b ⋄ a = b × a is orthogonal to a).
//!
//! **Right.** By the mirror g ↦ g⁻¹ ([`super::super::lie_poisson`] module docs): the right system
//! of ℓ is the left system of ℓ̃(η, a) = ℓ(−η, a) in μ̃ = −μ, g̃ = g⁻¹. The step is taken in the
//! mirrored variables; g_{k+1} = exp(−ũ) g_k.
//!
//! **Symmetry and order.** The adjoint discrete Lagrangian −L_d(g_{k+1}, g_k; −h) equals L_d
//! (log(f⁻¹) = −log f, and the trapezoid is symmetric in a_k, a_{k+1}), so the method is
//! symmetric, of order 2, and its compositions with the weights of [`Composition`] reach orders
//! 4 and 6. Why exp and not Cayley: cay⁻¹'s differential involves the matrix product uηu, which
//! lies in g only for quadratic groups, and the Cayley image of an element acts on a parameter
//! through the representation of the group, not of its Lie algebra; the exponential serves every
//! algebra and action lieflow knows (the coadjoint maps of [`LiePoisson`]).
//!
//! **The solve** is Newton's method with the residual's derivative to first order in u,
//! K = (1 − ½ad*_u) ℓ''/h − ½C(λ) (C(λ)_{·i} = ad*_{e_i} λ; dexp_u⁻¹ = 1 − ½ad_u + O(u²)),
//! inverted to that order by two applications of ℓ''⁻¹: a contraction by O(|u|²) per
//! iteration, three iterations at |u| = 0.01. ℓ'' is 𝕀 for a quadratic ℓ (its inverse kept),
//! else the Hessian at the start guess u = hξ(μ_k) (ξ the Legendre inverse), factored once per
//! step; for a quadratic ℓ the start guess is of second order (ξ = 𝕀⁻¹ of the momentum at the
//! step's middle, μ_k + ½ad*_u μ_k).
//! The rule is [`crate::convergence`]'s ([`RULE`]: the residual relative to the momenta); a step
//! whose residual is still above the tolerance after [`RULE`]`.max_iter` iterations is
//! [`crate::Error::NotConverged`].

use super::{inverse, mat_vec, EulerPoincare, Lagrangian};
use crate::convergence::{self, Failed, Monitor, Rule, Verdict};
use crate::error::Result;
use crate::integrate::hooks;
use crate::integrate::method::{Clock, Integrator, Properties, Stepper};
use crate::integrate::methods::Composition;
use crate::integrate::problem::{GroupField, Violation};
use crate::integrate::Problem;
use crate::numerics::linalg::{compensated_add, DenseLu};
use crate::systems::user::attitude::{Group, GroupScratch, Side};
use crate::systems::user::lie_poisson::{LiePoisson, LieScratch};

/// The stopping rule of the step's Newton iteration: the residual of the momentum equation
/// relative to the step's momenta (max(‖μ_k‖_∞, ‖λ‖_∞)), accepted below 10⁻¹², then on while
/// it decreases; ended at once by a residual at the rounding of the momenta (2ε). (In u the
/// precision of a stiff direction of ℓ'' is only ε·h·cond(ℓ'') of ‖u‖, so the residual, not
/// the update, says when the step is solved.)
pub const RULE: Rule = Rule {
    tol: convergence::TOL,
    floor: 2.0 * f64::EPSILON,
    max_iter: 50,
};

/// The discrete Euler–Poincaré method composed with the weights of a [`Composition`]
/// (`Composition::strang()`: the method itself, order 2). Symplectic (Poisson), symmetric; keeps
/// the coadjoint orbit and, with the configuration, the Noether momentum.
#[derive(Clone, Debug, PartialEq)]
pub struct Variational(pub Composition);

impl Integrator<EulerPoincare> for Variational {
    fn properties(&self) -> Properties {
        Properties::geometric(self.0.order())
    }

    fn stepper(&self, problem: &EulerPoincare, dt: f64) -> Result<Box<dyn Stepper>> {
        let (d, m) = problem.dims();
        let base = problem.system.without_attitude();
        let big = base.dim();
        let n = problem.system.space().dim();
        let (hessian, inertia_inv) = match &problem.legendre.lagrangian {
            Lagrangian::Quadratic(i) => (i.clone(), Some(inverse(i, d)?)),
            Lagrangian::Function { .. } => (vec![0.0; d * d], None),
        };
        let norms = inertia_inv
            .as_ref()
            .map(|inv| (row_norm(&hessian, d), row_norm(inv, d)));
        let group = problem
            .system
            .has_attitude()
            .then(|| problem.system.group())
            .flatten()
            .map(|g| (g, g.scratch()));
        Ok(Box::new(VariationalStepper {
            scratch: base.scratch(),
            base,
            ep: problem.clone(),
            group,
            gammas: self.0.gammas().to_vec(),
            h: dt,
            d,
            m,
            sign: problem.system.side().sign(),
            hessian,
            inertia_inv,
            lu: DenseLu::new(d),
            norms,
            dense: true,
            y: vec![0.0; n],
            mu: vec![0.0; big],
            u: vec![0.0; big],
            xi: vec![0.0; d],
            lam: vec![0.0; big],
            grad: vec![0.0; d],
            b_now: vec![0.0; m],
            b_next: vec![0.0; m],
            a_next: vec![0.0; big],
            diamond: vec![0.0; d],
            r: vec![0.0; big],
            col: vec![0.0; big],
            out: vec![0.0; big],
            theta: vec![0.0; d],
            carry: vec![0.0; big],
        }))
    }
}

struct VariationalStepper {
    ep: EulerPoincare,
    /// The Lie–Poisson form without the configuration: its coadjoint maps on g (⋉ V).
    base: LiePoisson,
    scratch: LieScratch,
    group: Option<(Group, GroupScratch)>,
    gammas: Vec<f64>,
    h: f64,
    d: usize,
    m: usize,
    /// +1 left, −1 right: the mirror (module docs).
    sign: f64,
    /// ∂²ℓ/∂ξ² (d×d; constant 𝕀 for a quadratic ℓ) and 𝕀⁻¹.
    hessian: Vec<f64>,
    inertia_inv: Option<Vec<f64>>,
    lu: DenseLu,
    /// (‖𝕀‖_∞, ‖𝕀⁻¹‖_∞) of a quadratic ℓ, and whether this step's Newton matrix is formed.
    norms: Option<(f64, f64)>,
    dense: bool,
    y: Vec<f64>,
    /// The mirrored momentum (and a), padded to dim g ⋉ V.
    mu: Vec<f64>,
    /// The unknown u (zero-padded: (u, 0) ∈ g ⋉ V).
    u: Vec<f64>,
    xi: Vec<f64>,
    lam: Vec<f64>,
    grad: Vec<f64>,
    b_now: Vec<f64>,
    b_next: Vec<f64>,
    /// (·, a_{k+1}): the parameter moved by exp(u)⁻¹.
    a_next: Vec<f64>,
    diamond: Vec<f64>,
    r: Vec<f64>,
    col: Vec<f64>,
    out: Vec<f64>,
    theta: Vec<f64>,
    /// The low-order parts of y's compensated sum (μ and a).
    carry: Vec<f64>,
}

/// Why a substep failed.
enum Failure {
    NotFinite,
    NotConverged(Failed),
}

/// ‖A‖_∞ (the largest row sum) of a d×d row-major A.
fn row_norm(a: &[f64], d: usize) -> f64 {
    a.chunks_exact(d)
        .map(|row| row.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// 𝕀⁻¹v in place (`tmp`: d values).
fn apply_inverse(inertia_inv: &[f64], v: &mut [f64], tmp: &mut [f64]) {
    let d = v.len();
    mat_vec(inertia_inv, v, &mut tmp[..d]);
    v.copy_from_slice(&tmp[..d]);
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

impl VariationalStepper {
    /// At u (mirrored; ξ = ±u/h the velocity of ℓ): λ (the mirrored ∂ℓ̃/∂ξ, averaged over a_k
    /// and a_{k+1}), b_k = ∂ℓ/∂a(ξ, a_k), a_{k+1} = exp(u)⁻¹·a_k and b_{k+1}. False when a
    /// function failed (its error recorded for the run).
    fn evaluate(&mut self, h: f64) -> bool {
        let (d, m, s) = (self.d, self.m, self.sign);
        let big = d + m;
        if self.inertia_inv.is_some() {
            // ℓ̃ = ℓ = ½⟨ξ, 𝕀ξ⟩: λ = 𝕀u/h, no parameter.
            mat_vec(&self.hessian, &self.u[..d], &mut self.lam[..d]);
            self.lam[..d].iter_mut().for_each(|l| *l /= h);
            return true;
        }
        for (x, u) in self.xi.iter_mut().zip(&self.u[..d]) {
            *x = s * u / h;
        }
        let Self {
            ep,
            xi,
            mu,
            grad,
            b_now,
            b_next,
            lam,
            a_next,
            u,
            col,
            base,
            scratch,
            ..
        } = self;
        let legendre = &ep.legendre;
        if !hooks::call(|| legendre.gradients(xi, &mu[d..big], grad, b_now)) {
            return false;
        }
        for (l, g) in lam[..d].iter_mut().zip(grad.iter()) {
            *l = s * g;
        }
        if m > 0 {
            a_next[..d].fill(0.0);
            a_next[d..big].copy_from_slice(&mu[d..big]);
            for (c, x) in col.iter_mut().zip(u.iter()) {
                *c = -x;
            }
            base.act(col, a_next, scratch);
            if !hooks::call(|| legendre.gradients(xi, &a_next[d..big], grad, b_next)) {
                return false;
            }
            for (l, g) in lam[..d].iter_mut().zip(grad.iter()) {
                *l = 0.5 * (*l + s * g);
            }
        }
        true
    }

    /// K = (ℓ'' − ½ad*_u ℓ'')/h − ½C(λ) (C(λ)_{·i} = ad*_{e_i} λ) formed at the start guess and
    /// factored; false if it is singular or not finite.
    fn factor_newton_matrix(&mut self, h: f64) -> bool {
        let d = self.d;
        let Self {
            base,
            hessian,
            lu,
            col,
            out,
            u,
            lam,
            ..
        } = self;
        let k = lu.matrix();
        for i in 0..d {
            col.fill(0.0);
            for r in 0..d {
                col[r] = hessian[r * d + i];
            }
            base.ad_star(u, col, out);
            for r in 0..d {
                k[(r, i)] = (hessian[r * d + i] - 0.5 * out[r]) / h;
            }
            col.fill(0.0);
            col[i] = 1.0;
            base.ad_star(col, lam, out);
            for r in 0..d {
                k[(r, i)] -= 0.5 * out[r];
            }
        }
        lu.factor()
    }

    /// The Newton update Δu = K⁻¹w into `r`, w = −(residual) in `r` on entry: by the factored
    /// K where it is formed, else matrix-free (below). K =
    /// (ℓ'' − ½ad*_u ℓ'')/h − ½C(λ) = (ℓ''/h)(1 − P), P = ℓ''⁻¹(½ad*_u ℓ'' + ½hC(λ)) = O(u), is
    /// the residual's derivative to first order in u (dexp_u⁻¹ = 1 − ½ad_u + O(u²)), inverted to
    /// the same order: K⁻¹ = h(1 + P)ℓ''⁻¹ + O(u²). With v = ℓ''⁻¹w, Pv = ℓ''⁻¹(½ad*_u w +
    /// ½h ad*_v λ) (C(λ)v = ad*_v λ): two applications of ℓ''⁻¹ and no matrix to form.
    fn newton_step(&mut self, h: f64) {
        let (d, big) = (self.d, self.u.len());
        if self.dense {
            self.lu.solve(&mut self.r[..d]);
            return;
        }
        self.r[d..big].fill(0.0);
        self.base.ad_star(&self.u, &self.r, &mut self.out);
        let Some(inv) = &self.inertia_inv else {
            unreachable!("the matrix-free step is for a quadratic ℓ only")
        };
        apply_inverse(inv, &mut self.r[..d], &mut self.theta);
        self.base.ad_star(&self.r, &self.lam, &mut self.col);
        for i in 0..d {
            self.out[i] = 0.5 * self.out[i] + 0.5 * h * self.col[i];
        }
        let Some(inv) = &self.inertia_inv else {
            unreachable!("the matrix-free step is for a quadratic ℓ only")
        };
        apply_inverse(inv, &mut self.out[..d], &mut self.theta);
        for i in 0..d {
            self.r[i] = h * (self.r[i] + self.out[i]);
        }
    }

    /// One step of size h on y (module docs).
    fn substep(&mut self, h: f64) -> std::result::Result<(), Failure> {
        let (d, m, s) = (self.d, self.m, self.sign);
        let big = d + m;
        for i in 0..d {
            self.mu[i] = s * self.y[i];
        }
        self.mu[d..big].copy_from_slice(&self.y[d..big]);
        // The start guess u = hξ̃ and ℓ'' there.
        match &self.inertia_inv {
            Some(ai) => {
                // ξ̃ = 𝕀⁻¹λ with λ = dexp_uᵀ μ̃ = μ̃ + ½ad*_u μ̃ + ⅙(ad*_u)²μ̃ + O(u³) (the
                // momentum at the step's middle), u = h𝕀⁻¹(μ̃ + ½ad*_u μ̃) in the bracket, itself
                // from u = h𝕀⁻¹μ̃: an error of O(h⁴), so that two Newton iterations reach
                // round-off at |u| = 0.01.
                self.r[..big].copy_from_slice(&self.mu[..big]);
                for pass in 0..2 {
                    mat_vec(ai, &self.r[..d], &mut self.col[..d]);
                    self.col[..d].iter_mut().for_each(|c| *c *= h);
                    self.col[d..big].fill(0.0);
                    self.base.ad_star(&self.col, &self.mu, &mut self.out);
                    for i in 0..d {
                        self.r[i] = self.mu[i] + 0.5 * self.out[i];
                    }
                    if pass == 1 {
                        self.base.ad_star(&self.col, &self.out, &mut self.lam);
                        for i in 0..d {
                            self.r[i] += self.lam[i] / 6.0;
                        }
                    }
                }
                mat_vec(ai, &self.r[..d], &mut self.xi);
            }
            None => {
                let Self { ep, y, xi, .. } = self;
                let legendre = &ep.legendre;
                let mut hess = None;
                let ok = hooks::call(|| {
                    legendre.velocity(&y[..d], &y[d..big], xi)?;
                    hess = Some(legendre.hessian(xi, &y[d..big])?);
                    Ok(())
                });
                let Some(hess) = hess.filter(|_| ok) else {
                    return Err(Failure::NotFinite);
                };
                for i in 0..d {
                    for j in 0..d {
                        self.hessian[i * d + j] = hess[(i, j)];
                    }
                }
                self.xi.iter_mut().for_each(|x| *x *= s);
            }
        }
        for i in 0..d {
            self.u[i] = h * self.xi[i];
        }
        self.u[d..big].fill(0.0);
        if !self.evaluate(h) {
            return Err(Failure::NotFinite);
        }
        // The Newton matrix: matrix-free where its first-order inverse converges fast (a
        // quadratic ℓ with cond(𝕀)·|u| and h|λ|‖𝕀⁻¹‖ small), else K formed and factored once.
        self.dense = match self.norms {
            Some((i, inv)) => {
                let (u, lam) = (inf_norm(&self.u[..d]), inf_norm(&self.lam[..d]));
                i * inv * u > 0.1 || h.abs() * lam * inv > 0.1
            }
            None => true,
        };
        if self.dense && !self.factor_newton_matrix(h) {
            return Err(Failure::NotFinite);
        }
        let mut monitor = Monitor::new(RULE);
        loop {
            // r = (dexp_u⁻¹)ᵀ λ − (h/2) b_k ⋄ a_k − μ̃_k.
            {
                let Self {
                    base,
                    scratch,
                    u,
                    lam,
                    r,
                    ep,
                    b_now,
                    mu,
                    diamond,
                    ..
                } = self;
                lam[d..big].fill(0.0);
                base.dexp_inv_dual(u, lam, r, scratch);
                if m > 0 {
                    ep.diamond(b_now, &mu[d..big], diamond);
                } else {
                    diamond.fill(0.0);
                }
                for i in 0..d {
                    r[i] = -(r[i] - 0.5 * h * diamond[i] - mu[i]);
                }
            }
            // The residual, in momentum units, relative to the momenta of the step (the
            // unknown u of a stiff direction of ℓ'' is known only to ε·h·cond(ℓ'')).
            let residual = inf_norm(&self.r[..d]);
            let scale = inf_norm(&self.mu[..d])
                .max(inf_norm(&self.lam[..d]))
                .max(f64::MIN_POSITIVE);
            self.newton_step(h);
            let mut step = 0.0f64;
            for (x, dx) in self.u[..d].iter_mut().zip(&self.r[..d]) {
                *x += dx;
                step = step.max(dx.abs());
            }
            if !step.is_finite() || !residual.is_finite() {
                return Err(Failure::NotFinite);
            }
            let verdict = monitor.check(residual, scale);
            if let Verdict::Failed(failed) = verdict {
                return Err(Failure::NotConverged(failed));
            }
            if (verdict == Verdict::Continue || m > 0) && !self.evaluate(h) {
                return Err(Failure::NotFinite);
            }
            if verdict == Verdict::Converged {
                break;
            }
        }
        // μ̃_{k+1} = Ad_{exp u}ᵀ (μ̃_k + (h/2) b_k ⋄ a_k) + (h/2) b_{k+1} ⋄ a_{k+1}, a_{k+1} = exp(u)⁻¹·a_k.
        let Self {
            base,
            scratch,
            ep,
            u,
            mu,
            b_now,
            b_next,
            diamond,
            col,
            r,
            out,
            carry,
            y,
            group,
            theta,
            ..
        } = self;
        // The step's increment Δ = μ̃_{k+1} − μ̃_k (and a_{k+1} − a_k) in `out`, added to y once
        // with compensated summation (an increment that repeats itself below an ulp of y at a
        // steady motion would otherwise round the same way every step).
        out[..big].fill(0.0);
        if m > 0 {
            ep.diamond(b_now, &mu[d..big], diamond);
            for i in 0..d {
                mu[i] += 0.5 * h * diamond[i];
                out[i] = 0.5 * h * diamond[i];
            }
        }
        for (c, x) in col.iter_mut().zip(u.iter()) {
            *c = -x;
        }
        if base.act_increment(col, mu, r, scratch) {
            for i in 0..big {
                out[i] += r[i];
                mu[i] += r[i];
            }
        } else {
            r[..big].copy_from_slice(&mu[..big]);
            base.act(col, mu, scratch);
            for i in 0..big {
                out[i] += mu[i] - r[i];
            }
        }
        if m > 0 {
            ep.diamond(b_next, &mu[d..big], diamond);
            for i in 0..d {
                out[i] += 0.5 * h * diamond[i];
            }
        }
        if out[..big].iter().any(|x| !x.is_finite()) {
            return Err(Failure::NotFinite);
        }
        out[..d].iter_mut().for_each(|x| *x *= s);
        compensated_add(&mut y[..big], carry, &out[..big]);
        if let Some((g, gs)) = group {
            // g ← g exp(ũ) (left) or exp(−ũ) g (right): θ = −ũ in Group::follow.
            for (t, x) in theta.iter_mut().zip(u.iter()) {
                *t = -x;
            }
            let side = if s > 0.0 { Side::Left } else { Side::Right };
            g.follow(side, theta, &mut y[big..], gs);
        }
        Ok(())
    }
}

impl Stepper for VariationalStepper {
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
                                what: "EulerPoincare state".into(),
                                message: "the discrete Euler–Poincaré step is not finite (the \
                                          motion blew up, or the Legendre map is singular on \
                                          the way); reduce dt"
                                    .into(),
                            },
                        ))
                    }
                    Err(Failure::NotConverged(failed)) => {
                        return Err(clock.not_converged(
                            s,
                            "discrete Euler–Poincaré Newton iteration",
                            failed,
                            RULE.tol,
                        ))
                    }
                }
            }
        }
        Ok(())
    }
}
