"""Two rolling spheres
===================

Two spheres rolling against each other (003 §2): a strip of frames of the motion (centres,
contact point and a body axis of each sphere), the energy and the total angular momentum against
time for the catalogued methods, and the planar subsystem (003 §2.4) against the rolling disks of
003 §1 with the same parameters.

Run it with (``--figure`` alone draws the figure, a path saves it)::

    python examples/rolling_spheres.py [--figure [docs/rolling_spheres.png]]
"""

import sys

import numpy as np

import lieflow as lf


def rot(axis_angle):
    return lf.lie.so3_exp(np.asarray(axis_angle, dtype=float))


def main():
    spheres = lf.RollingSpheres(0.7, 1.3, [0.1, -0.2, 0.15], [-0.3, 0.2, 0.4], 2.0, 3.5,
                                [[0.40, 0.05, -0.02], [0.05, 0.30, 0.04], [-0.02, 0.04, 0.25]],
                                [[0.90, -0.10, 0.05], [-0.10, 1.10, 0.08], [0.05, 0.08, 0.70]])
    z0 = spheres.state(rot([0.3, -0.2, 0.5]), rot([-0.4, 0.1, 0.2]), [0.6, 0.0, 0.8],
                       [0.5, -0.3, 0.8], [-0.2, 0.4, 0.1])
    runs = {m: lf.integrate(spheres, z0, dt=0.02, steps=50_000, method=m, save_every=100)
            for m in ("midpoint", "midpoint4", "rkmk4", "rk4")}
    for m, tr in runs.items():
        try:
            j = spheres.angular_momentum(tr.states)
            dj = f"{np.abs(j - j[0]).max():.1e}"
        except lf.NotInGroupError as e:  # rk4 does not keep SO(3); J is refused off the group
            dj = f"undefined ({str(e).split(': ', 1)[1]})"
        print(f"{m:10s} t = 1000: max |dE|/E = {np.abs(tr.energy() / tr.energy()[0] - 1).max():.1e}, "
              f"max |dJ| = {dj}")
    # 003 §2.4: planar-symmetric bodies in T Q0 move as the rolling disks
    i1 = np.array([[0.30, 0.05, 0], [0.05, 0.20, 0], [0, 0, 0.4]])
    i2 = np.array([[0.15, -0.03, 0], [-0.03, 0.25, 0], [0, 0, 0.3]])
    g1, g2, m1, m2, r1, r2 = np.array([0.3, 0.1]), np.array([-0.2, 0.25]), 1.0, 1.5, 1.0, 0.7
    planar = lf.RollingSpheres(r1, r2, [*g1, 0], [*g2, 0], m1, m2, i1, i2)
    theta, phi, thetadot = [0.3, -1.1], 0.5, [0.7, 0.2]
    disks = lf.RollingDisks(r1, r2, g1, g2, m1, m2, i1[0, 0] + i1[1, 1] + m1 * g1 @ g1,
                            i2[0, 0] + i2[1, 1] + m2 * g2 @ g2,
                            rolling_constant=(r1 + r2) * phi - r1 * theta[0] - r2 * theta[1])
    a = lf.integrate(disks, disks.state(theta, thetadot), dt=0.01, steps=2000, method="gauss6",
                     save_every=10)
    b = lf.integrate(planar, planar.planar_state(theta, phi, thetadot), dt=0.01, steps=2000,
                     method="midpoint4", save_every=10)
    p = np.array([planar.to_planar(z, 1e-12) for z in b.states])
    gap = np.abs(np.angle(np.exp(1j * (p[:, :2] - a.theta)))).max()
    print(f"planar spheres vs disks to t = 20: max angle difference {gap:.1e}")
    if "--figure" not in sys.argv:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    path = (sys.argv[sys.argv.index("--figure") + 1:] or [None])[0]  # None: only draw
    fig = plt.figure(figsize=(14, 7.5))
    tr = lf.integrate(spheres, z0, dt=0.01, steps=600, method="midpoint4", save_every=100)
    c, x, q = spheres.centres(tr.states), spheres.centres_of_mass(tr.states), spheres.contact_point(tr.states)
    for k in range(len(tr.t)):
        ax = fig.add_subplot(2, 7, k + 1, projection="3d")
        for s, (col, r) in enumerate((("tab:blue", 0.7), ("tab:orange", 1.3))):
            u, v = np.mgrid[0:2 * np.pi:16j, 0:np.pi:9j]
            ax.plot_wireframe(c[k, s, 0] + r * np.cos(u) * np.sin(v), c[k, s, 1] + r * np.sin(u) * np.sin(v),
                              c[k, s, 2] + r * np.cos(v), color=col, lw=0.3)
            ax.plot(*np.stack([c[k, s], x[k, s]]).T, color=col, lw=2)
        ax.scatter(*q[k], color="k", s=8)
        lo, hi = c[k].min() - 1.3, c[k].max() + 1.3
        ax.set(xlim=(lo, hi), ylim=(lo, hi), zlim=(lo, hi))
        ax.set_box_aspect((1, 1, 1))
        ax.set_axis_off()
        ax.set_title(f"t = {tr.t[k]:.0f}", fontsize=8)
    ax = fig.add_subplot(2, 1, 2)
    for m, tr in runs.items():
        ax.semilogy(tr.t[1:], np.abs(tr.energy() / tr.energy()[0] - 1)[1:] + 1e-17, label=f"{m}: |ΔE|/E")
    j = spheres.angular_momentum(runs["midpoint"].states)
    ax.semilogy(runs["midpoint"].t[1:], np.linalg.norm(j - j[0], axis=1)[1:] + 1e-17, "k:",
                label="midpoint: |ΔJ|")
    ax.set(xlabel="t", title=f"rolling spheres, dt = 0.02 (planar spheres = disks to {gap:.0e})")
    ax.legend(fontsize=7)
    fig.subplots_adjust(left=0.06, right=0.98, top=0.95, bottom=0.08, hspace=0.15)
    if path:  # the docs gallery draws the figure without saving it
        fig.savefig(path, dpi=110)
        print("figure:", path)


if __name__ == "__main__":
    main()
