"""Work–precision of the rolling systems of 003: `lf.RollingDisks` (two disks rolling against each
other, canonical, methods gauss4, gauss6, midpoint, rk4) and `lf.RollingSpheres` (two spheres
rolling against each other in space, methods midpoint, midpoint4, rkmk4 on SO(3)² × S² and rk4
on the flat 27 values), against scipy's solve_ivp (DOP853, RK45), then the drift of the
conserved quantities (energy, angular momentum) over a long run.

Problems (the parameters of examples/rolling_disks.py and examples/rolling_spheres.py), T = 20:

* disks: RollingDisks(r1=1, r2=0.7, gamma1=0.3+0.1i, gamma2=-0.2+0.25i, m1=1, m2=1.5,
  inertia1=0.8, inertia2=0.6), z0 = d.state([0.3, -1.1], [0.7, 0.2]);
* spheres: RollingSpheres(0.7, 1.3, ...) with the inertias and initial state of the example.

Right-hand sides for the rivals:

* disks: lieflow exposes no vector field for the disks, only M(theta) (`mass_matrix`); the script
  writes Hamilton's equations theta' = M^-1 p, p' = 1/2 v^T (dM/dtheta_k) v from M in the complex
  form of the module docs of crates/core/src/systems/rolling_disks.rs (M = [[I1c + e|A|^2,
  -e Re(A conj B)], [., I2c + e|B|^2]], A = z1 g1 - r1 u, B = z2 g2 + r2 u, u = exp(i phi)) as
  scalar Python (`cmath`), dM/dtheta in closed form; checked before timing: M against
  `d.mass_matrix`, one rk4 step against lieflow's rk4 step (round-off), H against `d.energy`.
* spheres: lieflow exposes the dynamics, `accelerations(states)` (dOmega_k/dt) and
  `udot(states)`; the rival integrates z = (z1, z2, u, Omega1, Omega2) with z_k' = z_k hat(Omega_k),
  u' = (alpha1 z1 Omega1 + alpha2 z2 Omega2) x u, Omega_k' = accelerations. `accelerations` refuses
  attitudes off SO(3) by more than 1e-10, so the RHS hands it the polar projection of z_k (SVD)
  and u/|u| (the kinematics use the unprojected values; the projection is timed with the
  RHS). Checked: u' against `udot`, and the derivative of a fine lieflow run at t = 0.
  (lieflow's own rk4 works in the momentum chart (z1, z2, u, P1, P2), so it is not step-for-step
  the same ODE.)

Error = max over 11 samples (every T/10) of the max-norm of the state difference from a reference
(disks: gauss6 at T/40000, checked against T/20000; spheres: rkmk4 at T/40000, checked against
midpoint4 at T/8000). Wall time: best of >= 5 repeats (more for fast runs, up to ~0.1 s per
point) of `lf.integrate(system, z0, dt, steps, method, save_every=steps/10)` and of
`solve_ivp(f, (0, T), z0, method, rtol=tol, atol=tol/100, t_eval=samples)`.

Long runs (one each, T_LONG = 5000): every lieflow method at a setting named in LONG, and
DOP853; the energy error max |H - H0| (spheres: relative) over [0, t] for growing t
and the largest error of the angular momentum J (disks: p1 + p2; spheres: the total angular
momentum, `invariants`, 3 components), and for the spheres how far the attitudes leave SO(3)
(max ||z^T z - I||_F) and u leaves S^2.

    python benches/python/rolling_work_precision.py [--figure docs/rolling_work_precision.png]
"""

import argparse
import cmath
import os
import time

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time, environment, print_ratios

T = 20.0
SAMPLES = 10
BUDGET = 0.1
REPEATS = 5             # best of at least this many calls per point

DISKS = dict(r1=1.0, r2=0.7, gamma1=0.3 + 0.1j, gamma2=-0.2 + 0.25j, m1=1.0, m2=1.5,
             inertia1=0.8, inertia2=0.6)
DISK_STEPS = {"gauss6": [20, 40, 80, 160, 320, 640],
              "gauss4": [40, 80, 160, 320, 640, 1280, 2560],
              "midpoint": [200, 800, 3200, 12800],
              "rk4": [80, 160, 320, 640, 1280, 2560, 5120]}
DISK_RTOLS = {"DOP853": [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13],
              "RK45": [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]}
