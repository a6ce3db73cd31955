//! The classical tangent Euler top on a surface (002 §II–III): a planar rigid body, carried as an
//! orthonormal frame (E₁, E₂) tangent to a two-dimensional Riemannian surface at its centre c.
//!
//! **Configuration.** η = (x¹, x², θ): the centre in the surface's chart and the angle θ from the
//! reference frame Ê₁ of the [`Surface`] to the body's E₁, E₁ = cos θ Ê₁ + sin θ Ê₂,
//! E₂ = −sin θ Ê₁ + cos θ Ê₂ (002 (11), (41)).
//!
//! **Lagrangian** (derived again from 002 (10), (13)–(17)). With ∫ξ dm = 0 (002 (1)),
//! L = ½ m |ċ|² + ½ I_ij ⟨∇_ċ E_i, ∇_ċ E_j⟩, where I_ij = ∫ξ^i ξ^j dm is the body's 2×2 Euler
//! tensor (002 (2), (42)). With w(v) = ⟨∇_v Ê₁, Ê₂⟩ = α_i v^i (so ∇Ê₁ = w Ê₂, ∇Ê₂ = −w Ê₁),
//! ∇_ċ E₁ = (θ̇ + w(ċ)) E₂ and ∇_ċ E₂ = −(θ̇ + w(ċ)) E₁, hence
//!
//! L = ½ m g_ij ẋ^i ẋ^j + ½ 𝕀 (θ̇ + α_i ẋ^i)²,   𝕀 = tr I = I₁₁ + I₂₂,
//!
//! (only the trace of the Euler tensor enters, 002 (42), (44)). The cross term is +𝕀 θ̇ α_i ẋ^i:
//! 002 (45) prints it with a minus sign (a slip; cf. 002 (68) and (79), and the errata), and the
//! off-diagonal entries of 002 (47) change sign accordingly. The metric on the configuration
//! space (002 (47), corrected) is
//!
//! g_AB = [[m g + 𝕀 α αᵀ, 𝕀 α], [𝕀 αᵀ, 𝕀]],
//!
//! i.e. g_AB = Aᵀ diag(m g, 𝕀) A with A = [[1, 0, 0], [0, 1, 0], [α₁, α₂, 1]]. The finite
//! differences of 002 (10) evaluated with an explicit ambient frame on the sphere confirm it
//! (`tests/tangent_top.rs`). It does not depend on the choice of reference frame (002 §II.C): a
//! frame rotated by χ(x) has α̃ = α + dχ and θ̃ = θ − χ, so θ̃̇ + α̃ẋ = θ̇ + αẋ.
//!
//! **Hamiltonian** on T*OM, z = (x¹, x², θ, p₁, p₂, p_θ): inverting g_AB through A,
//!
//! H = ½ g^{AB} p_A p_B = ½ πᵀ (m g)⁻¹ π + p_θ²/(2𝕀),   π = p_x − p_θ α,
//!
//! the charged particle of 002 §III.B with charge p_θ in the potential α. Velocities
//! ẋ = v = (m g)⁻¹ π, θ̇ = p_θ/𝕀 − α·v; forces
//! −∂H/∂x^k = ½ m vᵀ (∂_k g) v + p_θ (∂_k α_i) v^i (from ∂(g⁻¹) = −g⁻¹ (∂g) g⁻¹), ṗ_θ = 0.
//!
//! **Conserved quantities.** H; p_θ = 𝕀(θ̇ + α·ẋ), the body's angular momentum (002 (47):
//! ∂L/∂θ = 0), linear in z so every Gauss method keeps it to round-off; for every Killing field of
//! the surface, lifted to (x, θ) as in [`crate::systems::surface`], the momentum J = p_A X^A
//! (Noether; it generates the isometry that moves the frame along, 002 §III.A, §III.C).
//!
//! Only the intrinsic top is implemented; the second-fundamental-form term of an embedded surface
//! (002 (37), (39)) is not.

