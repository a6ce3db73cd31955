//! Tangent maps of the discrete flow (issue 26): the tangent lift of a problem, integrated by the
//! problem's own methods.
//!
//! **The mechanism.** For a problem P of a kind K and its state z ∈ ℝᵈ, the tangent lift TP is a
//! problem of the same kind K on (z, δz₁, …, δz_k), whose pieces are the pieces of P and their
//! directional derivatives (ż = f(z), δż_j = f′(z)δz_j). Every method of kind K then applies to TP
//! unchanged, and what it computes for the δz_j is exactly the derivative of its own discrete map
//! Φ_h applied to δz_j(0), to round-off — not an approximation of the variational equations:
//! - Runge–Kutta methods (RK4, Gauss) commute with linearisation: RK on the lifted field is the
//!   derivative of RK (internal differentiation; Hairer, Nørsett & Wanner I, §II.6);
//! - a splitting composes exact flows φ_τ; the lift's flows are their tangent maps
//!   (φ_τ(z), Dφ_τ(z)δz), exact flows of the lifted pieces, so the composition is the tangent of
//!   the composition (first-same-as-last fusion included: the lifted flows are flows);
//! - a Verlet composition is a composition of kicks q ↦ q, p ↦ p + τf(q) and drifts
//!   q ↦ q + τv(p): on the lifted separable problem (positions (q, δq), momenta (p, δp), force
//!   (f(q), f′(q)δq), velocity (v(p), v′(p)δp)) each kick and drift is the tangent map of the
//!   original one, so the composition is the tangent of the composition.
//!
//! So one lift per problem kind serves every method of that kind (no tangent twin of a method),
//! and a system opts in by giving the directional derivatives of its kind's primitives
//! ([`SeparableTangent`]: its force, from the potential's Hessian; [`VectorFieldTangent`]: its
//! field, for a canonical system through [`CanonicalTangent`], its Hamiltonian's Hessian
//! product; [`SplitTangent`]: its flows' tangent maps). The implicit methods' iterations converge
//! on the lifted unknowns as on the plain ones: the lifted Jacobian is block lower-triangular
//! with the plain one on its diagonal ([`VectorField::diagonal_blocks`]), so Gauss factors the
//! plain Newton matrix once per step and solves every direction with it (the
//! implicit-function theorem). Each block (the state, each direction) is measured against its
//! own scale ([`crate::convergence::Blocks`]): the state stops where the plain iteration does,
//! and its directions then converge at the accepted state. With k
//! directions the lifted state has at most d(1 + k) values, so a Jacobian run costs about
//! (1 + k) plain runs.
//!
//! **Parameters.** The problem's parameters θ ([`Problem::parameters`]) get p more directions
//! δz_{θ_m} = ∂z/∂θ_m, from 0 at the start, whose pieces carry the inhomogeneous term
//! (f′(z)δz + ∂f/∂θ_m; for a flow Dφ δz + ∂φ/∂θ_m): so k = e + p directions in all (e below).
//!
//! **Layouts.** A separable lift stores (q, δq₁, …, δq_k, p, δp₁, …, δp_k) (its kind needs the
//! positions before the momenta); a field, group-field or split lift (z, δz₁, …, δz_k). There
//! are e state directions, e = d less 6 per SO(3) block: the Jacobian is e × e, an SO(3) block's
//! directions left-trivialised (δR = Rξ̂). In a split or group-field lift a direction has those
//! e values (a flow's or a group action's tangent map is exact in ξ). In the field lift
//! ([`Tangent::field`]) it has all d values, ambient (δR a 3×3 matrix): a Runge–Kutta step
//! leaves SO(3), and its derivative is one of the flat values, which the field lift computes
//! with the field's derivative off the manifold ([`VectorFieldTangent::field_tangent`]). It
//! starts at δR = Rξ̂ and is read back by the derivative of the polar factor U of the run's R
//! ([`so3::PolarTangent`]: δU = Uξ̂), the flat blocks as they are, the base state as computed:
//! so every lift has the same e and Jacobian, and a system whose state has SO(3) blocks routes
//! its Runge–Kutta methods to the field lift ([`Catalog::tangent_for`], [`Tangent::routed`]),
//! the others to its left-trivialised lift. Without SO(3) blocks the layouts coincide (e = d).
//! [`TangentSystem::seed`] and [`TangentSystem::jacobian`] convert from and to the problem's
//! flat layout, so nothing outside this module sees either. The problem's chart
//! ([`Problem::to_internal`]) maps the directions by its tangent map at the base state
//! ([`Problem::tangent_to_internal_at`], ambient [`Problem::ambient_to_internal_at`]; by default
//! the chart itself, right for a linear one such as a turn to principal axes).
//!
//! **What the lift keeps.** Its space is the base's blocks and then the directions, so a run
//! retracts the base state's curved blocks exactly when the plain run does (every
//! [`crate::integrate::RETRACT_EVERY`] steps of a method that keeps the manifold): its base
//! states are the plain run's bit for bit however long the run. The directions are left as
//! they are: at a point of the manifold (to round-off) the retraction's derivative is the
//! identity on tangent directions (R(3I − RᵀR)/2 at RᵀR = I + E maps Rξ̂ to Rξ̂ + O(|E||ξ|)), so
//! the Jacobian is that of the retracted map to round-off. Its energy and invariants are the
//! base state's.

use std::sync::Arc;

pub use super::method::TangentSystem;

use super::method::Catalog;
use super::problem::{
    Canonical, Constrained, GroupField, Nonholonomic, Problem, Separable, Split, VectorField,
    Violation,
};
use super::space::{Block, Space};
use crate::error::{Error, Result};
use crate::lie::so3;
use nalgebra::{Matrix3, Vector3};

/// A [`Separable`] problem with the directional derivatives of its velocity and force: the data
/// of its tangent lift.
pub trait SeparableTangent: Separable {
    /// dv = v′(p)·dp, the derivative of the velocity along dp.
    fn velocity_tangent(&self, p: &[f64], dp: &[f64], dv: &mut [f64]);

    /// df = f′(q)·dq, the derivative of the force along dq (for f = −∂U/∂q, −D²U(q)\[dq\]).
    fn force_tangent(&self, q: &[f64], dq: &[f64], df: &mut [f64], s: &mut Self::Scratch);

