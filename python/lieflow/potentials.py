"""Potentials U(X) of pseudo-rigid bodies (bindings of ``lieflow::pseudo_rigid::potential``, 001 §4.1).

``Harmonic(k)``, ``SaintVenantKirchhoff(lam, mu)``, ``Volumetric(kappa, gamma)``, ``Stretch(k)``,
``Zero()`` and ``Callable(value, gradient, hessian=None)`` (Python callables: the slow path) build
:class:`Potential` objects; add them with ``+``. Every potential has ``value(X)``,
``gradient(X)`` and the Hessian applied to a direction, ``hessian(X, V)``.
"""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.potentials, globals())
