//! The symmetric relativistic tangent top on the static space-time −e^{2φ}dt² + γ of a potential
//! φ, γ the flat dx² + dy² or the metric of a [`Surface`], to second order in the body's size
//! (002 (115)–(117), derived again; module docs, "Static field").

use std::sync::Arc;

use nalgebra::Vector3;

use super::lift::{self, det, inner, inv, DerivsT, GeoT, M2, V2};
use super::weak_field::{angular_momentum, outside_potential};
use super::{
    energy, lagrangian, legendre_inverse, space, state, velocities, Derivs, Legendre, Potential,
};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::space::Space;
use crate::integrate::Problem;
use crate::numerics::dual::{Dual, Real};
use crate::systems::tangent_top::surface::{self, inverse, Mat2, Plane, Surface};

/// The symmetric relativistic tangent top on the static space-time
/// ds² = −e^{2φ}dt² + γ_ij dxⁱdxʲ of a potential φ(x¹, x²), the Lagrangian 002 (117) (derived
/// again, physical sign, module docs "Static field"): with Q = γ(ẋ, ẋ), b = e^{2φ} − Q,
/// I₀ = 𝕀/2, s = θ̇ + α·ẋ (α the connection 1-form of the surface's frame; s = θ̇ in the plane),
/// G the components of dφ in an orthonormal frame and c = G₂u₁ − G₁u₂ (u those of ẋ;
/// c = G_yẋ − G_xẏ in the plane),
/// L = −m√b + I₀s²/√b − I₀e^{2φ}|G|²/(2√b) + I₀(s²Q + 2e^{2φ}s c + e^{4φ}|G|²)/(2b^{3/2}).
/// [`StaticFieldTop::new`]: γ = dx² + dy² (Cartesian x = (x, y)); [`StaticFieldTop::on_surface`]:
/// γ = g of a [`Surface`], x = (x¹, x²) its chart. Its weak-field, slow-motion limit in the plane
/// is [`WeakFieldTop`](super::WeakFieldTop) (002 (118)), and φ = 0 gives
/// [`RelativisticTangentTop`](super::RelativisticTangentTop) (flat or on the same surface). State
/// z = (x¹, x², θ, p₁, p₂, p_θ); speeds √Q < e^φ.
#[derive(Clone, Debug)]
pub struct StaticFieldTop {
    mass: f64,
    i0: f64,
    potential: Potential,
    /// The spatial slice: None for the plane dx² + dy² in Cartesian coordinates (the kernel runs
    /// on [`Plane`]'s geometry); a surface for [`StaticFieldTop::on_surface`].
    surface: Option<Arc<dyn Surface>>,
    /// On a surface: its affine Killing generators that leave φ invariant (their momenta are
    /// invariants), by index of [`Surface::killing`].
    symmetries: Vec<usize>,
}

impl StaticFieldTop {
    /// Mass m > 0, 𝕀 = `inertia` > 0 (the symmetric body, I = (𝕀/2)·Id, I₀ = 𝕀/2) and the
    /// potential φ (g_tt = −e^{2φ}), on the flat spatial metric dx² + dy².
    pub fn new(mass: f64, inertia: f64, potential: Potential) -> Result<Self> {
        check::positive("mass", mass)?;
        check::positive("inertia", inertia)?;
        Ok(StaticFieldTop {
            mass,
            i0: 0.5 * inertia,
            potential,
            surface: None,
            symmetries: Vec::new(),
        })
    }

