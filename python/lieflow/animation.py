"""Animations of lieflow trajectories with matplotlib (``pip install lieflow[plot]``).

Each function returns a :class:`matplotlib.animation.FuncAnimation`; save it with
``anim.save("disks.mp4")`` or ``anim.save("disks.gif", writer="pillow")``, or show it in a
notebook with ``IPython.display.HTML(anim.to_jshtml())``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["rolling_disks"]


def rolling_disks(system, trajectory, *, ax=None, every=1, interval=40, trail=True):
    """Animate a :class:`lieflow.RollingDisks` trajectory (003 §1).

    Draws both disks as circles about their centres with a spoke from each centre to its centre
    of mass (which turns with the disk), the contact point, and optionally the trail of the
    centres of mass. Positions are in the centre-of-mass frame of the pair.

    Parameters
    ----------
    system : lieflow.RollingDisks
        The system the trajectory belongs to.
    trajectory : lieflow.Trajectory
        Its trajectory (any ``save_every``).
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure by default.
    every : int
        Draw every ``every``-th saved state.
    interval : float
        Milliseconds between frames.
    trail : bool
        Draw the paths of the centres of mass so far.

    Returns
    -------
    matplotlib.animation.FuncAnimation
    """
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation
    from matplotlib.patches import Circle

    if every < 1:
        raise ValueError(f"every must be >= 1, got {every}")
    states = np.asarray(trajectory.states)[::every]
    pos = system.positions(states)
    centres, masses, contact = pos["centres"], pos["masses"], pos["contact"]
    radii = [np.linalg.norm(contact[0] - centres[0, 0]), np.linalg.norm(contact[0] - centres[0, 1])]
    if ax is None:
        _, ax = plt.subplots(figsize=(5, 5))
    reach = np.abs(centres).max() + max(radii)
    ax.set(xlim=(-reach, reach), ylim=(-reach, reach), aspect="equal")
    disks = [ax.add_patch(Circle(centres[0, k], radii[k], fill=False, lw=1.5, color=c))
             for k, c in enumerate(("tab:blue", "tab:orange"))]
    spokes = [ax.plot([], [], color=c, lw=1.5)[0] for c in ("tab:blue", "tab:orange")]
    trails = [ax.plot([], [], color=c, lw=0.6, alpha=0.6)[0] for c in ("tab:blue", "tab:orange")]
    point, = ax.plot([], [], "ko", ms=4)

    def draw(i):
        for k in range(2):
            disks[k].center = centres[i, k]
            spokes[k].set_data(*np.stack([centres[i, k], masses[i, k]]).T)
            if trail:
                trails[k].set_data(masses[: i + 1, k, 0], masses[: i + 1, k, 1])
        point.set_data([contact[i, 0]], [contact[i, 1]])
        return (*disks, *spokes, *trails, point)

    return FuncAnimation(ax.figure, draw, frames=len(states), interval=interval, blit=True)
