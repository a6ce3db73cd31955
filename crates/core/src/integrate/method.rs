//! Methods as values, steppers, and each system's catalog of named methods.
//!
//! A method is a value (`Splitting(Composition::suzuki4())`, `Verlet::strang()`, `Gauss(2)`,
//! `Rk4`) that implements [`Integrator<P>`] for every problem `P` of the kind it needs. It builds
//! a [`Stepper`]: an object that owns a copy of the problem, the method's scratch and the current
//! state in the method's working form, and advances it without allocating.
//!
//! A system publishes a [`Catalog`]: the (name, method) pairs the Python API knows it by
//! ("splitting4", "verlet", …); the first entry is the system's default. Through the blanket
//! [`System`] implementation every catalogued problem is usable as a `dyn System` by name, which
//! is what the driver and the Python bindings hold; [`System::resolve`] looks a name up once and
//! gives a [`Resolved`] method, which runs and batches hold.

use std::sync::Arc;

pub use super::clock::Clock;
use super::problem::Problem;
use crate::error::{Error, Result};

/// What a method claims, for a given problem; the generic test suite checks every claim.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Properties {
    /// The order of accuracy.
    pub order: u32,
    /// A symplectic (Poisson) map: bounded energy error over long times.
    pub symplectic: bool,
    /// Symmetric: Φ_{−h} ∘ Φ_h = id (time-reversible for reversible systems).
    pub symmetric: bool,
    /// Keeps [`Problem::invariants`] to round-off.
    pub invariants: bool,
    /// Keeps the curved blocks of the space (SO(3), S²) to round-off; the driver then retracts
    /// them now and then so that round-off does not accumulate. A method without this claim
    /// (RK4) is left to drift off, as it does.
    pub manifold: bool,
    /// The exact flow of the system, to round-off at every step size (no truncation error): the
    /// generic suite checks its error instead of an order, and `order` is `u32::MAX`.
    pub exact: bool,
}

impl Properties {
    /// A structure-preserving method of the given order (all claims true).
    pub fn geometric(order: u32) -> Self {
        Properties {
            order,
            symplectic: true,
            symmetric: true,
            invariants: true,
            manifold: true,
            exact: false,
        }
    }

    /// A method of the given order that keeps no structure (the baseline).
    pub fn plain(order: u32) -> Self {
        Properties {
            order,
            symplectic: false,
            symmetric: false,
            invariants: false,
            manifold: false,
            exact: false,
        }
    }

    /// The exact flow of a system: every claim true, "every order" (`u32::MAX`).
    pub fn exact() -> Self {
        Properties {
            order: u32::MAX,
            exact: true,
            ..Properties::geometric(0)
        }
    }
}

/// Advances a state by whole steps; owns the problem, the method's scratch and the state.
pub trait Stepper: Send {
    /// Sets the current state from a flat state (internal frame).
    fn set(&mut self, z: &[f64]) -> Result<()>;

    /// Writes the current state (internal frame) to `z`.
    fn get(&self, z: &mut [f64]);

    /// Advances by `steps` steps; `clock` says which steps these are.
    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()>;
}

/// Advances a block of members of one problem together (their states side by side, in SIMD
/// lanes): the optional batch capability of a method/problem pair
/// ([`Integrator::batch_stepper`]), which the driver uses for batches
/// ([`crate::integrate::batch::Batch`]) instead of one [`Stepper`] per member.
///
/// The contract is reproducibility: member i advanced by a batch stepper ends, bit for bit,
/// where a [`Stepper`] of the same method set to the same state and advanced by the same calls
/// ends, whatever the other members, their number and i. No allocation in `advance`.
pub trait BatchStepper: Send {
    /// The number of members.
    fn members(&self) -> usize;

    /// Sets member `member`'s state from a flat state (internal frame), as [`Stepper::set`].
    fn set(&mut self, member: usize, z: &[f64]) -> Result<()>;

    /// Writes member `member`'s current state (internal frame) to `z`, as [`Stepper::get`].
    fn get(&self, member: usize, z: &mut [f64]);

    /// Advances every member by `steps` steps; `clock` says which steps these are. An error is
    /// the block's: the driver then takes the members one by one from their checked states.
    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()>;

