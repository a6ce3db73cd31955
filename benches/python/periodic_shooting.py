"""Cost and accuracy of one periodic-orbit solve (issue 27): lieflow's shooting on the method's own
map against the two routes a scipy user would take for the same orbit of the free rigid body
(I = (1, 2, 3), the orbit through M0 = (1, 0.3, 0.2), period guess 2 % off):

- scipy `least_squares` (Levenberg–Marquardt) on a DOP853 shooting (`solve_ivp`, rtol = atol =
  1e-12, dense output off), with lieflow's equations: M(T) − M0, energy, Casimir, phase;
- scipy `solve_bvp` on M' = T (f(M) + λ₁∇H + λ₂∇C), M(1) = M(0), H = E, C = C0, phase (the
  unfolding parameters λ vanish at a periodic orbit; tol 1e-10);

and the cost of a continued family (the Jacobi ellipsoid's first Lyapunov family, 20 orbits,
rattle6 at 100 steps per period). Errors are against the closed form 4K(k)/λ. Wall time is the
best of 5 calls.

    python benches/python/periodic_shooting.py
"""

import time

import numpy as np
from scipy.integrate import solve_bvp, solve_ivp
from scipy.optimize import least_squares

import lieflow as lf
from timing import best_time, environment

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.3, 0.2])


def closed_form(m):
    l2, e2 = m @ m, m @ (m / I)
    i1, i2, i3 = (I[0], I[1], I[2]) if l2 > e2 * I[1] else (I[2], I[1], I[0])
    lam = np.sqrt((i3 - i2) * (l2 - e2 * i1) / (i1 * i2 * i3))
    k2 = (i2 - i1) * (e2 * i3 - l2) / ((i3 - i2) * (l2 - e2 * i1))
    return 4 * lf.elliptic.ellipk(k2) / lam


def field(t, m):
    return np.cross(m, m / I)


EXACT = closed_form(M0)
GUESS = 1.02 * EXACT
E0, C0 = 0.5 * M0 @ (M0 / I), M0 @ M0
F0 = field(0, M0) / np.linalg.norm(field(0, M0))


def lieflow_solve(method, dt):
    body = lf.RigidBody(I)

    def run():
        return lf.periodic_orbit(body, M0, GUESS, method=method, dt=dt)
    return run


def scipy_shooting():
    def residual(u):
        m, t = u[:3], u[3]
        end = solve_ivp(field, (0, t), m, method="DOP853", rtol=1e-12, atol=1e-12).y[:, -1]
        return np.concatenate([end - m, [0.5 * m @ (m / I) - E0, m @ m - C0, (m - M0) @ F0]])

    def run():
        return least_squares(residual, np.concatenate([M0, [GUESS]]), method="lm", xtol=1e-14,
                             ftol=1e-14, gtol=1e-14)
    return run


def scipy_bvp():
    s = np.linspace(0, 1, 60)
    y0 = solve_ivp(field, (0, GUESS), M0, t_eval=s * GUESS, rtol=1e-10, atol=1e-12).y

    def f(s, y, p):
        t, l1, l2 = p
        m = y
        w = m / I[:, None]
        return t * (np.cross(m.T, w.T).T + l1 * w + l2 * 2 * m)

    def bc(ya, yb, p):
        return np.array([*(yb - ya), 0.5 * ya @ (ya / I) - E0, ya @ ya - C0, (ya - M0) @ F0])

    def run():
        return solve_bvp(f, bc, s, y0, p=[GUESS, 0.0, 0.0], tol=1e-10, max_nodes=100000)
    return run


def main():
    print(environment())
    print(f"free rigid body I = (1, 2, 3), M0 = (1, 0.3, 0.2): T = 4K(k)/λ = {EXACT:.15f}")
    print(f"{'solver':<46} {'period error':>13} {'closes to':>10} {'time':>10}")
    rows = []
    for name, method, dt in (("lieflow exact (8 steps)", "exact", 2.0),
                             ("lieflow dmv10 (dt 0.05, 222 steps)", "dmv10", 0.05),
                             ("lieflow splitting4 (dt 0.01)", "splitting4", 0.01)):
        t, o = best_time(lieflow_solve(method, dt), repeats=5)
        rows.append((name, abs(o.period - EXACT) / EXACT, o.residual, t))
    t, r = best_time(scipy_shooting(), repeats=5)
    end = solve_ivp(field, (0, r.x[3]), r.x[:3], method="DOP853", rtol=1e-12, atol=1e-12).y[:, -1]
    rows.append(("scipy least_squares on DOP853 (rtol 1e-12)", abs(r.x[3] - EXACT) / EXACT,
                 np.abs(end - r.x[:3]).max(), t))
    t, b = best_time(scipy_bvp(), repeats=5)
    rows.append((f"scipy solve_bvp (tol 1e-10, {b.x.size} nodes)", abs(b.p[0] - EXACT) / EXACT,
                 np.abs(b.y[:, -1] - b.y[:, 0]).max(), t))
    for name, err, close, t in rows:
        print(f"{name:<46} {err:13.1e} {close:10.1e} {t * 1e3:8.2f} ms")
    # A continued family: the Jacobi ellipsoid's first Lyapunov family.
    jacobi = lf.ellipsoids.jacobi(0.6)
    mode = jacobi.normal_modes()[0]
    t0 = time.perf_counter()
    start = lf.periodic_orbit.from_mode(jacobi, mode, 1e-3, method="rattle6", dt=mode.period / 100)
    t1 = time.perf_counter()
    branch = lf.continuation.periodic_family(jacobi.body, start, max_points=20)
    t2 = time.perf_counter()
    print(f"Jacobi a2/a1 = 0.6, mode ω = {mode.frequency:.6f}: first orbit {t1 - t0:.2f} s "
          f"({start.iterations} iterations), family of {len(branch)} orbits {t2 - t1:.1f} s "
          f"({(t2 - t1) / (len(branch) - 1):.2f} s per orbit), {branch}")


if __name__ == "__main__":
    main()
