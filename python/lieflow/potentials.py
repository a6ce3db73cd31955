"""Potentials U(X) of pseudo-rigid bodies (bindings of ``lieflow::pseudo_rigid::potential``, 001 §4.1).

``Harmonic(k)``, ``SaintVenantKirchhoff(lam, mu)``, ``Volumetric(kappa, gamma)``, ``Zero()`` and
``Callable(value, gradient)`` (Python callables: the slow path) build :class:`Potential` objects;
add them with ``+``.
"""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.potentials, globals())
