//! SO(n)×SO(n)-invariant potentials U(X) of pseudo-rigid bodies on GL⁺(n) (001 §4.1, (3.22);
//! 000 §5.3).
//!
//! A [`Potential`] gives the value U(X) and adds the gradient ∂U/∂X (with respect to the pairing
//! ⟨A, B⟩ = tr(AᵀB)) to a caller-owned matrix, using a caller-owned [`Workspace`], so that hot
//! loops (the Verlet kick) allocate nothing. The built-ins are all invariant under
//! X ↦ gXhᵀ, (g, h) ∈ SO(n)×SO(n), i.e. they are functions of the singular values of X only
//! (001 §4.1, U = U(A)):
//!
//! - [`Harmonic`]: U = (k/2) tr(XᵀX);
//! - [`SaintVenantKirchhoff`]: U = (λ/2)(tr E)² + μ tr(E²), E = ½(XᵀX − I);
//! - [`Volumetric`]: the polytropic gas U = κ (det(X)^{1−γ} − 1)/(γ − 1) (γ > 1), and its γ → 1
//!   limit U = −κ ln det X (isothermal);
//! - [`Stretch`]: the isotropic quadratic stretch energy U = (k/2) Σ_i (σ_i(X) − 1)²;
//! - [`SelfGravity`] (n = 3 only, [`super::gravity`]): the gravitational energy of a homogeneous
//!   ellipsoid, U = −4πGρ R_F(σ₁², σ₂², σ₃²) (Chandrasekhar, EFE ch. 3);
//! - [`Sum`] of potentials, and [`Zero`] (the free body).
//!
//! Every potential also has an analytic Hessian, as the directional second derivative
//! D²U(X)\[V\] = d/dε ∂U/∂X(X + εV)|_{ε=0} ([`Potential::add_hessian`]), used for the stability of
//! relative equilibria (001 §8). The checked entry points for single evaluations are [`value`],
//! [`gradient`], [`hessian_product`] and [`hessian`] (the n²×n² matrix). A potential may be defined
//! for one dimension n only ([`Potential::dimension`]); the checked entry points and the body
//! ([`super::dynamics::FullBody::new`]) refuse it at another n ([`check_dimension`]).

use crate::check;
use crate::error::{Error, Result};
use crate::numerics::linalg::{axpy, frob2, inner, mul};
use crate::Mat;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, inverse};
use faer::{Accum, MatMut, MatRef, Par};
use nalgebra::Matrix3;
use std::fmt::Debug;
use std::sync::Arc;

pub use super::gravity::SelfGravity;

/// Scratch memory for evaluating potentials of n×n matrices without allocation.
///
/// Create one per thread with [`Workspace::new`] and pass it to every call.
pub struct Workspace {
    n: usize,
    tmp: Mat,
    tmp2: Mat,
    lu: Mat,
    perm_fwd: Vec<usize>,
    perm_bwd: Vec<usize>,
    mem: MemBuffer,
}

impl Debug for Workspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Workspace")
            .field("n", &self.n)
            .finish_non_exhaustive()
    }
}

impl Workspace {
    /// Workspace for n×n matrices.
    pub fn new(n: usize) -> Self {
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()),
            inverse::inverse_scratch::<usize, f64>(n, Par::Seq),
        ]);
        Workspace {
            n,
            tmp: Mat::zeros(n, n),
            tmp2: Mat::zeros(n, n),
            lu: Mat::zeros(n, n),
            perm_fwd: vec![0; n],
            perm_bwd: vec![0; n],
            mem: MemBuffer::new(req),
        }
    }

    /// The matrix size n this workspace serves.
    pub fn n(&self) -> usize {
        self.n
    }
}

/// out += ∂U/∂X / θ for a U linear in its constant θ ≠ 0 (so ∂(∂U/∂X)/∂θ = ∂U/∂X / θ), without
/// a temporary: out ← (θ·out + ∂U/∂X)/θ.
pub(crate) fn add_gradient_over(
    pot: &dyn Potential,
    theta: f64,
    x: MatRef<'_, f64>,
    mut out: MatMut<'_, f64>,
    ws: &mut Workspace,
) {
    scale(out.as_mut(), theta);
    pot.add_gradient(x, out.as_mut(), ws);
    scale(out, 1.0 / theta);
}

fn scale(mut out: MatMut<'_, f64>, c: f64) {
    for j in 0..out.ncols() {
        for i in 0..out.nrows() {
            out[(i, j)] *= c;
        }
    }
}

