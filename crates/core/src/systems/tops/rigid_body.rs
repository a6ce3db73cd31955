//! The free rigid body (Euler top) on so(3)* (000 §3–§4).
//!
//! **so(3)\*.** Body angular momentum M ∈ R³, Ω = I⁻¹M, Euler's equation Ṁ = M × Ω (000 §4, the
//! Euler–Poincaré equation d/dt ∂ℓ/∂Ω = ∂ℓ/∂Ω × Ω with ℓ = ½ Ω·IΩ); energy H = ½ M·I⁻¹M; Casimir
//! |M|²; attitude Ṙ = R hat(Ω); spatial angular momentum R M is conserved (000 Theorem 4.2).
//! The inertia is given by its principal moments or as a symmetric positive-definite matrix,
//! diagonalised once (I = Q diag Qᵀ, Q ∈ SO(3)); the kernels work in the principal frame
//! (M' = QᵀM, R' = RQ) and the driver maps back. State z = M, or (M, R) for the body that carries
//! its attitude ([`RigidBody::with_attitude`]).

use super::methods::dmv::Dmv;
use super::methods::exact::{Exact, FreeFlow};
use super::methods::isospectral::Isospectral;
use super::methods::lgvi::Lgvi;
use super::top::{self, top_kinds, Top};
use crate::check;
use crate::error::Result;
use crate::integrate::methods::{Rk4, Rkmk4};
use crate::integrate::problem::GroupField;
use crate::integrate::space::Space;
use crate::integrate::{Catalog, Entry, Integrator, Problem, Properties, Stepper};
use crate::lie::so3;
use nalgebra::{Matrix3, Vector3};

/// A free rigid body with inertia tensor I (000 §3.1).
#[derive(Clone, Debug, PartialEq)]
pub struct RigidBody {
    pub(crate) top: Top,
}

impl RigidBody {
    /// A body with principal moments I₁, I₂, I₃ > 0 (body axes = principal axes).
    pub fn new(moments: [f64; 3]) -> Result<Self> {
        top::check_moments(&moments)?;
        Ok(RigidBody {
            top: Top::new(moments, None, None),
        })
    }

    /// A body with a symmetric positive-definite inertia matrix (row-major), diagonalised once.
    pub fn from_matrix(inertia: &[f64; 9]) -> Result<Self> {
        let (moments, q) = top::principal_frame(inertia)?;
        Ok(RigidBody {
            top: Top::new(moments, Some(q), None),
        })
    }

    /// The same body carrying its attitude R ∈ SO(3) along: state (M, R row-major), Ṙ = R hat(Ω);
    /// its invariants add the spatial momentum R M (000 Theorem 4.2).
    pub fn with_attitude(&self) -> Self {
        let mut top = self.top.clone();
        top.set_lifted(true);
        RigidBody { top }
    }

    /// Whether the state carries the attitude.
    pub fn has_attitude(&self) -> bool {
        self.top.lifted
    }

    /// The principal moments (in the order of the principal frame).
    pub fn moments(&self) -> [f64; 3] {
        self.top.moments
    }

    /// The principal frame Q (columns = principal axes in body coordinates), if the inertia was
    /// given as a matrix.
    pub fn frame(&self) -> Option<Matrix3<f64>> {
        self.top.frame
    }

    /// The state (M, R) of the body with attitude (R row-major).
    pub fn state_with_attitude(&self, m: [f64; 3], r: [f64; 9]) -> Vec<f64> {
        [&m[..], &r[..]].concat()
    }

    /// Body angular velocity Ω = I⁻¹M (user frame).
    pub fn angular_velocity(&self, m: &[f64]) -> Result<[f64; 3]> {
        check::len_of("M", m, 3)?;
        let mi = top::to_frame(&self.top.frame, m);
        let w = Vector3::from_fn(|i, _| mi[i] / self.top.moments[i]);
        Ok(top::from_frame(&self.top.frame, &w).into())
    }

