//! Self-gravity of a homogeneous ellipsoid (Chandrasekhar, *Ellipsoidal Figures of Equilibrium*
//! (EFE), 1969, ch. 3): the index symbols A_i, A_ij ([`index_symbols`]) and the gravitational
//! potential of a pseudo-rigid body ([`SelfGravity`]), the potential of the Riemann ellipsoids
//! (001 §9; EFE ch. 7).
//!
//! # Index symbols
//!
//! For semi-axes a₁, a₂, a₃ > 0 and Δ(u) = √((a₁²+u)(a₂²+u)(a₃²+u)) (EFE ch. 3 §21)
//!
//! A_i = a₁a₂a₃ ∫₀^∞ du / ((a_i²+u) Δ),   A_ij = a₁a₂a₃ ∫₀^∞ du / ((a_i²+u)(a_j²+u) Δ)
//!
//! (i, j = 1, 2, 3, the diagonal A_ii included). They satisfy Σ A_i = 2,
//! A_i − A_j = −(a_i² − a_j²) A_ij, 3A_ii + Σ_{j≠i} A_ij = 2/a_i² and
//! 3a_i²A_ii + Σ_{j≠i} a_j²A_ij = 3A_i (EFE ch. 3 §21; the last from ∫ u (d/du)(1/((a_i²+u)Δ)) du
//! = −∫ du/((a_i²+u)Δ) by parts); a sphere of radius a has A_i = 2/3 and A_ij = 2/(5a²).
//!
//! *Routes.* A_i = (2/3) a₁a₂a₃ R_D(a_j², a_k², a_i²) with Carlson's R_D
//! ([`crate::numerics::elliptic::carlson_rd`], a few ulp). The A_ij are not taken from the divided
//! difference −(A_i − A_j)/(a_i² − a_j²), which loses all digits as a_i → a_j (at a relative
//! difference 1e-12 it keeps about 4), nor from 3A_ii = 2/a_i² − Σ_{j≠i} A_ij, which cancels for a
//! needle; all six are computed directly by the trapezoidal rule in s = ln u (u = e^s,
//! du = e^s ds). Where the axes are well separated the divided difference is no more accurate than
//! the quadrature (measured against mpmath: both within 1–4 ulp), so one route serves every shape.
//!
//! *Convergence.* The integrand F(e^s)e^s is analytic in the strip |Im s| < π (the singularities
//! of F(u) are the branch points and poles at u = −a_k², i.e. s = ln a_k² ± iπ) and decays
//! exponentially at both ends, so the trapezoidal rule with step h converges like e^{−2πd/h} for
//! every d < π, i.e. like e^{−2π²/h} up to a power of 1/h from the order (up to 7/2, at a sphere)
//! of the singularities on the strip's edge. Measured: h = 1/2 leaves 2e-14 at a sphere,
//! h = 3/8 is at rounding level for every shape (e^{−2π²/h} = 1.4e-23), so h = 3/8 (exact in
//! binary: the nodes s = kh are exact and u = e^{kh} is correctly rounded). The positive terms are
//! added with Neumaier's compensated sum.
//!
//! *Truncation* (semi-axes normalized so that M = max a² ∈ [1, 4), m = min a²). Below: for u ≤ m
//! every a_l² + u ≤ 2a_l², so A_ij ≥ a₁a₂a₃ m / (2a_i² 2a_j² 2^{3/2} a₁a₂a₃), while the part
//! of the integral over u < U is at most a₁a₂a₃ U/(a_i²a_j²a₁a₂a₃): the relative tail is at most
//! 4·2^{3/2} U/m, and the discrete tail of the rule is 1.2 times that (h/(1 − e^{−h})); with
//! ln U = ln m − 42 it is below 8e-18. Above: the slowest integrand (u/((a_i²+u)(a_j²+u)Δ) of the
//! Hessian, below) is at most u^{−5/2}, so the part over u > U is at most (2/3)U^{−3/2}, while
//! the integral over u ≤ M is at least M²/2 /(2^{7/2} M^{7/2}): the relative tail is at most
//! 15 (M/U)^{3/2}, below 4e-19 with ln U = ln M + 30 (the A_ij integrands, ≤ u^{−7/2}, are far
//! smaller there). So the rule runs over s from ln m − 42 to ln M + 30: about 190 nodes for
//! comparable axes, 270 at an axis ratio 1e-3.
//!
//! Measured accuracy (tests/gravity.rs, against mpmath quadrature at 30 digits): A_i and A_ij
//! within a few ulp (≤ 1e-15 relative) for axis ratios down to 1e-3, near-coincident axes
//! (relative differences 1e-12, 1e-6, 1e-3), spheres and spheroids.
//!
//! # The potential
//!
//! The body's reference configuration is the unit ball of density ρ, mass M = (4π/3)ρ; X maps it
//! to the ellipsoid whose semi-axes are the singular values σ_i of X (X = R diag(σ) Sᵀ), of
//! density ρ′ = ρ/(σ₁σ₂σ₃). Its gravitational energy is W = −(3/10) G M² ∫₀^∞ du/Δ =
//! −(3/5) G M² R_F(σ₁², σ₂², σ₃²) (EFE ch. 3 §22 with ∫₀^∞ du/Δ = 2R_F). The physical kinetic
//! energy of the homogeneous body is (M/10) tr(ẊᵀẊ), the library's ½ tr(ẊᵀẊ); dividing W by M/5
//! gives the potential of the library's normalization,
//!
//! U(X) = −4πGρ R_F(σ₁², σ₂², σ₃²)     (a sphere of radius a: U = −4πGρ/a).
//!
//! *Gradient.* ∂R_F(σ²)/∂σ_i = −(σ_i/2) ∫ du/((σ_i²+u)Δ) = −σ_i A_i/(2σ₁σ₂σ₃), so
//! g_i = ∂U/∂σ_i = 2πGρ′ σ_i A_i = (4π/3) Gρ σ_i R_D(σ_j², σ_k², σ_i²) (EFE ch. 3 (§22)), computed
//! in the last form (no division by σ₁σ₂σ₃), and ∂U/∂X = R diag(g) Sᵀ (dσ_i\[V\] = (RᵀVS)_ii).
//!
//! *Hessian* of the spectral function U = f(σ(X)) (Lewis & Sendov 2001): with M = RᵀVS,
//! D²U(X)\[V\] = R H Sᵀ, H_ii = Σ_j f_ij M_jj,
//! H_ij = ½(M_ij + M_ji)(g_i − g_j)/(σ_i − σ_j) + ½(M_ij − M_ji)(g_i + g_j)/(σ_i + σ_j) (i ≠ j),
//! where f_ij = ∂²U/∂σ_i∂σ_j = 2πGρ′(δ_ij A_i − (1 + 2δ_ij) σ_iσ_j A_ij) (differentiate
//! σ_i ∫ du/((σ_i²+u)Δ) under the integral: ∂/∂σ_j of 1/Δ is −σ_j/((σ_j²+u)Δ)). The three
//! quantities are evaluated without cancellation:
//! - f_ij (i ≠ j) = −2πGρ ∫ σ_iσ_j du/((σ_i²+u)(σ_j²+u)Δ), a positive quadrature;
//! - f_ii: A_i − 3σ_i²A_ii = σ₁σ₂σ₃ ∫ (u − 2σ_i²) du/((σ_i²+u)²Δ) changes sign (it is small for a
//!   thin disc); since (u − 2σ_i²)/(σ_i²+u)^{5/2} = −2 (d/du)(u (σ_i²+u)^{−3/2}), integration by
//!   parts gives f_ii = −2πGρ ∫ u du/((σ_i²+u)Δ) (1/(σ_j²+u) + 1/(σ_k²+u)), sign-definite;
//! - the divided difference: σ_i/(σ_i²+u) − σ_j/(σ_j²+u) = (σ_i − σ_j)(u − σ_iσ_j)/P with
//!   P = (σ_i²+u)(σ_j²+u), so (g_i − g_j)/(σ_i − σ_j) = 2πGρ D_ij,
//!   D_ij = ∫ (u − σ_iσ_j) du/(PΔ) (= (A_j − σ_i(σ_i + σ_j)A_ij)/(σ₁σ₂σ₃), finite and exact at
//!   σ_i = σ_j, where the Maclaurin spheroids sit). Its integrand changes sign at u = σ_iσ_j; by
//!   parts with (d/du)(u/P) = (σ_i²σ_j² − u²)/P²,
//!   D_ij = −½ ∫ u du/((σ_iσ_j+u)(σ_k²+u)Δ) + ½(σ_i − σ_j)² ∫ u(σ_iσ_j − u) du/((σ_iσ_j+u)²PΔ),
//!   sign-definite at coincident σ and nearly so close to it. Where the σ are far apart the
//!   difference of the gradients, (g_i − g_j)/(σ_i − σ_j), is better conditioned; each evaluation
//!   takes the form whose condition number (Σ|terms| / |sum|) is smaller. For extreme shapes
//!   (e.g. the two short axes 0.0056 : 0.001 of a needle) both forms cancel (about 2e3), which
//!   costs digits of those small entries only: the Hessian stays accurate in norm.
//!
//! All three use the quadrature above (the same nodes). Formulas are evaluated on X/2^e with
//! 2^e ≤ max |X_ij| < 2^{e+1} (exact) and scaled back once (U ∝ 2^{−e}, ∂U/∂X ∝ 2^{−2e},
//! D²U ∝ 2^{−3e}), so no intermediate overflows.

