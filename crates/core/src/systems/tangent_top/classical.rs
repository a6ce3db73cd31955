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
//! the surface, lifted to (x, θ) as in [`crate::systems::tangent_top::surface`], the momentum J = p_A X^A
//! (Noether; it generates the isometry that moves the frame along, 002 §III.A, §III.C).
//!
//! **Tangent lift** (issue 26, [`crate::integrate::tangent::CanonicalTangent`]). The Hessian
//! product of H follows from the gradient above by one variation δ of its pieces (G, ∂_kG,
//! ∂_θG, α, ∂α, p, p_θ, 1/𝕀; `gradient_variation`): δv = G⁻¹(δπ − δG v), δπ = δp_x − δp_θ α − p_θ δα,
//! δθ̇ = δp_θ/𝕀 − δα·v − α·δv, δ(∂H/∂x^k) = −vᵀ∂_kG δv − ½vᵀδ(∂_kG)v − δp_θ ∂_kα·v
//! − p_θ δ(∂_kα)·v − p_θ ∂_kα·δv, δ(∂H/∂θ) = −vᵀ∂_θG δv − ½vᵀδ(∂_θG)v. Along a state direction
//! the variations need ∂²g, ∂²α of the surface and, embedded, ∂²W
//! ([`super::surface::SecondGeometry`], [`Surface::has_second_derivatives`]; a surface without
//! them — a graph, a metric given by closures, an embedded surface of revolution — leaves the
//! top without a lift, [`TangentTop::has_hessian`]). The same variation, with δG = g or
//! δG = WᵀQW/𝕀, gives the sensitivities to the mass and the inertia; the surface's own
//! constants (a radius) are not parameters.
//!
//! **Embedded surfaces** (002 §II.D, (29)–(39), derived again). On a surface in ℝ³ a body point
//! c + ξ^a E_a moves with ∇̃_ċ E_a = ∇_ċ E_a + B(ċ, E_a), and the normal parts add
//! ½ I_ab h(ċ, E_a) h(ċ, E_b) to L (002 (37); the cross terms vanish since B ⊥ TM). In the
//! reference frame h(ċ, Ê_a) = (W ẋ)_a with the shape operator W = e h ([`Shape`]), and
//! E_a = S_ba Ê_b with S = R(θ), so the term is ½ ẋᵀ Wᵀ Q(θ) W ẋ with Q(θ) = S I Sᵀ. The
//! translational metric becomes G(x, θ) = m g + Wᵀ Q W, and everything above holds with m g → G;
//! in addition ∂H/∂θ = −½ (W v)ᵀ Q′(θ) (W v), Q′ = S (J I − I J) Sᵀ (J the rotation by π/2).
//! For a symmetric body, I = (𝕀/2) Id, Q is constant and WᵀW = h g⁻¹ h (002 (38)), giving
//! 002 (39); then p_θ is still conserved. For an anisotropic body the Lagrangian depends on θ and
//! p_θ is not conserved; the Killing momenta of isometries that are rigid motions of ℝ³ (all
//! those of the built-ins) are. On the sphere of radius R this is exactly the Euler top about
//! the centre with the body tensor [[mR² + I₂₂, −I₁₂, 0], [−I₁₂, mR² + I₁₁, 0], [0, 0, 𝕀]] in the
//! frame (E₁, E₂, n) (tested against [`crate::systems::RigidBody`]).

use std::sync::Arc;

use super::surface::{self, add, inner, inverse, mul, Mat2, Shape, Surface, Vec2};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::canonical_catalog;
use crate::integrate::problem::Canonical;
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{CanonicalTangent, Tangent};
use crate::integrate::Problem;

/// The tangent Euler top of mass m and Euler tensor I (002 (42)) on a surface, intrinsic or
/// embedded (module docs); state z = (x¹, x², θ, p₁, p₂, p_θ).
#[derive(Clone, Debug)]
pub struct TangentTop {
    surface: Arc<dyn Surface>,
    mass: f64,
    /// The Euler tensor I = ∫ξξᵀ dm.
    tensor: Mat2,
    embedded: bool,
}

/// The pieces of H at one configuration: G = m g + WᵀQW with ∂_k G and ∂_θ G, α and ∂α (and
/// the surface's g, ∂g, for the mass sensitivity).
struct Local {
    g: Mat2,
    dg: [Mat2; 2],
    dtheta: Mat2,
    alpha: Vec2,
    dalpha: Mat2,
    metric: Mat2,
    dmetric: [Mat2; 2],
}

