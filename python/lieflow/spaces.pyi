# Type stubs for lieflow.spaces (002 §V).
from typing_extensions import final

import numpy as np
import numpy.typing as npt

_F64 = npt.NDArray[np.float64]

__all__ = ["Euclidean", "Hyperbolic", "Space", "Sphere"]

@final
class Space:
    """A three-dimensional space form with a global orthonormal reference frame field."""
    @property
    def curvature(self) -> float: ...
    @property
    def radius(self) -> float: ...
    @property
    def ambient_dim(self) -> int: ...
    def reference_frame(self, x: npt.ArrayLike) -> _F64:
        """(d, 3): the columns Ê1, Ê2, Ê3 at x (ambient components)."""
    def __eq__(self, value: object, /) -> bool: ...
    def __hash__(self) -> int: ...

def Euclidean(n: int = 3) -> Space: ...
def Sphere(n: int = 3, radius: float = 1.0) -> Space: ...
def Hyperbolic(n: int = 3, radius: float = 1.0) -> Space: ...
