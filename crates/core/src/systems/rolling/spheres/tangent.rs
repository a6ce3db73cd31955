//! The tangent lift (issue 26): the derivatives of the momentum chart, of the generator ξ(z), of
//! the action and of dexp on each so(3) factor, so that the Lie-group methods on
//! [`Tangent<RollingSpheres>`] carry the exact derivative of their own step.
//!
//! **Directions** (internal frame): (η₁, η₂, δu, δP₁, δP₂) with δz_k = z_kη̂_k (left-trivialised,
//! [`crate::integrate::space::Block::SO3`]) and δu ambient; in the user frame (η₁, η₂, δu, δΩ₁,
//! δΩ₂). With ζ_k = z_kη_k (the same variation as a spatial vector, δz_k = ζ̂_kz_k), the
//! configuration's quantities vary by δε_k = ζ_k × ε_k, δs₁ = α₁(δu − δε₁), δs₂ = α₂(δu + δε₂),
//! δ(K_k^s a) = ζ_k × K_k^s a − K_k^s(ζ_k × a) (module docs of [`super`], "Momentum form").
//!
//! **Chart** (P = Mω, P_k = K_k^sω_k + s_k × w, w = ω₁ × s₁ + ω₂ × s₂, 003 §2 re-derived):
//! δP = M δω + DM\[δz\]ω with (DM\[δz\]ω)_k = δK_k^s ω_k + δs_k × w + s_k × (ω₁ × δs₁ + ω₂ × δs₂),
//! and δω_k = ζ_k × ω_k + z_kδΩ_k (ω_k = z_kΩ_k); back, δω = M⁻¹(δP − DM\[δz\]ω) and
//! δΩ_k = z_kᵀ(δω_k − ζ_k × ω_k). The chart depends on the state, so the lift converts the
//! directions at the base state ([`Problem::tangent_to_internal_at`]).
//!
//! **Generator** ξ = (ω₁, ω₂, b, ṡ₁ × w, ṡ₂ × w), b = α₁ω₁ + α₂ω₂, u̇ = b × u (10),
//! ṡ₁ = α₁(u̇ − ω₁ × ε₁), ṡ₂ = α₂(u̇ + ω₂ × ε₂): its derivative by the product rule from δω
//! (above), δu̇ = δb × u + b × δu, δṡ_k, δw. Since ṡ₁ + ṡ₂ = w identically, the derivatives of the
//! two rates cancel as the rates do, and the lifted run keeps the gradient of J = P₁ + P₂.
//!
//! **Action** z_k ↦ exp(ξ̂_k)z_k, u ↦ exp(ξ̂_u)u, P ↦ P + ξ_P: with w_k = J_l(ξ_k)δξ_k
//! (δexp(ξ̂) = ŵ exp(ξ̂)), η_k' = η_k + z_k'ᵀw_k (z_k'ᵀδz_k' = (z_k'ᵀw_k)^ + η̂_k),
//! δu' = exp(ξ̂_u)δu + w_u × u', δP' = δP + δξ_P; dexp_u w = J_l(u)w on each so(3) factor, its
//! derivative [`so3::jacobian_left_derivative`].
//!
//! The field lift (RK4) is not offered: the state has SO(3) blocks, on which a Runge–Kutta
//! step's derivative is one in ambient coordinates ([`crate::integrate::tangent`]). Nor are
//! parameters: the chart P = M(θ)ω itself depends on the bodies' constants, which the lift's
//! state-to-state conversions do not carry.
//!
//! [`Problem::tangent_to_internal_at`]: crate::integrate::Problem::tangent_to_internal_at

use std::sync::Arc;

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use super::{local, Kin, RollingSpheres};
use crate::integrate::methods::{Composition, LieMidpoint, Rkmk4};
use crate::integrate::tangent::{GroupFieldTangent, Tangent, TangentSystem};
use crate::integrate::{Catalog, Entry};
use crate::lie::so3;

/// A configuration (z₁, z₂, u) and a direction of it as spatial vectors (ζ₁, ζ₂, δu).
struct Config {
    z: [Matrix3<f64>; 2],
    u: Vector3<f64>,
    zeta: [Vector3<f64>; 2],
    du: Vector3<f64>,
}

