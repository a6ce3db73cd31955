//! The symmetric relativistic tangent top on the static space-time −e^{2φ}dt² + dx² of a
//! potential φ(x, y), to second order in the body's size (002 (115)–(117), derived again; module
//! docs, "Static field").

use nalgebra::{Matrix3, Vector3};

use super::weak_field::{angular_momentum, outside_potential};
use super::{
    energy, lagrangian, legendre_inverse, space, state, velocities, Derivs, Legendre, Potential,
};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::space::Space;
use crate::integrate::Problem;

/// The symmetric relativistic tangent top on the static space-time ds² = −e^{2φ}dt² + dx² + dy²
/// of a potential φ, the Lagrangian 002 (117) (derived again, physical sign, module docs):
/// with b = e^{2φ} − v², I₀ = 𝕀/2, G = ∇φ,
/// L = −m√b + I₀θ̇²/√b − I₀e^{2φ}|G|²/(2√b) +
/// I₀(θ̇²v² + 2e^{2φ}θ̇(G_yẋ − G_xẏ) + e^{4φ}|G|²)/(2b^{3/2}).
/// Its weak-field, slow-motion limit is [`WeakFieldTop`](super::WeakFieldTop) (002 (118)), and
/// φ = 0 gives the flat [`RelativisticTangentTop`](super::RelativisticTangentTop). State
/// z = (x, y, θ, p_x, p_y, p_θ); coordinate speeds v < e^φ.
#[derive(Clone, Debug)]
pub struct StaticFieldTop {
    mass: f64,
    i0: f64,
    potential: Potential,
}

impl StaticFieldTop {
    /// Mass m > 0, 𝕀 = `inertia` > 0 (the symmetric body, I = (𝕀/2)·Id, I₀ = 𝕀/2) and the
    /// potential φ (g_tt = −e^{2φ}).
    pub fn new(mass: f64, inertia: f64, potential: Potential) -> Result<Self> {
        check::positive("mass", mass)?;
        check::positive("inertia", inertia)?;
        Ok(StaticFieldTop {
            mass,
            i0: 0.5 * inertia,
            potential,
        })
    }

    /// The potential.
    pub fn potential(&self) -> &Potential {
        &self.potential
    }

    /// The mass m.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// 𝕀 = tr I.
    pub fn inertia(&self) -> f64 {
        2.0 * self.i0
    }

    /// L(q, q̇) of 002 (117) (derived again, physical sign), q = (x, y, θ), q̇ = (ẋ, ẏ, θ̇).
    /// Errors: non-finite input, φ not finite at x, v ≥ e^φ.
    pub fn lagrangian(&self, q: [f64; 3], qdot: [f64; 3]) -> Result<f64> {
        lagrangian(self, q, qdot)
    }

    /// The canonical state (x, y, θ, p_x, p_y, p_θ) with p = ∂L/∂q̇. Errors: as
    /// [`StaticFieldTop::lagrangian`], a Legendre map that is not invertible there.
    pub fn state(
        &self,
        x: [f64; 2],
        theta: f64,
        xdot: [f64; 2],
        thetadot: f64,
    ) -> Result<Vec<f64>> {
        state(self, [x[0], x[1], theta], [xdot[0], xdot[1], thetadot])
    }

    /// The velocities (ẋ, ẏ, θ̇) of a state. Errors: wrong length, non-finite, outside the
    /// potential's domain or the range of the Legendre map.
    pub fn velocities(&self, z: &[f64]) -> Result<[f64; 3]> {
        velocities(self, z)
    }

    /// The angular momentum x p_y − y p_x about the origin (conserved for a central potential).
    pub fn angular_momentum(&self, z: &[f64]) -> Result<f64> {
        check::len_of("state", z, 6)?;
        angular_momentum(z)
    }
}

impl Problem for StaticFieldTop {
    fn calls_out(&self) -> bool {
        self.potential.calls_out()
    }
    fn name(&self) -> &'static str {
        "StaticFieldTop"
    }
    fn space(&self) -> Space {
        space()
    }
    /// E = p·q̇ − L (conserved: ∂_t is a Killing field of the static metric).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        energy(self, z)
    }
    /// p_θ and the momenta of the field's symmetries (`Potential::invariants`).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.potential.invariants(z)
    }
    fn invariant_count(&self) -> usize {
        self.potential.invariant_count()
    }
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.velocities(z).map(|_| ())
    }
}

