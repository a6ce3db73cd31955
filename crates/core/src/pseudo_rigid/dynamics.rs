//! Dynamics of generalized pseudo-rigid bodies on T*GL⁺(n) (001 §3–§5).
//!
//! The full system has H(X, P) = ½ tr(PᵀP) + U(X) (001 (3.22)) and Hamilton's equations
//! Ẋ = P, Ṗ = −∂U/∂X. The same motions are described by
//! - the Riemann-ellipsoid equations in Q = XXᵀ, N = XẊᵀ (001 (3.20)),
//!   [`FullBody::riemann_vector_field`];
//! - the Euler–Lagrange equations in SVD coordinates X = RASᵀ (001 Prop. 4.2),
//!   [`FullBody::lagrange_vector_field`], and at n = 3 their vector form (001 (5.3)–(5.5)),
//!   [`FullBody::lagrange_vector_field_3d`];
//! - Dedekind's reciprocity: X ↦ Xᵀ maps motions to motions and swaps L and Γ,
//!   [`adjoint_motion`].
//!
//! Time stepping of the full system is [`crate::integrate::methods::verlet`].

use crate::check;
use crate::error::{Error, Result};
use crate::lie::so;
use crate::numerics::linalg;
use crate::pseudo_rigid::momentum;
use crate::pseudo_rigid::potential::{self, Potential, Workspace};
use crate::Mat;
use faer::Side;
use nalgebra::Vector3;
use std::sync::Arc;

/// A generalized pseudo-rigid body in n dimensions with potential U: the Hamiltonian system
/// (T*GL⁺(n), tr(dPᵀ∧dX), H = ½ tr(PᵀP) + U(X)) of 001 (3.21)–(3.22).
#[derive(Debug, Clone)]
pub struct FullBody {
    n: usize,
    potential: Arc<dyn Potential>,
}

/// Rates of the Euler–Lagrange equations of 001 Prop. 4.2 at a point (A, Ω, Λ) of the body
/// coordinates X = RASᵀ, Ω = RᵀṘ, Λ = SᵀṠ.
#[derive(Debug, Clone)]
pub struct LagrangeRates {
    /// p_Ω = A²Ω + ΩA² − 2AΛA = RᵀLR, the body angular momentum (001 (4.15a)).
    pub p_omega: Mat,
    /// p_Λ = A²Λ + ΛA² − 2AΩA = SᵀΓS, the body circulation (001 (4.15b)).
    pub p_lambda: Mat,
    /// E = 𝔇(−(Ω² + Λ²)A + ΩAΛ + ΛAΩ) (001 (4.8)), as the vector of its diagonal.
    pub e: Vec<f64>,
    /// Ä = E − ∂U/∂A (001 (4.11a)), as a vector.
    pub a_ddot: Vec<f64>,
    /// d/dt p_Ω = [p_Ω, Ω] (001 (4.11b)).
    pub p_omega_dot: Mat,
    /// d/dt p_Λ = [p_Λ, Λ] (001 (4.11c)).
    pub p_lambda_dot: Mat,
}

/// The n = 3 vector form of [`LagrangeRates`] (001 §5, physics hat map: hat(ω) = Ω).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LagrangeRates3 {
    /// Body angular momentum m, hat(m) = RᵀLR (001 (5.2)–(5.3)).
    pub m: Vector3<f64>,
    /// Body circulation c, hat(c) = SᵀΓS (001 (5.2)–(5.3)).
    pub c: Vector3<f64>,
    /// E (001 (5.4)).
    pub e: Vector3<f64>,
    /// ä = E − ∇U(a) (001 (5.5a)).
    pub a_ddot: Vector3<f64>,
    /// ṁ = m × ω (001 (5.5b)).
    pub m_dot: Vector3<f64>,
    /// ċ = c × λ (001 (5.5c)).
    pub c_dot: Vector3<f64>,
}

impl FullBody {
    /// A body in n ≥ 2 dimensions with the given potential (use
    /// [`potential::Zero`] for the free body); a potential defined for another dimension
    /// ([`Potential::dimension`], e.g. [`potential::SelfGravity`] at n ≠ 3) is refused
    /// ([`potential::check_dimension`]).
    pub fn new(n: usize, potential: Arc<dyn Potential>) -> Result<Self> {
        if n < 2 {
            return Err(Error::invalid("n", format!("expected n ≥ 2, got {n}")));
        }
        potential::check_dimension(&*potential, n)?;
        // The state (X, P) holds 2n² floats.
        check::dense_size("n", 2 * n.min(usize::MAX / 2), n)?;
        Ok(FullBody { n, potential })
    }

    /// The dimension n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The potential U.
    pub fn potential(&self) -> &dyn Potential {
        &*self.potential
    }

    /// A shared handle to the potential U.
    pub fn potential_arc(&self) -> Arc<dyn Potential> {
        Arc::clone(&self.potential)
    }

