"""Jacobi elliptic functions and elliptic integrals of the first kind (bindings of
``lieflow::numerics::elliptic``; parameter :math:`m = k^2` as in ``scipy.special``): ``ellipj``, ``ellipk``,
``ellipf``. They give the exact solution of the free rigid body, ``RigidBody.exact_solution``."""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.elliptic, globals())
