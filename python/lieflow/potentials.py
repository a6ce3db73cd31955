r"""Potentials U(X) of pseudo-rigid bodies (bindings of ``lieflow::pseudo_rigid::potential``, 001 §4.1).

``Harmonic(k)``, ``SaintVenantKirchhoff(lam, mu)``, ``Volumetric(kappa, gamma)``, ``Stretch(k)``,
``SelfGravity(G=1.0, rho=1.0)``, ``Zero()`` and ``Callable(value, gradient, hessian=None)`` (Python
callables: the slow path) build :class:`Potential` objects; add them with ``+``. Every potential has
``value(X)``, ``gradient(X)`` and the Hessian applied to a direction, ``hessian(X, V)``.

``SelfGravity(G, rho)`` is the gravitational energy of a homogeneous ellipsoid (Chandrasekhar,
*Ellipsoidal Figures of Equilibrium* ch. 3), :math:`U = -4\pi G\rho\, R_F(s_1^2, s_2^2, s_3^2)`
over the singular values :math:`s_i` of X, for n = 3 only: the unit ball of density :math:`\rho` is
the reference configuration, and U is the physical energy divided by :math:`M/5`
(:math:`M = 4\pi\rho/3`), matching the kinetic energy :math:`\tfrac12 \operatorname{tr}(V^\top V)`. Its
index symbols are ``lieflow.pseudo_rigid.index_symbols(a)``.
"""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.potentials, globals())
