# Type stubs for lieflow.spaces (002 §V).
from collections.abc import Callable

from typing_extensions import final

import numpy as np
import numpy.typing as npt

_F64 = npt.NDArray[np.float64]

__all__ = ["Euclidean", "Hyperbolic", "Riemannian", "Space", "Sphere"]

@final
class Space:
    """A three-dimensional space with an orthonormal reference frame field: a space form or a
    Riemannian chart."""
    @property
    def curvature(self) -> float: ...
    @property
    def radius(self) -> float: ...
    @property
    def ambient_dim(self) -> int: ...
    def reference_frame(self, x: npt.ArrayLike) -> _F64:
        """(d, 3): the columns Ê1, Ê2, Ê3 at x (ambient or chart components)."""
    def check_frame(self, x: npt.ArrayLike, tol: float = 1e-10) -> None:
        """A Riemannian chart's frame orthonormal (E^T g E = 1 to tol) and det E > 0 at x."""
    def __eq__(self, value: object, /) -> bool: ...
    def __hash__(self) -> int: ...

def Euclidean(n: int = 3) -> Space: ...
def Sphere(n: int = 3, radius: float = 1.0) -> Space: ...
def Hyperbolic(n: int = 3, radius: float = 1.0) -> Space: ...
def Riemannian(
    metric: Callable[[float, float, float], npt.ArrayLike],
    frame: Callable[[float, float, float], npt.ArrayLike],
    domain: Callable[[float, float, float], bool] | None = None,
) -> Space: ...
