//! The tangent lift of the Legendre tops (issue 26): the Hessian of H(q, p) = p·q̇ − L(q, q̇) at
//! q̇ = q̇(q, p) through the implicit-function theorem on the Legendre map ∂L/∂q̇(q, q̇) = p,
//!
//! δq̇ = L_q̇q̇⁻¹(δp − L_q̇q δq),   δ(∂H/∂p) = δq̇,   δ(∂H/∂q) = −(L_qq δq + L_qq̇ δq̇),
//!
//! with L_q̇q δq, L_qq δq + L_qq̇ δq̇ the directional derivatives of the kernels' ∂L/∂q̇ and ∂L/∂q
//! evaluated in [`Dual`] numbers (exact to round-off; the kernels are written once over
//! [`Real`]); the parameters the same way, their rate in the ε parts. What the kernels read at x
//! is lifted here: the surface's g, ∂g, α, ∂α with their derivatives along δx (from
//! [`Surface::second_derivatives`]), the frame (∂_k e₁ = −Γ_k e₁ + α_k e₂,
//! ∂_k e₂ = −Γ_k e₂ − α_k e₁, ∇Ê₁ = wÊ₂ read in coordinates), and the potential's φ, ∇φ, ∇²φ
//! (with its third derivatives, [`Potential::third`]).

use super::{Derivs, Legendre, Potential};
use crate::numerics::dual::{Dual, Real};
use crate::systems::tangent_top::surface::{inverse, Surface};
use nalgebra::{Matrix3, Vector3};

pub(super) type V2<T> = [T; 2];
pub(super) type M2<T> = [[T; 2]; 2];

/// The derivatives of L at one point over [`Real`]: L, ∂L/∂q̇, ∂L/∂q, ∂²L/∂q̇².
pub(super) struct DerivsT<T> {
    pub(super) l: T,
    pub(super) lv: [T; 3],
    pub(super) lq: [T; 3],
    pub(super) hess: [[T; 3]; 3],
}

impl DerivsT<f64> {
    /// As [`Derivs`] (nalgebra), if every value is finite.
    pub(super) fn finite(self) -> Option<Derivs> {
        let d = Derivs {
            l: self.l,
            lv: Vector3::from(self.lv),
            lq: Vector3::from(self.lq),
            hess: Matrix3::from_fn(|i, j| self.hess[i][j]),
        };
        let ok = d.l.is_finite()
            && d.lv.iter().all(|x| x.is_finite())
            && d.lq.iter().all(|x| x.is_finite())
            && d.hess.iter().all(|x| x.is_finite());
        ok.then_some(d)
    }
}

/// A [`Real`] constant.
#[inline]
pub(super) fn c<T: Real>(x: f64) -> T {
    T::from(x)
}

/// g(u, v) = g_ij u^i v^j (the order of [`crate::systems::tangent_top::surface::inner`]).
pub(super) fn inner<T: Real>(g: &M2<T>, u: V2<T>, v: V2<T>) -> T {
    let mut s = c::<T>(0.0);
    for i in 0..2 {
        for j in 0..2 {
            s += g[i][j] * u[i] * v[j];
        }
    }
    s
}

pub(super) fn det<T: Real>(m: &M2<T>) -> T {
    m[0][0] * m[1][1] - m[0][1] * m[1][0]
}

pub(super) fn inv<T: Real>(m: &M2<T>) -> M2<T> {
    let d = det(m);
    [[m[1][1] / d, -m[0][1] / d], [-m[1][0] / d, m[0][0] / d]]
}

pub(super) fn mul<T: Real>(a: &M2<T>, b: &M2<T>) -> M2<T> {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
}

/// g, ∂g, α, ∂α over [`Real`] (`dg[k]` = ∂_k g, `dalpha[k][i]` = ∂_k α_i).
pub(super) struct GeoT<T> {
    pub(super) g: M2<T>,
    pub(super) dg: [M2<T>; 2],
    pub(super) alpha: V2<T>,
    pub(super) dalpha: M2<T>,
}

