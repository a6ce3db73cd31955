//! Isospectral symplectic midpoint for Euler–Arnold equations on so(n)* (Modin & Viviani,
//! "Lie–Poisson methods for isospectral flows", Found. Comput. Math. 20 (2020), eq. (9)).
//!
//! For Ṁ = [M, Ω(M)] with Ω = ∂H/∂M (lieflow's sign, 000 §3.3 and the so(3) check
//! [`crate::systems::tops::rigid_body`]), one step of size h is
//!
//! M_n = (I + h/2 Ω̃) M̃ (I − h/2 Ω̃),   M_{n+1} = (I − h/2 Ω̃) M̃ (I + h/2 Ω̃),   Ω̃ = Ω(M̃).
//!
//! Subtracting gives M_{n+1} = M_n + h [M̃, Ω̃], a consistent midpoint rule for Ṁ = [M, Ω]. (The
//! form with W = +∂H/∂M in place of −Ω̃ integrates Ṁ = [Ω, M], the opposite sign: it is the
//! convention of Modin & Viviani, whose equation is Ẇ = [∇H(W), W].) Since (I ± h/2 Ω̃) commute
//! and Q = (I − h/2 Ω̃)(I + h/2 Ω̃)⁻¹ is orthogonal (Cayley), M_{n+1} = Q M_n Qᵀ: the spectrum of M
//! and so every Casimir tr f(M) is preserved; the method is a symplectic (Poisson) map of order 2.
//! The attitude is reconstructed by R_{n+1} = R_n Qᵀ = R_n cay(h Ω̃), which keeps R M Rᵀ.
//!
//! The implicit equation for M̃ is solved by the fixed-point iteration
//! M̃ ← M_n − h/2 [Ω̃, M̃] + h²/4 Ω̃ M̃ Ω̃ (a contraction for h‖Ω‖ small) under the rule of
//! [`crate::convergence`] ([`RULE`]: the update relative to max|M_n|); a step whose update is still
//! above the tolerance after [`RULE`]`.max_iter` iterations is [`crate::Error::NotConverged`].
//!
//! The method value is [`Isospectral`], in the catalogs of [`crate::systems::RigidBody`] (through the
//! so(3) matrix hat(M), with the attitude) and [`crate::systems::GeneralizedRigidBody`].

use super::super::top;
use crate::convergence::{self, Failed, Monitor, Rule, Verdict};
use crate::error::Result;
use crate::integrate::{Clock, Integrator, Properties, Stepper};
use crate::lie::so3;
use crate::systems::tops::{GeneralizedRigidBody, RigidBody};
use nalgebra::{Matrix3, Vector3};

/// The stopping rule of the fixed-point iteration ([`crate::convergence`]; the update of M̃
/// relative to max|M_n|; ended at once at 4ε).
pub const RULE: Rule = Rule {
    tol: convergence::TOL,
    floor: 4.0 * f64::EPSILON,
    max_iter: 100,
};

/// The isospectral midpoint for Ω(M)_ij = M_ij / d_ij, with d_ij = J_i + J_j for the generalized
/// rigid body M = JΩ + ΩJ. Matrices are dense row-major n×n; all scratch is allocated once.
pub struct IsospectralMidpoint {
    n: usize,
    h: f64,
    inv_d: Vec<f64>,
    m0: Vec<f64>,
    mt: Vec<f64>,
    w: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
}

impl IsospectralMidpoint {
    /// A stepper of step `h` on so(n), with `d` the n×n matrix (row-major) of the denominators
    /// d_ij > 0 (i ≠ j; the diagonal is ignored).
    pub fn new(n: usize, d: &[f64], h: f64) -> Self {
        let inv_d = (0..n * n)
            .map(|k| if k / n == k % n { 0.0 } else { 1.0 / d[k] })
            .collect();
        IsospectralMidpoint {
            n,
            h,
            inv_d,
            m0: vec![0.0; n * n],
            mt: vec![0.0; n * n],
            w: vec![0.0; n * n],
            p: vec![0.0; n * n],
            q: vec![0.0; n * n],
        }
    }

    /// Ω̃ = Ω(M̃) of the last step (row-major), for the attitude update.
    pub fn omega(&self) -> &[f64] {
        &self.w
    }

    /// Computes p = W·M and q = W·M·W for the current W = self.w, M = self.mt.
    fn products(&mut self) {
        let n = self.n;
        matmul(n, &self.w, &self.mt, &mut self.p);
        matmul(n, &self.p, &self.w, &mut self.q);
    }

