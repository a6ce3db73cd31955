"""Type stubs of the native extension ``lieflow._lieflow`` (import ``lieflow`` instead).

States of the Lie–Poisson systems are flat float64 vectors z of length ``state_dim``;
observables are vectorised over leading axes (..., d) and return a float for a single state.
"""

from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any, Literal, overload

from typing_extensions import Self, disjoint_base, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .potentials import Potential

_F64 = NDArray[np.float64]

__all__ = [
    "LieflowError", "NotInGroupError", "ShapeError", "NonFiniteError", "DegenerateStratumError",
    "NoUniqueLogError", "InvalidArgumentError", "UnsupportedMethodError", "ConvergenceError",
    "LeftDomainError", "LieflowWarning", "ArgumentTypeError", "lie", "pseudo_rigid", "potentials", "spaces", "surfaces",
    "elliptic", "ellipsoids", "continuation", "System", "Integration", "_Tangent", "_Lyapunov", "_periodic_orbit", "_periodic_family",
    "RigidBody",
    "GeneralizedRigidBody", "HeavyTop", "SphericalPendulum", "Pendulum", "SphereParticle",
    "RollingDisk", "RollingSpheres", "RollingDisks", "RollingDisksEquilibrium",
    "RelativisticTangentTop", "WeakFieldTop", "StaticFieldTop", "TangentTop", "ChargedParticle",
    "FrameTop", "Canonical", "Separable", "LiePoisson", "EulerPoincare", "Forced", "PseudoRigidBody", "__version__",
    "inertia_tensor", "mass_matrix", "spatial_inertia",
]

class LieflowError(ValueError): ...
class NotInGroupError(LieflowError): ...
class ShapeError(LieflowError): ...
class NonFiniteError(LieflowError): ...
class DegenerateStratumError(LieflowError): ...
class NoUniqueLogError(LieflowError): ...
class InvalidArgumentError(LieflowError): ...
class UnsupportedMethodError(LieflowError): ...
class ConvergenceError(LieflowError): ...
class LeftDomainError(LieflowError): ...
class LieflowWarning(UserWarning): ...
class ArgumentTypeError(TypeError): ...

__version__: str
lie: ModuleType
pseudo_rigid: ModuleType
potentials: ModuleType
elliptic: ModuleType
ellipsoids: ModuleType
continuation: ModuleType
spaces: ModuleType
surfaces: ModuleType


@final
class Integration:
    """A native run in progress (from `System._start`); `advance` continues it."""

    method: str
    members: int
    batched: bool
    save_every: int
    t0: float
    dt: float
    @property
    def time(self) -> float: ...
    def advance(self, steps: int) -> tuple[_F64, _F64 | None]:
        """The states (b, k, d) and attitudes (b, k, 3, 3) | None saved in `steps` more steps."""
    def state(self) -> tuple[_F64, _F64 | None]:
        """The current states (b, d) and attitudes (b, 3, 3) | None."""
    def finish(self, t: float) -> tuple[_F64, _F64 | None]:
        """Advances to the time `t` (a last shortened step between grid times ends the run)."""
    def save_at(self, t_eval: ArrayLike) -> None:
        """Saves the states at the times `t_eval` instead of every `save_every`-th state."""
    def set_events(
        self, functions: list[Callable[[float, _F64], float]], directions: ArrayLike,
        terminal: list[int], tol: float,
    ) -> None:
        """Event functions g(t, state), their directions and terminal counts (a single run)."""
    def events_found(self) -> list[tuple[int, float, _F64, _F64 | None, int]]:
        """(event index, t, state (d,), attitude (3, 3) | None, absolute step) since the last call."""
    @property
    def stopped_by(self) -> int | None: ...
    @property
    def ended(self) -> float | None: ...
    @property
    def steps_done(self) -> int: ...
    def steps_to(self, t: float) -> int: ...
    def take_partial(self) -> tuple[_F64, _F64 | None] | None: ...
    def checked_state(self) -> tuple[_F64, _F64 | None]: ...

@final
class _Tangent:
    """The layout of a system's tangent lift (internal to `lieflow.integrate`)."""
    def seed(self, states: ArrayLike) -> _F64: ...
    @property
    def directions(self) -> int: ...
    @property
    def parameters(self) -> list[str]: ...
    def split(self, lifted: ArrayLike) -> tuple[_F64, _F64, _F64]: ...

