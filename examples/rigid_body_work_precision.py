"""
Work–precision: rigid-body methods against scipy
================================================

How much wall time does each method need for a given accuracy? The free rigid body
(I = diag(1, 2, 3), M₀ = (1, 0.5, −0.3)) is integrated to T = 20 by lieflow's methods at several
step sizes and by scipy's ``solve_ivp`` (RK45 and DOP853, adaptive, with a numpy right-hand
side) at several tolerances; the error is the distance of M(T) from the exact Jacobi-elliptic
solution ``RigidBody.exact_solution``. Times are the best of a few repeats of the public calls,
so lieflow's include its Python driver (a few µs per call).

This is a short version of ``benches/python/rigid_body_work_precision.py`` (T = 100, more
points, see :doc:`/benchmarks`); on a loaded 2-core machine the timings here are rough.

Run it with ``python examples/rigid_body_work_precision.py``.
"""

import time

import matplotlib.pyplot as plt
import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf

inertia = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])
T = 20.0
body = lf.RigidBody(inertia=inertia)
exact = body.exact_solution(M0, T)  # M(T), (3,)


def best_time(fn, repeats=3):
    """The best wall time of ``repeats`` calls of ``fn`` and its last result."""
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def euler(t, m):
    """Euler's equations dM/dt = M x Omega, Omega = I^-1 M, for scipy."""
    return np.cross(m, m / inertia)


points: dict[str, list[tuple[float, float]]] = {}  # method -> (seconds, error) pairs
for method in ("splitting", "splitting4", "splitting6", "processed8", "rkmk4", "rk4"):
    for steps in (50, 100, 200, 400, 800, 1600, 3200):
        sec, tr = best_time(lambda: lf.integrate(body, M0, dt=T / steps, steps=steps,
                                                 method=method, save_every=steps))
        points.setdefault(method, []).append((sec, np.abs(tr.states[-1] - exact).max()))
for method in ("RK45", "DOP853"):
    for tol in (1e-4, 1e-6, 1e-8, 1e-10):
        sec, sol = best_time(lambda: solve_ivp(euler, (0, T), M0, method=method, rtol=tol,
                                               atol=tol * 1e-2))
        points[f"scipy {method}"] = points.get(f"scipy {method}", []) + [
            (sec, np.abs(sol.y[:, -1] - exact).max())]

print(f"{'method':14s} {'fastest run with error < 1e-6':>32s}")
for method, pts in points.items():
    ok = [s for s, e in pts if e < 1e-6]
    print(f"{method:14s} {(f'{min(ok) * 1e3:.3f} ms' if ok else 'not reached'):>32s}")

# %%
# Error against wall time (lower left is better). The native explicit methods (the splittings
# and ``rk4``) reach a given accuracy about a hundred times faster than DOP853 here, and at such
# short runs much of their time is the fixed cost of one ``lf.integrate`` call. ``splitting`` is
# second order (its error falls four times per halving of the step), ``splitting4``, ``rkmk4``
# and ``rk4`` fourth order, ``splitting6`` sixth order until it meets round-off. ``processed8``
# runs an order-4 kernel conjugated by a processor (effective order 8): the best of the
# splittings here (see :doc:`/guide/methods`).

fig, ax = plt.subplots(figsize=(7.5, 4.8))
for method, pts in points.items():
    sec, err = np.array(pts).T
    ax.loglog(sec * 1e3, err, "o-" if method.startswith("scipy") else ".-", label=method, ms=4)
ax.set(xlabel="wall time (ms)", ylabel="error in M(T)",
       title=f"free rigid body to T = {T:g}: error against wall time")
ax.grid(True, which="major", alpha=0.3)
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()
