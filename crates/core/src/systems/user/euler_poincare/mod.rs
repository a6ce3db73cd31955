//! Mechanics from a reduced Lagrangian (000 §4): the Euler–Poincaré equations of ℓ(ξ) on a Lie
//! algebra g, or of ℓ(ξ, a) with an advected parameter a ∈ V* (a symmetry-breaking parameter such
//! as the heavy top's vertical Γ), left- or right-invariant, solved in their Hamiltonian form.
//!
//! **From ℓ to a Lie–Poisson system.** The Legendre transform μ = ∂ℓ/∂ξ (inverted by Newton's
//! method where ℓ is not quadratic) gives the reduced energy H(μ, a) = ⟨μ, ξ⟩ − ℓ(ξ, a), with
//! ∂H/∂μ = ξ and ∂H/∂a = −∂ℓ/∂a. Without a parameter, the left Euler–Poincaré equation
//! d/dt ∂ℓ/∂ξ = ad*_ξ ∂ℓ/∂ξ is the Lie–Poisson equation μ̇ = ad*_{∂H/∂μ} μ on g*, and the right one
//! (ξ = ġg⁻¹) has the opposite sign ([`Side`], derived by the mirror g ↦ g⁻¹ in the module docs of
//! [`super`]). With a parameter a ∈ V* under a representation ρ of g on V, the equations are the
//! Lie–Poisson equations on the dual of the semidirect product g ⋉ V, whose bracket is
//! [(ξ, v), (η, w)] = ([ξ, η], ρ(ξ)w − ρ(η)v): for the state (μ, a) they read
//!
//! μ̇ = ad*_ξ μ + ∂ℓ/∂a ⋄ a,    ȧ = −ξ·a    (left, 000 (4.4)–(4.5)),
//!
//! with ξ·a = −ρ(ξ)ᵀa the action on V* and the diamond ⟨b ⋄ a, η⟩ = −⟨b, η·a⟩, i.e.
//! (b ⋄ a)_i = ⟨ρ(e_i)b, a⟩ ([`EulerPoincare::diamond`]). The seed
//! writes the parameter term as −a ⋄ ∂ℓ/∂a with the pairing the other way round; it is the same
//! term. For the right side the mirror gives μ̇ = −ad*_ξ μ − ∂ℓ/∂a ⋄ a, ȧ = +ξ·a (a = g·a₀); the
//! seed's right-hand version (000, after Theorem 4.11) keeps the parameter term's sign, which the
//! mirror test contradicts: trust the test. The heavy top is the check: so(3) ⋉ ℝ³ with
//! ρ(ξ) = ξ̂ is se(3), and ℓ(Ω, Γ) = ½⟨Ω, 𝕀Ω⟩ − mgl⟨Γ, χ⟩ gives Ṁ = M × Ω + mgl Γ × χ,
//! Γ̇ = Γ × Ω (tested against [`crate::systems::HeavyTop`]).
//!
//! So an [`EulerPoincare`] system is a [`LiePoisson`] system (its methods, Casimirs, batches and
//! errors) on g or g ⋉ V with the Hamiltonian of its Lagrangian, plus the Legendre transform both
//! ways and the diamond map. A quadratic ℓ(ξ) = ½⟨ξ, 𝕀ξ⟩ is the native path H = ½⟨μ, 𝕀⁻¹μ⟩.

mod variational;

use std::sync::Arc;

use nalgebra::DMatrix;

pub use variational::Variational;

use super::attitude::Group;
use super::attitude::Side;
use super::lie_poisson::LieScratch;
use super::lie_poisson::{LieHamiltonian, LiePoisson};
use super::{fd_gradient, finite_entries, finite_value, GradientFn, ScalarFn, FD_STEP};
use crate::check;
use crate::convergence::{self, Monitor, Rule, Verdict};
use crate::error::{fmt_num, Error, Result};
use crate::integrate::methods::{group_field_catalog, Composition};
use crate::integrate::problem::{GroupField, VectorField};
use crate::integrate::space::Space;
use crate::integrate::tangent::{GroupFieldTangent, Tangent, TangentSystem, VectorFieldTangent};
use crate::integrate::{Catalog, Entry, Problem};
use crate::lie::so;
use crate::lie::structure::{Algebra, Structure};

/// ℓ(ξ, a) (a empty without a parameter).
pub type LagrangianFn = Arc<dyn Fn(&[f64], &[f64]) -> Result<f64> + Send + Sync>;
/// (∂ℓ/∂ξ, ∂ℓ/∂a) at (ξ, a) into the two outputs.
pub type LagrangianGradientFn =
    Arc<dyn Fn(&[f64], &[f64], &mut [f64], &mut [f64]) -> Result<()> + Send + Sync>;
