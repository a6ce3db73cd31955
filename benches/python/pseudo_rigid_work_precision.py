"""Work–precision of the 3-D elastic pseudo-rigid body: lieflow's Verlet methods against scipy's
solve_ivp (DOP853).

Problem (issue 5): n = 3, Saint Venant–Kirchhoff potential (lam, mu) = (0.7, 1.3) (001 (3.22)),
X0 = diag(1.2, 1.0, 0.85) + small shear, P0 with both angular momentum and circulation, T = 20.
The error is the max-norm of (X, P)(T) minus a reference (DOP853 at rtol = atol = 1e-13,
cross-checked against verlet6 at dt = 2.5e-4). Wall time is the best of several repeats through
the public Python API (`lf.integrate`, one sample saved). The DOP853 right-hand side is vectorised
numpy (one call per stage), the usual way such a model is written in Python.

    python benches/python/pseudo_rigid_work_precision.py
"""

import os
import platform

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time

LAM, MU = 0.7, 1.3
T = 20.0
X0 = np.diag([1.2, 1.0, 0.85]) + np.array([[0, 0.05, 0], [0, 0, 0.03], [0.02, 0, 0]])
P0 = np.array([[0.0, 0.4, -0.1], [-0.2, 0.05, 0.3], [0.15, -0.25, 0.0]])
BODY = lf.PseudoRigidBody(3, potential=lf.potentials.SaintVenantKirchhoff(LAM, MU))
I3 = np.eye(3)


def rhs(t, y):
    X = y[:9].reshape(3, 3)
    P = y[9:]
    E = 0.5 * (X.T @ X - I3)
    S = LAM * np.trace(E) * I3 + 2 * MU * E
    return np.concatenate([P, -(X @ S).ravel()])


def lieflow_final(method, dt):
    steps = int(round(T / dt))
    traj = lf.integrate(BODY, (X0, P0), dt=dt, steps=steps, method=method, save_every=steps)
    return traj.states[-1]


def dop853_final(tol):
    y0 = np.concatenate([X0.ravel(), P0.ravel()])
    sol = solve_ivp(rhs, (0, T), y0, method="DOP853", rtol=tol, atol=tol)
    return sol.y[:, -1]


def main():
    ref = dop853_final(1e-13)
    check = lieflow_final("verlet6", 2.5e-4)
    print(f"# reference: DOP853 1e-13 vs verlet6 dt=2.5e-4 differ by {np.max(np.abs(ref - check)):.1e}")
    print(f"# {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, lieflow {lf.__version__}")
    rows = []
    for method, dts in [
        ("verlet", [4e-2, 2e-2, 1e-2, 5e-3, 2.5e-3]),
        ("verlet4", [8e-2, 4e-2, 2e-2, 1e-2, 5e-3]),
        ("verlet6", [1e-1, 5e-2, 2.5e-2, 1.25e-2]),
    ]:
        for dt in dts:
            t, z = best_time(lambda: lieflow_final(method, dt), budget=0.3, max_repeats=200)
            rows.append((method, f"dt={dt:g}", np.max(np.abs(z - ref)), t))
    for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]:
        t, z = best_time(lambda: dop853_final(tol), repeats=1, budget=1.0)
        rows.append(("DOP853", f"tol={tol:g}", np.max(np.abs(z - ref)), t))
    print(f"{'method':<9}{'setting':<14}{'error':>11}{'time [s]':>12}")
    for m, s, e, t in rows:
        print(f"{m:<9}{s:<14}{e:>11.2e}{t:>12.2e}")
    # Speed-up at equal accuracy: for each DOP853 point, the fastest lieflow run at least as
    # accurate.
    print("\n# speed-up of the fastest lieflow run at least as accurate as each DOP853 point")
    lf_rows = [r for r in rows if r[0] != "DOP853"]
    for m, s, e, t in rows:
        if m != "DOP853":
            continue
        ok = [r for r in lf_rows if r[2] <= e]
        if ok:
            best = min(ok, key=lambda r: r[3])
            print(f"DOP853 {s}: error {e:.1e}, {t:.2e} s; {best[0]} {best[1]}: error {best[2]:.1e}, "
                  f"{best[3]:.2e} s -> {t / best[3]:.0f}x faster")


if __name__ == "__main__":
    main()