/// The second derivatives of G and α at one configuration (the Hessian of H): ∂_k∂_lG,
/// ∂_θ∂_kG, ∂²_θG, ∂_k∂_lα.
struct Second {
    ddg: [[Mat2; 2]; 2],
    dthetadg: [Mat2; 2],
    dtheta2: Mat2,
    ddalpha: [[Vec2; 2]; 2],
}

/// A variation δ of the pieces of H, along a state direction or a parameter: δG, δ(∂_kG),
/// δ(∂_θG), δα, δ(∂_kα), δp_x, δp_θ (or δe), δ(1/𝕀).
#[derive(Default)]
struct Variation {
    g: Mat2,
    dg: [Mat2; 2],
    dtheta: Mat2,
    alpha: Vec2,
    dalpha: Mat2,
    p: Vec2,
    pt: f64,
    inv_inertia: f64,
}

fn scale(a: &Mat2, c: f64) -> Mat2 {
    a.map(|r| r.map(|v| c * v))
}

/// a + c b.
fn axpy(a: &Mat2, c: f64, b: &Mat2) -> Mat2 {
    add(a, &scale(b, c))
}

fn apply(m: &Mat2, v: Vec2) -> Vec2 {
    [
        m[0][0] * v[0] + m[0][1] * v[1],
        m[1][0] * v[0] + m[1][1] * v[1],
    ]
}

