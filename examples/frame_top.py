"""The tangent top in three dimensions
=====================================

A rigid body whose centre moves on the 3-sphere and on hyperbolic 3-space, its axes an
orthonormal frame tangent there (002 §V, ``lf.FrameTop``). The centre's path, drawn in the
stereographic and the Poincaré-ball projections, is a helix of the isometry group that does not
depend on the body's inertia: two bodies with the same initial momenta but different inertia
tensors trace the same path while their frames turn differently. The integrals (energy, the
translational energy T and H − T, the Casimirs, the six Killing momenta) stay at round-off with
the exact flow.

Run it with (``--figure`` alone draws the figure, a path saves it)::

    python examples/frame_top.py [--figure [docs/frame_top.png]]
"""

import sys

import numpy as np

import lieflow as lf


def run(space, x, xdot, inertia, t_end, steps):
    """A top of mass 1 with angular velocity ω chosen so that Π = 𝕀ω = (0.9, −0.4, 1.3)."""
    top = lf.FrameTop(space, 1.0, inertia)
    omega = np.linalg.solve(top.inertia, [0.9, -0.4, 1.3])
    z0 = top.state(x, np.eye(3), xdot, omega)
    return top, lf.integrate(top, z0, dt=t_end / steps, steps=steps, save_every=steps // 400)


def projection(space, x):
    """Stereographic (sphere) or Poincaré-ball (hyperboloid) coordinates of points x (..., 4)."""
    r = space.radius
    return r * x[..., 1:] / (r + x[..., :1])


def main():
    sphere, hyper = lf.spaces.Sphere(3, radius=1.0), lf.spaces.Hyperbolic(3, radius=1.0)
    cases = {
        "S³": (sphere, np.array([1.0, 0, 0, 0]), np.array([0, 0.8, 0, 0.3]), 30.0),
        "H³": (hyper, np.array([1.0, 0, 0, 0]), np.array([0, 0.5, 0.1, 0]), 8.0),
    }
    inertias = ([1.0, 2.0, 3.0], [[2.5, 0.4, 0.0], [0.4, 1.2, 0.3], [0.0, 0.3, 1.9]])
    results = {}
    for name, (space, x, v, t_end) in cases.items():
        runs = [run(space, x, v, i, t_end, 4000) for i in inertias]
        (top, tr), (top2, tr2) = runs
        path, path2 = top.position(tr.states), top2.position(tr2.states)
        inv = tr.invariants()
        drift = np.abs(inv - inv[0]).max() / np.abs(inv).max()
        print(f"{name}: relative drift of the energy {np.ptp(tr.energy()) / tr.energy()[0]:.1e}, "
              f"of the Casimirs, T and Killing momenta {drift:.1e}; the two bodies' centres "
              f"differ by {np.abs(path - path2).max():.1e}, their frames by "
              f"{np.abs(top.frame(tr.states) - top2.frame(tr2.states)).max():.2f}")
        results[name] = (space, tr, path, inv)
    if "--figure" not in sys.argv:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    path_out = (sys.argv[sys.argv.index("--figure") + 1:] or [None])[0]
    fig = plt.figure(figsize=(13, 4.2))
    for k, (name, (space, tr, path, inv)) in enumerate(results.items()):
        ax = fig.add_subplot(1, 3, k + 1, projection="3d")
        p = projection(space, path)
        p[np.linalg.norm(p, axis=1) > 3] = np.nan   # near the projection's pole: not drawn
        ax.plot(*p.T, lw=1)
        ax.set_title(f"centre on {name} ({'stereographic' if k == 0 else 'Poincaré ball'})")
    ax = fig.add_subplot(1, 3, 3)
    for name, (space, tr, path, inv) in results.items():
        ax.semilogy(tr.t[1:], np.abs(tr.energy() - tr.energy()[0])[1:] + 1e-17, label=f"{name}: |ΔH|")
        ax.semilogy(tr.t[1:], np.abs(inv - inv[0]).max(axis=1)[1:] + 1e-17, "--",
                    label=f"{name}: max |Δ invariant|")
    ax.set(xlabel="t", title="integrals along the exact flow")
    ax.legend(fontsize=8)
    fig.tight_layout()
    if path_out:
        fig.savefig(path_out, dpi=110)
        print("figure:", path_out)


if __name__ == "__main__":
    main()
