//! Two disks rolling against each other in the plane without slipping (003 §1): a holonomic
//! system on SO(2)³ with the SO(2) symmetry of rotations about the centre of mass, its
//! rotational relative equilibria and their stability.
//!
//! **Configuration** (003 (1)–(4)). Disk k (radius r_k, mass m_k, centre of mass γ_k ∈ ℂ in the
//! reference disk, moment of inertia I_k = ∫|p|² dρ_k about the disk's centre, 003 (6)) is at
//! p ↦ z_k p + a_k with z_k = e^{iθ_k}; the contact point is P = a₁ + r₁u = a₂ − r₂u with
//! u = e^{iφ}, and the centre of mass of the pair is at the origin, which fixes a₁, a₂ (003 (4)).
//! Rolling without slipping integrates to Rφ − r₁θ₁ − r₂θ₂ = c, R = r₁ + r₂ (003 §1; c is the
//! *rolling constant*, a parameter of the system here). The state is z = (θ₁, θ₂, p₁, p₂), with
//! φ = (c + r₁θ₁ + r₂θ₂)/R.
//!
//! **Kinetic energy** (003 (6), derived again). KE_k = ½(I_k − m_k|γ_k|²)θ̇_k² + ½m_k|Ẋ_k|² with
//! X_k = z_kγ_k + a_k the centres of mass; by (4) X₁ = (m₂/M) w, X₂ = −(m₁/M) w with
//! w = z₁γ₁ − z₂γ₂ − Ru, so Σ½m_k|Ẋ_k|² = ½e|ẇ|², e = m₁m₂/(m₁ + m₂). Along the rolling
//! constraint ẇ = i(θ̇₁A − θ̇₂B) with A = z₁γ₁ − r₁u = X₁ − P and B = z₂γ₂ + r₂u = X₂ − P, so
//!
//! T = ½ θ̇ᵀ M(θ) θ̇,  M = [[I₁ᶜ + e|A|², −e Re(A B̄)], [−e Re(A B̄), I₂ᶜ + e|B|²]],
//! I_kᶜ = I_k − m_k|γ_k|² (the moment about the centre of mass).
//!
//! H = ½ pᵀM⁻¹p, integrated with the symplectic Gauss methods; ∂H/∂θ = −∂T/∂θ at fixed θ̇.
//!
//! **Tangent lift** (issue 26, [`CanonicalTangent`]). With s = Aθ̇₁ − Bθ̇₂ (= −iẇ),
//! Mθ̇ = (I_kᶜθ̇_k + e Re(c_k s̄))_k, c = (A, −B), and ∂H/∂θ_k = −e Re(s̄ s_k),
//! s_k = ∂_kA θ̇₁ − ∂_kB θ̇₂; one variation δ of (A, B, ∂A, ∂B, e, I_kᶜ, p) gives
//! δθ̇ = M⁻¹(δp − δM θ̇) and δ(∂H/∂θ_k) = −δe Re(s̄ s_k) − e Re(δs̄ s_k + s̄ δs_k): along a state
//! direction from ∂_k∂_lu = −(r_k r_l/R²)u, ∂²_{θ_1}a = −a, ∂²_{θ_2}b = −b; along the radii, the
//! masses, the moments and the rolling constant (all entering M) from how they move u, A, B, e
//! and I_kᶜ.
//!
//! **Symmetry.** The rotations e^{iψ} act by z_k, u ↦ e^{iψ}z_k, e^{iψ}u, i.e. θ ↦ θ + ψ(1, 1)
//! (the constraint is invariant); the momentum J = p₁ + p₂ is the total angular momentum about
//! the centre of mass (linear in z: every Gauss method keeps it to round-off). The locked
//! inertia is 𝕀(θ) = (1, 1)M(1, 1)ᵀ = I₁ᶜ + I₂ᶜ + e|w|².
//!
//! **Relative equilibria** (derived again; 003 §1 has two slips). A rotation θ(t) = θ₀ + ωt(1, 1)
//! solves the equations iff θ₀ is a critical point of the amended potential V_J = J²/(2𝕀) along
//! the shape direction, the rolling direction at fixed u: θ̇ ∝ (r₂, −r₁). In the gauge u = 1 with
//! a = z₁γ₁, b = z₂γ₂, d|w|²/dλ = 2R·f with
//!
//! f = Im((a − r₁)(b + r₂)‾) = Im((X₁ − P)(X₂ − P)‾),
//!
//! so **a rotational relative equilibrium is a configuration in which the two centres of mass
//! and the contact point are collinear** (the contact force is then central for both bodies).
//! 003 §1 prints the factorisation Im((z₁γ₁ + r₁)(z₂γ₂ − r₂)‾), i.e. X_k − P_k with P_k the
//! points diametrically opposite P: a sign slip in its last display (it is the condition for
//! u ↦ −u; the errata). Stability: V_J has a strict minimum iff 𝕀 has a strict maximum along the
//! rolling direction, i.e. f decreases through zero, f′_λ = R Re(a b̄) + r₂² Re a − r₁² Re b < 0
//! (a strict maximum of V_J, f′_λ > 0, is unstable: the shape space is one-dimensional). 003 §1
//! states the rule the other way round (stable where its quantity changes from negative to
//! positive, "local minima of the amended potential" meaning there the Lagrangian on the
//! generator, which is +½ξ²𝕀). Every ω ≠ 0 gives the same equilibria and verdicts (T is
//! homogeneous in θ̇ and there is no potential). Tests: each equilibrium stays put under the
//! dynamics, stable ones stay close after a perturbation and unstable ones leave
//! (`tests/rolling_disks.rs`).

