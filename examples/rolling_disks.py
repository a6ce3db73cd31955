"""Two rolling disks
=================

Two disks rolling against each other (003 §1): the rotational relative equilibria along the
family of rolling constants with their stability, frames of a motion that leaves an unstable
equilibrium and of one that stays near a stable one, and the invariants against time.

Run it with (``--figure`` alone draws the figure, a path saves it)::

    python examples/rolling_disks.py [--figure [docs/rolling_disks.png]]
"""

import sys

import numpy as np

import lieflow as lf

DISKS = dict(r1=1.0, r2=0.7, gamma1=0.3 + 0.1j, gamma2=-0.2 + 0.25j, m1=1.0, m2=1.5,
             inertia1=0.8, inertia2=0.6)


def main():
    d = lf.RollingDisks(**DISKS)
    eqs = d.relative_equilibria()
    print("relative equilibria for c = 0 (theta1 in [0, 2 pi), gauge phi = 0):")
    for e in eqs:
        print(f"  theta = ({e.theta1:.6f}, {e.theta2:.6f})  stable = {e.stable}  "
              f"locked inertia = {e.locked_inertia:.5f}  P = ({e.contact_point[0]:.4f}, "
              f"{e.contact_point[1]:.4f})")
    # the family over one period of the rolling constant (c -> c + 2 pi r2 relabels disk 2)
    cs = np.linspace(0.0, 2 * np.pi * DISKS["r2"], 241)
    family = [(c, e.theta1, e.stable) for c in cs for e in d.relative_equilibria(rolling_constant=c)]
    # motions: a 1e-3 kick off each equilibrium, t = 60
    runs = []
    for e in eqs:
        z = np.array(e.state(1.0))
        z[0] += 1e-3
        runs.append(lf.integrate(d, z, dt=0.01, steps=6000, method="gauss6", save_every=20))
    long = {m: lf.integrate(d, d.state([0.3, -1.1], [0.7, 0.2]), dt=0.05, steps=40_000, method=m,
                            save_every=200) for m in ("gauss6", "rk4")}
    for m, tr in long.items():
        print(f"{m}, dt = 0.05, t = 2000: max |dE| = {np.abs(tr.energy() - tr.energy()[0]).max():.1e}, "
              f"max |dJ| = {np.abs(d.angular_momentum(tr.states) - d.angular_momentum(tr.states[0])).max():.1e}")
    if "--figure" not in sys.argv:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle
    path = (sys.argv[sys.argv.index("--figure") + 1:] or [None])[0]  # None: only draw
    fig, axes = plt.subplots(1, 4, figsize=(17, 4.2))
    ax = axes[0]
    f = np.array(family, dtype=float)
    for stable, style, label in [(1.0, "o", "stable"), (0.0, "x", "unstable")]:
        sel = f[:, 2] == stable
        ax.plot(f[sel, 0], f[sel, 1], style, ms=2.5, label=label)
    ax.set(xlabel="rolling constant c", ylabel="θ₁ of the equilibrium (u = 1)",
           title="relative equilibria along the family")
    ax.legend(fontsize=8)
    for ax, e, tr in zip(axes[1:3], eqs, runs):
        pos = d.positions(tr.states)
        for i, alpha in zip(np.linspace(0, len(tr.t) - 1, 5).astype(int), np.linspace(0.25, 1, 5)):
            rot = np.exp(-1j * tr.phi[i])          # draw in the frame that turns with the contact
            for k, col in enumerate(("tab:blue", "tab:orange")):
                c = complex(*pos["centres"][i, k]) * rot
                x = complex(*pos["masses"][i, k]) * rot
                ax.add_patch(Circle((c.real, c.imag), DISKS[f"r{k + 1}"], fill=False, color=col,
                                    alpha=alpha))
                ax.plot([c.real, x.real], [c.imag, x.imag], color=col, alpha=alpha)
        ax.set(xlim=(-2.2, 2.2), ylim=(-2.2, 2.2), aspect="equal",
               title=f"{'stable' if e.stable else 'unstable'} equilibrium, kick 1e-3 (t ≤ 60)")
    ax = axes[3]
    for m, tr in long.items():
        ax.semilogy(tr.t[1:], np.abs(tr.energy() - tr.energy()[0])[1:] + 1e-17, label=f"{m}: |ΔH|")
    ax.set(xlabel="t", title="energy error, dt = 0.05")
    ax.legend(fontsize=8)
    fig.tight_layout()
    if path:  # the docs gallery draws the figure without saving it
        fig.savefig(path, dpi=110)
        print("figure:", path)


if __name__ == "__main__":
    main()