fn dot(a: Vec2, b: Vec2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn transpose(a: &Mat2) -> Mat2 {
    [[a[0][0], a[1][0]], [a[0][1], a[1][1]]]
}

/// aᵀ b c.
fn sandwich(a: &Mat2, b: &Mat2, c: &Mat2) -> Mat2 {
    mul(&transpose(a), &mul(b, c))
}

fn quad(m: &Mat2, v: Vec2) -> f64 {
    inner(m, v, v)
}

impl TangentTop {
    /// A symmetric top, I = (𝕀/2) Id, of mass m > 0 and inertia 𝕀 = tr I > 0 on `surface`
    /// (intrinsic; [`TangentTop::embedded`] adds the embedding term).
    pub fn new(surface: Arc<dyn Surface>, mass: f64, inertia: f64) -> Result<Self> {
        check::positive("inertia", inertia)?;
        TangentTop::with_tensor(surface, mass, [0.5 * inertia, 0.0, 0.0, 0.5 * inertia])
    }

    /// A top whose body has the 2×2 Euler tensor `tensor` = ∫ξξᵀ dm (row-major, symmetric,
    /// positive semi-definite with positive trace). The intrinsic dynamics depends on 𝕀 = tr I
    /// only; the embedded one on all of I. Errors: mass ≤ 0, a tensor that is not symmetric
    /// positive semi-definite or has zero trace.
    pub fn with_tensor(surface: Arc<dyn Surface>, mass: f64, tensor: [f64; 4]) -> Result<Self> {
        check::positive("mass", mass)?;
        check::finite_slice("inertia tensor", &tensor)?;
        let tr = tensor[0] + tensor[3];
        let sym = (tensor[1] - tensor[2]).abs() <= 1e-12 * tr.abs();
        let psd = tensor[0] >= 0.0
            && tensor[3] >= 0.0
            && tensor[0] * tensor[3] - tensor[1] * tensor[2] >= -1e-14 * tr * tr;
        if !(sym && psd && tr > 0.0) {
            return Err(Error::invalid(
                "inertia tensor",
                format!(
                    "expected a symmetric positive semi-definite Euler tensor ∫ξξᵀ dm with \
                     positive trace, got {tensor:?}"
                ),
            ));
        }
        let off = 0.5 * (tensor[1] + tensor[2]);
        Ok(TangentTop {
            surface,
            mass,
            tensor: [[tensor[0], off], [off, tensor[3]]],
            embedded: false,
        })
    }

    /// The same top moving on the surface as embedded in ℝ³: the second-fundamental-form term of
    /// 002 (37) (module docs). Errors: a surface without an embedding.
    pub fn embedded(mut self) -> Result<Self> {
        if self.surface.embedding().is_none() {
            return Err(Error::invalid(
                "embedded",
                format!(
                    "the {} chart has no embedding in ℝ³; use Plane, Sphere, Revolution or Graph",
                    self.surface.name()
                ),
            ));
        }
        self.embedded = true;
        Ok(self)
    }

    /// Whether the embedding term of 002 (37) is included.
    pub fn is_embedded(&self) -> bool {
        self.embedded
    }

    /// Whether the Euler tensor is a multiple of the identity (p_θ is then conserved).
    pub fn is_symmetric(&self) -> bool {
        let t = &self.tensor;
        let tol = 1e-14 * (t[0][0] + t[1][1]);
        (t[0][0] - t[1][1]).abs() <= tol && t[0][1].abs() <= tol
    }

    /// Whether the dynamics depends on θ (embedded and not symmetric).
    fn depends_on_theta(&self) -> bool {
        self.embedded && !self.is_symmetric()
    }

    /// G, ∂G, ∂_θG, α, ∂α at (x, θ); x must be in the domain.
    fn local(&self, x: Vec2, theta: f64) -> Local {
        let geo = self.surface.geometry(x);
        let m = self.mass;
        let mut g = scale(&geo.g, m);
        let mut dg = geo.dg.map(|d| scale(&d, m));
        let mut dtheta = [[0.0; 2]; 2];
        if self.embedded {
            let emb = self.surface.embedding().expect("checked by embedded()");
            let Shape { w, dw } = emb.shape(x);
            let (sn, cs) = theta.sin_cos();
            let s = [[cs, -sn], [sn, cs]];
            let j = [[0.0, -1.0], [1.0, 0.0]];
            let i = &self.tensor;
            let q = sandwich(&transpose(&s), i, &transpose(&s));
            let comm = add(&mul(&j, i), &mul(i, &j).map(|r| r.map(|v| -v)));
            let dq = sandwich(&transpose(&s), &comm, &transpose(&s));
            g = add(&g, &sandwich(&w, &q, &w));
            for (d, dwk) in dg.iter_mut().zip(&dw) {
                let a = sandwich(dwk, &q, &w);
                *d = add(d, &add(&a, &transpose(&a)));
            }
            dtheta = sandwich(&w, &dq, &w);
        }
        Local {
            g,
            dg,
            dtheta,
            alpha: geo.alpha,
            dalpha: geo.dalpha,
            metric: geo.g,
            dmetric: geo.dg,
        }
    }

    /// Whether the surface gives the second derivatives the Hessian of H needs (∂²g, ∂²α, and
    /// ∂²W when embedded): then the top has a tangent lift.
    pub fn has_hessian(&self) -> bool {
        self.surface.has_second_derivatives()
            && (!self.embedded
                || self
                    .surface
                    .embedding()
                    .is_some_and(|e| e.has_shape_second()))
    }

    /// The second derivatives of G and α at (x, θ) (module docs: G = m g + WᵀQ(θ)W, so
    /// ∂_k∂_l(WᵀQW) = B + Bᵀ + C + Cᵀ with B = (∂_k∂_lW)ᵀQW, C = (∂_kW)ᵀQ∂_lW,
    /// ∂_θ∂_k(WᵀQW) = A + Aᵀ with A = (∂_kW)ᵀQ′W, ∂²_θ(WᵀQW) = WᵀQ″W, Q″ = S(JC − CJ)Sᵀ with
    /// C = JI − IJ).
    fn second(&self, x: Vec2, theta: f64) -> Second {
        let sg = self.surface.second_derivatives(x);
        let m = self.mass;
        let mut ddg = sg.d2g.map(|r| r.map(|d| scale(&d, m)));
        let mut dthetadg = [[[0.0; 2]; 2]; 2];
        let mut dtheta2 = [[0.0; 2]; 2];
        if self.embedded {
            let emb = self.surface.embedding().expect("checked by embedded()");
            let Shape { w, dw } = emb.shape(x);
            let ddw = emb.shape_second(x);
            let (sn, cs) = theta.sin_cos();
            let st = [[cs, sn], [-sn, cs]];
            let j = [[0.0, -1.0], [1.0, 0.0]];
            let i = &self.tensor;
            let q = sandwich(&st, i, &st);
            let comm = axpy(&mul(&j, i), -1.0, &mul(i, &j));
            let dq = sandwich(&st, &comm, &st);
            let comm2 = axpy(&mul(&j, &comm), -1.0, &mul(&comm, &j));
            let ddq = sandwich(&st, &comm2, &st);
            for k in 0..2 {
                for l in 0..2 {
                    let b = sandwich(&ddw[k][l], &q, &w);
                    let c = sandwich(&dw[k], &q, &dw[l]);
                    let t = add(&add(&b, &transpose(&b)), &add(&c, &transpose(&c)));
                    ddg[k][l] = add(&ddg[k][l], &t);
                }
                let a = sandwich(&dw[k], &dq, &w);
                dthetadg[k] = add(&a, &transpose(&a));
            }
            dtheta2 = sandwich(&w, &ddq, &w);
        }
        Second {
            ddg,
            dthetadg,
            dtheta2,
            ddalpha: sg.d2alpha,
        }
    }

    /// The variation of the pieces along a state direction (dx, dθ, dp_x, dp_θ).
    fn state_variation(l: &Local, s: &Second, dq: &[f64], dp: &[f64]) -> Variation {
        let (dx, dth) = ([dq[0], dq[1]], dq.get(2).copied().unwrap_or(0.0));
        let mut var = Variation {
            g: scale(&l.dtheta, dth),
            dg: s.dthetadg.map(|d| scale(&d, dth)),
            dtheta: scale(&s.dtheta2, dth),
            p: [dp[0], dp[1]],
            pt: dp.get(2).copied().unwrap_or(0.0),
            ..Variation::default()
        };
        for (k, &dxk) in dx.iter().enumerate() {
            var.g = axpy(&var.g, dxk, &l.dg[k]);
            var.dtheta = axpy(&var.dtheta, dxk, &s.dthetadg[k]);
            for i in 0..2 {
                var.alpha[i] += l.dalpha[k][i] * dxk;
            }
            for j in 0..2 {
                var.dg[j] = axpy(&var.dg[j], dxk, &s.ddg[j][k]);
                for i in 0..2 {
                    var.dalpha[j][i] += s.ddalpha[j][k][i] * dxk;
                }
            }
        }
        var
    }

    /// The variation of the pieces along the parameter m: 0 the mass (δG = g, δ∂G = ∂g),
    /// 1 the inertia 𝕀 with the tensor's shape I/𝕀 kept (δG = WᵀQW/𝕀, δ(1/𝕀) = −1/𝕀²).
    fn parameter_variation(&self, l: &Local, m: usize) -> Variation {
        match m {
            0 => Variation {
                g: l.metric,
                dg: l.dmetric,
                ..Variation::default()
            },
            _ => {
                let (i, mass) = (self.inertia(), self.mass);
                Variation {
                    g: scale(&axpy(&l.g, -mass, &l.metric), 1.0 / i),
                    dg: std::array::from_fn(|k| {
                        scale(&axpy(&l.dg[k], -mass, &l.dmetric[k]), 1.0 / i)
                    }),
                    dtheta: scale(&l.dtheta, 1.0 / i),
                    inv_inertia: -1.0 / (i * i),
                    ..Variation::default()
                }
            }
        }
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
        self.tensor[0][0] + self.tensor[1][1]
    }

    /// The Euler tensor I (row-major).
    pub fn tensor(&self) -> [f64; 4] {
        let t = &self.tensor;
        [t[0][0], t[0][1], t[1][0], t[1][1]]
    }

    /// The metric g_AB of 002 (47) (corrected signs, module docs) at η = (x¹, x², θ), with
    /// m g → G(x, θ) for the embedded top. Errors: x outside the surface's domain, non-finite η,
    /// an overflow error where an entry exceeds the f64 range.
    pub fn metric(&self, eta: [f64; 3]) -> Result<[[f64; 3]; 3]> {
        check::finite_slice("eta", &eta)?;
        let x = [eta[0], eta[1]];
        self.surface.check(x).map_err(|v| v.at_start())?;
        let l = self.local(x, eta[2]);
        let (g, a, i) = (l.g, l.alpha, self.inertia());
        let out = [
            [
                g[0][0] + i * a[0] * a[0],
                g[0][1] + i * a[0] * a[1],
                i * a[0],
            ],
            [
                g[1][0] + i * a[1] * a[0],
                g[1][1] + i * a[1] * a[1],
                i * a[1],
            ],
            [i * a[0], i * a[1], i],
        ];
        if !out.as_flattened().iter().all(|v| v.is_finite()) {
            return Err(check::overflow_error("eta", "the metric g_AB of 002 (47)"));
        }
        Ok(out)
    }

    /// The Lagrangian L = ½ ẋᵀ G ẋ + ½ 𝕀 (θ̇ + α_i ẋ^i)² at (η, η̇), G = m g (+ WᵀQW embedded).
    /// Errors: x outside the domain, non-finite input, an overflow error where L exceeds the
    /// f64 range.
    pub fn lagrangian(&self, eta: [f64; 3], etadot: [f64; 3]) -> Result<f64> {
        check::finite_slice("eta and etadot", &[eta, etadot].concat())?;
        let x = [eta[0], eta[1]];
        self.surface.check(x).map_err(|v| v.at_start())?;
        let l = self.local(x, eta[2]);
        let v = [etadot[0], etadot[1]];
        let s = etadot[2] + l.alpha[0] * v[0] + l.alpha[1] * v[1];
        let lag = 0.5 * quad(&l.g, v) + 0.5 * self.inertia() * s * s;
        if !lag.is_finite() {
            return Err(check::overflow_error("eta and etadot", "the Lagrangian"));
        }
        Ok(lag)
    }

    /// The canonical state z = (x, θ, p) with p_A = g_AB η̇^B (Legendre transform) of the top at x
    /// with angle θ and velocities (ẋ, θ̇). Errors: x outside the domain, non-finite input.
    pub fn state(&self, x: Vec2, theta: f64, xdot: Vec2, thetadot: f64) -> Result<Vec<f64>> {
        check::finite_slice("x, theta, xdot, thetadot", &[x[0], x[1], theta])?;
        check::finite_slice("xdot, thetadot", &[xdot[0], xdot[1], thetadot])?;
        let g = self.metric([x[0], x[1], theta])?;
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
        surface::killing_momenta(&*self.surface, z, affine_only)
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
    fn calls_out(&self) -> bool {
        self.surface.calls_out()
    }
    fn name(&self) -> &'static str {
        "TangentTop"
    }
    /// The mass m and the inertia 𝕀 = tr I (the Euler tensor scaled with it; the surface's own
    /// constants are not parameters here).
    fn parameters(&self) -> Vec<&'static str> {
        TangentTop::PARAMETERS.to_vec()
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
    /// [p_θ (unless the top is embedded and anisotropic, module docs), the Killing momenta of
    /// the affine generators] — the ones quadratic in z, which the Gauss methods keep to
    /// round-off (all of them on the plane, J_z on the sphere, J_E and J_H on H², p_φ on a
    /// surface of revolution). [`TangentTop::killing_momenta`] gives all.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.check_z(z)?;
        let mut v = if self.depends_on_theta() {
            vec![]
        } else {
            vec![z[5]]
        };
        v.extend(self.killing_values(z, true));
        Ok(v)
    }
    fn invariant_names(&self) -> Vec<String> {
        let spin = (!self.depends_on_theta()).then(|| "p_θ".to_string());
        let killing = surface::killing_momentum_names(&*self.surface, true);
        spin.into_iter().chain(killing).collect()
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
    /// ∂H/∂p = (v, p_θ/𝕀 − α·v), ∂H/∂x^k = −½ vᵀ(∂_k G)v − p_θ (∂_k α_i) v^i,
    /// ∂H/∂θ = −½ vᵀ(∂_θ G)v (zero unless embedded and anisotropic; module docs); NaN outside
    /// the domain (the method then reports the step).
    fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
        let x = [q[0], q[1]];
        if !self.surface.contains(x) {
            hq[..3].fill(f64::NAN);
            hp[..3].fill(f64::NAN);
            return;
        }
        let l = self.local(x, q[2]);
        let pt = p[2];
        let (v, force) = charged_particle(&l, [p[0], p[1]], pt);
        hp[0] = v[0];
        hp[1] = v[1];
        hp[2] = pt / self.inertia() - (l.alpha[0] * v[0] + l.alpha[1] * v[1]);
        hq[0] = -force[0];
        hq[1] = -force[1];
        hq[2] = -0.5 * quad(&l.dtheta, v);
    }
}

