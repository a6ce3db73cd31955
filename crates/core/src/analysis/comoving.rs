//! Linear and energy–momentum stability of a relative equilibrium of a (constrained) mechanical
//! system, in the co-moving frame and without reduction: the route that works where reduced
//! coordinates do not exist (coincident semi-axes of a Maclaurin spheroid, larger isotropy), and
//! with holonomic constraints (an incompressible body).
//!
//! # Setting
//! A [`Constrained`] system (H = ½pᵀM⁻¹p + U(q) on T*{g = c}; with m = 0 constraints any
//! [`Separable`](crate::integrate::problem::Separable) system) with a linear symmetry
//! ([`Symmetric`]: momentum map J, generators η_Z). A relative equilibrium is a state z₀ and a
//! ξ ∈ g such that z(t) = exp(tξ)·z₀ is a motion: the co-moving field F(z) = f(z) − ξ_Z(z)
//! vanishes at z₀, f being the index-1 constrained field ż = (M⁻¹p, f − Gᵀλ(q, p))
//! ([`constrained_field`]).
//!
//! # The symplectic normal space
//! Variations δz are taken in S = T_{z₀}N ∩ ker dJ(z₀): tangent to the constrained phase space
//! N = {g(q) = c, G(q)M⁻¹p = 0} and keeping the momentum. The directions η_Z(z₀) with
//! dJ·η_Z = −ad*_η μ = 0 — the orbit of the isotropy group G_μ of μ = J(z₀) — are neutral (they
//! lead to the same relative equilibrium, moved by the symmetry), and are removed: C is an
//! orthonormal basis of the orthogonal complement of span{η_Z(z₀) : η ∈ g_μ} in S. Its dimension
//! is that of the symplectic normal space of Simo, Lewis & Marsden (1991).
//!
//! # Spectral verdict
//! L = Cᵀ DF(z₀) C. DF maps S into S (J is conserved and equivariant, ξ ∈ g_μ) and the orbit
//! directions into themselves (DF η_Z = [η, ξ]_Z for η ∈ g_μ, a subalgebra containing ξ), so L
//! is the linearisation on the quotient. DF from the derivative of the constrained field
//! ([`constrained_field_tangent`]: the system's force Hessian, the constraints' second and, where
//! given, third derivatives) and of the generator (linear in z).
//!
//! # Energy–momentum verdict
//! H_ξ = H − ⟨J, ξ⟩ is critical at z₀ on N (z₀ is a relative equilibrium), so
//! ∇H_ξ(z₀) = dΦᵀκ for the constraint map Φ = (g(q), G(q)M⁻¹p) and multipliers κ (least
//! squares). The second variation of H_ξ on N is that of the Lagrange function
//! ℒ = H_ξ − κ·Φ on T_{z₀}N; restricted to C it is the energy–momentum Hessian: positive
//! definite ⇒ the relative equilibrium is nonlinearly stable modulo G_μ (Patrick 1992; Simo,
//! Lewis & Marsden 1991).
//!
//! # Units
//! Positions and momenta have different units. The subspaces are built and orthonormalised in
//! the scaled coordinates z̃ = (q/ℓ, p/π) (ℓ = ‖q₀‖, π = ‖p₀‖, or ℓ·√(‖∇U‖/ℓ) at rest), the
//! finite-difference steps follow the same scales, and both matrices are those of the scaled
//! coordinates: the verdicts and the relative tolerances do not depend on the units.
//!
//! # Derivatives
//! The energy–momentum Hessian is exact wherever the system gives the derivatives (issue 26):
//! D²U = −f′ and M⁻¹ from [`SeparableTangent`] (analytic potential Hessians), ∇⟨J, ξ⟩ =
//! (−ξ_Z^p, ξ_Z^q) from the generator (J is the momentum map of a cotangent-lifted linear
//! action, so ⟨J, ξ⟩ generates ξ_Z and its Hessian is linear in z), dJ the same way, D²g by
//! polarisation of the curvature form, D³g(q)\[M⁻¹p, ·, ·\] (which multiplies the hidden
//! constraints' multipliers, zero at a relative equilibrium) from
//! [`Constrained::constraint_third`] where given, else by central differences.
//! So the verdict's margin is accurate to round-off and a change of the verdict along a family
//! is located to ~1e-12 (the Maclaurin–Jacobi bifurcation; by nested differences it was 7e-9).
//! The spectral verdict's DF is exact likewise: the multiplier's derivative needs
//! D³g\[δq, v, v\], in closed form where the constraint gives it
//! ([`Constrained::constraint_third`]: the incompressible body at n = 3, the sphere), else by
//! central differences of the curvature along δq.

