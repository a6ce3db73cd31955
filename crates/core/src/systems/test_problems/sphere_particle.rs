//! A particle on a sphere in uniform gravity: the spherical pendulum in Cartesian coordinates, a
//! test problem for holonomically constrained methods (RATTLE).
//!
//! q ∈ ℝ³ the position of a particle of mass m relative to the pivot (e₃ up), p = m q̇, held on
//! the sphere |q| = l:
//!
//! H = |p|²/(2m) + m g q₃,   g(q) = (|q|² − l²)/2 = 0,   G(q) = qᵀ,
//!
//! so the constrained phase space is {|q| = l, q·p = 0}. Rotations about e₃ are a symmetry: the
//! vertical angular momentum (q × p)₃ is conserved, and kept exactly by RATTLE (equivariant under
//! these rotations). The same motion as [`crate::systems::SphericalPendulum`] with u = q/l and
//! L = q × p ([`SphereParticle::from_spherical`], [`SphereParticle::to_spherical`]): since L ⊥ u,
//! p = m l u̇ = L × u / l, and |p|²/(2m) = |L|²/(2ml²).

use super::pendulum::Bob;
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::Rattle;
use crate::integrate::problem::{Constrained, Separable, Violation};
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{SeparableTangent, Tangent, TangentSystem};
use crate::integrate::{Catalog, Entry, Problem};
use nalgebra::Vector3;
use std::sync::Arc;

/// Relative tolerance of the constraints |q| = l and q·p = 0 on a state.
pub const CONSTRAINT_TOL: f64 = 1e-10;

/// A particle of mass m on the sphere of radius l in gravity g; state z = (q, p).
#[derive(Clone, Debug, PartialEq)]
pub struct SphereParticle {
    bob: Bob,
}

impl SphereParticle {
    /// m > 0, l > 0, g ≥ 0.
    pub fn new(mass: f64, length: f64, gravity: f64) -> Result<Self> {
        Ok(SphereParticle {
            bob: Bob::new(mass, length, gravity)?,
        })
    }

    /// The state (q, p) = (l u, L × u / l) of a [`crate::systems::SphericalPendulum`] state (u, L) with the
    /// same m, l, g.
    pub fn from_spherical(&self, z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("spherical-pendulum state (u, L)", z, 6)?;
        check::finite_slice("spherical-pendulum state (u, L)", z)?;
        // (u, L) must be a spherical-pendulum state (|u| = 1, u·L = 0), as its check_state asks.
        crate::systems::tops::spherical_pendulum::check_pendulum_state(z)?;
        let u = Vector3::from_column_slice(&z[..3]);
        let l = Vector3::from_column_slice(&z[3..]);
        let q = u * self.bob.length;
        let p = l.cross(&u) / self.bob.length;
        let out = [q.as_slice(), p.as_slice()].concat();
        if out.iter().any(|x| !x.is_finite()) {
            return Err(check::overflow_error(
                "states",
                "the momentum p = L × u / l",
            ));
        }
        Ok(out)
    }

    /// The [`crate::systems::SphericalPendulum`] state (u, L) = (q/l, q × p) of a state (q, p).
    pub fn to_spherical(&self, z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("state (q, p)", z, 6)?;
        let q = Vector3::from_column_slice(&z[..3]);
        let p = Vector3::from_column_slice(&z[3..]);
        Ok([(q / self.bob.length).as_slice(), q.cross(&p).as_slice()].concat())
    }
}

