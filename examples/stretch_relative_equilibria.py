"""Relative equilibria of a stretch body
=====================================

Relative equilibria of a Stretch body (U = (k/2) sum (sigma_i - 1)^2) rotating in the (1, 2)
plane (001 §8), and their stability.

For this potential the shear stiffness is k for every shape, so a rotation xi = w e_12,
eta = m e_12 of the shape diag(a1, a2, 1) balances iff (w + m)^2 = k and
(w - m)^2 = k (1 - 2 / (a1 + a2)) (the force balance solved by `relative_equilibria(shape=...)`).
The family below keeps a1 - a2 = 2.5 (elongated shapes) and lets a1 + a2 grow, so w runs from sqrt(k)/2 up; each
member is judged by the energy-momentum and the spectral test, and one stable and one unstable
member are simulated (verlet4, perturbation 1e-4) to t = 200.

Run it with (``--figure`` alone draws the figure, a path saves it)::

    python examples/stretch_relative_equilibria.py [--figure [docs/stretch_relative_equilibria.png]]
"""

import sys

import numpy as np

import lieflow as lf

pr = lf.pseudo_rigid


def family(k=1.0, gap=2.5, sums=np.linspace(2.52, 7.0, 90)):
    st = lf.potentials.Stretch(k)
    rows = []
    for s in sums:
        a = [(s + gap) / 2, (s - gap) / 2, 1.0]
        if abs(a[1] - 1.0) < 1e-9:
            continue
        eqs = [q for q in pr.relative_equilibria(st, shape=a, plane=(0, 1))
               if q.xi[0, 1] > 0]
        for q in eqs:
            v = q.stability()
            rows.append((q.xi[0, 1], q.eta[0, 1], *q.shape, q.energy, v.energy_momentum.stable,
                         v.spectral.stable, v.spectral.max_real_part, q))
    return st, rows


def simulate(st, q, t_end=200.0, dt=0.01):
    X, P = q.motion([0.0])
    X0 = X[0] + 1e-4 * np.random.default_rng(0).standard_normal((3, 3))
    body = lf.PseudoRigidBody(3, st, check_det=False)
    n = int(round(t_end / dt))
    tr = lf.integrate(body, (X0, P[0]), dt=dt, steps=n, method="verlet4", save_every=50)
    return tr.t, tr.singular_values()


def main():
    st, rows = family()
    print(f"{'omega':>8} {'mu':>8} {'a1':>7} {'a2':>7} {'a3':>5} {'energy':>9}  EM    spectral  max Re")
    for r in rows[::12]:
        print(f"{r[0]:8.4f} {r[1]:8.4f} {r[2]:7.3f} {r[3]:7.3f} {r[4]:5.2f} {r[5]:9.5f}  "
              f"{str(r[6]):5s} {str(r[7]):8s}  {r[8]:.2e}")
    stable = next((r for r in rows if r[7]), None)
    unstable = next((r for r in rows if not r[7]), None)
    sims = {}
    for name, r in [("stable", stable), ("unstable", unstable)]:
        if r is None:
            print(f"no {name} member in the family")
            continue
        t, sv = simulate(st, r[9])
        dev = np.abs(sv - np.sort(r[9].shape)[::-1]).max(axis=1)
        sims[name] = (r, t, sv)
        print(f"{name} member omega = {r[0]:.4f}: max deviation of the semi-axes over t = 200: "
              f"{dev.max():.2e}")
    if "--figure" in sys.argv:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        path = (sys.argv[sys.argv.index("--figure") + 1:] or [None])[0]  # None: only draw
        fig, ax = plt.subplots(1, 3, figsize=(14, 4))
        w = np.array([r[0] for r in rows])
        colour = np.array(["tab:blue" if r[7] else "tab:red" for r in rows])
        for i, lab in zip(range(3), ["a1", "a2", "a3"]):
            ax[0].scatter(w, [r[2 + i] for r in rows], c=colour, s=8)
        ax[0].set(xlabel="omega", ylabel="semi-axes a1, a2, a3",
                  title="family in the (1,2) plane (blue: stable, red: unstable)")
        ax[1].scatter(w, [r[5] for r in rows], c=colour, s=8)
        ax[1].set(xlabel="omega", ylabel="energy")
        for name, (r, t, sv) in sims.items():
            ax[2].plot(t, sv[:, 0] - sv[0, 0], label=f"{name}, omega = {r[0]:.3f}")
        ax[2].set(xlabel="t", ylabel="a1(t) - a1(0)", title="perturbed by 1e-4 (verlet4)")
        ax[2].legend()
        fig.tight_layout()
        if path:  # the docs gallery draws the figure without saving it
            fig.savefig(path, dpi=110)
            print("figure:", path)


if __name__ == "__main__":
    main()