/// ∂²ℓ/∂ξ² at (ξ, a) into a d×d row-major output.
pub type HessianFn = Arc<dyn Fn(&[f64], &[f64], &mut [f64]) -> Result<()> + Send + Sync>;
/// The Hessian product of ℓ in (ξ, a): (ξ, a, δξ, δa, out_ξ, out_a) with
/// (out_ξ, out_a) = D²ℓ(ξ, a)\[δξ, δa\], the derivative of (∂ℓ/∂ξ, ∂ℓ/∂a) along (δξ, δa)
/// ([`EulerPoincare::with_hessian`]).
pub type LagrangianHessianFn =
    Arc<dyn Fn(&[f64], &[f64], &[f64], &[f64], &mut [f64], &mut [f64]) -> Result<()> + Send + Sync>;

/// The reduced Lagrangian of an [`EulerPoincare`] system.
#[derive(Clone)]
pub enum Lagrangian {
    /// ℓ(ξ) = ½⟨ξ, 𝕀ξ⟩ with 𝕀 symmetric positive definite (d×d, row-major): the native path.
    Quadratic(Vec<f64>),
    /// ℓ and its derivatives as functions; a derivative not given is taken by central
    /// differences (of ℓ for the gradient, of the gradient for the Hessian).
    Function {
        /// ℓ(ξ, a).
        value: LagrangianFn,
        /// (∂ℓ/∂ξ, ∂ℓ/∂a), or `None`.
        gradient: Option<LagrangianGradientFn>,
        /// ∂²ℓ/∂ξ², or `None`.
        hessian: Option<HessianFn>,
    },
}

/// How g acts on the parameter space V (of dimension m).
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// The defining representation of so(3) or so(n) on ℝⁿ: ρ(ξ)v = ξ̂v; on se(3) that of its
    /// rotation part on ℝ³, ρ(ω, v) = ω̂ (through so(3) = se(3)/ℝ³).
    Vector,
    /// The action on V* as d matrices A_i (m×m, row-major, one after the other): e_i·a = A_i a.
    /// Then ρ(e_i) = −A_iᵀ (checked to be a representation: the Jacobi identity of g ⋉ V).
    Matrices(Vec<f64>),
}

impl Action {
    /// m of the vector action on `algebra`: n for so(3) and so(n) (ℝⁿ), 3 for se(3) (its
    /// rotations on ℝ³); None for structure constants.
    pub fn vector_dim(algebra: &Algebra) -> Option<usize> {
        match algebra {
            Algebra::So3 | Algebra::Se3 => Some(3),
            Algebra::So(n) => Some(*n),
            Algebra::Constants(_) => None,
        }
    }
}

/// The stopping rule of the Legendre inversion: the Newton step relative to 1 + ‖ξ‖_∞, ended at
/// once at 10⁻¹⁴ (round-off), then one more step.
const LEGENDRE: Rule = Rule {
    tol: convergence::TOL,
    floor: 1e-14,
    max_iter: 50,
};

/// The Legendre transform of ℓ both ways and the reduced energy (module docs).
pub struct Legendre {
    d: usize,
    m: usize,
    lagrangian: Lagrangian,
}

impl Legendre {
    /// ℓ(ξ, a), checked finite.
    pub fn lagrangian(&self, xi: &[f64], a: &[f64]) -> Result<f64> {
        match &self.lagrangian {
            Lagrangian::Quadratic(i) => {
                let mut ixi = vec![0.0; xi.len()];
                mat_vec(i, xi, &mut ixi);
                Ok(0.5 * dot(xi, &ixi))
            }
            Lagrangian::Function { value, .. } => {
                finite_value("the Lagrangian l(xi, a)", value(xi, a)?)
            }
        }
    }

    /// (∂ℓ/∂ξ, ∂ℓ/∂a) at (ξ, a), checked finite.
    pub fn gradients(&self, xi: &[f64], a: &[f64], dxi: &mut [f64], da: &mut [f64]) -> Result<()> {
        match &self.lagrangian {
            Lagrangian::Quadratic(i) => {
                mat_vec(i, xi, dxi);
                da.fill(0.0);
            }
            Lagrangian::Function {
                gradient: Some(g), ..
            } => g(xi, a, dxi, da)?,
            Lagrangian::Function { gradient: None, .. } => {
                let (d, m) = (self.d, self.m);
                let x = [xi, a].concat();
                let f = |y: &[f64]| self.lagrangian(&y[..d], &y[d..]);
                let mut g = vec![0.0; d + m];
                fd_gradient(&f, &x, &mut g)?;
                dxi.copy_from_slice(&g[..d]);
                da.copy_from_slice(&g[d..]);
            }
        }
        finite_entries("the gradient of the Lagrangian", "dl/dxi", dxi)?;
        finite_entries("the gradient of the Lagrangian", "dl/da", da)
    }

