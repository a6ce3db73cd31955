"""Generalized pseudo-rigid bodies on GL+(n) (bindings of ``lieflow::pseudo_rigid``, 001)."""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.pseudo_rigid, globals())
