//! The tangent lift (issue 26): the derivatives of the momentum chart, of the generator ξ(z), of
//! the action and of dexp on each so(3) factor, so that the Lie-group methods on
//! [`Tangent<RollingSpheres>`] carry the exact derivative of their own step.
//!
//! **Directions** (internal frame): (η₁, η₂, δu, δP₁, δP₂) with δz_k = z_kη̂_k (left-trivialised,
//! [`crate::integrate::space::Block::SO3`]) and δu ambient; in the user frame (η₁, η₂, δu, δΩ₁,
//! δΩ₂). The `rk4` lift's are ambient, (δz₁, δz₂, δu, δP₁, δP₂) with δz_k any 3×3 matrix. Every
//! derivative below is that of the code's map of the flat values along δz_k (a left-trivialised
//! direction being δz_k = z_kη̂_k): the configuration's quantities vary by δε_k = δz_ke_k,
//! δs₁ = α₁(δu − δε₁), δs₂ = α₂(δu + δε₂), δK_k^s = δz_kK_kz_kᵀ + z_kK_kδz_kᵀ (module docs of
//! [`super`], "Momentum form").
//!
//! **Chart** (P = Mω, P_k = K_k^sω_k + s_k × w, w = ω₁ × s₁ + ω₂ × s₂, 003 §2 re-derived):
//! δP = M δω + DM\[δz\]ω with (DM\[δz\]ω)_k = δK_k^s ω_k + δs_k × w + s_k × (ω₁ × δs₁ + ω₂ × δs₂),
//! and δω_k = δz_kΩ_k + z_kδΩ_k (ω_k = z_kΩ_k); back (Ω_k = z_kᵀω_k), δω = M⁻¹(δP − DM\[δz\]ω)
//! and δΩ_k = δz_kᵀω_k + z_kᵀδω_k. The chart depends on the state, so the lift converts the
//! directions at the base state ([`Problem::tangent_to_internal_at`],
//! [`Problem::ambient_to_internal_at`]).
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
//! **Field** (`rk4`, ambient directions): δż_k = (δω_k)^z_k + ω̂_kδz_k, δu̇ as above, δṖ_k the
//! rates' derivative, from the same δω and δṡ_k as the generator's.
//!
//! No parameters: the chart P = M(θ)ω itself depends on the bodies' constants, which the lift's
//! state-to-state conversions do not carry.
//!
//! [`Problem::tangent_to_internal_at`]: crate::integrate::Problem::tangent_to_internal_at
//! [`Problem::ambient_to_internal_at`]: crate::integrate::Problem::ambient_to_internal_at

use std::sync::Arc;

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use super::{local, put_rows, Kin, RollingSpheres};
use crate::integrate::methods::{Composition, LieMidpoint, Rk4, Rkmk4};
use crate::integrate::tangent::{GroupFieldTangent, Tangent, TangentSystem, VectorFieldTangent};
use crate::integrate::{Catalog, Entry};
use crate::lie::so3;

/// A configuration (z₁, z₂, u) and a variation of it (δz₁, δz₂, δu).
struct Config {
    z: [Matrix3<f64>; 2],
    u: Vector3<f64>,
    dz: [Matrix3<f64>; 2],
    du: Vector3<f64>,
}

fn v3(s: &[f64]) -> Vector3<f64> {
    Vector3::from_column_slice(&s[..3])
}

impl Config {
    /// From a flat state (27 values) and a direction, left-trivialised (15 values,
    /// δz_k = z_kη̂_k) or `ambient` (27), with the offset of the direction's velocity (user
    /// frame) or momentum (internal) part.
    fn new(z: &[f64], dz: &[f64], ambient: bool) -> (Config, usize) {
        let l = local(z);
        let (dz, du, rest) = match ambient {
            true => (
                [
                    Matrix3::from_row_slice(&dz[0..9]),
                    Matrix3::from_row_slice(&dz[9..18]),
                ],
                v3(&dz[18..21]),
                21,
            ),
            false => (
                [
                    l.z[0] * so3::hat(&v3(&dz[0..3])),
                    l.z[1] * so3::hat(&v3(&dz[3..6])),
                ],
                v3(&dz[6..9]),
                9,
            ),
        };
        let c = Config {
            z: l.z,
            u: l.u,
            dz,
            du,
        };
        (c, rest)
    }
}

/// The variations of the lever arms and of the rolling direction's quantities.
struct DKin {
    /// δε_k = δz_ke_k.
    eps: [Vector3<f64>; 2],
    /// δs₁ = α₁(δu − δε₁), δs₂ = α₂(δu + δε₂).
    s: [Vector3<f64>; 2],
}

/// The derivative of the field's parts (ξ of the group field, the flat field's rates) along a
/// variation: ω and δω, δb (b = α₁ω₁ + α₂ω₂), δu̇ and the momentum rates' δ(ṡ_k × w).
struct RatesTangent {
    w: [Vector3<f64>; 2],
    dw: [Vector3<f64>; 2],
    db: Vector3<f64>,
    dudot: Vector3<f64>,
    drates: [Vector3<f64>; 2],
}

