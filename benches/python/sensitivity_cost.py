"""Cost of the exact Jacobian of the discrete flow (issue 26): the run with sensitivity=True
against the plain run of the same method and step, for the rigid body with attitude
(splitting4; directions: 6 state + 3 moments), the heavy top (splitting4; 6 + 7), the
pseudo-rigid body n = 3 (verlet4, SVK + volumetric; 18 + 4), the incompressible one (rattle4: the
constrained lift, 18 + 4) and the pendulum with the implicit Gauss method (gauss6, through the
implicit-function theorem: one LU per step for all directions; 2 + 0). The lift carries k
directions, so the ideal factor is 1 + k. Then the free body with attitude under the methods
that differentiate their own implicit equations or group operations (exact, rkmk4, dmv, dmv8,
lgvi, isospectral), the heavy top's exact splitting, the pseudo-rigid body's reduced flows, the
rolling disks and the tangent top on the sphere (gauss4). Wall time is the best of 5 calls of 2000 steps (save_every = steps).

    python benches/python/sensitivity_cost.py
"""

import numpy as np

import lieflow as lf
from timing import best_time, environment

STEPS = 2000
SPIN = 2.0 * np.array([[0.0, 1.0, 0.5], [-1.0, 0.0, 0.8], [-0.5, -0.8, 0.0]])


def cases():
    R0 = lf.lie.so3_exp([0.4, -0.7, 0.3])
    rb = lf.RigidBody([1.0, 2.0, 3.0])
    ht = lf.HeavyTop([1.0, 2.0, 3.0], 0.7, chi=[0.2, -0.3, 1.0])
    prb = lf.PseudoRigidBody(3, lf.potentials.SaintVenantKirchhoff(1.0, 2.0)
                             + lf.potentials.Volumetric(0.5, 1.4))
    X = np.diag([1.3, 1.1, 0.9])
    P = np.array([[0.1, -0.5, 0.2], [0.6, 0.05, -0.3], [-0.1, 0.4, 0.02]])
    inc = lf.PseudoRigidBody(3, lf.potentials.SaintVenantKirchhoff(1.0, 2.0)
                             + lf.potentials.Volumetric(0.5, 1.4), incompressible=True)
    C = np.linalg.det(X) * np.linalg.inv(X).T
    P_inc = P - np.sum(C * P) / np.sum(C * C) * C      # on T*{det X = det X0}
    return [
        ("RigidBody with attitude", rb, np.array([0.3, -0.8, 1.1]), R0, "splitting4", 6 + 3),
        ("HeavyTop", ht, np.array([1.0, 0.5, -0.3, 0.0, 0.6, 0.8]), None, "splitting4", 6 + 7),
        ("PseudoRigidBody n = 3", prb, np.concatenate([X.ravel(), P.ravel()]), None, "verlet4",
         18 + 4),
        ("PseudoRigidBody incompr.", inc, np.concatenate([X.ravel(), P_inc.ravel()]), None,
         "rattle4", 18 + 4),
        ("Pendulum", lf.Pendulum(1.0, 1.0, 9.81), np.array([1.0, 0.3]), None, "gauss6", 2),
    ] + [
        # The methods of no kind (own tangent steppers) and the Lie-group methods (the group-field
        # lift), on the free body with attitude; the heavy top's exact splitting.
        ("RigidBody with attitude", rb, np.array([0.3, -0.8, 1.1]), R0, m, 6 + 3)
        for m in ["exact", "rkmk4", "dmv", "dmv8", "lgvi", "isospectral"]
    ] + [
        ("HeavyTop", ht, np.array([1.0, 0.5, -0.3, 0.0, 0.6, 0.8]), None, "exact_splitting4",
         6 + 7),
        # A spinning body (P = W X, W skew): the semi-axes stay apart (the reduced coordinates
        # need distinct a_i).
        ("PseudoRigidBody n = 3", prb, np.concatenate([np.diag([1.6, 1.1, 0.7]).ravel(),
                                                       (SPIN @ np.diag([1.6, 1.1, 0.7])).ravel()]),
         None, "reduced", 18 + 4),
        ("RollingDisks", lf.RollingDisks(1.0, 0.7, 0.3 + 0.1j, [-0.2, 0.25], 1.0, 1.5, 0.8, 0.6),
         np.array([0.1, 0.2, 0.5, -0.3]), None, "gauss4", 4 + 7),
        ("TangentTop on the sphere", lf.TangentTop(lf.surfaces.Sphere(1.0), 1.0, 0.5),
         np.array([0.3, 0.2, 0.1, 0.4, -0.2, 0.3]), None, "gauss4", 6 + 2),
    ]


def main():
    print(environment())
    print(f"{'system':26s} {'method':11s} {'plain':>10s} {'Jacobian':>10s} {'factor':>7s} "
          f"{'1 + k':>6s}")
    for name, system, z0, att, method, k in cases():
        def run(sensitivity):
            return lf.integrate(system, z0, 0.01, STEPS, method=method, attitude=att,
                                save_every=STEPS, sensitivity=sensitivity)
        plain, _ = best_time(lambda: run(False), repeats=5)
        tangent, traj = best_time(lambda: run(True), repeats=5)
        assert traj.final_jacobian is not None
        print(f"{name:26s} {method:11s} {plain * 1e3:8.2f}ms {tangent * 1e3:8.2f}ms "
              f"{tangent / plain:7.1f} {1 + k:6d}")


if __name__ == "__main__":
    main()