use crate::check;
use crate::error::{Error, Result};
use crate::numerics::elliptic::{rd_kernel, rf_kernel};
use crate::pseudo_rigid::potential::{Potential, Workspace};
use faer::{MatMut, MatRef};
use nalgebra::{Matrix3, Vector3};

/// Step of the trapezoidal rule in s = ln u (see the module doc).
const STEP: f64 = 0.375;
/// The rule starts at s = ln(min a²) − BELOW (relative lower tail < 8e-18).
const BELOW: f64 = 42.0;
/// The rule ends at s = ln(max a²) + ABOVE (relative upper tail < 4e-19).
const ABOVE: f64 = 30.0;
/// The least supported axis ratio min a / max a is 2^MIN_RATIO_LOG2 (≈ 5.5e-76): below it the
/// products of the quadrature's factors 1/(a_k² + u) leave the f64 range.
const MIN_RATIO_LOG2: i32 = -250;

/// Neumaier's compensated sum.
#[derive(Clone, Copy, Default)]
struct Acc {
    s: f64,
    c: f64,
}

impl Acc {
    fn add(&mut self, x: f64) {
        let t = self.s + x;
        if self.s.abs() >= x.abs() {
            self.c += (self.s - t) + x;
        } else {
            self.c += (x - t) + self.s;
        }
        self.s = t;
    }
    fn sum(self) -> f64 {
        self.s + self.c
    }
}

