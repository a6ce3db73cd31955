//! The pseudo-rigid body reduced by its right SO(n) symmetry, the relabelling of its particles
//! (001 §3): a system of its own on T*GL⁺(n)/SO(n), in the Riemann variables Q = XXᵀ, N = XPᵀ.
//!
//! # The reduced space (derived again)
//! H = ½ tr(PᵀP) + U(X) with U right-invariant (every built-in potential is SO(n)×SO(n)
//! invariant; a callable one is checked) is invariant under (X, P) ↦ (Xh⁻¹, Ph⁻¹), whose momentum
//! map is the circulation Γ = PᵀX − XᵀP (001 (3.23)). Q = XXᵀ (symmetric positive definite) and
//! N = XPᵀ are invariant and are coordinates of the quotient: P = NᵀX⁻ᵀ, so PPᵀ = NᵀQ⁻¹N and
//! H = ½ tr(NᵀQ⁻¹N) + U(C) for any C with CCᵀ = Q (here the Cholesky factor, C = X h for some
//! h ∈ SO(n)). With the unit metric of 001 (2.9), P = Ẋ and N is the shear tensor XẊᵀ; the
//! motion is the Riemann system 001 (3.20) and its Poisson structure is 001 (9.1).
//!
//! The angular momentum L = PXᵀ − XPᵀ = Nᵀ − N is a function on the quotient. The circulation is
//! not (it turns under h, 001 (2.31b)), but at the representative C it is
//! Γ_C = C⁻¹NC − CᵀNᵀC⁻ᵀ, conjugate to Γ of every X over (Q, N): the spectral invariants of Γ_C
//! are the Casimirs whose level sets are the reduced spaces Γ⁻¹(γ)/G_γ of 001 (3.27).
//!
//! # The reduced Hamiltonian (3.31)
//! On Γ⁻¹(γ), P = Y + X((A^R_X)⁻¹γ)ᵀ with Y horizontal for the right connection (3.24), and
//! H = ½⟨Y, Y⟩ + ½⟨γ, (A^R_X)⁻¹γ⟩ + U ((3.30)–(3.31); the middle term is the locked rotational
//! energy of the relabelling, ½‖X((A^R_X)⁻¹γ)ᵀ‖²). Each term is right-invariant:
//! [`RightReduced::hamiltonian_parts`] evaluates them at the representative C.
//!
//! # The method
//! The Störmer–Verlet step of the full body commutes with the right action, so it descends to the
//! quotient. Its kick and drift are the exact flows of U and of the kinetic energy K there:
//! - U: N ← N − τ C(∂U/∂X(C))ᵀ (X(∂U/∂X)ᵀ is the same at every X over Q, by invariance);
//! - K: P is constant, so Q ← Q + τ(N + Nᵀ) + τ²K and N ← N + τK with K = PPᵀ = WᵀW, W = C⁻¹N.
//!
//! Their compositions (`verlet`, `verlet4`, `verlet6`) are reductions of symplectic maps, hence
//! Poisson maps of the reduced space: they keep the Casimirs of Γ_C and (the potential being
//! left-invariant too) those of L to round-off, and the energy error bounded. `rk4` integrates
//! the Riemann field (3.20) as a baseline.
//!
//! # Reconstruction
//! [`RightReduced::reconstructing`] carries X along: a drift moves it by X ← X + τP,
//! P = NᵀX⁻ᵀ = NᵀQ⁻¹X, i.e. by the left factor I + τWᵀC⁻¹ computed from the reduced data alone;
//! a kick leaves it. The reconstructed (X, NᵀX⁻ᵀ) is the full Verlet motion of the same steps,
//! and its circulation stays the initial one ([`RightReduced::reconstruct`]).
//!
//! # Tangent lift
//! The Jacobians of `verlet`, `verlet4`, `verlet6` and `rk4` (issue 26,
//! [`crate::integrate::tangent`]) come from the tangent maps of the kick and the drift and the
//! derivative of the field, built from the derivative of the Cholesky factor,
//! δC = CΦ with Φ = the lower triangle of C⁻¹δQC⁻ᵀ, diagonal halved (δQ read from its lower
//! triangle, as the factorisation reads Q), and the potential's Hessian D²U(C)\[δC\]; X
//! (reconstruction) included; the parameters are the potential's constants. Directions are
//! ambient (Q need not stay symmetric along them).
//!
//! # The reduced Euler–Lagrange equation (3.17)
//! [`euler_lagrange`] is the reduced field of any right-invariant Lagrangian 𝓛(Q, N):
//! d/dt(∂𝓛/∂N)ᵀ = (∂𝓛/∂N − (∂𝓛/∂N)ᵀ)NᵀQ⁻¹ + 2∂𝓛/∂Q, with Q̇ = N + Nᵀ; for 𝓛 = ½tr(NᵀQ⁻¹N) − U
//! it is (3.20) (checked: with ∂K/∂N = Q⁻¹N, ∂K/∂Q = −½Q⁻¹NNᵀQ⁻¹ the equation reduces to
//! Ṅ = NᵀQ⁻¹N − 2Q∂U/∂Q). ∂𝓛/∂Q is the gradient over symmetric matrices (the variations
//! δQ = ζQ + Qζᵀ of (3.13) are symmetric).

use std::sync::Arc;

use super::connection::{self, Action};
use super::dynamics::FullBody;
use super::inertia::BiInertia;
use super::potential::{Potential, Workspace};
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::{Composition, Rk4, Splitting};
use crate::integrate::problem::{Split, VectorField, Violation};
use crate::integrate::space::{Block, Space};
use crate::integrate::tangent::{SplitTangent, Tangent, TangentSystem, VectorFieldTangent};
use crate::integrate::{Catalog, Entry, Problem};
use crate::lie::so::{spectral_invariants, spectral_names};
use crate::numerics::linalg;
use crate::Mat;
use faer::linalg::solvers::Solve;
use faer::{Accum, MatMut, MatRef};

/// Relative tolerance of a state's Q (symmetric: ‖Q − Qᵀ‖_F ≤ tol ‖Q‖_F) and, when
/// reconstructing, of its X over Q (‖XXᵀ − Q‖_F ≤ tol ‖Q‖_F).
pub const STATE_TOL: f64 = 1e-10;

/// Relative tolerance of the check that U is right SO(n)-invariant (U(Ch) against U(C) at a
/// state's representative and a fixed rotation h).
pub const INVARIANCE_TOL: f64 = 1e-8;

/// The pseudo-rigid body H = ½ tr(PᵀP) + U(X) reduced by the right SO(n) action (module docs):
/// state z = (Q, N) row-major (2n² values, Q symmetric positive definite), or (Q, N, X) when it
/// reconstructs.
#[derive(Debug, Clone)]
pub struct RightReduced {
    body: FullBody,
    reconstruct: bool,
}

impl RightReduced {
    /// The reduced body in n ≥ 2 dimensions with a right-invariant potential U.
    pub fn new(n: usize, potential: Arc<dyn Potential>) -> Result<Self> {
        check::dense_size("n", 3 * n.min(usize::MAX / 3), n)?;
        Ok(RightReduced {
            body: FullBody::new(n, potential)?,
            reconstruct: false,
        })
    }

    /// The same system carrying the configuration X (reconstruction; state (Q, N, X)).
    pub fn reconstructing(mut self) -> Self {
        self.reconstruct = true;
        self
    }

    /// Whether X is carried along (state (Q, N, X)).
    pub fn is_reconstructing(&self) -> bool {
        self.reconstruct
    }

