//! The exact flow (M(t), R(t)) of the free rigid body, the method `exact` of [`crate::systems::RigidBody`], and
//! the splittings of the heavy top whose kinetic flow is this exact flow (`exact_splitting*` of
//! [`crate::systems::HeavyTop`]). After Celledoni, Fassò, Säfström & Zanna, "The exact computation of the free
//! rigid body motion and its use in splitting methods", SIAM J. Sci. Comput. 30 (2008), and van
//! Zon & Schofield, J. Comput. Phys. 225 (2007): the same factorisation of the attitude through
//! the conserved spatial momentum. The formulas below were derived independently (the body factor
//! from the Euler angles of M about an adaptively chosen polar axis, an integral of the third
//! kind in its circular case with characteristic −1 ≤ n ≤ 0) rather than transcribed, and are
//! checked numerically in `tests/rigid_body_exact.rs` (RK4 and DOP853 references, finite
//! differences, 50-digit values).
//!
//! **Momentum.** As in [`crate::systems::RigidBody::exact_momentum`]: in working axes (p, mid, s) (a proper
//! relabelling of the principal axes with I_mid the middle moment and the orbit of M encircling
//! e_s), M = (σa₁ cn u, a₂ sn u, εa₃ dn u), u = u₀ + λt; g = d₂₃/d₁₃, h = d₁₂/d₁₃ = 1 − g
//! (d_ij = 1/I_i − 1/I_j), a₁² = g a₂², |M|² = a₁² + a₃², m = h a₂²/a₃².
//!
//! It is evaluated relative to its base point u₀, componentwise
//! M(t) = M₀ + amp·((cn, sn, dn)(u) − (cn, sn, dn)(u₀)) (amp = (σa₁, a₂, εa₃)), the
//! differences taken before the products: M(0) = M₀ bit for bit, and evaluations composed step
//! after step (continued runs, `Trajectory.concatenate`, the stepper `set` at every step)
//! random-walk in |M|² and H. The formula itself, amp·(cn, sn, dn)(u), is biased: from a fresh
//! M₀ it returns |M|² (−0.46 ± 0.82) ε low at t = 0 (the rounding of the amplitudes and of u₀),
//! which composed steps added up to a linear fall of |M|² and H (−7.6e-17 relative per step at
//! I = (1, 2, 3), dt = 0.1). Subtracting the rounded products at u₀ instead,
//! M₀ + (amp·(cn, sn, dn)(u) − amp·(cn, sn, dn)(u₀)), still drifted (+1.2e-17 per step): the
//! products at u₀ lie within an ulp of M₀ and round onto it more often than chance (the largest
//! component of M₀ in units of max |M₀ᵢ| is ±1, on the edge of a binade), so they hide the
//! amplitudes' rounding at t = 0 where the products at u keep it. Differences of (cn, sn, dn)
//! carry that rounding only as (relative error of amp)·(increment); measured, no drift is left
//! (`tests/roundoff.rs`, 0.3–1.6 ε√N over 10⁵ composed steps, also near the separatrix).
//!
//! **Attitude.** R M = m is conserved. Take a body "polar" axis e_a that the orbit never meets,
//! and coordinates W of M in which e_a = e₃. B(W), the rotation with rows
//! b₃ = W/|W|, b₂ = (W₂, −W₁, 0)/ρ, b₁ = b₂ × b₃ (ρ = √(W₁² + W₂²) > 0; B = exp(θê₂) exp(ψê₃)
//! with θ, ψ the Euler angles of W), takes M to |M|e₃. Then B₀R₀ᵀ R(t) B(t)ᵀ fixes e₃, so
//!
//! R(t) = R₀ S(t),   S(t) = B₀ᵀ Z(φ(t)) B(t),   Z(φ) = exp(φê₃),   φ(0) = 0,
//!
//! and Ṙ = R hat(Ω) with BᵀḂ = hat(θ̇ exp(−ψê₃)e₂ + ψ̇e₃) gives φ̇ = Ω·n − ψ̇ n₃ (n = W/|W|), which
//! is the precession rate of the Euler angles (Landau & Lifshitz, *Mechanics* §37)
//! φ̇ = |M| (W₁²/I_{a₁} + W₂²/I_{a₂}) / (W₁² + W₂²) = |M|/I_a + |M|(1/I_b − 1/I_a)/(1 + ν sn²u):
//! * polar axis s: W₁² + W₂² = a₁²(1 + ν sn²u), ν = h/g = I_s(I_mid − I_p)/(I_p(I_s − I_mid)),
//!   I_b = I_p;
//! * polar axis p: W₁² + W₂² = M_mid² + M_s² = a₃²(1 + ν sn²u), ν = (a₁/a₃)² = m g/h, I_b = I_s.
//!
//! The axis with ν ≤ 1 is taken (if h/g > 1 then (a₁/a₃)² ≤ g/h < 1): with ν ≫ 1 the integrand
//! would have peaks of height ~ν and width ~1/√ν (where M passes near the pole of B) whose
//! integral cancels a quick half turn of B, and digits would be lost in proportion.
//! With Π̃(u) = ∫₀ᵘ dv/(1 + ν sn²v) = Π(−ν; am u | m), the elliptic integral of the third kind
//! in its circular case, ∫₀ᵗ dτ/(1 + ν sn²) = (Π̃(u) − Π̃(u₀))/λ, and for |r| ≤ K (where
//! F(am r | m) = r) Π̃(r) = r − (ν/3) sn³r R_J(cn²r, dn²r, 1, 1 + ν sn²r) (DLMF 19.25.14,
//! [`elliptic::carlson_rj`]). Its secular and periodic parts are split, Π̃(u) = q u + P(u) with
//! q = Π(−ν | m)/K = 1 − (ν/3) R_J(0, k′², 1, 1 + ν)/K and P odd and 2K-periodic, evaluated at the
//! reduced r = u − 2Kj ∈ [−K, K] (sn r = (−1)ʲ sn u):
//!
//! φ(t) = ω̄ t + (c/λ)(P(u) − P(u₀)),   ω̄ = |M|((1 − q)/I_a + q/I_b),
//! P(r) = (1 − q) r − (ν/3) sn³r R_J(cn²r, dn²r, 1, 1 + ν sn²r),
//!
//! c/λ = ±σε|M|/(a₃√g) (+ for the polar axis s; c = |M|(1/I_b − 1/I_a)). ω̄ is a sum of two
//! positive terms and P stays bounded, so no digits are lost at large t beyond the ε·ω̄t of the
//! product itself (the conditioning of the phase). On the separatrix (k′ = 0, u unbounded)
//! Π̃(u) = (u + √ν atan(√ν tanh u))/(1 + ν), q = 1/(1 + ν), P(u) = √ν atan(√ν sn u)/(1 + ν).
//! Closed forms replace it for a symmetric body (I_o doubled, symmetry axis e_s, w = M_s(1/I_s −
//! 1/I_o)): M(t) rotates about e_s by −wt and S(t) = exp(t M̂₀/I_o) exp(t w ê_s) (the flows of
//! ½|M|²/I_o and ½(1/I_s − 1/I_o)M_s² commute); and for a steady rotation about a principal axis,
//! a spherical body or M = 0: M constant and S(t) = exp(t hat(I⁻¹M)).
//!
//! With the attitude, M(t) is returned as S(t)ᵀM₀ (which R M = R₀M₀ makes exact), a rotation of
//! M₀: |M| and R M stay at the rounding of orthogonal products even when evaluations are composed
//! step after step (measured: |M|² and H random-walk, like M without the attitude above); S is
//! evaluated relative to its own value at t = 0
//! (a base point), so S(0) = I exactly and the rounding of the formulas cancels in short steps.
//!
//! **Tangent map** (issue 26; `FreeFlow::momentum_tangent`, the method `exact` on the tangent
//! lift of the body without attitude). Dφ_t(M₀) = ∂M(t)/∂M₀ and ∂M(t)/∂I of the map
//! computed, M₀ + f(t) − f(0) with f = amp·(cn, sn, dn)(u) (above), are Df(t) and ∂f(t)/∂I:
//! f(0) ≡ M₀ identically in M₀ and I (u₀ inverts the parametrisation), so Df(0) = I and
//! ∂f(0)/∂I = 0. (Subtracting the computed Df(0) − I as well, I + Df(t) − Df(0), gave the same
//! error of composed Jacobians but a Casimir pulled back ∇C(z)ᵀJ − ∇C(z₀)ᵀ 5× larger after 10⁶
//! composed steps, measured.) Df by the chain rule through the parametrisation: M(t) = (σa₁ cos φ, a₂ sin φ, εa₃ Δ(φ)), φ = am(u | m),
//! Δ = √(1 − m sin²φ), where a₁², a₂², a₃², m, λ and φ₀ (sin φ₀ = sn u₀, cos φ₀ = cn u₀) are
//! rational in M₀ and (g, h, d₁₃), so their differentials are elementary
//! (dφ₀ = cn₀ dM₂/a₂ − σ sn₀ dM₁/a₁ + sn₀cn₀ dg/(2g) since a₁² = g a₂²). The amplitude moves with u
//! and m: u = F(φ | m), and ∂F/∂m|_φ = (G(φ) − sin φ cos φ/Δ)/(2k′²) (DLMF 19.4.1) with
//! G = (E − k′²F)/m = F − D, D(φ | m) = (F − E)/m = ⅓ sin³φ R_D(cos²φ, Δ², 1); along the
//! continued amplitude D(u) = D(r) + 2j D(K) on the reduced r = u − 2Kj (D(K) = ⅓R_D(0, k′², 1)).
//! With du = dφ₀/dn₀ + t dλ + Q dm, Q = (D(u) − D(u₀) − λt − sn₀cn₀/dn₀)/(2k′²) (the u₀ and u
//! terms of ∂F/∂m combined, G(u₀) − G(u) = D(u) − D(u₀) − λt) and c = dm/(2k′²):
//!
//! dφ = dn·du + sn cn·c,   dΔ = −m sn cn·du − sn² dn·c,
//!
//! dM = (σ da₁ cn − σa₁ sn dφ, da₂ sn + a₂ cn dφ, ε da₃ dn + εa₃ dΔ) (no division by dn). One
//! closed form for the directions of M₀ and of the moments (dg, dh = −dg, dd₁₃). Checked against
//! the variational equations integrated in double-double (`tests/tangent.rs`: 2e-15 to 1.4e-13
//! relative to |J| over t = 60, k′ ≥ 0.025). **Where it degrades**: the 1/k′² of ∂F/∂m cancels
//! (the derivative at fixed u is analytic at m = 1), so near the separatrix the error grows like
//! ε(1 + |u|)/k′² (measured 6.6e-12 at k′ = 5e-3, 2e-10 at k′ = 7e-4, relative to |J|, which
//! itself grows like t/k′²); exactly on it (k′ = 0) the directions are NaN and a lifted run stops
//! with its non-finite error. The closed forms have theirs: a steady rotation about a principal
//! axis, Dφ_t = exp(tA) of the constant-coefficient variational equation (cos/sin about the
//! stable axes, cosh/sinh about the middle one; ∂M/∂I = 0); a sphere, Dφ_t = I and
//! ∂M/∂I_q = t M₀ × ∂Ω/∂I_q; a symmetric body, the rotation's derivative (δθ = t δw), and
//! along one of its two equal moments (which breaks the symmetry) the variational equation
//! solved in closed form (`symmetric_parameter`).
//!
//! **With the attitude** (`FreeFlow::attitude_tangent`): R(t) = R₀S(t), and the left-trivialised
//! direction ξ(t) (δR = Rξ̂) of a direction (δM₀, ξ₀) is S(t)ᵀξ₀ + σ with σ the direction of S(t)
//! itself. No integral of the third kind needs differentiating: |M|² is kept, so
//! δM(t) = −σ × M(t) + S(t)ᵀδM₀ gives σ ⊥ M(t) from the δM(t) above, and along M,
//! d/dt (σ·M) = δΩ·M = δH₀ − ½ Σ_q δI_q M_q²/I_q² (the variation of the energy is conserved), so
//! σ·M(t) = t δH₀ − ½ Σ_q δI_q X_q/I_q² with X_q = ∫₀ᵗ M_q² ds: on an elliptic orbit
//! ∫sn² du = D(u) − D(u₀) (the D above), ∫cn² = Δu − ΔD, ∫dn² = Δu − mΔD. Checked against the
//! variational equation σ̇ = σ × Ω + δΩ integrated in double-double (`tests/tangent.rs`:
//! 2e-16…1.4e-13 relative over t = 60, near the separatrix included).
//!
//! **Heavy top.** The flow of T(M) on se(3)* carries Γ with the attitude, the spatial vertical
//! RΓ being fixed: Γ(t) = R(t)ᵀR₀Γ₀ = S(t)ᵀΓ₀ (then Γ̇ = −hat(Ω)Γ = Γ × Ω), R(t) = R₀S(t).
//! H = T + V(Γ) splits into this flow and the kick of V, M ↦ M + τ Γ × c
//! ([`ExactSplitting`]; symplectic, keeps |Γ|² and M·Γ to round-off: M(τ) = S(τ)ᵀM₀). Its short
//! steps skip u₀, K and the reduction: the addition theorems (A&S 16.17.1–3) give
//! (sn, cn, dn)(u₀ + λτ) from (sn, cn, dn)(u₀), read off M₀, and (sn, cn, dn)(λτ), and
//! Π̃(u) − Π̃(u₀) = λτ − (ν/3)(sn³u R_J(u) − sn³u₀ R_J(u₀)) while u stays in [−K, K]
//! (`Orbit::short_step`; about half the cost of a general evaluation).