/// The nodes u = e^{kh} of the trapezoidal rule for the squared semi-axes `a2`.
fn nodes(a2: &[f64; 3]) -> impl Iterator<Item = f64> {
    let (lo, hi) = (
        a2[0].min(a2[1]).min(a2[2]).ln() - BELOW,
        a2[0].max(a2[1]).max(a2[2]).ln() + ABOVE,
    );
    let (k0, k1) = ((lo / STEP).floor() as i32, (hi / STEP).ceil() as i32);
    (k0..=k1).map(|k| (f64::from(k) * STEP).exp())
}

/// The other two indices of `i`.
fn others(i: usize) -> (usize, usize) {
    ((i + 1) % 3, (i + 2) % 3)
}

/// The pairs (i, j, k) with i < j and k the third index, in the order (0,1), (0,2), (1,2).
const PAIRS: [(usize, usize, usize); 3] = [(0, 1, 2), (0, 2, 1), (1, 2, 0)];

/// A_i = (2/3) a₁a₂a₃ R_D(a_j², a_k², a_i²) and A_ij by the quadrature, for semi-axes normalized
/// to a largest one in [1, 2) and a ratio ≥ 2^MIN_RATIO_LOG2.
fn index_symbols_normalized(a: &[f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let a2 = a.map(|x| x * x);
    let prod = a[0] * a[1] * a[2];
    let mut ai = [0.0; 3];
    for (i, v) in ai.iter_mut().enumerate() {
        let (j, k) = others(i);
        *v = 2.0 / 3.0 * prod * rd_kernel(a2[j], a2[k], a2[i]);
    }
    let mut acc = [[Acc::default(); 3]; 3];
    for u in nodes(&a2) {
        let p = a2.map(|x| 1.0 / (x + u));
        // a₁a₂a₃ · u/Δ: du = u ds; p₀p₁p₂ ≤ 2^1000 at the least supported ratio.
        let w = prod * u * (p[0] * p[1] * p[2]).sqrt();
        for i in 0..3 {
            for j in i..3 {
                acc[i][j].add(w * p[i] * p[j]);
            }
        }
    }
    let mut aij = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in i..3 {
            aij[i][j] = STEP * acc[i][j].sum();
            aij[j][i] = aij[i][j];
        }
    }
    (ai, aij)
}