    /// The dimension n.
    pub fn n(&self) -> usize {
        self.body.n()
    }

    /// The underlying full body (its potential, its Riemann field).
    pub fn full(&self) -> &FullBody {
        &self.body
    }

    fn blocks(&self) -> usize {
        2 + usize::from(self.reconstruct)
    }

    /// The reduced state of (X, P): (Q, N) = (XXᵀ, XPᵀ), then X when reconstructing (checked:
    /// n×n, finite, det X > 0).
    pub fn reduce(&self, x: &Mat, p: &Mat) -> Result<Vec<f64>> {
        let n = self.n();
        check::square_of("X", x, n)?;
        check::square_of("P", p, n)?;
        check::finite_mat("X", x)?;
        check::finite_mat("P", p)?;
        let (q, nn) = super::riemann::riemann_variables(x, p)?;
        let mut z = vec![0.0; self.blocks() * n * n];
        write(&q, &mut z[..n * n]);
        write(&nn, &mut z[n * n..2 * n * n]);
        if self.reconstruct {
            write(x, &mut z[2 * n * n..]);
        }
        Ok(z)
    }

    /// (Q, N) of a flat state (checked length).
    pub fn split(&self, z: &[f64]) -> Result<(Mat, Mat)> {
        let n = self.n();
        check::len_of("state", z, self.blocks() * n * n)?;
        Ok((read(n, &z[..n * n]), read(n, &z[n * n..2 * n * n])))
    }

    /// The reconstructed full state (X, P), P = NᵀX⁻ᵀ, of a state of the reconstructing system.
    pub fn reconstruct(&self, z: &[f64]) -> Result<(Mat, Mat)> {
        let n = self.n();
        if !self.reconstruct {
            return Err(Error::invalid(
                "state",
                "this RightReduced system does not carry X: build it with reconstruct = true \
                 (state (Q, N, X)) to reconstruct the full motion",
            ));
        }
        let (_, nn) = self.split(z)?;
        check::finite_slice("state", z)?;
        let x = read(n, &z[2 * n * n..]);
        // Pᵀ = X⁻¹N.
        let pt = x.partial_piv_lu().solve(&nn);
        check::finite_mat("P", &pt).map_err(|_| check::overflow_error("P", "P = NᵀX⁻ᵀ"))?;
        Ok((x, pt.transpose().to_owned()))
    }

    /// (C, P_C) with CCᵀ = Q and P_C = NᵀC⁻ᵀ: the representative of the state's orbit the
    /// reduced quantities are evaluated at.
    fn representative_state(&self, z: &[f64]) -> Result<(Mat, Mat)> {
        let (q, nn) = self.split(z)?;
        check::finite_slice("state", z)?;
        let c = cholesky_of(&q)?;
        let mut w = nn;
        linalg::solve_lower(c.as_ref(), w.as_mut());
        Ok((c, w.transpose().to_owned()))
    }

    /// H = ½ tr(NᵀQ⁻¹N) + U(C) (001 (3.22) on the quotient).
    pub fn hamiltonian(&self, z: &[f64]) -> Result<f64> {
        let (c, p) = self.representative_state(z)?;
        self.body.hamiltonian(&c, &p)
    }

    /// The three terms of the reduced Hamiltonian 001 (3.31) at the state's circulation γ:
    /// [½⟨Y, Y⟩ (horizontal kinetic energy, the kinetic energy on T*(GL⁺(n)/SO(n))),
    /// ½⟨γ, (A^R_X)⁻¹γ⟩ (the locked energy of the relabelling), U]; their sum is H.
    pub fn hamiltonian_parts(&self, z: &[f64]) -> Result<[f64; 3]> {
        let (c, p) = self.representative_state(z)?;
        let b = BiInertia::new(&c)?;
        let vertical = connection::vertical_part(&b, &p, Action::Right)?;
        let horizontal = &p - &vertical;
        let u = self
            .body
            .potential()
            .value(c.as_ref(), &mut self.body.workspace());
        Ok([
            0.5 * linalg::frob2(horizontal.as_ref()),
            0.5 * linalg::frob2(vertical.as_ref()),
            u,
        ])
    }

    /// The angular momentum L = Nᵀ − N (001 (2.29), (3.10)): a function on the quotient.
    pub fn angular_momentum(&self, z: &[f64]) -> Result<Mat> {
        let (_, nn) = self.split(z)?;
        check::finite_slice("state", z)?;
        Ok(nn.transpose() - &nn)
    }

    /// The circulation at the representative C (CCᵀ = Q): Γ_C = C⁻¹NC − CᵀNᵀC⁻ᵀ, conjugate to the
    /// circulation of every X over (Q, N) (module docs).
    pub fn circulation(&self, z: &[f64]) -> Result<Mat> {
        let (c, p) = self.representative_state(z)?;
        Ok(super::momentum::momentum_map(&c, &p)?.1)
    }

    /// Whether U is right-invariant at C: |U(Ch) − U(C)| ≤ [`INVARIANCE_TOL`](1 + |U(C)|) for a
    /// fixed rotation h (a potential given by a callable need not be).
    fn check_invariance(&self, c: &Mat) -> Result<()> {
        let n = self.n();
        let pot = self.body.potential();
        let mut ws = self.body.workspace();
        // h: the rotation by 0.7 rad in every coordinate plane (i, i+1), composed.
        let mut h = Mat::identity(n, n);
        let (s, co) = 0.7f64.sin_cos();
        for i in 0..n - 1 {
            let mut g = Mat::identity(n, n);
            g[(i, i)] = co;
            g[(i + 1, i + 1)] = co;
            g[(i, i + 1)] = -s;
            g[(i + 1, i)] = s;
            h = &h * &g;
        }
        let (u0, u1) = (
            pot.value(c.as_ref(), &mut ws),
            pot.value((c * &h).as_ref(), &mut ws),
        );
        let defect = (u1 - u0).abs() / (1.0 + u0.abs());
        if defect.is_nan() || defect > INVARIANCE_TOL {
            return Err(Error::invalid(
                "potential",
                format!(
                    "the right reduction needs U(Xh) = U(X) for every rotation h (001 §3: U a \
                     function of Q = XXᵀ); this potential changes by |U(Xh) − U(X)|/(1 + |U|) = \
                     {defect:.3e} under a rotation of the labels (tolerance \
                     {INVARIANCE_TOL:.0e}): integrate the full PseudoRigidBody instead"
                ),
            ));
        }
        Ok(())
    }
}

/// (Q, N) ↦ (∂𝓛/∂Q, ∂𝓛/∂N) of a Lagrangian 𝓛(Q, N), or the caller's error.
pub type LagrangianGradient<'a, E> =
    dyn FnMut(&Mat, &Mat) -> std::result::Result<(Mat, Mat), E> + 'a;

