//! The discrete Moser–Veselov algorithm (DMV) for the free rigid body with its attitude, and its
//! preprocessed versions of orders 4, 6, 8 and 10 (J. Moser & A. P. Veselov, "Discrete versions
//! of some classical integrable systems and factorization of matrix polynomials", Comm. Math.
//! Phys. 139 (1991); E. Hairer & G. Vilmart, "Preprocessed discrete Moser–Veselov algorithm for
//! the full dynamics of a rigid body", J. Phys. A 39 (2006) 13225, cited as HV06 below).
//!
//! **The DMV step.** The discrete Lagrangian L_d(R_n, R_{n+1}) = (1/h) tr((1 − F_n) D) with the
//! relative rotation F_n = R_nᵀR_{n+1} ∈ SO(3) and the mass matrix D = ½ tr(I)·1 − I (so that
//! tr(ŵ D ŵᵀ) = w·Iw and L_d = h·½ w·Iw + O(h³) for F = exp(hŵ)) gives the discrete
//! Euler–Lagrange equations in the body momentum M (principal frame, I = diag(I₁, I₂, I₃)):
//!
//! h M̂_n = F_n D − D F_nᵀ,   M̂_{n+1} = F_nᵀ M̂_n F_n (M_{n+1} = F_nᵀ M_n),   R_{n+1} = R_n F_n
//!
//! (HV06 (3)–(5) with their Ω_n = F_nᵀ; for the free body this is the same map as the LGVI of
//! [`super::lgvi`], solved differently). With the Cayley parametrisation
//! F = (1 − ê)⁻¹(1 + ê) = 1 + 2(ê + ê²)/α, α = 1 + |e|² (the unit quaternion (1, e)/√α), and the
//! identities ê D + D ê = (Ie)^ and ê² D − D ê² = (e × Ie)^ (D is diagonal with
//! D_j + D_k = I_i), the two momenta are h α M_n = 2(Ie + e × Ie) and
//! h α M_{n+1} = 2(Ie − e × Ie). Hence, for (i, j, k) cyclic,
//!
//! e_i = α (h/2) M_i / I_i + ((I_j − I_k)/I_i) e_j e_k,   M_{n+1,i} = M_{n,i} + 4(I_j − I_k) e_j e_k / (hα),
//!
//! and the attitude, carried as a unit quaternion q (R = R(q)), is q_{n+1} = q_n (1, e)/|q_n (1, e)|
//! (Hamilton product; the normalisation keeps |q| = 1 to round-off). This is HV06 (16)–(18) with
//! e = (h/2) I⁻¹Y. The implicit equation for e is solved to round-off by Gauss–Seidel sweeps
//! (a contraction with factor O(|e|) = O(h|Ω|)) from a predictor accurate to O(|e|³), or, where
//! they contract slowly (large steps), by Newton's method on the same 3-vector equation
//! (`DmvStepper::solve`), both under the rule of [`crate::convergence`]; a step whose equation has
//! no solution nearby is [`crate::Error::NotConverged`] naming the step. The momentum increments are added with
//! compensated (Kahan) summation.
//!
//! **Preprocessing (HV06 §2).** DMV applied to a body with the modified inverse moments
//!
//! 1/Ĩ_j = s/I_j + d,   s = 1 + h²s₃ + h⁴s₅ + …,   d = h²d₃ + h⁴d₅ + …,
//!
//! where s_{2k+1}, d_{2k+1} are homogeneous polynomials of degree k in H = ½ Σ M_j²/I_j and
//! C = ½|M|² (HV06 Theorem 2.1), reproduces the exact flow of (M, R) as a formal series in h;
//! truncated after h^{2r−2} it is of order 2r (HV06 Algorithm 2.2). No map of the initial data is
//! needed: the state is used as it is, and every state a stepper reports is the method's own.
//! The coefficients here were derived anew (by the construction of HV06 §6: the Taylor series of
//! one DMV step with the modified moments against that of the exact flow, for M and for R, the
//! terms of order h^{2k+1} fixing s_{2k+1} from M and then d_{2k+1} from R, at many rational
//! inertias, then fitted exactly as symmetric polynomials): in the inverse moments u_j = 1/I_j,
//! the coefficient of H^{k−i} C^i in s_{2k+1} is a symmetric polynomial of degree k + i, in d_{2k+1}
//! of degree k + i + 1, written in the elementary symmetric polynomials p₁ = Σ u_j,
//! p₂ = Σ_{i<j} u_i u_j, p₃ = u₁u₂u₃ (the tables `S`, `D`). They agree exactly with Table 1 of HV06
//! (s₃ … d₇) and with the Fortran code DMV10 of the authors (up to s₉, d₉); no published formula
//! needed a correction; `scripts/dmv_coefficients.py` (sympy) re-derives them and checks
//! the tables (and `dmv10` agrees with that code's DMV10 to 1e-13 at T = 100 in M and R on the
//! test of tests/dmv.rs, dt = 0.1 … 0.8). They are evaluated scale-free: with u_ref = max u_j, μ_j = u_j/u_ref,
//! p̂ the elementary polynomials of μ, X = h² H u_ref and Y = h² C u_ref²,
//! s = 1 + Σ S_{k,i}(p̂) X^{k−i} Y^i and d = u_ref Σ D_{k,i}(p̂) X^{k−i} Y^i.
//!
//! For the free body H and C are invariants of the method, so the modified moments are computed
//! once, when a stepper's state is set (at the start of a run; the driver sets it again only after
//! its retractions of R, every 256 steps, from a state with the same invariants to round-off).
//!
//! **Tangent map** (issue 26; the methods on the tangent lift of [`crate::systems::RigidBody`],
//! with and without the attitude). The exact derivative of the map above (HV06 (16)–(18) with
//! the modified moments), to round-off: the base state is stepped by the plain stepper's own
//! code (the same bits), and each direction (δM, and ξ with δR = Rξ̂) by the derivative of that
//! step.
//! - The e-equation G(e; b, fac) = e − α b − fac∘(e_j e_k) = 0, b = a∘M with
//!   a_j = (h/2)/Ĩ_j, by the implicit-function theorem: δe = G_e⁻¹(α δb + δfac∘(e_j e_k)),
//!   δb = δa∘M + a∘δM (a, fac, fad of the kernel below), with G_e (Newton's matrix) formed and
//!   inverted once per step for all k directions.
//! - M_{n+1} = M_n + fad∘(e_j e_k)/α: δM_{n+1} = δM_n + δ(fad∘(e_j e_k)/α), with
//!   δα = 2e·δe.
//! - R_{n+1} = R_n F_n, F = cay(e): the left-trivialised ξ_{n+1} = F_nᵀξ_n + dcay_e δe, where
//!   F⁻¹δF = (dcay_e δe)^ with dcay_e δe = (2/α)(δe − e × δe) (twice the vector part of r̄ δr
//!   for the unit quaternion r = (1, e)/√α of F; its scalar part vanishes).
//! - The modified moments depend on M₀ through H and C and on I (HV06 (6)): δĨ =
//!   ∂Ĩ/∂M₀ δM₀ + ∂Ĩ/∂I δI, formed per direction when the stepper is set and entering every
//!   step through δa, δfac and δfad (for order 2, δĨ = δI). A stepper set again mid-run (the
//!   driver after its retractions of R) differentiates the preprocessing at the state it is set
//!   to along that state's directions: the derivative of the map it computes, equal to the
//!   one without the re-set since H and C are invariants of every DMV step.
//!
//! With the attitude the driver retracts the lift's R and sets its stepper again exactly where it
//! does so for the plain run (every [`crate::integrate::RETRACT_EVERY`]-th step), so its base
//! states are the plain run's bit for bit over any number of steps.
//!
//! **Properties** (HV06 Proposition 2.3, Table 2): order 2r; |M|² and the spatial momentum R M
//! are kept (the step is a rotation of M and R M is unchanged by it), R ∈ SO(3) to round-off;
//! the energy H too: DMV with the constant Ĩ keeps H̃ = ½ Σ M_j²/Ĩ_j = sH + dC and C, hence H;
//! symmetric (Ĩ depends on M only through H and C). DMV itself is symplectic on T*SO(3); the
//! preprocessed methods are Poisson integrators for M on so(3)* but not symplectic for the full
//! system with the attitude — their [`Properties::symplectic`] claim is the Poisson one.