/// A potential energy U(X) on n×n matrices (001 §4.1), with its gradient ∂U/∂X and Hessian.
///
/// Implementations are kernels for hot loops: they assume `x` is n×n with n = `ws.n()`, finite,
/// and (if [`Potential::needs_positive_det`]) det X > 0; they do not check and do not allocate.
/// Use [`value`] and [`gradient`] for checked single evaluations.
pub trait Potential: Send + Sync + Debug {
    /// U(X); +∞ where U is not defined (det X ≤ 0 for a volumetric term).
    fn value(&self, x: MatRef<'_, f64>, ws: &mut Workspace) -> f64;

    /// Adds ∂U/∂X (the gradient for the pairing tr(AᵀB)) to `out`.
    fn add_gradient(&self, x: MatRef<'_, f64>, out: MatMut<'_, f64>, ws: &mut Workspace);

    /// Adds the Hessian applied to V, D²U(X)\[V\] = d/dε ∂U/∂X(X + εV)|_{ε=0}, to `out`: the
    /// matrix H with ⟨W, H⟩ = D²U(X)\[V, W\] for the pairing tr(AᵀB), symmetric in V and W.
    ///
    /// Required, so that no potential is without a Hessian silently; implementations give it
    /// analytically (a Python callable without one falls back to finite differences, documented
    /// there). `v` is n×n like `x`.
    fn add_hessian(
        &self,
        x: MatRef<'_, f64>,
        v: MatRef<'_, f64>,
        out: MatMut<'_, f64>,
        ws: &mut Workspace,
    );

    /// The names of U's constants θ (`Harmonic`: k; `SaintVenantKirchhoff`: lambda, mu;
    /// `Volumetric`: kappa, gamma; …), the parameters of a body's sensitivities; none by
    /// default (a Python callable).
    fn parameters(&self) -> Vec<&'static str> {
        Vec::new()
    }

    /// Adds ∂(∂U/∂X)/∂θ_m, the derivative of the gradient along the constant m, to `out` (for
    /// m < `parameters().len()`; nothing by default).
    fn add_parameter_gradient(
        &self,
        _x: MatRef<'_, f64>,
        _m: usize,
        _out: MatMut<'_, f64>,
        _ws: &mut Workspace,
    ) {
    }

    /// Whether U is defined only on GL⁺(n) (det X > 0). Integrators then always check det X.
    fn needs_positive_det(&self) -> bool {
        false
    }

    /// Whether U is given by functions from outside lieflow (a binding's callables), which a
    /// body with this potential then calls ([`crate::integrate::Problem::calls_out`]).
    fn calls_out(&self) -> bool {
        false
    }

    /// Fixed-size fast path for n = 3: ∂U/∂X at a 3×3 X, or `None` if the potential has none
    /// (callers then use [`Potential::add_gradient`]). Must equal `add_gradient` (tested); lets
    /// the n = 3 Verlet loop run on stack matrices.
    fn gradient3(&self, _x: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        None
    }

    /// Fixed-size fast path for n = 3 of the Hessian product D²U(X)\[V\], or `None` (callers
    /// then use [`Potential::add_hessian`]). Must equal `add_hessian` (tested); lets the
    /// tangent lift of the n = 3 body (its Jacobians) run on stack matrices.
    fn hessian3(&self, _x: &Matrix3<f64>, _v: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        None
    }

    /// The one dimension n at which U is defined, or `None` if it is defined for every n (the
    /// default). [`SelfGravity`] is `Some(3)`; a [`Sum`] has the dimension of its terms, and
    /// `Some(0)` (defined for no n) if two terms disagree. Kernels called at another n return NaN
    /// (they must not panic); [`check_dimension`] refuses such calls.
    fn dimension(&self) -> Option<usize> {
        None
    }
}

/// Refuses a potential of another dimension than n ([`Potential::dimension`]) with
/// [`Error::InvalidArgument`] naming the potential, its dimension and n.
pub fn check_dimension(pot: &dyn Potential, n: usize) -> Result<()> {
    match pot.dimension() {
        Some(0) => Err(Error::invalid(
            "potential",
            format!(
                "{pot:?} is a sum of terms defined for different dimensions n, so it is defined \
                 for none (here n = {n})"
            ),
        )),
        Some(d) if d != n => Err(Error::invalid(
            "potential",
            format!("{pot:?} is defined for n = {d} only, not for n = {n}"),
        )),
        _ => Ok(()),
    }
}

/// Checks the dimension of the potential ([`check_dimension`]) and det X > 0 when the potential
/// needs it (shape and finiteness are checked by callers).
pub(crate) fn check_point(pot: &dyn Potential, x: &Mat, ws: &mut Workspace) -> Result<()> {
    check_dimension(pot, x.nrows())?;
    if pot.needs_positive_det() {
        // Fast path: a normal positive product of the pivots settles it; otherwise (overflow,
        // underflow, NaN, det ≤ 0) the one membership test of GL⁺(n) decides on the sign.
        let d = det(x.as_ref(), ws);
        if !(d.is_normal() && d > 0.0) {
            let group = format!("GL+({}) (the domain of this potential)", x.nrows());
            crate::lie::gl::check_det_positive("X", &group, x)?;
        }
    }
    Ok(())
}

/// U(X), checked: X square n×n with n ≥ 2, finite, det X > 0 if the potential needs it.
pub fn value(pot: &dyn Potential, x: &Mat) -> Result<f64> {
    let n = check::square("X", x, 2)?;
    let mut ws = Workspace::new(n);
    check_point(pot, x, &mut ws)?;
    let u = pot.value(x.as_ref(), &mut ws);
    if !u.is_finite() {
        return Err(not_representable("U(X)", x));
    }
    Ok(u)
}

/// The error of the checked evaluations when a finite X in the domain gives a non-finite result:
/// the quantity exceeds the f64 range there (e.g. U = μ tr E² with E ~ XᵀX/2 beyond 1e77, or a
/// volumetric det(X)^{1−γ} with a large γ), named with the scale of X.
fn not_representable(what: &str, x: &Mat) -> Error {
    Error::overflow(
        "X",
        format!(
            "{what} exceeds the f64 range at this X (‖X‖_F = {:.3e}); rescale the problem",
            (crate::lie::scaled_norm(
                (0..x.ncols())
                    .flat_map(|j| (0..x.nrows()).map(move |i| x[(i, j)]))
                    .collect::<Vec<_>>()
                    .iter()
            ))
        ),
    )
}

