"""Two Lyapunov families of a stable Jacobi ellipsoid (issue 27): docs/jacobi_lyapunov_family.png.

The Jacobi figure a2/a1 = 0.6 (G = rho = 1) as a relative equilibrium of the incompressible
self-gravitating body; each of its two slowest normal modes (`RelativeEquilibrium.normal_modes()`)
starts a family of relative periodic orbits (`periodic_orbit.from_mode`, amplitude 1e-3, rattle6
at 100 steps per period), followed by `continuation.periodic_family`.

* Mode 0 (omega = 2.668): every orbit stable; the family ends where its orbits shrink onto another
  relative equilibrium with the same angular momentum and circulation (the continuation passes
  it and would retrace the family: `end` says "turned back"). That equilibrium is found here by
  a second route: scipy's least squares on the co-moving field f(z) - xi_Z(z) = 0 (the flow by
  Richardson-extrapolated chords of rattle6 steps), started from the family's last orbit. It is
  a Riemann ellipsoid of type I: its principal axes tilted against the rotation axis.
* Mode 1 (omega = 3.672): stable up to a period doubling, located by the continuation.

Left: the period against the energy (stable solid, unstable dashed); right: the arguments of
the normal multipliers along both families.

    python benches/python/jacobi_lyapunov_family.py [--figure docs/jacobi_lyapunov_family.png]
"""

import sys
import time

import numpy as np
from scipy.optimize import least_squares

import lieflow as lf


def family(jacobi, k, **kwargs):
    mode = jacobi.normal_modes()[k]
    t0 = time.perf_counter()
    start = lf.periodic_orbit.from_mode(jacobi, k, 1e-3, method="rattle6", dt=mode.period / 100)
    branch = lf.continuation.periodic_family(jacobi.body, start, **kwargs)
    seconds = time.perf_counter() - t0
    worst = max(np.abs(np.abs(o.normal_multipliers) - 1).max()
                for o in branch.points if o.stable)
    print(f"mode {k} (omega = {mode.frequency:.6f}): {branch} in {seconds:.0f} s "
          f"({seconds / len(branch):.2f} s per orbit)")
    print(f"  stable orbits: | |mu| - 1 | <= {worst:.1e}; energy {branch.energies[0]:.6f} .. "
          f"{branch.energies[-1]:.6f}, period {branch.periods[0]:.6f} .. {branch.periods[-1]:.6f}")
    for sp in branch.special_points:
        mu = sp.orbit.normal_multipliers
        print(f"  {sp}: T = {sp.orbit.period:.6f}, normal multipliers {np.round(mu, 5)}")
    return branch


def axes(orbit):
    """The semi-axes (singular values of X) over one period: (min, max) per axis."""
    states = np.asarray(orbit.trajectory().states)
    s = np.linalg.svd(states[:, :9].reshape(-1, 3, 3), compute_uv=False)
    return s.min(0), s.max(0)


