//! Open systems (issue 15): external forces and torques, Rayleigh damping and double-bracket
//! dissipation added to any catalogued system by splitting.
//!
//! A forced system obeys ż = f(z) + g₁(t, z) + … + g_m(t, z), where f is the free system's
//! field and each g_j a [`Perturbation`]. With the time as a coordinate (ṫ = 1 moving with f),
//! the step
//!
//! Ψ_h = K₁(h/2) ∘ … ∘ K_m(h/2) ∘ Φ_h ∘ K_m(h/2) ∘ … ∘ K₁(h/2),
//!
//! where Φ_h is a symmetric second-order method of the free system and K_j(τ) a symmetric
//! second-order map of g_j's own flow with t frozen (at t_n before Φ_h, at t_n + h after it), is
//! symmetric and of order 2 (a palindromic composition of symmetric pieces, HLW §II.5, §V.1), and
//! the symmetric compositions of [`Composition`] lift it to order 4 and 6: [`Forced`]'s catalog
//! has, for every symmetric second-order method `m` of the free system, `m`, `m4` (Suzuki) and
//! `m6` (Yoshida). The free part keeps whatever its method keeps between the kicks (the group,
//! the sphere, exact sub-flows).
//!
//! The perturbations:
//! * [`Force`]: a generalised force F(t, z) on one block of the state (a body torque on `M`, a
//!   force matrix on a matrix momentum `P`, a force on `p`), a function of the time and
//!   the whole state (user frame). Its flow with t and the other blocks frozen is the kick
//!   y ← y + τF when F does not depend on the block y it changes (then exact, one evaluation);
//!   otherwise the implicit midpoint y' = y + τF(t, (y + y')/2), solved by fixed-point iteration
//!   (a momentum-independent F is recognised after its second evaluation, which returns the
//!   first bit for bit).
//! * [`Dissipation::Rayleigh`]: ṗ = −C ∂H/∂p for a canonical system (C = c·I or a symmetric
//!   positive semi-definite matrix), the same kick with the system's own gradient. With
//!   H = ½|p|²/m + U(q) and C = cI the damping map is p ↦ ((1 − a)/(1 + a)) p, a = cτ/2m: the
//!   method is conformally symplectic (it contracts dq∧dp by a constant factor per step).
//! * [`Dissipation::DoubleBracket`]: Bloch, Krishnaprasad, Marsden & Ratiu, "The Euler–Poincaré
//!   equations and double bracket dissipation", Comm. Math. Phys. 175 (1996):
//!   μ̇ = ad*_{∇H} μ + α ad*_{w♭} μ, w = ad*_{∇H} μ, ♭ the identity of the coordinates (g and g*
//!   in dual bases). Then dH/dt = ⟨∇H, α ad*_{w♭}μ⟩ = α⟨μ, [w♭, ∇H]⟩ = −α⟨ad*_{∇H}μ, w♭⟩ =
//!   −α|w|² ≤ 0, and the motion stays on the coadjoint orbit (every Casimir kept); on so(3)*
//!   with Ṁ = M × Ω it is Ṁ = M × Ω + α M × (M × Ω), whose energy decreases until M lies along
//!   the major axis (the minimum of H on the sphere |M| = const). For a [`GroupField`] whose
//!   action has generator ξ·μ = −ad*_ξ μ (lieflow's Lie–Poisson systems), the dissipative term
//!   is the field ξ_d(μ)·μ with ξ_d = −α f(μ) (f = ad*_{∇H}μ the free field), stepped by the
//!   symmetric Lie midpoint ([`LieMidpoint`]): one group action per step, so the Casimirs stay
//!   at round-off.
//!
//! Time dependence: a run's clock gives t_n = t₀ + n·dt at the start of every step (no sum of
//! step sizes across steps), so the states do not depend on how a run is cut into calls.

use std::collections::BTreeSet;
use std::sync::{Arc, Mutex, OnceLock};