@final
class _Lyapunov:
    """A Lyapunov computation in progress (internal to `lieflow.lyapunov`)."""
    def __new__(cls, system: System, state0: Any, dt: Any, steps: Any, method: Any,
                renormalise_every: Any) -> Self: ...
    def advance(self, segments: int) -> int: ...
    @property
    def segments(self) -> int: ...
    @property
    def segments_done(self) -> int: ...
    def result(self) -> tuple[_F64, _F64, _F64, _F64]: ...

def _periodic_orbit(
    system: System, state0: Any, period: Any, method: str, steps: Any, fix: str, tol: Any,
    max_iter: Any, attitude: Any = None, relative: bool = False, drift: Any = None,
    levels: Any = None, arclength: Any = None,
) -> dict[str, Any]:
    """One shooting (internal to `lieflow.periodic_orbit`)."""

def _periodic_family(
    system: System, start: tuple[Any, ...], method: str, parameter: str, stop: float | None,
    step: Any, max_step: Any, max_points: Any, direction: Any, tol: Any,
) -> dict[str, Any]:
    """A family's continuation (internal to `lieflow.continuation.periodic_family`)."""

@disjoint_base
class System:
    """Base class of every system: the protocol `lieflow.integrate` drives, pickling, repr."""

    @classmethod
    def methods(cls) -> list[str]:
        """The integration methods; the first is the default."""
    @property
    def parameters(self) -> list[str]:
        """The parameters theta, the columns of `Trajectory.parameter_jacobian`."""
    def sensitivity_methods(self, attitude: bool = False) -> list[str]:
        """The methods whose Jacobians `integrate(..., sensitivity=True)` computes."""
    def _tangent(self, attitude: bool = False,
                 method: str | None = None) -> tuple[System, _Tangent] | None: ...
    @property
    def state_dim(self) -> int: ...
    @property
    def fields(self) -> list[str]:
        """Names of the state's blocks."""
    @property
    def has_attitude(self) -> bool: ...
    def _normalize_state(self, state0: Any) -> tuple[_F64, bool]: ...
    def _start(
        self, state0: Any, attitude0: Any, dt: Any, method: Any, save_every: Any,
        t0: Any = None, threads: Any = None, steps: Any = None, first_member: int | None = None,
        t_eval: ArrayLike | None = None, single: bool = False,
    ) -> Integration: ...
    def _run(
        self, state0: Any, attitude0: Any, dt: Any, steps: Any, save_every: Any, method: Any, *,
        t0: Any = None, threads: Any = None, first_member: int | None = None,
    ) -> tuple[_F64, _F64 | None, _F64, _F64 | None]: ...
    def energy(self, states: ArrayLike) -> _F64 | float:
        """(..., d) -> (...)."""
    def invariants(self, states: ArrayLike) -> _F64:
        """(..., d) -> (..., c): what the geometric methods keep exactly."""
    @property
    def invariant_names(self) -> list[str]:
        """A label for each value of `invariants` (``"|M|²"``, ``"M·Γ"``, …)."""
    def casimirs(self, states: ArrayLike) -> _F64:
        """The same as `invariants`."""
    def __reduce__(self) -> tuple[type, tuple[Any, ...]]: ...


@final
class RigidBody(System):
    """Free rigid body on so(3)*: z = M (3,); Casimir [|M|^2]; all six methods."""

    def __new__(cls, inertia: ArrayLike) -> Self:
        """inertia: principal moments (3,) or a (3, 3) SPD matrix."""
    @property
    def moments(self) -> _F64: ...
    @property
    def frame(self) -> _F64 | None: ...
    def angular_velocity(self, states: ArrayLike) -> _F64:
        """Omega = I^{-1} M: (..., 3) -> (..., 3)."""
    def spatial_momentum(self, states: ArrayLike, attitude: ArrayLike) -> _F64:
        """R M: (..., 3), (..., 3, 3) -> (..., 3)."""
    @overload
    def exact_solution(self, M0: ArrayLike, t: ArrayLike, attitude: None = None) -> _F64:
        """Jacobi-elliptic M(t): (..., 3) and (k,) -> (..., k, 3); scalar t -> (..., 3)."""
    @overload
    def exact_solution(
        self, M0: ArrayLike, t: ArrayLike, attitude: ArrayLike
    ) -> tuple[_F64, _F64]:
        """(M(t), R(t)) from (M0, R0 = attitude): (..., [k,] 3) and (..., [k,] 3, 3)."""