fn v3(s: &[f64]) -> Vector3<f64> {
    Vector3::from_column_slice(&s[..3])
}

impl Config {
    /// From a flat state (27 values) and a direction (15 values, η_k body-side).
    fn new(z: &[f64], dz: &[f64]) -> Config {
        let l = local(z);
        Config {
            zeta: [l.z[0] * v3(&dz[0..3]), l.z[1] * v3(&dz[3..6])],
            z: l.z,
            u: l.u,
            du: v3(&dz[6..9]),
        }
    }
}

/// The variations of the lever arms and of the rolling direction's quantities.
struct DKin {
    /// δε_k = ζ_k × ε_k.
    eps: [Vector3<f64>; 2],
    /// δs₁ = α₁(δu − δε₁), δs₂ = α₂(δu + δε₂).
    s: [Vector3<f64>; 2],
}

impl RollingSpheres {
    fn dkin(&self, c: &Config, k: &Kin) -> DKin {
        let eps = [c.zeta[0].cross(&k.eps[0]), c.zeta[1].cross(&k.eps[1])];
        let s = [
            (c.du - eps[0]) * self.alpha[0],
            (c.du + eps[1]) * self.alpha[1],
        ];
        DKin { eps, s }
    }

    /// K_k^s = z_kK_kz_kᵀ.
    fn spatial_inertia(&self, z: &[Matrix3<f64>; 2], i: usize) -> Matrix3<f64> {
        z[i] * self.k[i] * z[i].transpose()
    }

    /// DM\[δz\]ω at fixed ω (module docs).
    fn dm_omega(&self, c: &Config, k: &Kin, dk: &DKin, w: &[Vector3<f64>; 2]) -> Vector6<f64> {
        let ww = w[0].cross(&k.s[0]) + w[1].cross(&k.s[1]);
        let dw = w[0].cross(&dk.s[0]) + w[1].cross(&dk.s[1]);
        let mut out = Vector6::zeros();
        for (i, wi) in w.iter().enumerate() {
            let ks = self.spatial_inertia(&c.z, i);
            let dks = c.zeta[i].cross(&(ks * wi)) - ks * c.zeta[i].cross(wi);
            let d = dks + dk.s[i].cross(&ww) + k.s[i].cross(&dw);
            out.fixed_rows_mut::<3>(3 * i).copy_from(&d);
        }
        out
    }

    /// M and its configuration's kinematics (ω = 0: M depends on the configuration only).
    fn config_mass(&self, c: &Config) -> (Kin, Matrix6<f64>) {
        let k = self.kin_spatial(&c.z, &c.u, [Vector3::zeros(); 2]);
        let m = self.mass_matrix(&c.z, &k);
        (k, m)
    }

    /// δω = M⁻¹(δP − DM\[δz\]ω) at an internal state with ω = M⁻¹P (NaN where M is not positive
    /// definite, as the generator).
    fn omega_tangent(
        &self,
        c: &Config,
        w: &[Vector3<f64>; 2],
        dp: &[f64],
    ) -> (Kin, [Vector3<f64>; 2]) {
        let (k, m) = self.config_mass(c);
        let dk = self.dkin(c, &k);
        let rhs = Vector6::from_column_slice(dp) - self.dm_omega(c, &k, &dk, w);
        let x = match m.cholesky() {
            Some(ch) => ch.solve(&rhs),
            None => Vector6::repeat(f64::NAN),
        };
        (
            k,
            [x.fixed_rows::<3>(0).into(), x.fixed_rows::<3>(3).into()],
        )
    }
}