    /// The same top on ds² = −e^{2φ}dt² + g over `surface` (002 (115)–(117) with a curved γ;
    /// module docs, "Static field"), φ a function of the surface's chart coordinates (x¹, x²);
    /// z = (x¹, x², θ, p₁, p₂, p_θ) in that chart. On [`Plane`] it is the top of
    /// [`StaticFieldTop::new`] (the same numbers; the invariants are the Killing momenta that
    /// keep φ); with φ = 0 the top of [`RelativisticTangentTop::on_surface`].
    ///
    /// [`RelativisticTangentTop::on_surface`]: super::RelativisticTangentTop::on_surface
    pub fn on_surface(
        surface: Arc<dyn Surface>,
        mass: f64,
        inertia: f64,
        potential: Potential,
    ) -> Result<Self> {
        let top = Self::new(mass, inertia, potential)?;
        let symmetries = field_symmetries(&*surface, &top.potential);
        Ok(StaticFieldTop {
            surface: Some(surface),
            symmetries,
            ..top
        })
    }

    /// The potential.
    pub fn potential(&self) -> &Potential {
        &self.potential
    }

    /// The mass m.
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// 𝕀 = tr I.
    pub fn inertia(&self) -> f64 {
        2.0 * self.i0
    }

    /// The spatial slice: the surface of [`StaticFieldTop::on_surface`], else [`Plane`].
    pub fn surface(&self) -> Arc<dyn Surface> {
        self.surface.clone().unwrap_or_else(|| Arc::new(Plane))
    }

    /// Whether the top lives on a surface ([`StaticFieldTop::on_surface`]) rather than in the
    /// Cartesian plane of [`StaticFieldTop::new`].
    pub fn is_on_surface(&self) -> bool {
        self.surface.is_some()
    }

    /// The spatial slice the kernel runs on.
    fn slice(&self) -> &dyn Surface {
        self.surface.as_deref().unwrap_or(&Plane)
    }

    /// L(q, q̇) of 002 (117) (derived again, physical sign), q = (x¹, x², θ), q̇ = (ẋ¹, ẋ², θ̇).
    /// Errors: non-finite input, x outside the chart, φ not finite at x, √γ(ẋ, ẋ) ≥ e^φ.
    pub fn lagrangian(&self, q: [f64; 3], qdot: [f64; 3]) -> Result<f64> {
        lagrangian(self, q, qdot)
    }

    /// The canonical state (x¹, x², θ, p₁, p₂, p_θ) with p = ∂L/∂q̇. Errors: as
    /// [`StaticFieldTop::lagrangian`], a Legendre map that is not invertible there.
    pub fn state(
        &self,
        x: [f64; 2],
        theta: f64,
        xdot: [f64; 2],
        thetadot: f64,
    ) -> Result<Vec<f64>> {
        state(self, [x[0], x[1], theta], [xdot[0], xdot[1], thetadot])
    }

    /// The velocities (ẋ¹, ẋ², θ̇) of a state. Errors: wrong length, non-finite, outside the
    /// chart, the potential's domain or the range of the Legendre map.
    pub fn velocities(&self, z: &[f64]) -> Result<[f64; 3]> {
        velocities(self, z)
    }

    /// The angular momentum x p_y − y p_x about the chart's origin (conserved for a central
    /// potential in the plane).
    pub fn angular_momentum(&self, z: &[f64]) -> Result<f64> {
        check::len_of("state", z, 6)?;
        angular_momentum(z)
    }

    /// The momenta J = p_A X^A of all Killing fields of the spatial slice lifted to (x, θ), in
    /// the order of [`Surface::killing`] (the plane: p_x, p_y, x p_y − y p_x + p_θ). Conserved
    /// when the field X leaves φ invariant (the invariants list the affine ones that provably
    /// do). Errors: wrong length, non-finite, x outside the chart.
    pub fn killing_momenta(&self, z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("state", z, 6)?;
        check::finite_slice("state", z)?;
        self.check_point(&z[..3])?;
        Ok(surface::killing_momenta(self.slice(), z, false))
    }
}

