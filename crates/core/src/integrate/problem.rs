//! Problem kinds: what a mechanical system offers to the integrators.
//!
//! Every system is a [`Problem`] (a state space, an energy, the invariants its geometric methods
//! keep, optionally a chart between the user's frame and the one the kernels work in). On top of
//! it a system implements the kinds it has, in the manner of GeometricIntegrators.jl's problem
//! types, and every method is generic over the kind it needs:
//!
//! | kind | what the system provides | methods over it |
//! |------|--------------------------|-----------------|
//! | [`VectorField`] | ż = f(z) | `Rk4` |
//! | [`Split`] | H = H₁ + … + H_m with exact flows | `Splitting(Composition)` |
//! | [`Separable`] | H = T(p) + U(q): velocity ∂T/∂p and force −∂U/∂q | `Verlet(Composition)` |
//! | [`Canonical`] | H(q, p) and its gradient | `Gauss(s)` (implicit midpoint = `Gauss(1)`) |
//! | [`Constrained`] | a [`Separable`] with holonomic g(q) = 0 (or g(q) = g(q₀)) | `Rattle(Composition)` |
//! | [`Nonholonomic`] | a [`Separable`] with velocity constraints A(q) q̇ = 0 | `NonholonomicRattle` |
//! | [`GroupField`] | ż = ξ(z)·z for a Lie-algebra valued ξ acting on z | `Rkmk4` |
//! | [`Symmetric`] | a momentum map J and infinitesimal generators | (equilibria, tests) |
//! | [`Perturbation`] | a non-conservative term g(t, z) with a symmetric map of its flow | `forcing::Forced` |
//!
//! Kernels work on flat slices of the state in the internal frame; they do not check lengths (the
//! driver checks a state once, against [`Problem::space`]) and do not allocate (per-thread
//! scratch comes from the kind's `Scratch` type).

use std::sync::Arc;

pub use super::clock::{Clock, Violation};
use super::space::Space;
use crate::error::{Error, Result};

/// `symbol` indexed 1…count with subscript digits ("J₁", "J₂", …): labels for
/// [`Problem::invariant_names`] of a vector-valued invariant.
pub fn indexed_names(symbol: &str, count: usize) -> Vec<String> {
    const SUBSCRIPT: [char; 10] = ['₀', '₁', '₂', '₃', '₄', '₅', '₆', '₇', '₈', '₉'];
    (1..=count)
        .map(|k| {
            let digits: String = (k.to_string().bytes())
                .map(|d| SUBSCRIPT[usize::from(d - b'0')])
                .collect();
            format!("{symbol}{digits}")
        })
        .collect()
}

/// What every system offers: its state space, energy and invariants.
pub trait Problem: Send + Sync {
    /// A short name for messages ("RigidBody", …).
    fn name(&self) -> &'static str;

    /// The state space (layout of the flat state vector, user frame and internal frame alike).
    fn space(&self) -> Space;

    /// The energy (Hamiltonian) of a state in the user's frame (`z.len()` = the space's dim).
    fn energy(&self, z: &[f64]) -> Result<f64>;

    /// The exact invariants the system's geometric methods keep (Casimirs, momentum maps, …) of a
    /// state in the user's frame (`z.len()` = the space's dim), in the order of
    /// [`Problem::invariant_names`].
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>>;

    /// A short label for each value [`Problem::invariants`] returns, as a plot or a table names
    /// it ("|M|²", "M·Γ", "J(rotation about z)", …).
    fn invariant_names(&self) -> Vec<String>;

    /// The number of values [`Problem::invariants`] returns.
    fn invariant_count(&self) -> usize {
        self.invariant_names().len()
    }

    /// Checks constraints of a state beyond its space (|q| = 1 and q·L = 0, det X > 0, …).
    fn check_state(&self, _z: &[f64]) -> Result<()> {
        Ok(())
    }

