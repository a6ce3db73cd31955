//! The vertical rolling disk (Bloch, *Nonholonomic Mechanics and Control*, §1.4): a test problem
//! for nonholonomic methods.
//!
//! A disk of mass m and radius R rolls without slipping on the plane, staying vertical;
//! q = (x, y, θ, φ) with (x, y) the contact point, θ the rolling angle and φ the heading. With the
//! moments of inertia I (about the axle) and J (about the vertical),
//!
//! T = ½ m(ẋ² + ẏ²) + ½ I θ̇² + ½ J φ̇²,   U = k(1 − cos φ) + m g̃ x,
//!
//! (a torsional spring of stiffness k on the heading and a plane tilted along x with the gravity
//! component g̃; both optional, [`RollingDisk::with_potential`]) and the rolling constraints
//! ẋ = R cos φ θ̇, ẏ = R sin φ θ̇, i.e. A(q) q̇ = 0 with A = [[1, 0, −R cos φ, 0],
//! [0, 1, −R sin φ, 0]]. The state is z = (q, p), p = M q̇, M = diag(m, m, I, J).
//!
//! **Reduced equations** (Lagrange–d'Alembert, M q̈ = −∇U + Aᵀλ; eliminating λ with the
//! differentiated constraints): ẍ = R cos φ θ̈ − R sin φ φ̇θ̇, ÿ = R sin φ θ̈ + R cos φ φ̇θ̇,
//! λ = (mẍ + mg̃, mÿ), and the θ equation I θ̈ = −R(cos φ λ₁ + sin φ λ₂) becomes
//!
//! (I + mR²) θ̈ = −m g̃ R cos φ,   J φ̈ = −k sin φ,   ẋ = R cos φ θ̇,   ẏ = R sin φ θ̇,
//!
//! with the energy ½(I + mR²)θ̇² + ½Jφ̇² + U conserved. Without potential (k = g̃ = 0) θ̇ and φ̇
//! are constant and the contact point runs on a circle of radius Rθ̇/φ̇ ([`RollingDisk::exact`]).

use std::sync::Arc;

use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::NonholonomicRattle;
use crate::integrate::problem::{Nonholonomic, Separable, Violation};
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{SeparableTangent, Tangent, TangentSystem};
use crate::integrate::{Catalog, Entry, Problem};

/// Relative tolerance of the rolling constraints A(q) M⁻¹p = 0 on a state (relative to |M⁻¹p|).
pub const CONSTRAINT_TOL: f64 = 1e-10;

/// The vertical rolling disk; state z = (x, y, θ, φ, p_x, p_y, p_θ, p_φ).
#[derive(Clone, Debug, PartialEq)]
pub struct RollingDisk {
    mass: f64,
    radius: f64,
    roll_inertia: f64,
    turn_inertia: f64,
    spring: f64,
    tilt: f64,
}

impl RollingDisk {
    /// Mass m, radius R, moments of inertia I (about the axle) and J (about the vertical), all
    /// > 0; no potential.
    pub fn new(mass: f64, radius: f64, roll_inertia: f64, turn_inertia: f64) -> Result<Self> {
        check::positive("mass", mass)?;
        check::positive("radius", radius)?;
        check::positive("roll_inertia", roll_inertia)?;
        check::positive("turn_inertia", turn_inertia)?;
        Ok(RollingDisk {
            mass,
            radius,
            roll_inertia,
            turn_inertia,
            spring: 0.0,
            tilt: 0.0,
        })
    }

    /// The same disk in the potential U = k(1 − cos φ) + m g̃ x (finite k and g̃).
    pub fn with_potential(&self, spring: f64, tilt: f64) -> Result<Self> {
        check::finite_slice("spring and tilt", &[spring, tilt])?;
        Ok(RollingDisk {
            spring,
            tilt,
            ..self.clone()
        })
    }

