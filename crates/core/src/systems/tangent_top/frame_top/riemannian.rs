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

use nalgebra::{Matrix3, Vector3};

use super::{Body, SpaceTop};
use crate::check;
use crate::error::Result;
use crate::integrate::methods::{Composition, LieMidpoint, Rk4, Rkmk4};
use crate::integrate::problem::{GroupField, VectorField};
use crate::integrate::space::{Block, Space};
use crate::integrate::{Catalog, Entry, Problem};
use crate::lie::so3;
use crate::systems::tangent_top::riemannian::{Geometry, Riemannian};
use crate::systems::tops::methods::exact::relative_attitude;

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

    fn invariant_count(&self) -> usize {
        2
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
}

/// ξ = (u, ṗ, −Cu, 1) ∈ ℝ³ × ℝ³ × so(3) × ℝ acting on (x, p, R, Π) (module docs), principal frame.
impl GroupField for RiemannianFrameTop {
    type Scratch = ();

    fn scratch(&self) {}

    fn algebra_dim(&self) -> usize {
        10
    }

    fn generator(&self, z: &[f64], xi: &mut [f64], _s: &mut ()) {
        let s = parts(z);
        let (geo, u, pdot) = self.wong(&s);
        xi[..3].copy_from_slice(u.as_slice());
        xi[3..6].copy_from_slice(pdot.as_slice());
        xi[6..9].copy_from_slice((-(geo.c * u)).as_slice());
        xi[9] = 1.0;
    }

    /// Translations, then the free body's flow over ξ₉ and the left rotation exp(ξ̂₆..₉)
    /// (they commute).
    fn act(&self, xi: &[f64], z: &mut [f64], _s: &mut ()) {
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
    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], _s: &mut ()) {
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
        vec![
            Entry::new("midpoint", LieMidpoint::new),
            Entry::new("midpoint4", || LieMidpoint(Composition::suzuki4())),
            Entry::new("midpoint6", || LieMidpoint(Composition::yoshida6())),
            Entry::new("rkmk4", || Rkmk4),
            Entry::new("rk4", || Rk4),
        ]
    }
}
