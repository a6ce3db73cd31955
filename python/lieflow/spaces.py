"""The three-dimensional spaces the :class:`lieflow.FrameTop` moves on (002 §V): the space forms
``Euclidean(3)``, ``Sphere(3, radius)``, ``Hyperbolic(3, radius)`` (bindings of
``lieflow::systems::tangent_top::space_form``) and ``Riemannian(metric, frame, domain=None)``, a
chart with its metric and an orthonormal frame field given as callables
(``lieflow::systems::tangent_top::riemannian``). They pickle (a chart with its callables)."""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.spaces, globals())
