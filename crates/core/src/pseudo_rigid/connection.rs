//! Connections on GL⁺(n) (001 §2.2, §6.2–6.3): the left and right connections ω^L, ω^R
//! (001 (2.14)–(2.15)), the bi-connection ω^B (001 (6.18)), the vertical vectors of the actions
//! (001 (6.17)), horizontal/vertical splits (001 (2.18)–(2.22), (6.4)–(6.7), (6.23)) and the
//! locked inertia tensors computed from the metric tr(YᵀZ) (001 (2.27), (6.24)).
//!
//! Every function takes the [`BiInertia`] at X (which holds X and caches its SVD).

use std::str::FromStr;

use super::inertia::BiInertia;
use super::momentum::momentum_map_unchecked;
use crate::error::{Error, Result};
use crate::lie::so;
use crate::{check, Mat};

/// Which SO(n) action: left X ↦ gX, right X ↦ Xh⁻¹, or two-sided X ↦ gXh⁻¹ (001 (2.2), (6.1)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// X ↦ gX.
    Left,
    /// X ↦ Xh⁻¹.
    Right,
    /// X ↦ gXh⁻¹ of SO(n)×SO(n).
    TwoSided,
}

impl FromStr for Action {
    type Err = Error;
    /// "left", "right" or "two-sided".
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "left" => Ok(Action::Left),
            "right" => Ok(Action::Right),
            "two-sided" => Ok(Action::TwoSided),
            _ => Err(Error::invalid(
                "action",
                format!("expected \"left\", \"right\" or \"two-sided\", got {s:?}"),
            )),
        }
    }
}

fn tangent(b: &BiInertia, y: &Mat) -> Result<()> {
    check::square_of("Y", y, b.n())
}

/// Left connection ω^L_X(Y) = (A^L_X)⁻¹(YXᵀ − XYᵀ) (001 (2.14)); defined on all of GL⁺(n).
/// ω^L(ξX) = ξ and ω^L_{gX} = Ad_g ∘ ω^L_X (2.16).
///
/// Scale-aware, as every connection here: J is formed with X̃ = X/c (c a power of two near the
/// largest singular value, `BiInertia::unit_x`) and the inverse on the scaled singular values,
/// ω_X(Y) = ω_X̃(Y/c), so X at 1e-200 or 1e200 gives ω wherever ω is representable.
pub fn left_connection(b: &BiInertia, y: &Mat) -> Result<Mat> {
    tangent(b, y)?;
    let (xs, _) = b.unit_x()?;
    b.left_solve_scaled(&momentum_map_unchecked(&xs, y).0, 1)
}

/// Right connection ω^R_X(Y) = (A^R_X)⁻¹(YᵀX − XᵀY) (001 (2.15)); defined on all of GL⁺(n).
/// ω^R(Xηᵀ) = η and ω^R_{Xh⁻¹} = Ad_h ∘ ω^R_X (2.17).
pub fn right_connection(b: &BiInertia, y: &Mat) -> Result<Mat> {
    tangent(b, y)?;
    let (xs, _) = b.unit_x()?;
    b.right_solve_scaled(&momentum_map_unchecked(&xs, y).1, 1)
}

/// Bi-connection ω^B_X(Y) = B_X⁻¹((YXᵀ − XYᵀ) ⊕ (YᵀX − XᵀY)) (001 (6.18)), by the closed-form
/// inverse of B_X. Needs the principal stratum ([`Error::DegenerateStratum`] otherwise).
/// ω^B(ξX + Xηᵀ) = ξ ⊕ η (6.19), ω^B_{gXh⁻¹} = Ad_(g,h) ∘ ω^B_X (6.20), ker ω^B = H_X (6.23).
/// Seed slip: the proof (6.21) as extracted reads B_X⁻¹ B_X⁻¹ (ξ ⊕ η); the step is
/// B_X⁻¹ B_X (ξ ⊕ η), since J(X, ξX + Xηᵀ) = B_X(ξ ⊕ η) (checked numerically).
pub fn bi_connection(b: &BiInertia, y: &Mat) -> Result<(Mat, Mat)> {
    tangent(b, y)?;
    let (xs, _) = b.unit_x()?;
    let (l, g) = momentum_map_unchecked(&xs, y);
    b.solve_scaled(&l, &g, 1)
}

/// The vertical vector (ξ ⊕ η)_P(X) = ξX + Xηᵀ induced by ξ ⊕ η ∈ so(n) ⊕ so(n) (001 (6.17));
/// η = 0 gives the left-action vector ξX, ξ = 0 the right-action vector Xηᵀ.
pub fn vertical_vector(b: &BiInertia, xi: &Mat, eta: &Mat) -> Result<Mat> {
    so::check_algebra_of("xi", xi, b.n())?;
    so::check_algebra_of("eta", eta, b.n())?;
    Ok(vertical_unchecked(b.x(), xi, eta))
}

