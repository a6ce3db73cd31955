# Type stubs for lieflow.chaos (Lyapunov exponents and Poincaré sections).
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._lieflow import System

_F64 = NDArray[np.float64]

__all__ = ["lyapunov", "LyapunovSpectrum", "poincare_section"]

@dataclass(frozen=True, eq=False)
class LyapunovSpectrum:
    """The Lyapunov spectrum of a run: exponents (e,) sorted descending, times (segments,),
    running (segments, e) in the QR's column order, state (d,) at the end."""

    exponents: _F64
    times: _F64
    running: _F64
    state: _F64

def lyapunov(
    system: System, state0: ArrayLike | tuple[ArrayLike, ...], *, dt: float, steps: int,
    method: str | None = None, renormalise_every: int = 10,
) -> LyapunovSpectrum: ...
def poincare_section(
    system: System, state0: ArrayLike | tuple[ArrayLike, ...],
    section: Callable[[_F64], float], *, direction: float = 1, crossings: int = 100,
    method: str | None = None, dt: float | None = None, max_steps: int = 1_000_000,
) -> tuple[_F64, _F64]: ...
