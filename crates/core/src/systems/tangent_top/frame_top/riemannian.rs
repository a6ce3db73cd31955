//! The tangent Euler top on a Riemannian 3-manifold given in a chart with an orthonormal frame
//! field ([`Riemannian`]): 002 §V for a general metric, derived again.
//!
//! # Minimal coupling
//! With the body frame F = ÊR (R ∈ SO(3) relative to the frame field) the angular velocity
//! relative to parallel transport is ω = ω_R + RᵀCẋ (ω_R = (RᵀṘ)^∨, C the connection matrix of the
//! frame, [`super::super::riemannian`]), so
//!
//! L = ½ m ẋᵀg ẋ + ½ (ω_R + RᵀCẋ)·𝕀(ω_R + RᵀCẋ).
//!
//! Its momenta are Π = 𝕀ω (body, conjugate to ω_R) and p = m g ẋ + Cᵀσ with the spatial spin
//! σ = RΠ, and H = K + E with
//!
//! K = (p − Cᵀσ)ᵀg⁻¹(p − Cᵀσ)/2m = ½ m uᵀg u (u = ẋ),  E = ½ Π·𝕀⁻¹Π,
//!
//! on T*ℝ³ × T*SO(3) (left-trivialised: Ṙ = R(∂H/∂Π)^, Π̇ = Π × ∂H/∂Π − τ with τ the
//! left-trivialised R-derivative). K depends on R and Π only through σ, and σ Poisson-commutes
//! with every function of Π, so {K, E} = 0: the spin obeys the free Euler equations exactly,
//! Π̇ = Π × 𝕀⁻¹Π, for any metric (E = H − T and |Π| are integrals, as 002 §V says for H − T), and
//! K's flow is Wong's equations of a charge σ in the SO(3) connection C:
//!
//! ẋ = u,  ṗ_k = ½ m uᵀ(∂_k g)u + σᵀ(∂_k C)u,  Ṙ = −(Cu)^R (so σ̇ = −(Cu) × σ),  Π̇ = 0.
//!
//! Equivalently m ∇_ẋ ẋ = −½⟨σ̂, Ω(ẋ, ·)⟩, the coupling of the spin to the curvature of 002 (122):
//! the force is orthogonal to ẋ, so T = K is conserved too. On a space form this is
//! [`super::FrameTop`]'s motion (`tests/frame_top.rs` compares the two through stereographic
//! coordinates of S³).
//!
//! # Methods
//! The field is ż = ξ(z)·z for the action of ℝ³ × ℝ³ × SO(3) × ℝ on z = (x, p, R, Π): the
//! translations of x and p, rotations R ↦ QR on the left, and the free rigid body's exact flow
//! (R, Π) ↦ (RS(τ), S(τ)ᵀΠ) (elliptic functions, [`crate::systems::tops`]), which commutes with
//! the left rotations; ξ = (u, ṗ, −Cu, 1). So the Lie-group methods apply ([`GroupField`]): the
//! implicit Lie midpoint rule (`midpoint`, default; composed to orders 4 and 6 as `midpoint4`,
//! `midpoint6`) and `rkmk4`. The E-part of ξ is the constant 1, so every one of them advances the
//! spin by its exact flow: Π(t), H − T and |Π| are exact to round-off, R stays in SO(3), and T and
//! H oscillate without drift (the midpoint rules are symmetric). `rk4` integrates the field as a
//! baseline.
//!
//! The geometry comes from closures by finite differences (errors ≈ 1e-9 in ∂C), so the force is
//! that accurate; every evaluation of the field calls the metric and the frame about 330 times.
//!
//! State z = (x, p, R row-major, Π), 18 values, x and p in the chart (p the canonical momentum,
//! not m g ẋ); [`SpaceTop::state`] makes it from (x, R, ẋ, ω). The kernels work in the principal
//! axes of 𝕀 (`to_internal`).
//!
//! # Tangent lift
//! (Issue 26; [`GroupFieldTangent`].) Directions (δx, δp, η, δΠ), δR = Rη̂ (12 values). The
//! generator's derivative is that of Wong's equations above by the product rule; along δx it
//! needs ∂∂g and ∂∂C, which come from fourth-order differences of ∂g and ∂C (step `H_SECOND`),
//! so the Jacobian along the path is as accurate as the chart's geometry (measured against
//! fourth-order differences of whole runs to ≲ 1e-8; central differences of a run at h = 1e-6
//! see ≈ 4e-6 of the geometry's round-off, since ∂C is itself a difference). The action's
//! derivative: translations add δξ; R' = Q R S(τ) varies by η' = R'ᵀw + Sᵀη + η_S
//! (w = J_l(ω)δω) and Π' = SᵀΠ by the free body's exact tangent map (`frame_top/tangent.rs`). The
//! midpoint rules, their compositions and `rkmk4` are lifted so; `rk4` on the field lift, whose
//! directions (δx, δp, δR, δΠ) are ambient (δR a 3×3 matrix: the field's derivative off SO(3)
//! too, from the same derivative of Wong's equations). No parameters.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::{Body, SpaceTop};
use crate::check;
use crate::error::Result;
use crate::integrate::methods::{Composition, LieMidpoint, Rk4, Rkmk4};
use crate::integrate::problem::{GroupField, VectorField};
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{GroupFieldTangent, Tangent, TangentSystem, VectorFieldTangent};
use crate::integrate::{Catalog, Entry, Problem};
use crate::lie::so3;
use crate::numerics::fd::diff4;
use crate::systems::tangent_top::riemannian::{Geometry, Riemannian};
use crate::systems::tops::methods::exact::relative_attitude;
use crate::systems::tops::methods::exact::FreeTangent;