use super::Verdict;
use crate::check;
use crate::error::{Error, Result};
use crate::integrate::methods::rattle::{constrained_field, constrained_field_tangent};
use crate::integrate::problem::{Constrained, Symmetric};
use crate::integrate::tangent::SeparableTangent;
use crate::numerics::fd::{self, Scheme::Richardson};
use crate::numerics::linalg::norm;
use crate::Mat;
use faer::linalg::solvers::Solve;

/// Relative tolerance of the relative-equilibrium check: |F(z₀)| ≤ this · (|f(z₀)| + |ξ_Z(z₀)|).
pub const EQUILIBRIUM_TOL: f64 = 1e-8;

/// Relative tolerance of the energy–momentum verdict (of the Hessian's eigenvalues).
pub const HESSIAN_TOL: f64 = 1e-7;

/// Relative tolerance of the spectral verdict (of max Re λ against the spectral radius): an
/// error δ in the Jacobian (round-off, or ~1e-11 where D³g comes from differences) moves
/// eigenvalues that meet (Krein collisions) by √δ.
pub const SPECTRAL_TOL: f64 = 1e-5;

/// The stability of a relative equilibrium in the co-moving frame ([`stability`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Stability {
    /// Definiteness of the second variation of H − ⟨J, ξ⟩ on the symplectic normal space.
    pub energy_momentum: Verdict,
    /// Eigenvalues of the co-moving linearisation on the symplectic normal space.
    pub spectral: Verdict,
    /// The dimension of the symplectic normal space (the size of both matrices).
    pub normal_dim: usize,
    /// The dimension of the isotropy orbit G_μ·z₀ removed from it.
    pub isotropy_orbit_dim: usize,
    /// The multipliers κ of the constraint map (g, G M⁻¹p) at z₀ (for an incompressible body:
    /// the pressure, with the sign of ∂H_ξ/∂g).
    pub multipliers: Vec<f64>,
    /// |F(z₀)| relative to |f(z₀)| + |ξ_Z(z₀)|.
    pub residual: f64,
    /// The oscillatory normal modes of the linearisation (eigenvalues with Im λ > 0), by
    /// ascending frequency.
    pub modes: Vec<Mode>,
}

/// A normal mode of a relative equilibrium: an eigenvalue λ = σ + iω (ω > 0) of the co-moving
/// linearisation on the symplectic normal space and its eigenvector in the state's coordinates;
/// the linear motion about z₀ in the co-moving frame is Re(v e^{λt}).
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// λ = (σ, ω).
    pub eigenvalue: (f64, f64),
    /// Re v (user frame), v scaled to unit length in the scaled coordinates (q/‖q₀‖, p/π)
    /// and turned so that its real part is the longest.
    pub re: Vec<f64>,
    /// Im v.
    pub im: Vec<f64>,
}

/// The oscillatory eigenpairs of `lin` (k × k, scaled coordinates) as modes in z through the
/// basis `cs` (scaled) and the scales `w` (z = diag(w)·cs·v).
fn modes(lin: &Mat, cs: &Mat, w: &[f64], tol: f64) -> Result<Vec<Mode>> {
    if lin.nrows() == 0 {
        return Ok(Vec::new());
    }
    let evd = lin
        .eigen()
        .map_err(|e| super::eig_error("eigenvectors of the linearisation", e))?;
    let (u, s) = (evd.U(), evd.S().column_vector());
    let mut out = Vec::new();
    for k in 0..s.nrows() {
        let lam = s[k];
        if lam.im <= tol {
            continue;
        }
        // In scaled coordinates: a + ib = cs·v.
        let nz = cs.nrows();
        let a: Vec<f64> = (0..nz)
            .map(|i| (0..cs.ncols()).map(|j| cs[(i, j)] * u[(j, k)].re).sum())
            .collect();
        let b: Vec<f64> = (0..nz)
            .map(|i| (0..cs.ncols()).map(|j| cs[(i, j)] * u[(j, k)].im).sum())
            .collect();
        let (aa, bb, ab) = (
            a.iter().map(|x| x * x).sum::<f64>(),
            b.iter().map(|x| x * x).sum::<f64>(),
            a.iter().zip(&b).map(|(x, y)| x * y).sum::<f64>(),
        );
        let length = (aa + bb).sqrt();
        if !(length > 0.0 && length.is_finite()) {
            continue;
        }
        // e^{iθ}(a + ib) has the longest real part a cos θ − b sin θ at tan 2θ = −2ab/(aa − bb).
        let theta = 0.5 * (-2.0 * ab).atan2(aa - bb);
        let (sn, cs_) = theta.sin_cos();
        out.push(Mode {
            eigenvalue: (lam.re, lam.im),
            re: (0..nz)
                .map(|i| w[i] * (a[i] * cs_ - b[i] * sn) / length)
                .collect(),
            im: (0..nz)
                .map(|i| w[i] * (a[i] * sn + b[i] * cs_) / length)
                .collect(),
        });
    }
    out.sort_by(|x, y| x.eigenvalue.1.total_cmp(&y.eigenvalue.1));
    Ok(out)
}

