//! Lie group variational integrator (LGVI) for the rigid body and the heavy top (Lee, Leok &
//! McClamroch, "Lie group variational integrators for the full body problem", CMAME 196 (2007);
//! "A Lie group variational integrator for the attitude dynamics of a rigid body with
//! applications to the 3D pendulum", IEEE CCA 2005, eqs. (11)–(13)).
//!
//! From the discrete Lagrangian L_d = (1/h) tr((I − F_k) J_d) − (h/2)(U_k + U_{k+1}), with
//! J_d = ½ tr(J) I − J (J the inertia tensor), F_k = R_kᵀ R_{k+1}:
//!
//! h Π̂_k + (h²/2) τ̂_k = F_k J_d − J_d F_kᵀ,   R_{k+1} = R_k F_k,
//! Π_{k+1} = F_kᵀ (Π_k + (h/2) τ_k) + (h/2) τ_{k+1},   Γ_{k+1} = F_kᵀ Γ_k,
//!
//! with τ = mgl Γ × χ the gravity torque (zero for the free body). In Cayley coordinates
//! F = (I − ĝ)⁻¹(I + ĝ) = I + 2(ĝ + ĝ²)/(1 + |g|²) one has (derived here, using
//! ĝJ_d + J_dĝ = (Jg)^ and [ĝ², J_d] = (g × Jg)^)
//! F J_d − J_d Fᵀ = 2 (Jg + g × Jg)^ / (1 + |g|²), so the implicit equation is the 3-vector
//! equation 2(Jg + g × Jg) = h P (1 + |g|²), P = Π_k + (h/2)τ_k, solved by Newton's method under
//! the rule of [`crate::convergence`] ([`RULE`]: |Δg| relative to 1 + |g|).
//!
//! The method value is [`Lgvi`], in the catalogs of [`crate::systems::RigidBody`] and [`crate::systems::HeavyTop`]
//! (as `lgvi`); it works on the same state layout as the splitting (the private `top::Top`).
//!
//! Order 2, symplectic on T*SO(3) (resp. the heavy-top phase space), R stays in SO(3) and |Π|²,
//! R Π (free body), |Γ|² and Π·Γ (heavy top) are kept to round-off: Π and Γ move only by the
//! rotation Fᵀ and by kicks orthogonal to Γ.
//!
//! **Tangent map** (issue 26; the method `lgvi` on the tangent lifts of the tops, with and
//! without the attitude). Differentiating the step (F = cay(2g) = (I − ĝ)⁻¹(I + ĝ), s = 1 + |g|²,
//! P = h p, p = Π_k + (h/2)τ_k): the implicit equation φ(g; P, J) = 2(Jg + g × Jg) − P s = 0
//! gives, by the implicit-function theorem with its Newton matrix at the solution
//! A = ∂φ/∂g = 2(J + ĝJ − (Jg)^) − 2P gᵀ (factored once per step, applied to every direction),
//!
//! A δg = h s δp − 2(δJ g + g × δJ g),   δp = δΠ_k + (h/2)(δΓ_k × c + Γ_k × δc),
//!
//! and F's left-trivialised derivative η = (F⁻¹δF)^∨ = 2(δg − g × δg)/s (from
//! δF = 2(I − ĝ)⁻¹δĝ(I − ĝ)⁻¹ and Q x̂ Qᵀ = det Q (Q⁻ᵀx)^). With δ(Fᵀv) = Fᵀδv + (Fᵀv) × η:
//!
//! δΓ_{k+1} = FᵀδΓ_k + Γ_{k+1} × η,
//! δΠ_{k+1} = Fᵀδp + (Fᵀp) × η + (h/2)(δΓ_{k+1} × c + Γ_{k+1} × δc),
//! ξ_{k+1} = Fᵀξ_k + η   (δR = Rξ̂, R_{k+1} = R_k F).
//!
//! A parameter direction starts at 0 and carries the inhomogeneous terms: δJ = e_q e_qᵀ along
//! the principal moment I_q, δc = ∂c/∂θ along mgl and χ (`top::TopParam`); δJ = 0, δc = 0 along
//! the state's directions. The base state is advanced by the plain step itself (the same bits).

use super::super::top::{Top, TopParam, TopWork};
use crate::convergence::{self, Failed, Monitor, Rule, Verdict};
use crate::error::Result;
use crate::integrate::{Clock, Stepper};
use crate::lie::so3;
use nalgebra::{Matrix3, Vector3};

/// The stopping rule of the Newton iteration ([`crate::convergence`]; |Δg| relative to 1 + |g|;
/// ended at once at 2ε, where the next update would be round-off).
pub const RULE: Rule = Rule {
    tol: convergence::TOL,
    floor: 2.0 * f64::EPSILON,
    max_iter: 30,
};

/// The Lie group variational integrator (a method value), order 2.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Lgvi;

impl Lgvi {
    /// The stepper for a body on SO(3) with step `h`.
    pub(crate) fn stepper_for(&self, top: &Top, h: f64) -> Box<dyn Stepper> {
        Box::new(LgviStepper::new(top, h, None))
    }

