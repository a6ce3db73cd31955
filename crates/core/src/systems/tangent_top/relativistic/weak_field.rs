//! The symmetric relativistic tangent top in the weak-field limit of a static potential φ(x, y),
//! the Lagrangian 002 (118) with its coupling sign corrected (002 (115)–(120)).

use std::fmt;
use std::sync::Arc;

use nalgebra::Vector3;

use super::lift::{self, DerivsT};
use super::{energy, lagrangian, legendre_inverse, space, state, velocities, Derivs, Legendre};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::space::Space;
use crate::integrate::Problem;
use crate::numerics::dual::{Dual, Real};

/// The rotation by π/2 applied to a 2-vector: J(a, b) = (−b, a).
fn rot90(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}

/// φ, ∇φ = (G_x, G_y) and the Hessian (φ_xx, φ_xy, φ_yy) of a potential at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PotentialValue {
    /// φ.
    pub phi: f64,
    /// G = ∇φ.
    pub grad: [f64; 2],
    /// (φ_xx, φ_xy, φ_yy).
    pub hess: [f64; 3],
}

type PotentialFn = dyn Fn([f64; 2]) -> PotentialValue + Send + Sync;

#[derive(Clone)]
enum PotentialKind {
    PointMass { gm: f64 },
    Uniform { g: [f64; 2] },
    Custom(Arc<PotentialFn>),
}

/// A static gravitational potential φ(x, y) (the g_tt = −e^{2φ} of 002 (115), corrected), with
/// its gradient and Hessian.
#[derive(Clone)]
pub struct Potential {
    kind: PotentialKind,
}

impl fmt::Debug for Potential {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.kind {
            PotentialKind::PointMass { gm } => write!(f, "Potential::point_mass({gm})"),
            PotentialKind::Uniform { g } => write!(f, "Potential::uniform({g:?})"),
            PotentialKind::Custom(_) => write!(f, "Potential::custom(..)"),
        }
    }
}

impl Potential {
    /// φ = −GM/r (r = |x| > 0), a point mass at the origin (the plane through it).
    pub fn point_mass(gm: f64) -> Result<Self> {
        check::positive("GM", gm)?;
        Ok(Potential {
            kind: PotentialKind::PointMass { gm },
        })
    }

    /// φ = g·x, a uniform field of strength −g (the force on the centre is −m g).
    pub fn uniform(g: [f64; 2]) -> Result<Self> {
        check::finite_slice("g", &g)?;
        Ok(Potential {
            kind: PotentialKind::Uniform { g },
        })
    }

    /// A potential given as a closure returning φ, ∇φ and the Hessian at a point (non-finite
    /// values mark points outside its domain).
    pub fn custom(f: impl Fn([f64; 2]) -> PotentialValue + Send + Sync + 'static) -> Self {
        Potential {
            kind: PotentialKind::Custom(Arc::new(f)),
        }
    }

    /// φ, ∇φ and the Hessian at x (non-finite at r = 0 for the point mass).
    pub fn eval(&self, x: [f64; 2]) -> PotentialValue {
        match &self.kind {
            PotentialKind::PointMass { gm } => {
                let r2 = x[0] * x[0] + x[1] * x[1];
                let r = r2.sqrt();
                let r3 = r2 * r;
                let r5 = r3 * r2;
                PotentialValue {
                    phi: -gm / r,
                    grad: [gm * x[0] / r3, gm * x[1] / r3],
                    hess: [
                        gm * (1.0 / r3 - 3.0 * x[0] * x[0] / r5),
                        -3.0 * gm * x[0] * x[1] / r5,
                        gm * (1.0 / r3 - 3.0 * x[1] * x[1] / r5),
                    ],
                }
            }
            PotentialKind::Uniform { g } => PotentialValue {
                phi: g[0] * x[0] + g[1] * x[1],
                grad: *g,
                hess: [0.0; 3],
            },
            PotentialKind::Custom(f) => f(x),
        }
    }
}

