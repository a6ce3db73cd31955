"""Continuation of families of relative equilibria (binding of ``lieflow::analysis::continuation``).

``follow(start, parameter="e", stop=0.9)`` follows the family of a figure of
:mod:`lieflow.ellipsoids` by pseudo-arclength continuation and returns a :class:`Branch`:
``points``, ``values``, ``stability`` (spectral) and ``energy_momentum`` flags,
``special_points`` (``kind`` "branch", "fold" or "stability", the parameter as an attribute,
e.g. ``.e``), ``switch(point)`` to follow the branch that crosses at a branch point, and
``plot()``.
"""

from . import _lieflow
from ._reexport import reexport as _reexport

__all__ = _reexport(_lieflow.continuation, globals())
from .periodic import PeriodicBranch, PeriodicSpecialPoint, periodic_family  # noqa: E402

__all__ += ["PeriodicBranch", "PeriodicSpecialPoint", "periodic_family"]

_LABELS = {
    "e": "eccentricity $e$",
    "a2_over_a1": "$a_2/a_1$",
    "a3_over_a1": "$a_3/a_1$",
    "Omega2_over_piGrho": r"$\Omega^2/(\pi G\rho)$",
    "L": r"$L/\sqrt{GM^3\bar a}$",
    "f": r"$f = \zeta/\Omega$",
}


def _plot_branch(branch, ax=None, *, x, y, label=None, color=None, **kwargs):
    """Draw ``branch`` (``Branch.plot``): stable segments solid, unstable dashed, special points marked."""
    import matplotlib.pyplot as plt
    import numpy as np

    if ax is None:
        ax = plt.gca()
    xs, ys = branch.values_of(x), branch.values_of(y)
    stable = branch.stability
    if len(stable) == 0:
        stable = np.ones(len(xs), dtype=bool)
    line = None
    start = 0
    for k in range(1, len(xs) + 1):
        if k == len(xs) or stable[k] != stable[start]:
            seg = slice(start, min(k + 1, len(xs)))
            style = "-" if stable[start] else "--"
            (line,) = ax.plot(
                xs[seg],
                ys[seg],
                style,
                color=color if line is None else line.get_color(),
                label=label if line is None else None,
                **kwargs,
            )
            start = k
    marks = {"branch": ("o", "branch point"), "fold": ("s", "fold"), "stability": ("x", "stability change")}
    for sp in branch.special_points:
        m, _ = marks[sp.kind]
        ax.plot(getattr(sp, x), getattr(sp, y), m, color="k", mfc="none" if m == "o" else None)
    ax.set_xlabel(_LABELS.get(x, x))
    ax.set_ylabel(_LABELS.get(y, y))
    return ax
