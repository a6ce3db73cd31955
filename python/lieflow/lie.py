"""Matrix Lie groups and algebras (bindings of ``lieflow::lie``).

All functions take numpy float64 arrays (or array-likes) and return new arrays; see each
function's docstring for the equation it implements.
"""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.lie, globals())