impl Problem for SphereParticle {
    fn name(&self) -> &'static str {
        "SphereParticle"
    }
    fn space(&self) -> Space {
        Space::new([("q", Block::Real(3)), ("p", Block::Real(3))])
    }
    /// H = |p|²/(2m) + m g q₃.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let p2: f64 = z[3..].iter().map(|x| x * x).sum();
        Ok(0.5 * p2 / self.bob.mass + self.bob.mass * self.bob.gravity * z[2])
    }
    /// [(q × p)₃], the vertical angular momentum.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let q = "the angular momentum (q × p)₃";
        Ok(vec![check::cross2("state", q, [z[0], z[1]], [z[3], z[4]])?])
    }
    fn invariant_names(&self) -> Vec<String> {
        vec!["(q×p)₃".into()]
    }
    /// |q| = l and q·p = 0, to [`CONSTRAINT_TOL`] relative to l and l|p|.
    fn check_state(&self, z: &[f64]) -> Result<()> {
        let r = z[..3].iter().map(|x| x * x).sum::<f64>().sqrt();
        let pn = z[3..].iter().map(|x| x * x).sum::<f64>().sqrt();
        let qp: f64 = (0..3).map(|i| z[i] * z[3 + i]).sum();
        if (r - self.bob.length).abs() > CONSTRAINT_TOL * self.bob.length
            || qp.abs() > CONSTRAINT_TOL * self.bob.length * pn
        {
            return Err(Error::invalid(
                "state",
                format!(
                    "a sphere-particle state needs |q| = l = {} and q·p = 0; got |q| = {r}, \
                     q·p = {qp}",
                    self.bob.length
                ),
            ));
        }
        Ok(())
    }
}

impl Separable for SphereParticle {
    type Scratch = ();
    fn scratch(&self) {}
    fn dof(&self) -> usize {
        3
    }
    /// v = p/m.
    fn velocity(&self, p: &[f64], v: &mut [f64]) {
        for (vi, pi) in v.iter_mut().zip(p) {
            *vi = pi / self.bob.mass;
        }
    }
    /// f = −m g e₃.
    fn force(&self, _q: &[f64], f: &mut [f64], _s: &mut ()) -> std::result::Result<(), Violation> {
        f.copy_from_slice(&[0.0, 0.0, -self.bob.mass * self.bob.gravity]);
        Ok(())
    }
}

impl Constrained for SphereParticle {
    fn constraints(&self) -> usize {
        1
    }
    /// g(q) = (|q|² − l²)/2.
    fn constraint(&self, q: &[f64], g: &mut [f64], _s: &mut ()) {
        g[0] = 0.5 * (q.iter().map(|x| x * x).sum::<f64>() - self.bob.length * self.bob.length);
    }
    /// G(q) = qᵀ.
    fn constraint_jacobian(&self, q: &[f64], jac: &mut [f64], _s: &mut ()) {
        jac.copy_from_slice(q);
    }
    /// D²g(q)[v, v] = |v|² (g is half the squared norm, up to a constant).
    fn constraint_curvature(&self, _q: &[f64], v: &[f64], out: &mut [f64], _s: &mut ()) {
        out[0] = v.iter().map(|x| x * x).sum();
    }
    /// D²g(q)\[u, ·\] = uᵀ.
    fn constraint_second(&self, _q: &[f64], u: &[f64], rows: &mut [f64], _s: &mut ()) -> bool {
        rows.copy_from_slice(u);
        true
    }
    /// D³g = 0 (g is quadratic).
    fn constraint_third(
        &self,
        _q: &[f64],
        _u: &[f64],
        _v: &[f64],
        rows: &mut [f64],
        _s: &mut (),
    ) -> bool {
        rows.fill(0.0);
        true
    }
}

/// v′ = 1/m, f′ = 0 (uniform gravity).
impl SeparableTangent for SphereParticle {
    fn velocity_tangent(&self, _p: &[f64], dp: &[f64], dv: &mut [f64]) {
        self.velocity(dp, dv);
    }
    fn force_tangent(&self, _q: &[f64], _dq: &[f64], df: &mut [f64], _s: &mut ()) {
        df.fill(0.0);
    }
}

impl Catalog for SphereParticle {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![Entry::new("rattle", Rattle::new)]
    }

    /// RATTLE's tangent lift.
    fn tangent(&self) -> Option<Arc<dyn TangentSystem>> {
        Some(Tangent::separable(self.clone()).into_system())
    }
}

impl Catalog for Tangent<SphereParticle> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![Entry::new("rattle", Rattle::new)]
    }
}