    /// A one-member stepper that continues member `member` exactly (bit for bit) as this block
    /// would, for the driver's work that needs one (shortened steps, events, replays).
    fn detach(&self, member: usize) -> Result<Box<dyn Stepper>>;
}

/// A method for problems of kind `P`.
pub trait Integrator<P: ?Sized>: Send + Sync {
    /// What the method claims for `P`.
    fn properties(&self) -> Properties;

    /// A stepper of step size `dt` (> 0, finite; checked by the driver) for `problem`.
    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>>;

    /// A [`BatchStepper`] of `members` members and step size `dt`, where the method has one for
    /// `problem`; None (the default) steps a batch one member at a time.
    fn batch_stepper(
        &self,
        _problem: &P,
        _dt: f64,
        _members: usize,
    ) -> Option<Result<Box<dyn BatchStepper>>> {
        None
    }
}

/// A named method of a system's catalog, built only when it is resolved or its properties are
/// asked for (a catalog costs its names, not the construction of every method: resolving one
/// method builds one).
pub struct Entry<P: ?Sized> {
    /// The name the Python API knows it by.
    pub name: &'static str,
    make: Box<dyn Fn() -> Box<dyn Integrator<P>>>,
}

impl<P: ?Sized + 'static> Entry<P> {
    /// The entry `name` → the method `make()` builds.
    pub fn new<M: Integrator<P> + 'static>(
        name: &'static str,
        make: impl Fn() -> M + 'static,
    ) -> Self {
        Entry {
            name,
            make: Box::new(move || Box::new(make()) as Box<dyn Integrator<P>>),
        }
    }

    /// The method.
    pub fn method(&self) -> Box<dyn Integrator<P>> {
        (self.make)()
    }
}

/// A system's named methods; the first is its default.
pub trait Catalog: Problem + Clone + 'static {
    /// The (name, method) pairs of this kind of system, known without an instance (so that a
    /// binding lists a class's methods without building one); where they depend on the
    /// instance, those of a typical one.
    fn kind_catalog() -> Vec<Entry<Self>>;

    /// The (name, method) pairs of this system: by default those of its kind.
    fn catalog(&self) -> Vec<Entry<Self>> {
        Self::kind_catalog()
    }

    /// The same system carrying its attitude R ∈ SO(3) along as a last block `R`, if it can.
    fn lifted(&self) -> Option<Self> {
        None
    }

    /// The tangent lift of the system ([`crate::integrate::tangent`]), whose runs carry the
    /// Jacobian of the discrete flow, where the system gives the derivatives it needs; by
    /// default none.
    fn tangent(&self) -> Option<Arc<dyn TangentSystem>> {
        None
    }

    /// The tangent lift whose runs of `method` carry its Jacobian, if any (it lists `method`
    /// then): by default [`Catalog::tangent`]; a system whose state has SO(3) blocks gives its
    /// Runge–Kutta methods the field lift with ambient directions
    /// ([`crate::integrate::tangent::Tangent::routed`]).
    fn tangent_for(&self, _method: &str) -> Option<Arc<dyn TangentSystem>> {
        self.tangent()
    }

    /// The system's own dissipative term of kind `d` (Rayleigh damping of a canonical system,
    /// double-bracket dissipation of a Lie–Poisson system), for
    /// [`crate::integrate::forcing::Forced`]; by default none.
    fn dissipation(
        &self,
        d: &crate::integrate::problem::Dissipation,
    ) -> Result<Arc<dyn crate::integrate::problem::Perturbation>> {
        Err(d.unsupported(self.name()))
    }
}

/// A method of a system's catalog, looked up once by name ([`System::resolve`]): its name, what
/// it claims, and its steppers of any step size. A run and a batch hold it for their whole life
/// (shortened steps, blocks of lanes, detached members); nothing looks the name up again.
pub struct Resolved {
    /// The name in the system's catalog.
    pub name: &'static str,
    /// What the method claims for the system.
    pub properties: Properties,
    stepper: Box<dyn Fn(f64) -> Result<Box<dyn Stepper>> + Send + Sync>,
    batch: BatchMaker,
}

