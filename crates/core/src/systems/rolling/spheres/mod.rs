//! 003 §2: two rigid spheres rolling against each other without slipping, free in space.
//!
//! **Configuration** (003 §2, (1)–(4)). Reference sphere k (k = 1, 2) has its centre at the
//! origin, radius r_k, mass m_k, centre of mass γ_k (|γ_k| < r_k) and second-moment matrix about
//! the centre of mass I_k = ∫(p − γ_k)(p − γ_k)ᵀρ_k (003 §2; symmetric positive semi-definite). In
//! the configuration (z_k, a_k) ∈ SO(3) × ℝ³ the material point p of body k is at z_k p + a_k. The
//! contact (1) and the centre-of-mass frame (3) leave 𝒬 = SO(3)² × S² = {(z₁, z₂, u)}: u is the
//! unit vector from the centre a₁ to the centre a₂ = a₁ + R u (R = r₁ + r₂), the contact point is
//! c = a₁ + r₁u = a₂ − r₂u, and (4) gives
//! a₁ = −(m₁z₁γ₁ + m₂z₂γ₂ + R m₂u)/(m₁ + m₂), a₂ = −(m₁z₁γ₁ + m₂z₂γ₂ − R m₁u)/(m₁ + m₂).
//!
//! **Velocities and the rolling constraint.** Ω_k ∈ ℝ³ are the body angular velocities
//! (ż_k = z_k Ω̂_k, 003's left trivialization). Rolling without slipping (the material contact
//! points have equal velocities) is (7), R u̇ = (r₁z₁Ω₁ + r₂z₂Ω₂) × u, i.e. (10)
//! u̇ = (α₁z₁Ω₁ + α₂z₂Ω₂) × u with α_k = r_k/R (re-derived from the material velocities
//! ȧ_k ± r_k (z_kΩ_k) × u of the contact point on each body; [`RollingSpheres::udot`]). The
//! state is therefore z = (z₁, z₂, u, Ω₁, Ω₂) ∈ SO(3) × SO(3) × S² × ℝ³ × ℝ³ (27 values, blocks
//! `z1`, `z2` row-major, `u`, `Omega1`, `Omega2`); u̇ is not a state variable, so (10) holds by
//! construction along every computed motion.
//!
//! **Lagrangian** (003 §2, re-derived). The kinetic energy of body k is
//! ½ Ω_kᵀJ_k⁰Ω_k + ½ m_k|ẋ_k|² with J_k⁰ = tr(I_k)𝟙 − I_k (the moment of inertia tensor about
//! the centre of mass) and x_k = z_kγ_k + a_k; by (4), ẋ₂ − ẋ₁ = d = R u̇ − z₁(Ω₁ × γ₁) +
//! z₂(Ω₂ × γ₂) and m₁|ẋ₁|² + m₂|ẋ₂|² = e|d|², e = m₁m₂/(m₁ + m₂). With
//! J_k = (J_k⁰ + e(|γ_k|²𝟙 − γ_kγ_kᵀ))/(eR²) and e_k = γ_k/r_k the kinetic energy is eR²·L with
//! L of (8),
//!
//! L = ½Ω₁ᵀJ₁Ω₁ + ½Ω₂ᵀJ₂Ω₂ + ½|u̇|² − u̇·(α₁z₁(Ω₁ × e₁) − α₂z₂(Ω₂ × e₂))
//!     − α₁α₂ z₁(Ω₁ × e₁)·z₂(Ω₂ × e₂)
//!   = ½Ω₁ᵀK₁Ω₁ + ½Ω₂ᵀK₂Ω₂ + ½|w|²,   K_k = J_k⁰/(eR²),   w = u̇ − α₁b₁ + α₂b₂ = d/R,
//!
//! b_k = z_k(Ω_k × e_k) (the second form: complete the square; α_k²|b_k|² is the parallel-axis
//! part of J_k). The tests check eR²·L against the kinetic energy of point-mass bodies whose
//! points move by (4), by finite differences in time. [`Problem::energy`] is the physical
//! kinetic energy eR²·L; [`RollingSpheres::lagrangian`] is L.
//!
//! **Momentum** (003 §2.1). SO(3) acts by A·(z₁, z₂, u) = (Az₁, Az₂, Au), lifted to
//! (Az₁, Az₂, Au, Ω₁, Ω₂, Au̇) (003 prints `u` for the lifted base point; the check of
//! invariance needs Au); L is invariant and the generator of ξ, (z₁ᵀξ, z₂ᵀξ, ξ × u), satisfies
//! (10) for every ξ (α₁ + α₂ = 1), so the symmetry is horizontal and the Noether momentum
//! ⟨∂L/∂(Ω₁, Ω₂, u̇), generator⟩ = ξ·J,
//!
//! J = z₁p₁ + z₂p₂ + u × w,   p_k = ∂L/∂Ω_k = K_kΩ_k ∓ α_k e_k × z_kᵀw  (− for k = 1, + for k = 2),
//!
//! is conserved ([`RollingSpheres::noether_momentum`]; the seed's ∂L/∂Ω_k of §2.3 agree with
//! these). eR²·J is the total angular momentum Σ ∫ x × ẋ dm about the centre of mass
//! ([`RollingSpheres::angular_momentum`], checked against the point masses). The material
//! symmetries (rotations of body k about e_k, when e_k is an eigenvector of J_k) have the
//! Noether quantities p_k·e_k/|e_k|, which are *not* conserved (their generator (σ₁e₁, σ₂e₂, 0)
//! violates (10)); [`RollingSpheres::body_momenta`] gives eR²·p_k.
//!
//! **Equations of motion** (Lagrange–d'Alembert, 003 §2.3 from (11)). Variations (η₁, η₂, δu)
//! with δz_k = z_kη̂_k and δu = (α₁z₁η₁ + α₂z₂η₂) × u (the constraint) give, as in 003,
//!
//! −ṗ_k + p_k × Ω_k + δL/δz_k − α_k z_kᵀ(u × ẇ) = 0,   w = ∂L/∂u̇,
//!
//! with δL/δz_k = (Ω_k × e_k) × z_kᵀc_k, c₁ = −α₁(u̇ + α₂b₂), c₂ = α₂(u̇ − α₁b₁). In spatial
//! form (ω_k = z_kΩ_k, ε_k = z_ke_k, using ε̇_k = b_k) these become
//! d/dt(z₁K₁Ω₁) = −s₁ × ẇ, d/dt(z₂K₂Ω₂) = −s₂ × ẇ with the lever arms
//! s₁ = α₁(u − ε₁) = (c − x₁)/R, s₂ = α₂(u + ε₂) = (x₂ − c)/R, and w = ω₁ × s₁ + ω₂ × s₂: the
//! Newton–Euler equations with the contact force eRẇ. Differentiating w,
//! ẇ = −s₁ × ω̇₁ − s₂ × ω̇₂ + a, a = ω₁ × ṡ₁ + ω₂ × ṡ₂, ṡ₁ = α₁(u̇ − ω₁ × ε₁),
//! ṡ₂ = α₂(u̇ + ω₂ × ε₂), and with the spatial tensors K_k^s = z_kK_kz_kᵀ (ω̇_k = z_kΩ̇_k):
//!
//! ⎡K₁^s − ŝ₁ŝ₁   −ŝ₁ŝ₂   ⎤ ⎡ω̇₁⎤   ⎡(K₁^sω₁) × ω₁ − s₁ × a⎤
//! ⎣−ŝ₂ŝ₁     K₂^s − ŝ₂ŝ₂⎦ ⎣ω̇₂⎦ = ⎣(K₂^sω₂) × ω₂ − s₂ × a⎦,
//!
//! a symmetric positive-definite 6 × 6 system (diag(K^s) + SᵀS, S = [ŝ₁ ŝ₂]) solved by a
//! fixed-size Cholesky factorization ([`RollingSpheres::accelerations`]). The tests compare it
//! with the constrained Newton–Euler equations of the two bodies in physical units (unknown
//! contact force from the second derivative of the no-slip condition) at random states, and
//! with 003's final equation of §2.3.
//!
//! **Slip in 003 §2.3**: in "Expand the derivative in lines 1 and 4", the derivative of line 1,
//! α₁α₂ e₁ × d/dt(z₁⁻¹z₂(Ω₂ × e₂)), loses its term α₁α₂ e₁ × z₁⁻¹z₂(Ω̇₂ × e₂) and prints
//! α₁α₂z₁⁻¹z₂(Ω₂ × (Ω₂ × e₂)) without the factor "e₁ ×". Hence in the final equation the Ω̇₂
//! coefficient reads α₁α₂((e₁ − z₁⁻¹u)^(z₁⁻¹u)^ − (z₁⁻¹u)^(z₁⁻¹z₂e₂)^)z₁⁻¹z₂ where the check
//! gives α₁α₂(e₁ − z₁⁻¹u)^(z₁⁻¹u + z₁⁻¹z₂e₂)^z₁⁻¹z₂, and the term
//! α₁α₂z₁⁻¹z₂(𝟙 − (z₂⁻¹u)^)(Ω₂ × (Ω₂ × e₂)) should read
//! α₁α₂z₁⁻¹z₂((z₂⁻¹z₁e₁)^ − (z₂⁻¹u)^)(Ω₂ × (Ω₂ × e₂)). With these two corrections the printed
//! equation (and the one for k = 2 by exchanging the indices and negating u, as 003 says) holds
//! to round-off at the accelerations above; as printed its residual is O(1) (tests).
//!
//! **Curvature** (003 §2.2). For the constrained fields X = (Ω₁, Ω₂, U), U = (α₁z₁Ω₁ +
//! α₂z₂Ω₂) × u with constant Ω_k, Δ(X, X̃) = −ν[X, X̃], ν(Ω₁, Ω₂, v) = v − (α₁z₁Ω₁ + α₂z₂Ω₂) × u,
//! [X, Y] = XY − YX as derivations; 003's closed form Δ = α₁α₂ u × ((z₁Ω₁ − z₂Ω₂) × (z₁Ω̃₁ −
//! z₂Ω̃₂)) is confirmed, sign included ([`RollingSpheres::curvature`] against
//! [`RollingSpheres::curvature_by_brackets`], which takes the bracket from the commutator of the
//! exact flows of X and X̃). It vanishes on T𝒬₀.
//!
//! **Holonomic subsystem** (003 §2.4). If γ_k ⊥ e₃ and e₃ is an eigenvector of I_k (003 asks
//! for J_k diagonal, which is more than needed), T𝒬₀ (z_k rotations about e₃, u ⊥ e₃,
//! Ω_k ∥ e₃) is invariant ([`RollingSpheres::is_planar`], [`RollingSpheres::planar_state`]);
//! there the system is the rolling disks of 003 §1 ([`RollingSpheres::planar_state`] documents
//! the correspondence).
//!
//! Other slips of 003 §2 noted in passing: "trace(ż_kI_kż_kᵗ) = ΩᵗJ_kΩ" means J_k⁰ (J_k is
//! defined only afterwards, and differs); §2.1 "tridiagonally" means diagonally; in §2.2 the
//! displayed ∂U/∂z_k Ω̃_k carries "+ α₂z₂Ω₂" for general k (harmless: the result is right); in
//! §2.4 δΩ_k = −δz_k × Ω_k + δz_k should end in the time derivative of δz_k (the conclusion
//! δΩ_k ⊥ e₃ is unaffected).
//!
//! **Momentum form** (what the methods integrate). With the constrained Lagrangian
//! L_c(ω) = ½Σω_kᵀK_k^sω_k + ½|w|² (w = ω₁ × s₁ + ω₂ × s₂), the spatial momenta
//! P_k = ∂L_c/∂ω_k = K_k^sω_k + s_k × w, i.e. P = Mω with the mass matrix above, obey
//! Ṗ_k = ṡ_k × w (from d/dt(K_k^sω_k) = −s_k × ẇ), and P₁ + P₂ = J: the rates cancel
//! identically because ṡ₁ + ṡ₂ = w. The kernels work in the chart (z₁, z₂, u, P₁, P₂)
//! ([`Problem::to_internal`]); the user state keeps (Ω₁, Ω₂). So J is kept to round-off by every
//! method below, not only to the truncation error (with Ω as the working variable the symmetric
//! midpoint let J drift linearly, ~5e-5 per 10⁴ steps at h = 0.01, on a round-body test).
//!
//! **Methods**: "midpoint" (default; the symmetric implicit Lie-group midpoint
//! [`LieMidpoint`], order 2), "midpoint4" (its Suzuki composition, order 4), "rkmk4" (RKMK,
//! order 4) — all three through [`GroupField`] with the left action z_k ↦ exp(ξ_k)z_k,
//! u ↦ exp(ξ_u)u, P ↦ P + ξ_P and ξ = (z₁Ω₁, z₂Ω₂, α₁z₁Ω₁ + α₂z₂Ω₂, ξ_P), so SO(3) and S²
//! are kept to round-off (in the chart above, ξ_P = (ṡ₁ × w, ṡ₂ × w)) — and "rk4" (classical
//! RK4 on the flat 27 values, the baseline; it leaves SO(3) and S²). Measured (tests, general
//! bodies, 10⁵ steps of h = 0.02): max |ΔE|/E 3.1e-5 (first half) and 3.3e-5 (second half) for
//! the reversible midpoint — no drift at this length, though longer runs (benches/python,
//! docs/benchmarks.md) show it rise slowly (×2.4 from t = 20 to 5000 at h = 0.02, ∝ h²) before
//! levelling off near t ≈ 10⁴: the method is reversible, not symplectic, and the system is
//! nonholonomic, so no bound is guaranteed; 7.5e-9 then 1.5e-8 for rkmk4 and 2.7e-7 then 8.3e-7
//! for rk4 — growing; |ΔJ|/|J| ≤ 2e-14 for the Lie-group methods.
//!
//! **Tangent lift** (issue 26): the Lie-group methods carry the exact derivative of their own
//! map, in left-trivialised directions on the SO(3) blocks (the chart's, the generator's, the
//! action's and dexp's derivatives: `tangent.rs`); `rk4` on the field lift, whose directions are
//! ambient (the field's derivative off SO(3) and S² too); no parameters.
//!
//! [`LieMidpoint`]: crate::integrate::methods::LieMidpoint
//! [`GroupField`]: crate::integrate::problem::GroupField

