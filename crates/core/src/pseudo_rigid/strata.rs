//! Strata and isotropy of the two-sided SO(n)×SO(n) action X ↦ gXh⁻¹ on GL⁺(n) (001 §6.1, (6.2),
//! (9.2), (9.3)).
//!
//! With X = R A Sᵀ and the singular values grouped into blocks of equal values with
//! multiplicities m₁, …, m_k, the isotropy group G_A = {(g, g) : g ∈ S(O(m₁)×…×O(m_k))}
//! (block-diagonal, det g = 1): g A = A h forces g to commute with A² and then h = g. Its
//! dimension is Σ m_l(m_l − 1)/2, so dim V_X = n(n−1) − dim G_A and dim H_X = n² − dim V_X.
//! Principal stratum: G_A = (Z₂)^{n−1} (6.2); n = 3 gives (9.2) and (9.3).

use crate::error::{Error, Result};
use crate::lie::gl::{self, Stratum};
use crate::lie::so;
use crate::Mat;

/// Stratum of X with the dimensions of the vertical and horizontal spaces and the isotropy type.
#[derive(Debug, Clone, PartialEq)]
pub struct StratumInfo {
    /// Singular values, multiplicities, smallest gap ([`gl::stratum`]).
    pub stratum: Stratum,
    /// dim V_X, the rank of ξ ⊕ η ↦ ξX + Xηᵀ (001 (6.5)).
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
/// coincide within `rel_tol`·a₁ (use [`gl::STRATUM_TOL`]). dim V_X is the rank of the vertical map
/// ξ ⊕ η ↦ ξX + Xηᵀ (001 (6.5)), read off in closed form from the singular values of X: the map's
/// singular values are |a_i − a_j| and a_i + a_j over the pairs i < j (the square roots of the
/// eigenvalues (a_i ∓ a_j)² of B_X, 001 (8.15)), so the rank counts those above `rel_tol`·a₁ — no
/// dense n²×n(n−1) matrix, O(n³) for the SVD of X. The isotropy dimension from the multiplicities
/// is checked against that count: a mismatch (possible only within rounding of the tolerance) is
/// reported as [`Error::DegenerateStratum`].
pub fn classify(x: &Mat, rel_tol: f64) -> Result<StratumInfo> {
    let stratum = gl::stratum(x, rel_tol)?;
    let (a, n) = (&stratum.a, stratum.a.len());
    let thresh = stratum.tol;
    let dim_vertical = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .map(|(i, j)| usize::from((a[i] - a[j]).abs() > thresh) + usize::from(a[i] + a[j] > thresh))
        .sum::<usize>();
    let isotropy_dim: usize = stratum.multiplicities.iter().map(|&m| so::dim(m)).sum();
    if dim_vertical + isotropy_dim != 2 * so::dim(n) {
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
