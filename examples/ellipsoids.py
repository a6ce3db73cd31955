"""The Maclaurin–Jacobi bifurcation diagram
========================================

The Maclaurin–Jacobi bifurcation diagram of self-gravitating fluid ellipsoids, computed by
continuation of the relative equilibria of the incompressible pseudo-rigid body (001 §8; EFE
ch. 5–6): start on the Maclaurin sequence, locate where the Jacobi family branches off and where
the spheroids lose spectral stability, switch onto the Jacobi branch and follow it.

Run it with (``--figure`` alone draws the figure, a path saves it)::

    python examples/ellipsoids.py [--figure [docs/ellipsoids.png]]
"""

import sys
import time

import numpy as np

import lieflow as lf


def main():
    t0 = time.perf_counter()
    mac = lf.continuation.follow(lf.ellipsoids.maclaurin(0.05), "e", 0.995)
    t1 = time.perf_counter()
    branch = next(s for s in mac.special_points if s.kind == "branch")
    jac = mac.switch(branch, stop=0.995)
    t2 = time.perf_counter()
    print(f"Maclaurin branch: {len(mac)} points in {t1 - t0:.2f} s; Jacobi branch: {len(jac)} "
          f"points in {t2 - t1:.2f} s (both with the two stability verdicts at every point)")
    for name, b in (("Maclaurin", mac), ("Jacobi", jac)):
        for s in b.special_points:
            what = s.kind if s.verdict is None else f"{s.kind} ({s.verdict} -> {s.stable})"
            print(f"  {name}: {what:42s} e = {s.e:.10f}  Omega^2/(pi G rho) = "
                  f"{s.Omega2_over_piGrho:.8f}  L = {s.L:.6f}  a2/a1 = {s.a2_over_a1:.6f}  "
                  f"a3/a1 = {s.a3_over_a1:.6f}")
    bif = lf.ellipsoids.maclaurin_jacobi_bifurcation()
    print(f"closed route (a1^4 A11 = a3^2 A3): e = {bif.e:.12f}, "
          f"Omega^2/(pi G rho) = {bif.Omega2_over_piGrho:.10f}, a = {bif.a}")
    print(f"Jacobi branch stable everywhere (spectral): {bool(jac.stability.all())}")
    if "--figure" not in sys.argv:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = (sys.argv[sys.argv.index("--figure") + 1:] or [None])[0]  # None: only draw
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.3))
    for ax, x in zip(axes, ("e", "L")):
        mac.plot(ax, x=x, label="Maclaurin spheroids", color="C0")
        jac.plot(ax, x=x, label="Jacobi ellipsoids", color="C1")
        ax.grid(alpha=0.3)
    axes[0].set_xlim(0, 1)
    axes[1].set_xlim(0, 1.0)
    axes[0].legend(loc="upper left", fontsize=8, title="solid: spectrally stable\ndashed: unstable",
                   title_fontsize=8)
    sp = next(s for s in mac.special_points if s.kind == "stability" and s.verdict == "spectral")
    axes[0].annotate(f"branch point\ne = {branch.e:.5f}", (branch.e, branch.Omega2_over_piGrho),
                     (0.45, 0.40), fontsize=8, arrowprops=dict(arrowstyle="->", lw=0.6))
    axes[0].annotate(f"spectral instability\ne = {sp.e:.5f}", (sp.e, sp.Omega2_over_piGrho),
                     (0.55, 0.22), fontsize=8, arrowprops=dict(arrowstyle="->", lw=0.6))
    fig.suptitle("Self-gravitating fluid ellipsoids: relative equilibria of the incompressible "
                 "pseudo-rigid body, by continuation")
    fig.tight_layout()
    if path:  # the docs gallery draws the figure without saving it
        fig.savefig(path, dpi=120)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
