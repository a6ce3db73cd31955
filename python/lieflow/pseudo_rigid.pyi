# Type stubs for lieflow.pseudo_rigid (bindings of lieflow::pseudo_rigid, 001).
# so(n) elements are skew (n, n) arrays; matrices on so(n) + so(n) use the e_ij basis with the
# xi block first. Every function of arrays except stratum, reduce and adjoint_motion maps over
# leading axes that broadcast as numpy's: a scalar result is a float for one item, an array
# for many.
from typing import Any, Callable, Literal, TypedDict

from typing_extensions import final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._lieflow import System
from .potentials import Potential

_F64 = NDArray[np.float64]
__all__ = [
    "NormalMode", "RelativeEquilibrium", "RightReduced", "Stability", "Verdict", "adjoint_motion", "amended_hessian",
    "amended_potential", "angular_momentum", "augmented_gradient", "augmented_hessian",
    "augmented_potential", "bi_connection", "bi_inertia", "bi_inertia_apply", "bi_inertia_eigen",
    "bi_inertia_quadratic_form", "bi_inertia_solve", "circulation", "e_term",
    "equilibrium_directions", "from_body", "guichardet_connection", "horizontal_part",
    "index_symbols", "kinetic_energy", "lagrange_vector_field", "left_connection", "left_inertia",
    "locked_inertia", "loop_area", "loop_circulation", "particle_locked_inertia", "reconstruct",
    "reduce", "reduced_euler_lagrange", "reduced_hamiltonian", "reduced_vector_field",
    "relative_equilibria", "riemann_bracket", "riemann_variables", "riemann_vector_field",
    "right_connection",
    "right_inertia", "stratum", "to_body", "vertical_vector",
]

_Action = Literal["two-sided", "left", "right"]

class _StratumInfo(TypedDict):
    singular_values: _F64
    multiplicities: list[int]
    min_gap: float
    principal: bool
    dim_vertical: int
    dim_horizontal: int
    isotropy: str
    isotropy_dim: int

def left_inertia(X: ArrayLike, xi: ArrayLike) -> _F64:
    """A^L_X xi = X X^T xi + xi X X^T (001 (2.11))."""

def right_inertia(X: ArrayLike, xi: ArrayLike) -> _F64:
    """A^R_X xi = X^T X xi + xi X^T X (001 (2.11))."""

def bi_inertia(X: ArrayLike) -> _F64:
    """B_X as an (n(n-1), n(n-1)) matrix (001 (6.9))."""

def bi_inertia_apply(X: ArrayLike, xi: ArrayLike, eta: ArrayLike) -> tuple[_F64, _F64]:
    """B_X(xi + eta) (001 (6.9))."""

def bi_inertia_solve(X: ArrayLike, lam: ArrayLike, gam: ArrayLike) -> tuple[_F64, _F64]:
    """B_X^{-1}(lam + gam) by the closed form (001 (7.6)-(7.9)); principal stratum only."""

def bi_inertia_eigen(X: ArrayLike) -> tuple[_F64, _F64]:
    """Eigenvalues (non-decreasing) and eigenvectors (columns) of B_X (001 (8.14)-(8.15))."""

def bi_inertia_quadratic_form(X: ArrayLike, xi: ArrayLike, eta: ArrayLike) -> float | _F64:
    """<xi + eta, B_X(xi + eta)> in SVD coordinates (001 (6.14))."""

def left_connection(X: ArrayLike, Y: ArrayLike) -> _F64:
    """omega^L_X(Y) (001 (2.14))."""

def right_connection(X: ArrayLike, Y: ArrayLike) -> _F64:
    """omega^R_X(Y) (001 (2.15))."""

def bi_connection(X: ArrayLike, Y: ArrayLike) -> tuple[_F64, _F64]:
    """omega^B_X(Y) (001 (6.18)); principal stratum only."""

def vertical_vector(X: ArrayLike, xi: ArrayLike, eta: ArrayLike) -> _F64:
    """xi X + X eta^T (001 (6.17))."""

def horizontal_part(X: ArrayLike, Y: ArrayLike, action: _Action = "two-sided") -> _F64:
    """Horizontal part of Y for the action (001 (2.20)-(2.22), (6.6), (6.23))."""

def locked_inertia(X: ArrayLike, action: _Action = "two-sided") -> _F64:
    """Locked inertia tensor from the metric tr(Y^T Z) (001 (2.27), (6.24))."""

def angular_momentum(X: ArrayLike, V: ArrayLike) -> _F64:
    """L = V X^T - X V^T (001 (2.29), (7.3))."""

def circulation(X: ArrayLike, V: ArrayLike) -> _F64:
    """Gamma = V^T X - X^T V (001 (2.29), (7.3))."""

def to_body(X: ArrayLike, V: ArrayLike) -> tuple[_F64, _F64, _F64, _F64, _F64, _F64]:
    """(R, a, S, Omega, adot, Lambda) (001 §4.1); principal stratum only."""