use super::method::{Catalog, Clock, Entry, Integrator, Properties, Stepper, System};
use super::methods::{Composition, LieMidpoint};
use super::problem::{Canonical, GroupField, Problem, VectorField};
pub use super::problem::{Dissipation, Kick, Perturbation};
use super::space::{Block, Space};
use crate::convergence::{self, Monitor, Rule, Verdict};
use crate::error::{fmt_num, Error, Result};

/// A force F(t, z, out): time, the whole state (user frame), the force on the block (flat).
pub type ForceFn = Arc<dyn Fn(f64, &[f64], &mut [f64]) -> Result<()> + Send + Sync>;

// ---------------------------------------------------------------------------------------------
// kicks of a momentum block

/// Evaluates g on the block at (t, z) (internal frame) into `out`.
type BlockField = Box<dyn FnMut(f64, &[f64], &mut [f64]) -> Result<()> + Send>;

/// The stopping rule of the fixed-point iteration of an implicit kick ([`crate::convergence`];
/// ‖Δy'‖_∞ relative to max(‖y'‖_∞, 1); ended at once by an update at round-off).
const KICK_RULE: Rule = Rule {
    tol: convergence::TOL,
    floor: f64::EPSILON,
    max_iter: 60,
};

/// The kick of a block y of z: y' = y + τ g(t, z with y ← (y + y')/2), by fixed-point iteration;
/// exact and explicit (one evaluation) when g does not depend on y.
struct BlockKick {
    at: std::ops::Range<usize>,
    tau: f64,
    depends: bool,
    g: BlockField,
    what: String,
    mid: Vec<f64>,
    f: Vec<f64>,
    prev: Vec<f64>,
    y1: Vec<f64>,
}

impl BlockKick {
    fn new(
        at: std::ops::Range<usize>,
        dim: usize,
        tau: f64,
        depends: bool,
        g: BlockField,
        what: String,
    ) -> Self {
        let k = at.len();
        BlockKick {
            at,
            tau,
            depends,
            g,
            what,
            mid: vec![0.0; dim],
            f: vec![0.0; k],
            prev: vec![0.0; k],
            y1: vec![0.0; k],
        }
    }
}

