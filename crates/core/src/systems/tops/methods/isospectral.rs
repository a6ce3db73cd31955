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
//!
//! **Tangent map** (issue 26; `isospectral` on the tangent lifts of both bodies, the rigid body
//! with and without the attitude). With a = h/2, W = L(M) the linear map M_ij ↦ M_ij/d_ij,
//! the step is G(M̃) = M_n, M_{n+1} = H(M̃) with G, H(M̃) = M̃ ± a[W̃, M̃] − a² W̃M̃W̃. For a
//! direction X = δM̃ and δW = LX + δL M̃ (δL = ∂(1/d_ij)/∂θ along a parameter, else 0), let
//! S₁ = [δW, M̃] + [W̃, X] and S₂ = δW M̃W̃ + W̃XW̃ + W̃M̃ δW (both skew); then δG = X + aS₁ − a²S₂
//! and δH = X − aS₁ − a²S₂. By the implicit-function theorem X solves
//!
//! DG(M̃)X = δM_n − (aS₁ − a²S₂)|_{X=0, δL}   (the inhomogeneous term only along a parameter),
//!
//! with DG(M̃) formed in the e_ij coordinates (column c from X = E_c, δW = E_c/d_c) and factored
//! once per step for all the directions (`DenseLu`), and
//! δM_{n+1} = δH. With the attitude R_{n+1} = R_n cay(v), v = h ω̃ (ω̃ the vector of W̃), the
//! left-trivialised direction is ξ_{n+1} = cay(v)ᵀ ξ_n + (δv − v × δv/2)/(1 + |v|²/4), δv = h δω
//! (the derivative of the Cayley map, as for the LGVI). The base state is advanced by the plain
//! step itself (the same bits); the fixed-point iteration converges to round-off (the rule of
//! [`crate::convergence`]), so the implicit-function theorem at its M̃ is the derivative of the
//! computed map to round-off. Cost per step: O(n⁵) for DG (N = n(n−1)/2 columns of O(n³)),
//! O(N³) for its factorisation, O(n³) per direction.

use super::super::top;
use crate::convergence::{self, Failed, Monitor, Rule, Verdict};
use crate::error::Result;
use crate::integrate::tangent::Tangent;
use crate::integrate::{Clock, Integrator, Properties, Stepper};
use crate::lie::so3;
use crate::numerics::linalg::DenseLu;
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
    /// The tangent map's parameter tables and work space (module docs; built by
    /// [`IsospectralMidpoint::with_parameters`]).
    tangent: Option<Box<TangentWork>>,
}

