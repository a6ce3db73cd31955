use std::fmt;
use std::sync::Arc;

use nalgebra::{Vector3, Vector6};

use super::*;
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::hooks;
use crate::integrate::methods::group_field_catalog;
use crate::integrate::problem::{indexed_names, GroupField, VectorField};
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{GroupFieldTangent, Tangent, TangentSystem, VectorFieldTangent};
use crate::integrate::{Catalog, Entry, Problem};
use crate::lie::structure::{Algebra, Kind, Structure};
use crate::lie::{se3, so, so3};
use crate::systems::tops::generalized::{GeneralizedRigidBody, SoScratch};

use super::attitude::{Group, GroupScratch, Side};

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

/// The Hessian product of a [`LiePoisson`] Hamiltonian: (μ, δμ, D²H(μ)\[δμ\] out), the
/// derivative of ∇H along δμ.
pub type LieHessianFn = Arc<dyn Fn(&[f64], &[f64], &mut [f64]) -> Result<()> + Send + Sync>;

/// A Lie–Poisson system μ̇ = ±ad*_{∇H} μ on g* (module docs).
#[derive(Clone)]
pub struct LiePoisson {
    algebra: Arc<Structure>,
    side: Side,
    hamiltonian: LieHamiltonian,
    /// D²H(μ)\[δμ\] of a function H ([`LiePoisson::with_hessian`]).
    hessian: Option<LieHessianFn>,
    casimirs: Option<Vec<ScalarFn>>,
    /// The group G of the configuration g (None: structure constants, no matrices) and whether
    /// the state carries g after μ ([`LiePoisson::with_attitude`]).
    group: Option<Group>,
    lifted: bool,
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
            .field("hessian", &self.hessian.is_some())
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
        let group = Group::of(&algebra);
        let algebra = Structure::new(algebra)?;
        let d = algebra.dim;
        if let LieHamiltonian::Quadratic(a) = &hamiltonian {
            let expected = format!("a symmetric matrix (H = ½ μᵀAμ on a {d}-dimensional g*)");
            check::symmetric("hamiltonian", &expected, a, d)?;
        }
        let so_kernels = match algebra.kind {
            Kind::So(n) => Some(GeneralizedRigidBody::new(&vec![1.0; n])?),
            _ => None,
        };
        Ok(LiePoisson {
            algebra: Arc::new(algebra),
            side: Side::Left,
            hamiltonian,
            hessian: None,
            casimirs,
            group,
            lifted: false,
            so_kernels,
        })
    }

    /// The same system with the Hessian product D²H(μ)\[δμ\] of a function H ([`LieHessianFn`]):
    /// with the gradient given too, its tangent lift (the Jacobian of every method,
    /// [`crate::integrate::tangent`]). A quadratic H has its own (A δμ); this one is then unused.
    pub fn with_hessian(mut self, hessian: LieHessianFn) -> Self {
        self.hessian = Some(hessian);
        self
    }

    /// Whether the derivatives the tangent lift needs are exact: a quadratic H, or a function
    /// H with its gradient and its Hessian product.
    pub fn has_tangent(&self) -> bool {
        match &self.hamiltonian {
            LieHamiltonian::Quadratic(_) => true,
            LieHamiltonian::Function { gradient, .. } => {
                gradient.is_some() && self.hessian.is_some()
            }
        }
    }

    /// D²H(μ)\[δμ\] into `out`, checked finite: A δμ for a quadratic H, else the Hessian
    /// product given ([`LiePoisson::with_hessian`]).
    ///
    /// Errors: a function H without a Hessian product; the function's error; a non-finite entry.
    pub fn hessian_product(&self, mu: &[f64], dmu: &[f64], out: &mut [f64]) -> Result<()> {
        match (&self.hamiltonian, &self.hessian) {
            (LieHamiltonian::Quadratic(a), _) => {
                let d = self.algebra.dim;
                for (i, o) in out.iter_mut().enumerate() {
                    *o = (0..d).map(|j| a[i * d + j] * dmu[j]).sum();
                }
            }
            (LieHamiltonian::Function { .. }, Some(h)) => h(mu, dmu, out)?,
            (LieHamiltonian::Function { .. }, None) => {
                return Err(Error::invalid(
                    "hessian",
                    "the Hamiltonian is a function given without its Hessian product \
                     (with_hessian)",
                ))
            }
        }
        finite_entries("the Hessian product of H", "d(dH/dmu)", out)
    }

    /// D²H(μ)\[δμ\] for a kernel: on failure NaN and the error recorded.
    fn kernel_hessian(&self, mu: &[f64], dmu: &[f64], out: &mut [f64]) {
        if !hooks::call(|| self.hessian_product(mu, dmu, out)) {
            out.fill(f64::NAN);
        }
    }

    /// The same system reduced from the other invariance: `side` fixes the sign of the
    /// bracket ([`Side`]; a new system is [`Side::Left`]).
    pub fn with_side(mut self, side: Side) -> Self {
        self.side = side;
        self
    }

    /// The invariance the system comes from ([`Side`]).
    pub fn side(&self) -> Side {
        self.side
    }

    /// The system whose configuration group is `group`, acted on by the first `group.dim()`
    /// components of the algebra (an Euler–Poincaré system with a parameter lives on g ⋉ V
    /// while g stays in G; [`super::attitude`]).
    pub(crate) fn with_group(mut self, group: Option<Group>) -> Self {
        self.group = group;
        self
    }

    /// The group G of the configuration (None for structure constants).
    pub fn group(&self) -> Option<Group> {
        self.group
    }

    /// The same system carrying its configuration g ∈ G along as a last block (`R` for SO(3),
    /// `g` otherwise, n×n row-major): ġ = gξ (left) or ξg (right) with ξ = ∂H/∂μ, moved by every
    /// method with the momentum ([`super::attitude`]); its Noether momentum joins the
    /// invariants. None for structure constants (no matrix group).
    pub fn with_attitude(&self) -> Option<Self> {
        self.group?;
        let mut lifted = self.clone();
        lifted.lifted = true;
        Some(lifted)
    }

    /// The same system without the configuration.
    pub(crate) fn without_attitude(&self) -> Self {
        let mut base = self.clone();
        base.lifted = false;
        base
    }

    /// ad*_ξ μ = ad_ξᵀ μ on the algebra (module docs).
    pub(crate) fn ad_star(&self, xi: &[f64], mu: &[f64], out: &mut [f64]) {
        self.algebra.ad_star(xi, mu, out);
    }

    /// (dexp⁻¹_u)ᵀ p: on so(3) in closed form; on so(n), whose ad_u is skew in its orthonormal
    /// coordinates, dexp⁻¹_{−u} p ([`GroupField::dexp_inv`]); otherwise the Bernoulli series of ad*_u
    /// ([`Structure::dexp_inv_series`]).
    pub(crate) fn dexp_inv_dual(&self, u: &[f64], p: &[f64], out: &mut [f64], s: &mut LieScratch) {
        match self.algebra.kind {
            Kind::So3 => {
                // J_l⁻¹(u)ᵀ p = p + ½ u × p + c u × (u × p), c = (1 − (θ/2) cot(θ/2))/θ² (its
                // series below θ = 0.1, to θ⁸: the rest is below 10⁻¹⁹); NaN from θ = π on, as
                // dexp_inv.
                let t2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
                let theta = t2.sqrt();
                if theta.is_nan() || theta >= std::f64::consts::PI {
                    out.fill(f64::NAN);
                    return;
                }
                let c = if theta < 0.1 {
                    1.0 / 12.0
                        + t2 * (1.0 / 720.0
                            + t2 * (1.0 / 30240.0 + t2 * (1.0 / 1209600.0 + t2 / 47900160.0)))
                } else {
                    let half = 0.5 * theta;
                    (1.0 - half / half.tan()) / t2
                };
                let cross = |a: &[f64], b: &[f64]| {
                    [
                        a[1] * b[2] - a[2] * b[1],
                        a[2] * b[0] - a[0] * b[2],
                        a[0] * b[1] - a[1] * b[0],
                    ]
                };
                let up = cross(u, p);
                let uup = cross(u, &up);
                for i in 0..3 {
                    out[i] = p[i] + 0.5 * up[i] + c * uup[i];
                }
            }
            Kind::So(_) => {
                let mut minus = std::mem::take(&mut s.sum);
                minus.iter_mut().zip(u).for_each(|(m, x)| *m = -x);
                self.dexp_inv(&minus, p, out, s);
                s.sum = minus;
            }
            _ => {
                let LieScratch {
                    a, b, term, next, ..
                } = s;
                self.algebra
                    .dexp_inv_series(u, p, out, true, [a, b, term, next]);
            }
        }
    }

    /// Whether the state carries the configuration g.
    pub fn has_attitude(&self) -> bool {
        self.lifted
    }

    /// Whether the Noether momentum is conserved as a whole: the algebra is the group's own
    /// (without an advected parameter, which breaks the symmetry to the isotropy of a₀).
    fn noether_conserved(&self) -> bool {
        self.group.is_some_and(|g| g.dim() == self.algebra.dim)
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

    /// μ ← exp(ξ)·μ on g* (the momentum alone): the built-in group's map, or
    /// [`LiePoisson::act_generic`].
    fn act_momentum(&self, xi: &[f64], z: &mut [f64], s: &mut LieScratch) {
        match (&self.algebra.kind, &self.so_kernels, &mut s.so) {
            (Kind::So3, _, _) => {
                // By the increment (so3::Rodrigues: no per-step bias of |M|²).
                let mut m = Vector3::from_column_slice(z);
                so3::Rodrigues::exp(&Vector3::from_column_slice(xi)).apply(&mut m);
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

    /// dexp⁻¹_u v by its Bernoulli series ([`Structure::dexp_inv_series`]).
    fn dexp_inv_generic(&self, u: &[f64], v: &[f64], out: &mut [f64], s: &mut LieScratch) {
        let LieScratch {
            a, b, term, next, ..
        } = s;
        self.algebra
            .dexp_inv_series(u, v, out, false, [a, b, term, next]);
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
    group: Option<GroupScratch>,
    /// The tangent lift's: w = dexp_u δu, the dexp series' three vectors.
    lift: [Vec<f64>; 4],
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
        let space = match self.algebra.kind {
            Kind::So3 => Space::new([("M", Block::Real(3))]),
            Kind::Se3 => Space::new([("M", Block::Real(3)), ("Gamma", Block::Real(3))]),
            Kind::So(n) => Space::new([("M", Block::SoDual(n))]),
            Kind::Generic => Space::new([("mu", Block::Real(self.algebra.dim))]),
        };
        match (self.lifted, self.group) {
            (true, Some(g)) => space.with(g.block_name(), g.block()),
            _ => space,
        }
    }
    /// H(μ).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.value(&z[..self.algebra.dim])
    }
    /// The Casimirs: the functions given, or the built-in ones of the algebra; with the
    /// attitude and no parameter also the Noether momentum ([`super::attitude::Group::noether`]).
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let d = self.algebra.dim;
        let mut out = match &self.casimirs {
            Some(fs) => fs
                .iter()
                .enumerate()
                .map(|(k, f)| finite_value(&format!("casimir {k}"), f(&z[..d])?))
                .collect::<Result<Vec<f64>>>()?,
            None => self.builtin_casimirs(&z[..d]),
        };
        if let (true, Some(g)) = (self.lifted && self.noether_conserved(), self.group) {
            let mut p = vec![0.0; d];
            g.noether(self.side, &z[..d], &z[d..], &mut p)?;
            out.extend(p);
        }
        Ok(out)
    }
    /// "casimir k" for the functions given; the built-in Casimirs by their formulas; the
    /// Noether momentum as J₁, J₂, ….
    fn invariant_names(&self) -> Vec<String> {
        let mut names = match (&self.casimirs, &self.algebra.kind) {
            (Some(fs), _) => (0..fs.len()).map(|k| format!("casimir {k}")).collect(),
            (None, Kind::So3) => vec!["|M|²".to_string()],
            (None, Kind::Se3) => vec!["|Γ|²".to_string(), "M·Γ".into()],
            (None, Kind::So(n)) => so::spectral_names("M", *n),
            (None, Kind::Generic) => Vec::new(),
        };
        if self.lifted && self.noether_conserved() && self.group.is_some() {
            names.extend(indexed_names("J", self.algebra.dim));
        }
        names
    }
    /// The attitude, if carried, is in the group.
    fn check_state(&self, z: &[f64]) -> Result<()> {
        match (self.lifted, self.group) {
            (true, Some(g)) => g.check(g.block_name(), &z[self.algebra.dim..]),
            _ => Ok(()),
        }
    }
}

impl VectorField for LiePoisson {
    /// μ̇ = ±ad*_{∇H} μ ([`Side`]); with the attitude ġ = gξ (left) or ξg (right), ξ = ∇H.
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let d = self.algebra.dim;
        let (z, g) = z.split_at(d);
        let (dz, dg) = dz.split_at_mut(d);
        let mut stack = [0.0; 32];
        let mut heap = Vec::new();
        let grad = if d <= stack.len() {
            &mut stack[..d]
        } else {
            heap.resize(d, 0.0);
            &mut heap[..]
        };
        self.kernel_gradient(z, grad);
        if let (true, Some(group)) = (self.lifted, self.group) {
            group.velocity(self.side, &grad[..group.dim()], g, dg);
        }
        if self.side == Side::Right {
            grad.iter_mut().for_each(|x| *x = -*x);
        }
        self.algebra.ad_star(grad, z, dz);
    }
}