use super::super::top::{self, Top};
use crate::check;
use crate::error::Result;
use crate::integrate::methods::Composition;
use crate::integrate::{Clock, Stepper};
use crate::lie::so3;
use crate::numerics::elliptic;
use nalgebra::{Matrix3, Vector3};

/// The motion of a free rigid body from one momentum M₀ (principal frame): its constants,
/// computed once; [`FreeFlow::momentum`] and [`FreeFlow::motion`] evaluate it at any t.
#[derive(Clone, Debug)]
pub(crate) struct FreeFlow {
    m0: Vector3<f64>,
    kind: Kind,
}

// Unboxed: a flow is built in every step of the heavy-top splittings, without allocation.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
enum Kind {
    /// M constant and S(t) = exp(t ω̂): M = 0, a spherical body, a steady rotation.
    Uniform(Vector3<f64>),
    /// A symmetric body: M rotates about e_s by −wt, S(t) = exp(t M̂₀/I_o) exp(t w ê_s).
    Symmetric { s: usize, w: f64, inv_io: f64 },
    /// Three distinct moments.
    Elliptic(Elliptic),
}

/// The constants of an elliptic orbit (module docs), in units of `scale` = max |M₀ᵢ|.
#[derive(Clone, Copy, Debug)]
struct Orbit {
    /// Principal indices of the working axes (p, mid, s).
    axes: [usize; 3],
    /// M[axes[i]] = amp[i]·(cn, sn, dn)[i] in units of `scale`: (σa₁, sg·a₂, εa₃).
    amp: [f64; 3],
    scale: f64,
    lambda: f64,
    kp: f64,
    m: f64,
    /// (sn, cn, dn)(u₀) from M₀ directly.
    jac0: (f64, f64, f64),
    /// W_i = wsign[i]·M[waxes[i]]: the coordinates with the polar axis third.
    waxes: [usize; 3],
    wsign: [f64; 3],
    nu: f64,
    /// The moments of the polar axis and of the other end axis (I_a, I_b).
    ia: f64,
    ib: f64,
    /// |M₀| in units of `scale`.
    norm: f64,
    /// c/λ.
    coef: f64,
}

/// What [`shape`] finds: a closed-form motion or an elliptic orbit.
// A transient value, unboxed like `Kind`.
#[allow(clippy::large_enum_variant)]
enum Shape {
    Closed(Kind),
    Elliptic(Orbit),
}

/// The constants of the elliptic motion at any t: the orbit, u₀, the secular part and the base
/// point.
#[derive(Clone, Debug)]
struct Elliptic {
    o: Orbit,
    u0: f64,
    /// 2K (+∞ on the separatrix).
    two_k: f64,
    /// 1 − q = (ν/3) R_J(0, k′², 1, 1 + ν)/K (ν/(1 + ν) on the separatrix).
    jk: f64,
    /// ω̄ (absolute units).
    omega: f64,
    /// The base point (the formulas at t = 0): P(u₀), B(W₀)ᵀ and (sn, cn, dn)(u₀).
    p0: f64,
    b0t: Matrix3<f64>,
    jac0: (f64, f64, f64),
}

impl FreeFlow {
    /// The constants of the motion from M₀ (principal frame, finite) of a body with principal
    /// moments `inertia` (> 0). Moments equal to 1e-14 (relative) count as equal.
    pub(crate) fn new(inertia: &[f64; 3], m0: &Vector3<f64>) -> FreeFlow {
        let kind = match shape(inertia, m0) {
            Shape::Closed(k) => k,
            Shape::Elliptic(o) => Kind::Elliptic(Elliptic::new(o)),
        };
        FreeFlow { m0: *m0, kind }
    }

    /// M(t) alone (principal frame), without the constants of the attitude: the elliptic formula
    /// at u₀ + λt relative to u₀ (module docs, "Momentum"; the arithmetic of
    /// [`crate::systems::RigidBody::exact_momentum`] and of [`FreeFlow::momentum`]).
    pub(crate) fn momentum_at(inertia: &[f64; 3], m0: &Vector3<f64>, t: f64) -> Vector3<f64> {
        match shape(inertia, m0) {
            Shape::Closed(kind) => FreeFlow { m0: *m0, kind }.momentum(t),
            Shape::Elliptic(o) => {
                let (u0, jac0) = o.base();
                let jac = elliptic::ellipj_kprime_unchecked(u0 + o.lambda * t, o.kp, o.m);
                o.relative_momentum(m0, jac, jac0)
            }
        }
    }