/// The re parts of x and their ε parts (None when all are zero or T is f64).
fn split<T: Real>(x: V2<T>) -> (V2<f64>, Option<V2<f64>>) {
    let (r, e) = ([x[0].re(), x[1].re()], [x[0].eps(), x[1].eps()]);
    (r, (T::DUAL && e != [0.0; 2]).then_some(e))
}

/// The surface's geometry at x: at x + ε dx with the derivatives along dx from
/// [`Surface::second_derivatives`] (NaN on a surface without them).
pub(super) fn geometry<T: Real>(surface: &dyn Surface, x: V2<T>) -> GeoT<T> {
    let (xr, dx) = split(x);
    let geo = surface.geometry(xr);
    let Some(dx) = dx else {
        return GeoT {
            g: geo.g.map(|r| r.map(T::from)),
            dg: geo.dg.map(|m| m.map(|r| r.map(T::from))),
            alpha: geo.alpha.map(T::from),
            dalpha: geo.dalpha.map(|r| r.map(T::from)),
        };
    };
    let s = surface.second_derivatives(xr);
    GeoT {
        g: std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                T::with(
                    geo.g[i][j],
                    geo.dg[0][i][j] * dx[0] + geo.dg[1][i][j] * dx[1],
                )
            })
        }),
        dg: std::array::from_fn(|k| {
            std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    T::with(
                        geo.dg[k][i][j],
                        s.d2g[k][0][i][j] * dx[0] + s.d2g[k][1][i][j] * dx[1],
                    )
                })
            })
        }),
        alpha: std::array::from_fn(|i| {
            T::with(
                geo.alpha[i],
                geo.dalpha[0][i] * dx[0] + geo.dalpha[1][i] * dx[1],
            )
        }),
        dalpha: std::array::from_fn(|k| {
            std::array::from_fn(|i| {
                T::with(
                    geo.dalpha[k][i],
                    s.d2alpha[k][0][i] * dx[0] + s.d2alpha[k][1][i] * dx[1],
                )
            })
        }),
    }
}

/// The orthonormal frame `e[a][i]` = e_a^i at x, its derivative along dx from the
/// Christoffel symbols and α (module docs): ∂_k e₁ = −Γ_k e₁ + α_k e₂, ∂_k e₂ = −Γ_k e₂ − α_k e₁,
/// (Γ_k)^j_l = Γ^j_kl.
pub(super) fn frame<T: Real>(surface: &dyn Surface, x: V2<T>) -> M2<T> {
    let (xr, dx) = split(x);
    let e = surface.frame(xr);
    let Some(dx) = dx else {
        return e.map(|r| r.map(T::from));
    };
    let geo = surface.geometry(xr);
    let gi = inverse(&geo.g);
    // Γ^j_kl = ½ g^{jm}(∂_k g_ml + ∂_l g_mk − ∂_m g_kl).
    let gamma = |j: usize, k: usize, l: usize| {
        (0..2)
            .map(|m| 0.5 * gi[j][m] * (geo.dg[k][m][l] + geo.dg[l][m][k] - geo.dg[m][k][l]))
            .sum::<f64>()
    };
    let de = |a: usize, j: usize, k: usize| {
        let conn = -(0..2).map(|l| gamma(j, k, l) * e[a][l]).sum::<f64>();
        let turn = if a == 0 {
            geo.alpha[k] * e[1][j]
        } else {
            -geo.alpha[k] * e[0][j]
        };
        conn + turn
    };
    std::array::from_fn(|a| {
        std::array::from_fn(|j| T::with(e[a][j], de(a, j, 0) * dx[0] + de(a, j, 1) * dx[1]))
    })
}