use super::super::top::Top;
use crate::convergence::{self, Failed, Monitor, Rule, Verdict};
use crate::error::{Error, Result};
use crate::integrate::{Clock, Properties, Stepper};
use crate::lie::rotations::{matrix_to_quaternion, quaternion_multiply, quaternion_to_matrix};
use nalgebra::{Matrix3, Vector3};

/// The DMV algorithm (`Dmv(2)`) and its preprocessed versions `Dmv(4)`, `Dmv(6)`, `Dmv(8)`,
/// `Dmv(10)` (a method value; the number is the order), for [`crate::systems::RigidBody`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dmv(pub u32);

/// The orders there are.
pub const ORDERS: [u32; 5] = [2, 4, 6, 8, 10];

/// The stopping rule of the Gauss–Seidel sweeps ([`crate::convergence`]; the update relative to
/// |e|, 1-norms; ended at once at ε²); after `max_iter` sweeps Newton's method takes over.
pub const FIXED_POINT: Rule = Rule {
    tol: convergence::TOL,
    floor: f64::EPSILON * f64::EPSILON,
    max_iter: 40,
};
/// Newton's method takes over when successive fixed-point updates shrink by less than this
/// factor (steps with |e| ≳ 0.1, where Newton needs fewer iterations).
pub const SLOW_CONTRACTION: f64 = 0.05;
/// The stopping rule of Newton's method after the sweeps (as [`FIXED_POINT`]).
pub const NEWTON: Rule = Rule {
    max_iter: 30,
    ..FIXED_POINT
};

/// One term num/den · p̂₁^a p̂₂^b p̂₃^c · X^{k−i} Y^i of s or d at h^{2k} (`p` = [a, b, c]).
#[derive(Clone, Copy, Debug)]
struct Term {
    k: u8,
    i: u8,
    p: [u8; 3],
    num: i32,
    den: i32,
}

const fn t(k: u8, i: u8, p: [u8; 3], num: i32, den: i32) -> Term {
    Term { k, i, p, num, den }
}