    /// The driver's finiteness guard on a state of a run (either frame): [`Error::NonFinite`]
    /// naming its first non-finite entry, by default by its index (a tangent lift names an
    /// entry of a Jacobian by its row and column).
    fn check_finite(&self, z: &[f64]) -> Result<()> {
        crate::check::finite_slice("state", z)
    }

    /// Maps a state from the user's frame to the frame the kernels work in (e.g. the principal
    /// axes of an inertia given as a full matrix). The identity by default.
    fn to_internal(&self, _z: &mut [f64]) {}

    /// Inverse of [`Problem::to_internal`].
    fn to_user(&self, _z: &mut [f64]) {}

    /// Maps a tangent vector (left-trivialised on SO(3) blocks, [`Space::tangent_dim`] values)
    /// at a state from the user's frame to the internal one: by default [`Problem::to_internal`]
    /// applied to it as to a state (right for a linear chart without SO(3) blocks).
    fn tangent_to_internal(&self, dz: &mut [f64]) {
        self.to_internal(dz)
    }

    /// Inverse of [`Problem::tangent_to_internal`].
    fn tangent_to_user(&self, dz: &mut [f64]) {
        self.to_user(dz)
    }

    /// [`Problem::tangent_to_internal`] at the state `z` (user frame): the chart's tangent map
    /// there, for a chart that depends on the state (momenta P = M(q)ω); by default the
    /// state-free map.
    fn tangent_to_internal_at(&self, _z: &[f64], dz: &mut [f64]) {
        self.tangent_to_internal(dz)
    }

    /// Inverse of [`Problem::tangent_to_internal_at`], at the state `z` (internal frame).
    fn tangent_to_user_at(&self, _z: &[f64], dz: &mut [f64]) {
        self.tangent_to_user(dz)
    }

    /// The derivative of [`Problem::to_internal`] at the state `z` (user frame) applied to an
    /// ambient tangent vector ([`Space::dim`] values: an SO(3) block's δR as a 3×3 matrix, not
    /// necessarily tangent), the directions of a Runge–Kutta lift
    /// ([`crate::integrate::tangent::Tangent::field`]); by default [`Problem::to_internal`]
    /// applied to it (right for a linear chart).
    fn ambient_to_internal_at(&self, _z: &[f64], dz: &mut [f64]) {
        self.to_internal(dz)
    }

    /// The derivative of [`Problem::to_user`] at the internal state `z` (which a Runge–Kutta run
    /// leaves off its manifold) applied to an ambient tangent vector; by default
    /// [`Problem::to_user`] applied to it.
    fn ambient_to_user_at(&self, _z: &[f64], dz: &mut [f64]) {
        self.to_user(dz)
    }

    /// The fastest angular rate of the motion at z (rad per unit time) where the system knows
    /// one (a body's |Ω|, a pendulum's frequency): a step h with h·rate beyond about 1 rad
    /// leaves fewer than ~6 steps per turn, which a method of finite order resolves badly.
    /// None by default.
    fn rate(&self, _z: &[f64]) -> Option<f64> {
        None
    }

    /// The names of the system's parameters θ, in order, whose sensitivities ∂z/∂θ a tangent
    /// run carries ([`crate::integrate::tangent`]); none by default.
    fn parameters(&self) -> Vec<&'static str> {
        Vec::new()
    }

    /// The system's symmetry (momentum map, generators, action) where it has one: the relative
    /// equilibria's and relative periodic orbits' data ([`crate::analysis`]). None by default.
    fn symmetry(&self) -> Option<&dyn Symmetric> {
        None
    }

    /// Moves a state (user frame) onto the manifold of the system's constraints, hidden ones
    /// included (for the iterates of a solver, [`crate::analysis::periodic`]): the nearest
    /// point in the momenta for a velocity constraint. The identity by default.
    fn project(&self, _z: &mut [f64]) -> Result<()> {
        Ok(())
    }

    /// Whether the kernels call functions from outside lieflow (user closures, a binding's
    /// callables), which may fail or have side effects: a run then steps one step at a time and
    /// ends at the first failure without taking any step again ([`super::hooks`]).
    fn calls_out(&self) -> bool {
        false
    }
}