SPHERE_STEPS = {"midpoint": [100, 200, 400, 800, 1600, 3200, 6400],
                "midpoint4": [50, 100, 200, 400, 800, 1600],
                "rkmk4": [50, 100, 200, 400, 800, 1600, 3200],
                "rk4": [50, 100, 200, 400, 800, 1600, 3200]}
SPHERE_RTOLS = {"DOP853": [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12],
                "RK45": [1e-5, 1e-6, 1e-7, 1e-8, 1e-9]}
T_LONG = {"disks": 5000.0, "spheres": 5000.0}
# long-run settings (steps per T = 20 for lieflow, rtol for DOP853), chosen from the tables: about
# 1e-9 … 1e-10 error at T = 20 for every method but the second-order midpoint rules (disks: error
# 1e-6 at 3200 steps; spheres: dt = 0.02, the example's, error 3e-5)
LONG = {"disks": {"gauss6": 80, "gauss4": 320, "midpoint": 3200, "rk4": 640, "DOP853": 1e-10},
        "spheres": {"midpoint": 1000, "midpoint4": 800, "rkmk4": 800, "rk4": 3200,
                    "DOP853": 1e-10}}


# ---------------------------------------------------------------------------------------------
# the disks: Hamilton's equations from M(theta)

def disks_field(q1, q2, p1, p2, r1, r2, g1, g2, m1, m2, i1, i2, c):
    """(theta1', theta2', p1', p2') of H = p^T M(theta)^-1 p / 2 (module docs)."""
    big_r = r1 + r2
    e = m1 * m2 / (m1 + m2)
    u = cmath.exp(1j * ((c + r1 * q1 + r2 * q2) / big_r))
    a = cmath.exp(1j * q1) * g1
    b = cmath.exp(1j * q2) * g2
    A = a - r1 * u
    B = b + r2 * u
    m11 = i1 - m1 * abs(g1) ** 2 + e * abs(A) ** 2
    m22 = i2 - m2 * abs(g2) ** 2 + e * abs(B) ** 2
    m12 = -e * (A * B.conjugate()).real
    det = m11 * m22 - m12 * m12
    v1 = (m22 * p1 - m12 * p2) / det
    v2 = (m11 * p2 - m12 * p1) / det
    # d/dtheta_k of A and B: du/dtheta_k = i (r_k / R) u
    du1, du2 = 1j * (r1 / big_r) * u, 1j * (r2 / big_r) * u
    dA = (1j * a - r1 * du1, -r1 * du2)
    dB = (r2 * du1, 1j * b + r2 * du2)
    out = []
    for k in range(2):
        d11 = 2.0 * e * (A.conjugate() * dA[k]).real
        d22 = 2.0 * e * (B.conjugate() * dB[k]).real
        d12 = -e * (dA[k] * B.conjugate() + A * dB[k].conjugate()).real
        out.append(0.5 * (d11 * v1 * v1 + 2.0 * d12 * v1 * v2 + d22 * v2 * v2))
    return v1, v2, out[0], out[1], (m11, m12, m22)


def disks_params(d):
    r1, r2, g1, g2, m1, m2, i1, i2, c = d.__reduce__()[1]
    return (r1, r2, complex(*g1), complex(*g2), m1, m2, i1, i2, c)


def disks_rhs(par):
    def f(t, y):
        return disks_field(*y.tolist(), *par)[:4]
    return f


def check_disks(d, z0, par):
    f = lambda z: np.array(disks_field(*z, *par)[:4])
    m11, m12, m22 = disks_field(*z0, *par)[4]
    m_diff = np.abs(np.array([[m11, m12], [m12, m22]]) - d.mass_matrix(z0[:2])).max()
    dt = 0.01
    k1 = f(z0)
    k2 = f(z0 + 0.5 * dt * k1)
    k3 = f(z0 + 0.5 * dt * k2)
    k4 = f(z0 + dt * k3)
    mine = z0 + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    theirs = lf.integrate(d, z0, dt=dt, steps=1, method="rk4").final_state
    step_diff = np.abs(mine - theirs).max()
    v = k1[:2]
    h_diff = abs(0.5 * v @ z0[2:] - d.energy(z0))
    print(f"  RHS check: |M - mass_matrix| = {m_diff:.1e}, |one rk4 step, script - lieflow| = "
          f"{step_diff:.1e}, |H script - lieflow| = {h_diff:.1e}")
    assert m_diff < 1e-14 and step_diff < 1e-13 and h_diff < 1e-14, (m_diff, step_diff, h_diff)