use std::sync::Arc;

use super::surface::{inverse, Surface, Vec2};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::{Gauss, Rk4, IMPLICIT_MIDPOINT};
use crate::integrate::problem::{Canonical, VectorField};
use crate::integrate::space::{Block, Space};
use crate::integrate::{Catalog, Entry, Problem};

/// The tangent Euler top of mass m and scalar inertia 𝕀 = tr I (002 (42)) on a surface; state
/// z = (x¹, x², θ, p₁, p₂, p_θ) (module docs).
#[derive(Clone, Debug)]
pub struct TangentTop {
    surface: Arc<dyn Surface>,
    mass: f64,
    inertia: f64,
}

impl TangentTop {
    /// A top of mass m > 0 and inertia 𝕀 > 0 on `surface`.
    pub fn new(surface: Arc<dyn Surface>, mass: f64, inertia: f64) -> Result<Self> {
        check::positive("mass", mass)?;
        check::positive("inertia", inertia)?;
        Ok(TangentTop {
            surface,
            mass,
            inertia,
        })
    }

    /// A top whose body has the 2×2 Euler tensor `tensor` (row-major, symmetric, positive
    /// semi-definite with positive trace): only 𝕀 = tr I enters the dynamics (module docs).
    pub fn with_tensor(surface: Arc<dyn Surface>, mass: f64, tensor: [f64; 4]) -> Result<Self> {
        check::finite_slice("inertia tensor", &tensor)?;
        let sym = (tensor[1] - tensor[2]).abs() <= 1e-12 * (tensor[0] + tensor[3]).abs();
        let psd = tensor[0] >= 0.0
            && tensor[3] >= 0.0
            && tensor[0] * tensor[3] - tensor[1] * tensor[2] >= 0.0;
        if !(sym && psd) {
            return Err(Error::invalid(
                "inertia tensor",
                "expected a symmetric positive semi-definite Euler tensor ∫ξξᵀ dm",
            ));
        }
        TangentTop::new(surface, mass, tensor[0] + tensor[3])
    }

    /// The surface.
    pub fn surface(&self) -> &Arc<dyn Surface> {
        &self.surface
    }

    /// m.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// 𝕀 = tr I.
    pub fn inertia(&self) -> f64 {
        self.inertia
    }

    /// The metric g_AB of 002 (47) (corrected signs, module docs) at x. Errors: x outside the
    /// surface's domain.
    pub fn metric(&self, x: Vec2) -> Result<[[f64; 3]; 3]> {
        self.surface.check(x).map_err(|v| v.at_start())?;
        let g = self.surface.metric(x);
        let a = self.surface.connection(x);
        let (m, i) = (self.mass, self.inertia);
        Ok([
            [
                m * g[0][0] + i * a[0] * a[0],
                m * g[0][1] + i * a[0] * a[1],
                i * a[0],
            ],
            [
                m * g[1][0] + i * a[1] * a[0],
                m * g[1][1] + i * a[1] * a[1],
                i * a[1],
            ],
            [i * a[0], i * a[1], i],
        ])
    }

    /// The Lagrangian L = ½ m g_ij ẋ^i ẋ^j + ½ 𝕀 (θ̇ + α_i ẋ^i)² at (η, η̇). Errors: x outside the
    /// domain, non-finite input.
    pub fn lagrangian(&self, eta: [f64; 3], etadot: [f64; 3]) -> Result<f64> {
        check::finite_slice("eta and etadot", &[eta, etadot].concat())?;
        let x = [eta[0], eta[1]];
        self.surface.check(x).map_err(|v| v.at_start())?;
        let g = self.surface.metric(x);
        let a = self.surface.connection(x);
        let v = [etadot[0], etadot[1]];
        let s = etadot[2] + a[0] * v[0] + a[1] * v[1];
        Ok(0.5 * self.mass * super::surface::inner(&g, v, v) + 0.5 * self.inertia * s * s)
    }