/// The tangent Euler top on a Riemannian 3-manifold in a chart (module docs).
#[derive(Clone, Debug)]
pub struct RiemannianFrameTop {
    space: Riemannian,
    body: Body,
}

/// The blocks of a flat state.
struct Parts {
    x: [f64; 3],
    p: Vector3<f64>,
    r: Matrix3<f64>,
    pi: Vector3<f64>,
}

fn parts(z: &[f64]) -> Parts {
    Parts {
        x: [z[0], z[1], z[2]],
        p: Vector3::from_column_slice(&z[3..6]),
        r: Matrix3::from_row_slice(&z[6..15]),
        pi: Vector3::from_column_slice(&z[15..18]),
    }
}

fn write(x: &[f64; 3], p: &Vector3<f64>, r: &Matrix3<f64>, pi: &Vector3<f64>, z: &mut [f64]) {
    z[..3].copy_from_slice(x);
    z[3..6].copy_from_slice(p.as_slice());
    for i in 0..3 {
        for j in 0..3 {
            z[6 + 3 * i + j] = r[(i, j)];
        }
    }
    z[15..18].copy_from_slice(pi.as_slice());
}

impl RiemannianFrameTop {
    /// A top of mass m > 0 and inertia tensor 𝕀 (3×3 row-major, symmetric positive definite)
    /// on `space`.
    pub fn new(space: Riemannian, mass: f64, inertia: &[f64; 9]) -> Result<Self> {
        Ok(RiemannianFrameTop {
            space,
            body: Body::new(mass, inertia)?,
        })
    }

    /// The manifold.
    pub fn space(&self) -> &Riemannian {
        &self.space
    }

    fn checked(&self, z: &[f64]) -> Result<Parts> {
        check::len_of("state", z, 18)?;
        check::finite_slice("state", z)?;
        Ok(parts(z))
    }

    /// u = ẋ = g⁻¹(p − Cᵀσ)/m.
    fn velocity_at(&self, geo: &Geometry, s: &Parts) -> Vector3<f64> {
        let sigma = s.r * s.pi;
        geo.g_inv * (s.p - geo.c.transpose() * sigma) / self.body.mass
    }

    /// (u, ṗ, σ) of K's flow at a state (module docs).
    fn wong(&self, s: &Parts) -> (Geometry, Vector3<f64>, Vector3<f64>) {
        let geo = self.space.geometry(s.x);
        let u = self.velocity_at(&geo, s);
        let sigma = s.r * s.pi;
        let m = self.body.mass;
        let pdot = Vector3::from_fn(|k, _| {
            0.5 * m * u.dot(&(geo.dg[k] * u)) + sigma.dot(&(geo.dc[k] * u))
        });
        (geo, u, pdot)
    }
}

impl SpaceTop for RiemannianFrameTop {
    fn body(&self) -> &Body {
        &self.body
    }

    /// 3 (chart coordinates).
    fn point_dim(&self) -> usize {
        3
    }

    /// The state (x, p, R, Π): Π = 𝕀ω, p = m g ẋ + Cᵀ R Π.
    fn state(
        &self,
        x: &[f64],
        r: &Matrix3<f64>,
        xdot: &[f64],
        omega: &Vector3<f64>,
    ) -> Result<Vec<f64>> {
        check::len_of("x", x, 3)?;
        check::finite_slice("x", x)?;
        check::len_of("xdot", xdot, 3)?;
        check::finite_slice("xdot", xdot)?;
        check::finite_slice("omega", omega.as_slice())?;
        so3::check_rotation("R", r)?;
        let x = [x[0], x[1], x[2]];
        self.space.check_point(x)?;
        let pi = self.body.inertia * omega;
        let p = self.space.metric(x) * Vector3::from_column_slice(xdot) * self.body.mass
            + self.space.connection(x).transpose() * (r * pi);
        let mut z = vec![0.0; 18];
        write(&x, &p, r, &pi, &mut z);
        check::finite_slice("state", &z)?;
        Ok(z)
    }

