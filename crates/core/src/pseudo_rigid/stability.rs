//! Stability of relative equilibria of the pseudo-rigid body on the principal stratum
//! (001 §8, with the reduced system of §7).
//!
//! # The point
//! A relative equilibrium is taken at its diagonal shape: A₀ = diag(a) (distinct a_i > 0),
//! p_a = 0, constant body velocities Ω, Λ ∈ so(n) and body momenta μ ⊕ ν = B_A(Ω ⊕ Λ)
//! (001 (6.27), (8.14)). It is an equilibrium of the reduced equations (7.27)–(7.28) when
//! [μ, Ω] = 0, [ν, Λ] = 0 (001 (8.6)) and ∂H/∂a = 0 at fixed (μ, ν) (Prop. 8.1).
//!
//! # The symplectic leaf and its chart
//! The reduced Poisson space (a, p_a, μ, ν) has the symplectic leaves
//! ℝⁿ × ℝⁿ × 𝒪_μ × 𝒪_ν (coadjoint orbits, 001 (7.23)); the reduced flow keeps every leaf. Near
//! the point the leaf is charted by ([`Leaf`])
//!
//! (δa, δp_a, c, c') ↦ (a + δa, δp_a, e^{ζ}μe^{−ζ}, e^{ζ'}νe^{−ζ'}), ζ = Σ c_k v_k, ζ' = Σ c'_k w_k,
//!
//! where v_k (w_k) is an orthonormal basis (e_ij coordinates, the pairing of 001 (2.8)) of the
//! complement of the isotropy algebra ker(ζ ↦ [ζ, μ]) of μ (of ν): the right singular vectors of
//! that linear map with nonzero singular values. Directions in the isotropy algebra do not move
//! the point and are removed.
//!
//! # Energy–momentum verdict (Arnold; Simo–Lewis–Marsden)
//! H = ½|p_a|² + K(a, μ, ν) + U(a) with K = ½⟨μ ⊕ ν, B_A⁻¹(μ ⊕ ν)⟩ (001 (6.30), (7.24)). At the
//! point the gradient of H in the chart vanishes (this is (8.9), Prop. 8.2), and the Hessian is
//! - (δa, δa): ∂²(K + U)/∂a² at fixed (μ, ν) — the Hessian of the amended potential (8.8) in the
//!   shape directions — exact: the potential's Hessian and the pair formulas' second derivatives
//!   ([`ReducedState::vector_field_tangent`]);
//! - (δp_a, δp_a) = I, and no (δp_a, ·) coupling;
//! - (δa, c): ∂/∂a_l ⟨[v_k, μ], Ω(a)⟩ (the first variation of (8.9) differentiated in a), exact
//!   from the derivative of Ω ⊕ Λ = B_A⁻¹(μ ⊕ ν) (001 (7.9); [`ReducedState::velocities_tangent`]);
//! - (c, c) exact: e^{ζ}μe^{−ζ} = μ + [ζ, μ] + ½[ζ, [ζ, μ]] + O(ζ³) and K is quadratic in (μ, ν),
//!   so with δm_k = [v_k, μ] ⊕ 0 (or 0 ⊕ [w_k, ν])
//!
//!   ∂²H/∂c_k∂c_l = ½⟨[v_k, [v_l, μ]] + [v_l, [v_k, μ]], Ω⟩ + ⟨δm_k, B_A⁻¹ δm_l⟩
//!
//!   (the first term only for two directions of the same orbit; Λ, ν for the second orbit).
//!
//! If this Hessian is positive definite, H restricted to the leaf has a strict minimum and the
//! relative equilibrium is nonlinearly (formally) stable: stable on its leaf, i.e. modulo the
//! isotropy group of the momentum (energy–momentum method). If it has a negative or zero
//! eigenvalue the test is **inconclusive**, not a proof of instability.
//!
//! # Spectral verdict
//! On the leaf, in the chart, the linearisation of the reduced field (7.24)–(7.28) at an
//! equilibrium is L = Π · D²H: the gradient of H in the chart vanishes, so the derivative of the
//! Poisson tensor does not enter. Π is the Poisson tensor at the point in the chart
//! coordinates: canonical on (δa, δp_a) (ȧ = ∂H/∂p_a, ṗ_a = −∂H/∂a), and on an orbit, from
//! μ̇ = [μ, ∇_μH] = −T∇_μH with T ζ = [ζ, μ] = U_r S_r V_rᵀ ζ (T is skew for the Ad-invariant
//! pairing, so range T = (ker T)^⊥ = span v_k), ċ = −V_rᵀ ∇_μH = −V_rᵀU_r S_r⁻¹ ∂H/∂c.
//! The eigenvalues of L are reported; `stable` = max Re λ ≤ tol · (spectral radius).
//!
//! A second route, independent of the chart, is [`Stability::full_spectrum`]: the Jacobian of
//! the reduced vector field in all coordinates (a, p_a, vee μ, vee ν), exact
//! ([`ReducedState::vector_field_tangent`]).
//! Its spectrum is that of L together with one zero per direction transverse to the leaf (the
//! Casimirs ½tr((μᵀμ)^k), ½tr((νᵀν)^k) are conserved, so the Jacobian maps into the tangent space
//! of the leaf at a point where the orbits are regular). These symmetry-forced zeros are listed in
//! [`Stability::forced_zeros`]; they are removed from the verdict because they belong to
//! neighbouring leaves (other momentum values), not to instability.
//!
//! A positive real part is conclusive (linear, hence nonlinear, instability, Lyapunov); spectral
//! stability alone is not a proof of nonlinear stability.