impl Kick for BlockKick {
    fn apply(&mut self, t: f64, z: &mut [f64], clock: Clock) -> Result<()> {
        let BlockKick {
            at,
            tau,
            g,
            f,
            prev,
            y1,
            mid,
            ..
        } = self;
        let what = &self.what;
        let mut g = |t: f64, z: &[f64], f: &mut [f64]| -> Result<()> {
            g(t, z, f)?;
            match f.iter().position(|x| !x.is_finite()) {
                None => Ok(()),
                Some(i) => Err(Error::NonFinite {
                    what: format!("the {what}"),
                    location: format!("entry {i} of its value ({})", f[i]),
                }),
            }
        };
        let y0 = &z[at.clone()];
        g(t, z, f)?;
        for ((y1, y0), f) in y1.iter_mut().zip(y0).zip(f.iter()) {
            *y1 = y0 + *tau * f;
        }
        if self.depends {
            mid.copy_from_slice(z);
            let mut monitor = Monitor::new(KICK_RULE);
            loop {
                prev.copy_from_slice(f);
                for ((m, y0), y1) in mid[at.clone()]
                    .iter_mut()
                    .zip(&z[at.clone()])
                    .zip(y1.iter())
                {
                    *m = 0.5 * (y0 + y1);
                }
                g(t, mid, f)?;
                if f == prev {
                    break; // the same force: y1 is the fixed point (always so for a y-free g)
                }
                let mut d = 0.0f64;
                let mut size = 1.0f64;
                for ((y1, y0), f) in y1.iter_mut().zip(&z[at.clone()]).zip(f.iter()) {
                    let new = y0 + *tau * f;
                    d = d.max((new - *y1).abs());
                    size = size.max(new.abs());
                    *y1 = new;
                }
                if !d.is_finite() {
                    return Err(clock.left_domain(
                        0,
                        super::problem::Violation {
                            what: what.clone(),
                            message:
                                "the implicit kick is not finite (the force blew up); reduce dt"
                                    .into(),
                        },
                    ));
                }
                match monitor.check(d, size) {
                    Verdict::Continue => {}
                    Verdict::Converged => break,
                    Verdict::Failed(failed) => {
                        return Err(clock.not_converged(
                            0,
                            &format!("implicit midpoint kick of the {what}"),
                            failed,
                            KICK_RULE.tol,
                        ))
                    }
                }
            }
        }
        z[at.clone()].copy_from_slice(y1);
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// external forces

/// A generalised force F(t, z) on the block `block` of the state (see the module docs).
#[derive(Clone)]
pub struct Force {
    block: &'static str,
    f: ForceFn,
    depends: bool,
}

impl Force {
    /// The force `f` on `block` of `space` (a block of real values: `M`, `P`, `p`, …);
    /// `depends_on_block` false declares F independent of that block (the kick is then explicit
    /// and exact; a false claim lowers the order to 1).
    pub fn new(space: &Space, block: &str, f: ForceFn, depends_on_block: bool) -> Result<Self> {
        let found = space.blocks().iter().find(|(n, _)| *n == block);
        match found {
            Some(&(name, Block::Real(_) | Block::Matrix(_) | Block::SoDual(_))) => Ok(Force { block: name, f, depends: depends_on_block }),
            Some((name, b)) => Err(Error::invalid("block", format!("a force acts on a block of real values (a momentum), not on the curved block {name} ({b:?})"))),
            None => Err(Error::invalid("block", format!("no block {block:?} in the state; the blocks are {}", names(space)))),
        }
    }

    /// The block it acts on.
    pub fn block(&self) -> &'static str {
        self.block
    }
}

/// The blocks a force acts on when none is named, in this order.
pub const MOMENTA: [&str; 5] = ["M", "P", "p", "L", "mu"];

/// The block a force of `system` (state space `space`) acts on when none is named: the first of
/// [`MOMENTA`] it has.
pub fn momentum_block(system: &str, space: &Space) -> Result<&'static str> {
    MOMENTA
        .into_iter()
        .find(|m| space.range(m).is_some())
        .ok_or_else(|| {
            Error::invalid(
                "block",
                format!(
                    "{system} has none of the momentum blocks {} (its blocks are {}): name the block",
                    MOMENTA.join(", "),
                    names(space)
                ),
            )
        })
}

