//! The reduced pseudo-rigid body on the principal stratum (001 §7, (6.30), (7.24)–(7.28)) and a
//! reduced-space integrator that keeps p_Ω and p_Λ on their coadjoint orbits exactly.
//!
//! # Reduced coordinates
//! On the principal stratum (distinct singular values) X = R A Sᵀ, and T*GL⁺(n) / (SO(n)×SO(n))
//! has coordinates (a, p_a, μ, ν): the singular values a, p_a = diag(RᵀPS) = ȧ, and the body
//! momenta μ = p_Ω = RᵀLR, ν = p_Λ = SᵀΓS (001 (4.15), (2.32)). [`reduce`] maps (X, P) to them
//! (and to the frames R, S); [`reconstruct`] maps back, with P = R(ΩA + diag(p_a) − AΛ)Sᵀ and
//! Ω ⊕ Λ = B_A⁻¹(μ ⊕ ν) (the (8.1)-type reconstruction RᵀṘ ⊕ SᵀṠ = B_A⁻¹(p_Ω ⊕ p_Λ)).
//!
//! # Reduced Hamiltonian
//! (6.30): H = ½|p_a|² + ½⟨μ ⊕ ν, B_A⁻¹(μ ⊕ ν)⟩ + U(a). Derived again from the closed form of
//! B_A⁻¹ (001 (7.9)): for i < j, with m = μ_ij, v = ν_ij, d± = a_i ± a_j,
//!
//! ((a_i² + a_j²)(m² + v²) + 4a_i a_j m v)/(a_i² − a_j²)² = ½((m + v)²/d₋² + (m − v)²/d₊²),
//!
//! so the rotational kinetic energy is a sum of pair terms
//! K = Σ_{i<j} K_ij, K_ij = ¼((μ_ij + ν_ij)²/(a_i − a_j)² + (μ_ij − ν_ij)²/(a_i + a_j)²)
//! (the eigenvalues (a_i ∓ a_j)² of B_A, 001 (8.15)), with
//! Ω_ij = ∂K/∂μ_ij = ½((m + v)/d₋² + (m − v)/d₊²), Λ_ij = ½((m + v)/d₋² − (m − v)/d₊²) (these
//! reproduce (7.9)).
//!
//! # Reduced equations (001 (7.24)–(7.28))
//! ȧ = p_a, ṗ_a = −∂K/∂a − ∂U/∂a, μ̇ = [μ, Ω], ν̇ = [ν, Λ]: canonical in (a, p_a) and the
//! Lie–Poisson equations on so(n)* ⊕ so(n)* (signs from d/dt(RᵀLR) = [RᵀLR, RᵀṘ] with L
//! constant, as in Prop. 4.2 (4.11b)–(4.11c)). −∂K/∂a at fixed (μ, ν) equals E of (4.8)
//! (Legendre transform: ∂K/∂a|_(μ,ν) = −∂K/∂a|_(Ω,Λ)); the tests check the field against
//! [`FullBody::lagrange_vector_field`] and against finite differences of the full flow.
//!
//! # The integrator (method `"reduced"`: `Splitting` over the reduced flows, [`ReducedWork`])
//! H = T + U + Σ_{i<j} K_ij with T = ½|p_a|². Every piece has an exact flow:
//! - T: a ← a + t p_a;
//! - U: p_a ← p_a − t ∂U/∂a;
//! - K_ij (a fixed): μ_ij, ν_ij are conserved (a 2×2 skew block commutes with rotations of its
//!   plane), so Ω = Ω_ij E_ij and Λ = Λ_ij E_ij are constant and the flow is μ ← GμGᵀ with the
//!   Givens rotation G = exp(−tΩ_ij E_ij), ν ← G'νG'ᵀ with G' = exp(−tΛ_ij E_ij),
//!   p_a ← p_a − t ∂K_ij/∂a (entries i, j only), and the frames follow exactly:
//!   R ← R Gᵀ, S ← S G'ᵀ (Ṙ = RΩ, Ṡ = SΛ with constant Ω, Λ).
//!
//! One step is the palindromic Strang composition of these flows (`Composition::sequence`),
//! T(h/2) U(h/2) K₁₂(h/2) … K_last(h) … K₁₂(h/2) U(h/2) T(h/2): symmetric, order 2, a Poisson
//! map of the reduced space (a composition of exact Hamiltonian flows) and, with the frames, a
//! symplectic map of T*GL⁺(n). It preserves exactly (to round-off):
//! - the coadjoint orbits of μ and ν (they change only by orthogonal conjugations), so their
//!   spectra, i.e. the Casimirs ½tr((μᵀμ)^k), ½tr((νᵀν)^k);
//! - L = RμRᵀ and Γ = SνSᵀ (each sub-flow conjugates μ and rotates R by the same G);
//! - det X = Π a_i > 0 is required: the reduced coordinates exist only on GL⁺(n), so the method
//!   stops with [`Error::LeftDomain`] when some a_i ≤ 0 or two a_i meet (principal stratum left).
//!
//! Step size: the rotation rates Ω_ij, Λ_ij grow like |μ_ij + ν_ij|/(a_i − a_j)² when two
//! semi-axes approach each other, and the splitting error with them; the step must resolve the
//! closest approach (Verlet, which has no such coordinate singularity, does not need this).
//! Generic motions do pass close to the boundary (an avoided crossing of two a_i while
//! μ_ij + ν_ij is small); a step whose rotation substep turns by more than [`MAX_ANGLE`] stops the
//! run with [`Error::LeftDomain`] naming the time, rather than return inaccurate data.
//!
//! [`super::PseudoRigidBody`] is a `Split` problem with these flows (flow 0 = T, 1 = U, then the
//! pairs (i, j) in e_ij order); its working state is a [`ReducedWork`], so a run reduces (X, P)
//! once and reconstructs only when a state is read.
//!
//! Each K_ij flow costs O(n) (two Givens conjugations, two column rotations), so a step costs
//! O(n³) (n(n−1)/2 pairs, plus one gradient of U at diag(a)).