    /// df += ∂f/∂θ_m (q) for the problem's parameter m ([`Problem::parameters`]); NaN unless
    /// a problem with parameters implements it (a run then stops at its first step).
    fn force_parameter(&self, _q: &[f64], _m: usize, df: &mut [f64], _s: &mut Self::Scratch) {
        df.fill(f64::NAN);
    }
}

/// A [`Split`] problem with the tangent maps of its exact flows: the data of its tangent lift
/// (whose flows are then the lifted flows (φ_τ(z), Dφ_τ(z)δz), exact again).
pub trait SplitTangent: Split {
    /// dz ← Dφ_i,τ(z)·dz for every direction dz in `dirs` (consecutive tangent vectors of
    /// [`crate::integrate::Space::tangent_dim`] values, internal frame), given the working
    /// state `before` the flow and `after` it: all at once, so that the flow's own quantities
    /// (its angle, its exponential) are formed once.
    fn flow_tangent(
        &self,
        i: usize,
        tau: f64,
        before: &Self::Work,
        after: &Self::Work,
        dirs: &mut [f64],
    );

    /// The directions (all of them, consecutive) from the state's coordinates into the working
    /// form's own, at the working point `w` just loaded (a work in other coordinates than the
    /// state, e.g. the reduced pseudo-rigid body's); the identity by default.
    fn directions_in(&self, _w: &Self::Work, _dirs: &mut [f64]) {}

    /// The inverse of [`SplitTangent::directions_in`], at the working point `w` being stored.
    fn directions_out(&self, _w: &Self::Work, _dirs: &mut [f64]) {}

    /// dz += ∂φ_i,τ/∂θ_m (z) for the parameter m, after [`SplitTangent::flow_tangent`] on the
    /// same dz; NaN unless a problem with parameters implements it.
    fn flow_parameter(
        &self,
        _i: usize,
        _tau: f64,
        _before: &Self::Work,
        _after: &Self::Work,
        _m: usize,
        dz: &mut [f64],
    ) {
        dz.fill(f64::NAN);
    }
}

/// A [`VectorField`] with the directional derivative of its field: the data of its tangent lift.
pub trait VectorFieldTangent: VectorField {
    /// out = f′(z)·dz, in ambient coordinates ([`Space::dim`] values; an SO(3) block's δR a
    /// 3×3 matrix, not necessarily tangent: the exact derivative of the field as a map of the
    /// flat values, which a Runge–Kutta stage evaluates off the manifold).
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]);

    /// out_j = f′(z)·dz_j for the consecutive directions dz_j of `dirs` (`out` alike): all at
    /// once, so that a field whose derivative has costly parts shared by every direction (a
    /// geometry's second derivatives) forms them once; by default one
    /// [`VectorFieldTangent::field_tangent`] each.
    fn field_tangents(&self, z: &[f64], dirs: &[f64], out: &mut [f64]) {
        let d = z.len();
        for (dz, o) in dirs.chunks_exact(d).zip(out.chunks_exact_mut(d)) {
            self.field_tangent(z, dz, o);
        }
    }

    /// out += ∂f/∂θ_m (z) for the parameter m; NaN unless a problem with parameters
    /// implements it.
    fn field_parameter(&self, _z: &[f64], _m: usize, out: &mut [f64]) {
        out.fill(f64::NAN);
    }
}

/// A [`Canonical`] system with the Hessian product of its Hamiltonian: the data of its tangent
/// lift, one route for every canonical system. Its Hamilton field f = (∂H/∂p, −∂H/∂q) has
/// f′(z)dz = (D(∂H/∂p)\[dz\], −D(∂H/∂q)\[dz\]), the blanket [`VectorFieldTangent`] below; the
/// lift is then `Tangent::field` (Gauss, implicit midpoint, RK4).
pub trait CanonicalTangent: Canonical {
    /// (dhq, dhp) = D²H(q, p)\[dq, dp\], the derivative of the gradient (∂H/∂q, ∂H/∂p) along
    /// (dq, dp) (every entry written; NaN where the gradient is NaN).
    fn gradient_tangent(
        &self,
        q: &[f64],
        p: &[f64],
        dq: &[f64],
        dp: &[f64],
        dhq: &mut [f64],
        dhp: &mut [f64],
    );

    /// dhq += ∂²H/∂θ_m∂q, dhp += ∂²H/∂θ_m∂p for the parameter m ([`Problem::parameters`]);
    /// NaN unless a system with parameters implements it.
    fn gradient_parameter(
        &self,
        _q: &[f64],
        _p: &[f64],
        _m: usize,
        dhq: &mut [f64],
        dhp: &mut [f64],
    ) {
        dhq.fill(f64::NAN);
        dhp.fill(f64::NAN);
    }
}

/// f′(z)dz = (D(∂H/∂p)\[dz\], −D(∂H/∂q)\[dz\]) and ∂f/∂θ_m = (∂²H/∂θ_m∂p, −∂²H/∂θ_m∂q): the
/// Hamilton field's derivatives, in place (the ṗ half negated around the call, exactly).
impl<P: CanonicalTangent + VectorField> VectorFieldTangent for P {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        let d = self.dof();
        let (oq, op) = out.split_at_mut(d);
        self.gradient_tangent(&z[..d], &z[d..], &dz[..d], &dz[d..], op, oq);
        op.iter_mut().for_each(|x| *x = -*x);
    }

    fn field_parameter(&self, z: &[f64], m: usize, out: &mut [f64]) {
        let d = self.dof();
        let (oq, op) = out.split_at_mut(d);
        op.iter_mut().for_each(|x| *x = -*x);
        self.gradient_parameter(&z[..d], &z[d..], m, op, oq);
        op.iter_mut().for_each(|x| *x = -*x);
    }
}

/// A [`GroupField`] with the derivatives of its generator, its action and its dexp: the data of
/// its tangent lift, on which the Lie-group methods (RKMK, the Lie midpoint) compute the
/// derivative of their own step (each of their operations replaced by its derivative: the
/// generator by ξ′(z)δz, the action by its derivative in (u, z), dexp⁻¹ by its derivative in
/// (u, v)).
pub trait GroupFieldTangent: GroupField {
    /// dξ = ξ′(z)·dz.
    fn generator_tangent(&self, z: &[f64], dz: &[f64], dxi: &mut [f64], s: &mut Self::Scratch);