/// Semi-axes divided by 2^e (the largest in [1, 2)), and e.
fn normalize(a: &[f64; 3]) -> ([f64; 3], i32) {
    let e = check::pow2_floor(a[0].max(a[1]).max(a[2]));
    (a.map(|x| check::ldexp(x, -e)), e)
}

/// Whether normalized semi-axes are within the supported ratio.
fn ratio_supported(a: &[f64; 3]) -> bool {
    a[0].min(a[1]).min(a[2]) >= check::ldexp(1.0, MIN_RATIO_LOG2)
}

/// Chandrasekhar's index symbols of the ellipsoid with semi-axes `a` (any order, all finite,
/// positive): (A_i, A_ij) with A_i = a₁a₂a₃ ∫₀^∞ du/((a_i²+u)Δ) and
/// A_ij = a₁a₂a₃ ∫₀^∞ du/((a_i²+u)(a_j²+u)Δ), Δ = √((a₁²+u)(a₂²+u)(a₃²+u)) (EFE ch. 3 §21;
/// A_ij symmetric, diagonal included). A_i by Carlson's R_D, A_ij by the trapezoidal rule in
/// ln u (module doc: routes, truncation, accuracy: a few ulp). The A_i are scale-free, the A_ij
/// scale as 1/a².
///
/// Errors: [`Error::NonFinite`] for a NaN or infinite semi-axis, [`Error::InvalidArgument`] for
/// one ≤ 0, for an axis ratio min a / max a below 2⁻²⁵⁰ ≈ 5.5e-76 (outside the quadrature's
/// range), and the overflow error where an A_ij exceeds the f64 range (semi-axes near 1e-154).
pub fn index_symbols(a: &[f64; 3]) -> Result<([f64; 3], [[f64; 3]; 3])> {
    for (i, &x) in a.iter().enumerate() {
        if !x.is_finite() {
            return Err(Error::NonFinite {
                what: "a".into(),
                location: format!("({i})"),
            });
        }
        if x <= 0.0 {
            return Err(Error::invalid(
                "a",
                format!(
                    "the semi-axes must be > 0, got a[{i}] = {}",
                    crate::error::fmt_num(x)
                ),
            ));
        }
    }
    let (an, e) = normalize(a);
    if !ratio_supported(&an) {
        let (lo, hi) = (a[0].min(a[1]).min(a[2]), a[0].max(a[1]).max(a[2]));
        return Err(Error::invalid(
            "a",
            format!(
                "the axis ratio min a / max a = {} / {} is below 2^{MIN_RATIO_LOG2} ≈ 5.5e-76, \
                 outside the range of the index-symbol quadrature",
                crate::error::fmt_num(lo),
                crate::error::fmt_num(hi)
            ),
        ));
    }
    let (ai, aij) = index_symbols_normalized(&an);
    let mut out = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = check::unscale("a", "the index symbol A_ij", aij[i][j], -2 * e)?;
        }
    }
    Ok((ai, out))
}