def relative_equilibrium(body, z0):
    """z with f(z) = xi_Z(z), xi = (c1 e12, c2 e12) acting as (e^xi X e^-eta, ...), at the
    momentum, circulation and volume of z0: scipy's least squares (Levenberg-Marquardt)."""
    e12 = np.zeros((3, 3))
    e12[0, 1], e12[1, 0] = -1.0, 1.0
    split = lambda z: (z[:9].reshape(3, 3), z[9:].reshape(3, 3))  # noqa: E731
    x0, p0 = split(z0)
    levels = (p0 @ x0.T - x0 @ p0.T, x0.T @ p0 - p0.T @ x0)
    volume = np.linalg.det(x0)

    def cofactor(x):
        return np.linalg.det(x) * np.linalg.inv(x).T

    def flow(z):
        x, p = split(z)
        c = cofactor(x)
        z = np.concatenate([x.ravel(), (p - np.sum(c * p) / np.sum(c * c) * c).ravel()])
        chord = lambda h: (np.asarray(lf.integrate(body, z, h, 1, method="rattle6").states)[-1]  # noqa: E731
                           - z) / h
        return 2.0 * chord(5e-4) - chord(1e-3)

    def residual(u):
        z, (c1, c2) = u[:18], u[18:]
        x, p = split(z)
        generated = np.concatenate([(c1 * e12 @ x - c2 * x @ e12).ravel(),
                                    (c1 * e12 @ p - c2 * p @ e12).ravel()])
        return np.concatenate([flow(z) - generated,
                               (p @ x.T - x @ p.T - levels[0]).ravel(),
                               (x.T @ p - p.T @ x - levels[1]).ravel(),
                               [np.linalg.det(x) - volume, np.sum(cofactor(x) * p)]])

    x, p = split(z0)
    g = np.column_stack([np.concatenate([(e12 @ x).ravel(), (e12 @ p).ravel()]),
                         np.concatenate([(-x @ e12).ravel(), (-p @ e12).ravel()])])
    c0 = np.linalg.lstsq(g, flow(z0), rcond=None)[0]
    sol = least_squares(residual, np.concatenate([z0, c0]), method="lm", x_scale=1e-2,
                        xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return sol.x[:18], sol.x[18:], float(np.abs(sol.fun).max())


def main():
    jacobi = lf.ellipsoids.jacobi(0.6)
    print("normal modes:", ", ".join(f"{m.frequency:.6f}" for m in jacobi.normal_modes()))
    first = family(jacobi, 0, max_points=40)
    last = first.points[-1]
    lo, hi = axes(last)
    print(f"  last orbit: semi-axes oscillate by {np.max((hi - lo) / hi):.1%} "
          f"(mid-family: {np.max(np.subtract(*axes(first.points[len(first) // 2])[::-1]) / hi):.1%})")
    t0 = time.perf_counter()
    z, c, res = relative_equilibrium(jacobi.body, last.state0)
    x = z[:9].reshape(3, 3)
    u, a, vt = np.linalg.svd(x)
    tilt = [np.degrees(np.arccos(min(1.0, abs(m[2, 2])))) for m in (u, vt.T)]
    print(f"  relative equilibrium at its end ({time.perf_counter() - t0:.0f} s): residual "
          f"{res:.1e} (the chords' error), E = {jacobi.body.energy(z):.7f} "
          f"(last orbit {last.energy:.7f}), semi-axes {np.round(a, 5)}, angular velocities "
          f"{np.round(c, 4)} about e3; the a1-a3 principal plane holds e3 and is turned by "
          f"{tilt[0]:.1f} deg (left) and {tilt[1]:.1f} deg (right): a Riemann ellipsoid of type I")
    second = family(jacobi, 1, max_points=14)
    if "--figure" in sys.argv:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
        for branch, color, name in ((first, "C0", "mode 0"), (second, "C1", "mode 1")):
            branch.plot(left, x="energy", y="period", color=color)
            left.plot([], [], color=color, label=name)
            for o in branch.points:
                args = np.angle(o.normal_multipliers)
                up = args[args >= 0]
                right.plot(np.full(up.shape, o.energy), up, "." if o.stable else "x",
                           color=color, ms=4)
        left.plot([jacobi.body.energy(z)], [last.period], "s", color="C0")
        left.annotate("type I Riemann\nellipsoid", (jacobi.body.energy(z), last.period),
                      textcoords="offset points", xytext=(-80, -5), fontsize=8)
        left.legend(loc="upper right")
        left.set_title(r"Lyapunov families of the Jacobi ellipsoid $a_2/a_1 = 0.6$")
        right.set_xlabel("energy")
        right.set_ylabel(r"arg $\mu$ of the normal multipliers (upper half)")
        right.set_title(r"Floquet multipliers (x: unstable orbit)")
        fig.tight_layout()
        path = sys.argv[sys.argv.index("--figure") + 1]
        fig.savefig(path, dpi=110)
        print("wrote", path)


if __name__ == "__main__":
    main()