fn names(space: &Space) -> String {
    space
        .blocks()
        .iter()
        .map(|(n, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}

impl Perturbation for Force {
    fn describe(&self) -> String {
        format!("force on {}", self.block)
    }

    /// F is a user function.
    fn calls_out(&self) -> bool {
        true
    }

    fn keeps_invariants(&self) -> bool {
        false
    }

    fn lifted(&self) -> Option<Arc<dyn Perturbation>> {
        Some(Arc::new(self.clone()))
    }

    fn kick(&self, base: &Arc<dyn Problem>, tau: f64) -> Result<Box<dyn Kick>> {
        let space = base.space();
        let at = space.range(self.block).ok_or_else(|| {
            Error::invalid(
                "block",
                format!("no block {:?} in {}", self.block, names(&space)),
            )
        })?;
        let d = space.dim();
        let (sys, f, r) = (base.clone(), self.f.clone(), at.clone());
        let (mut user, mut force) = (vec![0.0; d], vec![0.0; d]);
        let what = self.describe();
        let g: BlockField = Box::new(move |t, z, out| {
            // F sees the user's frame; the frames are linear maps, so F maps back by to_internal.
            user.copy_from_slice(z);
            sys.to_user(&mut user);
            force.fill(0.0);
            f(t, &user, &mut force[r.clone()])?;
            sys.to_internal(&mut force);
            out.copy_from_slice(&force[r.clone()]);
            Ok(())
        });
        Ok(Box::new(BlockKick::new(at, d, tau, self.depends, g, what)))
    }
}

// ---------------------------------------------------------------------------------------------
// dissipation

/// Rayleigh damping ṗ = −C ∂H/∂p of a canonical system `P` ([`Dissipation::Rayleigh`]).
pub fn rayleigh<P: Canonical + Clone + 'static>(
    problem: &P,
    d: &Dissipation,
) -> Result<Arc<dyn Perturbation>> {
    let Dissipation::Rayleigh(c) = d else {
        return Err(d.unsupported(problem.name()));
    };
    let n = problem.dof();
    crate::check::finite_slice("damping", c)?;
    let matrix = match c.len() {
        1 if c[0] >= 0.0 => None,
        1 => {
            return Err(Error::invalid(
                "damping",
                format!("the damping coefficient must be ≥ 0, got {}", fmt_num(c[0])),
            ))
        }
        k if k == n * n => {
            let m = crate::Mat::from_fn(n, n, |i, j| c[i * n + j]);
            let asym = (0..n)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .map(|(i, j)| (m[(i, j)] - m[(j, i)]).abs())
                .fold(0.0, f64::max);
            let scale = c
                .iter()
                .fold(0.0f64, |a, x| a.max(x.abs()))
                .max(f64::MIN_POSITIVE);
            let low = m.self_adjoint_eigen(faer::Side::Lower).map_err(|_| {
                Error::invalid(
                    "damping",
                    "the eigenvalues of the damping matrix could not be computed",
                )
            })?;
            let lmin = (0..n).map(|i| low.S()[i]).fold(f64::INFINITY, f64::min);
            if asym > 1e-12 * scale || lmin < -1e-12 * scale {
                return Err(Error::invalid("damping", format!("the damping matrix must be symmetric positive semi-definite (max |C − Cᵀ| = {asym:.3e}, smallest eigenvalue {lmin:.3e})")));
            }
            Some(c.clone())
        }
        k => {
            return Err(Error::shape(
                "damping",
                format!("one coefficient or a ({n}, {n}) matrix"),
                format!("{k} values"),
            ))
        }
    };
    Ok(Arc::new(Rayleigh {
        problem: problem.clone(),
        c: c[0],
        matrix,
    }))
}

#[derive(Clone)]
struct Rayleigh<P> {
    problem: P,
    c: f64,
    matrix: Option<Vec<f64>>,
}

impl<P: Canonical + Clone + 'static> Perturbation for Rayleigh<P> {
    fn describe(&self) -> String {
        "Rayleigh damping".into()
    }

    fn keeps_invariants(&self) -> bool {
        false
    }

    fn lifted(&self) -> Option<Arc<dyn Perturbation>> {
        None
    }

    fn kick(&self, base: &Arc<dyn Problem>, tau: f64) -> Result<Box<dyn Kick>> {
        let n = self.problem.dof();
        let me = self.clone();
        let (mut hq, mut hp) = (vec![0.0; n], vec![0.0; n]);
        let g: BlockField = Box::new(move |_t, z, out| {
            me.problem.gradient(&z[..n], &z[n..], &mut hq, &mut hp);
            match &me.matrix {
                None => out.iter_mut().zip(&hp).for_each(|(o, v)| *o = -me.c * v),
                Some(m) => {
                    for (i, o) in out.iter_mut().enumerate() {
                        *o = -(0..n).map(|j| m[i * n + j] * hp[j]).sum::<f64>();
                    }
                }
            }
            Ok(())
        });
        Ok(Box::new(BlockKick::new(
            n..2 * n,
            base.space().dim(),
            tau,
            true,
            g,
            self.describe(),
        )))
    }
}

