//! 002 §IV: the relativistic tangent Euler top in Minkowski space-time and on a curved static
//! space-time −dt² + γ_ij dxⁱdxʲ over a surface ([`RelativisticTangentTop`], 002 (87)–(111)), and
//! in the weak-field limit of a static gravitational potential φ(x, y) ([`WeakFieldTop`],
//! 002 (115)–(120)).
//!
//! # Set-up (002 (81)–(82))
//! A planar body with mass distribution dm(ξ), centre of mass at ξ = 0, second-moment tensor
//! I = ∫ ξ ξᵀ dm (2×2; 𝕀 = tr I as in 002 (42); a symmetric top has I = (𝕀/2)·Id). Its frame is
//! E_i = S_ji Ê_j with S = R(θ) the rotation by θ (E₁ = cos θ Ê₁ + sin θ Ê₂, as in 002 (41)), and
//! time is that of a distant static observer (E₀ = ∂_t normalised). Definition IV.1 (002 (82)):
//! the Lagrangian is the integral over the body of √|⟨ċ + ξⁱ∇_ċE_i, ċ + ξʲ∇_ċE_j⟩|, expanded to
//! second order in ξ (odd orders integrate to zero).
//!
//! **Sign convention.** 002 (82)–(118) write L with the sign +m√(1 − v²); here L is the physical
//! action density −∫dτ dm, the negative of the seed's. The Euler–Lagrange equations are the same;
//! momenta and energies change sign: our p_θ and energy are −(seed's), so 002 (96) reads
//! E = +mγ + … here.
//!
//! # Minkowski (002 (87)–(96))
//! With ∇_ċE_i = Ṡ_ji Ê_j and |ċ|² = −1 + |ẋ|², the integrand is
//! √(1 − v² − 2ẋ·Ṡξ − |Ṡξ|²) = √(1−v²) − ẋ·Ṡξ/√(1−v²) − |Ṡξ|²/(2√(1−v²))
//! − (ẋ·Ṡξ)²/(2(1−v²)^{3/2}) + O(ξ³), and with Ṡ = θ̇ J S (J the rotation by π/2),
//! K(θ) = S J I Jᵀ Sᵀ, γ = (1 − v²)^{−1/2}:
//!
//! L(ẋ, θ, θ̇) = −m/γ + ½ θ̇² (𝕀 γ + γ³ ẋᵀK(θ)ẋ),        (002 (90), physical sign)
//!
//! which agrees with 002 (90) (tr(ṠIṠᵀ) = θ̇² 𝕀). **Which variables it depends on:** although
//! (81)–(82) look second order, with E₀ = ∂_t the frame is rotated by S(θ) only, so L depends on
//! (ẋ, θ, θ̇) and not on ẍ: it is a first-order Lagrangian on T(ℝ² × S¹), x is cyclic (p = ∂L/∂ẋ
//! is conserved), and for the symmetric top (K = (𝕀/2) Id) θ is cyclic too. No Ostrogradsky
//! construction is needed; the system is integrated in canonical form with the Hamiltonian
//! H(q, p) = p·q̇ − L, q = (x, y, θ), the velocities q̇(q, p) found by inverting the Legendre map
//! p = ∂L/∂q̇ with Newton's method (the Hessian ∂²L/∂q̇² must be positive definite: it is for
//! slow, slowly spinning tops, and the state check says where it is not).
//!
//! **Symmetric top (002 (93)–(96)).** With I₀ = 𝕀/2 (the seed's I), L = −m/γ + I₀θ̇²γ(1 + ½v²γ²)
//! (002 (93)). The momenta p = (mγ + I₀θ̇²(2γ³ + (3/2)v²γ⁵)) ẋ and
//! J = p_θ = 2I₀θ̇γ(1 + ½v²γ²) are conserved; so (the Legendre map being invertible) ẋ and θ̇ are
//! constant. Eliminating θ̇, with 1 + ½v²γ² = ½(2 − v²)γ² and 2γ² + (3/2)v²γ⁴ = ½(4 − v²)γ⁴,
//!
//! |p| = mγv (1 + J²(1 − v²)(4 − v²) / (2 I₀ m (2 − v²)²)),          (002 (94))
//! θ̇ = J / (2 I₀ γ (1 + ½v²γ²)),                                    (002 (95))
//! E = mγ + I₀θ̇² (γ + (5/2) v²γ³ + (3/2) v⁴γ⁵).                     (002 (96))
//!
//! These agree with the seed once its "J" is read as half the canonical momentum p_θ (its (95)
//! has I where 2I₀ = 𝕀 would stand with J = p_θ; (94) then has 4J² for J²) and the overall sign
//! of (96) is that of its Lagrangian. **Slip:** the seed concludes from (94) that v is fixed by
//! |p| because the left side "is never constant on an interval"; that does not make it
//! injective, and it is not: with κ = J²/(2I₀m) > 7.34 the function v ↦ |p| decreases on an
//! interval below v = 1 (at κ = 10 on about 0.908 < v < 0.976), so one |p| belongs to up to
//! three speeds, and the Legendre map is singular where the slope vanishes. (κ ~ rotational
//! energy over rest energy, far outside the small-body expansion; below the threshold the claim
//! holds.)
//! What makes v constant is the invertibility of the Legendre map along the motion, which
//! [`RelativisticTangentTop`] checks.
//!
//! # Curved static space-time (002 (97)–(111))
//! The metric ds² = −dt² + γ_ij dxⁱdxʲ with γ = g the metric of a [`Surface`] (orthonormal frame
//! Ê_a, connection 1-form w(v) = ⟨∇_vÊ₁, Ê₂⟩ = α·v, see [`crate::systems::tangent_top::surface`]). The lapse is
//! 1, so ∂_t is parallel and no Christoffel symbol carries a t (002 (86)): with ċ = ∂_t + ẋ and
//! E₁ = cos θ Ê₁ + sin θ Ê₂, E₂ = −sin θ Ê₁ + cos θ Ê₂,
//!
//! ∇_ċE₁ = s E₂,  ∇_ċE₂ = −s E₁,   s = θ̇ + α·ẋ   (the covariant spin rate),
//!
//! i.e. in the reference frame ∇_ċE_i = (Ṡ + ΩS)_ji Ê_j with Ω = w(ẋ) J, Ṡ + ΩS = s J S. With the
//! frame components u_a = g(ẋ, Ê_a) of ẋ (|u|² = g(ẋ, ẋ) = v²), the integrand of (82) is
//! √(1 − |u + s J S ξ|²), the Minkowski one with ẋ → u and θ̇ → s. So, to second order in ξ,
//!
//! L = −m/γ + ½ s² (𝕀γ + γ³ uᵀK(θ)u),   γ = (1 − g(ẋ, ẋ))^{−1/2},      (002 (102), physical sign)
//!
//! and for the symmetric top (K = (𝕀/2) Id, uᵀKu = 𝕀v²/2)
//!
//! L = −m/γ + ½ 𝕀 s² (γ + ½ γ³ v²)    (002 (103), physical sign; the L of [`TangentTop`] − m as v → 0).
//!
//! Only the symmetric top is implemented on a surface ([`RelativisticTangentTop::on_surface`]):
//! for an anisotropic body L depends on u = e♭ẋ itself, whose x-derivatives need the derivatives
//! of the frame, which [`Surface`] does not provide (it gives g, ∂g, α, ∂α); the anisotropic top
//! stays in the Minkowski plane ([`RelativisticTangentTop::new`]).
//!
//! **Derivatives** (the kernel of the symmetric top on a surface). With Q = g(ẋ, ẋ),
//! f(Q) = γ + ½Qγ³, f′ = γ³ + ¾Qγ⁵, f″ = (9/4)γ⁵ + (15/8)Qγ⁷, L = −m√(1 − Q) + ½𝕀s²f(Q),
//! λ = ∂L/∂Q = ½mγ + ½𝕀s²f′, σ = ∂L/∂s = 𝕀sf, n = gẋ:
//! p_x = 2λ n + σ α,  p_θ = σ,  ∂L/∂x^k = λ ẋᵀ(∂_k g)ẋ + σ (∂_kα)·ẋ,  ∂L/∂θ = 0,
//! and the Hessian in (ẋ, θ̇) from L_QQ = ¼mγ³ + ½𝕀s²f″, L_Qs = 𝕀sf′, L_ss = 𝕀f.
//!
//! **Conserved.** E = p·q̇ − L = mγ + ½𝕀s²(γ + (5/2)v²γ³ + (3/2)v⁴γ⁵) (002 (96) with θ̇ → s);
//! p_θ = 𝕀 s f(v²) (θ is cyclic); and for every Killing field X of the surface, lifted to
//! (x, θ) as in [`crate::systems::tangent_top::surface`], J = p_A X^A (v², s and so L are invariant under the
//! lifted isometries; [`RelativisticTangentTop::killing_momenta`], computed by
//! [`crate::systems::TangentTop::killing_momenta`]). Since E and p_θ are functions of (v, s) only,
//! v and s are constant along a motion (where (v, s) ↦ (E, p_θ) is locally invertible, as for
//! slow tops; the sphere test checks it), and the x-equation is
//! 2λ g∇_tẋ = σ dw(ẋ, ·): a charge σ = p_θ of mass 2λ = mγ + 𝕀s²f′ in the "magnetic field" −K dA,
//! moving on a curve of geodesic curvature κ = |p_θ K|/(2λ v) (on the sphere: a circle). 002 (94)
//! holds with |p| read as |p_x − p_θ α|_{g⁻¹} = 2λv, and (95), (96) with θ̇ → s.
//!
//! **The seed's (97)–(103)** (checked by the test `curved_lagrangian_is_the_expansion_of_82`
//! against the exact (82) over a ring of mass points on the sphere and on the hyperbolic plane,
//! with ∇_ċE_i computed from the Christoffel symbols of g and the frame, not from α): the
//! structure of (102)–(103) is right (in the seed's sign, L_seed = −L) once the following are read
//! as intended. (97) writes γ_ij dxⁱdxⁱ for γ_ij dxⁱdxʲ; (99)/(101) write ξʲS_jiω_jᵏ for
//! ξⁱS_jiω_jᵏ; the first term of (102) and (103) is m(1 − γ_ij ẋⁱẋʲ), without the square root
//! ((108) restores it: m√(1 − v²)); the matrix ω of (102)–(103) must be read as Ω_kj = ω_jᵏ(ċ)
//! (column j the components of ∇_ċÊ_j, so Ω = w(ẋ) J): with the other index order the cross term
//! 2tr(ṠSᵀωᵀ) flips sign and (103) would give (θ̇ − α·ẋ)², which the ring test rejects; and (103)
//! writes ⟨ċ, E_j⟩ (body frame) where (102) has ⟨ċ, Ê_j⟩ (the same here, the bracket being s² Id
//! for the symmetric top, but not for an anisotropic one). In (103) "I" is the seed's I₀ = 𝕀/2,
//! as in (93). (104)–(114), the frame independence: s = θ̇ + α·ẋ is invariant under Ê → R(χ)Ê
//! (θ → θ − χ, α → α + dχ), and so are v² and L.
//!
//! # Weak field (002 (115)–(120))
//! The static metric is ds² = −e^{2φ(x)} dt² + δ_ij dxⁱdxʲ (**slip corrected:** 002 (115) lacks
//! the dt² of the time-time term and writes ẋ for dx). With E₀ = e^{−φ}∂_t, Γ^t_{ti} = ∂_iφ, so
//! ∇_ċE_i = Ṡ_ji ∂_j + (S_ji G_j) ∂_t, G = ∇φ, and the integrand of (82) is
//! e^{2φ}(1 + G·Sξ)² − |ẋ + Ṡξ|². To second order in ξ, with b = e^{2φ} − v², for a symmetric
//! top (I = I₀ Id) this gives (the physical-sign form of 002 (117))
//!
//! L = −m√b + I₀θ̇²/√b − I₀e^{2φ}|G|²/(2√b)
//!   + I₀(θ̇²v² + 2e^{2φ}θ̇ (G_y ẋ − G_x ẏ) + e^{4φ}|G|²)/(2 b^{3/2}).
//!
//! (The point of the body is moved along ξⁱ∇_ċE_i as (82) prescribes; evaluating φ at x + Sξ
//! instead would add a tidal term ∝ I₀ Δφ.) The weak-field limit, φ, |G| = O(ε²), v = O(ε),
//! θ̇ = O(1), keeping terms to O(ε³) and dropping the constant −m:
//!
//! L = ½ m v² − m φ + I₀ θ̇² (1 − φ + v²) + I₀ θ̇ (G_y ẋ − G_x ẏ).      (002 (118))
//!
//! **Slip:** 002 (118), in the seed's sign (L_seed = −L), carries the coupling term with the
//! opposite sign, +Iθ̇(G_yẋ − G_xẏ); the expansion of 002 (117) itself gives the sign above
//! (its ṠSᵀ should read SṠᵀ = −θ̇J). The test `weak_field_lagrangian_is_the_expansion` checks
//! the sign against the exact integral over a ring of mass points. The Euler–Lagrange equations
//! (002 (119), here with every term, G = ∇φ, Δφ = ∂_xG_x + ∂_yG_y):
//!
//! J = p_θ = 2I₀θ̇(1 − φ + v²) + I₀(G_y ẋ − G_x ẏ) = const,
//! (m + 2I₀θ̇²)ẍ + 4I₀θ̇θ̈ ẋ + I₀θ̈ G_y = −(m + I₀θ̇²) G_x − I₀θ̇ Δφ ẏ,
//! (m + 2I₀θ̇²)ÿ + 4I₀θ̇θ̈ ẏ − I₀θ̈ G_x = −(m + I₀θ̇²) G_y + I₀θ̇ Δφ ẋ.
//!
//! 002 (120) drops the θ̈G terms and prints the Δφ terms with the opposite signs (the same
//! coupling-sign slip). Here the full equations of (118) are integrated, in canonical form as
//! above. The Hessian of (118) in the velocities is positive definite only for slow motion (its
//! θ̇–ẋ entry 4I₀θ̇ẋ + I₀JᵀG grows with v): the weak-field ordering v = O(ε) is a domain
//! condition, which the state check enforces. Conserved: the energy
//! E = ½mv² + mφ + I₀θ̇²(1 − φ + 3v²) + I₀θ̇(G_yẋ − G_xẏ), p_θ, and for a central potential
//! the angular momentum x p_y − y p_x (a uniform field conserves the momentum across the field).
//! The spin–field force I₀θ̇Δφ(−ẏ, ẋ) is "magnetic" (it does no work); φ = −GM/r restricted to
//! the plane has Δφ = −GM/r³ ≠ 0, so it acts in the point-mass field.
//!
//! # State
//! Both systems: z = (x, y, θ, p_x, p_y, p_θ) (canonical, q = (x, y, θ); on a surface x = (x¹, x²)
//! are its chart's coordinates and p₁, p₂ their momenta); build one from velocities with `state`,
//! read the velocities back with `velocities`.