/// s_{2k+1} (k = 1…4) in the inverse moments: the coefficient of H^{k−i} C^i is
/// Σ num/den · p₁^a p₂^b p₃^c (module docs).
#[rustfmt::skip]
const S: [Term; 41] = [
    t(1, 0, [1, 0, 0], -1, 3),
    t(1, 1, [0, 1, 0], 1, 6),
    t(2, 0, [2, 0, 0], 1, 30),
    t(2, 0, [0, 1, 0], -1, 60),
    t(2, 1, [1, 1, 0], -1, 30),
    t(2, 1, [0, 0, 1], 2, 15),
    t(2, 2, [0, 2, 0], 1, 30),
    t(2, 2, [1, 0, 1], -1, 10),
    t(3, 0, [3, 0, 0], -1, 630),
    t(3, 0, [1, 1, 0], 1, 630),
    t(3, 0, [0, 0, 1], 1, 35),
    t(3, 1, [2, 1, 0], 1, 420),
    t(3, 1, [0, 2, 0], 41, 2520),
    t(3, 1, [1, 0, 1], -53, 630),
    t(3, 2, [1, 2, 0], -1, 70),
    t(3, 2, [2, 0, 1], 11, 210),
    t(3, 2, [0, 1, 1], -1, 84),
    t(3, 3, [0, 3, 0], 17, 2520),
    t(3, 3, [1, 1, 1], -11, 420),
    t(3, 3, [0, 0, 2], 5, 126),
    t(4, 0, [4, 0, 0], 1, 22680),
    t(4, 0, [2, 1, 0], -1, 15120),
    t(4, 0, [0, 2, 0], 17, 5040),
    t(4, 0, [1, 0, 1], -3, 280),
    t(4, 1, [3, 1, 0], -1, 11340),
    t(4, 1, [1, 2, 0], -11, 1890),
    t(4, 1, [2, 0, 1], 23, 945),
    t(4, 1, [0, 1, 1], -23, 1260),
    t(4, 2, [2, 2, 0], 13, 3780),
    t(4, 2, [0, 3, 0], 1, 2520),
    t(4, 2, [3, 0, 1], -17, 1260),
    t(4, 2, [1, 1, 1], 1, 252),
    t(4, 2, [0, 0, 2], 53, 1260),
    t(4, 3, [1, 3, 0], -11, 3240),
    t(4, 3, [2, 1, 1], 17, 1260),
    t(4, 3, [0, 2, 1], 47, 7560),
    t(4, 3, [1, 0, 2], -47, 945),
    t(4, 4, [0, 4, 0], 31, 22680),
    t(4, 4, [1, 2, 1], -19, 2520),
    t(4, 4, [2, 0, 2], 1, 120),
    t(4, 4, [0, 1, 2], 97, 15120),
];

/// d_{2k+1} (k = 1…4) in the inverse moments, as [`S`].
#[rustfmt::skip]
const D: [Term; 38] = [
    t(1, 0, [0, 1, 0], 1, 6),
    t(1, 1, [0, 0, 1], -1, 3),
    t(2, 0, [1, 1, 0], -1, 60),
    t(2, 0, [0, 0, 1], -1, 10),
    t(2, 1, [0, 2, 0], -1, 60),
    t(2, 1, [1, 0, 1], 2, 15),
    t(2, 2, [0, 1, 1], -1, 60),
    t(3, 0, [2, 1, 0], 1, 1260),
    t(3, 0, [0, 2, 0], -13, 1260),
    t(3, 0, [1, 0, 1], 1, 42),
    t(3, 1, [1, 2, 0], 13, 2520),
    t(3, 1, [2, 0, 1], -8, 315),
    t(3, 1, [0, 1, 1], 11, 252),
    t(3, 2, [0, 3, 0], 1, 1260),
    t(3, 2, [1, 1, 1], -1, 1260),
    t(3, 2, [0, 0, 2], -22, 315),
    t(3, 3, [0, 2, 1], -19, 2520),
    t(3, 3, [1, 0, 2], 1, 35),
    t(4, 0, [3, 1, 0], -1, 45360),
    t(4, 0, [1, 2, 0], -1, 7560),
    t(4, 0, [2, 0, 1], -1, 360),
    t(4, 0, [0, 1, 1], 17, 1680),
    t(4, 1, [2, 2, 0], -1, 1512),
    t(4, 1, [0, 3, 0], 97, 22680),
    t(4, 1, [3, 0, 1], 8, 2835),
    t(4, 1, [1, 1, 1], -23, 1890),
    t(4, 1, [0, 0, 2], -1, 35),
    t(4, 2, [1, 3, 0], -1, 1512),
    t(4, 2, [2, 1, 1], 19, 7560),
    t(4, 2, [0, 2, 1], -19, 1080),
    t(4, 2, [1, 0, 2], 89, 1890),
    t(4, 3, [0, 4, 0], -1, 45360),
    t(4, 3, [1, 2, 1], 37, 7560),
    t(4, 3, [2, 0, 2], -2, 105),
    t(4, 3, [0, 1, 2], 19, 1260),
    t(4, 4, [0, 3, 1], -61, 45360),
    t(4, 4, [1, 1, 2], 3, 560),
    t(4, 4, [0, 0, 3], -61, 4536),
];

/// The elementary symmetric polynomials (p₁, p₂, p₃) of v.
fn elementary(v: [f64; 3]) -> [f64; 3] {
    [
        v[0] + v[1] + v[2],
        v[0] * v[1] + v[1] * v[2] + v[2] * v[0],
        v[0] * v[1] * v[2],
    ]
}

