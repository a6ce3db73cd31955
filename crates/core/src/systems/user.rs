//! User-defined systems (issue 15): Hamiltonians given as functions, integrated with the generic
//! methods of [`crate::integrate::methods`].
//!
//! * [`UserCanonical`]: H(q, p) on T*ℝᵈ, state z = (q, p), with the gradient (∂H/∂q, ∂H/∂p) or,
//!   without it, central differences of H ([`FD_STEP`]); kinds [`Canonical`] and
//!   [`VectorField`]; methods "gauss4" (default), "gauss6", "midpoint", "rk4"
//!   ([`crate::integrate::methods::canonical_catalog`]).
//! * [`UserSeparable`]: H = ½ pᵀM⁻¹p + U(q) with a constant positive-definite mass M (a matrix, or
//!   a scalar or vector for a diagonal one) and U, ∇U functions; kinds [`Separable`] (Störmer–
//!   Verlet and its compositions "verlet" (default), "verlet4", "verlet6"), [`Canonical`] (the
//!   Gauss methods) and [`VectorField`] ("rk4").
//! * [`LiePoisson`]: a Lie–Poisson system on g* (so(3), se(3), so(n) or structure constants),
//!   μ̇ = ad*_{∂H/∂μ} μ, with H a function or a quadratic form ½ μᵀAμ (the native path); kinds
//!   [`GroupField`] (the coadjoint action: "rkmk4" (default), the Lie midpoint "midpoint" and its
//!   Suzuki composition "midpoint4", all of which keep the coadjoint orbit, i.e. every Casimir, to
//!   round-off) and [`VectorField`] ("rk4", the baseline).
//!
//! **Lie–Poisson conventions.** Coordinates μ_k of g* are dual to a basis e_k of g (the pairing
//! is the dot product of coordinates), with [e_i, e_j] = C_ij^k e_k. Then (ad_ξ)_{kj} =
//! Σ_i ξ_i C_ij^k, ad*_ξ μ = ad_ξᵀ μ, i.e. (ad*_ξ μ)_j = Σ_{i,k} C_ij^k ξ_i μ_k, and the equation
//! is μ̇ = ad*_{∇H} μ. Sign check on so(3) (e_k the physics basis, C_ij^k = ε_ijk, [û, v̂] =
//! (u × v)^): ad*_Ω M = −Ω × M = M × Ω, Euler's Ṁ = M × Ω for H = ½ M·I⁻¹M (000 §4; the sign of
//! [`super::RigidBody`], tested against it). On se(3) with ξ = (ω, v) (rotation first, the
//! bracket of [`crate::lie::se3::ad_matrix`]) and μ = (M, Γ): Ṁ = M × Ω + Γ × V, Γ̇ = Γ × Ω with
//! (Ω, V) = ∇H, Kirchhoff's equations of a body in an ideal fluid (Γ the impulse) and the heavy
//! top's (Γ the vertical); Casimirs |Γ|², M·Γ. On so(n) in the e_ij coordinates of
//! [`crate::lie::so::vee_n`] (pairing ½ tr(ξᵀη), 001 (2.8)): Ṁ = [M, Ω], the sign of
//! [`super::GeneralizedRigidBody`]; Casimirs ½ tr((MᵀM)^k), k = 1…⌊n/2⌋.
//!
//! **The coadjoint action as a [`GroupField`].** G acts on g* by g·μ = Ad*_{g⁻¹} μ =
//! Ad_{g⁻¹}ᵀ μ, whose infinitesimal generator is ξ·μ = −ad*_ξ μ; so ξ(μ) = −∇H(μ) gives
//! ξ(μ)·μ = ad*_{∇H} μ. exp(ξ)·μ is computed by the group maps of [`crate::lie`] where the group
//! is built in: so(3) μ ↦ exp(ξ̂) μ ([`so3::exp`]; dexp⁻¹ = J_l⁻¹, [`so3::jacobian_left_inv`],
//! as [`super::RigidBody`]); so(n) M ↦ g M gᵀ (the kernels of [`super::GeneralizedRigidBody`]);
//! se(3) μ ↦ Ad_{exp(−ξ)}ᵀ μ ([`se3::exp`], [`se3::SE3::adjoint_matrix`]). For structure
//! constants, exp(ξ)·μ = exp(−ad_ξᵀ) μ by the Taylor series of the exponential applied to μ
//! (scaled so that each factor has ‖ad_ξ‖ ≤ ½, summed to a term below 10⁻¹⁸ of the sum): an exact
//! coadjoint map up to round-off, so the orbit (every Casimir) is kept to round-off as with the
//! built-in groups. dexp⁻¹_u = Σ_k B_k/k! ad_uᵏ by its Bernoulli series for se(3) and structure
//! constants (NaN beyond ‖ad_u‖_∞ ≥ π, where the series converges slowly; RKMK then stops with
//! the step named).
//!
//! **Which methods, and why.** The orbit-preserving methods are the ones the kind [`GroupField`]
//! supports for any g: RKMK4 (explicit, order 4, energy error drifting like RK4's at O(h⁴)) and
//! the Lie midpoint (symmetric, order 2, and its composition of order 4; bounded energy error
//! for reversible systems such as the rigid body and Kirchhoff's body). The isospectral
//! symplectic midpoint of [`super::isospectral`] would generalise to any H on so(n)* (replace
//! Ω_ij = M_ij/d_ij by Ω = hat(∇H)), but its kernel is written for the rigid body's diagonal
//! map; it is not offered here. RK4 is the non-geometric baseline.
//!
//! **Failures of user functions.** The functions return [`Result`]; a kernel that cannot return
//! an error (the problem kinds' kernels do not) records it ([`hooks::fail`]) and hands NaN to the
//! method. These systems [call out](Problem::calls_out), so a run steps them one step at a time
//! and ends after the step in which a function failed, with that function's error located ("in
//! step k of gauss4, t = …, dt = …"), never taking a step twice. Values are checked: a
//! non-finite H or gradient entry is [`Error::NonFinite`] naming the entry. Evaluation of H
//! outside the kernels ([`Problem::energy`], the Casimirs) returns the error.
//!
//! **Finite differences** (a function given without its gradient): each derivative is a central
//! difference with one Richardson extrapolation ([`crate::analysis`]'s Jacobian, four
//! evaluations per coordinate), with steps h_l = [`FD_STEP`]·max(|x_l|, ‖x‖_∞) (x = (q, p) or
//! μ; [`FD_STEP`] alone at x = 0). The error is O(h⁴) truncation plus O(ε|H|/h) round-off:
//! about 1e-12 relative to the scale of H/x for smooth H whose variation scale is that of x
//! (measured 2e-13 … 3e-12 on the tests' pendulum and rigid body). Such a gradient is not exactly
//! the gradient of a function, so the Gauss and Verlet methods are symplectic only up to it: the
//! energy error of a long run may drift by about that much per unit time. Pass the gradient
//! where long runs or non-smooth scales matter.