    /// Chart coordinates.
    fn position(&self, z: &[f64]) -> Result<Vec<f64>> {
        Ok(self.checked(z)?.x.to_vec())
    }

    fn frame(&self, z: &[f64]) -> Result<Matrix3<f64>> {
        Ok(self.checked(z)?.r)
    }

    /// ẋ = g⁻¹(p − Cᵀσ)/m (chart components).
    fn velocity(&self, z: &[f64]) -> Result<Vec<f64>> {
        let s = self.checked(z)?;
        self.space.check_point(s.x)?;
        let geo = self.space.geometry(s.x);
        Ok(self.velocity_at(&geo, &s).as_slice().to_vec())
    }

    fn spin(&self, z: &[f64]) -> Result<Vector3<f64>> {
        Ok(self.checked(z)?.pi)
    }

    /// ½ m ẋᵀg ẋ.
    fn translational_energy(&self, z: &[f64]) -> Result<f64> {
        let s = self.checked(z)?;
        self.space.check_point(s.x)?;
        let u = Vector3::from_column_slice(&self.velocity(z)?);
        Ok(0.5 * self.body.mass * u.dot(&(self.space.metric(s.x) * u)))
    }
}

impl Problem for RiemannianFrameTop {
    fn name(&self) -> &'static str {
        "FrameTop"
    }

    fn space(&self) -> Space {
        Space::new([
            ("x", Block::Real(3)),
            ("p", Block::Real(3)),
            ("R", Block::SO3),
            ("Pi", Block::Real(3)),
        ])
    }

    /// H = T + ½Π·𝕀⁻¹Π.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        Ok(self.translational_energy(z)? + self.rotational_energy(z)?)
    }

    /// H − T and |Π|² (kept to round-off by every method but rk4: the spin moves by its exact
    /// flow).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let pi = self.spin(z)?;
        Ok(vec![self.rotational_energy(z)?, pi.norm_squared()])
    }

    fn invariant_names(&self) -> Vec<String> {
        vec!["H − T".into(), "|Π|²".into()]
    }

    /// x in the chart.
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.space.check_point([z[0], z[1], z[2]])
    }

    /// The principal frame of 𝕀: R ← RV, Π ← VᵀΠ.
    fn to_internal(&self, z: &mut [f64]) {
        if let Some(v) = self.body.axes() {
            let s = parts(z);
            write(&s.x, &s.p, &(s.r * v), &(v.transpose() * s.pi), z);
        }
    }

    fn to_user(&self, z: &mut [f64]) {
        if let Some(v) = self.body.axes() {
            let s = parts(z);
            write(&s.x, &s.p, &(s.r * v.transpose()), &(v * s.pi), z);
        }
    }

    /// The metric and the frame are closures (a binding's callables).
    fn calls_out(&self) -> bool {
        true
    }

    /// (δx, δp, η, δΠ) ↦ (δx, δp, Vᵀη, VᵀδΠ) (δ(RV) = RV(Vᵀη)^).
    fn tangent_to_internal(&self, dz: &mut [f64]) {
        self.turn_direction(dz, false)
    }

    fn tangent_to_user(&self, dz: &mut [f64]) {
        self.turn_direction(dz, true)
    }
}

/// ξ = (u, ṗ, −Cu, 1) ∈ ℝ³ × ℝ³ × so(3) × ℝ acting on (x, p, R, Π) (module docs), principal frame.
impl GroupField for RiemannianFrameTop {
    type Scratch = FrameScratch;

    fn scratch(&self) -> FrameScratch {
        FrameScratch::default()
    }

    fn algebra_dim(&self) -> usize {
        10
    }

    fn generator(&self, z: &[f64], xi: &mut [f64], _s: &mut FrameScratch) {
        let s = parts(z);
        let (geo, u, pdot) = self.wong(&s);
        xi[..3].copy_from_slice(u.as_slice());
        xi[3..6].copy_from_slice(pdot.as_slice());
        xi[6..9].copy_from_slice((-(geo.c * u)).as_slice());
        xi[9] = 1.0;
    }