/// The coadjoint action (module docs): ξ(μ) = ∓∇H(μ) ([`Side`]: − for left), exp(ξ)·μ =
/// Ad*_{exp(−ξ)} μ; with the attitude, g follows ([`super::attitude::Group::follow`]).
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
            group: match (self.lifted, self.group) {
                (true, Some(g)) => Some(g.scratch()),
                _ => None,
            },
            lift: std::array::from_fn(|_| vec![0.0; d]),
        }
    }
    fn algebra_dim(&self) -> usize {
        self.algebra.dim
    }
    fn generator(&self, z: &[f64], xi: &mut [f64], _s: &mut LieScratch) {
        self.kernel_gradient(&z[..self.algebra.dim], xi);
        if self.side == Side::Left {
            xi.iter_mut().for_each(|x| *x = -*x);
        }
    }
    fn act(&self, xi: &[f64], z: &mut [f64], s: &mut LieScratch) {
        let (z, g) = z.split_at_mut(self.algebra.dim);
        if let (Some(group), Some(gs)) = (self.group, &mut s.group) {
            group.follow(self.side, &xi[..group.dim()], g, gs);
        }
        self.act_momentum(xi, z, s);
    }
    /// exp(ξ)·z − z formed as an increment on so(3) (Rodrigues) and so(n) (the generalized
    /// body's kernels), so that the methods add it with compensated summation; with the
    /// attitude, g's change by [`super::attitude::Group::follow`]. Not for se(3) and structure
    /// constants (the methods then act directly).
    fn act_increment(&self, xi: &[f64], z: &[f64], dz: &mut [f64], s: &mut LieScratch) -> bool {
        let d = self.algebra.dim;
        match (&self.algebra.kind, &self.so_kernels, &mut s.so) {
            (Kind::So3, _, _) => {
                let inc = so3::Rodrigues::exp(&Vector3::from_column_slice(xi))
                    .increment(&Vector3::from_column_slice(&z[..3]));
                dz[..3].copy_from_slice(inc.as_slice());
            }
            (Kind::So(_), Some(body), Some(so)) => {
                body.act_increment(xi, &z[..d], &mut dz[..d], so);
            }
            _ => return false,
        }
        if let (Some(group), Some(gs)) = (self.group, &mut s.group) {
            let (g, dg) = (&z[d..], &mut dz[d..]);
            dg.copy_from_slice(g);
            group.follow(self.side, &xi[..group.dim()], dg, gs);
            dg.iter_mut().zip(g).for_each(|(x, y)| *x -= y);
        }
        true
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

/// The derivative of the field (rk4 on the lift): ±(ad*_{D²H δμ} μ + ad*_{∇H} δμ), and with an
/// attitude δġ = δg ξ̂ + g δξ̂ (left) or ξ̂ δg + δξ̂ g (right), ξ = ∇H, in ambient coordinates
/// (on SO(3) too: the field lift's directions).
impl VectorFieldTangent for LiePoisson {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        let d = self.algebra.dim;
        let mut stack = [0.0; 96];
        let mut heap = Vec::new();
        let buf = if 3 * d <= stack.len() {
            &mut stack[..3 * d]
        } else {
            heap.resize(3 * d, 0.0);
            &mut heap[..]
        };
        let (grad, rest) = buf.split_at_mut(d);
        let (dgrad, t) = rest.split_at_mut(d);
        self.kernel_gradient(&z[..d], grad);
        self.kernel_hessian(&z[..d], &dz[..d], dgrad);
        let (om, og) = out.split_at_mut(d);
        if let (true, Some(group)) = (self.lifted, self.group) {
            let k = group.dim();
            let g = (&z[d..], &dz[d..]);
            group.velocity_tangent(self.side, (&grad[..k], &dgrad[..k]), g, og);
        }
        if self.side == Side::Right {
            grad.iter_mut().for_each(|x| *x = -*x);
            dgrad.iter_mut().for_each(|x| *x = -*x);
        }
        self.algebra.ad_star(dgrad, &z[..d], om);
        self.algebra.ad_star(grad, &dz[..d], t);
        om.iter_mut().zip(t.iter()).for_each(|(o, x)| *o += x);
    }
}