    /// The stepper of the tangent lift of a body on SO(3) (module docs, "Tangent map"): state
    /// (z, δz₁, …, δz_k), the last `params.len()` directions along those parameters.
    pub(crate) fn tangent_stepper_for(
        &self,
        top: &Top,
        params: Vec<TopParam>,
        h: f64,
    ) -> Box<dyn Stepper> {
        let lift = Lift {
            params,
            dirs: Vec::new(),
        };
        Box::new(LgviStepper::new(top, h, Some(lift)))
    }
}

/// (cay(g) − I) v = 2(g × v + g × (g × v))/(1 + |g|²), computed without forming cay(g) − I by
/// subtraction, so its rounding error is O(ε|g||v|) rather than O(ε|v|).
fn cayley_minus_identity(g: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    let gv = g.cross(v);
    (gv + g.cross(&gv)) * (2.0 / (1.0 + g.norm_squared()))
}

/// Kahan's compensated addition sum += inc (carry holds the lost low-order part).
#[inline]
fn compensated_add(sum: &mut Vector3<f64>, carry: &mut Vector3<f64>, inc: Vector3<f64>) {
    let y = inc - *carry;
    let t = *sum + y;
    *carry = (t - *sum) - y;
    *sum = t;
}

/// The LGVI on (Π, [Γ], [R]) with the carries of the compensated sums; on a tangent lift also
/// the directions ([`Lift`]).
struct LgviStepper {
    top: Top,
    h: f64,
    j: Vector3<f64>,
    w: Option<TopWork>,
    carry_m: Vector3<f64>,
    carry_g: Vector3<f64>,
    lift: Option<Lift>,
}

/// The directions of a tangent lift (δΠ, [δΓ], [ξ]) one after another (principal frame), the
/// last `params.len()` of them along the parameters.
struct Lift {
    params: Vec<TopParam>,
    dirs: Vec<f64>,
}

impl LgviStepper {
    fn new(top: &Top, h: f64, lift: Option<Lift>) -> Self {
        LgviStepper {
            top: top.clone(),
            h,
            j: Vector3::from(top.moments),
            w: None,
            carry_m: Vector3::zeros(),
            carry_g: Vector3::zeros(),
            lift,
        }
    }

    /// The number of values of the base state.
    fn dim(&self) -> usize {
        3 + if self.top.c.is_some() { 3 } else { 0 } + if self.top.lifted { 9 } else { 0 }
    }

    /// Solves 2(Jg + g × Jg) = P (1 + |g|²) for the Cayley vector g of F (P = h·momentum).
    fn solve(&self, p: &Vector3<f64>) -> std::result::Result<Vector3<f64>, Failed> {
        let j = Matrix3::from_diagonal(&self.j);
        let mut g = p.component_div(&self.j) * 0.5;
        let mut monitor = Monitor::new(RULE);
        loop {
            let jg = j * g;
            let phi = (jg + g.cross(&jg)) * 2.0 - p * (1.0 + g.norm_squared());
            let jac = (j + so3::hat(&g) * j - so3::hat(&jg)) * 2.0 - p * g.transpose() * 2.0;
            // In place (`solve` copies and calls `solve_mut`: the same operations).
            let mut dg = phi;
            if !jac.lu().solve_mut(&mut dg) {
                return Err(monitor.failed(f64::INFINITY));
            }
            g -= dg;
            match monitor.check(dg.norm(), 1.0 + g.norm()) {
                Verdict::Continue => {}
                Verdict::Converged => return Ok(g),
                Verdict::Failed(failed) => return Err(failed),
            }
        }
    }

    fn torque(&self, gamma: &Option<Vector3<f64>>) -> Vector3<f64> {
        match (&self.top.c, gamma) {
            (Some(c), Some(g)) => g.cross(c),
            _ => Vector3::zeros(),
        }
    }

    /// One step. Π and Γ are advanced by increments, Π_{k+1} = Π_k + [(h/2)τ_k + (Fᵀ − I)P] +
    /// (h/2)τ_{k+1}, Γ_{k+1} = Γ_k + (Fᵀ − I)Γ_k, added with compensated summation: along a
    /// free-body run F is nearly the same rotation at every step, and forming Fᵀ P directly has a
    /// rounding bias that makes |Π|² drift linearly (~1e-11 after 10⁶ steps).
    /// Returns the state after the step and the Cayley vector g of its F.
    fn step(&mut self, mut s: TopWork) -> std::result::Result<(TopWork, Vector3<f64>), Failed> {
        let h = self.h;
        let kick = self.torque(&s.g) * (0.5 * h);
        let p = s.m + kick;
        let g = self.solve(&(p * h))?;
        compensated_add(
            &mut s.m,
            &mut self.carry_m,
            kick + cayley_minus_identity(&-g, &p),
        );
        if let Some(gam) = s.g.as_mut() {
            let dg = cayley_minus_identity(&-g, gam);
            compensated_add(gam, &mut self.carry_g, dg);
        }
        let kick = self.torque(&s.g) * (0.5 * h);
        compensated_add(&mut s.m, &mut self.carry_m, kick);
        if let Some(r) = s.r.as_mut() {
            // R F with F = (I − ĝ)⁻¹(I + ĝ) = cay(2g), by increments of R's rows: F formed as a
            // matrix is orthogonal only to ~ε, the same defect at every step of a steady rotation
            // (RᵀR drifted linearly); see `so3::Rodrigues`.
            so3::Rodrigues::cayley(&(g * 2.0)).right_mul(r);
        }
        Ok((s, g))
    }

