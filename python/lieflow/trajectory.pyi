"""The result of `lieflow.integrate`: `Trajectory` and `load`."""
import os
from typing import Any, Iterable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .integrate import _IntegrableSystem

_F64 = NDArray[np.float64]

__all__ = ["Trajectory", "load"]

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
    jacobian: _F64 | None
    """(k, d, d) / (b, k, d, d) Jacobians dz_k/dz_0 with sensitivity=True, else None."""
    final_jacobian: _F64 | None
    parameter_jacobian: _F64 | None
    """(k, d, p) / (b, k, d, p) derivatives dz_k/dtheta along `system.parameters`."""
    final_parameter_jacobian: _F64 | None
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
        jacobian: _F64 | None = None, final_jacobian: _F64 | None = None,
        parameter_jacobian: _F64 | None = None, final_parameter_jacobian: _F64 | None = None,
    ) -> None: ...
    def vjp(self, cotangent: ArrayLike) -> tuple[_F64, _F64]:
        """(grad_state0, grad_parameters) of a loss from its cotangent on the final state (d,)
        or on every sample (k, d)."""
    @classmethod
    def concatenate(cls, trajectories: Iterable[Trajectory]) -> Trajectory:
        """A run and its continuations (each starting at the previous `t_final` from its
        `final_state`) as one trajectory; the repeated sample at a seam kept once."""
    @property
    def batched(self) -> bool: ...
    def __len__(self) -> int: ...
    def energy(self) -> _F64:
        """(k,) or (b, k)."""
    @property
    def invariant_names(self) -> list[str]:
        """The system's label for each column of ``invariants()``."""
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