use std::fmt;
use std::sync::Arc;

use nalgebra::{Vector3, Vector6};

use super::rigid_body::{GeneralizedRigidBody, SoScratch};
use crate::check;
use crate::error::{fmt_num, Error, Result};
use crate::integrate::hooks;
use crate::integrate::methods::{canonical_catalog, Composition, LieMidpoint, Rk4, Rkmk4, Verlet};
use crate::integrate::problem::{Canonical, GroupField, Separable, VectorField, Violation};
use crate::integrate::space::{Block, Space};
use crate::integrate::{Catalog, Entry, Problem};
use crate::lie::{se3, so, so3};
use crate::Mat;

/// H(q, p) of a [`UserCanonical`].
pub type CanonicalFn = Arc<dyn Fn(&[f64], &[f64]) -> Result<f64> + Send + Sync>;
/// The gradient of a [`UserCanonical`]: (q, p, ∂H/∂q out, ∂H/∂p out).
pub type CanonicalGradientFn =
    Arc<dyn Fn(&[f64], &[f64], &mut [f64], &mut [f64]) -> Result<()> + Send + Sync>;
/// A scalar function f(x) (a potential U(q), a Lie–Poisson H(μ), a Casimir).
pub type ScalarFn = Arc<dyn Fn(&[f64]) -> Result<f64> + Send + Sync>;
/// The gradient of a [`ScalarFn`]: (x, ∇f out).
pub type GradientFn = Arc<dyn Fn(&[f64], &mut [f64]) -> Result<()> + Send + Sync>;

/// The base step of the finite differences, ε^{1/5} ≈ 7.4e-4 (the step that balances the O(h⁴)
/// truncation of the Richardson-extrapolated central difference against its O(ε/h) round-off).
pub const FD_STEP: f64 = 7.4e-4;

// ---------------------------------------------------------------------------------------------
// value checks and finite differences

/// `v`, or [`Error::NonFinite`] naming `what`.
fn finite_value(what: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::NonFinite {
            what: what.into(),
            location: format!("its value ({v})"),
        })
    }
}

/// Ok if every entry of `v` is finite, else [`Error::NonFinite`] naming `what` and the entry
/// `name[i]`.
fn finite_entries(what: &str, name: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::NonFinite {
            what: what.into(),
            location: format!("{name}[{i}] = {}", v[i]),
        }),
    }
}

/// ∇f(x) into `out` by central differences with one Richardson extrapolation (module docs).
fn fd_gradient(f: &dyn Fn(&[f64]) -> Result<f64>, x: &[f64], out: &mut [f64]) -> Result<()> {
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let h: Vec<f64> = x
        .iter()
        .map(|v| {
            let s = v.abs().max(scale);
            FD_STEP * if s > 0.0 { s } else { 1.0 }
        })
        .collect();
    let jac = crate::analysis::jacobian(&|y| f(y).map(|v| vec![v]), x, &h)?;
    for (i, o) in out.iter_mut().enumerate() {
        *o = jac[(0, i)];
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// UserCanonical

/// A canonical Hamiltonian system H(q, p) on T*ℝᵈ given by functions (module docs); state
/// z = (q, p).
#[derive(Clone)]
pub struct UserCanonical {
    dof: usize,
    h: CanonicalFn,
    gradient: Option<CanonicalGradientFn>,
}

impl fmt::Debug for UserCanonical {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UserCanonical")
            .field("dof", &self.dof)
            .field("gradient", &self.gradient.is_some())
            .finish()
    }
}

impl UserCanonical {
    /// H with `dof` ≥ 1 degrees of freedom and its gradient, or `None` for finite differences.
    pub fn new(dof: usize, h: CanonicalFn, gradient: Option<CanonicalGradientFn>) -> Result<Self> {
        check_dof("dof", dof)?;
        Ok(UserCanonical { dof, h, gradient })
    }

    /// Whether the gradient is computed by finite differences.
    pub fn finite_differences(&self) -> bool {
        self.gradient.is_none()
    }

    /// H(q, p), checked finite.
    pub fn value(&self, q: &[f64], p: &[f64]) -> Result<f64> {
        finite_value("the Hamiltonian H(q, p)", (self.h)(q, p)?)
    }

    /// (∂H/∂q, ∂H/∂p), checked finite.
    pub fn eval_gradient(
        &self,
        q: &[f64],
        p: &[f64],
        hq: &mut [f64],
        hp: &mut [f64],
    ) -> Result<()> {
        match &self.gradient {
            Some(g) => g(q, p, hq, hp)?,
            None => {
                let d = self.dof;
                let z = [q, p].concat();
                let mut out = vec![0.0; 2 * d];
                fd_gradient(&|y| self.value(&y[..d], &y[d..]), &z, &mut out)?;
                hq.copy_from_slice(&out[..d]);
                hp.copy_from_slice(&out[d..]);
            }
        }
        finite_entries("the gradient of H", "dH/dq", hq)?;
        finite_entries("the gradient of H", "dH/dp", hp)
    }
}

fn check_dof(what: &str, dof: usize) -> Result<()> {
    if dof == 0 {
        return Err(Error::invalid(
            what,
            "expected at least 1 degree of freedom, got 0",
        ));
    }
    check::array_size(what, &[2, dof]).map(|_| ())
}

/// The state space (q, p) of d degrees of freedom.
fn qp_space(d: usize) -> Space {
    Space::new([("q", Block::Real(d)), ("p", Block::Real(d))])
}

impl Problem for UserCanonical {
    /// H (or U) is a user function.
    fn calls_out(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "Canonical"
    }
    fn space(&self) -> Space {
        qp_space(self.dof)
    }
    /// H(q, p) (an error of the function, or a non-finite value, is returned).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.value(&z[..self.dof], &z[self.dof..])
    }
    /// None.
    fn invariants(&self, _z: &[f64]) -> Result<Vec<f64>> {
        Ok(Vec::new())
    }
    fn invariant_count(&self) -> usize {
        0
    }
}

