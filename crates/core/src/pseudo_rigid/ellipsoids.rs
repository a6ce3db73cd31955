//! Self-gravitating incompressible fluid ellipsoids — Maclaurin, Jacobi, Dedekind and Riemann
//! S-type — as relative equilibria of the incompressible pseudo-rigid body with the potential
//! [`SelfGravity`] (001 §1, §8; Chandrasekhar, *Ellipsoidal Figures of Equilibrium* (EFE),
//! ch. 5–7), and their one-parameter families for continuation.
//!
//! # The equations (derived again; checked in `tests/ellipsoids.rs`)
//! All these figures rotate in the (1, 2) plane: Ω = ω e₁₂, Λ = μ e₁₂ at A₀ = diag(a), and
//! X(t) = e^{tΩ}A₀e^{−tΛ} (001 (8.2)). The force balance of the augmented potential
//! U − ½‖ΩA − AΛ‖² (001 (8.12)) with the multiplier p of det X = V (the pressure) is, with
//! g = ∂U/∂a,
//!
//! F₁ = g₁ − (ω² + μ²)a₁ + 2ωμ a₂ − p a₂a₃ = 0,
//! F₂ = g₂ − (ω² + μ²)a₂ + 2ωμ a₁ − p a₁a₃ = 0,
//! F₃ = g₃ − p a₁a₂ = 0,  F₄ = a₁a₂a₃ − V = 0.
//!
//! The (8.6) condition holds for every shape (one plane: [`super::equilibria`]). F₁ − F₂ =
//! (g₁ − g₂) − (a₁ − a₂)[(ω + μ)² − p a₃] vanishes identically at a₁ = a₂ (g₁ = g₂ by symmetry):
//! the Maclaurin spheroids, from which the ellipsoids with a₁ ≠ a₂ branch off where the
//! antisymmetric derivative H₁₁ − H₁₂ − (ω + μ)² + p a₃ vanishes (H = ∂²U/∂a²).
//!
//! For [`SelfGravity`], g_i = 2πGρ′ a_i A_i and H_ij = 2πGρ′(δ_ij A_i − (1 + 2δ_ij)a_ia_jA_ij)
//! (index symbols A_i, A_ij; ρ′ = ρ/det X the density of the figure). With μ = 0, F₁/a₁ and
//! F₂/a₂ give ω² = 2πGρ′(A₁ − a₃²A₃/a₁²) = 2πGρ′(A₂ − a₃²A₃/a₂²), i.e. EFE §39 (4)
//! a₁²a₂²A₁₂ = a₃²A₃ and (5) Ω² = 2πGρ′B₁₂, B₁₂ = A₂ − a₁²A₁₂ (using A₁ − A₂ = −(a₁² − a₂²)A₁₂);
//! at a₁ = a₂ the branch condition is a₁⁴A₁₁ = a₃²A₃.
//!
//! # Physical quantities and conventions
//! The figure turns with the angular velocity Ω₃ = −ω about x₃ (hat(e₃) = −e₁₂ in the e_ij basis
//! of DESIGN.md). In the frame of the figure the fluid moves with u = −AΛA⁻¹x, whose vorticity is
//! ζ = μ(a₁² + a₂²)/(a₁a₂); f = ζ/Ω₃ (EFE's ratio): f = 0 Jacobi (rigid rotation), f = ±∞
//! Dedekind (stationary figure), f = −2 irrotational in the inertial frame. The velocities of a
//! family with fixed f lie on the ray μ/ω = −f a₁a₂/(a₁² + a₂²); figures are returned with
//! Ω₃ ≥ 0 (and μ ≤ 0 for Dedekind's, the transpose of Jacobi's: X ↦ Xᵀ swaps Ω and Λ).
//!
//! The library's kinetic energy is ½tr(ẊᵀẊ), the fluid's (M/5)·½tr(ẊᵀẊ) with M = 4πρ/3 (the
//! reference body is the unit ball of density ρ), so energies and momenta are multiplied by
//! M/5 and reported in EFE's units: L/√(GM³ā), E/(GM²/ā), ā = (a₁a₂a₃)^{1/3}.

use std::sync::Arc;

use super::equilibria::RelativeEquilibrium;
use super::gravity::SelfGravity;
use super::potential::{self, Potential};
use super::system::PseudoRigidBody;
use crate::analysis::comoving;
use crate::analysis::continuation::{self, Branch, Family, Indicator, Options};
use crate::error::{Error, Result};
use crate::Mat;