/// An ordinary differential equation ż = f(z) (internal frame).
pub trait VectorField: Problem {
    /// Evaluates f(z) into `dz`.
    fn field(&self, z: &[f64], dz: &mut [f64]);

    /// The number of equal diagonal blocks of f′ when it is block lower-triangular: a tangent
    /// lift ([`crate::integrate::tangent`]) has 1 + k, the base field's Jacobian on each (its
    /// directions enter the base field's equations linearly). An implicit method then factors
    /// one block and solves each block with it (the implicit-function theorem's matrix). 1 by
    /// default.
    fn diagonal_blocks(&self) -> usize {
        1
    }

    /// The index in the state of component i of diagonal block b ([`Self::diagonal_blocks`];
    /// block 0 is the base state).
    fn block_index(&self, _b: usize, i: usize) -> usize {
        i
    }
}

/// A Hamiltonian H = H₀ + … + H_{m−1} whose pieces have exact flows φ_i (Lie–Poisson splittings,
/// kick–drift splittings, reduced flows). Flow 0 is the outermost of the palindromic Strang step,
/// flow m − 1 the middle one ([`crate::integrate::methods::Composition::sequence`]).
pub trait Split: Problem {
    /// The working form of a state the flows act on (registers, or reduced coordinates).
    type Work: Send + Clone;

    /// The working form of a flat state (internal frame); may fail where the working
    /// coordinates do not exist.
    fn load(&self, z: &[f64]) -> Result<Self::Work>;

    /// Writes the working form back to a flat state (internal frame).
    fn store(&self, w: &Self::Work, z: &mut [f64]);

    /// The number m of exact flows.
    fn flows(&self) -> usize;

    /// Applies the exact flow φ_i over time τ.
    fn flow(&self, i: usize, tau: f64, w: &mut Self::Work);

    /// Whether [`Split::check_step`] must run after every step (then steps are not fused).
    const CHECKED: bool = false;

    /// Checks the working state after a step (for coordinates with a boundary).
    fn check_step(&self, _w: &mut Self::Work) -> std::result::Result<(), Violation> {
        Ok(())
    }

    /// The flows applied to many members at once ([`SplitLanes`]: SIMD lanes over a block of
    /// states), if the problem has them: the batch path of
    /// [`crate::integrate::methods::Splitting`]. None by default (the members are then stepped
    /// one by one).
    fn lanes(&self) -> Option<Arc<dyn SplitLanes>> {
        None
    }
}

/// What a batch of one [`Split`] problem's members does in one call of
/// [`SplitLanes::run`]: the flattened, fused sequence of a splitting method
/// ([`crate::integrate::methods::Composition::sequence`]) over `steps` steps. Member j gets
/// φ_outer(`first[j]`), then the `inner` flows, then `steps − 1` times φ_outer(`fused`) and the
/// `inner` flows (the lazy first-same-as-last fusion of the splitting stepper: the times are
/// the very floating-point values its one-member stepper uses).
#[derive(Clone, Copy, Debug)]
pub struct Program<'a> {
    /// The outer flow (first and last of a step).
    pub outer: usize,
    /// The time of the fused outer flow between two steps (last of one, first of the next).
    pub fused: f64,
    /// The flows between (index, time), in order.
    pub inner: &'a [(usize, f64)],
    /// The number of steps (≥ 1).
    pub steps: usize,
}

/// The exact flows of a [`Split`] problem on a block of members at once (structure of arrays,
/// typically in SIMD lanes): an optional capability ([`Split::lanes`]).
///
/// The contract is reproducibility: every member's result must be, bit for bit, what
/// [`Split::load`], [`Split::flow`] and [`Split::store`] give for it alone, whatever the other
/// members, their number and the member's position in the block. Kernels do not allocate.
pub trait SplitLanes: Send + Sync {
    /// The length d of a member's flat state (internal frame).
    fn dim(&self) -> usize;