impl Canonical for UserCanonical {
    fn dof(&self) -> usize {
        self.dof
    }
    fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64 {
        let mut h = f64::NAN;
        hooks::call(|| self.value(q, p).map(|v| h = v));
        h
    }
    fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
        if !hooks::call(|| self.eval_gradient(q, p, hq, hp)) {
            hq.fill(f64::NAN);
            hp.fill(f64::NAN);
        }
    }
}

impl VectorField for UserCanonical {
    /// q̇ = ∂H/∂p, ṗ = −∂H/∂q.
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let d = self.dof;
        let (qdot, pdot) = dz.split_at_mut(d);
        self.gradient(&z[..d], &z[d..], pdot, qdot);
        pdot.iter_mut().for_each(|x| *x = -*x);
    }
}

impl Catalog for UserCanonical {
    fn catalog(&self) -> Vec<Entry<Self>> {
        canonical_catalog()
    }

    fn dissipation(
        &self,
        d: &crate::integrate::forcing::Dissipation,
    ) -> crate::Result<std::sync::Arc<dyn crate::integrate::forcing::Perturbation>> {
        crate::integrate::forcing::rayleigh(self, d)
    }
}

// ---------------------------------------------------------------------------------------------
// UserSeparable

/// The constant kinetic mass M of a [`UserSeparable`] (T = ½ pᵀM⁻¹p).
#[derive(Clone, Debug, PartialEq)]
pub enum KineticMass {
    /// M = m·I (m > 0); the number of degrees of freedom is given separately.
    Scalar(f64),
    /// M = diag(m) (every m_i > 0).
    Diagonal(Vec<f64>),
    /// A symmetric positive-definite matrix.
    Matrix(Mat),
}

/// M⁻¹ in the form the kernels use.
#[derive(Clone, Debug, PartialEq)]
enum InverseMass {
    Scalar(f64),
    Diagonal(Vec<f64>),
    /// Row-major d×d.
    Dense(Vec<f64>),
}

impl InverseMass {
    fn apply(&self, p: &[f64], v: &mut [f64]) {
        match self {
            InverseMass::Scalar(w) => {
                for (vi, pi) in v.iter_mut().zip(p) {
                    *vi = w * pi;
                }
            }
            InverseMass::Diagonal(w) => {
                for ((vi, pi), wi) in v.iter_mut().zip(p).zip(w) {
                    *vi = wi * pi;
                }
            }
            InverseMass::Dense(w) => {
                let d = p.len();
                for (i, vi) in v.iter_mut().enumerate() {
                    *vi = (0..d).map(|j| w[i * d + j] * p[j]).sum();
                }
            }
        }
    }

    /// ½ pᵀM⁻¹p.
    fn kinetic(&self, p: &[f64]) -> f64 {
        let t = match self {
            InverseMass::Scalar(w) => w * p.iter().map(|x| x * x).sum::<f64>(),
            InverseMass::Diagonal(w) => p.iter().zip(w).map(|(x, wi)| wi * x * x).sum(),
            InverseMass::Dense(w) => {
                let d = p.len();
                (0..d)
                    .map(|i| p[i] * (0..d).map(|j| w[i * d + j] * p[j]).sum::<f64>())
                    .sum()
            }
        };
        0.5 * t
    }
}

/// A separable system H = ½ pᵀM⁻¹p + U(q) with U and ∇U given by functions (module docs); state
/// z = (q, p).
#[derive(Clone)]
pub struct UserSeparable {
    dof: usize,
    inverse: Arc<InverseMass>,
    u: ScalarFn,
    gradient: Option<GradientFn>,
}

impl fmt::Debug for UserSeparable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UserSeparable")
            .field("dof", &self.dof)
            .field("inverse_mass", &self.inverse)
            .field("gradient", &self.gradient.is_some())
            .finish()
    }
}

impl UserSeparable {
    /// The system with mass `mass`, potential `u` and its gradient (or `None` for finite
    /// differences); `dof` is needed for a scalar mass and must agree with a vector or matrix.
    ///
    /// Errors: a non-finite, non-positive or non-symmetric mass, or one that is not positive
    /// definite ([`Error::InvalidArgument`]); a mass of the wrong shape or a `dof` that disagrees
    /// ([`Error::Shape`]); a scalar mass without `dof`.
    pub fn new(
        mass: KineticMass,
        dof: Option<usize>,
        u: ScalarFn,
        gradient: Option<GradientFn>,
    ) -> Result<Self> {
        let (d, inverse) = match mass {
            KineticMass::Scalar(m) => {
                check::positive("mass", m)?;
                let d = dof.ok_or_else(|| {
                    Error::invalid(
                        "dof",
                        "a scalar mass needs the number of degrees of freedom (dof)",
                    )
                })?;
                (d, InverseMass::Scalar(1.0 / m))
            }
            KineticMass::Diagonal(m) => {
                for (i, &mi) in m.iter().enumerate() {
                    check::positive(&format!("mass[{i}]"), mi)?;
                }
                (
                    m.len(),
                    InverseMass::Diagonal(m.iter().map(|x| 1.0 / x).collect()),
                )
            }
            KineticMass::Matrix(m) => {
                let d = check::square("mass", &m, 1)?;
                (d, InverseMass::Dense(spd_inverse("mass", &m)?))
            }
        };
        if let Some(k) = dof {
            if k != d {
                return Err(Error::shape(
                    "mass",
                    format!("a scalar, ({k},) or ({k}, {k}) for dof = {k}"),
                    format!("a mass of {d} degrees of freedom"),
                ));
            }
        }
        check_dof("dof", d)?;
        if let InverseMass::Diagonal(w) | InverseMass::Dense(w) = &inverse {
            // 1/m of a subnormal mass overflows.
            check::finite_slice("the inverse of mass", w)?;
        }
        if let InverseMass::Scalar(w) = inverse {
            check::finite_slice("the inverse of mass", &[w])?;
        }
        Ok(UserSeparable {
            dof: d,
            inverse: Arc::new(inverse),
            u,
            gradient,
        })
    }

