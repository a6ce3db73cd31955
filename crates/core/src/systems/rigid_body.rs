//! The free rigid body (Euler top) on so(3)* (000 §3–§4) and the generalized rigid body on so(n)*
//! (Euler–Arnold / Manakov equations, the form of 001 (7.25)).
//!
//! **so(3)\*.** Body angular momentum M ∈ R³, Ω = I⁻¹M, Euler's equation Ṁ = M × Ω (000 §4, the
//! Euler–Poincaré equation d/dt ∂ℓ/∂Ω = ∂ℓ/∂Ω × Ω with ℓ = ½ Ω·IΩ); energy H = ½ M·I⁻¹M; Casimir
//! |M|²; attitude Ṙ = R hat(Ω); spatial angular momentum R M is conserved (000 Theorem 4.2).
//! The inertia is given by its principal moments or as a symmetric positive-definite matrix,
//! diagonalised once (I = Q diag Qᵀ, Q ∈ SO(3)); the kernels work in the principal frame
//! (M' = QᵀM, R' = RQ) and the driver maps back. State z = M, or (M, R) for the body that carries
//! its attitude ([`RigidBody::with_attitude`]).
//!
//! **so(n)\*.** M = JΩ + ΩJ with J = diag(J_i) (the mass matrix; a symmetric J is diagonalised
//! once), so Ω_ij = M_ij / (J_i + J_j); Ṁ = [M, Ω]; H = ½⟨M, Ω⟩ = ½ Σ_{i<j} M_ij Ω_ij; Casimirs
//! C_k = ½ tr((MᵀM)^k), k = 1…⌊n/2⌋ (they fix the spectrum of M). Coordinates are the e_ij
//! coordinates of `lie::so::vee_n`. Sign check against so(3): the matrix of the physics hat map
//! satisfies [hat M, hat Ω] = hat(M × Ω), so Ṁ = [M, Ω] is Euler's equation; in e_ij coordinates
//! c = (−w₃, w₂, −w₁), and with J_i + J_j = I_k ({i, j, k} = {1, 2, 3}) the energies agree (tested).

use super::dmv::Dmv;
use super::exact_flow::{Exact, FreeFlow};
use super::isospectral::Isospectral;
use super::lgvi::Lgvi;
use super::top::{self, top_kinds, Top};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::{
    Composition, Processed, ProcessedSplitting, Rk4, Rkmk4, Splitting,
};
use crate::integrate::problem::{GroupField, VectorField};
use crate::integrate::space::{Block, Space};
use crate::integrate::{Catalog, Entry, Integrator, Problem, Properties, Stepper};
use crate::lie::{so, so3};
use crate::Mat;
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
    /// angle); sn, cn, dn from k′ ([`crate::elliptic::ellipj_kprime`]), accurate as k′ → 0. On the
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

impl Problem for RigidBody {
    fn name(&self) -> &'static str {
        "RigidBody"
    }
    fn space(&self) -> Space {
        self.top.space()
    }
    /// H = ½ M·I⁻¹M.
    fn energy(&self, z: &[f64]) -> Result<f64> {
        Ok(self.top.kinetic_energy(&z[..3]))
    }
    /// [|M|²], and with the attitude also the spatial momentum R M.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let mut c = vec![z[..3].iter().map(|x| x * x).sum()];
        if self.top.lifted {
            c.extend(Self::spatial_momentum(z)?);
        }
        Ok(c)
    }
    fn invariant_count(&self) -> usize {
        if self.top.lifted {
            4
        } else {
            1
        }
    }
    fn to_internal(&self, z: &mut [f64]) {
        self.top.to_internal(z)
    }
    fn to_user(&self, z: &mut [f64]) {
        self.top.to_user(z)
    }
}

top_kinds!(RigidBody);

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

