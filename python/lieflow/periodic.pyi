# Type stubs for lieflow.periodic (periodic and relative periodic orbits by shooting).
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._lieflow import System
from .pseudo_rigid import NormalMode, RelativeEquilibrium
from .trajectory import Trajectory

_F64 = NDArray[np.float64]
_C128 = NDArray[np.complex128]

__all__ = ["PeriodicBranch", "PeriodicOrbit", "PeriodicSpecialPoint", "periodic_family",
           "periodic_orbit"]

DEFAULT_STEPS: int

class PeriodicOrbit:
    system: System
    method: str
    state0: _F64
    period: float
    steps: int
    energy: float
    monodromy: _F64
    multipliers: _C128
    trivial: NDArray[np.bool_]
    normal_multipliers: _C128
    stable: bool
    residual: float
    iterations: int
    attitude: _F64 | None
    drift: _F64 | None
    levels: _F64
    tangent: _F64
    def __init__(self, system: System, method: str, attitude: _F64 | None,
                 fields: dict[str, Any]) -> None: ...
    @property
    def dt(self) -> float: ...
    @property
    def drift_angle(self) -> float | None: ...
    def trajectory(self, steps: int | None = None, *, periods: int = 1,
                   save_every: int = 1) -> Trajectory: ...

class _PeriodicOrbitFunction(Protocol):
    def __call__(
        self, system: System, state0: ArrayLike, period: float, *, method: str | None = None,
        dt: float | None = None, fix: str = "energy", relative: bool = False,
        attitude: ArrayLike | None = None, drift: ArrayLike | None = None,
        levels: ArrayLike | None = None, tol: float = 1e-10, max_iter: int = 30,
    ) -> PeriodicOrbit: ...
    def from_mode(
        self, equilibrium: RelativeEquilibrium, mode: NormalMode | int, amplitude: float, *,
        method: str | None = None, dt: float | None = None, fix: str = "energy",
        tol: float = 1e-10, max_iter: int = 30,
    ) -> PeriodicOrbit: ...

periodic_orbit: _PeriodicOrbitFunction

def from_mode(
    equilibrium: RelativeEquilibrium, mode: NormalMode | int, amplitude: float, *,
    method: str | None = None, dt: float | None = None, fix: str = "energy", tol: float = 1e-10,
    max_iter: int = 30,
) -> PeriodicOrbit: ...

class PeriodicSpecialPoint:
    kind: str
    index: int
    value: float
    orbit: PeriodicOrbit
    def __init__(self, kind: str, index: int, value: float, orbit: PeriodicOrbit) -> None: ...

class PeriodicBranch:
    points: list[PeriodicOrbit]
    parameter: str
    special_points: list[PeriodicSpecialPoint]
    end: str
    def __init__(self, points: list[PeriodicOrbit], parameter: str,
                 special_points: list[PeriodicSpecialPoint], end: str) -> None: ...
    @property
    def energies(self) -> _F64: ...
    @property
    def periods(self) -> _F64: ...
    @property
    def values(self) -> _F64: ...
    @property
    def stable(self) -> NDArray[np.bool_]: ...
    def __len__(self) -> int: ...
    def plot(self, ax: Any = None, *, x: str = "energy", y: str = "period",
             **kwargs: Any) -> Any: ...

def periodic_family(
    system: System, orbit: PeriodicOrbit, *, parameter: str = "energy",
    stop: float | None = None, step: float = 0.02, max_step: float = 0.05, max_points: int = 40,
    direction: float = 1, tol: float = 1e-10,
) -> PeriodicBranch: ...
