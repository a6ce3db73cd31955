"""Generalized pseudo-rigid bodies on GL+(n) (bindings of ``lieflow::pseudo_rigid``, 001).

Every function of arrays except ``stratum``, ``reduce`` and ``adjoint_motion`` maps over leading
axes: a matrix argument is ``(..., n, n)``, a vector ``(..., n)``, the leading axes of the
arguments broadcast as numpy's and the results carry them (a scalar result is a float for one
item, an array for many); n is read from the first argument, and many items are computed in
parallel without the GIL.
"""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.pseudo_rigid, globals())
