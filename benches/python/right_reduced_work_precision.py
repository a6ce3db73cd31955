"""Work–precision of the pseudo-rigid body reduced by its right SO(n) symmetry (001 §3,
`lf.pseudo_rigid.RightReduced`): the reduced Verlet methods (verlet, verlet4, verlet6) and rk4
against the full body `lf.PseudoRigidBody` (verlet, verlet4, verlet6 at the same steps) and
scipy's DOP853 on the reduced (Riemann) equations.

Problem: n = 3, U = SaintVenantKirchhoff(1, 2) + Volumetric(0.5, 1.4), X0 = diag(1.6, 1.25, 0.9)
plus a small shear, P0 below (angular momentum L = P X^T - X P^T and circulation
Gamma = P^T X - X^T P both nonzero), T = 20; the reduced state is (Q, N) = (X X^T, X P^T).

scipy integrates dQ/dt = N + N^T, dN/dt = N^T Q^-1 N - C G^T through
`lf.pseudo_rigid.riemann_vector_field(Q, N, U)` (native, ~12 us a call from Python; the same
field written in numpy with a Cholesky factor costs ~34 us and is only used as a check). Before
timing the script checks the field against lieflow: one rk4 step (dt = 0.01) against
RightReduced's rk4 step, and DOP853 at rtol 1e-13 to t = 1 against
lf.integrate(body, z0, method="rk4", dt=1e-4).

Error = max-norm of (Q, N)(T) minus the reference, reduced verlet6 at T/32000 (cross-checked
against T/16000 and DOP853 at rtol 1e-13); the full body's error is that of (X X^T, X P^T)(T).
Drifts: max over the run of |I - I0| for traj.invariants() (tr(L^T L)/2 and tr(Gamma^T Gamma)/2,
the spectral invariants of L and of the circulation for n = 3) and of |H - H0|, over every
lieflow step and every accepted DOP853 step (an untimed second run). Wall time is the best of
>= 3 calls (more for fast ones, up to ~0.15 s per point) through lf.integrate(...,
save_every=steps); DOP853 is solve_ivp(rhs, (0, T), z0, method="DOP853", rtol=tol,
atol=tol * 1e-3). Ratios are DOP853's time over the method's, both interpolated log-log to the
same error in this run. Then one run each to T = 2000 (error ~1e-9 settings at T = 20) for the
drift of the energy and the Casimirs. Runs in ~30-40 s.

    python benches/python/right_reduced_work_precision.py
"""

import os
import subprocess
import time

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time, environment, time_to

N_DIM = 3
LAM, MU, KAPPA, GAMMA = 1.0, 2.0, 0.5, 1.4
POTENTIAL = lf.potentials.SaintVenantKirchhoff(LAM, MU) + lf.potentials.Volumetric(KAPPA, GAMMA)
X0 = np.diag([1.6, 1.25, 0.9]) + np.array([[0, 0.06, 0], [0, 0, 0.04], [0.03, 0, 0]])
P0 = np.array([[0.05, 0.45, -0.15], [-0.3, 0.02, 0.35], [0.2, -0.3, 0.0]])
T = 20.0
T_LONG = 2000.0
BUDGET = 0.15
TOLS = [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13]
STEPS = {"verlet": [1000, 2000, 4000, 8000, 16000, 32000],
         "verlet4": [250, 500, 1000, 2000, 4000],
         "verlet6": [100, 200, 400, 800, 1600, 3200, 6400],
         "rk4": [500, 1000, 2000, 4000, 8000, 16000]}
FULL_METHODS = ["verlet", "verlet4", "verlet6"]

REDUCED = lf.pseudo_rigid.RightReduced(N_DIM, POTENTIAL)
RECON = lf.pseudo_rigid.RightReduced(N_DIM, POTENTIAL, reconstruct=True)
FULL = lf.PseudoRigidBody(N_DIM, POTENTIAL)


def uptime():
    try:
        return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    except OSError:
        return f"load average {os.getloadavg()}"