/// The largest number of sign changes scanned for when solving for a₃.
const SCAN: usize = 400;

/// An ellipsoidal figure of equilibrium rotating in the (1, 2) plane (module docs): semi-axes,
/// the velocities Ω = ω e₁₂, Λ = μ e₁₂, the pressure multiplier, and the family it belongs to.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// Semi-axes (a₁, a₂, a₃).
    pub a: [f64; 3],
    /// ω: Ω = ω e₁₂ (the figure turns with Ω₃ = −ω about x₃).
    pub omega: f64,
    /// μ: Λ = μ e₁₂ (the internal motion).
    pub mu: f64,
    /// The multiplier of det X = a₁a₂a₃ (F₃: p = g₃/(a₁a₂)).
    pub pressure: f64,
    /// The family: f = ζ/Ω₃ (0 Jacobi, +∞ Dedekind).
    pub f: f64,
}

/// Physical quantities of a [`Figure`] (module docs for the units).
#[derive(Clone, Debug, PartialEq)]
pub struct Quantities {
    /// √(1 − a₃²/max(a₁, a₂)²) (the meridional eccentricity; NaN if a₃ is the longest axis).
    pub e: f64,
    /// a₂/a₁.
    pub a2_over_a1: f64,
    /// a₃/a₁.
    pub a3_over_a1: f64,
    /// Ω₃ (the figure's angular velocity about x₃).
    pub omega3: f64,
    /// ζ = μ(a₁² + a₂²)/(a₁a₂), the vorticity of the internal motion in the figure's frame.
    pub zeta: f64,
    /// f = ζ/Ω₃ (±∞ for a stationary figure).
    pub f: f64,
    /// Ω₃²/(πGρ′), ρ′ the density of the figure.
    pub omega2_over_pi_g_rho: f64,
    /// The angular momentum about x₃ in units of √(GM³ā).
    pub angular_momentum: f64,
    /// The circulation Γ of 001 (7.3) (the x₃ component of PᵀX − XᵀP, times M/5) in the same units.
    pub circulation: f64,
    /// The energy in units of GM²/ā.
    pub energy: f64,
}

/// The fluid: self-gravity with constants G and ρ (the density of the reference unit ball).
#[derive(Clone, Debug)]
pub struct Fluid {
    gravity: Arc<SelfGravity>,
}

fn e12(w: f64) -> Mat {
    Mat::from_fn(3, 3, |i, j| match (i, j) {
        (0, 1) => w,
        (1, 0) => -w,
        _ => 0.0,
    })
}

fn diag(a: &[f64; 3]) -> Mat {
    Mat::from_fn(3, 3, |i, j| if i == j { a[i] } else { 0.0 })
}

/// The family of figures with f = ζ/Ω₃ as a ray in the (ω, μ) plane: the figures satisfy
/// w_μ·μ(a₁² + a₂²) + w_ω·ω a₁a₂ = 0 with (w_μ, w_ω) ∝ (1, f) (∝ (0, 1) for f = ±∞), built from f
/// directly (no angle, so f = ±∞ and large |f| are exact).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Ray {
    w_mu: f64,
    w_omega: f64,
}

impl Ray {
    fn new(f: f64) -> Ray {
        let (p, q) = if f.is_infinite() {
            (0.0, 1.0)
        } else if f.abs() <= 1.0 {
            (1.0, f)
        } else {
            (1.0 / f, 1.0)
        };
        let r = p.hypot(q);
        Ray {
            w_mu: p / r,
            w_omega: q / r,
        }
    }

    /// The ray equation's residual at (a, ω, μ).
    fn residual(&self, a: &[f64; 3], omega: f64, mu: f64) -> f64 {
        self.w_mu * mu * (a[0] * a[0] + a[1] * a[1]) + self.w_omega * omega * a[0] * a[1]
    }

    /// The unit direction (c, s) of (ω, μ) on the ray, with c ≥ 0 (and s ≥ 0 when c = 0), so
    /// that a negative speed gives Ω₃ = −ω ≥ 0 (and μ ≤ 0 for a stationary figure).
    fn direction(&self, a: &[f64; 3]) -> (f64, f64) {
        let (c, s) = (
            self.w_mu * (a[0] * a[0] + a[1] * a[1]),
            -self.w_omega * a[0] * a[1],
        );
        let r = c.hypot(s);
        if c < 0.0 || (c == 0.0 && s < 0.0) {
            (-c / r, -s / r)
        } else {
            (c / r, s / r)
        }
    }
}