@final
class GeneralizedRigidBody(System):
    """Euler–Arnold body on so(n)*: z = e_ij coordinates of M; methods isospectral, rk4."""

    def __new__(cls, J: ArrayLike) -> Self:
        """J: principal entries (n,) or a symmetric PSD (n, n) matrix."""
    @property
    def n(self) -> int: ...
    @property
    def moments(self) -> _F64: ...
    def state(self, M: ArrayLike) -> _F64:
        """Skew (..., n, n) -> (..., n(n-1)/2)."""
    def matrix(self, states: ArrayLike) -> _F64:
        """(..., n(n-1)/2) -> skew (..., n, n)."""

@final
class HeavyTop(System):
    """Heavy top: z = (M, Gamma) (6,); Casimirs [|Gamma|^2, M . Gamma]."""

    def __new__(cls, inertia: ArrayLike, mgl: float, chi: ArrayLike = ...) -> Self: ...
    @property
    def moments(self) -> _F64: ...
    @property
    def mgl(self) -> float: ...
    @property
    def chi(self) -> _F64: ...
    def state(
        self, M: ArrayLike, Gamma: ArrayLike | None = None, attitude: ArrayLike | None = None
    ) -> _F64:
        """(M, Gamma) or (M, R^T e3) -> (..., 6)."""
    def spatial_momentum(self, states: ArrayLike, attitude: ArrayLike) -> _F64:
        """R M: (..., 6), (..., 3, 3) -> (..., 3)."""

@final
class SphericalPendulum(System):
    """Spherical pendulum on se(3)*: z = (q, L) (6,), |q| = 1, q . L = 0."""

    def __new__(cls, mass: float = 1.0, length: float = 1.0, g: float = 9.81) -> Self: ...
    @property
    def mass(self) -> float: ...
    @property
    def length(self) -> float: ...
    @property
    def g(self) -> float: ...
    def state_from_spherical(
        self, theta: ArrayLike, phi: ArrayLike, thetadot: ArrayLike | None = None,
        phidot: ArrayLike | None = None,
    ) -> _F64:
        """theta from the downward vertical; broadcasts; -> (..., 6)."""
    def vertical_momentum(self, states: ArrayLike) -> _F64 | float:
        """L3: (..., 6) -> (...)."""


@final
class Pendulum(System):
    """Planar pendulum in canonical coordinates (q, p); methods midpoint, gauss4, gauss6, verlet, rk4."""

    def __new__(cls, mass: float = 1.0, length: float = 1.0, g: float = 9.81) -> Self: ...
    def exact_solution(self, amplitude: ArrayLike, t: ArrayLike) -> _F64:
        """(...) -> (..., 2): the elliptic solution released at rest from `amplitude`."""

@final
class SphereParticle(System):
    """Particle on the sphere |q| = l in gravity (RATTLE)."""

    def __new__(cls, mass: float = 1.0, length: float = 1.0, g: float = 9.81) -> Self: ...
    def from_spherical(self, states: ArrayLike) -> _F64:
        """SphericalPendulum states (..., 6) -> (q, p) (..., 6)."""

@final
class RollingDisk(System):
    """Vertical rolling disk (nonholonomic)."""

    def __new__(
        cls, mass: float, radius: float, roll_inertia: float, turn_inertia: float,
        spring: float = 0.0, tilt: float = 0.0,
    ) -> Self: ...
    def state(self, q: ArrayLike, thetadot: float, phidot: float) -> list[float]: ...
    def constraint_residual(self, states: ArrayLike) -> _F64 | float: ...