/// The derivatives of the coadjoint action for the tangent lift ([`GroupFieldTangent`]):
/// ξ′(μ)δμ = ∓D²H(μ)\[δμ\]; with w = dexp_u δu (exp(u + εδu) = exp(εw) exp(u) to first order),
/// δ(exp(u)·μ) = exp(u)·δμ + w·y = exp(u)·δμ − ad*_w y at y = exp(u)·μ (the action is linear
/// in μ, its generator −ad*); with the attitude, `Group::follow_tangent` (left-trivialised on
/// SO(3), ambient on the matrix blocks). dexp and its derivative: so(3) J_l and
/// [`so3::jacobian_left_derivative`]; so(n) the generalized body's dense series; otherwise the
/// structure constants' (`Structure::dexp_series`).
impl GroupFieldTangent for LiePoisson {
    fn generator_tangent(&self, z: &[f64], dz: &[f64], dxi: &mut [f64], _s: &mut LieScratch) {
        let d = self.algebra.dim;
        self.kernel_hessian(&z[..d], &dz[..d], dxi);
        if self.side == Side::Left {
            dxi.iter_mut().for_each(|x| *x = -*x);
        }
    }

    fn act_tangent(&self, u: &[f64], du: &[f64], y: &[f64], dz: &mut [f64], s: &mut LieScratch) {
        let d = self.algebra.dim;
        let (dm, dg) = dz.split_at_mut(d);
        let (ym, yg) = y.split_at(d);
        let attitude = self.lifted && self.group.is_some();
        match (&self.algebra.kind, &self.so_kernels, &mut s.so) {
            (Kind::So3, _, _) => {
                let (g, jl) = so3::exp_and_jacobian_left(&Vector3::from_column_slice(u));
                let w = jl * Vector3::from_column_slice(du);
                let m =
                    g * Vector3::from_column_slice(dm) + w.cross(&Vector3::from_column_slice(ym));
                dm.copy_from_slice(m.as_slice());
                s.lift[0][..3].copy_from_slice(w.as_slice());
            }
            (Kind::So(_), Some(body), Some(so)) => {
                body.act_tangent(u, du, ym, dm, so);
                if attitude {
                    body.dexp_apply(u, du, &mut s.lift[0], so);
                }
            }
            _ => {
                self.act_momentum(u, dm, s);
                let [w, t, e, p] = &mut s.lift;
                self.algebra.dexp_series(u, du, None, w, None, [t, e, p]);
                self.algebra.ad_star(w, ym, p);
                dm.iter_mut().zip(p.iter()).for_each(|(x, a)| *x -= a);
            }
        }
        if let (true, Some(group), Some(gs)) = (attitude, self.group, &mut s.group) {
            let k = group.dim();
            group.follow_tangent(self.side, &u[..k], &s.lift[0][..k], yg, dg, gs);
        }
    }

