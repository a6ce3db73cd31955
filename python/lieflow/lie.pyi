"""Type stubs of ``lieflow.lie``."""

from typing import Any, Tuple, TypedDict

import numpy as np
import numpy.typing as npt

_F = npt.NDArray[np.float64]
_In = npt.ArrayLike

__all__ = [
    "Ad", "ad", "ad_star", "cayley", "cayley_inv", "dexp", "dexp_inv", "from_euler",
    "from_quaternion", "from_scipy", "from_svd", "hat", "hat_n", "is_rotation", "polar",
    "product_Ad", "product_bracket", "project_to_so", "se3_Ad", "se3_act", "se3_ad",
    "se3_ad_star", "se3_compose", "se3_exp", "se3_hat", "se3_inverse", "se3_jacobian_left",
    "se3_jacobian_right", "se3_log", "se3_vee", "so3_Ad", "so3_act", "so3_ad", "so3_ad_star",
    "so3_cayley", "so3_cayley_inv", "so3_compose", "so3_exp", "so3_hat", "so3_inverse",
    "so3_jacobian_left", "so3_jacobian_right", "so3_log", "so3_vee", "so_Ad", "so_act", "so_ad",
    "so_ad_star", "so_cayley", "so_cayley_inv", "so_compose", "so_dexp", "so_dexp_inv", "so_exp",
    "so_hat", "so_inverse", "so_jacobian_left", "so_jacobian_right", "so_log", "so_vee",
    "stratum", "svd_coordinates", "to_euler", "to_quaternion", "to_scipy", "vee", "vee_n",
]

# --- so(n) / SO(n) for any n >= 2 (e_ij basis, pairing ½ tr(ξᵀη)) ---

def so_hat(c: _In) -> _F:
    """(d,) or (b, d) coordinates, d = n(n−1)/2 → (n, n) or (b, n, n) skew matrices."""
def so_vee(xi: _In) -> _F:
    """(n, n) or (b, n, n) skew matrices → (d,) or (b, d) coordinates in the e_ij basis."""
def so_exp(xi: _In) -> _F:
    """exp: so(n) → SO(n); (n, n) or a batch (b, n, n) computed in parallel."""
def so_log(R: _In) -> _F:
    """Principal log: SO(n) → so(n); (n, n) or a batch (b, n, n) computed in parallel."""
def so_compose(g: _In, h: _In) -> _F:
    """g @ h of two rotations (n, n)."""
def so_inverse(R: _In) -> _F:
    """Rᵀ; (n, n) or a batch (b, n, n)."""
def so_act(R: _In, x: _In) -> _F:
    """R @ x for a rotation (n, n) and a vector (n,)."""
def so_cayley(xi: _In) -> _F:
    """(I − ξ/2)⁻¹ (I + ξ/2)."""
def so_cayley_inv(R: _In) -> _F:
    """2 (I + R)⁻¹ (R − I), the inverse of ``so_cayley``."""
def so_dexp(xi: _In, eta: _In) -> _F:
    """Right-trivialized dexp_ξ η = Σ ad_ξᵏ η / (k+1)!."""
def so_dexp_inv(xi: _In, eta: _In) -> _F:
    """Inverse of ``so_dexp`` (Bernoulli series), for |ξ| < π."""
def so_Ad(g: _In, xi: _In) -> _F:
    """g ξ gᵀ."""
def so_ad(xi: _In, eta: _In) -> _F:
    """[ξ, η]."""
def so_ad_star(xi: _In, mu: _In) -> _F:
    """[μ, ξ] (coadjoint action under ½ tr(ξᵀη))."""
def so_jacobian_left(xi: _In, inverse: bool = False) -> _F:
    """(d, d) matrix of dexp_ξ in e_ij coordinates (or of dexp⁻¹_ξ)."""
def so_jacobian_right(xi: _In, inverse: bool = False) -> _F:
    """J_r(ξ) = J_l(−ξ) (or its inverse), (d, d)."""
def is_rotation(R: _In, tol: float = 1e-10) -> bool:
    """‖RᵀR − I‖_F ≤ tol and det R > 0."""
def project_to_so(M: _In) -> _F:
    """Nearest rotation (polar factor with the determinant sign fix)."""

