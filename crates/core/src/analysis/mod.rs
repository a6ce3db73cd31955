//! Analysis of relative equilibria and their families: the two stability verdicts
//! ([`Verdict`]), the linear stability of relative equilibria of constrained mechanical systems in
//! the co-moving frame ([`comoving`]), and pseudo-arclength continuation with special points
//! ([`continuation`]), and the Lyapunov spectrum of a run ([`lyapunov`]). Generic: these layers
//! know no system; systems enter through the problem kinds of [`crate::integrate::problem`], the
//! [`continuation::Family`] trait or a tangent lift ([`crate::integrate::tangent`]).

pub mod comoving;
pub mod continuation;
pub mod lyapunov;
pub mod periodic;

use crate::error::{Error, Result};
use crate::Mat;
use faer::Side;

/// A verdict of one stability test.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// Eigenvalues (re, im): of the Hessian of the energy on the symplectic leaf or normal space
    /// (energy–momentum, all im = 0, ascending) or of the linearised flow there (spectral, by
    /// descending real part).
    pub eigenvalues: Vec<(f64, f64)>,
    /// Energy–momentum: the Hessian is positive definite (⇒ nonlinearly stable, modulo the
    /// symmetry). Spectral: max Re λ ≤ tol (spectrally stable).
    pub stable: bool,
    /// Whether the verdict decides nonlinear stability. Energy–momentum: `true` iff `stable`
    /// (an indefinite or singular Hessian is inconclusive, not unstable). Spectral: `true` iff
    /// not `stable` (an eigenvalue with positive real part proves instability; spectral stability
    /// does not prove nonlinear stability).
    pub conclusive: bool,
    /// The smallest real part of the eigenvalues.
    pub min_real_part: f64,
    /// The largest real part of the eigenvalues.
    pub max_real_part: f64,
    /// The absolute tolerance used: the relative tolerance times max|λ|.
    pub tol: f64,
}

impl Verdict {
    /// The energy–momentum verdict on a symmetric Hessian: positive definite means every
    /// eigenvalue exceeds `rel_tol` · max|λ| (the lower triangle is read).
    pub fn energy_momentum(hessian: &Mat, rel_tol: f64) -> Result<Verdict> {
        let ev: Vec<f64> = if hessian.nrows() == 0 {
            Vec::new()
        } else {
            hessian
                .self_adjoint_eigenvalues(Side::Lower)
                .map_err(|e| eig_error("symmetric eigenvalues of the Hessian", e))?
        };
        let scale = ev.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let tol = rel_tol * scale;
        let stable = ev.iter().all(|&x| x > tol);
        Ok(Verdict {
            eigenvalues: ev.iter().map(|&x| (x, 0.0)).collect(),
            stable,
            conclusive: stable,
            min_real_part: ev.iter().copied().fold(f64::INFINITY, f64::min),
            max_real_part: ev.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            tol,
        })
    }

    /// The spectral verdict on a linearisation: stable means max Re λ ≤ `rel_tol` · (spectral
    /// radius).
    pub fn spectral(linearisation: &Mat, rel_tol: f64) -> Result<Verdict> {
        let spec = sorted(general_eigenvalues(linearisation)?);
        let radius = spec
            .iter()
            .fold(0.0_f64, |m, &(re, im)| m.max(re.hypot(im)));
        let tol = rel_tol * radius;
        let max_re = spec.iter().map(|e| e.0).fold(f64::NEG_INFINITY, f64::max);
        let min_re = spec.iter().map(|e| e.0).fold(f64::INFINITY, f64::min);
        let stable = max_re <= tol;
        Ok(Verdict {
            eigenvalues: spec,
            stable,
            conclusive: !stable,
            min_real_part: min_re,
            max_real_part: max_re,
            tol,
        })
    }
}

/// Eigenvalues (re, im) of a general real square matrix (faer's real Schur / EVD).
pub(crate) fn general_eigenvalues(m: &Mat) -> Result<Vec<(f64, f64)>> {
    if m.nrows() == 0 {
        return Ok(Vec::new());
    }
    let ev = m
        .eigenvalues()
        .map_err(|e| eig_error("eigenvalues of the linearisation", e))?;
    Ok(ev.iter().map(|z| (z.re, z.im)).collect())
}

pub(crate) fn eig_error(what: &str, e: impl std::fmt::Debug) -> Error {
    Error::NotConverged {
        what: format!("{what} ({e:?})"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    }
}

/// By descending real part, then descending imaginary part.
pub(crate) fn sorted(mut v: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    v.sort_by(|x, y| y.0.total_cmp(&x.0).then(y.1.total_cmp(&x.1)));
    v
}

/// Rank tolerance of the subspaces ([`null_space`], [`range`]): singular values below this
/// times the largest are zero.
const RANK_TOL: f64 = 1e-9;

/// An orthonormal basis (columns) of the null space of `m` (rows × cols), by the SVD.
pub(crate) fn null_space(m: &Mat) -> Result<Mat> {
    let (r, c) = (m.nrows(), m.ncols());
    if r == 0 {
        return Ok(Mat::identity(c, c));
    }
    // Pad with zero rows so that all c right singular vectors are returned.
    let rows = r.max(c);
    let mp = Mat::from_fn(rows, c, |i, j| if i < r { m[(i, j)] } else { 0.0 });
    let svd = mp.svd().map_err(|e| eig_error("SVD (null space)", e))?;
    let (s, v) = (svd.S().column_vector(), svd.V());
    let smax = if c > 0 { s[0] } else { 0.0 };
    let rank = (0..c).filter(|&k| s[k] > RANK_TOL * smax).count();
    Ok(Mat::from_fn(c, c - rank, |i, j| v[(i, rank + j)]))
}

/// An orthonormal basis of the column space of `m`.
pub(crate) fn range(m: &Mat) -> Result<Mat> {
    if m.ncols() == 0 {
        return Ok(Mat::zeros(m.nrows(), 0));
    }
    let svd = m.thin_svd().map_err(|e| eig_error("SVD (range)", e))?;
    let (u, s) = (svd.U(), svd.S().column_vector());
    let smax = s[0];
    let rank = (0..s.nrows()).filter(|&k| s[k] > RANK_TOL * smax).count();
    Ok(Mat::from_fn(m.nrows(), rank, |i, j| u[(i, j)]))
}