    /// ∂²ℓ/∂ξ² at (ξ, a) (d×d), checked finite.
    fn hessian(&self, xi: &[f64], a: &[f64]) -> Result<DMatrix<f64>> {
        let d = self.d;
        let h = match &self.lagrangian {
            Lagrangian::Quadratic(i) => DMatrix::from_row_slice(d, d, i),
            Lagrangian::Function {
                hessian: Some(h), ..
            } => {
                let mut out = vec![0.0; d * d];
                h(xi, a, &mut out)?;
                DMatrix::from_row_slice(d, d, &out)
            }
            Lagrangian::Function { hessian: None, .. } => {
                // Central differences of ∂ℓ/∂ξ with one Richardson extrapolation, symmetrised.
                let scale = xi.iter().fold(0.0f64, |s, v| s.max(v.abs()));
                let mut cols = DMatrix::zeros(d, d);
                let mut da = vec![0.0; self.m];
                let mut grad_at = |y: &[f64]| -> Result<Vec<f64>> {
                    let mut g = vec![0.0; d];
                    self.gradients(y, a, &mut g, &mut da)?;
                    Ok(g)
                };
                for j in 0..d {
                    let h = FD_STEP * xi[j].abs().max(scale).max(1.0);
                    let mut diff = |h: f64| -> Result<Vec<f64>> {
                        let mut y = xi.to_vec();
                        y[j] = xi[j] + h;
                        let up = grad_at(&y)?;
                        y[j] = xi[j] - h;
                        let down = grad_at(&y)?;
                        Ok(up
                            .iter()
                            .zip(&down)
                            .map(|(u, v)| (u - v) / (2.0 * h))
                            .collect())
                    };
                    let (d1, d2) = (diff(h)?, diff(0.5 * h)?);
                    for i in 0..d {
                        cols[(i, j)] = (4.0 * d2[i] - d1[i]) / 3.0;
                    }
                }
                (&cols + cols.transpose()) * 0.5
            }
        };
        finite_entries(
            "the Hessian of the Lagrangian",
            "d2l/dxi2",
            h.transpose().as_slice(),
        )?;
        Ok(h)
    }

    /// μ = ∂ℓ/∂ξ(ξ, a).
    pub fn momentum(&self, xi: &[f64], a: &[f64], mu: &mut [f64]) -> Result<()> {
        let mut da = vec![0.0; self.m];
        self.gradients(xi, a, mu, &mut da)
    }

    /// The velocity ξ with ∂ℓ/∂ξ(ξ, a) = μ: 𝕀⁻¹μ for a quadratic ℓ, else Newton's method on the
    /// Hessian from the linear guess ∂²ℓ/∂ξ²(0, a)⁻¹ μ, to round-off (one step after the rule
    /// of the Legendre inversion is met: the step below 10⁻¹² of 1 + the largest velocity).
    ///
    /// Errors: a singular ∂²ℓ/∂ξ² on the way ([`Error::InvalidArgument`] naming ξ and μ), no
    /// convergence ([`Error::NotConverged`]), the functions' errors.
    pub fn velocity(&self, mu: &[f64], a: &[f64], xi: &mut [f64]) -> Result<()> {
        let d = self.d;
        let singular = |at: &[f64]| {
            Error::invalid(
                "state",
                format!(
                    "the Legendre map dl/dxi is singular at xi = {} (the Hessian d2l/dxi2 has no \
                     inverse there), so no velocity has the momentum mu = {}",
                    fmt_vec(at),
                    fmt_vec(mu)
                ),
            )
        };
        let solve = |h: DMatrix<f64>, r: &[f64], at: &[f64]| -> Result<Vec<f64>> {
            let scale = h.amax();
            let lu = h.lu();
            let x = lu
                .solve(&nalgebra::DVector::from_column_slice(r))
                .filter(|x| x.iter().all(|v| v.is_finite()))
                .ok_or_else(|| singular(at))?;
            // A pivot at round-off of the scale: numerically singular.
            let min_pivot = (0..d)
                .map(|k| lu.u()[(k, k)].abs())
                .fold(f64::INFINITY, f64::min);
            if min_pivot <= 1e-14 * scale || scale == 0.0 {
                return Err(singular(at));
            }
            Ok(x.as_slice().to_vec())
        };
        if let Lagrangian::Quadratic(_) = self.lagrangian {
            let h = self.hessian(xi, a)?;
            xi.copy_from_slice(&solve(h, mu, &vec![0.0; d])?);
            return Ok(());
        }
        let zero = vec![0.0; d];
        xi.copy_from_slice(&solve(self.hessian(&zero, a)?, mu, &zero)?);
        let mut monitor = Monitor::new(LEGENDRE);
        let mut polish = false;
        let mut g = vec![0.0; d];
        let mut da = vec![0.0; self.m];
        loop {
            self.gradients(xi, a, &mut g, &mut da)?;
            let r: Vec<f64> = mu.iter().zip(&g).map(|(m, g)| m - g).collect();
            let step = solve(self.hessian(xi, a)?, &r, xi)?;
            for (x, s) in xi.iter_mut().zip(&step) {
                *x += s;
            }
            if polish {
                return Ok(());
            }
            let size = step.iter().fold(0.0f64, |m, s| m.max(s.abs()));
            let scale = 1.0 + xi.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            match monitor.check(size, scale) {
                Verdict::Continue => {}
                Verdict::Converged => polish = true,
                Verdict::Failed(f) => {
                    return Err(Error::NotConverged {
                        what: format!(
                            "the Legendre inversion dl/dxi(xi) = mu at mu = {}",
                            fmt_vec(mu)
                        ),
                        iterations: f.iterations,
                        residual: f.residual,
                        tol: LEGENDRE.tol,
                    })
                }
            }
        }
    }