    /// Whether ∇U is computed by finite differences.
    pub fn finite_differences(&self) -> bool {
        self.gradient.is_none()
    }

    /// U(q), checked finite.
    pub fn potential(&self, q: &[f64]) -> Result<f64> {
        finite_value("the potential U(q)", (self.u)(q)?)
    }

    /// ∇U(q), checked finite.
    pub fn potential_gradient(&self, q: &[f64], out: &mut [f64]) -> Result<()> {
        match &self.gradient {
            Some(g) => g(q, out)?,
            None => fd_gradient(&|y| self.potential(y), q, out)?,
        }
        finite_entries("the gradient of U", "dU/dq", out)
    }

    /// The velocity M⁻¹p.
    pub fn velocity_of(&self, p: &[f64]) -> Vec<f64> {
        let mut v = vec![0.0; p.len()];
        self.inverse.apply(p, &mut v);
        v
    }
}

/// The inverse of a symmetric positive-definite matrix (row-major), by its eigendecomposition.
fn spd_inverse(what: &str, m: &Mat) -> Result<Vec<f64>> {
    check::finite_mat(what, m)?;
    let d = m.nrows();
    let scale = check::max_abs(m);
    let asym = (0..d)
        .flat_map(|a| (0..d).map(move |b| (a, b)))
        .fold(0.0f64, |s, (a, b)| s.max((m[(a, b)] - m[(b, a)]).abs()));
    if asym > 1e-12 * scale {
        return Err(Error::invalid(
            what,
            format!("not symmetric (max |M − Mᵀ| = {asym:.3e})"),
        ));
    }
    let eig = m
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| Error::invalid(what, format!("eigendecomposition failed: {e:?}")))?;
    let vals: Vec<f64> = (0..d).map(|i| eig.S()[i]).collect();
    let (lo, hi) = vals.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    if !(lo > 0.0 && lo > 1e-14 * hi) {
        return Err(Error::invalid(
            what,
            format!(
                "not positive definite (eigenvalues from {} to {}; the smallest must be > 1e-14 of \
                 the largest)",
                fmt_num(lo),
                fmt_num(hi)
            ),
        ));
    }
    let u = eig.U();
    let mut inv = vec![0.0; d * d];
    for i in 0..d {
        for j in 0..d {
            inv[i * d + j] = (0..d).map(|k| u[(i, k)] * u[(j, k)] / vals[k]).sum();
        }
    }
    // Exactly symmetric.
    for i in 0..d {
        for j in i + 1..d {
            let s = 0.5 * (inv[i * d + j] + inv[j * d + i]);
            inv[i * d + j] = s;
            inv[j * d + i] = s;
        }
    }
    Ok(inv)
}

impl Problem for UserSeparable {
    /// H (or U) is a user function.
    fn calls_out(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "Separable"
    }
    fn space(&self) -> Space {
        qp_space(self.dof)
    }
    /// ½ pᵀM⁻¹p + U(q).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let d = self.dof;
        let h = self.inverse.kinetic(&z[d..]) + self.potential(&z[..d])?;
        finite_value("the energy", h)
    }
    /// None.
    fn invariants(&self, _z: &[f64]) -> Result<Vec<f64>> {
        Ok(Vec::new())
    }
    fn invariant_count(&self) -> usize {
        0
    }
}

impl Separable for UserSeparable {
    type Scratch = ();
    fn scratch(&self) {}
    fn dof(&self) -> usize {
        self.dof
    }
    fn velocity(&self, p: &[f64], v: &mut [f64]) {
        self.inverse.apply(p, v);
    }
    /// f = −∇U(q); a failure of the functions is recorded (the method's step then stops the run)
    /// and reported as a violation.
    fn force(&self, q: &[f64], f: &mut [f64], _s: &mut ()) -> std::result::Result<(), Violation> {
        if hooks::call(|| self.potential_gradient(q, f)) {
            f.iter_mut().for_each(|x| *x = -*x);
            Ok(())
        } else {
            f.fill(f64::NAN);
            Err(Violation {
                what: "the gradient of U".into(),
                message: "the function failed".into(),
            })
        }
    }
}

impl Canonical for UserSeparable {
    fn dof(&self) -> usize {
        self.dof
    }
    fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64 {
        let mut u = f64::NAN;
        hooks::call(|| self.potential(q).map(|v| u = v));
        u + self.inverse.kinetic(p)
    }
    fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]) {
        self.inverse.apply(p, hp);
        if !hooks::call(|| self.potential_gradient(q, hq)) {
            hq.fill(f64::NAN);
        }
    }
}

impl VectorField for UserSeparable {
    /// q̇ = M⁻¹p, ṗ = −∇U(q).
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let d = self.dof;
        let (qdot, pdot) = dz.split_at_mut(d);
        Canonical::gradient(self, &z[..d], &z[d..], pdot, qdot);
        pdot.iter_mut().for_each(|x| *x = -*x);
    }
}

impl Catalog for UserSeparable {
    /// verlet (default), verlet4, verlet6, then gauss4, gauss6, midpoint, rk4.
    fn catalog(&self) -> Vec<Entry<Self>> {
        let mut entries = vec![
            Entry::new("verlet", Verlet::strang()),
            Entry::new("verlet4", Verlet(Composition::suzuki4())),
            Entry::new("verlet6", Verlet(Composition::yoshida6())),
        ];
        entries.extend(canonical_catalog());
        entries
    }

