"""lieflow: geometric mechanics on Lie groups with a Rust core.

Submodules
----------
lie           matrix Lie groups and algebras: SO(n), SO(3), SE(3), GL+(n), SO(n)×SO(n)
pseudo_rigid  generalized pseudo-rigid bodies on GL+(n) (inertia tensors, connections, momenta)

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
from . import lie, pseudo_rigid
from ._lieflow import PseudoRigidBody; from . import potentials  # noqa: E702

__all__ = [
    "ConvergenceError",
    "DegenerateStratumError",
    "InvalidArgumentError",
    "LeftDomainError",
    "LieflowError",
    "NoUniqueLogError",
    "NonFiniteError",
    "NotInGroupError",
    "ShapeError",
    "UnsupportedMethodError",
    "__version__",
    "lie",
    "pseudo_rigid",
]