    /// Applies `program` to the n = `first.len()` members of `block`, which holds their flat
    /// states (internal frame) component by component: `block[c·n + j]` is component c of
    /// member j (d·n values). `first[j]` is member j's time of the first outer flow.
    fn run(&self, block: &mut [f64], first: &[f64], program: &Program<'_>);
}

/// A separable Hamiltonian H(q, p) = T(p) + U(q) on T*ℝᵈ with state z = (q, p), d = [`Separable::dof`].
pub trait Separable: Problem {
    /// Per-thread scratch of [`Separable::force`].
    type Scratch: Send;

    /// Fresh scratch.
    fn scratch(&self) -> Self::Scratch;

    /// The number d of degrees of freedom.
    fn dof(&self) -> usize;

    /// The number of equal diagonal blocks of the problem's constraint matrices when they are
    /// block lower-triangular: 1 + k for a tangent lift ([`crate::integrate::tangent`]), whose
    /// RATTLE and nonholonomic solves then factor one block ([`VectorField::diagonal_blocks`]
    /// is the same for a field). 1 by default.
    fn diagonal_blocks(&self) -> usize {
        1
    }

    /// The velocity v = ∂T/∂p (linear in p, v = M⁻¹p, for the constrained kinds).
    fn velocity(&self, p: &[f64], v: &mut [f64]);

    /// The exact flow of T over time h: q ← q + h ∂T/∂p(p) (`v` is scratch of length d).
    /// Override it where the velocity need not be formed (T = ½|p|²).
    fn drift(&self, q: &mut [f64], p: &[f64], h: f64, v: &mut [f64]) {
        self.velocity(p, v);
        for (qi, vi) in q.iter_mut().zip(v.iter()) {
            *qi += h * vi;
        }
    }

    /// The force f = −∂U/∂q, or the [`Violation`] if q lies outside the problem's domain
    /// (det X ≤ 0, …; f is then unspecified). One call both checks and evaluates, so a kernel
    /// reads a new position once.
    fn force(
        &self,
        q: &[f64],
        f: &mut [f64],
        s: &mut Self::Scratch,
    ) -> std::result::Result<(), Violation>;
}

/// A canonical Hamiltonian system H(q, p) on T*ℝᵈ with state z = (q, p).
pub trait Canonical: Problem {
    /// The number d of degrees of freedom.
    fn dof(&self) -> usize;

    /// H(q, p) (internal frame).
    fn hamiltonian(&self, q: &[f64], p: &[f64]) -> f64;

    /// The gradient: `hq` = ∂H/∂q, `hp` = ∂H/∂p (every entry written).
    fn gradient(&self, q: &[f64], p: &[f64], hq: &mut [f64], hp: &mut [f64]);

    /// Hamilton's equations ż = (∂H/∂p, −∂H/∂q) into `dz`: the [`VectorField`] of a canonical
    /// system.
    fn hamilton_field(&self, z: &[f64], dz: &mut [f64]) {
        let d = self.dof();
        let (qdot, pdot) = dz.split_at_mut(d);
        self.gradient(&z[..d], &z[d..2 * d], pdot, qdot);
        pdot.iter_mut().for_each(|x| *x = -*x);
    }
}

/// A [`Separable`] system with T = ½ pᵀM⁻¹p restricted by holonomic constraints g(q) = 0
/// (g: ℝᵈ → ℝᵐ, full rank Jacobian G(q) = ∂g/∂q), or, when [`Constrained::level_set`] says so,
/// to the level set g(q) = g(q₀) through the initial position.
///
/// The constrained phase space is T*{g = c} = {g(q) = c, G(q) M⁻¹p = 0}; the second equation
/// (the *hidden* constraint, the time derivative of the first) is what a state must satisfy on
/// top of its position. Differentiating it once more along the motion gives the multiplier of
/// the index-1 formulation ṗ = f − Gᵀλ, λ = (G M⁻¹Gᵀ)⁻¹(G M⁻¹f + D²g(q)[M⁻¹p, M⁻¹p])
/// ([`crate::integrate::methods::rattle::constrained_field`]).
///
/// The kernels take the problem's [`Separable::Scratch`] (the constraint of a matrix-valued q
/// may need an LU), and do not allocate.
pub trait Constrained: Separable {
    /// The number m of constraints.
    fn constraints(&self) -> usize;