    fn dissipation(
        &self,
        d: &crate::integrate::forcing::Dissipation,
    ) -> crate::Result<std::sync::Arc<dyn crate::integrate::forcing::Perturbation>> {
        crate::integrate::forcing::rayleigh(self, d)
    }
}

// ---------------------------------------------------------------------------------------------
// LiePoisson

/// The Lie algebra g of a [`LiePoisson`] system.
#[derive(Clone, Debug, PartialEq)]
pub enum Algebra {
    /// so(3) in the physics basis (ℝ³, [û, v̂] = (u × v)^): μ = M.
    So3,
    /// se(3) = so(3) ⋉ ℝ³ with ξ = (ω, v) ([`se3::ad_matrix`]): μ = (M, Γ).
    Se3,
    /// so(n) in the e_ij coordinates of [`so::vee_n`] (n ≥ 2): μ = M ∈ so(n)*.
    So(usize),
    /// Structure constants C (d×d×d, row-major C\[i\]\[j\]\[k\] = C_ij^k: [e_i, e_j] = C_ij^k e_k),
    /// antisymmetric in (i, j) and satisfying the Jacobi identity (both checked).
    Constants(Vec<f64>),
}

/// One non-zero structure constant: [e_i, e_j] has c along e_k.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Term {
    i: u32,
    j: u32,
    k: u32,
    c: f64,
}

/// Which group maps the [`GroupField`] kernels use.
#[derive(Clone, Debug, PartialEq)]
enum Kind {
    So3,
    Se3,
    So(usize),
    Generic,
}

/// The algebra as the kernels use it.
#[derive(Clone, Debug, PartialEq)]
struct Structure {
    kind: Kind,
    dim: usize,
    terms: Vec<Term>,
}

impl Structure {
    fn new(algebra: Algebra) -> Result<Self> {
        let t = |i: usize, j: usize, k: usize, c: f64| Term {
            i: i as u32,
            j: j as u32,
            k: k as u32,
            c,
        };
        const CYCLIC: [(usize, usize, usize); 3] = [(0, 1, 2), (1, 2, 0), (2, 0, 1)];
        match algebra {
            Algebra::So3 => {
                // [e_i, e_j] = ε_ijk e_k.
                let mut terms = Vec::new();
                for (i, j, k) in CYCLIC {
                    terms.push(t(i, j, k, 1.0));
                    terms.push(t(j, i, k, -1.0));
                }
                Ok(Structure {
                    kind: Kind::So3,
                    dim: 3,
                    terms,
                })
            }
            Algebra::Se3 => {
                // [e_i, e_j] = ε_ijk e_k, [e_i, e_{3+j}] = ε_ijk e_{3+k} = −[e_{3+j}, e_i],
                // [e_{3+i}, e_{3+j}] = 0.
                let mut terms = Vec::new();
                for (i, j, k) in CYCLIC {
                    terms.push(t(i, j, k, 1.0));
                    terms.push(t(j, i, k, -1.0));
                    terms.push(t(i, 3 + j, 3 + k, 1.0));
                    terms.push(t(3 + j, i, 3 + k, -1.0));
                    terms.push(t(j, 3 + i, 3 + k, -1.0));
                    terms.push(t(3 + i, j, 3 + k, 1.0));
                }
                Ok(Structure {
                    kind: Kind::Se3,
                    dim: 6,
                    terms,
                })
            }
            Algebra::So(n) => {
                if n < 2 {
                    return Err(Error::invalid(
                        "algebra",
                        format!("so(n) needs n ≥ 2, got n = {n}"),
                    ));
                }
                // O(n³) non-zero constants, kept as (i, j, k, c): refuse what cannot be held.
                check::array_size("algebra so(n)", &[n, n, n, 4])?;
                Ok(Structure {
                    kind: Kind::So(n),
                    dim: so::dim(n),
                    terms: so_terms(n),
                })
            }
            Algebra::Constants(c) => Self::from_constants(&c),
        }
    }

    /// Structure constants given as an array: validated (finite, antisymmetric, Jacobi).
    fn from_constants(c: &[f64]) -> Result<Self> {
        let d = (c.len() as f64).cbrt().round() as usize;
        if d == 0 || d * d * d != c.len() {
            return Err(Error::shape(
                "algebra",
                "structure constants (d, d, d) with d ≥ 1",
                format!("{} values", c.len()),
            ));
        }
        check::finite_slice("algebra (structure constants)", c)?;
        let at = |i: usize, j: usize, k: usize| c[(i * d + j) * d + k];
        let cmax = c.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..d {
            for j in 0..d {
                for k in 0..d {
                    let s = at(i, j, k) + at(j, i, k);
                    if s.abs() > 1e-12 * cmax {
                        return Err(Error::invalid(
                            "algebra",
                            format!(
                                "structure constants not antisymmetric: C[{i}, {j}, {k}] + \
                                 C[{j}, {i}, {k}] = {s:.3e}"
                            ),
                        ));
                    }
                }
            }
        }
        // Rows: the non-zero (k, C_ab^k) of each bracket [e_a, e_b].
        let rows: Vec<Vec<(usize, f64)>> = (0..d * d)
            .map(|ab| {
                (0..d)
                    .filter_map(|k| {
                        let v = c[ab * d + k];
                        (v != 0.0).then_some((k, v))
                    })
                    .collect()
            })
            .collect();
        // Jacobi: [[e_i, e_j], e_l] + [[e_j, e_l], e_i] + [[e_l, e_i], e_j] = 0.
        let mut acc = vec![0.0; d];
        let tol = 1e-10 * cmax * cmax;
        let nested = |a: usize, b: usize, l: usize, acc: &mut [f64]| {
            for &(k, x) in &rows[a * d + b] {
                for &(m, y) in &rows[k * d + l] {
                    acc[m] += x * y;
                }
            }
        };
        for i in 0..d {
            for j in i + 1..d {
                for l in j + 1..d {
                    acc.fill(0.0);
                    nested(i, j, l, &mut acc);
                    nested(j, l, i, &mut acc);
                    nested(l, i, j, &mut acc);
                    if let Some(m) = acc.iter().position(|x| x.abs() > tol) {
                        return Err(Error::invalid(
                            "algebra",
                            format!(
                                "structure constants violate the Jacobi identity: component {m} \
                                 of [[e_{i}, e_{j}], e_{l}] + cyclic = {:.3e}",
                                acc[m]
                            ),
                        ));
                    }
                }
            }
        }
        let mut terms = Vec::new();
        for i in 0..d {
            for j in 0..d {
                for &(k, v) in &rows[i * d + j] {
                    terms.push(Term {
                        i: i as u32,
                        j: j as u32,
                        k: k as u32,
                        c: v,
                    });
                }
            }
        }
        Ok(Structure {
            kind: Kind::Generic,
            dim: d,
            terms,
        })
    }

