"""Work–precision of the tangent Euler top on a three-dimensional space form (002 §V,
`lf.FrameTop`): lieflow's methods (exact, splitting, splitting4, splitting6, rk4) against scipy's
DOP853 on the Lie–Poisson equations written out in this script.

Problems (mass m = 1.3, the non-diagonal inertia INERTIA below, R0 = so3_exp(0.3, -0.2, 0.5),
omega0 = (0.8, -0.6, 1.1)):

* (a) the 3-sphere of radius r = 1.7, x0 = r (0.6, 0.48, 0, 0.64)/|.|, xdot0 = (0.3, -0.5, 0.7, 0.1)
  projected on the tangent space, T = 20: the main case, every method at 4-6 step counts;
* (b) the hyperbolic 3-space of radius 1.7 (hyperboloid x0^2 - |x|^2 = r^2), x = (0.4, -0.3, 0.2)
  lifted, xdot = (0.3, -0.5, 0.7) lifted tangent, T = 5;
* (c) Euclidean R^3, x0 = (0.2, -0.1, 0.4), xdot0 = (0.3, -0.5, 0.7), T = 20.

The flat state is z = (g 4x4 row-major, Pi, P). scipy integrates, with Omega = I^-1 Pi, v = P/m,
kappa the curvature: dPi/dt = Pi x Omega, dP/dt = P x Omega + (kappa/m) Pi x P, dg/dt = g xi,
xi = [[0, -sigma v^T/l], [v/l, hat(Omega)]] (sigma = +1 sphere, -1 hyperbolic, 0 Euclidean;
l = r, or 1 on R^3). The right-hand side is scalar Python for the 3-vectors plus one numpy 4x4
product (~7 us a call; the same with np.cross and slicing costs ~80 us). Before timing the script
checks it against lieflow: one rk4 step (dt = 0.01) of it against lieflow's rk4 step, and DOP853
at rtol 1e-13 to t = 1 against lf.integrate(top, z0, method="rk4", dt=1e-4).

Error = max-norm of z(T) minus the reference, the `exact` method in one step of size T
(cross-checked against `exact` in 1000 steps, DOP853 at rtol 1e-13 and splitting6 at T/3200);
on (b) and (c) divided by the max-norm of the reference (the frame g grows there). Drifts:
max over the run of |C - C0| for the Casimirs Pi.P, |P|^2 + kappa |Pi|^2 and T (the first three
of traj.invariants()), of |J - J0| for the six Killing momenta (the rest), and of |H - H0|, over
every lieflow step and every accepted DOP853 step (an untimed second run). Wall time is the best
of >= 3 calls (more for fast ones, up to ~0.15 s per point) through lf.integrate(...,
save_every=steps) (so it includes lieflow's per-call overhead, ~8 us); DOP853 is
solve_ivp(rhs, (0, T), z0, method="DOP853", rtol=tol, atol=tol * 1e-3). Ratios are DOP853's
time over the method's, both interpolated log-log to the same error in this run. Then one run
each to T = 2000 on the sphere (settings with error ~1e-9 at T = 20) for the drift of the
energy, the Casimirs and the Killing momenta. Runs in ~20 s.

    python benches/python/frame_top_work_precision.py
"""

import os
import subprocess
import time

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time, environment, time_to

MASS = 1.3
RADIUS = 1.7
INERTIA = np.array([[0.9, 0.12, -0.05], [0.12, 1.3, 0.08], [-0.05, 0.08, 1.7]])
R0 = lf.lie.so3_exp([0.3, -0.2, 0.5])
OMEGA0 = np.array([0.8, -0.6, 1.1])
BUDGET = 0.15
TOLS = [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13]
T_LONG = 2000.0
LF_METHODS = ["splitting", "splitting4", "splitting6", "rk4"]


def uptime():
    try:
        return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    except OSError:
        return f"load average {os.getloadavg()}"


