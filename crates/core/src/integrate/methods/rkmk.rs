//! `Rkmk4`: the Runge–Kutta–Munthe-Kaas method with the classical fourth-order coefficients for a
//! [`GroupField`] ż = ξ(z)·z (Munthe-Kaas, "High order Runge–Kutta methods on manifolds", Appl.
//! Numer. Math. 29 (1999); Iserles, Munthe-Kaas, Nørsett & Zanna, "Lie-group methods", Acta
//! Numerica 9 (2000), §5).
//!
//! The solution is written z(t) = exp(u(t))·z_n with u in the Lie algebra; u solves the ODE
//! u̇ = dexp⁻¹_u(ξ(exp(u)·z_n)), u(0) = 0, in a linear space, where classical RK4 applies:
//!
//! k₁ = h ξ(z_n),  k₂ = h dexp⁻¹_{k₁/2} ξ(exp(k₁/2)·z_n),  k₃ = h dexp⁻¹_{k₂/2} ξ(exp(k₂/2)·z_n),
//! k₄ = h dexp⁻¹_{k₃} ξ(exp(k₃)·z_n),  z_{n+1} = exp((k₁ + 2k₂ + 2k₃ + k₄)/6)·z_n.
//!
//! The inverse derivative is the problem's exact [`GroupField::dexp_inv`] (a truncation after the
//! second commutator would keep order 4, Munthe-Kaas 1999). Every step is one group action, so
//! the state stays on the orbit of z₀ to round-off: the Casimirs (|M|², the spectrum of M on
//! so(n)*), the rotation R ∈ SO(3) and the spatial momentum of a body carrying its attitude. The
//! method is of order 4, neither symplectic nor symmetric; its energy error drifts like RK4's,
//! at O(h⁴).
//!
//! A non-finite increment (from a problem whose dexp⁻¹ or generator left its domain, e.g. a step
//! so large that the exponential coordinates reach a singularity of dexp⁻¹) stops the run with
//! [`crate::Error::LeftDomain`] naming the step.

use crate::error::Result;
use crate::integrate::method::{Clock, Integrator, Properties, Stepper};
use crate::integrate::problem::{GroupField, Violation};

/// RKMK with the classical RK4 coefficients (order 4; keeps the orbit).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Rkmk4;

impl<P: GroupField + Clone + 'static> Integrator<P> for Rkmk4 {
    fn properties(&self) -> Properties {
        Properties {
            order: 4,
            symplectic: false,
            symmetric: false,
            invariants: true,
            manifold: true,
            exact: false,
        }
    }

    fn stepper(&self, problem: &P, dt: f64) -> Result<Box<dyn Stepper>> {
        let (n, g) = (problem.space().dim(), problem.algebra_dim());
        Ok(Box::new(RkmkStepper {
            scratch: problem.scratch(),
            problem: problem.clone(),
            h: dt,
            y: vec![0.0; n],
            yt: vec![0.0; n],
            u: vec![0.0; g],
            xi: vec![0.0; g],
            k: [vec![0.0; g], vec![0.0; g], vec![0.0; g], vec![0.0; g]],
            dz: vec![0.0; n],
            carry: vec![0.0; n],
        }))
    }
}

struct RkmkStepper<P: GroupField> {
    problem: P,
    scratch: P::Scratch,
    h: f64,
    y: Vec<f64>,
    yt: Vec<f64>,
    u: Vec<f64>,
    xi: Vec<f64>,
    k: [Vec<f64>; 4],
    /// The step's increment exp(u)·y − y, where the problem forms it
    /// ([`GroupField::act_increment`]).
    dz: Vec<f64>,
    /// The low-order part lost in adding the increments (Kahan's compensated summation).
    carry: Vec<f64>,
}

impl<P: GroupField> RkmkStepper<P> {
    /// One step; false when the increment is not finite.
    fn step(&mut self) -> bool {
        let RkmkStepper {
            problem,
            scratch,
            h,
            y,
            yt,
            u,
            xi,
            k: [k1, k2, k3, k4],
            dz,
            carry,
        } = self;
        let h = *h;
        problem.generator(y, k1, scratch);
        k1.iter_mut().for_each(|x| *x *= h);
        // k_{i+1} = h dexp⁻¹_u ξ(exp(u)·y) with u = c k_i.
        let mut stage = |kin: &[f64], c: f64, kout: &mut [f64]| {
            for (ui, ki) in u.iter_mut().zip(kin) {
                *ui = c * ki;
            }
            yt.copy_from_slice(y);
            problem.act(u, yt, scratch);
            problem.generator(yt, xi, scratch);
            problem.dexp_inv(u, xi, kout, scratch);
            kout.iter_mut().for_each(|x| *x *= h);
        };
        stage(k1, 0.5, k2);
        stage(k2, 0.5, k3);
        stage(k3, 1.0, k4);
        let mut finite = true;
        for i in 0..u.len() {
            u[i] = (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]) / 6.0;
            finite &= u[i].is_finite();
        }
        if finite {
            if problem.act_increment(u, y, dz, scratch) {
                // Kahan's compensated y += dz: a step's rounding is carried into the next
                // instead of repeating itself at a steady motion (GroupField::act_increment).
                crate::numerics::linalg::compensated_add(y, carry, dz);
            } else {
                problem.act(u, y, scratch);
            }
        }
        finite
    }
}

impl<P: GroupField> Stepper for RkmkStepper<P> {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.y.copy_from_slice(z);
        self.carry.fill(0.0);
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        z.copy_from_slice(&self.y);
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        for k in 0..steps {
            if !self.step() {
                return Err(clock.left_domain(
                    k,
                    Violation {
                        what: format!("{} state", self.problem.name()),
                        message: "the RKMK increment in the Lie algebra is not finite (the \
                                  exponential coordinates left the domain of dexp⁻¹, or the \
                                  motion blew up); reduce dt"
                            .into(),
                    },
                ));
            }
        }
        Ok(())
    }
}
