# Type stubs for lieflow.continuation (families of relative equilibria).
from typing import Any

from typing_extensions import final

import numpy as np
from numpy.typing import NDArray

from .pseudo_rigid import RelativeEquilibrium

_F64 = NDArray[np.float64]

from .periodic import PeriodicBranch as PeriodicBranch
from .periodic import PeriodicSpecialPoint as PeriodicSpecialPoint
from .periodic import periodic_family as periodic_family

__all__ = ["Branch", "PeriodicBranch", "PeriodicSpecialPoint", "SpecialPoint", "follow",
           "periodic_family"]

@final
class SpecialPoint:
    kind: str
    """"branch", "fold" or "stability"."""
    verdict: str | None
    """For kind "stability": "spectral" or "energy_momentum"."""
    value: float
    stable: list[bool]
    point: RelativeEquilibrium
    def __getattr__(self, name: str) -> float:
        """The family's parameters by name: e, a2_over_a1, a3_over_a1, Omega2_over_piGrho, L, f."""

@final
class Branch:
    points: list[RelativeEquilibrium]
    parameter: str
    values: _F64
    stability: NDArray[np.bool_]
    energy_momentum: NDArray[np.bool_]
    special_points: list[SpecialPoint]
    end: str
    def values_of(self, name: str) -> _F64: ...
    def switch(
        self, point: SpecialPoint, *, stop: float | None = None, parameter: str | None = None,
        direction: float | None = None,
    ) -> Branch: ...
    def plot(self, ax: Any = None, *, x: str | None = None, y: str = "Omega2_over_piGrho",
             **kwargs: Any) -> Any: ...
    def __len__(self) -> int: ...

def follow(
    start: RelativeEquilibrium, parameter: str = "e", stop: float = 0.9, *, stability: bool = True,
    step: float = 0.01, max_step: float = 0.05, max_points: int = 2000,
) -> Branch:
    """Pseudo-arclength continuation of the family of `start` (a figure of lieflow.ellipsoids)."""
