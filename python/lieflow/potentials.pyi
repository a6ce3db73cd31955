# Type stubs for lieflow.potentials (bindings of lieflow::pseudo_rigid::potential, 001 §4.1).
from typing import Callable as _Fn

from typing_extensions import final

import numpy as np
from numpy.typing import ArrayLike, NDArray

_F64 = NDArray[np.float64]

__all__ = [
    "Callable", "Harmonic", "Potential", "SaintVenantKirchhoff", "SelfGravity", "Stretch",
    "Volumetric", "Zero",
]

@final
class Potential:
    """An SO(n)×SO(n)-invariant potential U(X); add potentials with `+`."""

    def value(self, X: ArrayLike) -> float: ...
    def gradient(self, X: ArrayLike) -> _F64: ...
    def hessian(self, X: ArrayLike, V: ArrayLike) -> _F64: ...
    def __add__(self, value: Potential, /) -> Potential: ...
    def __radd__(self, value: Potential, /) -> Potential: ...

def Harmonic(k: float) -> Potential: ...
def SaintVenantKirchhoff(lam: float, mu: float) -> Potential: ...
def Volumetric(kappa: float, gamma: float = 1.4) -> Potential: ...
def Stretch(k: float) -> Potential: ...
def SelfGravity(G: float = 1.0, rho: float = 1.0) -> Potential:
    """U = -4 pi G rho R_F(s1^2, s2^2, s3^2), the self-gravity of a homogeneous ellipsoid (n = 3)."""
def Zero() -> Potential: ...
def Callable(
    value: _Fn[[_F64], float],
    gradient: _Fn[[_F64], ArrayLike],
    hessian: _Fn[[_F64, _F64], ArrayLike] | None = None,
) -> Potential: ...