# Aliases of the so_* and so3_* names (kept working).
def hat_n(c: _In) -> _F:
    """Alias of so_hat."""
def vee_n(xi: _In) -> _F:
    """Alias of so_vee."""
def cayley(xi: _In) -> _F:
    """Alias of so_cayley."""
def cayley_inv(R: _In) -> _F:
    """Alias of so_cayley_inv."""
def dexp(xi: _In, eta: _In) -> _F:
    """Alias of so_dexp."""
def dexp_inv(xi: _In, eta: _In) -> _F:
    """Alias of so_dexp_inv."""
def Ad(g: _In, xi: _In) -> _F:
    """Alias of so_Ad."""
def ad(xi: _In, eta: _In) -> _F:
    """Alias of so_ad."""
def ad_star(xi: _In, mu: _In) -> _F:
    """Alias of so_ad_star."""
def hat(w: _In) -> _F:
    """Alias of so3_hat."""
def vee(xi: _In) -> _F:
    """Alias of so3_vee."""

# --- SO(n) × SO(n) on so(n) ⊕ so(n) (componentwise, 001 (7.23), (7.26)) ---

def product_Ad(g: _In, h: _In, xi: _In, eta: _In) -> Tuple[_F, _F]:
    """(g ξ gᵀ, h η hᵀ)."""
def product_bracket(xi1: _In, eta1: _In, xi2: _In, eta2: _In) -> Tuple[_F, _F]:
    """([ξ1, ξ2], [η1, η2])."""


# --- SO(3)/so(3) fast path and SE(3) ---
# Every function accepts one element or a batch along a leading axis b and returns the same
# batching (two-argument functions broadcast a single element against a batch). so(3) vectors
# use the physics hat map (so3_hat(w) @ x == cross(w, x)); se(3) vectors are (omega, v) with the
# rotation FIRST; SE(3) elements are 4x4 homogeneous matrices.

def so3_hat(w: _In) -> _F:
    """(3,) -> (3, 3) or (b, 3) -> (b, 3, 3): skew matrix with hat(w) @ x = w x x."""

def so3_vee(xi: _In) -> _F:
    """(3, 3) -> (3,) or (b, 3, 3) -> (b, 3); NotInGroupError if xi is not skew."""

def so3_exp(w: _In) -> _F:
    """Rodrigues: (3,) -> (3, 3) or (b, 3) -> (b, 3, 3)."""

def so3_log(R: _In, strict: bool = False) -> _F:
    """Principal log |w| <= pi: (3, 3) -> (3,) or (b, 3, 3) -> (b, 3); strict raises at pi."""

def so3_compose(R1: _In, R2: _In) -> _F:
    """R1 @ R2, batched."""

def so3_inverse(R: _In) -> _F:
    """R.T, batched."""

def so3_act(R: _In, x: _In) -> _F:
    """R @ x: (3, 3), (3,) -> (3,), batched."""

def so3_Ad(R: _In, w: _In) -> _F:
    """R @ w (Ad_R w), batched."""

def so3_ad(u: _In, v: _In) -> _F:
    """u x v, batched."""

def so3_ad_star(xi: _In, mu: _In) -> _F:
    """mu x xi, batched."""

def so3_cayley(w: _In) -> _F:
    """cay(w) = (I - hat(w)/2)^-1 (I + hat(w)/2): (3,) -> (3, 3), batched."""

def so3_cayley_inv(R: _In) -> _F:
    """Inverse Cayley map: (3, 3) -> (3,), batched; InvalidArgumentError at a half turn."""

def so3_jacobian_right(w: _In, inverse: bool = False) -> _F:
    """J_r(w) (or J_r(w)^-1): exp(w + d) ~ exp(w) exp(J_r d); (3,) -> (3, 3), batched."""

def so3_jacobian_left(w: _In, inverse: bool = False) -> _F:
    """J_l(w) (or J_l(w)^-1): exp(w + d) ~ exp(J_l d) exp(w); (3,) -> (3, 3), batched."""

def se3_hat(xi: _In) -> _F:
    """(6,) -> (4, 4) [[hat(omega), v], [0, 0]], batched."""