/// Stability of the relative equilibrium z(t) = exp(tξ)·z₀ (module docs): z₀ a state (user
/// frame, on the constraint manifold), ξ ∈ g in the coordinates of [`Symmetric`].
///
/// Errors: wrong lengths, non-finite input, a state the system refuses, and
/// [`Error::InvalidArgument`] with the residual when F(z₀) ≠ 0 (relative residual above
/// [`EQUILIBRIUM_TOL`]: not a relative equilibrium with this ξ).
pub fn stability<P: Constrained + Symmetric + SeparableTangent>(
    problem: &P,
    z0: &[f64],
    xi: &[f64],
) -> Result<Stability> {
    let d = problem.dof();
    let m = problem.constraints();
    let nz = 2 * d;
    let g = problem.symmetry_dim();
    check::len_of("state", z0, nz)?;
    check::finite_slice("state", z0)?;
    check::len_of("xi", xi, g)?;
    check::finite_slice("xi", xi)?;
    problem.check_state(z0)?;
    let mut scratch = problem.scratch();

    // The co-moving field F = f − ξ_Z (user frame = internal frame is required: see below).
    let mut probe = z0.to_vec();
    problem.to_internal(&mut probe);
    if probe != z0 {
        return Err(Error::invalid(
            "system",
            format!(
                "{} works in another frame than the user's; the co-moving analysis needs the same",
                problem.name()
            ),
        ));
    }
    let field = |z: &[f64], s: &mut P::Scratch| -> Result<Vec<f64>> {
        let mut dz = vec![0.0; nz];
        constrained_field(problem, z, &mut dz, s)?;
        Ok(dz)
    };
    let f0 = field(z0, &mut scratch)?;
    let gen0 = problem.generator(xi, z0)?;
    let resid: Vec<f64> = f0.iter().zip(&gen0).map(|(a, b)| a - b).collect();
    // The scale of the terms that cancel at a relative equilibrium: the velocity, the potential
    // force (balanced by the constraint force: hydrostatic equilibrium of a near-static figure),
    // and the generator ‖ξ‖‖z₀‖.
    let mut force0 = vec![0.0; d];
    problem
        .force(&z0[..d], &mut force0, &mut scratch)
        .map_err(|v| v.at_start())?;
    let scale = norm(&f0) + norm(&gen0) + norm(&force0) + norm(xi) * norm(z0);
    let residual = if norm(&resid) == 0.0 {
        0.0
    } else {
        norm(&resid) / scale
    };
    if residual.is_nan() || residual > EQUILIBRIUM_TOL {
        return Err(Error::invalid(
            "relative equilibrium (state, xi)",
            format!(
                "the co-moving field f(z) − ξ_Z(z) does not vanish: relative residual \
                 {residual:.3e} > {EQUILIBRIUM_TOL:.0e}"
            ),
        ));
    }

    // Constraint map Φ = (g(q), G(q)M⁻¹p) and its gradient rows at z₀.
    let dphi = grad_phi(problem, z0, &mut scratch);

    // dJ, exact: row a is ∇J_a = (−(e_a)_Z^p, (e_a)_Z^q) (`pairing_gradient`); the generators
    // η_Z(z₀).
    let mut dj = Mat::zeros(g, nz);
    let mut e = vec![0.0; g];
    for a in 0..g {
        e[a] = 1.0;
        for (l, x) in pairing_gradient(problem, &e, z0)?.into_iter().enumerate() {
            dj[(a, l)] = x;
        }
        e[a] = 0.0;
    }
    let mut gens = Mat::zeros(nz, g);
    for k in 0..g {
        e[k] = 1.0;
        let col = problem.generator(&e, z0)?;
        e[k] = 0.0;
        for (i, x) in col.into_iter().enumerate() {
            gens[(i, k)] = x;
        }
    }

    // Positions and momenta have different units: the subspaces are built, and orthonormalised,
    // in the scaled coordinates z̃ = (q/ℓ, p/π) with ℓ = ‖q‖ and π = ‖p‖, or for a state at
    // rest the momentum ℓ·√(‖∇U‖/ℓ) the potential's force builds up in unit time. So the
    // verdicts and their tolerances do not depend on the units (of time, mass or length).
    let zscale = norm(z0).max(1.0);
    let (q0, p0) = z0.split_at(d);
    let ell = norm(q0).max(f64::MIN_POSITIVE);
    let pi = norm(p0).max(ell * (norm(&force0) / ell).sqrt());
    let pi = if pi > 0.0 { pi } else { 1.0 };
    let wz: Vec<f64> = (0..nz).map(|i| if i < d { ell } else { pi }).collect();

    // S = ker [dΦ; dJ]; the isotropy orbit W = Gen · ker(dJ · Gen); C = S ⊖ W (in z̃: row
    // vectors times diag(w), generators divided by w).
    let rows = 2 * m + g;
    let stack = Mat::from_fn(rows, nz, |i, j| {
        wz[j]
            * if i < 2 * m {
                dphi[i][j]
            } else {
                dj[(i - 2 * m, j)]
            }
    });
    let gens_s = Mat::from_fn(nz, g, |i, j| gens[(i, j)] / wz[i]);
    let s_basis = super::null_space(&stack)?;
    let iso = super::null_space(&(&dj * &gens))?;
    let w_basis = super::range(&(&gens_s * &iso))?;
    // Coordinates of W in S, then the complement inside S.
    let w_in_s = s_basis.transpose() * &w_basis;
    let comp = super::null_space(&w_in_s.transpose().to_owned())?;
    let cs = &s_basis * &comp;
    let k = cs.ncols();
    // C in z (columns diag(w)·c̃) and its left inverse on the normal space, c̃ᵀ diag(1/w).
    let c = Mat::from_fn(nz, k, |i, j| wz[i] * cs[(i, j)]);
    let c_left = Mat::from_fn(k, nz, |i, j| cs[(j, i)] / wz[j]);

    // Spectral: L = C⁺ DF C with C⁺ = c̃ᵀ diag(1/w), the linearisation in z̃ on the normal space.
    // Steps: positions on the scale of ‖q‖, momenta on that of ‖p‖ or, for a state at rest, of
    // the momentum ‖q‖·√(‖∇U‖/‖q‖) the potential's force would build up in unit time; the two
    // blocks have different units, so one scale would misjudge one of them.
    let hz: Vec<f64> = z0
        .iter()
        .zip(&wz)
        .map(|(x, w)| 1e-4 * x.abs().max(1e-2 * w))
        .collect();
    let df = comoving_jacobian(problem, xi, z0, &hz)?;
    check::finite_mat("co-moving Jacobian", &df)?;
    let lin = &c_left * &df * &c;
    let spectral = Verdict::spectral(&lin, SPECTRAL_TOL)?;
    let modes = modes(&lin, &cs, &wz, spectral.tol)?;

    // Energy–momentum: multipliers κ from ∇H_ξ = dΦᵀκ, then Cᵀ D²ℒ C.
    let mut gh0 = vec![0.0; nz];
    {
        let (gq, gp) = gh0.split_at_mut(d);
        gq.copy_from_slice(&force0);
        gq.iter_mut().for_each(|x| *x = -*x);
        problem.velocity(p0, gp);
    }
    for (x, y) in gh0.iter_mut().zip(pairing_gradient(problem, xi, z0)?) {
        *x -= y;
    }
    let multipliers = if m == 0 {
        Vec::new()
    } else {
        // Least squares by the normal equations (2m unknowns, m small).
        let a = Mat::from_fn(nz, 2 * m, |i, j| dphi[j][i]);
        let b = Mat::from_fn(nz, 1, |i, _| gh0[i]);
        let sol = (a.transpose() * &a)
            .partial_piv_lu()
            .solve(&(a.transpose() * &b));
        (0..2 * m).map(|i| sol[(i, 0)]).collect::<Vec<f64>>()
    };
    let hess = lagrange_hessian(problem, xi, z0, &multipliers, zscale, &mut scratch)?;
    let hc = c.transpose() * &hess * &c;
    let hsym = Mat::from_fn(k, k, |i, j| 0.5 * (hc[(i, j)] + hc[(j, i)]));
    check::finite_mat("energy–momentum Hessian", &hsym)?;
    let energy_momentum = Verdict::energy_momentum(&hsym, HESSIAN_TOL)?;

    Ok(Stability {
        energy_momentum,
        spectral,
        normal_dim: k,
        isotropy_orbit_dim: w_basis.ncols(),
        multipliers,
        residual,
        modes,
    })
}