use nalgebra::Complex;

use crate::check;
use crate::error::{fmt_num, Error, Result};
use crate::integrate::methods::canonical_catalog;
use crate::integrate::problem::{Canonical, Symmetric};
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{CanonicalTangent, Tangent};
use crate::integrate::Problem;

type C = Complex<f64>;

/// The widest θ₁ range [`RollingDisks::relative_equilibria`] searches, in turns of disk 1.
const MAX_TURNS: f64 = 1000.0;

/// Two disks rolling against each other (module docs); state z = (θ₁, θ₂, p₁, p₂).
#[derive(Clone, Debug, PartialEq)]
pub struct RollingDisks {
    r: [f64; 2],
    gamma: [C; 2],
    mass: [f64; 2],
    inertia: [f64; 2],
    c: f64,
}

/// The complex positions at one configuration (u = e^{iφ}, a = z₁γ₁, b = z₂γ₂, A = a − r₁u,
/// B = b + r₂u).
struct Local {
    u: C,
    a: C,
    b: C,
    big_a: C,
    big_b: C,
}

/// The pieces of T = ½Σ I_kᶜ θ̇_k² + ½e|s|², s = Aθ̇₁ − Bθ̇₂ (= −iẇ), at one configuration, with
/// ∂_kA, ∂_kB: M θ̇ = (I_kᶜθ̇_k + e Re(c_k s̄))_k with c = (A, −B), ∂H/∂θ_k = −e Re(s̄ s_k),
/// s_k = ∂_kA θ̇₁ − ∂_kB θ̇₂. A [`Pieces`] is also a variation δ of these (along a state
/// direction or a parameter, with δp).
#[derive(Clone, Copy, Default)]
struct Pieces {
    a: C,
    b: C,
    da: [C; 2],
    db: [C; 2],
    e: f64,
    central: [f64; 2],
    p: [f64; 2],
}

/// Where the pieces of the pair are, in the centre-of-mass frame (003 (4)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Positions {
    /// The disks' centres O_k = a_k.
    pub centres: [[f64; 2]; 2],
    /// The centres of mass X_k = z_kγ_k + a_k.
    pub masses: [[f64; 2]; 2],
    /// The contact point P.
    pub contact: [f64; 2],
}