use crate::check;
use crate::error::{Error, Result};
use crate::lie::so;
use crate::numerics::linalg::norm;
use crate::pseudo_rigid::dynamics::FullBody;
use crate::pseudo_rigid::momentum;
use crate::pseudo_rigid::reduced::ReducedState;
use crate::Mat;

pub use crate::analysis::Verdict;
use crate::analysis::{general_eigenvalues, sorted};

/// Relative tolerance of the equilibrium check (residual of the reduced vector field relative
/// to the scales of its terms).
pub const EQUILIBRIUM_TOL: f64 = 1e-8;

/// Relative tolerance of the energy–momentum verdict: positive definite means every Hessian
/// eigenvalue exceeds this times the largest |eigenvalue|.
pub const HESSIAN_TOL: f64 = 1e-8;

/// Relative tolerance of the spectral verdict: stable means max Re λ ≤ this times the spectral
/// radius. Eigenvalues of a Hamiltonian matrix that meet (Krein collisions, Jordan blocks) move
/// by ~√(error of the matrix), hence the loose value.
pub const SPECTRAL_TOL: f64 = 1e-6;

/// Stability analysis of a relative equilibrium ([`stability`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Stability {
    /// The energy–momentum (Arnold) test: definiteness of D²H on the symplectic leaf.
    pub energy_momentum: Verdict,
    /// The spectral test: eigenvalues of the linearised reduced flow on the leaf.
    pub spectral: Verdict,
    /// The Hessian D²H in the leaf chart (order δa, δp_a, c, c'), symmetric.
    pub hessian: Mat,
    /// The linearisation L = Π D²H of the reduced field on the leaf (same order).
    pub linearisation: Mat,
    /// Dimension of the leaf, 2n + dim 𝒪_μ + dim 𝒪_ν.
    pub leaf_dim: usize,
    /// Eigenvalues (re, im) of the Jacobian of the reduced field in all coordinates
    /// (a, p_a, vee μ, vee ν) (second route, module docs), by descending real part.
    pub full_spectrum: Vec<(f64, f64)>,
    /// The 2·dim so(n) − dim 𝒪_μ − dim 𝒪_ν eigenvalues of [`Stability::full_spectrum`] smallest
    /// in modulus: the zeros forced by the Casimirs (directions transverse to the leaf), listed
    /// as computed (≈ 0 up to the finite-difference error).
    pub forced_zeros: Vec<(f64, f64)>,
    /// Relative residual of the reduced vector field at the point (≤ [`EQUILIBRIUM_TOL`]).
    pub residual: f64,
    /// |∇H| in the leaf chart at the point, relative to the scales of its terms (≈ 0: the point
    /// is critical on the leaf, 001 (8.9)).
    pub gradient: f64,
}