    /// H(μ, a) = ⟨μ, ξ⟩ − ℓ(ξ, a) at the velocity of μ.
    pub fn hamiltonian(&self, mu: &[f64], a: &[f64]) -> Result<f64> {
        let mut xi = vec![0.0; self.d];
        self.velocity(mu, a, &mut xi)?;
        Ok(dot(mu, &xi) - self.lagrangian(&xi, a)?)
    }

    /// D²H(μ, a)\[δμ, δa\] (d + m values into `out`), the derivative of the gradient
    /// (∂H/∂μ, ∂H/∂a) = (ξ, −∂ℓ/∂a) at the velocity ξ of μ: from ∂ℓ/∂ξ(ξ, a) = μ,
    /// ℓ_ξξ δξ = δμ − ℓ_ξa δa, and δ(∂H/∂a) = −(ℓ_aξ δξ + ℓ_aa δa). ℓ_ξξ is built from
    /// `product` (d calls) where given, else it is the Lagrangian's Hessian ∂²ℓ/∂ξ² (which,
    /// without a parameter, is all it takes); the parameter's terms need `product`.
    ///
    /// Errors: a parameter without `product`; those of [`Legendre::velocity`] and of the
    /// functions; a singular ℓ_ξξ.
    pub fn hamiltonian_hessian(
        &self,
        z: &[f64],
        dz: &[f64],
        product: Option<&LagrangianHessianFn>,
        out: &mut [f64],
    ) -> Result<()> {
        let (d, m) = (self.d, self.m);
        let (mu, a) = z.split_at(d);
        let (dmu, da) = dz.split_at(d);
        let mut xi = vec![0.0; d];
        self.velocity(mu, a, &mut xi)?;
        let (mut gx, mut ga) = (vec![0.0; d], vec![0.0; m]);
        let h = match product {
            Some(p) => {
                let mut h = DMatrix::zeros(d, d);
                let (mut e, zero) = (vec![0.0; d], vec![0.0; m]);
                for j in 0..d {
                    e[j] = 1.0;
                    p(&xi, a, &e, &zero, &mut gx, &mut ga)?;
                    e[j] = 0.0;
                    h.column_mut(j).copy_from_slice(&gx);
                }
                h
            }
            None if m == 0 => self.hessian(&xi, a)?,
            None => {
                return Err(Error::invalid(
                    "hessian",
                    "the derivative of the Hamiltonian with an advected parameter needs the \
                     Lagrangian's mixed second derivatives: give its Hessian product \
                     (with_hessian)",
                ))
            }
        };
        let mut rhs = dmu.to_vec();
        if let (Some(p), true) = (product, m > 0) {
            p(&xi, a, &vec![0.0; d], da, &mut gx, &mut ga)?;
            rhs.iter_mut().zip(&gx).for_each(|(r, g)| *r -= g);
        }
        let dxi = h
            .lu()
            .solve(&nalgebra::DVector::from_column_slice(&rhs))
            .filter(|x| x.iter().all(|v| v.is_finite()))
            .ok_or_else(|| {
                Error::invalid(
                    "state",
                    format!(
                        "the Hessian d2l/dxi2 is singular at xi = {}: the Legendre map has no \
                         derivative there",
                        fmt_vec(&xi)
                    ),
                )
            })?;
        out[..d].copy_from_slice(dxi.as_slice());
        if m > 0 {
            if let Some(p) = product {
                p(&xi, a, dxi.as_slice(), da, &mut gx, &mut ga)?;
                out[d..].iter_mut().zip(&ga).for_each(|(o, g)| *o = -g);
            }
        }
        Ok(())
    }

    /// (∂H/∂μ, ∂H/∂a) = (ξ, −∂ℓ/∂a) into `out` (d + m).
    pub fn hamiltonian_gradient(&self, mu: &[f64], a: &[f64], out: &mut [f64]) -> Result<()> {
        let (d, m) = (self.d, self.m);
        let (xi, rest) = out.split_at_mut(d);
        self.velocity(mu, a, xi)?;
        if m == 0 {
            return Ok(());
        }
        let mut g = vec![0.0; d];
        self.gradients(xi, a, &mut g, &mut rest[..m])?;
        rest.iter_mut().for_each(|v| *v = -*v);
        Ok(())
    }
}

/// A system of a reduced Lagrangian (module docs): its Lie–Poisson form and its Legendre map.
#[derive(Clone)]
pub struct EulerPoincare {
    /// The algebra g (without the parameter).
    algebra: Algebra,
    system: LiePoisson,
    legendre: Arc<Legendre>,
    /// The representation ρ(e_i) of g on V (m×m each, row-major), for the diamond map.
    rho: Arc<Vec<f64>>,
}