    /// M(t) (principal frame).
    pub(crate) fn momentum(&self, t: f64) -> Vector3<f64> {
        match &self.kind {
            Kind::Uniform(_) => self.m0,
            Kind::Symmetric { s, w, .. } => {
                let mut m = self.m0;
                top::rotate_axis(&mut m, *s, t * w);
                m
            }
            Kind::Elliptic(e) => e.momentum(&self.m0, t),
        }
    }

    /// (M(t), S(t)) with S(t) = R₀ᵀR(t), the attitude relative to the start (principal frame).
    /// NaN where an angle exceeds [`crate::numerics::angle::EXP_MAX_NORM`] (lost to rounding).
    pub(crate) fn motion(&self, t: f64) -> (Vector3<f64>, Matrix3<f64>) {
        match &self.kind {
            Kind::Uniform(w) => (self.m0, so3::exp_unchecked(&(w * t))),
            Kind::Symmetric { s, w, inv_io } => {
                let mut m = self.m0;
                top::rotate_axis(&mut m, *s, t * w);
                let mut spin = Vector3::zeros();
                spin[*s] = t * w;
                (
                    m,
                    so3::exp_unchecked(&(self.m0 * (t * inv_io))) * so3::exp_unchecked(&spin),
                )
            }
            Kind::Elliptic(e) => {
                let (y, jac) = e.scaled(t);
                let pu = e.periodic_at(e.u0 + e.o.lambda * t, jac);
                let phi = e.omega * t + e.o.coef * (pu - e.p0);
                let s = e.o.relative(&e.b0t, phi, &y);
                // M = SᵀM₀ (R M conserved), a rotation of M₀: composed evaluations keep |M| and
                // R M to the rounding of orthogonal products, without a bias per step.
                (s.transpose() * self.m0, s)
            }
        }
    }

    /// The largest rate at which a phase of the motion grows (|λ| + ω̄, or |Ω|): t·rate beyond
    /// [`crate::numerics::angle::EXP_MAX_NORM`] loses the angle to rounding.
    pub(crate) fn rate(&self) -> f64 {
        match &self.kind {
            Kind::Uniform(w) => w.amax() * 3f64.sqrt(),
            Kind::Symmetric { w, inv_io, .. } => w.abs() + self.m0.amax() * 3f64.sqrt() * inv_io,
            Kind::Elliptic(e) => e.o.lambda.abs() + e.omega,
        }
    }
}

impl FreeFlow {
    /// The tangent map of the momentum's flow at t (module docs, "Tangent map"):
    /// (Dφ_t(M₀) = ∂M(t)/∂M₀, ∂M(t)/∂I with column q the derivative along the moment I_q),
    /// principal frame, from the moments `inertia` this flow was built with. NaN on the
    /// separatrix itself (k′ = 0; module docs).
    pub(crate) fn momentum_tangent(
        &self,
        inertia: &[f64; 3],
        t: f64,
    ) -> (Matrix3<f64>, Matrix3<f64>) {
        let m0 = &self.m0;
        match &self.kind {
            Kind::Uniform(_) => uniform_tangent(inertia, m0, t),
            Kind::Symmetric { s, w, inv_io } => {
                // M(t) = Rot_s(−θ)M₀, θ = t w(M₀, I): δM(t) = Rot δM₀ + δθ (M_j(t), −M_i(t)).
                let (s, (i, j)) = (*s, ((*s + 1) % 3, (*s + 2) % 3));
                let mt = self.momentum(t);
                let (sin, cm1) = crate::numerics::simd::angle_sin_cosm1(t * w);
                let mut jac = Matrix3::identity();
                for c in [i, j] {
                    let mut e = Vector3::zeros();
                    e[c] = 1.0;
                    top::rotate_axis_sc(&mut e, s, sin, cm1);
                    jac.set_column(c, &e);
                }
                let turn = Vector3::from_fn(|r, _| {
                    if r == i {
                        mt[j]
                    } else if r == j {
                        -mt[i]
                    } else {
                        0.0
                    }
                });
                let coef = 1.0 / inertia[s] - inv_io;
                jac.set_column(s, &(jac.column(s) + turn * (t * coef)));
                // Along I_s: δθ = −t M_s/I_s²; along the equal moments, `symmetric_parameter`.
                let mut par = Matrix3::zeros();
                par.set_column(s, &(turn * (-t * m0[s] / (inertia[s] * inertia[s]))));
                let di = symmetric_parameter(m0, &mt, (i, j, s), *w, *inv_io, 1.0 / inertia[s], t);
                // I_j: the sum of the two (δθ = t M_s/I_o², the rotation rate) less I_i's.
                let dsum = turn * (t * m0[s] * inv_io * inv_io);
                par.set_column(i, &di);
                par.set_column(j, &(dsum - di));
                (jac, par)
            }
            Kind::Elliptic(e) => e.tangent(inertia, m0, t),
        }
    }
}

/// ∂M(t)/∂I_i for a symmetric body (I_i = I_j = I_o, symmetry axis e_s, (i, j, s) cyclic) along
/// one of its equal moments, which breaks the symmetry: with a = 1/I_o, b = 1/I_s, w =
/// M_s(b − a) (M_i + iM_j = z₀e^{−iwt}), the variational equation δ̇ = δ × Ω + M × I⁻¹δ +
/// M × ∂Ω/∂I_i (∂Ω = −a²M_i e_i) from δ(0) = 0 integrates in closed form:
/// δ_s = (a²/2)(M_i M⁰_j + M_j M⁰_i) S, S = sin(wt)/w, and δ_i + iδ_j = −i z(t) A − i z̄₀ B with
/// A = (b − a)∫₀ᵗδ_s + a²M_s t/2, B = a²M_s S/2, ∫₀ᵗδ_s = (a²t²/4)(2M⁰_iM⁰_j sinc²(wt) +
/// (M⁰_i² − M⁰_j²) 2(sin y − y)/y²), y = 2wt (series for small y: no cancellation at w → 0).
fn symmetric_parameter(
    m0: &Vector3<f64>,
    mt: &Vector3<f64>,
    (i, j, s): (usize, usize, usize),
    w: f64,
    a: f64,
    b: f64,
    t: f64,
) -> Vector3<f64> {
    let x = w * t;
    let sinc = if x.abs() < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    };
    let y = 2.0 * x;
    // 2(sin y − y)/y² = 2 Σ_{k≥1} (−1)^k y^{2k−1}/(2k+1)!.
    let defect = if y.abs() < 0.5 {
        let (mut term, mut sum) = (-y / 6.0, 0.0);
        for k in 1..12 {
            sum += term;
            term *= -y * y / (((2 * k + 2) * (2 * k + 3)) as f64);
        }
        2.0 * sum
    } else {
        2.0 * (y.sin() - y) / (y * y)
    };
    let (p, q) = (m0[i], m0[j]);
    let a2 = a * a;
    let big_s = t * sinc;
    let int_ds = a2 * t * t / 4.0 * (2.0 * p * q * sinc * sinc + (p * p - q * q) * defect);
    let big_a = (b - a) * int_ds + a2 * m0[s] * t / 2.0;
    let big_b = a2 * m0[s] * big_s / 2.0;
    let mut d = Vector3::zeros();
    d[i] = big_a * mt[j] - big_b * q;
    d[j] = -big_a * mt[i] - big_b * p;
    d[s] = a2 / 2.0 * (mt[i] * q + mt[j] * p) * big_s;
    d
}

/// The tangent map of a uniform motion: M₀ = 0 or a spherical body (Dφ = I; a sphere's
/// ∂M/∂I_q = t M₀ × ∂Ω/∂I_q with ∂Ω = −M₀_q/I_q² e_q, the field being constant to first
/// order), or a steady rotation M₀ = μe_k about a principal axis of three distinct moments: the
/// variational equation at an equilibrium has constant coefficients, δṀ_i = αδM_j,
/// δṀ_j = βδM_i (α = μ(1/I_k − 1/I_j), β = μ(1/I_i − 1/I_k), (i, j, k) cyclic), so
/// Dφ_t = exp(tA) in closed form (cos/sin about a stable axis, cosh/sinh about the middle one);
/// M stays μe_k for every I, so ∂M/∂I = 0.
fn uniform_tangent(inertia: &[f64; 3], m0: &Vector3<f64>, t: f64) -> (Matrix3<f64>, Matrix3<f64>) {
    let mut jac = Matrix3::identity();
    let mut par = Matrix3::zeros();
    let nonzero: Vec<usize> = (0..3).filter(|&k| m0[k] != 0.0).collect();
    let (lo, hi) = (
        inertia.iter().copied().fold(f64::INFINITY, f64::min),
        inertia.iter().copied().fold(0.0, f64::max),
    );
    if nonzero.is_empty() {
        return (jac, par);
    }
    if (hi - lo).abs() <= 1e-14 * hi || nonzero.len() != 1 {
        // A sphere (the only uniform motion with more than one nonzero component).
        for q in 0..3 {
            let mut dw = Vector3::zeros();
            dw[q] = -m0[q] / (inertia[q] * inertia[q]);
            par.set_column(q, &(m0.cross(&dw) * t));
        }
        return (jac, par);
    }
    let k = nonzero[0];
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let mu = m0[k];
    let alpha = mu * (1.0 / inertia[k] - 1.0 / inertia[j]);
    let beta = mu * (1.0 / inertia[i] - 1.0 / inertia[k]);
    let kappa = alpha * beta;
    let (c, s) = if kappa < 0.0 {
        let w = (-kappa).sqrt();
        ((w * t).cos(), (w * t).sin() / w)
    } else if kappa > 0.0 {
        let w = kappa.sqrt();
        ((w * t).cosh(), (w * t).sinh() / w)
    } else {
        (1.0, t)
    };
    jac[(i, i)] = c;
    jac[(j, j)] = c;
    jac[(i, j)] = alpha * s;
    jac[(j, i)] = beta * s;
    (jac, par)
}