    /// dξ += ∂ξ/∂θ_m (z) for the parameter m; NaN unless a problem with parameters implements
    /// it.
    fn generator_parameter(&self, _z: &[f64], _m: usize, dxi: &mut [f64], _s: &mut Self::Scratch) {
        dxi.fill(f64::NAN);
    }

    /// dz ← D(exp(u)·z)\[du, dz\] = exp(u)·dz + (dexp_u du)·y, the derivative of the action
    /// along (du, dz), given its result y = exp(u)·z (dexp right-trivialised, as
    /// [`GroupField::dexp_inv`]'s inverse).
    fn act_tangent(&self, u: &[f64], du: &[f64], y: &[f64], dz: &mut [f64], s: &mut Self::Scratch);

    /// out = D_u(dexp_u w)\[du\], the derivative of dexp_u w in u (then
    /// D(dexp⁻¹_u v)\[du, dv\] = dexp⁻¹_u(dv − D_u(dexp_u w)\[du\]) at w = dexp⁻¹_u v).
    fn dexp_tangent(
        &self,
        u: &[f64],
        du: &[f64],
        w: &[f64],
        out: &mut [f64],
        s: &mut Self::Scratch,
    );
}

/// f′(z)dz = (v′(p)dp, f′(q)dq) of a separable problem's Hamilton field, from its
/// [`SeparableTangent`] derivatives: the [`VectorFieldTangent`] of a separable system.
pub fn separable_field_tangent<P: SeparableTangent>(
    problem: &P,
    z: &[f64],
    dz: &[f64],
    out: &mut [f64],
    s: &mut P::Scratch,
) {
    let d = problem.dof();
    let (ov, of) = out.split_at_mut(d);
    problem.velocity_tangent(&z[d..], &dz[d..], ov);
    problem.force_tangent(&z[..d], &dz[..d], of, s);
}

thread_local! {
    /// Work space of the separable layout's gathers (three state-sized vectors per thread,
    /// sized at their first use).
    static BUFFERS: std::cell::Cell<[Vec<f64>; 3]> = Default::default();
}

/// Runs `f` on this thread's buffers, taken out for the call: a user function called inside
/// (a Hessian that runs another lifted integration) finds none and gets fresh ones, never a
/// buffer in use.
fn with_buffers<R>(f: impl FnOnce(&mut [Vec<f64>; 3]) -> R) -> R {
    let mut buffers = BUFFERS.take();
    let r = f(&mut buffers);
    BUFFERS.set(buffers);
    r
}

/// Where the lift keeps its directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layout {
    /// (q, δq₁…δq_k, p, δp₁…δp_k), each block of length `dof`.
    Separable { dof: usize },
    /// (z, δz₁…δz_k).
    Field,
}

/// The tangent lift of a problem with k = e + p directions (module docs).
#[derive(Clone, Debug)]
pub struct Tangent<P> {
    problem: P,
    /// The state's and a tangent vector's dimensions (they differ by 6 per SO(3) block): e
    /// state directions, and the Jacobian is e × e.
    d: usize,
    e: usize,
    /// The values of a direction: e (left-trivialised), or d (ambient: the field lift).
    w: usize,
    /// The number of parameter directions (after the e state directions).
    np: usize,
    layout: Layout,
}

impl<P: Problem + Clone> Tangent<P> {
    /// The lift with directions of e values (left-trivialised), or of d values (`ambient`).
    fn with(problem: P, layout: Layout, ambient: bool) -> Self {
        let (d, e) = (problem.space().dim(), problem.space().tangent_dim());
        let np = problem.parameters().len();
        Tangent {
            problem,
            d,
            e,
            w: if ambient { d } else { e },
            np,
            layout,
        }
    }

    /// Whether the directions are ambient on SO(3) blocks (δR a 3×3 matrix): the field lift of
    /// a state with SO(3) blocks ([`Tangent::field`]), whose catalog is its Runge–Kutta
    /// methods.
    pub fn ambient(&self) -> bool {
        self.w != self.e
    }

    /// The number k = e + p of directions.
    #[inline]
    fn k(&self) -> usize {
        self.e + self.np
    }

    /// The length of block j: the state (j = 0) or a direction.
    #[inline]
    fn len_of(&self, j: usize) -> usize {
        if j == 0 {
            self.d
        } else {
            self.w
        }
    }

    /// The base problem.
    pub fn problem(&self) -> &P {
        &self.problem
    }

    /// Index of component i of the base state (j = 0, i < d) or of direction j (i < w).
    #[inline]
    fn at(&self, j: usize, i: usize) -> usize {
        match self.layout {
            Layout::Field if j == 0 => i,
            Layout::Field => self.d + (j - 1) * self.w + i,
            Layout::Separable { dof } => {
                let (half, c) = (i / dof, i % dof);
                half * dof * (self.k() + 1) + j * dof + c
            }
        }
    }

    fn gather(&self, lifted: &[f64], j: usize, out: &mut [f64]) {
        for (i, o) in out[..self.len_of(j)].iter_mut().enumerate() {
            *o = lifted[self.at(j, i)];
        }
    }

    fn scatter(&self, v: &[f64], j: usize, lifted: &mut [f64]) {
        for (i, x) in v[..self.len_of(j)].iter().enumerate() {
            lifted[self.at(j, i)] = *x;
        }
    }

    /// Applies `tangent` to every direction, given the base state as it was, then `state` to
    /// the base state. In place in the field layout; the separable one through this thread's
    /// buffers (allocated once, not per saved sample).
    fn each(
        &self,
        z: &mut [f64],
        state: impl Fn(&mut [f64]),
        tangent: impl Fn(&[f64], &mut [f64]),
    ) {
        if self.layout == Layout::Field {
            let (base, dirs) = z.split_at_mut(self.d);
            dirs.chunks_exact_mut(self.w).for_each(|v| tangent(base, v));
            state(base);
            return;
        }
        with_buffers(|[v, base, _]| {
            v.resize(self.d, 0.0);
            base.resize(self.d, 0.0);
            self.gather(z, 0, base);
            for j in 1..=self.k() {
                self.gather(z, j, v);
                tangent(base, &mut v[..self.w]);
                self.scatter(v, j, z);
            }
            state(base);
            self.scatter(base, 0, z);
        });
    }
}

