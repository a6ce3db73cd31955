"""Self-gravitating incompressible fluid ellipsoids (bindings of ``lieflow::pseudo_rigid::ellipsoids``).

The Maclaurin spheroids, Jacobi, Dedekind and Riemann S-type ellipsoids (Chandrasekhar,
*Ellipsoidal Figures of Equilibrium*, ch. 5–7) as relative equilibria of the incompressible
pseudo-rigid body ``PseudoRigidBody(3, SelfGravity(G, rho), incompressible=True)`` (001 §8):

``maclaurin(e)``, ``jacobi(a2_over_a1)``, ``dedekind(a2_over_a1)``, ``riemann_s(a2_over_a1, f)``
and ``maclaurin_jacobi_bifurcation()`` return :class:`lieflow.pseudo_rigid.RelativeEquilibrium`
objects (``a``, ``e``, ``Omega2_over_piGrho``, ``f``, ``angular_momentum``, ``quantities``,
``motion(t)``, ``stability()``); ``index_symbols(a)`` gives Chandrasekhar's A_i and A_ij.
Follow a family with :func:`lieflow.continuation.follow`.
"""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.ellipsoids, globals())
index_symbols = _lieflow.pseudo_rigid.index_symbols
__all__ = sorted(__all__ + ["index_symbols"])