/// Σ num/den · p₁^a p₂^b p₃^c over the terms of `terms` at h^{2k}, by the power i of C.
fn coefficients(terms: &[Term], p: [f64; 3], k: usize) -> [f64; 5] {
    let mut out = [0.0; 5];
    for t in terms.iter().filter(|t| usize::from(t.k) == k) {
        let pp: f64 = (0..3).map(|a| p[a].powi(i32::from(t.p[a]))).product();
        out[usize::from(t.i)] += f64::from(t.num) / f64::from(t.den) * pp;
    }
    out
}

/// The gradients in (p₁, p₂, p₃) of [`coefficients`] (for the derivative of the modified moments
/// along the principal moments).
fn coefficient_gradients(terms: &[Term], p: [f64; 3], k: usize) -> [[f64; 3]; 5] {
    let mut out = [[0.0; 3]; 5];
    for t in terms.iter().filter(|t| usize::from(t.k) == k) {
        let c = f64::from(t.num) / f64::from(t.den);
        let row = &mut out[usize::from(t.i)];
        for (a, g) in row.iter_mut().enumerate().filter(|&(a, _)| t.p[a] > 0) {
            // ∂/∂p_a of p₁^a₁ p₂^a₂ p₃^a₃.
            let d: f64 = (0..3)
                .map(|b| match b == a {
                    true => f64::from(t.p[b]) * p[b].powi(i32::from(t.p[b]) - 1),
                    false => p[b].powi(i32::from(t.p[b])),
                })
                .product();
            *g += c * d;
        }
    }
    out
}

/// The coefficients of H^{k−i} C^i (i = 0…k) in s_{2k+1} and d_{2k+1}, k = 1…4, of principal
/// moments I (unscaled: s = 1 + Σ_k h^{2k} Σ_i s_i H^{k−i} C^i, likewise d); for tests against
/// HV06 Table 1. Zeros for other k.
pub fn series_coefficients(moments: &[f64; 3], k: usize) -> ([f64; 5], [f64; 5]) {
    let p = elementary(moments.map(|m| 1.0 / m));
    (coefficients(&S, p, k), coefficients(&D, p, k))
}

/// The series s, d of one body and order, scale-free (module docs): the coefficients of
/// X^{k−i} Y^i at k = 1…r−1 in s and d/u_ref, computed once per stepper.
#[derive(Clone, Copy, Debug)]
struct Series {
    order: u32,
    u_ref: f64,
    mu: [f64; 3],
    s: [[f64; 5]; 4],
    d: [[f64; 5]; 4],
    /// The gradients of `s` and `d` in the elementary polynomials p̂ of μ.
    s_grad: [[[f64; 3]; 5]; 4],
    d_grad: [[[f64; 3]; 5]; 4],
}

impl Series {
    /// Errors: an order not in [`ORDERS`]; moments not positive and finite.
    fn new(moments: &[f64; 3], order: u32) -> Result<Self> {
        if !ORDERS.contains(&order) {
            return Err(Error::invalid(
                "order",
                format!("the DMV methods have orders 2, 4, 6, 8, 10, got {order}"),
            ));
        }
        super::super::top::check_moments(moments)?;
        let u = moments.map(|i| 1.0 / i);
        let u_ref = u.iter().fold(0.0f64, |a, &b| a.max(b));
        let mu = u.map(|x| x / u_ref);
        let p = elementary(mu);
        let mut series = Series {
            order,
            u_ref,
            mu,
            s: [[0.0; 5]; 4],
            d: [[0.0; 5]; 4],
            s_grad: [[[0.0; 3]; 5]; 4],
            d_grad: [[[0.0; 3]; 5]; 4],
        };
        for k in 1..(order as usize / 2) {
            series.s[k - 1] = coefficients(&S, p, k);
            series.d[k - 1] = coefficients(&D, p, k);
            series.s_grad[k - 1] = coefficient_gradients(&S, p, k);
            series.d_grad[k - 1] = coefficient_gradients(&D, p, k);
        }
        Ok(series)
    }

    /// The modified moments for the body momentum m (principal frame) and the step h.
    fn moments(&self, m: &[f64; 3], h: f64) -> Result<[f64; 3]> {
        let (mu, u_ref) = (self.mu, self.u_ref);
        // v = h u_ref M: X = h²H u_ref = ½ Σ μ_j v_j², Y = h²C u_ref² = ½ Σ v_j².
        let v = [0, 1, 2].map(|j| h * u_ref * m[j]);
        let x = 0.5 * (0..3).map(|j| mu[j] * v[j] * v[j]).sum::<f64>();
        let y = 0.5 * v.iter().map(|a| a * a).sum::<f64>();
        // Σ_k Σ_i c[k][i] x^{k−i} y^i, highest order (smallest) first.
        let sum = |c: &[[f64; 5]; 4]| {
            (1..(self.order as usize / 2))
                .rev()
                .map(|k| {
                    (0..=k)
                        .map(|i| c[k - 1][i] * x.powi((k - i) as i32) * y.powi(i as i32))
                        .sum::<f64>()
                })
                .sum::<f64>()
        };
        let s = 1.0 + sum(&self.s);
        let d = sum(&self.d);
        let mut out = [0.0; 3];
        for j in 0..3 {
            let inv = u_ref * (s * mu[j] + d);
            if !(inv.is_finite() && inv > 0.0) {
                return Err(Error::invalid(
                    "dt",
                    format!(
                        "dt = {} is too large for dmv{} at this state: the modified inverse \
                         moment 1/Ĩ[{j}] = {} is not positive and finite (h²H·max(1/I) = {}; \
                         reduce dt)",
                        crate::error::fmt_num(h),
                        self.order,
                        crate::error::fmt_num(inv),
                        crate::error::fmt_num(x),
                    ),
                ));
            }
            out[j] = 1.0 / inv;
        }
        Ok(out)
    }