mod curvature;
mod dynamics;
mod methods;
mod planar;
mod tangent;

use nalgebra::{Matrix3, Vector3};

use crate::check;
use crate::error::{Error, Result};
use crate::integrate::Problem;

/// The state layout: z₁ (9, row-major), z₂ (9), u (3), Ω₁ (3), Ω₂ (3).
pub const STATE_DIM: usize = 27;

/// Two spheres rolling against each other without slipping (003 §2); see the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct RollingSpheres {
    radii: [f64; 2],
    masses: [f64; 2],
    gammas: [Vector3<f64>; 2],
    inertias: [Matrix3<f64>; 2],
    /// e = m₁m₂/(m₁ + m₂).
    reduced_mass: f64,
    /// R = r₁ + r₂.
    big_r: f64,
    /// α_k = r_k/R.
    alpha: [f64; 2],
    /// e_k = γ_k/r_k.
    e: [Vector3<f64>; 2],
    /// K_k = J_k⁰/(eR²).
    k: [Matrix3<f64>; 2],
    /// 003's J_k = K_k + α_k²(|e_k|²𝟙 − e_ke_kᵀ).
    j: [Matrix3<f64>; 2],
}

/// A configuration and velocity read from a flat state.
#[derive(Clone, Copy, Debug)]
struct Local {
    z: [Matrix3<f64>; 2],
    u: Vector3<f64>,
    omega: [Vector3<f64>; 2],
}