    /// The canonical state z = (x, θ, p) with p_A = g_AB η̇^B (Legendre transform) of the top at x
    /// with angle θ and velocities (ẋ, θ̇). Errors: x outside the domain, non-finite input.
    pub fn state(&self, x: Vec2, theta: f64, xdot: Vec2, thetadot: f64) -> Result<Vec<f64>> {
        check::finite_slice("x, theta, xdot, thetadot", &[x[0], x[1], theta])?;
        check::finite_slice("xdot, thetadot", &[xdot[0], xdot[1], thetadot])?;
        let g = self.metric(x)?;
        let eta_dot = [xdot[0], xdot[1], thetadot];
        let mut z = vec![x[0], x[1], theta, 0.0, 0.0, 0.0];
        for a in 0..3 {
            z[3 + a] = (0..3).map(|b| g[a][b] * eta_dot[b]).sum();
        }
        Ok(z)
    }

    /// Checks a state: length 6, finite, x in the surface's domain.
    fn check_z(&self, z: &[f64]) -> Result<()> {
        check::len_of("state", z, 6)?;
        check::finite_slice("state", z)?;
        self.surface.check([z[0], z[1]]).map_err(|v| v.at_start())
    }

    /// The velocities η̇ = (ẋ¹, ẋ², θ̇) = g^{AB} p_B of a state.
    pub fn velocities(&self, z: &[f64]) -> Result<[f64; 3]> {
        self.check_z(z)?;
        let (mut hq, mut hp) = ([0.0; 3], [0.0; 3]);
        self.gradient(&z[..3], &z[3..], &mut hq, &mut hp);
        Ok(hp)
    }

    /// The body's angular momentum p_θ = 𝕀(θ̇ + α·ẋ) (002 §III.A).
    pub fn p_theta(&self, z: &[f64]) -> Result<f64> {
        self.check_z(z)?;
        Ok(z[5])
    }

    /// The momenta J_ξ = p_A X_ξ^A of the surface's Killing fields lifted to (x, θ), in the order
    /// of [`Surface::killing`]: Plane (translation x, y, rotation about the origin), Sphere (the
    /// ambient angular momentum, x, y, z; J_z = p_φ), HyperbolicPlane (E, H, F of SL(2, ℝ)),
    /// Revolution (p_φ); none for a [`super::surface::MetricSurface`].
    pub fn killing_momenta(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.check_z(z)?;
        Ok(self.killing_values(z, false))
    }

    fn killing_values(&self, z: &[f64], affine_only: bool) -> Vec<f64> {
        let x = [z[0], z[1]];
        (0..self.surface.killing_count())
            .filter(|&k| !affine_only || self.surface.killing_is_affine(k))
            .map(|k| {
                let xk = self.surface.killing(k, x);
                (0..3).map(|a| z[3 + a] * xk[a]).sum()
            })
            .collect()
    }

    /// The body frame in ℝ³ for an embedded surface: (position c, E₁, E₂), None otherwise.
    pub fn ambient_frame(&self, z: &[f64]) -> Result<Option<[[f64; 3]; 3]>> {
        self.check_z(z)?;
        let Some(emb) = self.surface.embedding() else {
            return Ok(None);
        };
        let x = [z[0], z[1]];
        let e = self.surface.frame(x);
        let (s, c) = z[2].sin_cos();
        let e1 = [c * e[0][0] + s * e[1][0], c * e[0][1] + s * e[1][1]];
        let e2 = [-s * e[0][0] + c * e[1][0], -s * e[0][1] + c * e[1][1]];
        Ok(Some([
            emb.position(x),
            emb.tangent(x, e1),
            emb.tangent(x, e2),
        ]))
    }
}