use std::fmt;
use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::classical::TangentTop;
use super::surface::{self, inverse, Geometry, Plane, Surface};
use crate::check;
use crate::convergence::{self, Monitor, Rule, Verdict};
use crate::error::{Error, Result};
use crate::integrate::methods::canonical_catalog;
use crate::integrate::problem::{Canonical, VectorField};
use crate::integrate::space::{Block, Space};
use crate::integrate::{Catalog, Entry, Problem};

/// The derivatives of a Lagrangian L(q, q̇) on ℝ³ at one point: value, ∂L/∂q̇, ∂L/∂q, ∂²L/∂q̇².
struct Derivs {
    l: f64,
    lv: Vector3<f64>,
    lq: Vector3<f64>,
    hess: Matrix3<f64>,
}

/// The stopping rule of the Legendre inversion ([`crate::convergence`]; the Newton step relative
/// to 1 + |q̇|_∞; ended at once at 10⁻¹³, after which one more step brings q̇ to round-off).
const LEGENDRE: Rule = Rule {
    tol: convergence::TOL,
    floor: 1e-13,
    max_iter: 60,
};

/// Solves ∂L/∂q̇(q, q̇) = p for q̇ by Newton's method with a Cholesky-factored Hessian (so that the
/// Hessian is positive definite at the answer), halving steps that leave the domain (`derivs`
/// returns None there), from `guess`, under the rule [`LEGENDRE`], then takes one more step. None
/// when it fails (singular or indefinite Hessian, no convergence).
fn legendre_inverse(
    p: &[f64],
    guess: Vector3<f64>,
    derivs: impl Fn(&Vector3<f64>) -> Option<Derivs>,
) -> Option<(Vector3<f64>, Derivs)> {
    let p = Vector3::new(p[0], p[1], p[2]);
    let mut v = guess;
    let mut d = derivs(&v)?;
    let mut monitor = Monitor::new(LEGENDRE);
    let mut polish = false;
    loop {
        let chol = d.hess.cholesky()?;
        let step = chol.solve(&(p - d.lv));
        let mut t = 1.0;
        let (nv, nd) = loop {
            let nv = v + step * t;
            if let Some(nd) = derivs(&nv) {
                break (nv, nd);
            }
            t *= 0.5;
            if t < 1e-12 {
                return None;
            }
        };
        v = nv;
        d = nd;
        if polish {
            return d.hess.cholesky().is_some().then_some((v, d));
        }
        match monitor.check(step.amax() * t, 1.0 + v.amax()) {
            Verdict::Continue => {}
            Verdict::Converged => polish = true,
            Verdict::Failed(_) => return None,
        }
    }
}