/// D²g(q)\[v, e_k\] for every constraint a and coordinate k (rows\[a\]\[k\]), by polarisation of
/// the quadratic form D²g(q)\[w, w\] (exact up to round-off).
fn curvature_rows<P: Constrained>(
    problem: &P,
    q: &[f64],
    v: &[f64],
    s: &mut P::Scratch,
) -> Vec<Vec<f64>> {
    let (d, m) = (problem.dof(), problem.constraints());
    let mut rows = vec![vec![0.0; d]; m];
    let (mut cp, mut cm) = (vec![0.0; m], vec![0.0; m]);
    let mut w = v.to_vec();
    for k in 0..d {
        w[k] = v[k] + 1.0;
        problem.constraint_curvature(q, &w, &mut cp, s);
        w[k] = v[k] - 1.0;
        problem.constraint_curvature(q, &w, &mut cm, s);
        w[k] = v[k];
        for a in 0..m {
            rows[a][k] = 0.25 * (cp[a] - cm[a]);
        }
    }
    rows
}

/// The gradients of the constraint map Φ = (g(q), G(q)M⁻¹p) as 2d-vectors: (G_a, 0) and
/// (D²g_a\[M⁻¹p, ·\], M⁻¹G_a).
fn grad_phi<P: Constrained>(problem: &P, z: &[f64], s: &mut P::Scratch) -> Vec<Vec<f64>> {
    let (d, m) = (problem.dof(), problem.constraints());
    let (q, p) = z.split_at(d);
    let mut v = vec![0.0; d];
    problem.velocity(p, &mut v);
    let mut jac = vec![0.0; m * d];
    problem.constraint_jacobian(q, &mut jac, s);
    let curv = curvature_rows(problem, q, &v, s);
    let mut out = Vec::with_capacity(2 * m);
    for ga in jac.chunks_exact(d) {
        out.push(
            ga.iter()
                .copied()
                .chain(std::iter::repeat(0.0).take(d))
                .collect(),
        );
    }
    for (ga, row) in jac.chunks_exact(d).zip(curv) {
        let mut wa = vec![0.0; d];
        problem.velocity(ga, &mut wa);
        out.push(row.into_iter().chain(wa).collect());
    }
    out
}