impl Potential {
    /// The third derivatives (φ_xxx, φ_xxy, φ_xyy, φ_yyy) at x, which the tangent lift of a
    /// top in the field needs: for the point mass
    /// ∂_i∂_j∂_kφ = GM(15x_ix_jx_k/r⁷ − 3(δ_ijx_k + δ_ikx_j + δ_jkx_i)/r⁵), zero for the uniform
    /// field; None for a custom potential (its value gives no third derivatives).
    pub fn third(&self, x: [f64; 2]) -> Option<[f64; 4]> {
        match &self.kind {
            PotentialKind::PointMass { gm } => {
                let r2 = x[0] * x[0] + x[1] * x[1];
                let r5 = r2 * r2 * r2.sqrt();
                let r7 = r5 * r2;
                let (a, b) = (x[0], x[1]);
                Some([
                    gm * (15.0 * a * a * a / r7 - 9.0 * a / r5),
                    gm * (15.0 * a * a * b / r7 - 3.0 * b / r5),
                    gm * (15.0 * a * b * b / r7 - 3.0 * a / r5),
                    gm * (15.0 * b * b * b / r7 - 9.0 * b / r5),
                ])
            }
            PotentialKind::Uniform { .. } => Some([0.0; 4]),
            PotentialKind::Custom(_) => None,
        }
    }

    /// Whether [`Potential::third`] is given.
    pub fn has_third(&self) -> bool {
        !matches!(self.kind, PotentialKind::Custom(_))
    }

    /// Whether φ is a closure from outside lieflow.
    pub(super) fn calls_out(&self) -> bool {
        matches!(self.kind, PotentialKind::Custom(_))
    }

    /// The invariants of a top in this field at a state z = (x, y, θ, p_x, p_y, p_θ): p_θ (θ is
    /// cyclic), then the momenta of the potential's symmetries: for the point mass the angular
    /// momentum x p_y − y p_x (quadratic in z), for a uniform field the momentum across the
    /// field p·Ĵĝ (linear); none more for a custom potential. The Gauss methods keep all of them.
    pub(super) fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        check::len_of("state", z, 6)?;
        let mut out = vec![z[5]];
        out.extend(match &self.kind {
            PotentialKind::PointMass { .. } => vec![angular_momentum(z)?],
            PotentialKind::Uniform { g } => {
                let n = g[0].hypot(g[1]);
                if n > 0.0 {
                    let t = rot90([g[0] / n, g[1] / n]);
                    vec![t[0] * z[3] + t[1] * z[4]]
                } else {
                    vec![]
                }
            }
            PotentialKind::Custom(_) => vec![],
        });
        Ok(out)
    }

    /// Whether the affine vector field X(x) = A x + b of the chart leaves φ invariant,
    /// X(φ) = 0 everywhere (`a[i][j]` = A_ij): for φ = k·x when Aᵀk = 0 and k·b = 0; for the point
    /// mass when A is skew and b = 0 (x·(Ax + b) = 0 for all x); never for a custom φ (unknown).
    /// The symmetries of the field on a surface ([`StaticFieldTop`](super::StaticFieldTop)).
    pub(super) fn kept_by(&self, a: [[f64; 2]; 2], b: [f64; 2]) -> bool {
        match &self.kind {
            PotentialKind::PointMass { .. } => {
                a[0][0] == 0.0 && a[1][1] == 0.0 && a[0][1] + a[1][0] == 0.0 && b == [0.0, 0.0]
            }
            PotentialKind::Uniform { g } => {
                let atk = [
                    a[0][0] * g[0] + a[1][0] * g[1],
                    a[0][1] * g[0] + a[1][1] * g[1],
                ];
                atk == [0.0, 0.0] && g[0] * b[0] + g[1] * b[1] == 0.0
            }
            PotentialKind::Custom(_) => false,
        }
    }

    /// The number of [`Potential::invariants`].
    /// The labels of [`Potential::invariants`].
    pub(super) fn invariant_names(&self) -> Vec<String> {
        let mut names = vec!["p_θ".to_string()];
        match &self.kind {
            PotentialKind::PointMass { .. } => names.push("x p_y − y p_x".into()),
            PotentialKind::Uniform { g } if g[0].hypot(g[1]) > 0.0 => names.push("p⊥g".into()),
            PotentialKind::Uniform { .. } | PotentialKind::Custom(_) => {}
        }
        names
    }
}