    /// Translations, then the free body's flow over ξ₉ and the left rotation exp(ξ̂₆..₉)
    /// (they commute).
    fn act(&self, xi: &[f64], z: &mut [f64], _s: &mut FrameScratch) {
        let mut s = parts(z);
        for k in 0..3 {
            s.x[k] += xi[k];
            s.p[k] += xi[3 + k];
        }
        let rel = relative_attitude(self.body.moments(), &s.pi, xi[9]);
        rel.apply_momentum(&mut s.pi);
        // R ← Q R S: S on the rows of R, then Q on its columns.
        let mut r = s.r;
        for i in 0..3 {
            let mut v = r.row(i).transpose();
            rel.apply(&mut v);
            r.set_row(i, &v.transpose());
        }
        let q = so3::Rodrigues::exp(&Vector3::new(xi[6], xi[7], xi[8]));
        for j in 0..3 {
            let mut v = r.column(j).into_owned();
            q.apply(&mut v);
            r.set_column(j, &v);
        }
        write(&s.x, &s.p, &r, &s.pi, z);
    }

    /// 1e-9, the accuracy of ∂C: it comes from differences of differences, whose round-off
    /// (≈ 1e-11 relative, times the step) stalls the midpoint iteration above
    /// [`crate::convergence::TOL`] at steps of 0.1 and near 1e-10 at steps of 0.5.
    fn solve_tolerance(&self) -> f64 {
        1e-9
    }

    /// Identity on ℝ⁶ and ℝ; on so(3) the left action's J_l(u)⁻¹ (as for the rigid body); NaN
    /// where it is singular.
    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], _s: &mut FrameScratch) {
        out.copy_from_slice(v);
        match so3::jacobian_left_inv(&Vector3::new(u[6], u[7], u[8])) {
            Ok(j) => out[6..9].copy_from_slice((j * Vector3::new(v[6], v[7], v[8])).as_slice()),
            Err(_) => out.fill(f64::NAN),
        }
    }
}

/// ẋ = u, ṗ (Wong), Ṙ = Rω̂ − (Cu)^R, Π̇ = Π × ω (principal frame): the baseline `rk4`.
impl VectorField for RiemannianFrameTop {
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let s = parts(z);
        let (geo, u, pdot) = self.wong(&s);
        let m = self.body.moments();
        let omega = Vector3::from_fn(|k, _| s.pi[k] / m[k]);
        let rdot = s.r * so3::hat(&omega) - so3::hat(&(geo.c * u)) * s.r;
        let x = [u[0], u[1], u[2]];
        write(&x, &pdot, &rdot, &s.pi.cross(&omega), dz);
    }
}

/// `midpoint` (default), `midpoint4`, `midpoint6` (the Lie midpoint rule and its Suzuki and
/// Yoshida compositions), `rkmk4`, `rk4` (module docs).
impl Catalog for RiemannianFrameTop {
    fn kind_catalog() -> Vec<Entry<Self>> {
        let mut c = lie_methods();
        c.push(Entry::new("rk4", || Rk4));
        c
    }

    /// The lift of the Lie-group methods (module docs, "Tangent lift").
    fn tangent(&self) -> Option<Arc<dyn TangentSystem>> {
        Some(Tangent::group_field(self.clone()).into_system())
    }

    /// `rk4` on the field lift (ambient directions), the others on [`Catalog::tangent`]'s.
    fn tangent_for(&self, method: &str) -> Option<Arc<dyn TangentSystem>> {
        Tangent::routed(self, method, || self.tangent())
    }
}

fn lie_methods<P: GroupField + Clone + 'static>() -> Vec<Entry<P>> {
    vec![
        Entry::new("midpoint", LieMidpoint::new),
        Entry::new("midpoint4", || LieMidpoint(Composition::suzuki4())),
        Entry::new("midpoint6", || LieMidpoint(Composition::yoshida6())),
        Entry::new("rkmk4", || Rkmk4),
    ]
}

/// The Lie-group methods on the group-field lift, `rk4` on the field lift (ambient directions).
impl Catalog for Tangent<RiemannianFrameTop> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        lie_methods()
    }

    fn catalog(&self) -> Vec<Entry<Self>> {
        match self.ambient() {
            true => vec![Entry::new("rk4", || Rk4)],
            false => lie_methods(),
        }
    }
}

/// Step of the differences of the geometry for its second derivatives (∂∂g, ∂∂C): ∂C carries
/// ≈ 1e-11 of round-off, so this step trades its amplification (÷ h) against the truncation
/// (h⁴).
const H_SECOND: f64 = 1e-2;

/// The x-derivatives of ∂g and ∂C at a point: `dg[j][k]` = ∂_j∂_k g, `dc[j][k]` = ∂_j∂_k C.
#[derive(Clone, Copy, Debug)]
struct Second {
    dg: [[Matrix3<f64>; 3]; 3],
    dc: [[Matrix3<f64>; 3]; 3],
}

/// The work space of the kernels: for the tangent lift, the geometry and its second derivatives
/// at the last point (the k directions of a stage share them), and the last action's free-body
/// tangent and J_l (keyed by the algebra element and the result's Π).
#[derive(Default)]
pub struct FrameScratch {
    at: Option<([f64; 3], Geometry, Second)>,
    act: Option<([f64; 13], Matrix3<f64>, FreeTangent)>,
}