def problems():
    """(label, top, z0, sigma, ell, T, relative, steps per method, DOP853 tolerances)."""
    S = lf.spaces
    x = np.array([0.6, 0.48, 0.0, 0.64])
    x = RADIUS * x / np.linalg.norm(x)
    v = np.array([0.3, -0.5, 0.7, 0.1])
    v -= (v @ x) / (x @ x) * x
    sphere = lf.FrameTop(S.Sphere(3, radius=RADIUS), MASS, INERTIA)
    xs, vs = np.array([0.4, -0.3, 0.2]), np.array([0.3, -0.5, 0.7])
    xh = np.concatenate([[np.sqrt(RADIUS**2 + xs @ xs)], xs])
    vh = np.concatenate([[(xs @ vs) / xh[0]], vs])        # -x0 v0 + x.v = 0
    hyper = lf.FrameTop(S.Hyperbolic(3, radius=RADIUS), MASS, INERTIA)
    flat = lf.FrameTop(S.Euclidean(3), MASS, INERTIA)
    main_steps = {"exact": [1, 20, 1000],
                  "splitting": [500, 1000, 2000, 4000, 8000, 16000],
                  "splitting4": [200, 400, 800, 1600, 3200],
                  "splitting6": [100, 200, 400, 800, 1600],
                  "rk4": [250, 500, 1000, 2000, 4000, 8000, 16000, 32000]}
    short_steps = {"exact": [1],
                   "splitting": [250, 1000, 4000],
                   "splitting4": [25, 50, 100, 200, 400, 800],
                   "splitting6": [25, 50, 100, 200, 400],
                   "rk4": [30, 60, 125, 250, 500, 1000, 2000, 4000]}
    long_steps = {"exact": [1],
                  "splitting": [500, 2000, 8000],
                  "splitting4": [100, 200, 400, 800, 1600],
                  "splitting6": [100, 200, 400, 800, 1600],
                  "rk4": [125, 250, 500, 1000, 2000, 4000, 8000, 16000]}
    return [
        ("(a) sphere S^3(r = 1.7), T = 20", sphere,
         sphere.state(x, R0, v, OMEGA0), 1.0, RADIUS, 20.0, False, main_steps,
         TOLS),
        ("(b) hyperbolic H^3(r = 1.7), T = 5", hyper,
         hyper.state(xh, R0, vh, OMEGA0), -1.0, RADIUS, 5.0, True, short_steps,
         TOLS),
        ("(c) Euclidean R^3, T = 20", flat,
         flat.state(xs, R0, vs, OMEGA0), 0.0, 1.0, 20.0, True, long_steps,
         TOLS),
    ]


def make_rhs(top, sigma, ell):
    """The Lie–Poisson field of the top on z = (g, Pi, P) as a scipy right-hand side."""
    m = top.mass
    k = top.space.curvature / m
    (a11, a12, a13), (a21, a22, a23), (a31, a32, a33) = np.linalg.inv(top.inertia).tolist()
    c = 1.0 / (m * ell)
    s = sigma

    def rhs(_t, z):
        p1, p2, p3, q1, q2, q3 = z[16:].tolist()
        w1 = a11 * p1 + a12 * p2 + a13 * p3
        w2 = a21 * p1 + a22 * p2 + a23 * p3
        w3 = a31 * p1 + a32 * p2 + a33 * p3
        v1, v2, v3 = q1 * c, q2 * c, q3 * c
        xi = np.array([[0.0, -s * v1, -s * v2, -s * v3], [v1, 0.0, -w3, w2],
                       [v2, w3, 0.0, -w1], [v3, -w2, w1, 0.0]])
        out = np.empty(22)
        out[:16] = (z[:16].reshape(4, 4) @ xi).ravel()
        out[16:] = (p2 * w3 - p3 * w2, p3 * w1 - p1 * w3, p1 * w2 - p2 * w1,
                    q2 * w3 - q3 * w2 + k * (p2 * q3 - p3 * q2),
                    q3 * w1 - q1 * w3 + k * (p3 * q1 - p1 * q3),
                    q1 * w2 - q2 * w1 + k * (p1 * q2 - p2 * q1))
        return out

    return rhs