/// The charged particle of 002 §III.B at one point: for H = ½ πᵀ G⁻¹ π, π = p − e α, the
/// velocity v = G⁻¹π and the force −∂H/∂x^k = ½ vᵀ(∂_k G)v + e (∂_k α_i) v^i.
fn charged_particle(l: &Local, p: Vec2, e: f64) -> (Vec2, Vec2) {
    let gi = inverse(&l.g);
    let pi = [p[0] - e * l.alpha[0], p[1] - e * l.alpha[1]];
    let v = [
        gi[0][0] * pi[0] + gi[0][1] * pi[1],
        gi[1][0] * pi[0] + gi[1][1] * pi[1],
    ];
    let force = std::array::from_fn(|k| {
        let da = l.dalpha[k];
        0.5 * quad(&l.dg[k], v) + e * (da[0] * v[0] + da[1] * v[1])
    });
    (v, force)
}

/// The derivative of the gradient of H = ½ πᵀG⁻¹π + p_θ²/(2𝕀), π = p − eα (e = p_θ), along a
/// variation of its pieces (δπ = δp − δe α − e δα, δv = G⁻¹(δπ − δG v)):
/// δ(∂H/∂p) = (δv, δe/𝕀 + e δ(1/𝕀) − δα·v − α·δv),
/// δ(∂H/∂x^k) = −vᵀ∂_kG δv − ½ vᵀδ(∂_kG)v − (δe ∂_kα + e δ(∂_kα))·v − e ∂_kα·δv,
/// δ(∂H/∂θ) = −vᵀ∂_θG δv − ½ vᵀδ(∂_θG)v. Returns (δ∂H/∂q, δ∂H/∂p), three entries each (the
/// charged particle uses the first two).
fn gradient_variation(
    l: &Local,
    p: Vec2,
    e: f64,
    inv_inertia: f64,
    var: &Variation,
) -> ([f64; 3], [f64; 3]) {
    let gi = inverse(&l.g);
    let pi = [p[0] - e * l.alpha[0], p[1] - e * l.alpha[1]];
    let v = apply(&gi, pi);
    let dgv = apply(&var.g, v);
    let dpi: Vec2 =
        std::array::from_fn(|i| var.p[i] - var.pt * l.alpha[i] - e * var.alpha[i] - dgv[i]);
    let dv = apply(&gi, dpi);
    let dhp = [
        dv[0],
        dv[1],
        var.pt * inv_inertia + e * var.inv_inertia - dot(var.alpha, v) - dot(l.alpha, dv),
    ];
    let dhq: [f64; 3] = std::array::from_fn(|k| {
        if k == 2 {
            return -(inner(&l.dtheta, v, dv) + 0.5 * quad(&var.dtheta, v));
        }
        let (da, dda) = (l.dalpha[k], var.dalpha[k]);
        -(inner(&l.dg[k], v, dv)
            + 0.5 * quad(&var.dg[k], v)
            + var.pt * dot(da, v)
            + e * dot(dda, v)
            + e * dot(da, dv))
    });
    (dhq, dhp)
}