def from_body(
    R: ArrayLike, a: ArrayLike, S: ArrayLike, Omega: ArrayLike, adot: ArrayLike, Lambda: ArrayLike
) -> tuple[_F64, _F64]:
    """(X, V) from body coordinates (001 §4.1)."""

def kinetic_energy(X: ArrayLike, V: ArrayLike) -> float | _F64:
    """tr(V^T V) / 2 (001 (3.2), (4.5), (6.28))."""

def stratum(X: ArrayLike, tol: float = 1e-8) -> _StratumInfo:
    """Stratum, dim V_X, dim H_X and isotropy (001 (6.2), (9.2), (9.3))."""

def riemann_variables(X: ArrayLike, V: ArrayLike) -> tuple[_F64, _F64]:
    """(Q, N) = (X X^T, X V^T) (001 (3.4))."""

def riemann_bracket(
    Q: ArrayLike, N: ArrayLike, dfdQ: ArrayLike, dfdN: ArrayLike, dgdQ: ArrayLike, dgdN: ArrayLike
) -> float | _F64:
    """Poisson bracket of functions of (Q, N) (001 (9.1))."""

class _Reduced(TypedDict):
    a: _F64
    p_a: _F64
    p_Omega: _F64
    p_Lambda: _F64
    R: _F64
    S: _F64

def reduce(X: ArrayLike, P: ArrayLike) -> _Reduced:
    """(X, P) -> (a, p_a, p_Omega, p_Lambda) and the frames R, S (001 §7)."""

def reconstruct(
    R: ArrayLike, S: ArrayLike, a: ArrayLike, p_a: ArrayLike, p_Omega: ArrayLike, p_Lambda: ArrayLike
) -> tuple[_F64, _F64]:
    """(X, P) from reduced coordinates and frames (001 (7.9)); inverse of `reduce`."""

def adjoint_motion(X: ArrayLike, P: ArrayLike) -> tuple[_F64, _F64]:
    """Dedekind's adjoint motion (X^T, P^T) of stacked frames (..., n, n)."""

# --- the equations of motion (001 (3.20), Prop. 4.2, (4.8), (5.5), (7.24)-(7.28)) ---

class _LagrangeRates(TypedDict):
    p_Omega: _F64
    p_Lambda: _F64
    E: _F64
    addot: _F64
    p_Omegadot: _F64
    p_Lambdadot: _F64

class _ReducedRates(TypedDict):
    a: _F64
    p_a: _F64
    p_Omega: _F64
    p_Lambda: _F64

def riemann_vector_field(Q: ArrayLike, N: ArrayLike, potential: Any | None = None) -> tuple[_F64, _F64]:
    """(dQ/dt, dN/dt) = (N + N^T, N^T Q^-1 N - 2 Q dU/dQ) (001 (3.20))."""

def e_term(a: ArrayLike, Omega: ArrayLike, Lambda: ArrayLike) -> _F64:
    """E = D(-(Omega^2 + Lambda^2) A + Omega A Lambda + Lambda A Omega) (001 (4.8); n = 3: (5.4))."""

def lagrange_vector_field(
    a: ArrayLike, Omega: ArrayLike, Lambda: ArrayLike, potential: Any | None = None
) -> _LagrangeRates:
    """The Euler-Lagrange equations (4.11a)-(4.11c) of 001 Prop. 4.2 (n = 3: (5.5))."""

def reduced_hamiltonian(
    a: ArrayLike, p_a: ArrayLike, p_Omega: ArrayLike, p_Lambda: ArrayLike,
    potential: Any | None = None,
) -> float | _F64:
    """H = |p_a|^2/2 + <p, B_A^-1 p>/2 + U(A) on the principal stratum (001 (7.24), (6.30))."""

def reduced_vector_field(
    a: ArrayLike, p_a: ArrayLike, p_Omega: ArrayLike, p_Lambda: ArrayLike,
    potential: Any | None = None,
) -> _ReducedRates:
    """The reduced Hamilton equations (001 (7.25)-(7.28)): the rate of each variable by name."""

# --- relative equilibria and their stability (001 §8) ---

def amended_potential(X: ArrayLike, lam: ArrayLike, gam: ArrayLike, potential: Any) -> float:
    """V_{lam+gam}(X) = U(X) + <lam+gam, B_X^{-1}(lam+gam)>/2 (001 (8.11))."""
def augmented_potential(X: ArrayLike, xi: ArrayLike, eta: ArrayLike, potential: Any) -> float:
    """U_{xi+eta}(X) = U(X) - <xi+eta, B_X(xi+eta)>/2 (001 (8.12))."""
def augmented_gradient(X: ArrayLike, xi: ArrayLike, eta: ArrayLike, potential: Any) -> _F64:
    """dU_{xi+eta}/dX, (n, n)."""
def augmented_hessian(
    X: ArrayLike, xi: ArrayLike, eta: ArrayLike, potential: Any, V: ArrayLike | None = None
) -> _F64:
    """D^2U_{xi+eta}(X)[V], (n, n); without V the (n^2, n^2) row-major vec(X) matrix (001 (8.12))."""
