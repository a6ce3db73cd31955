"""Work–precision of lf.Forced (issue 15): a rigid body driven by a Python torque τ(t, M),
lieflow's kicked splittings against scipy's DOP853 and RK45 on the same equations (the torque
a Python function in both), error at T = 20 against DOP853 at rtol 1e-14.

    python benches/python/forced_work_precision.py
"""

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time, environment, print_ratios

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])
T = 20.0


def driven(t, z):
    return np.array([0.3, -0.2, 0.25 * np.cos(2 * t)])


def dragged(t, z):
    return np.array([0.3, -0.2, 0.25 * np.cos(2 * t)]) - 0.1 * z[:3]


def rhs(torque):
    def f(t, m):
        return np.cross(m, m / I) + torque(t, m)
    return f


def case(name, torque, depends):
    print(f"\n{name}")
    ref = solve_ivp(rhs(torque), (0, T), M0, method="DOP853", rtol=1e-14, atol=1e-14).y[:, -1]
    body = lf.Forced(lf.RigidBody(inertia=I), torque, depends_on_block=depends)
    points = {}
    for method in ("splitting", "splitting4", "splitting6"):
        pts = []
        for steps in (250, 500, 1000, 2000, 4000, 8000):
            secs, traj = best_time(lambda: lf.integrate(body, M0, dt=T / steps, steps=steps,
                                                        method=method, save_every=steps))
            pts.append((float(np.linalg.norm(traj.states[-1] - ref)), secs))
        points[f"lieflow {method}"] = pts
    for method in ("DOP853", "RK45"):
        pts = []
        for rtol in (1e-5, 1e-7, 1e-9, 1e-11, 1e-12):
            secs, sol = best_time(lambda: solve_ivp(rhs(torque), (0, T), M0, method=method,
                                                    rtol=rtol, atol=rtol * 1e-2))
            pts.append((float(np.linalg.norm(sol.y[:, -1] - ref)), secs))
        points[f"scipy {method}"] = pts
    for label, pts in points.items():
        print(f"  {label:20s} " + "  ".join(f"{e:.1e}/{s * 1e3:.1f}ms" for e, s in pts))
    print_ratios(points, (1e-6, 1e-9), width=20)


if __name__ == "__main__":
    print(environment())
    case("torque τ(t) (depends_on_block=False: one call per kick)", driven, False)
    case("torque τ(t) − 0.1 M (implicit kicks)", dragged, True)