    /// δĨ, the derivative of [`Series::moments`] (= `tilde`) along δM = `dm` and the principal
    /// `moments` moving by δI = `di` (HV06 (6): 1/Ĩ_j = s u_j + d, u = 1/I). Scale-free as there:
    /// s and d are functions of u alone (each term of degree zero in u_ref), so u_ref is held
    /// fixed and μ_j = u_j/u_ref moves by −μ_j u_j δI_j; X = ½ Σ μ_j v_j² and Y = ½ Σ v_j² with
    /// v = h u_ref M; p̂ moves by (Σ δμ_j, Σ δμ_j(p̂₁ − μ_j), Σ δμ_j p̂₃/μ_j).
    fn moments_tangent(
        &self,
        m: &[f64; 3],
        h: f64,
        moments: &[f64; 3],
        tilde: &[f64; 3],
        dm: &[f64; 3],
        di: &[f64; 3],
    ) -> [f64; 3] {
        let (mu, u_ref) = (self.mu, self.u_ref);
        let dmu = [0, 1, 2].map(|j| -mu[j] * di[j] / moments[j]);
        let v = [0, 1, 2].map(|j| h * u_ref * m[j]);
        let dv = [0, 1, 2].map(|j| h * u_ref * dm[j]);
        let x = 0.5 * (0..3).map(|j| mu[j] * v[j] * v[j]).sum::<f64>();
        let y = 0.5 * v.iter().map(|a| a * a).sum::<f64>();
        let dx = (0..3)
            .map(|j| 0.5 * dmu[j] * v[j] * v[j] + mu[j] * v[j] * dv[j])
            .sum::<f64>();
        let dy = (0..3).map(|j| v[j] * dv[j]).sum::<f64>();
        let p = elementary(mu);
        let others = |j: usize| mu[(j + 1) % 3] * mu[(j + 2) % 3];
        let dp = [
            dmu.iter().sum::<f64>(),
            (0..3).map(|j| dmu[j] * (p[0] - mu[j])).sum::<f64>(),
            (0..3).map(|j| dmu[j] * others(j)).sum::<f64>(),
        ];
        // (Σ c x^{k−i} y^i, its derivative), term by term.
        let pow = |z: f64, n: usize| z.powi(n as i32);
        let dpow = |z: f64, n: usize| match n {
            0 => 0.0,
            _ => n as f64 * z.powi(n as i32 - 1),
        };
        let sum = |c: &[[f64; 5]; 4], g: &[[[f64; 3]; 5]; 4]| {
            let (mut val, mut der) = (0.0, 0.0);
            for k in 1..(self.order as usize / 2) {
                for i in 0..=k {
                    let (c, g) = (c[k - 1][i], g[k - 1][i]);
                    let (xa, yb) = (pow(x, k - i), pow(y, i));
                    val += c * xa * yb;
                    der += (g[0] * dp[0] + g[1] * dp[1] + g[2] * dp[2]) * xa * yb
                        + c * (dpow(x, k - i) * dx * yb + xa * dpow(y, i) * dy);
                }
            }
            (val, der)
        };
        let (s, ds) = sum(&self.s, &self.s_grad);
        let (_, dd) = sum(&self.d, &self.d_grad);
        let s = 1.0 + s;
        [0, 1, 2].map(|j| {
            let dinv = u_ref * (ds * mu[j] + s * dmu[j] + dd);
            -tilde[j] * tilde[j] * dinv
        })
    }
}

/// The modified principal moments Ĩ of the preprocessed DMV of `order` (2 returns I) for the
/// step `h` and the body momentum `m` (principal frame): 1/Ĩ_j = s/I_j + d with s and d
/// truncated after h^{order−2} (module docs, HV06 (6) and Algorithm 2.2).
///
/// Errors: an order not in [`ORDERS`], moments not positive, non-finite input, and a step so
/// large that some 1/Ĩ_j is not positive and finite ([`Error::InvalidArgument`] naming dt).
pub fn modified_moments(moments: &[f64; 3], m: &[f64; 3], h: f64, order: u32) -> Result<[f64; 3]> {
    let series = Series::new(moments, order)?;
    crate::check::finite_slice("M", m)?;
    crate::check::finite_slice("dt", &[h])?;
    if order == 2 {
        return Ok(*moments);
    }
    series.moments(m, h)
}

impl Dmv {
    /// Order `self.0`; symplectic (for the preprocessed orders: Poisson on so(3)*, module docs),
    /// symmetric, keeps |M|², R M and SO(3).
    pub(crate) fn properties(&self) -> Properties {
        Properties::geometric(self.0)
    }