/// A rotational relative equilibrium θ(t) = θ + ωt(1, 1), any ω ≠ 0 (module docs), in the gauge
/// u = 1 (the contact point on the positive real axis from disk 1's centre).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisksEquilibrium {
    /// (θ₁, θ₂).
    pub theta: [f64; 2],
    /// Whether the amended potential has a strict minimum there (Lyapunov stable relative to
    /// the rotation); see `degenerate`.
    pub stable: bool,
    /// f′_λ ≈ 0 (to 1e-10 relative): a degenerate critical point, the verdict is inconclusive.
    pub degenerate: bool,
    /// The contact point P (centre-of-mass frame).
    pub contact: [f64; 2],
    /// The locked inertia 𝕀 there.
    pub locked_inertia: f64,
    /// d²𝕀/dλ² along the rolling direction (r₂, −r₁): negative where stable.
    pub curvature: f64,
}

fn xy(z: C) -> [f64; 2] {
    [z.re, z.im]
}

impl RollingDisks {
    /// Disks of radii r_k > 0, centres of mass γ_k (|γ_k| < r_k), masses m_k > 0 and moments of
    /// inertia I_k about the disks' centres (I_k > m_k|γ_k|²), rolling constant 0. Errors:
    /// [`Error::InvalidArgument`] naming the parameter.
    pub fn new(
        r: [f64; 2],
        gamma: [[f64; 2]; 2],
        mass: [f64; 2],
        inertia: [f64; 2],
    ) -> Result<Self> {
        check::finite_slice("gamma", gamma.as_flattened())?;
        for k in 0..2 {
            check::positive(["r1", "r2"][k], r[k])?;
            check::positive(["m1", "m2"][k], mass[k])?;
            check::positive(["inertia1", "inertia2"][k], inertia[k])?;
            let g = C::new(gamma[k][0], gamma[k][1]).norm();
            if g >= r[k] {
                return Err(Error::invalid(
                    ["gamma1", "gamma2"][k],
                    format!(
                        "the centre of mass must lie inside the disk: |γ| = {g} ≥ r = {}",
                        r[k]
                    ),
                ));
            }
            if inertia[k] <= mass[k] * g * g {
                return Err(Error::invalid(
                    ["inertia1", "inertia2"][k],
                    format!(
                        "the moment about the disk's centre must exceed m|γ|² = {} (it is the \
                         moment about the centre of mass plus m|γ|²), got {}",
                        mass[k] * g * g,
                        inertia[k]
                    ),
                ));
            }
        }
        Ok(RollingDisks {
            r,
            gamma: gamma.map(|g| C::new(g[0], g[1])),
            mass,
            inertia,
            c: 0.0,
        })
    }

    /// The same pair with rolling constant c = Rφ − r₁θ₁ − r₂θ₂. Errors: non-finite c.
    pub fn with_rolling_constant(mut self, c: f64) -> Result<Self> {
        check::finite_slice("rolling_constant", &[c])?;
        self.c = c;
        Ok(self)
    }

    /// The rolling constant c.
    pub fn rolling_constant(&self) -> f64 {
        self.c
    }

    /// R = r₁ + r₂.
    fn big_r(&self) -> f64 {
        self.r[0] + self.r[1]
    }

    /// e = m₁m₂/(m₁ + m₂).
    fn reduced_mass(&self) -> f64 {
        self.mass[0] * self.mass[1] / (self.mass[0] + self.mass[1])
    }

    /// I_kᶜ = I_k − m_k|γ_k|².
    fn central(&self, k: usize) -> f64 {
        self.inertia[k] - self.mass[k] * self.gamma[k].norm_sqr()
    }

    /// φ = (c + r₁θ₁ + r₂θ₂)/R.
    pub fn phi(&self, theta: [f64; 2]) -> f64 {
        (self.c + self.r[0] * theta[0] + self.r[1] * theta[1]) / self.big_r()
    }

    fn local(&self, theta: [f64; 2]) -> Local {
        let u = C::from_polar(1.0, self.phi(theta));
        let a = C::from_polar(1.0, theta[0]) * self.gamma[0];
        let b = C::from_polar(1.0, theta[1]) * self.gamma[1];
        Local {
            u,
            a,
            b,
            big_a: a - u * self.r[0],
            big_b: b + u * self.r[1],
        }
    }