    /// out ← ad*_g μ, (ad*_g μ)_j = Σ C_ij^k g_i μ_k.
    fn ad_star(&self, g: &[f64], mu: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for t in &self.terms {
            out[t.j as usize] += t.c * g[t.i as usize] * mu[t.k as usize];
        }
    }

    /// out ← [u, v] = ad_u v, [u, v]_k = Σ C_ij^k u_i v_j.
    fn bracket(&self, u: &[f64], v: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for t in &self.terms {
            out[t.k as usize] += t.c * u[t.i as usize] * v[t.j as usize];
        }
    }

    /// A bound of ‖ad_u‖_∞ (and of ‖ad_uᵀ‖_∞): max over rows of Σ |C_ij^k u_i| for the two
    /// index placements.
    fn ad_bound(&self, u: &[f64], rows: &mut [f64], cols: &mut [f64]) -> f64 {
        rows.fill(0.0);
        cols.fill(0.0);
        for t in &self.terms {
            let a = (t.c * u[t.i as usize]).abs();
            rows[t.k as usize] += a;
            cols[t.j as usize] += a;
        }
        rows.iter()
            .chain(cols.iter())
            .fold(0.0f64, |m, x| m.max(*x))
    }

    /// The dense (d, d, d) array C[i][j][k].
    fn dense(&self) -> Vec<f64> {
        let d = self.dim;
        let mut c = vec![0.0; d * d * d];
        for t in &self.terms {
            c[(t.i as usize * d + t.j as usize) * d + t.k as usize] += t.c;
        }
        c
    }
}

/// The structure constants of so(n) in the e_ij basis: with E_ab = −E_ba,
/// [E_ab, E_cd] = δ_bc E_ad − δ_bd E_ac − δ_ac E_bd + δ_ad E_bc.
fn so_terms(n: usize) -> Vec<Term> {
    // index[a][b]: (coordinate, sign) of E_ab.
    let mut index = vec![(0usize, 0.0f64); n * n];
    let mut c = 0;
    for a in 0..n {
        for b in a + 1..n {
            index[a * n + b] = (c, 1.0);
            index[b * n + a] = (c, -1.0);
            c += 1;
        }
    }
    let pairs: Vec<(usize, usize)> = (0..n)
        .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
        .collect();
    let mut terms = Vec::new();
    let add = |i: usize, j: usize, x: usize, y: usize, s: f64, terms: &mut Vec<Term>| {
        let (k, sign) = index[x * n + y];
        if sign != 0.0 {
            terms.push(Term {
                i: i as u32,
                j: j as u32,
                k: k as u32,
                c: s * sign,
            });
        }
    };
    for (i, &(a, b)) in pairs.iter().enumerate() {
        for (j, &(cc, dd)) in pairs.iter().enumerate() {
            if b == cc {
                add(i, j, a, dd, 1.0, &mut terms);
            }
            if b == dd {
                add(i, j, a, cc, -1.0, &mut terms);
            }
            if a == cc {
                add(i, j, b, dd, -1.0, &mut terms);
            }
            if a == dd {
                add(i, j, b, cc, 1.0, &mut terms);
            }
        }
    }
    terms
}

/// The Hamiltonian of a [`LiePoisson`] system.
#[derive(Clone)]
pub enum LieHamiltonian {
    /// H = ½ μᵀAμ with A symmetric (d×d, row-major): ∇H = Aμ, the native path.
    Quadratic(Vec<f64>),
    /// H and its gradient (or `None` for finite differences) as functions of μ.
    Function {
        /// H(μ).
        value: ScalarFn,
        /// ∇H(μ), or `None`.
        gradient: Option<GradientFn>,
    },
}

/// A Lie–Poisson system μ̇ = ad*_{∇H} μ on g* (module docs).
#[derive(Clone)]
pub struct LiePoisson {
    algebra: Arc<Structure>,
    hamiltonian: LieHamiltonian,
    casimirs: Option<Vec<ScalarFn>>,
    /// The so(n) kernels (of a generalized rigid body; only its group action is used).
    so_kernels: Option<GeneralizedRigidBody>,
}

impl fmt::Debug for LiePoisson {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("LiePoisson")
            .field("kind", &self.algebra.kind)
            .field("dim", &self.algebra.dim)
            .field(
                "quadratic",
                &matches!(self.hamiltonian, LieHamiltonian::Quadratic(_)),
            )
            .finish()
    }
}

