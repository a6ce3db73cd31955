"""Work–precision of lf.EulerPoincare (issue 24): the discrete Euler–Poincaré method and the
Lie–Poisson methods against scipy's DOP853 on the Euler–Poincaré equations written out in
numpy, and the native quadratic path's cost per step against the built-in RigidBody's lgvi.

1. The free rigid body from l = <Omega, I Omega>/2 with its attitude (the native path), T = 20,
   error of (M, R) against the exact solution (lf.RigidBody "exact").
2. The quartic l = <Omega, I Omega>/2 + (c/4)|Omega|^4 (Python callables: l, gradient,
   Hessian), T = 10, error of mu against DOP853 at rtol 1e-14; scipy solves
   (I + c(|w|^2 1 + 2 w w^T)) dw/dt = mu x w.

    python benches/python/euler_poincare_work_precision.py
"""

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time, environment, print_ratios

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])
R0 = lf.lie.so3_exp([0.2, -0.35, 0.56])
C = 0.4


def rigid_rhs(_, z):
    m, r = z[:3], z[3:].reshape(3, 3)
    w = m / I
    return np.concatenate([np.cross(m, w), (r @ lf.lie.so3_hat(w)).ravel()])


def quartic(w):
    n2 = float(w @ w)
    return 0.5 * float(w @ (I * w)) + 0.25 * C * n2 * n2


def quartic_grad(w):
    return I * w + C * float(w @ w) * w


def quartic_hess(w):
    return np.diag(I) + C * (float(w @ w) * np.eye(3) + 2 * np.outer(w, w))


def quartic_rhs(_, w):
    return np.linalg.solve(quartic_hess(w), np.cross(quartic_grad(w), w))


def run_methods(system, z0, t, steps_of, attitude=None):
    points = {}
    for method, steps in steps_of.items():
        pts = []
        for n in steps:
            secs, traj = best_time(lambda: lf.integrate(system, z0, dt=t / n, steps=n,
                                                        method=method, save_every=n,
                                                        attitude=attitude))
            pts.append((traj, secs))
        points[f"lieflow {method}"] = pts
    return points


def scipy_points(rhs, y0, t, error):
    pts = []
    for rtol in (1e-5, 1e-7, 1e-9, 1e-11, 1e-13):
        secs, sol = best_time(lambda: solve_ivp(rhs, (0, t), y0, method="DOP853", rtol=rtol,
                                                atol=rtol * 1e-2))
        pts.append((error(sol.y[:, -1]), secs))
    return pts


def show(points, targets):
    for label, pts in points.items():
        print(f"  {label:22s} " + "  ".join(f"{e:.1e}/{s * 1e3:.1f}ms" for e, s in pts))
    print_ratios(points, targets, width=22)


def rigid_body():
    t = 20.0
    print(f"\n1. free rigid body from l = <Omega, I Omega>/2 with its attitude, T = {t:g}")
    ep = lf.EulerPoincare("so3", inertia=np.diag(I))
    exact = lf.integrate(lf.RigidBody(I), M0, dt=t, steps=1, method="exact", attitude=R0)
    want = np.concatenate([exact.states[-1], exact.attitude[-1].ravel()])

    def error(z):
        return float(np.linalg.norm(z - want))

    steps = {"variational": (1000, 2000, 4000, 8000, 16000, 32000),
             "variational4": (200, 400, 800, 1600, 3200),
             "variational6": (100, 200, 400, 800, 1600),
             "rkmk4": (200, 400, 800, 1600, 3200)}
    points = {k: [(error(np.concatenate([tr.states[-1], tr.attitude[-1].ravel()])), s)
                  for tr, s in v]
              for k, v in run_methods(ep, M0, t, steps, attitude=R0).items()}
    points["scipy DOP853"] = scipy_points(rigid_rhs, np.concatenate([M0, R0.ravel()]), t,
                                          error)
    show(points, (1e-6, 1e-9))


def quartic_case():
    t = 10.0
    print(f"\n2. quartic l = <Omega, I Omega>/2 + (c/4)|Omega|^4 (Python callables), T = {t:g}")
    ep = lf.EulerPoincare("so3", quartic, gradient=quartic_grad, hessian=quartic_hess)
    w0 = np.array([0.8, -0.4, 0.3])
    mu0 = ep.state(w0)
    ref = solve_ivp(quartic_rhs, (0, t), w0, method="DOP853", rtol=1e-14, atol=1e-15).y[:, -1]
    want = quartic_grad(ref)
    steps = {"variational": (250, 500, 1000, 2000),
             "variational6": (50, 100, 200, 400),
             "rkmk4": (100, 200, 400, 800)}
    points = {k: [(float(np.linalg.norm(tr.states[-1] - want)), s) for tr, s in v]
              for k, v in run_methods(ep, mu0, t, steps).items()}
    points["scipy DOP853"] = scipy_points(quartic_rhs, w0, t,
                                          lambda w: float(np.linalg.norm(quartic_grad(w) - want)))
    show(points, (1e-6, 1e-9))


def per_step():
    n = 100_000
    print(f"\n3. cost per step, {n} steps with the attitude (dt = 0.01), best of 5")
    ep = lf.EulerPoincare("so3", inertia=np.diag(I))
    body = lf.RigidBody(I)
    rows = {}
    for label, system, method in (("EulerPoincare variational", ep, "variational"),
                                  ("RigidBody lgvi", body, "lgvi"),
                                  ("EulerPoincare rkmk4", ep, "rkmk4"),
                                  ("RigidBody rkmk4", body, "rkmk4")):
        secs, _ = best_time(lambda: lf.integrate(system, M0, dt=0.01, steps=n, method=method,
                                                 save_every=n, attitude=R0), repeats=5)
        rows[label] = secs / n
        print(f"  {label:28s} {secs / n * 1e9:7.1f} ns/step")
    print(f"  variational / lgvi = {rows['EulerPoincare variational'] / rows['RigidBody lgvi']:.2f}")


if __name__ == "__main__":
    print(environment())
    rigid_body()
    quartic_case()
    per_step()