fn finite(what: &str, x: f64) -> Result<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(Error::NonFinite {
            what: what.into(),
            location: "the result".into(),
        })
    }
}

impl Fluid {
    /// Self-gravity with G > 0, ρ > 0.
    pub fn new(g: f64, rho: f64) -> Result<Self> {
        Ok(Fluid {
            gravity: Arc::new(SelfGravity::new(g, rho)?),
        })
    }

    /// The potential.
    pub fn potential(&self) -> Arc<dyn Potential> {
        self.gravity.clone()
    }

    /// The self-gravity.
    pub fn gravity(&self) -> &SelfGravity {
        &self.gravity
    }

    /// g = ∂U/∂a at diag(a) (the diagonal of ∂U/∂X).
    fn force(&self, a: &[f64; 3]) -> Result<[f64; 3]> {
        let g = potential::gradient(self.gravity.as_ref(), &diag(a))?;
        Ok([g[(0, 0)], g[(1, 1)], g[(2, 2)]])
    }

    /// H = ∂²U/∂a² at diag(a) (diagonal entries of D²U[E_jj]).
    fn stiffness(&self, a: &[f64; 3]) -> Result<[[f64; 3]; 3]> {
        let x = diag(a);
        let mut h = [[0.0; 3]; 3];
        for (j, col) in h.iter_mut().enumerate() {
            let ejj = Mat::from_fn(3, 3, |r, c| if r == j && c == j { 1.0 } else { 0.0 });
            let d = potential::hessian_product(self.gravity.as_ref(), &x, &ejj)?;
            *col = [d[(0, 0)], d[(1, 1)], d[(2, 2)]];
        }
        Ok(h) // symmetric: h[j][i] = H_ij
    }

    /// The residuals (F₁, F₂, F₃) of the force balance (module docs) at u = (a, ω, μ, p).
    fn balance(&self, a: &[f64; 3], omega: f64, mu: f64, p: f64) -> Result<[f64; 3]> {
        let g = self.force(a)?;
        let w2 = omega * omega + mu * mu;
        let c = 2.0 * omega * mu;
        Ok([
            g[0] - w2 * a[0] + c * a[1] - p * a[1] * a[2],
            g[1] - w2 * a[1] + c * a[0] - p * a[0] * a[2],
            g[2] - p * a[0] * a[1],
        ])
    }

    /// The figure of the family f with semi-axes a: p from F₃, the speed on the ray from F₁
    /// (or F₂), or `None` if its square is negative.
    fn velocities(&self, a: &[f64; 3], f: f64) -> Result<Option<Figure>> {
        let g = self.force(a)?;
        let p = g[2] / (a[0] * a[1]);
        let (c, s) = Ray::new(f).direction(a);
        let s2c = 2.0 * s * c;
        let (n1, d1) = (g[0] - p * a[1] * a[2], a[0] - s2c * a[1]);
        let (n2, d2) = (g[1] - p * a[0] * a[2], a[1] - s2c * a[0]);
        let speed2 = if d1.abs() >= d2.abs() {
            n1 / d1
        } else {
            n2 / d2
        };
        if speed2.is_nan() || speed2 < 0.0 {
            return Ok(None);
        }
        // Ω₃ = −ω ≥ 0 (Ray::direction has c ≥ 0); 0·c stays +0 for a stationary figure.
        let sp = -speed2.sqrt();
        Ok(Some(Figure {
            a: *a,
            omega: if c == 0.0 { 0.0 } else { sp * c },
            mu: sp * s,
            pressure: p,
            f,
        }))
    }

    /// F₁ and F₂ on the ray of f at fixed (a₁, a₂), divided by a₁ − a₂, as a function of a₃
    /// (zero at a figure; smooth through a₁ = a₂). With D = (g₁ − g₂)/(a₁ − a₂) from the
    /// potential's Hessian (the Lewis–Sendov divided difference: the (1, 2) entry of
    /// D²U(A)[E₁₂ + E₂₁], exact at a₁ = a₂), G_k = g_k − p·(product of the other two axes) and
    /// c₂ = sin 2φ of the ray direction: G₁ − G₂ = (a₁ − a₂)(D + p a₃), so
    /// [G₁(a₂ − c₂a₁) − G₂(a₁ − c₂a₂)]/(a₁ − a₂) = a₂(D + pa₃) − G₂ − c₂[a₁(D + pa₃) + G₂].
    /// At a₁ = a₂, f = 0 its root is the Maclaurin–Jacobi bifurcation.
    fn mismatch(&self, a: &[f64; 3], f: f64) -> Result<f64> {
        let g = self.force(a)?;
        let p = g[2] / (a[0] * a[1]);
        let v = Mat::from_fn(3, 3, |i, j| if i + j == 1 { 1.0 } else { 0.0 });
        let d = potential::hessian_product(self.gravity.as_ref(), &diag(a), &v)?[(0, 1)];
        let (c, s) = Ray::new(f).direction(a);
        let c2 = 2.0 * s * c;
        let g2 = g[1] - p * a[0] * a[2];
        let dp = d + p * a[2];
        Ok(a[1] * dp - g2 - c2 * (a[0] * dp + g2))
    }