    /// M(θ) of T = ½θ̇ᵀMθ̇ (module docs). Errors: non-finite θ.
    pub fn mass_matrix(&self, theta: [f64; 2]) -> Result<[[f64; 2]; 2]> {
        check::finite_slice("theta", &theta)?;
        Ok(self.metric(&self.local(theta)))
    }

    fn metric(&self, l: &Local) -> [[f64; 2]; 2] {
        let e = self.reduced_mass();
        let off = -e * (l.big_a * l.big_b.conj()).re;
        [
            [self.central(0) + e * l.big_a.norm_sqr(), off],
            [off, self.central(1) + e * l.big_b.norm_sqr()],
        ]
    }

    /// The locked inertia 𝕀(θ) = I₁ᶜ + I₂ᶜ + e|w|² (module docs). Errors: non-finite θ.
    pub fn locked_inertia(&self, theta: [f64; 2]) -> Result<f64> {
        let m = self.mass_matrix(theta)?;
        Ok(m[0][0] + 2.0 * m[0][1] + m[1][1])
    }

    fn check_z(&self, z: &[f64]) -> Result<()> {
        check::len_of("state", z, 4)?;
        check::finite_slice("state", z)
    }

    /// The state z = (θ, Mθ̇). Errors: non-finite input, an overflow error where Mθ̇ exceeds the
    /// f64 range.
    pub fn state(&self, theta: [f64; 2], thetadot: [f64; 2]) -> Result<Vec<f64>> {
        check::finite_slice("thetadot", &thetadot)?;
        let m = self.mass_matrix(theta)?;
        let z = vec![
            theta[0],
            theta[1],
            m[0][0] * thetadot[0] + m[0][1] * thetadot[1],
            m[1][0] * thetadot[0] + m[1][1] * thetadot[1],
        ];
        if z.iter().any(|x| !x.is_finite()) {
            return Err(check::overflow_error("thetadot", "the momentum p = Mθ̇"));
        }
        Ok(z)
    }

    /// θ̇ = M⁻¹p.
    pub fn velocities(&self, z: &[f64]) -> Result<[f64; 2]> {
        self.check_z(z)?;
        Ok(velocity(
            &self.metric(&self.local([z[0], z[1]])),
            [z[2], z[3]],
        ))
    }

    /// The total angular momentum about the centre of mass, J = p₁ + p₂.
    pub fn angular_momentum(&self, z: &[f64]) -> Result<f64> {
        self.check_z(z)?;
        Ok(z[2] + z[3])
    }

    /// The disks' centres, centres of mass and the contact point (003 (4)).
    pub fn positions(&self, z: &[f64]) -> Result<Positions> {
        self.check_z(z)?;
        Ok(self.place([z[0], z[1]]))
    }

    fn place(&self, theta: [f64; 2]) -> Positions {
        let l = self.local(theta);
        let (m1, m2) = (self.mass[0], self.mass[1]);
        let mm = m1 + m2;
        let s = m1 * l.a + m2 * l.b;
        let a1 = -(s + l.u * (self.big_r() * m2)) / mm;
        let a2 = -(s - l.u * (self.big_r() * m1)) / mm;
        Positions {
            centres: [xy(a1), xy(a2)],
            masses: [xy(l.a + a1), xy(l.b + a2)],
            contact: xy(a1 + l.u * self.r[0]),
        }
    }

    /// f(θ₁) = Im((X₁ − P)(X₂ − P)‾) along the rolling line in the gauge u = 1, and
    /// f′_λ = R Re(a b̄) + r₂² Re a − r₁² Re b, its derivative along (r₂, −r₁) (module docs).
    fn balance(&self, theta1: f64) -> (f64, f64, [f64; 2]) {
        let [r1, r2] = self.r;
        let theta = [theta1, -(self.c + r1 * theta1) / r2];
        let a = C::from_polar(1.0, theta[0]) * self.gamma[0];
        let b = C::from_polar(1.0, theta[1]) * self.gamma[1];
        let f = ((a - r1) * (b + r2).conj()).im;
        let df = self.big_r() * (a * b.conj()).re + r2 * r2 * a.re - r1 * r1 * b.re;
        (f, df, theta)
    }

