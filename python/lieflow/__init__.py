"""lieflow: geometric mechanics on Lie groups with a Rust core.

Submodules
----------
lie           matrix Lie groups and algebras: SO(n), SO(3), SE(3), GL+(n), SO(n)×SO(n)
pseudo_rigid  generalized pseudo-rigid bodies on GL+(n) (inertia tensors, connections, momenta)
elliptic      Jacobi elliptic functions sn, cn, dn and the integrals K(m), F(phi | m)

Systems and integration
-----------------------
RigidBody, GeneralizedRigidBody, HeavyTop, SphericalPendulum   Lie–Poisson systems of 000 §3–§5
integrate(system, state0, dt=..., steps=..., method=...)        -> Trajectory

Errors are subclasses of :class:`LieflowError` (itself a ``ValueError``).
"""

from ._lieflow import (
    ConvergenceError,
    DegenerateStratumError,
    InvalidArgumentError,
    LeftDomainError,
    LieflowError,
    NoUniqueLogError,
    NonFiniteError,
    NotInGroupError,
    ShapeError,
    UnsupportedMethodError,
    __version__,
)
from ._lieflow import (
    GeneralizedRigidBody,
    HeavyTop,
    LiePoissonSystem,
    RigidBody,
    SphericalPendulum,
)
from . import elliptic, lie, pseudo_rigid
from .integrate import Trajectory, integrate
from ._lieflow import PseudoRigidBody; from . import potentials  # noqa: E702

__all__ = [
    "ConvergenceError",
    "DegenerateStratumError",
    "GeneralizedRigidBody",
    "HeavyTop",
    "InvalidArgumentError",
    "LeftDomainError",
    "LiePoissonSystem",
    "LieflowError",
    "NoUniqueLogError",
    "NonFiniteError",
    "NotInGroupError",
    "RigidBody",
    "ShapeError",
    "SphericalPendulum",
    "Trajectory",
    "UnsupportedMethodError",
    "__version__",
    "elliptic",
    "integrate",
    "lie",
    "pseudo_rigid",
]