/// The affine Killing generators of `surface` that leave φ invariant ([`Potential`]'s
/// `kept_by`): the spatial part X(x) = A x + b read off at x = 0, e₁, e₂ (an affine generator is
/// a closed formula, defined off the chart too). None on a surface that calls out (no foreign
/// calls at construction).
fn field_symmetries(surface: &dyn Surface, potential: &Potential) -> Vec<usize> {
    if surface.calls_out() {
        return Vec::new();
    }
    (0..surface.killing_count())
        .filter(|&k| surface.killing_is_affine(k))
        .filter(|&k| {
            let at = |x: [f64; 2]| {
                let v = surface.killing(k, x);
                [v[0], v[1]]
            };
            let (b, e1, e2) = (at([0.0, 0.0]), at([1.0, 0.0]), at([0.0, 1.0]));
            let a: Mat2 = [[e1[0] - b[0], e2[0] - b[0]], [e1[1] - b[1], e2[1] - b[1]]];
            let finite = a.iter().flatten().chain(&b).all(|v| v.is_finite());
            finite && potential.kept_by(a, b)
        })
        .collect()
}

impl Problem for StaticFieldTop {
    fn calls_out(&self) -> bool {
        self.potential.calls_out() || self.surface.as_ref().is_some_and(|s| s.calls_out())
    }
    fn name(&self) -> &'static str {
        "StaticFieldTop"
    }
    /// The mass m and the inertia 𝕀: the sensitivities of a tangent run (the
    /// potential's and the surface's constants are not parameters here).
    fn parameters(&self) -> Vec<&'static str> {
        vec!["mass", "inertia"]
    }
    fn space(&self) -> Space {
        space()
    }
    /// E = p·q̇ − L (conserved: ∂_t is a Killing field of the static metric).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        energy(self, z)
    }
    /// In the plane: p_θ and the momenta of the field's symmetries (`Potential::invariants`). On
    /// a surface: p_θ and the momenta of the surface's affine Killing generators that leave φ
    /// invariant (quadratic in z, so kept by the Gauss methods).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let Some(surface) = &self.surface else {
            return self.potential.invariants(z);
        };
        check::len_of("state", z, 6)?;
        check::finite_slice("state", z)?;
        self.check_point(&z[..3])?;
        let x = [z[0], z[1]];
        let momenta = self.symmetries.iter().map(|&k| {
            let xk = surface.killing(k, x);
            (0..3).map(|a| z[3 + a] * xk[a]).sum()
        });
        Ok(std::iter::once(z[5]).chain(momenta).collect())
    }
    fn invariant_names(&self) -> Vec<String> {
        let Some(surface) = &self.surface else {
            return self.potential.invariant_names();
        };
        let momenta = self
            .symmetries
            .iter()
            .map(|&k| surface::killing_momentum_name(&**surface, k));
        std::iter::once("p_θ".to_string()).chain(momenta).collect()
    }
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.velocities(z).map(|_| ())
    }
}

/// What the kernel needs at one point x, whatever the velocities (computed once per Legendre
/// inversion): the slice's geometry, the field's ε = e^{2φ}, |G|² = g⁻¹(dφ, dφ),
/// h = gφ⊥/√det g (φ⊥ = (∂₂φ, −∂₁φ); c = h·ẋ) and their x-derivatives (module docs, "Static
/// field"); over [`Real`] (f64, or [`Dual`] along a direction for the tangent lift).
struct Local<T> {
    geo: GeoT<T>,
    /// φ (the local light speed is e^φ).
    phi: T,
    eps: T,
    g2: T,
    h: V2<T>,
    /// `dh[k][j]` = ∂_k h_j.
    dh: M2<T>,
    /// ∂_k ε = 2ε∂_kφ.
    deps: V2<T>,
    /// ∂_k|G|² = 2∂_k∂_iφ (g⁻¹dφ)ⁱ − (g⁻¹dφ)ᵀ∂_kg(g⁻¹dφ).
    dg2: V2<T>,
}