    /// Every rotational relative equilibrium with θ₁ in `theta1_range` (one turn of disk 1 is
    /// (0, 2π)), in the gauge u = 1 (module docs), sorted by θ₁. The zeros of f are bracketed on
    /// a grid fine enough for its frequencies and refined by safeguarded Newton to round-off; a
    /// double zero (tangency) is found only if the grid hits a sign change. Errors: an empty or
    /// non-finite range.
    pub fn relative_equilibria(&self, theta1_range: (f64, f64)) -> Result<Vec<DisksEquilibrium>> {
        let (lo, hi) = theta1_range;
        check::finite_slice("theta1_range", &[lo, hi])?;
        if lo >= hi {
            return Err(Error::invalid(
                "theta1_range",
                format!("expected lo < hi, got ({lo}, {hi})"),
            ));
        }
        let [r1, r2] = self.r;
        let turns = ((hi - lo) / std::f64::consts::TAU).ceil().max(1.0);
        if turns > MAX_TURNS {
            return Err(Error::invalid(
                "theta1_range",
                format!(
                    "the range spans {} turns of disk 1; at most {MAX_TURNS} are searched (the \
                     equilibria repeat with the rolling constant, see the module docs)",
                    fmt_num(turns)
                ),
            ));
        }
        let n = (256.0 * turns * (2.0 + r1 / r2)).min(1e7) as usize;
        let h = (hi - lo) / n as f64;
        let mut out = Vec::new();
        let mut prev = (lo, self.balance(lo).0);
        for i in 1..=n {
            let t = if i == n { hi } else { lo + h * i as f64 };
            let f = self.balance(t).0;
            if prev.1 == 0.0 && prev.0 < hi {
                out.push(prev.0);
            } else if prev.1 * f < 0.0 {
                out.push(self.refine(prev.0, t));
            }
            prev = (t, f);
        }
        let scale = self.big_r() * self.big_r() * (self.gamma[0].norm() + self.gamma[1].norm());
        Ok(out
            .into_iter()
            .map(|t1| {
                let (_, df, theta) = self.balance(t1);
                let pos = self.place(theta);
                let curvature = 2.0 * self.reduced_mass() * self.big_r() * df;
                DisksEquilibrium {
                    theta,
                    stable: df < 0.0,
                    degenerate: df.abs() <= 1e-10 * scale,
                    contact: pos.contact,
                    locked_inertia: self.locked_inertia(theta).unwrap_or(f64::NAN),
                    curvature,
                }
            })
            .collect())
    }

    /// The zero of f in (lo, hi) (a sign change) by Newton steps kept inside the bracket.
    fn refine(&self, mut lo: f64, mut hi: f64) -> f64 {
        let f_lo = self.balance(lo).0;
        let mut t = 0.5 * (lo + hi);
        for _ in 0..100 {
            let (f, df, _) = self.balance(t);
            if f == 0.0 {
                return t;
            }
            if (f < 0.0) == (f_lo < 0.0) {
                lo = t;
            } else {
                hi = t;
            }
            // d/dθ₁ = f′_λ / r₂ along (1, −r₁/r₂)
            let newton = t - f * self.r[1] / df;
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if (next - t).abs() <= 4.0 * f64::EPSILON * t.abs().max(1.0) {
                return next;
            }
            t = next;
        }
        t
    }
}

/// Derivatives of the gradient (the tangent lift, 003 (6)).
impl RollingDisks {
    /// ∂u/∂θ_k = i(r_k/R)u, ∂_k∂_lu = −(r_k r_l/R²)u.
    fn du(&self, u: C) -> [C; 2] {
        let big_r = self.big_r();
        self.r.map(|rk| u * C::new(0.0, rk / big_r))
    }