use faer::{Accum, MatMut, MatRef};

use crate::check;
use crate::error::{Error, Result};
use crate::integrate::problem::Violation;
use crate::lie::{gl, so};
use crate::numerics::linalg;
use crate::pseudo_rigid::dynamics::FullBody;
use crate::pseudo_rigid::momentum::{self, momentum_map_unchecked};
use crate::pseudo_rigid::potential::{Potential, Workspace};
use crate::Mat;

/// A point (a, p_a, μ = p_Ω, ν = p_Λ) of the reduced space of 001 §7 (principal stratum).
#[derive(Debug, Clone, PartialEq)]
pub struct ReducedState {
    /// Singular values a_i > 0, pairwise distinct (any order).
    pub a: Vec<f64>,
    /// Momenta conjugate to a (p_a = ȧ).
    pub p_a: Vec<f64>,
    /// Body angular momentum p_Ω = RᵀLR ∈ so(n)* (skew n×n).
    pub p_omega: Mat,
    /// Body circulation p_Λ = SᵀΓS ∈ so(n)* (skew n×n).
    pub p_lambda: Mat,
}

/// Time derivatives of a [`ReducedState`] (001 (7.24)–(7.28)).
#[derive(Debug, Clone, PartialEq)]
pub struct ReducedRates {
    /// ȧ = p_a.
    pub a_dot: Vec<f64>,
    /// ṗ_a = −∂K/∂a − ∂U/∂a (= E − ∂U/∂A of 001 (4.11a)).
    pub p_a_dot: Vec<f64>,
    /// μ̇ = [μ, Ω].
    pub p_omega_dot: Mat,
    /// ν̇ = [ν, Λ].
    pub p_lambda_dot: Mat,
}

/// The pair term K_ij of the rotational kinetic energy and its derivatives (module docs).
#[derive(Debug, Clone, Copy)]
struct Pair {
    k: f64,
    omega: f64,
    lambda: f64,
    dk_dai: f64,
    dk_daj: f64,
}

fn pair(ai: f64, aj: f64, m: f64, v: f64) -> Pair {
    let (dm, dp) = (ai - aj, ai + aj);
    let (s, d) = (m + v, m - v);
    let (qm, qp) = (s / (dm * dm), d / (dp * dp));
    Pair {
        k: 0.25 * (s * qm + d * qp),
        omega: 0.5 * (qm + qp),
        lambda: 0.5 * (qm - qp),
        dk_dai: -0.5 * (s * qm / dm + d * qp / dp),
        dk_daj: 0.5 * (s * qm / dm - d * qp / dp),
    }
}

/// The derivative of a [`Pair`]'s rates and forces along (δa_i, δa_j, δm, δv): with s = m + v,
/// d = m − v, d∓ = a_i ∓ a_j, Ω_ij ± Λ_ij = s/d₋², d/d₊² (·2/2) and ∂K/∂a_{i,j} =
/// ∓½ s²/d₋³ − ½ d²/d₊³ (signs per the module docs).
#[derive(Debug, Clone, Copy)]
struct PairTangent {
    omega: f64,
    lambda: f64,
    dk_dai: f64,
    dk_daj: f64,
}

#[allow(clippy::too_many_arguments)]
fn pair_tangent(
    ai: f64,
    aj: f64,
    m: f64,
    v: f64,
    dai: f64,
    daj: f64,
    dm: f64,
    dv: f64,
) -> PairTangent {
    let (dmi, dpl) = (ai - aj, ai + aj);
    let (s, d) = (m + v, m - v);
    let (ds, dd) = (dm + dv, dm - dv);
    let (ddm, ddp) = (dai - daj, dai + daj);
    // δ(s/d₋²), δ(d/d₊²); δ(s²/d₋³), δ(d²/d₊³).
    let dqm = ds / (dmi * dmi) - 2.0 * s * ddm / (dmi * dmi * dmi);
    let dqp = dd / (dpl * dpl) - 2.0 * d * ddp / (dpl * dpl * dpl);
    let dcm = (2.0 * s * ds - 3.0 * s * s * ddm / dmi) / (dmi * dmi * dmi);
    let dcp = (2.0 * d * dd - 3.0 * d * d * ddp / dpl) / (dpl * dpl * dpl);
    PairTangent {
        omega: 0.5 * (dqm + dqp),
        lambda: 0.5 * (dqm - dqp),
        dk_dai: -0.5 * (dcm + dcp),
        dk_daj: 0.5 * (dcm - dcp),
    }
}

impl ReducedState {
    /// Checks lengths, finiteness, a_i > 0 distinct, μ, ν skew; returns n.
    pub fn validate(&self) -> Result<usize> {
        let n = self.a.len();
        if n < 2 {
            return Err(Error::shape("a", "(n,) with n ≥ 2", format!("({n},)")));
        }
        check::finite_slice("a", &self.a)?;
        check::len_of("p_a", &self.p_a, n)?;
        check::finite_slice("p_a", &self.p_a)?;
        so::check_algebra_of("p_omega", &self.p_omega, n)?;
        so::check_algebra_of("p_lambda", &self.p_lambda, n)?;
        if let Some(i) = self.a.iter().position(|&ai| ai <= 0.0) {
            return Err(Error::invalid(
                "a",
                format!("singular values must be > 0, got a[{i}] = {}", self.a[i]),
            ));
        }
        let amax = self.a.iter().copied().fold(0.0, f64::max);
        let tol = gl::STRATUM_TOL * amax;
        let mut gap = f64::INFINITY;
        for i in 0..n {
            for j in i + 1..n {
                gap = gap.min((self.a[i] - self.a[j]).abs());
            }
        }
        if gap <= tol {
            return Err(Error::DegenerateStratum {
                what: "reduced state (a)".into(),
                gap,
                tol,
            });
        }
        Ok(n)
    }

