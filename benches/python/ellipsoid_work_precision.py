"""Work–precision of the incompressible self-gravitating fluid ellipsoid
(`lf.PseudoRigidBody(3, lf.potentials.SelfGravity(), incompressible=True)`): lieflow's RATTLE
methods (rattle, rattle4, rattle6; symplectic on T*{det X = det X0}) against scipy's solve_ivp
(DOP853, RK45) on the index-1 ODE of the same motion.

Problems (T = 20 periods of the Jacobi ellipsoid j = lf.ellipsoids.jacobi(0.6), 2 pi / Omega):

* (a) the Jacobi ellipsoid itself, a relative equilibrium: (X0, P0) = j.motion(0); the reference
  is the exact motion X(t) = exp(t xi) A0 from `j.motion(t)`;
* (b) a random perturbation of it (seed 1): X0 = A0 + 0.1 N, rescaled to det X0 = det A0,
  P0 = body.project_momentum(X0, P_J + 0.1 N'); the reference is rattle6 at T/64000 (checked
  against T/32000).

Rivals' right-hand side (written here, checked before timing): X' = P, P' = -dU/dX + p cof X with
dU/dX = `SelfGravity().gradient(X)` and the pressure chosen so that d^2/dt^2 det X = 0:
d/dt det X = <cof X, P>, d^2/dt^2 det X = <D cof(X)[P], P> + <cof X, P'> with
<D cof(X)[P], P> = det X (tr(M)^2 - tr(M^2)), M = X^-1 P, so

    p = (<cof X, dU/dX> - det X (tr(M)^2 - tr(M^2))) / |cof X|^2.

It does not keep det X: its drift is reported. The RHS is scalar Python (`cof` by cofactors,
≈ 5 µs a call including the ≈ 1.9 µs lieflow gradient) and is checked against the exact Jacobi
motion (P' = xi P - P eta, p = j.pressure) and, at the perturbed state, by a finite difference of
det along X + hP + h^2/2 P'.

Error = max over the saved samples (10 per period, 201 in all) of ||X(t) - X_ref(t)||_F;
det error = max |det X / det X0 - 1|, energy error = max |H - H0| over the same samples (scipy:
`t_eval` at the same times, i.e. its dense output). Wall time is the best of >= 5 repeats (more
for fast runs, up to ~0.1 s per point) of `lf.integrate(body, (X0, P0), dt, steps, method,
save_every=n/10)` and of `solve_ivp(f, (0, T), y0, method, rtol=tol, atol=tol/100, t_eval=...)`.

    python benches/python/ellipsoid_work_precision.py [--figure docs/ellipsoid_work_precision.png]
"""

import argparse
import os
import time

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time, environment, print_ratios

PERIODS = 20
SAMPLES = 10            # saved samples per period
BUDGET = 0.1
REPEATS = 5             # best of at least this many calls per point
STEPS = {"rattle": [40, 80, 160, 320, 640, 1280, 2560],     # steps per period
         "rattle4": [20, 40, 80, 160, 320, 640],
         "rattle6": [20, 40, 80, 160, 320, 640]}
RTOLS = {"DOP853": [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13],
         "RK45": [1e-4, 1e-5, 1e-6, 1e-7, 1e-8]}
REF_STEPS = 3200        # rattle6 steps per period for the reference of (b)

GRAVITY = lf.potentials.SelfGravity()
_grad = GRAVITY.gradient


def rhs(t, y):
    """X' = P, P' = -dU/dX + p cof X with d^2/dt^2 det X = 0 (module docs); y = (X, P) row-major."""
    (x11, x12, x13, x21, x22, x23, x31, x32, x33,
     p11, p12, p13, p21, p22, p23, p31, p32, p33) = y.tolist()
    g11, g12, g13, g21, g22, g23, g31, g32, g33 = _grad(y[:9].reshape(3, 3)).ravel().tolist()
    # cofactors: c_ij of x_ij, cof X = C = det(X) X^-T, X^-1 = C^T / det
    c11 = x22 * x33 - x23 * x32
    c12 = x23 * x31 - x21 * x33
    c13 = x21 * x32 - x22 * x31
    c21 = x13 * x32 - x12 * x33
    c22 = x11 * x33 - x13 * x31
    c23 = x12 * x31 - x11 * x32
    c31 = x12 * x23 - x13 * x22
    c32 = x13 * x21 - x11 * x23
    c33 = x11 * x22 - x12 * x21
    d = x11 * c11 + x12 * c12 + x13 * c13
    # N = det(X) M = C^T P
    n11 = c11 * p11 + c21 * p21 + c31 * p31
    n12 = c11 * p12 + c21 * p22 + c31 * p32
    n13 = c11 * p13 + c21 * p23 + c31 * p33
    n21 = c12 * p11 + c22 * p21 + c32 * p31
    n22 = c12 * p12 + c22 * p22 + c32 * p32
    n23 = c12 * p13 + c22 * p23 + c32 * p33
    n31 = c13 * p11 + c23 * p21 + c33 * p31
    n32 = c13 * p12 + c23 * p22 + c33 * p32
    n33 = c13 * p13 + c23 * p23 + c33 * p33
    tr = n11 + n22 + n33
    tr2 = n11 * n11 + n22 * n22 + n33 * n33 + 2.0 * (n12 * n21 + n13 * n31 + n23 * n32)
    cg = (c11 * g11 + c12 * g12 + c13 * g13 + c21 * g21 + c22 * g22 + c23 * g23
          + c31 * g31 + c32 * g32 + c33 * g33)
    cc = (c11 * c11 + c12 * c12 + c13 * c13 + c21 * c21 + c22 * c22 + c23 * c23
          + c31 * c31 + c32 * c32 + c33 * c33)
    p = (cg - (tr * tr - tr2) / d) / cc
    return [p11, p12, p13, p21, p22, p23, p31, p32, p33,
            p * c11 - g11, p * c12 - g12, p * c13 - g13,
            p * c21 - g21, p * c22 - g22, p * c23 - g23,
            p * c31 - g31, p * c32 - g32, p * c33 - g33]