    fn dexp_tangent(&self, u: &[f64], du: &[f64], w: &[f64], out: &mut [f64], s: &mut LieScratch) {
        match (&self.algebra.kind, &self.so_kernels, &mut s.so) {
            (Kind::So3, _, _) => {
                let q = so3::jacobian_left_derivative(
                    &Vector3::from_column_slice(u),
                    &Vector3::from_column_slice(du),
                );
                out.copy_from_slice((q * Vector3::from_column_slice(w)).as_slice());
            }
            (Kind::So(_), Some(body), Some(so)) => body.dexp_tangent(u, du, w, out, so),
            _ => {
                let [value, t, e, p] = &mut s.lift;
                self.algebra
                    .dexp_series(u, w, Some(du), value, Some(out), [t, e, p]);
            }
        }
    }
}

impl Catalog for LiePoisson {
    /// rkmk4 (default), midpoint, midpoint4 (the Lie midpoint and its Suzuki composition),
    /// rk4.
    fn kind_catalog() -> Vec<Entry<Self>> {
        group_field_catalog()
    }

    /// Double-bracket dissipation of a left-invariant system (the generic construction takes
    /// the field as ad*_{∇H} μ; for a right-invariant one it would pump energy in).
    /// The system with its configuration g ([`LiePoisson::with_attitude`]).
    fn lifted(&self) -> Option<Self> {
        self.with_attitude()
    }