    /// The state rolling with the rates θ̇, φ̇ from (x, y, θ, φ): p = M q̇ with ẋ = R cos φ θ̇,
    /// ẏ = R sin φ θ̇.
    pub fn state(&self, q: [f64; 4], theta_dot: f64, phi_dot: f64) -> Result<Vec<f64>> {
        check::finite_slice("q", &q)?;
        check::finite_slice("rates", &[theta_dot, phi_dot])?;
        let (s, c) = q[3].sin_cos();
        let v = self.radius * theta_dot;
        Ok(vec![
            q[0],
            q[1],
            q[2],
            q[3],
            self.mass * v * c,
            self.mass * v * s,
            self.roll_inertia * theta_dot,
            self.turn_inertia * phi_dot,
        ])
    }

    /// The exact state at time t from z0 for the disk without potential: θ̇ and φ̇ constant,
    /// x = x₀ + Rθ̇ t cos(φ₀ + φ̇t/2) sinc(φ̇t/2), y = y₀ + Rθ̇ t sin(φ₀ + φ̇t/2) sinc(φ̇t/2) (the
    /// circle of radius Rθ̇/φ̇, a line when φ̇ = 0). Errors: a disk with a potential, a state of
    /// the wrong length or non-finite.
    pub fn exact(&self, z0: &[f64], t: f64) -> Result<Vec<f64>> {
        if self.spring != 0.0 || self.tilt != 0.0 {
            return Err(Error::invalid(
                "RollingDisk",
                "the exact solution is known only without potential (spring = tilt = 0)",
            ));
        }
        check::len_of("z0", z0, 8)?;
        check::finite_slice("z0 and t", &[z0, &[t]].concat())?;
        let (wt, wp) = (z0[6] / self.roll_inertia, z0[7] / self.turn_inertia);
        let half = 0.5 * wp * t;
        let sinc = if half == 0.0 { 1.0 } else { half.sin() / half };
        let chord = self.radius * wt * t * sinc;
        let mid = z0[3] + half;
        self.state(
            [
                z0[0] + chord * mid.cos(),
                z0[1] + chord * mid.sin(),
                z0[2] + wt * t,
                z0[3] + wp * t,
            ],
            wt,
            wp,
        )
    }

    /// The relative constraint residual |A(q) M⁻¹p| / |M⁻¹p| of a state (0 at rest).
    pub fn constraint_residual(&self, z: &[f64]) -> Result<f64> {
        check::len_of("state", z, 8)?;
        let v = [
            z[4] / self.mass,
            z[5] / self.mass,
            z[6] / self.roll_inertia,
            z[7] / self.turn_inertia,
        ];
        let (s, c) = z[3].sin_cos();
        let r = (v[0] - self.radius * c * v[2]).hypot(v[1] - self.radius * s * v[2]);
        // The scale of the terms that cancel: the velocities of the contact point and of the rim.
        let scale = v[0].hypot(v[1]) + self.radius * v[2].abs();
        Ok(if scale == 0.0 { r } else { r / scale })
    }
}

impl Problem for RollingDisk {
    fn name(&self) -> &'static str {
        "RollingDisk"
    }
    fn space(&self) -> Space {
        Space::new([("q", Block::Real(4)), ("p", Block::Real(4))])
    }
    /// H = p_x²/(2m) + p_y²/(2m) + p_θ²/(2I) + p_φ²/(2J) + k(1 − cos φ) + m g̃ x.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let t = 0.5
            * ((z[4] * z[4] + z[5] * z[5]) / self.mass
                + z[6] * z[6] / self.roll_inertia
                + z[7] * z[7] / self.turn_inertia);
        Ok(t + self.spring * (1.0 - z[3].cos()) + self.mass * self.tilt * z[0])
    }
    /// None: with a potential the disk conserves only its energy, which the nonholonomic method
    /// keeps up to a bounded O(h²) error, not exactly.
    fn invariants(&self, _z: &[f64]) -> Result<Vec<f64>> {
        Ok(Vec::new())
    }
    fn invariant_names(&self) -> Vec<String> {
        Vec::new()
    }
    /// The potential's constants: the spring k and the tilt g̃ (the sensitivities ∂z/∂k,
    /// ∂z/∂g̃ of a tangent run; the inertias and the radius enter M and A, which the lift does
    /// not differentiate).
    fn parameters(&self) -> Vec<&'static str> {
        vec!["spring", "tilt"]
    }
    /// The rolling constraints to [`CONSTRAINT_TOL`] ([`RollingDisk::constraint_residual`]).
    fn check_state(&self, z: &[f64]) -> Result<()> {
        let r = self.constraint_residual(z)?;
        if r > CONSTRAINT_TOL {
            return Err(Error::invalid(
                "state",
                format!(
                    "a rolling-disk state needs ẋ = R cos φ θ̇ and ẏ = R sin φ θ̇; the relative \
                     residual is {r:.3e} (tolerance {CONSTRAINT_TOL:.0e}); build it with \
                     RollingDisk::state"
                ),
            ));
        }
        Ok(())
    }
}

