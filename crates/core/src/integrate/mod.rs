//! Structure-preserving integrators and the integration driver.
//!
//! Methods are values ([`Method`]) passed to one driver, [`integrate`] (one initial state) or
//! [`integrate_batch`] (many, in parallel with rayon). A mechanical system implements [`System`]:
//! it says which methods it supports and builds a [`Stepper`] for a method and a time step. The
//! stepper advances a [`State`] in place; the driver saves every `save_every`-th state.
//!
//! | method        | kind                                                  | order | module |
//! |---------------|-------------------------------------------------------|-------|--------|
//! | `splitting`   | Lie–Poisson splitting, Strang composition             | 2 | [`splitting`] |
//! | `splitting4`  | the same, Suzuki's 5-stage composition                | 4 | [`splitting`] |
//! | `splitting6`  | the same, Yoshida's 7-stage composition               | 6 | [`splitting`] |
//! | `isospectral` | isospectral symplectic midpoint (Modin & Viviani 2020) | 2 | [`isospectral`] |
//! | `lgvi`        | Lie group variational integrator (Lee, Leok & McClamroch) | 2 | [`variational`] |
//! | `rk4`         | classical Runge–Kutta (non-geometric baseline)         | 4 | [`rk`] |
//! | `verlet`, `verlet4`, `verlet6` | Störmer–Verlet on T*GL⁺(n) and its compositions | 2, 4, 6 | [`verlet`] |
//! | `reduced`     | pseudo-rigid body, reduced-space splitting (001 §7)    | 2 | [`crate::pseudo_rigid::reduced`] |
//!
//! ```
//! use lieflow::integrate::{integrate, Method, System};
//! use lieflow::systems::RigidBody;
//! let body = RigidBody::new([1.0, 2.0, 3.0])?;
//! let traj = integrate(&body, Method::Splitting4, &body.state([1.0, 0.5, -0.3]), 1e-2, 1000, 100)?;
//! assert_eq!(traj.len(), 11);
//! let (h0, h1) = (body.energy(traj.state(0))?, body.energy(traj.state(10))?);
//! assert!((h1 - h0).abs() < 1e-9);
//! # Ok::<(), lieflow::Error>(())
//! ```

pub mod isospectral;
pub mod rk;
pub mod splitting;
pub mod variational;
pub mod verlet;

use crate::check;
use crate::error::{Error, Result};
use crate::lie::so3;
use rayon::prelude::*;

/// An integration method, named as in the Python API.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Lie–Poisson splitting with exact sub-flows, Strang composition (order 2).
    Splitting,
    /// Lie–Poisson splitting, Suzuki's fourth-order composition of Strang steps.
    Splitting4,
    /// Lie–Poisson splitting, Yoshida's sixth-order composition of Strang steps.
    Splitting6,
    /// Isospectral symplectic midpoint on so(n)* (Modin & Viviani 2020), order 2.
    Isospectral,
    /// Lie group variational integrator in Cayley coordinates (Lee, Leok & McClamroch), order 2.
    Lgvi,
    /// Classical fourth-order Runge–Kutta, the non-geometric baseline.
    Rk4,
    /// Störmer–Verlet on T*GL⁺(n) (pseudo-rigid bodies), order 2.
    Verlet,
    /// Störmer–Verlet, Suzuki's 5-stage composition, order 4.
    Verlet4,
    /// Störmer–Verlet, Yoshida's 7-stage composition, order 6.
    Verlet6,
    /// Reduced-space splitting of the pseudo-rigid body on the principal stratum
    /// ([`crate::pseudo_rigid::reduced`]), order 2, exact coadjoint orbits.
    Reduced,
}

impl Method {
    /// Every method, in the order of the table above.
    pub const ALL: [Method; 10] = [
        Method::Splitting,
        Method::Splitting4,
        Method::Splitting6,
        Method::Isospectral,
        Method::Lgvi,
        Method::Rk4,
        Method::Verlet,
        Method::Verlet4,
        Method::Verlet6,
        Method::Reduced,
    ];

    /// The method's name in the Python API ("splitting", "splitting4", …).
    pub fn name(self) -> &'static str {
        match self {
            Method::Splitting => "splitting",
            Method::Splitting4 => "splitting4",
            Method::Splitting6 => "splitting6",
            Method::Isospectral => "isospectral",
            Method::Lgvi => "lgvi",
            Method::Rk4 => "rk4",
            Method::Verlet => "verlet",
            Method::Verlet4 => "verlet4",
            Method::Verlet6 => "verlet6",
            Method::Reduced => "reduced",
        }
    }

    /// Parses a method name; an unknown name gives [`Error::InvalidArgument`] listing all names.
    pub fn from_name(name: &str) -> Result<Method> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| {
                Error::invalid(
                    "method",
                    format!(
                        "unknown method {name:?}; known methods: {}",
                        names(&Method::ALL)
                    ),
                )
            })
    }

    /// The nominal order of accuracy.
    pub fn order(self) -> u32 {
        match self {
            Method::Splitting
            | Method::Isospectral
            | Method::Lgvi
            | Method::Verlet
            | Method::Reduced => 2,
            Method::Splitting4 | Method::Rk4 | Method::Verlet4 => 4,
            Method::Splitting6 | Method::Verlet6 => 6,
        }
    }
}

