"""Generalized pseudo-rigid bodies on GL+(n) (bindings of ``lieflow::pseudo_rigid``, 001)."""

from . import _lieflow
from ._reexport import reexport

__all__ = reexport(_lieflow.pseudo_rigid, globals())
