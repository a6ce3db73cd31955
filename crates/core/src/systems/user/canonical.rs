use std::fmt;

use super::*;
use crate::error::Result;
use crate::integrate::hooks;
use crate::integrate::methods::canonical_catalog;
use crate::integrate::problem::Canonical;
use crate::integrate::space::Space;
use crate::integrate::tangent::{CanonicalTangent, Tangent};
use crate::integrate::Problem;

/// A canonical Hamiltonian system H(q, p) on T*ℝᵈ given by functions (module docs); state
/// z = (q, p).
#[derive(Clone)]
pub struct UserCanonical {
    dof: usize,
    h: CanonicalFn,
    gradient: Option<CanonicalGradientFn>,
    hessian: Option<CanonicalHessianFn>,
}

impl fmt::Debug for UserCanonical {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UserCanonical")
            .field("dof", &self.dof)
            .field("gradient", &self.gradient.is_some())
            .field("hessian", &self.hessian.is_some())
            .finish()
    }
}

impl UserCanonical {
    /// H with `dof` ≥ 1 degrees of freedom and its gradient, or `None` for finite differences.
    pub fn new(dof: usize, h: CanonicalFn, gradient: Option<CanonicalGradientFn>) -> Result<Self> {
        check_dof("dof", dof)?;
        Ok(UserCanonical {
            dof,
            h,
            gradient,
            hessian: None,
        })
    }

    /// The same system with the Hessian product D²H(q, p)\[dq, dp\] (with an exact gradient,
    /// it makes every method's Jacobian exact: the tangent lift, [`crate::integrate::tangent`]).
    pub fn with_hessian(mut self, hessian: CanonicalHessianFn) -> Self {
        self.hessian = Some(hessian);
        self
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
    fn invariant_names(&self) -> Vec<String> {
        Vec::new()
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

/// D²H(q, p)\[dq, dp\] from the Hessian callable (a failure recorded as for the gradient;
/// NaN): the field lift through [`CanonicalTangent`].
impl CanonicalTangent for UserCanonical {
    fn gradient_tangent(
        &self,
        q: &[f64],
        p: &[f64],
        dq: &[f64],
        dp: &[f64],
        dhq: &mut [f64],
        dhp: &mut [f64],
    ) {
        let ok = match &self.hessian {
            Some(h) => hooks::call(|| {
                h(q, p, dq, dp, dhq, dhp)?;
                finite_entries("the Hessian product of H", "d(dH/dq)", dhq)?;
                finite_entries("the Hessian product of H", "d(dH/dp)", dhp)
            }),
            None => false,
        };
        if !ok {
            dhq.fill(f64::NAN);
            dhp.fill(f64::NAN);
        }
    }
}

// The tangent lift (every method) where a gradient and a Hessian are given.
crate::integrate::methods::canonical_system!(
    UserCanonical,
    canonical_catalog(),
    |s: &UserCanonical| (s.hessian.is_some() && s.gradient.is_some())
        .then(|| Tangent::field(s.clone()).into_system())
);
