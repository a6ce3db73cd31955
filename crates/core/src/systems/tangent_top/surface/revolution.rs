//! Surfaces of revolution about the z axis from a profile (r(s), z(s)) (002 §III.A): metric,
//! frame, connection, the Killing field ∂/∂φ and the embedding, in closed form.

use std::fmt;
use std::sync::Arc;

use super::{
    finite2, normal_and_invertible, Embedding, Geometry, Mat2, SecondGeometry, Shape, Surface,
    Vec2, Vec3, ZERO2,
};
use crate::check;
use crate::error::{Error, Result};

/// A profile function s ↦ (f(s), f′(s), f″(s), f‴(s)) (the third derivative enters only the
/// shape operator's derivative, i.e. the embedded top).
pub type Profile = Arc<dyn Fn(f64) -> [f64; 4] + Send + Sync>;

/// A surface of revolution X(s, φ) = (r(s) cos φ, r(s) sin φ, z(s)) about the z axis, from the
/// profile functions r and z with their first three derivatives, on s_min < s < s_max with
/// r(s) > 0. Coordinates x = (s, φ); with λ = √(r′² + z′²):
/// g = diag(λ², r²), Ê₁ = ∂s/λ, Ê₂ = ∂φ/r.
///
/// **Connection.** θ¹ = λ ds, θ² = r dφ: dθ¹ = 0, dθ² = r′ ds∧dφ = −w∧θ¹, so w = (r′/λ) dφ,
/// α = (0, r′/λ), ∂_s α_φ = z′(r″z′ − r′z″)/λ³, K = z′(r′z″ − r″z′)/(λ⁴ r) (the sphere's profile
/// r = R sin s, z = R cos s gives back [`Sphere`](super::Sphere)). The Killing field ∂/∂φ moves
/// the frame along (ψ = 0): X_φ = (0, 1, 0), momentum p_φ (002 §III.A).
///
/// **Embedding.** n = Ê₁ × Ê₂ = (−z′ cos φ, −z′ sin φ, r′)/λ,
/// h = diag((r′z″ − z′r″)/λ, r z′/λ), so W = e h = diag((r′z″ − z′r″)/λ², z′/λ).
#[derive(Clone)]
pub struct Revolution {
    r: Profile,
    z: Profile,
    range: (f64, f64),
    /// Made by [`Revolution::new`] from the caller's functions.
    user: bool,
}

impl fmt::Debug for Revolution {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Revolution")
            .field("range", &self.range)
            .finish_non_exhaustive()
    }
}

impl Revolution {
    /// The surface of the profile r(s), z(s) (each returning the value and its first three
    /// derivatives) on s_min < s < s_max. Errors: a non-finite or empty range.
    pub fn new(
        r: impl Fn(f64) -> [f64; 4] + Send + Sync + 'static,
        z: impl Fn(f64) -> [f64; 4] + Send + Sync + 'static,
        range: (f64, f64),
    ) -> Result<Self> {
        Ok(Revolution {
            user: true,
            ..Revolution::built_in(r, z, range)?
        })
    }

    /// [`Revolution::new`] for the profiles of lieflow's own surfaces.
    fn built_in(
        r: impl Fn(f64) -> [f64; 4] + Send + Sync + 'static,
        z: impl Fn(f64) -> [f64; 4] + Send + Sync + 'static,
        range: (f64, f64),
    ) -> Result<Self> {
        check::finite_slice("range", &[range.0, range.1])?;
        if range.0 >= range.1 {
            return Err(Error::invalid(
                "range",
                format!("expected s_min < s_max, got ({}, {})", range.0, range.1),
            ));
        }
        Ok(Revolution {
            r: Arc::new(r),
            z: Arc::new(z),
            range,
            user: false,
        })
    }

    /// The sphere of radius R as a surface of revolution: r = R sin s, z = R cos s, 0 < s < π.
    pub fn sphere(radius: f64) -> Result<Self> {
        check::positive("radius", radius)?;
        let rr = radius;
        Revolution::built_in(
            move |s| {
                let (sn, cs) = s.sin_cos();
                [rr * sn, rr * cs, -rr * sn, -rr * cs]
            },
            move |s| {
                let (sn, cs) = s.sin_cos();
                [rr * cs, -rr * sn, -rr * cs, rr * sn]
            },
            (0.0, std::f64::consts::PI),
        )
    }