/// The mass m and the inertia 𝕀 = tr I (the tensor scaled with it: I ↦ I 𝕀′/𝕀).
impl TangentTop {
    const PARAMETERS: [&'static str; 2] = ["mass", "inertia"];
}

/// D²H\[dq, dp\] by `gradient_variation` along the state direction, with the second
/// derivatives of the surface (and of its shape operator when embedded); NaN outside the
/// domain or on a surface without them ([`TangentTop::has_hessian`]).
impl CanonicalTangent for TangentTop {
    fn gradient_tangent(
        &self,
        q: &[f64],
        p: &[f64],
        dq: &[f64],
        dp: &[f64],
        dhq: &mut [f64],
        dhp: &mut [f64],
    ) {
        let x = [q[0], q[1]];
        if !self.surface.contains(x) {
            dhq[..3].fill(f64::NAN);
            dhp[..3].fill(f64::NAN);
            return;
        }
        let l = self.local(x, q[2]);
        let var = TangentTop::state_variation(&l, &self.second(x, q[2]), dq, dp);
        let (a, b) = gradient_variation(&l, [p[0], p[1]], p[2], 1.0 / self.inertia(), &var);
        dhq[..3].copy_from_slice(&a);
        dhp[..3].copy_from_slice(&b);
    }

    /// ∂∇H/∂m, ∂∇H/∂𝕀 ([`TangentTop::parameters`]).
    fn gradient_parameter(&self, q: &[f64], p: &[f64], m: usize, dhq: &mut [f64], dhp: &mut [f64]) {
        let x = [q[0], q[1]];
        if !self.surface.contains(x) {
            dhq[..3].fill(f64::NAN);
            dhp[..3].fill(f64::NAN);
            return;
        }
        let l = self.local(x, q[2]);
        let var = self.parameter_variation(&l, m);
        let (a, b) = gradient_variation(&l, [p[0], p[1]], p[2], 1.0 / self.inertia(), &var);
        for i in 0..3 {
            dhq[i] += a[i];
            dhp[i] += b[i];
        }
    }
}

// The tangent lift (Gauss, midpoint, RK4) on the surfaces with second derivatives.
crate::integrate::methods::canonical_system!(TangentTop, canonical_catalog(), |t: &TangentTop| t
    .has_hessian()
    .then(|| Tangent::field(t.clone()).into_system()));

/// The charged particle equivalent to a tangent top (002 §III.B): with p_θ fixed, the centre of
/// the top moves as a particle of mass m on the surface in the magnetic potential A = α (the
/// connection 1-form) with charge e = p_θ. State z = (x¹, x², p₁, p₂).
///
/// **Derivation (Routh).** For L = ½ ẋᵀGẋ + ½𝕀(θ̇ + α·ẋ)², G = m g, θ is cyclic; the Routhian
/// R = L − p_θθ̇ = ½ ẋᵀGẋ + p_θ α·ẋ − p_θ²/(2𝕀) is the Lagrangian 002 (57) with metric
/// ĝ = G/m = g, potential A = α and charge q = p_θ (the last term is constant), whose
/// Euler–Lagrange equations are those of (x¹, x²) in the top's. **Slip:** 002 (58) puts 𝕀ααᵀ/m
/// into ĝ, A = −α and the charge ½𝕀θ̇, reasoning that θ̇ is conserved; it is p_θ = 𝕀(θ̇ + α·ẋ)
/// that is conserved, not θ̇, and that regrouping does not give the top's x-equations (the
/// test `magnetic_analogue_reproduces_the_centre` checks the Routh form). For a symmetric
/// embedded top, G includes the (39) term: ĝ = g + (I₀/m) h g⁻¹ h. An anisotropic embedded top
/// has no such analogue (its Lagrangian depends on θ).
///
/// H = ½ πᵀG⁻¹π, π = p − e α, so that the top's energy is H + p_θ²/(2𝕀). The Killing momenta
/// are the top's with p_θ = e: J = p_i X^i + e ψ̇ (the magnetic translations).
#[derive(Clone, Debug)]
pub struct ChargedParticle {
    top: TangentTop,
    charge: f64,
}

impl TangentTop {
    /// The charged particle of 002 §III.B for the tops with p_θ = `p_theta` ([`ChargedParticle`]).
    /// Errors: non-finite p_θ; an anisotropic embedded top (its Lagrangian depends on θ).
    pub fn magnetic_analogue(&self, p_theta: f64) -> Result<ChargedParticle> {
        check::finite_slice("p_theta", &[p_theta])?;
        if self.depends_on_theta() {
            return Err(Error::invalid(
                "magnetic_analogue",
                "an anisotropic embedded top depends on θ and has no charged-particle analogue",
            ));
        }
        Ok(ChargedParticle {
            top: self.clone(),
            charge: p_theta,
        })
    }
}

impl ChargedParticle {
    /// The top it stands for.
    pub fn top(&self) -> &TangentTop {
        &self.top
    }