def check_rhs(top, z0, rhs):
    dt = 0.01
    f = lambda z: rhs(0.0, z)
    k1 = f(z0)
    k2 = f(z0 + 0.5 * dt * k1)
    k3 = f(z0 + 0.5 * dt * k2)
    k4 = f(z0 + dt * k3)
    mine = z0 + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    theirs = lf.integrate(top, z0, dt=dt, steps=1, method="rk4").final_state
    step = np.abs(mine - theirs).max()
    sol = solve_ivp(rhs, (0, 1.0), z0, method="DOP853", rtol=1e-13, atol=1e-15)
    rk = lf.integrate(top, z0, dt=1e-4, steps=10000, method="rk4", save_every=10000)
    flow = np.abs(sol.y[:, -1] - rk.final_state).max()
    print(f"RHS check: one rk4 step (dt = 0.01), scipy RHS vs lieflow: {step:.1e}; "
          f"DOP853 rtol 1e-13 vs lieflow rk4 dt = 1e-4 at t = 1: {flow:.1e}\n")
    assert step < 1e-13 and flow < 1e-11, (step, flow)


def drifts(top, states, inv0, h0):
    inv = np.asarray(top.invariants(states))
    d = np.abs(inv - inv0)
    return d[:, :3].max(), d[:, 3:].max(), np.abs(np.asarray(top.energy(states)) - h0).max()


def run(label, top, z0, sigma, ell, t_end, relative, steps_of, tols):
    print(f"### {label}\n")
    z0 = np.asarray(z0, dtype=float)
    rhs = make_rhs(top, sigma, ell)
    check_rhs(top, z0, rhs)
    inv0, h0 = np.asarray(top.invariants(z0)), top.energy(z0)
    ref = lf.integrate(top, z0, dt=t_end, steps=1, method="exact").final_state
    scale = np.abs(ref).max() if relative else 1.0
    ex1000 = lf.integrate(top, z0, dt=t_end / 1000, steps=1000, method="exact",
                          save_every=1000).final_state
    dop = solve_ivp(rhs, (0, t_end), z0, method="DOP853", rtol=1e-13, atol=1e-16).y[:, -1]
    s6 = lf.integrate(top, z0, dt=t_end / 3200, steps=3200, method="splitting6",
                      save_every=3200).final_state
    print(f"Reference: exact in 1 step; against exact in 1000 steps "
          f"{np.abs(ex1000 - ref).max() / scale:.1e}, DOP853 rtol 1e-13 "
          f"{np.abs(dop - ref).max() / scale:.1e}, splitting6 T/3200 "
          f"{np.abs(s6 - ref).max() / scale:.1e}"
          + (f" (relative to max|z(T)| = {scale:.3g})" if relative else "") + "\n")

    rows, points = [], {}
    for method, steps_list in steps_of.items():
        for n in steps_list:
            dt = t_end / n
            sec, tr = best_time(lambda: lf.integrate(top, z0, dt=dt, steps=n, method=method,
                                                     save_every=n), budget=BUDGET)
            err = np.abs(tr.final_state - ref).max() / scale
            full = lf.integrate(top, z0, dt=dt, steps=n, method=method, save_every=1)
            rows.append((f"`{method}`", f"{n} steps", err, *drifts(top, full.states, inv0, h0),
                         sec))
            points.setdefault(method, []).append((err, sec))
    for tol in tols:
        sec, sol = best_time(lambda: solve_ivp(rhs, (0, t_end), z0, method="DOP853", rtol=tol,
                                               atol=tol * 1e-3), budget=BUDGET)
        err = np.abs(sol.y[:, -1] - ref).max() / scale
        rows.append(("DOP853", f"rtol {tol:.0e} ({sol.nfev} RHS)", err,
                     *drifts(top, sol.y.T, inv0, h0), sec))
        points.setdefault("DOP853", []).append((err, sec))

    err_name = "rel. error" if relative else "error"
    print(f"| method | setting | {err_name} at T | max \\|ΔC\\| (Π·P, \\|P\\|²+κ\\|Π\\|², T) | "
          f"max \\|ΔJ\\| (Killing) | max \\|H − H0\\| | time |")
    print("|---|---|---|---|---|---|---|")
    for name, setting, err, dc, dj, dh, sec in rows:
        print(f"| {name} | {setting} | {err:.1e} | {dc:.1e} | {dj:.1e} | {dh:.1e} | "
              f"{sec * 1e3:.3f} ms |")

    # Time to reach an error, DOP853 / method; `exact` reaches round-off in one step, so its
    # ratio is DOP853's time to the target over the time of that one step.
    exact_one = next(s for (e, s), n in zip(points["exact"], steps_of["exact"]) if n == 1)
    targets = [1e-6, 1e-9, 1e-12]
    print(f"\nTime to reach the error, as (time of DOP853) / (time of the method):\n")
    print("| error | DOP853 | " + " | ".join(f"`{m}`" for m in LF_METHODS)
          + " | best stepping method | `exact`, 1 step |")
    print("|---" * (len(LF_METHODS) + 4) + "|")
    headline = {}
    for target in targets:
        ref_t = time_to(points["DOP853"], target)
        cells, best = [], None
        for m in LF_METHODS:
            t = time_to(points[m], target)
            cells.append("—" if t is None or ref_t is None else f"{ref_t / t:.1f}×")
            if t is not None and (best is None or t < best[1]):
                best = (m, t)
        dop = "—" if ref_t is None else f"{ref_t * 1e3:.2f} ms"
        bst = ("—" if best is None or ref_t is None
               else f"`{best[0]}` {ref_t / best[1]:.1f}×")
        exa = "—" if ref_t is None else f"{ref_t / exact_one:.0f}×"
        print(f"| {target:.0e} | {dop} | " + " | ".join(cells) + f" | {bst} | {exa} |")
        headline[target] = (best, ref_t)
    print()
    return headline