/// Double-bracket dissipation of a Lie–Poisson system `P` ([`Dissipation::DoubleBracket`]):
/// its [`GroupField`] must be the coadjoint action (generator ξ·μ = −ad*_ξ μ) on the whole state
/// and its [`VectorField`] the Lie–Poisson field ad*_{∇H}μ (module docs).
pub fn double_bracket<P: GroupField + VectorField + Clone + 'static>(
    problem: &P,
    d: &Dissipation,
) -> Result<Arc<dyn Perturbation>> {
    let Dissipation::DoubleBracket(alpha) = *d else {
        return Err(d.unsupported(problem.name()));
    };
    if !(alpha.is_finite() && alpha >= 0.0) {
        return Err(Error::invalid(
            "dissipation",
            format!(
                "the coefficient α must be finite and ≥ 0, got {}",
                fmt_num(alpha)
            ),
        ));
    }
    if problem.space().dim() != problem.algebra_dim() {
        return Err(Error::invalid("dissipation", format!("{} carries more than its momentum (an attitude): double-bracket dissipation acts on the reduced state only", problem.name())));
    }
    Ok(Arc::new(DoubleBracket {
        problem: problem.clone(),
        alpha,
    }))
}

/// The dissipative part as a group field: ξ_d(μ) = −α f(μ).
#[derive(Clone)]
struct DoubleBracket<P> {
    problem: P,
    alpha: f64,
}

impl<P: Problem> Problem for DoubleBracket<P> {
    fn name(&self) -> &'static str {
        self.problem.name()
    }
    fn calls_out(&self) -> bool {
        self.problem.calls_out()
    }
    fn space(&self) -> Space {
        self.problem.space()
    }
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.problem.energy(z)
    }
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.problem.invariants(z)
    }
    fn invariant_names(&self) -> Vec<String> {
        self.problem.invariant_names()
    }
}

impl<P: GroupField + VectorField> GroupField for DoubleBracket<P> {
    type Scratch = P::Scratch;
    fn scratch(&self) -> P::Scratch {
        self.problem.scratch()
    }
    fn algebra_dim(&self) -> usize {
        self.problem.algebra_dim()
    }
    fn generator(&self, z: &[f64], xi: &mut [f64], _s: &mut P::Scratch) {
        self.problem.field(z, xi);
        xi.iter_mut().for_each(|x| *x *= -self.alpha);
    }
    fn act(&self, xi: &[f64], z: &mut [f64], s: &mut P::Scratch) {
        self.problem.act(xi, z, s)
    }
    fn act_increment(&self, xi: &[f64], z: &[f64], dz: &mut [f64], s: &mut P::Scratch) -> bool {
        self.problem.act_increment(xi, z, dz, s)
    }
    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], s: &mut P::Scratch) {
        self.problem.dexp_inv(u, v, out, s)
    }
}

impl<P: GroupField + VectorField + Clone + 'static> Perturbation for DoubleBracket<P> {
    fn describe(&self) -> String {
        "double-bracket dissipation".into()
    }

    fn keeps_invariants(&self) -> bool {
        true
    }

    fn lifted(&self) -> Option<Arc<dyn Perturbation>> {
        None
    }

    fn kick(&self, _base: &Arc<dyn Problem>, tau: f64) -> Result<Box<dyn Kick>> {
        struct Midpoint(Box<dyn Stepper>);
        impl Kick for Midpoint {
            fn apply(&mut self, _t: f64, z: &mut [f64], clock: Clock) -> Result<()> {
                self.0.set(z)?;
                self.0.advance(1, clock)?;
                self.0.get(z);
                Ok(())
            }
        }
        Ok(Box::new(Midpoint(LieMidpoint::new().stepper(self, tau)?)))
    }
}

// ---------------------------------------------------------------------------------------------
// the forced system

/// A catalogued system with perturbations: forces, damping, dissipation (module docs).
#[derive(Clone)]
pub struct Forced {
    base: Arc<dyn System>,
    terms: Vec<Arc<dyn Perturbation>>,
}