@final
class RollingSpheres(System):
    """Two spheres rolling against each other without slipping (003 §2); state
    (z1, z2, u, Omega1, Omega2) (27,); midpoint, midpoint4, rkmk4, rk4."""

    def __new__(
        cls, r1: float, r2: float, gamma1: ArrayLike, gamma2: ArrayLike, m1: float, m2: float,
        inertia1: ArrayLike, inertia2: ArrayLike,
    ) -> Self: ...
    @property
    def scale(self) -> float: ...
    @property
    def alphas(self) -> tuple[float, float]: ...
    def state(
        self, z1: ArrayLike, z2: ArrayLike, u: ArrayLike, Omega1: ArrayLike, Omega2: ArrayLike,
    ) -> list[float]: ...
    def planar_state(self, theta: ArrayLike, phi: float, thetadot: ArrayLike) -> list[float]: ...
    def to_planar(self, state: ArrayLike, tol: float = 1e-9) -> tuple[float, float, float, float, float]: ...
    def lagrangian(self, states: ArrayLike) -> _F64 | float:
        """(..., 27) -> (...): L of 003 (8) (scale * L = energy)."""
    def curvature(self, states: ArrayLike, Omega: ArrayLike, Omega_tilde: ArrayLike) -> _F64:
        """(..., 27), (..., 2, 3), (..., 2, 3) -> (..., 3): 003 §2.2's closed form
        alpha1 alpha2 u x ((z1 W1 - z2 W2) x (z1 W1~ - z2 W2~))."""
    def curvature_by_brackets(
        self, states: ArrayLike, Omega: ArrayLike, Omega_tilde: ArrayLike, s: float = 2e-3,
    ) -> _F64:
        """The curvature -nu([X, X~]) of 003 §2.2 from the commutator of the exact flows."""
    def angular_momentum(self, states: ArrayLike) -> _F64:
        """(..., 27) -> (..., 3): total angular momentum about the centre of mass (conserved)."""
    def body_momenta(self, states: ArrayLike) -> _F64:
        """(..., 27) -> (..., 2, 3)."""
    def spatial_momenta(self, states: ArrayLike) -> _F64:
        """(..., 27) -> (..., 2, 3); P1 + P2 = angular_momentum."""
    def udot(self, states: ArrayLike) -> _F64:
        """(..., 27) -> (..., 3): du/dt of 003 (10)."""
    def contact_point(self, states: ArrayLike) -> _F64:
        """(..., 27) -> (..., 3)."""
    def centres(self, states: ArrayLike) -> _F64:
        """(..., 27) -> (..., 2, 3): geometric centres."""
    def centres_of_mass(self, states: ArrayLike) -> _F64:
        """(..., 27) -> (..., 2, 3)."""
    def accelerations(self, states: ArrayLike) -> _F64:
        """(..., 27) -> (..., 2, 3): (dOmega1/dt, dOmega2/dt)."""


# --- the pseudo-rigid body on T*GL+(n): z = (X row-major, P row-major), d = 2 n^2 ---


@final
class PseudoRigidBody(System):
    """Generalized pseudo-rigid body on T*GL+(n), H = tr(P^T P)/2 + U(X) (001 (3.22)); methods
    verlet (default), verlet4, verlet6, reduced. With ``incompressible=True`` the volume is held,
    det X = det X0 (the pressure is the multiplier): methods rattle (default), rattle4, rattle6,
    states with <cof X, P> = 0 (``project_momentum``), det X appended to the invariants."""

    def __new__(
        cls, n: int, potential: Potential | None = None, check_det: bool = True,
        incompressible: bool = False,
    ) -> Self: ...
    @property
    def n(self) -> int: ...
    @property
    def check_det(self) -> bool: ...
    @property
    def incompressible(self) -> bool: ...
    def project_momentum(self, X: ArrayLike, P: ArrayLike) -> _F64:
        """(n, n), (n, n) -> (n, n): P - kappa cof X, kappa = <cof X, P>/|cof X|^2."""
    @property
    def potential(self) -> Potential: ...
    def angular_momentum(self, states: ArrayLike) -> _F64: ...
    def circulation(self, states: ArrayLike) -> _F64: ...
    def singular_values(self, states: ArrayLike) -> _F64: ...

