# Stub FRAGMENT for lieflow._lieflow (the Lie–Poisson system classes, re-exported as
# lieflow.RigidBody, ...); to be merged into _lieflow.pyi. States are flat float64 vectors z of
# length state_dim; observables are vectorised over leading axes (..., d) and return a float
# for a single state.
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

F64 = NDArray[np.float64]

class LiePoissonSystem:
    """Base class: the protocol `lieflow.integrate` drives."""

    @property
    def state_dim(self) -> int: ...
    @property
    def has_attitude(self) -> bool: ...
    def _normalize_state(self, state0: Any) -> tuple[F64, bool]: ...
    def _run(
        self, z0: ArrayLike, attitude0: ArrayLike | None, dt: float, steps: int,
        save_every: int, method: str,
    ) -> tuple[F64, F64 | None, F64, F64 | None]: ...
    def energy(self, states: ArrayLike) -> F64 | float:
        """(..., d) -> (...)."""
    def casimirs(self, states: ArrayLike) -> F64:
        """(..., d) -> (..., c)."""

class RigidBody(LiePoissonSystem):
    """Free rigid body on so(3)*: z = M (3,); Casimir [|M|^2]; all six methods."""

    def __init__(self, inertia: ArrayLike) -> None:
        """inertia: principal moments (3,) or a (3, 3) SPD matrix."""
    @staticmethod
    def methods() -> list[str]: ...
    @property
    def moments(self) -> F64: ...
    @property
    def frame(self) -> F64 | None: ...
    def angular_velocity(self, states: ArrayLike) -> F64:
        """Omega = I^{-1} M: (..., 3) -> (..., 3)."""
    def spatial_momentum(self, states: ArrayLike, attitude: ArrayLike) -> F64:
        """R M: (..., 3), (..., 3, 3) -> (..., 3)."""
    def exact_solution(self, M0: ArrayLike, t: ArrayLike) -> F64:
        """Jacobi-elliptic M(t): (..., 3) and (k,) -> (..., k, 3); scalar t -> (..., 3)."""
    def _fields(self, states: ArrayLike) -> dict[str, F64]: ...

class GeneralizedRigidBody(LiePoissonSystem):
    """Euler–Arnold body on so(n)*: z = e_ij coordinates of M; methods isospectral, rk4."""

    def __init__(self, J: ArrayLike) -> None:
        """J: principal entries (n,) or a symmetric PSD (n, n) matrix."""
    @staticmethod
    def methods() -> list[str]: ...
    @property
    def n(self) -> int: ...
    @property
    def moments(self) -> F64: ...
    def state(self, M: ArrayLike) -> F64:
        """Skew (..., n, n) -> (..., n(n-1)/2)."""
    def matrix(self, states: ArrayLike) -> F64:
        """(..., n(n-1)/2) -> skew (..., n, n)."""
    def _fields(self, states: ArrayLike) -> dict[str, F64]: ...

class HeavyTop(LiePoissonSystem):
    """Heavy top: z = (M, Gamma) (6,); Casimirs [|Gamma|^2, M . Gamma]."""

    def __init__(self, inertia: ArrayLike, mgl: float, chi: ArrayLike = ...) -> None: ...
    @staticmethod
    def methods() -> list[str]: ...
    @property
    def moments(self) -> F64: ...
    @property
    def mgl(self) -> float: ...
    @property
    def chi(self) -> F64: ...
    def state(
        self, M: ArrayLike, Gamma: ArrayLike | None = None, attitude: ArrayLike | None = None
    ) -> F64:
        """(M, Gamma) or (M, R^T e3) -> (..., 6)."""
    def spatial_momentum(self, states: ArrayLike, attitude: ArrayLike) -> F64:
        """R M: (..., 6), (..., 3, 3) -> (..., 3)."""
    def _fields(self, states: ArrayLike) -> dict[str, F64]: ...

class SphericalPendulum(LiePoissonSystem):
    """Spherical pendulum on se(3)*: z = (q, L) (6,), |q| = 1, q . L = 0."""

    def __init__(self, mass: float = 1.0, length: float = 1.0, g: float = 9.81) -> None: ...
    @staticmethod
    def methods() -> list[str]: ...
    @property
    def mass(self) -> float: ...
    @property
    def length(self) -> float: ...
    @property
    def g(self) -> float: ...
    def state_from_spherical(
        self, theta: ArrayLike, phi: ArrayLike, theta_dot: ArrayLike | None = None,
        phi_dot: ArrayLike | None = None,
    ) -> F64:
        """theta from the downward vertical; broadcasts; -> (..., 6)."""
    def vertical_momentum(self, states: ArrayLike) -> F64 | float:
        """L3: (..., 6) -> (...)."""
    def _fields(self, states: ArrayLike) -> dict[str, F64]: ...
