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

use super::super::top::{Top, TopWork};
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
        Box::new(LgviStepper {
            top: top.clone(),
            h,
            j: Vector3::from(top.moments),
            w: None,
            carry_m: Vector3::zeros(),
            carry_g: Vector3::zeros(),
        })
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

/// The LGVI on (Π, [Γ], [R]) with the carries of the compensated sums.
struct LgviStepper {
    top: Top,
    h: f64,
    j: Vector3<f64>,
    w: Option<TopWork>,
    carry_m: Vector3<f64>,
    carry_g: Vector3<f64>,
}

impl LgviStepper {
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
    fn step(&mut self, mut s: TopWork) -> std::result::Result<TopWork, Failed> {
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
        Ok(s)
    }
}

impl Stepper for LgviStepper {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.w = Some(self.top.load(z));
        self.carry_m = Vector3::zeros();
        self.carry_g = Vector3::zeros();
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        if let Some(w) = &self.w {
            self.top.store(w, z);
        }
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        let Some(mut w) = self.w.take() else {
            return Ok(());
        };
        for k in 0..steps {
            match self.step(w) {
                Ok(next) => w = next,
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