impl StaticFieldTop {
    /// The geometry of the slice and the field at x (`Local`); None outside the chart or where
    /// φ, its derivatives or e^{2φ} are not finite. In the plane (g = Id, ∂g = 0) the terms with
    /// ∂g are exact zeros and the products with g, g⁻¹ and √det g = 1 exact: h = (G_y, −G_x),
    /// |G|² = G_x² + G_y², ∂_k|G|² = 2(HG)_k, ∂_kh = ∂_kφ⊥, bit for bit the flat formulas.
    fn local<T: Real>(&self, q: [T; 3]) -> Option<Local<T>> {
        let k = |x: f64| T::from(x);
        let x = [q[0], q[1]];
        let slice = self.slice();
        if !slice.contains([x[0].re(), x[1].re()]) {
            return None;
        }
        let geo = lift::geometry(slice, x);
        let (phi, grad, hess) = lift::potential(&self.potential, x)?;
        let [gx, gy] = grad;
        let [hxx, hxy, hyy] = hess;
        let eps = (k(2.0) * phi).exp();
        if ![eps, gx, gy, hxx, hxy, hyy].iter().all(|v| v.is_finite()) {
            return None;
        }
        let g = &geo.g;
        let gi = inv(g);
        let sd = det(g).sqrt();
        let perp = [gy, -gx];
        let h = [
            (perp[0] * g[0][0] + perp[1] * g[1][0]) / sd,
            (perp[0] * g[0][1] + perp[1] * g[1][1]) / sd,
        ];
        let grad_up = [gi[0][0] * gx + gi[0][1] * gy, gi[1][0] * gx + gi[1][1] * gy]; // g⁻¹dφ
        let g2 = gx * grad_up[0] + gy * grad_up[1];
        let hess_rows = [[hxx, hxy], [hxy, hyy]];
        let mut dh = [[k(0.0); 2]; 2];
        let (mut deps, mut dg2) = ([k(0.0); 2], [k(0.0); 2]);
        for kk in 0..2 {
            let dg = &geo.dg[kk];
            let hr = hess_rows[kk];
            deps[kk] = k(2.0) * eps * grad[kk];
            dg2[kk] =
                k(2.0) * (hr[0] * grad_up[0] + hr[1] * grad_up[1]) - inner(dg, grad_up, grad_up);
            // ∂_k h = (g ∂_kφ⊥ + ∂_kg φ⊥)/√det g − h ½tr(g⁻¹∂_kg).
            let dperp = [hr[1], -hr[0]];
            let dlog = k(0.5) * (gi[0][0] * dg[0][0] + gi[0][1] * dg[1][0])
                + k(0.5) * (gi[1][0] * dg[0][1] + gi[1][1] * dg[1][1]);
            dh[kk] = std::array::from_fn(|j| {
                ((dperp[0] * g[0][j] + dperp[1] * g[1][j])
                    + (perp[0] * dg[0][j] + perp[1] * dg[1][j]))
                    / sd
                    - h[j] * dlog
            });
        }
        Some(Local {
            geo,
            phi,
            eps,
            g2,
            h,
            dh,
            deps,
            dg2,
        })
    }

    /// m and I₀, the parameter (0: the mass, 1: the inertia 𝕀 = 2I₀) moved at unit rate.
    fn constants<T: Real>(&self, parameter: Option<usize>) -> (T, T) {
        (
            T::with(self.mass, f64::from(u8::from(parameter == Some(0)))),
            T::with(self.i0, 0.5 * f64::from(u8::from(parameter == Some(1)))),
        )
    }

