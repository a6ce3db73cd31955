use std::fmt;

use super::*;
use crate::error::Result;
use crate::integrate::hooks;
use crate::integrate::problem::Canonical;
use crate::integrate::space::Space;
use crate::integrate::Problem;

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

crate::integrate::methods::canonical_system!(UserCanonical);