/// The batch steppers of a [`Resolved`] method: (dt, members) → a block, where it has one.
type BatchMaker = Box<dyn Fn(f64, usize) -> Option<Result<Box<dyn BatchStepper>>> + Send + Sync>;

impl Resolved {
    /// A stepper of step size `dt` ([`Integrator::stepper`]).
    pub fn stepper(&self, dt: f64) -> Result<Box<dyn Stepper>> {
        (self.stepper)(dt)
    }

    /// A [`BatchStepper`] of `members` members, where the method has one for the system
    /// ([`Integrator::batch_stepper`]).
    pub fn batch_stepper(&self, dt: f64, members: usize) -> Option<Result<Box<dyn BatchStepper>>> {
        (self.batch)(dt, members)
    }
}

/// A system the driver integrates by method name: every [`Catalog`] problem, as a trait object.
pub trait System: Problem {
    /// The names and properties of the catalogued methods; the first is the default.
    fn methods(&self) -> Vec<(&'static str, Properties)>;

    /// The method called `method`, looked up once, or [`Error::UnsupportedMethod`] listing this
    /// system's methods (with a suggestion when the name is close to one of them).
    fn resolve(&self, method: &str) -> Result<Arc<Resolved>>;

    /// The system's default method (the first of its catalog), resolved once.
    fn resolve_default(&self) -> Result<Arc<Resolved>>;

    /// A stepper for the method called `method` ([`System::resolve`], then
    /// [`Resolved::stepper`]).
    fn stepper(&self, method: &str, dt: f64) -> Result<(Box<dyn Stepper>, Properties)> {
        let m = self.resolve(method)?;
        Ok((m.stepper(dt)?, m.properties))
    }

    /// A [`BatchStepper`] of `members` members for the method called `method`, where the method
    /// has one for this system; None otherwise (also for an unknown name: [`System::resolve`]
    /// reports it).
    fn batch_stepper(
        &self,
        method: &str,
        dt: f64,
        members: usize,
    ) -> Option<Result<Box<dyn BatchStepper>>> {
        self.resolve(method).ok()?.batch_stepper(dt, members)
    }

    /// The system carrying its attitude along ([`Catalog::lifted`]).
    fn lift(&self) -> Option<Arc<dyn System>>;

    /// The tangent lift ([`Catalog::tangent`]).
    fn tangent(&self) -> Option<Arc<dyn TangentSystem>>;

    /// The tangent lift for runs of `method` ([`Catalog::tangent_for`]).
    fn tangent_for(&self, method: &str) -> Option<Arc<dyn TangentSystem>>;

    /// The methods whose Jacobians a lifted run computes: those of the system's catalog that
    /// their lift ([`System::tangent_for`]) lists, in the catalog's order.
    fn tangent_methods(&self) -> Vec<&'static str>;

    /// The system's own dissipative term of kind `d` ([`Catalog::dissipation`]).
    fn dissipation(
        &self,
        d: &crate::integrate::problem::Dissipation,
    ) -> Result<Arc<dyn crate::integrate::problem::Perturbation>>;

    /// The concrete system, for bindings that downcast to their own type (a binding keeps one
    /// `Arc<dyn System>` and reaches the typed system through it).
    fn as_any(&self) -> &dyn std::any::Any;
}

/// A lifted system as the driver and the bindings see it ([`crate::integrate::tangent`]): a
/// [`System`] whose states (`space().dim()` values) carry the directions, with the conversions
/// from and to the base problem's flat layout.
pub trait TangentSystem: System {
    /// The dimension d of the base state.
    fn base_dim(&self) -> usize;

    /// The dimension e of a direction (d less 6 per SO(3) block, left-trivialised).
    fn tangent_dim(&self) -> usize;

    /// The names of the parameters θ whose directions the lift carries.
    fn parameter_names(&self) -> Vec<&'static str>;

    /// The lifted state of a base state (user frame) with the identity as directions (on an
    /// SO(3) block δR = Rê_j, in ambient directions too) and ∂z₀/∂θ = 0.
    fn seed(&self, z0: &[f64]) -> Result<Vec<f64>>;