    /// The torus of radii a > b > 0: r = a + b cos s, z = b sin s, s ∈ (−π, π) (the inner circle
    /// s = ±π is left out of the chart).
    pub fn torus(a: f64, b: f64) -> Result<Self> {
        check::positive("a", a)?;
        check::positive("b", b)?;
        if b >= a {
            return Err(Error::invalid(
                "b",
                format!("a torus needs b < a, got a = {a}, b = {b}"),
            ));
        }
        Revolution::built_in(
            move |s| {
                let (sn, cs) = s.sin_cos();
                [a + b * cs, -b * sn, -b * cs, b * sn]
            },
            move |s| {
                let (sn, cs) = s.sin_cos();
                [b * sn, b * cs, -b * sn, -b * cs]
            },
            (-std::f64::consts::PI, std::f64::consts::PI),
        )
    }

    /// (r, r′, r″, z′, z″, λ) at s.
    fn profile(&self, s: f64) -> (f64, f64, f64, f64, f64, f64) {
        let [r, dr, ddr, _] = (self.r)(s);
        let [_, dz, ddz, _] = (self.z)(s);
        (r, dr, ddr, dz, ddz, (dr * dr + dz * dz).sqrt())
    }
}

impl Surface for Revolution {
    fn name(&self) -> &'static str {
        "Revolution"
    }
    fn calls_out(&self) -> bool {
        self.user
    }
    fn domain(&self) -> &'static str {
        "s_min < s < s_max with r(s) > 0 and a regular profile"
    }
    fn contains(&self, x: Vec2) -> bool {
        if !(finite2(x) && x[0] > self.range.0 && x[0] < self.range.1) {
            return false;
        }
        let (r, dr, ddr, dz, ddz, l) = self.profile(x[0]);
        r > 0.0
            && normal_and_invertible(r)
            && normal_and_invertible(l)
            && [r, dr, ddr, dz, ddz, l].iter().all(|v| v.is_finite())
    }
    fn metric(&self, x: Vec2) -> Mat2 {
        let (r, _, _, _, _, l) = self.profile(x[0]);
        [[l * l, 0.0], [0.0, r * r]]
    }
    fn metric_derivatives(&self, x: Vec2) -> [Mat2; 2] {
        let (r, dr, ddr, dz, ddz, _) = self.profile(x[0]);
        [
            [[2.0 * (dr * ddr + dz * ddz), 0.0], [0.0, 2.0 * r * dr]],
            ZERO2,
        ]
    }
    fn frame(&self, x: Vec2) -> Mat2 {
        let (r, _, _, _, _, l) = self.profile(x[0]);
        [[1.0 / l, 0.0], [0.0, 1.0 / r]]
    }
    fn connection(&self, x: Vec2) -> Vec2 {
        let (_, dr, _, _, _, l) = self.profile(x[0]);
        [0.0, dr / l]
    }
    fn connection_derivatives(&self, x: Vec2) -> Mat2 {
        let (_, dr, ddr, dz, ddz, l) = self.profile(x[0]);
        [[0.0, dz * (ddr * dz - dr * ddz) / (l * l * l)], ZERO2[1]]
    }
    fn geometry(&self, x: Vec2) -> Geometry {
        let (r, dr, ddr, dz, ddz, l) = self.profile(x[0]);
        Geometry {
            g: [[l * l, 0.0], [0.0, r * r]],
            dg: [
                [[2.0 * (dr * ddr + dz * ddz), 0.0], [0.0, 2.0 * r * dr]],
                ZERO2,
            ],
            alpha: [0.0, dr / l],
            dalpha: [[0.0, dz * (ddr * dz - dr * ddz) / (l * l * l)], [0.0, 0.0]],
        }
    }
    fn has_second_derivatives(&self) -> bool {
        true
    }
    /// ∂²_s g₁₁ = 2(r″² + r′r‴ + z″² + z′z‴), ∂²_s g₂₂ = 2(r′² + r r″); ∂_s α₂ = N/λ³ with
    /// N = z′(r″z′ − r′z″), so ∂²_s α₂ = N′/λ³ − 3Nλ′/λ⁴, N′ = r‴z′² + r″z′z″ − r′z″² − r′z′z‴,
    /// λ′ = (r′r″ + z′z″)/λ. (The embedded top's ∂²W would need fourth derivatives of the
    /// profile: not given.)
    fn second_derivatives(&self, x: Vec2) -> SecondGeometry {
        let [r, dr, ddr, dddr] = (self.r)(x[0]);
        let [_, dz, ddz, dddz] = (self.z)(x[0]);
        let l = (dr * dr + dz * dz).sqrt();
        let dl = (dr * ddr + dz * ddz) / l;
        let n = dz * (ddr * dz - dr * ddz);
        let dn = dddr * dz * dz + ddr * dz * ddz - dr * ddz * ddz - dr * dz * dddz;
        let mut s = SecondGeometry::ZERO;
        s.d2g[0][0] = [
            [2.0 * (ddr * ddr + dr * dddr + ddz * ddz + dz * dddz), 0.0],
            [0.0, 2.0 * (dr * dr + r * ddr)],
        ];
        s.d2alpha[0][0][1] = dn / (l * l * l) - 3.0 * n * dl / (l * l * l * l);
        s
    }
    fn curvature(&self, x: Vec2) -> f64 {
        let (r, dr, ddr, dz, ddz, l) = self.profile(x[0]);
        dz * (dr * ddz - ddr * dz) / (l * l * l * l * r)
    }
    fn killing_count(&self) -> usize {
        1
    }
    fn killing_names(&self) -> &'static [&'static str] {
        &["rotation about z"]
    }
    fn killing(&self, k: usize, _x: Vec2) -> Vec3 {
        if k == 0 {
            [0.0, 1.0, 0.0]
        } else {
            [0.0; 3]
        }
    }
    fn killing_is_affine(&self, k: usize) -> bool {
        k == 0
    }
    fn embedding(&self) -> Option<&dyn Embedding> {
        Some(self)
    }
}