@final
class RelativisticTangentTop(System):
    """The relativistic tangent top in Minkowski space (002 (87)-(96)), or with `surface` the
    top on -dt^2 + g over that surface (002 (97)-(103)); inertia tr I, (I11, I12, I22) or (2, 2);
    gauss4, gauss6, midpoint, rk4."""

    def __new__(
        cls, mass: float, inertia: float | ArrayLike, surface: Any | None = None,
    ) -> Self: ...
    def state(self, x: ArrayLike, theta: float, xdot: ArrayLike, thetadot: float) -> list[float]: ...
    def lagrangian(self, x: ArrayLike, theta: float, xdot: ArrayLike, thetadot: float) -> float:
        """L of 002 (90) / (102), physical sign."""
    def prescribed_inertia(self, theta: ArrayLike, velocity: ArrayLike) -> _F64 | float:
        """F(theta) = I gamma + gamma^3 u^T K(theta) u, the centre moving with velocity u (002 (91))."""
    def prescribed_spin_rate(
        self, theta: ArrayLike, energy: ArrayLike, velocity: ArrayLike,
    ) -> _F64 | float:
        """sqrt(2 E / F(theta)), 002 (92)."""
    def prescribed_potential(
        self, theta: ArrayLike, energy: ArrayLike, velocity: ArrayLike,
    ) -> _F64 | float:
        """V(theta) = -E / F(theta): thetadot^2 / 2 + V = 0."""
    def velocities(self, states: ArrayLike) -> _F64:
        """(..., 6) -> (..., 3): (xdot, ydot, thetadot)."""
    def momentum_94(self, v: ArrayLike, p_theta: ArrayLike) -> _F64 | float:
        """|p| of the symmetric top from v and J = p_theta, 002 (94)."""
    def spin_rate_95(self, v: ArrayLike, p_theta: ArrayLike) -> _F64 | float:
        """thetadot of the symmetric top from v and J = p_theta, 002 (95)."""
    def energy_96(self, v: ArrayLike, thetadot: ArrayLike) -> _F64 | float:
        """The energy of the symmetric top from v and thetadot, 002 (96)."""
    def speed_and_spin(self, states: ArrayLike) -> _F64:
        """(..., 6) -> (..., 2): v = sqrt(g(xdot, xdot)), s = thetadot + w(xdot)."""
    def killing_momenta(self, states: ArrayLike) -> _F64:
        """(..., 6) -> (..., k): the Killing momenta of the surface (the plane's by default)."""

@final
class WeakFieldTop(System):
    """The tangent top in a weak static gravitational field (002 (115)-(120), corrected)."""

    def __new__(
        cls, mass: float, inertia: float, gm: float | None = None,
        g: tuple[float, float] | None = None,
    ) -> Self: ...
    def state(self, x: ArrayLike, theta: float, xdot: ArrayLike, thetadot: float) -> list[float]: ...
    def lagrangian(self, x: ArrayLike, theta: float, xdot: ArrayLike, thetadot: float) -> float:
        """L of 002 (118), coupling sign corrected, physical sign."""
    def angular_momentum(self, states: ArrayLike) -> _F64 | float: ...

@final
class StaticFieldTop(System):
    """The symmetric relativistic top on -exp(2 phi) dt^2 + dx^2, or with `surface` on
    -exp(2 phi) dt^2 + g over that surface (002 (115)-(117), derived again); gauss4, gauss6,
    midpoint, rk4."""

    def __new__(
        cls, mass: float, inertia: float, gm: float | None = None,
        g: tuple[float, float] | None = None, surface: Any | None = None,
    ) -> Self: ...
    def state(self, x: ArrayLike, theta: float, xdot: ArrayLike, thetadot: float) -> list[float]: ...
    def lagrangian(self, x: ArrayLike, theta: float, xdot: ArrayLike, thetadot: float) -> float:
        """L of 002 (117), physical sign."""
    def velocities(self, states: ArrayLike) -> _F64:
        """(..., 6) -> (..., 3): (xdot, ydot, thetadot)."""
    def angular_momentum(self, states: ArrayLike) -> _F64 | float: ...
    def killing_momenta(self, states: ArrayLike) -> _F64:
        """(..., 6) -> (..., k): the Killing momenta of the plane or the surface."""