impl Separable for RollingDisk {
    type Scratch = ();
    fn scratch(&self) {}
    fn dof(&self) -> usize {
        4
    }
    /// v = M⁻¹p.
    fn velocity(&self, p: &[f64], v: &mut [f64]) {
        v[0] = p[0] / self.mass;
        v[1] = p[1] / self.mass;
        v[2] = p[2] / self.roll_inertia;
        v[3] = p[3] / self.turn_inertia;
    }
    /// f = (−m g̃, 0, 0, −k sin φ).
    fn force(&self, q: &[f64], f: &mut [f64], _s: &mut ()) -> std::result::Result<(), Violation> {
        f.copy_from_slice(&[-self.mass * self.tilt, 0.0, 0.0, -self.spring * q[3].sin()]);
        Ok(())
    }
}

impl Nonholonomic for RollingDisk {
    fn constraints(&self) -> usize {
        2
    }
    /// A(q) = \[\[1, 0, −R cos φ, 0\], \[0, 1, −R sin φ, 0\]\].
    fn constraint_matrix(&self, q: &[f64], a: &mut [f64], _s: &mut ()) {
        let (s, c) = q[3].sin_cos();
        a.copy_from_slice(&[
            1.0,
            0.0,
            -self.radius * c,
            0.0,
            0.0,
            1.0,
            -self.radius * s,
            0.0,
        ]);
    }

    /// DA(q)\[dq\] = dφ \[\[0, 0, R sin φ, 0\], \[0, 0, −R cos φ, 0\]\].
    fn constraint_matrix_tangent(&self, q: &[f64], dq: &[f64], out: &mut [f64], _s: &mut ()) {
        let (s, c) = q[3].sin_cos();
        let r = self.radius * dq[3];
        out.copy_from_slice(&[0.0, 0.0, r * s, 0.0, 0.0, 0.0, -r * c, 0.0]);
    }
}

/// v′ = M⁻¹; f′(q)dq = (0, 0, 0, −k cos φ dφ); ∂f/∂k = (0, 0, 0, −sin φ), ∂f/∂g̃ = (−m, 0, 0, 0).
impl SeparableTangent for RollingDisk {
    fn velocity_tangent(&self, _p: &[f64], dp: &[f64], dv: &mut [f64]) {
        self.velocity(dp, dv);
    }
    fn force_tangent(&self, q: &[f64], dq: &[f64], df: &mut [f64], _s: &mut ()) {
        df.copy_from_slice(&[0.0, 0.0, 0.0, -self.spring * q[3].cos() * dq[3]]);
    }
    fn force_parameter(&self, q: &[f64], m: usize, df: &mut [f64], _s: &mut ()) {
        match m {
            0 => df[3] -= q[3].sin(),
            1 => df[0] -= self.mass,
            _ => df.fill(f64::NAN),
        }
    }
}

impl Catalog for RollingDisk {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![Entry::new("nonholonomic", || NonholonomicRattle)]
    }

    /// The nonholonomic lift (Lagrange–d'Alembert with the lifted constraints and force rows).
    fn tangent(&self) -> Option<Arc<dyn TangentSystem>> {
        Some(Tangent::separable(self.clone()).into_system())
    }
}

impl Catalog for Tangent<RollingDisk> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![Entry::new("nonholonomic", || NonholonomicRattle)]
    }
}
