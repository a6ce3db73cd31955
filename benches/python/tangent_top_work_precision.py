"""Work–precision of the tangent Euler top (seed 002, `lf.TangentTop`): lieflow's methods against
scipy's solve_ivp (DOP853, RK45) and, if numba is installed, a numba-jitted fixed-step RK4 loop
and DOP853 with a numba-jitted right-hand side.

Problems (T = 20, canonical state z = (x1, x2, theta, p1, p2, p_theta)):

* (a) the symmetric top on the unit sphere, m = 1, inertia 0.4,
  z0 = top.state([1.2, 0], 0, [0.15, 0.5], 2);
* (b) the same top on the hyperbolic plane (upper half plane), z0 = top.state([0, 1], 0,
  [0.4, 0.2], 2);
* (c) the embedded anisotropic top on the sphere of radius 1.4, m = 0.9, I = diag(0.5, 0.2)
  (002 (37): theta enters H, p_theta is not conserved), z0 = top.state([1.1, 0.3], 0.4,
  [0.5, -0.3], 0.8).

Right-hand side for the rivals, written here from the Hamiltonian (module docs of
crates/core/src/systems/tangent_top.rs): H = 1/2 pi^T G^-1 pi + p_theta^2/(2 tr I), pi = p_x -
p_theta alpha, G = m g (+ W^T S(theta) I S(theta)^T W on the embedded surface, W = diag(1, sin x1)
on the sphere), sphere g = R^2 diag(1, sin^2 x1), alpha = (0, cos x1); H^2 g = I/y^2,
alpha = (1/y, 0); no finite differences. It is plain scalar Python (`math`: ≈ 1.6 µs a call,
against ≈ 25 µs for the same with numpy 2-vectors, 2×2 arrays and np.linalg.solve) and is
checked against lieflow before timing: one rk4 step of it must equal lieflow's rk4 step to
round-off, and H against `top.energy`.

Error = max-norm of z(T) minus a reference (gauss6 at T/40000 steps, checked against T/20000).
Energy error = max |H - H0| over the run (every lieflow step, every accepted scipy step; from an
untimed second run). Wall time is the best of >= 3 repeats (more for fast runs, up to ~0.1 s per
point) through the public Python API (`lf.integrate(..., save_every=steps)`, so lieflow's times
include its per-call overhead); scipy `solve_ivp(f, (0, T), z0, method, rtol=tol, atol=tol/100)`.
numba times exclude compilation (one warm-up call first). Then, per problem, one long run to
T_LONG = 5000 with gauss6, rk4 and DOP853 at settings that reach ~1e-10 at T = 20: the energy
error over [0, t] for growing t (does it drift?) and the largest error of the Killing momenta.

    python benches/python/tangent_top_work_precision.py
"""

import math
import os
import time

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time, environment, print_ratios

try:
    import numba
except ImportError:
    numba = None

T = 20.0
T_LONG = 5000.0
BUDGET = 0.1
SPHERE, HYPERBOLIC = 0, 1


def field(x1, x2, th, p1, p2, pt, kind, radius, m, i11, i12, i22, emb):
    """Hamilton's equations of the tangent top: returns (dz0, ..., dz5)."""
    trace = i11 + i22
    dth11 = dth12 = dth22 = 0.0     # d/dtheta of G
    if kind == SPHERE:
        s, c = math.sin(x1), math.cos(x1)
        mr2 = m * radius * radius
        g11, g12, g22 = mr2, 0.0, mr2 * s * s
        d11, d12, d22 = 0.0, 0.0, 2.0 * mr2 * s * c      # d/dx1 of G (d/dx2 = 0)
        a1, a2 = 0.0, c
        da1, da2 = 0.0, -s                                # d/dx1 of alpha
        if emb:
            # Q = S I S^T, S = rotation by theta; G += W^T Q W, W = diag(1, sin x1).
            cs, sn = math.cos(th), math.sin(th)
            q11 = cs * cs * i11 - 2.0 * cs * sn * i12 + sn * sn * i22
            q12 = cs * sn * (i11 - i22) + (cs * cs - sn * sn) * i12
            q22 = sn * sn * i11 + 2.0 * cs * sn * i12 + cs * cs * i22
            g11 += q11
            g12 += s * q12
            g22 += s * s * q22
            d12 += c * q12
            d22 += 2.0 * s * c * q22
            dth11, dth12, dth22 = -2.0 * q12, s * (q11 - q22), 2.0 * s * s * q12
    else:   # the upper half plane, x2 = y > 0
        iy = 1.0 / x2
        g11 = g22 = m * iy * iy
        g12 = 0.0
        a1, a2 = iy, 0.0
    det = g11 * g22 - g12 * g12
    pi1, pi2 = p1 - pt * a1, p2 - pt * a2
    v1 = (g22 * pi1 - g12 * pi2) / det
    v2 = (g11 * pi2 - g12 * pi1) / det
    if kind == SPHERE:
        f1 = (0.5 * (d11 * v1 * v1 + 2.0 * d12 * v1 * v2 + d22 * v2 * v2)
              + pt * (da1 * v1 + da2 * v2))
        f2 = 0.0
    else:
        f1 = 0.0
        f2 = -m * iy * iy * iy * (v1 * v1 + v2 * v2) - pt * iy * iy * v1
    fth = 0.5 * (dth11 * v1 * v1 + 2.0 * dth12 * v1 * v2 + dth22 * v2 * v2)
    return v1, v2, pt / trace - (a1 * v1 + a2 * v2), f1, f2, fth