/// The constants of the motion from M₀ (principal frame, finite): a closed form (M = 0, a
/// sphere, a symmetric body, a steady rotation) or an elliptic orbit. Moments equal to 1e-14
/// (relative) count as equal.
fn shape(inertia: &[f64; 3], m0: &Vector3<f64>) -> Shape {
    let uniform = |w: Vector3<f64>| Shape::Closed(Kind::Uniform(w));
    let omega = Vector3::from_fn(|i, _| m0[i] / inertia[i]);
    if m0.amax() == 0.0 {
        return uniform(Vector3::zeros());
    }
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| inertia[a].total_cmp(&inertia[b]));
    let (lo, mid, hi) = (idx[0], idx[1], idx[2]);
    let (ilo, imid, ihi) = (inertia[lo], inertia[mid], inertia[hi]);
    let eq = |a: f64, b: f64| (a - b).abs() <= 1e-14 * a.max(b);
    if eq(ilo, ihi) {
        return uniform(omega);
    }
    if eq(ilo, imid) || eq(imid, ihi) {
        // Symmetric top: H = ½|M|²/I_o + ½ M_s²(1/I_s − 1/I_o), a uniform rotation about e_s.
        let (s, io) = if eq(ilo, imid) { (hi, ilo) } else { (lo, ihi) };
        return Shape::Closed(Kind::Symmetric {
            s,
            w: m0[s] * (1.0 / inertia[s] - 1.0 / io),
            inv_io: 1.0 / io,
        });
    }
    // Scale-free from here on (the orbit's shape does not depend on |M|, the frequency is
    // proportional to it), so no square below can overflow or underflow for a finite M0.
    let scale = m0.amax();
    let y = m0 / scale;
    // e₂ = 2H·I_mid − |M|² = Σ_k M_k² (I_mid − I_k)/I_k = A² − B² = (A − B)(A + B) with
    // A = |M_lo| √((I_mid − I_lo)/I_lo), B = |M_hi| √((I_hi − I_mid)/I_hi): the middle term
    // vanishes and the other two have fixed signs, so e₂ is formed from the components without
    // the cancellation of the invariants (error ~ ulp(A², B²), not ulp(|M|²)). Its sign says
    // which side of the separatrix M0 lies on; e₂ = 0 (A = B) is the separatrix itself.
    let ea = y[lo].abs() * ((imid - ilo) / ilo).sqrt();
    let eb = y[hi].abs() * ((ihi - imid) / ihi).sqrt();
    // Axes (p, mid, s): s carries dn, |M|²/2H lies between I_mid and I_s (e₂ ≥ 0 ⇔ s = lo).
    let (p, s) = if ea >= eb { (hi, lo) } else { (lo, hi) };
    let perm = [p, mid, s];
    // Sign of the permutation: cyclic ⇔ even. Flip the middle component if odd (proper rotation).
    let even = (perm[1] + 3 - perm[0]) % 3 == 1;
    let sg = if even { 1.0 } else { -1.0 };
    let (y1, y2, y3) = (y[p], sg * y[mid], y[s]);
    if y1 == 0.0 && (y2 == 0.0 || y3 == 0.0) {
        return uniform(omega); // steady rotation about the s axis or the middle axis
    }
    let (i1, i2, i3) = (inertia[p], inertia[mid], inertia[s]);
    // Ratios of the moment differences, all positive since I₂ lies between I₁ and I₃:
    // g = d₂₃/d₁₃, h = d₁₂/d₁₃ with d_ij = 1/I_i − 1/I_j = (I_j − I_i)/(I_i I_j).
    let g = i1 * (i3 - i2) / (i2 * (i3 - i1));
    let h = i3 * (i2 - i1) / (i2 * (i3 - i1));
    let d13 = (i3 - i1) / (i1 * i3);
    // Amplitudes from the two conservation laws, each a sum of positive terms:
    // a₁² = M₁² + g M₂² (M₁ at M₂ = 0), a₂² = M₂² + M₁²/g (M₂ at M₁ = 0),
    // a₃² = M₃² + h M₂² (M₃ at M₂ = 0).
    let a1 = y1.hypot(g.sqrt() * y2);
    let a2 = y2.hypot(y1 / g.sqrt());
    let a3 = y3.hypot(h.sqrt() * y2);
    // m = k² = h a₂²/a₃², and its complement directly, as the complementary modulus
    // k′ = √(1 − m) = √(e₂ I₃/(I₂ − I₃)) / a₃ (1 − m = (M₃² − M₁² d₁₂/d₂₃)/a₃², and
    // M₃² d₂₃ − M₁² d₁₂ = −e₂/I₂), as a product of square roots: no square that could underflow
    // (1 − m ~ (M_lo/M_mid)² may lie below the least double near the middle axis).
    let m = (h * (a2 / a3) * (a2 / a3)).min(1.0);
    let kp =
        ((ea - eb).abs().sqrt() * (ea + eb).sqrt() * (i3 / (i2 - i3)).abs().sqrt() / a3).min(1.0);
    // M₁ = σ a₁ cn u, M₂ = a₂ sn u, M₃ = ε a₃ dn u with σ = sign M₁, ε = sign M₃ (both signs fixed
    // on the separatrix; elsewhere σ = −1 is the same solution shifted by 2K), u = u₀ + λt,
    // λ = σε a₁a₃ d₁₃ / a₂ = σε a₃ d₁₃ √g (from Ṁ₂ = d₁₃ M₁M₃), and u₀ ∈ [−K, K] from
    // sn u₀ = M₂/a₂, cn u₀ = |M₁|/a₁, dn u₀ = |M₃|/a₃ directly (no amplitude angle, no m).
    let sigma = if y1 >= 0.0 { 1.0 } else { -1.0 };
    let eps = if y3 >= 0.0 { 1.0 } else { -1.0 };
    let lambda = sigma * eps * a3 * d13 * g.sqrt() * scale;
    let (sn0, cn0, dn0) = (
        (y2 / a2).clamp(-1.0, 1.0),
        (y1.abs() / a1).min(1.0),
        (y3.abs() / a3).min(1.0),
    );
    // The attitude (module docs): the polar axis with ν ≤ 1.
    let nu_s = i3 * (i2 - i1) / (i1 * (i3 - i2));
    let polar_s = nu_s <= 1.0;
    let (waxes, wsign, nu, ia, ib) = if polar_s {
        ([p, mid, s], [1.0, sg, 1.0], nu_s, i3, i1)
    } else {
        ([mid, s, p], [sg, 1.0, 1.0], (a1 / a3) * (a1 / a3), i1, i3)
    };
    let norm = (y1 * y1 + y2 * y2 + y3 * y3).sqrt();
    Shape::Elliptic(Orbit {
        axes: perm,
        amp: [sigma * a1, sg * a2, eps * a3],
        scale,
        lambda,
        kp,
        m,
        jac0: (sn0, cn0, dn0),
        waxes,
        wsign,
        nu,
        ia,
        ib,
        norm,
        coef: if polar_s { 1.0 } else { -1.0 } * sigma * eps * norm / (a3 * g.sqrt()),
    })
}

impl Orbit {
    /// u₀ = F(sn₀, cn₀, dn₀) from (sn₀, cn₀, dn₀) read off M₀, and (sn, cn, dn)(u₀).
    fn base(&self) -> (f64, (f64, f64, f64)) {
        let (sn0, cn0, dn0) = self.jac0;
        let u0 = elliptic::ellipf_from_jacobi(sn0, cn0, dn0);
        (u0, elliptic::ellipj_kprime_unchecked(u0, self.kp, self.m))
    }

    /// M(t) = M₀ + amp·((cn, sn, dn)(u) − (cn, sn, dn)(u₀))·scale (principal frame) from
    /// (sn, cn, dn) at u and at the base point u₀.
    #[inline]
    fn relative_momentum(
        &self,
        m0: &Vector3<f64>,
        (sn, cn, dn): (f64, f64, f64),
        (sn0, cn0, dn0): (f64, f64, f64),
    ) -> Vector3<f64> {
        let mut m = *m0;
        for (w, d) in [cn - cn0, sn - sn0, dn - dn0].into_iter().enumerate() {
            let i = self.axes[w];
            m[i] += self.amp[w] * d * self.scale;
        }
        m
    }