/// ∇⟨J, ξ⟩(z) = (−ξ_Z^p, ξ_Z^q): the symmetry is a cotangent lift, so ⟨J, ξ⟩ generates ξ_Z
/// (exact; tested against differences of [`Symmetric::momentum_map`]).
fn pairing_gradient<P: Constrained + Symmetric>(
    problem: &P,
    xi: &[f64],
    z: &[f64],
) -> Result<Vec<f64>> {
    let d = problem.dof();
    let gen = problem.generator(xi, z)?;
    Ok(gen[d..]
        .iter()
        .map(|x| -x)
        .chain(gen[..d].iter().copied())
        .collect())
}

/// DF(z₀) of the co-moving field F = f − ξ_Z (2d × 2d): the constrained field's derivative
/// exact ([`constrained_field_tangent`]; D³g of the constraints in closed form where the
/// system gives it), ξ_Z's by central differences with the steps `h` (exact: ξ_Z is linear
/// in z for the cotangent lift of a linear action).
fn comoving_jacobian<P: Constrained + Symmetric + SeparableTangent>(
    problem: &P,
    xi: &[f64],
    z0: &[f64],
    h: &[f64],
) -> Result<Mat> {
    let nz = z0.len();
    let mut dirs = vec![0.0; nz * nz];
    for j in 0..nz {
        dirs[j * nz + j] = 1.0;
    }
    let mut out = vec![0.0; nz * nz];
    constrained_field_tangent(problem, z0, &dirs, &mut out)?;
    let mut df = Mat::from_fn(nz, nz, |i, j| out[j * nz + i]);
    let mut z = z0.to_vec();
    for j in 0..nz {
        z[j] = z0[j] + h[j];
        let up = problem.generator(xi, &z)?;
        z[j] = z0[j] - h[j];
        let down = problem.generator(xi, &z)?;
        z[j] = z0[j];
        for i in 0..nz {
            df[(i, j)] -= (up[i] - down[i]) / (2.0 * h[j]);
        }
    }
    Ok(df)
}