/// `m`, or [`not_representable`] if an entry is not finite.
fn finite_result(what: &str, x: &Mat, m: Mat) -> Result<Mat> {
    if check::finite_mat(what, &m).is_err() {
        return Err(not_representable(what, x));
    }
    Ok(m)
}

/// ∂U/∂X, checked like [`value`].
pub fn gradient(pot: &dyn Potential, x: &Mat) -> Result<Mat> {
    let n = check::square("X", x, 2)?;
    let mut ws = Workspace::new(n);
    check_point(pot, x, &mut ws)?;
    let mut g = Mat::zeros(n, n);
    pot.add_gradient(x.as_ref(), g.as_mut(), &mut ws);
    finite_result("the gradient ∂U/∂X", x, g)
}

/// The Hessian applied to a direction, D²U(X)\[V\] = d/dε ∂U/∂X(X + εV)|_{ε=0}
/// ([`Potential::add_hessian`]), checked like [`value`]; V must be n×n and finite.
pub fn hessian_product(pot: &dyn Potential, x: &Mat, v: &Mat) -> Result<Mat> {
    let n = check::square("X", x, 2)?;
    check::square_of("V", v, n)?;
    let mut ws = Workspace::new(n);
    check_point(pot, x, &mut ws)?;
    let mut h = Mat::zeros(n, n);
    pot.add_hessian(x.as_ref(), v.as_ref(), h.as_mut(), &mut ws);
    finite_result("the Hessian product D²U(X)[V]", x, h)
}

/// The Hessian of U at X as an n²×n² matrix in the row-major vec(X) basis: entry
/// (p·n + q, i·n + j) is ∂²U/∂X_pq∂X_ij, i.e. column i·n + j is D²U(X)\[E_ij\] (E_ij the unit
/// matrix with 1 at (i, j)) flattened row-major. Symmetric. Checked like [`value`], and refused
/// with [`Error::InvalidArgument`] when n⁴ exceeds [`check::MAX_DENSE_ENTRIES`].
pub fn hessian(pot: &dyn Potential, x: &Mat) -> Result<Mat> {
    let n = check::square("X", x, 2)?;
    let m = n.saturating_mul(n);
    check::dense_size("Hessian", m, m)?;
    let mut ws = Workspace::new(n);
    check_point(pot, x, &mut ws)?;
    let mut h = Mat::zeros(m, m);
    let mut e = Mat::zeros(n, n);
    let mut col = Mat::zeros(n, n);
    for i in 0..n {
        for j in 0..n {
            e[(i, j)] = 1.0;
            col.fill(0.0);
            pot.add_hessian(x.as_ref(), e.as_ref(), col.as_mut(), &mut ws);
            e[(i, j)] = 0.0;
            for p in 0..n {
                for q in 0..n {
                    h[(p * n + q, i * n + j)] = col[(p, q)];
                }
            }
        }
    }
    finite_result("the Hessian D²U(X)", x, h)
}

/// U = 0: the free pseudo-rigid body, whose motions are straight lines X(t) = X₀ + tP₀.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Zero;

impl Potential for Zero {
    fn value(&self, _x: MatRef<'_, f64>, _ws: &mut Workspace) -> f64 {
        0.0
    }
    fn add_gradient(&self, _x: MatRef<'_, f64>, _out: MatMut<'_, f64>, _ws: &mut Workspace) {}
    fn add_hessian(
        &self,
        _x: MatRef<'_, f64>,
        _v: MatRef<'_, f64>,
        _out: MatMut<'_, f64>,
        _ws: &mut Workspace,
    ) {
    }
    fn gradient3(&self, _x: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        Some(Matrix3::zeros())
    }
    fn hessian3(&self, _x: &Matrix3<f64>, _v: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        Some(Matrix3::zeros())
    }
}

/// Harmonic (isotropic linear-spring) potential U = (k/2) tr(XᵀX), ∂U/∂X = kX, D²U\[V\] = kV;
/// 000 §5.3.
///
/// Its motions are X(t) = X₀ cos ωt + (P₀/ω) sin ωt with ω = √k.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Harmonic {
    k: f64,
}

impl Harmonic {
    /// Spring constant k > 0 (finite).
    pub fn new(k: f64) -> Result<Self> {
        check::positive("k", k)?;
        Ok(Harmonic { k })
    }
    /// The spring constant k.
    pub fn k(&self) -> f64 {
        self.k
    }
}

impl Potential for Harmonic {
    fn value(&self, x: MatRef<'_, f64>, _ws: &mut Workspace) -> f64 {
        0.5 * self.k * frob2(x)
    }
    fn add_gradient(&self, x: MatRef<'_, f64>, out: MatMut<'_, f64>, _ws: &mut Workspace) {
        axpy(out, self.k, x);
    }
    fn add_hessian(
        &self,
        _x: MatRef<'_, f64>,
        v: MatRef<'_, f64>,
        out: MatMut<'_, f64>,
        _ws: &mut Workspace,
    ) {
        axpy(out, self.k, v);
    }
    fn gradient3(&self, x: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        Some(x * self.k)
    }
    fn hessian3(&self, _x: &Matrix3<f64>, v: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        Some(v * self.k)
    }
    fn parameters(&self) -> Vec<&'static str> {
        vec!["k"]
    }
    /// ∂(kX)/∂k = X.
    fn add_parameter_gradient(
        &self,
        x: MatRef<'_, f64>,
        _m: usize,
        out: MatMut<'_, f64>,
        _ws: &mut Workspace,
    ) {
        axpy(out, 1.0, x);
    }
}