    /// Body velocities Ω ⊕ Λ = B_A⁻¹(p_Ω ⊕ p_Λ) (001 (7.9)), the right-hand side of the
    /// reconstruction equations RᵀṘ = Ω, SᵀṠ = Λ (001 (8.1)-type).
    ///
    /// Scale-aware (`ReducedState::velocities_scaled`): an overflow error where Ω or Λ exceeds
    /// the f64 range.
    pub fn velocities(&self) -> Result<(Mat, Mat)> {
        let n = self.validate()?;
        let (o, l, em, ea) = self.velocities_scaled(n);
        let what = "a, p_Omega, p_Lambda";
        let q = "the body velocities Ω ⊕ Λ = B_A⁻¹(p_Ω ⊕ p_Λ)";
        Ok((
            check::unscale_mat(what, q, &o, em - 2 * ea)?,
            check::unscale_mat(what, q, &l, em - 2 * ea)?,
        ))
    }

    fn velocities_unchecked(&self, n: usize) -> (Mat, Mat) {
        let (o, l, em, ea) = self.velocities_scaled(n);
        (
            check::ldexp_mat(&o, em - 2 * ea),
            check::ldexp_mat(&l, em - 2 * ea),
        )
    }

    /// (Ω̃, Λ̃, em, ea) with Ω ⊕ Λ = 2^(em − 2ea)(Ω̃ ⊕ Λ̃): the pair formulas evaluated on
    /// ã = a·2^−ea and (μ, ν)·2^−em ([`check::pow2_exponent`]; both 0, i.e. the plain formula,
    /// for moderate values), so that (a_i ∓ a_j)² neither underflow nor overflow where Ω ⊕ Λ,
    /// or the momentum P of [`reconstruct`] (degree −1 in a), is representable.
    fn velocities_scaled(&self, n: usize) -> (Mat, Mat, i32, i32) {
        let ea = check::pow2_exponent_of(self.a.iter().copied());
        let em =
            check::pow2_exponent(check::max_abs(&self.p_omega).max(check::max_abs(&self.p_lambda)));
        let mut omega = Mat::zeros(n, n);
        let mut lambda = Mat::zeros(n, n);
        for i in 0..n {
            for j in i + 1..n {
                let q = pair(
                    check::ldexp(self.a[i], -ea),
                    check::ldexp(self.a[j], -ea),
                    check::ldexp(self.p_omega[(i, j)], -em),
                    check::ldexp(self.p_lambda[(i, j)], -em),
                );
                omega[(i, j)] = q.omega;
                omega[(j, i)] = -q.omega;
                lambda[(i, j)] = q.lambda;
                lambda[(j, i)] = -q.lambda;
            }
        }
        (omega, lambda, em, ea)
    }

    fn pair(&self, i: usize, j: usize) -> Pair {
        pair(
            self.a[i],
            self.a[j],
            self.p_omega[(i, j)],
            self.p_lambda[(i, j)],
        )
    }

    /// The reduced Hamiltonian (001 (6.30)): ½|p_a|² + ½⟨μ ⊕ ν, B_A⁻¹(μ ⊕ ν)⟩ + U(a).
    pub fn hamiltonian(&self, body: &FullBody) -> Result<f64> {
        let n = self.check_body(body)?;
        let mut k = 0.5 * dot(&self.p_a, &self.p_a);
        for i in 0..n {
            for j in i + 1..n {
                k += self.pair(i, j).k;
            }
        }
        let mut ws = Workspace::new(n);
        Ok(k + body.potential().value(diag(&self.a).as_ref(), &mut ws))
    }

    /// The reduced vector field (001 (7.24)–(7.28), module docs).
    pub fn vector_field(&self, body: &FullBody) -> Result<ReducedRates> {
        let n = self.check_body(body)?;
        let (omega, lambda) = self.velocities_unchecked(n);
        let mut grad = Mat::zeros(n, n);
        let mut ws = Workspace::new(n);
        body.potential()
            .add_gradient(diag(&self.a).as_ref(), grad.as_mut(), &mut ws);
        let mut p_a_dot: Vec<f64> = (0..n).map(|i| -grad[(i, i)]).collect();
        for i in 0..n {
            for j in i + 1..n {
                let q = self.pair(i, j);
                p_a_dot[i] -= q.dk_dai;
                p_a_dot[j] -= q.dk_daj;
            }
        }
        Ok(ReducedRates {
            a_dot: self.p_a.clone(),
            p_a_dot,
            p_omega_dot: so::bracket(&self.p_omega, &omega),
            p_lambda_dot: so::bracket(&self.p_lambda, &lambda),
        })
    }

    /// The derivatives (δΩ, δΛ) of the body velocities Ω ⊕ Λ = B_A⁻¹(μ ⊕ ν) along a tangent
    /// vector `d` = (δa, δp_a, δμ, δν) (a [`ReducedState`] read as a direction; 001 (7.9)
    /// differentiated pair by pair).
    pub fn velocities_tangent(&self, d: &ReducedState) -> (Mat, Mat) {
        let n = self.a.len();
        let (mut om, mut la) = (Mat::zeros(n, n), Mat::zeros(n, n));
        for i in 0..n {
            for j in i + 1..n {
                let q = self.pair_tangent(i, j, d);
                (om[(i, j)], om[(j, i)]) = (q.omega, -q.omega);
                (la[(i, j)], la[(j, i)]) = (q.lambda, -q.lambda);
            }
        }
        (om, la)
    }