impl RigidBody {
    /// The exact motion (M(t), R(t)) from (M0, R0) (user frame, R row-major): M by Jacobi
    /// elliptic functions ([`RigidBody::exact_momentum`]) and R(t) = R₀ B₀ᵀ Z(φ(t)) B(t), the
    /// factorisation of Celledoni et al. (2008) through the conserved spatial momentum R M, with
    /// the precession angle φ from Carlson's R_J split into ω̄t and a periodic part evaluated on
    /// the reduced argument (module docs of `systems::exact_flow`). Accurate to a few ε·(1 + ω t)
    /// for every t, near the separatrix, for symmetric bodies (closed form) and steady rotations.
    ///
    /// Errors: non-finite input; R0 not a rotation (to [`so3::ROTATION_TOL`]); |t| so large that
    /// a phase of the motion exceeds [`crate::lie::EXP_MAX_NORM`] (lost to rounding).
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

impl Integrator<RigidBody> for Dmv {
    fn properties(&self) -> Properties {
        Dmv::properties(self)
    }

    fn stepper(&self, body: &RigidBody, dt: f64) -> Result<Box<dyn Stepper>> {
        self.stepper_for(&body.top, dt)
    }
}

impl Catalog for RigidBody {
    fn catalog(&self) -> Vec<Entry<Self>> {
        vec![
            Entry::new("splitting", Splitting::strang()),
            Entry::new("splitting4", Splitting(Composition::suzuki4())),
            Entry::new("splitting6", Splitting(Composition::yoshida6())),
            Entry::new("splitting8", Splitting(Composition::kahan_li8())),
            Entry::new("processed6", ProcessedSplitting(Processed::bcm6())),
            Entry::new("processed8", ProcessedSplitting(Processed::bcm8())),
            Entry::new("processed10", ProcessedSplitting(Processed::bcm10())),
            Entry::new("isospectral", Isospectral),
            Entry::new("lgvi", Lgvi),
            Entry::new("dmv", Dmv(2)),
            Entry::new("dmv4", Dmv(4)),
            Entry::new("dmv6", Dmv(6)),
            Entry::new("dmv8", Dmv(8)),
            Entry::new("dmv10", Dmv(10)),
            Entry::new("rk4", Rk4),
            Entry::new("rkmk4", Rkmk4),
            Entry::new("exact", Exact),
        ]
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
}

/// The generalized rigid body on so(n)*: M = JΩ + ΩJ, Ṁ = [M, Ω] (Euler–Arnold; Manakov).
#[derive(Clone, Debug, PartialEq)]
pub struct GeneralizedRigidBody {
    n: usize,
    j: Vec<f64>,
    frame: Option<Mat>,
    /// d_ij = J_i + J_j, row-major n×n (diagonal unused).
    d: Vec<f64>,
    /// (coordinate index, sign) of entry (i, j) of hat_n, row-major; sign 0 on the diagonal.
    index: Vec<(usize, f64)>,
}

impl GeneralizedRigidBody {
    /// A body with principal mass-matrix entries J_i ≥ 0, n ≥ 2, J_i + J_j > 0 for i ≠ j.
    pub fn new(j: &[f64]) -> Result<Self> {
        let n = j.len();
        if n < 2 {
            return Err(Error::shape("J", "(n,) with n ≥ 2", format!("({n},)")));
        }
        check::finite_slice("J", j)?;
        // The body keeps dense n×n tables (and its steppers n×n scratch): refuse what cannot be
        // allocated instead of aborting.
        check::dense_size("J", n, n)?;
        for (i, &ji) in j.iter().enumerate() {
            if ji < 0.0 {
                return Err(Error::invalid("J", format!("J[{i}] = {ji} < 0")));
            }
        }
        let mut d = vec![0.0; n * n];
        let mut index = vec![(0usize, 0.0); n * n];
        let mut c = 0;
        for i in 0..n {
            for k in i + 1..n {
                let s = j[i] + j[k];
                if s <= 0.0 {
                    return Err(Error::invalid(
                        "J",
                        format!("J[{i}] + J[{k}] = {s} must be > 0 (non-positive inertia)"),
                    ));
                }
                d[i * n + k] = s;
                d[k * n + i] = s;
                index[i * n + k] = (c, 1.0);
                index[k * n + i] = (c, -1.0);
                c += 1;
            }
        }
        Ok(GeneralizedRigidBody {
            n,
            j: j.to_vec(),
            frame: None,
            d,
            index,
        })
    }