impl Legendre for StaticFieldTop {
    /// Derivatives of L at (q, q̇) through the invariants Q = v², c = G_yẋ − G_xẏ, w = θ̇ and the
    /// field's ε = e^{2φ}, |G|² (module docs, "Static field"); None where φ or its derivatives
    /// are not finite, v² ≥ e^{2φ} or a value overflows.
    fn derivs(&self, q: &[f64], v: &Vector3<f64>) -> Option<Derivs> {
        let pv = self.potential.eval([q[0], q[1]]);
        let (m, i0) = (self.mass, self.i0);
        let (u, w) = ([v[0], v[1]], v[2]);
        let [gx, gy] = pv.grad;
        let [hxx, hxy, hyy] = pv.hess;
        let eps = (2.0 * pv.phi).exp();
        let qq = u[0] * u[0] + u[1] * u[1];
        let b = eps - qq;
        let field_finite = [eps, gx, gy, hxx, hxy, hyy].iter().all(|x| x.is_finite());
        if !(field_finite && b > 0.0 && w.is_finite() && q[2].is_finite()) {
            return None;
        }
        let h = [gy, -gx]; // JᵀG: c = h·ẋ
        let c = h[0] * u[0] + h[1] * u[1];
        let g2 = gx * gx + gy * gy;
        let b1 = 1.0 / b.sqrt(); // β = b^{−1/2}
        let b3 = b1 * b1 * b1;
        let b5 = b3 * b1 * b1;
        let b7 = b5 * b1 * b1;
        let w2 = w * w;
        let t = w2 * qq + 2.0 * eps * w * c + eps * eps * g2;
        let l = -m * b * b1 + i0 * w2 * b1 - 0.5 * i0 * eps * g2 * b1 + 0.5 * i0 * b3 * t;
        let l_q = 0.5 * m * b1 + i0 * w2 * b3 - 0.25 * i0 * eps * g2 * b3 + 0.75 * i0 * b5 * t;
        let l_c = i0 * b3 * eps * w;
        let l_w = 2.0 * i0 * w * b1 + i0 * b3 * (w * qq + eps * c);
        let l_qq =
            0.25 * m * b3 + 2.25 * i0 * w2 * b5 - 0.375 * i0 * eps * g2 * b5 + 1.875 * i0 * b7 * t;
        let l_qc = 1.5 * i0 * b5 * eps * w;
        let l_qw = 2.0 * i0 * w * b3 + 1.5 * i0 * b5 * (w * qq + eps * c);
        let l_cw = i0 * b3 * eps;
        let l_ww = 2.0 * i0 * b1 + i0 * b3 * qq;
        // ∂L/∂ε and ∂L/∂|G|² at fixed (Q, c, w).
        let l_eps = -0.5 * m * b1 - 0.5 * i0 * w2 * b3 - 0.5 * i0 * g2 * b1
            + 0.25 * i0 * eps * g2 * b3
            - 0.75 * i0 * b5 * t
            + i0 * b3 * (w * c + eps * g2);
        let l_g2 = -0.5 * i0 * eps * b1 + 0.5 * i0 * b3 * eps * eps;
        let lv = Vector3::new(
            2.0 * l_q * u[0] + l_c * h[0],
            2.0 * l_q * u[1] + l_c * h[1],
            l_w,
        );
        // ∂ε/∂x_k = 2εG_k, ∂|G|²/∂x_k = 2(HG)_k, ∂c/∂x_k = H_yk ẋ − H_xk ẏ.
        let hg = [hxx * gx + hxy * gy, hxy * gx + hyy * gy];
        let dc = [hxy * u[0] - hxx * u[1], hyy * u[0] - hxy * u[1]];
        let lq = Vector3::new(
            2.0 * eps * gx * l_eps + 2.0 * hg[0] * l_g2 + l_c * dc[0],
            2.0 * eps * gy * l_eps + 2.0 * hg[1] * l_g2 + l_c * dc[1],
            0.0,
        );
        let mut hess = Matrix3::zeros();
        for i in 0..2 {
            for j in 0..2 {
                let delta = if i == j { 1.0 } else { 0.0 };
                hess[(i, j)] = 2.0 * l_q * delta
                    + 4.0 * l_qq * u[i] * u[j]
                    + 2.0 * l_qc * (u[i] * h[j] + h[i] * u[j]);
            }
            let hw = 2.0 * l_qw * u[i] + l_cw * h[i];
            hess[(i, 2)] = hw;
            hess[(2, i)] = hw;
        }
        hess[(2, 2)] = l_ww;
        let finite = l.is_finite()
            && lv.iter().all(|x| x.is_finite())
            && lq.iter().all(|x| x.is_finite())
            && hess.iter().all(|x| x.is_finite());
        finite.then_some(Derivs { l, lv, lq, hess })
    }

    /// From a free particle of mass m + 2I₀θ̇² (the low-speed form of the momenta) slower than
    /// the local light speed e^φ, with θ̇ = p_θ/(2I₀); failing that, from rest.
    fn solve(&self, q: &[f64], p: &[f64]) -> Option<(Vector3<f64>, Derivs)> {
        let pv = self.potential.eval([q[0], q[1]]);
        let c = pv.phi.exp();
        if !(c.is_finite() && c > 0.0) {
            return None;
        }
        let w = p[2] / (2.0 * self.i0);
        let mm = self.mass + 2.0 * self.i0 * w * w;
        let e = (mm * mm + p[0] * p[0] + p[1] * p[1]).sqrt();
        let guess = Vector3::new(c * p[0] / e, c * p[1] / e, w);
        let derivs = |v: &Vector3<f64>| self.derivs(q, v);
        legendre_inverse(p, guess, derivs)
            .or_else(|| legendre_inverse(p, Vector3::new(0.0, 0.0, w), derivs))
    }

    fn undefined(&self, q: [f64; 3], v: [f64; 3]) -> Error {
        let pv = self.potential.eval([q[0], q[1]]);
        let field = [pv.phi, pv.grad[0], pv.grad[1]];
        let hess = pv.hess;
        if !(field.iter().chain(&hess).all(|x| x.is_finite()) && (2.0 * pv.phi).exp().is_finite()) {
            return outside_potential(q);
        }
        Error::invalid(
            "velocity",
            format!(
                "expected a coordinate speed |ẋ| < e^φ = {} (the local speed of light), got \
                 |({}, {})| = {}",
                pv.phi.exp(),
                v[0],
                v[1],
                v[0].hypot(v[1]),
            ),
        )
    }
}