    /// Spatial angular momentum R M (000 Theorem 4.2), conserved, of a state (M, R).
    ///
    /// Errors: a non-finite M or R; R not a rotation (to 1e-3, which admits the drift of methods
    /// that do not keep SO(3), such as rk4, and refuses 0, 2I or a reflection).
    pub fn spatial_momentum(z: &[f64]) -> Result<[f64; 3]> {
        check::len_of("state (M, R)", z, 12)?;
        let r = top::observed_attitude("attitude R", &z[3..])?;
        Ok((r * Vector3::from_column_slice(&z[..3])).into())
    }

    /// The exact body momentum M(t) from M(0) = `m0` by Jacobi elliptic functions (user frame).
    ///
    /// With principal moments relabelled (1, 2, 3) so that I₂ is the middle one and
    /// D = |M|²/(2H) lies between I₂ and I₃ (a proper rotation of the axes, one sign flip if the
    /// relabelling is odd): M₁ = σ a₁ cn u, M₂ = a₂ sn u, M₃ = ε a₃ dn u, u = u₀ + λt, σ = sign M₁,
    /// ε = sign M₃ (cf. Landau & Lifshitz, *Mechanics* §37). Every quantity is formed from the
    /// components of M0 and the moments as sums of terms of one sign, never as a difference of the
    /// invariants 2H·I_k − |M|² (d_ij = 1/I_i − 1/I_j, g = d₂₃/d₁₃, h = d₁₂/d₁₃ > 0):
    /// a₁² = M₁² + g M₂², a₂² = M₂² + M₁²/g, a₃² = M₃² + h M₂², m = h a₂²/a₃²,
    /// λ = σε a₃ d₁₃ √g, and the complementary modulus k′ = √(1 − m) = √(e₂ I₃/(I₂ − I₃))/a₃ from
    /// e₂ = 2H I₂ − |M|² = Σ_k M_k² (I₂ − I_k)/I_k = A² − B² = (A − B)(A + B) (one positive and
    /// one negative term: the distance to the separatrix, exactly as accurate as the components);
    /// u₀ = sn₀ R_F(cn₀², dn₀², 1) with sn₀ = M₂/a₂, cn₀ = |M₁|/a₁, dn₀ = |M₃|/a₃ (no amplitude
    /// angle); sn, cn, dn from k′ ([`crate::numerics::elliptic::ellipj_kprime`]), accurate as k′ → 0. M is
    /// evaluated relative to u₀, M(t) = M0 + (a₁(cn u − cn u₀), …) (differences before the
    /// products), so M(0) = M0 exactly and the amplitudes' rounding does not bias a step: the
    /// method `exact` composed with itself random-walks in |M|² and H. On the
    /// separatrix (k′ = 0) this is the heteroclinic solution sn = tanh, cn = dn = sech. Steady
    /// rotations about a principal axis (unstable included) are returned unchanged, and a
    /// symmetric body rotates M uniformly about its symmetry axis.
    /// Errors: non-finite input.
    pub fn exact_momentum(&self, m0: &[f64], t: f64) -> Result<[f64; 3]> {
        check::len_of("M0", m0, 3)?;
        check::finite_slice("M0", m0)?;
        check::finite_slice("t", &[t])?;
        let mi = top::to_frame(&self.top.frame, m0);
        let m = FreeFlow::momentum_at(&self.top.moments, &mi, t);
        Ok(top::from_frame(&self.top.frame, &m).into())
    }
}

impl RigidBody {
    /// Parameter m (`I1`, `I2`, `I3`) as the kernels see it.
    pub(crate) fn top_parameter(&self, m: usize) -> top::TopParam {
        top::TopParam::Moment(m)
    }
}