def check_rhs(j, y_pert):
    """The RHS against the exact Jacobi motion, and d^2/dt^2 det X = 0 at the perturbed state."""
    X, P = (a[0] for a in j.motion(np.array([0.0])))
    dy = np.array(rhs(0.0, np.concatenate((X.ravel(), P.ravel()))))
    exact = j.xi @ P - P @ j.eta
    e1 = np.abs(dy[9:].reshape(3, 3) - exact).max()
    # pressure from the residual: P' + grad U = p cof X
    cof = np.linalg.det(X) * np.linalg.inv(X).T
    p = np.sum((dy[9:].reshape(3, 3) + GRAVITY.gradient(X)) * cof) / np.sum(cof * cof)
    e2 = abs(p - j.pressure)
    Xp, Pp = y_pert[:9].reshape(3, 3), y_pert[9:].reshape(3, 3)
    Fp = np.array(rhs(0.0, y_pert))[9:].reshape(3, 3)
    h = 1e-3
    phi = [np.linalg.det(Xp + s * h * Pp + 0.5 * (s * h) ** 2 * Fp) for s in (-1, 0, 1)]
    dd = (phi[0] - 2 * phi[1] + phi[2]) / h ** 2
    d1 = np.linalg.det(Xp) * np.trace(np.linalg.solve(Xp, Pp))
    print(f"  RHS check: |P' - (xi P - P eta)| = {e1:.1e}, |p - j.pressure| = {e2:.1e} "
          f"(p = {j.pressure:.6f}); perturbed state: d^2/dt^2 det X by finite differences "
          f"(h = 1e-3) = {dd:.1e}, d/dt det X = <cof X, P> = {d1:.1e}")
    assert e1 < 1e-12 and e2 < 1e-12 and abs(dd) < 1e-5, (e1, e2, dd)


def measures(body, states, X_ref, h0, det0):
    X = states[:, :9].reshape(-1, 3, 3)
    err = np.linalg.norm(X - X_ref, axis=(1, 2)).max()
    ddet = np.abs(np.linalg.det(X) / det0 - 1.0).max()
    de = np.abs(body.energy(states) - h0).max()
    return err, ddet, de