impl EulerPoincare {
    /// The system of `lagrangian` on `algebra` reduced from the side `side`, with a parameter
    /// of dimension m acted on by `action` (None: no parameter). The state is μ (d), then a (m).
    ///
    /// Errors: those of the algebra ([`LiePoisson::new`]); an inertia of the wrong size,
    /// non-finite, not symmetric or not positive definite; an action of the wrong size, or
    /// `Action::Vector` on structure constants; matrices that are not a
    /// representation (the Jacobi identity of g ⋉ V fails).
    pub fn new(
        algebra: Algebra,
        lagrangian: Lagrangian,
        side: Side,
        action: Option<(Action, usize)>,
    ) -> Result<Self> {
        let g = Structure::new(algebra.clone())?;
        let d = g.dim;
        if let Lagrangian::Quadratic(i) = &lagrangian {
            check_inertia(i, d)?;
            if action.is_some() {
                return Err(Error::invalid(
                    "inertia",
                    "a quadratic Lagrangian l = <xi, I xi>/2 has no parameter; pass the \
                     Lagrangian l(xi, a) as a function to use an action",
                ));
            }
        }
        let (semidirect, rho, m) = match &action {
            None => (algebra.clone(), Vec::new(), 0),
            Some((action, m)) => {
                let rho = representation(&algebra, d, action, *m)?;
                let total = if matches!((&algebra, action), (Algebra::So3, Action::Vector)) {
                    // so(3) ⋉ ℝ³ with ρ(ξ) = ξ̂ is se(3) (module docs): the built-in group.
                    Algebra::Se3
                } else {
                    Algebra::Constants(semidirect_constants(&g.dense(), d, &rho, *m))
                };
                (total, rho, *m)
            }
        };
        let legendre = Arc::new(Legendre {
            d,
            m,
            lagrangian: lagrangian.clone(),
        });
        let hamiltonian = match &lagrangian {
            Lagrangian::Quadratic(i) => LieHamiltonian::Quadratic(inverse(i, d)?),
            Lagrangian::Function { .. } => {
                let (lv, lg) = (legendre.clone(), legendre.clone());
                let value: ScalarFn = Arc::new(move |z: &[f64]| lv.hamiltonian(&z[..d], &z[d..]));
                let gradient: GradientFn = Arc::new(move |z: &[f64], out: &mut [f64]| {
                    lg.hamiltonian_gradient(&z[..d], &z[d..], out)
                });
                LieHamiltonian::Function {
                    value,
                    gradient: Some(gradient),
                }
            }
        };
        let mut system = LiePoisson::new(semidirect, hamiltonian, None)
            .map_err(|e| match e {
                Error::InvalidArgument { message, .. } if action.is_some() => Error::invalid(
                    "action",
                    format!("the action is not a representation of the algebra: {message}"),
                ),
                other => other,
            })?
            .with_side(side)
            .with_group(Group::of(&algebra));
        // Without a parameter, ∂²ℓ/∂ξ² is all the tangent lift needs (D²H = ℓ_ξξ⁻¹).
        if let Lagrangian::Function {
            gradient: Some(_),
            hessian: Some(_),
            ..
        } = &lagrangian
        {
            if m == 0 {
                system = system.with_hessian(hamiltonian_hessian(&legendre, None));
            }
        }
        Ok(EulerPoincare {
            algebra,
            system,
            legendre,
            rho: Arc::new(rho),
        })
    }

    /// The same system with the Hessian product of its Lagrangian in (ξ, a)
    /// ([`LagrangianHessianFn`]), from which the Hamiltonian's D²H follows
    /// ([`Legendre::hamiltonian_hessian`]): with the Lagrangian's gradient given too, the
    /// tangent lift of the Lie–Poisson methods (the Jacobian of each step). Without a parameter
    /// the Lagrangian's own Hessian ∂²ℓ/∂ξ² suffices and this is not needed; a quadratic ℓ has
    /// its own. Unused where the gradient is taken by finite differences (no exact lift).
    pub fn with_hessian(mut self, hessian: LagrangianHessianFn) -> Self {
        if let Lagrangian::Function {
            gradient: Some(_), ..
        } = &self.legendre.lagrangian
        {
            let h = hamiltonian_hessian(&self.legendre, Some(hessian));
            self.system = self.system.with_hessian(h);
        }
        self
    }

    /// Whether the system has a tangent lift ([`LiePoisson::has_tangent`] of its form).
    pub fn has_tangent(&self) -> bool {
        self.system.has_tangent()
    }

    /// The Lie–Poisson form (with the configuration where the system carries it).
    pub fn system(&self) -> &LiePoisson {
        &self.system
    }

    /// The same system carrying its configuration g ∈ G along as a last block
    /// ([`LiePoisson::with_attitude`]; G the group of g, also with a parameter); None for
    /// structure constants.
    pub fn with_attitude(&self) -> Option<Self> {
        Some(EulerPoincare {
            system: self.system.with_attitude()?,
            ..self.clone()
        })
    }