/// ξX + Xηᵀ without checks.
pub(crate) fn vertical_unchecked(x: &Mat, xi: &Mat, eta: &Mat) -> Mat {
    xi * x + x * eta.transpose()
}

/// Vertical part of Y ∈ T_X GL⁺(n) for an action: the orthogonal projection (metric tr(YᵀZ))
/// onto the tangent space of the orbit, ω^L(Y)X (left), Xω^R(Y)ᵀ (right), or (ξ ⊕ η)_P(X) with
/// ξ ⊕ η = B_X⁺ J(X, Y) (two-sided, 001 (6.4)–(6.5)). B_X⁺ is the least-squares inverse
/// ([`BiInertia::solve_least_squares`]), so the split is defined on every stratum (it equals
/// ω^B on the principal one) — the one-sided splits (2.22) likewise.
pub fn vertical_part(b: &BiInertia, y: &Mat, action: Action) -> Result<Mat> {
    tangent(b, y)?;
    let zero = Mat::zeros(b.n(), b.n());
    // Scale-aware (see [`left_connection`]): ξ ⊕ η = B_X⁺ J(X, Y) = B_X̃⁺ J(X̃, Y)/c, and the
    // vertical vector ξX + Xηᵀ = (ξ̃X̃ + X̃η̃ᵀ) with ξ̃ = cξ.
    let (xs, _) = b.unit_x()?;
    let (l, g) = momentum_map_unchecked(&xs, y);
    let (xi, eta) = match action {
        Action::Left => (b.left_solve_scaled(&l, 0)?, zero),
        Action::Right => (zero, b.right_solve_scaled(&g, 0)?),
        Action::TwoSided => b.solve_least_squares_scaled(&l, &g, 0)?,
    };
    Ok(vertical_unchecked(&xs, &xi, &eta))
}

/// Horizontal part Y − vertical part (001 (2.20)–(2.22), (6.6), (6.23)): the left one satisfies
/// YXᵀ = XYᵀ, the right one YᵀX = XᵀY, the two-sided one both.
pub fn horizontal_part(b: &BiInertia, y: &Mat, action: Action) -> Result<Mat> {
    Ok(y - vertical_part(b, y, action)?)
}

/// The locked inertia tensor computed from the metric, an independent route to the inertia
/// tensors (001 (2.27), (6.24)): the matrix with entries tr(V(e_a)ᵀ V(e_b)) over the e_ij basis,
/// where V(ξ) = ξX (left, d×d), Xξᵀ (right) or V(ξ ⊕ η) = ξX + Xηᵀ (two-sided, 2d×2d, ξ block
/// first). Equals the matrix of A^L_X, A^R_X, B_X respectively (2.28), (6.25). The display
/// (6.25) is missing from the extraction; derived: with ξᵀ = −ξ, ηᵀ = −η,
/// ‖ξX + Xηᵀ‖² = 2 tr(ξXηXᵀ) − tr(ξ²XXᵀ) − tr(η²XᵀX) = ⟨ξ ⊕ η, B_X(ξ ⊕ η)⟩ with the pairing
/// (6.8), polarised. O(n⁶) (a Gram matrix of n(n−1) vectors in R^{n²}): a check, not a hot
/// path.
///
/// Scale-aware: computed at X̃ = X/c (`BiInertia::unit_x`) and multiplied by c² once; an
/// overflow error (InvalidArgument) where an entry exceeds the f64 range.
pub fn locked_inertia(b: &BiInertia, action: Action) -> Result<Mat> {
    let (xs, scale) = b.unit_x()?;
    let (n, d) = (b.n(), so::dim(b.n()));
    let zero = Mat::zeros(n, n);
    let blocks = if action == Action::TwoSided { 2 } else { 1 };
    let vectors: Vec<Mat> = (0..blocks * d)
        .map(|k| {
            let mut c = vec![0.0; blocks * d];
            c[k] = 1.0;
            let e = so::hat_n_unchecked(n, &c[..d]);
            match action {
                Action::Left => vertical_unchecked(&xs, &e, &zero),
                Action::Right => vertical_unchecked(&xs, &zero, &e),
                Action::TwoSided => vertical_unchecked(&xs, &e, &so::hat_n_unchecked(n, &c[d..])),
            }
        })
        .collect();
    let gram = Mat::from_fn(blocks * d, blocks * d, |p, q| {
        let (u, v) = (&vectors[p], &vectors[q]);
        let mut s = 0.0;
        for j in 0..n {
            for i in 0..n {
                s += u[(i, j)] * v[(i, j)];
            }
        }
        s
    });
    super::inertia::rescale("the locked inertia tensor", gram, scale, -2)
}