    /// A body with a symmetric positive-semidefinite mass matrix J (n×n), diagonalised once.
    pub fn from_matrix(j: &Mat) -> Result<Self> {
        let n = check::square("J", j, 2)?;
        let asym = (0..n)
            .flat_map(|a| (0..n).map(move |b| (a, b)))
            .fold(0.0f64, |s, (a, b)| s.max((j[(a, b)] - j[(b, a)]).abs()));
        if asym > 1e-12 * j.norm_l2().max(1.0) {
            return Err(Error::invalid(
                "J",
                format!("not symmetric (max |J − Jᵀ| = {asym:.3e})"),
            ));
        }
        let eig = j
            .self_adjoint_eigen(faer::Side::Lower)
            .map_err(|e| Error::invalid("J", format!("eigendecomposition failed: {e:?}")))?;
        // Round-off can leave a zero eigenvalue of a PSD J slightly negative: clamp those within
        // 1e-12·‖J‖ to 0 and let `new` reject what is truly negative.
        let floor = 1e-12 * j.norm_l2();
        let vals: Vec<f64> = (0..n)
            .map(|i| eig.S()[i])
            .map(|v| if v < 0.0 && v >= -floor { 0.0 } else { v })
            .collect();
        let mut q = Mat::from_fn(n, n, |a, b| eig.U()[(a, b)]);
        if q.determinant() < 0.0 {
            for a in 0..n {
                q[(a, n - 1)] = -q[(a, n - 1)];
            }
        }
        let mut body = Self::new(&vals)?;
        body.frame = Some(q);
        Ok(body)
    }

    /// n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The principal entries J_i.
    pub fn principal(&self) -> &[f64] {
        &self.j
    }

    fn entry(&self, z: &[f64], i: usize, k: usize) -> f64 {
        let (c, s) = self.index[i * self.n + k];
        s * z[c]
    }

    pub(crate) fn dense(&self, z: &[f64], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate() {
            let (c, s) = self.index[k];
            *o = s * z[c];
        }
    }

    pub(crate) fn coords(&self, m: &[f64], z: &mut [f64]) {
        let n = self.n;
        let mut c = 0;
        for i in 0..n {
            for k in i + 1..n {
                z[c] = m[i * n + k];
                c += 1;
            }
        }
    }

    /// The denominators d_ij = J_i + J_j (row-major n×n, diagonal unused).
    pub(crate) fn denominators(&self) -> &[f64] {
        &self.d
    }

    fn conjugate(&self, z: &mut [f64], transpose_first: bool) {
        if let Some(q) = &self.frame {
            let m = so::hat_n_unchecked(self.n, z);
            let m = if transpose_first {
                q.transpose() * &m * q
            } else {
                q * &m * q.transpose()
            };
            z.copy_from_slice(&so::vee_n_unchecked(&m));
        }
    }
}

impl Problem for GeneralizedRigidBody {
    fn name(&self) -> &'static str {
        "GeneralizedRigidBody"
    }
    fn space(&self) -> Space {
        Space::new([("M", Block::SoDual(self.n))])
    }
    /// H = ½ Σ_{i<j} M_ij² / (J_i + J_j) (principal frame).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let mut zi = z.to_vec();
        self.to_internal(&mut zi);
        let n = self.n;
        let mut e = 0.0;
        for i in 0..n {
            for k in i + 1..n {
                let m = self.entry(&zi, i, k);
                e += m * m / self.d[i * n + k];
            }
        }
        Ok(0.5 * e)
    }
    /// C_k = ½ tr((MᵀM)^k), k = 1…⌊n/2⌋ (C₁ = |M|² on so(3)).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let m = so::hat_n_unchecked(self.n, z);
        Ok(crate::lie::so::spectral_invariants(&m))
    }
    fn invariant_count(&self) -> usize {
        self.n / 2
    }
    fn to_internal(&self, z: &mut [f64]) {
        self.conjugate(z, true);
    }
    fn to_user(&self, z: &mut [f64]) {
        self.conjugate(z, false);
    }
}