/// The reduced field of a right-invariant Lagrangian 𝓛(Q, N) (001 (3.17), module docs): returns
/// (Q̇, Ṅ). `gradient(Q, N)` gives (∂𝓛/∂Q over symmetric matrices, ∂𝓛/∂N); D_N(∂𝓛/∂N) and
/// D_Q(∂𝓛/∂N)[Q̇] are its central differences with steps h·max(1, max|entry|): h = ε^{1/3} for
/// a gradient exact to round-off (relative error ≈ 1e-10 for a smooth 𝓛), h = ε^{2/9} when
/// `gradient_is_difference` (a gradient that is itself [`lagrangian_gradient`], whose error
/// ε^{2/3} the outer difference divides by h: ≈ 1e-7), and Ṅ solves
/// D_N(∂𝓛/∂N)\[Ṅ\] = ((∂𝓛/∂N − (∂𝓛/∂N)ᵀ)NᵀQ⁻¹ + 2∂𝓛/∂Q)ᵀ − D_Q(∂𝓛/∂N)\[Q̇\] (an error when the
/// Hessian of 𝓛 in N is singular: 𝓛 is then not regular). Errors of `gradient` are returned.
pub fn euler_lagrange<E: From<Error>>(
    gradient: &mut LagrangianGradient<'_, E>,
    q: &Mat,
    nn: &Mat,
    gradient_is_difference: bool,
) -> std::result::Result<(Mat, Mat), E> {
    let step = match gradient_is_difference {
        false => f64::EPSILON.cbrt(),
        true => f64::EPSILON.powf(2.0 / 9.0),
    };
    let n = check::square("Q", q, 1)?;
    check::square_of("N", nn, n)?;
    check::finite_mat("Q", q)?;
    check::finite_mat("N", nn)?;
    let c = cholesky_of(q)?;
    let q_dot = nn + nn.transpose();
    let (gq, gn) = gradient(q, nn)?;
    check::square_of("∂L/∂Q", &gq, n)?;
    check::square_of("∂L/∂N", &gn, n)?;
    let gq = (&gq + gq.transpose()) * faer::Scale(0.5);
    // NᵀQ⁻¹ = (Q⁻¹N)ᵀ, Q⁻¹N = C⁻ᵀC⁻¹N.
    let mut w = nn.clone();
    linalg::solve_lower(c.as_ref(), w.as_mut());
    let q_inv_n = c.transpose().partial_piv_lu().solve(&w);
    let rhs = (&gn - gn.transpose()) * q_inv_n.transpose() + &gq * faer::Scale(2.0);
    let hq = step * check::max_abs(q).max(1.0) / check::max_abs(&q_dot).max(1e-300);
    let hn = step * check::max_abs(nn).max(1.0);
    let mut diff = |dq: &Mat, dn: &Mat, h: f64| -> std::result::Result<Mat, E> {
        let (_, plus) = gradient(&(q + dq * faer::Scale(h)), &(nn + dn * faer::Scale(h)))?;
        let (_, minus) = gradient(&(q - dq * faer::Scale(h)), &(nn - dn * faer::Scale(h)))?;
        Ok((plus - minus) * faer::Scale(0.5 / h))
    };
    let zero = Mat::zeros(n, n);
    let b = rhs.transpose() - diff(&q_dot, &zero, hq)?;
    let m = n * n;
    let mut hess = Mat::zeros(m, m);
    for k in 0..m {
        let e = Mat::from_fn(n, n, |i, j| if i * n + j == k { 1.0 } else { 0.0 });
        let col = diff(&zero, &e, hn)?;
        for r in 0..m {
            hess[(r, k)] = col[(r / n, r % n)];
        }
    }
    let rhs_v = Mat::from_fn(m, 1, |r, _| b[(r / n, r % n)]);
    let lu = hess.partial_piv_lu();
    let sol = lu.solve(&rhs_v);
    let residual = (&hess * &sol - &rhs_v).norm_l2() / rhs_v.norm_l2().max(1e-300);
    if !sol.norm_l2().is_finite() || residual > 1e-6 {
        return Err(Error::invalid(
            "lagrangian",
            "the Hessian of L in N is singular here (L is not regular): the reduced \
             Euler–Lagrange equation does not determine dN/dt",
        )
        .into());
    }
    let n_dot = Mat::from_fn(n, n, |i, j| sol[(i * n + j, 0)]);
    Ok((q_dot, n_dot))
}

/// (∂𝓛/∂Q over symmetric matrices, ∂𝓛/∂N) of a Lagrangian given by its values, by central
/// differences with steps ε^{1/3}·max(1, max|entry|) (relative error ≈ 1e-10 for a smooth 𝓛; the
/// gradient [`euler_lagrange`] needs when the caller has none). Q_ij and Q_ji move together, so
/// the difference quotient is G_ij + G_ji = 2G_ij off the diagonal.
pub fn lagrangian_gradient(
    value: &dyn Fn(&Mat, &Mat) -> Result<f64>,
    q: &Mat,
    nn: &Mat,
) -> Result<(Mat, Mat)> {
    let n = check::square("Q", q, 1)?;
    check::square_of("N", nn, n)?;
    let step = f64::EPSILON.cbrt();
    let (hq, hn) = (
        step * check::max_abs(q).max(1.0),
        step * check::max_abs(nn).max(1.0),
    );
    let mut gq = Mat::zeros(n, n);
    let mut gn = Mat::zeros(n, n);
    for i in 0..n {
        for j in 0..n {
            if j >= i {
                let e = Mat::from_fn(n, n, |a, b| {
                    f64::from(u8::from((a, b) == (i, j) || (a, b) == (j, i)))
                });
                let d = (value(&(q + &e * faer::Scale(hq)), nn)?
                    - value(&(q - &e * faer::Scale(hq)), nn)?)
                    / (2.0 * hq);
                let g = if i == j { d } else { 0.5 * d };
                gq[(i, j)] = g;
                gq[(j, i)] = g;
            }
            let e = Mat::from_fn(n, n, |a, b| f64::from(u8::from((a, b) == (i, j))));
            gn[(i, j)] = (value(q, &(nn + &e * faer::Scale(hn)))?
                - value(q, &(nn - &e * faer::Scale(hn)))?)
                / (2.0 * hn);
        }
    }
    Ok((gq, gn))
}

/// The Cholesky factor C of Q (CCᵀ = Q), or an error naming Q when it is not positive definite.
fn cholesky_of(q: &Mat) -> Result<Mat> {
    let mut c = q.clone();
    if !linalg::cholesky(c.as_mut()) {
        return Err(Error::NotInGroup {
            what: "Q".into(),
            group: format!("Sym+({})", q.nrows()),
            defect_name: "positive definiteness (Cholesky pivot)".into(),
            defect: f64::NAN,
            tol: 0.0,
        });
    }
    Ok(c)
}

fn read(n: usize, z: &[f64]) -> Mat {
    Mat::from_fn(n, n, |i, j| z[i * n + j])
}

fn write(m: &Mat, z: &mut [f64]) {
    let n = m.nrows();
    for (k, v) in z.iter_mut().enumerate() {
        *v = m[(k / n, k % n)];
    }
}

