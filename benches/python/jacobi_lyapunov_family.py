"""The first Lyapunov family of a stable Jacobi ellipsoid (issue 27): docs/jacobi_lyapunov_family.png.

The Jacobi figure a2/a1 = 0.6 (G = rho = 1) as a relative equilibrium of the incompressible
self-gravitating body; its slowest normal mode (`RelativeEquilibrium.normal_modes()`) starts a
family of relative periodic orbits (`periodic_orbit.from_mode`, amplitude 1e-3, rattle6 at 100
steps per period), followed by `continuation.periodic_family`. Left: the period against the
energy (stable solid); right: the arguments of the normal multipliers along the family, which
start at ±ω_k T of the other modes and stay on the unit circle (their moduli are printed).

    python benches/python/jacobi_lyapunov_family.py [--figure docs/jacobi_lyapunov_family.png]
"""

import sys
import time

import numpy as np

import lieflow as lf


def main():
    jacobi = lf.ellipsoids.jacobi(0.6)
    modes = jacobi.normal_modes()
    print("normal modes:", ", ".join(f"{m.frequency:.6f}" for m in modes))
    t0 = time.perf_counter()
    start = lf.periodic_orbit.from_mode(jacobi, 0, 1e-3, method="rattle6",
                                        dt=modes[0].period / 100)
    branch = lf.continuation.periodic_family(jacobi.body, start, max_points=40)
    seconds = time.perf_counter() - t0
    print(f"{branch} in {seconds:.0f} s")
    for sp in branch.special_points:
        print(" ", sp, np.round(sp.orbit.normal_multipliers, 5))
    worst = max(np.abs(np.abs(o.normal_multipliers) - 1).max() for o in branch.points)
    print(f"max | |mu| - 1 | of the normal multipliers along the branch: {worst:.1e}; stable: "
          f"{branch.stable.all()}")
    print(f"energy {branch.energies[0]:.6f} .. {branch.energies.max():.6f}, period "
          f"{branch.periods.min():.6f} .. {branch.periods.max():.6f}")
    if "--figure" in sys.argv:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
        branch.plot(a, x="energy", y="period")
        a.set_title("Lyapunov family of the Jacobi ellipsoid $a_2/a_1 = 0.6$")
        e = branch.energies
        for o, ek in zip(branch.points, e):
            args = np.angle(o.normal_multipliers)
            up = args[args > 0]
            b.plot(np.full(up.shape, ek), up, ".", color="C1", ms=4)
        b.set_xlabel("energy")
        b.set_ylabel(r"arg $\mu$ of the normal multipliers (upper half)")
        b.set_title(r"Floquet multipliers: $|\mu| = 1$ " + f"to {worst:.0e}")
        fig.tight_layout()
        path = sys.argv[sys.argv.index("--figure") + 1]
        fig.savefig(path, dpi=110)
        print("wrote", path)


if __name__ == "__main__":
    main()