    /// The stepper for a free body `top` (M, or (M, R) when lifted).
    ///
    /// Errors: an order not in [`ORDERS`] ([`Error::InvalidArgument`]).
    pub(crate) fn stepper_for(&self, top: &Top, dt: f64) -> Result<Box<dyn Stepper>> {
        Ok(Box::new(DmvStepper::new(top, dt, self.0)?))
    }

    /// The stepper of the tangent lift of a free body `top` (module docs, "Tangent map").
    ///
    /// Errors: as [`Dmv::stepper_for`].
    pub(crate) fn tangent_stepper_for(&self, top: &Top, dt: f64) -> Result<Box<dyn Stepper>> {
        Ok(Box::new(DmvTangentStepper {
            base: DmvStepper::new(top, dt, self.0)?,
            e: if top.lifted { 6 } else { 3 },
            dirs: Vec::new(),
            dkernel: Vec::new(),
        }))
    }
}

/// The constants of a DMV step for the (modified) moments Ĩ: a_j = (h/2)/Ĩ_j,
/// fac_i = (Ĩ_j − Ĩ_k)/Ĩ_i and fad_i = 4(Ĩ_j − Ĩ_k)/h, (i, j, k) cyclic.
#[derive(Clone, Copy, Debug)]
struct Kernel {
    a: [f64; 3],
    fac: [f64; 3],
    fad: [f64; 3],
}

impl Kernel {
    /// The derivative of [`Kernel::new`] at Ĩ = `inertia` along δĨ = `d` (δa_j = −a_j δĨ_j/Ĩ_j,
    /// δfac_i = (δĨ_j − δĨ_k − fac_i δĨ_i)/Ĩ_i, δfad_i = 4(δĨ_j − δĨ_k)/h).
    fn tangent(&self, inertia: &[f64; 3], d: &[f64; 3], h: f64) -> Self {
        let cyc = |i: usize| ((i + 1) % 3, (i + 2) % 3);
        Kernel {
            a: [0, 1, 2].map(|j| -self.a[j] * d[j] / inertia[j]),
            fac: [0, 1, 2].map(|i| {
                let (j, k) = cyc(i);
                (d[j] - d[k] - self.fac[i] * d[i]) / inertia[i]
            }),
            fad: [0, 1, 2].map(|i| {
                let (j, k) = cyc(i);
                4.0 * (d[j] - d[k]) / h
            }),
        }
    }

    fn new(inertia: &[f64; 3], h: f64) -> Self {
        let cyc = |i: usize| ((i + 1) % 3, (i + 2) % 3);
        Kernel {
            a: inertia.map(|i| 0.5 * h / i),
            fac: [0, 1, 2].map(|i| {
                let (j, k) = cyc(i);
                (inertia[j] - inertia[k]) / inertia[i]
            }),
            fad: [0, 1, 2].map(|i| {
                let (j, k) = cyc(i);
                4.0 * (inertia[j] - inertia[k]) / h
            }),
        }
    }
}

/// ∂G/∂e for G(e) = e − α b − fac∘(e_j e_k), α = 1 + |e|² (the e-equation, module docs):
/// 1 − 2 b eᵀ − ∂(fac∘(e_j e_k))/∂e. Newton's matrix, and that of the implicit-function theorem
/// in the tangent map.
fn newton_matrix(b: &[f64; 3], e: &[f64; 3], f: &[f64; 3]) -> Matrix3<f64> {
    Matrix3::new(
        1.0 - 2.0 * b[0] * e[0],
        -2.0 * b[0] * e[1] - f[0] * e[2],
        -2.0 * b[0] * e[2] - f[0] * e[1],
        -2.0 * b[1] * e[0] - f[1] * e[2],
        1.0 - 2.0 * b[1] * e[1],
        -2.0 * b[1] * e[2] - f[1] * e[0],
        -2.0 * b[2] * e[0] - f[2] * e[1],
        -2.0 * b[2] * e[1] - f[2] * e[0],
        1.0 - 2.0 * b[2] * e[2],
    )
}

/// The DMV stepper on M (principal frame) and the attitude quaternion.
struct DmvStepper {
    series: Series,
    moments: [f64; 3],
    h: f64,
    lifted: bool,
    m: Vector3<f64>,
    carry: Vector3<f64>,
    /// The attitude (w, x, y, z), |q| = 1.
    q: [f64; 4],
    /// The modified moments Ĩ of the kernel (I for order 2).
    inertia: [f64; 3],
    kernel: Kernel,
}

impl DmvStepper {
    fn new(top: &Top, h: f64, order: u32) -> Result<Self> {
        let moments = top.moments;
        Ok(DmvStepper {
            series: Series::new(&moments, order)?,
            moments,
            h,
            lifted: top.lifted,
            m: Vector3::zeros(),
            carry: Vector3::zeros(),
            q: [1.0, 0.0, 0.0, 0.0],
            inertia: moments,
            kernel: Kernel::new(&moments, h),
        })
    }