    /// M in units of `scale` (principal frame) from (sn, cn, dn)(u).
    #[inline]
    fn momentum(&self, (sn, cn, dn): (f64, f64, f64)) -> Vector3<f64> {
        let mut y = Vector3::zeros();
        y[self.axes[0]] = self.amp[0] * cn;
        y[self.axes[1]] = self.amp[1] * sn;
        y[self.axes[2]] = self.amp[2] * dn;
        y
    }

    /// W, the coordinates with the polar axis third, of a (scaled) momentum.
    #[inline]
    fn polar(&self, y: &Vector3<f64>) -> Vector3<f64> {
        Vector3::from_fn(|i, _| self.wsign[i] * y[self.waxes[i]])
    }

    /// S = B₀ᵀ Z(φ) B(W(y)) in the principal frame, from `b0t` = B₀ᵀ (polar coordinates).
    #[inline]
    fn relative(&self, b0t: &Matrix3<f64>, phi: f64, y: &Vector3<f64>) -> Matrix3<f64> {
        let b = body_frame(&self.polar(y));
        let (sp, cp) = crate::numerics::angle::angle_sin_cos(phi);
        // Z(φ) B: rows c b₁ − s b₂, s b₁ + c b₂, b₃.
        let mut zb = b;
        for j in 0..3 {
            zb[(0, j)] = cp * b[(0, j)] - sp * b[(1, j)];
            zb[(1, j)] = sp * b[(0, j)] + cp * b[(1, j)];
        }
        let sw = b0t * zb;
        let mut s = Matrix3::zeros();
        for a in 0..3 {
            for c in 0..3 {
                s[(self.waxes[a], self.waxes[c])] = self.wsign[a] * self.wsign[c] * sw[(a, c)];
            }
        }
        s
    }

    /// S(τ) over a short step by the addition theorems (A&S 16.17.1–3) from (sn, cn, dn)(u₀),
    /// read off M₀, and (sn, cn, dn)(λτ), with Π̃(u) − Π̃(u₀) = λτ − (ν/3)(sn³u R_J(u) −
    /// sn³u₀ R_J(u₀)) (both in [−K, K], where F(am u) = u): no u₀, K, reduction or base point.
    /// None where it does not apply or would lose accuracy: |λτ| > ½, k′ < 0.05 (the sums of
    /// the addition theorem lose the relative accuracy of cn and dn near the separatrix, which
    /// R_J needs), or u leaving [−K, K] (cn u < 0).
    fn short_step(&self, tau: f64) -> Option<Matrix3<f64>> {
        let d = self.lambda * tau;
        if !(d.abs() <= 0.5 && self.kp >= 0.05) {
            return None;
        }
        let (s1, c1, d1) = self.jac0;
        let (s2, c2, d2) = elliptic::landen(d.abs(), self.kp, self.m);
        let s2 = s2.copysign(d);
        let den = 1.0 - self.m * (s1 * s2) * (s1 * s2);
        let sn = (s1 * c2 * d2 + s2 * c1 * d1) / den;
        let cn = (c1 * c2 - s1 * d1 * (s2 * d2)) / den;
        let dn = (d1 * d2 - self.m * s1 * c1 * (s2 * c2)) / den;
        if cn < 0.0 {
            return None;
        }
        let nu = self.nu;
        let rj = |sn: f64, cn: f64, dn: f64| {
            sn * sn * sn * elliptic::rj_from_roots(cn, dn, 1.0, (1.0 + nu * sn * sn).sqrt())
        };
        let dpi = d - nu / 3.0 * (rj(sn, cn, dn) - rj(s1, c1, d1));
        let phi = self.norm * self.scale * tau / self.ia + self.coef * dpi;
        let b0t = body_frame(&self.polar(&self.momentum(self.jac0))).transpose();
        Some(self.relative(&b0t, phi, &self.momentum((sn, cn, dn))))
    }
}

/// S(τ) = R₀ᵀR(τ) of the free motion from M₀ (principal frame), for a step of the heavy-top
/// splittings, as it acts on body vectors x ↦ Sᵀx (M, Γ, the rows of R).
pub(crate) enum Relative {
    /// The closed forms (a symmetric body, a uniform rotation): Sᵀx = the turn exp(−v̂)x
    /// (v = τM₀/I_o, or τω) followed by the rotation about e_s by −θ, each by increments
    /// (`so3::Rodrigues`, `top::rotate_axis_sc`). A matrix S would be orthogonal only to ~ε, and
    /// for a symmetric body its defect is nearly the same at every step (the Lagrange top's |Γ|²
    /// and M·Γ drifted linearly with `exact_splitting`). The turn leaves M itself fixed (v ∥ M).
    Closed {
        turn: so3::Rodrigues,
        /// (s, θ): the rotation about e_s by −θ, as (s, sin θ, cos θ − 1).
        spin: Option<(usize, f64, f64)>,
    },
    /// The elliptic motion: [`Orbit::short_step`] where it applies, else [`FreeFlow::motion`].
    Matrix(Matrix3<f64>),
}

impl Relative {
    /// x ↦ Sᵀx for a body vector other than M (Γ, a row of R).
    #[inline]
    pub(crate) fn apply(&self, x: &mut Vector3<f64>) {
        match self {
            Relative::Closed { turn, spin } => {
                turn.apply(x);
                if let Some((k, s, cm1)) = *spin {
                    top::rotate_axis_sc(x, k, s, cm1);
                }
            }
            Relative::Matrix(s) => *x = s.transpose() * *x,
        }
    }

    /// M ↦ SᵀM (R M conserved).
    #[inline]
    pub(crate) fn apply_momentum(&self, m: &mut Vector3<f64>) {
        match self {
            Relative::Closed { spin, .. } => {
                if let Some((k, s, cm1)) = *spin {
                    top::rotate_axis_sc(m, k, s, cm1);
                }
            }
            Relative::Matrix(s) => *m = s.transpose() * *m,
        }
    }
}

/// The relative attitude S(τ) of the free motion from M₀ (principal frame) over τ ([`Relative`]).
pub(crate) fn relative_attitude(inertia: &[f64; 3], m0: &Vector3<f64>, tau: f64) -> Relative {
    let kind = match shape(inertia, m0) {
        Shape::Closed(Kind::Uniform(w)) => {
            return Relative::Closed {
                turn: so3::Rodrigues::exp(&-(w * tau)),
                spin: None,
            }
        }
        Shape::Closed(Kind::Symmetric { s, w, inv_io }) => {
            let (sin, cm1) = crate::numerics::simd::angle_sin_cosm1(tau * w);
            return Relative::Closed {
                turn: so3::Rodrigues::exp(&-(m0 * (tau * inv_io))),
                spin: Some((s, sin, cm1)),
            };
        }
        Shape::Closed(k) => k,
        Shape::Elliptic(o) => match o.short_step(tau) {
            Some(s) => return Relative::Matrix(s),
            None => Kind::Elliptic(Elliptic::new(o)),
        },
    };
    Relative::Matrix(FreeFlow { m0: *m0, kind }.motion(tau).1)
}

impl Elliptic {
    /// u₀, the secular part and the base point of an orbit.
    fn new(o: Orbit) -> Elliptic {
        let (u0, jac) = o.base();
        let nu = o.nu;
        let (two_k, jk) = if o.kp == 0.0 {
            (f64::INFINITY, nu / (1.0 + nu))
        } else {
            let k = elliptic::ellipk_kprime(o.kp);
            let jk = nu / 3.0 * elliptic::rj_from_roots(0.0, o.kp, 1.0, (1.0 + nu).sqrt()) / k;
            (2.0 * k, jk)
        };
        let mut e = Elliptic {
            o,
            u0,
            two_k,
            jk,
            omega: o.norm * o.scale * (jk / o.ia + (1.0 - jk) / o.ib),
            p0: 0.0,
            b0t: Matrix3::identity(),
            jac0: jac,
        };
        // The base point: the formulas evaluated at t = 0, so that M(0) = M₀, S(0) = I and
        // P(u) − P(u₀) = 0 exactly: the rounding of the formulas cancels in short steps instead
        // of biasing every step the same way.
        e.p0 = e.periodic_at(u0, jac);
        e.b0t = body_frame(&o.polar(&o.momentum(jac))).transpose();
        e
    }
}

impl Elliptic {
    /// M(t) = M₀ + amp·((cn, sn, dn)(u) − (cn, sn, dn)(u₀))·scale (module docs, "Momentum"):
    /// M(0) = M₀ bit for bit.
    #[inline]
    fn momentum(&self, m0: &Vector3<f64>, t: f64) -> Vector3<f64> {
        let u = self.u0 + self.o.lambda * t;
        let jac = elliptic::ellipj_kprime_unchecked(u, self.o.kp, self.o.m);
        self.o.relative_momentum(m0, jac, self.jac0)
    }