/// The state layout shared by both systems.
fn space() -> Space {
    Space::new([
        ("x", Block::Real(2)),
        ("theta", Block::Real(1)),
        ("p", Block::Real(2)),
        ("p_theta", Block::Real(1)),
    ])
}

/// The rotation by π/2 applied to a 2-vector: J(a, b) = (−b, a).
fn rot90(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}

// ---------------------------------------------------------------------------------------------
// Minkowski
// ---------------------------------------------------------------------------------------------

/// What both tops share: a Lagrangian L(q, q̇) in q = (x, y, θ) with its derivatives, and the
/// inverse of its Legendre map, from which H, Hamilton's equations, the state helpers and the
/// catalog follow once ([`legendre_kinds`]).
trait Legendre: Problem {
    /// L, ∂L/∂q̇, ∂L/∂q and ∂²L/∂q̇² at (q, q̇); None where L is not defined.
    fn derivs(&self, q: &[f64], v: &Vector3<f64>) -> Option<Derivs>;

    /// q̇ with ∂L/∂q̇(q, q̇) = p, and the derivatives there; None where the map is not inverted.
    fn solve(&self, q: &[f64], p: &[f64]) -> Option<(Vector3<f64>, Derivs)>;

    /// The error for a (q, q̇) where L is not defined.
    fn undefined(&self, q: [f64; 3], v: [f64; 3]) -> Error;

    /// Checks that q lies in the configuration space's chart (before a Legendre inversion).
    fn check_point(&self, _q: &[f64]) -> Result<()> {
        Ok(())
    }
}

/// L(q, q̇), checked.
fn lagrangian<T: Legendre>(t: &T, q: [f64; 3], v: [f64; 3]) -> Result<f64> {
    check::finite_slice("q and qdot", &[q[0], q[1], q[2], v[0], v[1], v[2]])?;
    t.derivs(&q, &Vector3::from(v))
        .map(|d| d.l)
        .ok_or_else(|| t.undefined(q, v))
}

/// The canonical state (q, ∂L/∂q̇) at (q, q̇); the Legendre map must be invertible there.
fn state<T: Legendre>(t: &T, q: [f64; 3], v: [f64; 3]) -> Result<Vec<f64>> {
    check::finite_slice(
        "x, theta, xdot, thetadot",
        &[q[0], q[1], q[2], v[0], v[1], v[2]],
    )?;
    let d = t
        .derivs(&q, &Vector3::from(v))
        .ok_or_else(|| t.undefined(q, v))?;
    if d.hess.cholesky().is_none() {
        return Err(not_invertible(t.name()));
    }
    Ok(vec![q[0], q[1], q[2], d.lv[0], d.lv[1], d.lv[2]])
}

/// The velocities of a state (the inverse Legendre map).
fn velocities<T: Legendre>(t: &T, z: &[f64]) -> Result<[f64; 3]> {
    check::len_of("state", z, 6)?;
    check::finite_slice("state", z)?;
    t.check_point(&z[..3])?;
    t.solve(&z[..3], &z[3..])
        .map(|(v, _)| [v[0], v[1], v[2]])
        .ok_or_else(|| not_invertible(t.name()))
}