    /// Solves e_i = α b_i + fac_i e_j e_k, α = 1 + |e|² ((i, j, k) cyclic): Gauss–Seidel sweeps
    /// from the predictor under the rule [`FIXED_POINT`] while they contract fast (ratio of
    /// successive updates ρ ≤ [`SLOW_CONTRACTION`]), ended early where the error left after an
    /// update (≤ ρ/(1 − ρ) times it) is below ε/8 (round-off reached one sweep before the
    /// update shows it); a slow contraction (large steps), a non-finite update or no convergence
    /// hands the solve to Newton's method.
    fn solve(&self, b: [f64; 3]) -> std::result::Result<[f64; 3], Failed> {
        let f = self.kernel.fac;
        // Predictor: the first sweep from e = b (error O(|e|³)).
        let mut e = [0.0; 3];
        e[0] = b[0] + f[0] * b[1] * b[2];
        e[1] = b[1] + f[1] * e[0] * b[2];
        e[2] = b[2] + f[2] * e[0] * e[1];
        let mut monitor = Monitor::new(FIXED_POINT);
        loop {
            let alpha = 1.0 + e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
            let n0 = alpha * b[0] + f[0] * e[1] * e[2];
            let n1 = alpha * b[1] + f[1] * n0 * e[2];
            let n2 = alpha * b[2] + f[2] * n0 * n1;
            let diff = (n0 - e[0]).abs() + (n1 - e[1]).abs() + (n2 - e[2]).abs();
            let size = n0.abs() + n1.abs() + n2.abs();
            e = [n0, n1, n2];
            let rho = diff / monitor.last();
            let fast = monitor.iterations() >= 1 && rho <= SLOW_CONTRACTION;
            if fast && diff * rho <= 0.125 * f64::EPSILON * size * (1.0 - rho) {
                return Ok(e);
            }
            match monitor.check(diff, size) {
                Verdict::Converged => return Ok(e),
                Verdict::Failed(_) => break,
                Verdict::Continue if monitor.iterations() >= 2 && rho > SLOW_CONTRACTION => {
                    return self.newton(b, e)
                }
                Verdict::Continue => {}
            }
        }
        // Not finite, or no convergence: Newton from the predictor.
        let mut e = [0.0; 3];
        e[0] = b[0] + f[0] * b[1] * b[2];
        e[1] = b[1] + f[1] * e[0] * b[2];
        e[2] = b[2] + f[2] * e[0] * e[1];
        self.newton(b, e)
    }

    /// Newton's method for the same equation from `e` under the rule [`NEWTON`], ended early in
    /// the quadratic regime (an update below 10⁻⁹|e| and 10⁻⁴ of the one before: what is left is
    /// of the order of its square).
    fn newton(&self, b: [f64; 3], mut e: [f64; 3]) -> std::result::Result<[f64; 3], Failed> {
        let f = self.kernel.fac;
        let mut monitor = Monitor::new(NEWTON);
        loop {
            let alpha = 1.0 + e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
            let g = [
                e[0] - alpha * b[0] - f[0] * e[1] * e[2],
                e[1] - alpha * b[1] - f[1] * e[2] * e[0],
                e[2] - alpha * b[2] - f[2] * e[0] * e[1],
            ];
            let Some(inv) = newton_matrix(&b, &e, &f).try_inverse() else {
                let size = e[0].abs() + e[1].abs() + e[2].abs();
                return Err(monitor.failed((g[0].abs() + g[1].abs() + g[2].abs()) / size));
            };
            let de = inv * Vector3::from(g);
            e = [e[0] - de[0], e[1] - de[1], e[2] - de[2]];
            let diff = de.lp_norm(1);
            let size = e[0].abs() + e[1].abs() + e[2].abs();
            if diff <= 1e-9 * size && diff <= 1e-4 * monitor.last() {
                return Ok(e);
            }
            match monitor.check(diff, size) {
                Verdict::Continue => {}
                Verdict::Converged => return Ok(e),
                Verdict::Failed(failed) => return Err(failed),
            }
        }
    }

    /// b = a∘M, the right-hand side of the e-equation at the current M.
    fn rhs(&self) -> [f64; 3] {
        [0, 1, 2].map(|j| self.kernel.a[j] * self.m[j])
    }

    /// One step; returns the Cayley vector e it solved for.
    fn step(&mut self) -> std::result::Result<[f64; 3], Failed> {
        let k = &self.kernel;
        let b = self.rhs();
        let e = self.solve(b)?;
        let alpha = 1.0 + e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        let inc = Vector3::new(
            k.fad[0] * (e[1] * e[2]),
            k.fad[1] * (e[2] * e[0]),
            k.fad[2] * (e[0] * e[1]),
        ) / alpha;
        // Kahan's compensated m += inc.
        let y = inc - self.carry;
        let t = self.m + y;
        self.carry = (t - self.m) - y;
        self.m = t;
        if self.lifted {
            let p = quaternion_multiply(&self.q, &[1.0, e[0], e[1], e[2]]);
            let inv = 1.0 / (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]).sqrt();
            self.q = p.map(|c| c * inv);
        }
        Ok(e)
    }

    /// The error of a step k of a chunk that did not converge.
    fn failed(clock: Clock, k: usize, failed: Failed) -> Error {
        clock.not_converged(
            k,
            "DMV iteration for the relative rotation",
            failed,
            NEWTON.tol,
        )
    }
}

impl Stepper for DmvStepper {
    /// M (and R), and the modified moments from the invariants of M.
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.m = Vector3::from_column_slice(&z[..3]);
        self.carry = Vector3::zeros();
        if self.lifted {
            self.q = matrix_to_quaternion(&Matrix3::from_row_slice(&z[3..12]));
        }
        self.inertia = if self.series.order == 2 {
            self.moments
        } else {
            self.series.moments(&self.m.into(), self.h)?
        };
        self.kernel = Kernel::new(&self.inertia, self.h);
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        z[..3].copy_from_slice(self.m.as_slice());
        if self.lifted {
            let r = quaternion_to_matrix(&self.q);
            z[3..12].copy_from_slice(&super::super::top::row_major(&r));
        }
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        for k in 0..steps {
            self.step().map_err(|f| DmvStepper::failed(clock, k, f))?;
        }
        Ok(())
    }
}