@final
class TangentTop(System):
    """The tangent Euler top on a surface (002 §II-III), intrinsic or embedded ((37)/(39));
    midpoint, gauss4, gauss6, rk4."""

    def __new__(
        cls, surface: Any, mass: float, inertia: float | ArrayLike, embedded: bool = False,
    ) -> Self: ...
    @property
    def tensor(self) -> list[list[float]]: ...
    def state(self, x: ArrayLike, theta: float, xdot: ArrayLike, thetadot: float) -> list[float]: ...
    def metric(self, x: ArrayLike, theta: float) -> _F64:
        """(3, 3): the configuration metric g_AB of 002 (47) (corrected cross terms)."""
    def lagrangian(self, x: ArrayLike, theta: float, xdot: ArrayLike, thetadot: float) -> float:
        """L = m g(xdot, xdot)/2 + I (thetadot + w(xdot))^2 / 2 (002 (43)-(47))."""
    def velocities(self, states: ArrayLike) -> _F64: ...
    def p_theta(self, states: ArrayLike) -> _F64 | float: ...
    def killing_momenta(self, states: ArrayLike) -> _F64: ...
    def ambient_frame(self, states: ArrayLike) -> _F64:
        """(..., 6) -> (..., 3, 3): rows c, E1, E2 in R^3."""
    def magnetic_analogue(self, p_theta: float) -> ChargedParticle: ...

@final
class FrameTop(System):
    """The tangent Euler top on a three-dimensional space (002 §V): on a space form exact,
    splitting, splitting4, splitting6, rk4; on a Riemannian chart midpoint, midpoint4, midpoint6,
    rkmk4, rk4."""

    def __new__(cls, space: Any, mass: float, inertia: ArrayLike) -> Self: ...
    @property
    def space(self) -> Any: ...
    @property
    def mass(self) -> float: ...
    @property
    def inertia(self) -> _F64: ...
    def state(self, x: ArrayLike, R: ArrayLike, xdot: ArrayLike, omega: ArrayLike) -> _F64: ...
    def position(self, states: ArrayLike) -> _F64: ...
    def frame(self, states: ArrayLike) -> _F64: ...
    def velocity(self, states: ArrayLike) -> _F64: ...
    def angular_velocity(self, states: ArrayLike) -> _F64: ...
    def killing_momenta(self, states: ArrayLike) -> _F64: ...
    def group_momentum(self, states: ArrayLike) -> _F64:
        """On S^3: (..., 4, 4) so(4) body momentum M, dM/dt = [M, xi]."""
    def group_inertia(self) -> _F64:
        """On S^3: (6, 6) inertia of the SO(4) top in e_ij coordinates."""
    def translational_energy(self, states: ArrayLike) -> _F64 | float: ...
    def rotational_energy(self, states: ArrayLike) -> _F64 | float: ...

@final
class ChargedParticle(System):
    """The charged particle of 002 §III.B equivalent to a tangent top (Routh form)."""

    def __new__(cls, top: TangentTop, charge: float) -> Self: ...
    @property
    def charge(self) -> float: ...
    def metric(self, x: ArrayLike) -> list[list[float]]: ...
    def potential(self, x: ArrayLike) -> list[float]: ...
    def state(self, x: ArrayLike, xdot: ArrayLike) -> list[float]: ...
    def velocities(self, states: ArrayLike) -> _F64: ...
    def killing_momenta(self, states: ArrayLike) -> _F64: ...

@final
class RollingDisks(System):
    """Two disks rolling against each other in the plane (003 §1); gauss4, gauss6, midpoint, rk4."""

    def __new__(
        cls, r1: float, r2: float, gamma1: complex | ArrayLike, gamma2: complex | ArrayLike,
        m1: float, m2: float, inertia1: float, inertia2: float, rolling_constant: float = 0.0,
    ) -> Self: ...
    @property
    def rolling_constant(self) -> float: ...
    def state(self, theta: ArrayLike, thetadot: ArrayLike) -> list[float]: ...
    def mass_matrix(self, theta: ArrayLike) -> list[list[float]]: ...
    def locked_inertia(self, theta: ArrayLike) -> float: ...
    def angular_momentum(self, states: ArrayLike) -> _F64 | float: ...
    def positions(self, states: ArrayLike) -> dict[str, _F64]:
        """(..., 4) -> {"centres": (..., 2, 2), "masses": (..., 2, 2), "contact": (..., 2)}."""
    def relative_equilibria(
        self, rolling_constant: float | None = None,
        theta1_range: tuple[float, float] = (0.0, 6.283185307179586),
    ) -> list[RollingDisksEquilibrium]: ...