impl RiemannianFrameTop {
    fn turn_direction(&self, dz: &mut [f64], inverse: bool) {
        if let Some(v) = self.body.axes() {
            let m = if inverse { *v } else { v.transpose() };
            for r in [6..9, 9..12] {
                let w = m * Vector3::from_column_slice(&dz[r.clone()]);
                dz[r].copy_from_slice(w.as_slice());
            }
        }
    }

    /// The geometry at x and its second derivatives by fourth-order differences of ∂g and ∂C
    /// (step [`H_SECOND`]), cached in the scratch.
    fn second<'a>(&self, x: [f64; 3], s: &'a mut FrameScratch) -> (&'a Geometry, &'a Second) {
        if s.at.as_ref().map_or(true, |(y, _, _)| *y != x) {
            let f = |y: [f64; 3]| -> [f64; 54] {
                let geo = self.space.geometry(y);
                std::array::from_fn(|n| {
                    let (m, k, e) = (n / 27, (n % 27) / 9, n % 9);
                    let a = if m == 0 { &geo.dg[k] } else { &geo.dc[k] };
                    a[(e / 3, e % 3)]
                })
            };
            let mut sec = Second {
                dg: [[Matrix3::zeros(); 3]; 3],
                dc: [[Matrix3::zeros(); 3]; 3],
            };
            for j in 0..3 {
                let d = diff4(f, x, j, H_SECOND);
                for k in 0..3 {
                    sec.dg[j][k] = Matrix3::from_fn(|a, b| d[9 * k + 3 * a + b]);
                    sec.dc[j][k] = Matrix3::from_fn(|a, b| d[27 + 9 * k + 3 * a + b]);
                }
            }
            s.at = Some((x, self.space.geometry(x), sec));
        }
        let (_, geo, sec) = s.at.as_ref().expect("just set");
        (geo, sec)
    }
}

fn v3(s: &[f64]) -> Vector3<f64> {
    Vector3::from_column_slice(&s[..3])
}

/// The derivative of Wong's equations at a state along (δx, δp, δσ): Cu there (u the
/// velocity), δu, δṗ and δ(Cu).
struct WongTangent {
    cu: Vector3<f64>,
    du: Vector3<f64>,
    dpdot: Vector3<f64>,
    dcu: Vector3<f64>,
}

impl RiemannianFrameTop {
    /// With σ = RΠ and along δx the geometry's derivatives (δg = Σδx_j∂_jg, δC, δ∂_kg, δ∂_kC):
    /// m g δu = δp − δCᵀσ − Cᵀδσ − m δg u,
    /// δṗ_k = m uᵀ∂_kg δu + ½m uᵀδ(∂_kg)u + δσᵀ∂_kC u + σᵀδ(∂_kC)u + σᵀ∂_kC δu,
    /// δ(Cu) = δC u + C δu.
    fn wong_tangent(
        &self,
        st: &Parts,
        (dx, dp, dsigma): (Vector3<f64>, Vector3<f64>, Vector3<f64>),
        s: &mut FrameScratch,
    ) -> WongTangent {
        let (geo, sec) = self.second(st.x, s);
        let m = self.body.mass;
        let u = self.velocity_at(geo, st);
        let sigma = st.r * st.pi;
        let along = |a: &[Matrix3<f64>; 3]| a[0] * dx[0] + a[1] * dx[1] + a[2] * dx[2];
        let (dg, dc) = (along(&geo.dg), along(&geo.dc));
        let du =
            geo.g_inv * (dp - dc.transpose() * sigma - geo.c.transpose() * dsigma - dg * u * m) / m;
        let mut dpdot = Vector3::zeros();
        for k in 0..3 {
            let ddg = sec.dg[0][k] * dx[0] + sec.dg[1][k] * dx[1] + sec.dg[2][k] * dx[2];
            let ddc = sec.dc[0][k] * dx[0] + sec.dc[1][k] * dx[1] + sec.dc[2][k] * dx[2];
            dpdot[k] = m * u.dot(&(geo.dg[k] * du))
                + 0.5 * m * u.dot(&(ddg * u))
                + dsigma.dot(&(geo.dc[k] * u))
                + sigma.dot(&(ddc * u))
                + sigma.dot(&(geo.dc[k] * du));
        }
        WongTangent {
            cu: geo.c * u,
            du,
            dpdot,
            dcu: dc * u + geo.c * du,
        }
    }