def long_run(label, top, z0, sigma, ell, *_):
    """One run each to T_LONG at settings with error ~1e-9 at T = 20: how the energy, the Casimirs
    and the Killing momenta drift (lieflow sampled every few steps, DOP853 at accepted steps)."""
    z0 = np.asarray(z0, dtype=float)
    inv0, h0 = np.asarray(top.invariants(z0)), top.energy(z0)
    windows = [20.0, T_LONG / 10, T_LONG]
    print(f"### {label}: long run to T = {T_LONG:g} (settings with error ~1e-9 at T = 20)\n")
    print("| method | setting | " + " | ".join(f"max \\|H − H0\\|, t ≤ {w:g}" for w in windows)
          + f" | max \\|ΔC\\|, t ≤ {T_LONG:g} | max \\|ΔJ\\|, t ≤ {T_LONG:g} | time |")
    print("|---" * (len(windows) + 5) + "|")

    def report(name, setting, sec, t, states):
        dh = np.abs(np.asarray(top.energy(states)) - h0)
        d = np.abs(np.asarray(top.invariants(states)) - inv0)
        print(f"| {name} | {setting} | " + " | ".join(f"{dh[t <= w].max():.1e}" for w in windows)
              + f" | {d[:, :3].max():.1e} | {d[:, 3:].max():.1e} | {sec:.2f} s |")

    for method, per20, every in [("exact", 200, 1), ("splitting6", 400, 2), ("rk4", 2000, 10)]:
        n = int(per20 * T_LONG / 20)
        sec, tr = best_time(lambda: lf.integrate(top, z0, dt=T_LONG / n, steps=n, method=method,
                                                 save_every=every), repeats=1)
        report(f"`{method}`", f"dt = {T_LONG / n:g}", sec, np.asarray(tr.t), tr.states)
    rhs = make_rhs(top, sigma, ell)
    sec, sol = best_time(lambda: solve_ivp(rhs, (0, T_LONG), z0, method="DOP853", rtol=1e-9,
                                           atol=1e-12), repeats=1)
    report("DOP853", "rtol 1e-9", sec, sol.t, sol.y.T)
    print()


def main():
    t0 = time.perf_counter()
    print(environment())
    print(f"uptime at start: {uptime()}\n")
    probs = problems()
    for prob in probs:
        run(*prob)
    long_run(*probs[0])
    print(f"total {time.perf_counter() - t0:.0f} s; uptime at end: {uptime()}")


if __name__ == "__main__":
    main()