impl VectorField for GeneralizedRigidBody {
    /// Ṁ = [M, Ω] in e_ij coordinates (principal frame).
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let n = self.n;
        let om = |i: usize, k: usize| {
            if i == k {
                0.0
            } else {
                self.entry(z, i, k) / self.d[i * n + k]
            }
        };
        let mut c = 0;
        for i in 0..n {
            for j in i + 1..n {
                let mut s = 0.0;
                for k in 0..n {
                    s += self.entry(z, i, k) * om(k, j) - om(i, k) * self.entry(z, k, j);
                }
                dz[c] = s;
                c += 1;
            }
        }
    }
}

impl Catalog for GeneralizedRigidBody {
    fn catalog(&self) -> Vec<Entry<Self>> {
        vec![
            Entry::new("isospectral", Isospectral),
            Entry::new("rk4", Rk4),
            Entry::new("rkmk4", Rkmk4),
        ]
    }

    fn dissipation(
        &self,
        d: &crate::integrate::forcing::Dissipation,
    ) -> crate::Result<std::sync::Arc<dyn crate::integrate::forcing::Perturbation>> {
        crate::integrate::forcing::double_bracket(self, d)
    }
}

/// so(n) in e_ij coordinates acting on so(n)* (principal frame): ξ(M) = −Ω, so that the generator
/// [ξ, M] = [M, Ω] is the Euler–Arnold equation, and g = exp(ξ) acts by M ↦ gMgᵀ (a left action
/// that keeps the spectrum of M). The kernels work on the dense skew matrices in [`SoScratch`],
/// without allocation: exp − I by scaling and squaring of its Taylor series, dexp⁻¹ by its
/// Bernoulli series (the conventions of [`so::exp`] and [`so::dexp_inv`], checked against them in
/// the tests).
impl GroupField for GeneralizedRigidBody {
    type Scratch = SoScratch;
    fn scratch(&self) -> SoScratch {
        SoScratch::new(self.n)
    }
    fn algebra_dim(&self) -> usize {
        so::dim(self.n)
    }
    fn generator(&self, z: &[f64], xi: &mut [f64], _s: &mut SoScratch) {
        let n = self.n;
        let mut c = 0;
        for i in 0..n {
            for k in i + 1..n {
                xi[c] = -z[c] / self.d[i * n + k];
                c += 1;
            }
        }
    }
    /// M ← gMgᵀ = M + (P − Pᵀ) + P(g − I)ᵀ with P = (g − I)M: the increment is formed from
    /// g − I (summed apart from I), so its rounding errors are relative to |ξ||M| rather than
    /// |M| (with g itself the spectrum drifts by ~1e-16 per step, systematically).
    fn act(&self, xi: &[f64], z: &mut [f64], s: &mut SoScratch) {
        let mut dz = std::mem::take(&mut s.dz);
        self.act_increment(xi, z, &mut dz, s);
        z.iter_mut().zip(&dz).for_each(|(zi, d)| *zi += d);
        s.dz = dz;
    }
    /// gMgᵀ − M = (G M + M Gᵀ) + G M Gᵀ with G = exp(ξ) − I, in e_ij coordinates.
    fn act_increment(&self, xi: &[f64], z: &[f64], dz: &mut [f64], s: &mut SoScratch) -> bool {
        let n = self.n;
        self.dense(xi, &mut s.a);
        s.expm1();
        self.dense(z, &mut s.m);
        matmul(n, &s.g, &s.m, &mut s.b);
        let mut c = 0;
        for i in 0..n {
            for j in i + 1..n {
                let q: f64 = (0..n).map(|k| s.b[i * n + k] * s.g[j * n + k]).sum();
                dz[c] = (s.b[i * n + j] - s.b[j * n + i]) + q;
                c += 1;
            }
        }
        true
    }
    /// Σ_k B_k/k! ad_uᵏ v, summed until a bound of the tail is below 10⁻¹⁷ of the sum; NaN for
    /// |u| ≥ π/2 (the series converges for |u| < π; the bound keeps the number of terms ≤ 64).
    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], s: &mut SoScratch) {
        let n = self.n;
        let nu = u.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !nu.is_finite() || nu >= std::f64::consts::FRAC_PI_2 || v.iter().any(|x| !x.is_finite())
        {
            out.fill(f64::NAN);
            return;
        }
        self.dense(u, &mut s.a);
        self.dense(v, &mut s.m);
        out.copy_from_slice(v);
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut bound = 1.0;
        for &ck in &so::bernoulli_coefficients()[1..] {
            // p ← [u, p] = u p − (u p)ᵀ for skew u, p.
            matmul(n, &s.a, &s.m, &mut s.b);
            let mut c = 0;
            let mut pn = 0.0;
            for i in 0..n {
                s.m[i * n + i] = 0.0;
                for j in i + 1..n {
                    let x = s.b[i * n + j] - s.b[j * n + i];
                    s.m[i * n + j] = x;
                    s.m[j * n + i] = -x;
                    out[c] += ck * x;
                    pn += x * x;
                    c += 1;
                }
            }
            // |b_j| ≤ 4/(2π)^j (j ≥ 2) and |ad_uʲ⁻ᵏ p| ≤ (2|u|)^{j−k} |p|, so the terms after k
            // sum to at most 4|p|/(2π)^k · r/(1 − r) ≤ 4|p|/(2π)^k, r = |u|/π ≤ ½.
            bound /= two_pi;
            let sum = out.iter().map(|x| x * x).sum::<f64>().sqrt();
            if 4.0 * pn.sqrt() * bound <= 1e-17 * sum || pn == 0.0 {
                return;
            }
        }
    }
}