/// A chart of the symplectic leaf ℝⁿ × ℝⁿ × 𝒪_μ × 𝒪_ν through a reduced state (module docs).
#[derive(Debug, Clone)]
pub struct Leaf {
    /// The base point (the chart's origin).
    pub base: ReducedState,
    /// Orthonormal basis v_k (skew n×n) of the complement of the isotropy algebra of μ.
    pub basis_omega: Vec<Mat>,
    /// Orthonormal basis w_k of the complement of the isotropy algebra of ν.
    pub basis_lambda: Vec<Mat>,
    /// The Poisson tensor of the orbit of μ in the coordinates c: −V_rᵀU_r S_r⁻¹.
    poisson_omega: Mat,
    /// The same for ν.
    poisson_lambda: Mat,
}

impl Leaf {
    /// The chart through `base` (validated, see [`ReducedState::validate`]).
    pub fn new(base: ReducedState) -> Result<Self> {
        base.validate()?;
        let (basis_omega, poisson_omega) = orbit_chart(&base.p_omega)?;
        let (basis_lambda, poisson_lambda) = orbit_chart(&base.p_lambda)?;
        Ok(Leaf {
            base,
            basis_omega,
            basis_lambda,
            poisson_omega,
            poisson_lambda,
        })
    }

    /// n.
    pub fn n(&self) -> usize {
        self.base.a.len()
    }

    /// The leaf dimension 2n + r + r' (r, r' the orbit dimensions).
    pub fn dim(&self) -> usize {
        2 * self.n() + self.basis_omega.len() + self.basis_lambda.len()
    }

    /// The point of the leaf with chart coordinates (δa, δp_a, c, c'):
    /// (a + δa, p_a + δp_a, e^{ζ}μe^{−ζ}, e^{ζ'}νe^{−ζ'}) with ζ = Σ c_k v_k, ζ' = Σ c'_k w_k.
    pub fn point(&self, coords: &[f64]) -> Result<ReducedState> {
        check::len_of("leaf coordinates", coords, self.dim())?;
        check::finite_slice("leaf coordinates", coords)?;
        let n = self.n();
        let r = self.basis_omega.len();
        let (da, rest) = coords.split_at(n);
        let (dp, rest) = rest.split_at(n);
        let (c1, c2) = rest.split_at(r);
        let conj = |basis: &[Mat], c: &[f64], m: &Mat| -> Result<Mat> {
            let mut zeta = Mat::zeros(n, n);
            for (v, &ck) in basis.iter().zip(c) {
                zeta += v * ck;
            }
            let g = so::exp(&zeta)?;
            Ok(&g * m * g.transpose())
        };
        let state = ReducedState {
            a: self.base.a.iter().zip(da).map(|(a, d)| a + d).collect(),
            p_a: self.base.p_a.iter().zip(dp).map(|(p, d)| p + d).collect(),
            p_omega: conj(&self.basis_omega, c1, &self.base.p_omega)?,
            p_lambda: conj(&self.basis_lambda, c2, &self.base.p_lambda)?,
        };
        state.validate()?;
        Ok(state)
    }

    /// The Poisson tensor Π at the base point in the chart coordinates (module docs): canonical
    /// on (δa, δp_a), −V_rᵀU_r S_r⁻¹ on each orbit block.
    pub fn poisson(&self) -> Mat {
        let n = self.n();
        let r = self.basis_omega.len();
        let mut pi = Mat::zeros(self.dim(), self.dim());
        for i in 0..n {
            pi[(i, n + i)] = 1.0;
            pi[(n + i, i)] = -1.0;
        }
        for (off, block) in [
            (2 * n, &self.poisson_omega),
            (2 * n + r, &self.poisson_lambda),
        ] {
            for i in 0..block.nrows() {
                for j in 0..block.ncols() {
                    pi[(off + i, off + j)] = block[(i, j)];
                }
            }
        }
        pi
    }
}

