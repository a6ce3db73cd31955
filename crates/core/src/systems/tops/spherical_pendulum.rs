//! The spherical pendulum (000 §5.1) as a Lie–Poisson system on se(3)*.
//!
//! A bob of mass m on a massless rod of length l about a fixed pivot; q ∈ S² the unit vector from
//! the pivot to the bob (spatial frame, e₃ up), L = m l² q × q̇ the angular momentum about the
//! pivot. With ω = L/(ml²):
//!
//! q̇ = ω × q,   L̇ = mgl e₃ × q,   H = |L|²/(2ml²) + mgl q₃,
//!
//! the Lie–Poisson equations of e(3)* with Casimirs |q|² = 1 and q·L = 0, and the vertical
//! angular momentum L₃ conserved (rotations about e₃). This is the Euler–Poincaré form of 000
//! §5.1.2 written in space: with x = RX, |X| = l, Γ = Rᵀe₃ and body momentum M the reduced
//! equations are Ṁ = M × Ω + mgl Γ × χ, Γ̇ = Γ × Ω (χ = X/l; the extraction of §5.1.2 is garbled:
//! its Γ̇ = Λ × Ω and R̈ = −mgRΓ̂ are not right), and q = Rχ, L = RM turn them into the equations
//! above; L₃ = (RM)·e₃ = M·Γ is the Casimir M·Γ of the heavy top. §5.1.1's potential
//! V = −mgz is a sign slip (its Euler–Lagrange equation Rθ̈ − R sinθ cosθ φ̇² + g sinθ = 0, θ from
//! the downward vertical, is right and needs V = +mgR(1 − cos θ)); the tests check q(t) against
//! that equation.
//!
//! Splitting: the kinetic flow rotates q about the fixed L by the angle t|L|/(ml²); the potential
//! flow kicks L ↦ L + t mgl e₃ × q. Both are exact, keep |q|², q·L and L₃ exactly.
//!
//! Tangent lift (issue 26, [`crate::integrate::tangent`]): the tangent maps of both flows and the
//! derivative of the field, in the ambient R⁶ (off the constraints too), with the parameters
//! `mass`, `length`, `g` through ml² and mgl.

use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::{Composition, Rk4, Splitting};
use crate::integrate::problem::{Split, Symmetric, VectorField};
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{SplitTangent, Tangent, TangentSystem, VectorFieldTangent};
use crate::integrate::{Catalog, Entry, Problem};
use crate::systems::test_problems::pendulum::Bob;
use nalgebra::Vector3;

/// Tolerance of the constraints |q| = 1 and q·L = 0 on an initial state.
pub const CONSTRAINT_TOL: f64 = 1e-10;

/// A spherical pendulum with mass m, length l and gravity g.
#[derive(Clone, Debug, PartialEq)]
pub struct SphericalPendulum {
    bob: Bob,
}

impl SphericalPendulum {
    /// m > 0, l > 0, g ≥ 0.
    pub fn new(mass: f64, length: f64, gravity: f64) -> Result<Self> {
        Ok(SphericalPendulum {
            bob: Bob::new(mass, length, gravity)?,
        })
    }

    /// The mass m of the bob.
    pub fn mass(&self) -> f64 {
        self.bob.mass
    }

    /// The length l of the rod.
    pub fn length(&self) -> f64 {
        self.bob.length
    }

    /// The gravitational acceleration g.
    pub fn gravity(&self) -> f64 {
        self.bob.gravity
    }

    /// The state (q, L) from spherical coordinates of 000 §5.1.1 (θ from the downward vertical):
    /// q = (sinθ cosφ, sinθ sinφ, −cosθ), L = ml² q × q̇.
    pub fn state_from_spherical(
        &self,
        theta: f64,
        phi: f64,
        theta_dot: f64,
        phi_dot: f64,
    ) -> Result<Vec<f64>> {
        check::finite_slice("spherical coordinates", &[theta, phi, theta_dot, phi_dot])?;
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        let q = Vector3::new(st * cp, st * sp, -ct);
        let qd = Vector3::new(ct * cp, ct * sp, st) * theta_dot
            + Vector3::new(-st * sp, st * cp, 0.0) * phi_dot;
        let l = q.cross(&qd) * self.bob.inertia();
        Ok([q.as_slice(), l.as_slice()].concat())
    }

    /// The vertical angular momentum L₃ (conserved).
    pub fn vertical_momentum(&self, z: &[f64]) -> Result<f64> {
        check::len_of("state", z, 6)?;
        Ok(z[5])
    }

    fn casimirs(z: &[f64]) -> [f64; 2] {
        [
            z[..3].iter().map(|x| x * x).sum(),
            (0..3).map(|i| z[i] * z[3 + i]).sum(),
        ]
    }
}