/// D²ℒ(z₀) of ℒ = H − ⟨J, ξ⟩ − κ·Φ (module docs), 2d × 2d: D²H from the system's derivatives
/// (D²U = −f′ and M⁻¹ of [`SeparableTangent`]), D²⟨J, ξ⟩ from the generator (linear in z:
/// central differences with a step of the state's size are exact), D²g by polarisation.
/// D³g(q)\[M⁻¹p, ·, ·\] of the hidden constraints from [`Constrained::constraint_third`] where
/// given, else by differences (central, Richardson); its multipliers vanish at a relative
/// equilibrium (the velocity is the generator's).
fn lagrange_hessian<P: Constrained + Symmetric + SeparableTangent>(
    problem: &P,
    xi: &[f64],
    z0: &[f64],
    kappa: &[f64],
    zscale: f64,
    s: &mut P::Scratch,
) -> Result<Mat> {
    let (d, m) = (problem.dof(), problem.constraints());
    let nz = 2 * d;
    let (q0, p0) = z0.split_at(d);
    let mut hess = Mat::zeros(nz, nz);
    let (mut e, mut col) = (vec![0.0; d], vec![0.0; d]);
    for k in 0..d {
        e[k] = 1.0;
        // D²U e_k = −f′(q₀)[e_k]; M⁻¹e_k.
        problem.force_tangent(q0, &e, &mut col, s);
        for i in 0..d {
            hess[(i, k)] = -col[i];
        }
        problem.velocity_tangent(p0, &e, &mut col);
        for i in 0..d {
            hess[(d + i, d + k)] = col[i];
        }
        // −κ_a D²g_a[e_k, ·] (qq) and −κ_{m+a} D²g_a[M⁻¹e_k, ·] (the qp and pq blocks).
        let rows = curvature_rows(problem, q0, &e, s);
        problem.velocity(&e, &mut col);
        let mixed = curvature_rows(problem, q0, &col, s);
        for a in 0..m {
            for i in 0..d {
                hess[(i, k)] -= kappa[a] * rows[a][i];
                hess[(i, d + k)] -= kappa[m + a] * mixed[a][i];
                hess[(d + k, i)] -= kappa[m + a] * mixed[a][i];
            }
        }
        e[k] = 0.0;
    }
    // −D²⟨J, ξ⟩.
    let mut zp = z0.to_vec();
    for k in 0..nz {
        zp[k] = z0[k] + zscale;
        let up = pairing_gradient(problem, xi, &zp)?;
        zp[k] = z0[k] - zscale;
        let down = pairing_gradient(problem, xi, &zp)?;
        zp[k] = z0[k];
        for i in 0..nz {
            hess[(i, k)] -= (up[i] - down[i]) / (2.0 * zscale);
        }
    }
    // −Σ κ_{m+a} D³g_a[M⁻¹p, ·, ·] (qq): closed form where the constraint gives it, else by
    // differences of the polarised rows.
    if kappa[m..].iter().any(|&k| k != 0.0) {
        let mut v = vec![0.0; d];
        problem.velocity(p0, &mut v);
        let mut rows = vec![0.0; m * d];
        e.fill(0.0);
        if problem.constraint_third(q0, &v, &e, &mut rows, s) {
            for k in 0..d {
                e[k] = 1.0;
                problem.constraint_third(q0, &v, &e, &mut rows, s);
                e[k] = 0.0;
                for i in 0..d {
                    hess[(i, k)] -= (0..m).map(|a| kappa[m + a] * rows[a * d + i]).sum::<f64>();
                }
            }
            return Ok(hess);
        }
        let cell = std::cell::RefCell::new(problem.scratch());
        let hidden = |q: &[f64]| -> Result<Vec<f64>> {
            let rows = curvature_rows(problem, q, &v, &mut cell.borrow_mut());
            Ok((0..d)
                .map(|i| (0..m).map(|a| kappa[m + a] * rows[a][i]).sum())
                .collect())
        };
        let h: Vec<f64> = q0
            .iter()
            .map(|x| 1e-4 * x.abs().max(1e-2 * zscale))
            .collect();
        let third = fd::jacobian(&hidden, q0, &h, Richardson)?;
        for i in 0..d {
            for k in 0..d {
                hess[(i, k)] -= third[(i, k)];
            }
        }
    }
    Ok(hess)
}