impl<P: SeparableTangent + Clone> Tangent<P> {
    /// The lift of a separable problem (its Verlet methods; flat blocks only).
    pub fn separable(problem: P) -> Self {
        let dof = problem.dof();
        Tangent::with(problem, Layout::Separable { dof }, false)
    }
}

impl<P: VectorFieldTangent + Clone> Tangent<P> {
    /// The lift of a vector field (its Runge–Kutta and Gauss methods): (z, δz₁, …, δz_k), each
    /// direction of d values, ambient on SO(3) blocks (module docs, "Layouts").
    pub fn field(problem: P) -> Self {
        Tangent::with(problem, Layout::Field, true)
    }
}

impl<P: VectorFieldTangent + Clone> Tangent<P>
where
    Tangent<P>: Catalog,
{
    /// [`Catalog::tangent_for`] of a system whose state has SO(3) blocks: the field lift for the
    /// methods of its catalog (the Runge–Kutta methods), `other` (the system's left-trivialised
    /// lift) for the rest.
    pub fn routed(
        problem: &P,
        method: &str,
        other: impl FnOnce() -> Option<Arc<dyn TangentSystem>>,
    ) -> Option<Arc<dyn TangentSystem>> {
        let field = Tangent::field(problem.clone());
        let ours = field.ambient() && field.catalog().iter().any(|e| e.name == method);
        if ours {
            Some(field.into_system())
        } else {
            other()
        }
    }
}

impl<P: GroupFieldTangent + Clone> Tangent<P> {
    /// The lift of a group field (its Lie-group methods; and its Runge–Kutta methods where it is
    /// a [`VectorFieldTangent`] without SO(3) blocks): (z, δz₁, …, δz_k), the directions
    /// left-trivialised on SO(3) blocks.
    pub fn group_field(problem: P) -> Self {
        Tangent::with(problem, Layout::Field, false)
    }
}

impl<P: SplitTangent + Clone> Tangent<P> {
    /// The lift of a split problem (its splittings; and its Runge–Kutta methods where it is a
    /// [`VectorFieldTangent`] without SO(3) blocks): (z, δz₁, …, δz_k), the directions
    /// left-trivialised on SO(3) blocks.
    pub fn split(problem: P) -> Self {
        Tangent::with(problem, Layout::Field, false)
    }
}

impl<P: Problem + Clone> Problem for Tangent<P> {
    fn name(&self) -> &'static str {
        self.problem.name()
    }

    /// The base problem's blocks, then the directions (d + k·w values in all, w = e, or d for
    /// the field lift): a run retracts the base state's curved blocks as the plain run does
    /// (module docs); the separable layout interleaves its values and is flat (its problems are).
    fn space(&self) -> Space {
        match self.layout {
            Layout::Field => self
                .problem
                .space()
                .with("directions", Block::Real(self.k() * self.w)),
            Layout::Separable { .. } => {
                Space::new([("z", Block::Real(self.d + self.k() * self.w))])
            }
        }
    }

    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.problem.energy(&self.base(z))
    }

    fn rate(&self, z: &[f64]) -> Option<f64> {
        self.problem.rate(&self.base(z))
    }

    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.problem.invariants(&self.base(z))
    }

    fn invariant_names(&self) -> Vec<String> {
        self.problem.invariant_names()
    }

    /// The base state checked as the base problem checks it (its space, its constraints).
    fn check_state(&self, z: &[f64]) -> Result<()> {
        let base = self.base(z);
        self.problem.space().check("state", &base)?;
        self.problem.check_state(&base)
    }

    /// The directions by the chart's tangent map at the base state: ambient
    /// ([`Problem::ambient_to_internal_at`]) or left-trivialised.
    fn to_internal(&self, z: &mut [f64]) {
        let ambient = self.ambient();
        self.each(
            z,
            |v| self.problem.to_internal(v),
            |b, v| match ambient {
                true => self.problem.ambient_to_internal_at(b, v),
                false => self.problem.tangent_to_internal_at(b, v),
            },
        );
    }

    fn to_user(&self, z: &mut [f64]) {
        let ambient = self.ambient();
        self.each(
            z,
            |v| self.problem.to_user(v),
            |b, v| match ambient {
                true => self.problem.ambient_to_user_at(b, v),
                false => self.problem.tangent_to_user_at(b, v),
            },
        );
    }

    fn calls_out(&self) -> bool {
        self.problem.calls_out()
    }

    /// A non-finite entry named by what it is to the user: of the base state (its index), else
    /// of the Jacobian or the parameter Jacobian (row and column, the parameter's name), never
    /// by its place in the lift's layout (e.g. ∂M/∂I beyond the float range while M is not).
    fn check_finite(&self, z: &[f64]) -> Result<()> {
        if z.iter().all(|x| x.is_finite()) {
            return Ok(());
        }
        let names = self.problem.parameters();
        for j in 0..=self.k() {
            let Some(i) = (0..self.len_of(j)).find(|&i| !z[self.at(j, i)].is_finite()) else {
                continue;
            };
            let (what, location) = match j {
                0 => ("state".to_string(), format!("index {i}")),
                j if j <= self.e => (
                    "the Jacobian ∂z/∂z₀ (sensitivity=True)".to_string(),
                    format!("row {i}, column {}", j - 1),
                ),
                j => {
                    let m = j - 1 - self.e;
                    (
                        "the parameter Jacobian ∂z/∂θ (sensitivity=True)".to_string(),
                        format!("row {i}, column {m} ({})", names.get(m).unwrap_or(&"?")),
                    )
                }
            };
            return Err(Error::NonFinite { what, location });
        }
        crate::check::finite_slice("state", z)
    }
}

impl<P: Problem + Clone> Tangent<P> {
    fn base(&self, z: &[f64]) -> Vec<f64> {
        let mut v = vec![0.0; self.d];
        self.gather(z, 0, &mut v);
        v
    }
}