    /// The Legendre transform of the Lagrangian.
    pub fn legendre(&self) -> &Legendre {
        &self.legendre
    }

    /// (dim g, dim V).
    pub fn dims(&self) -> (usize, usize) {
        (self.legendre.d, self.legendre.m)
    }

    /// The size n of the group elements g (n×n matrices) of the algebra: 3 for so(3), n for
    /// so(n), 4 for se(3) (homogeneous matrices); None for structure constants (no group).
    pub fn group_size(&self) -> Option<usize> {
        Group::of(&self.algebra).map(Group::size)
    }

    /// The Noether momentum of the momentum μ (the first dim g entries of a state) at the group
    /// element g (n×n, row-major; the configuration g(t) of the motion, body to space):
    /// Ad*_{g⁻¹}μ (left) or Ad*_g μ (right), [`Group::noether`]. With an advected parameter only
    /// the components that fix a₀ are conserved (Theorem 4.11: for the heavy top the vertical
    /// one, e₃·(R M)); the whole vector is returned.
    ///
    /// Errors: structure constants (no group), g of the wrong size or not in the group
    /// ([`Error::NotInGroup`] from the group's check).
    pub fn noether(&self, mu: &[f64], g: &[f64], out: &mut [f64]) -> Result<()> {
        let group = Group::of(&self.algebra).ok_or_else(|| {
            Error::invalid(
                "g",
                "an algebra given by structure constants has no matrix group here: no Noether \
                 momentum",
            )
        })?;
        group.noether(self.system.side(), mu, g, out)
    }

    /// The diamond b ⋄ a ∈ g* of b ∈ V (the derivative ∂ℓ/∂a) and a ∈ V*, defined by
    /// ⟨b ⋄ a, η⟩ = −⟨b, η·a⟩ with η·a = −ρ(η)ᵀa: (b ⋄ a)_i = ⟨b, ρ(e_i)ᵀ a⟩ = ⟨ρ(e_i) b, a⟩.
    pub fn diamond(&self, b: &[f64], a: &[f64], out: &mut [f64]) {
        let m = self.legendre.m;
        for (i, o) in out.iter_mut().enumerate() {
            let r = &self.rho[i * m * m..(i + 1) * m * m];
            *o = (0..m)
                .map(|p| a[p] * (0..m).map(|q| r[p * m + q] * b[q]).sum::<f64>())
                .sum();
        }
    }
}

/// D²H of the Lie–Poisson form as its Hessian-product function ([`Legendre::hamiltonian_hessian`]).
fn hamiltonian_hessian(
    legendre: &Arc<Legendre>,
    product: Option<LagrangianHessianFn>,
) -> super::LieHessianFn {
    let legendre = legendre.clone();
    Arc::new(move |z: &[f64], dz: &[f64], out: &mut [f64]| {
        legendre.hamiltonian_hessian(z, dz, product.as_ref(), out)
    })
}

/// ρ(e_i) (m×m each) of `action` on the algebra.
fn representation(algebra: &Algebra, d: usize, action: &Action, m: usize) -> Result<Vec<f64>> {
    match action {
        Action::Vector => {
            let Some(n) = Action::vector_dim(algebra) else {
                return Err(Error::invalid(
                    "action",
                    "the \"vector\" action is the defining representation of so(3) and \
                         so(n) on R^n (and of se(3) through its rotations); give the action of \
                         another algebra as a callable",
                ));
            };
            if m != n {
                return Err(Error::shape(
                    "parameter",
                    format!("({n},) (the vector action on R^{n})"),
                    format!("({m},)"),
                ));
            }
            // ρ(e_i) = ê_i (row-major); on se(3) the rotations ê_i (i < 3) and 0 for the
            // translations: the representation of se(3) through so(3) = se(3)/ℝ³ (a direction
            // fixed in space seen from a body that also translates, e.g. gravity for a vehicle
            // in a fluid).
            let mut rho = vec![0.0; d * n * n];
            for (i, r) in rho.chunks_exact_mut(n * n).enumerate() {
                match algebra {
                    Algebra::So3 | Algebra::Se3 if i < 3 => {
                        let mut e = nalgebra::Vector3::zeros();
                        e[i] = 1.0;
                        let x = crate::lie::so3::hat(&e);
                        r.iter_mut()
                            .enumerate()
                            .for_each(|(k, v)| *v = x[(k / 3, k % 3)]);
                    }
                    Algebra::So(_) => {
                        let mut e = vec![0.0; d];
                        e[i] = 1.0;
                        let x = so::hat_n_unchecked(n, &e);
                        r.iter_mut()
                            .enumerate()
                            .for_each(|(k, v)| *v = x[(k / n, k % n)]);
                    }
                    _ => {}
                }
            }
            Ok(rho)
        }
        Action::Matrices(a) => {
            check::finite_slice("action", a)?;
            if a.len() != d * m * m {
                return Err(Error::shape(
                    "action",
                    format!("({d}, {m}, {m}) (one matrix per basis element)"),
                    format!("{} values", a.len()),
                ));
            }
            // ρ(e_i) = −A_iᵀ.
            let mut rho = vec![0.0; d * m * m];
            for i in 0..d {
                for p in 0..m {
                    for q in 0..m {
                        rho[i * m * m + p * m + q] = -a[i * m * m + q * m + p];
                    }
                }
            }
            Ok(rho)
        }
    }
}