/// x p_y − y p_x of a state (length checked by the caller).
pub(super) fn angular_momentum(z: &[f64]) -> Result<f64> {
    let q = "the angular momentum x p_y − y p_x";
    check::cross2("state", q, [z[0], z[1]], [z[3], z[4]])
}

/// The symmetric relativistic tangent top in a weak static gravitational field, the Lagrangian
/// 002 (118) with its coupling sign corrected (module docs):
/// L = ½mv² − mφ + I₀θ̇²(1 − φ + v²) + I₀θ̇(G_yẋ − G_xẏ), I₀ = 𝕀/2, G = ∇φ.
/// State z = (x, y, θ, p_x, p_y, p_θ).
#[derive(Clone, Debug)]
pub struct WeakFieldTop {
    mass: f64,
    i0: f64,
    potential: Potential,
}

impl WeakFieldTop {
    /// Mass m > 0, 𝕀 = `inertia` > 0 (I₀ = 𝕀/2), and the potential φ.
    pub fn new(mass: f64, inertia: f64, potential: Potential) -> Result<Self> {
        check::positive("mass", mass)?;
        check::positive("inertia", inertia)?;
        Ok(WeakFieldTop {
            mass,
            i0: 0.5 * inertia,
            potential,
        })
    }

    /// The potential.
    pub fn potential(&self) -> &Potential {
        &self.potential
    }

    /// L(q, q̇) of 002 (118) (corrected, physical sign), q = (x, y, θ), q̇ = (ẋ, ẏ, θ̇).
    /// Errors: non-finite input or potential.
    pub fn lagrangian(&self, q: [f64; 3], qdot: [f64; 3]) -> Result<f64> {
        lagrangian(self, q, qdot)
    }

    /// The canonical state with p = ∂L/∂q̇ (see
    /// [`RelativisticTangentTop::state`](super::RelativisticTangentTop::state)).
    pub fn state(
        &self,
        x: [f64; 2],
        theta: f64,
        xdot: [f64; 2],
        thetadot: f64,
    ) -> Result<Vec<f64>> {
        state(self, [x[0], x[1], theta], [xdot[0], xdot[1], thetadot])
    }

    /// The velocities (ẋ, ẏ, θ̇) of a state. Errors: wrong length, non-finite, outside the
    /// potential's domain or the range of the Legendre map.
    pub fn velocities(&self, z: &[f64]) -> Result<[f64; 3]> {
        velocities(self, z)
    }

    /// The angular momentum x p_y − y p_x about the origin (conserved for a central potential).
    pub fn angular_momentum(&self, z: &[f64]) -> Result<f64> {
        check::len_of("state", z, 6)?;
        angular_momentum(z)
    }
}

pub(super) fn outside_potential(q: [f64; 3]) -> Error {
    Error::invalid(
        "x",
        format!(
            "the potential or its derivatives are not finite at ({}, {})",
            q[0], q[1]
        ),
    )
}

impl Problem for WeakFieldTop {
    fn calls_out(&self) -> bool {
        self.potential.calls_out()
    }
    fn name(&self) -> &'static str {
        "WeakFieldTop"
    }
    /// The mass m and the inertia 𝕀: the sensitivities of a tangent run (the
    /// potential's and the surface's constants are not parameters here).
    fn parameters(&self) -> Vec<&'static str> {
        vec!["mass", "inertia"]
    }
    fn space(&self) -> Space {
        space()
    }
    /// E = p·q̇ − L = ½mv² + mφ + I₀θ̇²(1 − φ + 3v²) + I₀θ̇(G_yẋ − G_xẏ) (module docs).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        energy(self, z)
    }
    /// p_θ and the momenta of the field's symmetries (`Potential::invariants`).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.potential.invariants(z)
    }
    fn invariant_names(&self) -> Vec<String> {
        self.potential.invariant_names()
    }
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.velocities(z).map(|_| ())
    }
}