/// Isotropic Saint Venant–Kirchhoff elastic energy U = (λ/2)(tr E)² + μ tr(E²) with the
/// Green–Lagrange strain E = ½(XᵀX − I).
///
/// ∂U/∂X = X S with the second Piola–Kirchhoff stress S = λ (tr E) I + 2μE (derived from
/// dE = ½(dXᵀX + XᵀdX)). Since tr E and tr E² depend on XᵀX only through its eigenvalues a_i²,
/// U = U(A) is SO(n)×SO(n)-invariant (001 §4.1).
///
/// Hessian: with C = XᵀX, S = μC + (λ tr E − μ)I, dC\[V\] = VᵀX + XᵀV and d tr E\[V\] = tr(XᵀV),
/// D²U(X)\[V\] = V S + X (μ(VᵀX + XᵀV) + λ tr(XᵀV) I).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SaintVenantKirchhoff {
    lambda: f64,
    mu: f64,
}

impl SaintVenantKirchhoff {
    /// Lamé parameters: shear modulus μ > 0 and λ ≥ 0 (Poisson ratio in [0, ½)), both finite.
    pub fn new(lambda: f64, mu: f64) -> Result<Self> {
        check::positive("mu", mu)?;
        if !(lambda.is_finite() && lambda >= 0.0) {
            return Err(Error::invalid(
                "lambda",
                format!(
                    "expected a finite Lamé parameter λ ≥ 0, got {}",
                    crate::error::fmt_num(lambda)
                ),
            ));
        }
        Ok(SaintVenantKirchhoff { lambda, mu })
    }
    /// Lamé's first parameter λ.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }
    /// The shear modulus μ.
    pub fn mu(&self) -> f64 {
        self.mu
    }

    /// Writes C = XᵀX into `ws.tmp` and returns (tr E, tr E²).
    fn strain(x: MatRef<'_, f64>, ws: &mut Workspace) -> (f64, f64) {
        mul(ws.tmp.as_mut(), Accum::Replace, x.transpose(), x, 1.0);
        let n = x.nrows();
        let (mut tr, mut tr2) = (0.0, 0.0);
        for j in 0..n {
            for i in 0..n {
                let e = 0.5 * (ws.tmp[(i, j)] - if i == j { 1.0 } else { 0.0 });
                tr2 += e * e;
                if i == j {
                    tr += e;
                }
            }
        }
        (tr, tr2)
    }

    /// Writes the second Piola–Kirchhoff stress S = λ tr(E) I + 2μE = μC + (λ tr E − μ)I into
    /// `ws.tmp`.
    fn stress(&self, x: MatRef<'_, f64>, ws: &mut Workspace) {
        let (tr, _) = Self::strain(x, ws);
        let n = x.nrows();
        for j in 0..n {
            for i in 0..n {
                ws.tmp[(i, j)] *= self.mu;
            }
            ws.tmp[(j, j)] += self.lambda * tr - self.mu;
        }
    }
}

impl Potential for SaintVenantKirchhoff {
    fn value(&self, x: MatRef<'_, f64>, ws: &mut Workspace) -> f64 {
        let (tr, tr2) = Self::strain(x, ws);
        0.5 * self.lambda * tr * tr + self.mu * tr2
    }
    fn add_gradient(&self, x: MatRef<'_, f64>, out: MatMut<'_, f64>, ws: &mut Workspace) {
        self.stress(x, ws);
        mul(out, Accum::Add, x, ws.tmp.as_ref(), 1.0);
    }
    fn add_hessian(
        &self,
        x: MatRef<'_, f64>,
        v: MatRef<'_, f64>,
        mut out: MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        // V S, then X dS with dS = μ(VᵀX + XᵀV) + λ tr(XᵀV) I.
        self.stress(x, ws);
        mul(out.as_mut(), Accum::Add, v, ws.tmp.as_ref(), 1.0);
        let dtr = inner(x, v);
        mul(ws.tmp.as_mut(), Accum::Replace, v.transpose(), x, self.mu);
        mul(ws.tmp.as_mut(), Accum::Add, x.transpose(), v, self.mu);
        for i in 0..x.nrows() {
            ws.tmp[(i, i)] += self.lambda * dtr;
        }
        mul(out, Accum::Add, x, ws.tmp.as_ref(), 1.0);
    }
    fn gradient3(&self, x: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        // The same S = μC + (λ tr E − μ)I over C = XᵀX as add_gradient.
        let c = x.transpose() * x;
        let tr = 0.5 * (c.trace() - 3.0);
        let mut st = c * self.mu;
        for i in 0..3 {
            st[(i, i)] += self.lambda * tr - self.mu;
        }
        Some(x * st)
    }
    fn hessian3(&self, x: &Matrix3<f64>, v: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        // V S + X dS, dS = μ(VᵀX + XᵀV) + λ tr(XᵀV) I, as add_hessian.
        let c = x.transpose() * x;
        let tr = 0.5 * (c.trace() - 3.0);
        let mut st = c * self.mu;
        let mut ds = (v.transpose() * x + x.transpose() * v) * self.mu;
        let dtr = x.dot(v);
        for i in 0..3 {
            st[(i, i)] += self.lambda * tr - self.mu;
            ds[(i, i)] += self.lambda * dtr;
        }
        Some(v * st + x * ds)
    }
    fn parameters(&self) -> Vec<&'static str> {
        vec!["lambda", "mu"]
    }
    /// ∂U/∂X = X S with S = λ tr(E) I + 2μE: ∂/∂λ = tr(E) X, ∂/∂μ = 2XE = X(C − I).
    fn add_parameter_gradient(
        &self,
        x: MatRef<'_, f64>,
        m: usize,
        out: MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        let (tr, _) = Self::strain(x, ws);
        if m == 0 {
            axpy(out, tr, x);
        } else {
            // ws.tmp holds C = XᵀX: 2XE = XC − X.
            let mut out = out;
            mul(out.as_mut(), Accum::Add, x, ws.tmp.as_ref(), 1.0);
            axpy(out, -1.0, x);
        }
    }
}