    /// Whether the constraint manifold is the level set {g(q) = g(q₀)} through the position of
    /// the state a stepper is set to (e.g. det X = det X₀ for an incompressible body, whose
    /// volume is fixed by the initial state), rather than {g(q) = 0}. False by default.
    fn level_set(&self) -> bool {
        false
    }

    /// g(q) into `g` (m values).
    fn constraint(&self, q: &[f64], g: &mut [f64], s: &mut Self::Scratch);

    /// G(q) = ∂g/∂q into `jac` (m × d, row-major).
    fn constraint_jacobian(&self, q: &[f64], jac: &mut [f64], s: &mut Self::Scratch);

    /// The second derivative of g along v: D²g(q)[v, v] = d²/dε² g(q + εv) at ε = 0, into `out`
    /// (m values) — the curvature term of the acceleration constraint
    /// d²/dt² g(q(t)) = G(q) q̈ + D²g(q)[q̇, q̇] = 0.
    fn constraint_curvature(&self, q: &[f64], v: &[f64], out: &mut [f64], s: &mut Self::Scratch);

    /// D²g(q)\[u, ·\] (the derivative of G along u) into `rows` (m × d, row-major) where the
    /// problem has it in closed form: returns true then; false by default, and a tangent lift
    /// takes it by polarisation of [`Constrained::constraint_curvature`] (2d calls).
    fn constraint_second(
        &self,
        _q: &[f64],
        _u: &[f64],
        _rows: &mut [f64],
        _s: &mut Self::Scratch,
    ) -> bool {
        false
    }

    /// D³g(q)\[u, v, ·\] into `rows` (m × d, row-major) where the problem has it in closed
    /// form: returns true then; false by default, and [`crate::integrate::methods::rattle::constrained_field_tangent`]
    /// takes the D³g\[δq, v, v\] it needs by central differences of
    /// [`Constrained::constraint_curvature`].
    fn constraint_third(
        &self,
        _q: &[f64],
        _u: &[f64],
        _v: &[f64],
        _rows: &mut [f64],
        _s: &mut Self::Scratch,
    ) -> bool {
        false
    }

    /// The rows F (m × d, row-major) along which the multipliers act on the momenta,
    /// ṗ = f − Fᵀλ, when they differ from G(q): writes them and returns true. A mechanical
    /// system's are G (false, the default); a tangent lift's are not
    /// ([`crate::integrate::tangent`]: the lifted constraint forces pair the directions the
    /// other way round).
    fn constraint_forces(&self, _q: &[f64], _rows: &mut [f64], _s: &mut Self::Scratch) -> bool {
        false
    }
}

/// A [`Separable`] system with T = ½ pᵀM⁻¹p restricted by linear velocity constraints
/// A(q) q̇ = 0 (A: m × d of full rank), with the Lagrange–d'Alembert principle: the constraint
/// forces are −A(q)ᵀλ.
///
/// The kernels take the problem's [`Separable::Scratch`] and do not allocate.
pub trait Nonholonomic: Separable {
    /// The number m of constraints.
    fn constraints(&self) -> usize;

    /// A(q) into `a` (m × d, row-major).
    fn constraint_matrix(&self, q: &[f64], a: &mut [f64], s: &mut Self::Scratch);

