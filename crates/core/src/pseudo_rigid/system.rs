//! The pseudo-rigid body as an integrable [`System`] of the driver ([`crate::integrate`]).
//!
//! State layout: z = (X row-major, P row-major), length 2n². Methods `verlet`, `verlet4`,
//! `verlet6` ([`crate::integrate::verlet`], on all of T*GL⁺(n), or all n×n matrices with
//! `check_det = false`) and `reduced` ([`super::reduced`], on the principal stratum; it maps
//! (X, P) to the reduced space once, integrates there, and reconstructs (X, P) at save points).
//!
//! ```
//! use std::sync::Arc;
//! use lieflow::integrate::{integrate, Method, System};
//! use lieflow::pseudo_rigid::potential::Harmonic;
//! use lieflow::pseudo_rigid::system::PseudoRigidBody;
//! use lieflow::Mat;
//! let body = PseudoRigidBody::new(3, Arc::new(Harmonic::new(1.0)?), true)?;
//! let x0 = Mat::from_fn(3, 3, |i, j| if i == j { 1.0 + 0.2 * i as f64 } else { 0.0 });
//! let p0 = Mat::from_fn(3, 3, |i, j| 0.1 * (i as f64 - j as f64));
//! let traj = integrate(&body, Method::Verlet4, &body.state(&x0, &p0)?, 1e-2, 100, 10)?;
//! let (e0, e1) = (body.energy(traj.state(0))?, body.energy(traj.state(10))?);
//! assert!((e1 - e0).abs() < 1e-8);
//! # Ok::<(), lieflow::Error>(())
//! ```

use std::sync::Arc;

use super::dynamics::FullBody;
use super::momentum::momentum_map_unchecked;
use super::potential::Potential;
use super::reduced::{spectral_invariants, ReducedSplitting};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::splitting::Composition;
use crate::integrate::verlet::{Verlet, VerletOrder, VerletScratch};
use crate::integrate::{Method, State, Stepper, System};
use crate::lie::gl;
use crate::Mat;

/// The methods of [`PseudoRigidBody`].
pub const METHODS: [Method; 4] = [
    Method::Verlet,
    Method::Verlet4,
    Method::Verlet6,
    Method::Reduced,
];

/// A generalized pseudo-rigid body H = ½ tr(PᵀP) + U(X) (001 (3.22)) for the integration
/// driver, with state z = (X, P) row-major.
#[derive(Debug, Clone)]
pub struct PseudoRigidBody {
    body: FullBody,
    check_det: bool,
}

impl PseudoRigidBody {
    /// A body in n ≥ 2 dimensions with potential U. `check_det`: stop with
    /// [`Error::LeftDomain`] when det X ≤ 0 (always on for potentials defined only on GL⁺(n)).
    pub fn new(n: usize, potential: Arc<dyn Potential>, check_det: bool) -> Result<Self> {
        Ok(PseudoRigidBody {
            body: FullBody::new(n, potential)?,
            check_det,
        })
    }

    /// The underlying [`FullBody`] (vector fields, Hamiltonian).
    pub fn full(&self) -> &FullBody {
        &self.body
    }

    /// The dimension n.
    pub fn n(&self) -> usize {
        self.body.n()
    }

    /// Whether det X > 0 is enforced.
    pub fn check_det(&self) -> bool {
        self.check_det || self.body.potential().needs_positive_det()
    }

    /// The flat state z = (X, P) row-major (checked: n×n, finite).
    pub fn state(&self, x: &Mat, p: &Mat) -> Result<State> {
        let n = self.n();
        check::square_of("X", x, n)?;
        check::square_of("P", p, n)?;
        check::finite_mat("X", x)?;
        check::finite_mat("P", p)?;
        let mut z = Vec::with_capacity(2 * n * n);
        for m in [x, p] {
            for i in 0..n {
                for j in 0..n {
                    z.push(m[(i, j)]);
                }
            }
        }
        Ok(State::new(z))
    }

    /// (X, P) from a flat state (checked length).
    pub fn split(&self, z: &[f64]) -> Result<(Mat, Mat)> {
        let n = self.n();
        check::len_of("state", z, 2 * n * n)?;
        Ok(split_unchecked(n, z))
    }

    /// L = PXᵀ − XPᵀ and Γ = PᵀX − XᵀP (001 (7.3)) of a flat state.
    pub fn momenta(&self, z: &[f64]) -> Result<(Mat, Mat)> {
        let (x, p) = self.split(z)?;
        check::finite_slice("state", z)?;
        Ok(momentum_map_unchecked(&x, &p))
    }

    /// Singular values a₁ ≥ … ≥ aₙ of X (the semi-axes of the ellipsoid X(ball)).
    pub fn singular_values(&self, z: &[f64]) -> Result<Vec<f64>> {
        let (x, _) = self.split(z)?;
        check::finite_mat("X", &x)?;
        let s = x.singular_values().map_err(|e| Error::NotConverged {
            what: format!("SVD of X ({e:?})"),
            iterations: 0,
            residual: f64::NAN,
            tol: 0.0,
        })?;
        Ok(s)
    }
}

