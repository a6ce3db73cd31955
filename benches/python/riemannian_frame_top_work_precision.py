"""Work–precision of the tangent Euler top on a Riemannian chart (002 §V for a general metric,
`lf.FrameTop(lf.spaces.Riemannian(metric, frame), m, I)`): lieflow's methods (midpoint,
midpoint4, midpoint6, rkmk4, rk4) against scipy's DOP853 on the same equations written out by
hand in closed form.

Problem: S^3 of radius r = 1.3 in the stereographic chart from its south pole, g = lambda^2 1 with
lambda = 2r/(1 + |y|^2), the frame E_a = lambda^-1 d/dy_a, given to lieflow as Python callables
(lieflow finds the connection and its derivatives by differences). m = 1.3, I = diag(2, 3.1, 4.2),
y0 = (0.3, -0.2, 0.5), ydot0 = (0.4, 0.1, -0.3), R0 = so3_exp(0.4, -0.7, 0.3),
omega0 = (0.7, -0.4, 1.1), T = 2.

DOP853 integrates what a user would write for this chart without lieflow, derived by hand: for a
conformal frame the connection matrix is C = hat(grad phi), phi = log lambda (so C and its
derivatives in closed form), x' = u = g^-1 (p - C^T R Pi)/m, p'_k = m/2 u.(d_k g)u +
(R Pi).(d_k C)u, R' = R hat(omega) - hat(C u) R, Pi' = Pi x omega (numpy right-hand side, ~40 us
a call). The script checks it first against lieflow's field (one rk4 step each).

Reference: the same motion by FrameTop on Sphere(3, 1.3) with the exact flow, mapped through the
chart (error = max-norm of the chart position y(T) and of the frame R(T)). Wall time is the best
of >= 2 calls through lf.integrate; ratios are DOP853's time over the method's, interpolated
log-log to the same error in this run. Runs in about a minute.

    python benches/python/riemannian_frame_top_work_precision.py
"""

import time

import numpy as np
from scipy.integrate import solve_ivp

import lieflow as lf
from timing import best_time, environment, time_to

R3, MASS = 1.3, 1.3
MOMENTS = np.array([2.0, 3.1, 4.2])
Y0, YD0 = np.array([0.3, -0.2, 0.5]), np.array([0.4, 0.1, -0.3])
R0 = lf.lie.so3_exp([0.4, -0.7, 0.3])
W0 = np.array([0.7, -0.4, 1.1])
T = 2.0


def metric(y1, y2, y3):
    lam = 2 * R3 / (1 + y1 * y1 + y2 * y2 + y3 * y3)
    return lam * lam * np.eye(3)


def frame(y1, y2, y3):
    return (1 + y1 * y1 + y2 * y2 + y3 * y3) / (2 * R3) * np.eye(3)


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def rhs(t, z):
    y, p, R, pi = z[:3], z[3:6], z[6:15].reshape(3, 3), z[15:]
    s = y @ y
    lam = 2 * R3 / (1 + s)
    grad_phi = -2 * y / (1 + s)
    hess_phi = -2 * np.eye(3) / (1 + s) + 4 * np.outer(y, y) / (1 + s) ** 2
    C = hat(grad_phi)
    sigma = R @ pi
    u = (p - C.T @ sigma) / (MASS * lam * lam)
    # d_k g = 2 lambda^2 d_k phi 1; d_k C = hat(d_k grad phi).
    pdot = np.array([MASS * lam * lam * grad_phi[k] * (u @ u) + sigma @ (hat(hess_phi[k]) @ u)
                     for k in range(3)])
    omega = pi / MOMENTS
    rdot = R @ hat(omega) - hat(C @ u) @ R
    return np.concatenate([u, pdot, rdot.ravel(), np.cross(pi, omega)])


def stereo(y):
    s = y @ y
    return R3 * np.concatenate([[(1 - s) / (1 + s)], 2 * y / (1 + s)])