    /// The tangent map of the step from `before` to `after` (Cayley vector `g`) on every
    /// direction of `lift` (module docs, "Tangent map").
    fn tangent(&self, before: &TopWork, after: &TopWork, g: &Vector3<f64>, lift: &mut Lift) {
        let (h, c) = (self.h, self.top.c.unwrap_or_else(Vector3::zeros));
        let (heavy, x) = (
            self.top.c.is_some(),
            if self.top.c.is_some() { 6 } else { 3 },
        );
        let e = x + if self.top.lifted { 3 } else { 0 };
        let gam0 = before.g.unwrap_or_else(Vector3::zeros);
        let gam1 = after.g.unwrap_or_else(Vector3::zeros);
        let p = before.m + self.torque(&before.g) * (0.5 * h);
        let s = 1.0 + g.norm_squared();
        let j = Matrix3::from_diagonal(&self.j);
        let jg = j * g;
        let newton = (j + so3::hat(g) * j - so3::hat(&jg)) * 2.0 - p * g.transpose() * (2.0 * h);
        let lu = newton.lu();
        // Fᵀv = cay(−2g)v, by its increment as in the step.
        let ft = |v: &Vector3<f64>| v + cayley_minus_identity(&-g, v);
        let fp = ft(&p);
        let k = lift.dirs.len() / e;
        let first_param = k - lift.params.len();
        for (i, dy) in lift.dirs.chunks_exact_mut(e).enumerate() {
            let (dj, dc) = match i.checked_sub(first_param).map(|m| lift.params[m]) {
                Some(TopParam::Moment(q)) => (Some(q), Vector3::zeros()),
                Some(TopParam::Gravity(dc)) => (None, dc),
                None => (None, Vector3::zeros()),
            };
            let dm = Vector3::from_column_slice(&dy[..3]);
            let dgam = match heavy {
                true => Vector3::from_column_slice(&dy[3..6]),
                false => Vector3::zeros(),
            };
            let dp = dm + (dgam.cross(&c) + gam0.cross(&dc)) * (0.5 * h);
            let mut rhs = dp * (h * s);
            if let Some(q) = dj {
                let djg = Vector3::ith(q, g[q]);
                rhs -= (djg + g.cross(&djg)) * 2.0;
            }
            let dg = lu.solve(&rhs).unwrap_or_else(|| Vector3::repeat(f64::NAN));
            let eta = (dg - g.cross(&dg)) * (2.0 / s);
            let dgam1 = ft(&dgam) + gam1.cross(&eta);
            let dm1 = ft(&dp) + fp.cross(&eta) + (dgam1.cross(&c) + gam1.cross(&dc)) * (0.5 * h);
            dy[..3].copy_from_slice(dm1.as_slice());
            if heavy {
                dy[3..6].copy_from_slice(dgam1.as_slice());
            }
            if self.top.lifted {
                let xi = ft(&Vector3::from_column_slice(&dy[x..x + 3])) + eta;
                dy[x..x + 3].copy_from_slice(xi.as_slice());
            }
        }
    }
}

impl Stepper for LgviStepper {
    /// The base state, and on a lift its directions after it.
    fn set(&mut self, z: &[f64]) -> Result<()> {
        let d = self.dim();
        self.w = Some(self.top.load(&z[..d]));
        if let Some(lift) = self.lift.as_mut() {
            lift.dirs.clear();
            lift.dirs.extend_from_slice(&z[d..]);
        }
        self.carry_m = Vector3::zeros();
        self.carry_g = Vector3::zeros();
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        if let Some(w) = &self.w {
            let d = self.dim();
            self.top.store(w, &mut z[..d]);
            if let Some(lift) = &self.lift {
                z[d..].copy_from_slice(&lift.dirs);
            }
        }
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        let Some(mut w) = self.w.take() else {
            return Ok(());
        };
        for k in 0..steps {
            match self.step(w) {
                Ok((next, g)) => {
                    if let Some(mut lift) = self.lift.take() {
                        self.tangent(&w, &next, &g, &mut lift);
                        self.lift = Some(lift);
                    }
                    w = next;
                }
                Err(failed) => {
                    self.w = Some(w);
                    return Err(clock.not_converged(k, "LGVI Newton iteration", failed, RULE.tol));
                }
            }
        }
        self.w = Some(w);
        Ok(())
    }
}