impl Embedding for Revolution {
    fn position(&self, x: Vec2) -> [f64; 3] {
        let r = (self.r)(x[0])[0];
        let z = (self.z)(x[0])[0];
        let (sp, cp) = x[1].sin_cos();
        [r * cp, r * sp, z]
    }
    fn normal(&self, x: Vec2) -> [f64; 3] {
        let (_, dr, _, dz, _, l) = self.profile(x[0]);
        let (sp, cp) = x[1].sin_cos();
        [-dz * cp / l, -dz * sp / l, dr / l]
    }
    fn second_fundamental_form(&self, x: Vec2) -> Mat2 {
        let (r, dr, ddr, dz, ddz, l) = self.profile(x[0]);
        [[(dr * ddz - dz * ddr) / l, 0.0], [0.0, r * dz / l]]
    }
    fn tangent(&self, x: Vec2, v: Vec2) -> [f64; 3] {
        let (r, dr, _, dz, _, _) = self.profile(x[0]);
        let (sp, cp) = x[1].sin_cos();
        [
            dr * cp * v[0] - r * sp * v[1],
            dr * sp * v[0] + r * cp * v[1],
            dz * v[0],
        ]
    }
    /// W₁₁ = k/λ², W₂₂ = z′/λ with k = r′z″ − z′r″, λ² = r′² + z′²; ∂_s by the quotient rule
    /// (k′ = r′z‴ − z′r‴, (λ²)′ = 2(r′r″ + z′z″)).
    fn shape(&self, x: Vec2) -> Shape {
        let [_, dr, ddr, dddr] = (self.r)(x[0]);
        let [_, dz, ddz, dddz] = (self.z)(x[0]);
        let l2 = dr * dr + dz * dz;
        let l = l2.sqrt();
        let dl2 = 2.0 * (dr * ddr + dz * ddz);
        let k = dr * ddz - dz * ddr;
        let dk = dr * dddz - dz * dddr;
        Shape {
            w: [[k / l2, 0.0], [0.0, dz / l]],
            dw: [
                [
                    [dk / l2 - k * dl2 / (l2 * l2), 0.0],
                    [0.0, ddz / l - 0.5 * dz * dl2 / (l2 * l)],
                ],
                ZERO2,
            ],
        }
    }
}