def hamiltonian(z, kind, radius, m, i11, i12, i22, emb):
    """H from the same formulas (used only to check them against lieflow)."""
    x1, x2, th, p1, p2, pt = z
    v1, v2, *_ = field(x1, x2, th, p1, p2, pt, kind, radius, m, i11, i12, i22, emb)
    a1, a2 = (0.0, math.cos(x1)) if kind == SPHERE else (1.0 / x2, 0.0)
    return 0.5 * ((p1 - pt * a1) * v1 + (p2 - pt * a2) * v2) + pt * pt / (2.0 * (i11 + i22))


if numba is not None:
    field_nb = numba.njit(cache=False)(field)

    @numba.njit(cache=False)
    def rk4_nb(z0, dt, steps, kind, radius, m, i11, i12, i22, emb):
        z = z0.copy()
        y = np.empty(6)
        k = np.empty((4, 6))
        for _ in range(steps):
            for s in range(4):
                if s == 0:
                    y[:] = z
                else:
                    h = dt if s == 3 else 0.5 * dt
                    for i in range(6):
                        y[i] = z[i] + h * k[s - 1, i]
                f = field_nb(y[0], y[1], y[2], y[3], y[4], y[5], kind, radius, m, i11, i12, i22,
                             emb)
                for i in range(6):
                    k[s, i] = f[i]
            for i in range(6):
                z[i] += dt / 6.0 * (k[0, i] + 2.0 * k[1, i] + 2.0 * k[2, i] + k[3, i])
        return z

def problems():
    S = lf.surfaces
    a = lf.TangentTop(S.Sphere(1.0), 1.0, 0.4)
    b = lf.TangentTop(S.HyperbolicPlane(), 1.0, 0.4)
    c = lf.TangentTop(S.Sphere(1.4), 0.9, np.diag([0.5, 0.2]), embedded=True)
    return [
        ("(a) unit sphere, m = 1, inertia 0.4", a, a.state([1.2, 0.0], 0.0, [0.15, 0.5], 2.0),
         (SPHERE, 1.0, 1.0, 0.2, 0.0, 0.2, False), (800, 8000)),
        ("(b) hyperbolic plane, m = 1, inertia 0.4", b, b.state([0.0, 1.0], 0.0, [0.4, 0.2], 2.0),
         (HYPERBOLIC, 1.0, 1.0, 0.2, 0.0, 0.2, False), (200, 4000)),
        ("(c) embedded sphere R = 1.4, m = 0.9, I = diag(0.5, 0.2)", c,
         c.state([1.1, 0.3], 0.4, [0.5, -0.3], 0.8), (SPHERE, 1.4, 0.9, 0.5, 0.0, 0.2, True),
         (800, 8000)),
    ]


STEPS = {"gauss6": [50, 100, 200, 400, 800, 1600],
         "gauss4": [100, 200, 400, 800, 1600, 3200, 6400],
         "rk4": [250, 500, 1000, 2000, 4000, 8000, 16000],
         "midpoint": [1000, 4000, 16000, 64000]}
RTOLS = {"DOP853": [1e-4, 1e-6, 1e-8, 1e-10, 1e-12],
         "RK45": [1e-4, 1e-6, 1e-8, 1e-10]}


def check_rhs(top, z0, par):
    """The numpy RHS against lieflow: one rk4 step of each, and H."""
    dt = 0.01
    f = lambda z: np.array(field(*z, *par))
    k1 = f(z0)
    k2 = f(z0 + 0.5 * dt * k1)
    k3 = f(z0 + 0.5 * dt * k2)
    k4 = f(z0 + dt * k3)
    mine = z0 + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    theirs = lf.integrate(top, z0, dt=dt, steps=1, method="rk4").final_state
    step_diff = np.abs(mine - theirs).max()
    h_diff = abs(hamiltonian(z0, *par) - top.energy(z0))
    print(f"  RHS check: |one rk4 step, numpy - lieflow| = {step_diff:.1e}, "
          f"|H numpy - lieflow| = {h_diff:.1e}")
    assert step_diff < 1e-13 and h_diff < 1e-13, (step_diff, h_diff)


