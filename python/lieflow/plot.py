"""Plots and animations of lieflow trajectories with matplotlib (``pip install lieflow[plot]``).

Every function takes an optional ``ax`` (or ``axes``) to draw into and returns the matplotlib
objects it made, so they can be restyled:

* :func:`invariants` -- relative drift of the energy and the invariants against time (log scale);
* :func:`states` -- the named fields of the state against time, one panel per field;
* :func:`work_precision` -- error against cost of several methods (log-log);
* :func:`animate` -- an animation with one frame per saved sample: a body-fixed box turning in
  3-D (rigid body, heavy top; needs the attitude), the ellipsoid X·ball (pseudo-rigid body in
  2-D or 3-D), the two disks (rolling disks); saved as GIF (pillow) or MP4 (ffmpeg).
"""

from __future__ import annotations

import os
import shutil
from typing import TYPE_CHECKING, Any, Mapping, Sequence

import numpy as np

from ._lieflow import InvalidArgumentError
from .integrate import _MAX_COUNT
from ._text import brief

if TYPE_CHECKING:
    from matplotlib.animation import FuncAnimation
    from matplotlib.axes import Axes

    from .trajectory import Trajectory

__all__ = ["animate", "invariants", "states", "work_precision"]


def _pyplot():
    try:
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError("lieflow.plot needs matplotlib: pip install lieflow[plot]") from None
    return plt


def _axes(ax, **subplot):
    if ax is not None:
        return ax
    return _pyplot().subplots(**subplot)[1]