fn split_unchecked(n: usize, z: &[f64]) -> (Mat, Mat) {
    let nn = n * n;
    (
        Mat::from_fn(n, n, |i, j| z[i * n + j]),
        Mat::from_fn(n, n, |i, j| z[nn + i * n + j]),
    )
}

fn write_back(n: usize, x: &Mat, p: &Mat, z: &mut [f64]) {
    let nn = n * n;
    for i in 0..n {
        for j in 0..n {
            z[i * n + j] = x[(i, j)];
            z[nn + i * n + j] = p[(i, j)];
        }
    }
}

impl System for PseudoRigidBody {
    fn name(&self) -> &'static str {
        "PseudoRigidBody"
    }

    fn dim(&self) -> usize {
        2 * self.n() * self.n()
    }

    fn methods(&self) -> &'static [Method] {
        &METHODS
    }

    /// H = ½ tr(PᵀP) + U(X) (001 (3.22)).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        let (x, p) = self.split(z)?;
        check::finite_slice("state", z)?;
        self.body.hamiltonian(&x, &p)
    }

    /// The spectral invariants ½tr((LᵀL)^k) then ½tr((ΓᵀΓ)^k), k = 1…⌊n/2⌋: they fix the
    /// coadjoint orbits of p_Ω = RᵀLR and p_Λ = SᵀΓS (the Casimirs of the reduced space, 001 §7).
    fn casimirs(&self, z: &[f64]) -> Result<Vec<f64>> {
        let (l, g) = self.momenta(z)?;
        let mut c = spectral_invariants(&l);
        c.extend(spectral_invariants(&g));
        Ok(c)
    }

    /// det X > 0 when checked.
    fn check_constraints(&self, state: &State) -> Result<()> {
        if self.check_det() {
            let (x, _) = split_unchecked(self.n(), &state.z);
            gl::check_gl_plus("X0", &x)?;
        }
        Ok(())
    }

    fn stepper<'a>(&'a self, method: Method, dt: f64) -> Result<Box<dyn Stepper + 'a>> {
        self.check_method(method)?;
        let n = self.n();
        let order = match method {
            Method::Verlet => VerletOrder::Two,
            Method::Verlet4 => VerletOrder::Four,
            Method::Verlet6 => VerletOrder::Six,
            _ => {
                return Ok(Box::new(ReducedStepper {
                    body: self,
                    dt,
                    done: 0,
                    cache: None,
                }))
            }
        };
        Ok(Box::new(VerletStepper {
            body: self,
            verlet: Verlet::new(order).with_check_det(self.check_det),
            dt,
            done: 0,
            x: Mat::zeros(n, n),
            p: Mat::zeros(n, n),
            scratch: VerletScratch::new(n),
        }))
    }
}

/// Verlet of order 2, 4 or 6 on the flat state.
struct VerletStepper<'a> {
    body: &'a PseudoRigidBody,
    verlet: Verlet,
    dt: f64,
    done: usize,
    x: Mat,
    p: Mat,
    scratch: VerletScratch,
}

impl Stepper for VerletStepper<'_> {
    fn run(&mut self, state: &mut State, steps: usize) -> Result<()> {
        let n = self.body.n();
        let nn = n * n;
        for i in 0..n {
            for j in 0..n {
                self.x[(i, j)] = state.z[i * n + j];
                self.p[(i, j)] = state.z[nn + i * n + j];
            }
        }
        let t0 = self.done as f64 * self.dt;
        self.verlet.run(
            self.body.full().potential(),
            &mut self.x,
            &mut self.p,
            t0,
            self.dt,
            steps,
            &mut self.scratch,
        )?;
        self.done += steps;
        write_back(n, &self.x, &self.p, &mut state.z);
        Ok(())
    }
}

/// The reduced-space splitting; keeps the reduced state between calls (it reduces again only if
/// the state it is given is not the one it returned).
struct ReducedStepper<'a> {
    body: &'a PseudoRigidBody,
    dt: f64,
    done: usize,
    cache: Option<(Vec<f64>, ReducedSplitting)>,
}

impl Stepper for ReducedStepper<'_> {
    fn run(&mut self, state: &mut State, steps: usize) -> Result<()> {
        let n = self.body.n();
        let cache = match self.cache.as_mut() {
            Some(c) if c.0 == state.z => c,
            _ => {
                let (x, p) = split_unchecked(n, &state.z);
                let split = ReducedSplitting::new(&x, &p, &Composition::strang())?;
                self.cache.insert((state.z.clone(), split))
            }
        };
        let (z, split) = (&mut cache.0, &mut cache.1);
        let t0 = self.done as f64 * self.dt;
        split.run(self.body.full().potential(), t0, self.dt, steps)?;
        self.done += steps;
        let (x, p) = split.full_state();
        write_back(n, &x, &p, &mut state.z);
        z.copy_from_slice(&state.z);
        Ok(())
    }
}