    /// The figure of the family f with a₁ = 1, a₂ = r (0 < r ≤ 1): a₃ is the root of the
    /// mismatch (scanned on a geometric grid in (10⁻⁴, 1.5), refined by bisection to round-off)
    /// with a real speed; of several, the one with the largest a₃. At r = 1 it is the spheroid
    /// where the family branches off the Maclaurin sequence.
    fn ellipsoid(&self, r: f64, f: f64, what: &str) -> Result<Figure> {
        if !(r > 0.0 && r <= 1.0) {
            return Err(Error::invalid(
                "a2_over_a1",
                format!("expected 0 < a2/a1 ≤ 1 for {what} ellipsoids, got {r}"),
            ));
        }
        let at = |a3: f64| self.mismatch(&[1.0, r, a3], f);
        let (lo, hi) = (1e-4_f64, 1.5_f64);
        let grid: Vec<f64> = (0..=SCAN)
            .map(|k| lo * (hi / lo).powf(k as f64 / SCAN as f64))
            .collect();
        let mut best: Option<Figure> = None;
        let mut prev = at(grid[SCAN])?;
        for k in (0..SCAN).rev() {
            let (x0, x1) = (grid[k], grid[k + 1]);
            let f0 = at(x0)?;
            if (f0 > 0.0) != (prev > 0.0) && f0 != 0.0 && prev != 0.0 {
                // Bisection to round-off.
                let (mut l, mut h, mut fl) = (x0, x1, f0);
                for _ in 0..200 {
                    let m = 0.5 * (l + h);
                    if m <= l || m >= h {
                        break;
                    }
                    let fm = at(m)?;
                    if (fm > 0.0) == (fl > 0.0) {
                        l = m;
                        fl = fm;
                    } else {
                        h = m;
                    }
                }
                let a3 = 0.5 * (l + h);
                if let Some(fig) = self.velocities(&[1.0, r, a3], f)? {
                    best = Some(fig);
                    break;
                }
            }
            prev = f0;
        }
        best.ok_or_else(|| {
            Error::invalid(
                "ellipsoid",
                format!("no {what} ellipsoid with a2/a1 = {r} (f = {f}) for a3/a1 in (1e-4, 1.5)"),
            )
        })
    }

    /// The Maclaurin spheroid of eccentricity e ∈ [0, 1): a = (1, 1, √(1 − e²)), rigid rotation
    /// with Ω₃² = (g₁ − p a₃)/a₁ (EFE ch. 5 §32: Ω²/(πGρ) = 2√(1−e²)(3−2e²) asin(e)/e³ − 6(1−e²)/e²).
    pub fn maclaurin(&self, e: f64) -> Result<Figure> {
        if !(0.0..1.0).contains(&e) {
            return Err(Error::invalid("e", format!("expected 0 ≤ e < 1, got {e}")));
        }
        let a = [1.0, 1.0, (1.0 - e * e).sqrt()];
        self.velocities(&a, 0.0)?.ok_or_else(|| {
            Error::invalid("e", format!("no rotating Maclaurin spheroid at e = {e}"))
        })
    }

    /// The Jacobi ellipsoid with a₁ = 1, a₂ = r ∈ (0, 1] (EFE ch. 6 §39: a₁²a₂²A₁₂ = a₃²A₃;
    /// r = 1 is the Maclaurin spheroid where the sequence branches off).
    pub fn jacobi(&self, r: f64) -> Result<Figure> {
        self.ellipsoid(r, 0.0, "Jacobi")
    }