/// The work space of a separable lift's kernels: the base problem's, and for a constrained lift
/// G(q), D²g(q)\[δq, ·\] and the polarisation's buffers, for a nonholonomic lift A(q) and
/// DA(q)\[δq\] (sized at their first use).
pub struct LiftScratch<S> {
    base: S,
    jac: Vec<f64>,
    second: Vec<f64>,
    w: Vec<f64>,
    c: Vec<f64>,
}

/// Positions (q, δq₁…δq_k), momenta (p, δp₁…δp_k), force (f(q), f′(q)δq_j), velocity
/// (v(p), v′(p)δp_j).
impl<P: SeparableTangent + Clone> Separable for Tangent<P> {
    type Scratch = LiftScratch<P::Scratch>;

    fn scratch(&self) -> Self::Scratch {
        LiftScratch {
            base: self.problem.scratch(),
            jac: Vec::new(),
            second: Vec::new(),
            w: Vec::new(),
            c: Vec::new(),
        }
    }

    fn dof(&self) -> usize {
        self.problem.dof() * (self.k() + 1)
    }

    /// The state and its k directions (the constrained and nonholonomic lifts' matrices are
    /// block lower-triangular with the base one on the diagonal).
    fn diagonal_blocks(&self) -> usize {
        self.k() + 1
    }

    /// The velocity does not depend on the parameters (T(p) is the problem's own).
    fn velocity(&self, p: &[f64], v: &mut [f64]) {
        let n = self.problem.dof();
        let (v0, dv) = v.split_at_mut(n);
        self.problem.velocity(&p[..n], v0);
        for (dpj, dvj) in p[n..].chunks_exact(n).zip(dv.chunks_exact_mut(n)) {
            self.problem.velocity_tangent(&p[..n], dpj, dvj);
        }
    }

    fn force(
        &self,
        q: &[f64],
        f: &mut [f64],
        s: &mut Self::Scratch,
    ) -> std::result::Result<(), Violation> {
        let s = &mut s.base;
        let n = self.problem.dof();
        let (f0, df) = f.split_at_mut(n);
        self.problem.force(&q[..n], f0, s)?;
        let e = self.e;
        for (j, (dqj, dfj)) in q[n..]
            .chunks_exact(n)
            .zip(df.chunks_exact_mut(n))
            .enumerate()
        {
            self.problem.force_tangent(&q[..n], dqj, dfj, s);
            if j >= e {
                self.problem.force_parameter(&q[..n], j - e, dfj, s);
            }
        }
        Ok(())
    }
}

/// D²g(q)\[u, ·\] into `rows` (m × d, row-major), by polarisation of the quadratic form
/// D²g(q)\[w, w\] ([`Constrained::constraint_curvature`]; exact up to round-off): `w` (d
/// values) and `c` (2m values) are work space.
pub fn constraint_second<P: Constrained>(
    problem: &P,
    q: &[f64],
    u: &[f64],
    rows: &mut [f64],
    w: &mut [f64],
    c: &mut [f64],
    s: &mut P::Scratch,
) {
    if problem.constraint_second(q, u, rows, s) {
        return;
    }
    let (d, m) = (problem.dof(), problem.constraints());
    let (cp, cm) = c.split_at_mut(m);
    w.copy_from_slice(u);
    for k in 0..d {
        w[k] = u[k] + 1.0;
        problem.constraint_curvature(q, w, cp, s);
        w[k] = u[k] - 1.0;
        problem.constraint_curvature(q, w, cm, s);
        w[k] = u[k];
        for a in 0..m {
            rows[a * d + k] = 0.25 * (cp[a] - cm[a]);
        }
    }
}

/// The lift of a constrained problem (RATTLE): the constraints g̃ = (g(q), G(q)δq₁, …,
/// G(q)δq_k), whose Jacobian is block lower-triangular (G on the diagonal, D²g(q)\[δq_j, ·\]
/// in the first column). A level-set problem's lift is one too (the level of G(q)δq_j is its
/// initial value: the derivative of the level g(q₀) along δq₀); otherwise G(q)δq_j = 0, the
/// derivative of the map as RATTLE extends it off the constraint manifold (its first step
/// projects).
impl<P: Constrained + SeparableTangent + Clone> Constrained for Tangent<P> {
    fn constraints(&self) -> usize {
        self.problem.constraints() * (self.k() + 1)
    }

    fn level_set(&self) -> bool {
        self.problem.level_set()
    }

    fn constraint(&self, q: &[f64], g: &mut [f64], s: &mut Self::Scratch) {
        let (n, m) = (self.problem.dof(), self.problem.constraints());
        let LiftScratch { base, jac, .. } = s;
        jac.resize(m * n, 0.0);
        self.problem.constraint(&q[..n], &mut g[..m], base);
        self.problem.constraint_jacobian(&q[..n], jac, base);
        for (dq, gj) in q[n..].chunks_exact(n).zip(g[m..].chunks_exact_mut(m)) {
            for (ga, row) in gj.iter_mut().zip(jac.chunks_exact(n)) {
                *ga = row.iter().zip(dq).map(|(x, y)| x * y).sum();
            }
        }
    }

    fn constraint_jacobian(&self, q: &[f64], jac: &mut [f64], s: &mut Self::Scratch) {
        self.constrained_rows(q, Coupling::Column, jac, s);
    }

    /// The force rows pair the other way round: the base multipliers λ act on the directions
    /// through D²g(q)\[δq_j, ·\]ᵀλ (the derivative of G(q)ᵀλ), so F = (G, D²g\[δq₁, ·\], …)
    /// for the base rows and G in its own block for each direction's; with G̃ as above,
    /// G̃ M̃⁻¹F̃ᵀ is block lower-triangular with G M⁻¹Gᵀ on its diagonal.
    fn constraint_forces(&self, q: &[f64], rows: &mut [f64], s: &mut Self::Scratch) -> bool {
        self.constrained_rows(q, Coupling::Row, rows, s);
        true
    }