impl std::fmt::Debug for Forced {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let terms: Vec<String> = self.terms.iter().map(|t| t.describe()).collect();
        f.debug_struct("Forced")
            .field("base", &self.base.name())
            .field("terms", &terms)
            .finish()
    }
}

impl Forced {
    /// The free system `base` with no perturbation yet.
    pub fn new(base: Arc<dyn System>) -> Self {
        Forced {
            base,
            terms: Vec::new(),
        }
    }

    /// The same with one more perturbation (applied inside the ones before it).
    pub fn with(mut self, term: Arc<dyn Perturbation>) -> Self {
        self.terms.push(term);
        self
    }

    /// The same with a force F(t, z) on `block` ([`Force::new`]).
    pub fn with_force(self, block: &str, f: ForceFn, depends_on_block: bool) -> Result<Self> {
        let force = Force::new(&self.base.space(), block, f, depends_on_block)?;
        Ok(self.with(Arc::new(force)))
    }

    /// The same with the free system's own dissipation of kind `d` ([`Catalog::dissipation`]).
    pub fn with_dissipation(self, d: &Dissipation) -> Result<Self> {
        let term = self.base.dissipation(d)?;
        Ok(self.with(term))
    }

    /// The free system.
    pub fn base(&self) -> &Arc<dyn System> {
        &self.base
    }

    /// What acts on it, in order.
    pub fn terms(&self) -> Vec<String> {
        self.terms.iter().map(|t| t.describe()).collect()
    }
}

impl Problem for Forced {
    fn name(&self) -> &'static str {
        self.base.name()
    }
    fn calls_out(&self) -> bool {
        self.base.calls_out() || self.terms.iter().any(|t| t.calls_out())
    }
    fn space(&self) -> Space {
        self.base.space()
    }
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.base.energy(z)
    }
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.base.invariants(z)
    }
    fn invariant_names(&self) -> Vec<String> {
        self.base.invariant_names()
    }
    fn rate(&self, z: &[f64]) -> Option<f64> {
        self.base.rate(z)
    }
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.base.check_state(z)
    }
    fn to_internal(&self, z: &mut [f64]) {
        self.base.to_internal(z)
    }
    fn to_user(&self, z: &mut [f64]) {
        self.base.to_user(z)
    }
}

/// `name` with a suffix, as a `&'static str` (each distinct name is allocated once).
fn interned(name: &str, suffix: &str) -> &'static str {
    static NAMES: OnceLock<Mutex<BTreeSet<&'static str>>> = OnceLock::new();
    let full = format!("{name}{suffix}");
    let mut set = NAMES
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    if let Some(&s) = set.get(full.as_str()) {
        return s;
    }
    let s: &'static str = Box::leak(full.into_boxed_str());
    set.insert(s);
    s
}

impl Catalog for Forced {
    /// None: the methods are those of the free system, known with an instance only.
    fn kind_catalog() -> Vec<Entry<Self>> {
        Vec::new()
    }

    /// For every symmetric second-order method `m` of the free system: `m`, `m4`, `m6`.
    fn catalog(&self) -> Vec<Entry<Self>> {
        let mut out = Vec::new();
        for (name, p) in self.base.methods() {
            if !(p.symmetric && p.order == 2) {
                continue;
            }
            let invariants = p.invariants && self.terms.iter().all(|t| t.keeps_invariants());
            for (suffix, comp) in [
                ("", Composition::strang()),
                ("4", Composition::suzuki4()),
                ("6", Composition::yoshida6()),
            ] {
                let name = interned(name, suffix);
                let kicked = Kicked {
                    base: name_of(name, suffix),
                    manifold: p.manifold,
                    invariants,
                    composition: comp,
                };
                out.push(Entry::new(name, move || kicked.clone()));
            }
        }
        out
    }