# ---------------------------------------------------------------------------------------------
# the spheres: lieflow's accelerations, the kinematics here

def spheres_rhs(sp):
    a1, a2 = sp.alphas
    acc = sp.accelerations
    svd = np.linalg.svd

    def f(t, y):
        U, _, Vt = svd(y[:18].reshape(2, 3, 3))
        s = y.copy()
        s[:18] = (U @ Vt).ravel()
        (x11, x12, x13, x21, x22, x23, x31, x32, x33,
         y11, y12, y13, y21, y22, y23, y31, y32, y33,
         u1, u2, u3, o1, o2, o3, w1, w2, w3) = y.tolist()
        nu = (u1 * u1 + u2 * u2 + u3 * u3) ** -0.5
        s[18:21] = (u1 * nu, u2 * nu, u3 * nu)
        # spatial angular velocities omega_k = z_k Omega_k; v = alpha1 omega1 + alpha2 omega2
        v1 = a1 * (x11 * o1 + x12 * o2 + x13 * o3) + a2 * (y11 * w1 + y12 * w2 + y13 * w3)
        v2 = a1 * (x21 * o1 + x22 * o2 + x23 * o3) + a2 * (y21 * w1 + y22 * w2 + y23 * w3)
        v3 = a1 * (x31 * o1 + x32 * o2 + x33 * o3) + a2 * (y31 * w1 + y32 * w2 + y33 * w3)
        # rows of z hat(Omega) are the rows of z crossed with Omega; u' = v x u
        return [x12 * o3 - x13 * o2, x13 * o1 - x11 * o3, x11 * o2 - x12 * o1,
                x22 * o3 - x23 * o2, x23 * o1 - x21 * o3, x21 * o2 - x22 * o1,
                x32 * o3 - x33 * o2, x33 * o1 - x31 * o3, x31 * o2 - x32 * o1,
                y12 * w3 - y13 * w2, y13 * w1 - y11 * w3, y11 * w2 - y12 * w1,
                y22 * w3 - y23 * w2, y23 * w1 - y21 * w3, y21 * w2 - y22 * w1,
                y32 * w3 - y33 * w2, y33 * w1 - y31 * w3, y31 * w2 - y32 * w1,
                v2 * u3 - v3 * u2, v3 * u1 - v1 * u3, v1 * u2 - v2 * u1,
                *acc(s).ravel().tolist()]
    return f


def check_spheres(sp, z0, f):
    du = np.array(f(0.0, z0))[18:21]
    u_diff = np.abs(du - sp.udot(z0)).max()
    # derivative of a fine lieflow run at t = 0 (central difference, h = 1e-3, rkmk4 at h/100)
    h = 1e-3
    fw = lf.integrate(sp, z0, dt=h / 100, steps=100, method="rkmk4").final_state
    fw2 = lf.integrate(sp, z0, dt=h / 100, steps=200, method="rkmk4").final_state
    fd = (-3 * z0 + 4 * fw - fw2) / (2 * h)        # one-sided, O(h^2)
    d_diff = np.abs(fd - np.array(f(0.0, z0))).max()
    print(f"  RHS check: |u' - udot| = {u_diff:.1e}, |f(z0) - d/dt of a lieflow run| = "
          f"{d_diff:.1e} (one-sided difference, h = 1e-3: O(h^2))")
    assert u_diff < 1e-14 and d_diff < 1e-5, (u_diff, d_diff)


def rot(axis_angle):
    return lf.lie.so3_exp(np.asarray(axis_angle, dtype=float))


def spheres_problem():
    sp = lf.RollingSpheres(0.7, 1.3, [0.1, -0.2, 0.15], [-0.3, 0.2, 0.4], 2.0, 3.5,
                           [[0.40, 0.05, -0.02], [0.05, 0.30, 0.04], [-0.02, 0.04, 0.25]],
                           [[0.90, -0.10, 0.05], [-0.10, 1.10, 0.08], [0.05, 0.08, 0.70]])
    z0 = np.array(sp.state(rot([0.3, -0.2, 0.5]), rot([-0.4, 0.1, 0.2]), [0.6, 0.0, 0.8],
                           [0.5, -0.3, 0.8], [-0.2, 0.4, 0.1]))
    return sp, z0