    /// M(t) in units of `scale` (principal frame) and (sn, cn, dn)(u).
    #[inline]
    fn scaled(&self, t: f64) -> (Vector3<f64>, (f64, f64, f64)) {
        let u = self.u0 + self.o.lambda * t;
        // k′ carries the parameter near the separatrix (k′ = 0 there: sn = tanh, cn = dn = sech),
        // m near a stable axis.
        let jac = elliptic::ellipj_kprime_unchecked(u, self.o.kp, self.o.m);
        (self.o.momentum(jac), jac)
    }

    /// P(u) from (sn, cn, dn)(u): on the reduced r = u − 2Kj ∈ [−K, K] with sn r = (−1)ʲ sn u,
    /// cn r = |cn u|, dn r = dn u; on the separatrix √ν atan(√ν sn u)/(1 + ν).
    #[inline]
    fn periodic_at(&self, u: f64, (sn, cn, dn): (f64, f64, f64)) -> f64 {
        if self.o.kp == 0.0 {
            return separatrix_periodic(self.o.nu, sn);
        }
        let j = (u / self.two_k).round();
        let r = (-self.two_k).mul_add(j, u);
        let sr = if j.rem_euclid(2.0) == 0.0 { sn } else { -sn };
        periodic(self.o.nu, self.jk, r, sr, cn.abs(), dn)
    }
}

impl Elliptic {
    /// (∂M(t)/∂M₀, ∂M(t)/∂I) on an elliptic orbit: (Df(t), ∂f(t)/∂I) of the elliptic formula f
    /// by the chain rule through the parametrisation (module docs, "Tangent map"; f(0) ≡ M₀, so
    /// this is the derivative of M₀ + f(t) − f(0) as well); NaN on the separatrix (k′ = 0).
    fn tangent(
        &self,
        inertia: &[f64; 3],
        m0: &Vector3<f64>,
        t: f64,
    ) -> (Matrix3<f64>, Matrix3<f64>) {
        let o = &self.o;
        let [p, mid, s] = o.axes;
        let (sigma, sg, eps) = (o.amp[0].signum(), o.amp[1].signum(), o.amp[2].signum());
        let (a1, a2, a3) = (o.amp[0].abs(), o.amp[1].abs(), o.amp[2].abs());
        let y = m0 / o.scale;
        let (y1, y2, y3) = (y[p], sg * y[mid], y[s]);
        // The same g, h, d₁₃ as `shape`.
        let (i1, i2, i3) = (inertia[p], inertia[mid], inertia[s]);
        let g = i1 * (i3 - i2) / (i2 * (i3 - i1));
        let h = i3 * (i2 - i1) / (i2 * (i3 - i1));
        let d13 = (i3 - i1) / (i1 * i3);
        let (sn0, cn0, dn0) = o.jac0;
        let (m, kp2, lambda) = (o.m, o.kp * o.kp, o.lambda);
        let (sn, cn, dn) = elliptic::ellipj_kprime_unchecked(self.u0 + lambda * t, o.kp, m);
        // Q = (G(u₀) − G(u) − sn₀cn₀/dn₀)/(2k′²), G = F − D = (E − k′²F)/m.
        let q = (self.d_increment(t, (sn, cn, dn)) - lambda * t - sn0 * cn0 / dn0) / (2.0 * kp2);
        let one = |dy: &Vector3<f64>, dg: f64, dh: f64, dd13: f64| {
            let (dy1, dy2, dy3) = (dy[p], sg * dy[mid], dy[s]);
            let da1sq = 2.0 * y1 * dy1 + 2.0 * g * y2 * dy2 + y2 * y2 * dg;
            let da2sq = 2.0 * y2 * dy2 + 2.0 * y1 * dy1 / g - y1 * y1 * dg / (g * g);
            let da3sq = 2.0 * y3 * dy3 + 2.0 * h * y2 * dy2 + y2 * y2 * dh;
            let dm = (dh * a2 * a2 + h * da2sq - m * da3sq) / (a3 * a3);
            let dlam = lambda * (da3sq / (2.0 * a3 * a3) + dd13 / d13 + dg / (2.0 * g));
            let dphi0 = cn0 * dy2 / a2 - sigma * sn0 * dy1 / a1 + sn0 * cn0 * dg / (2.0 * g);
            let w = dphi0 / dn0 + t * dlam + q * dm;
            let c = dm / (2.0 * kp2);
            let dphi = dn * w + sn * cn * c;
            let ddn = -m * sn * cn * w - sn * sn * dn * c;
            let mut out = Vector3::zeros();
            out[p] = sigma * da1sq / (2.0 * a1) * cn - o.amp[0] * sn * dphi;
            out[mid] = sg * da2sq / (2.0 * a2) * sn + o.amp[1] * cn * dphi;
            out[s] = eps * da3sq / (2.0 * a3) * dn + o.amp[2] * ddn;
            out
        };
        let mut jac = Matrix3::zeros();
        for c in 0..3 {
            let mut e = Vector3::zeros();
            e[c] = 1.0;
            jac.set_column(c, &one(&e, 0.0, 0.0, 0.0));
        }
        // ∂(g, d₁₃)/∂(I₁, I₂, I₃) in the working axes (h = 1 − g).
        let den = (i3 - i1) * (i3 - i1);
        let dg = [
            (i3 - i2) / i2 * i3 / den,
            -i1 / (i3 - i1) * i3 / (i2 * i2),
            i1 / i2 * (i2 - i1) / den,
        ];
        let dd = [-1.0 / (i1 * i1), 0.0, 1.0 / (i3 * i3)];
        let mut par = Matrix3::zeros();
        for (w, &axis) in o.axes.iter().enumerate() {
            let col = one(&Vector3::zeros(), dg[w], -dg[w], dd[w]) * o.scale;
            par.set_column(axis, &col);
        }
        (jac, par)
    }
}

impl Elliptic {
    /// D(u) − D(u₀) at u = u₀ + λt from (sn, cn, dn)(u), D = (F − E)/m = ∫₀ᵘ sn² along the
    /// continued amplitude: D(r) + 2j D(K) on the reduced r = u − 2Kj (module docs).
    fn d_increment(&self, t: f64, (sn, cn, dn): (f64, f64, f64)) -> f64 {
        let dfun = |sn: f64, cn: f64, dn: f64| {
            sn * sn * sn * elliptic::rd_kernel(cn * cn, dn * dn, 1.0) / 3.0
        };
        let u = self.u0 + self.o.lambda * t;
        let j = (u / self.two_k).round();
        let sr = if j.rem_euclid(2.0) == 0.0 { sn } else { -sn };
        let dc = elliptic::rd_kernel(0.0, self.o.kp * self.o.kp, 1.0) / 3.0;
        let (sn0, cn0, dn0) = self.o.jac0;
        dfun(sr, cn.abs(), dn) + 2.0 * j * dc - dfun(sn0, cn0, dn0)
    }
}

impl FreeFlow {
    /// X_q = ∫₀ᵗ M_q(s)² ds (principal frame): M₀² t for a uniform motion; for a symmetric body
    /// (M_i = cos θ M⁰_i + sin θ M⁰_j, θ = ws) ½t[(1 ± sinc 2wt)…] ± M⁰_iM⁰_j t sin(wt) sinc(wt);
    /// on an elliptic orbit (a₁² cn², a₂² sn², a₃² dn² in the working axes) from
    /// ∫sn² du = D(u) − D(u₀), ∫cn² = Δu − ΔD, ∫dn² = Δu − mΔD.
    fn square_integrals(&self, t: f64) -> Vector3<f64> {
        let m0 = &self.m0;
        match &self.kind {
            Kind::Uniform(_) => m0.component_mul(m0) * t,
            Kind::Symmetric { s, w, .. } => {
                let (s, i, j) = (*s, (*s + 1) % 3, (*s + 2) % 3);
                let th = t * w;
                let sinc = |x: f64| if x == 0.0 { 1.0 } else { x.sin() / x };
                let (c2, cross) = (sinc(2.0 * th), t * th.sin() * sinc(th) * m0[i] * m0[j]);
                let (pi, pj) = (m0[i] * m0[i], m0[j] * m0[j]);
                let mut x = Vector3::zeros();
                x[i] = 0.5 * t * ((1.0 + c2) * pi + (1.0 - c2) * pj) + cross;
                x[j] = 0.5 * t * ((1.0 + c2) * pj + (1.0 - c2) * pi) - cross;
                x[s] = m0[s] * m0[s] * t;
                x
            }
            Kind::Elliptic(e) => {
                let o = &e.o;
                let (_, jac) = e.scaled(t);
                let dd = e.d_increment(t, jac) / o.lambda;
                let mut x = Vector3::zeros();
                let sq = |a: f64| a * a * o.scale * o.scale;
                x[o.axes[0]] = sq(o.amp[0]) * (t - dd);
                x[o.axes[1]] = sq(o.amp[1]) * dd;
                x[o.axes[2]] = sq(o.amp[2]) * (t - o.m * dd);
                x
            }
        }
    }