impl Problem for RigidBody {
    fn name(&self) -> &'static str {
        "RigidBody"
    }

    /// The principal moments I1, I2, I3 (of an inertia given as a matrix: its eigenvalues, in
    /// the order of its principal frame, which stays fixed).
    fn parameters(&self) -> Vec<&'static str> {
        vec!["I1", "I2", "I3"]
    }
    fn space(&self) -> Space {
        self.top.space()
    }
    /// H = ½ M·I⁻¹M.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        Ok(self.top.kinetic_energy(&z[..3]))
    }
    /// |Ω| = |I⁻¹M|.
    fn rate(&self, z: &[f64]) -> Option<f64> {
        Some(self.top.rate(&z[..3]))
    }
    /// [|M|²], and with the attitude also the spatial momentum R M.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let mut c = vec![z[..3].iter().map(|x| x * x).sum()];
        if self.top.lifted {
            c.extend(Self::spatial_momentum(z)?);
        }
        Ok(c)
    }
    fn invariant_names(&self) -> Vec<String> {
        let mut names = vec!["|M|²".to_string()];
        if self.top.lifted {
            names.extend(["(RM)₁", "(RM)₂", "(RM)₃"].map(String::from));
        }
        names
    }
    fn to_internal(&self, z: &mut [f64]) {
        self.top.to_internal(z)
    }
    fn to_user(&self, z: &mut [f64]) {
        self.top.to_user(z)
    }
    fn tangent_to_internal(&self, dz: &mut [f64]) {
        self.top.tangent_frame(dz, false)
    }
    fn tangent_to_user(&self, dz: &mut [f64]) {
        self.top.tangent_frame(dz, true)
    }
}

top_kinds!(RigidBody; ;
    "exact" => || Exact, "rkmk4" => || Rkmk4, "isospectral" => || Isospectral,
    "dmv" => || Dmv(2), "dmv4" => || Dmv(4), "dmv6" => || Dmv(6), "dmv8" => || Dmv(8),
    "dmv10" => || Dmv(10));

/// so(3) in physics coordinates acting on M, or on (M, R) with the attitude (principal frame):
/// ξ(z) = −Ω = −I⁻¹M, and g = exp(ξ̂) acts by g·(M, R) = (gM, R gᵀ), a left action whose
/// generator ξ̂M = M × Ω, −R ξ̂ = R hat(Ω) is Euler's equation with the attitude. It keeps |M|,
/// R ∈ SO(3) and R M.
/// For this left action RKMK needs the right-trivialized dexp, which is the left Jacobian
/// ([`so3::jacobian_left`]: exp(u + δ) = exp(J_l(u)δ) exp(u) to first order in δ), so
/// dexp⁻¹_u = J_l(u)⁻¹ (checked against finite differences of exp in the tests).
impl GroupField for RigidBody {
    type Scratch = ();
    fn scratch(&self) {}
    fn algebra_dim(&self) -> usize {
        3
    }
    fn generator(&self, z: &[f64], xi: &mut [f64], _s: &mut ()) {
        for (i, x) in xi.iter_mut().enumerate() {
            *x = -z[i] / self.top.moments[i];
        }
    }
    /// By increments (`so3::Rodrigues`: exp(ξ̂) formed as a matrix biases |M|² and RᵀR the same
    /// way at every step of a steady rotation).
    fn act(&self, xi: &[f64], z: &mut [f64], s: &mut ()) {
        let mut dz = [0.0; 12];
        let n = z.len();
        self.act_increment(xi, z, &mut dz[..n], s);
        z.iter_mut().zip(dz).for_each(|(zi, d)| *zi += d);
    }
    /// (exp(ξ̂)M − M, rows exp(ξ̂)r − r): [`so3::Rodrigues::increment`].
    fn act_increment(&self, xi: &[f64], z: &[f64], dz: &mut [f64], _s: &mut ()) -> bool {
        let g = so3::Rodrigues::exp(&Vector3::from_column_slice(xi));
        let n = if self.top.lifted { 4 } else { 1 };
        for (v, d) in z.chunks_exact(3).zip(dz.chunks_exact_mut(3)).take(n) {
            d.copy_from_slice(g.increment(&Vector3::from_column_slice(v)).as_slice());
        }
        true
    }
    /// J_l(u)⁻¹ v; NaN where J_l is singular (|u| = 2πk, k ≥ 1).
    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], _s: &mut ()) {
        match so3::jacobian_left_inv(&Vector3::from_column_slice(u)) {
            Ok(j) => out.copy_from_slice((j * Vector3::from_column_slice(v)).as_slice()),
            Err(_) => out.fill(f64::NAN),
        }
    }
}