def rhs(_t, y):
    qd, nd = lf.pseudo_rigid.riemann_vector_field(y[:9].reshape(3, 3), y[9:].reshape(3, 3),
                                                  POTENTIAL)
    return np.concatenate([np.ravel(qd), np.ravel(nd)])


def rhs_numpy(_t, y):
    """The same field in numpy (C the Cholesky factor of Q, G = dU/dX at C): a check only."""
    q, n = y[:9].reshape(3, 3), y[9:].reshape(3, 3)
    c = np.linalg.cholesky(q)
    w = np.linalg.solve(c, n)
    e = 0.5 * (c.T @ c - np.eye(3))
    s = LAM * np.trace(e) * np.eye(3) + 2 * MU * e
    det = c[0, 0] * c[1, 1] * c[2, 2]
    # G = C S - KAPPA det^(1 - GAMMA) C^-T, so C G^T = C S C^T - KAPPA det^(1 - GAMMA) 1.
    cgt = c @ s @ c.T - KAPPA * det ** (1 - GAMMA) * np.eye(3)
    return np.concatenate([(n + n.T).ravel(), (w.T @ w - cgt).ravel()])


def reduce_full(states):
    """(Q, N) = (X X^T, X P^T) of full states (..., 18)."""
    x = states[..., :9].reshape(*states.shape[:-1], 3, 3)
    p = states[..., 9:].reshape(*states.shape[:-1], 3, 3)
    q = x @ np.swapaxes(x, -1, -2)
    nn = x @ np.swapaxes(p, -1, -2)
    return np.concatenate([q.reshape(*states.shape[:-1], 9), nn.reshape(*states.shape[:-1], 9)],
                          axis=-1)


def check_rhs(z0):
    dt = 0.01
    f = lambda z: rhs(0.0, z)
    k1 = f(z0)
    k2 = f(z0 + 0.5 * dt * k1)
    k3 = f(z0 + 0.5 * dt * k2)
    k4 = f(z0 + dt * k3)
    mine = z0 + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    theirs = lf.integrate(REDUCED, z0, dt=dt, steps=1, method="rk4").final_state
    step = np.abs(mine - theirs).max()
    sol = solve_ivp(rhs, (0, 1.0), z0, method="DOP853", rtol=1e-13, atol=1e-15)
    rk = lf.integrate(REDUCED, z0, dt=1e-4, steps=10000, method="rk4", save_every=10000)
    flow = np.abs(sol.y[:, -1] - rk.final_state).max()
    numpy_diff = np.abs(rhs_numpy(0.0, z0) - rhs(0.0, z0)).max()
    c1, _ = best_time(lambda: [rhs(0.0, z0) for _ in range(1000)])
    c2, _ = best_time(lambda: [rhs_numpy(0.0, z0) for _ in range(1000)])
    print(f"RHS check: one rk4 step (dt = 0.01), riemann_vector_field vs lieflow: {step:.1e}; "
          f"DOP853 rtol 1e-13 vs lieflow rk4 dt = 1e-4 at t = 1: {flow:.1e}; numpy field "
          f"(Cholesky) vs riemann_vector_field: {numpy_diff:.1e}; cost per call "
          f"{c1 * 1e3:.1f} us (riemann_vector_field) / {c2 * 1e3:.1f} us (numpy)\n")
    assert step < 1e-13 and flow < 1e-11 and numpy_diff < 1e-12, (step, flow, numpy_diff)