/// Volumetric energy of a polytropic gas filling the body, U = f(det X) (001 §4.1: a function of
/// the volume det X = Π a_i, hence SO(n)×SO(n)-invariant):
///
/// U = κ (det(X)^{1−γ} − 1)/(γ − 1) for γ > 1, and U = −κ ln det X for γ = 1 (the limit γ → 1;
/// isothermal gas). The pressure is p = −dU/d(det X) = κ det(X)^{−γ}, and
/// ∂U/∂X = −κ det(X)^{−γ} cof(X) = −κ det(X)^{1−γ} X⁻ᵀ (from ∂ det/∂X = det(X) X⁻ᵀ = cof X).
/// U → +∞ as det X → 0⁺, so this term keeps bodies from collapsing. Defined on GL⁺(n) only:
/// [`Potential::value`] returns +∞ for det X ≤ 0 and integrators always check det X.
///
/// Hessian, from d(det^{1−γ})\[V\] = (1−γ) det(X)^{1−γ} tr(X⁻¹V) and dX⁻ᵀ\[V\] = −X⁻ᵀVᵀX⁻ᵀ:
/// D²U(X)\[V\] = κ det(X)^{1−γ} (X⁻ᵀVᵀX⁻ᵀ − (1−γ) tr(X⁻¹V) X⁻ᵀ) (NaN for det X ≤ 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Volumetric {
    kappa: f64,
    gamma: f64,
}

impl Volumetric {
    /// Polytropic gas with pressure constant κ > 0 and exponent γ ≥ 1 (both finite).
    pub fn polytropic(kappa: f64, gamma: f64) -> Result<Self> {
        check::positive("kappa", kappa)?;
        if !(gamma.is_finite() && gamma >= 1.0) {
            return Err(Error::invalid(
                "gamma",
                format!(
                    "expected a finite polytropic exponent γ ≥ 1, got {}",
                    crate::error::fmt_num(gamma)
                ),
            ));
        }
        Ok(Volumetric { kappa, gamma })
    }
    /// The pressure constant κ.
    pub fn kappa(&self) -> f64 {
        self.kappa
    }
    /// The polytropic exponent γ.
    pub fn gamma(&self) -> f64 {
        self.gamma
    }
}

