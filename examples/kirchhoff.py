"""Kirchhoff's equations: a rigid body in an ideal fluid
=====================================================

Kirchhoff's equations for a rigid body in an ideal fluid, written as a user would: a
Lie–Poisson system on se(3)* with a quadratic Hamiltonian (docs/user_systems.md).

The body's impulse is (M, P) (angular, linear) and H = ½ (M·AM + P·BP) (A, B diagonal: the body's
added-mass tensors in its principal frame). Kirchhoff's equations Ṁ = M × Ω + P × V, Ṗ = P × Ω
with (Ω, V) = ∇H are the Lie–Poisson equations of se(3)*: `lf.LiePoisson("se3", H)` with H the
6×6 matrix diag(A, B) (the native quadratic path), fields M and Gamma (= P). Casimirs ‖P‖² and M·P.

Clebsch's integrable case: B_i = θ A₁A₂A₃/A_i + c (i.e. (B₂ − B₃)/A₁ + (B₃ − B₁)/A₂ +
(B₁ − B₂)/A₃ = 0); its extra integral is F = ½‖M‖² − ½θ Σ A_i P_i². No method keeps F exactly:
the Lie midpoint (symmetric) keeps its error bounded, RKMK4 and RK4 let it drift; all but RK4
keep the Casimirs to round-off. The same H as a Python callable gives the same motion, slower.

Run it with (``--figure`` alone draws the figure, a path saves it)::

    python examples/kirchhoff.py [--figure [docs/kirchhoff.png]]
"""

import sys
import time

import numpy as np

import lieflow as lf

A = np.array([1.0, 0.7, 0.4])
THETA, SHIFT = 0.8, 0.3
B = THETA * np.prod(A) / A + SHIFT           # Clebsch's condition
H = np.diag(np.concatenate([A, B]))          # H = ½ μᵀ H μ, μ = (M, P)
Z0 = np.array([0.3, -0.5, 0.8, 1.0, 0.4, -0.6])


def clebsch_integral(states):
    """F = ½|M|² − ½θ Σ A_i P_i², the extra integral of Clebsch's case."""
    m, p = states[..., :3], states[..., 3:]
    return 0.5 * np.sum(m * m, axis=-1) - 0.5 * THETA * np.sum(A * p * p, axis=-1)


def hamiltonian(mu):
    """The same H as a Python callable (the slow path)."""
    return 0.5 * float(mu @ H @ mu)


def gradient(mu):
    return H @ mu


def main():
    body = lf.LiePoisson("se3", H)
    dt, t_end = 0.02, 2000.0
    n = int(round(t_end / dt))
    runs = {}
    for method in ("midpoint4", "rkmk4", "rk4"):
        t0 = time.perf_counter()
        runs[method] = lf.integrate(body, Z0, dt=dt, steps=n, method=method, save_every=50)
        elapsed = time.perf_counter() - t0
        tr = runs[method]
        f, h, c = clebsch_integral(tr.states), tr.energy(), tr.invariants()
        print(f"{method:10s} T = {t_end:g}, dt = {dt}: max |ΔF|/F = "
              f"{np.abs(f / f[0] - 1).max():.1e}, |ΔH|/H = {np.abs(h / h[0] - 1).max():.1e}, "
              f"Casimirs {np.abs(c / c[0] - 1).max():.1e}  ({elapsed / n * 1e6:.2f} µs/step)")
    # The Clebsch integral is kept by the exact flow: the midpoint's error is bounded (no drift).
    f = clebsch_integral(runs["midpoint4"].states)
    assert np.abs(f / f[0] - 1).max() < 1e-8
    assert np.abs(runs["midpoint4"].invariants() / runs["midpoint4"].invariants()[0] - 1).max() < 1e-12
    # The same body with H and ∇H as Python callables.
    python = lf.LiePoisson("se3", hamiltonian, gradient)
    t0 = time.perf_counter()
    slow = lf.integrate(python, Z0, dt=dt, steps=5000, method="rkmk4")
    elapsed = time.perf_counter() - t0
    fast = lf.integrate(body, Z0, dt=dt, steps=5000, method="rkmk4")
    print(f"Python callables: {elapsed / 5000 * 1e6:.1f} µs/step, max difference from the native "
          f"path {np.abs(slow.states - fast.states).max():.1e}")
    if "--figure" not in sys.argv:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    path = (sys.argv[sys.argv.index("--figure") + 1:] or [None])[0]  # None: only draw
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    tr = lf.integrate(body, Z0, dt=dt, steps=3000, method="midpoint4", save_every=5)
    ax = axes[0]
    for i, name in enumerate(("M₁", "M₂", "M₃")):
        ax.plot(tr.t, tr.M[:, i], lw=1, label=name)
    for i, name in enumerate(("P₁", "P₂", "P₃")):
        ax.plot(tr.t, tr.Gamma[:, i], "--", lw=1, label=name)
    ax.set(xlabel="t", title="Kirchhoff's body, Clebsch case (midpoint4)")
    ax.legend(fontsize=7, ncol=2)
    ax = axes[1]
    for method, style in (("midpoint4", "-"), ("rkmk4", "--"), ("rk4", ":")):
        tr = runs[method]
        f = clebsch_integral(tr.states)
        ax.loglog(tr.t[1:], np.abs(f / f[0] - 1)[1:] + 1e-17, style, label=method)
    ax.set(xlabel="t", ylabel="|ΔF| / F", title=f"Clebsch's integral, dt = {dt}")
    ax.legend(fontsize=8)
    ax = axes[2]
    for method, style in (("midpoint4", "-"), ("rkmk4", "--"), ("rk4", ":")):
        tr = runs[method]
        c = tr.invariants()
        ax.loglog(tr.t[1:], np.abs(c / c[0] - 1).max(axis=1)[1:] + 1e-17, style, label=method)
    ax.set(xlabel="t", ylabel="max relative change", title="Casimirs |P|², M·P")
    ax.legend(fontsize=8)
    fig.tight_layout()
    if path:  # the docs gallery draws the figure without saving it
        fig.savefig(path, dpi=110)
        print("figure:", path)


if __name__ == "__main__":
    main()
