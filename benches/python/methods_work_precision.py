"""Work–precision of the methods of the mechanics core against scipy's DOP853 (what a user would
otherwise pick), on their test problems:

* the canonical pendulum (H = p^2/2 - 9.81 cos q, released at rest from q = 2, T = 20), exact
  solution by Jacobi elliptic functions: `midpoint`, `gauss4`, `gauss6`, `verlet` vs DOP853 on
  (q, p);
* the rolling disk with a torsional spring and a tilt (T = 20): `nonholonomic` vs DOP853 on the
  reduced equations (J phi'' = -k sin phi, (I + m R^2) theta'' = -m g R cos phi, x' = R cos phi
  theta', y' = R sin phi theta'), reference DOP853 at rtol 1e-13.

Prints, per method, the error at T and the best-of-3 time of one call (Python included), and the
time ratio DOP853 / lieflow at equal error (log-log interpolation).

    python benches/python/methods_work_precision.py
"""

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time


def table(name, runs):
    print(f"\n{name}")
    print(f"{'method':>12} {'steps/rtol':>11} {'error':>10} {'time':>10}")
    for method, rows in runs.items():
        for knob, err, sec in rows:
            print(f"{method:>12} {knob:>11.3g} {err:10.2e} {sec * 1e3:8.3f} ms")


def ratio_at(rows_a, rows_b, err):
    """Time of a / time of b at the error `err` (log-log interpolation), or None."""
    def time_at(rows):
        e = np.log([r[1] for r in rows])
        t = np.log([r[2] for r in rows])
        order = np.argsort(e)
        e, t = e[order], t[order]
        if not e[0] <= np.log(err) <= e[-1]:
            return None
        return np.exp(np.interp(np.log(err), e, t))
    a, b = time_at(rows_a), time_at(rows_b)
    return None if a is None or b is None else a / b


def pendulum():
    p = lf.Pendulum(1.0, 1.0, 9.81)
    t_end, z0 = 20.0, [2.0, 0.0]
    exact = p.exact_solution(2.0, t_end)
    runs = {}
    for method, steps in [("midpoint", [2000, 8000, 32000, 128000]),
                          ("gauss4", [250, 500, 1000, 2000, 4000]),
                          ("gauss6", [100, 200, 400, 800]),
                          ("verlet", [2000, 8000, 32000, 128000])]:
        rows = []
        for n in steps:
            f = lambda: lf.integrate(p, z0, dt=t_end / n, steps=n, method=method,
                                     save_every=n).final_state
            rows.append((n, np.abs(f() - exact).max(), best_time(f, 3)[0]))
        runs[method] = rows
    rhs = lambda t, y: [y[1], -9.81 * np.sin(y[0])]
    rows = []
    for rtol in [1e-6, 1e-8, 1e-10, 1e-12]:
        f = lambda: solve_ivp(rhs, (0, t_end), z0, method="DOP853", rtol=rtol,
                              atol=rtol * 1e-2).y[:, -1]
        rows.append((rtol, np.abs(f() - exact).max(), best_time(f, 3)[0]))
    runs["DOP853"] = rows
    table("pendulum, T = 20, amplitude 2 (error in (q, p) against the elliptic solution)", runs)
    for err in [1e-6, 1e-8, 1e-10]:
        for m in ["gauss4", "gauss6", "verlet"]:
            r = ratio_at(runs["DOP853"], runs[m], err)
            if r is not None:
                print(f"  at error {err:g}: DOP853 / {m} = {r:.1f}x")


def rolling_disk():
    m, radius, inertia, turn, k, g = 1.0, 0.5, 0.125, 0.0625, 0.4, 0.1
    disk = lf.RollingDisk(m, radius, inertia, turn, spring=k, tilt=g)
    t_end = 20.0
    q0, thd, phd = [0.0, 0.0, 0.0, 0.7], 2.0, 0.5
    z0 = disk.state(q0, thd, phd)

    def rhs(t, y):
        x, yy, th, ph, w, v = y
        return [radius * np.cos(ph) * w, radius * np.sin(ph) * w, w, v,
                -m * g * radius * np.cos(ph) / (inertia + m * radius**2), -k * np.sin(ph) / turn]

    y0 = [*q0, thd, phd]
    ref = solve_ivp(rhs, (0, t_end), y0, method="DOP853", rtol=1e-13, atol=1e-15).y[:4, -1]
    runs = {}
    rows = []
    for n in [1000, 4000, 16000, 64000]:
        f = lambda: lf.integrate(disk, z0, dt=t_end / n, steps=n, method="nonholonomic",
                                 save_every=n).final_state[:4]
        rows.append((n, np.abs(f() - ref).max(), best_time(f, 3)[0]))
    runs["nonholonomic"] = rows
    rows = []
    for rtol in [1e-4, 1e-6, 1e-8, 1e-10]:
        f = lambda: solve_ivp(rhs, (0, t_end), y0, method="DOP853", rtol=rtol,
                              atol=rtol * 1e-2).y[:4, -1]
        rows.append((rtol, np.abs(f() - ref).max(), best_time(f, 3)[0]))
    runs["DOP853"] = rows
    table("rolling disk with spring and tilt, T = 20 (error in q)", runs)
    for err in [1e-4, 1e-6, 1e-8]:
        r = ratio_at(runs["DOP853"], runs["nonholonomic"], err)
        if r is not None:
            print(f"  at error {err:g}: DOP853 / nonholonomic = {r:.2f}x")


if __name__ == "__main__":
    pendulum()
    rolling_disk()