impl Problem for TangentTop {
    fn name(&self) -> &'static str {
        "TangentTop"
    }
    fn space(&self) -> Space {
        Space::new([
            ("x", Block::Real(2)),
            ("theta", Block::Real(1)),
            ("p", Block::Real(3)),
        ])
    }
    /// H = ½ g^{AB} p_A p_B.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.check_z(z)?;
        Ok(self.hamiltonian(&z[..3], &z[3..]))
    }
    /// [p_θ, the Killing momenta of the affine generators] — the ones quadratic in z, which the
    /// Gauss methods keep to round-off (all of them on the plane, J_z on the sphere, J_E and J_H
    /// on H², p_φ on a surface of revolution). [`TangentTop::killing_momenta`] gives all.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.check_z(z)?;
        let mut v = vec![z[5]];
        v.extend(self.killing_values(z, true));
        Ok(v)
    }
    fn invariant_count(&self) -> usize {
        1 + (0..self.surface.killing_count())
            .filter(|&k| self.surface.killing_is_affine(k))
            .count()
    }
    /// x in the surface's domain.
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.surface.check([z[0], z[1]]).map_err(|v| v.at_start())
    }
}

impl Canonical for TangentTop {
    fn dof(&self) -> usize {
        3
    }
    /// H = ½ p·η̇ = ½ π·v + p_θ²/(2𝕀) (module docs); NaN outside the domain.
    fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64 {
        let (mut hq, mut hp) = ([0.0; 3], [0.0; 3]);
        self.gradient(q, p, &mut hq, &mut hp);
        // H = ½ p_A g^{AB} p_B = ½ p·η̇.
        0.5 * (p[0] * hp[0] + p[1] * hp[1] + p[2] * hp[2])
    }
    /// ∂H/∂p = (v, p_θ/𝕀 − α·v), ∂H/∂x^k = −½ m vᵀ(∂_k g)v − p_θ (∂_k α_i) v^i, ∂H/∂θ = 0
    /// (module docs); NaN outside the domain (the method then reports the step).
    fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
        let x = [q[0], q[1]];
        if !self.surface.contains(x) {
            hq[..3].fill(f64::NAN);
            hp[..3].fill(f64::NAN);
            return;
        }
        let geo = self.surface.geometry(x);
        let gi = inverse(&geo.g);
        let pt = p[2];
        let a = geo.alpha;
        let pi = [p[0] - pt * a[0], p[1] - pt * a[1]];
        let m = self.mass;
        let v = [
            (gi[0][0] * pi[0] + gi[0][1] * pi[1]) / m,
            (gi[1][0] * pi[0] + gi[1][1] * pi[1]) / m,
        ];
        hp[0] = v[0];
        hp[1] = v[1];
        hp[2] = pt / self.inertia - (a[0] * v[0] + a[1] * v[1]);
        for (h, (d, da)) in hq.iter_mut().zip(geo.dg.iter().zip(&geo.dalpha)) {
            let vgv =
                d[0][0] * v[0] * v[0] + (d[0][1] + d[1][0]) * v[0] * v[1] + d[1][1] * v[1] * v[1];
            *h = -0.5 * m * vgv - pt * (da[0] * v[0] + da[1] * v[1]);
        }
        hq[2] = 0.0;
    }
}

impl VectorField for TangentTop {
    /// ż = (∂H/∂p, −∂H/∂q).
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let (mut hq, mut hp) = ([0.0; 3], [0.0; 3]);
        self.gradient(&z[..3], &z[3..6], &mut hq, &mut hp);
        for a in 0..3 {
            dz[a] = hp[a];
            dz[3 + a] = -hq[a];
        }
    }
}

impl Catalog for TangentTop {
    fn catalog(&self) -> Vec<Entry<Self>> {
        vec![
            Entry::new("midpoint", IMPLICIT_MIDPOINT),
            Entry::new("gauss4", Gauss(2)),
            Entry::new("gauss6", Gauss(3)),
            Entry::new("rk4", Rk4),
        ]
    }
}