    /// The derivative of the reduced vector field ([`ReducedState::vector_field`]) along `d` =
    /// (δa, δp_a, δμ, δν): δȧ = δp_a, δṗ_a = −D²U(A)δa − δ(∂K/∂a), δμ̇ = [δμ, Ω] + [μ, δΩ],
    /// δν̇ = [δν, Λ] + [ν, δΛ] — exact (the potential's Hessian, the pair formulas' derivatives).
    pub fn vector_field_tangent(&self, body: &FullBody, d: &ReducedState) -> Result<ReducedRates> {
        let n = self.check_body(body)?;
        for (what, len) in [("δa", d.a.len()), ("δp_a", d.p_a.len())] {
            if len != n {
                return Err(Error::shape(what, format!("({n},)"), format!("({len},)")));
            }
        }
        so::check_algebra_of("δp_omega", &d.p_omega, n)?;
        so::check_algebra_of("δp_lambda", &d.p_lambda, n)?;
        let (omega, lambda) = self.velocities_unchecked(n);
        let (domega, dlambda) = self.velocities_tangent(d);
        let mut ws = Workspace::new(n);
        let mut h = Mat::zeros(n, n);
        body.potential().add_hessian(
            diag(&self.a).as_ref(),
            diag(&d.a).as_ref(),
            h.as_mut(),
            &mut ws,
        );
        let mut p_a_dot: Vec<f64> = (0..n).map(|i| -h[(i, i)]).collect();
        for i in 0..n {
            for j in i + 1..n {
                let q = self.pair_tangent(i, j, d);
                p_a_dot[i] -= q.dk_dai;
                p_a_dot[j] -= q.dk_daj;
            }
        }
        Ok(ReducedRates {
            a_dot: d.p_a.clone(),
            p_a_dot,
            p_omega_dot: so::bracket(&d.p_omega, &omega) + so::bracket(&self.p_omega, &domega),
            p_lambda_dot: so::bracket(&d.p_lambda, &lambda) + so::bracket(&self.p_lambda, &dlambda),
        })
    }

    fn pair_tangent(&self, i: usize, j: usize, d: &ReducedState) -> PairTangent {
        pair_tangent(
            self.a[i],
            self.a[j],
            self.p_omega[(i, j)],
            self.p_lambda[(i, j)],
            d.a[i],
            d.a[j],
            d.p_omega[(i, j)],
            d.p_lambda[(i, j)],
        )
    }

    fn check_body(&self, body: &FullBody) -> Result<usize> {
        let n = self.validate()?;
        if n != body.n() {
            return Err(Error::shape(
                "reduced state",
                format!("n = {} (the body's dimension)", body.n()),
                format!("n = {n}"),
            ));
        }
        Ok(n)
    }
}

/// Reduction (X, P) ↦ (a, p_a, p_Ω, p_Λ) on the principal stratum (001 §7), with the frames:
/// X = R A Sᵀ ([`gl::svd_coordinates`], a decreasing), p_a = diag(RᵀPS), p_Ω = RᵀLR,
/// p_Λ = SᵀΓS. Returns (reduced state, R, S).
///
/// Errors: shapes, non-finite, det X ≤ 0, [`Error::DegenerateStratum`] off the principal stratum, an
/// overflow error where a reduced momentum exceeds the f64 range.
pub fn reduce(x: &Mat, p: &Mat) -> Result<(ReducedState, Mat, Mat)> {
    let n = gl::check_gl_plus("X", x)?;
    check::square_of("P", p, n)?;
    check::finite_mat("P", p)?;
    let c = gl::svd_coordinates(x)?;
    c.require_principal("reduction to (a, p_a, p_Omega, p_Lambda)")?;
    let m = c.r.transpose() * p * &c.s;
    let (l, g) = momentum_map_unchecked(x, p);
    let state = ReducedState {
        p_a: (0..n).map(|i| m[(i, i)]).collect(),
        p_omega: c.r.transpose() * l * &c.r,
        p_lambda: c.s.transpose() * g * &c.s,
        a: c.a,
    };
    let finite = |v: &Mat| (0..n).all(|i| (0..n).all(|j| v[(i, j)].is_finite()));
    if !(state.p_a.iter().all(|v| v.is_finite())
        && finite(&state.p_omega)
        && finite(&state.p_lambda))
    {
        return Err(check::overflow_error(
            "X, P",
            "a reduced momentum (p_a, p_Ω or p_Λ)",
        ));
    }
    Ok((state, c.r, c.s))
}

/// Reconstruction (R, S, a, p_a, p_Ω, p_Λ) ↦ (X, P): X = R A Sᵀ, P = R(ΩA + diag(p_a) − AΛ)Sᵀ
/// with Ω ⊕ Λ = B_A⁻¹(p_Ω ⊕ p_Λ) (001 §4.1, (7.9)). The inverse of [`reduce`].
///
/// Errors: R, S not rotations, an invalid reduced state ([`ReducedState::validate`]), an
/// overflow error where P exceeds the f64 range. Scale-aware: ΩA − AΛ (degree −1 in a) is
/// formed from the scaled pair formulas (`ReducedState::velocities_scaled`), so tiny or huge
/// a give the representable P although Ω, Λ alone may not be representable.
pub fn reconstruct(r: &Mat, s: &Mat, state: &ReducedState) -> Result<(Mat, Mat)> {
    let n = state.validate()?;
    let x = gl::from_svd(r, &state.a, s)?;
    let p = lift_momentum(r, s, state, n);
    check::unscale_mat("a, p_a, p_Omega, p_Lambda", "the momentum P", &p, 0)?;
    Ok((x, p))
}

/// P = R(ΩA + diag(p_a) − AΛ)Sᵀ with Ω ⊕ Λ = B_A⁻¹(μ ⊕ ν), scale-aware (entries ±inf where P is
/// not representable).
fn lift_momentum(r: &Mat, s: &Mat, state: &ReducedState, n: usize) -> Mat {
    let (omega, lambda, em, ea) = state.velocities_scaled(n);
    let a = Mat::from_fn(n, n, |i, j| {
        if i == j {
            check::ldexp(state.a[i], -ea)
        } else {
            0.0
        }
    });
    let rot = check::ldexp_mat(&(&omega * &a - &a * &lambda), em - ea);
    let m = rot + diag(&state.p_a);
    r * m * s.transpose()
}