/// The linear map T: ζ ↦ [ζ, m] on so(n) in e_ij coordinates (a d×d matrix).
fn bracket_matrix(m: &Mat) -> Mat {
    let n = m.nrows();
    let d = so::dim(n);
    let mut t = Mat::zeros(d, d);
    let mut e = vec![0.0; d];
    for k in 0..d {
        e[k] = 1.0;
        let col = so::vee_n_unchecked(&so::bracket(&so::hat_n_unchecked(n, &e), m));
        e[k] = 0.0;
        for (i, x) in col.into_iter().enumerate() {
            t[(i, k)] = x;
        }
    }
    t
}

/// Basis of the complement of the isotropy algebra of m (right singular vectors of T with
/// nonzero singular values) and the orbit Poisson tensor −V_rᵀU_r S_r⁻¹ (module docs).
fn orbit_chart(m: &Mat) -> Result<(Vec<Mat>, Mat)> {
    let n = m.nrows();
    let t = bracket_matrix(m);
    let svd = t.svd().map_err(|e| Error::NotConverged {
        what: format!("SVD of ζ ↦ [ζ, μ] ({e:?})"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    })?;
    let (u, s, v) = (svd.U(), svd.S(), svd.V());
    let d = t.nrows();
    let smax = if d > 0 { s[0] } else { 0.0 };
    let r = (0..d)
        .filter(|&k| s[k] > 1e-10 * smax && s[k] > 0.0)
        .count();
    let basis = (0..r)
        .map(|k| so::hat_n_unchecked(n, &(0..d).map(|i| v[(i, k)]).collect::<Vec<_>>()))
        .collect();
    let mut pi = Mat::zeros(r, r);
    for i in 0..r {
        for j in 0..r {
            let vu: f64 = (0..d).map(|l| v[(l, i)] * u[(l, j)]).sum();
            pi[(i, j)] = -vu / s[j];
        }
    }
    Ok((basis, pi))
}

/// Stability of the relative equilibrium A₀ = diag(a), p_a = 0, body velocities Ω, Λ
/// (momenta μ ⊕ ν = B_A(Ω ⊕ Λ), 001 (6.27)): the energy–momentum and the spectral verdicts on
/// the symplectic leaf through the point (module docs; 001 §8).
///
/// Errors: shapes, non-finite input, a_i ≤ 0 or not distinct ([`Error::DegenerateStratum`]),
/// Ω, Λ not skew, a body of another dimension, and [`Error::InvalidArgument`] with the residual
/// when the point is not an equilibrium of the reduced equations (relative residual above
/// [`EQUILIBRIUM_TOL`]); [`Error::NonFinite`] if the potential is not finite near the point.
pub fn stability(body: &FullBody, a: &[f64], omega: &Mat, lambda: &Mat) -> Result<Stability> {
    let n = body.n();
    check::len_of("a", a, n)?;
    check::finite_slice("a", a)?;
    so::check_algebra_of("omega", omega, n)?;
    so::check_algebra_of("lambda", lambda, n)?;
    let (mu, nu) = momentum::body_momenta(a, omega, lambda)?;
    let base = ReducedState {
        a: a.to_vec(),
        p_a: vec![0.0; n],
        p_omega: mu,
        p_lambda: nu,
    };
    let leaf = Leaf::new(base)?;
    let base = &leaf.base;
    let (mu, nu) = (&base.p_omega, &base.p_lambda);
    let d = so::dim(n);

    // The reduced field at the point and its scales.
    let rates = base.vector_field(body)?;
    let (om, la) = base.velocities()?;
    let grad_u = potential_gradient(body, a)?;
    let grad_k: Vec<f64> = rates
        .p_a_dot
        .iter()
        .zip(&grad_u)
        .map(|(f, gu)| -f - gu)
        .collect();

    // (δa, δa): ∂(∂H/∂a)/∂a_l = −δṗ_a along e_l (the field's exact derivative), and the
    // orbit velocities' derivatives δΩ, δΛ along it.
    let along_a = |l: usize| {
        let mut e = ReducedState {
            a: vec![0.0; n],
            p_a: vec![0.0; n],
            p_omega: Mat::zeros(n, n),
            p_lambda: Mat::zeros(n, n),
        };
        e.a[l] = 1.0;
        e
    };
    let mut haa = Mat::zeros(n, n);
    let mut dvel = Vec::with_capacity(n);
    for l in 0..n {
        let e = along_a(l);
        let rates = base.vector_field_tangent(body, &e)?;
        for k in 0..n {
            haa[(k, l)] = -rates.p_a_dot[k];
        }
        dvel.push(base.velocities_tangent(&e));
    }
    // (δa, c): ∂/∂a_l of the orbit gradients ⟨[v_k, μ], Ω(a)⟩, ⟨[w_k, ν], Λ(a)⟩.
    let tang_mu: Vec<Mat> = leaf
        .basis_omega
        .iter()
        .map(|v| so::bracket(v, mu))
        .collect();
    let tang_nu: Vec<Mat> = leaf
        .basis_lambda
        .iter()
        .map(|w| so::bracket(w, nu))
        .collect();
    let orbit_grad = |(o, l): &(Mat, Mat)| -> Vec<f64> {
        tang_mu
            .iter()
            .map(|t| so::pairing(t, o))
            .chain(tang_nu.iter().map(|t| so::pairing(t, l)))
            .collect()
    };
    // Rows: orbit directions, columns: a_l.
    let columns: Vec<Vec<f64>> = dvel.iter().map(orbit_grad).collect();
    let hac = Mat::from_fn(columns[0].len(), n, |k, l| columns[l][k]);
    let g_orbit = orbit_grad(&(om.clone(), la.clone()));

    // (c, c): exact second variation of K along the orbits.
    let r1 = tang_mu.len();
    let rr = r1 + tang_nu.len();
    let dm: Vec<(Mat, Mat)> = tang_mu
        .iter()
        .map(|t| (t.clone(), Mat::zeros(n, n)))
        .chain(tang_nu.iter().map(|t| (Mat::zeros(n, n), t.clone())))
        .collect();
    let binv: Vec<(Mat, Mat)> = dm
        .iter()
        .map(|(x, y)| {
            ReducedState {
                a: a.to_vec(),
                p_a: vec![0.0; n],
                p_omega: x.clone(),
                p_lambda: y.clone(),
            }
            .velocities()
        })
        .collect::<Result<_>>()?;
    let mut hcc = Mat::zeros(rr, rr);
    for k in 0..rr {
        for l in 0..rr {
            let mut h = so::pairing(&dm[k].0, &binv[l].0) + so::pairing(&dm[k].1, &binv[l].1);
            if k < r1 && l < r1 {
                let (vk, vl) = (&leaf.basis_omega[k], &leaf.basis_omega[l]);
                let dd = so::bracket(vk, &tang_mu[l]) + so::bracket(vl, &tang_mu[k]);
                h += 0.5 * so::pairing(&dd, &om);
            } else if k >= r1 && l >= r1 {
                let (wk, wl) = (&leaf.basis_lambda[k - r1], &leaf.basis_lambda[l - r1]);
                let dd = so::bracket(wk, &tang_nu[l - r1]) + so::bracket(wl, &tang_nu[k - r1]);
                h += 0.5 * so::pairing(&dd, &la);
            }
            hcc[(k, l)] = h;
        }
    }

    // Assemble D²H in the order (δa, δp_a, c, c').
    let dim = leaf.dim();
    let mut hess = Mat::zeros(dim, dim);
    for i in 0..n {
        for j in 0..n {
            hess[(i, j)] = 0.5 * (haa[(i, j)] + haa[(j, i)]);
        }
        hess[(n + i, n + i)] = 1.0;
    }
    for k in 0..rr {
        for l in 0..n {
            hess[(2 * n + k, l)] = hac[(k, l)];
            hess[(l, 2 * n + k)] = hac[(k, l)];
        }
        for l in 0..rr {
            hess[(2 * n + k, 2 * n + l)] = 0.5 * (hcc[(k, l)] + hcc[(l, k)]);
        }
    }
    check::finite_mat(
        "Hessian of the reduced Hamiltonian (potential near the point)",
        &hess,
    )?;

    // Equilibrium check: relative residual of (ṗ_a, μ̇, ν̇).
    let stiff = max_abs(&haa) * a.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let f_scale = norm(&grad_u).max(norm(&grad_k)).max(stiff);
    let ratio = |num: f64, den: f64| {
        if num == 0.0 {
            0.0
        } else if den > 0.0 {
            num / den
        } else {
            f64::INFINITY
        }
    };
    let residual = ratio(norm(&rates.p_a_dot), f_scale)
        .max(ratio(
            rates.p_omega_dot.norm_l2(),
            mu.norm_l2() * om.norm_l2(),
        ))
        .max(ratio(
            rates.p_lambda_dot.norm_l2(),
            nu.norm_l2() * la.norm_l2(),
        ));
    if residual.is_nan() || residual > EQUILIBRIUM_TOL {
        return Err(Error::invalid(
            "relative equilibrium (a, omega, lambda)",
            format!(
                "not an equilibrium of the reduced equations (001 (7.27)-(7.28), (8.6)): relative \
                 residual {residual:.3e} > {EQUILIBRIUM_TOL:.0e} (|dp_a/dt| = {:.3e}, \
                 |[mu, Omega]| = {:.3e}, |[nu, Lambda]| = {:.3e})",
                norm(&rates.p_a_dot),
                rates.p_omega_dot.norm_l2(),
                rates.p_lambda_dot.norm_l2()
            ),
        ));
    }
    let g_scale = mu.norm_l2() * om.norm_l2() + nu.norm_l2() * la.norm_l2();
    let gradient = ratio(norm(&rates.p_a_dot), f_scale).max(ratio(norm(&g_orbit), g_scale));

    // Energy–momentum verdict.
    let energy_momentum = Verdict::energy_momentum(&hess, HESSIAN_TOL)?;

    // Spectral verdict: L = Π D²H on the leaf.
    let lin = leaf.poisson() * &hess;
    let spectral = Verdict::spectral(&lin, SPECTRAL_TOL)?;

    // Second route: the Jacobian in all coordinates (a, p_a, vee μ, vee ν).
    let z0: Vec<f64> = a
        .iter()
        .chain(&base.p_a)
        .copied()
        .chain(so::vee_n_unchecked(mu))
        .chain(so::vee_n_unchecked(nu))
        .collect();
    let state_of = |z: &[f64]| ReducedState {
        a: z[..n].to_vec(),
        p_a: z[n..2 * n].to_vec(),
        p_omega: so::hat_n_unchecked(n, &z[2 * n..2 * n + d]),
        p_lambda: so::hat_n_unchecked(n, &z[2 * n + d..]),
    };
    let nz = z0.len();
    let mut jac = Mat::zeros(nz, nz);
    let mut e = vec![0.0; nz];
    for l in 0..nz {
        e[l] = 1.0;
        let f = base.vector_field_tangent(body, &state_of(&e))?;
        e[l] = 0.0;
        let col = f
            .a_dot
            .into_iter()
            .chain(f.p_a_dot)
            .chain(so::vee_n_unchecked(&f.p_omega_dot))
            .chain(so::vee_n_unchecked(&f.p_lambda_dot));
        for (k, x) in col.enumerate() {
            jac[(k, l)] = x;
        }
    }
    check::finite_mat("Jacobian of the reduced vector field", &jac)?;
    let mut full = general_eigenvalues(&jac)?;
    let transverse = 2 * d - rr;
    full.sort_by(|x, y| x.0.hypot(x.1).total_cmp(&y.0.hypot(y.1)));
    let forced_zeros = full[..transverse.min(full.len())].to_vec();
    let full_spectrum = sorted(full);

    Ok(Stability {
        energy_momentum,
        spectral,
        hessian: hess,
        linearisation: lin,
        leaf_dim: dim,
        full_spectrum,
        forced_zeros,
        residual,
        gradient,
    })
}

/// ∂U/∂a at diag(a) (the diagonal of ∂U/∂X, by invariance).
fn potential_gradient(body: &FullBody, a: &[f64]) -> Result<Vec<f64>> {
    let n = a.len();
    let x = Mat::from_fn(n, n, |i, j| if i == j { a[i] } else { 0.0 });
    let g = crate::pseudo_rigid::potential::gradient(body.potential(), &x)?;
    Ok((0..n).map(|i| g[(i, i)]).collect())
}

fn max_abs(m: &Mat) -> f64 {
    let mut x = 0.0_f64;
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            x = x.max(m[(i, j)].abs());
        }
    }
    x
}
