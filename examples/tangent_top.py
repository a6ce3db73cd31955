"""The tangent Euler top
=====================

The tangent Euler top on a sphere and on the hyperbolic plane (002 §II–III): the path of the
centre with the body frame drawn along it, the path of the equivalent charged particle
(002 §III.B, `TangentTop.magnetic_analogue`) overlaid, and the invariants against time (energy,
p_theta and the Killing momenta, kept by the symplectic Gauss–Legendre method).

Run it with (``--figure`` alone draws the figure, a path saves it)::

    python examples/tangent_top.py [--figure [docs/tangent_top.png]]
"""

import sys

import numpy as np

import lieflow as lf


def run(surface, x0, xdot0, thetadot0, t_end=20.0, dt=0.01):
    """The top's trajectory and that of its charged particle (charge p_theta)."""
    top = lf.TangentTop(surface, 1.0, 0.4)
    z0 = top.state(x0, 0.0, xdot0, thetadot0)
    n = int(round(t_end / dt))
    tr = lf.integrate(top, z0, dt=dt, steps=n, method="gauss6", save_every=10)
    particle = top.magnetic_analogue(z0[5])
    w0 = particle.state(x0, xdot0)
    pr = lf.integrate(particle, w0, dt=dt, steps=n, method="gauss6", save_every=10)
    return top, tr, pr


def main():
    sphere, ts, ps = run(lf.surfaces.Sphere(1.0), [1.2, 0.0], [0.15, 0.5], 2.0)
    hyper, th, ph_ = run(lf.surfaces.HyperbolicPlane(), [0.0, 1.0], [0.4, 0.2], 2.0)
    for name, tr, pr in [("sphere", ts, ps), ("hyperbolic plane", th, ph_)]:
        k = tr.killing_momenta()
        print(f"{name}: energy drift {np.ptp(tr.energy()):.2e}, p_theta drift "
              f"{np.ptp(tr.p_theta()):.2e}, Killing momenta drift {np.ptp(k, axis=0).max():.2e}, "
              f"charged particle off the centre by {np.abs(pr.x - tr.x).max():.1e}")
    if "--figure" not in sys.argv:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    path = (sys.argv[sys.argv.index("--figure") + 1:] or [None])[0]  # None: only draw
    fig = plt.figure(figsize=(14, 4.2))
    # Sphere: the centre in R^3 and the body axis E1 (every 20 samples), from ambient_frame;
    # the charged particle's path (dashed) lies on the centre's.
    ax = fig.add_subplot(1, 3, 1, projection="3d")
    frame = sphere.ambient_frame(ts.states)
    p, body = frame[:, 0], frame[:, 1]
    ax.plot(*p.T, lw=1, label="top's centre")
    for i in range(0, len(p), 20):
        ax.quiver(*p[i], *(0.15 * body[i]), color="tab:red", lw=0.8)
    t_, f_ = ps.x[:, 0], ps.x[:, 1]
    q = np.stack([np.sin(t_) * np.cos(f_), np.sin(t_) * np.sin(f_), np.cos(t_)], axis=1)
    ax.plot(*q[::4].T, "k.", ms=1.5, label="charged particle")
    ax.legend(fontsize=8)
    ax.set_title("top on the unit sphere (centre and body axis)")
    # Hyperbolic plane: the centre in the half-plane, the body axis in the frame (y dx, y dy).
    ax = fig.add_subplot(1, 3, 2)
    x, y = th.x[:, 0], th.x[:, 1]
    ax.plot(x, y, lw=1, label="top's centre")
    ax.plot(ph_.x[::4, 0], ph_.x[::4, 1], "k.", ms=1.5, label="charged particle")
    ax.legend(fontsize=8)
    for i in range(0, len(x), 20):
        ax.arrow(x[i], y[i], 0.1 * y[i] * np.cos(th.theta[i]), 0.1 * y[i] * np.sin(th.theta[i]),
                 color="tab:red", width=0.002 * y[i])
    ax.set(xlabel="x", ylabel="y", title="top on the hyperbolic plane (Poincaré half-plane)")
    ax.set_aspect("equal")
    ax = fig.add_subplot(1, 3, 3)
    for name, tr in [("sphere", ts), ("H²", th)]:
        ax.semilogy(tr.t[1:], np.abs(tr.energy() - tr.energy()[0])[1:] + 1e-17, label=f"{name}: |ΔH|")
        k = tr.killing_momenta()
        ax.semilogy(tr.t[1:], np.abs(k - k[0]).max(axis=1)[1:] + 1e-17, "--",
                    label=f"{name}: max |ΔJ|")
    ax.set(xlabel="t", title="invariants, gauss6, dt = 0.01")
    ax.legend(fontsize=8)
    fig.tight_layout()
    if path:  # the docs gallery draws the figure without saving it
        fig.savefig(path, dpi=110)
        print("figure:", path)


if __name__ == "__main__":
    main()
