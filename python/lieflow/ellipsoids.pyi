# Type stubs for lieflow.ellipsoids (self-gravitating fluid ellipsoids, EFE ch. 5-7).
import numpy as np
from numpy.typing import ArrayLike, NDArray

from .pseudo_rigid import RelativeEquilibrium

_F64 = NDArray[np.float64]

__all__ = [
    "dedekind", "index_symbols", "jacobi", "maclaurin", "maclaurin_jacobi_bifurcation",
    "riemann_s",
]

def maclaurin(e: float, *, G: float = 1.0, rho: float = 1.0) -> RelativeEquilibrium:
    """The Maclaurin spheroid a = (1, 1, sqrt(1 - e^2)), 0 <= e < 1."""
def jacobi(a2_over_a1: float, *, G: float = 1.0, rho: float = 1.0) -> RelativeEquilibrium:
    """The Jacobi ellipsoid with a1 = 1, a2 = a2_over_a1 in (0, 1] (EFE §39)."""
def dedekind(a2_over_a1: float, *, G: float = 1.0, rho: float = 1.0) -> RelativeEquilibrium:
    """The Dedekind ellipsoid adjoint (X -> X^T) to the Jacobi ellipsoid with the same axes."""
def riemann_s(
    a2_over_a1: float, f: float, *, G: float = 1.0, rho: float = 1.0
) -> RelativeEquilibrium:
    """The Riemann S-type ellipsoid with a1 = 1, a2 = a2_over_a1 and f = zeta/Omega."""
def maclaurin_jacobi_bifurcation(*, G: float = 1.0, rho: float = 1.0) -> RelativeEquilibrium:
    """The Maclaurin spheroid where the Jacobi ellipsoids branch off (e = 0.81267)."""
def index_symbols(a: ArrayLike) -> tuple[_F64, _F64]:
    """Chandrasekhar's index symbols (A (3,), A_ij (3, 3)) (EFE ch. 3 §21)."""