impl Potential for Volumetric {
    fn value(&self, x: MatRef<'_, f64>, ws: &mut Workspace) -> f64 {
        let d = det(x, ws);
        if d.is_nan() || d <= 0.0 {
            f64::INFINITY
        } else if self.gamma == 1.0 {
            -self.kappa * d.ln()
        } else {
            self.kappa * (d.powf(1.0 - self.gamma) - 1.0) / (self.gamma - 1.0)
        }
    }
    fn add_gradient(&self, x: MatRef<'_, f64>, out: MatMut<'_, f64>, ws: &mut Workspace) {
        let mut cof = std::mem::replace(&mut ws.tmp, Mat::new());
        let d = det_cofactor(x, cof.as_mut(), ws);
        let pressure = if self.gamma == 1.0 {
            self.kappa / d
        } else {
            self.kappa * d.powf(-self.gamma)
        };
        let scale = if d > 0.0 { -pressure } else { f64::NAN };
        axpy(out, scale, cof.as_ref());
        ws.tmp = cof;
    }
    fn add_hessian(
        &self,
        x: MatRef<'_, f64>,
        v: MatRef<'_, f64>,
        mut out: MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        // Over cof X = det(X) X⁻ᵀ: D²U[V] = κ det^{−1−γ} (cof Vᵀ cof − (1−γ)⟨cof, V⟩ cof),
        // since tr(X⁻¹V) = ⟨X⁻ᵀ, V⟩.
        let mut cof = std::mem::replace(&mut ws.tmp, Mat::new());
        let d = det_cofactor(x, cof.as_mut(), ws);
        let c = if d > 0.0 {
            self.kappa * d.powf(-1.0 - self.gamma)
        } else {
            f64::NAN
        };
        mul(
            ws.tmp2.as_mut(),
            Accum::Replace,
            v.transpose(),
            cof.as_ref(),
            1.0,
        );
        mul(out.as_mut(), Accum::Add, cof.as_ref(), ws.tmp2.as_ref(), c);
        axpy(
            out,
            -c * (1.0 - self.gamma) * inner(cof.as_ref(), v),
            cof.as_ref(),
        );
        ws.tmp = cof;
    }
    fn gradient3(&self, x: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        // cof X = (adj X)ᵀ, by cross products of the columns; det X = ⟨x₀, x₁ × x₂⟩.
        let (c0, c1, c2) = (x.column(0), x.column(1), x.column(2));
        let cof = Matrix3::from_columns(&[c1.cross(&c2), c2.cross(&c0), c0.cross(&c1)]);
        let d = c0.dot(&cof.column(0));
        let pressure = if self.gamma == 1.0 {
            self.kappa / d
        } else {
            self.kappa * d.powf(-self.gamma)
        };
        let scale = if d > 0.0 { -pressure } else { f64::NAN };
        Some(cof * scale)
    }
    fn hessian3(&self, x: &Matrix3<f64>, v: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        // κ det^{−1−γ} (cof Vᵀ cof − (1−γ)⟨cof, V⟩ cof), as add_hessian.
        let (c0, c1, c2) = (x.column(0), x.column(1), x.column(2));
        let cof = Matrix3::from_columns(&[c1.cross(&c2), c2.cross(&c0), c0.cross(&c1)]);
        let d = c0.dot(&cof.column(0));
        let c = if d > 0.0 {
            self.kappa * d.powf(-1.0 - self.gamma)
        } else {
            f64::NAN
        };
        Some((cof * v.transpose() * cof) * c - cof * (c * (1.0 - self.gamma) * cof.dot(v)))
    }
    fn parameters(&self) -> Vec<&'static str> {
        vec!["kappa", "gamma"]
    }
    /// ∂U/∂X = −κ det^{−γ} cof X: ∂/∂κ = −det^{−γ} cof X, ∂/∂γ = κ ln(det) det^{−γ} cof X.
    fn add_parameter_gradient(
        &self,
        x: MatRef<'_, f64>,
        m: usize,
        out: MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        let mut cof = std::mem::replace(&mut ws.tmp, Mat::new());
        let d = det_cofactor(x, cof.as_mut(), ws);
        let p = if d > 0.0 {
            d.powf(-self.gamma)
        } else {
            f64::NAN
        };
        let c = if m == 0 { -p } else { self.kappa * d.ln() * p };
        axpy(out, c, cof.as_ref());
        ws.tmp = cof;
    }
    fn needs_positive_det(&self) -> bool {
        true
    }
}

/// Isotropic quadratic stretch energy U = (k/2) Σ_i (σ_i(X) − 1)² over the singular values σ_i
/// of X: zero exactly on the rotations, a function of the singular values only, hence
/// SO(n)×SO(n)-invariant (001 §4.1, U = U(A)).
///
/// Gradient, from the SVD X = R diag(σ) Sᵀ (R, S ∈ O(n); dσ_i\[V\] = (RᵀVS)_ii):
/// ∂U/∂X = R diag(k(σ − 1)) Sᵀ = k(X − RSᵀ). On GL⁺(n) the orthogonal factor RSᵀ is the polar
/// rotation polar(X) = X(XᵀX)^{−1/2}, so ∂U/∂X = k(X − polar X).
///
/// Hessian: the derivative of the polar factor is d(RSᵀ)\[V\] = R Ω Sᵀ with Ω skew solving
/// Ωdiag(σ) + diag(σ)Ω = M − Mᵀ, M = RᵀVS (differentiate X = (RSᵀ)P with P symmetric), i.e.
/// Ω_ij = (M_ij − M_ji)/(σ_i + σ_j); so D²U(X)\[V\] = k(V − R Ω Sᵀ).
///
/// The SVD form is defined for every X (so [`Potential::needs_positive_det`] is false), but U is
/// smooth only where all σ_i > 0 (det X ≠ 0; Σ σ_i, the nuclear norm, has a kink at singular X)
/// and the Hessian formula needs σ_i + σ_j > 0 for i ≠ j. Coincident σ_i are fine (the
/// orthogonal polar factor is unique for invertible X even where the SVD is not). Each
/// evaluation computes a faer SVD, which allocates (the n = 3 gradient uses nalgebra's
/// stack-allocated SVD).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stretch {
    k: f64,
}

impl Stretch {
    /// Stiffness k > 0 (finite).
    pub fn new(k: f64) -> Result<Self> {
        check::positive("k", k)?;
        Ok(Stretch { k })
    }
    /// The stiffness k.
    pub fn k(&self) -> f64 {
        self.k
    }
}

/// The SVD X = R diag(σ) Sᵀ (faer; R, S orthogonal, σ nonnegative and non-increasing), or `None`
/// if it does not converge.
fn svd_of(x: MatRef<'_, f64>) -> Option<(Mat, Vec<f64>, Mat)> {
    let svd = x.svd().ok()?;
    let sigma = svd.S().column_vector().iter().copied().collect();
    Some((svd.U().to_owned(), sigma, svd.V().to_owned()))
}