/// The quadratures of the Hessian at normalized singular values σ̂ (module doc, "Hessian"), each
/// without the factor 2πGρ: `fd[i]` = ∫ u du/((σ_i²+u)Δ)(1/(σ_j²+u) + 1/(σ_k²+u)) (= −f_ii),
/// and per pair p = (i, j, k) of [`PAIRS`]: `fo[p]` = ∫ σ_iσ_j du/((σ_i²+u)(σ_j²+u)Δ)
/// (= −f_ij), `d[p]` = D_ij by parts and `d_cond[p]` its condition Σ|terms|/|sum|.
struct HessianQuadrature {
    fd: [f64; 3],
    fo: [f64; 3],
    d: [f64; 3],
    d_cond: [f64; 3],
}

fn hessian_quadrature(s: &[f64; 3]) -> HessianQuadrature {
    let a2 = s.map(|x| x * x);
    let (mut fd, mut fo, mut d) = (
        [Acc::default(); 3],
        [Acc::default(); 3],
        [Acc::default(); 3],
    );
    let mut dabs = [0.0; 3];
    let q = PAIRS.map(|(i, j, _)| s[i] * s[j]);
    let dl = PAIRS.map(|(i, j, _)| (s[i] - s[j]) * (s[i] - s[j]));
    for u in nodes(&a2) {
        let p = a2.map(|x| 1.0 / (x + u));
        let w = u * (p[0] * p[1] * p[2]).sqrt(); // u/Δ (du = u ds)
        for (i, f) in fd.iter_mut().enumerate() {
            let (j, k) = others(i);
            f.add(u * w * p[i] * (p[j] + p[k]));
        }
        for (n, &(i, j, k)) in PAIRS.iter().enumerate() {
            fo[n].add(w * (s[i] * p[i]) * (s[j] * p[j]));
            let qu = q[n] + u;
            let t1 = -0.5 * u * w * p[k] / qu;
            let t2 = 0.5 * dl[n] * u * (q[n] - u) * w * p[i] * p[j] / (qu * qu);
            d[n].add(t1);
            d[n].add(t2);
            dabs[n] += t1.abs() + t2.abs();
        }
    }
    let d = d.map(|x| STEP * x.sum());
    HessianQuadrature {
        fd: fd.map(|x| STEP * x.sum()),
        fo: fo.map(|x| STEP * x.sum()),
        d_cond: [0, 1, 2].map(|n| STEP * dabs[n] / d[n].abs()),
        d,
    }
}

/// Self-gravity of a homogeneous pseudo-rigid body in three dimensions (EFE ch. 3, the potential
/// of the Riemann ellipsoids):
/// U(X) = −4πGρ R_F(σ₁², σ₂², σ₃²) over the singular values σ_i of X, for the unit ball of
/// density ρ as reference configuration (mass M = 4πρ/3) and the library's kinetic energy
/// ½ tr(ẊᵀẊ) (the physical energy divided by M/5; module doc). A sphere of radius a has
/// U = −4πGρ/a; ∂U/∂σ_i = 2πGρ′ σ_i A_i with the actual density ρ′ = ρ/(σ₁σ₂σ₃) and the index
/// symbols A_i ([`index_symbols`]), so the force balance of a figure of equilibrium reads as in
/// EFE (e.g. a Maclaurin spheroid: Ω² = 2πGρ′(A₁ − A₃ a₃²/a₁²)).
///
/// Defined for n = 3 only ([`Potential::dimension`]) and where every σ_i > 0
/// ([`Potential::needs_positive_det`]: the checked entry points and the integrators refuse
/// det X ≤ 0). Value, gradient (R diag(g) Sᵀ, nalgebra's 3×3 SVD, also [`Potential::gradient3`])
/// and analytic Hessian (Lewis–Sendov form with the cancellation-free quadratures of the module
/// doc; exact at coincident singular values, e.g. Maclaurin spheroids). An axis ratio below
/// 2⁻²⁵⁰ gives a non-finite Hessian (refused by the checked entry points).
#[derive(Clone, Copy, PartialEq)]
pub struct SelfGravity {
    g: f64,
    rho: f64,
    /// 4πGρ = km · 2^ke (km of moderate size even where G or ρ is extreme).
    km: f64,
    ke: i32,
}