/// E = H = p·q̇ − L of a state.
fn energy<T: Legendre>(t: &T, z: &[f64]) -> Result<f64> {
    check::len_of("state", z, 6)?;
    check::finite_slice("state", z)?;
    t.check_point(&z[..3])?;
    let sol = t.solve(&z[..3], &z[3..]);
    if sol.is_none() {
        return Err(not_invertible(t.name()));
    }
    Ok(hamiltonian_of(&z[3..], sol))
}

/// `Canonical` (H and its gradient through the inverse Legendre map), `VectorField` (Hamilton's
/// equations, for rk4) and the catalog of a [`Legendre`] top.
macro_rules! legendre_kinds {
    ($t:ty) => {
        impl Canonical for $t {
            fn dof(&self) -> usize {
                3
            }
            fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64 {
                hamiltonian_of(p, self.solve(q, p))
            }
            fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
                gradient_of(self.solve(q, p), hq, hp);
            }
        }

        impl VectorField for $t {
            /// Hamilton's equations q̇ = ∂H/∂p, ṗ = −∂H/∂q.
            fn field(&self, z: &[f64], dz: &mut [f64]) {
                self.hamilton_field(z, dz);
            }
        }

        impl Catalog for $t {
            fn kind_catalog() -> Vec<Entry<Self>> {
                canonical_catalog()
            }

            fn dissipation(
                &self,
                d: &$crate::integrate::forcing::Dissipation,
            ) -> $crate::Result<std::sync::Arc<dyn $crate::integrate::forcing::Perturbation>> {
                $crate::integrate::forcing::rayleigh(self, d)
            }
        }
    };
}

/// The relativistic tangent Euler top in 1+2 Minkowski space-time, 002 (87)–(96) (module docs):
/// L = −m/γ + ½θ̇²(𝕀γ + γ³ẋᵀK(θ)ẋ), K(θ) = R(θ) J I Jᵀ R(θ)ᵀ, physical sign (−L of 002 (90));
/// or, built by [`RelativisticTangentTop::on_surface`], the symmetric top on the static
/// space-time −dt² + g over a [`Surface`], 002 (97)–(103): L = −m/γ + ½𝕀s²(γ + ½γ³v²),
/// v² = g(ẋ, ẋ), s = θ̇ + α·ẋ. State z = (x¹, x², θ, p₁, p₂, p_θ); speeds v < 1 (c = 1).
#[derive(Clone, Debug)]
pub struct RelativisticTangentTop {
    mass: f64,
    /// The second-moment tensor I = ∫ξξᵀdm as (I₁₁, I₁₂, I₂₂).
    moments: [f64; 3],
    /// The spatial slice: None for the Minkowski plane in Cartesian coordinates (the closed-form
    /// kernel of 002 (90), any I); a surface for [`RelativisticTangentTop::on_surface`] (the
    /// kernel of the symmetric top, 002 (103)).
    surface: Option<Arc<dyn Surface>>,
}

/// Equal masses and moments on the same space-time: both Minkowski, or the same surface object.
impl PartialEq for RelativisticTangentTop {
    fn eq(&self, other: &Self) -> bool {
        self.mass == other.mass
            && self.moments == other.moments
            && match (&self.surface, &other.surface) {
                (None, None) => true,
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                _ => false,
            }
    }
}

impl RelativisticTangentTop {
    /// A top of mass m > 0 with second-moment tensor I = ∫ξξᵀ dm = [[i11, i12], [i12, i22]]
    /// (`moments` = (i11, i12, i22), positive semidefinite with 𝕀 = tr I > 0).
    pub fn new(mass: f64, moments: [f64; 3]) -> Result<Self> {
        check::positive("mass", mass)?;
        check::finite_slice("moments", &moments)?;
        let [a, b, c] = moments;
        if a < 0.0 || c < 0.0 || a * c - b * b < -1e-14 * (a + c).powi(2) || a + c <= 0.0 {
            return Err(Error::invalid(
                "moments",
                format!(
                    "expected a positive semidefinite second-moment tensor \
                     [[I11, I12], [I12, I22]] with positive trace, got ({a}, {b}, {c})"
                ),
            ));
        }
        Ok(RelativisticTangentTop {
            mass,
            moments,
            surface: None,
        })
    }

    /// The symmetric top, I = (𝕀/2)·Id (the seed's "2I = 𝕀" of 002 (93)); `inertia` = 𝕀 > 0.
    pub fn symmetric(mass: f64, inertia: f64) -> Result<Self> {
        check::positive("inertia", inertia)?;
        Self::new(mass, [0.5 * inertia, 0.0, 0.5 * inertia])
    }

    /// The symmetric top (I = (𝕀/2)·Id, `inertia` = 𝕀 > 0) of mass m > 0 on the static space-time
    /// ds² = −dt² + g over `surface` (002 (97)–(103), module docs); z = (x¹, x², θ, p₁, p₂, p_θ)
    /// in the surface's chart. (An anisotropic body is supported in the Minkowski plane only,
    /// [`RelativisticTangentTop::new`].) On [`Plane`] it is the same top as
    /// [`RelativisticTangentTop::symmetric`], with the Killing momenta of SE(2) as invariants.
    pub fn on_surface(surface: Arc<dyn Surface>, mass: f64, inertia: f64) -> Result<Self> {
        let top = Self::symmetric(mass, inertia)?;
        Ok(RelativisticTangentTop {
            surface: Some(surface),
            ..top
        })
    }

    /// The spatial slice: the surface of [`RelativisticTangentTop::on_surface`], else [`Plane`].
    pub fn surface(&self) -> Arc<dyn Surface> {
        self.surface.clone().unwrap_or_else(|| Arc::new(Plane))
    }

    /// Whether the top lives on a surface ([`RelativisticTangentTop::on_surface`]) rather than
    /// in the Minkowski plane of [`RelativisticTangentTop::new`].
    pub fn is_on_surface(&self) -> bool {
        self.surface.is_some()
    }

    /// The non-relativistic limit: the classical (intrinsic) [`TangentTop`] of the same mass and
    /// Euler tensor on the same surface (the Plane for a Minkowski top). As all velocities scale
    /// by ε → 0, L + m → the classical L up to O(ε⁴) (module docs).
    pub fn classical_limit(&self) -> Result<TangentTop> {
        let [a, b, c] = self.moments;
        TangentTop::with_tensor(self.surface(), self.mass, [a, b, b, c])
    }

    /// The momenta J = p_A X^A of the Killing fields of the surface lifted to (x, θ), in the order
    /// of [`Surface::killing`] (on the Minkowski plane: p_x, p_y and x p_y − y p_x + p_θ, the
    /// last conserved for any I). Errors: wrong length, non-finite, x outside the chart.
    pub fn killing_momenta(&self, z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("state", z, 6)?;
        check::finite_slice("state", z)?;
        self.check_point(&z[..3])?;
        Ok(surface::killing_momenta(&*self.surface(), z, false))
    }

