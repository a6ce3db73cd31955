//! Störmer–Verlet for separable Hamiltonians H = ½ tr(PᵀP) + U(X) on T*GL⁺(n) (001 (3.22)),
//! and its symmetric compositions of order 4 (Suzuki 1990) and 6 (Yoshida 1990).
//!
//! One step of size h is kick–drift–kick: P ← P − (h/2)∂U/∂X(X); X ← X + hP;
//! P ← P − (h/2)∂U/∂X(X). It is symplectic, symmetric (order 2), and equivariant under the linear
//! symmetries X ↦ gXhᵀ, P ↦ gPhᵀ of an SO(n)×SO(n)-invariant U, so it preserves the quadratic
//! momentum maps L = PXᵀ − XPᵀ and Γ = PᵀX − XᵀP exactly (up to round-off): each kick adds to P
//! a multiple of ∂U/∂X, for which X(∂U/∂X)ᵀ and Xᵀ(∂U/∂X) are symmetric, and each drift adds to X
//! a multiple of P. The energy error stays bounded over exponentially long times.
//!
//! The gradient at the end of a substep is reused at the start of the next (first same as last),
//! so a step costs one gradient evaluation. The equations extend to all n×n matrices; with
//! `check_det` (the default) a step that ends with det X ≤ 0 stops the run with
//! [`Error::LeftDomain`]. Potentials defined only on GL⁺(n) (a volumetric term) are always checked.

use super::splitting::Composition;
use crate::check;
use crate::error::{Error, Result};
use crate::pseudo_rigid::potential::{self, Potential, Workspace};
use crate::Mat;
use nalgebra::Matrix3;

/// Order of the Verlet method: 2 (plain), 4 or 6 (symmetric composition).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VerletOrder {
    /// Störmer–Verlet, order 2.
    Two,
    /// Suzuki's 5-stage composition of Verlet, order 4 (smaller error than the triple jump).
    Four,
    /// Yoshida's composition "solution A" of Verlet, order 6 (7 stages).
    Six,
}

impl VerletOrder {
    /// The order for 2, 4 or 6.
    pub fn from_order(order: usize) -> Result<Self> {
        match order {
            2 => Ok(VerletOrder::Two),
            4 => Ok(VerletOrder::Four),
            6 => Ok(VerletOrder::Six),
            _ => Err(Error::invalid(
                "order",
                format!("Verlet has orders 2, 4 and 6, got {order}"),
            )),
        }
    }

    /// The order as a number.
    pub fn order(self) -> usize {
        match self {
            VerletOrder::Two => 2,
            VerletOrder::Four => 4,
            VerletOrder::Six => 6,
        }
    }

    /// The symmetric composition of Verlet steps giving this order ([`Composition`]).
    pub fn composition(self) -> Composition {
        match self {
            VerletOrder::Two => Composition::strang(),
            VerletOrder::Four => Composition::suzuki4(),
            VerletOrder::Six => Composition::yoshida6(),
        }
    }
}

/// Caller-owned scratch for [`Verlet::run`] on n×n matrices (no allocation per step).
#[derive(Debug)]
pub struct VerletScratch {
    grad: Mat,
    ws: Workspace,
}

impl VerletScratch {
    /// Scratch for n×n matrices.
    pub fn new(n: usize) -> Self {
        VerletScratch {
            grad: Mat::zeros(n, n),
            ws: Workspace::new(n),
        }
    }

    /// The matrix size n this scratch serves.
    pub fn n(&self) -> usize {
        self.ws.n()
    }
}

/// Störmer–Verlet of order 2, 4 or 6 for H = ½ tr(PᵀP) + U(X).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Verlet {
    /// The order (2, 4 or 6).
    pub order: VerletOrder,
    /// Stop with [`Error::LeftDomain`] when det X ≤ 0 after a substep (default true).
    pub check_det: bool,
}

impl Verlet {
    /// Verlet of the given order with `check_det` on.
    pub fn new(order: VerletOrder) -> Self {
        Verlet {
            order,
            check_det: true,
        }
    }

    /// The same method with `check_det` set.
    pub fn with_check_det(self, check_det: bool) -> Self {
        Verlet { check_det, ..self }
    }

