"""Work–precision of the relativistic top in a static gravitational field (002 (117),
`lf.StaticFieldTop`): lieflow's methods against scipy's DOP853.

Problem: m = 1, tr I = 0.02, a point mass phi = -gm/r with gm = 0.15, an eccentric orbit from
x = (1, 0), xdot = (0, 0.35), theta = 0, thetadot = 2; T = 20 (about one orbit). Canonical state
z = (x, y, theta, p_x, p_y, p_theta).

The rival's right-hand side is what a user without lieflow's kernels would write from the
Lagrangian alone: qdot from lieflow's Legendre inversion (`top.velocities`, native Newton) and
pdot = dL/dq at fixed qdot by central differences of `top.lagrangian` (h = 1e-6: the field is
good to about 1e-10, which bounds the rival's accuracy). Error = max-norm of z(T) against gauss6
at T/8000 (checked against T/4000). Energy error = max |H - H0| over the saved samples.

    python benches/python/static_field_top_work_precision.py
"""

import time

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf

T = 20.0


def best(f, repeat=3):
    out = None
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return min(times), out


def main():
    import os
    print("load average", os.getloadavg()[0])
    top = lf.StaticFieldTop(1.0, 0.02, gm=0.15)
    z0 = np.asarray(top.state([1.0, 0.0], 0.0, [0.0, 0.35], 2.0))
    ref = lf.integrate(top, z0, dt=T / 8000, steps=8000, save_every=8000, method="gauss6")
    half = lf.integrate(top, z0, dt=T / 4000, steps=4000, save_every=4000, method="gauss6")
    zr = ref.final_state
    print(f"reference gauss6 T/8000 vs T/4000: {np.abs(half.final_state - zr).max():.1e}")
    e0 = float(top.energy(z0))
    print("| method | steps / rtol | error at T | max \\|H − H0\\| | time |")
    print("|---|---|---|---|---|")
    rows = {}
    for m, counts in (("midpoint", (500, 2000, 8000)), ("gauss4", (100, 200, 400, 800)),
                      ("gauss6", (50, 100, 200, 400)), ("rk4", (500, 2000, 8000))):
        for n in counts:
            sec, tr = best(lambda: lf.integrate(top, z0, dt=T / n, steps=n, save_every=max(1, n // 100),
                                                method=m))
            err = np.abs(tr.final_state - zr).max()
            de = np.abs(tr.energy() - e0).max()
            rows.setdefault(m, []).append((err, sec))
            print(f"| `{m}` | {n} | {err:.1e} | {de:.1e} | {sec * 1e3:.2f} ms |")

    def rhs(t, z):
        qd = top.velocities(z)
        q = z[:3]
        g = np.empty(3)
        h = 1e-6
        for i in range(3):
            e = np.zeros(3)
            e[i] = h
            lp = top.lagrangian((q + e)[:2], (q + e)[2], qd[:2], qd[2])
            lm = top.lagrangian((q - e)[:2], (q - e)[2], qd[:2], qd[2])
            g[i] = (lp - lm) / (2 * h)
        return np.concatenate([qd, g])

    # The rival's field against lieflow's: one rk4 step each.
    dt = 0.01
    k1 = rhs(0, z0); k2 = rhs(0, z0 + dt / 2 * k1); k3 = rhs(0, z0 + dt / 2 * k2)
    k4 = rhs(0, z0 + dt * k3)
    one = z0 + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    lf_one = lf.integrate(top, z0, dt=dt, steps=1, method="rk4").final_state
    print(f"\nrival field check: one rk4 step vs lieflow's rk4: {np.abs(one - lf_one).max():.1e}\n")
    for rtol in (1e-6, 1e-8, 1e-10):
        sec, sol = best(lambda: solve_ivp(rhs, (0, T), z0, "DOP853", rtol=rtol, atol=rtol * 1e-3),
                        repeat=1)
        err = np.abs(sol.y[:, -1] - zr).max()
        de = np.abs(top.energy(sol.y.T) - e0).max()
        rows.setdefault("DOP853", []).append((err, sec))
        print(f"| DOP853 | rtol {rtol:.0e} ({sol.nfev} RHS) | {err:.1e} | {de:.1e} | {sec * 1e3:.1f} ms |")

    def time_at(m, target):
        pts = sorted(rows[m])
        for (e1, t1), (e2, t2) in zip(pts, pts[1:]):
            if e1 <= target <= e2:
                w = (np.log(target) - np.log(e1)) / (np.log(e2) - np.log(e1))
                return float(np.exp(np.log(t1) + w * (np.log(t2) - np.log(t1))))
        return None

    print("\nTime to reach the error, (time of DOP853) / (time of the method):\n")
    print("| error | DOP853 | " + " | ".join(f"`{m}`" for m in ("midpoint", "gauss4", "gauss6", "rk4")) + " |")
    print("|---|---|---|---|---|---|")
    for target in (1e-6, 1e-8):
        d = time_at("DOP853", target)
        cells = []
        for m in ("midpoint", "gauss4", "gauss6", "rk4"):
            t = time_at(m, target)
            cells.append("—" if t is None or d is None else f"{d / t:.0f}×")
        print(f"| {target:.0e} | {'—' if d is None else f'{d * 1e3:.0f} ms'} | " + " | ".join(cells) + " |")
    print("load average", os.getloadavg()[0])


if __name__ == "__main__":
    main()