/// The derivatives of the action of [`GroupField`] for its tangent lift (RKMK4 with
/// sensitivities): g = exp(û), δg = ŵ g with w = J_l(u)δu, so δ(gM) = g δM + w × gM and, for
/// R' = R gᵀ with δR = R η̂, δR' = R'((gη)^ − ŵ): η' = gη − w; D_u(J_l(u)w)\[δu\] is
/// [`so3::jacobian_left_derivative`].
impl crate::integrate::tangent::GroupFieldTangent for RigidBody {
    fn generator_tangent(&self, _z: &[f64], dz: &[f64], dxi: &mut [f64], _s: &mut ()) {
        for (i, x) in dxi.iter_mut().enumerate() {
            *x = -dz[i] / self.top.moments[i];
        }
    }
    /// ∂(−M_m/I_m)/∂I_m = M_m/I_m².
    fn generator_parameter(&self, z: &[f64], m: usize, dxi: &mut [f64], _s: &mut ()) {
        dxi[m] += z[m] / (self.top.moments[m] * self.top.moments[m]);
    }
    fn act_tangent(&self, u: &[f64], du: &[f64], y: &[f64], dz: &mut [f64], _s: &mut ()) {
        let (g, jl) = so3::exp_and_jacobian_left(&Vector3::from_column_slice(u));
        let w = jl * Vector3::from_column_slice(du);
        let dm = g * Vector3::from_column_slice(&dz[..3])
            + w.cross(&Vector3::from_column_slice(&y[..3]));
        dz[..3].copy_from_slice(dm.as_slice());
        if self.top.lifted {
            let eta = g * Vector3::from_column_slice(&dz[3..6]) - w;
            dz[3..6].copy_from_slice(eta.as_slice());
        }
    }
    fn dexp_tangent(&self, u: &[f64], du: &[f64], w: &[f64], out: &mut [f64], _s: &mut ()) {
        let q = so3::jacobian_left_derivative(
            &Vector3::from_column_slice(u),
            &Vector3::from_column_slice(du),
        );
        out.copy_from_slice((q * Vector3::from_column_slice(w)).as_slice());
    }
}

impl RigidBody {
    /// The exact motion (M(t), R(t)) from (M0, R0) (user frame, R row-major): M by Jacobi
    /// elliptic functions ([`RigidBody::exact_momentum`]) and R(t) = R₀ B₀ᵀ Z(φ(t)) B(t), the
    /// factorisation of Celledoni et al. (2008) through the conserved spatial momentum R M, with
    /// the precession angle φ from Carlson's R_J split into ω̄t and a periodic part evaluated on
    /// the reduced argument (module docs of `systems::exact_flow`). Accurate to a few ε·(1 + ω t)
    /// for every t, near the separatrix, for symmetric bodies (closed form) and steady rotations.
    ///
    /// Errors: non-finite input; R0 not a rotation (to [`so3::ROTATION_TOL`]); |t| so large that
    /// a phase of the motion exceeds [`crate::numerics::angle::EXP_MAX_NORM`] (lost to rounding).
    pub fn exact_motion(&self, m0: &[f64], r0: &[f64], t: f64) -> Result<([f64; 3], [f64; 9])> {
        check::len_of("M0", m0, 3)?;
        check::len_of("R0", r0, 9)?;
        check::finite_slice("M0", m0)?;
        check::finite_slice("t", &[t])?;
        let r0 = Matrix3::from_row_slice(r0);
        so3::check_rotation("R0", &r0)?;
        let mi = top::to_frame(&self.top.frame, m0);
        let flow = FreeFlow::new(&self.top.moments, &mi);
        crate::lie::check_exp_norm("t", "the exact free rigid body flow", t.abs() * flow.rate())?;
        let (m, s) = flow.motion(t);
        let (m, r) = match &self.top.frame {
            Some(q) => (q * m, r0 * q * s * q.transpose()),
            None => (m, r0 * s),
        };
        Ok((m.into(), top::row_major(&r)))
    }
}