    /// A, B, ∂A, ∂B, e, I_kᶜ at θ (∂A = (ia − r₁∂₁u, −r₁∂₂u), ∂B = (r₂∂₁u, ib + r₂∂₂u)).
    fn pieces(&self, l: &Local, p: [f64; 2]) -> Pieces {
        let i = C::i();
        let [r1, r2] = self.r;
        let du = self.du(l.u);
        Pieces {
            a: l.big_a,
            b: l.big_b,
            da: [i * l.a - du[0] * r1, -du[1] * r1],
            db: [du[0] * r2, i * l.b + du[1] * r2],
            e: self.reduced_mass(),
            central: [self.central(0), self.central(1)],
            p,
        }
    }

    /// The variation of the pieces along dθ (δp = dp): ∂_l∂_kA = −δ_{k1}δ_{l1}a − r₁∂_k∂_lu,
    /// ∂_l∂_kB = −δ_{k2}δ_{l2}b + r₂∂_k∂_lu (indices from 1).
    fn state_variation(&self, l: &Local, x: &Pieces, dq: &[f64], dp: &[f64]) -> Pieces {
        let [r1, r2] = self.r;
        let big_r = self.big_r();
        let mut v = Pieces {
            p: [dp[0], dp[1]],
            ..Pieces::default()
        };
        for (k, &dqk) in dq[..2].iter().enumerate() {
            v.a += x.da[k] * dqk;
            v.b += x.db[k] * dqk;
            for (j, &dqj) in dq[..2].iter().enumerate() {
                let ddu = l.u * (-self.r[k] * self.r[j] / (big_r * big_r));
                let mut dda = -ddu * r1;
                let mut ddb = ddu * r2;
                if k == j {
                    if k == 0 {
                        dda -= l.a;
                    } else {
                        ddb -= l.b;
                    }
                }
                v.da[k] += dda * dqj;
                v.db[k] += ddb * dqj;
            }
        }
        v
    }

    /// The variation of the pieces along the parameter m ([`RollingDisks::PARAMETERS`]): r_j
    /// moves φ by (θ_j − φ)/R and A, B directly (A = a − r₁u, B = b + r₂u); m_k moves
    /// e = m₁m₂/(m₁ + m₂) and I_kᶜ = I_k − m_k|γ_k|²; I_k moves I_kᶜ; c moves φ by 1/R.
    fn parameter_variation(&self, l: &Local, theta: [f64; 2], m: usize) -> Pieces {
        let [r1, r2] = self.r;
        let big_r = self.big_r();
        let du = self.du(l.u);
        let mut v = Pieces::default();
        // The rate of φ and of the factor r_k/R in ∂_ku, for r₁, r₂, c.
        let moves_u = |dphi: f64, dfac: [f64; 2]| -> (C, [C; 2]) {
            let i = C::i();
            let dpu = l.u * (i * dphi);
            let ddu = std::array::from_fn(|k| l.u * (i * dfac[k]) + du[k] * (i * dphi));
            (dpu, ddu)
        };
        // A parameter that moves u moves A = a − r₁u and B = b + r₂u (and their ∂_k) with it.
        let through_u = |v: &mut Pieces, dpu: C, ddu: [C; 2]| {
            v.a -= dpu * r1;
            v.b += dpu * r2;
            for (k, dd) in ddu.iter().enumerate() {
                v.da[k] -= dd * r1;
                v.db[k] += dd * r2;
            }
        };
        match m {
            0 | 1 => {
                let phi = self.phi(theta);
                let dfac = std::array::from_fn(|k| {
                    (if k == m { 1.0 } else { 0.0 }) / big_r - self.r[k] / (big_r * big_r)
                });
                let (dpu, ddu) = moves_u((theta[m] - phi) / big_r, dfac);
                through_u(&mut v, dpu, ddu);
                // and r_m directly: δA = −u, δ∂_kA = −∂_ku (m = r₁); δB = u, δ∂_kB = ∂_ku (r₂).
                let sign = if m == 0 { -1.0 } else { 1.0 };
                let (x, dx) = if m == 0 {
                    (&mut v.a, &mut v.da)
                } else {
                    (&mut v.b, &mut v.db)
                };
                *x += l.u * sign;
                for (dxk, duk) in dx.iter_mut().zip(du) {
                    *dxk += duk * sign;
                }
            }
            2 | 3 => {
                let k = m - 2;
                let total = self.mass[0] + self.mass[1];
                let other = self.mass[1 - k];
                v.e = other * other / (total * total);
                v.central[k] = -self.gamma[k].norm_sqr();
            }
            4 | 5 => v.central[m - 4] = 1.0,
            _ => {
                let (dpu, ddu) = moves_u(1.0 / big_r, [0.0; 2]);
                through_u(&mut v, dpu, ddu);
            }
        }
        v
    }