def work_precision():
    z0 = np.asarray(REDUCED.reduce(X0, P0))
    zf0 = np.concatenate([X0.ravel(), P0.ravel()])
    zx0 = np.asarray(RECON.reduce(X0, P0))
    L0 = P0 @ X0.T - X0 @ P0.T
    G0 = P0.T @ X0 - X0.T @ P0
    print(f"### Right-reduced pseudo-rigid body, n = 3, SVK(1, 2) + Volumetric(0.5, 1.4), "
          f"T = {T:g}\n")
    print(f"L0 = {np.round(L0, 4).tolist()}, Gamma0 = {np.round(G0, 4).tolist()}, "
          f"H0 = {REDUCED.energy(z0):.6f} (full body {FULL.energy(zf0):.6f}), "
          f"invariants {np.round(np.asarray(REDUCED.invariants(z0)), 6).tolist()}\n")
    check_rhs(z0)
    refs = {n: lf.integrate(REDUCED, z0, dt=T / n, steps=n, method="verlet6",
                            save_every=n).final_state for n in (16000, 32000)}
    ref = refs[32000]
    dop = solve_ivp(rhs, (0, T), z0, method="DOP853", rtol=1e-13, atol=1e-16).y[:, -1]
    print(f"Reference: reduced verlet6 at T/32000; against T/16000 "
          f"{np.abs(refs[16000] - ref).max():.1e}, DOP853 rtol 1e-13 "
          f"{np.abs(dop - ref).max():.1e}\n")
    inv0, h0 = np.asarray(REDUCED.invariants(z0)), REDUCED.energy(z0)

    def drifts(system, states):
        return (np.abs(np.asarray(system.invariants(states)) - inv0).max(),
                np.abs(np.asarray(system.energy(states)) - h0).max())

    rows, points, same = [], {}, []
    for method, steps_list in STEPS.items():
        for n in steps_list:
            dt = T / n
            sec, tr = best_time(lambda: lf.integrate(REDUCED, z0, dt=dt, steps=n, method=method,
                                                     save_every=n), budget=BUDGET)
            err = np.abs(tr.final_state - ref).max()
            full = lf.integrate(REDUCED, z0, dt=dt, steps=n, method=method, save_every=1)
            rows.append((f"`{method}`", f"{n} steps", err, *drifts(REDUCED, full.states), sec))
            points.setdefault(f"reduced {method}", []).append((err, sec))
            if method not in FULL_METHODS:
                continue
            secf, trf = best_time(lambda: lf.integrate(FULL, zf0, dt=dt, steps=n, method=method,
                                                       save_every=n), budget=BUDGET)
            errf = np.abs(reduce_full(trf.final_state) - ref).max()
            fullf = lf.integrate(FULL, zf0, dt=dt, steps=n, method=method, save_every=1)
            rows.append((f"full `{method}`", f"{n} steps", errf, *drifts(FULL, fullf.states),
                         secf))
            points.setdefault(f"full {method}", []).append((errf, secf))
            # The reduced run is the full Verlet motion: (Q, N) of the full run, and X, P
            # reconstructed by the reconstructing system, against the full run.
            secx, trx = best_time(lambda: lf.integrate(RECON, zx0, dt=dt, steps=n, method=method,
                                                       save_every=n), budget=BUDGET)
            xr, pr = RECON.reconstruct(trx.final_state)
            same.append((method, n, np.abs(reduce_full(trf.final_state)
                                           - tr.final_state).max(),
                         np.abs(np.concatenate([np.ravel(xr), np.ravel(pr)])
                                - trf.final_state).max(), sec / n, secx / n, secf / n))
    for tol in TOLS:
        sec, sol = best_time(lambda: solve_ivp(rhs, (0, T), z0, method="DOP853", rtol=tol,
                                               atol=tol * 1e-3), budget=BUDGET)
        err = np.abs(sol.y[:, -1] - ref).max()
        rows.append(("DOP853", f"rtol {tol:.0e} ({sol.nfev} RHS)", err,
                     *drifts(REDUCED, sol.y.T), sec))
        points.setdefault("DOP853", []).append((err, sec))

    print("| method | setting | error of (Q, N) at T | max \\|ΔI\\| (spectra of L, Γ) | "
          "max \\|H − H0\\| | time |")
    print("|---|---|---|---|---|---|")
    for name, setting, err, di, dh, sec in rows:
        print(f"| {name} | {setting} | {err:.1e} | {di:.1e} | {dh:.1e} | {sec * 1e3:.3f} ms |")

    print("\nReduced against full Verlet at the same steps (cost per step from the runs above):\n")
    print("| method | steps | \\|(Q, N) of full − reduced\\| | \\|(X, P) reconstructed − full\\| | "
          "reduced | reduced + X | full | reduced / full |")
    print("|---|---|---|---|---|---|---|---|")
    for method, n, d1, d2, r, x, f in same:
        print(f"| `{method}` | {n} | {d1:.1e} | {d2:.1e} | {r * 1e9:.0f} ns | {x * 1e9:.0f} ns | "
              f"{f * 1e9:.0f} ns | {r / f:.1f}× |")

    names = [f"reduced {m}" for m in STEPS] + [f"full {m}" for m in FULL_METHODS]
    print("\nTime to reach the error, as (time of DOP853) / (time of the method):\n")
    print("| error | DOP853 | " + " | ".join(f"{m}" for m in names)
          + " | best reduced | best overall |")
    print("|---" * (len(names) + 4) + "|")
    for target in [1e-6, 1e-9, 1e-12]:
        ref_t = time_to(points["DOP853"], target)
        cells, best_red, best_all = [], None, None
        for m in names:
            t = time_to(points[m], target)
            cells.append("—" if t is None or ref_t is None else f"{ref_t / t:.1f}×")
            if t is None:
                continue
            if m.startswith("reduced") and (best_red is None or t < best_red[1]):
                best_red = (m, t)
            if best_all is None or t < best_all[1]:
                best_all = (m, t)
        fmt = lambda b: "—" if b is None or ref_t is None else f"{b[0]} {ref_t / b[1]:.1f}×"
        dop = "—" if ref_t is None else f"{ref_t * 1e3:.2f} ms"
        print(f"| {target:.0e} | {dop} | " + " | ".join(cells)
              + f" | {fmt(best_red)} | {fmt(best_all)} |")
    print()
    return z0, zf0


