# Type stubs for lieflow.integrate (the integration driver and Trajectory).
import os
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
def _time(name: str, value: Any) -> float: ...
def _check_system(system: Any) -> None: ...
def _check_method(method: Any) -> None: ...
def _sample_times(t0: float, dt: float, save_every: int, k: int) -> _F64: ...
def _attitude(attitude: ArrayLike, b: int, batched: bool) -> _F64: ...

class _NativeRun(Protocol):
    method: str
    def advance(self, steps: int) -> tuple[_F64, _F64 | None]: ...
    def state(self) -> tuple[_F64, _F64 | None]: ...

class _OutputControl(_NativeRun, Protocol):
    """What `t_eval`, `events` and `err.partial` use besides `_NativeRun` (`lieflow.Integration`
    has all of it; a duck-typed run without it supports the plain runs only)."""

    time: float
    ended: float | None
    stopped_by: int | None
    steps_done: int
    def finish(self, t: float) -> tuple[_F64, _F64 | None]: ...
    def save_at(self, t_eval: ArrayLike) -> None: ...
    def set_events(
        self, functions: list[Callable[[float, _F64], float]], directions: list[float],
        terminal: list[int], tol: float,
    ) -> None: ...
    def events_found(self) -> list[tuple[int, float, _F64, _F64 | None, int]]: ...
    def steps_to(self, t: float) -> int: ...
    def take_partial(self) -> tuple[_F64, _F64 | None] | None: ...
    def checked_state(self) -> tuple[_F64, _F64 | None]: ...

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
        self, z0: _F64, attitude0: _F64 | None, dt: float, method: str | None, save_every: int, *,
        t0: float = 0.0, threads: int | None = None, steps: int | None = None,
    ) -> _NativeRun: ...
    def energy(self, states: ArrayLike) -> _F64 | float: ...
    def invariants(self, states: ArrayLike) -> _F64: ...

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
    t0: float = 0.0,
    t_eval: ArrayLike | None = None,
    events: _EventFunction | list[_EventFunction] | None = None,
    event_tol: float = 0.0,
) -> Trajectory:
    """Integrate `steps` fixed steps of size `dt` from time `t0`; k = steps // save_every + 1
    samples, or the states at the times `t_eval` (shortened steps between grid times; with
    steps=None the run ends at t_eval[-1]). `events`: scipy-style event functions (attributes
    `terminal`, `direction`), located on the method's trajectory by shortened steps. An
    exception during the run carries `err.partial`, the trajectory computed before it."""

class Trajectory:
    system: _IntegrableSystem
    method: str | tuple[str, ...]
    dt: float | None
    save_every: int | None
    """None when `t_eval` gave the times (or concatenated parts differ)."""
    t: _F64
    """(k,) sample times (absolute)."""
    t0: float
    """The time of `initial_state` (a Trajectory built by hand without times: None)."""
    t_final: float
    """The time of `final_state` (a Trajectory built by hand without times: None)."""
    status: int
    """0 reached the end, 1 a terminal event ended it, -1 failed (`err.partial`)."""
    t_events: list[_F64] | None
    """One (n_i,) array of event times per event function, or None without events."""
    state_events: list[_F64] | None
    """One (n_i, d) array of event states per event function."""
    attitude_events: list[_F64] | None
    initial_state: _F64 | None
    initial_attitude: _F64 | None
    states: _F64
    """(k, d), or (b, k, d) for a batch."""
    attitude: _F64 | None
    """(k, 3, 3) / (b, k, 3, 3) or None."""
    final_state: _F64
    final_attitude: _F64 | None
    def __init__(
        self, system: _IntegrableSystem, method: str | tuple[str, ...], t: _F64, states: _F64,
        attitude: _F64 | None, final_state: _F64, final_attitude: _F64 | None, dt: float | None,
        save_every: int | None, *, t_final: float | None = None, status: int = 0,
        t_events: list[_F64] | None = None, state_events: list[_F64] | None = None,
        attitude_events: list[_F64] | None = None, t0: float | None = None,
        initial_state: _F64 | None = None, initial_attitude: _F64 | None = None,
    ) -> None: ...
    @classmethod
    def concatenate(cls, trajectories: Iterable[Trajectory]) -> Trajectory:
        """A run and its continuations (each starting at the previous `t_final` from its
        `final_state`) as one trajectory; the repeated sample at a seam kept once."""
    @property
    def batched(self) -> bool: ...
    def __len__(self) -> int: ...
    def energy(self) -> _F64:
        """(k,) or (b, k)."""
    def invariants(self) -> _F64:
        """(k, c) or (b, k, c)."""
    def casimirs(self) -> _F64:
        """The same as `invariants()`."""
    def to_xarray(self, *, observables: bool = True) -> Any:
        """An `xarray.Dataset` (layout: `lieflow.io`)."""
    def save(self, path: str | os.PathLike[str], *, allow_pickle: bool = False) -> None:
        """Writes a NetCDF file; read it back with `lieflow.load`."""
    def __getattr__(self, name: str) -> Any:
        """Named fields of the system (M, Gamma, q, L, ...) or an observable
        `traj.NAME(...) == system.NAME(traj.states, ...)`."""

def load(path: str | os.PathLike[str] | Any, *, allow_pickle: bool = False) -> Trajectory:
    """A trajectory written by `Trajectory.save` (or a Dataset of `to_xarray()`), its system
    rebuilt."""