    /// The derivative of the gradient along a variation δ of the pieces: δv = M⁻¹(δp − δM v)
    /// with (δM v)_i = δI_iᶜv_i + δe Re(c_i s̄) + e Re(δc_i s̄ + c_i δs̄) (δs = δAv₁ − δBv₂ at
    /// fixed v), then δ(∂H/∂θ_k) = −δe Re(s̄ s_k) − e Re(δs̄ s_k + s̄ δs_k) with the total δs,
    /// δs_k. Returns (δ∂H/∂θ, δ∂H/∂p).
    fn gradient_variation(&self, l: &Local, x: &Pieces, d: &Pieces) -> ([f64; 2], [f64; 2]) {
        let m = self.metric(l);
        let v = velocity(&m, x.p);
        let s = x.a * v[0] - x.b * v[1];
        let ds_v = d.a * v[0] - d.b * v[1];
        let (c, dc) = ([x.a, -x.b], [d.a, -d.b]);
        let dmv: [f64; 2] = std::array::from_fn(|i| {
            d.central[i] * v[i]
                + d.e * (c[i] * s.conj()).re
                + x.e * (dc[i] * s.conj() + c[i] * ds_v.conj()).re
        });
        let dv = velocity(&m, [d.p[0] - dmv[0], d.p[1] - dmv[1]]);
        let ds = ds_v + x.a * dv[0] - x.b * dv[1];
        let dhq = std::array::from_fn(|k| {
            let sk = x.da[k] * v[0] - x.db[k] * v[1];
            let dsk = d.da[k] * v[0] - d.db[k] * v[1] + x.da[k] * dv[0] - x.db[k] * dv[1];
            -d.e * (s.conj() * sk).re - x.e * (ds.conj() * sk + s.conj() * dsk).re
        });
        (dhq, dv)
    }

    /// The parameters of [`Problem::parameters`], in order.
    const PARAMETERS: [&'static str; 7] = [
        "r1",
        "r2",
        "m1",
        "m2",
        "inertia1",
        "inertia2",
        "rolling_constant",
    ];
}

/// D²H\[dq, dp\] of H = ½pᵀM(θ)⁻¹p through its pieces (module docs; the second derivatives of
/// A, B from those of u = e^{iφ}), and ∂∇H/∂θ_m for the radii, masses, moments and the rolling
/// constant.
impl CanonicalTangent for RollingDisks {
    fn gradient_tangent(
        &self,
        q: &[f64],
        p: &[f64],
        dq: &[f64],
        dp: &[f64],
        dhq: &mut [f64],
        dhp: &mut [f64],
    ) {
        let l = self.local([q[0], q[1]]);
        let x = self.pieces(&l, [p[0], p[1]]);
        let d = self.state_variation(&l, &x, dq, dp);
        let (a, b) = self.gradient_variation(&l, &x, &d);
        dhq[..2].copy_from_slice(&a);
        dhp[..2].copy_from_slice(&b);
    }

    fn gradient_parameter(&self, q: &[f64], p: &[f64], m: usize, dhq: &mut [f64], dhp: &mut [f64]) {
        let theta = [q[0], q[1]];
        let l = self.local(theta);
        let x = self.pieces(&l, [p[0], p[1]]);
        let d = self.parameter_variation(&l, theta, m);
        let (a, b) = self.gradient_variation(&l, &x, &d);
        for i in 0..2 {
            dhq[i] += a[i];
            dhp[i] += b[i];
        }
    }
}