    /// Advances (X, P) in place by `steps` steps of size `dt` from time `t0`.
    ///
    /// Errors (and changes nothing) for shapes other than n×n with n = `scratch.n()` ≥ 2,
    /// non-finite X, P or dt, dt ≤ 0, steps < 1, or det X₀ ≤ 0 when det X is checked. During
    /// the run, returns [`Error::LeftDomain`] with the time at which det X ≤ 0 was found (X, P are
    /// then the first state found outside GL⁺(n)), or [`Error::NonFinite`] if the state
    /// overflowed. Allocation-free after the checks.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        potential: &dyn Potential,
        x: &mut Mat,
        p: &mut Mat,
        t0: f64,
        dt: f64,
        steps: usize,
        scratch: &mut VerletScratch,
    ) -> Result<()> {
        let n = scratch.n();
        if n < 2 {
            return Err(Error::invalid(
                "scratch",
                format!("expected n ≥ 2, got {n}"),
            ));
        }
        check::square_of("X", x, n)?;
        check::square_of("P", p, n)?;
        check::positive("dt", dt)?;
        if !t0.is_finite() {
            return Err(Error::invalid(
                "t0",
                format!("expected a finite time, got {t0}"),
            ));
        }
        if steps < 1 {
            return Err(Error::invalid("steps", "expected steps ≥ 1, got 0"));
        }
        let check_det = self.check_det || potential.needs_positive_det();
        let VerletScratch { grad, ws } = scratch;
        if check_det {
            let d = potential::det(x.as_ref(), ws);
            if d.is_nan() || d <= 0.0 {
                return Err(Error::NotInGroup {
                    what: "X0".into(),
                    group: format!("GL+({n})"),
                    defect_name: "det X".into(),
                    defect: d,
                    tol: 0.0,
                });
            }
        }
        let composition = self.order.composition();
        if n == 3 {
            let x3 = Matrix3::from_fn(|i, j| x[(i, j)]);
            if let Some(g3) = potential.gradient3(&x3) {
                let mut s3 = (x3, Matrix3::from_fn(|i, j| p[(i, j)]));
                let run = run3(
                    potential,
                    &composition,
                    &mut s3,
                    g3,
                    (t0, dt, steps),
                    check_det,
                );
                for i in 0..3 {
                    for j in 0..3 {
                        x[(i, j)] = s3.0[(i, j)];
                        p[(i, j)] = s3.1[(i, j)];
                    }
                }
                run?;
                check::finite_mat("X after integration", x)?;
                check::finite_mat("P after integration", p)?;
                return Ok(());
            }
        }
        grad.fill(0.0);
        potential.add_gradient(x.as_ref(), grad.as_mut(), ws);
        for k in 0..steps {
            let mut t = t0 + k as f64 * dt;
            for &g in composition.gammas() {
                let h = g * dt;
                potential::axpy(p.as_mut(), -0.5 * h, grad.as_ref());
                potential::axpy(x.as_mut(), h, p.as_ref());
                t += h;
                if check_det {
                    let d = potential::det(x.as_ref(), ws);
                    if d.is_nan() || d <= 0.0 {
                        return Err(left_domain(n, t, d, k + 1, dt));
                    }
                }
                grad.fill(0.0);
                potential.add_gradient(x.as_ref(), grad.as_mut(), ws);
                potential::axpy(p.as_mut(), -0.5 * h, grad.as_ref());
            }
        }
        check::finite_mat("X after integration", x)?;
        check::finite_mat("P after integration", p)?;
        Ok(())
    }
}

/// The error for det X ≤ 0 found at time `t` after step `step`.
fn left_domain(n: usize, t: f64, d: f64, step: usize, dt: f64) -> Error {
    Error::LeftDomain {
        what: format!("X (pseudo-rigid body in GL+({n}))"),
        t,
        message: format!(
            "det X = {d:.3e} ≤ 0 after step {step} (dt = {dt}): the motion left GL+({n}); the \
             equations extend to all n×n matrices, so pass check_det = false to continue (not \
             possible with a volumetric potential, which is defined only for det X > 0)"
        ),
    }
}

/// The n = 3 loop of [`Verlet::run`] on stack matrices, for potentials with
/// [`Potential::gradient3`]; the same arithmetic as the general loop. `s` = (X, P) is left at
/// the last state computed (also on error); `g` = ∂U/∂X at the initial X.
fn run3(
    potential: &dyn Potential,
    composition: &Composition,
    s: &mut (Matrix3<f64>, Matrix3<f64>),
    mut g: Matrix3<f64>,
    (t0, dt, steps): (f64, f64, usize),
    check_det: bool,
) -> Result<()> {
    let (x, p) = s;
    for k in 0..steps {
        let mut t = t0 + k as f64 * dt;
        for &w in composition.gammas() {
            let h = w * dt;
            *p -= g * (0.5 * h);
            *x += *p * h;
            t += h;
            if check_det {
                let d = x.determinant();
                if d.is_nan() || d <= 0.0 {
                    return Err(left_domain(3, t, d, k + 1, dt));
                }
            }
            // A potential's fast path does not come and go; NaN would surface as NonFinite.
            g = potential
                .gradient3(x)
                .unwrap_or_else(|| Matrix3::from_element(f64::NAN));
            *p -= g * (0.5 * h);
        }
    }
    Ok(())
}