    /// The derivative of A along dq, DA(q)\[dq\] = d/dε A(q + ε dq) at ε = 0, into `out`
    /// (m × d, row-major): the data of the tangent lift ([`crate::integrate::tangent`], whose
    /// constraint A(q)v = 0 differentiates to DA(q)\[δq\]v + A(q)δv = 0). Required, as A is: it
    /// is as basic as A itself, and a default (NaN) would only surface as a singular
    /// constraint matrix in a lifted run.
    fn constraint_matrix_tangent(
        &self,
        q: &[f64],
        dq: &[f64],
        out: &mut [f64],
        s: &mut Self::Scratch,
    );

    /// The rows F (m × d, row-major) along which the multipliers act on the momenta,
    /// ṗ = f − Fᵀλ, when they differ from A(q): writes them and returns true. A mechanical
    /// system's are A (false, the default); a tangent lift's are not (as for
    /// [`Constrained::constraint_forces`]).
    fn constraint_forces(&self, _q: &[f64], _rows: &mut [f64], _s: &mut Self::Scratch) -> bool {
        false
    }
}

/// A vector field of the form ż = ξ(z)·z, where ξ(z) lies in a Lie algebra g (coordinates of
/// length [`GroupField::algebra_dim`]) acting on the state: the setting of Runge–Kutta–Munthe-Kaas
/// methods, which stay on the group orbit of the initial state (coadjoint orbits, SO(3)).
///
/// The action is a left action, so a curve z(t) = exp(u(t))·z₀ solves ż = ξ(z)·z when
/// u̇ = dexp⁻¹_u(ξ(z)) with the right-trivialized derivative d/dt exp(u) = dexp_u(u̇)·exp(u).
pub trait GroupField: Problem {
    /// Per-thread scratch of the kernels below (matrices of a runtime size, …).
    type Scratch: Send;

    /// Fresh scratch.
    fn scratch(&self) -> Self::Scratch;

    /// dim g.
    fn algebra_dim(&self) -> usize;

    /// ξ(z) ∈ g.
    fn generator(&self, z: &[f64], xi: &mut [f64], s: &mut Self::Scratch);

    /// z ← exp(ξ)·z, exactly on the orbit.
    fn act(&self, xi: &[f64], z: &mut [f64], s: &mut Self::Scratch);

    /// The increment exp(ξ)·z − z written to `dz` without rounding z (its own rounding relative
    /// to its size), where the problem can form it: returns true then, and the methods add it to
    /// the state with compensated summation; by default false (they use [`GroupField::act`]).
    /// Why: at a steady motion the increment of a component kept by the symmetry (M₃ of a
    /// symmetric body) is the same to below an ulp of that component at every step, and rounding
    /// z + dz then errs the same way every step (|M|² drifted linearly under RKMK4).
    fn act_increment(
        &self,
        _xi: &[f64],
        _z: &[f64],
        _dz: &mut [f64],
        _s: &mut Self::Scratch,
    ) -> bool {
        false
    }

    /// The number of blocks of an iteration over the algebra coordinates: 1, or the state and
    /// its directions for a tangent lift ([`crate::convergence::Blocks`]).
    fn diagonal_blocks(&self) -> usize {
        1
    }

    /// dexp⁻¹_u(v) ∈ g (the inverse of the right-trivialized derivative of exp at u, applied to
    /// v); non-finite values where u lies outside the domain the implementation supports.
    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], s: &mut Self::Scratch);

    /// The relative accuracy the generator is known to: the implicit Lie-group methods accept
    /// an iterate whose update is below the larger of this and [`crate::convergence::TOL`].
    /// [`crate::convergence::TOL`] by default; a generator computed by finite differences, whose
    /// round-off is amplified far above ε, declares its own (else a step that has converged to
    /// the field's own noise would be reported as a failure).
    fn solve_tolerance(&self) -> f64 {
        crate::convergence::TOL
    }
}

