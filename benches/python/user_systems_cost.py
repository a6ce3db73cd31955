"""Cost per step of user-defined systems from Python callables against the native paths
(issue 15): the rigid body as lf.RigidBody, as lf.LiePoisson("so3", matrix) (native quadratic)
and from callables; the pendulum as lf.Pendulum, lf.Separable and lf.Canonical.

    cd benches/python && python user_systems_cost.py
"""

import numpy as np

import lieflow as lf
from timing import best_time, environment

I = np.array([1.0, 2.0, 3.0])
M0 = np.array([1.0, 0.5, -0.3])


def h_rb(m):
    return 0.5 * float(m @ (m / I))


def dh_rb(m):
    return m / I


def u_pend(q):
    return -9.81 * float(np.cos(q[0]))


def du_pend(q):
    return np.array([9.81 * np.sin(q[0])])


def h_pend(q, p):
    return 0.5 * float(p[0] ** 2) + u_pend(q)


def grad_pend(q, p):
    return np.array([du_pend(q), p])


def main():
    print(environment())
    cases = [
        ("rigid body", "lf.RigidBody(I)", lf.RigidBody(I), M0, ["rkmk4", "splitting"]),
        ("rigid body", 'lf.LiePoisson("so3", diag(1/I))', lf.LiePoisson("so3", np.diag(1 / I)),
         M0, ["rkmk4", "midpoint4"]),
        ("rigid body", 'lf.LiePoisson("so3", H, dH)', lf.LiePoisson("so3", h_rb, dh_rb), M0,
         ["rkmk4", "midpoint", "midpoint4"]),
        ("rigid body", 'lf.LiePoisson("so3", H) (finite differences)', lf.LiePoisson("so3", h_rb),
         M0, ["rkmk4"]),
        ("pendulum", "lf.Pendulum()", lf.Pendulum(), [0.5, 0.0], ["verlet", "gauss4"]),
        ("pendulum", "lf.Separable(1.0, U, dU, dof=1)", lf.Separable(1.0, u_pend, du_pend, dof=1),
         [0.5, 0.0], ["verlet", "gauss4"]),
        ("pendulum", "lf.Canonical(H, grad, dof=1)", lf.Canonical(h_pend, grad_pend, 1),
         [0.5, 0.0], ["gauss4"]),
        ("pendulum", "lf.Canonical(H, dof=1) (finite differences)", lf.Canonical(h_pend, None, 1),
         [0.5, 0.0], ["gauss4"]),
    ]
    print(f"{'system':11s} {'constructed as':46s} {'method':10s} {'us/step':>8s}")
    for name, how, sys, z0, methods in cases:
        for m in methods:
            steps = 20_000 if "finite" not in how and "H" not in how else 2_000
            sec, _ = best_time(lambda: lf.integrate(sys, z0, dt=0.01, steps=steps, method=m,
                                                    save_every=steps), repeats=3)
            print(f"{name:11s} {how:46s} {m:10s} {sec / steps * 1e6:8.2f}")


if __name__ == "__main__":
    main()