    /// NaN: the lift's curvature needs D³g, which no constraint gives (RATTLE does not use it;
    /// the index-1 field of a lift is not offered).
    fn constraint_curvature(
        &self,
        _q: &[f64],
        _v: &[f64],
        out: &mut [f64],
        _s: &mut Self::Scratch,
    ) {
        out.fill(f64::NAN);
    }
}

/// Where the coupling blocks of a constrained lift's rows sit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Coupling {
    /// In the first block column, (j, 0): the constraint rows (the derivative of the base rows
    /// along δq_j acts on the base velocity or position).
    Column,
    /// In the first block row, (0, j): the force rows (the base multipliers act on direction j
    /// through the derivative of the base rows).
    Row,
}

/// The m(k + 1) × n(k + 1) rows (row-major) of a constrained lift: the base rows `own` (m × n)
/// in every diagonal block, and for each direction j ≥ 1 the block `coupling(j, buf)` (m × n,
/// written to `buf`) at (j, 0) or (0, j) ([`Coupling`]); zero elsewhere. One layout for the
/// holonomic lift (G, D²g\[δq_j, ·\]) and the nonholonomic one (A, DA\[δq_j\]).
fn lifted_rows(
    own: &[f64],
    n: usize,
    k: usize,
    at: Coupling,
    buf: &mut [f64],
    mut coupling: impl FnMut(usize, &mut [f64]),
    rows: &mut [f64],
) {
    let m = own.len() / n;
    let cols = n * (k + 1);
    rows.fill(0.0);
    for j in 0..=k {
        if j > 0 {
            coupling(j, buf);
        }
        for a in 0..m {
            let diag = (j * m + a) * cols + j * n;
            rows[diag..diag + n].copy_from_slice(&own[a * n..(a + 1) * n]);
            if j > 0 {
                let off = match at {
                    Coupling::Column => (j * m + a) * cols,
                    Coupling::Row => a * cols + j * n,
                };
                rows[off..off + n].copy_from_slice(&buf[a * n..(a + 1) * n]);
            }
        }
    }
}

impl<S> LiftScratch<S> {
    /// The buffers for m base rows of length n.
    fn sized(&mut self, m: usize, n: usize) {
        self.jac.resize(m * n, 0.0);
        self.second.resize(m * n, 0.0);
        self.w.resize(n, 0.0);
        self.c.resize(2 * m, 0.0);
    }
}

impl<P: Constrained + SeparableTangent + Clone> Tangent<P> {
    /// The holonomic lift's constraint rows (G̃) or force rows (F̃) at the lifted position q.
    fn constrained_rows(
        &self,
        q: &[f64],
        at: Coupling,
        rows: &mut [f64],
        s: &mut LiftScratch<P::Scratch>,
    ) {
        let (n, m, k) = (self.problem.dof(), self.problem.constraints(), self.k());
        s.sized(m, n);
        let LiftScratch {
            base,
            jac: g,
            second,
            w,
            c,
        } = s;
        self.problem.constraint_jacobian(&q[..n], g, base);
        let coupling = |j: usize, out: &mut [f64]| {
            let dq = &q[j * n..(j + 1) * n];
            constraint_second(&self.problem, &q[..n], dq, out, w, c, base);
        };
        lifted_rows(g, n, k, at, second, coupling, rows);
    }
}

impl<P: Nonholonomic + SeparableTangent + Clone> Tangent<P> {
    /// The nonholonomic lift's constraint rows (Ã) or force rows (F̃) at the lifted position q.
    fn velocity_rows(
        &self,
        q: &[f64],
        at: Coupling,
        rows: &mut [f64],
        s: &mut LiftScratch<P::Scratch>,
    ) {
        let (n, m, k) = (
            self.problem.dof(),
            Nonholonomic::constraints(&self.problem),
            self.k(),
        );
        s.sized(m, n);
        let LiftScratch {
            base,
            jac: a,
            second,
            ..
        } = s;
        self.problem.constraint_matrix(&q[..n], a, base);
        let coupling = |j: usize, out: &mut [f64]| {
            let dq = &q[j * n..(j + 1) * n];
            self.problem
                .constraint_matrix_tangent(&q[..n], dq, out, base);
        };
        lifted_rows(a, n, k, at, second, coupling, rows);
    }
}

/// The lift of a nonholonomic problem (Lagrange–d'Alembert; `NonholonomicRattle`): the
/// velocity constraints Ã(q̃)ṽ = 0 with Ã = \[\[A(q), 0\], \[DA(q)\[δq_j\], A(q)\]\] (the derivative
/// of A(q)v = 0: DA(q)\[δq_j\]v + A(q)δv_j = 0), block lower-triangular, and the force rows
/// paired the other way round (the derivative of −A(q)ᵀλ is −DA(q)\[δq_j\]ᵀλ − A(q)ᵀδλ_j): as for
/// the holonomic lift, every matrix of the method's step is block lower-triangular with the
/// plain one on its diagonal, and the method applied to the lift is the derivative of the
/// method. A direction needs not satisfy the linearised constraint at the start: like the
/// method's map off the constraint (its steps project), the lift differentiates across it.
impl<P: Nonholonomic + SeparableTangent + Clone> Nonholonomic for Tangent<P> {
    fn constraints(&self) -> usize {
        Nonholonomic::constraints(&self.problem) * (self.k() + 1)
    }

    fn constraint_matrix(&self, q: &[f64], a: &mut [f64], s: &mut Self::Scratch) {
        self.velocity_rows(q, Coupling::Column, a, s);
    }

    /// F̃: the base rows (A, DA\[δq₁\], …, DA\[δq_k\]) and A in its own block for each
    /// direction's.
    fn constraint_forces(&self, q: &[f64], rows: &mut [f64], s: &mut Self::Scratch) -> bool {
        self.velocity_rows(q, Coupling::Row, rows, s);
        true
    }

    /// NaN: the lift's derivative needs D²A, which no system gives (a lift is not lifted again).
    fn constraint_matrix_tangent(
        &self,
        _q: &[f64],
        _dq: &[f64],
        out: &mut [f64],
        _s: &mut Self::Scratch,
    ) {
        out.fill(f64::NAN);
    }
}