    /// The charge e = p_θ.
    pub fn charge(&self) -> f64 {
        self.charge
    }

    fn check_x(&self, x: Vec2) -> Result<()> {
        check::finite_slice("x", &x)?;
        self.top.surface.check(x).map_err(|v| v.at_start())
    }

    /// ĝ(x) = G/m (= g intrinsically; module docs). Errors: x outside the chart.
    pub fn metric(&self, x: Vec2) -> Result<Mat2> {
        self.check_x(x)?;
        let m = self.top.mass;
        Ok(self.top.local(x, 0.0).g.map(|r| r.map(|v| v / m)))
    }

    /// The magnetic potential A = α (the frame's connection 1-form). Errors: x outside the chart.
    pub fn potential(&self, x: Vec2) -> Result<Vec2> {
        self.check_x(x)?;
        Ok(self.top.surface.connection(x))
    }

    /// The canonical state (x, p = Gẋ + eα) at x with velocity ẋ. Errors: x outside the chart,
    /// non-finite input.
    pub fn state(&self, x: Vec2, xdot: Vec2) -> Result<Vec<f64>> {
        check::finite_slice("xdot", &xdot)?;
        self.check_x(x)?;
        let l = self.top.local(x, 0.0);
        let e = self.charge;
        Ok(vec![
            x[0],
            x[1],
            l.g[0][0] * xdot[0] + l.g[0][1] * xdot[1] + e * l.alpha[0],
            l.g[1][0] * xdot[0] + l.g[1][1] * xdot[1] + e * l.alpha[1],
        ])
    }

