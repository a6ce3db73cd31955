"""Command line: ``python -m lieflow demo``."""

import argparse
import time

import numpy as np


def demo(figure=None, animation=None) -> None:
    """Simulate a spinning 3-D elastic pseudo-rigid body (SVK + gas) and report its invariants;
    on request save a figure (semi-axes and invariant drifts) and an animation (the ellipsoid
    X·ball, GIF or MP4)."""
    import lieflow as lf

    print(f"lieflow {lf.__version__}: an elastic pseudo-rigid body in 3-D (001 §3–§7)")
    pot = lf.potentials.SaintVenantKirchhoff(1.0, 2.0) + lf.potentials.Volumetric(0.5, 1.4)
    body = lf.PseudoRigidBody(3, potential=pot)
    print("H = tr(P^T P)/2 + U(X), U = Saint Venant-Kirchhoff (lam = 1, mu = 2) + polytropic "
          "gas (kappa = 0.5, gamma = 1.4):", repr(pot))
    print("units: nondimensional; length = the radius of the reference ball (X = I), the body's "
          "inertia (second moment of mass) = 1; the moduli lam, mu, kappa are energies in those "
          "units and set the time scale")
    # A stretched ellipsoid that spins (L != 0) and has internal vortical flow (Γ != 0).
    X0 = np.diag([1.3, 1.0, 0.8])
    W, V = lf.lie.hat([0.1, 0.3, 1.0]), lf.lie.hat([0.4, -0.2, 0.6])
    P0 = W @ X0 + X0 @ V.T + np.diag([0.1, -0.05, 0.0])
    dt, steps = 2e-3, 20_000
    t0 = time.perf_counter()
    traj = lf.integrate(body, (X0, P0), dt=dt, steps=steps, method="verlet4", save_every=20)
    elapsed = time.perf_counter() - t0
    t, E = traj.t, traj.energy()
    L, G = traj.angular_momentum(), traj.circulation()

    def drift(q):
        q0 = q[0]
        return np.max(np.abs(q - q0)) / max(np.max(np.abs(q0)), 1e-300)

    rows = [
        ("energy H", E[0], E[-1], drift(E)),
        ("|L| (angular momentum)", np.linalg.norm(L[0]), np.linalg.norm(L[-1]), drift(L)),
        ("|Γ| (circulation)", np.linalg.norm(G[0]), np.linalg.norm(G[-1]), drift(G)),
    ]
    print(f"method verlet4, dt = {dt}, {steps} steps to t = {t[-1]:g} in {elapsed:.2f} s")
    print(f"{'quantity':<26}{'start':>16}{'end':>16}{'max rel. drift':>16}")
    for name, a, b, d in rows:
        print(f"{name:<26}{a:>16.10f}{b:>16.10f}{d:>16.2e}")
    a = traj.singular_values()
    print("semi-axes a_i: start", np.round(a[0], 4), " min", np.round(a.min(0), 4),
          " max", np.round(a.max(0), 4))
    if figure is None and animation is None:
        return
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(the figure and the animation need matplotlib: pip install lieflow[plot])")
        return
    from . import plot

    if figure is not None:
        fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, layout="constrained")
        for i in range(3):
            top.plot(t, a[:, i], label=f"$a_{i + 1}$")
        top.set(ylabel="semi-axes", title=r"Elastic pseudo-rigid body: semi-axes $a_i(t)$")
        plot._legend_beside(top)
        plot.invariants(traj, ax=bottom)
        fig.savefig(figure, dpi=120)
        print(f"figure (semi-axes and invariant drifts) saved to {figure}")
    if animation is not None:
        plot.animate(traj, animation, every=20, interval=100)
        print(f"animation of the ellipsoid X·ball saved to {animation}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="lieflow", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    d = sub.add_parser("demo", help="run the main demo (a spinning elastic pseudo-rigid body)")
    d.add_argument("--figure", metavar="PATH", help="save a figure of the semi-axes and the "
                   "invariant drifts (.png, .pdf, ...)")
    d.add_argument("--animation", metavar="PATH", help="save an animation of the body (.gif, or "
                   ".mp4 with ffmpeg)")
    args = parser.parse_args(argv)
    if args.command == "demo":
        demo(args.figure, args.animation)
    return 0