impl RollingSpheres {
    /// The chart's tangent map at the user state z: (η, δu, δΩ) ↦ (η, δu, δP) (module docs).
    pub(super) fn chart_tangent(&self, z: &[f64], dz: &mut [f64]) {
        let l = local(z);
        let c = Config::new(z, dz);
        let w = [l.z[0] * l.omega[0], l.z[1] * l.omega[1]];
        let (k, m) = self.config_mass(&c);
        let dk = self.dkin(&c, &k);
        let mut dw = Vector6::zeros();
        for i in 0..2 {
            let d = c.zeta[i].cross(&w[i]) + l.z[i] * v3(&dz[9 + 3 * i..]);
            dw.fixed_rows_mut::<3>(3 * i).copy_from(&d);
        }
        let dp = m * dw + self.dm_omega(&c, &k, &dk, &w);
        dz[9..15].copy_from_slice(dp.as_slice());
    }

    /// The inverse of [`RollingSpheres::chart_tangent`] at the internal state z.
    pub(super) fn chart_tangent_inverse(&self, z: &[f64], dz: &mut [f64]) {
        let l = local(z);
        let c = Config::new(z, dz);
        let w = self.omegas_from_momenta(&l.z, &l.u, &z[21..27]);
        let (_, dw) = self.omega_tangent(&c, &w, &dz[9..15]);
        for i in 0..2 {
            let d = l.z[i].transpose() * (dw[i] - c.zeta[i].cross(&w[i]));
            dz[9 + 3 * i..12 + 3 * i].copy_from_slice(d.as_slice());
        }
    }
}

/// The derivatives of the generator, the action and dexp (module docs), internal frame.
impl GroupFieldTangent for RollingSpheres {
    fn generator_tangent(&self, z: &[f64], dz: &[f64], dxi: &mut [f64], _s: &mut ()) {
        let l = local(z);
        let c = Config::new(z, dz);
        let w = self.omegas_from_momenta(&l.z, &l.u, &z[21..27]);
        let (_, dw) = self.omega_tangent(&c, &w, &dz[9..15]);
        let k = self.kin_spatial(&l.z, &l.u, w);
        let dk = self.dkin(&c, &k);
        let [a1, a2] = self.alpha;
        let b = w[0] * a1 + w[1] * a2;
        let db = dw[0] * a1 + dw[1] * a2;
        let dudot = db.cross(&l.u) + b.cross(&c.du);
        let sd = self.sdot(&k);
        let dsd = [
            (dudot - dw[0].cross(&k.eps[0]) - w[0].cross(&dk.eps[0])) * a1,
            (dudot + dw[1].cross(&k.eps[1]) + w[1].cross(&dk.eps[1])) * a2,
        ];
        let ww = self.w(&k);
        let dww = dw[0].cross(&k.s[0])
            + w[0].cross(&dk.s[0])
            + dw[1].cross(&k.s[1])
            + w[1].cross(&dk.s[1]);
        dxi[0..3].copy_from_slice(dw[0].as_slice());
        dxi[3..6].copy_from_slice(dw[1].as_slice());
        dxi[6..9].copy_from_slice(db.as_slice());
        for i in 0..2 {
            let d = dsd[i].cross(&ww) + sd[i].cross(&dww);
            dxi[9 + 3 * i..12 + 3 * i].copy_from_slice(d.as_slice());
        }
    }

    fn act_tangent(&self, u: &[f64], du: &[f64], y: &[f64], dz: &mut [f64], _s: &mut ()) {
        let l = local(y);
        for i in 0..3 {
            let r = 3 * i..3 * i + 3;
            let (g, jl) = so3::exp_and_jacobian_left(&v3(&u[r.clone()]));
            let w = jl * v3(&du[r.clone()]);
            let d = if i < 2 {
                v3(&dz[r.clone()]) + l.z[i].transpose() * w
            } else {
                g * v3(&dz[r.clone()]) + w.cross(&l.u)
            };
            dz[r].copy_from_slice(d.as_slice());
        }
        for (d, x) in dz[9..15].iter_mut().zip(&du[9..15]) {
            *d += x;
        }
    }

    fn dexp_tangent(&self, u: &[f64], du: &[f64], w: &[f64], out: &mut [f64], _s: &mut ()) {
        for i in 0..3 {
            let r = 3 * i..3 * i + 3;
            let q = so3::jacobian_left_derivative(&v3(&u[r.clone()]), &v3(&du[r.clone()]));
            out[r.clone()].copy_from_slice((q * v3(&w[r])).as_slice());
        }
        out[9..15].fill(0.0);
    }
}