    /// A [`Workspace`] of the right size for this body's potential.
    pub fn workspace(&self) -> Workspace {
        Workspace::new(self.n)
    }

    /// Checks X (n×n, finite, det X > 0 if U needs it).
    fn check_x(&self, x: &Mat, ws: &mut Workspace) -> Result<()> {
        check::square_of("X", x, self.n)?;
        potential::check_point(&*self.potential, x, ws)
    }

    /// The Hamiltonian H = ½ tr(PᵀP) + U(X) (001 (3.22)).
    pub fn hamiltonian(&self, x: &Mat, p: &Mat) -> Result<f64> {
        let mut ws = self.workspace();
        self.check_x(x, &mut ws)?;
        check::square_of("P", p, self.n)?;
        Ok(0.5 * linalg::frob2(p.as_ref()) + self.potential.value(x.as_ref(), &mut ws))
    }

    /// Hamilton's vector field (Ẋ, Ṗ) = (P, −∂U/∂X) of H (001 (3.21)–(3.22)).
    pub fn vector_field(&self, x: &Mat, p: &Mat) -> Result<(Mat, Mat)> {
        let mut ws = self.workspace();
        self.check_x(x, &mut ws)?;
        check::square_of("P", p, self.n)?;
        let mut f = Mat::zeros(self.n, self.n);
        self.potential.add_gradient(x.as_ref(), f.as_mut(), &mut ws);
        Ok((p.clone(), -f))
    }

    /// The Riemann-ellipsoid equations (001 (3.20)) in Q = XXᵀ, N = XẊᵀ:
    ///
    /// Ṅ = NᵀQ⁻¹N − 2Q ∂U/∂Q,  Q̇ = N + Nᵀ.
    ///
    /// Derived again from Ẍ = −∂U/∂X: Ṅ = ẊẊᵀ + XẌᵀ with ẊẊᵀ = NᵀQ⁻¹N, and for U = V(Q),
    /// ∂U/∂X = 2(∂V/∂Q)X, so X(∂U/∂X)ᵀ = 2Q ∂V/∂Q — the seed's (3.20a) holds as printed. The force
    /// term is computed as X(∂U/∂X)ᵀ at X = Q^{1/2}; this is the same for every X with XXᵀ = Q
    /// because U is right SO(n)-invariant (the setting U = U(Q) of 001 §3.1). Q must be symmetric
    /// positive definite.
    pub fn riemann_vector_field(&self, q: &Mat, nn: &Mat) -> Result<(Mat, Mat)> {
        let n = self.n;
        check::square_of("Q", q, n)?;
        check::square_of("N", nn, n)?;
        let scale = q.norm_l2().max(1.0);
        let asym = (q - q.transpose()).norm_l2() / scale;
        if asym > 1e-10 {
            return Err(Error::NotInGroup {
                what: "Q".into(),
                group: format!("Sym+({n})"),
                defect_name: "‖Q − Qᵀ‖_F / ‖Q‖_F".into(),
                defect: asym,
                tol: 1e-10,
            });
        }
        let eig = q
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| Error::invalid("Q", format!("eigen-decomposition failed: {e:?}")))?;
        let (v, s) = (eig.U(), eig.S());
        let qmin = (0..n).map(|i| s[i]).fold(f64::INFINITY, f64::min);
        if qmin.is_nan() || qmin <= 0.0 {
            return Err(Error::NotInGroup {
                what: "Q".into(),
                group: format!("Sym+({n})"),
                defect_name: "smallest eigenvalue".into(),
                defect: qmin,
                tol: 0.0,
            });
        }
        let vs = |f: &dyn Fn(f64) -> f64| {
            let d = Mat::from_fn(n, n, |i, j| if i == j { f(s[i]) } else { 0.0 });
            v * d * v.transpose()
        };
        let x = vs(&f64::sqrt);
        let q_inv = vs(&|l: f64| 1.0 / l);
        let mut ws = self.workspace();
        self.check_x(&x, &mut ws)?;
        let mut g = Mat::zeros(n, n);
        self.potential.add_gradient(x.as_ref(), g.as_mut(), &mut ws);
        let n_dot = nn.transpose() * &q_inv * nn - &x * g.transpose();
        let q_dot = nn + nn.transpose();
        Ok((q_dot, n_dot))
    }

    /// The Euler–Lagrange equations of 001 Prop. 4.2 at body coordinates (A, Ω, Λ):
    /// Ä = E − ∂U/∂A, d/dt(RᵀLR) = [RᵀLR, Ω], d/dt(SᵀΓS) = [SᵀΓS, Λ], with E (4.8) and
    /// RᵀLR = p_Ω, SᵀΓS = p_Λ from (4.15).
    ///
    /// Derived again from Ẍ = −∂U/∂X: with M = RᵀẊS = ΩA + Ȧ − AΛ, RᵀẌS = Ṁ + ΩM − MΛ, whose
    /// diagonal is Ä − E; the diagonal of Rᵀ(∂U/∂X)S is ∂U/∂A by invariance. `a` are the
    /// singular values (any order, all > 0), `omega`, `lambda` skew-symmetric n×n.
    pub fn lagrange_vector_field(
        &self,
        a: &[f64],
        omega: &Mat,
        lambda: &Mat,
    ) -> Result<LagrangeRates> {
        let n = self.n;
        check::len_of("a", a, n)?;
        momentum::check_velocities(a, omega, lambda)?;
        let (p_omega, p_lambda) = momentum::body_momenta(a, omega, lambda)?;
        let e = momentum::e_term_unchecked(a, omega, lambda);
        let am = Mat::from_fn(n, n, |i, j| if i == j { a[i] } else { 0.0 });
        let mut ws = self.workspace();
        let mut g = Mat::zeros(n, n);
        self.potential
            .add_gradient(am.as_ref(), g.as_mut(), &mut ws);
        let a_ddot = (0..n).map(|i| e[i] - g[(i, i)]).collect();
        let p_omega_dot = so::bracket(&p_omega, omega);
        let p_lambda_dot = so::bracket(&p_lambda, lambda);
        Ok(LagrangeRates {
            p_omega,
            p_lambda,
            e,
            a_ddot,
            p_omega_dot,
            p_lambda_dot,
        })
    }

    /// The n = 3 equations 001 (5.5): ä = E − ∇U(a), ṁ = m × ω, ċ = c × λ, with m, c from
    /// (5.3) and E from (5.4), for hat(ω) = Ω, hat(λ) = Λ (physics hat map). The seed's
    /// (5.3)–(5.5) agree with Prop. 4.2 under this hat map (checked in the tests).
    pub fn lagrange_vector_field_3d(
        &self,
        a: &Vector3<f64>,
        omega: &Vector3<f64>,
        lambda: &Vector3<f64>,
    ) -> Result<LagrangeRates3> {
        if self.n != 3 {
            return Err(Error::invalid(
                "body",
                format!(
                    "the vector equations (5.5) need n = 3, this body has n = {}",
                    self.n
                ),
            ));
        }
        for (what, v) in [("a", a), ("omega", omega), ("lambda", lambda)] {
            check::finite_slice(what, v.as_slice())?;
        }
        if let Some(i) = a.iter().position(|&ai| ai <= 0.0) {
            return Err(Error::invalid(
                "a",
                format!("singular values must be > 0, got a[{i}] = {}", a[i]),
            ));
        }
        let (w, l) = (omega, lambda);
        let (m, c) = momentum::body_momenta_3(a, w, l);
        let e = momentum::e_term_3(a, w, l);
        let am = Mat::from_fn(3, 3, |i, j| if i == j { a[i] } else { 0.0 });
        let mut ws = self.workspace();
        let mut g = Mat::zeros(3, 3);
        self.potential
            .add_gradient(am.as_ref(), g.as_mut(), &mut ws);
        let grad = Vector3::new(g[(0, 0)], g[(1, 1)], g[(2, 2)]);
        Ok(LagrangeRates3 {
            m,
            c,
            e,
            a_ddot: e - grad,
            m_dot: m.cross(w),
            c_dot: c.cross(l),
        })
    }
}