/// B_A(Ω ⊕ Λ) for the Ω ⊕ Λ of [`ReducedState::velocities`]: recovers (p_Ω, p_Λ), a second
/// route through the bi-inertia tensor (001 (6.27)) that checks the pair formula for (7.9).
pub fn momenta_of_velocities(state: &ReducedState) -> Result<(Mat, Mat)> {
    let (o, l) = state.velocities()?;
    momentum::body_momenta(&state.a, &o, &l)
}

/// The working state of the reduced splitting (module docs): (a, p_a, μ, ν), the frames (R, S),
/// the scratch of the U flow and the largest rotation angle of the current step; no allocation
/// per step.
#[derive(Debug)]
pub struct ReducedWork {
    pairs: Vec<(usize, usize)>,
    /// Current reduced state.
    pub state: ReducedState,
    /// Current left frame R.
    pub r: Mat,
    /// Current right frame S.
    pub s: Mat,
    amat: Mat,
    grad: Mat,
    ws: Workspace,
    angle: f64,
}

impl Clone for ReducedWork {
    fn clone(&self) -> Self {
        let n = self.state.a.len();
        ReducedWork {
            pairs: self.pairs.clone(),
            state: self.state.clone(),
            r: self.r.clone(),
            s: self.s.clone(),
            amat: Mat::zeros(n, n),
            grad: Mat::zeros(n, n),
            ws: Workspace::new(n),
            angle: self.angle,
        }
    }

    /// Without allocation (the tangent lift keeps the point before each flow).
    fn clone_from(&mut self, other: &Self) {
        if self.state.a.len() != other.state.a.len() {
            *self = other.clone();
            return;
        }
        let (s, o) = (&mut self.state, &other.state);
        s.a.copy_from_slice(&o.a);
        s.p_a.copy_from_slice(&o.p_a);
        s.p_omega.copy_from(&o.p_omega);
        s.p_lambda.copy_from(&o.p_lambda);
        self.r.copy_from(&other.r);
        self.s.copy_from(&other.s);
        self.angle = other.angle;
    }
}

impl ReducedWork {
    /// Reduces (X, P) ([`reduce`]).
    pub fn new(x: &Mat, p: &Mat) -> Result<Self> {
        let (state, r, s) = reduce(x, p)?;
        let n = state.a.len();
        Ok(ReducedWork {
            pairs: (0..n)
                .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
                .collect(),
            state,
            r,
            s,
            amat: Mat::zeros(n, n),
            grad: Mat::zeros(n, n),
            ws: Workspace::new(n),
            angle: 0.0,
        })
    }

    /// The number of exact flows: T, U and one per pair i < j.
    pub fn flows(n: usize) -> usize {
        2 + n * (n - 1) / 2
    }

    /// The current (X, P) (reconstructed).
    pub fn full_state(&self) -> (Mat, Mat) {
        let n = self.state.a.len();
        let x = &self.r * diag(&self.state.a) * self.s.transpose();
        (x, lift_momentum(&self.r, &self.s, &self.state, n))
    }

    /// The exact flow i over time τ with potential U: 0 = T, 1 = U, 2 + k = the k-th pair.
    pub fn flow(&mut self, i: usize, t: f64, potential: &dyn Potential) {
        let st = &mut self.state;
        let n = st.a.len();
        match i {
            0 => {
                for (a, p) in st.a.iter_mut().zip(&st.p_a) {
                    *a += t * p;
                }
            }
            1 => {
                for k in 0..n {
                    self.amat[(k, k)] = st.a[k];
                }
                self.grad.fill(0.0);
                potential.add_gradient(self.amat.as_ref(), self.grad.as_mut(), &mut self.ws);
                for k in 0..n {
                    st.p_a[k] -= t * self.grad[(k, k)];
                }
            }
            f => {
                let (i, j) = self.pairs[f - 2];
                let q = st.pair(i, j);
                self.angle = self
                    .angle
                    .max((t * q.omega).abs())
                    .max((t * q.lambda).abs());
                st.p_a[i] -= t * q.dk_dai;
                st.p_a[j] -= t * q.dk_daj;
                let (sw, cw) = (t * q.omega).sin_cos();
                givens_conj(&mut st.p_omega, i, j, cw, sw);
                givens_cols(&mut self.r, i, j, cw, sw);
                let (sl, cl) = (t * q.lambda).sin_cos();
                givens_conj(&mut st.p_lambda, i, j, cl, sl);
                givens_cols(&mut self.s, i, j, cl, sl);
            }
        }
    }

    /// Checks the state after a step: some a_i ≤ 0, two a_i reordered (met), a non-finite value,
    /// or a rotation substep larger than [`MAX_ANGLE`] end the run.
    pub fn check_step(&mut self) -> std::result::Result<(), Violation> {
        let state = &self.state;
        let n = state.a.len();
        let angle = std::mem::take(&mut self.angle);
        let bad = state.a.iter().any(|&a| a.is_nan() || a <= 0.0)
            || state.p_a.iter().any(|p| !p.is_finite());
        if bad {
            return Err(Violation {
                what: format!("reduced pseudo-rigid body state (a, p_a) in GL+({n})"),
                message: format!(
                    "a = {:?}, p_a = {:?}: the motion left the principal stratum of GL+({n}) (a \
                     singular value reached 0, two met, or the state overflowed); the reduced \
                     method needs distinct a_i > 0 — use method 'verlet' for such motions",
                    state.a, state.p_a
                ),
            });
        }
        // The exact flow cannot reorder the a_i (the barrier (μ_ij + ν_ij)²/(4(a_i − a_j)²)
        // repels them); a step that does has jumped over an unresolved near-collision.
        let crossed = state.a.windows(2).any(|w| w[0] <= w[1]);
        if angle > MAX_ANGLE || crossed {
            return Err(Violation {
                what: format!(
                    "reduced pseudo-rigid body state (a) near the boundary of the principal \
                     stratum of GL+({n})"
                ),
                message: format!(
                    "a = {:?}: two semi-axes came so close that a step reordered them or a \
                     rotation substep turned by {angle:.2} rad (limit {MAX_ANGLE} rad; the rates \
                     Ω_ij, Λ_ij grow like 1/(a_i − a_j)²); the step does not resolve the motion \
                     there — reduce dt or use method 'verlet', which has no such singularity",
                    state.a
                ),
            });
        }
        Ok(())
    }
}

