"""Type stubs of ``lieflow.lie``."""

from typing import Tuple

import numpy as np
import numpy.typing as npt

_F = npt.NDArray[np.float64]
_In = npt.ArrayLike

# --- so(n) / SO(n) for any n >= 2 (e_ij basis, pairing ½ tr(ξᵀη)) ---

def hat_n(c: _In) -> _F:
    """(d,) or (b, d) coordinates, d = n(n−1)/2 → (n, n) or (b, n, n) skew matrices."""
def vee_n(xi: _In) -> _F:
    """(n, n) or (b, n, n) skew matrices → (d,) or (b, d) coordinates in the e_ij basis."""
def so_exp(xi: _In) -> _F:
    """exp: so(n) → SO(n); (n, n) or a batch (b, n, n) computed in parallel."""
def so_log(R: _In) -> _F:
    """Principal log: SO(n) → so(n); (n, n) or a batch (b, n, n) computed in parallel."""
def cayley(xi: _In) -> _F:
    """(I − ξ/2)⁻¹ (I + ξ/2)."""
def cayley_inv(R: _In) -> _F:
    """2 (I + R)⁻¹ (R − I), the inverse of ``cayley``."""
def dexp(xi: _In, eta: _In) -> _F:
    """Right-trivialized dexp_ξ η = Σ ad_ξᵏ η / (k+1)!."""
def dexp_inv(xi: _In, eta: _In) -> _F:
    """Inverse of ``dexp`` (Bernoulli series), for |ξ| < π."""
def Ad(g: _In, xi: _In) -> _F:
    """g ξ gᵀ."""
def ad(xi: _In, eta: _In) -> _F:
    """[ξ, η]."""
def ad_star(xi: _In, mu: _In) -> _F:
    """[μ, ξ] (coadjoint action under ½ tr(ξᵀη))."""
def is_rotation(R: _In, tol: float = 1e-10) -> bool:
    """‖RᵀR − I‖_F ≤ tol and det R > 0."""
def project_to_so(M: _In) -> _F:
    """Nearest rotation (polar factor with the determinant sign fix)."""

# --- SO(n) × SO(n) on so(n) ⊕ so(n) (componentwise, 001 (7.23), (7.26)) ---

def product_Ad(g: _In, h: _In, xi: _In, eta: _In) -> Tuple[_F, _F]:
    """(g ξ gᵀ, h η hᵀ)."""
def product_bracket(xi1: _In, eta1: _In, xi2: _In, eta2: _In) -> Tuple[_F, _F]:
    """([ξ1, ξ2], [η1, η2])."""