impl Potential for Stretch {
    fn value(&self, x: MatRef<'_, f64>, _ws: &mut Workspace) -> f64 {
        match x.singular_values() {
            Ok(sigma) => 0.5 * self.k * sigma.iter().map(|s| (s - 1.0) * (s - 1.0)).sum::<f64>(),
            Err(_) => f64::NAN,
        }
    }
    fn add_gradient(&self, x: MatRef<'_, f64>, mut out: MatMut<'_, f64>, ws: &mut Workspace) {
        let Some((r, sigma, s)) = svd_of(x) else {
            out.fill(f64::NAN);
            return;
        };
        // out += R diag(k(σ − 1)) Sᵀ.
        let n = x.nrows();
        for j in 0..n {
            for i in 0..n {
                ws.tmp[(i, j)] = r[(i, j)] * self.k * (sigma[j] - 1.0);
            }
        }
        mul(out, Accum::Add, ws.tmp.as_ref(), s.transpose(), 1.0);
    }
    fn add_hessian(
        &self,
        x: MatRef<'_, f64>,
        v: MatRef<'_, f64>,
        mut out: MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        let Some((r, sigma, s)) = svd_of(x) else {
            out.fill(f64::NAN);
            return;
        };
        // M = RᵀVS in ws.tmp; Ω_ij = (M_ij − M_ji)/(σ_i + σ_j) in ws.tmp2.
        let n = x.nrows();
        mul(ws.tmp2.as_mut(), Accum::Replace, r.transpose(), v, 1.0);
        mul(
            ws.tmp.as_mut(),
            Accum::Replace,
            ws.tmp2.as_ref(),
            s.as_ref(),
            1.0,
        );
        for j in 0..n {
            ws.tmp2[(j, j)] = 0.0;
            for i in 0..j {
                let w = (ws.tmp[(i, j)] - ws.tmp[(j, i)]) / (sigma[i] + sigma[j]);
                ws.tmp2[(i, j)] = w;
                ws.tmp2[(j, i)] = -w;
            }
        }
        // out += k(V − R Ω Sᵀ).
        axpy(out.as_mut(), self.k, v);
        mul(
            ws.tmp.as_mut(),
            Accum::Replace,
            r.as_ref(),
            ws.tmp2.as_ref(),
            1.0,
        );
        mul(out, Accum::Add, ws.tmp.as_ref(), s.transpose(), -self.k);
    }
    fn parameters(&self) -> Vec<&'static str> {
        vec!["k"]
    }
    /// U is linear in k.
    fn add_parameter_gradient(
        &self,
        x: MatRef<'_, f64>,
        _m: usize,
        out: MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        add_gradient_over(self, self.k, x, out, ws);
    }
    fn gradient3(&self, x: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        // The same R diag(k(σ − 1)) Sᵀ with nalgebra's 3×3 SVD (None, i.e. the general kernel,
        // if it does not converge).
        let svd = x.try_svd(true, true, f64::EPSILON, 1000)?;
        let (r, st) = (svd.u?, svd.v_t?);
        let d = svd.singular_values.map(|s| self.k * (s - 1.0));
        Some(r * Matrix3::from_diagonal(&d) * st)
    }
}

/// Sum of potentials U = Σ U_k (e.g. elastic + volumetric).
#[derive(Debug, Default)]
pub struct Sum {
    terms: Vec<Arc<dyn Potential>>,
}

impl Sum {
    /// The sum of `terms` (an empty sum is U = 0).
    pub fn new(terms: Vec<Arc<dyn Potential>>) -> Self {
        Sum { terms }
    }
    /// The terms.
    pub fn terms(&self) -> &[Arc<dyn Potential>] {
        &self.terms
    }
}

impl Potential for Sum {
    fn value(&self, x: MatRef<'_, f64>, ws: &mut Workspace) -> f64 {
        self.terms.iter().map(|t| t.value(x, ws)).sum()
    }
    fn add_gradient(&self, x: MatRef<'_, f64>, mut out: MatMut<'_, f64>, ws: &mut Workspace) {
        for t in &self.terms {
            t.add_gradient(x, out.as_mut(), ws);
        }
    }
    fn add_hessian(
        &self,
        x: MatRef<'_, f64>,
        v: MatRef<'_, f64>,
        mut out: MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        for t in &self.terms {
            t.add_hessian(x, v, out.as_mut(), ws);
        }
    }
    fn gradient3(&self, x: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        let mut g = Matrix3::zeros();
        for t in &self.terms {
            g += t.gradient3(x)?;
        }
        Some(g)
    }
    fn hessian3(&self, x: &Matrix3<f64>, v: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        let mut h = Matrix3::zeros();
        for t in &self.terms {
            h += t.hessian3(x, v)?;
        }
        Some(h)
    }
    /// The terms' constants in the order of the terms (a name repeats where two terms have
    /// it).
    fn parameters(&self) -> Vec<&'static str> {
        self.terms.iter().flat_map(|t| t.parameters()).collect()
    }
    fn add_parameter_gradient(
        &self,
        x: MatRef<'_, f64>,
        m: usize,
        out: MatMut<'_, f64>,
        ws: &mut Workspace,
    ) {
        let mut m = m;
        for t in &self.terms {
            let k = t.parameters().len();
            if m < k {
                return t.add_parameter_gradient(x, m, out, ws);
            }
            m -= k;
        }
    }
    fn needs_positive_det(&self) -> bool {
        self.terms.iter().any(|t| t.needs_positive_det())
    }
    fn calls_out(&self) -> bool {
        self.terms.iter().any(|t| t.calls_out())
    }
    fn dimension(&self) -> Option<usize> {
        let mut dim = None;
        for d in self.terms.iter().filter_map(|t| t.dimension()) {
            match dim {
                None => dim = Some(d),
                Some(e) if e != d => return Some(0),
                _ => {}
            }
        }
        dim
    }
}