    /// The speed v = √g(ẋ, ẋ) and the covariant spin rate s = θ̇ + α·ẋ of a state (both constant
    /// along a motion of the symmetric top, module docs). Errors: as
    /// [`RelativisticTangentTop::velocities`].
    pub fn speed_and_spin(&self, z: &[f64]) -> Result<(f64, f64)> {
        let v = self.velocities(z)?;
        let surface = self.surface();
        let x = [z[0], z[1]];
        let (g, a) = (surface.metric(x), surface.connection(x));
        let xd = [v[0], v[1]];
        Ok((
            super::surface::inner(&g, xd, xd).sqrt(),
            v[2] + a[0] * xd[0] + a[1] * xd[1],
        ))
    }

    /// The mass m.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// 𝕀 = tr I.
    pub fn inertia(&self) -> f64 {
        self.moments[0] + self.moments[2]
    }

    /// Whether I = (𝕀/2)·Id (then θ is cyclic and p_θ is conserved).
    pub fn is_symmetric(&self) -> bool {
        self.moments[1] == 0.0 && self.moments[0] == self.moments[2]
    }

    /// K(θ) = R(θ) J I Jᵀ R(θ)ᵀ and its first θ-derivative K' = JK − KJ, as (K₁₁, K₁₂, K₂₂).
    fn k(&self, theta: f64) -> ([f64; 3], [f64; 3]) {
        let [a, b, c] = self.moments;
        // J I Jᵀ = [[c, −b], [−b, a]]; rotate by θ.
        let (s, co) = theta.sin_cos();
        let (p, q, r) = (c, -b, a);
        // R M Rᵀ for symmetric M = [[p, q], [q, r]].
        let k11 = co * co * p - 2.0 * co * s * q + s * s * r;
        let k12 = co * s * (p - r) + (co * co - s * s) * q;
        let k22 = s * s * p + 2.0 * co * s * q + co * co * r;
        // K' = JK − KJ = [[−2K12, K11 − K22], [K11 − K22, 2K12]].
        ([k11, k12, k22], [-2.0 * k12, k11 - k22, 2.0 * k12])
    }

    /// L(q, q̇) of 002 (90) (physical sign, module docs), q = (x, y, θ), q̇ = (ẋ, ẏ, θ̇).
    /// Errors: non-finite input, |ẋ| ≥ 1.
    pub fn lagrangian(&self, q: [f64; 3], qdot: [f64; 3]) -> Result<f64> {
        lagrangian(self, q, qdot)
    }

    /// The canonical state (x, y, θ, p_x, p_y, p_θ) with p = ∂L/∂q̇ at the given position, angle
    /// and velocities. Errors: non-finite input, |ẋ| ≥ 1, a Legendre map that is not invertible
    /// there (∂²L/∂q̇² not positive definite).
    pub fn state(
        &self,
        x: [f64; 2],
        theta: f64,
        xdot: [f64; 2],
        thetadot: f64,
    ) -> Result<Vec<f64>> {
        state(self, [x[0], x[1], theta], [xdot[0], xdot[1], thetadot])
    }

    /// The velocities (ẋ, ẏ, θ̇) of a state (the inverse Legendre map). Errors: wrong length,
    /// non-finite, or momenta outside the range of the Legendre map.
    pub fn velocities(&self, z: &[f64]) -> Result<[f64; 3]> {
        velocities(self, z)
    }

    fn symmetric_only(&self, what: &str) -> Result<f64> {
        if self.is_symmetric() {
            Ok(0.5 * self.inertia())
        } else {
            Err(Error::invalid(
                what,
                "002 (94)–(96) hold for the symmetric top only (I = (𝕀/2)·Id)",
            ))
        }
    }

    /// |p| as a function of the speed v and J = p_θ for the symmetric top, 002 (94) (module docs;
    /// the seed's J is half of this one; on a surface |p| = |p_x − p_θ α|_{g⁻¹}). Errors: not
    /// symmetric, v ∉ [0, 1), non-finite J.
    pub fn momentum_94(&self, v: f64, j: f64) -> Result<f64> {
        let i0 = self.symmetric_only("momentum_94")?;
        check_speed(v)?;
        check::finite_slice("J", &[j])?;
        let (m, s) = (self.mass, v * v);
        let g = 1.0 / (1.0 - s).sqrt();
        Ok(m * g * v * (1.0 + j * j * (1.0 - s) * (4.0 - s) / (2.0 * i0 * m * (2.0 - s).powi(2))))
    }

    /// θ̇ of the symmetric top from v and J = p_θ, 002 (95): θ̇ = J/(2I₀γ(1 + ½v²γ²)) (on a
    /// surface: the covariant spin rate s = θ̇ + α·ẋ).
    pub fn spin_rate_95(&self, v: f64, j: f64) -> Result<f64> {
        let i0 = self.symmetric_only("spin_rate_95")?;
        check_speed(v)?;
        check::finite_slice("J", &[j])?;
        let g2 = 1.0 / (1.0 - v * v);
        Ok(j / (2.0 * i0 * g2.sqrt() * (1.0 + 0.5 * v * v * g2)))
    }

    /// The energy of the symmetric top from v and θ̇, 002 (96) (physical sign):
    /// E = mγ + I₀θ̇²(γ + (5/2)v²γ³ + (3/2)v⁴γ⁵) (on a surface with θ̇ → s = θ̇ + α·ẋ).
    pub fn energy_96(&self, v: f64, thetadot: f64) -> Result<f64> {
        let i0 = self.symmetric_only("energy_96")?;
        check_speed(v)?;
        check::finite_slice("thetadot", &[thetadot])?;
        let s = v * v;
        let g = 1.0 / (1.0 - s).sqrt();
        let (g3, g5) = (g * g * g, g.powi(5));
        Ok(self.mass * g + i0 * thetadot * thetadot * (g + 2.5 * s * g3 + 1.5 * s * s * g5))
    }
}

fn check_speed(v: f64) -> Result<()> {
    if v.is_finite() && (0.0..1.0).contains(&v) {
        Ok(())
    } else {
        Err(Error::invalid(
            "v",
            format!("expected a speed 0 ≤ v < 1 (c = 1), got {v}"),
        ))
    }
}

fn superluminal(v: [f64; 3], speed: f64) -> Error {
    Error::invalid(
        "velocity",
        format!(
            "expected a speed |ẋ| < 1 (c = 1), got |({}, {})| = {speed}",
            v[0], v[1],
        ),
    )
}

fn not_invertible(name: &str) -> Error {
    Error::invalid(
        "state",
        format!(
            "{name}: the Legendre map is not invertible at these momenta (∂²L/∂q̇² not positive \
             definite, or no velocity with these momenta); the expansion of 002 §IV needs slow, \
             moderately spinning tops"
        ),
    )
}

/// H(q, p) = p·q̇ − L and its gradient ∂H/∂p = q̇, ∂H/∂q = −∂L/∂q (at the q̇ of p); NaN where the
/// Legendre map cannot be inverted (the Gauss solver then reports the step).
fn hamiltonian_of(p: &[f64], sol: Option<(Vector3<f64>, Derivs)>) -> f64 {
    match sol {
        Some((v, d)) => p[0] * v[0] + p[1] * v[1] + p[2] * v[2] - d.l,
        None => f64::NAN,
    }
}