/// A system with a symmetry: a momentum map J: state → g* and the infinitesimal generators of
/// the action (the data relative equilibria and their stability need). For a canonical
/// system the action is a cotangent lift and J its momentum map: ⟨J, ξ⟩ generates ξ_Z, i.e.
/// ∇⟨J, ξ⟩ = (−ξ_Z^p, ξ_Z^q) (what [`crate::analysis::comoving`] relies on).
pub trait Symmetric: Problem {
    /// dim g.
    fn symmetry_dim(&self) -> usize;

    /// J(z) ∈ g* (user frame), [`Symmetric::symmetry_dim`] values.
    fn momentum_map(&self, z: &[f64]) -> Result<Vec<f64>>;

    /// The infinitesimal generator ξ_Z(z) (the velocity of the state under the one-parameter
    /// group exp(tξ)), user frame.
    fn generator(&self, xi: &[f64], z: &[f64]) -> Result<Vec<f64>>;

    /// The action exp(ξ)·z of the group element exp(ξ) on a state (user frame): the drift of a
    /// relative periodic orbit ([`crate::analysis::periodic`]). By default an
    /// [`Error::InvalidArgument`] (not built for this system).
    fn act(&self, _xi: &[f64], _z: &[f64]) -> Result<Vec<f64>> {
        Err(Error::invalid(
            "system",
            format!(
                "the finite action of {}'s symmetry is not built",
                self.name()
            ),
        ))
    }
}

/// A non-conservative term g(t, z) of an open system
/// ([`crate::integrate::forcing::Forced`]): a force, damping or dissipation.
pub trait Perturbation: Send + Sync {
    /// What it is, for messages ("force on M", "Rayleigh damping", …).
    fn describe(&self) -> String;

    /// Whether its flow keeps the free system's [`Problem::invariants`] (Casimirs).
    fn keeps_invariants(&self) -> bool;

    /// Whether it calls a function from outside lieflow ([`Problem::calls_out`]).
    fn calls_out(&self) -> bool {
        false
    }

    /// The same term for the free system carrying its attitude, or `None` where it does not
    /// apply there.
    fn lifted(&self) -> Option<Arc<dyn Perturbation>>;

    /// A symmetric second-order map of the term's flow over τ with the time frozen, for the
    /// free system `base` (whose frames it may need).
    fn kick(&self, base: &Arc<dyn Problem>, tau: f64) -> Result<Box<dyn Kick>>;
}

/// A prepared map of a [`Perturbation`]'s flow over one fixed τ (owns its scratch).
pub trait Kick: Send {
    /// Applies it at time t to the state z (internal frame); `clock` names the step for errors.
    fn apply(&mut self, t: f64, z: &mut [f64], clock: Clock) -> Result<()>;
}

/// A dissipative term a system may support (through [`crate::integrate::Catalog::dissipation`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Dissipation {
    /// Rayleigh damping ṗ = −C ∂H/∂p of a canonical system: C = c·I (one value c ≥ 0) or a
    /// symmetric positive semi-definite d×d matrix (row-major).
    Rayleigh(Vec<f64>),
    /// Double-bracket dissipation of a Lie–Poisson system with the coefficient α ≥ 0.
    DoubleBracket(f64),
}

impl Dissipation {
    /// Its name in messages.
    pub fn describe(&self) -> &'static str {
        match self {
            Dissipation::Rayleigh(_) => "Rayleigh damping",
            Dissipation::DoubleBracket(_) => "double-bracket dissipation",
        }
    }

    /// The error of a system without this kind of dissipation.
    pub fn unsupported(&self, system: &str) -> Error {
        let which = match self {
            Dissipation::Rayleigh(_) => "canonical systems (state (q, p))",
            Dissipation::DoubleBracket(_) => {
                "Lie–Poisson systems whose state is the momentum alone (no attitude)"
            }
        };
        Error::invalid(
            "dissipation",
            format!(
                "{system} has no {}: it is defined for {which}",
                self.describe()
            ),
        )
    }
}