/// The structure constants of g ⋉ V (dimension d + m) from those of g (`c`, d³) and ρ:
/// [e_i, e_j] = C_ij^k e_k, [e_i, f_q] = Σ_p ρ(e_i)_{pq} f_p = −[f_q, e_i], [f, f] = 0.
fn semidirect_constants(c: &[f64], d: usize, rho: &[f64], m: usize) -> Vec<f64> {
    let n = d + m;
    let mut out = vec![0.0; n * n * n];
    for i in 0..d {
        for j in 0..d {
            for k in 0..d {
                out[(i * n + j) * n + k] = c[(i * d + j) * d + k];
            }
        }
        for q in 0..m {
            for p in 0..m {
                let v = rho[i * m * m + p * m + q];
                out[(i * n + d + q) * n + d + p] = v;
                out[((d + q) * n + i) * n + d + p] = -v;
            }
        }
    }
    out
}

/// Checks an inertia operator 𝕀 (d×d): finite, symmetric, positive definite.
fn check_inertia(i: &[f64], d: usize) -> Result<()> {
    check::symmetric("inertia", "a symmetric positive definite matrix", i, d)?;
    if DMatrix::from_row_slice(d, d, i).cholesky().is_none() {
        return Err(Error::invalid(
            "inertia",
            "the inertia must be positive definite (the kinetic energy <xi, I xi>/2 > 0)",
        ));
    }
    Ok(())
}

/// 𝕀⁻¹ (row-major) of a checked inertia.
fn inverse(i: &[f64], d: usize) -> Result<Vec<f64>> {
    let m = DMatrix::from_row_slice(d, d, i);
    let inv = m
        .cholesky()
        .map(|c| c.inverse())
        .ok_or_else(|| Error::invalid("inertia", "the inertia must be positive definite"))?;
    let inv = (&inv + inv.transpose()) * 0.5;
    Ok(inv.transpose().as_slice().to_vec())
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// out ← A x for a d×d row-major A (d = x.len()).
fn mat_vec(a: &[f64], x: &[f64], out: &mut [f64]) {
    for (o, row) in out.iter_mut().zip(a.chunks_exact(x.len())) {
        *o = row.iter().zip(x).map(|(r, v)| r * v).sum();
    }
}

fn fmt_vec(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| fmt_num(*x)).collect();
    format!("[{}]", items.join(", "))
}

/// The Lie–Poisson form's: state, energy H, Casimirs (and the Noether momentum with the
/// configuration).
impl Problem for EulerPoincare {
    fn calls_out(&self) -> bool {
        self.system.calls_out()
    }
    fn name(&self) -> &'static str {
        "EulerPoincare"
    }
    fn space(&self) -> Space {
        self.system.space()
    }
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.system.energy(z)
    }
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.system.invariants(z)
    }
    fn invariant_names(&self) -> Vec<String> {
        self.system.invariant_names()
    }
    fn check_state(&self, z: &[f64]) -> Result<()> {
        self.system.check_state(z)
    }
}

impl VectorField for EulerPoincare {
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        self.system.field(z, dz)
    }
}

impl GroupField for EulerPoincare {
    type Scratch = LieScratch;
    fn scratch(&self) -> LieScratch {
        self.system.scratch()
    }
    fn algebra_dim(&self) -> usize {
        self.system.algebra_dim()
    }
    fn generator(&self, z: &[f64], xi: &mut [f64], s: &mut LieScratch) {
        self.system.generator(z, xi, s)
    }
    fn act(&self, xi: &[f64], z: &mut [f64], s: &mut LieScratch) {
        self.system.act(xi, z, s)
    }
    fn act_increment(&self, xi: &[f64], z: &[f64], dz: &mut [f64], s: &mut LieScratch) -> bool {
        self.system.act_increment(xi, z, dz, s)
    }
    fn dexp_inv(&self, u: &[f64], v: &[f64], out: &mut [f64], s: &mut LieScratch) {
        self.system.dexp_inv(u, v, out, s)
    }
}

/// The Lie–Poisson form's derivatives ([`LiePoisson`]'s [`VectorFieldTangent`]).
impl VectorFieldTangent for EulerPoincare {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        self.system.field_tangent(z, dz, out)
    }
}

/// The Lie–Poisson form's derivatives ([`LiePoisson`]'s [`GroupFieldTangent`]).
impl GroupFieldTangent for EulerPoincare {
    fn generator_tangent(&self, z: &[f64], dz: &[f64], dxi: &mut [f64], s: &mut LieScratch) {
        self.system.generator_tangent(z, dz, dxi, s)
    }
    fn act_tangent(&self, u: &[f64], du: &[f64], y: &[f64], dz: &mut [f64], s: &mut LieScratch) {
        self.system.act_tangent(u, du, y, dz, s)
    }
    fn dexp_tangent(&self, u: &[f64], du: &[f64], w: &[f64], out: &mut [f64], s: &mut LieScratch) {
        self.system.dexp_tangent(u, du, w, out, s)
    }
}