fn gradient_of(sol: Option<(Vector3<f64>, Derivs)>, hq: &mut [f64], hp: &mut [f64]) {
    match sol {
        Some((v, d)) => {
            for i in 0..3 {
                hp[i] = v[i];
                hq[i] = -d.lq[i];
            }
        }
        None => {
            hq.fill(f64::NAN);
            hp.fill(f64::NAN);
        }
    }
}

impl Problem for RelativisticTangentTop {
    fn calls_out(&self) -> bool {
        self.surface.as_ref().is_some_and(|s| s.calls_out())
    }
    fn name(&self) -> &'static str {
        "RelativisticTangentTop"
    }
    fn space(&self) -> Space {
        space()
    }
    /// E = H = p·q̇ − L (002 (96) for the symmetric top, with the physical sign).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        energy(self, z)
    }
    /// Minkowski: (p_x, p_y), and p_θ for the symmetric top: momenta of cyclic coordinates,
    /// linear, so kept exactly by the Gauss methods. On a surface: p_θ and the Killing momenta of
    /// the affine generators ([`Surface::killing_is_affine`]; quadratic in z, so also kept by the
    /// Gauss methods); [`RelativisticTangentTop::killing_momenta`] gives all.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("state", z, 6)?;
        let Some(surface) = &self.surface else {
            let mut out = vec![z[3], z[4]];
            if self.is_symmetric() {
                out.push(z[5]);
            }
            return Ok(out);
        };
        check::finite_slice("state", z)?;
        self.check_point(&z[..3])?;
        let affine = surface::killing_momenta(&**surface, z, true);
        Ok(std::iter::once(z[5]).chain(affine).collect())
    }
    fn invariant_count(&self) -> usize {
        match &self.surface {
            None => 2 + usize::from(self.is_symmetric()),
            Some(surface) => {
                1 + (0..surface.killing_count())
                    .filter(|&k| surface.killing_is_affine(k))
                    .count()
            }
        }
    }
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.velocities(z).map(|_| ())
    }
}

impl Legendre for RelativisticTangentTop {
    /// Derivatives of L at (q, q̇); None where v ≥ 1, x is outside the chart or the input is not
    /// finite.
    fn derivs(&self, q: &[f64], v: &Vector3<f64>) -> Option<Derivs> {
        match &self.surface {
            None => self.minkowski_derivs(q, v),
            Some(surface) => {
                let x = [q[0], q[1]];
                if !(surface.contains(x) && q[2].is_finite()) {
                    return None;
                }
                self.curved_derivs(&surface.geometry(x), v)
            }
        }
    }

    fn solve(&self, q: &[f64], p: &[f64]) -> Option<(Vector3<f64>, Derivs)> {
        match &self.surface {
            None => self.minkowski_solve(q, p),
            Some(surface) => {
                let x = [q[0], q[1]];
                if !(surface.contains(x) && q[2].is_finite()) {
                    return None;
                }
                self.curved_solve(&surface.geometry(x), p)
            }
        }
    }

    fn undefined(&self, q: [f64; 3], v: [f64; 3]) -> Error {
        match &self.surface {
            None => superluminal(v, v[0].hypot(v[1])),
            Some(surface) => {
                let x = [q[0], q[1]];
                if let Err(e) = surface.check(x) {
                    return e.at_start();
                }
                let speed = super::surface::inner(&surface.metric(x), [v[0], v[1]], [v[0], v[1]]);
                superluminal(v, speed.sqrt())
            }
        }
    }

    fn check_point(&self, q: &[f64]) -> Result<()> {
        match &self.surface {
            None => Ok(()),
            Some(surface) => surface.check([q[0], q[1]]).map_err(|e| e.at_start()),
        }
    }
}

legendre_kinds!(RelativisticTangentTop);

impl RelativisticTangentTop {
    /// The symmetric top on a surface (module docs, "Derivatives"): L, ∂L/∂q̇, ∂L/∂q, ∂²L/∂q̇² at
    /// the geometry of x and q̇ = (ẋ, θ̇); None where g(ẋ, ẋ) ≥ 1 or q̇ is not finite.
    fn curved_derivs(&self, geo: &Geometry, v: &Vector3<f64>) -> Option<Derivs> {
        let (m, tr) = (self.mass, self.inertia());
        let (xd, w) = ([v[0], v[1]], v[2]);
        let g = &geo.g;
        let n = [
            g[0][0] * xd[0] + g[0][1] * xd[1],
            g[1][0] * xd[0] + g[1][1] * xd[1],
        ];
        let qq = n[0] * xd[0] + n[1] * xd[1];
        if !(qq.is_finite() && qq < 1.0 && w.is_finite()) {
            return None;
        }
        let a = geo.alpha;
        let s = w + a[0] * xd[0] + a[1] * xd[1];
        let g1 = 1.0 / (1.0 - qq).sqrt();
        let g3 = g1 * g1 * g1;
        let g5 = g3 * g1 * g1;
        let g7 = g5 * g1 * g1;
        let f = g1 + 0.5 * qq * g3;
        let f1 = g3 + 0.75 * qq * g5;
        let f2 = 2.25 * g5 + 1.875 * qq * g7;
        let s2 = s * s;
        let l = -m / g1 + 0.5 * tr * s2 * f;
        let lam = 0.5 * m * g1 + 0.5 * tr * s2 * f1; // ∂L/∂Q
        let sig = tr * s * f; // ∂L/∂s = p_θ
        let l_qq = 0.25 * m * g3 + 0.5 * tr * s2 * f2;
        let l_qs = tr * s * f1;
        let l_ss = tr * f;
        let lv = Vector3::new(
            2.0 * lam * n[0] + sig * a[0],
            2.0 * lam * n[1] + sig * a[1],
            sig,
        );
        let mut lq = Vector3::zeros();
        for k in 0..2 {
            let d = &geo.dg[k];
            let vgv = d[0][0] * xd[0] * xd[0]
                + (d[0][1] + d[1][0]) * xd[0] * xd[1]
                + d[1][1] * xd[1] * xd[1];
            let da = geo.dalpha[k];
            lq[k] = lam * vgv + sig * (da[0] * xd[0] + da[1] * xd[1]);
        }
        let mut hess = Matrix3::zeros();
        for i in 0..2 {
            for j in 0..2 {
                hess[(i, j)] = 2.0 * lam * g[i][j]
                    + 4.0 * l_qq * n[i] * n[j]
                    + 2.0 * l_qs * (n[i] * a[j] + a[i] * n[j])
                    + l_ss * a[i] * a[j];
            }
            let h = 2.0 * l_qs * n[i] + l_ss * a[i];
            hess[(i, 2)] = h;
            hess[(2, i)] = h;
        }
        hess[(2, 2)] = l_ss;
        Some(Derivs { l, lv, lq, hess })
    }