    /// The tangent lift of every method ([`crate::integrate::tangent`]; with the attitude on
    /// SO(3) all but rk4) where the derivatives are exact ([`LiePoisson::has_tangent`]).
    fn tangent(&self) -> Option<Arc<dyn TangentSystem>> {
        self.has_tangent()
            .then(|| Tangent::group_field(self.clone()).into_system())
    }

    /// With the attitude on SO(3), rk4 on the field lift (ambient directions).
    fn tangent_for(&self, method: &str) -> Option<Arc<dyn TangentSystem>> {
        match self.has_tangent() {
            true => Tangent::routed(self, method, || self.tangent()),
            false => None,
        }
    }

    fn dissipation(
        &self,
        d: &crate::integrate::forcing::Dissipation,
    ) -> crate::Result<std::sync::Arc<dyn crate::integrate::forcing::Perturbation>> {
        if self.side == Side::Right {
            return Err(Error::invalid(
                "dissipation",
                "double-bracket dissipation is built for left-invariant Lie–Poisson systems \
                 (side=\"left\"); this one is right-invariant",
            ));
        }
        crate::integrate::forcing::double_bracket(self, d)
    }
}

/// The Lie–Poisson methods on the tangent lift (each the derivative of its own step): rkmk4,
/// midpoint, midpoint4 and rk4 (with an SO(3) attitude rk4 on the field lift:
/// `lifted_catalog`).
impl Catalog for Tangent<LiePoisson> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        group_field_catalog()
    }

    fn catalog(&self) -> Vec<Entry<Self>> {
        lifted_catalog(self)
    }
}

/// [`group_field_catalog`] of a lift; where the state carries an SO(3) attitude, rk4 alone on
/// the field lift (its directions ambient: a Runge–Kutta step is not differentiated in
/// left-trivialised ones) and the others on the group-field lift.
pub(crate) fn lifted_catalog<P>(lift: &Tangent<P>) -> Vec<Entry<Tangent<P>>>
where
    P: GroupFieldTangent + VectorFieldTangent + Clone + 'static,
{
    let mut c = group_field_catalog();
    let space = lift.problem().space();
    if space.dim() != space.tangent_dim() {
        let ambient = lift.ambient();
        c.retain(|e| (e.name == "rk4") == ambient);
    }
    c
}