impl DisksEquilibrium {
    /// The state of the rotation with angular velocity ω (θ̇ = (ω, ω)).
    pub fn state(&self, disks: &RollingDisks, omega: f64) -> Result<Vec<f64>> {
        disks.state(self.theta, [omega, omega])
    }
}

/// M⁻¹p for a 2×2 M.
fn velocity(m: &[[f64; 2]; 2], p: [f64; 2]) -> [f64; 2] {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [
        (m[1][1] * p[0] - m[0][1] * p[1]) / det,
        (m[0][0] * p[1] - m[1][0] * p[0]) / det,
    ]
}

impl Problem for RollingDisks {
    fn name(&self) -> &'static str {
        "RollingDisks"
    }
    /// The radii r₁, r₂, masses m₁, m₂, moments I₁, I₂ (about the disks' centres) and the
    /// rolling constant c (the centres of mass γ_k are not parameters here).
    fn parameters(&self) -> Vec<&'static str> {
        RollingDisks::PARAMETERS.to_vec()
    }
    fn space(&self) -> Space {
        Space::new([("theta", Block::Real(2)), ("p", Block::Real(2))])
    }
    /// H = ½ pᵀM⁻¹p.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.check_z(z)?;
        Ok(self.hamiltonian(&z[..2], &z[2..]))
    }
    /// [J = p₁ + p₂].
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        Ok(vec![self.angular_momentum(z)?])
    }
    fn invariant_names(&self) -> Vec<String> {
        vec!["J".into()]
    }
}

impl Canonical for RollingDisks {
    fn dof(&self) -> usize {
        2
    }
    fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64 {
        let v = velocity(&self.metric(&self.local([q[0], q[1]])), [p[0], p[1]]);
        0.5 * (p[0] * v[0] + p[1] * v[1])
    }
    /// ∂H/∂p = v = M⁻¹p; ∂H/∂θ_k = −∂T/∂θ_k = −e Re(ẇ̄ ∂_kẇ), ẇ = i(v₁A − v₂B) with
    /// ∂_kA, ∂_kB from ∂u/∂θ_k = i(r_k/R)u.
    fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
        let l = self.local([q[0], q[1]]);
        let v = velocity(&self.metric(&l), [p[0], p[1]]);
        hp[0] = v[0];
        hp[1] = v[1];
        let i = C::i();
        let [r1, r2] = self.r;
        let big_r = self.big_r();
        let du = [l.u * (i * (r1 / big_r)), l.u * (i * (r2 / big_r))];
        let da = [i * l.a - du[0] * r1, -du[1] * r1];
        let db = [du[0] * r2, i * l.b + du[1] * r2];
        let wdot = i * (l.big_a * v[0] - l.big_b * v[1]);
        let e = self.reduced_mass();
        for k in 0..2 {
            let dwdot = i * (da[k] * v[0] - db[k] * v[1]);
            hq[k] = -e * (wdot.conj() * dwdot).re;
        }
    }
}

impl Symmetric for RollingDisks {
    fn symmetry_dim(&self) -> usize {
        1
    }
    /// J = p₁ + p₂.
    fn momentum_map(&self, z: &[f64]) -> Result<Vec<f64>> {
        Ok(vec![self.angular_momentum(z)?])
    }
    /// θ̇ = ξ(1, 1), ṗ = 0.
    fn generator(&self, xi: &[f64], z: &[f64]) -> Result<Vec<f64>> {
        self.check_z(z)?;
        check::len_of("xi", xi, 1)?;
        Ok(vec![xi[0], xi[0], 0.0, 0.0])
    }
}

// The tangent lift: Gauss, midpoint and RK4 differentiate their own steps.
crate::integrate::methods::canonical_system!(
    RollingDisks,
    canonical_catalog(),
    |d: &RollingDisks| Some(Tangent::field(d.clone()).into_system())
);