impl RollingSpheres {
    fn dkin(&self, c: &Config) -> DKin {
        let eps = [c.dz[0] * self.e[0], c.dz[1] * self.e[1]];
        let s = [
            (c.du - eps[0]) * self.alpha[0],
            (c.du + eps[1]) * self.alpha[1],
        ];
        DKin { eps, s }
    }

    /// DM\[δz\]ω at fixed ω (module docs).
    fn dm_omega(&self, c: &Config, k: &Kin, dk: &DKin, w: &[Vector3<f64>; 2]) -> Vector6<f64> {
        let ww = w[0].cross(&k.s[0]) + w[1].cross(&k.s[1]);
        let dw = w[0].cross(&dk.s[0]) + w[1].cross(&dk.s[1]);
        let mut out = Vector6::zeros();
        for (i, wi) in w.iter().enumerate() {
            let kz = self.k[i] * c.z[i].transpose();
            let dks = c.dz[i] * kz + kz.transpose() * c.dz[i].transpose();
            let d = dks * wi + dk.s[i].cross(&ww) + k.s[i].cross(&dw);
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
    fn omega_tangent(&self, c: &Config, w: &[Vector3<f64>; 2], dp: &[f64]) -> [Vector3<f64>; 2] {
        let (k, m) = self.config_mass(c);
        let dk = self.dkin(c);
        let rhs = Vector6::from_column_slice(dp) - self.dm_omega(c, &k, &dk, w);
        let x = match m.cholesky() {
            Some(ch) => ch.solve(&rhs),
            None => Vector6::repeat(f64::NAN),
        };
        [x.fixed_rows::<3>(0).into(), x.fixed_rows::<3>(3).into()]
    }

    /// The derivative of the field's parts at the internal state z along the variation c and
    /// the momenta's δP (module docs, "Generator").
    fn rates_tangent(&self, z: &[f64], c: &Config, dp: &[f64]) -> RatesTangent {
        let l = local(z);
        let w = self.omegas_from_momenta(&l.z, &l.u, &z[21..27]);
        let dw = self.omega_tangent(c, &w, dp);
        let k = self.kin_spatial(&l.z, &l.u, w);
        let dk = self.dkin(c);
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
        let drates = [0, 1].map(|i| dsd[i].cross(&ww) + sd[i].cross(&dww));
        RatesTangent {
            w,
            dw,
            db,
            dudot,
            drates,
        }
    }
}

impl RollingSpheres {
    /// The chart's tangent map at the user state z: (·, δΩ) ↦ (·, δP) for a left-trivialised
    /// or `ambient` direction (module docs).
    pub(super) fn chart_tangent(&self, z: &[f64], dz: &mut [f64], ambient: bool) {
        let l = local(z);
        let (c, at) = Config::new(z, dz, ambient);
        let w = [l.z[0] * l.omega[0], l.z[1] * l.omega[1]];
        let (k, m) = self.config_mass(&c);
        let dk = self.dkin(&c);
        let mut dw = Vector6::zeros();
        for i in 0..2 {
            let d = c.dz[i] * l.omega[i] + l.z[i] * v3(&dz[at + 3 * i..]);
            dw.fixed_rows_mut::<3>(3 * i).copy_from(&d);
        }
        let dp = m * dw + self.dm_omega(&c, &k, &dk, &w);
        dz[at..at + 6].copy_from_slice(dp.as_slice());
    }

    /// The derivative of the chart's inverse at the internal state z (off SO(3) too):
    /// (·, δP) ↦ (·, δΩ), the inverse of [`RollingSpheres::chart_tangent`] on SO(3).
    pub(super) fn chart_tangent_inverse(&self, z: &[f64], dz: &mut [f64], ambient: bool) {
        let l = local(z);
        let (c, at) = Config::new(z, dz, ambient);
        let w = self.omegas_from_momenta(&l.z, &l.u, &z[21..27]);
        let dw = self.omega_tangent(&c, &w, &dz[at..at + 6]);
        for i in 0..2 {
            let d = c.dz[i].transpose() * w[i] + l.z[i].transpose() * dw[i];
            dz[at + 3 * i..at + 3 * i + 3].copy_from_slice(d.as_slice());
        }
    }
}

/// The derivative of the flat field of `rk4` along an ambient direction (module docs, "Field"),
/// internal frame.
impl VectorFieldTangent for RollingSpheres {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        let (c, at) = Config::new(z, dz, true);
        let t = self.rates_tangent(z, &c, &dz[at..at + 6]);
        for i in 0..2 {
            let d = so3::hat(&t.dw[i]) * c.z[i] + so3::hat(&t.w[i]) * c.dz[i];
            put_rows(&d, &mut out[9 * i..9 * i + 9]);
        }
        out[18..21].copy_from_slice(t.dudot.as_slice());
        out[21..24].copy_from_slice(t.drates[0].as_slice());
        out[24..27].copy_from_slice(t.drates[1].as_slice());
    }
}

/// The derivatives of the generator, the action and dexp (module docs), internal frame.
impl GroupFieldTangent for RollingSpheres {
    fn generator_tangent(&self, z: &[f64], dz: &[f64], dxi: &mut [f64], _s: &mut ()) {
        let (c, at) = Config::new(z, dz, false);
        let t = self.rates_tangent(z, &c, &dz[at..at + 6]);
        dxi[0..3].copy_from_slice(t.dw[0].as_slice());
        dxi[3..6].copy_from_slice(t.dw[1].as_slice());
        dxi[6..9].copy_from_slice(t.db.as_slice());
        dxi[9..12].copy_from_slice(t.drates[0].as_slice());
        dxi[12..15].copy_from_slice(t.drates[1].as_slice());
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

/// `midpoint`, `midpoint4`, `rkmk4` on the group-field lift, `rk4` on the field lift (ambient
/// directions).
impl Catalog for Tangent<RollingSpheres> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("midpoint", LieMidpoint::new),
            Entry::new("midpoint4", || LieMidpoint(Composition::suzuki4())),
            Entry::new("rkmk4", || Rkmk4),
        ]
    }

