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
//! equation 2(Jg + g × Jg) = h P (1 + |g|²), P = Π_k + (h/2)τ_k, solved by Newton's method.
//!
//! Order 2, symplectic on T*SO(3) (resp. the heavy-top phase space), R stays in SO(3) and |Π|²,
//! R Π (free body), |Γ|² and Π·Γ (heavy top) are kept to round-off: Π and Γ move only by the
//! rotation Fᵀ and by kicks orthogonal to Γ.

use crate::error::{Error, Result};
use crate::lie::so3;
use nalgebra::{Matrix3, Vector3};

/// Newton tolerance on |Δg| relative to 1 + |g|.
pub const TOL: f64 = 2.0 * f64::EPSILON;
/// Maximal Newton iterations per step.
pub const MAX_ITER: usize = 30;

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

/// The state the LGVI advances: Π, optionally Γ and R, and the carries of the compensated sums.
pub struct LgviState {
    /// Body momentum Π.
    pub m: Vector3<f64>,
    /// Γ = Rᵀe₃ (heavy top).
    pub gamma: Option<Vector3<f64>>,
    /// Attitude R.
    pub r: Option<Matrix3<f64>>,
    carry_m: Vector3<f64>,
    carry_g: Vector3<f64>,
}

impl LgviState {
    /// Wraps a state (zero carries).
    pub fn new(m: Vector3<f64>, gamma: Option<Vector3<f64>>, r: Option<Matrix3<f64>>) -> Self {
        LgviState {
            m,
            gamma,
            r,
            carry_m: Vector3::zeros(),
            carry_g: Vector3::zeros(),
        }
    }
}

/// The LGVI of a rigid body with principal moments `inertia` (internal principal frame), and
/// optionally a gravity torque τ = Γ × c with c = mgl χ.
pub struct Lgvi {
    h: f64,
    j: Vector3<f64>,
    c: Option<Vector3<f64>>,
}

impl Lgvi {
    /// A stepper of step `h`; `c = mgl χ` for the heavy top, `None` for the free body.
    pub fn new(inertia: [f64; 3], h: f64, c: Option<[f64; 3]>) -> Self {
        Lgvi {
            h,
            j: Vector3::from(inertia),
            c: c.map(Vector3::from),
        }
    }

    /// Solves 2(Jg + g × Jg) = P (1 + |g|²) for the Cayley vector g of F (P = h·momentum).
    pub fn solve(&self, p: &Vector3<f64>) -> Result<Vector3<f64>> {
        let j = Matrix3::from_diagonal(&self.j);
        let mut g = p.component_div(&self.j) * 0.5;
        for iter in 1..=MAX_ITER {
            let jg = j * g;
            let phi = (jg + g.cross(&jg)) * 2.0 - p * (1.0 + g.norm_squared());
            let jac = (j + crate::lie::so3::hat(&g) * j - crate::lie::so3::hat(&jg)) * 2.0
                - p * g.transpose() * 2.0;
            let dg = jac.lu().solve(&phi).ok_or_else(|| Error::NotConverged {
                what: "LGVI Newton iteration (singular Jacobian; reduce dt)".into(),
                iterations: iter,
                residual: phi.norm(),
                tol: TOL,
            })?;
            g -= dg;
            let size = dg.norm();
            if !size.is_finite() {
                break;
            }
            if size <= TOL * (1.0 + g.norm()) {
                return Ok(g);
            }
        }
        Err(Error::NotConverged {
            what: "LGVI Newton iteration (reduce dt)".into(),
            iterations: MAX_ITER,
            residual: f64::NAN,
            tol: TOL,
        })
    }

    fn torque(&self, gamma: &Option<Vector3<f64>>) -> Vector3<f64> {
        match (&self.c, gamma) {
            (Some(c), Some(g)) => g.cross(c),
            _ => Vector3::zeros(),
        }
    }

    /// One step. Π and Γ are advanced by increments, Π_{k+1} = Π_k + [(h/2)τ_k + (Fᵀ − I)P] +
    /// (h/2)τ_{k+1}, Γ_{k+1} = Γ_k + (Fᵀ − I)Γ_k, added with compensated summation: along a
    /// free-body run F is nearly the same rotation at every step, and forming Fᵀ P directly has a
    /// rounding bias that makes |Π|² drift linearly (~1e-11 after 10⁶ steps).
    pub fn step(&self, s: &mut LgviState) -> Result<()> {
        let h = self.h;
        let kick = self.torque(&s.gamma) * (0.5 * h);
        let p = s.m + kick;
        let g = self.solve(&(p * h))?;
        compensated_add(
            &mut s.m,
            &mut s.carry_m,
            kick + cayley_minus_identity(&-g, &p),
        );
        if let Some(gam) = s.gamma.as_mut() {
            let dg = cayley_minus_identity(&-g, gam);
            compensated_add(gam, &mut s.carry_g, dg);
        }
        let kick = self.torque(&s.gamma) * (0.5 * h);
        compensated_add(&mut s.m, &mut s.carry_m, kick);
        if let Some(r) = s.r.as_mut() {
            *r *= so3::cayley(&(g * 2.0)); // (I − ĝ)⁻¹(I + ĝ) = cay(2g)
        }
        Ok(())
    }
}