    /// The kernel (module docs, "Static field"): L, ∂L/∂q̇, ∂L/∂q, ∂²L/∂q̇² at the data `lo` of
    /// x, the angle θ and q̇ = (ẋ, θ̇), through the invariants Q = g(ẋ, ẋ), c = h·ẋ,
    /// s = θ̇ + α·ẋ and the field's ε, |G|², with the constants m, I₀. In the plane (g = Id,
    /// α = 0) every added term is an exact zero, so the numbers are those of the flat kernel.
    /// None where Q ≥ e^{2φ} or a value is not finite.
    fn kernel<T: Real>(
        &self,
        lo: &Local<T>,
        theta: T,
        v: [T; 3],
        (m, i0): (T, T),
    ) -> Option<DerivsT<T>> {
        let k = |x: f64| T::from(x);
        let (u, w) = ([v[0], v[1]], v[2]);
        let geo = &lo.geo;
        let (g, a, h) = (&geo.g, geo.alpha, lo.h);
        let (eps, g2) = (lo.eps, lo.g2);
        let n = [
            g[0][0] * u[0] + g[0][1] * u[1],
            g[1][0] * u[0] + g[1][1] * u[1],
        ]; // gẋ
        let qq = n[0] * u[0] + n[1] * u[1];
        let b = eps - qq;
        if !(b.re() > 0.0 && w.is_finite() && theta.is_finite()) {
            return None;
        }
        let s = w + (a[0] * u[0] + a[1] * u[1]);
        let c = h[0] * u[0] + h[1] * u[1];
        let b1 = k(1.0) / b.sqrt(); // β = b^{−1/2}
        let b3 = b1 * b1 * b1;
        let b5 = b3 * b1 * b1;
        let b7 = b5 * b1 * b1;
        let s2 = s * s;
        let t = s2 * qq + k(2.0) * eps * s * c + eps * eps * g2;
        let l = -m * b * b1 + i0 * s2 * b1 - k(0.5) * i0 * eps * g2 * b1 + k(0.5) * i0 * b3 * t;
        let l_q =
            k(0.5) * m * b1 + i0 * s2 * b3 - k(0.25) * i0 * eps * g2 * b3 + k(0.75) * i0 * b5 * t;
        let l_c = i0 * b3 * eps * s;
        let l_s = k(2.0) * i0 * s * b1 + i0 * b3 * (s * qq + eps * c);
        let l_qq = k(0.25) * m * b3 + k(2.25) * i0 * s2 * b5 - k(0.375) * i0 * eps * g2 * b5
            + k(1.875) * i0 * b7 * t;
        let l_qc = k(1.5) * i0 * b5 * eps * s;
        let l_qs = k(2.0) * i0 * s * b3 + k(1.5) * i0 * b5 * (s * qq + eps * c);
        let l_cs = i0 * b3 * eps;
        let l_ss = k(2.0) * i0 * b1 + i0 * b3 * qq;
        // ∂L/∂ε and ∂L/∂|G|² at fixed (Q, c, s).
        let l_eps = -k(0.5) * m * b1 - k(0.5) * i0 * s2 * b3 - k(0.5) * i0 * g2 * b1
            + k(0.25) * i0 * eps * g2 * b3
            - k(0.75) * i0 * b5 * t
            + i0 * b3 * (s * c + eps * g2);
        let l_g2 = -k(0.5) * i0 * eps * b1 + k(0.5) * i0 * b3 * eps * eps;
        let lv = [
            k(2.0) * l_q * n[0] + l_c * h[0] + l_s * a[0],
            k(2.0) * l_q * n[1] + l_c * h[1] + l_s * a[1],
            l_s,
        ];
        // Through x: ∂_kQ = ẋᵀ∂_kgẋ, ∂_kc = ∂_kh·ẋ, ∂_ks = ∂_kα·ẋ, and ∂_kε, ∂_k|G|² of `lo`.
        let mut lq = [k(0.0); 3];
        for (kk, lqk) in lq.iter_mut().enumerate().take(2) {
            let dh = lo.dh[kk];
            let dc = dh[0] * u[0] + dh[1] * u[1];
            let dq = inner(&geo.dg[kk], u, u);
            let da = geo.dalpha[kk];
            let ds = da[0] * u[0] + da[1] * u[1];
            *lqk = lo.deps[kk] * l_eps + lo.dg2[kk] * l_g2 + l_c * dc + l_q * dq + l_s * ds;
        }
        let mut hess = [[k(0.0); 3]; 3];
        for i in 0..2 {
            for j in 0..2 {
                hess[i][j] = k(2.0) * l_q * g[i][j]
                    + k(4.0) * l_qq * n[i] * n[j]
                    + k(2.0) * l_qc * (n[i] * h[j] + h[i] * n[j])
                    + k(2.0) * l_qs * (n[i] * a[j] + a[i] * n[j])
                    + l_cs * (h[i] * a[j] + a[i] * h[j])
                    + l_ss * a[i] * a[j];
            }
            let hw = k(2.0) * l_qs * n[i] + l_cs * h[i] + l_ss * a[i];
            hess[i][2] = hw;
            hess[2][i] = hw;
        }
        hess[2][2] = l_ss;
        Some(DerivsT { l, lv, lq, hess })
    }
}