/// (f(z), f′(z)δz_j), in either layout (a separable problem's lift serves its Verlet methods
/// and its Runge–Kutta and Gauss methods with one layout).
impl<P: VectorFieldTangent + Clone> VectorField for Tangent<P> {
    /// Only with directions of d values (the field lift, or a lift of a state without SO(3)
    /// blocks): a Runge–Kutta step on a curved block is differentiated in its ambient
    /// coordinates, which a left-trivialised direction is not; such a lift gets NaN here (its
    /// catalog offers no Runge–Kutta method).
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let (d, e) = (self.d, self.e);
        if self.w != d {
            dz.fill(f64::NAN);
            return;
        }
        if self.layout == Layout::Field {
            let (f0, df) = dz.split_at_mut(d);
            self.problem.field(&z[..d], f0);
            self.problem.field_tangents(&z[..d], &z[d..], df);
            for (m, dfj) in df[e * d..].chunks_exact_mut(d).enumerate() {
                self.problem.field_parameter(&z[..d], m, dfj);
            }
            return;
        }
        // Separable layout: each block gathered into this thread's buffers (allocated once).
        with_buffers(|[base, dir, out]| {
            for v in [&mut *base, &mut *dir, &mut *out] {
                v.resize(d, 0.0);
            }
            self.gather(z, 0, base);
            self.problem.field(base, out);
            self.scatter(out, 0, dz);
            for j in 1..=self.k() {
                self.gather(z, j, dir);
                self.problem.field_tangent(base, dir, out);
                if j > e {
                    self.problem.field_parameter(base, j - 1 - e, out);
                }
                self.scatter(out, j, dz);
            }
        });
    }

    /// The state and its k directions: f′ is block lower-triangular with f′(z) on each diagonal
    /// block (an implicit method factors it once).
    fn diagonal_blocks(&self) -> usize {
        if self.w == self.d {
            self.k() + 1
        } else {
            1
        }
    }

    fn block_index(&self, b: usize, i: usize) -> usize {
        if self.w == self.d {
            self.at(b, i)
        } else {
            i
        }
    }
}

/// The work space of a group-field lift's kernels: the base problem's, the base result of an
/// action, two algebra vectors.
pub struct GroupLiftScratch<S> {
    base: S,
    y: Vec<f64>,
    t: Vec<f64>,
    v: Vec<f64>,
}

/// The generator (ξ(z), ξ′(z)δz_j), the action (exp(u)·z, D(exp(u)·z)\[δu_j, δz_j\]) and
/// dexp⁻¹ (dexp⁻¹_u v, its derivative along (δu_j, δv_j)) of the lift, in the algebra
/// coordinates (u, δu₁, …, δu_k): each the derivative of the base one, so a Lie-group method's
/// step on the lift (built from these and linear combinations) is the derivative of its step.
impl<P: GroupFieldTangent + Clone> GroupField for Tangent<P> {
    type Scratch = GroupLiftScratch<P::Scratch>;

    fn scratch(&self) -> Self::Scratch {
        let g = self.problem.algebra_dim();
        GroupLiftScratch {
            base: self.problem.scratch(),
            y: vec![0.0; self.d],
            t: vec![0.0; g],
            v: vec![0.0; g],
        }
    }

    fn algebra_dim(&self) -> usize {
        self.problem.algebra_dim() * (self.k() + 1)
    }

    /// The state and its k directions (the lifted iteration's blocks).
    fn diagonal_blocks(&self) -> usize {
        self.k() + 1
    }

    fn generator(&self, z: &[f64], xi: &mut [f64], s: &mut Self::Scratch) {
        let (d, e, g) = (self.d, self.e, self.problem.algebra_dim());
        let (x0, dx) = xi.split_at_mut(g);
        self.problem.generator(&z[..d], x0, &mut s.base);
        for (j, (dz, dxj)) in z[d..]
            .chunks_exact(self.w)
            .zip(dx.chunks_exact_mut(g))
            .enumerate()
        {
            self.problem
                .generator_tangent(&z[..d], dz, dxj, &mut s.base);
            if j >= e {
                self.problem
                    .generator_parameter(&z[..d], j - e, dxj, &mut s.base);
            }
        }
    }

    fn act(&self, u: &[f64], z: &mut [f64], s: &mut Self::Scratch) {
        let (d, w, g) = (self.d, self.w, self.problem.algebra_dim());
        let (z0, dz) = z.split_at_mut(d);
        self.problem.act(&u[..g], z0, &mut s.base);
        for (dzj, du) in dz.chunks_exact_mut(w).zip(u[g..].chunks_exact(g)) {
            self.problem.act_tangent(&u[..g], du, z0, dzj, &mut s.base);
        }
    }

    /// The base state's increment as the base problem forms it (so the lifted run's states
    /// are the plain run's), the directions' as new minus old.
    fn act_increment(&self, u: &[f64], z: &[f64], inc: &mut [f64], s: &mut Self::Scratch) -> bool {
        let (d, w, g) = (self.d, self.w, self.problem.algebra_dim());
        let (i0, di) = inc.split_at_mut(d);
        if !self
            .problem
            .act_increment(&u[..g], &z[..d], i0, &mut s.base)
        {
            return false;
        }
        for ((y, zi), dzi) in s.y.iter_mut().zip(&z[..d]).zip(i0.iter()) {
            *y = zi + dzi;
        }
        for ((dij, du), dz) in di
            .chunks_exact_mut(w)
            .zip(u[g..].chunks_exact(g))
            .zip(z[d..].chunks_exact(w))
        {
            dij.copy_from_slice(dz);
            self.problem
                .act_tangent(&u[..g], du, &s.y, dij, &mut s.base);
            dij.iter_mut().zip(dz).for_each(|(a, b)| *a -= b);
        }
        true
    }

    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], s: &mut Self::Scratch) {
        let g = self.problem.algebra_dim();
        let (w, dw) = out.split_at_mut(g);
        self.problem.dexp_inv(&u[..g], &v[..g], w, &mut s.base);
        for ((du, dv), dwj) in u[g..]
            .chunks_exact(g)
            .zip(v[g..].chunks_exact(g))
            .zip(dw.chunks_exact_mut(g))
        {
            self.problem
                .dexp_tangent(&u[..g], du, w, &mut s.t, &mut s.base);
            for ((vi, dvi), ti) in s.v.iter_mut().zip(dv).zip(&s.t) {
                *vi = dvi - ti;
            }
            self.problem.dexp_inv(&u[..g], &s.v, dwj, &mut s.base);
        }
    }

    fn solve_tolerance(&self) -> f64 {
        self.problem.solve_tolerance()
    }
}