# ---------------------------------------------------------------------------------------------

def conserved(system, states, relative):
    """(energy error (k,), max |J - J0|) along states."""
    h = np.asarray(system.energy(states))
    de = np.abs(h - h[0]) / (abs(h[0]) if relative else 1.0)
    j = np.asarray(system.invariants(states)).reshape(len(h), -1)
    return de, np.abs(j - j[0]).max()


def work_precision(title, system, z0, ref, steps_of, rtols_of, rhs, relative):
    print(f"\n{title}, T = {T:g}")
    t_samples = np.linspace(0.0, T, SAMPLES + 1)
    rows = []
    for method, steps_list in steps_of.items():
        for steps in steps_list:
            dt = T / steps
            sec, tr = best_time(lambda: lf.integrate(system, z0, dt=dt, steps=steps,
                                                     method=method,
                                                     save_every=steps // SAMPLES),
                                repeats=REPEATS, budget=BUDGET)
            err = np.abs(tr.states - ref).max()
            de, dj = conserved(system, tr.states, relative)
            rows.append(dict(name=f"lieflow {method}", setting=f"steps={steps}", sec=sec, err=err,
                             de=de.max(), dj=dj))
    for method, tols in rtols_of.items():
        for tol in tols:
            sec, sol = best_time(lambda: solve_ivp(rhs, (0, T), z0, method=method, rtol=tol,
                                                   atol=tol * 1e-2, t_eval=t_samples),
                                 repeats=REPEATS, budget=BUDGET)
            err = np.abs(sol.y.T - ref).max()
            de, dj = conserved(system, sol.y.T, relative)
            rows.append(dict(name=f"scipy {method}", setting=f"rtol={tol:.0e}", sec=sec, err=err,
                             de=de.max(), dj=dj, nfev=sol.nfev))
    hname = "max|dH|/H" if relative else "max|H-H0|"
    print(f"  {'method':18s} {'setting':12s} {'time [ms]':>10s} {'error':>10s} {hname:>10s} "
          f"{'max|J-J0|':>10s}")
    for r in rows:
        extra = f"  ({r['nfev']} evaluations)" if "nfev" in r else ""
        print(f"  {r['name']:18s} {r['setting']:12s} {r['sec'] * 1e3:10.3f} {r['err']:10.2e} "
              f"{r['de']:10.2e} {r['dj']:10.2e}{extra}")
    points = {}
    for r in rows:
        points.setdefault(r["name"], []).append((r["err"], r["sec"]))
    print_ratios(points, [1e-6, 1e-8, 1e-10])
    return rows


def long_run(key, system, z0, rhs, relative, geometry=None):
    t_long = T_LONG[key]
    windows = [T, t_long / 10, t_long]
    print(f"  long run to T = {t_long:g} (one run each; lieflow saved every step up to 50000 "
          f"samples, DOP853 at every accepted step):")
    print(f"  {'method':18s} {'setting':13s} {'time [s]':>8s} "
          + " ".join(f"{'dH<=' + format(w, 'g'):>10s}" for w in windows)
          + f" {'max|J-J0|':>10s}" + (f" {'SO(3) dev':>9s} {'|u|-1':>9s}" if geometry else ""))
    curves = {}

    def report(name, setting, sec, t, states):
        de, dj = conserved(system, states, relative)
        line = (f"  {name:18s} {setting:13s} {sec:8.2f} "
                + " ".join(f"{de[t <= w].max():10.2e}" for w in windows) + f" {dj:10.2e}")
        if geometry:
            so3, sph = geometry(states)
            line += f" {so3:9.1e} {sph:9.1e}"
        print(line)
        curves[name] = (t, de)

    for method, spt in LONG[key].items():
        if method == "DOP853":
            continue
        n = int(round(spt * t_long / T))
        every = max(1, n // 50000)
        sec, tr = best_time(lambda: lf.integrate(system, z0, dt=t_long / n, steps=n,
                                                 method=method, save_every=every), repeats=1)
        report(f"lieflow {method}", f"dt={T / spt:.3g}", sec, np.asarray(tr.t), tr.states)
    tol = LONG[key]["DOP853"]
    sec, sol = best_time(lambda: solve_ivp(rhs, (0, t_long), z0, method="DOP853", rtol=tol,
                                           atol=tol * 1e-2), repeats=1)
    report("scipy DOP853", f"rtol={tol:.0e}", sec, sol.t, sol.y.T)
    return curves


def spheres_geometry(states):
    Z = states[:, :18].reshape(-1, 2, 3, 3)
    dev = np.linalg.norm(np.swapaxes(Z, -1, -2) @ Z - np.eye(3), axis=(-2, -1)).max()
    sph = np.abs(np.linalg.norm(states[:, 18:21], axis=1) - 1.0).max()
    return dev, sph


def figure(path, panels):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 2, figsize=(13, 9))
    markers = "osD^v<>"
    for ax, (title, rows) in zip(axes[0], panels["wp"]):
        names = list(dict.fromkeys(r["name"] for r in rows))
        for i, name in enumerate(names):
            pts = [(r["sec"], r["err"]) for r in rows if r["name"] == name]
            ls = "--" if name.startswith("scipy") else "-"
            ax.loglog([p[0] * 1e3 for p in pts], [p[1] for p in pts], markers[i] + ls, ms=4,
                      label=name)
        ax.set(xlabel="wall time [ms] (best of >= 5)", ylabel="max error over 11 samples",
               title=title)
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=8)
    for ax, (title, curves, ylabel) in zip(axes[1], panels["long"]):
        for name, (t, de) in curves.items():
            k = slice(1, None, max(1, len(t) // 4000))
            ax.loglog(t[k], np.maximum.accumulate(de)[k] + 1e-18, lw=1.0, label=name)
        ax.set(xlabel="t", ylabel=ylabel, title=title, ylim=(1e-16, None))
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print("figure:", path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--figure", default=None, help="write a PNG here")
    args = ap.parse_args()
    t_start = time.perf_counter()
    print(environment())
    panels = {"wp": [], "long": []}

    # --- disks
    d = lf.RollingDisks(**DISKS)
    z0 = np.array(d.state([0.3, -1.1], [0.7, 0.2]))
    par = disks_params(d)
    print(f"\nRollingDisks {d}, z0 = {np.round(z0, 6).tolist()}, methods {d.methods()}")
    check_disks(d, z0, par)
    n = 20000
    refs = [lf.integrate(d, z0, dt=T / m, steps=m, method="gauss6", save_every=m // SAMPLES)
            .states for m in (n, 2 * n)]
    print(f"  reference gauss6 {n} vs {2 * n} steps: {np.abs(refs[0] - refs[1]).max():.1e}")
    rhs = disks_rhs(par)
    rows = work_precision("(a) rolling disks", d, z0, refs[1], DISK_STEPS, DISK_RTOLS, rhs, False)
    panels["wp"].append(("(a) rolling disks, T = 20", rows))
    curves = long_run("disks", d, z0, rhs, False)
    panels["long"].append((f"(a) disks to t = {T_LONG['disks']:g}", curves,
                           "max |H − H0| over [0, t]"))

    # --- spheres
    sp, z0 = spheres_problem()
    print(f"\nRollingSpheres (examples/rolling_spheres.py), methods {sp.methods()}")
    rhs = spheres_rhs(sp)
    check_spheres(sp, z0, rhs)
    ref = lf.integrate(sp, z0, dt=T / 40000, steps=40000, method="rkmk4",
                       save_every=40000 // SAMPLES).states
    ref2 = lf.integrate(sp, z0, dt=T / 8000, steps=8000, method="midpoint4",
                        save_every=8000 // SAMPLES).states
    print(f"  reference rkmk4 40000 steps vs midpoint4 8000 steps: "
          f"{np.abs(ref - ref2).max():.1e}")
    rows = work_precision("(b) rolling spheres", sp, z0, ref, SPHERE_STEPS, SPHERE_RTOLS, rhs,
                          True)
    panels["wp"].append(("(b) rolling spheres, T = 20", rows))
    curves = long_run("spheres", sp, z0, rhs, True, spheres_geometry)
    panels["long"].append((f"(b) spheres to t = {T_LONG['spheres']:g}", curves,
                           "max |E − E0| / E0 over [0, t]"))

    if args.figure:
        figure(args.figure, panels)
    print(f"\ntotal {time.perf_counter() - t_start:.0f} s, "
          f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