    /// One step on the skew matrix `m` (row-major n×n), in place; on failure the iterations
    /// taken and the last relative update (∞ for a diverged iteration).
    pub fn step(&mut self, m: &mut [f64]) -> std::result::Result<(), Failed> {
        let n = self.n;
        let (a, a2) = (0.5 * self.h, 0.25 * self.h * self.h);
        self.m0.copy_from_slice(m);
        self.mt.copy_from_slice(m);
        let scale = m
            .iter()
            .fold(0.0f64, |s, x| s.max(x.abs()))
            .max(f64::MIN_POSITIVE);
        let mut monitor = Monitor::new(RULE);
        loop {
            for k in 0..n * n {
                self.w[k] = self.mt[k] * self.inv_d[k];
            }
            self.products();
            // M̃ ← M_n − a [W, M̃] + a² W M̃ W, with [W, M̃] = P − Pᵀ; kept exactly skew.
            let mut diff = 0.0f64;
            let mut finite = true;
            for i in 0..n {
                for j in i + 1..n {
                    let comm = self.p[i * n + j] - self.p[j * n + i];
                    let v = self.m0[i * n + j] - a * comm + a2 * self.q[i * n + j];
                    diff = diff.max((v - self.mt[i * n + j]).abs());
                    finite &= v.is_finite();
                    self.mt[i * n + j] = v;
                    self.mt[j * n + i] = -v;
                }
            }
            let update = if finite { diff } else { f64::INFINITY };
            match monitor.check(update, scale) {
                Verdict::Continue => {}
                Verdict::Converged => break,
                Verdict::Failed(failed) => return Err(failed),
            }
        }
        for k in 0..n * n {
            self.w[k] = self.mt[k] * self.inv_d[k];
        }
        self.products();
        // M_{n+1} = (I − aW) M̃ (I + aW) = M̃ − a[W, M̃] − a² W M̃ W.
        for i in 0..n {
            for j in i + 1..n {
                let comm = self.p[i * n + j] - self.p[j * n + i];
                let v = self.mt[i * n + j] - a * comm - a2 * self.q[i * n + j];
                m[i * n + j] = v;
                m[j * n + i] = -v;
            }
            m[i * n + i] = 0.0;
        }
        Ok(())
    }
}

/// c = a·b for dense row-major n×n matrices.
fn matmul(n: usize, a: &[f64], b: &[f64], c: &mut [f64]) {
    for i in 0..n {
        for j in 0..n {
            let mut s = 0.0;
            for k in 0..n {
                s += a[i * n + k] * b[k * n + j];
            }
            c[i * n + j] = s;
        }
    }
}

/// The isospectral symplectic midpoint (a method value), order 2.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Isospectral;

fn failed(clock: &Clock, k: usize, failed: Failed) -> crate::Error {
    clock.not_converged(
        k,
        "isospectral midpoint fixed-point iteration",
        failed,
        RULE.tol,
    )
}

impl Integrator<RigidBody> for Isospectral {
    fn properties(&self) -> Properties {
        Properties::geometric(2)
    }

    /// On so(3) through the matrix hat(M): d_12 = I₃, d_13 = I₂, d_23 = I₁.
    fn stepper(&self, body: &RigidBody, dt: f64) -> Result<Box<dyn Stepper>> {
        let [i1, i2, i3] = body.top.moments;
        let d = [0.0, i3, i2, i3, 0.0, i1, i2, i1, 0.0];
        Ok(Box::new(So3Stepper {
            kernel: IsospectralMidpoint::new(3, &d, dt),
            h: dt,
            mat: [0.0; 9],
            r: None,
            lifted: body.top.lifted,
        }))
    }
}

struct So3Stepper {
    kernel: IsospectralMidpoint,
    h: f64,
    mat: [f64; 9],
    r: Option<Matrix3<f64>>,
    lifted: bool,
}

impl Stepper for So3Stepper {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.mat = top::row_major(&so3::hat(&Vector3::from_column_slice(&z[..3])));
        self.r = self.lifted.then(|| Matrix3::from_row_slice(&z[3..12]));
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        let m = &self.mat;
        z[..3].copy_from_slice(&[m[7], m[2], m[3]]);
        if let Some(r) = &self.r {
            z[3..12].copy_from_slice(&top::row_major(r));
        }
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        for k in 0..steps {
            self.kernel
                .step(&mut self.mat)
                .map_err(|e| failed(&clock, k, e))?;
            if let Some(r) = self.r.as_mut() {
                let w = self.kernel.omega();
                // R cay(hΩ̃) by increments of R's rows (no bias at a steady rotation:
                // `so3::Rodrigues`).
                so3::Rodrigues::cayley(&(Vector3::new(w[7], w[2], w[3]) * self.h)).right_mul(r);
            }
        }
        Ok(())
    }
}

impl Integrator<GeneralizedRigidBody> for Isospectral {
    fn properties(&self) -> Properties {
        Properties::geometric(2)
    }

    fn stepper(&self, body: &GeneralizedRigidBody, dt: f64) -> Result<Box<dyn Stepper>> {
        let n = body.n();
        Ok(Box::new(SonStepper {
            kernel: IsospectralMidpoint::new(n, body.denominators(), dt),
            body: body.clone(),
            mat: vec![0.0; n * n],
        }))
    }
}

struct SonStepper {
    kernel: IsospectralMidpoint,
    body: GeneralizedRigidBody,
    mat: Vec<f64>,
}

impl Stepper for SonStepper {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.body.dense(z, &mut self.mat);
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        self.body.coords(&self.mat, z);
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        for k in 0..steps {
            self.kernel
                .step(&mut self.mat)
                .map_err(|e| failed(&clock, k, e))?;
        }
        Ok(())
    }
}