@final
class RollingDisksEquilibrium:
    """A rotational relative equilibrium of RollingDisks (any angular velocity)."""

    @property
    def theta1(self) -> float: ...
    @property
    def theta2(self) -> float: ...
    @property
    def stable(self) -> bool: ...
    @property
    def degenerate(self) -> bool: ...
    @property
    def contact_point(self) -> tuple[float, float]: ...
    @property
    def angular_velocity_range(self) -> tuple[float, float]: ...
    @property
    def locked_inertia(self) -> float: ...
    @property
    def curvature(self) -> float: ...
    def state(self, omega: float = 1.0) -> list[float]: ...

# --- user-defined systems (issue 15) ---

@final
class Canonical(System):
    """H(q, p) on T*R^d from Python callables: z = (q, p) (2d,); gauss4 (default), gauss6,
    midpoint, rk4. The callables run single-threaded with the GIL; exceptions are re-raised with
    a note naming the step; wrong shapes are ShapeError, NaN/inf NonFiniteError."""

    def __new__(
        cls, hamiltonian: Callable[[_F64, _F64], float],
        gradient: Callable[[_F64, _F64], Any] | None = None, dof: int | None = None,
        hessian: Callable[[_F64, _F64, _F64, _F64], Any] | None = None,
    ) -> Self:
        """hamiltonian(q, p) -> float; gradient(q, p) -> (dH/dq, dH/dp) of shape (2, d), or None
        for central differences; dof: the number of degrees of freedom (required);
        hessian(q, p, dq, dp) -> the gradient's derivative along (dq, dp), shape (2, d): exact
        Jacobians of every method (sensitivity=True)."""
    @property
    def dof(self) -> int: ...
    @property
    def finite_differences(self) -> bool: ...

@final
class Separable(System):
    """H = p.M^{-1}p/2 + U(q) with U from Python callables: z = (q, p) (2d,); verlet (default),
    verlet4, verlet6, gauss4, gauss6, midpoint, rk4."""

    def __new__(
        cls, mass: ArrayLike, potential: Callable[[_F64], float],
        gradient: Callable[[_F64], ArrayLike] | None = None, dof: int | None = None,
        hessian: Callable[[_F64, _F64], ArrayLike] | None = None,
    ) -> Self:
        """mass: a number (then dof is required), a vector (d,) or an SPD (d, d) matrix;
        potential(q) -> float; gradient(q) -> (d,), or None for central differences;
        hessian(q, v) -> D^2U(q)[v] (d,): exact Jacobians of the Verlet methods."""
    @property
    def dof(self) -> int: ...
    @property
    def finite_differences(self) -> bool: ...

@final
class Forced(System):
    """A system with a force or torque F(t, state) on one momentum block, Rayleigh damping
    (canonical systems) or double-bracket dissipation (Lie-Poisson systems without attitude).
    Methods: m, m4, m6 for every symmetric second-order method m of `system` (kicks around it,
    orders 2, 4, 6). A force callable runs single-threaded with the GIL."""

    def __new__(
        cls, system: System, force: Callable[[float, _F64], ArrayLike] | None = None,
        block: str | None = None, depends_on_block: bool | None = None,
        damping: float | ArrayLike | None = None, dissipation: float | None = None,
    ) -> Self:
        """force(t, state) -> the block's shape; block: None for the first of M, P, p, L, mu;
        depends_on_block=False: one call per kick (exact for a force free of its block);
        damping: c >= 0 or a symmetric PSD (d, d) matrix; dissipation: alpha >= 0."""
    @property
    def block(self) -> str | None: ...
    @property
    def terms(self) -> list[str]: ...
    @property
    def system(self) -> System: ...

def inertia_tensor(
    masses: ArrayLike | None = None, positions: ArrayLike | None = None, *,
    shape: Literal["ellipsoid", "box"] | None = None, mass: float | None = None,
    semi_axes: ArrayLike | None = None,
) -> _F64:
    """``I = sum m (x.x 1 - x x^T)`` (3, 3) of point masses or a homogeneous solid (000 §3.1)."""