    /// The Dedekind ellipsoid adjoint to the Jacobi ellipsoid with the same axes (Dedekind's
    /// theorem: X ↦ Xᵀ swaps Ω and Λ): a stationary figure with internal motion.
    pub fn dedekind(&self, r: f64) -> Result<Figure> {
        let j = self.jacobi(r)?;
        Ok(Figure {
            omega: j.mu,
            mu: j.omega,
            f: f64::INFINITY,
            ..j
        })
    }

    /// The Riemann S-type ellipsoid with a₁ = 1, a₂ = r ∈ (0, 1) and f = ζ/Ω₃ (EFE ch. 7 §48;
    /// f = ±∞ gives the Dedekind ellipsoid computed on its own ray).
    pub fn riemann_s(&self, r: f64, f: f64) -> Result<Figure> {
        if f.is_nan() {
            return Err(Error::invalid(
                "f",
                "expected a real number or ±inf, got NaN",
            ));
        }
        // f = ±∞ is one family (the stationary figures), recorded as +∞.
        let f = if f.is_infinite() { f64::INFINITY } else { f };
        self.ellipsoid(r, f, "Riemann S-type")
    }

    /// The point where the Jacobi ellipsoids branch off the Maclaurin spheroids: the root in
    /// e of H₁₁ − H₁₂ − ω² + p a₃ = 0 on the Maclaurin sequence (module docs; EFE: e = 0.81267,
    /// a₁⁴A₁₁ = a₃²A₃), by bisection to round-off.
    pub fn maclaurin_jacobi_bifurcation(&self) -> Result<Figure> {
        let test = |e: f64| -> Result<f64> {
            let m = self.maclaurin(e)?;
            let h = self.stiffness(&m.a)?;
            Ok(h[0][0] - h[1][0] - m.omega * m.omega + m.pressure * m.a[2])
        };
        let (mut lo, mut hi) = (0.5, 0.95);
        let flo = test(lo)?;
        if (flo > 0.0) == (test(hi)? > 0.0) {
            return Err(Error::invalid(
                "bifurcation",
                "the branch test does not change sign on the Maclaurin sequence for e in (0.5, 0.95)",
            ));
        }
        for _ in 0..200 {
            let m = 0.5 * (lo + hi);
            if m <= lo || m >= hi {
                break;
            }
            if (test(m)? > 0.0) == (flo > 0.0) {
                lo = m;
            } else {
                hi = m;
            }
        }
        self.maclaurin(0.5 * (lo + hi))
    }

    /// The relative equilibrium of the incompressible body with this figure (residuals with the
    /// pressure, [`RelativeEquilibrium::incompressible`]).
    pub fn relative_equilibrium(&self, fig: &Figure) -> Result<RelativeEquilibrium> {
        RelativeEquilibrium::incompressible(
            self.gravity.as_ref(),
            &fig.a,
            &e12(fig.omega),
            &e12(fig.mu),
        )
    }

    /// The incompressible body of this fluid ([`PseudoRigidBody::incompressible`]).
    pub fn body(&self) -> Result<PseudoRigidBody> {
        PseudoRigidBody::incompressible(3, self.potential())
    }

    /// The state (X₀, P₀) = (A₀, ΩA₀ − A₀Λ) of a figure, flat, and its ξ ⊕ η = Ω ⊕ Λ in the
    /// e_ij coordinates of [`crate::integrate::problem::Symmetric`] (ξ block first).
    pub fn state(fig: &Figure) -> (Vec<f64>, Vec<f64>) {
        let (x, om, la) = (diag(&fig.a), e12(fig.omega), e12(fig.mu));
        let p = &om * &x - &x * &la;
        let z = (0..9)
            .map(|k| x[(k / 3, k % 3)])
            .chain((0..9).map(|k| p[(k / 3, k % 3)]))
            .collect();
        (z, vec![fig.omega, 0.0, 0.0, fig.mu, 0.0, 0.0])
    }

    /// √(Gρ): the rate that scales all velocities (ω, μ ∝ √(Gρ), p ∝ Gρ at fixed shape).
    fn rate(&self) -> f64 {
        (self.gravity.g() * self.gravity.rho()).sqrt()
    }

    /// The same figure of the fluid with G = ρ = 1 (time measured in units of 1/√(Gρ)).
    fn to_unit(&self, fig: &Figure) -> Figure {
        let r = self.rate();
        Figure {
            omega: fig.omega / r,
            mu: fig.mu / r,
            pressure: fig.pressure / r / r,
            ..fig.clone()
        }
    }