/// φ, ∇φ, ∇²φ = (φ_xx, φ_xy, φ_yy) at x over [`Real`], with their derivatives along dx (the
/// third derivatives from [`Potential::third`]; None without them).
pub(super) fn potential<T: Real>(pot: &Potential, x: V2<T>) -> Option<(T, V2<T>, [T; 3])> {
    let (xr, dx) = split(x);
    let pv = pot.eval(xr);
    let Some(dx) = dx else {
        return Some((T::from(pv.phi), pv.grad.map(T::from), pv.hess.map(T::from)));
    };
    let t = pot.third(xr)?;
    let [hxx, hxy, hyy] = pv.hess;
    Some((
        T::with(pv.phi, pv.grad[0] * dx[0] + pv.grad[1] * dx[1]),
        [
            T::with(pv.grad[0], hxx * dx[0] + hxy * dx[1]),
            T::with(pv.grad[1], hxy * dx[0] + hyy * dx[1]),
        ],
        [
            T::with(hxx, t[0] * dx[0] + t[1] * dx[1]),
            T::with(hxy, t[1] * dx[0] + t[2] * dx[1]),
            T::with(hyy, t[2] * dx[0] + t[3] * dx[1]),
        ],
    ))
}

fn duals(a: &[f64], b: [f64; 3]) -> [Dual; 3] {
    std::array::from_fn(|i| Dual::with(a[i], b[i]))
}

/// D²H(q, p)\[dq, dp\] by the implicit-function theorem (module docs): NaN where the Legendre
/// map is not inverted or the kernel's derivatives are not available.
pub(super) fn gradient_tangent<T: Legendre>(
    t: &T,
    q: &[f64],
    p: &[f64],
    dq: &[f64],
    dp: &[f64],
    dhq: &mut [f64],
    dhp: &mut [f64],
) {
    let ok = (|| {
        let (v, d) = t.solve(q, p)?;
        let chol = d.hess.cholesky()?;
        let qd = duals(q, [dq[0], dq[1], dq[2]]);
        let a = t.derivs_dual(qd, duals(v.as_slice(), [0.0; 3]), None)?;
        let rhs = Vector3::from_fn(|i, _| dp[i] - a.lv[i].b);
        let dv = chol.solve(&rhs);
        let b = t.derivs_dual(qd, duals(v.as_slice(), [dv[0], dv[1], dv[2]]), None)?;
        for i in 0..3 {
            dhp[i] = dv[i];
            dhq[i] = -b.lq[i].b;
        }
        Some(())
    })()
    .is_some();
    if !ok {
        dhq[..3].fill(f64::NAN);
        dhp[..3].fill(f64::NAN);
    }
}

/// dhq += ∂²H/∂θ_m∂q, dhp += ∂²H/∂θ_m∂p: δq̇ = −L_q̇q̇⁻¹ ∂_θL_q̇, δ(∂H/∂q) = −(∂_θL_q + L_qq̇ δq̇).
pub(super) fn gradient_parameter<T: Legendre>(
    t: &T,
    q: &[f64],
    p: &[f64],
    m: usize,
    dhq: &mut [f64],
    dhp: &mut [f64],
) {
    let ok = (|| {
        let (v, d) = t.solve(q, p)?;
        let chol = d.hess.cholesky()?;
        let qd = duals(q, [0.0; 3]);
        let a = t.derivs_dual(qd, duals(v.as_slice(), [0.0; 3]), Some(m))?;
        let dv = -chol.solve(&Vector3::from_fn(|i, _| a.lv[i].b));
        let b = t.derivs_dual(qd, duals(v.as_slice(), [dv[0], dv[1], dv[2]]), Some(m))?;
        for i in 0..3 {
            dhp[i] += dv[i];
            dhq[i] -= b.lq[i].b;
        }
        Some(())
    })()
    .is_some();
    if !ok {
        dhq[..3].fill(f64::NAN);
        dhp[..3].fill(f64::NAN);
    }
}