/// The tangent maps of the reduced splitting (issue 26, [`crate::integrate::tangent`]).
///
/// A direction (δX, δP) at the working point is carried in the working form's coordinates
/// (δa, δp_a, δμ, δν, ξ, η) with δR = Rξ, δS = Sη (the skew δμ, δν, ξ, η by their entries
/// i < j in pair order): 2n² values, as many as (δX, δP). From X = RASᵀ,
/// RᵀδXS = ξA + δA − Aη, so δa_i is its diagonal and, for i < j, with M = RᵀδXS,
/// ξ_ij = (a_j M_ij + a_i M_ji)/(a_j² − a_i²), η_ij = (a_i M_ij + a_j M_ji)/(a_j² − a_i²)
/// (solvable on the principal stratum). From P = RΠSᵀ with Π = ΩA + diag(p_a) − AΛ, the pair
/// formulas give Π_ij = −s/(2d₋) + d/(2d₊), Π_ji = −s/(2d₋) − d/(2d₊) (s = μ_ij + ν_ij,
/// d = μ_ij − ν_ij, d∓ = a_i ∓ a_j), i.e. s = −d₋(Π_ij + Π_ji), d = d₊(Π_ij − Π_ji): δΠ =
/// RᵀδPS − ξΠ + Πη, δp_a its diagonal, and (δμ_ij, δν_ij) from the derivatives of s and d.
///
/// The flows' tangent maps in these coordinates: T: δa += τδp_a; U: δp_a −= τ D²U(A)δa on the
/// diagonal; K_ij (a, μ_ij, ν_ij fixed, so δΩ_ij, δΛ_ij are constant along it):
/// δp_a −= τ δ(∂K_ij/∂a), δμ ← G(δμ + τδΩ_ij[μ, E_ij])Gᵀ, ξ ← GξGᵀ + τδΩ_ij E_ij with the
/// flow's G = exp(−τΩ_ij E_ij) (from R′ = RGᵀ: R′ᵀδR′ = GξGᵀ + GδGᵀ), and the same for (ν, η)
/// with Λ_ij.
impl ReducedWork {
    /// (δX, δP) ↦ (δa, δp_a, δμ, δν, ξ, η) at this point, for every direction in `dirs`.
    pub fn tangent_in(&self, dirs: &mut [f64]) {
        TangentScratch::with(self.state.a.len(), |t| self.tangent_in_with(t, dirs));
    }

    fn tangent_in_with(&self, t: &mut TangentScratch, dirs: &mut [f64]) {
        let n = self.state.a.len();
        let nn = n * n;
        let pi = self.pi();
        let a = &self.state.a;
        for dz in dirs.chunks_exact_mut(2 * nn) {
            for (k, m) in [&mut t.ms, &mut t.ns].into_iter().enumerate() {
                let v = MatRef::from_row_major_slice(&dz[k * nn..(k + 1) * nn], n, n);
                linalg::mul(t.tmp.as_mut(), Accum::Replace, self.r.transpose(), v, 1.0);
                linalg::mul(
                    m.as_mut(),
                    Accum::Replace,
                    t.tmp.as_ref(),
                    self.s.as_ref(),
                    1.0,
                );
            }
            for (k, &(i, j)) in self.pairs.iter().enumerate() {
                let (mij, mji) = (t.ms[(i, j)], t.ms[(j, i)]);
                let den = a[j] * a[j] - a[i] * a[i];
                let (x, e) = (
                    (a[j] * mij + a[i] * mji) / den,
                    (a[i] * mij + a[j] * mji) / den,
                );
                (t.xi[(i, j)], t.xi[(j, i)], t.eta[(i, j)], t.eta[(j, i)]) = (x, -x, e, -e);
                t.out[Slot::Xi.at(n, k)] = x;
                t.out[Slot::Eta.at(n, k)] = e;
            }
            // δΠ = N − ξΠ + Πη.
            linalg::mul(t.ns.as_mut(), Accum::Add, t.xi.as_ref(), pi.as_ref(), -1.0);
            linalg::mul(t.ns.as_mut(), Accum::Add, pi.as_ref(), t.eta.as_ref(), 1.0);
            for i in 0..n {
                t.out[i] = t.ms[(i, i)];
                t.out[n + i] = t.ns[(i, i)];
            }
            for (k, &(i, j)) in self.pairs.iter().enumerate() {
                let (dm, dp) = (a[i] - a[j], a[i] + a[j]);
                let (ddm, ddp) = (t.out[i] - t.out[j], t.out[i] + t.out[j]);
                let ds = -ddm * (pi[(i, j)] + pi[(j, i)]) - dm * (t.ns[(i, j)] + t.ns[(j, i)]);
                let dd = ddp * (pi[(i, j)] - pi[(j, i)]) + dp * (t.ns[(i, j)] - t.ns[(j, i)]);
                t.out[Slot::Mu.at(n, k)] = 0.5 * (ds + dd);
                t.out[Slot::Nu.at(n, k)] = 0.5 * (ds - dd);
            }
            dz.copy_from_slice(&t.out);
        }
    }

    /// (δa, δp_a, δμ, δν, ξ, η) ↦ (δX, δP) at this point: δX = R(ξA + δA − Aη)Sᵀ,
    /// δP = R(ξΠ + δΠ − Πη)Sᵀ.
    pub fn tangent_out(&self, dirs: &mut [f64]) {
        TangentScratch::with(self.state.a.len(), |t| self.tangent_out_with(t, dirs));
    }