/// The Lie–Poisson methods on the tangent lift (not the variational ones, of another kind):
/// rkmk4, midpoint, midpoint4, and rk4 (with an SO(3) attitude on the field lift).
impl Catalog for Tangent<EulerPoincare> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        group_field_catalog()
    }

    fn catalog(&self) -> Vec<Entry<Self>> {
        super::lie_poisson::lifted_catalog(self)
    }
}

impl Catalog for EulerPoincare {
    /// variational (default; the discrete Euler–Poincaré method, order 2), variational4 and
    /// variational6 (its Suzuki and Yoshida compositions), then the Lie–Poisson methods of the
    /// Hamiltonian form (`group_field_catalog`: rkmk4, midpoint, midpoint4, rk4).
    fn kind_catalog() -> Vec<Entry<Self>> {
        let mut catalog = vec![
            Entry::new("variational", || Variational(Composition::strang())),
            Entry::new("variational4", || Variational(Composition::suzuki4())),
            Entry::new("variational6", || Variational(Composition::yoshida6())),
        ];
        catalog.extend(group_field_catalog());
        catalog
    }

    /// The system with its configuration ([`EulerPoincare::with_attitude`]).
    fn lifted(&self) -> Option<Self> {
        self.with_attitude()
    }

    /// The tangent lift of the Lie–Poisson methods where the derivatives are exact
    /// ([`EulerPoincare::has_tangent`]: a quadratic ℓ; or ℓ with its gradient and either its
    /// Hessian ∂²ℓ/∂ξ² without a parameter or its Hessian product
    /// ([`EulerPoincare::with_hessian`])).
    fn tangent(&self) -> Option<Arc<dyn TangentSystem>> {
        self.has_tangent()
            .then(|| Tangent::group_field(self.clone()).into_system())
    }

    /// With the attitude on SO(3), rk4 on the field lift (ambient directions).
    fn tangent_for(&self, method: &str) -> Option<Arc<dyn TangentSystem>> {
        match self.has_tangent() {
            true => Tangent::routed(self, method, || self.tangent()),
            false => None,
        }
    }

    /// The Lie–Poisson form's double-bracket dissipation (left-invariant systems).
    fn dissipation(
        &self,
        d: &crate::integrate::forcing::Dissipation,
    ) -> Result<Arc<dyn crate::integrate::forcing::Perturbation>> {
        self.system.dissipation(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn so3_with_the_vector_action_is_se3() {
        let so3 = Structure::new(Algebra::So3).unwrap();
        let rho = representation(&Algebra::So3, 3, &Action::Vector, 3).unwrap();
        let c = semidirect_constants(&so3.dense(), 3, &rho, 3);
        assert_eq!(c, Structure::new(Algebra::Se3).unwrap().dense());
        // The same from the action on V* as matrices: e_i·a = ê_i a (ρ = −Aᵀ = ê_i).
        let a: Vec<f64> = (0..3)
            .flat_map(|i| rho[i * 9..(i + 1) * 9].to_vec())
            .collect();
        assert_eq!(
            representation(&Algebra::So3, 3, &Action::Matrices(a), 3).unwrap(),
            {
                let mut r = rho.clone();
                for i in 0..3 {
                    for p in 0..3 {
                        for q in 0..3 {
                            r[i * 9 + p * 3 + q] = -rho[i * 9 + q * 3 + p];
                        }
                    }
                }
                r
            }
        );
    }

    #[test]
    fn the_vector_action_of_so_n_is_a_representation() {
        // The Jacobi identity of so(n) ⋉ ℝⁿ (checked by Structure::new) holds only if ρ is one.
        for n in [2, 3, 4, 5] {
            let d = n * (n - 1) / 2;
            let g = Structure::new(Algebra::So(n)).unwrap();
            let rho = representation(&Algebra::So(n), d, &Action::Vector, n).unwrap();
            let c = semidirect_constants(&g.dense(), d, &rho, n);
            Structure::new(Algebra::Constants(c)).unwrap();
        }
        // A non-representation is refused: ρ(e_i) = identity for every i.
        let mut a = vec![0.0; 3 * 4];
        for i in 0..3 {
            a[i * 4] = 1.0;
            a[i * 4 + 3] = 1.0;
        }
        let l = Lagrangian::Function {
            value: Arc::new(|x: &[f64], _: &[f64]| Ok(0.5 * dot(x, x))),
            gradient: None,
            hessian: None,
        };
        let e = EulerPoincare::new(Algebra::So3, l, Side::Left, Some((Action::Matrices(a), 2)))
            .err()
            .unwrap();
        assert!(e.to_string().contains("not a representation"), "{e}");
    }
}