    fn lifted(&self) -> Option<Self> {
        let base = self.base.lift()?;
        let terms = self
            .terms
            .iter()
            .map(|t| t.lifted())
            .collect::<Option<Vec<_>>>()?;
        Some(Forced { base, terms })
    }
}

/// The method of [`Forced`]: the composition of the kicked step of the free method `base`.
#[derive(Clone)]
struct Kicked {
    base: &'static str,
    manifold: bool,
    invariants: bool,
    composition: Composition,
}

/// The free method's name of a composed name.
fn name_of(name: &'static str, suffix: &str) -> &'static str {
    &name[..name.len() - suffix.len()]
}

impl Integrator<Forced> for Kicked {
    /// The composition's order; symmetric; not symplectic; the invariants where every term keeps
    /// them; the manifold where the free method keeps it.
    fn properties(&self) -> Properties {
        Properties {
            order: self.composition.order(),
            symplectic: false,
            symmetric: true,
            invariants: self.invariants,
            manifold: self.manifold,
            exact: false,
        }
    }

    fn stepper(&self, problem: &Forced, dt: f64) -> Result<Box<dyn Stepper>> {
        let mut sizes: Vec<f64> = Vec::new();
        let mut stages = Vec::new();
        for &g in self.composition.gammas() {
            let i = sizes
                .iter()
                .position(|s| s.to_bits() == g.to_bits())
                .unwrap_or_else(|| {
                    sizes.push(g);
                    sizes.len() - 1
                });
            stages.push(i);
        }
        // The free method, looked up once for all its stage sizes.
        let method = problem.base.resolve(self.base)?;
        let free = sizes
            .iter()
            .map(|g| method.stepper(g * dt))
            .collect::<Result<Vec<_>>>()?;
        // The kicks see the free system as a problem (its space and frames).
        let free_problem: Arc<dyn Problem> = problem.base.clone();
        let kicks = sizes
            .iter()
            .map(|g| {
                problem
                    .terms
                    .iter()
                    .map(|t| t.kick(&free_problem, 0.5 * g * dt))
                    .collect::<Result<Vec<_>>>()
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Box::new(KickedStepper {
            sizes,
            stages,
            free,
            kicks,
            h: dt,
            z: vec![0.0; problem.space().dim()],
            set: false,
        }))
    }
}

struct KickedStepper {
    /// The distinct stage weights γ and, per stage, the index of its weight.
    sizes: Vec<f64>,
    stages: Vec<usize>,
    /// Per weight: the free stepper of size γh and the kicks of size γh/2 of every term.
    free: Vec<Box<dyn Stepper>>,
    kicks: Vec<Vec<Box<dyn Kick>>>,
    h: f64,
    z: Vec<f64>,
    set: bool,
}

impl KickedStepper {
    fn run(&mut self, steps: usize, clock: Clock) -> Result<()> {
        for k in 0..steps {
            let c = Clock {
                done: clock.done + k as u64,
                ..clock
            };
            let mut t = clock.time(k);
            for s in 0..self.stages.len() {
                let i = self.stages[s];
                for kick in self.kicks[i].iter_mut() {
                    kick.apply(t, &mut self.z, c)?;
                }
                let free = &mut self.free[i];
                free.set(&self.z)?;
                free.advance(1, c)?;
                free.get(&mut self.z);
                t += self.sizes[i] * self.h;
                for kick in self.kicks[i].iter_mut().rev() {
                    kick.apply(t, &mut self.z, c)?;
                }
            }
        }
        Ok(())
    }
}

impl Stepper for KickedStepper {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        // The free method checks the state it is given (e.g. a hidden constraint).
        self.free[self.stages[0]].set(z)?;
        self.z.copy_from_slice(z);
        self.set = true;
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        z.copy_from_slice(&self.z);
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        if !self.set {
            return Ok(());
        }
        self.run(steps, clock)
    }
}