impl Problem for RightReduced {
    fn name(&self) -> &'static str {
        "RightReduced"
    }

    fn calls_out(&self) -> bool {
        self.body.potential().calls_out()
    }

    /// The potential's constants ([`Potential::parameters`]).
    fn parameters(&self) -> Vec<&'static str> {
        self.body.potential().parameters()
    }

    fn space(&self) -> Space {
        let n = self.n();
        if self.reconstruct {
            Space::new([
                ("Q", Block::Matrix(n)),
                ("N", Block::Matrix(n)),
                ("X", Block::Matrix(n)),
            ])
        } else {
            Space::new([("Q", Block::Matrix(n)), ("N", Block::Matrix(n))])
        }
    }

    /// H = ½ tr(NᵀQ⁻¹N) + U (001 (3.22), (3.31)).
    fn energy(&self, z: &[f64]) -> Result<f64> {
        self.hamiltonian(z)
    }

    /// ½tr((LᵀL)^k) then ½tr((Γ_CᵀΓ_C)^k), k = 1…⌊n/2⌋: the same values as the full body's
    /// (L = Nᵀ − N; Γ_C conjugate to Γ), the Casimirs of the reduced space.
    fn invariants(&self, z: &[f64]) -> Result<Vec<f64>> {
        let mut c = spectral_invariants(&self.angular_momentum(z)?);
        c.extend(spectral_invariants(&self.circulation(z)?));
        Ok(c)
    }

    fn invariant_names(&self) -> Vec<String> {
        let mut names = spectral_names("L", self.n());
        names.extend(spectral_names("Γ", self.n()));
        names
    }

    /// Q symmetric to [`STATE_TOL`] and positive definite; U right-invariant there
    /// ([`INVARIANCE_TOL`]); when reconstructing, det X > 0 and XXᵀ = Q to [`STATE_TOL`].
    fn check_state(&self, z: &[f64]) -> Result<()> {
        let n = self.n();
        let (q, _) = self.split(z)?;
        let scale = linalg::frob2(q.as_ref()).sqrt();
        let asym = (&q - q.transpose()).norm_l2() / scale;
        if asym.is_nan() || asym > STATE_TOL {
            return Err(Error::NotInGroup {
                what: "Q".into(),
                group: format!("Sym+({n})"),
                defect_name: "‖Q − Qᵀ‖_F / ‖Q‖_F".into(),
                defect: asym,
                tol: STATE_TOL,
            });
        }
        let c = cholesky_of(&q)?;
        self.check_invariance(&c)?;
        if self.reconstruct {
            let x = read(n, &z[2 * n * n..]);
            crate::lie::gl::check_gl_plus("X", &x)?;
            let d = (&x * x.transpose() - &q).norm_l2() / scale;
            if d.is_nan() || d > STATE_TOL {
                return Err(Error::invalid(
                    "state",
                    format!(
                        "X must lie over Q (XXᵀ = Q); got ‖XXᵀ − Q‖_F/‖Q‖_F = {d:.3e} \
                         (tolerance {STATE_TOL:.0e}): make the state with reduce(X, P)"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The working state of the reduced flows: (Q, N[, X]), the representative C (the Cholesky
/// factor of the current Q when `fresh`), W = C⁻¹N or the force, the potential's workspace;
/// whether Q stopped being positive definite.
#[derive(Debug)]
pub struct Work {
    q: Mat,
    nn: Mat,
    x: Option<Mat>,
    c: Mat,
    w: Mat,
    t: Mat,
    ws: Workspace,
    lost: bool,
    fresh: bool,
}

impl Clone for Work {
    fn clone(&self) -> Self {
        let n = self.q.nrows();
        Work {
            q: self.q.clone(),
            nn: self.nn.clone(),
            x: self.x.clone(),
            c: Mat::zeros(n, n),
            w: Mat::zeros(n, n),
            t: Mat::zeros(n, n),
            ws: Workspace::new(n),
            lost: self.lost,
            fresh: false,
        }
    }
}

impl Work {
    /// C ← the Cholesky factor of Q (once per value of Q); false (and `lost` set) when Q is not
    /// positive definite.
    fn factor(&mut self) -> bool {
        if !self.fresh && !self.lost {
            self.c.copy_from(&self.q);
            if !linalg::cholesky(self.c.as_mut()) {
                self.lost = true;
            }
            self.fresh = true;
        }
        !self.lost
    }
}

impl Split for RightReduced {
    type Work = Work;

    fn load(&self, z: &[f64]) -> Result<Work> {
        let n = self.n();
        let (q, nn) = self.split(z)?;
        Ok(Work {
            q,
            nn,
            x: self.reconstruct.then(|| read(n, &z[2 * n * n..])),
            c: Mat::zeros(n, n),
            w: Mat::zeros(n, n),
            t: Mat::zeros(n, n),
            ws: Workspace::new(n),
            lost: false,
            fresh: false,
        })
    }

    fn store(&self, w: &Work, z: &mut [f64]) {
        let n = self.n();
        write(&w.q, &mut z[..n * n]);
        write(&w.nn, &mut z[n * n..2 * n * n]);
        if let Some(x) = &w.x {
            write(x, &mut z[2 * n * n..]);
        }
    }

    /// 0: the potential U (the kick, outer), 1: the kinetic energy K (the drift).
    fn flows(&self) -> usize {
        2
    }

    fn flow(&self, i: usize, tau: f64, w: &mut Work) {
        if w.lost || !w.factor() {
            return;
        }
        if i == 0 {
            // N ← N − τ C (∂U/∂X(C))ᵀ (∂U/∂X on stack matrices at n = 3 where the potential
            // has them).
            let pot = self.body.potential();
            let g3 = (w.c.nrows() == 3)
                .then(|| pot.gradient3(&nalgebra::Matrix3::from_fn(|i, j| w.c[(i, j)])))
                .flatten();
            match g3 {
                Some(g) => {
                    for i in 0..3 {
                        for j in 0..3 {
                            w.w[(i, j)] = g[(i, j)];
                        }
                    }
                }
                None => {
                    w.w.fill(0.0);
                    pot.add_gradient(w.c.as_ref(), w.w.as_mut(), &mut w.ws);
                }
            }
            linalg::mul(
                w.nn.as_mut(),
                Accum::Add,
                w.c.as_ref(),
                w.w.transpose(),
                -tau,
            );
            return;
        }
        // W = C⁻¹N, K = WᵀW; X ← X + τ Wᵀ C⁻¹X first (it reads the old Q's factor).
        w.w.copy_from(&w.nn);
        linalg::solve_lower(w.c.as_ref(), w.w.as_mut());
        if let Some(x) = &mut w.x {
            w.t.copy_from(&*x);
            linalg::solve_lower(w.c.as_ref(), w.t.as_mut());
            linalg::mul(x.as_mut(), Accum::Add, w.w.transpose(), w.t.as_ref(), tau);
        }
        // t = K = WᵀW (symmetric by construction).
        linalg::mul(
            w.t.as_mut(),
            Accum::Replace,
            w.w.transpose(),
            w.w.as_ref(),
            1.0,
        );
        let n = w.q.nrows();
        for i in 0..n {
            for j in 0..n {
                w.q[(i, j)] += tau * (w.nn[(i, j)] + w.nn[(j, i)]) + tau * tau * w.t[(i, j)];
            }
        }
        linalg::axpy(w.nn.as_mut(), tau, w.t.as_ref());
        w.fresh = false;
    }

    const CHECKED: bool = true;

    /// Q must stay positive definite (det X → 0: the ellipsoid collapsed) and finite.
    fn check_step(&self, w: &mut Work) -> std::result::Result<(), Violation> {
        if w.lost || !w.factor() || !check::max_abs(&w.nn).is_finite() {
            let n = self.n();
            return Err(Violation {
                what: format!("Q = XXᵀ (right-reduced pseudo-rigid body, Sym+({n}))"),
                message: "Q is no longer positive definite: the ellipsoid collapsed (det X \
                          reached 0) or the state overflowed; the reduced motion ends here"
                    .into(),
            });
        }
        Ok(())
    }
}

/// The Riemann field (001 (3.20)) and, when reconstructing, Ẋ = NᵀQ⁻¹X; the baseline `rk4`.
impl VectorField for RightReduced {
    fn field(&self, z: &[f64], dz: &mut [f64]) {
        let n = self.n();
        let (q, nn) = (read(n, &z[..n * n]), read(n, &z[n * n..2 * n * n]));
        let mut c = q.clone();
        if !linalg::cholesky(c.as_mut()) {
            dz.fill(f64::NAN);
            return;
        }
        let mut g = Mat::zeros(n, n);
        let mut ws = self.body.workspace();
        self.body
            .potential()
            .add_gradient(c.as_ref(), g.as_mut(), &mut ws);
        let mut w = nn.clone();
        linalg::solve_lower(c.as_ref(), w.as_mut());
        let n_dot = w.transpose() * &w - &c * g.transpose();
        write(&(&nn + nn.transpose()), &mut dz[..n * n]);
        write(&n_dot, &mut dz[n * n..2 * n * n]);
        if self.reconstruct {
            let mut t = read(n, &z[2 * n * n..]);
            linalg::solve_lower(c.as_ref(), t.as_mut());
            write(&(w.transpose() * t), &mut dz[2 * n * n..]);
        }
    }
}

/// The derivatives of the reduced flows and field at one state (Q, N\[, X\]) (module docs,
/// "Tangent lift"): its representative C, G = ∂U/∂X(C), W = C⁻¹N, T = C⁻¹X, and the scratch of
/// one direction; formed once for all the directions of a flow.
struct Linear<'a> {
    pot: &'a dyn Potential,
    c: Mat,
    g: Mat,
    w: Mat,
    t: Option<Mat>,
    dc: Mat,
    dw: Mat,
    a: Mat,
    b: Mat,
    ws: Workspace,
}

/// A row-major n×n block of a flat direction.
fn view(z: &mut [f64], n: usize) -> MatMut<'_, f64> {
    MatMut::from_row_major_slice_mut(z, n, n)
}

impl<'a> Linear<'a> {
    /// None where Q is not positive definite.
    fn at(body: &'a RightReduced, q: &Mat, nn: &Mat, x: Option<&Mat>) -> Option<Self> {
        let n = body.n();
        let pot = body.body.potential();
        let mut c = q.clone();
        if !linalg::cholesky(c.as_mut()) {
            return None;
        }
        let mut ws = body.body.workspace();
        let mut g = Mat::zeros(n, n);
        pot.add_gradient(c.as_ref(), g.as_mut(), &mut ws);
        let mut w = nn.clone();
        linalg::solve_lower(c.as_ref(), w.as_mut());
        let t = x.map(|x| {
            let mut t = x.clone();
            linalg::solve_lower(c.as_ref(), t.as_mut());
            t
        });
        Some(Linear {
            pot,
            c,
            g,
            w,
            t,
            dc: Mat::zeros(n, n),
            dw: Mat::zeros(n, n),
            a: Mat::zeros(n, n),
            b: Mat::zeros(n, n),
            ws,
        })
    }

    /// dc ← δC = CΦ, Φ the lower triangle of C⁻¹SC⁻ᵀ with its diagonal halved, S the symmetric
    /// matrix of δQ's lower triangle (from δQ = δC Cᵀ + C δCᵀ).
    fn cholesky(&mut self, dq: MatRef<'_, f64>) {
        let n = self.c.nrows();
        for i in 0..n {
            for j in 0..=i {
                self.a[(i, j)] = dq[(i, j)];
                self.a[(j, i)] = dq[(i, j)];
            }
        }
        linalg::solve_lower(self.c.as_ref(), self.a.as_mut());
        self.b.copy_from(self.a.transpose());
        linalg::solve_lower(self.c.as_ref(), self.b.as_mut());
        for i in 0..n {
            for j in 0..n {
                self.a[(i, j)] = match i.cmp(&j) {
                    std::cmp::Ordering::Greater => self.b[(i, j)],
                    std::cmp::Ordering::Equal => 0.5 * self.b[(i, i)],
                    std::cmp::Ordering::Less => 0.0,
                };
            }
        }
        linalg::mul(
            self.dc.as_mut(),
            Accum::Replace,
            self.c.as_ref(),
            self.a.as_ref(),
            1.0,
        );
    }

    /// dn += α(δC Gᵀ + C D²U(C)\[δC\]ᵀ), the derivative of αCGᵀ (after [`Linear::cholesky`]).
    fn force(&mut self, alpha: f64, mut dn: MatMut<'_, f64>) {
        self.b.fill(0.0);
        self.pot.add_hessian(
            self.c.as_ref(),
            self.dc.as_ref(),
            self.b.as_mut(),
            &mut self.ws,
        );
        linalg::mul(
            dn.as_mut(),
            Accum::Add,
            self.dc.as_ref(),
            self.g.transpose(),
            alpha,
        );
        linalg::mul(dn, Accum::Add, self.c.as_ref(), self.b.transpose(), alpha);
    }

    /// a ← δK = δWᵀW + WᵀδW with δW = C⁻¹(δN − δC W) in dw (after [`Linear::cholesky`]): the
    /// derivative of K = WᵀW.
    fn kinetic(&mut self, dn: MatRef<'_, f64>) {
        self.dw.copy_from(dn);
        linalg::mul(
            self.dw.as_mut(),
            Accum::Add,
            self.dc.as_ref(),
            self.w.as_ref(),
            -1.0,
        );
        linalg::solve_lower(self.c.as_ref(), self.dw.as_mut());
        linalg::mul(
            self.a.as_mut(),
            Accum::Replace,
            self.dw.transpose(),
            self.w.as_ref(),
            1.0,
        );
        linalg::mul(
            self.a.as_mut(),
            Accum::Add,
            self.w.transpose(),
            self.dw.as_ref(),
            1.0,
        );
    }

    /// b ← δT = C⁻¹(δX − δC T) (after [`Linear::cholesky`]).
    fn reconstruction(&mut self, dx: MatRef<'_, f64>) {
        let t = self.t.as_ref().expect("X is carried");
        self.b.copy_from(dx);
        linalg::mul(
            self.b.as_mut(),
            Accum::Add,
            self.dc.as_ref(),
            t.as_ref(),
            -1.0,
        );
        linalg::solve_lower(self.c.as_ref(), self.b.as_mut());
    }

    /// out += α(δWᵀT + WᵀδT), the derivative of αWᵀT (after [`Linear::kinetic`] and
    /// [`Linear::reconstruction`]).
    fn add_reconstruction(&self, mut out: MatMut<'_, f64>, alpha: f64) {
        let t = self.t.as_ref().expect("X is carried");
        linalg::mul(
            out.as_mut(),
            Accum::Add,
            self.dw.transpose(),
            t.as_ref(),
            alpha,
        );
        linalg::mul(out, Accum::Add, self.w.transpose(), self.b.as_ref(), alpha);
    }

    /// dn += α C (∂G/∂θ_m)ᵀ.
    fn force_parameter(&mut self, m: usize, alpha: f64, dn: MatMut<'_, f64>) {
        self.b.fill(0.0);
        self.pot
            .add_parameter_gradient(self.c.as_ref(), m, self.b.as_mut(), &mut self.ws);
        linalg::mul(dn, Accum::Add, self.c.as_ref(), self.b.transpose(), alpha);
    }
}

impl RightReduced {
    /// The blocks (δQ, δN, δX) of a flat direction (δX empty without reconstruction).
    fn blocks_of<'z>(&self, dz: &'z mut [f64]) -> (&'z mut [f64], &'z mut [f64], &'z mut [f64]) {
        let nn = self.n() * self.n();
        let (dq, rest) = dz.split_at_mut(nn);
        let (dn, dx) = rest.split_at_mut(nn);
        (dq, dn, dx)
    }
}

/// The kick: δN′ = δN − τ(δC Gᵀ + C D²U(C)\[δC\]ᵀ). The drift (Q′ = Q + τ(N + Nᵀ) + τ²K,
/// N′ = N + τK, X′ = X + τWᵀT): δQ′ = δQ + τ(δN + δNᵀ) + τ²δK, δN′ = δN + τδK,
/// δX′ = δX + τ(δWᵀT + WᵀδT) (module docs, "Tangent lift"). NaN where Q is not positive definite.
impl SplitTangent for RightReduced {
    fn flow_tangent(&self, i: usize, tau: f64, before: &Work, _after: &Work, dirs: &mut [f64]) {
        let n = self.n();
        let Some(mut lin) = Linear::at(self, &before.q, &before.nn, before.x.as_ref()) else {
            dirs.fill(f64::NAN);
            return;
        };
        for dz in dirs.chunks_exact_mut(self.blocks() * n * n) {
            let (dq, dn, dx) = self.blocks_of(dz);
            lin.cholesky(MatRef::from_row_major_slice(dq, n, n));
            if i == 0 {
                lin.force(-tau, view(dn, n));
                continue;
            }
            lin.kinetic(MatRef::from_row_major_slice(dn, n, n));
            if !dx.is_empty() {
                lin.reconstruction(MatRef::from_row_major_slice(dx, n, n));
                lin.add_reconstruction(view(dx, n), tau);
            }
            let (mut q, mut m) = (view(dq, n), view(dn, n));
            for r in 0..n {
                for c in 0..n {
                    q[(r, c)] += tau * (m[(r, c)] + m[(c, r)]) + tau * tau * lin.a[(r, c)];
                }
            }
            linalg::axpy(m.as_mut(), tau, lin.a.as_ref());
        }
    }

    /// The kick moves with the potential's constants: δN′ −= τ C (∂G/∂θ_m)ᵀ.
    fn flow_parameter(
        &self,
        i: usize,
        tau: f64,
        before: &Work,
        _after: &Work,
        m: usize,
        dz: &mut [f64],
    ) {
        if i != 0 {
            return;
        }
        let n = self.n();
        let Some(mut lin) = Linear::at(self, &before.q, &before.nn, None) else {
            dz.fill(f64::NAN);
            return;
        };
        let (_, dn, _) = self.blocks_of(dz);
        lin.force_parameter(m, -tau, view(dn, n));
    }
}

/// The derivative of the Riemann field (001 (3.20)): δQ̇ = δN + δNᵀ,
/// δṄ = δK − δC Gᵀ − C D²U(C)\[δC\]ᵀ, δẊ = δWᵀT + WᵀδT.
impl VectorFieldTangent for RightReduced {
    fn field_tangent(&self, z: &[f64], dz: &[f64], out: &mut [f64]) {
        let n = self.n();
        let nn = n * n;
        let (q, m) = (read(n, &z[..nn]), read(n, &z[nn..2 * nn]));
        let x = self.reconstruct.then(|| read(n, &z[2 * nn..]));
        let Some(mut lin) = Linear::at(self, &q, &m, x.as_ref()) else {
            out.fill(f64::NAN);
            return;
        };
        out.fill(0.0);
        let (oq, on, ox) = self.blocks_of(out);
        let dn = MatRef::from_row_major_slice(&dz[nn..2 * nn], n, n);
        lin.cholesky(MatRef::from_row_major_slice(&dz[..nn], n, n));
        lin.kinetic(dn);
        if !ox.is_empty() {
            lin.reconstruction(MatRef::from_row_major_slice(&dz[2 * nn..], n, n));
            lin.add_reconstruction(view(ox, n), 1.0);
        }
        let (mut oq, mut on) = (view(oq, n), view(on, n));
        for r in 0..n {
            for c in 0..n {
                oq[(r, c)] = dn[(r, c)] + dn[(c, r)];
            }
        }
        on.copy_from(lin.a.as_ref());
        lin.force(-1.0, on);
    }

    /// δṄ −= C (∂G/∂θ_m)ᵀ.
    fn field_parameter(&self, z: &[f64], m: usize, out: &mut [f64]) {
        let n = self.n();
        let nn = n * n;
        let (q, mm) = (read(n, &z[..nn]), read(n, &z[nn..2 * nn]));
        let Some(mut lin) = Linear::at(self, &q, &mm, None) else {
            out.fill(f64::NAN);
            return;
        };
        let (_, on, _) = self.blocks_of(out);
        lin.force_parameter(m, -1.0, view(on, n));
    }
}

/// `verlet` (default), `verlet4`, `verlet6` (the reduced Störmer–Verlet and its Suzuki / Yoshida
/// compositions), `rk4` (the Riemann field, a baseline that keeps nothing).
impl Catalog for RightReduced {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("verlet", Splitting::strang),
            Entry::new("verlet4", || Splitting(Composition::suzuki4())),
            Entry::new("verlet6", || Splitting(Composition::yoshida6())),
            Entry::new("rk4", || Rk4),
        ]
    }

    /// The tangent lift of every method (module docs, "Tangent lift").
    fn tangent(&self) -> Option<Arc<dyn TangentSystem>> {
        Some(Tangent::split(self.clone()).into_system())
    }
}

/// Every method of the system, on its tangent lift.
impl Catalog for Tangent<RightReduced> {
    fn kind_catalog() -> Vec<Entry<Self>> {
        vec![
            Entry::new("verlet", Splitting::strang),
            Entry::new("verlet4", || Splitting(Composition::suzuki4())),
            Entry::new("verlet6", || Splitting(Composition::yoshida6())),
            Entry::new("rk4", || Rk4),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::integrate;
    use crate::lie::so;
    use crate::pseudo_rigid::potential::{
        Harmonic, SaintVenantKirchhoff, Stretch, Sum, Volumetric,
    };
    use crate::pseudo_rigid::PseudoRigidBody;

    /// An elastic body with a gas inside (the volumetric term keeps det X > 0 away from 0).
    fn potential(n: usize) -> Arc<dyn Potential> {
        let elastic: Arc<dyn Potential> = if n == 3 {
            Arc::new(SaintVenantKirchhoff::new(1.0, 2.0).unwrap())
        } else {
            Arc::new(Sum::new(vec![
                Arc::new(Harmonic::new(1.5).unwrap()),
                Arc::new(Stretch::new(0.7).unwrap()),
            ]))
        };
        Arc::new(Sum::new(vec![
            elastic,
            Arc::new(Volumetric::polytropic(0.5, 1.4).unwrap()),
        ]))
    }

    /// A generic state: X near a stretched identity with shear, P with both rotations.
    fn state(n: usize) -> (Mat, Mat) {
        let x = Mat::from_fn(n, n, |i, j| {
            if i == j {
                1.0 + 0.25 * i as f64
            } else {
                0.1 * ((i + 2 * j) as f64).sin()
            }
        });
        let p = Mat::from_fn(n, n, |i, j| {
            0.3 * ((3 * i + j) as f64).cos() + 0.2 * (i as f64 - j as f64)
        });
        (x, p)
    }

    fn rel(a: &Mat, b: &Mat) -> f64 {
        (a - b).norm_l2() / b.norm_l2().max(1e-300)
    }

    #[test]
    fn reduced_verlet_reconstructs_the_full_verlet_motion() {
        for n in [3, 4] {
            let (x0, p0) = state(n);
            let full = PseudoRigidBody::new(n, potential(n), true).unwrap();
            let red = RightReduced::new(n, potential(n)).unwrap().reconstructing();
            let gamma0 = crate::pseudo_rigid::momentum::momentum_map(&x0, &p0)
                .unwrap()
                .1;
            for (m_full, m_red) in [("verlet", "verlet"), ("verlet4", "verlet4")] {
                // The full body's verlet4 composes kick–drift–kick Strang steps, as the reduced
                // splitting composes U–K–U: the same maps.
                let a = integrate(
                    &full,
                    m_full,
                    &full.state(&x0, &p0).unwrap(),
                    0.02,
                    500,
                    100,
                )
                .unwrap();
                let b =
                    integrate(&red, m_red, &red.reduce(&x0, &p0).unwrap(), 0.02, 500, 100).unwrap();
                for k in 0..a.len() {
                    let (xa, pa) = full.split(a.state(k)).unwrap();
                    let (xb, pb) = red.reconstruct(b.state(k)).unwrap();
                    assert!(
                        rel(&xb, &xa) < 1e-12,
                        "n={n} {m_red} k={k}: {}",
                        rel(&xb, &xa)
                    );
                    assert!(
                        rel(&pb, &pa) < 1e-11,
                        "n={n} {m_red} k={k}: {}",
                        rel(&pb, &pa)
                    );
                    // The reduced coordinates are those of the full state.
                    let (q, nn) = red.split(b.state(k)).unwrap();
                    let (qa, na) =
                        crate::pseudo_rigid::riemann::riemann_variables(&xa, &pa).unwrap();
                    assert!(rel(&q, &qa) < 1e-12 && rel(&nn, &na) < 1e-11);
                    // Kelvin: the reconstructed circulation is the initial one.
                    let g = crate::pseudo_rigid::momentum::momentum_map(&xb, &pb)
                        .unwrap()
                        .1;
                    assert!(
                        rel(&g, &gamma0) < 1e-12,
                        "n={n} k={k}: {}",
                        rel(&g, &gamma0)
                    );
                }
            }
        }
    }

    #[test]
    fn casimirs_to_round_off_energy_bounded_and_orders() {
        let n = 3;
        let (x0, p0) = state(n);
        let red = RightReduced::new(n, potential(n)).unwrap();
        let z0 = red.reduce(&x0, &p0).unwrap();
        let (c0, e0) = (red.invariants(&z0).unwrap(), red.energy(&z0).unwrap());
        let t = integrate(&red, "verlet", &z0, 0.05, 20_000, 1000).unwrap();
        for k in 0..t.len() {
            let c = red.invariants(t.state(k)).unwrap();
            for (a, b) in c.iter().zip(&c0) {
                assert!((a - b).abs() < 1e-12 * b.abs().max(1.0), "{a} vs {b}");
            }
            assert!((red.energy(t.state(k)).unwrap() - e0).abs() < 1e-2 * e0.abs());
        }
        // Orders from error ratios against a fine verlet6 run at t = 1.
        let reference = integrate(&red, "verlet6", &z0, 1e-3, 1000, 1000).unwrap();
        let zr = reference.state(1).to_vec();
        let err = |m: &str, h: f64| {
            let s = (1.0 / h).round() as usize;
            let z = integrate(&red, m, &z0, h, s, s).unwrap().state(1).to_vec();
            z.iter()
                .zip(&zr)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        };
        for (m, order, h) in [
            ("verlet", 2.0, 0.02),
            ("verlet4", 4.0, 0.05),
            ("rk4", 4.0, 0.05),
        ] {
            let ratio = err(m, h) / err(m, h / 2.0);
            let observed = ratio.log2();
            assert!(
                (observed - order).abs() < 0.3,
                "{m}: observed order {observed}"
            );
        }
    }

    #[test]
    fn the_field_is_the_riemann_field_and_hamiltons_equations_of_the_bracket_9_1() {
        for n in [2, 3, 4] {
            let (x0, p0) = state(n);
            let red = RightReduced::new(n, potential(n)).unwrap();
            let z = red.reduce(&x0, &p0).unwrap();
            let mut dz = vec![0.0; z.len()];
            red.field(&z, &mut dz);
            let (q, nn) = red.split(&z).unwrap();
            let (qd, nd) = red.full().riemann_vector_field(&q, &nn).unwrap();
            assert!(rel(&read(n, &dz[..n * n]), &qd) < 1e-13);
            assert!(rel(&read(n, &dz[n * n..]), &nd) < 1e-12);
            // ż_k = {z_k, H} with the bracket (9.1) and ∂H by central differences (Q perturbed
            // symmetrically, so ∂H/∂Q is the symmetric gradient the bracket expects).
            let h = 1e-5;
            let mut dh_q = Mat::zeros(n, n);
            let mut dh_n = Mat::zeros(n, n);
            for i in 0..n {
                for j in 0..n {
                    let e = |zz: &mut Vec<f64>, off: usize, s: f64| {
                        zz[off + i * n + j] += s;
                        if off == 0 && i != j {
                            zz[j * n + i] += s;
                        }
                    };
                    let (mut zp, mut zm) = (z.clone(), z.clone());
                    e(&mut zp, 0, h);
                    e(&mut zm, 0, -h);
                    let d = (red.energy(&zp).unwrap() - red.energy(&zm).unwrap()) / (2.0 * h);
                    dh_q[(i, j)] = if i == j { d } else { 0.5 * d };
                    let (mut zp, mut zm) = (z.clone(), z.clone());
                    e(&mut zp, n * n, h);
                    e(&mut zm, n * n, -h);
                    dh_n[(i, j)] =
                        (red.energy(&zp).unwrap() - red.energy(&zm).unwrap()) / (2.0 * h);
                }
            }
            for (k, &dzk) in dz.iter().enumerate() {
                let mut df = (Mat::zeros(n, n), Mat::zeros(n, n));
                if k < n * n {
                    df.0[(k / n, k % n)] = 1.0;
                } else {
                    df.1[((k - n * n) / n, k % n)] = 1.0;
                }
                let b = crate::pseudo_rigid::riemann::poisson_bracket(
                    &q,
                    &nn,
                    (&df.0, &df.1),
                    (&dh_q, &dh_n),
                )
                .unwrap();
                assert!(
                    (b - dzk).abs() < 1e-8 * (1.0 + dzk.abs()),
                    "n={n} k={k}: {b} vs {dzk}"
                );
            }
        }
    }

    #[test]
    fn the_terms_of_3_31_are_right_invariant_and_add_up_to_h() {
        for n in [2, 3, 4] {
            let (x, p) = state(n);
            let red = RightReduced::new(n, potential(n)).unwrap();
            let z = red.reduce(&x, &p).unwrap();
            let [hor, locked, u] = red.hamiltonian_parts(&z).unwrap();
            assert!(
                (hor + locked + u - red.energy(&z).unwrap()).abs()
                    < 1e-13 * (hor + locked + u.abs())
            );
            // At X itself (not the representative): Y from the right connection's horizontal
            // part, the locked term as ½ gᵀ𝕀⁻¹g with g_a = tr(PᵀX e_aᵀ) = ⟨Γ, e_a⟩-type
            // pairings and 𝕀 the locked inertia matrix of the right action (001 (2.27)).
            let b = BiInertia::new(&x).unwrap();
            let y = connection::horizontal_part(&b, &p, Action::Right).unwrap();
            assert!((0.5 * linalg::frob2(y.as_ref()) - hor).abs() < 1e-12 * hor);
            let inertia = connection::locked_inertia(&b, Action::Right).unwrap();
            let d = so::dim(n);
            let g = Mat::from_fn(d, 1, |a, _| {
                let mut c = vec![0.0; d];
                c[a] = 1.0;
                let e = so::hat_n_unchecked(n, &c);
                linalg::inner(p.as_ref(), (&x * e.transpose()).as_ref())
            });
            let w = inertia.partial_piv_lu().solve(&g);
            let locked_x = 0.5 * (g.transpose() * &w)[(0, 0)];
            assert!(
                (locked_x - locked).abs() < 1e-12 * locked,
                "{locked_x} vs {locked}"
            );
            // A rotated representative gives the same reduced state and terms.
            let h = crate::lie::so::exp(&so::hat_n_unchecked(n, &vec![0.3; d])).unwrap();
            let z2 = red.reduce(&(&x * &h), &(&p * &h)).unwrap();
            let parts2 = red.hamiltonian_parts(&z2).unwrap();
            for (a, b) in parts2.iter().zip([hor, locked, u]) {
                assert!((a - b).abs() < 1e-12 * b.abs().max(1.0));
            }
        }
    }

    #[test]
    fn euler_lagrange_3_17_is_3_20_for_the_quadratic_lagrangian_and_keeps_the_energy() {
        let n = 3;
        let (x, p) = state(n);
        let red = RightReduced::new(n, potential(n)).unwrap();
        let z = red.reduce(&x, &p).unwrap();
        let (q, nn) = red.split(&z).unwrap();
        // ∂𝓛/∂Q (symmetric) and ∂𝓛/∂N of 𝓛 = ½tr(NᵀQ⁻¹N) − U(Q^{1/2}), by the chain rule at
        // the Cholesky representative: ∂U/∂Q = ½ C⁻ᵀ(∂U/∂X(C))ᵀ... symmetrised.
        let pot = potential(n);
        let mut grad = |q: &Mat, nn: &Mat| -> Result<(Mat, Mat)> {
            let qi = q.partial_piv_lu().solve(Mat::identity(n, n));
            let mut c = q.clone();
            assert!(linalg::cholesky(c.as_mut()));
            let mut g = Mat::zeros(n, n);
            pot.add_gradient(c.as_ref(), g.as_mut(), &mut Workspace::new(n));
            // ∂U/∂X = 2(∂V/∂Q)X ⇒ ∂V/∂Q = ½ (∂U/∂X) X⁻¹ (symmetric by invariance).
            let dv = &g * c.partial_piv_lu().solve(Mat::identity(n, n)) * faer::Scale(0.5);
            let dk_dq = &qi * nn * nn.transpose() * &qi * faer::Scale(-0.5);
            Ok((dk_dq - dv, &qi * nn))
        };
        let (qd, nd) = euler_lagrange(&mut grad, &q, &nn, false).unwrap();
        let (qr, nr) = red.full().riemann_vector_field(&q, &nn).unwrap();
        assert!(rel(&qd, &qr) < 1e-14);
        assert!(rel(&nd, &nr) < 1e-8, "{}", rel(&nd, &nr));

        // A Lagrangian that is not quadratic in N: 𝓛 = ½tr(NᵀQ⁻¹N) + ε(tr NᵀQ⁻¹N)² − tr Q.
        // Its energy ⟨∂𝓛/∂N, N⟩ − 𝓛 is conserved by the reduced field (RK4, small steps).
        let eps = 0.05;
        let mut grad2 = |q: &Mat, nn: &Mat| -> Result<(Mat, Mat)> {
            let qi = q.partial_piv_lu().solve(Mat::identity(n, n));
            let k = linalg::inner(nn.as_ref(), (&qi * nn).as_ref());
            let dk_dq = &qi * nn * nn.transpose() * &qi * faer::Scale(-1.0);
            let dq = dk_dq * faer::Scale(0.5 + 2.0 * eps * k) - Mat::identity(n, n);
            let dn = &qi * nn * faer::Scale(1.0 + 4.0 * eps * k);
            Ok((dq, dn))
        };
        let energy = |q: &Mat, nn: &Mat| {
            let qi = q.partial_piv_lu().solve(Mat::identity(n, n));
            let k = linalg::inner(nn.as_ref(), (&qi * nn).as_ref());
            // ⟨∂𝓛/∂N, N⟩ = k(1 + 4εk)... 𝓛 = k/2 + εk² − tr Q.
            k * (1.0 + 4.0 * eps * k)
                - (0.5 * k + eps * k * k - (0..n).map(|i| q[(i, i)]).sum::<f64>())
        };
        let (mut q, mut nn) = (q, nn * faer::Scale(0.3));
        let e0 = energy(&q, &nn);
        let h = 2e-3;
        for _ in 0..500 {
            let mut f = |q: &Mat, nn: &Mat| euler_lagrange(&mut grad2, q, nn, false).unwrap();
            let (k1q, k1n) = f(&q, &nn);
            let (k2q, k2n) = f(
                &(&q + &k1q * faer::Scale(h / 2.0)),
                &(&nn + &k1n * faer::Scale(h / 2.0)),
            );
            let (k3q, k3n) = f(
                &(&q + &k2q * faer::Scale(h / 2.0)),
                &(&nn + &k2n * faer::Scale(h / 2.0)),
            );
            let (k4q, k4n) = f(
                &(&q + &k3q * faer::Scale(h)),
                &(&nn + &k3n * faer::Scale(h)),
            );
            q = &q
                + (k1q + k2q * faer::Scale(2.0) + k3q * faer::Scale(2.0) + k4q)
                    * faer::Scale(h / 6.0);
            nn = &nn
                + (k1n + k2n * faer::Scale(2.0) + k3n * faer::Scale(2.0) + k4n)
                    * faer::Scale(h / 6.0);
        }
        let e1 = energy(&q, &nn);
        assert!((e1 - e0).abs() < 1e-8 * e0.abs(), "{e0} → {e1}");
        // A sign error in (3.17)'s first term would not keep it: flip it and see.
        let (_, good) = euler_lagrange(&mut grad2, &q, &nn, false).unwrap();
        let mut flipped = |q: &Mat, nn: &Mat| -> Result<(Mat, Mat)> {
            let (dq, dn) = grad2(q, nn)?;
            Ok((dq, dn.transpose().to_owned()))
        };
        let (_, bad) = euler_lagrange(&mut flipped, &q, &nn, false).unwrap();
        assert!(rel(&bad, &good) > 1e-3);
    }

    #[test]
    fn a_collapse_ends_the_run_and_bad_states_are_refused() {
        let n = 3;
        let red = RightReduced::new(n, Arc::new(crate::pseudo_rigid::potential::Zero)).unwrap();
        let x = Mat::identity(n, n);
        let mut p = Mat::zeros(n, n);
        p[(0, 0)] = -1.0;
        // X(t) = diag(1 − t, 1, 1): Q is singular at t = 1 = 4 steps of 0.25.
        let err = integrate(&red, "verlet", &red.reduce(&x, &p).unwrap(), 0.25, 8, 1).unwrap_err();
        assert!(err.to_string().contains("positive definite"), "{err}");
        let mut z = red.reduce(&x, &Mat::zeros(n, n)).unwrap();
        z[1] = 0.5; // Q not symmetric
        assert!(red.check_state(&z).is_err());
        let z = red.reduce(&x, &Mat::zeros(n, n)).unwrap();
        let recon = red.clone().reconstructing();
        assert!(red.reconstruct(&z).is_err());
        let mut z = recon.reduce(&x, &Mat::zeros(n, n)).unwrap();
        z[2 * n * n] = 1.5; // X not over Q
        assert!(recon
            .check_state(&z)
            .unwrap_err()
            .to_string()
            .contains("XXᵀ = Q"));
    }
}