/// Scratch of the so(n) kernels of [`GeneralizedRigidBody`]'s [`GroupField`]: dense n×n
/// matrices (row-major).
#[derive(Clone, Debug)]
pub struct SoScratch {
    n: usize,
    a: Vec<f64>,
    b: Vec<f64>,
    g: Vec<f64>,
    m: Vec<f64>,
    t: Vec<f64>,
    /// The increment of [`GroupField::act`] (e_ij coordinates).
    dz: Vec<f64>,
}

impl SoScratch {
    fn new(n: usize) -> Self {
        SoScratch {
            n,
            a: vec![0.0; n * n],
            b: vec![0.0; n * n],
            g: vec![0.0; n * n],
            m: vec![0.0; n * n],
            t: vec![0.0; n * n],
            dz: vec![0.0; n * (n - 1) / 2],
        }
    }

    /// g ← exp(a) − I for the skew matrix in `a` (overwritten): the Taylor series of exp − I at
    /// a/2ˢ, ‖a/2ˢ‖_F ≤ ½, summed until a term is below 10⁻¹⁸ (at most 17 terms), then s
    /// doublings exp(2x) − I = 2(eˣ − I) + (eˣ − I)², which keep the small increment apart from I.
    fn expm1(&mut self) {
        let n = self.n;
        let norm = self.a.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !norm.is_finite() {
            self.g.fill(f64::NAN);
            return;
        }
        let mut doublings = 0;
        let mut scale = 1.0;
        while norm * scale > 0.5 {
            scale *= 0.5;
            doublings += 1;
        }
        self.a.iter_mut().for_each(|x| *x *= scale);
        // g = a, t = a; then t ← t a / k, g += t.
        self.t.copy_from_slice(&self.a);
        self.g.copy_from_slice(&self.a);
        for k in 2..=30 {
            matmul(n, &self.t, &self.a, &mut self.b);
            let inv = 1.0 / k as f64;
            let mut tn = 0.0;
            for ((t, b), g) in self.t.iter_mut().zip(&self.b).zip(self.g.iter_mut()) {
                *t = b * inv;
                *g += *t;
                tn += *t * *t;
            }
            if tn.sqrt() <= 1e-18 {
                break;
            }
        }
        for _ in 0..doublings {
            matmul(n, &self.g, &self.g, &mut self.b);
            for (g, b) in self.g.iter_mut().zip(&self.b) {
                *g = 2.0 * *g + b;
            }
        }
    }
}

/// c = a·b for dense row-major n×n matrices.
fn matmul(n: usize, a: &[f64], b: &[f64], c: &mut [f64]) {
    for i in 0..n {
        for j in 0..n {
            c[i * n + j] = (0..n).map(|k| a[i * n + k] * b[k * n + j]).sum();
        }
    }
}