    /// The base state (d values), the Jacobian ∂z/∂z₀ (e×e row-major, column j = δz_j) and the
    /// parameter Jacobian ∂z/∂θ (e×p row-major) of a lifted state.
    fn jacobian(&self, lifted: &[f64], z: &mut [f64], jac: &mut [f64], pjac: &mut [f64]);
}

/// The method names of a kind of system, without an instance ([`Catalog::kind_catalog`]); the
/// first is its default.
pub fn kind_methods<P: Catalog>() -> Vec<&'static str> {
    P::kind_catalog().iter().map(|e| e.name).collect()
}

impl<P: Catalog> System for P {
    fn methods(&self) -> Vec<(&'static str, Properties)> {
        self.catalog()
            .iter()
            .map(|e| (e.name, e.method().properties()))
            .collect()
    }

    fn resolve(&self, method: &str) -> Result<Arc<Resolved>> {
        let catalog = self.catalog();
        match catalog.iter().position(|e| e.name == method) {
            Some(i) => Ok(resolved(self, catalog, i)),
            None => {
                let names: Vec<_> = catalog.iter().map(|e| e.name).collect();
                Err(unsupported(self.name(), method, &names))
            }
        }
    }

    fn resolve_default(&self) -> Result<Arc<Resolved>> {
        let catalog = self.catalog();
        match catalog.is_empty() {
            false => Ok(resolved(self, catalog, 0)),
            true => Err(unsupported(self.name(), "", &[])),
        }
    }

    fn lift(&self) -> Option<Arc<dyn System>> {
        self.lifted().map(|s| Arc::new(s) as Arc<dyn System>)
    }

    fn tangent(&self) -> Option<Arc<dyn TangentSystem>> {
        Catalog::tangent(self)
    }

    fn tangent_for(&self, method: &str) -> Option<Arc<dyn TangentSystem>> {
        Catalog::tangent_for(self, method)
    }

    fn tangent_methods(&self) -> Vec<&'static str> {
        self.catalog()
            .iter()
            .map(|e| e.name)
            .filter(|m| {
                Catalog::tangent_for(self, m)
                    .is_some_and(|t| t.methods().iter().any(|(n, _)| n == m))
            })
            .collect()
    }

    fn dissipation(
        &self,
        d: &crate::integrate::problem::Dissipation,
    ) -> Result<Arc<dyn crate::integrate::problem::Perturbation>> {
        Catalog::dissipation(self, d)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// Entry `i` of `problem`'s catalog as a [`Resolved`] method (holding a copy of the problem).
fn resolved<P: Catalog>(problem: &P, catalog: Vec<Entry<P>>, i: usize) -> Arc<Resolved> {
    let entry = &catalog[i];
    let integrator: Arc<dyn Integrator<P>> = entry.method().into();
    let problem = Arc::new(problem.clone());
    let (i2, p2) = (integrator.clone(), problem.clone());
    Arc::new(Resolved {
        name: entry.name,
        properties: integrator.properties(),
        stepper: Box::new(move |dt| integrator.stepper(&problem, dt)),
        batch: Box::new(move |dt, n| i2.batch_stepper(&p2, dt, n)),
    })
}

/// The error for an unknown method: the system's own methods, and the closest one when the name
/// looks like a typo of it.
pub fn unsupported(system: &str, method: &str, names: &[&str]) -> Error {
    let close = names
        .iter()
        .map(|n| (edit_distance(method, n), *n))
        .min()
        .filter(|&(d, n)| d <= 2.max(n.len() / 3));
    let mut supported = names.join(", ");
    if let Some((_, n)) = close {
        supported.push_str(&format!(" (did you mean {n:?}?)"));
    }
    Error::UnsupportedMethod {
        method: method.into(),
        system: system.into(),
        supported,
    }
}

/// Levenshtein distance of two strings (by characters).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for j in 0..b.len() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != b[j]))
                .min(row[j] + 1)
                .min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggestions_for_typos_only() {
        let names = ["splitting", "splitting4", "rk4"];
        let msg = |m| unsupported("RigidBody", m, &names).to_string();
        assert!(msg("spliting").contains("did you mean \"splitting\""));
        assert!(msg("rk5").contains("did you mean \"rk4\""));
        assert!(!msg("verlet").contains("did you mean"));
        assert!(msg("verlet").contains("splitting, splitting4, rk4"));
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }
}