    /// [`VectorFieldTangent::field_tangent`] with the geometry's derivatives cached in `s`.
    fn field_tangent_with(&self, z: &[f64], dz: &[f64], out: &mut [f64], s: &mut FrameScratch) {
        let st = parts(z);
        let dr = Matrix3::from_row_slice(&dz[6..15]);
        let dpi = v3(&dz[15..]);
        let dsigma = dr * st.pi + st.r * dpi;
        let t = self.wong_tangent(&st, (v3(dz), v3(&dz[3..]), dsigma), s);
        let m = self.body.moments();
        let omega = Vector3::from_fn(|k, _| st.pi[k] / m[k]);
        let domega = Vector3::from_fn(|k, _| dpi[k] / m[k]);
        let hat = so3::hat;
        let drdot = dr * hat(&omega) + st.r * hat(&domega) - hat(&t.dcu) * st.r - hat(&t.cu) * dr;
        let dpidot = dpi.cross(&omega) + st.pi.cross(&domega);
        let dx = [t.du[0], t.du[1], t.du[2]];
        write(&dx, &t.dpdot, &drdot, &dpidot, out);
    }
}

/// The derivative of the `rk4` field along an ambient direction (δx, δp, δR, δΠ), δR a 3×3
/// matrix: Wong's with δσ = δRΠ + RδΠ, δṘ = δRω̂ + R(δω)^ − (δ(Cu))^R − (Cu)^δR,
/// δΠ̇ = δΠ × ω + Π × δω.
impl VectorFieldTangent for RiemannianFrameTop {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        self.field_tangent_with(z, dz, out, &mut FrameScratch::default());
    }

    /// The geometry's second derivatives formed once for every direction.
    fn field_tangents(&self, z: &[f64], dirs: &[f64], out: &mut [f64]) {
        let mut s = FrameScratch::default();
        for (dz, o) in dirs.chunks_exact(18).zip(out.chunks_exact_mut(18)) {
            self.field_tangent_with(z, dz, o, &mut s);
        }
    }
}

/// The tangent lift (module docs, "Tangent lift"): directions (δx, δp, η, δΠ), δR = Rη̂.
impl GroupFieldTangent for RiemannianFrameTop {
    /// Wong's derivative (`wong_tangent`) with δσ = R(η × Π + δΠ);
    /// δ(−Cu), and 0 for the free body's time.
    fn generator_tangent(&self, z: &[f64], dz: &[f64], dxi: &mut [f64], s: &mut FrameScratch) {
        let st = parts(z);
        let dsigma = st.r * (v3(&dz[6..]).cross(&st.pi) + v3(&dz[9..]));
        let t = self.wong_tangent(&st, (v3(dz), v3(&dz[3..]), dsigma), s);
        dxi[..3].copy_from_slice(t.du.as_slice());
        dxi[3..6].copy_from_slice(t.dpdot.as_slice());
        dxi[6..9].copy_from_slice((-t.dcu).as_slice());
        dxi[9] = 0.0;
    }

    /// Translations add δξ; R' = QRS(τ) varies by η' = R'ᵀw + Sᵀη + η_S (w = J_l(ω)δω, η_S of
    /// the free body's tangent map, `FreeTangent`), Π' = SᵀΠ by its δΠ'.
    fn act_tangent(&self, u: &[f64], du: &[f64], y: &[f64], dz: &mut [f64], s: &mut FrameScratch) {
        let out = parts(y);
        let mut key = [0.0; 13];
        key[..10].copy_from_slice(&u[..10]);
        key[10..].copy_from_slice(out.pi.as_slice());
        if s.act.as_ref().map_or(true, |(k, _, _)| *k != key) {
            // The free body's state before the action: Π' flowed back over τ.
            let tau = u[9];
            let mut pi0 = out.pi;
            relative_attitude(self.body.moments(), &out.pi, -tau).apply_momentum(&mut pi0);
            let free = FreeTangent::new(self.body.moments(), &pi0, tau);
            let (_, jl) = so3::exp_and_jacobian_left(&v3(&u[6..]));
            s.act = Some((key, jl, free));
        }
        let (_, jl, free) = s.act.as_ref().expect("just set");
        for k in 0..6 {
            dz[k] += du[k];
        }
        let w = jl * v3(&du[6..]);
        let (dpi, eta_s) = free.apply_timed(&v3(&dz[9..]), du[9]);
        let eta = out.r.transpose() * w + free.turn(&v3(&dz[6..])) + eta_s;
        dz[6..9].copy_from_slice(eta.as_slice());
        dz[9..12].copy_from_slice(dpi.as_slice());
    }