impl LiePoisson {
    /// The system on g* with Hamiltonian `hamiltonian` and, optionally, Casimirs given as
    /// functions (replacing the built-in ones: |M|² on so(3); |Γ|², M·Γ on se(3); ½ tr((MᵀM)^k)
    /// on so(n); none for structure constants).
    ///
    /// Errors: invalid structure constants (shape, non-finite, not antisymmetric, Jacobi), n < 2,
    /// a quadratic form of the wrong size, non-finite or not symmetric.
    pub fn new(
        algebra: Algebra,
        hamiltonian: LieHamiltonian,
        casimirs: Option<Vec<ScalarFn>>,
    ) -> Result<Self> {
        let algebra = Structure::new(algebra)?;
        let d = algebra.dim;
        if let LieHamiltonian::Quadratic(a) = &hamiltonian {
            if a.len() != d * d {
                return Err(Error::shape(
                    "hamiltonian",
                    format!("a symmetric ({d}, {d}) matrix (H = ½ μᵀAμ on a {d}-dimensional g*)"),
                    format!("{} values", a.len()),
                ));
            }
            check::finite_slice("hamiltonian", a)?;
            let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for i in 0..d {
                for j in i + 1..d {
                    let s = (a[i * d + j] - a[j * d + i]).abs();
                    if s > 1e-12 * scale {
                        return Err(Error::invalid(
                            "hamiltonian",
                            format!(
                                "the quadratic form must be symmetric: |A[{i}, {j}] − A[{j}, {i}]| \
                                 = {s:.3e}"
                            ),
                        ));
                    }
                }
            }
        }
        let so_kernels = match algebra.kind {
            Kind::So(n) => Some(GeneralizedRigidBody::new(&vec![1.0; n])?),
            _ => None,
        };
        Ok(LiePoisson {
            algebra: Arc::new(algebra),
            hamiltonian,
            casimirs,
            so_kernels,
        })
    }

    /// dim g.
    pub fn dim(&self) -> usize {
        self.algebra.dim
    }

    /// The structure constants C\[i\]\[j\]\[k\] = C_ij^k, row-major (d, d, d).
    ///
    /// Errors: an array too large to hold (so(n) for large n).
    pub fn structure_constants(&self) -> Result<Vec<f64>> {
        let d = self.algebra.dim;
        check::array_size("structure_constants", &[d, d, d])?;
        Ok(self.algebra.dense())
    }

    /// Whether H is the native quadratic form.
    pub fn is_quadratic(&self) -> bool {
        matches!(self.hamiltonian, LieHamiltonian::Quadratic(_))
    }

    /// H(μ), checked finite.
    pub fn value(&self, mu: &[f64]) -> Result<f64> {
        match &self.hamiltonian {
            LieHamiltonian::Quadratic(a) => {
                let d = self.algebra.dim;
                let h: f64 = (0..d)
                    .map(|i| mu[i] * (0..d).map(|j| a[i * d + j] * mu[j]).sum::<f64>())
                    .sum();
                finite_value("the Hamiltonian H(mu)", 0.5 * h)
            }
            LieHamiltonian::Function { value, .. } => {
                finite_value("the Hamiltonian H(mu)", value(mu)?)
            }
        }
    }

    /// ∇H(μ) into `out`, checked finite.
    pub fn eval_gradient(&self, mu: &[f64], out: &mut [f64]) -> Result<()> {
        match &self.hamiltonian {
            LieHamiltonian::Quadratic(a) => {
                let d = self.algebra.dim;
                for (i, o) in out.iter_mut().enumerate() {
                    *o = (0..d).map(|j| a[i * d + j] * mu[j]).sum();
                }
            }
            LieHamiltonian::Function { gradient, .. } => match gradient {
                Some(g) => g(mu, out)?,
                None => fd_gradient(&|y| self.value(y), mu, out)?,
            },
        }
        finite_entries("the gradient of H", "dH/dmu", out)
    }

    /// ∇H(μ) for a kernel: on failure NaN and the error recorded.
    fn kernel_gradient(&self, mu: &[f64], out: &mut [f64]) {
        if !hooks::call(|| self.eval_gradient(mu, out)) {
            out.fill(f64::NAN);
        }
    }

    /// The built-in Casimirs of the algebra.
    fn builtin_casimirs(&self, mu: &[f64]) -> Vec<f64> {
        match self.algebra.kind {
            Kind::So3 => vec![mu.iter().map(|x| x * x).sum()],
            Kind::Se3 => vec![
                mu[3..].iter().map(|x| x * x).sum(),
                (0..3).map(|i| mu[i] * mu[3 + i]).sum(),
            ],
            Kind::So(n) => so::spectral_invariants(&so::hat_n_unchecked(n, mu)),
            Kind::Generic => Vec::new(),
        }
    }

    /// exp(ξ)·μ = exp(−ad_ξᵀ) μ for structure constants (module docs): the Taylor series of the
    /// exponential applied to μ, in s factors with ‖ad_ξ/s‖ ≤ ½.
    fn act_generic(&self, xi: &[f64], z: &mut [f64], s: &mut LieScratch) {
        let beta = self.algebra.ad_bound(xi, &mut s.a, &mut s.b);
        if !beta.is_finite() {
            z.fill(f64::NAN);
            return;
        }
        let factors = (beta / 0.5).ceil().max(1.0);
        if factors > 1e6 {
            z.fill(f64::NAN);
            return;
        }
        for (x, y) in s.xi.iter_mut().zip(xi) {
            *x = -y / factors;
        }
        for _ in 0..factors as usize {
            // The increment Σ_{m≥1} B^m z / m! (B v = −ad*_ξ v, the scaled ξ is negated), summed
            // apart from z so that its rounding errors are relative to |ξ||z|, not |z|.
            s.sum.fill(0.0);
            s.term.copy_from_slice(z);
            let zn = z.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            for m in 1..=40 {
                self.algebra.ad_star(&s.xi, &s.term, &mut s.next);
                let inv = 1.0 / m as f64;
                let mut tn = 0.0f64;
                for ((t, nx), sm) in s.term.iter_mut().zip(&s.next).zip(s.sum.iter_mut()) {
                    *t = nx * inv;
                    *sm += *t;
                    tn = tn.max(t.abs());
                }
                if tn <= 1e-18 * zn || tn == 0.0 {
                    break;
                }
            }
            for (zi, inc) in z.iter_mut().zip(&s.sum) {
                *zi += inc;
            }
        }
    }