    /// The inverse Legendre map of the top on a surface: from a free particle of mass
    /// m + 𝕀 s² (exact at low speed) carrying π = p_x − p_θ α at spin s = p_θ/𝕀, slower than
    /// light; failing that, from rest.
    fn curved_solve(&self, geo: &Geometry, p: &[f64]) -> Option<(Vector3<f64>, Derivs)> {
        let tr = self.inertia();
        let s = p[2] / tr;
        let a = geo.alpha;
        let pi = [p[0] - p[2] * a[0], p[1] - p[2] * a[1]];
        let gi = inverse(&geo.g);
        let up = [
            gi[0][0] * pi[0] + gi[0][1] * pi[1],
            gi[1][0] * pi[0] + gi[1][1] * pi[1],
        ];
        let mm = self.mass + tr * s * s;
        let e = (mm * mm + up[0] * pi[0] + up[1] * pi[1]).sqrt();
        let xd = [up[0] / e, up[1] / e];
        let guess = Vector3::new(xd[0], xd[1], s - a[0] * xd[0] - a[1] * xd[1]);
        legendre_inverse(p, guess, |v| self.curved_derivs(geo, v)).or_else(|| {
            legendre_inverse(p, Vector3::new(0.0, 0.0, s), |v| self.curved_derivs(geo, v))
        })
    }

    /// Derivatives of the Minkowski L (002 (90)) at (q, q̇); None where |ẋ| ≥ 1 or the input is
    /// not finite.
    fn minkowski_derivs(&self, q: &[f64], v: &Vector3<f64>) -> Option<Derivs> {
        let (u, w) = ([v[0], v[1]], v[2]);
        let s = u[0] * u[0] + u[1] * u[1];
        if !(s.is_finite() && s < 1.0 && w.is_finite() && q[2].is_finite()) {
            return None;
        }
        let m = self.mass;
        let tr = self.inertia();
        let g = 1.0 / (1.0 - s).sqrt();
        let (g3, g5) = (g * g * g, g * g * g * g * g);
        let g7 = g5 * g * g;
        let (k, kp) = self.k(q[2]);
        let ku = [k[0] * u[0] + k[1] * u[1], k[1] * u[0] + k[2] * u[1]];
        let qk = u[0] * ku[0] + u[1] * ku[1];
        let qkp = kp[0] * u[0] * u[0] + 2.0 * kp[1] * u[0] * u[1] + kp[2] * u[1] * u[1];
        let w2 = w * w;
        let l = -m / g + 0.5 * w2 * (tr * g + g3 * qk);
        let a_s = m * g + 0.5 * w2 * tr * g3 + 1.5 * w2 * g5 * qk;
        let b_s = m * g3 + 1.5 * w2 * tr * g5 + 7.5 * w2 * g7 * qk;
        let lv = Vector3::new(
            a_s * u[0] + w2 * g3 * ku[0],
            a_s * u[1] + w2 * g3 * ku[1],
            w * (tr * g + g3 * qk),
        );
        let lq = Vector3::new(0.0, 0.0, 0.5 * w2 * g3 * qkp);
        let mut hess = Matrix3::zeros();
        let kk = [[k[0], k[1]], [k[1], k[2]]];
        for i in 0..2 {
            for j in 0..2 {
                let delta = if i == j { 1.0 } else { 0.0 };
                hess[(i, j)] = a_s * delta
                    + b_s * u[i] * u[j]
                    + 3.0 * w2 * g5 * (u[i] * ku[j] + ku[i] * u[j])
                    + w2 * g3 * kk[i][j];
            }
            let huw = w * ((tr * g3 + 3.0 * g5 * qk) * u[i] + 2.0 * g3 * ku[i]);
            hess[(i, 2)] = huw;
            hess[(2, i)] = huw;
        }
        hess[(2, 2)] = tr * g + g3 * qk;
        Some(Derivs { l, lv, lq, hess })
    }