/// Guichardet's connection of N particles in n dimensions (001 §2.3, (2.23)–(2.26)):
/// ω = A_Q⁻¹(Σ_α m_α (ẋ_α x_αᵀ − x_α ẋ_αᵀ)) ∈ so(n), A_Q ξ = Qξ + ξQ, Q = Σ_α m_α x_α x_αᵀ — the
/// rigid rotation that carries the particles' angular momentum (in three dimensions
/// hat⁻¹ω = A⁻¹ Σ m x × ẋ with A = tr(Q)1 − Q the inertia tensor (2.23), (2.25); the seed's (2.24)
/// drops the A⁻¹ that (2.26) has). `positions` and `velocities` are N × n (rows x_α, ẋ_α),
/// masses > 0. For particles x_α = Xu_α whose labels have Σ m u uᵀ = 1, Q = XXᵀ and
/// Σ m ẋxᵀ = ẊXᵀ: ω is the left connection ω^L_X(Ẋ) (2.14), of which it is thus the discrete
/// original. A_Q is diagonal in Q's eigenbasis (ξ_ij/(q_i + q_j)); an error where the particles
/// span fewer than n − 1 dimensions (A_Q singular).
pub fn guichardet_connection(masses: &[f64], positions: &Mat, velocities: &Mat) -> Result<Mat> {
    let (q, _) = particle_moments(masses, positions)?;
    if velocities.nrows() != positions.nrows() || velocities.ncols() != positions.ncols() {
        return Err(Error::shape(
            "velocities",
            format!("({}, {})", positions.nrows(), positions.ncols()),
            format!("({}, {})", velocities.nrows(), velocities.ncols()),
        ));
    }
    check::finite_mat("velocities", velocities)?;
    let n = positions.ncols();
    let mut l = Mat::zeros(n, n);
    for (a, &m) in masses.iter().enumerate() {
        for i in 0..n {
            for j in 0..n {
                l[(i, j)] += m
                    * (velocities[(a, i)] * positions[(a, j)]
                        - positions[(a, i)] * velocities[(a, j)]);
            }
        }
    }
    let eig = q
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| Error::invalid("positions", format!("eigen-decomposition failed: {e:?}")))?;
    let (v, s) = (eig.U(), eig.S());
    let lt = v.transpose() * &l * v;
    let scale = (0..n).map(|i| s[i].abs()).fold(0.0, f64::max);
    let mut w = Mat::zeros(n, n);
    for i in 0..n {
        for j in 0..n {
            if i != j {
                let d = s[i] + s[j];
                if d.is_nan() || d <= 1e-14 * scale {
                    return Err(Error::invalid(
                        "positions",
                        "the particles lie on a line (or at one point): the locked inertia \
                         A_Q ξ = Qξ + ξQ is singular and the connection is not defined",
                    ));
                }
                w[(i, j)] = lt[(i, j)] / d;
            }
        }
    }
    let omega = v * w * v.transpose();
    check::finite_mat("connection", &omega)
        .map_err(|_| check::overflow_error("masses, positions, velocities", "the connection"))?;
    Ok(omega)
}

/// The locked inertia of N particles (001 (2.27)): the Gram matrix
/// 𝕀_ab = Σ_α m_α (e_a x_α)·(e_b x_α) of the rotation generators e_a (so(n)'s e_ij basis, as
/// [`locked_inertia`]), i.e. the matrix of A_Q; for x_α = Xu_α with Σ m u uᵀ = 1 it is the
/// pseudo-rigid body's locked inertia of the left action (A^L_X).
pub fn particle_locked_inertia(masses: &[f64], positions: &Mat) -> Result<Mat> {
    let (q, n) = particle_moments(masses, positions)?;
    let d = so::dim(n);
    let basis: Vec<Mat> = (0..d)
        .map(|k| {
            let mut c = vec![0.0; d];
            c[k] = 1.0;
            so::hat_n_unchecked(n, &c)
        })
        .collect();
    // Σ m (e_a x)·(e_b x) = tr(e_aᵀ e_b Q).
    let gram = Mat::from_fn(d, d, |a, b| {
        let p = basis[a].transpose() * &basis[b] * &q;
        (0..n).map(|i| p[(i, i)]).sum()
    });
    check::finite_mat("locked inertia", &gram)
        .map_err(|_| check::overflow_error("masses, positions", "the locked inertia"))?;
    Ok(gram)
}

/// Q = Σ m x xᵀ of N particles (checked: masses > 0 and finite, N × n positions finite, n ≥ 2).
fn particle_moments(masses: &[f64], positions: &Mat) -> Result<(Mat, usize)> {
    let n = positions.ncols();
    if positions.nrows() != masses.len() || n < 2 {
        return Err(Error::shape(
            "positions",
            format!("({}, n) with n ≥ 2, one row per mass", masses.len()),
            format!("({}, {})", positions.nrows(), n),
        ));
    }
    for &m in masses {
        check::positive("masses", m)?;
    }
    check::finite_mat("positions", positions)?;
    let mut q = Mat::zeros(n, n);
    for (a, &m) in masses.iter().enumerate() {
        for i in 0..n {
            for j in 0..n {
                q[(i, j)] += m * positions[(a, i)] * positions[(a, j)];
            }
        }
    }
    check::finite_mat("Q", &q).map_err(|_| check::overflow_error("positions", "Σ m x xᵀ"))?;
    Ok((q, n))
}