def mass_matrix(
    masses: ArrayLike | None = None, positions: ArrayLike | None = None, *,
    shape: Literal["ellipsoid", "box"] | None = None, mass: float | None = None,
    semi_axes: ArrayLike | None = None,
) -> _F64:
    """J = sum m x x^T (n, n) of point masses or of a homogeneous solid in R^n."""
def spatial_inertia(R: ArrayLike, inertia: ArrayLike) -> _F64:
    """R I R^T (..., 3, 3) (000 (4.1))."""

@final
class EulerPoincare(System):
    """Mechanics from a reduced Lagrangian l(xi) or l(xi, a) (000 §4): state mu = dl/dxi (d,),
    then a (m,) with an action; left (body) or right (spatial); with attitude=g0 the
    configuration g (3, 3), (n, n) or (4, 4) is carried along. Methods: variational (default,
    the discrete Euler–Poincaré method), variational4, variational6, rkmk4, midpoint, midpoint4,
    rk4."""

    def __new__(
        cls, algebra: str | tuple[str, int] | ArrayLike,
        lagrangian: Callable[..., float] | None = None,
        inertia: ArrayLike | None = None,
        gradient: Callable[..., Any] | None = None,
        hessian: Callable[..., ArrayLike] | None = None,
        side: Literal["left", "right"] | None = None,
        action: Literal["vector"] | Callable[[_F64, _F64], ArrayLike] | None = None,
        parameter_dim: int | None = None,
    ) -> Self:
        """lagrangian: l(xi) or l(xi, a); inertia: I for l = <xi, I xi>/2 (native); gradient:
        xi -> dl/dxi, or (xi, a) -> (dl/dxi, dl/da); hessian: (xi[, a]) -> (d, d); action:
        "vector" or (xi, a) -> xi.a with parameter_dim."""
    @property
    def dim(self) -> int: ...
    @property
    def parameter_dim(self) -> int: ...
    @property
    def side(self) -> Literal["left", "right"]: ...
    @property
    def is_quadratic(self) -> bool: ...
    def state(self, xi: ArrayLike, a: ArrayLike | None = None) -> _F64:
        """(mu[, a]) with mu = dl/dxi(xi, a)."""
    def velocity(self, state: ArrayLike) -> _F64:
        """xi of a state (the inverse Legendre transform)."""
    def noether(self, states: ArrayLike, g: ArrayLike) -> _F64:
        """Ad*_{g^-1} mu (left) or Ad*_g mu (right), (..., d), at group elements (..., n, n)."""
    def diamond(self, b: ArrayLike, a: ArrayLike) -> _F64:
        """b <> a (d,): <b <> a, eta> = -<b, eta.a>."""

@final
class LiePoisson(System):
    """A Lie–Poisson system d mu/dt = ad*_{dH/dmu} mu on g* (so3, se3, ("so", n) or structure
    constants (d, d, d)), or -ad* with side="right"; rkmk4 (default), midpoint, midpoint4 (keep
    the coadjoint orbit), rk4. Casimirs: |M|^2 (so3); |Gamma|^2, M.Gamma (se3);
    tr((M^T M)^k)/2 (so(n)); or `casimirs`."""

    def __new__(
        cls, algebra: str | tuple[str, int] | ArrayLike,
        hamiltonian: Callable[[_F64], float] | ArrayLike,
        gradient: Callable[[_F64], ArrayLike] | None = None,
        casimirs: Sequence[Callable[[_F64], float]] | None = None,
        side: Literal["left", "right"] | None = None,
        hessian: Callable[[_F64, _F64], ArrayLike] | None = None,
    ) -> Self:
        """hamiltonian: a callable mu -> float, or a symmetric (d, d) matrix A for H = mu.A mu/2
        (the native path); gradient: mu -> (d,) or None (finite differences; None for a
        matrix); side: the invariance reduced from, "left" (default) or "right"; hessian:
        (mu, dmu) -> D²H(mu)[dmu] or None (with it, runs with sensitivity=True)."""
    @property
    def side(self) -> Literal["left", "right"]: ...
    @property
    def dim(self) -> int: ...
    @property
    def is_quadratic(self) -> bool: ...
    def structure_constants(self) -> _F64:
        """C (d, d, d) with [e_i, e_j] = C[i, j, k] e_k."""