/// LU-factors a copy of `x` into `ws.lu` (partial pivoting) and returns det X.
fn lu_det(x: MatRef<'_, f64>, ws: &mut Workspace) -> f64 {
    ws.lu.as_mut().copy_from(x);
    let (info, _) = factor::lu_in_place(
        ws.lu.as_mut(),
        &mut ws.perm_fwd,
        &mut ws.perm_bwd,
        Par::Seq,
        MemStack::new(&mut ws.mem),
        Default::default(),
    );
    let mut d = if info.transposition_count % 2 == 0 {
        1.0
    } else {
        -1.0
    };
    for i in 0..x.nrows() {
        d *= ws.lu[(i, i)];
    }
    d
}

/// det X: closed forms for n ≤ 3, an LU factorization (faer, in `ws`) above.
pub(crate) fn det(x: MatRef<'_, f64>, ws: &mut Workspace) -> f64 {
    match x.nrows() {
        2 => x[(0, 0)] * x[(1, 1)] - x[(0, 1)] * x[(1, 0)],
        3 => {
            x[(0, 0)] * (x[(1, 1)] * x[(2, 2)] - x[(1, 2)] * x[(2, 1)])
                - x[(0, 1)] * (x[(1, 0)] * x[(2, 2)] - x[(1, 2)] * x[(2, 0)])
                + x[(0, 2)] * (x[(1, 0)] * x[(2, 1)] - x[(1, 1)] * x[(2, 0)])
        }
        _ => lu_det(x, ws),
    }
}

/// Writes the cofactor matrix cof X = det(X) X⁻ᵀ (= ∂ det/∂X) into `cof`; returns det X.
/// Closed forms for n ≤ 3; for n > 3 an LU inverse (faer), so X must be invertible there.
pub(crate) fn det_cofactor(
    x: MatRef<'_, f64>,
    mut cof: MatMut<'_, f64>,
    ws: &mut Workspace,
) -> f64 {
    let n = x.nrows();
    match n {
        2 => {
            cof[(0, 0)] = x[(1, 1)];
            cof[(0, 1)] = -x[(1, 0)];
            cof[(1, 0)] = -x[(0, 1)];
            cof[(1, 1)] = x[(0, 0)];
            det(x, ws)
        }
        3 => {
            // Column i of cof X is (column i+1 of X) × (column i+2 of X).
            for i in 0..3 {
                let (a, b) = ((i + 1) % 3, (i + 2) % 3);
                for r in 0..3 {
                    let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
                    cof[(r, i)] = x[(r1, a)] * x[(r2, b)] - x[(r2, a)] * x[(r1, b)];
                }
            }
            det(x, ws)
        }
        _ => {
            let d = lu_det(x, ws);
            let perm = faer::perm::PermRef::new_checked(&ws.perm_fwd, &ws.perm_bwd, n);
            // `inverse` reads the unit lower triangle of its L argument and the upper triangle
            // of its U argument, so the packed factor serves as both.
            inverse::inverse(
                cof.as_mut(),
                ws.lu.as_ref(),
                ws.lu.as_ref(),
                perm,
                Par::Seq,
                MemStack::new(&mut ws.mem),
            );
            // cof = d · (X⁻¹)ᵀ: transpose in place.
            for j in 0..n {
                cof[(j, j)] *= d;
                for i in j + 1..n {
                    let (a, b) = (cof[(i, j)], cof[(j, i)]);
                    cof[(i, j)] = d * b;
                    cof[(j, i)] = d * a;
                }
            }
            d
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(n: usize) -> Mat {
        Mat::from_fn(n, n, |i, j| {
            (if i == j { 1.5 } else { 0.0 }) + 0.3 * ((i * 7 + j * 3) as f64).sin()
        })
    }

    #[test]
    fn det_and_cofactor_match_lu_for_every_size() {
        for n in 2..=7 {
            // A row-reversed matrix forces pivoting in the LU.
            let s = sample(n);
            let x = Mat::from_fn(n, n, |i, j| s[(n - 1 - i, j)]);
            let mut ws = Workspace::new(n);
            let d_ref = x.as_ref().determinant();
            let mut cof = Mat::zeros(n, n);
            let d = det_cofactor(x.as_ref(), cof.as_mut(), &mut ws);
            assert!((d - d_ref).abs() < 1e-12 * d_ref.abs().max(1.0), "n={n}");
            assert!((det(x.as_ref(), &mut ws) - d_ref).abs() < 1e-12 * d_ref.abs().max(1.0));
            // Xᵀ cof X = det(X) I.
            let prod = x.transpose() * &cof;
            let err = (&prod - Mat::identity(n, n) * faer::Scale(d)).norm_l2();
            assert!(err < 1e-12 * d.abs().max(1.0), "n={n}: {err}");
        }
    }

    #[test]
    fn small_and_faer_products_agree() {
        for n in 2..=6 {
            let a = sample(n);
            let b = sample(n).transpose().to_owned();
            let mut c = Mat::zeros(n, n);
            mul(c.as_mut(), Accum::Replace, a.transpose(), b.as_ref(), 2.0);
            mul(c.as_mut(), Accum::Add, a.as_ref(), b.as_ref(), -1.0);
            let r = (a.transpose() * &b) * faer::Scale(2.0) - &a * &b;
            assert!((&c - &r).norm_l2() < 1e-13);
        }
    }
}
