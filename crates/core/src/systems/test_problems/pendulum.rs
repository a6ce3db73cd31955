//! The planar pendulum in canonical coordinates: a test problem for the methods of canonical and
//! separable Hamiltonians.
//!
//! A bob of mass m on a massless rod of length l in gravity g; q the angle from the downward
//! vertical, p = m l² q̇ its conjugate momentum:
//!
//! H = p²/(2ml²) − mgl cos q,   q̇ = p/(ml²),   ṗ = −mgl sin q.
//!
//! **Exact solution** ([`Pendulum::exact`]). Released at rest from the amplitude q₀ (|q₀| < π),
//! with k = sin(q₀/2), ω = √(g/l) and K = K(k²):
//! sin(q/2) = k sn(K − ωt | k²),  p = −2 m l² k ω cn(K − ωt | k²).
//! Derivation: energy conservation gives q̇² = 2ω²(cos q − cos q₀) = 4ω²(k² − sin²(q/2)); with
//! sin(q/2) = k sn u, u = K − ωt, differentiation gives ½ cos(q/2) q̇ = −kω cn u dn u, and
//! cos(q/2) = dn u (|q| < π), so q̇ = −2kω cn u, which satisfies the energy equation; at t = 0,
//! sn K = 1 and cn K = 0 give q = q₀, p = 0.

use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::{Gauss, Rk4, Verlet, IMPLICIT_MIDPOINT};
use crate::integrate::problem::{Canonical, Separable, VectorField, Violation};
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{
    separable_field_tangent, SeparableTangent, Tangent, VectorFieldTangent,
};
use crate::integrate::{Entry, Problem};
use crate::numerics::elliptic::{ellipj, ellipk};

/// The parameters every pendulum shares: a bob of mass m > 0 on a massless rod of length l > 0 in
/// gravity g ≥ 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Bob {
    pub(crate) mass: f64,
    pub(crate) length: f64,
    pub(crate) gravity: f64,
}

impl Bob {
    /// Checked parameters.
    pub(crate) fn new(mass: f64, length: f64, gravity: f64) -> Result<Self> {
        check::positive("mass", mass)?;
        check::positive("length", length)?;
        if !(gravity.is_finite() && gravity >= 0.0) {
            return Err(Error::invalid(
                "gravity",
                format!("expected a finite number ≥ 0, got {gravity}"),
            ));
        }
        Ok(Bob {
            mass,
            length,
            gravity,
        })
    }

    /// The moment of inertia m l² about the pivot.
    pub(crate) fn inertia(&self) -> f64 {
        self.mass * self.length * self.length
    }

    /// m g l.
    pub(crate) fn mgl(&self) -> f64 {
        self.mass * self.gravity * self.length
    }
}

/// A planar pendulum with mass m, length l and gravity g; state z = (q, p).
#[derive(Clone, Debug, PartialEq)]
pub struct Pendulum {
    bob: Bob,
}

impl Pendulum {
    /// m > 0, l > 0, g ≥ 0.
    pub fn new(mass: f64, length: f64, gravity: f64) -> Result<Self> {
        Ok(Pendulum {
            bob: Bob::new(mass, length, gravity)?,
        })
    }

    /// The exact state (q, p) at time t of the pendulum released at rest from the angle
    /// `amplitude` (module docs). Errors: |amplitude| ≥ π (no oscillation), non-finite input.
    pub fn exact(&self, amplitude: f64, t: f64) -> Result<[f64; 2]> {
        check::finite_slice("amplitude and t", &[amplitude, t])?;
        if amplitude.abs() >= std::f64::consts::PI {
            return Err(Error::invalid(
                "amplitude",
                format!("an oscillation needs |amplitude| < π, got {amplitude}"),
            ));
        }
        let k = (0.5 * amplitude).sin();
        let m = k * k;
        let w = (self.bob.gravity / self.bob.length).sqrt();
        let (sn, cn, _) = ellipj(ellipk(m)? - w * t, m)?;
        Ok([
            2.0 * (k * sn).asin(),
            -2.0 * self.bob.inertia() * k * w * cn,
        ])
    }
}

impl Problem for Pendulum {
    fn name(&self) -> &'static str {
        "Pendulum"
    }
    fn space(&self) -> Space {
        Space::new([("q", Block::Real(1)), ("p", Block::Real(1))])
    }
    /// H = p²/(2ml²) − mgl cos q.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        Ok(self.hamiltonian(&z[..1], &z[1..]))
    }
    /// None: a pendulum has no conserved quantity besides its energy (which no method here keeps
    /// exactly).
    fn invariants(&self, _z: &[f64]) -> Result<Vec<f64>> {
        Ok(Vec::new())
    }
    fn invariant_names(&self) -> Vec<String> {
        Vec::new()
    }
}

impl Canonical for Pendulum {
    fn dof(&self) -> usize {
        1
    }
    fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64 {
        0.5 * p[0] * p[0] / self.bob.inertia() - self.bob.mgl() * q[0].cos()
    }
    /// ∂H/∂q = mgl sin q, ∂H/∂p = p/(ml²).
    fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
        hq[0] = self.bob.mgl() * q[0].sin();
        hp[0] = p[0] / self.bob.inertia();
    }
}

impl Separable for Pendulum {
    type Scratch = ();
    fn scratch(&self) {}
    fn dof(&self) -> usize {
        1
    }
    /// v = p/(ml²).
    fn velocity(&self, p: &[f64], v: &mut [f64]) {
        v[0] = p[0] / self.bob.inertia();
    }
    /// f = −mgl sin q.
    fn force(&self, q: &[f64], f: &mut [f64], _s: &mut ()) -> std::result::Result<(), Violation> {
        f[0] = -self.bob.mgl() * q[0].sin();
        Ok(())
    }
}

/// The pendulum's methods, for it and for its tangent lift.
fn methods<P: Separable + VectorField + Clone + 'static>() -> Vec<Entry<P>> {
    vec![
        Entry::new("midpoint", || IMPLICIT_MIDPOINT),
        Entry::new("gauss4", || Gauss(2)),
        Entry::new("gauss6", || Gauss(3)),
        Entry::new("verlet", Verlet::strang),
        Entry::new("rk4", || Rk4),
    ]
}

/// v′ = 1/(ml²), f′(q)\[dq\] = −mgl cos q dq.
impl SeparableTangent for Pendulum {
    fn velocity_tangent(&self, _p: &[f64], dp: &[f64], dv: &mut [f64]) {
        dv[0] = dp[0] / self.bob.inertia();
    }
    fn force_tangent(&self, q: &[f64], dq: &[f64], df: &mut [f64], _s: &mut ()) {
        df[0] = -self.bob.mgl() * q[0].cos() * dq[0];
    }
}

impl VectorFieldTangent for Pendulum {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        separable_field_tangent(self, z, dz, out, &mut ());
    }
}

// The tangent lift in the separable layout serves every method (Verlet, Gauss, RK4).
crate::integrate::methods::canonical_system!(Pendulum, methods(), |p: &Pendulum| Some(
    Tangent::separable(p.clone()).into_system()
));