impl Problem for SphericalPendulum {
    fn name(&self) -> &'static str {
        "SphericalPendulum"
    }
    /// The constructor's m, l, g.
    fn parameters(&self) -> Vec<&'static str> {
        vec!["mass", "length", "g"]
    }
    fn space(&self) -> Space {
        Space::new([("q", Block::Real(3)), ("L", Block::Real(3))])
    }
    /// H = |L|²/(2ml²) + mgl q₃.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let l2: f64 = z[3..].iter().map(|x| x * x).sum();
        Ok(0.5 * l2 / self.bob.inertia() + self.bob.mgl() * z[2])
    }
    /// [|q|², q·L] (the Casimirs; the vertical momentum L₃ is [`Self::vertical_momentum`]).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        Ok(Self::casimirs(z).to_vec())
    }
    fn invariant_names(&self) -> Vec<String> {
        vec!["|q|²".into(), "q·L".into()]
    }
    /// |q| = 1 and q·L = 0 to [`CONSTRAINT_TOL`].
    fn check_state(&self, z: &[f64]) -> Result<()> {
        check_pendulum_state(z)
    }
}

/// The state-space check of a spherical-pendulum state (q, L): |q| = 1 and q·L = 0 to
/// [`CONSTRAINT_TOL`] (shared with [`crate::systems::SphereParticle::from_spherical`]).
pub(crate) fn check_pendulum_state(z: &[f64]) -> Result<()> {
    let [q2, ql] = SphericalPendulum::casimirs(z);
    let l = z[3..].iter().map(|x| x * x).sum::<f64>().sqrt();
    if (q2.sqrt() - 1.0).abs() > CONSTRAINT_TOL || ql.abs() > CONSTRAINT_TOL * l.max(1.0) {
        return Err(Error::invalid(
            "state",
            format!(
                "a spherical-pendulum state needs |q| = 1 and q·L = 0; got |q| = {}, q·L = {ql}",
                q2.sqrt()
            ),
        ));
    }
    Ok(())
}

/// Flow 0: the potential kick L ↦ L + t mgl e₃ × q; flow 1: the kinetic rotation of q about L.
impl Split for SphericalPendulum {
    type Work = (Vector3<f64>, Vector3<f64>);
    fn load(&self, z: &[f64]) -> Result<Self::Work> {
        Ok((
            Vector3::from_column_slice(&z[..3]),
            Vector3::from_column_slice(&z[3..]),
        ))
    }
    fn store(&self, (q, l): &Self::Work, z: &mut [f64]) {
        z[..3].copy_from_slice(q.as_slice());
        z[3..].copy_from_slice(l.as_slice());
    }
    fn flows(&self) -> usize {
        2
    }
    fn flow(&self, i: usize, tau: f64, (q, l): &mut Self::Work) {
        if i == 0 {
            *l += Vector3::new(-q.y, q.x, 0.0) * (tau * self.bob.mgl());
        } else {
            // q + (exp(ŵ) − I) q: the matrix exp(ŵ) is orthogonal only to ~ε, and on the
            // conical pendulum (a steady rotation) its defect biased |q|² and q·L the same way at
            // every step (`so3::Rodrigues`).
            crate::lie::so3::Rodrigues::exp(&(*l * (tau / self.bob.inertia()))).apply(q);
        }
    }
}

/// Rotations about the vertical e₃ (the symmetry of gravity): (q, L) ↦ (gq, gL).
impl Symmetric for SphericalPendulum {
    fn symmetry_dim(&self) -> usize {
        1
    }

    /// J = L₃, the vertical angular momentum.
    fn momentum_map(&self, z: &[f64]) -> Result<Vec<f64>> {
        Ok(vec![self.vertical_momentum(z)?])
    }

    /// (ξ e₃ × q, ξ e₃ × L).
    fn generator(&self, xi: &[f64], z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("xi", xi, 1)?;
        check::len_of("state", z, 6)?;
        let w = xi[0];
        Ok(vec![-w * z[1], w * z[0], 0.0, -w * z[4], w * z[3], 0.0])
    }
}

impl VectorField for SphericalPendulum {
    /// q̇ = ω × q, L̇ = mgl e₃ × q.
    fn field(&self, y: &[f64], dy: &mut [f64]) {
        let q = Vector3::from_column_slice(&y[..3]);
        let w = Vector3::from_column_slice(&y[3..]) / self.bob.inertia();
        dy[..3].copy_from_slice(w.cross(&q).as_slice());
        dy[3..].copy_from_slice(&[-self.bob.mgl() * q.y, self.bob.mgl() * q.x, 0.0]);
    }
}