    fn check_z(&self, z: &[f64]) -> Result<()> {
        check::len_of("state", z, 4)?;
        check::finite_slice("state", z)?;
        self.top
            .surface
            .check([z[0], z[1]])
            .map_err(|v| v.at_start())
    }

    /// The velocity ẋ = G⁻¹(p − eα).
    pub fn velocities(&self, z: &[f64]) -> Result<Vec2> {
        self.check_z(z)?;
        Ok(charged_particle(
            &self.top.local([z[0], z[1]], 0.0),
            [z[2], z[3]],
            self.charge,
        )
        .0)
    }

    /// The momenta of the surface's Killing fields, J = p_i X^i + e ψ̇, in the order of
    /// [`Surface::killing`] (those of the top at p_θ = e).
    pub fn killing_momenta(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.check_z(z)?;
        Ok(self.killing_values(z, false))
    }

    fn killing_values(&self, z: &[f64], affine_only: bool) -> Vec<f64> {
        let top_z = [z[0], z[1], 0.0, z[2], z[3], self.charge];
        self.top.killing_values(&top_z, affine_only)
    }
}

impl Problem for ChargedParticle {
    fn calls_out(&self) -> bool {
        self.top.calls_out()
    }
    fn name(&self) -> &'static str {
        "ChargedParticle"
    }
    /// The top's mass m and inertia 𝕀 (which enters G when the top is embedded), and the
    /// charge e = p_θ.
    fn parameters(&self) -> Vec<&'static str> {
        vec!["mass", "inertia", "charge"]
    }
    fn space(&self) -> Space {
        Space::new([("x", Block::Real(2)), ("p", Block::Real(2))])
    }
    /// H = ½ πᵀG⁻¹π.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.check_z(z)?;
        Ok(self.hamiltonian(&z[..2], &z[2..]))
    }
    /// The Killing momenta of the affine generators (as for the top).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.check_z(z)?;
        Ok(self.killing_values(z, true))
    }
    fn invariant_names(&self) -> Vec<String> {
        surface::killing_momentum_names(&*self.top.surface, true)
    }
    /// x in the surface's domain.
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.top
            .surface
            .check([z[0], z[1]])
            .map_err(|v| v.at_start())
    }
}

