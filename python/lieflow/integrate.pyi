# Type stubs for lieflow.integrate (the integration driver and Trajectory).
from typing import Any, Callable, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

F64 = NDArray[np.float64]

CHUNK_WORK: int

class NativeRun(Protocol):
    method: str
    def advance(self, steps: int) -> tuple[F64, F64 | None]: ...
    def state(self) -> tuple[F64, F64 | None]: ...

class IntegrableSystem(Protocol):
    """The protocol `integrate` drives (implemented once by `lieflow.System`)."""

    @property
    def state_dim(self) -> int: ...
    def methods(self) -> list[str]: ...
    def _normalize_state(self, state0: Any) -> tuple[F64, bool]: ...
    def _start(
        self, z0: F64, attitude0: F64 | None, dt: float, method: str | None, save_every: int, *,
        t0: float = 0.0, threads: int | None = None, steps: int | None = None,
    ) -> NativeRun: ...
    def energy(self, states: ArrayLike) -> F64 | float: ...
    def invariants(self, states: ArrayLike) -> F64: ...

def integrate(
    system: IntegrableSystem,
    state0: Any,
    dt: float,
    steps: int,
    method: str | None = None,
    save_every: int = 1,
    attitude: ArrayLike | None = None,
    progress: bool = False,
    chunk_steps: int | None = None,
    threads: int | None = None,
) -> Trajectory:
    """Integrate `steps` fixed steps of size `dt`; k = steps // save_every + 1 samples."""

class Trajectory:
    system: IntegrableSystem
    method: str
    dt: float
    save_every: int
    t: F64
    """(k,) sample times."""
    states: F64
    """(k, d), or (b, k, d) for a batch."""
    attitude: F64 | None
    """(k, 3, 3) / (b, k, 3, 3) or None."""
    final_state: F64
    final_attitude: F64 | None
    @property
    def batched(self) -> bool: ...
    def __len__(self) -> int: ...
    def energy(self) -> F64:
        """(k,) or (b, k)."""
    def invariants(self) -> F64:
        """(k, c) or (b, k, c)."""
    def casimirs(self) -> F64:
        """The same as `invariants()`."""
    def __getattr__(self, name: str) -> Any:
        """Named fields of the system (M, Gamma, q, L, ...) or an observable
        `traj.NAME(...) == system.NAME(traj.states, ...)`."""
