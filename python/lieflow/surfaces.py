"""Surfaces for the tangent Euler top (bindings of ``lieflow::systems::tangent_top::surface``, 002 §II):
``Plane()``, ``Sphere(radius)``, ``HyperbolicPlane()``. They pickle."""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.surfaces, globals())