impl Integrator<RigidBody> for Exact {
    fn properties(&self) -> Properties {
        Properties::exact()
    }

    fn stepper(&self, body: &RigidBody, dt: f64) -> Result<Box<dyn Stepper>> {
        Ok(self.stepper_for(&body.top, dt))
    }
}

/// The exact flow on the tangent lift: (M(t), R(t)) as the plain method's and the directions by
/// the exact tangent map Dφ_t (and ∂/∂I) of the elliptic solution (module docs of
/// `methods::exact`, "Tangent map").
impl Integrator<crate::integrate::tangent::Tangent<RigidBody>> for Exact {
    fn properties(&self) -> Properties {
        Properties::exact()
    }

    fn stepper(
        &self,
        lift: &crate::integrate::tangent::Tangent<RigidBody>,
        dt: f64,
    ) -> Result<Box<dyn Stepper>> {
        Ok(self.tangent_stepper_for(&lift.problem().top, dt))
    }
}

impl Integrator<RigidBody> for Dmv {
    fn properties(&self) -> Properties {
        Dmv::properties(self)
    }

    fn stepper(&self, body: &RigidBody, dt: f64) -> Result<Box<dyn Stepper>> {
        self.stepper_for(&body.top, dt)
    }
}

/// DMV on the tangent lift, with or without the attitude: the base state as the plain method's
/// and the directions by the derivative of its step (module docs of `methods::dmv`, "Tangent
/// map").
impl Integrator<crate::integrate::tangent::Tangent<RigidBody>> for Dmv {
    fn properties(&self) -> Properties {
        Dmv::properties(self)
    }

    fn stepper(
        &self,
        lift: &crate::integrate::tangent::Tangent<RigidBody>,
        dt: f64,
    ) -> Result<Box<dyn Stepper>> {
        self.tangent_stepper_for(&lift.problem().top, dt)
    }
}

impl Catalog for RigidBody {
    fn kind_catalog() -> Vec<Entry<Self>> {
        let mut catalog = top::splittings();
        catalog.extend([
            Entry::new("isospectral", || Isospectral),
            Entry::new("lgvi", || Lgvi),
            Entry::new("dmv", || Dmv(2)),
            Entry::new("dmv4", || Dmv(4)),
            Entry::new("dmv6", || Dmv(6)),
            Entry::new("dmv8", || Dmv(8)),
            Entry::new("dmv10", || Dmv(10)),
            Entry::new("rk4", || Rk4),
            Entry::new("rkmk4", || Rkmk4),
            Entry::new("exact", || Exact),
        ]);
        catalog
    }

    fn dissipation(
        &self,
        d: &crate::integrate::forcing::Dissipation,
    ) -> crate::Result<std::sync::Arc<dyn crate::integrate::forcing::Perturbation>> {
        crate::integrate::forcing::double_bracket(self, d)
    }

    fn lifted(&self) -> Option<Self> {
        Some(self.with_attitude())
    }

    /// The tangent lift of every method (with the attitude `rk4` through [`Catalog::tangent_for`]); with the attitude
    /// its directions are left-trivialised (δR = Rξ̂).
    fn tangent(&self) -> Option<std::sync::Arc<dyn crate::integrate::tangent::TangentSystem>> {
        Some(crate::integrate::tangent::Tangent::split(self.clone()).into_system())
    }

    /// With the attitude, `rk4` on the field lift (ambient directions).
    fn tangent_for(
        &self,
        method: &str,
    ) -> Option<std::sync::Arc<dyn crate::integrate::tangent::TangentSystem>> {
        crate::integrate::tangent::Tangent::routed(self, method, || self.tangent())
    }
}