/// Dedekind's reciprocity: the adjoint motion X ↦ Xᵀ, P ↦ Pᵀ of a sampled trajectory.
///
/// If U(Xᵀ) = U(X) (true for every SO(n)×SO(n)-invariant U, since Xᵀ = SARᵀ has the same
/// singular values), then ∂U/∂X(Xᵀ) = (∂U/∂X(X))ᵀ, so the transposed curve again solves
/// Ẍ = −∂U/∂X, and L(Xᵀ, Pᵀ) = PᵀX − XᵀP = Γ(X, P): angular momentum and circulation swap
/// (the Dedekind ellipsoid is the adjoint of the Jacobi ellipsoid, 000 §5.3).
///
/// `x` and `p` hold k frames of n×n matrices stacked row-major, shape (k, n, n); returns the
/// transposed stacks in the same layout.
pub fn adjoint_motion(n: usize, x: &[f64], p: &[f64]) -> Result<(Vec<f64>, Vec<f64>)> {
    if n < 2 {
        return Err(Error::invalid("n", format!("expected n ≥ 2, got {n}")));
    }
    let nn = n * n;
    if x.len() % nn != 0 {
        return Err(Error::shape(
            "X stack",
            format!("(k, {n}, {n}) = a multiple of {nn} values"),
            format!("{} values", x.len()),
        ));
    }
    check::len_of("P stack", p, x.len())?;
    check::finite_slice("X stack", x)?;
    let transpose = |s: &[f64]| {
        let mut out = vec![0.0; s.len()];
        for (src, dst) in s.chunks_exact(nn).zip(out.chunks_exact_mut(nn)) {
            for i in 0..n {
                for j in 0..n {
                    dst[j * n + i] = src[i * n + j];
                }
            }
        }
        out
    };
    Ok((transpose(x), transpose(p)))
}
