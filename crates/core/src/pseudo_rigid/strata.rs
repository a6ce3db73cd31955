//! Strata and isotropy of the two-sided SO(n)×SO(n) action X ↦ gXh⁻¹ on GL⁺(n) (001 §6.1, (6.2),
//! (9.2), (9.3)).
//!
//! With X = R A Sᵀ and the singular values grouped into blocks of equal values with
//! multiplicities m₁, …, m_k, the isotropy group G_A = {(g, g) : g ∈ S(O(m₁)×…×O(m_k))}
//! (block-diagonal, det g = 1): g A = A h forces g to commute with A² and then h = g. Its
//! dimension is Σ m_l(m_l − 1)/2, so dim V_X = n(n−1) − dim G_A and dim H_X = n² − dim V_X.
//! Principal stratum: G_A = (Z₂)^{n−1} (6.2); n = 3 gives (9.2) and (9.3).

use super::connection::vertical_unchecked;
use super::inertia::BiInertia;
use crate::error::{Error, Result};
use crate::lie::gl::{self, Stratum};
use crate::lie::so;
use crate::Mat;

/// Stratum of X with the dimensions of the vertical and horizontal spaces and the isotropy type.
#[derive(Debug, Clone, PartialEq)]
pub struct StratumInfo {
    /// Singular values, multiplicities, smallest gap ([`gl::stratum`]).
    pub stratum: Stratum,
    /// dim V_X, computed as the rank of ξ ⊕ η ↦ ξX + Xηᵀ (001 (6.5)).
    pub dim_vertical: usize,
    /// dim H_X = n² − dim V_X (001 (6.4), (6.6)).
    pub dim_horizontal: usize,
    /// The isotropy group, e.g. "(Z2)^2", "S(O(2)×O(1))", "SO(3)" (001 (6.2), (9.2)).
    pub isotropy: String,
    /// dim G_A = Σ m_l(m_l − 1)/2.
    pub isotropy_dim: usize,
}

/// Name of S(O(m₁)×…×O(m_k)) with the special cases of 001 (6.2) and (9.2).
fn isotropy_name(multiplicities: &[usize]) -> String {
    let n: usize = multiplicities.iter().sum();
    if multiplicities.len() == 1 {
        format!("SO({n})")
    } else if multiplicities.iter().all(|&m| m == 1) {
        format!("(Z2)^{}", n - 1)
    } else {
        let parts: Vec<String> = multiplicities.iter().map(|m| format!("O({m})")).collect();
        format!("S({})", parts.join("×"))
    }
}

/// Classifies X ∈ GL⁺(n) under the two-sided action (001 §6.1, (9.2), (9.3)). Singular values
/// coincide within `rel_tol`·a₁ (use [`gl::STRATUM_TOL`]); dim V_X is the numerical rank, at the
/// same relative tolerance, of the n²×n(n−1) matrix of the vertical map (faer SVD; its singular
/// values are |a_i − a_j| and a_i + a_j). The isotropy dimension from the multiplicities is
/// checked against the computed rank: a mismatch (possible only within rounding of the
/// tolerance) is reported as [`Error::DegenerateStratum`]. The rank costs an SVD of an
/// n²×n(n−1) matrix, O(n⁶): a tool for analysis and tests (about a second at n = 30).
pub fn classify(x: &Mat, rel_tol: f64) -> Result<StratumInfo> {
    let stratum = gl::stratum(x, rel_tol)?;
    let b = BiInertia::new(x)?;
    let n = b.n();
    let d = so::dim(n);
    let mut map = Mat::zeros(n * n, 2 * d);
    let mut c = vec![0.0; 2 * d];
    for col in 0..2 * d {
        c[col] = 1.0;
        let xi = so::hat_n_unchecked(n, &c[..d]);
        let eta = so::hat_n_unchecked(n, &c[d..]);
        let v = vertical_unchecked(b.x(), &xi, &eta);
        for j in 0..n {
            for i in 0..n {
                map[(j * n + i, col)] = v[(i, j)];
            }
        }
        c[col] = 0.0;
    }
    let sv = map.singular_values().map_err(|e| Error::NotConverged {
        what: format!("SVD of the vertical map ({e:?})"),
        iterations: 0,
        residual: f64::NAN,
        tol: 0.0,
    })?;
    let thresh = rel_tol * stratum.a[0];
    let dim_vertical = sv.iter().filter(|&&s| s > thresh).count();
    let isotropy_dim: usize = stratum.multiplicities.iter().map(|&m| so::dim(m)).sum();
    if dim_vertical + isotropy_dim != 2 * d {
        return Err(Error::DegenerateStratum {
            what: "stratum classification (rank of the vertical map disagrees with the \
                   singular-value multiplicities at this tolerance)"
                .into(),
            gap: stratum.min_gap,
            tol: thresh,
        });
    }
    Ok(StratumInfo {
        isotropy: isotropy_name(&stratum.multiplicities),
        isotropy_dim,
        dim_horizontal: n * n - dim_vertical,
        dim_vertical,
        stratum,
    })
}