    /// The energy–momentum and spectral stability of a figure under the incompressible full
    /// dynamics, in the co-moving frame ([`comoving::stability`]; valid at coincident axes).
    /// Computed for the fluid with G = ρ = 1 and the figure in its units: G and ρ only set the
    /// unit of time, so the verdicts do not depend on them (eigenvalues are in units of √(Gρ)).
    pub fn stability(&self, fig: &Figure) -> Result<comoving::Stability> {
        let (z, xi) = Self::state(&self.to_unit(fig));
        comoving::stability(&Fluid::new(1.0, 1.0)?.body()?, &z, &xi)
    }

    /// The residuals (F₁, F₂, F₃) of a figure's force balance (module docs).
    pub fn residuals(&self, fig: &Figure) -> Result<[f64; 3]> {
        self.balance(&fig.a, fig.omega, fig.mu, fig.pressure)
    }

    /// Physical quantities (module docs).
    pub fn quantities(&self, fig: &Figure) -> Result<Quantities> {
        let (g, rho) = (self.gravity.g(), self.gravity.rho());
        let a = &fig.a;
        let v = a[0] * a[1] * a[2];
        let rho_fig = rho / v;
        let mass = 4.0 * std::f64::consts::PI * rho / 3.0;
        let abar = v.cbrt();
        let re = self.relative_equilibrium(fig)?;
        let omega3 = 0.0 - fig.omega; // +0 for a stationary figure
        let zeta = fig.mu * (a[0] * a[0] + a[1] * a[1]) / (a[0] * a[1]);
        // (M/5)ℓ/√(GM³ā) = ℓ/(5√(GMā)) and (M/5)H/(GM²/ā) = Hā/(5GM): no powers of M that
        // under- or overflow.
        let lunit = 5.0 * (g * mass * abar).sqrt();
        let amax = a[0].max(a[1]);
        Ok(Quantities {
            e: (1.0 - (a[2] / amax).powi(2)).sqrt(),
            a2_over_a1: a[1] / a[0],
            a3_over_a1: a[2] / a[0],
            omega3,
            zeta,
            // A stationary figure (Dedekind's) has f = +∞ (θ = π/2).
            f: match (omega3 == 0.0, zeta == 0.0) {
                (true, true) => 0.0,
                (true, false) => f64::INFINITY,
                _ => zeta / omega3,
            },
            omega2_over_pi_g_rho: finite(
                "Omega²/(πGρ)",
                omega3 * omega3 / (std::f64::consts::PI * g * rho_fig),
            )?,
            angular_momentum: -re.lam[(0, 1)] / lunit,
            circulation: -re.gam[(0, 1)] / lunit,
            energy: re.energy * abar / (5.0 * g * mass),
        })
    }
}

/// The family of figures with fixed f = ζ/Ω₃ through a given volume, for
/// [`crate::analysis::continuation`]: unknowns u = (a₁, a₂, a₃, ω, μ, p) in the units of the fluid
/// with G = ρ = 1 (ω, μ in units of √(Gρ), p of Gρ, so that the unknowns are of one size whatever
/// G and ρ), equations F₁..F₄ of the module docs (F₄ relative: a₁a₂a₃/V − 1) and the ray
/// w_μ·μ(a₁² + a₂²) + w_ω·ω a₁a₂ = 0. The Jacobian is analytic (the potential's Hessian).
#[derive(Clone, Debug)]
pub struct EllipsoidFamily {
    /// The fluid (its G and ρ are those of the figures returned).
    pub fluid: Fluid,
    /// f = ζ/Ω₃ along the family.
    pub f: f64,
    /// The volume a₁a₂a₃ along the family.
    pub volume: f64,
    /// The fluid with G = ρ = 1, in which the equations are solved.
    unit: Fluid,
    ray: Ray,
}

impl EllipsoidFamily {
    /// The family of `fig` (its f and volume).
    pub fn of(fluid: &Fluid, fig: &Figure) -> Result<Self> {
        Ok(EllipsoidFamily {
            fluid: fluid.clone(),
            f: fig.f,
            volume: fig.a.iter().product(),
            unit: Fluid::new(1.0, 1.0)?,
            ray: Ray::new(fig.f),
        })
    }

    /// u of a figure of the fluid.
    pub fn unknowns_of(&self, fig: &Figure) -> Vec<f64> {
        let g = self.fluid.to_unit(fig);
        vec![g.a[0], g.a[1], g.a[2], g.omega, g.mu, g.pressure]
    }