impl SphericalPendulum {
    /// (∂(ml²)/∂θ, ∂(mgl)/∂θ) for the parameter θ = m, l or g (0, 1, 2).
    fn rates(&self, m: usize) -> (f64, f64) {
        let Bob {
            mass,
            length: l,
            gravity: g,
        } = self.bob;
        match m {
            0 => (l * l, g * l),
            1 => (2.0 * mass * l, mass * g),
            _ => (0.0, mass * l),
        }
    }
}

fn v3(z: &[f64]) -> Vector3<f64> {
    Vector3::new(z[0], z[1], z[2])
}

/// Flow 0, the kick: δL′ = δL + τ mgl e₃ × δq. Flow 1, q′ = exp(ŵ)q with w = τL/(ml²) and L
/// fixed: exp(w + δw) = exp(hat(J_l(w)δw)) exp(ŵ) to first order, so
/// δq′ = exp(ŵ)δq + (J_l(w)δw) × q′, δw = τδL/(ml²).
impl SplitTangent for SphericalPendulum {
    fn flow_tangent(
        &self,
        i: usize,
        tau: f64,
        before: &Self::Work,
        after: &Self::Work,
        dirs: &mut [f64],
    ) {
        if i == 0 {
            let k = tau * self.bob.mgl();
            for dz in dirs.chunks_exact_mut(6) {
                let (x, y) = (dz[0], dz[1]);
                dz[3] -= k * y;
                dz[4] += k * x;
            }
            return;
        }
        let t = tau / self.bob.inertia();
        let (e, jl) = crate::lie::so3::exp_and_jacobian_left(&(before.1 * t));
        let q1 = after.0;
        for dz in dirs.chunks_exact_mut(6) {
            let dq = e * v3(dz) + (jl * (v3(&dz[3..]) * t)).cross(&q1);
            dz[..3].copy_from_slice(dq.as_slice());
        }
    }

    /// Kick: τ ∂(mgl) e₃ × q. Rotation: w moves by ∂w = −(∂I/I)w, and J_l(w)w = w, so
    /// δq′ = −(∂I/I) w × q′ (I = ml²).
    fn flow_parameter(
        &self,
        i: usize,
        tau: f64,
        before: &Self::Work,
        after: &Self::Work,
        m: usize,
        dz: &mut [f64],
    ) {
        let (di, dk) = self.rates(m);
        if i == 0 {
            let q = before.0;
            dz[3] -= tau * dk * q.y;
            dz[4] += tau * dk * q.x;
            return;
        }
        let i = self.bob.inertia();
        let d = (before.1 * (-tau * di / (i * i))).cross(&after.0);
        for c in 0..3 {
            dz[c] += d[c];
        }
    }
}

/// δq̇ = (δL/(ml²)) × q + ω × δq, δL̇ = mgl e₃ × δq.
impl VectorFieldTangent for SphericalPendulum {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        let i = self.bob.inertia();
        let (q, l) = (v3(z), v3(&z[3..]));
        let (dq, dl) = (v3(dz), v3(&dz[3..]));
        out[..3].copy_from_slice(((dl.cross(&q) + l.cross(&dq)) / i).as_slice());
        let k = self.bob.mgl();
        out[3..].copy_from_slice(&[-k * dq.y, k * dq.x, 0.0]);
    }

    /// ∂q̇ = −(∂I/I²) L × q, ∂L̇ = ∂(mgl) e₃ × q.
    fn field_parameter(&self, z: &[f64], m: usize, out: &mut [f64]) {
        let (di, dk) = self.rates(m);
        let i = self.bob.inertia();
        let (q, l) = (v3(z), v3(&z[3..]));
        let d = l.cross(&q) * (-di / (i * i));
        for c in 0..3 {
            out[c] += d[c];
        }
        out[3] -= dk * q.y;
        out[4] += dk * q.x;
    }
}

impl Catalog for SphericalPendulum {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("splitting", Splitting::strang),
            Entry::new("splitting4", || Splitting(Composition::suzuki4())),
            Entry::new("splitting6", || Splitting(Composition::yoshida6())),
            Entry::new("rk4", || Rk4),
        ]
    }

    /// The tangent lift of every method (the splittings' flows and rk4's field).
    fn tangent(&self) -> Option<std::sync::Arc<dyn TangentSystem>> {
        Some(Tangent::split(self.clone()).into_system())
    }
}

/// Every method of the system, on its tangent lift.
impl Catalog for Tangent<SphericalPendulum> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("splitting", Splitting::strang),
            Entry::new("splitting4", || Splitting(Composition::suzuki4())),
            Entry::new("splitting6", || Splitting(Composition::yoshida6())),
            Entry::new("rk4", || Rk4),
        ]
    }
}
