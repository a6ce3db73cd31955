# Stub FRAGMENT for lieflow.lie (SO(3)/so(3) fast path and SE(3)); to be merged into lie.pyi.
# Every function accepts one element or a batch along a leading axis b and returns the same
# batching. so(3) vectors use the physics hat map (hat(w) @ x == cross(w, x)); se(3) vectors are
# (omega, v) with the rotation FIRST; SE(3) elements are 4x4 homogeneous matrices.
import numpy as np
from numpy.typing import ArrayLike, NDArray

def hat(w: ArrayLike) -> NDArray[np.float64]:
    """(3,) -> (3, 3) or (b, 3) -> (b, 3, 3): skew matrix with hat(w) @ x = w x x."""

def vee(xi: ArrayLike) -> NDArray[np.float64]:
    """(3, 3) -> (3,) or (b, 3, 3) -> (b, 3); NotInGroupError if xi is not skew."""

def so3_exp(w: ArrayLike) -> NDArray[np.float64]:
    """Rodrigues: (3,) -> (3, 3) or (b, 3) -> (b, 3, 3)."""

def so3_log(r: ArrayLike, strict: bool = False) -> NDArray[np.float64]:
    """Principal log |w| <= pi: (3, 3) -> (3,) or (b, 3, 3) -> (b, 3); strict raises at pi."""

def so3_cayley(w: ArrayLike) -> NDArray[np.float64]:
    """cay(w) = (I - hat(w)/2)^-1 (I + hat(w)/2): (3,) -> (3, 3), batched."""

def so3_cayley_inv(r: ArrayLike) -> NDArray[np.float64]:
    """Inverse Cayley map: (3, 3) -> (3,), batched; InvalidArgumentError at a half turn."""

def so3_jacobian_right(w: ArrayLike, inverse: bool = False) -> NDArray[np.float64]:
    """J_r(w) (or J_r(w)^-1): exp(w + d) ~ exp(w) exp(J_r d); (3,) -> (3, 3), batched."""

def so3_jacobian_left(w: ArrayLike, inverse: bool = False) -> NDArray[np.float64]:
    """J_l(w) (or J_l(w)^-1): exp(w + d) ~ exp(J_l d) exp(w); (3,) -> (3, 3), batched."""

def se3_exp(xi: ArrayLike) -> NDArray[np.float64]:
    """(6,) -> (4, 4) or (b, 6) -> (b, 4, 4); xi = (omega, v)."""

def se3_log(g: ArrayLike, strict: bool = False) -> NDArray[np.float64]:
    """(4, 4) -> (6,) or (b, 4, 4) -> (b, 6); strict raises NoUniqueLogError at angle pi."""

def se3_Ad(g: ArrayLike) -> NDArray[np.float64]:
    """Adjoint matrix [[R, 0], [hat(t) R, R]]: (4, 4) -> (6, 6), batched."""

def se3_inverse(g: ArrayLike) -> NDArray[np.float64]:
    """(4, 4) -> (4, 4), batched."""

def se3_compose(g: ArrayLike, h: ArrayLike) -> NDArray[np.float64]:
    """g @ h for (4, 4) or (b, 4, 4) (a single matrix broadcasts against a batch)."""