    fn tangent_out_with(&self, t: &mut TangentScratch, dirs: &mut [f64]) {
        let n = self.state.a.len();
        let nn = n * n;
        let pi = self.pi();
        let (a, mu, nu) = (&self.state.a, &self.state.p_omega, &self.state.p_lambda);
        for dz in dirs.chunks_exact_mut(2 * nn) {
            t.load(n, &self.pairs, dz);
            let da = &dz[..n];
            for i in 0..n {
                t.ms[(i, i)] = da[i];
                t.ns[(i, i)] = dz[n + i];
            }
            for (k, &(i, j)) in self.pairs.iter().enumerate() {
                let (x, e) = (t.xi[(i, j)], t.eta[(i, j)]);
                t.ms[(i, j)] = x * a[j] - a[i] * e;
                t.ms[(j, i)] = -x * a[i] + a[j] * e;
                let (dm, dp) = (a[i] - a[j], a[i] + a[j]);
                let (ddm, ddp) = (da[i] - da[j], da[i] + da[j]);
                let (s, d) = (mu[(i, j)] + nu[(i, j)], mu[(i, j)] - nu[(i, j)]);
                let (dmu, dnu) = (dz[Slot::Mu.at(n, k)], dz[Slot::Nu.at(n, k)]);
                let (ds, dd) = (dmu + dnu, dmu - dnu);
                let sym = -0.5 * ds / dm + 0.5 * s * ddm / (dm * dm);
                let anti = 0.5 * dd / dp - 0.5 * d * ddp / (dp * dp);
                t.ns[(i, j)] = sym + anti;
                t.ns[(j, i)] = sym - anti;
            }
            linalg::mul(t.ns.as_mut(), Accum::Add, t.xi.as_ref(), pi.as_ref(), 1.0);
            linalg::mul(t.ns.as_mut(), Accum::Add, pi.as_ref(), t.eta.as_ref(), -1.0);
            for (k, m) in [&t.ms, &t.ns].into_iter().enumerate() {
                linalg::mul(
                    t.tmp.as_mut(),
                    Accum::Replace,
                    self.r.as_ref(),
                    m.as_ref(),
                    1.0,
                );
                let v = MatMut::from_row_major_slice_mut(&mut dz[k * nn..(k + 1) * nn], n, n);
                linalg::mul(v, Accum::Replace, t.tmp.as_ref(), self.s.transpose(), 1.0);
            }
        }
    }

    /// dz ← Dφ_i,τ dz for every direction (working coordinates), `self` the point before the
    /// flow.
    pub fn flow_tangent(&self, i: usize, tau: f64, potential: &dyn Potential, dirs: &mut [f64]) {
        let n = self.state.a.len();
        TangentScratch::with(n, |t| self.flow_tangent_with(t, i, tau, potential, dirs));
    }

    fn flow_tangent_with(
        &self,
        t: &mut TangentScratch,
        i: usize,
        tau: f64,
        potential: &dyn Potential,
        dirs: &mut [f64],
    ) {
        let n = self.state.a.len();
        let e = 2 * n * n;
        match i {
            0 => {
                for dz in dirs.chunks_exact_mut(e) {
                    let (da, dp) = dz.split_at_mut(n);
                    da.iter_mut().zip(&dp[..n]).for_each(|(a, p)| *a += tau * p);
                }
            }
            1 => {
                // H_kl = ∂²U/∂a_k∂a_l = D²U(A)[E_ll]_kk, formed once.
                let (amat, unit, out) = (&mut t.tmp, &mut t.ms, &mut t.ns);
                amat.fill(0.0);
                unit.fill(0.0);
                for k in 0..n {
                    amat[(k, k)] = self.state.a[k];
                }
                for l in 0..n {
                    unit[(l, l)] = 1.0;
                    out.fill(0.0);
                    potential.add_hessian(amat.as_ref(), unit.as_ref(), out.as_mut(), &mut t.ws);
                    unit[(l, l)] = 0.0;
                    for k in 0..n {
                        t.h[(k, l)] = out[(k, k)];
                    }
                }
                for dz in dirs.chunks_exact_mut(e) {
                    for k in 0..n {
                        let hk: f64 = (0..n).map(|l| t.h[(k, l)] * dz[l]).sum();
                        dz[n + k] -= tau * hk;
                    }
                }
            }
            f => {
                let k = f - 2;
                let (i, j) = self.pairs[k];
                let st = &self.state;
                let q = st.pair(i, j);
                let (mu, nu) = (&st.p_omega, &st.p_lambda);
                let (sw, cw) = (tau * q.omega).sin_cos();
                let (sl, cl) = (tau * q.lambda).sin_cos();
                for dz in dirs.chunks_exact_mut(e) {
                    let dq = pair_tangent(
                        st.a[i],
                        st.a[j],
                        mu[(i, j)],
                        nu[(i, j)],
                        dz[i],
                        dz[j],
                        dz[Slot::Mu.at(n, k)],
                        dz[Slot::Nu.at(n, k)],
                    );
                    dz[n + i] -= tau * dq.dk_dai;
                    dz[n + j] -= tau * dq.dk_daj;
                    t.load(n, &self.pairs, dz);
                    for (m, dm_, frame, turn, c, sn) in [
                        (mu, &mut t.ms, &mut t.xi, dq.omega, cw, sw),
                        (nu, &mut t.ns, &mut t.eta, dq.lambda, cl, sl),
                    ] {
                        // δm + τδΩ[m, E]: [m, E] = mE − Em touches rows and columns i, j.
                        let c_ = tau * turn;
                        for r in 0..n {
                            dm_[(r, j)] += c_ * m[(r, i)];
                            dm_[(r, i)] -= c_ * m[(r, j)];
                            dm_[(i, r)] -= c_ * m[(j, r)];
                            dm_[(j, r)] += c_ * m[(i, r)];
                        }
                        givens_conj(dm_, i, j, c, sn);
                        givens_conj(frame, i, j, c, sn);
                        frame[(i, j)] += c_;
                        frame[(j, i)] -= c_;
                    }
                    t.store(n, &self.pairs, dz);
                }
            }
        }
    }