def run(title, top, z0, par):
    print(f"\n{title}, T = {T:g}")
    z0 = np.asarray(z0, dtype=float)
    check_rhs(top, z0, par)
    h0 = top.energy(z0)
    n = 20000
    ref = lf.integrate(top, z0, dt=T / n, steps=n, method="gauss6", save_every=n).final_state
    ref2 = lf.integrate(top, z0, dt=T / (2 * n), steps=2 * n, method="gauss6",
                        save_every=2 * n).final_state
    print(f"  reference gauss6 {n} steps vs {2 * n} steps: {np.abs(ref - ref2).max():.1e}")
    ref = ref2

    rows = []   # (name, setting, seconds, error, energy error)
    for method, steps_list in STEPS.items():
        for steps in steps_list:
            dt = T / steps
            sec, tr = best_time(lambda: lf.integrate(top, z0, dt=dt, steps=steps, method=method,
                                                     save_every=steps), budget=BUDGET)
            err = np.abs(tr.final_state - ref).max()
            full = lf.integrate(top, z0, dt=dt, steps=steps, method=method, save_every=1)
            de = np.abs(full.energy() - h0).max()
            rows.append((f"lieflow {method}", f"steps={steps}", sec, err, de))

    rhs = lambda t, y: field(*y.tolist(), *par)
    for method, tols in RTOLS.items():
        for tol in tols:
            sec, sol = best_time(lambda: solve_ivp(rhs, (0, T), z0, method=method, rtol=tol,
                                                   atol=tol * 1e-2), budget=BUDGET)
            err = np.abs(sol.y[:, -1] - ref).max()
            de = np.abs(top.energy(sol.y.T) - h0).max()
            rows.append((f"scipy {method}", f"rtol={tol:.0e}", sec, err, de))

    if numba is not None:
        rk4_nb(z0, 0.01, 2, *par)   # compile
        for steps in STEPS["rk4"]:
            dt = T / steps
            sec, zt = best_time(lambda: rk4_nb(z0, dt, steps, *par), budget=BUDGET)
            rows.append(("numba rk4", f"steps={steps}", sec, np.abs(zt - ref).max(), float("nan")))
        rhs_nb = lambda t, y: field_nb(y[0], y[1], y[2], y[3], y[4], y[5], *par)
        rhs_nb(0.0, z0)             # compile
        for tol in RTOLS["DOP853"]:
            sec, sol = best_time(lambda: solve_ivp(rhs_nb, (0, T), z0, method="DOP853", rtol=tol,
                                                   atol=tol * 1e-2), budget=BUDGET)
            err = np.abs(sol.y[:, -1] - ref).max()
            de = np.abs(top.energy(sol.y.T) - h0).max()
            rows.append(("scipy DOP853, numba RHS", f"rtol={tol:.0e}", sec, err, de))

    print(f"  {'method':24s} {'setting':14s} {'time [ms]':>10s} {'error':>10s} {'max|H-H0|':>10s}")
    for name, setting, sec, err, de in rows:
        des = "-" if np.isnan(de) else f"{de:.2e}"
        print(f"  {name:24s} {setting:14s} {sec * 1e3:10.3f} {err:10.2e} {des:>10s}")

    points = {}
    for name, _, sec, err, _ in rows:
        points.setdefault(name, []).append((err, sec))
    print_ratios(points, [1e-6, 1e-8, 1e-10], width=24)
    return rows


def long_run(top, z0, par, gauss6_steps, rk4_steps):
    """Energy error max |H - H0| over [0, t] for t = T, T_LONG/10, T_LONG, and the largest error of
    the Killing momenta, at settings that reach ~1e-10 at T (lieflow states sampled every
    n/50000 steps, so the windows beyond T may miss the largest in-between values)."""
    z0 = np.asarray(z0, dtype=float)
    h0, j0 = top.energy(z0), np.asarray(top.killing_momenta(z0))
    k = int(T_LONG / T)
    print(f"  long run to T = {T_LONG:g} (settings with error ~1e-10 at T = {T:g}; one run each):")
    windows = [T, T_LONG / 10, T_LONG]
    print(f"  {'method':24s} {'setting':14s} {'time [ms]':>10s} "
          + " ".join(f"{'dH<=' + format(w, 'g'):>10s}" for w in windows) + f" {'max|J-J0|':>10s}")

    def report(name, setting, sec, t, states):
        de = np.abs(top.energy(states) - h0)
        dj = np.abs(np.asarray(top.killing_momenta(states)) - j0).max()
        print(f"  {name:24s} {setting:14s} {sec * 1e3:10.1f} "
              + " ".join(f"{de[t <= w].max():10.2e}" for w in windows) + f" {dj:10.2e}")

    for method, steps in [("gauss6", gauss6_steps), ("rk4", rk4_steps)]:
        n = steps * k
        every = max(1, n // 50000)
        sec, tr = best_time(lambda: lf.integrate(top, z0, dt=T_LONG / n, steps=n, method=method,
                                                 save_every=every), repeats=1)
        report(f"lieflow {method}", f"steps/T={steps}", sec, np.asarray(tr.t), tr.states)
    rhs = lambda t, y: field(*y.tolist(), *par)
    sec, sol = best_time(lambda: solve_ivp(rhs, (0, T_LONG), z0, method="DOP853", rtol=1e-10,
                                           atol=1e-12), repeats=1)
    report("scipy DOP853", "rtol=1e-10", sec, sol.t, sol.y.T)


def main():
    t0 = time.perf_counter()
    print(environment(numba=numba.__version__ if numba else "not installed"))
    for title, top, z0, par, long_steps in problems():
        run(title, top, z0, par)
        long_run(top, z0, par, *long_steps)
    print(f"\ntotal {time.perf_counter() - t0:.0f} s, load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