/// `midpoint`, `midpoint4`, `rkmk4` on the lift (not `rk4`: module docs).
impl Catalog for Tangent<RollingSpheres> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("midpoint", LieMidpoint::new),
            Entry::new("midpoint4", || LieMidpoint(Composition::suzuki4())),
            Entry::new("rkmk4", || Rkmk4),
        ]
    }
}

impl RollingSpheres {
    /// The tangent lift as a trait object (`Catalog::tangent`).
    pub(super) fn lift(&self) -> Arc<dyn TangentSystem> {
        Tangent::group_field(self.clone()).into_system()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::problem::{GroupField, VectorField};
    use crate::integrate::Problem;

    fn spheres() -> RollingSpheres {
        RollingSpheres::new(
            0.7,
            1.3,
            [0.1, -0.2, 0.15],
            [-0.3, 0.2, 0.4],
            2.0,
            3.5,
            [[0.40, 0.05, -0.02], [0.05, 0.30, 0.04], [-0.02, 0.04, 0.25]],
            [[0.90, -0.10, 0.05], [-0.10, 1.10, 0.08], [0.05, 0.08, 0.70]],
        )
        .unwrap()
    }

    fn rows(m: &Matrix3<f64>) -> Vec<f64> {
        (0..9).map(|k| m[(k / 3, k % 3)]).collect()
    }

    /// A user state and a direction (η, δu, δΩ).
    fn state() -> (Vec<f64>, Vec<f64>) {
        let z1 = so3::exp_unchecked(&Vector3::new(0.3, -0.2, 0.5));
        let z2 = so3::exp_unchecked(&Vector3::new(-0.4, 0.1, 0.2));
        let z = [
            rows(&z1),
            rows(&z2),
            vec![0.6, 0.0, 0.8, 0.5, -0.3, 0.8, -0.2, 0.4, 0.1],
        ]
        .concat();
        let dz = vec![
            0.3, -0.7, 0.2, 0.5, 0.1, -0.4, 0.2, 0.9, -0.3, 0.6, -0.2, 0.35, -0.8, 0.4, 0.15,
        ];
        (z, dz)
    }

    /// The state moved along the direction by s: z_k exp(sη̂_k), u + sδu, the rest + s·δ.
    fn moved(z: &[f64], dz: &[f64], s: f64) -> Vec<f64> {
        let mut out = z.to_vec();
        for i in 0..2 {
            let zi = Matrix3::from_row_slice(&z[9 * i..9 * i + 9]);
            let m = zi * so3::exp_unchecked(&(v3(&dz[3 * i..]) * s));
            out[9 * i..9 * i + 9].copy_from_slice(&rows(&m));
        }
        for j in 18..27 {
            out[j] += s * dz[j - 12];
        }
        out
    }

    /// A direction of the end state from central differences: (z_kᵀδz_k)^∨, the rest flat.
    fn read(p: &[f64], q: &[f64], h: f64) -> Vec<f64> {
        let mut out = vec![0.0; 15];
        for i in 0..2 {
            let a = Matrix3::from_row_slice(&p[9 * i..9 * i + 9]);
            let b = Matrix3::from_row_slice(&q[9 * i..9 * i + 9]);
            let x = so3::vee_unchecked(&((a + b).transpose() * (a - b) / (4.0 * h)));
            out[3 * i..3 * i + 3].copy_from_slice(x.as_slice());
        }
        for j in 18..27 {
            out[j - 12] = (p[j] - q[j]) / (2.0 * h);
        }
        out
    }

    fn worst(a: &[f64], b: &[f64]) -> f64 {
        let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale
    }

    /// The chart's tangent map and its inverse against central differences of the chart.
    #[test]
    fn chart_tangent_is_the_charts_derivative() {
        let s = spheres();
        let (z, dz) = state();
        let h = 1e-6;
        let chart = |s_: f64| {
            let mut v = moved(&z, &dz, s_);
            s.to_internal(&mut v);
            v
        };
        let fd = read(&chart(h), &chart(-h), h);
        let mut d = dz.clone();
        s.chart_tangent(&z, &mut d);
        let err = worst(&d, &fd);
        eprintln!("chart tangent vs differences {err:.1e}");
        assert!(err < 1e-9, "chart: {err:e}");
        let mut zi = z.clone();
        s.to_internal(&mut zi);
        s.chart_tangent_inverse(&zi, &mut d);
        let err = worst(&d, &dz);
        assert!(err < 1e-14, "round trip: {err:e}");
    }

    /// ξ′(z)δz against central differences of the generator (internal states).
    #[test]
    fn generator_tangent_is_the_generators_derivative() {
        let s = spheres();
        let (z, dz) = state();
        let mut zi = z.clone();
        s.to_internal(&mut zi);
        let gen = |s_: f64| {
            let v = moved(&zi, &dz, s_);
            let mut xi = vec![0.0; 15];
            s.generator(&v, &mut xi, &mut ());
            xi
        };
        let h = 1e-6;
        let (p, q) = (gen(h), gen(-h));
        let fd: Vec<f64> = p.iter().zip(&q).map(|(a, b)| (a - b) / (2.0 * h)).collect();
        let mut d = vec![0.0; 15];
        s.generator_tangent(&zi, &dz, &mut d, &mut ());
        let err = worst(&d, &fd);
        eprintln!("generator tangent vs differences {err:.1e}");
        assert!(err < 1e-9, "generator: {err:e}");
        // The generator is the field: ξ·z = f(z) (a check of the layout used above).
        let mut f = vec![0.0; 27];
        s.field(&zi, &mut f);
        assert!((f[21] - p[9]).abs() < 1e-5);
    }

    /// The action's derivative along (δξ, δz) and dexp's derivative against central differences.
    #[test]
    fn act_and_dexp_tangents_are_their_derivatives() {
        let s = spheres();
        let (z, dz) = state();
        let mut zi = z.clone();
        s.to_internal(&mut zi);
        let xi: Vec<f64> = (0..15).map(|k| 0.4 * ((k as f64) * 0.7).sin()).collect();
        let dxi: Vec<f64> = (0..15).map(|k| 0.5 * ((k as f64) * 1.3).cos()).collect();
        let h = 1e-6;
        let act = |s_: f64| {
            let mut v = moved(&zi, &dz, s_);
            let x: Vec<f64> = xi.iter().zip(&dxi).map(|(a, b)| a + s_ * b).collect();
            s.act(&x, &mut v, &mut ());
            v
        };
        let fd = read(&act(h), &act(-h), h);
        let mut y = zi.clone();
        s.act(&xi, &mut y, &mut ());
        let mut d = dz.clone();
        s.act_tangent(&xi, &dxi, &y, &mut d, &mut ());
        let err = worst(&d, &fd);
        eprintln!("act tangent vs differences {err:.1e}");
        assert!(err < 1e-9, "act: {err:e}");
        // D_u(dexp_u w)[du] with dexp_u w = dexp_inv⁻¹: differences of the inverse.
        let w: Vec<f64> = (0..15).map(|k| 0.3 - 0.05 * k as f64).collect();
        let dexp = |s_: f64| {
            let x: Vec<f64> = xi.iter().zip(&dxi).map(|(a, b)| a + s_ * b).collect();
            let mut out = vec![0.0; 15];
            for i in 0..3 {
                let r = 3 * i..3 * i + 3;
                let j = so3::jacobian_left_unchecked(&v3(&x[r.clone()]));
                out[r.clone()].copy_from_slice((j * v3(&w[r])).as_slice());
            }
            out[9..].copy_from_slice(&w[9..]);
            out
        };
        let (p, q) = (dexp(h), dexp(-h));
        let fd: Vec<f64> = p.iter().zip(&q).map(|(a, b)| (a - b) / (2.0 * h)).collect();
        let mut d = vec![0.0; 15];
        s.dexp_tangent(&xi, &dxi, &w, &mut d, &mut ());
        let err = worst(&d, &fd);
        eprintln!("dexp tangent vs differences {err:.1e}");
        assert!(err < 1e-9, "dexp: {err:e}");
    }
}