    /// The left-trivialised direction σ of S(t) (S⁻¹δS = σ̂) along (δM₀, δI), from M(t), S(t),
    /// δM(t) (`momentum_tangent`) and X = `square_integrals`: |M|² is kept, so
    /// δM(t) = −σ × M(t) + S(t)ᵀδM₀ fixes σ ⊥ M; along M, d/dt(σ·M) = δΩ·M
    /// = δH₀ − ½Σ_q δI_q M_q²/I_q² (δH = Ω·δM − ½Σ δI_q M_q²/I_q² is conserved), so
    /// σ·M(t) = t δH₀ − ½ Σ_q δI_q X_q/I_q². At M = 0: σ = t I⁻¹δM₀.
    #[allow(clippy::too_many_arguments)]
    fn attitude_tangent(
        &self,
        inertia: &[f64; 3],
        t: f64,
        (m, s): (&Vector3<f64>, &Matrix3<f64>),
        x: &Vector3<f64>,
        dm0: &Vector3<f64>,
        di: &Vector3<f64>,
        dm: &Vector3<f64>,
    ) -> Vector3<f64> {
        let inv = Vector3::from_fn(|q, _| 1.0 / inertia[q]);
        let n2 = m.norm_squared();
        if n2 == 0.0 {
            return dm0.component_mul(&inv) * t;
        }
        let m0 = &self.m0;
        let w = Vector3::from_fn(|q, _| di[q] * inv[q] * inv[q]);
        let dh0 = m0.component_mul(&inv).dot(dm0) - 0.5 * w.dot(&m0.component_mul(m0));
        let along = t * dh0 - 0.5 * w.dot(x);
        let v = s.transpose() * dm0 - dm;
        (m.cross(&v) + m * along) / n2
    }
}

/// The tangent map of the free motion from M₀ at t, once per (M₀, t): S(t), M(t) = S(t)ᵀM₀,
/// Dφ_t, ∂M(t)/∂I and the square integrals, for [`FreeTangent::apply`] (the free body's
/// `exact`, the heavy top's exact splittings, the frame tops).
pub(crate) struct FreeTangent {
    flow: FreeFlow,
    pub(crate) m: Vector3<f64>,
    pub(crate) s: Matrix3<f64>,
    jac: Matrix3<f64>,
    par: Matrix3<f64>,
    x: Vector3<f64>,
    inertia: [f64; 3],
    t: f64,
}

impl FreeTangent {
    /// At t along `flow` (built from the moments `inertia`).
    pub(crate) fn of(flow: &FreeFlow, inertia: &[f64; 3], t: f64) -> FreeTangent {
        let (m, s) = flow.motion(t);
        let (jac, par) = flow.momentum_tangent(inertia, t);
        FreeTangent {
            flow: flow.clone(),
            m,
            s,
            jac,
            par,
            x: flow.square_integrals(t),
            inertia: *inertia,
            t,
        }
    }

    /// At t from M₀ for the moments `inertia`.
    pub(crate) fn new(inertia: &[f64; 3], m0: &Vector3<f64>, t: f64) -> FreeTangent {
        FreeTangent::of(&FreeFlow::new(inertia, m0), inertia, t)
    }

    /// S(t)ᵀv.
    pub(crate) fn turn(&self, v: &Vector3<f64>) -> Vector3<f64> {
        self.s.transpose() * v
    }

    /// (δM(t), σ) along (δM₀, δt): a change of the flow's time adds δt (M × Ω, Ω) with
    /// Ω = 𝕀⁻¹M(t) (Euler's equation, and Ṡ = SΩ̂).
    pub(crate) fn apply_timed(&self, dm0: &Vector3<f64>, dt: f64) -> (Vector3<f64>, Vector3<f64>) {
        let (dm, sigma) = self.apply(dm0, None);
        let omega = Vector3::from_fn(|q, _| self.m[q] / self.inertia[q]);
        (dm + self.m.cross(&omega) * dt, sigma + omega * dt)
    }

    /// (δM(t), σ) of the direction δM₀ (and, for `moment` = Some(q), of ∂/∂I_q added): the
    /// momentum's and the attitude's (δS = Sσ̂) directions (module docs, "With the attitude").
    pub(crate) fn apply(
        &self,
        dm0: &Vector3<f64>,
        moment: Option<usize>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let flow = &self.flow;
        let mut dm = self.jac * dm0;
        let mut di = Vector3::zeros();
        if let Some(q) = moment {
            dm += self.par.column(q);
            di[q] = 1.0;
        }
        let sigma = flow.attitude_tangent(
            &self.inertia,
            self.t,
            (&self.m, &self.s),
            &self.x,
            dm0,
            &di,
            &dm,
        );
        (dm, sigma)
    }
}

/// P(r) = (1 − q) r − (ν/3) sn³r R_J(cn²r, dn²r, 1, 1 + ν sn²r) for |r| ≤ K, from sn r, cn r ≥ 0
/// and dn r (module docs); `jk` = 1 − q.
#[inline]
fn periodic(nu: f64, jk: f64, r: f64, sn: f64, cn: f64, dn: f64) -> f64 {
    let s2 = sn * sn;
    jk * r - nu / 3.0 * (s2 * sn) * elliptic::rj_from_roots(cn, dn, 1.0, (1.0 + nu * s2).sqrt())
}

/// P(u) = √ν atan(√ν tanh u)/(1 + ν) on the separatrix (sn u = tanh u).
#[inline]
fn separatrix_periodic(nu: f64, sn: f64) -> f64 {
    let r = nu.sqrt();
    r * (r * sn).atan() / (1.0 + nu)
}

/// B(W): rows b₁ = b₂ × b₃, b₂ = (W₂, −W₁, 0)/ρ, b₃ = W/|W| (ρ = √(W₁² + W₂²) > 0), the rotation
/// exp(θê₂) exp(ψê₃) that takes W to |W|e₃ (module docs). W is of order one (scaled).
#[inline]
fn body_frame(w: &Vector3<f64>) -> Matrix3<f64> {
    let rho = w[0].hypot(w[1]);
    let mu = rho.hypot(w[2]);
    let (c1, c2, c3) = (w[0] / rho, w[1] / rho, w[2] / mu);
    let st = rho / mu;
    Matrix3::new(
        -c1 * c3,
        -c2 * c3,
        st, //
        c2,
        -c1,
        0.0, //
        c1 * st,
        c2 * st,
        c3,
    )
}

/// The exact flow of the free rigid body as a method (catalog name `exact`): each step is the
/// exact flow over dt, evaluated from the state last handed to the stepper (the start of the run,
/// or the last retraction of R, every [`crate::integrate::RETRACT_EVERY`] steps) at the time
/// k·dt of the steps since, so that round-off does not accumulate step by step and the result
/// does not depend on how a run is cut into chunks. Properties: [`crate::integrate::Properties::exact`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Exact;

impl Exact {
    /// The stepper for a free body `top` (M, or (M, R) when lifted).
    pub(crate) fn stepper_for(&self, top: &Top, dt: f64) -> Box<dyn Stepper> {
        Box::new(ExactStepper {
            moments: top.moments,
            lifted: top.lifted,
            dt,
            flow: None,
            r_ref: Matrix3::identity(),
            steps: 0,
            m: Vector3::zeros(),
            r: Matrix3::identity(),
        })
    }
}

struct ExactStepper {
    moments: [f64; 3],
    lifted: bool,
    dt: f64,
    /// The motion from the reference state (None before `set`).
    flow: Option<FreeFlow>,
    r_ref: Matrix3<f64>,
    /// Steps since the reference state.
    steps: u64,
    m: Vector3<f64>,
    r: Matrix3<f64>,
}

impl Stepper for ExactStepper {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.m = Vector3::from_column_slice(&z[..3]);
        check::finite_slice("state", self.m.as_slice())?;
        if self.lifted {
            self.r = Matrix3::from_row_slice(&z[3..12]);
            self.r_ref = self.r;
        }
        self.flow = Some(FreeFlow::new(&self.moments, &self.m));
        self.steps = 0;
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        z[..3].copy_from_slice(self.m.as_slice());
        if self.lifted {
            z[3..12].copy_from_slice(&top::row_major(&self.r));
        }
    }

    fn advance(&mut self, steps: usize, _clock: Clock) -> Result<()> {
        let Some(flow) = &self.flow else {
            return Ok(());
        };
        if steps == 0 {
            return Ok(());
        }
        self.steps += steps as u64;
        let t = self.steps as f64 * self.dt;
        if self.lifted {
            let (m, s) = flow.motion(t);
            self.m = m;
            self.r = self.r_ref * s;
        } else {
            self.m = flow.momentum(t);
        }
        Ok(())
    }
}