def se3_vee(X: _In) -> _F:
    """(4, 4) -> (6,), batched; NotInGroupError if X is not in se(3)."""

def se3_exp(xi: _In) -> _F:
    """(6,) -> (4, 4) or (b, 6) -> (b, 4, 4); xi = (omega, v)."""

def se3_log(g: _In, strict: bool = False) -> _F:
    """(4, 4) -> (6,) or (b, 4, 4) -> (b, 6); strict raises NoUniqueLogError at angle pi."""

def se3_Ad(g: _In, xi: _In | None = None) -> _F:
    """Ad_g xi (6,), or without xi the matrix [[R, 0], [hat(t) R, R]] (6, 6); batched."""

def se3_ad(xi: _In, eta: _In) -> _F:
    """(w1 x w2, w1 x v2 - w2 x v1), batched."""

def se3_ad_star(xi: _In, mu: _In) -> _F:
    """ad_xi^T mu, batched."""

def se3_act(g: _In, x: _In) -> _F:
    """R x + t: (4, 4), (3,) -> (3,), batched."""

def se3_jacobian_left(xi: _In, inverse: bool = False) -> _F:
    """[[J_l(omega), 0], [Q, J_l(omega)]] (or its inverse): (6,) -> (6, 6), batched."""

def se3_jacobian_right(xi: _In, inverse: bool = False) -> _F:
    """J_r(xi) = J_l(-xi) (or its inverse): (6,) -> (6, 6), batched."""

def se3_inverse(g: _In) -> _F:
    """(4, 4) -> (4, 4), batched."""

def se3_compose(g: _In, h: _In) -> _F:
    """g @ h for (4, 4) or (b, 4, 4) (a single matrix broadcasts against a batch)."""


# --- GL+(n) ---

class _GLStratum(TypedDict):
    singular_values: _F
    multiplicities: list[int]
    min_gap: float
    tol: float
    principal: bool

def svd_coordinates(X: _In) -> tuple[_F, _F, _F]:
    """SVD coordinates (R, a, S) with X = R @ diag(a) @ S.T, R, S in SO(n) (001 (2.4))."""

def from_svd(R: _In, a: _In, S: _In) -> _F:
    """X = R @ diag(a) @ S.T (001 (2.6))."""

def polar(X: _In) -> tuple[_F, _F]:
    """Polar decomposition X = R @ P, R in SO(n), P symmetric positive definite."""

def stratum(X: _In, tol: float = 1e-8) -> _GLStratum:
    """Coincidences of the singular values of X (001 §6.1, (9.2))."""


# --- rotation interop (scipy.spatial.transform.Rotation conventions) ---
# Quaternions are Hamilton, R v = q v q̄; scalar_first=True is (w, x, y, z), False is scipy's
# default (x, y, z, w). Euler sequences: 3 letters of x, y, z, upper case = intrinsic ("XYZ" is
# Rx(a) @ Ry(b) @ Rz(c)), lower case = extrinsic ("xyz" is Rz(c) @ Ry(b) @ Rx(a)); the 12
# proper-Euler and Tait–Bryan sequences; radians. All map over any leading axes.

def to_quaternion(R: _In, scalar_first: bool = True) -> _F:
    """(..., 3, 3) -> (..., 4) unit quaternions, canonical sign (w >= 0; scipy's canonical=True)."""

def from_quaternion(q: _In, scalar_first: bool = True) -> _F:
    """(..., 4) -> (..., 3, 3); q is normalised (InvalidArgumentError for q = 0)."""

def to_euler(R: _In, seq: str) -> _F:
    """(..., 3, 3) -> (..., 3) angles as scipy's as_euler(seq) (gimbal lock: third angle 0, no warning)."""

def from_euler(angles: _In, seq: str) -> _F:
    """(..., 3) -> (..., 3, 3) as scipy's Rotation.from_euler(seq, angles).as_matrix()."""

def to_scipy(R: _In) -> Any:
    """scipy.spatial.transform.Rotation of R (ImportError without scipy)."""

def from_scipy(rotation: Any) -> _F:
    """Rotation matrices of a scipy Rotation: (3, 3) or (*rotation.shape, 3, 3)."""