impl Legendre for StaticFieldTop {
    /// The kernel at the geometry and field of x (module docs, "Static field"); None outside
    /// the chart and where [`StaticFieldTop::kernel`] is.
    fn derivs(&self, q: &[f64], v: &Vector3<f64>) -> Option<Derivs> {
        let q = [q[0], q[1], q[2]];
        self.kernel(
            &self.local(q)?,
            q[2],
            [v[0], v[1], v[2]],
            self.constants(None),
        )?
        .finite()
    }

    /// From a free particle of mass m + 𝕀s² (the low-speed form of the momenta) carrying
    /// π = p_x − p_θα at spin s = p_θ/𝕀, slower than the local light speed e^φ; failing that,
    /// from rest. The geometry and the field are evaluated once.
    fn solve(&self, q: &[f64], p: &[f64]) -> Option<(Vector3<f64>, Derivs)> {
        let lo = self.local([q[0], q[1], q[2]])?;
        let c = lo.phi.exp();
        if !(c.is_finite() && c > 0.0) {
            return None;
        }
        let tr = 2.0 * self.i0;
        let s = p[2] / tr;
        let a = lo.geo.alpha;
        let pi = [p[0] - p[2] * a[0], p[1] - p[2] * a[1]];
        let gi = inverse(&lo.geo.g);
        let up = [
            gi[0][0] * pi[0] + gi[0][1] * pi[1],
            gi[1][0] * pi[0] + gi[1][1] * pi[1],
        ];
        let mm = self.mass + tr * s * s;
        let e = (mm * mm + up[0] * pi[0] + up[1] * pi[1]).sqrt();
        let xd = [c * up[0] / e, c * up[1] / e];
        let guess = Vector3::new(xd[0], xd[1], s - (a[0] * xd[0] + a[1] * xd[1]));
        let constants = self.constants(None);
        let derivs = |v: &Vector3<f64>| {
            self.kernel(&lo, q[2], [v[0], v[1], v[2]], constants)?
                .finite()
        };
        legendre_inverse(p, guess, derivs)
            .or_else(|| legendre_inverse(p, Vector3::new(0.0, 0.0, s), derivs))
    }

    fn derivs_dual(
        &self,
        q: [Dual; 3],
        v: [Dual; 3],
        parameter: Option<usize>,
    ) -> Option<DerivsT<Dual>> {
        self.kernel(&self.local(q)?, q[2], v, self.constants(parameter))
    }

    /// On a slice with second derivatives in a potential with third derivatives.
    fn has_hessian(&self) -> bool {
        self.slice().has_second_derivatives() && self.potential.has_third()
    }

    fn undefined(&self, q: [f64; 3], v: [f64; 3]) -> Error {
        let x = [q[0], q[1]];
        if let Some(surface) = &self.surface {
            if let Err(e) = surface.check(x) {
                return e.at_start();
            }
        }
        let pv = self.potential.eval(x);
        let field = [pv.phi, pv.grad[0], pv.grad[1]];
        let hess = pv.hess;
        if !(field.iter().chain(&hess).all(|x| x.is_finite()) && (2.0 * pv.phi).exp().is_finite()) {
            return outside_potential(q);
        }
        let speed = match &self.surface {
            None => v[0].hypot(v[1]),
            Some(s) => inner(&s.metric(x), [v[0], v[1]], [v[0], v[1]]).sqrt(),
        };
        Error::invalid(
            "velocity",
            format!(
                "expected a speed √γ(ẋ, ẋ) < e^φ = {} (the local speed of light), got \
                 |({}, {})| = {speed}",
                pv.phi.exp(),
                v[0],
                v[1],
            ),
        )
    }