    /// dexp⁻¹_u v = Σ_k B_k/k! ad_uᵏ v (module docs); NaN when the bound of ‖ad_u‖ reaches π.
    fn dexp_inv_generic(&self, u: &[f64], v: &[f64], out: &mut [f64], s: &mut LieScratch) {
        let beta = self.algebra.ad_bound(u, &mut s.a, &mut s.b);
        if beta.is_nan() || beta >= std::f64::consts::PI || v.iter().any(|x| !x.is_finite()) {
            out.fill(f64::NAN);
            return;
        }
        out.copy_from_slice(v);
        s.term.copy_from_slice(v);
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut bound = 1.0;
        for &b in &so::bernoulli_coefficients()[1..] {
            self.algebra.bracket(u, &s.term, &mut s.next);
            std::mem::swap(&mut s.term, &mut s.next);
            let mut pn = 0.0f64;
            for (o, t) in out.iter_mut().zip(&s.term) {
                *o += b * t;
                pn = pn.max(t.abs());
            }
            // |b_j| ≤ 4/(2π)^j (j ≥ 2) and ‖ad_u‖ ≤ β < π: the rest is below 4‖p_k‖/(2π)^k.
            bound /= two_pi;
            let sum = out.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            if pn == 0.0 || 4.0 * pn * bound <= 1e-17 * sum {
                return;
            }
        }
    }
}

/// Per-thread scratch of the [`LiePoisson`] kernels.
pub struct LieScratch {
    so: Option<SoScratch>,
    xi: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    sum: Vec<f64>,
    term: Vec<f64>,
    next: Vec<f64>,
}

impl Problem for LiePoisson {
    /// H is a user function (not the quadratic form).
    fn calls_out(&self) -> bool {
        matches!(self.hamiltonian, LieHamiltonian::Function { .. })
    }
    fn name(&self) -> &'static str {
        "LiePoisson"
    }
    fn space(&self) -> Space {
        match self.algebra.kind {
            Kind::So3 => Space::new([("M", Block::Real(3))]),
            Kind::Se3 => Space::new([("M", Block::Real(3)), ("Gamma", Block::Real(3))]),
            Kind::So(n) => Space::new([("M", Block::SoDual(n))]),
            Kind::Generic => Space::new([("mu", Block::Real(self.algebra.dim))]),
        }
    }
    /// H(μ).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.value(z)
    }
    /// The Casimirs: the functions given, or the built-in ones of the algebra.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        match &self.casimirs {
            Some(fs) => fs
                .iter()
                .enumerate()
                .map(|(k, f)| finite_value(&format!("casimir {k}"), f(z)?))
                .collect(),
            None => Ok(self.builtin_casimirs(z)),
        }
    }
    fn invariant_count(&self) -> usize {
        match (&self.casimirs, &self.algebra.kind) {
            (Some(fs), _) => fs.len(),
            (None, Kind::So3) => 1,
            (None, Kind::Se3) => 2,
            (None, Kind::So(n)) => n / 2,
            (None, Kind::Generic) => 0,
        }
    }
}

impl VectorField for LiePoisson {
    /// μ̇ = ad*_{∇H} μ.
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let d = self.algebra.dim;
        let mut stack = [0.0; 32];
        let mut heap = Vec::new();
        let g = if d <= stack.len() {
            &mut stack[..d]
        } else {
            heap.resize(d, 0.0);
            &mut heap[..]
        };
        self.kernel_gradient(z, g);
        self.algebra.ad_star(g, z, dz);
    }
}

/// The coadjoint action (module docs): ξ(μ) = −∇H(μ), exp(ξ)·μ = Ad*_{exp(−ξ)} μ.
impl GroupField for LiePoisson {
    type Scratch = LieScratch;
    fn scratch(&self) -> LieScratch {
        let d = self.algebra.dim;
        LieScratch {
            so: self.so_kernels.as_ref().map(GroupField::scratch),
            xi: vec![0.0; d],
            a: vec![0.0; d],
            b: vec![0.0; d],
            sum: vec![0.0; d],
            term: vec![0.0; d],
            next: vec![0.0; d],
        }
    }
    fn algebra_dim(&self) -> usize {
        self.algebra.dim
    }
    fn generator(&self, z: &[f64], xi: &mut [f64], _s: &mut LieScratch) {
        self.kernel_gradient(z, xi);
        xi.iter_mut().for_each(|x| *x = -*x);
    }
    fn act(&self, xi: &[f64], z: &mut [f64], s: &mut LieScratch) {
        match (&self.algebra.kind, &self.so_kernels, &mut s.so) {
            (Kind::So3, _, _) => {
                let g = so3::exp_unchecked(&Vector3::from_column_slice(xi));
                let m = g * Vector3::from_column_slice(z);
                z.copy_from_slice(m.as_slice());
            }
            (Kind::Se3, _, _) => {
                let x = Vector6::from_column_slice(xi);
                let ad = se3::exp_unchecked(&(-x)).adjoint_matrix();
                let m = ad.transpose() * Vector6::from_column_slice(z);
                z.copy_from_slice(m.as_slice());
            }
            (Kind::So(_), Some(body), Some(so)) => body.act(xi, z, so),
            _ => self.act_generic(xi, z, s),
        }
    }
    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], s: &mut LieScratch) {
        match (&self.algebra.kind, &self.so_kernels, &mut s.so) {
            (Kind::So3, _, _) => match so3::jacobian_left_inv(&Vector3::from_column_slice(u)) {
                Ok(j) => out.copy_from_slice((j * Vector3::from_column_slice(v)).as_slice()),
                Err(_) => out.fill(f64::NAN),
            },
            (Kind::So(_), Some(body), Some(so)) => body.dexp_inv(u, v, out, so),
            _ => self.dexp_inv_generic(u, v, out, s),
        }
    }
}

impl Catalog for LiePoisson {
    /// rkmk4 (default), midpoint, midpoint4 (the Lie midpoint and its Suzuki composition),
    /// rk4.
    fn catalog(&self) -> Vec<Entry<Self>> {
        vec![
            Entry::new("rkmk4", Rkmk4),
            Entry::new("midpoint", LieMidpoint::new()),
            Entry::new("midpoint4", LieMidpoint(Composition::suzuki4())),
            Entry::new("rk4", Rk4),
        ]
    }

    fn dissipation(
        &self,
        d: &crate::integrate::forcing::Dissipation,
    ) -> crate::Result<std::sync::Arc<dyn crate::integrate::forcing::Perturbation>> {
        crate::integrate::forcing::double_bracket(self, d)
    }
}
