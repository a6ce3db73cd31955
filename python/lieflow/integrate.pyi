# Type stubs for lieflow.integrate (the integration driver and Trajectory).
from typing import Any, Callable, Iterable, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

_F64 = NDArray[np.float64]

__all__ = ["integrate", "load", "Trajectory", "CHUNK_WORK", "MIN_CHUNK_STEPS"]

CHUNK_WORK: int
MIN_CHUNK_STEPS: int

# The driver's argument checks, shared with lieflow.ensemble (private).
_MAX_COUNT: int
def _count(name: str, value: Any) -> int: ...
def _step(dt: Any) -> float: ...
def _real(value: Any) -> bool: ...
def _time(name: str, value: Any) -> float: ...
def _check_system(system: Any) -> None: ...
def _check_method(method: Any) -> None: ...

class _NativeRun(Protocol):
    method: str
    def advance(self, steps: int) -> tuple[_F64, _F64 | None]: ...
    def state(self) -> tuple[_F64, _F64 | None]: ...

class _OutputControl(_NativeRun, Protocol):
    """What `integrate` uses besides `_NativeRun` (`lieflow.Integration` has all of it; a
    duck-typed run without it supports the plain runs only): `_chunk` returns the times of
    its samples, the current state and the time of the final state."""

    members: int
    batched: bool
    save_every: int
    t0: float
    dt: float
    stopped_by: int | None
    def _chunk(self, steps: int | None, t: float | None = None) -> tuple[Any, ...]: ...
    def _partial(self) -> tuple[Any, ...] | None: ...
    def _head(self) -> tuple[Any, ...]: ...
    def _initial(self) -> tuple[_F64, _F64 | None]: ...
    def set_events(
        self, functions: list[Callable[[float, _F64], float]], directions: list[float],
        terminal: list[int], tol: float,
    ) -> None: ...
    def steps_to(self, t: float) -> int: ...

class _EventFunction(Protocol):
    """g(t, state) -> float, with the optional attributes of scipy's events: `terminal` (bool,
    or the number of occurrences that ends the run) and `direction` (> 0 rising, < 0 falling,
    0 both)."""

    def __call__(self, t: float, state: _F64, /) -> float: ...

class _IntegrableSystem(Protocol):
    """The protocol `integrate` drives (implemented once by `lieflow.System`)."""

    @property
    def state_dim(self) -> int: ...
    def methods(self) -> list[str]: ...
    def _normalize_state(self, state0: Any) -> tuple[_F64, bool]: ...
    def _start(
        self, state0: Any, attitude0: Any, dt: Any, method: Any, save_every: Any,
        t0: Any = ..., threads: Any = ..., steps: Any = ..., first_member: int | None = None,
        t_eval: _F64 | None = None, single: bool = False,
    ) -> _NativeRun: ...
    def energy(self, states: ArrayLike) -> _F64 | float: ...
    def invariants(self, states: ArrayLike) -> _F64: ...
    @property
    def invariant_names(self) -> list[str]: ...

def integrate(
    system: _IntegrableSystem,
    state0: Any,
    dt: float,
    steps: int | None = None,
    method: str | None = None,
    save_every: int = 1,
    attitude: ArrayLike | None = None,
    progress: bool = False,
    chunk_steps: int | None = None,
    threads: int | None = None,
    *,
    t0: float | None = None,
    t_span: tuple[float, float] | None = None,
    t_eval: ArrayLike | None = None,
    events: _EventFunction | list[_EventFunction] | None = None,
    event_tol: float = 0.0,
    sensitivity: bool = False,
) -> Trajectory:
    """Integrate `steps` fixed steps of size `dt` from time `t0`; k = steps // save_every + 1
    samples, or the states at the times `t_eval` (shortened steps between grid times; with
    steps=None the run ends at t_eval[-1]; `t_span=(t0, t1)`: ceil((t1 - t0)/dt) equal steps
    ending at t1). `events`: scipy-style event functions (attributes
    `terminal`, `direction`), located on the method's trajectory by shortened steps. An
    exception during the run carries `err.partial`, the trajectory computed before it.
    `sensitivity=True`: also the Jacobians of the method's discrete map (`traj.jacobian`)."""

from .trajectory import Trajectory as Trajectory, load as load