impl Canonical for ChargedParticle {
    fn dof(&self) -> usize {
        2
    }
    /// H = ½ p·ẋ − ½ e α·ẋ = ½ π·v.
    fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64 {
        let (mut hq, mut hp) = ([0.0; 2], [0.0; 2]);
        self.gradient(q, p, &mut hq, &mut hp);
        let a = self.top.surface.connection([q[0], q[1]]);
        let e = self.charge;
        0.5 * ((p[0] - e * a[0]) * hp[0] + (p[1] - e * a[1]) * hp[1])
    }
    /// ∂H/∂p = v, ∂H/∂x = −(½ vᵀ(∂G)v + e (∂α) v); NaN outside the domain.
    fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
        let x = [q[0], q[1]];
        if !self.top.surface.contains(x) {
            hq[..2].fill(f64::NAN);
            hp[..2].fill(f64::NAN);
            return;
        }
        let (v, force) = charged_particle(&self.top.local(x, 0.0), [p[0], p[1]], self.charge);
        hp[..2].copy_from_slice(&v);
        hq[0] = -force[0];
        hq[1] = -force[1];
    }
}

/// D²H\[dq, dp\] of H = ½ πᵀG⁻¹π by the top's `gradient_variation` at θ = 0, p_θ = e;
/// NaN outside the domain or without the surface's second derivatives.
impl CanonicalTangent for ChargedParticle {
    fn gradient_tangent(
        &self,
        q: &[f64],
        p: &[f64],
        dq: &[f64],
        dp: &[f64],
        dhq: &mut [f64],
        dhp: &mut [f64],
    ) {
        let x = [q[0], q[1]];
        if !self.top.surface.contains(x) {
            dhq[..2].fill(f64::NAN);
            dhp[..2].fill(f64::NAN);
            return;
        }
        let l = self.top.local(x, 0.0);
        let var = TangentTop::state_variation(&l, &self.top.second(x, 0.0), dq, dp);
        let (a, b) = gradient_variation(&l, [p[0], p[1]], self.charge, 0.0, &var);
        dhq[..2].copy_from_slice(&a[..2]);
        dhp[..2].copy_from_slice(&b[..2]);
    }

    /// ∂∇H/∂m, ∂∇H/∂𝕀 (as the top's), ∂∇H/∂e (δπ = −α).
    fn gradient_parameter(&self, q: &[f64], p: &[f64], m: usize, dhq: &mut [f64], dhp: &mut [f64]) {
        let x = [q[0], q[1]];
        if !self.top.surface.contains(x) {
            dhq[..2].fill(f64::NAN);
            dhp[..2].fill(f64::NAN);
            return;
        }
        let l = self.top.local(x, 0.0);
        let var = if m == 2 {
            Variation {
                pt: 1.0,
                ..Variation::default()
            }
        } else {
            self.top.parameter_variation(&l, m)
        };
        let (a, b) = gradient_variation(&l, [p[0], p[1]], self.charge, 0.0, &var);
        for i in 0..2 {
            dhq[i] += a[i];
            dhp[i] += b[i];
        }
    }
}

// The tangent lift where the top has one.
crate::integrate::methods::canonical_system!(
    ChargedParticle,
    canonical_catalog(),
    |c: &ChargedParticle| c
        .top
        .has_hessian()
        .then(|| Tangent::field(c.clone()).into_system())
);