    /// The figure of the fluid at u (checked: finite, semi-axes > 0).
    pub fn figure(&self, u: &[f64]) -> Result<Figure> {
        let g = self.unit_figure(u)?;
        let r = self.fluid.rate();
        Ok(Figure {
            omega: g.omega * r,
            mu: g.mu * r,
            pressure: g.pressure * r * r,
            ..g
        })
    }

    /// The figure of the unit fluid at u.
    fn unit_figure(&self, u: &[f64]) -> Result<Figure> {
        crate::check::len_of("u", u, 6)?;
        if u[..3].iter().any(|&x| x <= 0.0) {
            return Err(Error::invalid(
                "semi-axes",
                format!(
                    "expected all > 0, got {:?} (the family left GL+(3))",
                    &u[..3]
                ),
            ));
        }
        Ok(Figure {
            a: [u[0], u[1], u[2]],
            // The stationary family's ray is ω = 0: exactly, not the corrector's round-off.
            omega: if self.ray.w_mu == 0.0 { 0.0 } else { u[3] },
            mu: u[4],
            pressure: u[5],
            f: self.f,
        })
    }

    /// The direction of the branch crossing at a simple branch point
    /// ([`continuation::switch_direction`]) in the given [`Sense`].
    pub fn switch_direction(
        &self,
        point: &continuation::Point,
        sense: Sense<'_>,
    ) -> Result<Vec<f64>> {
        let mut d = continuation::switch_direction(self, point)?;
        // Splitting: a₁ − a₂ grows (the ellipsoids branching off the Maclaurin spheroids are
        // then numbered with a₁ > a₂, as in EFE).
        if d[0] - d[1] < 0.0 {
            d.iter_mut().for_each(|x| *x = -*x);
        }
        let flip = match sense {
            Sense::Splitting => false,
            Sense::Joining => true,
            Sense::Towards(name, stop) => {
                // The sign of dπ/ds along d; a parameter even in d (e at a symmetric
                // pitchfork) keeps the splitting sense.
                let u = &point.u;
                let h = 1e-6 * (1.0 + u.iter().map(|x| x * x).sum::<f64>().sqrt());
                let at = |sg: f64| -> Result<f64> {
                    let v: Vec<f64> = u.iter().zip(&d).map(|(a, b)| a + sg * h * b).collect();
                    self.parameter(name, &v)
                };
                let here = self.parameter(name, u)?;
                let slope = (at(1.0)? - at(-1.0)?) / (2.0 * h);
                slope.abs() > 1e-6 * (1.0 + here.abs()) && slope * (stop - here) < 0.0
            }
        };
        if flip {
            d.iter_mut().for_each(|x| *x = -*x);
        }
        Ok(d)
    }

    /// A named parameter of the figure at u: "e", "a2_over_a1", "a3_over_a1",
    /// "Omega2_over_piGrho", "L" (angular momentum), "f".
    pub fn parameter(&self, name: &str, u: &[f64]) -> Result<f64> {
        let q = self.unit.quantities(&self.unit_figure(u)?)?;
        Ok(match name {
            "e" => q.e,
            "a2_over_a1" => q.a2_over_a1,
            "a3_over_a1" => q.a3_over_a1,
            "Omega2_over_piGrho" => q.omega2_over_pi_g_rho,
            "L" => q.angular_momentum,
            "f" => q.f,
            other => {
                return Err(Error::invalid(
                    "parameter",
                    format!(
                        "unknown parameter {other:?}; expected one of {:?}",
                        PARAMETERS
                    ),
                ))
            }
        })
    }
}

/// The sense of the branch taken at a branch point ([`EllipsoidFamily::switch_direction`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sense<'a> {
    /// The way a₁ − a₂ grows.
    Splitting,
    /// The other way.
    Joining,
    /// The way the named parameter moves towards the value (or `Splitting` where it is even).
    Towards(&'a str, f64),
}

/// The parameters [`EllipsoidFamily::parameter`] knows.
pub const PARAMETERS: [&str; 6] = [
    "e",
    "a2_over_a1",
    "a3_over_a1",
    "Omega2_over_piGrho",
    "L",
    "f",
];

impl Family for EllipsoidFamily {
    fn unknowns(&self) -> usize {
        6
    }

    fn residual(&self, u: &[f64]) -> Result<Vec<f64>> {
        let f = self.unit_figure(u)?;
        let a = &f.a;
        let b = self.unit.balance(a, f.omega, f.mu, f.pressure)?;
        let ray = self.ray.residual(a, f.omega, f.mu);
        Ok(vec![
            b[0],
            b[1],
            b[2],
            a[0] * a[1] * a[2] / self.volume - 1.0,
            ray,
        ])
    }

