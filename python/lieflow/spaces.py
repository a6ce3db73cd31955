"""The three-dimensional space forms the :class:`lieflow.FrameTop` moves on (bindings of
``lieflow::systems::tangent_top::space_form``, 002 §V): ``Euclidean(3)``, ``Sphere(3, radius)``,
``Hyperbolic(3, radius)``. They pickle."""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.spaces, globals())