/// The working form of a split lift: the base problem's, and the directions (flat).
#[derive(Clone, Debug)]
pub struct SplitWork<W> {
    base: W,
    /// The base before the current flow (its storage reused from flow to flow).
    before: W,
    dirs: Vec<f64>,
}

/// The flows (φ_τ(z), Dφ_τ(z)δz_j), in either layout (a separable problem's lift serves its
/// Verlet methods and its splittings with one layout); the directions in the working form's
/// coordinates ([`SplitTangent::directions_in`]) while loaded.
impl<P: SplitTangent + Clone> Split for Tangent<P> {
    type Work = SplitWork<P::Work>;

    fn load(&self, z: &[f64]) -> Result<Self::Work> {
        let mut dirs = vec![0.0; self.k() * self.w];
        for (j, v) in dirs.chunks_exact_mut(self.w).enumerate() {
            self.gather(z, j + 1, v);
        }
        let base = with_buffers(|[b, ..]| {
            b.resize(self.d, 0.0);
            self.gather(z, 0, b);
            self.problem.load(b)
        })?;
        self.problem.directions_in(&base, &mut dirs);
        Ok(SplitWork {
            before: base.clone(),
            base,
            dirs,
        })
    }

    fn store(&self, w: &Self::Work, z: &mut [f64]) {
        with_buffers(|[b, v, _]| {
            b.resize(self.d, 0.0);
            self.problem.store(&w.base, b);
            self.scatter(b, 0, z);
            v.clear();
            v.extend_from_slice(&w.dirs);
            self.problem.directions_out(&w.base, v);
            for (j, dz) in v.chunks_exact(self.w).enumerate() {
                self.scatter(dz, j + 1, z);
            }
        });
    }

    fn flows(&self) -> usize {
        self.problem.flows()
    }

    fn flow(&self, i: usize, tau: f64, w: &mut Self::Work) {
        w.before.clone_from(&w.base);
        self.problem.flow(i, tau, &mut w.base);
        self.problem
            .flow_tangent(i, tau, &w.before, &w.base, &mut w.dirs);
        for (m, dz) in w.dirs[self.e * self.w..]
            .chunks_exact_mut(self.w)
            .enumerate()
        {
            self.problem
                .flow_parameter(i, tau, &w.before, &w.base, m, dz);
        }
    }

    const CHECKED: bool = P::CHECKED;

    fn check_step(&self, w: &mut Self::Work) -> std::result::Result<(), Violation> {
        self.problem.check_step(&mut w.base)
    }
}

impl<P: Problem + Clone> Tangent<P>
where
    Tangent<P>: Catalog,
{
    /// The lift as a [`TangentSystem`] trait object.
    pub fn into_system(self) -> Arc<dyn TangentSystem> {
        Arc::new(self)
    }
}

impl<P: Problem + Clone> TangentSystem for Tangent<P>
where
    Tangent<P>: Catalog,
{
    fn base_dim(&self) -> usize {
        self.d
    }

    fn tangent_dim(&self) -> usize {
        self.e
    }

    fn parameter_names(&self) -> Vec<&'static str> {
        self.problem.parameters()
    }

    fn seed(&self, z0: &[f64]) -> Result<Vec<f64>> {
        if z0.len() != self.d {
            return Err(Error::shape(
                "state",
                format!("({},)", self.d),
                format!("({},)", z0.len()),
            ));
        }
        let ambient = self.ambient();
        let mut z = vec![0.0; self.d + self.k() * self.w];
        self.scatter(z0, 0, &mut z);
        let (mut at, mut dir) = (0, 0);
        for &(_, b) in self.problem.space().blocks() {
            if ambient && b == Block::SO3 {
                // δR = Rê_c for the left-trivialised direction c.
                let r = Matrix3::from_row_slice(&z0[at..at + 9]);
                for c in 0..3 {
                    let dr = r * so3::hat(&Vector3::ith(c, 1.0));
                    for k in 0..9 {
                        z[self.at(dir + c + 1, at + k)] = dr[(k / 3, k % 3)];
                    }
                }
            } else {
                let pos = if ambient { at } else { dir };
                for i in 0..b.tangent_len() {
                    z[self.at(dir + i + 1, pos + i)] = 1.0;
                }
            }
            at += b.len();
            dir += b.tangent_len();
        }
        Ok(z)
    }

    /// An ambient direction's SO(3) block is read by the derivative of the polar factor at the
    /// run's R ([`so3::PolarTangent`]: a Runge–Kutta run leaves SO(3)), NaN where R has none;
    /// the base state as computed.
    fn jacobian(&self, lifted: &[f64], z: &mut [f64], jac: &mut [f64], pjac: &mut [f64]) {
        let (e, np, k, ambient) = (self.e, self.np, self.k(), self.ambient());
        self.gather(lifted, 0, z);
        let mut put = |i: usize, j: usize, v: f64| match j < e {
            true => jac[i * e + j] = v,
            false => pjac[i * np + j - e] = v,
        };
        let (mut at, mut dir) = (0, 0);
        for &(_, b) in self.problem.space().blocks() {
            if ambient && b == Block::SO3 {
                let polar = so3::PolarTangent::new(&Matrix3::from_row_slice(&z[at..at + 9])).ok();
                for j in 0..k {
                    let dr = Matrix3::from_fn(|r, c| lifted[self.at(j + 1, at + 3 * r + c)]);
                    let xi = polar.map_or(Vector3::repeat(f64::NAN), |p| p.apply(&dr));
                    for (c, x) in xi.iter().enumerate() {
                        put(dir + c, j, *x);
                    }
                }
            } else {
                let pos = if ambient { at } else { dir };
                for i in 0..b.tangent_len() {
                    for j in 0..k {
                        put(dir + i, j, lifted[self.at(j + 1, pos + i)]);
                    }
                }
            }
            at += b.len();
            dir += b.tangent_len();
        }
    }
}