    /// dz += ∂φ_i,τ/∂θ_m: only U's flow moves with the potential's constants,
    /// δp_a −= τ ∂(∂U/∂a)/∂θ_m.
    pub fn flow_parameter(
        &self,
        i: usize,
        tau: f64,
        potential: &dyn Potential,
        m: usize,
        dz: &mut [f64],
    ) {
        if i != 1 {
            return;
        }
        let n = self.state.a.len();
        let mut ws = Workspace::new(n);
        let mut g = Mat::zeros(n, n);
        potential.add_parameter_gradient(diag(&self.state.a).as_ref(), m, g.as_mut(), &mut ws);
        for k in 0..n {
            dz[n + k] -= tau * g[(k, k)];
        }
    }

    /// Π = RᵀPS = ΩA + diag(p_a) − AΛ by the pair formulas (module docs of the tangent maps).
    fn pi(&self) -> Mat {
        let st = &self.state;
        let mut pi = diag(&st.p_a);
        for &(i, j) in &self.pairs {
            let (s, d) = (
                st.p_omega[(i, j)] + st.p_lambda[(i, j)],
                st.p_omega[(i, j)] - st.p_lambda[(i, j)],
            );
            let (sym, anti) = (
                -0.5 * s / (st.a[i] - st.a[j]),
                0.5 * d / (st.a[i] + st.a[j]),
            );
            pi[(i, j)] = sym + anti;
            pi[(j, i)] = sym - anti;
        }
        pi
    }
}

/// The skew blocks of a direction in working coordinates, after (δa, δp_a).
#[derive(Clone, Copy)]
enum Slot {
    Mu,
    Nu,
    Xi,
    Eta,
}

impl Slot {
    /// The index of entry k (the k-th pair i < j) of this block.
    fn at(self, n: usize, k: usize) -> usize {
        2 * n + (self as usize) * (n * (n - 1) / 2) + k
    }
}

/// The matrices of the tangent maps: one per thread, kept from call to call
/// ([`TangentScratch::with`]).
struct TangentScratch {
    ms: Mat,
    ns: Mat,
    xi: Mat,
    eta: Mat,
    tmp: Mat,
    h: Mat,
    out: Vec<f64>,
    ws: Workspace,
}

thread_local! {
    static SCRATCH: std::cell::Cell<Option<TangentScratch>> = const { std::cell::Cell::new(None) };
}

impl TangentScratch {
    fn new(n: usize) -> Self {
        TangentScratch {
            ms: Mat::zeros(n, n),
            ns: Mat::zeros(n, n),
            xi: Mat::zeros(n, n),
            eta: Mat::zeros(n, n),
            tmp: Mat::zeros(n, n),
            h: Mat::zeros(n, n),
            out: vec![0.0; 2 * n * n],
            ws: Workspace::new(n),
        }
    }

    /// `f` on this thread's scratch for dimension n (made at the first call, or for a new n).
    fn with<R>(n: usize, f: impl FnOnce(&mut TangentScratch) -> R) -> R {
        let mut t = SCRATCH
            .take()
            .filter(|t| t.ws.n() == n)
            .unwrap_or_else(|| TangentScratch::new(n));
        let r = f(&mut t);
        SCRATCH.set(Some(t));
        r
    }

    /// The skew blocks of a direction (working coordinates) into ms = δμ, ns = δν, xi, eta.
    fn load(&mut self, n: usize, pairs: &[(usize, usize)], dz: &[f64]) {
        for (m, slot) in [
            (&mut self.ms, Slot::Mu),
            (&mut self.ns, Slot::Nu),
            (&mut self.xi, Slot::Xi),
            (&mut self.eta, Slot::Eta),
        ] {
            m.fill(0.0);
            for (k, &(i, j)) in pairs.iter().enumerate() {
                m[(i, j)] = dz[slot.at(n, k)];
                m[(j, i)] = -dz[slot.at(n, k)];
            }
        }
    }

    /// The inverse of [`TangentScratch::load`] (the entries i < j).
    fn store(&self, n: usize, pairs: &[(usize, usize)], dz: &mut [f64]) {
        for (m, slot) in [
            (&self.ms, Slot::Mu),
            (&self.ns, Slot::Nu),
            (&self.xi, Slot::Xi),
            (&self.eta, Slot::Eta),
        ] {
            for (k, &(i, j)) in pairs.iter().enumerate() {
                dz[slot.at(n, k)] = m[(i, j)];
            }
        }
    }
}

/// Largest rotation angle |τ| of one K_ij sub-flow that [`ReducedWork::check_step`] accepts: a
/// step that turns the frames by more has stopped resolving the motion near a coincidence of
/// semi-axes, and the run stops instead of returning inaccurate data.
pub const MAX_ANGLE: f64 = 0.5;

/// m ← G m Gᵀ for the Givens rotation G = exp(−τE_ij), G_ii = G_jj = c, G_ij = −s, G_ji = s.
fn givens_conj(m: &mut Mat, i: usize, j: usize, c: f64, s: f64) {
    let n = m.nrows();
    for k in 0..n {
        let (x, y) = (m[(i, k)], m[(j, k)]);
        m[(i, k)] = c * x - s * y;
        m[(j, k)] = s * x + c * y;
    }
    givens_cols(m, i, j, c, s);
}

/// m ← m Gᵀ for the G of [`givens_conj`] (columns i, j rotated).
fn givens_cols(m: &mut Mat, i: usize, j: usize, c: f64, s: f64) {
    let n = m.nrows();
    for k in 0..n {
        let (x, y) = (m[(k, i)], m[(k, j)]);
        m[(k, i)] = c * x - s * y;
        m[(k, j)] = s * x + c * y;
    }
}

fn diag(a: &[f64]) -> Mat {
    Mat::from_fn(a.len(), a.len(), |i, j| if i == j { a[i] } else { 0.0 })
}

fn dot(u: &[f64], v: &[f64]) -> f64 {
    u.iter().zip(v).map(|(p, q)| p * q).sum()
}
