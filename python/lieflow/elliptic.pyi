# Type stubs for lieflow.elliptic (parameter m = k^2 as in scipy.special; numpy broadcasting).
import numpy as np
from numpy.typing import ArrayLike, NDArray

_F64 = NDArray[np.float64]

__all__ = ["ellipf", "ellipj", "ellipk"]

def ellipj(u: ArrayLike, m: ArrayLike) -> tuple[_F64, _F64, _F64]:
    """(sn, cn, dn)(u | m), 0 <= m < 1 (descending Landen / AGM, A&S 16.4)."""

def ellipk(m: ArrayLike) -> _F64 | float:
    """Complete elliptic integral of the first kind K(m) (AGM, A&S 17.6)."""

def ellipf(phi: ArrayLike, m: ArrayLike) -> _F64 | float:
    """Incomplete elliptic integral of the first kind F(phi | m) (Carlson R_F)."""