    /// [`so3::jacobian_left_derivative`] on so(3), 0 on the flat factors.
    fn dexp_tangent(
        &self,
        u: &[f64],
        du: &[f64],
        w: &[f64],
        out: &mut [f64],
        _s: &mut FrameScratch,
    ) {
        out.fill(0.0);
        let q = so3::jacobian_left_derivative(&v3(&u[6..]), &v3(&du[6..]));
        out[6..9].copy_from_slice((q * v3(&w[6..])).as_slice());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The catalog's chart: a conformally flat metric λ²δ with a rotating frame Q(x)/λ.
    fn top() -> RiemannianFrameTop {
        let lambda = |x: [f64; 3]| 1.0 + 0.1 * (x[0] * x[0] + 0.5 * x[1] * x[2]);
        let chart = Riemannian::new(
            move |x| {
                let l2 = lambda(x).powi(2);
                [[l2, 0.0, 0.0], [0.0, l2, 0.0], [0.0, 0.0, l2]]
            },
            move |x| {
                let q =
                    so3::exp_unchecked(&Vector3::new(0.3 * x[0], -0.2 * x[2], 0.4 * x[0] * x[1]))
                        / lambda(x);
                std::array::from_fn(|a| std::array::from_fn(|i| q[(i, a)]))
            },
            None,
        );
        RiemannianFrameTop::new(chart, 1.3, &[2.0, 0.3, -0.1, 0.3, 3.1, 0.2, -0.1, 0.2, 4.2])
            .unwrap()
    }

    fn state(t: &RiemannianFrameTop) -> Vec<f64> {
        let mut z = t
            .state(
                &[0.3, -0.2, 0.5],
                &so3::exp_unchecked(&Vector3::new(0.4, -0.7, 0.3)),
                &[0.4, 0.1, -0.3],
                &Vector3::new(0.7, -0.4, 1.1),
            )
            .unwrap();
        t.to_internal(&mut z);
        z
    }

    /// z moved along (δx, δp, η, δΠ) by s (R exp(sη̂)).
    fn moved(z: &[f64], dz: &[f64], s: f64) -> Vec<f64> {
        let mut p = parts(z);
        for k in 0..3 {
            p.x[k] += s * dz[k];
            p.p[k] += s * dz[3 + k];
            p.pi[k] += s * dz[9 + k];
        }
        let r = p.r * so3::exp_unchecked(&(v3(&dz[6..]) * s));
        let mut out = vec![0.0; 18];
        write(&p.x, &p.p, &r, &p.pi, &mut out);
        out
    }

    fn read(a: &[f64], b: &[f64], h: f64) -> Vec<f64> {
        let (pa, pb) = (parts(a), parts(b));
        let mut out: Vec<f64> = (0..6).map(|k| (a[k] - b[k]) / (2.0 * h)).collect();
        let eta = so3::vee_unchecked(&((pa.r + pb.r).transpose() * (pa.r - pb.r) / (4.0 * h)));
        out.extend(eta.iter());
        out.extend(((pa.pi - pb.pi) / (2.0 * h)).iter());
        out
    }

    fn worst(a: &[f64], b: &[f64]) -> f64 {
        let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale
    }

    /// ξ′(z)δz against differences of the generator: along (δp, η, δΠ) to 1e-9; along δx the
    /// geometry's second derivatives are differences themselves, and the generator's own
    /// round-off (≈ 1e-11 in ∂C) limits the check (fourth-order differences at h = 1e-3).
    #[test]
    fn generator_tangent_is_the_generators_derivative() {
        let t = top();
        let z = state(&t);
        let mut s = t.scratch();
        let gen = |v: &[f64]| {
            let mut xi = vec![0.0; 10];
            t.generator(v, &mut xi, &mut t.scratch());
            xi
        };
        for (dz, h, fourth, tol) in [
            (
                vec![
                    0.0, 0.0, 0.0, 0.4, -0.3, 0.8, 0.2, -0.5, 0.3, 0.6, 0.1, -0.7,
                ],
                1e-6,
                false,
                1e-9,
            ),
            (
                vec![0.5, -0.3, 0.7, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                1e-3,
                true,
                1e-7,
            ),
        ] {
            let at = |s_: f64| gen(&moved(&z, &dz, s_));
            let fd: Vec<f64> = if fourth {
                let (p1, m1, p2, m2) = (at(h), at(-h), at(2.0 * h), at(-2.0 * h));
                (0..10)
                    .map(|i| (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * h))
                    .collect()
            } else {
                let (p, q) = (at(h), at(-h));
                p.iter().zip(&q).map(|(a, b)| (a - b) / (2.0 * h)).collect()
            };
            let mut d = vec![0.0; 10];
            t.generator_tangent(&z, &dz, &mut d, &mut s);
            let err = worst(&d, &fd);
            eprintln!("generator tangent vs differences {err:.1e}");
            assert!(err < tol, "{err:e}");
        }
    }

    /// The action's derivative (translations, the left rotation, the free body's flow, also
    /// along its time) and dexp's against central differences.
    #[test]
    fn act_and_dexp_tangents_are_their_derivatives() {
        let t = top();
        let z = state(&t);
        let dz = vec![
            0.3, -0.2, 0.5, 0.4, -0.3, 0.8, 0.2, -0.5, 0.3, 0.6, 0.1, -0.7,
        ];
        let xi = vec![0.1, -0.2, 0.3, 0.05, 0.1, -0.1, 0.4, -0.3, 0.6, 0.35];
        let dxi = vec![0.2, 0.1, -0.3, 0.5, -0.2, 0.1, -0.6, 0.3, 0.2, 0.8];
        let h = 1e-6;
        let act = |s_: f64| {
            let mut v = moved(&z, &dz, s_);
            let x: Vec<f64> = xi.iter().zip(&dxi).map(|(a, b)| a + s_ * b).collect();
            t.act(&x, &mut v, &mut t.scratch());
            v
        };
        let fd = read(&act(h), &act(-h), h);
        let mut y = z.clone();
        let mut s = t.scratch();
        t.act(&xi, &mut y, &mut s);
        let mut d = dz.clone();
        t.act_tangent(&xi, &dxi, &y, &mut d, &mut s);
        let err = worst(&d, &fd);
        eprintln!("act tangent vs differences {err:.1e}");
        assert!(err < 1e-8, "act: {err:e}");
        let w = vec![0.3, -0.1, 0.2, 0.4, 0.5, -0.6, 0.7, 0.1, -0.2, 0.9];
        let dexp = |s_: f64| {
            let x: Vec<f64> = xi.iter().zip(&dxi).map(|(a, b)| a + s_ * b).collect();
            let mut out = w.clone();
            let j = so3::jacobian_left_unchecked(&v3(&x[6..]));
            out[6..9].copy_from_slice((j * v3(&w[6..])).as_slice());
            out
        };
        let (p, q) = (dexp(h), dexp(-h));
        let fd: Vec<f64> = p.iter().zip(&q).map(|(a, b)| (a - b) / (2.0 * h)).collect();
        let mut d = vec![0.0; 10];
        t.dexp_tangent(&xi, &dxi, &w, &mut d, &mut s);
        let err = worst(&d, &fd);
        assert!(err < 1e-9, "dexp: {err:e}");
    }

    /// The `rk4` field's derivative along ambient directions (δR any 3×3 matrix) at a state
    /// with R off SO(3), against differences of the field: along (δp, δR, δΠ) central to 1e-9,
    /// along δx fourth-order (the geometry's round-off, as for the generator); and all
    /// directions at once as each alone, bit for bit.
    #[test]
    fn field_tangent_is_the_fields_derivative() {
        let t = top();
        let mut z = state(&t);
        for (k, v) in z[6..15].iter_mut().enumerate() {
            *v += 1e-3 * (0.7 * k as f64).sin();
        }
        let field = |v: &[f64]| {
            let mut f = vec![0.0; 18];
            t.field(v, &mut f);
            f
        };
        let mut dirs = vec![];
        for (dz, h, fourth, tol) in [
            (
                (0..18)
                    .map(|k| {
                        if k < 3 {
                            0.0
                        } else {
                            0.4 * (1.3 * k as f64).cos()
                        }
                    })
                    .collect::<Vec<f64>>(),
                1e-6,
                false,
                1e-9,
            ),
            (
                (0..18)
                    .map(|k| if k < 3 { 0.5 - 0.3 * k as f64 } else { 0.0 })
                    .collect(),
                1e-3,
                true,
                1e-7,
            ),
        ] {
            let at = |s_: f64| {
                let v: Vec<f64> = z.iter().zip(&dz).map(|(a, b)| a + s_ * b).collect();
                field(&v)
            };
            let fd: Vec<f64> = if fourth {
                let (p1, m1, p2, m2) = (at(h), at(-h), at(2.0 * h), at(-2.0 * h));
                (0..18)
                    .map(|i| (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * h))
                    .collect()
            } else {
                let (p, q) = (at(h), at(-h));
                p.iter().zip(&q).map(|(a, b)| (a - b) / (2.0 * h)).collect()
            };
            let mut d = vec![0.0; 18];
            t.field_tangent(&z, &dz, &mut d);
            let err = worst(&d, &fd);
            eprintln!("field tangent vs differences {err:.1e}");
            assert!(err < tol, "{err:e}");
            dirs.extend(dz);
        }
        let mut one = vec![0.0; 36];
        for (dz, o) in dirs.chunks_exact(18).zip(one.chunks_exact_mut(18)) {
            t.field_tangent(&z, dz, o);
        }
        let mut all = vec![0.0; 36];
        t.field_tangents(&z, &dirs, &mut all);
        assert_eq!(one, all);
    }
}