    fn minkowski_solve(&self, q: &[f64], p: &[f64]) -> Option<(Vector3<f64>, Derivs)> {
        // Start from a free particle of the mass the spin adds to at low speed
        // (p ≈ (m + ω²(𝕀/2 + K))ẋ, bounded by m + ω²𝕀·3/2; u = p/√(M² + |p|²) is slower than light)
        // with the spin of a top at rest; failing that, from rest.
        let tr = self.inertia();
        let w = p[2] / tr;
        let mm = self.mass + 1.5 * w * w * tr;
        let e = (mm * mm + p[0] * p[0] + p[1] * p[1]).sqrt();
        let guess = Vector3::new(p[0] / e, p[1] / e, w);
        legendre_inverse(p, guess, |v| self.minkowski_derivs(q, v)).or_else(|| {
            legendre_inverse(p, Vector3::new(0.0, 0.0, w), |v| {
                self.minkowski_derivs(q, v)
            })
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Weak field
// ---------------------------------------------------------------------------------------------

/// φ, ∇φ = (G_x, G_y) and the Hessian (φ_xx, φ_xy, φ_yy) of a potential at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PotentialValue {
    /// φ.
    pub phi: f64,
    /// G = ∇φ.
    pub grad: [f64; 2],
    /// (φ_xx, φ_xy, φ_yy).
    pub hess: [f64; 3],
}

type PotentialFn = dyn Fn([f64; 2]) -> PotentialValue + Send + Sync;

#[derive(Clone)]
enum PotentialKind {
    PointMass { gm: f64 },
    Uniform { g: [f64; 2] },
    Custom(Arc<PotentialFn>),
}

/// A static gravitational potential φ(x, y) (the g_tt = −e^{2φ} of 002 (115), corrected), with
/// its gradient and Hessian.
#[derive(Clone)]
pub struct Potential {
    kind: PotentialKind,
}

impl fmt::Debug for Potential {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.kind {
            PotentialKind::PointMass { gm } => write!(f, "Potential::point_mass({gm})"),
            PotentialKind::Uniform { g } => write!(f, "Potential::uniform({g:?})"),
            PotentialKind::Custom(_) => write!(f, "Potential::custom(..)"),
        }
    }
}

impl Potential {
    /// φ = −GM/r (r = |x| > 0), a point mass at the origin (the plane through it).
    pub fn point_mass(gm: f64) -> Result<Self> {
        check::positive("GM", gm)?;
        Ok(Potential {
            kind: PotentialKind::PointMass { gm },
        })
    }

    /// φ = g·x, a uniform field of strength −g (the force on the centre is −m g).
    pub fn uniform(g: [f64; 2]) -> Result<Self> {
        check::finite_slice("g", &g)?;
        Ok(Potential {
            kind: PotentialKind::Uniform { g },
        })
    }

    /// A potential given as a closure returning φ, ∇φ and the Hessian at a point (non-finite
    /// values mark points outside its domain).
    pub fn custom(f: impl Fn([f64; 2]) -> PotentialValue + Send + Sync + 'static) -> Self {
        Potential {
            kind: PotentialKind::Custom(Arc::new(f)),
        }
    }

    /// φ, ∇φ and the Hessian at x (non-finite at r = 0 for the point mass).
    pub fn eval(&self, x: [f64; 2]) -> PotentialValue {
        match &self.kind {
            PotentialKind::PointMass { gm } => {
                let r2 = x[0] * x[0] + x[1] * x[1];
                let r = r2.sqrt();
                let r3 = r2 * r;
                let r5 = r3 * r2;
                PotentialValue {
                    phi: -gm / r,
                    grad: [gm * x[0] / r3, gm * x[1] / r3],
                    hess: [
                        gm * (1.0 / r3 - 3.0 * x[0] * x[0] / r5),
                        -3.0 * gm * x[0] * x[1] / r5,
                        gm * (1.0 / r3 - 3.0 * x[1] * x[1] / r5),
                    ],
                }
            }
            PotentialKind::Uniform { g } => PotentialValue {
                phi: g[0] * x[0] + g[1] * x[1],
                grad: *g,
                hess: [0.0; 3],
            },
            PotentialKind::Custom(f) => f(x),
        }
    }
}

/// The symmetric relativistic tangent top in a weak static gravitational field, the Lagrangian
/// 002 (118) with its coupling sign corrected (module docs):
/// L = ½mv² − mφ + I₀θ̇²(1 − φ + v²) + I₀θ̇(G_yẋ − G_xẏ), I₀ = 𝕀/2, G = ∇φ.
/// State z = (x, y, θ, p_x, p_y, p_θ).
#[derive(Clone, Debug)]
pub struct WeakFieldTop {
    mass: f64,
    i0: f64,
    potential: Potential,
}

impl WeakFieldTop {
    /// Mass m > 0, 𝕀 = `inertia` > 0 (I₀ = 𝕀/2), and the potential φ.
    pub fn new(mass: f64, inertia: f64, potential: Potential) -> Result<Self> {
        check::positive("mass", mass)?;
        check::positive("inertia", inertia)?;
        Ok(WeakFieldTop {
            mass,
            i0: 0.5 * inertia,
            potential,
        })
    }

    /// The potential.
    pub fn potential(&self) -> &Potential {
        &self.potential
    }

    /// L(q, q̇) of 002 (118) (corrected, physical sign), q = (x, y, θ), q̇ = (ẋ, ẏ, θ̇).
    /// Errors: non-finite input or potential.
    pub fn lagrangian(&self, q: [f64; 3], qdot: [f64; 3]) -> Result<f64> {
        lagrangian(self, q, qdot)
    }

    /// The canonical state with p = ∂L/∂q̇ (see [`RelativisticTangentTop::state`]).
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
        let q = "the angular momentum x p_y − y p_x";
        check::cross2("state", q, [z[0], z[1]], [z[3], z[4]])
    }
}

fn outside_potential(q: [f64; 3]) -> Error {
    Error::invalid(
        "x",
        format!(
            "the potential or its derivatives are not finite at ({}, {})",
            q[0], q[1]
        ),
    )
}

impl Problem for WeakFieldTop {
    fn calls_out(&self) -> bool {
        matches!(self.potential.kind, PotentialKind::Custom(_))
    }
    fn name(&self) -> &'static str {
        "WeakFieldTop"
    }
    fn space(&self) -> Space {
        space()
    }
    /// E = p·q̇ − L = ½mv² + mφ + I₀θ̇²(1 − φ + 3v²) + I₀θ̇(G_yẋ − G_xẏ) (module docs).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        energy(self, z)
    }
    /// p_θ (θ is cyclic); for the point mass also x p_y − y p_x (quadratic); for a uniform field
    /// also the momentum across the field, p·Ĵĝ (linear). The Gauss methods keep all of them.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("state", z, 6)?;
        let mut out = vec![z[5]];
        match &self.potential.kind {
            PotentialKind::PointMass { .. } => out.push(self.angular_momentum(z)?),
            PotentialKind::Uniform { g } => {
                let n = g[0].hypot(g[1]);
                if n > 0.0 {
                    let t = rot90([g[0] / n, g[1] / n]);
                    out.push(t[0] * z[3] + t[1] * z[4]);
                }
            }
            PotentialKind::Custom(_) => {}
        }
        Ok(out)
    }
    fn invariant_count(&self) -> usize {
        match &self.potential.kind {
            PotentialKind::PointMass { .. } => 2,
            PotentialKind::Uniform { g } => 1 + usize::from(g[0].hypot(g[1]) > 0.0),
            PotentialKind::Custom(_) => 1,
        }
    }
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.velocities(z).map(|_| ())
    }
}

impl Legendre for WeakFieldTop {
    /// Derivatives of L at (q, q̇); None where φ or q̇ is not finite.
    fn derivs(&self, q: &[f64], v: &Vector3<f64>) -> Option<Derivs> {
        let pv = self.potential.eval([q[0], q[1]]);
        let (m, i0) = (self.mass, self.i0);
        let (u, w) = ([v[0], v[1]], v[2]);
        let s = u[0] * u[0] + u[1] * u[1];
        let [gx, gy] = pv.grad;
        let [hxx, hxy, hyy] = pv.hess;
        let c = gy * u[0] - gx * u[1];
        let l = 0.5 * m * s - m * pv.phi + i0 * w * w * (1.0 - pv.phi + s) + i0 * w * c;
        if !(l.is_finite() && hxx.is_finite() && hxy.is_finite() && hyy.is_finite()) {
            return None;
        }
        let a = m + 2.0 * i0 * w * w;
        let lv = Vector3::new(
            a * u[0] + i0 * w * gy,
            a * u[1] - i0 * w * gx,
            2.0 * i0 * w * (1.0 - pv.phi + s) + i0 * c,
        );
        let f = m + i0 * w * w;
        // ∂c/∂x_k = H_yk u_x − H_xk u_y.
        let lq = Vector3::new(
            -f * gx + i0 * w * (hxy * u[0] - hxx * u[1]),
            -f * gy + i0 * w * (hyy * u[0] - hxy * u[1]),
            0.0,
        );
        let mut hess = Matrix3::zeros();
        hess[(0, 0)] = a;
        hess[(1, 1)] = a;
        hess[(0, 2)] = 4.0 * i0 * w * u[0] + i0 * gy;
        hess[(1, 2)] = 4.0 * i0 * w * u[1] - i0 * gx;
        hess[(2, 0)] = hess[(0, 2)];
        hess[(2, 1)] = hess[(1, 2)];
        hess[(2, 2)] = 2.0 * i0 * (1.0 - pv.phi + s);
        Some(Derivs { l, lv, lq, hess })
    }

    fn solve(&self, q: &[f64], p: &[f64]) -> Option<(Vector3<f64>, Derivs)> {
        let guess = Vector3::new(p[0] / self.mass, p[1] / self.mass, p[2] / (2.0 * self.i0));
        legendre_inverse(p, guess, |v| self.derivs(q, v))
    }

    fn undefined(&self, q: [f64; 3], _v: [f64; 3]) -> Error {
        outside_potential(q)
    }
}

legendre_kinds!(WeakFieldTop);
