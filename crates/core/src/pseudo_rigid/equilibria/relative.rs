//! The relative equilibrium through X₀ = diag(a) (001 (8.2)–(8.4)): the candidate from body
//! velocities or momenta with its residuals and motion, and the force balances in the semi-axes.

use super::{
    augmented_gradient, check_axes, check_pair, diag, equilibrium_residual, finite,
    require_distinct, vertical,
};
use crate::check;
use crate::error::Result;
use crate::lie::so;
use crate::pseudo_rigid::inertia::BiInertia;
use crate::pseudo_rigid::potential::{self, Potential};
use crate::Mat;

/// The Euclidean norm of the diagonal of `m`, without overflow of the squares (entries beyond
/// 1e154 have a representable norm).
fn diagonal_norm(m: &Mat) -> f64 {
    (0..m.nrows().min(m.ncols())).fold(0.0, |r: f64, k| r.hypot(m[(k, k)]))
}

/// How well a [`RelativeEquilibrium`] satisfies its conditions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Residuals {
    /// ‖∇_a U_{ξ⊕η}‖ (Euclidean norm over k): the force balance in the semi-axes.
    pub force: f64,
    /// The (8.6) residual ‖[Ω ⊕ Λ, B_A(Ω ⊕ Λ)]‖ ([`equilibrium_residual`]).
    pub commutator: f64,
    /// ‖∂U_{ξ⊕η}/∂X(A₀)‖_F = ‖Ẍ + ∂U/∂X‖ at t = 0 along the curve: the full equation of motion
    /// (zero iff both of the above vanish, on the principal stratum).
    pub motion: f64,
}

/// A relative equilibrium through the representative X₀ = A₀ = diag(a) (R₀ = S₀ = I, so body
/// and spatial quantities agree at t = 0): X(t) = e^{tΩ} A₀ e^{−tΛ} (001 (8.2)–(8.3)).
#[derive(Debug, Clone, PartialEq)]
pub struct RelativeEquilibrium {
    /// The semi-axes a (A₀ = diag(a)); any order, all > 0.
    pub a: Vec<f64>,
    /// Body angular velocity Ω = ξ (skew n×n, constant).
    pub xi: Mat,
    /// Body velocity Λ = η of the right action (skew n×n, constant).
    pub eta: Mat,
    /// Angular momentum λ = L = P₀X₀ᵀ − X₀P₀ᵀ = the ξ block of B_A(Ω ⊕ Λ) (001 (7.3), (8.4)).
    pub lam: Mat,
    /// Circulation γ = Γ = P₀ᵀX₀ − X₀ᵀP₀ = the η block of B_A(Ω ⊕ Λ) (001 (7.3), (8.4)).
    pub gam: Mat,
    /// Energy H = ½‖ΩA − AΛ‖² + U(A) (001 (3.22)).
    pub energy: f64,
    /// Residuals of the defining conditions.
    pub residuals: Residuals,
    /// The multiplier p of the incompressibility constraint det X = det A₀ (the force balance
    /// is ∂U_{ξ⊕η}/∂X = p cof X, [`RelativeEquilibrium::incompressible`]); 0 for a compressible
    /// body.
    pub pressure: f64,
}

impl RelativeEquilibrium {
    /// The candidate with body velocities (Ω, Λ) at A₀ = diag(a), with its momenta, energy and
    /// residuals (it is a relative equilibrium iff the residuals vanish; nothing is solved here).
    ///
    /// Errors: a not n ≥ 2 positive finite values, Ω, Λ not skew n×n, U not finite at A₀.
    pub fn from_velocities(pot: &dyn Potential, a: &[f64], xi: &Mat, eta: &Mat) -> Result<Self> {
        let n = check_axes(a)?;
        check_pair(("xi", "eta"), xi, eta, n)?;
        let x0 = diag(a);
        let (lam, gam) = BiInertia::new(&x0)?.apply(xi, eta)?;
        let grad = augmented_gradient(pot, &x0, xi, eta)?;
        let p0 = vertical(&x0, xi, eta);
        let energy = finite(
            "energy",
            0.5 * p0.norm_l2().powi(2) + potential::value(pot, &x0)?,
        )?;
        let residuals = Residuals {
            force: diagonal_norm(&grad),
            commutator: equilibrium_residual(a, xi, eta)?,
            motion: grad.norm_l2(),
        };
        Ok(RelativeEquilibrium {
            a: a.to_vec(),
            xi: xi.clone(),
            eta: eta.clone(),
            lam,
            gam,
            energy,
            residuals,
            pressure: 0.0,
        })
    }

    /// The candidate with body velocities (Ω, Λ) at A₀ = diag(a) for an incompressible body
    /// (holonomic constraint det X = det A₀,
    /// [`crate::pseudo_rigid::PseudoRigidBody::incompressible`]): the pressure p is the
    /// least-squares multiplier of the force balance ∂U_{ξ⊕η}/∂X(A₀) = p cof A₀
    /// (cof A₀ = diag(∏_{j≠i} a_j) = ∇_a ∏ a_j), and the residuals are those of
    /// ∂U_{ξ⊕η}/∂X − p cof A₀.
    ///
    /// Errors as [`RelativeEquilibrium::from_velocities`].
    pub fn incompressible(pot: &dyn Potential, a: &[f64], xi: &Mat, eta: &Mat) -> Result<Self> {
        let mut re = Self::from_velocities(pot, a, xi, eta)?;
        let n = a.len();
        let cof: Vec<f64> = (0..n)
            .map(|i| (0..n).filter(|&j| j != i).map(|j| a[j]).product())
            .collect();
        let mut grad = augmented_gradient(pot, &diag(a), xi, eta)?;
        let c2: f64 = cof.iter().map(|c| c * c).sum();
        let p = (0..n).map(|k| grad[(k, k)] * cof[k]).sum::<f64>() / c2;
        for k in 0..n {
            grad[(k, k)] -= p * cof[k];
        }
        re.residuals.force = diagonal_norm(&grad);
        re.residuals.motion = grad.norm_l2();
        re.pressure = finite("pressure", p)?;
        Ok(re)
    }