    fn jacobian(&self, u: &[f64]) -> Result<Mat> {
        let f = self.unit_figure(u)?;
        let (a, w, m, p) = (&f.a, f.omega, f.mu, f.pressure);
        let h = self.unit.stiffness(a)?;
        let (w2, c) = (w * w + m * m, 2.0 * w * m);
        let (ct, st) = (self.ray.w_mu, self.ray.w_omega);
        let mut j = Mat::zeros(5, 6);
        // F₁ = g₁ − w2 a₁ + c a₂ − p a₂a₃
        j[(0, 0)] = h[0][0] - w2;
        j[(0, 1)] = h[1][0] + c - p * a[2];
        j[(0, 2)] = h[2][0] - p * a[1];
        j[(0, 3)] = -2.0 * w * a[0] + 2.0 * m * a[1];
        j[(0, 4)] = -2.0 * m * a[0] + 2.0 * w * a[1];
        j[(0, 5)] = -a[1] * a[2];
        // F₂ = g₂ − w2 a₂ + c a₁ − p a₁a₃
        j[(1, 0)] = h[0][1] + c - p * a[2];
        j[(1, 1)] = h[1][1] - w2;
        j[(1, 2)] = h[2][1] - p * a[0];
        j[(1, 3)] = -2.0 * w * a[1] + 2.0 * m * a[0];
        j[(1, 4)] = -2.0 * m * a[1] + 2.0 * w * a[0];
        j[(1, 5)] = -a[0] * a[2];
        // F₃ = g₃ − p a₁a₂
        j[(2, 0)] = h[0][2] - p * a[1];
        j[(2, 1)] = h[1][2] - p * a[0];
        j[(2, 2)] = h[2][2];
        j[(2, 5)] = -a[0] * a[1];
        // F₄ = a₁a₂a₃/V − 1
        j[(3, 0)] = a[1] * a[2] / self.volume;
        j[(3, 1)] = a[0] * a[2] / self.volume;
        j[(3, 2)] = a[0] * a[1] / self.volume;
        // ray = w_μ μ(a₁² + a₂²) + w_ω ω a₁a₂
        j[(4, 0)] = 2.0 * ct * m * a[0] + st * w * a[1];
        j[(4, 1)] = 2.0 * ct * m * a[1] + st * w * a[0];
        j[(4, 3)] = st * a[0] * a[1];
        j[(4, 4)] = ct * (a[0] * a[0] + a[1] * a[1]);
        Ok(j)
    }
}

/// Follows the family of `start` ([`EllipsoidFamily::of`]) in the named parameter
/// ([`PARAMETERS`]) until it reaches `stop` ([`continuation::follow`]); with `stability`, the
/// spectral and the energy–momentum verdicts ([`Fluid::stability`], in this order) are monitored
/// and their changes located. `direction`: the initial tangent in u (branch switching).
pub fn follow(
    family: &EllipsoidFamily,
    start: &[f64],
    parameter: &str,
    stop: f64,
    stability: bool,
    direction: Option<&[f64]>,
    opts: &Options,
) -> Result<Branch> {
    if parameter == "f" {
        return Err(Error::invalid(
            "parameter",
            "f is constant along a family (the family is the set of figures with the f of its \
             start); follow it in e, a2_over_a1, a3_over_a1, Omega2_over_piGrho or L",
        ));
    }
    family.parameter(parameter, start)?;
    let param = |u: &[f64]| family.parameter(parameter, u);
    // Margins: none for the spectral verdict (max Re λ leaves 0 like a square root at a Krein
    // collision: bisection), the smallest Hessian eigenvalue relative to the largest for the
    // energy–momentum verdict (a smooth crossing of zero).
    let monitor = |u: &[f64]| -> Result<Vec<Indicator>> {
        let s = family.unit.stability(&family.unit_figure(u)?)?;
        let em = &s.energy_momentum;
        let scale = em.min_real_part.abs().max(em.max_real_part.abs());
        Ok(vec![
            Indicator {
                stable: s.spectral.stable,
                margin: f64::NAN,
            },
            Indicator {
                stable: em.stable,
                margin: em.min_real_part / scale,
            },
        ])
    };
    let mon: Option<continuation::Monitor<'_>> = if stability { Some(&monitor) } else { None };
    continuation::follow(family, start, &param, stop, mon, direction, opts)
}