impl std::fmt::Debug for SelfGravity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SelfGravity")
            .field("g", &self.g)
            .field("rho", &self.rho)
            .finish()
    }
}

impl SelfGravity {
    /// The self-gravity with gravitational constant G > 0 and reference density ρ > 0 (both
    /// finite).
    pub fn new(g: f64, rho: f64) -> Result<Self> {
        check::positive("G", g)?;
        check::positive("rho", rho)?;
        let (eg, er) = (check::pow2_exponent(g), check::pow2_exponent(rho));
        let km = 4.0 * std::f64::consts::PI * check::ldexp(g, -eg) * check::ldexp(rho, -er);
        Ok(SelfGravity {
            g,
            rho,
            km,
            ke: eg + er,
        })
    }
    /// The gravitational constant G.
    pub fn g(&self) -> f64 {
        self.g
    }
    /// The density ρ of the reference configuration (the unit ball).
    pub fn rho(&self) -> f64 {
        self.rho
    }

    /// U = −km R_F(σ̂²) 2^{ke − e} from the scaled SVD.
    fn value3(&self, svd: &Svd3) -> f64 {
        let s2 = svd.s.map(|x| x * x);
        -check::ldexp(self.km * rf_kernel(s2[0], s2[1], s2[2]), self.ke - svd.e)
    }

    /// ĝ_i = σ̂_i R_D(σ̂_j², σ̂_k², σ̂_i²)/3, the gradient in σ without km 2^{ke − 2e}.
    fn grad_sigma(s: &Vector3<f64>) -> [f64; 3] {
        let s2 = s.map(|x| x * x);
        [0, 1, 2].map(|i| {
            let (j, k) = others(i);
            s[i] * rd_kernel(s2[j], s2[k], s2[i]) / 3.0
        })
    }

    fn gradient_of(&self, svd: &Svd3) -> Matrix3<f64> {
        let g = Self::grad_sigma(&svd.s);
        let c = |x: f64| check::ldexp(self.km * x, self.ke - 2 * svd.e);
        let d = Vector3::new(c(g[0]), c(g[1]), c(g[2]));
        svd.u * Matrix3::from_diagonal(&d) * svd.v.transpose()
    }

    fn hessian_of(&self, svd: &Svd3, v: &Matrix3<f64>) -> Matrix3<f64> {
        let s = [svd.s[0], svd.s[1], svd.s[2]];
        if !ratio_supported(&s.map(|x| x / s[0].max(s[1]).max(s[2]))) {
            return Matrix3::from_element(f64::NAN);
        }
        let q = hessian_quadrature(&s);
        let g = Self::grad_sigma(&svd.s);
        // Everything below is in units of km 2^{ke − 3e}: f = −½ fd, −½ fo; (g_i − g_j)/(σ_i − σ_j)
        // = ½ D_ij or the difference of ĝ; (g_i + g_j)/(σ_i + σ_j).
        let mut f = Matrix3::zeros();
        let (mut dd, mut sm) = (Matrix3::zeros(), Matrix3::zeros());
        for i in 0..3 {
            f[(i, i)] = -0.5 * q.fd[i];
        }
        for (n, &(i, j, _)) in PAIRS.iter().enumerate() {
            f[(i, j)] = -0.5 * q.fo[n];
            f[(j, i)] = f[(i, j)];
            let gcond = (g[i] + g[j]) / (g[i] - g[j]).abs();
            let x = if s[i] != s[j] && gcond < q.d_cond[n] {
                (g[i] - g[j]) / (s[i] - s[j])
            } else {
                0.5 * q.d[n]
            };
            dd[(i, j)] = x;
            dd[(j, i)] = x;
            let y = (g[i] + g[j]) / (s[i] + s[j]);
            sm[(i, j)] = y;
            sm[(j, i)] = y;
        }
        let m = svd.u.transpose() * v * svd.v;
        let mut h = Matrix3::zeros();
        for i in 0..3 {
            h[(i, i)] = (0..3).map(|j| f[(i, j)] * m[(j, j)]).sum();
            for j in 0..3 {
                if i != j {
                    h[(i, j)] = 0.5 * (m[(i, j)] + m[(j, i)]) * dd[(i, j)]
                        + 0.5 * (m[(i, j)] - m[(j, i)]) * sm[(i, j)];
                }
            }
        }
        let out = svd.u * h * svd.v.transpose();
        out.map(|x| check::ldexp(self.km * x, self.ke - 3 * svd.e))
    }
}