    /// The candidate with body momenta (λ, γ) at A₀ = diag(a): Ω ⊕ Λ = B_A⁻¹(λ ⊕ γ) (001 (7.9)),
    /// then [`RelativeEquilibrium::from_velocities`].
    ///
    /// Errors: as `from_velocities`, and
    /// [`Error::DegenerateStratum`](crate::Error::DegenerateStratum) for coincident a_i.
    pub fn from_momenta(pot: &dyn Potential, a: &[f64], lam: &Mat, gam: &Mat) -> Result<Self> {
        let n = check_axes(a)?;
        check_pair(("lam", "gam"), lam, gam, n)?;
        require_distinct("B_A⁻¹ (body velocities from momenta)", a)?;
        let (xi, eta) = BiInertia::new(&diag(a))?.solve(lam, gam)?;
        Self::from_velocities(pot, a, &xi, &eta)
    }

    /// The dimension n.
    pub fn n(&self) -> usize {
        self.a.len()
    }

    /// X₀ = diag(a).
    pub fn x0(&self) -> Mat {
        diag(&self.a)
    }

    /// P₀ = Ẋ(0) = ΩA₀ − A₀Λ.
    pub fn p0(&self) -> Mat {
        vertical(&self.x0(), &self.xi, &self.eta)
    }

    /// (X(t), P(t)) = (e^{tΩ} A₀ e^{−tΛ}, e^{tΩ}(ΩA₀ − A₀Λ) e^{−tΛ}) at the given times
    /// (001 (8.3); R(t) = e^{tΩ}, S(t) = e^{tΛ} solve Ṙ = RΩ, Ṡ = SΛ).
    ///
    /// Errors: a non-finite time or |tΩ|, |tΛ| beyond [`crate::numerics::angle::EXP_MAX_NORM`].
    pub fn motion(&self, times: &[f64]) -> Result<Vec<(Mat, Mat)>> {
        check::finite_slice("times", times)?;
        let (x0, p0) = (self.x0(), self.p0());
        times
            .iter()
            .map(|&t| {
                let r = so::exp(&(&self.xi * faer::Scale(t)))?;
                let s = so::exp(&(&self.eta * faer::Scale(t)))?;
                Ok((&r * &x0 * s.transpose(), &r * &p0 * s.transpose()))
            })
            .collect()
    }
}

/// The force balance F_k = ∂/∂a_k [U(a) − ½‖ΩA − AΛ‖²] = (∂U_{ξ⊕η}/∂X)_kk at A = diag(a) for
/// body velocities (Ω, Λ) (module docs; zero at a relative equilibrium with p_a = 0).
///
/// Errors: as [`RelativeEquilibrium::from_velocities`].
pub fn force_balance(pot: &dyn Potential, a: &[f64], xi: &Mat, eta: &Mat) -> Result<Vec<f64>> {
    let n = check_axes(a)?;
    let g = augmented_gradient(pot, &diag(a), xi, eta)?;
    Ok((0..n).map(|k| g[(k, k)]).collect())
}

/// The amended force ∂/∂a_k [U(a) + K(a; μ, ν)] at fixed body momenta (μ, ν) (001 (8.8)), with
/// the pair formula of [`crate::pseudo_rigid::reduced`]:
/// K = Σ_{i<j} ¼((μ_ij + ν_ij)²/(a_i − a_j)² + (μ_ij − ν_ij)²/(a_i + a_j)²), so ∂K/∂a_i gets
/// −½(s²/d₋³ + t²/d₊³) and ∂K/∂a_j gets ½(s²/d₋³ − t²/d₊³) from each pair (s = μ_ij + ν_ij,
/// t = μ_ij − ν_ij, d∓ = a_i ∓ a_j).
/// Equals minus ṗ_a of the reduced vector field.
///
/// Errors: a invalid or with coincident entries
/// ([`Error::DegenerateStratum`](crate::Error::DegenerateStratum)), μ, ν not skew.
pub fn amended_force(pot: &dyn Potential, a: &[f64], lam: &Mat, gam: &Mat) -> Result<Vec<f64>> {
    let n = check_axes(a)?;
    check_pair(("lam", "gam"), lam, gam, n)?;
    require_distinct("amended force", a)?;
    let g = potential::gradient(pot, &diag(a))?;
    let mut f: Vec<f64> = (0..n).map(|k| g[(k, k)]).collect();
    for i in 0..n {
        for j in i + 1..n {
            let (s, t) = (lam[(i, j)] + gam[(i, j)], lam[(i, j)] - gam[(i, j)]);
            let (dm, dp) = (a[i] - a[j], a[i] + a[j]);
            let (qm, qp) = (0.5 * s * s / dm.powi(3), 0.5 * t * t / dp.powi(3));
            f[i] += -qm - qp;
            f[j] += qm - qp;
        }
    }
    check::finite_slice("amended force", &f)?;
    Ok(f)
}