def _legend_beside(ax, fontsize="small"):
    """The legend to the right of the axes, where it covers no data."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=fontsize)


def _trajectory(traj):
    """TypeError unless `traj` is a Trajectory."""
    from .trajectory import Trajectory

    if not isinstance(traj, Trajectory):
        raise TypeError(f"invalid traj: expected a lieflow Trajectory (from lf.integrate), got "
                        f"{type(traj).__name__} {brief(traj, 60)}")
    return traj


def _relative_drift(q):
    """|q(t) − q(0)| / |q(0)| along the time axis (−2), max over leading (member) axes; the
    absolute drift for a quantity that starts at 0."""
    q0 = q[..., :1, :]
    scale = np.where(np.abs(q0) > 0, np.abs(q0), 1.0)
    d = np.abs(q - q0) / scale
    return d.reshape((-1,) + d.shape[-2:]).max(axis=0)


def invariants(traj: Trajectory, *, ax: Axes | None = None) -> Axes:
    """Relative drift of the energy and of each invariant against time, on a log scale.

    For a batch, the largest drift over the members at each time. Samples with no drift at all
    are left out (they have no logarithm); a dotted line marks machine epsilon.

    Parameters
    ----------
    traj : lieflow.Trajectory
    ax : matplotlib.axes.Axes, optional
        Where to draw (a new figure by default).

    Returns
    -------
    matplotlib.axes.Axes
    """
    _trajectory(traj)
    ax = _axes(ax, figsize=(7, 3.5), layout="constrained")
    t = np.asarray(traj.t)
    energy: Any = np.asarray(traj.energy(), dtype=float)[..., None]
    inv: Any = np.asarray(traj.invariants(), dtype=float).reshape(energy.shape[:-1] + (-1,))
    labels = ["energy"] + traj.invariant_names
    drift = _relative_drift(np.concatenate([energy, inv], axis=-1))
    for label, d in zip(labels, drift.T):
        ax.plot(t, np.where(d > 0, d, np.nan), label=label)
    ax.axhline(np.finfo(float).eps, color="0.5", ls=":", lw=1, label="machine ε")
    ax.set_yscale("log")
    ax.set(xlabel="t", ylabel="relative drift",
           title=f"{type(traj.system).__name__}, {_method(traj)}"
                 + (f" (max over {traj.states.shape[0]} members)" if traj.batched else ""))
    _legend_beside(ax)
    return ax


def _method(traj):
    m = traj.method
    return m if isinstance(m, str) else "+".join(m)


def states(traj: Trajectory, *, fields: str | Sequence[str] | None = None, member: int = 0,
           axes: Sequence[Axes] | None = None) -> np.ndarray:
    """The named fields of the state (``M``, ``Gamma``, ``X``, ``q``, ...) against time, one
    panel per field (every component of a vector or matrix field).

    Parameters
    ----------
    traj : lieflow.Trajectory
    fields : list of str, optional
        The fields to draw (default: all of ``traj.system.fields``).
    member : int
        For a batch, the member to draw.
    axes : sequence of matplotlib.axes.Axes, optional
        One per field (new figure by default).

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes
    """
    views = _trajectory(traj)._fields()
    if isinstance(fields, str):
        fields = [fields]
    try:
        names = list(views) if fields is None else list(fields)
    except TypeError:
        names = []
    unknown = [n for n in names if not isinstance(n, str) or n not in views]
    if unknown or not names:
        raise InvalidArgumentError(f"invalid fields: expected names among {list(views)}, got "
                                   f"{fields!r}")
    if axes is None:
        plt = _pyplot()
        _, axes = plt.subplots(len(names), 1, sharex=True, squeeze=False, layout="constrained",
                               figsize=(7, 1.2 + 1.6 * len(names)))
    panels = np.asarray(axes).ravel()
    if len(panels) != len(names):
        raise InvalidArgumentError(f"invalid axes: expected {len(names)} (one per field), got "
                                   f"{len(axes)}")
    if traj.batched:
        b = traj.states.shape[0]
        if isinstance(member, bool) or not isinstance(member, (int, np.integer)) \
                or not -b <= member < b:
            raise InvalidArgumentError(f"invalid member: expected an integer in [0, {b}), got "
                                       f"{brief(member, 60)}")
    t = np.asarray(traj.t)
    for ax, name in zip(panels, names):
        v = np.asarray(views[name])
        if traj.batched:
            v = v[member]
        v = v.reshape(len(t), -1)
        shape = np.asarray(views[name]).shape[traj.states.ndim - 1:]
        for j in range(v.shape[1]):
            index = np.unravel_index(j, shape) if shape else ()
            label = f"{name}[{', '.join(str(int(i)) for i in index)}]" if shape else name
            ax.plot(t, v[:, j], lw=1, label=label)
        ax.set_ylabel(name)
        if v.shape[1] <= 9:
            _legend_beside(ax, fontsize="x-small")
    panels[-1].set_xlabel("t")
    return panels


def work_precision(results: Mapping[str, tuple[Any, Any]], *, ax: Axes | None = None,
                   cost: str = "time [s]") -> Axes:
    """Work–precision diagram: for each method, its cost against its error (log-log), one
    point per step size, as in scipy's and DifferentialEquations.jl's benchmarks.

    Parameters
    ----------
    results : dict
        ``{label: (errors, costs)}``: for each method (or solver) the errors and costs of its
        runs (equal-length sequences of positive numbers).
    ax : matplotlib.axes.Axes, optional
    cost : str
        The label of the cost axis.

    Returns
    -------
    matplotlib.axes.Axes
    """
    if not isinstance(results, dict) or not results:
        raise InvalidArgumentError("invalid results: expected a non-empty dict {label: "
                                   "(errors, costs)}")
    ax = _axes(ax, figsize=(7, 4), layout="constrained")
    for label, value in results.items():
        try:
            err, work = (np.asarray(v, dtype=float).ravel() for v in value)
        except (TypeError, ValueError):
            raise InvalidArgumentError(f"invalid results[{label!r}]: expected a pair (errors, "
                                       f"costs) of sequences of numbers") from None
        if err.shape != work.shape:
            raise InvalidArgumentError(f"invalid results[{label!r}]: {err.size} errors but "
                                       f"{work.size} costs")
        order = np.argsort(err)
        ax.loglog(err[order], work[order], "o-", ms=4, label=str(label))
    ax.set(xlabel="error", ylabel=cost)
    ax.grid(True, which="both", alpha=0.3)
    _legend_beside(ax)
    return ax


# --- animations -------------------------------------------------------------------------------

def animate(traj: Trajectory, path: str | os.PathLike[str] | None = None, *, every: int = 1,
            interval: float = 40, ax: Axes | None = None) -> FuncAnimation:
    """An animation of the trajectory, one frame per saved sample (or per ``every`` samples).

    * ``RigidBody``, ``HeavyTop`` (also wrapped in ``lf.Forced``): a box with the body's
      principal axes (side lengths from the moments of inertia, as a uniform box) turning in
      3-D, with the angular momentum in space; the heavy top's box sits on its axis ``chi``
      above the fixed point. Needs the attitude (``integrate(..., attitude=R0)``).
    * ``PseudoRigidBody``: the ellipsoid X·ball (an ellipse in 2-D).
    * ``RollingDisks``: both disks, a spoke to each centre of mass, the contact point and the
      trails of the centres of mass.
    * ``RollingSpheres``: both spheres (wireframes), a spoke to each centre of mass and the
      contact point.
    * ``TangentTop`` on a surface with an embedding in R³: the centre's path and the body's
      frame (E1, E2) carried along it.

    For a batch, the first member. Every frame is stamped with its time ("t = …", top left)
    and the axes are labelled (x, y, z); a saved file is drawn at 80 dpi.

    Parameters
    ----------
    traj : lieflow.Trajectory
    path : str or os.PathLike, optional
        Save the animation there: ``.gif`` (pillow) or ``.mp4`` (needs ffmpeg).
    every : int
        Draw every ``every``-th saved sample.
    interval : float
        Milliseconds between frames (also sets the frame rate of a saved file).
    ax : matplotlib.axes.Axes, optional
        Where to draw (a 3-D axes for the boxes; a new figure by default).

    Returns
    -------
    matplotlib.animation.FuncAnimation
        Its figure is ``anim._fig``; show it in a notebook with
        ``IPython.display.HTML(anim.to_jshtml())``.

    Raises
    ------
    lieflow.InvalidArgumentError
        No animation for this system, no attitude where one is needed, ``every`` not in
        [1, 2**63 - 1], an unknown file type, MP4 without ffmpeg.
    """
    _trajectory(traj)
    if isinstance(every, bool) or not isinstance(every, (int, np.integer)) \
            or not 1 <= every <= _MAX_COUNT:
        raise InvalidArgumentError(f"invalid every: expected an integer in [1, 2**63 - 1], "
                                   f"got {brief(every, 60)}")
    every = int(every)
    if isinstance(interval, bool) or not isinstance(interval, (int, float, np.integer,
                                                               np.floating)) \
            or not 0 < interval < np.inf:
        raise InvalidArgumentError(f"invalid interval: expected milliseconds > 0, got "
                                   f"{brief(interval, 60)}")
    suffix = None
    if path is not None:
        suffix = str(path).rsplit(".", 1)[-1].lower() if "." in str(path) else ""
        if suffix not in ("gif", "mp4"):
            raise InvalidArgumentError(f"invalid path: expected a .gif or .mp4 file, got "
                                       f"{str(path)!r}")
        if suffix == "mp4" and shutil.which("ffmpeg") is None:
            raise InvalidArgumentError("invalid path: MP4 needs ffmpeg, which is not on PATH; "
                                       "save as .gif instead")
    system: Any = traj.system
    while type(system).__name__ == "Forced":
        system = system.system
    kind = type(system).__name__
    drawers = {"RigidBody": _box, "HeavyTop": _box, "PseudoRigidBody": _ellipsoid,
               "RollingDisks": _rolling_disks, "RollingSpheres": _rolling_spheres,
               "TangentTop": _tangent_top}
    if kind not in drawers:
        raise InvalidArgumentError(f"invalid trajectory: no animation for {kind}; there is one "
                                   f"for {', '.join(drawers)}")
    anim = drawers[kind](system, traj, every, interval, ax)
    if path is not None:
        # 80 dpi: a 5-inch figure at 400 px, a GIF of ~100 frames well under a megabyte.
        anim.save(str(path), writer="pillow" if suffix == "gif" else "ffmpeg",
                  fps=max(1.0, 1000.0 / interval), dpi=80)
    return anim


def _samples(traj, every, field=None):
    """The states (or the named field) and the attitudes of the frames (first member)."""
    s = np.asarray(traj.states if field is None else traj._fields()[field])
    a = traj.attitude
    if traj.batched:
        s, a = s[0], None if a is None else a[0]
    return s[::every], None if a is None else np.asarray(a)[::every]


def _animation(ax, draw, times, interval, blit):
    """The animation of ``draw(i)`` (which returns the artists it changed) over the frames at
    ``times``, each stamped "t = …" in the corner of ``ax``."""
    from matplotlib.animation import FuncAnimation
    text = ax.text2D if hasattr(ax, "text2D") else ax.text
    stamp = text(0.02, 0.98, "", transform=ax.transAxes, ha="left", va="top", fontsize=9)

    def frame(i):
        stamp.set_text(f"t = {times[i]:.4g}")
        return tuple(draw(i)) + (stamp,)

    return FuncAnimation(ax.figure, frame, frames=len(times), interval=interval, blit=blit)


def _times(traj, every):
    """The times of the frames."""
    return np.asarray(traj.t)[::every]


def _box(system, traj, every, interval, ax):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # type: ignore[import-untyped]

    momentum, att = _samples(traj, every, "M")
    if att is None:
        raise InvalidArgumentError(f"invalid trajectory: the box of {type(system).__name__} "
                                   f"needs the attitude; integrate with attitude=R0")
    inertia = np.asarray(system.moments, dtype=float)
    # A uniform box with these principal moments has sides ∝ sqrt(I_j + I_k − I_i).
    sides = np.sqrt(np.maximum(inertia.sum() - 2 * inertia, 0.05 * inertia.max()))
    half = 0.5 * sides / sides.max()
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    top = type(system).__name__ == "HeavyTop"
    offset = np.asarray(system.chi, dtype=float) if top else np.zeros(3)
    if ax is None:
        fig = _pyplot().figure(figsize=(5, 5))
        ax = fig.add_subplot(projection="3d")
    reach = 1.0 + (np.linalg.norm(offset) if top else 0.0)
    ax.set(xlim=(-reach, reach), ylim=(-reach, reach), zlim=(-reach if not top else -0.2, reach),
           xlabel="x", ylabel="y", zlabel="z")
    ax.set_box_aspect((1, 1, 1))
    box = Poly3DCollection([], facecolors=["tab:blue", "tab:blue", "tab:orange", "tab:orange",
                                           "tab:green", "tab:green"], edgecolor="k", alpha=0.7)
    ax.add_collection3d(box)
    momentum = np.einsum("kij,kj->ki", att, momentum)  # in space: R M
    scale = 0.9 * reach / max(np.linalg.norm(momentum, axis=1).max(), 1e-300)
    arrow, = ax.plot([], [], [], color="k", lw=2, label="spatial angular momentum")
    rod, = ax.plot([], [], [], color="0.3", lw=1.5)
    trail, = ax.plot([], [], [], color="tab:red", lw=0.8, alpha=0.7)
    tips = att @ offset if top else None
    ax.legend(loc="upper left", fontsize="small")
    ax.set_title(f"{type(system).__name__} ({_method(traj)})")

    def draw(i):
        world = (corners + offset) @ att[i].T
        box.set_verts([world[f] for f in faces])
        arrow.set_data_3d(*np.stack([np.zeros(3), scale * momentum[i]]).T)
        if top:
            rod.set_data_3d(*np.stack([np.zeros(3), tips[i]]).T)
            trail.set_data_3d(*tips[: i + 1].T)
        return box, arrow, rod, trail

    return _animation(ax, draw, _times(traj, every), interval, blit=False)


def _ellipsoid(system, traj, every, interval, ax):

    n = system.n
    if n not in (2, 3):
        raise InvalidArgumentError(f"invalid trajectory: the ellipsoid is drawn for n = 2 or 3, "
                                   f"got n = {n}")
    X, _ = _samples(traj, every, "X")
    reach = 1.05 * np.linalg.norm(X, ord=2, axis=(1, 2)).max()
    if n == 2:
        ax = _axes(ax, figsize=(5, 5))
        s = np.linspace(0, 2 * np.pi, 121)
        circle = np.stack([np.cos(s), np.sin(s)])
        curve, = ax.plot([], [], lw=2)
        ax.set(xlim=(-reach, reach), ylim=(-reach, reach), aspect="equal", xlabel="x",
               ylabel="y", title=f"PseudoRigidBody: X·disk ({_method(traj)})")

        def draw(i):
            curve.set_data(*(X[i] @ circle))
            return (curve,)

        return _animation(ax, draw, _times(traj, every), interval, blit=True)
    if ax is None:
        fig = _pyplot().figure(figsize=(5, 5))
        ax = fig.add_subplot(projection="3d")
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 25), np.linspace(0, np.pi, 13))
    ball = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)])
    ax.set(xlim=(-reach, reach), ylim=(-reach, reach), zlim=(-reach, reach), xlabel="x",
           ylabel="y", zlabel="z")
    ax.set_box_aspect((1, 1, 1))
    ax.set_title(f"PseudoRigidBody: X·ball ({_method(traj)})")
    surface = [None]

    def draw(i):
        if surface[0] is not None:
            surface[0].remove()
        x = np.einsum("ij,jab->iab", X[i], ball)
        surface[0] = ax.plot_surface(*x, color="tab:blue", linewidth=0.2, shade=True,
                                     edgecolor="k")
        return (surface[0],)

    return _animation(ax, draw, _times(traj, every), interval, blit=False)


def _rolling_disks(system, traj, every, interval, ax):
    """Both disks as circles about their centres, a spoke from each centre to its centre of mass
    (turning with the disk), the contact point and the trails of the centres of mass, in the
    centre-of-mass frame of the pair (003 §1)."""
    from matplotlib.patches import Circle

    states, _ = _samples(traj, every)
    pos = system.positions(states)
    centres, masses, contact = pos["centres"], pos["masses"], pos["contact"]
    radii = [np.linalg.norm(contact[0] - centres[0, 0]), np.linalg.norm(contact[0] - centres[0, 1])]
    ax = _axes(ax, figsize=(5, 5))
    reach = np.abs(centres).max() + max(radii)
    ax.set(xlim=(-reach, reach), ylim=(-reach, reach), aspect="equal", xlabel="x", ylabel="y")
    colours = ("tab:blue", "tab:orange")
    disks = [ax.add_patch(Circle(centres[0, k], radii[k], fill=False, lw=1.5, color=c))
             for k, c in enumerate(colours)]
    spokes = [ax.plot([], [], color=c, lw=1.5)[0] for c in colours]
    trails = [ax.plot([], [], color=c, lw=0.6, alpha=0.6)[0] for c in colours]
    point, = ax.plot([], [], "ko", ms=4)

    def draw(i):
        for k in range(2):
            disks[k].center = centres[i, k]
            spokes[k].set_data(*np.stack([centres[i, k], masses[i, k]]).T)
            trails[k].set_data(masses[: i + 1, k, 0], masses[: i + 1, k, 1])
        point.set_data([contact[i, 0]], [contact[i, 1]])
        return (*disks, *spokes, *trails, point)

    return _animation(ax, draw, _times(traj, every), interval, blit=True)


def _new_3d(ax):
    if ax is None:
        fig = _pyplot().figure(figsize=(5, 5))
        ax = fig.add_subplot(projection="3d")
    ax.set_box_aspect((1, 1, 1))
    return ax


def _rolling_spheres(system, traj, every, interval, ax):
    """Both spheres as wireframes about their centres, a spoke from each centre to its centre
    of mass and the contact point (003 §2), in the frame of the computation."""

    states, _ = _samples(traj, every)
    centres = system.centres(states)
    masses = system.centres_of_mass(states)
    contact = system.contact_point(states)
    radii = np.linalg.norm(contact[0] - centres[0], axis=1)
    ax = _new_3d(ax)
    lo, hi = centres.min() - radii.max(), centres.max() + radii.max()
    ax.set(xlim=(lo, hi), ylim=(lo, hi), zlim=(lo, hi), xlabel="x", ylabel="y", zlabel="z")
    ax.set_title(f"RollingSpheres ({_method(traj)})")
    u, v = np.mgrid[0:2 * np.pi:16j, 0:np.pi:9j]
    ball = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)])
    colours = ("tab:blue", "tab:orange")
    spokes = [ax.plot([], [], [], color=c, lw=2)[0] for c in colours]
    point, = ax.plot([], [], [], "ko", ms=4)
    wires = [None, None]

    def draw(i):
        for k in range(2):
            if wires[k] is not None:
                wires[k].remove()
            x = centres[i, k][:, None, None] + radii[k] * ball
            wires[k] = ax.plot_wireframe(*x, color=colours[k], lw=0.3)
            spokes[k].set_data_3d(*np.stack([centres[i, k], masses[i, k]]).T)
        point.set_data_3d(*contact[i][:, None])
        return (*wires, *spokes, point)

    return _animation(ax, draw, _times(traj, every), interval, blit=False)


def _tangent_top(system, traj, every, interval, ax):
    """The centre's path on the embedded surface and the body frame E1, E2 at the centre
    (002 §II)."""

    states, _ = _samples(traj, every)
    try:
        body = np.asarray(system.ambient_frame(states))
    except InvalidArgumentError:
        raise InvalidArgumentError("invalid trajectory: the tangent top is drawn on a surface "
                                   "with an embedding in R³; this one has none") from None
    centre, e1, e2 = body[:, 0], body[:, 1], body[:, 2]
    ax = _new_3d(ax)
    size = 0.15 * max(np.ptp(centre, axis=0).max(), 1e-3)
    lo, hi = centre.min() - 2 * size, centre.max() + 2 * size
    ax.set(xlim=(lo, hi), ylim=(lo, hi), zlim=(lo, hi), xlabel="x", ylabel="y", zlabel="z")
    surface = system.__reduce__()[1][0]           # the constructor's first argument
    ax.set_title(f"TangentTop on {surface!r} ({_method(traj)})")
    trail, = ax.plot([], [], [], color="0.4", lw=0.8)
    axes = [ax.plot([], [], [], color=c, lw=2, label=n)[0]
            for c, n in (("tab:red", "E1"), ("tab:blue", "E2"))]
    ax.legend(loc="upper left", fontsize="small")

    def draw(i):
        trail.set_data_3d(*centre[: i + 1].T)
        for line, e in zip(axes, (e1, e2)):
            line.set_data_3d(*np.stack([centre[i], centre[i] + size * e[i]]).T)
        return (trail, *axes)

    return _animation(ax, draw, _times(traj, every), interval, blit=False)