fn local(z: &[f64]) -> Local {
    Local {
        z: [
            Matrix3::from_row_slice(&z[0..9]),
            Matrix3::from_row_slice(&z[9..18]),
        ],
        u: Vector3::from_column_slice(&z[18..21]),
        omega: [
            Vector3::from_column_slice(&z[21..24]),
            Vector3::from_column_slice(&z[24..27]),
        ],
    }
}

fn put_rows(m: &Matrix3<f64>, out: &mut [f64]) {
    for i in 0..3 {
        for j in 0..3 {
            out[3 * i + j] = m[(i, j)];
        }
    }
}

fn rows(m: [[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[i][j])
}

fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

/// Kinematic quantities of a state (spatial frame).
struct Kin {
    /// ω_k = z_kΩ_k.
    w: [Vector3<f64>; 2],
    /// ε_k = z_ke_k.
    eps: [Vector3<f64>; 2],
    /// u̇ of (10).
    udot: Vector3<f64>,
    /// Lever arms s₁ = α₁(u − ε₁), s₂ = α₂(u + ε₂).
    s: [Vector3<f64>; 2],
}

impl RollingSpheres {
    /// The spheres of radii r_k > 0, centres of mass γ_k (|γ_k| < r_k), masses m_k > 0 and
    /// second-moment matrices about the centres of mass I_k = ∫(p − γ_k)(p − γ_k)ᵀρ_k
    /// (symmetric positive semi-definite, with J_k⁰ = tr(I_k)𝟙 − I_k positive definite, i.e. not
    /// all mass on a line). Errors: [`Error::NonFinite`], [`Error::InvalidArgument`] naming the
    /// input.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        r1: f64,
        r2: f64,
        gamma1: [f64; 3],
        gamma2: [f64; 3],
        m1: f64,
        m2: f64,
        inertia1: [[f64; 3]; 3],
        inertia2: [[f64; 3]; 3],
    ) -> Result<Self> {
        check::finite_slice("r1, r2, m1, m2", &[r1, r2, m1, m2])?;
        check::finite_slice("gamma1", &gamma1)?;
        check::finite_slice("gamma2", &gamma2)?;
        check::finite_slice("inertia1", inertia1.as_flattened())?;
        check::finite_slice("inertia2", inertia2.as_flattened())?;
        check::positive("r1", r1)?;
        check::positive("r2", r2)?;
        check::positive("m1", m1)?;
        check::positive("m2", m2)?;
        let radii = [r1, r2];
        let masses = [m1, m2];
        let gammas = [Vector3::from(gamma1), Vector3::from(gamma2)];
        let inertias = [rows(inertia1), rows(inertia2)];
        for i in 0..2 {
            let g = gammas[i].norm();
            if g >= radii[i] {
                return Err(Error::invalid(
                    format!("gamma{}", i + 1),
                    format!(
                        "the centre of mass must lie inside the sphere, |γ| < r; got |γ| = {g}, \
                         r = {}",
                        radii[i]
                    ),
                ));
            }
            let a = inertias[i];
            let scale = a.norm().max(f64::MIN_POSITIVE);
            let asym = (a - a.transpose()).norm();
            if asym > 1e-12 * scale {
                return Err(Error::invalid(
                    format!("inertia{}", i + 1),
                    format!("the second-moment matrix must be symmetric; ‖I − Iᵀ‖ = {asym:.3e}"),
                ));
            }
            let sym = (a + a.transpose()) * 0.5;
            let ev = sym.symmetric_eigenvalues();
            let min = ev.min();
            if min < -1e-12 * scale {
                return Err(Error::invalid(
                    format!("inertia{}", i + 1),
                    format!(
                        "the second-moment matrix ∫(p − γ)(p − γ)ᵀρ must be positive \
                         semi-definite; smallest eigenvalue {min:.6e}"
                    ),
                ));
            }
            // Eigenvalues of J⁰ = tr(I)𝟙 − I are the sums of pairs of eigenvalues of I.
            let mut sorted = [ev[0], ev[1], ev[2]];
            sorted.sort_by(f64::total_cmp);
            if sorted[0] + sorted[1] <= 1e-12 * scale {
                return Err(Error::invalid(
                    format!("inertia{}", i + 1),
                    "the moment of inertia tensor tr(I)𝟙 − I must be positive definite (the \
                     mass may not lie on one line through the centre of mass)",
                ));
            }
        }
        // e = m₁m₂/(m₁ + m₂) = lo/(1 + lo/hi): no overflow of m₁m₂ or m₁ + m₂.
        let (lo, hi) = (m1.min(m2), m1.max(m2));
        let reduced_mass = lo / (1.0 + lo / hi);
        let big_r = r1 + r2;
        let alpha = [r1 / big_r, r2 / big_r];
        let scale = reduced_mass * big_r * big_r;
        // The energy scale eR² and the rescaled inertias K_k = J_k⁰/(eR²) must be representable
        // (positive normal numbers, finite): radii or masses near the ends of the f64 range
        // make them overflow or underflow, and every observable would be NaN.
        if !(scale.is_finite() && scale >= f64::MIN_POSITIVE) {
            return Err(Error::overflow(
                "r1, r2, m1, m2",
                format!(
                    "the energy scale eR² = m₁m₂/(m₁ + m₂)·(r₁ + r₂)² = {} is not a positive \
                     normal number (outside the f64 range [{:e}, {:e}])",
                    crate::error::fmt_num(scale),
                    f64::MIN_POSITIVE,
                    f64::MAX
                ),
            ));
        }
        let e = [gammas[0] / r1, gammas[1] / r2];
        let sym = |a: Matrix3<f64>| (a + a.transpose()) * 0.5;
        let j0 = [0, 1].map(|i| {
            let a = sym(inertias[i]);
            Matrix3::identity() * a.trace() - a
        });
        let k = [j0[0] / scale, j0[1] / scale];
        let j = [0, 1].map(|i| {
            k[i] + (Matrix3::identity() * e[i].norm_squared() - e[i] * e[i].transpose())
                * (alpha[i] * alpha[i])
        });
        for i in 0..2 {
            let (min, max) = (k[i].symmetric_eigenvalues().min(), k[i].amax());
            if !(max.is_finite() && j[i].iter().all(|x| x.is_finite()) && min >= f64::MIN_POSITIVE)
            {
                return Err(Error::overflow(
                    format!("inertia{}", i + 1),
                    format!(
                        "the rescaled moment of inertia K_{} = J_{}⁰/(eR²) (003 §2) has \
                         eigenvalues outside the f64 range (smallest {}, largest entry {}): \
                         the inertia is out of scale with eR² = {}",
                        i + 1,
                        i + 1,
                        crate::error::fmt_num(min),
                        crate::error::fmt_num(max),
                        crate::error::fmt_num(scale)
                    ),
                ));
            }
        }
        Ok(RollingSpheres {
            radii,
            masses,
            gammas,
            inertias,
            reduced_mass,
            big_r,
            alpha,
            e,
            k,
            j,
        })
    }

    /// The radii (r₁, r₂).
    pub fn radii(&self) -> [f64; 2] {
        self.radii
    }

    /// The masses (m₁, m₂).
    pub fn masses(&self) -> [f64; 2] {
        self.masses
    }

    /// e = m₁m₂/(m₁ + m₂) (003 §2).
    pub fn reduced_mass(&self) -> f64 {
        self.reduced_mass
    }

    /// eR², the factor between the physical kinetic energy and L of (8).
    pub fn scale(&self) -> f64 {
        self.reduced_mass * self.big_r * self.big_r
    }

    /// α_k = r_k/R (003 §2).
    pub fn alphas(&self) -> [f64; 2] {
        self.alpha
    }

    /// e_k = γ_k/r_k (003 §2).
    pub fn e_vectors(&self) -> [[f64; 3]; 2] {
        [arr(&self.e[0]), arr(&self.e[1])]
    }

    /// The moment of inertia tensors about the centres of mass J_k⁰ = tr(I_k)𝟙 − I_k (003 §2).
    pub fn moment_tensors(&self) -> [Matrix3<f64>; 2] {
        [self.k[0] * self.scale(), self.k[1] * self.scale()]
    }

    /// 003's rescaled J_k = (J_k⁰ + e(|γ_k|²𝟙 − γ_kγ_kᵀ))/(eR²) of (8).
    pub fn j_tensors(&self) -> [Matrix3<f64>; 2] {
        self.j
    }

    /// The state (z₁, z₂, u, Ω₁, Ω₂) (flat, 27 values). Errors: non-finite values, z_k not in
    /// SO(3), |u| ≠ 1 ([`Error::NotInGroup`]).
    pub fn state(
        &self,
        z1: [[f64; 3]; 3],
        z2: [[f64; 3]; 3],
        u: [f64; 3],
        omega1: [f64; 3],
        omega2: [f64; 3],
    ) -> Result<Vec<f64>> {
        let mut s = Vec::with_capacity(STATE_DIM);
        s.extend_from_slice(z1.as_flattened());
        s.extend_from_slice(z2.as_flattened());
        s.extend_from_slice(&u);
        s.extend_from_slice(&omega1);
        s.extend_from_slice(&omega2);
        self.space().check("state", &s)?;
        Ok(s)
    }

    /// The configuration and velocity of an observed state, checked as [`RollingSpheres::state`]
    /// and the integrators check it
    /// ([`Space::check`](crate::integrate::space::Space::check): length, finite, z_k ∈ SO(3),
    /// |u| = 1): the observables are defined on the state space only (a zero or scaled z_k is not
    /// a configuration, and gives NaN or inf).
    fn observed(&self, z: &[f64]) -> Result<Local> {
        self.space().check("state", z)?;
        Ok(local(z))
    }

    fn kin(&self, l: &Local) -> Kin {
        self.kin_spatial(&l.z, &l.u, [l.z[0] * l.omega[0], l.z[1] * l.omega[1]])
    }

    fn kin_spatial(&self, z: &[Matrix3<f64>; 2], u: &Vector3<f64>, w: [Vector3<f64>; 2]) -> Kin {
        let eps = [z[0] * self.e[0], z[1] * self.e[1]];
        let udot = (w[0] * self.alpha[0] + w[1] * self.alpha[1]).cross(u);
        let s = [(u - eps[0]) * self.alpha[0], (u + eps[1]) * self.alpha[1]];
        Kin { w, eps, udot, s }
    }

    /// ṡ₁ = α₁(u̇ − ω₁ × ε₁), ṡ₂ = α₂(u̇ + ω₂ × ε₂) (ṡ₁ + ṡ₂ = w identically).
    fn sdot(&self, k: &Kin) -> [Vector3<f64>; 2] {
        [
            (k.udot - k.w[0].cross(&k.eps[0])) * self.alpha[0],
            (k.udot + k.w[1].cross(&k.eps[1])) * self.alpha[1],
        ]
    }

    /// u̇ of the rolling constraint (10), u̇ = (α₁z₁Ω₁ + α₂z₂Ω₂) × u.
    pub fn udot(&self, z: &[f64]) -> Result<[f64; 3]> {
        finite1("u̇", arr(&self.kin(&self.observed(z)?).udot))
    }

    /// The residual |R u̇ − (r₁z₁Ω₁ + r₂z₂Ω₂) × u| of (7) for a given u̇ (for tests of the
    /// velocities of computed motions).
    pub fn constraint_residual(&self, z: &[f64], udot: [f64; 3]) -> Result<f64> {
        let l = self.observed(z)?;
        check::finite_slice("udot", &udot)?;
        let v = Vector3::from(udot) * self.big_r
            - (l.z[0] * l.omega[0] * self.radii[0] + l.z[1] * l.omega[1] * self.radii[1])
                .cross(&l.u);
        Ok(finite1("the residual", [v.norm()])?[0])
    }

    /// w = ∂L/∂u̇ = u̇ − α₁b₁ + α₂b₂ = ω₁ × s₁ + ω₂ × s₂ (the relative velocity of the centres of
    /// mass over R).
    fn w(&self, k: &Kin) -> Vector3<f64> {
        k.w[0].cross(&k.s[0]) + k.w[1].cross(&k.s[1])
    }

    /// The geometric centres a₁, a₂ of (4) (centre-of-mass frame).
    pub fn centres(&self, z: &[f64]) -> Result<[[f64; 3]; 2]> {
        let l = self.observed(z)?;
        let [m1, m2] = self.masses;
        let m = m1 + m2;
        let g = l.z[0] * self.gammas[0] * m1 + l.z[1] * self.gammas[1] * m2;
        let a1 = -(g + l.u * (self.big_r * m2)) / m;
        let a2 = -(g - l.u * (self.big_r * m1)) / m;
        finite2("the centres", [arr(&a1), arr(&a2)])
    }

    /// The centres of mass x_k = z_kγ_k + a_k.
    pub fn centres_of_mass(&self, z: &[f64]) -> Result<[[f64; 3]; 2]> {
        let a = self.centres(z)?;
        let l = local(z);
        Ok([0, 1].map(|i| arr(&(l.z[i] * self.gammas[i] + Vector3::from(a[i])))))
    }

    /// The contact point c = a₁ + r₁u = a₂ − r₂u.
    pub fn contact_point(&self, z: &[f64]) -> Result<[f64; 3]> {
        let a = self.centres(z)?;
        Ok(arr(
            &(Vector3::from(a[0]) + Vector3::from_column_slice(&z[18..21]) * self.radii[0])
        ))
    }
}

/// The values, or an overflow error naming the state where one exceeds the f64 range (a
/// valid state with velocities near the end of the range).
fn finite1<const N: usize>(quantity: &str, v: [f64; N]) -> Result<[f64; N]> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(check::overflow_error("state", quantity))
    }
}

/// [`finite1`] for a pair of 3-vectors.
fn finite2(quantity: &str, v: [[f64; 3]; 2]) -> Result<[[f64; 3]; 2]> {
    finite1(quantity, v[0])?;
    finite1(quantity, v[1])?;
    Ok(v)
}