/// The work space of [`IsospectralMidpoint::tangent`]: the tables ∂(1/d_ij)/∂θ_m (n×n), the
/// factored DG(M̃) (N×N), dense n×n scratch and the e_ij coordinates of S₁, S₂.
struct TangentWork {
    dinv: Vec<Vec<f64>>,
    lu: DenseLu,
    x: Vec<f64>,
    dw: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    d: Vec<f64>,
    s1: Vec<f64>,
    s2: Vec<f64>,
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
            tangent: None,
        }
    }

    /// The same stepper with its tangent map ([`IsospectralMidpoint::tangent`]), along the
    /// parameters whose tables ∂(1/d_ij)/∂θ_m (n×n, row-major) are `dinv`.
    pub(crate) fn with_parameters(mut self, dinv: Vec<Vec<f64>>) -> Self {
        let (n, big) = (self.n, self.n * (self.n - 1) / 2);
        self.tangent = Some(Box::new(TangentWork {
            dinv,
            lu: DenseLu::new(big),
            x: vec![0.0; n * n],
            dw: vec![0.0; n * n],
            a: vec![0.0; n * n],
            b: vec![0.0; n * n],
            c: vec![0.0; n * n],
            d: vec![0.0; n * n],
            s1: vec![0.0; big],
            s2: vec![0.0; big],
        }));
        self
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

impl IsospectralMidpoint {
    /// The tangent map of the last [`IsospectralMidpoint::step`] (module docs, "Tangent map";
    /// needs [`IsospectralMidpoint::with_parameters`]): `dirs` holds k directions δM_n one after
    /// another, each in the N = n(n−1)/2 e_ij coordinates (the upper triangle row by row), the
    /// last `dinv.len()` along the parameters, and gets δM_{n+1}; `dw`, if given (same layout),
    /// gets δW̃ = δΩ̃ of each. NaN where DG(M̃) is singular.
    pub(crate) fn tangent(&mut self, dirs: &mut [f64], mut dw: Option<&mut [f64]>) {
        let Some(mut t) = self.tangent.take() else {
            dirs.fill(f64::NAN);
            return;
        };
        let (n, big) = (self.n, self.n * (self.n - 1) / 2);
        let (a, a2) = (0.5 * self.h, 0.25 * self.h * self.h);
        let k = dirs.len() / big;
        let first_param = k - t.dinv.len();
        // DG(M̃) column by column: X = E_c, δW = E_c/d_c.
        let mut col = 0;
        for i in 0..n {
            for j in i + 1..n {
                t.x.fill(0.0);
                t.x[i * n + j] = 1.0;
                t.x[j * n + i] = -1.0;
                let inv = self.inv_d[i * n + j];
                for (dw, x) in t.dw.iter_mut().zip(&t.x) {
                    *dw = x * inv;
                }
                self.variation(&mut t);
                for r in 0..big {
                    let unit = if r == col { 1.0 } else { 0.0 };
                    t.lu.matrix()[(r, col)] = unit + a * t.s1[r] - a2 * t.s2[r];
                }
                col += 1;
            }
        }
        if !t.lu.factor() {
            dirs.fill(f64::NAN);
            self.tangent = Some(t);
            return;
        }
        // The right-hand sides: δM_n, less the inhomogeneous term along a parameter.
        for (m, rhs) in dirs.chunks_exact_mut(big).skip(first_param).enumerate() {
            t.x.fill(0.0);
            self.parameter_part(&mut t, m);
            self.variation(&mut t);
            for ((y, s1), s2) in rhs.iter_mut().zip(&t.s1).zip(&t.s2) {
                *y -= a * s1 - a2 * s2;
            }
        }
        // At most N columns at a time (the factor's scratch is sized for N).
        for block in dirs.chunks_mut(big * big) {
            let cols = block.len() / big;
            t.lu.solve_columns(faer::MatMut::from_column_major_slice_mut(block, big, cols));
        }
        // δM_{n+1} = δH from X = δM̃.
        for (l, xc) in dirs.chunks_exact_mut(big).enumerate() {
            upper_to_dense(n, xc, &mut t.x);
            match l.checked_sub(first_param) {
                Some(m) => self.parameter_part(&mut t, m),
                None => t.dw.fill(0.0),
            }
            for ((dw, x), inv) in t.dw.iter_mut().zip(&t.x).zip(&self.inv_d) {
                *dw += x * inv;
            }
            self.variation(&mut t);
            for ((y, s1), s2) in xc.iter_mut().zip(&t.s1).zip(&t.s2) {
                *y += -a * s1 - a2 * s2;
            }
            if let Some(out) = dw.as_deref_mut() {
                dense_to_upper(n, &t.dw, &mut out[l * big..(l + 1) * big]);
            }
        }
        self.tangent = Some(t);
    }

    /// t.dw ← δL M̃ along parameter m.
    fn parameter_part(&self, t: &mut TangentWork, m: usize) {
        for ((dw, x), dl) in t.dw.iter_mut().zip(&self.mt).zip(&t.dinv[m]) {
            *dw = x * dl;
        }
    }

    /// S₁ = [δW, M̃] + [W̃, X] and S₂ = δW M̃W̃ + W̃XW̃ + W̃M̃ δW (e_ij coordinates) for X = t.x and
    /// δW = t.dw (dense, skew), after a step (M̃, W̃ in place): with A = δW M̃, B = W̃X,
    /// [δW, M̃] = A − Aᵀ, [W̃, X] = B − Bᵀ, W̃XW̃ = BW̃, δW M̃W̃ + W̃M̃ δW = AW̃ − (AW̃)ᵀ.
    fn variation(&self, t: &mut TangentWork) {
        let n = self.n;
        matmul(n, &t.dw, &self.mt, &mut t.a);
        matmul(n, &self.w, &t.x, &mut t.b);
        matmul(n, &t.b, &self.w, &mut t.c);
        matmul(n, &t.a, &self.w, &mut t.d);
        let mut r = 0;
        for i in 0..n {
            for j in i + 1..n {
                let (ij, ji) = (i * n + j, j * n + i);
                t.s1[r] = (t.a[ij] - t.a[ji]) + (t.b[ij] - t.b[ji]);
                t.s2[r] = t.c[ij] + (t.d[ij] - t.d[ji]);
                r += 1;
            }
        }
    }
}

/// The skew n×n matrix (row-major) of e_ij coordinates (the upper triangle row by row).
fn upper_to_dense(n: usize, u: &[f64], m: &mut [f64]) {
    let mut r = 0;
    for i in 0..n {
        m[i * n + i] = 0.0;
        for j in i + 1..n {
            m[i * n + j] = u[r];
            m[j * n + i] = -u[r];
            r += 1;
        }
    }
}

/// The e_ij coordinates of a skew n×n matrix.
fn dense_to_upper(n: usize, m: &[f64], u: &mut [f64]) {
    let mut r = 0;
    for i in 0..n {
        for j in i + 1..n {
            u[r] = m[i * n + j];
            r += 1;
        }
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
        Ok(Box::new(So3Stepper::new(body, dt, None)))
    }
}

/// The isospectral midpoint on the tangent lift of the rigid body, with or without the
/// attitude (module docs, "Tangent map"); parameters I1, I2, I3.
impl Integrator<Tangent<RigidBody>> for Isospectral {
    fn properties(&self) -> Properties {
        Properties::geometric(2)
    }

    fn stepper(&self, lift: &Tangent<RigidBody>, dt: f64) -> Result<Box<dyn Stepper>> {
        let body = lift.problem();
        let dirs = So3Lift {
            dirs: Vec::new(),
            upper: Vec::new(),
            dw: Vec::new(),
        };
        Ok(Box::new(So3Stepper::new(body, dt, Some(dirs))))
    }
}

struct So3Stepper {
    kernel: IsospectralMidpoint,
    h: f64,
    mat: [f64; 9],
    r: Option<Matrix3<f64>>,
    lifted: bool,
    lift: Option<So3Lift>,
}

/// The directions of a tangent lift, (δM, [ξ]) one after another (principal frame), and their
/// δM and δΩ̃ in e_ij coordinates for the kernel.
struct So3Lift {
    dirs: Vec<f64>,
    upper: Vec<f64>,
    dw: Vec<f64>,
}

/// The e_ij coordinates of hat(v): (−v₃, v₂, −v₁) (an involution up to sign: its own inverse
/// is u ↦ (−u₃, u₂, −u₁)).
fn so3_upper(v: &[f64]) -> [f64; 3] {
    [-v[2], v[1], -v[0]]
}

impl So3Stepper {
    fn new(body: &RigidBody, dt: f64, lift: Option<So3Lift>) -> Self {
        let [i1, i2, i3] = body.top.moments;
        let d = [0.0, i3, i2, i3, 0.0, i1, i2, i1, 0.0];
        let mut kernel = IsospectralMidpoint::new(3, &d, dt);
        if lift.is_some() {
            // ∂(1/d_ij)/∂I_q = −1/I_q² where d_ij = I_q.
            let at = [[5, 7], [2, 6], [1, 3]];
            let dinv = (0..3)
                .map(|q| {
                    let mut t = vec![0.0; 9];
                    for k in at[q] {
                        t[k] = -1.0 / (d[k] * d[k]);
                    }
                    t
                })
                .collect();
            kernel = kernel.with_parameters(dinv);
        }
        So3Stepper {
            kernel,
            h: dt,
            mat: [0.0; 9],
            r: None,
            lifted: body.top.lifted,
            lift,
        }
    }

    /// The values of the base state and of a direction.
    fn dims(&self) -> (usize, usize) {
        match self.lifted {
            true => (12, 6),
            false => (3, 3),
        }
    }

    /// The tangent map of the last step on every direction (module docs, "Tangent map").
    fn tangent(&mut self, lift: &mut So3Lift) {
        let e = self.dims().1;
        for (dz, u) in lift
            .dirs
            .chunks_exact(e)
            .zip(lift.upper.chunks_exact_mut(3))
        {
            u.copy_from_slice(&so3_upper(&dz[..3]));
        }
        self.kernel.tangent(&mut lift.upper, Some(&mut lift.dw));
        let w = self.kernel.omega();
        let v = Vector3::new(w[7], w[2], w[3]) * self.h;
        let back = so3::Rodrigues::cayley(&-v);
        let s = 1.0 + 0.25 * v.norm_squared();
        let dirs = lift.dirs.chunks_exact_mut(e);
        for ((dz, u), dw) in dirs
            .zip(lift.upper.chunks_exact(3))
            .zip(lift.dw.chunks_exact(3))
        {
            dz[..3].copy_from_slice(&so3_upper(u));
            if self.lifted {
                let dv = Vector3::from(so3_upper(dw)) * self.h;
                let mut xi = Vector3::from_column_slice(&dz[3..6]);
                back.apply(&mut xi);
                xi += (dv - v.cross(&dv) * 0.5) / s;
                dz[3..6].copy_from_slice(xi.as_slice());
            }
        }
    }
}

impl Stepper for So3Stepper {
    /// The base state, and on a lift its directions after it.
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.mat = top::row_major(&so3::hat(&Vector3::from_column_slice(&z[..3])));
        self.r = self.lifted.then(|| Matrix3::from_row_slice(&z[3..12]));
        let (d, e) = self.dims();
        if let Some(lift) = self.lift.as_mut() {
            let k = (z.len() - d) / e;
            lift.dirs.clear();
            lift.dirs.extend_from_slice(&z[d..]);
            lift.upper.resize(3 * k, 0.0);
            lift.dw.resize(3 * k, 0.0);
        }
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        let m = &self.mat;
        z[..3].copy_from_slice(&[m[7], m[2], m[3]]);
        if let Some(r) = &self.r {
            z[3..12].copy_from_slice(&top::row_major(r));
        }
        if let Some(lift) = &self.lift {
            let d = self.dims().0;
            if z.len() == d + lift.dirs.len() {
                z[d..].copy_from_slice(&lift.dirs);
            }
        }
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        for k in 0..steps {
            self.kernel
                .step(&mut self.mat)
                .map_err(|e| failed(&clock, k, e))?;
            if let Some(mut lift) = self.lift.take() {
                self.tangent(&mut lift);
                self.lift = Some(lift);
            }
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
        Ok(Box::new(SonStepper::new(body, dt, None)))
    }
}

/// The isospectral midpoint on the tangent lift of the generalized rigid body (module docs,
/// "Tangent map"; no parameters): the directions are e_ij coordinates, the kernel's own.
impl Integrator<Tangent<GeneralizedRigidBody>> for Isospectral {
    fn properties(&self) -> Properties {
        Properties::geometric(2)
    }

    fn stepper(&self, lift: &Tangent<GeneralizedRigidBody>, dt: f64) -> Result<Box<dyn Stepper>> {
        Ok(Box::new(SonStepper::new(
            lift.problem(),
            dt,
            Some(Vec::new()),
        )))
    }
}

struct SonStepper {
    kernel: IsospectralMidpoint,
    body: GeneralizedRigidBody,
    mat: Vec<f64>,
    /// A lift's directions (after the state in the lifted state).
    dirs: Option<Vec<f64>>,
}

impl SonStepper {
    fn new(body: &GeneralizedRigidBody, dt: f64, dirs: Option<Vec<f64>>) -> Self {
        let n = body.n();
        let mut kernel = IsospectralMidpoint::new(n, body.denominators(), dt);
        if dirs.is_some() {
            kernel = kernel.with_parameters(Vec::new());
        }
        SonStepper {
            kernel,
            body: body.clone(),
            mat: vec![0.0; n * n],
            dirs,
        }
    }
}

impl Stepper for SonStepper {
    fn set(&mut self, z: &[f64]) -> Result<()> {
        self.body.dense(z, &mut self.mat);
        let n = self.body.n();
        if let Some(dirs) = self.dirs.as_mut() {
            dirs.clear();
            dirs.extend_from_slice(&z[n * (n - 1) / 2..]);
        }
        Ok(())
    }

    fn get(&self, z: &mut [f64]) {
        self.body.coords(&self.mat, z);
        let n = self.body.n();
        if let Some(dirs) = &self.dirs {
            let d = n * (n - 1) / 2;
            if z.len() == d + dirs.len() {
                z[d..].copy_from_slice(dirs);
            }
        }
    }

    fn advance(&mut self, steps: usize, clock: Clock) -> Result<()> {
        for k in 0..steps {
            self.kernel
                .step(&mut self.mat)
                .map_err(|e| failed(&clock, k, e))?;
            if let Some(dirs) = self.dirs.as_mut() {
                self.kernel.tangent(dirs, None);
            }
        }
        Ok(())
    }
}