/// Comma-separated method names.
fn names(methods: &[Method]) -> String {
    methods
        .iter()
        .map(|m| m.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// A state of a system: the reduced state `z` (flat, layout fixed by the system, see
/// [`System::dim`]) and, for systems on SO(3) that track it, the attitude R ∈ SO(3) (row-major).
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// The reduced (Lie–Poisson) state, length [`System::dim`].
    pub z: Vec<f64>,
    /// The attitude R (body-to-space rotation, row-major 3×3), when tracked.
    pub attitude: Option<[f64; 9]>,
}

impl State {
    /// A state without attitude.
    pub fn new(z: Vec<f64>) -> Self {
        State { z, attitude: None }
    }

    /// A state with attitude R (row-major).
    pub fn with_attitude(z: Vec<f64>, r: [f64; 9]) -> Self {
        State {
            z,
            attitude: Some(r),
        }
    }
}

/// Advances a state by whole time steps, in place, without allocating.
pub trait Stepper {
    /// Advances `state` (in the system's internal frame, see [`System::to_internal`]) by `steps`
    /// steps of the step size the stepper was built with.
    fn run(&mut self, state: &mut State, steps: usize) -> Result<()>;
}

/// A mechanical system that the driver can integrate.
pub trait System: Sync {
    /// A short name for messages ("RigidBody", …).
    fn name(&self) -> &'static str;

    /// Length of the reduced state `z`.
    fn dim(&self) -> usize;

    /// Whether the system can carry an attitude R ∈ SO(3) along.
    fn has_attitude(&self) -> bool {
        false
    }

    /// The supported methods.
    fn methods(&self) -> &'static [Method];

    /// The energy (Hamiltonian) of a reduced state (user frame).
    fn energy(&self, z: &[f64]) -> Result<f64>;

    /// The Casimir functions (and other exact invariants of the reduced dynamics) of a state.
    fn casimirs(&self, z: &[f64]) -> Result<Vec<f64>>;

    /// Checks a state beyond its length and finiteness (system constraints such as |q| = 1).
    fn check_constraints(&self, _state: &State) -> Result<()> {
        Ok(())
    }

    /// Maps a state from the user's frame to the frame the steppers work in (e.g. the principal
    /// axes of an inertia given as a full matrix). The identity by default.
    fn to_internal(&self, _state: &mut State) {}

    /// Inverse of [`System::to_internal`].
    fn to_user(&self, _state: &mut State) {}

    /// Builds a stepper for `method` and step `dt` (both already validated by the driver).
    fn stepper<'a>(&'a self, method: Method, dt: f64) -> Result<Box<dyn Stepper + 'a>>;

    /// Full validation of a state: length, finiteness, attitude in SO(3), system constraints.
    fn check_state(&self, state: &State) -> Result<()> {
        check::len_of("state", &state.z, self.dim())?;
        if let Some(r) = &state.attitude {
            if !self.has_attitude() {
                return Err(Error::invalid(
                    "attitude",
                    format!("{} carries no attitude", self.name()),
                ));
            }
            check_rotation(r)?;
        }
        self.check_constraints(state)
    }

    /// Checks that `method` is supported, else [`Error::UnsupportedMethod`] listing the supported.
    fn check_method(&self, method: Method) -> Result<()> {
        if self.methods().contains(&method) {
            Ok(())
        } else {
            Err(Error::UnsupportedMethod {
                method: method.name().into(),
                system: self.name().into(),
                supported: names(self.methods()),
            })
        }
    }
}

/// Checks that a row-major 3×3 attitude is finite and in SO(3) (to [`so3::ROTATION_TOL`]).
pub fn check_rotation(r: &[f64; 9]) -> Result<()> {
    so3::check_rotation("attitude", &nalgebra::Matrix3::from_row_slice(r))
}

/// A computed trajectory: the saved samples and the final state.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    /// Sample times t₀ + k·save_every·dt, k = 0, 1, …, ⌊steps / save_every⌋ (t₀ = 0).
    pub t: Vec<f64>,
    /// The saved reduced states, row-major (len × dim).
    pub states: Vec<f64>,
    /// The saved attitudes (len × 9, row-major R), when the initial state had one.
    pub attitude: Option<Vec<f64>>,
    /// Length of one reduced state.
    pub dim: usize,
    /// The state after all `steps` steps (also when `steps` is not a multiple of `save_every`);
    /// pass it as the next initial state to integrate in chunks.
    pub final_state: State,
}

impl Trajectory {
    /// Number of saved samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether no sample was saved (never the case for a trajectory returned by [`integrate`]).
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The k-th saved reduced state.
    pub fn state(&self, k: usize) -> &[f64] {
        &self.states[k * self.dim..(k + 1) * self.dim]
    }

    /// The k-th saved attitude (row-major), if tracked.
    pub fn attitude(&self, k: usize) -> Option<&[f64]> {
        self.attitude.as_ref().map(|a| &a[9 * k..9 * (k + 1)])
    }
}