    fn catalog(&self) -> Vec<Entry<Self>> {
        match self.ambient() {
            true => vec![Entry::new("rk4", || Rk4)],
            false => Self::kind_catalog(),
        }
    }
}

impl RollingSpheres {
    /// The tangent lift as a trait object (`Catalog::tangent`).
    pub(super) fn lift(&self) -> Arc<dyn TangentSystem> {
        Tangent::group_field(self.clone()).into_system()
    }

    /// The lift for runs of `method` (`Catalog::tangent_for`).
    pub(super) fn lift_for(&self, method: &str) -> Option<Arc<dyn TangentSystem>> {
        Tangent::routed(self, method, || Some(self.lift()))
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
        s.chart_tangent(&z, &mut d, false);
        let err = worst(&d, &fd);
        eprintln!("chart tangent vs differences {err:.1e}");
        assert!(err < 1e-9, "chart: {err:e}");
        let mut zi = z.clone();
        s.to_internal(&mut zi);
        s.chart_tangent_inverse(&zi, &mut d, false);
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

    /// Along an ambient direction (δz_k any 3×3 matrix) at a state off SO(3) and S² (where a
    /// Runge–Kutta stage evaluates them): the flat field's derivative and the chart's (both
    /// ways) against central differences of the field, `to_internal` and `to_user`.
    #[test]
    fn ambient_field_and_chart_tangents_are_their_derivatives() {
        let s = spheres();
        let (z, _) = state();
        let off = |v: &[f64]| -> Vec<f64> {
            v.iter()
                .enumerate()
                .map(|(k, x)| x + 1e-3 * (0.9 * k as f64).sin())
                .collect()
        };
        let dz: Vec<f64> = (0..27).map(|k| 0.5 * (1.7 * k as f64).cos()).collect();
        let moved =
            |v: &[f64], t: f64| -> Vec<f64> { v.iter().zip(&dz).map(|(a, b)| a + t * b).collect() };
        let h = 1e-6;
        let quotient = |f: &dyn Fn(&[f64]) -> Vec<f64>, v: &[f64]| -> Vec<f64> {
            let (p, q) = (f(&moved(v, h)), f(&moved(v, -h)));
            p.iter().zip(&q).map(|(a, b)| (a - b) / (2.0 * h)).collect()
        };
        let user = off(&z);
        let mut internal = z.clone();
        s.to_internal(&mut internal);
        let internal = off(&internal);
        let field = |v: &[f64]| {
            let mut f = vec![0.0; 27];
            s.field(v, &mut f);
            f
        };
        let mut d = vec![0.0; 27];
        s.field_tangent(&internal, &dz, &mut d);
        let err = worst(&d, &quotient(&field, &internal));
        eprintln!("ambient field tangent vs differences {err:.1e}");
        assert!(err < 1e-9, "field: {err:e}");
        for (inverse, at) in [(false, &user), (true, &internal)] {
            let chart = |v: &[f64]| {
                let mut w = v.to_vec();
                match inverse {
                    false => s.to_internal(&mut w),
                    true => s.to_user(&mut w),
                }
                w
            };
            let mut d = dz.clone();
            match inverse {
                false => s.ambient_to_internal_at(at, &mut d),
                true => s.ambient_to_user_at(at, &mut d),
            }
            let err = worst(&d, &quotient(&chart, at));
            eprintln!("ambient chart tangent (inverse: {inverse}) vs differences {err:.1e}");
            assert!(err < 1e-9, "chart (inverse: {inverse}): {err:e}");
        }
    }
}