def stereo_jacobian(y):
    s = y @ y
    d = (1 + s) ** 2
    return np.vstack([-4 * R3 * y / d, 2 * R3 * ((1 + s) * np.eye(3) - 2 * np.outer(y, y)) / d])


def reference():
    """(y(T), R(T)) from FrameTop on the sphere, exact, mapped back through the chart."""
    group = lf.FrameTop(lf.spaces.Sphere(3, radius=R3), MASS, MOMENTS)
    x0 = stereo(Y0)
    J = stereo_jacobian(Y0)
    axes = J @ frame(*Y0).T @ R0
    g0 = group.state(x0, group.space.reference_frame(x0).T @ axes, J @ YD0, W0)
    zT = lf.integrate(group, g0, dt=T, steps=1).final_state
    x = group.position(zT)
    y = x[1:] / (R3 + x[0])            # inverse stereographic projection
    axes_T = group.space.reference_frame(x) @ group.frame(zT)
    Jt = stereo_jacobian(y)
    # axes = J E R: R = E^-1 J^+ axes (J^+ the left inverse on the tangent space).
    R = np.linalg.inv(frame(*y).T) @ np.linalg.pinv(Jt) @ axes_T
    return y, R


def main():
    print(environment())
    top = lf.FrameTop(lf.spaces.Riemannian(metric, frame), MASS, MOMENTS)
    z0 = top.state(Y0, R0, YD0, W0)
    # The hand-written field against lieflow's (one rk4 step each).
    a = lf.integrate(top, z0, dt=0.01, steps=1, method="rk4").final_state
    k1 = rhs(0, z0)
    k2 = rhs(0, z0 + 0.005 * k1)
    k3 = rhs(0, z0 + 0.005 * k2)
    k4 = rhs(0, z0 + 0.01 * k3)
    b = z0 + 0.01 / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    print(f"check: hand-written field vs lieflow's, one rk4 step: {np.abs(a - b).max():.1e}")
    y_ref, r_ref = reference()

    def error(z):
        return max(np.abs(z[:3] - y_ref).max(), np.abs(z[6:15].reshape(3, 3) - r_ref).max())

    points = {}
    for method, counts in [("midpoint", [10, 20, 40, 80]), ("midpoint4", [5, 10, 20, 40]),
                           ("midpoint6", [8, 16, 32]), ("rkmk4", [10, 20, 40, 80]),
                           ("rk4", [10, 20, 40, 80])]:
        pts = []
        for n in counts:
            secs, traj = best_time(
                lambda: lf.integrate(top, z0, dt=T / n, steps=n, save_every=n, method=method),
                repeats=2)
            pts.append((error(traj.final_state), secs))
            print(f"{method:10s} n={n:4d}  error {pts[-1][0]:.2e}  {secs * 1e3:8.1f} ms")
        points[method] = pts
    pts = []
    for tol in [1e-6, 1e-8, 1e-10, 1e-12]:
        secs, sol = best_time(lambda: solve_ivp(rhs, (0, T), z0, method="DOP853", rtol=tol,
                                                atol=tol * 1e-3), repeats=2)
        pts.append((error(sol.y[:, -1]), secs))
        print(f"DOP853     rtol={tol:.0e}  error {pts[-1][0]:.2e}  {secs * 1e3:8.1f} ms "
              f"({sol.nfev} evaluations)")
    points["DOP853"] = pts
    print("\nDOP853 time / method time at the same error (log-log interpolation):")
    for target in [1e-6, 1e-8]:
        base = time_to(points["DOP853"], target)
        row = []
        for m in ("midpoint", "midpoint4", "midpoint6", "rkmk4", "rk4"):
            t = time_to(points[m], target)
            row.append(f"{m} {base / t:.2f}x" if base and t else f"{m} -")
        print(f"  error {target:.0e}: " + ", ".join(row))


if __name__ == "__main__":
    t0 = time.time()
    main()
    print(f"({time.time() - t0:.0f} s)")