fn check_run(dt: f64, steps: usize, save_every: usize) -> Result<()> {
    check::positive("dt", dt)?;
    if steps < 1 {
        return Err(Error::invalid("steps", "expected steps ≥ 1, got 0"));
    }
    if save_every < 1 {
        return Err(Error::invalid(
            "save_every",
            "expected save_every ≥ 1, got 0",
        ));
    }
    Ok(())
}

/// Integrates `system` from `state0` by `steps` steps of size `dt` with `method`, saving every
/// `save_every`-th state (and the initial one). States are in the user's frame.
///
/// Errors: `dt` ≤ 0 or non-finite, `steps` < 1, `save_every` < 1 ([`Error::InvalidArgument`]);
/// wrong state length ([`Error::Shape`]); NaN/inf ([`Error::NonFinite`]); attitude not in SO(3)
/// ([`Error::NotInGroup`]); a method the system does not support ([`Error::UnsupportedMethod`]);
/// an implicit solve that fails ([`Error::NotConverged`]); a state that becomes non-finite.
///
/// To integrate in chunks (e.g. to check for Ctrl-C in between), call again with
/// `traj.final_state` and drop the first sample of the new chunk.
pub fn integrate<S: System + ?Sized>(
    system: &S,
    method: Method,
    state0: &State,
    dt: f64,
    steps: usize,
    save_every: usize,
) -> Result<Trajectory> {
    check_run(dt, steps, save_every)?;
    system.check_method(method)?;
    system.check_state(state0)?;
    run_checked(system, method, state0, dt, steps, save_every)
}

fn run_checked<S: System + ?Sized>(
    system: &S,
    method: Method,
    state0: &State,
    dt: f64,
    steps: usize,
    save_every: usize,
) -> Result<Trajectory> {
    let dim = system.dim();
    let n_saved = steps / save_every + 1;
    let too_many = || {
        Error::invalid(
            "save_every",
            format!("{n_saved} samples of {dim} values do not fit in memory; save less often"),
        )
    };
    let mut traj = Trajectory {
        t: Vec::new(),
        states: Vec::new(),
        attitude: state0.attitude.map(|_| Vec::new()),
        dim,
        final_state: state0.clone(),
    };
    traj.t.try_reserve_exact(n_saved).map_err(|_| too_many())?;
    let values = n_saved.checked_mul(dim).ok_or_else(too_many)?;
    traj.states
        .try_reserve_exact(values)
        .map_err(|_| too_many())?;
    if let Some(a) = traj.attitude.as_mut() {
        let values = n_saved.checked_mul(9).ok_or_else(too_many)?;
        a.try_reserve_exact(values).map_err(|_| too_many())?;
    }
    let mut stepper = system.stepper(method, dt)?;
    let mut state = state0.clone();
    system.to_internal(&mut state);
    let mut out = state0.clone();
    let save = |traj: &mut Trajectory, out: &State, k: usize| {
        traj.t.push(k as f64 * dt);
        traj.states.extend_from_slice(&out.z);
        if let (Some(a), Some(r)) = (traj.attitude.as_mut(), out.attitude.as_ref()) {
            a.extend_from_slice(r);
        }
    };
    save(&mut traj, &out, 0);
    let mut done = 0;
    while done < steps {
        let k = save_every.min(steps - done);
        stepper.run(&mut state, k)?;
        done += k;
        out.z.copy_from_slice(&state.z);
        out.attitude = state.attitude;
        system.to_user(&mut out);
        if let Err(e) = check::finite_slice("state", &out.z) {
            return Err(Error::LeftDomain {
                what: "state".into(),
                t: done as f64 * dt,
                message: format!("the integration produced a non-finite value ({e})"),
            });
        }
        if k == save_every {
            save(&mut traj, &out, done);
        }
    }
    traj.final_state = out;
    Ok(traj)
}

/// Integrates many initial states in parallel (rayon), each exactly as [`integrate`] would.
///
/// `threads`: `None` uses rayon's global pool (all cores); `Some(n)` runs on a pool of n threads.
/// Every input is validated before any work starts; the first error (in input order) is returned.
/// The step loops do not allocate: each trajectory allocates its output once.
pub fn integrate_batch<S: System + ?Sized>(
    system: &S,
    method: Method,
    states0: &[State],
    dt: f64,
    steps: usize,
    save_every: usize,
    threads: Option<usize>,
) -> Result<Vec<Trajectory>> {
    check_run(dt, steps, save_every)?;
    system.check_method(method)?;
    for s in states0 {
        system.check_state(s)?;
    }
    let work = || {
        states0
            .par_iter()
            .map(|s| run_checked(system, method, s, dt, steps, save_every))
            .collect::<Result<Vec<_>>>()
    };
    match threads {
        None => work(),
        Some(0) => Err(Error::invalid("threads", "expected threads ≥ 1, got 0")),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| Error::invalid("threads", format!("cannot build a pool of {n}: {e}")))?
            .install(work),
    }
}