def run(title, body, X0, P0, period, reference):
    """Every method on one problem; `reference(t)` -> X_ref (k, 3, 3) at the sample times."""
    T = PERIODS * period
    print(f"\n{title}, T = {PERIODS} periods = {T:.6g}")
    z0 = np.concatenate((X0.ravel(), P0.ravel()))
    h0, det0 = body.energy(z0), np.linalg.det(X0)
    t_samples = np.arange(PERIODS * SAMPLES + 1) * (period / SAMPLES)
    X_ref = reference(t_samples)
    rows = []
    for method, steps_list in STEPS.items():
        for n in steps_list:
            dt, steps = period / n, PERIODS * n
            sec, tr = best_time(lambda: lf.integrate(body, (X0, P0), dt=dt, steps=steps,
                                                     method=method, save_every=n // SAMPLES),
                                repeats=REPEATS, budget=BUDGET)
            assert np.allclose(tr.t, t_samples, rtol=0, atol=1e-9 * T)
            err, ddet, de = measures(body, tr.states, X_ref, h0, det0)
            rows.append(dict(name=f"lieflow {method}", setting=f"n/period={n}", sec=sec,
                             err=err, ddet=ddet, de=de))
    for method, tols in RTOLS.items():
        for tol in tols:
            sec, sol = best_time(lambda: solve_ivp(rhs, (0, T), z0, method=method, rtol=tol,
                                                   atol=tol * 1e-2, t_eval=t_samples),
                                 repeats=REPEATS, budget=BUDGET)
            err, ddet, de = measures(body, sol.y.T, X_ref, h0, det0)
            rows.append(dict(name=f"scipy {method}", setting=f"rtol={tol:.0e}", sec=sec,
                             err=err, ddet=ddet, de=de, nfev=sol.nfev))
            if method == "DOP853" and tol == 1e-10:
                drift = np.abs(np.linalg.det(sol.y[:9].T.reshape(-1, 3, 3)) / det0 - 1.0)
                growth = ", ".join(f"{drift[:k * SAMPLES + 1].max():.1e} (t <= {k} periods)"
                                   for k in (1, 2, 5, 10, 20))
    print(f"  {'method':17s} {'setting':14s} {'time [ms]':>10s} {'max|X-Xref|':>11s} "
          f"{'det drift':>10s} {'max|H-H0|':>10s}")
    for r in rows:
        extra = f"  ({r['nfev']} evaluations)" if "nfev" in r else ""
        print(f"  {r['name']:17s} {r['setting']:14s} {r['sec'] * 1e3:10.3f} {r['err']:11.2e} "
              f"{r['ddet']:10.2e} {r['de']:10.2e}{extra}")
    print(f"  DOP853 rtol=1e-10, max det drift over [0, t]: {growth}")
    points = {}
    for r in rows:
        points.setdefault(r["name"], []).append((r["err"], r["sec"]))
    print_ratios(points, [1e-4, 1e-6, 1e-8, 1e-10], width=17)
    return rows


def figure(path, results):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    styles = {"lieflow rattle": "o-", "lieflow rattle4": "s-", "lieflow rattle6": "D-",
              "scipy DOP853": "^--", "scipy RK45": "v--"}
    for ax, (title, rows) in zip(axes[:2], results):
        for name, style in styles.items():
            pts = [(r["sec"], r["err"]) for r in rows if r["name"] == name]
            ax.loglog([p[0] * 1e3 for p in pts], [p[1] for p in pts], style, label=name, ms=4)
        ax.set(xlabel="wall time [ms] (best of >= 5)", ylabel="max_t ||X - X_ref||_F",
               title=title)
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=8)
    ax = axes[2]
    for name, style in styles.items():
        pts = [(r["err"], max(r["ddet"], 1e-17)) for r in results[0][1] if r["name"] == name]
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, label=name, ms=4)
    ax.set(xlabel="max_t ||X - X_ref||_F", ylabel="max_t |det X / det X0 - 1|",
           title="(a) Jacobi: volume drift against accuracy")
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8)
    fig.suptitle(f"incompressible self-gravitating ellipsoid, Jacobi a2/a1 = 0.6, "
                 f"T = {PERIODS} periods")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print("figure:", path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--figure", default=None, help="write a PNG here")
    args = ap.parse_args()
    t_start = time.perf_counter()
    print(environment())
    body = lf.PseudoRigidBody(3, GRAVITY, incompressible=True)
    j = lf.ellipsoids.jacobi(0.6)
    period = 2 * np.pi / j.Omega
    print(f"Jacobi ellipsoid a = {np.round(j.a, 6).tolist()}, Omega = {j.Omega:.6f}, "
          f"period = {period:.6f}, pressure = {j.pressure:.6f}; methods {body.methods()}")
    XJ, PJ = (a[0] for a in j.motion(np.array([0.0])))

    rng = np.random.default_rng(1)
    Xp = XJ + 0.1 * rng.standard_normal((3, 3))
    Xp *= (np.linalg.det(XJ) / np.linalg.det(Xp)) ** (1 / 3)
    Pp = body.project_momentum(Xp, PJ + 0.1 * rng.standard_normal((3, 3)))
    check_rhs(j, np.concatenate((Xp.ravel(), Pp.ravel())))

    results = []
    rows = run("(a) Jacobi ellipsoid a2/a1 = 0.6 (exact reference)", body, XJ, PJ, period,
               lambda t: j.motion(t)[0])
    results.append(("(a) Jacobi ellipsoid (exact reference)", rows))

    def ref_pert(t):
        out = []
        for n in (REF_STEPS // 2, REF_STEPS):
            tr = lf.integrate(body, (Xp, Pp), dt=period / n, steps=PERIODS * n,
                              method="rattle6", save_every=n // SAMPLES)
            out.append(tr.states[:, :9].reshape(-1, 3, 3))
        gap = np.linalg.norm(out[0] - out[1], axis=(1, 2)).max()
        print(f"  reference rattle6 at {REF_STEPS // 2} vs {REF_STEPS} steps per period: "
              f"max ||dX||_F = {gap:.1e}")
        return out[1]

    rows = run("(b) perturbed Jacobi state (reference rattle6, period/3200)", body, Xp, Pp,
               period, ref_pert)
    results.append(("(b) perturbed Jacobi state (rattle6 reference)", rows))
    if args.figure:
        figure(args.figure, results)
    print(f"\ntotal {time.perf_counter() - t_start:.0f} s, "
          f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