/// The DMV stepper on the tangent lift (module docs, "Tangent map"): the base state by
/// [`DmvStepper`] itself, the directions (δM, and ξ with the attitude) by the derivative of its
/// step.
struct DmvTangentStepper {
    base: DmvStepper,
    /// Values per direction: 3 (δM) or 6 (δM, ξ).
    e: usize,
    /// The k directions (k·e values: the first e along the state, then the moments I₁, I₂, I₃).
    dirs: Vec<f64>,
    /// Per direction, the derivative of the kernel's constants along its δĨ (constant between
    /// two sets).
    dkernel: Vec<Kernel>,
}

impl DmvTangentStepper {
    /// The base state's dimension (M, or M and R row-major).
    fn d(&self) -> usize {
        if self.base.lifted {
            12
        } else {
            3
        }
    }

    /// δĨ of every direction from its δM and its parameter (module docs): the preprocessing
    /// differentiated at the state the base stepper was set to.
    fn preprocess(&mut self) {
        let b = &self.base;
        let m: [f64; 3] = b.m.into();
        self.dkernel.clear();
        for (j, dir) in self.dirs.chunks_exact(self.e).enumerate() {
            let mut di = [0.0; 3];
            if j >= self.e {
                di[j - self.e] = 1.0;
            }
            let dm = [dir[0], dir[1], dir[2]];
            let dtilde = match b.series.order {
                2 => di,
                _ => b
                    .series
                    .moments_tangent(&m, b.h, &b.moments, &b.inertia, &dm, &di),
            };
            self.dkernel
                .push(b.kernel.tangent(&b.inertia, &dtilde, b.h));
        }
    }

    /// The directions through one step from M = `m` that solved for `e` (module docs):
    /// δe = G_e⁻¹(α δb + δfac∘(e_j e_k)) with G_e formed once, δM' = δM + δ(inc), and
    /// ξ' = Fᵀξ + (2/α)(δe − e × δe).
    fn tangent_step(&mut self, m: &Vector3<f64>, e: [f64; 3]) {
        let k = &self.base.kernel;
        let b = [0, 1, 2].map(|j| k.a[j] * m[j]);
        let ge = newton_matrix(&b, &e, &k.fac)
            .try_inverse()
            .unwrap_or_else(|| Matrix3::from_element(f64::NAN));
        let ev = Vector3::from(e);
        let alpha = 1.0 + ev.norm_squared();
        let p = Vector3::new(e[1] * e[2], e[2] * e[0], e[0] * e[1]);
        let fad = Vector3::from(k.fad);
        for (dir, dk) in self.dirs.chunks_exact_mut(self.e).zip(&self.dkernel) {
            let dm = Vector3::new(dir[0], dir[1], dir[2]);
            let rhs = Vector3::from_fn(|i, _| {
                alpha * (dk.a[i] * m[i] + k.a[i] * dm[i]) + dk.fac[i] * p[i]
            });
            let de = ge * rhs;
            let dalpha = 2.0 * ev.dot(&de);
            let dp = Vector3::new(
                de[1] * e[2] + e[1] * de[2],
                de[2] * e[0] + e[2] * de[0],
                de[0] * e[1] + e[0] * de[1],
            );
            let dinc = (Vector3::from(dk.fad).component_mul(&p) + fad.component_mul(&dp)) / alpha
                - fad.component_mul(&p) * (dalpha / (alpha * alpha));
            dir[..3].copy_from_slice((dm + dinc).as_slice());
            if self.e == 6 {
                // R' = R F, F = cay(e): ξ' = Fᵀξ + (F⁻¹δF)^∨, Fᵀ = 1 + 2(ê² − ê)/α.
                let xi = Vector3::new(dir[3], dir[4], dir[5]);
                let ex = ev.cross(&xi);
                let turned = xi + (ev.cross(&ex) - ex) * (2.0 / alpha);
                let dcay = (de - ev.cross(&de)) * (2.0 / alpha);
                dir[3..].copy_from_slice((turned + dcay).as_slice());
            }
        }
    }
}

impl Stepper for DmvTangentStepper {
    /// The base state as [`DmvStepper::set`] (its modified moments from the invariants of M),
    /// and their derivative along the directions given.
    fn set(&mut self, z: &[f64]) -> Result<()> {
        let d = self.d();
        self.base.set(&z[..d])?;
        self.dirs.clear();
        self.dirs.extend_from_slice(&z[d..]);
        self.preprocess();
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        let d = self.d();
        self.base.get(&mut z[..d]);
        // Nothing before `set`.
        if z.len() == d + self.dirs.len() {
            z[d..].copy_from_slice(&self.dirs);
        }
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        for k in 0..steps {
            let m = self.base.m;
            let e = self
                .base
                .step()
                .map_err(|f| DmvStepper::failed(clock, k, f))?;
            self.tangent_step(&m, e);
        }
        Ok(())
    }
}