def amended_hessian(
    X: ArrayLike, lam: ArrayLike, gam: ArrayLike, potential: Any, V: ArrayLike | None = None
) -> _F64:
    """D^2V_{lam+gam}(X)[V], (n, n); without V the (n^2, n^2) row-major vec(X) matrix (001 (8.11))."""
def equilibrium_directions(a: ArrayLike) -> list[dict[str, Any]]:
    """Velocity directions satisfying (8.6) for A = diag(a): (8.15), (8.17)-(8.18)."""
def relative_equilibria(
    potential: Any, *, shape: ArrayLike | None = None,
    velocities: tuple[ArrayLike, ArrayLike] | None = None,
    momenta: tuple[ArrayLike, ArrayLike] | None = None, plane: tuple[int, int] | None = None,
    bounds: tuple[float, float] = (0.05, 5.0), starts: int = 6, incompressible: bool = False,
) -> list[RelativeEquilibrium]:
    """Relative equilibria by shape and plane, by velocities or by momenta (001 §8);
    `incompressible=True` (with shape= and plane=) keeps det X with the pressure as multiplier."""

def index_symbols(a: ArrayLike) -> tuple[_F64, _F64]:
    """Chandrasekhar's index symbols (A (3,), A_ij (3, 3)) of the ellipsoid with semi-axes a
    (EFE ch. 3 §21): A_i by Carlson's R_D, A_ij by the trapezoidal rule in ln u."""

@final
class Verdict:
    eigenvalues: NDArray[np.complex128]
    kind: str
    stable: bool
    conclusive: bool
    min_real_part: float
    max_real_part: float
    tol: float

@final
class Stability:
    energy_momentum: Verdict
    spectral: Verdict

@final
class RelativeEquilibrium:
    shape: _F64
    a: _F64
    xi: _F64
    eta: _F64
    L: _F64
    Gamma: _F64
    energy: float
    pressure: float
    incompressible: bool
    residuals: dict[str, float]
    # The figures of lieflow.ellipsoids only (AttributeError otherwise):
    e: float
    a2_over_a1: float
    a3_over_a1: float
    Omega: float
    zeta: float
    f: float
    Omega2_over_piGrho: float
    angular_momentum: float
    circulation: float
    quantities: dict[str, float]
    def motion(self, t: ArrayLike) -> tuple[_F64, _F64]:
        """(X(t), P(t)), each (k, n, n)."""
    def stability(self) -> Stability: ...
    @property
    def body(self) -> System:
        """The body of the equilibrium over (X, P), for integrating or shooting its orbits."""
    @property
    def state(self) -> _F64:
        """(X0, P0) flat, (2 n^2,)."""
    def normal_modes(self) -> list[NormalMode]:
        """The oscillatory normal modes of the co-moving linearisation, by frequency."""

@final
class NormalMode:
    index: int
    frequency: float
    period: float
    eigenvalue: complex
    vector: NDArray[np.complex128]

def loop_circulation(X: ArrayLike, V: ArrayLike, labels: ArrayLike) -> float:
    """Kelvin's circulation of the material loop X(C0), C0 the closed polygon through the rows
    of ``labels`` (001 (2.34)); equals ``<Gamma, loop_area(labels)>``."""
def loop_area(labels: ArrayLike) -> _F64:
    """The oriented areas zeta_ij of the closed polygon through the rows of ``labels``
    (001 (2.36)), a skew (n, n) array."""
def guichardet_connection(masses: ArrayLike, positions: ArrayLike, velocities: ArrayLike) -> _F64:
    """Guichardet's connection of N particles (001 (2.23)-(2.26)), a skew (n, n) array."""
def particle_locked_inertia(masses: ArrayLike, positions: ArrayLike) -> _F64:
    """The locked inertia of N particles (001 (2.27)) in so(n)'s e_ij basis."""
def reduced_euler_lagrange(
    lagrangian: Callable[[_F64, _F64], float], Q: ArrayLike, N: ArrayLike,
    gradient: Callable[[_F64, _F64], tuple[ArrayLike, ArrayLike]] | None = None,
) -> tuple[_F64, _F64]:
    """(dQ/dt, dN/dt) of the reduced Euler-Lagrange equation (001 (3.17)) of L(Q, N)."""

@final
class RightReduced(System):
    """The pseudo-rigid body reduced by its right SO(n) symmetry (001 §3) on T*GL+(n)/SO(n),
    state (Q, N[, X]) row-major."""
    def __new__(cls, n: int, potential: Potential | None = None,
                reconstruct: bool = False) -> RightReduced: ...
    @property
    def n(self) -> int: ...
    @property
    def reconstruct_configuration(self) -> bool: ...
    @property
    def potential(self) -> Potential: ...
    def reduce(self, X: ArrayLike, P: ArrayLike) -> _F64: ...
    def reconstruct(self, states: ArrayLike) -> tuple[_F64, _F64]: ...
    def hamiltonian_parts(self, states: ArrayLike) -> _F64: ...
    def angular_momentum(self, states: ArrayLike) -> _F64: ...
    def circulation(self, states: ArrayLike) -> _F64: ...