impl WeakFieldTop {
    /// The kernel of (118) over [`Real`] (f64 for the run, [`Dual`] for its tangent lift) at
    /// (q, q̇) with the mass m and I₀ = 𝕀/2; None where φ, its derivatives or q̇ are not finite.
    fn kernel<T: Real>(&self, q: [T; 3], v: [T; 3], m: T, i0: T) -> Option<DerivsT<T>> {
        let k = |x: f64| T::from(x);
        let (phi, grad, hess) = lift::potential(&self.potential, [q[0], q[1]])?;
        let (u, w) = ([v[0], v[1]], v[2]);
        let s = u[0] * u[0] + u[1] * u[1];
        let [gx, gy] = grad;
        let [hxx, hxy, hyy] = hess;
        let c = gy * u[0] - gx * u[1];
        let l = k(0.5) * m * s - m * phi + i0 * w * w * (k(1.0) - phi + s) + i0 * w * c;
        if !(l.is_finite() && hxx.is_finite() && hxy.is_finite() && hyy.is_finite()) {
            return None;
        }
        let a = m + k(2.0) * i0 * w * w;
        let lv = [
            a * u[0] + i0 * w * gy,
            a * u[1] - i0 * w * gx,
            k(2.0) * i0 * w * (k(1.0) - phi + s) + i0 * c,
        ];
        let f = m + i0 * w * w;
        // ∂c/∂x_k = H_yk u_x − H_xk u_y.
        let lq = [
            -f * gx + i0 * w * (hxy * u[0] - hxx * u[1]),
            -f * gy + i0 * w * (hyy * u[0] - hxy * u[1]),
            k(0.0),
        ];
        let h02 = k(4.0) * i0 * w * u[0] + i0 * gy;
        let h12 = k(4.0) * i0 * w * u[1] - i0 * gx;
        let hess = [
            [a, k(0.0), h02],
            [k(0.0), a, h12],
            [h02, h12, k(2.0) * i0 * (k(1.0) - phi + s)],
        ];
        Some(DerivsT { l, lv, lq, hess })
    }

    /// m and I₀, the parameter (0: the mass, 1: the inertia 𝕀 = 2I₀) moved at unit rate.
    fn constants<T: Real>(&self, parameter: Option<usize>) -> (T, T) {
        (
            T::with(self.mass, f64::from(u8::from(parameter == Some(0)))),
            T::with(self.i0, 0.5 * f64::from(u8::from(parameter == Some(1)))),
        )
    }
}

impl Legendre for WeakFieldTop {
    /// Derivatives of L at (q, q̇); None where φ or q̇ is not finite.
    fn derivs(&self, q: &[f64], v: &Vector3<f64>) -> Option<Derivs> {
        let (m, i0) = self.constants(None);
        self.kernel([q[0], q[1], q[2]], [v[0], v[1], v[2]], m, i0)?
            .finite()
    }

    fn derivs_dual(
        &self,
        q: [Dual; 3],
        v: [Dual; 3],
        parameter: Option<usize>,
    ) -> Option<DerivsT<Dual>> {
        let (m, i0) = self.constants(parameter);
        self.kernel(q, v, m, i0)
    }

    /// Where the potential gives its third derivatives (the point mass, the uniform field).
    fn has_hessian(&self) -> bool {
        self.potential.has_third()
    }

    fn solve(&self, q: &[f64], p: &[f64]) -> Option<(Vector3<f64>, Derivs)> {
        let guess = Vector3::new(p[0] / self.mass, p[1] / self.mass, p[2] / (2.0 * self.i0));
        legendre_inverse(p, guess, |v| self.derivs(q, v))
    }

    fn undefined(&self, q: [f64; 3], _v: [f64; 3]) -> Error {
        outside_potential(q)
    }
}