impl Exact {
    /// The stepper of the tangent lift of a free body without attitude, state (M, δM₁, …,
    /// δM_k) with k = 3 + 3 (the directions of M₀ and of I₁, I₂, I₃): like [`ExactStepper`],
    /// every step is evaluated from the state last handed to it at the time t = k·dt since, M
    /// by the same [`FreeFlow::momentum`] (the same bits as the plain run) and each direction
    /// by the exact tangent map, δM(t) = Dφ_t δM_ref (+ ∂M(t)/∂I_q for the parameter q's).
    /// With the attitude (state (M, R), directions (δM, ξ), δR = Rξ̂): R(t) = R_ref S(t) as
    /// the plain run's, ξ(t) = S(t)ᵀξ_ref + σ (`FreeFlow::attitude_tangent`).
    pub(crate) fn tangent_stepper_for(&self, top: &Top, dt: f64) -> Box<dyn Stepper> {
        Box::new(ExactTangentStepper {
            moments: top.moments,
            lifted: top.lifted,
            dt,
            flow: None,
            steps: 0,
            r_ref: Matrix3::identity(),
            z_ref: Vec::new(),
            z: Vec::new(),
        })
    }
}

struct ExactTangentStepper {
    moments: [f64; 3],
    lifted: bool,
    dt: f64,
    flow: Option<FreeFlow>,
    steps: u64,
    r_ref: Matrix3<f64>,
    /// The lifted state handed to `set` and the current one.
    z_ref: Vec<f64>,
    z: Vec<f64>,
}

impl Stepper for ExactTangentStepper {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        let m = Vector3::from_column_slice(&z[..3]);
        check::finite_slice("state", m.as_slice())?;
        self.z_ref.clear();
        self.z_ref.extend_from_slice(z);
        self.z.clone_from(&self.z_ref);
        if self.lifted {
            self.r_ref = Matrix3::from_row_slice(&z[3..12]);
        }
        self.flow = Some(FreeFlow::new(&self.moments, &m));
        self.steps = 0;
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        // Nothing before `set`.
        if self.z.len() == z.len() {
            z.copy_from_slice(&self.z);
        }
    }

    fn advance(&mut self, steps: usize, _clock: Clock) -> Result<()> {
        let Some(flow) = &self.flow else {
            return Ok(());
        };
        if steps == 0 {
            return Ok(());
        }
        self.steps += steps as u64;
        let t = self.steps as f64 * self.dt;
        if !self.lifted {
            let (jac, par) = flow.momentum_tangent(&self.moments, t);
            self.z[..3].copy_from_slice(flow.momentum(t).as_slice());
            let dirs = self.z_ref[3..]
                .chunks_exact(3)
                .zip(self.z[3..].chunks_exact_mut(3));
            for (j, (from, to)) in dirs.enumerate() {
                let mut d = jac * Vector3::from_column_slice(from);
                if j >= 3 {
                    d += par.column(j - 3);
                }
                to.copy_from_slice(d.as_slice());
            }
            return Ok(());
        }
        let ft = FreeTangent::of(flow, &self.moments, t);
        self.z[..3].copy_from_slice(ft.m.as_slice());
        self.z[3..12].copy_from_slice(&top::row_major(&(self.r_ref * ft.s)));
        let dirs = self.z_ref[12..]
            .chunks_exact(6)
            .zip(self.z[12..].chunks_exact_mut(6));
        for (j, (from, to)) in dirs.enumerate() {
            let dm0 = Vector3::from_column_slice(&from[..3]);
            let (dm, sigma) = ft.apply(&dm0, j.checked_sub(6));
            let xi = ft.s.transpose() * Vector3::from_column_slice(&from[3..]) + sigma;
            to[..3].copy_from_slice(dm.as_slice());
            to[3..].copy_from_slice(xi.as_slice());
        }
        Ok(())
    }
}

/// The splitting of the heavy top H = T(M) + V(Γ) into the exact free flow of T (M by the
/// exact flow, Γ ↦ S(τ)ᵀΓ, R ↦ R S(τ)) and the kick of V (M ↦ M + τ Γ × c), with the
/// composition's weights (catalog names `exact_splitting`, `exact_splitting4`,
/// `exact_splitting6`: Strang, Suzuki 4, Yoshida 6). One free flow per stage (the kicks of
/// consecutive stages fuse); Poisson, symplectic with R, keeps |Γ|² and M·Γ to round-off.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactSplitting(pub Composition);

#[cfg(test)]
mod tests {
    use super::*;

    /// The separatrix branch is taken where e₂ vanishes exactly: I = (1, 1.25, 1.953125) has
    /// √((I₂ − I₁)/I₁) = 0.5 and √((I₃ − I₂)/I₃) = 0.6 (to rounding), and M = (0.6, 1, 0.5) lies
    /// on the separatrix (0.6·0.5 = 0.5·0.6); the tests of `tests/rigid_body_exact.rs` compare
    /// this motion with RK4.
    /// The short step (addition theorems, no reduction) and the general evaluation agree, on
    /// both sides of the separatrix, with both polar axes, forwards and backwards.
    #[test]
    fn short_step_agrees_with_the_motion() {
        let mut worst = 0.0f64;
        let mut used = 0;
        for inertia in [[1.0, 2.0, 3.0], [3.0, 2.9, 1.0], [1.0, 1.5, 4.0]] {
            for k in 0..200 {
                let a = 0.37 * k as f64;
                let m0 = Vector3::new(a.sin() * 2.0, (1.3 * a).cos(), (0.7 * a).sin() - 0.2);
                let tau = 0.3 * ((k % 7) as f64 - 3.0) / 3.0;
                let Shape::Elliptic(o) = shape(&inertia, &m0) else {
                    continue;
                };
                let want = FreeFlow::new(&inertia, &m0).motion(tau).1;
                if let Some(s) = o.short_step(tau) {
                    used += 1;
                    worst = worst.max((s - want).amax());
                }
            }
        }
        assert!(
            used > 300 && worst < 1e-14,
            "{used} steps, max difference {worst:e}"
        );
    }

    /// The tangent map against central differences of the flow in M₀ and in the moments, on
    /// both sides of the separatrix, for a symmetric body and at steady rotations.
    #[test]
    fn momentum_tangent_is_the_flows_derivative() {
        let mut worst = (0.0f64, 0.0f64);
        let cases: Vec<([f64; 3], Vector3<f64>)> = vec![
            ([1.0, 2.0, 3.0], Vector3::new(1.0, 0.3, 0.2)),
            ([1.0, 2.0, 3.0], Vector3::new(0.2, 0.3, -1.0)),
            ([1.0, 2.0, 3.0], Vector3::new(-0.3, 1.0, 0.1)),
            ([3.0, 2.9, 1.0], Vector3::new(0.7, -0.4, 0.9)),
            ([1.0, 1.5, 4.0], Vector3::new(0.1, 1.2, -0.6)),
            ([1.0, 2.0, 2.0], Vector3::new(0.5, -0.4, 0.3)),
            ([3.0, 2.0, 3.0], Vector3::new(0.5, -0.4, 0.3)),
            ([3.0, 2.0, 3.0], Vector3::new(0.5, 0.0, 0.3)),
            ([3.0, 3.0, 1.0], Vector3::new(0.2, 0.7, 0.0)),
            ([1.0, 2.0, 2.0 + 1e-5], Vector3::new(0.5, -0.4, 0.3)),
            ([1.0, 2.0, 3.0], Vector3::new(0.0, 0.0, 1.3)),
            ([1.0, 2.0, 3.0], Vector3::new(0.0, 1.3, 0.0)),
            ([2.0, 2.0, 2.0], Vector3::new(0.4, 0.5, 0.6)),
        ];
        for (inertia, m0) in cases {
            for t in [0.3, 2.0, 7.5, -4.0] {
                let (jac, par) = FreeFlow::new(&inertia, &m0).momentum_tangent(&inertia, t);
                let h = 1e-6;
                let scale = jac.amax().max(1.0);
                for c in 0..3 {
                    let mut e = Vector3::zeros();
                    e[c] = h;
                    let fd = (FreeFlow::momentum_at(&inertia, &(m0 + e), t)
                        - FreeFlow::momentum_at(&inertia, &(m0 - e), t))
                        / (2.0 * h);
                    let err = (jac.column(c) - fd).amax() / scale;
                    assert!(
                        err < 1e-7,
                        "{inertia:?} {m0:?} t {t} column {c}: {err:e}\n{jac}\n{fd}"
                    );
                    worst.0 = worst.0.max(err);
                    let (mut ip, mut im) = (inertia, inertia);
                    ip[c] += h;
                    im[c] -= h;
                    let pc = par.column(c);
                    let fd = (FreeFlow::momentum_at(&ip, &m0, t)
                        - FreeFlow::momentum_at(&im, &m0, t))
                        / (2.0 * h);
                    let err = (pc - fd).amax() / scale;
                    assert!(
                        err < 1e-6,
                        "{inertia:?} {m0:?} t {t} I{c}: {err:e}\n{par}\n{fd}"
                    );
                    worst.1 = worst.1.max(err);
                }
            }
        }
        eprintln!(
            "tangent vs differences: M₀ {:.1e}, I {:.1e}",
            worst.0, worst.1
        );
    }

    #[test]
    fn separatrix_branch() {
        let f = FreeFlow::new(&[1.0, 1.25, 1.953125], &Vector3::new(0.6, 1.0, 0.5));
        match f.kind {
            Kind::Elliptic(e) => assert_eq!(e.o.kp, 0.0, "k′ = {}", e.o.kp),
            k => panic!("{k:?}"),
        }
    }
}