/// X/2^e = U diag(σ̂) Vᵀ (nalgebra's 3×3 SVD; U, V orthogonal, σ̂ ≥ 0), 2^e ≤ max |X_ij| < 2^{e+1}
/// (exact), so that the largest σ̂ lies in [1, 6).
struct Svd3 {
    u: Matrix3<f64>,
    s: Vector3<f64>,
    v: Matrix3<f64>,
    e: i32,
}

fn svd3(x: &Matrix3<f64>) -> Option<Svd3> {
    let e = check::pow2_floor(x.amax());
    let xs = x.map(|v| check::ldexp(v, -e));
    let svd = xs.try_svd(true, true, f64::EPSILON, 1000)?;
    Some(Svd3 {
        u: svd.u?,
        s: svd.singular_values,
        v: svd.v_t?.transpose(),
        e,
    })
}

/// The 3×3 copy of a faer matrix (`None` if it is not 3×3).
fn mat3(x: MatRef<'_, f64>) -> Option<Matrix3<f64>> {
    (x.nrows() == 3 && x.ncols() == 3).then(|| Matrix3::from_fn(|i, j| x[(i, j)]))
}

impl Potential for SelfGravity {
    /// −4πGρ R_F(σ₁², σ₂², σ₃²); NaN where X is not 3×3 or the SVD fails.
    fn parameters(&self) -> Vec<&'static str> {
        vec!["G", "rho"]
    }
    /// U is linear in G and in ρ.
    fn add_parameter_gradient(
        &self,
        x: MatRef<'_, f64>,
        m: usize,
        out: MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        let theta = if m == 0 { self.g } else { self.rho };
        super::potential::add_gradient_over(self, theta, x, out, ws);
    }
    fn value(&self, x: MatRef<'_, f64>, _ws: &mut Workspace) -> f64 {
        match mat3(x).as_ref().and_then(svd3) {
            Some(svd) => self.value3(&svd),
            None => f64::NAN,
        }
    }

    fn add_gradient(&self, x: MatRef<'_, f64>, mut out: MatMut<'_, f64>, _ws: &mut Workspace) {
        match mat3(x).and_then(|x| self.gradient3(&x)) {
            Some(g) => {
                for i in 0..3 {
                    for j in 0..3 {
                        out[(i, j)] += g[(i, j)];
                    }
                }
            }
            None => out.fill(f64::NAN),
        }
    }

    fn add_hessian(
        &self,
        x: MatRef<'_, f64>,
        v: MatRef<'_, f64>,
        mut out: MatMut<'_, f64>,
        _ws: &mut Workspace,
    ) {
        let svd = mat3(x).as_ref().and_then(svd3);
        match (svd, mat3(v)) {
            (Some(svd), Some(v)) => {
                let h = self.hessian_of(&svd, &v);
                for i in 0..3 {
                    for j in 0..3 {
                        out[(i, j)] += h[(i, j)];
                    }
                }
            }
            _ => out.fill(f64::NAN),
        }
    }

    fn needs_positive_det(&self) -> bool {
        true
    }

    fn dimension(&self) -> Option<usize> {
        Some(3)
    }

    fn gradient3(&self, x: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        svd3(x).map(|svd| self.gradient_of(&svd))
    }
}