def long_run(z0, zf0):
    inv0, h0 = np.asarray(REDUCED.invariants(z0)), REDUCED.energy(z0)
    windows = [20.0, T_LONG / 10, T_LONG]
    print(f"### Long run to T = {T_LONG:g} (settings with error ~1e-9 at T = 20)\n")
    print("| method | setting | " + " | ".join(f"max \\|H − H0\\|, t ≤ {w:g}" for w in windows)
          + f" | max \\|ΔI\\|, t ≤ {T_LONG:g} | time |")
    print("|---" * (len(windows) + 4) + "|")

    def report(name, setting, sec, system, t, states):
        dh = np.abs(np.asarray(system.energy(states)) - h0)
        di = np.abs(np.asarray(system.invariants(states)) - inv0).max()
        print(f"| {name} | {setting} | " + " | ".join(f"{dh[t <= w].max():.1e}" for w in windows)
              + f" | {di:.1e} | {sec:.2f} s |")

    for name, system, state, method, per20, every in [
            ("`verlet6`", REDUCED, z0, "verlet6", 1600, 4),
            ("full `verlet6`", FULL, zf0, "verlet6", 1600, 4),
            ("`rk4`", REDUCED, z0, "rk4", 8000, 20)]:
        n = int(per20 * T_LONG / 20)
        sec, tr = best_time(lambda: lf.integrate(system, state, dt=T_LONG / n, steps=n,
                                                 method=method, save_every=every), repeats=1)
        report(name, f"dt = {T_LONG / n:g}", sec, system, np.asarray(tr.t), tr.states)
    sec, sol = best_time(lambda: solve_ivp(rhs, (0, T_LONG), z0, method="DOP853", rtol=1e-9,
                                           atol=1e-12), repeats=1)
    report("DOP853", "rtol 1e-9", sec, REDUCED, sol.t, sol.y.T)
    print()


def main():
    t0 = time.perf_counter()
    print(environment())
    print(f"uptime at start: {uptime()}\n")
    z0, zf0 = work_precision()
    long_run(z0, zf0)
    print(f"total {time.perf_counter() - t0:.0f} s; uptime at end: {uptime()}")


if __name__ == "__main__":
    main()
