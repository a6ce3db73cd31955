"""Work–precision of the free rigid body: lieflow's integrators against scipy's solve_ivp.

Problem (issue 4): I = diag(1, 2, 3), M0 = (1, 0.5, -0.3), T = 100. The error is the max-norm of
M(T) minus the exact solution (lieflow's Jacobi-elliptic solution, cross-checked here against a
DOP853 run at rtol = atol = 1e-13). Wall time is the best of several repeats (at least 3, more
for fast runs, up to a budget of ~0.3 s per point), measured through the public Python API, so
lieflow's times include the per-call overhead of `lf.integrate` (a few microseconds).

    python benches/python/rigid_body_work_precision.py [--plot docs/rigid_body_work_precision.png]
"""

import argparse

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time, environment

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])
T = 100.0


def euler(t, m):
    om = m / I
    return np.cross(m, om)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plot", default=None, help="save a work-precision figure here")
    args = parser.parse_args()

    print(environment())
    body = lf.RigidBody(inertia=I)
    exact = np.asarray(body.exact_solution(M0, [T]))[-1]
    ref = solve_ivp(euler, (0, T), M0, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    print(f"exact vs DOP853(1e-13): {np.max(np.abs(exact - ref)):.2e}")

    rows = []
    for method in ["RK45", "DOP853"]:
        for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]:
            sec, sol = best_time(
                lambda: solve_ivp(euler, (0, T), M0, method=method, rtol=tol, atol=tol * 1e-2),
                repeats=3,
                budget=0.3,
            )
            rows.append((f"scipy {method}", f"rtol={tol:.0e}", sec, np.max(np.abs(sol.y[:, -1] - exact))))
    for method in lf.RigidBody.methods():
        for steps in [250, 500, 1000, 2000, 4000, 8000, 16000, 32000]:
            dt = T / steps
            sec, tr = best_time(
                lambda: lf.integrate(body, M0, dt=dt, steps=steps, method=method, save_every=steps),
                budget=0.3,
            )
            err = np.max(np.abs(np.asarray(tr.states)[-1] - exact))
            rows.append((f"lieflow {method}", f"steps={steps}", sec, err))

    print(f"{'method':24s} {'setting':14s} {'time [ms]':>10s} {'error':>10s}")
    for name, setting, sec, err in rows:
        print(f"{name:24s} {setting:14s} {sec * 1e3:10.3f} {err:10.2e}")

    def time_to(name, target=1e-8):
        """Interpolated (log-log) wall time at which `name` reaches `target` error."""
        pts = sorted((e, s) for n, _, s, e in rows if n == name and e > 0)
        for (e1, s1), (e2, s2) in zip(pts, pts[1:]):
            if e1 <= target <= e2:
                w = (np.log(target) - np.log(e1)) / (np.log(e2) - np.log(e1))
                return float(np.exp(np.log(s1) + w * (np.log(s2) - np.log(s1))))
        return None

    base = time_to("scipy DOP853")
    print("\nwall time to reach error 1e-8:")
    for name in dict.fromkeys(n for n, *_ in rows):
        t = time_to(name)
        if t is not None:
            ratio = f"  ({base / t:.0f}x faster than DOP853)" if base and name.startswith("lieflow") else ""
            print(f"  {name:24s} {t * 1e3:9.3f} ms{ratio}")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 5))
        for name in dict.fromkeys(n for n, *_ in rows):
            pts = [(s, e) for n, _, s, e in rows if n == name]
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=name)
        ax.axhline(1e-8, color="gray", lw=0.8, ls="--")
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("max error of M(T), T = 100")
        ax.set_title("Free rigid body, I = diag(1,2,3): work-precision")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"saved {args.plot}")


if __name__ == "__main__":
    main()