    fn check_point(&self, q: &[f64]) -> Result<()> {
        match &self.surface {
            None => Ok(()),
            Some(surface) => surface.check([q[0], q[1]]).map_err(|e| e.at_start()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::systems::tangent_top::surface::{Graph, HyperbolicPlane, Sphere};

    /// 4th-order central difference of f along coordinate i of x.
    fn fd(f: impl Fn(&[f64; 3]) -> f64, x: [f64; 3], i: usize) -> f64 {
        let h = 1e-4;
        let at = |k: f64| {
            let mut y = x;
            y[i] += k * h;
            f(&y)
        };
        (8.0 * (at(1.0) - at(-1.0)) - (at(2.0) - at(-2.0))) / (12.0 * h)
    }

    /// The kernel's ∂L/∂q̇, ∂L/∂q against differences of its L, and ∂²L/∂q̇² against differences
    /// of its ∂L/∂q̇, in the plane and on surfaces with diagonal (sphere, half-plane) and
    /// non-diagonal (a quadric graph) metrics, in fields with a full Hessian.
    #[test]
    fn kernel_derivatives_are_those_of_its_lagrangian() {
        let point = Potential::point_mass(0.2).unwrap();
        let uniform = Potential::uniform([0.25, -0.4]).unwrap();
        let cases: Vec<(StaticFieldTop, [f64; 3], [f64; 3])> = vec![
            (
                StaticFieldTop::new(1.1, 0.3, point.clone()).unwrap(),
                [0.7, -0.5, 0.3],
                [0.3, 0.2, 1.4],
            ),
            (
                StaticFieldTop::on_surface(
                    Arc::new(Sphere::new(1.3).unwrap()),
                    1.1,
                    0.3,
                    point.clone(),
                )
                .unwrap(),
                [1.1, 0.4, 0.7],
                [0.25, -0.3, 1.6],
            ),
            (
                StaticFieldTop::on_surface(Arc::new(HyperbolicPlane), 1.0, 0.4, uniform.clone())
                    .unwrap(),
                [0.3, 0.8, -0.5],
                [0.2, -0.15, 1.2],
            ),
            (
                StaticFieldTop::on_surface(
                    Arc::new(Graph::quadric(0.8, -0.5).unwrap()),
                    1.0,
                    0.4,
                    point,
                )
                .unwrap(),
                [0.6, 0.5, 2.0],
                [0.3, -0.25, -0.9],
            ),
        ];
        let mut worst = 0.0f64;
        for (top, q, v) in &cases {
            let d = top.derivs(q, &Vector3::from(*v)).unwrap();
            let lag = |q: &[f64; 3], v: &[f64; 3]| top.derivs(q, &Vector3::from(*v)).unwrap();
            for i in 0..3 {
                let lv = fd(|w| lag(q, w).l, *v, i);
                let lq = fd(|y| lag(y, v).l, *q, i);
                worst = worst.max((lv - d.lv[i]).abs()).max((lq - d.lq[i]).abs());
                for j in 0..3 {
                    let h = fd(|w| lag(q, w).lv[j], *v, i);
                    worst = worst.max((h - d.hess[(j, i)]).abs());
                }
            }
            // The coupling and the connection matter at these points.
            assert!(d.lq.amax() > 1e-2 && d.hess[(0, 2)].abs() > 1e-3);
        }
        eprintln!("StaticFieldTop kernel vs differences of L: {worst:.1e}");
        assert!(worst < 1e-9, "{worst}");
    }
}
